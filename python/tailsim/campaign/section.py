"""The comparison section of the report: the paired Monte-Carlo result.

The controllers are compared on the same random plants, winds and gusts (paired
samples, `tailsim.campaign`), not on one nominal mission: completion probability of
each arm (controller × configuration × state source) with its 95 % Wilson interval,
and the paired differences of every two controllers of one configuration and state source
(TSD − LQR, PX4 − LQR, PX4 − TSD: the later minus the earlier in `sampling.ORDER`) on the same samples
with 95 % percentile-bootstrap intervals — completion (all samples), RMS and max position
error (samples both completed).

Two sources, both shown when present:

* the documented full run (≥ 1000 samples), summarised once into
  `docs/campaign_full_run.json` by

      python -m tailsim.campaign.section --write docs/campaign_full_run.json FOLDER...

  (FOLDERs: campaigns of the same seed and sample space, e.g. one per axis; their rows
  are merged, samples paired by id — a sample's draw does not depend on the axes);
* the main job's small campaign (`<out>/campaign`, `scripts/main.sh`).

`report_section(out)` is the hook of `tailsim.reports.compare`.
"""

from __future__ import annotations

import json
import pathlib
import sys
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from .. import cli
from .report import _arm_mask, arms, bootstrap_mean_ci, controller_pairs, paired, wilson_interval
from .sampling import CampaignSpec

ROOT = pathlib.Path(__file__).resolve().parents[3]
FULL_RUN = ROOT / "docs" / "campaign_full_run.json"
#: Spec fields that fix the samples: campaigns merged into one summary must agree on them.
SAMPLE_SPACE = (
    "seed",
    "tau_aero",
    "tau_mass",
    "wind_max",
    "gust_max",
    "gust_duration",
    "mission",
    "aero_model",
    "step_size",
)


def _load(folders: Iterable[str | pathlib.Path]):
    import pyarrow as pa
    import pyarrow.parquet as pq

    tables, specs, stats = [], [], []
    for f in map(pathlib.Path, folders):
        spec = CampaignSpec.from_json(json.loads((f / "campaign.json").read_text())["spec"])
        specs.append(spec)
        tables.append(pq.read_table(f / "results.parquet"))
        run = json.loads((f / "last_run.json").read_text()) if (f / "last_run.json").exists() else {}
        native = f / "native" / "comparison.json"
        if native.exists():
            run["native"] = json.loads(native.read_text())["timing"]
        stats.append({"folder": f.name, **run})
    ref = specs[0].to_json()
    for s in specs[1:]:
        d = s.to_json()
        bad = [k for k in SAMPLE_SPACE if d[k] != ref[k]]
        if bad:
            raise SystemExit(f"campaigns of different sample spaces cannot be paired ({', '.join(bad)} differ)")
    return pa.concat_tables(tables, promote_options="default"), specs, stats


def summarize(folders: Iterable[str | pathlib.Path]) -> dict[str, Any]:
    """The paired Monte-Carlo summary of one or more campaign folders (same sample space)."""
    table, specs, stats = _load(folders)
    cols = {k: np.asarray(v) for k, v in table.to_pydict().items()}
    A = arms(cols)
    out: dict[str, Any] = {
        "spec": {
            **{k: specs[0].to_json()[k] for k in SAMPLE_SPACE},
            # What a run must do to count as completed, and the strongest turbulence flown
            # (the avionics arms fly without the atmosphere): the readings name both.
            "turbulence_max": max(sp.to_json()["turbulence_max"] for sp in specs),
            "error_limit_m": max(sp.to_json()["error_limit_m"] for sp in specs),
        },
        "samples": {f"{a[0]}/{a[1]}/{a[2]}": int(_arm_mask(cols, a).sum()) for a in A},
        "arms": {},
        "paired": {},
        "runtime": stats,
    }
    for a in A:
        m = _arm_mask(cols, a)
        n, k = int(m.sum()), int(cols["completed"][m].sum())
        lo, hi = wilson_interval(k, n)
        ok = m & cols["completed"].astype(bool)
        reasons: dict[str, int] = {}
        for r in cols["failure"][m]:
            if r:
                reasons[str(r)] = reasons.get(str(r), 0) + 1
        med = {
            q: float(np.median(cols[q][ok].astype(float))) if ok.any() else float("nan") for q in ("max_err", "rms_err")
        }
        out["arms"]["/".join(a)] = {
            "runs": n,
            "completed": k,
            "p": k / n if n else float("nan"),
            "wilson95": [lo, hi],
            "failures": reasons,
            "median_completed": med,
        }
    for b, a in controller_pairs(A):
        _, cb, ca = paired(cols, b, a, "completed")
        d = ca.astype(float) - cb.astype(float)
        res = {"pair": [a[0], b[0]], "completion": _ci(d)}
        both = (cb > 0) & (ca > 0)
        for q in ("rms_err", "max_err"):
            _, vb, va = paired(cols, b, a, q)
            dd = (va - vb)[both]
            res[q] = _ci(dd[np.isfinite(dd)])
        out["paired"][pair_key(b, a)] = res
    return out


