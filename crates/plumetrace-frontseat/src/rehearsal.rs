//! A rehearsal in three steps: [`Rehearsal::prepare`] opens the front seat's end of the line (a
//! TCP port or a pseudo-terminal) and gives the onboard file its back seat flies;
//! [`Rehearsal::start`] builds the mission (the plume spun up) with the front seat in the planned
//! vehicle's slot; [`Flight::fly`] steps it to its end (paced to the wall clock in real time) and
//! reports what the front seat saw.

use crate::options::{FrontSeatOptions, Protocol};
use crate::seat::FrontSeat;
use crate::stats::FrontSeatStats;
use crate::wire::Wire;
use crate::{FrontSeatError, onboard_file};
use plumetrace_mission::{Mission, MissionOptions, MissionSetup};
use plumetrace_onboard::geo::LocalFrame;
use plumetrace_onboard::transport::serial::Pty;
use plumetrace_scenario::BuiltScenario;
use std::net::TcpListener;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// A rehearsal with its line open, before its mission is built.
pub struct Rehearsal {
    name: String,
    setup: MissionSetup,
    seat: FrontSeat,
    stats: Arc<Mutex<FrontSeatStats>>,
    link: toml::Table,
    location: String,
    lock_step: bool,
    nav_period_s: f64,
    flow: bool,
}

/// The `[link]` table of the onboard file and the front seat's end of the line.
fn open_wire(options: &FrontSeatOptions) -> Result<(toml::Table, Wire, String), FrontSeatError> {
    let mut link = toml::Table::new();
    let mut origin_t = toml::Table::new();
    origin_t.insert("lat_deg".into(), options.origin.lat_deg.into());
    origin_t.insert("lon_deg".into(), options.origin.lon_deg.into());
    let (wire, location) = match options.protocol {
        Protocol::Bluefin => {
            let listener =
                TcpListener::bind(&options.listen).map_err(|error| FrontSeatError::Listen {
                    address: options.listen.clone(),
                    error,
                })?;
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
            let pty = Pty::open().map_err(FrontSeatError::Pty)?;
            link.insert("protocol".into(), "iver".into());
            link.insert("device".into(), pty.path.display().to_string().into());
            link.insert(
                "remote_helm_major".into(),
                i64::from(options.remote_helm_major).into(),
            );
            let w = format!("device {}", pty.path.display());
            (Wire::Pty(pty), w)
        }
    };
    link.insert("origin".into(), origin_t.into());
    // A rehearsal's back seat stops soon after its front seat is gone for good; over a
    // pseudo-terminal it must not reopen the device at all (its number may soon belong to
    // another terminal), so it gives up before its first retry. Over TCP it tries again at
    // least every second, and gives up 5 s after a restart fault's end at the earliest.
    let give_up = match options.protocol {
        Protocol::Bluefin => {
            link.insert("reconnect_max_s".into(), 1.0.into());
            5.0 + options
                .faults
                .restart_at
                .map_or(0.0, |_| options.faults.restart_for)
        }
        Protocol::Iver => 0.05,
    };
    link.insert("give_up_s".into(), give_up.into());
    Ok((link, wire, location))
}

impl Rehearsal {
    /// Checks `options`, sets the scenario's mission up and opens the front seat's end of the
    /// line (the TCP port is listening, or the pseudo-terminal open, when this returns).
    pub fn prepare(sc: BuiltScenario, options: &FrontSeatOptions) -> Result<Self, FrontSeatError> {
        options.check()?;
        let frame = LocalFrame::new(options.origin).map_err(|e| FrontSeatError::Option {
            option: "--origin",
            message: e.to_string(),
        })?;
        let name = sc.name.clone();
        let mut setup = MissionSetup::new(sc)?;
        if let Some(limit) = options.time_limit_s {
            if !(limit.is_finite() && limit > 0.0 && limit <= setup.spec.time_limit_s) {
                return Err(FrontSeatError::Option {
                    option: "--time-limit-s",
                    message: format!(
                        "{limit} is outside (0, {}] (the scenario's limit)",
                        setup.spec.time_limit_s
                    ),
                });
            }
            setup.spec.time_limit_s = limit;
        }
        let (link, wire, location) = open_wire(options)?;
        let stats = Arc::new(Mutex::new(FrontSeatStats::default()));
        let seat = FrontSeat::new(options, wire, frame, setup.spec.time_limit_s, stats.clone());
        Ok(Rehearsal {
            name,
            setup,
            seat,
            stats,
            link,
            location,
            lock_step: options.lock_step,
            nav_period_s: options.nav_period_s,
            flow: options.flow,
        })
    }

    /// The scenario's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Where the front seat is (`listening on ADDRESS`, `device PATH`).
    pub fn location(&self) -> &str {
        &self.location
    }

    /// The onboard file's `[link]` table: this front seat's address or device, the origin, and
    /// the back seat's give-up time.
    pub fn link_table(&self) -> &toml::Table {
        &self.link
    }

    /// The onboard file for the scenario's first planned vehicle and this link (TOML, with a
    /// comment saying what wrote it).
    pub fn onboard_file(&self) -> Result<String, FrontSeatError> {
        onboard_file::onboard_file(
            &self.setup,
            &self.link,
            self.lock_step,
            self.nav_period_s,
            self.flow,
        )
    }

    /// Builds the mission (the plume spun up) with the front seat standing in for the first
    /// planned vehicle's planner; other vehicles fly their own.
    pub fn start(self) -> Result<Flight, FrontSeatError> {
        let k = self
            .setup
            .planners
            .iter()
            .position(Option::is_some)
            .ok_or(FrontSeatError::NoPlanner)?;
        let mut mission = Mission::new(self.setup, MissionOptions::default())?;
        mission.replace_planner(k, Box::new(self.seat))?;
        Ok(Flight {
            name: self.name,
            mission,
            stats: self.stats,
            location: self.location,
            pace: !self.lock_step,
        })
    }
}

/// A rehearsal's mission, built and ready to fly.
pub struct Flight {
    name: String,
    mission: Mission,
    stats: Arc<Mutex<FrontSeatStats>>,
    location: String,
    pace: bool,
}

/// What a rehearsal came to.
#[derive(Debug, Clone)]
pub struct FrontSeatReport {
    /// The scenario's name.
    pub name: String,
    /// Mission time at the end, s.
    pub time_s: f64,
    /// What the front seat saw.
    pub stats: FrontSeatStats,
}

impl Flight {
    /// The scenario's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Where the front seat is (`listening on ADDRESS`, `device PATH`).
    pub fn location(&self) -> &str {
        &self.location
    }

    /// Steps the mission to its end: in real time paced to the wall clock from now, in
    /// lock-step as fast as the back seat answers.
    pub fn fly(mut self) -> Result<FrontSeatReport, FrontSeatError> {
        // Real time starts when the plume has spun up.
        let started = Instant::now();
        loop {
            let end = self.mission.step()?;
            if self.pace {
                let ahead = self.mission.time_s() - started.elapsed().as_secs_f64();
                if ahead > 0.0 {
                    std::thread::sleep(Duration::from_secs_f64(ahead.min(1.0)));
                }
            }
            if end.is_some() {
                break;
            }
        }
        let time_s = self.mission.time_s();
        drop(self.mission);
        let stats = self.stats.lock().map(|s| s.clone()).unwrap_or_default();
        Ok(FrontSeatReport {
            name: self.name,
            time_s,
            stats,
        })
    }
}
