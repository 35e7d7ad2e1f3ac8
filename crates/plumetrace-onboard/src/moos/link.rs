//! The MOOS community client as a vehicle link ([`MoosLink`]): connecting and the handshake,
//! the welcome and registrations, timing messages (the heartbeat) and the clock skew,
//! notifications in, set-points and the plume-tracing variables out, reconnection with back-off
//! and the raw traffic log (one line per message).

use super::nav::{NAV_VARIABLES, NavState};
use super::view::{self, Views};
use super::wire::{
    Framer, Message, MoosError, PROTOCOL, TIMING_PERIOD, decode_messages, encode_packet, kind,
    protocol_bytes, unix_now,
};
use crate::config::Onboard;
use crate::geo::{LocalFrame, OriginError};
use crate::link::{Backoff, Link, LinkEvent, LinkTiming, Outgoing};
use crate::protocol::sentence::{LineCounts, UtcTime};
use crate::transport::conn::read_tcp;
use plumetrace_core::{Decision, PlanStatus, PlannerEvent, SensorSnapshot, variant_name};
use std::io::Write;
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// The MOOS link's settings.
#[derive(Debug, Clone, PartialEq)]
pub struct MoosSettings {
    /// The MOOSDB's host.
    pub host: String,
    /// The MOOSDB's port.
    pub port: u16,
    /// The name the client connects as.
    pub app_name: String,
    /// The variable carrying the chemical reading.
    pub chem_variable: Option<String>,
    /// Publish `DESIRED_SPEED = 0` when the planner pauses.
    pub safe_stop: bool,
    /// A navigation or chemical posting older than this (by its MOOS time) is not taken, s.
    pub stale_nav_s: f64,
    /// Silence, reconnection.
    pub timing: LinkTiming,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    Welcome,
    Ready,
}

/// The MOOS community client as a vehicle link.
pub struct MoosLink {
    settings: MoosSettings,
    frame: LocalFrame,
    conn: Option<TcpStream>,
    phase: Phase,
    framer: Framer,
    last_byte: Instant,
    next_try: Instant,
    backoff: Backoff,
    counts: LineCounts,
    traffic: Option<Box<dyn Write + Send>>,
    started: Instant,
    deferred: Vec<LinkEvent>,
    skew: f64,
    // Whether the skew is estimated (not for a MOOSDB on this host), and the timing replies
    // on this connection (the first does not count).
    skew_on: bool,
    timing_replies: u64,
    // The MOOSDB's consolidation period: outgoing mail is paced by it.
    outgoing_delay: Duration,
    last_send: Option<Instant>,
    community: String,
    next_id: i32,
    last_timing: Option<Instant>,
    nav: NavState,
    clock: f64,
    paused: bool,
    outbox: Vec<Message>,
    // What pMarineViewer draws: the mission's polygons (posted at each welcome) and the
    // planner's points.
    geometry: Vec<(&'static str, String)>,
    views: Views,
    // The process posting NAV_X, as its postings name it (for run.alog's source column).
    nav_source: plumetrace_log::alog::SharedName,
}

impl MoosLink {
    /// A client with `settings` whose positions pass the runner about `frame`'s origin; raw
    /// traffic (one line per message) goes to `traffic`.
    pub fn new(
        settings: MoosSettings,
        frame: LocalFrame,
        traffic: Option<Box<dyn Write + Send>>,
    ) -> Self {
        let now = Instant::now();
        MoosLink {
            backoff: Backoff::new(&settings.timing),
            settings,
            frame,
            conn: None,
            phase: Phase::Welcome,
            framer: Framer::default(),
            last_byte: now,
            next_try: now,
            counts: LineCounts::default(),
            traffic,
            started: now,
            deferred: Vec::new(),
            skew: 0.0,
            skew_on: true,
            timing_replies: 0,
            outgoing_delay: Duration::ZERO,
            last_send: None,
            community: String::new(),
            next_id: 0,
            last_timing: None,
            nav: NavState::default(),
            clock: f64::NEG_INFINITY,
            paused: false,
            outbox: Vec::new(),
            geometry: Vec::new(),
            views: Views::default(),
            nav_source: Default::default(),
        }
    }

