//! `tailsitter_lqr`: the gain-scheduled LQR controller of thesis chapter 3
//! ([`lqr_control::LqrController`]) bound to the generic FMI 2.0 Co-Simulation export
//! layer ([`fmi2_export`]). Only the mapping between FMU variables and the controller
//! lives here; the variables are declared in `modelDescription/tailsitter_lqr.json`.
//!
//! Timing (DESIGN.md §2): the command for the start time is computed in
//! `initialize` (outputs after fmi2ExitInitializationMode hold it); `doStep(t, h)`
//! samples the inputs set for `t` when `t` is a due multiple of `sample_time`
//! ([`SampleClock`]) and holds the command otherwise.

use flight_mission::{ControllerInput, ControllerOutput, FlightController, Measurement, Notice, SampleClock};
use fmi2_export::{FmuModel, Logger, ModelError, StateError, StateReader, StateWriter};
use lqr_control::{LqrController, LqrParams};
use nalgebra::{Vector3, Vector4};
use tailsitter_physics::Airframe;

/// Generated from the declaration: `Variables`, `vr`, `GUID`, `MODEL_IDENTIFIER`, `MODEL_DESCRIPTION_XML`.
#[allow(clippy::all)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/variables.rs"));
}
pub use generated::{vr, Variables, GUID, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};

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

    /// The controller input at time `t` from the input variables.
    fn input(vars: &Variables, t: f64) -> Result<ControllerInput, ModelError> {
        let measurement = Measurement {
            pos_ned: Vector3::new(vars.pos_n, vars.pos_e, vars.pos_d),
            vel_ned: Vector3::new(vars.vel_n, vars.vel_e, vars.vel_d),
            vel_body: Vector3::new(vars.u, vars.v, vars.w),
            rates: Vector3::new(vars.p, vars.q, vars.r),
            quat: Vector4::new(vars.quat_1, vars.quat_2, vars.quat_3, vars.quat_4),
            airspeed: vars.airspeed,
            alpha: vars.alpha,
            beta: vars.beta,
            thrust: vars.thrust,
            surfaces: [
                vars.elevator,
                vars.aileron,
                vars.rudder,
                vars.flap_collective,
                vars.flap_differential,
                vars.vertical_flap,
            ],
            specific_force_body: Vector3::new(vars.accel_x, vars.accel_y, vars.accel_z),
            induced_velocity: vars.induced_velocity,
        };
        if let Some(name) = measurement.first_non_finite() {
            return Err(ModelError::new(format!("input {name} is not finite at t = {t} s")));
        }
        let ref_offset_ned = Vector3::new(vars.ref_offset_n, vars.ref_offset_e, vars.ref_offset_d);
        if !ref_offset_ned.iter().all(|x| x.is_finite()) {
            return Err(ModelError::new(format!("ref_offset_n/e/d not finite at t = {t} s")));
        }
        Ok(ControllerInput {
            t,
            measurement,
            ref_offset_ned,
        })
    }

    fn write_outputs(&self, vars: &mut Variables) {
        let Some(out) = &self.last else { return };
        let c = &out.command;
        vars.thrust_cmd = c.thrust;
        vars.elevator_cmd = c.elevator;
        vars.aileron_cmd = c.aileron;
        vars.rudder_cmd = c.rudder;
        vars.flap_collective_cmd = c.flap_collective;
        vars.flap_differential_cmd = c.flap_differential;
        vars.vertical_flap_cmd = c.vertical_flap;
        let d = &out.diagnostics;
        vars.ref_pos_n = d.ref_pos_ned.x;
        vars.ref_pos_e = d.ref_pos_ned.y;
        vars.ref_pos_d = d.ref_pos_ned.z;
        vars.ref_airspeed = d.ref_airspeed;
        vars.phase = d.phase.code();
        vars.pos_error = d.pos_error;
    }

    /// One sample at `t`.
    fn sample(&mut self, vars: &Variables, t: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        let input = Self::input(vars, t)?;
        let controller = self
            .controller
            .as_mut()
            .ok_or_else(|| ModelError::new("controller not initialised"))?;
        let out = controller
            .update(&input)
            .map_err(|e| ModelError::new(format!("LQR at t = {t} s: {e}")))?;
        match out.notice {
            Some(Notice::GainFallback(why)) => log.warning(format_args!(
                "t = {t} s: gain computation failed ({why}); using the last good gains"
            )),
            Some(Notice::Saturated(name)) if !self.saturated => log.warning(format_args!(
                "t = {t} s: {name} saturated (further saturations until it ends are not logged)"
            )),
            _ => {}
        }
        self.saturated = matches!(out.notice, Some(Notice::Saturated(_)));
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
        match &self.last {
            Some(out) => {
                w.bool(true);
                let c = &out.command;
                for v in [
                    c.thrust,
                    c.elevator,
                    c.aileron,
                    c.rudder,
                    c.flap_collective,
                    c.flap_differential,
                    c.vertical_flap,
                ] {
                    w.f64(v);
                }
                let d = &out.diagnostics;
                for v in [
                    d.ref_pos_ned.x,
                    d.ref_pos_ned.y,
                    d.ref_pos_ned.z,
                    d.ref_airspeed,
                    d.pos_error,
                ] {
                    w.f64(v);
                }
                w.i32(d.phase.code());
            }
            None => w.bool(false),
        }
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
        let last = if r.bool()? {
            let mut v = [0.0; 12];
            for x in v.iter_mut() {
                *x = r.f64()?;
            }
            let phase = match r.i32()? {
                0 => flight_mission::Phase::Vertical1,
                1 => flight_mission::Phase::TransitionToLevel,
                2 => flight_mission::Phase::Level,
                3 => flight_mission::Phase::TransitionToVertical,
                4 => flight_mission::Phase::Vertical2,
                p => return Err(StateError::invalid(format!("phase {p} out of range"))),
            };
            Some(ControllerOutput {
                command: flight_mission::Command {
                    thrust: v[0],
                    elevator: v[1],
                    aileron: v[2],
                    rudder: v[3],
                    flap_collective: v[4],
                    flap_differential: v[5],
                    vertical_flap: v[6],
                },
                diagnostics: flight_mission::Diagnostics {
                    ref_pos_ned: Vector3::new(v[7], v[8], v[9]),
                    ref_airspeed: v[10],
                    phase,
                    pos_error: v[11],
                },
                notice: None,
            })
        } else {
            None
        };
        let n = r.u32()? as usize;
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
