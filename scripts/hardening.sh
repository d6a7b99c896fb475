#!/usr/bin/env bash
# Long-run hardening of the FMU libraries. Not part of scripts/test.sh,
# which runs the short versions (cargo test -p fmi-fuzz: 2500 fuzz sequences,
# 64-thread check, 10 000-cycle RSS check; pytest test_conformance/test_interop).
#
#   scripts/hardening.sh [FUZZ_SECONDS]        default 600
#   scripts/hardening.sh calls [N]             only the fuzz, until N FMI calls (default 10^7)
#                                              over all units: calls, calls/s, violations,
#                                              FMI functions and states exercised; exit 1 on
#                                              any violation → target/hardening/calls.txt
#
# Environment: TAILSITTER_FMUS=a,b narrows the FMUs (default: every declared model, fmi-fuzz all_models);
# HARDENING_SKIP_DIST=1 skips `cargo xtask dist`; FUZZ_SEED sets the fuzz seed;
# VALGRIND_CYCLES (default 5) cycles per FMU under valgrind; RSS_CYCLES (default 100000)
# light and RSS_FULL_CYCLES (default 5000; ~40 ms each for the LQR FMU) full cycles.
#
# Both modes write the sequence about to run to target/hardening/fuzz-progress.txt: if the
# process dies (abort, crash), that file and the stderr line of the signal handler give the
# `fmi-fuzz fuzz --replay 0x… --max-calls N` command that runs the failing sequence alone.
#
# Steps and what each reports:
#  1. long call-sequence fuzz through the C ABI: sequences, FMI calls, reset and restore
#     checks, violations, (function, state, status) coverage table → target/hardening/fuzz.txt
#  2. valgrind memcheck of instantiate → 50 steps → get/serialize/deserialize/set state →
#     free cycles of each FMU: the ERROR SUMMARY and LEAK SUMMARY → target/hardening/valgrind.txt
#     (2b: the same for a few hundred fuzz sequences: error paths, corrupt FMU states)
#  3. RSS before/after RSS_CYCLES instantiate/state/free cycles and RSS_FULL_CYCLES
#     instantiate/initialise/step/state/free cycles per FMU
#  4. 64 instances stepped concurrently vs. sequentially (the cargo test, with output)
set -euo pipefail
cd "$(dirname "$0")/.."
MODE=full
if [ "${1:-}" = calls ]; then
    MODE=calls
    CALLS="${2:-10000000}"
fi
SECONDS_FUZZ="${1:-600}"
OUT=target/hardening
mkdir -p "$OUT"

if [ "${HARDENING_SKIP_DIST:-0}" != 1 ]; then
    if [ -n "${TAILSITTER_FMUS:-}" ]; then cargo xtask dist --platforms linux64,win64 --only "$TAILSITTER_FMUS"; else cargo xtask dist --platforms linux64,win64; fi
fi
cargo build --release -p fmi-fuzz --bin fmi-fuzz
BIN=target/release/fmi-fuzz

if [ "$MODE" = calls ]; then
    echo "== fuzz until ${CALLS} FMI calls (seed ${FUZZ_SEED:-24301})"
    status=0
    "$BIN" fuzz --calls "$CALLS" --seconds 31536000 --seed "${FUZZ_SEED:-24301}" --coverage \
        --progress "$OUT/fuzz-progress.txt" > "$OUT/calls.txt" || status=$?
    grep -E "calls/s|^coverage:|^fmi-fuzz:|^  tailsitter|VIOLATION|×" "$OUT/calls.txt"
    [ "$status" = 0 ] && echo "== done: 0 violations (table of (function, state, status) counts in $OUT/calls.txt)"
    exit "$status"
fi

echo "== 1. fuzz for ${SECONDS_FUZZ} s"
"$BIN" fuzz --seconds "$SECONDS_FUZZ" --seed "${FUZZ_SEED:-24301}" --coverage \
    --progress "$OUT/fuzz-progress.txt" | tee "$OUT/fuzz.txt"

echo "== 2. valgrind memcheck (${VALGRIND_CYCLES:-5} cycles per FMU)"
valgrind --tool=memcheck --leak-check=full --show-leak-kinds=definite,indirect,possible \
    --errors-for-leak-kinds=definite,indirect --track-origins=yes --error-exitcode=99 \
    "$BIN" cycles --n "${VALGRIND_CYCLES:-5}" 2>&1 | tee "$OUT/valgrind.txt"
grep -E "ERROR SUMMARY|definitely lost|indirectly lost|possibly lost|still reachable|in use at exit" "$OUT/valgrind.txt"
echo "== 2b. valgrind memcheck of ${VALGRIND_FUZZ_SEQUENCES:-300} fuzz sequences (error paths, corrupt states)"
valgrind --tool=memcheck --leak-check=full --errors-for-leak-kinds=definite,indirect --error-exitcode=99 \
    "$BIN" fuzz --sequences "${VALGRIND_FUZZ_SEQUENCES:-300}" --seconds 3600 2>&1 | tee "$OUT/valgrind-fuzz.txt" \
    | grep -E "fmi-fuzz:|VIOLATION|ERROR SUMMARY|definitely lost|indirectly lost"

echo "== 3. RSS over ${RSS_CYCLES:-100000} instantiate/state/free and ${RSS_FULL_CYCLES:-5000} full cycles per FMU"
"$BIN" rss --n "${RSS_CYCLES:-100000}" | tee "$OUT/rss.txt"
"$BIN" rss --full --n "${RSS_FULL_CYCLES:-5000}" | tee -a "$OUT/rss.txt"

echo "== 4. 64 concurrent instances vs. sequential runs"
cargo test --release -p fmi-fuzz --test threads_memory -- --nocapture --test-threads 1 | tee "$OUT/threads.txt"

echo "== done: reports in $OUT/"
