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
//! their own) go into every snapshot as the latest [`FlowSample`], stamped on arrival, as a
//! simulated flow sensor's do; without them the planner keeps the prior flow direction. A command that fails the
//! chokepoint is not sent (the previous one stands) and is counted.
//!
//! Time is either the wall clock (`real_time`) or the front seat's (`lock_step`): mission time
//! is then the time carried by the front seat's sentences since its first one (or, for a
//! protocol without times, the number of navigation records times `run.lock_step_period_s`),
//! and every navigation record gets exactly one command back, so a simulated front seat can
//! wait for it before stepping: the whole mission is deterministic.

use crate::command::{CheckedCommand, check};
use crate::config::{Onboard, ProtocolKind, RunMode, SafeAction};
use crate::geo::LocalFrame;
use crate::iver::Units;
use crate::link::{
    Bluefin, BluefinSettings, Endpoint, Iver, IverSettings, LineLink, Link, LinkEvent, LinkTiming,
    NavFix, Outgoing,
};
use crate::sentence::{LineCounts, UtcTime};
use plumetrace_core::{
    ChemSample, Decision, FlowSample, Heading, NavEstimate, PlanStatus, PlannerEvent,
    SensorSnapshot, Vec2, VehicleId,
};
use std::io::Write;
use std::time::{Duration, Instant, SystemTime};

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
    /// Lines accepted and rejected by the link.
    pub lines: LineCounts,
}

/// The link timing an onboard file sets.
fn timing(l: &crate::config::LinkFile) -> LinkTiming {
    let secs = Duration::from_secs_f64;
    LinkTiming {
        silence_timeout: secs(l.silence_timeout_s),
        reconnect_min: secs(l.reconnect_min_s),
        reconnect_max: secs(l.reconnect_max_s),
    }
}

/// Makes the link an onboard file describes; raw traffic goes to `traffic`. An error when the
/// file asks for a link this build does not have (MOOS without the `moos` feature).
pub fn link_for(
    onboard: &Onboard,
    traffic: Option<Box<dyn Write + Send>>,
) -> Result<Box<dyn Link>, String> {
    let l = &onboard.file.link;
    let secs = Duration::from_secs_f64;
    let safe_stop = l.safe_command == SafeAction::Stop;
    let (endpoint, protocol): (Endpoint, Box<dyn crate::link::Protocol>) = match l.protocol {
        ProtocolKind::Bluefin => (
            Endpoint::Tcp(l.address.clone().unwrap_or_default()),
            Box::new(Bluefin::new(BluefinSettings {
                ack_timeout: secs(l.ack_timeout_s),
                ack_tries: l.ack_tries,
                status_period: secs(l.status_period_s),
                safe_stop,
            })),
        ),
        ProtocolKind::Iver => (
            Endpoint::Serial {
                path: l.device.clone().unwrap_or_default(),
                baud: l.baud,
            },
            Box::new(Iver::new(IverSettings {
                units: Units {
                    remote_helm_major: l.remote_helm_major.unwrap_or(5),
                },
                poll_period: secs(l.poll_period_s),
                oms_timeout_s: l.oms_timeout_s,
                max_pitch_deg: 45.0,
                safe_stop,
            })),
        ),
        #[cfg(feature = "moos")]
        ProtocolKind::Moos => {
            return crate::moos::MoosLink::for_onboard(onboard, timing(l), traffic)
                .map(|m| Box::new(m) as Box<dyn Link>);
        }
        #[cfg(not(feature = "moos"))]
        ProtocolKind::Moos => return Err(crate::config::MOOS_MISSING.into()),
    };
    let c = &onboard.file.chemical;
    let on_link = c.address.is_none() && c.device.is_none();
    let mut link = LineLink::new(
        endpoint,
        protocol,
        on_link.then(|| c.line_format()),
        timing(l),
        traffic,
    );
    if let Some(f) = onboard
        .file
        .flow
        .as_ref()
        .filter(|f| f.address.is_none() && f.device.is_none())
    {
        link = link.with_flow(f.line_format());
    }
    link.set_lock_step(onboard.file.run.mode == RunMode::LockStep);
    Ok(Box::new(link))
}

