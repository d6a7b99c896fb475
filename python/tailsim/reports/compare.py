"""The comparison product: fly the missions and step tests with each
controller, write CSVs, plots and a report (Markdown + self-contained HTML).

    python -m tailsim.reports.compare --controller both --out out
"""

from __future__ import annotations

import json
import math
import pathlib
import sys
import time

import numpy as np

from .. import cli, controllers, declarations
from ..campaign import section as campaign_section
from ..masters import ClosedLoop, Fmu, RunResult, pos_error, step
from ..metrics import CRITERIA, PHASES, SURFACES, mission_metrics, phase_starts, step_settling
from . import analysis as analysis_report
from . import verdict
from .markdown import fmt, markdown_to_html, toc

NAMES = controllers.NAMES
COLORS = controllers.COLORS
# The mission parameters every controller declares (modelDescription/fragments/controller_interface.json).
DURATIONS = list(declarations.PHASE_DURATIONS)
MISSION = [*DURATIONS, "v_level"]
#: The fast mission: the declared preset `fast` (the thesis's T1 = 3 s, T2 = 4 s).
FAST = declarations.PRESETS["fast"]
STEP_CASES = [
    # (flight, axis, offset NED, step time, controller params, stop time)
    ("level", "normal", (0.0, 0.0, 5.0), 16.0, {"t_level": 30.0}, 34.0),
    ("level", "lateral", (0.0, 5.0, 0.0), 16.0, {"t_level": 30.0}, 34.0),
    ("vertical", "normal", (5.0, 0.0, 0.0), 2.0, {"t_vertical_1": 30.0}, 15.0),
    ("vertical", "lateral", (0.0, 5.0, 0.0), 2.0, {"t_vertical_1": 30.0}, 15.0),
]


def level_trim_theta(plant: Fmu, v_level: float) -> float:
    s = plant.instantiate("trim")
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    plant.set(s, {"initial_condition": 1, "initial_speed": v_level})
    s.exitInitializationMode()
    (theta,) = s.getReal([plant.variables["theta"].valueReference])
    s.terminate()
    s.freeInstance()
    return theta


def mission_defaults(controllers: list[Fmu]) -> dict[str, float]:
    """The mission's defaults (durations, v_level) as the controllers declare them
    (start values in their modelDescription.xml); all controllers must agree."""
    defaults = controllers[0].starts(MISSION)
    for c in controllers[1:]:
        if c.starts(MISSION) != defaults:
            raise ValueError(f"{c.identifier} declares other mission defaults: {c.starts(MISSION)} != {defaults}")
    return defaults


def mission_params(defaults: dict[str, float], t1: float, t2: float) -> dict[str, float]:
    """The phase durations of the mission with transitions T1 = `t1`, T2 = `t2`, the rest default."""
    return {**{k: defaults[k] for k in DURATIONS}, "t_transition_1": t1, "t_transition_2": t2}


#: Deflections smaller than this everywhere (rad, 0.05°) leave a surface out of the plots' legends.
ACTIVE_SURFACE = math.radians(0.05)
AERO_MODELS = {0: "thesis (linear) aerodynamics", 1: "global (post-stall) aerodynamics"}
CONFIGURATIONS = {0: "tuned", 1: "thesis"}


def setting(plant: Fmu, ctrls: dict[str, Fmu]) -> str:
    """What flies, for the plots' titles: the plant's aerodynamic model and each controller's
    configuration (a controller without the `configuration` switch flies its declared defaults)."""
    aero = AERO_MODELS.get(int(plant.start("aero_model")), f"aero_model {plant.start('aero_model'):g}")

    def configuration(c: Fmu) -> str:
        if "configuration" not in c.variables:
            return "default"
        v = c.start("configuration")
        return CONFIGURATIONS.get(int(v), f"configuration {v:g}")

    conf = ", ".join(f"{k.upper()} {configuration(c)}" for k, c in ctrls.items())
    return f"plant: {aero}; {conf} configuration"


def shade_phases(ax, starts: list[float], label: bool = False) -> None:
    """Shade every other phase of the mission (`starts`: phase starts and the end, s) and name them."""
    for i, (a, b) in enumerate(zip(starts[:-1], starts[1:], strict=False)):
        if i % 2:
            ax.axvspan(a, b, color="0.9", zorder=0)
        if label:
            ax.text((a + b) / 2, 0.98, PHASES[i], transform=ax.get_xaxis_transform(), ha="center", va="top", fontsize=7)


