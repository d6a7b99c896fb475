//! Drive the built FMU libraries (`target/x86_64-unknown-linux-gnu/release/lib<id>.so`,
//! the linux64 libraries `cargo xtask dist` builds and packs) through their real C ABI,
//! the way a foreign host does: `dlopen` with `libloading`, a recording host logger, and
//! thin wrappers that return the raw `fmi2Status`.
//!
//! - [`fuzz`]: random FMI call sequences against a mirror of the state machine
//!   (the short deterministic run is `tests/fuzz.rs`; the long run is the
//!   `fmi-fuzz fuzz` binary, see `scripts/hardening.sh`);
//! - `tests/threads_memory.rs`: 64 concurrent instances vs. sequential, RSS over
//!   10 000 instantiate/free cycles;
//! - `tests/failure.rs`: divergence and garbage-input behaviour;
//! - the `fmi-fuzz cycles` driver for valgrind.
//!
//! The libraries are built by `cargo xtask dist` (scripts/test.sh runs it before
//! `cargo test`); a missing library is a test failure with that hint.
//!
//! Which FMUs are required: all three (`tailsitter_plant`, `tailsitter_lqr`,
//! `tailsitter_tsd`); `TAILSITTER_FMUS=tailsitter_plant,...` narrows the set.

pub mod fuzz;
pub mod progress;

use fmi_sys::fmi2::*;
use libloading::Library;
use model_description::{Causality, VarType, Variability};
use std::ffi::CString;
use std::path::PathBuf;

pub use fmi_sys::fmi2;
/// The variable kinds of the model description, re-exported for the tests.
pub mod model_description_types {
    pub use model_description::{Causality, VarType, Variability};
}

/// Every FMU of the workspace: each model declared in `modelDescription/<id>.json`, plant
/// first, then by identifier (a new unit is fuzzed by its declaration alone).
pub fn all_models() -> Vec<String> {
    let dir = workspace_root().join("modelDescription");
    let mut ids: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok()?.file_name().to_str()?.strip_suffix(".json").map(str::to_string))
        .collect();
    ids.sort_by_key(|id| (id != "tailsitter_plant", id.clone()));
    ids
}

/// The models whose `fmi2DoStep` random inputs make fail (the plant leaves its flight
/// envelope): a fuzz run over at least one of them must reach `StepFailed`. The estimator
/// never fails a step (it rejects a bad measurement and keeps estimating), the sensor
/// model only on an impossible quaternion.
pub const STEP_CAN_FAIL: [&str; 1] = ["tailsitter_plant"];

pub const OK: fmi2Status = fmi2Status_fmi2OK;
pub const WARNING: fmi2Status = fmi2Status_fmi2Warning;
pub const DISCARD: fmi2Status = fmi2Status_fmi2Discard;
pub const ERROR: fmi2Status = fmi2Status_fmi2Error;

/// Readable name of a status.
pub fn status_name(s: fmi2Status) -> &'static str {
    match s {
        0 => "OK",
        1 => "Warning",
        2 => "Discard",
        3 => "Error",
        4 => "Fatal",
        5 => "Pending",
        _ => "?",
    }
}

pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("workspace root")
}

/// The models under test: `TAILSITTER_FMUS` (comma-separated) or [`all_models`].
pub fn required_models() -> Vec<String> {
    match std::env::var("TAILSITTER_FMUS") {
        Ok(list) if !list.trim().is_empty() => list.split(',').map(|s| s.trim().to_string()).collect(),
        _ => all_models(),
    }
}

