//! A toy model (first-order lag) with a hand-written `VariableStore`, shared by
//! the integration tests, which record the FMI logger with
//! [`fmi2_export::test_host::Host`].
#![allow(dead_code)]

use fmi2_export::{
    Causality, FmuModel, Logger, ModelError, StateError, StateReader, StateWriter, ValueType, Variability,
    VariableSpec, VariableStore,
};
use std::ffi::CString;

pub mod vr {
    pub const U: u32 = 0;
    pub const Y: u32 = 1;
    pub const TAU: u32 = 2;
    pub const GAIN: u32 = 3;
    pub const MODE: u32 = 4;
    pub const ENABLED: u32 = 5;
    pub const LABEL: u32 = 6;
    pub const STEPS: u32 = 7;
    pub const Y0: u32 = 8;
    pub const X0: u32 = 9;
}

#[derive(Debug, Clone, PartialEq)]
pub struct ToyVars {
    pub u: f64,
    pub y: f64,
    pub tau: f64,
    pub gain: f64,
    pub mode: i32,
    pub enabled: bool,
    pub label: String,
    pub steps: i32,
    pub y0: f64,
    pub x0: f64,
}

const fn spec(
    name: &'static str,
    value_reference: u32,
    value_type: ValueType,
    causality: Causality,
    variability: Variability,
    min: f64,
    max: f64,
) -> VariableSpec {
    VariableSpec {
        name,
        value_reference,
        value_type,
        causality,
        variability,
        min,
        max,
        unit: "",
        description: "",
    }
}

const INF: f64 = f64::INFINITY;

impl VariableStore for ToyVars {
    const MODEL_IDENTIFIER: &'static str = "toy";
    const GUID: &'static str = TOY_GUID;
    const VARIABLES: &'static [VariableSpec] = &[
        spec(
            "u",
            0,
            ValueType::Real,
            Causality::Input,
            Variability::Continuous,
            -10.0,
            10.0,
        ),
        spec(
            "y",
            1,
            ValueType::Real,
            Causality::Output,
            Variability::Continuous,
            -INF,
            INF,
        ),
        spec(
            "tau",
            2,
            ValueType::Real,
            Causality::Parameter,
            Variability::Fixed,
            0.01,
            100.0,
        ),
        spec(
            "gain",
            3,
            ValueType::Real,
            Causality::Parameter,
            Variability::Tunable,
            -INF,
            INF,
        ),
        spec(
            "mode",
            4,
            ValueType::Integer,
            Causality::Parameter,
            Variability::Fixed,
            0.0,
            2.0,
        ),
        spec(
            "enabled",
            5,
            ValueType::Boolean,
            Causality::Input,
            Variability::Discrete,
            -INF,
            INF,
        ),
        spec(
            "label",
            6,
            ValueType::String,
            Causality::Parameter,
            Variability::Tunable,
            -INF,
            INF,
        ),
        spec(
            "steps",
            7,
            ValueType::Integer,
            Causality::Output,
            Variability::Discrete,
            -INF,
            INF,
        ),
        spec(
            "y0",
            8,
            ValueType::Real,
            Causality::CalculatedParameter,
            Variability::Fixed,
            -INF,
            INF,
        ),
        spec(
            "x0",
            9,
            ValueType::Real,
            Causality::Parameter,
            Variability::Fixed,
            -INF,
            INF,
        ),
    ];

    fn with_start_values() -> Self {
        Self {
            u: 0.0,
            y: 0.0,
            tau: 1.0,
            gain: 2.0,
            mode: 0,
            enabled: true,
            label: "toy".into(),
            steps: 0,
            y0: 0.0,
            x0: 0.5,
        }
    }

    fn index_of(value_reference: u32) -> Option<usize> {
        let i = value_reference as usize;
        (i < Self::VARIABLES.len()).then_some(i)
    }

    fn get_real(&self, value_reference: u32) -> Option<f64> {
        match value_reference {
            0 => Some(self.u),
            1 => Some(self.y),
            2 => Some(self.tau),
            3 => Some(self.gain),
            8 => Some(self.y0),
            9 => Some(self.x0),
            _ => None,
        }
    }
    fn set_real(&mut self, value_reference: u32, value: f64) -> bool {
        match value_reference {
            0 => self.u = value,
            1 => self.y = value,
            2 => self.tau = value,
            3 => self.gain = value,
            8 => self.y0 = value,
            9 => self.x0 = value,
            _ => return false,
        }
        true
    }
    fn get_integer(&self, value_reference: u32) -> Option<i32> {
        match value_reference {
            4 => Some(self.mode),
            7 => Some(self.steps),
            _ => None,
        }
    }
    fn set_integer(&mut self, value_reference: u32, value: i32) -> bool {
        match value_reference {
            4 => self.mode = value,
            7 => self.steps = value,
            _ => return false,
        }
        true
    }
    fn get_boolean(&self, value_reference: u32) -> Option<bool> {
        (value_reference == 5).then_some(self.enabled)
    }
    fn set_boolean(&mut self, value_reference: u32, value: bool) -> bool {
        if value_reference == 5 {
            self.enabled = value;
        }
        value_reference == 5
    }
    fn get_string(&self, value_reference: u32) -> Option<&str> {
        (value_reference == 6).then_some(self.label.as_str())
    }
    fn set_string(&mut self, value_reference: u32, value: &str) -> bool {
        if value_reference == 6 {
            self.label = value.to_string();
        }
        value_reference == 6
    }

    fn write_state(&self, w: &mut StateWriter) {
        w.f64(self.u);
        w.f64(self.y);
        w.f64(self.tau);
        w.f64(self.gain);
        w.i32(self.mode);
        w.bool(self.enabled);
        w.str(&self.label);
        w.i32(self.steps);
        w.f64(self.y0);
        w.f64(self.x0);
    }
    fn read_state(&mut self, r: &mut StateReader<'_>) -> Result<(), StateError> {
        self.u = r.f64()?;
        self.y = r.f64()?;
        self.tau = r.f64()?;
        self.gain = r.f64()?;
        self.mode = r.i32()?;
        self.enabled = r.bool()?;
        self.label = r.str()?.into();
        self.steps = r.i32()?;
        self.y0 = r.f64()?;
        self.x0 = r.f64()?;
        Ok(())
    }
}

