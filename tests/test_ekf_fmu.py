"""The estimator FMU (tailsitter_ekf) under fmpy: ports named like the plant outputs,
tracking a straight climb from noise-free sensors, a GPS spike rejected, counted and
logged, a NaN input refused with an error, FMU state serialize/restore continuing
bit-identically; the initial estimate independent of the command inputs (no initialisation
loop through the controller), as the ModelStructure declares."""

from __future__ import annotations

import json
import math

import pytest
from fmpy.fmi2 import FMU2Slave

from fmu_util import ROOT, LogRecorder, Unpacked
from tailsim.declarations import COMMANDS

H = 0.02
CLIMB = 3.0  # m/s, the plant's default trimmed climb


@pytest.fixture(scope="module")
def ekf(tmp_path_factory) -> Unpacked:
    return Unpacked("tailsitter_ekf", tmp_path_factory.mktemp("ekf"))


def _declared(model: str) -> list[dict]:
    return json.loads((ROOT / "modelDescription" / f"{model}.json").read_text())["variables"]


def test_outputs_are_the_plant_outputs_with_their_units(ekf):
    outputs = {v.name: v.unit for v in ekf.md.modelVariables if v.causality == "output"}
    # Every plant output a controller reads (the controllers' inputs named like plant
    # outputs); plant diagnostics no controller reads (e.g. stall_fraction) need no estimate.
    from fmpy import read_model_description

    from fmu_util import fmu_path

    read = {
        v.name
        for c in ("tailsitter_lqr", "tailsitter_tsd")
        for v in read_model_description(str(fmu_path(c))).modelVariables
        if v.causality == "input"
    }
    for v in _declared("tailsitter_plant"):
        if v["causality"] == "output" and v["name"] in read:
            assert v["name"] in outputs, v["name"]
            assert outputs[v["name"]] == v.get("unit"), v["name"]
    for name in ("est_std_pos", "est_std_vel", "est_std_att", "wind_est_n", "wind_est_e", "wind_est_d"):
        assert name in outputs
    assert next(v for v in ekf.md.modelVariables if v.name == "rejected_measurements").type == "Integer"


class Climb:
    """Noise-free sensors of the plant's default state: 3 m/s straight up above the
    reference point, nose up, heading north (the FMU's input start values at t = 0)."""

    def __init__(self, ekf: Unpacked, slave: FMU2Slave):
        self.ekf, self.slave, self.k, self.fix = ekf, slave, 0, 0
        self.spike = 0.0

    def set_inputs(self):
        if self.k % 12 == 0:
            self.fix += 1
            t = self.k * H
            self.slave.setReal([self.ekf.vr["gps_height"]], [CLIMB * t + self.spike])
            self.slave.setInteger([self.ekf.vr["gps_fix_count"]], [self.fix])

    def step(self):
        self.set_inputs()
        self.slave.doStep(self.k * H, H)
        self.k += 1


def test_tracks_a_climb_rejects_a_spike_and_restores_state(ekf):
    log = LogRecorder()
    s = ekf.slave("climb", log=log)
    s.setDebugLogging(True, [])
    c = Climb(ekf, s)
    for _ in range(250):
        c.step()
    t = c.k * H
    pos_d, vel_d, std_pos, theta = ekf.get(s, "pos_d", "vel_d", "est_std_pos", "theta")
    assert abs(pos_d + CLIMB * t) < 3 * std_pos
    assert abs(vel_d + CLIMB) < 0.2
    assert abs(theta - math.pi / 2) < 0.02
    assert s.getInteger([ekf.vr["rejected_measurements"]])[0] == 0

    # A 200 m height spike on one fix: rejected, counted, logged; the estimate does not jump.
    while c.k % 12:
        c.step()
    c.spike = 200.0
    c.step()
    c.spike = 0.0
    assert s.getInteger([ekf.vr["rejected_measurements"]])[0] == 1
    assert any("GPS position measurement rejected" in m for _, _, m in log.messages), log.messages
    pos_d, std_pos = ekf.get(s, "pos_d", "est_std_pos")
    assert abs(pos_d + CLIMB * c.k * H) < 3 * std_pos

    # A NaN measurement is refused by fmi2SetReal (fmpy raises on fmi2Error).
    with pytest.raises(Exception):
        s.setReal([ekf.vr["imu_accel_x"]], [float("nan")])
    c.step()
    assert all(math.isfinite(x) for x in ekf.get(s, "pos_n", "pos_e", "pos_d", "quat_4", "alpha"))

    # Serialize, run on, restore, run again: identical outputs.
    state = s.serializeFMUstate(s.getFMUstate())
    k0, fix0 = c.k, c.fix
    names = ("pos_n", "pos_d", "vel_d", "quat_2", "est_std_pos", "airspeed")
    first = []
    for _ in range(60):
        c.step()
        first.append(ekf.get(s, *names))
    s.setFMUstate(s.deSerializeFMUstate(state))
    c.k, c.fix = k0, fix0
    for expected in first:
        c.step()
        assert ekf.get(s, *names) == expected
    s.terminate()
    s.freeInstance()


def test_initial_outputs_do_not_depend_on_the_commands(ekf):
    """A master that initialises every connection at once (OMSimulator) sets the controller's
    commands on the estimator in Initialization Mode and reads its outputs back, iterating
    until they agree. The outputs read in Initialization Mode and after it are the same, bit
    for bit, whatever the commands: there is no loop. The motor and servos start at
    `init_thrust`, `init_elevator`; the InitialUnknowns declare the measurements, no command."""
    outputs = [v.name for v in ekf.md.modelVariables if v.causality == "output" and v.type == "Real"]

    def initial(commands: list[dict[str, float]], **params: float) -> tuple[list[list[float]], list[float]]:
        s = ekf.initializing_slave("init")
        if params:
            ekf.set(s, **params)
        during = []
        for c in commands:
            ekf.set(s, **c)
            during.append(ekf.get(s, *outputs))
        s.exitInitializationMode()
        after = ekf.get(s, *outputs)
        s.terminate()
        s.freeInstance()
        return during, after

    trim = {n: float(ekf.var[n].start) for n in COMMANDS}
    assert trim["thrust_cmd"] == pytest.approx(88.376, abs=1e-3)
    # The LQR's first command under OMSimulator's former fixed point, then far-off values.
    off = [{**trim, "thrust_cmd": 77.56}, dict(zip(COMMANDS, (40.0, 0.3, -0.2, 0.1, 0.25, -0.15, 0.05), strict=True))]
    (reference,), after = initial([trim])
    assert after == reference
    during, after = initial(off)
    assert during == [reference, reference] and after == reference
    thrust, elevator = (reference[outputs.index(n)] for n in ("thrust", "elevator"))
    assert (thrust, elevator) == (float(ekf.var["init_thrust"].start), 0.0)
    # The parameters set the start (clamped to the limits as the plant's actuators).
    _, moved = initial(off, init_thrust=70.0, init_elevator=0.1)
    assert (moved[outputs.index("thrust")], moved[outputs.index("elevator")]) == (70.0, 0.1)

    commands = {ekf.var[n] for n in COMMANDS}
    unknowns = ekf.md.initialUnknowns
    assert len(unknowns) >= len(outputs)
    for u in unknowns:
        assert u.dependencies is not None, u.variable.name
        assert not commands & set(u.dependencies), f"{u.variable.name} declares a command"
    pos_n = next(u for u in unknowns if u.variable.name == "pos_n")
    assert ekf.var["gps_latitude"] in pos_n.dependencies
