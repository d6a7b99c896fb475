//! The sensor-limited bound of the horizontal position relative to the take-off point at
//! the touchdown: how well *any* estimator can know where the aircraft is relative to where
//! it took off, given Table D.1's GPS and accelerometers (thesis App. D.3–D.4).
//!
//! # Model (per horizontal axis, linear and Gaussian: the Kalman filter's covariance is
//! the Cramér–Rao bound, exactly)
//!
//! * On the gear for `gear_time` from the first fix: the aircraft does not move (x = x₀,
//!   v = 0 known exactly: the best a zero-velocity detector can do); every GPS fix measures x₀.
//! * In flight for `flight_time`: v̇ = a_m + n_a, the accelerometer's white noise of density
//!   q_a = σ_a² T_imu (the density of Table D.1's σ_a behind the sensors' 8 Hz Butterworth,
//!   [`crate::AnalogFilter::noise_correlation_time`]), starting from v = 0 at the lift-off.
//!   No attitude error, no accelerometer or gyro bias: every unknown left out only lowers the
//!   error, so this is a lower bound for the full 6-DOF problem.
//! * GPS at `gps_rate`: position x + n_p (σ_p: Table D.1's 6.2832e-7 rad times the metres
//!   per radian of latitude, 3.99 m north, or of longitude, 3.33 m east at the sensors' site
//!   −33.93°), velocity v + n_v (σ_v = 0.5 m/s), both white — as Table D.1 is given (the
//!   variances D.4 hands its Kalman filter, which assumes white noise) and as the sensor model
//!   draws them (`sensor-model`: one independent normal deviate per fix and axis).
//!
//! x₀ is a clone of x (stochastic cloning, as [`crate::Ekf`]'s start position): at the
//! touchdown T the filter's joint covariance of (x_T, x₀) conditioned on every fix up to T
//! gives Var(x_T − x₀) = P_xx + P₀₀ − 2P_x0: x_T filtered (causal: the touchdown happens
//! before the later fixes), x₀ smoothed by every later fix through the flight's dead
//! reckoning.
//!
//! # What limits it
//!
//! Below ω = (q_a f_GPS/σ_v²)^{1/2} = 0.13 rad/s (periods over 47 s) the accelerometer's
//! velocity random walk (density q_a/ω²) is worse than the GPS velocity (σ_v²/f_GPS), so the
//! displacement over a long flight is known to a random walk of density σ_v²/f_GPS
//! (0.0625 m²/s): x₀ is pinned by the fixes near the start only (the gear's and
//! the first seconds of flight), x_T by those of the last seconds. Neither averages down
//! with a longer flight. With a GPS error correlated over minutes (real receivers: the
//! atmospheric and orbit errors) the common part would cancel in x_T − x₀; with white noise
//! it cannot.
use nalgebra::{Matrix3, Vector3};

/// The sensor figures and the flight of the bound (one horizontal axis).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundInputs {
    /// GPS position σ along the axis (m).
    pub sigma_position: f64,
    /// GPS velocity σ (m/s).
    pub sigma_velocity: f64,
    /// GPS fix rate (Hz).
    pub gps_rate: f64,
    /// Two-sided density of the accelerometer's white noise ((m/s²)²/Hz = m²/s³).
    pub accel_density: f64,
    /// Time at rest on the gear from the first fix to the lift-off (s).
    pub gear_time: f64,
    /// Time from the lift-off to the touchdown (s).
    pub flight_time: f64,
}

/// Standard deviations at the touchdown (m): the position x_T (filtered), the start x₀
/// (smoothed by every fix up to T) and their difference, the bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisBound {
    pub sigma_touchdown: f64,
    pub sigma_start: f64,
    pub sigma_relative: f64,
}

/// The Kalman filter of the model above, state (x, v, x₀) (module documentation).
pub fn axis_bound(b: &BoundInputs) -> AxisBound {
    let dt = 1.0 / b.gps_rate;
    let (rp, rv) = (b.sigma_position.powi(2), b.sigma_velocity.powi(2));
    // No prior on the position: diffuse (σ 10 km), v = 0 known, x₀ ≡ x.
    let big = 1e8;
    let mut p = Matrix3::new(big, 0.0, big, 0.0, 0.0, 0.0, big, 0.0, big);
    let fuse = |p: &mut Matrix3<f64>, h: Vector3<f64>, r: f64| {
        let ph = *p * h;
        let s = h.dot(&ph) + r;
        *p -= ph * ph.transpose() / s;
        *p = (*p + p.transpose()) * 0.5;
    };
    let e_x = Vector3::new(1.0, 0.0, 0.0);
    let e_v = Vector3::new(0.0, 1.0, 0.0);
    // Fixes at k dt: on the gear while k dt < gear_time, then in flight up to the touchdown.
    let end = b.gear_time + b.flight_time;
    let mut t = 0.0;
    let mut k = 0u64;
    loop {
        fuse(&mut p, e_x, rp);
        if t >= b.gear_time {
            fuse(&mut p, e_v, rv);
        }
        k += 1;
        let next = k as f64 * dt;
        if next > end + 1e-9 {
            break;
        }
        // Propagate to the next fix; on the gear nothing moves (x = x₀, v = 0).
        if next > b.gear_time {
            fly(&mut p, next - t.max(b.gear_time), b.accel_density);
        }
        t = next;
    }
    // From the last fix to the touchdown.
    let s = end - t.max(b.gear_time);
    if s > 0.0 {
        fly(&mut p, s, b.accel_density);
    }
    AxisBound {
        sigma_touchdown: p[(0, 0)].sqrt(),
        sigma_start: p[(2, 2)].sqrt(),
        sigma_relative: (p[(0, 0)] + p[(2, 2)] - 2.0 * p[(0, 2)]).max(0.0).sqrt(),
    }
}

