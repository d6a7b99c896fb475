//! Random FMI call sequences against a mirror of the export layer's state
//! machine (crates/fmi2-export/README.md).
//!
//! Every call's status is predicted from the mirror and the arguments: exactly
//! where the layer's rules decide (illegal state, bad value reference, range,
//! step arguments, corrupt FMU-state buffers), "OK or Error" where the model
//! decides (initialisation, steps, output computation). Invariants checked:
//! - the status is the predicted one (so every illegal call gives fmi2Error);
//! - every fmi2Error of a live instance is logged, every fmi2Discard too when
//!   warnings are enabled; every log call uses the `"%s"` format, our
//!   environment and the instance name; no message reports a panic;
//! - after each sequence, fmi2Reset gives an instance whose legal run is
//!   bit-identical to a fresh instance's, and a restored FMU state (direct and
//!   serialized) continues bit-identically.
//!
//! A crash or an escaped panic aborts the process, which fails the test.

use crate::*;
use fmi_sys::fmi2::*;
use std::collections::{BTreeMap, BTreeSet};
use std::ffi::{c_char, c_void};
use std::time::Instant;

/// Run limits.
#[derive(Debug, Clone)]
pub struct Config {
    pub seed: u64,
    /// Stop after this many sequences…
    pub sequences: u64,
    /// …or once this many FMI calls were issued (checked between sequences)…
    pub max_total_calls: u64,
    /// …or at this instant, whichever comes first.
    pub deadline: Option<Instant>,
    /// Calls per sequence (uniform in 1..=max_calls).
    pub max_calls: usize,
    /// Optional cap on the sequences of individual FMUs (id → count): expensive
    /// models (the LQR FMU builds its trajectory and gains in every instantiate
    /// and reset) get fewer sequences in the short run.
    pub per_fmu_cap: BTreeMap<String, u64>,
    /// Before each sequence, overwrite this file with the sequence's index, FMU and
    /// seed-state ([`crate::progress`]): after a crash or abort it names the sequence
    /// to replay. `None`: only the in-memory marker the abort handler prints.
    pub progress_file: Option<std::path::PathBuf>,
}

impl Default for Config {
    fn default() -> Self {
        Self {
            seed: 1,
            sequences: 1000,
            max_total_calls: u64::MAX,
            deadline: None,
            max_calls: 40,
            per_fmu_cap: BTreeMap::new(),
            progress_file: None,
        }
    }
}

/// What a run did and found.
#[derive(Debug, Default)]
pub struct Report {
    pub sequences: u64,
    /// FMI calls issued (every exported function call counts one).
    pub calls: u64,
    /// "fmi2Function @ state" → calls per returned status (OK, Warning, Discard, Error).
    pub coverage: BTreeMap<String, [u64; 4]>,
    pub violations: u64,
    /// Violations by kind (FMU + function + a digit-free prefix of the description).
    pub violation_kinds: BTreeMap<String, u64>,
    /// The first violations, described.
    pub first_violations: Vec<String>,
    pub reset_checks: u64,
    pub restore_checks: u64,
    /// Calls slower than 1 s.
    pub slow_calls: Vec<String>,
    /// Per FMU: (sequences, seconds).
    pub per_fmu: BTreeMap<String, (u64, f64)>,
}

impl Report {
    /// (function, state) pairs exercised, and how many distinct (function, state, status) outcomes.
    pub fn coverage_summary(&self) -> (usize, usize) {
        let outcomes = self
            .coverage
            .values()
            .map(|c| c.iter().filter(|n| **n > 0).count())
            .sum();
        (self.coverage.len(), outcomes)
    }

    /// The checks every short test run makes: no invariant violated, every sequence's
    /// reset checked, and more than half of them a state restore.
    pub fn assert_sound(&self) {
        assert_eq!(self.violations, 0, "invariant violations (see output)");
        assert_eq!(self.reset_checks, self.sequences);
        assert!(
            self.restore_checks > self.sequences / 2,
            "restore checks {}",
            self.restore_checks
        );
    }

    /// Every "fmi2Function @ state" of `must` was called at least once.
    pub fn assert_covers(&self, must: &[&str]) {
        for must in must {
            assert!(self.coverage.contains_key(*must), "{must} never exercised");
        }
    }

    pub fn print(&self) {
        let (pairs, outcomes) = self.coverage_summary();
        println!(
            "fmi-fuzz: {} sequences, {} FMI calls, {} reset checks, {} restore checks, {} violations; \
             coverage: {pairs} (function, state) pairs, {outcomes} (function, state, status) outcomes",
            self.sequences, self.calls, self.reset_checks, self.restore_checks, self.violations
        );
        for (id, (n, secs)) in &self.per_fmu {
            println!("  {id}: {n} sequences in {secs:.1} s");
        }
        for (k, n) in &self.violation_kinds {
            println!("  {n:>6} × {k}");
        }
        for v in &self.first_violations {
            println!("  VIOLATION {v}");
        }
        for s in &self.slow_calls {
            println!("  SLOW {s}");
        }
    }

    /// The FMI functions called at least once, and the states they were called in
    /// (from the coverage keys "function @ state").
    pub fn functions_and_states(&self) -> (BTreeSet<String>, BTreeSet<String>) {
        let mut functions = BTreeSet::new();
        let mut states = BTreeSet::new();
        for key in self.coverage.keys() {
            let (f, st) = key.split_once(" @ ").unwrap_or((key, ""));
            if f == "fmi2GetTypesPlatform/Version" {
                functions.insert("fmi2GetTypesPlatform".to_string());
                functions.insert("fmi2GetVersion".to_string());
            } else {
                functions.insert(f.to_string());
            }
            states.insert(st.to_string());
        }
        (functions, states)
    }

    /// One line each: FMI 2.0 functions exercised (and any never called), the states
    /// the calls were made in.
    pub fn print_coverage_summary(&self) {
        let (functions, states) = self.functions_and_states();
        let missing: Vec<&str> = FMI2_FUNCTIONS
            .iter()
            .copied()
            .filter(|f| !functions.contains(*f))
            .collect();
        // FMI states (Co-Simulation, "ME …" Model Exchange) vs. other call contexts
        // (fmi2Instantiate argument variants, foreign components, "any").
        let fmi = |st: &str| {
            let st = st.strip_prefix("ME ").unwrap_or(st);
            matches!(
                st,
                "Instantiated"
                    | "InitializationMode"
                    | "StepComplete"
                    | "StepInProgress"
                    | "StepFailed"
                    | "StepCanceled"
                    | "Terminated"
                    | "EventMode"
                    | "ContinuousTimeMode"
            )
        };
        let (in_states, contexts): (Vec<&String>, Vec<&String>) = states.iter().partition(|s| fmi(s));
        let join = |v: &[&String]| v.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(", ");
        println!(
            "coverage: {} of the {} FMI 2.0 functions called (never: {}); calls in {} FMI states: {}; \
             other call contexts: {}",
            FMI2_FUNCTIONS.len() - missing.len(),
            FMI2_FUNCTIONS.len(),
            if missing.is_empty() {
                "none".to_string()
            } else {
                missing.join(", ")
            },
            in_states.len(),
            join(&in_states),
            join(&contexts)
        );
    }

    pub fn print_coverage(&self) {
        println!(
            "{:<52} {:>9} {:>9} {:>9} {:>9}",
            "function @ state", "OK", "Warning", "Discard", "Error"
        );
        for (k, c) in &self.coverage {
            println!("{k:<52} {:>9} {:>9} {:>9} {:>9}", c[0], c[1], c[2], c[3]);
        }
    }
}

/// Every function of the FMI 2.0 C API (common, Co-Simulation, Model Exchange).
pub const FMI2_FUNCTIONS: [&str; 44] = [
    "fmi2GetTypesPlatform",
    "fmi2GetVersion",
    "fmi2SetDebugLogging",
    "fmi2Instantiate",
    "fmi2FreeInstance",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode",
    "fmi2Terminate",
    "fmi2Reset",
    "fmi2GetReal",
    "fmi2GetInteger",
    "fmi2GetBoolean",
    "fmi2GetString",
    "fmi2SetReal",
    "fmi2SetInteger",
    "fmi2SetBoolean",
    "fmi2SetString",
    "fmi2GetFMUstate",
    "fmi2SetFMUstate",
    "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize",
    "fmi2SerializeFMUstate",
    "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative",
    "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives",
    "fmi2DoStep",
    "fmi2CancelStep",
    "fmi2GetStatus",
    "fmi2GetRealStatus",
    "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus",
    "fmi2GetStringStatus",
    "fmi2EnterEventMode",
    "fmi2NewDiscreteStates",
    "fmi2EnterContinuousTimeMode",
    "fmi2CompletedIntegratorStep",
    "fmi2SetTime",
    "fmi2SetContinuousStates",
    "fmi2GetDerivatives",
    "fmi2GetEventIndicators",
    "fmi2GetContinuousStates",
    "fmi2GetNominalsOfContinuousStates",
];

/// Mirror of the state-machine fields an FMU state captures.
#[derive(Debug, Clone, Copy)]
struct Mirror {
    st: St,
    start: f64,
    time: f64,
    stop: Option<f64>,
    /// The state was captured by (or, re-sealed by the fuzzer, claims) a Model Exchange
    /// instance: a Co-Simulation instance must refuse to restore it.
    model_exchange: bool,
}

impl Mirror {
    fn fresh() -> Self {
        Self {
            st: St::Instantiated,
            start: 0.0,
            time: 0.0,
            stop: None,
            model_exchange: false,
        }
    }
}

/// Expected outcome of a call.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Expect {
    Ok,
    Error,
    Discard,
    /// Decided by the model.
    OkOrError,
}

impl Expect {
    fn admits(self, s: fmi2Status) -> bool {
        match self {
            Expect::Ok => s == OK,
            Expect::Error => s == ERROR,
            Expect::Discard => s == DISCARD,
            Expect::OkOrError => s == OK || s == ERROR,
        }
    }
}

