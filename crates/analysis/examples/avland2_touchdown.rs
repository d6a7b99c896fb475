//! The estimator's horizontal error relative to the take-off point at the touchdown, over
//! many sensor seeds: the take-off-to-landing mission with the avionics chain (tuned
//! estimator), against the sensor-limited bound (`state_estimator::bound`).
//!
//! `avland2_touchdown lqr|tsd SEEDS [jacobi] [nozupt] [WIND_M_S BEARING_DEG]` (`nozupt`: the
//! estimator's zero-velocity update off)
//!
//! Per run: the estimate's error (estimated − true position relative to the start, N and E)
//! at the end of the spin-up on the gear and at the touchdown (first contact after the
//! flight), the landing's miss at the touchdown, whether the landing met every criterion.
//! Summary: RMS per axis, median and 95th percentile of the 2-D error, the fraction under 1 m.
use analysis::controllers::Kind;
use analysis::takeoff_landing;
use analysis::wind_envelope::plant;
use closed_loop::avionics::{Avionics, AvionicsSource};
use closed_loop::{fly_with, wind_from, Ordering, Scenario, StateSource, Wind};
use flight_mission::{Command, Measurement};
use nalgebra::Vector3;
use tailsitter_physics::{idx, InputVector, Plant, StateVector};

/// The chain, recording the horizontal estimation error relative to the start at every step.
struct Recorded {
    inner: AvionicsSource,
    origin: Vector3<f64>,
    /// (t, estimate − truth, N and E).
    errors: Vec<(f64, [f64; 2])>,
}

impl StateSource for Recorded {
    fn measure(
        &mut self,
        t: f64,
        h: f64,
        plant: &Plant,
        x: &StateVector,
        u: &InputVector,
        wind: &Vector3<f64>,
        truth: &Measurement,
    ) -> Result<Measurement, String> {
        let m = self.inner.measure(t, h, plant, x, u, wind, truth)?;
        let e = m.pos_ned - (truth.pos_ned - self.origin);
        self.errors.push((t, [e.x, e.y]));
        Ok(m)
    }
    fn flown(&mut self, t: f64, h: f64, command: &Command) -> Result<(), String> {
        self.inner.flown(t, h, command)
    }
}

fn at(errors: &[(f64, [f64; 2])], t: f64) -> [f64; 2] {
    errors
        .iter()
        .rev()
        .find(|(s, _)| *s <= t + 1e-9)
        .map_or([f64::NAN; 2], |(_, e)| *e)
}

