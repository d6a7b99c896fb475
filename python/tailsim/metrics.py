"""Numbers of the thesis's chapter-6 comparison, computed from a run."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .master import RunResult, pos_error, settling_time

PHASES = ["vertical 1", "transition 1", "level", "transition 2", "vertical 2"]
SURFACES = ["elevator", "aileron", "rudder", "flap_collective", "flap_differential", "vertical_flap"]


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


def mission_metrics(
    r: RunResult,
    level_end: float,
    theta_trim: float,
    v_level: float = 25.0,
    deflection_limit: float = math.radians(25.0),
    thrust_max: float = 150.0,
) -> MissionMetrics:
    t = r.time
    err = pos_error(r)
    phase = r["phase"]
    max_e, rms_e = [], []
    for k in range(5):
        m = phase == k
        max_e.append(float(err[m].max()) if m.any() else float("nan"))
        rms_e.append(float(math.sqrt(np.mean(err[m] ** 2))) if m.any() else float("nan"))
    alt_dev = []
    for k in (1, 3):
        m = phase == k
        alt_dev.append(float(np.abs(r["pos_d"][m] - r["ref_pos_d"][m]).max()) if m.any() else float("nan"))
    h = float(t[1] - t[0]) if len(t) > 1 else 0.0
    saturated = np.zeros(len(t), dtype=bool)
    for s in SURFACES:
        saturated |= np.abs(r[s]) >= deflection_limit * 0.999
    saturated |= (r["thrust_cmd"] >= thrust_max * 0.999) | (r["thrust_cmd"] <= 1e-9)
    window = (t >= level_end - 5.0) & (t < level_end)
    finite = all(np.all(np.isfinite(v)) for v in r.signals.values())
    level_v = float(np.abs(r["airspeed"][window] - v_level).max()) if window.any() else float("nan")
    level_theta = float(np.degrees(np.abs(r["theta"][window] - theta_trim)).max()) if window.any() else float("nan")
    final_theta = float(abs(math.degrees(r["theta"][-1]) - 90.0))
    reasons = []
    if not finite:
        reasons.append("non-finite values")
    if not level_v <= 1.0:
        reasons.append(f"level airspeed error {level_v:.2f} m/s > 1")
    if not level_theta <= 5.0:
        reasons.append(f"level pitch error {level_theta:.1f} deg > 5")
    if not final_theta <= 10.0:
        reasons.append(f"final pitch {final_theta:.1f} deg from vertical > 10")
    return MissionMetrics(
        completed=not reasons,
        reason="; ".join(reasons) or "ok",
        max_error=max_e,
        rms_error=rms_e,
        altitude_deviation_transition=(alt_dev[0], alt_dev[1]),
        max_alpha_deg=float(np.degrees(np.nanmax(r["alpha"]))),
        saturation_time=float(saturated.sum() * h),
        level_airspeed_error=level_v,
        level_pitch_error_deg=level_theta,
        final_pitch_error_deg=final_theta,
        controller_us_per_step=1e6 * r.wall_time_controller / max(r.steps, 1),
    )


def step_settling(r: RunResult, t_step: float, band: float = 0.5) -> float:
    return settling_time(r.time, pos_error(r), t_step + 1e-9, band)
