//! Dryden turbulence against its analytic statistics over one long run
//! (h = 10 m, V = 25 m/s, W20 = 15 m/s, T = 0.01 s, 100 000 s = 10⁷ samples).
//!
//! Variances: the sample mean square of a zero-mean Gaussian process with
//! autocorrelation ρ over a run of length T_run has relative standard deviation
//! √(2·∫_{−∞}^{∞} ρ²(t) dt / T_run): ∫ρ² = τ for u (ρ = e^{−|t|/τ}) and
//! 5τ/8 for v and w (ρ = (1 − |t|/(2τ)) e^{−|t|/τ}), τ = L/V. Tolerance: 4 standard
//! deviations.
//!
//! PSDs: Welch (Hann window, segments of 4096 samples = 40.96 s, 50 % overlap), the
//! windowed DFT evaluated at six bin frequencies from 0.29 Hz (12 bins: the window's
//! smoothing bias on these spectra stays below 1 %) to 9.99 Hz (Nyquist/5). The
//! reference is the exact PSD of the sampled process: the analytic Dryden form
//! aliased, Σ_k S(|f + k f_s|). Relative standard deviation of a Welch estimate:
//! √((1 + 2c²)/K) with K segments and c = 0.167 (Hann at 50 % overlap); tolerance
//! 4 standard deviations + 2 % for the window bias.

use atmosphere::{dryden, Atmosphere, Inputs, Params};
use std::f64::consts::PI;

const H: f64 = 10.0;
const V: f64 = 25.0;
const W20: f64 = 15.0;
const T: f64 = 0.01;
const N: usize = 10_000_000;
const SEG: usize = 4096;
const BINS: [usize; 6] = [12, 24, 48, 96, 192, 409];

/// One-sided temporal PSD per Hz of a component with spatial PSD `phi` (per rad/m).
fn temporal(phi: impl Fn(f64) -> f64, f: f64) -> f64 {
    2.0 * PI * phi(2.0 * PI * f.abs() / V) / V
}

/// The exact one-sided PSD per Hz of the sampled process (the aliased analytic form).
fn aliased(phi: impl Fn(f64) -> f64 + Copy, f: f64) -> f64 {
    let fs = 1.0 / T;
    (-20_000i64..=20_000).map(|k| temporal(phi, f + k as f64 * fs)).sum()
}

