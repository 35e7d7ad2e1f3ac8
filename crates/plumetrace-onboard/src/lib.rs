//! The planner on a vehicle.
//!
//! In the backseat-driver arrangement the vehicle's own computer (the front seat) keeps low-level
//! control and safety, and a payload computer (the back seat) sends it set-points. This crate is
//! the back seat: it reads navigation and the chemical sensor from a vehicle link, feeds any
//! registered planner the same [`plumetrace_core::SensorSnapshot`]s the simulator would, and
//! sends the planner's commands back, checked at one chokepoint. It depends on no simulator
//! crate, so what flies a vehicle is exactly what flew the simulations.
//!
//! Its layers, from the bytes up:
//!
//! - [`protocol`]: what the lines mean: the sentence rule and the Bluefin, Iver, chemical and
//!   current-meter codecs, and the back seat's session of each protocol (acknowledgements,
//!   polls, keep-alives);
//! - [`transport`]: how the lines travel: TCP and serial connections, line framing, raw serial
//!   lines and pseudo-terminals, and the line link that carries a session over them
//!   (reconnection, counts, the raw traffic log);
//! - `moos` (the `moos` feature): a MOOS community client: its wire format, navigation from its
//!   postings, and the MOOS link;
//! - [`link`]: the link trait the runner drives and what links report;
//! - [`runner`]: the onboard runner (snapshots in, checked commands out, pauses for safety) and
//!   the links an onboard file describes;
//!
//! and beside them [`config`] (the onboard file: planner, mission geometry, chemical input, link,
//! time), [`command`] (the chokepoint every command passes: finite, within the vehicle's limits)
//! and [`geo`] (latitude and longitude to the local frame and back: the core's geodesy, re-exported).
//!
//! The snapshot log and the `.alog` files a run writes are `plumetrace_log`'s formats.

pub mod command;
pub mod config;
pub use plumetrace_core::geo;
pub mod link;
#[cfg(feature = "moos")]
pub mod moos;
pub mod protocol;
pub mod runner;
pub mod transport;
