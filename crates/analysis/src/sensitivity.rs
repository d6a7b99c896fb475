//! The sensitivity study of thesis §5.1: one parameter at a time scaled in the **plant**
//! by C(k) = C₀·τ^(−1+2k/N), k = 0…N−1 (5.1.1; N = 50, τ = 1.5 for aerodynamic
//! coefficients and 1.1 for physical constants), the controllers keeping the gains of the
//! nominal model, and the closed-loop poles recomputed ([`crate::closed`]).
//!
//! Measure of Table 5.1 (§5.2.1): "the distance each pole moves … as a percentage of the
//! pole's natural frequency … the RMS of these distances". The thesis does not say between
//! which points the distance is taken; here it is the largest excursion of each pole from
//! its nominal position over the sweep, d_i = max_k |p_i(k) − p_i⁰| / ω_n,i⁰, and the
//! table entry is 100·√(mean_i d_i²). Poles are tracked along the sweep from the nominal
//! point (k = N/2, factor 1) outwards by nearest-neighbour matching. Poles with
//! ω_n < [`MIN_OMEGA`] are left out of the RMS (a nearly neutral pole makes any movement
//! an infinite percentage). The end-to-end span |p_i(N−1) − p_i(0)|/ω_n,i is kept too.

use serde::{Deserialize, Serialize};
use tailsitter_physics::Airframe;

use crate::linalg::{match_poles, C64};

/// s-plane poles with Re s below this (z ≈ 0: a saturated actuator) are degenerate.
pub const DEGENERATE_S: f64 = -1e6;

/// Poles slower than this (rad/s) are not counted in the RMS.
pub const MIN_OMEGA: f64 = 0.05;

/// Aerodynamic or physical parameter (decides τ).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ParamClass {
    /// Stability/control derivative: τ = 1.5.
    Aerodynamic,
    /// Mass or inertia: τ = 1.1.
    Physical,
}

/// One parameter of Table 5.1.
#[derive(Debug, Clone, Copy)]
pub struct Param {
    /// Thesis symbol (LaTeX-free), e.g. "C_Lα".
    pub name: &'static str,
    /// File-name-safe id.
    pub id: &'static str,
    /// Aerodynamic or physical.
    pub class: ParamClass,
    /// The thesis's Table 5.1 values (LQR %, TSD %).
    pub thesis: (f64, f64),
    scale: fn(&mut Airframe, f64),
}

impl Param {
    /// τ of (5.1.1).
    pub fn tau(&self) -> f64 {
        match self.class {
            ParamClass::Aerodynamic => 1.5,
            ParamClass::Physical => 1.1,
        }
    }

    /// `af` with this parameter scaled by `factor` (both the α = 0 and α = 5.9° values).
    pub fn scaled(&self, af: &Airframe, factor: f64) -> Airframe {
        let mut a = *af;
        (self.scale)(&mut a, factor);
        a
    }
}

macro_rules! aero {
    ($name:expr, $id:expr, $a0:ident, $a1:ident, $lqr:expr, $tsd:expr) => {
        Param {
            name: $name,
            id: $id,
            class: ParamClass::Aerodynamic,
            thesis: ($lqr, $tsd),
            scale: |a: &mut Airframe, f: f64| {
                a.$a0 *= f;
                a.$a1 *= f;
            },
        }
    };
}

/// A physical parameter of Table 5.1: one airframe field scaled.
macro_rules! physical {
    ($name:expr, $id:expr, $field:ident, $lqr:expr, $tsd:expr) => {
        Param {
            name: $name,
            id: $id,
            class: ParamClass::Physical,
            thesis: ($lqr, $tsd),
            scale: |a: &mut Airframe, f: f64| a.$field *= f,
        }
    };
}

