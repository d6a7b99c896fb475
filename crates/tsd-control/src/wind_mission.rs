//! Mission logic in wind (tuned configuration; README, "Missions in wind"): the heading
//! ψ_w of the prescribed normal vector (§4.3.2.1) from the last seconds of the first
//! vertical phase through the front transition, level flight and the back transition into
//! the last vertical phase.
//!
//! A tail-sitter makes force along its nose (thrust) and its belly (the normal force of
//! the wing and of the surfaces in the slip-stream, pitch); along the span it has only the
//! weak rudder and vertical flaps. Unbanked, its plane of symmetry is the vertical plane of
//! bearing ψ_w in hover (belly towards ψ_w) as in level flight (nose towards ψ_w), so the
//! heading chooses which way the air meets it. The target is the bearing of the horizontal
//! air-relative velocity previewed by [`AIR_PREVIEW_TIME`], v_h − ŵ_h + τ Σ^RE_h (ŵ the
//! weathervane's filtered air-data wind, Σ^RE (4.3.35–4.3.36) the reference's specific
//! acceleration): the plane of symmetry along the air flow (small sideslip). In hover it is
//! the wind's bearing (belly or back into the wind, as the weathervane); through the front
//! transition it turns with the growing airspeed along the track towards the level flight's
//! crab; in level flight the heading does not act (γ = 0 makes the prescribed normal vector
//! vertical, and the computed one of (4.3.29–4.3.30) takes over); in the back transition it
//! turns back towards the wind.
//!
//! **Face.** The front transition pitches the nose over towards the belly, so the belly must
//! face the track's side when it starts: the face is chosen against the track
//! ([`track_face`]) — the belly towards the air flow within 90° + [`BELLY_MARGIN`] of the
//! track (a crosswind, a headwind), the back beyond (a tailwind), with a hysteresis band of
//! ±[`FACE_HYSTERESIS`] — not the nearer face of the weathervane, which could leave the back
//! towards a crosswind and turn the transition's heading away from the track.
//!
//! Engaged from the whole first vertical phase through the transitions and level flight
//! into the last vertical phase's `settle_time`, when the wind estimate engages: the
//! weathervane's 4 s estimate or this logic's own [`ENGAGE_FILTER_TIME`] one at or above the
//! engage speed (a wind stepping in 3 s before the transition is turned into at once),
//! released with the weathervane's below its release speed; the heading turns at up to
//! [`WINDOW_RATE`]. In still air the logic is idle and the calm mission is flown exactly as
//! without it.

use flight_mission::{Measurement, MissionParams, Phase};
use guidance::weathervane::{air_data_wind, nearer_face, wrap_pi};
use guidance::Weathervane;
use nalgebra::{Quaternion, UnitQuaternion, Vector2, Vector3};

/// Preview τ of the air-relative velocity by the reference's acceleration (s).
pub const AIR_PREVIEW_TIME: f64 = 1.0;
/// Time constant of the engagement's own air-data wind estimate (s).
pub const ENGAGE_FILTER_TIME: f64 = 1.0;
/// How far behind the beam the belly may face the air flow (rad).
pub const BELLY_MARGIN: f64 = 20.0 * core::f64::consts::PI / 180.0;
/// Half-width of the band around 90° + [`BELLY_MARGIN`] in which the nearer face is kept (rad).
pub const FACE_HYSTERESIS: f64 = 10.0 * core::f64::consts::PI / 180.0;
/// Largest heading rate of the mission logic (rad/s): a 90° turn in 3 s.
pub const WINDOW_RATE: f64 = 30.0 * core::f64::consts::PI / 180.0;
/// Previewed horizontal air-relative speed below which the heading is held (m/s).
pub const MIN_AIR_SPEED: f64 = 1.0;

pub use guidance::ground::{LANDING_FLAP_TRIM_GAIN, LANDING_FLAP_TRIM_LIMIT};

/// Collective flap per radian of lean towards the belly in the landing phases, per m/s of
/// the wind estimate (rad/rad per m/s), within [`LANDING_LEAN_GAIN_RANGE`]: the flaps' direct
/// force takes the wind load off the tilt (README, "Take-off and landing in wind").
pub const LANDING_LEAN_GAIN_PER_WIND: f64 = 0.2;
/// Range of the lean gain (rad/rad): 0.8 up to 4 m/s, 1.6 from 8 m/s. Measured with fixed
/// gains: 2.5 lost every 3 m/s take-off → landing cell and 1.5 one (the lean loop through the
/// flaps' pitching moment oscillates); 1.2 at 8 m/s tipped 4 of 8 over after the thrust cut.
/// Under Jacobi (a sample more of delay) 0.3 /(m/s) within 1.2–1.8 lost the 5 m/s tailwind
/// cell in the descent (20.4 m); this schedule holds it.
pub const LANDING_LEAN_GAIN_RANGE: (f64, f64) = (0.8, 1.6);

