"""The sensor FMU `tailsitter_sensors`  through fmpy (the conformance
checks and the every-variable test run over it with every FMU: test_conformance.py,
test_variables.py): its own behaviour through the real C ABI: plant → sensors wired by name,
reset mid-run, FMU state (get/set and serialised) continuing bit-identically,
bad input and parameters as FMI errors with finite outputs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fmu_util import LogRecorder, Unpacked, assert_refused, assert_state_continues_bit_identically
from tailsim import declarations

ID = "tailsitter_sensors"
H = 0.02
_DECLARED = declarations.VARIABLES[ID]
_REAL_OUTPUTS = [n for n, v in _DECLARED.items() if v.causality == "output" and v.type == "Real"]
#: The analogue channels (IMU, magnetometer, pitot) and the GPS's Real outputs, as declared.
ANALOG = [n for n in _REAL_OUTPUTS if not n.startswith("gps_")]
GPS = [n for n in _REAL_OUTPUTS if n.startswith("gps_")]
#: The true state (plant outputs of the same names): every input.
TRUTH = [n for n, v in _DECLARED.items() if v.causality == "input"]


@pytest.fixture(scope="module")
def sensors(tmp_path_factory) -> Unpacked:
    return Unpacked(ID, tmp_path_factory.mktemp("sensors"))


# ----------------------------------------------------------------- its own behaviour
def outputs(f: Unpacked, s) -> list:
    return f.get(s, *ANALOG, *GPS) + s.getInteger([f.vr["gps_fix_count"]]) + s.getBoolean([f.vr["gps_valid"]])


def test_plant_to_sensors_by_name(plant, sensors):
    """The plant's default vertical climb through the sensors: every input is a plant
    output of the same name, and each measurement is its truth within 5 delivered σ (Table D.1)."""
    p = plant.slave("plant")
    log = LogRecorder()
    s = sensors.initializing_slave("sensors", log)
    sensors.set(s, **dict(zip(TRUTH, plant.get(p, *TRUTH), strict=False)))
    s.exitInitializationMode()
    accel_std, gps_h_std = sensors.get(s, "accel_std", "gps_height_std")
    fixes = []
    for k in range(250):
        t = k * H
        truth = dict(zip(TRUTH, plant.get(p, *TRUTH), strict=False))
        sensors.set(s, **truth)
        s.doStep(t, H)
        p.doStep(t, H)
        (count,) = s.getInteger([sensors.vr["gps_fix_count"]])
        ax, ay, az, height, vd = sensors.get(s, "imu_accel_x", "imu_accel_y", "imu_accel_z", "gps_height", "gps_vel_d")
        # The climb is steady: the specific force is constant, so the filter lag does not matter.
        for meas, true in ((ax, truth["accel_x"]), (ay, truth["accel_y"]), (az, truth["accel_z"])):
            assert abs(meas - true) < 5 * accel_std + 0.05, (t, meas, true)
        if not fixes or count != fixes[-1][0]:
            fixes.append((count, height + truth["pos_d"], vd - truth["vel_d"]))
    # 5 s at 4 Hz: fixes at 0, 0.25, …, 4.75 s → 20, the first at initialisation.
    assert [c for c, _, _ in fixes] == list(range(1, 21))
    errs = np.array([e for _, e, _ in fixes])
    assert np.all(np.abs(errs) < 5 * gps_h_std), errs
    # GPS vertical-speed errors: zero mean within 3σ/√n (σ 0.5 m/s, Table D.1).
    vel_errs = np.array([e for _, _, e in fixes])
    assert abs(vel_errs.mean()) < 3 * 0.5 / math.sqrt(len(vel_errs)), vel_errs
    assert not log.errors(), log.messages
    s.terminate()
    s.freeInstance()
    p.terminate()
    p.freeInstance()


def run(f: Unpacked, s, steps: int, t0: float = 0.0) -> list:
    out = []
    for k in range(steps):
        s.doStep(t0 + k * H, H)
        out.append(outputs(f, s))
    return out


def test_reset_mid_run_repeats_the_run(sensors):
    s = sensors.slave("reset")
    sensors.set(s, airspeed=20.0, p=0.1)
    first = run(sensors, s, 60)
    s.reset()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    sensors.set(s, airspeed=20.0, p=0.1)
    assert run(sensors, s, 60) == first
    s.terminate()
    s.freeInstance()


def test_fmu_state_and_serialisation_continue_bit_identically(sensors):
    def lead_in(s):
        sensors.set(s, airspeed=15.0, q=-0.05)
        run(sensors, s, 23)

    assert_state_continues_bit_identically(sensors.slave, lead_in, lambda s: run(sensors, s, 80, 23 * H))


def test_bad_input_is_an_fmi_error_naming_the_input(sensors):
    log = LogRecorder()
    s = sensors.slave("nan", log)
    run(sensors, s, 3)
    before = outputs(sensors, s)
    # A NaN is refused by fmi2SetReal already (the input keeps its value).
    assert_refused(log, lambda: sensors.set(s, alpha=math.nan), "alpha")
    s.doStep(3 * H, H)
    # A finite but impossible truth (zero quaternion) fails the step; outputs stay as they were.
    before = outputs(sensors, s)
    sensors.set(s, quat_4=0.0)
    log.clear()
    assert_refused(log, lambda: s.doStep(4 * H, H), "quaternion")
    after = outputs(sensors, s)
    assert after == before and all(math.isfinite(x) for x in after[:16])
    s.freeInstance()


def test_all_zero_inputs_before_the_first_plant_sample_are_held_with_a_warning(sensors):
    """A master that starts its connections at 0.0 (fmpy's simulate_ssp) hands the sensors
    an all-zero true state (a zero quaternion) in the first step: before any plant sample
    that is "no plant sample yet" (outputs of the start held, a warning naming the cause),
    after one it is the invalid state it is (an error)."""
    log = LogRecorder()
    s = sensors.slave("zeros", log)
    s.setDebugLogging(True, [])  # warnings are logged when logging is on
    start = outputs(sensors, s)
    sensors.set(s, **{n: 0.0 for n in TRUTH})
    s.doStep(0.0, H)
    assert outputs(sensors, s) == start
    warnings = [m for st, _, m in log.messages if st == "Warning"]
    assert any("no plant sample yet" in m for m in warnings), log.messages
    assert not log.errors()
    # A real sample, then zeros again: refused.
    sensors.set(s, quat_1=0.0, quat_2=math.sqrt(0.5), quat_3=0.0, quat_4=math.sqrt(0.5), airspeed=3.0, accel_x=9.81)
    s.doStep(H, H)
    sensors.set(s, **{n: 0.0 for n in TRUTH})
    log.clear()
    assert_refused(log, lambda: s.doStep(2 * H, H), "quaternion")
    s.freeInstance()


def test_out_of_range_parameters_are_refused(sensors):
    log = LogRecorder()
    s = sensors.initializing_slave("params", log)
    # Outside the declared range: refused by the setter.
    with pytest.raises(Exception):
        s.setInteger([sensors.vr["fault_channel"]], [11])
    # Inside the declared ranges but inconsistent (cut-off above 0.45 × the 50 Hz magnetometer).
    sensors.set(s, filter_bandwidth=30.0)
    log.clear()
    assert_refused(log, lambda: s.exitInitializationMode(), "filter_bandwidth")
    s.freeInstance()
