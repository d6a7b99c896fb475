"""Small helpers for the fmpy tests: open a packaged FMU as FMU2Slave with a
logger that records every message (formatted by fmpy's C logger proxy)."""

from __future__ import annotations

import pathlib
from collections.abc import Callable
from ctypes import byref
from dataclasses import dataclass, field

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.logging import addLoggerProxy

from tailsim import declarations

ROOT = pathlib.Path(__file__).resolve().parent.parent
DIST = ROOT / "dist"
STATUS = ["OK", "Warning", "Discard", "Error", "Fatal", "Pending"]
#: The plant's continuous states (Model Exchange) in state order: its variables declared
#: with a derivative `der_<name>`.
PLANT_STATES = [n.removeprefix("der_") for n in declarations.VARIABLES["tailsitter_plant"] if n.startswith("der_")]
#: The plant's states but the flaps' (states of the global model only, idle elsewhere).
PLANT_STATES_BUT_FLAPS = [n for n in PLANT_STATES if "flap" not in n]


def fmu_path(model_identifier: str) -> pathlib.Path:
    path = DIST / f"{model_identifier}.fmu"
    assert path.exists(), f"{path} missing: run `cargo xtask dist` first"
    return path


@dataclass
class LogRecorder:
    """Keeps (status, category, message) of every log call."""

    messages: list[tuple[str, str, str]] = field(default_factory=list)

    def __post_init__(self):
        def log(_env, _instance, status, category, message):
            self.messages.append((STATUS[status], category.decode(), message.decode()))

        self._callback = fmi2CallbackLoggerTYPE(log)
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = self._callback
        addLoggerProxy(byref(self.callbacks))

    def errors(self) -> list[str]:
        return [m for s, _, m in self.messages if s == "Error"]

    def clear(self) -> None:
        self.messages.clear()


class Unpacked:
    """An extracted FMU: model description, name → value reference, slave factory."""

    def __init__(self, model_identifier: str, tmp: pathlib.Path):
        self.path = fmu_path(model_identifier)
        self.md = read_model_description(str(self.path))
        self.dir = extract(str(self.path), unzipdir=str(tmp / model_identifier))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.var = {v.name: v for v in self.md.modelVariables}

    def slave(self, name: str = "instance", log: LogRecorder | None = None, init: bool = True) -> FMU2Slave:
        s = FMU2Slave(
            guid=self.md.guid,
            unzipDirectory=self.dir,
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        s.instantiate(callbacks=(log.callbacks if log else None))
        if init:
            self.enter_initialization(s)
            s.exitInitializationMode()
        return s

    @staticmethod
    def enter_initialization(s: FMU2Slave) -> FMU2Slave:
        """Set up the experiment from t = 0 and enter initialization mode (parameters settable)."""
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        return s

    def initializing_slave(self, name: str = "instance", log: LogRecorder | None = None) -> FMU2Slave:
        """A slave in initialization mode: `slave` without leaving it."""
        return self.enter_initialization(self.slave(name, log, init=False))

    def get(self, slave: FMU2Slave, *names: str) -> list[float]:
        return slave.getReal([self.vr[n] for n in names])

    def set(self, slave: FMU2Slave, **values: float) -> None:
        slave.setReal([self.vr[n] for n in values], list(values.values()))


def assert_state_continues_bit_identically(
    start: Callable[[str], FMU2Slave], lead_in: Callable[[FMU2Slave], object], run_on: Callable[[FMU2Slave], list]
) -> None:
    """An FMU state taken after `lead_in` continues bit-identically: `run_on` from it gives
    the same outputs again after fmi2SetFMUstate, and in a fresh instance of `start` (a
    name: a running instance) after fmi2SerializeFMUstate / fmi2DeSerializeFMUstate."""
    s = start("state")
    lead_in(s)
    state = s.getFMUstate()
    blob = s.serializeFMUstate(state)
    reference = run_on(s)
    s.setFMUstate(state)
    assert np.array_equal(run_on(s), reference)
    other = start("state2")
    restored = other.deSerializeFMUstate(blob)
    other.setFMUstate(restored)
    assert np.array_equal(run_on(other), reference)
    other.freeFMUstate(restored)
    s.freeFMUstate(state)
    for x in (s, other):
        x.terminate()
        x.freeInstance()


def assert_refused(log: LogRecorder, call: Callable[..., object], what: str, *args, **kwargs) -> None:
    """`call(*args, **kwargs)` fails (an FMI error raised by fmpy) and `log` holds an error
    naming `what`."""
    try:
        call(*args, **kwargs)
    except Exception:
        pass
    else:
        raise AssertionError(f"{what}: the call succeeded")
    assert any(what in m for m in log.errors()), (what, log.messages)


@dataclass
class CosimRun:
    """An SSP flown under libcosim: the `plant` and `controller` slaves, their variables'
    references by name, the last values and the plant's airspeed series observed."""

    execution: object
    plant: int
    ctrl: int
    pv: dict[str, int]
    cv: dict[str, int]
    last: object
    series: object


def libcosim_fly_ssp(
    path: pathlib.Path, n_slaves: int, stop_ns: int = 35 * 10**9, observe: tuple[str, ...] = ("airspeed",)
) -> CosimRun:
    """Load `path` with libcosim's `from_ssp_file` (step size from its annotation), check it
    holds `n_slaves` components and run it to `stop_ns`, observing the series of the plant's
    Real outputs `observe`."""
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_ssp_file(str(path))
    assert execution.num_slaves() == n_slaves
    plant = execution.slave_index_from_instance_name("plant")
    ctrl = execution.slave_index_from_instance_name("controller")
    assert plant is not None and ctrl is not None
    pv = {v.name.decode(): v.reference for v in execution.slave_variables(plant)}
    cv = {v.name.decode(): v.reference for v in execution.slave_variables(ctrl)}
    last = CosimObserver.create_last_value()
    series = CosimObserver.create_time_series()
    assert execution.add_observer(last) and execution.add_observer(series)
    for name in observe:
        assert series.start_time_series(plant, pv[name], CosimVariableType.REAL)
    assert execution.simulate_until(stop_ns)
    assert execution.status().current_time == stop_ns
    return CosimRun(execution, plant, ctrl, pv, cv, last, series)
