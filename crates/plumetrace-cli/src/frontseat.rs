//! `plumetrace frontseat`: a simulated front seat. It flies a scenario's vehicle and plume and
//! speaks a front-seat protocol to a back seat (`plumetrace onboard`): the Bluefin standard
//! payload interface on a TCP port, or the Iver remote helm on a pseudo-terminal. The vehicle's
//! planner slot holds [`FrontSeat`], which reports the vehicle's navigation estimate and chemical
//! readings on the link and steers by the commands that come back, so a whole mission can be
//! rehearsed on one machine and tests can fly the real link end to end.
//!
//! In lock-step (`--lock-step`) the front seat waits for the command that answers each
//! navigation record before it steps on: the mission is then deterministic. Faults can be
//! injected: dropped lines, delays, garbage lines, a silent period (no navigation; the clock goes
//! on in `$BFCTL` lines), a restart (the connection and the listening socket closed for a while).

use anyhow::{Context, Result, bail};
use plumetrace_core::{
    Command, Decision, Heading, PlanStatus, Planner, SensorSnapshot, VerticalCommand,
};
use plumetrace_mission::{Mission, MissionOptions, MissionSetup};
use plumetrace_onboard::command::VehicleLimits;
use plumetrace_onboard::geo::{LocalFrame, Origin};
use plumetrace_onboard::protocol::bluefin::{
    self, AckStatus, HorizontalMode, SpeedMode, VerticalMode,
};
use plumetrace_onboard::protocol::chem::ChemFormat;
use plumetrace_onboard::protocol::current::Cur;
use plumetrace_onboard::protocol::iver::{self, M_PER_FT, MPS_PER_KN, Units};
use plumetrace_onboard::protocol::sentence::UtcTime;
use plumetrace_onboard::transport::serial::Pty;
use serde::Serialize;
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The protocol a front seat speaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Protocol {
    /// Bluefin standard payload interface on a TCP port.
    Bluefin,
    /// Iver remote helm on a pseudo-terminal.
    Iver,
}

/// Arguments of `plumetrace frontseat`.
#[derive(Debug, clap::Args)]
pub struct FrontseatArgs {
    /// Scenario file (TOML); give this or --preset.
    pub scenario: Option<PathBuf>,
    /// Built-in scenario (see `plumetrace presets`).
    #[arg(long, conflicts_with = "scenario")]
    pub preset: Option<String>,
    /// Run seed (overrides the scenario's).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::seed)]
    pub seed: Option<u64>,
    /// The protocol.
    #[arg(long, value_enum, default_value = "bluefin")]
    pub protocol: Protocol,
    /// Bluefin: where to listen (`host:port`; port 0 picks a free one).
    #[arg(long, default_value = "127.0.0.1:29500")]
    pub listen: String,
    /// Iver: the remote-helm major version the simulated vehicle has (depth in feet below 5).
    #[arg(long, default_value_t = 5)]
    pub remote_helm_major: u32,
    /// Wait for the answer to each navigation record before stepping on (deterministic).
    #[arg(long)]
    pub lock_step: bool,
    /// Navigation record period, s of mission time.
    #[arg(long, default_value_t = 0.1)]
    pub nav_period_s: f64,
    /// The local frame's origin, `LAT,LON` in degrees.
    #[arg(long, default_value = "36.18,-75.75", allow_hyphen_values = true)]
    pub origin: String,
    /// Write an onboard file for this scenario's planner and this link here.
    #[arg(long)]
    pub write_onboard: Option<PathBuf>,
    /// Write `frontseat.json` (what the front seat saw) into this directory.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// How long to wait for the back seat (to connect, or to answer in lock-step), s of wall
    /// time; a back seat that does not answer in time leaves the vehicle on its last command.
    #[arg(long, default_value_t = 30.0)]
    pub wait_s: f64,
    /// Fault: drop each outgoing line with this probability.
    #[arg(long, default_value_t = 0.0)]
    pub drop: f64,
    /// Fault: send a garbage line before a navigation record with this probability.
    #[arg(long, default_value_t = 0.0)]
    pub garbage: f64,
    /// Fault: wait this long (wall time, s) before each navigation record.
    #[arg(long, default_value_t = 0.0)]
    pub delay_s: f64,
    /// Fault: no navigation from this mission time on, s ...
    #[arg(long)]
    pub silent_at: Option<f64>,
    /// ... for this long, s.
    #[arg(long, default_value_t = 30.0)]
    pub silent_for: f64,
    /// Fault: restart the front seat at this mission time, s (Bluefin: the connection and the
    /// listening socket closed; Iver: the serial line silent, what arrives lost, then a line of
    /// boot text) ...
    #[arg(long)]
    pub restart_at: Option<f64>,
    /// ... for this long (wall time), s.
    #[arg(long, default_value_t = 2.0)]
    pub restart_for: f64,
    /// End the mission at this time instead of the scenario's limit, s.
    #[arg(long)]
    pub time_limit_s: Option<f64>,
    /// Seed of the fault draws.
    #[arg(long, default_value_t = 1)]
    pub fault_seed: u64,
    /// Do not send the vehicle's current readings (`$VDCUR`); the onboard file then has no
    /// `[flow]` table and the planner keeps the prior flow.
    #[arg(long)]
    pub no_flow: bool,
}

