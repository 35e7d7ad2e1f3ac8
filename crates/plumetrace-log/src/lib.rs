//! The log formats both sides of plumetrace write: a simulated mission and a vehicle process log
//! the same way, so a run on a vehicle replays like a simulated one and opens in the same tools.
//!
//! - [`snapshot`]: the snapshot log (every snapshot a planner received and every decision it
//!   returned), its file writer and reader, and its replay through fresh planners;
//! - [`alog`]: a MOOS `.alog` writer (navigation, set-points and the plume-tracing variables).
//!
//! It depends only on the core types and the planner registry (to rebuild a logged planner), not
//! on the simulator nor on any vehicle link.

pub mod alog;
pub mod snapshot;

use std::path::PathBuf;

/// Why a snapshot log could not be written.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// A planner's table could not be written into the header.
    #[error("{key}: {error}")]
    PlannerTable {
        /// The planner table's key path.
        key: String,
        /// What went wrong.
        error: toml::ser::Error,
    },
    /// A line was written after the log was finished.
    #[error("the log is already finished")]
    Finished,
    /// A line could not be serialised.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A line could not be written.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// The file could not be completed or given its name.
    #[error("{}: {error}", path.display())]
    Finish {
        /// The log's path.
        path: PathBuf,
        /// What went wrong.
        error: std::io::Error,
    },
}
