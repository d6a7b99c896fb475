//! Multicopter attitude control in PX4's way: a quaternion error with the tilt (thrust
//! direction) prioritised over the yaw (PX4
//! `src/modules/mc_att_control/AttitudeControl/AttitudeControl.cpp`,
//! `AttitudeControl::update`; the reference model `MC_REF_FF` off, PX4's legacy
//! behaviour), and the attitude of a thrust vector and a yaw (PX4
//! `src/modules/mc_pos_control/PositionControl/ControlMath.cpp`, `bodyzToAttitude`).
//!
//! Quaternions rotate the vehicle's frame into the earth frame (NED), as PX4's.

use nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};

/// Gains and limits of the attitude loop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeGains {
    /// MC_ROLL_P, MC_PITCH_P, MC_YAW_P (1/s).
    pub p: Vector3<f64>,
    /// MC_YAW_WEIGHT ∈ [0, 1].
    pub yaw_weight: f64,
    /// Rate setpoint limits (rad/s).
    pub rate_limit: Vector3<f64>,
}

/// `q` with a non-negative scalar part (the same rotation).
fn canonical(q: &Quaternion<f64>) -> Quaternion<f64> {
    if q.w < 0.0 {
        -q
    } else {
        *q
    }
}

/// Rate setpoint (body axes of `q`, rad/s) of the attitude `q` towards `qd`: the reduced
/// attitude that turns the z axis (thrust) straight onto the desired one first, the yaw
/// about it only by `yaw_weight` of the remainder, then e = 2 Im(q⁻¹ q_d) (sign chosen for
/// the short way) times the gains, the yaw gain divided by the weight so that the yaw
/// response keeps MC_YAW_P (`setProportionalGain`), plus `yaw_rate_ff` about the earth's
/// down axis, limited per axis.
pub fn attitude_rate_setpoint(
    g: &AttitudeGains,
    q: &UnitQuaternion<f64>,
    qd: &UnitQuaternion<f64>,
    yaw_rate_ff: f64,
) -> Vector3<f64> {
    let e_z = q * Vector3::z();
    let e_z_d = qd * Vector3::z();
    let qd_red = match UnitQuaternion::rotation_between(&e_z, &e_z_d) {
        // The tilt error rotation in the earth frame, applied to the attitude.
        Some(tilt) if tilt.i.abs() < 1.0 - 1e-5 && tilt.j.abs() < 1.0 - 1e-5 => tilt * q,
        // Thrust exactly opposite: full attitude control.
        _ => *qd,
    };
    let yaw_w = g.yaw_weight.clamp(0.0, 1.0);
    let dyaw = canonical((qd_red.inverse() * qd).quaternion());
    let (w, z) = (dyaw.w.clamp(-1.0, 1.0), dyaw.k.clamp(-1.0, 1.0));
    let scaled = Quaternion::new((yaw_w * w.acos()).cos(), 0.0, 0.0, (yaw_w * z.asin()).sin());
    let qd_mix = qd_red * UnitQuaternion::new_normalize(scaled);
    let qe = canonical((q.inverse() * qd_mix).quaternion());
    let eq = 2.0 * qe.imag();
    let mut p = g.p;
    if yaw_w > 1e-4 {
        p.z /= yaw_w;
    }
    let mut rate_sp = eq.component_mul(&p);
    // Yaw-rate feed-forward about the earth's down axis, in body axes.
    rate_sp += q.inverse() * Vector3::z() * yaw_rate_ff;
    for i in 0..3 {
        rate_sp[i] = rate_sp[i].clamp(-g.rate_limit[i], g.rate_limit[i]);
    }
    rate_sp
}

