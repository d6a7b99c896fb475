//! Decomposition and normal-vector-direction (NVD) stage (Fig. 4.2, §4.3.1, §4.3.2): the
//! guidance command Σ split into the inner loops' commands — axial A_Wc = Σ·i^W, normal C_Wc
//! and lateral B_Wc, and the commanded normal vector k^Wc (4.3.27–4.3.30) — with the
//! prescribed normal vector of §4.3.2.1 in vertical flight and the transitions, and the NVD
//! error angle φ (4.3.3–4.3.5) the roll loop turns into a roll-rate reference.

use crate::axes::LoopAxes;
use crate::reference::ReferenceSignals;
use crate::TsdController;
use flight_mission::Phase;
use nalgebra::Vector3;

/// The inner loops' commands from Σ.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AccelCommands {
    /// Axial, lateral and normal specific-acceleration commands A_Wc, B_Wc, C_Wc (m/s²).
    pub a_cmd: f64,
    pub b_cmd: f64,
    pub c_cmd: f64,
    /// Commanded normal vector k^Wc, NED.
    pub k_cmd: Vector3<f64>,
    /// NVD error angle φ (4.3.5) (rad).
    pub roll_error: f64,
    /// Weight of the computed (vs prescribed) normal vector, 0..1.
    pub normal_weight: f64,
}

/// The prescribed normal vector k = (sin γ, 0, cos γ) of §4.3.2.1 turned about the earth's
/// down axis by the weathervane's heading ψ_w (README, "Weathervaning").
pub(crate) fn prescribed_normal(r: &ReferenceSignals) -> Vector3<f64> {
    let k = r.reference.prescribed_normal();
    if r.heading == 0.0 {
        k
    } else {
        let (s, c) = r.heading.sin_cos();
        Vector3::new(c * k.x - s * k.y, s * k.x + c * k.y, k.z)
    }
}

impl TsdController {
    /// Weight of the computed normal vector of (4.3.29–4.3.30) against the prescribed one:
    /// 1 inside level flight, ramping over `normal_vector_blend_time` at both ends (no command
    /// jumps), and faded out when the normal command ‖N‖ = `n_norm` is below
    /// `min_normal_accel`; 0 in vertical flight and the transitions (§4.3.2.1).
    pub(crate) fn normal_weight(&self, r: &ReferenceSignals, n_norm: f64) -> f64 {
        if r.reference.phase != Phase::Level {
            return 0.0;
        }
        let p = &self.params;
        let (_, tau) = self.mission.phase_at(r.t_mission);
        let bt = p.normal_vector_blend_time;
        let ramp = if bt > 0.0 {
            (tau / bt).min((self.mission.t_level - tau) / bt).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let nmin = p.min_normal_accel;
        let size = if nmin > 0.0 {
            ((n_norm - nmin) / nmin).clamp(0.0, 1.0)
        } else {
            1.0
        };
        ramp * size
    }

    /// Decomposition (4.3.27–4.3.30) of `sigma` in the loop frame and the NVD error (4.3.5).
    ///
    /// With the prescribed normal vector the lateral part of Σ goes to the directional loop
    /// (B_Wc = Σ·j^W), as in the thesis's vertical flight; with the computed one (level
    /// flight) B_Wc = 0 (coordinated turns) and C_Wc = ±‖N‖, signed so that normal flight
    /// lifts against the belly (4.3.29).
    pub(crate) fn decompose(&self, sigma: &Vector3<f64>, axes: &LoopAxes, r: &ReferenceSignals) -> AccelCommands {
        let (iw, jw, kw) = (&axes.iw, &axes.jw, &axes.kw);
        let a_cmd = sigma.dot(iw);
        let n_vec = sigma - iw * a_cmd;
        let n_norm = n_vec.norm();
        let k_pres = prescribed_normal(r);
        let w_n = self.normal_weight(r, n_norm);
        let (c_comp, k_comp) = if n_norm > 1e-9 {
            if n_vec.dot(&k_pres) <= 0.0 {
                (-n_norm, -n_vec / n_norm)
            } else {
                (n_norm, n_vec / n_norm)
            }
        } else {
            (0.0, k_pres)
        };
        let c_cmd = (1.0 - w_n) * sigma.dot(kw) + w_n * c_comp;
        let b_cmd = (1.0 - w_n) * sigma.dot(jw);
        let k_blend = k_pres * (1.0 - w_n) + k_comp * w_n;
        let k_cmd = if k_blend.norm() > 1e-9 {
            k_blend.normalize()
        } else {
            k_pres
        };
        // NVD error angle (4.3.3–4.3.5): the roll about i^W taking k^W to k^Wc;
        // k^Wc·j^W = −sin φ, k^Wc·k^W = cos φ (atan2 keeps the sign and the full range).
        let (sj, ck) = (-k_cmd.dot(jw), k_cmd.dot(kw));
        let roll_error = if sj.hypot(ck) > 0.1 { sj.atan2(ck) } else { 0.0 };
        AccelCommands {
            a_cmd,
            b_cmd,
            c_cmd,
            k_cmd,
            roll_error,
            normal_weight: w_n,
        }
    }
}
