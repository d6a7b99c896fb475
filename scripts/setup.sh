#!/usr/bin/env bash
# Set up a fresh machine: system packages (libclang for fmi-sys' bindgen),
# the Rust crates (fetched by cargo on first build) and the pinned Python venv.
# Idempotent: re-running only checks.
set -euo pipefail
cd "$(dirname "$0")/.."

# fmi-sys runs bindgen, which loads libclang's C API at build time. Test for the library
# bindgen really loads (scripts/find-libclang.sh), not for any file named libclang*: the
# base image ships libclang-cpp14, which matches such a name but has no C API.
if ! scripts/find-libclang.sh >/dev/null; then
    echo "== installing libclang-dev (needed by fmi-sys' bindgen)"
    SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libclang-dev >/dev/null
    scripts/find-libclang.sh >/dev/null || { echo "setup: libclang-dev installed but no loadable libclang found" >&2; exit 1; }
fi

if [ ! -x .venv/bin/python ] || ! cmp -s tests/requirements.txt .venv/requirements.installed; then
    echo "== creating Python venv .venv (pinned: tests/requirements.txt)"
    python3 -m venv .venv
    .venv/bin/pip install -q --upgrade pip
    .venv/bin/pip install -q -r tests/requirements.txt
    cp tests/requirements.txt .venv/requirements.installed
fi
