"""The plant as FMI 2.0 Model Exchange (same tailsitter_plant.fmu, same binary).

A small ME master (below) steps a controller FMU (Co-Simulation) at its sample
time and integrates the plant between samples with fmpy's CVode (SUNDIALS, variable
step and order, error control scaled by the plant's nominal values). At each sample
the new commands are a discontinuity of the plant's inputs: the master enters event
mode, sets them, leaves event mode and re-initialises CVode, as an ME importer must.
The same mission is flown with the plant as Co-Simulation (fixed-step RK4 inside the
FMU, 2 ms) by tailsim's Gauss-Seidel master, which samples identically; the two
trajectories must agree to ME_TOL.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.fmi2 import FMU2Model, fmi2False

from fmu_util import PLANT_STATES_BUT_FLAPS, fmu_path
from tailsim import ClosedLoop

CONTROLLERS = ["tailsitter_lqr", "tailsitter_tsd"]
RTOL = 1e-9
COMPARED = PLANT_STATES_BUT_FLAPS
# ME (CVode, rtol 1e-9) vs CS (RK4, 2 ms): both integrate the same right-hand side over
# the same 20 ms sample intervals with the same held commands. RK4's local error
# ~ (2 ms)^5 f^(5) and CVode's tolerance-controlled error are both far below 1e-6 per
# sample; the closed loop (marginally stable in hover) may grow them over 35 s, but not
# past 0.1 mm (measured: 1e-5 N thrust, 5e-6 m position, on the thesis's transitions). The
# α-limited profile ends the LQR's back transition in a coasting climb with the
# thrust at its 0 N floor, where the induced velocity has a kink that both integrators step
# across differently: 1.0e-4 measured there. 3e-4 in SI units (m, m/s, rad/s, N, rad).
ME_TOL = 3e-4


class _NoInput:
    def apply(self, _t):
        return None


def fly_model_exchange(plant_fmu, controller, stop_time=None, plant=None):
    """The closed loop with the plant integrated by CVode as Model Exchange.

    Returns (time, {plant output: values}) sampled like tailsim's ClosedLoop: row k is
    t_k = k h, plant outputs at t_k, after the controller sampled them. `plant`: an
    instantiated Model Exchange instance of the plant with the FMI 2.0 calls of fmpy's
    FMU2Model (tests/test_fmi3.py passes the FMI 3.0 plant behind them); default: the
    FMI 2.0 plant of `plant_fmu`."""
    from fmpy.sundials import CVodeSolver

    md = read_model_description(str(fmu_path("tailsitter_plant")))
    assert md.modelExchange is not None and md.coSimulation is not None
    assert md.numberOfEventIndicators == 0
    nx = len(md.derivatives)
    pv = {v.name: v for v in md.modelVariables}
    if plant is None:
        plant = FMU2Model(
            guid=md.guid,
            unzipDirectory=plant_fmu.dir,
            modelIdentifier=md.modelExchange.modelIdentifier,
            instanceName="plant_me",
        )
        plant.instantiate()
    c = controller.instantiate("controller")
    cv = controller.variables
    c_in = [n for n in controller.names("input") if n in pv and pv[n].causality == "output"]
    c_out = [n for n in controller.names("output") if n in pv and pv[n].causality == "input"]
    p_out_vr = [pv[n].valueReference for n in c_in]
    c_in_vr = [cv[n].valueReference for n in c_in]
    c_out_vr = [cv[n].valueReference for n in c_out]
    p_in_vr = [pv[n].valueReference for n in c_out]
    rec_vr = [pv[n].valueReference for n in COMPARED]
    h = float(controller.md.defaultExperiment.stepSize)
    stop = float(stop_time if stop_time is not None else controller.md.defaultExperiment.stopTime)
    n = int(round(stop / h))

    plant.setupExperiment(tolerance=RTOL, startTime=0.0)
    plant.enterInitializationMode()
    plant.exitInitializationMode()
    info = plant.newDiscreteStates()
    assert info[0] == fmi2False  # newDiscreteStatesNeeded
    plant.enterContinuousTimeMode()
    c.setupExperiment(startTime=0.0)
    c.enterInitializationMode()
    c.setReal(c_in_vr, plant.getReal(p_out_vr))
    c.exitInitializationMode()

    solver = CVodeSolver(
        nx=nx,
        nz=0,
        get_x=plant.getContinuousStates,
        set_x=plant.setContinuousStates,
        get_dx=plant.getDerivatives,
        get_z=plant.getEventIndicators,
        get_nominals=plant.getNominalsOfContinuousStates,
        set_time=plant.setTime,
        input=_NoInput(),
        startTime=0.0,
        maxStep=h,
        relativeTolerance=RTOL,
    )
    time = np.arange(n + 1) * h
    data = np.full((n + 1, len(COMPARED)), np.nan)
    for k in range(n + 1):
        t = time[k]
        c.setReal(c_in_vr, plant.getReal(p_out_vr))
        c.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        u = c.getReal(c_out_vr)
        data[k] = plant.getReal(rec_vr)
        if k == n:
            break
        # New commands: a discontinuity of the inputs, handled at an event.
        plant.enterEventMode()
        plant.setReal(p_in_vr, u)
        info = plant.newDiscreteStates()
        assert info[0] == fmi2False and info[1] == fmi2False
        plant.enterContinuousTimeMode()
        solver.reset(t)
        t_next = time[k + 1]
        _, _, t_reached = solver.step(t, t_next)
        assert t_reached == pytest.approx(t_next, abs=1e-12)
        plant.setTime(t_next)
        plant.completedIntegratorStep()
    for s in (plant, c):
        s.terminate()
        s.freeInstance()
    return time, {name: data[:, i] for i, name in enumerate(COMPARED)}


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_model_exchange_cvode_closed_loop_agrees_with_co_simulation(controller, fmus):
    time, me = fly_model_exchange(fmus["tailsitter_plant"], fmus[controller])
    cs = ClosedLoop(fmus["tailsitter_plant"], fmus[controller]).run()
    assert len(cs.time) == len(time)
    worst = {n: float(np.max(np.abs(me[n] - cs[n]))) for n in COMPARED}
    name, err = max(worst.items(), key=lambda kv: kv[1])
    pos = max(worst[k] for k in ("pos_n", "pos_e", "pos_d"))
    print(
        f"\n{controller}: ME (CVode, rtol {RTOL:g}) vs CS (RK4 2 ms) over {time[-1]:.0f} s: "
        f"max |Δ| = {err:.3g} ({name}), position {pos:.3g} m"
    )
    # The mission really flew: level flight at 25 m/s reached (θ well below 90°).
    assert np.max(np.hypot(me["u"], me["w"])) > 20.0
    assert err < ME_TOL, worst


def test_saturations_hold_under_the_variable_step_solver(fmus):
    """Thrust stays in [thrust_min, thrust_max] and no servo moves faster than its rate
    limit along the CVode trajectory of the first 12 s (vertical flight, transition 1)."""
    time, me = fly_model_exchange(fmus["tailsitter_plant"], fmus["tailsitter_tsd"], stop_time=12.0)
    md = read_model_description(str(fmu_path("tailsitter_plant")))
    start = {v.name: float(v.start) for v in md.modelVariables if v.start is not None and v.type == "Real"}
    lo, hi = start["thrust_min"], start["thrust_max"]
    assert np.all(me["thrust"] >= lo - 1e-9 * hi) and np.all(me["thrust"] <= hi * (1 + 1e-9))
    rate = start["servo_rate_limit"]
    lim = start["deflection_limit"]
    for s in ("elevator", "aileron", "rudder"):
        assert np.all(np.abs(me[s]) <= lim * (1 + 1e-9))
        # Over each sample the mean rate is bounded by the limit (plus solver tolerance).
        assert np.max(np.abs(np.diff(me[s])) / np.diff(time)) <= rate * (1 + 1e-6) + 1e-6


def test_me_derivatives_saturate_at_the_bounds(fmus):
    """At thrust = thrust_max with a command above it, Ṫ = 0 (never outwards); a large
    elevator command gives exactly the rate limit as derivative (2.3.16, App. D.5)."""
    plant = fmus["tailsitter_plant"]
    md = plant.md
    pv = plant.variables
    s = FMU2Model(
        guid=md.guid, unzipDirectory=plant.dir, modelIdentifier=md.modelExchange.modelIdentifier, instanceName="bounds"
    )
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.newDiscreteStates()
    s.enterContinuousTimeMode()
    nx = len(md.derivatives)
    x = np.array(_get_x(s, nx))
    t_max = float(pv["thrust_max"].start)
    rate = float(pv["servo_rate_limit"].start)
    states = [d.variable.derivative.name for d in md.derivatives]
    x[states.index("thrust")] = t_max
    _set_x(s, x)
    s.enterEventMode()
    s.setReal([pv["thrust_cmd"].valueReference, pv["elevator_cmd"].valueReference], [10 * t_max, 0.5])
    s.enterContinuousTimeMode()
    dx = _get_dx(s, nx)
    assert dx[states.index("thrust")] == 0.0
    assert dx[states.index("elevator")] == pytest.approx(rate, rel=1e-12)
    (der_t,) = s.getReal([pv["der_thrust"].valueReference])
    assert der_t == 0.0
    s.terminate()
    s.freeInstance()
    assert math.isfinite(rate)


def _get_x(s, nx):
    from ctypes import c_double

    buf = (c_double * nx)()
    s.getContinuousStates(buf, nx)
    return list(buf)


def _set_x(s, x):
    from ctypes import c_double

    buf = (c_double * len(x))(*x)
    s.setContinuousStates(buf, len(x))


def _get_dx(s, nx):
    from ctypes import c_double

    buf = (c_double * nx)()
    s.getDerivatives(buf, nx)
    return list(buf)


def test_model_exchange_state_machine_guards(fmus):
    """Calls outside the ME states they are legal in fail with a logged message (the
    export layer's masks, FMI 2.0 §3.2.3), and a controller (no continuous states)
    cannot be instantiated as Model Exchange."""
    from fmu_util import LogRecorder

    plant = fmus["tailsitter_plant"]
    md = plant.md
    rec = LogRecorder()
    s = FMU2Model(
        guid=md.guid, unzipDirectory=plant.dir, modelIdentifier=md.modelExchange.modelIdentifier, instanceName="guards"
    )
    s.instantiate(callbacks=rec.callbacks)
    nx = len(md.derivatives)

    def fails(call, text):
        with pytest.raises(Exception):
            call()
        assert any(text in m for _, _, m in rec.messages), (text, rec.messages[-3:])

    fails(lambda: s.enterEventMode(), "fmi2EnterEventMode: illegal call in state Instantiated")
    fails(lambda: _get_dx(s, nx), "fmi2GetDerivatives: illegal call in state Instantiated")
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()  # → EventMode
    fails(lambda: _set_x(s, [0.0] * nx), "fmi2SetContinuousStates: illegal call in state EventMode")
    fails(lambda: s.completedIntegratorStep(), "fmi2CompletedIntegratorStep: illegal call in state EventMode")
    s.enterContinuousTimeMode()
    fails(lambda: s.newDiscreteStates(), "fmi2NewDiscreteStates: illegal call in state ContinuousTimeMode")
    fails(lambda: _get_dx(s, nx - 1), f"nx = {nx - 1}, but the model has {nx} continuous states")
    x = _get_x(s, nx)
    x[0] = float("nan")
    fails(lambda: _set_x(s, x), "state pos_n = NaN is not finite")
    fails(lambda: s.setReal([plant.variables["mass"].valueReference], [10.0]), "mass")
    s.terminate()
    s.freeInstance()

    lqr = fmus["tailsitter_lqr"]
    me = FMU2Model(guid=lqr.md.guid, unzipDirectory=lqr.dir, modelIdentifier="tailsitter_lqr", instanceName="x")
    with pytest.raises(Exception):
        me.instantiate(callbacks=rec.callbacks)
    assert any("is a Co-Simulation FMU only" in m for _, _, m in rec.messages)