/// Time over which the collective flaps' landing command ([`landing_flap_trim`]) fades in
/// from the mission's end, by a cosine (s): the approach (4–6 s) starts with the trim and
/// the lean feedback partly on and the descent with them fully on, instead of a step of up
/// to −25° of flap when the last vertical phase ends leaning into the wind (Jacobi, 3 m/s:
/// 17–25° of lean, the step threw the aircraft to 70° and 10.9–24.8 m off in the approach;
/// faded over 8 s 2.9–9.3 m; steady wind under Gauss-Seidel, 10 m/s from the north 5.1 →
/// 1.7 m in the approach).
pub const LANDING_TRIM_RAMP_TIME: f64 = 8.0;

/// Vertical flap per radian of lean along the span in the landing phases (rad/rad): the
/// vertical flaps' direct side force takes the load off the span-wise lean, as the
/// collective flaps take it off the lean towards the belly ([`landing_vertical_flap`];
/// README, "Take-off and landing in wind"). Measured (moderate turbulence, 0–5 m/s, 24
/// cells): 0.5–2.5 keep the span-wise lean of the last 3 s before the touchdown at 7–18°
/// (11–28° without), 3.5 loses 22 of 24 cells (the loop through the flaps' yawing moment).
pub const LANDING_SPAN_LEAN_GAIN: f64 = 1.2;

/// Engage speed of the take-off and landing phases' heading (m/s): below the weathervane's
/// (3 m/s). Its estimate (a 4 s filter) reaches a steady 3 m/s wind only asymptotically, so a
/// 3 m/s wind engaged it from some bearings and not from others; not engaged, a quartering
/// 3 m/s wind met the belly and the span together and the aircraft touched down 12° from the
/// vertical. The landing phases only, with their own hysteresis: in the take-off, or through
/// the mission logic's flag, the lower speed turned the heading before the mission (3 m/s
/// cells under Jacobi lost in T2). Still air is unaffected (the estimate is 0).
pub const GROUND_ENGAGE_SPEED: f64 = 2.0;

/// Number of f64 values [`WindMission::save`] writes.
pub const WIND_MISSION_STATE_LEN: usize = 4;

/// State of the mission logic in wind: its own filtered horizontal air-data wind (for the
/// engagement) and whether the logic and the landing phases' heading are engaged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindMission {
    /// Air-data wind low-passed over [`ENGAGE_FILTER_TIME`], N and E (m/s); NaN before the
    /// first sample.
    wind: [f64; 2],
    engaged: bool,
    /// Whether the landing phases' heading is engaged: its own hysteresis, so that its lower
    /// engage speed does not reach the take-off or the mission's logic.
    ground_engaged: bool,
}

impl Default for WindMission {
    fn default() -> Self {
        Self {
            wind: [f64::NAN; 2],
            engaged: false,
            ground_engaged: false,
        }
    }
}

/// The heading nearest `heading` that puts the belly or the back towards `bearing` (rad),
/// the face chosen against the track (the mission's heading, 0): the belly when `bearing`
/// is within 90° + [`BELLY_MARGIN`] − [`FACE_HYSTERESIS`] of the track, the back beyond
/// 90° + [`BELLY_MARGIN`] + [`FACE_HYSTERESIS`], in between the face nearer `heading`.
pub fn track_face(heading: f64, bearing: f64) -> f64 {
    use core::f64::consts::{FRAC_PI_2, PI};
    let off = wrap_pi(bearing).abs();
    if off <= FRAC_PI_2 + BELLY_MARGIN - FACE_HYSTERESIS {
        heading + wrap_pi(bearing - heading)
    } else if off >= FRAC_PI_2 + BELLY_MARGIN + FACE_HYSTERESIS {
        heading + wrap_pi(bearing + PI - heading)
    } else {
        nearer_face(heading, bearing)
    }
}

