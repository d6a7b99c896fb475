"""Every declared variable of every FMU can be read and written through the
FMI API exactly as its declaration says (causality, variability, type)."""

from __future__ import annotations

import pytest

from fmu_util import LogRecorder
from tailsim import declarations

FMUS = list(declarations.MODELS)


def getter(slave, v):
    return {"Real": slave.getReal, "Integer": slave.getInteger, "Boolean": slave.getBoolean, "String": slave.getString}[
        v.type
    ]


def setter(slave, v):
    return {"Real": slave.setReal, "Integer": slave.setInteger, "Boolean": slave.setBoolean, "String": slave.setString}[
        v.type
    ]


def start_of(v):
    if v.type == "Real":
        return float(v.start)
    if v.type == "Integer":
        return int(v.start)
    if v.type == "Boolean":
        return v.start in ("true", "1", True)
    return v.start or ""


@pytest.mark.parametrize("name", FMUS)
def test_every_variable_as_declared(fmus, name):
    fmu = fmus[name]
    log = LogRecorder()
    s = fmu.instantiate("vars", log.callbacks)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    settable_in_init = {"parameter", "input"}
    for v in fmu.md.modelVariables:
        (value,) = getter(s, v)([v.valueReference])
        if isinstance(value, bytes):
            value = value.decode()
        if v.start is not None and v.causality in settable_in_init:
            if v.type == "Boolean":
                # fmpy returns an fmi2Boolean (0/1), the start value is parsed to bool.
                assert bool(value) == start_of(v), v.name
            else:
                assert value == pytest.approx(start_of(v)), v.name
        if v.causality in settable_in_init:
            setter(s, v)([v.valueReference], [start_of(v)])
        else:
            log.clear()
            with pytest.raises(Exception):
                setter(s, v)([v.valueReference], [0.0 if v.type == "Real" else 0])
            assert any(v.name in m for m in log.errors()), (v.name, log.messages)
    s.exitInitializationMode()
    for v in fmu.md.modelVariables:
        getter(s, v)([v.valueReference])
        if v.causality == "input" or (v.causality == "parameter" and v.variability == "tunable"):
            setter(s, v)([v.valueReference], [start_of(v)])
        elif v.causality == "parameter":
            log.clear()
            with pytest.raises(Exception):
                setter(s, v)([v.valueReference], [start_of(v)])
            assert any(v.name in m for m in log.errors()), (v.name, log.messages)
    # Wrong type and unknown value reference.
    real = next(v for v in fmu.md.modelVariables if v.type == "Real" and v.causality == "input")
    with pytest.raises(Exception):
        s.setInteger([real.valueReference], [1])
    with pytest.raises(Exception):
        s.getReal([10_000])
    s.terminate()
    s.freeInstance()