/// The 25 parameters of Table 5.1 with the thesis's values.
pub fn params() -> Vec<Param> {
    vec![
        aero!("C_Lα", "CLa", c_L_alpha_a0, c_L_alpha_a1, 39.7, 33.6),
        aero!("C_Lq", "CLq", c_L_q_a0, c_L_q_a1, 6.4, 6.3),
        aero!("C_Lδe", "CLde", c_L_de_a0, c_L_de_a1, 9.5, 8.8),
        aero!("C_Yβ", "CYb", c_Y_beta_a0, c_Y_beta_a1, 3.2, 60.4),
        aero!("C_Yp", "CYp", c_Y_p_a0, c_Y_p_a1, 1.2, 1.7),
        aero!("C_Yr", "CYr", c_Y_r_a0, c_Y_r_a1, 0.7, 11.1),
        aero!("C_Yδa", "CYda", c_Y_da_a0, c_Y_da_a1, 0.0, 0.0),
        aero!("C_Yδr", "CYdr", c_Y_dr_a0, c_Y_dr_a1, 2.6, 30.2),
        aero!("C_lβ", "Clb", c_l_beta_a0, c_l_beta_a1, 0.1, 1.2),
        aero!("C_lp", "Clp", c_l_p_a0, c_l_p_a1, 51.4, 61.4),
        aero!("C_lr", "Clr", c_l_r_a0, c_l_r_a1, 1.9, 7.0),
        aero!("C_lδa", "Clda", c_l_da_a0, c_l_da_a1, 31.2, 40.3),
        aero!("C_lδr", "Cldr", c_l_dr_a0, c_l_dr_a1, 1.2, 39.1),
        aero!("C_mα", "Cma", c_m_alpha_a0, c_m_alpha_a1, 47.1, 89.4),
        aero!("C_mq", "Cmq", c_m_q_a0, c_m_q_a1, 24.0, 56.0),
        aero!("C_mδe", "Cmde", c_m_de_a0, c_m_de_a1, 59.0, 105.0),
        aero!("C_nβ", "Cnb", c_n_beta_a0, c_n_beta_a1, 19.1, 95.8),
        aero!("C_np", "Cnp", c_n_p_a0, c_n_p_a1, 1.1, 3.4),
        aero!("C_nr", "Cnr", c_n_r_a0, c_n_r_a1, 5.9, 24.7),
        aero!("C_nδa", "Cnda", c_n_da_a0, c_n_da_a1, 0.6, 1.4),
        aero!("C_nδr", "Cndr", c_n_dr_a0, c_n_dr_a1, 5.5, 124.4),
        physical!("m", "m", mass, 7.4, 14.0),
        physical!("I_x", "Ix", i_xx, 5.5, 10.0),
        physical!("I_y", "Iy", i_yy, 5.1, 12.0),
        physical!("I_z", "Iz", i_zz, 3.4, 9.4),
    ]
}

/// The scale factors τ^(−1+2k/N), k = 0…N−1 (5.1.1). With N even, k = N/2 is exactly 1.
pub fn factors(tau: f64, n: usize) -> Vec<f64> {
    (0..n).map(|k| tau.powf(-1.0 + 2.0 * k as f64 / n as f64)).collect()
}

/// Index of the factor closest to 1.
pub fn nominal_index(factors: &[f64]) -> usize {
    (0..factors.len())
        .min_by(|&a, &b| (factors[a].ln().abs()).total_cmp(&factors[b].ln().abs()))
        .unwrap_or(0)
}

/// Poles tracked along a sweep and the Table 5.1 measure.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SensitivityRow {
    /// RMS over poles of the largest excursion from nominal, % of natural frequency.
    pub rms_percent: f64,
    /// RMS over poles of the end-to-end span |p(N−1) − p(0)|, % of natural frequency.
    pub rms_span_percent: f64,
    /// Number of sweep points where the poles could not be computed (flight failed).
    pub failed_points: usize,
    /// Number of sweep points with an unstable closed-loop pole (Re s > 0).
    pub unstable_points: usize,
    /// Number of sweep points with a degenerate pole z ≈ 0 (s ≤ [`DEGENERATE_S`]): a
    /// saturated actuator annihilates its direction in one step; such points are left out
    /// of that pole's excursion.
    #[serde(default)]
    pub degenerate_points: usize,
    /// Tracked loci: `loci[i][k]` = pole i at factor k (None where the point failed).
    pub loci: Vec<Vec<Option<(f64, f64)>>>,
}