fn legal(st: St, states: &[St]) -> bool {
    states.contains(&st)
}

use St::*;
const SET: &[St] = &[Instantiated, InitializationMode, StepComplete];
const GET: &[St] = &[InitializationMode, StepComplete, StepFailed, StepCanceled, Terminated];
const STATUS: &[St] = &[StepComplete, StepFailed, StepCanceled, Terminated];

/// Serialized-state envelope parts (see crates/fmi2-export/src/state.rs).
struct Envelope {
    /// magic, version, GUID (with length)
    head: Vec<u8>,
    payload: Vec<u8>,
}

fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

fn open(buf: &[u8]) -> Option<Envelope> {
    let glen = u32::from_le_bytes(buf.get(12..16)?.try_into().ok()?) as usize;
    let head_end = 16 + glen;
    let plen = u64::from_le_bytes(buf.get(head_end..head_end + 8)?.try_into().ok()?) as usize;
    let payload = buf.get(head_end + 8..head_end + 8 + plen)?.to_vec();
    Some(Envelope {
        head: buf[..head_end].to_vec(),
        payload,
    })
}

fn seal(head: &[u8], payload: &[u8]) -> Vec<u8> {
    let mut out = head.to_vec();
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(payload);
    let sum = fnv1a64(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

/// The machine fields at the start of a payload (u8 state, f64 start, f64 time,
/// bool+f64 stop, bool+f64 tolerance, bool initialized, bool dirty).
fn machine_of(payload: &[u8]) -> Option<Mirror> {
    let f = |at: usize| {
        payload
            .get(at..at + 8)
            .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
    };
    let st = St::from_code(*payload.first()?)?;
    let start = f(1)?;
    let time = f(9)?;
    let has_stop = *payload.get(17)? == 1;
    let stop = f(18)?;
    // Machine layout (fmi2-export): state u8, start, time, has_stop, stop, has_tolerance,
    // tolerance, initialized, dirty, model_exchange → the flag is byte 37.
    let model_exchange = *payload.get(37)? == 1;
    Some(Mirror {
        st,
        start,
        time,
        stop: has_stop.then_some(stop),
        model_exchange,
    })
}

/// A pointer that is readable but is not an FMU object (random first words).
struct Fake(Box<[u64; 16]>);

impl Fake {
    fn new(rng: &mut Rng) -> Self {
        let mut words = [0u64; 16];
        for w in &mut words {
            *w = rng.next_u64();
        }
        Self(Box::new(words))
    }
    fn ptr(&mut self) -> *mut c_void {
        self.0.as_mut_ptr().cast()
    }
}

/// Long-lived objects of each FMU, used as foreign pointers/buffers for the others.
struct Donor<'a> {
    inst: Instance<'a>,
    state: fmi2FMUstate,
    buffer: Vec<u8>,
}

/// The fuzzer over a set of loaded FMUs.
pub struct Fuzzer<'a> {
    fmus: &'a [Fmu],
    rng: Rng,
    report: Report,
    donors: Vec<Donor<'a>>,
    /// Serialized states per FMU (bytes, mirror at serialization), of the current
    /// sequence only (so that a sequence depends on its seed-state alone).
    banks: Vec<Vec<(Vec<u8>, Mirror)>>,
    /// Index of the current sequence (1-based) and the RNG state it started from.
    seq: u64,
    seq_state: u64,
    /// Print every call, its status and its log records (replay).
    verbose: bool,
    /// The run's `Config::max_calls` (for the replay hint).
    max_calls: usize,
}

/// The RNG state sequence `index` of a run with `seed` starts from: a pure function
/// of both, so that any sequence can be replayed alone (`fmi-fuzz fuzz --replay`).
pub fn sequence_state(seed: u64, index: u64) -> u64 {
    // splitmix64 of (seed, index); never 0 (xorshift's fixed point).
    let mut z = seed ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    (z ^ (z >> 31)) | 1
}

/// The instance under test in one sequence.
struct Live<'a> {
    inst: Instance<'a>,
    m: Mirror,
    /// Warnings/Discards reach the logger.
    warn_log: bool,
    /// enabled[logStatusWarning, logStatusError, logAll]
    cats: [bool; 3],
    name: String,
}

impl<'a> Live<'a> {
    fn new(fmu: &'a Fmu, name: &str, logging_on: bool) -> Self {
        let inst = fmu.instance(name, logging_on);
        Self {
            inst,
            m: Mirror::fresh(),
            warn_log: logging_on,
            cats: [logging_on; 3],
            name: name.to_string(),
        }
    }
}

const CATEGORIES: [&str; 3] = ["logStatusWarning", "logStatusError", "logAll"];

impl<'a> Fuzzer<'a> {
    pub fn new(fmus: &'a [Fmu], seed: u64) -> Self {
        let mut donors = Vec::new();
        for fmu in fmus {
            let mut inst = fmu.instance("donor", false);
            inst.initialize();
            let (s, state) = inst.get_state();
            assert_eq!(s, OK, "{}: donor fmi2GetFMUstate", fmu.id);
            let (s, buffer) = inst.serialize(state);
            assert_eq!(s, OK, "{}: donor serialize", fmu.id);
            donors.push(Donor { inst, state, buffer });
        }
        Self {
            fmus,
            rng: Rng::new(seed),
            report: Report::default(),
            donors,
            banks: fmus.iter().map(|_| Vec::new()).collect(),
            seq: 0,
            seq_state: 0,
            verbose: false,
            max_calls: 0,
        }
    }

    /// Run sequences 1, 2, … of `cfg.seed` until a limit is reached. Sequence `i` starts
    /// from [`sequence_state`]`(seed, i)`: its first draw picks the FMU (a sequence whose
    /// FMU has reached its cap is skipped), the rest drives the calls.
    pub fn run(mut self, cfg: &Config) -> Report {
        let mut progress = crate::progress::Progress::new(cfg.progress_file.as_deref(), cfg.seed, cfg.max_calls);
        self.max_calls = cfg.max_calls;
        let mut index = 0u64;
        while self.report.sequences < cfg.sequences
            && self.report.calls < cfg.max_total_calls
            && cfg.deadline.is_none_or(|d| Instant::now() < d)
        {
            let open = (0..self.fmus.len()).any(|i| !self.capped(cfg, i));
            if !open {
                break;
            }
            index += 1;
            let state = sequence_state(cfg.seed, index);
            self.rng = Rng::from_state(state);
            let f = self.rng.below(self.fmus.len());
            if self.capped(cfg, f) {
                continue;
            }
            self.timed_sequence(&mut progress, index, state, f, cfg.max_calls);
        }
        self.finish(progress)
    }

    /// Run the one sequence that starts from RNG state `state` (as logged by a run, or
    /// [`sequence_state`] of a seed and an index), printing every call, its status and
    /// what the FMU logged.
    pub fn replay(mut self, index: u64, state: u64, max_calls: usize) -> Report {
        self.verbose = true;
        self.max_calls = max_calls;
        self.rng = Rng::from_state(state);
        let f = self.rng.below(self.fmus.len());
        println!(
            "replay: sequence {index}, seed-state {state:#x}, FMU {}",
            self.fmus[f].id
        );
        let mut progress = crate::progress::Progress::new(None, 0, max_calls);
        self.timed_sequence(&mut progress, index, state, f, max_calls);
        self.finish(progress)
    }

    /// Run sequence `index` (RNG already at `state`) on FMU `f`, marking it in `progress`
    /// and adding its count and wall time to the report.
    fn timed_sequence(
        &mut self,
        progress: &mut crate::progress::Progress,
        index: u64,
        state: u64,
        f: usize,
        max_calls: usize,
    ) {
        progress.mark(index, state, &self.fmus[f].id);
        let t0 = Instant::now();
        let id = self.sequence(index, state, f, max_calls);
        let entry = self.report.per_fmu.entry(id).or_default();
        entry.0 += 1;
        entry.1 += t0.elapsed().as_secs_f64();
        self.report.sequences += 1;
    }

    /// Close the progress log, free the donor instances and hand back the report.
    fn finish(mut self, mut progress: crate::progress::Progress) -> Report {
        progress.finish();
        self.free_donors();
        self.report
    }

    fn capped(&self, cfg: &Config, f: usize) -> bool {
        let id = &self.fmus[f].id;
        cfg.per_fmu_cap
            .get(id)
            .is_some_and(|cap| self.report.per_fmu.get(id).map_or(0, |e| e.0) >= *cap)
    }

    fn free_donors(&mut self) {
        for d in &mut self.donors {
            let mut st = d.state;
            assert_eq!(d.inst.free_state(&mut st), OK);
        }
    }

    fn violation(&mut self, fmu: &Fmu, what: String) {
        self.report.violations += 1;
        let kind = if let Some(i) = what.find("internal error (panic)") {
            let func = what.split(':').next().unwrap_or("");
            let msg: String = what[i..].chars().take(60).filter(|c| !c.is_ascii_digit()).collect();
            format!("{func}: {msg}")
        } else {
            what.chars().filter(|c| !c.is_ascii_digit()).take(70).collect()
        };
        *self
            .report
            .violation_kinds
            .entry(format!("{}: {kind}", fmu.id))
            .or_default() += 1;
        if self.report.first_violations.len() < 40 {
            self.report.first_violations.push(format!(
                "[{} seq {} seed-state {:#x}: replay with `fmi-fuzz fuzz --replay {:#x} --max-calls {}`] {what}",
                fmu.id, self.seq, self.seq_state, self.seq_state, self.max_calls
            ));
        }
    }

