"""The atmosphere FMU as a unit of the Python master (`ClosedLoop(..., atmosphere=...)`):
the plant flies the atmosphere's wind at its own height, turbulence is reproducible
with the seed, and the native closed loop (`closed_loop::Wind::Atmosphere`, through
`analysis wind-trace`) flies the same turbulent run."""

from __future__ import annotations

import math
import subprocess

import numpy as np
import pytest

from fmu_util import ROOT
from tailsim import ClosedLoop

ATMOSPHERE = "tailsitter_atmosphere"
WIND = ("wind_n", "wind_e", "wind_d")
STOP = 6.0
GROUND = 10.0  # the plant FMU's default ground: 10 m below the NED origin


def loop(fmus, controller="tailsitter_tsd", ordering="gauss-seidel", **params) -> ClosedLoop:
    return ClosedLoop(
        fmus["tailsitter_plant"],
        fmus[controller],
        ordering=ordering,
        atmosphere=fmus[ATMOSPHERE],
        atmosphere_params=params,
    )


def test_steady_wind_is_the_profile_at_the_plants_height(fmus):
    """5 m/s from the east (90°), power-law profile, no turbulence: at every point the
    plant's wind inputs are the profile at the plant's height; the same wind as a function
    of time gives the same flight, bit for bit (the plant flew the atmosphere's output)."""
    p = {"wind_speed": 5.0, "wind_from": math.pi / 2, "origin_height": GROUND}
    r = loop(fmus, **p).run(stop_time=STOP)
    h = GROUND - r["pos_d"]
    exponent = fmus[ATMOSPHERE].start("wind_profile_exponent")
    ref = fmus[ATMOSPHERE].start("wind_ref_height")
    speed = 5.0 * (np.clip(h, 0.1, 1e4) / ref) ** exponent
    assert np.allclose(r["wind_e"], -speed, rtol=1e-12, atol=0.0)
    assert np.max(np.abs(r["wind_n"])) < 1e-14 * 5.0 and not np.any(r["wind_d"])
    assert h[-1] > GROUND + 10.0  # the climb: the wind grew with height
    recorded = np.column_stack([r[w] for w in WIND])
    initialised = []

    def replay(t):
        # In initialisation the plant's wind inputs keep their start value 0 (the atmosphere
        # leaves initialisation after the plant); from t = 0 on, the recorded wind.
        if not initialised:
            initialised.append(True)
            return (0.0, 0.0, 0.0)
        return recorded[int(round(t / 0.02))]

    plain = ClosedLoop(fmus["tailsitter_plant"], fmus["tailsitter_tsd"]).run(stop_time=STOP, wind=replay)
    assert len(r.time) == len(plain.time)
    for name in ("pos_n", "pos_e", "pos_d", "airspeed", "thrust_cmd", *WIND):
        np.testing.assert_array_equal(plain[name], r[name], err_msg=name)


def test_calm_atmosphere_changes_nothing(fmus):
    """The atmosphere at its defaults (no wind) flies the loop without wind, bit for bit."""
    a = loop(fmus).run(stop_time=3.0)
    b = ClosedLoop(fmus["tailsitter_plant"], fmus["tailsitter_tsd"]).run(stop_time=3.0)
    for name in ("pos_n", "pos_d", "airspeed", "thrust_cmd", "elevator_cmd", *WIND):
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


@pytest.mark.parametrize("ordering", ["gauss-seidel", "jacobi"])
def test_turbulence_is_reproducible_with_the_seed(fmus, ordering):
    p = {"wind_speed": 5.0, "wind_from": math.pi / 2, "origin_height": GROUND, "turbulence_intensity": 2}
    a = loop(fmus, ordering=ordering, seed=7, **p).run(stop_time=3.0)
    b = loop(fmus, ordering=ordering, seed=7, **p).run(stop_time=3.0)
    c = loop(fmus, ordering=ordering, seed=8, **p).run(stop_time=3.0)
    for name in ("pos_n", "pos_e", "pos_d", "thrust_cmd", *WIND):
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)
    assert np.all(a["wind_n"][1:] != c["wind_n"][1:])
    # moderate turbulence at ~10 m: tenths of metres per second at least, not a rounding error
    assert 0.1 < np.ptp(a["wind_n"]) < 30.0