#[test]
fn dryden_variances_and_psds_match_the_analytic_forms() {
    let params = Params {
        turbulence_w20: W20,
        turbulence_sample_time: T,
        seed: 20_261_127,
        ..Params::default()
    };
    let mut a = Atmosphere::new(params).unwrap();
    let inputs = Inputs {
        pos_ned: [0.0, 0.0, -H],
        airspeed: V,
    };
    // No mean wind: the turbulence axes are north, east, down.
    a.start(&inputs, 0.0).unwrap();

    // Windowed DFT kernels w[n] e^{-iωn} at the test bins.
    let window: Vec<f64> = (0..SEG)
        .map(|n| 0.5 - 0.5 * (2.0 * PI * n as f64 / SEG as f64).cos())
        .collect();
    let w2: f64 = window.iter().map(|w| w * w).sum();
    let kernels: Vec<Vec<(f64, f64)>> = BINS
        .iter()
        .map(|&b| {
            (0..SEG)
                .map(|n| {
                    let ph = 2.0 * PI * (b * n) as f64 / SEG as f64;
                    (window[n] * ph.cos(), -window[n] * ph.sin())
                })
                .collect()
        })
        .collect();

    let mut ring = vec![[0.0f64; 3]; SEG];
    let mut sum_sq = [0.0f64; 3];
    let mut psd = vec![[0.0f64; 3]; BINS.len()];
    let mut segments = 0usize;
    for k in 0..N {
        let w = if k == 0 {
            a.wind()
        } else {
            a.step(&inputs, k as f64 * T, T).unwrap()
        };
        for c in 0..3 {
            sum_sq[c] += w[c] * w[c];
        }
        ring[k % SEG] = w;
        if k + 1 >= SEG && (k + 1) % (SEG / 2) == 0 {
            let first = k + 1 - SEG;
            for (j, kern) in kernels.iter().enumerate() {
                let mut acc = [(0.0f64, 0.0f64); 3];
                for (n, (kr, ki)) in kern.iter().enumerate() {
                    let x = ring[(first + n) % SEG];
                    for c in 0..3 {
                        acc[c].0 += kr * x[c];
                        acc[c].1 += ki * x[c];
                    }
                }
                for c in 0..3 {
                    psd[j][c] += 2.0 * T * (acc[c].0 * acc[c].0 + acc[c].1 * acc[c].1) / w2;
                }
            }
            segments += 1;
        }
    }

    let sigma = dryden::intensities(H, W20);
    let length = dryden::scale_lengths(H);
    let run = N as f64 * T;
    let names = ["u", "v", "w"];
    let mut failures = Vec::new();
    for c in 0..3 {
        let tau = length[c] / V;
        let integral = if c == 0 { tau } else { 0.625 * tau };
        let rel_std = (2.0 * integral / run).sqrt();
        let ratio = sum_sq[c] / N as f64 / (sigma[c] * sigma[c]);
        let tol = 4.0 * rel_std;
        eprintln!(
            "variance {}: sigma = {:.4} m/s, L = {:.2} m, measured/analytic = {ratio:.4} (tolerance ±{tol:.4})",
            names[c], sigma[c], length[c]
        );
        if (ratio - 1.0).abs() > tol {
            failures.push(format!("variance {}: ratio {ratio}", names[c]));
        }
    }
    let rel_std = ((1.0 + 2.0 * 0.167f64.powi(2)) / segments as f64).sqrt();
    let tol = 4.0 * rel_std + 0.02;
    eprintln!("Welch: {segments} segments, tolerance ±{tol:.4}");
    for (j, &b) in BINS.iter().enumerate() {
        let f = b as f64 / (SEG as f64 * T);
        let mut line = format!("PSD at {f:.3} Hz, measured/analytic:");
        for c in 0..3 {
            let (s, l) = (sigma[c], length[c]);
            let exact = if c == 0 {
                aliased(move |om| dryden::psd_u(om, s, l), f)
            } else {
                aliased(move |om| dryden::psd_vw(om, s, l), f)
            };
            let plain = if c == 0 {
                temporal(|om| dryden::psd_u(om, s, l), f)
            } else {
                temporal(|om| dryden::psd_vw(om, s, l), f)
            };
            let ratio = psd[j][c] / segments as f64 / exact;
            line += &format!(" {} {ratio:.4} (alias {:.4})", names[c], exact / plain);
            if (ratio - 1.0).abs() > tol {
                failures.push(format!("PSD {} at {f} Hz: ratio {ratio}", names[c]));
            }
        }
        eprintln!("{line}");
    }
    assert!(failures.is_empty(), "{failures:?}");
}

#[test]
fn the_analytic_forms_integrate_to_the_variance() {
    // The reference of the PSD test itself: ∫₀^∞ Φ dΩ = σ² (substitution Ω = tan θ / L).
    let (s, l) = (1.3, 7.0);
    for c in 0..2 {
        let m = 100_000;
        let mut total = 0.0;
        for k in 0..m {
            let th = (k as f64 + 0.5) / m as f64 * PI / 2.0;
            let om = th.tan() / l;
            let jac = 1.0 / (l * th.cos().powi(2));
            let phi = if c == 0 {
                dryden::psd_u(om, s, l)
            } else {
                dryden::psd_vw(om, s, l)
            };
            total += phi * jac * (PI / 2.0) / m as f64;
        }
        assert!((total / (s * s) - 1.0).abs() < 1e-8, "component {c}: {total}");
    }
}
