"""The verdict is read from the result files, for whichever controllers they hold: the better
controller is named only where an interval separates it, the numbers in the text are the
files' numbers, and the flown transition times are measured on the trajectory."""

from __future__ import annotations

import json
import math

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from tailsim.campaign.report import wilson_interval
from tailsim.masters import RunResult
from tailsim.metrics import flown_transitions, phase_starts
from tailsim.reports import verdict

SPEC = {"tau_aero": 1.5, "tau_mass": 1.1, "wind_max": 5.0, "gust_max": 5.0, "aero_model": 1}


def write_campaign(folder, completed: dict[tuple[str, str, str], list[bool]], rms: dict[str, float]):
    """A campaign folder: arm → completion per sample; `rms[controller]`: its RMS error (m)."""
    rows = {k: [] for k in ("sample_id", "controller", "configuration", "state_source", "completed", "rms_err")}
    for (c, conf, src), done in completed.items():
        for i, ok in enumerate(done):
            for k, v in zip(rows, (i, c, conf, src, ok, rms[c] + 0.01 * i), strict=True):
                rows[k].append(v)
    folder.mkdir(parents=True)
    pq.write_table(pa.table(rows), folder / "results.parquet")
    (folder / "campaign.json").write_text(json.dumps({"spec": SPEC}))


def test_campaign_names_the_controller_an_interval_separates(tmp_path):
    n = 40
    write_campaign(
        tmp_path / "campaign",
        {
            ("alpha", "tuned", "perfect"): [True] * n,
            ("beta", "tuned", "perfect"): [i % 2 == 0 for i in range(n)],
            # Same completion, same errors: not separated.
            ("alpha", "thesis", "perfect"): [i % 4 != 0 for i in range(n)],
            ("beta", "thesis", "perfect"): [i % 4 != 0 for i in range(n)],
            ("gamma", "tuned", "perfect"): [i % 5 != 0 for i in range(n)],
        },
        {"alpha": 1.0, "beta": 1.0, "gamma": 2.0},
    )
    found = verdict.campaign_findings(tmp_path / "campaign")
    by = {f.condition.split(", ", 1)[1]: f for f in found}
    tuned = by["tuned configuration, perfect state"]
    assert tuned.better == "alpha"
    # alpha − beta: completion +0.5 exactly (every odd sample), its bootstrap interval above 0.
    assert "ALPHA 40/40 (P = 1.00 [0.91, 1.00]" in tuned.by
    assert "BETA 20/40 (P = 0.50 [0.35, 0.65]" in tuned.by
    assert "ALPHA − BETA on the same 40 samples: completion +0.50 [+0.3" in tuned.by
    assert "GAMMA 32/40" in tuned.by
    assert by["thesis configuration, perfect state"].better is None
    md = "\n".join(verdict.markdown(found))
    assert "| not separated |" in md and "ALPHA is better in 1 of the 2 conditions" in md


def test_campaign_with_one_controller_gives_no_finding(tmp_path):
    write_campaign(tmp_path / "c", {("alpha", "tuned", "perfect"): [True] * 5}, {"alpha": 1.0})
    assert verdict.campaign_findings(tmp_path / "c") == []
    assert verdict.campaign_findings(tmp_path / "missing") == []


def test_nominal_missions_report_what_was_flown(tmp_path):
    def run(k, err, ok=True):
        return {
            "controller": k,
            "mission": "fast",
            "requested": [0.5, 0.5],
            "completed": ok,
            "reason": "ok" if ok else "level airspeed error",
            "max_error": [0.0, err, 0.1, 0.2, 0.1],
            "flown_transition": [2.4, 4.9],
        }

    path = tmp_path / "metrics.json"
    path.write_text(json.dumps({"a_fast": run("a", 0.3), "b_fast": run("b", 0.2, ok=False)}))
    (f,) = verdict.nominal_findings(path)
    assert f.better == "a"  # the one that completed, though its error is larger
    assert "requested 0.5 / 0.5 s" in f.condition and "transitions flown in 2.4 / 4.9 s" in f.by
    assert "B not completed (level airspeed error)" in f.by


def test_wind_envelope_counts_cells_held(tmp_path):
    cells = []
    for k, held_up_to in (("x", 4.0), ("y", 2.0)):
        for s in (0.0, 2.0, 4.0):
            for b in (0.0, 180.0):
                ok = s <= held_up_to
                cells.append(
                    {
                        "mission": "default",
                        "wind": "step",
                        "controller": k,
                        "speed": s,
                        "bearing_deg": b,
                        "held": ok,
                        "completed": ok,
                    }
                )
    path = tmp_path / "wind_envelope.json"
    path.write_text(json.dumps({"cells": cells}))
    (f,) = verdict.wind_findings(path)
    assert f.better == "x"
    assert "X holds 6/6 cells, held at every bearing up to 4 m/s" in f.by
    assert "Y holds 4/6 cells, held at every bearing up to 2 m/s" in f.by


