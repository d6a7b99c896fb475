"""The analysis report, rendered from the data the Rust campaign writes.

    cargo run --release -p analysis -- all --out out/analysis
    .venv/bin/python -m tailsim.reports.analysis out/analysis

The campaign (`crates/analysis`) writes data only: `report.json` (every table
as structured data) and the CSV files of every table and figure. This module
renders them: `report.md` (everything) and one Markdown file per section
(`open_loop_modes.md`, `closed_loop_poles.md`, `table_5_1.md`,
`robustness.md`, `gusts.md`, `aero_models.md`), `report.html` and the plots
(`tailsim.reports.analysis_plots`, `tailsim.reports.aero`). `tailsim.reports.compare` includes the same sections in
the comparison report.
"""

from __future__ import annotations

import json
import pathlib

from . import aero as aero_report
from . import envelope as report_envelope
from . import hover as report_hover
from . import reproduction as report_reproduction
from . import takeoff as report_takeoff
from . import wind_envelope as report_wind
from .markdown import fmt_or_dash, fmt_pole, markdown_to_html, shortest, table_head, toc

OPEN_LOOP_NOTES = (
    "Differences from the thesis: the thesis's modes were computed from its AVL-based model with numbers it "
    "does not publish (span, inertia cross-terms, the trim it linearised at: α = 5.9° in AVL against our α ≈ 7.5°, "
    "δe ≈ −6° once the elevator's own lift counts). Its short period −10.44 ± 24.2i does not follow from its own "
    "published derivatives: with C_mα = −1.65, C_mq = −7.64, C_Lα = 4.25, I_y = 0.42 kg m², m = 9 kg, S = 0.574 m², "
    "c̄ = 0.366 m at 25 m/s (q̄Sc̄ ≈ 80 N m), M_α ≈ q̄Sc̄C_mα/I_y ≈ −315 s⁻², M_q ≈ q̄Sc̄²C_mq/(2V I_y) ≈ −10.7 s⁻¹ "
    "and Z_α/V ≈ q̄SC_Lα/(mV) ≈ 4.2 s⁻¹, so ζω ≈ (10.7 + 4.2)/2 ≈ 7.4 s⁻¹ and ω ≈ √(315 + 10.7·4.2) ≈ 19 rad/s — "
    "our −7.4 ± 16.5i (ω_n 18.1), not the thesis's ω_n 26.4 rad/s, which would need about twice the pitch "
    "stiffness C_mα/I_y. Lateral modes depend on the span b = 1.569 m (S/c̄) we assume, which sets the roll damping "
    "L_p ∝ b² and hence the roll pole (ours ≈ −8 against −10.3) and the Dutch roll. The spiral mode is unstable in "
    "both (no dihedral, §3.4.2), slower in ours. The phugoid matches in frequency (≈ √2·g/V)."
)

SENSITIVITY_NOTES = (
    "Our closed loops differ from the thesis's (controllers retuned for this airframe, our full sampled-data loop "
    "with servo and thrust lags and integrators against the thesis's linear model), so the percentages are compared "
    "in ranking, not value. The measure is the largest excursion over the sweep; the end-to-end span "
    "|p(k=N−1) − p(k=0)| is in `table_5_1.csv` (rms_span_percent)."
)


def load(folder: str | pathlib.Path) -> dict:
    """`report.json` of an analysis output folder, with `aero_models.json` (if written)
    under the key `aero_models` and `wind_envelope.json` (if written) under `wind_envelope`."""
    d = json.loads((pathlib.Path(folder) / "report.json").read_text())
    return report_reproduction.load_into(report_wind.load_into(aero_report.load_into(d, folder), folder), folder)


def _rows(header: str, rule: str, lines: list[str]) -> list[str]:
    return [header, rule] + lines


