//! A simulated front seat. It flies a scenario's vehicle and plume and speaks a front-seat
//! protocol to a back seat (`plumetrace onboard`, or any back seat built on
//! `plumetrace_onboard`): the Bluefin standard payload interface on a TCP port, or the Iver remote
//! helm on a pseudo-terminal. The vehicle's planner slot holds the front seat, which reports the
//! vehicle's navigation estimate and chemical and current readings on the link and steers by the
//! commands that come back, so a whole mission can be rehearsed on one machine and tests can fly
//! the real link end to end.
//!
//! In lock-step the front seat waits for the command that answers each navigation record before
//! it steps on: the mission is then deterministic. Faults can be injected ([`Faults`]): dropped
//! lines, delays, garbage lines, a silent period (no navigation; the clock goes on in `$BFCTL`
//! lines), a restart (the connection and the listening socket closed for a while).
//!
//! - [`options`]: what a rehearsal is asked for, and its checks;
//! - [`rehearsal`]: a rehearsal prepared (the port or pseudo-terminal open, the onboard file for
//!   its back seat), started (the mission built) and flown;
//! - `seat.rs`: the front seat in the planner slot (navigation out, commands in);
//! - `wire.rs`: its end of the line (accepting, sending with faults, reading, restarting);
//! - [`stats`]: what the front seat saw;
//! - `onboard_file.rs`: the onboard file of the scenario's planner for this link.
//!
//! It is simulator-side: it uses the mission crate and the onboard crate's codecs, and no back
//! seat depends on it.

mod onboard_file;
pub mod options;
pub mod rehearsal;
mod seat;
pub mod stats;
mod wire;

pub use options::{Faults, FrontSeatOptions, Protocol};
pub use rehearsal::{Flight, FrontSeatReport, Rehearsal};
pub use stats::FrontSeatStats;

use plumetrace_mission::MissionError;

/// Why a rehearsal could not be prepared or flown.
#[derive(Debug, thiserror::Error)]
pub enum FrontSeatError {
    /// An option is out of its bounds (named as the `plumetrace frontseat` flag).
    #[error("{option}: {message}")]
    Option {
        /// The option's flag (`--drop`, ...).
        option: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The scenario has no vehicle with a planner.
    #[error("the scenario has no vehicle with a planner")]
    NoPlanner,
    /// The TCP port could not be opened.
    #[error("listening on {address}: {error}")]
    Listen {
        /// The address asked for.
        address: String,
        /// What went wrong.
        error: std::io::Error,
    },
    /// No pseudo-terminal could be opened.
    #[error("opening a pseudo-terminal: {0}")]
    Pty(std::io::Error),
    /// Another input or output error.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// The onboard file could not be written.
    #[error(transparent)]
    Table(#[from] toml::ser::Error),
    /// The mission could not be set up or flown.
    #[error(transparent)]
    Mission(#[from] MissionError),
}
