"""The Monte-Carlo campaign : sampling, the runner against
ClosedLoop, and the Dask campaign on a 2-worker LocalCluster on 127.0.0.1
(distributed = serial, resume, a killed worker, a failing sample)."""

from __future__ import annotations

import dataclasses
import json
import math
import os
import pathlib

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException

from conftest import ROOT
from tailsim.campaign import Store, deterministic, local_cluster, run_campaign
from tailsim.campaign import runner as R
from tailsim.campaign.report import bootstrap_mean_ci, spearman, wilson_interval, write_report
from tailsim.campaign.sampling import (
    CONFIGURATIONS,
    CONTROLLERS,
    MISSIONS,
    TABLE_5_1,
    CampaignSpec,
    atmosphere_parameters,
    draw_sample,
    jobs,
    plant_parameters,
    sample_columns,
    wind_function,
)
from tailsim.masters import ClosedLoop

DIST = ROOT / "dist"
N = 3  # samples of the campaign tests: 6 runs of the short (11 s) mission


def short_spec(**kw) -> CampaignSpec:
    # The machinery tests fly the thesis aerodynamics: the short mission's 3 s / 4 s
    # transitions stall under the global model for most samples (a physics result, not
    # what these tests are about).
    kw.setdefault("aero_model", 0)
    kw.setdefault("n_samples", N)
    # The machinery tests compare runs with ClosedLoop's wind function: no turbulence (the
    # atmosphere's runs have tests of their own).
    kw.setdefault("turbulence_max", 0)
    kw.setdefault("wind_max", 5.0)
    # The machinery tests fly the two thesis controllers (the arms of both configurations);
    # the tests of the third arm say `controllers=CONTROLLERS`.
    kw.setdefault("controllers", ("lqr", "tsd"))
    return CampaignSpec(seed=7, mission_name="short", mission=dict(MISSIONS["short"]), **kw)


@pytest.fixture(scope="module")
def client():
    from distributed import Client

    with local_cluster(2) as cluster, Client(cluster) as c:
        c.wait_for_workers(2)
        yield c


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("serial")
    return run_campaign(short_spec(), out, DIST, serial=True, progress=False)


# --- sampling -----------------------------------------------------------------------------


def test_table_5_1_maps_to_plant_parameters_and_scales_both_alpha_points():
    from fmpy import read_model_description

    md = read_model_description(str(DIST / "tailsitter_plant.fmu"))
    params = {v.name: float(v.start) for v in md.modelVariables if v.causality == "parameter" and v.type == "Real"}
    assert len(TABLE_5_1) == 25
    names = [n for p in TABLE_5_1 for n in p.plant_params]
    assert all(n in params for n in names), [n for n in names if n not in params]
    s = draw_sample(short_spec(), 4)
    pp = plant_parameters(s, params)
    for p in TABLE_5_1:
        for n in p.plant_params:  # every point of a derivative gets the parameter's factor
            assert pp[n] == pytest.approx(params[n] * s[f"k_{p.name}"], rel=1e-15, abs=0.0)


def test_samples_are_reproducible_subsets_and_log_uniform():
    a, b = CampaignSpec(seed=11, n_samples=5), CampaignSpec(seed=11, n_samples=500)
    assert draw_sample(a, 3) == draw_sample(b, 3)  # sample i depends on (seed, i) only
    assert draw_sample(a, 3) != draw_sample(CampaignSpec(seed=12), 3)
    assert [j["sample_id"] for j in jobs(a)] == [i for i in range(5) for _ in CONTROLLERS]  # paired: every controller
    n = 4000
    samples = [draw_sample(b, i) for i in range(n)]
    for p in (TABLE_5_1[0], TABLE_5_1[-1]):
        tau = b.tau(p)
        x = np.log([s[f"k_{p.name}"] for s in samples])
        assert np.all(np.abs(x) <= math.log(tau))
        # ln k = u ln τ, u ~ U(−1, 1): mean 0, variance (ln τ)²/3.
        sd = math.log(tau) / math.sqrt(3)
        assert abs(x.mean()) < 4 * sd / math.sqrt(n)
        assert x.var() == pytest.approx(sd**2, rel=0.08)
    # steady wind ≤ wind_max, gust inside the mission
    s = samples[17]
    assert math.hypot(s["wind_steady_n"], s["wind_steady_e"]) <= b.wind_max
    assert 0 <= s["gust_start"] <= b.stop_time - s["gust_duration"]
    w = wind_function(s)
    t_peak = s["gust_start"] + s["gust_duration"] / 2
    assert w(t_peak) == pytest.approx((s["wind_steady_n"] + s["gust_n"], s["wind_steady_e"] + s["gust_e"], s["gust_d"]))


