"""One campaign run, on whatever process executes it (a Dask worker or the caller).

The process keeps the FMUs it was given (as bytes: no shared filesystem is
assumed) extracted in a temp dir of its own, and one instance per FMU (per
thread), reset (fmi2Reset) between runs. A run is `ClosedLoop`'s system
(`tailsim.masters`, Gauss-Seidel) on these instances: it only records fewer
signals and stops early on divergence or timeout. tests/test_campaign.py checks
that a run equals ClosedLoop's exactly.

Any failure of a run (an FMI error status, a Python exception) becomes a failed
row; it never propagates, so one bad sample cannot crash a campaign.
"""

from __future__ import annotations

import collections
import hashlib
import json
import math
import os
import pathlib
import shutil
import socket
import tempfile
import threading
import time
from collections.abc import Mapping
from typing import Any

import numpy as np
from fmpy.fmi1 import FMICallException

from .. import controllers, declarations, fmilog
from ..masters import AvionicsLoop, ClosedLoop, Fmu, NonFinite, pos_error
from .sampling import CONFIGURATIONS, CampaignSpec, atmosphere_parameters, plant_parameters, wind_function

FMU_NAMES = {
    "plant": "tailsitter_plant",
    **controllers.NAMES,
    "sensors": "tailsitter_sensors",
    "ekf": "tailsitter_ekf",
    "atmosphere": "tailsitter_atmosphere",
}
#: The FMUs a state source needs beside the plant and the controllers (the perfect state
#: source flies the samples with turbulence through the atmosphere).
STATE_SOURCE_FMUS = {
    "perfect": ("atmosphere",),
    "avionics": ("sensors", "ekf"),
    "avionics_app_d": ("sensors", "ekf"),
}
#: EKF parameters of each avionics state source: `avionics` the tuned estimator (the FMU's
#: defaults), `avionics_app_d` the thesis App.-D-faithful one (Table D.1 variances, no extras).
AVIONICS_EKF_PARAMS = {"avionics": {}, "avionics_app_d": {"app_d_configuration": True}}
N_PHASES = len(declarations.PHASES)
#: Command limits of the saturation metric: the plant's declared thrust limits and surface
#: deflection limit (its parameters' defaults).
THRUST_LIMITS = declarations.THRUST_LIMITS
DEFLECTION_LIMIT = declarations.DEFLECTION_LIMIT
#: The commands, thrust first.
COMMANDS = list(declarations.COMMANDS)
#: `error`: flown to the stop time, but the largest position error exceeded the spec's
#: `error_limit_m`.
FAILURES = ("fmi_error", "divergence", "timeout", "exception", "error")


def digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


# --- the FMUs and instances this process holds --------------------------------------------

_lock = threading.Lock()
_fmus: dict[str, Fmu] = {}  # by sha256 of the .fmu bytes
_dirs: list[str] = []
_slaves: dict[tuple[int, str], _Slave] = {}  # (thread id, digest) -> instance


class _Slave:
    """An fmpy instance (uniquely named) with the last messages the FMU logged for it."""

    def __init__(self, fmu: Fmu, name: str):
        self.name = f"{name}-{fmu.identifier}-{threading.get_ident()}"
        self.messages: collections.deque[str] = collections.deque(maxlen=8)
        fmilog.route(self.name, lambda status, _category, message: self.messages.append(f"[{status}] {message}"))
        self.fmu = fmu
        self.slave = fmu.instantiate(self.name)
        self.used = False

    def free(self) -> None:
        try:
            self.slave.freeInstance()
        except Exception:  # noqa: BLE001 - already broken; drop it
            pass
        fmilog.unroute(self.name)


def install_fmus(blobs: Mapping[str, bytes]) -> dict[str, str]:
    """Extract FMUs given as bytes (once per content) into a temp dir of this process.
    Returns {name: digest}."""
    out = {}
    with _lock:
        for name, data in blobs.items():
            d = digest(data)
            out[name] = d
            if d in _fmus:
                continue
            tmp = tempfile.mkdtemp(prefix=f"tailsim-campaign-{os.getpid()}-")
            _dirs.append(tmp)
            path = pathlib.Path(tmp) / f"{name}.fmu"
            path.write_bytes(data)
            _fmus[d] = Fmu(path, pathlib.Path(tmp) / "x")
    return out


