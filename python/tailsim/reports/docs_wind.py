"""The wind envelope in the documentation: the compact result file `docs/wind_envelope.json`
and the blocks generated from it (registered into `tailsim.reports.docs.BLOCKS`).

`summarize(full, command)` condenses the analysis's `wind_envelope.json`
(`cargo run --release -p analysis -- wind-envelope --all --threads 1 --out out/analysis`,
`crates/analysis/src/wind_envelope.rs`; every cell with its flight's details) into one row
per controller × configuration × state source × ordering × mission × wind form × speed:
the cells held of those flown (one per bearing), completed, landings passed (the
take-off-to-landing mission), the smallest and largest of the completed cells' largest
errors, and per bearing the cell's largest error and status (`STATUS`). Regeneration, one
command after the analysis run (`COMMAND`):

    python -m tailsim.reports.docs --write --wind-envelope out/analysis/wind_envelope.json

writes `docs/wind_envelope.json` and rewrites every block below (docs/WIND.md, the README's
wind sentence, the controllers' READMEs' "Wind envelope" sections).
"""

from __future__ import annotations

import json
import math
import subprocess
from collections.abc import Mapping, Sequence
from typing import Any

from .docs import ROOT, Sources, block

WIND = "wind_envelope.json"
#: The run and the summary that make `docs/wind_envelope.json`.
COMMAND = (
    "cargo run --release -p analysis -- wind-envelope --all --threads 1 --out out/analysis; "
    "python -m tailsim.reports.docs --write --wind-envelope out/analysis/wind_envelope.json"
)
#: A cell's status, one letter per bearing.
STATUS = {
    "H": "held: completed within the error limit of the reference",
    "C": "completed, beyond the error limit",
    "L": "lost: farther than the lost distance from the reference, stopped",
    "N": "did not land by the stop time",
    "T": "landed beyond the error limit from the target",
    "F": "stopped by an error of the plant, controller or estimator",
}
MISSIONS = {"default": "default mission", "takeoff_landing": "take-off to landing", "handover": "handover"}
WINDS = {"step": "step", "turbulent": "turbulent"}
STATES = {"perfect": "perfect", "avionics": "avionics", "avionics_app_d": "avionics (App. D)"}
ORDERINGS = {"gauss-seidel": "Gauss-Seidel", "jacobi": "Jacobi"}
#: The axis of the envelope tables: the goals' axis (tuned controllers, perfect state, Gauss-Seidel).
MAIN_AXIS = ("tuned", "perfect", "gauss-seidel")
_AXIS_KEYS = ("configuration", "state", "ordering")
_ROW_KEYS = ("controller", *_AXIS_KEYS, "mission", "wind", "speed")
#: The axis of a cell that names none (a file of one grid: tuned, perfect state, Gauss-Seidel).
_DEFAULT_AXIS = dict(zip(_AXIS_KEYS, MAIN_AXIS, strict=True))


# --- the summary ---------------------------------------------------------------------------------------------------


def status(c: Mapping[str, Any]) -> str:
    """The one-letter status of a cell of the analysis's `wind_envelope.json`."""
    if c["held"]:
        return "H"
    if c["completed"]:
        return "C"
    failure = c.get("failure") or ""
    if failure.startswith("lost"):
        return "L"
    if failure.startswith("did not land"):
        return "N"
    if failure.startswith("landed"):
        return "T"
    return "F"


def _round(x: Any) -> float | None:
    return round(x, 2) if isinstance(x, (int, float)) and math.isfinite(x) else None