/// What the front seat saw, for `frontseat.json` and the tests.
#[derive(Debug, Clone, Default, Serialize)]
pub struct FrontSeatStats {
    /// Navigation records sent.
    pub nav_records: u64,
    /// Commands received (heading/speed set-points).
    pub commands: u64,
    /// Stop commands received.
    pub stops: u64,
    /// Commands outside the vehicle's limits or not finite (never steered by).
    pub unsafe_commands: u64,
    /// Lines received that did not parse.
    pub bad_lines: u64,
    /// Connections accepted.
    pub connections: u64,
    /// Restarts injected (`--restart-at`).
    pub restarts: u64,
    /// Navigation records that got no answer in time (lock-step).
    pub unanswered: u64,
    /// Whether the back seat said it finished.
    pub finished: bool,
    /// Whether the back seat went away for longer than `--wait-s` (lock-step).
    pub back_seat_gone: bool,
    /// Mission time at the end, s.
    pub end_s: f64,
}

/// A small deterministic generator for fault draws (splitmix64).
struct FaultRng(u64);

impl FaultRng {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

enum Wire {
    Tcp {
        addr: SocketAddr,
        listener: Option<TcpListener>,
        conn: Option<TcpStream>,
    },
    Pty(Pty),
}

/// The simulated front seat, sitting in the vehicle's planner slot.
pub struct FrontSeat {
    protocol: Protocol,
    wire: Wire,
    buf: Vec<u8>,
    frame: LocalFrame,
    nav_period_s: f64,
    lock_step: bool,
    wait: Duration,
    chem: ChemFormat,
    flow: bool,
    last_flow_s: Option<f64>,
    units: Units,
    limits: VehicleLimits,
    command: Option<Command>,
    rng: FaultRng,
    drop: f64,
    garbage: f64,
    delay: Duration,
    silent: Option<(f64, f64)>,
    restart: Option<(f64, Duration)>,
    polled: bool,
    pty_heard: bool,
    time_limit_s: f64,
    stats: Arc<Mutex<FrontSeatStats>>,
}

/// Midday UTC: the first navigation record's time of day.
const START_S: f64 = 43_200.0;

impl FrontSeat {
    fn stat(&self, f: impl FnOnce(&mut FrontSeatStats)) {
        if let Ok(mut s) = self.stats.lock() {
            f(&mut s);
        }
    }

    fn gone(&self) -> bool {
        self.stats
            .lock()
            .is_ok_and(|s| s.back_seat_gone || s.finished)
    }

