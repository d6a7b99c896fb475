"""The SSP 1.0 system files dist/<controller>.ssp (written by `cargo xtask ssp`, and by
`cargo xtask dist`): structure, schema, and flights under two SSP importers.

- fmpy 0.3.32 (`fmpy.ssp.simulation.simulate_ssp`) validates the SSD against the SSP 1.0
  schema and flies it. Its limits, worked around or tested as far as they go:
  * it does not apply the SSD's ParameterBindings (it reads them, `read_ssd`, but
    `simulate_ssp` only applies a `parameter_set` argument): the test builds that argument
    from the SSD's own bindings;
  * it ignores the default experiment: stop time and step size are passed explicitly,
    and it advances time by repeated addition (it may take one step past 35 s);
  * it is a Jacobi master whose connectors all start at 0.0, so over the first step the
    controller sees zeros (a zero quaternion, zero airspeed) and the plant a zero command;
    the loop recovers within a few samples and flies the mission;
  * it records connectors only, one row per step labelled with the step's start time but
    holding the values at its end: the SSD declares every plant output and controller
    output as a connector so the whole state is recorded.
- libcosim (libcosimpy 0.0.6, `CosimExecution.from_ssp_file`) reads the bindings, the
  default experiment and the OSP step-size annotation, and flies it.

With dist/tailsitter_atmosphere.fmu the systems hold a third component, `atmosphere`, wired
by name to the plant and bound calm: the flight is the same, bit for bit, as without it.
"""

from __future__ import annotations

import math
import pathlib
import zipfile

import numpy as np
import pytest
from lxml import etree

from fmu_util import libcosim_fly_ssp
from tailsim.metrics import CRITERIA, declared_mission, level_window, phase_starts

ROOT = pathlib.Path(__file__).resolve().parent.parent
DIST = ROOT / "dist"
CONTROLLERS = ["tailsitter_lqr", "tailsitter_tsd"]
ATMOSPHERE = "tailsitter_atmosphere"
# The systems hold the atmosphere when its FMU was packaged.
HAS_ATMOSPHERE = (DIST / f"{ATMOSPHERE}.fmu").exists()
COMPONENTS = ["controller", "plant"] + (["atmosphere"] if HAS_ATMOSPHERE else [])
# The SSP binds the controllers' declared mission defaults.
MISSION = declared_mission()
NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
}
LEVEL_END = phase_starts(MISSION)[3]  # t_vertical_1 + t_transition_1 + t_level


def ssp_path(controller: str) -> pathlib.Path:
    path = DIST / f"{controller}.ssp"
    assert path.exists(), f"{path} missing: run `cargo xtask dist` (or `cargo xtask ssp`) first"
    return path


def ssd_root(controller: str):
    with zipfile.ZipFile(ssp_path(controller)) as z:
        return etree.fromstring(z.read("SystemStructure.ssd"))


def model_description(fmu_bytes: bytes):
    import io

    with zipfile.ZipFile(io.BytesIO(fmu_bytes)) as z:
        return etree.fromstring(z.read("modelDescription.xml"))


