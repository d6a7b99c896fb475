"""The "Reproduction of the thesis" section of the analysis report, rendered from
`reproduction.json` (`cargo run --release -p analysis -- reproduction --out out/analysis`,
`crates/analysis/src/reproduction.rs`): both controllers as printed (`configuration = 1`)
beside the tuned ones on the thesis's own setting (linear aerodynamics, true state, calm
air, nominal plant). Every number comes from the result file."""

from __future__ import annotations

import argparse
import json
import pathlib
import sys

import numpy as np

from .. import declarations
from . import load_json_into
from .markdown import fmt_or_dash, fmt_pole, table

FILE = "reproduction.json"
#: Chapter 6's conclusions on our plant in wind, from campaign folders (`python -m
#: tailsim.reports.reproduction --wind FOLDER... --out FOLDER`).
WIND_FILE = "reproduction_wind.json"

METHOD_NOTES = (
    "How this matches §5.1: the thesis applies the gains of the perfect model to a linear model with an altered "
    "state matrix, one parameter at a time, and takes the RMS over poles of each pole's movement in % of its "
    "natural frequency. Here the plant's parameter is altered while the controller keeps the nominal airframe as "
    "its design model (gains and feedback linearisation of the perfect model), and the linear model is the "
    "Jacobian of the closed loop's sampled map at the level-flight operating point the altered plant reaches. "
    "Not stated by the thesis, chosen here: the distance is each pole's largest excursion from its nominal "
    "position over the sweep (the end-to-end span is in `reproduction.json`, `*_span`), the altered model is "
    "linearised about its own operating point, and poles slower than the threshold are left out. Our linear model "
    "is the full sampled loop (plant 19 coordinates with servo and thrust lags, controller integrators), the "
    "thesis's its linearised state-space model; the airframe numbers the thesis omits are this project's."
)

TABLE_4_4_NOTES = (
    "Placed = the effective parameters of the configuration (cfg 1: Table 4.3 verbatim, level guidance "
    "−0.75 ± 0.45i). Achieved = the closed-loop pole matched one-to-one to the placed one (nearest first, "
    "over every pole of the closed loop, guidance closed); the thesis's Table 4.4 shows the inner loops and the "
    "NVD applied to its complete model and does not state its climb speed, ours is the mission's vertical "
    "flight. A placed pole whose partner is far away has moved or merged with another loop's."
)


def load_into(d: dict, folder: str | pathlib.Path) -> dict:
    """Add `reproduction.json` and `reproduction_wind.json` of `folder` (if written) to the report data `d`."""
    return load_json_into(load_json_into(d, folder, FILE, "reproduction"), folder, WIND_FILE, "reproduction_wind")


def wind_summary(folders) -> dict:
    """Per arm of the campaign folders (controller/configuration/state source): runs,
    completion, and over the completed runs the median largest error overall and per phase."""
    from ..campaign import section

    table, specs, _ = section._load(folders)
    cols = {k: np.asarray(v) for k, v in table.to_pydict().items()}
    out = {"spec": {k: specs[0].to_json()[k] for k in section.SAMPLE_SPACE}, "arms": {}}
    for a in section.arms(cols):
        m = section._arm_mask(cols, a)
        ok = m & cols["completed"].astype(bool)

        def med(q: str, ok=ok) -> float:
            return float(np.median(cols[q][ok].astype(float))) if ok.any() else float("nan")

        out["arms"]["/".join(a)] = {
            "runs": int(m.sum()),
            "completed": int(ok.sum()),
            "p": float(ok.sum() / m.sum()) if m.any() else float("nan"),
            "median_max_err": med("max_err"),
            "median_rms_err": med("rms_err"),
            "median_phase_max_err": [med(f"max_err_p{k}") for k in range(len(declarations.PHASES))],
        }
    return out


