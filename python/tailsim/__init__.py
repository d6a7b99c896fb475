"""tailsim: fly the tail-sitter FMUs from Python.

`tailsim.masters` holds the co-simulation engine (a system of FMUs wired by port
name, docs/DESIGN.md "Ports and timing") and its configurations: `ClosedLoop`
(plant + controller: every controller input gets the plant output of the same name,
every controller output goes to the plant input of the same name) and
`AvionicsLoop` (plant, sensors, estimator, controller). `tailsim.campaign` is the
Monte-Carlo campaign, `tailsim.reports` the reports, `tailsim.metrics` the
measures of a run, `tailsim.declarations` the FMUs' declared interfaces (generated data).
"""

from .masters import ClosedLoop, Fmu, RunResult, one_minus_cosine_gust, step

__all__ = ["ClosedLoop", "Fmu", "RunResult", "one_minus_cosine_gust", "step"]