def variables(md) -> dict[str, tuple[str, str]]:
    """name -> (causality, type element)."""
    out = {}
    for sv in md.iterfind("ModelVariables/ScalarVariable"):
        out[sv.get("name")] = (sv.get("causality", "local"), sv[0].tag)
    return out


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_archive_holds_the_packaged_fmus(controller):
    """resources/*.fmu are byte-identical to dist/*.fmu (else the SSP is stale: `cargo xtask ssp`)."""
    with zipfile.ZipFile(ssp_path(controller)) as z:
        names = set(z.namelist())
        fmus = ["tailsitter_plant", controller] + ([ATMOSPHERE] if HAS_ATMOSPHERE else [])
        assert names == {"SystemStructure.ssd"} | {f"resources/{f}.fmu" for f in fmus}
        for fmu in fmus:
            assert z.read(f"resources/{fmu}.fmu") == (DIST / f"{fmu}.fmu").read_bytes(), (
                f"{controller}.ssp holds a stale {fmu}.fmu: run `cargo xtask ssp`"
            )


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_ssd_passes_fmpy_schema_and_wires_by_name(controller):
    from fmpy.ssp.ssd import read_ssd, validate_tree

    ssd = read_ssd(str(ssp_path(controller)), validate=True)  # raises on schema errors
    comps = {c.name: c for c in ssd.system.elements}
    assert set(comps) == set(COMPONENTS)
    assert comps["plant"].source == "resources/tailsitter_plant.fmu"
    assert comps["controller"].source == f"resources/{controller}.fmu"

    with zipfile.ZipFile(ssp_path(controller)) as z:
        plant_vars = variables(model_description(z.read("resources/tailsitter_plant.fmu")))
        ctrl_vars = variables(model_description(z.read(f"resources/{controller}.fmu")))
        atm_vars = variables(model_description(z.read(f"resources/{ATMOSPHERE}.fmu"))) if HAS_ATMOSPHERE else {}
    of = {"plant": plant_vars, "controller": ctrl_vars, "atmosphere": atm_vars}
    # Every connection joins equal names: plant output -> controller input, controller output -> plant input,
    # and with the atmosphere plant output -> atmosphere input, atmosphere output -> plant input.
    pairs = {("plant", "controller"), ("controller", "plant"), ("plant", "atmosphere"), ("atmosphere", "plant")}
    wired = set()
    for c in ssd.system.connections:
        assert c.startConnector == c.endConnector
        assert (c.startElement, c.endElement) in pairs
        src, dst = of[c.startElement], of[c.endElement]
        assert src[c.startConnector][0] == "output" and dst[c.endConnector][0] == "input"
        assert src[c.startConnector][1] == dst[c.endConnector][1]
        wired.add((c.endElement, c.endConnector))
    expected = {("controller", n) for n, (caus, _) in ctrl_vars.items() if caus == "input" and n in plant_vars}
    expected |= {("plant", n) for n, (caus, _) in ctrl_vars.items() if caus == "output" and n in plant_vars}
    if HAS_ATMOSPHERE:
        expected |= {("atmosphere", n) for n, (caus, _) in atm_vars.items() if caus == "input"}
        expected |= {("plant", n) for n in ("wind_n", "wind_e", "wind_d")}
        assert {n for n, (caus, _) in atm_vars.items() if caus == "input"} <= set(plant_vars)
    assert wired == expected
    assert {n for n, (caus, _) in plant_vars.items() if caus == "input" and n.endswith("_cmd")} <= {
        n for e, n in wired if e == "plant"
    }
    # Connector kinds and types match the FMUs (SSP 1.0: the kind must match the causality).
    for comp, fmu_vars in ((c, of[c]) for c in COMPONENTS):
        for conn in ssd_root(controller).iterfind(f".//ssd:Component[@name='{comp}']/ssd:Connectors/ssd:Connector", NS):
            caus, kind = fmu_vars[conn.get("name")]
            assert conn.get("kind") == caus
            assert etree.QName(conn[0]).localname == kind
    # Inline parameter sets are valid SSV too.
    for ps in ssd_root(controller).iterfind(".//ssd:ParameterValues/ssv:ParameterSet", NS):
        validate_tree(etree.fromstring(etree.tostring(ps)), "SystemStructureParameterValues.xsd")


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_ssd_binds_the_mission_and_default_experiment(controller):
    from fmpy.ssp.ssd import read_ssd

    ssd = read_ssd(str(ssp_path(controller)))
    comps = {c.name: c for c in ssd.system.elements}
    # One binding, one set per component (OMSimulator applies only a component's last inline
    # binding, libcosim only its first): the mission, then the design model.
    sets = {ps.name: ps for b in comps["controller"].parameterBindings for ps in b.parameterValues}
    assert len(comps["controller"].parameterBindings) == 1 and set(sets) == {"controller"}
    bound = [p.name for p in sets["controller"].parameters]
    assert bound[: len(MISSION)] == list(MISSION)
    assert {p.name: float(p.value) for p in sets["controller"].parameters if p.name in MISSION} == MISSION
    plant = {
        p.name: p.value for b in comps["plant"].parameterBindings for ps in b.parameterValues for p in ps.parameters
    }
    assert plant == {"initial_condition": "0", "initial_speed": "3.0"}
    root = ssd_root(controller)
    exp = root.find("ssd:DefaultExperiment", NS)
    assert float(exp.get("startTime")) == 0.0 and float(exp.get("stopTime")) == 35.0
    osp = "ssd:Annotations/ssc:Annotation[@type='com.opensimulationplatform']"
    algo = exp.find(f"{osp}/osp:Algorithm/osp:FixedStepAlgorithm", NS)
    assert float(algo.get("baseStepSize")) == 0.02


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_design_model_is_bound_to_the_plants_declared_airframe(controller):
    """The controller's design model (its `design_airframe` parameters, the plant's names) is
    bound on the controller, after the mission, to the plant FMU's declared start values — every one of
    them — and is not connected to the plant's parameters: a parameter set that changes the
    plant's airframe leaves the controller designing on the nominal aircraft (the honest
    default: a controller never knows the aircraft it flies) unless it changes the
    controller's values too."""
    from fmpy.ssp.ssd import read_ssd

    ssd = read_ssd(str(ssp_path(controller)))
    comps = {c.name: c for c in ssd.system.elements}
    sets = {ps.name: ps for b in comps["controller"].parameterBindings for ps in b.parameterValues}
    design = {p.name: float(p.value) for p in sets["controller"].parameters if p.name not in MISSION}
    with zipfile.ZipFile(ssp_path(controller)) as z:
        plant_md = model_description(z.read("resources/tailsitter_plant.fmu"))
        ctrl_md = model_description(z.read(f"resources/{controller}.fmu"))
    ctrl_params = {
        v.get("name") for v in ctrl_md.iterfind("ModelVariables/ScalarVariable") if v.get("causality") == "parameter"
    }
    airframe = {
        v.get("name"): float(v.find("Real").get("start"))
        for v in plant_md.iterfind("ModelVariables/ScalarVariable")
        if v.get("causality") == "parameter" and v.get("name") in ctrl_params and v.find("Real") is not None
    }
    assert len(design) >= 70 and design["mass"] == 9.0
    assert design == airframe  # every design parameter = the plant's declared value
    # ... and the plant's airframe is not bound by the SSD (nothing ties the two together)
    plant_bound = {p.name for b in comps["plant"].parameterBindings for ps in b.parameterValues for p in ps.parameters}
    assert not plant_bound & set(design)
    assert not [c for c in ssd.system.connections if c.startConnector in design or c.endConnector in design]