def test_wind_axis_draws_steady_wind_to_10_m_s_and_turbulence_after_the_other_draws():
    n = 3000
    spec = CampaignSpec(seed=5, n_samples=n)
    assert (spec.wind_max, spec.turbulence_max, spec.error_limit_m) == (10.0, 2, 5.0)
    samples = [draw_sample(spec, i) for i in range(n)]
    speed = np.array([math.hypot(s["wind_steady_n"], s["wind_steady_e"]) for s in samples])
    # U(0, 10): mean 5, standard deviation 10/√12; every band of 2 m/s holds ≈ 1/5.
    assert speed.min() >= 0.0 and speed.max() <= 10.0
    assert abs(speed.mean() - 5.0) < 4 * (10 / math.sqrt(12)) / math.sqrt(n)
    hist, _ = np.histogram(speed, bins=5, range=(0, 10))
    assert np.all(np.abs(hist / n - 0.2) < 4 * math.sqrt(0.2 * 0.8 / n)), hist
    level = np.array([s["turbulence_intensity"] for s in samples])
    assert set(level.tolist()) == {0, 1, 2}
    assert np.all(np.abs(np.bincount(level) / n - 1 / 3) < 4 * math.sqrt(2 / 9 / n))
    # The turbulence is drawn last: without it every other draw of a sample is the same.
    calm = draw_sample(dataclasses.replace(spec, turbulence_max=0), 7)
    assert calm["turbulence_intensity"] == 0
    assert {k: v for k, v in calm.items() if k != "turbulence_intensity"} == {
        k: v for k, v in samples[7].items() if k != "turbulence_intensity"
    }
    assert sample_columns()[-2:] == ["turbulence_seed", "turbulence_intensity"]
    # The atmosphere's steady wind is the sample's: −U (cos ψ_from, sin ψ_from) = (wind_n, wind_e).
    for s in samples[:50]:
        p = atmosphere_parameters(s)
        u, b = p["wind_speed"], p["wind_from"]
        assert 0.0 <= b < 2 * math.pi
        assert (-u * math.cos(b), -u * math.sin(b)) == pytest.approx(
            (s["wind_steady_n"], s["wind_steady_e"]), abs=1e-12
        )
        assert (p["turbulence_intensity"], p["seed"]) == (s["turbulence_intensity"], s["turbulence_seed"])
        assert (p["gust_amplitude_n"], p["gust_start"], p["gust_duration"]) == (
            s["gust_n"],
            s["gust_start"],
            s["gust_duration"],
        )


def test_completion_is_the_error_criterion_not_divergence_alone():
    assert R.error_failure(4.99, 5.0) == ("", "")
    assert R.error_failure(5.0, 5.0) == ("", "")
    failure, detail = R.error_failure(5.01, 5.0)
    assert failure == "error" and "5.01 m > 5 m" in detail
    assert R.error_failure(float("nan"), 5.0)[0] == "error"
    assert "error" in R.FAILURES
    with pytest.raises(ValueError, match="turbulence_max"):
        CampaignSpec(state_sources=("avionics",))
    CampaignSpec(state_sources=("avionics",), turbulence_max=0)
    with pytest.raises(ValueError, match="error_limit_m"):
        CampaignSpec(error_limit_m=0.0)


def test_unknown_axes_are_refused_clearly():
    with pytest.raises(ValueError, match="unknown configuration 'printed'"):
        CampaignSpec(configurations=("printed",))
    with pytest.raises(ValueError, match="unknown state source 'gps'"):
        CampaignSpec(state_sources=("gps",))
    with pytest.raises(ValueError, match="distinct"):
        CampaignSpec(configurations=("tuned", "tuned"))
    with pytest.raises(ValueError, match="no arm: .*'px4'"):
        CampaignSpec(controllers=("px4",), configurations=("thesis",))


def test_axes_multiply_runs_without_changing_the_draws():
    one = short_spec(n_samples=2)
    four = short_spec(n_samples=2, configurations=("tuned", "thesis"), state_sources=("perfect", "avionics"))
    a, b = jobs(one), jobs(four)
    assert len(a) == 2 * 2 and len(b) == 2 * 2 * 2 * 2
    # A controller without the thesis's `configuration` (PX4) is an arm of `tuned` only, on the
    # same samples: 3 tuned + 2 thesis arms per state source.
    assert "px4" in CONTROLLERS and "px4" in CONFIGURATIONS["tuned"] and "px4" not in CONFIGURATIONS["thesis"]
    three = short_spec(
        n_samples=2, controllers=CONTROLLERS, configurations=("tuned", "thesis"), state_sources=("perfect", "avionics")
    )
    c = jobs(three)
    assert len(c) == 2 * (3 + 2) * 2
    assert {(j["controller"], j["configuration"]) for j in c if j["controller"] == "px4"} == {("px4", "tuned")}
    b = b + [j for j in c if j["controller"] == "px4"]
    assert len({j["key"] for j in b}) == len(b)
    for j in b:  # every run of a sample sees the sample's draw, whatever its axes
        ref = next(x for x in a if x["sample_id"] == j["sample_id"])
        assert {k: j[k] for k in sample_columns()} == {k: ref[k] for k in sample_columns()}
        assert j["key"] == f"{j['sample_id']}/{j['controller']}/{j['configuration']}/{j['state_source']}"


