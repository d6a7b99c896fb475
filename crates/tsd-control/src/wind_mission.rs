//! Mission logic in wind (tuned configuration; README, "Missions in wind"): the heading
//! ψ_w of the prescribed normal vector (§4.3.2.1) from the last seconds of the first
//! vertical phase through the front transition, level flight and the back transition into
//! the last vertical phase.
//!
//! A tail-sitter makes force along its nose (thrust) and its belly (the normal force of
//! the wing and of the surfaces in the slip-stream, pitch); along the span it has only the
//! weak rudder and vertical flaps. Unbanked, its plane of symmetry is the vertical plane of
//! bearing ψ_w in hover (belly towards ψ_w) as in level flight (nose towards ψ_w), so the
//! heading chooses which horizontal forces are made in the strong plane. The target is the
//! bearing of the horizontal specific force the flight needs, belly or back towards it
//! (whichever is nearer): the reference's own Σ^RE (4.3.35–4.3.36) — the push-over's
//! acceleration and the pull-up's deceleration, along the track — plus the wind load, the
//! low-passed difference between the measured horizontal specific force and Σ^RE. In hover
//! in a crosswind the load dominates and the belly faces the wind, as the weathervane turns
//! it, so the handover from the weathervane is continuous; as the front transition
//! accelerates along the track the target turns towards the track; in level flight the
//! heading does not act (γ = 0 makes the prescribed normal vector vertical, and the
//! computed one of (4.3.29–4.3.30) takes over); the back transition's deceleration turns
//! it back towards the track.
//!
//! Engaged with the weathervane (its filtered air-data wind at or above its engage speed,
//! released below its release speed), at its rate limit: in still air the logic is idle
//! and the calm mission is flown exactly as without it.

use flight_mission::{Measurement, MissionParams, Phase};
use guidance::weathervane::nearer_face;
use guidance::Weathervane;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// Time constant of the low-passed wind load (s).
pub const LOAD_FILTER_TIME: f64 = 1.0;
/// Horizontal specific force below which the heading is held (m/s²).
pub const MIN_HORIZONTAL_FORCE: f64 = 0.5;

/// Collective-flap trim per m/s of wind into the belly in the landing phases (rad s/m):
/// the slope of the plant's still, upright hover trim (−5.2°, −9.8°, −13.8° of collective
/// flaps at 1, 2, 3 m/s face-on, `cargo run --release -p analysis --example tsd_wind_bounds`).
pub const LANDING_FLAP_TRIM_GAIN: f64 = 4.6 * core::f64::consts::PI / 180.0;
/// Largest collective-flap trim in the landing phases (rad): the trim of the upright hover
/// is −20° from 5 m/s; the rest of the ±25° is left to the normal loop.
pub const LANDING_FLAP_TRIM_LIMIT: f64 = 17.0 * core::f64::consts::PI / 180.0;

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

/// State of the mission logic in wind: the low-passed horizontal wind load and whether the
/// logic and the take-off and landing heading are engaged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindMission {
    /// Low-passed horizontal (measured − reference) specific force, N and E (m/s²); NaN
    /// before the first sample.
    load: [f64; 2],
    engaged: bool,
    /// Whether the landing phases' heading is engaged: its own hysteresis, so that its lower
    /// engage speed does not reach the take-off or the mission's logic.
    ground_engaged: bool,
}

impl Default for WindMission {
    fn default() -> Self {
        Self {
            load: [f64::NAN; 2],
            engaged: false,
            ground_engaged: false,
        }
    }
}

