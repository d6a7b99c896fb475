"""Avionics in the loop: plant → sensors → estimator → controller → plant.

The chain of four FMUs, every connection by name:

* plant outputs → `tailsitter_sensors` inputs (true state),
* sensor outputs → `tailsitter_ekf` measurement inputs (Real, Integer
  `gps_fix_count`, Boolean `gps_valid`),
* estimator outputs → controller inputs (the estimator's outputs carry the
  names of the plant outputs they estimate, so a controller flies the estimate
  exactly as it flies the plant),
* controller commands → plant inputs and → estimator command inputs (its motor
  and servo models).

The parameters the sensors and the estimator share (reference point
`ref_latitude`, `ref_longitude`, `ref_height`, Earth field `mag_field_total`,
`mag_declination`, `mag_inclination`, the analogue filter `filter_enabled`,
`filter_bandwidth`) are copied from the sensors' parameters to the estimator's
unless the estimator's are given explicitly; so is the plant's `aero_model` to
the estimator's (the aerodynamic model of its prediction).

Orderings (per controller step h, at t = k h):

* Gauss-Seidel: plant outputs at t → sensors step [t, t + h_s) → the
  controller reads the estimator's outputs (the estimate of t) and steps → the
  estimator gets the measurements of t and the commands for [t, t + h) and
  steps → the plant gets the commands and steps.
* Jacobi: every unit's inputs are set from outputs at t before any steps: the
  estimator fuses the sensors' outputs of the previous step and the commands
  of the previous sample, the plant flies the command of the previous sample
  (as `tailsim.master.ClosedLoop` under Jacobi). The estimator is told so:
  unless given, its `measurement_latency` (the age of the samples) and its
  `prediction_lead` (the outputs describe the time the command computed from
  them reaches the plant) are set to the controller's step.

Communication step of the plant and sensors, `plant_step` h_s (h_s = h / m,
m an integer; default h): the plant and the sensors step m times per
controller step, the controller and the estimator once. How h_s affects the
sensor model: the sensors see the truth only at their communication points and
hold it over the step, while each sensor samples at its own rate (IMU 200 Hz,
magnetometer and pitot 50 Hz, GPS 4 Hz) and runs its 8 Hz Butterworth at that
rate. With h_s = 20 ms the four IMU samples of a step all see the truth of its
start (a 200 Hz sensor fed a 50 Hz staircase: the filter then smooths the
staircase, the effective delay grows by ≈ h_s/2); with h_s = 5 ms every IMU
sample sees a fresh truth, as a real sensor would. The noise does not change:
each sensor's noise sequence depends on its sample index only. The estimator
still reads the latest sample once per h (the sample taken in
[t, t + h_s)), and the GPS fix instants (every 0.25 s) fall on the h_s grid.

Delays: the latest IMU sample describes the aircraft the Butterworth's group
delay (28 ms) plus `measurement_latency` before the communication point, and
the controller's command reaches the plant `prediction_lead` after the end of
the estimator's step. The estimator predicts its outputs over both with its own
aircraft model driven by the commands (`model_prediction`,
crates/state-estimator/README.md). Without it (extrapolating the samples by
their backward difference) the TSD's normal-acceleration / pitch loop (≈ 4.5
Hz) had no margin left: it diverged under Jacobi and lost 19–21 m with plant
and sensors at 5 ms; with it both controllers fly Gauss-Seidel and Jacobi at
20 ms and with plant and sensors at 5 ms (tests/test_avionics.py).

The result is a `tailsim.master.RunResult` whose signals hold the plant's
outputs (the truth) under their names, the controller's outputs, the
estimator's outputs as `est_<name>` (its diagnostics `est_std_*` as they are),
and the estimation errors against the truth: `err_pos` (m), `err_vel` (m/s),
`err_att` (rad, the angle of the rotation between the true and estimated
attitude), `err_airspeed` (m/s), `err_alpha`, `err_beta` (rad).
"""

from __future__ import annotations

