//! Weathervaning of the heading reference in vertical flight (issue 16), shared by the
//! controllers.
//!
//! A tail-sitter hanging on its propellers offers the wind either its wing's face (belly or
//! back, the plane of symmetry along the wind) or its span (the wind along the wing). Into
//! the belly or the back the wind is a headwind at large α: holding position needs the nose
//! tilted into the wind, the pitch loop (elevator and flaps in the slip-stream) carries it
//! and the wing's normal force points downwind and up. Along the span the wind is a
//! sideslip of up to 90°: the vertical surfaces are small, the rudder has little authority
//! against the side force and the roll/yaw couplings of β, and both controllers lose the
//! aircraft in a 5–7 m/s crosswind. So in vertical flight the heading reference turns the
//! belly or the back — whichever is nearer — into the wind.
//!
//! **Heading.** Rotation of the reference attitude about the earth's down axis by ψ_w (rad),
//! ψ_w = 0 = the mission's reference. In vertical flight the belly points towards the bearing
//! ψ_w (nose up, heading north: belly north).
//!
//! **Wind estimate (what is measured).** The air-data wind
//! `ŵ_raw = v_NED − DCM_EB v_air`, `v_air = V̄ (cα cβ, sβ, sα cβ)` (inverse of
//! (2.2.12–2.2.13)), from the measured airspeed, α, β, attitude and inertial velocity,
//! low-passed with the time constant `filter_time`: only its horizontal part is used. In
//! still air it is zero to rounding, so the weathervane is idle and a calm mission is flown
//! exactly as without it. (The steady tilt needed to hold position points into the wind as
//! well, but it also carries every manoeuvre's acceleration and is zero for a wind into the
//! face while the tilt is small; the air data see the wind directly.)
//!
//! **Target.** Engaged when |ŵ_h| ≥ `engage_speed`, released below `release_speed`
//! (hysteresis): the bearing the wind comes from, b = atan2(−ŵ_E, −ŵ_N), puts the belly into
//! the wind (ψ_w = b) and b + π the back; the one nearer the present ψ_w is taken, so the
//! aircraft turns by at most 90°. Released, the heading is held. In the first vertical phase
//! the target is 0 from `return_window` = (π/2)/`max_rate` + `return_margin` before the
//! transition (the transitions and level flight follow the mission's heading); in the
//! transitions and level flight it is 0; in the last vertical phase it is free from
//! `settle_time` after its start (the back transition's errors settle first: turning at once
//! left the LQR 40° off vertical at the end of the default mission in a 3 m/s crosswind).
//!
//! **Rate limit.** ψ̇_w = clamp((target − ψ_w)/`time_constant`, ±`max_rate`): a first-order
//! approach, rate-limited, so the heading reference and its rate are continuous.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use flight_mission::{Measurement, MissionParams, Phase};

/// Time constant of the tuned wind estimate (s).
const FILTER_TIME: f64 = 4.0;
/// Engage speed of the tuned weathervane (m/s).
const ENGAGE_SPEED: f64 = 3.0;

/// Tuning of the weathervane (not FMU parameters: fixed per controller configuration).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeathervaneParams {
    /// Off: the heading reference is the mission's (the thesis configurations).
    pub enabled: bool,
    /// Time constant of the low-pass air-data wind estimate (s).
    pub filter_time: f64,
    /// Horizontal wind speed from which the heading follows the wind (m/s).
    pub engage_speed: f64,
    /// Horizontal wind speed below which the heading is held (m/s).
    pub release_speed: f64,
    /// Largest heading rate (rad/s).
    pub max_rate: f64,
    /// Time constant of the approach to the target heading (s).
    pub time_constant: f64,
    /// Time the heading is back at the mission's before the first transition, beyond the
    /// worst-case turn (π/2)/`max_rate` + 3 `time_constant` (s).
    pub return_margin: f64,
    /// Time into the last vertical phase from which the heading follows the wind (s): the
    /// back transition's errors settle first.
    pub settle_time: f64,
}

impl WeathervaneParams {
    /// Weathervaning off.
    pub fn disabled() -> Self {
        Self {
            enabled: false,
            ..Self::tuned()
        }
    }

    /// The tuned configuration's weathervane (README of each controller, "Weathervaning"):
    /// a 4 s estimate and engaged from 3 m/s, so that a 1 − cos gust turns the aircraft little
    /// (with 2 s and 2 m/s a 6 m/s, 5 s crosswind gust turned the TSD mid-gust: 11 m off;
    /// below 3 m/s a crosswind is flown as it comes), released below 1 m/s, a 90° turn in
    /// about 5 s at most 20°/s, following the wind from 5 s into the last vertical phase.
    pub fn tuned() -> Self {
        Self {
            enabled: true,
            filter_time: FILTER_TIME,
            engage_speed: ENGAGE_SPEED,
            release_speed: 1.0,
            max_rate: 20f64.to_radians(),
            time_constant: 0.5,
            return_margin: 0.5,
            settle_time: 5.0,
        }
    }

