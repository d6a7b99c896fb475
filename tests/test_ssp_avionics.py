"""The SSP 1.0 systems with avionics in the loop, dist/<controller>_avionics.ssp (written
by `cargo xtask ssp` / `cargo xtask dist` when the sensor and estimator FMUs are there):
plant → sensors → estimator → controller → plant and controller → estimator, every
connection explicit and by name, plus the atmosphere (plant ↔ atmosphere by name, bound
calm) when its FMU was packaged. Structure and schema under fmpy, flights under fmpy's
simulate_ssp and libcosim (both Jacobi masters: see tests/test_ssp.py for their limits);
libcosim's flight is tailsim's fmpy Jacobi master's.
"""

from __future__ import annotations

import math
import pathlib
import zipfile

import numpy as np
import pytest
from lxml import etree

from fmu_util import libcosim_fly_ssp
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
if (DIST / "tailsitter_atmosphere.fmu").exists():
    ELEMENTS["atmosphere"] = "tailsitter_atmosphere"
# Allowed connection directions (start element, end element).
FLOWS = {
    ("plant", "sensors"),
    ("sensors", "estimator"),
    ("estimator", "controller"),
    ("controller", "plant"),
    ("controller", "estimator"),
    ("plant", "atmosphere"),
    ("atmosphere", "plant"),
}


def ssp_path(controller: str) -> pathlib.Path:
    path = DIST / f"{controller}_avionics.ssp"
    assert path.exists(), f"{path} missing: run `cargo xtask dist` (or `cargo xtask ssp`) first"
    return path


