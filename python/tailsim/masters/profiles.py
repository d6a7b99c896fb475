"""Time functions driving the external inputs of a system (wind, reference offset)."""

from __future__ import annotations

import math
from collections.abc import Callable

Vector3 = tuple[float, float, float]
TimeFunction = Callable[[float], Vector3]


def zero(_t: float) -> Vector3:
    """The zero profile."""
    return (0.0, 0.0, 0.0)


# Time edges (s): a communication point t has reached an edge t_edge when
# t >= t_edge - EDGE_TOLERANCE, so that t = k*h computed in floating point meets
# an edge at a multiple of h. The same definition as the Rust closed loop
# (`closed_loop::EDGE_TOLERANCE`: `Wind::Step`, `Scenario::ref_offset`,
# `Trace::window`); the value is `edge_tolerance` of
# modelDescription/fragments/mission_criteria.json (tailsim.metrics checks).
EDGE_TOLERANCE = 1e-9


def step(t_step: float, value: Vector3) -> TimeFunction:
    """A profile that is zero before `t_step` and `value` from then on (from the
    first t with t >= t_step - EDGE_TOLERANCE, as `closed_loop::Wind::Step`)."""

    def f(t: float) -> Vector3:
        return value if t >= t_step - EDGE_TOLERANCE else (0.0, 0.0, 0.0)

    return f


def wind_from(from_bearing: float, speed: float) -> Vector3:
    """Air-mass velocity (NED, m/s) of a horizontal wind of `speed` blowing *from* the
    bearing `from_bearing` (rad, 0 = from the north, π/2 = from the east):
    −speed (cos b, sin b, 0), as `closed_loop::wind_from`. A steady wind switched on at
    t is `step(t, wind_from(b, speed))` (`closed_loop::Wind::step_from`)."""
    return (-speed * math.cos(from_bearing), -speed * math.sin(from_bearing), 0.0)


def one_minus_cosine_gust(t_start: float, duration: float, amplitude: Vector3) -> TimeFunction:
    """The 1 − cos gust: amplitude · (1 − cos(2π(t − t_start)/duration))/2 for
    0 ≤ (t − t_start)/duration ≤ 1, zero outside (as `closed_loop::Wind::OneMinusCosine`)."""

    def f(t: float) -> Vector3:
        s = (t - t_start) / duration
        if 0.0 <= s <= 1.0:
            k = 0.5 * (1.0 - math.cos(2.0 * math.pi * s))
            return (amplitude[0] * k, amplitude[1] * k, amplitude[2] * k)
        return (0.0, 0.0, 0.0)

    return f
