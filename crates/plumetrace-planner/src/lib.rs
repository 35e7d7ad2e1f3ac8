//! Onboard plume-tracing planners.
//!
//! A planner turns what one vehicle can know (a [`plumetrace_core::SensorSnapshot`]) into
//! commands, through the [`plumetrace_core::Planner`] trait. It depends on no simulator code, so
//! the same planner runs in simulation, on a replayed log or on a vehicle.
//!
//! - [`amp`]: the REMUS Adaptive Mission Planner: behaviours Go-To, Find, Track-In, Track-Out and
//!   Reacquire switched on the time since the last detection, source declaration after Track-Out,
//!   post-declaration mapping and multi-source (subregion) missions.
//! - [`flow`]: the planner's running estimate of the current from flow measurements.

pub mod amp;
pub mod flow;

pub use amp::{Amp, AmpParams, DeclarationRule, LostPointEviction, MappingParams};
pub use flow::FlowEstimate;

/// Every planner plumetrace knows, for `list` commands and campaign files.
pub const REGISTRY: &[(&str, &str)] = &[(
    "amp",
    "REMUS Adaptive Mission Planner: Find, Track-In, Track-Out, Reacquire (Bowtie), declaration, mapping",
)];