/// The attitude whose z axis is `body_z` (unit, earth axes) and whose x axis points as near
/// heading `yaw` as the tilt allows (`bodyzToAttitude`: y from the yaw's right-hand
/// vector crossed, x = y × z).
pub fn body_z_to_attitude(body_z: &Vector3<f64>, yaw: f64) -> UnitQuaternion<f64> {
    let z = if body_z.norm_squared() > 1e-12 {
        body_z.normalize()
    } else {
        Vector3::z()
    };
    let y_c = Vector3::new(-yaw.sin(), yaw.cos(), 0.0);
    let mut x = y_c.cross(&z);
    if z.z < 0.0 {
        // Upside down: keep the heading of x.
        x = -x;
    }
    if x.norm_squared() < 1e-12 {
        // z horizontal along the yaw's right: any x perpendicular.
        x = Vector3::new(0.0, 0.0, 1.0).cross(&z);
    }
    let x = x.normalize();
    let y = z.cross(&x);
    let r = Matrix3::from_columns(&[x, y, z]);
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gains() -> AttitudeGains {
        AttitudeGains {
            p: Vector3::new(6.5, 6.5, 2.8),
            yaw_weight: 0.4,
            rate_limit: Vector3::repeat(10.0),
        }
    }

    #[test]
    fn tilt_is_prioritised_over_yaw() {
        let g = gains();
        let q = UnitQuaternion::identity();
        // Desired: 0.2 rad roll about the yawed x axis and 0.6 rad yaw. The tilt error is
        // corrected with the full roll-pitch gain; only the weight's share of the yaw error
        // is commanded, times MC_YAW_P / w: for small angles 2 sin(0.4·0.6/2)·2.8/0.4.
        let qd = UnitQuaternion::from_euler_angles(0.2, 0.0, 0.6);
        let w = attitude_rate_setpoint(&g, &q, &qd, 0.0);
        let tilt = w.xy().norm();
        assert!((tilt - 6.5 * 2.0 * 0.1f64.sin()).abs() < 0.02 * tilt, "{w}");
        assert!((w.z - 2.0 * (0.4f64 * 0.6 / 2.0).sin() * 2.8 / 0.4).abs() < 0.05, "{w}");
        // Pure yaw error: the same rate about z whatever the weight (gain compensation).
        let qy = UnitQuaternion::from_euler_angles(0.0, 0.0, 0.1);
        let a = attitude_rate_setpoint(&g, &q, &qy, 0.0);
        let b = attitude_rate_setpoint(&AttitudeGains { yaw_weight: 1.0, ..g }, &q, &qy, 0.0);
        assert!((a.z - b.z).abs() < 1e-3 && a.x.abs() < 1e-12, "{a} {b}");
    }

    #[test]
    fn tilt_error_is_not_diluted_by_yaw() {
        // With a large yaw error, the roll-pitch correction still points the thrust axis
        // at the desired one: the rate's x-y part equals that of the tilt-only error.
        let g = gains();
        let q = UnitQuaternion::from_euler_angles(0.0, 0.3, 0.0);
        let qd = UnitQuaternion::from_euler_angles(0.0, 0.0, 2.5);
        let w = attitude_rate_setpoint(&g, &q, &qd, 0.0);
        let tilt = attitude_rate_setpoint(&g, &q, &UnitQuaternion::identity(), 0.0);
        assert!((w.y - tilt.y).abs() < 0.35 * tilt.y.abs(), "{w} vs {tilt}");
        assert!(w.y < -1.0, "pitches back towards level: {w}");
    }

    #[test]
    fn rates_are_limited() {
        let g = AttitudeGains {
            rate_limit: Vector3::new(1.0, 2.0, 0.5),
            ..gains()
        };
        let w = attitude_rate_setpoint(
            &g,
            &UnitQuaternion::identity(),
            &UnitQuaternion::from_euler_angles(1.0, -1.0, 1.0),
            0.0,
        );
        assert!(w.x.abs() <= 1.0 && w.y.abs() <= 2.0 && w.z.abs() <= 0.5, "{w}");
    }

    #[test]
    fn body_z_attitude_keeps_the_heading() {
        let q = body_z_to_attitude(&Vector3::new(0.2, 0.0, 1.0).normalize(), 0.3);
        let z = q * Vector3::z();
        assert!((z - Vector3::new(0.2, 0.0, 1.0).normalize()).norm() < 1e-12);
        let x = q * Vector3::x();
        let heading = x.y.atan2(x.x);
        assert!((heading - 0.3).abs() < 0.05, "{heading}");
        let level = body_z_to_attitude(&Vector3::z(), -1.0);
        assert!((level.euler_angles().2 + 1.0).abs() < 1e-12);
    }
}
