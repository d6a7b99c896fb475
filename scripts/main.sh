#!/usr/bin/env bash
# The main job, from a fresh clone: set up, build and package the three FMUs
# (and the SSP systems) into dist/, run the analysis campaign (modes,
# closed-loop poles, Table 5.1 sensitivity, nonlinear robustness and gust
# sweeps; cached in out/analysis/cache, so a re-run only computes what
# changed), fly the default and fast missions and the position-step tests
# with the LQR and the TSD controller, and write CSVs, plots and the
# comparison report (out/report.md, out/report.html).
#
#   scripts/main.sh [--no-analysis] [runner options: --controller lqr|tsd|both, --jacobi, --no-steps, ...]
set -euo pipefail
cd "$(dirname "$0")/.."
analysis=1
runner_args=()
for arg in "$@"; do
    if [ "$arg" = "--no-analysis" ]; then analysis=0; else runner_args+=("$arg"); fi
done
scripts/setup.sh
cargo xtask dist
if [ "$analysis" = 1 ]; then
    echo "== analysis campaign (out/analysis)"
    cargo run --release --locked -p analysis -- all --out out/analysis
    .venv/bin/python -m tailsim.reports.analysis out/analysis
fi
# Before the missions: the comparison report's first section is the paired Monte-Carlo result.
echo "== Monte-Carlo campaign (out/campaign; the full run: docs/CAMPAIGN.md)"
.venv/bin/python -m tailsim.campaign --samples 16 --seed 1 --out out/campaign --replace --no-progress
echo "== flying the missions"
.venv/bin/python -m tailsim.reports.compare --out out "${runner_args[@]+"${runner_args[@]}"}"
