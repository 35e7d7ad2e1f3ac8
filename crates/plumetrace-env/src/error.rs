//! Errors of the environment models.

use std::path::PathBuf;

/// What can go wrong building or running an environment model.
#[derive(Debug, thiserror::Error)]
pub enum EnvError {
    /// A parameter is out of its valid range; `key` names it.
    #[error("{key}: {message}")]
    InvalidParameter {
        /// The parameter (config key path where known).
        key: String,
        /// What is wrong with it.
        message: String,
    },
    /// A data file could not be read or parsed.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong, with the line where known.
        message: String,
    },
    /// The flow field produced a non-finite or runaway velocity.
    #[error("flow.farrell: the field diverged at t = {time_s:?} s: {message}")]
    Diverged {
        /// Simulation time of the failure, s.
        time_s: f64,
        /// What was seen.
        message: String,
    },
}

impl EnvError {
    /// Shorthand for [`EnvError::InvalidParameter`].
    pub fn invalid(key: impl Into<String>, message: impl Into<String>) -> Self {
        EnvError::InvalidParameter {
            key: key.into(),
            message: message.into(),
        }
    }
}

/// Checks that `value` is finite and strictly positive.
pub fn require_positive(key: &str, value: f64) -> Result<(), EnvError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(EnvError::invalid(
            key,
            format!("must be a finite number > 0, got {value:?}"),
        ))
    }
}

/// Checks that `value` is finite and not negative.
pub fn require_non_negative(key: &str, value: f64) -> Result<(), EnvError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(EnvError::invalid(
            key,
            format!("must be a finite number >= 0, got {value:?}"),
        ))
    }
}

/// Checks that `value` is finite.
pub fn require_finite(key: &str, value: f64) -> Result<(), EnvError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(EnvError::invalid(
            key,
            format!("must be a finite number, got {value:?}"),
        ))
    }
}
