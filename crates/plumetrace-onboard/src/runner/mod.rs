//! The onboard runner: navigation and chemical readings from a [`Link`] become
//! [`SensorSnapshot`]s for the planner; its commands go back through the chokepoint.
//!
//! Safety comes first. The planner is paused, and the link sends the protocol's safe command
//! (or nothing, as configured), when navigation is older than `link.stale_nav_s`, when the link
//! is lost (it reconnects with back-off meanwhile), when a serial line has been silent for
//! `link.silence_timeout_s` (the device stays open) or when the front seat says it does not
//! accept commands; it resumes with the next fresh navigation record.
//!
//! Current readings (the `[flow]` table: `$--CUR` sentences on the vehicle link or an input of
//! their own) go into every snapshot as the latest [`plumetrace_core::FlowSample`], stamped on
//! arrival, as a simulated flow sensor's do; without them the planner keeps the prior flow
//! direction. A command that fails the chokepoint is not sent (the previous one stands) and is
//! counted.
//!
//! Time is either the wall clock (`real_time`) or the front seat's (`lock_step`): mission time
//! is then the time carried by the front seat's sentences since its first one (or, for a
//! protocol without times, the number of navigation records times `run.lock_step_period_s`),
//! and every navigation record gets exactly one command back, so a simulated front seat can
//! wait for it before stepping: the whole mission is deterministic.
//!
//! - `links.rs`: the links an onboard file describes ([`link_for`], [`chem_link_for`],
//!   [`flow_link_for`]);
//! - `flight.rs`: one run's loop (events in, snapshots decided, commands out, the checks after
//!   each poll);
//! - `state.rs`: the run's clock, pause and report.

mod flight;
mod links;
mod state;

pub use links::{chem_link_for, flow_link_for, link_for};

use crate::config::Onboard;
use crate::geo::OriginError;
use crate::link::Link;
use crate::protocol::sentence::LineCounts;
use flight::{FixOutcome, Flight};
use plumetrace_core::params::ParamError;
use plumetrace_core::{Decision, SensorSnapshot, Vec2};

/// Why a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunEnd {
    /// The planner finished its mission.
    Finished,
    /// The planner aborted.
    Aborted,
    /// `run.time_limit_s` was reached.
    TimeLimit,
    /// The link stayed down for `link.give_up_s`.
    LinkGaveUp,
}

/// A time the planner was paused.
#[derive(Debug, Clone, PartialEq)]
pub struct Pause {
    /// Mission time it started, s.
    pub start_s: f64,
    /// Mission time it ended (`None`: still paused at the end), s.
    pub end_s: Option<f64>,
    /// Why.
    pub reason: String,
}

/// What a run did.
#[derive(Debug, Clone, PartialEq)]
pub struct RunReport {
    /// Why it ended.
    pub end: RunEnd,
    /// Mission time at the end, s.
    pub time_s: f64,
    /// Navigation records received.
    pub nav_records: u64,
    /// Planner decisions.
    pub decisions: u64,
    /// Commands sent (resends for lock-step included).
    pub commands_sent: u64,
    /// Commands the chokepoint stopped.
    pub commands_rejected: u64,
    /// Safe commands sent (or, with `safe_command = "none"`, pauses that sent nothing).
    pub safe_commands: u64,
    /// Commands given up after every try without an acknowledgement.
    pub acks_given_up: u64,
    /// Times the link came up.
    pub connections: u64,
    /// The pauses, in order.
    pub pauses: Vec<Pause>,
    /// Declared source positions, m.
    pub declarations: Vec<Vec2>,
    /// What the planner reported when the run ended for a reason it did not choose
    /// (`Planner::run_ended`: a declaration it was holding), at `time_s`; its declarations are
    /// among `declarations` too.
    pub ended_events: Vec<plumetrace_core::PlannerEvent>,
    /// Lines accepted and rejected by the link.
    pub lines: LineCounts,
}