    /// Record and check one call on the live instance.
    #[allow(clippy::too_many_arguments)]
    fn check(
        &mut self,
        fmu: &Fmu,
        live: &Live<'_>,
        func: &str,
        state: St,
        expect: Expect,
        got: fmi2Status,
        log_from: usize,
        detail: &str,
    ) {
        self.count(func, state.name(), got);
        let new = live.inst.host.since(log_from);
        if self.verbose {
            println!("    {detail} → expected {expect:?}");
            for r in &new {
                println!("      log [{}] {}", status_name(r.status), r.message);
            }
        }
        if !expect.admits(got) {
            self.violation(
                fmu,
                format!(
                    "{func} in {} ({detail}): expected {expect:?}, got {}; log: {:?}",
                    state.name(),
                    status_name(got),
                    new.iter().map(|r| &r.message).collect::<Vec<_>>()
                ),
            );
        }
        if got == ERROR && !new.iter().any(|r| r.status == ERROR) {
            self.violation(
                fmu,
                format!(
                    "{func} in {} ({detail}) returned fmi2Error without logging",
                    state.name()
                ),
            );
        }
        if got == DISCARD && live.warn_log && !new.iter().any(|r| r.status == DISCARD) {
            self.violation(
                fmu,
                format!(
                    "{func} in {} ({detail}) returned fmi2Discard without logging",
                    state.name()
                ),
            );
        }
        for r in &new {
            if !r.well_formed || r.instance != live.name || r.message.contains("panic") {
                self.violation(fmu, format!("{func}: bad log record {r:?}"));
            }
        }
    }

    fn count(&mut self, func: &str, state: &str, got: fmi2Status) {
        self.report.calls += 1;
        if self.verbose {
            println!("  {func} @ {state}: {}", status_name(got));
        }
        let slot = self.report.coverage.entry(format!("{func} @ {state}")).or_default();
        if let Some(n) = slot.get_mut(got as usize) {
            *n += 1;
        }
    }

    fn foreign_donor(&mut self, me: usize) -> Option<usize> {
        let others: Vec<usize> = (0..self.fmus.len()).filter(|&i| i != me).collect();
        (!others.is_empty()).then(|| *self.rng.pick(&others))
    }

    /// One random sequence on FMU `f`; returns its id.
    fn sequence(&mut self, index: u64, state: u64, f: usize, max_calls: usize) -> String {
        self.seq = index;
        self.seq_state = state;
        for bank in &mut self.banks {
            bank.clear();
        }
        let fmu: &'a Fmu = &self.fmus[f];
        let logging_on = self.rng.chance(0.5);
        let mut live = Live::new(fmu, &format!("fuzz{}", self.seq), logging_on);
        let mut states: Vec<(fmi2FMUstate, Mirror)> = Vec::new();
        let mut fake = Fake::new(&mut self.rng);
        let n = 1 + self.rng.below(max_calls);
        for _ in 0..n {
            let t0 = Instant::now();
            let op = self.rng.below(100);
            if self.verbose {
                println!("op {op}:");
            }
            self.op(op, f, fmu, &mut live, &mut states, &mut fake);
            let dt = t0.elapsed().as_secs_f64();
            if dt > 1.0 && self.report.slow_calls.len() < 20 {
                self.report.slow_calls.push(format!("{} op {op}: {dt:.1} s", fmu.id));
            }
        }
        // Reset → a legal run must match a fresh instance bit for bit.
        let from = live.inst.host.len();
        let s = live.inst.reset();
        self.check(
            fmu,
            &live,
            "fmi2Reset",
            live.m.st,
            Expect::Ok,
            s,
            from,
            "end of sequence",
        );
        live.m = Mirror::fresh();
        let seed = self.rng.next_u64();
        let after_reset = canonical_run(&mut live.inst, seed);
        let mut fresh = fmu.instance("fresh", false);
        let fresh_run = canonical_run(&mut fresh, seed);
        self.report.reset_checks += 1;
        if after_reset.trace != fresh_run.trace {
            let k = after_reset.trace.iter().zip(&fresh_run.trace).position(|(a, b)| a != b);
            self.violation(
                fmu,
                format!("run after fmi2Reset differs from a fresh instance (first at {k:?})"),
            );
        }
        for problem in after_reset.problems.iter().chain(&fresh_run.problems) {
            self.violation(fmu, problem.clone());
        }
        if after_reset.restore_checked {
            self.report.restore_checks += 1;
        }
        for (mut st, _) in states.drain(..) {
            let from = live.inst.host.len();
            let s = live.inst.free_state(&mut st);
            self.check(
                fmu,
                &live,
                "fmi2FreeFMUstate",
                live.m.st,
                Expect::Ok,
                s,
                from,
                "cleanup",
            );
        }
        fmu.id.clone()
    }