def open_loop(d: dict) -> list[str]:
    ol = d["open_loop"]
    coords = ol["coords"]
    lvl, vert = ol["conditions"][0], ol["conditions"][1]
    tr = lvl["trim"]
    out = ["## Open-loop modes (thesis §3.4.2, Tables 3.2 and 3.3)", ""]
    out += [
        f"{lvl['condition']}: trim α = {tr['alpha_deg']:.2f}°, δe = {tr['elevator_deg']:.2f}°, T = "
        f"{tr['thrust_n']:.2f} N. "
        "Coordinates (V̄, α, β, p, q, r, φ, θ, ψ), 3-2-1 Euler angles; mode shapes normalised to the largest displayed "
        "component (V in m/s, angles in rad, rates in rad/s).",
        "",
        "| mode | ours | ζ | ω_n (rad/s) | thesis | shape (ours) | shape (thesis) |",
        "|---|---|---|---|---|---|---|",
    ]
    for th in ol["thesis_level"]:
        m = next((m for m in lvl["modes"] if m["name"] == th["name"]), None)
        if m is None:
            continue
        ours = []
        for c, _, _ in th["shape"]:
            i = coords.index(c) if c in coords else 0
            mag, ph = m["shape"][i]
            ours.append(f"{c} {mag:.3f}∠{ph:.0f}°")
        thesis = [f"{c} {a:.3f}∠{p:.0f}°" for c, a, p in th["shape"]]
        out.append(
            f"| {m['name']} | {fmt_pole(m['re'], m['im'])} | {m['damping']:.3f} | {m['omega_n']:.3f} | "
            f"{fmt_pole(th['re'], th['im'])} | {', '.join(ours)} | {', '.join(thesis)} |"
        )
    out += [
        "",
        f"{vert['condition']}: trim T = {vert['trim']['thrust_n']:.2f} N. The conventional names do not apply; "
        "modes named by their dominant coordinate.",
        "",
        "| mode | eigenvalue | ζ | ω_n (rad/s) |",
        "|---|---|---|---|",
    ]
    for m in vert["modes"]:
        out.append(f"| {m['name']} | {fmt_pole(m['re'], m['im'])} | {m['damping']:.3f} | {m['omega_n']:.3f} |")
    out += ["", OPEN_LOOP_NOTES]
    return out


def closed_loop(d: dict) -> list[str]:
    cl = d["closed_loop"]
    at = cl["analysis_time_s"]
    out = [
        "",
        "## Closed-loop poles (Jacobian of the closed-loop sampled map, s = ln z / T)",
        "",
        "One method for both controllers: plant over one sample time + controller update, perturbed in the plant's "
        "19 minimal coordinates and the controller's integrators (through its save/restore state), at the operating "
        f"point the nominal mission reaches (level: t = {at['level']:.1f} s, vertical 3 m/s climb: t = "
        f"{at['vertical']:.1f} s). "
        "Upper half plane only; servo (−20) and thrust-lag (−10) poles included.",
        "",
    ]
    for run in cl["runs"]:
        out += [f"### {run['controller']} — {run['condition']} flight", ""]
        if run["error"] is not None:
            out += [f"failed: {run['error']}", ""]
            continue
        out += ["| pole | ζ | ω_n (rad/s) | dominant coordinates |", "|---|---|---|---|"]
        for p in run["poles"]:
            if p["im"] < -1e-9:
                continue
            out.append(f"| {fmt_pole(p['re'], p['im'])} | {p['damping']:.3f} | {p['omega_n']:.3f} | {p['dominant']} |")
        out.append("")
        if run["tsd_placed"]:
            out += [
                "TSD placed (Table 4.3, our parameters) against achieved (nearest closed-loop pole, one-to-one, "
                "closest "
                "pairs first; where loops couple and poles crowd, the assignment is ambiguous — the dominant "
                "coordinates "
                "in the list above identify the loops):",
                "",
                "| loop | placed | achieved (ours) | thesis Table 4.4 |",
                "|---|---|---|---|",
            ]
            for r in run["tsd_placed"]:
                achieved = fmt_pole(*r["achieved"]) if r["achieved"] is not None else "—"
                out.append(f"| {r['loop']} | {fmt_pole(*r['placed'])} | {achieved} | {r['thesis'] or '—'} |")
            out.append("")
    return out


def table_5_1(d: dict) -> list[str]:
    s = d["sensitivity"]
    out = [
        "",
        "## Sensitivity (thesis §5.1, Table 5.1)",
        "",
        "Each parameter scaled in the plant alone by C₀·τ^(−1+2k/N), k = 0…N−1, "
        f"N = {d['n']}, τ = 1.5 (aerodynamic) / 1.1 (m, I); controllers keep their nominal design model. Entry: RMS "
        "over "
        "the closed-loop poles of each pole's largest excursion from nominal, in % of its nominal natural frequency "
        f"(poles with ω_n < {shortest(s['min_omega'])} rad/s left out). `!` marks sweeps with an unstable closed-loop "
        "pole somewhere, `✗n` sweeps where n points failed to reach the operating point, `sn` sweeps where at n points "
        "an actuator saturated at the operating point (a pole at z = 0, left out of that pole's excursion). The "
        "thesis's column is level flight.",
        "",
    ]
    # The thesis's controllers only: a controller outside the thesis is named with the reason.
    ctrls = [k for k in d["controllers"] if all(k in p["thesis_percent"] for p in d["params"])]
    for na in s.get("not_applicable", []):
        out += [f"Not for {na['controller']}: {na['reason']}.", ""]
    cells = [[f"{k} thesis", *(f"{k} ours ({c})" for c in d["conditions"])] for k in ctrls]
    out += table_head(["parameter", *(c for per_controller in cells for c in per_controller)])
    rows = {(r["param"], r["controller"], r["condition"]): r for r in s["rows"]}
    for p in d["params"]:
        line = f"| {p['name']} |"
        for k in ctrls:
            line += f" {p['thesis_percent'][k]:.1f}% |"
            for c in d["conditions"]:
                row = rows.get((p["id"], k, c), {}).get("row")
                if row is None:
                    cell = "failed"
                else:
                    cell = f"{row['rms_percent']:.1f}%"
                    if row["unstable_points"] > 0:
                        cell += " !"
                    if row["degenerate_points"] > 0:
                        cell += f" s{row['degenerate_points']}"
                    if row["failed_points"] > 0:
                        cell += f" ✗{row['failed_points']}"
                line += f" {cell} |"
        out.append(line)
    out += ["", SENSITIVITY_NOTES]
    return out


