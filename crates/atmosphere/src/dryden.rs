//! Dryden turbulence (MIL-F-8785C §3.7): spectra, low-altitude intensities and
//! scale lengths, and the exact discretisation of the shaping filters.
//!
//! Spectra in spatial frequency Ω (rad/m), one-sided (∫₀^∞ Φ dΩ = σ²):
//! Φ_u(Ω) = σ_u² (2L_u/π) / (1 + (L_uΩ)²),
//! Φ_v(Ω) = σ_v² (L_v/π) (1 + 3(L_vΩ)²) / (1 + (L_vΩ)²)², Φ_w likewise with L_w, σ_w.
//! An aircraft at airspeed V crossing the frozen field sees ω = VΩ.
//!
//! Filters in normalised time s = t V / L (unit-variance stationary outputs):
//! - u: x' = −x + √2 ξ, output x (autocorrelation e^{−|s|});
//! - v, w: x₁' = −x₁ + x₂, x₂' = −x₂ + 2ξ (ξ unit white noise), output
//!   y = ((1 − √3) x₁ + √3 x₂)/2, transfer ξ → y (1 + √3 p)/(1 + p)², autocorrelation
//!   (1 − |s|/2) e^{−|s|}; stationary covariance P = [[1, 1], [1, 2]].
//!
//! Exact discretisation over one sample T (normalised step η = V T / L): the sampled
//! process has exactly the continuous autocovariance at the sample lags.
//! u: x ← a x + √(1 − a²) n, a = e^{−η}.
//! v, w: x ← Φ x + L n, Φ = e^{−η} [[1, η], [0, 1]], L L^T = Q = P − Φ P Φ^T:
//! Q₁₁ = 1 − e^{−2η}(1 + 2η + 2η²), Q₁₂ = 1 − e^{−2η}(1 + 2η), Q₂₂ = 2(1 − e^{−2η}),
//! evaluated as e^{−2η} times the tails of the exponential series (no cancellation
//! for small η). The output is σ times the unit-variance output, with σ and L of the
//! current height: a change of height or airspeed changes the correlation time and
//! the intensity without a transient.

use crate::FOOT;
use sensor_model::rng::NoiseRng;

/// Number of filter states (u: 1, v: 2, w: 2).
pub const STATE_LEN: usize = 5;
/// Heights (m) between which the low-altitude form is evaluated: 10 ft and 1000 ft.
/// Below and above, the values at the bound hold.
pub const MIN_HEIGHT: f64 = 10.0 * FOOT;
pub const MAX_HEIGHT: f64 = 1000.0 * FOOT;
/// Largest normalised step: beyond it consecutive samples are uncorrelated to
/// e^{−50} (a guard against overflow for absurd airspeeds).
const MAX_ETA: f64 = 50.0;

const SQRT3: f64 = 1.732_050_807_568_877_2;
/// Output weights of the second-order filter on (x₁, x₂).
const C1: f64 = 0.5 * (1.0 - SQRT3);
const C2: f64 = 0.5 * SQRT3;

/// σ_u, σ_v, σ_w (unit of `w20`) at height `h` (m), MIL-F-8785C §3.7 low altitude:
/// σ_w = 0.1 W20, σ_u = σ_v = σ_w / (0.177 + 0.000823 h_ft)^0.4.
pub fn intensities(h: f64, w20: f64) -> [f64; 3] {
    let h_ft = h.clamp(MIN_HEIGHT, MAX_HEIGHT) / FOOT;
    let sigma_w = 0.1 * w20;
    let sigma_u = sigma_w / libm::pow(0.177 + 0.000823 * h_ft, 0.4);
    [sigma_u, sigma_u, sigma_w]
}

/// L_u, L_v, L_w (m) at height `h` (m), MIL-F-8785C §3.7 low altitude:
/// L_w = h, L_u = L_v = h / (0.177 + 0.000823 h)^1.2 (h in ft).
pub fn scale_lengths(h: f64) -> [f64; 3] {
    let h_ft = h.clamp(MIN_HEIGHT, MAX_HEIGHT) / FOOT;
    let l_u = h_ft / libm::pow(0.177 + 0.000823 * h_ft, 1.2) * FOOT;
    [l_u, l_u, h_ft * FOOT]
}

/// One-sided spatial PSD of the u component (m²/s² per rad/m).
pub fn psd_u(omega: f64, sigma: f64, l: f64) -> f64 {
    sigma * sigma * (2.0 * l / std::f64::consts::PI) / (1.0 + (l * omega).powi(2))
}

/// One-sided spatial PSD of the v and w components (m²/s² per rad/m).
pub fn psd_vw(omega: f64, sigma: f64, l: f64) -> f64 {
    let x2 = (l * omega).powi(2);
    sigma * sigma * (l / std::f64::consts::PI) * (1.0 + 3.0 * x2) / (1.0 + x2).powi(2)
}

/// Σ_{n ≥ m} x^n / n! (x ≥ 0), accurate for small x.
fn exp_tail(x: f64, m: u32) -> f64 {
    if x < 1.0 {
        let mut term = 1.0;
        for n in 1..=m {
            term *= x / f64::from(n);
        }
        let mut sum = 0.0;
        let mut n = m;
        while term > 1e-18 * sum || sum == 0.0 {
            sum += term;
            n += 1;
            term *= x / f64::from(n);
            if term == 0.0 || n > 60 {
                break;
            }
        }
        sum
    } else {
        let mut partial = 0.0;
        let mut term = 1.0;
        for n in 0..m {
            partial += term;
            term *= x / f64::from(n + 1);
        }
        libm::exp(x) - partial
    }
}

