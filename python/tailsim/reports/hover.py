"""Hover in wind: the `envelope_hover` key of the analysis campaign's
`report.json` (`crates/analysis/src/envelope_hover.rs`) rendered as Markdown.

Steady wind steps of 5, 7 and 8 m/s from eight bearings and 1 − cos gusts along each
earth axis in each mission phase, both controllers (tuned configuration, weathervaning
heading reference on; the thesis configuration on the steps from the east), Gauss-Seidel
and Jacobi, global aerodynamics.
"""

from __future__ import annotations

from .. import declarations
from .markdown import shortest, table_head

PHASES = list(declarations.PHASES)
ORDERINGS = ["Gauss-Seidel", "Jacobi"]


def _controller_ordering_header(first: tuple[str, ...], controllers) -> list[str]:
    """Header and rule of a table with the `first` columns, then one per controller × ordering."""
    cols = list(first) + [f"{k} {o}" for k in controllers for o in ORDERINGS]
    return ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]


def _cell(r: dict | None, key: str = "max_pos_error") -> str:
    """`✓ 2.99 m` for a hold, `✗ 131 m` otherwise (the largest position error)."""
    if r is None:
        return "—"
    mark = "✓" if r["held"] else "✗"
    v = r[key]
    return f"{mark} {v:.3g} m"


def _gust_cell(r: dict | None) -> str:
    """`✓ +0.12 m` (position error the gust adds to the still-air flight's over its window)."""
    if r is None:
        return "—"
    mark = "✓" if r["held"] else "✗"
    calm = r.get("calm_max_pos_error")
    if calm is None:
        return f"{mark} {r['max_pos_error']:.3g} m"
    return f"{mark} {r['max_pos_error'] - calm:+.2f} m"


def section(d: dict) -> list[str]:
    """The hover-in-wind section (empty when the campaign did not fly it)."""
    h = d.get("envelope_hover")
    if not h:
        return []
    st, gu = h["step"], h["gust"]
    controllers = sorted({r["controller"] for r in st["rows"]}, key=["LQR", "TSD"].index)
    tuned = [r for r in st["rows"] if r["configuration"] == "tuned"]
    by = {(r["controller"], r["ordering"], r["speed"], r["from_deg"]): r for r in tuned}
    thesis = {(r["controller"], r["speed"]): r for r in st["rows"] if r["configuration"] == "thesis"}
    out = [
        "",
        "## Hover in wind",
        "",
        f"Global aerodynamics, the plant's ground 10 m below the start. Hover is the vertical phase at "
        f"{shortest(st['v_vertical'])} m/s climb (the LQR's model needs airspeed); the wind is a step at "
        f"{shortest(st['t_step_s'])} s, the run lasts {shortest(st['stop_s'])} s. ✓ = held: completed without "
        f"ground contact, position error below {shortest(h['hold_max_error_m'])} m throughout and below "
        f"{shortest(h['hold_final_error_m'])} m over the last 5 s; the cell gives the largest position error. "
        "Tuned configuration (weathervaning heading reference: the belly or back turns into the wind in "
        "vertical flight); the thesis configuration has no weathervane.",
        "",
        "### Steady wind from the east",
        "",
    ]
    out += table_head(
        ["wind step", *(c for k in controllers for c in (f"{k} tuned, GS", f"{k} tuned, Jacobi", f"{k} thesis, GS"))]
    )
    for v in st["speeds"]:
        line = f"| {shortest(v)} m/s from the east |"
        for k in controllers:
            line += (
                f" {_cell(by.get((k, 'Gauss-Seidel', v, 90.0)))} | {_cell(by.get((k, 'Jacobi', v, 90.0)))} |"
                f" {_cell(thesis.get((k, v)))} |"
            )
        out.append(line)
    out += [
        "",
        "### Steady wind from every direction",
        "",
        "Bearing the wind comes from (0° = north; at the start the belly faces north and the span east–west).",
        "",
    ]
    out += _controller_ordering_header(("speed", "from"), controllers)
    for v in st["speeds"]:
        for b in st["bearings_deg"]:
            line = f"| {shortest(v)} m/s | {shortest(b)}° |"
            for k in controllers:
                for o in ORDERINGS:
                    line += f" {_cell(by.get((k, o, v, b)))} |"
            out.append(line)
    held = {
        (k, o): [r for r in tuned if r["controller"] == k and r["ordering"] == o]
        for k in controllers
        for o in ORDERINGS
    }
    out += ["", "Held / flown, per speed:", ""]
    for (k, o), rows in held.items():
        per = ", ".join(
            f"{shortest(v)} m/s {sum(r['held'] for r in rows if r['speed'] == v)}/"
            f"{sum(1 for r in rows if r['speed'] == v)}"
            for v in st["speeds"]
        )
        out.append(f"- {k}, {o}: {per}")
    out += [
        "",
        "### 1 − cos gusts: axis × phase",
        "",
        f"{shortest(gu['amplitude'])} m/s peak over {shortest(gu['duration_s'])} s along one earth axis (+ = towards "
        "north/east/down), centred on the middle of each phase of the default mission. The cell gives the position "
        f"error the gust adds to the still-air flight's over the window from the gust to "
        f"{shortest(gu['window_after_s'])} s after it; ✓ = completed without ground contact and less than "
        f"{shortest(gu['added_error_m'])} m added.",
        "",
    ]
    gby = {(r["controller"], r["ordering"], r["phase"], r["axis"]): r for r in gu["rows"]}
    out += _controller_ordering_header(("phase", "axis"), controllers)
    for ph in range(5):
        for axis in ["N", "E", "D"]:
            line = f"| {PHASES[ph]} | {axis} |"
            for k in controllers:
                for o in ORDERINGS:
                    line += f" {_gust_cell(gby.get((k, o, ph, axis)))} |"
            out.append(line)
    return out