    #[allow(clippy::too_many_lines)]
    fn op(
        &mut self,
        op: usize,
        f: usize,
        fmu: &'a Fmu,
        live: &mut Live<'a>,
        states: &mut Vec<(fmi2FMUstate, Mirror)>,
        fake: &mut Fake,
    ) {
        let api = &fmu.api;
        let st = live.m.st;
        let c = live.inst.c;
        let from = live.inst.host.len();
        match op {
            // ---- lifecycle
            0..=3 => {
                let tol_defined = self.rng.chance(0.3);
                let tol = *self.rng.pick(&[1e-6, 0.0, -1.0, f64::NAN, f64::INFINITY, 5e-324]);
                let start = *self.rng.pick(&[
                    0.0,
                    0.0,
                    0.0,
                    1.5,
                    -3.0,
                    1e300,
                    f64::NAN,
                    f64::INFINITY,
                    5e-324,
                    f64::MAX,
                ]);
                let stop_defined = self.rng.chance(0.4);
                let stop = *self.rng.pick(&[
                    start + 10.0,
                    start + 0.05,
                    start,
                    start - 1.0,
                    f64::NAN,
                    f64::INFINITY,
                    1e300,
                ]);
                let valid = start.is_finite()
                    && (!stop_defined || (stop.is_finite() && stop >= start))
                    && (!tol_defined || (tol.is_finite() && tol > 0.0));
                let expect = if legal(st, &[Instantiated]) && valid {
                    Expect::Ok
                } else {
                    Expect::Error
                };
                // SAFETY: live instance.
                let s = unsafe {
                    ffi!(
                        api,
                        setup_experiment(c, i32::from(tol_defined), tol, start, i32::from(stop_defined), stop)
                    )
                };
                let detail = format!("tol {tol_defined}/{tol}, start {start}, stop {stop_defined}/{stop}");
                self.check(fmu, live, "fmi2SetupExperiment", st, expect, s, from, &detail);
                if s == OK {
                    live.m.start = start;
                    live.m.time = start;
                    live.m.stop = stop_defined.then_some(stop);
                }
            }
            4..=6 => {
                let expect = if st == Instantiated { Expect::Ok } else { Expect::Error };
                // SAFETY: live instance.
                let s = unsafe { ffi!(api, enter_initialization_mode(c)) };
                self.check(fmu, live, "fmi2EnterInitializationMode", st, expect, s, from, "");
                if s == OK {
                    live.m.st = InitializationMode;
                }
            }
            7..=9 => {
                let expect = if st == InitializationMode {
                    Expect::OkOrError
                } else {
                    Expect::Error
                };
                // SAFETY: live instance.
                let s = unsafe { ffi!(api, exit_initialization_mode(c)) };
                self.check(fmu, live, "fmi2ExitInitializationMode", st, expect, s, from, "");
                if s == OK {
                    live.m.st = StepComplete;
                }
            }
            10 => {
                let expect = if legal(st, &[StepComplete, StepFailed]) {
                    Expect::Ok
                } else {
                    Expect::Error
                };
                // SAFETY: live instance.
                let s = unsafe { ffi!(api, terminate(c)) };
                self.check(fmu, live, "fmi2Terminate", st, expect, s, from, "");
                if s == OK {
                    live.m.st = Terminated;
                }
            }
            11 => {
                // SAFETY: live instance.
                let s = unsafe { ffi!(api, reset(c)) };
                self.check(fmu, live, "fmi2Reset", st, Expect::Ok, s, from, "");
                live.m = Mirror::fresh();
            }
            12 => {
                let on = self.rng.chance(0.5);
                let pool = ["logStatusWarning", "logStatusError", "logAll", "bogusCategory", ""];
                let k = self.rng.below(3);
                let names: Vec<&str> = (0..k).map(|_| *self.rng.pick(&pool)).collect();
                let cstrs: Vec<CString> = names.iter().map(|n| CString::new(*n).expect("no NUL")).collect();
                let mut ptrs: Vec<*const c_char> = cstrs.iter().map(|s| s.as_ptr()).collect();
                let null_name = !ptrs.is_empty() && self.rng.chance(0.1);
                if null_name {
                    ptrs[0] = std::ptr::null();
                }
                let valid = !null_name && names.iter().all(|n| CATEGORIES.contains(n));
                // SAFETY: live instance, array of `len` string pointers.
                let s = unsafe { ffi!(api, set_debug_logging(c, i32::from(on), ptrs.len(), ptrs.as_ptr())) };
                let expect = if valid { Expect::Ok } else { Expect::Error };
                self.check(
                    fmu,
                    live,
                    "fmi2SetDebugLogging",
                    st,
                    expect,
                    s,
                    from,
                    &format!("{on} {names:?}"),
                );
                if s == OK {
                    if names.is_empty() {
                        live.cats = [on; 3];
                    }
                    for n in &names {
                        let i = CATEGORIES.iter().position(|x| x == n).expect("valid");
                        live.cats[i] = on;
                    }
                    live.warn_log = live.cats[0] || live.cats[2];
                }
            }
            // ---- values
            13..=30 => self.op_set(fmu, live, from),
            31..=44 => self.op_get(fmu, live, from),
            45..=62 => self.op_step(fmu, live, from),
            63 => {
                // SAFETY: live instance.
                let s = unsafe { ffi!(api, cancel_step(c)) };
                self.check(fmu, live, "fmi2CancelStep", st, Expect::Error, s, from, "");
            }
            64..=67 => self.op_status(fmu, live, from),
            // ---- FMU state
            68..=71 => {
                let variant = self.rng.below(6);
                let mut label = "new";
                let (s, expect) = match variant {
                    0 => {
                        label = "NULL out pointer";
                        // SAFETY: NULL is rejected.
                        (
                            unsafe { ffi!(api, get_fmu_state(c, std::ptr::null_mut())) },
                            Expect::Error,
                        )
                    }
                    1 if !states.is_empty() => {
                        label = "reuse own";
                        let i = self.rng.below(states.len());
                        // SAFETY: live instance, own state slot.
                        let s = unsafe { ffi!(api, get_fmu_state(c, &mut states[i].0)) };
                        if s == OK {
                            states[i].1 = live.m;
                        }
                        (s, Expect::Ok)
                    }
                    2 => {
                        label = "reuse foreign/fake";
                        let mut p = match self.foreign_donor(f) {
                            Some(d) if self.rng.chance(0.5) => self.donors[d].state,
                            _ => fake.ptr(),
                        };
                        // SAFETY: `p` is readable; the FMU checks its tag.
                        (unsafe { ffi!(api, get_fmu_state(c, &mut p)) }, Expect::Error)
                    }
                    _ => {
                        let mut p: fmi2FMUstate = std::ptr::null_mut();
                        // SAFETY: live instance.
                        let s = unsafe { ffi!(api, get_fmu_state(c, &mut p)) };
                        if s == OK {
                            states.push((p, live.m));
                        }
                        (s, Expect::Ok)
                    }
                };
                self.check(fmu, live, "fmi2GetFMUstate", st, expect, s, from, label);
            }
            72..=75 => {
                let (p, expect, restored, label) = match self.rng.below(6) {
                    0 => (std::ptr::null_mut(), Expect::Error, None, "NULL"),
                    1 => match self.foreign_donor(f) {
                        Some(d) => (self.donors[d].state, Expect::Error, None, "foreign"),
                        None => (fake.ptr(), Expect::Error, None, "fake"),
                    },
                    2 => (fake.ptr(), Expect::Error, None, "fake"),
                    _ if !states.is_empty() => {
                        let (p, m) = *self.rng.pick(states);
                        if m.model_exchange {
                            // Only re-sealed, mutated buffers get here (the fuzzer's CS
                            // instances capture CS states): another interface's state.
                            (p, Expect::Error, None, "own, Model Exchange flag")
                        } else {
                            (p, Expect::Ok, Some(m), "own")
                        }
                    }
                    _ => (
                        self.donors[f].state,
                        Expect::Ok,
                        Some(donor_mirror()),
                        "donor of the same FMU",
                    ),
                };
                // SAFETY: live instance; `p` NULL, readable fake, or an FMU state.
                let s = unsafe { ffi!(api, set_fmu_state(c, p)) };
                self.check(fmu, live, "fmi2SetFMUstate", st, expect, s, from, label);
                if let (OK, Some(m)) = (s, restored) {
                    live.m = m;
                }
            }
            76..=77 => {
                let (s, expect, label) = match self.rng.below(5) {
                    0 => {
                        let mut p: fmi2FMUstate = std::ptr::null_mut();
                        // SAFETY: pointer to NULL: a no-op.
                        (unsafe { ffi!(api, free_fmu_state(c, &mut p)) }, Expect::Ok, "&NULL")
                    }
                    1 => {
                        // SAFETY: NULL: a no-op.
                        (
                            unsafe { ffi!(api, free_fmu_state(c, std::ptr::null_mut())) },
                            Expect::Ok,
                            "NULL",
                        )
                    }
                    2 => {
                        let mut p = match self.foreign_donor(f) {
                            Some(d) => self.donors[d].state,
                            None => fake.ptr(),
                        };
                        // SAFETY: readable pointer; refused by tag.
                        (
                            unsafe { ffi!(api, free_fmu_state(c, &mut p)) },
                            Expect::Error,
                            "foreign/fake",
                        )
                    }
                    _ if !states.is_empty() => {
                        let i = self.rng.below(states.len());
                        let (mut p, _) = states.swap_remove(i);
                        // SAFETY: own live state, removed from the pool.
                        let s = unsafe { ffi!(api, free_fmu_state(c, &mut p)) };
                        if !p.is_null() {
                            self.violation(fmu, "fmi2FreeFMUstate did not set *state = NULL".into());
                        }
                        (s, Expect::Ok, "own")
                    }
                    _ => {
                        let mut p: fmi2FMUstate = std::ptr::null_mut();
                        // SAFETY: pointer to NULL.
                        (unsafe { ffi!(api, free_fmu_state(c, &mut p)) }, Expect::Ok, "&NULL")
                    }
                };
                self.check(fmu, live, "fmi2FreeFMUstate", st, expect, s, from, label);
            }
            78..=81 => self.op_serialize(f, fmu, live, states, fake, from),
            82..=87 => self.op_deserialize(f, fmu, live, states, from),
            // ---- unsupported functions
            88..=89 => {
                let which = self.rng.below(13);
                let mut flag: fmi2Boolean = 0;
                let mut buf = [0.0f64; 4];
                let vrs = [0u32; 4];
                let order = [1i32; 4];
                // SAFETY: live instance; arrays of 4 elements; these functions only refuse.
                let (name, s) = unsafe {
                    match which {
                        0 => (
                            "fmi2GetDirectionalDerivative",
                            ffi!(
                                api,
                                get_directional_derivative(
                                    c,
                                    vrs.as_ptr(),
                                    1,
                                    vrs.as_ptr(),
                                    1,
                                    buf.as_ptr(),
                                    buf.as_mut_ptr()
                                )
                            ),
                        ),
                        1 => (
                            "fmi2SetRealInputDerivatives",
                            ffi!(
                                api,
                                set_real_input_derivatives(c, vrs.as_ptr(), 1, order.as_ptr(), buf.as_ptr())
                            ),
                        ),
                        2 => (
                            "fmi2GetRealOutputDerivatives",
                            ffi!(
                                api,
                                get_real_output_derivatives(c, vrs.as_ptr(), 1, order.as_ptr(), buf.as_mut_ptr())
                            ),
                        ),
                        3 => ("fmi2EnterEventMode", ffi!(api, enter_event_mode(c))),
                        4 => (
                            "fmi2NewDiscreteStates",
                            ffi!(api, new_discrete_states(c, std::ptr::null_mut())),
                        ),
                        5 => ("fmi2EnterContinuousTimeMode", ffi!(api, enter_continuous_time_mode(c))),
                        6 => (
                            "fmi2CompletedIntegratorStep",
                            ffi!(api, completed_integrator_step(c, 1, &mut flag, &mut flag)),
                        ),
                        7 => ("fmi2SetTime", ffi!(api, set_time(c, 1.0))),
                        8 => (
                            "fmi2SetContinuousStates",
                            ffi!(api, set_continuous_states(c, buf.as_ptr(), 4)),
                        ),
                        9 => ("fmi2GetDerivatives", ffi!(api, get_derivatives(c, buf.as_mut_ptr(), 4))),
                        10 => (
                            "fmi2GetEventIndicators",
                            ffi!(api, get_event_indicators(c, buf.as_mut_ptr(), 4)),
                        ),
                        11 => (
                            "fmi2GetContinuousStates",
                            ffi!(api, get_continuous_states(c, buf.as_mut_ptr(), 4)),
                        ),
                        _ => (
                            "fmi2GetNominalsOfContinuousStates",
                            ffi!(api, get_nominals_of_continuous_states(c, buf.as_mut_ptr(), 4)),
                        ),
                    }
                };
                self.check(fmu, live, name, st, Expect::Error, s, from, "unsupported");
            }
            // ---- other instances, foreign and NULL components
            90..=91 => self.op_instantiate(fmu),
            92 => {
                // Free the instance under test and start over with a new one (FMU states survive).
                let logging_on = self.rng.chance(0.5);
                let name = format!("fuzz{}b", self.seq);
                *live = Live::new(fmu, &name, logging_on);
            }
            93..=96 => {
                let target: fmi2Component = match self.rng.below(3) {
                    0 => std::ptr::null_mut(),
                    1 => fake.ptr(),
                    _ => match self.foreign_donor(f) {
                        Some(d) => self.donors[d].inst.c,
                        None => fake.ptr(),
                    },
                };
                let donors_before: Vec<usize> = self.donors.iter().map(|d| d.inst.host.len()).collect();
                let mut x = [0.0f64; 2];
                let vrs = [0u32, 1];
                let mut stt: fmi2FMUstate = std::ptr::null_mut();
                // SAFETY: NULL, a readable fake, or another model's component: all refused by tag.
                let (name, s) = unsafe {
                    match self.rng.below(8) {
                        0 => ("fmi2DoStep", ffi!(api, do_step(target, 0.0, 0.02, 1))),
                        1 => (
                            "fmi2GetReal",
                            ffi!(api, get_real(target, vrs.as_ptr(), 2, x.as_mut_ptr())),
                        ),
                        2 => ("fmi2SetReal", ffi!(api, set_real(target, vrs.as_ptr(), 2, x.as_ptr()))),
                        3 => ("fmi2Reset", ffi!(api, reset(target))),
                        4 => ("fmi2GetFMUstate", ffi!(api, get_fmu_state(target, &mut stt))),
                        5 => (
                            "fmi2SetDebugLogging",
                            ffi!(api, set_debug_logging(target, 1, 0, std::ptr::null())),
                        ),
                        6 => ("fmi2Terminate", ffi!(api, terminate(target))),
                        _ => {
                            ffi!(api, free_instance(target));
                            ("fmi2FreeInstance", ERROR)
                        }
                    }
                };
                self.count(name, "foreign component", s);
                if s != ERROR || !stt.is_null() {
                    self.violation(
                        fmu,
                        format!("{name} on a foreign/NULL component returned {}", status_name(s)),
                    );
                }
                let donors_after: Vec<usize> = self.donors.iter().map(|d| d.inst.host.len()).collect();
                if donors_before != donors_after {
                    self.violation(
                        fmu,
                        format!("{name} on a foreign component reached that component's logger"),
                    );
                }
            }
            _ => {
                // SAFETY: plain getters.
                let (tp, v) = unsafe { (text(ffi!(api, get_types_platform())), text(ffi!(api, get_version()))) };
                self.count("fmi2GetTypesPlatform/Version", "any", OK);
                if tp != "default" || v != "2.0" {
                    self.violation(fmu, format!("types platform {tp:?}, version {v:?}"));
                }
            }
        }
    }

