//! `tailsitter_ekf`: the pure-Rust state estimator ([`state_estimator::Ekf`]) bound to
//! the generic FMI 2.0 Co-Simulation export layer through the one adapter of every
//! co-simulation unit ([`controller_fmu::UnitFmu`]). The variables and their groups
//! (`measurements`, `commands`, `estimate`, `estimator`) are declared in
//! `modelDescription/tailsitter_ekf.json`; timing, state and messages live in
//! `controller-fmu` (docs/DESIGN.md §2, §7).
//!
//! Timing: `fmi2DoStep(t, h)` fuses the measurements set for t, predicts to t + h with the
//! IMU sample held and advances the motor and servo models with the commands set for t
//! (those for [t, t + h)); the outputs then hold the estimate at t + h. No output depends
//! directly on an input, and the outputs after initialisation on no command.

use controller_fmu::flight_mission::{ControlError, ParamError, SteppedUnit, UnitLog};
use controller_fmu::Binding;
use state_estimator::{Ekf, Estimate, EstimatorParams, FilterState, Measurements, STATE_WORDS};
use tailsitter_physics::InputVector;

/// Generated from the declaration: `Variables`, `vr`, `GUID`, `MODEL_IDENTIFIER`, `MODEL_DESCRIPTION_XML`.
#[allow(clippy::all)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/variables.rs"));
}
pub use generated::{vr, Variables, GUID, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};

/// The estimator as a co-simulation unit: input the measurements and the commands.
#[derive(Debug, Clone)]
pub struct Estimator(pub Ekf);

impl SteppedUnit for Estimator {
    type Config = EstimatorParams;
    type Input = (Measurements, InputVector);
    type Output = Estimate;

    fn build(params: &EstimatorParams) -> Result<Self, ParamError> {
        Ekf::new(params.clone()).map(Self).map_err(ParamError)
    }

    /// Initialise from the inputs set for the start time: attitude by accelerometer levelling
    /// and magnetometer (TRIAD), position and velocity from a valid GPS fix, motor and servos
    /// at `init_thrust`, `init_elevator`, not at the commands ([`Ekf::initialize`]); logged.
    fn start(&mut self, (m, _): &Self::Input, _t0: f64, log: &mut dyn UnitLog) -> Result<(), ControlError> {
        let r = self.0.initialize(m);
        let tuning = &self.0.params().tuning;
        if !r.from_gps {
            log.warning(format_args!(
                "no valid GPS fix at initialisation: position starts at the reference point (sigma {} m), velocity at rest (sigma {} m/s)",
                tuning.init_std_pos_no_gps, tuning.init_std_vel_no_gps
            ));
        }
        if !r.attitude_from_sensors {
            log.warning(format_args!("accelerometer/magnetometer unusable at initialisation: attitude starts nose up, heading north (sigma 0.5 rad)"));
        } else if (r.accel_ratio - 1.0).abs() > 0.2 {
            log.warning(format_args!(
                "levelling at initialisation with |f|/g = {:.2}: the aircraft accelerates, the initial attitude is poor",
                r.accel_ratio
            ));
        }
        Ok(())
    }

    fn step(&mut self, (m, u): &Self::Input, t: f64, h: f64, log: &mut dyn UnitLog) -> Result<(), ControlError> {
        let rep = self.0.step(m, u, h);
        for r in rep.rejections.iter().flatten() {
            log.warning(format_args!("t = {t} s: {r}"));
        }
        if let Some((from, to)) = rep.gps_restart {
            log.warning(format_args!(
                "t = {t} s: GPS fix counter went back from {from} to {to} (receiver restart): fix used"
            ));
        }
        for (k, what) in ["position", "velocity"].iter().enumerate() {
            if rep.gps_reset[k] {
                log.warning(format_args!(
                    "t = {t} s: {} GPS {what} fixes rejected in a row: {what} reset to the GPS",
                    self.0.params().tuning.gps_reset_after
                ));
            }
        }
        if rep.reverted {
            log.error(format_args!(
                "t = {t} s: the update produced a non-finite estimate and was undone (prediction only)"
            ));
        }
        Ok(())
    }

    fn output(&self) -> Option<Estimate> {
        Some(self.0.estimate())
    }

    fn save(&self, out: &mut impl FnMut(u64)) {
        self.0.state.to_words().iter().for_each(|x| out(x.to_bits()));
    }

    fn restore(&mut self, next: &mut impl FnMut() -> Option<u64>) -> Result<(), ControlError> {
        let mut words = [0.0; STATE_WORDS];
        for x in words.iter_mut() {
            *x = f64::from_bits(next().ok_or_else(|| ControlError("estimator state truncated".into()))?);
        }
        self.0.state =
            FilterState::from_words(&words).ok_or_else(|| ControlError("estimator state: malformed counter".into()))?;
        Ok(())
    }
}

/// The estimator bound to this FMU's variables.
pub struct EkfBinding;

impl Binding for EkfBinding {
    type Unit = Estimator;
    type Vars = Variables;
    const NAME: &'static str = "estimator";

    fn config(v: &Variables) -> Result<EstimatorParams, ParamError> {
        let mut p = v.estimator();
        p.earth.site = v.site();
        p.tuning.gps_reset_after = v.gps_reset_after.max(1) as u32;
        if v.app_d_configuration {
            p = p.app_d();
        }
        // One gravity for the navigation equations and the airframe's motor model.
        p.airframe.gravity = p.earth.gravity;
        Ok(p)
    }

    fn input(v: &Variables, _t: f64) -> (Measurements, InputVector) {
        (v.measurements(), v.commands())
    }

    fn write_output(v: &mut Variables, estimate: &Estimate) {
        v.set_estimate(estimate);
    }
}

/// One estimator instance.
pub type EkfModel = controller_fmu::UnitFmu<EkfBinding>;

fmi2_export::export_fmu!(EkfModel);
// The same model as an FMI 3.0 FMU (fmi3* symbols; dist/fmi3/<id>.fmu).
fmi3_export::export_fmu3!(EkfModel);
