"""The closed loop under a second, independent master: libcosim (DNV/OSP, PyPI `libcosimpy`).

Two ways in, both returning the `RunResult` of `tailsim.masters` so the runs
compare sample by sample with the fmpy master:

- `run_fmus(plant_fmu, controller_fmu, ...)`: the plain FMUs as two local
  slaves, every controller input connected to the plant output of the same
  name and every controller output to the plant input of the same name
  (docs/DESIGN.md, "Ports and timing"), parameters set as initial values;
- `run_ssp(path)`: a system file `dist/<controller>.ssp` (written by
  `cargo xtask ssp`), loaded with `CosimExecution.from_ssp_file`; the mission
  parameters come from the SSP's parameter bindings.

libcosim's fixed-step algorithm steps every slave from the same time t on
the inputs transferred after the previous step, then transfers outputs to
inputs (after initialisation it transfers once more, so the plant flies the
controller's t = 0 command over the first step). The controller therefore
samples the plant outputs at t, like the reference Gauss-Seidel master, but
the plant flies the command of the previous sample: exactly the Jacobi
ordering of `ClosedLoop(..., ordering="jacobi")`.

Recording: a time-series observer samples every output after every step.
Row k of the result holds the plant outputs at t_k and the controller outputs
computed at t_k (observed by libcosim after the step, at t_k + h), the same
alignment as `tailsim.masters`; the run goes one step past the stop time to
get the controller's last sample.

libcosimpy 0.0.6 segfaults when it uses a slave that could not be created
(bad path, GUID mismatch, missing binary): `run_fmus` checks the slave
pointer and the slave index before using either.
"""

from __future__ import annotations

import pathlib
import tempfile
import time as wall
import zipfile
from collections.abc import Mapping

import numpy as np
from fmpy import read_model_description

from .fmu import RunResult

NS = 1_000_000_000


def _seconds_to_ns(t: float) -> int:
    return int(round(t * NS))


def _import_libcosim():
    from libcosimpy.CosimEnums import CosimVariableCausality, CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    return (
        CosimExecution,
        CosimObserver,
        CosimLocalSlave,
        CosimVariableType,
        CosimVariableCausality,
        (
            CosimLogLevel,
            log_output_level,
        ),
    )


def set_log_level(level: str = "error") -> None:
    """libcosim's console log level: trace, debug, info, warning, error, fatal."""
    *_, (CosimLogLevel, log_output_level) = _import_libcosim()
    log_output_level(getattr(CosimLogLevel, level.upper()))


class _Slave:
    """A slave of an execution: its index and its variables by name."""

    def __init__(self, execution, index: int, md):
        self.index = index
        self.vars = {v.name.decode(): v for v in execution.slave_variables(index)}
        self.md = md
        self.units = {v.name: (v.unit or "") for v in md.modelVariables}

    def names(self, causality) -> list[str]:
        return [n for n, v in self.vars.items() if v.causality == causality.value]


def _set_initial(execution, slave: _Slave, values: Mapping[str, float | int | bool], var_type) -> None:
    for name, value in values.items():
        if name not in slave.vars:
            raise KeyError(f"slave {slave.index} has no variable '{name}'")
        v = slave.vars[name]
        if v.type == var_type.REAL.value:
            ok = execution.real_initial_value(slave.index, v.reference, float(value))
        elif v.type == var_type.INTEGER.value:
            ok = execution.integer_initial_value(slave.index, v.reference, int(value))
        elif v.type == var_type.BOOLEAN.value:
            ok = execution.boolean_initial_value(slave.index, v.reference, bool(value))
        else:
            ok = execution.string_initial_value(slave.index, v.reference, str(value))
        if not ok:
            raise RuntimeError(f"libcosim refused the initial value {name} = {value!r}")


