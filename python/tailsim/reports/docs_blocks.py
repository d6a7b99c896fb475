"""The generated blocks of docs/*.md (registered into `tailsim.reports.docs.BLOCKS`).

Sources: `docs/campaign_full_run.json`, `docs/campaign_rerun_200.json` (campaign summaries,
`python -m tailsim.campaign.section --write`), `docs/reproduction.json` (the part of
`analysis reproduction`'s reproduction.json the docs quote, taken by
`python -m tailsim.reports.docs --write --reproduction FILE`), and the definitions: the
declarations (`tailsim.declarations`) and the campaign's defaults (`CampaignSpec`).
Keys `def.<scope>.<name>` are definitions resolved by `definition` (no registration).
"""

from __future__ import annotations

import json
import math
import re
import statistics
from collections.abc import Mapping
from typing import Any

from .. import declarations
from .docs import Sources, block, f, g, interval, pct

FULL = "campaign_full_run.json"
RERUN = "campaign_rerun_200.json"
REPRO = "reproduction.json"


# --- definitions ------------------------------------------------------------------------------------------------

#: Units of the campaign's defaults (`CampaignSpec` fields).
_SPEC_UNITS = {
    "wind_max": "m/s",
    "gust_max": "m/s",
    "divergence_m": "m",
    "error_limit_m": "m",
    "timeout_s": "s",
    "step_size": "s",
}
_LIMITS = {"thrust_max": (declarations.THRUST_LIMITS[1], "N"), "deflection": (declarations.DEFLECTION_LIMIT, "rad")}


#: How a declared unit is written in prose.
_UNIT_TEXT = {"m2": "m²", "m/s2": "m/s²", "kg/m3": "kg/m³", "kg.m2": "kg m²"}


def with_unit(x: float, unit: str | None) -> str:
    """A declared value in its unit as the docs write it (angles in degrees)."""
    if unit == "rad":
        return f"{math.degrees(x):.4g}°"
    return f"{x:.4g}" + (f" {_UNIT_TEXT.get(unit, unit)}" if unit else "")


def _mission_unit(name: str) -> str | None:
    for model in declarations.VARIABLES.values():
        if name in model:
            return model[name].unit
    return None


def definition(key: str) -> str:
    """`def.campaign.<field>` (CampaignSpec default), `def.mission.<name>` (mission default),
    `def.limits.thrust_max` / `def.limits.deflection`, `def.<model>.<variable>` (start value);
    a trailing `.value` drops the unit, `.ms` writes seconds in ms."""
    parts = key.split(".")[1:]
    bare, ms = parts[-1] == "value", parts[-1] == "ms"
    if bare or ms:
        parts = parts[:-1]
    scope, name = parts[0], ".".join(parts[1:])
    if scope == "campaign":
        from ..campaign.sampling import CampaignSpec

        x, unit = getattr(CampaignSpec(), name), _SPEC_UNITS.get(name)
    elif scope == "mission":
        x, unit = declarations.MISSION_DEFAULTS[name], _mission_unit(name)
    elif scope == "limits":
        x, unit = _LIMITS[name]
    elif scope in declarations.VARIABLES:
        v = declarations.VARIABLES[scope][name]
        x, unit = v.start, v.unit
    else:
        raise KeyError(f"no definition {key!r}")
    if ms:
        if unit != "s":
            raise KeyError(f"{key!r}: .ms of a value in {unit!r}")
        return f"{1e3 * x:.4g} ms"
    return with_unit(x, None if bare and unit != "rad" else unit)


def mission_text(name: str) -> str:
    m = declarations.mission(name)
    return ", ".join(g(m[k]) for k in declarations.PHASE_DURATIONS) + f" s; {g(declarations.stop_time(m))} s"


@block("mission.default.stop", "declarations")
def _default_stop(src: Sources) -> str:
    return f"{g(declarations.stop_time(declarations.mission('default')))} s"


@block("mission.fast", "declarations")
def _mission_fast(src: Sources) -> str:
    m = declarations.mission("fast")
    return f"T1 = {g(m['t_transition_1'])} s, T2 = {g(m['t_transition_2'])} s"


