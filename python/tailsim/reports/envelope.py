"""The transition envelope: the `envelope_transitions` key of the analysis
`report.json` (written by `crates/analysis/src/envelope_transitions.rs`) as a Markdown
section and a plot of the fastest transitions each controller flies inside α ≤ 15°.

Hooked into `tailsim.reports.analysis` (section) and `tailsim.reports.analysis_plots` (plot).
"""

from __future__ import annotations

from pathlib import Path

from .. import declarations
from .markdown import fmt_or_dash, shortest

#: (T1, T2) of the declared missions default, fast and fast_limited: the thesis configurations'
#: rows shown (the tuned ones are shown at every timing).
MISSION_TIMINGS = [
    (m["t_transition_1"], m["t_transition_2"]) for m in map(declarations.mission, ("default", "fast", "fast_limited"))
]


def section(d: dict) -> list[str]:
    """The Markdown section (empty if the report has no `envelope_transitions`)."""
    e = d.get("envelope_transitions")
    if not e:
        return []
    bound = shortest(round(e["alpha_bound_deg"], 6))
    out = [
        "",
        "## Transitions inside the linear α range",
        "",
        f"Global aerodynamics (aero_model = {e['aero_model']}), flown natively (`closed_loop::fly`). The tuned "
        "controllers (configuration 0) fly the α- and thrust-limited point-mass profile "
        f"(|α_ref| ≤ {shortest(round(e['profile_alpha_max_deg'], 6))}°, T_ref ≤ "
        f"{shortest(e['profile_thrust_fraction'])} T_max; "
        "derivation in `crates/guidance/README.md`); the thesis configuration (1) flies the thesis's "
        "transitions unchanged. Altitude deviation: max |h − h_ref| from the start of a transition to "
        f"{shortest(e['settle_window_s'])} s after its end; max α: largest |α| from the first transition to "
        f"{shortest(e['settle_window_s'])} s after the second; rotation: time until the flown flight-path angle stays "
        f"within {shortest(e['rotation_tolerance_deg'])}° of level / vertical. Goal: α ≤ {bound}°, altitude deviation "
        "< 1 m per transition, max position error < 2 m.",
        "",
        "| controller | conf. | master | T1 / T2 (s) | max α (°) | alt. dev. T1 / T2 (m) | max error (m) | "
        "rotation T1 / T2 (s) | reference climb in T2 (m) | goal |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in e["rows"]:
        if (r["t1"], r["t2"]) not in MISSION_TIMINGS and r["configuration"] != 0:
            continue
        out.append(
            f"| {r['controller']} | {'tuned' if r['configuration'] == 0 else 'thesis'} | {r['ordering']} | "
            f"{shortest(r['t1'])} / {shortest(r['t2'])} | {fmt_or_dash(r['max_alpha_deg'], 1)} | "
            f"{fmt_or_dash(r['alt_dev_t1'])} / {fmt_or_dash(r['alt_dev_t2'])} | {fmt_or_dash(r['max_pos_error'])} | "
            f"{fmt_or_dash(r['rotation_t1'])} / {fmt_or_dash(r['rotation_t2'])} | "
            f"{fmt_or_dash(r['ref_climb_t2'], 1)} | "
            f"{'yes' if r['meets_goal'] else ('no' if r['completed'] else 'crashed')} |"
        )
    out += [
        "",
        f"### Minimum rotation times of the profile (airframe T/W = {e['airframe_thrust_to_weight']:.2f})",
        "",
        "The profile flown with T1 = T2 = 0.5 s (as fast as the limits let it, full thrust): time until γ stays "
        "within 2° of level / vertical, and the lower bounds of the README.",
        "",
        "| T/W | α_max (°) | front (s) | front bound (s) | back (s) | back bound (s) |",
        "|---|---|---|---|---|---|",
    ]
    for r in e["min_times"]:
        out.append(
            f"| {shortest(r['thrust_to_weight'])} | {shortest(r['alpha_max_deg'])} | {fmt_or_dash(r['front'])} | "
            f"{fmt_or_dash(r['front_bound'])} | {fmt_or_dash(r['back'])} | {fmt_or_dash(r['back_bound'])} |"
        )
    fastest = e.get("fastest", {})
    if fastest:
        out += [
            "",
            f"Fastest transitions each tuned controller flies with α ≤ {bound}° in both masters (shortest flown "
            "rotations; plot `envelope_fastest.png`):",
            "",
        ]
        for k, f in fastest.items():
            out.append(
                f"- {k}: T1 = {shortest(f['t1'])} s, T2 = {shortest(f['t2'])} s: flown rotations "
                f"{fmt_or_dash(f['rotation_t1'])} s (front) and {fmt_or_dash(f['rotation_t2'])} s (back)"
            )
    return out


def title(e: dict) -> str:
    """The plot's title: the α bound, the aerodynamic model and the controllers' configuration
    (the fastest transitions are the tuned controllers', flown under the Gauss-Seidel master;
    `crates/analysis/src/envelope_transitions.rs`)."""
    from .analysis_plots import setting

    bound = shortest(round(e["alpha_bound_deg"], 6))
    return f"Fastest transitions inside α ≤ {bound}°: {setting(e['aero_model'])}, Gauss-Seidel master"


def figure(d: dict):
    """The figure of `plot` (None if there is nothing to draw)."""
    e = d.get("envelope_transitions")
    if not e or not e.get("fastest"):
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    for k, f in e["fastest"].items():
        s = f["series"]
        label = f"{k} T1 = {shortest(f['t1'])} s, T2 = {shortest(f['t2'])} s"
        axes[0].plot(s["t"], s["alpha_deg"], label=label)
        axes[1].plot(s["t"], s["gamma_deg"], label=label)
        axes[2].plot(s["t"], s["alt_error"], label=label)
        for ax in axes:
            for t in f["phase_starts"][1:5]:
                ax.axvline(t, color="0.8", lw=0.5)
    axes[0].axhline(e["alpha_bound_deg"], color="r", ls="--", lw=0.8, label="α bound")
    axes[0].axhline(-e["alpha_bound_deg"], color="r", ls="--", lw=0.8)
    axes[0].set_ylabel("α (deg)")
    axes[1].set_ylabel("flight-path angle γ (deg)")
    axes[2].set_ylabel("h − h_ref (m)")
    axes[2].set_xlabel("t (s)")
    for ax in axes:
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    axes[0].set_title(title(e), fontsize=9)
    fig.tight_layout()
    return fig


def plot(out: str | Path, d: dict) -> Path | None:
    """`envelope_fastest.png`: α, flight-path angle and altitude error of the fastest
    transitions of each controller; None if there is nothing to draw."""
    fig = figure(d)
    if fig is None:
        return None
    import matplotlib.pyplot as plt

    path = Path(out) / "envelope_fastest.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