def test_side_by_side_puts_every_controller_in_its_column(tmp_path):
    """The three-way table: one column per controller, the campaign's completion with its
    Wilson interval, – for a controller not flown under a condition (no thesis configuration)."""
    n = 20
    write_campaign(
        tmp_path / "campaign",
        {
            ("lqr", "tuned", "perfect"): [True] * n,
            ("tsd", "tuned", "perfect"): [i % 2 == 0 for i in range(n)],
            ("px4", "tuned", "perfect"): [i % 4 != 0 for i in range(n)],
            ("lqr", "thesis", "perfect"): [True] * n,
            ("tsd", "thesis", "perfect"): [i % 2 == 0 for i in range(n)],
        },
        {"lqr": 1.0, "tsd": 1.0, "px4": 2.0},
    )
    found = verdict.campaign_findings(tmp_path / "campaign")
    md = verdict.side_by_side(found)
    assert md[3] == "| condition | LQR | TSD | PX4 | better |"
    rows = {r.split(" | ")[0].lstrip("| "): r for r in md[5:]}
    tuned = rows["tuned configuration, uncertain plants, perfect state"]
    lo, hi = wilson_interval(15, n)
    assert f"P(complete) 0.750 [{lo:.3f}, {hi:.3f}]" in tuned
    assert "P(complete) 1.000 [" in tuned and tuned.endswith("| LQR |")
    thesis = rows["thesis configuration, uncertain plants, perfect state"]
    assert thesis.split(" | ")[3] == "–"
    assert md[2] == "" and "\n".join(md) in "\n".join(verdict.markdown(found))


def test_collect_reads_one_run_folder_and_prints(tmp_path, capsys):
    assert verdict.collect(tmp_path) == []
    assert verdict.main([str(tmp_path)]) == 0
    assert "nothing was measured" in capsys.readouterr().out


def test_headline_table_is_generic_over_controllers():
    arm = {"runs": 100, "completed": 90, "p": 0.9, "wilson95": [0.83, 0.94], "median_completed": {"rms_err": 1.0}}
    low = {**arm, "completed": 50, "p": 0.5, "wilson95": [0.4, 0.6]}
    summary = {
        "spec": {**SPEC, "seed": 3, "mission": {"a": 10.0, "b": 25.0}},
        "arms": {"one/tuned/perfect": arm, "two/tuned/perfect": low, "three/tuned/perfect": arm},
    }
    lines = verdict.headline_table(summary)
    assert lines[0].count("P(complete)") == 3 and "THREE" in lines[0]
    # one and three are not separated from each other: no controller is named.
    assert lines[2].endswith("| not separated |")
    del summary["arms"]["three/tuned/perfect"]
    assert verdict.headline_table(summary)[2].endswith("| ONE |")


def test_flown_transitions_measure_the_flight_path():
    """γ turns from vertical to level over 2 s from the start of T1 and back over 3 s from
    the start of T2: the flown durations are measured where γ enters the 5° band for good."""
    mission = {"t_vertical_1": 2.0, "t_transition_1": 5.0, "t_level": 6.0, "t_transition_2": 5.0, "t_vertical_2": 4.0}
    s = phase_starts(mission)
    t = np.arange(0.0, s[-1] + 1e-9, 0.02)
    gamma = np.full_like(t, math.pi / 2)
    down = (t >= s[1]) & (t < s[1] + 2.0)
    gamma[down] = math.pi / 2 * (1 - (t[down] - s[1]) / 2.0)
    gamma[(t >= s[1] + 2.0) & (t < s[3])] = 0.0
    up = (t >= s[3]) & (t < s[3] + 3.0)
    gamma[up] = math.pi / 2 * (t[up] - s[3]) / 3.0
    speed = 10.0
    r = RunResult(
        signals={"time": t, "vel_n": speed * np.cos(gamma), "vel_e": 0 * t, "vel_d": -speed * np.sin(gamma)},
        units={},
        plant="p",
        controller="c",
        ordering="gauss-seidel",
    )
    first, second = flown_transitions(r, mission)
    # Linear ramps: within 5° of the target 5/90 of the ramp before its end.
    assert first == pytest.approx(2.0 * (1 - 5 / 90), abs=0.021)
    assert second == pytest.approx(3.0 * (1 - 5 / 90), abs=0.021)
    # Never settling: NaN.
    r.signals["vel_d"] = -speed * np.ones_like(t)
    r.signals["vel_n"] = 0 * t
    assert math.isnan(flown_transitions(r, mission)[0])


def test_cli_prints_the_verdict_of_a_run_folder(tmp_path, capsys):
    """What `scripts/main.sh` prints at its end: one sentence, one line per condition."""
    write_campaign(
        tmp_path / "campaign",
        {("one", "tuned", "perfect"): [True] * 30, ("two", "tuned", "perfect"): [i % 3 == 0 for i in range(30)]},
        {"one": 0.5, "two": 2.0},
    )
    assert verdict.main([str(tmp_path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert (
        lines[0]
        == "Verdict: ONE is better in 1 of the 1 conditions (tuned configuration, uncertain plants, perfect state)."
    )
    assert lines[1].startswith(
        "- uncertain plants in wind and gusts (30 samples), tuned configuration, perfect state: ONE."
    )
    assert "`" not in "\n".join(lines) and "**" not in "\n".join(lines)


def test_the_headline_caption_names_the_turbulence_and_the_completion_criterion():
    spec = {"tau_aero": 1.5, "tau_mass": 1.1, "wind_max": 10.0, "gust_max": 5.0, "aero_model": 1}
    plain = verdict._conditions_text(spec)
    assert "turbulence" not in plain and "completed" not in plain
    text = verdict._conditions_text({**spec, "turbulence_max": 2, "error_limit_m": 5.0})
    assert "Dryden turbulence up to moderate" in text
    assert "within 5 m of the controller's reference" in text
    # the documented full run records both, and the README's caption says them
    root = verdict.ROOT
    full = json.loads((root / "docs" / "campaign_full_run.json").read_text())
    assert full["spec"]["error_limit_m"] == 5.0 and full["spec"]["turbulence_max"] == 2
    assert "completed = flown to the end within 5 m" in (root / "README.md").read_text()
