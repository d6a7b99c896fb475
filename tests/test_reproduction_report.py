"""The "Reproduction of the thesis" section renders from `reproduction.json` and
`reproduction_wind.json` (`tests/data/analysis/`: the output of
`cargo run --release -p analysis -- reproduction --out out/analysis` and of
`python -m tailsim.reports.reproduction --wind out/c200perfect --out out/analysis` on a
200-sample campaign of both configurations), every number taken from the files."""

from __future__ import annotations

import json

from fmu_util import ROOT
from tailsim.reports import reproduction
from tailsim.reports.markdown import fmt_or_dash

DATA = ROOT / "tests" / "data" / "analysis"


def test_section_renders_from_the_fixture():
    d = reproduction.load_into({}, DATA)
    r = d["reproduction"]
    lines = reproduction.section(d)
    text = "\n".join(lines)
    for heading in [
        "## Reproduction of the thesis",
        "### Claims, figures and verdicts",
        f"### Table 5.1 by the method of §5.1 (level flight, N = {r['setting']['n']})",
        "### The four conclusions of §5.2.1",
        "### Table 4.4 from Table 4.3's placement (TSD)",
        "### Tables 3.2/3.3: open-loop level-flight modes",
        "### Missions on the thesis's setting",
    ]:
        assert heading in lines, heading
    # Every claim is a row with its verdict.
    for c in r["claims"]:
        row = next(x for x in lines if x.startswith(f"| {c['claim']} |"))
        assert row.endswith(f"| {c['verdict']} |")
        assert c["verdict"] in ("reproduced", "partly", "not reproduced")
    # Table 5.1 rows: thesis value, ours (configuration 1), ratio, tuned, from the file.
    for e in r["table_5_1"]:
        row = next(x for x in lines if x.startswith(f"| {e['name']} |"))
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[1:5] == [
            fmt_or_dash(e["lqr_thesis"], 1),
            fmt_or_dash(e["lqr_cfg1"], 1),
            fmt_or_dash(e["lqr_cfg1_ratio"], 2),
            fmt_or_dash(e["lqr_cfg0"], 1),
        ]
        assert e["lqr_cfg1"] > 0 and e["tsd_cfg1"] > 0
    assert "Spearman rank correlation" in text
    assert len(r["conclusions_5_2_1"]) == 4


def test_section_without_the_file_says_how_to_compute_it():
    lines = reproduction.section({})
    assert lines[1] == "## Reproduction of the thesis"
    assert "reproduction --out" in lines[-1]


def test_fixture_is_the_format_the_rust_run_writes():
    r = json.loads((DATA / "reproduction.json").read_text())
    assert {
        "setting",
        "table_5_1",
        "spearman",
        "conclusions_5_2_1",
        "table_4_4",
        "open_loop_modes",
        "missions",
        "fast_transitions",
        "step_responses",
        "conclusions_6_2_6",
        "claims",
    } <= set(r)


def test_fast_transitions_steps_and_chapter_6_render_from_the_files():
    d = reproduction.load_into({}, DATA)
    r, w = d["reproduction"], d["reproduction_wind"]
    lines = reproduction.section(d)
    for heading in [
        "### The TSD's 3/4 s transitions (App. E.1)",
        "### Position steps (§3.4.1, §4.4.2–4.4.3)",
        "### Chapter 6's conclusions (§6.2.6), twice",
    ]:
        assert heading in lines, heading
    # App. E.1: one row per flown variant, the pass and the demand from the file.
    for x in r["fast_transitions"]["rows"]:
        row = next(line for line in lines if line.startswith(f"| {x['variant']} | {x['v_vertical']:g} |"))
        assert f"| {'yes' if x['passed'] else 'no'} | {fmt_or_dash(x['max_pos_error'], 2)} |" in row
        assert f"{x['demand']['n_t2_start']:.2f} g" in row
    # Steps: every flown step is a row ending with its verdict; the claims table carries
    # one row per controller, flight and axis.
    step_rows = [
        line
        for line in lines
        if line.startswith(("| LQR | cfg", "| TSD | cfg")) and ("| level |" in line or "| vertical (V_V" in line)
    ]
    assert len(step_rows) == len(r["step_responses"]["rows"])
    for x, row in zip(r["step_responses"]["rows"], step_rows, strict=True):
        assert row.endswith(f"| {x['verdict']} |")
        assert x["verdict"] in ("reproduced", "partly", "not reproduced")
    assert sum(" step in " in c["claim"] for c in r["claims"]) == 8
    # §6.2.6: each conclusion with both verdicts, the wind one recomputed from the arms.
    wind = {c["id"]: c for c in reproduction.wind_conclusions(w)}
    for c in r["conclusions_6_2_6"]:
        row = next(line for line in lines if line.startswith(f"| {c['claim']} |") and line.count("|") == 7)
        assert row.endswith(f"| {c['verdict']} | {wind[c['id']]['figure']} | {wind[c['id']]['verdict']} |")


def test_every_table_row_has_its_header_s_columns():
    """No cell text splits a Markdown table (a `|` inside a figure would)."""
    lines = reproduction.section(reproduction.load_into({}, DATA))
    header = None
    for line in lines:
        if not line.startswith("|"):
            header = None
            continue
        if header is None:
            header = line.count("|")
        assert line.count("|") == header, line


def test_wind_conclusions_follow_the_arms():
    """The §6.2.6 verdicts in wind move with the campaign's figures."""
    arm = {"runs": 100, "completed": 50, "median_max_err": 5.0, "median_rms_err": 2.0}
    w = {
        "arms": {
            "lqr/thesis/perfect": {**arm, "p": 0.9, "median_phase_max_err": [1, 5, 1, 6, 1]},
            "tsd/thesis/perfect": {**arm, "p": 0.2, "median_phase_max_err": [1, 1, 1, 1, 1]},
        }
    }
    v = {c["id"]: c["verdict"] for c in reproduction.wind_conclusions(w)}
    assert v == {"lqr_phases": "reproduced", "lqr_robust": "reproduced", "tsd_better": "not reproduced"}
    w["arms"]["tsd/thesis/perfect"].update(p=0.95, median_max_err=1.0)
    w["arms"]["lqr/thesis/perfect"]["median_phase_max_err"] = [9, 5, 1, 6, 1]
    v = {c["id"]: c["verdict"] for c in reproduction.wind_conclusions(w)}
    assert v == {"lqr_phases": "not reproduced", "lqr_robust": "not reproduced", "tsd_better": "reproduced"}
