"""The declarations module (tailsim.declarations, loading the data `declarations.json`
that `cargo xtask regen` writes): it agrees with the packaged FMUs, and no module of
python/tailsim restates what it carries (lists of phase-duration, phase or command
names, the command limits, the mission presets) by hand. The Rust test
`python_declarations_data_matches_generated` (modelDescription/tests/declarations.rs)
checks the committed data is the generator's."""

import ast
import math

import pytest

from fmu_util import ROOT
from tailsim import declarations as D

PACKAGE = ROOT / "python" / "tailsim"
MODULES = sorted(PACKAGE.rglob("*.py"))


@pytest.mark.parametrize("identifier", D.MODELS)
def test_declarations_match_the_packaged_fmu(fmus, identifier):
    fmu = fmus[identifier]
    assert list(D.VARIABLES[identifier]) == [v.name for v in fmu.md.modelVariables]
    for v in fmu.md.modelVariables:
        d = D.VARIABLES[identifier][v.name]
        assert (d.type, d.causality, d.variability, d.unit) == (v.type, v.causality, v.variability, v.unit), v.name
        if v.start is not None:
            assert str(d.start).lower() == str(v.start).lower() or float(d.start) == float(v.start), v.name
    e = fmu.md.defaultExperiment
    assert D.DEFAULT_EXPERIMENTS[identifier] == (float(e.startTime), float(e.stopTime), float(e.stepSize))


def test_commands_limits_phases_and_presets(fmus):
    plant = fmus["tailsitter_plant"]
    assert D.THRUST_LIMITS == (plant.start("thrust_min"), plant.start("thrust_max"))
    assert D.DEFLECTION_LIMIT == plant.start("deflection_limit")
    assert set(D.COMMANDS) == {n for n in plant.names("input") if n.endswith("_cmd")}
    assert D.COMMANDS[0] == "thrust_cmd"
    assert len(D.PHASES) == len(D.PHASE_DURATIONS) == 5
    assert [D.PHASE_NAMES[k] for k in range(5)] == list(D.PHASES)
    lqr = fmus["tailsitter_lqr"]
    assert D.MISSION_DEFAULTS == lqr.starts(list(D.MISSION))
    for name, values in D.PRESETS.items():
        m = D.mission(name)
        for k, (lo, hi) in D.MISSION_RANGES.items():
            assert lo <= m[k] <= hi, (name, k)
        assert set(values) <= set(D.MISSION)
    # The fast mission is the thesis's (App. E.1: the TSD flies T1 = 3 s, T2 = 4 s).
    assert D.stop_time(D.mission("fast")) == 5 + 3 + 10 + 4 + 5
    with pytest.raises(KeyError):
        D.mission(t_nothing=1.0)


def _strings(node: ast.AST) -> list[str]:
    items = node.keys if isinstance(node, ast.Dict) else getattr(node, "elts", [])
    return [x.value for x in items if isinstance(x, ast.Constant) and isinstance(x.value, str)]


def _hand_copies(path) -> list[str]:
    tree = ast.parse(path.read_text(), str(path))
    found = []
    lists = {
        "phase-duration names": set(D.PHASE_DURATIONS),
        "phase names": set(D.PHASES),
        "command names": set(D.COMMANDS),
    }
    for name, values in D.PRESETS.items():
        if len(values) >= 3:
            lists[f"preset {name!r}"] = set(values)
    for node in ast.walk(tree):
        where = f"{path.relative_to(ROOT) if path.is_relative_to(ROOT) else path}:{getattr(node, 'lineno', '?')}"
        if isinstance(node, ast.List | ast.Tuple | ast.Set | ast.Dict):
            strings = set(_strings(node))
            for what, names in lists.items():
                if len(strings & names) >= 3:
                    found.append(f"{where}: a literal list of {what}")
        elif isinstance(node, ast.Constant) and isinstance(node.value, float):
            if node.value == D.THRUST_LIMITS[1]:
                found.append(f"{where}: the thrust limit {node.value}")
            if math.isclose(node.value, D.DEFLECTION_LIMIT, rel_tol=1e-6):
                found.append(f"{where}: the deflection limit {node.value}")
        elif isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", "")) == "radians":
            arg = node.args[0] if node.args else None
            if isinstance(arg, ast.Constant) and math.isclose(math.radians(arg.value), D.DEFLECTION_LIMIT):
                found.append(f"{where}: the deflection limit as radians({arg.value})")
    return found


def test_no_module_restates_the_declarations():
    assert MODULES, PACKAGE
    found = [f for p in MODULES for f in _hand_copies(p)]
    assert not found, "import these from tailsim.declarations instead:\n" + "\n".join(found)


def test_the_guard_sees_a_hand_copy(tmp_path):
    bad = tmp_path / "hand_copy.py"
    bad.write_text(
        'DURATIONS = ["t_vertical_1", "t_transition_1", "t_level", "t_transition_2", "t_vertical_2"]\n'
        "THRUST = (0.0, 150.0)\n"
        "import math\nLIMIT = math.radians(25)\n"
    )
    found = _hand_copies(bad)
    for what in ("phase-duration names", "thrust limit", "deflection limit"):
        assert any(what in f for f in found), (what, found)


def test_the_product_names_no_internal_issue():
    """Regression: variable descriptions (and so every modelDescription.xml and its docs) and a
    report module's docstring once cited internal issue numbers; the product carries results,
    the history stays in git."""
    import re

    pattern = re.compile(r"\bissues?\s*#?\d+", re.IGNORECASE)
    files = [
        *MODULES,
        PACKAGE / "declarations.json",
        *sorted((ROOT / "modelDescription").glob("*.json")),
        *sorted((ROOT / "modelDescription" / "fragments").glob("*.json")),
        *sorted((ROOT / "modelDescription" / "generated").glob("*.md")),
        *sorted((ROOT / "modelDescription" / "generated").glob("*.xml")),
        ROOT / "README.md",
    ]
    found = [
        f"{f.relative_to(ROOT)}:{n}: {m.group(0)}"
        for f in files
        for n, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1)
        if (m := pattern.search(line))
    ]
    assert not found, "\n".join(found)
