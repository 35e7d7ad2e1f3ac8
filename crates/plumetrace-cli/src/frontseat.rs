//! `plumetrace frontseat`: a simulated front seat (`plumetrace_frontseat`). It flies a scenario's
//! vehicle and plume and speaks a front-seat protocol to a back seat (`plumetrace onboard`): the
//! Bluefin standard payload interface on a TCP port, or the Iver remote helm on a
//! pseudo-terminal. This command reads the flags, loads the scenario, writes the onboard file and
//! `frontseat.json`, and prints where the front seat is and what it saw.

use anyhow::{Context, Result};
use plumetrace_frontseat::{Faults, FrontSeatOptions, Rehearsal};
use plumetrace_onboard::geo::Origin;
use std::path::PathBuf;

/// The protocol a front seat speaks (`--protocol`).
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

impl FrontseatArgs {
    /// The rehearsal's options.
    fn options(&self, origin: Origin) -> FrontSeatOptions {
        FrontSeatOptions {
            protocol: match self.protocol {
                Protocol::Bluefin => plumetrace_frontseat::Protocol::Bluefin,
                Protocol::Iver => plumetrace_frontseat::Protocol::Iver,
            },
            listen: self.listen.clone(),
            remote_helm_major: self.remote_helm_major,
            lock_step: self.lock_step,
            nav_period_s: self.nav_period_s,
            origin,
            wait_s: self.wait_s,
            faults: Faults {
                drop: self.drop,
                garbage: self.garbage,
                delay_s: self.delay_s,
                silent_at: self.silent_at,
                silent_for: self.silent_for,
                restart_at: self.restart_at,
                restart_for: self.restart_for,
                seed: self.fault_seed,
            },
            time_limit_s: self.time_limit_s,
            flow: !self.no_flow,
        }
    }
}

/// `LAT,LON` in degrees (its range is checked with the other options).
fn parse_origin(text: &str) -> Result<Origin> {
    let (a, b) = text
        .split_once(',')
        .context("--origin: give LAT,LON in degrees")?;
    Ok(Origin {
        lat_deg: a.trim().parse().context("--origin: latitude")?,
        lon_deg: b.trim().parse().context("--origin: longitude")?,
    })
}

/// Runs the simulated front seat.
pub fn run(args: &FrontseatArgs) -> Result<()> {
    let options = args.options(parse_origin(&args.origin)?);
    options.check()?;
    let sc = crate::run::load(args.scenario.as_deref(), args.preset.as_deref(), args.seed)?;
    let rehearsal = Rehearsal::prepare(sc, &options)?;
    if let Some(path) = &args.write_onboard {
        crate::output::write_atomic(path, rehearsal.onboard_file()?.as_bytes())?;
    }
    let flight = rehearsal.start()?;
    let name = flight.name().to_string();
    crate::outln!("{name}: front seat {}", flight.location());
    let report = flight.fly()?;
    let s = &report.stats;
    crate::outln!(
        "{name}: front seat ended at {:.1} s: {} navigation records, {} commands, {} stops, {} unsafe, {} bad lines, {} connections, {} unanswered{}",
        report.time_s,
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
        crate::output::create_out_dir(out)?;
        crate::output::write_atomic(
            &out.join("frontseat.json"),
            serde_json::to_string_pretty(s)?.as_bytes(),
        )?;
    }
    Ok(())
}
