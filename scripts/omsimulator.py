#!/usr/bin/env python3
"""Fly the SSPs in dist/ (`cargo xtask dist`) in OpenModelica's OMSimulator, unmodified, and
compare each flight with the fmpy Jacobi master of tailsim (the ordering of every SSP importer).

OMSimulator is not on any package registry: docs/OMSIMULATOR.md has the build recipe. The
binary is taken from --omsimulator, else $OMSIMULATOR, else `OMSimulator` on PATH; without one
the script says so and exits 0 (nothing to run).

Per SSP: the command line `OMSimulator X.ssp --stopTime=<the SSD's default stop time>
--resultFile=X.mat` (the command line replaces the SSD's stop time by its --stopTime flag,
default 1 s, so the script passes the SSD's own), then the MAT result (exact doubles: the CSV
writer keeps 12 digits) against the same system under tailsim's fmpy master with
ordering="jacobi" (ClosedLoop with the atmosphere; AvionicsLoop for `*_avionics.ssp`) at the
FMUs' defaults, which are the SSD's bindings (tests/test_ssp_omsimulator.py checks that).

    python scripts/omsimulator.py [--json FILE] [SSP ...]

By default (every SSP of dist/) the figures go to docs/omsimulator_run.json, with the
OMSimulator version and commit and the commands, and the generated blocks of the docs
(docs/OMSIMULATOR.md) are rewritten from it (`python -m tailsim.reports.docs --write`).
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import zipfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
DIST = ROOT / "dist"
NS = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription"}
# Euler angles swing by pi at theta = 90 deg for tiny attitude changes (gimbal lock): compared
# through the quaternion instead.
GIMBAL = {"phi", "psi"}
#: The committed record of the last run (docs/OMSIMULATOR.md is generated from it).
RECORD = ROOT / "docs" / "omsimulator_run.json"
#: A flight this close to the reference is the same flight (the closed loops reach ~1e-11 m).
SAME_FLIGHT_M = 1e-6


def find_omsimulator(explicit: str | None = None) -> str | None:
    """The OMSimulator binary: `explicit`, else $OMSIMULATOR, else `OMSimulator` on PATH."""
    for candidate in (explicit, os.environ.get("OMSIMULATOR"), shutil.which("OMSimulator")):
        if candidate and pathlib.Path(candidate).is_file() and os.access(candidate, os.X_OK):
            return str(candidate)
    return None


def default_stop_time(ssp: pathlib.Path) -> float:
    """The SSD's DefaultExperiment stopTime."""
    from lxml import etree

    with zipfile.ZipFile(ssp) as z:
        root = etree.fromstring(z.read("SystemStructure.ssd"))
    experiment = root.find("ssd:DefaultExperiment", NS)
    if experiment is None or experiment.get("stopTime") is None:
        raise ValueError(f"{ssp.name}: no default stop time")
    return float(experiment.get("stopTime"))


