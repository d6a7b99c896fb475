"""Wind-envelope section of the analysis report, rendered from `wind_envelope.json`
(`cargo run --release -p analysis -- wind-envelope --out out/analysis`,
`crates/analysis/src/wind_envelope.rs`): both tuned controllers over whole missions in a
steady wind of every speed from every bearing, stepping in or present from the start
with moderate Dryden turbulence (the atmosphere).

`load_into(d, folder)` adds the data under `wind_envelope`; `section(d)` gives the
Markdown lines (hooked into `tailsim.reports.analysis.SECTIONS`); `plot(folder)` draws
`wind_envelope.png`, a speed × bearing heat map per controller, mission and wind form
(held / completed / lost, the largest error annotated).
"""

from __future__ import annotations

import math
import pathlib

from . import load_json_into

FILE = "wind_envelope.json"
MISSIONS = {"default": "default mission", "takeoff_landing": "take-off to landing"}
WINDS = {
    "step": "steady wind stepping in",
    "turbulent": "steady wind from t = 0 with moderate Dryden turbulence",
}


def load_into(d: dict, folder: str | pathlib.Path) -> dict:
    """Add `wind_envelope.json` of `folder` (if the analysis wrote it) to the report data `d`."""
    return load_json_into(d, folder, FILE, "wind_envelope")


def _err(x) -> str:
    return "–" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.1f}"


def _cells(w: dict, mission: str, wind: str, controller: str) -> list[dict]:
    return [c for c in w["cells"] if (c["mission"], c["wind"], c["controller"]) == (mission, wind, controller)]


def _controllers(w: dict) -> list[str]:
    return list(dict.fromkeys(c["controller"] for c in w["cells"]))


def _missions(w: dict) -> list[str]:
    return [m for m in MISSIONS if any(c["mission"] == m for c in w["cells"])]


def section(d: dict) -> list[str]:
    """Markdown lines of the section (empty without data)."""
    w = d.get("wind_envelope")
    if not w:
        return []
    bearings = w["bearings_deg"]
    out = [
        "## Wind envelope over whole missions",
        "",
        "Both tuned controllers, perfect state, Gauss-Seidel, the plant FMU's default plant (global aerodynamics, "
        "ground 10 m below the start). Steady horizontal wind from each bearing (clockwise from north, the "
        f"mission's heading: 0° a headwind in level flight), stepping in at {w['step_time']:g} s, or present from "
        "t = 0 through the atmosphere (uniform profile, moderate Dryden turbulence, W20 = 30 kt, seed 1 + the "
        f"bearing's index). **Held**: the flight completes (the landing mission: lands within "
        f"{w['held_max_error']:g} m of the target) and stays within {w['held_max_error']:g} m of the controller's "
        "own reference throughout. Each cell: largest distance to the reference (m), ✓ held, ✗ lost (did not "
        "complete), ~ completed beyond the limit; for the landing mission also the distance from the target at "
        "rest (m) / touchdown speed (m/s) where it landed. "
        f"{len(w['cells'])} flights in {w['wall_time_s']:.0f} s on {w['threads']} threads.",
        "",
    ]
    for mission in _missions(w):
        for wind in WINDS:
            out += [f"### {MISSIONS[mission]}, {WINDS[wind]}", ""]
            header = "| controller | speed (m/s) | held | " + " | ".join(f"{b:g}°" for b in bearings) + " |"
            out += [header, "|---|---|---|" + "---|" * len(bearings)]
            for k in _controllers(w):
                cells = _cells(w, mission, wind, k)
                for s in w["speeds"]:
                    row = sorted((c for c in cells if c["speed"] == s), key=lambda c: c["bearing_deg"])
                    if not row:
                        continue
                    held = sum(c["held"] for c in row)
                    marks = []
                    for c in row:
                        m = "✓" if c["held"] else ("~" if c["completed"] else "✗")
                        text = f"{m} {_err(c['max_error'])}"
                        if mission == "takeoff_landing" and c["touchdown_speed"] is not None:
                            text += f" ({_err(c['landing_distance'])}/{_err(c['touchdown_speed'])})"
                        marks.append(text)
                    out.append(f"| {k} | {s:g} | {held}/{len(row)} | " + " | ".join(marks) + " |")
            out.append("")
    return out


def plot(folder: str | pathlib.Path) -> pathlib.Path | None:
    """Draw `wind_envelope.png` into `folder` (None without data)."""
    folder = pathlib.Path(folder)
    w = load_into({}, folder).get("wind_envelope")
    if not w:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.colors import ListedColormap

    controllers, missions = _controllers(w), _missions(w)
    panels = [(m, wind) for m in missions for wind in WINDS]
    speeds, bearings = w["speeds"], w["bearings_deg"]
    fig, axes = plt.subplots(
        len(panels), len(controllers), figsize=(5.2 * len(controllers), 2.9 * len(panels)), squeeze=False
    )
    cmap = ListedColormap(["#d9534f", "#f0ad4e", "#5cb85c"])  # lost, completed beyond the limit, held
    for i, (mission, wind) in enumerate(panels):
        for j, k in enumerate(controllers):
            ax = axes[i][j]
            grid = np.full((len(speeds), len(bearings)), np.nan)
            for c in _cells(w, mission, wind, k):
                r, q = speeds.index(c["speed"]), bearings.index(c["bearing_deg"])
                grid[r, q] = 2 if c["held"] else (1 if c["completed"] else 0)
                e = c["max_error"]
                label = _err(e) if c["completed"] else f"✗ {_err(e)}"
                ax.text(q, r, label, ha="center", va="center", fontsize=7)
            ax.imshow(grid, cmap=cmap, vmin=0, vmax=2, aspect="auto", origin="lower")
            ax.set_xticks(range(len(bearings)), [f"{b:g}" for b in bearings], fontsize=7)
            ax.set_yticks(range(len(speeds)), [f"{s:g}" for s in speeds], fontsize=7)
            held = sum(c["held"] for c in _cells(w, mission, wind, k))
            ax.set_title(f"{k}: {MISSIONS[mission]}, {wind} ({held} held)", fontsize=8)
            if i == len(panels) - 1:
                ax.set_xlabel("wind from (deg)", fontsize=8)
            if j == 0:
                ax.set_ylabel("speed (m/s)", fontsize=8)
    fig.suptitle(
        f"Wind envelope: green held (< {w['held_max_error']:g} m), orange completed beyond it, red lost; "
        "largest distance to the reference (m)",
        fontsize=9,
    )
    fig.tight_layout()
    path = folder / "wind_envelope.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
