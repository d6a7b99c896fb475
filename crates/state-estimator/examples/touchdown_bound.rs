//! The sensor-limited bound of the horizontal position relative to the take-off point at
//! the touchdown (`state_estimator::bound`) for the estimator's default sensor figures:
//! `touchdown_bound [GEAR_TIME_S [FLIGHT_TIME_S]]` (defaults 2 s and 162 s, the
//! take-off-to-landing mission).
use state_estimator::bound::{axis_bound, probability_within, BoundInputs};
use state_estimator::{EstimatorParams, LocalFrame};

fn main() {
    let a: Vec<f64> = std::env::args().skip(1).filter_map(|s| s.parse().ok()).collect();
    let gear_time = a.first().copied().unwrap_or(2.0);
    let flight_time = a.get(1).copied().unwrap_or(162.0);
    let p = EstimatorParams::default();
    let (m_lat, m_lon) = LocalFrame::metres_per_radian(p.earth.site.ref_latitude, 0.0);
    let axis = |sigma_position: f64| {
        axis_bound(&BoundInputs {
            sigma_position,
            sigma_velocity: p.noise.sigma_gps_vel,
            gps_rate: 4.0,
            accel_density: p.noise.sigma_accel.powi(2) * p.filter.noise_correlation_time(0.02),
            gear_time,
            flight_time,
        })
    };
    let (n, e) = (
        axis(p.noise.sigma_gps_latlon * m_lat),
        axis(p.noise.sigma_gps_latlon * m_lon),
    );
    println!("gear {gear_time} s, flight {flight_time} s");
    println!(
        "sigma relative N {:.3} E {:.3} m; touchdown N {:.3} E {:.3}; start N {:.3} E {:.3}",
        n.sigma_relative, e.sigma_relative, n.sigma_touchdown, e.sigma_touchdown, n.sigma_start, e.sigma_start
    );
    println!(
        "P(2-D < 1 m) = {:.3}, P(2-D < 0.5 m) = {:.3}",
        probability_within(1.0, n.sigma_relative, e.sigma_relative),
        probability_within(0.5, n.sigma_relative, e.sigma_relative)
    );
}
