"""The aarch64 Linux FMUs (`dist/aarch64-linux/<id>.fmu`) fly the default mission as the
x86-64 ones do.

A small C master (tests/c-master/master.c: plant + controller, Gauss-Seidel, the timing of
tailsim's ClosedLoop) is built twice from the same source: for the host with `cc` and for
aarch64 with Debian's cross gcc (`aarch64-linux-gnu-gcc`). The host build flies the x86-64
libraries of `dist/`; the aarch64 build flies the aarch64 libraries under qemu-user
(`qemu-aarch64 -L /usr/aarch64-linux-gnu`, Debian's aarch64 glibc). Both write every plant
output at every communication point with 17 significant digits; the trajectories must
agree to POSITION_TOL. The host run must also reproduce tailsim's own master (fmpy) on the
same x86-64 FMUs, so the C master is known to fly the mission the project's masters fly.
scripts/setup.sh installs the cross gcc, its glibc and qemu-user.

Figures: .venv/bin/python -m pytest tests/test_aarch64.py -s
"""

from __future__ import annotations

import json
import os
import pathlib
import shutil
import subprocess
import zipfile

import numpy as np
import pytest

from tailsim import ClosedLoop
from tailsim.masters.closed_loop import commands_driven
from tailsim.masters.system import default_step, default_stop, wire

ROOT = pathlib.Path(__file__).resolve().parent.parent
DIST = ROOT / "dist"
MASTER = ROOT / "tests" / "c-master" / "master.c"
PLANT = "tailsitter_plant"
CONTROLLERS = ["tailsitter_lqr", "tailsitter_tsd"]
#: Largest position difference (m) between the x86-64 and the aarch64 flights. Both run the
#: same Rust code compiled for each instruction set; libm's transcendental functions and the
#: compilers' use of fused multiply-add on aarch64 may round the last bit differently.
POSITION_TOL = 1e-9
#: The host C master against tailsim's fmpy master: the same libraries and call sequence.
MASTER_TOL = 1e-9
POSITIONS = ["pos_n", "pos_e", "pos_d"]
QEMU = ["qemu-aarch64", "-L", "/usr/aarch64-linux-gnu"]


