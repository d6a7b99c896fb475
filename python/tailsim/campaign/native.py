"""The campaign's runs flown by the native Rust loop on identical jobs
(performance): the same samples, parameters, wind and limits as the fmpy runs, through
`analysis campaign-jobs` (crates/analysis/src/native_campaign.rs), compared row by row
with the fmpy campaign's rows and timed side by side.

    python -m tailsim.campaign.native --campaign out/campaign [--threads 1] [--samples N]

reads the campaign's specification (`campaign.json`) and rows (`results.parquet`), flies
the perfect-state runs natively and writes `<campaign>/native/rows.jsonl`,
`comparison.json` and `comparison.md`: per metric the largest difference between the
engines over the runs both completed, the runs whose outcome differs, and the CPU time
per run of each engine.

Identical jobs: a plant parameter (and the wind) is sent as the bit pattern of the value the fmpy
runner uses (nominal from the plant FMU's modelDescription × the sample's factor), so
no decimal round trip changes it. The two engines are the same Rust code behind
different masters (fmpy + FMI vs a direct call), so rows agree to round-off, amplified
by the closed loop: TOLERANCE is the agreement required of a completed run's metrics.
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import struct
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from .. import cli
from .runner import FMU_NAMES, metric_columns
from .sampling import CONFIGURATION_INDEX, TABLE_5_1, CampaignSpec, jobs, plant_parameters

ROOT = pathlib.Path(__file__).resolve().parents[3]
#: Largest |fmpy − native| of a completed run's metric (m, deg, fractions, s). The two
#: engines fly the same Rust code behind different masters and, with the fmpy master's
#: timing mirrored (`closed_loop::MeasuredWind::HeldInput`) and the inputs passed as bit
#: patterns, the same trajectory bit for bit: maxima agree exactly, RMS values differ only
#: by the order of summation (numpy's pairwise sum vs a sequential one), a relative
#: error of at most n·ε ≈ 1751 · 2.2e-16 ≈ 4e-13, i.e. ≈ 4e-11 on a 100 m RMS error.
TOLERANCE = 1e-9


def _bits(x: float) -> int:
    return struct.unpack("<Q", struct.pack("<d", float(x)))[0]


def plant_nominal(dist: str | pathlib.Path) -> dict[str, float]:
    """The nominal values of the Table 5.1 plant parameters, as the fmpy runner reads them."""
    from fmpy import read_model_description

    md = read_model_description(str(pathlib.Path(dist) / f"{FMU_NAMES['plant']}.fmu"))
    names = {n for p in TABLE_5_1 for n in p.plant_params}
    return {v.name: float(v.start) for v in md.modelVariables if v.name in names}


def native_job(job: Mapping[str, Any], spec: CampaignSpec, nominal: Mapping[str, float]) -> dict[str, Any]:
    """The native job of a campaign job (perfect state source only)."""
    pp = plant_parameters(job, nominal)
    pp.update(json.loads(job.get("overrides") or "{}"))
    return {
        "key": job["key"],
        "controller": job["controller"],
        "configuration": CONFIGURATION_INDEX[job["configuration"]],
        "state_source": job["state_source"],
        "plant_bits": {k: _bits(v) for k, v in pp.items()},
        "aero_model": int(spec.aero_model),
        "mission_bits": {k: _bits(v) for k, v in spec.mission.items()},
        "wind": {
            k: _bits(job[c])
            for k, c in (
                ("steady_n", "wind_steady_n"),
                ("steady_e", "wind_steady_e"),
                ("gust_n", "gust_n"),
                ("gust_e", "gust_e"),
                ("gust_d", "gust_d"),
                ("gust_start", "gust_start"),
                ("gust_duration", "gust_duration"),
            )
        }
        | {k: int(job.get(k, 0)) for k in ("turbulence_intensity", "turbulence_seed")},
        "stop_time": spec.stop_time,
        "step_size": spec.step_size,
        "divergence_m": spec.divergence_m,
        "error_limit_m": spec.error_limit_m,
    }


def analysis_binary(profile: str = "release") -> pathlib.Path:
    """The `analysis` binary of a cargo profile ("release" or "debug": the same floating-point
    results, Rust does not contract or reorder without being told), built if needed."""
    cmd = ["cargo", "build", "-q", "-p", "analysis"] + (["--release"] if profile == "release" else [])
    subprocess.run(cmd, cwd=ROOT, check=True)
    return ROOT / "target" / profile / "analysis"


def run_native(
    spec: CampaignSpec,
    dist: str | pathlib.Path = ROOT / "dist",
    sample_ids: Iterable[int] | None = None,
    threads: int | None = None,
    workdir: str | pathlib.Path | None = None,
    profile: str = "release",
) -> tuple[list[dict[str, Any]], float]:
    """Fly the campaign's perfect-state runs natively; returns the rows (metrics flattened,
    None → NaN) and the wall time of the native process (s)."""
    nominal = plant_nominal(dist)
    js = [native_job(j, spec, nominal) for j in jobs(spec, sample_ids) if j["state_source"] == "perfect"]
    tmp = pathlib.Path(workdir or tempfile.mkdtemp(prefix="tailsim-native-"))
    tmp.mkdir(parents=True, exist_ok=True)
    (tmp / "jobs.jsonl").write_text("".join(json.dumps(j) + "\n" for j in js))
    cmd = [
        str(analysis_binary(profile)),
        "campaign-jobs",
        "--jobs",
        str(tmp / "jobs.jsonl"),
        "--out",
        str(tmp / "rows.jsonl"),
    ]
    if threads:
        cmd += ["--threads", str(threads)]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True)
    wall = time.perf_counter() - t0
    rows = []
    for line in (tmp / "rows.jsonl").read_text().splitlines():
        r = json.loads(line)
        m = r.pop("metrics")
        r.update({k: (math.nan if m.get(k) is None else float(m[k])) for k in metric_columns()})
        rows.append(r)
    return rows, wall


def compare(fmpy_rows: Iterable[Mapping[str, Any]], native_rows: Iterable[Mapping[str, Any]], tol: float = TOLERANCE):
    """Row-by-row comparison: {"runs", "same_outcome", "outcome_differs": [keys],
    "max_abs_diff": {metric: (value, key)}, "beyond_tolerance": [(key, metric, fmpy, native)]}.

    Outcomes are compared as (completed, failure); metrics on runs both engines completed,
    NaN equal to NaN."""
    by_key = {r["key"]: r for r in fmpy_rows}
    out: dict[str, Any] = {
        "runs": 0,
        "same_outcome": 0,
        "outcome_differs": [],
        "max_abs_diff": {},
        "beyond_tolerance": [],
    }
    for n in native_rows:
        f = by_key.get(n["key"])
        if f is None:
            continue
        out["runs"] += 1
        if (bool(f["completed"]), f["failure"]) != (bool(n["completed"]), n["failure"]):
            out["outcome_differs"].append(n["key"])
            continue
        out["same_outcome"] += 1
        if not f["completed"]:
            continue
        for k in metric_columns():
            a, b = float(f[k]), float(n[k])
            if math.isnan(a) and math.isnan(b):
                continue
            d = abs(a - b) if not (math.isnan(a) or math.isnan(b)) else math.inf
            if d > out["max_abs_diff"].get(k, (-1.0, ""))[0]:
                out["max_abs_diff"][k] = (d, n["key"])
            if d > tol:
                out["beyond_tolerance"].append((n["key"], k, a, b))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = cli.Parser(prog="python -m tailsim.campaign.native", description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--campaign", default="out/campaign", help="folder of an fmpy campaign (campaign.json, results.parquet)"
    )
    ap.add_argument("--dist", default=str(ROOT / "dist"))
    ap.add_argument("--threads", type=cli.integer(1), help="native threads, ≥ 1 (default: all cores)")
    ap.add_argument("--samples", type=cli.integer(1), help="only the first N samples, ≥ 1")
    a = ap.parse_args(argv)
    for name in ("campaign.json", "results.parquet"):
        if not (pathlib.Path(a.campaign) / name).is_file():
            ap.error(f"argument --campaign: {a.campaign!r} holds no {name} (run `python -m tailsim.campaign` first)")
    cli.check_fmus(ap, "--dist", a.dist, [FMU_NAMES["plant"]])
    return cli.guard(ap.prog, a.debug, lambda: _main(a))


def _main(a: argparse.Namespace) -> int:
    import pyarrow.parquet as pq

    folder = pathlib.Path(a.campaign)
    spec = CampaignSpec.from_json(json.loads((folder / "campaign.json").read_text())["spec"])
    fmpy_rows = pq.read_table(folder / "results.parquet").to_pylist()
    ids = sorted({r["sample_id"] for r in fmpy_rows})
    if a.samples:
        ids = ids[: a.samples]
    native_rows, wall = run_native(spec, a.dist, ids, a.threads, folder / "native")
    cmp = compare(fmpy_rows, native_rows)
    keys = {r["key"] for r in native_rows}
    cpu_f = np.array([r["cpu_time_s"] for r in fmpy_rows if r["key"] in keys], dtype=float)
    cpu_n = np.array([r["cpu_time_s"] for r in native_rows], dtype=float)
    cmp["timing"] = {
        "fmpy_cpu_s_per_run_mean": float(np.nanmean(cpu_f)),
        "native_cpu_s_per_run_mean": float(np.nanmean(cpu_n)),
        "speed_ratio": float(np.nanmean(cpu_f) / np.nanmean(cpu_n)),
        "native_wall_s": wall,
        "native_threads": a.threads,
    }
    cmp["tolerance"] = TOLERANCE
    (folder / "native" / "comparison.json").write_text(json.dumps(cmp, indent=1))
    t = cmp["timing"]
    print(
        f"{cmp['runs']} runs: same outcome {cmp['same_outcome']}, differing {len(cmp['outcome_differs'])}, "
        f"metrics beyond {TOLERANCE:g}: {len(cmp['beyond_tolerance'])}; largest differences: "
        + ", ".join(f"{k} {v[0]:.2e}" for k, v in sorted(cmp["max_abs_diff"].items()))
    )
    print(
        f"CPU per run: fmpy {t['fmpy_cpu_s_per_run_mean'] * 1e3:.1f} ms, native "
        f"{t['native_cpu_s_per_run_mean'] * 1e3:.1f} ms "
        f"({t['speed_ratio']:.1f}×); native wall {wall:.1f} s"
    )
    return 0 if not cmp["outcome_differs"] and not cmp["beyond_tolerance"] else 1


if __name__ == "__main__":
    sys.exit(main())