    fn connected(&self) -> bool {
        match &self.wire {
            Wire::Tcp { conn, .. } => conn.is_some(),
            Wire::Pty(_) => true,
        }
    }

    /// Accepts a back seat, waiting up to `wait`.
    fn accept(&mut self, wait: Duration) {
        let Wire::Tcp { listener, conn, .. } = &mut self.wire else {
            return;
        };
        let Some(l) = listener.as_ref() else { return };
        if conn.is_some() {
            return;
        }
        let deadline = Instant::now() + wait;
        let _ = l.set_nonblocking(true);
        loop {
            match l.accept() {
                Ok((s, _)) => {
                    let _ = s.set_nonblocking(false);
                    let _ = s.set_nodelay(true);
                    *conn = Some(s);
                    self.buf.clear();
                    self.stat(|s| s.connections += 1);
                    return;
                }
                Err(_) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(5)),
                Err(_) => return,
            }
        }
    }

    fn send(&mut self, line: &str) {
        if self.drop > 0.0 && self.rng.unit() < self.drop {
            return;
        }
        let failed = match &mut self.wire {
            Wire::Tcp { conn: Some(c), .. } => c.write_all(line.as_bytes()).is_err(),
            Wire::Tcp { conn: None, .. } => false,
            Wire::Pty(p) => p.controller.write_all(line.as_bytes()).is_err(),
        };
        if failed && let Wire::Tcp { conn, .. } = &mut self.wire {
            *conn = None;
        }
    }

    /// Reads what arrives within `wait` and returns the complete lines.
    fn read_lines(&mut self, wait: Duration) -> Vec<String> {
        let mut chunk = [0u8; 4096];
        let n = match &mut self.wire {
            Wire::Tcp { conn: Some(c), .. } => {
                plumetrace_onboard::transport::conn::read_tcp(c, &mut chunk, wait).map_err(|_| ())
            }
            Wire::Tcp { conn: None, .. } => {
                std::thread::sleep(wait.min(Duration::from_millis(10)));
                Ok(0)
            }
            Wire::Pty(p) => {
                let deadline = Instant::now() + wait;
                loop {
                    match p.controller.read(&mut chunk) {
                        Ok(n) if n > 0 => {
                            self.pty_heard = true;
                            break Ok(n);
                        }
                        Err(e) if e.kind() != std::io::ErrorKind::WouldBlock => {
                            // No back seat has the device open: not yet, or no more.
                            if self.pty_heard && self.lock_step {
                                if let Ok(mut st) = self.stats.lock() {
                                    st.back_seat_gone = true;
                                }
                                break Ok(0);
                            }
                            std::thread::sleep(wait.min(Duration::from_millis(20)));
                            break Ok(0);
                        }
                        _ if Instant::now() >= deadline => break Ok(0),
                        _ => std::thread::sleep(Duration::from_micros(200)),
                    }
                }
            }
        };
        match n {
            Ok(n) => self.buf.extend_from_slice(&chunk[..n]),
            Err(()) => {
                if let Wire::Tcp { conn, .. } = &mut self.wire {
                    *conn = None;
                }
                self.buf.clear();
            }
        }
        let mut lines = Vec::new();
        while let Some(k) = self.buf.iter().position(|b| *b == b'\n') {
            let raw: Vec<u8> = self.buf.drain(..=k).collect();
            lines.push(String::from_utf8_lossy(&raw).into_owned());
        }
        if self.buf.len() > 4096 {
            self.buf.clear();
        }
        lines
    }

