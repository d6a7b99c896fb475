"""A co-simulation master for the tail-sitter FMUs (fmpy's FMU2Slave underneath).

Timing follows docs/DESIGN.md, "Ports and timing" and "A co-simulation
step". Gauss-Seidel (the reference): at each communication point t the
controller inputs are set from the plant outputs at t, the controller steps,
the plant inputs are set from the controller outputs, the plant steps.
Jacobi: both units are set from values at t before either
steps, so the plant flies the command of the previous sample.
"""

from __future__ import annotations

import math
import pathlib
import shutil
import tempfile
from dataclasses import dataclass, field
from typing import Callable, Mapping

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from . import fmilog

Vector3 = tuple[float, float, float]
TimeFunction = Callable[[float], Vector3]


# Time edges (s): a communication point t has reached an edge t_edge when
# t >= t_edge - EDGE_TOLERANCE, so that t = k*h computed in floating point meets
# an edge at a multiple of h. The same definition as the Rust closed loop
# (`closed_loop::EDGE_TOLERANCE`: `Wind::Step`, `Scenario::ref_offset`,
# `Trace::window`); the value is `edge_tolerance` of
# modelDescription/fragments/mission_criteria.json (tailsim.metrics checks).
EDGE_TOLERANCE = 1e-9


def step(t_step: float, value: Vector3) -> TimeFunction:
    """A profile that is zero before `t_step` and `value` from then on (from the
    first t with t >= t_step - EDGE_TOLERANCE, as `closed_loop::Wind::Step`)."""

    def f(t: float) -> Vector3:
        return value if t >= t_step - EDGE_TOLERANCE else (0.0, 0.0, 0.0)

    return f


def wind_from(from_bearing: float, speed: float) -> Vector3:
    """Air-mass velocity (NED, m/s) of a horizontal wind of `speed` blowing *from* the
    bearing `from_bearing` (rad, 0 = from the north, π/2 = from the east):
    −speed (cos b, sin b, 0), as `closed_loop::wind_from`. A steady wind switched on at
    t is `step(t, wind_from(b, speed))` (`closed_loop::Wind::step_from`)."""
    return (-speed * math.cos(from_bearing), -speed * math.sin(from_bearing), 0.0)


def one_minus_cosine_gust(t_start: float, duration: float, amplitude: Vector3) -> TimeFunction:
    """The 1 − cos gust: amplitude · (1 − cos(2π(t − t_start)/duration))/2 for
    0 ≤ (t − t_start)/duration ≤ 1, zero outside (as `closed_loop::Wind::OneMinusCosine`)."""

    def f(t: float) -> Vector3:
        s = (t - t_start) / duration
        if 0.0 <= s <= 1.0:
            k = 0.5 * (1.0 - math.cos(2.0 * math.pi * s))
            return (amplitude[0] * k, amplitude[1] * k, amplitude[2] * k)
        return (0.0, 0.0, 0.0)

    return f


class Fmu:
    """An FMU extracted once; `instantiate` gives fresh fmpy slaves of it."""

    def __init__(self, path: str | pathlib.Path, workdir: str | pathlib.Path | None = None):
        self.path = pathlib.Path(path)
        self.md = read_model_description(str(self.path))
        self._tmp = None if workdir else tempfile.mkdtemp(prefix="tailsim-")
        target = pathlib.Path(workdir or self._tmp) / self.md.coSimulation.modelIdentifier
        self.dir = extract(str(self.path), unzipdir=str(target))
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.identifier = self.md.coSimulation.modelIdentifier

    def start(self, name: str) -> float:
        """The declared start value of variable `name` (its default, from modelDescription.xml)."""
        v = self.variables[name]
        if v.start is None:
            raise KeyError(f"{self.identifier}: variable '{name}' declares no start value")
        return float(v.start)

    def starts(self, names: list[str]) -> dict[str, float]:
        """Declared start values of `names`."""
        return {n: self.start(n) for n in names}

    def names(self, causality: str) -> list[str]:
        return [v.name for v in self.md.modelVariables if v.causality == causality]

    def instantiate(self, name: str, callbacks=None) -> FMU2Slave:
        slave = FMU2Slave(
            guid=self.md.guid, unzipDirectory=self.dir, modelIdentifier=self.identifier, instanceName=name
        )
        # fmilog's callbacks, not fmpy's defaults: fmpy's logger proxy may point at a logger
        # some earlier fmpy call freed (see fmilog).
        slave.instantiate(callbacks=fmilog.callbacks() if callbacks is None else callbacks)
        return slave

    def set(self, slave: FMU2Slave, values: Mapping[str, float | int | bool]) -> None:
        """Set values by name, each through the setter of its declared type."""
        by_type: dict[str, tuple[list[int], list]] = {}
        for name, value in values.items():
            if name not in self.variables:
                raise KeyError(f"{self.identifier} has no variable '{name}'")
            v = self.variables[name]
            vrs, vals = by_type.setdefault(v.type, ([], []))
            vrs.append(v.valueReference)
            vals.append(value)
        for type_, (vrs, vals) in by_type.items():
            if type_ == "Real":
                slave.setReal(vrs, [float(x) for x in vals])
            elif type_ == "Integer":
                slave.setInteger(vrs, [int(x) for x in vals])
            elif type_ == "Boolean":
                slave.setBoolean(vrs, [bool(x) for x in vals])
            else:
                slave.setString(vrs, [str(x) for x in vals])

    def cleanup(self) -> None:
        if self._tmp:
            shutil.rmtree(self._tmp, ignore_errors=True)


