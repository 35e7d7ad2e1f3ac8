//! The front seat in the vehicle's planner slot: each decision opportunity sends the vehicle's
//! navigation record and readings on the line, takes the commands that come back (in lock-step
//! it waits for the answer), and steers the simulated vehicle by the last command that passed
//! the vehicle's limits.

use crate::options::{FrontSeatOptions, Protocol};
use crate::stats::{FaultRng, FrontSeatStats};
use crate::wire::Wire;
use plumetrace_core::{
    Command, Decision, Heading, PlanStatus, Planner, SensorSnapshot, VerticalCommand,
};
use plumetrace_onboard::command::{VehicleLimits, check};
use plumetrace_onboard::geo::LocalFrame;
use plumetrace_onboard::protocol::bluefin::{
    self, AckStatus, HorizontalMode, SpeedMode, VerticalMode,
};
use plumetrace_onboard::protocol::chem::ChemFormat;
use plumetrace_onboard::protocol::current::Cur;
use plumetrace_onboard::protocol::iver::{self, M_PER_FT, MPS_PER_KN, Units};
use plumetrace_onboard::protocol::sentence::UtcTime;
use plumetrace_onboard::transport::lines::LineBuffer;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The simulated front seat, sitting in the vehicle's planner slot.
pub(crate) struct FrontSeat {
    pub(crate) protocol: Protocol,
    pub(crate) wire: Wire,
    pub(crate) lines: LineBuffer,
    pub(crate) frame: LocalFrame,
    pub(crate) nav_period_s: f64,
    pub(crate) lock_step: bool,
    pub(crate) wait: Duration,
    pub(crate) chem: ChemFormat,
    pub(crate) flow: bool,
    pub(crate) last_flow_s: Option<f64>,
    pub(crate) units: Units,
    pub(crate) limits: VehicleLimits,
    pub(crate) command: Option<Command>,
    pub(crate) rng: FaultRng,
    pub(crate) drop: f64,
    // Lines the drop fault has dropped.
    pub(crate) dropped: u64,
    pub(crate) garbage: f64,
    pub(crate) delay: Duration,
    pub(crate) silent: Option<(f64, f64)>,
    pub(crate) restart: Option<(f64, Duration)>,
    pub(crate) polled: bool,
    pub(crate) pty_heard: bool,
    pub(crate) time_limit_s: f64,
    pub(crate) stats: Arc<Mutex<FrontSeatStats>>,
}

/// Midday UTC: the first navigation record's time of day.
const START_S: f64 = 43_200.0;

impl FrontSeat {
    /// The front seat `options` ask for on `wire`, positions about `frame`, the mission ending
    /// at `time_limit_s`; what it sees goes to `stats`.
    pub(crate) fn new(
        options: &FrontSeatOptions,
        wire: Wire,
        frame: LocalFrame,
        time_limit_s: f64,
        stats: Arc<Mutex<FrontSeatStats>>,
    ) -> Self {
        let f = &options.faults;
        FrontSeat {
            protocol: options.protocol,
            wire,
            lines: LineBuffer::default(),
            frame,
            nav_period_s: options.nav_period_s,
            lock_step: options.lock_step,
            wait: Duration::from_secs_f64(options.wait_s),
            chem: ChemFormat::default(),
            flow: options.flow,
            last_flow_s: None,
            units: Units {
                remote_helm_major: options.remote_helm_major,
            },
            limits: VehicleLimits::default(),
            command: None,
            rng: FaultRng(f.seed),
            drop: f.drop,
            dropped: 0,
            garbage: f.garbage,
            delay: Duration::from_secs_f64(f.delay_s),
            silent: f.silent_at.map(|a| (a, f.silent_for)),
            restart: f
                .restart_at
                .map(|a| (a, Duration::from_secs_f64(f.restart_for))),
            polled: false,
            pty_heard: false,
            time_limit_s,
            stats,
        }
    }

    /// Updates the shared statistics.
    pub(crate) fn stat(&self, f: impl FnOnce(&mut FrontSeatStats)) {
        if let Ok(mut s) = self.stats.lock() {
            f(&mut s);
        }
    }

