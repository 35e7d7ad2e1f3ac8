//! The interface between a world (simulated, logged or real) and a planner.
//!
//! A planner receives one [`SensorSnapshot`] per decision and returns a [`Decision`]: the
//! command, anything worth logging, and whether the mission goes on. The same planner code runs
//! against the simulator, a replayed log or a vehicle link.

use crate::{Command, SensorSnapshot, Vec2};
use serde::{Deserialize, Serialize};

/// Something a planner reports for the event stream (written to logs, never read back).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "event")]
pub enum PlannerEvent {
    /// The active behaviour changed.
    Behaviour {
        /// The behaviour now active (a registry name such as `"track_in"`).
        name: &'static str,
    },
    /// A detection was registered (the first after a gap, to keep logs small).
    Detection {
        /// Estimated position, m.
        pos_m: Vec2,
    },
    /// A point where plume contact was lost was saved.
    LostPoint {
        /// Estimated position, m.
        pos_m: Vec2,
    },
    /// A source location was declared.
    Declared {
        /// Declared position, m.
        pos_m: Vec2,
        /// Which rule declared it (a registry name such as `"along_flow"`).
        rule: &'static str,
    },
    /// Work on a subregion of a multi-source mission started or ended.
    Region {
        /// Subregion index.
        index: usize,
        /// What happened.
        what: RegionEvent,
    },
}

/// What happened to a subregion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RegionEvent {
    /// Search started.
    Started,
    /// A source was declared inside it.
    Declared,
    /// The plume was traced to its upflow edge; a source was declared there.
    DeclaredAtEdge,
    /// The search timed out: declared source-free.
    TimedOut,
}

/// Whether the mission goes on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanStatus {
    /// Keep going.
    Running,
    /// The planner has finished its mission (declared and mapped, or searched everything).
    Finished,
    /// The planner aborts the mission (e.g. the cage: far outside the op-area).
    Abort,
}

/// A planner's answer to one snapshot.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Decision {
    /// What the vehicle should do until the next decision.
    pub command: Command,
    /// Events for the log, in order.
    pub events: Vec<PlannerEvent>,
    /// Whether the mission goes on.
    pub status: PlanStatus,
}

/// A planner: decides one vehicle's commands from what that vehicle can know.
pub trait Planner: Send {
    /// A short name for logs ("amp", ...).
    fn name(&self) -> &'static str;

    /// The decision for this snapshot.
    fn decide(&mut self, snapshot: &SensorSnapshot) -> Decision;

    /// Declared source positions so far, in order.
    fn declarations(&self) -> Vec<Vec2>;
}
