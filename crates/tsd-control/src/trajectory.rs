//! Kinematic reference trajectory of the TSD controller (thesis §4.3.3).
//!
//! The mission (vertical climb → quarter loop → level → quarter loop → vertical) is
//! described purely kinematically: position, velocity, specific acceleration and the
//! flight-path angle, all in the NED earth frame, heading north, in the north–down plane.
//!
//! Corrections to the printed equations (derived from first principles):
//! * (4.3.33–4.3.40) start the transition with θ = 0 while the velocity of (4.3.37) is then
//!   horizontal; here the *turned angle* φ = s/r runs from 0 to π/2 and the flight-path
//!   angle is γ = π/2 − φ in the first (push-over) transition and γ = φ in the second
//!   (pull-up) one.
//! * The radius is fixed so that the loop ends exactly level (or vertical): the arc
//!   length flown in the transition with linear airspeed (4.3.31–4.3.32) is
//!   s(T) = (V_V + V_L)·T/2, and a quarter loop needs s(T) = r·π/2, hence
//!   r = (V_V + V_L)·T/π (≈ 35.7 m for T = 4 s, 44.6 m for T = 5 s).
//! * (4.3.35–4.3.36): the specific acceleration is Σ = a − g with
//!   a = A_V·t̂ + (V̄²/r)·n̂ (tangential plus centripetal, n̂ towards the centre of the loop)
//!   and g = (0, 0, g) in NED; the printed component signs depend on the (undefined)
//!   figure 4.11 and are replaced by this vector form.
//! * (4.3.39–4.3.40): positions are the integrals of the velocities, continuous at every
//!   phase boundary; a vertical climb at V_V precedes and follows the loops.

use core::f64::consts::FRAC_PI_2;
use flight_mission::{MissionParams, Phase};
use guidance::Profile;
use nalgebra::Vector3;

/// The reference at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reference {
    /// Mission phase.
    pub phase: Phase,
    /// Position, NED (m) (without the user offset).
    pub pos: Vector3<f64>,
    /// Inertial velocity, NED (m/s).
    pub vel: Vector3<f64>,
    /// Specific acceleration Σ^RE = a − g, NED (m/s²) (4.3.35–4.3.36).
    pub specific_accel: Vector3<f64>,
    /// Reference airspeed V̄ (m/s) (4.3.31–4.3.32).
    pub airspeed: f64,
    /// Flight-path angle γ (rad) (π/2 climbing vertically, 0 level).
    pub gamma: f64,
}

impl Reference {
    /// Unit tangent t̂ = (cos γ, 0, −sin γ), NED.
    pub fn tangent(&self) -> Vector3<f64> {
        Vector3::new(self.gamma.cos(), 0.0, -self.gamma.sin())
    }

    /// The prescribed normal vector k^Wc of §4.3.2.1: the wind z axis of wings-level
    /// flight along the reference path, k = (sin γ, 0, cos γ) (belly north in the
    /// vertical climb, down in level flight).
    pub fn prescribed_normal(&self) -> Vector3<f64> {
        Vector3::new(self.gamma.sin(), 0.0, self.gamma.cos())
    }
}

/// The kinematic trajectory of a mission.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    /// The α- and thrust-limited point-mass path ([`guidance::profile`])
    /// replacing the quarter loops, if set.
    profile: Option<Profile>,
    mission: MissionParams,
    gravity: f64,
    /// Radii of the two quarter loops (m).
    r1: f64,
    r2: f64,
    /// Start positions of phases 1..4 (NED).
    starts: [Vector3<f64>; 5],
}

impl Trajectory {
    /// The trajectory of `mission` starting at the origin at t = 0; `gravity` in m/s².
    pub fn new(mission: MissionParams, gravity: f64) -> Self {
        let (vv, vl) = (mission.v_vertical, mission.v_level);
        let r1 = Self::radius(vv, vl, mission.t_transition_1);
        let r2 = Self::radius(vv, vl, mission.t_transition_2);
        let p0 = Vector3::zeros();
        let p1 = p0 + Vector3::new(0.0, 0.0, -vv * mission.t_vertical_1);
        let p2 = p1 + Vector3::new(r1, 0.0, -r1);
        let p3 = p2 + Vector3::new(vl * mission.t_level, 0.0, 0.0);
        let p4 = p3 + Vector3::new(r2, 0.0, -r2);
        Self {
            profile: None,
            mission,
            gravity,
            r1,
            r2,
            starts: [p0, p1, p2, p3, p4],
        }
    }

