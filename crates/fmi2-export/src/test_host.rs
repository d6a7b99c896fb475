//! A recording FMI host logger for tests of FMUs through their C ABI, shared by
//! the export layer's tests and the fuzzer.
//!
//! The FMI logger callback is C-variadic, and defining variadic functions is not
//! stable Rust. The export layer always calls it as
//! `logger(env, name, status, category, "%s", message)`, so the recorder is a
//! plain 6-argument `extern "C"` function transmuted to the variadic pointer type:
//! on x86_64 System V (and AArch64 Linux) a variadic call passes its first
//! variadic pointer argument exactly like a 6th fixed argument. Any other format
//! is recorded as not [`Record::well_formed`].

use crate::fmi_sys::fmi2::{
    fmi2CallbackFunctions, fmi2CallbackLogger, fmi2Component, fmi2ComponentEnvironment, fmi2Status, fmi2Status_fmi2OK,
    fmi2String, fmi2Type_fmi2CoSimulation,
};
use crate::{ffi, FmuModel};
use std::ffi::{c_char, c_void, CStr, CString};
use std::sync::Mutex;

/// One logger call.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    pub instance: String,
    pub status: fmi2Status,
    pub category: String,
    pub message: String,
    /// The format was `"%s"` and the environment our recorder.
    pub well_formed: bool,
}

#[derive(Default)]
pub struct Recorder(pub Mutex<Vec<Record>>);

impl Recorder {
    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<Record>> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// A C string from an FMU as a Rust string; `"(NULL)"` for a null pointer.
///
/// # Safety
/// `p` is null or points to a NUL-terminated string.
pub unsafe fn text(p: *const c_char) -> String {
    if p.is_null() {
        "(NULL)".into()
    } else {
        // SAFETY: non-NULL strings from the FMU are NUL-terminated.
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    }
}

/// The recording logger. Never panics (a panic here would abort: it is called from C).
unsafe extern "C" fn record_log(
    env: fmi2ComponentEnvironment,
    instance_name: fmi2String,
    status: fmi2Status,
    category: fmi2String,
    format: fmi2String,
    arg: *const c_char,
) {
    if env.is_null() {
        return;
    }
    // SAFETY: env is the Recorder we registered; strings are NUL-terminated.
    unsafe {
        let rec = &*(env as *const Recorder);
        let format = text(format);
        let well_formed = format == "%s";
        rec.lock().push(Record {
            instance: text(instance_name),
            status,
            category: text(category),
            message: if well_formed { text(arg) } else { format },
            well_formed,
        });
    }
}

type SixArgs =
    unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, *const c_char);
type Variadic = unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);

/// A host: callbacks whose `componentEnvironment` is a boxed [`Recorder`].
pub struct Host {
    pub recorder: Box<Recorder>,
    pub callbacks: Box<fmi2CallbackFunctions>,
}

impl Default for Host {
    fn default() -> Self {
        Self::new()
    }
}

