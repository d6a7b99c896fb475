//! Take-off from rest on the gear and landing on a target point, around the thesis's
//! mission (issue 16): the phase logic both controllers share.
//!
//! With the defaults (`takeoff_spinup_time = 0`, `landing_descent_rate = 0`) nothing here
//! acts: [`GroundPhases::step`] returns [`GroundMode::Mission`] at the mission time with a
//! zero offset, and the controllers fly exactly the thesis's mission.
//!
//! # Phases (times from the start of the simulation, τ within the phase)
//!
//! * [`Phase::OnGround`], `t < t_s` (`takeoff_spinup_time`): on the gear. The controller
//!   does not run (no integrator wind-up, no gain computation against a ground reaction it
//!   does not model); the thrust command ramps linearly to `takeoff_spinup_thrust · m g`
//!   (below the weight: the aircraft stays on the gear), surfaces centred (no moment, no
//!   tip-over). The mission origin O is the CG position measured at the last sample on the
//!   gear (a master may hand the first sample start values, not the plant's outputs).
//! * [`Phase::TakeOff`], `τ < T_to` (`takeoff_time`): vertical reference from rest,
//!   climb rate `v(τ) = V_V (1 − cos(πτ/T_to))/2`, height `h(τ) = V_V (τ/2 − T_to/(2π)
//!   sin(πτ/T_to))`, acceleration `V_V π/(2T_to) sin(πτ/T_to)`: continuous in position,
//!   velocity and acceleration at both ends. It ends at height `V_V T_to/2` climbing at V_V.
//! * The thesis's mission at mission time `t − t_s − T_to`, its reference shifted by
//!   `O + (0, 0, −V_V T_to/2)` (NED).
//! * Without landing the last vertical phase continues as today. With
//!   `landing_descent_rate` V_d > 0, at the mission's end (reference position P₀, velocity
//!   v₀) [`Phase::Approach`]: a cubic Hermite blend per axis, over
//!   `T_a = max(4 s, 1.5 |Δ_horizontal| / landing_approach_speed)` (1.5 d/T is the peak
//!   speed of the blend), from (P₀, v₀) to rest over the target at the height
//!   `P₀ + v₀,d T_a/3` (vertically `v_d(s) = v₀,d (1 − s)²`, monotone: the climb stops
//!   without reversing).
//! * [`Phase::Descent`]: from rest the sink rate ramps by a cosine to V_d over
//!   [`DESCENT_RAMP_TIME`], then stays at V_d until `landing_flare_height` h_f above the
//!   target.
//! * [`Phase::Flare`] (from h_f, raised for a thrust-limited airframe:
//!   [`GroundPhases::flare_height`]): the sink rate falls linearly in time from V_d to the touchdown rate
//!   V_td over `t_f = 2 (h_f − h_td)/(V_d + V_td)` (covering h_f − h_td), then stays at V_td
//!   over the last `h_td = V_td ·` [`FINAL_SEGMENT_TIME`] (the gear meets the ground at a
//!   steady sink, thrust ≈ weight: no flare thrust to bounce on), on to
//!   [`TOUCHDOWN_OVERSHOOT`] below the target, held there for [`TOUCHDOWN_HOLD_TIME`], then
//!   slower ([`TOUCHDOWN_SEARCH_RATE`]) until the touchdown is detected, at most [`TOUCHDOWN_SEARCH_DEPTH`] below the target
//!   (its height is only as good as the height estimate: with GPS alone σ ≈ 1.4 m).
//! * [`Phase::Landed`]: latched by the land detector, which does not use the height: while a
//!   sink is commanded (the descent at its full rate, the flare), a ground contact — the gear's share of the weight
//!   by the accelerometer, `f_x/g − T/(m g)` (specific force along the thrust axis against
//!   the thrust), rises above its mean in the air by [`CONTACT_REACTION`] and
//!   [`CONTACT_SIGMAS`] of its spread: the gear carries weight, at the impact or as the
//!   controller takes thrust off — followed by the sink stopping (|v_d| < [`LANDED_SINK`]
//!   V_td, tilt rate < [`LANDED_TILT_RATE`], for [`TOUCHDOWN_DWELL`]). Then the thrust
//!   command is 0 (the controllers clamp it to their thrust minimum), surfaces centred, held
//!   for good.
//!
//! The reference attitude in the vertical phases here is the mission's vertical one
//! (nose up, belly north); while descending the air comes from behind, α = π.

use nalgebra::Vector3;

use flight_mission::{Measurement, MissionParams, Phase};

/// Time of the cosine ramp of the sink rate at the start of the descent (s).
pub const DESCENT_RAMP_TIME: f64 = 2.0;
/// Shortest approach (s).
pub const APPROACH_MIN_TIME: f64 = 4.0;
/// Collective-flap trim of the landing phases per m/s of wind into the belly (rad s/m), both
/// controllers': the slope of the plant's still, upright hover trim (−5.2°, −9.8°, −13.8° of
/// collective flaps at 1, 2, 3 m/s face-on, `cargo run --release -p analysis --example
/// tsd_wind_bounds`).
pub const LANDING_FLAP_TRIM_GAIN: f64 = 4.6 * core::f64::consts::PI / 180.0;
/// Largest collective-flap trim of the landing phases (rad): the upright hover trim is −20°
/// from 5 m/s; the rest of the ±25° is left to the feedback.
pub const LANDING_FLAP_TRIM_LIMIT: f64 = 17.0 * core::f64::consts::PI / 180.0;

