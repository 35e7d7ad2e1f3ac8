//! Missions: onboard planners flying simulated vehicles until an outcome.
//!
//! This crate is where the two sides meet. [`MissionSetup`] reads every vehicle's planner from
//! a built scenario through the planner registry (so `check` catches every bad key), [`Mission`]
//! develops the plume first (spin-up) and steps the world until every planner has finished or
//! stopped or the time limit comes, and observers record what happened: the events, every
//! vehicle's trajectory, a summary with the declaration errors, and a snapshot log that a planner
//! can replay. Figures and pages are drawn from the finished run by the report crate.
//!
//! - [`setup`]: scenario to mission, planners checked;
//! - [`mission`]: the stepper ([`Mission::new`], [`Mission::step`], [`Mission::finish`]);
//! - [`shared`]: several missions of one scenario and seed in one environment
//!   ([`fly_shared`]), each with the result it has alone;
//! - [`outcome`]: how a mission ends and what it comes to;
//! - [`record`]: the observer trait and the mission's own recorders;
//! - [`summary`]: the key numbers written as `summary.json`; [`team`]: what a team of vehicles
//!   did together (formation error, centroid against the centre line, overhead, losses);
//! - [`metrics`]: the run metrics, declared once ([`RunMetrics`]: name, type, unit, meaning and
//!   how each is read from the summary), which campaigns and the Python bindings read;
//! - [`snapshot_log`]: the observer writing the replayable log of snapshots and decisions (its
//!   format and replay are `plumetrace_log`'s);
//! - [`alog`]: MOOS `.alog` files, one per planned vehicle (the log crate's writer);
//! - [`output`]: atomic file writing.

pub mod alog;
pub mod metrics;
pub mod mission;
pub mod outcome;
pub mod output;
pub mod record;
pub mod setup;
pub mod shared;
pub mod snapshot_log;
pub mod summary;
pub mod team;

pub use metrics::{Column, ColumnKind, Columns, Leaf, MetricContext, RunMetrics, Value};
pub use mission::{
    FaultWindow, Mission, MissionOptions, MissionRun, PLUME_FRAME_EVERY_S, VehicleInfo,
    run_mission, run_mission_with,
};
pub use outcome::{EndReason, MissionEnd, MissionEvent, Outcome, VehicleStatus};
pub use plumetrace_planner::PlannerKind;
pub use plumetrace_planner::planners::kind_name as planner_kind_name;
pub use plumetrace_planner::registry_defaults as planner_defaults;
pub use record::{
    EventKind, EventRecord, LostPointTrack, Observer, PlumeFrame, PlumeFrames, RecordError,
    StepView, TrajectoryRow, lost_points,
};
pub use setup::{MissionError, MissionSetup, PlannedVehicle};
pub use shared::fly_shared;
pub use summary::{DeclarationRecord, SourceRecord, Summary, VehicleSummary};
pub use team::{TeamStats, TeamSummary};

/// serde, for the code [`columns!`] makes in other crates.
#[doc(hidden)]
pub use serde as __serde;