/// `target/x86_64-unknown-linux-gnu/release/lib<id>.so`, built by `cargo xtask dist` (or
/// `$FMI_FUZZ_LIB_DIR/lib<id>.so`).
pub fn library_path(id: &str) -> PathBuf {
    let dir = std::env::var_os("FMI_FUZZ_LIB_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join("target/x86_64-unknown-linux-gnu/release"));
    dir.join(format!("lib{id}.so"))
}

/// Load every required model, panicking with a clear hint when one is missing.
pub fn load_required() -> Vec<Fmu> {
    required_models()
        .iter()
        .map(|id| Fmu::load(id).unwrap_or_else(|e| panic!("{e}")))
        .collect()
}

// ------------------------------------------------------------------ the C API

macro_rules! api {
    ($($field:ident : $ty:ident = $sym:literal),* $(,)?) => {
        /// Every FMI 2.0 function of one library, resolved at load time.
        pub struct Api {
            $(pub $field: $ty,)*
            _lib: Library,
        }
        impl Api {
            /// # Safety
            /// Loads and runs the initialisers of a shared library.
            unsafe fn load(path: &std::path::Path) -> Result<Self, String> {
                // SAFETY: per the function contract.
                let lib = unsafe { Library::new(path) }.map_err(|e| format!("{}: {e}", path.display()))?;
                $(
                    // SAFETY: the symbol has the FMI 2.0 signature of the fmi-sys type.
                    let $field: $ty = *unsafe { lib.get::<$ty>(concat!($sym, "\0").as_bytes()) }
                        .map_err(|e| format!("{}: symbol {} missing: {e}", path.display(), $sym))?;
                    if $field.is_none() {
                        return Err(format!("{}: symbol {} is NULL", path.display(), $sym));
                    }
                )*
                Ok(Self { $($field,)* _lib: lib })
            }
        }
    };
}

api! {
    get_types_platform: fmi2GetTypesPlatformTYPE = "fmi2GetTypesPlatform",
    get_version: fmi2GetVersionTYPE = "fmi2GetVersion",
    set_debug_logging: fmi2SetDebugLoggingTYPE = "fmi2SetDebugLogging",
    instantiate: fmi2InstantiateTYPE = "fmi2Instantiate",
    free_instance: fmi2FreeInstanceTYPE = "fmi2FreeInstance",
    setup_experiment: fmi2SetupExperimentTYPE = "fmi2SetupExperiment",
    enter_initialization_mode: fmi2EnterInitializationModeTYPE = "fmi2EnterInitializationMode",
    exit_initialization_mode: fmi2ExitInitializationModeTYPE = "fmi2ExitInitializationMode",
    terminate: fmi2TerminateTYPE = "fmi2Terminate",
    reset: fmi2ResetTYPE = "fmi2Reset",
    get_real: fmi2GetRealTYPE = "fmi2GetReal",
    get_integer: fmi2GetIntegerTYPE = "fmi2GetInteger",
    get_boolean: fmi2GetBooleanTYPE = "fmi2GetBoolean",
    get_string: fmi2GetStringTYPE = "fmi2GetString",
    set_real: fmi2SetRealTYPE = "fmi2SetReal",
    set_integer: fmi2SetIntegerTYPE = "fmi2SetInteger",
    set_boolean: fmi2SetBooleanTYPE = "fmi2SetBoolean",
    set_string: fmi2SetStringTYPE = "fmi2SetString",
    get_fmu_state: fmi2GetFMUstateTYPE = "fmi2GetFMUstate",
    set_fmu_state: fmi2SetFMUstateTYPE = "fmi2SetFMUstate",
    free_fmu_state: fmi2FreeFMUstateTYPE = "fmi2FreeFMUstate",
    serialized_fmu_state_size: fmi2SerializedFMUstateSizeTYPE = "fmi2SerializedFMUstateSize",
    serialize_fmu_state: fmi2SerializeFMUstateTYPE = "fmi2SerializeFMUstate",
    deserialize_fmu_state: fmi2DeSerializeFMUstateTYPE = "fmi2DeSerializeFMUstate",
    get_directional_derivative: fmi2GetDirectionalDerivativeTYPE = "fmi2GetDirectionalDerivative",
    set_real_input_derivatives: fmi2SetRealInputDerivativesTYPE = "fmi2SetRealInputDerivatives",
    get_real_output_derivatives: fmi2GetRealOutputDerivativesTYPE = "fmi2GetRealOutputDerivatives",
    do_step: fmi2DoStepTYPE = "fmi2DoStep",
    cancel_step: fmi2CancelStepTYPE = "fmi2CancelStep",
    get_status: fmi2GetStatusTYPE = "fmi2GetStatus",
    get_real_status: fmi2GetRealStatusTYPE = "fmi2GetRealStatus",
    get_integer_status: fmi2GetIntegerStatusTYPE = "fmi2GetIntegerStatus",
    get_boolean_status: fmi2GetBooleanStatusTYPE = "fmi2GetBooleanStatus",
    get_string_status: fmi2GetStringStatusTYPE = "fmi2GetStringStatus",
    enter_event_mode: fmi2EnterEventModeTYPE = "fmi2EnterEventMode",
    new_discrete_states: fmi2NewDiscreteStatesTYPE = "fmi2NewDiscreteStates",
    enter_continuous_time_mode: fmi2EnterContinuousTimeModeTYPE = "fmi2EnterContinuousTimeMode",
    completed_integrator_step: fmi2CompletedIntegratorStepTYPE = "fmi2CompletedIntegratorStep",
    set_time: fmi2SetTimeTYPE = "fmi2SetTime",
    set_continuous_states: fmi2SetContinuousStatesTYPE = "fmi2SetContinuousStates",
    get_derivatives: fmi2GetDerivativesTYPE = "fmi2GetDerivatives",
    get_event_indicators: fmi2GetEventIndicatorsTYPE = "fmi2GetEventIndicators",
    get_continuous_states: fmi2GetContinuousStatesTYPE = "fmi2GetContinuousStates",
    get_nominals_of_continuous_states: fmi2GetNominalsOfContinuousStatesTYPE = "fmi2GetNominalsOfContinuousStates",
}

/// Call a resolved function pointer (checked non-NULL at load time).
#[macro_export]
macro_rules! ffi {
    ($api:expr, $f:ident ( $($arg:expr),* $(,)? )) => {
        ($api.$f.expect(concat!(stringify!($f), " resolved at load time")))($($arg),*)
    };
}

// ------------------------------------------------------------------ model info

/// One variable as the model description declares it.
#[derive(Debug, Clone)]
pub struct Var {
    pub name: String,
    pub vr: u32,
    pub ty: VarType,
    pub causality: Causality,
    pub variability: Variability,
    pub min: f64,
    pub max: f64,
    /// Numeric start value (Real/Integer/Boolean as 0/1), if any.
    pub start: Option<f64>,
}

impl Var {
    /// Settable in `state` (mirror of the export layer's rule).
    pub fn settable(&self, state: St) -> bool {
        match (self.causality, self.variability) {
            (_, Variability::Constant) => false,
            (Causality::Input, _) => true,
            (Causality::Parameter, Variability::Tunable) => true,
            (Causality::Parameter, _) => matches!(state, St::Instantiated | St::InitializationMode),
            _ => false,
        }
    }
}

/// A loaded FMU library plus its model description.
pub struct Fmu {
    pub id: String,
    pub guid: String,
    pub vars: Vec<Var>,
    pub default_step: f64,
    /// Number of continuous states (> 0: the FMU also offers Model Exchange).
    pub n_states: usize,
    pub api: Api,
}

// SAFETY: the library handle and function pointers are immutable after loading;
// the FMI functions themselves are called on distinct instances per thread.
unsafe impl Sync for Fmu {}
unsafe impl Send for Fmu {}

impl Fmu {
    /// Load [`library_path`] and the declaration `modelDescription/<id>.json`.
    pub fn load(id: &str) -> Result<Self, String> {
        let path = library_path(id);
        if !path.exists() {
            return Err(format!(
                "{} missing: build the FMUs first with `cargo xtask dist` (scripts/test.sh does), \
                 or narrow the set with TAILSITTER_FMUS",
                path.display()
            ));
        }
        let model = model_description::load(
            &workspace_root().join("modelDescription"),
            id,
            env!("CARGO_PKG_VERSION"),
        )
        .map_err(|e| format!("declaration of {id}: {e}"))?;
        let vars = model
            .variables
            .iter()
            .map(|v| Var {
                name: v.decl.name.clone(),
                vr: v.value_reference,
                ty: v.decl.var_type,
                causality: v.decl.causality,
                variability: v.variability,
                min: v.decl.min.unwrap_or(f64::NEG_INFINITY),
                max: v.decl.max.unwrap_or(f64::INFINITY),
                start: match &v.decl.start {
                    Some(model_description::Start::Number(x)) => Some(*x),
                    Some(model_description::Start::Bool(b)) => Some(f64::from(u8::from(*b))),
                    _ => None,
                },
            })
            .collect();
        // SAFETY: loading our own FMU library.
        let api = unsafe { Api::load(&path) }?;
        Ok(Self {
            id: id.to_string(),
            guid: model.guid.clone(),
            vars,
            default_step: model.default_experiment.step_size,
            n_states: model.continuous_states().len(),
            api,
        })
    }

    pub fn var(&self, name: &str) -> &Var {
        self.vars
            .iter()
            .find(|v| v.name == name)
            .unwrap_or_else(|| panic!("{}: no variable {name}", self.id))
    }

    pub fn vars_of(&self, ty: VarType) -> impl Iterator<Item = &Var> {
        self.vars.iter().filter(move |v| v.ty == ty)
    }

    pub fn spec(&self, vr: u32, ty: VarType) -> Option<&Var> {
        self.vars.iter().find(|v| v.vr == vr && v.ty == ty)
    }

    /// [`Fmu::instantiate`], panicking with the FMU's logged reason on failure
    /// (typically a GUID mismatch: the library is older than `modelDescription/`).
    pub fn instance(&self, name: &str, logging_on: bool) -> Instance<'_> {
        self.instantiate(name, logging_on).unwrap_or_else(|| {
            let (host, c) = self.instantiate_raw(name, c"", true);
            if !c.is_null() {
                // SAFETY: live component.
                unsafe { ffi!(self.api, free_instance(c)) };
            }
            let why: Vec<String> = host.records().into_iter().map(|r| r.message).collect();
            panic!(
                "{}: fmi2Instantiate failed: {why:?} (rebuild with `cargo xtask dist` if the declaration changed)",
                self.id
            )
        })
    }

    /// Instantiate with this model's GUID and a fresh recording host.
    pub fn instantiate(&self, name: &str, logging_on: bool) -> Option<Instance<'_>> {
        let (host, c) = self.instantiate_raw(name, c"file:///nonexistent", logging_on);
        (!c.is_null()).then_some(Instance { fmu: self, c, host })
    }

    /// fmi2Instantiate (Co-Simulation, this model's GUID) logging into a fresh host; the
    /// component may be NULL. The host owns the callbacks: keep it while the component lives.
    fn instantiate_raw(&self, name: &str, resources: &std::ffi::CStr, logging_on: bool) -> (Host, fmi2Component) {
        let host = Host::new();
        let cname = CString::new(name).expect("no NUL");
        let guid = CString::new(self.guid.as_str()).expect("no NUL");
        // SAFETY: valid arguments; the callbacks are boxed in `host`, returned with the component.
        let c = unsafe {
            ffi!(
                self.api,
                instantiate(
                    cname.as_ptr(),
                    fmi2Type_fmi2CoSimulation,
                    guid.as_ptr(),
                    resources.as_ptr(),
                    &*host.callbacks,
                    0,
                    i32::from(logging_on)
                )
            )
        };
        (host, c)
    }
}

