"""Closed loop under fmpy: plant + each controller FMU wired by port name
(the acceptance of the LQR and TSD issues). Per-phase position errors are
printed (run pytest with -s to see them)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tailsim import ClosedLoop, step
from tailsim.masters import pos_error, settling_time
from tailsim.metrics import mission_check

MISSION = ["t_vertical_1", "t_transition_1", "t_level", "t_transition_2", "t_vertical_2", "v_level"]

CONTROLLERS = ["tailsitter_lqr", "tailsitter_tsd"]
PHASES = ["vertical 1", "transition 1", "level", "transition 2", "vertical 2"]


def fly(fmus, controller, **kw):
    run_kw = {k: kw.pop(k) for k in ("stop_time", "ref_offset", "wind") if k in kw}
    loop = ClosedLoop(fmus["tailsitter_plant"], fmus[controller], **kw)
    return loop.run(**run_kw)


def report(result, title):
    err = pos_error(result)
    print(f"\n{title}: max position error {err.max():.3f} m")
    for k, name in enumerate(PHASES):
        m = result["phase"] == k
        if m.any():
            print(f"  {name:>12}: max {err[m].max():.3f} m, rms {math.sqrt(np.mean(err[m] ** 2)):.3f} m")
    return err


def check_mission(result, theta_trim, controller):
    """The mission criteria (modelDescription/fragments/mission_criteria.json, the
    same check as the Rust `closed_loop::MissionCheck::passed`) on the mission the
    controller declares by default."""
    check = mission_check(result, controller.starts(MISSION), theta_trim)
    assert check.passed(), check.failures()
    assert check.level_airspeed_error > 0.0 and check.level_pitch_error > 0.0  # the window held samples
    assert result["phase"][-1] == 4


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_default_mission(fmus, controller, level_trim_theta):
    result = fly(fmus, controller)
    report(result, f"{controller} default mission (Gauss-Seidel)")
    check_mission(result, level_trim_theta, fmus[controller])
    # The phase output follows the mission timing (5/5/10/10/5 s).
    t, phase = result.time, result["phase"]
    assert np.all(phase[t < 4.99] == 0) and np.all(phase[(t > 10.01) & (t < 19.99)] == 2)


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_default_mission_jacobi(fmus, controller, level_trim_theta):
    result = fly(fmus, controller, ordering="jacobi")
    report(result, f"{controller} default mission (Jacobi)")
    check_mission(result, level_trim_theta, fmus[controller])


@pytest.mark.parametrize("controller", CONTROLLERS)
@pytest.mark.parametrize(
    "flight,offset",
    [
        ("level", (0.0, 0.0, 5.0)),  # normal to the flight path
        ("level", (0.0, 5.0, 0.0)),  # lateral
        ("vertical", (5.0, 0.0, 0.0)),  # normal (in the pitch plane)
        ("vertical", (0.0, 5.0, 0.0)),  # lateral
    ],
)
def test_position_step_settles(fmus, controller, flight, offset):
    if flight == "level":
        t_step, params = 16.0, {"t_level": 30.0}  # 6 s into level flight: the transition has settled
        stop = 34.0
    else:
        t_step, params = 2.0, {"t_vertical_1": 30.0}
        stop = 15.0
    result = fly(fmus, controller, controller_params=params, stop_time=stop, ref_offset=step(t_step, offset))
    err = pos_error(result)
    ts = settling_time(result.time, err, t_step + 0.02, band=0.5)
    print(f"\n{controller} {flight} step {offset}: settling time {ts:.2f} s, max error {err.max():.2f} m")
    assert math.isfinite(ts), "never settled to < 0.5 m"
    assert err[-1] < 0.5


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_mission_with_plant_c_m_alpha_scaled(fmus, controller, level_trim_theta):
    """The controllers keep their nominal model while the plant's C_mα is 20 % larger."""
    plant_params = {"c_m_alpha_a0": -1.6497 * 1.2, "c_m_alpha_a1": -1.6147 * 1.2}
    result = fly(fmus, controller, plant_params=plant_params)
    report(result, f"{controller} with plant C_m_alpha x 1.2")
    for name, values in result.signals.items():
        assert np.all(np.isfinite(values)), f"{name} not finite"
    assert abs(result["theta"][-1] - math.pi / 2) < math.radians(10.0)
    assert pos_error(result).max() < 20.0


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_controllers_are_interchangeable(fmus, controller):
    """Same ports and mission parameters in both controllers (docs/DESIGN.md, "Ports and timing")."""
    a, b = fmus["tailsitter_lqr"], fmus["tailsitter_tsd"]
    shared = {"input", "output"}

    def ports(f):
        return {(v.name, v.causality, v.type, v.unit) for v in f.md.modelVariables if v.causality in shared}

    assert ports(a) == ports(b)
    mission = [
        "t_vertical_1",
        "t_transition_1",
        "t_level",
        "t_transition_2",
        "t_vertical_2",
        "v_level",
        "v_vertical",
        "sample_time",
    ]
    for name in mission:
        assert a.variables[name].start == b.variables[name].start, name
    plant_inputs = set(fmus["tailsitter_plant"].names("input"))
    plant_outputs = set(fmus["tailsitter_plant"].names("output"))
    c = fmus[controller]
    for name in c.names("output"):
        assert name in plant_inputs or name in {
            "ref_pos_n",
            "ref_pos_e",
            "ref_pos_d",
            "ref_airspeed",
            "phase",
            "pos_error",
        }, name
    for name in c.names("input"):
        assert name in plant_outputs or name.startswith("ref_offset_"), name