impl Host {
    pub fn new() -> Self {
        let recorder = Box::new(Recorder::default());
        // SAFETY: the export layer always calls logger(env, name, status, category, "%s", msg):
        // on x86_64 System V / AArch64 Linux the one variadic `const char*` is passed like a
        // sixth fixed argument.
        let logger: fmi2CallbackLogger = Some(unsafe { std::mem::transmute::<SixArgs, Variadic>(record_log) });
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger,
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: &*recorder as *const Recorder as *mut c_void,
        });
        Self { recorder, callbacks }
    }

    pub fn len(&self) -> usize {
        self.recorder.lock().len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn records(&self) -> Vec<Record> {
        self.recorder.lock().clone()
    }

    /// Records from index `from` on.
    pub fn since(&self, from: usize) -> Vec<Record> {
        self.recorder
            .lock()
            .get(from..)
            .map(<[Record]>::to_vec)
            .unwrap_or_default()
    }

    pub fn clear(&self) {
        self.recorder.lock().clear();
    }

    /// Every message; panics if a call did not use the `"%s"` format.
    pub fn messages(&self) -> Vec<String> {
        let records = self.records();
        assert!(
            records.iter().all(|r| r.well_formed),
            "message not passed as the argument of a %s format: {records:?}"
        );
        records.into_iter().map(|r| r.message).collect()
    }

    /// A Co-Simulation instance of `M` (instance name `name`) set up for t = 0 and in
    /// Initialization Mode: the caller sets its parameters, then calls
    /// `ffi::exit_initialization_mode`. Panics if a call fails.
    ///
    /// # Safety
    /// `self` must outlive the instance, which the caller frees with `ffi::free_instance`.
    pub unsafe fn initializing<M: FmuModel>(&self, name: &str) -> fmi2Component {
        let name = CString::new(name).expect("no NUL in the instance name");
        let guid = CString::new(M::GUID).expect("no NUL in the GUID");
        // SAFETY: NUL-terminated strings that live over the call; callbacks in `self`,
        // which outlives the instance (the caller's contract).
        let inst = unsafe {
            ffi::instantiate::<M>(
                name.as_ptr(),
                fmi2Type_fmi2CoSimulation,
                guid.as_ptr(),
                std::ptr::null(),
                &*self.callbacks,
                0,
                0,
            )
        };
        assert!(!inst.is_null(), "fmi2Instantiate failed: {:?}", self.records());
        // SAFETY: a live instance just created.
        unsafe {
            assert_eq!(ffi::setup_experiment::<M>(inst, 0, 0.0, 0.0, 0, 0.0), fmi2Status_fmi2OK);
            assert_eq!(ffi::enter_initialization_mode::<M>(inst), fmi2Status_fmi2OK);
        }
        inst
    }

    /// Whether some message contains every one of `parts`.
    pub fn logged(&self, parts: &[&str]) -> bool {
        self.messages().iter().any(|m| parts.iter().all(|p| m.contains(p)))
    }
}

/// What [`restore_forged`] observed.
#[derive(Debug)]
pub struct ForgedRestore {
    /// fmi2DeSerializeFMUstate of the forged buffer: status and the messages it logged.
    pub deserialize: (fmi2Status, Vec<String>),
    /// fmi2SetFMUstate of a state altered the same way in memory: status and messages.
    pub set_state: (fmi2Status, Vec<String>),
    /// Every Real of the instance bit-identical before and after both calls.
    pub unchanged: bool,
}

/// Restore a state in which the Real variable `name` holds `forged`, the two ways a host
/// can: (1) a serialized state of an initialised instance of `M` whose `name` was set to
/// `marker` (a value that occurs once in the payload), the marker replaced by `forged` and
/// the buffer re-sealed with a valid checksum — what a corrupted store or a fuzzer hands to
/// fmi2DeSerializeFMUstate; (2) that value written into a state from fmi2GetFMUstate,
/// then fmi2SetFMUstate. Panics if the set-up calls fail.
pub fn restore_forged<M: FmuModel>(name: &str, marker: f64, forged: f64) -> ForgedRestore {
    use crate::fmi_sys::fmi2::{fmi2FMUstate, fmi2Status_fmi2OK as OK};
    use crate::{ValueType, VariableStore};
    let spec = M::Vars::VARIABLES
        .iter()
        .find(|s| s.name == name && s.value_type == ValueType::Real)
        .unwrap_or_else(|| panic!("{name} is not a Real of {}", M::MODEL_IDENTIFIER));
    let vr = spec.value_reference;
    let reals: Vec<u32> = M::Vars::VARIABLES
        .iter()
        .filter(|s| s.value_type == ValueType::Real)
        .map(|s| s.value_reference)
        .collect();
    let host = Host::new();
    // SAFETY: the instance lives within this function and `host` outlives it; every
    // pointer passed points to live memory of the stated length.
    unsafe {
        let c = host.initializing::<M>("forged");
        assert_eq!(ffi::set_real::<M>(c, &vr, 1, &marker), OK, "{:?}", host.messages());
        assert_eq!(ffi::exit_initialization_mode::<M>(c), OK, "{:?}", host.messages());
        let mut st: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(ffi::get_fmu_state::<M>(c, &mut st), OK);
        let mut size = 0;
        assert_eq!(ffi::serialized_fmu_state_size::<M>(c, st, &mut size), OK);
        let mut buf = vec![0u8; size];
        assert_eq!(ffi::serialize_fmu_state::<M>(c, st, buf.as_mut_ptr().cast(), size), OK);
        let mut payload = crate::state::open(M::GUID, &buf).expect("own state").to_vec();
        let needle = marker.to_le_bytes();
        let hits: Vec<usize> = (0..payload.len().saturating_sub(7))
            .filter(|&i| payload[i..i + 8] == needle)
            .collect();
        assert_eq!(hits.len(), 1, "marker {marker} must occur once in the payload");
        payload[hits[0]..hits[0] + 8].copy_from_slice(&forged.to_le_bytes());
        let forged_bytes = crate::state::seal(M::GUID, &payload);

        let read = |c| {
            let mut v = vec![0.0; reals.len()];
            assert_eq!(ffi::get_real::<M>(c, reals.as_ptr(), reals.len(), v.as_mut_ptr()), OK);
            v.iter().map(|x: &f64| x.to_bits()).collect::<Vec<u64>>()
        };
        let before = read(c);
        let from = host.len();
        let mut restored: fmi2FMUstate = std::ptr::null_mut();
        let s = ffi::deserialize_fmu_state::<M>(c, forged_bytes.as_ptr().cast(), forged_bytes.len(), &mut restored);
        let deserialize = (s, host.since(from).into_iter().map(|r| r.message).collect());
        if !restored.is_null() {
            assert_eq!(ffi::free_fmu_state::<M>(c, &mut restored), OK);
        }
        let snap = &mut *st.cast::<crate::Snapshot<M>>();
        assert!(snap.vars.set_real(vr, forged));
        let from = host.len();
        let s = ffi::set_fmu_state::<M>(c, st);
        let set_state = (s, host.since(from).into_iter().map(|r| r.message).collect());
        let unchanged = read(c) == before;
        assert_eq!(ffi::free_fmu_state::<M>(c, &mut st), OK);
        ffi::free_instance::<M>(c);
        ForgedRestore {
            deserialize,
            set_state,
            unchanged,
        }
    }
}

