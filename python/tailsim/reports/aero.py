"""The thesis's linear aerodynamics (`aero_model` = 0) against the global model
(`aero_model` = 1, the plant FMU's default), side by side: a section of the
analysis report rendered from `aero_models.json` (+ `aero_coefficients.csv`),
which `cargo run --release -p analysis -- all|aero --out DIR` writes.

    cargo run --release -p analysis -- aero --out out/analysis
    .venv/bin/python -m tailsim.reports.analysis out/analysis

Tables: the flight cases (default and fast mission, hover wind steps) and the
analysis's gust sweep, each with the thesis / global values side by side and
what changed; the parameter sweep of Table 5.1 on both models is in the
robustness section (`tailsim.reports.analysis`, rendered with
`robustness_changes` from here). Writes `aero_models.md`
(via `tailsim.reports.analysis`) and the plots
`aero_coefficients.png` (C_L, C_D, C_m of both models over α = 0…180°) and
`aero_flights.png` (largest position error of every flight).
"""

from __future__ import annotations

import json
import math
import pathlib

from . import load_json_into
from .markdown import fmt_or_dash, shortest, table_head

FILE = "aero_models.json"

#: Below this stall fraction a run counts as flown in attached flow.
ATTACHED = 0.01

MODEL_NOTES = (
    "What the global model changes (crates/tailsitter-physics/README.md, 'Global aerodynamic model'): inside "
    "attached flow (|α| ≤ {aa}°, |β| ≤ 15°) it is the thesis's model to rounding, so trims, modes, Table 5.1 and "
    "every run that stays there are unchanged. Beyond it, the thesis's lift keeps growing linearly "
    "(C_L = C_L0 + C_Lα α: {cl90:.1f} at 90°, {ratio:.1f} times the broadside normal force C_D90 = {cd90:.3f} a "
    "flat plate can produce) while the global model blends C¹ into a flat plate by {as_}°: the lift saturates "
    "(C_Lmax {clmax:.2f} near {at:.0f}°), the drag rises to C_D90 broadside, the centre of pressure moves aft to "
    "mid-chord, the control surfaces fade with the chordwise flow, and the part of the wing in the propeller "
    "slip-stream follows its own local flow (it stays attached at high thrust). Tail first (α near 180°) the wing "
    "lifts again as a section flown backwards (C_L {clrev:.2f} at {atrev:.0f}°) and stalls early "
    "({ra}°–{rs}° from 180°). Where a run leaves attached flow the thesis's model gives the aircraft lift, "
    "restoring moments and control authority a real wing does not have, so the two models differ there — the "
    "verdict column says in which direction. The controllers are not retuned: where one now fails, "
    "the table says so. What the global model leaves out: it is quasi-steady (no dynamic stall, stall hysteresis "
    "or stall delay in fast pitch-ups, which add transient lift and pitching moment in the quickest transitions), has "
    "no jet-height correction of the slip-stream strip (it overestimates slip-stream lift in a crosswind), and "
    "stalls symmetrically (no spin autorotation)."
)


def load_into(d: dict, folder: str | pathlib.Path) -> dict:
    """Add `aero_models.json` of `folder` (if the campaign wrote it) to the report data `d`."""
    return load_json_into(d, folder, FILE, "aero_models")


def _num(x) -> float:
    return float("nan") if x is None else float(x)