def test_swapping_the_controller_swaps_one_component():
    """The two SSDs differ only in the controller component and the connections it needs."""
    roots = {c: ssd_root(c) for c in CONTROLLERS}

    def plant_xml(root):
        return etree.tostring(root.find(".//ssd:Component[@name='plant']", NS), method="c14n")

    def rest(root):
        root = etree.fromstring(etree.tostring(root))
        system = root.find("ssd:System", NS)
        for tag in ("ssd:Elements", "ssd:Connections"):
            system.remove(system.find(tag, NS))
        for a in ("name",):
            root.attrib.pop(a)
            system.attrib.pop(a)
        system.attrib.pop("description")
        return etree.tostring(root, method="c14n")

    lqr, tsd = roots["tailsitter_lqr"], roots["tailsitter_tsd"]
    assert plant_xml(lqr) == plant_xml(tsd)
    assert rest(lqr) == rest(tsd)
    for root in (lqr, tsd):
        assert [c.get("name") for c in root.iterfind("ssd:System/ssd:Elements/ssd:Component", NS)] == COMPONENTS


def fmpy_parameter_set(path: pathlib.Path):
    """The SSD's own bindings as the `parameter_set` fmpy's simulate_ssp applies (names system-relative)."""
    from fmpy.ssp.ssd import ParameterSet, read_ssd

    ssd = read_ssd(str(path))
    params = []
    for comp in ssd.system.elements:
        for b in comp.parameterBindings:
            for ps in b.parameterValues:
                for p in ps.parameters:
                    p.name = f"{comp.name}.{p.name}"
                    params.append(p)
    return ParameterSet(name="bindings", parameters=params)


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_fmpy_simulate_ssp_flies_the_default_mission(controller):
    from fmpy.ssp.simulation import simulate_ssp

    path = ssp_path(controller)
    r = simulate_ssp(str(path), stop_time=35.0, step_size=0.02, parameter_set=fmpy_parameter_set(path))
    # fmpy advances time by repeated addition of the step and loops while time < stop:
    # 50 * 35 additions of 0.02 fall short of 35.0, so it may take one extra step.
    assert len(r) in (1750, 1751)
    for name in r.dtype.names:
        assert np.all(np.isfinite(r[name])), f"{name} not finite"
    # Row k holds the values at the end of the step that starts at r["time"][k].
    t_end = r["time"] + 0.02
    theta, airspeed = r["plant.theta"], r["plant.airspeed"]
    window = level_window(t_end, MISSION)
    level_error = np.max(np.abs(airspeed[window] - MISSION["v_level"]))
    final_pitch = abs(math.degrees(theta[-1]) - 90.0)
    print(
        f"\n{controller} under fmpy simulate_ssp: level airspeed error {level_error:.3f} m/s, "
        f"final pitch {final_pitch:.2f} deg from vertical, max pos_error {r['controller.pos_error'].max():.3f} m"
    )
    assert level_error <= CRITERIA["level_airspeed_error_max"]
    assert final_pitch <= CRITERIA["final_pitch_error_max"]
    assert r["controller.phase"][-1] == 4
    assert set(np.unique(r["controller.phase"])) == {0, 1, 2, 3, 4}
    # Controller inputs are recorded too: they are the plant outputs one step later (Jacobi).
    if "controller.theta" in r.dtype.names:
        assert np.array_equal(r["controller.theta"], r["plant.theta"])


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_libcosim_from_ssp_file_flies_the_default_mission(controller):
    """Straight libcosimpy: from_ssp_file takes step size and mission from the SSP."""
    run = libcosim_fly_ssp(ssp_path(controller), len(COMPONENTS))  # 1750 steps of the annotated 0.02 s
    plant, ctrl, pv, cv, last, series = run.plant, run.ctrl, run.pv, run.cv, run.last, run.series
    # The parameter bindings reached the controller.
    assert last.last_real_values(ctrl, [cv[n] for n in MISSION]) == pytest.approx(list(MISSION.values()))
    theta, airspeed = last.last_real_values(plant, [pv["theta"], pv["airspeed"]])
    assert abs(math.degrees(theta) - 90.0) <= CRITERIA["final_pitch_error_max"]
    assert last.last_integer_values(ctrl, [cv["phase"]]) == [4]
    times, _, speeds = series.time_series_real_samples(plant, pv["airspeed"], from_step=1, sample_count=1750)
    t = np.array(times) / 1e9
    v = np.array(speeds)
    window = level_window(t, MISSION)
    assert window.sum() == 250  # 5 s of 0.02 s steps
    assert np.max(np.abs(v[window] - MISSION["v_level"])) <= CRITERIA["level_airspeed_error_max"]
    assert np.all(np.isfinite(v))