# --- statistics ---------------------------------------------------------------------------


def test_wilson_interval_matches_newcombe_1998():
    # Newcombe, Stat. Med. 17 (1998) 857, Table I, method 3 (score, no continuity correction).
    for k, n, lo, hi in [
        (81, 263, 0.2553, 0.3662),
        (15, 148, 0.0624, 0.1605),
        (0, 20, 0.0, 0.1611),
        (1, 29, 0.0061, 0.1718),
    ]:
        assert wilson_interval(k, n) == pytest.approx((lo, hi), abs=6e-5)


def test_wilson_interval_contains_the_proportion():
    """Regression: round-off put the lower bound at k = 0 above 0 (2.8e-17), and the upper one at
    k = n below 1, so the error bars of the campaign's wind plot got a negative length."""
    for n in range(1, 300):
        for k in range(n + 1):
            lo, hi = wilson_interval(k, n)
            assert 0.0 <= lo <= k / n <= hi <= 1.0, (k, n, lo, hi)


def test_spearman_and_bootstrap():
    # ranks of y = 1, 2, 3.5, 5, 3.5: ρ = 8/√(10·9.5) (by hand)
    assert spearman([1, 2, 3, 4, 5], [5, 6, 7, 8, 7]) == pytest.approx(8 / math.sqrt(95), rel=1e-12)
    assert spearman([1, 2, 3, 4], [1, 10, math.inf, math.inf]) == pytest.approx(
        np.corrcoef([1, 2, 3, 4], [1, 2, 3.5, 3.5])[0, 1], rel=1e-12
    )
    assert spearman([0.1, 0.2, 0.3], np.exp([1, 2, 3])) == pytest.approx(1.0)
    d = np.random.default_rng(0).normal(1.0, 1.0, 400)
    lo, hi = bootstrap_mean_ci(d)
    half = 1.96 * d.std() / math.sqrt(d.size)  # normal-theory interval of the mean
    assert lo == pytest.approx(d.mean() - half, abs=0.25 * half) and hi == pytest.approx(
        d.mean() + half, abs=0.25 * half
    )


# --- the runner ---------------------------------------------------------------------------


def test_reset_and_reuse_run_equals_closed_loop(fmus):
    spec = short_spec()
    blobs = R.load_fmu_bytes(DIST, ["lqr", "tsd"])
    dig = R.install_fmus(blobs)
    js = jobs(spec)
    first = R.run_job(js[0], spec.to_json(), dig)  # uses (then keeps) one LQR and one plant instance
    assert first["completed"], first
    j = js[2]  # sample 1, LQR: flown on the reset instances
    assert j["controller"] == "lqr"
    plant, ctrl = fmus["tailsitter_plant"], fmus["tailsitter_lqr"]
    nominal = {n: float(v.start) for n, v in plant.variables.items() if v.causality == "parameter" and v.type == "Real"}
    pp = plant_parameters(j, nominal)
    pp["aero_model"] = spec.aero_model
    ref = ClosedLoop(plant, ctrl, pp, dict(spec.mission)).run(
        stop_time=spec.stop_time, step_size=spec.step_size, wind=wind_function(j)
    )
    ps, cs = R._instance(dig["plant"], "plant"), R._instance(dig["lqr"], "controller")
    assert ps.used and cs.used
    ps.slave.reset()
    cs.slave.reset()
    sig, failure, _ = R.fly(
        ps.fmu, ps.slave, cs.fmu, cs.slave, pp, dict(spec.mission), wind_function(j), spec.stop_time, spec.step_size
    )
    assert failure == ""
    for name, v in sig.items():
        assert np.array_equal(v, ref[name]), name  # bit for bit
    row = R.run_job(j, spec.to_json(), dig)
    ref_metrics = R.run_metrics({k: ref[k] for k in sig})
    for k, v in ref_metrics.items():
        assert row[k] == v or (math.isnan(v) and math.isnan(row[k])), k
    assert row["t_end"] == pytest.approx(spec.stop_time) and row["last_phase"] == 4