// ------------------------------------------------------------------ host logger

pub use fmi2_export::test_host::{text, Host, Record, Recorder};

// ------------------------------------------------------------------ instances

/// Mirror of the export layer's FMI states.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum St {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    StepCanceled,
    Terminated,
}

impl St {
    pub fn from_code(code: u8) -> Option<Self> {
        Some(match code {
            1 => Self::Instantiated,
            2 => Self::InitializationMode,
            3 => Self::StepComplete,
            5 => Self::StepFailed,
            6 => Self::StepCanceled,
            7 => Self::Terminated,
            _ => return None,
        })
    }
    pub fn name(self) -> &'static str {
        match self {
            Self::Instantiated => "Instantiated",
            Self::InitializationMode => "InitializationMode",
            Self::StepComplete => "StepComplete",
            Self::StepFailed => "StepFailed",
            Self::StepCanceled => "StepCanceled",
            Self::Terminated => "Terminated",
        }
    }
}

/// A live instance with its own host; freed on drop.
pub struct Instance<'a> {
    pub fmu: &'a Fmu,
    pub c: fmi2Component,
    pub host: Host,
}

// SAFETY: an instance is used by one thread at a time (moved, never shared).
unsafe impl Send for Instance<'_> {}

impl Drop for Instance<'_> {
    fn drop(&mut self) {
        // SAFETY: `c` is live and owned.
        unsafe { ffi!(self.fmu.api, free_instance(self.c)) }
    }
}

