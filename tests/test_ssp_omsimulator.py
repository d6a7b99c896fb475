"""The SSPs in OpenModelica's OMSimulator (docs/OMSIMULATOR.md), unmodified.

Always run (dist/*.ssp only): the properties OMSimulator needs of an SSD, which fmpy and
libcosim accept too —
- OpenModelica's fixed-step master as the system's first annotation (without it OMSimulator
  acb56d9d cannot create the system and aborts), at the step of the OSP annotation;
- one parameter binding, holding one parameter set, per component: with several inline
  bindings OMSimulator applies only the last and libcosim only the first, silently;
- every declared binding reaches its FMU under fmpy (set as fmpy's `simulate_ssp` sets them,
  read back from the FMU), and the same with every real value moved by one ulp, so that the
  value read back is the SSD's and not the FMU's default.

With an `OMSimulator` binary ($OMSIMULATOR or PATH; skipped otherwise), through
scripts/omsimulator.py: each SSP, closed loop and avionics, flies the default mission to the
SSD's stop time and matches the fmpy Jacobi master to 1e-9 m; the avionics systems start with
the estimator's motor and servos where the plant's are (its initial outputs depend on no
command, so OMSimulator's initialisation of every connection at once has no loop to solve); an
edited mission value reaches the controller; OMSimulator's library honours the SSD's stop time
(its command line replaces it by `--stopTime`).
"""

from __future__ import annotations

import ctypes
import pathlib
import sys
import zipfile

import numpy as np
import pytest
from lxml import etree

ROOT = pathlib.Path(__file__).resolve().parent.parent
DIST = ROOT / "dist"
sys.path.insert(0, str(ROOT / "scripts"))
import omsimulator  # noqa: E402

CLOSED_LOOP = ["tailsitter_lqr", "tailsitter_tsd"]
SSPS = CLOSED_LOOP + [f"{c}_avionics" for c in CLOSED_LOOP]
NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
    "oms": "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd",
}
BINARY = omsimulator.find_omsimulator()
needs_omsimulator = pytest.mark.skipif(BINARY is None, reason="no OMSimulator binary ($OMSIMULATOR or PATH)")


def ssp_path(name: str) -> pathlib.Path:
    path = DIST / f"{name}.ssp"
    assert path.exists(), f"{path} missing: run `cargo xtask dist` (or `cargo xtask ssp`) first"
    return path


def ssd_bytes(name: str) -> bytes:
    with zipfile.ZipFile(ssp_path(name)) as z:
        return z.read("SystemStructure.ssd")


def with_ssd(name: str, ssd: bytes, out: pathlib.Path) -> pathlib.Path:
    """A copy of the SSP with another SystemStructure.ssd."""
    with zipfile.ZipFile(ssp_path(name)) as z, zipfile.ZipFile(out, "w") as o:
        o.writestr("SystemStructure.ssd", ssd)
        for item in z.namelist():
            if item != "SystemStructure.ssd":
                o.writestr(item, z.read(item))
    return out


@pytest.mark.parametrize("name", SSPS)
def test_openmodelica_fixed_step_master_is_the_systems_first_annotation(name):
    root = etree.fromstring(ssd_bytes(name))
    annotations = root.findall("ssd:System/ssd:Annotations/ssc:Annotation", NS)
    # OMSimulator reads the first ssc:Annotation of the system only
    assert annotations and annotations[0].get("type") == "org.openmodelica"
    master = annotations[0].find("oms:Annotations/oms:SimulationInformation/oms:FixedStepMaster", NS)
    assert master is not None and master.get("description") == "oms-ma"
    osp = root.find("ssd:DefaultExperiment//osp:FixedStepAlgorithm", NS)
    assert float(master.get("stepSize")) == float(osp.get("baseStepSize")) == 0.02
    assert float(master.get("relativeTolerance")) > 0  # passed to fmi2SetupExperiment
    # OMSimulator and libcosim match fixed prefixes; libcosim reads xmlns attributes on children
    assert root.nsmap["oms"] == NS["oms"]
    assert not [e for e in root.iter() if e is not root and e.nsmap != root.nsmap]


@pytest.mark.parametrize("name", SSPS)
def test_one_parameter_binding_per_component(name):
    root = etree.fromstring(ssd_bytes(name))
    components = root.findall("ssd:System/ssd:Elements/ssd:Component", NS)
    bound = 0
    for comp in components:
        bindings = comp.findall("ssd:ParameterBindings/ssd:ParameterBinding", NS)
        assert len(bindings) <= 1, comp.get("name")
        for b in bindings:
            assert b.get("source") is None  # inline
            sets = b.findall("ssd:ParameterValues/ssv:ParameterSet", NS)
            assert [s.get("name") for s in sets] == [comp.get("name")]
            names = [p.get("name") for p in sets[0].iterfind("ssv:Parameters/ssv:Parameter", NS)]
            assert names and len(names) == len(set(names))
            bound += 1
    assert bound >= 2  # at least the controller and the plant


