//! Vehicle links as the runner sees them: one small trait ([`Link`]), what a link reports
//! ([`LinkEvent`], [`NavFix`]), what the runner asks it to send ([`Outgoing`]) and its timing
//! ([`LinkTiming`]).
//!
//! The implementations are a line protocol on a line transport
//! ([`crate::transport::line_link::LineLink`]: the Bluefin and Iver sessions of
//! [`crate::protocol::session`] on TCP or a serial device) and, with the `moos` feature, the MOOS
//! community client (`crate::moos::link::MoosLink`). Nothing a link receives is acted on unless it
//! parsed: a malformed, out-of-range or checksum-failing line is counted (by kind), written to the
//! traffic log and dropped.

use crate::command::CheckedCommand;
use crate::protocol::sentence::{LineCounts, UtcTime};
use std::time::Duration;

/// A navigation record as the front seat reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavFix {
    /// The front seat's time of the record (`None`: the protocol carries none).
    pub time: Option<UtcTime>,
    /// Latitude, deg.
    pub lat_deg: f64,
    /// Longitude, deg.
    pub lon_deg: f64,
    /// Compass heading, deg.
    pub heading_deg: f64,
    /// Speed, m/s.
    pub speed_mps: f64,
    /// Height above the seabed, m.
    pub altitude_m: Option<f64>,
    /// Depth, m.
    pub depth_m: Option<f64>,
    /// Whether the position is a GPS fix.
    pub gps: bool,
}

/// What a link reports.
#[derive(Debug, Clone, PartialEq)]
pub enum LinkEvent {
    /// The link is up (again).
    Connected,
    /// The link went down (why).
    Lost(String),
    /// A serial line stays open but nothing has come for the silence timeout (a vehicle
    /// computer restarting, a cut cable): the planner pauses; the device is kept open and
    /// polled, and the next navigation record resumes it.
    Quiet(String),
    /// A complete navigation record.
    Nav(NavFix),
    /// A chemical reading.
    Chem(f64),
    /// A current reading (a `$--CUR` sentence): the water's velocity `(east, north)`, m/s.
    Flow(plumetrace_core::Vec2),
    /// The front seat's time, from any sentence that carries one.
    Clock(UtcTime),
    /// Whether the front seat accepts payload commands.
    Accepting(bool),
    /// A command was not acknowledged after every try.
    AckGaveUp,
    /// The front seat refused a command.
    Refused(String),
}

/// What the runner asks a link to send.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outgoing {
    /// Steer: a command that passed the chokepoint.
    Steer(CheckedCommand),
    /// The protocol's safe command (the planner is paused).
    Safe,
    /// The mission is over: the safe command and a final status.
    Finished,
}

/// A vehicle link as the runner sees it.
pub trait Link {
    /// Waits up to `wait` for traffic (connecting first if down and due) and returns what
    /// arrived; never panics on what the other side sends.
    fn poll(&mut self, wait: Duration) -> Vec<LinkEvent>;
    /// Sends a command, the safe command or the end, stamped with the front seat's `time`.
    fn send(&mut self, what: Outgoing, time: UtcTime);
    /// Lines accepted and rejected so far.
    fn counts(&self) -> &LineCounts;
    /// Whether the link is connected.
    fn connected(&self) -> bool;
    /// Ends the link after the last send, so that what was sent reaches the other side.
    fn close(&mut self) {}
    /// What the planner decided from a snapshot (before its command is sent). A link that
    /// publishes more than set-points (MOOS: behaviour, detections, declarations) uses it;
    /// the others ignore it.
    fn decided(
        &mut self,
        _snapshot: &plumetrace_core::SensorSnapshot,
        _decision: &plumetrace_core::Decision,
    ) {
    }
}

/// A link's timing settings.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkTiming {
    /// The link counts as lost after this long without a byte.
    pub silence_timeout: Duration,
    /// First reconnection delay; doubled after each failure.
    pub reconnect_min: Duration,
    /// Longest reconnection delay.
    pub reconnect_max: Duration,
}