/// How far the touchdown reference sinks below the target before it holds, if the touchdown
/// is not detected before (m): three σ of the height relative to the start that GPS alone
/// gives at the landing (≈ 1.4 m, σ 4 m fixes at 4 Hz), and some.
pub const TOUCHDOWN_SEARCH_DEPTH: f64 = 5.0;
/// How far the touchdown reference sinks below the target at the touchdown rate before it
/// slows to [`TOUCHDOWN_SEARCH_RATE`] (m).
pub const TOUCHDOWN_OVERSHOOT: f64 = 0.3;
/// Time the touchdown reference holds at [`TOUCHDOWN_OVERSHOOT`] before it searches deeper (s):
/// with a good height measurement the controllers settle onto the gear there.
pub const TOUCHDOWN_HOLD_TIME: f64 = 10.0;
/// Sink rate of the touchdown reference after [`TOUCHDOWN_HOLD_TIME`], in touchdown rates
/// (–): the ground is near, the gear meets it slower.
pub const TOUCHDOWN_SEARCH_RATE: f64 = 1.0 / 3.0;
/// Time flown at the touchdown rate before the target, after the flare (s).
pub const FINAL_SEGMENT_TIME: f64 = 1.0;
/// Ground contact: least rise of the gear's share of the weight, `f_x/g − T/(m g)` from the
/// accelerometer's specific force along the thrust axis f_x and the thrust T, above its mean
/// in the air (–). In the air the share is the aerodynamic force along x (the wing's drag in
/// the slipstream: −0.06…−0.02 in the flares) and the estimate's noise; a thrust below the
/// weight in the air shows as a fall (f_x ≈ T/m), not as a reaction. At the touchdown the
/// gear's spring stops the sink (+0.8 at 0.25 m/s on four legs, +0.09 for 0.1 s at 0.07 m/s
/// on one); at rest it carries what the controller, whose reference keeps sinking, takes off
/// the thrust.
pub const CONTACT_REACTION: f64 = 0.05;
/// Ground contact: least rise of the gear's share in standard deviations of its spread in
/// the air (–): with the avionics chain's noise (σ ≈ 0.01–0.02) the rise must be larger.
pub const CONTACT_SIGMAS: f64 = 5.0;
/// Ground contact: largest rise of the gear's share above its mean in the air that the test
/// asks for (–), however large the spread there: in moderate turbulence the share's spread in
/// the descent is 0.16–0.25 (the wing's and body's gust loads along x), so five spreads
/// (0.8–1.2) were out of reach at rest on the gear with the thrust at 0.6 weights (rise
/// 0.5); the aircraft sat undetected on its gear and a gust tipped it over under the
/// loop's thrust. Still air and the avionics chain's noise (spread 0.01–0.02) stay below it.
pub const CONTACT_REACTION_MAX: f64 = 0.35;
/// Time constant of the gear share's mean and spread in the air (s).
pub const SHARE_TIME: f64 = 2.0;
/// How long a ground contact counts for the landing (s): the impact's reaction lasts a few
/// samples, the sink must have stopped by the end.
pub const CONTACT_MEMORY: f64 = 0.5;
/// Largest vertical speed of a landing, in touchdown rates V_td (–): the commanded sink does
/// not happen. The estimate's after an impact is 0.2 m/s off with the avionics chain (PX4's
/// land detector allows 0.25 m/s, widened 2.5 times once it suspects a landing).
pub const LANDED_SINK: f64 = 1.0;
/// Largest tilt rate |(q, r)| of a landing (rad/s): the gear is not rocking or tipping.
pub const LANDED_TILT_RATE: f64 = 40.0 * core::f64::consts::PI / 180.0;
/// Time the sink must have stopped (and the tilt rate be small) after a ground contact
/// before the landing is declared (s): two samples at 20 ms.
pub const TOUCHDOWN_DWELL: f64 = 0.04;
/// Gravity of the contact test (m/s²): the airframes' g (C.1).
pub const CONTACT_GRAVITY: f64 = 9.81;
/// Thrust kept for the loop in a thrust-limited flare, in weights (–): with a thrust limit
/// given ([`GroundPhases::with_thrust_limit`]) the flare's deceleration may use the thrust
/// reserve `T_max − T̄` (T̄ the mean thrust of the steady descent) less this. In a 10 m/s
/// wind the upright hover needs 130 N of the airframe's 150 N; the flare from 2 m/s over
/// 1.2 m needs 14.7 N more, and the loop's lead at the flare's start saturated the thrust
/// (touchdowns at 0.57–0.78 m/s). In still air (T̄ ≈ 91 N) the flare needs 1.6 m/s² of the
/// 4.9 m/s² left: unchanged up to T̄ ≈ 120 N.
pub const FLARE_LOOP_RESERVE: f64 = 0.17;
/// Highest flare of a thrust-limited descent (m above the target).
pub const FLARE_HEIGHT_MAX: f64 = 6.0;
/// Height above the target at which the reference's flare height is fixed, from the mean
/// thrust of the descent so far (m): above [`FLARE_HEIGHT_MAX`], where the reference of
/// every flare height is still the steady descent.
pub const FLARE_LATCH_HEIGHT: f64 = 8.0;
/// Time constant of the descent's mean thrust (s).
pub const DESCENT_THRUST_TIME: f64 = 2.0;

/// A reference for vertical (nose-up) flight, NED, mission origin included.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerticalReference {
    pub phase: Phase,
    /// Position of the CG (m).
    pub pos: Vector3<f64>,
    /// Inertial velocity (m/s).
    pub vel: Vector3<f64>,
    /// Inertial acceleration (m/s²) (not the specific force: gravity not included).
    pub accel: Vector3<f64>,
}

/// What the controller does at a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GroundMode {
    /// Fly the thesis's mission at mission time `t`, its reference position shifted by
    /// `offset` (NED, m) relative to the controller's own mission origin.
    Mission { t: f64, offset: Vector3<f64> },
    /// Fly this vertical reference.
    Vertical(VerticalReference),
    /// Do not fly: command `thrust` (N), surfaces centred ([`Phase::OnGround`], [`Phase::Landed`]).
    Idle { phase: Phase, thrust: f64 },
}

/// The take-off and landing phase logic of a controller (module docs). Plain state,
/// saved with the controller ([`Self::save`], [`Self::restore`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundPhases {
    mission: MissionParams,
    /// Weight m g of the controller's airframe (N).
    weight: f64,
    /// Mission origin: the position measured at the first sample of a take-off.
    origin: Option<Vector3<f64>>,
    /// Reference position and velocity at the end of the mission (start of the approach).
    approach_start: Option<(Vector3<f64>, Vector3<f64>)>,
    /// Time since which the landing's conditions hold (NaN: they do not).
    touch_since: f64,
    /// Time of the last ground contact (NaN: none).
    contact_at: f64,
    /// The gear's share in the air: exponential mean, variance, time of the last sample
    /// (NaN: none yet).
    share_mean: f64,
    share_var: f64,
    share_t: f64,
    landed: bool,
    /// Largest thrust of the airframe (N); infinite: no thrust-limited flare.
    thrust_limit: f64,
    /// Mean thrust of the descent (N) and the time of its last sample (NaN: none yet).
    descent_thrust: f64,
    descent_thrust_t: f64,
    /// Flare height fixed in the descent (m; NaN: not yet, `landing_flare_height`).
    flare_height: f64,
}

