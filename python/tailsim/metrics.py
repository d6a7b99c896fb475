"""Numbers of the thesis's chapter-6 comparison, computed from a run.

The mission criteria (1 m/s, 5°, 10°, the 5 s level window, …) are read from
`modelDescription/fragments/mission_criteria.json`, the file the Rust closed
loop (`closed_loop::Criteria`) compiles in: one source for both languages.
`mission_check` mirrors `closed_loop::MissionCheck::of` line by line (same
window edges, same tolerances); `tests/test_metrics_agree.py` checks both give
the same numbers on a stored trajectory.
"""

from __future__ import annotations

import json
import math
import pathlib
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from . import declarations
from .masters.fmu import RunResult, pos_error, settling_time
from .masters.profiles import EDGE_TOLERANCE

PHASES = list(declarations.PHASES)
#: The control surfaces: the plant outputs of the deflections commanded by COMMANDS[1:].
SURFACES = [c.removesuffix("_cmd") for c in declarations.COMMANDS[1:]]
CRITERIA_FILE = pathlib.Path(__file__).resolve().parents[2] / "modelDescription" / "fragments" / "mission_criteria.json"


def _load_criteria() -> dict[str, float]:
    data = json.loads(CRITERIA_FILE.read_text())
    return {k: float(v["value"]) for k, v in data.items() if isinstance(v, dict)}


CRITERIA: dict[str, float] = _load_criteria()
assert CRITERIA["edge_tolerance"] == EDGE_TOLERANCE, "master.EDGE_TOLERANCE must match mission_criteria.json"


@dataclass
class MissionCheck:
    """The issues' acceptance criteria on a run (mirror of `closed_loop::MissionCheck`)."""

    level_airspeed_error: float
    """Max |airspeed − v_level| over the level window (m/s)."""
    level_pitch_error: float
    """Max |θ − θ_trim| over the level window (rad)."""
    final_pitch_error: float
    """|θ − 90°| at the end (rad)."""
    all_finite: bool
    phase_samples: list[int]
    phase_max: list[float]
    """Max position error per phase (m), 0 for a phase without samples."""
    phase_rms: list[float]

    def failures(self) -> list[str]:
        c = CRITERIA
        out = []
        if not self.all_finite:
            out.append("non-finite values")
        if not self.level_airspeed_error <= c["level_airspeed_error_max"]:
            out.append(f"level airspeed error {self.level_airspeed_error:.2f} m/s > {c['level_airspeed_error_max']:g}")
        if not self.level_pitch_error <= math.radians(c["level_pitch_error_max"]):
            out.append(
                f"level pitch error {math.degrees(self.level_pitch_error):.1f} deg > {c['level_pitch_error_max']:g}"
            )
        if not self.final_pitch_error <= math.radians(c["final_pitch_error_max"]):
            out.append(
                f"final pitch {math.degrees(self.final_pitch_error):.1f} deg from vertical > "
                f"{c['final_pitch_error_max']:g}"
            )
        return out

    def passed(self) -> bool:
        return not self.failures()


def phase_starts(mission: Mapping[str, float]) -> list[float]:
    """Start times (s) of the five phases and the end of the mission."""
    out = [0.0]
    for key in declarations.PHASE_DURATIONS:
        out.append(out[-1] + float(mission[key]))
    return out


def window(t: np.ndarray, t0: float, t1: float) -> np.ndarray:
    """Samples with t0 ≤ t < t1, edges with the shared tolerance (`Trace::window`)."""
    return (t >= t0 - EDGE_TOLERANCE) & (t < t1 - EDGE_TOLERANCE)


def level_window(t: np.ndarray, mission: Mapping[str, float]) -> np.ndarray:
    """Samples of the criteria's level window: the last `level_window` seconds of
    level flight (from the later of its start and its end minus that)."""
    s = phase_starts(mission)
    return window(t, max(s[3] - CRITERIA["level_window"], s[2]), s[3])


def declared_mission() -> dict[str, float]:
    """The mission parameters' defaults as the controllers declare them
    (modelDescription/fragments/controller_interface.json, group "mission"); from
    a packaged FMU read the same start values with `Fmu.starts`."""
    return {k: float(v) for k, v in declarations.MISSION_DEFAULTS.items()}


def mission_check(r: RunResult, mission: Mapping[str, float], theta_level_trim: float) -> MissionCheck:
    """`closed_loop::MissionCheck::of` on a recorded run; `mission` holds the
    controller's mission parameters (t_*, v_level)."""
    w = level_window(r.time, mission)
    level_v = float(np.max(np.abs(r["airspeed"][w] - float(mission["v_level"])), initial=0.0))
    level_theta = float(np.max(np.abs(r["theta"][w] - theta_level_trim), initial=0.0))
    final_theta = abs(float(r["theta"][-1]) - math.pi / 2) if len(r.time) else math.inf
    err = pos_error(r)
    phase = r["phase"]
    samples, mx, rms = [], [], []
    for k in range(5):
        m = phase == k
        samples.append(int(m.sum()))
        mx.append(float(np.max(err[m], initial=0.0)))
        rms.append(float(math.sqrt(np.sum(err[m] ** 2) / m.sum())) if m.any() else 0.0)
    return MissionCheck(
        level_airspeed_error=level_v,
        level_pitch_error=level_theta,
        final_pitch_error=final_theta,
        all_finite=all(bool(np.all(np.isfinite(v))) for v in r.signals.values()),
        phase_samples=samples,
        phase_max=mx,
        phase_rms=rms,
    )