def read_mat4(path: pathlib.Path) -> dict[str, np.ndarray]:
    """The trajectories of an OMSimulator MAT v4 result (`Aclass` "binTrans": `name` one
    column per variable, `dataInfo` (matrix, signed 1-based column), `data_2` the
    time-varying signals with one row per variable)."""
    raw = path.read_bytes()
    matrices, at = {}, 0
    while at < len(raw):
        mopt, rows, cols, imag, namelen = np.frombuffer(raw, "<i4", 5, at)
        at += 20
        name = raw[at : at + namelen - 1].decode()
        at += namelen
        if mopt // 1000 != 0 or imag:
            raise ValueError(f"{path.name}: matrix {name} is not little-endian real")
        dtype = {0: "<f8", 1: "<f4", 2: "<i4", 3: "<i2", 4: "<u2", 5: "u1"}[(mopt // 10) % 10]
        n = int(rows) * int(cols)
        values = np.frombuffer(raw, dtype, n, at)
        at += n * np.dtype(dtype).itemsize
        matrices[name] = values.reshape((int(cols), int(rows)))  # column-major: one row per column
    names = ["".join(chr(c) for c in col).rstrip("\0 ") for col in matrices["name"].astype(int)]
    info = matrices["dataInfo"]
    out = {}
    for name, (matrix, column, *_) in zip(names, info, strict=True):
        if matrix == 2 or name == "time":
            out[name] = np.sign(column) * matrices["data_2"][:, abs(int(column)) - 1]
    return out


def run_omsimulator(binary: str, ssp: pathlib.Path, workdir: pathlib.Path) -> dict:
    """Run one SSP; the run's log, return code and trajectories by `component.variable`."""
    stop = default_stop_time(ssp)
    result = workdir / f"{ssp.stem}.mat"
    cmd = [binary, str(ssp.resolve()), f"--stopTime={stop!r}", f"--resultFile={result.name}", "--tempDir=."]
    proc = subprocess.run(cmd, cwd=workdir, capture_output=True, text=True, timeout=600)
    shown = ["OMSimulator", ssp.name, *cmd[2:]]
    run = {
        "command": " ".join(shown),
        "returncode": proc.returncode,
        "log": proc.stdout + proc.stderr,
        "stop_time": stop,
    }
    if proc.returncode == 0 and result.exists():
        full = read_mat4(result)
        # `<model>.<system>.<component>.<variable>` -> `component.variable`
        run["signals"] = {("time" if n == "time" else ".".join(n.split(".")[-2:])): v for n, v in full.items()}
    return run


def last_per_time(signals: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """OMSimulator writes each communication point twice (before and after the step's
    input exchange): keep the last row of every time."""
    t = signals["time"]
    keep = np.r_[t[1:] != t[:-1], True]
    return {n: v[keep] for n, v in signals.items()}


def fmpy_jacobi(ssp: pathlib.Path, dist: pathlib.Path = DIST, ekf_params: dict[str, float] | None = None):
    """The same system under tailsim's fmpy master, Jacobi ordering, at the FMUs' defaults
    (the FMUs of `dist`; `ekf_params` set on the estimator of an avionics system)."""
    from tailsim import ClosedLoop, Fmu
    from tailsim.masters.avionics import AvionicsLoop

    stem = ssp.stem
    avionics = stem.endswith("_avionics")
    controller = stem.removesuffix("_avionics")
    fmu = {n: Fmu(dist / f"{n}.fmu") for n in ("tailsitter_plant", controller)}
    if avionics:
        sensors, ekf = Fmu(dist / "tailsitter_sensors.fmu"), Fmu(dist / "tailsitter_ekf.fmu")
        loop = AvionicsLoop(
            fmu["tailsitter_plant"], sensors, ekf, fmu[controller], ekf_params=ekf_params, ordering="jacobi"
        )
    else:
        atmosphere = dist / "tailsitter_atmosphere.fmu"
        loop = ClosedLoop(
            fmu["tailsitter_plant"],
            fmu[controller],
            ordering="jacobi",
            atmosphere=Fmu(atmosphere) if atmosphere.exists() else None,
        )
    return loop.run(stop_time=default_stop_time(ssp))


def output_connectors(ssp: pathlib.Path) -> dict[str, set[str]]:
    """The SSD's output connectors by component."""
    from lxml import etree

    with zipfile.ZipFile(ssp) as z:
        root = etree.fromstring(z.read("SystemStructure.ssd"))
    out: dict[str, set[str]] = {}
    for comp in root.iterfind("ssd:System/ssd:Elements/ssd:Component", NS):
        names = {c.get("name") for c in comp.iterfind("ssd:Connectors/ssd:Connector[@kind='output']", NS)}
        out[comp.get("name")] = names
    return out


def compare(oms: dict[str, np.ndarray], reference, outputs: dict[str, set[str]]) -> dict:
    """OMSimulator vs the reference: the plant's position distance and largest output
    difference at equal times, and the controller's largest output difference one row later.

    Both record the plant's state at each communication point t. The controller's command for
    the sample at t_k is computed in its step from t_k: tailsim records it at t_k, OMSimulator
    (a slave's outputs after its step) at t_k + h."""
    o = last_per_time(oms)
    t = reference.time
    n = min(len(t), len(o["time"])) - 1
    if not np.allclose(o["time"][: n + 1], t[: n + 1], rtol=0, atol=1e-9):
        raise ValueError("OMSimulator and reference communication points differ")
    # A name recorded once by the reference (tailsim merges the units' signals by name).
    owners = {}
    for comp, names in outputs.items():
        for name in names:
            owners.setdefault(name, []).append(comp)

    def largest(component: str, shift: int) -> tuple[str, float]:
        """The output of `component` farthest from the reference (`shift` rows later)."""
        diffs = {
            name: float(np.max(np.abs(o[f"{component}.{name}"][shift : n + shift] - reference[name][:n])))
            for name in sorted(outputs.get(component, ()))
            if name in reference.signals and name not in GIMBAL and owners[name] == [component]
        }
        worst = max(diffs, key=diffs.get)
        return worst, diffs[worst]

    distance = np.sqrt(sum((o[f"plant.pos_{k}"][:n] - reference[f"pos_{k}"][:n]) ** 2 for k in "ned"))
    ref_error = np.sqrt(sum((reference[f"pos_{k}"][:n] - reference[f"ref_pos_{k}"][:n]) ** 2 for k in "ned"))
    return {
        "rows": int(n + 1),
        # distance of the plant to the controller's reference (the reference's definition)
        "max_pos_error_m": float(
            np.sqrt(sum((o[f"plant.pos_{k}"][:n] - o[f"controller.ref_pos_{k}"][1 : n + 1]) ** 2 for k in "ned")).max()
        ),
        "reference_max_pos_error_m": float(ref_error.max()),
        "max_position_distance_m": float(distance.max()),
        "largest_plant_output_difference": largest("plant", 0),
        "largest_controller_output_difference": largest("controller", 1),
        # the same quantities read from one OMSimulator row (the recording offset, docs)
        "same_row_max_pos_error_m": float(
            np.sqrt(sum((o[f"plant.pos_{k}"][:n] - o[f"controller.ref_pos_{k}"][:n]) ** 2 for k in "ned")).max()
        ),
        "same_row_controller_output_difference": largest("controller", 0),
    }


def fly(binary: str, ssp: pathlib.Path, workdir: pathlib.Path, dist: pathlib.Path | None = DIST) -> dict:
    """Run `ssp` in OMSimulator; its figures, compared with the fmpy Jacobi run of the FMUs in
    `dist` (none if `dist` is None)."""
    run = run_omsimulator(binary, ssp, workdir)
    figures = {"ssp": ssp.name, "returncode": run["returncode"], "stop_time": run["stop_time"]}
    lines = run["log"].splitlines()
    figures["errors_logged"] = sum(line.startswith("error:") for line in lines)
    # OMSimulator validates the SSD against SSP 1.0 when it finds the schemas (docs/OMSIMULATOR.md)
    figures["schema_validated"] = not any("could not load the ssd schema" in line for line in lines)
    figures["schema_violations"] = sum("does not conform to the SSP standard" in line for line in lines)
    if "signals" not in run:
        figures["log_tail"] = run["log"][-2000:]
        return figures
    sig = run["signals"]
    figures["final_time"] = float(sig["time"][-1])
    figures["final_phase"] = int(sig["controller.phase"][-1])
    if dist is not None:
        figures.update(compare(sig, fmpy_jacobi(ssp, dist), output_connectors(ssp)))
        if ssp.stem.endswith("_avionics"):
            figures.update(avionics_initialisation(sig, ssp, dist))
    return figures


def avionics_initialisation(signals: dict[str, np.ndarray], ssp: pathlib.Path, dist: pathlib.Path) -> dict:
    """The avionics system's initial values in OMSimulator (t = 0: the controller's thrust
    command, the estimator's and the plant's thrust) and, when the flight differs from the
    fmpy Jacobi one, the distance to the fmpy Jacobi master started with the estimator on
    OMSimulator's initial commands (its `ekf_params`)."""
    from tailsim import Fmu

    s = last_per_time(signals)
    out = {
        "initial": {
            "controller.thrust_cmd": float(s["controller.thrust_cmd"][0]),
            "estimator.thrust": float(s["estimator.thrust"][0]),
            "plant.thrust": float(s["plant.thrust"][0]),
        }
    }
    inputs = Fmu(dist / "tailsitter_ekf.fmu").names("input")
    commands = {n: float(s[f"controller.{n}"][0]) for n in inputs if n.endswith("_cmd")}
    try:
        ref = fmpy_jacobi(ssp, dist, ekf_params=commands)
    except Exception as e:  # an estimator that no longer takes its actuator states from the commands
        out["started_on_initial_commands_error"] = f"{type(e).__name__}: {e}"
        return out
    n = min(len(ref.time), len(s["time"]))
    distance = np.sqrt(sum((s[f"plant.pos_{k}"][:n] - ref[f"pos_{k}"][:n]) ** 2 for k in "ned"))
    out["started_on_initial_commands_distance_m"] = float(distance.max())
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("ssp", nargs="*", type=pathlib.Path, help="SSP files (default: dist/*.ssp)")
    parser.add_argument("--omsimulator", help="the OMSimulator binary")
    parser.add_argument("--dist", type=pathlib.Path, default=DIST, help="the FMUs and SSPs (default: dist/)")
    parser.add_argument(
        "--json",
        type=pathlib.Path,
        help="write the figures here (default: docs/omsimulator_run.json and rewrite the docs, "
        "when every SSP of dist/ is flown)",
    )
    args = parser.parse_args(argv)
    binary = find_omsimulator(args.omsimulator)
    if binary is None:
        print("OMSimulator not found (--omsimulator, $OMSIMULATOR or PATH): nothing run; see docs/OMSIMULATOR.md")
        return 0
    ssps = args.ssp or sorted(args.dist.glob("*.ssp"))
    version = subprocess.run([binary, "--version"], capture_output=True, text=True).stdout.strip()
    record_path = args.json or (RECORD if not args.ssp and args.dist == DIST else None)
    print(f"{version}: {len(ssps)} SSPs")
    results = []
    with tempfile.TemporaryDirectory(prefix="omsimulator-") as tmp:
        for ssp in ssps:
            f = fly(binary, ssp, pathlib.Path(tmp), args.dist)
            results.append(f)
            if "max_pos_error_m" in f:
                (pn, pd), (cn, cd) = f["largest_plant_output_difference"], f["largest_controller_output_difference"]
                print(
                    f"{f['ssp']}: to {f['final_time']:g} s, final phase {f['final_phase']}, "
                    f"max pos error {f['max_pos_error_m']:.10f} m "
                    f"(fmpy Jacobi {f['reference_max_pos_error_m']:.10f} m), "
                    f"position distance {f['max_position_distance_m']:.2e} m, largest output difference: "
                    f"plant {pn} {pd:.2e}, controller {cn} {cd:.2e}"
                )
            else:
                print(f"{f['ssp']:>32}: FAILED (exit {f['returncode']})\n{f.get('log_tail', '')}")
    ok = all("max_pos_error_m" in f for f in results)
    if record_path:
        record = {
            "omsimulator": version,
            # `OMSimulator <commit>-<platform>`
            "commit": version.split()[-1].split("-")[0] if version else None,
            "command": "python scripts/omsimulator.py" + (f" --json {args.json}" if args.json else ""),
            "date": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d"),
            "same_flight_m": SAME_FLIGHT_M,
            "runs": results,
        }
        record_path.write_text(json.dumps(record, indent=1) + "\n")
        print(f"wrote {record_path}")
        if record_path == RECORD and ok:
            from tailsim.reports import docs

            for file in docs.regenerate(ROOT):
                print(f"{file}: rewritten")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
