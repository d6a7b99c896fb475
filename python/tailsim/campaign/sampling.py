"""The sample space of the Monte-Carlo campaign.

A *sample* is one draw of everything random: the 25 uncertain parameters of the
thesis's Table 5.1 (each scaled by an independent log-uniform factor within
[1/τ, τ], τ = 1.5 for the aerodynamic derivatives and 1.1 for the mass and the
inertias, as in the thesis's sweep (5.1.1)), a steady horizontal wind, a 1 − cos
gust of random direction, amplitude and timing, a sensor-noise seed (for the
avionics state source: the sensors' `seed`), and a Dryden turbulence intensity and seed
(the `tailsitter_atmosphere` FMU's `turbulence_intensity` and `seed`).

A *run* is one sample flown on one point of the configuration axes:
controller × configuration × state source. Every run of a sample sees the same
draw, so controllers are compared on paired samples.

Sample i is drawn from its own generator, seeded with (seed, i), so any subset of
a campaign is reproducible on its own and a campaign can grow.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import controllers, declarations

# Thesis Table 5.1: (column name, symbol, plant-FMU parameters, uncertainty class).
# The plant interpolates each stability/control derivative between α = 0 and
# α = alpha_1 (5.9°): both table points (_a0, _a1) are scaled by the same factor.
_AERO = [
    ("C_La", "C_Lα", "c_L_alpha"),
    ("C_Lq", "C_Lq", "c_L_q"),
    ("C_Lde", "C_Lδe", "c_L_de"),
    ("C_Yb", "C_Yβ", "c_Y_beta"),
    ("C_Yp", "C_Yp", "c_Y_p"),
    ("C_Yr", "C_Yr", "c_Y_r"),
    ("C_Yda", "C_Yδa", "c_Y_da"),
    ("C_Ydr", "C_Yδr", "c_Y_dr"),
    ("C_lb", "C_lβ", "c_l_beta"),
    ("C_lp", "C_lp", "c_l_p"),
    ("C_lr", "C_lr", "c_l_r"),
    ("C_lda", "C_lδa", "c_l_da"),
    ("C_ldr", "C_lδr", "c_l_dr"),
    ("C_ma", "C_mα", "c_m_alpha"),
    ("C_mq", "C_mq", "c_m_q"),
    ("C_mde", "C_mδe", "c_m_de"),
    ("C_nb", "C_nβ", "c_n_beta"),
    ("C_np", "C_np", "c_n_p"),
    ("C_nr", "C_nr", "c_n_r"),
    ("C_nda", "C_nδa", "c_n_da"),
    ("C_ndr", "C_nδr", "c_n_dr"),
]
_MASS = [("m", "m", "mass"), ("I_x", "I_x", "i_xx"), ("I_y", "I_y", "i_yy"), ("I_z", "I_z", "i_zz")]


@dataclass(frozen=True)
class Uncertain:
    """One Table 5.1 parameter."""

    name: str  # column-safe name (sample column `k_<name>`)
    symbol: str  # thesis symbol
    plant_params: tuple[str, ...]  # plant-FMU parameters scaled by the same factor
    kind: str  # "aero" (τ_aero) or "mass" (τ_mass)


TABLE_5_1: tuple[Uncertain, ...] = tuple(
    [Uncertain(n, s, (f"{p}_a0", f"{p}_a1"), "aero") for n, s, p in _AERO]
    + [Uncertain(n, s, (p,), "mass") for n, s, p in _MASS]
)
assert len(TABLE_5_1) == 25

#: Configuration axes. A configuration is the controller parameters it sets
#: (the controller FMUs' `configuration`: 0 = tuned, the default; 1 = the thesis's
#: configuration as printed, see the parameter's description). A state source is what the
#: controller flies on: `perfect` = the plant's outputs; `avionics` = the estimate of
#: `tailsitter_ekf` fed by `tailsitter_sensors` (tailsim.masters.avionics, Gauss-Seidel), the
#: sensors seeded with the sample's `noise_seed`.
#: The campaign's controllers: every declared controller. A configuration applies to the
#: controllers it lists: `tuned` (each controller's defaults) to all of them, `thesis` to
#: those with the thesis's `configuration` parameter; a controller without one
#: (`tailsitter_px4`, PX4's parameters) is an arm of the `tuned` configuration only, flown
#: on the same paired samples.
CONTROLLERS = controllers.KEYS
CONFIGURATIONS: dict[str, dict[str, dict[str, int]]] = {
    "tuned": {k: {} for k in CONTROLLERS},
    "thesis": {
        k: {"configuration": 1} for k in CONTROLLERS if "configuration" in declarations.VARIABLES[controllers.NAMES[k]]
    },
}
#: The order the reports list controllers in: the thesis's (those with its `configuration`)
#: first, each group in declaration order (LQR, TSD, then PX4).
ORDER = tuple(sorted(CONTROLLERS, key=lambda k: k not in CONFIGURATIONS["thesis"]))
#: The controller FMUs' `configuration` value of each configuration (the native campaign's input).
CONFIGURATION_INDEX = {"tuned": 0, "thesis": 1}
STATE_SOURCES = ("perfect", "avionics", "avionics_app_d")

#: Missions (controller parameters; identical for both controllers): the phase durations of
#: the declared presets `default` (the controllers' defaults: 5 s climb, T1 = 5 s, 10 s level,
#: T2 = 10 s, 5 s vertical) and `short` (all five phases in 11 s, for tests and smoke runs).
MISSIONS: dict[str, dict[str, float]] = {
    name: {k: declarations.mission(name)[k] for k in declarations.PHASE_DURATIONS} for name in ("default", "short")
}


#: The atmosphere's `turbulence_intensity` values (0 none, 1 light, 2 moderate, 3 severe).
TURBULENCE_LEVELS = (0, 1, 2, 3)


def mission_stop_time(mission: Mapping[str, float]) -> float:
    return declarations.stop_time(dict(mission))


@dataclass(frozen=True)
class CampaignSpec:
    """Everything that fixes a campaign's runs (the FMUs aside: they are hashed)."""

    seed: int = 0
    n_samples: int = 64
    controllers: tuple[str, ...] = CONTROLLERS
    configurations: tuple[str, ...] = ("tuned",)
    state_sources: tuple[str, ...] = ("perfect",)
    tau_aero: float = 1.5
    tau_mass: float = 1.1
    #: Largest steady horizontal wind speed (m/s); heading uniform.
    wind_max: float = 10.0
    #: Largest 1 − cos gust amplitude (m/s); direction uniform on the sphere.
    gust_max: float = 5.0
    #: Range of the gust duration (s).
    gust_duration: tuple[float, float] = (1.0, 3.0)
    mission_name: str = "default"
    mission: Mapping[str, float] = field(default_factory=lambda: dict(MISSIONS["default"]))
    step_size: float = 0.02
    #: Largest Dryden turbulence intensity drawn (the atmosphere's `turbulence_intensity`:
    #: 0 none, 1 light, 2 moderate, 3 severe), uniform on 0..turbulence_max.
    turbulence_max: int = 2
    #: A run is stopped as diverged once the controller's pos_error exceeds this (m).
    divergence_m: float = 50.0
    #: A run that reached the stop time counts as completed only if its largest position
    #: error stayed within this (m); beyond it the run is a failure `error`.
    error_limit_m: float = 5.0
    #: A run is stopped as timed out after this wall time (s).
    timeout_s: float = 300.0
    #: Extra plant-parameter values for some samples {sample_id: {name: value}}:
    #: what-if studies and fault injection (an invalid value makes a failed run).
    overrides: Mapping[int, Mapping[str, float]] = field(default_factory=dict)
    #: The plant's `aero_model` for every run: 1 = global (post-stall, the FMU's default),
    #: 0 = the thesis's linear derivatives at every angle.
    aero_model: int = 1

    def __post_init__(self):
        for c in self.controllers:
            if c not in CONTROLLERS:
                raise ValueError(f"unknown controller {c!r} (one of {CONTROLLERS})")
        for c in self.configurations:
            if c not in CONFIGURATIONS:
                raise ValueError(f"unknown configuration {c!r} (available: {tuple(CONFIGURATIONS)})")
        for s in self.state_sources:
            if s not in STATE_SOURCES:
                raise ValueError(f"unknown state source {s!r} (available: {STATE_SOURCES})")
        for name, axis in (
            ("controllers", self.controllers),
            ("configurations", self.configurations),
            ("state_sources", self.state_sources),
        ):
            if not axis or len(set(axis)) != len(axis):
                raise ValueError(f"{name} = {axis!r}: expected distinct values, at least one")
        if not arms(self):
            raise ValueError(
                f"no arm: none of the controllers {self.controllers!r} has a configuration of "
                f"{self.configurations!r} ({', '.join(f'{k}: {tuple(v)}' for k, v in CONFIGURATIONS.items())})"
            )
        if self.aero_model not in (0, 1):
            raise ValueError(f"aero_model = {self.aero_model!r}: expected 0 (thesis) or 1 (global)")
        if not (self.tau_aero >= 1.0 and self.tau_mass >= 1.0):
            raise ValueError("tau_aero and tau_mass must be ≥ 1")
        if self.turbulence_max not in TURBULENCE_LEVELS:
            raise ValueError(f"turbulence_max = {self.turbulence_max!r}: expected one of {TURBULENCE_LEVELS}")
        if self.turbulence_max > 0 and "avionics" in self.state_sources:
            raise ValueError("the avionics state source flies without the atmosphere unit: turbulence_max must be 0")
        if not self.error_limit_m > 0.0:
            raise ValueError(f"error_limit_m = {self.error_limit_m!r}: must be > 0")

    @property
    def stop_time(self) -> float:
        return mission_stop_time(self.mission)

    def to_json(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d["overrides"] = {str(k): dict(v) for k, v in self.overrides.items()}
        d["mission"] = dict(self.mission)
        return d

    @classmethod
    def from_json(cls, d: Mapping[str, Any]) -> CampaignSpec:
        d = dict(d)
        for k in ("controllers", "configurations", "state_sources", "gust_duration"):
            d[k] = tuple(d[k])
        d["overrides"] = {int(k): dict(v) for k, v in d.get("overrides", {}).items()}
        return cls(**d)

    def identity(self) -> dict[str, Any]:
        """What must not change when a campaign is resumed or grown (n_samples may)."""
        d = self.to_json()
        d.pop("n_samples")
        return d

    def tau(self, u: Uncertain) -> float:
        return self.tau_aero if u.kind == "aero" else self.tau_mass


def sample_generator(seed: int, i: int) -> np.random.Generator:
    """The generator of sample i: its own stream, derived from (seed, i) only."""
    return np.random.default_rng(np.random.SeedSequence(entropy=seed, spawn_key=(i,)))


def draw_sample(spec: CampaignSpec, i: int) -> dict[str, Any]:
    """Sample i as a flat dict (the sample columns of the results).

    Draw order (fixed, so that adding configuration axes never changes a draw):
    25 log-uniform exponents, steady wind (speed, heading), gust (amplitude,
    direction, duration, start), noise seed, turbulence (seed, intensity): a later draw
    never changes an earlier one.
    """
    rng = sample_generator(spec.seed, i)
    s: dict[str, Any] = {"sample_id": int(i)}
    # Log-uniform on [1/τ, τ]: k = τ^u with u ~ U(−1, 1) (thesis (5.1.1) spans the same range).
    u = rng.uniform(-1.0, 1.0, size=len(TABLE_5_1))
    for p, ui in zip(TABLE_5_1, u, strict=False):
        s[f"k_{p.name}"] = float(spec.tau(p) ** ui)
    speed = rng.uniform(0.0, spec.wind_max)
    heading = rng.uniform(0.0, 2.0 * math.pi)
    s["wind_steady_n"] = float(speed * math.cos(heading))
    s["wind_steady_e"] = float(speed * math.sin(heading))
    amp = rng.uniform(0.0, spec.gust_max)
    d = rng.normal(size=3)
    d /= np.linalg.norm(d)
    dur = rng.uniform(*spec.gust_duration)
    start = rng.uniform(0.0, max(spec.stop_time - dur, 0.0))
    s["gust_n"], s["gust_e"], s["gust_d"] = (float(x) for x in amp * d)
    s["gust_start"] = float(start)
    s["gust_duration"] = float(dur)
    # The sensors' `seed` of the avionics runs (all runs of a sample share it: paired noise).
    s["noise_seed"] = int(rng.integers(0, 2**31 - 1))
    s["turbulence_seed"] = int(rng.integers(0, 2**31 - 1))
    s["turbulence_intensity"] = int(rng.integers(0, spec.turbulence_max + 1))
    return s


def sample_columns() -> list[str]:
    return (
        ["sample_id"]
        + [f"k_{p.name}" for p in TABLE_5_1]
        + ["wind_steady_n", "wind_steady_e", "gust_n", "gust_e", "gust_d", "gust_start", "gust_duration", "noise_seed"]
        + ["turbulence_seed", "turbulence_intensity"]
    )


def plant_parameters(sample: Mapping[str, Any], nominal: Mapping[str, float]) -> dict[str, float]:
    """The plant-parameter values of a sample: every Table 5.1 parameter's
    nominal value (from the plant's modelDescription) times its factor."""
    out = {}
    for p in TABLE_5_1:
        k = sample[f"k_{p.name}"]
        for name in p.plant_params:
            out[name] = float(nominal[name]) * k
    return out


def wind_function(sample: Mapping[str, Any]):
    """Wind (n, e, d) (m/s) of a sample: steady horizontal wind plus the 1 − cos gust
    amplitude·(1 − cos(2π(t − t_start)/duration))/2 inside the gust."""
    wn, we = sample["wind_steady_n"], sample["wind_steady_e"]
    gn, ge, gd = sample["gust_n"], sample["gust_e"], sample["gust_d"]
    t0, dur = sample["gust_start"], sample["gust_duration"]
    two_pi = 2.0 * math.pi

    def wind(t: float) -> tuple[float, float, float]:
        s = (t - t0) / dur
        if 0.0 <= s <= 1.0:
            k = 0.5 * (1.0 - math.cos(two_pi * s))
            return (wn + gn * k, we + ge * k, gd * k)
        return (wn, we, 0.0)

    return wind


def atmosphere_parameters(sample: Mapping[str, Any]) -> dict[str, float]:
    """The `tailsitter_atmosphere` parameters of a sample with turbulence: its steady wind
    (uniform with height, so equal to the wind function's), Dryden turbulence of the sample's
    intensity and seed, and its 1 − cos gust (the atmosphere's, same form as `wind_function`)."""
    wn, we = float(sample["wind_steady_n"]), float(sample["wind_steady_e"])
    return {
        "wind_speed": math.hypot(wn, we),
        # The bearing the wind blows FROM: the air moves along (wn, we).
        "wind_from": math.atan2(-we, -wn) % (2.0 * math.pi),
        "wind_profile": 0,
        "turbulence_model": 1,
        "turbulence_intensity": int(sample["turbulence_intensity"]),
        "seed": int(sample["turbulence_seed"]),
        "gust_amplitude_n": float(sample["gust_n"]),
        "gust_amplitude_e": float(sample["gust_e"]),
        "gust_amplitude_d": float(sample["gust_d"]),
        "gust_start": float(sample["gust_start"]),
        "gust_duration": float(sample["gust_duration"]),
    }


def run_key(sample_id: int, controller: str, configuration: str, state_source: str) -> str:
    return f"{sample_id}/{controller}/{configuration}/{state_source}"


def arms(spec: CampaignSpec) -> list[tuple[str, str, str]]:
    """The campaign's arms (controller, configuration, state source): every controller in
    every configuration that applies to it (`CONFIGURATIONS`), every state source."""
    return [
        (c, cfg, src)
        for c in spec.controllers
        for cfg in spec.configurations
        if c in CONFIGURATIONS[cfg]
        for src in spec.state_sources
    ]


def jobs(spec: CampaignSpec, sample_ids=None) -> list[dict[str, Any]]:
    """Every run of the campaign: sample × arm (`arms`), every arm on the same draw."""
    out = []
    arms_ = arms(spec)
    for i in range(spec.n_samples) if sample_ids is None else sample_ids:
        s = draw_sample(spec, i)
        for c, cfg, src in arms_:
            out.append(
                {
                    "key": run_key(i, c, cfg, src),
                    "controller": c,
                    "configuration": cfg,
                    "state_source": src,
                    "overrides": json.dumps(dict(spec.overrides.get(i, {})), sort_keys=True),
                    **s,
                }
            )
    return out