    /// The trajectory of `mission` along the limited flight-path `profile` (built for the
    /// same mission): position, velocity and acceleration of the point mass, heading north.
    pub fn limited(mission: MissionParams, gravity: f64, profile: Profile) -> Self {
        Self {
            profile: Some(profile),
            ..Self::new(mission, gravity)
        }
    }

    /// Radius of a quarter loop flown in `duration` with airspeed changing linearly between
    /// `v_vertical` and `v_level`: r = (V_V + V_L)·T/π, so that s(T)/r = π/2 exactly.
    pub fn radius(v_vertical: f64, v_level: f64, duration: f64) -> f64 {
        (v_vertical + v_level) * duration / core::f64::consts::PI
    }

    /// Radii (r1, r2) of the two quarter loops (m).
    pub fn radii(&self) -> (f64, f64) {
        (self.r1, self.r2)
    }

    /// The mission this trajectory flies.
    pub fn mission(&self) -> &MissionParams {
        &self.mission
    }

    /// The feed-forward Σ^RE of (4.3.24) previewed `lead` seconds ahead, **resolved in the
    /// path axes** (tangent t̂, lateral, normal k̂ = the prescribed normal) of the point it
    /// is read at and re-expressed in the path axes at `t`: the preview brings forward the
    /// *magnitudes* of the tangential and normal specific accelerations (thrust and lift the
    /// inner loops need time to build), not the path's turn over the lead. Read as a vector at
    /// t + lead, the large tangential part (≈ 13 m/s² of thrust in the fast push-over) turned
    /// with the path by γ̇·lead (7° at γ̇ = 1.2 rad/s, 0.1 s) became a normal command at t:
    /// the attitude led the path, gravity amplified the lead, and the TSD sank 0.9 m in the
    /// fast front transition (README, "Front transition: preview in path axes"). Where γ is
    /// constant (vertical and level flight) this is the previewed vector itself.
    pub fn previewed_specific_accel(&self, t: f64, lead: f64) -> Vector3<f64> {
        let now = self.at(t);
        let ahead = self.at(t + lead);
        let s = ahead.specific_accel;
        now.tangent() * s.dot(&ahead.tangent())
            + now.prescribed_normal() * s.dot(&ahead.prescribed_normal())
            + Vector3::new(0.0, s.y, 0.0)
    }

    /// The reference at mission time `t`: the limited profile's point mass if set, else the
    /// vertical climb, the quarter loops (4.3.31–4.3.40) and level flight.
    pub fn at(&self, t: f64) -> Reference {
        if let Some(profile) = &self.profile {
            return self.on_profile(profile, t);
        }
        let m = &self.mission;
        let (phase, tau) = m.phase_at(t);
        let tau = tau.max(0.0);
        match phase {
            Phase::Vertical1 => self.climb(phase, tau, self.starts[0]),
            Phase::Vertical2 => self.climb(phase, tau, self.starts[4]),
            // Take-off and landing: flown from guidance::ground, never a mission time.
            Phase::OnGround | Phase::TakeOff | Phase::Approach | Phase::Descent | Phase::Flare | Phase::Landed => {
                self.climb(phase, tau, self.starts[4])
            }
            Phase::Level => Reference {
                phase,
                pos: self.starts[2] + Vector3::new(m.v_level * tau, 0.0, 0.0),
                vel: Vector3::new(m.v_level, 0.0, 0.0),
                specific_accel: -self.gravity_vector(),
                airspeed: m.v_level,
                gamma: 0.0,
            },
            Phase::TransitionToLevel => self.push_over(phase, tau),
            Phase::TransitionToVertical => self.pull_up(phase, tau),
        }
    }

    /// Gravity g = (0, 0, g), NED (m/s²).
    fn gravity_vector(&self) -> Vector3<f64> {
        Vector3::new(0.0, 0.0, self.gravity)
    }

