import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "python"))

from fmu_util import Unpacked  # noqa: E402
from tailsim import Fmu  # noqa: E402


@pytest.fixture(scope="session")
def plant(tmp_path_factory) -> Unpacked:
    return Unpacked("tailsitter_plant", tmp_path_factory.mktemp("fmus"))


@pytest.fixture(scope="session")
def fmus(tmp_path_factory) -> dict[str, Fmu]:
    """The three packaged FMUs, extracted once."""
    out = {}
    tmp = tmp_path_factory.mktemp("closed-loop")
    for name in ("tailsitter_plant", "tailsitter_lqr", "tailsitter_tsd"):
        path = ROOT / "dist" / f"{name}.fmu"
        assert path.exists(), f"{path} missing: run `cargo xtask dist` first"
        out[name] = Fmu(path, tmp)
    return out