def declared_bindings(root) -> dict[str, dict[str, tuple[str, str]]]:
    """component -> parameter -> (type, value), from the SSD with lxml."""
    out = {}
    for comp in root.iterfind("ssd:System/ssd:Elements/ssd:Component", NS):
        params = comp.findall(".//ssd:ParameterBinding/ssd:ParameterValues/ssv:ParameterSet//ssv:Parameter", NS)
        out[comp.get("name")] = {p.get("name"): (etree.QName(p[0]).localname, p[0].get("value")) for p in params}
    return out


def read_back(ssp: pathlib.Path) -> dict[str, dict[str, float]]:
    """Each component's bound parameters as its FMU reports them after fmpy set them the way
    `simulate_ssp` does (instantiate, setupExperiment, set, then read in initialisation mode)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    from fmpy.ssp.simulation import get_value, set_value
    from fmpy.ssp.ssd import read_ssd

    ssd = read_ssd(str(ssp))
    out = {}
    with zipfile.ZipFile(ssp) as z:
        for comp in ssd.system.elements:
            params = [p for b in comp.parameterBindings for s in b.parameterValues for p in s.parameters]
            if not params:
                continue
            fmu = ssp.parent / f"{ssp.stem}-{comp.name}.fmu"
            fmu.write_bytes(z.read(comp.source))
            md = read_model_description(str(fmu))
            comp.variables = {v.name: v for v in md.modelVariables}
            unzipdir = extract(str(fmu))
            comp.fmu = FMU2Slave(
                guid=md.guid,
                unzipDirectory=unzipdir,
                modelIdentifier=md.coSimulation.modelIdentifier,
                instanceName=comp.name,
            )
            comp.fmu.instantiate()
            comp.fmu.setupExperiment(startTime=0.0)
            for p in params:
                set_value(comp, p.name, p.value)
            comp.fmu.enterInitializationMode()
            out[comp.name] = {p.name: float(get_value(comp, p.name)) for p in params}
            comp.fmu.freeInstance()
    return out


@pytest.mark.parametrize("name", SSPS)
def test_every_declared_binding_reaches_the_fmu_under_fmpy(name, tmp_path):
    root = etree.fromstring(ssd_bytes(name))
    declared = declared_bindings(root)
    got = read_back(with_ssd(name, ssd_bytes(name), tmp_path / f"{name}.ssp"))
    assert set(got) == {c for c, p in declared.items() if p}
    for comp, params in declared.items():
        for p, (_, value) in params.items():
            assert got[comp][p] == float(value), f"{comp}.{p}"
    # Every non-zero Real moved by one ulp towards zero (inside every declared range here):
    # the FMU now reports the SSD's value, not its default.
    moved = {}
    for comp in root.iterfind("ssd:System/ssd:Elements/ssd:Component", NS):
        for p in comp.iterfind(".//ssv:Parameter", NS):
            real = p.find("ssv:Real", NS)
            if real is not None and float(real.get("value")) != 0.0:
                y = float(np.nextafter(float(real.get("value")), 0.0))
                real.set("value", repr(y))
                moved[(comp.get("name"), p.get("name"))] = y
    assert len(moved) >= 80
    got = read_back(
        with_ssd(name, etree.tostring(root, xml_declaration=True, encoding="UTF-8"), tmp_path / "moved.ssp")
    )
    for (comp, p), y in moved.items():
        assert got[comp][p] == y, f"{comp}.{p}"


@needs_omsimulator
@pytest.mark.parametrize("name", SSPS)
def test_omsimulator_flies_like_the_fmpy_jacobi_master(name, tmp_path):
    """The closed loops and the avionics systems, each as shipped: nothing is given to either
    master but the SSP's FMUs and bindings."""
    figures = omsimulator.fly(BINARY, ssp_path(name), tmp_path)
    print(f"\n{name} in OMSimulator: {figures}")
    assert figures["returncode"] == 0 and figures["errors_logged"] == 0
    assert figures["schema_violations"] == 0
    assert figures["final_time"] == 35.0 and figures["final_phase"] == 4
    assert figures["rows"] == 1751
    assert figures["max_position_distance_m"] < 1e-9
    assert abs(figures["max_pos_error_m"] - figures["reference_max_pos_error_m"]) < 1e-9
    _, plant = figures["largest_plant_output_difference"]
    _, command = figures["largest_controller_output_difference"]
    assert plant < 1e-8 and command < 1e-8