def why(thesis: dict, glob: dict, alpha_attached: float = 10.0, beta_attached: float = 15.0) -> str:
    """Why the global model's run differs, from the data: where the thesis's model was used
    outside attached flow, and whether the error is mostly height."""
    parts = []
    ta, tb = _num(thesis["max_alpha_deg"]), _num(thesis["max_beta_deg"])
    ga = _num(glob["max_alpha_deg"])
    if ta > alpha_attached and ta < 90:
        text = (
            f"the thesis's model flew it at α up to {ta:.0f}° (attached flow ends at {shortest(alpha_attached)}°), "
            "where its linear lift exceeds what a stalled wing gives"
        )
        if ga > 150:
            text += f"; with the lift capped it tumbles (α {ga:.0f}°)"
        elif ga > ta + 1:
            text += f"; with the lift capped it needs more α ({ga:.0f}°)"
        parts.append(text)
    elif ga > 150 and ta < 150:
        parts.append(f"it tumbles (α {ga:.0f}°)")
    if tb > beta_attached and tb < 89:
        parts.append(
            f"in the side wind the thesis's model reached β {tb:.0f}° (attached ≤ {shortest(beta_attached)}°) with its "
            "side force and restoring roll/yaw moments still growing linearly; the global model bounds them"
        )
    e, h = _num(glob["max_pos_error_m"]), _num(glob["max_alt_dev_m"])
    if math.isfinite(e) and e > 1.0 and h > 0.8 * e:
        parts.append(f"the error is mostly height ({h:.1f} of {e:.1f} m)")
    return "; ".join(parts)


def verdict(thesis: dict, glob: dict, alpha_attached: float = 10.0, beta_attached: float = 15.0) -> str:
    """What changed from the thesis's model to the global one, and why, in words."""
    st, sg = _num(thesis["max_stall_fraction"]), _num(glob["max_stall_fraction"])
    reason = why(thesis, glob, alpha_attached, beta_attached)
    reason = f": {reason}" if reason else ""
    if thesis["passed"] and not glob["passed"]:
        return f"LOST with the global model ({glob['failure'] or 'mission criteria missed'}){reason}"
    if glob["passed"] and not thesis["passed"]:
        return (
            "saved by the global model: the thesis's model fails here "
            f"({thesis['failure'] or 'mission criteria missed'}; its forces past stall are not physical)"
        )
    if not thesis["passed"] and not glob["passed"]:
        return "lost with both models"
    if max(st, sg) < ATTACHED:
        return "unchanged: attached flow throughout"
    de = _num(glob["max_pos_error_m"]) - _num(thesis["max_pos_error_m"])
    da = _num(glob["max_alpha_deg"]) - _num(thesis["max_alpha_deg"])
    if abs(de) < 0.05 and abs(da) < 0.5:
        return f"unchanged within 0.05 m: left attached flow only briefly (stall fraction ≤ {max(st, sg):.2f})"
    word = "worse" if de > 0 else "better"
    return (
        f"passes with both; {word} with the global model (error {de:+.2f} m, max α {da:+.1f}°, "
        f"stall fraction up to {sg:.2f}){reason}"
    )


def _pair(t, g, digits=1) -> str:
    return f"{fmt_or_dash(_num(t), digits)} / {fmt_or_dash(_num(g), digits)}"


