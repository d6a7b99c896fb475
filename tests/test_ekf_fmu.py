"""The estimator FMU (tailsitter_ekf) under fmpy: ports named like the plant outputs,
tracking a straight climb from noise-free sensors, a GPS spike rejected, counted and
logged, a NaN input refused with an error, FMU state serialize/restore continuing
bit-identically."""

from __future__ import annotations

import json
import math

import pytest
from fmpy.fmi2 import FMU2Slave

from fmu_util import ROOT, LogRecorder, Unpacked

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
