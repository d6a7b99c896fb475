//! `tailsitter_lqr`: the gain-scheduled LQR controller of thesis chapter 3
//! ([`lqr_control::LqrController`]) bound to the generic FMI 2.0 Co-Simulation export
//! layer ([`fmi2_export`]). Only the mapping between FMU variables and the controller
//! lives here; the variables are declared in `modelDescription/tailsitter_lqr.json`.
//!
//! Timing (DESIGN.md §2): the command for the start time is computed in
//! `initialize` (outputs after fmi2ExitInitializationMode hold it); `doStep(t, h)`
//! samples the inputs set for `t` when `t` is a due multiple of `sample_time`
//! ([`SampleClock`]) and holds the command otherwise.

use flight_mission::{ControllerOutput, ControllerPorts, FlightController, SampleClock};
use fmi2_export::{FmuModel, Logger, ModelError, StateError, StateReader, StateWriter};
use lqr_control::{LqrController, LqrParams};
use tailsitter_physics::Airframe;

/// Generated from the declaration: `Variables`, `vr`, `GUID`, `MODEL_IDENTIFIER`, `MODEL_DESCRIPTION_XML`.
#[allow(clippy::all)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/variables.rs"));
}
pub use generated::{vr, Variables, GUID, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};

// The ports of DESIGN.md §2 ↔ the controller's input and output types.
flight_mission::impl_controller_ports!(Variables);

/// Upper bound on the controller values an FMU state may claim (the real count is a few hundred).
const MAX_SAVED_VALUES: usize = 4096;

/// Number of f64s of [`LqrController::save`] (checked when restoring).
fn saved_len(c: &LqrController) -> usize {
    let mut n = 0;
    c.save(&mut |_| n += 1);
    n
}

/// The construction inputs of a controller: rebuilt only when one changes.
#[derive(Debug, Clone, PartialEq)]
struct Config {
    mission: flight_mission::MissionParams,
    params: LqrParams,
    weights_file: String,
}

/// One controller instance.
#[derive(Debug, Clone)]
pub struct LqrModel {
    /// The controller in its freshly constructed state, with the configuration it was
    /// built from (construction builds the trajectory table: done once).
    pristine: Option<(Config, LqrController)>,
    controller: Option<LqrController>,
    clock: SampleClock,
    last: Option<ControllerOutput>,
    /// Controller state read from an FMU state before the controller existed.
    pending: Option<Vec<f64>>,
    /// The previous sample reported a saturation: warn only when one starts.
    saturated: bool,
}

impl LqrModel {
    fn config(vars: &Variables) -> Config {
        Config {
            mission: vars.mission(),
            params: vars.lqr(),
            weights_file: vars.weights_file.clone(),
        }
    }

    /// A fresh controller for the configuration in `vars` (cached).
    fn fresh(&mut self, vars: &Variables) -> Result<LqrController, ModelError> {
        let config = Self::config(vars);
        if let Some((c, ctl)) = &self.pristine {
            if *c == config {
                return Ok(ctl.clone());
            }
        }
        let ctl = if config.weights_file.is_empty() {
            LqrController::new(Airframe::default(), config.mission, config.params.clone())
        } else {
            let json = std::fs::read_to_string(&config.weights_file)
                .map_err(|e| ModelError::new(format!("weights_file {:?}: {e}", config.weights_file)))?;
            LqrController::with_weights_json(Airframe::default(), config.mission, config.params.clone(), &json)
        }
        .map_err(|e| ModelError::new(format!("LQR controller: {e}")))?;
        self.pristine = Some((config, ctl.clone()));
        Ok(ctl)
    }

    fn write_outputs(&self, vars: &mut Variables) {
        if let Some(out) = &self.last {
            vars.write_output(out);
        }
    }

    /// One sample at `t`.
    fn sample(&mut self, vars: &Variables, t: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        let input = vars
            .controller_input(t)
            .map_err(|name| ModelError::new(format!("input {name} is not finite at t = {t} s")))?;
        let controller = self
            .controller
            .as_mut()
            .ok_or_else(|| ModelError::new("controller not initialised"))?;
        let out = controller
            .update(&input)
            .map_err(|e| ModelError::new(format!("LQR at t = {t} s: {e}")))?;
        self.saturated = controller_fmu::log_notice(log, t, out.notice, self.saturated);
        self.last = Some(out);
        Ok(())
    }