    /// Applies a received line; returns whether it was a command (or a stop).
    fn take(&mut self, line: &str, time: UtcTime) -> bool {
        if line.trim().is_empty() {
            return false;
        }
        match self.protocol {
            Protocol::Bluefin => match bluefin::Sentence::parse(line) {
                Ok(bluefin::Sentence::Rmb(r)) => {
                    let stop = r.horizontal_mode == HorizontalMode::Rudder
                        || r.speed_mode == SpeedMode::Rpm;
                    let vertical = match r.vertical_mode {
                        VerticalMode::Depth => Some(VerticalCommand::Depth(r.vertical)),
                        VerticalMode::Altitude => Some(VerticalCommand::Altitude(r.vertical)),
                        VerticalMode::Pitch => None,
                    };
                    if stop {
                        self.stop();
                    } else {
                        self.steer(r.heading_deg, r.speed, vertical);
                    }
                    let ack = bluefin::Sentence::Ack(bluefin::Ack {
                        time,
                        acked: "RMB".into(),
                        command_time: r.time,
                        behaviour: "PAYLOAD".into(),
                        status: AckStatus::Ok,
                        reserved: String::new(),
                        description: "accepted".into(),
                    });
                    self.send(&ack.encode());
                    true
                }
                Ok(bluefin::Sentence::Sts {
                    ok: false, text, ..
                }) if text == "Finished" => {
                    self.stat(|s| s.finished = true);
                    false
                }
                Ok(_) => false,
                Err(_) => {
                    self.stat(|s| s.bad_lines += 1);
                    false
                }
            },
            Protocol::Iver => match iver::Sentence::parse(line) {
                Ok(iver::Sentence::Oms(o)) => {
                    let depth = self.units.depth_from_wire(o.depth);
                    self.steer(
                        o.heading_deg,
                        o.speed_kn * MPS_PER_KN,
                        Some(VerticalCommand::Depth(depth)),
                    );
                    true
                }
                Ok(iver::Sentence::Omstop) => {
                    self.stop();
                    true
                }
                Ok(iver::Sentence::Osd) => {
                    self.polled = true;
                    false
                }
                Ok(_) => false,
                Err(_) => {
                    self.stat(|s| s.bad_lines += 1);
                    false
                }
            },
        }
    }

    fn stop(&mut self) {
        self.stat(|s| s.stops += 1);
        if let Some(c) = self.command.as_mut() {
            c.speed_mps = 0.0;
        }
    }

    fn steer(&mut self, heading_deg: f64, speed_mps: f64, vertical: Option<VerticalCommand>) {
        let last = self.command;
        let vertical = vertical
            .or(last.map(|c| c.vertical))
            .unwrap_or(VerticalCommand::Surface);
        let c = Command {
            heading: Heading::from_deg(heading_deg),
            speed_mps,
            vertical,
        };
        if plumetrace_onboard::command::check(&c, &self.limits).is_err() {
            self.stat(|s| s.unsafe_commands += 1);
            return;
        }
        self.stat(|s| s.commands += 1);
        self.command = Some(c);
    }

    fn nav_lines(&mut self, s: &SensorSnapshot, time: UtcTime) -> Vec<String> {
        let pos = s.nav.pos_m.unwrap_or_default();
        let (lat, lon) = self.frame.to_geographic(pos);
        let heading = plumetrace_core::wrap_deg_360(s.nav.heading.deg());
        let v = plumetrace_core::heading_vector(s.nav.heading) * s.nav.speed_mps;
        let fixed = s
            .nav
            .last_fix_s
            .is_some_and(|f| s.time_s - f < self.nav_period_s.max(1e-9));
        match self.protocol {
            Protocol::Bluefin => vec![
                bluefin::Sentence::Nvg(bluefin::Nvg {
                    time,
                    lat_deg: lat,
                    lon_deg: lon,
                    quality: u32::from(fixed),
                    altitude_m: s.nav.altitude_m.unwrap_or(0.0),
                    depth_m: s.nav.depth_m.unwrap_or(0.0),
                    heading_deg: heading,
                    roll_deg: 0.0,
                    pitch_deg: 0.0,
                    computed: time,
                })
                .encode(),
                bluefin::Sentence::Nvr(bluefin::Nvr {
                    time,
                    east_mps: v.x,
                    north_mps: v.y,
                    down_mps: 0.0,
                    pitch_rate_dps: 0.0,
                    roll_rate_dps: 0.0,
                    yaw_rate_dps: 0.0,
                })
                .encode(),
            ],
            Protocol::Iver => vec![
                iver::Sentence::Osi(iver::Osi {
                    fin_motor: "0".into(),
                    mode: iver::Mode::Normal,
                    next_waypoint: 0,
                    lat_deg: lat,
                    lon_deg: lon,
                    speed_kn: s.nav.speed_mps / MPS_PER_KN,
                    distance_next: 0.0,
                    error: String::new(),
                    altitude_ft: s.nav.altitude_m.unwrap_or(0.0) / M_PER_FT,
                    park_time: String::new(),
                    declination_deg: 0.0,
                    mission: "rehearsal".into(),
                    remaining: String::new(),
                    heading_deg: heading,
                    depth_ft: s.nav.depth_m.unwrap_or(0.0) / M_PER_FT,
                })
                .encode(),
            ],
        }
    }

