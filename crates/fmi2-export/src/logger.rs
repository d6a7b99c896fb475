//! Logging through the host's `fmi2CallbackLogger` (or, for the FMI 3.0 layer built on
//! this one, its `fmi3LogMessageCallback`: [`LogSink::new_fmi3`]).
//!
//! The callback is variadic and hosts treat `message` as a printf format, so
//! every message is passed as the argument of a constant `"%s"` format, with
//! interior NULs stripped. The host's `componentEnvironment` and the instance
//! name are passed back unchanged.
//!
//! Categories (see [`LOG_CATEGORIES`](crate::LOG_CATEGORIES)): errors are always
//! logged (`logStatusError`); warnings when `logStatusWarning` or `logAll` is
//! enabled; info/debug messages when `logAll` is enabled. `fmi2Instantiate`'s
//! `loggingOn` enables all categories; `fmi2SetDebugLogging` changes them.

use fmi_sys::{fmi2, fmi3};
use std::ffi::{CStr, CString};
use std::fmt::Display;

/// Index into [`crate::LOG_CATEGORIES`].
pub(crate) const CAT_WARNING: usize = 0;
pub(crate) const CAT_ERROR: usize = 1;
pub(crate) const CAT_ALL: usize = 2;
const N_CATEGORIES: usize = 3;

const CATEGORY_CSTRS: [&CStr; N_CATEGORIES] = [c"logStatusWarning", c"logStatusError", c"logAll"];

/// Severity of a message sent to the host.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    /// `fmi2Error`, category `logStatusError`; always logged.
    Error,
    /// `fmi2Discard`, category `logStatusWarning`.
    Discard,
    /// `fmi2Warning`, category `logStatusWarning`.
    Warning,
    /// `fmi2OK`, category `logAll`.
    Info,
    /// `fmi2OK`, category `logAll`.
    Debug,
}

/// The host's logger function: FMI 2.0 (variadic, printf format) or FMI 3.0 (plain message).
#[derive(Debug, Clone, Copy)]
enum Callback {
    Fmi2(fmi2::fmi2CallbackLogger),
    Fmi3(fmi3::fmi3LogMessageCallback),
}

/// The host's logger of one instance plus its category filter.
#[derive(Debug)]
pub struct LogSink {
    callback: Callback,
    env: fmi2::fmi2ComponentEnvironment,
    instance_name: CString,
    enabled: [bool; N_CATEGORIES],
}

impl LogSink {
    /// A sink forwarding to `callback` (may be `None`: nothing is logged).
    pub fn new(
        callback: fmi2::fmi2CallbackLogger,
        env: fmi2::fmi2ComponentEnvironment,
        instance_name: &str,
        logging_on: bool,
    ) -> Self {
        Self {
            callback: Callback::Fmi2(callback),
            env,
            instance_name: to_cstring(instance_name),
            enabled: [logging_on; N_CATEGORIES],
        }
    }

    /// A sink forwarding to an FMI 3.0 `fmi3LogMessageCallback` (may be `None`: nothing
    /// is logged). `env` is the host's `instanceEnvironment`.
    pub fn new_fmi3(
        callback: fmi3::fmi3LogMessageCallback,
        env: fmi3::fmi3InstanceEnvironment,
        instance_name: &str,
        logging_on: bool,
    ) -> Self {
        Self {
            callback: Callback::Fmi3(callback),
            env,
            instance_name: to_cstring(instance_name),
            enabled: [logging_on; N_CATEGORIES],
        }
    }

    /// A sink that drops every message.
    pub fn null() -> Self {
        Self::new(None, std::ptr::null_mut(), "", false)
    }

    /// Whether a message of this level would reach the host.
    pub fn enabled(&self, level: Level) -> bool {
        let present = match self.callback {
            Callback::Fmi2(c) => c.is_some(),
            Callback::Fmi3(c) => c.is_some(),
        };
        present
            && match level {
                Level::Error => true,
                Level::Warning | Level::Discard => self.enabled[CAT_WARNING] || self.enabled[CAT_ALL],
                Level::Info | Level::Debug => self.enabled[CAT_ALL],
            }
    }