/// Direct-force command of the collective flaps in the landing phases (approach, descent,
/// flare) (rad), from the filtered air-data wind `wind` (NED) and the measured attitude
/// (README, "Take-off and landing in wind"); the controller weights it with the measured
/// wind (0 in still air). Nose up, the flaps sit in the propellers' slip-stream (≈ 23 m/s in
/// hover): a wind into the belly turns the slip-stream's flow over the wing, whose normal
/// force then needs 30° of tilt at 3 m/s and 41° at 5 m/s to be held (measured at
/// touchdown), far outside an upright landing. The collective flaps deflected against the
/// wind cancel that force with the nose vertical (the plant's trim: −13.8° at 3 m/s, −20° at
/// 5–8 m/s; the elevator trims the moment). Two parts:
///
/// * the trim −[`LANDING_FLAP_TRIM_GAIN`] × (wind into the belly), within
///   ±[`LANDING_FLAP_TRIM_LIMIT`];
/// * the lean feedback −k_λ sin λ, λ the lean of the nose towards the belly's horizontal
///   direction, k_λ = [`LANDING_LEAN_GAIN_PER_WIND`] |ŵ_h| within
///   [`LANDING_LEAN_GAIN_RANGE`]. The TSD's normal loop regulates the normal specific force,
///   not the attitude: leaning into the wind and deflecting the flaps make the same force, and
///   with the trim alone the aircraft hung 20–23° into 5 m/s; with larger fixed trims the
///   attitude swung ±50° at a steady position. The lean feedback makes the flaps carry the
///   load the lean would carry, so the position loop levels the nose.
///
/// Faded in over [`LANDING_TRIM_RAMP_TIME`] from the mission's end (`since_mission_end`, s;
/// NaN: fully on). 0 in other phases, without a wind estimate, or with the belly axis within
/// 30° of the vertical.
pub fn landing_flap_trim(m: &Measurement, phase: Phase, wind: &Vector3<f64>, since_mission_end: f64) -> f64 {
    let landing = matches!(phase, Phase::Approach | Phase::Descent | Phase::Flare);
    if !(landing && wind.x.is_finite() && wind.y.is_finite()) {
        return 0.0;
    }
    // Faded in by a cosine over LANDING_TRIM_RAMP_TIME from the mission's end.
    let x = (since_mission_end / LANDING_TRIM_RAMP_TIME).clamp(0.0, 1.0);
    let ramp = if x.is_nan() {
        1.0
    } else {
        0.5 * (1.0 - (core::f64::consts::PI * x).cos())
    };
    let Some((belly, size, sin_lean)) = lean_towards(m, &Vector3::z()) else {
        return 0.0;
    };
    let into_belly = -wind.xy().dot(&belly) / size;
    let trim = -(LANDING_FLAP_TRIM_GAIN * into_belly).clamp(-LANDING_FLAP_TRIM_LIMIT, LANDING_FLAP_TRIM_LIMIT);
    let (lo, hi) = LANDING_LEAN_GAIN_RANGE;
    let gain = (LANDING_LEAN_GAIN_PER_WIND * wind.xy().norm()).clamp(lo, hi);
    ramp * (trim - gain * sin_lean)
}

/// The horizontal part of the body axis `axis` (NED), its length, and the sine of the nose's
/// lean towards it (the nose's horizontal part along it); `None` with the axis within 30° of
/// the vertical (length below 0.5).
fn lean_towards(m: &Measurement, axis: &Vector3<f64>) -> Option<(Vector2<f64>, f64, f64)> {
    let q = &m.quat;
    let r = UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]));
    let (nose, a) = (r * Vector3::x(), (r * axis).xy());
    let size = a.norm();
    (size >= 0.5).then(|| (a, size, nose.xy().dot(&a) / size))
}

/// Direct-force command of the vertical flaps in the descent and the flare (rad):
/// +[`LANDING_SPAN_LEAN_GAIN`] sin λ_s, λ_s the lean of the nose along the body's span (positive towards the right wing); the controller weights it with the
/// measured wind as [`landing_flap_trim`]. The tail-sitter makes force along its span only
/// by leaning the thrust that way or with the vertical flaps in the slip-stream (positive
/// towards the right wing: the plant's upright edge-on hover trim is +9.6° of vertical flap
/// in 5 m/s from the right, `cargo run --release -p analysis --example tsd_wind_bounds`).
/// The TSD's lateral loop regulates the force, not the attitude, so a span-wise gust is
/// met by leaning; this feedback hands that load to the flaps and the position loop levels
/// the nose (the span-wise counterpart of the lean feedback of [`landing_flap_trim`]).
///
/// 0 in other phases (the approach translates along the span, leaning on purpose) or with
/// the span within 30° of the vertical.
pub fn landing_vertical_flap(m: &Measurement, phase: Phase) -> f64 {
    if !matches!(phase, Phase::Descent | Phase::Flare) {
        return 0.0;
    }
    lean_towards(m, &Vector3::y()).map_or(0.0, |(_, _, sin_lean)| LANDING_SPAN_LEAN_GAIN * sin_lean)
}

/// Angle of attack above which the pitch guard pushes the nose down (rad, 26°): the wing's
/// stall (25°), past which the normal force no longer grows with α ([`pitch_guard`]).
pub const PITCH_GUARD_ALPHA: f64 = 0.45;
/// Nose-down δm per radian of α above [`PITCH_GUARD_ALPHA`] (rad/rad).
pub const PITCH_GUARD_ALPHA_GAIN: f64 = 1.0;
/// Angle of attack above which the pitch rate is limited (rad, 20°).
pub const PITCH_GUARD_RATE_ALPHA: f64 = 0.35;
/// Nose-up pitch rate the guard lets through above [`PITCH_GUARD_RATE_ALPHA`] (rad/s): the
/// still-air level flight and back transition pitch at up to 0.28 rad/s and α ≤ 8°.
pub const PITCH_GUARD_RATE: f64 = 1.0;
/// Nose-down δm per rad/s of pitch rate above [`PITCH_GUARD_RATE`] (rad per rad/s).
pub const PITCH_GUARD_RATE_GAIN: f64 = 0.3;
/// Time into level flight from which the guard acts there (s): the front transition's
/// thrust-borne recovery at its end (α up to 170° in 10 m/s from 135° in turbulence) is left
/// alone (guarded from the start of level flight, that cell was lost at 13.4 s).
pub const PITCH_GUARD_LEVEL_DELAY: f64 = 2.0;