def wind_conclusions(w: dict) -> list[dict]:
    """Chapter 6's conclusions (§6.2.6) judged on the campaign in wind: figure and verdict each."""
    arms = w["arms"]

    def arm(k, c="thesis", s="perfect"):
        return arms.get(f"{k}/{c}/{s}")

    def verdict(ok: bool, partly: bool) -> str:
        return "reproduced" if ok else ("partly" if partly else "not reproduced")

    out = []
    lq = arm("lqr")
    if lq:
        ph = lq["median_phase_max_err"]
        trans, steady = max(ph[1], ph[3]), max(ph[0], ph[2], ph[4])
        out.append(
            {
                "id": "lqr_phases",
                "figure": f"LQR cfg 1, median over completed runs ({lq['completed']} of {lq['runs']}): "
                f"largest error in the transitions {trans:.2f} m, in vertical/level flight {steady:.2f} m",
                "verdict": verdict(trans > steady, False),
            }
        )
    rows = [(k, arm(k)) for k in ("lqr", "tsd")]
    if all(r for _, r in rows):
        (_, l1), (_, t1) = rows
        out.append(
            {
                "id": "lqr_robust",
                "figure": f"completion on uncertain plants in wind, cfg 1: LQR {l1['p']:.3f}, TSD {t1['p']:.3f} "
                f"(of {l1['runs']} each)",
                "verdict": verdict(l1["p"] > t1["p"] + 0.1, l1["p"] > t1["p"]),
            }
        )
        out.append(
            {
                "id": "tsd_better",
                "figure": f"cfg 1: completion TSD {t1['p']:.3f} vs LQR {l1['p']:.3f}; median largest error TSD "
                f"{t1['median_max_err']:.2f} m vs LQR {l1['median_max_err']:.2f} m",
                "verdict": verdict(
                    t1["p"] >= l1["p"] and t1["median_max_err"] < l1["median_max_err"],
                    t1["median_max_err"] < l1["median_max_err"] or t1["p"] > l1["p"],
                ),
            }
        )
    tuned = [arm(k, "tuned") for k in ("lqr", "tsd")]
    if all(tuned):
        for o in out:
            if o["id"] == "tsd_better":
                o["figure"] += (
                    f"; tuned: completion TSD {tuned[1]['p']:.3f} vs LQR {tuned[0]['p']:.3f}, median largest error "
                    f"TSD {tuned[1]['median_max_err']:.2f} m vs LQR {tuned[0]['median_max_err']:.2f} m"
                )
    return out


def _pole(p) -> str:
    return "—" if p is None else fmt_pole(p[0], p[1])


def _pct(x) -> str:
    return fmt_or_dash(x, 1)


def _ratio(x) -> str:
    return fmt_or_dash(x, 2)


def _cfg(name: str) -> str:
    """ "cfg1" → "cfg 1"."""
    return name.replace("cfg", "cfg ")


def _t51(r: dict) -> list[str]:
    header = ["parameter"]
    for k in ("LQR", "TSD"):
        header += [f"{k} thesis", f"{k} cfg 1", "ratio", f"{k} cfg 0"]
    rows = []
    for e in r["table_5_1"]:
        row = [e["name"]]
        for k in ("lqr", "tsd"):
            row += [_pct(e[f"{k}_thesis"]), _pct(e[f"{k}_cfg1"]), _ratio(e[f"{k}_cfg1_ratio"]), _pct(e[f"{k}_cfg0"])]
        rows.append(row)
    return table(header, rows)