def pair_key(b, a) -> str:
    """The summary's key of the paired difference a − b: `configuration/state source` for
    TSD − LQR (as every summary before the third controller wrote it), else with the pair."""
    group = f"{a[1]}/{a[2]}"
    return group if (b[0], a[0]) == ("lqr", "tsd") else f"{group}: {a[0].upper()} − {b[0].upper()}"


def merge(base: Mapping[str, Any], new: Mapping[str, Any]) -> dict[str, Any]:
    """Two summaries of one sample space as one: each arm and each paired difference from the
    summary that measured it on more samples (the base on a tie), the runtimes of both. For
    adding arms to a documented run without its folders (`--base`)."""
    # As JSON (a summary read from a file has lists where a fresh one has tuples).
    norm = json.loads(json.dumps([base["spec"], new["spec"]]))
    bad = [k for k in SAMPLE_SPACE if norm[0].get(k) != norm[1].get(k)]
    if bad:
        raise SystemExit(f"summaries of different sample spaces cannot be merged ({', '.join(bad)} differ)")
    out = {"spec": dict(base["spec"]), "samples": {}, "arms": {}, "paired": {}, "runtime": []}
    for k in dict.fromkeys([*base["arms"], *new["arms"]]):
        b, n = base["arms"].get(k), new["arms"].get(k)
        src = base if n is None or (b is not None and b["runs"] >= n["runs"]) else new
        out["arms"][k] = src["arms"][k]
        out["samples"][k] = src["samples"][k]
    for k in dict.fromkeys([*base["paired"], *new["paired"]]):
        b, n = base["paired"].get(k), new["paired"].get(k)
        better_b = n is None or (b is not None and b["completion"]["n"] >= n["completion"]["n"])
        out["paired"][k] = b if better_b else n
    out["runtime"] = [*base["runtime"], *new["runtime"]]
    return out


def _ci(d: np.ndarray) -> dict[str, float]:
    lo, hi = bootstrap_mean_ci(d)
    return {
        "n": int(d.size),
        "mean": float(d.mean()) if d.size else float("nan"),
        "ci95": [lo, hi],
        "median": float(np.median(d)) if d.size else float("nan"),
    }


def _f(x: float, nd: int = 3) -> str:
    return "—" if x is None or not np.isfinite(x) else f"{x:.{nd}f}"