def summarize(full: Mapping[str, Any], command: str = COMMAND, commit: str | None = None) -> dict[str, Any]:
    """The compact summary of the analysis's `wind_envelope.json` (`full`)."""
    rows: dict[tuple, list[Mapping[str, Any]]] = {}
    for c in full["cells"]:
        rows.setdefault(tuple(c.get(k, _DEFAULT_AXIS.get(k)) for k in _ROW_KEYS), []).append(c)
    out_rows = []
    for key, cells in rows.items():
        cells = sorted(cells, key=lambda c: c["bearing_deg"])
        done = [c["max_error"] for c in cells if c["completed"] and _round(c["max_error"]) is not None]
        row = dict(zip(_ROW_KEYS, key, strict=True))
        row.update(
            cells=len(cells),
            held=sum(bool(c["held"]) for c in cells),
            completed=sum(bool(c["completed"]) for c in cells),
            landing_passed=(sum(bool(c.get("landing_passed")) for c in cells) if key[4] == "takeoff_landing" else None),
            error_min=_round(min(done)) if done else None,
            error_max=_round(max(done)) if done else None,
            bearings_deg=[c["bearing_deg"] for c in cells],
            status="".join(status(c) for c in cells),
            errors=[_round(c["max_error"]) for c in cells],
        )
        out_rows.append(row)
    keep = ("speeds", "bearings_deg", "step_time", "held_max_error", "held_max_error_avionics", "turbulence_intensity")
    return {
        "command": command,
        "commit": commit,
        **{k: full[k] for k in keep if k in full},
        "axes": full.get("axes", {}),
        "run": {k: full.get(k) for k in ("wall_time_s", "cpu_time_s", "flown", "from_cache", "threads")},
        "status": STATUS,
        "rows": out_rows,
    }


def dumps(summary: Mapping[str, Any]) -> str:
    """The summary as JSON, one row per line (compact, and a re-run's diff reads row by row)."""
    head = {k: v for k, v in summary.items() if k != "rows"}
    text = json.dumps(head, indent=1, ensure_ascii=False)[:-2]
    rows = ",\n".join("  " + json.dumps(r, ensure_ascii=False) for r in summary["rows"])
    return f'{text},\n "rows": [\n{rows}\n ]\n}}\n'


def head_commit() -> str | None:
    """The checkout's commit (`+dirty` with uncommitted changes to the sources the flights
    depend on: crates, FMUs, declarations), or None outside git."""

    def git(*args: str) -> str:
        return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()

    try:
        rev = git("rev-parse", "--short", "HEAD")
        dirty = git("status", "--porcelain", "--", "crates", "fmu-*", "modelDescription", ":(exclude)*.md")
    except (OSError, subprocess.CalledProcessError):
        return None
    return rev + ("+dirty" if dirty else "")


# --- reading the summary ------------------------------------------------------------------------------------------


def _axis(r: Mapping[str, Any]) -> tuple[str, str, str]:
    return tuple(r[k] for k in _AXIS_KEYS)


def rows_of(w: Mapping[str, Any], controller: str, axis=MAIN_AXIS, mission=None, wind=None) -> list[Mapping]:
    return [
        r
        for r in w["rows"]
        if r["controller"] == controller
        and _axis(r) == tuple(axis)
        and (mission is None or r["mission"] == mission)
        and (wind is None or r["wind"] == wind)
    ]


def controllers(w: Mapping[str, Any], axis=MAIN_AXIS) -> list[str]:
    return list(dict.fromkeys(r["controller"] for r in w["rows"] if _axis(r) == tuple(axis)))


def _present(w: Mapping[str, Any], key: str, names: Mapping[str, str]) -> list[str]:
    seen = {r[key] for r in w["rows"]}
    return [k for k in names if k in seen] + sorted(seen - set(names))


def _m(x: float) -> str:
    return f"{x:.1f}"


def cell_text(r: Mapping[str, Any]) -> str:
    """`held/cells`, the completed cells' largest errors (m) and what the others did."""
    text = f"{r['held']}/{r['cells']}"
    if r["error_min"] is not None:
        lo, hi = _m(r["error_min"]), _m(r["error_max"])
        text += f", {lo} m" if lo == hi else f", {lo}–{hi} m"
    lost = {s: r["status"].count(s) for s in "LNTF" if s in r["status"]}
    if lost:
        text += ", " + " ".join(f"{n}{s}" for s, n in lost.items())
    return text


