//! Vehicle links: one small trait ([`Link`]) the runner drives, one implementation
//! ([`LineLink`]) that puts a protocol ([`Protocol`]: Bluefin or Iver) on a line transport (TCP
//! or a serial device), with reconnection and back-off, keep-alives, acknowledgements and
//! resends, counts of bad lines, and the raw traffic written to a log.
//!
//! Nothing a link receives is acted on unless it parsed: a malformed, out-of-range or
//! checksum-failing line is counted (by kind), written to the traffic log and dropped.

use crate::bluefin::{self, AckStatus, HorizontalMode, Rmb, SpeedMode, VerticalMode};
use crate::chem::ChemFormat;
use crate::command::{CheckedCommand, Vertical};
use crate::current::FlowFormat;
use crate::iver::{self, M_PER_FT, MPS_PER_KN, Oms, Units};
use crate::sentence::{LineCounts, MAX_LINE, SentenceError, UtcTime};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::PathBuf;
use std::time::{Duration, Instant};

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
/// port): every line its [`ChemFormat`] does not claim is rejected, nothing is ever sent.
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

/// Where a link's lines travel.
#[derive(Debug, Clone, PartialEq)]
pub enum Endpoint {
    /// A TCP server (`host:port`).
    Tcp(String),
    /// A serial device (or pseudo-terminal) path, set to raw mode at `baud`.
    Serial {
        /// Device path.
        path: PathBuf,
        /// Baud rate.
        baud: u32,
    },
}

/// Reads what a TCP stream has within `wait` (`Ok(0)`: nothing came; no wait at all is a
/// non-blocking read, since read timeouts round up to the kernel's tick); the peer closing the
/// connection is an `UnexpectedEof` error.
pub fn read_tcp(s: &mut TcpStream, buf: &mut [u8], wait: Duration) -> std::io::Result<usize> {
    s.set_nonblocking(wait.is_zero())?;
    s.set_read_timeout(Some(wait.max(Duration::from_millis(1))))?;
    match s.read(buf) {
        Ok(0) => Err(std::io::Error::new(
            std::io::ErrorKind::UnexpectedEof,
            "the other side closed the connection",
        )),
        Ok(n) => Ok(n),
        Err(e)
            if matches!(
                e.kind(),
                std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
            ) =>
        {
            Ok(0)
        }
        Err(e) => Err(e),
    }
}

enum Conn {
    Tcp(TcpStream),
    Serial(std::fs::File),
}

impl Conn {
    fn open(e: &Endpoint) -> std::io::Result<Conn> {
        match e {
            Endpoint::Tcp(addr) => {
                let addr = std::net::ToSocketAddrs::to_socket_addrs(addr.as_str())?
                    .next()
                    .ok_or_else(|| std::io::Error::other(format!("{addr}: no address")))?;
                let s = TcpStream::connect_timeout(&addr, Duration::from_secs(2))?;
                s.set_nodelay(true)?;
                Ok(Conn::Tcp(s))
            }
            Endpoint::Serial { path, baud } => {
                let f = std::fs::OpenOptions::new()
                    .read(true)
                    .write(true)
                    .open(path)?;
                crate::serial::set_raw(&f, *baud)?;
                Ok(Conn::Serial(f))
            }
        }
    }

    /// Reads what is there within `wait`: `Ok(0)` when nothing came.
    fn read(&mut self, buf: &mut [u8], wait: Duration) -> std::io::Result<usize> {
        match self {
            Conn::Tcp(s) => read_tcp(s, buf, wait),
            // Raw mode with VMIN 0 and VTIME 1: a read returns after 0.1 s without data.
            Conn::Serial(f) => match f.read(buf) {
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => Ok(0),
                other => other,
            },
        }
    }