    /// A value reference: mostly valid for `ty`, sometimes another type's or unknown.
    fn pick_vr(&mut self, fmu: &Fmu, ty: VarType, settable_bias: bool) -> u32 {
        let of_type: Vec<&Var> = fmu.vars_of(ty).collect();
        let inputs: Vec<&Var> = of_type
            .iter()
            .copied()
            .filter(|v| matches!(v.causality, Causality::Input | Causality::Parameter))
            .collect();
        match self.rng.below(10) {
            0 => *self
                .rng
                .pick(&[u32::MAX, 1_000_000, fmu.vars.len() as u32, 0x8000_0000]),
            1 => self.rng.pick(&fmu.vars).vr,
            2..=5 if settable_bias && !inputs.is_empty() => self.rng.pick(&inputs).vr,
            _ if !of_type.is_empty() => self.rng.pick(&of_type).vr,
            _ => self.rng.next_u64() as u32,
        }
    }

    /// The arguments of a set/get call: a type (Real three times as likely), fewer than
    /// `max_n` value references of it ([`Self::pick_vr`]), and whether to pass NULL arrays
    /// instead (5 % of non-empty calls).
    fn pick_access(&mut self, fmu: &Fmu, max_n: usize, settable_bias: bool) -> (VarType, Vec<u32>, bool) {
        let ty = *self.rng.pick(&[
            VarType::Real,
            VarType::Real,
            VarType::Real,
            VarType::Integer,
            VarType::Boolean,
            VarType::String,
        ]);
        let n = self.rng.below(max_n);
        let vrs: Vec<u32> = (0..n).map(|_| self.pick_vr(fmu, ty, settable_bias)).collect();
        let null_arrays = n > 0 && self.rng.chance(0.05);
        (ty, vrs, null_arrays)
    }

    fn op_set(&mut self, fmu: &Fmu, live: &mut Live<'_>, from: usize) {
        let api = &fmu.api;
        let c = live.inst.c;
        let st = live.m.st;
        let (ty, vrs, null_arrays) = self.pick_access(fmu, 5, true);
        let n = vrs.len();
        // Expected outcome from the layer's rules.
        let mut ok = legal(st, SET) && !null_arrays;
        let (s, detail) = match ty {
            VarType::Real => {
                let values: Vec<f64> = vrs
                    .iter()
                    .map(|vr| match (self.rng.below(3), fmu.spec(*vr, ty)) {
                        (0, _) => self.rng.wild_f64(),
                        (1, Some(v)) => v.start.unwrap_or(0.0),
                        (_, Some(v)) => self.rng.in_range(v.min, v.max),
                        (_, None) => self.rng.wild_f64(),
                    })
                    .collect();
                for (vr, x) in vrs.iter().zip(&values) {
                    ok &= fmu
                        .spec(*vr, ty)
                        .is_some_and(|v| v.settable(st) && x.is_finite() && *x >= v.min && *x <= v.max);
                }
                let (pv, px) = if null_arrays {
                    (std::ptr::null(), std::ptr::null())
                } else {
                    (vrs.as_ptr(), values.as_ptr())
                };
                // SAFETY: arrays of n elements (or NULL, refused).
                (
                    unsafe { ffi!(api, set_real(c, pv, n, px)) },
                    format!("{vrs:?} = {values:?}"),
                )
            }
            VarType::Integer => {
                let values: Vec<i32> = vrs
                    .iter()
                    .map(|vr| match (self.rng.below(3), fmu.spec(*vr, ty)) {
                        (0, _) => *self.rng.pick(&[i32::MIN, i32::MAX, -1, 0, 1, 2, 7]),
                        (_, Some(v)) => self.rng.in_range(v.min.max(-1e6), v.max.min(1e6)).round() as i32,
                        (_, None) => self.rng.next_u64() as i32,
                    })
                    .collect();
                for (vr, x) in vrs.iter().zip(&values) {
                    let x = f64::from(*x);
                    ok &= fmu
                        .spec(*vr, ty)
                        .is_some_and(|v| v.settable(st) && x >= v.min && x <= v.max);
                }
                let (pv, px) = if null_arrays {
                    (std::ptr::null(), std::ptr::null())
                } else {
                    (vrs.as_ptr(), values.as_ptr())
                };
                // SAFETY: arrays of n elements (or NULL, refused).
                (
                    unsafe { ffi!(api, set_integer(c, pv, n, px)) },
                    format!("{vrs:?} = {values:?}"),
                )
            }
            VarType::Boolean => {
                let values: Vec<i32> = vrs.iter().map(|_| *self.rng.pick(&[0, 1, 1, -7, 255])).collect();
                for vr in &vrs {
                    ok &= fmu.spec(*vr, ty).is_some_and(|v| v.settable(st));
                }
                let (pv, px) = if null_arrays {
                    (std::ptr::null(), std::ptr::null())
                } else {
                    (vrs.as_ptr(), values.as_ptr())
                };
                // SAFETY: arrays of n elements (or NULL, refused).
                (
                    unsafe { ffi!(api, set_boolean(c, pv, n, px)) },
                    format!("{vrs:?} = {values:?}"),
                )
            }
            VarType::String => {
                let raw: Vec<Vec<u8>> = vrs
                    .iter()
                    .map(|_| match self.rng.below(4) {
                        0 => Vec::new(),
                        1 => vec![0xff, 0xfe, b'x'],
                        2 => "ünïcödé ✈".as_bytes().to_vec(),
                        _ => b"%s%n%x".to_vec(),
                    })
                    .collect();
                let cstrs: Vec<CString> = raw.iter().map(|b| CString::new(b.clone()).expect("no NUL")).collect();
                let mut ptrs: Vec<*const c_char> = cstrs.iter().map(|s| s.as_ptr()).collect();
                let null_string = n > 0 && self.rng.chance(0.1);
                if null_string {
                    ptrs[0] = std::ptr::null();
                }
                ok &= !null_string;
                for (vr, b) in vrs.iter().zip(&raw) {
                    ok &= fmu.spec(*vr, ty).is_some_and(|v| v.settable(st)) && std::str::from_utf8(b).is_ok();
                }
                let (pv, px) = if null_arrays {
                    (std::ptr::null(), std::ptr::null())
                } else {
                    (vrs.as_ptr(), ptrs.as_ptr())
                };
                // SAFETY: arrays of n elements (or NULL, refused).
                (
                    unsafe { ffi!(api, set_string(c, pv, n, px)) },
                    format!("{vrs:?} = {raw:?}"),
                )
            }
        };
        let expect = if ok { Expect::Ok } else { Expect::Error };
        let name = match ty {
            VarType::Real => "fmi2SetReal",
            VarType::Integer => "fmi2SetInteger",
            VarType::Boolean => "fmi2SetBoolean",
            VarType::String => "fmi2SetString",
        };
        self.check(fmu, live, name, st, expect, s, from, &detail);
    }

    fn op_get(&mut self, fmu: &Fmu, live: &mut Live<'_>, from: usize) {
        let st = live.m.st;
        let (ty, vrs, null_arrays) = self.pick_access(fmu, 6, false);
        let n = vrs.len();
        let all_valid = vrs.iter().all(|vr| fmu.spec(*vr, ty).is_some());
        let expect = if !legal(st, GET) || null_arrays || !all_valid {
            Expect::Error
        } else if n == 0 {
            Expect::Ok
        } else {
            Expect::OkOrError
        };
        let api = &fmu.api;
        let c = live.inst.c;
        let pv = if null_arrays { std::ptr::null() } else { vrs.as_ptr() };
        let (name, s) = match ty {
            VarType::Real => {
                let mut out = vec![0.0f64; n];
                let po = if null_arrays {
                    std::ptr::null_mut()
                } else {
                    out.as_mut_ptr()
                };
                // SAFETY: arrays of n elements (or NULL, refused).
                ("fmi2GetReal", unsafe { ffi!(api, get_real(c, pv, n, po)) })
            }
            VarType::Integer => {
                let mut out = vec![0i32; n];
                let po = if null_arrays {
                    std::ptr::null_mut()
                } else {
                    out.as_mut_ptr()
                };
                // SAFETY: arrays of n elements (or NULL, refused).
                ("fmi2GetInteger", unsafe { ffi!(api, get_integer(c, pv, n, po)) })
            }
            VarType::Boolean => {
                let mut out = vec![0i32; n];
                let po = if null_arrays {
                    std::ptr::null_mut()
                } else {
                    out.as_mut_ptr()
                };
                // SAFETY: arrays of n elements (or NULL, refused).
                let s = unsafe { ffi!(api, get_boolean(c, pv, n, po)) };
                if s == OK && out.iter().any(|b| *b != 0 && *b != 1) {
                    self.violation(fmu, format!("fmi2GetBoolean returned non-0/1 values {out:?}"));
                }
                ("fmi2GetBoolean", s)
            }
            VarType::String => {
                let mut out = vec![std::ptr::null::<c_char>(); n];
                let po = if null_arrays {
                    std::ptr::null_mut()
                } else {
                    out.as_mut_ptr()
                };
                // SAFETY: arrays of n elements (or NULL, refused); pointers read at once.
                let s = unsafe { ffi!(api, get_string(c, pv, n, po)) };
                if s == OK && out.iter().any(|p| p.is_null()) {
                    self.violation(fmu, "fmi2GetString returned a NULL string".into());
                }
                // SAFETY: valid until the next fmi2GetString.
                let _texts: Vec<String> = out.iter().map(|p| unsafe { text(*p) }).collect();
                ("fmi2GetString", s)
            }
        };
        self.check(fmu, live, name, st, expect, s, from, &format!("{vrs:?}"));
    }