@block("mission.short", "declarations")
def _mission_short(src: Sources) -> str:
    m = declarations.mission("short")
    return ", ".join(g(m[k]) for k in declarations.PHASE_DURATIONS) + " s"


@block("plant.thrust_to_weight", "declarations")
def _thrust_to_weight(src: Sources) -> str:
    v = declarations.VARIABLES["tailsitter_plant"]
    return f"{v['thrust_max'].start / (v['mass'].start * v['gravity'].start):.1f}"


@block("plant.n_airframe", "modelDescription/tailsitter_plant.json")
def _n_airframe(src: Sources) -> str:
    from .docs import ROOT

    # a declaration, like the package's declarations: always the checkout's
    doc = json.loads((ROOT / "modelDescription" / "tailsitter_plant.json").read_text())

    def count(x) -> int:
        if isinstance(x, dict):
            return (x.get("group") == "airframe") + sum(count(v) for v in x.values())
        return sum(count(v) for v in x) if isinstance(x, list) else 0

    return str(count(doc))


@block("campaign.missions", "declarations")
def _missions(src: Sources) -> str:
    m = declarations.mission("default")
    from ..campaign.sampling import CampaignSpec

    return (
        f"`default` = the controllers' defaults ({g(m['t_vertical_1'])} s climb, "
        f"T1 = {g(m['t_transition_1'])} s, {g(m['t_level'])} s level, T2 = {g(m['t_transition_2'])} s, "
        f"{g(m['t_vertical_2'])} s vertical; {g(declarations.stop_time(m))} s), `short` ({mission_text('short')}, "
        f"for tests). Communication step {g(CampaignSpec().step_size)} s."
    )


@block("campaign.gust_duration", "declarations")
def _gust_duration(src: Sources) -> str:
    from ..campaign.sampling import CampaignSpec

    lo, hi = CampaignSpec().gust_duration
    return f"U({g(lo)}, {g(hi)}) s"


@block("campaign.native_tolerance", "declarations")
def _native_tol(src: Sources) -> str:
    from ..campaign import native

    return re.sub(r"e([+-])0*(\d)", r"e\1\2", f"{native.TOLERANCE:g}").replace("e+", "e")


# --- the campaign summaries -------------------------------------------------------------------------------------


def n_samples(s: Mapping[str, Any]) -> int:
    """The largest number of samples of an arm of a campaign summary."""
    return max(s["samples"].values())


def _arm(s: Mapping[str, Any], key: str) -> Mapping[str, Any]:
    return s["arms"][key]


def spec_text(s: Mapping[str, Any], n_campaigns: int | None = None) -> str:
    sp = s["spec"]
    aero = "global (post-stall)" if sp["aero_model"] == 1 else "thesis (linear)"
    return (
        f"Seed {sp['seed']}, default mission ({g(sum(sp['mission'].values()))} s), {aero} plant aerodynamics, "
        f"τ = {g(sp['tau_aero'])} / {g(sp['tau_mass'])}, wind ≤ {g(sp['wind_max'])} m/s, gust ≤ {g(sp['gust_max'])} m/s"
    )


@block("campaign.full_run.spec", FULL)
def _full_spec(src: Sources) -> str:
    s = src.json(FULL)
    n = len(s["runtime"])
    t = spec_text(s)
    return t[0].lower() + t[1:] + f"; {n} campaigns of the same sample space, rows merged by sample"


@block("campaign.full_run.wind_max", FULL)
def _full_wind(src: Sources) -> str:
    return f"{g(src.json(FULL)['spec']['wind_max'])} m/s"


@block("campaign.full_run.workers", FULL)
def _full_workers(src: Sources) -> str:
    w = sorted({r["worker_threads"] for r in src.json(FULL)["runtime"]})
    return "/".join(map(str, w)) + " worker processes"


def _labels(s: Mapping[str, Any]) -> list[str]:
    from .verdict import label

    return sorted({k.split("/")[0] for k in s["arms"]}, key=label)


