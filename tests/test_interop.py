"""Interoperability matrix: every packaged FMU under two independent
runtimes, fmpy (its own FMI 2.0 bindings) and libcosim (libcosimpy, DNV/OSP on
the FMI Library): instantiate, initialise, step through the default
experiment, read every Real; get/set/serialize the FMU state where the master
supports it (fmpy). libcosim's result must agree with fmpy's. The third row,
the Rust `fmi` crate, is tests/rust-import/tests/interop.rs.

Run with `-s` to see the printed matrix (also written to target/interop-matrix.md)."""

from __future__ import annotations

import os

import numpy as np
import pytest
from fmpy import simulate_fmu

from fmu_util import ROOT, LogRecorder, Unpacked

ALL = ["tailsitter_plant", "tailsitter_lqr", "tailsitter_tsd"]
MODELS = [m.strip() for m in os.environ.get("TAILSITTER_FMUS", "").split(",") if m.strip()] or ALL
MATRIX: dict[tuple[str, str], str] = {}
SIM_TIME = 1.0  # s of the default experiment in each master


COLUMNS = ["fmpy simulate_fmu", "fmpy get/set/serialize state", "libcosim (libcosimpy 0.0.6)"]


def matrix_text() -> str:
    """The interoperability matrix of the cells this module's tests filled (✗: failed or not run)."""
    lines = ["| FMU | " + " | ".join(COLUMNS) + " | Rust fmi 0.8 |", "|---" * (len(COLUMNS) + 2) + "|"]
    for model in MODELS:
        cells = [MATRIX.get((model, c), "✗") for c in COLUMNS]
        lines.append(f"| {model} | " + " | ".join(cells) + " | cargo test -p fmu-import-tests |")
    return "\n".join(lines)


@pytest.fixture(scope="module", autouse=True)
def print_matrix():
    """After the module's tests, in whatever order they ran: print the matrix and
    write it to target/interop-matrix.md (each cell is asserted by its own test)."""
    yield
    text = matrix_text()
    print("\n" + text)
    (ROOT / "target").mkdir(exist_ok=True)
    (ROOT / "target" / "interop-matrix.md").write_text(text + "\n")


@pytest.fixture(scope="module", params=MODELS)
def fmu(request, tmp_path_factory) -> Unpacked:
    return Unpacked(request.param, tmp_path_factory.mktemp("interop"))


def real_vrs(fmu: Unpacked) -> list[int]:
    return [v.valueReference for v in fmu.md.modelVariables if v.type == "Real"]


def step_size(fmu: Unpacked) -> float:
    return float(fmu.md.defaultExperiment.stepSize)


def fmpy_run(fmu: Unpacked, t_end: float) -> np.ndarray:
    """FMU2Slave, hand-written master loop; every Real at t_end."""
    log = LogRecorder()
    s = fmu.slave("fmpy", log=log)
    h = step_size(fmu)
    for k in range(round(t_end / h)):
        s.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
    values = np.array(s.getReal(real_vrs(fmu)))
    s.terminate()
    s.freeInstance()
    assert not log.errors(), log.errors()
    return values


def test_fmpy_simulate_fmu(fmu):
    outputs = [v.name for v in fmu.md.modelVariables if v.causality == "output" and v.type == "Real"]
    result = simulate_fmu(str(fmu.path), fmi_type="CoSimulation", stop_time=SIM_TIME, output=outputs)
    assert result["time"][-1] == pytest.approx(SIM_TIME)
    for name in outputs:
        assert np.all(np.isfinite(result[name])), name
    MATRIX[(fmu.md.coSimulation.modelIdentifier, "fmpy simulate_fmu")] = "✓"


def test_fmpy_state_get_set_serialize(fmu):
    """Save at t1, run on, restore (directly and via bytes), run again: bit-identical."""
    s = fmu.slave("fmpy-state")
    h = step_size(fmu)
    vrs = real_vrs(fmu)
    for k in range(10):
        s.doStep(k * h, h)
    t1 = 10 * h
    state = s.getFMUstate()

    def run_on():
        out = []
        for k in range(10):
            s.doStep(t1 + k * h, h)
            out.append(s.getReal(vrs))
        return np.array(out)

    a = run_on()
    s.setFMUstate(state)
    b = run_on()
    blob = s.serializeFMUstate(state)
    restored = s.deSerializeFMUstate(blob)
    s.setFMUstate(restored)
    c = run_on()
    assert np.array_equal(a, b, equal_nan=True) and np.array_equal(a, c, equal_nan=True)
    s.freeFMUstate(restored)
    s.freeFMUstate(state)
    s.terminate()
    s.freeInstance()
    MATRIX[(fmu.md.coSimulation.modelIdentifier, "fmpy get/set/serialize state")] = f"✓ ({len(blob)} B)"


def test_libcosim_runs_and_agrees_with_fmpy(fmu):
    from libcosimpy.CosimEnums import CosimExecutionState
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    model = fmu.md.coSimulation.modelIdentifier
    h_ns = round(step_size(fmu) * 1e9)
    execution = CosimExecution.from_step_size(step_size=h_ns)
    slave = CosimLocalSlave(fmu_path=str(fmu.path), instance_name=model)
    assert slave.ptr(), "libcosim could not create the slave"  # NULL pointer: adding it would segfault
    index = execution.add_local_slave(local_slave=slave)
    assert index >= 0, f"add_local_slave returned {index}"
    observer = CosimObserver.create_last_value()
    assert execution.add_observer(observer=observer)
    assert execution.simulate_until(target_time=round(SIM_TIME * 1e9)), execution.status().error_code
    status = execution.status()
    assert status.error_code == 0 and status.state != CosimExecutionState.ERROR.value, (status.state, status.error_code)
    assert status.current_time == round(SIM_TIME * 1e9)
    vrs = real_vrs(fmu)
    values = np.array(observer.last_real_values(slave_index=index, variable_references=vrs))
    assert np.all(np.isfinite(values))
    # Same FMU, same inputs, same steps under fmpy: the same numbers.
    reference = fmpy_run(fmu, SIM_TIME)
    assert np.allclose(values, reference, rtol=1e-9, atol=1e-9), np.max(np.abs(values - reference))
    MATRIX[(model, "libcosim (libcosimpy 0.0.6)")] = "✓ (= fmpy to 1e-9)"
