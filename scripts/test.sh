#!/usr/bin/env bash
# The whole test suite, from a fresh clone: set-up, lints, Rust tests, FMU
# packaging, Python (fmpy) tests. This is what CI runs (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh

echo "== cargo fmt --check"
cargo fmt --all -- --check
echo "== cargo clippy -D warnings"
cargo clippy --workspace --all-targets --locked -- -D warnings
echo "== build and package the FMUs (dist/)"
cargo xtask dist
echo "== Rust tests"
cargo test --workspace --locked
echo "== the export layers' tests on aarch64 (qemu-user)"
cargo test -p fmi2-export -p fmi3-export --locked --target aarch64-unknown-linux-gnu
echo "== ruff check / ruff format --check (python/, tests/, scripts/)"
.venv/bin/ruff check python tests scripts
.venv/bin/ruff format --check python tests scripts
echo "== Python tests (fmpy)"
.venv/bin/python -m pytest tests -q --ignore=tests/test_win64.py
# The win64 FMUs under Wine through fmpy's remoting client, in a process of their own:
# that client (fmpy's, not ours) has crashed its host process at random when instantiated
# under load; a crash must not take the rest of the suite with it. One retry on a crash
# (signal exit), never on a failed assertion.
echo "== win64 FMUs under Wine (fmpy remoting)"
set +e
.venv/bin/python -m pytest tests/test_win64.py -q
rc=$?
if [ "$rc" -ge 128 ]; then
    echo "fmpy's remoting client crashed (exit $rc); running the win64 tests once more"
    .venv/bin/python -m pytest tests/test_win64.py -q
    rc=$?
fi
set -e
exit "$rc"