/// Propagate the covariance of (x, v, x₀) over `s` of flight with the accelerometer's
/// white noise of density `q`: Φ = [[1, s, 0], [0, 1, 0], [0, 0, 1]], Q = q [[s³/3, s²/2, 0],
/// [s²/2, s, 0], [0, 0, 0]].
fn fly(p: &mut Matrix3<f64>, s: f64, q: f64) {
    let f = Matrix3::new(1.0, s, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    let (q3, q2) = (q * s.powi(3) / 3.0, q * s * s / 2.0);
    let qm = Matrix3::new(q3, q2, 0.0, q2, q * s, 0.0, 0.0, 0.0, 0.0);
    *p = f * *p * f.transpose() + qm;
}

/// Probability that a zero-mean Gaussian 2-D error of independent axes with σ `sigma_n`,
/// `sigma_e` lies within `radius` (polar midpoint quadrature, error < 1e-6 here).
pub fn probability_within(radius: f64, sigma_n: f64, sigma_e: f64) -> f64 {
    let (nr, nt) = (400, 256);
    let (dr, dth) = (radius / nr as f64, std::f64::consts::TAU / nt as f64);
    let norm = 1.0 / (std::f64::consts::TAU * sigma_n * sigma_e);
    let mut sum = 0.0;
    for i in 0..nr {
        let r = (i as f64 + 0.5) * dr;
        for j in 0..nt {
            let th = (j as f64 + 0.5) * dth;
            let (n, e) = (r * th.cos(), r * th.sin());
            sum += (-0.5 * ((n / sigma_n).powi(2) + (e / sigma_e).powi(2))).exp() * r;
        }
    }
    sum * norm * dr * dth
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inputs(gear_time: f64, flight_time: f64) -> BoundInputs {
        BoundInputs {
            sigma_position: 4.0,
            sigma_velocity: 0.5,
            gps_rate: 4.0,
            accel_density: 0.1414f64.powi(2) * 0.05635,
            gear_time,
            flight_time,
        }
    }

    /// On the gear alone the start is the mean of the fixes: σ/√N (fixes at 0, 0.25, …, 2 s:
    /// N = 9), and a touchdown at the lift-off is at the start exactly.
    #[test]
    fn on_the_gear_the_start_is_the_mean_of_the_fixes() {
        let b = axis_bound(&inputs(2.0, 0.0));
        assert!((b.sigma_start - 4.0 / 3.0).abs() < 1e-6, "{b:?}");
        assert!(b.sigma_relative < 1e-6, "{b:?}");
    }

    /// With a perfect accelerometer the displacement since the lift-off (from rest) is known
    /// exactly: the relative bound vanishes however poor the fixes, while the absolute
    /// position is the mean of every fix.
    #[test]
    fn a_perfect_accelerometer_knows_the_displacement() {
        let mut i = inputs(2.0, 30.0);
        i.accel_density = 0.0;
        let b = axis_bound(&i);
        assert!(b.sigma_relative < 1e-3, "{b:?}");
        let n = 2.0 * 4.0 + 30.0 * 4.0 + 1.0;
        assert!((b.sigma_touchdown / (4.0 / f64::sqrt(n)) - 1.0).abs() < 1e-3, "{b:?}");
    }

    /// A long flight: the position at the touchdown reaches the steady state of the
    /// position fixes combined with the displacement known to the GPS velocity's random walk,
    /// (σ_v² σ_p² / f²)^{1/4} = 0.707 m (continuous-time limit, the accelerometer adds
    /// little); the start gains the one-sided fixes of the flight's first seconds on top of
    /// the gear's, and the relative bound no longer depends on the flight's length.
    #[test]
    fn a_long_flight_reaches_the_steady_state() {
        let b = axis_bound(&inputs(2.0, 150.0));
        let steady = (0.25f64 * 16.0 / 16.0).powf(0.25);
        assert!((b.sigma_touchdown / steady - 1.0).abs() < 0.1, "{b:?} vs {steady}");
        let gear = 4.0 / 8f64.sqrt();
        assert!(b.sigma_start < 0.6 * gear, "{b:?}");
        let longer = axis_bound(&inputs(2.0, 300.0));
        assert!((longer.sigma_relative / b.sigma_relative - 1.0).abs() < 1e-3);
        // More time on the gear only helps, down to the touchdown's own σ.
        let g30 = axis_bound(&inputs(30.0, 150.0));
        assert!(g30.sigma_relative < b.sigma_relative && g30.sigma_relative > b.sigma_touchdown);
    }

    /// The 2-D probability against the Rayleigh form of equal axes, 1 − exp(−r²/2σ²).
    #[test]
    fn probability_within_matches_rayleigh() {
        for s in [0.3f64, 0.7, 1.0, 2.0] {
            let exact = 1.0 - (-1.0 / (2.0 * s * s)).exp();
            assert!((probability_within(1.0, s, s) - exact).abs() < 1e-5, "{s}");
        }
    }
}
