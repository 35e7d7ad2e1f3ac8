//! A run's clock (the wall clock or the front seat's), its pause and its report.

use super::{Pause, RunEnd, RunReport};
use crate::link::{Link, Outgoing};
use crate::protocol::sentence::{LineCounts, UtcTime};
use std::time::{Instant, SystemTime};

/// The UTC time of day now.
fn utc_now() -> UtcTime {
    let s = SystemTime::now()
        .duration_since(SystemTime::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64());
    UtcTime::from_seconds(s.rem_euclid(86_400.0))
}

/// The clock, the pause and the report of a run.
pub(super) struct State {
    pub(super) lock_step: bool,
    pub(super) started: Instant,
    // The latest front-seat time the clock advanced to, and the milliseconds since the first.
    pub(super) last_time: Option<UtcTime>,
    pub(super) front_elapsed_ms: i64,
    pub(super) front_time: UtcTime,
    pub(super) clock_s: f64,
    pub(super) last_nav_s: Option<f64>,
    pub(super) last_nav_wall: Option<Instant>,
    pub(super) paused: Option<String>,
    pub(super) accepting: bool,
    pub(super) report: RunReport,
}

impl State {
    /// A run starting now, paused until navigation comes.
    pub(super) fn new(lock_step: bool) -> Self {
        State {
            lock_step,
            started: Instant::now(),
            last_time: None,
            front_elapsed_ms: 0,
            front_time: UtcTime::default(),
            clock_s: 0.0,
            last_nav_s: None,
            last_nav_wall: None,
            paused: Some("waiting for navigation".into()),
            accepting: true,
            report: RunReport {
                end: RunEnd::TimeLimit,
                time_s: 0.0,
                nav_records: 0,
                decisions: 0,
                commands_sent: 0,
                commands_rejected: 0,
                safe_commands: 0,
                acks_given_up: 0,
                connections: 0,
                pauses: Vec::new(),
                declarations: Vec::new(),
                ended_events: Vec::new(),
                lines: LineCounts::default(),
            },
        }
    }

    /// Mission time now, s.
    pub(super) fn now_s(&self) -> f64 {
        if self.lock_step {
            self.clock_s
        } else {
            self.started.elapsed().as_secs_f64()
        }
    }

    /// The time to stamp what is sent with.
    pub(super) fn stamp(&self) -> UtcTime {
        if self.lock_step {
            self.front_time
        } else {
            utc_now()
        }
    }

    /// Advances the lock-step clock to the front seat's time `t`: by the time since the latest
    /// one, the short way round the day (a midnight between them counts). A time behind the
    /// latest (a record stamped late, out of order) leaves the clock where it is.
    pub(super) fn tick(&mut self, t: UtcTime) {
        let Some(last) = self.last_time else {
            self.last_time = Some(t);
            return;
        };
        let d = t.offset_ms_from(last);
        if d > 0 {
            self.front_elapsed_ms += d;
            self.last_time = Some(t);
            self.clock_s = self.clock_s.max(self.front_elapsed_ms as f64 / 1000.0);
        }
    }

    /// Pauses the planner (once) and sends the safe command.
    pub(super) fn pause(&mut self, link: &mut dyn Link, reason: String) {
        if self.paused.is_some() {
            return;
        }
        let t = self.now_s();
        self.report.pauses.push(Pause {
            start_s: t,
            end_s: None,
            reason: reason.clone(),
        });
        self.paused = Some(reason);
        self.report.safe_commands += 1;
        if link.connected() {
            link.send(Outgoing::Safe, self.stamp());
        }
    }

    /// Ends a pause.
    pub(super) fn resume(&mut self) {
        if self.paused.take().is_some() {
            let t = self.now_s();
            if let Some(p) = self.report.pauses.last_mut() {
                p.end_s = Some(t);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_stamped_before_the_first_does_not_move_the_clock_a_day() {
        let mut s = State::new(true);
        let at = |h: f64| UtcTime::from_seconds(h);
        for t in [43_200.0, 43_199.0, 43_200.5, 43_201.0] {
            s.tick(at(t));
        }
        assert!((s.clock_s - 1.0).abs() < 1e-9, "{}", s.clock_s);
        // Midnight between two records.
        let mut s = State::new(true);
        for t in [86_399.5, 0.5, 1.0] {
            s.tick(at(t));
        }
        assert!((s.clock_s - 1.5).abs() < 1e-9, "{}", s.clock_s);
    }
}
