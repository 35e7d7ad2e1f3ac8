//! Missions: an onboard planner flying simulated vehicles until an outcome.
//!
//! This crate is where the two sides meet. It builds planners from a scenario's `[planner]`
//! table, puts them in a [`plumetrace_sim::World`] built from the scenario, develops the plume
//! first (spin-up), steps the world until every planner has finished, a vehicle stopped or the
//! time limit, and records what happened: the trajectory, the event stream, a summary with the
//! declaration errors, and a figure.

pub mod output;
pub mod planner_config;
pub mod plot;
pub mod run;

pub use planner_config::{PlannerError, amp_params};
pub use run::{
    DeclarationRecord, LOCATED_RADIUS_M, MissionError, MissionOptions, MissionRun, Outcome,
    SourceRecord, Summary, TrajectoryRow, run_mission, run_mission_with,
};