def section(d: dict) -> list[str]:
    """The reproduction section (a note when `reproduction.json` was not computed)."""
    r = d.get("reproduction")
    out = ["", "## Reproduction of the thesis", ""]
    if not r:
        return out + ["Not computed: `cargo run --release -p analysis -- reproduction --out <folder>`."]
    s = r["setting"]
    out += [
        f"The thesis's setting: {s['plant']}; the mission T1/T2 = "
        f"{s['mission']['t_transition_1']:g}/{s['mission']['t_transition_2']:g} s at "
        f"{s['mission']['v_level']:g} m/s level and {s['mission']['v_vertical']:g} m/s climb. "
        "cfg 1 = `configuration = 1` (the thesis as printed, docs/THESIS.md §1), cfg 0 = tuned.",
        "",
        "### Claims, figures and verdicts",
        "",
    ]
    out += table(
        ["claim", "thesis", "our figure (thesis's setting)", "verdict"],
        [[c["claim"], c["where"], c["figure"], c["verdict"]] for c in r["claims"]],
    )
    out += [
        "",
        f"### Table 5.1 by the method of §5.1 (level flight, N = {s['n']})",
        "",
        "Plant parameter scaled by (5.1.1), the controller keeping the nominal design model (the original "
        "gains), the closed loop linearised at the level-flight operating point (the Jacobian of the sampled "
        "map), each pole's largest excursion from nominal in % of its natural frequency, RMS over poles "
        f"faster than {s['min_omega']:g} rad/s. Ratio = ours (cfg 1) / thesis.",
        "",
    ]
    out += _t51(r)
    out += ["", METHOD_NOTES]
    sp = r["spearman"]
    out += [
        "",
        "Spearman rank correlation with the thesis's column: "
        + ", ".join(f"{k.split('_')[0].upper()} {_cfg(k.split('_')[1])} {fmt_or_dash(v, 2)}" for k, v in sp.items())
        + ".",
        "",
        "### The four conclusions of §5.2.1",
        "",
    ]
    for c in r["conclusions_5_2_1"]:
        out.append(f"- **{c['claim']}** ({c['measure']}): {c['verdict']}.")
        if "of" in c:
            ours = ", ".join(f"{_cfg(k)}: {v}" for k, v in c["ours"].items())
            out.append(f"  Holds for {ours} of {c['of']} parameters (thesis: {c['thesis']}).")
        elif "named" in c:
            t = c["ours"]
            out.append(
                "  Top three: "
                + "; ".join(f"{k.replace('_', ' ')}: {', '.join(v)}" for k, v in t.items())
                + f". Named three among cfg 1's top three: LQR {c['overlap_lqr']}, TSD {c['overlap_tsd']}."
            )
        elif "ours_cndr_ratio" in c:
            out.append(
                f"  C_nδr TSD/LQR: ours {_ratio(c['ours_cndr_ratio'])}, thesis {_ratio(c['thesis_cndr_ratio'])}; "
                f"TSD/LQR > 5 (and TSD > 10 %): ours {', '.join(c['ours_params']) or 'none'}, "
                f"thesis {', '.join(c['thesis_params']) or 'none'}."
            )
        else:
            out.append(
                "  Largest / mean entry, physical vs aerodynamic: "
                + "; ".join(
                    f"{k.upper()} {_pct(c[k]['physical_max'])} / {_pct(c[k]['physical_mean'])} % vs "
                    f"{_pct(c[k]['aero_max'])} / {_pct(c[k]['aero_mean'])} %"
                    for k in ("lqr", "tsd")
                )
                + "."
            )
    out += ["", "### Table 4.4 from Table 4.3's placement (TSD)", "", TABLE_4_4_NOTES, ""]
    rows = []
    for conf in ("cfg1", "cfg0"):
        for cond in r["table_4_4"][conf]:
            if cond.get("error"):
                rows.append([_cfg(conf), cond["condition"], cond["error"], "", "", "", ""])
                continue
            for row in cond["rows"]:
                rows.append(
                    [
                        _cfg(conf),
                        cond["condition"],
                        row["loop"],
                        _pole(row["placed"]),
                        _pole(row["achieved"]),
                        _pole(row["thesis"]),
                        _pct(row["ours_vs_thesis_pct"]),
                    ]
                )
            rows.append(
                [
                    _cfg(conf),
                    cond["condition"],
                    "rightmost closed-loop pole",
                    "",
                    _pole(cond["rightmost"]),
                    "",
                    "",
                ]
            )
    out += table(
        [
            "configuration",
            "phase",
            "loop",
            "placed (Table 4.3)",
            "achieved (ours)",
            "Table 4.4",
            "ours − thesis (% of ω_n)",
        ],
        rows,
    )
    out += [
        "",
        "### Tables 3.2/3.3: open-loop level-flight modes",
        "",
        "Our airframe's numbers the thesis omits (span, cross-inertias, the trim it linearised at) are chosen "
        "(docs/THESIS.md §4), so the modes are compared in kind and stability, not value.",
        "",
    ]
    out += table(
        ["mode", "thesis", "ours", "ω_n thesis / ours (rad/s)"],
        [
            [
                m["mode"],
                _pole(m["thesis"]),
                _pole(m["ours"]),
                f"{fmt_or_dash(m['thesis_omega_n'], 3)} / {fmt_or_dash(m['ours_omega_n'], 3)}",
            ]
            for m in r["open_loop_modes"]
        ],
    )
    out += ["", "### Missions on the thesis's setting", ""]
    rows = []
    for key, m in r["missions"].items():
        k, conf, mission = key.split("_")
        if "error" in m:
            rows.append([k.upper(), _cfg(conf), mission, m["error"], "", "", "", ""])
            continue
        rows.append(
            [
                k.upper(),
                _cfg(conf),
                f"{m['t_transition_1']:g}/{m['t_transition_2']:g} s",
                "yes" if m["passed"] else "no",
                fmt_or_dash(m["max_pos_error"], 2),
                fmt_or_dash(m["rms_pos_error"], 2),
                " / ".join(fmt_or_dash(x, 2) for x in m["phase_max"]),
                fmt_or_dash(m["alpha_max_deg"], 1),
            ]
        )
    out += table(
        [
            "controller",
            "configuration",
            "T1/T2",
            "passed",
            "max error (m)",
            "RMS error (m)",
            "max per phase V1/T1/L/T2/V2 (m)",
            "α_max T1–T2 (°)",
        ],
        rows,
    )
    out += _fast(r) + _steps(r) + _chapter6(r, d.get("reproduction_wind"))
    return out