import math
import time as wall
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from .master import Fmu, RunResult, TimeFunction, pos_error

#: Parameters of the same meaning in the sensors and the estimator.
SHARED_PARAMETERS = (
    "ref_latitude",
    "ref_longitude",
    "ref_height",
    "mag_field_total",
    "mag_declination",
    "mag_inclination",
    "filter_enabled",
    "filter_bandwidth",
)

#: Phase names by the controller's `phase` output.
PHASES = ["vertical 1", "transition 1", "level", "transition 2", "vertical 2"]

#: Estimation errors recorded (signal name, unit).
ERRORS = [
    ("err_pos", "m"),
    ("err_vel", "m/s"),
    ("err_att", "rad"),
    ("err_airspeed", "m/s"),
    ("err_alpha", "rad"),
    ("err_beta", "rad"),
]


class _Link:
    """Values of the variables `names` of `src` copied to the same names of `dst`,
    grouped by type (Real, Integer, Boolean)."""

    def __init__(self, src: Fmu, dst: Fmu, names: list[str]):
        self.groups = []
        for type_ in ("Real", "Integer", "Boolean"):
            sel = [n for n in names if src.variables[n].type == type_]
            if sel:
                self.groups.append(
                    (
                        type_,
                        [src.variables[n].valueReference for n in sel],
                        [dst.variables[n].valueReference for n in sel],
                    )
                )

    def get(self, slave) -> list:
        out = []
        for type_, vr_src, _ in self.groups:
            getter = {"Real": slave.getReal, "Integer": slave.getInteger, "Boolean": slave.getBoolean}[type_]
            out.append(getter(vr_src))
        return out

    def set(self, slave, values: list) -> None:
        for (type_, _, vr_dst), vals in zip(self.groups, values):
            setter = {"Real": slave.setReal, "Integer": slave.setInteger, "Boolean": slave.setBoolean}[type_]
            setter(vr_dst, list(vals))

    def copy(self, src_slave, dst_slave) -> None:
        self.set(dst_slave, self.get(src_slave))


def _wire(src: Fmu, dst: Fmu) -> list[str]:
    """Names of `src` outputs that are `dst` inputs."""
    out = set(src.names("output"))
    return [n for n in dst.names("input") if n in out]