    fn op_step(&mut self, fmu: &Fmu, live: &mut Live<'_>, from: usize) {
        let st = live.m.st;
        let m = live.m;
        let t = match self.rng.below(12) {
            0 => m.time + 1.0,
            1 => m.time - 1e-3,
            2 => f64::NAN,
            3 => f64::INFINITY,
            4 => m.time * (1.0 + 1e-12) + 1e-12,
            _ => m.time,
        };
        let h = match self.rng.below(20) {
            0 => 0.0,
            1 => -0.0,
            2 => -fmu.default_step,
            3 => f64::NAN,
            4 => f64::INFINITY,
            5 => 1e300,
            6 => f64::MAX,
            7 => 5e-324,
            8 => 1.0,
            9 => 1e-3,
            10 => 0.1,
            11 => -1e300,
            _ => fmu.default_step,
        };
        // The layer's argument checks (crates/fmi2-export/src/instance.rs, do_step).
        let t_ok = t.is_finite() && (t - m.time).abs() <= 1e-9 * m.time.abs().max(1.0);
        let h_ok = h.is_finite() && h > 0.0;
        let stop_ok = m.stop.is_none_or(|stop| t + h <= stop + 1e-9 * stop.abs().max(1.0));
        let end_ok = (t + h).is_finite();
        let expect = if st == StepComplete && t_ok && h_ok && stop_ok && end_ok {
            Expect::OkOrError
        } else {
            Expect::Error
        };
        // SAFETY: live instance.
        let s = unsafe { ffi!(fmu.api, do_step(live.inst.c, t, h, i32::from(self.rng.chance(0.5)))) };
        self.check(
            fmu,
            live,
            "fmi2DoStep",
            st,
            expect,
            s,
            from,
            &format!("t = {t}, h = {h}, FMU time {}", m.time),
        );
        if expect == Expect::OkOrError {
            if s == OK {
                live.m.time = t + h;
                if !live.m.time.is_finite() {
                    self.violation(
                        fmu,
                        format!("fmi2DoStep(t = {t}, h = {h}) accepted: FMU time is now {}", t + h),
                    );
                }
            } else if s == ERROR {
                live.m.st = StepFailed;
            }
        }
    }

    fn op_status(&mut self, fmu: &Fmu, live: &mut Live<'_>, from: usize) {
        let st = live.m.st;
        let c = live.inst.c;
        let api = &fmu.api;
        let kind = *self.rng.pick(&[
            fmi2StatusKind_fmi2DoStepStatus,
            fmi2StatusKind_fmi2PendingStatus,
            fmi2StatusKind_fmi2LastSuccessfulTime,
            fmi2StatusKind_fmi2Terminated,
            99,
        ]);
        let null_out = self.rng.chance(0.1);
        let legal_here = legal(st, STATUS) && !null_out;
        let which = self.rng.below(5);
        let mut status_val: fmi2Status = 99;
        let mut real_val = f64::NAN;
        let mut int_val: fmi2Integer = 0;
        let mut bool_val: fmi2Boolean = -1;
        let mut str_val: fmi2String = std::ptr::null();
        // SAFETY: live instance; out pointers valid or NULL (refused).
        let (name, s, expected_kind) = unsafe {
            match which {
                0 => (
                    "fmi2GetStatus",
                    ffi!(
                        api,
                        get_status(
                            c,
                            kind,
                            if null_out {
                                std::ptr::null_mut()
                            } else {
                                &mut status_val
                            }
                        )
                    ),
                    fmi2StatusKind_fmi2DoStepStatus,
                ),
                1 => (
                    "fmi2GetRealStatus",
                    ffi!(
                        api,
                        get_real_status(c, kind, if null_out { std::ptr::null_mut() } else { &mut real_val })
                    ),
                    fmi2StatusKind_fmi2LastSuccessfulTime,
                ),
                2 => (
                    "fmi2GetIntegerStatus",
                    ffi!(
                        api,
                        get_integer_status(c, kind, if null_out { std::ptr::null_mut() } else { &mut int_val })
                    ),
                    u32::MAX,
                ),
                3 => (
                    "fmi2GetBooleanStatus",
                    ffi!(
                        api,
                        get_boolean_status(c, kind, if null_out { std::ptr::null_mut() } else { &mut bool_val })
                    ),
                    fmi2StatusKind_fmi2Terminated,
                ),
                _ => (
                    "fmi2GetStringStatus",
                    ffi!(
                        api,
                        get_string_status(c, kind, if null_out { std::ptr::null_mut() } else { &mut str_val })
                    ),
                    u32::MAX,
                ),
            }
        };
        let expect = if !legal_here {
            Expect::Error
        } else if kind == expected_kind {
            Expect::Ok
        } else {
            Expect::Discard
        };
        self.check(fmu, live, name, st, expect, s, from, &format!("kind {kind}"));
        if s == OK {
            let right = match which {
                0 => {
                    status_val
                        == match st {
                            StepFailed => ERROR,
                            StepCanceled => DISCARD,
                            _ => OK,
                        }
                }
                1 => real_val.to_bits() == live.m.time.to_bits(),
                3 => bool_val == i32::from(matches!(st, StepFailed | Terminated)),
                _ => true,
            };
            if !right {
                self.violation(
                    fmu,
                    format!(
                        "{name}({kind}) in {}: value {status_val}/{real_val}/{bool_val}, FMU time {}",
                        st.name(),
                        live.m.time
                    ),
                );
            }
        }
    }

    fn op_serialize(
        &mut self,
        f: usize,
        fmu: &Fmu,
        live: &mut Live<'_>,
        states: &mut [(fmi2FMUstate, Mirror)],
        fake: &mut Fake,
        from: usize,
    ) {
        let st = live.m.st;
        let c = live.inst.c;
        let api = &fmu.api;
        let mut size = 0usize;
        if states.is_empty() || self.rng.chance(0.15) {
            let p = match self.foreign_donor(f) {
                Some(d) if self.rng.chance(0.5) => self.donors[d].state,
                _ => fake.ptr(),
            };
            // SAFETY: readable pointer, refused by tag.
            let s = unsafe { ffi!(api, serialized_fmu_state_size(c, p, &mut size)) };
            self.check(
                fmu,
                live,
                "fmi2SerializedFMUstateSize",
                st,
                Expect::Error,
                s,
                from,
                "foreign/fake",
            );
            return;
        }
        let (p, m) = *self.rng.pick(states);
        let null_size = self.rng.chance(0.05);
        // SAFETY: own state; out pointer valid or NULL (refused).
        let s = unsafe {
            ffi!(
                api,
                serialized_fmu_state_size(c, p, if null_size { std::ptr::null_mut() } else { &mut size })
            )
        };
        let expect = if null_size { Expect::Error } else { Expect::Ok };
        self.check(fmu, live, "fmi2SerializedFMUstateSize", st, expect, s, from, "own");
        if s != OK {
            return;
        }
        let from = live.inst.host.len();
        let mut buf = vec![0u8; size + 8];
        let (len, null_buf, expect) = match self.rng.below(8) {
            0 => (
                size.saturating_sub(1 + self.rng.below(size.max(1))),
                false,
                Expect::Error,
            ),
            1 => (size, true, Expect::Error),
            2 => (size + 8, false, Expect::Ok),
            _ => (size, false, Expect::Ok),
        };
        let ptr = if null_buf {
            std::ptr::null_mut()
        } else {
            buf.as_mut_ptr().cast()
        };
        // SAFETY: buffer of size + 8 ≥ len bytes (or NULL, refused).
        let s = unsafe { ffi!(api, serialize_fmu_state(c, p, ptr, len)) };
        self.check(
            fmu,
            live,
            "fmi2SerializeFMUstate",
            st,
            expect,
            s,
            from,
            &format!("size {len} of {size}"),
        );
        if s == OK {
            buf.truncate(size);
            let bank = &mut self.banks[f];
            if bank.len() < 8 {
                bank.push((buf, m));
            } else {
                let i = self.rng.below(8);
                bank[i] = (buf, m);
            }
        }
    }

