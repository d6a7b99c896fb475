"""Wind-envelope section of the analysis report, rendered from `wind_envelope.json`
(`cargo run --release -p analysis -- wind-envelope --out out/analysis`, `--all` for every
axis; `crates/analysis/src/wind_envelope.rs`, schema in crates/analysis/README.md): the
controllers over whole missions in a steady wind of every speed from every bearing, stepping
in or present from the start with moderate Dryden turbulence (the atmosphere), on the axes
state source (perfect / avionics), ordering (Gauss-Seidel / Jacobi) and configuration
(tuned / thesis).

`load_into(d, folder)` adds the data under `wind_envelope`; `section(d)` gives the
Markdown lines (hooked into `tailsim.reports.analysis.SECTIONS`): the held cells per
controller and axis at each speed, then one speed × bearing table per axis, mission and
wind form; `plot(folder)` draws a speed × bearing heat map per controller, mission and wind
form for each axis (held / completed / lost, the largest error annotated): `wind_envelope.png`
for perfect state, Gauss-Seidel, tuned, `wind_envelope_<configuration>_<state>_<ordering>.png`
for the others, and with more than one axis `wind_envelope_axes.png` (cells held against wind
speed per controller and axis).
"""

from __future__ import annotations

import math
import pathlib

from . import load_json_into

FILE = "wind_envelope.json"
MISSIONS = {
    "default": "default mission",
    "takeoff_landing": "take-off to landing",
    "handover": "hover-to-transition handover",
}
WINDS = {
    "step": "steady wind stepping in",
    "turbulent": "steady wind from t = 0 with moderate Dryden turbulence",
}
STATES = {"perfect": "perfect state", "avionics": "avionics", "avionics_app_d": "avionics (App.-D estimator)"}
ORDERINGS = {"gauss-seidel": "Gauss-Seidel", "jacobi": "Jacobi"}
CONFIGURATIONS = {"tuned": "tuned", "thesis": "thesis"}
#: The axis of a file without axes (one grid: perfect state, Gauss-Seidel, tuned).
DEFAULT_AXIS = ("tuned", "perfect", "gauss-seidel")


def load_into(d: dict, folder: str | pathlib.Path) -> dict:
    """Add `wind_envelope.json` of `folder` (if the analysis wrote it) to the report data `d`."""
    return load_json_into(d, folder, FILE, "wind_envelope")


def _err(x) -> str:
    return "–" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.1f}"


def axis_of(c: dict, w: dict | None = None) -> tuple[str, str, str]:
    """(configuration, state, ordering) of cell `c`; a file without axes flew one (its
    top-level `state` and `ordering`, the tuned configuration)."""
    w = w or {}
    return (
        c.get("configuration", "tuned"),
        c.get("state", w.get("state", "perfect")),
        c.get("ordering", w.get("ordering", "gauss-seidel")),
    )


def axis_label(axis: tuple[str, str, str]) -> str:
    """The axis in words, e.g. "tuned, perfect state, Gauss-Seidel"."""
    configuration, state, ordering = axis
    return (
        f"{CONFIGURATIONS.get(configuration, configuration)}, {STATES.get(state, state)}, "
        f"{ORDERINGS.get(ordering, ordering)}"
    )


def axes(w: dict) -> list[tuple[str, str, str]]:
    """The axes of the cells, in the order they were flown."""
    return list(dict.fromkeys(axis_of(c, w) for c in w["cells"]))


def error_limit(w: dict, state: str) -> float:
    """The held limit of a state source (m)."""
    return w.get("held_max_error_avionics", 5.0) if state.startswith("avionics") else w["held_max_error"]


def _cells(w: dict, mission: str, wind: str, controller: str, axis=None) -> list[dict]:
    return [
        c
        for c in w["cells"]
        if (c["mission"], c["wind"], c["controller"]) == (mission, wind, controller)
        and (axis is None or axis_of(c, w) == axis)
    ]


def _controllers(w: dict) -> list[str]:
    return list(dict.fromkeys(c["controller"] for c in w["cells"]))


def _missions(w: dict) -> list[str]:
    return [m for m in MISSIONS if any(c["mission"] == m for c in w["cells"])]


def _winds(w: dict) -> list[str]:
    return [f for f in WINDS if any(c["wind"] == f for c in w["cells"])]


def _speeds(w: dict) -> list[float]:
    return sorted({c["speed"] for c in w["cells"]})


def held_per_speed(cells: list[dict], speeds: list[float]) -> list[tuple[int, int]]:
    """(cells held, cells) at each of `speeds`."""
    out = []
    for s in speeds:
        row = [c for c in cells if c["speed"] == s]
        out.append((sum(bool(c["held"]) for c in row), len(row)))
    return out


