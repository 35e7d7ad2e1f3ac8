//! Onboard guidance: turning a goal into heading and speed commands a vehicle can follow.
//!
//! This crate runs on the vehicle (or its backseat computer). It depends only on
//! `plumetrace-core` and sees only what a vehicle knows: its navigation estimate, its measured
//! flow and time. It implements the guidance modes of the REMUS plume-tracing system:
//! - [`GoToPoint`]: head for a point, arrive within a radius;
//! - [`FollowLine`]: approach the start of a segment with the right heading, then hold the line
//!   with a proportional cross-track law, exiting near the end or once past it;
//! - [`GoToPointWithHeading`]: the shortest of the four CSC Dubins paths (LSL, LSR, RSL, RSR) with
//!   a minimum turning radius, followed by pursuit;
//! - [`Cage`]: keep the vehicle inside the [`OpArea`] by removing the outward part of commands near
//!   the edge, steering back when outside, aborting far outside;
//! - [`RateFilter`]: limit the commanded heading rate;
//! - [`compensate_flow`]: the water-relative heading and speed that keep the ground track on the
//!   desired course in a current (crab angle), or a report that the current is too strong;
//! - [`Autopilot`]: the three above in the order every planner uses them (cage, flow
//!   compensation, rate filter), turning a desired course over ground into a command.
//!
//! Headings are compass headings ([`plumetrace_core::Heading`]); the Dubins crate's
//! anticlockwise-from-East angles are converted at its boundary only.

mod autopilot;
mod cage;
mod dubins;
mod flow_comp;
mod geometry;
mod line;
mod op_area;
mod point;
mod rate;

pub use autopilot::{Autopilot, AutopilotParams, CageAbort};
pub use cage::{Cage, CageAction};
pub use dubins::{CscPath, CscWord, GoToPointWithHeading, Pose, csc_candidates, shortest_csc};
pub use flow_comp::{FlowCompensation, compensate_flow};
pub use geometry::{along_track_m, signed_cross_track_m};
pub use line::{FollowLine, FollowLinePhase};
pub use op_area::{EdgeInfo, OpArea, OpAreaError};
pub use point::GoToPoint;
pub use rate::RateFilter;

use plumetrace_core::Heading;

/// What a guidance mode asks for at one decision time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Steer {
    /// Desired course over ground (before flow compensation and rate filtering).
    pub heading: Heading,
    /// Desired speed, m/s.
    pub speed_mps: f64,
}

/// The state of a guidance mode after a decision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModeStatus {
    /// Still working towards its goal; steer with this.
    Running(Steer),
    /// The goal is reached (the mode's exit condition held).
    Done(DoneReason),
}

/// Why a guidance mode finished.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DoneReason {
    /// Within the arrival radius of the destination (eq. 6).
    Arrived,
    /// Passed the end of the line by more than `R_L` along it (eq. 10).
    PassedEnd,
    /// Within the arrival radius and heading tolerance of a posed destination.
    ArrivedWithHeading,
    /// A posed approach that needed more re-plans than it is allowed: the path cannot be flown
    /// (e.g. its turns lie where the cage or the current keeps the vehicle from going).
    GaveUp,
}
