//! The avionics chain as a [`StateSource`] of [`crate::fly_with`]: plant → sensors
//! ([`sensor_model`], Table D.1 noise, 8 Hz Butterworth) → estimator ([`state_estimator::Ekf`])
//! → controller, and the command the plant flies → estimator (its motor and servo models).
//! The controller reads the estimate exactly as it reads the plant (the estimator's outputs
//! carry the plant-output names); the trace records the truth.
//!
//! Timing, one communication step h at t (the FMU chain of `tailsim.masters.AvionicsLoop`,
//! docs/DESIGN.md §7): the sensors take their samples due in [t, t + h) of the plant's
//! outputs at t (held over the step); the controller samples the estimate of t; the estimator
//! fuses the measurements and predicts to t + h with the command flown over [t, t + h);
//! the plant steps. Gauss-Seidel: the estimator fuses this step's sensor outputs. Jacobi:
//! every unit's inputs are the outputs at t before any unit steps, so the estimator fuses the
//! sensor outputs of the previous step and the plant flies the previous sample's command
//! ([`crate::Ordering::Jacobi`]); the estimator is told both delays
//! (`measurement_latency` = `prediction_lead` = h, as that master sets them).

use flight_mission::{plant_inputs, Command, Measurement};
use nalgebra::Vector3;
use sensor_model::SensorModel;
use state_estimator::{Ekf, Estimate, EstimatorParams, Measurements};
use tailsitter_physics::{InputVector, Plant, StateVector};

use crate::{Ordering, StateSource};

/// Parameters of the chain: the sensors' and the estimator's, as their FMUs' defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct Avionics {
    pub sensors: sensor_model::Params,
    pub estimator: EstimatorParams,
    /// The master's ordering ([`Ordering::Jacobi`]: the estimator fuses the previous step's
    /// sensor outputs).
    pub ordering: Ordering,
}

impl Avionics {
    /// The declared defaults of `tailsitter_sensors` (seeded with `seed`) and `tailsitter_ekf`
    /// (`app_d`: its `app_d_configuration`, the thesis App.-D-faithful estimator), the shared
    /// site and analogue filter the sensors', under `ordering` with communication step `h`
    /// (Jacobi: `measurement_latency` and `prediction_lead` one step each).
    pub fn new(seed: u64, app_d: bool, ordering: Ordering, h: f64) -> Self {
        let sensors = sensor_model::Params {
            seed,
            ..sensor_model::Params::default()
        };
        let mut estimator = EstimatorParams::default();
        if app_d {
            estimator = estimator.app_d();
        }
        estimator.earth.site = sensors.site;
        estimator.filter.enabled = sensors.filter_enabled;
        estimator.filter.bandwidth = sensors.filter_bandwidth;
        // One gravity for the navigation equations and the motor model (as fmu-ekf).
        estimator.airframe.gravity = estimator.earth.gravity;
        if ordering == Ordering::Jacobi {
            estimator.filter.latency = h;
            estimator.prediction.lead = h;
        }
        Self {
            sensors,
            estimator,
            ordering,
        }
    }
}

/// The estimate as the controller's measurement (the plant outputs of the same names).
pub fn measurement_of(e: &Estimate) -> Measurement {
    Measurement {
        pos_ned: e.pos_ned,
        vel_ned: e.vel_ned,
        vel_body: e.vel_body,
        rates: e.rates,
        quat: e.quat,
        airspeed: e.airspeed,
        alpha: e.alpha,
        beta: e.beta,
        thrust: e.thrust,
        surfaces: e.surfaces,
        specific_force_body: e.specific_force,
        induced_velocity: e.induced_velocity,
    }
}

/// Replace `field` of the estimate `m` by the truth (development probes: which part of the
/// estimate loses a flight): `all`, `pos` (the truth relative to `origin`, the frame of the
/// start-relative estimate), `vel`, `att`, `rates`, `air` (airspeed, α, β), `act` (thrust,
/// surfaces, induced velocity), `sf` (specific force). False for an unknown field.
pub fn substitute_truth(m: &mut Measurement, truth: &Measurement, origin: &Vector3<f64>, field: &str) -> bool {
    match field {
        "all" => {
            *m = *truth;
            m.pos_ned = truth.pos_ned - origin;
        }
        "pos" => m.pos_ned = truth.pos_ned - origin,
        "vel" => {
            m.vel_ned = truth.vel_ned;
            m.vel_body = truth.vel_body;
        }
        "att" => m.quat = truth.quat,
        "rates" => m.rates = truth.rates,
        "air" => {
            m.airspeed = truth.airspeed;
            m.alpha = truth.alpha;
            m.beta = truth.beta;
        }
        "act" => {
            m.thrust = truth.thrust;
            m.surfaces = truth.surfaces;
            m.induced_velocity = truth.induced_velocity;
        }
        "sf" => m.specific_force_body = truth.specific_force_body,
        _ => return false,
    }
    true
}

