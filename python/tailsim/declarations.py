"""The FMUs' declared interfaces (modelDescription/*.json), for the Python masters and reports.

The data is `declarations.json` beside this module, written by `cargo xtask regen`
(modelDescription/src/python.rs; a Rust test fails when the committed copy drifts):
every model's variables and default experiment, and from the controller interface the
commands and the plant's limits on them, the phases, the mission parameters and the
mission presets. This module only loads it into the names below.
"""

from __future__ import annotations

import json
from importlib import resources
from typing import NamedTuple


class Variable(NamedTuple):
    """One declared variable, as in modelDescription.xml."""

    name: str
    type: str
    causality: str
    variability: str
    unit: str | None
    start: float | int | bool | str | None
    min: float | None
    max: float | None
    description: str


class DefaultExperiment(NamedTuple):
    start_time: float
    stop_time: float
    step_size: float


# importlib.resources reads it from a folder or from a zip (the campaign ships the package
# to workers that lack it as a zip archive).
_DATA = json.loads(resources.files(__package__).joinpath("declarations.json").read_text(encoding="utf-8"))


def _floats(values: dict) -> dict[str, float]:
    return {k: float(v) for k, v in values.items()}


#: The model identifiers.
MODELS: tuple[str, ...] = tuple(_DATA["models"])

#: Default experiment of each model.
DEFAULT_EXPERIMENTS: dict[str, DefaultExperiment] = {
    k: DefaultExperiment(*(float(x) for x in m["default_experiment"])) for k, m in _DATA["models"].items()
}

#: The variables of each model by name, in declaration (value reference) order.
VARIABLES: dict[str, dict[str, Variable]] = {
    k: {v[0]: Variable(*v) for v in m["variables"]} for k, m in _DATA["models"].items()
}

#: The controllers' commands (outputs of the controller interface's `command` group), thrust first.
COMMANDS: tuple[str, ...] = tuple(_DATA["commands"])

#: The plant's thrust limits (N): its parameters `thrust_min`, `thrust_max`.
THRUST_LIMITS: tuple[float, float] = tuple(float(x) for x in _DATA["thrust_limits"])
#: The plant's deflection limit of every surface, +/- (rad): its parameter `deflection_limit`.
DEFLECTION_LIMIT: float = float(_DATA["deflection_limit"])

#: Names of the codes of the controllers' `phase` output.
PHASE_NAMES: dict[int, str] = {int(k): v for k, v in _DATA["phase_names"].items()}

#: The phases of the mission (codes 0, 1, ...), in order.
PHASES: tuple[str, ...] = tuple(_DATA["phases"])

#: The mission parameters of the phases' durations (s), in phase order.
PHASE_DURATIONS: tuple[str, ...] = tuple(_DATA["phase_durations"])

#: The mission parameters every controller declares (the controller interface's `mission` group).
MISSION: tuple[str, ...] = tuple(_DATA["mission"])
#: Their declared defaults.
MISSION_DEFAULTS: dict[str, float] = _floats(_DATA["mission_defaults"])
#: Their declared ranges (min, max).
MISSION_RANGES: dict[str, tuple[float | None, float | None]] = {
    k: tuple(None if x is None else float(x) for x in r) for k, r in _DATA["mission_ranges"].items()
}

#: Named missions: values over `MISSION_DEFAULTS`.
PRESETS: dict[str, dict[str, float]] = {k: _floats(v) for k, v in _DATA["presets"].items()}
#: What each preset is.
PRESET_DESCRIPTIONS: dict[str, str] = dict(_DATA["preset_descriptions"])

del _DATA


def mission(preset: str = "default", **values: float) -> dict[str, float]:
    """Every mission parameter: the declared defaults, the preset's values, then `values`."""
    unknown = [k for k in values if k not in MISSION_DEFAULTS]
    if unknown:
        raise KeyError(f"not mission parameters: {unknown}")
    return {**MISSION_DEFAULTS, **PRESETS[preset], **values}


def stop_time(params: dict[str, float]) -> float:
    """The end of the mission: the sum of its phases' durations (s)."""
    return float(sum(float(params[k]) for k in PHASE_DURATIONS))
