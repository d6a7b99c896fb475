"""Main job (for now): fly the packaged plant FMU under fmpy and write CSV + plots.

Two runs: the default experiment (trimmed 3 m/s vertical climb with the start
inputs) and a level-flight start at 25 m/s holding the trim commands, each
with a gust. Controllers join this job when their FMUs land.
"""

from __future__ import annotations

import argparse
import csv
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from fmpy import read_model_description, simulate_fmu  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
SIGNALS = ["pos_n", "pos_d", "vel_d", "airspeed", "alpha", "theta", "q", "thrust", "elevator", "induced_velocity"]


def level_trim(fmu: str) -> dict[str, float]:
    """Start values for a level-flight start: ask the FMU for its trim."""
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    s = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmu), modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="trim")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.setInteger([vr["initial_condition"]], [1])
    s.setReal([vr["initial_speed"]], [25.0])
    s.exitInitializationMode()
    thrust, elevator = s.getReal([vr["trim_thrust"], vr["trim_elevator"]])
    s.terminate()
    s.freeInstance()
    return {"initial_condition": 1, "initial_speed": 25.0, "thrust_cmd": thrust, "elevator_cmd": elevator}


def write_csv(path: pathlib.Path, result, units: dict[str, str]) -> None:
    names = ["time"] + SIGNALS
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow([f"{n} [{units.get(n, 's' if n == 'time' else '')}]" for n in names])
        for row in result:
            w.writerow([f"{row[n]:.9g}" for n in names])


def plot(path: pathlib.Path, title: str, result) -> None:
    fig, axes = plt.subplots(3, 2, figsize=(11, 8), sharex=True)
    t = result["time"]
    axes[0, 0].plot(t, result["pos_n"], label="north")
    axes[0, 0].plot(t, -result["pos_d"], label="height")
    axes[0, 0].set_ylabel("m")
    axes[0, 0].legend()
    axes[0, 1].plot(t, result["airspeed"])
    axes[0, 1].set_ylabel("airspeed [m/s]")
    axes[1, 0].plot(t, np.degrees(result["theta"]), label="θ")
    axes[1, 0].plot(t, np.degrees(result["alpha"]), label="α")
    axes[1, 0].set_ylabel("deg")
    axes[1, 0].legend()
    axes[1, 1].plot(t, np.degrees(result["q"]))
    axes[1, 1].set_ylabel("q [deg/s]")
    axes[2, 0].plot(t, result["thrust"], label="T")
    axes[2, 0].plot(t, result["induced_velocity"], label="w [m/s]")
    axes[2, 0].set_ylabel("N, m/s")
    axes[2, 0].legend()
    axes[2, 1].plot(t, np.degrees(result["elevator"]))
    axes[2, 1].set_ylabel("δe [deg]")
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    for ax in axes.flat:
        ax.grid(True, alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="out", help="output folder (default: out)")
    parser.add_argument("--fmu", default=str(ROOT / "dist" / "tailsitter_plant.fmu"))
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    md = read_model_description(args.fmu)
    units = {v.name: (v.unit or "") for v in md.modelVariables}
    gust = np.array([(0.0, 0.0), (2.0, 0.0), (2.0, 3.0), (3.0, 3.0), (3.0, 0.0)],
                    dtype=[("time", np.float64), ("wind_e", np.float64)])
    runs = {
        "plant_vertical_climb": ("Plant alone: trimmed 3 m/s vertical climb, 3 m/s side gust at 2–3 s", {}),
        "plant_level_flight": ("Plant alone: level trim at 25 m/s, open loop, 3 m/s side gust at 2–3 s",
                               level_trim(args.fmu)),
    }
    for name, (title, start) in runs.items():
        result = simulate_fmu(args.fmu, fmi_type="CoSimulation", stop_time=10.0, output_interval=0.02,
                              start_values=start, input=gust, output=SIGNALS)
        write_csv(out / f"{name}.csv", result, units)
        plot(out / f"{name}.png", title, result)
        print(f"{name}: t = {result['time'][-1]:.1f} s, height {-result['pos_d'][-1]:.2f} m, "
              f"airspeed {result['airspeed'][-1]:.2f} m/s -> {out / name}.csv/.png")
    print(f"results in {out.resolve()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