/// The true state as the sensors see it (the plant outputs of the same names), off the
/// gear or resting on fresh anchors (the start).
pub fn truth(plant: &Plant, x: &StateVector, u: &InputVector, wind: &Vector3<f64>) -> sensor_model::Truth {
    truth_of(&flight_mission::measurement(x, &plant.outputs(x, u, wind)))
}

/// The true state as the sensors see it, from the closed loop's true measurement (whose
/// specific force on the ground carries the gear's stick-slip anchors).
pub fn truth_of(m: &Measurement) -> sensor_model::Truth {
    sensor_model::Truth {
        pos_ned: m.pos_ned,
        vel_ned: m.vel_ned,
        rates: m.rates,
        quat: m.quat,
        airspeed: m.airspeed,
        alpha: m.alpha,
        beta: m.beta,
        specific_force: m.specific_force_body,
    }
}

/// The sensors' outputs as the estimator's inputs (the FMU connections by name).
pub fn to_estimator(m: &sensor_model::Measurements) -> Measurements {
    Measurements {
        gps_latitude: m.gps_latitude,
        gps_longitude: m.gps_longitude,
        gps_height: m.gps_height,
        gps_vel: m.gps_vel,
        gps_fix_count: m.gps_fix_count as i32,
        gps_valid: m.gps_valid,
        accel: m.accel(),
        gyro: m.gyro(),
        mag: m.mag(),
        pitot: m.pitot_airspeed(),
    }
}

/// The running chain (see the module documentation).
#[derive(Debug, Clone)]
pub struct AvionicsSource {
    sensors: SensorModel,
    ekf: Ekf,
    jacobi: bool,
    /// Jacobi: the sensors' outputs of the previous step.
    previous: Measurements,
    /// What the estimator fuses at the end of this step.
    pending: Measurements,
}

impl AvionicsSource {
    /// Start the chain at t = 0 on the plant in `x0` with the commands `u0` held and no wind
    /// at the plant's inputs: the sensors take their first samples, the estimator initialises
    /// from them (attitude by levelling and magnetometer, position and velocity from the fix;
    /// its motor and servo models at its `init_thrust` / `init_elevator`, as the estimator FMU).
    pub fn start(avionics: &Avionics, plant: &Plant, x0: &StateVector, u0: &InputVector) -> Result<Self, String> {
        let mut sensors = SensorModel::new(avionics.sensors).map_err(|e| format!("sensors: {e}"))?;
        let mut ekf = Ekf::new(avionics.estimator.clone()).map_err(|e| format!("estimator: {e}"))?;
        let m0 = sensors
            .start(&truth(plant, x0, u0, &Vector3::zeros()), 0.0)
            .map_err(|e| format!("sensors at t = 0: {e}"))?;
        let m0 = to_estimator(&m0);
        ekf.initialize(&m0);
        Ok(Self {
            sensors,
            ekf,
            jacobi: avionics.ordering == Ordering::Jacobi,
            previous: m0,
            pending: m0,
        })
    }

    /// The estimate now.
    pub fn estimate(&self) -> Estimate {
        self.ekf.estimate()
    }
}

impl StateSource for AvionicsSource {
    fn measure(
        &mut self,
        t: f64,
        h: f64,
        _plant: &Plant,
        _x: &StateVector,
        _u: &InputVector,
        _wind: &Vector3<f64>,
        truth: &Measurement,
    ) -> Result<Measurement, String> {
        let fresh = self
            .sensors
            .step(&truth_of(truth), t, h)
            .map_err(|e| format!("sensors failed at t = {t}: {e}"))?;
        let fresh = to_estimator(&fresh);
        self.pending = if self.jacobi {
            std::mem::replace(&mut self.previous, fresh)
        } else {
            fresh
        };
        Ok(measurement_of(&self.ekf.estimate()))
    }

