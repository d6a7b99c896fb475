"""The PX4 controller FMU (tailsitter_px4) in the closed loop under fmpy: plant + controller
wired by port name, Gauss-Seidel and Jacobi, the default and fast missions and a
multicopter position step; it swaps in for the LQR and TSD with the same ports and mission
parameters. Bounds are the native closed loop's measured figures with a margin
(tests/missions/tests/px4_closed_loop.rs)."""

from __future__ import annotations

import math
import pathlib

import numpy as np
import pytest

from tailsim import ClosedLoop, controllers, step
from tailsim.masters import pos_error, settling_time
from tailsim.metrics import mission_check

ROOT = pathlib.Path(__file__).resolve().parents[1]
MISSION = ["t_vertical_1", "t_transition_1", "t_level", "t_transition_2", "t_vertical_2", "v_level"]


def fly(fmus, **kw):
    run_kw = {k: kw.pop(k) for k in ("stop_time", "ref_offset") if k in kw}
    return ClosedLoop(fmus["tailsitter_plant"], fmus["tailsitter_px4"], **kw).run(**run_kw)


def test_discovered_as_a_controller():
    assert "tailsitter_px4" in controllers.MODEL_IDS and controllers.NAMES["px4"] == "tailsitter_px4"


def test_same_ports_and_mission_as_the_thesis_controllers(fmus):
    shared = {"input", "output"}

    def ports(f):
        return {(v.name, v.causality, v.type, v.unit) for v in f.md.modelVariables if v.causality in shared}

    px4 = fmus["tailsitter_px4"]
    for other in ("tailsitter_lqr", "tailsitter_tsd"):
        assert ports(px4) == ports(fmus[other])
        for name in [*MISSION, "v_vertical", "sample_time"]:
            assert px4.variables[name].start == fmus[other].variables[name].start, name
    # PX4's own parameter names.
    px4_names = ("MC_ROLL_P", "MC_ROLLRATE_P", "MPC_XY_P", "FW_PR_P", "FW_T_ALT_TC", "VT_F_TRANS_DUR", "VT_B_TRANS_DUR")
    for name in px4_names:
        assert px4.variables[name].causality == "parameter", name


@pytest.mark.parametrize("ordering", ["gauss-seidel", "jacobi"])
def test_default_mission(fmus, ordering, level_trim_theta):
    result = fly(fmus, ordering=ordering)
    err = pos_error(result)
    print(f"\nPX4 default mission ({ordering}): max position error {err.max():.2f} m")
    for name, values in result.signals.items():
        assert np.all(np.isfinite(values)), f"{name} not finite"
    check = mission_check(result, fmus["tailsitter_px4"].starts(MISSION), level_trim_theta)
    assert check.passed(), check.failures()
    assert result["phase"][-1] == 4
    assert abs(result["theta"][-1] - math.pi / 2) < math.radians(1.0)
    # On the reference in the first vertical phase; the profile's climb through the back
    # transition is not flown by PX4's method (native: 103 m at the end).
    assert err[result["phase"] == 0].max() < 0.05
    assert err.max() < 110.0


def test_fast_mission(fmus, level_trim_theta):
    """T1 = 3 s, T2 = 4 s: PX4's ramps fly it and end upright; TECS leaves the level airspeed
    1.3 m/s short in the criteria's window (the 1 m/s criterion is not met)."""
    result = fly(fmus, controller_params={"t_transition_1": 3.0, "t_transition_2": 4.0})
    for name, values in result.signals.items():
        assert np.all(np.isfinite(values)), f"{name} not finite"
    assert abs(result["theta"][-1] - math.pi / 2) < math.radians(4.0)
    mission = {**fmus["tailsitter_px4"].starts(MISSION), "t_transition_1": 3.0, "t_transition_2": 4.0}
    check = mission_check(result, mission, level_trim_theta)
    assert check.level_airspeed_error < 1.5 and check.level_pitch_error < math.radians(3.0)
    assert pos_error(result).max() < 32.0


def test_vertical_position_step_settles(fmus):
    t_step = 2.0
    result = fly(
        fmus,
        controller_params={"t_vertical_1": 30.0},
        stop_time=15.0,
        ref_offset=step(t_step, (5.0, 0.0, 0.0)),
    )
    err = pos_error(result)
    ts = settling_time(result.time, err, t_step + 0.02, band=0.5)
    print(f"\nPX4 vertical step north 5 m: settling {ts:.2f} s")
    assert ts < 3.0 and err[-1] < 0.2


def test_libcosim_and_its_ssp_fly_the_default_mission(fmus, level_trim_theta):
    """libcosim (a Jacobi master) flies the plain FMUs and dist/tailsitter_px4.ssp alike, and
    agrees with fmpy's Jacobi master up to the rounding of the communication time."""
    from tailsim.masters.cosim import run_fmus, run_ssp

    dist = ROOT / "dist"
    lc = run_fmus(dist / "tailsitter_plant.fmu", dist / "tailsitter_px4.fmu")
    ssp = run_ssp(dist / "tailsitter_px4.ssp")
    for n in lc.signals:
        assert np.array_equal(ssp[n], lc[n]), n
    check = mission_check(lc, fmus["tailsitter_px4"].starts(MISSION), level_trim_theta)
    assert check.passed(), check.failures()
    assert lc["phase"][-1] == 4
    ja = fly(fmus, ordering="jacobi")
    d = max(float(np.max(np.abs(lc[f"pos_{k}"] - ja[f"pos_{k}"]))) for k in "ned")
    assert d < 1e-6, d