class AvionicsLoop:
    """Plant + sensors + estimator + controller (see the module documentation).

    `*_params`: values set in initialisation mode by name. `plant_step`: the
    communication step of the plant and the sensors (s), a divisor of the
    controller's step (default: the controller's step).

    A run that fails mid-flight (an FMI error status, e.g. the plant's envelope check)
    raises the unit's exception with the record up to the last completed step attached
    as `exc.partial_result` (a `RunResult`; no rows when it failed in initialisation).

    `truth_inputs` (diagnostics only): controller inputs taken from the plant's outputs of
    the same names (the truth of t) instead of the estimator's, e.g. ("alpha", "beta") to
    see whether the α/β estimate is what loses a run.
    """

    def __init__(
        self,
        plant: Fmu,
        sensors: Fmu,
        ekf: Fmu,
        controller: Fmu,
        plant_params: Mapping[str, float] | None = None,
        sensors_params: Mapping[str, float | int | bool] | None = None,
        ekf_params: Mapping[str, float | int | bool] | None = None,
        controller_params: Mapping[str, float] | None = None,
        ordering: str = "gauss-seidel",
        plant_step: float | None = None,
        callbacks=None,
        truth_inputs: tuple[str, ...] = (),
    ):
        if ordering not in ("gauss-seidel", "jacobi"):
            raise ValueError(f"ordering must be 'gauss-seidel' or 'jacobi', not {ordering!r}")
        self.plant, self.sensors, self.ekf, self.controller = plant, sensors, ekf, controller
        self.plant_params = dict(plant_params or {})
        self.sensors_params = dict(sensors_params or {})
        shared = {n: v for n, v in self.sensors_params.items() if n in SHARED_PARAMETERS}
        self.ekf_params = {**shared, **dict(ekf_params or {})}
        if "aero_model" in self.plant_params and "aero_model" not in self.ekf_params:
            # The estimator predicts with the plant's configured aerodynamic model.
            self.ekf_params["aero_model"] = self.plant_params["aero_model"]
        if ordering == "jacobi":
            # The delays a Jacobi master adds, one controller step each (set in `run`).
            self._jacobi_defaults = [n for n in ("measurement_latency", "prediction_lead") if n not in self.ekf_params]
        else:
            self._jacobi_defaults = []
        self.controller_params = dict(controller_params or {})
        self.ordering = ordering
        self.plant_step = plant_step
        self.callbacks = callbacks

        self.plant_to_sensors = _Link(plant, sensors, _wire(plant, sensors))
        meas = _wire(sensors, ekf)
        self.sensors_to_ekf = _Link(sensors, ekf, meas)
        ekf_meas_inputs = [n for n in ekf.names("input") if not n.endswith("_cmd")]
        missing = [n for n in ekf_meas_inputs if n not in meas]
        if missing:
            raise ValueError(f"{sensors.identifier} does not drive {ekf.identifier} inputs {missing}")
        self.ekf_to_controller = _Link(ekf, controller, _wire(ekf, controller))
        # The controller's other inputs (mission reference offset) are set by the master.
        p_out = set(plant.names("output"))
        not_estimated = [
            n
            for n in controller.names("input")
            if n in p_out and n not in ekf.names("output")
        ]
        if not_estimated:
            raise ValueError(f"{ekf.identifier} does not estimate controller inputs {not_estimated}")
        unknown = [n for n in truth_inputs if n not in _wire(ekf, controller) or n not in p_out]
        if unknown:
            raise ValueError(f"truth_inputs {unknown} are not estimator outputs the controller reads")
        # Diagnostic oracle: these controller inputs come from the plant (the truth), the
        # others from the estimator; flying with one estimate replaced by the truth tells
        # whether that estimate is what loses a run.
        self.truth_to_controller = _Link(plant, controller, list(truth_inputs)) if truth_inputs else None
        self.controller_to_plant = _Link(controller, plant, _wire(controller, plant))
        self.controller_to_ekf = _Link(controller, ekf, _wire(controller, ekf))
        missing = [n for n in plant.names("input") if n.endswith("_cmd") and n not in _wire(controller, plant)]
        if missing:
            raise ValueError(f"{controller.identifier} does not drive plant inputs {missing}")

        self.plant_outputs = [n for n in plant.names("output") if plant.variables[n].type == "Real"]
        self.controller_outputs = [n for n in controller.names("output") if controller.variables[n].type == "Real"]
        self.controller_int_outputs = [
            n for n in controller.names("output") if controller.variables[n].type == "Integer"
        ]
        self.ekf_outputs = [n for n in ekf.names("output") if ekf.variables[n].type == "Real"]
        self.ekf_int_outputs = [n for n in ekf.names("output") if ekf.variables[n].type == "Integer"]

    @staticmethod
    def est_name(name: str) -> str:
        return name if name.startswith("est_") else f"est_{name}"

    def run(
        self,
        stop_time: float | None = None,
        step_size: float | None = None,
        wind: TimeFunction | None = None,
        ref_offset: TimeFunction | None = None,
    ) -> RunResult:
        c_md = self.controller.md
        h = float(step_size or self.controller_params.get("sample_time") or c_md.defaultExperiment.stepSize)
        hs = float(self.plant_step or h)
        m = int(round(h / hs))
        if m < 1 or abs(m * hs - h) > 1e-12 * h:
            raise ValueError(f"plant_step {hs} s must divide the controller step {h} s")
        hs = h / m
        stop = float(stop_time if stop_time is not None else c_md.defaultExperiment.stopTime)
        n = int(round(stop / h))
        wind = wind or (lambda t: (0.0, 0.0, 0.0))
        ref_offset = ref_offset or (lambda t: (0.0, 0.0, 0.0))

        P, S, E, C = self.plant, self.sensors, self.ekf, self.controller
        p = P.instantiate("plant", self.callbacks)
        s = S.instantiate("sensors", self.callbacks)
        e = E.instantiate("ekf", self.callbacks)
        c = C.instantiate("controller", self.callbacks)
        slaves = (p, s, e, c)
        wind_vr = [P.variables[f"wind_{k}"].valueReference for k in "ned"]
        offset_vr = [C.variables[f"ref_offset_{k}"].valueReference for k in "ned"]
        rec_p = [P.variables[x].valueReference for x in self.plant_outputs]
        rec_c = [C.variables[x].valueReference for x in self.controller_outputs]
        rec_ci = [C.variables[x].valueReference for x in self.controller_int_outputs]
        rec_e = [E.variables[x].valueReference for x in self.ekf_outputs]
        rec_ei = [E.variables[x].valueReference for x in self.ekf_int_outputs]
        names = (
            ["time"]
            + self.plant_outputs
            + self.controller_outputs
            + self.controller_int_outputs
            + [self.est_name(x) for x in self.ekf_outputs + self.ekf_int_outputs]
            + ["wind_n", "wind_e", "wind_d", "ref_offset_n", "ref_offset_e", "ref_offset_d"]
        )
        data = np.full((n + 1, len(names)), np.nan)
        t_ctrl = t_plant = 0.0
        k_done = -1  # the last recorded row

        def step_plant_sensors(t0: float, first_sensor_step_done: bool) -> float:
            """Plant over [t0, t0 + h) in m steps; the sensors step at every inner
            point after the first (the first is stepped by the caller). Returns the
            wall time of the plant."""
            spent = 0.0
            for j in range(m):
                tj = t0 + j * hs
                if j > 0 or not first_sensor_step_done:
                    self.plant_to_sensors.copy(p, s)
                    s.doStep(currentCommunicationPoint=tj, communicationStepSize=hs)
                p.setReal(wind_vr, list(wind(tj)))
                w0 = wall.perf_counter()
                p.doStep(currentCommunicationPoint=tj, communicationStepSize=hs)
                spent += wall.perf_counter() - w0
            return spent

        try:
            for x in slaves:
                x.setupExperiment(startTime=0.0)
                x.enterInitializationMode()
            P.set(p, self.plant_params)
            p.setReal(wind_vr, list(wind(0.0)))
            p.exitInitializationMode()
            S.set(s, self.sensors_params)
            self.plant_to_sensors.copy(p, s)
            s.exitInitializationMode()
            E.set(e, {**{n: h for n in self._jacobi_defaults}, **self.ekf_params})
            self.sensors_to_ekf.copy(s, e)
            e.exitInitializationMode()
            C.set(c, self.controller_params)
            self.ekf_to_controller.copy(e, c)
            if self.truth_to_controller:
                self.truth_to_controller.copy(p, c)
            c.setReal(offset_vr, list(ref_offset(0.0)))
            c.exitInitializationMode()

            for k in range(n + 1):
                t = k * h
                off = ref_offset(t)
                if self.ordering == "gauss-seidel":
                    # Plant outputs at t → sensors [t, t + h_s).
                    self.plant_to_sensors.copy(p, s)
                    s.doStep(currentCommunicationPoint=t, communicationStepSize=hs)
                    # Controller on the estimate of t.
                    self.ekf_to_controller.copy(e, c)
                    if self.truth_to_controller:
                        self.truth_to_controller.copy(p, c)
                    c.setReal(offset_vr, list(off))
                    w0 = wall.perf_counter()
                    c.doStep(currentCommunicationPoint=t, communicationStepSize=h)
                    t_ctrl += wall.perf_counter() - w0
                    # Estimator: measurements of t, commands for [t, t + h).
                    self.sensors_to_ekf.copy(s, e)
                    self.controller_to_ekf.copy(c, e)
                    self.controller_to_plant.copy(c, p)
                    sensors_stepped = True
                else:
                    # Every input from the outputs at t, before any unit steps.
                    y_s = self.sensors_to_ekf.get(s)
                    y_e = self.ekf_to_controller.get(e)
                    u_prev = self.controller_to_plant.get(c)
                    u_prev_e = self.controller_to_ekf.get(c)
                    self.plant_to_sensors.copy(p, s)
                    self.sensors_to_ekf.set(e, y_s)
                    self.controller_to_ekf.set(e, u_prev_e)
                    self.ekf_to_controller.set(c, y_e)
                    if self.truth_to_controller:
                        self.truth_to_controller.copy(p, c)
                    c.setReal(offset_vr, list(off))
                    self.controller_to_plant.set(p, u_prev)
                    s.doStep(currentCommunicationPoint=t, communicationStepSize=hs)
                    w0 = wall.perf_counter()
                    c.doStep(currentCommunicationPoint=t, communicationStepSize=h)
                    t_ctrl += wall.perf_counter() - w0
                    sensors_stepped = True

                # Record the truth at t, the controller's output of t, the estimate of t
                # (the estimator's outputs before its step of t).
                data[k, 0] = t
                col = 1
                for vals in (
                    p.getReal(rec_p),
                    c.getReal(rec_c),
                    c.getInteger(rec_ci) if rec_ci else [],
                    e.getReal(rec_e),
                    e.getInteger(rec_ei) if rec_ei else [],
                ):
                    data[k, col : col + len(vals)] = vals
                    col += len(vals)
                data[k, col : col + 6] = list(wind(t)) + list(off)
                k_done = k
                if k < n:
                    e.doStep(currentCommunicationPoint=t, communicationStepSize=h)
                    t_plant += step_plant_sensors(t, sensors_stepped)
            for x in slaves:
                x.terminate()
        except Exception as exc:
            # Keep what was flown: an error status mid-flight (e.g. the plant's envelope
            # check) is a result of the run, and its record up to the failing step is part of it.
            exc.partial_result = self._result(names, data[: k_done + 1], n, t_ctrl, t_plant)
            raise
        finally:
            for x in slaves:
                try:
                    x.freeInstance()
                except Exception:  # noqa: BLE001 - already failed; free what can be freed
                    pass
        return self._result(names, data, n, t_ctrl, t_plant)

    def _result(self, names: list[str], data: np.ndarray, n: int, t_ctrl: float, t_plant: float) -> RunResult:
        P, E, C = self.plant, self.ekf, self.controller
        units = {"time": "s"}
        for x in self.plant_outputs:
            units[x] = P.variables[x].unit or ""
        for x in self.controller_outputs:
            units[x] = C.variables[x].unit or ""
        for x in self.ekf_outputs:
            units[self.est_name(x)] = E.variables[x].unit or ""
        for x in ["wind_n", "wind_e", "wind_d", "ref_offset_n", "ref_offset_e", "ref_offset_d"]:
            units[x] = "m/s" if x.startswith("wind") else "m"
        signals = {x: data[:, i].copy() for i, x in enumerate(names)}
        signals.update(estimation_errors(signals))
        units.update(dict(ERRORS))
        return RunResult(
            signals=signals,
            units=units,
            plant=P.identifier,
            controller=C.identifier,
            ordering=self.ordering,
            wall_time_controller=t_ctrl,
            wall_time_plant=t_plant,
            steps=len(data),
        )


