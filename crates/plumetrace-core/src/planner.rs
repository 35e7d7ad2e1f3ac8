//! The interface between a world (simulated, logged or real) and a planner.
//!
//! A planner receives one [`SensorSnapshot`] per decision and returns a [`Decision`]: the
//! command, the messages it sends, what it reports (events and telemetry), and whether the mission
//! goes on. The same planner code runs against the simulator, a replayed log or a vehicle link.
//!
//! Everything a planner reports is typed: behaviours are [`BehaviourKind`]s, declaration rules
//! [`DeclarationKind`]s (rules named by the planners that use them). Names in files come from
//! serde (`snake_case`), in one place.

use crate::{Command, Outgoing, SensorSnapshot, Vec2};
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

/// The behaviours of plume-tracing planners: one vocabulary shared by every planner, so that
/// figures colour them alike and campaigns can compare time spent in each.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BehaviourKind {
    /// Drive to the start of the search.
    GoTo,
    /// Drive to the next subregion, ignoring detections.
    Transit,
    /// Search for the plume.
    Find,
    /// Follow the plume up-flow while in contact.
    TrackIn,
    /// Cross the plume up-flow of the last contact after losing it.
    TrackOut,
    /// Search around where the plume was lost.
    Reacquire,
    /// Survey lanes over the area (exhaustive search).
    Survey,
    /// A pattern over a declared source (e.g. sidescan lines).
    Mapping,
    /// Go around an obstacle towards a reference target (the interrupted behaviour resumes
    /// after it).
    Avoid,
    /// Moves chosen for what they are expected to tell about the source (infotaxis).
    Infotaxis,
    /// Mission over: no more commands.
    Done,
}

impl BehaviourKind {
    /// Every behaviour, in the order above.
    pub const ALL: [BehaviourKind; 11] = [
        BehaviourKind::GoTo,
        BehaviourKind::Transit,
        BehaviourKind::Find,
        BehaviourKind::TrackIn,
        BehaviourKind::TrackOut,
        BehaviourKind::Reacquire,
        BehaviourKind::Survey,
        BehaviourKind::Mapping,
        BehaviourKind::Avoid,
        BehaviourKind::Infotaxis,
        BehaviourKind::Done,
    ];
}

/// What made a planner declare a source: the name of a declaration rule. Each planner declares
/// the rules it uses (with a line of doc each) in its own module, as constants made with
/// [`DeclarationKind::new`]; files carry the name (`"along_flow"`), and a rule read back from a
/// file keeps whatever name it had.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct DeclarationKind(Cow<'static, str>);

impl DeclarationKind {
    /// The rule called `name` (snake_case, as in files).
    pub const fn new(name: &'static str) -> Self {
        DeclarationKind(Cow::Borrowed(name))
    }

    /// The rule of a planner outside the registry (a Python planner, say), which names none.
    pub const CUSTOM: DeclarationKind = DeclarationKind::new("custom");

    /// Its name in files.
    pub fn name(&self) -> &str {
        &self.0
    }
}

impl std::fmt::Display for DeclarationKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl Serialize for DeclarationKind {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.0)
    }
}

impl<'de> Deserialize<'de> for DeclarationKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        String::deserialize(d).map(|name| DeclarationKind(Cow::Owned(name)))
    }
}

/// A declaration rule with what it means, as a planner documents the rules it uses.
#[derive(Debug, Clone, PartialEq)]
pub struct RuleDoc {
    /// The rule.
    pub rule: DeclarationKind,
    /// One line saying when it declares, and where.
    pub doc: &'static str,
}