def fmi2_headers() -> pathlib.Path:
    """The FMI 2.0 headers shipped with the fmi-sys crate the workspace builds with."""
    cargo = os.environ.get("CARGO", "cargo")
    meta = subprocess.run(
        [cargo, "metadata", "--format-version", "1", "--locked", "--offline"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    for p in json.loads(meta.stdout)["packages"]:
        if p["name"] == "fmi-sys":
            headers = pathlib.Path(p["manifest_path"]).parent / "fmi-standard2" / "headers"
            assert (headers / "fmi2Functions.h").exists(), headers
            return headers
    raise AssertionError("fmi-sys is not a dependency of the workspace")


def tool(name: str) -> str:
    path = shutil.which(name)
    assert path, f"{name} missing: run scripts/setup.sh (Debian gcc-aarch64-linux-gnu, qemu-user)"
    return path


def build_masters(source: pathlib.Path, headers: pathlib.Path, tmp: pathlib.Path) -> dict[str, list[str]]:
    """A C master built for the host and for aarch64: the command prefix of each."""
    out = {}
    for arch, cc in [("x86_64", shutil.which("cc") or "gcc"), ("aarch64", tool("aarch64-linux-gnu-gcc"))]:
        exe = tmp / f"{source.stem}-{arch}"
        flags = ["-std=c11", "-D_POSIX_C_SOURCE=200809L", "-O2", "-Wall", "-Wextra", "-Werror"]
        subprocess.run([cc, *flags, f"-I{headers}", str(source), "-o", str(exe), "-ldl"], check=True)
        out[arch] = [*(([tool(QEMU[0]), *QEMU[1:]]) if arch == "aarch64" else []), str(exe)]
    return out


@pytest.fixture(scope="module")
def masters(tmp_path_factory) -> dict[str, list[str]]:
    """tests/c-master/master.c built for the host and for aarch64."""
    return build_masters(MASTER, fmi2_headers(), tmp_path_factory.mktemp("c-master"))


def library(folder: pathlib.Path, model: str, tmp: pathlib.Path) -> pathlib.Path:
    fmu = folder / f"{model}.fmu"
    assert fmu.exists(), f"{fmu} missing: run `cargo xtask dist`"
    with zipfile.ZipFile(fmu) as z:
        z.extract(f"binaries/linux64/{model}.so", tmp / folder.name)
    return tmp / folder.name / "binaries" / "linux64" / f"{model}.so"


def fly(master: list[str], folder: pathlib.Path, controller: str, fmus, tmp: pathlib.Path):
    """Fly the default mission with the C master: (time, {plant output: values})."""
    plant, ctrl = fmus[PLANT], fmus[controller]
    vr = lambda f, n: f.variables[n].valueReference  # noqa: E731
    record = [n for n in plant.names("output") if plant.variables[n].type == "Real"]
    links = [wire(plant, ctrl), commands_driven(plant, ctrl)]
    for names, (src, dst) in zip(links, [(plant, ctrl), (ctrl, plant)], strict=True):
        typed = {src.variables[n].type for n in names} | {dst.variables[n].type for n in names}
        assert typed == {"Real"}, f"the C master links Reals only; {names} are {typed}"
    args = [
        str(library(folder, PLANT, tmp)),
        plant.md.guid,
        str(library(folder, controller, tmp)),
        ctrl.md.guid,
        repr(default_step(ctrl, {}, None)),
        repr(default_stop(ctrl, None)),
        ",".join(f"{vr(plant, n)}:{vr(ctrl, n)}" for n in links[0]),
        ",".join(f"{vr(ctrl, n)}:{vr(plant, n)}" for n in links[1]),
        ",".join(str(vr(plant, n)) for n in record),
    ]
    run = subprocess.run([*master, *args], capture_output=True, text=True)
    assert run.returncode == 0, f"{master[-1]} exited {run.returncode}: {run.stderr[-2000:]}"
    data = np.loadtxt(run.stdout.splitlines(), delimiter=",", ndmin=2)
    return data[:, 0], {n: data[:, 1 + i] for i, n in enumerate(record)}


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_aarch64_flies_the_default_mission_as_x86_64(masters, fmus, controller, tmp_path):
    t_x86, x86 = fly(masters["x86_64"], DIST, controller, fmus, tmp_path)
    t_arm, arm = fly(masters["aarch64"], DIST / "aarch64-linux", controller, fmus, tmp_path)
    assert np.array_equal(t_x86, t_arm)
    assert t_x86[-1] == pytest.approx(default_stop(fmus[controller], None))
    # A real flight, not a plant at rest: both fly hundreds of metres.
    travel = max(np.ptp(x86[p]) for p in POSITIONS)
    assert travel > 50.0, f"the mission moved the plant only {travel} m"
    for name, values in x86.items():
        assert np.isfinite(values).all() and np.isfinite(arm[name]).all(), name
    dpos = max(np.max(np.abs(x86[p] - arm[p])) for p in POSITIONS)
    worst = max(x86, key=lambda n: np.max(np.abs(x86[n] - arm[n])))
    print(
        f"\n{controller}: {len(t_x86)} points, largest position difference aarch64 - x86_64 {dpos:.3g} m; "
        f"largest of any output: {worst} {np.max(np.abs(x86[worst] - arm[worst])):.3g}"
    )
    assert dpos <= POSITION_TOL


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_c_master_flies_as_tailsim(masters, fmus, controller, tmp_path):
    """The host C master reproduces tailsim's ClosedLoop on the same x86-64 FMUs."""
    t, c = fly(masters["x86_64"], DIST, controller, fmus, tmp_path)
    reference = ClosedLoop(fmus[PLANT], fmus[controller]).run()
    assert np.array_equal(t, reference.signals["time"])
    dpos = max(np.max(np.abs(c[p] - reference.signals[p])) for p in POSITIONS)
    print(f"\n{controller}: C master vs tailsim (fmpy), largest position difference {dpos:.3g} m")
    assert dpos <= MASTER_TOL
