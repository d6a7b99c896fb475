//! Guidance stage (Fig. 4.2, the outer position/velocity loop, §4.3.2): the
//! commanded earth-axis specific acceleration Σ = −K_P e_P − K_V e_V + Σ^RE (4.3.24) from the
//! position and velocity errors and the trajectory's feed-forward Σ^RE (4.3.35–4.3.36).

use crate::design::LoopDesign;
use crate::reference::ReferenceSignals;
use crate::trajectory::{Reference, Trajectory};
use nalgebra::Vector3;

/// The feed-forward Σ^RE of (4.3.24) as `(sigma_ff, sigma_ahead)`: the preview
/// (`feedforward_lead` = `lead` > 0; 0 in the thesis configuration) read at t + lead and
/// resolved in the path axes of t (`sigma_ff`, the guidance command) and as read at t + lead
/// (`sigma_ahead`, the normal loop's steady-state feed-forward); the ground phases' own Σ.
///
/// Read as a vector, the preview also turns the command with the path by γ̇·lead — 7° of the
/// ≈ 13 m/s² thrust acceleration in the fast push-over became a normal command the integrator
/// E_C then held: the attitude led the path, gravity amplified the lead and the TSD sank
/// 0.8 m and climbed back in the fast front transition (README, "Front transition: preview
/// in path axes").
pub(crate) fn feedforward(trajectory: &Trajectory, r: &ReferenceSignals, lead: f64) -> (Vector3<f64>, Vector3<f64>) {
    if let Some(s) = r.sigma_ground {
        (s, s)
    } else if lead > 0.0 {
        (
            trajectory.previewed_specific_accel(r.t_mission, lead),
            trajectory.at(r.t_mission + lead).specific_accel,
        )
    } else {
        (r.reference.specific_accel, r.reference.specific_accel)
    }
}

/// The guidance law (4.3.24): Σ = −K_P e_P − K_V e_V + Σ^RE, with the gains `d.guidance`
/// along the path and `d.guidance_lateral` across it (t̂ × k̂: the path's own lateral axis,
/// independent of the weathervane's heading), and the feedback bounded in norm by
/// `d.guidance_feedback_limit` (infinite in the thesis configuration): for the small errors
/// the poles were placed for it is the linear law; a large error (a gust, a wind step, an
/// uncertain plant) is recovered at that bound instead of commanding accelerations that
/// saturate thrust and surfaces (README, "Robustness on uncertain plants").
pub(crate) fn command(
    d: &LoopDesign,
    reference: &Reference,
    pos_error: &Vector3<f64>,
    vel_error: &Vector3<f64>,
    sigma_ff: &Vector3<f64>,
) -> Vector3<f64> {
    let (kp_g, kv_g) = d.guidance;
    let lateral = reference.tangent().cross(&reference.prescribed_normal());
    let (kp_l, kv_l) = d.guidance_lateral;
    let mut feedback = -pos_error * kp_g - vel_error * kv_g;
    if (kp_l, kv_l) != (kp_g, kv_g) {
        feedback -= lateral * ((kp_l - kp_g) * lateral.dot(pos_error) + (kv_l - kv_g) * lateral.dot(vel_error));
    }
    let size = feedback.norm();
    if size > d.guidance_feedback_limit {
        feedback *= d.guidance_feedback_limit / size;
    }
    feedback + sigma_ff
}
