"""The FMI 3.0 units (`dist/fmi3/<id>.fmu`, `cargo xtask dist`): the same declarations and
the same libraries as the FMI 2.0 units, exported through crates/fmi3-export.

- every unit validates (fmpy: the FMI 3.0 XSDs and its semantic checks; fmutool's FMI 3.0
  checks), carries the x86_64-linux, aarch64-linux and x86_64-windows libraries (those the
  FMI 2.0 archives carry: all three by default), and declares the FMI 2.0 interface (names,
  value references, causality, variability, start values, dependencies);
- fmpy flies the default mission with plant + controller as FMI 3.0 Co-Simulation, with the
  master loop of tailsim's ClosedLoop, and matches the FMI 2.0 run (tailsim, fmpy) to
  POSITION_TOL;
- the plant as FMI 3.0 Model Exchange: integrated by fmpy's CVode in the closed loop of
  tests/test_model_exchange.py, it matches the FMI 2.0 Model Exchange run; fmpy's own
  `simulate_fmu` runs it;
- bad input (calls in the wrong state, unknown value references, NaN, wrong times) gives
  an error status and a log message, never a crash, and the instance stays usable;
- the aarch64 library loads and flies under qemu-user (tests/c-master/master_fmi3.c built
  for the host and for aarch64) and matches x86-64; the x86_64-windows library flies under
  Wine (the same master built with MinGW) and matches x86-64 Linux;
- every platform's library exports every function of fmi3FunctionTypes.h.

Figures: .venv/bin/python -m pytest tests/test_fmi3.py -s
"""

from __future__ import annotations

import ctypes
import math
import os
import pathlib
import re
import subprocess
import sys
import zipfile

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi3 import FMU3Model, FMU3Slave
from fmpy.validation import validate_fmu

from tailsim import ClosedLoop, declarations
from tailsim.masters.closed_loop import commands_driven
from tailsim.masters.system import default_step, default_stop, wire

ROOT = pathlib.Path(__file__).resolve().parent.parent
DIST = ROOT / "dist"
FMI3 = DIST / "fmi3"
UNITS = sorted(declarations.VARIABLES)
PLANT = "tailsitter_plant"
CONTROLLERS = ["tailsitter_lqr", "tailsitter_tsd", "tailsitter_px4"]
PLATFORMS = {"x86_64-linux": "so", "aarch64-linux": "so", "x86_64-windows": "dll"}
POSITIONS = ["pos_n", "pos_e", "pos_d"]
#: FMI 3.0 vs FMI 2.0 (m): the same library, model and call sequence; only the ABI differs.
POSITION_TOL = 1e-9
STATUS = ["OK", "Warning", "Discard", "Error", "Fatal"]
FMUTOOL = pathlib.Path(sys.executable).with_name("fmutool")
TYPE_2_TO_3 = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean", "String": "String"}


def fmi3_path(unit: str) -> pathlib.Path:
    path = FMI3 / f"{unit}.fmu"
    assert path.exists(), f"{path} missing: run `cargo xtask dist`"
    return path


class Log:
    """An fmi3LogMessageCallback recording (status, category, message)."""

    def __init__(self):
        self.messages: list[tuple[str, str, str]] = []

    def __call__(self, _env, status, category, message):
        self.messages.append((STATUS[status], category.decode(), message.decode()))

    def last_error(self) -> str:
        errors = [m for s, _, m in self.messages if s == "Error"]
        assert errors, self.messages
        return errors[-1]