/// The touchdown reference below the target (m, + down) and its sink rate (m/s), `x` (s)
/// after it passed `s0` (m) sinking at `vtd` (m/s): at `vtd` to [`TOUCHDOWN_OVERSHOOT`], held
/// there for [`TOUCHDOWN_HOLD_TIME`] (where the ground is when the height is measured well),
/// then at [`TOUCHDOWN_SEARCH_RATE`] `vtd` to [`TOUCHDOWN_SEARCH_DEPTH`], where it holds.
fn touchdown_search(s0: f64, vtd: f64, x: f64) -> (f64, f64) {
    let s = s0 + vtd * x;
    if s < TOUCHDOWN_OVERSHOOT {
        return (s, vtd);
    }
    let x1 = (TOUCHDOWN_OVERSHOOT - s0).max(0.0) / vtd + TOUCHDOWN_HOLD_TIME;
    let s1 = s0.max(TOUCHDOWN_OVERSHOOT);
    if x < x1 {
        return (s1, 0.0);
    }
    let v = TOUCHDOWN_SEARCH_RATE * vtd;
    let s = s1 + v * (x - x1);
    if s < TOUCHDOWN_SEARCH_DEPTH {
        (s, v)
    } else {
        (TOUCHDOWN_SEARCH_DEPTH, 0.0)
    }
}

/// Cosine ramp from rest to `v` over `t_r`: (distance, speed, acceleration) at τ ∈ [0, t_r].
fn ramp(v: f64, t_r: f64, tau: f64) -> (f64, f64, f64) {
    let w = core::f64::consts::PI / t_r;
    let (s, c) = (w * tau).sin_cos();
    (v * (0.5 * tau - s / (2.0 * w)), 0.5 * v * (1.0 - c), 0.5 * v * w * s)
}

impl GroundPhases {
    /// Number of values [`Self::save`] writes.
    pub const SAVED_LEN: usize = 20;

    /// The phase logic of `mission` for an airframe of weight `weight` (N).
    pub fn new(mission: MissionParams, weight: f64) -> Self {
        Self {
            mission,
            weight,
            origin: None,
            approach_start: None,
            touch_since: f64::NAN,
            contact_at: f64::NAN,
            share_mean: f64::NAN,
            share_var: f64::NAN,
            share_t: f64::NAN,
            landed: false,
            thrust_limit: f64::INFINITY,
            descent_thrust: f64::NAN,
            descent_thrust_t: f64::NAN,
            flare_height: f64::NAN,
        }
    }

    /// The same with the airframe's largest thrust `limit` (N): a thrust-limited flare
    /// ([`Self::flare_height`]). Without it the flare starts at `landing_flare_height`.
    pub fn with_thrust_limit(mut self, limit: f64) -> Self {
        self.thrust_limit = limit;
        self
    }

    /// Height of the flare above the target (m): `landing_flare_height`, raised so that the
    /// flare's deceleration `(V_d² − V_td²) / (2 (h_f − h_td))` leaves [`FLARE_LOOP_RESERVE`]
    /// of the thrust reserve over the descent's mean thrust to the loop (a wind
    /// that the hover needs much thrust against), within [`FLARE_HEIGHT_MAX`]. Fixed at
    /// [`FLARE_LATCH_HEIGHT`] above the target.
    pub fn flare_height(&self) -> f64 {
        if self.flare_height.is_nan() {
            self.mission.landing_flare_height
        } else {
            self.flare_height
        }
    }

    /// The thrust-limited flare height from the mean thrust `thrust` (N) ([`Self::flare_height`]).
    fn limited_flare_height(&self, thrust: f64) -> f64 {
        let m = &self.mission;
        let h_f = m.landing_flare_height;
        if !(self.thrust_limit.is_finite() && thrust.is_finite()) {
            return h_f;
        }
        let (vd, vtd) = (m.landing_descent_rate, m.landing_touchdown_rate);
        let a_max = CONTACT_GRAVITY * ((self.thrust_limit - thrust) / self.weight - FLARE_LOOP_RESERVE);
        let h_td = vtd * FINAL_SEGMENT_TIME;
        let needed = if a_max > 0.0 {
            h_td + (vd * vd - vtd * vtd) / (2.0 * a_max)
        } else {
            FLARE_HEIGHT_MAX
        };
        if needed > h_f {
            needed.min(FLARE_HEIGHT_MAX).max(h_f)
        } else {
            h_f
        }
    }

    /// Track the descent's mean thrust and fix the flare height at [`FLARE_LATCH_HEIGHT`]
    /// above the target (or at once, in a descent that starts lower).
    fn track_descent(&mut self, t: f64, meas: &Measurement, remaining: f64) {
        if !self.flare_height.is_nan() || !self.thrust_limit.is_finite() {
            return;
        }
        if self.descent_thrust.is_nan() {
            self.descent_thrust = meas.thrust;
        } else {
            let a = ((t - self.descent_thrust_t) / DESCENT_THRUST_TIME).clamp(0.0, 1.0);
            self.descent_thrust += a * (meas.thrust - self.descent_thrust);
        }
        self.descent_thrust_t = t;
        if remaining <= FLARE_LATCH_HEIGHT {
            self.flare_height = self.limited_flare_height(self.descent_thrust);
        }
    }

    /// Whether the mission starts at rest on the ground.
    pub fn takeoff(&self) -> bool {
        self.mission.takeoff_spinup_time > 0.0
    }

    /// Whether the mission ends with a landing.
    pub fn landing(&self) -> bool {
        self.mission.landing_descent_rate > 0.0
    }

    /// Whether landed (thrust cut).
    pub fn landed(&self) -> bool {
        self.landed
    }

    /// Mission origin: the take-off point once measured; the NED origin without take-off.
    pub fn origin(&self) -> Option<Vector3<f64>> {
        if self.takeoff() {
            self.origin
        } else {
            Some(Vector3::zeros())
        }
    }

