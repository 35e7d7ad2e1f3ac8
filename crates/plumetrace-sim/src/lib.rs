//! Simulated vehicles: what really happens to a vehicle and what its sensors report.
//!
//! This crate is the simulator's side of a vehicle. It keeps the truth (where the vehicle is,
//! where it points, how high it flies) and produces what the onboard side may see: a navigation
//! estimate that drifts and jumps at fixes ([`nav`]), chemical, flow and obstacle-range samples
//! ([`sensors`]). The onboard side never depends on it.
//!
//! - [`vehicle`]: AUV and surface-craft dynamics: water-relative speed and compass heading
//!   commands, a first-order speed response, a turn-rate limit, drift with the current, and an
//!   altitude (or depth) hold with a slowly varying error;
//! - [`nav`]: dead reckoning from measured heading, speed and flow with a slowly drifting error,
//!   corrected by position fixes (long-baseline for an AUV, GPS for a surface craft);
//! - [`world`]: an environment and several vehicles stepped together in named, timed stages,
//!   with planners plugged in through `plumetrace_core::Planner`; the vehicles' side is a
//!   [`Fleet`], which only reads the environment, so several fleets can share one;
//! - [`sensors`]: the 10 Hz chemical sensor (readings; planners threshold them), an ADCP-like flow sensor
//!   with bias and a wrong-layer fault, and three-group obstacle range sensors.
//!
//! - [`comms`]: messages between vehicles through a channel model per link (acoustic modem,
//!   radio): delay, loss, range and one packet in flight per modem, seeded per link kind; and
//!   acoustic ranging (requests, echoes, ranges measured by the simulator with timing noise).

pub mod comms;
pub mod nav;
pub mod sensors;
pub mod vehicle;
pub mod world;

pub use comms::{ChannelParams, CommsParams, LossReason, RangingParams};
pub use nav::{FixEvent, NavParams, Navigator};
pub use sensors::{
    ChemSensor, ChemSensorParams, FlowFault, FlowSensor, FlowSensorParams, RangeSensor,
    RangeSensorParams,
};
pub use vehicle::{Vehicle, VehicleParams, VehicleState};
pub use world::{
    Fleet, Incident, Lap, SimVehicle, StageTimes, StepReport, World, WorldEvent, WorldView,
    steps_per_env_step,
};
