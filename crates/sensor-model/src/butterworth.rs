//! Second-order Butterworth low-pass of the avionics (thesis App. D.3: "all
//! analogue signals … low pass filtered with a bandwidth of 8 Hz by a second
//! order Butterworth filter implemented in software"), discretised at the
//! sensor's own sample rate by the bilinear transform with prewarping, so that
//! the digital filter's −3 dB point is exactly the requested cut-off.
//!
//! Analogue prototype H(s) = Ω_c² / (s² + √2 Ω_c s + Ω_c²). With
//! s = c (1 − z⁻¹)/(1 + z⁻¹), c = Ω_c / K, K = tan(π f_c / f_s):
//!
//! H(z) = K² (1 + z⁻¹)² / [(1 + √2K + K²) + 2(K² − 1) z⁻¹ + (1 − √2K + K²) z⁻²].

use std::f64::consts::{PI, SQRT_2};

/// Coefficients of one biquad section, normalised to a₀ = 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Butterworth2 {
    pub b0: f64,
    pub b1: f64,
    pub b2: f64,
    pub a1: f64,
    pub a2: f64,
}

/// Largest cut-off as a fraction of the sample rate: below Nyquist with margin.
pub const MAX_CUTOFF_FRACTION: f64 = 0.45;

impl Butterworth2 {
    /// Low-pass with −3 dB at `cutoff` (Hz) for samples at `rate` (Hz).
    /// `None` unless 0 < cutoff < 0.45·rate (both finite).
    pub fn low_pass(cutoff: f64, rate: f64) -> Option<Self> {
        if !(cutoff.is_finite() && rate.is_finite() && cutoff > 0.0 && cutoff < MAX_CUTOFF_FRACTION * rate) {
            return None;
        }
        let k = libm::tan(PI * cutoff / rate);
        let k2 = k * k;
        let n = 1.0 / (1.0 + SQRT_2 * k + k2);
        let b0 = k2 * n;
        Some(Self {
            b0,
            b1: 2.0 * b0,
            b2: b0,
            a1: 2.0 * (k2 - 1.0) * n,
            a2: (1.0 - SQRT_2 * k + k2) * n,
        })
    }

    /// The pass-through "filter" (filter disabled).
    pub const IDENTITY: Self = Self {
        b0: 1.0,
        b1: 0.0,
        b2: 0.0,
        a1: 0.0,
        a2: 0.0,
    };

    /// One sample through the filter (direct form II transposed).
    #[inline]
    pub fn apply(&self, state: &mut [f64; 2], x: f64) -> f64 {
        let y = self.b0 * x + state[0];
        state[0] = self.b1 * x - self.a1 * y + state[1];
        state[1] = self.b2 * x - self.a2 * y;
        y
    }

    /// The state in which a constant input `x` is passed unchanged (DC gain 1).
    pub fn steady_state(&self, x: f64) -> [f64; 2] {
        [(1.0 - self.b0) * x, (self.b2 - self.a2) * x]
    }

    /// Ratio σ_out/σ_in for white input noise: √(Σ h[n]²) over the impulse response.
    pub fn noise_gain(&self) -> f64 {
        let mut s = [0.0; 2];
        let mut sum = 0.0;
        let mut x = 1.0;
        // Poles inside |z| < 1: the tail decays geometrically; 10⁶ samples bound the loop.
        for _ in 0..1_000_000 {
            let y = self.apply(&mut s, x);
            x = 0.0;
            sum += y * y;
            if y * y < 1e-20 * sum && s[0].abs() + s[1].abs() < 1e-12 {
                break;
            }
        }
        sum.sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// |H(e^{jω})| evaluated from the coefficients.
    fn gain(f: &Butterworth2, freq: f64, rate: f64) -> f64 {
        let w = 2.0 * PI * freq / rate;
        let (c1, s1, c2, s2) = (w.cos(), w.sin(), (2.0 * w).cos(), (2.0 * w).sin());
        let num = ((f.b0 + f.b1 * c1 + f.b2 * c2).powi(2) + (f.b1 * s1 + f.b2 * s2).powi(2)).sqrt();
        let den = ((1.0 + f.a1 * c1 + f.a2 * c2).powi(2) + (f.a1 * s1 + f.a2 * s2).powi(2)).sqrt();
        num / den
    }

    #[test]
    fn prewarped_cutoff_is_exactly_minus_3_db_and_response_is_maximally_flat() {
        for rate in [50.0, 200.0, 1000.0] {
            let f = Butterworth2::low_pass(8.0, rate).unwrap();
            assert!((gain(&f, 0.0, rate) - 1.0).abs() < 1e-12);
            assert!((gain(&f, 8.0, rate) - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12);
            // Bilinear maps Ω = c·tan(ω/2): |H|² = 1/(1 + (tan(πf/fs)/tan(πfc/fs))⁴).
            for freq in [1.0, 4.0, 12.0, 20.0] {
                let r = (PI * freq / rate).tan() / (PI * 8.0 / rate).tan();
                let expected = 1.0 / (1.0 + r.powi(4)).sqrt();
                assert!((gain(&f, freq, rate) - expected).abs() < 1e-12, "{rate} {freq}");
            }
        }
    }

    #[test]
    fn steady_state_passes_a_constant() {
        let f = Butterworth2::low_pass(8.0, 200.0).unwrap();
        let mut s = f.steady_state(-9.81);
        for _ in 0..100 {
            assert!((f.apply(&mut s, -9.81) + 9.81).abs() < 1e-12);
        }
    }

    #[test]
    fn rejects_cutoffs_at_or_above_nyquist() {
        assert!(Butterworth2::low_pass(8.0, 16.0).is_none());
        assert!(Butterworth2::low_pass(0.0, 200.0).is_none());
        assert!(Butterworth2::low_pass(f64::NAN, 200.0).is_none());
        assert!(Butterworth2::low_pass(8.0, f64::INFINITY).is_none());
    }
}