    fn write_all(&mut self, b: &[u8]) -> std::io::Result<()> {
        match self {
            Conn::Tcp(s) => s.write_all(b),
            Conn::Serial(f) => f.write_all(b),
        }
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

/// A protocol on a line transport, with reconnection, counts and a traffic log.
pub struct LineLink {
    endpoint: Endpoint,
    protocol: Box<dyn Protocol>,
    chem: Option<ChemFormat>,
    flow: Option<FlowFormat>,
    timing: LinkTiming,
    conn: Option<Conn>,
    buf: Vec<u8>,
    last_byte: Instant,
    next_try: Instant,
    backoff: Duration,
    counts: LineCounts,
    clock: UtcTime,
    traffic: Option<Box<dyn Write + Send>>,
    started: Instant,
    // A serial line silent for the silence timeout (reported once until bytes come again).
    quiet: bool,
    // Events from sending (a write that failed), reported by the next poll.
    deferred: Vec<LinkEvent>,
}

impl LineLink {
    /// A link to `endpoint` speaking `protocol`; chemical lines in `chem` travel on it too
    /// when given. Raw traffic goes to `traffic` (one line per line: seconds since start,
    /// `<` received, `>` sent, `!` rejected with the reason, `#` a link event).
    pub fn new(
        endpoint: Endpoint,
        protocol: Box<dyn Protocol>,
        chem: Option<ChemFormat>,
        timing: LinkTiming,
        traffic: Option<Box<dyn Write + Send>>,
    ) -> Self {
        let now = Instant::now();
        LineLink {
            endpoint,
            protocol,
            chem,
            flow: None,
            backoff: timing.reconnect_min,
            timing,
            conn: None,
            buf: Vec::new(),
            last_byte: now,
            next_try: now,
            counts: LineCounts::default(),
            clock: UtcTime::default(),
            traffic,
            started: now,
            quiet: false,
            deferred: Vec::new(),
        }
    }

    /// The same link with current readings in `flow` travelling on it too.
    pub fn with_flow(mut self, flow: FlowFormat) -> Self {
        self.flow = Some(flow);
        self
    }

    /// Sets lock-step behaviour of the protocol (Iver polls after each command).
    pub fn set_lock_step(&mut self, on: bool) {
        self.protocol.set_lock_step(on);
    }

    fn log(&mut self, mark: char, text: &str) {
        if let Some(t) = self.traffic.as_mut() {
            let s = self.started.elapsed().as_secs_f64();
            let _ = writeln!(t, "{s:.3} {mark} {}", text.trim_end());
        }
    }

    fn drop_conn(&mut self, why: String, events: &mut Vec<LinkEvent>) {
        self.quiet = false;
        if self.conn.take().is_some() {
            self.log('#', &format!("lost: {why}"));
            events.push(LinkEvent::Lost(why));
        }
        self.buf.clear();
        self.next_try = Instant::now() + self.backoff;
    }

    fn send_lines(&mut self, lines: Vec<String>, events: &mut Vec<LinkEvent>) {
        for line in lines {
            let Some(c) = self.conn.as_mut() else { return };
            match c.write_all(line.as_bytes()) {
                Ok(()) => self.log('>', &line),
                Err(e) => {
                    self.drop_conn(format!("writing: {e}"), events);
                    return;
                }
            }
        }
    }

    fn connect(&mut self, events: &mut Vec<LinkEvent>) {
        let now = Instant::now();
        if self.conn.is_some() || now < self.next_try {
            return;
        }
        match Conn::open(&self.endpoint) {
            Ok(c) => {
                self.conn = Some(c);
                self.backoff = self.timing.reconnect_min;
                self.last_byte = now;
                self.log('#', "connected");
                events.push(LinkEvent::Connected);
                let hello = self.protocol.hello();
                self.send_lines(hello, events);
            }
            Err(e) => {
                self.log(
                    '#',
                    &format!(
                        "connecting failed: {e}; next try in {:.1} s",
                        self.backoff.as_secs_f64()
                    ),
                );
                self.next_try = now + self.backoff;
                self.backoff = (self.backoff * 2).min(self.timing.reconnect_max);
            }
        }
    }

    fn take_line(&mut self, line: &str, events: &mut Vec<LinkEvent>) {
        self.log('<', line);
        if let Some(chem) = self.chem.as_ref().filter(|c| c.claims(line)) {
            let r = chem.parse(line);
            self.counts.count(&r);
            match r {
                Ok(v) => events.push(LinkEvent::Chem(v)),
                Err(e) => self.log('!', &e.to_string()),
            }
            return;
        }
        if let Some(flow) = self.flow.as_ref().filter(|f| f.claims(line)) {
            let r = flow.parse(line);
            self.counts.count(&r);
            match r {
                Ok(Some(v)) => events.push(LinkEvent::Flow(v)),
                Ok(None) => {}
                Err(e) => self.log('!', &e.to_string()),
            }
            return;
        }
        let before = events.len();
        let r = self.protocol.read(line, events);
        self.counts.count(&r);
        if let Err(e) = r {
            events.truncate(before);
            self.log('!', &e.to_string());
        }
        for e in &events[before..] {
            if let LinkEvent::Clock(t) = e {
                self.clock = *t;
            }
        }
    }
}

impl Link for LineLink {
    fn poll(&mut self, wait: Duration) -> Vec<LinkEvent> {
        let mut events = std::mem::take(&mut self.deferred);
        self.connect(&mut events);
        let deadline = Instant::now() + wait;
        let mut chunk = [0u8; 4096];
        loop {
            let now = Instant::now();
            let Some(conn) = self.conn.as_mut() else {
                // Down: wait out the interval (the caller's loop keeps its pace).
                std::thread::sleep(
                    deadline
                        .saturating_duration_since(now)
                        .min(Duration::from_millis(50)),
                );
                break;
            };
            let left = deadline.saturating_duration_since(now);
            match conn.read(&mut chunk, left) {
                Ok(0) => {}
                Ok(n) => {
                    self.last_byte = Instant::now();
                    if self.quiet {
                        self.quiet = false;
                        self.log('#', "the line speaks again");
                    }
                    self.buf.extend_from_slice(&chunk[..n]);
                    while let Some(k) = self.buf.iter().position(|b| *b == b'\n') {
                        let raw: Vec<u8> = self.buf.drain(..=k).collect();
                        let line = String::from_utf8_lossy(&raw).into_owned();
                        if !line.trim().is_empty() {
                            self.take_line(&line, &mut events);
                        }
                    }
                    if self.buf.len() > 2 * MAX_LINE {
                        let r: Result<(), _> = Err(SentenceError::TooLong(self.buf.len()));
                        self.counts.count(&r);
                        self.log('!', "an endless line was dropped");
                        self.buf.clear();
                    }
                }
                Err(e) => {
                    self.drop_conn(e.to_string(), &mut events);
                    break;
                }
            }
            if self.conn.is_some() && self.last_byte.elapsed() >= self.timing.silence_timeout {
                let s = self.timing.silence_timeout.as_secs_f64();
                let why = format!("nothing received for {s:.1} s");
                if matches!(self.conn, Some(Conn::Serial(_))) {
                    // A serial device stays: reopening it would not bring the vehicle back.
                    if !self.quiet {
                        self.quiet = true;
                        self.log('#', &format!("silent: {why}"));
                        events.push(LinkEvent::Quiet(why));
                    }
                } else {
                    self.drop_conn(why, &mut events);
                    break;
                }
            }
            if !events.is_empty() || Instant::now() >= deadline {
                break;
            }
        }
        if self.conn.is_some() {
            let clock = self.clock;
            let lines = self.protocol.tick(Instant::now(), clock, &mut events);
            self.send_lines(lines, &mut events);
        }
        events
    }

    fn send(&mut self, what: Outgoing, time: UtcTime) {
        let mut events = Vec::new();
        let lines = self.protocol.write(what, time, Instant::now());
        self.send_lines(lines, &mut events);
        self.deferred.extend(events);
        if let Some(t) = self.traffic.as_mut() {
            let _ = t.flush();
        }
    }

    fn counts(&self) -> &LineCounts {
        &self.counts
    }

    fn connected(&self) -> bool {
        self.conn.is_some()
    }

    fn close(&mut self) {
        if let Some(t) = self.traffic.as_mut() {
            let _ = t.flush();
        }
        // Closing a TCP socket with unread data resets the connection, and the other side may
        // then drop what it had not read yet (the final stop): end the sending side, then read
        // what is left until the other side closes or half a second has passed.
        if let Some(Conn::Tcp(s)) = self.conn.as_mut() {
            let _ = s.flush();
            let _ = s.shutdown(std::net::Shutdown::Write);
            let deadline = Instant::now() + Duration::from_millis(500);
            let mut chunk = [0u8; 4096];
            while Instant::now() < deadline {
                let left = deadline.saturating_duration_since(Instant::now());
                match read_tcp(s, &mut chunk, left.min(Duration::from_millis(50))) {
                    Ok(_) => {}
                    Err(_) => break,
                }
            }
        }
        self.conn = None;
    }
}
