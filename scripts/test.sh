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
echo "== Python tests (fmpy)"
.venv/bin/python -m pytest tests -q
