"""FMI 2.0 conformance of every packaged FMU: two independent static
checkers (fmpy's validator and fmu-manipulation-toolbox's `fmutool -check`),
packaging (binary, documentation/index.html), model metadata, and the GUID
check at instantiation (a wrong GUID gives NULL plus a logged reason, never a
crash). All three FMUs are required; TAILSITTER_FMUS=a,b narrows the set while
some are not built yet."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from fmu_util import LogRecorder, fmu_path
from tailsim import declarations

ALL = list(declarations.MODELS)
MODELS = [m.strip() for m in os.environ.get("TAILSITTER_FMUS", "").split(",") if m.strip()] or ALL
FMUTOOL = Path(sys.executable).with_name("fmutool")


@pytest.fixture(scope="module", params=MODELS)
def model(request):
    return request.param


def test_fmpy_validate_reports_nothing(model):
    assert validate_fmu(str(fmu_path(model))) == []


def test_fmutool_check_passes(model):
    proc = subprocess.run(
        [str(FMUTOOL), "-input", str(fmu_path(model)), "-check"], capture_output=True, text=True, timeout=120
    )
    out = proc.stdout + proc.stderr
    assert proc.returncode == 0, f"fmutool -check exit code {proc.returncode} (7 = errors):\n{out}"
    assert "compliant with FMI-2.0" in out, out
    assert "No semantic error" in out, out
    assert not re.search(r"^\s*(ERROR|WARNING)\b", out, re.M), out


def test_archive_holds_binary_and_documentation(model):
    with zipfile.ZipFile(fmu_path(model)) as z:
        names = set(z.namelist())
        assert {
            "modelDescription.xml",
            f"binaries/linux64/{model}.so",
            f"binaries/win64/{model}.dll",
            "documentation/index.html",
        } <= names
        doc = z.read("documentation/index.html").decode()
    md = read_model_description(str(fmu_path(model)))
    assert doc.lstrip().lower().startswith("<!doctype html>")
    assert len(doc) > 2000, "documentation/index.html is a stub"
    assert md.guid in doc, "the documentation names the GUID of the interface it documents"
    assert "Platforms and interfaces" in doc and "binaries/win64/" in doc and "binaries/linux64/" in doc
    assert ("Model Exchange" in doc) == (md.modelExchange is not None)
    for v in md.modelVariables:
        assert f"<code>{v.name}</code>" in doc, f"{v.name} undocumented"


def test_metadata_present(model):
    md = read_model_description(str(fmu_path(model)))
    assert md.fmiVersion == "2.0"
    assert md.coSimulation is not None and md.coSimulation.modelIdentifier == model
    if model == "tailsitter_plant":
        # One archive, both interfaces, one binary (as the Reference FMUs ship).
        me = md.modelExchange
        assert me is not None and me.modelIdentifier == model
        assert md.numberOfEventIndicators == 0 and len(md.derivatives) == 20
        assert all(d.variable.derivative.nominal for d in md.derivatives)
    else:
        assert md.modelExchange is None
    for attr in ("author", "version", "generationTool", "description", "guid"):
        assert (getattr(md, attr) or "").strip(), f"{attr} missing"
    assert re.fullmatch(r"\{[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}\}", md.guid), md.guid
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    assert md.defaultExperiment is not None and md.defaultExperiment.stepSize


def test_guids_are_distinct_per_model():
    guids = {m: read_model_description(str(fmu_path(m))).guid for m in MODELS}
    assert len(set(guids.values())) == len(guids), guids


def _slave(model, tmp_path, guid):
    md = read_model_description(str(fmu_path(model)))
    unzipped = extract(str(fmu_path(model)), unzipdir=str(tmp_path / model))
    return FMU2Slave(guid=guid, unzipDirectory=unzipped, modelIdentifier=model, instanceName="guidcheck"), md


def test_wrong_guid_is_refused_at_instantiate(model, tmp_path):
    md = read_model_description(str(fmu_path(model)))
    wrong = md.guid[:-5] + ("0000}" if not md.guid.endswith("0000}") else "1111}")
    slave, _ = _slave(model, tmp_path, wrong)
    log = LogRecorder()
    with pytest.raises(Exception, match="(?i)instantiate"):
        slave.instantiate(callbacks=log.callbacks)
    assert any("GUID" in m for m in log.errors()), log.messages
    # The process is intact and the right GUID works in the same library.
    good, _ = _slave(model, tmp_path / "good", md.guid)
    good.instantiate()
    good.setupExperiment(startTime=0.0)
    good.enterInitializationMode()
    good.exitInitializationMode()
    good.doStep(0.0, float(md.defaultExperiment.stepSize))
    good.terminate()
    good.freeInstance()


def test_model_structure_states_its_dependencies(model):
    """Every Unknown of ModelStructure carries `dependencies` (none = "depends on every
    known", which makes an importer solve an algebraic loop over all the connections
    at initialisation), naming only knowns of its list: inputs and continuous states
    for Outputs and Derivatives (FMI 2.0 §2.2.8), inputs and variables with
    initial="exact" for InitialUnknowns. Nothing reads a command input directly except
    the plant's actuator derivatives; a sampled unit's initial outputs read its inputs."""
    md = read_model_description(str(fmu_path(model)), validate=True)
    inputs = {v for v in md.modelVariables if v.causality == "input"}
    states = {d.variable.derivative for d in md.derivatives}
    exact = {v for v in md.modelVariables if v.initial == "exact" or (v.causality == "parameter" and v.initial is None)}
    lists = [("Outputs", md.outputs, inputs | states), ("Derivatives", md.derivatives, inputs | states)]
    lists.append(("InitialUnknowns", md.initialUnknowns, inputs | exact))
    for name, unknowns, knowns in lists:
        for u in unknowns:
            assert u.dependencies is not None, f"{name}/{u.variable.name}: no dependencies"
            stray = [v.name for v in u.dependencies if v not in knowns]
            assert not stray, f"{name}/{u.variable.name} depends on {stray}, not knowns of the list"
    commands = {v for v in inputs if v.name.endswith("_cmd")}
    for u in md.outputs:
        assert not (set(u.dependencies) & commands), f"output {u.variable.name} reads a command directly"
    if model == "tailsitter_plant":
        for u in md.initialUnknowns:
            read = {v.name for v in set(u.dependencies) & commands}
            assert read <= {u.variable.name.removeprefix("der_") + "_cmd"}, (u.variable.name, read)
    else:
        assert not any(set(u.dependencies) & inputs for u in md.outputs)
        assert all(set(u.dependencies) & inputs for u in md.initialUnknowns)
