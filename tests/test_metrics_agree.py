"""The Python metrics and profiles agree with the Rust ones.

`tests/data/mission_metrics_rust.json` holds what the Rust closed loop
(`closed_loop::MissionCheck::of_samples`, `Wind`, `Scenario::ref_offset`)
computes on the stored trajectory `tests/data/mission_metrics_trajectory.csv`
(the LQR default mission under the fmpy master) and a time grid; the Rust test
`crates/closed-loop/tests/metrics_reference.rs` checks the file is what Rust
computes now. Here the Python side computes the same from the same files.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from fmu_util import ROOT
from tailsim.masters import EDGE_TOLERANCE, RunResult, one_minus_cosine_gust, step, wind_from
from tailsim.metrics import CRITERIA, mission_check

DATA = ROOT / "tests" / "data"


@pytest.fixture(scope="module")
def rust():
    return json.loads((DATA / "mission_metrics_rust.json").read_text())


@pytest.fixture(scope="module")
def trajectory() -> RunResult:
    path = DATA / "mission_metrics_trajectory.csv"
    names = [h.split(" ")[0] for h in path.read_text().splitlines()[0].split(",")]
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return RunResult(
        signals={n: data[:, i] for i, n in enumerate(names)}, units={}, plant="", controller="", ordering=""
    )


def test_criteria_are_read_from_the_same_file(rust):
    c = rust["criteria"]
    assert CRITERIA["level_window"] == c["level_window"]
    assert CRITERIA["level_airspeed_error_max"] == c["level_airspeed_error_max"]
    assert math.radians(CRITERIA["level_pitch_error_max"]) == pytest.approx(c["level_pitch_error_max_rad"], rel=1e-15)
    assert math.radians(CRITERIA["final_pitch_error_max"]) == pytest.approx(c["final_pitch_error_max_rad"], rel=1e-15)
    assert EDGE_TOLERANCE == c["edge_tolerance"] == CRITERIA["edge_tolerance"]


def test_mission_check_agrees_with_rust(rust, trajectory):
    inputs = rust["inputs"]
    check = mission_check(trajectory, inputs["mission"], inputs["theta_level_trim"])
    r = rust["mission_check"]
    assert check.all_finite is r["all_finite"] and check.passed() is r["passed"]
    assert check.phase_samples == r["phase_samples"]
    for name in ("level_airspeed_error", "level_pitch_error", "final_pitch_error"):
        assert getattr(check, name) == pytest.approx(r[name], rel=1e-12, abs=0.0), name
    # Rust sums the squares sequentially, numpy pairwise: the RMS agree to rounding.
    assert check.phase_max == pytest.approx(r["phase_max"], rel=1e-12, abs=0.0)
    assert check.phase_rms == pytest.approx(r["phase_rms"], rel=1e-12, abs=0.0)


def test_mission_check_sees_a_violation_like_rust(rust, trajectory):
    """With the trim pitch 6° off, both languages' criteria fail the level pitch (5°)."""
    inputs = rust["inputs"]
    check = mission_check(trajectory, inputs["mission"], inputs["theta_level_trim"] + math.radians(6.0))
    assert not check.passed()
    assert any("level pitch" in f for f in check.failures())


def test_profiles_and_step_edge_agree_with_rust(rust):
    i = rust["inputs"]
    wind_step = step(i["step"]["t_start"], tuple(i["step"]["value"]))
    gust = one_minus_cosine_gust(i["gust"]["t_start"], i["gust"]["duration"], tuple(i["gust"]["amplitude"]))
    offset = step(i["ref_offset"]["t"], tuple(i["ref_offset"]["value"]))
    switched = 0
    for p in rust["profiles"]:
        t = p["t"]
        assert list(wind_step(t)) == p["step"], t
        assert list(offset(t)) == p["ref_offset"], t
        assert list(gust(t)) == pytest.approx(p["gust"], rel=1e-14, abs=1e-14), t
        switched += p["step"] != [0.0, 0.0, 0.0]
    # The edge: 2.1 − 1e-12 and 105·0.02 count as reached, 2.1 − 1e-6 not.
    times = {p["t"]: p for p in rust["profiles"]}
    assert times[2.1 - 1e-12]["step"] == [1.0, 2.0, 3.0]
    assert times[2.1 - 1e-6]["step"] == [0.0, 0.0, 0.0]
    assert switched > 0


def test_rust_mission_defaults_are_the_declared_ones(rust):
    """The Rust reference used `MissionParams::default()`; the Python side takes the
    defaults from the declarations (start values of the controller ports)."""
    fragment = json.loads((ROOT / "modelDescription" / "fragments" / "controller_interface.json").read_text())
    declared = {v["name"]: v["start"] for v in fragment["variables"] if v.get("group") == "mission"}
    for name, value in rust["inputs"]["mission"].items():
        assert declared[name] == value, name


def test_wind_from_a_bearing_agrees_with_rust(rust):
    """`wind_from` and the steady step from a bearing (`closed_loop::wind_from`,
    `Wind::step_from`), 7 m/s from eight bearings, switched on at 2.1 s."""
    assert len(rust["winds_from"]) == 8
    for w in rust["winds_from"]:
        ours = wind_from(w["bearing"], 7.0)
        assert list(ours) == pytest.approx(w["wind"], rel=1e-15, abs=1e-15)
        profile = step(2.1, ours)
        assert list(profile(2.1 - 1e-6)) == w["step_before"] == [0.0, 0.0, 0.0]
        assert list(profile(105 * 0.02)) == pytest.approx(w["step_at"], rel=1e-15, abs=1e-15)
        # Blowing *from* the bearing: the air moves away from it.
        b = w["bearing"]
        assert ours[0] * math.cos(b) + ours[1] * math.sin(b) == pytest.approx(-7.0)
