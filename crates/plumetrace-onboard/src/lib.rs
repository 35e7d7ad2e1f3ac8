//! The planner on a vehicle.
//!
//! In the backseat-driver arrangement the vehicle's own computer (the front seat) keeps low-level
//! control and safety, and a payload computer (the back seat) sends it set-points. This crate is
//! the back seat: it reads navigation and the chemical sensor from a vehicle link, feeds any
//! registered planner the same [`plumetrace_core::SensorSnapshot`]s the simulator would, and
//! sends the planner's commands back, checked at one chokepoint. It depends on no simulator
//! crate, so what flies a vehicle is exactly what flew the simulations.
//!
//! - [`sentence`]: the line rule (framing and checksum) and field readers shared by the codecs;
//! - [`bluefin`]: the Bluefin standard payload interface sentences;
//! - [`iver`]: the Iver remote-helm sentences and their unit setting;
//! - [`chem`]: the chemical sensor's line input;
//! - [`current`]: the current meter's `$--CUR` sentences (measured flow);
//! - [`config`]: the onboard file (planner, mission geometry, chemical input, link, time);
//! - [`command`]: the chokepoint every command passes (finite, within the vehicle's limits);
//! - [`link`]: the link trait, the Bluefin and Iver protocols on TCP or a serial line,
//!   reconnection, keep-alives, acknowledgements and the raw traffic log;
//! - `moos` (the `moos` feature): a MOOS community client, its wire format and the MOOS link;
//! - [`runner`]: the onboard runner (snapshots in, checked commands out, pauses for safety);
//! - [`serial`]: raw serial lines and pseudo-terminals (no system library);
//! - [`geo`]: latitude and longitude to the local frame and back (GeographicLib geodesics).
//!
//! The snapshot log and the `.alog` files a run writes are `plumetrace_log`'s formats.

pub mod bluefin;
pub mod chem;
pub mod command;
pub mod config;
pub mod current;
pub mod geo;
pub mod iver;
pub mod link;
#[cfg(feature = "moos")]
pub mod moos;
pub mod runner;
pub mod sentence;
pub mod serial;

pub use sentence::{SentenceError, UtcTime};