/// Pitch guard of the normal loop in level flight and the back transition in wind (rad of
/// δm, positive nose down; README, "Missions in wind"):
/// [`PITCH_GUARD_ALPHA_GAIN`] (α − [`PITCH_GUARD_ALPHA`]) above the stall, plus
/// [`PITCH_GUARD_RATE_GAIN`] (Q − [`PITCH_GUARD_RATE`]) above the rate limit once α passes
/// [`PITCH_GUARD_RATE_ALPHA`]. `windy`: the mission logic's wind estimate at or above the
/// weathervane's release speed (0 otherwise: still air unchanged); `since_level` (s): mission
/// time since level flight began (level flight is guarded from [`PITCH_GUARD_LEVEL_DELAY`]).
///
/// The normal loop regulates the normal specific force C_W, not α. With the wind behind, the
/// still-air ground path leaves the wing less air (a 5 m/s tailwind at the level flight's
/// height in turbulence: 17–18 m/s of air for 25 m/s over the ground), while the pull-up's
/// curvature asks the force the path needs at the ground speed: δm saturates nose up, α passes
/// the stall, C_W falls with α and the loop pitches on; the axial loop, seeing the drag, puts
/// the thrust from 0 to 150 N in 0.2 s and the slip-stream over the surfaces still deflected
/// nose up turns the aircraft through the vertical at 4 rad/s (α 26° → 85° in 0.3 s, then
/// reversed flow). The guard does not forbid the high-α, thrust-borne pull-up: it slows the
/// pitch-up (the rate term) and holds the nose near the stall until the thrust has built.
pub fn pitch_guard(alpha: f64, q: f64, phase: Phase, windy: bool, since_level: f64) -> f64 {
    let guarded = match phase {
        Phase::Level => since_level >= PITCH_GUARD_LEVEL_DELAY,
        Phase::TransitionToVertical => true,
        _ => false,
    };
    if !(guarded && windy) {
        return 0.0;
    }
    let stall = PITCH_GUARD_ALPHA_GAIN * (alpha - PITCH_GUARD_ALPHA).max(0.0);
    let rate = if alpha > PITCH_GUARD_RATE_ALPHA {
        PITCH_GUARD_RATE_GAIN * (q - PITCH_GUARD_RATE).max(0.0)
    } else {
        0.0
    };
    stall + rate
}

impl WindMission {
    /// Whether the phase at mission time `t` is flown with this heading: the first vertical
    /// phase (so the face is the transition's from the start), the transitions and level
    /// flight, and the last vertical phase until the weathervane follows the wind again.
    pub fn in_window(wv: &Weathervane, mission: &MissionParams, t: f64) -> bool {
        let p = wv.params();
        let (phase, tau) = mission.phase_at(t);
        p.enabled
            && match phase {
                Phase::Vertical1 | Phase::TransitionToLevel | Phase::Level | Phase::TransitionToVertical => true,
                Phase::Vertical2 => tau < p.settle_time,
                _ => false,
            }
    }

    /// Horizontal speed of the logic's own [`ENGAGE_FILTER_TIME`] air-data wind estimate (m/s);
    /// NaN before its first sample.
    pub fn wind_speed(&self) -> f64 {
        self.wind[0].hypot(self.wind[1])
    }

    /// Whether the logic is engaged (the wind estimate's hysteresis).
    pub fn engaged(&self) -> bool {
        self.engaged
    }

    /// Update with the sample's measurement `m` and the reference's Σ^RE (NED) at mission
    /// time `t`; the target heading (rad) and its largest rate (rad/s) for
    /// [`Weathervane::update_towards`], or `None` (the weathervane's own). `wv` is the
    /// weathervane before its update at this sample.
    pub fn target(
        &mut self,
        wv: &Weathervane,
        mission: &MissionParams,
        t: f64,
        m: &Measurement,
        sigma_ref: &Vector3<f64>,
    ) -> Option<(f64, f64)> {
        if !wv.params().enabled {
            return None;
        }
        let raw = air_data_wind(m);
        if raw.x.is_finite() && raw.y.is_finite() {
            if self.wind[0].is_finite() && self.wind[1].is_finite() {
                let k = 1.0 - (-mission.sample_time / ENGAGE_FILTER_TIME).exp();
                self.wind[0] += k * (raw.x - self.wind[0]);
                self.wind[1] += k * (raw.y - self.wind[1]);
            } else {
                self.wind = [raw.x, raw.y];
            }
        }
        self.engage(wv);
        if self.wind[0].hypot(self.wind[1]) >= wv.params().engage_speed {
            self.engaged = true;
        }
        if !(self.engaged && Self::in_window(wv, mission, t)) {
            return None;
        }
        // The previewed horizontal air-relative velocity v − ŵ + τ Σ^RE.
        let w = wv.wind();
        let n = m.vel_ned.x - w.x + AIR_PREVIEW_TIME * sigma_ref.x;
        let e = m.vel_ned.y - w.y + AIR_PREVIEW_TIME * sigma_ref.y;
        let heading = wv.heading();
        let size = n.hypot(e);
        if size.is_nan() || size < MIN_AIR_SPEED {
            return Some((heading, WINDOW_RATE));
        }
        Some((track_face(heading, e.atan2(n)), WINDOW_RATE))
    }

