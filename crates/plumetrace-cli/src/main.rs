//! The `plumetrace` command.
//!
//! Subcommands: `run` (fly a mission, or simulate a plume, and write the outputs), `presets` (list
//! the built-in scenarios), `check` (validate a scenario file), `campaign` and `merge` (Monte
//! Carlo campaigns), `bench plume` (time the plume model on pompy's scenario or a field-scale one)
//! and `bench missions` (missions per second on 1 and more threads); benchmarks print JSON.

mod bench;
mod campaign;
mod mission;
mod output;
mod plot;
mod progress;
mod run;

use anyhow::Result;
use clap::{Parser, Subcommand};
use std::path::PathBuf;

/// Chemical plume tracing with marine robots: plume simulation, planners, campaigns.
#[derive(Debug, Parser)]
#[command(name = "plumetrace", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run a scenario (a file or a built-in preset) and write its outputs into a directory.
    Run(run::RunArgs),
    /// List the built-in scenarios, one line each.
    Presets,
    /// Validate a scenario file and print the first error with its key path.
    Check {
        /// The scenario file (TOML).
        file: PathBuf,
    },
    /// Run a Monte Carlo campaign (resumable, parallel, shardable) and summarise it.
    Campaign(campaign::CampaignArgs),
    /// Merge the output directories of a campaign's shards.
    Merge(campaign::MergeArgs),
    /// Benchmarks; print one JSON object.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
}

fn main() {
    let cli = Cli::parse();
    if let Err(e) = dispatch(cli) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn dispatch(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Run(args) => run::run(&args),
        Command::Presets => {
            let width = plumetrace_scenario::PRESETS
                .iter()
                .map(|p| p.name.len())
                .max()
                .unwrap_or(0);
            for p in plumetrace_scenario::PRESETS {
                println!("{:width$}  {}", p.name, p.summary);
            }
            Ok(())
        }
        Command::Check { file } => {
            let cfg = plumetrace_scenario::load_file(&file)?;
            let origin = plumetrace_scenario::Origin::File(file.clone());
            let built = plumetrace_scenario::build(&cfg, &origin, None)?;
            if let Some(pc) = &cfg.planner {
                plumetrace_mission::amp_params(pc)
                    .map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
            }
            let what = if built.mission.is_some() {
                "mission"
            } else {
                "plume run"
            };
            println!(
                "{}: ok ({what}, {} steps of {} s)",
                file.display(),
                built.steps,
                built.dt_s
            );
            Ok(())
        }
        Command::Campaign(args) => campaign::run(&args),
        Command::Merge(args) => campaign::run_merge(&args),
        Command::Bench(b) => bench::run(&b),
    }
}