    /// Time before the first transition from which the target is the mission's heading (s):
    /// the worst-case turn at the rate limit, three time constants of the approach (5 % of
    /// the rate-limited band left) and the margin.
    pub fn return_window(&self) -> f64 {
        std::f64::consts::FRAC_PI_2 / self.max_rate + 3.0 * self.time_constant + self.return_margin
    }

    fn validate(&self) -> Result<(), String> {
        let positive = [
            ("filter_time", self.filter_time),
            ("max_rate", self.max_rate),
            ("time_constant", self.time_constant),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("weathervane {name} = {v}: must be finite and > 0"));
            }
        }
        if !(self.release_speed.is_finite()
            && self.release_speed >= 0.0
            && self.engage_speed.is_finite()
            && self.engage_speed >= self.release_speed
            && self.return_margin.is_finite()
            && self.return_margin >= 0.0
            && self.settle_time.is_finite()
            && self.settle_time >= 0.0)
        {
            return Err(format!(
                "weathervane speeds {} / {} m/s and margin {} s: need 0 <= release <= engage, margin >= 0 (settle time {} s: >= 0)",
                self.release_speed, self.engage_speed, self.return_margin, self.settle_time
            ));
        }
        Ok(())
    }
}

/// The heading reference of one sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HeadingRef {
    /// Rotation ψ_w of the reference attitude about the earth's down axis (rad).
    pub heading: f64,
    /// Its rate ψ̇_w (rad/s).
    pub rate: f64,
}

/// Number of f64 values [`Weathervane::save`] writes.
pub const WEATHERVANE_STATE_LEN: usize = 5;

/// The weathervane's state: filtered wind, heading, engaged flag.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weathervane {
    params: WeathervaneParams,
    /// Filtered air-data wind, NED (m/s); NaN before the first sample.
    wind: Vector3<f64>,
    heading: f64,
    engaged: bool,
}

/// The air-data wind `v_NED − DCM_EB V̄ (cα cβ, sβ, sα cβ)` of a measurement, NED (m/s).
pub fn air_data_wind(m: &Measurement) -> Vector3<f64> {
    let q = &m.quat;
    let body_to_earth = UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]));
    let (sa, ca) = m.alpha.sin_cos();
    let (sb, cb) = m.beta.sin_cos();
    let v_air = m.airspeed * Vector3::new(ca * cb, sb, sa * cb);
    m.vel_ned - body_to_earth * v_air
}

/// Wrap an angle to (−π, π].
pub fn wrap_pi(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let x = a.rem_euclid(t);
    if x > std::f64::consts::PI {
        x - t
    } else {
        x
    }
}

/// The heading nearest `heading` that puts the belly (ψ = `bearing`) or the back
/// (ψ = `bearing` + π) towards `bearing`: `heading` plus the difference wrapped to ±π/2.
pub fn nearer_face(heading: f64, bearing: f64) -> f64 {
    let mut d = wrap_pi(bearing - heading);
    if d > std::f64::consts::FRAC_PI_2 {
        d -= std::f64::consts::PI;
    } else if d <= -std::f64::consts::FRAC_PI_2 {
        d += std::f64::consts::PI;
    }
    heading + d
}