def markdown(summary: Mapping[str, Any], title: str) -> list[str]:
    """Markdown of a summary: completion per arm, the paired differences, runtime."""
    s = summary["spec"]
    n_samples = max(summary["samples"].values()) if summary["samples"] else 0
    md = [
        f"### {title}",
        "",
        f"Up to {n_samples} samples per arm (seed {s['seed']}; Table 5.1 factors log-uniform within τ = "
        f"{s['tau_aero']:g} "
        f"aero / {s['tau_mass']:g} mass and inertia; steady wind ≤ {s['wind_max']:g} m/s and a 1 − cos gust ≤ "
        f"{s['gust_max']:g} m/s of random direction and timing; plant aerodynamics "
        f"{'global (post-stall)' if s['aero_model'] == 1 else 'thesis (linear)'}; mission "
        f"{sum(s['mission'].values()):g} s). Arm = controller/configuration/state source.",
        "",
        "| arm | runs | completed | P(complete) | 95 % Wilson interval | failures | median max / RMS error of "
        "completed runs (m) |",
        "|---|---|---|---|---|---|---|",
    ]
    for arm, r in summary["arms"].items():
        f = ", ".join(f"{k}: {v}" for k, v in sorted(r["failures"].items())) or "none"
        lo, hi = r["wilson95"]
        med = r["median_completed"]
        md.append(
            f"| {arm} | {r['runs']} | {r['completed']} | {_f(r['p'])} | [{_f(lo)}, {_f(hi)}] | {f} | "
            f"{_f(med['max_err'], 2)} / {_f(med['rms_err'], 2)} |"
        )
    if summary["paired"]:
        md += [
            "",
            "Paired differences A − B on the same samples (completion: all paired samples, +1 = only A "
            "completed; errors: samples both completed), mean with a 95 % percentile-bootstrap interval, median:",
            "",
            "| configuration/state source | A − B | quantity | samples | mean A − B | 95 % interval | median |",
            "|---|---|---|---|---|---|---|",
        ]
        for key, res in summary["paired"].items():
            a, b = res.get("pair", ["tsd", "lqr"])
            group, name = key.split(":")[0], f"{a.upper()} − {b.upper()}"
            for q, label in (
                ("completion", "completion"),
                ("rms_err", "RMS position error (m)"),
                ("max_err", "max position error (m)"),
            ):
                r = res[q]
                md.append(
                    f"| {group} | {name} | {label} | {r['n']} | {_f(r['mean'])} | "
                    f"[{_f(r['ci95'][0])}, {_f(r['ci95'][1])}] | {_f(r['median'])} |"
                )
    rt = [r for r in summary["runtime"] if r.get("runs_done_now")]
    if rt:
        md += [
            "",
            "Runtime: "
            + "; ".join(
                f"{r['folder']}: {r['runs_done_now']} runs in {r['elapsed_s']:.0f} s on {r['worker_threads']} "
                "worker(s) "
                f"({r['runs_per_s']:.2f} runs/s, {1e3 / r['runs_per_cpu_s']:.0f} ms CPU per run"
                + (
                    f"; native Rust on identical jobs {1e3 * r['native']['native_cpu_s_per_run_mean']:.0f} ms CPU "
                    "per run, "
                    f"{r['native']['speed_ratio']:.1f}× faster"
                    if "native" in r
                    else ""
                )
                + ")"
                for r in rt
            )
            + ".",
        ]
    return md


def report_section(out: str | pathlib.Path) -> list[str]:
    """The report's comparison section (hook of `tailsim.reports.compare`): the documented full run
    and, when present, the main job's campaign in `<out>/campaign`."""
    md = [
        "",
        "## Comparison: paired Monte-Carlo",
        "",
        "The controllers are compared on uncertain plants, not on the nominal one (where each controller's design "
        "model is the plant exactly): every sample is flown by every arm, so differences are paired. The nominal "
        "missions below are single points of this distribution.",
        "",
    ]
    if FULL_RUN.exists():
        md += markdown(json.loads(FULL_RUN.read_text()), "Documented full run (docs/CAMPAIGN.md)")
    campaign = pathlib.Path(out) / "campaign"
    if (campaign / "results.parquet").exists():
        try:
            md += [""] + markdown(summarize([campaign]), f"This run's campaign ({campaign})")
        except Exception as e:  # noqa: BLE001 - a broken campaign folder must not lose the report
            md += ["", f"(campaign in {campaign} not summarised: {e})"]
    return md


def main(argv: list[str] | None = None) -> int:
    ap = cli.Parser(prog="python -m tailsim.campaign.section", description=__doc__.split("\n\n")[0])
    ap.add_argument("folders", nargs="+", help="campaign folders of one sample space (rows merged, paired by sample)")
    ap.add_argument("--write", help="write the summary JSON here (e.g. docs/campaign_full_run.json)")
    ap.add_argument(
        "--base",
        help="a summary JSON of the same sample space to merge with (each arm and paired difference from the "
        "summary with more samples), e.g. docs/campaign_full_run.json when adding a controller",
    )
    a = ap.parse_args(argv)
    if a.base and not pathlib.Path(a.base).is_file():
        ap.error(f"argument --base: {a.base!r} is not a file")
    for f in a.folders:
        for name in ("campaign.json", "results.parquet"):
            if not (pathlib.Path(f) / name).is_file():
                ap.error(f"argument folders: {f!r} holds no {name} (run `python -m tailsim.campaign` first)")
    if a.write and pathlib.Path(a.write).is_dir():
        ap.error(f"argument --write: {a.write!r} is a folder (expected a file name)")

    def run() -> int:
        s = summarize(a.folders)
        if a.base:
            s = merge(json.loads(pathlib.Path(a.base).read_text()), s)
        if a.write:
            pathlib.Path(a.write).write_text(json.dumps(s, indent=1) + "\n")
        print("\n".join(markdown(s, "Paired Monte-Carlo")))
        return 0

    return cli.guard(ap.prog, a.debug, run)


if __name__ == "__main__":
    sys.exit(main())