class Unit3:
    """An extracted FMI 3.0 unit: model description, variables by name, slave factory."""

    def __init__(self, unit: str, tmp: pathlib.Path):
        self.path = fmi3_path(unit)
        self.md = read_model_description(str(self.path))
        self.dir = extract(str(self.path), unzipdir=str(tmp / f"{unit}-fmi3"))
        self.variables = {v.name: v for v in self.md.modelVariables}

    def vrs(self, names) -> list[int]:
        return [self.variables[n].valueReference for n in names]

    def slave(self, name: str, log: Log | None = None) -> FMU3Slave:
        s = FMU3Slave(
            guid=self.md.guid,
            unzipDirectory=self.dir,
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        s.instantiate(logMessage=log or Log())
        return s


@pytest.fixture(scope="module")
def units3(tmp_path_factory) -> dict[str, Unit3]:
    tmp = tmp_path_factory.mktemp("fmi3")
    return {u: Unit3(u, tmp) for u in UNITS}


# ------------------------------------------------------------------ model descriptions


@pytest.mark.parametrize("unit", UNITS)
def test_unit_validates_and_carries_every_platform(unit):
    path = fmi3_path(unit)
    problems = validate_fmu(str(path))
    assert problems == [], problems
    md = read_model_description(str(path), validate=True)
    assert md.fmiVersion == "3.0"
    assert md.coSimulation is not None
    assert (md.modelExchange is not None) == (unit == PLANT)
    with zipfile.ZipFile(path) as z:
        names = {n for n in z.namelist() if n.startswith("binaries/")}
    # The platforms `cargo xtask dist` built (by default all three), as the FMI 2.0 archives.
    with zipfile.ZipFile(DIST / f"{unit}.fmu") as z:
        win64 = f"binaries/win64/{unit}.dll" in z.namelist()
    built = {"x86_64-linux": True, "x86_64-windows": win64, "aarch64-linux": (DIST / "aarch64-linux").is_dir()}
    assert names == {f"binaries/{f}/{unit}.{PLATFORMS[f]}" for f, b in built.items() if b}
    # FMI 3.0 requires one independent variable; the FMI 2.0 declarations leave time
    # implicit: `time`, one above the largest declared value reference.
    independent = [v for v in md.modelVariables if v.causality == "independent"]
    assert [(v.name, v.type) for v in independent] == [("time", "Float64")]
    others = [v.valueReference for v in md.modelVariables if v.causality != "independent"]
    assert independent[0].valueReference == max(others) + 1


@pytest.mark.parametrize("unit", UNITS)
def test_fmutool_finds_no_fmi3_error(unit):
    """fmu-manipulation-toolbox's schema and semantic checks of the FMI 3.0 standard."""
    proc = subprocess.run([str(FMUTOOL), "-input", str(fmi3_path(unit)), "-check"], capture_output=True, text=True)
    out = proc.stdout + proc.stderr
    assert proc.returncode == 0, f"fmutool -check exit code {proc.returncode} (7 = errors):\n{out}"
    assert "compliant with FMI-3.0" in out and "No semantic error" in out, out
    assert not re.search(r"^\s*(ERROR|WARNING)\b", out, re.M), out


def _fmi3_headers() -> pathlib.Path:
    """The FMI 3.0 headers shipped with the fmi-sys crate the workspace builds with."""
    from test_aarch64 import fmi2_headers

    headers = fmi2_headers().parent.parent / "fmi-standard3" / "headers"
    assert (headers / "fmi3Functions.h").exists(), headers
    return headers


def _fmi3_functions() -> set[str]:
    """Every function of fmi3FunctionTypes.h (the headers of the fmi-sys crate)."""

    header = _fmi3_headers() / "fmi3FunctionTypes.h"
    return set(re.findall(r"\b(fmi3\w+)TYPE\s*\(", header.read_text()))


@pytest.mark.parametrize("unit", UNITS)
def test_every_library_exports_every_fmi3_function(unit, tmp_path):
    """fmpy resolves the FMI 3.0 functions as it calls them; other importers resolve all of
    them at load: every platform's library exports the complete set."""
    from test_aarch64 import tool

    wanted = _fmi3_functions()
    assert len(wanted) > 70
    tools = {
        "x86_64-linux": ["nm", "-D", "--defined-only"],
        "aarch64-linux": [tool("aarch64-linux-gnu-nm"), "-D", "--defined-only"],
        "x86_64-windows": [tool("x86_64-w64-mingw32-objdump"), "-p"],
    }
    with zipfile.ZipFile(fmi3_path(unit)) as z:
        libraries = [n for n in z.namelist() if n.startswith("binaries/")]
        z.extractall(tmp_path, members=libraries)
    for name in libraries:
        folder = name.split("/")[1]
        listing = subprocess.run([*tools[folder], str(tmp_path / name)], capture_output=True, text=True, check=True)
        exported = set(re.findall(r"\b(fmi3\w+)$", listing.stdout, re.M))
        assert wanted <= exported, (name, sorted(wanted - exported))


def _unknowns(unknowns) -> list[tuple[str, list[str]]]:
    return [(u.variable.name, sorted(d.name for d in (u.dependencies or []))) for u in unknowns]


@pytest.mark.parametrize("unit", UNITS)
def test_fmi3_declares_the_fmi2_interface(unit):
    md2 = read_model_description(str(DIST / f"{unit}.fmu"))
    md3 = read_model_description(str(fmi3_path(unit)))
    assert md3.guid == md2.guid
    v3 = {v.name: v for v in md3.modelVariables if v.name != "time"}
    assert list(v3) == [v.name for v in md2.modelVariables]
    for v in md2.modelVariables:
        w = v3[v.name]
        assert TYPE_2_TO_3[v.type] == w.type, v.name
        same = ("valueReference", "causality", "variability", "unit", "min", "max", "nominal", "description")
        for attr in same:
            assert getattr(w, attr) == getattr(v, attr), (v.name, attr)
        assert str(w.start) == str(v.start), v.name
        if v.derivative is not None:
            assert w.derivative.name == v.derivative.name
    assert _unknowns(md3.outputs) == _unknowns(md2.outputs)
    assert _unknowns(md3.derivatives) == _unknowns(md2.derivatives)
    assert _unknowns(md3.initialUnknowns) == _unknowns(md2.initialUnknowns)
    e2, e3 = md2.defaultExperiment, md3.defaultExperiment
    assert (e3.startTime, e3.stopTime, e3.stepSize) == (e2.startTime, e2.stopTime, e2.stepSize)


# ------------------------------------------------------------------ Co-Simulation mission


def _link(src: Unit3, dst: Unit3, names: list[str]) -> list[tuple[str, list[int], list[int]]]:
    """The transfers of a link, one per type: (type, source vrs, destination vrs)."""
    out = []
    for type_ in ("Float64", "Int32", "Boolean"):
        typed = [n for n in names if src.variables[n].type == type_]
        assert all(dst.variables[n].type == type_ for n in typed)
        if typed:
            out.append((type_, src.vrs(typed), dst.vrs(typed)))
    assert sum(len(s) for _, s, _ in out) == len(names), "every link is Float64, Int32 or Boolean"
    return out


def _transfer(src: FMU3Slave, dst: FMU3Slave, link) -> None:
    for type_, s, d in link:
        getattr(dst, f"set{type_}")(d, getattr(src, f"get{type_}")(s))


def fly_fmi3(plant: Unit3, controller: Unit3, fmus) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The default mission with fmpy's FMI 3.0 API and the loop of tailsim's ClosedLoop
    (Gauss-Seidel): plant then controller leave initialisation, the controller reading the
    plant's outputs; at t = k h the controller reads the plant and steps, the plant reads
    the controller, the plant's outputs at t are recorded, the plant steps."""
    p2, c2 = fmus[PLANT], fmus[controller.md.coSimulation.modelIdentifier]
    to_controller = _link(plant, controller, wire(p2, c2))
    to_plant = _link(controller, plant, commands_driven(p2, c2))
    h, stop = default_step(c2, {}, None), default_stop(c2, None)
    n = int(round(stop / h))
    p, c = plant.slave("plant"), controller.slave("controller")
    for s in (p, c):
        s.enterInitializationMode(startTime=0.0)
    p.exitInitializationMode()
    _transfer(p, c, to_controller)
    c.exitInitializationMode()
    record = plant.vrs(POSITIONS)
    data = np.full((n + 1, len(POSITIONS)), np.nan)
    for k in range(n + 1):
        t = k * h
        _transfer(p, c, to_controller)
        assert c.doStep(t, h) == (False, False, False, t + h)
        _transfer(c, p, to_plant)
        data[k] = p.getFloat64(record)
        if k < n:
            p.doStep(t, h)
            assert p.getFloat64([plant.variables["time"].valueReference]) == [t + h]
    for s in (p, c):
        s.terminate()
        s.freeInstance()
    return np.arange(n + 1) * h, {name: data[:, i] for i, name in enumerate(POSITIONS)}


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_fmpy_flies_the_default_mission_as_fmi2(units3, fmus, controller):
    t, fmi3 = fly_fmi3(units3[PLANT], units3[controller], fmus)
    reference = ClosedLoop(fmus[PLANT], fmus[controller]).run()
    assert np.array_equal(t, reference.signals["time"])
    travel = max(np.ptp(fmi3[p]) for p in POSITIONS)
    assert travel > 50.0, f"the mission moved the plant only {travel} m"
    dpos = max(float(np.max(np.abs(fmi3[p] - reference.signals[p]))) for p in POSITIONS)
    print(f"\n{controller}: FMI 3.0 vs FMI 2.0 over {t[-1]:g} s ({len(t)} points): largest |Δpos| = {dpos:.3g} m")
    assert dpos <= POSITION_TOL


# ------------------------------------------------------------------ Model Exchange


class Fmi3ModelAsFmi2:
    """The FMI 3.0 plant (fmpy's FMU3Model) behind the calls of fmpy's FMU2Model that
    tests/test_model_exchange.py's master makes: the calls FMI 3.0 renamed or merged are
    mapped, every other one passes through."""

    def __init__(self, plant: Unit3, log: Log):
        md = plant.md
        self.m = FMU3Model(
            guid=md.guid, unzipDirectory=plant.dir, modelIdentifier=md.modelExchange.modelIdentifier, instanceName="me"
        )
        self.m.instantiate(logMessage=log)
        self.experiment: dict = {}

    def setupExperiment(self, tolerance=None, startTime=0.0):
        self.experiment = {"tolerance": tolerance, "startTime": startTime}

    def enterInitializationMode(self):
        self.m.enterInitializationMode(**self.experiment)

    def newDiscreteStates(self):
        return self.m.updateDiscreteStates()

    def getReal(self, vr):
        return self.m.getFloat64(vr)

    def setReal(self, vr, values):
        self.m.setFloat64(vr, values)

    def getDerivatives(self, dx, nx):
        return self.m.getContinuousStateDerivatives(dx, nx)

    def __getattr__(self, name):
        return getattr(self.m, name)


def test_plant_model_exchange_matches_fmi2_model_exchange(units3, fmus):
    """tests/test_model_exchange.py's closed loop (CVode, its tolerance, the LQR as
    Co-Simulation) with the plant once through FMI 2.0 and once through FMI 3.0 Model
    Exchange."""
    from test_model_exchange import RTOL, fly_model_exchange

    controller = fmus["tailsitter_lqr"]
    log = Log()
    plant3 = Fmi3ModelAsFmi2(units3[PLANT], log)
    nx = plant3.getNumberOfContinuousStates()
    assert nx == len(units3[PLANT].md.derivatives) and plant3.getNumberOfEventIndicators() == 0
    t3, me3 = fly_model_exchange(fmus[PLANT], controller, plant=plant3)
    assert [m for s, _, m in log.messages if s == "Error"] == []
    t2, me2 = fly_model_exchange(fmus[PLANT], controller)
    assert np.array_equal(t3, t2)
    assert np.max(np.hypot(me3["u"], me3["w"])) > 20.0, "the mission reached level flight"
    worst = {n: float(np.max(np.abs(me3[n] - me2[n]))) for n in me2}
    name, err = max(worst.items(), key=lambda kv: kv[1])
    dpos = max(worst[p] for p in POSITIONS)
    print(
        f"\nME FMI 3.0 vs FMI 2.0 (CVode, rtol {RTOL:g}, {t3[-1]:g} s, {nx} states): "
        f"position {dpos:.3g} m, largest of any state {err:.3g} ({name})"
    )
    assert dpos <= POSITION_TOL


def test_fmpy_simulates_the_plant_as_model_exchange(fmus):
    """fmpy's own Model Exchange driver (event and continuous-time modes, CVode) on the
    FMI 3.0 plant, inputs at their start values: the trajectory of the FMI 2.0 plant."""
    outputs = ["pos_d", "theta", "u", "w"]
    kw = dict(fmi_type="ModelExchange", solver="CVode", stop_time=2.0, output_interval=0.02, output=outputs)
    r3 = simulate_fmu(str(fmi3_path(PLANT)), **kw)
    r2 = simulate_fmu(str(fmus[PLANT].path), **kw)
    assert np.array_equal(r3["time"], r2["time"])
    assert r3["time"][-1] == pytest.approx(2.0)
    # A real flight: the trim's vertical climb at its initial speed.
    assert r3["pos_d"][-1] < r3["pos_d"][0] - 1.0
    for name in outputs:
        assert np.max(np.abs(r3[name] - r2[name])) <= POSITION_TOL, name


# ------------------------------------------------------------------ bad input


def _raises(log: Log, call, *args) -> str:
    with pytest.raises(FMICallException):
        call(*args)
    return log.last_error()


def test_bad_input_gives_an_error_status_never_a_crash(units3):
    plant = units3[PLANT]
    log = Log()
    p = plant.slave("bad", log)
    throttle = plant.vrs(["throttle_cmd"]) if "throttle_cmd" in plant.variables else None
    inputs = [v for v in plant.md.modelVariables if v.causality == "input" and v.type == "Float64"]
    vr_in = inputs[0].valueReference
    pos_n = plant.variables["pos_n"].valueReference
    time_vr = plant.variables["time"].valueReference
    assert _raises(log, p.doStep, 0.0, 0.02) == "fmi3DoStep: illegal call in state Instantiated"
    assert _raises(log, p.getFloat64, [pos_n]) == "fmi3GetFloat64: illegal call in state Instantiated"
    assert _raises(log, p.exitInitializationMode) == "fmi3ExitInitializationMode: illegal call in state Instantiated"
    p.enterInitializationMode(startTime=0.0, stopTime=1.0)
    assert _raises(log, p.setFloat64, [99999], [1.0]) == "fmi3SetFloat64: unknown value reference 99999"
    assert f"{inputs[0].name} (value reference {vr_in}): value nan is not finite" in _raises(
        log, p.setFloat64, [vr_in], [math.nan]
    ).replace("NaN", "nan")
    assert "is the independent variable" in _raises(log, p.setFloat64, [time_vr], [1.0])
    assert "is of type Real, not Integer" in _raises(log, p.getInt32, [pos_n])
    assert "is not a Float32 variable" in _raises(log, p.getFloat32, [pos_n])
    p.exitInitializationMode()
    assert "does not match the FMU time 0 s" in _raises(log, p.doStep, 0.5, 0.02)
    assert "must be finite and > 0" in _raises(log, p.doStep, 0.0, -0.02)
    assert "after the stop time" in _raises(log, p.doStep, 0.0, 2.0)
    assert "not supported" in _raises(log, p.enterConfigurationMode)
    # The instance is intact: it steps and its outputs are finite.
    p.doStep(0.0, 0.02)
    assert p.getFloat64([time_vr]) == [0.02]
    assert all(math.isfinite(x) for x in p.getFloat64(plant.vrs(POSITIONS)))
    p.terminate()
    assert _raises(log, p.doStep, 0.02, 0.02) == "fmi3DoStep: illegal call in state Terminated"
    p.freeInstance()
    assert throttle is None or throttle[0] >= 0


def test_model_exchange_bad_input_gives_an_error_status(units3):
    plant = units3[PLANT]
    nx = len(plant.md.derivatives)
    log = Log()
    m = FMU3Model(guid=plant.md.guid, unzipDirectory=plant.dir, modelIdentifier=PLANT, instanceName="bad_me")
    m.instantiate(logMessage=log)
    x = (ctypes.c_double * nx)()
    assert "illegal call in state Instantiated" in _raises(log, m.getContinuousStates, x, nx)
    m.enterInitializationMode(startTime=0.0)
    m.exitInitializationMode()
    assert "illegal call in state EventMode" in _raises(log, m.setContinuousStates, x, nx)
    flag, last = ctypes.c_bool(), ctypes.c_double()
    args = (m.component, 0.0, 0.01, True, *(ctypes.byref(flag) for _ in range(3)), ctypes.byref(last))
    assert "illegal call in state EventMode" in _raises(log, m.fmi3DoStep, *args)
    m.enterContinuousTimeMode()
    m.getContinuousStates(x, nx)
    assert all(math.isfinite(v) for v in x)
    assert f"but the model has {nx} continuous states" in _raises(log, m.getContinuousStateDerivatives, x, nx - 1)
    assert "has none" in _raises(log, m.getEventIndicators, x, 1)
    good = list(x)
    x[3] = math.nan
    assert "is not finite" in _raises(log, m.setContinuousStates, x, nx)
    assert "time = inf is not finite" in _raises(log, m.setTime, math.inf)
    # Nothing was taken over: the derivatives at the states before the refused calls.
    x[3] = good[3]
    m.setContinuousStates(x, nx)
    dx = (ctypes.c_double * nx)()
    m.getContinuousStateDerivatives(dx, nx)
    assert all(math.isfinite(v) for v in dx)
    m.terminate()
    m.freeInstance()


@pytest.mark.parametrize("unit", UNITS)
def test_every_unit_refuses_illegal_calls(units3, unit):
    u = units3[unit]
    log = Log()
    s = u.slave("bad", log)
    assert _raises(log, s.doStep, 0.0, 0.01) == "fmi3DoStep: illegal call in state Instantiated"
    assert "value nan is not finite" in _raises(
        log,
        s.setFloat64,
        [next(v.valueReference for v in u.md.modelVariables if v.causality == "parameter" and v.type == "Float64")],
        [math.nan],
    ).replace("NaN", "nan")
    # Wrong token: no instance, a message.
    bad = FMU3Slave(guid="{wrong}", unzipDirectory=u.dir, modelIdentifier=unit, instanceName="x")
    wrong = Log()
    with pytest.raises(Exception, match="Failed to instantiate"):
        bad.instantiate(logMessage=wrong)
    assert "instantiationToken mismatch" in wrong.last_error()
    s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    s.doStep(0.0, 0.01)
    s.terminate()
    s.freeInstance()


# ------------------------------------------------------------------ aarch64 under qemu


@pytest.fixture(scope="module")
def masters3(tmp_path_factory) -> dict[str, list[str]]:
    """tests/c-master/master_fmi3.c built for the host and for aarch64 (as test_aarch64's
    FMI 2.0 master)."""
    from test_aarch64 import build_masters

    source = ROOT / "tests" / "c-master" / "master_fmi3.c"
    return build_masters(source, _fmi3_headers(), tmp_path_factory.mktemp("c-master3"))


def _fly_c(master: list[str], folder: str, controller: str, units3, fmus, tmp: pathlib.Path):
    plant, ctrl = units3[PLANT], units3[controller]
    libs = []
    for u in (PLANT, controller):
        with zipfile.ZipFile(fmi3_path(u)) as z:
            libs.append(z.extract(f"binaries/{folder}/{u}.{PLATFORMS[folder]}", tmp / folder))
    links = [wire(fmus[PLANT], fmus[controller]), commands_driven(fmus[PLANT], fmus[controller])]
    for names, src in zip(links, [plant, ctrl], strict=True):
        assert {src.variables[n].type for n in names} == {"Float64"}, "the C master links Float64 only"
    c2 = fmus[controller]
    args = [
        libs[0],
        plant.md.guid,
        libs[1],
        ctrl.md.guid,
        repr(default_step(c2, {}, None)),
        repr(default_stop(c2, None)),
        ",".join(f"{a}:{b}" for a, b in zip(plant.vrs(links[0]), ctrl.vrs(links[0]), strict=True)),
        ",".join(f"{a}:{b}" for a, b in zip(ctrl.vrs(links[1]), plant.vrs(links[1]), strict=True)),
        ",".join(str(v) for v in plant.vrs(POSITIONS)),
    ]
    run = subprocess.run([*master, *args], capture_output=True, text=True)
    assert run.returncode == 0, f"{master[-1]} exited {run.returncode}: {run.stderr[-2000:]}"
    data = np.loadtxt(run.stdout.splitlines(), delimiter=",", ndmin=2)
    return data[:, 0], {n: data[:, 1 + i] for i, n in enumerate(POSITIONS)}


def test_aarch64_fmi3_library_flies_under_qemu_as_x86_64(masters3, units3, fmus, tmp_path):
    controller = "tailsitter_lqr"
    t_x86, x86 = _fly_c(masters3["x86_64"], "x86_64-linux", controller, units3, fmus, tmp_path)
    t_arm, arm = _fly_c(masters3["aarch64"], "aarch64-linux", controller, units3, fmus, tmp_path)
    reference = ClosedLoop(fmus[PLANT], fmus[controller]).run()
    assert np.array_equal(t_x86, t_arm) and np.array_equal(t_x86, reference.signals["time"])
    d_arm = max(float(np.max(np.abs(x86[p] - arm[p]))) for p in POSITIONS)
    d_fmi2 = max(float(np.max(np.abs(x86[p] - reference.signals[p]))) for p in POSITIONS)
    print(
        f"\n{controller}, C master on FMI 3.0: aarch64 (qemu) - x86_64 {d_arm:.3g} m; "
        f"x86_64 FMI 3.0 - FMI 2.0 (tailsim) {d_fmi2:.3g} m"
    )
    assert max(np.ptp(x86[p]) for p in POSITIONS) > 50.0
    assert d_arm <= POSITION_TOL
    assert d_fmi2 <= POSITION_TOL


def test_win64_fmi3_library_flies_under_wine_as_x86_64(units3, fmus, tmp_path):
    """The x86_64-windows library, driven by the same C master built with MinGW, under Wine
    (with test_win64's bcryptprimitives stand-in next to the master): the x86_64-linux
    flight within test_win64's tolerance (only libm's last bits differ)."""
    from test_win64 import MINGW_GCC, WIN64_TOL, _prng_shim, _wine64

    wine = _wine64()
    os.environ.setdefault("WINEDEBUG", "-all")
    exe = tmp_path / "master_fmi3.exe"
    flags = ["-std=c11", "-D_POSIX_C_SOURCE=200809L", "-O2", "-Wall", "-Wextra", "-Werror"]
    source = ROOT / "tests" / "c-master" / "master_fmi3.c"
    subprocess.run([MINGW_GCC, *flags, f"-I{_fmi3_headers()}", str(source), "-o", str(exe)], check=True)
    _prng_shim(tmp_path)
    controller = "tailsitter_lqr"
    t_win, win = _fly_c([wine, str(exe)], "x86_64-windows", controller, units3, fmus, tmp_path)
    from test_aarch64 import build_masters

    host = build_masters(source, _fmi3_headers(), tmp_path)["x86_64"]
    t_lin, lin = _fly_c(host, "x86_64-linux", controller, units3, fmus, tmp_path)
    assert np.array_equal(t_win, t_lin)
    assert max(np.ptp(win[p]) for p in POSITIONS) > 50.0
    dpos = max(float(np.max(np.abs(win[p] - lin[p]))) for p in POSITIONS)
    print(f"\n{controller}, C master on FMI 3.0: x86_64-windows (Wine) - x86_64-linux {dpos:.3g} m")
    assert dpos <= WIN64_TOL
