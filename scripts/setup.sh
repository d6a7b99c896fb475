#!/usr/bin/env bash
# Set up a fresh machine: system packages (libclang for fmi-sys' bindgen; MinGW-w64
# and Wine for the win64 binaries; Debian's aarch64 cross gcc, glibc and qemu-user for
# the aarch64 tests), the Rust targets x86_64-pc-windows-gnu and aarch64-unknown-linux-gnu,
# the Rust crates (fetched by cargo on first build), the pinned Python venv (with Zig and
# cargo-zigbuild, which link the Linux binaries against glibc 2.17) and the tailsim package
# (pyproject.toml; installed editable into the venv, so no PYTHONPATH is needed).
# Idempotent and non-interactive: re-running only checks.
set -euo pipefail
cd "$(dirname "$0")/.."

# fmi-sys runs bindgen, which loads libclang's C API at build time. Test for the library
# bindgen really loads (scripts/find-libclang.sh), not for any file named libclang*: the
# base image ships libclang-cpp14, which matches such a name but has no C API.
SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"
apt_updated=""
apt_install() {
    [ -n "$apt_updated" ] || { $SUDO apt-get update -qq; apt_updated=1; }
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$@" >/dev/null
}

if ! scripts/find-libclang.sh >/dev/null; then
    echo "== installing libclang-dev (needed by fmi-sys' bindgen)"
    apt_install libclang-dev
    scripts/find-libclang.sh >/dev/null || { echo "setup: libclang-dev installed but no loadable libclang found" >&2; exit 1; }
fi

# win64 binaries (binaries/win64/<id>.dll): rustc's x86_64-pc-windows-gnu target links
# with MinGW-w64's gcc and import libraries; tests run the DLLs under Wine (wine64).
if ! command -v x86_64-w64-mingw32-gcc >/dev/null || ! command -v x86_64-w64-mingw32-objdump >/dev/null; then
    echo "== installing gcc-mingw-w64-x86-64 (links the win64 DLLs)"
    apt_install gcc-mingw-w64-x86-64
fi
# aarch64-linux binaries: `cargo xtask dist` links the FMU libraries with cargo-zigbuild
# (Zig, glibc 2.17; both from the venv below). The tests link with Debian's cross gcc and
# run under qemu-user with Debian's aarch64 glibc in /usr/aarch64-linux-gnu
# (.cargo/config.toml; tests/test_aarch64.py).
installed_targets=$(rustup target list --installed)
for target in x86_64-pc-windows-gnu aarch64-unknown-linux-gnu; do
    if ! grep -qx "$target" <<<"$installed_targets"; then
        echo "== adding the Rust target $target"
        rustup target add "$target"
    fi
done
if ! command -v aarch64-linux-gnu-gcc >/dev/null || [ ! -e /usr/aarch64-linux-gnu/lib/libc.so.6 ] \
    || ! command -v qemu-aarch64 >/dev/null; then
    echo "== installing gcc-aarch64-linux-gnu, libc6-dev-arm64-cross, qemu-user (aarch64 tests)"
    apt_install gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user
fi
if [ ! -x /usr/lib/wine/wine64 ] && ! command -v wine64 >/dev/null; then
    echo "== installing wine64 (runs the win64 DLLs in the tests, through fmpy's remoting)"
    apt_install wine64
fi
# Debian installs the loader as /usr/lib/wine/wine64, outside PATH; fmpy looks for `wine64`.
if ! command -v wine64 >/dev/null; then
    $SUDO ln -sf /usr/lib/wine/wine64 /usr/local/bin/wine64
fi

# The browser test of the reports drives Debian's Chromium (never a browser download).
if [ ! -x /usr/bin/chromium ]; then
    echo "== installing chromium (the reports' browser test)"
    apt_install chromium
fi

if [ ! -x .venv/bin/python ] || ! cmp -s tests/requirements.txt .venv/requirements.installed; then
    echo "== creating Python venv .venv (pinned: tests/requirements.txt)"
    python3 -m venv .venv
    .venv/bin/pip install -q --upgrade pip
    .venv/bin/pip install -q -r tests/requirements.txt
    cp tests/requirements.txt .venv/requirements.installed
fi
# The tailsim package (python/tailsim), editable: the venv imports the checkout's sources.
if ! (root=$PWD; cd / && "$root/.venv/bin/python" -c "import tailsim" 2>/dev/null) || ! cmp -s pyproject.toml .venv/pyproject.installed; then
    echo "== installing the tailsim package into .venv (pip install -e .)"
    .venv/bin/pip install -q --no-deps -e .
    cp pyproject.toml .venv/pyproject.installed
fi