@needs_omsimulator
def test_omsimulator_applies_an_edited_mission_binding(tmp_path):
    """t_transition_1 = 4 s in the SSD: the level phase starts at 9 s instead of 10 s."""
    root = etree.fromstring(ssd_bytes("tailsitter_lqr"))
    (value,) = root.findall(".//ssd:Component[@name='controller']//ssv:Parameter[@name='t_transition_1']/ssv:Real", NS)
    assert float(value.get("value")) == 5.0
    value.set("value", "4.0")
    ssd = etree.tostring(root, xml_declaration=True, encoding="UTF-8")
    edited = with_ssd("tailsitter_lqr", ssd, tmp_path / "t4.ssp")
    runs = {}
    for label, path in (("shipped", ssp_path("tailsitter_lqr")), ("edited", edited)):
        run = omsimulator.run_omsimulator(BINARY, path, tmp_path)
        s = omsimulator.last_per_time(run["signals"])
        # the controller's phase for the sample at t_k is recorded at t_k + h
        level = s["time"][np.argmax(s["controller.phase"] >= 2)] - 0.02
        runs[label] = level
    assert runs["shipped"] == pytest.approx(10.0, abs=0.021)
    assert runs["edited"] == pytest.approx(9.0, abs=0.021)


@needs_omsimulator
def test_omsimulator_library_honours_the_ssd_stop_time(tmp_path):
    """The command line runs 1 s unless --stopTime is given; the library reads the SSD's 35 s."""
    lib = pathlib.Path(BINARY).resolve().parent.parent / "lib" / "x86_64-linux-gnu" / "libOMSimulator.so"
    if not lib.exists():
        pytest.skip(f"no {lib}")
    oms = ctypes.CDLL(str(lib))
    cref = ctypes.c_char_p()
    assert oms.oms_setTempDirectory(str(tmp_path).encode()) == 0
    assert oms.oms_importFile(str(ssp_path("tailsitter_tsd")).encode(), ctypes.byref(cref)) == 0
    stop = ctypes.c_double()
    assert oms.oms_getStopTime(cref, ctypes.byref(stop)) == 0
    assert stop.value == 35.0
    assert oms.oms_setResultFile(cref, str(tmp_path / "library.mat").encode(), 1) == 0
    assert oms.oms_instantiate(cref) == 0 and oms.oms_initialize(cref) == 0 and oms.oms_simulate(cref) == 0
    t = ctypes.c_double()
    assert oms.oms_getTime(cref, ctypes.byref(t)) == 0
    oms.oms_terminate(cref)
    oms.oms_delete(cref)
    assert t.value == pytest.approx(35.0, abs=1e-9)
    signals = omsimulator.read_mat4(tmp_path / "library.mat")
    assert signals["time"][-1] == pytest.approx(35.0, abs=1e-9)


@needs_omsimulator
@pytest.mark.parametrize("controller", CLOSED_LOOP)
def test_omsimulator_starts_the_avionics_estimator_on_the_plants_actuators(controller, tmp_path):
    """OMSimulator initialises every connection at once, the controller's initial commands
    included. The estimator's motor and servos start at `init_thrust`, `init_elevator` (the
    trim the plant is released in), not at its command inputs, so at t = 0 its actuator
    outputs are the plant's, and the controller's first command is the fmpy master's (which
    initialises the estimator before the controller): the same start."""
    ssp = ssp_path(f"{controller}_avionics")
    run = omsimulator.run_omsimulator(BINARY, ssp, tmp_path)
    assert run["returncode"] == 0, run["log"][-2000:]
    sig = run["signals"]
    start = sig["time"] == 0.0
    for n in ("thrust", "elevator", "aileron", "rudder", "flap_collective", "flap_differential", "vertical_flap"):
        est, plant = sig[f"estimator.{n}"][start], sig[f"plant.{n}"][start]
        assert np.all(np.abs(est - plant) < 1e-9), (n, est, plant)
    assert sig["plant.thrust"][start][0] == pytest.approx(88.376, abs=1e-3)
    ref = omsimulator.fmpy_jacobi(ssp)
    s = omsimulator.last_per_time(sig)
    # The command for the sample at t_k: tailsim records it at t_k, OMSimulator at t_k + h.
    assert s["controller.thrust_cmd"][1] == pytest.approx(ref["thrust_cmd"][0], abs=1e-9)