    /// The client an onboard file describes (`link.moos`, `link.origin`, `link.safe_command`).
    pub fn for_onboard(
        onboard: &Onboard,
        timing: LinkTiming,
        traffic: Option<Box<dyn Write + Send>>,
    ) -> Result<Self, OriginError> {
        let l = &onboard.file.link;
        let m = l.moos.clone().unwrap_or_default();
        let frame = LocalFrame::new(l.origin)?;
        let mission = &onboard.file.mission;
        let geometry = view::geometry(&mission.op_area, &mission.subregions);
        Ok(MoosLink::new(
            MoosSettings {
                host: m.host,
                port: m.port,
                app_name: m.app_name,
                chem_variable: m.chem_variable,
                safe_stop: l.safe_command == crate::config::SafeAction::Stop,
                stale_nav_s: l.stale_nav_s,
                timing,
            },
            frame,
            traffic,
        )
        .with_geometry(geometry))
    }

    /// The same client posting `geometry` (`VIEW_POLYGON` postings) at each connection.
    pub fn with_geometry(mut self, geometry: Vec<(&'static str, String)>) -> Self {
        self.geometry = geometry;
        self
    }

    /// The clock skew in use (server minus this computer), s.
    pub fn skew_s(&self) -> f64 {
        self.skew
    }

    /// The community's name from the welcome.
    pub fn community(&self) -> &str {
        &self.community
    }

    fn moos_time(&self) -> f64 {
        unix_now() + self.skew
    }

    fn log(&mut self, mark: char, text: &str) {
        self.log_at(Instant::now(), mark, text);
    }

    /// A traffic line stamped `at` (a sent packet's lines carry the instant the pacing counted,
    /// not the moment they were written down, which a busy machine can delay).
    fn log_at(&mut self, at: Instant, mark: char, text: &str) {
        if let Some(t) = self.traffic.as_mut() {
            let s = at.saturating_duration_since(self.started).as_secs_f64();
            let _ = writeln!(t, "{s:.3} {mark} {}", text.trim_end());
        }
    }

    fn reject(&mut self, kind: &'static str, why: &str) {
        *self.counts.rejected.entry(kind).or_default() += 1;
        self.log('!', why);
    }

    fn drop_conn(&mut self, why: String, events: &mut Vec<LinkEvent>) {
        if self.conn.take().is_some() {
            self.log('#', &format!("lost: {why}"));
            if self.phase == Phase::Ready {
                events.push(LinkEvent::Lost(why));
            }
        }
        self.phase = Phase::Welcome;
        self.framer.clear();
        self.outbox.clear();
        self.next_try = Instant::now() + self.backoff.lost();
    }

    fn write_raw(&mut self, bytes: &[u8], events: &mut Vec<LinkEvent>) -> bool {
        let Some(c) = self.conn.as_mut() else {
            return false;
        };
        match c.write_all(bytes) {
            Ok(()) => true,
            Err(e) => {
                self.drop_conn(format!("writing: {e}"), events);
                false
            }
        }
    }

    /// Sends `messages` as one packet (a timing message first when one is due).
    fn send_messages(&mut self, mut messages: Vec<Message>, events: &mut Vec<LinkEvent>) {
        if self.conn.is_none() {
            return;
        }
        let now = Instant::now();
        if self.phase == Phase::Ready
            && self
                .last_timing
                .is_none_or(|t| now.duration_since(t) >= TIMING_PERIOD)
        {
            self.last_timing = Some(now);
            messages.insert(0, Message::timing(unix_now()));
        }
        if messages.is_empty() {
            return;
        }
        let packet = match encode_packet(&messages) {
            Ok(p) => p,
            Err(e) => {
                self.log('#', &format!("not sent: {e}"));
                return;
            }
        };
        if self.write_raw(&packet, events) {
            self.last_send = Some(now);
            for m in &messages {
                self.log_at(now, '>', &m.summary());
            }
        }
    }

    /// Whether outgoing mail may go now: the MOOSDB's consolidation period has passed since the
    /// last packet (as libMOOS's writing thread waits it out).
    fn mail_due(&self) -> bool {
        self.last_send
            .is_none_or(|t| t.elapsed() >= self.outgoing_delay)
    }

    fn post(&mut self, key: &str, value: PostValue) -> Message {
        let t = self.moos_time();
        let mut m = match value {
            PostValue::Double(v) => Message::with_double(kind::NOTIFY, key, v, t),
            PostValue::Text(s) => Message::with_string(kind::NOTIFY, key, &s, t),
        };
        m.source = self.settings.app_name.clone();
        m.id = self.next_id;
        self.next_id = self.next_id.wrapping_add(1);
        m
    }

    fn connect(&mut self, events: &mut Vec<LinkEvent>) {
        let now = Instant::now();
        if self.conn.is_some() || now < self.next_try {
            return;
        }
        let addr = format!("{}:{}", self.settings.host, self.settings.port);
        let opened = std::net::ToSocketAddrs::to_socket_addrs(addr.as_str())
            .and_then(|mut a| {
                a.next()
                    .ok_or_else(|| std::io::Error::other(format!("{addr}: no address")))
            })
            .and_then(|a| TcpStream::connect_timeout(&a, Duration::from_secs(2)))
            .and_then(|s| s.set_nodelay(true).map(|()| s));
        match opened {
            Ok(s) => {
                self.conn = Some(s);
                self.backoff.connected();
                self.phase = Phase::Welcome;
                self.framer.clear();
                self.last_byte = now;
                self.last_timing = None;
                self.nav = NavState::default();
                let name = self.settings.app_name.clone();
                self.log('#', &format!("connected to {addr}; handshaking as {name}"));
                let hello = Message::handshake(&name, unix_now());
                let mut bytes = protocol_bytes().to_vec();
                match encode_packet(std::slice::from_ref(&hello)) {
                    Ok(p) => bytes.extend_from_slice(&p),
                    Err(e) => {
                        self.drop_conn(format!("the handshake: {e}"), events);
                        return;
                    }
                }
                if self.write_raw(&bytes, events) {
                    self.log('>', &format!("protocol \"{PROTOCOL}\""));
                    self.log('>', &hello.summary());
                }
            }
            Err(e) => {
                self.log(
                    '#',
                    &format!(
                        "connecting to {addr} failed: {e}; next try in {:.1} s",
                        self.backoff.current().as_secs_f64()
                    ),
                );
                self.next_try = now + self.backoff.failed();
            }
        }
    }

    fn welcome(&mut self, m: &Message, events: &mut Vec<LinkEvent>) {
        // As libMOOS: no skew correction for a MOOSDB on this host (the welcome's source aux
        // names the DB's host), else the welcome's skew, then the timing replies'.
        let db_host = m
            .source_aux
            .split(',')
            .find_map(|kv| kv.trim().strip_prefix("hostname="))
            .unwrap_or("");
        self.skew_on = local_host_name().is_none_or(|h| h != db_host);
        self.skew = if self.skew_on && m.double.is_finite() && m.double.abs() < 1e9 {
            m.double
        } else {
            0.0
        };
        self.timing_replies = 0;
        self.community = m.community.clone();
        self.phase = Phase::Ready;
        // `paused` is kept: a `CPT_PAUSED = true` published before the connection was lost is
        // still the community's value, and the next set-point publishes `false`.
        self.log(
            '#',
            &format!(
                "welcome to community {} (skew {})",
                self.community,
                if self.skew_on {
                    format!("{:.3} s", self.skew)
                } else {
                    "not estimated: the MOOSDB is on this host".into()
                }
            ),
        );
        events.push(LinkEvent::Connected);
        let mut vars: Vec<String> = NAV_VARIABLES.iter().map(|v| (*v).to_string()).collect();
        vars.extend(self.settings.chem_variable.clone());
        let t = self.moos_time();
        let mut regs: Vec<Message> = vars
            .iter()
            .map(|v| {
                let mut r = Message::with_double(kind::REGISTER, v, 0.0, t);
                r.source = self.settings.app_name.clone();
                r.id = self.next_id;
                self.next_id = self.next_id.wrapping_add(1);
                r
            })
            .collect();
        for (key, value) in self.geometry.clone() {
            let m = self.post(key, PostValue::Text(value));
            regs.push(m);
        }
        self.send_messages(regs, events);
    }

    fn timing_reply(&mut self, m: &Message) {
        // The MOOSDB's consolidation period paces outgoing mail (bounded: a second at most).
        if m.double2.is_finite() {
            let delay = Duration::from_secs_f64(m.double2.clamp(0.0, 1.0));
            if delay != self.outgoing_delay {
                self.outgoing_delay = delay;
                self.log(
                    '#',
                    &format!(
                        "consolidation period {:.3} s (the MOOSDB's timing reply): at most one packet of set-points per period",
                        delay.as_secs_f64()
                    ),
                );
            }
        }
        self.timing_replies += 1;
        // As libMOOS: the first reply does not count towards the skew.
        if !self.skew_on || self.timing_replies < 2 {
            return;
        }
        let rx = unix_now();
        let (rq, tx) = (m.time, m.double);
        if !(rq.is_finite() && tx.is_finite()) {
            return;
        }
        let measured = 0.5 * ((tx - rx) + (tx - rq));
        if measured.abs() >= 1e9 {
            return;
        }
        self.skew = if self.skew == 0.0 {
            measured
        } else {
            0.9 * self.skew + 0.1 * measured
        };
    }

    /// Takes one notification; `Err` with a count kind when it is not acted on. The posting's
    /// time, when later than any before, is the front seat's clock.
    fn notify(&mut self, m: &Message, events: &mut Vec<LinkEvent>) -> Result<(), &'static str> {
        // A MOOSDB sends each variable's stored value at registration, however old: a reading
        // or a position older than the staleness limit by its MOOS time is not taken.
        let measured = m.key != "MOOS_MANUAL_OVERRIDE";
        if measured && m.time.is_finite() && self.moos_time() - m.time > self.settings.stale_nav_s {
            return Err("stale");
        }
        self.nav
            .take(m, self.settings.chem_variable.as_deref(), events)?;
        if m.key == "NAV_X"
            && !m.source.is_empty()
            && let Ok(mut name) = self.nav_source.lock()
            && *name != m.source
        {
            name.clone_from(&m.source);
        }
        if m.time.is_finite() && m.time > self.clock && m.time > 0.0 {
            self.clock = m.time;
            events.push(LinkEvent::Clock(UtcTime::from_seconds(
                m.time.rem_euclid(86_400.0),
            )));
        }
        Ok(())
    }