    /// The engagement's hysteresis on the weathervane's filtered air-data wind.
    fn engage(&mut self, wv: &Weathervane) {
        self.engaged = Self::hysteresis(self.engaged, wv, wv.params().engage_speed);
    }

    /// Engaged after a sample with the weathervane's filtered air-data wind, engaged before
    /// `engaged`: at or above `engage_speed` (m/s) engaged, below the weathervane's release
    /// speed (or without an estimate) released, else as before.
    fn hysteresis(engaged: bool, wv: &Weathervane, engage_speed: f64) -> bool {
        let w = wv.wind();
        let speed = w.x.hypot(w.y);
        if speed >= engage_speed {
            true
        } else if speed.is_nan() || speed < wv.params().release_speed {
            false
        } else {
            engaged
        }
    }

    /// Whether the landing phases' heading is engaged (its own hysteresis, from
    /// [`GROUND_ENGAGE_SPEED`]).
    pub fn ground_engaged(&self) -> bool {
        self.ground_engaged
    }

    /// The heading target of the take-off and landing phases (README, "Take-off and landing
    /// in wind"), for [`Weathervane::update_towards`]: engaged, the belly or the back into the
    /// wind (the weathervane's); released, the heading held. `phase`: in the take-off engaged
    /// with the mission logic's hysteresis, in the landing phases (approach, descent, flare)
    /// with its own from [`GROUND_ENGAGE_SPEED`]. `None` with the weathervane off.
    pub fn ground_target(&mut self, wv: &Weathervane, phase: Phase) -> Option<(f64, f64)> {
        let p = wv.params();
        if !p.enabled {
            return None;
        }
        let engaged = if matches!(phase, Phase::Approach | Phase::Descent | Phase::Flare) {
            self.ground_engaged = Self::hysteresis(
                self.ground_engaged,
                wv,
                p.engage_speed.min(GROUND_ENGAGE_SPEED).max(p.release_speed),
            );
            self.ground_engaged
        } else {
            self.engage(wv);
            self.engaged
        };
        let heading = wv.heading();
        let w = wv.wind();
        if !(engaged && w.x.is_finite() && w.y.is_finite()) {
            return Some((heading, p.max_rate));
        }
        Some((nearer_face(heading, (-w.y).atan2(-w.x)), p.max_rate))
    }

    /// The heading target of the take-off climb (README, "Missions in wind"):
    /// [`Self::ground_target`] with the face chosen against the track ([`track_face`]), so
    /// the first vertical phase starts on the front transition's face instead of turning it
    /// round (from the back into a crosswind: 180° in the 5 s before the transition).
    pub fn takeoff_target(&mut self, wv: &Weathervane) -> Option<(f64, f64)> {
        let (target, rate) = self.ground_target(wv, Phase::TakeOff)?;
        let w = wv.wind();
        if !(self.engaged && w.x.is_finite() && w.y.is_finite()) {
            return Some((target, rate));
        }
        Some((track_face(wv.heading(), (-w.y).atan2(-w.x)), rate))
    }

    /// Write the state ([`WIND_MISSION_STATE_LEN`] values).
    pub fn save(&self, out: &mut impl FnMut(f64)) {
        out(self.wind[0]);
        out(self.wind[1]);
        out(if self.engaged { 1.0 } else { 0.0 });
        out(if self.ground_engaged { 1.0 } else { 0.0 });
    }