/// The measured specific force in earth axes (NED) (m/s²).
fn specific_force_earth(m: &Measurement) -> Vector3<f64> {
    let q = &m.quat;
    let r = UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]));
    r * m.specific_force_body
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
/// 0 in other phases, without a wind estimate, or with the belly axis within 30° of the
/// vertical.
pub fn landing_flap_trim(m: &Measurement, phase: Phase, wind: &Vector3<f64>) -> f64 {
    let landing = matches!(phase, Phase::Approach | Phase::Descent | Phase::Flare);
    if !(landing && wind.x.is_finite() && wind.y.is_finite()) {
        return 0.0;
    }
    let q = &m.quat;
    let r = UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]));
    let (nose, belly) = (r * Vector3::x(), r * Vector3::z());
    let size = belly.xy().norm();
    if size < 0.5 {
        return 0.0;
    }
    let into_belly = -wind.xy().dot(&belly.xy()) / size;
    let trim = -(LANDING_FLAP_TRIM_GAIN * into_belly).clamp(-LANDING_FLAP_TRIM_LIMIT, LANDING_FLAP_TRIM_LIMIT);
    let (lo, hi) = LANDING_LEAN_GAIN_RANGE;
    let gain = (LANDING_LEAN_GAIN_PER_WIND * wind.xy().norm()).clamp(lo, hi);
    let sin_lean = nose.xy().dot(&belly.xy()) / size;
    trim - gain * sin_lean
}