/// Track poles along a sweep from the nominal index outwards and compute the measure.
/// `points[k]` = poles at factor k (None = failed). Needs `points[nominal]`.
pub fn track(points: &[Option<Vec<C64>>], nominal: usize) -> Option<SensitivityRow> {
    let p0 = points.get(nominal)?.as_ref()?.clone();
    let n = p0.len();
    let mut loci: Vec<Vec<Option<(f64, f64)>>> = vec![vec![None; points.len()]; n];
    for (i, p) in p0.iter().enumerate() {
        loci[i][nominal] = Some((p.re, p.im));
    }
    for dir in [1i64, -1] {
        let mut prev = p0.clone();
        let mut k = nominal as i64 + dir;
        while k >= 0 && (k as usize) < points.len() {
            if let Some(cur) = &points[k as usize] {
                let m = match_poles(&prev, cur);
                for i in 0..n {
                    if let Some(j) = m[i] {
                        loci[i][k as usize] = Some((cur[j].re, cur[j].im));
                        prev[i] = cur[j];
                    }
                }
            }
            k += dir;
        }
    }
    let mut sum = 0.0;
    let mut sum_span = 0.0;
    let mut count = 0usize;
    for (i, p) in p0.iter().enumerate() {
        let w = p.norm();
        if w < MIN_OMEGA {
            continue;
        }
        let d = loci[i]
            .iter()
            .flatten()
            .filter(|(re, _)| *re > DEGENERATE_S)
            .map(|(re, im)| (C64::new(*re, *im) - p).norm())
            .fold(0.0, f64::max)
            / w;
        let first = loci[i].iter().flatten().find(|(re, _)| *re > DEGENERATE_S);
        let last = loci[i].iter().flatten().rfind(|(re, _)| *re > DEGENERATE_S);
        let span = match (first, last) {
            (Some(a), Some(b)) => (C64::new(a.0, a.1) - C64::new(b.0, b.1)).norm() / w,
            _ => 0.0,
        };
        sum += d * d;
        sum_span += span * span;
        count += 1;
    }
    let c = count.max(1) as f64;
    Some(SensitivityRow {
        rms_percent: 100.0 * (sum / c).sqrt(),
        rms_span_percent: 100.0 * (sum_span / c).sqrt(),
        failed_points: points.iter().filter(|p| p.is_none()).count(),
        degenerate_points: points
            .iter()
            .flatten()
            .filter(|p| p.iter().any(|s| s.re <= DEGENERATE_S))
            .count(),
        unstable_points: points
            .iter()
            .flatten()
            .filter(|p| p.iter().any(|s| s.re > 1e-9))
            .count(),
        loci,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_follow_5_1_1() {
        let f = factors(1.5, 50);
        assert_eq!(f.len(), 50);
        assert!((f[0] - 1.0 / 1.5).abs() < 1e-15);
        assert!((f[25] - 1.0).abs() < 1e-15);
        assert_eq!(nominal_index(&f), 25);
        assert!((f[49] - 1.5f64.powf(0.96)).abs() < 1e-12);
    }

    #[test]
    fn scaling_touches_both_columns() {
        let p = params();
        assert_eq!(p.len(), 25);
        let a = Airframe::default();
        let cma = p.iter().find(|p| p.id == "Cma").unwrap().scaled(&a, 2.0);
        assert_eq!(cma.c_m_alpha_a0, 2.0 * a.c_m_alpha_a0);
        assert_eq!(cma.c_m_alpha_a1, 2.0 * a.c_m_alpha_a1);
        assert_eq!(cma.c_m_q_a0, a.c_m_q_a0);
        let m = p.iter().find(|p| p.id == "m").unwrap();
        assert_eq!(m.tau(), 1.1);
    }
}
