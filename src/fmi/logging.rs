//! logging — messages to the master through its fmi2CallbackLogger.
//!
//! Categories (declared in `<LogCategories>`): `logEvents`, `logStatusWarning`,
//! `logStatusError`, `logStatusFatal`, `logAll`.
//! * The status categories (warning/error/fatal) are on by default, so the
//!   master always learns why a call failed; fmi2SetDebugLogging can switch them
//!   off only by naming them.
//! * `logEvents` and `logAll` are debug logging: on only while debug logging is
//!   on (`loggingOn` of fmi2Instantiate / fmi2SetDebugLogging) and the category
//!   is enabled. `logAll` traces every FMI call, so it is the one that may cost time.
//!
//! Must never: pass user text as the format (always `"%s"` + one NUL-terminated
//! argument), call a null callback, or allocate when the message is filtered out.

use super::types::{fmi2CallbackFunctions, Fmi2Status};
use std::ffi::CString;

/// Log categories, in the order of [`CATEGORY_NAMES`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Category {
    /// `logEvents`: state changes (initialization, termination, reset, FMU state
    /// restored) and fmi2OK/fmi2Pending messages; debug logging only.
    Events = 0,
    /// `logStatusWarning`: messages sent with fmi2Warning or fmi2Discard; on by default.
    StatusWarning = 1,
    /// `logStatusError`: why a call answered fmi2Error; on by default.
    StatusError = 2,
    /// `logStatusFatal`: why a call answered fmi2Fatal; on by default.
    StatusFatal = 3,
    /// `logAll`: a trace line for every FMI call; debug logging only.
    All = 4,
}

/// Category names as declared in the XML (checked by build.rs via spec.rs).
pub const CATEGORY_NAMES: [&str; 5] = [
    "logEvents",
    "logStatusWarning",
    "logStatusError",
    "logStatusFatal",
    "logAll",
];

impl Category {
    const ALL: [Category; 5] = [
        Category::Events,
        Category::StatusWarning,
        Category::StatusError,
        Category::StatusFatal,
        Category::All,
    ];
    /// The declared name.
    pub fn name(self) -> &'static str {
        CATEGORY_NAMES[self as usize]
    }
    /// The category matching a message status.
    pub fn for_status(status: Fmi2Status) -> Category {
        match status {
            Fmi2Status::Ok | Fmi2Status::Pending => Category::Events,
            Fmi2Status::Warning | Fmi2Status::Discard => Category::StatusWarning,
            Fmi2Status::Error => Category::StatusError,
            Fmi2Status::Fatal => Category::StatusFatal,
        }
    }
    fn is_debug(self) -> bool {
        matches!(self, Category::Events | Category::All)
    }
}

/// The master's logger plus the instance's filter settings.
#[derive(Debug)]
pub struct Logger {
    callbacks: Option<fmi2CallbackFunctions>,
    instance_name: CString,
    debug: bool,
    enabled: [bool; 5],
}

// SAFETY: the callback struct holds plain C function pointers and the master's
// opaque environment pointer; FMI lets an instance move between threads as long
// as it is not used concurrently, which is the master's duty.
unsafe impl Send for Logger {}

impl Logger {
    /// A logger for `instance_name`; `callbacks` may be absent (then nothing is logged).
    pub fn new(callbacks: Option<fmi2CallbackFunctions>, instance_name: &str, debug: bool) -> Self {
        Logger {
            callbacks,
            instance_name: to_cstring(instance_name),
            debug,
            // Status categories on; the debug categories follow loggingOn.
            enabled: [debug, true, true, true, debug],
        }
    }

    /// Would a message of this category reach the master?
    #[inline]
    pub fn wants(&self, cat: Category) -> bool {
        if self.callbacks.and_then(|c| c.logger).is_none() {
            return false;
        }
        self.enabled[cat as usize] && (!cat.is_debug() || self.debug)
    }

    /// Send `msg` with `status` under `cat` (if the filter lets it through).
    pub fn log(&self, status: Fmi2Status, cat: Category, msg: &str) {
        if !self.wants(cat) {
            return;
        }
        let Some(cb) = self.callbacks else { return };
        let Some(f) = cb.logger else { return };
        let text = to_cstring(msg);
        let category = to_cstring(cat.name());
        // SAFETY: every pointer is a live NUL-terminated string; the format is the
        // constant "%s" with exactly one string argument.
        unsafe {
            f(
                cb.component_environment,
                self.instance_name.as_ptr(),
                status,
                category.as_ptr(),
                c"%s".as_ptr(),
                text.as_ptr(),
            );
        }
    }

    /// Log with the category that matches the status.
    pub fn status(&self, status: Fmi2Status, msg: &str) {
        self.log(status, Category::for_status(status), msg);
    }

    /// fmi2SetDebugLogging: with no categories, switch debug logging on/off
    /// (logEvents and logAll follow it); with categories, switch those on/off.
    /// Unknown category names are an error (nothing is changed then).
    pub fn set_debug_logging(&mut self, on: bool, categories: &[&str]) -> Result<(), String> {
        if categories.is_empty() {
            self.debug = on;
            self.enabled[Category::Events as usize] = on;
            self.enabled[Category::All as usize] = on;
            return Ok(());
        }
        let mut idx = Vec::with_capacity(categories.len());
        for c in categories {
            match Category::ALL.iter().find(|k| k.name() == *c) {
                Some(k) => idx.push(*k as usize),
                None => {
                    return Err(format!(
                        "unknown log category \"{c}\" (known: {})",
                        CATEGORY_NAMES.join(", ")
                    ))
                }
            }
        }
        if on {
            // FMI 2.0 §2.1.5: with loggingOn and a category list, only the
            // listed categories are logged — except errors and fatal errors,
            // which always reach the master (a refused call must say why).
            self.enabled = [false; 5];
            self.enabled[Category::StatusError as usize] = true;
            self.enabled[Category::StatusFatal as usize] = true;
            self.debug = true;
        }
        for i in idx {
            self.enabled[i] = on;
        }
        Ok(())
    }
}

/// NUL-terminated copy of `s` (interior NULs become '?').
pub fn to_cstring(s: &str) -> CString {
    CString::new(s.replace('\0', "?")).unwrap_or_default()
}