def active_surfaces(runs: dict[str, RunResult]) -> list[str]:
    """The control surfaces that move in any of `runs` (|δ| > `ACTIVE_SURFACE` somewhere)."""
    return [s for s in SURFACES if any(np.nanmax(np.abs(r[s]), initial=0.0) > ACTIVE_SURFACE for r in runs.values())]


def plot_mission(runs: dict[str, RunResult], title: str, path: pathlib.Path, starts: list[float] | None = None) -> None:
    """The mission's track, airspeed, α and θ, position error, thrust and the surfaces that move,
    one colour per controller; the phases shaded (`starts`: phase starts and end, s)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 2, figsize=(13, 11))
    surfaces = active_surfaces(runs)
    styles = ["-", "--", ":", "-.", (0, (5, 1)), (0, (1, 1)), (0, (3, 1, 1, 1))]
    for key, r in runs.items():
        c, t = COLORS[key], r.time
        ax[0, 0].plot(r["pos_n"], -r["pos_d"], color=c, label=f"{key.upper()} flown")
        ax[0, 0].plot(r["ref_pos_n"], -r["ref_pos_d"], color=c, ls="--", lw=1, label=f"{key.upper()} reference")
        ax[0, 1].plot(t, r["airspeed"], color=c, label=f"{key.upper()} V")
        ax[0, 1].plot(t, r["ref_airspeed"], color=c, ls="--", lw=1, label=f"{key.upper()} V ref")
        ax[1, 0].plot(t, np.degrees(r["alpha"]), color=c, label=f"{key.upper()} α")
        ax[1, 0].plot(t, np.degrees(r["theta"]), color=c, ls=":", label=f"{key.upper()} θ")
        ax[1, 1].plot(t, pos_error(r), color=c, label=key.upper())
        ax[2, 0].plot(t, r["thrust"], color=c, label=f"{key.upper()} T")
        for s, ls in zip(surfaces, styles, strict=False):
            ax[2, 1].plot(t, np.degrees(r[s]), color=c, ls=ls, lw=1, label=f"{key.upper()} {s}")
    ax[0, 0].set(xlabel="north (m)", ylabel="height (m)", title="track (Figs. 3.20 / 4.19)")
    ax[0, 0].axis("equal")
    ax[0, 1].set(xlabel="t (s)", ylabel="airspeed (m/s)", title="airspeed")
    ax[1, 0].set(xlabel="t (s)", ylabel="angle (deg)", title="angle of attack α and pitch θ")
    ax[1, 1].set(xlabel="t (s)", ylabel="distance (m)", title="position error")
    ax[2, 0].set(xlabel="t (s)", ylabel="thrust (N)", title="thrust")
    ax[2, 1].set(xlabel="t (s)", ylabel="deflection (deg)", title="surface deflections (the surfaces that move)")
    for k, a in enumerate(ax.flat):
        if starts and k:
            shade_phases(a, starts, label=k == 1)
        a.grid(True, alpha=0.3)
        a.legend(fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_steps(step_runs: dict[str, dict[str, tuple[RunResult, float]]], path: pathlib.Path, what: str = "") -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = [f"{f} {a}" for f, a, *_ in STEP_CASES]
    fig, ax = plt.subplots(2, 2, figsize=(12, 8))
    for a, case in zip(ax.flat, cases, strict=False):
        for key, runs in step_runs.items():
            if case in runs:
                r, t_step = runs[case]
                m = r.time >= t_step - 1.0
                a.plot(r.time[m] - t_step, pos_error(r)[m], color=COLORS[key], label=key.upper())
        a.axhline(CRITERIA["settling_band"], color="k", lw=0.8, ls=":")
        flight, axis = case.split()
        a.set(title=f"5 m {axis} step in {flight} flight", xlabel="time after step (s)", ylabel="position error (m)")
        a.grid(True, alpha=0.3)
        a.legend()
    fig.suptitle(f"Position steps of 5 m; {what}" if what else "Position steps of 5 m")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def analysis_section(out: pathlib.Path) -> list[str]:
    """The analysis campaign's report, rendered from its data
    (`analysis/report.json`, written by `cargo run --release -p analysis -- all
    --out <out>/analysis`), headings demoted under one section, with its plots."""
    if not (out / "analysis" / "report.json").exists():
        return []
    lines = ["", "## Analysis: modes, closed-loop poles, sensitivity (Table 5.1) and robustness", ""]
    for line in analysis_report.markdown(analysis_report.load(out / "analysis")):
        if line.startswith("#"):
            line = "#" + line if line.startswith("##") else "### " + line.lstrip("# ")
            line = line if not line.startswith("####") else "### " + line.lstrip("# ")
        lines.append(line)
    pngs = analysis_report.plots(out / "analysis")
    if pngs:
        lines += ["", "### Analysis plots", ""]
        for p in pngs:
            lines += [f"![{p.stem}](analysis/{p.name})", ""]
    return lines


def parser() -> cli.Parser:
    ap = cli.Parser(prog="tailsim.reports.compare", description=__doc__.split("\n\n")[0])
    ap.add_argument("--controller", choices=[*controllers.KEYS, "both"], default="both")
    ap.add_argument("--dist", default="dist", help="folder with the .fmu files")
    ap.add_argument("--out", default="out", help="output folder")
    for k, n in (("t_transition_1", "T1"), ("t_transition_2", "T2")):
        lo, hi = declarations.MISSION_RANGES[k]
        ap.add_argument(
            f"--fast-{n.lower()}",
            type=cli.declared_mission(k),
            default=FAST[k],
            help=f"{n} of the fast mission [s], within the declared [{lo:g}, {hi:g}] of `{k}`",
        )
    ap.add_argument("--no-steps", action="store_true", help="skip the position-step tests")
    ap.add_argument("--jacobi", action="store_true", help="use a Jacobi master instead of Gauss-Seidel")
    ap.add_argument("--no-avionics", action="store_true", help="skip the missions with avionics in the loop")
    return ap


def main(argv: list[str] | None = None) -> int:
    ap = parser()
    args = ap.parse_args(argv)
    keys = list(controllers.KEYS) if args.controller == "both" else [args.controller]
    needed = ["tailsitter_plant", *(NAMES[k] for k in keys)]
    if not args.no_avionics:
        needed += ["tailsitter_sensors", "tailsitter_ekf"]
    cli.check_fmus(ap, "--dist", args.dist, needed)
    cli.check_out(ap, "--out", args.out)
    return cli.guard(ap.prog, args.debug, lambda: run(args))


def run(args) -> int:
    """The comparison of the parsed and checked options `args` (see `main`)."""
    from tqdm import tqdm

    out = pathlib.Path(args.out)
    (out / "csv").mkdir(parents=True, exist_ok=True)
    dist = pathlib.Path(args.dist)
    keys = list(controllers.KEYS) if args.controller == "both" else [args.controller]
    plant = Fmu(dist / "tailsitter_plant.fmu")
    ctrls = {k: Fmu(dist / f"{NAMES[k]}.fmu") for k in keys}
    defaults = mission_defaults(list(ctrls.values()))
    theta_trim = level_trim_theta(plant, defaults["v_level"])
    ordering = "jacobi" if args.jacobi else "gauss-seidel"

    missions = {
        "default": (defaults["t_transition_1"], defaults["t_transition_2"]),
        "fast": (args.fast_t1, args.fast_t2),
    }
    jobs = [("mission", m, k) for m in missions for k in keys]
    if not args.no_steps:
        jobs += [("step", f"{c[0]} {c[1]}", k) for c in STEP_CASES for k in keys]
    mission_runs: dict[str, dict[str, RunResult]] = {m: {} for m in missions}
    step_runs: dict[str, dict[str, tuple[RunResult, float]]] = {k: {} for k in keys}
    failures: dict[tuple[str, str, str], str] = {}
    t_start = time.time()
    for kind, name, key in tqdm(jobs, desc="runs", unit="run"):
        try:
            if kind == "mission":
                t1, t2 = missions[name]
                params = mission_params(defaults, t1, t2)
                loop = ClosedLoop(plant, ctrls[key], controller_params=params, ordering=ordering)
                r = loop.run(stop_time=phase_starts(params)[-1], progress=True, description=f"{key} {name}")
                mission_runs[name][key] = r
                r.write_csv(out / "csv" / f"{key}_{name}_mission.csv")
            else:
                case = next(c for c in STEP_CASES if f"{c[0]} {c[1]}" == name)
                _, _, offset, t_step, params, stop = case
                loop = ClosedLoop(plant, ctrls[key], controller_params=params, ordering=ordering)
                r = loop.run(
                    stop_time=stop, ref_offset=step(t_step, offset), progress=True, description=f"{key} {name}"
                )
                step_runs[key][name] = (r, t_step)
                r.write_csv(out / "csv" / f"{key}_step_{name.replace(' ', '_')}.csv")
        except Exception as e:  # noqa: BLE001 - a failed run is a result of the comparison
            failures[(kind, name, key)] = str(e)

    # The numbers of each mission run, written first: the verdict and the report read them from metrics.json.
    metrics = {}
    limits = {"deflection_limit": plant.start("deflection_limit"), "thrust_max": plant.start("thrust_max")}
    flown_params = {
        m: {**mission_params(defaults, t1, t2), "v_level": defaults["v_level"]} for m, (t1, t2) in missions.items()
    }
    for m in missions:
        for k in keys:
            if k in mission_runs[m]:
                metrics[(m, k)] = mission_metrics(mission_runs[m][k], flown_params[m], theta_trim, **limits)
    summary = {
        f"{k}_{m}": {"controller": k, "mission": m, "requested": list(missions[m]), **vars(v)}
        for (m, k), v in metrics.items()
    }
    (out / "metrics.json").write_text(json.dumps(summary, indent=1, default=str))

    what = setting(plant, ctrls)
    plots = []
    for m, runs in mission_runs.items():
        if runs:
            t1, t2 = missions[m]
            p = out / f"mission_{m}.png"
            flown = ", ".join(
                f"{k.upper()} " + " / ".join(fmt(v, 1) for v in metrics[(m, k)].flown_transition) + " s"
                for k in runs
                if (m, k) in metrics
            )
            plot_mission(
                runs,
                f"{m} mission: T1 / T2 requested {t1:g} / {t2:g} s, flown {flown}\n{what}",
                p,
                phase_starts(flown_params[m]),
            )
            plots.append((f"{m.capitalize()} mission (T1 / T2 requested {t1:g} / {t2:g} s)", p))
    if not args.no_steps and any(step_runs.values()):
        p = out / "steps.png"
        plot_steps(step_runs, p, what)
        plots.append(("Position steps of 5 m (§3.4.1, §4.4.2)", p))

    # The comparison table.
    rows: list[tuple[str, list[str]]] = []
    header = ["quantity"] + [f"{k.upper()} {m}" for m in missions for k in keys]

    def row(label, f):
        vals = []
        for m in missions:
            for k in keys:
                if (m, k) in metrics:
                    vals.append(f(metrics[(m, k)]))
                else:
                    vals.append("failed: " + failures.get(("mission", m, k), "?")[:60])
        rows.append((label, vals))

    row("mission completed", lambda x: "yes" if x.completed else f"no ({x.reason})")
    rows.append(
        (
            "transitions requested T1 / T2 (s)",
            [f"{missions[m][0]:g} / {missions[m][1]:g}" for m in missions for k in keys],
        )
    )
    row(
        "transitions flown (s) (γ within 5° of level / vertical for good)",
        lambda x: " / ".join(fmt(v, 1) for v in x.flown_transition),
    )
    for i, ph in enumerate(PHASES):
        row(f"max / RMS position error, {ph} (m)", lambda x, i=i: f"{fmt(x.max_error[i])} / {fmt(x.rms_error[i])}")
    row(
        "max altitude deviation, transition 1 / 2 (m)",
        lambda x: " / ".join(fmt(v) for v in x.altitude_deviation_transition),
    )
    row("max α (deg)", lambda x: fmt(x.max_alpha_deg, 1))
    row("time in actuator saturation (s)", lambda x: fmt(x.saturation_time))
    row(
        "level flight: max airspeed error (m/s) / pitch error (deg)",
        lambda x: f"{fmt(x.level_airspeed_error)} / {fmt(x.level_pitch_error_deg)}",
    )
    row("controller compute per step (fmpy call incl.) (µs)", lambda x: fmt(x.controller_us_per_step, 0))
    fastest = {}
    alpha_max = CRITERIA["linear_alpha_max"]
    for k in keys:
        # Flown = completed with α in the linear region of the aerodynamic model (thesis §4.4.4); the
        # durations are the measured ones, not the requested T1, T2.
        done = [
            metrics[(m, k)].flown_transition
            for m in missions
            if (m, k) in metrics
            and metrics[(m, k)].completed
            and metrics[(m, k)].max_alpha_deg < alpha_max
            and all(math.isfinite(v) for v in metrics[(m, k)].flown_transition)
        ]
        fastest[k] = min(done, key=lambda tt: tt[0] + tt[1]) if done else None
    step_rows = []
    for c in [] if args.no_steps else STEP_CASES:
        name = f"{c[0]} {c[1]}"
        vals = []
        for k in keys:
            if name in step_runs[k]:
                r, t_step = step_runs[k][name]
                vals.append(fmt(step_settling(r, t_step)))
            else:
                vals.append("failed")
        step_rows.append((f"settling time to < {CRITERIA['settling_band']:g} m, 5 m step, {name} (s)", vals))

    body = campaign_part(out)
    body += ["", "## Missions (thesis ch. 6 comparison)", ""]
    body.append(f"One run per controller on the nominal plant without wind; {what}.")
    body.append("")
    body.append("| " + " | ".join(header) + " |")
    body.append("|" + "---|" * len(header))
    for label, vals in rows:
        body.append(f"| {label} | " + " | ".join(vals) + " |")
    body += [
        "",
        f"Fastest transitions flown (measured, completed with α < {alpha_max:g}°): "
        + ", ".join(
            f"{k.upper()} {fastest[k][0]:.1f} s forward, {fastest[k][1]:.1f} s back"
            if fastest[k]
            else f"{k.upper()}: none of the missions flown kept α < {alpha_max:g}°"
            for k in keys
        )
        + ".",
    ]
    if step_rows:
        body += [
            "",
            "## Position steps",
            "",
            "| step | " + " | ".join(k.upper() for k in keys) + " |",
            "|" + "---|" * (len(keys) + 1),
        ]
        for label, vals in step_rows:
            body.append(f"| {label} | " + " | ".join(vals) + " |")
    if failures:
        body += ["", "## Failed runs", ""] + [f"- {k[2].upper()} {k[1]} ({k[0]}): {v}" for k, v in failures.items()]
    if not args.no_avionics:
        from .avionics import avionics_section

        body += avionics_section(
            dist,
            keys,
            flown_params,
            {(m, k): r for m, runs in mission_runs.items() for k, r in runs.items()},
            theta_trim,
            ordering=ordering,
            out=out,
        )
    body += ["", "## Plots", ""]
    for title, p in plots:
        body += [f"### {title}", "", f"![{title}]({p.name})", ""]
    body += ["CSV of every run (time + all signals, units in the header): `csv/`."]
    body += analysis_section(out)
    body += documented_runs()
    body += [
        "",
        "## This run",
        "",
        f"Master: fmpy, {ordering}; plant `tailsitter_plant`; controllers: {', '.join(NAMES[k] for k in keys)}. "
        f"Level-trim pitch of the plant at {defaults['v_level']:g} m/s: {math.degrees(theta_trim):.2f}°. Wall time "
        f"{time.time() - t_start:.0f} s.",
    ]

    head = ["# Tail-sitter controller comparison", ""]
    head += verdict.markdown(verdict.collect(out))
    head += ["", "## Contents", "", *toc(body)]
    md = head + body
    (out / "report.md").write_text("\n".join(md) + "\n")
    (out / "report.html").write_text(markdown_to_html(md, out, "Tail-sitter comparison"))
    print(f"report: {out / 'report.md'} and {out / 'report.html'}; plots and csv/ in {out}/")
    for f in failures.values():
        print("failed run:", f, file=sys.stderr)
    plant.cleanup()
    for c in ctrls.values():
        c.cleanup()
    return 0


def campaign_part(out: pathlib.Path) -> list[str]:
    """This run's paired Monte-Carlo campaign (`<out>/campaign`), with its plots; its own report
    (`campaign/report.md`) also as HTML."""
    folder = out / "campaign"
    if not (folder / "results.parquet").exists():
        return []
    md = [
        "",
        "## This run's paired Monte-Carlo campaign",
        "",
        "The controllers are compared on uncertain plants, not on the nominal one (where each controller's design "
        "model is the plant exactly): every sample is flown by every arm (controller/configuration/state source), so "
        "differences are paired. The nominal missions below are single points of this distribution.",
        "",
    ]
    try:
        md += campaign_section.markdown(campaign_section.summarize([folder]), "Campaign in `campaign/`")
    except Exception as e:  # noqa: BLE001 - a broken campaign folder must not lose the report
        md += [f"(campaign in {folder} not summarised: {e})"]
    for p in sorted(folder.glob("*.png")):
        md += ["", f"![{p.stem}](campaign/{p.name})"]
    if (folder / "report.md").exists():
        page = (folder / "report.md").read_text().splitlines()
        (folder / "report.html").write_text(markdown_to_html(page, folder, "Tail-sitter Monte-Carlo campaign"))
        md += ["", "The campaign's own report: [campaign/report.html](campaign/report.html)."]
    return md


def documented_runs() -> list[str]:
    """The documented full run (`docs/campaign_full_run.json`), labelled as such: not this run's data."""
    if not campaign_section.FULL_RUN.exists():
        return []
    md = [
        "",
        "## Documented full runs (not this run)",
        "",
        "Recorded earlier with ≥ 1000 samples per arm and summarised into `docs/campaign_full_run.json` "
        "(how: `docs/CAMPAIGN.md`); shown for reference, not computed by this run.",
        "",
    ]
    return md + campaign_section.markdown(json.loads(campaign_section.FULL_RUN.read_text()), "Full run")


if __name__ == "__main__":
    raise SystemExit(main())