/// Where the current meter's lines come from when not on the vehicle link.
fn flow_endpoint(onboard: &Onboard) -> Option<Endpoint> {
    let f = onboard.file.flow.as_ref()?;
    match (&f.address, &f.device) {
        (Some(a), _) => Some(Endpoint::Tcp(a.clone())),
        (None, Some(d)) => Some(Endpoint::Serial {
            path: d.clone(),
            baud: onboard.file.link.baud,
        }),
        (None, None) => None,
    }
}

/// The separate current-meter input an onboard file names (`flow.address` or `flow.device`),
/// unless it is the chemical input's too (then that input carries both); its raw lines go to
/// `traffic`.
pub fn flow_link_for(
    onboard: &Onboard,
    traffic: Option<Box<dyn Write + Send>>,
) -> Option<LineLink> {
    let endpoint = flow_endpoint(onboard)?;
    if chem_endpoint(onboard).as_ref() == Some(&endpoint) {
        return None;
    }
    let f = onboard.file.flow.as_ref()?;
    Some(
        LineLink::new(
            endpoint,
            Box::new(crate::link::ChemOnly),
            None,
            timing(&onboard.file.link),
            traffic,
        )
        .with_flow(f.line_format()),
    )
}

fn chem_endpoint(onboard: &Onboard) -> Option<Endpoint> {
    let c = &onboard.file.chemical;
    match (&c.address, &c.device) {
        (Some(a), _) => Some(Endpoint::Tcp(a.clone())),
        (None, Some(d)) => Some(Endpoint::Serial {
            path: d.clone(),
            baud: onboard.file.link.baud,
        }),
        (None, None) => None,
    }
}

/// The separate chemical input an onboard file names (`chemical.address` or
/// `chemical.device`), if any; its raw lines go to `traffic`.
pub fn chem_link_for(
    onboard: &Onboard,
    traffic: Option<Box<dyn Write + Send>>,
) -> Option<LineLink> {
    let c = &onboard.file.chemical;
    let endpoint = chem_endpoint(onboard)?;
    let shared = flow_endpoint(onboard).as_ref() == Some(&endpoint);
    let mut link = LineLink::new(
        endpoint,
        Box::new(crate::link::ChemOnly),
        Some(c.line_format()),
        timing(&onboard.file.link),
        traffic,
    );
    if let Some(f) = onboard.file.flow.as_ref().filter(|_| shared) {
        link = link.with_flow(f.line_format());
    }
    Some(link)
}

/// The UTC time of day now.
fn utc_now() -> UtcTime {
    let s = SystemTime::now()
        .duration_since(SystemTime::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64());
    UtcTime::from_seconds(s.rem_euclid(86_400.0))
}

struct State {
    lock_step: bool,
    started: Instant,
    first_time: Option<UtcTime>,
    front_time: UtcTime,
    clock_s: f64,
    last_nav_s: Option<f64>,
    last_nav_wall: Option<Instant>,
    paused: Option<String>,
    accepting: bool,
    report: RunReport,
}

impl State {
    fn now_s(&self) -> f64 {
        if self.lock_step {
            self.clock_s
        } else {
            self.started.elapsed().as_secs_f64()
        }
    }

    fn stamp(&self) -> UtcTime {
        if self.lock_step {
            self.front_time
        } else {
            utc_now()
        }
    }