def release_all() -> None:
    """Free every instance and remove the extracted FMUs of this process."""
    with _lock:
        for s in _slaves.values():
            s.free()
        _slaves.clear()
        _fmus.clear()
        for d in _dirs:
            shutil.rmtree(d, ignore_errors=True)
        _dirs.clear()


def instances() -> dict[str, int]:
    """How many instances this process holds, by model identifier (for tests and monitoring)."""
    out: dict[str, int] = {}
    for s in _slaves.values():
        out[s.fmu.identifier] = out.get(s.fmu.identifier, 0) + 1
    return out


def _instance(d: str, role: str) -> _Slave:
    key = (threading.get_ident(), d)
    s = _slaves.get(key)
    if s is None:
        if d not in _fmus:
            raise RuntimeError(f"FMU {d[:12]} not installed on this worker (plugin missing?)")
        s = _Slave(_fmus[d], role)
        _slaves[key] = s
    return s


def _discard(d: str) -> None:
    s = _slaves.pop((threading.get_ident(), d), None)
    if s is not None:
        s.free()


# --- the closed loop ---------------------------------------------------------------------


class Diverged(Exception):
    pass


class TimedOut(Exception):
    pass


#: What a campaign run records: plant outputs, then controller outputs.
RECORD_PLANT = ["pos_d", "alpha"]
RECORD_CONTROLLER = ["ref_pos_d", "pos_error", "phase", *COMMANDS]


def fly(
    plant: Fmu,
    p,
    controller: Fmu,
    c,
    plant_params: Mapping[str, float],
    controller_params: Mapping[str, float],
    wind,
    stop_time: float,
    step_size: float,
    divergence_m: float = math.inf,
    deadline: float = math.inf,
    atmosphere: tuple[Fmu, Any, Mapping[str, float]] | None = None,
) -> tuple[dict[str, np.ndarray], str, str]:
    """Fly instances `p`, `c` (freshly instantiated or reset) through `ClosedLoop`'s
    system (Gauss-Seidel, zero ref_offset), stopping early on divergence or timeout.
    `atmosphere` = (FMU, instance, parameters): the wind from the atmosphere unit instead of
    the function `wind`.

    Returns the recorded signals (up to where it stopped) — time, phase, pos_error,
    ref_pos_d, pos_d, alpha and the seven commands, as ClosedLoop records them —
    and (failure, detail) with failure '' when it reached the stop time.
    """
    slaves = {"plant": p, "controller": c}
    if atmosphere is None:
        loop = ClosedLoop(plant, controller, plant_params, controller_params)
    else:
        fmu, slaves["atmosphere"], params = atmosphere
        loop = ClosedLoop(plant, controller, plant_params, controller_params, atmosphere=fmu, atmosphere_params=params)
        wind = None
    system = loop.system(wind, None, RECORD_PLANT, RECORD_CONTROLLER, finite_sources=["plant"])
    i_err = system.signal_names().index("pos_error")

    def monitor(k: int, t: float, row: np.ndarray) -> None:
        e = row[i_err]
        if not e <= divergence_m:
            raise Diverged(f"position error {e:.1f} m > {divergence_m:g} m at t = {t:.2f} s")
        if k % 50 == 0 and time.perf_counter() > deadline:
            raise TimedOut(f"wall-time limit reached at t = {t:.2f} s")

    failure = detail = ""
    try:
        r = system.run(stop_time, step_size, slaves=slaves, monitor=monitor)
    except (Diverged, NonFinite) as exc:
        failure, detail, r = "divergence", str(exc), exc.partial_result
    except TimedOut as exc:
        failure, detail, r = "timeout", str(exc), exc.partial_result
    except FMICallException as exc:  # an error status mid-flight: keep what was flown
        if exc.t is None:
            raise  # in initialisation: not a flight
        failure, detail, r = "fmi_error", f"{exc} at t = {exc.t:.2f} s", exc.partial_result
    signals = {name: r[name] for name in ("time", "pos_d", "alpha", "ref_pos_d", "pos_error", *COMMANDS)}
    signals["phase"] = r["phase"].astype(np.int64)
    return signals, failure, detail