def completion_sentence(s: Mapping[str, Any], group: str, fmt=pct) -> str:
    """`the tuned TSD completes 98 % and the tuned LQR 79 %` for `group` = configuration/state source,
    the better controller first."""
    from .verdict import label

    ks = sorted((k for k in _labels(s) if f"{k}/{group}" in s["arms"]), key=lambda k: -_arm(s, f"{k}/{group}")["p"])
    cfg = group.split("/")[0]
    first, *rest = ks
    out = f"the {cfg} {label(first)} completes {fmt(_arm(s, f'{first}/{group}')['p'])}"
    for k in rest:
        out += f" and the {cfg} {label(k)} {fmt(_arm(s, f'{k}/{group}')['p'])}"
    return out


def _p3(p: float) -> str:
    return f"{p:.3f}"


@block("campaign.full_run.reading", FULL)
def _full_reading(src: Sources) -> str:
    from .verdict import label

    s = src.json(FULL)
    ks = _labels(s)
    tp = s["paired"]["tuned/perfect"]["rms_err"]
    av = [k for k in ks if f"{k}/tuned/avionics" in s["arms"]]
    n_av = max(_arm(s, f"{k}/tuned/avionics")["runs"] for k in av)
    return (
        f"on uncertain plants in wind {completion_sentence(s, 'tuned/perfect')}; where both complete the "
        f"paired RMS position error differs by {f(tp['mean'], 1)} m (TSD − LQR, {interval(tp['ci95'], 1)}). With the "
        "sensors and the estimator in the loop both lose some ("
        + ", ".join(f"{label(k)} {_p3(_arm(s, f'{k}/tuned/avionics')['p'])}" for k in av)
        + f" on the first {n_av} samples): the avionics' remaining cost is mostly the estimator's rate and "
        "specific-force lag (crates/state-estimator/README.md). The thesis configurations ("
        + ", ".join(
            f"{label(k)} {_p3(_arm(s, f'{k}/thesis/perfect')['p'])}" for k in ks if f"{k}/thesis/perfect" in s["arms"]
        )
        + ") are worse for both (the thesis TSD's wind-axes frame is linearly unstable in the "
        f"{definition('def.mission.v_vertical')} climb, crates/tsd-control/README.md)."
    )


@block("campaign.rerun.spec", RERUN)
def _rerun_spec(src: Sources) -> str:
    s = src.json(RERUN)
    t = spec_text(s)
    return (
        f"The arms were re-run on the first {n_samples(s)} samples of the same sample space ({t[0].lower()}{t[1:]}, "
        "no turbulence, completion = flown to the end)"
    )


@block("campaign.rerun.tables", RERUN)
def _rerun_tables(src: Sources) -> str:
    from ..campaign import section

    s = src.json(RERUN)
    md = section.markdown(s, "")[2:]
    failures = {k for r in s["arms"].values() for k in r["failures"]}
    md += ["", f"Failure kinds: {', '.join(sorted(failures)) or 'none'}."]
    return "\n".join(md)


@block("campaign.rerun.reading", RERUN, FULL)
def _rerun_reading(src: Sources) -> str:
    from .verdict import label

    s, full = src.json(RERUN), src.json(FULL)
    ks = _labels(s)
    n = n_samples(s)

    def p(sm, arm):
        return _p3(_arm(sm, arm)["p"])

    def med(sm, arm):
        return f"{_arm(sm, arm)['median_completed']['max_err']:.2f}"

    av = "tuned/avionics"
    return (
        "with the sensors at Table D.1 today's avionics give "
        + ", ".join(f"{label(k)} {p(s, f'{k}/{av}')} (full run {p(full, f'{k}/{av}')})" for k in ks)
        + f" on these {n} samples; the medians of the largest error of completed runs are "
        + ", ".join(f"{label(k)} {med(s, f'{k}/{av}')} m (full run {med(full, f'{k}/{av}')} m)" for k in ks)
        + ". The App.-D-faithful estimator completes "
        + ", ".join(f"{label(k)} {p(s, f'{k}/tuned/avionics_app_d')}" for k in ks)
        + "; which of its differences (Table D.1 variances, the four extras off) costs how much is not measured "
        "here (crates/state-estimator/README.md has the extras' effects one by one on the default mission). The "
        "thesis configurations in wind (perfect state) complete "
        + ", ".join(f"{label(k)} {p(s, f'{k}/thesis/perfect')}" for k in ks)
        + f" (the TSD's printed design: its {definition('def.mission.v_vertical')} climb is linearly unstable, "
        "docs/THESIS.md D-4.27)."
    )