    fn maybe_restart(&mut self, t: f64) {
        let Some((at, pause)) = self.restart else {
            return;
        };
        if t < at {
            return;
        }
        self.restart = None;
        match &mut self.wire {
            Wire::Tcp {
                addr,
                listener,
                conn,
            } => {
                *conn = None;
                *listener = None;
                std::thread::sleep(pause);
                *listener = TcpListener::bind(*addr).ok();
            }
            Wire::Pty(p) => {
                // An Iver's computer restarting: the serial line stays, but nothing answers
                // and what the back seat sends meanwhile is lost; it comes back with a line of
                // boot text (not a sentence) and answers polls again.
                let deadline = Instant::now() + pause;
                let mut chunk = [0u8; 4096];
                while Instant::now() < deadline {
                    if !matches!(p.controller.read(&mut chunk), Ok(n) if n > 0) {
                        std::thread::sleep(Duration::from_millis(10));
                    }
                }
                let _ = p.controller.write_all(b"remote helm restarted\r\n");
                self.polled = false;
            }
        }
        self.stat(|s| s.restarts += 1);
        self.buf.clear();
    }
}

impl Planner for FrontSeat {
    fn decision_period_s(&self) -> f64 {
        self.nav_period_s
    }

    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        let t = s.time_s;
        let time = UtcTime::from_seconds(START_S + t);
        self.maybe_restart(t);
        if !self.connected() {
            let wait = if self.lock_step {
                self.wait
            } else {
                Duration::ZERO
            };
            self.accept(wait);
            if self.lock_step && !self.connected() {
                // In lock-step nothing moves without a back seat: it is gone, the mission ends.
                self.stat(|st| st.back_seat_gone = true);
            }
        }
        let silent = self.silent.is_some_and(|(a, d)| t >= a && t < a + d);
        if !self.delay.is_zero() {
            std::thread::sleep(self.delay);
        }
        // Iver answers polls: in lock-step, wait for the poll before answering.
        let mut answered = false;
        if self.protocol == Protocol::Iver && self.lock_step && !silent {
            let deadline = Instant::now() + self.wait;
            while !self.polled && Instant::now() < deadline && !self.gone() {
                for line in self.read_lines(Duration::from_millis(50)) {
                    answered |= self.take(&line, time);
                }
            }
            self.polled = false;
        }
        for c in &s.chem {
            let line = self.chem.encode(time, c.reading);
            self.send(&line);
        }
        // A new reading of the vehicle's flow sensor goes out as the current meter's sentence.
        if let Some(f) = s
            .flow
            .filter(|f| self.flow && self.last_flow_s != Some(f.time_s))
        {
            self.last_flow_s = Some(f.time_s);
            let cur = Cur::of_velocity(f.velocity_mps, s.nav.depth_m, 1);
            self.send(&cur.encode());
        }
        if self.garbage > 0.0 && self.rng.unit() < self.garbage {
            let n = (self.rng.unit() * 60.0) as usize;
            let junk: String = (0..n)
                .map(|_| char::from(32 + (self.rng.unit() * 95.0) as u8))
                .collect();
            self.send(&format!("${junk}*00\r\n"));
        }
        if silent {
            if self.protocol == Protocol::Bluefin {
                let tick = bluefin::Sentence::Ctl {
                    time,
                    accepting: true,
                };
                self.send(&tick.encode());
            }
        } else {
            for line in self.nav_lines(s, time) {
                self.send(&line);
            }
            self.stat(|st| st.nav_records += 1);
        }
        if self.lock_step && !silent && self.connected() {
            let deadline = Instant::now() + self.wait;
            while !answered && Instant::now() < deadline && self.connected() && !self.gone() {
                for line in self.read_lines(Duration::from_millis(50)) {
                    answered |= self.take(&line, time);
                }
                if self.stats.lock().is_ok_and(|s| s.finished) {
                    break;
                }
            }
            // Lines that came with the answer (a final status).
            for line in self.read_lines(Duration::ZERO) {
                self.take(&line, time);
            }
            if !answered {
                self.stat(|st| st.unanswered += 1);
            }
        } else {
            for line in self.read_lines(Duration::ZERO) {
                self.take(&line, time);
            }
        }
        if self.protocol == Protocol::Bluefin && t + self.nav_period_s >= self.time_limit_s - 1e-9 {
            // The last record: the clock's last tick tells the back seat the time is up.
            let end = UtcTime::from_seconds(START_S + self.time_limit_s);
            let tick = bluefin::Sentence::Ctl {
                time: end,
                accepting: false,
            };
            self.send(&tick.encode());
        }
        let finished = self
            .stats
            .lock()
            .is_ok_and(|s| s.finished || s.back_seat_gone);
        self.stat(|st| st.end_s = t);
        let command = self.command.unwrap_or(Command {
            heading: s.nav.heading,
            speed_mps: 0.0,
            vertical: VerticalCommand::Surface,
        });
        Decision::new(
            command,
            if finished {
                PlanStatus::Finished
            } else {
                PlanStatus::Running
            },
        )
    }
}

