//! Errors as Python exceptions, with the same located messages as the command line.

use pyo3::create_exception;
use pyo3::prelude::*;

create_exception!(
    _plumetrace,
    PlumetraceError,
    pyo3::exceptions::PyException,
    "A scenario, campaign or planner error; the message names the file and the key."
);

/// `e` and its causes, as the command line prints them.
pub fn located(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let text = c.to_string();
        if !s.contains(&text) {
            s.push_str(": ");
            s.push_str(&text);
        }
        cause = c.source();
    }
    s
}

/// A plumetrace error as a Python exception.
pub fn to_py(e: impl std::error::Error) -> PyErr {
    PlumetraceError::new_err(located(&e))
}

/// A message as a Python exception.
pub fn msg(m: impl Into<String>) -> PyErr {
    PlumetraceError::new_err(m.into())
}