/// Why a run could not start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunError {
    /// The planner could not be built.
    #[error(transparent)]
    Planner(#[from] ParamError),
    /// The link's origin has no local frame.
    #[error(transparent)]
    Origin(#[from] OriginError),
    /// The file asks for a MOOS link and this build has none.
    #[error("{}", crate::config::MOOS_MISSING)]
    MoosMissing,
}

/// Runs the planner of `onboard` against `link` (and a separate chemical input `chem`, if
/// any) until it finishes, aborts, reaches the time limit or the link gives up. Every snapshot
/// and decision is shown to `observe` (the snapshot log, the `.alog` writer).
pub fn run(
    onboard: &Onboard,
    link: &mut dyn Link,
    chem_link: Option<&mut dyn Link>,
    observe: &mut dyn FnMut(&SensorSnapshot, &Decision),
) -> Result<RunReport, RunError> {
    let mut inputs: Vec<&mut dyn Link> = chem_link.into_iter().collect();
    run_with_inputs(onboard, link, &mut inputs, observe)
}

/// [`run`] with any number of separate sensor inputs (the chemical sensor, the current meter):
/// only their chemical and current readings count, their connection state is not the
/// vehicle's.
pub fn run_with_inputs(
    onboard: &Onboard,
    link: &mut dyn Link,
    inputs: &mut [&mut dyn Link],
    observe: &mut dyn FnMut(&SensorSnapshot, &Decision),
) -> Result<RunReport, RunError> {
    let mut flight = Flight::new(onboard)?;
    let end = loop {
        let mut fixes = Vec::new();
        for e in Flight::poll(link, inputs) {
            flight.take_event(link, e, &mut fixes);
        }
        for fix in fixes {
            match flight.take_fix(link, fix, observe) {
                FixOutcome::Next => {}
                FixOutcome::LimitReached => break,
                FixOutcome::PlannerEnded(end, t) => return Ok(flight.planner_ended(link, end, t)),
            }
        }
        if let Some(end) = flight.after_poll(link) {
            break end;
        }
    };
    Ok(flight.ended(link, end))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::{LinkEvent, NavFix, Outgoing};
    use crate::protocol::sentence::{LineCounts, UtcTime};
    use std::time::{Duration, Instant};

    /// A link that plays a script of events against the wall clock and records what is sent.
    struct Script {
        start: Instant,
        events: Vec<(f64, LinkEvent)>,
        sent: Vec<(f64, Outgoing)>,
        counts: LineCounts,
    }

    impl Link for Script {
        fn poll(&mut self, wait: Duration) -> Vec<LinkEvent> {
            std::thread::sleep(wait.min(Duration::from_millis(10)));
            let now = self.start.elapsed().as_secs_f64();
            let due = self.events.iter().take_while(|e| e.0 <= now).count();
            self.events.drain(..due).map(|e| e.1).collect()
        }
        fn send(&mut self, what: Outgoing, _time: UtcTime) {
            self.sent.push((self.start.elapsed().as_secs_f64(), what));
        }
        fn counts(&self) -> &LineCounts {
            &self.counts
        }
        fn connected(&self) -> bool {
            true
        }
    }

    fn nav(t: f64) -> (f64, LinkEvent) {
        (
            t,
            LinkEvent::Nav(NavFix {
                time: None,
                lat_deg: 36.18,
                lon_deg: -75.75 + 0.003,
                heading_deg: 270.0,
                speed_mps: 2.0,
                altitude_m: Some(2.0),
                depth_m: Some(6.0),
                gps: false,
            }),
        )
    }

    /// The AMP over a Bluefin link with one more `[link]` line and a time limit.
    fn amp_over_bluefin(link_line: &str, time_limit_s: f64) -> Onboard {
        let text = format!(
            "[mission]\nop_area = [[60.0, -80.0], [460.0, -80.0], [460.0, 80.0], [60.0, 80.0]]\n\
             prior_flow_toward_deg = 90.0\n[planner]\nkind = \"amp\"\n[link]\n\
             protocol = \"bluefin\"\naddress = \"127.0.0.1:1\"\n\
             origin = {{ lat_deg = 36.18, lon_deg = -75.75 }}\n{link_line}\n\
             [run]\ntime_limit_s = {time_limit_s:?}\n"
        );
        Onboard::from_toml(&text).unwrap_or_else(|e| panic!("{e}\n{text}"))
    }

    #[test]
    fn in_real_time_stale_navigation_pauses_the_planner_and_sends_the_safe_command() {
        let onboard = amp_over_bluefin("stale_nav_s = 0.3", 1.6);
        let mut events = vec![(0.0, LinkEvent::Connected)];
        events.extend([0.0, 0.1, 0.2].map(nav));
        // Silence from 0.2 s to 1.0 s.
        events.extend([1.0, 1.1, 1.2, 1.3].map(nav));
        let mut link = Script {
            start: Instant::now(),
            events,
            sent: Vec::new(),
            counts: LineCounts::default(),
        };
        let mut decisions = 0;
        let report = run(&onboard, &mut link, None, &mut |_, _| decisions += 1)
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(report.end, RunEnd::TimeLimit);
        assert_eq!(report.nav_records, 7);
        assert_eq!(decisions, 7);
        let stale: Vec<&Pause> = report
            .pauses
            .iter()
            .filter(|p| p.reason.starts_with("navigation older than 0.3 s"))
            .collect();
        assert_eq!(stale.len(), 1, "{:?}", report.pauses);
        let (start, end) = (stale[0].start_s, stale[0].end_s.unwrap_or(f64::NAN));
        assert!((0.5..0.8).contains(&start), "paused at {start}");
        assert!((1.0..1.2).contains(&end), "resumed at {end}");
        // The safe command went out once, between the commands before and after the silence.
        let safe: Vec<f64> = link
            .sent
            .iter()
            .filter(|s| s.1 == Outgoing::Safe)
            .map(|s| s.0)
            .collect();
        assert_eq!(safe.len(), 1, "{:?}", link.sent);
        assert!(
            !link
                .sent
                .iter()
                .any(|s| matches!(s.1, Outgoing::Steer(_)) && s.0 > start && s.0 < end)
        );
        assert!(
            link.sent
                .iter()
                .any(|s| matches!(s.1, Outgoing::Steer(_)) && s.0 >= end)
        );
    }

    #[test]
    fn a_link_that_connects_and_drops_without_navigation_gives_up() {
        let onboard = amp_over_bluefin("give_up_s = 0.5", 5.0);
        let flapping = |from: f64| {
            (0..20).flat_map(move |k| {
                let t = from + 0.1 * k as f64;
                [
                    (t, LinkEvent::Connected),
                    (t + 0.05, LinkEvent::Lost("closed by the peer".into())),
                ]
            })
        };
        // Up with navigation to 0.2 s, then a connection every 0.1 s that is dropped at once.
        let mut events = vec![(0.0, LinkEvent::Connected)];
        events.extend([0.0, 0.1, 0.2].map(nav));
        events.push((0.25, LinkEvent::Lost("closed by the peer".into())));
        events.extend(flapping(0.3));
        let mut link = Script {
            start: Instant::now(),
            events,
            sent: Vec::new(),
            counts: LineCounts::default(),
        };
        let started = Instant::now();
        let report =
            run(&onboard, &mut link, None, &mut |_, _| {}).unwrap_or_else(|e| panic!("{e}"));
        let wall = started.elapsed().as_secs_f64();
        assert_eq!(report.end, RunEnd::LinkGaveUp, "{report:?}");
        // Down since 0.25 s; given up 0.5 s later, not at the end of the flapping (2.3 s).
        assert!((0.7..1.6).contains(&wall), "gave up after {wall} s");
        assert!(report.connections >= 5, "{}", report.connections);
    }

    /// A planner that holds a declaration until its run ends.
    struct Holding;

    impl plumetrace_core::Planner for Holding {
        fn decide(&mut self, _: &SensorSnapshot) -> Decision {
            Decision::new(
                plumetrace_core::Command {
                    heading: plumetrace_core::Heading::NORTH,
                    speed_mps: 0.0,
                    vertical: plumetrace_core::VerticalCommand::Altitude(2.0),
                },
                plumetrace_core::PlanStatus::Running,
            )
        }
        fn run_ended(&mut self, _t_s: f64) -> Vec<plumetrace_core::PlannerEvent> {
            vec![plumetrace_core::PlannerEvent::Declared {
                pos_m: Vec2::new(100.0, -2.0),
                rule: plumetrace_core::DeclarationKind::new("held"),
            }]
        }
    }

    #[test]
    fn a_run_that_ends_on_its_own_records_what_the_planner_held() {
        let onboard = amp_over_bluefin("give_up_s = 0.5", 5.0);
        let flight = Flight::new(&onboard)
            .unwrap_or_else(|e| panic!("{e}"))
            .flying(Box::new(Holding));
        let mut link = Script {
            start: Instant::now(),
            events: Vec::new(),
            sent: Vec::new(),
            counts: LineCounts::default(),
        };
        let report = flight.ended(&mut link, RunEnd::LinkGaveUp);
        assert_eq!(report.end, RunEnd::LinkGaveUp);
        assert_eq!(report.declarations, vec![Vec2::new(100.0, -2.0)]);
        // The events themselves, for the .alog (with their rule).
        assert_eq!(
            report.ended_events,
            vec![plumetrace_core::PlannerEvent::Declared {
                pos_m: Vec2::new(100.0, -2.0),
                rule: plumetrace_core::DeclarationKind::new("held"),
            }]
        );
    }
}
