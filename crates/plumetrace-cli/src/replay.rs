//! `plumetrace replay LOG`: feed a snapshot log to fresh planners built from its header (or from
//! another planner table) and report where their decisions differ from the logged ones.

use anyhow::{Context, Result};
use std::path::PathBuf;

/// Arguments of `plumetrace replay`.
#[derive(Debug, clap::Args)]
pub struct ReplayArgs {
    /// The snapshot log (`snapshots.jsonl.gz` written by `plumetrace run`).
    pub log: PathBuf,
    /// A planner table (TOML with `kind` and keys) to replay every logged vehicle with instead
    /// of its own configuration.
    #[arg(long)]
    pub planner_file: Option<PathBuf>,
}

/// Replays and prints the report; exits with an error if the log cannot be read.
pub fn run(args: &ReplayArgs) -> Result<()> {
    let other: Option<toml::Table> = match &args.planner_file {
        Some(p) => {
            let text =
                std::fs::read_to_string(p).with_context(|| format!("reading {}", p.display()))?;
            Some(text.parse().with_context(|| format!("{}", p.display()))?)
        }
        None => None,
    };
    let log = plumetrace_mission::snapshot_log::open(&args.log)
        .with_context(|| format!("opening {}", args.log.display()))?;
    let report = plumetrace_mission::snapshot_log::replay(log, &|_| other.clone())
        .with_context(|| format!("{}", args.log.display()))?;
    println!(
        "{}: {} decisions replayed, {} differ",
        args.log.display(),
        report.decisions,
        report.differing
    );
    for d in &report.first {
        println!(
            "  line {}, vehicle {}, t = {:.1} s: logged heading {:.2} deg, speed {:.2} m/s, status {:?}; replayed heading {:.2} deg, speed {:.2} m/s, status {:?}",
            d.line,
            d.vehicle,
            d.t_s,
            d.logged.command.heading.deg(),
            d.logged.command.speed_mps,
            d.logged.status,
            d.replayed.command.heading.deg(),
            d.replayed.command.speed_mps,
            d.replayed.status,
        );
    }
    Ok(())
}