def _fly(execution, plant: _Slave, controller: _Slave, stop: float, h: float, params: Mapping[str, float]) -> RunResult:
    """Observe every output, simulate to stop + h, assemble a RunResult aligned like tailsim.masters."""
    _, CosimObserver, _, var_type, causality, _ = _import_libcosim()
    n = int(round(stop / h))
    observer = CosimObserver.create_time_series()
    if not execution.add_observer(observer):
        raise RuntimeError("libcosim: cannot add the time-series observer")
    real, integer = var_type.REAL.value, var_type.INTEGER.value
    plant_out = [x for x in plant.names(causality.OUTPUT) if plant.vars[x].type == real]
    ctrl_real = [x for x in controller.names(causality.OUTPUT) if controller.vars[x].type == real]
    ctrl_int = [x for x in controller.names(causality.OUTPUT) if controller.vars[x].type == integer]
    observed = [(plant, x, var_type.REAL) for x in plant_out]
    observed += [(controller, x, var_type.REAL) for x in ctrl_real]
    observed += [(controller, x, var_type.INTEGER) for x in ctrl_int]
    for slave, name, t in observed:
        if not observer.start_time_series(slave.index, slave.vars[name].reference, t):
            raise RuntimeError(f"libcosim: cannot observe {name}")
    t0 = wall.perf_counter()
    # One step past the stop time: the controller's output for t_n is observed at t_n + h.
    if not execution.simulate_until(_seconds_to_ns((n + 1) * h)):
        raise RuntimeError(f"libcosim simulation failed: {execution.status()}")
    elapsed = wall.perf_counter() - t0

    def series(slave: _Slave, name: str, t) -> np.ndarray:
        getter = observer.time_series_real_samples if t is var_type.REAL else observer.time_series_integer_samples
        ref = slave.vars[name].reference
        # libcosimpy 0.0.6 trims its answer by counting zero step numbers, which drops a sample
        # whenever step 0 is in the request: read step 0 with a 2-sample request, then from step 1.
        _, steps0, values0 = getter(slave.index, ref, from_step=0, sample_count=2)
        _, steps, values = getter(slave.index, ref, from_step=1, sample_count=n + 1)
        out = np.full(n + 2, np.nan)
        out[[int(s) for s in steps0[:1]]] = values0[:1]
        out[[int(s) for s in steps]] = values
        return out

    signals: dict[str, np.ndarray] = {"time": np.arange(n + 1) * h}
    for slave, name, t in observed:
        values = series(slave, name, t)
        # Plant rows: samples 0..n (t_k). Controller rows: samples 1..n+1 (computed at t_k).
        signals[name] = values[: n + 1] if slave is plant else values[1 : n + 2]
    for name in ("wind_n", "wind_e", "wind_d", "ref_offset_n", "ref_offset_e", "ref_offset_d"):
        signals[name] = np.full(n + 1, float(params.get(name, 0.0)))
    units = {"time": "s"}
    units.update({x: plant.units.get(x, "") for x in plant_out})
    units.update({x: controller.units.get(x, "") for x in ctrl_real})
    units.update({f"wind_{k}": "m/s" for k in "ned"})
    units.update({f"ref_offset_{k}": "m" for k in "ned"})
    result = RunResult(
        signals=signals,
        units=units,
        plant=plant.md.coSimulation.modelIdentifier,
        controller=controller.md.coSimulation.modelIdentifier,
        ordering="libcosim",
        steps=n + 1,
    )
    result.log.append(("libcosim", "info", f"simulate_until took {elapsed:.3f} s wall time"))
    return result