def reach(rows: Sequence[Mapping[str, Any]]) -> float | None:
    """The largest speed up to which every cell (every bearing, every lower speed, every row at
    that speed) is held; None if not even the calm one."""
    best = None
    for speed in sorted({r["speed"] for r in rows}):
        if any(r["held"] != r["cells"] for r in rows if r["speed"] == speed):
            break
        best = speed
    return best


def reach_text(rows: Sequence[Mapping[str, Any]]) -> str:
    """The highest speed held from every bearing (`none`: not even in calm air) and the cells
    held of those flown, e.g. `3 m/s (19/40)`."""
    s = reach(rows)
    held, n = sum(r["held"] for r in rows), sum(r["cells"] for r in rows)
    return f"{'none' if s is None else f'{s:g} m/s'} ({held}/{n})"


# --- the blocks ---------------------------------------------------------------------------------------------------


@block("wind.run", WIND)
def _run(src: Sources) -> str:
    w = src.json(WIND)
    run = w["run"]
    n = sum(r["cells"] for r in w["rows"])
    speeds = ", ".join(f"{s:g}" for s in w["speeds"])
    rate = f", {run['flown'] / run['cpu_time_s']:.1f} flights per CPU-second" if run.get("cpu_time_s") else ""
    return (
        f"{n} flights: wind speeds {speeds} m/s from {len(w['bearings_deg'])} bearings "
        f"({', '.join(f'{b:g}°' for b in w['bearings_deg'])}; clockwise from north, the mission's heading), "
        f"the step wind switching on at {w['step_time']:g} s, the turbulent wind present from t = 0 with Dryden "
        f"turbulence of intensity {w['turbulence_intensity']} (moderate). Held: completed and within "
        f"{w['held_max_error']:g} m of the controller's own reference and of the reference it flies in still "
        f"air, the mission's path (perfect state; {w['held_max_error_avionics']:g} m with avionics); the take-off "
        f"to landing also on its landing criteria where stated. Flown by `{w['command'].split(';')[0]}` "
        f"(commit {w['commit']}; {run['flown']} flights flown, {run['from_cache']} from the cache, "
        f"{run['wall_time_s']:.0f} s on {run['threads']} thread(s){rate})."
    )


def envelope_table(w: Mapping[str, Any], controller: str, axis=MAIN_AXIS) -> list[str]:
    """Mission × wind form rows, speed columns: held of the bearings, the completed cells'
    largest errors; the landings passed and the reach."""
    speeds = w["speeds"]
    md = [
        "| mission | wind | " + " | ".join(f"{s:g} m/s" for s in speeds) + " | landings passed | held |",
        "|---|---|" + "---|" * len(speeds) + "---|---|",
    ]
    for mission in _present(w, "mission", MISSIONS):
        for wind in _present(w, "wind", WINDS):
            rows = rows_of(w, controller, axis, mission, wind)
            if not rows:
                continue
            by_speed = {r["speed"]: r for r in rows}
            cells = [cell_text(by_speed[s]) if s in by_speed else "–" for s in speeds]
            landed = (
                f"{sum(r['landing_passed'] for r in rows)}/{sum(r['cells'] for r in rows)}"
                if mission == "takeoff_landing"
                else "–"
            )
            md.append(
                f"| {MISSIONS.get(mission, mission)} | {WINDS.get(wind, wind)} | "
                + " | ".join(cells)
                + f" | {landed} | {reach_text(rows)} |"
            )
    return md


def _legend(w: Mapping[str, Any]) -> str:
    codes = ", ".join(f"{s} {w['status'][s].split(':')[0]}" for s in "LNTF")
    return (
        "Each speed: cells held of the bearings, the smallest–largest of the completed cells' largest distance to "
        f"the reference, the cells not completed ({codes}). Held: the highest wind held from every bearing at it "
        "and every lower speed (none: not even in calm air), and the cells held of those flown."
    )


