"""Monte-Carlo campaign: both controllers on the same uncertain plants, winds and
gusts, run as Dask tasks on an embedded LocalCluster or on
an existing Dask cluster, streamed to Parquet (resumable), then reported.

    python -m tailsim.campaign --samples 200 --seed 1 --out out/campaign
    python -m tailsim.campaign --samples 200 --seed 1 --out out/campaign --scheduler tcp://HOST:8786
    python -m tailsim.campaign --report-only --out out/campaign

See docs/CAMPAIGN.md for the sample space, the output schema and resuming.
"""

from __future__ import annotations

import argparse
import io
import json
import os
import pathlib
import re
import sys
import time
import uuid
import zipfile
from collections.abc import Callable, Mapping
from typing import Any

from .. import cli, declarations
from .runner import FMU_NAMES, STATE_SOURCE_FMUS, digest, install_fmus, load_fmu_bytes, metric_columns, run_job
from .sampling import (
    CONFIGURATIONS,
    CONTROLLERS,
    MISSIONS,
    STATE_SOURCES,
    TURBULENCE_LEVELS,
    CampaignSpec,
    jobs,
    sample_columns,
)

ROOT = pathlib.Path(__file__).resolve().parents[3]
#: Columns that depend on where and when a run was executed, not on what was run.
NONDETERMINISTIC = ("worker", "wall_time_s", "cpu_time_s")
SORT_KEYS = [
    ("sample_id", "ascending"),
    ("controller", "ascending"),
    ("configuration", "ascending"),
    ("state_source", "ascending"),
]


# --- Parquet store ------------------------------------------------------------------------


def row_schema():
    import pyarrow as pa

    fields = [
        ("key", pa.string()),
        ("sample_id", pa.int64()),
        ("controller", pa.string()),
        ("configuration", pa.string()),
        ("state_source", pa.string()),
        ("completed", pa.bool_()),
        ("failure", pa.string()),
        ("detail", pa.string()),
    ]
    fields += [(c, pa.float64()) for c in metric_columns()]
    for c in sample_columns()[1:]:
        fields.append((c, pa.int64() if c == "noise_seed" else pa.float64()))
    fields += [
        ("overrides", pa.string()),
        ("worker", pa.string()),
        ("wall_time_s", pa.float64()),
        ("cpu_time_s", pa.float64()),
    ]
    return pa.schema(fields)