@dataclass
class MissionMetrics:
    completed: bool
    reason: str
    max_error: list[float]
    rms_error: list[float]
    altitude_deviation_transition: tuple[float, float]
    max_alpha_deg: float
    saturation_time: float
    level_airspeed_error: float
    level_pitch_error_deg: float
    final_pitch_error_deg: float
    controller_us_per_step: float
    flown_transition: tuple[float, float]
    """Flown durations of the two transitions (s, `flown_transitions`): what was flown, not what was asked."""


def mission_metrics(
    r: RunResult,
    mission: Mapping[str, float],
    theta_trim: float,
    deflection_limit: float,
    thrust_max: float,
) -> MissionMetrics:
    """The comparison's numbers of a mission run: the criteria of `mission_check`
    plus altitude deviation, α, saturation and compute time. `mission`: the
    controller's mission parameters; `deflection_limit` (rad) and `thrust_max`
    (N): the plant's (read them from its declaration, `Fmu.start`)."""
    check = mission_check(r, mission, theta_trim)
    t = r.time
    phase = r["phase"]
    alt_dev = []
    for k in (1, 3):
        m = phase == k
        alt_dev.append(float(np.abs(r["pos_d"][m] - r["ref_pos_d"][m]).max()) if m.any() else float("nan"))
    h = float(t[1] - t[0]) if len(t) > 1 else 0.0
    saturated = np.zeros(len(t), dtype=bool)
    for s in SURFACES:
        saturated |= np.abs(r[s]) >= deflection_limit * 0.999
    saturated |= (r["thrust_cmd"] >= thrust_max * 0.999) | (r["thrust_cmd"] <= 1e-9)
    nan = float("nan")
    reasons = check.failures()
    return MissionMetrics(
        completed=not reasons,
        reason="; ".join(reasons) or "ok",
        max_error=[m if n else nan for m, n in zip(check.phase_max, check.phase_samples, strict=False)],
        rms_error=[m if n else nan for m, n in zip(check.phase_rms, check.phase_samples, strict=False)],
        altitude_deviation_transition=(alt_dev[0], alt_dev[1]),
        max_alpha_deg=float(np.degrees(np.nanmax(r["alpha"]))),
        saturation_time=float(saturated.sum() * h),
        level_airspeed_error=check.level_airspeed_error,
        level_pitch_error_deg=math.degrees(check.level_pitch_error),
        final_pitch_error_deg=math.degrees(check.final_pitch_error),
        controller_us_per_step=1e6 * r.wall_time_controller / max(r.steps, 1),
        flown_transition=flown_transitions(r, mission),
    )


#: Tolerance of the flown flight-path angle around its target (rad): 5°, the rotation tolerance of the
#: analysis's transition envelope (`crates/analysis/src/envelope_transitions.rs`, `ROTATION_TOLERANCE`).
ROTATION_TOLERANCE = math.radians(5.0)


def flight_path_angle(r: RunResult) -> np.ndarray:
    """Flown flight-path angle γ = atan2(−v_d, |v_ne|) (rad): 0 in level flight, π/2 climbing vertically."""
    return np.arctan2(-r["vel_d"], np.hypot(r["vel_n"], r["vel_e"]))


def held_from(t: np.ndarray, ok: np.ndarray, t0: float, t1: float) -> float:
    """Time (s, from `t0`) after which `ok` holds on every sample of [t0, t1); NaN if it
    does not hold at the last sample (or there are none)."""
    w = window(t, t0, t1)
    tw, okw = t[w], ok[w]
    if not okw.size or not okw[-1]:
        return float("nan")
    bad = np.nonzero(~okw)[0]
    return float(tw[bad[-1] + 1] - t0) if bad.size else float(tw[0] - t0)


def flown_transitions(r: RunResult, mission: Mapping[str, float]) -> tuple[float, float]:
    """The transitions as flown (s): from the start of each transition until the flown
    flight-path angle γ is within `ROTATION_TOLERANCE` of its target (0 after the first,
    90° after the second) and stays there to the end of the following phase (level flight,
    the last vertical climb). NaN where it never settles. The requested T1, T2 shape the
    reference; the airframe and the reference generator's limits decide what is flown."""
    s, t, gamma = phase_starts(mission), r.time, flight_path_angle(r)
    first = held_from(t, np.abs(gamma) <= ROTATION_TOLERANCE, s[1], s[3])
    second = held_from(t, np.abs(gamma - math.pi / 2) <= ROTATION_TOLERANCE, s[3], s[5])
    return (first, second)


def step_settling(r: RunResult, t_step: float, band: float | None = None) -> float:
    """Settling time (s) of the position error into `band` (m; default: the
    criteria's settling band), counted over the samples strictly after the
    reference step at `t_step` (the step's own sample is left out)."""
    band = CRITERIA["settling_band"] if band is None else band
    return settling_time(r.time, pos_error(r), t_step + EDGE_TOLERANCE, band)