# --- metrics of one run -------------------------------------------------------------------


def metric_columns() -> list[str]:
    cols = []
    for k in range(N_PHASES):
        cols += [f"max_err_p{k}", f"rms_err_p{k}"]
    return cols + [
        "max_err",
        "rms_err",
        "alt_loss_t1",
        "alt_loss_t2",
        "max_alpha_deg",
        "sat_frac",
        "sat_frac_thrust",
        "t_end",
        "last_phase",
    ]


def run_metrics(sig: Mapping[str, np.ndarray]) -> dict[str, float]:
    """Metrics of the recorded part of a run (NaN where a phase was not reached).

    max/RMS of the controller's pos_error per phase (phase output 0..4) and over the
    run; altitude loss in transition 1 and 2 = largest height below the reference
    (pos_d − ref_pos_d, ≥ 0) in phase 1 / 3; max α over phases 1–3 (α is not
    meaningful in the near-hover vertical phases); saturation = fraction of samples
    with any command at its limit (thrust at `THRUST_LIMITS`, a surface at ±`DEFLECTION_LIMIT`).
    """
    out: dict[str, float] = {}
    err, phase = sig["pos_error"], sig["phase"]
    nan = float("nan")
    for k in range(N_PHASES):
        e = err[phase == k]
        out[f"max_err_p{k}"] = float(e.max()) if e.size else nan
        out[f"rms_err_p{k}"] = float(math.sqrt(np.mean(e**2))) if e.size else nan
    out["max_err"] = float(err.max()) if err.size else nan
    out["rms_err"] = float(math.sqrt(np.mean(err**2))) if err.size else nan
    below = sig["pos_d"] - sig["ref_pos_d"]
    for name, k in (("alt_loss_t1", 1), ("alt_loss_t2", 3)):
        b = below[phase == k]
        out[name] = float(max(b.max(), 0.0)) if b.size else nan
    a = sig["alpha"][(phase >= 1) & (phase <= 3)]
    out["max_alpha_deg"] = float(np.degrees(a.max())) if a.size else nan
    thrust = sig["thrust_cmd"]
    sat_thrust = (thrust <= THRUST_LIMITS[0]) | (thrust >= THRUST_LIMITS[1] * (1 - 1e-9))
    sat = sat_thrust.copy()
    for name in COMMANDS[1:]:
        sat |= np.abs(sig[name]) >= DEFLECTION_LIMIT * (1 - 1e-9)
    out["sat_frac"] = float(sat.mean()) if sat.size else nan
    out["sat_frac_thrust"] = float(sat_thrust.mean()) if sat.size else nan
    out["t_end"] = float(sig["time"][-1]) if sig["time"].size else nan
    out["last_phase"] = float(phase.max()) if phase.size else nan
    return out


def _worker_name() -> str:
    try:
        from distributed import get_worker

        return get_worker().address
    except Exception:  # noqa: BLE001 - not on a Dask worker
        return f"{socket.gethostname()}:{os.getpid()}"