def test_jacobi_flies_the_previous_output(fmus):
    """Jacobi: the plant flies the atmosphere's output of the previous point. With a 1 − cos
    gust and no turbulence, the recorded (current) wind of Gauss-Seidel is the one Jacobi's
    plant flies one step later: replaying it delayed as a wind function gives Jacobi's flight."""
    p = {"gust_amplitude_e": 4.0, "gust_start": 1.0, "gust_duration": 1.0, "origin_height": GROUND}
    j = loop(fmus, ordering="jacobi", **p).run(stop_time=3.0)
    w = np.column_stack([j[n] for n in WIND])
    delayed = np.vstack([w[:1], w[:-1]])
    # the output after initialisation equals the output of the step at 0 (no sample is due)
    plain = ClosedLoop(fmus["tailsitter_plant"], fmus["tailsitter_tsd"], ordering="jacobi").run(
        stop_time=3.0, wind=lambda t: delayed[int(round(t / 0.02))]
    )
    for name in ("pos_n", "pos_e", "pos_d", "thrust_cmd"):
        np.testing.assert_array_equal(plain[name], j[name], err_msg=name)


@pytest.mark.parametrize("ordering", ["gauss-seidel", "jacobi"])
@pytest.mark.parametrize("controller", ["lqr", "tsd"])
def test_native_loop_flies_the_same_turbulent_run(fmus, tmp_path, ordering, controller):
    """Native (`closed_loop::fly` with `Wind::Atmosphere`, `analysis wind-trace`) against the
    FMU master: same seed, same ordering, 5 s of moderate turbulence in a 5 m/s wind."""
    from tailsim.campaign.native import analysis_binary

    speed, bearing, seed, intensity, stop = 5.0, 90.0, 3, 2, 5.0
    profile = "release" if (ROOT / "target" / "release" / "analysis").exists() else "debug"
    out = tmp_path / "native.csv"
    subprocess.run(
        [str(analysis_binary(profile)), "wind-trace", "--controller", controller, "--ordering", ordering]
        + ["--speed", str(speed), "--from-deg", str(bearing), "--seed", str(seed), "--intensity", str(intensity)]
        + ["--origin-height", str(GROUND), "--stop", str(stop), "--out", str(out)],
        check=True,
    )
    native = np.genfromtxt(out, delimiter=",", names=True)
    r = loop(
        fmus,
        controller=f"tailsitter_{controller}",
        ordering=ordering,
        wind_speed=speed,
        wind_from=math.radians(bearing),
        seed=seed,
        turbulence_intensity=intensity,
        origin_height=GROUND,
    ).run(stop_time=stop)
    assert len(native) == len(r.time)
    np.testing.assert_array_equal(native["time"], r.time)
    worst = {}
    for name in ("pos_n", "pos_e", "pos_d"):
        worst[name] = float(np.max(np.abs(native[name] - r[name])))
    # The native trace records what the plant flies from t; the FMU master records the
    # controller's and the atmosphere's outputs at t: under Jacobi the plant flies them one
    # point later.
    lag = 1 if ordering == "jacobi" else 0
    for name in ("thrust_cmd", "elevator_cmd", *WIND):
        worst[name] = float(np.max(np.abs(native[name][lag:] - r[name][: len(r.time) - lag])))
    print(f"\n{controller} {ordering}: largest |native − FMU master| {max(worst.values()):.1e}")
    assert max(worst.values()) < 1e-9, worst
    assert np.ptp(r["wind_n"]) > 0.1  # turbulent
