"""Issue 16, take-off and landing through the packaged FMUs: the fmpy master flies the
take-off-to-landing mission with the plant at rest on the gear (`initial_condition = 2`) and
the controllers' take-off and landing mission parameters, and so does fmpy's SSP simulation
of the packaged systems with those values in place of the SSD's bindings. Touchdown
criteria of the issue: vertical speed < 0.5 m/s, within 0.5 m of the target, upright, no
bounce."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fmu_util import DIST
from tailsim import ClosedLoop
from tailsim.reports.takeoff import MISSION, PLANT, touchdown

#: Long enough for the mission, the approach and the 2 m/s descent from ≈ 230 m (s).
STOP = 190.0


def check(td: dict, what: str) -> None:
    print(f"\n{what}: {td}")
    assert td["lifted_off"] and td["touched_down"], what
    assert MISSION["takeoff_spinup_time"] < td["liftoff_time"] < MISSION["takeoff_spinup_time"] + 1.0, what
    assert 0.0 < td["touchdown_speed"] < 0.5, what
    assert td["miss_touchdown"] < 0.5 and td["miss_final"] < 0.5, what
    assert td["tilt_touchdown_deg"] < 10.0 and td["tilt_final_deg"] < 10.0, what
    assert not td["bounced"], what
    assert td["landed"], what


@pytest.mark.parametrize(
    "controller,ordering",
    [("tailsitter_lqr", "gauss-seidel"), ("tailsitter_tsd", "jacobi")],
)
def test_master_flies_take_off_to_landing(fmus, controller, ordering):
    r = ClosedLoop(
        fmus["tailsitter_plant"], fmus[controller], plant_params=PLANT, controller_params=MISSION, ordering=ordering
    ).run(stop_time=STOP)
    td = touchdown(r)
    check(td, f"{controller} {ordering}")
    # At rest on the gear at the end: thrust cut, the CG back at its take-off height.
    assert r["thrust_cmd"][-1] == pytest.approx(0.0, abs=1e-9)
    assert td["final_pos_d"] == pytest.approx(r["pos_d"][0], abs=0.01)
    # Every phase in order: ground, take-off, the mission, approach, descent, flare, landed.
    phases = r["phase"].astype(int)
    order = [int(p) for i, p in enumerate(phases) if i == 0 or p != phases[i - 1]]
    assert order == [5, 6, 0, 1, 2, 3, 4, 7, 8, 9, 10]


def test_defaults_keep_the_thesis_mission(fmus):
    """Without the take-off and landing parameters the controllers fly today's mission: the
    phase output never leaves 0…4 and the plant starts in the climb trim."""
    r = ClosedLoop(fmus["tailsitter_plant"], fmus["tailsitter_tsd"]).run(stop_time=40.0)
    assert set(np.unique(r["phase"]).astype(int)) == {0, 1, 2, 3, 4}
    assert r["vel_d"][0] == pytest.approx(-3.0, abs=1e-9)


def test_ssp_flies_take_off_to_landing():
    from fmpy.ssp.simulation import simulate_ssp
    from fmpy.ssp.ssd import ParameterSet, read_ssd

    path = DIST / "tailsitter_tsd.ssp"
    if not path.exists():
        pytest.skip("dist/tailsitter_tsd.ssp not packaged (cargo xtask dist)")
    ssd = read_ssd(str(path))
    params, seen = [], set()
    for comp in ssd.system.elements:
        for b in comp.parameterBindings:
            for ps in b.parameterValues:
                for p in ps.parameters:
                    name = p.name
                    if comp.name == "plant" and name in PLANT:
                        p.value = str(PLANT[name])
                    if comp.name == "controller" and name in MISSION:
                        p.value = str(MISSION[name])
                        seen.add(name)
                    p.name = f"{comp.name}.{name}"
                    params.append(p)
    assert seen == set(MISSION), "the SSD binds every take-off and landing parameter"
    r = simulate_ssp(
        str(path), stop_time=STOP, step_size=0.02, parameter_set=ParameterSet(name="tl", parameters=params)
    )
    contact = r["plant.ground_contact_points"]
    assert contact[0] > 0, "starts on the gear"
    phases = r["controller.phase"]
    assert phases[-1] == 10, "landed"
    k = np.flatnonzero((contact > 0) & (np.arange(contact.size) > np.flatnonzero(contact == 0)[0]))[0]
    speed = max(r["plant.touchdown_speed"][-1], r["plant.vel_d"][k - 1])
    miss = math.hypot(r["plant.pos_n"][-1] - MISSION["landing_target_n"], r["plant.pos_e"][-1])
    print(f"\nSSP TSD: touchdown {speed:.3f} m/s, miss {miss:.3f} m")
    assert 0.0 < speed < 0.5
    assert miss < 0.5
    assert abs(math.degrees(r["plant.theta"][-1]) - 90.0) < 10.0
    assert np.all(contact[k:] > 0), "no bounce"


def test_report_section_and_plot_from_the_campaign_data(tmp_path):
    """The analysis report renders the `takeoff_landing` key of report.json (fixture of a
    tiny campaign): the table per flight, the per-phase errors and the plot."""
    import json
    import shutil

    from fmu_util import ROOT
    from tailsim.reports import analysis as analysis_report
    from tailsim.reports import takeoff as report_takeoff

    data = ROOT / "tests" / "data" / "analysis"
    for f in data.iterdir():
        shutil.copy(f, tmp_path / f.name)
    d = json.loads((data / "report.json").read_text())
    lines = report_takeoff.section(d)
    assert "## Take-off and landing" in lines
    rows = [x for x in lines if x.startswith("| LQR |") or x.startswith("| TSD |")]
    # One row per flight in each of the two tables.
    assert len(rows) == 2 * len(d["takeoff_landing"]["flights"]) == 8
    for f in d["takeoff_landing"]["flights"]:
        assert f["passed"] and 0.0 < f["touchdown_speed"] < 0.5
        assert any(f"{f['touchdown_speed']:.3f}" in x for x in rows)
    assert report_takeoff.section({}) == []
    analysis_report.write(tmp_path)
    assert (tmp_path / "takeoff_landing.png").stat().st_size > 10_000
    text = (tmp_path / "report.md").read_text()
    assert "## Take-off and landing" in text and "takeoff_landing.png" in text