def run_job(job: Mapping[str, Any], spec_json: Mapping[str, Any], digests: Mapping[str, str]) -> dict[str, Any]:
    """Fly one run; always returns its row (failed runs included)."""
    spec = CampaignSpec.from_json(spec_json)
    t0, c0 = time.perf_counter(), time.thread_time()
    row: dict[str, Any] = dict(job)
    row.update({k: float("nan") for k in metric_columns()})
    row.update(completed=False, failure="", detail="", worker=_worker_name())
    pd_, cd_ = digests["plant"], digests[job["controller"]]
    plant_ok = ctrl_ok = False
    try:
        if pd_ not in _fmus:
            raise RuntimeError(f"FMU {pd_[:12]} not installed on this worker (plugin missing?)")
        plant = _fmus[pd_]
        nominal = {n: v.start for n, v in plant.variables.items() if v.causality == "parameter"}
        pp = plant_parameters(job, {k: float(v) for k, v in nominal.items() if k in _scaled_names()})
        pp["aero_model"] = spec.aero_model
        pp.update(json.loads(job.get("overrides") or "{}"))
        cp = dict(spec.mission)
        cp.update(CONFIGURATIONS[job["configuration"]][job["controller"]])
        if job["state_source"] in AVIONICS_EKF_PARAMS:
            plant_ok = ctrl_ok = True  # the avionics loop instantiates its own four units
            row.update(_run_avionics(job, spec, digests, pp, cp))
            return row
        ps, cs = _instance(pd_, "plant"), _instance(cd_, "controller")
        held = [ps, cs]
        atmosphere = None
        if int(job.get("turbulence_intensity", 0)) > 0:
            ad_ = digests["atmosphere"]
            if ad_ not in _fmus:
                raise RuntimeError(f"FMU {ad_[:12]} not installed on this worker (plugin missing?)")
            as_ = _instance(ad_, "atmosphere")
            held.append(as_)
            ap = atmosphere_parameters(job)
            ap["origin_height"] = float(pp.get("ground_height", nominal["ground_height"]))
            atmosphere = (_fmus[ad_], as_.slave, ap)
        for s in held:
            if s.used:
                s.slave.reset()  # fmi2Reset: back to the instantiated state, then set parameters
            s.used = True
            s.messages.clear()
        ctrl = cs.fmu
        sig, failure, detail = fly(
            plant,
            ps.slave,
            ctrl,
            cs.slave,
            pp,
            cp,
            wind_function(job),
            spec.stop_time,
            spec.step_size,
            spec.divergence_m,
            t0 + spec.timeout_s,
            atmosphere,
        )
        row.update(run_metrics(sig))
        if failure == "fmi_error":
            logs = _error_logs(pd_, cd_)
            if any("left its envelope" in m for m in logs):
                failure = "divergence"  # the plant's own tumble check (an error status by design)
            detail = " | ".join([detail, *logs])
        plant_ok = ctrl_ok = not failure
        if not failure:
            failure, detail = error_failure(row["max_err"], spec.error_limit_m)
        row.update(completed=not failure, failure=failure, detail=detail)
    except Exception as exc:  # noqa: BLE001 - a failed run is a result, not a crash
        kind = "fmi_error" if isinstance(exc, FMICallException) else "exception"
        logs = _error_logs(pd_, cd_)
        row.update(completed=False, failure=kind, detail=" | ".join([f"{type(exc).__name__}: {exc}", *logs]))
    finally:
        # An instance that went through a failure is not trusted again: free it.
        if not plant_ok:
            _discard(pd_)
        if not ctrl_ok:
            _discard(cd_)
        if not plant_ok and "atmosphere" in digests:
            _discard(digests["atmosphere"])
        row["wall_time_s"] = time.perf_counter() - t0
        row["cpu_time_s"] = time.thread_time() - c0  # CPU time of this run's thread (load-independent cost)
    return row


