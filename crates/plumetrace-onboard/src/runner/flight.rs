//! One run of the planner against its links: the events of each poll taken in, a snapshot built
//! and decided from each navigation record, the checked command sent, and the checks after each
//! poll (time limit, stale navigation, a link down too long).

use super::state::State;
use super::{RunEnd, RunError, RunReport};
use crate::command::{CheckedCommand, check};
use crate::config::{Onboard, RunMode};
use crate::geo::LocalFrame;
use crate::link::{Link, LinkEvent, NavFix, Outgoing};
use plumetrace_core::{
    ChemSample, Decision, FlowSample, Heading, NavEstimate, PlanStatus, Planner, PlannerEvent,
    SensorSnapshot, VehicleId,
};
use std::time::{Duration, Instant};

/// What came of one navigation record.
pub(super) enum FixOutcome {
    /// Go on with the next.
    Next,
    /// The record reached the time limit: no more records this poll.
    LimitReached,
    /// The planner finished or aborted at this mission time, s.
    PlannerEnded(RunEnd, f64),
}

/// Everything a run keeps between polls.
pub(super) struct Flight<'a> {
    onboard: &'a Onboard,
    planner: Box<dyn Planner>,
    frame: LocalFrame,
    s: State,
    chem: Vec<ChemSample>,
    flow: Option<FlowSample>,
    last_fix_s: Option<f64>,
    next_decision_s: f64,
    current: Option<CheckedCommand>,
    // Since when the link has been down (cleared when a connection opens), and what it was
    // before that connection: a connection lost before it carried a navigation record does not
    // count as the link having been up, so a peer that accepts and drops every connection still
    // ends the run after `link.give_up_s`.
    down_since: Option<Instant>,
    down_before: Option<Instant>,
    carried: bool,
    period: f64,
}

impl<'a> Flight<'a> {
    /// The same flight with `planner` in place of the one `onboard` builds (tests).
    #[cfg(test)]
    pub(super) fn flying(mut self, planner: Box<dyn Planner>) -> Self {
        self.planner = planner;
        self
    }

    /// The planner of `onboard` built and its clock started, paused until navigation comes.
    pub(super) fn new(onboard: &'a Onboard) -> Result<Self, RunError> {
        let planner = onboard.planner.build(&onboard.context, "planner")?;
        let frame = LocalFrame::new(onboard.file.link.origin)?;
        let s = State::new(onboard.file.run.mode == RunMode::LockStep);
        let period = planner.decision_period_s();
        Ok(Flight {
            onboard,
            planner,
            frame,
            s,
            chem: Vec::new(),
            flow: None,
            last_fix_s: None,
            next_decision_s: f64::NEG_INFINITY,
            current: None,
            down_since: Some(Instant::now()),
            down_before: None,
            carried: false,
            period,
        })
    }

    /// What the separate inputs and the vehicle link have: of the inputs, only their chemical
    /// and current readings (their connection state is not the vehicle's).
    pub(super) fn poll(link: &mut dyn Link, inputs: &mut [&mut dyn Link]) -> Vec<LinkEvent> {
        let mut events: Vec<LinkEvent> = Vec::new();
        for input in inputs.iter_mut() {
            events.extend(
                input
                    .poll(Duration::ZERO)
                    .into_iter()
                    .filter(|e| matches!(e, LinkEvent::Chem(_) | LinkEvent::Flow(_))),
            );
        }
        events.extend(link.poll(Duration::from_millis(100)));
        events
    }

    /// Takes one event; a navigation record goes to `fixes`.
    pub(super) fn take_event(
        &mut self,
        link: &mut dyn Link,
        e: LinkEvent,
        fixes: &mut Vec<NavFix>,
    ) {
        let onboard = self.onboard;
        let l = &onboard.file.link;
        let s = &mut self.s;
        match e {
            LinkEvent::Connected => {
                self.down_before = self.down_since.take();
                self.carried = false;
                s.report.connections += 1;
            }
            LinkEvent::Lost(why) => {
                if self.down_since.is_none() {
                    let before = self.down_before.filter(|_| !self.carried);
                    self.down_since = Some(before.unwrap_or_else(Instant::now));
                }
                s.pause(link, format!("link lost: {why}"));
            }
            LinkEvent::Quiet(why) => s.pause(link, format!("line silent: {why}")),
            LinkEvent::Clock(t) => {
                s.front_time = t;
                if s.lock_step {
                    s.tick(t);
                    // Checked at every tick of the front seat's clock, so a pause starts
                    // at the same mission time whatever the batching of lines.
                    if s.last_nav_s.is_some_and(|n| s.clock_s - n > l.stale_nav_s) {
                        s.pause(link, format!("navigation older than {} s", l.stale_nav_s));
                    }
                }
            }
            LinkEvent::Chem(reading) => self.chem.push(ChemSample {
                time_s: s.now_s(),
                reading,
            }),
            // Like a simulated flow sensor's: the latest reading, stamped on arrival, in
            // every snapshot until the next.
            LinkEvent::Flow(velocity_mps) => {
                self.flow = Some(FlowSample {
                    time_s: s.now_s(),
                    velocity_mps,
                });
            }
            LinkEvent::Accepting(a) => {
                s.accepting = a;
                // The front seat's last tick at the time limit: the run's end sends the final
                // stop, once.
                let ending = s.lock_step && s.clock_s >= onboard.file.run.time_limit_s;
                if !a && !ending {
                    s.pause(link, "the front seat does not accept commands".into());
                }
            }
            LinkEvent::Nav(f) => {
                self.carried = true;
                self.down_before = None;
                fixes.push(f);
            }
            LinkEvent::AckGaveUp => s.report.acks_given_up += 1,
            LinkEvent::Refused(_) => s.report.commands_rejected += 1,
        }
    }