    fn op_deserialize(
        &mut self,
        f: usize,
        fmu: &Fmu,
        live: &mut Live<'_>,
        states: &mut Vec<(fmi2FMUstate, Mirror)>,
        from: usize,
    ) {
        let st = live.m.st;
        let c = live.inst.c;
        let (own, mirror) = if self.banks[f].is_empty() {
            (self.donors[f].buffer.clone(), donor_mirror())
        } else {
            self.rng.pick(&self.banks[f]).clone()
        };
        let mut null_out = false;
        let (bytes, expect, mirror, label): (Vec<u8>, Expect, Option<Mirror>, String) = match self.rng.below(13) {
            12 => match self.forge_variable(fmu, &own) {
                // A parameter or input forged, re-sealed: refused exactly when fmi2Set* would
                // refuse the value (crates/fmi2-export/README.md, FMU state).
                Some((b, refused, label)) => {
                    let expect = if refused { Expect::Error } else { Expect::OkOrError };
                    (b, expect, (!refused).then_some(mirror), label)
                }
                None => (own, Expect::Ok, Some(mirror), "intact".into()),
            },
            0 => {
                let n = self.rng.below(own.len());
                (own[..n].to_vec(), Expect::Error, None, format!("truncated to {n}"))
            }
            1 | 2 => {
                let mut b = own.clone();
                let bit = self.rng.below(b.len() * 8);
                b[bit / 8] ^= 1 << (bit % 8);
                (b, Expect::Error, None, format!("bit {bit} flipped"))
            }
            3 => {
                let mut b = own.clone();
                b.push(0);
                (b, Expect::Error, None, "padded".into())
            }
            4 => match self.foreign_donor(f) {
                Some(d) => (self.donors[d].buffer.clone(), Expect::Error, None, "foreign FMU".into()),
                None => {
                    // A well-formed buffer of another GUID (same length), checksum recomputed.
                    let env = open(&own).expect("own buffer parses");
                    let mut head = env.head.clone();
                    let g = 16 + self.rng.below(head.len() - 16);
                    head[g] = if head[g] == b'0' { b'1' } else { b'0' };
                    (seal(&head, &env.payload), Expect::Error, None, "forged GUID".into())
                }
            },
            5 => {
                let n = self.rng.below(256);
                let b: Vec<u8> = (0..n).map(|_| self.rng.next_u64() as u8).collect();
                (b, Expect::Error, None, "random bytes".into())
            }
            6 => (Vec::new(), Expect::Error, None, "empty".into()),
            7 | 8 => {
                // Structure-aware: mutate the payload, re-seal with a correct checksum.
                let env = open(&own).expect("own buffer parses");
                let mut payload = env.payload.clone();
                let k = 1 + self.rng.below(3);
                for _ in 0..k {
                    let at = if self.rng.chance(0.6) {
                        self.rng.below(payload.len().min(37))
                    } else {
                        self.rng.below(payload.len())
                    };
                    payload[at] = match self.rng.below(3) {
                        0 => payload[at] ^ (1 << self.rng.below(8)),
                        1 => *self.rng.pick(&[0, 1, 2, 4, 6, 7, 8, 0x7f, 0xff]),
                        _ => self.rng.next_u64() as u8,
                    };
                }
                let b = seal(&env.head, &payload);
                let m = machine_of(&payload);
                (b, Expect::OkOrError, m, "payload mutated, re-sealed".into())
            }
            9 => {
                null_out = true;
                (own, Expect::Error, None, "NULL out pointer".into())
            }
            _ => (own, Expect::Ok, Some(mirror), "intact".into()),
        };
        let mut p: fmi2FMUstate = std::ptr::null_mut();
        let out: *mut fmi2FMUstate = if null_out { std::ptr::null_mut() } else { &mut p };
        let data = if bytes.is_empty() {
            std::ptr::null()
        } else {
            bytes.as_ptr().cast()
        };
        // SAFETY: buffer of len bytes; out pointer valid or NULL (refused).
        let s = unsafe { ffi!(fmu.api, deserialize_fmu_state(c, data, bytes.len(), out)) };
        self.check(fmu, live, "fmi2DeSerializeFMUstate", st, expect, s, from, &label);
        if s == OK {
            match mirror {
                Some(m) => states.push((p, m)),
                None => {
                    self.violation(
                        fmu,
                        format!("fmi2DeSerializeFMUstate accepted an invalid buffer ({label})"),
                    );
                    let mut p = p;
                    // SAFETY: own state just created.
                    unsafe { ffi!(fmu.api, free_fmu_state(c, &mut p)) };
                }
            }
        } else if !p.is_null() {
            self.violation(
                fmu,
                format!("fmi2DeSerializeFMUstate failed ({label}) but wrote a state"),
            );
        }
    }

    /// `own` (a serialized state of `fmu`) with one Real or Integer parameter or input
    /// replaced by a value from the edges of its range (or beyond: non-finite, huge,
    /// just outside), re-sealed with a valid checksum. Returns the buffer, whether
    /// fmi2Set* would refuse the value, and a label; `None` if the payload does not have
    /// the declared layout (machine fields, then every variable in declaration order).
    fn forge_variable(&mut self, fmu: &Fmu, own: &[u8]) -> Option<(Vec<u8>, bool, String)> {
        const MACHINE_BYTES: usize = 38;
        let env = open(own)?;
        let mut payload = env.payload.clone();
        let mut at = MACHINE_BYTES;
        let mut slots = Vec::new();
        for v in &fmu.vars {
            let len = match v.ty {
                VarType::Real => 8,
                VarType::Integer => 4,
                VarType::Boolean => 1,
                VarType::String => 4 + u32::from_le_bytes(payload.get(at..at + 4)?.try_into().ok()?) as usize,
            };
            let bounded = matches!(v.causality, Causality::Parameter | Causality::Input)
                && v.variability != Variability::Constant
                && matches!(v.ty, VarType::Real | VarType::Integer);
            if bounded {
                slots.push((v, at));
            }
            at += len;
        }
        if at > payload.len() || slots.is_empty() {
            return None;
        }
        let (v, at) = *self.rng.pick(&slots);
        let (lo, hi) = (v.min, v.max);
        let above = if hi.is_finite() {
            hi + hi.abs().max(1.0) * 1e-6
        } else {
            1e300
        };
        let below = if lo.is_finite() {
            lo - lo.abs().max(1.0) * 1e-6
        } else {
            -1e300
        };
        let inside = self.rng.in_range(lo, hi);
        if v.ty == VarType::Real {
            let x = *self.rng.pick(&[
                f64::NAN,
                f64::INFINITY,
                f64::NEG_INFINITY,
                2e10,
                -2e10,
                f64::MAX,
                above,
                below,
                inside,
            ]);
            payload[at..at + 8].copy_from_slice(&x.to_le_bytes());
            let refused = !x.is_finite() || x < lo || x > hi;
            Some((seal(&env.head, &payload), refused, format!("forged {} = {x}", v.name)))
        } else {
            let clamp = |x: f64| x.clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32;
            let x = *self.rng.pick(&[
                i32::MIN,
                i32::MAX,
                clamp(lo.max(-1e6) - 1.0),
                clamp(hi.min(1e6) + 1.0),
                clamp(inside.round()),
            ]);
            payload[at..at + 4].copy_from_slice(&x.to_le_bytes());
            let refused = f64::from(x) < lo || f64::from(x) > hi;
            Some((seal(&env.head, &payload), refused, format!("forged {} = {x}", v.name)))
        }
    }

    fn op_instantiate(&mut self, fmu: &Fmu) {
        let host = Host::new();
        let guid = CString::new(fmu.guid.as_str()).expect("no NUL");
        let wrong = CString::new(fmu.guid.replace(['1', '2', '3'], "0") + "x").expect("no NUL");
        let mut no_logger = *host.callbacks;
        no_logger.logger = None;
        let name = c"second";
        let variant = self.rng.below(8);
        let (n, ty, g, cb, should_log, label): (
            *const c_char,
            fmi2Type,
            *const c_char,
            *const fmi2CallbackFunctions,
            bool,
            &str,
        ) = match variant {
            0 => (
                name.as_ptr(),
                fmi2Type_fmi2CoSimulation,
                wrong.as_ptr(),
                &*host.callbacks,
                true,
                "wrong GUID",
            ),
            1 => (
                c"".as_ptr(),
                fmi2Type_fmi2CoSimulation,
                guid.as_ptr(),
                &*host.callbacks,
                true,
                "empty name",
            ),
            2 => (
                std::ptr::null(),
                fmi2Type_fmi2CoSimulation,
                guid.as_ptr(),
                &*host.callbacks,
                true,
                "NULL name",
            ),
            3 => (
                name.as_ptr(),
                fmi2Type_fmi2ModelExchange,
                guid.as_ptr(),
                &*host.callbacks,
                fmu.n_states == 0,
                "ME",
            ),
            4 => (
                name.as_ptr(),
                fmi2Type_fmi2CoSimulation,
                std::ptr::null(),
                &*host.callbacks,
                true,
                "NULL GUID",
            ),
            5 => (
                name.as_ptr(),
                fmi2Type_fmi2CoSimulation,
                guid.as_ptr(),
                std::ptr::null(),
                false,
                "NULL callbacks",
            ),
            6 => (
                name.as_ptr(),
                fmi2Type_fmi2CoSimulation,
                guid.as_ptr(),
                &no_logger,
                false,
                "NULL logger",
            ),
            _ => (
                name.as_ptr(),
                fmi2Type_fmi2CoSimulation,
                guid.as_ptr(),
                &*host.callbacks,
                false,
                "valid",
            ),
        };
        // SAFETY: strings NUL-terminated or NULL; callbacks valid or NULL; host outlives the instance.
        let comp = unsafe { ffi!(fmu.api, instantiate(n, ty, g, c"".as_ptr(), cb, 0, 1)) };
        // Model Exchange is valid exactly for the FMUs with continuous states.
        let valid = variant == 7 || (variant == 3 && fmu.n_states > 0);
        self.count("fmi2Instantiate", label, if comp.is_null() { ERROR } else { OK });
        if comp.is_null() == valid {
            self.violation(fmu, format!("fmi2Instantiate ({label}) returned {comp:?}"));
        }
        if should_log && host.records().iter().all(|r| r.status != ERROR) {
            self.violation(fmu, format!("fmi2Instantiate ({label}) refused without logging"));
        }
        if !comp.is_null() {
            if variant == 3 {
                // SAFETY: a live Model Exchange component of this model; host outlives it.
                unsafe { self.model_exchange_sequence(fmu, comp, &host) };
            }
            // SAFETY: a live component of this model.
            unsafe { ffi!(fmu.api, free_instance(comp)) };
        }
    }

