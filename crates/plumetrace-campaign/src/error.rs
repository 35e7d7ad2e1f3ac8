//! What can go wrong with a campaign, with the file, key or line it concerns.

use plumetrace_scenario::locate::at_line;

/// A campaign error.
#[derive(Debug, thiserror::Error)]
pub enum CampaignError {
    /// A file could not be read or written.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What failed.
        message: String,
    },
    /// The campaign file is malformed or has a bad value.
    #[error("{file}{}: {}{message}", at_line(*line), if key.is_empty() { String::new() } else { format!("{key}: ") })]
    Invalid {
        /// The campaign file.
        file: String,
        /// The line of the key in the file (or of the table it belongs in), when known.
        line: Option<usize>,
        /// Key path in it (empty for syntax errors, which name their line).
        key: String,
        /// What is wrong.
        message: String,
    },
    /// A scenario with a configuration and sweep point does not build.
    #[error("{file}{}: {group}: {message}", at_line(*line))]
    Group {
        /// The campaign file.
        file: String,
        /// The line of the campaign file that gives the key at fault, when it gives it (a key
        /// of the scenario's own file is not in it).
        line: Option<usize>,
        /// Scenario, configuration and sweep point.
        group: String,
        /// The scenario or planner error (with its key path).
        message: String,
    },
    /// A results file is damaged or belongs to another campaign.
    #[error("{path}{}: {message}", at_line(*line))]
    Results {
        /// The file.
        path: String,
        /// Line number, 1-based.
        line: Option<u64>,
        /// What is wrong.
        message: String,
    },
    /// A planner from outside the registry could not be made, or failed during a run.
    #[error("configuration '{config}', run seed {seed}: {message}")]
    External {
        /// The configuration it flies.
        config: String,
        /// The run's seed.
        seed: u64,
        /// What went wrong.
        message: String,
    },
    /// A chart could not be drawn.
    #[error("drawing {what}: {message}")]
    Chart {
        /// Which chart.
        what: String,
        /// Why.
        message: String,
    },
}

/// Why one run could not run: the `message` of its row (outcome `error`).
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// Its scenario did not build.
    #[error(transparent)]
    Campaign(#[from] CampaignError),
    /// Its mission could not be set up or flown.
    #[error(transparent)]
    Mission(#[from] plumetrace_mission::MissionError),
    /// Its summary has a number that is not finite.
    #[error("the summary has a number that is not finite ({at})")]
    NonFinite {
        /// Where in the summary.
        at: String,
    },
    /// The example run's track could not be written.
    #[error(transparent)]
    Example(std::io::Error),
    /// The example run's replay page could not be made or written.
    #[error(transparent)]
    Page(#[from] crate::example::PageError),
}

impl CampaignError {
    /// The error with the line of its key in `text` (the campaign file's), where it names a key
    /// and has no line yet: the key's own line, or the table's it belongs in
    /// ([`plumetrace_scenario::locate::line_of`]).
    pub fn located(mut self, text: &str) -> Self {
        if let CampaignError::Invalid { line, key, .. } = &mut self
            && line.is_none()
            && !key.is_empty()
        {
            *line = plumetrace_scenario::locate::line_of(text, key);
        }
        self
    }

    pub(crate) fn io(path: &std::path::Path, e: impl std::fmt::Display) -> Self {
        CampaignError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    }
}
