"""The controllers' `phase` output switches at the communication point of a phase edge also
when the master accumulates its time (t += h: 250 steps of 0.02 s give 4.999999999999981,
not 5.0): a phase begins within the mission's time-edge tolerance of its start."""

import pytest

from fmu_util import Unpacked
from tailsim import controllers

H = 0.02


@pytest.mark.parametrize("model", controllers.MODEL_IDS)
def test_phase_switches_at_an_accumulated_edge(tmp_path, model):
    c = Unpacked(model, tmp_path)
    s = c.slave()
    phase_vr = [c.vr["phase"]]
    t, switched_at = 0.0, None
    for _ in range(260):
        s.doStep(t, H)
        if switched_at is None and s.getInteger(phase_vr)[0] == 1:
            switched_at = t
        t += H
    s.terminate()
    s.freeInstance()
    # The step computed at the accumulated 4.999999999999981 is the first of transition 1.
    assert switched_at is not None
    assert abs(switched_at - 5.0) < 1e-9, switched_at
    assert switched_at < 5.0
