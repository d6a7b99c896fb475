#!/usr/bin/env python3
"""Time the default mission (35 s, 20 ms, Gauss-Seidel) under the fmpy master (issue 17).

For each controller: `runs` runs of `ClosedLoop.run` on the packaged FMUs (FMU extraction
and model-description parsing excluded), median and best of the CPU time of this process
and of the wall-clock time, and the share spent inside the controller's and the plant's
fmi2DoStep.

    .venv/bin/python scripts/bench_fmpy.py [--dist dist] [--runs 5]
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time

import numpy as np

from tailsim import ClosedLoop, Fmu

ROOT = pathlib.Path(__file__).resolve().parent.parent


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dist", default=str(ROOT / "dist"), help="folder of the packaged FMUs")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--controller", choices=["lqr", "tsd", "both"], default="both")
    a = ap.parse_args()
    dist = pathlib.Path(a.dist)
    plant = Fmu(dist / "tailsitter_plant.fmu")
    for name in ["lqr", "tsd"] if a.controller == "both" else [a.controller]:
        ctrl = Fmu(dist / f"tailsitter_{name}.fmu")
        loop = ClosedLoop(plant, ctrl, ordering="gauss-seidel")
        cpu, wall, inside = [], [], []
        for _ in range(a.runs):
            c0, w0 = time.process_time(), time.perf_counter()
            r = loop.run(stop_time=35.0)
            cpu.append(time.process_time() - c0)
            wall.append(time.perf_counter() - w0)
            inside.append(r.wall_time_controller + r.wall_time_plant)
        print(
            f"{name}: default mission ({r.steps} steps): CPU median {np.median(cpu):.3f} s (best {min(cpu):.3f}), "
            f"wall median {np.median(wall):.3f} s (best {min(wall):.3f}); inside fmi2DoStep (wall) "
            f"median {np.median(inside):.3f} s; max position error {np.max(r['pos_error']):.3f} m"
        )
        ctrl.cleanup()
    plant.cleanup()
    return 0


if __name__ == "__main__":
    sys.exit(main())
