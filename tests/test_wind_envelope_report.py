"""The wind-envelope report over its axes (tailsim.reports.wind_envelope): the held table per
controller and axis, one speed × bearing table and one heat map per axis, the held-against-speed
chart; a file of one axis (no axis fields) renders as that axis."""

import json

import pytest

from tailsim.reports import wind_envelope as W

BEARINGS = [0.0, 90.0, 180.0, 270.0]
SPEEDS = [0.0, 5.0, 10.0]


def cell(controller, axis, mission, wind, speed, bearing, held, completed=None, max_error=1.0):
    configuration, state, ordering = axis
    return {
        "controller": controller,
        "configuration": configuration,
        "state": state,
        "ordering": ordering,
        "mission": mission,
        "wind": wind,
        "speed": speed,
        "bearing_deg": bearing,
        "completed": held if completed is None else completed,
        "held": held,
        "max_error": max_error,
        "failure": None,
        "landing_distance": None,
        "touchdown_speed": None,
        "landing_passed": None,
        "wall_time_s": 0.01,
    }


AXES = [("tuned", "perfect", "gauss-seidel"), ("tuned", "avionics", "jacobi"), ("thesis", "perfect", "gauss-seidel")]


def envelope():
    """Held up to a speed that falls along the axes; the thesis axis completes beyond the limit."""
    cells = []
    for n, axis in enumerate(AXES):
        for k in ("LQR", "TSD"):
            for wind in ("step", "turbulent"):
                for s in SPEEDS:
                    for b in BEARINGS:
                        held = s <= 10.0 - 5.0 * n and not (k == "LQR" and b == 90.0 and s > 0)
                        completed = held or axis[0] == "thesis"
                        cells.append(cell(k, axis, "default", wind, s, b, held, completed, 0.5 + s + n))
    return {
        "speeds": SPEEDS,
        "bearings_deg": BEARINGS,
        "step_time": 2.0,
        "held_max_error": 3.0,
        "held_max_error_avionics": 5.0,
        "turbulence_intensity": 2,
        "wall_time_s": 12.0,
        "cpu_time_s": 20.0,
        "flown": len(cells),
        "threads": 2,
        "cells": cells,
    }


def test_held_table_counts_every_controller_and_axis():
    w = envelope()
    lines = W.section({"wind_envelope": w})
    text = "\n".join(lines)
    block = text.split("### Cells held per controller and axis")[1].split("\n### ")[0]
    rows = [r for r in block.splitlines() if r.startswith("| LQR") or r.startswith("| TSD")]
    assert len(rows) == 2 * len(AXES) * 2
    row = next(r for r in rows if r.startswith("| LQR | tuned | avionics | Jacobi | default mission | step |"))
    cols = [c.strip() for c in row.strip("|").split("|")]
    # avionics Jacobi holds up to 5 m/s, never at 90° in wind.
    assert cols[6:9] == ["4/4", "3/4", "0/4"]
    assert cols[9] == "7/12"
    thesis = next(
        r for r in rows if r.startswith("| TSD | thesis | perfect state | Gauss-Seidel | default mission | turb")
    )
    # every thesis cell completes: the largest error of the completed is the 10 m/s one.
    assert thesis.endswith("| 4/12 | 12.5 |")
    assert f"{len(w['cells'])} flights" in text and "(144 flown, 7.2 flights per CPU-second)" in text
    assert "5 m with avionics" in text


def test_one_bearing_table_per_axis_mission_and_wind():
    w = envelope()
    text = "\n".join(W.section({"wind_envelope": w}))
    for axis in AXES:
        for wind in W.WINDS.values():
            title = f"### default mission, {wind} — {W.axis_label(axis)}"
            assert text.count(title) == 1, title
            block = text.split(title)[1].split("\n### ")[0]
            rows = [r for r in block.splitlines() if r.startswith("| LQR |") or r.startswith("| TSD |")]
            assert len(rows) == 2 * len(SPEEDS)
            for r in rows:
                assert len([c for c in r.strip("|").split("|")]) == 3 + len(BEARINGS)


def test_a_file_of_one_axis_renders_as_that_axis():
    w = envelope()
    w["cells"] = [
        {k: v for k, v in c.items() if k not in ("configuration", "state", "ordering")}
        for c in w["cells"]
        if (c["configuration"], c["state"], c["ordering"]) == W.DEFAULT_AXIS
    ]
    w["state"], w["ordering"] = "perfect", "gauss-seidel"
    assert W.axes(w) == [W.DEFAULT_AXIS]
    text = "\n".join(W.section({"wind_envelope": w}))
    assert "### Cells held per controller and axis" not in text
    assert "### default mission, steady wind stepping in — tuned, perfect state, Gauss-Seidel" in text


def test_one_heat_map_per_axis_and_the_held_chart(tmp_path):
    pytest.importorskip("matplotlib")
    (tmp_path / W.FILE).write_text(json.dumps(envelope()))
    paths = W.plot(tmp_path)
    names = {p.name for p in paths}
    assert names == {
        "wind_envelope.png",
        "wind_envelope_tuned_avionics_jacobi.png",
        "wind_envelope_thesis_perfect_gauss_seidel.png",
        "wind_envelope_axes.png",
    }
    assert all(p.stat().st_size > 10_000 for p in paths)
    assert W.plot(tmp_path / "empty") == []