    fn take_packet(&mut self, packet: &[u8], events: &mut Vec<LinkEvent>) {
        let decoded = match decode_messages(packet) {
            Ok(m) => m,
            Err(e) => {
                let why = format!("a packet of {} bytes: {e}", packet.len());
                self.reject(e.kind(), &why);
                return;
            }
        };
        let mut messages = Vec::with_capacity(decoded.len());
        for m in decoded {
            match m {
                Ok(m) => messages.push(m),
                Err(e) => self.reject(e.kind(), &format!("a message: {e}")),
            }
        }
        let before = events.len();
        for m in &messages {
            self.log('<', &m.summary());
            if self.conn.is_none() {
                break;
            }
            match (self.phase, m.kind) {
                (_, kind::POISON) => {
                    self.counts.accepted += 1;
                    let why = format!(
                        "the MOOSDB refused the client: {}",
                        String::from_utf8_lossy(&m.string)
                    );
                    self.drop_conn(why, events);
                }
                (_, kind::TERMINATE) => {
                    self.counts.accepted += 1;
                    self.drop_conn("the MOOSDB ended the connection".into(), events);
                }
                (Phase::Welcome, kind::WELCOME) => {
                    self.counts.accepted += 1;
                    self.welcome(m, events);
                }
                (Phase::Welcome, _) => self.reject("unexpected", "a message before the welcome"),
                (Phase::Ready, kind::TIMING) => {
                    self.counts.accepted += 1;
                    self.timing_reply(m);
                }
                (Phase::Ready, kind::NULL) => self.counts.accepted += 1,
                (Phase::Ready, kind::NOTIFY) => {
                    let n = events.len();
                    match self.notify(m, events) {
                        Ok(()) => self.counts.accepted += 1,
                        Err(k) => {
                            events.truncate(n);
                            self.reject(k, &format!("{}: not taken ({k})", m.key));
                        }
                    }
                }
                (Phase::Ready, _) => self.reject("unexpected", "a message type a client ignores"),
            }
        }
        if self.conn.is_none() {
            // Refused or ended: nothing it said counts beyond that.
            let keep: Vec<LinkEvent> = events
                .drain(before..)
                .filter(|e| matches!(e, LinkEvent::Lost(_) | LinkEvent::Connected))
                .collect();
            events.extend(keep);
            return;
        }
        self.assemble(events);
    }