    fn pause(&mut self, link: &mut dyn Link, reason: String) {
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

    fn resume(&mut self) {
        if self.paused.take().is_some() {
            let t = self.now_s();
            if let Some(p) = self.report.pauses.last_mut() {
                p.end_s = Some(t);
            }
        }
    }
}

/// Runs the planner of `onboard` against `link` (and a separate chemical input `chem`, if
/// any) until it finishes, aborts, reaches the time limit or the link gives up. Every snapshot
/// and decision is shown to `observe` (the snapshot log, the `.alog` writer).
pub fn run(
    onboard: &Onboard,
    link: &mut dyn Link,
    chem_link: Option<&mut dyn Link>,
    observe: &mut dyn FnMut(&SensorSnapshot, &Decision),
) -> Result<RunReport, String> {
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
) -> Result<RunReport, String> {
    let mut planner = onboard
        .planner
        .build(&onboard.context, "planner")
        .map_err(|e| e.to_string())?;
    let frame = LocalFrame::new(onboard.file.link.origin)?;
    let l = &onboard.file.link;
    let run = &onboard.file.run;
    let mut s = State {
        lock_step: run.mode == RunMode::LockStep,
        started: Instant::now(),
        first_time: None,
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
            lines: LineCounts::default(),
        },
    };
    let mut chem: Vec<ChemSample> = Vec::new();
    let mut flow: Option<FlowSample> = None;
    let mut last_fix_s: Option<f64> = None;
    let mut next_decision_s = f64::NEG_INFINITY;
    let mut current: Option<CheckedCommand> = None;
    let mut down_since: Option<Instant> = Some(Instant::now());
    let period = planner.decision_period_s();
    let end = loop {
        let mut events: Vec<LinkEvent> = Vec::new();
        for input in inputs.iter_mut() {
            // Only their readings count: their connection state is not the vehicle's.
            events.extend(
                input
                    .poll(Duration::ZERO)
                    .into_iter()
                    .filter(|e| matches!(e, LinkEvent::Chem(_) | LinkEvent::Flow(_))),
            );
        }
        events.extend(link.poll(Duration::from_millis(100)));
        let mut fixes: Vec<NavFix> = Vec::new();
        for e in events {
            match e {
                LinkEvent::Connected => {
                    down_since = None;
                    s.report.connections += 1;
                }
                LinkEvent::Lost(why) => {
                    down_since.get_or_insert_with(Instant::now);
                    s.pause(link, format!("link lost: {why}"));
                }
                LinkEvent::Quiet(why) => s.pause(link, format!("line silent: {why}")),
                LinkEvent::Clock(t) => {
                    s.front_time = t;
                    if s.lock_step {
                        let first = *s.first_time.get_or_insert(t);
                        s.clock_s = s.clock_s.max(t.since(first));
                        // Checked at every tick of the front seat's clock, so a pause starts
                        // at the same mission time whatever the batching of lines.
                        if s.last_nav_s.is_some_and(|n| s.clock_s - n > l.stale_nav_s) {
                            s.pause(link, format!("navigation older than {} s", l.stale_nav_s));
                        }
                    }
                }
                LinkEvent::Chem(reading) => chem.push(ChemSample {
                    time_s: s.now_s(),
                    reading,
                }),
                // Like a simulated flow sensor's: the latest reading, stamped on arrival, in
                // every snapshot until the next.
                LinkEvent::Flow(velocity_mps) => {
                    flow = Some(FlowSample {
                        time_s: s.now_s(),
                        velocity_mps,
                    });
                }
                LinkEvent::Accepting(a) => {
                    s.accepting = a;
                    if !a {
                        s.pause(link, "the front seat does not accept commands".into());
                    }
                }
                LinkEvent::Nav(f) => fixes.push(f),
                LinkEvent::AckGaveUp => s.report.acks_given_up += 1,
                LinkEvent::Refused(_) => s.report.commands_rejected += 1,
            }
        }
        for fix in fixes {
            s.report.nav_records += 1;
            let t = if !s.lock_step {
                s.now_s()
            } else if fix.time.is_some() {
                s.clock_s
            } else {
                s.clock_s = s.report.nav_records.saturating_sub(1) as f64 * run.lock_step_period_s;
                s.clock_s
            };
            s.last_nav_s = Some(t);
            s.last_nav_wall = Some(Instant::now());
            if s.accepting && link.connected() {
                s.resume();
            }
            if fix.gps {
                last_fix_s = Some(t);
            }
            let mut decided = false;
            if s.paused.is_none() && t >= next_decision_s - 1e-9 {
                let snapshot = SensorSnapshot {
                    time_s: t,
                    vehicle: VehicleId(0),
                    nav: NavEstimate {
                        pos_m: Some(frame.to_local(fix.lat_deg, fix.lon_deg)),
                        heading: Heading::from_deg(fix.heading_deg),
                        speed_mps: fix.speed_mps,
                        altitude_m: fix.altitude_m,
                        depth_m: fix.depth_m,
                        last_fix_s,
                    },
                    chem: std::mem::take(&mut chem),
                    flow,
                    ranges: None,
                    inbox: Vec::new(),
                };
                let decision = planner.decide(&snapshot);
                s.report.decisions += 1;
                next_decision_s = if period > 0.0 { t + period } else { t };
                observe(&snapshot, &decision);
                link.decided(&snapshot, &decision);
                for e in &decision.events {
                    if let PlannerEvent::Declared { pos_m, .. } = e {
                        s.report.declarations.push(*pos_m);
                    }
                }
                match decision.status {
                    PlanStatus::Running => {}
                    PlanStatus::Finished | PlanStatus::Abort => {
                        link.send(Outgoing::Finished, s.stamp());
                        s.report.lines = link.counts().clone();
                        link.close();
                        s.report.time_s = t;
                        s.report.end = if decision.status == PlanStatus::Finished {
                            RunEnd::Finished
                        } else {
                            RunEnd::Aborted
                        };
                        return Ok(s.report);
                    }
                }
                match check(&decision.command, &l.limits) {
                    Ok(c) => current = Some(c),
                    Err(_) => s.report.commands_rejected += 1,
                }
                decided = true;
            }
            // One command per navigation record in lock-step; in real time only new ones.
            if s.paused.is_none()
                && (decided || s.lock_step)
                && let Some(c) = current
            {
                link.send(Outgoing::Steer(c), s.stamp());
                s.report.commands_sent += 1;
            }
            if t >= run.time_limit_s {
                break;
            }
        }
        let t = s.now_s();
        if t >= run.time_limit_s {
            break RunEnd::TimeLimit;
        }
        let stale = match (s.lock_step, s.last_nav_s, s.last_nav_wall) {
            (true, Some(n), _) => t - n > l.stale_nav_s,
            (false, _, Some(w)) => w.elapsed().as_secs_f64() > l.stale_nav_s,
            _ => false,
        };
        if stale {
            s.pause(link, format!("navigation older than {} s", l.stale_nav_s));
        }
        if down_since.is_some_and(|d| d.elapsed().as_secs_f64() > l.give_up_s) {
            break RunEnd::LinkGaveUp;
        }
    };
    if link.connected() {
        link.send(Outgoing::Finished, s.stamp());
    }
    s.report.end = end;
    s.report.time_s = s.now_s();
    s.report.lines = link.counts().clone();
    link.close();
    Ok(s.report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::NavFix;

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

    #[test]
    fn in_real_time_stale_navigation_pauses_the_planner_and_sends_the_safe_command() {
        let text = r#"
[mission]
op_area = [[60.0, -80.0], [460.0, -80.0], [460.0, 80.0], [60.0, 80.0]]
prior_flow_toward_deg = 90.0
[planner]
kind = "amp"
[link]
protocol = "bluefin"
address = "127.0.0.1:1"
origin = { lat_deg = 36.18, lon_deg = -75.75 }
stale_nav_s = 0.3
[run]
time_limit_s = 1.6
"#;
        let onboard = Onboard::from_toml(text).unwrap_or_else(|e| panic!("{e}"));
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
}