@dataclass
class RunResult:
    """Every recorded signal by name (numpy arrays over `time`) with its unit."""

    signals: dict[str, np.ndarray]
    units: dict[str, str]
    plant: str
    controller: str
    ordering: str
    wall_time_controller: float = 0.0
    wall_time_plant: float = 0.0
    steps: int = 0
    log: list[tuple[str, str, str]] = field(default_factory=list)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.signals[name]

    @property
    def time(self) -> np.ndarray:
        return self.signals["time"]

    def write_csv(self, path: str | pathlib.Path) -> None:
        """CSV with a header `name [unit]`."""
        names = list(self.signals)
        header = ",".join(f"{n} [{self.units.get(n, '')}]" if self.units.get(n) else n for n in names)
        data = np.column_stack([self.signals[n] for n in names])
        np.savetxt(path, data, delimiter=",", header=header, comments="", fmt="%.17g")


class ClosedLoop:
    """Plant + controller, wired by port name.

    plant_params / controller_params: start values set in initialisation mode
    (parameters and inputs, by name). `wind` and `ref_offset` are functions of
    time giving (n, e, d); they drive the plant's `wind_*` and the controller's
    `ref_offset_*` inputs.
    """

    def __init__(
        self,
        plant: Fmu,
        controller: Fmu,
        plant_params: Mapping[str, float] | None = None,
        controller_params: Mapping[str, float] | None = None,
        ordering: str = "gauss-seidel",
        callbacks=None,
    ):
        if ordering not in ("gauss-seidel", "jacobi"):
            raise ValueError(f"ordering must be 'gauss-seidel' or 'jacobi', not {ordering!r}")
        self.plant, self.controller = plant, controller
        self.plant_params = dict(plant_params or {})
        self.controller_params = dict(controller_params or {})
        self.ordering = ordering
        self.callbacks = callbacks
        p_out = set(plant.names("output"))
        p_in = set(plant.names("input"))
        # Wiring by name: controller input ← plant output, controller output → plant input.
        self.to_controller = [n for n in controller.names("input") if n in p_out]
        self.to_plant = [n for n in controller.names("output") if n in p_in]
        missing = [n for n in p_in if n.endswith("_cmd") and n not in self.to_plant]
        if missing:
            raise ValueError(f"{controller.identifier} does not drive plant inputs {missing}")
        self._p_vr_out = [plant.variables[n].valueReference for n in self.to_controller]
        self._c_vr_in = [controller.variables[n].valueReference for n in self.to_controller]
        self._c_vr_out = [controller.variables[n].valueReference for n in self.to_plant]
        self._p_vr_in = [plant.variables[n].valueReference for n in self.to_plant]
        self.plant_outputs = [n for n in plant.names("output")]
        self.controller_outputs = [n for n in controller.names("output") if controller.variables[n].type == "Real"]
        self.controller_int_outputs = [
            n for n in controller.names("output") if controller.variables[n].type == "Integer"
        ]

    def _step_loop(self, p, c, iterator, h, n, wind, ref_offset, data, rec_p, rec_c, rec_ci):
        """The communication steps (DESIGN.md §2 Timing), recording row k of `data` at t = k h.

        Per step and unit one get and one set of Real values (plus the controller's Integer
        outputs), through fmpy's low-level `fmi2GetReal`/`fmi2SetReal` on ctypes arrays
        prepared once: no per-step list, dict or ctypes-array building. The calls, their
        order and the values passed are those of the plain master (same trajectories, bit
        for bit): the controller inputs are the plant outputs read before the plant's wind
        is set; the recorded plant outputs are read after the wind and the command are set.
        """
        import ctypes
        import time as wall

        real = ctypes.c_double
        vr_t = ctypes.c_uint

        def vrs(refs):
            return (vr_t * len(refs))(*refs)

        pv, cv = self.plant.variables, self.controller.variables
        n_in, n_cmd = len(self._c_vr_in), len(self._c_vr_out)
        # Controller inputs: [plant outputs wired by name..., ref_offset n, e, d].
        c_in_vr = vrs(self._c_vr_in + [cv[f"ref_offset_{k}"].valueReference for k in "ned"])
        p_out_vr = vrs(self._p_vr_out)
        c_in = (real * (n_in + 3))()
        # Plant inputs: [wind n, e, d, commands wired by name...].
        p_in_vr = vrs([pv[f"wind_{k}"].valueReference for k in "ned"] + self._p_vr_in)
        p_in = (real * (3 + n_cmd))()
        p_in_np = np.ctypeslib.as_array(p_in)
        cmd_vr = vrs(self._c_vr_out)
        # Recording buffers (numpy views of the ctypes arrays).
        rec_p_vr, rec_c_vr, rec_ci_vr = vrs(rec_p), vrs(rec_c), vrs(rec_ci)
        rec_p_buf, rec_c_buf = (real * len(rec_p))(), (real * len(rec_c))()
        rec_ci_buf = (ctypes.c_int * len(rec_ci))()
        rec_p_np, rec_c_np = np.ctypeslib.as_array(rec_p_buf), np.ctypeslib.as_array(rec_c_buf)
        rec_ci_np = np.ctypeslib.as_array(rec_ci_buf) if rec_ci else None
        n_rp, n_rc, n_rci = len(rec_p), len(rec_c), len(rec_ci)
        c0, c1, c2 = 1 + n_rp, 1 + n_rp + n_rc, 1 + n_rp + n_rc + n_rci
        # Gauss-Seidel: the command is read with the recorded controller outputs.
        rec_c_pos = {r: i for i, r in enumerate(rec_c)}
        cmd_in_rec = [rec_c_pos.get(r) for r in self._c_vr_out]
        gs_from_rec = self.ordering == "gauss-seidel" and None not in cmd_in_rec
        cmd_idx = np.array(cmd_in_rec if gs_from_rec else [], dtype=np.intp)
        cmd_ptr = ctypes.cast(ctypes.addressof(p_in) + 3 * ctypes.sizeof(real), ctypes.POINTER(real))  # p_in[3:]
        jacobi = self.ordering == "jacobi"
        p_comp, c_comp = p.component, c.component
        p_get, p_set, p_step = p.fmi2GetReal, p.fmi2SetReal, p.fmi2DoStep
        c_get, c_set, c_step, c_get_int = c.fmi2GetReal, c.fmi2SetReal, c.fmi2DoStep, c.fmi2GetInteger
        n_c_in, n_p_in = n_in + 3, 3 + n_cmd
        clock = wall.perf_counter
        t_ctrl = t_plant = 0.0
        for k in iterator:
            t = k * h
            w, off = wind(t), ref_offset(t)
            p_get(p_comp, p_out_vr, n_in, c_in)  # y_p, straight into the controller's buffer
            if jacobi:
                c_get(c_comp, cmd_vr, n_cmd, cmd_ptr)  # command of the previous sample
            c_in[n_in], c_in[n_in + 1], c_in[n_in + 2] = off
            c_set(c_comp, c_in_vr, n_c_in, c_in)
            p_in[0], p_in[1], p_in[2] = w
            # The controller also samples at the last point, so the recorded
            # reference and command belong to the same time as the plant outputs.
            t0 = clock()
            c_step(c_comp, t, h, 1)
            t_ctrl += clock() - t0
            c_get(c_comp, rec_c_vr, n_rc, rec_c_buf)
            if not jacobi:
                if gs_from_rec:
                    p_in_np[3:] = rec_c_np[cmd_idx]
                else:
                    c_get(c_comp, cmd_vr, n_cmd, cmd_ptr)
            p_set(p_comp, p_in_vr, n_p_in, p_in)
            p_get(p_comp, rec_p_vr, n_rp, rec_p_buf)
            row = data[k]
            row[0] = t
            row[1:c0] = rec_p_np
            row[c0:c1] = rec_c_np
            if n_rci:
                c_get_int(c_comp, rec_ci_vr, n_rci, rec_ci_buf)
                row[c1:c2] = rec_ci_np
            row[c2 : c2 + 3] = w
            row[c2 + 3 : c2 + 6] = off
            if k < n:
                t0 = clock()
                p_step(p_comp, t, h, 1)
                t_plant += clock() - t0
        return t_ctrl, t_plant

    def run(
        self,
        stop_time: float | None = None,
        step_size: float | None = None,
        wind: TimeFunction | None = None,
        ref_offset: TimeFunction | None = None,
        progress: bool = False,
        description: str = "",
    ) -> RunResult:
        import time as wall

        c_md = self.controller.md
        h = float(step_size or self.controller_params.get("sample_time") or c_md.defaultExperiment.stepSize)
        stop = float(stop_time if stop_time is not None else c_md.defaultExperiment.stopTime)
        n = int(round(stop / h))
        wind = wind or (lambda t: (0.0, 0.0, 0.0))
        ref_offset = ref_offset or (lambda t: (0.0, 0.0, 0.0))
        p = self.plant.instantiate("plant", self.callbacks)
        c = self.controller.instantiate("controller", self.callbacks)
        pv, cv = self.plant.variables, self.controller.variables
        wind_vr = [pv[f"wind_{k}"].valueReference for k in "ned"]
        offset_vr = [cv[f"ref_offset_{k}"].valueReference for k in "ned"]
        rec_p = [pv[n].valueReference for n in self.plant_outputs]
        rec_c = [cv[n].valueReference for n in self.controller_outputs]
        rec_ci = [cv[n].valueReference for n in self.controller_int_outputs]
        names = ["time"] + self.plant_outputs + self.controller_outputs + self.controller_int_outputs
        names += ["wind_n", "wind_e", "wind_d", "ref_offset_n", "ref_offset_e", "ref_offset_d"]
        data = np.full((n + 1, len(names)), np.nan)
        t_ctrl = t_plant = 0.0
        try:
            for s in (p, c):
                s.setupExperiment(startTime=0.0)
                s.enterInitializationMode()
            self.plant.set(p, self.plant_params)
            p.setReal(wind_vr, list(wind(0.0)))
            p.exitInitializationMode()
            self.controller.set(c, self.controller_params)
            c.setReal(self._c_vr_in, p.getReal(self._p_vr_out))
            c.setReal(offset_vr, list(ref_offset(0.0)))
            c.exitInitializationMode()
            iterator = range(n + 1)
            if progress:
                from tqdm import tqdm

                iterator = tqdm(iterator, desc=description or f"{self.controller.identifier}", unit="step", leave=False)
            t_ctrl, t_plant = self._step_loop(p, c, iterator, h, n, wind, ref_offset, data, rec_p, rec_c, rec_ci)
            for s in (p, c):
                s.terminate()
        finally:
            for s in (p, c):
                try:
                    s.freeInstance()
                except Exception:  # noqa: BLE001 - already failed; free what can be freed
                    pass
        units = {"time": "s"}
        for name in self.plant_outputs:
            units[name] = pv[name].unit or ""
        for name in self.controller_outputs:
            units[name] = cv[name].unit or ""
        for name in ["wind_n", "wind_e", "wind_d", "ref_offset_n", "ref_offset_e", "ref_offset_d"]:
            units[name] = "m/s" if name.startswith("wind") else "m"
        signals = {name: data[:, i].copy() for i, name in enumerate(names)}
        # The command the plant flew over [t, t+h) under this ordering.
        return RunResult(
            signals=signals,
            units=units,
            plant=self.plant.identifier,
            controller=self.controller.identifier,
            ordering=self.ordering,
            wall_time_controller=t_ctrl,
            wall_time_plant=t_plant,
            steps=n + 1,
        )


def phase_slices(result: RunResult) -> dict[int, np.ndarray]:
    """Boolean masks of the samples in each phase (controller's `phase` output)."""
    phase = result["phase"]
    return {k: phase == k for k in range(5)}


def pos_error(result: RunResult) -> np.ndarray:
    return np.sqrt(
        (result["pos_n"] - result["ref_pos_n"]) ** 2
        + (result["pos_e"] - result["ref_pos_e"]) ** 2
        + (result["pos_d"] - result["ref_pos_d"]) ** 2
    )


def settling_time(t: np.ndarray, error: np.ndarray, t_step: float, band: float = 0.5) -> float:
    """Time after `t_step` from which `error` stays below `band` (inf if it never does)."""
    after = t >= t_step
    te, ee = t[after], error[after]
    outside = np.nonzero(ee >= band)[0]
    if len(outside) == 0:
        return 0.0
    last = outside[-1]
    if last == len(ee) - 1:
        return math.inf
    return float(te[last + 1] - t_step)


__all__ = [
    "ClosedLoop",
    "Fmu",
    "RunResult",
    "one_minus_cosine_gust",
    "phase_slices",
    "pos_error",
    "settling_time",
    "step",
]
