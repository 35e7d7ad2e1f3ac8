//! Scenario errors: every one names where (file or preset) and what (key path).

use crate::locate::at_line;

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
    #[error("{origin}{}: {}{message}", at_line(*line), if path.is_empty() { String::new() } else { format!("{path}: ") })]
    Parse {
        /// File or preset.
        origin: String,
        /// The line of the key in the file, when known.
        line: Option<usize>,
        /// Key path, e.g. `flow.farrell.nx` (empty when unknown).
        path: String,
        /// The parser's message (with line and column).
        message: String,
    },
    /// A value is out of range or inconsistent with another.
    #[error("{origin}{}: {path}: {message}", at_line(*line))]
    Invalid {
        /// File or preset.
        origin: String,
        /// The line of the key in the file, when known.
        line: Option<usize>,
        /// Key path.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// No preset has that name.
    #[error("no preset named '{name}'{} (known: {known})", match near { Some(n) => format!("; did you mean '{n}'?"), None => String::new() })]
    UnknownPreset {
        /// The name asked for.
        name: String,
        /// The nearest preset name, when one is near.
        near: Option<String>,
        /// The known names.
        known: String,
    },
}

impl ScenarioError {
    /// The error with the line of its key in `text` (the scenario's text), when it names a key
    /// written there ([`crate::locate::line_of`]).
    pub fn located(mut self, text: &str) -> Self {
        if let ScenarioError::Parse { path, line, .. } | ScenarioError::Invalid { path, line, .. } =
            &mut self
            && line.is_none()
            && !path.is_empty()
        {
            *line = crate::locate::line_of(text, path);
        }
        self
    }

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
