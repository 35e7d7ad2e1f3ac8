//! Errors of the environment models.

use std::path::PathBuf;

/// What can go wrong building or running an environment model.
#[derive(Debug, thiserror::Error)]
pub enum EnvError {
    /// A parameter is out of its valid range; `key` names it.
    #[error("{key}: {message}")]
    InvalidParameter {
        /// The parameter: the model's own field (`nx`, `vertices[3]`), placed under where the
        /// model sits by whoever holds it ([`EnvError::under`]).
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

    /// The error with its parameter `dt_s` named `key` instead (a caller that calls a step by
    /// its own name); other errors are returned as they are.
    pub fn renamed(self, key: &str) -> Self {
        match self {
            EnvError::InvalidParameter { key: k, message } if k == "dt_s" => {
                EnvError::invalid(key, message)
            }
            other => other,
        }
    }

    /// The error with its parameter placed under `path` ([`join_key`]): a model names only its
    /// own fields, and whoever holds it says where it sits (`vehicles[0].nav` of a scenario).
    /// Other errors are returned as they are.
    pub fn under(self, path: &str) -> Self {
        match self {
            EnvError::InvalidParameter { key, message } => EnvError::InvalidParameter {
                key: join_key(path, &key),
                message,
            },
            other => other,
        }
    }
}

/// `key` under `path`: `path.key`, `path[k]` for an index (`key` = `[k]`), `path` for an empty
/// key and `key` for an empty path.
pub fn join_key(path: &str, key: &str) -> String {
    if key.is_empty() {
        path.to_string()
    } else if path.is_empty() {
        key.to_string()
    } else if key.starts_with('[') {
        format!("{path}{key}")
    } else {
        format!("{path}.{key}")
    }
}

/// A polygon's fault as the error of its vertex list: a vertex that is not finite is named by
/// its index (`[k]`), every other fault by the list (an empty key).
impl From<plumetrace_core::PolygonError> for EnvError {
    fn from(e: plumetrace_core::PolygonError) -> Self {
        match e {
            plumetrace_core::PolygonError::NonFinite(k) => {
                EnvError::invalid(format!("[{k}]"), "is not finite")
            }
            other => EnvError::invalid("", other.to_string()),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_join_under_their_holder() {
        let cases = [
            (
                "vehicles[0].nav",
                "fix_interval_s",
                "vehicles[0].nav.fix_interval_s",
            ),
            ("mission.op_area", "[3]", "mission.op_area[3]"),
            ("kelp[1]", "", "kelp[1]"),
            ("", "sources[0].x_m", "sources[0].x_m"),
        ];
        for (path, key, want) in cases {
            assert_eq!(join_key(path, key), want);
        }
        let e = EnvError::invalid("rate_hz", "must be a finite number > 0, got 0.0")
            .under("flow_sensor")
            .under("vehicles[2]");
        assert_eq!(
            e.to_string(),
            "vehicles[2].flow_sensor.rate_hz: must be a finite number > 0, got 0.0"
        );
    }
}
