"""The comparison product: fly the missions and step tests with each
controller, write CSVs, plots and a report (Markdown + self-contained HTML).

    python -m tailsim.compare --controller both --out out
"""

from __future__ import annotations

import argparse
import base64
import html
import json
import math
import pathlib
import sys
import time

import numpy as np

from .master import ClosedLoop, Fmu, RunResult, pos_error, step
from .metrics import PHASES, SURFACES, mission_metrics, step_settling

NAMES = {"lqr": "tailsitter_lqr", "tsd": "tailsitter_tsd"}
COLORS = {"lqr": "tab:blue", "tsd": "tab:red"}
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


def mission_params(t1: float, t2: float) -> dict[str, float]:
    return {"t_vertical_1": 5.0, "t_transition_1": t1, "t_level": 10.0, "t_transition_2": t2, "t_vertical_2": 5.0}


def plot_mission(runs: dict[str, RunResult], title: str, path: pathlib.Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 2, figsize=(13, 11))
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
        for s, ls in zip(["elevator", "flap_collective", "aileron", "rudder"], ["-", "--", ":", "-."]):
            ax[2, 1].plot(t, np.degrees(r[s]), color=c, ls=ls, lw=1, label=f"{key.upper()} {s}")
    ax[0, 0].set(xlabel="north [m]", ylabel="height [m]", title="track (Figs. 3.20 / 4.19)")
    ax[0, 0].axis("equal")
    ax[0, 1].set(xlabel="t [s]", ylabel="airspeed [m/s]", title="airspeed")
    ax[1, 0].set(xlabel="t [s]", ylabel="[deg]", title="angle of attack α and pitch θ")
    ax[1, 1].set(xlabel="t [s]", ylabel="[m]", title="position error")
    ax[2, 0].set(xlabel="t [s]", ylabel="[N]", title="thrust")
    ax[2, 1].set(xlabel="t [s]", ylabel="[deg]", title="surface deflections")
    for a in ax.flat:
        a.grid(True, alpha=0.3)
        a.legend(fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_steps(step_runs: dict[str, dict[str, tuple[RunResult, float]]], path: pathlib.Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = [f"{f} {a}" for f, a, *_ in STEP_CASES]
    fig, ax = plt.subplots(2, 2, figsize=(12, 8))
    for a, case in zip(ax.flat, cases):
        for key, runs in step_runs.items():
            if case in runs:
                r, t_step = runs[case]
                m = r.time >= t_step - 1.0
                a.plot(r.time[m] - t_step, pos_error(r)[m], color=COLORS[key], label=key.upper())
        a.axhline(0.5, color="k", lw=0.8, ls=":")
        flight, axis = case.split()
        a.set(title=f"5 m {axis} step in {flight} flight", xlabel="time after step [s]", ylabel="position error [m]")
        a.grid(True, alpha=0.3)
        a.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def analysis_section(out: pathlib.Path) -> list[str]:
    """The analysis campaign's report (`analysis/report.md`, written by
    `cargo run --release -p analysis -- all --out <out>/analysis`), headings
    demoted under one section, with its plots."""
    report = out / "analysis" / "report.md"
    if not report.exists():
        return []
    lines = ["", "## Analysis: modes, closed-loop poles, sensitivity (Table 5.1) and robustness", ""]
    for line in report.read_text().splitlines():
        if line.startswith("#"):
            line = "#" + line if line.startswith("##") else "### " + line.lstrip("# ")
            line = line if not line.startswith("####") else "### " + line.lstrip("# ")
        lines.append(line)
    pngs = sorted((out / "analysis").glob("*.png"))
    if pngs:
        lines += ["", "### Analysis plots", ""]
        for p in pngs:
            lines += [f"![{p.stem}](analysis/{p.name})", ""]
    return lines


def fmt(x: float, digits: int = 2) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    if isinstance(x, float) and math.isinf(x):
        return "never"
    return f"{x:.{digits}f}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="tailsim.compare", description=__doc__.split("\n\n")[0])
    ap.add_argument("--controller", choices=["lqr", "tsd", "both"], default="both")
    ap.add_argument("--dist", default="dist", help="folder with the .fmu files")
    ap.add_argument("--out", default="out", help="output folder")
    ap.add_argument("--fast-t1", type=float, default=3.0, help="T1 of the fast mission [s]")
    ap.add_argument("--fast-t2", type=float, default=4.0, help="T2 of the fast mission [s]")
    ap.add_argument("--no-steps", action="store_true", help="skip the position-step tests")
    ap.add_argument("--jacobi", action="store_true", help="use a Jacobi master instead of Gauss-Seidel")
    args = ap.parse_args(argv)

    from tqdm import tqdm

    out = pathlib.Path(args.out)
    (out / "csv").mkdir(parents=True, exist_ok=True)
    dist = pathlib.Path(args.dist)
    keys = ["lqr", "tsd"] if args.controller == "both" else [args.controller]
    plant = Fmu(dist / "tailsitter_plant.fmu")
    ctrls = {k: Fmu(dist / f"{NAMES[k]}.fmu") for k in keys}
    theta_trim = level_trim_theta(plant, 25.0)
    ordering = "jacobi" if args.jacobi else "gauss-seidel"

    missions = {"default": (5.0, 10.0), "fast": (args.fast_t1, args.fast_t2)}
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
                params = mission_params(t1, t2)
                loop = ClosedLoop(plant, ctrls[key], controller_params=params, ordering=ordering)
                r = loop.run(stop_time=20.0 + t1 + t2, progress=True, description=f"{key} {name}")
                mission_runs[name][key] = r
                r.write_csv(out / "csv" / f"{key}_{name}_mission.csv")
            else:
                case = next(c for c in STEP_CASES if f"{c[0]} {c[1]}" == name)
                _, _, offset, t_step, params, stop = case
                loop = ClosedLoop(plant, ctrls[key], controller_params=params, ordering=ordering)
                r = loop.run(stop_time=stop, ref_offset=step(t_step, offset), progress=True, description=f"{key} {name}")
                step_runs[key][name] = (r, t_step)
                r.write_csv(out / "csv" / f"{key}_step_{name.replace(' ', '_')}.csv")
        except Exception as e:  # noqa: BLE001 - a failed run is a result of the comparison
            failures[(kind, name, key)] = str(e)

    plots = []
    for m, runs in mission_runs.items():
        if runs:
            t1, t2 = missions[m]
            p = out / f"mission_{m}.png"
            plot_mission(runs, f"{m} mission: T1 = {t1:g} s, T2 = {t2:g} s", p)
            plots.append((f"{m.capitalize()} mission (T1 = {t1:g} s, T2 = {t2:g} s)", p))
    if not args.no_steps and any(step_runs.values()):
        p = out / "steps.png"
        plot_steps(step_runs, p)
        plots.append(("Position steps of 5 m (§3.4.1, §4.4.2)", p))

    # The comparison table.
    rows: list[tuple[str, list[str]]] = []
    metrics = {}
    for m, (t1, t2) in missions.items():
        for k in keys:
            if k in mission_runs[m]:
                metrics[(m, k)] = mission_metrics(mission_runs[m][k], 5.0 + t1 + 10.0, theta_trim)
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
    for i, ph in enumerate(PHASES):
        row(f"max / RMS position error, {ph} [m]", lambda x, i=i: f"{fmt(x.max_error[i])} / {fmt(x.rms_error[i])}")
    row("max altitude deviation, transition 1 / 2 [m]", lambda x: " / ".join(fmt(v) for v in x.altitude_deviation_transition))
    row("max α [deg]", lambda x: fmt(x.max_alpha_deg, 1))
    row("time in actuator saturation [s]", lambda x: fmt(x.saturation_time))
    row("level flight: max airspeed error [m/s] / pitch error [deg]", lambda x: f"{fmt(x.level_airspeed_error)} / {fmt(x.level_pitch_error_deg)}")
    row("controller compute per step (fmpy call incl.) [µs]", lambda x: fmt(x.controller_us_per_step, 0))
    fastest = {}
    for k in keys:
        # Flown = completed with α in the linear region of the aerodynamic model (< 20°, thesis §4.4.4).
        done = [
            missions[m]
            for m in missions
            if (m, k) in metrics and metrics[(m, k)].completed and metrics[(m, k)].max_alpha_deg < 20.0
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
        step_rows.append((f"settling time to < 0.5 m, 5 m step, {name} [s]", vals))

    md = ["# Tail-sitter controller comparison", ""]
    md.append(f"Master: fmpy, {ordering}; plant `tailsitter_plant`; controllers: {', '.join(NAMES[k] for k in keys)}. "
              f"Level-trim pitch of the plant at 25 m/s: {math.degrees(theta_trim):.2f}°. Wall time {time.time() - t_start:.0f} s.")
    md += ["", "## Missions (thesis ch. 6 comparison)", ""]
    md.append("| " + " | ".join(header) + " |")
    md.append("|" + "---|" * len(header))
    for label, vals in rows:
        md.append(f"| {label} | " + " | ".join(vals) + " |")
    md += ["", "Fastest transition flown (completed with α < 20°): " + ", ".join(
        f"{k.upper()} T1 = {fastest[k][0]:g} s, T2 = {fastest[k][1]:g} s" if fastest[k] else f"{k.upper()}: none of the missions flown kept α < 20°"
        for k in keys)]
    if step_rows:
        md += ["", "## Position steps", "", "| step | " + " | ".join(k.upper() for k in keys) + " |", "|" + "---|" * (len(keys) + 1)]
        for label, vals in step_rows:
            md.append(f"| {label} | " + " | ".join(vals) + " |")
    if failures:
        md += ["", "## Failed runs", ""] + [f"- {k[2].upper()} {k[1]} ({k[0]}): {v}" for k, v in failures.items()]
    md += ["", "## Plots", ""]
    for title, p in plots:
        md += [f"### {title}", "", f"![{title}]({p.name})", ""]
    md += ["CSV of every run (time + all signals, units in the header): `csv/`."]
    md += analysis_section(out)
    (out / "report.md").write_text("\n".join(md) + "\n")

    body = []
    in_table = False
    for line in md:
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip("|").split("|")]
            if set("".join(cells)) <= set("-"):
                continue
            if not in_table:
                body.append("<table>")
                in_table = True
                body.append("<tr>" + "".join(f"<th>{html.escape(c)}</th>" for c in cells) + "</tr>")
            else:
                body.append("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in cells) + "</tr>")
            continue
        if in_table:
            body.append("</table>")
            in_table = False
        if line.startswith("### "):
            body.append(f"<h3>{html.escape(line[4:])}</h3>")
        elif line.startswith("## "):
            body.append(f"<h2>{html.escape(line[3:])}</h2>")
        elif line.startswith("# "):
            body.append(f"<h1>{html.escape(line[2:])}</h1>")
        elif line.startswith("!["):
            name = line[line.rindex("](") + 2 : -1]
            data = base64.b64encode((out / name).read_bytes()).decode()
            body.append(f'<img alt="{html.escape(name)}" src="data:image/png;base64,{data}" style="max-width:100%">')
        elif line.startswith("- "):
            body.append(f"<p>• {html.escape(line[2:])}</p>")
        elif line:
            body.append(f"<p>{html.escape(line)}</p>")
    if in_table:
        body.append("</table>")
    style = "body{font-family:sans-serif;max-width:80em;margin:2em auto}table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:3px 8px}th{background:#eee}"
    (out / "report.html").write_text(f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>Tail-sitter comparison</title><style>{style}</style></head><body>{''.join(body)}</body></html>\n")
    summary = {f"{k}_{m}": vars(v) for (m, k), v in metrics.items()}
    (out / "metrics.json").write_text(json.dumps(summary, indent=1, default=str))
    print(f"report: {out / 'report.md'} and {out / 'report.html'}; plots and csv/ in {out}/")
    for f in failures.values():
        print("failed run:", f, file=sys.stderr)
    plant.cleanup()
    for c in ctrls.values():
        c.cleanup()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