/// Something a planner reports for the event stream (written to logs, never read back by the
/// planner).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "event")]
pub enum PlannerEvent {
    /// The active behaviour changed.
    Behaviour {
        /// The behaviour now active.
        behaviour: BehaviourKind,
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
    /// A saved lost point was moved: a position fix showed how far the navigation was off when
    /// it was saved (the AMP's `fix_smoothing`). The point is the latest saved of those last at
    /// `from_m` (a saved point's `pos_m` or an earlier move's `to_m`, the same bits): a planner
    /// moving several points at one spot at once moves the latest saved first.
    LostPointMoved {
        /// Where it was, m.
        from_m: Vec2,
        /// Where it is now, m.
        to_m: Vec2,
    },
    /// A source location was declared.
    Declared {
        /// Declared position, m.
        pos_m: Vec2,
        /// What made the planner declare.
        rule: DeclarationKind,
    },
    /// Work on a subregion of a multi-source mission started or ended.
    Region {
        /// Subregion index.
        index: usize,
        /// What happened.
        what: RegionEvent,
    },
    /// The op-area cage aborted the mission: the vehicle was too far outside.
    CageAbort {
        /// How far outside the op-area the estimate was, m.
        distance_outside_m: f64,
    },
    /// An obstacle was sensed: obstacle avoidance took over, with a virtual path through
    /// `pos_m` along the course the vehicle had.
    AvoidStart {
        /// Estimated position, m: the virtual path's origin.
        pos_m: Vec2,
        /// The vehicle's course then, the path's direction, deg (compass).
        course_deg: f64,
    },
    /// A dynamic reference target was placed on the virtual path.
    ReferenceTarget {
        /// The target, m.
        pos_m: Vec2,
    },
    /// The obstacle was passed: the interrupted behaviour resumed.
    AvoidEnd {
        /// Estimated position, m.
        pos_m: Vec2,
    },
}

impl PlannerEvent {
    /// The behaviour switched to, if this is a behaviour switch.
    pub fn behaviour(&self) -> Option<BehaviourKind> {
        match self {
            PlannerEvent::Behaviour { behaviour } => Some(*behaviour),
            _ => None,
        }
    }
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

/// What a planner believes, reported for logs and displays (never read back by the planner).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "event")]
pub enum Telemetry {
    /// The planner's current best guess of the source position.
    SourceEstimate {
        /// Estimated source position, m.
        pos_m: Vec2,
    },
    /// A formation member's state: its cross-flow scale and, for a follower, the ranges it
    /// measured to its left and right leaders against their set-point.
    Formation {
        /// Cross-flow scale `s_cw` (a follower's: the latest it heard, if any).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        scale_cw: Option<f64>,
        /// Latest measured ranges to the left and right leader, m (follower only).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        ranges_m: Option<[f64; 2]>,
        /// The vehicles those ranges are to: left and right leader (follower only).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        ranges_to: Option<[crate::VehicleId; 2]>,
        /// The range set-point, m (follower only).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        setpoint_m: Option<f64>,
        /// The member's filtered chemical reading.
        reading: f64,
        /// The confidence of the declaration just made (a leader's confirmed rule), 0 to 1.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        declaration_confidence: Option<f64>,
    },
    /// The state of the planner's source-likelihood map.
    SourceMap {
        /// Entropy of the posterior, bits.
        entropy_bits: f64,
        /// Centre of the most likely cell, m.
        peak_m: Vec2,
        /// Posterior mass within the declaration radius of the peak.
        mass: f64,
    },
    /// The whole posterior of the planner's source-likelihood map: a raster of cells over the
    /// op-area's bounding box, `log10` of each cell's probability (rounded to 0.01; cells
    /// outside the op-area, and those below 1e-12, at -12).
    SourceMapRaster {
        /// Lower-left corner of the raster, m.
        origin_m: Vec2,
        /// Cell size, m.
        cell_m: f64,
        /// Cells along x.
        nx: usize,
        /// Cells along y.
        ny: usize,
        /// `log10 p`, row by row from the south (`ny` rows of `nx`).
        log10_p: Vec<f32>,
    },
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
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Decision {
    /// What the vehicle should do until the next decision.
    pub command: Command,
    /// Messages to send; the world (or the vehicle's modem) delivers them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub outbox: Vec<Outgoing>,
    /// Events for the log, in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub events: Vec<PlannerEvent>,
    /// What the planner reports about its beliefs, for the log.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub telemetry: Vec<Telemetry>,
    /// Whether the mission goes on.
    pub status: PlanStatus,
}

impl Decision {
    /// A decision with only a command and a status.
    pub fn new(command: Command, status: PlanStatus) -> Self {
        Decision {
            command,
            outbox: Vec::new(),
            events: Vec::new(),
            telemetry: Vec::new(),
            status,
        }
    }
}

/// A planner: decides one vehicle's commands from what that vehicle can know.
///
/// Kept small on purpose: behaviours, arbitration and the autopilot live in the onboard crates;
/// a world needs only this.
pub trait Planner: Send {
    /// The decision for this snapshot (samples and messages since the previous one).
    fn decide(&mut self, snapshot: &SensorSnapshot) -> Decision;

    /// Time between decisions, s; 0 means at every step of the world. Between decisions the
    /// vehicle keeps its last command and samples accumulate for the next snapshot.
    fn decision_period_s(&self) -> f64 {
        0.0
    }

    /// Control comes back after a detour this planner did not fly (obstacle avoidance took the
    /// vehicle around an obstacle), with the vehicle at `pos_m`, off the planner's own path. A
    /// planner that lost the plume meanwhile may search around this point; the default does
    /// nothing.
    fn detour_ended(&mut self, pos_m: Vec2) {
        let _ = pos_m;
    }

    /// The run ends at `t_s` for a reason the planner did not choose (on a vehicle: the link
    /// given up, the time limit; in a simulated mission: the time limit, a collision, leaving the
    /// domain): what it still has to report, such as a declaration it was holding. Called once,
    /// after the last decision. The default has nothing.
    fn run_ended(&mut self, t_s: f64) -> Vec<PlannerEvent> {
        let _ = t_s;
        Vec::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Heading, VerticalCommand};

    #[test]
    fn decisions_round_trip_through_json_exactly_with_names_from_serde() {
        let d = Decision {
            command: Command {
                heading: Heading::from_deg(123.456_789_012_345),
                speed_mps: 1.0 / 3.0,
                vertical: VerticalCommand::Altitude(2.0),
            },
            outbox: vec![],
            events: vec![
                PlannerEvent::Behaviour {
                    behaviour: BehaviourKind::TrackIn,
                },
                PlannerEvent::Declared {
                    pos_m: Vec2::new(0.1, -7.0e-9),
                    rule: DeclarationKind::new("upflow_edge"),
                },
            ],
            telemetry: vec![Telemetry::SourceEstimate {
                pos_m: Vec2::new(1.5, 2.5),
            }],
            status: PlanStatus::Running,
        };
        let text = serde_json::to_string(&d).unwrap_or_default();
        assert!(text.contains(r#""behaviour":"track_in""#), "{text}");
        assert!(text.contains(r#""rule":"upflow_edge""#), "{text}");
        assert!(!text.contains("outbox"), "empty lists are left out: {text}");
        let back: Decision = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}: {text}"));
        assert_eq!(back, d);
    }
}