def test_thesis_configuration_run_equals_closed_loop_with_configuration_1(fmus):
    """The `thesis` axis sets the controller's `configuration` = 1 and nothing else."""
    spec = short_spec(configurations=("thesis",))
    dig = R.install_fmus(R.load_fmu_bytes(DIST, ["lqr", "tsd"]))
    plant = fmus["tailsitter_plant"]
    nominal = {n: float(v.start) for n, v in plant.variables.items() if v.causality == "parameter" and v.type == "Real"}
    for j in jobs(spec, [1]):
        assert j["configuration"] == "thesis"
        pp = plant_parameters(j, nominal)
        pp["aero_model"] = spec.aero_model
        ctrl = fmus[f"tailsitter_{j['controller']}"]

        def fly(controller_params, ctrl=ctrl, pp=pp, j=j):
            # What the campaign keeps of a flight: up to an FMI error status, and up to the
            # first row beyond the divergence bound.
            try:
                r = ClosedLoop(plant, ctrl, pp, controller_params).run(
                    stop_time=spec.stop_time, step_size=spec.step_size, wind=wind_function(j)
                )
            except FMICallException as exc:
                r = exc.partial_result
            names = ("time", "phase", "pos_d", "alpha", "ref_pos_d", "pos_error", *R.COMMANDS)
            over = np.nonzero(~(r["pos_error"] <= spec.divergence_m))[0]
            end = int(over[0]) if len(over) else len(r["time"])  # the monitor stops before it
            return {k: r[k][:end] for k in names}

        ref = fly({**spec.mission, "configuration": 1})
        tuned = fly(dict(spec.mission))
        row = R.run_job(j, spec.to_json(), dig)
        want = R.run_metrics(ref)
        for k, v in want.items():
            assert row[k] == v or (math.isnan(v) and math.isnan(row[k])), (j["key"], k)
        # and the configuration changes the flight (the parameter reached the controller)
        assert abs(row["rms_err"] - math.sqrt(np.mean(tuned["pos_error"] ** 2))) > 1e-3, j["key"]


def test_avionics_run_equals_the_avionics_loop_with_the_sample_seed(fmus):
    """The `avionics` axis flies tailsim.masters.avionics' chain with the sensors' seed = the sample's
    noise_seed; errors are the TRUE position against the reference."""
    from tailsim.masters import pos_error
    from tailsim.masters.avionics import AvionicsLoop

    spec = short_spec(state_sources=("avionics",), controllers=("lqr",))
    dig = R.install_fmus(R.load_fmu_bytes(DIST, ["lqr"], ["avionics"]))
    assert {"sensors", "ekf"} <= set(dig)
    j = jobs(spec, [2])[0]
    row = R.run_job(j, spec.to_json(), dig)
    assert row["completed"], row["detail"]
    plant = fmus["tailsitter_plant"]
    nominal = {n: float(v.start) for n, v in plant.variables.items() if v.causality == "parameter" and v.type == "Real"}
    pp = plant_parameters(j, nominal)
    pp["aero_model"] = spec.aero_model
    sensors, ekf = fmus["tailsitter_sensors"], fmus["tailsitter_ekf"]

    def metrics(seed):
        r = AvionicsLoop(
            plant,
            sensors,
            ekf,
            fmus["tailsitter_lqr"],
            plant_params=pp,
            sensors_params={"seed": seed},
            controller_params=dict(spec.mission),
        ).run(stop_time=spec.stop_time, step_size=spec.step_size, wind=wind_function(j))
        sig = {k: r[k] for k in ("time", "phase", "pos_d", "alpha", "ref_pos_d", *R.COMMANDS)}
        sig["phase"] = sig["phase"].astype(np.int64)
        sig["pos_error"] = pos_error(r)
        return R.run_metrics(sig)

    want = metrics(j["noise_seed"])
    for k, v in want.items():
        assert row[k] == v or (math.isnan(v) and math.isnan(row[k])), k
    other = metrics(j["noise_seed"] + 1)  # the seed reaches the sensors: other noise, other flight
    assert abs(other["rms_err"] - row["rms_err"]) > 1e-6


# --- the Dask campaign --------------------------------------------------------------------


def test_embedded_cluster_listens_on_loopback_only(client):
    import psutil

    # the worker processes: every socket they listen on
    pids = set(client.run(os.getpid).values())
    assert len(pids) == 2 and os.getpid() not in pids
    listening = [
        c.laddr.ip
        for pid in pids
        for c in psutil.Process(pid).net_connections(kind="inet")
        if c.status == psutil.CONN_LISTEN
    ]
    # the scheduler and the nannies (in this process): their comm and HTTP ports
    sched = client.cluster.scheduler
    ports = {int(sched.address.rsplit(":", 1)[1]), sched.http_server.port}
    ports |= {int(w["nanny"].rsplit(":", 1)[1]) for w in client.scheduler_info()["workers"].values()}
    mine = [
        c
        for c in psutil.Process().net_connections(kind="inet")
        if c.status == psutil.CONN_LISTEN and c.laddr.port in ports
    ]
    assert len(mine) == len(ports) == 4
    listening += [c.laddr.ip for c in mine]
    assert len(listening) >= 6 and set(listening) == {"127.0.0.1"}, listening