    /// Whether the back seat finished or went away.
    pub(crate) fn gone(&self) -> bool {
        self.stats
            .lock()
            .is_ok_and(|s| s.back_seat_gone || s.finished)
    }

    /// Applies a received line; returns whether it was a command (or a stop).
    pub(crate) fn take(&mut self, line: &str, time: UtcTime) -> bool {
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

    /// A stop: the vehicle keeps its heading and depth at no speed.
    fn stop(&mut self) {
        self.stat(|s| s.stops += 1);
        if let Some(c) = self.command.as_mut() {
            c.speed_mps = 0.0;
        }
    }

    /// A set-point: steered by when it passes the vehicle's limits, else counted as unsafe.
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
        if check(&c, &self.limits).is_err() {
            self.stat(|s| s.unsafe_commands += 1);
            return;
        }
        self.stat(|s| s.commands += 1);
        self.command = Some(c);
    }

    /// The navigation record of a snapshot in the protocol's sentences.
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

    /// Without a back seat, accepts one (in lock-step waiting for it; nothing moves without
    /// it, so one that does not come is gone and the mission ends).
    fn reconnect(&mut self) {
        if self.connected() {
            return;
        }
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

    /// Iver answers polls: in lock-step, waits for the poll before answering; returns whether a
    /// command came meanwhile.
    fn await_poll(&mut self, time: UtcTime) -> bool {
        let mut answered = false;
        let deadline = Instant::now() + self.wait;
        while !self.polled && Instant::now() < deadline && !self.gone() {
            for line in self.read_lines(Duration::from_millis(50)) {
                answered |= self.take(&line, time);
            }
        }
        self.polled = false;
        answered
    }

    /// The chemical readings, a new current reading and (the garbage fault) a garbage line.
    fn send_readings(&mut self, s: &SensorSnapshot, time: UtcTime) {
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
    }

    /// In lock-step, waits for the answer to the record just sent (`answered`: it came while
    /// waiting for the poll); otherwise takes what is there.
    fn await_answer(&mut self, time: UtcTime, silent: bool, mut answered: bool) {
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
    }
}

impl FrontSeat {
    /// After the clock's last tick, takes what the back seat sends until it says it finished
    /// (its final stop and status), so the connection does not close under them.
    fn await_finish(&mut self, time: UtcTime) {
        let wait = if self.lock_step {
            self.wait
        } else {
            self.wait.min(Duration::from_secs(2))
        };
        let deadline = Instant::now() + wait;
        while Instant::now() < deadline && self.connected() && !self.gone() {
            for line in self.read_lines(Duration::from_millis(50)) {
                self.take(&line, time);
            }
        }
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
        self.reconnect();
        let silent = self.silent.is_some_and(|(a, d)| t >= a && t < a + d);
        if !self.delay.is_zero() {
            std::thread::sleep(self.delay);
        }
        let answered =
            self.protocol == Protocol::Iver && self.lock_step && !silent && self.await_poll(time);
        self.send_readings(s, time);
        if silent && self.protocol == Protocol::Bluefin {
            let tick = bluefin::Sentence::Ctl {
                time,
                accepting: true,
            };
            self.send(&tick.encode());
        }
        let dropped = self.dropped;
        if !silent {
            for line in self.nav_lines(s, time) {
                self.send(&line);
            }
            self.stat(|st| st.nav_records += 1);
        }
        // A record the drop fault broke gets no answer: in lock-step the front seat steps on
        // at once, as a vehicle's clock would, instead of waiting for one.
        let broken = self.dropped != dropped;
        self.await_answer(time, silent || broken, answered);
        if self.protocol == Protocol::Bluefin && t + self.nav_period_s >= self.time_limit_s - 1e-9 {
            // The last record: the clock's last tick tells the back seat the time is up.
            let end = UtcTime::from_seconds(START_S + self.time_limit_s);
            let tick = bluefin::Sentence::Ctl {
                time: end,
                accepting: false,
            };
            self.send(&tick.encode());
            self.await_finish(end);
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
