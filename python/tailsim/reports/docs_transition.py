"""The generated blocks of docs/TRANSITION.md (registered into `tailsim.reports.docs.BLOCKS`).

Sources: `docs/transition_flown.json` (`cargo run --release -p analysis --example
transition_flown`: the controllers on the default mission with T2 shortened) and
`docs/transition_bounds.json` (`… --example transition_bounds`: the point-mass minimum times).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from .. import declarations
from .docs import Sources, block, g

FLOWN = "transition_flown.json"
BOUNDS = "transition_bounds.json"


def _rows(src: Sources, aero: str = "thesis") -> list[Mapping[str, Any]]:
    return [r for r in src.json(FLOWN)["rows"] if r["aero"] == aero]


def _controllers(src: Sources) -> list[str]:
    return list(dict.fromkeys(r["controller"] for r in src.json(FLOWN)["rows"]))


def _t2s(src: Sources) -> list[float]:
    return list(dict.fromkeys(r["t2"] for r in src.json(FLOWN)["rows"]))


def _row(src: Sources, ctl: str, t2: float, aero: str = "thesis") -> Mapping[str, Any]:
    return next(r for r in _rows(src, aero) if r["controller"] == ctl and r["t2"] == t2)


def _s(x: float | None, nd: int = 2) -> str:
    return "–" if x is None else f"{x:.{nd}f}"


def _fastest(src: Sources, ctl: str, key: str) -> Mapping[str, Any]:
    rows = [r for r in _rows(src) if r["controller"] == ctl and r[key] is not None]
    return min(rows, key=lambda r: r[key])


@block("transition.flown.table", FLOWN)
def _flown_table(src: Sources) -> str:
    ctls = _controllers(src)
    fastest = {c: _fastest(src, c, "transition")["t2"] for c in ctls}
    head = ["T2 requested", *(f"{c} rotation / transition" for c in ctls), "profile rotation / transition"]
    head += [" / ".join(ctls) + " max pos. error (m)", " / ".join(ctls) + " max α in T2 + vertical"]
    md = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for t2 in _t2s(src):
        rs = {c: _row(src, c, t2) for c in ctls}
        cells = [g(t2)]
        for c in ctls:
            tr = _s(rs[c]["transition"])
            cells.append(f"{_s(rs[c]['rotation'])} / " + (f"**{tr}**" if fastest[c] == t2 else tr))
        p = rs[ctls[0]]
        cells.append(f"{_s(p['profile_rotation'])} / {_s(p['profile_transition'])}")
        cells.append(" / ".join(_s(rs[c]["max_pos_error"]) for c in ctls))
        cells.append(" / ".join(f"{_s(rs[c]['max_alpha_deg'], 1)}°" for c in ctls))
        md.append("| " + " | ".join(cells) + " |")
    return "\n".join(md)


@block("transition.flown.global", FLOWN)
def _flown_global(src: Sources) -> str:
    diffs, errs = [], []
    for r in _rows(src, "global"):
        t = _row(src, r["controller"], r["t2"])
        diffs += [abs(r[k] - t[k]) for k in ("rotation", "transition") if r[k] is not None and t[k] is not None]
        errs.append(r["max_pos_error"])
    return f"the same times within {max(diffs):.2f} s and position errors ≤ {max(errs):.2f} m"


@block("transition.flown.findings", FLOWN, BOUNDS)
def _flown_findings(src: Sources) -> str:
    d = src.json(FLOWN)
    ctls = _controllers(src)
    rows = _rows(src)
    t2s = _t2s(src)
    tracked = [c for c in ctls if all(r["tracked"] for r in rows if r["controller"] == c)]
    who = " and ".join(tracked)
    err = max(r["max_pos_error"] for r in rows if r["controller"] in tracked) if tracked else float("nan")
    lines = []
    if tracked:
        lines.append(
            f"* **{'Both controllers' if len(tracked) == len(ctls) == 2 else who} track every T2 down to "
            f"{g(min(t2s))} s** (the shortest flown): completed, position error ≤ {err:.2f} m, ending vertical at "
            f"{g(d['mission']['v_vertical'])} m/s."
        )
    fast = {c: _fastest(src, c, "transition") for c in ctls}
    rot = {c: _fastest(src, c, "rotation") for c in ctls}
    lines[-1:] = [
        (lines[-1] + " " if lines else "* ")
        + "The fastest *flown* back transition: "
        + "; ".join(f"{c} {fast[c]['transition']:.2f} s at T2 = {g(fast[c]['t2'])} s" for c in ctls)
        + "; the fastest rotation: "
        + "; ".join(f"{c} {rot[c]['rotation']:.2f} s at T2 = {g(rot[c]['t2'])} s" for c in ctls)
        + "."
    ]
    dev = {
        c: max(
            abs(r["transition"] - r["profile_transition"])
            for r in rows
            if r["controller"] == c and r["transition"] is not None and r["profile_transition"] is not None
        )
        for c in ctls
    }
    prof = [_row(src, ctls[0], t2) for t2 in t2s]
    p_min = min(prof, key=lambda r: r["profile_rotation"])
    shortest = min(prof, key=lambda r: r["t2"])
    t2_stop = max(fast[c]["t2"] for c in ctls)
    lines.append(
        f"* **Requested vs flown**: below T2 = {g(t2_stop)} s the requested time no longer shortens the flight; "
        "the flown transition times follow the profile's to within "
        + ", ".join(f"{dev[c]:.2f} s ({c})" for c in ctls)
        + f", i.e. the reference, not the tracking, sets them. Below T2 = {g(p_min['t2'])} s the profile's "
        f"rotation grows again ({p_min['profile_rotation']:.1f} → {shortest['profile_rotation']:.1f} s at "
        f"T2 = {g(shortest['t2'])} s)."
    )
    b = src.json(BOUNDS)
    slope = {t["trim"]: t["cl_slope_small_alpha"] for t in b["trims"]}
    amax = d["mission"]["transition_alpha_max_deg"]
    if "TSD" in ctls:
        a = [r["max_alpha_deg"] for r in rows if r["controller"] == "TSD"]
        e, fm = slope["elevator only"], slope["flap mixing"]
        lines.append(
            f"* The TSD flies the same path at {min(a):.0f}–{max(a):.0f}° instead of {g(amax)}°: its "
            "normal-acceleration loop uses the flap mixing, whose trimmed lift slope is "
            f"{fm:.2f} instead of {e:.2f} /rad ({g(amax)}° × {e:.2f}/{fm:.2f} = {amax * e / fm:.1f}°)."
        )
    return "\n".join(lines)


def _flown_range(src: Sources) -> str:
    """The flown transition times at and below the fastest requested T2, all controllers."""
    ctls = _controllers(src)
    t2_stop = max(_fastest(src, c, "transition")["t2"] for c in ctls)
    ts = [r["transition"] for r in _rows(src) if r["t2"] <= t2_stop and r["transition"] is not None]
    dev = max(
        abs(r["transition"] - r["profile_transition"])
        for r in _rows(src)
        if r["transition"] is not None and r["profile_transition"] is not None
    )
    return f"{min(ts):.1f}–{max(ts):.1f} s for T2 ≤ {g(t2_stop)} s, following the profile to {dev:.2f} s"


def _flown_range_short(src: Sources) -> str:
    return _flown_range(src).split(" for ")[0]


def _profile_min(src: Sources) -> str:
    prof = [_row(src, _controllers(src)[0], t2) for t2 in _t2s(src)]
    return (
        f"≥ {min(r['profile_rotation'] for r in prof):.1f} s and ≥ {min(r['profile_transition'] for r in prof):.1f} s"
    )


# --- the bounds -------------------------------------------------------------------------------------------------


def _bound(src: Sources, trim: str, deg: float, tau: float = 0.0, aero: str = "thesis", rates: bool = True):
    for b in src.json(BOUNDS)["bounds"]:
        if (b["trim"], b["alpha_max_deg"], b["tau_alpha"], b["aero"], b["rate_terms"]) == (trim, deg, tau, aero, rates):
            return b
    raise KeyError((trim, deg, tau, aero, rates))


def _trims(src: Sources) -> list[str]:
    return [t["trim"] for t in src.json(BOUNDS)["trims"]]


def _alphas(src: Sources) -> list[float]:
    return list(dict.fromkeys(b["alpha_max_deg"] for b in src.json(BOUNDS)["bounds"]))


def _span(xs: list[float], nd: int = 2, unit: str = "") -> str:
    lo, hi = f"{min(xs):.{nd}f}", f"{max(xs):.{nd}f}"
    return (lo if lo == hi else f"{lo}–{hi}") + unit


def _signed(x: float, nd: int = 1) -> str:
    return f"{x:+.{nd}f}".replace("-", "−")


@block("transition.trim.table", BOUNDS)
def _trim_table(src: Sources) -> str:
    b = src.json(BOUNDS)
    v = g(b["v_level"])
    md = [
        f"| trim | C_Lt/α (small α) | C_Lt(12°) | C_Lt(15°) | n = L/(m g) at {v} m/s, 15° "
        f"| with thrust: (L + T sin α)/(m g), T = T_trim … T_max | δ at {v} m/s, 15°, T = 0 |",
        "|---|---|---|---|---|---|---|",
    ]
    for t in b["trims"]:
        by = {a["alpha_deg"]: a for a in t["alpha"]}
        a15 = by[15.0]["at_25_m_s"]
        d0 = a15[0]
        delta = f"δe {_signed(d0['delta_e_deg'])}°"
        if t["trim"] != "elevator only":
            at_limit = abs(d0["delta_fc_deg"]) >= math.degrees(declarations.DEFLECTION_LIMIT) - 1e-6
            delta += f", δfc {_signed(d0['delta_fc_deg'])}°" + (" (saturated)" if at_limit else "")
        md.append(
            f"| {t['trim']} | {t['cl_slope_small_alpha']:.2f} /rad | {by[12.0]['cl_trimmed']:.3f} | "
            f"{by[15.0]['cl_trimmed']:.3f} | {_span([x['n_aero'] for x in a15])} | "
            f"{a15[1]['n_total']:.2f} … {a15[2]['n_total']:.2f} | {delta} |"
        )
    return "\n".join(md)


def _switching(b: dict, first: bool) -> str:
    r = b["rotation"] if b.get("_manoeuvre") == "rotation" else b["complete"]
    if b.get("_manoeuvre") == "rotation":
        return "α_max, T_max, no switch" if r["t_cut"] is None else f"T_max → 0 at {r['t_cut']:.2f} s"
    if first:
        return (
            f"T_max → 0 at {r['t_cut']:.2f} s → T_max at V = {r['v_on']:.1f} m/s; α_max to γ = "
            f"{r['gamma_s_deg']:.0f}°, then −α_max → hold"
        )
    return f"cut at {r['t_cut']:.2f} s, on at {r['v_on']:.1f} m/s; α_max to γ = {r['gamma_s_deg']:.0f}°"


@block("transition.bound.table", BOUNDS)
def _bound_table(src: Sources) -> str:
    lag = src.json(BOUNDS)["alpha_lag"]
    md = [
        f"| manoeuvre | trim | α_max | τ_α = 0 (α direct) | τ_α = {g(lag)} s | peak n (τ_α = 0) "
        "| switching (τ_α = 0) |",
        "|---|---|---|---|---|---|---|",
    ]
    for man in ("rotation", "complete"):
        first = True
        for trim in _trims(src):
            for deg in _alphas(src):
                b0, b1 = _bound(src, trim, deg), _bound(src, trim, deg, lag)
                r0, r1 = b0[man], b1[man]
                sw = _switching({**b0, "_manoeuvre": man}, first)
                first = False
                md.append(
                    f"| {man} | {trim} | {g(deg)}° | **{r0['time']:.2f}** | {r1['time']:.2f} | "
                    f"{r0['peak_n']:.2f} ({r0['peak_n_total']:.2f}) at {r0['v_at_peak']:.1f} m/s | {sw} |"
                )
    return "\n".join(md)


@block("transition.bound.findings", BOUNDS)
def _bound_findings(src: Sources) -> str:
    b = src.json(BOUNDS)
    lag = b["alpha_lag"]
    rows = [(t, a) for t in _trims(src) for a in _alphas(src)]

    def cost(man: str) -> list[float]:
        return [_bound(src, t, a, lag)[man]["time"] - _bound(src, t, a)[man]["time"] for t, a in rows]

    def times(man: str, **kw) -> str:
        return " / ".join(f"{_bound(src, t, a, **kw)[man]['time']:.2f}" for t, a in rows)

    peak_v = [_bound(src, t, a)["rotation"]["v_at_peak"] for t, a in rows]
    n15 = [
        x["n_aero"]
        for t in b["trims"]
        for a in t["alpha"]
        if a["alpha_deg"] == max(_alphas(src))
        for x in a["at_25_m_s"]
    ]
    flap = {a: _bound(src, "flap mixing", a)["complete"]["max_flap_deg"] for a in _alphas(src)}
    return "\n".join(
        [
            f"* **α lag**: {g(lag)} s on α costs {_span(cost('rotation'), unit=' s')} in the rotation and "
            f"{_span(cost('complete'), unit=' s')} in the complete transition (α builds up in ≈ 2τ_α, and the "
            "arrival needs α back at 0).",
            "* **Pitch-rate derivatives** (C_Lq, C_mq at q ≈ γ̇ ≈ 1 rad/s) help: without them the rotation takes "
            f"{times('rotation', rates=False)} s (rows 1–{len(rows)}, τ_α = 0).",
            f"* **Global aerodynamics** (plant FMU default), τ_α = 0: rotation {times('rotation', aero='global')} s, "
            f"complete {times('complete', aero='global')} s (same row order), same switching structure.",
            f"* The peak load of the rotation comes late, at {min(peak_v):.0f}–{max(peak_v):.0f} m/s: full thrust "
            "accelerates the aircraft while it pulls up. At V_L it is the "
            f"{min(n15):.1f}–{max(n15):.1f} g of the table above. No structural load limit is known for this "
            "airframe; a load limit would lengthen the rotation.",
            "* The deflection limits hold on every optimal trajectory (flap mixing runs the flaps at "
            + " and ".join(f"{flap[a]:.1f}° at {g(a)}°" for a in sorted(flap, reverse=True))
            + ", in the low-thrust deceleration).",
        ]
    )


@block("transition.comparison", BOUNDS, FLOWN)
def _comparison(src: Sources) -> str:
    lag = src.json(BOUNDS)["alpha_lag"]
    a_m = src.json(FLOWN)["mission"]["transition_alpha_max_deg"]
    a_lo, a_hi = min(_alphas(src)), max(_alphas(src))
    e = _bound(src, "elevator only", round(a_m), lag)
    f_lo, f_hi = _bound(src, "flap mixing", a_lo, lag), _bound(src, "flap mixing", a_hi, lag)
    f0_hi = _bound(src, "flap mixing", a_hi)
    e_hi = [_bound(src, "elevator only", a_hi, t)["complete"]["time"] for t in (0.0, lag)]
    flown_min = min(r["transition"] for r in src.json(FLOWN)["rows"] if r["transition"] is not None)
    reach = [f0_hi["complete"]["time"], f_hi["complete"]["time"]]
    return (
        f"α_max = {g(a_m)}° the profile's own model (elevator-only lift, τ_α = {g(lag)} s) allows a "
        f"rotation in {e['rotation']['time']:.2f} s and a complete transition in {e['complete']['time']:.2f} s; the "
        f"profile takes {_profile_min(src)}, and the controllers fly it. About "
        f"{flown_min - e['complete']['time']:.0f} s of the flown {_flown_range_short(src)} are the profile's law, not "
        "the airframe (its ingredients — speed held near V_L while the path turns, at most "
        f"{g(src.json(FLOWN)['mission']['transition_thrust_fraction'])} T_max, thrust floor, smootherstep tracking, "
        "speed shed as the path nears vertical — were not separated here). With the TSD's flap mixing the airframe "
        f"allows {f_lo['rotation']['time']:.2f} s and "
        f"{f_lo['complete']['time']:.2f} s at {g(a_lo)}°; at α_max = {g(a_hi)}° {f_hi['rotation']['time']:.2f} s "
        f"and {f_hi['complete']['time']:.2f} s. A back transition in ≤ 3 s to the steady climb is therefore "
        + (
            f"reachable for this airframe inside {g(a_hi)}° with flap mixing ({_span(reach, 1)} s), not with the "
            f"elevator alone (≥ {min(e_hi):.1f} s) and not at {g(a_lo)}°."
            if min(reach) <= 3.0 < min(e_hi)
            else f"{'reachable' if min(reach) <= 3.0 else 'not reachable'} inside {g(a_hi)}° with flap mixing "
            f"({_span(reach, 1)} s); with the elevator alone ≥ {min(e_hi):.1f} s."
        )
    )


@block("transition.alpha_lag", BOUNDS)
def _alpha_lag(src: Sources) -> str:
    return f"{g(src.json(BOUNDS)['alpha_lag'])} s"


@block("transition.trim.findings", BOUNDS)
def _trim_findings(src: Sources) -> str:
    b = src.json(BOUNDS)
    t = {x["trim"]: x for x in b["trims"]}
    e, fm = t["elevator only"]["cl_slope_small_alpha"], t["flap mixing"]["cl_slope_small_alpha"]
    wing = declarations.VARIABLES["tailsitter_plant"]["c_L_alpha_a0"].start
    flaps = {a["alpha_deg"]: a["at_25_m_s"][0]["delta_fc_deg"] for a in t["flap mixing"]["alpha"]}
    limit = math.degrees(declarations.DEFLECTION_LIMIT)
    hi, lo = max(flaps), min(flaps)
    flap_hi = (
        f"flaps reach their {limit:.0f}° limit (the remaining moment goes to the elevator)"
        if abs(flaps[hi]) >= limit - 1e-6
        else f"flaps need {abs(flaps[hi]):.0f}°"
    )
    return (
        f"equals the profile's C_Lα from the level trim ({e:.2f} /rad: the elevator's "
        f"download costs {100 * (1 - e / wing):.0f} % of the wing's {wing:.2f} /rad). The mixed actuator has a "
        "small *negative* lift derivative and trims nose-up with a negative δm, so its trim lift *adds* to the "
        f"wing's: {_signed(100 * (fm / wing - 1), 0)} % instead of {_signed(100 * (e / wing - 1), 0)} %. At "
        f"{g(hi)}° and low thrust the {flap_hi}, at {g(lo)}° they need {abs(flaps[lo]):.0f}°."
    )


@block("transition.bound.global_change", BOUNDS)
def _global_change(src: Sources) -> str:
    d = []
    for t in _trims(src):
        for a in _alphas(src):
            gl, th = _bound(src, t, a, aero="global"), _bound(src, t, a)
            d += [gl[m]["time"] - th[m]["time"] for m in ("rotation", "complete")]
    return f"{_signed(min(d), 2)} … {_signed(max(d), 2)} s"


def _complete_bounds(src: Sources) -> list[dict]:
    return [b["complete"] for b in src.json(BOUNDS)["bounds"] if b["complete"] is not None and b["aero"] == "thesis"]


@block("transition.bound.holds", BOUNDS)
def _holds(src: Sources) -> str:
    cs = _complete_bounds(src)
    n = sum(c["holds"] for c in cs)
    return "all cases do" if n == len(cs) else f"{n} of {len(cs)} cases do"


@block("transition.bound.entry", BOUNDS)
def _entry(src: Sources) -> str:
    return _span([c["time"] - c["entry"] for c in _complete_bounds(src)], unit=" s")


@block("transition.flown.setting", FLOWN)
def _flown_setting(src: Sources) -> str:
    m = src.json(FLOWN)["mission"]
    return (
        f"(T1 = {g(m['t_transition_1'])} s, level {g(m['t_level'])} s, T2 varied, vertical "
        f"{g(m['t_vertical_2'])} s; profile α_max = {m['transition_alpha_max_deg']:.0f}°, thrust fraction "
        f"{g(m['transition_thrust_fraction'])}, Gauss-Seidel, {g(1e3 * m['sample_time'])} ms)"
    )


@block("transition.flown.pos_limit", FLOWN)
def _pos_limit(src: Sources) -> str:
    return f"{g(src.json(FLOWN)['pos_error_limit'])} m"