def test_distributed_equals_serial(client, serial, tmp_path):
    assert serial.num_rows == 2 * N
    assert all(serial.column("completed").to_pylist()), serial.column("detail").to_pylist()
    table = run_campaign(short_spec(), tmp_path, DIST, client=client, progress=False)
    assert deterministic(table).equals(deterministic(serial))
    assert all(w.startswith("tcp://127.0.0.1:") for w in table.column("worker").to_pylist())
    # each worker keeps (at most) one instance per FMU, reset between its runs
    held = list(client.run(R.instances).values())
    assert any(held) and all(n == 1 for h in held for n in h.values()), held


def test_existing_cluster_without_tailsim_runs_the_same_campaign(serial, tmp_path):
    """--scheduler: a separately started scheduler and workers (loopback), whose Python
    cannot import tailsim (hidden from their sys.path, another cwd): the package and the FMUs are sent."""
    import subprocess
    import sys
    import time

    dask_cli = str(pathlib.Path(sys.executable).parent / "dask")
    # The venv has tailsim installed (editable: its folder on sys.path through a .pth);
    # a sitecustomize drops that entry in the cluster's processes, as on a machine
    # without the package.
    hide = tmp_path / "hide"
    hide.mkdir()
    (hide / "sitecustomize.py").write_text(
        "import os, sys\n"
        "sys.path[:] = [p for p in sys.path if not os.path.isfile(os.path.join(p, 'tailsim', '__init__.py'))]\n"
    )
    env = {**os.environ, "PYTHONPATH": str(hide)}
    sched_file = tmp_path / "scheduler.json"
    log = open(tmp_path / "cluster.log", "w")
    common = dict(cwd=tmp_path, env=env, stdout=log, stderr=subprocess.STDOUT)
    procs = [
        subprocess.Popen(
            [
                dask_cli,
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--dashboard-address",
                "127.0.0.1:0",
                "--scheduler-file",
                str(sched_file),
            ],
            **common,
        )
    ]
    try:
        deadline = time.monotonic() + 60
        while not sched_file.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        procs.append(
            subprocess.Popen(
                [
                    dask_cli,
                    "worker",
                    "--scheduler-file",
                    str(sched_file),
                    "--host",
                    "127.0.0.1",
                    "--nthreads",
                    "1",
                    "--nworkers",
                    "2",
                    "--dashboard-address",
                    "127.0.0.1:0",
                ],
                **common,
            )
        )
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        probe = subprocess.run([sys.executable, "-c", "import tailsim"], cwd=tmp_path, env=env, capture_output=True)
        assert probe.returncode != 0  # the workers' Python does not have tailsim
        table = run_campaign(short_spec(), tmp_path / "out", DIST, scheduler=address, progress=False)
        assert deterministic(table).equals(deterministic(serial))
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in reversed(procs):
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()


def test_interrupted_campaign_resumes_to_the_same_content(client, serial, tmp_path):
    seen = []

    def interrupt(row, _client):
        seen.append(row["key"])
        if len(seen) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_campaign(short_spec(), tmp_path, DIST, client=client, progress=False, flush_rows=1, on_row=interrupt)
    kept = Store(tmp_path).done_keys()
    assert set(seen) <= kept and len(kept) < 2 * N
    again = []
    table = run_campaign(
        short_spec(), tmp_path, DIST, client=client, progress=False, on_row=lambda r, c: again.append(r["key"])
    )
    assert not set(again) & kept  # completed runs are skipped
    assert deterministic(table).equals(deterministic(serial))


def test_killed_worker_loses_no_sample(client, serial, tmp_path):
    """A worker process dies mid-campaign (runs are recorded after its death): every run
    is still recorded, equal to the serial run's, and the nanny replaces the process.

    Robust under load: the killed process is identified by its pid, not its address (the
    restarted worker may get the same port), and the replacement is awaited by polling
    until the scheduler lists two workers none of which is the killed process — the
    scheduler may still list the dead worker for a while after the campaign ended (it
    notices a closed connection asynchronously), so `wait_for_workers(2)` alone could
    return at once with the dead worker counted."""
    import time

    killed, after = [], []

    def kill_one(row, c):
        if killed:
            after.append(row["key"])
            return
        busy = [w for w, tasks in c.processing().items() if tasks] or list(c.scheduler_info()["workers"])
        victim = busy[0]
        pid = c.run(os.getpid, workers=[victim])[victim]
        killed.append((victim, pid))
        try:
            c.run(os._exit, 1, workers=[victim])  # the worker process dies mid-campaign
        except Exception:  # noqa: BLE001 - its connection closes instead of answering
            pass

    table = run_campaign(short_spec(), tmp_path, DIST, client=client, progress=False, on_row=kill_one)
    assert killed and after  # killed after the first row, with runs still to record
    assert deterministic(table).equals(deterministic(serial))
    _, pid = killed[0]
    deadline, pids = time.monotonic() + 120, None
    while time.monotonic() < deadline:
        if len(client.scheduler_info()["workers"]) == 2:
            try:
                pids = set(client.run(os.getpid).values())
            except Exception:  # noqa: BLE001 - a worker listed but already gone
                pids = None
            if pids is not None and len(pids) == 2 and pid not in pids:
                break
        time.sleep(0.2)
    assert pids is not None and len(pids) == 2 and pid not in pids, pids  # restarted (with the FMU plugin)
    # the replacement got the FMUs from the plugin
    wanted = {R.digest(b) for b in R.load_fmu_bytes(DIST, ["lqr", "tsd"]).values()}
    held = client.run(lambda: sorted(R._fmus))
    assert all(wanted <= set(v) for v in held.values()), held