    /// The point mass of the limited profile at `t`: t̂ = (cos γ, 0, −sin γ),
    /// dt̂/dγ = (−sin γ, 0, −cos γ), a = V̇ t̂ + V γ̇ dt̂/dγ, Σ = a − g.
    fn on_profile(&self, profile: &Profile, t: f64) -> Reference {
        let p = profile.at(t);
        let (sg, cg) = p.gamma.sin_cos();
        let tangent = Vector3::new(cg, 0.0, -sg);
        let turn = Vector3::new(-sg, 0.0, -cg);
        let a = tangent * p.v_dot + turn * (p.v * p.gamma_dot);
        Reference {
            phase: self.mission.phase_at(t).0,
            pos: Vector3::new(p.north, 0.0, -p.height),
            vel: tangent * p.v,
            specific_accel: a - Vector3::new(0.0, 0.0, self.gravity),
            airspeed: p.v,
            gamma: p.gamma,
        }
    }

    /// Vertical climb at V_V from `start`, `tau` into the phase: Σ = −g.
    fn climb(&self, phase: Phase, tau: f64, start: Vector3<f64>) -> Reference {
        let vv = self.mission.v_vertical;
        Reference {
            phase,
            pos: start + Vector3::new(0.0, 0.0, -vv * tau),
            vel: Vector3::new(0.0, 0.0, -vv),
            specific_accel: -self.gravity_vector(),
            airspeed: vv,
            gamma: FRAC_PI_2,
        }
    }

    /// First transition (4.3.31), (4.3.33): push-over on the quarter loop of radius r1 with
    /// the airspeed linear from V_V to V_L, γ = π/2 − φ.
    fn push_over(&self, phase: Phase, tau: f64) -> Reference {
        let m = &self.mission;
        let (vv, vl) = (m.v_vertical, m.v_level);
        let tt = m.t_transition_1;
        let tau = tau.min(tt);
        let av = (vl - vv) / tt;
        let v = vv + av * tau;
        let s = vv * tau + 0.5 * av * tau * tau;
        let phi = s / self.r1;
        let (sp, cp) = phi.sin_cos();
        let tangent = Vector3::new(sp, 0.0, -cp);
        let normal = Vector3::new(cp, 0.0, sp); // dt̂/dφ, towards the centre
        let a = tangent * av + normal * (v * v / self.r1);
        Reference {
            phase,
            pos: self.starts[1] + Vector3::new(self.r1 * (1.0 - cp), 0.0, -self.r1 * sp),
            vel: tangent * v,
            specific_accel: a - self.gravity_vector(),
            airspeed: v,
            gamma: FRAC_PI_2 - phi,
        }
    }