def _range(r: dict | None) -> str:
    if r is None:
        return "—"
    return f"{r['range'][0]:.3f} … {r['range'][1]:.3f}" if r["range"] is not None else "nominal fails"


def _robustness_table(d: dict, rows: list[dict]) -> list[str]:
    """One row per parameter; with rows on both aerodynamic models every cell is
    `thesis / global`."""
    models = sorted({r.get("aero_model", 0) for r in rows})
    both = models == [0, 1]
    out = table_head(
        ["parameter", *(c for k in d["controllers"] for c in (f"{k} range", f"{k} passes", f"{k} worst pos. err (m)"))]
    )
    by = {(r["param"], r["controller"], r.get("aero_model", 0)): r for r in rows}
    for p in d["params"]:
        line = f"| {p['name']} |"
        for k in d["controllers"]:
            cells = []
            for m in models if both else models[:1]:
                r = by.get((p["id"], k, m))
                if r is None:
                    cells.append(("—", "—", "—"))
                    continue
                cells.append((_range(r), f"{r['passes']}/{r['points']}", fmt_or_dash(r["worst_pos_error"])))
            line += "".join(f" {' / '.join(c[i] for c in cells)} |" for i in range(3))
        out.append(line)
    return out


def robustness(d: dict) -> list[str]:
    rb = d.get("robustness")
    if not rb:
        return []
    both = sorted(rb.get("aero_models") or [0]) == [0, 1]
    out = [
        "",
        "## Nonlinear robustness (beyond the thesis)",
        "",
        "The whole default mission flown in the nonlinear closed loop with the parameter scaled over the same sweep as "
        "Table 5.1 (τ = 1.5 / 1.1); range = contiguous range of factors around 1 over which the mission passes the "
        "mission criteria (`MissionCheck::passed`); worst = largest position error over that range; passes "
        "= passing points of N. The mission is symmetric and flown in calm air, so the lateral derivatives are hardly "
        "excited (identical position errors): their robustness shows in the gust sweep.",
    ]
    if both:
        out += [
            "",
            "Every flight is flown twice: on the thesis's linear aerodynamics (`aero_model` 0, the "
            "controllers' design model) and on the global model (`aero_model` 1, the plant FMU's default); same "
            "plant otherwise (no ground), same untuned controllers. Cells: thesis / global.",
        ]
    out.append("")
    alpha_attached = rb.get("alpha_attached_deg", 10.0)
    out += _robustness_table(d, rb["rows"])
    if both:
        out += ["", *aero_report.robustness_changes(d, rb["rows"], alpha_attached)]
    w = rb.get("wide")
    if w:
        a, m = w["aerodynamic_range"], w["mass_inertia_range"]
        out += [
            "",
            f"### Wider sweep: τ^{shortest(w['tau_power'])} ({a[0]:.2f} … {a[1]:.2f} aerodynamic, "
            f"{m[0]:.3f} … {m[1]:.3f} m and I)",
            "",
            "The same flights over a wider range, to find where the missions start failing"
            + (", on both models (cells: thesis / global)." if both else "."),
            "",
        ]
        out += _robustness_table(d, w["rows"])
        if both:
            out += ["", *aero_report.robustness_changes(d, w["rows"], alpha_attached, nominal=False)]
    return out