    /// Start of the thesis's mission (s): after the spin-up and the take-off climb.
    pub fn mission_start(&self) -> f64 {
        if self.takeoff() {
            self.mission.takeoff_spinup_time + self.mission.takeoff_time
        } else {
            0.0
        }
    }

    /// Height gained in the take-off climb (m).
    pub fn takeoff_height(&self) -> f64 {
        if self.takeoff() {
            0.5 * self.mission.v_vertical * self.mission.takeoff_time
        } else {
            0.0
        }
    }

    /// The landing target (NED, m), once the origin is known.
    pub fn target(&self) -> Option<Vector3<f64>> {
        let m = &self.mission;
        self.origin()
            .map(|o| o + Vector3::new(m.landing_target_n, m.landing_target_e, m.landing_target_d))
    }

    /// Duration of the approach from `p0` to above the target (s).
    fn approach_time(&self, p0: &Vector3<f64>, target: &Vector3<f64>) -> f64 {
        let d = (target.xy() - p0.xy()).norm();
        APPROACH_MIN_TIME.max(1.5 * d / self.mission.landing_approach_speed)
    }

    /// End of the approach, at rest over the target.
    fn approach_end(&self, p0: &Vector3<f64>, v0: &Vector3<f64>, target: &Vector3<f64>, t_a: f64) -> Vector3<f64> {
        Vector3::new(target.x, target.y, p0.z + v0.z * t_a / 3.0)
    }

    /// The reference of the landing at time τ after the mission's end.
    fn landing_reference(
        &self,
        tau: f64,
        p0: &Vector3<f64>,
        v0: &Vector3<f64>,
        target: &Vector3<f64>,
    ) -> VerticalReference {
        let m = &self.mission;
        let t_a = self.approach_time(p0, target);
        let pa = self.approach_end(p0, v0, target, t_a);
        if tau < t_a {
            // Cubic Hermite from (P₀, v₀) to (P_a, 0): p = P₀ + T v₀ h₁₀(s) + (P_a − P₀) h₀₁(s).
            let s = (tau / t_a).max(0.0);
            let d = pa - p0;
            let (h10, h10d, h10dd) = (s * s * s - 2.0 * s * s + s, 3.0 * s * s - 4.0 * s + 1.0, 6.0 * s - 4.0);
            let (h01, h01d, h01dd) = (-2.0 * s * s * s + 3.0 * s * s, -6.0 * s * s + 6.0 * s, -12.0 * s + 6.0);
            return VerticalReference {
                phase: Phase::Approach,
                pos: p0 + v0 * (t_a * h10) + d * h01,
                vel: v0 * h10d + d * (h01d / t_a),
                accel: v0 * (h10dd / t_a) + d * (h01dd / (t_a * t_a)),
            };
        }
        let tau = tau - t_a;
        let (vd, vtd, tr) = (m.landing_descent_rate, m.landing_touchdown_rate, DESCENT_RAMP_TIME);
        let height = target.z - pa.z;
        let d_ramp = 0.5 * vd * tr;
        let t_const = ((height - d_ramp - self.flare_height()) / vd).max(0.0);
        // The flare ends FINAL_SEGMENT_TIME before the target: the aircraft meets the
        // ground at a steady sink rate (thrust ≈ weight, no deceleration thrust to bounce on).
        let d_final = vtd * FINAL_SEGMENT_TIME;
        let d_flare = (height - d_ramp - vd * t_const - d_final).max(0.0);
        let t_flare = 2.0 * d_flare / (vd + vtd);
        // (phase, distance sunk, sink rate, sink acceleration)
        let (phase, s, v, a) = if tau < tr {
            let (s, v, a) = ramp(vd, tr, tau);
            (Phase::Descent, s, v, a)
        } else if tau < tr + t_const {
            (Phase::Descent, d_ramp + vd * (tau - tr), vd, 0.0)
        } else {
            let x = tau - tr - t_const;
            let s0 = d_ramp + vd * t_const;
            if x < t_flare {
                let k = (vd - vtd) / t_flare;
                (Phase::Flare, s0 + vd * x - 0.5 * k * x * x, vd - k * x, -k)
            } else {
                let (s, v) = touchdown_search(s0 + d_flare - height, vtd, x - t_flare);
                (Phase::Flare, height + s, v, 0.0)
            }
        };
        VerticalReference {
            phase,
            pos: Vector3::new(pa.x, pa.y, pa.z + s),
            vel: Vector3::new(0.0, 0.0, v),
            accel: Vector3::new(0.0, 0.0, a),
        }
    }

    /// The mode at time `t` (s) with measurement `meas`; `mission_ref(τ)` is the
    /// controller's own mission reference (position, velocity; NED) at mission time τ with
    /// the mission origin and the user's reference offset but without the take-off shift
    /// (the `offset` of [`GroundMode::Mission`], added here), asked once, at the end of the
    /// mission, when landing.
    pub fn step(
        &mut self,
        t: f64,
        meas: &Measurement,
        mission_ref: impl FnOnce(f64) -> (Vector3<f64>, Vector3<f64>),
    ) -> GroundMode {
        let m = self.mission;
        if self.takeoff() && (self.origin.is_none() || t < m.takeoff_spinup_time) {
            // Re-measured at every sample on the gear, frozen at the take-off: a master may
            // hand the first sample the inputs' start values instead of the plant's outputs
            // (Jacobi, fmpy's SSP master), never those of the last sample of the spin-up.
            self.origin = Some(meas.pos_ned);
        }
        if self.landed {
            return GroundMode::Idle {
                phase: Phase::Landed,
                thrust: 0.0,
            };
        }
        let origin = self.origin().unwrap_or_else(Vector3::zeros);
        if self.takeoff() {
            let ts = m.takeoff_spinup_time;
            if t < ts {
                return GroundMode::Idle {
                    phase: Phase::OnGround,
                    thrust: m.takeoff_spinup_thrust * self.weight * (t / ts).clamp(0.0, 1.0),
                };
            }
            let tau = t - ts;
            if tau < m.takeoff_time {
                let (h, v, a) = ramp(m.v_vertical, m.takeoff_time, tau);
                return GroundMode::Vertical(VerticalReference {
                    phase: Phase::TakeOff,
                    pos: origin - Vector3::new(0.0, 0.0, h),
                    vel: Vector3::new(0.0, 0.0, -v),
                    accel: Vector3::new(0.0, 0.0, -a),
                });
            }
        }
        let tm = t - self.mission_start();
        let offset = Vector3::new(0.0, 0.0, -self.takeoff_height());
        let end = m.end_time();
        if !self.landing() || tm < end {
            return GroundMode::Mission { t: tm, offset };
        }
        let (p0, v0) = *self.approach_start.get_or_insert_with(|| {
            let (p, v) = mission_ref(end);
            (p + offset, v)
        });
        let target = origin + Vector3::new(m.landing_target_n, m.landing_target_e, m.landing_target_d);
        let mut r = self.landing_reference(tm - end, &p0, &v0, &target);
        if r.phase == Phase::Descent {
            let unfixed = self.flare_height.is_nan();
            self.track_descent(t, meas, target.z - r.pos.z);
            if unfixed && !self.flare_height.is_nan() {
                r = self.landing_reference(tm - end, &p0, &v0, &target);
            }
        }
        // A sink is commanded: the flare, or the descent at its full rate (not its ramp from
        // rest, where the aircraft is still slow in the air).
        let sinking = r.phase == Phase::Flare || r.phase == Phase::Descent && r.vel.z >= m.landing_descent_rate - 1e-9;
        if sinking && self.detect_landing(t, meas) {
            return GroundMode::Idle {
                phase: Phase::Landed,
                thrust: 0.0,
            };
        }
        GroundMode::Vertical(r)
    }