impl Instance<'_> {
    pub fn setup(&mut self, start: f64, stop: Option<f64>) -> fmi2Status {
        // SAFETY: live instance.
        unsafe {
            ffi!(
                self.fmu.api,
                setup_experiment(self.c, 0, 0.0, start, i32::from(stop.is_some()), stop.unwrap_or(0.0))
            )
        }
    }
    pub fn enter_init(&mut self) -> fmi2Status {
        // SAFETY: live instance.
        unsafe { ffi!(self.fmu.api, enter_initialization_mode(self.c)) }
    }
    pub fn exit_init(&mut self) -> fmi2Status {
        // SAFETY: live instance.
        unsafe { ffi!(self.fmu.api, exit_initialization_mode(self.c)) }
    }
    /// Setup at t = 0, enter and exit initialisation; panics on failure.
    pub fn initialize(&mut self) {
        assert_eq!(
            self.setup(0.0, None),
            OK,
            "{}: setup: {:?}",
            self.fmu.id,
            self.host.records()
        );
        assert_eq!(
            self.enter_init(),
            OK,
            "{}: enter init: {:?}",
            self.fmu.id,
            self.host.records()
        );
        assert_eq!(
            self.exit_init(),
            OK,
            "{}: exit init: {:?}",
            self.fmu.id,
            self.host.records()
        );
    }
    pub fn step(&mut self, t: f64, h: f64) -> fmi2Status {
        // SAFETY: live instance.
        unsafe { ffi!(self.fmu.api, do_step(self.c, t, h, 1)) }
    }
    pub fn reset(&mut self) -> fmi2Status {
        // SAFETY: live instance.
        unsafe { ffi!(self.fmu.api, reset(self.c)) }
    }
    pub fn terminate(&mut self) -> fmi2Status {
        // SAFETY: live instance.
        unsafe { ffi!(self.fmu.api, terminate(self.c)) }
    }
    pub fn set_reals(&mut self, vrs: &[u32], values: &[f64]) -> fmi2Status {
        assert_eq!(vrs.len(), values.len());
        // SAFETY: live instance, arrays of equal length.
        unsafe { ffi!(self.fmu.api, set_real(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr())) }
    }
    pub fn set_integers(&mut self, vrs: &[u32], values: &[i32]) -> fmi2Status {
        assert_eq!(vrs.len(), values.len());
        // SAFETY: live instance, arrays of equal length.
        unsafe {
            ffi!(
                self.fmu.api,
                set_integer(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr())
            )
        }
    }
    /// One fmi2Get{Real,Integer,Boolean} call over `vrs`.
    fn get_values<T: Copy + Default>(
        &mut self,
        vrs: &[u32],
        get: Option<unsafe extern "C" fn(fmi2Component, *const fmi2ValueReference, usize, *mut T) -> fmi2Status>,
    ) -> (fmi2Status, Vec<T>) {
        let mut out = vec![T::default(); vrs.len()];
        let get = get.expect("fmi2Get* resolved at load time");
        // SAFETY: live instance, arrays of equal length.
        let s = unsafe { get(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
        (s, out)
    }
    pub fn get_reals(&mut self, vrs: &[u32]) -> (fmi2Status, Vec<f64>) {
        self.get_values(vrs, self.fmu.api.get_real)
    }
    pub fn get_integers(&mut self, vrs: &[u32]) -> (fmi2Status, Vec<i32>) {
        self.get_values(vrs, self.fmu.api.get_integer)
    }
    pub fn get_booleans(&mut self, vrs: &[u32]) -> (fmi2Status, Vec<i32>) {
        self.get_values(vrs, self.fmu.api.get_boolean)
    }
    pub fn get_strings(&mut self, vrs: &[u32]) -> (fmi2Status, Vec<String>) {
        let mut out = vec![std::ptr::null(); vrs.len()];
        // SAFETY: live instance, arrays of equal length; the returned pointers are read at once.
        unsafe {
            let s = ffi!(
                self.fmu.api,
                get_string(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
            );
            (s, out.iter().map(|p| text(*p)).collect())
        }
    }
    pub fn get_state(&mut self) -> (fmi2Status, fmi2FMUstate) {
        let mut st: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: live instance, valid out pointer.
        let s = unsafe { ffi!(self.fmu.api, get_fmu_state(self.c, &mut st)) };
        (s, st)
    }
    /// `st`: NULL or a state from this model's get/deserialize (the FMU rejects others by tag).
    #[allow(clippy::not_unsafe_ptr_arg_deref)]
    pub fn set_state(&mut self, st: fmi2FMUstate) -> fmi2Status {
        // SAFETY: live instance; `st` is checked by the FMU.
        unsafe { ffi!(self.fmu.api, set_fmu_state(self.c, st)) }
    }
    pub fn free_state(&mut self, st: &mut fmi2FMUstate) -> fmi2Status {
        // SAFETY: live instance, valid pointer to a state handle.
        unsafe { ffi!(self.fmu.api, free_fmu_state(self.c, st)) }
    }
    /// `st`: NULL or a state from this model's get/deserialize (the FMU rejects others by tag).
    #[allow(clippy::not_unsafe_ptr_arg_deref)]
    pub fn serialize(&mut self, st: fmi2FMUstate) -> (fmi2Status, Vec<u8>) {
        let mut size = 0usize;
        // SAFETY: live instance, valid out pointers, buffer of `size` bytes.
        unsafe {
            let s = ffi!(self.fmu.api, serialized_fmu_state_size(self.c, st, &mut size));
            if s != OK {
                return (s, Vec::new());
            }
            let mut buf = vec![0u8; size];
            let s = ffi!(
                self.fmu.api,
                serialize_fmu_state(self.c, st, buf.as_mut_ptr().cast(), size)
            );
            (s, buf)
        }
    }
    pub fn deserialize(&mut self, bytes: &[u8]) -> (fmi2Status, fmi2FMUstate) {
        let mut st: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: live instance, buffer of `len` bytes, valid out pointer.
        let s = unsafe {
            ffi!(
                self.fmu.api,
                deserialize_fmu_state(self.c, bytes.as_ptr().cast(), bytes.len(), &mut st)
            )
        };
        (s, st)
    }
    /// Value references of every Real variable.
    pub fn all_real_vrs(&self) -> Vec<u32> {
        self.fmu.vars_of(VarType::Real).map(|v| v.vr).collect()
    }
    /// Every Real, Integer, Boolean value (Strings as their bytes), as bit patterns.
    pub fn snapshot_bits(&mut self) -> (Vec<fmi2Status>, Vec<u64>) {
        let mut statuses = Vec::new();
        let mut bits = Vec::new();
        let reals: Vec<u32> = self.fmu.vars_of(VarType::Real).map(|v| v.vr).collect();
        let ints: Vec<u32> = self.fmu.vars_of(VarType::Integer).map(|v| v.vr).collect();
        let bools: Vec<u32> = self.fmu.vars_of(VarType::Boolean).map(|v| v.vr).collect();
        let strs: Vec<u32> = self.fmu.vars_of(VarType::String).map(|v| v.vr).collect();
        let (s, r) = self.get_reals(&reals);
        statuses.push(s);
        bits.extend(r.iter().map(|x| x.to_bits()));
        let (s, i) = self.get_integers(&ints);
        statuses.push(s);
        bits.extend(i.iter().map(|x| *x as u64));
        let (s, b) = self.get_booleans(&bools);
        statuses.push(s);
        bits.extend(b.iter().map(|x| *x as u64));
        let (s, t) = self.get_strings(&strs);
        statuses.push(s);
        bits.extend(t.iter().flat_map(|x| x.bytes().map(u64::from)));
        (statuses, bits)
    }
}

// ------------------------------------------------------------------ cycles

/// One full life cycle of an instance: instantiate → initialise → `steps` steps →
/// get, serialize, deserialize and set the FMU state → read everything → free.
/// Returns false on any status other than OK.
pub fn cycle(fmu: &Fmu, steps: usize) -> bool {
    let Some(mut inst) = fmu.instantiate("cycle", false) else {
        return false;
    };
    let mut ok = inst.setup(0.0, None) == OK && inst.enter_init() == OK && inst.exit_init() == OK;
    let h = fmu.default_step;
    for k in 0..steps {
        ok &= inst.step(k as f64 * h, h) == OK;
    }
    ok &= state_round_trip(&mut inst, |inst| inst.snapshot_bits().0.iter().all(|s| *s == OK));
    ok &= inst.terminate() == OK;
    ok
}

/// Get the FMU state, serialize it, deserialize and set the copy, run `then` (its result
/// counts), free both states: true if every status was OK.
fn state_round_trip(inst: &mut Instance<'_>, then: impl FnOnce(&mut Instance<'_>) -> bool) -> bool {
    let (s, mut state) = inst.get_state();
    let mut ok = s == OK;
    let (s, bytes) = inst.serialize(state);
    ok &= s == OK;
    let (s, mut restored) = inst.deserialize(&bytes);
    ok &= s == OK && inst.set_state(restored) == OK;
    ok &= then(inst);
    ok &= inst.free_state(&mut restored) == OK && inst.free_state(&mut state) == OK;
    ok
}

/// The light cycle: instantiate → setup → get/serialize/deserialize/set/free the
/// FMU state → free, without initialisation (the LQR FMU's initialisation builds
/// its trajectory and gains: ~40 ms). Returns false on any status other than OK.
pub fn light_cycle(fmu: &Fmu) -> bool {
    let Some(mut inst) = fmu.instantiate("light", false) else {
        return false;
    };
    let mut ok = inst.setup(0.0, None) == OK;
    ok &= state_round_trip(&mut inst, |_| true);
    ok
}

/// Resident set size of this process (KiB), from /proc/self/status.
pub fn rss_kib() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or(0)
}