    /// The mission time of a navigation record (lock-step over a protocol without times: the
    /// records counted).
    fn fix_time(&mut self, fix: &NavFix) -> f64 {
        let s = &mut self.s;
        if !s.lock_step {
            s.now_s()
        } else if fix.time.is_some() {
            s.clock_s
        } else {
            s.clock_s = s.report.nav_records.saturating_sub(1) as f64
                * self.onboard.file.run.lock_step_period_s;
            s.clock_s
        }
    }

    /// The snapshot of a navigation record at mission time `t`, with the chemical readings
    /// since the last one.
    fn snapshot(&mut self, fix: &NavFix, t: f64) -> SensorSnapshot {
        SensorSnapshot {
            time_s: t,
            vehicle: VehicleId(0),
            nav: NavEstimate {
                pos_m: Some(self.frame.to_local(fix.lat_deg, fix.lon_deg)),
                heading: Heading::from_deg(fix.heading_deg),
                speed_mps: fix.speed_mps,
                altitude_m: fix.altitude_m,
                depth_m: fix.depth_m,
                last_fix_s: self.last_fix_s,
            },
            chem: std::mem::take(&mut self.chem),
            flow: self.flow,
            ranges: None,
            inbox: Vec::new(),
        }
    }

    /// Takes one navigation record: the planner decides when it is due and not paused, and a
    /// command goes out (one per record in lock-step, only new ones in real time).
    pub(super) fn take_fix(
        &mut self,
        link: &mut dyn Link,
        fix: NavFix,
        observe: &mut dyn FnMut(&SensorSnapshot, &Decision),
    ) -> FixOutcome {
        self.s.report.nav_records += 1;
        let t = self.fix_time(&fix);
        self.s.last_nav_s = Some(t);
        self.s.last_nav_wall = Some(Instant::now());
        if self.s.accepting && link.connected() {
            self.s.resume();
        }
        if fix.gps {
            self.last_fix_s = Some(t);
        }
        let mut decided = false;
        if self.s.paused.is_none() && t >= self.next_decision_s - 1e-9 {
            let snapshot = self.snapshot(&fix, t);
            let decision = self.planner.decide(&snapshot);
            self.s.report.decisions += 1;
            self.next_decision_s = if self.period > 0.0 {
                t + self.period
            } else {
                t
            };
            observe(&snapshot, &decision);
            link.decided(&snapshot, &decision);
            for e in &decision.events {
                if let PlannerEvent::Declared { pos_m, .. } = e {
                    self.s.report.declarations.push(*pos_m);
                }
            }
            match decision.status {
                PlanStatus::Running => {}
                PlanStatus::Finished => return FixOutcome::PlannerEnded(RunEnd::Finished, t),
                PlanStatus::Abort => return FixOutcome::PlannerEnded(RunEnd::Aborted, t),
            }
            match check(&decision.command, &self.onboard.file.link.limits) {
                Ok(c) => self.current = Some(c),
                Err(_) => self.s.report.commands_rejected += 1,
            }
            decided = true;
        }
        if self.s.paused.is_none()
            && (decided || self.s.lock_step)
            && let Some(c) = self.current
        {
            link.send(Outgoing::Steer(c), self.s.stamp());
            self.s.report.commands_sent += 1;
        }
        if t >= self.onboard.file.run.time_limit_s {
            FixOutcome::LimitReached
        } else {
            FixOutcome::Next
        }
    }

    /// The checks after a poll: the time limit, stale navigation (a pause), a link down for
    /// longer than `link.give_up_s`.
    pub(super) fn after_poll(&mut self, link: &mut dyn Link) -> Option<RunEnd> {
        let onboard = self.onboard;
        let l = &onboard.file.link;
        let t = self.s.now_s();
        if t >= self.onboard.file.run.time_limit_s {
            return Some(RunEnd::TimeLimit);
        }
        let stale = match (self.s.lock_step, self.s.last_nav_s, self.s.last_nav_wall) {
            (true, Some(n), _) => t - n > l.stale_nav_s,
            (false, _, Some(w)) => w.elapsed().as_secs_f64() > l.stale_nav_s,
            _ => false,
        };
        if stale {
            self.s
                .pause(link, format!("navigation older than {} s", l.stale_nav_s));
        }
        if self
            .down_since
            .is_some_and(|d| d.elapsed().as_secs_f64() > l.give_up_s)
        {
            return Some(RunEnd::LinkGaveUp);
        }
        None
    }

    /// The end the planner chose at mission time `t`: the end sent, the link closed.
    pub(super) fn planner_ended(mut self, link: &mut dyn Link, end: RunEnd, t: f64) -> RunReport {
        link.send(Outgoing::Finished, self.s.stamp());
        self.s.report.lines = link.counts().clone();
        link.close();
        self.s.report.time_s = t;
        self.s.report.end = end;
        self.s.report
    }

    /// Any other end: what the planner still has to report (a declaration it was holding)
    /// recorded, the end sent if the link is up, the link closed.
    pub(super) fn ended(mut self, link: &mut dyn Link, end: RunEnd) -> RunReport {
        let t = self.s.now_s();
        for e in self.planner.run_ended(t) {
            if let PlannerEvent::Declared { pos_m, .. } = e {
                self.s.report.declarations.push(pos_m);
            }
            self.s.report.ended_events.push(e);
        }
        if link.connected() {
            link.send(Outgoing::Finished, self.s.stamp());
        }
        self.s.report.end = end;
        self.s.report.time_s = t;
        self.s.report.lines = link.counts().clone();
        link.close();
        self.s.report
    }
}