@block("thesis.app_d_completion", RERUN)
def _thesis_app_d(src: Sources) -> str:
    from .verdict import label

    s = src.json(RERUN)
    n = n_samples(s)
    return (
        f"App.-D-faithful estimator against today's on {n} campaign samples (uncertain plants, wind, tuned "
        "controllers): completion "
        + ", ".join(
            f"{label(k)} {_p3(_arm(s, f'{k}/tuned/avionics_app_d')['p'])} vs {_p3(_arm(s, f'{k}/tuned/avionics')['p'])}"
            for k in _labels(s)
        )
    )


# --- the reproduction of the thesis -----------------------------------------------------------------------------


def _fast(src: Sources, variant: str, v_vertical: float) -> Mapping[str, Any]:
    for r in src.json(REPRO)["fast_transitions"]["rows"]:
        if r["variant"].startswith(variant) and r["v_vertical"] == v_vertical:
            return r
    raise KeyError((variant, v_vertical))


def _flight(r: Mapping[str, Any], pitch: bool = True) -> str:
    out = f"{r['max_pos_error']:.2f} m, α_max {r['alpha_max_deg']:.1f}°"
    return out + (f", final pitch {r['final_pitch_error_deg']:.1f}°" if pitch else "")


@block("thesis.fast_demand", REPRO)
def _fast_demand(src: Sources) -> str:
    """D-4.28 'printed' column: what the printed quarter loop asks of the wing at T1/T2 = 3/4 s."""
    rows = src.json(REPRO)["fast_transitions"]
    d3, d8 = _fast(src, "cfg 1 (as", 3.0)["demand"], _fast(src, "cfg 1 (as", 8.0)["demand"]
    lin = rows["alpha_linear_deg"]
    plant = declarations.VARIABLES["tailsitter_plant"]
    return (
        f"**{d3['n_t2_start']:.2f} g** at T2 = 4 s, V_V = 3 m/s ({d8['n_t2_start']:.2f} g at 8 m/s). With C_L0 = 0 "
        f"(C.2.1) the wing gives it at α = n m g/(q̄ S C_Lα) = **{d3['alpha_t2_deg']:.1f}°** "
        f"({d8['alpha_t2_deg']:.1f}° at 8 m/s; m {g(plant['mass'].start)} kg, S {g(plant['wing_area'].start)} m², "
        f"C_Lα {plant['c_L_alpha_a0'].start:.2f} /rad; with the thesis's own AVL trim "
        f"5.9° at 1 g, n·5.9° = {d3['n_t2_start'] * 5.9:.1f}°) (wing alone: the thrust's T sin α and the mixed "
        f"surfaces' lift, −0.1 C_Lδe δe by Table 4.1, left out). α ≤ {g(lin)}° needs T2 ≥ {d3['t2_for_linear']:.1f} s "
        f"({d8['t2_for_linear']:.1f} s at 8 m/s); the push-over at the end of T1 = 3 s asks for "
        f"{f(d3['n_t1_end'])} g ({f(d3['alpha_t1_deg'], 1)}°), inside the range for T1 ≥ {d3['t1_for_linear']:.1f} s"
    )