    /// The share of the weight the gear carries by the accelerometer, `f_x/g − T/(m g)` (–).
    pub fn gear_share(&self, meas: &Measurement) -> f64 {
        meas.specific_force_body.x / CONTACT_GRAVITY - meas.thrust / self.weight
    }

    /// Ground contact: the gear's share ([`Self::gear_share`]) above its mean in the air by
    /// at least [`CONTACT_REACTION`] and [`CONTACT_SIGMAS`] of its spread there, at most
    /// [`CONTACT_REACTION_MAX`] (module docs;
    /// the air's is the wing's drag and the estimate's noise). No height: the estimate's is
    /// metres off with GPS alone.
    pub fn ground_contact(&self, meas: &Measurement) -> bool {
        let (mean, var) = if self.share_mean.is_nan() {
            (0.0, 0.0)
        } else {
            (self.share_mean, self.share_var)
        };
        self.gear_share(meas) - mean
            > CONTACT_REACTION
                .max(CONTACT_SIGMAS * var.sqrt())
                .min(CONTACT_REACTION_MAX)
    }

    /// Track the gear's share in the air (no contact): exponential mean and variance over
    /// [`SHARE_TIME`].
    fn track_share(&mut self, t: f64, meas: &Measurement) {
        let x = self.gear_share(meas);
        if self.share_mean.is_nan() {
            (self.share_mean, self.share_var) = (x, 0.0);
        } else {
            let a = ((t - self.share_t) / SHARE_TIME).clamp(0.0, 1.0);
            let d = x - self.share_mean;
            self.share_mean += a * d;
            self.share_var = (1.0 - a) * (self.share_var + a * d * d);
        }
        self.share_t = t;
    }

    /// The land detector at `t` while a sink is commanded (the descent at its full rate and
    /// the flare): a ground
    /// contact within the last [`CONTACT_MEMORY`], the vertical speed below [`LANDED_SINK`]
    /// V_td and the tilt rate below [`LANDED_TILT_RATE`] for [`TOUCHDOWN_DWELL`] latch the
    /// landing.
    fn detect_landing(&mut self, t: f64, meas: &Measurement) -> bool {
        if self.ground_contact(meas) {
            self.contact_at = t;
        } else {
            self.track_share(t, meas);
        }
        let still = meas.vel_ned.z.abs() < LANDED_SINK * self.mission.landing_touchdown_rate
            && meas.rates.yz().norm() < LANDED_TILT_RATE;
        if !(still && t - self.contact_at <= CONTACT_MEMORY + 1e-9) {
            self.touch_since = f64::NAN;
            return false;
        }
        if self.touch_since.is_nan() {
            self.touch_since = t;
        }
        self.landed = t - self.touch_since >= TOUCHDOWN_DWELL - 1e-9;
        self.landed
    }

    /// Append the state ([`Self::SAVED_LEN`] values).
    pub fn save(&self, out: &mut impl FnMut(f64)) {
        let nan = Vector3::repeat(f64::NAN);
        out(f64::from(u8::from(self.origin.is_some())));
        for v in self.origin.unwrap_or(nan).iter() {
            out(*v);
        }
        out(f64::from(u8::from(self.approach_start.is_some())));
        let (p, v) = self.approach_start.unwrap_or((nan, nan));
        for x in p.iter().chain(v.iter()) {
            out(*x);
        }
        out(self.touch_since);
        out(f64::from(u8::from(self.landed)));
        out(self.contact_at);
        out(self.share_mean);
        out(self.share_var);
        out(self.share_t);
        out(self.descent_thrust);
        out(self.descent_thrust_t);
        out(self.flare_height);
    }