fn percentile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let kind = match a.get(1).map(String::as_str) {
        Some("lqr") => Kind::Lqr,
        _ => Kind::Tsd,
    };
    let seeds: u64 = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(20);
    let ordering = if a.iter().any(|s| s == "jacobi") {
        Ordering::Jacobi
    } else {
        Ordering::GaussSeidel
    };
    let numbers: Vec<f64> = a.iter().skip(3).filter_map(|s| s.parse().ok()).collect();
    let plant = plant();
    let mission = takeoff_landing::mission();
    let x0 = plant.resting_on_ground(0.0, 0.0, 0.0);
    let origin = Vector3::new(x0[idx::POS_N], x0[idx::POS_E], x0[idx::POS_D]);
    let mut scenario = Scenario::mission(mission);
    scenario.stop_time = takeoff_landing::stop_time(&mission);
    scenario.ordering = ordering;
    if let [speed, bearing, ..] = numbers[..] {
        scenario.wind = Wind::Step {
            t_start: 2.0,
            wind: wind_from(bearing.to_radians(), speed),
        };
    }
    println!("seed  gear_N  gear_E   td_N    td_E   |td|   miss  landed passed");
    let (mut td, mut gear, mut miss) = (Vec::new(), Vec::new(), Vec::new());
    let (mut sum_sq, mut n_passed) = ([0.0; 2], 0);
    let mut flight_times = Vec::new();
    for seed in 1..=seeds {
        let mut av = Avionics::new(seed, false, ordering, scenario.comm_step);
        av.estimator.tuning.zero_velocity_update = !a.iter().any(|s| s == "nozupt");
        let mut src = Recorded {
            inner: AvionicsSource::start(&av, &plant, &x0, &InputVector::zeros()).unwrap(),
            origin,
            errors: Vec::new(),
        };
        let mut c = kind.make_configured(&mission, 0).unwrap();
        let mut trace = fly_with(
            &plant,
            x0,
            &mut c,
            &scenario,
            &mut src,
            takeoff_landing::after_landing(),
        );
        for s in &mut trace.samples {
            s.measurement.pos_ned -= origin;
        }
        let f = takeoff_landing::evaluate(&plant, kind, ordering, &mission, &trace);
        let g = at(&src.errors, mission.takeoff_spinup_time - scenario.comm_step);
        let Some(t_td) = f.touchdown_time else {
            println!("{seed:4} no touchdown ({:?})", trace.failure);
            continue;
        };
        let e = at(&src.errors, t_td);
        let r = e[0].hypot(e[1]);
        println!(
            "{seed:4} {:7.3} {:7.3} {:7.3} {:7.3} {:6.3} {:6.3} {:6} {:6}",
            g[0],
            g[1],
            e[0],
            e[1],
            r,
            f.miss_touchdown,
            f.landed_time.is_some(),
            f.passed
        );
        sum_sq[0] += e[0] * e[0];
        sum_sq[1] += e[1] * e[1];
        td.push(r);
        flight_times.push(t_td - f.liftoff_time.unwrap_or(mission.takeoff_spinup_time));
        gear.push(g[0].hypot(g[1]));
        miss.push(f.miss_touchdown);
        n_passed += usize::from(f.passed);
    }
    let n = td.len() as f64;
    // The sensor-limited bound for the same time on the gear and the median flight.
    let flight = percentile(&mut flight_times, 0.5);
    let est = state_estimator::EstimatorParams::default();
    let (m_lat, m_lon) = state_estimator::LocalFrame::metres_per_radian(est.earth.site.ref_latitude, 0.0);
    let axis = |sigma_position: f64| {
        state_estimator::bound::axis_bound(&state_estimator::bound::BoundInputs {
            sigma_position,
            sigma_velocity: est.noise.sigma_gps_vel,
            gps_rate: 4.0,
            accel_density: est.noise.sigma_accel.powi(2) * est.filter.noise_correlation_time(scenario.comm_step),
            gear_time: mission.takeoff_spinup_time,
            flight_time: flight,
        })
    };
    let (bn, be) = (
        axis(est.noise.sigma_gps_latlon * m_lat),
        axis(est.noise.sigma_gps_latlon * m_lon),
    );
    println!(
        "bound (gear {:.1} s, flight {flight:.1} s): N {bn:?}\n                                E {be:?}\n  P(2-D < 1 m) = {:.3}, P(2-D < 0.5 m) = {:.3}",
        mission.takeoff_spinup_time,
        state_estimator::bound::probability_within(1.0, bn.sigma_relative, be.sigma_relative),
        state_estimator::bound::probability_within(0.5, bn.sigma_relative, be.sigma_relative)
    );
    let under = |v: &[f64]| v.iter().filter(|r| **r < 1.0).count();
    let under_half = |v: &[f64]| v.iter().filter(|r| **r < 0.5).count();
    println!(
        "{} runs: estimate at touchdown RMS N {:.3} E {:.3} m, 2-D median {:.3} p95 {:.3}, < 1 m {}, < 0.5 m {}; \
         at the end of the spin-up 2-D median {:.3}; miss median {:.3} p95 {:.3}, < 1 m {}; passed {}",
        td.len(),
        (sum_sq[0] / n).sqrt(),
        (sum_sq[1] / n).sqrt(),
        percentile(&mut td.clone(), 0.5),
        percentile(&mut td.clone(), 0.95),
        under(&td),
        under_half(&td),
        percentile(&mut gear, 0.5),
        percentile(&mut miss.clone(), 0.5),
        percentile(&mut miss.clone(), 0.95),
        under(&miss),
        n_passed
    );
}
