"""Take-off-to-landing section of the analysis report, rendered from the
`takeoff_landing` key the Rust campaign writes into `report.json`
(`crates/analysis/src/takeoff_landing.rs`): both controllers start at rest on the gear,
take off, fly the thesis's mission and land on a target point, on the global
aerodynamics, Gauss-Seidel and Jacobi.

`section(d)` gives the Markdown lines (hooked into `tailsim.reports.analysis.SECTIONS`);
`plot(folder)` draws `takeoff_landing.png` (called by `tailsim.reports.analysis.write`).
"""

from __future__ import annotations

import json
import math
import pathlib

from .. import declarations

#: Phase codes of the controllers' `phase` output (modelDescription/fragments/controller_interface.json).
PHASE_NAMES = declarations.PHASE_NAMES


def _f(x, digits=2) -> str:
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{digits}f}"


def section(d: dict) -> list[str]:
    """Markdown lines of the section (empty without data)."""
    tl = d.get("takeoff_landing")
    if not tl:
        return []
    c = tl["criteria"]
    m = dict(tl["mission"])
    out = [
        "## Take-off and landing",
        "",
        "Both controllers start at rest on the gear (plant `initial_condition = 2`, global aerodynamics, ground "
        f"contact), spin the motors up for {_f(m['takeoff_spinup_time'], 1)} s to "
        f"{_f(100 * m['takeoff_spinup_thrust'], 0)} % of the weight without flying, take off "
        f"(climb rate ramped to V_V over {_f(m['takeoff_time'], 1)} s), fly the thesis's mission, stop over the "
        f"landing target ({_f(m['landing_target_n'], 1)} m N, {_f(m['landing_target_e'], 1)} m E of the take-off "
        f"point), descend tail first at {_f(m['landing_descent_rate'], 1)} m/s, flare from "
        f"{_f(m['landing_flare_height'], 1)} m to {_f(m['landing_touchdown_rate'], 1)} m/s and cut the thrust once "
        f"the gear carries the aircraft. Criteria: touchdown vertical speed < {_f(c['max_touchdown_speed'], 1)} m/s, "
        f"within {_f(c['max_miss_distance'], 1)} m of the target, upright (tilt < {_f(c['max_tilt_deg'], 0)}°), "
        "no bounce.",
        "",
        "| controller | ordering | lift-off (s) | touchdown (s) | touchdown speed (m/s) | miss at touchdown / rest (m) "
        "| tilt at touchdown / rest (°) | horizontal speed (m/s) | bounce | max error to touchdown (m) | passed |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for f in tl["flights"]:
        out.append(
            f"| {f['controller']} | {f['ordering']} | {_f(f['liftoff_time'])} | {_f(f['touchdown_time'])} "
            f"| {_f(f['touchdown_speed'], 3)} | {_f(f['miss_touchdown'], 3)} / {_f(f['miss_final'], 3)} "
            f"| {_f(f['tilt_touchdown_deg'])} / {_f(f['tilt_final_deg'])} | {_f(f['horizontal_speed_touchdown'], 3)} "
            f"| {'yes' if f['bounced'] else 'no'} ({_f(1000 * f['rebound_height'], 1)} mm) "
            f"| {_f(f['max_pos_error'])} | {'yes' if f['passed'] else 'NO'} |"
            + (f" {f['failure']}" if f["failure"] else "")
        )
    out += ["", "Maximum position error per phase (m):", ""]
    phases = []
    for f in tl["flights"]:
        for p in f["phases"]:
            if p["phase"] not in phases:
                phases.append(p["phase"])
    out.append("| controller | ordering | " + " | ".join(PHASE_NAMES.get(p, str(p)) for p in phases) + " |")
    out.append("|---|---|" + "---|" * len(phases))
    for f in tl["flights"]:
        by = {p["phase"]: p["max"] for p in f["phases"]}
        out.append(f"| {f['controller']} | {f['ordering']} | " + " | ".join(_f(by.get(p), 3) for p in phases) + " |")
    out.append("")
    return out


def plot(folder: str | pathlib.Path) -> pathlib.Path | None:
    """Draw `takeoff_landing.png` (track north–height, height and tilt against time) into `folder`."""
    folder = pathlib.Path(folder)
    path = folder / "report.json"
    if not path.exists():
        return None
    tl = json.loads(path.read_text()).get("takeoff_landing")
    if not tl:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    for f in tl["flights"]:
        if f["ordering"] != "gauss-seidel":
            continue
        rows = f["trajectory"]
        t = [r[0] for r in rows]
        n = [r[1] for r in rows]
        d0 = rows[0][3]  # heights above the take-off point
        h = [d0 - r[3] for r in rows]
        (line,) = axes[0].plot(n, h, lw=1.2, label=f["controller"])
        axes[0].plot([r[4] for r in rows], [d0 - r[6] for r in rows], "--", lw=0.8, color=line.get_color())
        axes[1].plot(t, h, lw=1.2, color=line.get_color(), label=f["controller"])
        axes[2].plot(t, [r[8] for r in rows], lw=1.0, color=line.get_color(), label=f["controller"])
        tgt = f["target"]
        axes[0].plot([tgt[0]], [d0 - tgt[2]], "kx")
    axes[0].set_xlabel("north (m)")
    axes[0].set_ylabel("height above take-off (m)")
    axes[0].set_title("track (dashed: reference; x: target)", fontsize=9)
    axes[1].set_xlabel("t (s)")
    axes[1].set_ylabel("height above take-off (m)")
    axes[1].set_title("height", fontsize=9)
    axes[2].set_xlabel("t (s)")
    axes[2].set_ylabel("tilt from vertical (deg)")
    axes[2].set_title("attitude", fontsize=9)
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Take-off to landing, global aerodynamics, Gauss-Seidel", fontsize=10)
    fig.tight_layout()
    out = folder / "takeoff_landing.png"
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


#: The take-off-to-landing mission of the report (the Rust `analysis::takeoff_landing::mission`):
#: controller parameters on top of the declared defaults (the declared preset `takeoff_landing`).
MISSION = dict(declarations.PRESETS["takeoff_landing"])
#: The plant at rest on the gear (global aerodynamics and the ground are its defaults).
PLANT = {"initial_condition": 2}


def touchdown(result, mission: dict | None = None) -> dict:
    """Touchdown figures of a `tailsim.masters.RunResult` of the mission (plant outputs):
    first contact after lift-off, the gear's sink rate there (`touchdown_speed`, the larger of
    the plant's output and the CG's sink just before), miss distance from the target at
    touchdown and at the end, tilt from the vertical (|90° − θ|), bounce (contact lost after
    the touchdown), and whether the controller declared the landing (phase 10)."""
    import numpy as np

    m = {**MISSION, **(mission or {})}
    contact = result["ground_contact_points"]
    n, e, dn = result["pos_n"], result["pos_e"], result["pos_d"]
    target = np.array([n[0] + m["landing_target_n"], e[0] + m["landing_target_e"]])
    airborne = np.flatnonzero(contact == 0)
    if airborne.size == 0:
        return {"lifted_off": False}
    after = np.flatnonzero((contact > 0) & (np.arange(contact.size) > airborne[0]))
    if after.size == 0:
        return {"lifted_off": True, "touched_down": False}
    k = after[0]
    tilt = np.abs(90.0 - np.degrees(result["theta"]))
    miss = np.hypot(n - target[0], e - target[1])
    return {
        "lifted_off": True,
        "touched_down": True,
        "liftoff_time": float(result.time[airborne[0]]),
        "touchdown_time": float(result.time[k]),
        "touchdown_speed": float(max(result["touchdown_speed"][-1], result["vel_d"][k - 1])),
        "miss_touchdown": float(miss[k]),
        "miss_final": float(miss[-1]),
        "tilt_touchdown_deg": float(tilt[k]),
        "tilt_final_deg": float(tilt[-1]),
        "bounced": bool(np.any(contact[k:] == 0)),
        "landed": bool(np.any(result["phase"] == 10)),
        "final_pos_d": float(dn[-1]),
    }
