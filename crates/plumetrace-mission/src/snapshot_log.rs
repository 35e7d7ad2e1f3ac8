//! The snapshot log of a simulated mission: an observer that writes every snapshot a planner
//! received and every decision it returned (the format, the file and the replay are the log
//! crate's, [`plumetrace_log::snapshot`]).

use crate::record::{Observer, RecordError, StepView};
use crate::setup::PlannedVehicle;
use plumetrace_log::snapshot::{Header, LoggablePlanner, SnapshotLogFile};
use plumetrace_planner::{BuildContext, PlannerConfig};
use std::path::Path;

impl LoggablePlanner for PlannedVehicle {
    fn key(&self) -> &str {
        &self.key
    }
    fn config(&self) -> &PlannerConfig {
        &self.config
    }
    fn context(&self) -> &BuildContext {
        &self.context
    }
}

/// Writes the log as the mission runs: gzip-compressed into a temporary file beside `path`,
/// renamed to `path` when the mission finishes (a crash leaves no partial log under the name).
pub struct SnapshotLogWriter {
    file: SnapshotLogFile,
    error: Option<String>,
}

impl SnapshotLogWriter {
    /// Starts the log at `path` (conventionally `snapshots.jsonl.gz`) with `header`.
    pub fn create(path: &Path, header: &Header) -> std::io::Result<Self> {
        Ok(SnapshotLogWriter {
            file: SnapshotLogFile::create(path, header)?,
            error: None,
        })
    }
}

impl Observer for SnapshotLogWriter {
    fn observe(&mut self, step: &StepView<'_>) {
        if self.error.is_some() {
            return;
        }
        for (k, snapshot, decision) in step.decided() {
            if let Err(e) = self.file.write(k as u32, snapshot, decision) {
                self.error = Some(e.to_string());
                return;
            }
        }
    }

    fn wants_snapshots(&self) -> bool {
        true
    }

    fn finish(&mut self) -> Result<(), RecordError> {
        if let Some(e) = self.error.take() {
            return Err(RecordError::file(self.file.path(), e));
        }
        self.file.finish().map_err(RecordError::Log)
    }
}
