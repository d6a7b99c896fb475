"""The comparison plots say what flew (aerodynamic model, configuration) and show only the
control surfaces that move."""

from __future__ import annotations

import math

import numpy as np

from tailsim.masters import RunResult
from tailsim.metrics import SURFACES
from tailsim.reports import compare


def run_with(moving: dict[str, float]) -> RunResult:
    t = np.linspace(0.0, 1.0, 11)
    signals = {"time": t, **{s: np.zeros_like(t) for s in SURFACES}}
    for s, amplitude in moving.items():
        signals[s] = amplitude * np.sin(2 * math.pi * t)
    return RunResult(signals=signals, units={}, plant="p", controller="c", ordering="gauss-seidel")


def test_only_surfaces_that_move_are_plotted():
    runs = {"a": run_with({"elevator": 0.1}), "b": run_with({"flap_collective": -0.05, "rudder": 1e-6})}
    assert compare.active_surfaces(runs) == [s for s in SURFACES if s in ("elevator", "flap_collective")]
    assert compare.active_surfaces({"a": run_with({})}) == []


def test_setting_names_the_aerodynamics_and_each_configuration(fmus):
    plant = fmus["tailsitter_plant"]
    ctrls = {"lqr": fmus["tailsitter_lqr"], "tsd": fmus["tailsitter_tsd"]}
    text = compare.setting(plant, ctrls)
    declared = compare.AERO_MODELS[int(plant.start("aero_model"))]
    assert text.startswith(f"plant: {declared};")
    for k, c in ctrls.items():
        assert f"{k.upper()} {compare.CONFIGURATIONS[int(c.start('configuration'))]}" in text
