//! The back seat's side of each line protocol, as a session a line link drives ([`Protocol`]):
//! what to say on connecting, how to read a line, how to write a command, what is due
//! periodically. [`Bluefin`]: subscriptions, acknowledgements with resends and give-ups, the
//! status keep-alive. [`Iver`]: navigation polls (after each command in lock-step), the `$OMS`
//! resent before its timeout. [`ChemOnly`]: a sensor's own line, which is only read.

use crate::command::{CheckedCommand, Vertical};
use crate::link::{LinkEvent, NavFix, Outgoing};
use crate::protocol::bluefin::{self, AckStatus, HorizontalMode, Rmb, SpeedMode, VerticalMode};
use crate::protocol::iver::{self, M_PER_FT, MPS_PER_KN, Oms, Units};
use crate::protocol::sentence::{SentenceError, UtcTime};
use std::time::{Duration, Instant};

/// One protocol's side of a link: what to say on connecting, how to read a line, how to write a
/// command, what to send periodically.
pub trait Protocol: Send {
    /// Lines sent on (re)connecting.
    fn hello(&mut self) -> Vec<String>;
    /// Reads one received line into events.
    fn read(&mut self, line: &str, events: &mut Vec<LinkEvent>) -> Result<(), SentenceError>;
    /// Lines for an outgoing command.
    fn write(&mut self, what: Outgoing, time: UtcTime, now: Instant) -> Vec<String>;
    /// Lines due now (keep-alives, resends, polls); events such as a give-up.
    fn tick(&mut self, now: Instant, time: UtcTime, events: &mut Vec<LinkEvent>) -> Vec<String>;
    /// Whether the protocol sends the next navigation poll only after a command (lock-step).
    fn set_lock_step(&mut self, on: bool);
}

/// The Bluefin protocol's settings.
#[derive(Debug, Clone, PartialEq)]
pub struct BluefinSettings {
    /// Resend an unacknowledged command after this long.
    pub ack_timeout: Duration,
    /// Tries per command (the first send included).
    pub ack_tries: u32,
    /// `$BPSTS` keep-alive period.
    pub status_period: Duration,
    /// Send the interface's stop as the safe command (else nothing: the front seat's own
    /// timeout takes over).
    pub safe_stop: bool,
}

/// The Bluefin standard payload interface (back-seat side).
pub struct Bluefin {
    settings: BluefinSettings,
    nvg: Option<bluefin::Nvg>,
    pending: Option<(String, UtcTime, Instant, u32)>,
    last_status: Option<Instant>,
}

impl Bluefin {
    /// The protocol with `settings`.
    pub fn new(settings: BluefinSettings) -> Self {
        Bluefin {
            settings,
            nvg: None,
            pending: None,
            last_status: None,
        }
    }
}

/// The `$BPRMB` of a checked command.
pub fn rmb_of(c: &CheckedCommand, time: UtcTime) -> Rmb {
    let (vertical, vertical_mode) = match c.vertical() {
        Vertical::Depth(d) => (d, VerticalMode::Depth),
        Vertical::Altitude(a) => (a, VerticalMode::Altitude),
    };
    Rmb {
        time,
        heading_deg: c.heading_deg(),
        vertical,
        vertical_mode,
        speed: c.speed_mps(),
        speed_mode: SpeedMode::Mps,
        horizontal_mode: HorizontalMode::Heading,
    }
}

impl Protocol for Bluefin {
    fn hello(&mut self) -> Vec<String> {
        self.nvg = None;
        self.pending = None;
        ["ACK", "NVG", "NVR", "CTL"]
            .iter()
            .map(|id| {
                bluefin::Sentence::Log {
                    id: (*id).into(),
                    on: true,
                }
                .encode()
            })
            .collect()
    }