def test_failing_sample_is_a_recorded_failure(client, serial, tmp_path):
    spec = short_spec(overrides={1: {"mass": -1.0}})  # outside the plant's [0.1, 1000] kg
    table = run_campaign(spec, tmp_path, DIST, client=client, progress=False)
    rows = {r["key"]: r for r in table.to_pylist()}
    ref = {r["key"]: r for r in serial.to_pylist()}
    assert len(rows) == 2 * N
    for key, r in rows.items():
        if r["sample_id"] == 1:
            assert not r["completed"] and r["failure"] == "fmi_error"
            assert "mass" in r["detail"], r["detail"]  # the FMU's own message is kept
        else:
            assert r["completed"] and r["max_err"] == ref[key]["max_err"]


def test_tumble_mid_flight_is_a_divergence_and_the_next_run_is_clean(serial, tmp_path):
    # Pitch-rate damping of the wrong sign (C_mq = +30 instead of −7.6): the aircraft
    # tumbles and the plant stops with its envelope error (|q| > 50 rad/s).
    spec = short_spec(n_samples=2, overrides={0: {"c_m_q_a0": 30.0, "c_m_q_a1": 30.0}})
    rows = {r["key"]: r for r in run_campaign(spec, tmp_path, DIST, serial=True, progress=False).to_pylist()}
    ref = {r["key"]: r for r in serial.to_pylist()}
    for c in ("lqr", "tsd"):
        r = rows[f"0/{c}/tuned/perfect"]
        assert not r["completed"] and r["failure"] == "divergence" and "envelope" in r["detail"], r["detail"]
        assert 0 < r["t_end"] < spec.stop_time and r["max_err_p0"] >= 0  # metrics of what was flown
        clean = rows[f"1/{c}/tuned/perfect"]  # flown on fresh instances after the error
        assert clean["completed"] and clean["max_err"] == ref[f"1/{c}/tuned/perfect"]["max_err"]


def test_avionics_tumble_keeps_what_was_flown(tmp_path):
    """Issue 14: with avionics in the loop, a plant envelope error mid-flight is a divergence
    whose metrics cover what was flown (the phase reached, t_end, the errors so far), as on
    the perfect state. The avionics loop used to drop its record on an FMI error, so every
    such run was reported as failing "before the first step" (LQR 13, TSD 43 of 200)."""
    spec = short_spec(n_samples=1, state_sources=("avionics",), overrides={0: {"c_m_q_a0": 30.0, "c_m_q_a1": 30.0}})
    rows = {r["key"]: r for r in run_campaign(spec, tmp_path, DIST, serial=True, progress=False).to_pylist()}
    for c in ("lqr", "tsd"):
        r = rows[f"0/{c}/tuned/avionics"]
        assert not r["completed"] and r["failure"] == "divergence" and "envelope" in r["detail"], r["detail"]
        assert 0 < r["t_end"] < spec.stop_time, r["t_end"]
        assert f"at t = {r['t_end']:.2f} s" in r["detail"], r["detail"]  # the last recorded step
        assert math.isfinite(r["last_phase"]) and r["last_phase"] >= 0
        assert r["max_err_p0"] >= 0 and r["max_err"] >= r["max_err_p0"]


