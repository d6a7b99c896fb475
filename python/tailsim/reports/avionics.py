"""The comparison report's avionics section: the controllers on the estimate of
`tailsitter_ekf` (`tailsim.masters.AvionicsLoop`) beside their runs on the perfect state."""

from __future__ import annotations

import math
import pathlib
from collections.abc import Mapping

import numpy as np

from .. import declarations
from ..masters import Fmu, RunResult, pos_error
from ..masters.avionics import PHASES, fly_with_avionics, phase_errors
from ..metrics import mission_check


def avionics_section(
    dist,
    keys: list[str],
    missions: Mapping[str, Mapping[str, float]],
    perfect: Mapping[tuple[str, str], RunResult],
    theta_trim: float,
    ordering: str = "gauss-seidel",
    out=None,
) -> list[str]:
    """Markdown section of the comparison report (`tailsim.reports.compare`): each controller
    (`keys`: "lqr", "tsd") flies each mission (name → controller parameters) with
    avionics in the loop; its max true position error per phase beside the run on the
    perfect state (`perfect[(mission, key)]`), and the estimation errors per phase.
    CSVs of the avionics runs go to `out`/csv when `out` is given."""
    dist = pathlib.Path(dist)
    ids = ["tailsitter_plant", "tailsitter_sensors", "tailsitter_ekf"] + [f"tailsitter_{k}" for k in keys]
    fmus = {i: Fmu(dist / f"{i}.fmu") for i in ids}
    md = [
        "",
        "## Avionics in the loop",
        "",
        f"The controllers fly on the estimates of `tailsitter_ekf`, fed by `tailsitter_sensors` "
        f"(thesis Table D.1 noise, 8 Hz Butterworth on the analogue channels, GPS 4 Hz), {ordering} "
        "(tailsim.masters.avionics). Position error: the TRUE position against the reference; it includes "
        "the estimation error of the displacement since the start (the estimator navigates "
        "relative to the start, its estimate of the start refined by every GPS fix).",
    ]
    try:
        for m, params in missions.items():
            runs: dict[str, RunResult | str] = {}
            for k in keys:
                try:
                    r = fly_with_avionics(
                        fmus,
                        f"tailsitter_{k}",
                        ordering=ordering,
                        controller_params=dict(params),
                        stop_time=declarations.stop_time(dict(params)),
                    )
                    runs[k] = r
                    if out is not None:
                        r.write_csv(pathlib.Path(out) / "csv" / f"{k}_{m}_mission_avionics.csv")
                except Exception as e:  # noqa: BLE001 - a failed run is a result
                    runs[k] = f"failed: {e}"[:80]
            header = ["quantity"] + [f"{k.upper()} {w}" for k in keys for w in ("perfect state", "avionics")]
            md += [
                "",
                f"### {m} mission: perfect state vs avionics",
                "",
                "| " + " | ".join(header) + " |",
                "|" + "---|" * len(header),
            ]

            def cell(run, f):
                if isinstance(run, str):
                    return run
                if run is None:
                    return "–"
                return f(run)

            def completed(r, params=params):
                mc = mission_check(r, {**params}, theta_trim)
                return "yes" if mc.passed() else "no: " + "; ".join(mc.failures())[:60]

            rows = [("mission criteria met", completed)]
            for i, ph in enumerate(PHASES):
                rows.append(
                    (
                        f"max position error, {ph} (m)",
                        lambda r, i=i: f"{float(np.max(pos_error(r)[r['phase'] == i], initial=0.0)):.2f}",
                    )
                )
            for label, f in rows:
                vals = []
                for k in keys:
                    vals += [cell(perfect.get((m, k)), f), cell(runs[k], f)]
                md.append(f"| {label} | " + " | ".join(vals) + " |")
            for k in keys:
                r = runs[k]
                if isinstance(r, str):
                    continue
                md += [
                    "",
                    f"Estimation errors, {k.upper()} {m} mission (RMS per phase; α, β weakly observable "
                    "in vertical flight):",
                    "",
                    "| phase | position (m) | velocity (m/s) | attitude (deg) | airspeed (m/s) | α (deg) | β (deg) |",
                    "|---|---|---|---|---|---|---|",
                ]
                for pe in phase_errors(r):
                    q = pe.rms
                    md.append(
                        f"| {pe.phase} | {q['err_pos']:.2f} | {q['err_vel']:.2f} | {math.degrees(q['err_att']):.2f} | "
                        f"{q['err_airspeed']:.2f} | {math.degrees(q['err_alpha']):.2f} | "
                        f"{math.degrees(q['err_beta']):.2f} |"
                    )
    finally:
        for f in fmus.values():
            f.cleanup()
    return md


__all__ = ["avionics_section"]
