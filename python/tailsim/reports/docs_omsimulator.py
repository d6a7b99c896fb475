"""The generated blocks of docs/OMSIMULATOR.md (registered into `tailsim.reports.docs.BLOCKS`).

Source: `docs/omsimulator_run.json`, written by `python scripts/omsimulator.py` (every SSP of
`dist/` flown in OMSimulator and compared with tailsim's fmpy Jacobi master; the script then
rewrites these blocks). Whether a system flies "the same" in both masters is decided by the
record's `same_flight_m` (the largest position distance of one flight).
"""

from __future__ import annotations

from typing import Any

from .. import declarations
from .docs import Sources, block

RUN = "omsimulator_run.json"
#: A position error above this (m) is called large (the table's note).
LARGE_ERROR_M = 5.0


def _runs(src: Sources) -> dict[str, dict[str, Any]]:
    return {r["ssp"].removesuffix(".ssp"): r for r in src.json(RUN)["runs"]}


def _same(src: Sources, run: dict[str, Any]) -> bool:
    return run["max_position_distance_m"] <= src.json(RUN)["same_flight_m"]


def _e(x: float) -> str:
    """Two significant digits, exponent without padding (`4.9e-7`)."""
    mantissa, exponent = f"{x:.1e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def _m(x: float) -> str:
    """A distance: two decimals from a centimetre up, else two significant digits."""
    return f"{x:.2f} m" if x >= 0.01 else f"{_e(x)} m"


#: How a declared unit is written in prose.
_UNIT_TEXT = {"m/s2": "m/s²", "rad/s2": "rad/s²"}


def _unit(name: str) -> str:
    for model in declarations.VARIABLES.values():
        if name in model and model[name].unit:
            return f", {_UNIT_TEXT.get(model[name].unit, model[name].unit)}"
    return ""


def _output(diff: list) -> str:
    name, x = diff
    return f"{_e(x)} ({name}{_unit(name)})"


def _n(x: float, nd: int) -> str:
    return f"{x:.{nd}f}".replace("-", "−")


@block("omsim.stop_time", RUN)
def _stop_time(src: Sources) -> str:
    stops = {r["stop_time"] for r in src.json(RUN)["runs"]}
    if len(stops) != 1:
        raise ValueError(f"{RUN}: the SSDs' stop times differ: {sorted(stops)}")
    return f"{stops.pop():g} s"


@block("omsim.run.intro", RUN)
def _intro(src: Sources) -> str:
    rec = src.json(RUN)
    runs = rec["runs"]
    ok = all(r.get("final_phase") == 4 and r["errors_logged"] == 0 and r["returncode"] == 0 for r in runs)
    end = (
        "every run ending in phase 4 with no error logged"
        if ok
        else "runs: " + ", ".join(f"{r['ssp']} phase {r.get('final_phase')}, {r['errors_logged']} errors" for r in runs)
    )
    return (
        f"OMSimulator `{rec['commit']}` on the SSPs of this repository (`{rec['command']}`, run {rec['date']}), "
        f"{_stop_time(src)} of the default mission each, {end}."
    )


#: The table's row order: the closed loops, then the avionics systems.
ORDER = ("lqr", "tsd", "px4")


@block("omsim.run.table", RUN)
def _table(src: Sources) -> str:
    runs = _runs(src)
    names = [f"tailsitter_{c}" for c in ORDER] + [f"tailsitter_{c}_avionics" for c in ORDER]
    rows = [
        "| SSP | max position error, OMSimulator | max position error, fmpy Jacobi | distance "
        "| plant outputs | controller outputs |",
        "|---|---|---|---|---|---|",
    ]
    for name in [n for n in names if n in runs] + sorted(set(runs) - set(names)):
        r = runs[name]
        same = _same(src, r)
        rows.append(
            f"| `{name}.ssp` | {r['max_pos_error_m']:.10f} m | {r['reference_max_pos_error_m']:.10f} m "
            f"| {_m(r['max_position_distance_m'])} "
            f"| {_output(r['largest_plant_output_difference']) if same else 'see below'} "
            f"| {_output(r['largest_controller_output_difference']) if same else 'see below'} |"
        )
    # a large error that both masters share is the controller's flight, not the importer's
    shared = [
        n
        for n, r in runs.items()
        if r["reference_max_pos_error_m"] > LARGE_ERROR_M
        and abs(r["max_pos_error_m"] - r["reference_max_pos_error_m"]) < 0.1 * r["reference_max_pos_error_m"]
    ]
    if shared:
        rows += [
            "",
            "(" + ", ".join(f"`{n}.ssp`" for n in sorted(shared)) + f": an error above {LARGE_ERROR_M:g} m that fmpy "
            "shares is the controller's own flight; this page is about the importer.)",
        ]
    return "\n".join(rows)