    /// Enable/disable every category.
    pub fn set_all(&mut self, on: bool) {
        self.enabled = [on; N_CATEGORIES];
    }

    /// Enable/disable one category by name; `false` if the name is unknown.
    pub fn set_category(&mut self, name: &str, on: bool) -> bool {
        match crate::LOG_CATEGORIES.iter().position(|(n, _)| *n == name) {
            Some(i) => {
                self.enabled[i] = on;
                true
            }
            None => false,
        }
    }

    pub fn instance_name(&self) -> &CStr {
        &self.instance_name
    }

    /// Send `message` to the host if `level` is enabled. Allocates only when it logs.
    pub fn log(&self, level: Level, message: &dyn Display) {
        if !self.enabled(level) {
            return;
        }
        let (status, category) = match level {
            Level::Error => (fmi2::fmi2Status_fmi2Error, CATEGORY_CSTRS[CAT_ERROR]),
            Level::Discard => (fmi2::fmi2Status_fmi2Discard, CATEGORY_CSTRS[CAT_WARNING]),
            Level::Warning => (fmi2::fmi2Status_fmi2Warning, CATEGORY_CSTRS[CAT_WARNING]),
            Level::Info | Level::Debug => (fmi2::fmi2Status_fmi2OK, CATEGORY_CSTRS[CAT_ALL]),
        };
        let text = to_cstring(&message.to_string());
        match self.callback {
            // SAFETY: the host supplied `callback`; every pointer passed is a valid
            // NUL-terminated string that outlives the call; "%s" consumes exactly
            // the one variadic argument supplied.
            Callback::Fmi2(Some(callback)) => unsafe {
                callback(
                    self.env,
                    self.instance_name.as_ptr(),
                    status,
                    category.as_ptr(),
                    c"%s".as_ptr(),
                    text.as_ptr(),
                );
            },
            // SAFETY: as above; FMI 3.0 passes the message itself (no format) and no
            // instance name. The FMI 2.0 and 3.0 status codes used here are equal
            // (OK 0, Warning 1, Discard 2, Error 3).
            Callback::Fmi3(Some(callback)) => unsafe {
                callback(self.env, status as fmi3::fmi3Status, category.as_ptr(), text.as_ptr());
            },
            Callback::Fmi2(None) | Callback::Fmi3(None) => {}
        }
    }
}

/// `s` as a C string, interior NULs removed.
pub(crate) fn to_cstring(s: &str) -> CString {
    let bytes: Vec<u8> = s.bytes().filter(|&b| b != 0).collect();
    CString::new(bytes).unwrap_or_default()
}

/// The logger handed to model methods: forwards to the instance's host logger.
#[derive(Debug, Clone, Copy)]
pub struct Logger<'a> {
    sink: Option<&'a LogSink>,
}

impl<'a> Logger<'a> {
    /// A logger writing to `sink`.
    pub fn new(sink: &'a LogSink) -> Self {
        Self { sink: Some(sink) }
    }

    /// A logger that drops every message (for unit tests of models).
    pub fn null() -> Logger<'static> {
        Logger { sink: None }
    }

    /// Whether a message of this level would reach the host (to skip costly formatting).
    pub fn enabled(&self, level: Level) -> bool {
        self.sink.is_some_and(|s| s.enabled(level))
    }

    pub fn log(&self, level: Level, message: impl Display) {
        if let Some(sink) = self.sink {
            sink.log(level, &message);
        }
    }
    /// Always logged (status fmi2Error). The model still has to return an error.
    pub fn error(&self, message: impl Display) {
        self.log(Level::Error, message)
    }
    /// Logged with status fmi2Warning when warnings are enabled.
    pub fn warning(&self, message: impl Display) {
        self.log(Level::Warning, message)
    }
    /// Logged with status fmi2OK when `logAll` is enabled.
    pub fn info(&self, message: impl Display) {
        self.log(Level::Info, message)
    }
    /// Logged with status fmi2OK when `logAll` is enabled.
    pub fn debug(&self, message: impl Display) {
        self.log(Level::Debug, message)
    }
}
