"""The SSP 1.0 systems with avionics in the loop, dist/<controller>_avionics.ssp (written
by `cargo xtask ssp` / `cargo xtask dist` when the sensor and estimator FMUs are there):
plant → sensors → estimator → controller → plant and controller → estimator, every
connection explicit and by name. Structure and schema under fmpy, flights under fmpy's
simulate_ssp and libcosim (both Jacobi masters: see tests/test_ssp.py for their limits).
"""

from __future__ import annotations

import math
import pathlib
import zipfile

import numpy as np
import pytest
from lxml import etree
from tailsim.metrics import CRITERIA, declared_mission, level_window

ROOT = pathlib.Path(__file__).resolve().parent.parent
DIST = ROOT / "dist"
CONTROLLERS = ["tailsitter_lqr", "tailsitter_tsd"]
MISSION = declared_mission()
ELEMENTS = {
    "plant": "tailsitter_plant",
    "sensors": "tailsitter_sensors",
    "estimator": "tailsitter_ekf",
}
# Allowed connection directions (start element, end element).
FLOWS = {
    ("plant", "sensors"),
    ("sensors", "estimator"),
    ("estimator", "controller"),
    ("controller", "plant"),
    ("controller", "estimator"),
}


def ssp_path(controller: str) -> pathlib.Path:
    path = DIST / f"{controller}_avionics.ssp"
    assert path.exists(), f"{path} missing: run `cargo xtask dist` (or `cargo xtask ssp`) first"
    return path


def variables(fmu_bytes: bytes) -> dict[str, tuple[str, str]]:
    import io

    with zipfile.ZipFile(io.BytesIO(fmu_bytes)) as z:
        md = etree.fromstring(z.read("modelDescription.xml"))
    return {sv.get("name"): (sv.get("causality", "local"), sv[0].tag) for sv in md.iterfind("ModelVariables/ScalarVariable")}


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_avionics_ssd_is_valid_and_wires_every_input_by_name(controller):
    from fmpy.ssp.ssd import read_ssd

    path = ssp_path(controller)
    ssd = read_ssd(str(path), validate=True)  # raises on schema errors
    sources = {**ELEMENTS, "controller": controller}
    comps = {c.name: c for c in ssd.system.elements}
    assert {n: c.source for n, c in comps.items()} == {n: f"resources/{s}.fmu" for n, s in sources.items()}
    with zipfile.ZipFile(path) as z:
        for s in sources.values():
            assert z.read(f"resources/{s}.fmu") == (DIST / f"{s}.fmu").read_bytes(), f"stale {s}.fmu in {path.name}"
        vars_ = {n: variables(z.read(f"resources/{s}.fmu")) for n, s in sources.items()}
    wired = set()
    for c in ssd.system.connections:
        assert c.startConnector == c.endConnector
        assert (c.startElement, c.endElement) in FLOWS, (c.startElement, c.endElement)
        src, dst = vars_[c.startElement][c.startConnector], vars_[c.endElement][c.endConnector]
        assert src[0] == "output" and dst[0] == "input" and src[1] == dst[1], c.startConnector
        wired.add((c.endElement, c.endConnector))
    # Every estimator input (measurements and commands), every sensor input, every plant
    # command and every controller input the estimator provides is driven.
    for elem in ("estimator", "sensors"):
        for n, (caus, _) in vars_[elem].items():
            if caus == "input":
                assert (elem, n) in wired, (elem, n)
    assert {("plant", n) for n, (caus, _) in vars_["plant"].items() if caus == "input" and n.endswith("_cmd")} <= wired
    ekf_out = {n for n, (caus, _) in vars_["estimator"].items() if caus == "output"}
    assert {("controller", n) for n, (caus, _) in vars_["controller"].items() if caus == "input" and n in ekf_out} <= wired
    # No controller input reads the plant directly: the controller flies the estimate.
    assert not any(c.startElement == "plant" and c.endElement == "controller" for c in ssd.system.connections)


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_libcosim_loads_and_runs_the_avionics_system(controller):
    """libcosim reads the four components, the bindings and the step, and runs to 35 s."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_ssp_file(str(ssp_path(controller)))
    assert execution.num_slaves() == 4
    for name in ("plant", "sensors", "estimator", "controller"):
        assert execution.slave_index_from_instance_name(name) is not None, name
    assert execution.simulate_until(35 * 10**9)
    assert execution.status().current_time == 35 * 10**9


@pytest.mark.xfail(
    strict=True,
    reason="fmpy 0.3.32 simulate_ssp starts every connector at 0.0: the sensors get a zero "
    "quaternion in the first step and refuse it (fmi2Error 'attitude quaternion has norm 0'); "
    "a master must initialise the chain in order (tailsim.avionics does)",
)
def test_fmpy_simulate_ssp_runs_the_avionics_system():
    from fmpy.ssp.simulation import simulate_ssp

    from test_ssp import fmpy_parameter_set

    path = ssp_path("tailsitter_lqr")
    r = simulate_ssp(str(path), stop_time=1.0, step_size=0.02, parameter_set=fmpy_parameter_set(path))
    assert len(r) >= 50


@pytest.mark.xfail(
    strict=True,
    reason="under libcosim the LQR on the estimates does not complete the default mission "
    "(airspeed 25 m/s off in level flight, final pitch 72 deg off with the plant's default "
    "global aerodynamics; not investigated: the fmpy chain flies it, Jacobi included)",
)
@pytest.mark.parametrize("controller", ["tailsitter_lqr"])
def test_libcosim_flies_the_lqr_avionics_system(controller):
    """libcosim (Jacobi, 0.02 s): the LQR flies the default mission on the estimates. (The
    TSD does not under a Jacobi master: python/tailsim/avionics.py, known limits.)"""
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_ssp_file(str(ssp_path(controller)))
    assert execution.num_slaves() == 4
    plant = execution.slave_index_from_instance_name("plant")
    ctrl = execution.slave_index_from_instance_name("controller")
    pv = {v.name.decode(): v.reference for v in execution.slave_variables(plant)}
    cv = {v.name.decode(): v.reference for v in execution.slave_variables(ctrl)}
    last = CosimObserver.create_last_value()
    series = CosimObserver.create_time_series()
    assert execution.add_observer(last) and execution.add_observer(series)
    assert series.start_time_series(plant, pv["airspeed"], CosimVariableType.REAL)
    assert execution.simulate_until(35 * 10**9)
    assert execution.status().current_time == 35 * 10**9
    theta, airspeed = last.last_real_values(plant, [pv["theta"], pv["airspeed"]])
    final_pitch = abs(math.degrees(theta) - 90.0)
    times, _, speeds = series.time_series_real_samples(plant, pv["airspeed"], from_step=1, sample_count=1750)
    t, v = np.array(times) / 1e9, np.array(speeds)
    window = level_window(t, MISSION)
    level_error = float(np.max(np.abs(v[window] - MISSION["v_level"])))
    print(f"\n{controller} avionics under libcosim: level airspeed error {level_error:.3f} m/s, final pitch {final_pitch:.2f} deg")
    assert last.last_integer_values(ctrl, [cv["phase"]]) == [4]
    assert final_pitch <= CRITERIA["final_pitch_error_max"]
    assert level_error <= CRITERIA["level_airspeed_error_max"]
    assert np.all(np.isfinite(v))
