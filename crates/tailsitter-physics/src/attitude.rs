//! Attitude: quaternion (thesis convention A.2.8, scalar part last), DCM and Euler angles.
//!
//! `DCM^BE` maps earth (NED) components to body components. For a frame rotation of
//! angle a about axis i, `T^i_a` is the matrix of (A.2.1–A.2.3); the 3-2-1 sequence is
//! `DCM^BE = T^1_φ T^2_θ T^3_ψ` (A.2.5) and the 2-3-1 sequence `DCM^BE = T^1_φ T^3_θ T^2_ψ`
//! (A.2.6). The printed expanded (A.2.5) has wrong entries (rows 2 and 3) and (A.2.9) a wrong
//! element (1,2) — here every matrix is derived from the products and tested against them.

use nalgebra::{Matrix3, Vector3, Vector4};

/// Frame rotation `T^1_a` about x (A.2.1).
pub fn rot_x(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, s, 0.0, -s, c)
}

/// Frame rotation `T^2_a` about y (A.2.2).
pub fn rot_y(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, 0.0, -s, 0.0, 1.0, 0.0, s, 0.0, c)
}

/// Frame rotation `T^3_a` about z (A.2.3).
pub fn rot_z(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0)
}

/// `DCM^BE` (earth → body components) of the quaternion `q = [q1 q2 q3 q4]` (A.2.8,
/// q4 scalar), corrected (A.2.9): element (1,2) is `2(q1 q2 + q4 q3)`, not `2(q4 q3 + q1 q3)`.
///
/// The matrix is divided by |q|², so a quaternion that is not exactly unit still gives a
/// proper rotation (the norm direction then has no effect on the dynamics).
/// Element (0,2) is −sin θ.
#[inline]
pub fn dcm_earth_to_body(q: &Vector4<f64>) -> Matrix3<f64> {
    let (q1, q2, q3, q4) = (q[0], q[1], q[2], q[3]);
    let n = q1 * q1 + q2 * q2 + q3 * q3 + q4 * q4;
    let k = if n > 0.0 { 1.0 / n } else { 1.0 };
    let (q11, q22, q33, q44) = (q1 * q1, q2 * q2, q3 * q3, q4 * q4);
    Matrix3::new(
        (q44 + q11 - q22 - q33) * k,
        2.0 * (q1 * q2 + q4 * q3) * k,
        2.0 * (q1 * q3 - q4 * q2) * k,
        2.0 * (q1 * q2 - q4 * q3) * k,
        (q44 - q11 + q22 - q33) * k,
        2.0 * (q2 * q3 + q4 * q1) * k,
        2.0 * (q1 * q3 + q4 * q2) * k,
        2.0 * (q2 * q3 - q4 * q1) * k,
        (q44 - q11 - q22 + q33) * k,
    )
}

/// The unit quaternion (q4 ≥ 0) of a `DCM^BE` (Shepperd's method: robust at every attitude).
pub fn quat_from_dcm(c: &Matrix3<f64>) -> Vector4<f64> {
    let tr = c[(0, 0)] + c[(1, 1)] + c[(2, 2)];
    let q = if tr >= c[(0, 0)] && tr >= c[(1, 1)] && tr >= c[(2, 2)] {
        let q4 = 0.5 * (1.0 + tr).max(0.0).sqrt();
        let k = 0.25 / q4;
        Vector4::new(
            (c[(1, 2)] - c[(2, 1)]) * k,
            (c[(2, 0)] - c[(0, 2)]) * k,
            (c[(0, 1)] - c[(1, 0)]) * k,
            q4,
        )
    } else if c[(0, 0)] >= c[(1, 1)] && c[(0, 0)] >= c[(2, 2)] {
        let q1 = 0.5 * (1.0 + c[(0, 0)] - c[(1, 1)] - c[(2, 2)]).max(0.0).sqrt();
        let k = 0.25 / q1;
        Vector4::new(
            q1,
            (c[(0, 1)] + c[(1, 0)]) * k,
            (c[(0, 2)] + c[(2, 0)]) * k,
            (c[(1, 2)] - c[(2, 1)]) * k,
        )
    } else if c[(1, 1)] >= c[(2, 2)] {
        let q2 = 0.5 * (1.0 - c[(0, 0)] + c[(1, 1)] - c[(2, 2)]).max(0.0).sqrt();
        let k = 0.25 / q2;
        Vector4::new(
            (c[(0, 1)] + c[(1, 0)]) * k,
            q2,
            (c[(1, 2)] + c[(2, 1)]) * k,
            (c[(2, 0)] - c[(0, 2)]) * k,
        )
    } else {
        let q3 = 0.5 * (1.0 - c[(0, 0)] - c[(1, 1)] + c[(2, 2)]).max(0.0).sqrt();
        let k = 0.25 / q3;
        Vector4::new(
            (c[(0, 2)] + c[(2, 0)]) * k,
            (c[(1, 2)] + c[(2, 1)]) * k,
            q3,
            (c[(0, 1)] - c[(1, 0)]) * k,
        )
    };
    let q = q / q.norm();
    if q[3] < 0.0 {
        -q
    } else {
        q
    }
}

