"""Avionics in the loop: plant → sensors → estimator → controller → plant.

The chain of four FMUs, every connection by name:

* plant outputs → `tailsitter_sensors` inputs (true state),
* sensor outputs → `tailsitter_ekf` measurement inputs (Real, Integer
  `gps_fix_count`, Boolean `gps_valid`),
* estimator outputs → controller inputs (the estimator's outputs carry the
  names of the plant outputs they estimate, so a controller flies the estimate
  exactly as it flies the plant),
* controller commands → plant inputs and → estimator command inputs (its motor
  and servo models).

The parameters the sensors and the estimator share (reference point
`ref_latitude`, `ref_longitude`, `ref_height`, Earth field `mag_field_total`,
`mag_declination`, `mag_inclination`, the analogue filter `filter_enabled`,
`filter_bandwidth`) are copied from the sensors' parameters to the estimator's
unless the estimator's are given explicitly; so is the plant's `aero_model` to
the estimator's (the aerodynamic model of its prediction).

Orderings (per controller step h, at t = k h):

* Gauss-Seidel: plant outputs at t → sensors step [t, t + h_s) → the
  controller reads the estimator's outputs (the estimate of t) and steps → the
  estimator gets the measurements of t and the commands for [t, t + h) and
  steps → the plant gets the commands and steps.
* Jacobi: every unit's inputs are set from outputs at t before any steps: the
  estimator fuses the sensors' outputs of the previous step and the commands
  of the previous sample, the plant flies the command of the previous sample
  (as `tailsim.masters.ClosedLoop` under Jacobi). The estimator is told so:
  unless given, its `measurement_latency` (the age of the samples) and its
  `prediction_lead` (the outputs describe the time the command computed from
  them reaches the plant) are set to the controller's step.

Communication step of the plant and sensors, `plant_step` h_s (h_s = h / m,
m an integer; default h): the plant and the sensors step m times per
controller step, the controller and the estimator once. How h_s affects the
sensor model: the sensors see the truth only at their communication points and
hold it over the step, while each sensor samples at its own rate (IMU 200 Hz,
magnetometer and pitot 50 Hz, GPS 4 Hz) and runs its 8 Hz Butterworth at that
rate. With h_s = 20 ms the four IMU samples of a step all see the truth of its
start (a 200 Hz sensor fed a 50 Hz staircase: the filter then smooths the
staircase, the effective delay grows by ≈ h_s/2); with h_s = 5 ms every IMU
sample sees a fresh truth, as a real sensor would. The noise does not change:
each sensor's noise sequence depends on its sample index only. The estimator
still reads the latest sample once per h (the sample taken in
[t, t + h_s)), and the GPS fix instants (every 0.25 s) fall on the h_s grid.

Delays: the latest IMU sample describes the aircraft the Butterworth's group
delay (28 ms) plus `measurement_latency` before the communication point, and
the controller's command reaches the plant `prediction_lead` after the end of
the estimator's step. The estimator predicts its outputs over both with its own
aircraft model driven by the commands (`model_prediction`,
crates/state-estimator/README.md). Without it (extrapolating the samples by
their backward difference) the TSD's normal-acceleration / pitch loop (≈ 4.5
Hz) had no margin left: it diverged under Jacobi and lost 19–21 m with plant
and sensors at 5 ms; with it both controllers fly Gauss-Seidel and Jacobi at
20 ms and with plant and sensors at 5 ms (tests/test_avionics.py).

The chain is a configuration of `tailsim.masters.system.System`: the sensors and
the controller are samplers, the estimator and the plant state units, the plant and
the sensors minor units. As in every configuration the truth recorded at t is the
plant's outputs with its inputs of t set (the command and the wind of t).

The result is a `tailsim.masters.RunResult` whose signals hold the plant's
outputs (the truth) under their names, the controller's outputs, the
estimator's outputs as `est_<name>` (its diagnostics `est_std_*` as they are),
and the estimation errors against the truth: `err_pos` (m), `err_vel` (m/s),
`err_att` (rad, the angle of the rotation between the true and estimated
attitude), `err_airspeed` (m/s), `err_alpha`, `err_beta` (rad).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .. import declarations
from .closed_loop import commands_driven, int_outputs, real_outputs, ref_offset_external, wind_external
from .fmu import Fmu, RunResult, pos_error
from .profiles import TimeFunction
from .system import Link, Loop, System, Unit, check_ordering, wire

#: Parameters of the same meaning in the sensors and the estimator.
SHARED_PARAMETERS = (
    "ref_latitude",
    "ref_longitude",
    "ref_height",
    "mag_field_total",
    "mag_declination",
    "mag_inclination",
    "filter_enabled",
    "filter_bandwidth",
)

#: Phase names by the controller's `phase` output.
PHASES = list(declarations.PHASES)

#: Estimation errors recorded (signal name, unit).
ERRORS = [
    ("err_pos", "m"),
    ("err_vel", "m/s"),
    ("err_att", "rad"),
    ("err_airspeed", "m/s"),
    ("err_alpha", "rad"),
    ("err_beta", "rad"),
]


class AvionicsLoop(Loop):
    """Plant + sensors + estimator + controller (see the module documentation).

    `*_params`: values set in initialisation mode by name. `plant_step`: the
    communication step of the plant and the sensors (s), a divisor of the
    controller's step (default: the controller's step).

    A run that fails mid-flight (an FMI error status, e.g. the plant's envelope check)
    raises the unit's exception with the record up to the last completed step attached
    as `exc.partial_result` (a `RunResult`; no rows when it failed in initialisation).

    `truth_inputs` (diagnostics only): controller inputs taken from the plant's outputs of
    the same names (the truth of t) instead of the estimator's, e.g. ("alpha", "beta") to
    see whether the α/β estimate is what loses a run.
    """

    def __init__(
        self,
        plant: Fmu,
        sensors: Fmu,
        ekf: Fmu,
        controller: Fmu,
        plant_params: Mapping[str, float] | None = None,
        sensors_params: Mapping[str, float | int | bool] | None = None,
        ekf_params: Mapping[str, float | int | bool] | None = None,
        controller_params: Mapping[str, float] | None = None,
        ordering: str = "gauss-seidel",
        plant_step: float | None = None,
        callbacks=None,
        truth_inputs: tuple[str, ...] = (),
    ):
        check_ordering(ordering)
        self.plant, self.sensors, self.ekf, self.controller = plant, sensors, ekf, controller
        self.plant_params = dict(plant_params or {})
        self.sensors_params = dict(sensors_params or {})
        shared = {n: v for n, v in self.sensors_params.items() if n in SHARED_PARAMETERS}
        self.ekf_params = {**shared, **dict(ekf_params or {})}
        if "aero_model" in self.plant_params and "aero_model" not in self.ekf_params:
            # The estimator predicts with the plant's configured aerodynamic model.
            self.ekf_params["aero_model"] = self.plant_params["aero_model"]
        if ordering == "jacobi":
            # The delays a Jacobi master adds, one controller step each (set in `run`).
            self._jacobi_defaults = [n for n in ("measurement_latency", "prediction_lead") if n not in self.ekf_params]
        else:
            self._jacobi_defaults = []
        self.controller_params = dict(controller_params or {})
        self.ordering = ordering
        self.plant_step = plant_step
        self.callbacks = callbacks

        self.plant_to_sensors = wire(plant, sensors)
        self.sensors_to_ekf = wire(sensors, ekf)
        missing = [n for n in ekf.names("input") if not n.endswith("_cmd") and n not in self.sensors_to_ekf]
        if missing:
            raise ValueError(f"{sensors.identifier} does not drive {ekf.identifier} inputs {missing}")
        self.ekf_to_controller = wire(ekf, controller)
        # The controller's other inputs (mission reference offset) are set by the master.
        p_out = set(plant.names("output"))
        e_out = set(ekf.names("output"))
        not_estimated = [n for n in controller.names("input") if n in p_out and n not in e_out]
        if not_estimated:
            raise ValueError(f"{ekf.identifier} does not estimate controller inputs {not_estimated}")
        unknown = [n for n in truth_inputs if n not in self.ekf_to_controller or n not in p_out]
        if unknown:
            raise ValueError(f"truth_inputs {unknown} are not estimator outputs the controller reads")
        # Diagnostic oracle: these controller inputs come from the plant (the truth), the
        # others from the estimator; flying with one estimate replaced by the truth tells
        # whether that estimate is what loses a run.
        self.truth_inputs = list(truth_inputs)
        self.controller_to_plant = commands_driven(plant, controller)
        self.controller_to_ekf = wire(controller, ekf)

    @staticmethod
    def est_name(name: str) -> str:
        return name if name.startswith("est_") else f"est_{name}"

    def system_for(self, h: float, wind: TimeFunction | None = None, ref_offset: TimeFunction | None = None) -> System:
        """The chain as a `System`, for the controller step `h` (the Jacobi delays)."""
        hs = float(self.plant_step or h)
        if round(h / hs) < 1 or abs(round(h / hs) * hs - h) > 1e-12 * h:
            raise ValueError(f"plant_step {hs} s must divide the controller step {h} s")
        P, S, E, C = self.plant, self.sensors, self.ekf, self.controller
        links = [
            Link("plant", "sensors", self.plant_to_sensors),
            Link("ekf", "controller", self.ekf_to_controller),
            Link("sensors", "ekf", self.sensors_to_ekf),
            Link("controller", "ekf", self.controller_to_ekf),
            Link("controller", "plant", self.controller_to_plant),
        ]
        if self.truth_inputs:
            links.insert(2, Link("plant", "controller", self.truth_inputs))
        ekf_params = {**{n: h for n in self._jacobi_defaults}, **self.ekf_params}
        return System(
            [
                Unit("sensors", S, self.sensors_params, sampler=True, minor=True),
                Unit("controller", C, self.controller_params, sampler=True, record=real_outputs(C) + int_outputs(C)),
                Unit("ekf", E, ekf_params, record=real_outputs(E) + int_outputs(E), prefix="est_"),
                Unit("plant", P, self.plant_params, minor=True, record=real_outputs(P)),
            ],
            links,
            [wind_external(wind), ref_offset_external(ref_offset)],
            ordering=self.ordering,
            init_order=["plant", "sensors", "ekf", "controller"],
            # The record: the truth, the controller's outputs, the estimate.
            record_order=["plant", "controller", "ekf", "sensors"],
        )

    @property
    def minor_step(self) -> float | None:
        return self.plant_step

    def finish(self, result: RunResult) -> RunResult:
        return with_estimation_errors(result)


def with_estimation_errors(result: RunResult) -> RunResult:
    """`result` with the estimation errors (`ERRORS`) added."""
    result.signals.update(estimation_errors(result.signals))
    result.units.update(dict(ERRORS))
    return result


def estimation_errors(sig: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Estimation errors against the truth (the `est_*` signals against the plant's)."""

    def norm3(prefix_true: str, prefix_est: str, axes: str) -> np.ndarray:
        return np.sqrt(sum((sig[f"{prefix_est}{prefix_true}{a}"] - sig[f"{prefix_true}{a}"]) ** 2 for a in axes))

    q_t = np.column_stack([sig[f"quat_{i}"] for i in range(1, 5)])
    q_e = np.column_stack([sig[f"est_quat_{i}"] for i in range(1, 5)])
    q_t = q_t / np.linalg.norm(q_t, axis=1, keepdims=True)
    q_e = q_e / np.linalg.norm(q_e, axis=1, keepdims=True)
    dot = np.clip(np.abs(np.sum(q_t * q_e, axis=1)), 0.0, 1.0)
    return {
        "err_pos": norm3("pos_", "est_", "ned"),
        "err_vel": norm3("vel_", "est_", "ned"),
        "err_att": 2.0 * np.arccos(dot),
        "err_airspeed": sig["est_airspeed"] - sig["airspeed"],
        "err_alpha": sig["est_alpha"] - sig["alpha"],
        "err_beta": sig["est_beta"] - sig["beta"],
    }


@dataclass
class PhaseErrors:
    """Max true position error and RMS / max estimation errors in one phase."""

    phase: str
    max_position_error: float
    rms: dict[str, float]
    max: dict[str, float]


def phase_errors(result: RunResult) -> list[PhaseErrors]:
    """Per phase (controller's `phase` output): max |true position − reference|
    and the RMS and max |estimation error| of each of `ERRORS`."""
    err = pos_error(result)
    out = []
    for k, name in enumerate(PHASES):
        sel = result["phase"] == k
        if not sel.any():
            continue
        rms = {e: float(math.sqrt(np.mean(result[e][sel] ** 2))) for e, _ in ERRORS}
        mx = {e: float(np.max(np.abs(result[e][sel]))) for e, _ in ERRORS}
        out.append(PhaseErrors(name, float(err[sel].max()), rms, mx))
    return out


def format_phase_errors(result: RunResult, title: str = "") -> str:
    """A plain-text table of `phase_errors` (angles in degrees)."""
    lines = [
        title
        or f"{result.controller} with avionics ({result.ordering}): max position error {pos_error(result).max():.2f} m",
        f"  {'phase':>12} {'max |x-ref|':>11} | RMS est. error: {'pos':>6} {'vel':>6} {'att':>6} {'V':>6} "
        f"{'alpha':>6} {'beta':>6}",
    ]
    for pe in phase_errors(result):
        r = pe.rms
        lines.append(
            f"  {pe.phase:>12} {pe.max_position_error:9.2f} m |                 "
            f"{r['err_pos']:6.2f} {r['err_vel']:6.2f} {math.degrees(r['err_att']):5.2f}° "
            f"{r['err_airspeed']:6.2f} {math.degrees(r['err_alpha']):5.2f}° {math.degrees(r['err_beta']):5.2f}°"
        )
    return "\n".join(lines)


def fly_with_avionics(
    fmus: Mapping[str, Fmu],
    controller: str,
    ordering: str = "gauss-seidel",
    plant_step: float | None = None,
    sensors_params: Mapping[str, float | int | bool] | None = None,
    ekf_params: Mapping[str, float | int | bool] | None = None,
    controller_params: Mapping[str, float] | None = None,
    plant_params: Mapping[str, float] | None = None,
    **run_kw,
) -> RunResult:
    """One run of `controller` (a modelIdentifier) with avionics in the loop; `fmus`
    maps modelIdentifiers to `Fmu`s (tailsitter_plant, _sensors, _ekf, controller)."""
    loop = AvionicsLoop(
        fmus["tailsitter_plant"],
        fmus["tailsitter_sensors"],
        fmus["tailsitter_ekf"],
        fmus[controller],
        plant_params=plant_params,
        sensors_params=sensors_params,
        ekf_params=ekf_params,
        controller_params=controller_params,
        ordering=ordering,
        plant_step=plant_step,
    )
    return loop.run(**run_kw)


__all__ = [
    "ERRORS",
    "PHASES",
    "SHARED_PARAMETERS",
    "AvionicsLoop",
    "PhaseErrors",
    "estimation_errors",
    "fly_with_avionics",
    "format_phase_errors",
    "phase_errors",
    "with_estimation_errors",
]