@block("omsim.recording", RUN)
def _recording(src: Sources) -> str:
    lqr = _runs(src)["tailsitter_lqr"]
    name, x = lqr["same_row_controller_output_difference"]
    return (
        f"Compared at the same point the LQR's commands seem to differ by up to {x:.0f}{_unit(name).replace(',', '')} "
        f"({name}), and a position error formed from one OMSimulator row (plant position and controller "
        f"reference of the same row) is {lqr['same_row_max_pos_error_m']:.2f} m instead of "
        f"{lqr['max_pos_error_m']:.2f} m: a recording offset, not a different flight."
    )


def _ctrl(name: str) -> str:
    return name.removeprefix("tailsitter_").removesuffix("_avionics").upper()


@block("omsim.initialisation", RUN)
def _initialisation(src: Sources) -> str:
    runs = _runs(src)
    avionics = {n: r for n, r in runs.items() if n.endswith("_avionics")}
    same = [n for n, r in avionics.items() if _same(src, r)]
    differ = [n for n, r in avionics.items() if not _same(src, r)]
    trim = {n: r["initial"]["plant.thrust"] for n, r in avionics.items() if "initial" in r}
    if not differ:
        return (
            "Both masters start the avionics systems on the same values and fly the same trajectories "
            "(table): at t = 0 the estimator's thrust equals the plant's, "
            + ", ".join(
                f"{_ctrl(n)} {_n(r['initial']['estimator.thrust'], 3)} N / {_n(r['initial']['plant.thrust'], 3)} N"
                for n, r in sorted(avionics.items())
                if "initial" in r
            )
            + "."
        )
    out = [
        "OMSimulator initialises every connection at once and solves the loop the avionics system has at "
        "initialisation (the controller's commands feed the estimator, whose actuator states the controller "
        "reads; the FMUs declare no dependencies); tailsim's master initialises the units one after the other "
        "(plant, sensors, estimator, controller), so the estimator starts on its command inputs' start values. "
        "OMSimulator's initial values at t = 0:"
    ]
    for n in sorted(differ):
        r = avionics[n]
        i = r["initial"]
        gap = i["plant.thrust"] - i["estimator.thrust"]
        text = (
            f"{_ctrl(n)}: thrust command {_n(i['controller.thrust_cmd'], 3)} N, estimator `thrust` "
            f"{_n(i['estimator.thrust'], 3)} N, plant `thrust` {_n(i['plant.thrust'], 3)} N "
            f"({_n(gap, 1)} N apart); it flies {_m(r['max_position_distance_m'])} away from the fmpy run"
        )
        if "started_on_initial_commands_distance_m" in r:
            text += (
                f", and {_m(r['started_on_initial_commands_distance_m'])} from the fmpy Jacobi master given "
                f"OMSimulator's initial commands as the estimator's start values (`ekf_params`)"
            )
        out.append(text + ".")
    if same:
        out.append(
            "The two initialisations coincide for "
            + ", ".join(f"{_ctrl(n)} ({_m(avionics[n]['max_position_distance_m'])})" for n in sorted(same))
            + (
                f": the loop settles on the plant's trim ({_n(next(iter(trim.values())), 3)} N)."
                if trim and len(set(round(v, 6) for v in trim.values())) == 1
                else "."
            )
        )
    lqr, lqr_av = runs.get("tailsitter_lqr"), avionics.get("tailsitter_lqr_avionics")
    if lqr and lqr_av and "tailsitter_lqr_avionics" in differ:
        out.append(
            f"So the LQR's {lqr['max_pos_error_m']:.2f} m (closed loop) against {lqr_av['max_pos_error_m']:.2f} m "
            f"(avionics system, fmpy Jacobi {lqr_av['reference_max_pos_error_m']:.2f} m) is this initialisation, "
            f"not the bindings: the SSD cannot set it."
        )
    return " ".join(out)


@block("omsim.schema", RUN)
def _schema(src: Sources) -> str:
    runs = src.json(RUN)["runs"]
    if not all(r.get("schema_validated") for r in runs):
        return "in the recorded run it could not load the schemas for " + ", ".join(
            f"`{r['ssp']}`" for r in runs if not r.get("schema_validated")
        )
    bad = [r for r in runs if r.get("schema_violations")]
    if not bad:
        return f"in the recorded run all {len(runs)} shipped SSDs pass without a message"
    return (
        "in the recorded run " + ", ".join(f"`{r['ssp']}` ({r['schema_violations']} messages)" for r in bad) + " do not"
    )
