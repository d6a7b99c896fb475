"""The Python masters: one engine (`system.System`, FMUs wired by name) and its
configurations (`ClosedLoop`: plant + controller; `AvionicsLoop`: plant, sensors,
estimator, controller), the FMU wrapper and run record, and the libcosim master
(`cosim`)."""

from .avionics import AvionicsLoop, fly_with_avionics
from .closed_loop import ClosedLoop
from .fmu import Fmu, RunResult, phase_slices, pos_error, settling_time
from .profiles import EDGE_TOLERANCE, TimeFunction, one_minus_cosine_gust, step, wind_from
from .system import External, Link, NonFinite, System, Unit, wire

__all__ = [
    "EDGE_TOLERANCE",
    "AvionicsLoop",
    "ClosedLoop",
    "External",
    "Fmu",
    "Link",
    "NonFinite",
    "RunResult",
    "System",
    "TimeFunction",
    "Unit",
    "fly_with_avionics",
    "one_minus_cosine_gust",
    "phase_slices",
    "pos_error",
    "settling_time",
    "step",
    "wind_from",
    "wire",
]