def gusts(d: dict) -> list[str]:
    g = d.get("gusts")
    if not g:
        return []
    amps = g["amplitudes"]
    out = [
        "",
        "## Gust sweep (beyond the thesis)",
        "",
        f"1−cos gusts of {shortest(g['duration_s'])} s along one earth axis (NED; + = towards north/east/down), "
        f"amplitudes {shortest(amps[0]) if amps else '0'}…{shortest(amps[-1]) if amps else '0'} m/s: in the first "
        "vertical phase (3 m/s climb, from t = 1.5 s), centred on the middle of the first transition, and in level "
        "flight (from 2 s after its start). Largest amplitude A such that every amplitude ≤ A still passes the mission "
        "criteria (0 = the smallest fails); the criteria do not bound the position error, so the last column also "
        f"requires a position error ≤ {shortest(g['pos_bound_m'])} m. Flown on the thesis's linear aerodynamics "
        "(`aero_model` 0, no ground); the same sweep on both models (with the plant FMU's ground) is in the section "
        "on thesis against global aerodynamics.",
        "",
    ]
    bound = shortest(g["pos_bound_m"])
    per_controller = ("largest survived (m/s)", "max pos. err at it (m)", f"largest with pos. err ≤ {bound} m")
    out += table_head(["phase", "axis", *(f"{k} {c}" for k in d["controllers"] for c in per_controller)])
    cases: list[tuple[str, str]] = []
    for r in g["rows"]:
        if (r["phase"], r["axis"]) not in cases:
            cases.append((r["phase"], r["axis"]))
    by = {(r["phase"], r["axis"], r["controller"]): r for r in g["rows"]}
    for ph, axis in cases:
        line = f"| {ph} | {axis} |"
        for k in d["controllers"]:
            r = by.get((ph, axis, k))
            if r is None:
                continue
            line += (
                f" {r['largest_survived']:.0f} | {fmt_or_dash(r['max_pos_error_at_largest'])} | "
                f"{r['largest_bounded']:.0f} |"
            )
        out.append(line)
    return out


SECTIONS = {
    "open_loop_modes.md": open_loop,
    "closed_loop_poles.md": closed_loop,
    "table_5_1.md": table_5_1,
    "robustness.md": robustness,
    "gusts.md": gusts,
    "aero_models.md": aero_report.section,
    "envelope_hover.md": report_hover.section,
    "envelope_transitions.md": report_envelope.section,
    "takeoff_landing.md": report_takeoff.section,
    "wind_envelope.md": report_wind.section,
    "reproduction.md": report_reproduction.section,
}


def markdown(d: dict) -> list[str]:
    """The whole analysis report as Markdown lines."""
    lines = [
        "# Tail-sitter analysis report",
        "",
        f"Generated by `cargo run --release -p analysis -- all --out {d['out']}` (N = {d['n']}, wall time "
        f"{d['wall_time_s']:.1f} s, {d['jobs']} jobs, {d['cache_hits']} from the cache).",
        "",
    ]
    for section in SECTIONS.values():
        lines += section(d)
    return lines


def plots(folder: pathlib.Path) -> list[pathlib.Path]:
    """The analysis plots (PNG) of `folder`, in a stable order."""
    return sorted(folder.glob("*.png"))


def write(folder: str | pathlib.Path, with_plots: bool = True) -> pathlib.Path:
    """Render `report.md`, the per-section Markdown files, the plots and
    `report.html` into the analysis output `folder`; returns report.md."""
    folder = pathlib.Path(folder)
    d = load(folder)
    for name, section in SECTIONS.items():
        lines = section(d)
        if lines:
            (folder / name).write_text("\n".join(lines) + "\n")
    if with_plots:
        from . import analysis_plots

        analysis_plots.main(folder)
        aero_report.plot(folder)
        report_takeoff.plot(folder)
        report_wind.plot(folder)
    md = markdown(d)
    pngs = plots(folder)
    if pngs:
        md += ["", "## Plots", ""]
        for p in pngs:
            md += [f"![{p.stem}]({p.name})", ""]
    md = md[:4] + ["## Contents", "", *toc(md), ""] + md[4:]
    (folder / "report.md").write_text("\n".join(md) + "\n")
    (folder / "report.html").write_text(markdown_to_html(md, folder, "Tail-sitter analysis report"))
    return folder / "report.md"


def main(argv: list[str] | None = None) -> int:
    from .. import cli

    ap = cli.Parser(prog="tailsim.reports.analysis", description=__doc__.split("\n\n")[0])
    ap.add_argument("folder", nargs="?", default="out/analysis", help="output folder of the analysis campaign")
    ap.add_argument("--no-plots", action="store_true", help="tables only")
    args = ap.parse_args(argv)
    if not (pathlib.Path(args.folder) / "report.json").is_file():
        ap.error(
            f"argument folder: {args.folder!r} holds no report.json; "
            "write it with `cargo run --release -p analysis -- all --out FOLDER`"
        )

    def run() -> int:
        path = write(args.folder, with_plots=not args.no_plots)
        print(f"analysis report: {path} and {path.with_suffix('.html')}")
        return 0

    return cli.guard(ap.prog, args.debug, run)


if __name__ == "__main__":
    raise SystemExit(main())