def held_table(w: dict) -> list[str]:
    """Cells held out of those flown per controller × axis × mission × wind form at each
    speed, and the largest error of the completed cells (m)."""
    speeds = _speeds(w)
    out = [
        "| controller | configuration | state | ordering | mission | wind | "
        + " | ".join(f"{s:g} m/s" for s in speeds)
        + " | held | largest error of the completed (m) |",
        "|---|---|---|---|---|---|" + "---|" * len(speeds) + "---|---|",
    ]
    for k in _controllers(w):
        for axis in axes(w):
            for mission in _missions(w):
                for wind in _winds(w):
                    cells = _cells(w, mission, wind, k, axis)
                    if not cells:
                        continue
                    counts = [f"{h}/{n}" if n else "–" for h, n in held_per_speed(cells, speeds)]
                    done = [c["max_error"] for c in cells if c["completed"] and c["max_error"] is not None]
                    largest = _err(max(done)) if done else "–"
                    configuration, state, ordering = axis
                    out.append(
                        f"| {k} | {configuration} | {STATES.get(state, state)} | {ORDERINGS.get(ordering, ordering)} "
                        f"| {MISSIONS[mission]} | {wind} | "
                        + " | ".join(counts)
                        + f" | {sum(c['held'] for c in cells)}/{len(cells)} | {largest} |"
                    )
    return out


def section(d: dict) -> list[str]:
    """Markdown lines of the section (empty without data)."""
    w = d.get("wind_envelope")
    if not w:
        return []
    bearings = w["bearings_deg"]
    limit_avionics = w.get("held_max_error_avionics", 5.0)
    timing = f"{len(w['cells'])} flights in {w['wall_time_s']:.0f} s on {w['threads']} threads"
    if w.get("cpu_time_s") and w.get("flown"):
        timing += f" ({w['flown']} flown, {w['flown'] / w['cpu_time_s']:.1f} flights per CPU-second)"
    out = [
        "## Wind envelope over whole missions",
        "",
        "The plant FMU's default plant (global aerodynamics, ground 10 m below the start). Steady horizontal wind "
        "from each bearing (clockwise from north, the mission's heading: 0° a headwind in level flight), stepping in "
        f"at {w['step_time']:g} s, or present from t = 0 through the atmosphere (uniform profile, moderate Dryden "
        "turbulence, W20 = 30 kt, seed 1 + the bearing's index). Axes: the controllers' configuration (tuned, or "
        "the thesis's as printed), the state they measure (perfect: the plant's outputs; avionics: the estimate of "
        "the sensors and the estimator, sensors seeded 1 + the bearing's index) and the master's ordering "
        "(Gauss-Seidel, or Jacobi: one sample of delay between the units). **Held**: the flight completes (the "
        "landing mission: lands within the limit of the target) and the true position stays within "
        f"{w['held_max_error']:g} m (perfect state; {limit_avionics:g} m with avionics) of the controller's own "
        "reference throughout. Each cell: largest distance to the reference (m), ✓ held, ✗ lost (did not "
        "complete), ~ completed beyond the limit; for the landing mission also the distance from the target at "
        f"rest (m) / touchdown speed (m/s) where it landed. {timing}.",
        "",
    ]
    if len(axes(w)) > 1:
        out += ["### Cells held per controller and axis", "", *held_table(w), ""]
    for axis in axes(w):
        label = axis_label(axis)
        for mission in _missions(w):
            for wind in _winds(w):
                rows = []
                for k in _controllers(w):
                    cells = _cells(w, mission, wind, k, axis)
                    for s in _speeds(w):
                        row = sorted((c for c in cells if c["speed"] == s), key=lambda c: c["bearing_deg"])
                        if not row:
                            continue
                        held = sum(c["held"] for c in row)
                        marks = []
                        for c in row:
                            m = "✓" if c["held"] else ("~" if c["completed"] else "✗")
                            text = f"{m} {_err(c['max_error'])}"
                            if mission == "takeoff_landing" and c.get("touchdown_speed") is not None:
                                text += f" ({_err(c['landing_distance'])}/{_err(c['touchdown_speed'])})"
                            marks.append(text)
                        rows.append(f"| {k} | {s:g} | {held}/{len(row)} | " + " | ".join(marks) + " |")
                if not rows:
                    continue
                out += [f"### {MISSIONS[mission]}, {WINDS[wind]} — {label}", ""]
                header = "| controller | speed (m/s) | held | " + " | ".join(f"{b:g}°" for b in bearings) + " |"
                out += [header, "|---|---|---|" + "---|" * len(bearings), *rows, ""]
    return out


def png_name(axis: tuple[str, str, str]) -> str:
    """The heat map's file of an axis: `wind_envelope.png` for perfect state, Gauss-Seidel, tuned."""
    if axis == DEFAULT_AXIS:
        return "wind_envelope.png"
    return "wind_envelope_" + "_".join(a.replace("-", "_") for a in axis) + ".png"