def section(d: dict) -> list[str]:
    """Markdown lines of the section (empty if the campaign did not write the data)."""
    a = d.get("aero_models")
    if not a:
        return []
    c = a["coefficients"]
    alphas = c["alpha_deg"]
    gl = c["global"]["c_L"]
    i90 = alphas.index(90.0) if 90.0 in alphas else len(alphas) // 2
    fwd = [(v, al) for v, al in zip(gl, alphas, strict=False) if al <= 60]
    clmax, at = max(fwd)
    rev = [(-v, al) for v, al in zip(gl, alphas, strict=False) if al >= 150]
    clrev, atrev = max(rev) if rev else (float("nan"), float("nan"))
    cl90 = c["thesis"]["c_L"][i90]
    out = [
        "",
        "## Thesis (linear) against global aerodynamics (beyond the thesis)",
        "",
        MODEL_NOTES.format(
            aa=shortest(round(c["alpha_attached_deg"], 6)),
            as_=shortest(round(c["alpha_stalled_deg"], 6)),
            ra=shortest(round(c["alpha_reverse_attached_deg"], 6)),
            rs=shortest(round(c["alpha_reverse_stalled_deg"], 6)),
            cl90=cl90,
            ratio=cl90 / c["c_D_90"],
            cd90=c["c_D_90"],
            clmax=clmax,
            at=at,
            clrev=-clrev,
            atrev=atrev,
        ),
        "",
        "Both controllers (untuned) fly each case on a plant with each model, native closed loop, ground "
        f"{shortest(a['ground_height_m'])} m below the start (touching it ends the run as lost). Cells: thesis / "
        "global. Completed = reached the stop time without failure or ground contact; for the missions also the "
        "mission criteria. Altitude deviation = largest |altitude − reference altitude|. Stall fraction = share of "
        "the wing in post-stall flow (for the thesis's model: how far outside its validity it was used).",
        "",
        "| case | controller | completed | max α (°) | max β (°) | max pos. err (m) | max alt. dev (m) "
        "| max stall fraction | what changed |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    desc = {x["id"]: x["description"] for x in a["cases"]}
    by = {(r["case"], r["controller"], r["aero_model"]): r for r in a["rows"]}
    for case in [x["id"] for x in a["cases"]]:
        for ctl in d.get("controllers") or sorted({r["controller"] for r in a["rows"]}):
            t, g = by.get((case, ctl, 0)), by.get((case, ctl, 1))
            if t is None or g is None:
                continue
            yes = {True: "yes", False: "**no**"}
            out.append(
                f"| {desc[case]} | {ctl} | {yes[t['passed']]} / {yes[g['passed']]} "
                f"| {_pair(t['max_alpha_deg'], g['max_alpha_deg'])} "
                f"| {_pair(t['max_beta_deg'], g['max_beta_deg'])} "
                f"| {_pair(t['max_pos_error_m'], g['max_pos_error_m'], 2)} "
                f"| {_pair(t['max_alt_dev_m'], g['max_alt_dev_m'], 2)} "
                f"| {_pair(t['max_stall_fraction'], g['max_stall_fraction'], 2)} "
                f"| {verdict(t, g, c['alpha_attached_deg'], 15.0)} |"
            )
    ctls = d.get("controllers") or sorted({r["controller"] for r in a["rows"]})
    out += gust_table(a, ctls)
    out += sweep_summary(d)
    lost = [f"{r['controller']} — {desc[r['case']]}" for r in a["rows"] if r["aero_model"] == 1 and not r["passed"]]
    out += [
        "",
        "Lost with the global model (the FMU's default): " + ("; ".join(lost) if lost else "none") + ".",
        "",
        f"Coefficient curves (`aero_coefficients.csv`, plot `aero_coefficients.png`): both models at "
        f"{shortest(c['airspeed_m_s'])} m/s, β = 0, no thrust, no rotation, surfaces neutral; C_m about the CG.",
    ]
    return out


def gust_table(a: dict, controllers: list[str]) -> list[str]:
    """The analysis's gust sweep flown on both models: largest survived amplitude."""
    g = a.get("gusts")
    if not g or not g["rows"]:
        return []
    amps = g["amplitudes"]
    out = [
        "",
        "### Gust sweep on both models",
        "",
        f"The gust sweep of the analysis (1−cos, {shortest(g['duration_s'])} s, along one NED axis, default "
        f"mission, amplitudes {shortest(amps[0])}…{shortest(amps[-1])} m/s) flown on both models with the same "
        "ground: largest amplitude A such that every amplitude ≤ A passes the mission criteria without touching "
        "the ground. Cells: thesis / global.",
        "",
    ]
    out += table_head(["phase", "axis", *(f"{k} (m/s)" for k in controllers), "changed"])
    by = {(r["phase"], r["axis"], r["controller"], r["aero_model"]): r for r in g["rows"]}
    cases: list[tuple[str, str]] = []
    for r in g["rows"]:
        if (r["phase"], r["axis"]) not in cases:
            cases.append((r["phase"], r["axis"]))
    for ph, axis in cases:
        line = f"| {ph} | {axis} |"
        changes = []
        for k in controllers:
            t, gl = by.get((ph, axis, k, 0)), by.get((ph, axis, k, 1))
            if t is None or gl is None:
                line += " – |"
                continue
            line += f" {t['largest_survived']:.0f} / {gl['largest_survived']:.0f} |"
            if gl["largest_survived"] < t["largest_survived"]:
                changes.append(f"{k} lower with the global model")
            elif gl["largest_survived"] > t["largest_survived"]:
                changes.append(f"{k} higher with the global model")
        out.append(line + f" {'; '.join(changes) if changes else 'same'} |")
    return out


def sweep_summary(d: dict) -> list[str]:
    """Pointer to the robustness sweep flown on both models, with its pass counts."""
    rb = d.get("robustness")
    if not rb or sorted(rb.get("aero_models") or [0]) != [0, 1]:
        return []

    def counts(rows: list[dict]) -> str:
        def of(m: int, key: str) -> int:
            return sum(r[key] for r in rows if r["aero_model"] == m)

        return f"thesis {of(0, 'passes')}/{of(0, 'points')}, global {of(1, 'passes')}/{of(1, 'points')}"

    text = (
        "The parameter sweep of Table 5.1 (every parameter, every factor of the sweep, both controllers) is flown "
        "on both models in the nonlinear robustness section, side by side with what changed and why. Flights "
        f"passing the mission criteria: {counts(rb['rows'])}"
    )
    w = rb.get("wide")
    if w:
        text += f" (wider sweep τ^{shortest(w['tau_power'])}: {counts(w['rows'])})"
    return ["", "### Parameter sweep on both models", "", text + "."]


#: A worst position error that moves by more than this (m) counts as changed.
ERROR_CHANGE = 0.05


def _sweep_changed(t: dict, g: dict) -> bool:
    """Whether one parameter's sweep (thesis row `t`, global row `g`) differs between the models."""
    if t["passes"] != g["passes"] or t["range"] != g["range"]:
        return True
    et, eg = _num(t["worst_pos_error"]), _num(g["worst_pos_error"])
    if math.isfinite(et) != math.isfinite(eg):
        return True
    return math.isfinite(et) and abs(eg - et) > ERROR_CHANGE


def _n(count: int, word: str) -> str:
    """`1 sweep`, `2 sweeps`."""
    return f"{count} {word}{'' if count == 1 else 's'}"


def robustness_changes(d: dict, rows: list[dict], alpha_attached: float = 10.0, nominal: bool = True) -> list[str]:
    """Which results of a robustness sweep flown on both models (rows with `aero_model` 0 and
    1) changed, and why, in words generated from the rows: per controller the nominal
    flight on both models, the sweeps that pass at fewer / more factors on the global model,
    the largest change of the worst position error, and whether the changed sweeps left
    attached flow (where the models differ) while the unchanged ones stayed in it.
    `nominal`: also state the nominal flight (factor 1) on both models."""
    by = {(r["param"], r["controller"], r.get("aero_model", 0)): r for r in rows}
    names = {p["id"]: p["name"] for p in d["params"]}
    out = ["Linear against global (generated from the rows above):", ""]
    for k in d["controllers"]:
        pairs = [(pid, by[pid, k, 0], by[pid, k, 1]) for pid in names if (pid, k, 0) in by and (pid, k, 1) in by]
        if not pairs:
            continue
        parts = []
        nt, ng = pairs[0][1].get("nominal"), pairs[0][2].get("nominal")
        if nominal and nt and ng:
            ok = {True: "passes", False: "**fails**"}
            parts.append(
                f"the nominal airframe (factor 1) {ok[nt['passed']]} / {ok[ng['passed']]}, position error "
                f"{_pair(nt['max_pos_error'], ng['max_pos_error'], 2)} m, max α "
                f"{_pair(nt['max_alpha_deg'], ng['max_alpha_deg'], 0)}°, stall fraction "
                f"{_pair(nt['max_stall_fraction'], ng['max_stall_fraction'], 2)}"
            )
        fewer = [(pid, t, g) for pid, t, g in pairs if g["passes"] < t["passes"]]
        more = [(pid, t, g) for pid, t, g in pairs if g["passes"] > t["passes"]]
        same = len(pairs) - len(fewer) - len(more)
        text = f"{same} of {_n(len(pairs), 'sweep')} pass at as many factors on both models"

        def listing(xs):
            return ", ".join(f"{names[pid]} {t['passes']} → {g['passes']}" for pid, t, g in xs)

        if fewer:
            text += f"; fewer on the global model: {listing(fewer)}"
        if more:
            text += f"; more on the global model: {listing(more)}"
        parts.append(text)
        moved = [
            (abs(_num(g["worst_pos_error"]) - _num(t["worst_pos_error"])), pid, t, g)
            for pid, t, g in pairs
            if math.isfinite(_num(t["worst_pos_error"]))
            and math.isfinite(_num(g["worst_pos_error"]))
            and abs(_num(g["worst_pos_error"]) - _num(t["worst_pos_error"])) > ERROR_CHANGE
        ]
        if moved:
            _, pid, t, g = max(moved, key=lambda x: x[0])
            parts.append(
                f"the worst position error moves by more than {shortest(ERROR_CHANGE)} m in {_n(len(moved), 'sweep')} "
                f"(most: {names[pid]}, {_pair(t['worst_pos_error'], g['worst_pos_error'], 2)} m)"
            )
        else:
            parts.append(f"no worst position error moves by more than {shortest(ERROR_CHANGE)} m")
        out.append(f"- **{k}**: " + "; ".join(parts) + ".")
    out += ["", why_sweeps(d, rows, alpha_attached)]
    return out


def why_sweeps(d: dict, rows: list[dict], alpha_attached: float = 10.0) -> str:
    """Why the changed sweeps changed: whether they left attached flow, from the rows."""
    by = {(r["param"], r["controller"], r.get("aero_model", 0)): r for r in rows}
    names = {p["id"]: p["name"] for p in d["params"]}
    changed, changed_attached, same_attached, same_stalled = [], [], 0, 0
    fewer = more = 0
    for k in d["controllers"]:
        for pid in names:
            t, g = by.get((pid, k, 0)), by.get((pid, k, 1))
            if t is None or g is None:
                continue
            stalled = max(_num(t["max_stall_fraction"]), _num(g["max_stall_fraction"])) > 0.0
            if _sweep_changed(t, g):
                (changed if stalled else changed_attached).append((k, pid, t, g))
                fewer += g["passes"] < t["passes"]
                more += g["passes"] > t["passes"]
            elif stalled:
                same_stalled += 1
            else:
                same_attached += 1
    if not changed and not changed_attached:
        return "Why: nothing changed — " + (
            "every flight stayed in attached flow, where the global model is the thesis's."
            if not same_stalled
            else f"{_n(same_stalled, 'sweep')} left attached flow, but too briefly or too little to change a result."
        )
    text = "Why: "
    if changed:
        alpha = max(max(_num(t["max_alpha_deg"]), _num(g["max_alpha_deg"])) for _, _, t, g in changed)
        stall = max(max(_num(t["max_stall_fraction"]), _num(g["max_stall_fraction"])) for _, _, t, g in changed)
        text += (
            f"{'the changed sweep' if len(changed) == 1 else f'all {len(changed)} changed sweeps'} left attached "
            "flow (stall "
            f"fraction > 0: part of the wing beyond |α| = {shortest(alpha_attached)}° or at large β; α up to "
            f"{alpha:.0f}°, stall fraction up to {stall:.2f}), where the thesis's lift, moments and control power "
            "keep growing linearly while the global model's saturate into flat-plate behaviour (lift capped, drag "
            "rising to broadside, centre of pressure moving aft, control surfaces fading)"
        )
        reasons = []
        if fewer:
            reasons.append(
                f"in {fewer} of them the global model's lost lift and control power past stall costs passing factors"
            )
        if more:
            reasons.append(f"in {more} of them the thesis's unphysical post-stall forces were what failed the mission")
        if reasons:
            text += "; " + ", and ".join(reasons)
        text += ". "
        if changed_attached:
            text = text.replace("Why: all ", "Why: ", 1).replace("Why: the changed sweep", "Why: one changed sweep", 1)
    if changed_attached:
        text += (
            f"{_n(len(changed_attached), 'sweep')} changed without leaving attached flow "
            f"({', '.join(f'{k} {names[pid]}' for k, pid, _, _ in changed_attached)}): not explained by the stall "
            "model. "
        )
    text += (
        f"{_n(same_attached, 'sweep')} stayed in attached flow on both models and fly identically (the global model "
        "is the thesis's there)"
    )
    if same_stalled:
        text += f"; {same_stalled} left attached flow without a result changing"
    return text + "."


def plot(folder: str | pathlib.Path) -> list[pathlib.Path]:
    """`aero_coefficients.png` and `aero_flights.png` from the data in `folder`."""
    folder = pathlib.Path(folder)
    path = folder / FILE
    if not path.exists():
        return []
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    a = json.loads(path.read_text())
    c = a["coefficients"]
    al = c["alpha_deg"]
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    for ax, key, name in zip(axes, ["c_L", "c_D", "c_m"], ["C_L", "C_D", "C_m (CG)"], strict=False):
        ax.plot(al, c["thesis"][key], "--", label="thesis (aero_model 0)")
        ax.plot(al, c["global"][key], label="global (aero_model 1)")
        ax.axvspan(c["alpha_attached_deg"], c["alpha_stalled_deg"], color="0.85", lw=0)
        ax.axvspan(180 - c["alpha_reverse_stalled_deg"], 180 - c["alpha_reverse_attached_deg"], color="0.85", lw=0)
        ax.set_xlabel("α (deg)")
        ax.set_title(name, fontsize=10)
        ax.set_xlim(0, 180)
        ax.grid(alpha=0.3)
    lim = 2.5 * c["c_D_90"]
    for ax in axes:
        lo, hi = ax.get_ylim()
        ax.set_ylim(max(lo, -lim), min(hi, lim))
    axes[0].legend(fontsize=8)
    fig.suptitle("Aerodynamic coefficients of both models (grey: blend bands)", fontsize=10)
    fig.tight_layout()
    out = [folder / "aero_coefficients.png"]
    fig.savefig(out[0], dpi=110)
    plt.close(fig)

    rows = a["rows"]
    labels = []
    vals = {0: [], 1: []}
    for case in [x["id"] for x in a["cases"]]:
        for ctl in sorted({r["controller"] for r in rows}):
            got = {r["aero_model"]: r for r in rows if r["case"] == case and r["controller"] == ctl}
            if len(got) < 2:
                continue
            labels.append(f"{case}\n{ctl}")
            for m in (0, 1):
                v = _num(got[m]["max_pos_error_m"])
                vals[m].append(v if math.isfinite(v) else 0.0)
    fig, ax = plt.subplots(figsize=(max(6, 0.7 * len(labels)), 4))
    xs = range(len(labels))
    ax.bar([x - 0.2 for x in xs], vals[0], 0.4, label="thesis (aero_model 0)")
    ax.bar([x + 0.2 for x in xs], vals[1], 0.4, label="global (aero_model 1)")
    ax.set_yscale("log")
    ax.set_xticks(list(xs))
    ax.set_xticklabels(labels, fontsize=7)
    ax.set_ylabel("largest position error (m)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    out.append(folder / "aero_flights.png")
    fig.savefig(out[1], dpi=110)
    plt.close(fig)
    return out
