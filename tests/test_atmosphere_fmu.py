"""The atmosphere FMU `tailsitter_atmosphere` through fmpy (the conformance checks and the
every-variable test run over it with every FMU: test_conformance.py, test_variables.py):
its own behaviour through the real C ABI: quiet defaults, the steady-wind direction convention, Dryden variances,
plant ↔ atmosphere wired by name, FMU state continuing bit-identically, bad input and
parameters as FMI errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from fmpy import simulate_fmu

from fmu_util import LogRecorder, Unpacked, assert_refused, assert_state_continues_bit_identically, fmu_path

ID = "tailsitter_atmosphere"
H = 0.02
WIND = ["wind_n", "wind_e", "wind_d"]
INPUTS = ["pos_n", "pos_e", "pos_d", "airspeed"]
FOOT = 0.3048


@pytest.fixture(scope="module")
def atmosphere(tmp_path_factory) -> Unpacked:
    return Unpacked(ID, tmp_path_factory.mktemp("atmosphere"))


# ----------------------------------------------------------------- its own behaviour
def started(f: Unpacked, name: str, log: LogRecorder | None = None, ints: dict | None = None, **reals):
    s = f.initializing_slave(name, log)
    if reals:
        f.set(s, **reals)
    for n, x in (ints or {}).items():
        s.setInteger([f.vr[n]], [x])
    s.exitInitializationMode()
    return s


def run(f: Unpacked, s, steps: int, t0: float = 0.0) -> list:
    out = []
    for k in range(steps):
        s.doStep(t0 + k * H, H)
        out.append(f.get(s, *WIND))
    return out


def test_defaults_simulate_to_no_wind():
    result = simulate_fmu(str(fmu_path(ID)), fmi_type="CoSimulation", stop_time=5.0, output=WIND)
    assert len(result) > 200
    for n in WIND:
        assert np.all(result[n] == 0.0), n


def test_steady_wind_from_east_blows_west_at_the_set_speed(atmosphere):
    s = started(atmosphere, "east", wind_speed=8.0, wind_from=math.pi / 2, pos_d=-6.1)
    for k in range(10):
        wn, we, wd = atmosphere.get(s, *WIND)
        assert we == pytest.approx(-8.0, abs=1e-12) and abs(wn) < 1e-12 and wd == 0.0
        s.doStep(k * H, H)
    # Power law 1/7: at 4 × the reference height, 4^(1/7) times the speed.
    atmosphere.set(s, pos_d=-24.4)
    s.doStep(10 * H, H)
    (we,) = atmosphere.get(s, "wind_e")
    assert we == pytest.approx(-8.0 * 4 ** (1 / 7), rel=1e-12)
    s.terminate()
    s.freeInstance()


def test_dryden_variances_at_the_fmu_level(atmosphere):
    """2000 s at h = 10 m, V = 25 m/s, W20 = 15 m/s (100 000 steps of 20 ms), no mean wind
    (u north, v east, w down). Tolerance 4 standard deviations of the mean square,
    √(2∫ρ²/T_run): ±21 % (u, v; L = 67 m), ±6.3 % (w; L = 10 m)."""
    h, v, w20, run_time = 10.0, 25.0, 15.0, 2000.0
    s = started(atmosphere, "dryden", turbulence_w20=w20, pos_d=-h, airspeed=v)
    n = int(run_time / H)
    vrs = [atmosphere.vr[x] for x in WIND]
    samples = np.empty((n, 3))
    for k in range(n):
        s.doStep(k * H, H)
        samples[k] = s.getReal(vrs)
    h_ft = h / FOOT
    k_ = 0.177 + 0.000823 * h_ft
    sigma_w = 0.1 * w20
    sigma = np.array([sigma_w / k_**0.4, sigma_w / k_**0.4, sigma_w])
    length = np.array([h_ft / k_**1.2 * FOOT, h_ft / k_**1.2 * FOOT, h])
    integral = np.array([1.0, 0.625, 0.625]) * length / v
    tol = 4 * np.sqrt(2 * integral / run_time)
    ratio = (samples**2).mean(axis=0) / sigma**2
    print("FMU-level variance ratios", ratio, "tolerance", tol)
    assert np.all(np.abs(ratio - 1) < tol), (ratio, tol)
    s.terminate()
    s.freeInstance()


def test_plant_and_atmosphere_connect_by_name(plant, atmosphere):
    """Every input is a plant output and every output a plant input of the same name;
    a Gauss-Seidel loop (atmosphere, then plant) flies the plant's default climb into a
    light-turbulence, 5 m/s westerly wind without an error."""
    plant_out = {v.name for v in plant.md.modelVariables if v.causality == "output"}
    plant_in = {v.name for v in plant.md.modelVariables if v.causality == "input"}
    assert set(INPUTS) <= plant_out
    assert set(WIND) <= plant_in
    p = plant.slave("plant")
    log = LogRecorder()
    a = started(atmosphere, "wind", log, ints={"turbulence_intensity": 1}, wind_speed=5.0, wind_from=1.5 * math.pi)
    for k in range(100):
        t = k * H
        atmosphere.set(a, **dict(zip(INPUTS, plant.get(p, *INPUTS), strict=True)))
        a.doStep(t, H)
        plant.set(p, **dict(zip(WIND, atmosphere.get(a, *WIND), strict=True)))
        p.doStep(t, H)
    wn, we, wd = atmosphere.get(a, *WIND)
    assert 0 < we < 15 and abs(wn) < 10 and abs(wd) < 10, (wn, we, wd)
    assert not log.errors(), log.messages
    for x in (a, p):
        x.terminate()
        x.freeInstance()


def test_fmu_state_and_serialisation_continue_bit_identically(atmosphere):
    assert_state_continues_bit_identically(
        lambda name: started(atmosphere, name, ints={"turbulence_intensity": 2}, airspeed=12.0, pos_d=-20.0),
        lambda s: run(atmosphere, s, 23),
        lambda s: run(atmosphere, s, 80, 23 * H),
    )


def test_nan_and_out_of_range_parameters_are_errors_not_crashes(atmosphere):
    log = LogRecorder()
    s = atmosphere.initializing_slave("params", log)
    for name, value in (("wind_speed", math.nan), ("wind_speed", -1.0), ("turbulence_sample_time", 0.0)):
        log.clear()
        assert_refused(log, atmosphere.set, name, s, **{name: value})
    with pytest.raises(Exception):
        s.setInteger([atmosphere.vr["turbulence_intensity"]], [4])
    # Inside the declared ranges but inconsistent: the log law below its roughness length.
    s.setInteger([atmosphere.vr["wind_profile"]], [2])
    atmosphere.set(s, wind_roughness_length=0.5, wind_min_height=0.2)
    log.clear()
    assert_refused(log, lambda: s.exitInitializationMode(), "wind_min_height")
    s.freeInstance()


def test_nan_input_is_refused_and_outputs_stay_finite(atmosphere):
    log = LogRecorder()
    s = started(atmosphere, "nan", log, ints={"turbulence_intensity": 3}, wind_speed=3.0)
    run(atmosphere, s, 3)
    before = atmosphere.get(s, *WIND)
    assert_refused(log, lambda: atmosphere.set(s, airspeed=math.nan), "airspeed")
    s.doStep(3 * H, H)
    after = atmosphere.get(s, *WIND)
    assert all(math.isfinite(x) for x in after) and after != before
    s.freeInstance()


def test_reset_mid_run_repeats_the_run(atmosphere):
    s = started(atmosphere, "reset", ints={"turbulence_intensity": 1}, airspeed=20.0, pos_d=-15.0)
    first = run(atmosphere, s, 60)
    s.reset()  # every variable back to its start value
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.setInteger([atmosphere.vr["turbulence_intensity"]], [1])
    atmosphere.set(s, airspeed=20.0, pos_d=-15.0)
    s.exitInitializationMode()
    assert run(atmosphere, s, 60) == first
    s.terminate()
    s.freeInstance()
