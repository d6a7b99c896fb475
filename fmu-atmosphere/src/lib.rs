//! `tailsitter_atmosphere`: the pure-Rust atmosphere ([`atmosphere`]: steady wind
//! profile, Dryden turbulence, 1 − cos gust) bound to the generic FMI 2.0
//! Co-Simulation export layer through the one adapter of every co-simulation unit
//! ([`controller_fmu::UnitFmu`]). The variables and their groups (`inputs`, `wind`,
//! `params`) are declared in `modelDescription/tailsitter_atmosphere.json`; timing,
//! state and messages live in `controller-fmu`.
//!
//! Timing: after fmi2ExitInitializationMode the outputs hold the wind at the start
//! time; `doStep(t, h)` takes the internal turbulence samples at t₀ + k·T ≤ t from
//! the inputs set for t, and the outputs then hold the wind for [t, t + h) (steady
//! wind at the inputs' height, turbulence and gust of the last sample): a master steps the
//! atmosphere before the plant (Gauss-Seidel) or alongside it (Jacobi).

use atmosphere::{Atmosphere, Inputs, Params, State};
use controller_fmu::flight_mission::{ControlError, ParamError, SteppedUnit, UnitLog};
use controller_fmu::Binding;

/// Generated from the declaration: `Variables`, `vr`, `GUID`, `MODEL_IDENTIFIER`, `MODEL_DESCRIPTION_XML`.
#[allow(clippy::all)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/variables.rs"));
}
pub use generated::{vr, Variables, GUID, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};

/// The atmosphere as a co-simulation unit; outputs the NED wind.
#[derive(Debug, Clone)]
pub struct AtmosphereUnit {
    model: Atmosphere,
}

impl AtmosphereUnit {
    /// The model.
    pub fn model(&self) -> &Atmosphere {
        &self.model
    }
}

impl SteppedUnit for AtmosphereUnit {
    type Config = Params;
    type Input = Inputs;
    type Output = [f64; 3];

    fn build(params: &Params) -> Result<Self, ParamError> {
        let model = Atmosphere::new(*params).map_err(|e| ParamError(e.to_string()))?;
        Ok(Self { model })
    }

    fn start(&mut self, inputs: &Inputs, t0: f64, _log: &mut dyn UnitLog) -> Result<(), ControlError> {
        self.model
            .start(inputs, t0)
            .map(|_| ())
            .map_err(|e| ControlError(format!("at the start time {t0} s: {e}")))
    }

    fn step(&mut self, inputs: &Inputs, t: f64, h: f64, _log: &mut dyn UnitLog) -> Result<(), ControlError> {
        self.model
            .step(inputs, t, h)
            .map(|_| ())
            .map_err(|e| ControlError(format!("step from t = {t} s: {e}")))
    }

    fn output(&self) -> Option<[f64; 3]> {
        self.model.state().started.then(|| self.model.wind())
    }

    fn save(&self, out: &mut impl FnMut(u64)) {
        self.model.state().save(out);
    }

    fn restore(&mut self, next: &mut impl FnMut() -> Option<u64>) -> Result<(), ControlError> {
        self.model.set_state(State::restore(next).map_err(ControlError)?);
        Ok(())
    }
}

/// The atmosphere bound to this FMU's variables.
pub struct AtmosphereBinding;

impl Binding for AtmosphereBinding {
    type Unit = AtmosphereUnit;
    type Vars = Variables;
    const NAME: &'static str = "atmosphere";

    fn config(v: &Variables) -> Result<Params, ParamError> {
        Ok(v.params())
    }

    fn input(v: &Variables, _t: f64) -> Inputs {
        v.inputs()
    }

    fn write_output(v: &mut Variables, wind: &[f64; 3]) {
        v.set_wind(wind);
    }
}

/// One atmosphere instance.
pub type AtmosphereModel = controller_fmu::UnitFmu<AtmosphereBinding>;

fmi2_export::export_fmu!(AtmosphereModel);
// The same model as an FMI 3.0 FMU (fmi3* symbols; dist/fmi3/<id>.fmu).
fmi3_export::export_fmu3!(AtmosphereModel);