def test_fast_mission_tsd(fmus):
    """TSD flies T1 = 3 s, T2 = 4 s with α below 20° (thesis §4.4.4)."""
    params = {"t_transition_1": 3.0, "t_transition_2": 4.0}
    # The thesis's result, on the thesis's (linear) aerodynamics: with the global model
    # (aero_model = 1) this transition stalls the wing (alpha up to about 80 deg).
    result = fly(
        fmus, "tailsitter_tsd", controller_params=params, plant_params={"aero_model": 0}, stop_time=5 + 3 + 10 + 4 + 5
    )
    report(result, "tailsitter_tsd fast mission")
    for name, values in result.signals.items():
        assert np.all(np.isfinite(values)), f"{name} not finite"
    alpha_max = np.degrees(result["alpha"].max())
    print(f"  max alpha {alpha_max:.1f} deg")
    assert alpha_max < 20.0
    assert abs(result["theta"][-1] - math.pi / 2) < math.radians(10.0)


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_design_model_is_the_plants_airframe_and_a_mismatch_flies_differently(fmus, controller):
    """Issue 15, part 1: the controller's design model (group design_airframe) carries the
    plant's airframe parameters with the same names and defaults; a design C_mα x 1.2 with
    the nominal plant flies differently from the nominal design (whose run the stored
    reference reproduces, tests/test_reference.py)."""
    plant, c = fmus["tailsitter_plant"], fmus[controller]
    shared = [n for n in plant.names("parameter") if n in c.variables]
    assert len(shared) >= 79 and "c_m_alpha_a0" in shared  # the 79 airframe parameters
    for name in shared:
        assert c.variables[name].causality == "parameter", name
        assert c.variables[name].start == plant.variables[name].start, name
    design = {n: c.start(n) * 1.2 for n in ("c_m_alpha_a0", "c_m_alpha_a1")}
    nominal = fly(fmus, controller, stop_time=15.0)
    perturbed = fly(fmus, controller, stop_time=15.0, controller_params=design)
    d = math.dist(
        [nominal[k][-1] for k in ("pos_n", "pos_e", "pos_d")],
        [perturbed[k][-1] for k in ("pos_n", "pos_e", "pos_d")],
    )
    print(f"\n{controller}: design C_m_alpha x 1.2 moves the 15 s position by {d:.4f} m")
    assert d > 1e-3
