"""The analysis report is rendered by Python from the data the Rust campaign
writes. `tests/data/analysis/` holds the output of a tiny campaign
(`cargo run --release -p analysis -- all --n 2 --params Cmde --max-gust 2`,
report.json + CSV; `aero_models.json` + CSV of
`-- aero --max-gust 2 --out tests/data/analysis`); the Rust test `tiny_campaign_tables_come_from_runs_and_are_cached`
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
        "## Thesis (linear) against global aerodynamics (beyond the thesis, issue 13)",
        "## Transitions inside the linear α range (issue 16)",
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
    # Transitions (issue 16): one row per tuned run, the thesis configuration on the timings.
    env = d["envelope_transitions"]
    tr = [line for line in lines_of(folder, "envelope_transitions.md") if line.startswith("| LQR") or line.startswith("| TSD")]
    assert len(tr) == len(env["rows"])
    fast = next(r for r in env["rows"] if r["controller"] == "LQR" and r["configuration"] == 0 and r["t1"] == 2.0)
    assert f"| {fast['max_alpha_deg']:.1f} | {fast['alt_dev_t1']:.2f} / {fast['alt_dev_t2']:.2f} |" in "\n".join(tr)


def test_every_plot_is_drawn_and_embedded(rendered):
    folder, d = rendered
    expected = {"open_loop_modes", "table_5_1", "robustness", "gusts", "aero_coefficients", "aero_flights"}
    expected |= {"envelope_fastest"}
    expected |= {f"closed_loop_poles_{c}" for c in d["conditions"]}
    expected |= {"takeoff_landing"} if d.get("takeoff_landing") else set()
    expected |= {f"loci_{k}_{c}_{kind}" for k in d["controllers"] for c in d["conditions"] for kind in ("pitch", "all")}
    assert {p.stem for p in folder.glob("*.png")} == expected
    html = (folder / "report.html").read_text()
    assert html.count("data:image/png;base64,") == len(expected)


def test_aero_models_section_shows_both_models_side_by_side(rendered):
    """Every case × controller has one row with the thesis (0) and global (1) values side by
    side, and the verdict names the direction of the change."""
    folder, _ = rendered
    a = json.loads((DATA / "aero_models.json").read_text())
    lines = lines_of(folder, "aero_models.md")
    desc = {c["id"]: c["description"] for c in a["cases"]}
    by = {(r["case"], r["controller"], r["aero_model"]): r for r in a["rows"]}
    assert len(a["rows"]) == 2 * 2 * len(a["cases"])
    for case, ctl, _ in [k for k in by if k[2] == 0]:
        t, g = by[case, ctl, 0], by[case, ctl, 1]
        row = [line for line in lines if line.startswith(f"| {desc[case]} | {ctl} |")]
        assert len(row) == 1, (case, ctl)
        cells = [c.strip() for c in row[0].strip("|").split("|")]
        assert cells[3] == f"{t['max_alpha_deg']:.1f} / {g['max_alpha_deg']:.1f}"
        assert cells[5] == f"{t['max_pos_error_m']:.2f} / {g['max_pos_error_m']:.2f}"
        assert cells[6] == f"{t['max_alt_dev_m']:.2f} / {g['max_alt_dev_m']:.2f}"
        lost = t["passed"] and not g["passed"]
        assert cells[8].startswith("LOST with the global model") == lost
    # Gust sweep on both models: 3 phases × 3 axes, thesis / global per controller.
    i = lines.index("### Gust sweep on both models")
    j = lines.index("### Parameter end points on both models")
    gust = [line for line in lines[i:j] if line.startswith("| ") and not line.startswith("| phase")]
    assert len(gust) == 9
    g = {(r["phase"], r["axis"], r["controller"], r["aero_model"]): r["largest_survived"] for r in a["gusts"]["rows"]}
    first = [c.strip() for c in gust[0].strip("|").split("|")]
    assert first[2] == f"{g[first[0], first[1], 'LQR', 0]:.0f} / {g[first[0], first[1], 'LQR', 1]:.0f}"
    # Parameter end points: one row per parameter of Table 5.1, ÷τ and ×τ per controller.
    i = lines.index("### Parameter end points on both models")
    scaled = [line for line in lines[i:] if line.startswith("| ") and not line.startswith("| parameter")]
    assert len(scaled) == len({r["param"] for r in a["scaled"]}) == 25
    r = next(r for r in a["scaled"] if r["param"] == "CLa" and r["controller"] == "LQR" and r["factor"] < 1)
    assert scaled[0].startswith(f"| {r['name']} | {r['max_pos_error_m']:.2f}{'' if r['passed'] else ' ✗'} / ")
    # Coefficient curves: both models over 0…180°, identical in attached flow.
    c = a["coefficients"]
    assert c["alpha_deg"][0] == 0 and c["alpha_deg"][-1] == 180
    for al, t, g in zip(c["alpha_deg"], c["thesis"]["c_L"], c["global"]["c_L"]):
        if al <= c["alpha_attached_deg"]:
            assert abs(t - g) < 1e-12


def test_aero_verdicts():
    """The verdict logic on hand-made rows (independent of any run)."""
    from tailsim.aero_report import verdict

    def row(passed, alpha, err, alt, stall, beta=0.0, failure=None):
        return {"passed": passed, "max_alpha_deg": alpha, "max_beta_deg": beta, "max_pos_error_m": err,
                "max_alt_dev_m": alt, "max_stall_fraction": stall, "failure": failure}

    assert verdict(row(True, 8, 0.5, 0.3, 0.0), row(True, 8, 0.5, 0.3, 0.0)) == "unchanged: attached flow throughout"
    v = verdict(row(True, 22, 0.4, 0.2, 0.5), row(False, 170, 80, 79, 1.0, failure="touched the ground"))
    assert v.startswith("LOST with the global model (touched the ground)")
    assert "α up to 22°" in v and "tumbles" in v and "mostly height (79.0 of 80.0 m)" in v
    assert verdict(row(False, 170, 90, 80, 1.0), row(True, 5, 1, 1, 0.5)).startswith("saved by the global model")
    assert verdict(row(False, 170, 90, 80, 1.0), row(False, 170, 90, 80, 1.0)) == "lost with both models"
    v = verdict(row(True, 22, 0.4, 0.2, 0.5), row(True, 52, 12.9, 12.7, 1.0))
    assert v.startswith("passes with both; worse with the global model (error +12.50 m, max α +30.0°")