def _run_avionics(
    job: Mapping[str, Any],
    spec: CampaignSpec,
    digests: Mapping[str, str],
    pp: Mapping[str, float],
    cp: Mapping[str, Any],
) -> dict[str, Any]:
    """Metrics and outcome of one run with avionics in the loop (`tailsim.masters.AvionicsLoop`,
    Gauss-Seidel, fresh instances): the sensors seeded with the sample's `noise_seed`. Position
    error, altitude loss and α are the TRUE ones (plant outputs against the controller's
    reference), not the controller's view of its estimate. A run whose true position error
    exceeds `divergence_m` is a divergence, its metrics taken up to that point; an FMI error
    (the plant's envelope check: a divergence; any other: an fmi_error) ends the run, its
    metrics taken over the record up to the last completed step (`partial_result`, as `fly`
    keeps what was flown)."""
    fmus = {}
    for role in ("plant", "sensors", "ekf", job["controller"]):
        d = digests.get(role)
        if d is None or d not in _fmus:
            raise RuntimeError(f"FMU '{role}' not installed on this worker (campaign without the avionics axis?)")
        fmus[role] = _fmus[d]
    messages: collections.deque[str] = collections.deque(maxlen=8)
    names = ("plant", "sensors", "ekf", "controller")  # AvionicsLoop's instance names
    for n in names:
        fmilog.route(n, lambda status, _c, message: messages.append(f"[{status}] {message}"))
    try:
        loop = AvionicsLoop(
            fmus["plant"],
            fmus["sensors"],
            fmus["ekf"],
            fmus[job["controller"]],
            plant_params=pp,
            sensors_params={"seed": int(job["noise_seed"])},
            ekf_params=AVIONICS_EKF_PARAMS[job["state_source"]],
            controller_params=cp,
        )
        failure = detail = ""
        try:
            r = loop.run(stop_time=spec.stop_time, step_size=spec.step_size, wind=wind_function(job))
        except FMICallException as exc:  # an error status mid-flight
            logs = [m for m in messages if m.startswith("[3]") or m.startswith("[4]")]
            failure = "divergence" if any("left its envelope" in m for m in logs) else "fmi_error"
            r = getattr(exc, "partial_result", None)
            t_fail = f" at t = {r.time[-1]:.2f} s" if r is not None and r.time.size else " in initialisation"
            detail = " | ".join([f"{exc}{t_fail}", *logs])
    finally:
        for n in names:
            fmilog.unroute(n)
    if r is None:
        out: dict[str, Any] = {}
    else:
        sig = {k: r[k] for k in ("time", "phase", "pos_d", "alpha", "ref_pos_d", *COMMANDS)}
        sig["phase"] = sig["phase"].astype(np.int64)
        sig["pos_error"] = pos_error(r)  # the truth against the reference
        over = np.nonzero(~(sig["pos_error"] <= spec.divergence_m))[0]
        if over.size:  # the true error crossed the limit first: the run ends there
            k = int(over[0])
            failure = "divergence"
            detail = (
                f"true position error {sig['pos_error'][k]:.1f} m > {spec.divergence_m:g} m "
                f"at t = {sig['time'][k]:.2f} s"
            )
            sig = {n: v[: k + 1] for n, v in sig.items()}
        out = run_metrics(sig)
    if not failure:
        failure, detail = error_failure(out.get("max_err", math.nan), spec.error_limit_m)
    out.update(completed=not failure, failure=failure, detail=detail)
    return out


def error_failure(max_err: float, limit: float) -> tuple[str, str]:
    """The completion criterion of a run flown to the stop time: ('', '') if its largest
    position error is within `limit` (m), else ('error', why)."""
    if max_err <= limit:
        return "", ""
    return "error", f"largest position error {max_err:.2f} m > {limit:g} m"


def _error_logs(*digests: str) -> list[str]:
    """The error/fatal messages the FMUs logged for this thread's instances in this run."""
    logs = []
    for d in digests:
        s = _slaves.get((threading.get_ident(), d))
        if s is not None:
            logs += [m for m in s.messages if m.startswith("[3]") or m.startswith("[4]")]
    return logs


def _scaled_names() -> set[str]:
    from .sampling import TABLE_5_1

    return {n for p in TABLE_5_1 for n in p.plant_params}


def load_fmu_bytes(dist: str | pathlib.Path, controllers, state_sources=("perfect",)) -> dict[str, bytes]:
    """The .fmu files a campaign needs: the plant, its controllers, and the FMUs of its state sources."""
    dist = pathlib.Path(dist)
    names = ["plant", *controllers, *[n for s in state_sources for n in STATE_SOURCE_FMUS[s]]]
    return {n: (dist / f"{FMU_NAMES[n]}.fmu").read_bytes() for n in names}
