#!/usr/bin/env bash
# The main job, from a fresh clone: set up, build and package the three FMUs
# into dist/, fly the default and fast missions and the position-step tests
# with the LQR and the TSD controller, and write CSVs, plots and the
# comparison report into out/ (options: python -m tailsim.compare --help).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cargo xtask dist
PYTHONPATH=python .venv/bin/python -m tailsim.compare --out out "$@"