    /// The estimator steps as its FMU does: a rejected or undone update is reported there
    /// (a log message), never a failure of the run.
    fn flown(&mut self, _t: f64, h: f64, command: &Command) -> Result<(), String> {
        self.ekf.step(&self.pending, &plant_inputs(command), h);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tailsitter_physics::idx;

    /// The estimator is told the Jacobi master's delays (one step each) and nothing under
    /// Gauss-Seidel; it shares the sensors' site and filter; `app_d` is its App.-D switch.
    #[test]
    fn parameters_follow_the_ordering_and_the_sensors() {
        let gs = Avionics::new(7, false, Ordering::GaussSeidel, 0.02);
        assert_eq!((gs.estimator.filter.latency, gs.estimator.prediction.lead), (0.0, 0.0));
        assert_eq!(gs.sensors.seed, 7);
        assert_eq!(gs.estimator.earth.site, gs.sensors.site);
        assert_eq!(gs.estimator.filter.bandwidth, gs.sensors.filter_bandwidth);
        assert!(gs.estimator.tuning.relative_to_start);
        let jacobi = Avionics::new(7, true, Ordering::Jacobi, 0.02);
        assert_eq!(
            (jacobi.estimator.filter.latency, jacobi.estimator.prediction.lead),
            (0.02, 0.02)
        );
        assert!(!jacobi.estimator.tuning.relative_to_start && !jacobi.estimator.prediction.model);
    }

    /// The chain starts on a resting aircraft: the estimate's position is the start (the
    /// tuned estimator's positions are relative to it) and its attitude within a few degrees.
    #[test]
    fn the_chain_starts_at_the_start() {
        let mut plant = Plant::new(tailsitter_physics::Airframe::default());
        plant.ground = tailsitter_physics::Ground::default();
        let x0 = plant.resting_on_ground(0.0, 0.0, 0.0);
        let a = Avionics::new(1, false, Ordering::GaussSeidel, 0.02);
        let s = AvionicsSource::start(&a, &plant, &x0, &InputVector::zeros()).unwrap();
        let e = s.estimate();
        assert!(e.pos_ned.norm() < 1e-9, "{:?}", e.pos_ned);
        let q_true = x0.fixed_rows::<4>(idx::Q1).into_owned();
        let att = state_estimator::attitude_error(
            &tailsitter_physics::dcm_earth_to_body(&q_true),
            &tailsitter_physics::dcm_earth_to_body(&e.quat),
        );
        assert!(att.norm() < 5f64.to_radians(), "{att:?}");
    }

    /// Resting on the gear (motor off) for 5 s, the tuned estimator's zero-velocity update
    /// keeps its start-relative position at the start, the mean of the fixes taken there,
    /// from 0.5 s on (the motor model's start at `init_thrust` and the first fix's velocity
    /// pass first); without it the estimate wanders with the GPS velocity's noise.
    #[test]
    fn at_rest_on_the_gear_the_position_stays_at_the_start() {
        let mut plant = Plant::new(tailsitter_physics::Airframe::default());
        plant.ground = tailsitter_physics::Ground::default();
        let x0 = plant.resting_on_ground(0.0, 0.0, 0.0);
        let h = 0.02;
        let wander = |zero_velocity_update: bool, seed: u64| {
            let mut a = Avionics::new(seed, false, Ordering::GaussSeidel, h);
            a.estimator.tuning.zero_velocity_update = zero_velocity_update;
            let command = Command::default();
            let u = plant_inputs(&command);
            let mut source = AvionicsSource::start(&a, &plant, &x0, &u).unwrap();
            let (mut x, mut worst) = (x0, 0.0f64);
            let wind = Vector3::zeros();
            for k in 0..250 {
                let t = k as f64 * h;
                let truth = flight_mission::measure(&plant, &x, &u, &wind);
                let m = source.measure(t, h, &plant, &x, &u, &wind, &truth).unwrap();
                if t >= 0.5 {
                    worst = worst.max(m.pos_ned.xy().norm());
                }
                source.flown(t, h, &command).unwrap();
                plant.advance(&mut x, &u, &wind, h).unwrap();
            }
            worst
        };
        let (mut with, mut without) = (0.0f64, 0.0f64);
        for seed in 1..=4 {
            with = with.max(wander(true, seed));
            without = without.max(wander(false, seed));
        }
        eprintln!("largest start-relative position at rest: {with:.3} m with the update, {without:.3} m without");
        assert!(with < 0.05, "{with}");
        assert!(without > 0.2, "{without}");
    }
}
