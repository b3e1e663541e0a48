//! Logging through the importer's callback: always with the format `"%s"` (a `%` in a message is
//! never a directive), the copied instance name, and the importer's componentEnvironment.
use super::types::{Fmi2CallbackLogger, Fmi2ComponentEnvironment, Status};
use crate::error::{Error, Result};
use std::ffi::CString;

/// The log categories declared in `<LogCategories>`: `(name, description)`.
pub const CATEGORIES: [(&str, &str); 6] = [
    ("logEvents", "Solves, re-solves and other events (only with debug logging on)"),
    ("logStatusWarning", "Calls that return fmi2Warning"),
    ("logStatusDiscard", "Calls that return fmi2Discard"),
    ("logStatusError", "Calls that return fmi2Error"),
    ("logStatusFatal", "Calls that return fmi2Fatal"),
    ("logAll", "Every category"),
];

/// Which category a message belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Category {
    Events,
    Warning,
    Discard,
    Error,
    Fatal,
}

impl Category {
    fn index(self) -> usize {
        match self {
            Category::Events => 0,
            Category::Warning => 1,
            Category::Discard => 2,
            Category::Error => 3,
            Category::Fatal => 4,
        }
    }
    fn status(self) -> Status {
        match self {
            Category::Events => Status::Ok,
            Category::Warning => Status::Warning,
            Category::Discard => Status::Discard,
            Category::Error => Status::Error,
            Category::Fatal => Status::Fatal,
        }
    }
}

/// The instance's logger. Messages of status Warning and above are always passed on (an error
/// must never be silent); `logEvents` only when debug logging is on for it.
pub struct Logger {
    callback: Fmi2CallbackLogger,
    env: Fmi2ComponentEnvironment,
    name: CString,
    logging_on: bool,
    /// Enabled categories (by [`CATEGORIES`] index) when logging is on.
    enabled: [bool; CATEGORIES.len()],
}

impl Logger {
    /// `name` is copied; `env` is passed back unchanged.
    pub fn new(callback: Fmi2CallbackLogger, env: Fmi2ComponentEnvironment, name: &str, logging_on: bool) -> Self {
        Logger { callback, env, name: to_cstring(name), logging_on, enabled: [true; CATEGORIES.len()] }
    }

    pub fn instance_name(&self) -> &str {
        self.name.to_str().unwrap_or("?")
    }

    /// `fmi2SetDebugLogging`: `categories` empty = all. Unknown names are refused (nothing changes).
    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Result<()> {
        if let Some(bad) = categories.iter().find(|c| !CATEGORIES.iter().any(|(n, _)| n == c)) {
            let known: Vec<&str> = CATEGORIES.iter().map(|(n, _)| *n).collect();
            return Err(Error::input(format!("unknown log category \"{bad}\"; known: {}", known.join(", "))));
        }
        self.logging_on = on;
        if categories.is_empty() || categories.iter().any(|c| c == "logAll") {
            self.enabled = [true; CATEGORIES.len()];
        } else {
            self.enabled = [false; CATEGORIES.len()];
            for c in categories {
                let i = CATEGORIES.iter().position(|(n, _)| n == c).expect("checked above");
                self.enabled[i] = true;
            }
        }
        Ok(())
    }

    /// Whether a message of `category` would reach the importer (so callers can skip formatting).
    pub fn enabled(&self, category: Category) -> bool {
        self.callback.is_some() && (category != Category::Events || (self.logging_on && self.enabled[category.index()]))
    }

    pub fn log(&self, category: Category, message: &str) {
        if !self.enabled(category) {
            return;
        }
        let Some(cb) = self.callback else { return };
        let cat = to_cstring(CATEGORIES[category.index()].0);
        let msg = to_cstring(message);
        // SAFETY: the importer gave us this callback; the format is "%s" with exactly one
        // NUL-terminated string argument, so nothing in `msg` is interpreted.
        unsafe { cb(self.env, self.name.as_ptr(), category.status().raw(), cat.as_ptr(), c"%s".as_ptr(), msg.as_ptr()) };
    }

    pub fn event(&self, message: &str) {
        self.log(Category::Events, message)
    }
    pub fn warning(&self, message: &str) {
        self.log(Category::Warning, message)
    }
    pub fn discard(&self, message: &str) {
        self.log(Category::Discard, message)
    }
    pub fn error(&self, message: &str) {
        self.log(Category::Error, message)
    }
}

/// A C string of `s`, with interior NULs shown as `\0`.
pub fn to_cstring(s: &str) -> CString {
    CString::new(s.replace('\0', "\\0")).expect("no interior NUL left")
}

impl crate::fmi::EventLog for Logger {
    fn events_enabled(&self) -> bool {
        self.enabled(Category::Events)
    }
    fn event(&self, message: &str) {
        self.log(Category::Events, message)
    }
}