impl WindMission {
    /// Whether the phase at mission time `t` is flown with this heading: the last
    /// `return_window` of the first vertical phase (where the weathervane alone would return
    /// to the mission's heading), the transitions and level flight, and the last vertical
    /// phase until the weathervane follows the wind again.
    pub fn in_window(wv: &Weathervane, mission: &MissionParams, t: f64) -> bool {
        let p = wv.params();
        let (phase, tau) = mission.phase_at(t);
        p.enabled
            && match phase {
                Phase::Vertical1 => mission.t_vertical_1 - tau <= p.return_window(),
                Phase::TransitionToLevel | Phase::Level | Phase::TransitionToVertical => true,
                Phase::Vertical2 => tau < p.settle_time,
                _ => false,
            }
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
        let p = wv.params();
        if !p.enabled {
            return None;
        }
        let f = specific_force_earth(m) - sigma_ref;
        if f.x.is_finite() && f.y.is_finite() {
            if self.load[0].is_finite() && self.load[1].is_finite() {
                let k = 1.0 - (-mission.sample_time / LOAD_FILTER_TIME).exp();
                self.load[0] += k * (f.x - self.load[0]);
                self.load[1] += k * (f.y - self.load[1]);
            } else {
                self.load = [f.x, f.y];
            }
        }
        self.engage(wv);
        if !(self.engaged && Self::in_window(wv, mission, t)) {
            return None;
        }
        let (n, e) = (sigma_ref.x + self.load[0], sigma_ref.y + self.load[1]);
        let heading = wv.heading();
        let size = n.hypot(e);
        if size.is_nan() || size < MIN_HORIZONTAL_FORCE {
            return Some((heading, p.max_rate));
        }
        Some((nearer_face(heading, e.atan2(n)), p.max_rate))
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

    /// Write the state ([`WIND_MISSION_STATE_LEN`] values).
    pub fn save(&self, out: &mut impl FnMut(f64)) {
        out(self.load[0]);
        out(self.load[1]);
        out(if self.engaged { 1.0 } else { 0.0 });
        out(if self.ground_engaged { 1.0 } else { 0.0 });
    }

    /// Restore what [`Self::save`] wrote (`v`: [`WIND_MISSION_STATE_LEN`] values).
    pub fn restore(&mut self, v: &[f64]) {
        self.load = [v[0], v[1]];
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
        let r = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), core::f64::consts::FRAC_PI_2);
        Measurement {
            specific_force_body: r.inverse() * (f_h - Vector3::new(0.0, 0.0, 9.81)),
            ..Measurement::still_in_air(&r, &(r.inverse() * (-w)))
        }
    }

    /// Still air: idle everywhere. A crosswind from the east held by a force towards the
    /// east: in the first vertical phase's return window the belly turns east (90°); in the
    /// front transition the reference's acceleration north turns it towards the track.
    #[test]
    fn idle_in_still_air_and_the_belly_towards_the_needed_force_in_wind() {
        let mission = MissionParams::default();
        let s = mission.phase_starts();
        let g = Vector3::new(0.0, 0.0, -9.81);
        let mut wv = Weathervane::new(WeathervaneParams::tuned()).unwrap();
        let mut wm = WindMission::default();
        for k in 0..200 {
            let t = k as f64 * mission.sample_time;
            assert_eq!(
                wm.target(&wv, &mission, t, &hovering(Vector3::zeros(), Vector3::zeros()), &g),
                None
            );
        }
        // 8 m/s from the east, 5 m/s² of horizontal force towards the east.
        let m = hovering(Vector3::new(0.0, -8.0, 0.0), Vector3::new(0.0, 5.0, 0.0));
        let mut last = None;
        for k in 0..((s[1] - 0.1) / mission.sample_time) as usize {
            let t = k as f64 * mission.sample_time;
            last = wm.target(&wv, &mission, t, &m, &g);
            wv.update_towards(&mission, t, &m, last);
        }
        assert!(wm.engaged() && WindMission::in_window(&wv, &mission, s[1] - 0.1));
        let (target, rate) = last.unwrap();
        assert!(
            (target - core::f64::consts::FRAC_PI_2).abs() < 0.05,
            "{}",
            target.to_degrees()
        );
        assert_eq!(rate, wv.params().max_rate);
        // In T1 with 5 m/s² along the track the bearing of (5, 5) is 45°.
        let sigma = Vector3::new(5.0, 0.0, -9.81);
        let m = hovering(Vector3::new(0.0, -8.0, 0.0), Vector3::new(5.0, 5.0, 0.0));
        let (target, _) = wm.target(&wv, &mission, s[1] + 0.5, &m, &sigma).unwrap();
        assert!(
            (target - core::f64::consts::FRAC_PI_4).abs() < 0.05,
            "{}",
            target.to_degrees()
        );
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
        let t = landing_flap_trim(&m, Phase::Descent, &from_north(3.0));
        assert!((deg(t) + 13.8).abs() < 1e-9, "{}", deg(t));
        let t = landing_flap_trim(&m, Phase::Flare, &from_north(-3.0));
        assert!((deg(t) - 13.8).abs() < 1e-9, "{}", deg(t));
        let t = landing_flap_trim(&m, Phase::Approach, &from_north(10.0));
        assert!((deg(t) + 17.0).abs() < 1e-9, "{}", deg(t));
        // Leaning 6° towards the belly in 5 m/s: 1.0 × sin 6° more flap towards the belly;
        // in 2 m/s (gain 0.8) and 10 m/s (1.6) the gain's range.
        let tilted = |deg: f64| {
            let r = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), (90.0 - deg).to_radians());
            Measurement::still_in_air(&r, &Vector3::zeros())
        };
        for (v, gain) in [(5.0, 1.0), (2.0, 0.8), (10.0, 1.6)] {
            let t = landing_flap_trim(&tilted(6.0), Phase::Descent, &from_north(v));
            let trim = -(4.6 * v).min(17.0).to_radians();
            assert!(
                (t - (trim - gain * 6f64.to_radians().sin())).abs() < 1e-12,
                "{v}: {}",
                deg(t)
            );
        }
        // Leaning towards the back: the other way.
        let t = landing_flap_trim(&tilted(-6.0), Phase::Descent, &Vector3::zeros());
        assert!((t - 0.8 * 6f64.to_radians().sin()).abs() < 1e-12, "{}", deg(t));
        // Along the span: no trim; outside the landing phases or without an estimate: none.
        assert!(landing_flap_trim(&m, Phase::Descent, &Vector3::new(0.0, 8.0, 0.0)).abs() < 1e-12);
        assert_eq!(landing_flap_trim(&m, Phase::Vertical2, &from_north(5.0)), 0.0);
        assert_eq!(landing_flap_trim(&m, Phase::Descent, &Vector3::repeat(f64::NAN)), 0.0);
    }
}
