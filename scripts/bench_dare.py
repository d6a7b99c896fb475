#!/usr/bin/env python3
"""Our DARE + gain against scipy.linalg.solve_discrete_are on the same matrices (issue 17).

One invocation: builds and runs the Rust example `dare_benchmark` (it computes the
linearised, discretised 17×17 / 17×7 model of the default mission at time t, times our
DARE + gain and a whole relinearisation on itself over many repetitions, so process
start-up is excluded, and writes the matrices, P, K and its timings to JSON), then times
scipy's solve_discrete_are + gain on the same matrices in this process, checks that the
gains agree, and prints the ratio.

Timings are medians over batches of the CPU time of the calling thread (robust on a
loaded machine: it excludes the time spent waiting for a core); wall-clock medians are
printed beside them. BLAS is limited to one thread so that scipy's CPU time is all on
this thread (17×17 problems do not profit from threads).

    .venv/bin/python scripts/bench_dare.py [--t 15] [--batches 15] [--exe BINARY]
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import subprocess
import sys
import time

for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import numpy as np  # noqa: E402
import scipy  # noqa: E402
import scipy.linalg  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent


def scipy_dare_and_gain(phi, gamma, q, r):
    p = scipy.linalg.solve_discrete_are(phi, gamma, q, r)
    btp = gamma.T @ p
    k = np.linalg.solve(r + btp @ gamma, btp @ phi)
    return p, k


def time_scipy(args, batches: int) -> tuple[float, float]:
    """(CPU, wall) medians in µs per call."""
    c0 = time.thread_time()
    calib = 0
    while time.thread_time() - c0 < 0.02:
        scipy_dare_and_gain(*args)
        calib += 1
    reps = max(1, calib * 2)
    cpu, wall = [], []
    for _ in range(batches):
        c0, w0 = time.thread_time(), time.perf_counter()
        for _ in range(reps):
            scipy_dare_and_gain(*args)
        cpu.append((time.thread_time() - c0) / reps * 1e6)
        wall.append((time.perf_counter() - w0) / reps * 1e6)
    return float(np.median(cpu)), float(np.median(wall))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--t", type=float, default=15.0, help="mission time of the linearisation point (s)")
    ap.add_argument("--batches", type=int, default=15, help="timing batches (medians are reported)")
    ap.add_argument("--out", default=str(ROOT / "target" / "dare"), help="folder of the JSON case")
    ap.add_argument("--no-build", action="store_true", help="use the already built example binary")
    ap.add_argument(
        "--exe",
        help="run this dare_benchmark binary instead (e.g. a base commit's build, for before/after runs; "
        "implies --no-build)",
    )
    a = ap.parse_args()

    if not (a.no_build or a.exe):
        subprocess.run(
            ["cargo", "build", "--release", "-q", "-p", "lqr-control", "--example", "dare_benchmark"],
            cwd=ROOT,
            check=True,
        )
    exe = pathlib.Path(a.exe) if a.exe else ROOT / "target" / "release" / "examples" / "dare_benchmark"
    out = subprocess.run(
        [str(exe), repr(a.t), a.out, str(a.batches)], cwd=ROOT, check=True, capture_output=True, text=True
    ).stdout
    print(out.strip())
    case = json.loads(pathlib.Path(out.strip().rsplit("-> ", 1)[1]).read_text())
    phi, gamma, q, r = (np.array(case[k], dtype=float) for k in ("phi", "gamma", "q", "r"))
    p_ours, k_ours = np.array(case["p"]), np.array(case["k"])

    p_sp, k_sp = scipy_dare_and_gain(phi, gamma, q, r)
    k_rel = np.abs(k_sp - k_ours).max() / np.abs(k_sp).max()
    p_rel = np.abs(p_sp - p_ours).max() / np.abs(p_sp).max()

    def residual(p):
        btp = gamma.T @ p
        k = np.linalg.solve(r + btp @ gamma, btp @ phi)
        res = phi.T @ p @ phi - p - phi.T @ p @ gamma @ k + q
        return np.linalg.norm(res) / np.linalg.norm(p)

    sp_cpu, sp_wall = time_scipy((phi, gamma, q, r), a.batches)
    ours_cpu, ours_wall = case["us_dare_and_gain"], case["us_wall_dare_and_gain"]
    print(f"matrices: Φ {phi.shape}, Γ {gamma.shape}, t = {a.t} s ({case['euler']}); scipy {scipy.__version__}")
    print(f"gains: max |K_ours − K_scipy| / max |K| = {k_rel:.2e}; P: {p_rel:.2e}")
    print(f"DARE relative residual: ours {residual(p_ours):.2e}, scipy {residual(p_sp):.2e}")
    print(
        f"DARE + gain, median CPU (wall) µs per call: ours {ours_cpu:.1f} ({ours_wall:.1f}), scipy {sp_cpu:.1f} "
        f"({sp_wall:.1f})"
    )
    print(f"ratio scipy / ours: {sp_cpu / ours_cpu:.1f}× (CPU time), {sp_wall / ours_wall:.1f}× (wall)")
    print(f"one whole relinearisation + gain (ours): {case['us_relinearise_discretise_dare_checks']:.1f} µs CPU")
    if not k_rel <= 1e-8:
        print("FAIL: gains differ by more than 1e-8 relative", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
