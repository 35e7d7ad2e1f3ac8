//! The simulated ocean of plumetrace.
//!
//! This crate is the simulator's truth: where the water goes ([`flow`]), where the chemical is
//! ([`plume`], [`steady`]), what the vehicles must not enter ([`obstacle`]) and the seeded random
//! streams that make every run reproducible ([`rng`]). The onboard side of plumetrace never
//! depends on it: a planner only sees what a vehicle's sensors report.
//!
//! The main types are [`Environment`], which steps a flow field and a plume together, the
//! [`FlowField`] trait with its four models, and [`ConcentrationField`], answered by the filament
//! plume, the steady plume and gridded fields alike.

mod csv_grid;
pub mod domain;
pub mod environment;
pub mod error;
pub mod field;
pub mod flow;
pub mod input;
pub mod kelp;
pub mod normal;
pub mod obstacle;
pub mod plume;
pub mod rng;
pub mod seabed;
mod simd;
pub use simd::vector_unit;
pub mod steady;
#[cfg(test)]
mod test_files;

pub use domain::Rect;
pub use environment::{Environment, FlowStepper, Plume, flow_schedule, flow_substeps};
pub use error::EnvError;
pub use field::{ConcentrationField, GridSpec, MeanConcentrationGrid};
pub use flow::{FlowField, FlowModel};
pub use kelp::{KelpFieldParams, kelp_field};
pub use obstacle::{ObstacleSet, SoftObstacle};
pub use plume::{
    DownflowSink, FilamentParams, FilamentPlume, PlumeStats, Source, VerticalBoundary,
};
pub use rng::{SimRng, StreamId, derive_seed, stream_rng};
pub use seabed::{Seabed, SeabedOptions};