fn parse_origin(text: &str) -> Result<Origin> {
    let (a, b) = text
        .split_once(',')
        .context("--origin: give LAT,LON in degrees")?;
    let origin = Origin {
        lat_deg: a.trim().parse().context("--origin: latitude")?,
        lon_deg: b.trim().parse().context("--origin: longitude")?,
    };
    LocalFrame::new(origin)
        .map_err(anyhow::Error::msg)
        .context("--origin")?;
    Ok(origin)
}

/// The onboard file for a scenario's first planned vehicle and this link.
fn onboard_file(
    setup: &MissionSetup,
    link: &toml::Table,
    lock_step: bool,
    nav_period_s: f64,
    flow: bool,
) -> Result<String> {
    let k = setup
        .planners
        .iter()
        .position(Option::is_some)
        .context("the scenario has no vehicle with a planner")?;
    let Some(p) = &setup.planners[k] else {
        bail!("no planner")
    };
    let poly = |v: &[plumetrace_core::Vec2]| {
        toml::Value::Array(
            v.iter()
                .map(|p| toml::Value::Array(vec![p.x.into(), p.y.into()]))
                .collect(),
        )
    };
    let g = &p.context.geometry;
    let mut mission = toml::Table::new();
    mission.insert("op_area".into(), poly(g.op_area.vertices()));
    mission.insert(
        "subregions".into(),
        toml::Value::Array(g.subregions.iter().map(|r| poly(r.vertices())).collect()),
    );
    if g.prior_flow_given {
        mission.insert(
            "prior_flow_toward_deg".into(),
            g.prior_flow_toward_deg.into(),
        );
    }
    mission.insert(
        "vehicle_kind".into(),
        plumetrace_core::variant_name(&p.context.vehicle_kind)
            .unwrap_or("auv")
            .into(),
    );
    let mut run = toml::Table::new();
    run.insert(
        "mode".into(),
        if lock_step { "lock_step" } else { "real_time" }.into(),
    );
    run.insert("lock_step_period_s".into(), nav_period_s.into());
    run.insert("time_limit_s".into(), setup.spec.time_limit_s.into());
    let mut file = toml::Table::new();
    file.insert("name".into(), format!("{} on a vehicle", setup.name).into());
    file.insert("mission".into(), mission.into());
    file.insert(
        "planner".into(),
        p.config.to_table().map_err(anyhow::Error::msg)?.into(),
    );
    file.insert("link".into(), link.clone().into());
    if flow {
        // The current meter's sentences travel on the vehicle link.
        file.insert("flow".into(), toml::Table::new().into());
    }
    file.insert("run".into(), run.into());
    Ok(format!(
        "# Written by `plumetrace frontseat` for scenario '{}': the planner table, mission geometry\n# and link of its first planned vehicle.\n{}",
        setup.name,
        toml::to_string(&file)?
    ))
}