def variables(fmu_bytes: bytes) -> dict[str, tuple[str, str]]:
    import io

    with zipfile.ZipFile(io.BytesIO(fmu_bytes)) as z:
        md = etree.fromstring(z.read("modelDescription.xml"))
    return {
        sv.get("name"): (sv.get("causality", "local"), sv[0].tag) for sv in md.iterfind("ModelVariables/ScalarVariable")
    }


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
    for elem in [e for e in ("estimator", "sensors", "atmosphere") if e in vars_]:
        for n, (caus, _) in vars_[elem].items():
            if caus == "input":
                assert (elem, n) in wired, (elem, n)
    assert {("plant", n) for n, (caus, _) in vars_["plant"].items() if caus == "input" and n.endswith("_cmd")} <= wired
    ekf_out = {n for n, (caus, _) in vars_["estimator"].items() if caus == "output"}
    assert {
        ("controller", n) for n, (caus, _) in vars_["controller"].items() if caus == "input" and n in ekf_out
    } <= wired
    # No controller input reads the plant directly: the controller flies the estimate.
    assert not any(c.startElement == "plant" and c.endElement == "controller" for c in ssd.system.connections)


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_libcosim_loads_and_runs_the_avionics_system(controller):
    """libcosim reads the four components, the bindings and the step, and runs to 35 s."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_ssp_file(str(ssp_path(controller)))
    assert execution.num_slaves() == len(ELEMENTS) + 1
    for name in ("plant", "sensors", "estimator", "controller"):
        assert execution.slave_index_from_instance_name(name) is not None, name
    assert execution.simulate_until(35 * 10**9)
    assert execution.status().current_time == 35 * 10**9


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_fmpy_simulate_ssp_flies_the_avionics_system(controller):
    """fmpy 0.3.32's simulate_ssp starts every connector at 0.0, so in the first step the
    sensors get an all-zero true state (a zero quaternion). The sensors take that, before
    any plant sample, as "no plant sample yet" (outputs of the start held, a logged warning;
    `SensorModel::step_or_hold`), so the chain starts; the estimator's `measurement_latency`
    and `prediction_lead` come from the SSD's bindings (one step each: a Jacobi master)."""
    from fmpy.ssp.simulation import simulate_ssp

    from test_ssp import fmpy_parameter_set

    path = ssp_path(controller)
    r = simulate_ssp(str(path), stop_time=35.0, step_size=0.02, parameter_set=fmpy_parameter_set(path))
    assert len(r) in (1750, 1751)  # time advanced by repeated addition (tests/test_ssp.py)
    for name in r.dtype.names:
        assert np.all(np.isfinite(r[name])), f"{name} not finite"
    t_end = r["time"] + 0.02  # row k holds the values at the end of its step
    window = level_window(t_end, MISSION)
    level_error = float(np.max(np.abs(r["plant.airspeed"][window] - MISSION["v_level"])))
    final_pitch = abs(math.degrees(r["plant.theta"][-1]) - 90.0)
    print(
        f"\n{controller} avionics under fmpy simulate_ssp: level airspeed error {level_error:.3f} m/s, "
        f"final pitch {final_pitch:.2f} deg, max pos_error {r['controller.pos_error'].max():.2f} m"
    )
    assert r["controller.phase"][-1] == 4
    assert final_pitch <= CRITERIA["final_pitch_error_max"]
    assert level_error <= CRITERIA["level_airspeed_error_max"]


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_libcosim_flies_the_avionics_system(controller):
    """libcosim (Jacobi, 0.02 s): both controllers fly the default mission on the estimates,
    on the plant's default (global) aerodynamics. Formerly the LQR lost it here (final pitch
    72–104° off): the estimator predicted with the thesis's linear aerodynamics while the
    LQR's back transition runs the plant's wing to α ≈ 50°; its `aero_model` now defaults to
    the plant's (global)."""
    run = libcosim_fly_ssp(ssp_path(controller), len(ELEMENTS) + 1)
    plant, ctrl, pv, cv, last, series = run.plant, run.ctrl, run.pv, run.cv, run.last, run.series
    theta, airspeed = last.last_real_values(plant, [pv["theta"], pv["airspeed"]])
    final_pitch = abs(math.degrees(theta) - 90.0)
    times, _, speeds = series.time_series_real_samples(plant, pv["airspeed"], from_step=1, sample_count=1750)
    t, v = np.array(times) / 1e9, np.array(speeds)
    window = level_window(t, MISSION)
    level_error = float(np.max(np.abs(v[window] - MISSION["v_level"])))
    print(
        f"\n{controller} avionics under libcosim: level airspeed error {level_error:.3f} m/s, final pitch "
        f"{final_pitch:.2f} deg"
    )
    assert last.last_integer_values(ctrl, [cv["phase"]]) == [4]
    assert final_pitch <= CRITERIA["final_pitch_error_max"]
    assert level_error <= CRITERIA["level_airspeed_error_max"]
    assert np.all(np.isfinite(v))


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_libcosim_flies_the_avionics_system_like_the_fmpy_jacobi_master(controller):
    """libcosim initialises by passing the connections' values round (controller → estimator
    → controller included), tailsim's master one unit after the other. The estimator's
    initial outputs depend on no command (its motor and servos start at `init_thrust`,
    `init_elevator`), so both start alike and fly the same trajectory."""
    from tailsim import Fmu
    from tailsim.masters.avionics import AvionicsLoop

    run = libcosim_fly_ssp(ssp_path(controller), len(ELEMENTS) + 1, observe=("pos_n", "pos_e", "pos_d"))
    ref = AvionicsLoop(
        Fmu(DIST / "tailsitter_plant.fmu"),
        Fmu(DIST / "tailsitter_sensors.fmu"),
        Fmu(DIST / "tailsitter_ekf.fmu"),
        Fmu(DIST / f"{controller}.fmu"),
        ordering="jacobi",
    ).run(stop_time=35.0)
    columns = []
    for k in "ned":
        times, _, values = run.series.time_series_real_samples(
            run.plant, run.pv[f"pos_{k}"], from_step=0, sample_count=len(ref.time)
        )
        columns.append(np.array(values))
    n = len(times)
    assert n >= 1750
    np.testing.assert_allclose(np.array(times) / 1e9, ref.time[:n], rtol=0, atol=1e-9)
    distance = np.sqrt(sum((c - ref[f"pos_{k}"][:n]) ** 2 for c, k in zip(columns, "ned", strict=True)))
    print(f"\n{controller} avionics: libcosim vs fmpy Jacobi {distance.max():.2e} m")
    assert distance.max() < 1e-9
