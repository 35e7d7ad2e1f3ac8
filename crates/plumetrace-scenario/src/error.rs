//! Scenario errors: every one names where (file or preset) and what (key path).

/// What can go wrong reading or building a scenario.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("{origin}: {message}")]
    Io {
        /// File or preset.
        origin: String,
        /// The I/O error.
        message: String,
    },
    /// The TOML is malformed, has an unknown key or a value of the wrong type.
    #[error("{origin}: {}{message}", if path.is_empty() { String::new() } else { format!("{path}: ") })]
    Parse {
        /// File or preset.
        origin: String,
        /// Key path, e.g. `flow.farrell.nx` (empty when unknown).
        path: String,
        /// The parser's message (with line and column).
        message: String,
    },
    /// A value is out of range or inconsistent with another.
    #[error("{origin}: {path}: {message}")]
    Invalid {
        /// File or preset.
        origin: String,
        /// Key path.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// No preset has that name.
    #[error("no preset named '{name}' (known: {known})")]
    UnknownPreset {
        /// The name asked for.
        name: String,
        /// The known names.
        known: String,
    },
}

impl ScenarioError {
    /// The key path of the error, if it has one.
    pub fn key_path(&self) -> Option<&str> {
        match self {
            ScenarioError::Parse { path, .. } | ScenarioError::Invalid { path, .. }
                if !path.is_empty() =>
            {
                Some(path)
            }
            _ => None,
        }
    }
}
