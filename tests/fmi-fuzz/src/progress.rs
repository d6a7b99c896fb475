//! Where a fuzz run is, kept so that it survives the run: an abort (an allocation
//! failure, a panic leaving an `extern "C"` function) or a crash inside an FMU ends the
//! process before any report is printed.
//!
//! Before each sequence, [`Progress::mark`] stores the sequence's index and seed-state
//! in atomics and, if a file was given, overwrites that file's first line with them
//! (one `pwrite`, no flush: the page cache outlives the process). A handler of SIGABRT,
//! SIGSEGV, SIGBUS, SIGILL and SIGFPE prints the stored sequence to stderr with
//! `write(2)` (async-signal-safe, no allocation) and lets the signal's default action
//! end the process, e.g.
//!
//! ```text
//! memory allocation of 171798692088160 bytes failed
//! fmi-fuzz: signal 6 during sequence 123456 (seed 0x309) — replay: fmi-fuzz fuzz --replay 0x5c1e… --max-calls 60
//! ```

use std::fs::File;
use std::os::unix::fs::FileExt;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Once;

static SEED: AtomicU64 = AtomicU64::new(0);
/// Index of the running sequence; 0 outside sequences.
static INDEX: AtomicU64 = AtomicU64::new(0);
static STATE: AtomicU64 = AtomicU64::new(0);
static MAX_CALLS: AtomicU64 = AtomicU64::new(0);

const SIGNALS: [libc::c_int; 5] = [libc::SIGABRT, libc::SIGSEGV, libc::SIGBUS, libc::SIGILL, libc::SIGFPE];

/// Append `n` in decimal (`hex`: `0x…` hexadecimal) to `buf` at `*at`.
fn put_num(buf: &mut [u8], at: &mut usize, mut n: u64, hex: bool) {
    let base = if hex { 16 } else { 10 };
    if hex {
        put(buf, at, b"0x");
    }
    let mut digits = [0u8; 20];
    let mut k = 0;
    loop {
        digits[k] = b"0123456789abcdef"[(n % base) as usize];
        n /= base;
        k += 1;
        if n == 0 {
            break;
        }
    }
    while k > 0 {
        k -= 1;
        put(buf, at, &digits[k..=k]);
    }
}

fn put(buf: &mut [u8], at: &mut usize, s: &[u8]) {
    for &b in s {
        if *at < buf.len() {
            buf[*at] = b;
            *at += 1;
        }
    }
}

extern "C" fn on_fatal_signal(sig: libc::c_int) {
    let mut buf = [0u8; 256];
    let mut at = 0;
    let index = INDEX.load(Ordering::SeqCst);
    put(&mut buf, &mut at, b"\nfmi-fuzz: signal ");
    put_num(&mut buf, &mut at, sig as u64, false);
    if index == 0 {
        put(&mut buf, &mut at, b" outside any fuzz sequence\n");
    } else {
        let state = STATE.load(Ordering::SeqCst);
        put(&mut buf, &mut at, b" during sequence ");
        put_num(&mut buf, &mut at, index, false);
        put(&mut buf, &mut at, b" (seed ");
        put_num(&mut buf, &mut at, SEED.load(Ordering::SeqCst), true);
        put(&mut buf, &mut at, b") - replay: fmi-fuzz fuzz --replay ");
        put_num(&mut buf, &mut at, state, true);
        put(&mut buf, &mut at, b" --max-calls ");
        put_num(&mut buf, &mut at, MAX_CALLS.load(Ordering::SeqCst), false);
        put(&mut buf, &mut at, b"\n");
    }
    // SAFETY: write(2) is async-signal-safe; the buffer is valid for `at` bytes.
    unsafe { libc::write(2, buf.as_ptr().cast(), at) };
    // SA_RESETHAND restored the default action; the signal, blocked while the handler
    // runs, is delivered again on return and ends the process as it would have.
    // SAFETY: raise(3) is async-signal-safe.
    unsafe { libc::raise(sig) };
}

fn install_handler() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        for sig in SIGNALS {
            // SAFETY: a zeroed sigaction is valid; the handler only touches atomics and write(2).
            unsafe {
                let mut sa: libc::sigaction = std::mem::zeroed();
                sa.sa_sigaction = on_fatal_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
                sa.sa_flags = libc::SA_RESETHAND | libc::SA_ONSTACK;
                libc::sigemptyset(&mut sa.sa_mask);
                libc::sigaction(sig, &sa, std::ptr::null_mut());
            }
        }
    });
}

/// The marker of one run.
pub struct Progress {
    file: Option<File>,
    seed: u64,
    max_calls: usize,
    last: Option<(u64, u64)>,
}

/// Width of the file's record (padded so a shorter record overwrites a longer one).
const RECORD: usize = 160;

impl Progress {
    /// Install the signal handler (once per process) and create `file` if given; the
    /// run's `seed` and `max_calls` (which a replay must repeat) go into the messages.
    pub fn new(file: Option<&Path>, seed: u64, max_calls: usize) -> Self {
        install_handler();
        SEED.store(seed, Ordering::SeqCst);
        MAX_CALLS.store(max_calls as u64, Ordering::SeqCst);
        let file = file.and_then(|p| {
            File::create(p)
                .map_err(|e| eprintln!("fmi-fuzz: cannot write the progress file {}: {e}", p.display()))
                .ok()
        });
        Self {
            file,
            seed,
            max_calls,
            last: None,
        }
    }

    fn write(&self, text: &str) {
        if let Some(f) = &self.file {
            let mut line = format!("{text:<width$}", width = RECORD - 1).into_bytes();
            line.truncate(RECORD - 1);
            line.push(b'\n');
            // A failed write only loses the marker.
            let _ = f.write_at(&line, 0);
        }
    }

    /// Sequence `index` (seed-state `state`, on FMU `fmu`) is about to run.
    pub fn mark(&mut self, index: u64, state: u64, fmu: &str) {
        INDEX.store(index, Ordering::SeqCst);
        STATE.store(state, Ordering::SeqCst);
        self.last = Some((index, state));
        self.write(&format!(
            "running sequence {index} of seed {:#x} on {fmu}, seed-state {state:#x}: \
             replay with `fmi-fuzz fuzz --replay {state:#x} --max-calls {}`",
            self.seed, self.max_calls
        ));
    }

    /// The run ended normally.
    pub fn finish(&mut self) {
        INDEX.store(0, Ordering::SeqCst);
        if let Some((index, state)) = self.last {
            self.write(&format!(
                "finished after sequence {index} of seed {:#x} (seed-state {state:#x})",
                self.seed
            ));
        }
    }
}