def estimation_errors(sig: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Estimation errors against the truth (the `est_*` signals against the plant's)."""

    def norm3(prefix_true: str, prefix_est: str, axes: str) -> np.ndarray:
        return np.sqrt(sum((sig[f"{prefix_est}{prefix_true}{a}"] - sig[f"{prefix_true}{a}"]) ** 2 for a in axes))

    q_t = np.column_stack([sig[f"quat_{i}"] for i in range(1, 5)])
    q_e = np.column_stack([sig[f"est_quat_{i}"] for i in range(1, 5)])
    q_t = q_t / np.linalg.norm(q_t, axis=1, keepdims=True)
    q_e = q_e / np.linalg.norm(q_e, axis=1, keepdims=True)
    dot = np.clip(np.abs(np.sum(q_t * q_e, axis=1)), 0.0, 1.0)
    return {
        "err_pos": norm3("pos_", "est_", "ned"),
        "err_vel": norm3("vel_", "est_", "ned"),
        "err_att": 2.0 * np.arccos(dot),
        "err_airspeed": sig["est_airspeed"] - sig["airspeed"],
        "err_alpha": sig["est_alpha"] - sig["alpha"],
        "err_beta": sig["est_beta"] - sig["beta"],
    }


@dataclass
class PhaseErrors:
    """Max true position error and RMS / max estimation errors in one phase."""

    phase: str
    max_position_error: float
    rms: dict[str, float]
    max: dict[str, float]


def phase_errors(result: RunResult) -> list[PhaseErrors]:
    """Per phase (controller's `phase` output): max |true position − reference|
    and the RMS and max |estimation error| of each of `ERRORS`."""
    err = pos_error(result)
    out = []
    for k, name in enumerate(PHASES):
        sel = result["phase"] == k
        if not sel.any():
            continue
        rms = {e: float(math.sqrt(np.mean(result[e][sel] ** 2))) for e, _ in ERRORS}
        mx = {e: float(np.max(np.abs(result[e][sel]))) for e, _ in ERRORS}
        out.append(PhaseErrors(name, float(err[sel].max()), rms, mx))
    return out


def format_phase_errors(result: RunResult, title: str = "") -> str:
    """A plain-text table of `phase_errors` (angles in degrees)."""
    lines = [
        title
        or f"{result.controller} with avionics ({result.ordering}): max position error {pos_error(result).max():.2f} m",
        f"  {'phase':>12} {'max |x-ref|':>11} | RMS est. error: {'pos':>6} {'vel':>6} {'att':>6} {'V':>6} {'alpha':>6} {'beta':>6}",
    ]
    for pe in phase_errors(result):
        r = pe.rms
        lines.append(
            f"  {pe.phase:>12} {pe.max_position_error:9.2f} m |                 "
            f"{r['err_pos']:6.2f} {r['err_vel']:6.2f} {math.degrees(r['err_att']):5.2f}° "
            f"{r['err_airspeed']:6.2f} {math.degrees(r['err_alpha']):5.2f}° {math.degrees(r['err_beta']):5.2f}°"
        )
    return "\n".join(lines)


def fly_with_avionics(
    fmus: Mapping[str, Fmu],
    controller: str,
    ordering: str = "gauss-seidel",
    plant_step: float | None = None,
    sensors_params: Mapping[str, float | int | bool] | None = None,
    ekf_params: Mapping[str, float | int | bool] | None = None,
    controller_params: Mapping[str, float] | None = None,
    plant_params: Mapping[str, float] | None = None,
    **run_kw,
) -> RunResult:
    """One run of `controller` (a modelIdentifier) with avionics in the loop; `fmus`
    maps modelIdentifiers to `Fmu`s (tailsitter_plant, _sensors, _ekf, controller)."""
    loop = AvionicsLoop(
        fmus["tailsitter_plant"],
        fmus["tailsitter_sensors"],
        fmus["tailsitter_ekf"],
        fmus[controller],
        plant_params=plant_params,
        sensors_params=sensors_params,
        ekf_params=ekf_params,
        controller_params=controller_params,
        ordering=ordering,
        plant_step=plant_step,
    )
    return loop.run(**run_kw)


def avionics_section(
    dist,
    keys: list[str],
    missions: Mapping[str, Mapping[str, float]],
    perfect: Mapping[tuple[str, str], RunResult],
    theta_trim: float,
    ordering: str = "gauss-seidel",
    out=None,
) -> list[str]:
    """Markdown section of the comparison report (`tailsim.compare`): each controller
    (`keys`: "lqr", "tsd") flies each mission (name → controller parameters) with
    avionics in the loop; its max true position error per phase beside the run on the
    perfect state (`perfect[(mission, key)]`), and the estimation errors per phase.
    CSVs of the avionics runs go to `out`/csv when `out` is given."""
    import pathlib

    from .metrics import mission_check

    dist = pathlib.Path(dist)
    ids = ["tailsitter_plant", "tailsitter_sensors", "tailsitter_ekf"] + [f"tailsitter_{k}" for k in keys]
    fmus = {i: Fmu(dist / f"{i}.fmu") for i in ids}
    md = [
        "",
        "## Avionics in the loop",
        "",
        f"The controllers fly on the estimates of `tailsitter_ekf`, fed by `tailsitter_sensors` "
        f"(thesis Table D.1 noise, 8 Hz Butterworth on the analogue channels, GPS 4 Hz), {ordering} "
        "(tailsim.avionics). Position error: the TRUE position against the reference; it includes "
        "the estimation error of the displacement since the start (the estimator navigates "
        "relative to the start, its estimate of the start refined by every GPS fix).",
    ]
    try:
        for m, params in missions.items():
            runs: dict[str, RunResult | str] = {}
            for k in keys:
                try:
                    r = fly_with_avionics(
                        fmus, f"tailsitter_{k}", ordering=ordering, controller_params=dict(params),
                        stop_time=sum(float(params[d]) for d in ("t_vertical_1", "t_transition_1", "t_level",
                                                                  "t_transition_2", "t_vertical_2")),
                    )
                    runs[k] = r
                    if out is not None:
                        r.write_csv(pathlib.Path(out) / "csv" / f"{k}_{m}_mission_avionics.csv")
                except Exception as e:  # noqa: BLE001 - a failed run is a result
                    runs[k] = f"failed: {e}"[:80]
            header = ["quantity"] + [f"{k.upper()} {w}" for k in keys for w in ("perfect state", "avionics")]
            md += ["", f"### {m} mission: perfect state vs avionics", "", "| " + " | ".join(header) + " |",
                   "|" + "---|" * len(header)]

            def cell(run, f):
                if isinstance(run, str):
                    return run
                if run is None:
                    return "–"
                return f(run)

            def completed(r):
                mc = mission_check(r, {**params}, theta_trim)
                return "yes" if mc.passed() else "no: " + "; ".join(mc.failures())[:60]

            rows = [("mission criteria met", completed)]
            for i, ph in enumerate(PHASES):
                rows.append((
                    f"max position error, {ph} [m]",
                    lambda r, i=i: f"{float(np.max(pos_error(r)[r['phase'] == i], initial=0.0)):.2f}",
                ))
            for label, f in rows:
                vals = []
                for k in keys:
                    vals += [cell(perfect.get((m, k)), f), cell(runs[k], f)]
                md.append(f"| {label} | " + " | ".join(vals) + " |")
            for k in keys:
                r = runs[k]
                if isinstance(r, str):
                    continue
                md += ["", f"Estimation errors, {k.upper()} {m} mission (RMS per phase; α, β weakly observable "
                       "in vertical flight):", "",
                       "| phase | position [m] | velocity [m/s] | attitude [deg] | airspeed [m/s] | α [deg] | β [deg] |",
                       "|---|---|---|---|---|---|---|"]
                for pe in phase_errors(r):
                    q = pe.rms
                    md.append(
                        f"| {pe.phase} | {q['err_pos']:.2f} | {q['err_vel']:.2f} | {math.degrees(q['err_att']):.2f} | "
                        f"{q['err_airspeed']:.2f} | {math.degrees(q['err_alpha']):.2f} | {math.degrees(q['err_beta']):.2f} |"
                    )
    finally:
        for f in fmus.values():
            f.cleanup()
    return md


__all__ = [
    "AvionicsLoop",
    "avionics_section",
    "ERRORS",
    "PHASES",
    "PhaseErrors",
    "SHARED_PARAMETERS",
    "estimation_errors",
    "fly_with_avionics",
    "format_phase_errors",
    "phase_errors",
]
