"""The "Reproduction of the thesis" section of the analysis report, rendered from
`reproduction.json` (`cargo run --release -p analysis -- reproduction --out out/analysis`,
`crates/analysis/src/reproduction.rs`): both controllers as printed (`configuration = 1`)
beside the tuned ones on the thesis's own setting (linear aerodynamics, true state, calm
air, nominal plant). Every number comes from the result file."""

from __future__ import annotations

import pathlib

from . import load_json_into
from .markdown import fmt_or_dash, fmt_pole, table

FILE = "reproduction.json"

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
    """Add `reproduction.json` of `folder` (if written) to the report data `d`."""
    return load_json_into(d, folder, FILE, "reproduction")


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
    return out