    fn read(&mut self, line: &str, events: &mut Vec<LinkEvent>) -> Result<(), SentenceError> {
        use bluefin::Sentence as S;
        match bluefin::Sentence::parse(line)? {
            S::Nvg(n) => {
                events.push(LinkEvent::Clock(n.time));
                self.nvg = Some(n);
            }
            S::Nvr(v) => {
                events.push(LinkEvent::Clock(v.time));
                // A record is complete when its velocities follow its position.
                if let Some(n) = self.nvg.take().filter(|n| n.time == v.time) {
                    events.push(LinkEvent::Nav(NavFix {
                        time: Some(n.time),
                        lat_deg: n.lat_deg,
                        lon_deg: n.lon_deg,
                        heading_deg: n.heading_deg,
                        speed_mps: v.east_mps.hypot(v.north_mps),
                        altitude_m: Some(n.altitude_m),
                        depth_m: Some(n.depth_m),
                        gps: n.quality == 1,
                    }));
                }
            }
            S::Ack(a) => {
                events.push(LinkEvent::Clock(a.time));
                if let Some((_, t, _, _)) = &self.pending
                    && a.acked == "RMB"
                    && a.command_time == *t
                {
                    self.pending = None;
                    if matches!(a.status, AckStatus::Invalid | AckStatus::Failed) {
                        events.push(LinkEvent::Refused(a.description));
                    }
                }
            }
            S::Ctl { time, accepting } => {
                events.push(LinkEvent::Clock(time));
                events.push(LinkEvent::Accepting(accepting));
            }
            other => {
                // A payload sentence coming back: not ours to act on.
                let _ = other;
                return Err(SentenceError::Unknown(
                    "a payload sentence from the front seat".into(),
                ));
            }
        }
        Ok(())
    }

    fn write(&mut self, what: Outgoing, time: UtcTime, now: Instant) -> Vec<String> {
        let rmb = match what {
            Outgoing::Steer(c) => Some(rmb_of(&c, time)),
            Outgoing::Safe | Outgoing::Finished => self.settings.safe_stop.then(|| Rmb::stop(time)),
        };
        let mut lines = Vec::new();
        if let Some(r) = rmb {
            let line = bluefin::Sentence::Rmb(r).encode();
            self.pending = Some((line.clone(), time, now, 1));
            lines.push(line);
        }
        if what == Outgoing::Finished {
            lines.push(
                bluefin::Sentence::Sts {
                    time,
                    ok: false,
                    text: "Finished".into(),
                }
                .encode(),
            );
        }
        lines
    }

    fn tick(&mut self, now: Instant, time: UtcTime, events: &mut Vec<LinkEvent>) -> Vec<String> {
        let mut lines = Vec::new();
        if self
            .last_status
            .is_none_or(|t| now.duration_since(t) >= self.settings.status_period)
        {
            self.last_status = Some(now);
            lines.push(
                bluefin::Sentence::Sts {
                    time,
                    ok: true,
                    text: "Running".into(),
                }
                .encode(),
            );
        }
        if let Some((line, _, sent, tries)) = &mut self.pending
            && now.duration_since(*sent) >= self.settings.ack_timeout
        {
            if *tries >= self.settings.ack_tries {
                self.pending = None;
                events.push(LinkEvent::AckGaveUp);
            } else {
                *tries += 1;
                *sent = now;
                lines.push(line.clone());
            }
        }
        lines
    }

    fn set_lock_step(&mut self, _on: bool) {}
}

/// A line source that carries chemical readings only (a sensor on its own serial line or TCP
/// port): every line its [`ChemFormat`](crate::protocol::chem::ChemFormat) does not claim is
/// rejected, nothing is ever sent.
pub struct ChemOnly;

impl Protocol for ChemOnly {
    fn hello(&mut self) -> Vec<String> {
        Vec::new()
    }
    fn read(&mut self, line: &str, _events: &mut Vec<LinkEvent>) -> Result<(), SentenceError> {
        let id = line
            .trim()
            .trim_start_matches('$')
            .split([',', '*'])
            .next()
            .unwrap_or("");
        Err(SentenceError::Unknown(id.chars().take(16).collect()))
    }
    fn write(&mut self, _what: Outgoing, _time: UtcTime, _now: Instant) -> Vec<String> {
        Vec::new()
    }
    fn tick(&mut self, _now: Instant, _time: UtcTime, _events: &mut Vec<LinkEvent>) -> Vec<String> {
        Vec::new()
    }
    fn set_lock_step(&mut self, _on: bool) {}
}

/// The Iver remote-helm protocol's settings.
#[derive(Debug, Clone, PartialEq)]
pub struct IverSettings {
    /// Depth units of `$OMS`.
    pub units: Units,
    /// `$OSD` poll period (real time).
    pub poll_period: Duration,
    /// The `$OMS` timeout field, s; the last command is resent at half of it.
    pub oms_timeout_s: u32,
    /// Maximum pitch field of `$OMS`, deg.
    pub max_pitch_deg: f64,
    /// Send `$OMSTOP,0` as the safe command (else nothing).
    pub safe_stop: bool,
}