@block("thesis.fast_flown", REPRO)
def _fast_flown(src: Sources) -> str:
    """D-4.28 'effect' column: the flights of `analysis reproduction` at T1/T2 = 3/4 s."""
    p3, p8 = _fast(src, "cfg 1 (as", 3.0), _fast(src, "cfg 1 (as", 8.0)
    l3, l8 = _fast(src, "cfg 1 + limited", 3.0), _fast(src, "cfg 1 + limited", 8.0)
    t = _fast(src, "cfg 0", 3.0)

    def verdict(r):
        return "passes" if r["passed"] else "fails"

    d3, d8 = p3["demand"], p8["demand"]
    above = all(r["alpha_max_deg"] > r["demand"]["alpha_t2_deg"] for r in (p3, p8))
    return (
        f"thesis setting, T1/T2 = 3/4 s: printed at V_V 3 m/s {verdict(p3)} ({_flight(p3)}: the climb instability "
        f"of D-4.27); printed at V_V 8 m/s **{verdict(p8)}** ({_flight(p8)}); printed + limited profile (D-4.22) at "
        f"3 m/s {_flight(l3)} ({verdict(l3)}), at 8 m/s {verdict(l8)} ({_flight(l8, pitch=False)}); tuned "
        f"{verdict(t)} ({_flight(t, pitch=False)}). The flown α_max is "
        + ("above" if above else "not everywhere above")
        + f" the wing's quasi-steady {d3['alpha_t2_deg']:.1f}° / {d8['alpha_t2_deg']:.1f}° in every printed run "
        "(`analysis reproduction`, reproduction.json `fast_transitions`)"
    )


@block("thesis.table_5_1", REPRO)
def _table_5_1(src: Sources) -> str:
    r = src.json(REPRO)
    rho = r["spearman"]
    med = r["table_5_1_median_ratio"]
    return (
        f"thesis configurations: Spearman ρ LQR {rho['lqr_cfg1']:.2f}, TSD {rho['tsd_cfg1']:.2f} against Table 5.1; "
        f"median entry over the thesis's: LQR {med['lqr_cfg1']:.2f}, TSD {med['tsd_cfg1']:.2f} "
        '(the analysis report, "Reproduction of the thesis")'
    )


def _mode(src: Sources, name: str) -> list[float]:
    return next(m for m in src.json(REPRO)["open_loop_modes"] if m["mode"] == name)["ours"]


@block("design.short_period", REPRO)
def _short_period(src: Sources) -> str:
    re_, im = _mode(src, "short period")
    return f"{f(re_, 1)} ± {im:.1f}i rad/s"


@block("transition.short_period_time", REPRO)
def _short_period_time(src: Sources) -> str:
    re_ = -_mode(src, "short period")[0]
    return f"1/{re_:.2f} s = {1 / re_:.3f} s"


def take_reproduction(full: Mapping[str, Any], command: str) -> dict[str, Any]:
    """The part of `analysis reproduction`'s reproduction.json the docs quote (docs/reproduction.json)."""
    ratios = {}
    for k in ("lqr_cfg0", "lqr_cfg1", "tsd_cfg0", "tsd_cfg1"):
        xs = [row[f"{k}_ratio"] for row in full["table_5_1"] if row.get(f"{k}_ratio") is not None]
        ratios[k] = statistics.median(xs)
    return {
        "command": command,
        "setting": full["setting"],
        "fast_transitions": full["fast_transitions"],
        "missions": {
            k: {q: v[q] for q in ("max_pos_error", "alpha_max_deg", "final_pitch_error_deg", "passed")}
            for k, v in full["missions"].items()
        },
        "spearman": full["spearman"],
        "table_5_1_median_ratio": ratios,
        "open_loop_modes": full["open_loop_modes"],
    }


def _sig3(x: float) -> str:
    """Three significant digits, trailing zeros kept, Unicode minus."""
    return f"{x:#.3g}".rstrip(".").replace("-", "−")


def _pole(re_: float, im: float, fmt) -> str:
    sign = "+" if re_ > 0 else ""
    return f"{sign}{fmt(re_)}" + (f" ± {fmt(abs(im))}i" if im else "")


@block("physics.open_loop_modes", REPRO)
def _physics_modes(src: Sources) -> str:
    """crates/tailsitter-physics/README.md: the open-loop modes at the level trim beside the thesis's."""
    rows = ["| mode | this model | thesis (Tables 3.2/3.3) |", "|---|---|---|"]
    for m in src.json(REPRO)["open_loop_modes"]:
        thesis = _pole(*m["thesis"], lambda x: f"{x:g}".replace("-", "−"))
        rows.append(f"| {m['mode']} | {_pole(*m['ours'], _sig3)} | {thesis} |")
    return "\n".join(rows)
