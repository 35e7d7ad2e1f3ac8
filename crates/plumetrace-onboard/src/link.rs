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
    /// The name of the process posting the vehicle's measurements, for a link whose traffic
    /// carries one (MOOS: the source of the `NAV_X` postings), filled in as it is learned; for
    /// `run.alog`'s source column.
    fn sensor_source(&self) -> Option<plumetrace_log::alog::SharedName> {
        None
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

/// The delay before a link's next connection attempt: doubled (up to
/// [`LinkTiming::reconnect_max`]) after each failed attempt and after each connection that was
/// lost before it carried a navigation record, and back to [`LinkTiming::reconnect_min`] once a
/// connection has carried one. So a peer that accepts and then drops every connection (a MOOSDB
/// re-sending a value the client refuses, a front seat that crashes at each connection) is
/// retried ever more slowly, not at the shortest delay for ever.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Backoff {
    delay: Duration,
    min: Duration,
    max: Duration,
    // Whether the current (or last) connection carried a navigation record.
    proven: bool,
}

impl Backoff {
    /// At the shortest delay.
    pub(crate) fn new(timing: &LinkTiming) -> Self {
        Backoff {
            delay: timing.reconnect_min,
            min: timing.reconnect_min,
            max: timing.reconnect_max.max(timing.reconnect_min),
            proven: false,
        }
    }

    /// The delay to wait now, the next one doubled.
    fn double(&mut self) -> Duration {
        let d = self.delay;
        self.delay = (self.delay * 2).min(self.max);
        d
    }

    /// A connection attempt failed: the delay before the next.
    pub(crate) fn failed(&mut self) -> Duration {
        self.double()
    }

    /// A connection opened: it has carried nothing yet.
    pub(crate) fn connected(&mut self) {
        self.proven = false;
    }

    /// The connection carried a navigation record: the delay is back to its least.
    pub(crate) fn carried(&mut self) {
        if !self.proven {
            self.proven = true;
            self.delay = self.min;
        }
    }

    /// The connection was lost: the delay before the next attempt (doubling on if it carried
    /// nothing).
    pub(crate) fn lost(&mut self) -> Duration {
        if std::mem::take(&mut self.proven) {
            self.delay
        } else {
            self.double()
        }
    }

    /// The delay the next failure would wait.
    pub(crate) fn current(&self) -> Duration {
        self.delay
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_connection_that_carries_nothing_does_not_reset_the_delay() {
        let s = Duration::from_secs_f64;
        let mut b = Backoff::new(&LinkTiming {
            silence_timeout: s(10.0),
            reconnect_min: s(0.5),
            reconnect_max: s(4.0),
        });
        assert_eq!(b.failed(), s(0.5));
        assert_eq!(b.failed(), s(1.0));
        // Connections accepted and dropped before any navigation: the delay grows to its most.
        let mut waits = Vec::new();
        for _ in 0..4 {
            b.connected();
            waits.push(b.lost());
        }
        assert_eq!(waits, [s(2.0), s(4.0), s(4.0), s(4.0)]);
        // One that carried a record: back to the least, and a loss waits only that.
        b.connected();
        b.carried();
        assert_eq!(b.lost(), s(0.5));
        assert_eq!(b.current(), s(0.5));
        // The next failure doubles from there.
        assert_eq!(b.failed(), s(0.5));
        assert_eq!(b.current(), s(1.0));
    }
}
