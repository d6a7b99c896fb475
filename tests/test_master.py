"""The fmpy master (python/tailsim): wiring by name, parameter overrides,
wind, reference steps, CSV output, and the comparison report's numbers
against its own CSVs."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from tailsim import ClosedLoop, one_minus_cosine_gust, step
from tailsim.masters import pos_error, settling_time
from tailsim.reports.compare import main as compare_main


def test_wiring_is_by_name(fmus):
    loop = ClosedLoop(fmus["tailsitter_plant"], fmus["tailsitter_lqr"])
    commands = [
        "thrust_cmd",
        "elevator_cmd",
        "aileron_cmd",
        "rudder_cmd",
        "flap_collective_cmd",
        "flap_differential_cmd",
        "vertical_flap_cmd",
    ]
    assert sorted(loop.to_plant) == sorted(commands)
    plant_outputs = set(fmus["tailsitter_plant"].names("output"))
    assert set(loop.to_controller) == plant_outputs & set(fmus["tailsitter_lqr"].names("input"))
    assert {"pos_n", "airspeed", "quat_4", "thrust"} <= set(loop.to_controller)


def test_a_controller_missing_a_command_is_refused(fmus):
    # The plant is not a controller: it drives none of the *_cmd inputs.
    with pytest.raises(ValueError, match="does not drive"):
        ClosedLoop(fmus["tailsitter_plant"], fmus["tailsitter_plant"])
    with pytest.raises(ValueError, match="ordering"):
        ClosedLoop(fmus["tailsitter_plant"], fmus["tailsitter_lqr"], ordering="random")


def test_commands_reach_the_plant(fmus):
    r = ClosedLoop(fmus["tailsitter_plant"], fmus["tailsitter_tsd"]).run(stop_time=12.0)
    # The plant's actual thrust follows the controller's command through the 0.1 s lag.
    t, cmd, thrust = r.time, r["thrust_cmd"], r["thrust"]
    lagged = np.interp(t - 0.3, t, cmd)
    steady = t > 11.0
    assert np.max(np.abs(thrust[steady] - lagged[steady])) < 2.0
    assert abs(r["elevator"][-1] - r["elevator_cmd"][-2]) < math.radians(1.0)


@pytest.mark.parametrize("controller", ["tailsitter_lqr", "tailsitter_tsd"])
def test_parameter_overrides_reach_both_fmus(fmus, controller):
    r = ClosedLoop(
        fmus["tailsitter_plant"], fmus[controller], controller_params={"v_level": 22.0, "t_level": 12.0}
    ).run(stop_time=20.0)
    level = (r.time > 15.0) & (r.time < 20.0)
    # The tuned controllers' reference (guidance::profile) reaches V_L through the
    # point-mass response after the thrust-limited front transition (overshoot ≈ 0.3 m/s
    # decaying at k_V = 1.5 /s), the thesis's within rounding: both far from the default 25.
    assert np.all(np.abs(r["ref_airspeed"][level] - 22.0) < 0.01)
    assert np.max(np.abs(r["airspeed"][level] - 22.0)) < 1.0
    # A plant parameter: a heavier aircraft starts in a climb trim with more thrust.
    heavy = ClosedLoop(fmus["tailsitter_plant"], fmus[controller], plant_params={"mass": 10.0}).run(stop_time=1.0)
    climb_drag = 0.5 * 1.225 * 3.0**2 * 0.5737 * 0.0272
    assert heavy["thrust"][0] == pytest.approx(10.0 * 9.81 + climb_drag, rel=1e-9)


def test_constant_wind_is_flown_through(fmus):
    wind = (0.0, 2.0, 0.0)
    hover_long = {"t_vertical_1": 30.0}
    # On the thesis's aerodynamics (the controller's design model): with the global model
    # (default) β = 34° here is past the sideslip stall band and TSD drifts 0.13 m/s.
    r = ClosedLoop(
        fmus["tailsitter_plant"], fmus["tailsitter_tsd"], plant_params={"aero_model": 0}, controller_params=hover_long
    ).run(stop_time=10.0, wind=lambda t: wind)
    assert np.all(r["wind_e"] == 2.0)
    # In the vertical climb the controller holds position: the air moves past at 2 m/s sideways.
    k = r.time > 8.0
    assert np.all(np.abs(r["airspeed"][k] - math.hypot(3.0, 2.0)) < 0.1)
    assert pos_error(r)[k].max() < 0.2


def test_gust_and_step_profiles():
    g = one_minus_cosine_gust(1.0, 2.0, (0.0, 0.0, 6.0))
    assert g(0.5) == (0.0, 0.0, 0.0) and g(2.0)[2] == pytest.approx(6.0) and g(1.5)[2] == pytest.approx(3.0)
    s = step(2.0, (1.0, 2.0, 3.0))
    assert s(1.99) == (0.0, 0.0, 0.0) and s(2.0) == (1.0, 2.0, 3.0)
    t = np.arange(0, 10, 0.5)
    e = np.where(t < 4.0, 2.0, 0.1)
    assert settling_time(t, e, 1.0, 0.5) == pytest.approx(3.0)
    assert settling_time(t, np.full_like(t, 2.0), 1.0, 0.5) == math.inf


def test_reference_step_moves_the_reference(fmus):
    r = ClosedLoop(fmus["tailsitter_plant"], fmus["tailsitter_lqr"], controller_params={"t_vertical_1": 20.0}).run(
        stop_time=10.0, ref_offset=step(2.0, (0.0, 5.0, 0.0))
    )
    before, after = r.time < 1.99, r.time > 2.01
    assert np.all(np.abs(r["ref_pos_e"][before]) < 1e-9) and np.all(np.abs(r["ref_pos_e"][after] - 5.0) < 1e-9)
    assert abs(r["pos_e"][-1] - 5.0) < 0.5


def test_csv_has_units_and_every_signal(fmus, tmp_path):
    r = ClosedLoop(fmus["tailsitter_plant"], fmus["tailsitter_tsd"]).run(stop_time=1.0)
    path = tmp_path / "run.csv"
    r.write_csv(path)
    header = path.read_text().splitlines()[0].split(",")
    assert header[0] == "time [s]" and "airspeed [m/s]" in header and "alpha [rad]" in header and "phase" in header
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    assert data.shape == (51, len(r.signals))
    np.testing.assert_allclose(data[:, header.index("pos_d [m]")], r["pos_d"], rtol=1e-9, atol=1e-12)


def test_report_numbers_come_from_the_csvs(tmp_path):
    out = tmp_path / "out"
    assert compare_main(["--controller", "both", "--out", str(out), "--no-steps"]) == 0
    for name in ["report.md", "report.html", "mission_default.png", "mission_fast.png", "metrics.json"]:
        assert (out / name).exists(), name
    html = (out / "report.html").read_text()
    assert "data:image/png;base64," in html and "<table>" in html
    metrics = json.loads((out / "metrics.json").read_text())
    for key in ["lqr", "tsd"]:
        path = out / "csv" / f"{key}_default_mission.csv"
        header = [h.split(" [")[0] for h in path.read_text().splitlines()[0].split(",")]
        data = np.loadtxt(path, delimiter=",", skiprows=1)
        col = {h: data[:, i] for i, h in enumerate(header)}
        err = np.sqrt(sum((col[f"pos_{a}"] - col[f"ref_pos_{a}"]) ** 2 for a in "ned"))
        m = metrics[f"{key}_default"]
        for k in range(5):
            mask = col["phase"] == k
            assert m["max_error"][k] == pytest.approx(err[mask].max(), rel=1e-6, abs=1e-9)
            assert m["rms_error"][k] == pytest.approx(math.sqrt(np.mean(err[mask] ** 2)), rel=1e-6, abs=1e-9)
        assert m["max_alpha_deg"] == pytest.approx(np.degrees(col["alpha"].max()), rel=1e-6)
        assert m["completed"] is True
        text = (out / "report.md").read_text()
        assert f"{m['max_error'][2]:.2f}" in text


def test_one_engine_a_system_wired_by_hand_flies_as_closed_loop(fmus):
    """ClosedLoop is a configuration of tailsim.masters.system.System: the same units,
    links and external inputs declared by hand fly the same trajectory bit for bit, and
    a run stopped by its monitor hands back the record flown so far."""
    from tailsim.masters import External, Link, System, Unit, wire

    plant, ctrl = fmus["tailsitter_plant"], fmus["tailsitter_tsd"]
    gust = one_minus_cosine_gust(1.0, 1.0, (2.0, 0.0, -1.0))
    offset = step(1.5, (0.0, 1.0, 0.0))
    ref = ClosedLoop(plant, ctrl).run(stop_time=3.0, wind=gust, ref_offset=offset)
    system = System(
        [
            Unit("controller", ctrl, sampler=True, record=["pos_error", "thrust_cmd", "phase"]),
            Unit("plant", plant, record=["pos_n", "alpha"]),
        ],
        [Link("plant", "controller", wire(plant, ctrl)), Link("controller", "plant", wire(ctrl, plant))],
        [
            External("plant", ("wind_n", "wind_e", "wind_d"), gust, ("wind_n", "wind_e", "wind_d")),
            External(
                "controller", ("ref_offset_n", "ref_offset_e", "ref_offset_d"), offset, ("off_n", "off_e", "off_d")
            ),
        ],
        init_order=["plant", "controller"],
    )
    r = system.run(3.0, 0.02)
    for name in ["time", "pos_error", "thrust_cmd", "phase", "pos_n", "alpha", "wind_n", "wind_d"]:
        assert np.array_equal(r[name], ref[name]), name
    assert np.array_equal(r["off_e"], ref["ref_offset_e"])

    class Stop(Exception):
        pass

    def monitor(k, t, row):
        if t >= 1.0:
            raise Stop

    with pytest.raises(Stop) as info:
        system.run(3.0, 0.02, monitor=monitor)
    partial = info.value.partial_result
    assert info.value.t == pytest.approx(1.0) and partial.time[-1] == pytest.approx(0.98)
    assert np.array_equal(partial["pos_n"], ref["pos_n"][: len(partial.time)])