def _fast(r: dict) -> list[str]:
    f = r.get("fast_transitions")
    if not f:
        return []
    out = [
        "",
        "### The TSD's 3/4 s transitions (App. E.1)",
        "",
        "The printed quarter loop (4.3.31–4.3.36) turns the path at V̄ linear in t over a quarter circle of "
        "radius r = (V_V + V_L) T / π; at V_L its centripetal acceleration V_L²/r asks for a load n = 1 + V_L²/(r g) "
        "at the start of T2 and 1 − V_L²/(r g) at the end of T1. With C_L0 = 0 (C.2.1) the wing gives n at "
        "α = n m g / (q̄ S C_Lα). *Demand* lists n and that α; *T for α ≤ "
        f"{f['alpha_linear_deg']:g}°* the shortest transitions whose quarter loop stays in the linear range.",
        "",
    ]
    rows = []
    for x in f["rows"]:
        dm = x["demand"]
        rows.append(
            [
                x["variant"],
                f"{x['v_vertical']:g}",
                "yes" if x["passed"] else "no",
                fmt_or_dash(x["max_pos_error"], 2),
                f"{fmt_or_dash(x['alpha_min_t1_deg'], 1)} / {fmt_or_dash(x['alpha_max_t2_deg'], 1)}",
                fmt_or_dash(x["final_pitch_error_deg"], 1),
                f"{dm['n_t1_end']:.2f} g, {dm['alpha_t1_deg']:.1f}° / "
                f"{dm['n_t2_start']:.2f} g, {dm['alpha_t2_deg']:.1f}°",
                f"{dm['t1_for_linear']:.1f} / {dm['t2_for_linear']:.1f} s",
            ]
        )
    return out + table(
        [
            "TSD",
            "V_V (m/s)",
            "passed",
            "max error (m)",
            "α min T1 / max T2 (°)",
            "final pitch error (°)",
            "demand end T1 / start T2",
            f"T1 / T2 for α ≤ {f['alpha_linear_deg']:g}°",
        ],
        rows,
    )


def _settled(x: dict) -> str:
    if not x["completed"]:
        return "lost"
    return "no" if x["settle_time"] is None else fmt_or_dash(x["settle_time"], 1)


