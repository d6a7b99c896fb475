#!/usr/bin/env bash
# The main job, from a fresh clone: set up, build and package the FMUs
# (and the SSP systems) into dist/, run the analysis campaign (modes,
# closed-loop poles, Table 5.1 sensitivity, nonlinear robustness and gust
# sweeps; cached in out/analysis/cache, so a re-run only computes what
# changed), fly the default and fast missions and the position-step tests
# with each declared controller, and write CSVs, plots and the
# comparison report (out/report.md, out/report.html); it ends with the verdict.
#
#   scripts/main.sh [--help] [--no-analysis] [runner options: --controller lqr|tsd|both, --jacobi, --no-steps, ...]
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
    cat <<'EOF'
usage: scripts/main.sh [--no-analysis] [runner options]

The main job: set up the machine (scripts/setup.sh), build and package the FMUs and
the SSP systems into dist/ (cargo xtask dist), run the analysis campaign (out/analysis),
a small Monte-Carlo campaign (out/campaign), fly the missions and the position steps
with each controller, write the comparison report (out/report.md, out/report.html) and
print its verdict.

  -h, --help       this help (nothing is set up or built)
  --no-analysis    skip the analysis campaign
  runner options   passed to `python -m tailsim.reports.compare` and checked before
                   anything is built: --controller lqr|tsd|both, --jacobi, --no-steps,
                   --no-avionics, --fast-t1 S, --fast-t2 S, --debug
                   (.venv/bin/python -m tailsim.reports.compare --help)
EOF
}

analysis=1
runner_args=()
for arg in "$@"; do
    case "$arg" in
        -h | --help) usage; exit 0 ;;
        --no-analysis) analysis=0 ;;
        *) runner_args+=("$arg") ;;
    esac
done

# The runner's options, checked (types, ranges, names) before any set-up or build work;
# its FMUs are checked by the runner itself once they are built.
check_runner_args() {
    .venv/bin/python -c 'import sys; from tailsim.reports.compare import parser; parser().parse_args(sys.argv[1:])' \
        "${runner_args[@]+"${runner_args[@]}"}"
}
checked=0
if [ -x .venv/bin/python ] && .venv/bin/python -c 'import tailsim' 2>/dev/null; then
    check_runner_args
    checked=1
fi
scripts/setup.sh
[ "$checked" = 1 ] || check_runner_args
cargo xtask dist
if [ "$analysis" = 1 ]; then
    echo "== analysis campaign (out/analysis)"
    cargo run --release --locked -p analysis -- all --out out/analysis
    echo "== the thesis reproduction (Table 5.1 by §5.1 with the thesis configurations, Table 4.4, modes, missions)"
    cargo run --release --locked -p analysis -- reproduction --out out/analysis
    echo "== wind envelope of the default mission (both controllers, 0-10 m/s, 8 bearings, steady and turbulent)"
    cargo run --release --locked -p analysis -- wind-envelope --default-only --out out/analysis
    .venv/bin/python -m tailsim.reports.analysis out/analysis
fi
# Before the missions: the report's verdict reads the paired Monte-Carlo result (every controller, both
# configurations, perfect state and the avionics chain, on the same uncertain plants in wind).
echo "== Monte-Carlo campaign (out/campaign; the full run: docs/CAMPAIGN.md)"
.venv/bin/python -m tailsim.campaign --samples 32 --seed 1 --out out/campaign --replace --no-progress \
    --configurations tuned,thesis --state-sources perfect,avionics
echo "== flying the missions"
.venv/bin/python -m tailsim.reports.compare --out out "${runner_args[@]+"${runner_args[@]}"}"
echo
.venv/bin/python -m tailsim.reports.verdict out
echo "(the report: out/report.html)"
