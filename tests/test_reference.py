"""Regression data: the packaged FMUs under the fmpy master (Gauss-Seidel, the
reference ordering) reproduce the stored reference trajectories of the default
mission, tests/reference/tailsitter_{lqr,tsd}_default_ref.csv, to 1e-9
(relative to max(1, |value|)).

The files are written by the native closed loop
(`TAILSIM_REGEN_REFERENCE=1 cargo test -p closed-loop --test reference`, see
crates/closed-loop/tests/reference.rs), so this test also shows that the FMUs
and the pure-Rust loop fly the same trajectory. Run with -s for the deviations.
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import ROOT
from tailsim import ClosedLoop

TOLERANCE = 1e-9


def read_reference(controller: str) -> dict[str, np.ndarray]:
    path = ROOT / "tests" / "reference" / f"tailsitter_{controller}_default_ref.csv"
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    names = path.read_text().splitlines()[0].split(",")
    return {name: data[:, i] for i, name in enumerate(names)}


@pytest.mark.parametrize("controller", ["lqr", "tsd"])
def test_default_mission_matches_reference(fmus, controller):
    ref = read_reference(controller)
    # The stored trajectories are the thesis aerodynamics (the native loop's Plant::new);
    # the FMU defaults to the global model (aero_model = 1), identical only in attached flow.
    result = ClosedLoop(
        fmus["tailsitter_plant"],
        fmus[f"tailsitter_{controller}"],
        plant_params={"aero_model": 0},
        ordering="gauss-seidel",
    ).run()
    t = result.time
    # The stored rows are every k-th communication point.
    k = int(round((ref["time"][1] - ref["time"][0]) / (t[1] - t[0])))
    rows = slice(0, None, k)
    assert len(t[rows]) == len(ref["time"])
    worst = (0.0, "", 0.0)
    for name, want in ref.items():
        got = result[name][rows]
        err = np.abs(got - want) / np.maximum(1.0, np.abs(want))
        i = int(np.argmax(err))
        if err[i] > worst[0]:
            worst = (float(err[i]), name, float(ref["time"][i]))
    print(
        f"\n{controller}: worst relative deviation from the native loop {worst[0]:.1e} ({worst[1]} at t = {worst[2]})"
    )
    assert worst[0] <= TOLERANCE, f"{worst[1]} at t = {worst[2]} deviates by {worst[0]:.3e}"