    /// Rebuild the controller after an FMU-state restore into an instance without one.
    fn ensure_controller(&mut self, vars: &Variables) -> Result<(), ModelError> {
        // The clock's period is a parameter restored with the variables.
        let next = self.clock.next_index();
        self.clock = SampleClock::new(vars.sample_time, 0.0);
        self.clock.set_next_index(next);
        if let Some(saved) = self.pending.take() {
            let mut c = self.fresh(vars)?;
            let mut it = saved.into_iter();
            c.restore(&mut || it.next())
                .map_err(|e| ModelError::new(format!("restoring the FMU state: {e}")))?;
            self.controller = Some(c);
        }
        Ok(())
    }
}

impl FmuModel for LqrModel {
    type Vars = Variables;
    const MODEL_IDENTIFIER: &'static str = MODEL_IDENTIFIER;
    const GUID: &'static str = GUID;

    fn new(vars: &Variables) -> Self {
        Self {
            pristine: None,
            controller: None,
            clock: SampleClock::new(vars.sample_time.max(1e-9), 0.0),
            last: None,
            pending: None,
            saturated: false,
        }
    }

    fn initialize(&mut self, vars: &mut Variables, start_time: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        // Idempotent: a fresh controller every time, then the sample at the start time.
        self.controller = Some(self.fresh(vars)?);
        self.pending = None;
        self.clock = SampleClock::new(vars.sample_time, start_time);
        self.last = None;
        self.saturated = false;
        let due = self.clock.take(start_time);
        debug_assert!(due);
        self.sample(vars, start_time, log)?;
        self.write_outputs(vars);
        Ok(())
    }

    fn update_outputs(&mut self, vars: &mut Variables) -> Result<(), ModelError> {
        self.ensure_controller(vars)?;
        self.write_outputs(vars);
        Ok(())
    }

    fn do_step(&mut self, vars: &mut Variables, t: f64, _h: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        self.ensure_controller(vars)?;
        if self.clock.take(t) || self.last.is_none() {
            self.sample(vars, t, log)?;
        }
        self.write_outputs(vars);
        Ok(())
    }

    fn write_state(&self, w: &mut StateWriter) {
        w.u64(self.clock.next_index());
        controller_fmu::write_held(w, &self.last);
        match (&self.controller, &self.pending) {
            (Some(c), _) => {
                w.u32(saved_len(c) as u32);
                c.save(&mut |v| w.f64(v));
            }
            (None, Some(p)) => {
                w.u32(p.len() as u32);
                for v in p {
                    w.f64(*v);
                }
            }
            (None, None) => w.u32(0),
        }
    }

    fn read_state(&mut self, r: &mut StateReader<'_>) -> Result<(), StateError> {
        let next_index = r.u64()?;
        let last = controller_fmu::read_held(r)?;
        let n = r.u32()? as usize;
        // The count comes from the buffer: bound it before allocating.
        if n > MAX_SAVED_VALUES {
            return Err(StateError::invalid(format!(
                "LQR state claims {n} values (at most {MAX_SAVED_VALUES})"
            )));
        }
        let mut saved = Vec::with_capacity(n);
        for _ in 0..n {
            saved.push(r.f64()?);
        }
        self.clock.set_next_index(next_index);
        self.last = last;
        if n == 0 {
            self.controller = None;
            self.pending = None;
        } else if let Some(c) = self.controller.as_mut() {
            if n != saved_len(c) {
                return Err(StateError::invalid(format!(
                    "LQR state has {n} values, expected {}",
                    saved_len(c)
                )));
            }
            let mut it = saved.into_iter();
            c.restore(&mut || it.next()).map_err(|e| StateError::invalid(e.0))?;
        } else {
            self.pending = Some(saved);
        }
        Ok(())
    }
}

fmi2_export::export_fmu!(LqrModel);