def plot(folder: str | pathlib.Path) -> list[pathlib.Path]:
    """Draw the heat maps (one PNG per axis) and, with more than one axis, the held cells
    against speed (`wind_envelope_axes.png`) into `folder`; their paths (none without data)."""
    folder = pathlib.Path(folder)
    w = load_into({}, folder).get("wind_envelope")
    if not w:
        return []
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = []
    for axis in axes(w):
        fig = _heat_maps(plt, w, axis)
        path = folder / png_name(axis)
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    if len(axes(w)) > 1:
        fig = _held_against_speed(plt, w)
        path = folder / "wind_envelope_axes.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths


def _heat_maps(plt, w: dict, axis: tuple[str, str, str]):
    import numpy as np
    from matplotlib.colors import ListedColormap

    controllers = _controllers(w)
    panels = [
        (m, wind) for m in _missions(w) for wind in _winds(w) if any(_cells(w, m, wind, k, axis) for k in controllers)
    ]
    speeds, bearings = _speeds(w), w["bearings_deg"]
    fig, ax_grid = plt.subplots(
        len(panels), len(controllers), figsize=(5.2 * len(controllers), 2.9 * len(panels)), squeeze=False
    )
    cmap = ListedColormap(["#d9534f", "#f0ad4e", "#5cb85c"])  # lost, completed beyond the limit, held
    for i, (mission, wind) in enumerate(panels):
        for j, k in enumerate(controllers):
            ax = ax_grid[i][j]
            grid = np.full((len(speeds), len(bearings)), np.nan)
            cells = _cells(w, mission, wind, k, axis)
            for c in cells:
                r, q = speeds.index(c["speed"]), bearings.index(c["bearing_deg"])
                grid[r, q] = 2 if c["held"] else (1 if c["completed"] else 0)
                e = c["max_error"]
                label = _err(e) if c["completed"] else f"✗ {_err(e)}"
                ax.text(q, r, label, ha="center", va="center", fontsize=7)
            ax.imshow(grid, cmap=cmap, vmin=0, vmax=2, aspect="auto", origin="lower")
            ax.set_xticks(range(len(bearings)), [f"{b:g}" for b in bearings], fontsize=7)
            ax.set_yticks(range(len(speeds)), [f"{s:g}" for s in speeds], fontsize=7)
            held = sum(c["held"] for c in cells)
            ax.set_title(f"{k}: {MISSIONS[mission]}, {wind} ({held}/{len(cells)} held)", fontsize=8)
            if i == len(panels) - 1:
                ax.set_xlabel("wind from (deg)", fontsize=8)
            if j == 0:
                ax.set_ylabel("speed (m/s)", fontsize=8)
    limit = error_limit(w, axis[1])
    fig.suptitle(
        f"Wind envelope, {axis_label(axis)}: green held (< {limit:g} m), orange completed beyond it, red lost; "
        "largest distance to the reference (m)",
        fontsize=9,
    )
    fig.tight_layout()
    return fig


def _held_against_speed(plt, w: dict):
    """Per controller (columns) and wind form (rows): the fraction of the cells held at each
    speed, one line per axis and mission."""
    controllers, winds, speeds = _controllers(w), _winds(w), _speeds(w)
    fig, ax_grid = plt.subplots(
        len(winds), len(controllers), figsize=(5.6 * len(controllers), 3.4 * len(winds)), squeeze=False
    )
    styles = {"default": "-", "takeoff_landing": "--", "handover": ":"}
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, wind in enumerate(winds):
        for j, k in enumerate(controllers):
            ax = ax_grid[i][j]
            for n, axis in enumerate(axes(w)):
                for mission in _missions(w):
                    cells = _cells(w, mission, wind, k, axis)
                    if not cells:
                        continue
                    frac = [h / n if n else float("nan") for h, n in held_per_speed(cells, speeds)]
                    ax.plot(
                        speeds,
                        frac,
                        styles.get(mission, "-"),
                        marker="o",
                        ms=3,
                        color=colours[n % len(colours)],
                        label=f"{axis_label(axis)}; {MISSIONS[mission]}",
                    )
            ax.set_ylim(-0.05, 1.05)
            ax.set_title(f"{k}: {WINDS[wind]}", fontsize=8)
            ax.set_xlabel("wind speed (m/s)", fontsize=8)
            if j == 0:
                ax.set_ylabel("cells held (fraction of the bearings)", fontsize=8)
            ax.grid(alpha=0.3)
    handles, labels = ax_grid[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=6)
    fig.suptitle("Wind envelope: cells held against wind speed per controller and axis", fontsize=9)
    fig.tight_layout(rect=(0, 0.04 + 0.018 * len(labels) / 2, 1, 1))
    return fig
