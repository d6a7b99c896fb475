"""Set-up of a fresh machine: the libclang check of scripts/setup.sh.

Regression test for the fresh-machine failure: set-up tested for any file named
``libclang*.so`` and so took the base image's ``libclang-cpp.so.14`` (the C++ library,
no C API) for the libclang that fmi-sys' bindgen loads; libclang-dev was never
installed and the build failed on a fresh machine.
"""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
FIND = ROOT / "scripts" / "find-libclang.sh"


def find_libclang(dirs):
    env = dict(os.environ, FIND_LIBCLANG_DIRS=":".join(str(d) for d in dirs))
    return subprocess.run([str(FIND)], env=env, capture_output=True, text=True)


def exports_c_api(path):
    out = subprocess.run(["nm", "-D", "--defined-only", path], capture_output=True, text=True).stdout
    return any(line.split()[-1].split("@")[0] == "clang_createIndex" for line in out.splitlines() if line.split())


def test_a_library_named_like_libclang_without_the_c_api_is_not_taken(tmp_path):
    # Stand-ins named as clang-sys would match them, but without clang_createIndex:
    # the C++ library's name from the base image and a plain libclang.so name.
    libm = next(
        p for p in ("/lib/x86_64-linux-gnu/libm.so.6", "/usr/lib/x86_64-linux-gnu/libm.so.6") if os.path.exists(p)
    )
    shutil.copy(libm, tmp_path / "libclang-cpp.so.14")
    shutil.copy(libm, tmp_path / "libclang.so.1")
    result = find_libclang([tmp_path])
    assert result.returncode == 1, result.stdout
    assert result.stdout == ""


def test_an_empty_directory_has_no_libclang(tmp_path):
    assert find_libclang([tmp_path]).returncode == 1


def test_the_real_cpp_library_is_not_taken(tmp_path):
    cpp = Path("/usr/lib/x86_64-linux-gnu/libclang-cpp.so.14")
    if not cpp.exists():
        pytest.skip("libclang-cpp14 not installed")
    (tmp_path / cpp.name).symlink_to(cpp)
    assert find_libclang([tmp_path]).returncode == 1


def test_a_long_symbol_listing_after_the_match_is_still_found(tmp_path):
    # Regression test (CI failure): the check piped nm into `grep -q` under pipefail, so it
    # failed at random when grep exited at the match while nm was still writing (SIGPIPE).
    # A stand-in nm prints the symbol first and then far more than a pipe holds.
    fake_nm = tmp_path / "fake_nm.sh"
    fake_nm.write_text(
        'echo "0000000000001000 T clang_createIndex@@LLVM_13"\nyes "0000000000002000 T clang_other" | head -c 4000000\n'
    )
    libdir = tmp_path / "lib"
    libdir.mkdir()
    (libdir / "libclang-14.so.1").write_bytes(b"")
    env = dict(os.environ, FIND_LIBCLANG_DIRS=str(libdir), FIND_LIBCLANG_NM=f"bash {fake_nm}")
    result = subprocess.run([str(FIND)], env=env, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == str(libdir / "libclang-14.so.1")


def test_set_up_leaves_a_libclang_that_bindgen_can_load():
    # After scripts/setup.sh (which the test command runs first) the default search
    # finds a library exporting libclang's C API.
    result = subprocess.run([str(FIND)], capture_output=True, text=True)
    assert result.returncode == 0, "scripts/find-libclang.sh found no loadable libclang"
    path = result.stdout.strip()
    assert Path(path).exists()
    assert exports_c_api(path)


def test_set_up_uses_the_loadable_library_check():
    setup = (ROOT / "scripts" / "setup.sh").read_text()
    assert "scripts/find-libclang.sh" in setup
    assert "ldconfig -p 2>/dev/null | grep -q 'libclang" not in setup