class Store:
    """Results as Parquet part files under <out>/runs/, one row per run. Each part is
    written to a temporary name and renamed, so an interrupted campaign leaves only
    whole parts; the union of the parts is the campaign's state."""

    def __init__(self, out: str | pathlib.Path):
        self.dir = pathlib.Path(out) / "runs"
        self.dir.mkdir(parents=True, exist_ok=True)
        self.schema = row_schema()

    def parts(self) -> list[pathlib.Path]:
        return sorted(self.dir.glob("part-*.parquet"))

    def done_keys(self) -> set[str]:
        import pyarrow.parquet as pq

        keys: set[str] = set()
        for p in self.parts():
            keys.update(pq.read_table(p, columns=["key"]).column("key").to_pylist())
        return keys

    def write(self, rows: list[Mapping[str, Any]]) -> None:
        if not rows:
            return
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.Table.from_pylist([{f.name: r.get(f.name) for f in self.schema} for r in rows], schema=self.schema)
        name = f"part-{time.time_ns():020d}-{os.getpid()}-{uuid.uuid4().hex[:6]}.parquet"
        tmp = self.dir / f".{name}.tmp"
        pq.write_table(table, tmp)
        os.replace(tmp, self.dir / name)

    def read(self):
        """All runs, one row per key (the first written wins), sorted by sample and axes."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        parts = self.parts()
        if not parts:
            return self.schema.empty_table()
        table = pa.concat_tables([pq.read_table(p, schema=self.schema) for p in parts])
        seen: set[str] = set()
        keep = []
        for i, k in enumerate(table.column("key").to_pylist()):
            if k not in seen:
                seen.add(k)
                keep.append(i)
        return table.take(keep).sort_by(SORT_KEYS)


def deterministic(table):
    """The table without the columns that depend on where/when runs executed."""
    return table.drop_columns([c for c in NONDETERMINISTIC if c in table.column_names])


class _Writer:
    def __init__(self, store: Store, flush_rows: int, flush_seconds: float):
        self.store, self.flush_rows, self.flush_seconds = store, flush_rows, flush_seconds
        self.rows: list[dict] = []
        self.last = time.monotonic()
        self.written = 0
        self.cpu: list[float] = []  # CPU time of each run recorded now

    def add(self, row: dict) -> None:
        self.rows.append(row)
        self.cpu.append(row.get("cpu_time_s", float("nan")))
        if len(self.rows) >= self.flush_rows or time.monotonic() - self.last > self.flush_seconds:
            self.flush()

    def flush(self) -> None:
        self.store.write(self.rows)
        self.written += len(self.rows)
        self.rows = []
        self.last = time.monotonic()


# --- the campaign -------------------------------------------------------------------------


def _check_campaign_file(out: pathlib.Path, spec: CampaignSpec, digests: Mapping[str, str], replace: bool) -> None:
    path = out / "campaign.json"
    meta = {"spec": spec.to_json(), "fmus": dict(digests)}
    if path.exists():
        old = json.loads(path.read_text())
        old_spec = CampaignSpec.from_json(old["spec"])
        if old_spec.identity() != spec.identity() or old["fmus"] != dict(digests):
            if not replace:
                raise SystemExit(
                    f"{out} holds a different campaign (spec or FMUs differ; only --samples may change on resume): "
                    "use another --out, or --replace to discard it"
                )
            for p in Store(out).parts():
                p.unlink()
            (out / "results.parquet").unlink(missing_ok=True)
    path.write_text(json.dumps(meta, indent=1))


def local_cluster(n_workers: int | None = None):
    """One single-threaded worker process per core, everything on 127.0.0.1, no dashboard."""
    from distributed import LocalCluster

    return LocalCluster(
        n_workers=n_workers or os.cpu_count() or 1,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address="127.0.0.1:0",  # the scheduler's HTTP server: loopback, any free port
        worker_dashboard_address=None,  # workers' HTTP servers bind to their host, 127.0.0.1
    )


def _package_zip() -> bytes:
    """The tailsim package as zip bytes, for workers that do not have it."""
    pkg = pathlib.Path(__file__).resolve().parents[1]
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for f in sorted([*pkg.rglob("*.py"), *pkg.rglob("*.json")]):
            info = zipfile.ZipInfo(f"tailsim/{f.relative_to(pkg).as_posix()}", date_time=(2020, 1, 1, 0, 0, 0))
            z.writestr(info, f.read_bytes())
    return buf.getvalue()


def run_campaign(
    spec: CampaignSpec,
    out: str | pathlib.Path,
    dist: str | pathlib.Path = ROOT / "dist",
    *,
    client=None,
    scheduler: str | None = None,
    n_workers: int | None = None,
    serial: bool = False,
    upload: bool | None = None,
    progress: bool = True,
    flush_rows: int = 32,
    flush_seconds: float = 10.0,
    retries: int = 2,
    replace: bool = False,
    on_row: Callable[[dict, Any], None] | None = None,
):
    """Run the campaign's missing runs and return all its rows (a pyarrow Table).

    client / scheduler / neither: an existing Client, the address of an existing
    cluster, or an embedded LocalCluster (n_workers, default one per core).
    serial: run in this process, without Dask (the reference for tests).
    upload: send the tailsim package to the workers (default: with `scheduler`).
    replace: discard the runs in `out` if they belong to a different campaign
    (other specification or FMUs) instead of refusing.
    on_row(row, client): called after each recorded row (tests use it to interrupt
    or to kill a worker).
    """
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    blobs = load_fmu_bytes(dist, spec.controllers, spec.state_sources)
    digests = {n: digest(b) for n, b in blobs.items()}
    _check_campaign_file(out, spec, digests, replace)
    store = Store(out)
    done = store.done_keys()
    todo = [j for j in jobs(spec) if j["key"] not in done]
    spec_json = spec.to_json()
    writer = _Writer(store, flush_rows, flush_seconds)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(todo), unit="run", desc="campaign", smoothing=0.05)
    missing = 0
    t0 = time.perf_counter()
    t_compute = t_last = t0  # first submission (after any cluster start-up), last result
    n_workers_used = 1
    cluster = own_client = None

    def record(row, client) -> float:
        """Store a finished run and report it; returns when it arrived."""
        t = time.perf_counter()
        writer.add(row)
        if bar:
            bar.update()
        if on_row:
            on_row(row, client)
        return t

    try:
        if serial:
            install_fmus(blobs)
            t_compute = time.perf_counter()
            for j in todo:
                t_last = record(run_job(j, spec_json, digests), None)
        elif todo:
            from distributed import Client, as_completed

            if client is None:
                if scheduler:
                    own_client = client = Client(scheduler)
                else:
                    cluster = local_cluster(n_workers)
                    own_client = client = Client(cluster)
            from . import plugin as campaign_plugin

            package = None
            if upload if upload is not None else bool(scheduler):
                # Workers without tailsim: the plugin is pickled by value and brings the package.
                import cloudpickle

                cloudpickle.register_pickle_by_value(campaign_plugin)
                package = _package_zip()
            plugin = campaign_plugin.FmuPlugin(blobs, package)
            # One plugin per content, registered once (idempotent): re-registering would tear
            # down the instances of runs still executing after an interrupted campaign.
            key = "".join(sorted(digests.values())) + (digest(package) if package else "")
            client.register_plugin(plugin, name=f"{plugin.name}-{digest(key.encode())[:16]}")
            n_workers_used = sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values())
            token = uuid.uuid4().hex[:8]
            t_compute = time.perf_counter()
            futures = client.map(
                campaign_plugin.make_task() if package else run_job,
                todo,
                spec_json=spec_json,
                digests=digests,
                key=[f"tailsim-run-{token}-{j['key']}" for j in todo],
                retries=retries,
                pure=False,
            )
            try:
                pending = as_completed(futures)
                requeued: dict[str, int] = {}
                for fut in pending:
                    if fut.status in ("pending", "lost") and requeued.get(fut.key, 0) < 10:
                        # Finished, then its result was lost with its worker before it was
                        # gathered: the scheduler computes it again; wait for that.
                        requeued[fut.key] = requeued.get(fut.key, 0) + 1
                        pending.add(fut)
                        continue
                    if fut.status != "finished":  # failed more often than allowed: left for a resume
                        missing += 1
                        exc = fut.exception() if fut.status == "error" else fut.status
                        print(f"run {fut.key} not recorded: {exc!r}", file=sys.stderr)
                        continue
                    row = fut.result()
                    fut.release()
                    t_last = record(row, client)
            except BaseException:
                client.cancel(futures)
                raise
            n_workers_used = max(
                n_workers_used, sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values()), 1
            )
    finally:
        writer.flush()
        if bar:
            bar.close()
        if own_client is not None:
            own_client.close()
        if cluster is not None:
            cluster.close()
    elapsed, compute = time.perf_counter() - t0, t_last - t_compute
    table = store.read()
    import numpy as np
    import pyarrow.parquet as pq

    cpu = writer.cpu

    pq.write_table(table, out / "results.parquet")
    stats = {
        "runs_done_now": writer.written,
        "runs_total": table.num_rows,
        "not_recorded": missing,
        "elapsed_s": elapsed,
        "compute_s": compute,
        "worker_threads": n_workers_used,
        "runs_per_s": writer.written / compute if compute > 0 else float("nan"),
        "runs_per_s_per_worker_thread": writer.written / compute / n_workers_used if compute > 0 else float("nan"),
        # Load-independent: runs per second of one dedicated core (mean CPU time of a run).
        "runs_per_cpu_s": 1.0 / float(np.mean(cpu)) if cpu else float("nan"),
    }
    (out / "last_run.json").write_text(json.dumps(stats, indent=1))
    return table


# --- command line -------------------------------------------------------------------------


def parser() -> cli.Parser:
    atmosphere = "tailsitter_atmosphere"
    wind = declarations.VARIABLES[atmosphere]["wind_speed"]
    gust = declarations.VARIABLES[atmosphere]["gust_amplitude_n"]
    ap = cli.Parser(prog="python -m tailsim.campaign", description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="out/campaign", help="output folder (resumes what is there)")
    ap.add_argument("--dist", default=str(ROOT / "dist"), help="folder of the .fmu files")
    ap.add_argument(
        "--samples", type=cli.integer(1), default=64, help="number of samples, ≥ 1 (each flown by every controller)"
    )
    ap.add_argument("--seed", type=cli.integer(0), default=0, help="seed of the sample generators, ≥ 0")
    ap.add_argument(
        "--controllers",
        type=cli.choices_list(CONTROLLERS),
        default=CONTROLLERS,
        help=f"comma-separated, of {', '.join(CONTROLLERS)}",
    )
    ap.add_argument(
        "--configurations",
        type=cli.choices_list(tuple(CONFIGURATIONS)),
        default=("tuned",),
        help=f"comma-separated, of {', '.join(CONFIGURATIONS)}",
    )
    ap.add_argument(
        "--state-sources",
        type=cli.choices_list(STATE_SOURCES),
        default=("perfect",),
        help=f"comma-separated, of {', '.join(STATE_SOURCES)}",
    )
    ap.add_argument("--mission", choices=sorted(MISSIONS), default="default")
    ap.add_argument(
        "--aero-model", type=int, choices=(0, 1), default=1, help="plant aerodynamics: 1 global (default), 0 thesis"
    )
    ap.add_argument("--tau-aero", type=cli.number(1.0), default=1.5, help="aerodynamic factors in [1/τ, τ], τ ≥ 1")
    ap.add_argument("--tau-mass", type=cli.number(1.0), default=1.1, help="mass and inertia factors in [1/τ, τ], τ ≥ 1")
    ap.add_argument(
        "--wind-max",
        type=cli.declared(atmosphere, "wind_speed"),
        default=10.0,
        help=f"largest steady horizontal wind (m/s), within the declared [{wind.min:g}, {wind.max:g}] of `wind_speed`",
    )
    ap.add_argument(
        "--gust-max",
        type=cli.declared_magnitude(atmosphere, "gust_amplitude_n"),
        default=5.0,
        help=f"largest 1-cos gust amplitude (m/s), ≥ 0 and within the declared gust amplitudes "
        f"[{gust.min:g}, {gust.max:g}]",
    )
    ap.add_argument(
        "--turbulence-max",
        type=int,
        choices=TURBULENCE_LEVELS,
        help="largest Dryden turbulence intensity drawn (0 none, 1 light, 2 moderate, 3 severe; uniform on "
        "0..max; default 2, 0 with the avionics state source, which flies without the atmosphere)",
    )
    ap.add_argument(
        "--error-limit",
        type=cli.number(0.0, lo_open=True),
        default=5.0,
        help="a run flown to the end is completed only if its largest position error stays within this (m), > 0",
    )
    ap.add_argument(
        "--timeout", type=cli.number(0.0, lo_open=True), default=300.0, help="wall-time limit of one run (s), > 0"
    )
    ap.add_argument("--scheduler", type=_scheduler, help="tcp://HOST:PORT of an existing Dask scheduler")
    ap.add_argument("--workers", type=cli.integer(1), help="LocalCluster workers, ≥ 1 (default: one per core)")
    ap.add_argument("--serial", action="store_true", help="no Dask: run in this process")
    ap.add_argument("--replace", action="store_true", help="discard --out's runs if they are of another campaign/FMUs")
    ap.add_argument("--no-upload", action="store_true", help="workers already have tailsim importable")
    ap.add_argument("--no-progress", action="store_true")
    ap.add_argument("--report-only", action="store_true", help="only (re)write the report of what is in --out")
    ap.add_argument("--no-report", action="store_true")
    return ap


def _scheduler(text: str) -> str:
    if not re.fullmatch(r"([a-z]+://)?(\[[0-9a-fA-F:.]+\]|[^\s:/\[\]]+):\d+", text):
        raise argparse.ArgumentTypeError(f"{text!r}: expected an address [PROTOCOL://]HOST:PORT (tcp://HOST:8786)")
    return text


def main(argv: list[str] | None = None) -> int:
    ap = parser()
    a = ap.parse_args(argv)
    cli.check_out(ap, "--out", a.out)
    if a.report_only:
        if a.no_report:
            ap.error("argument --no-report: not allowed with --report-only (nothing to do)")
        if not (pathlib.Path(a.out) / "campaign.json").is_file():
            ap.error(f"argument --out: {a.out!r} holds no campaign (no campaign.json) for --report-only")
    else:
        names = ["plant", *a.controllers, *[n for s in a.state_sources for n in STATE_SOURCE_FMUS[s]]]
        cli.check_fmus(ap, "--dist", a.dist, [FMU_NAMES[n] for n in names])
    return cli.guard(ap.prog, a.debug, lambda: _main(a))


def _main(a: argparse.Namespace) -> int:
    out = pathlib.Path(a.out)
    if a.report_only:
        spec = CampaignSpec.from_json(json.loads((out / "campaign.json").read_text())["spec"])
    else:
        spec = CampaignSpec(
            seed=a.seed,
            n_samples=a.samples,
            controllers=a.controllers,
            configurations=a.configurations,
            state_sources=a.state_sources,
            tau_aero=a.tau_aero,
            tau_mass=a.tau_mass,
            aero_model=a.aero_model,
            wind_max=a.wind_max,
            gust_max=a.gust_max,
            turbulence_max=(
                a.turbulence_max if a.turbulence_max is not None else (0 if "avionics" in a.state_sources else 2)
            ),
            error_limit_m=a.error_limit,
            mission_name=a.mission,
            mission=dict(MISSIONS[a.mission]),
            timeout_s=a.timeout,
        )
        run_campaign(
            spec,
            out,
            a.dist,
            scheduler=a.scheduler,
            n_workers=a.workers,
            serial=a.serial,
            upload=False if a.no_upload else None,
            replace=a.replace,
            progress=not a.no_progress,
        )
        stats = json.loads((out / "last_run.json").read_text())
        if stats["runs_done_now"]:
            done = (
                f"{stats['runs_done_now']} runs in {stats['elapsed_s']:.1f} s ({stats['runs_per_s']:.2f} runs/s on "
                f"{stats['worker_threads']} worker threads after start-up, {stats['runs_per_cpu_s']:.1f} runs per "
                "CPU-second)"
            )
        else:
            done = "nothing to run (every run is already in the folder)"
        print(
            f"{done}; {stats['runs_total']} runs in {out}/results.parquet"
            + (f"; {stats['not_recorded']} not recorded (run again to resume)" if stats["not_recorded"] else "")
        )
    if not a.no_report:
        from .report import write_report

        path = write_report(out, spec)
        print(f"report: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
