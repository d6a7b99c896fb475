"""The analysis report is rendered by Python from the data the Rust campaign
writes. `tests/data/analysis/` holds the output of a tiny campaign
(`cargo run --release -p analysis -- all --n 2 --params Cmde --max-gust 2 --out /tmp/fx`:
report.json + CSV + aero_models.json, copied without summary.json and the cache, with
"out" set back to "out/analysis" and each take-off/landing trajectory trimmed to 11 points;
crates/analysis/README.md); the Rust test `tiny_campaign_tables_come_from_runs_and_are_cached`
checks that a campaign still writes report.json with the same structure. The robustness
sweep is flown on both aerodynamic models: its table shows thesis / global side
by side with a generated what-changed-and-why."""

from __future__ import annotations

import json
import shutil

import pytest

from fmu_util import ROOT
from tailsim.reports import analysis as analysis_report

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
        "## Thesis (linear) against global aerodynamics (beyond the thesis)",
        "## Transitions inside the linear α range",
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
    # Robustness: range, passes and worst error of each controller, thesis / global model
    # side by side.
    rb = next(line for line in lines_of(folder, "robustness.md") if line.startswith("| C_mδe |"))
    cells = [c.strip() for c in rb.strip("|").split("|")]
    by = {(r["controller"], r["aero_model"]): r for r in d["robustness"]["rows"]}
    assert set(by) == {(k, m) for k in d["controllers"] for m in (0, 1)}
    for i, k in enumerate(d["controllers"]):
        t, g = by[k, 0], by[k, 1]
        assert (
            cells[1 + 3 * i] == f"{t['range'][0]:.3f} … {t['range'][1]:.3f} / {g['range'][0]:.3f} … {g['range'][1]:.3f}"
        )
        assert cells[2 + 3 * i] == f"{t['passes']}/{t['points']} / {g['passes']}/{g['points']}"
        assert cells[3 + 3 * i] == f"{t['worst_pos_error']:.2f} / {g['worst_pos_error']:.2f}"
    # The generated comparison: one line per controller with its nominal flight on both models.
    text = lines_of(folder, "robustness.md")
    assert text.count("Linear against global (generated from the rows above):") == 2  # thesis range + wide
    for k in d["controllers"]:
        t, g = by[k, 0]["nominal"], by[k, 1]["nominal"]
        line = next(x for x in text if x.startswith(f"- **{k}**: the nominal airframe (factor 1)"))
        assert f"position error {t['max_pos_error']:.2f} / {g['max_pos_error']:.2f} m" in line
    assert sum(x.startswith("Why: ") for x in text) == 2
    # Gusts: 3 phases × 3 axes.
    gu = [line for line in lines_of(folder, "gusts.md") if line.startswith("| ") and not line.startswith("| phase")]
    assert len(gu) == 9
    # Transitions: one row per tuned run, the thesis configuration on the timings.
    env = d["envelope_transitions"]
    tr = [
        line
        for line in lines_of(folder, "envelope_transitions.md")
        if line.startswith("| LQR") or line.startswith("| TSD")
    ]
    assert len(tr) == len(env["rows"])
    fast = next(r for r in env["rows"] if r["controller"] == "LQR" and r["configuration"] == 0 and r["t1"] == 2.0)
    assert f"| {fast['max_alpha_deg']:.1f} | {fast['alt_dev_t1']:.2f} / {fast['alt_dev_t2']:.2f} |" in "\n".join(tr)


def test_every_plot_is_drawn_and_embedded(rendered):
    folder, d = rendered
    expected = {"open_loop_modes", "table_5_1", "robustness", "gusts", "aero_coefficients", "aero_flights"}
    expected |= {"envelope_fastest"}
    expected |= {f"closed_loop_poles_{c}" for c in d["conditions"]}
    expected |= {"takeoff_landing"} if d.get("takeoff_landing") else set()
    expected |= {"wind_envelope"} if (DATA / "wind_envelope.json").exists() else set()
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
    j = lines.index("### Parameter sweep on both models")
    gust = [line for line in lines[i:j] if line.startswith("| ") and not line.startswith("| phase")]
    assert len(gust) == 9
    g = {(r["phase"], r["axis"], r["controller"], r["aero_model"]): r["largest_survived"] for r in a["gusts"]["rows"]}
    first = [c.strip() for c in gust[0].strip("|").split("|")]
    assert first[2] == f"{g[first[0], first[1], 'LQR', 0]:.0f} / {g[first[0], first[1], 'LQR', 1]:.0f}"
    # The parameter sweep on both models: its pass counts from report.json's robustness rows.
    i = lines.index("### Parameter sweep on both models")
    rows = json.loads((DATA / "report.json").read_text())["robustness"]["rows"]
    for m, name in ((0, "thesis"), (1, "global")):
        passes = sum(r["passes"] for r in rows if r["aero_model"] == m)
        points = sum(r["points"] for r in rows if r["aero_model"] == m)
        assert f"{name} {passes}/{points}" in lines[i + 2]
    # Coefficient curves: both models over 0…180°, identical in attached flow.
    c = a["coefficients"]
    assert c["alpha_deg"][0] == 0 and c["alpha_deg"][-1] == 180
    for al, t, g in zip(c["alpha_deg"], c["thesis"]["c_L"], c["global"]["c_L"], strict=False):
        if al <= c["alpha_attached_deg"]:
            assert abs(t - g) < 1e-12