/// Runs the simulated front seat.
pub fn run(args: &FrontseatArgs) -> Result<()> {
    if !(args.nav_period_s.is_finite() && args.nav_period_s > 0.0 && args.nav_period_s <= 60.0) {
        bail!("--nav-period-s: {} is outside (0, 60]", args.nav_period_s);
    }
    for (name, p) in [("--drop", args.drop), ("--garbage", args.garbage)] {
        if !(0.0..=1.0).contains(&p) {
            bail!("{name}: {p} is not a probability in [0, 1]");
        }
    }
    for (name, v) in [
        ("--delay-s", args.delay_s),
        ("--wait-s", args.wait_s),
        ("--silent-for", args.silent_for),
        ("--restart-for", args.restart_for),
    ] {
        if !(v.is_finite() && (0.0..=3600.0).contains(&v)) {
            bail!("{name}: {v} is outside [0, 3600]");
        }
    }
    if args.protocol == Protocol::Iver && args.lock_step && args.silent_at.is_some() {
        bail!(
            "--silent-at: Iver sentences carry no time, so in lock-step a back seat cannot see navigation missing for a span of mission time; use --restart-at (the serial line silent for a span of wall time)"
        );
    }
    let origin = parse_origin(&args.origin)?;
    let frame = LocalFrame::new(origin).map_err(anyhow::Error::msg)?;
    let sc = crate::run::load(args.scenario.as_deref(), args.preset.as_deref(), args.seed)?;
    let name = sc.name.clone();
    let mut setup = MissionSetup::new(sc)?;
    if let Some(limit) = args.time_limit_s {
        if !(limit.is_finite() && limit > 0.0 && limit <= setup.spec.time_limit_s) {
            bail!(
                "--time-limit-s: {limit} is outside (0, {}] (the scenario's limit)",
                setup.spec.time_limit_s
            );
        }
        setup.spec.time_limit_s = limit;
    }
    let mut link = toml::Table::new();
    let mut origin_t = toml::Table::new();
    origin_t.insert("lat_deg".into(), origin.lat_deg.into());
    origin_t.insert("lon_deg".into(), origin.lon_deg.into());
    let (wire, where_) = match args.protocol {
        Protocol::Bluefin => {
            let listener = TcpListener::bind(&args.listen)
                .with_context(|| format!("listening on {}", args.listen))?;
            let addr = listener.local_addr()?;
            link.insert("protocol".into(), "bluefin".into());
            link.insert("address".into(), addr.to_string().into());
            (
                Wire::Tcp {
                    addr,
                    listener: Some(listener),
                    conn: None,
                },
                format!("listening on {addr}"),
            )
        }
        Protocol::Iver => {
            let pty = Pty::open().context("opening a pseudo-terminal")?;
            link.insert("protocol".into(), "iver".into());
            link.insert("device".into(), pty.path.display().to_string().into());
            link.insert(
                "remote_helm_major".into(),
                i64::from(args.remote_helm_major).into(),
            );
            let w = format!("device {}", pty.path.display());
            (Wire::Pty(pty), w)
        }
    };
    link.insert("origin".into(), origin_t.into());
    // A rehearsal's back seat stops soon after its front seat is gone for good; over a
    // pseudo-terminal it must not reopen the device at all (its number may soon belong to
    // another terminal), so it gives up before its first retry.
    let give_up = match args.protocol {
        Protocol::Bluefin => 5.0,
        Protocol::Iver => 0.05,
    };
    link.insert("give_up_s".into(), give_up.into());
    if let Some(path) = &args.write_onboard {
        let text = onboard_file(
            &setup,
            &link,
            args.lock_step,
            args.nav_period_s,
            !args.no_flow,
        )?;
        crate::output::write_atomic(path, text.as_bytes())?;
    }
    let k = setup
        .planners
        .iter()
        .position(Option::is_some)
        .context("the scenario has no vehicle with a planner")?;
    let stats = Arc::new(Mutex::new(FrontSeatStats::default()));
    let seat = FrontSeat {
        protocol: args.protocol,
        wire,
        buf: Vec::new(),
        frame,
        nav_period_s: args.nav_period_s,
        lock_step: args.lock_step,
        wait: Duration::from_secs_f64(args.wait_s),
        chem: ChemFormat::default(),
        flow: !args.no_flow,
        last_flow_s: None,
        units: Units {
            remote_helm_major: args.remote_helm_major,
        },
        limits: VehicleLimits::default(),
        command: None,
        rng: FaultRng(args.fault_seed),
        drop: args.drop,
        garbage: args.garbage,
        delay: Duration::from_secs_f64(args.delay_s),
        silent: args.silent_at.map(|a| (a, args.silent_for)),
        restart: args
            .restart_at
            .map(|a| (a, Duration::from_secs_f64(args.restart_for))),
        polled: false,
        pty_heard: false,
        time_limit_s: setup.spec.time_limit_s,
        stats: stats.clone(),
    };
    // The front seat stands in for vehicle k's planner; other vehicles fly their own.
    let mut mission = Mission::new(setup, MissionOptions::default())?;
    mission.replace_planner(k, Box::new(seat))?;
    crate::outln!("{name}: front seat {where_}");
    let pace = !args.lock_step;
    // Real time starts when the plume has spun up.
    let started = Instant::now();
    loop {
        let end = mission.step()?;
        if pace {
            let ahead = mission.time_s() - started.elapsed().as_secs_f64();
            if ahead > 0.0 {
                std::thread::sleep(Duration::from_secs_f64(ahead.min(1.0)));
            }
        }
        if end.is_some() {
            break;
        }
    }
    let t = mission.time_s();
    drop(mission);
    let s = stats.lock().map(|s| s.clone()).unwrap_or_default();
    crate::outln!(
        "{name}: front seat ended at {t:.1} s: {} navigation records, {} commands, {} stops, {} unsafe, {} bad lines, {} connections, {} unanswered{}",
        s.nav_records,
        s.commands,
        s.stops,
        s.unsafe_commands,
        s.bad_lines,
        s.connections,
        s.unanswered,
        if s.finished {
            "; the back seat finished"
        } else if s.back_seat_gone {
            "; the back seat went away"
        } else {
            ""
        }
    );
    if let Some(out) = &args.out {
        std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
        crate::output::write_atomic(
            &out.join("frontseat.json"),
            serde_json::to_string_pretty(&s)?.as_bytes(),
        )?;
    }
    Ok(())
}
