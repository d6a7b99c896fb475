"""The Linux binaries of every packaged FMU load on glibc 2.17 and later.

`cargo xtask dist` links them against the symbol versions of glibc 2.17 (the manylinux2014
baseline: RHEL/CentOS 7 and every later x86-64 or aarch64 distribution). A library that
needs a newer `GLIBC_x.y` (a symbol re-versioned since, such as `hypot@GLIBC_2.35` or
`fmod@GLIBC_2.38`) fails to load there with "version `GLIBC_x.y' not found". This reads
the version needs (`.gnu.version_r`, `readelf -V`) of every `binaries/linux64/*.so` in
`dist/*.fmu` (x86-64) and `dist/aarch64-linux/*.fmu` (aarch64), and checks each archive
holds the architecture it says.
"""

from __future__ import annotations

import pathlib
import re
import shutil
import subprocess
import zipfile

import pytest

from tailsim import declarations

ROOT = pathlib.Path(__file__).resolve().parent.parent
DIST = ROOT / "dist"
#: The newest glibc symbol version a packaged library may need.
GLIBC_MAX = (2, 17)
#: ELF e_machine of each archive folder's libraries.
MACHINES = {DIST: 62, DIST / "aarch64-linux": 183}  # EM_X86_64, EM_AARCH64
#: Every FMU shared library may need only these (no libgcc_s, libstdc++, newer libs).
ALLOWED_NEEDED = {"libc.so.6", "libm.so.6", "libdl.so.2", "libpthread.so.0", "ld-linux-x86-64.so.2"}
CASES = [(folder, model) for folder in MACHINES for model in declarations.VARIABLES]


def needed_versions(library: pathlib.Path) -> dict[str, set[str]]:
    """`readelf -V`'s version needs: file name → versions (e.g. libc.so.6 → {GLIBC_2.17})."""
    readelf = shutil.which("readelf")
    assert readelf, "readelf (binutils) missing"
    text = subprocess.run([readelf, "-V", "-W", str(library)], capture_output=True, text=True, check=True).stdout
    section = text.split(".gnu.version_r", 1)
    assert len(section) == 2, f"{library.name}: no .gnu.version_r section"
    needs: dict[str, set[str]] = {}
    current = None
    for line in section[1].splitlines():
        if m := re.search(r"File: (\S+)", line):
            current = needs.setdefault(m.group(1), set())
        elif (m := re.search(r"Name: (\S+)", line)) and current is not None:
            current.add(m.group(1))
    return needs


def dynamic_needed(library: pathlib.Path) -> set[str]:
    text = subprocess.run(["readelf", "-d", "-W", str(library)], capture_output=True, text=True, check=True).stdout
    return set(re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", text))


def glibc_version(name: str) -> tuple[int, ...]:
    return tuple(int(x) for x in name.removeprefix("GLIBC_").split("."))


@pytest.fixture(scope="module")
def libraries(tmp_path_factory) -> dict[tuple[pathlib.Path, str], pathlib.Path]:
    """Every packaged Linux library, extracted: (archive folder, model) → path."""
    tmp = tmp_path_factory.mktemp("glibc")
    out = {}
    for folder, model in CASES:
        fmu = folder / f"{model}.fmu"
        assert fmu.exists(), f"{fmu} missing: run `cargo xtask dist`"
        target = tmp / folder.name / model
        with zipfile.ZipFile(fmu) as z:
            z.extract(f"binaries/linux64/{model}.so", target)
        out[(folder, model)] = target / "binaries" / "linux64" / f"{model}.so"
    return out


@pytest.mark.parametrize(("folder", "model"), CASES, ids=[f"{f.name}-{m}" for f, m in CASES])
def test_needs_at_most_glibc_2_17(libraries, folder, model):
    library = libraries[(folder, model)]
    machine = int.from_bytes(library.read_bytes()[18:20], "little")
    assert machine == MACHINES[folder], f"{library}: e_machine {machine}, expected {MACHINES[folder]}"
    needs = needed_versions(library)
    glibc = sorted({v for versions in needs.values() for v in versions if v.startswith("GLIBC_")}, key=glibc_version)
    # Every FMU calls into libc (malloc, memcpy, pthread keys): an empty list would mean
    # the parsing found nothing, not a library free of glibc.
    assert "libc.so.6" in needs and glibc, f"{library.name}: no GLIBC version needs found: {needs}"
    too_new = [v for v in glibc if glibc_version(v) > GLIBC_MAX]
    assert not too_new, f"{folder.name}/{model}: needs {too_new} (> GLIBC_2.17); all: {glibc}"
    extra = dynamic_needed(library) - ALLOWED_NEEDED - {"ld-linux-aarch64.so.1"}
    assert not extra, f"{folder.name}/{model}: needs libraries beyond glibc: {sorted(extra)}"
    print(f"{folder.relative_to(ROOT)}/{model}.fmu: highest {glibc[-1]} ({', '.join(glibc)})")


def test_readelf_parsing_sees_a_newer_glibc(tmp_path):
    """The check can fail: a library linked here against the system glibc (2.36 on Debian
    12) with a symbol versioned after 2.17 is reported as too new."""
    cc = shutil.which("cc") or shutil.which("gcc")
    assert cc, "a C compiler (gcc) is needed"
    src = tmp_path / "new.c"
    # getrandom appeared in glibc 2.25.
    src.write_text("#include <sys/random.h>\nlong f(void *b) { return getrandom(b, 8, 0); }\n")
    lib = tmp_path / "libnew.so"
    subprocess.run([cc, "-shared", "-fPIC", "-o", str(lib), str(src)], check=True)
    glibc = {v for vs in needed_versions(lib).values() for v in vs if v.startswith("GLIBC_")}
    assert any(glibc_version(v) > GLIBC_MAX for v in glibc), glibc
