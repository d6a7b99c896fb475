//! Multicopter position and velocity control (PX4
//! `src/modules/mc_pos_control/PositionControl/PositionControl.cpp`:
//! `_positionControl`, `_velocityControl`, `_accelerationControl`): a P position loop with
//! velocity feed-forward, a PID velocity loop on acceleration with acceleration
//! feed-forward, and the thrust vector of the acceleration for a hover thrust, tilt-limited,
//! with the anti-windup of the velocity integrator.
//!
//! Earth axes NED; thrust normalised by the largest thrust (PX4: negative z is up).

use nalgebra::Vector3;

/// Gains and limits (the `MPC_*` parameters).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PositionGains {
    pub pos_p: Vector3<f64>,
    pub vel_p: Vector3<f64>,
    pub vel_i: Vector3<f64>,
    pub vel_d: Vector3<f64>,
    pub vel_max_xy: f64,
    pub vel_max_up: f64,
    pub vel_max_down: f64,
    pub tilt_max: f64,
    pub thr_hover: f64,
    pub thr_min: f64,
    pub thr_max: f64,
    pub gravity: f64,
}

/// Setpoints of one sample; a NaN component is not controlled (PX4's convention; the
/// transitions leave the horizontal axes free).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PositionSetpoint {
    pub pos: Vector3<f64>,
    pub vel: Vector3<f64>,
    pub acc: Vector3<f64>,
}

/// The velocity integrator (state of the loop).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PositionControl {
    pub vel_int: Vector3<f64>,
}

/// `v` with NaN replaced by zero.
fn or_zero(v: f64) -> f64 {
    if v.is_nan() {
        0.0
    } else {
        v
    }
}

/// `body_z` turned towards `world_z` so that its tilt from it is at most `max`
/// (`ControlMath::limitTilt`).
fn limit_tilt(body_z: Vector3<f64>, world_z: &Vector3<f64>, max: f64) -> Vector3<f64> {
    let dot = body_z.dot(world_z).clamp(-1.0, 1.0);
    let angle = dot.acos();
    if angle <= max {
        return body_z;
    }
    let rejection = body_z - dot * world_z;
    if rejection.norm_squared() < 1e-12 {
        return *world_z;
    }
    let r = rejection.normalize();
    max.cos() * world_z + max.sin() * r
}

impl PositionControl {
    /// The thrust vector (NED, fraction of T_max; its length the collective thrust) of
    /// position `pos`, velocity `vel` and acceleration `vel_dot` (earth axes) for setpoint
    /// `sp`, integrating over `dt`.
    pub fn update(
        &mut self,
        g: &PositionGains,
        sp: &PositionSetpoint,
        pos: &Vector3<f64>,
        vel: &Vector3<f64>,
        vel_dot: &Vector3<f64>,
        dt: f64,
    ) -> Vector3<f64> {
        // Position loop (_positionControl): velocity setpoint = P e_p + feed-forward, limited.
        let mut vel_sp = Vector3::zeros();
        for i in 0..3 {
            let e = sp.pos[i] - pos[i];
            vel_sp[i] = if e.is_nan() { 0.0 } else { g.pos_p[i] * e } + or_zero(sp.vel[i]);
        }
        let xy = vel_sp.xy().norm();
        if xy > g.vel_max_xy {
            let k = g.vel_max_xy / xy;
            vel_sp.x *= k;
            vel_sp.y *= k;
        }
        vel_sp.z = vel_sp.z.clamp(-g.vel_max_up, g.vel_max_down);
        // Velocity loop (_velocityControl): PID on acceleration with feed-forward; an
        // uncontrolled axis (NaN position and velocity) contributes only its feed-forward.
        let mut vel_err = vel_sp - vel;
        for i in 0..3 {
            if sp.pos[i].is_nan() && sp.vel[i].is_nan() {
                vel_err[i] = 0.0;
            }
        }
        let d = Vector3::new(g.vel_d.x * vel_dot.x, g.vel_d.y * vel_dot.y, g.vel_d.z * vel_dot.z);
        let free = |i: usize| sp.pos[i].is_nan() && sp.vel[i].is_nan();
        let mut acc_sp = Vector3::zeros();
        for i in 0..3 {
            let fb = if free(i) {
                0.0
            } else {
                g.vel_p[i] * vel_err[i] + self.vel_int[i] - d[i]
            };
            acc_sp[i] = fb + or_zero(sp.acc[i]);
        }
        let mut thr = self.acceleration_control(g, &acc_sp);
        // The vertical thrust saturates at MPC_THR_MAX.
        thr.z = thr.z.max(-g.thr_max);
        // Anti-windup, vertical: stop integrating when the collective is at a limit in the
        // direction of the error.
        let thr_z = thr.z;
        if (thr_z >= -g.thr_min && vel_err.z >= 0.0) || (thr_z <= -g.thr_max && vel_err.z <= 0.0) {
            vel_err.z = 0.0;
        }
        // Horizontal: the horizontal thrust left under the vertical one, and the tracking
        // anti-windup on the acceleration not produced (gain 2 / MPC_XY_VEL_P_ACC).
        let thr_xy_max = (g.thr_max * g.thr_max - thr_z * thr_z).max(0.0).sqrt();
        let mut thr_out = thr;
        let thr_xy = thr.xy().norm();
        if thr_xy > thr_xy_max && thr_xy > 0.0 {
            let k = thr_xy_max / thr_xy;
            thr_out.x *= k;
            thr_out.y *= k;
        }
        let acc_xy_produced = thr_out.xy() * (g.gravity / g.thr_hover);
        let acc_xy_sp = acc_sp.xy();
        if acc_xy_sp.norm_squared() > acc_xy_produced.norm_squared() && g.vel_p.x > 0.0 {
            let arw = 2.0 / g.vel_p.x;
            let corr = arw * (acc_xy_sp - acc_xy_produced);
            vel_err.x -= corr.x;
            vel_err.y -= corr.y;
        }
        for i in 0..3 {
            if !free(i) {
                let next = self.vel_int[i] + vel_err[i] * g.vel_i[i] * dt;
                if next.is_finite() {
                    // PX4 bounds the vertical integrator by gravity.
                    self.vel_int[i] = if i == 2 {
                        next.clamp(-g.gravity, g.gravity)
                    } else {
                        next
                    };
                }
            }
        }
        thr_out
    }

