//! `tailsitter_sensors`: the pure-Rust sensor model ([`sensor_model`]) bound to the
//! generic FMI 2.0 Co-Simulation export layer through the one adapter of every
//! co-simulation unit ([`controller_fmu::UnitFmu`]). The variables and their groups
//! (`truth`, `measurements`, `params`, `noise_gains`) are declared in
//! `modelDescription/tailsitter_sensors.json`; timing, state and messages live in
//! `controller-fmu` (docs/DESIGN.md §2, §7).
//!
//! Timing: the start takes every sensor's first sample at the start time from the
//! inputs set then (outputs after fmi2ExitInitializationMode hold them);
//! `doStep(t, h)` takes each sensor's samples due at instants in [t, t + h) from the
//! inputs set for t (held over the step), and the outputs then hold each sensor's
//! latest sample.

use controller_fmu::flight_mission::{ControlError, ParamError, SteppedUnit, UnitLog};
use controller_fmu::Binding;
use sensor_model::{FaultMode, Measurements, Params, SensorModel, State, Truth};

/// Generated from the declaration: `Variables`, `vr`, `GUID`, `MODEL_IDENTIFIER`, `MODEL_DESCRIPTION_XML`.
#[allow(clippy::all)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/variables.rs"));
}
pub use generated::{vr, Variables, GUID, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};

/// The sensor model as a co-simulation unit; outputs the measurements and the
/// filters' noise gains (calculated parameters).
#[derive(Debug, Clone)]
pub struct Sensors {
    model: SensorModel,
    noise_gains: [f64; 4],
}

impl SteppedUnit for Sensors {
    type Config = Params;
    type Input = Truth;
    type Output = (Measurements, [f64; 4]);

    fn build(params: &Params) -> Result<Self, ParamError> {
        let model = SensorModel::new(*params).map_err(|e| ParamError(e.to_string()))?;
        let noise_gains = model.noise_gains();
        Ok(Self { model, noise_gains })
    }

    fn start(&mut self, truth: &Truth, t0: f64, _log: &mut dyn UnitLog) -> Result<(), ControlError> {
        self.model
            .start(truth, t0)
            .map(|_| ())
            .map_err(|e| ControlError(format!("at the start time {t0} s: {e}")))
    }

    fn step(&mut self, truth: &Truth, t: f64, h: f64, log: &mut dyn UnitLog) -> Result<(), ControlError> {
        let (_, held) = self
            .model
            .step_or_hold(truth, t, h)
            .map_err(|e| ControlError(format!("step from t = {t} s: {e}")))?;
        if held {
            log.warning(format_args!(
                "step from t = {t} s: every true-state input is 0 (the zero quaternion included) before any plant sample: \
                 taken as no plant sample yet (a master that starts its connections at 0, e.g. fmpy simulate_ssp); \
                 nothing sampled, the outputs of the start held"
            ));
        }
        Ok(())
    }

    fn output(&self) -> Option<Self::Output> {
        Some((self.model.measurements(), self.noise_gains))
    }

    fn save(&self, out: &mut impl FnMut(u64)) {
        self.model.state().save(out);
    }

    fn restore(&mut self, next: &mut impl FnMut() -> Option<u64>) -> Result<(), ControlError> {
        self.model.set_state(State::restore(next).map_err(ControlError)?);
        Ok(())
    }
}

/// The sensor model bound to this FMU's variables.
pub struct SensorsBinding;

impl Binding for SensorsBinding {
    type Unit = Sensors;
    type Vars = Variables;
    const NAME: &'static str = "sensor model";

    fn config(v: &Variables) -> Result<Params, ParamError> {
        let fault_mode = match v.fault_mode {
            0 => FaultMode::None,
            1 => FaultMode::Stuck,
            2 => FaultMode::Offset,
            other => {
                return Err(ParamError(format!(
                    "fault_mode = {other}: expected 0 (none), 1 (stuck) or 2 (offset)"
                )))
            }
        };
        // Every i32 maps to a distinct 64-bit seed.
        let seed = v.seed as i64 as u64;
        Ok(Params {
            seed,
            fault_mode,
            site: v.site(),
            ..v.params()
        })
    }

    fn input(v: &Variables, _t: f64) -> Truth {
        v.truth()
    }

    fn write_output(v: &mut Variables, (m, noise_gains): &(Measurements, [f64; 4])) {
        v.set_measurements(m);
        // The count wraps like the i32 of FMI after 2³¹ fixes (17 years at 4 Hz).
        v.gps_fix_count = m.gps_fix_count as i32;
        v.set_noise_gains(noise_gains);
    }
}

/// One sensor-model instance.
pub type SensorsModel = controller_fmu::UnitFmu<SensorsBinding>;

fmi2_export::export_fmu!(SensorsModel);
// The same model as an FMI 3.0 FMU (fmi3* symbols; dist/fmi3/<id>.fmu).
fmi3_export::export_fmu3!(SensorsModel);