    /// A random sequence of Model Exchange calls on a fresh ME instance, legal and
    /// illegal, each checked against the ME state table (FMI 2.0 §3.2.3) and argument
    /// rules (nx must equal the number of states, states finite, no event indicators).
    ///
    /// # Safety
    /// `c` is a live Model Exchange component of `fmu`, logging into `host`.
    unsafe fn model_exchange_sequence(&mut self, fmu: &Fmu, c: fmi2Component, host: &Host) {
        #[derive(Clone, Copy, PartialEq, Debug)]
        enum Me {
            Instantiated,
            InitializationMode,
            EventMode,
            ContinuousTimeMode,
            Terminated,
        }
        let api = &fmu.api;
        let n = fmu.n_states;
        let mut st = Me::Instantiated;
        let mut x = vec![0.0; n + 1];
        let mut good_x: Option<Vec<f64>> = None;
        let mut flag: fmi2Boolean = 0;
        let mut flag2: fmi2Boolean = 0;
        let mut info = fmi2EventInfo::default();
        for _ in 0..self.rng.below(40) + 5 {
            let from = host.len();
            let op = self.rng.below(16);
            let nx = *self.rng.pick(&[n, n, n, n.saturating_sub(1), n + 1, 0]);
            let in_ = |states: &[Me]| states.contains(&st);
            // Each call: its name, whether it is legal here, its status, and the state a
            // legal call that returns OK leads to (`None`: it stays).
            // SAFETY (every call below): live component, buffers of n + 1 ≥ nx elements.
            let (name, expect, s, next) = unsafe {
                match op {
                    0 => (
                        "fmi2SetupExperiment",
                        in_(&[Me::Instantiated]),
                        ffi!(api, setup_experiment(c, 0, 0.0, 0.0, 0, 0.0)),
                        None,
                    ),
                    1 => (
                        "fmi2EnterInitializationMode",
                        in_(&[Me::Instantiated]),
                        ffi!(api, enter_initialization_mode(c)),
                        Some(Me::InitializationMode),
                    ),
                    2 => (
                        "fmi2ExitInitializationMode",
                        in_(&[Me::InitializationMode]),
                        ffi!(api, exit_initialization_mode(c)),
                        Some(Me::EventMode),
                    ),
                    3 => (
                        "fmi2EnterEventMode",
                        in_(&[Me::EventMode, Me::ContinuousTimeMode]),
                        ffi!(api, enter_event_mode(c)),
                        Some(Me::EventMode),
                    ),
                    4 => (
                        "fmi2NewDiscreteStates",
                        in_(&[Me::EventMode]),
                        ffi!(api, new_discrete_states(c, &mut info)),
                        None,
                    ),
                    5 => (
                        "fmi2EnterContinuousTimeMode",
                        in_(&[Me::EventMode]),
                        ffi!(api, enter_continuous_time_mode(c)),
                        Some(Me::ContinuousTimeMode),
                    ),
                    6 => (
                        "fmi2CompletedIntegratorStep",
                        in_(&[Me::ContinuousTimeMode]),
                        ffi!(api, completed_integrator_step(c, 1, &mut flag, &mut flag2)),
                        None,
                    ),
                    7 => {
                        let t = *self.rng.pick(&[0.01, 0.5, f64::NAN, f64::INFINITY]);
                        let ok = in_(&[Me::EventMode, Me::ContinuousTimeMode]) && t.is_finite();
                        ("fmi2SetTime", ok, ffi!(api, set_time(c, t)), None)
                    }
                    8 => {
                        // Perturb the last states read back, sometimes with a NaN.
                        let mut v = good_x.clone().unwrap_or_else(|| vec![0.0; n]);
                        for e in v.iter_mut() {
                            *e *= 1.0 + 1e-3 * (self.rng.unit() - 0.5);
                        }
                        let nan = n > 0 && self.rng.chance(0.2);
                        if nan {
                            let k = self.rng.below(n);
                            v[k] = f64::NAN;
                        }
                        v.push(0.0);
                        let ok = in_(&[Me::ContinuousTimeMode]) && nx == n && !nan;
                        let s = ffi!(api, set_continuous_states(c, v.as_ptr(), nx));
                        ("fmi2SetContinuousStates", ok, s, None)
                    }
                    9 => (
                        "fmi2GetDerivatives",
                        in_(&[Me::EventMode, Me::ContinuousTimeMode, Me::Terminated]) && nx == n,
                        ffi!(api, get_derivatives(c, x.as_mut_ptr(), nx)),
                        None,
                    ),
                    10 => {
                        let ok = in_(&[
                            Me::InitializationMode,
                            Me::EventMode,
                            Me::ContinuousTimeMode,
                            Me::Terminated,
                        ]) && nx == n;
                        let s = ffi!(api, get_continuous_states(c, x.as_mut_ptr(), nx));
                        if s == OK {
                            good_x = Some(x[..n].to_vec());
                        }
                        ("fmi2GetContinuousStates", ok, s, None)
                    }
                    11 => {
                        let ok =
                            in_(&[Me::Instantiated, Me::EventMode, Me::ContinuousTimeMode, Me::Terminated]) && nx == n;
                        let s = ffi!(api, get_nominals_of_continuous_states(c, x.as_mut_ptr(), nx));
                        if s == OK && x[..n].iter().any(|v| !(v.is_finite() && *v > 0.0)) {
                            self.violation(fmu, format!("fmi2GetNominalsOfContinuousStates gave {:?}", &x[..n]));
                        }
                        ("fmi2GetNominalsOfContinuousStates", ok, s, None)
                    }
                    12 => {
                        let ni = *self.rng.pick(&[0, 0, 1, 3]);
                        let ok = in_(&[
                            Me::InitializationMode,
                            Me::EventMode,
                            Me::ContinuousTimeMode,
                            Me::Terminated,
                        ]) && ni == 0;
                        let s = ffi!(api, get_event_indicators(c, x.as_mut_ptr(), ni));
                        ("fmi2GetEventIndicators", ok, s, None)
                    }
                    13 => ("fmi2DoStep", false, ffi!(api, do_step(c, 0.0, 0.01, 1)), None),
                    14 => (
                        "fmi2Terminate",
                        in_(&[Me::EventMode, Me::ContinuousTimeMode]),
                        ffi!(api, terminate(c)),
                        Some(Me::Terminated),
                    ),
                    _ => {
                        good_x = None;
                        ("fmi2Reset", true, ffi!(api, reset(c)), Some(Me::Instantiated))
                    }
                }
            };
            // A legal call may still fail in the model (e.g. a derivative not finite at a
            // perturbed state): OK or Error then; an illegal one must be Error and logged.
            let label = format!("ME {st:?}");
            self.count(name, &label, s);
            if !expect && s != ERROR {
                self.violation(
                    fmu,
                    format!("{name} in ME state {st:?} (nx {nx}) returned {}", status_name(s)),
                );
            }
            if expect && s != OK && s != ERROR {
                self.violation(fmu, format!("{name} in ME state {st:?} returned {}", status_name(s)));
            }
            if s == ERROR && host.records()[from..].iter().all(|r| r.status != ERROR) {
                self.violation(fmu, format!("{name} in ME state {st:?} failed without logging"));
            }
            if host.records()[from..].iter().any(|r| r.message.contains("panic")) {
                self.violation(fmu, format!("{name} in ME state {st:?} panicked"));
            }
            // fmi2Reset leads to Instantiated whatever it returns.
            if (s == OK && expect) || op == 15 {
                st = next.unwrap_or(st);
            }
        }
    }
}

/// The mirror of the donor states: captured right after initialisation at t = 0.
fn donor_mirror() -> Mirror {
    Mirror {
        st: StepComplete,
        ..Mirror::fresh()
    }
}

use model_description::{Causality, VarType};
use std::ffi::CString;

/// Outcome of [`canonical_run`].
pub struct Canonical {
    /// Statuses and value bits of every call, in order.
    pub trace: Vec<u64>,
    /// Invariant violations found inside the run (state restore not bit-identical).
    pub problems: Vec<String>,
    pub restore_checked: bool,
}

/// A legal run from a just-instantiated or just-reset instance, determined by
/// `seed`: set a few parameters/inputs to valid values, initialise, step, read
/// everything; then check that restoring an FMU state mid-run (directly and
/// through serialization) continues bit-identically.
pub fn canonical_run(inst: &mut Instance<'_>, seed: u64) -> Canonical {
    let fmu = inst.fmu;
    let mut rng = Rng::new(seed);
    let mut trace = Vec::new();
    let mut problems = Vec::new();
    trace.push(inst.setup(0.0, None) as u64);
    let settable: Vec<&Var> = fmu
        .vars
        .iter()
        .filter(|v| v.ty == VarType::Real && v.start.is_some() && v.settable(St::Instantiated))
        .collect();
    for _ in 0..rng.below(4) {
        if settable.is_empty() {
            break;
        }
        let v = *rng.pick(&settable);
        let x0 = v.start.unwrap_or(0.0);
        let x = (x0 + (rng.unit() - 0.5) * 0.02 * x0.abs().max(1.0)).clamp(v.min, v.max);
        trace.push(inst.set_reals(&[v.vr], &[x]) as u64);
    }
    trace.push(inst.enter_init() as u64);
    trace.push(inst.exit_init() as u64);
    let (s, bits) = inst.snapshot_bits();
    trace.extend(s.iter().map(|s| *s as u64));
    trace.extend(bits);
    let h = fmu.default_step;
    let mut restore_checked = false;
    let mut t = 0.0;
    for k in 0..6 {
        if k == 3 {
            // Branch: state S; 3 steps → A; restore S; 3 steps → B; deserialize(S) → C. A = B = C.
            let (s, state) = inst.get_state();
            if s == OK {
                let runs: Vec<Vec<u64>> = (0..3)
                    .map(|mode| {
                        let ok = match mode {
                            0 => true,
                            1 => inst.set_state(state) == OK,
                            _ => {
                                let (s, bytes) = inst.serialize(state);
                                let (s2, mut restored) = inst.deserialize(&bytes);
                                let ok = s == OK && s2 == OK && inst.set_state(restored) == OK;
                                inst.free_state(&mut restored);
                                ok
                            }
                        };
                        let mut out = vec![u64::from(ok)];
                        let mut tt = t;
                        for _ in 0..3 {
                            out.push(inst.step(tt, h) as u64);
                            tt += h;
                            out.extend(inst.snapshot_bits().1);
                        }
                        out
                    })
                    .collect();
                if runs[0] != runs[1] || runs[0] != runs[2] {
                    problems.push(format!(
                        "{}: continuing from a restored FMU state is not bit-identical (direct {}, serialized {})",
                        fmu.id,
                        runs[0] == runs[1],
                        runs[0] == runs[2]
                    ));
                }
                restore_checked = true;
                let mut state = state;
                assert_eq!(inst.set_state(state), OK);
                inst.free_state(&mut state);
            }
        }
        trace.push(inst.step(t, h) as u64);
        t += h;
        let (s, bits) = inst.snapshot_bits();
        trace.extend(s.iter().map(|s| *s as u64));
        trace.extend(bits);
    }
    Canonical {
        trace,
        problems,
        restore_checked,
    }
}