/// A model `M` whose start values `set` changes fails `initialize` with an error whose
/// message contains `what`, and a step after the failed initialisation is an error, not a
/// panic.
pub fn assert_initialization_fails<M: FmuModel>(set: impl FnOnce(&mut M::Vars), what: &str) {
    use crate::{Logger, VariableStore};
    let mut v = M::Vars::with_start_values();
    set(&mut v);
    let mut m = M::new(&v);
    let e = m
        .initialize(&mut v, 0.0, &mut Logger::null())
        .err()
        .unwrap_or_else(|| panic!("{what}: initialisation succeeded"));
    assert!(e.message.contains(what), "{what}: {e}");
    assert!(m.do_step(&mut v, 0.0, 0.02, &mut Logger::null()).is_err());
}

/// The FMU state of `m` (variables `v`) taken now continues bit-identically: steps `k` of
/// `steps` (at t = k h, `input(v, k)` set first) give the same `outputs` in a fresh model
/// restored from the written state and the variables saved with it (as
/// fmi2DeSerializeFMUstate does: variables, then model state); every truncation of the
/// state is an error, never a panic.
pub fn assert_state_round_trip<M: FmuModel, O: PartialEq + std::fmt::Debug>(
    m: &mut M,
    v: &mut M::Vars,
    steps: std::ops::Range<usize>,
    h: f64,
    input: impl Fn(&mut M::Vars, usize),
    outputs: impl Fn(&M::Vars) -> O,
) {
    use crate::{Logger, StateReader, StateWriter};
    let mut log = Logger::null();
    let mut w = StateWriter::new();
    m.write_state(&mut w);
    let bytes = w.into_bytes();
    let mut v2 = v.clone();
    let mut reference = Vec::new();
    for k in steps.clone() {
        input(v, k);
        m.do_step(v, k as f64 * h, h, &mut log).unwrap();
        reference.push(outputs(v));
    }
    let mut m2 = M::new(&v2);
    let mut r = StateReader::new(&bytes);
    m2.read_state(&mut r).unwrap();
    r.finish().unwrap();
    for (i, k) in steps.enumerate() {
        input(&mut v2, k);
        m2.do_step(&mut v2, k as f64 * h, h, &mut log).unwrap();
        assert_eq!(outputs(&v2), reference[i], "step {k}");
    }
    for n in 0..bytes.len() {
        let mut m3 = M::new(&v2);
        assert!(m3.read_state(&mut StateReader::new(&bytes[..n])).is_err(), "{n}");
    }
}