@block("wind.tables", WIND)
def _tables(src: Sources) -> str:
    w = src.json(WIND)
    md = []
    for k in controllers(w):
        md += [f"**{k}**, tuned, perfect state, Gauss-Seidel:", "", *envelope_table(w, k), ""]
    md.append(_legend(w))
    return "\n".join(md)


@block("wind.axes", WIND)
def _axes(src: Sources) -> str:
    """Cells held per controller and axis, each mission × wind form summed over the speeds."""
    w = src.json(WIND)
    cols = [
        (m, f)
        for m in _present(w, "mission", MISSIONS)
        for f in _present(w, "wind", WINDS)
        if any(r["mission"] == m and r["wind"] == f for r in w["rows"])
    ]
    md = [
        "| controller | configuration | state | ordering | "
        + " | ".join(f"{MISSIONS.get(m, m)}, {WINDS.get(f, f)}" for m, f in cols)
        + " |",
        "|---|---|---|---|" + "---|" * len(cols),
    ]
    axes = list(dict.fromkeys(_axis(r) for r in w["rows"]))
    for k in list(dict.fromkeys(r["controller"] for r in w["rows"])):
        for axis in axes:
            if not rows_of(w, k, axis):
                continue
            cells = []
            for m, f in cols:
                rows = rows_of(w, k, axis, m, f)
                cells.append(reach_text(rows) if rows else "–")
            c, s, o = axis
            md.append(f"| {k} | {c} | {STATES.get(s, s)} | {ORDERINGS.get(o, o)} | " + " | ".join(cells) + " |")
    return "\n".join(md)


def _controller_block(w: Mapping[str, Any], controller: str) -> str:
    md = [
        f"Generated from `docs/wind_envelope.json` ([`docs/WIND.md`](../../docs/WIND.md): how it is flown, "
        f"every axis): the tuned {controller}, perfect state, Gauss-Seidel, in steady wind from "
        f"{len(w['bearings_deg'])} bearings.",
        "",
        *envelope_table(w, controller),
        "",
        _legend(w),
        "",
        "Per state source and ordering, the highest wind held from every bearing (cells held):",
        "",
    ]
    for axis in dict.fromkeys(_axis(r) for r in w["rows"] if r["controller"] == controller):
        c, s, o = axis
        if c != "tuned":
            continue
        cells = [
            f"{MISSIONS.get(m, m)}, {WINDS.get(f, f)} {reach_text(rows)}"
            for m in _present(w, "mission", MISSIONS)
            for f in _present(w, "wind", WINDS)
            if (rows := rows_of(w, controller, axis, m, f))
        ]
        md.append(f"- {STATES.get(s, s)}, {ORDERINGS.get(o, o)}: " + "; ".join(cells))
    return "\n".join(md)


@block("wind.lqr", WIND)
def _lqr(src: Sources) -> str:
    return _controller_block(src.json(WIND), "LQR")


@block("wind.tsd", WIND)
def _tsd(src: Sources) -> str:
    return _controller_block(src.json(WIND), "TSD")


@block("wind.readme", WIND)
def _readme(src: Sources) -> str:
    """The README's wind sentence: per wind form and tuned controller (perfect state,
    Gauss-Seidel), the highest steady wind held from every bearing in the default mission /
    from take-off to landing."""
    w = src.json(WIND)

    def reach_of(k: str, mission: str, wind: str) -> str:
        rows = rows_of(w, k, MAIN_AXIS, mission, wind)
        s = reach(rows)
        return "–" if not rows else "none" if s is None else f"{s:g} m/s"

    forms = {"step": "the wind stepping in", "turbulent": "with moderate turbulence"}
    held = f"held = completed within {w['held_max_error']:g} m of its own reference and of its still-air path"
    parts = [f"{held} (perfect state, Gauss-Seidel)"]
    for wind in _present(w, "wind", WINDS):
        each = [f"{k} {reach_of(k, 'default', wind)} / {reach_of(k, 'takeoff_landing', wind)}" for k in controllers(w)]
        parts.append(f"{forms.get(wind, wind)}: " + ", ".join(each))
    return "; ".join(parts)