/// First-order lag `tau x' = u - x`, `y = gain x` (0 while disabled).
/// `u > 9.5` makes a step fail; `u == -9.75` makes it panic.
#[derive(Debug, Clone)]
pub struct Toy {
    x: f64,
    /// Counts `update_outputs` calls (observable through the FMU state only).
    pub updates: u64,
}

impl Toy {
    fn outputs(&self, vars: &mut ToyVars) {
        vars.y = if vars.enabled { vars.gain * self.x } else { 0.0 };
    }
}

pub const TOY_GUID: &str = "{11111111-2222-3333-4444-555555555555}";

impl FmuModel for Toy {
    type Vars = ToyVars;
    const MODEL_IDENTIFIER: &'static str = "toy";
    const GUID: &'static str = TOY_GUID;

    fn new(_vars: &ToyVars) -> Self {
        Self { x: 0.0, updates: 0 }
    }

    fn initialize(&mut self, vars: &mut ToyVars, _start_time: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        if vars.mode == 2 {
            return Err(ModelError::new("mode 2 cannot be initialised"));
        }
        self.x = vars.x0;
        vars.steps = 0;
        vars.y0 = vars.gain * vars.x0;
        self.outputs(vars);
        log.info(format!("initialised with x0 = {} %s %n", vars.x0));
        Ok(())
    }

    fn update_outputs(&mut self, vars: &mut ToyVars) -> Result<(), ModelError> {
        self.updates += 1;
        self.outputs(vars);
        Ok(())
    }

    fn do_step(&mut self, vars: &mut ToyVars, t: f64, h: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        if vars.u == -9.75 {
            panic!("toy model panics at t = {t}");
        }
        if vars.u > 9.5 {
            return Err(ModelError::new(format!("input u = {} too large", vars.u)));
        }
        if vars.u > 9.0 {
            log.warning("input u close to its limit");
        }
        self.x += (1.0 - (-h / vars.tau).exp()) * (vars.u - self.x);
        vars.steps += 1;
        self.outputs(vars);
        Ok(())
    }

    fn write_state(&self, w: &mut StateWriter) {
        w.f64(self.x);
        w.u64(self.updates);
    }
    fn read_state(&mut self, r: &mut StateReader<'_>) -> Result<(), StateError> {
        self.x = r.f64()?;
        self.updates = r.u64()?;
        if !self.x.is_finite() {
            return Err(StateError::invalid("toy state x is not finite"));
        }
        Ok(())
    }
}

/// A second model with the same variables but another GUID ("foreign" FMU).
#[derive(Debug, Clone)]
pub struct Other(Toy);

impl FmuModel for Other {
    type Vars = ToyVars;
    const MODEL_IDENTIFIER: &'static str = "other";
    const GUID: &'static str = "{99999999-2222-3333-4444-555555555555}";
    fn new(vars: &ToyVars) -> Self {
        Self(Toy::new(vars))
    }
    fn initialize(&mut self, vars: &mut ToyVars, t: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        self.0.initialize(vars, t, log)
    }
    fn update_outputs(&mut self, vars: &mut ToyVars) -> Result<(), ModelError> {
        self.0.update_outputs(vars)
    }
    fn do_step(&mut self, vars: &mut ToyVars, t: f64, h: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        self.0.do_step(vars, t, h, log)
    }
    fn write_state(&self, w: &mut StateWriter) {
        self.0.write_state(w)
    }
    fn read_state(&mut self, r: &mut StateReader<'_>) -> Result<(), StateError> {
        self.0.read_state(r)
    }
}

// ------------------------------------------------------------------ host side

pub use fmi2_export::test_host::Host;

pub fn cstring(s: &str) -> CString {
    CString::new(s).unwrap()
}
