//! Onboard estimation of where the source is: a probability map over candidate source cells,
//! built from what the vehicle measures, and the expected-entropy move choice that reads it.
//!
//! - [`map`]: the source-likelihood map over the op-area (log domain, normalised after every
//!   sample): each chemical sample, detection or not, is back-projected along the measured flow
//!   history with a spread that grows with travel time, a vertical-mixing factor for a bottom
//!   source seen from the vehicle's altitude, and an intermittency model (a sample inside the
//!   plume detects only with some probability, so a non-detection there is weak evidence);
//! - [`infotaxis`]: the one-step outcome model of a candidate move (the chance of a hit, of
//!   finding the source, and the posterior entropy after each outcome) and the two objectives
//!   that rank moves, infotaxis and space-aware infotaxis; the infotaxis planner and the
//!   grid-world benchmark both choose their moves with it;
//! - [`tracker`]: the map as a planner keeps it (fed from snapshots, read on a period, the
//!   declaration rule: mass within a radius of the most likely cell);
//! - [`gridworld`]: the windy grid world of the published infotaxis benchmark (mean hit rates of
//!   an advection-diffusion model on a lattice), the model a searcher there knows.
//!
//! Nothing here draws random numbers: the map and the choice are deterministic functions of
//! their inputs (same samples, same map).

pub mod gridworld;
pub mod infotaxis;
pub mod map;
pub mod tracker;

pub use infotaxis::{MoveOutcome, Objective, entropy_bits};
pub use map::{MapModel, SourceMap};
pub use tracker::{MapRead, MapRule, MapTracker};