/// Quaternion of the 3-2-1 Euler angles (yaw ψ, then pitch θ, then roll φ), (A.2.5), q4 ≥ 0
/// for |angles| ≤ π/2. Valid at θ = ±90° (only the inverse is singular there).
pub fn quat_from_euler_321(phi: f64, theta: f64, psi: f64) -> Vector4<f64> {
    let (sf, cf) = (0.5 * phi).sin_cos();
    let (st, ct) = (0.5 * theta).sin_cos();
    let (sp, cp) = (0.5 * psi).sin_cos();
    Vector4::new(
        sf * ct * cp - cf * st * sp,
        cf * st * cp + sf * ct * sp,
        cf * ct * sp - sf * st * cp,
        cf * ct * cp + sf * st * sp,
    )
}

/// Pitch θ of the 3-2-1 Euler angles from DCM element C₁₃ = −sin θ (A.2.5): well
/// defined at θ = ±90° (vertical flight), where φ and ψ are not.
pub fn pitch_321(q: &Vector4<f64>) -> f64 {
    (-dcm_earth_to_body(q)[(0, 2)]).clamp(-1.0, 1.0).asin()
}

/// 3-2-1 Euler angles `[φ, θ, ψ]` of a quaternion: φ = atan2(C₂₃, C₃₃), θ = −asin C₁₃,
/// ψ = atan2(C₁₂, C₁₁) (1-based elements of `DCM^BE`). Singular (but finite) at θ = ±90°.
pub fn euler_321_from_quat(q: &Vector4<f64>) -> Vector3<f64> {
    let c = dcm_earth_to_body(q);
    Vector3::new(
        c[(1, 2)].atan2(c[(2, 2)]),
        (-c[(0, 2)]).clamp(-1.0, 1.0).asin(),
        c[(0, 1)].atan2(c[(0, 0)]),
    )
}

/// `DCM^BE` of the 2-3-1 Euler angles, `T^1_φ T^3_θ T^2_ψ` (A.2.6): ψ about y first, then θ
/// about z, then φ about x. Non-singular in vertical flight (θ₃₂₁ = 90° ⇔ ψ₂₃₁ = 90°, θ₂₃₁ = 0).
pub fn dcm_from_euler_231(phi: f64, theta: f64, psi: f64) -> Matrix3<f64> {
    rot_x(phi) * rot_z(theta) * rot_y(psi)
}

/// Quaternion of the 2-3-1 Euler angles (A.2.6), see [`dcm_from_euler_231`].
pub fn quat_from_euler_231(phi: f64, theta: f64, psi: f64) -> Vector4<f64> {
    quat_from_dcm(&dcm_from_euler_231(phi, theta, psi))
}

/// 2-3-1 Euler angles `[φ, θ, ψ]` (A.2.6) of a quaternion, used by the LQR controller in
/// vertical flight: from the first row `[cθ cψ, sθ, −cθ sψ]` and second column
/// `[sθ, cφ cθ, −sφ cθ]` of `DCM^BE`: θ = asin C₁₂, ψ = atan2(−C₁₃, C₁₁), φ = atan2(−C₃₂, C₂₂).
/// Singular only at θ₂₃₁ = ±90° (a knife-edge attitude).
pub fn euler_231_from_quat(q: &Vector4<f64>) -> Vector3<f64> {
    let c = dcm_earth_to_body(q);
    Vector3::new(
        (-c[(2, 1)]).atan2(c[(1, 1)]),
        c[(0, 1)].clamp(-1.0, 1.0).asin(),
        (-c[(0, 2)]).atan2(c[(0, 0)]),
    )
}

/// Alias of [`euler_231_from_quat`].
pub fn euler_231(q: &Vector4<f64>) -> Vector3<f64> {
    euler_231_from_quat(q)
}

/// Quaternion kinematics (2.2.3): `q̇ = ½ Ω(ω) q` with body rates ω = (p, q, r).
#[inline]
pub fn quat_derivative(q: &Vector4<f64>, omega: &Vector3<f64>) -> Vector4<f64> {
    let (q1, q2, q3, q4) = (q[0], q[1], q[2], q[3]);
    let (p, qq, r) = (omega[0], omega[1], omega[2]);
    0.5 * Vector4::new(
        q4 * p - q3 * qq + q2 * r,
        q3 * p + q4 * qq - q1 * r,
        -q2 * p + q1 * qq + q4 * r,
        -q1 * p - q2 * qq - q3 * r,
    )
}