/// The Iver remote helm (back-seat side).
pub struct Iver {
    settings: IverSettings,
    last_poll: Option<Instant>,
    last_oms: Option<(String, Instant)>,
    lock_step: bool,
    water_depth_m: Option<f64>,
}

impl Iver {
    /// The protocol with `settings`.
    pub fn new(settings: IverSettings) -> Self {
        Iver {
            settings,
            last_poll: None,
            last_oms: None,
            lock_step: false,
            water_depth_m: None,
        }
    }
}

/// The `$OMS` of a checked command. The remote helm takes depths only: an altitude hold becomes
/// the depth that leaves that altitude over the water depth last reported (`$OSI` depth plus
/// altitude); without a report there is no `$OMS` (`None`).
pub fn oms_of(c: &CheckedCommand, s: &IverSettings, water_depth_m: Option<f64>) -> Option<Oms> {
    let depth_m = match c.vertical() {
        Vertical::Depth(d) => d,
        Vertical::Altitude(a) => (water_depth_m? - a).max(0.0),
    };
    Some(Oms {
        heading_deg: c.heading_deg(),
        depth: s.units.depth_to_wire(depth_m),
        max_pitch_deg: s.max_pitch_deg,
        speed_kn: c.speed_mps() / MPS_PER_KN,
        timeout_s: s.oms_timeout_s,
    })
}

impl Protocol for Iver {
    fn hello(&mut self) -> Vec<String> {
        self.last_poll = Some(Instant::now());
        self.last_oms = None;
        vec![iver::Sentence::Osd.encode()]
    }

    fn read(&mut self, line: &str, events: &mut Vec<LinkEvent>) -> Result<(), SentenceError> {
        match iver::Sentence::parse(line)? {
            iver::Sentence::Osi(o) => {
                self.water_depth_m = (o.altitude_ft > 0.0)
                    .then_some((o.depth_ft + o.altitude_ft) * M_PER_FT)
                    .or(self.water_depth_m);
                events.push(LinkEvent::Accepting(o.mode == iver::Mode::Normal));
                events.push(LinkEvent::Nav(NavFix {
                    time: None,
                    lat_deg: o.lat_deg,
                    lon_deg: o.lon_deg,
                    heading_deg: o.heading_deg,
                    speed_mps: o.speed_kn * MPS_PER_KN,
                    altitude_m: Some(o.altitude_ft * M_PER_FT),
                    depth_m: Some(o.depth_ft * M_PER_FT),
                    gps: false,
                }));
                Ok(())
            }
            _ => Err(SentenceError::Unknown(
                "a payload sentence from the vehicle".into(),
            )),
        }
    }

    fn write(&mut self, what: Outgoing, _time: UtcTime, now: Instant) -> Vec<String> {
        let mut lines = Vec::new();
        match what {
            Outgoing::Steer(c) => {
                if let Some(o) = oms_of(&c, &self.settings, self.water_depth_m) {
                    let line = iver::Sentence::Oms(o).encode();
                    self.last_oms = Some((line.clone(), now));
                    lines.push(line);
                }
            }
            Outgoing::Safe | Outgoing::Finished => {
                self.last_oms = None;
                if self.settings.safe_stop {
                    lines.push(iver::Sentence::Omstop.encode());
                }
            }
        }
        if self.lock_step && what != Outgoing::Finished {
            self.last_poll = Some(now);
            lines.push(iver::Sentence::Osd.encode());
        }
        lines
    }

    fn tick(&mut self, now: Instant, _time: UtcTime, _events: &mut Vec<LinkEvent>) -> Vec<String> {
        let mut lines = Vec::new();
        let resend = Duration::from_secs_f64(f64::from(self.settings.oms_timeout_s) / 2.0);
        if let Some((line, sent)) = &mut self.last_oms
            && now.duration_since(*sent) >= resend
        {
            *sent = now;
            lines.push(line.clone());
        }
        // In lock-step the poll follows each command; a poll is repeated only if the vehicle
        // stays silent for a poll period (a lost line).
        let period = if self.lock_step {
            self.settings.poll_period.max(Duration::from_secs(1))
        } else {
            self.settings.poll_period
        };
        if self
            .last_poll
            .is_none_or(|t| now.duration_since(t) >= period)
        {
            self.last_poll = Some(now);
            lines.push(iver::Sentence::Osd.encode());
        }
        lines
    }

    fn set_lock_step(&mut self, on: bool) {
        self.lock_step = on;
    }
}