    /// Restore what [`Self::save`] wrote (`v`: [`WIND_MISSION_STATE_LEN`] values).
    pub fn restore(&mut self, v: &[f64]) {
        self.wind = [v[0], v[1]];
        self.engaged = v[2] != 0.0;
        self.ground_engaged = v[3] != 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use guidance::WeathervaneParams;

    /// Nose up, belly north, hovering still in the horizontal wind `w` (NED) while making
    /// the horizontal specific force `f_h` (NED, m/s²) against it.
    fn hovering(w: Vector3<f64>, f_h: Vector3<f64>) -> Measurement {
        moving(w, Vector3::zeros(), f_h)
    }

    /// As [`hovering`], moving at the velocity `v` (NED).
    fn moving(w: Vector3<f64>, v: Vector3<f64>, f_h: Vector3<f64>) -> Measurement {
        let r = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), core::f64::consts::FRAC_PI_2);
        Measurement {
            specific_force_body: r.inverse() * (f_h - Vector3::new(0.0, 0.0, 9.81)),
            vel_ned: v,
            ..Measurement::still_in_air(&r, &(r.inverse() * (v - w)))
        }
    }

    /// A weathervane at `heading` (rad) with the filtered wind `w` (NED) settled.
    fn weathervane_at(heading: f64, w: Vector3<f64>) -> Weathervane {
        let mut wv = Weathervane::new(WeathervaneParams::tuned()).unwrap();
        let v = [w.x, w.y, w.z, heading, 1.0];
        let mut it = v.into_iter();
        wv.restore(&mut || it.next()).unwrap();
        wv
    }

    /// Still air: idle everywhere. Engaged by its own 1 s estimate half a second after an
    /// 8 m/s step (the weathervane's 4 s estimate needs 1.9 s).
    #[test]
    fn idle_in_still_air_and_engaged_soon_after_a_wind_step() {
        let mission = MissionParams::default();
        let g = Vector3::new(0.0, 0.0, -9.81);
        let mut wv = Weathervane::new(WeathervaneParams::tuned()).unwrap();
        let mut wm = WindMission::default();
        for k in 0..200 {
            let t = k as f64 * mission.sample_time;
            let m = hovering(Vector3::zeros(), Vector3::zeros());
            assert_eq!(wm.target(&wv, &mission, t, &m, &g), None);
            wv.update_towards(&mission, t, &m, None);
        }
        let m = hovering(Vector3::new(0.0, -8.0, 0.0), Vector3::zeros());
        let mut engaged_after = None;
        for k in 0..100 {
            let t = 4.0 + k as f64 * mission.sample_time;
            let target = wm.target(&wv, &mission, t, &m, &g);
            wv.update_towards(&mission, t, &m, target);
            if target.is_some() && engaged_after.is_none() {
                engaged_after = Some(k as f64 * mission.sample_time);
            }
        }
        let after = engaged_after.unwrap();
        assert!((0.4..0.55).contains(&after), "{after}");
        assert!(!wv.engaged());
    }

    /// The face against the track: an 8 m/s wind from the east is faced with the belly
    /// (+90°) even from the back face (−90°: the weathervane's nearer face would stay); from
    /// the west with the belly (−90°); a tailwind from the south with the back (0°); one from
    /// 135° with the back (−45°). In the front transition, 10 m/s along the track and
    /// 5 m/s² of Σ^RE with the east wind: the bearing of (15, 8), 28°.
    #[test]
    fn belly_towards_the_air_flow_on_the_tracks_side() {
        let mission = MissionParams::default();
        let s = mission.phase_starts();
        let g = Vector3::new(0.0, 0.0, -9.81);
        let deg = |x: f64| x.to_degrees();
        let case = |from_deg: f64, heading_deg: f64| {
            let b = from_deg.to_radians();
            let w = -8.0 * Vector3::new(b.cos(), b.sin(), 0.0);
            let wv = weathervane_at(heading_deg.to_radians(), w);
            let mut wm = WindMission::default();
            let (target, rate) = wm
                .target(&wv, &mission, 1.0, &hovering(w, Vector3::zeros()), &g)
                .unwrap();
            assert_eq!(rate, WINDOW_RATE);
            deg(target)
        };
        for (from, heading, expected) in [
            (90.0, -90.0, 90.0),
            (90.0, 0.0, 90.0),
            (270.0, 90.0, -90.0),
            (180.0, 0.0, 0.0),
            (135.0, 0.0, -45.0),
            (225.0, 0.0, 45.0),
        ] {
            let t = case(from, heading);
            let off = wrap_pi((t - expected).to_radians());
            assert!(off.abs() < 1e-8, "from {from}°, heading {heading}°: {t}°");
        }
        // Inside the hysteresis band (115° from the track) the nearer face is kept.
        assert!((case(115.0, 90.0) - 115.0).abs() < 1e-6);
        assert!((case(115.0, 0.0) + 65.0).abs() < 1e-6);
        // Front transition.
        let w = Vector3::new(0.0, -8.0, 0.0);
        let wv = weathervane_at(core::f64::consts::FRAC_PI_2, w);
        let mut wm = WindMission::default();
        let m = moving(w, Vector3::new(10.0, 0.0, -2.0), Vector3::zeros());
        let sigma = Vector3::new(5.0, 0.0, -9.81);
        let (target, _) = wm.target(&wv, &mission, s[1] + 1.0, &m, &sigma).unwrap();
        assert!((deg(target) - deg(8f64.atan2(15.0))).abs() < 1e-6, "{}", deg(target));
    }

    /// The take-off and landing phases: still air holds the heading exactly (the calm
    /// flights unchanged); a steady 8 m/s wind from the east turns the belly or the back
    /// into it (±90°) once the filtered estimate has engaged.
    #[test]
    fn ground_heading_holds_in_still_air_and_faces_the_wind() {
        let mission = MissionParams::default();
        let mut wv = Weathervane::new(WeathervaneParams::tuned()).unwrap();
        let mut wm = WindMission::default();
        let calm = hovering(Vector3::zeros(), Vector3::zeros());
        for k in 0..100 {
            let target = wm.ground_target(&wv, Phase::Descent);
            assert_eq!(target, Some((0.0, wv.params().max_rate)));
            wv.update_towards(&mission, k as f64 * mission.sample_time, &calm, target);
            assert_eq!(wv.heading(), 0.0);
        }
        let m = hovering(Vector3::new(0.0, -8.0, 0.0), Vector3::zeros());
        for k in 0..1500 {
            let target = wm.ground_target(&wv, Phase::Descent);
            wv.update_towards(&mission, k as f64 * mission.sample_time, &m, target);
        }
        assert!(wm.ground_engaged() && !wm.engaged());
        let (target, _) = wm.ground_target(&wv, Phase::Descent).unwrap();
        assert!(
            (target.abs() - core::f64::consts::FRAC_PI_2).abs() < 0.02,
            "{}",
            target.to_degrees()
        );
        assert!((wv.heading() - target).abs() < 0.02, "{}", wv.heading().to_degrees());
    }

    /// The take-off climb in 8 m/s from the west: the ground phases' nearer face is the back
    /// (+90°), the take-off's the belly (−90°), the face the front transition needs.
    #[test]
    fn takeoff_faces_the_wind_with_the_transitions_face() {
        let w = Vector3::new(0.0, 8.0, 0.0);
        let wv = weathervane_at(0.0, w);
        let mut wm = WindMission::default();
        let (ground, _) = wm.ground_target(&wv, Phase::TakeOff).unwrap();
        let (takeoff, rate) = wm.takeoff_target(&wv).unwrap();
        assert!((ground.to_degrees() - 90.0).abs() < 1e-9, "{}", ground.to_degrees());
        assert!((takeoff.to_degrees() + 90.0).abs() < 1e-9, "{}", takeoff.to_degrees());
        assert_eq!(rate, wv.params().max_rate);
    }

    /// The landing phases' heading engages at [`GROUND_ENGAGE_SPEED`], below the
    /// weathervane's engage speed: a steady 2.5 m/s wind from the north-east turns the belly
    /// or the back into it in the descent; 1.5 m/s does not (the heading is held), nor does
    /// 2.5 m/s in the take-off (the weathervane's engage speed there).
    #[test]
    fn landing_heading_engages_below_the_weathervanes_engage_speed() {
        let mission = MissionParams::default();
        let fly = |speed: f64, phase: Phase| {
            let mut wv = Weathervane::new(WeathervaneParams::tuned()).unwrap();
            let mut wm = WindMission::default();
            let d = core::f64::consts::FRAC_1_SQRT_2 * speed;
            let m = hovering(Vector3::new(-d, -d, 0.0), Vector3::zeros());
            for k in 0..2000 {
                let target = wm.ground_target(&wv, phase);
                wv.update_towards(&mission, k as f64 * mission.sample_time, &m, target);
            }
            assert!(wv.params().engage_speed > 2.5);
            (wm.ground_engaged() || wm.engaged(), wv.heading())
        };
        let (engaged, heading) = fly(2.5, Phase::Descent);
        assert!(engaged);
        // Belly or back towards 45°: within 0.02 rad of 45° modulo 180°.
        let off = (heading - core::f64::consts::FRAC_PI_4).rem_euclid(core::f64::consts::PI);
        assert!(off.min(core::f64::consts::PI - off) < 0.02, "{}", heading.to_degrees());
        assert_eq!(fly(1.5, Phase::Descent), (false, 0.0));
        assert_eq!(fly(2.5, Phase::TakeOff), (false, 0.0));
    }

    /// The collective-flap command: −4.6° per m/s of wind into the belly, ±17° at most, the
    /// sign following the face, and the lean feedback; only in the landing phases.
    #[test]
    fn landing_flap_trim_opposes_the_wind_into_the_belly() {
        let m = hovering(Vector3::zeros(), Vector3::zeros());
        let from_north = |v: f64| Vector3::new(-v, 0.0, 0.0);
        let deg = |x: f64| x.to_degrees();
        let t = landing_flap_trim(&m, Phase::Descent, &from_north(3.0), 100.0);
        assert!((deg(t) + 13.8).abs() < 1e-9, "{}", deg(t));
        let t = landing_flap_trim(&m, Phase::Flare, &from_north(-3.0), 100.0);
        assert!((deg(t) - 13.8).abs() < 1e-9, "{}", deg(t));
        let t = landing_flap_trim(&m, Phase::Approach, &from_north(10.0), 100.0);
        assert!((deg(t) + 17.0).abs() < 1e-9, "{}", deg(t));
        // Leaning 6° towards the belly in 5 m/s: 1.0 × sin 6° more flap towards the belly;
        // in 2 m/s (gain 0.8) and 10 m/s (1.6) the gain's range.
        let tilted = |deg: f64| {
            let r = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), (90.0 - deg).to_radians());
            Measurement::still_in_air(&r, &Vector3::zeros())
        };
        for (v, gain) in [(5.0, 1.0), (2.0, 0.8), (10.0, 1.6)] {
            let t = landing_flap_trim(&tilted(6.0), Phase::Descent, &from_north(v), 100.0);
            let trim = -(4.6 * v).min(17.0).to_radians();
            assert!(
                (t - (trim - gain * 6f64.to_radians().sin())).abs() < 1e-12,
                "{v}: {}",
                deg(t)
            );
        }
        // Leaning towards the back: the other way.
        let t = landing_flap_trim(&tilted(-6.0), Phase::Descent, &Vector3::zeros(), 100.0);
        assert!((t - 0.8 * 6f64.to_radians().sin()).abs() < 1e-12, "{}", deg(t));
        // Along the span: no trim; outside the landing phases or without an estimate: none.
        assert!(landing_flap_trim(&m, Phase::Descent, &Vector3::new(0.0, 8.0, 0.0), 100.0).abs() < 1e-12);
        assert_eq!(landing_flap_trim(&m, Phase::Vertical2, &from_north(5.0), 100.0), 0.0);
        assert_eq!(
            landing_flap_trim(&m, Phase::Descent, &Vector3::repeat(f64::NAN), 100.0),
            0.0
        );
        // Faded in from the mission's end: 0 at its end, half at half the ramp time, whole
        // from the ramp time; NaN (no mission end known) whole.
        let full = landing_flap_trim(&m, Phase::Approach, &from_north(3.0), LANDING_TRIM_RAMP_TIME);
        assert!((deg(full) + 13.8).abs() < 1e-9, "{}", deg(full));
        assert_eq!(landing_flap_trim(&m, Phase::Approach, &from_north(3.0), 0.0), 0.0);
        let half = landing_flap_trim(&m, Phase::Approach, &from_north(3.0), 0.5 * LANDING_TRIM_RAMP_TIME);
        assert!((half - 0.5 * full).abs() < 1e-12, "{}", deg(half));
        assert_eq!(landing_flap_trim(&m, Phase::Approach, &from_north(3.0), f64::NAN), full);
    }

    /// The pitch guard: in the back transition with a wind estimate, 1 rad of nose-down δm per
    /// radian of α above 26° plus 0.3 rad per rad/s of pitch rate above 1 rad/s once α passes
    /// 20°; in level flight only from 2 s in; nothing in still air or in the other phases.
    #[test]
    fn pitch_guard_slows_the_pitch_up_past_the_stall_in_wind() {
        let t2 = Phase::TransitionToVertical;
        let a = PITCH_GUARD_ALPHA;
        assert_eq!(pitch_guard(0.3, 3.0, t2, true, 20.0), 0.0);
        assert_eq!(pitch_guard(0.4, 0.9, t2, true, 20.0), 0.0);
        assert!((pitch_guard(0.4, 2.0, t2, true, 20.0) - 0.3).abs() < 1e-12);
        assert!((pitch_guard(a + 0.2, 0.0, t2, true, 20.0) - 0.2).abs() < 1e-12);
        assert!((pitch_guard(a + 0.2, 3.0, t2, true, 20.0) - 0.8).abs() < 1e-12);
        assert!((pitch_guard(a + 0.2, 0.0, Phase::Level, true, 2.5) - 0.2).abs() < 1e-12);
        assert_eq!(pitch_guard(a + 0.2, 3.0, Phase::Level, true, 1.5), 0.0);
        assert_eq!(pitch_guard(a + 0.5, 3.0, t2, false, 20.0), 0.0);
        for phase in [
            Phase::Vertical1,
            Phase::TransitionToLevel,
            Phase::Vertical2,
            Phase::Descent,
        ] {
            assert_eq!(pitch_guard(a + 0.5, 3.0, phase, true, 20.0), 0.0);
        }
    }

    /// The vertical flaps' span-wise lean feedback: nose up, belly north, the right wing
    /// east; leaning 6° east (towards the right wing) deflects the vertical flaps
    /// +1.2 sin 6° (their side force towards the right wing takes the load), west the other
    /// way; leaning towards the belly does nothing; only in the descent and the flare.
    #[test]
    fn landing_vertical_flap_takes_the_span_wise_lean() {
        let up = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), core::f64::consts::FRAC_PI_2);
        let leaning = |axis: Vector3<f64>, deg: f64| {
            let r = UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis), deg.to_radians()) * up;
            Measurement::still_in_air(&r, &Vector3::zeros())
        };
        // About the north axis by +6°: the nose (up) tips east.
        let east = leaning(Vector3::x(), 6.0);
        let q = &east.quat;
        let r = UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]));
        assert!((r * Vector3::x()).y > 0.1 && (r * Vector3::y()).y > 0.9);
        let expected = LANDING_SPAN_LEAN_GAIN * 6f64.to_radians().sin();
        for phase in [Phase::Descent, Phase::Flare] {
            assert!((landing_vertical_flap(&east, phase) - expected).abs() < 1e-12);
            let west = leaning(Vector3::x(), -6.0);
            assert!((landing_vertical_flap(&west, phase) + expected).abs() < 1e-12);
            let north = leaning(Vector3::y(), -6.0);
            let q = &north.quat;
            let r = UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]));
            assert!((r * Vector3::x()).x > 0.1);
            assert!(landing_vertical_flap(&north, phase).abs() < 1e-12);
        }
        for phase in [Phase::Approach, Phase::Vertical2, Phase::TakeOff] {
            assert_eq!(landing_vertical_flap(&east, phase), 0.0);
        }
    }
}