    /// `_accelerationControl`: body z against the acceleration with gravity, tilt-limited;
    /// the collective thrust for the vertical acceleration with the hover thrust, divided by
    /// the tilt's cosine, at least MPC_THR_MIN.
    fn acceleration_control(&self, g: &PositionGains, acc_sp: &Vector3<f64>) -> Vector3<f64> {
        let body_z = Vector3::new(-acc_sp.x, -acc_sp.y, g.gravity).normalize();
        let body_z = limit_tilt(body_z, &Vector3::z(), g.tilt_max);
        let mut collective = acc_sp.z * (g.thr_hover / g.gravity) - g.thr_hover;
        collective /= body_z.z.max(1e-3);
        collective = collective.min(-g.thr_min);
        body_z * collective
    }

    pub fn reset(&mut self) {
        self.vel_int = Vector3::zeros();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gains() -> PositionGains {
        PositionGains {
            pos_p: Vector3::new(0.95, 0.95, 1.0),
            vel_p: Vector3::new(1.8, 1.8, 4.0),
            vel_i: Vector3::new(0.4, 0.4, 2.0),
            vel_d: Vector3::new(0.2, 0.2, 0.0),
            vel_max_xy: 12.0,
            vel_max_up: 3.0,
            vel_max_down: 1.5,
            tilt_max: 45f64.to_radians(),
            thr_hover: 0.5,
            thr_min: 0.12,
            thr_max: 1.0,
            gravity: 9.81,
        }
    }

    /// One update of `pc` towards `sp` from rest at the origin.
    fn at_rest(pc: &mut PositionControl, sp: &PositionSetpoint) -> Vector3<f64> {
        let zero = Vector3::zeros();
        pc.update(&gains(), sp, &zero, &zero, &zero, 0.02)
    }

    #[test]
    fn hover_at_the_setpoint_asks_hover_thrust_upright() {
        let mut pc = PositionControl::default();
        let sp = PositionSetpoint {
            pos: Vector3::zeros(),
            vel: Vector3::zeros(),
            acc: Vector3::zeros(),
        };
        let t = at_rest(&mut pc, &sp);
        assert!((t - Vector3::new(0.0, 0.0, -0.5)).norm() < 1e-12, "{t}");
    }

    #[test]
    fn tilt_is_limited_and_the_integrator_does_not_wind_up() {
        let mut pc = PositionControl::default();
        let sp = PositionSetpoint {
            pos: Vector3::new(100.0, 0.0, 0.0),
            vel: Vector3::zeros(),
            acc: Vector3::zeros(),
        };
        let mut t = Vector3::zeros();
        for _ in 0..500 {
            t = at_rest(&mut pc, &sp);
        }
        let tilt = (-t.z / t.norm()).acos();
        assert!(tilt <= 45f64.to_radians() + 1e-9, "{}", tilt.to_degrees());
        // Without the tracking anti-windup the integrator would reach 0.4·12·10 = 48 m/s².
        assert!(pc.vel_int.x < 12.0, "{}", pc.vel_int.x);
    }

    #[test]
    fn free_axes_are_not_controlled() {
        let mut pc = PositionControl::default();
        let sp = PositionSetpoint {
            pos: Vector3::new(f64::NAN, f64::NAN, 0.0),
            vel: Vector3::new(f64::NAN, f64::NAN, 0.0),
            acc: Vector3::zeros(),
        };
        let t = pc.update(
            &gains(),
            &sp,
            &Vector3::new(5.0, 5.0, 0.0),
            &Vector3::new(3.0, 0.0, 0.0),
            &Vector3::zeros(),
            0.02,
        );
        assert!(t.x.abs() < 1e-12 && t.y.abs() < 1e-12, "{t}");
    }
}