// ------------------------------------------------------------------ PRNG

/// xorshift64*: tiny, seeded, deterministic.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    /// Continue from a state as [`Rng::state`] returned it (0 is mapped to 1).
    pub fn from_state(state: u64) -> Self {
        Self(state.max(1))
    }
    /// The current state.
    pub fn state(&self) -> u64 {
        self.0
    }
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in `0..n` (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn pick<'a, T>(&mut self, xs: &'a [T]) -> &'a T {
        &xs[self.below(xs.len())]
    }
    /// Uniform in [lo, hi] for finite bounds, else a "moderate" value.
    pub fn in_range(&mut self, lo: f64, hi: f64) -> f64 {
        let lo = if lo.is_finite() { lo } else { -1e3 };
        let hi = if hi.is_finite() { hi } else { 1e3 };
        lo + (hi - lo) * self.unit()
    }
    /// An interesting f64: specials, extremes, subnormals, or ordinary numbers.
    pub fn wild_f64(&mut self) -> f64 {
        const SPECIAL: [f64; 16] = [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
            0.0,
            -0.0,
            1e300,
            -1e300,
            1e30,
            -1e30,
            1.0,
            -1.0,
        ];
        match self.below(4) {
            0 => *self.pick(&SPECIAL),
            1 => f64::from_bits(self.next_u64()),
            _ => (self.unit() - 0.5) * 10f64.powi(self.below(12) as i32 - 3),
        }
    }
}
