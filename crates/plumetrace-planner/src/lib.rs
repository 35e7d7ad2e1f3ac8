//! Onboard plume-tracing planners.
//!
//! A planner turns what one vehicle can know (a [`plumetrace_core::SensorSnapshot`]) into
//! commands, through the [`plumetrace_core::Planner`] trait. It depends on no simulator code, so
//! the same planner runs in simulation, on a replayed log or on a vehicle.
//!
//! - [`planners`]: the registry of every planner (parameters, defaults, bounds, validation,
//!   construction) and the mission geometry planners are built with;
//! - [`amp`]: the REMUS Adaptive Mission Planner: behaviours Go-To, Find, Track-In, Track-Out and
//!   Reacquire switched on the time since the last detection, source declaration after Track-Out,
//!   post-declaration mapping and multi-source (subregion) missions;
//! - [`avoid`]: obstacle avoidance over any planner (`avoid_obstacles = true`): the fuzzy
//!   following-obstacle layer with dynamic reference targets;
//! - [`behaviour`]: the small behaviour and arbiter traits planners are built from, and the
//!   behaviours any planner can use;
//! - [`estimate`]: the source-likelihood map (a posterior over source cells from every sample)
//!   and the expected-entropy move choice of infotaxis, with the windy grid world it is checked on;
//! - [`flow`]: the planner's running estimate of the current from flow measurements.
//! - [`formation`]: formation tracing (seed 004): surface leaders and an underwater follower on
//!   acoustic ranges.
//! - [`fuzzy`]: fuzzy navigation past obstacles (seed 001): Mamdani engine, side lock, DRTs.
//! - [`shared_keys`]: keys several planners share, declared once (the autopilot's, the source
//!   map's) and included in each planner's table.

pub mod avoid;
pub mod behaviour;
pub mod estimate;
pub mod flow;
pub mod fuzzy;
pub mod planners;
pub mod shared_keys;

pub use flow::FlowEstimate;
pub use planners::amp::{self, Amp, AmpParams, DeclarationRule, LostPointEviction, MappingParams};
pub use planners::formation::{
    self, FormationFollower, FormationFollowerParams, FormationLeader, FormationLeaderParams,
};
pub use planners::moth::{self, Moth, MothParams, MothStrategy};
pub use planners::{
    BuildContext, CommonParams, MissionGeometry, PLANNERS, PlannerConfig, PlannerEntry,
    PlannerKind, PlannerParams, PlannerSpec, registry_defaults, registry_markdown,
};
pub use shared_keys::{AutopilotKeys, MapKeys};