def test_native_campaign_flies_identical_jobs_to_the_same_rows(serial, tmp_path):
    """The native Rust loop (`analysis campaign-jobs`) on the campaign's jobs: the same
    outcome for every run (an invalid parameter, a tumble) and the same metrics, to the
    summation order of the RMS values (campaign_native.TOLERANCE), both configurations."""
    from tailsim.campaign.native import TOLERANCE, compare, run_native

    faults = {1: {"c_m_q_a0": 30.0, "c_m_q_a1": 30.0}, 3: {"mass": -1.0}}  # a tumble, an invalid value
    # Samples 0 and 1 of seed 7 draw light and moderate turbulence: their wind is the atmosphere's in both engines.
    spec = short_spec(
        n_samples=N + 1,
        controllers=CONTROLLERS,
        configurations=("tuned", "thesis"),
        overrides=faults,
        turbulence_max=2,
    )
    assert [draw_sample(spec, i)["turbulence_intensity"] for i in range(N + 1)] == [1, 2, 0, 0]
    fmpy_rows = run_campaign(spec, tmp_path / "fmpy", DIST, serial=True, progress=False).to_pylist()
    # The release binary when one was built (fast); else the debug one (same numbers, slower).
    profile = "release" if (ROOT / "target" / "release" / "analysis").exists() else "debug"
    native, _ = run_native(spec, DIST, threads=1, workdir=tmp_path / "native", profile=profile)
    assert len(native) == len(fmpy_rows) == (N + 1) * (3 + 2)  # PX4: the tuned configuration only
    cmp = compare(fmpy_rows, native)
    assert cmp["runs"] == len(native) and not cmp["outcome_differs"], cmp["outcome_differs"]
    assert not cmp["beyond_tolerance"], cmp["beyond_tolerance"]
    outcome = {r["key"]: (r["completed"], r["failure"]) for r in native}
    assert outcome["1/px4/tuned/perfect"] == (False, "divergence")
    assert outcome["3/px4/tuned/perfect"] == (False, "fmi_error")
    for c in ("lqr", "tsd"):
        for cfg in ("tuned", "thesis"):
            assert outcome[f"1/{c}/{cfg}/perfect"] == (False, "divergence")
            assert outcome[f"3/{c}/{cfg}/perfect"] == (False, "fmi_error")
        # The thesis configurations fly the printed design, which may lose this short
        # mission's 3/4 s transitions; the tuned ones complete it without turbulence.
        assert outcome[f"2/{c}/tuned/perfect"] == (True, "")
    # In 7.6 m/s and light turbulence the thesis LQR flies to the end, but beyond the 5 m
    # error limit (20.7 m): not completed, in both engines; both tuned controllers complete
    # (LQR 3.6 m, TSD 1.1 m).
    assert outcome["0/lqr/thesis/perfect"] == (False, "error")
    assert outcome["0/lqr/tuned/perfect"] == (True, "")
    assert outcome["0/tsd/tuned/perfect"] == (True, "")
    # the tuned rows are those of the fixture's campaign (a different overrides map, same samples)
    ref = {r["key"]: r for r in serial.to_pylist()}
    for r in native:
        if r["key"] in ref and r["key"].split("/")[0] == "2":
            assert r["max_err"] == ref[r["key"]]["max_err"]
            assert abs(r["rms_err"] - ref[r["key"]]["rms_err"]) <= TOLERANCE


def test_resume_refuses_a_different_campaign_unless_replace(serial, tmp_path):
    other = {"spec": short_spec(tau_aero=2.0).to_json(), "fmus": {}}
    (tmp_path / "campaign.json").write_text(json.dumps(other))
    Store(tmp_path).write([{"key": "0/lqr/tuned/perfect", "sample_id": 0}])  # a run of the other campaign
    with pytest.raises(SystemExit, match="different campaign"):
        run_campaign(short_spec(), tmp_path, DIST, serial=True, progress=False)
    assert Store(tmp_path).done_keys() == {"0/lqr/tuned/perfect"}  # nothing discarded
    table = run_campaign(short_spec(), tmp_path, DIST, serial=True, progress=False, replace=True)
    assert deterministic(table).equals(deterministic(serial))  # the other campaign's run is gone


def test_comparison_section_is_the_paired_result(serial, tmp_path):
    """tailsim.campaign.section (the comparison report's first section): Wilson intervals and
    paired TSD − LQR differences of the campaign's rows; campaigns of other samples refused."""
    import pyarrow.parquet as pq

    from tailsim.campaign import section as S

    for name, spec in (("a", short_spec()), ("b", dataclasses.replace(short_spec(), seed=8))):
        (tmp_path / name).mkdir()
        pq.write_table(serial, tmp_path / name / "results.parquet")
        (tmp_path / name / "campaign.json").write_text(json.dumps({"spec": spec.to_json(), "fmus": {}}))
    s = S.summarize([tmp_path / "a"])
    rows = serial.to_pylist()
    for c in ("lqr", "tsd"):
        r = s["arms"][f"{c}/tuned/perfect"]
        k = sum(x["completed"] for x in rows if x["controller"] == c)
        assert (r["runs"], r["completed"]) == (N, k) and r["wilson95"] == list(wilson_interval(k, N))
    p = s["paired"]["tuned/perfect"]
    by = {(x["sample_id"], x["controller"]): x for x in rows}
    d = [by[(i, "tsd")]["rms_err"] - by[(i, "lqr")]["rms_err"] for i in range(N)]
    assert p["completion"]["n"] == N and p["rms_err"]["n"] == N
    assert p["rms_err"]["mean"] == pytest.approx(np.mean(d), rel=1e-12)
    assert p["rms_err"]["ci95"][0] <= p["rms_err"]["mean"] <= p["rms_err"]["ci95"][1]
    with pytest.raises(SystemExit, match="seed"):
        S.summarize([tmp_path / "a", tmp_path / "b"])
    (tmp_path / "out").mkdir()
    (tmp_path / "a").rename(tmp_path / "out" / "campaign")
    text = "\n".join(S.report_section(tmp_path / "out"))
    assert "## Comparison: paired Monte-Carlo" in text
    assert "tuned/perfect | TSD − LQR | RMS position error (m) | 3 |" in text


