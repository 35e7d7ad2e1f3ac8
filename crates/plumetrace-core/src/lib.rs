//! Shared value types of plumetrace.
//!
//! This crate is the vocabulary that the simulator side and the onboard side (guidance, behaviours,
//! planners) have in common. It holds no randomness and no models, so the onboard side can depend on
//! it without seeing anything a real vehicle could not know.
//!
//! Conventions, used everywhere in plumetrace:
//! - positions in metres in a local tangent plane, `x` = East, `y` = North, `z` = height above the
//!   seabed (positive up);
//! - headings and courses in compass degrees (clockwise from North) at the edges (configs, logs,
//!   plots), radians inside [`Heading`];
//! - flow directions are the direction the water moves *towards*;
//! - time in seconds, as an integer step count times a fixed `dt`.

pub mod angle;
pub mod any_f64;
pub mod file_name;
pub mod finite;
pub mod flow_gate;
pub mod frame;
pub mod geo;
pub mod message;
pub mod names;
pub mod params;
pub mod planner;
pub mod vector;
pub mod vehicle;

pub use angle::{Heading, wrap_deg_180, wrap_deg_360, wrap_rad_pi};
pub use finite::first_non_finite;
pub use flow_gate::{FlowGate, FlowGateParams};
pub use frame::{
    PolygonError, Vec2, Vec3, bearing_between, check_polygon, heading_vector, self_intersection,
    signed_area2,
};
pub use message::{Link, Message, MessageBody, Outgoing, Recipient};
pub use names::{closest, plain_types, toml_message, variant_name};
pub use planner::{
    BehaviourKind, Decision, DeclarationKind, PlanStatus, Planner, PlannerEvent, RegionEvent,
    RuleDoc, Telemetry,
};
pub use vehicle::{
    ChemSample, Command, FlowSample, NavEstimate, RangeReturn, SensorSnapshot, VehicleId,
    VehicleKind, VerticalCommand,
};