def _steps(r: dict) -> list[str]:
    st = r.get("step_responses")
    if not st:
        return []
    out = [
        "",
        "### Position steps (§3.4.1, §4.4.2–4.4.3)",
        "",
        f"A {st['step']:g} m step of the reference (normal: up in level flight, toward the belly = north in the "
        f"climb; lateral: east), followed {st['window']:g} s; the response is the difference to the same flight "
        "without the step. Settled: within 10 % of the step. Δ = signed peak change from the value at the step; a "
        "surface counts as used at ≥ 10 % of the largest surface's peak; \"against\" = the pair's changes are "
        "negatively correlated. Roll is given in level flight only.",
        "",
    ]
    rows = []
    for x in st["rows"]:
        checks = ", ".join(f"{c['check']} {'✓' if c['shown'] else '✗'}" for c in x["checks"])
        sf = x["d_surfaces_deg"]
        rows.append(
            [
                x["controller"],
                f"cfg {x['configuration']}",
                f"{x['flight']} (V_V {x['v_vertical']:g})" if x["flight"] == "vertical" else x["flight"],
                x["axis"],
                x["where"],
                x["text"],
                "lost"
                if not x["completed"]
                else fmt_or_dash(x["settle_time"], 1)
                if x["settle_time"] is not None
                else "no",
                f"α {fmt_or_dash(x['d_alpha_deg'], 1)}, β {fmt_or_dash(x['d_beta_deg'], 1)}, "
                f"φ {fmt_or_dash(x['d_roll_deg'], 1)}, θ {fmt_or_dash(x['d_pitch_deg'], 1)}, "
                f"T {fmt_or_dash(x['d_thrust'], 1)} N",
                "/".join(fmt_or_dash(v, 2) for v in sf),
                checks,
                x["verdict"],
            ]
        )
    return out + table(
        [
            "controller",
            "configuration",
            "flight",
            "step",
            "thesis",
            "behaviour described",
            "settled (s)",
            "Δ peaks (°, N)",
            "peak Δδ e/a/r/fc/fd/v (°)",
            "checks",
            "verdict",
        ],
        rows,
    )


def _chapter6(r: dict, wind: dict | None) -> list[str]:
    six = r.get("conclusions_6_2_6")
    if not six:
        return []
    out = [
        "",
        "### Chapter 6's conclusions (§6.2.6), twice",
        "",
        "On the thesis's setting (above) and on our plant in wind: the campaign's uncertain plants "
        "(global post-stall aerodynamics, wind and gusts, perfect state)"
        + (
            f", {wind['spec'].get('tau_aero', '')} / {wind['spec'].get('tau_mass', '')} parameter spread, "
            f"wind ≤ {wind['spec'].get('wind_max', '')} m/s, gusts ≤ {wind['spec'].get('gust_max', '')} m/s, "
            f"{next(iter(wind['arms'].values()))['runs']} samples per arm."
            if wind
            else " — not computed (`python -m tailsim.reports.reproduction --wind FOLDER... --out FOLDER`)."
        ),
        "",
    ]
    w = {c["id"]: c for c in wind_conclusions(wind)} if wind else {}
    rows = []
    for c in six:
        wc = w.get(c["id"], {})
        rows.append([c["claim"], c["where"], c["figure"], c["verdict"], wc.get("figure", "—"), wc.get("verdict", "—")])
    return out + table(
        ["conclusion", "thesis", "thesis's setting", "verdict", "our plant in wind (campaign)", "verdict"], rows
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m tailsim.reports.reproduction",
        description="Write reproduction_wind.json: chapter 6's conclusions measured on campaign folders.",
    )
    ap.add_argument("--wind", nargs="+", required=True, help="campaign folders (same sample space)")
    ap.add_argument("--out", required=True, help="analysis folder to write reproduction_wind.json into")
    a = ap.parse_args(argv)
    w = wind_summary(a.wind)
    w["conclusions"] = wind_conclusions(w)
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / WIND_FILE).write_text(json.dumps(w, indent=1, allow_nan=True))
    print(out / WIND_FILE)
    return 0


if __name__ == "__main__":
    sys.exit(main())