    /// Restore what [`Self::save`] wrote; `None` if values are missing.
    pub fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Option<()> {
        let mut v = [0.0; Self::SAVED_LEN];
        for x in v.iter_mut() {
            *x = next()?;
        }
        self.origin = (v[0] != 0.0).then(|| Vector3::new(v[1], v[2], v[3]));
        self.approach_start = (v[4] != 0.0).then(|| (Vector3::new(v[5], v[6], v[7]), Vector3::new(v[8], v[9], v[10])));
        self.touch_since = v[11];
        self.landed = v[12] != 0.0;
        self.contact_at = v[13];
        (self.share_mean, self.share_var, self.share_t) = (v[14], v[15], v[16]);
        (self.descent_thrust, self.descent_thrust_t, self.flare_height) = (v[17], v[18], v[19]);
        Some(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector4;

    fn meas(pos: Vector3<f64>, vel: Vector3<f64>) -> Measurement {
        Measurement {
            pos_ned: pos,
            vel_ned: vel,
            vel_body: Vector3::zeros(),
            rates: Vector3::zeros(),
            quat: Vector4::new(0.0, 0.5f64.sqrt(), 0.0, 0.5f64.sqrt()),
            airspeed: 0.0,
            alpha: 0.0,
            beta: 0.0,
            thrust: 0.0,
            surfaces: [0.0; 6],
            specific_force_body: Vector3::zeros(),
            induced_velocity: 0.0,
        }
    }

    fn ground_mission() -> MissionParams {
        MissionParams {
            takeoff_spinup_time: 2.0,
            takeoff_time: 2.0,
            landing_descent_rate: 1.5,
            landing_target_n: 30.0,
            landing_target_e: -4.0,
            ..Default::default()
        }
    }

    /// A straight vertical climb as the stand-in for a controller's mission reference.
    fn climb(m: &MissionParams, offset: Vector3<f64>) -> impl Fn(f64) -> (Vector3<f64>, Vector3<f64>) {
        let v = m.v_vertical;
        move |t| (offset + Vector3::new(0.0, 0.0, -v * t), Vector3::new(0.0, 0.0, -v))
    }

    #[test]
    fn defaults_fly_the_thesis_mission_untouched() {
        let m = MissionParams::default();
        let mut g = GroundPhases::new(m, 88.0);
        assert!(!g.takeoff() && !g.landing());
        for t in [0.0, 3.0, 35.0, 200.0] {
            let mode = g.step(
                t,
                &meas(Vector3::new(1.0, 2.0, 3.0), Vector3::zeros()),
                |_| unreachable!(),
            );
            assert_eq!(
                mode,
                GroundMode::Mission {
                    t,
                    offset: Vector3::zeros()
                }
            );
        }
    }

    #[test]
    fn spin_up_ramps_below_the_weight_and_take_off_is_smooth() {
        let m = ground_mission();
        let start = Vector3::new(5.0, 1.0, 9.56);
        let mut g = GroundPhases::new(m, 100.0);
        let at = |g: &mut GroundPhases, t| g.step(t, &meas(start, Vector3::zeros()), |_| unreachable!());
        assert_eq!(
            at(&mut g, 0.0),
            GroundMode::Idle {
                phase: Phase::OnGround,
                thrust: 0.0
            }
        );
        match at(&mut g, 1.0) {
            GroundMode::Idle {
                phase: Phase::OnGround,
                thrust,
            } => assert!((thrust - 45.0).abs() < 1e-12),
            other => panic!("{other:?}"),
        }
        let h = 1e-6;
        let mut tau: f64 = 0.0;
        while tau < 2.0 - 2.0 * h {
            let r = |t| match at(&mut g.clone(), 2.0 + t) {
                GroundMode::Vertical(r) => r,
                other => panic!("{other:?}"),
            };
            let (a, b, c) = (r((tau - h).max(0.0)), r(tau.max(h)), r(tau + h));
            assert_eq!(b.phase, Phase::TakeOff);
            let dt = tau + h - (tau - h).max(0.0);
            assert!(((c.pos - a.pos) / dt - b.vel).norm() < 1e-5, "τ = {tau}");
            assert!(((c.vel - a.vel) / dt - b.accel).norm() < 1e-4, "τ = {tau}");
            tau += 0.05;
        }
        // Starts at rest at the measured point, ends climbing at V_V at height V_V T/2,
        // where the mission takes over with the matching offset.
        let GroundMode::Vertical(r0) = at(&mut g, 2.0) else {
            panic!()
        };
        assert!((r0.pos - start).norm() < 1e-12 && r0.vel.norm() < 1e-12);
        let GroundMode::Vertical(r1) = at(&mut g, 4.0 - 1e-9) else {
            panic!()
        };
        assert!((r1.pos - (start - Vector3::new(0.0, 0.0, 3.0))).norm() < 1e-6);
        assert!((r1.vel.z + 3.0).abs() < 1e-6);
        let mode = at(&mut g, 4.0);
        assert_eq!(
            mode,
            GroundMode::Mission {
                t: 0.0,
                offset: Vector3::new(0.0, 0.0, -3.0)
            }
        );

        // A first sample with the inputs' start values (a Jacobi master) does not fix the
        // origin: the last sample on the gear does.
        let mut g = GroundPhases::new(m, 100.0);
        let none = |_| -> (Vector3<f64>, Vector3<f64>) { unreachable!() };
        g.step(0.0, &meas(Vector3::zeros(), Vector3::zeros()), none);
        g.step(1.98, &meas(start, Vector3::zeros()), none);
        let lifted = meas(start + Vector3::new(0.0, 0.0, -0.01), Vector3::zeros());
        let GroundMode::Vertical(r) = g.step(2.0, &lifted, none) else {
            panic!()
        };
        assert_eq!(r.pos, start);
    }

    #[test]
    fn landing_reference_is_continuous_and_ends_on_the_target() {
        let m = ground_mission();
        let origin = Vector3::new(0.0, 0.0, 9.56);
        let mut g = GroundPhases::new(m, 100.0);
        let air = meas(Vector3::new(0.0, 0.0, -50.0), Vector3::zeros());
        g.step(0.0, &meas(origin, Vector3::zeros()), |_| unreachable!());
        let shift = Vector3::new(0.0, 0.0, -g.takeoff_height());
        let offset = origin + shift;
        let t_end = g.mission_start() + m.end_time();
        let reference = |g: &mut GroundPhases, t: f64| match g.step(t, &air, climb(&m, origin)) {
            GroundMode::Vertical(r) => r,
            GroundMode::Mission { t: tm, .. } => {
                let (p, v) = climb(&m, offset)(tm);
                VerticalReference {
                    phase: Phase::Vertical2,
                    pos: p,
                    vel: v,
                    accel: Vector3::zeros(),
                }
            }
            other => panic!("{other:?}"),
        };
        let target = origin + Vector3::new(30.0, -4.0, 0.0);
        let h = 1e-6;
        let mut phases = Vec::new();
        let mut t = t_end - 1.0;
        let mut last = reference(&mut g, t);
        while t < t_end + 200.0 {
            t += 0.01;
            let r = reference(&mut g, t);
            assert!((r.pos - last.pos).norm() < 0.01 * 3.2 + 1e-9, "position jump at {t}");
            // (The velocity steps: to the search rate below the target and the hold at the
            // search depth, reached only if the touchdown is never detected.)
            let search = (r.vel.z - TOUCHDOWN_SEARCH_RATE * m.landing_touchdown_rate).abs() < 1e-12;
            let held = (r.vel == Vector3::zeros() || search) && r.phase == Phase::Flare;
            assert!(
                held || (r.vel - last.vel).norm() < 0.01 * 2.0,
                "velocity jump at {t}: {:?} {:?}",
                last.vel,
                r.vel
            );
            if r.phase != Phase::Vertical2 {
                let (a, b) = (reference(&mut g, t - h), reference(&mut g, t + h));
                if a.phase == b.phase && r.vel.norm() > 0.0 {
                    assert!(((b.pos - a.pos) / (2.0 * h) - r.vel).norm() < 1e-5, "t = {t}");
                }
                // Never climbs back up once descending, never below the search depth.
                assert!(r.pos.z <= target.z + TOUCHDOWN_SEARCH_DEPTH + 1e-9);
            }
            if phases.last() != Some(&r.phase) {
                phases.push(r.phase);
            }
            last = r;
        }
        assert_eq!(
            phases,
            [Phase::Vertical2, Phase::Approach, Phase::Descent, Phase::Flare]
        );
        // Without a touchdown it sinks on past the target at V_td (the target's height is an
        // estimate) and ends held the search depth below it, centred on it.
        assert!((last.pos - (target + Vector3::new(0.0, 0.0, TOUCHDOWN_SEARCH_DEPTH))).norm() < 1e-9);
        assert_eq!(last.vel, Vector3::zeros());
    }

    /// A one-second mission without take-off, then the landing at `descent_rate` (m/s) to
    /// `target_d` (m) below the origin.
    fn short_landing(descent_rate: f64, target_d: f64) -> MissionParams {
        MissionParams {
            landing_descent_rate: descent_rate,
            landing_target_d: target_d,
            t_vertical_1: 0.0,
            t_transition_1: 0.5,
            t_level: 0.0,
            t_transition_2: 0.5,
            t_vertical_2: 0.0,
            ..Default::default()
        }
    }

    /// The flare of a thrust-limited airframe: at still air's thrust the mission's flare
    /// height (the reference identical to one without a limit); at the thrust an upright
    /// hover needs in a 10 m/s wind (130 N of 150 N, 9 kg) raised so that the flare's
    /// deceleration leaves [`FLARE_LOOP_RESERVE`] of the weight to the loop; fixed at
    /// [`FLARE_LATCH_HEIGHT`]; the reference continuous through it.
    #[test]
    fn a_thrust_limited_flare_starts_higher_with_less_reserve() {
        let m = short_landing(2.0, 40.0);
        let weight = 9.0 * CONTACT_GRAVITY;
        let mref = |_| (Vector3::zeros(), Vector3::zeros());
        // Fly the reference with the thrust `thrust` measured; the last descent sample's height
        // above the target (the flare height) and the largest step of the reference position.
        let flare_at = |mut g: GroundPhases, thrust: f64| {
            let (mut t, mut last, mut h_flare, mut step) = (0.0, None::<VerticalReference>, f64::NAN, 0.0f64);
            while t < 60.0 {
                let mut x = meas(Vector3::zeros(), Vector3::zeros());
                x.thrust = thrust;
                if let GroundMode::Vertical(r) = g.step(t, &x, mref) {
                    if let Some(l) = last {
                        step = step.max((r.pos - l.pos).norm());
                        if l.phase == Phase::Descent && r.phase == Phase::Flare {
                            h_flare = m.landing_target_d - l.pos.z;
                        }
                    }
                    last = Some(r);
                }
                t += 0.02;
            }
            (h_flare, step, g.flare_height())
        };
        let plain = flare_at(GroundPhases::new(m, weight), 130.0);
        let still = flare_at(GroundPhases::new(m, weight).with_thrust_limit(150.0), 91.0);
        let windy = flare_at(GroundPhases::new(m, weight).with_thrust_limit(150.0), 130.0);
        assert_eq!(still, plain);
        assert_eq!(plain.2, m.landing_flare_height);
        assert!(
            (plain.0 - m.landing_flare_height).abs() < 2.0 * 0.02 + 1e-9,
            "{plain:?}"
        );
        // a = g ((150 − 130)/W − 0.17) = 0.554 m/s²: h_f = 0.3 + (2² − 0.3²)/(2 a) = 3.83 m.
        let a = CONTACT_GRAVITY * (20.0 / weight - FLARE_LOOP_RESERVE);
        let h_f = 0.3 + (4.0 - 0.09) / (2.0 * a);
        assert!((windy.2 - h_f).abs() < 1e-12 && (h_f - 3.83).abs() < 0.01, "{windy:?}");
        assert!((windy.0 - h_f).abs() < 2.0 * 0.02 + 1e-9, "{windy:?}");
        // No jump where the flare height is fixed (0.02 s at 2 m/s).
        assert!(windy.1 < 0.02 * 2.0 + 1e-9, "{windy:?}");
        // No reserve at all: the highest flare.
        let full = flare_at(GroundPhases::new(m, weight).with_thrust_limit(150.0), 150.0);
        assert_eq!(full.2, FLARE_HEIGHT_MAX);
    }

    /// A measurement in the flare: sinking at `sink` (m/s) at `height` (m) above the target
    /// (20 m down), thrust `thrust` and specific force along x `f_x` in weights / g, tilt
    /// rate `q` (rad/s).
    fn flare_meas(height: f64, sink: f64, thrust: f64, f_x: f64, q: f64) -> Measurement {
        let mut m = meas(Vector3::new(0.0, 0.0, 20.0 - height), Vector3::new(0.0, 0.0, sink));
        m.thrust = thrust * 100.0;
        m.specific_force_body = Vector3::new(f_x * CONTACT_GRAVITY, 0.0, 0.0);
        m.rates = Vector3::new(0.0, q, 0.0);
        m
    }

    #[test]
    fn the_land_detector_needs_ground_contact_not_the_height_then_latches() {
        let m = short_landing(1.0, 20.0);
        let mut g = GroundPhases::new(m, 100.0);
        let mref = |_| (Vector3::zeros(), Vector3::zeros());
        let air = meas(Vector3::zeros(), Vector3::zeros());
        // Before the descent even a resting aircraft on the gear is not landed.
        let resting = flare_meas(0.0, 0.0, 0.5, 1.0, 0.0);
        assert!(matches!(g.clone().step(1.0, &resting, mref), GroundMode::Vertical(r) if r.phase == Phase::Approach));
        // Find the flare.
        let mut t = 1.0;
        while !matches!(g.clone().step(t, &air, mref), GroundMode::Vertical(r) if r.phase == Phase::Flare) {
            t += 0.02;
        }
        // In the air: the wing's drag, −0.04 W, and the noise of an estimate (±0.01 W).
        for k in 0..400 {
            let noise = 0.01 * if k % 2 == 0 { 1.0 } else { -1.0 };
            let air = flare_meas(0.0, 0.0, 1.04, 1.0 + noise, 0.0);
            assert!(matches!(
                g.step(t + 0.02 * f64::from(k), &air, mref),
                GroundMode::Vertical(_)
            ));
        }
        t += 8.0;
        assert!(
            (g.share_mean + 0.04).abs() < 2e-3 && (g.share_var.sqrt() - 0.01).abs() < 2e-3,
            "{g:?}"
        );
        let flying = |g: &mut GroundPhases, t: f64, x: &Measurement| {
            for k in 0..50 {
                assert!(
                    matches!(g.step(t + 0.02 * f64::from(k), x, mref), GroundMode::Vertical(_)),
                    "{x:?}"
                );
            }
        };
        let landed = GroundMode::Idle {
            phase: Phase::Landed,
            thrust: 0.0,
        };
        // In the descent's ramp from rest (the aircraft still slow in the air) a rise of the
        // share (an estimate's accelerometer lagging a thrust change) is no landing.
        let mut gd = GroundPhases::new(m, 100.0);
        let mut td = 1.0;
        while !matches!(gd.clone().step(td, &air, mref), GroundMode::Vertical(r) if r.phase == Phase::Descent) {
            td += 0.02;
        }
        flying(&mut gd, td, &flare_meas(2.0, 0.0, 0.9, 1.0, 0.0));
        // Holding a height (sink stopped) at hover thrust, or well below it while falling
        // (f_x = T/m, no reaction): flying.
        flying(&mut g.clone(), t, &flare_meas(0.0, 0.0, 1.03, 0.98, 0.0));
        flying(&mut g.clone(), t, &flare_meas(0.5, 0.1, 0.6, 0.6, 0.0));
        // Noise of 4 σ above the mean: flying.
        flying(&mut g.clone(), t, &flare_meas(0.0, 0.0, 1.0, 1.0, 0.0));
        // The gear carries 0.3 W but the aircraft sinks faster than the commanded rate, or tips:
        // not landed.
        flying(&mut g.clone(), t, &flare_meas(0.0, 0.35, 0.7, 1.0, 0.0));
        flying(&mut g.clone(), t, &flare_meas(0.0, 0.0, 0.7, 1.0, 1.0));
        // On the gear at rest, thrust taken off: landed after the dwell wherever the
        // estimated height puts it (1.5 m above or below the target).
        for height in [1.5, -1.5] {
            let down = flare_meas(height, 0.05, 0.7, 1.0, 0.05);
            let mut g = g;
            let t0 = t + 2.0;
            let mut k = 0;
            while g.step(t0 + 0.02 * f64::from(k), &down, mref) != landed {
                k += 1;
                assert!(k < 100);
            }
            assert_eq!(k, 2);
        }
        // A soft touch on one leg (0.07 m/s: the share rises by 0.09 W, to +0.05, for a few
        // samples), then standing at hover thrust: landed.
        let mut gi = g;
        let t1 = t + 3.0;
        gi.step(t1, &flare_meas(0.0, 0.07, 1.04, 1.09, 0.0), mref);
        gi.step(t1 + 0.02, &flare_meas(0.0, 0.05, 1.04, 1.09, 0.0), mref);
        assert_eq!(gi.step(t1 + 0.04, &flare_meas(0.0, 0.03, 1.04, 1.0, 0.0), mref), landed);
        // An impact: the gear's spring stops the sink (one sample of reaction), the sink stays
        // stopped at hover thrust: landed after the dwell, within the contact memory.
        let t1 = t + 4.0;
        let mut gi = g;
        let still = flare_meas(0.0, 0.02, 1.0, 1.0, 0.0);
        assert!(matches!(
            gi.step(t1, &flare_meas(0.0, 0.4, 1.0, 1.8, 0.0), mref),
            GroundMode::Vertical(_)
        ));
        assert!(matches!(gi.step(t1 + 0.02, &still, mref), GroundMode::Vertical(_)));
        assert!(matches!(gi.step(t1 + 0.04, &still, mref), GroundMode::Vertical(_)));
        assert_eq!(gi.step(t1 + 0.06, &still, mref), landed);
        // The same impact followed by a still hover past the memory: forgotten.
        let mut gi = g;
        gi.step(t1, &flare_meas(0.0, 0.4, 1.0, 1.8, 0.0), mref);
        gi.step(t1 + 0.02, &flare_meas(0.0, 0.4, 1.0, 1.0, 0.0), mref);
        flying(&mut gi, t1 + CONTACT_MEMORY + 0.02, &still);
        // Latched for good.
        let down = flare_meas(0.0, 0.0, 0.7, 1.0, 0.0);
        g.step(t + 6.0, &down, mref);
        g.step(t + 6.02, &down, mref);
        assert_eq!(g.step(t + 6.04, &down, mref), landed);
        let sinking = flare_meas(0.5, 0.3, 1.0, 1.0, 0.0);
        assert_eq!(g.step(t + 7.0, &sinking, mref), landed);
        // Round trip of the state.
        let mut saved = Vec::new();
        g.save(&mut |x| saved.push(x));
        assert_eq!(saved.len(), GroundPhases::SAVED_LEN);
        let mut fresh = GroundPhases::new(m, 100.0);
        let mut it = saved.into_iter();
        fresh.restore(&mut || it.next()).unwrap();
        assert_eq!(fresh.step(t + 6.0, &sinking, mref), landed);
        assert!(fresh.approach_start.is_some() && fresh.landed());
    }
}
