"""The "Reproduction of the thesis" section renders from `reproduction.json`
(`tests/data/analysis/reproduction.json`: the output of a tiny run,
`cargo run --release -p analysis -- reproduction --n 4 --params Cmde,m --out /tmp/fx`),
every number taken from the file."""

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
        "claims",
    } <= set(r)