    fn assemble(&mut self, events: &mut Vec<LinkEvent>) {
        if let Some(fix) = self.nav.assemble(&self.frame) {
            self.backoff.carried();
            events.push(LinkEvent::Nav(fix));
        }
    }
}

/// This computer's host name, as `gethostname` gives it (what a MOOSDB puts in its welcome).
fn local_host_name() -> Option<String> {
    ["/proc/sys/kernel/hostname", "/etc/hostname"]
        .iter()
        .find_map(|p| std::fs::read_to_string(p).ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
}

enum PostValue {
    Double(f64),
    Text(String),
}

impl Link for MoosLink {
    fn poll(&mut self, wait: Duration) -> Vec<LinkEvent> {
        let mut events = std::mem::take(&mut self.deferred);
        self.connect(&mut events);
        let deadline = Instant::now() + wait;
        let mut chunk = [0u8; 8192];
        loop {
            let now = Instant::now();
            let Some(conn) = self.conn.as_mut() else {
                std::thread::sleep(
                    deadline
                        .saturating_duration_since(now)
                        .min(Duration::from_millis(50)),
                );
                break;
            };
            let left = deadline.saturating_duration_since(now);
            match read_tcp(conn, &mut chunk, left) {
                Ok(0) => {}
                Ok(n) => {
                    self.last_byte = Instant::now();
                    self.framer.push(&chunk[..n]);
                    while let Some(p) = self.framer.next_packet() {
                        match p {
                            Ok(packet) => self.take_packet(&packet, &mut events),
                            Err(e @ MoosError::TooLarge(_)) => {
                                self.reject(e.kind(), &format!("skipped: {e}"));
                            }
                            Err(e) => {
                                self.reject(e.kind(), &format!("the stream: {e}"));
                                self.drop_conn(format!("unreadable stream: {e}"), &mut events);
                            }
                        }
                        if self.conn.is_none() {
                            break;
                        }
                    }
                }
                Err(e) => {
                    self.drop_conn(e.to_string(), &mut events);
                    break;
                }
            }
            if self.conn.is_some()
                && self.last_byte.elapsed() >= self.settings.timing.silence_timeout
            {
                let s = self.settings.timing.silence_timeout.as_secs_f64();
                let what = if self.phase == Phase::Ready {
                    "nothing received"
                } else {
                    "no welcome"
                };
                self.drop_conn(format!("{what} for {s:.1} s"), &mut events);
                break;
            }
            if !events.is_empty() || Instant::now() >= deadline {
                break;
            }
        }
        if self.conn.is_some() && self.phase == Phase::Ready {
            let out = if self.mail_due() {
                std::mem::take(&mut self.outbox)
            } else {
                Vec::new()
            };
            // The heartbeat goes out whatever the pacing.
            self.send_messages(out, &mut events);
        }
        if let Some(t) = self.traffic.as_mut() {
            let _ = t.flush();
        }
        events
    }

    fn send(&mut self, what: Outgoing, _time: UtcTime) {
        if self.conn.is_none() || self.phase != Phase::Ready {
            self.outbox.clear();
            return;
        }
        let mut out = std::mem::take(&mut self.outbox);
        match what {
            Outgoing::Steer(c) => {
                if self.paused {
                    self.paused = false;
                    out.push(self.post("CPT_PAUSED", PostValue::Text("false".into())));
                }
                // A newer set-point replaces one still waiting for the consolidation period.
                out.retain(|m| !m.key.starts_with("DESIRED_"));
                out.push(self.post("DESIRED_HEADING", PostValue::Double(c.heading_deg())));
                out.push(self.post("DESIRED_SPEED", PostValue::Double(c.speed_mps())));
                if let Some(d) = self.nav.depth_of(&c) {
                    out.push(self.post("DESIRED_DEPTH", PostValue::Double(d)));
                }
                if !self.mail_due() {
                    self.outbox = out;
                    return;
                }
            }
            Outgoing::Safe => {
                self.paused = true;
                if self.settings.safe_stop {
                    out.push(self.post("DESIRED_SPEED", PostValue::Double(0.0)));
                }
                out.push(self.post("CPT_PAUSED", PostValue::Text("true".into())));
            }
            Outgoing::Finished => {
                if self.settings.safe_stop {
                    out.push(self.post("DESIRED_SPEED", PostValue::Double(0.0)));
                }
                out.push(self.post("CPT_STATUS", PostValue::Text("ended".into())));
            }
        }
        let mut events = Vec::new();
        self.send_messages(out, &mut events);
        self.deferred.extend(events);
        if let Some(t) = self.traffic.as_mut() {
            let _ = t.flush();
        }
    }

    fn counts(&self) -> &LineCounts {
        &self.counts
    }

    fn connected(&self) -> bool {
        self.conn.is_some() && self.phase == Phase::Ready
    }

    fn sensor_source(&self) -> Option<plumetrace_log::alog::SharedName> {
        Some(self.nav_source.clone())
    }

    fn decided(&mut self, _snapshot: &SensorSnapshot, d: &Decision) {
        // Counted whether or not they can go out now, so labels stay unique.
        let drawn = self.views.of(d);
        if !self.connected() {
            return;
        }
        for e in &d.events {
            let posting = match e {
                PlannerEvent::Behaviour { behaviour } => Some((
                    "CPT_BEHAVIOUR",
                    variant_name(behaviour).unwrap_or("?").to_string(),
                )),
                PlannerEvent::Detection { pos_m } => Some((
                    "CPT_DETECTION",
                    format!("x={:.2},y={:.2}", pos_m.x, pos_m.y),
                )),
                PlannerEvent::Declared { pos_m, rule } => Some((
                    "CPT_DECLARATION",
                    format!(
                        "x={:.2},y={:.2},rule={}",
                        pos_m.x,
                        pos_m.y,
                        variant_name(rule).unwrap_or("?")
                    ),
                )),
                _ => None,
            };
            if let Some((key, value)) = posting
                && self.outbox.len() < 1000
            {
                let m = self.post(key, PostValue::Text(value));
                self.outbox.push(m);
            }
        }
        for (key, value) in drawn {
            if self.outbox.len() < 1000 {
                let m = self.post(key, PostValue::Text(value));
                self.outbox.push(m);
            }
        }
        if d.status != PlanStatus::Running {
            let v = variant_name(&d.status).unwrap_or("?").to_string();
            let m = self.post("CPT_STATUS", PostValue::Text(v));
            self.outbox.push(m);
        }
    }
}