impl Weathervane {
    /// A weathervane at the mission's heading; `Err` names an invalid parameter.
    pub fn new(params: WeathervaneParams) -> Result<Self, String> {
        params.validate()?;
        Ok(Self {
            params,
            wind: Vector3::new(f64::NAN, f64::NAN, f64::NAN),
            heading: 0.0,
            engaged: false,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &WeathervaneParams {
        &self.params
    }

    /// The filtered wind estimate, NED (m/s) (NaN before the first sample).
    pub fn wind(&self) -> Vector3<f64> {
        self.wind
    }

    /// Whether the wind estimate has engaged the weathervane (it may still be held at the
    /// mission's heading by the phase: see [`Self::active`]).
    pub fn engaged(&self) -> bool {
        self.engaged
    }

    /// Whether the mission phase at `t` lets the heading follow the wind (the first vertical
    /// phase until the return window, the last one from `settle_time`).
    pub fn free(&self, mission: &MissionParams, t: f64) -> bool {
        let p = &self.params;
        let (phase, tau) = mission.phase_at(t);
        p.enabled
            && match phase {
                Phase::Vertical1 => mission.t_vertical_1 - tau > p.return_window(),
                Phase::Vertical2 => tau >= p.settle_time,
                _ => false,
            }
    }

    /// Whether the heading follows the wind now: engaged and [`Self::free`].
    pub fn active(&self, mission: &MissionParams, t: f64) -> bool {
        self.engaged && self.free(mission, t)
    }

    /// The target heading for the filtered wind, phase and the present heading (rad).
    fn target(&mut self, mission: &MissionParams, t: f64) -> f64 {
        if !self.free(mission, t) {
            return 0.0;
        }
        let p = &self.params;
        let w = Vector3::new(self.wind.x, self.wind.y, 0.0);
        let speed = w.norm();
        if !speed.is_finite() {
            return self.heading;
        }
        if speed >= p.engage_speed {
            self.engaged = true;
        } else if speed < p.release_speed {
            self.engaged = false;
        }
        if !self.engaged {
            return self.heading;
        }
        // Bearing the wind comes from: belly into the wind at ψ_w = b, back at b + π.
        nearer_face(self.heading, (-w.y).atan2(-w.x))
    }

    /// Update with the measurement of the sample at mission time `t` (sample time `ts` (s))
    /// and return the heading reference. Disabled: always zero. Non-finite values are never
    /// committed.
    pub fn update(&mut self, mission: &MissionParams, t: f64, m: &Measurement) -> HeadingRef {
        self.update_towards(mission, t, m, None)
    }

    /// The heading of the present sample (rad).
    pub fn heading(&self) -> f64 {
        self.heading
    }

    /// [`Self::update`] with the target heading (rad) and the largest rate (rad/s) given by
    /// the caller, `target = Some((heading, max_rate))`, instead of the wind's (a controller's
    /// own mission logic in wind); `None`: the wind's, as [`Self::update`]. The wind estimate
    /// and the approach's time constant are the same.
    pub fn update_towards(
        &mut self,
        mission: &MissionParams,
        t: f64,
        m: &Measurement,
        target: Option<(f64, f64)>,
    ) -> HeadingRef {
        if !self.params.enabled {
            return HeadingRef::default();
        }
        let raw = air_data_wind(m);
        if raw.iter().all(|v| v.is_finite()) {
            self.wind = if self.wind.iter().all(|v| v.is_finite()) {
                let k = 1.0 - (-mission.sample_time / self.params.filter_time).exp();
                self.wind + k * (raw - self.wind)
            } else {
                raw
            };
        }
        let (target, max_rate) = match target {
            Some((x, r)) if x.is_finite() && r > 0.0 => (x, r),
            _ => (self.target(mission, t), self.params.max_rate),
        };
        let rate = ((target - self.heading) / self.params.time_constant).clamp(-max_rate, max_rate);
        let next = self.heading + rate * mission.sample_time;
        if next.is_finite() {
            self.heading = next;
        }
        HeadingRef {
            heading: self.heading,
            rate: if next.is_finite() { rate } else { 0.0 },
        }
    }

    /// Write the state ([`WEATHERVANE_STATE_LEN`] values).
    pub fn save(&self, out: &mut impl FnMut(f64)) {
        for v in self.wind.iter() {
            out(*v);
        }
        out(self.heading);
        out(if self.engaged { 1.0 } else { 0.0 });
    }

    /// Restore what [`Self::save`] wrote; `None` from `next` = truncated.
    pub fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Result<(), String> {
        let mut v = [0.0; WEATHERVANE_STATE_LEN];
        for slot in v.iter_mut() {
            *slot = next().ok_or("truncated weathervane state")?;
        }
        if !v[3].is_finite() {
            return Err(format!("weathervane heading {} is not finite", v[3]));
        }
        self.wind = Vector3::new(v[0], v[1], v[2]);
        self.heading = v[3];
        self.engaged = v[4] != 0.0;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Nose up, belly towards bearing `psi`, hovering still in the horizontal wind `w` (NED):
    /// the measurement's air data are those of the air velocity −w.
    fn hovering(psi: f64, w: Vector3<f64>) -> Measurement {
        // Body → earth: pitch up 90° about the body y axis, then heading ψ about down.
        let r = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), psi)
            * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2);
        Measurement {
            thrust: 90.0,
            induced_velocity: 10.0,
            ..Measurement::still_in_air(&r, &(r.inverse() * (-w)))
        }
    }

    fn hover_mission() -> MissionParams {
        MissionParams {
            t_vertical_1: 60.0,
            ..Default::default()
        }
    }

    #[test]
    fn air_data_wind_recovers_the_wind() {
        let w = Vector3::new(-3.0, 4.0, 0.5);
        for psi in [0.0, 1.0, -2.5] {
            let e = air_data_wind(&hovering(psi, w)) - w;
            assert!(e.norm() < 1e-12, "{psi}: {e}");
        }
    }

    /// Steady wind from the east along the span (belly north): the belly or the back turns
    /// east/west (±90°), at no more than the rate limit, and stays there.
    #[test]
    fn turns_the_face_into_a_crosswind_at_the_limited_rate() {
        let mission = hover_mission();
        let mut wv = Weathervane::new(WeathervaneParams::tuned()).unwrap();
        let w = Vector3::new(0.0, -6.0, 0.0); // from the east
        let ts = mission.sample_time;
        let mut psi = 0.0;
        let mut last = 0.0;
        for k in 0..1500 {
            let h = wv.update(&mission, k as f64 * ts, &hovering(psi, w));
            assert!((h.heading - last).abs() <= wv.params().max_rate * ts * (1.0 + 1e-12));
            last = h.heading;
            psi = h.heading;
        }
        assert!((psi.abs() - std::f64::consts::FRAC_PI_2).abs() < 1e-3, "{psi}");
    }

    /// A wind into the belly or the back needs no turn; a wind 30° off the back turns 30°.
    #[test]
    fn takes_the_nearer_face() {
        let mission = hover_mission();
        for (from_deg, expected_deg) in [(0.0, 0.0), (180.0, 0.0), (150.0, -30.0), (200.0, 20.0), (-20.0, -20.0)] {
            let b = f64::to_radians(from_deg);
            let w = -5.0 * Vector3::new(b.cos(), b.sin(), 0.0);
            let mut wv = Weathervane::new(WeathervaneParams::tuned()).unwrap();
            let mut psi = 0.0;
            for k in 0..1500 {
                psi = wv.update(&mission, k as f64 * 0.02, &hovering(psi, w)).heading;
            }
            assert!(
                (psi - f64::to_radians(expected_deg)).abs() < 1e-3,
                "{from_deg}: {}",
                psi.to_degrees()
            );
        }
    }

    #[test]
    fn idle_in_still_air_and_below_the_engage_speed() {
        let mission = hover_mission();
        for w in [Vector3::zeros(), Vector3::new(0.0, 2.9, 0.0)] {
            let mut wv = Weathervane::new(WeathervaneParams::tuned()).unwrap();
            for k in 0..500 {
                let h = wv.update(&mission, k as f64 * 0.02, &hovering(0.0, w));
                assert_eq!((h.heading, h.rate), (0.0, 0.0));
            }
        }
    }

    /// Back at the mission's heading before the first transition, zero through the
    /// transitions and level flight.
    #[test]
    fn returns_before_the_transition() {
        let mission = MissionParams {
            t_vertical_1: 20.0,
            ..Default::default()
        };
        let mut wv = Weathervane::new(WeathervaneParams::tuned()).unwrap();
        let w = Vector3::new(0.0, -6.0, 0.0);
        let mut psi = 0.0;
        let mut max: f64 = 0.0;
        let ts = mission.sample_time;
        let s = mission.phase_starts();
        for k in 0..(s[4] / ts) as usize {
            let t = k as f64 * ts;
            psi = wv.update(&mission, t, &hovering(psi, w)).heading;
            max = max.max(psi.abs());
            if t >= s[1] - wv.params().return_margin {
                assert!(psi.abs() < 0.05, "t = {t}: {}", psi.to_degrees());
            }
        }
        assert!(max > 1.5, "turned {max}");
    }

    #[test]
    fn disabled_and_state_round_trip() {
        let mission = hover_mission();
        let mut off = Weathervane::new(WeathervaneParams::disabled()).unwrap();
        let h = off.update(&mission, 0.0, &hovering(0.0, Vector3::new(0.0, 8.0, 0.0)));
        assert_eq!(h, HeadingRef::default());
        let mut a = Weathervane::new(WeathervaneParams::tuned()).unwrap();
        for k in 0..200 {
            a.update(&mission, k as f64 * 0.02, &hovering(0.0, Vector3::new(0.0, 8.0, 0.0)));
        }
        let mut saved = Vec::new();
        a.save(&mut |v| saved.push(v));
        assert_eq!(saved.len(), WEATHERVANE_STATE_LEN);
        let mut b = Weathervane::new(WeathervaneParams::tuned()).unwrap();
        let mut it = saved.iter().copied();
        b.restore(&mut || it.next()).unwrap();
        assert_eq!(a, b);
        let mut short = saved[..3].iter().copied();
        assert!(b.restore(&mut || short.next()).is_err());
        assert!(Weathervane::new(WeathervaneParams {
            max_rate: 0.0,
            ..WeathervaneParams::tuned()
        })
        .is_err());
    }
}
