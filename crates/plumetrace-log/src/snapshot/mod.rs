//! The snapshot log: every snapshot a planner received and every decision it returned, one JSON
//! object per line, so that a mission can be replayed through a planner.
//!
//! Format (`snapshots.jsonl.gz`: gzip-compressed JSON lines, `zcat` reads it; version 1):
//! - line 1, the header: `{"format": "plumetrace-snapshots", "version": 1, "scenario": NAME,
//!   "seed": N, "vehicles": [{"id": 0, "name": "auv", "planner_key": "planner",
//!   "planner": "<the planner's table as TOML, every key>", "context": {...}}]}`, one entry per
//!   vehicle with a planner (`context` is the planner's build context: mission geometry, vehicle
//!   id and kind);
//! - then one line per decision, in the order they were made:
//!   `{"vehicle": 0, "snapshot": {...}, "decision": {...}}` (the core `SensorSnapshot` and
//!   `Decision`, serde's field names; numbers round-trip exactly).
//!
//! The format lives in a crate both sides use, so a vehicle process writes the same log as a
//! simulated mission. [`SnapshotLogFile`] writes it (`file.rs`, with [`open`] to read it back);
//! [`replay`] builds a fresh planner per vehicle from the header (or from other tables) and feeds
//! it the logged snapshots; [`ReplayReport`] says which decisions differ (`replay.rs`).

mod file;
mod replay;

pub use file::{SnapshotLogFile, open};
pub use replay::{
    Defaulted, Difference, ReplayError, ReplayReport, Replayed, read_header, replay, replay_with,
    same,
};

use crate::LogError;
use plumetrace_core::{Decision, SensorSnapshot};
use plumetrace_planner::{BuildContext, PlannerConfig};
use serde::{Deserialize, Serialize};

/// What the header needs of one vehicle's planner (the mission's planned vehicles and the
/// onboard runner's planner both give it).
pub trait LoggablePlanner {
    /// The planner table's key path (`planner` or `planners.NAME`).
    fn key(&self) -> &str;
    /// The planner's configuration.
    fn config(&self) -> &PlannerConfig;
    /// What it is built with.
    fn context(&self) -> &BuildContext;
}

/// The header's `format` value.
pub const FORMAT: &str = "plumetrace-snapshots";
/// The format version this code writes and reads.
pub const VERSION: u32 = 1;

/// One vehicle's planner in the header.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoggedPlanner {
    /// Vehicle index.
    pub id: u32,
    /// Vehicle name.
    pub name: String,
    /// The planner table's key path in the scenario.
    pub planner_key: String,
    /// The planner's table as TOML (every key, defaults included).
    pub planner: String,
    /// What it was built with.
    pub context: BuildContext,
}

/// The first line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// Scenario name.
    pub scenario: String,
    /// Run seed.
    pub seed: u64,
    /// The vehicles with planners.
    pub vehicles: Vec<LoggedPlanner>,
}

impl Header {
    /// The header of a mission's planners; an error if a planner's table cannot be written.
    pub fn new<P: LoggablePlanner>(
        scenario: &str,
        seed: u64,
        names: &[String],
        planners: &[Option<P>],
    ) -> Result<Self, LogError> {
        let mut vehicles = Vec::new();
        for (k, p) in planners.iter().enumerate() {
            let Some(p) = p else { continue };
            let table_error = |error| LogError::PlannerTable {
                key: p.key().to_string(),
                error,
            };
            let table = p.config().to_table().map_err(table_error)?;
            vehicles.push(LoggedPlanner {
                id: k as u32,
                name: names.get(k).cloned().unwrap_or_default(),
                planner_key: p.key().to_string(),
                planner: toml::to_string(&table).map_err(table_error)?,
                context: p.context().clone(),
            });
        }
        Ok(Header {
            format: FORMAT.into(),
            version: VERSION,
            scenario: scenario.into(),
            seed,
            vehicles,
        })
    }
}

/// One decision line.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct Line {
    /// Vehicle index.
    pub vehicle: u32,
    /// What the planner received.
    pub snapshot: SensorSnapshot,
    /// What it returned.
    pub decision: Decision,
}