def test_comparison_section_pairs_every_two_controllers(tmp_path):
    """Three controllers: the summary holds each pair's paired difference (later-declared
    minus earlier), TSD − LQR under its old key, and the Markdown names each pair."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from tailsim.campaign import section as S

    n, rows = 8, []
    rms = {"lqr": 1.0, "tsd": 0.5, "px4": 2.0}
    for i in range(n):
        for c in ("lqr", "tsd", "px4"):
            done = not (c == "px4" and i % 2)
            rows.append(
                {
                    "sample_id": i,
                    "controller": c,
                    "configuration": "tuned",
                    "state_source": "perfect",
                    "completed": done,
                    "failure": "" if done else "divergence",
                    "rms_err": rms[c] + 0.1 * i,
                    "max_err": 2 * rms[c],
                }
            )
    (tmp_path / "c").mkdir()
    pq.write_table(pa.Table.from_pylist(rows), tmp_path / "c" / "results.parquet")
    (tmp_path / "c" / "campaign.json").write_text(json.dumps({"spec": short_spec().to_json(), "fmus": {}}))
    s = S.summarize([tmp_path / "c"])
    assert set(s["paired"]) == {"tuned/perfect", "tuned/perfect: PX4 − LQR", "tuned/perfect: PX4 − TSD"}
    p = s["paired"]["tuned/perfect: PX4 − TSD"]
    assert p["pair"] == ["px4", "tsd"]
    assert p["completion"]["mean"] == pytest.approx(-0.5) and p["completion"]["n"] == n
    assert p["rms_err"]["n"] == n // 2 and p["rms_err"]["mean"] == pytest.approx(1.5)
    assert s["paired"]["tuned/perfect"]["rms_err"]["mean"] == pytest.approx(-0.5)
    assert s["arms"]["px4/tuned/perfect"]["completed"] == n // 2
    md = "\n".join(S.markdown(s, "three"))
    assert "| tuned/perfect | PX4 − LQR | completion | 8 | -0.500 |" in md
    assert "| tuned/perfect | TSD − LQR | RMS position error (m) | 8 | -0.500 |" in md
    # Merged into a documented run (`--base`): each arm from the summary with more runs.
    base = {
        "spec": s["spec"],
        "samples": {"lqr/tuned/perfect": 100},
        "arms": {"lqr/tuned/perfect": {**s["arms"]["lqr/tuned/perfect"], "runs": 100}},
        "paired": {},
        "runtime": [{"folder": "old"}],
    }
    m = S.merge(base, s)
    assert m["arms"]["lqr/tuned/perfect"]["runs"] == 100 and m["samples"]["lqr/tuned/perfect"] == 100
    assert m["arms"]["px4/tuned/perfect"] == s["arms"]["px4/tuned/perfect"]
    assert m["paired"] == s["paired"] and m["runtime"][0] == {"folder": "old"}
    with pytest.raises(SystemExit, match="seed"):
        S.merge({**base, "spec": {**s["spec"], "seed": 99}}, s)


def test_report(serial, tmp_path):
    path = write_report(tmp_path, short_spec(), serial)
    text = path.read_text()
    for needle in ("Wilson", "Paired differences", "| TSD − LQR | completion |", "Spearman", "chapter-6"):
        assert needle in text
    for png in ("completion.png", "distributions.png", "paired.png", "drivers.png"):
        assert (tmp_path / png).stat().st_size > 5000


def test_every_avionics_state_source_sets_declared_ekf_parameters():
    """Each avionics arm flies the sensors and the EKF, with EKF parameters the EKF declares:
    `avionics` its defaults, `avionics_app_d` the App.-D-faithful switch on."""
    from tailsim import declarations
    from tailsim.campaign.sampling import STATE_SOURCES

    ekf = declarations.VARIABLES["tailsitter_ekf"]
    avionics = [s for s in STATE_SOURCES if s != "perfect"]
    assert set(avionics) == set(R.AVIONICS_EKF_PARAMS)
    for s in avionics:
        assert R.STATE_SOURCE_FMUS[s] == ("sensors", "ekf")
        for name in R.AVIONICS_EKF_PARAMS[s]:
            assert ekf[name].causality == "parameter", name
    assert R.AVIONICS_EKF_PARAMS["avionics"] == {}
    assert R.AVIONICS_EKF_PARAMS["avionics_app_d"] == {"app_d_configuration": True}
    assert CampaignSpec(state_sources=("avionics_app_d",)).state_sources == ("avionics_app_d",)