def run_fmus(
    plant_fmu: str | pathlib.Path,
    controller_fmu: str | pathlib.Path,
    plant_params: Mapping[str, float] | None = None,
    controller_params: Mapping[str, float] | None = None,
    stop_time: float | None = None,
    step_size: float | None = None,
    log_level: str = "error",
) -> RunResult:
    """Fly plant + controller FMUs under libcosim, wired by port name.

    Parameters and inputs in `plant_params` / `controller_params` are set as
    initial values (a constant wind or reference offset goes here too).
    Step size: `sample_time` if given, else the controller's default experiment.
    """
    CosimExecution, _, CosimLocalSlave, var_type, causality, _ = _import_libcosim()
    set_log_level(log_level)
    plant_params, controller_params = dict(plant_params or {}), dict(controller_params or {})
    plant_fmu, controller_fmu = pathlib.Path(plant_fmu).resolve(), pathlib.Path(controller_fmu).resolve()
    p_md, c_md = read_model_description(str(plant_fmu)), read_model_description(str(controller_fmu))
    h = float(step_size or controller_params.get("sample_time") or c_md.defaultExperiment.stepSize)
    stop = float(stop_time if stop_time is not None else c_md.defaultExperiment.stopTime)
    execution = CosimExecution.from_step_size(_seconds_to_ns(h))
    slaves = []  # keep the Python wrappers alive as long as the execution
    indices = []
    for path, name in ((plant_fmu, "plant"), (controller_fmu, "controller")):
        if not path.is_file():
            raise FileNotFoundError(path)
        slave = CosimLocalSlave(fmu_path=str(path), instance_name=name)
        if not slave.ptr():
            raise RuntimeError(f"libcosim could not create a slave from {path}")
        index = execution.add_local_slave(slave)
        if index < 0:
            raise RuntimeError(f"libcosim could not add the slave {name} ({path})")
        slaves.append(slave)
        indices.append(index)
    plant, controller = _Slave(execution, indices[0], p_md), _Slave(execution, indices[1], c_md)
    real = var_type.REAL.value
    links = [
        (plant, controller, x)
        for x in controller.names(causality.INPUT)
        if x in plant.names(causality.OUTPUT) and controller.vars[x].type == plant.vars[x].type == real
    ]
    links += [
        (controller, plant, x)
        for x in controller.names(causality.OUTPUT)
        if x in plant.names(causality.INPUT) and controller.vars[x].type == plant.vars[x].type == real
    ]
    undriven = [
        x for x in plant.names(causality.INPUT) if x.endswith("_cmd") and not any(link[2] == x for link in links)
    ]
    if undriven:
        raise ValueError(f"{controller_fmu.name} does not drive plant inputs {undriven}")
    for src, dst, x in links:
        rc = execution.connect_real_variables(src.index, src.vars[x].reference, dst.index, dst.vars[x].reference)
        if rc != 0:
            raise RuntimeError(f"libcosim could not connect {x} (return {rc})")
    _set_initial(execution, plant, plant_params, var_type)
    _set_initial(execution, controller, controller_params, var_type)
    result = _fly(execution, plant, controller, stop, h, {**plant_params, **controller_params})
    del slaves
    return result


def run_ssp(
    ssp: str | pathlib.Path,
    stop_time: float | None = None,
    step_size: float | None = None,
    log_level: str = "error",
) -> RunResult:
    """Fly a system file (`dist/<controller>.ssp`) under libcosim.

    The step size is the SSD's OSP FixedStepAlgorithm annotation unless
    `step_size` overrides it; the stop time defaults to the SSD's default
    experiment (35 s for the packages `cargo xtask ssp` writes).
    """
    CosimExecution, *_ = _import_libcosim()
    set_log_level(log_level)
    ssp = pathlib.Path(ssp).resolve()
    from lxml import etree

    with zipfile.ZipFile(ssp) as z, tempfile.TemporaryDirectory(prefix="tailsim-ssp-") as tmp:
        root = etree.fromstring(z.read("SystemStructure.ssd"))
        ns = {
            "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
            "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
        }
        sources = {c.get("name"): c.get("source") for c in root.iterfind(".//ssd:Component", ns)}
        mds = {}
        for name, source in sources.items():
            target = pathlib.Path(tmp) / pathlib.Path(source).name
            target.write_bytes(z.read(source))
            mds[name] = read_model_description(str(target))
        exp = root.find("ssd:DefaultExperiment", ns)
        algo = root.find(".//osp:FixedStepAlgorithm", ns)
    if step_size is None and algo is None:
        raise ValueError(f"{ssp.name} has no OSP step size annotation: pass step_size")
    h = float(step_size if step_size is not None else algo.get("baseStepSize"))
    if stop_time is None:
        if exp is None or exp.get("stopTime") is None:
            raise ValueError(f"{ssp.name} has no default stop time: pass stop_time")
        stop_time = float(exp.get("stopTime"))
    if step_size is None:
        execution = CosimExecution.from_ssp_file(str(ssp))
    else:
        execution = CosimExecution.from_ssp_file(str(ssp), step_size=_seconds_to_ns(step_size))
    index = {}
    for name in ("plant", "controller"):
        i = execution.slave_index_from_instance_name(name)
        if i is None:
            raise RuntimeError(f"{ssp.name} has no component '{name}'")
        index[name] = i
    plant = _Slave(execution, index["plant"], mds["plant"])
    controller = _Slave(execution, index["controller"], mds["controller"])
    return _fly(execution, plant, controller, float(stop_time), h, {})


__all__ = ["run_fmus", "run_ssp", "set_log_level"]