/// Exact one-sample transition of the second-order filter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SecondOrder {
    /// e^{−η} and η e^{−η}.
    decay: f64,
    decay_eta: f64,
    /// Cholesky factor of Q: [L₁₁, L₂₁, L₂₂].
    chol: [f64; 3],
}

impl SecondOrder {
    pub fn new(eta: f64) -> Self {
        let eta = eta.min(MAX_ETA);
        let x = 2.0 * eta;
        let (q11, q12, q22) = if x < 1.0 {
            let e2 = libm::exp(-x);
            (e2 * exp_tail(x, 3), e2 * exp_tail(x, 2), 2.0 * e2 * exp_tail(x, 1))
        } else {
            let e2 = libm::exp(-x);
            (
                1.0 - e2 * (1.0 + x + 0.5 * x * x),
                1.0 - e2 * (1.0 + x),
                -2.0 * libm::expm1(-x),
            )
        };
        let l11 = q11.sqrt();
        let l21 = q12 / l11;
        let l22 = (q22 - l21 * l21).max(0.0).sqrt();
        let decay = libm::exp(-eta);
        Self {
            decay,
            decay_eta: decay * eta,
            chol: [l11, l21, l22],
        }
    }

    /// Propagate (x₁, x₂) by one sample with the normals n₁, n₂.
    pub fn advance_for_test(&self, x: &mut [f64; 2], n1: f64, n2: f64) {
        self.advance(x, n1, n2);
    }

    /// The Cholesky factor [L₁₁, L₂₁, L₂₂] of the one-sample noise covariance.
    pub fn chol_for_test(&self) -> [f64; 3] {
        self.chol
    }

    fn advance(&self, x: &mut [f64; 2], n1: f64, n2: f64) {
        let x1 = self.decay * x[0] + self.decay_eta * x[1] + self.chol[0] * n1;
        let x2 = self.decay * x[1] + self.chol[1] * n1 + self.chol[2] * n2;
        *x = [x1, x2];
    }
}

/// Everything one internal sample needs at a given height and airspeed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// σ_u, σ_v, σ_w (m/s).
    pub sigma: [f64; 3],
    /// L_u, L_v, L_w (m).
    pub length: [f64; 3],
    /// u: x ← a x + b n.
    a_u: f64,
    b_u: f64,
    v: SecondOrder,
    w: SecondOrder,
}

impl Coefficients {
    /// At height `h` (m), airspeed `v` (m/s, > 0), W20 `w20` (m/s), sample time `t_s` (s).
    pub fn new(h: f64, v: f64, w20: f64, t_s: f64) -> Self {
        let sigma = intensities(h, w20);
        let length = scale_lengths(h);
        let eta = length.map(|l| (v * t_s / l).min(MAX_ETA));
        let a_u = libm::exp(-eta[0]);
        Self {
            sigma,
            length,
            a_u,
            b_u: (-libm::expm1(-2.0 * eta[0])).sqrt(),
            v: SecondOrder::new(eta[1]),
            w: SecondOrder::new(eta[2]),
        }
    }
}

/// The shaping-filter states in unit-variance coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Dryden {
    pub u: f64,
    pub v: [f64; 2],
    pub w: [f64; 2],
}

impl Dryden {
    /// A draw from the stationary distribution: u ~ N(0, 1), (x₁, x₂) ~ N(0, P) with
    /// P = [[1, 1], [1, 2]] = L L^T, L = [[1, 0], [1, 1]]. Five normals, in the order
    /// u, v₁, v₂, w₁, w₂ (as every sample).
    pub fn stationary(rng: &mut NoiseRng) -> Self {
        let u = rng.normal();
        let (a, b) = (rng.normal(), rng.normal());
        let (c, d) = (rng.normal(), rng.normal());
        Self {
            u,
            v: [a, a + b],
            w: [c, c + d],
        }
    }

    /// One internal sample: five normals, in the order u, v₁, v₂, w₁, w₂.
    pub fn advance(&mut self, c: &Coefficients, rng: &mut NoiseRng) {
        self.u = c.a_u * self.u + c.b_u * rng.normal();
        let (a, b) = (rng.normal(), rng.normal());
        c.v.advance(&mut self.v, a, b);
        let (a, b) = (rng.normal(), rng.normal());
        c.w.advance(&mut self.w, a, b);
    }

    /// The turbulence in the turbulence axes (u along the mean wind, v lateral, w down), m/s.
    pub fn output(&self, c: &Coefficients) -> [f64; 3] {
        [
            c.sigma[0] * self.u,
            c.sigma[1] * (C1 * self.v[0] + C2 * self.v[1]),
            c.sigma[2] * (C1 * self.w[0] + C2 * self.w[1]),
        ]
    }

    pub fn to_array(&self) -> [f64; STATE_LEN] {
        [self.u, self.v[0], self.v[1], self.w[0], self.w[1]]
    }

    pub fn from_array(x: [f64; STATE_LEN]) -> Self {
        Self {
            u: x[0],
            v: [x[1], x[2]],
            w: [x[3], x[4]],
        }
    }
}
