import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from fmu_util import Unpacked  # noqa: E402
from tailsim import Fmu, fmilog  # noqa: E402


@pytest.fixture(autouse=True)
def _fmpy_logger_target():
    """fmpy's native logger proxy calls one process-global Python logger, the one registered
    last; `fmpy.simulate_fmu` and a test's `LogRecorder` register loggers that die with them.
    Point the proxy back at the process logger around every test (tailsim.fmilog), so no test
    inherits a dangling target (that segfaulted inside fmi2DoStep once a freed one was called)."""
    fmilog.rearm()
    yield
    fmilog.rearm()


@pytest.fixture(scope="session")
def plant(tmp_path_factory) -> Unpacked:
    return Unpacked("tailsitter_plant", tmp_path_factory.mktemp("fmus"))


class _Fmus(dict):
    """The packaged FMUs by modelIdentifier, each extracted on first use."""

    def __init__(self, tmp: pathlib.Path):
        super().__init__()
        self.tmp = tmp

    def __missing__(self, name: str) -> Fmu:
        path = ROOT / "dist" / f"{name}.fmu"
        assert path.exists(), f"{path} missing: run `cargo xtask dist` first"
        self[name] = Fmu(path, self.tmp)
        return self[name]


@pytest.fixture(scope="session")
def fmus(tmp_path_factory) -> dict[str, Fmu]:
    """The three packaged FMUs (extracted once, on first use)."""
    return _Fmus(tmp_path_factory.mktemp("closed-loop"))


@pytest.fixture(scope="session")
def level_trim_theta(fmus):
    """Pitch of the plant's level trim at the declared v_level (θ = α in level flight)."""
    plant = fmus["tailsitter_plant"]
    s = plant.instantiate("trim")
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    plant.set(s, {"initial_condition": 1, "initial_speed": fmus["tailsitter_lqr"].start("v_level")})
    s.exitInitializationMode()
    (theta,) = s.getReal([plant.variables["theta"].valueReference])
    s.terminate()
    s.freeInstance()
    return theta
