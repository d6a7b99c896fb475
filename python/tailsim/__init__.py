"""tailsim: fly the tail-sitter FMUs from Python.

`ClosedLoop` is a small co-simulation master (fmpy underneath) that wires a
plant FMU and any controller FMU by port name (docs/DESIGN.md, "Ports and
timing"): every controller input gets the plant output of the same name,
every controller output goes to the plant input of the same name.
"""

from .master import ClosedLoop, Fmu, RunResult, one_minus_cosine_gust, step

__all__ = ["ClosedLoop", "Fmu", "RunResult", "one_minus_cosine_gust", "step"]