    /// Second transition (4.3.32), (4.3.34): pull-up on the quarter loop of radius r2 with
    /// the airspeed linear from V_L to V_V, γ = φ.
    fn pull_up(&self, phase: Phase, tau: f64) -> Reference {
        let m = &self.mission;
        let (vv, vl) = (m.v_vertical, m.v_level);
        let tt = m.t_transition_2;
        let tau = tau.min(tt);
        let av = (vv - vl) / tt;
        let v = vl + av * tau;
        let s = vl * tau + 0.5 * av * tau * tau;
        let phi = s / self.r2;
        let (sp, cp) = phi.sin_cos();
        let tangent = Vector3::new(cp, 0.0, -sp);
        let normal = Vector3::new(-sp, 0.0, -cp);
        let a = tangent * av + normal * (v * v / self.r2);
        Reference {
            phase,
            pos: self.starts[3] + Vector3::new(self.r2 * sp, 0.0, -self.r2 * (1.0 - cp)),
            vel: tangent * v,
            specific_accel: a - self.gravity_vector(),
            airspeed: v,
            gamma: phi,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vector3<f64>, b: Vector3<f64>, tol: f64) -> bool {
        (a - b).norm() <= tol
    }

    #[test]
    fn radius_and_pull_up_load_factor() {
        let r = Trajectory::radius(3.0, 25.0, 4.0);
        assert!((r - 35.65).abs() < 0.05, "{r}");
        // Lift at the start of the pull-up: V²/r + g ≈ 2.8 g.
        let n = (25.0 * 25.0 / r + 9.81) / 9.81;
        assert!((n - 2.79).abs() < 0.02, "{n}");
    }

    #[test]
    fn loops_end_exactly_level_and_vertical_and_are_continuous() {
        for (t1, t2) in [(5.0, 10.0), (3.0, 4.0)] {
            let m = MissionParams {
                t_transition_1: t1,
                t_transition_2: t2,
                ..Default::default()
            };
            let tr = Trajectory::new(m, 9.81);
            let s = m.phase_starts();
            let eps = 1e-9;
            for &tb in &s[1..5] {
                let before = tr.at(tb - eps);
                let after = tr.at(tb);
                assert!(close(before.pos, after.pos, 1e-6), "pos jump at {tb}");
                assert!(
                    close(before.vel, after.vel, 1e-6),
                    "vel jump at {tb}: {:?} {:?}",
                    before.vel,
                    after.vel
                );
                assert!((before.gamma - after.gamma).abs() < 1e-6);
                assert!((before.airspeed - after.airspeed).abs() < 1e-6);
            }
            let end1 = tr.at(s[2] - 1e-12);
            assert!(end1.gamma.abs() < 1e-9 && end1.vel.z.abs() < 1e-9, "{end1:?}");
            let end2 = tr.at(s[4] - 1e-12);
            assert!(
                (end2.gamma - FRAC_PI_2).abs() < 1e-9 && end2.vel.x.abs() < 1e-9,
                "{end2:?}"
            );
        }
    }

    /// The preview keeps the path-axes components of the point ahead (the thrust's and the
    /// lift's share of Σ) and turns them with the path back to `t`: in the turning push-over of
    /// the fast mission's limited profile the previewed vector read as is would differ from
    /// this by |Σ|·2 sin(Δγ/2), the path's turn Δγ over the lead; on straight segments the
    /// two are the same vector.
    #[test]
    fn preview_is_resolved_in_the_path_axes() {
        let m = MissionParams::fast_limited();
        let pm = guidance::PointMass {
            mass: 9.0,
            gravity: 9.81,
            air_density: 1.225,
            wing_area: 0.5737,
            c_l_alpha: 3.1,
            c_d0: 0.0272,
            k_induced: 1.0 / (core::f64::consts::PI * 0.8 * 4.29),
            thrust_max: 150.0,
        };
        let profile = Profile::new(&m, &pm, &guidance::ProfileLimits::of(&m)).unwrap();
        let tr = Trajectory::limited(m, 9.81, profile);
        let s = m.phase_starts();
        let lead = 0.1;
        // The vertical climb: the previewed vector itself.
        let p = tr.previewed_specific_accel(1.0, lead);
        assert!(close(p, tr.at(1.0 + lead).specific_accel, 1e-12));
        let mut turned = 0.0f64;
        let mut t = 0.0;
        while t < m.end_time() {
            let (now, ahead) = (tr.at(t), tr.at(t + lead));
            let p = tr.previewed_specific_accel(t, lead);
            let sa = ahead.specific_accel;
            assert!((p.dot(&now.tangent()) - sa.dot(&ahead.tangent())).abs() < 1e-9);
            assert!((p.dot(&now.prescribed_normal()) - sa.dot(&ahead.prescribed_normal())).abs() < 1e-9);
            assert!((p.norm() - sa.norm()).abs() < 1e-9);
            let dg = ahead.gamma - now.gamma;
            assert!(((p - sa).norm() - sa.norm() * 2.0 * (0.5 * dg).sin().abs()).abs() < 1e-9);
            if t >= s[1] && t < s[2] {
                turned = turned.max(dg.abs());
            }
            t += 0.05;
        }
        // The fast push-over turns the path by several degrees over 0.1 s.
        assert!(turned > 4f64.to_radians(), "{}", turned.to_degrees());
    }

    #[test]
    fn velocity_is_the_derivative_of_position_and_accel_of_velocity() {
        let m = MissionParams {
            t_transition_1: 3.0,
            t_transition_2: 4.0,
            ..Default::default()
        };
        let tr = Trajectory::new(m, 9.81);
        let g = Vector3::new(0.0, 0.0, 9.81);
        let h = 1e-5;
        let mut t = 0.013;
        while t < m.end_time() {
            let (a, b) = (tr.at(t - h), tr.at(t + h));
            if a.phase == b.phase {
                let r = tr.at(t);
                assert!(close((b.pos - a.pos) / (2.0 * h), r.vel, 1e-4), "t={t}");
                assert!(close((b.vel - a.vel) / (2.0 * h), r.specific_accel + g, 1e-3), "t={t}");
                assert!((r.vel.norm() - r.airspeed).abs() < 1e-9);
                assert!(close(r.tangent() * r.airspeed, r.vel, 1e-9));
                assert!(r.prescribed_normal().dot(&r.tangent()).abs() < 1e-12);
            }
            t += 0.1;
        }
    }
}
