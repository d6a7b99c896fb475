"""The analysis report is rendered by Python from the data the Rust campaign
writes. `tests/data/analysis/` holds the output of a tiny campaign
(`cargo run --release -p analysis -- all --n 2 --params Cmde --max-gust 2`,
report.json + CSV); the Rust test `tiny_campaign_tables_come_from_runs_and_are_cached`
checks that a campaign still writes report.json with the same structure."""

from __future__ import annotations

import json
import shutil

import pytest

from fmu_util import ROOT
from tailsim import analysis_report

DATA = ROOT / "tests" / "data" / "analysis"


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    folder = tmp_path_factory.mktemp("analysis")
    for f in DATA.iterdir():
        shutil.copy(f, folder / f.name)
    analysis_report.write(folder)
    return folder, json.loads((DATA / "report.json").read_text())


def lines_of(folder, name):
    return (folder / name).read_text().splitlines()


def test_every_section_and_file_is_written(rendered):
    folder, _ = rendered
    text = (folder / "report.md").read_text()
    for heading in [
        "## Open-loop modes (thesis §3.4.2, Tables 3.2 and 3.3)",
        "## Closed-loop poles (Jacobian of the closed-loop sampled map, s = ln z / T)",
        "### LQR — level flight",
        "### TSD — vertical flight",
        "## Sensitivity (thesis §5.1, Table 5.1)",
        "## Nonlinear robustness (beyond the thesis)",
        "### Wider sweep: τ^3 (0.30 … 1.00 aerodynamic, 0.751 … 1.000 m and I)",
        "## Gust sweep (beyond the thesis)",
    ]:
        assert heading in text.splitlines(), heading
    for name in analysis_report.SECTIONS:
        assert (folder / name).read_text().strip() in text, name


def test_tables_hold_the_data(rendered):
    folder, d = rendered
    # Table 5.1: thesis column (Table 5.1: C_mδe LQR 59.0 %, TSD 105.0 %) and ours, 1 decimal.
    row = next(line for line in lines_of(folder, "table_5_1.md") if line.startswith("| C_mδe |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1] == "59.0%" and cells[4] == "105.0%"
    ours = {(r["controller"], r["condition"]): r["row"]["rms_percent"] for r in d["sensitivity"]["rows"]}
    assert cells[2] == f"{ours['LQR', 'level']:.1f}%" and cells[6] == f"{ours['TSD', 'vertical']:.1f}%"
    # Open loop: one row per thesis mode our level modes name.
    ol = lines_of(folder, "open_loop_modes.md")
    ours_level = {m["name"] for m in d["open_loop"]["conditions"][0]["modes"]}
    for m in d["open_loop"]["thesis_level"]:
        assert any(line.startswith(f"| {m['name']} |") for line in ol) == (m["name"] in ours_level), m["name"]
    # Closed loop: the upper-half poles of each run, and TSD's placed-against-achieved tables.
    cl = (folder / "closed_loop_poles.md").read_text()
    for run in d["closed_loop"]["runs"]:
        upper = [p for p in run["poles"] if p["im"] >= -1e-9]
        assert len(upper) > 0
        for p in upper:
            assert f"| {p['damping']:.3f} | {p['omega_n']:.3f} | {p['dominant']} |" in cl
    assert cl.count("| loop | placed | achieved (ours) | thesis Table 4.4 |") == 2
    assert "| Roll rate |" in cl and "−10.6 ± 4.5i" in cl  # thesis Table 4.4, roll rate, level
    # Robustness: range, passes and worst error of each controller.
    rb = next(line for line in lines_of(folder, "robustness.md") if line.startswith("| C_mδe |"))
    for r in d["robustness"]["rows"]:
        assert f"{r['range'][0]:.3f} … {r['range'][1]:.3f} | {r['passes']}/{r['points']} | {r['worst_pos_error']:.2f}" in rb
    # Gusts: 3 phases × 3 axes.
    gu = [line for line in lines_of(folder, "gusts.md") if line.startswith("| ") and not line.startswith("| phase")]
    assert len(gu) == 9


def test_every_plot_is_drawn_and_embedded(rendered):
    folder, d = rendered
    expected = {"open_loop_modes", "table_5_1", "robustness", "gusts"}
    expected |= {f"closed_loop_poles_{c}" for c in d["conditions"]}
    expected |= {"takeoff_landing"} if d.get("takeoff_landing") else set()
    expected |= {f"loci_{k}_{c}_{kind}" for k in d["controllers"] for c in d["conditions"] for kind in ("pitch", "all")}
    assert {p.stem for p in folder.glob("*.png")} == expected
    html = (folder / "report.html").read_text()
    assert html.count("data:image/png;base64,") == len(expected)