def test_aero_verdicts():
    """The verdict logic on hand-made rows (independent of any run)."""
    from tailsim.reports.aero import verdict

    def row(passed, alpha, err, alt, stall, beta=0.0, failure=None):
        return {
            "passed": passed,
            "max_alpha_deg": alpha,
            "max_beta_deg": beta,
            "max_pos_error_m": err,
            "max_alt_dev_m": alt,
            "max_stall_fraction": stall,
            "failure": failure,
        }

    assert verdict(row(True, 8, 0.5, 0.3, 0.0), row(True, 8, 0.5, 0.3, 0.0)) == "unchanged: attached flow throughout"
    v = verdict(row(True, 22, 0.4, 0.2, 0.5), row(False, 170, 80, 79, 1.0, failure="touched the ground"))
    assert v.startswith("LOST with the global model (touched the ground)")
    assert "α up to 22°" in v and "tumbles" in v and "mostly height (79.0 of 80.0 m)" in v
    assert verdict(row(False, 170, 90, 80, 1.0), row(True, 5, 1, 1, 0.5)).startswith("saved by the global model")
    assert verdict(row(False, 170, 90, 80, 1.0), row(False, 170, 90, 80, 1.0)) == "lost with both models"
    v = verdict(row(True, 22, 0.4, 0.2, 0.5), row(True, 52, 12.9, 12.7, 1.0))
    assert v.startswith("passes with both; worse with the global model (error +12.50 m, max α +30.0°")


def test_robustness_changes_say_what_changed_and_why():
    """The linear-against-global sentences on hand-made sweep rows (independent of any run):
    fewer and more passing factors on the global model are listed with their counts, the
    largest change of the worst error is named, and the reason depends on whether the
    changed sweeps left attached flow."""
    from tailsim.reports.aero import robustness_changes

    d = {
        "controllers": ["LQR"],
        "params": [{"id": "CLa", "name": "C_Lα"}, {"id": "Cma", "name": "C_mα"}, {"id": "Cnb", "name": "C_nβ"}],
    }

    def row(pid, model, passes, worst, alpha, stall, rng=(0.8, 1.2)):
        nominal = {"passed": True, "max_pos_error": 0.4 + model, "max_alpha_deg": 11.0, "max_stall_fraction": 0.01}
        return {
            "param": pid,
            "controller": "LQR",
            "aero_model": model,
            "passes": passes,
            "points": 50,
            "range": list(rng),
            "worst_pos_error": worst,
            "max_alpha_deg": alpha,
            "max_stall_fraction": stall,
            "nominal": nominal,
        }

    rows = [
        row("CLa", 0, 50, 0.5, 22, 0.4),
        row("CLa", 1, 44, 3.5, 60, 1.0, (0.9, 1.2)),  # fewer, stalled
        row("Cma", 0, 40, 2.0, 30, 0.5, (0.9, 1.2)),
        row("Cma", 1, 46, 2.0, 35, 0.6),  # more, stalled
        row("Cnb", 0, 50, 0.7, 8, 0.0),
        row("Cnb", 1, 50, 0.7, 8, 0.0),  # attached, identical
    ]
    out = robustness_changes(d, rows)
    line = next(x for x in out if x.startswith("- **LQR**"))
    assert "position error 0.40 / 1.40 m" in line
    assert "1 of 3 sweeps pass at as many factors" in line
    assert "fewer on the global model: C_Lα 50 → 44" in line and "more on the global model: C_mα 40 → 46" in line
    assert "in 1 sweep (most: C_Lα, 0.50 / 3.50 m)" in line
    why = out[-1]
    assert why.startswith("Why: all 2 changed sweeps left attached flow") and "α up to 60°" in why
    assert "1 sweep stayed in attached flow on both models and fly identically" in why
    # A sweep that changed although it stayed attached is called out, not explained away.
    rows[5] = row("Cnb", 1, 49, 0.7, 8, 0.0)
    why = robustness_changes(d, rows)[-1]
    assert "1 sweep changed without leaving attached flow (LQR C_nβ)" in why and not why.startswith("Why: all")
    # Nothing changed, all attached.
    same = [row("Cnb", 0, 50, 0.7, 8, 0.0), row("Cnb", 1, 50, 0.7, 8, 0.0)]
    assert robustness_changes(d, same)[-1] == (
        "Why: nothing changed — every flight stayed in attached flow, where the global model is the thesis's."
    )
    assert not any("nominal airframe" in x for x in robustness_changes(d, same, nominal=False))


def test_wind_envelope_section_counts_the_held_cells(rendered):
    """wind_envelope.md (from `analysis wind-envelope`): per mission and wind form one row per
    controller and speed with the held count of the data's summary and one cell per bearing."""
    folder, _ = rendered
    w = json.loads((DATA / "wind_envelope.json").read_text())
    text = (folder / "wind_envelope.md").read_text()
    blocks = text.split("\n### ")[1:]
    titles = {"default": "default mission", "takeoff_landing": "take-off to landing"}
    forms = {"step": "stepping in", "turbulent": "turbulence"}
    for s in w["summary"]:
        block = next(b for b in blocks if b.startswith(titles[s["mission"]]) and forms[s["wind"]] in b.splitlines()[0])
        row = next(line for line in block.splitlines() if line.startswith(f"| {s['controller']} | {s['speed']:g} | "))
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[2] == f"{s['held']}/{s['cells']}", row
        assert len(cells) == 3 + len(w["bearings_deg"])
        assert sum(c.startswith("✓") for c in cells[3:]) == s["held"]