def without_atmosphere(path: pathlib.Path, out: pathlib.Path) -> pathlib.Path:
    """A copy of the SSP without the atmosphere component, its connections and its FMU (the
    system as written before the atmosphere existed)."""
    with zipfile.ZipFile(path) as z:
        root = etree.fromstring(z.read("SystemStructure.ssd"))
        system = root.find("ssd:System", NS)
        elements = system.find("ssd:Elements", NS)
        elements.remove(elements.find("ssd:Component[@name='atmosphere']", NS))
        for c in list(system.find("ssd:Connections", NS)):
            if "atmosphere" in (c.get("startElement"), c.get("endElement")):
                system.find("ssd:Connections", NS).remove(c)
        plant = elements.find("ssd:Component[@name='plant']/ssd:Connectors", NS)
        for conn in list(plant):
            if conn.get("name") in ("wind_n", "wind_e", "wind_d"):
                plant.remove(conn)
        with zipfile.ZipFile(out, "w") as o:
            o.writestr("SystemStructure.ssd", etree.tostring(root, xml_declaration=True, encoding="UTF-8"))
            for name in z.namelist():
                if name.startswith("resources/") and ATMOSPHERE not in name:
                    o.writestr(name, z.read(name))
    return out


@pytest.mark.skipif(not HAS_ATMOSPHERE, reason="no atmosphere FMU packaged")
@pytest.mark.parametrize("controller", CONTROLLERS)
def test_calm_atmosphere_leaves_the_flight_unchanged(controller, tmp_path):
    """fmpy simulate_ssp: the system with the atmosphere at its bound (calm) parameters flies
    the same values, bit for bit, as the system without it; a wind set in the atmosphere's
    parameter set reaches the plant's wind inputs."""
    from fmpy.ssp.simulation import simulate_ssp

    path = ssp_path(controller)
    bare = without_atmosphere(path, tmp_path / "bare.ssp")
    with_atm = simulate_ssp(str(path), stop_time=6.0, step_size=0.02, parameter_set=fmpy_parameter_set(path))
    without = simulate_ssp(str(bare), stop_time=6.0, step_size=0.02, parameter_set=fmpy_parameter_set(bare))
    shared = [n for n in without.dtype.names if n != "time"]
    assert len(shared) > 20
    for name in shared:
        assert np.array_equal(with_atm[name], without[name]), name
    assert not np.any(with_atm["plant.wind_n"]) and not np.any(with_atm["atmosphere.wind_e"])
    # 5 m/s from the east, uniform: the plant's wind_e input is -5 m/s (Jacobi: from the second step).
    windy = fmpy_parameter_set(path)
    for p in windy.parameters:
        if p.name == "atmosphere.wind_speed":
            p.value = "5.0"
        if p.name == "atmosphere.wind_from":
            p.value = repr(math.pi / 2)
        if p.name == "atmosphere.wind_profile":
            p.value = "0"
    r = simulate_ssp(str(path), stop_time=1.0, step_size=0.02, parameter_set=windy)
    assert np.allclose(r["plant.wind_e"][1:], -5.0, rtol=0, atol=1e-12)
