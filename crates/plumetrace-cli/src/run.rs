//! `plumetrace run`: simulate a scenario and write its outputs.
//!
//! A mission scenario is flown ([`crate::mission`]); a scenario without vehicles simulates the
//! environment alone ([`plumetrace_plume_run`]) and writes a concentration snapshot, the
//! time-averaged concentration and intermittency, the final filaments, statistics and a figure,
//! and when `[output]` asks for them the probe series and filament snapshots (with the `netcdf`
//! feature also `plume.nc`).

use anyhow::{Context, Result, bail};
use plumetrace_scenario::{BuiltScenario, Origin};
use std::path::{Path, PathBuf};

/// Arguments of `plumetrace run`.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// Scenario file (TOML); give this or --preset.
    scenario: Option<PathBuf>,
    /// Built-in scenario (see `plumetrace presets`).
    #[arg(long, conflicts_with = "scenario")]
    preset: Option<String>,
    /// Run seed (overrides the scenario's).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::seed)]
    seed: Option<u64>,
    /// Output directory (created if needed).
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// Print the time spent in each stage of the step.
    #[arg(long)]
    stats: bool,
    /// Do not write the snapshot log (`snapshots.jsonl.gz`: every snapshot and decision of every
    /// planner, for `plumetrace replay`).
    #[arg(long)]
    no_snapshot_log: bool,
    /// Also write a MOOS `.alog` per vehicle with a planner (`NAME.alog`: navigation, set-points,
    /// behaviour, readings, detections, declarations).
    #[arg(long)]
    alog: bool,
}

/// Loads a scenario from a file or preset.
pub fn load(
    scenario: Option<&Path>,
    preset: Option<&str>,
    seed: Option<u64>,
) -> Result<BuiltScenario> {
    let (cfg, origin) = match (scenario, preset) {
        (Some(path), None) => (
            plumetrace_scenario::load_file(path)?,
            Origin::File(path.to_path_buf()),
        ),
        (None, Some(name)) => (
            plumetrace_scenario::load_preset(name)?,
            Origin::Preset(name.to_string()),
        ),
        (None, None) => bail!("give a scenario file or --preset NAME (see `plumetrace presets`)"),
        (Some(_), Some(_)) => bail!("give a scenario file or --preset, not both"),
    };
    Ok(plumetrace_scenario::build(&cfg, &origin, seed)?)
}

/// Runs the scenario: a mission when it has one, otherwise the plume alone.
pub fn run(args: &RunArgs) -> Result<()> {
    let sc = load(args.scenario.as_deref(), args.preset.as_deref(), args.seed)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    if let Some(path) = &args.scenario {
        crate::output::refuse_overwriting(path, &args.out, OUTPUTS)?;
    }
    if sc.mission.is_some() {
        crate::mission::run(sc, &args.out, args.stats, !args.no_snapshot_log, args.alog)
    } else {
        run_plume(sc, args)
    }
}

/// Every file `run` may write into its output directory.
pub const OUTPUTS: &[&str] = &[
    "summary.json",
    "trajectory.csv",
    "events.jsonl",
    "plot.svg",
    crate::mission::REPLAY_PAGE,
    crate::mission::SNAPSHOT_LOG,
    "stats.json",
    "snapshot.csv",
    "filaments.csv",
    "plume.svg",
    "probes.csv",
    "filament_series.csv",
    "plume.nc",
];

/// Runs the plume alone ([`plumetrace_plume_run::run_plume`]) and draws its figure.
fn run_plume(sc: BuiltScenario, args: &RunArgs) -> Result<()> {
    let mut progress = crate::progress::reporter("steps");
    let stats = plumetrace_plume_run::run_plume(sc, &args.out, &mut progress, &mut |f| {
        Ok(plumetrace_report::plume_figure(
            f.scenario,
            f.snapshot,
            f.mean,
            f.mean_samples,
        )?)
    })?;
    if let Some(warning) = stats.filament_series_warning() {
        eprintln!("{warning}");
    }
    if args.stats {
        eprintln!(
            "stage times: advance environment {:.3} s, sense (time average, probes) {:.3} s, \
             record {:.3} s",
            stats.stage_times.advance_environment_s,
            stats.stage_times.sense_s,
            stats.stage_times.record_s
        );
    }
    let live = stats
        .filaments
        .map(|f| format!(", {} live filaments", f.live))
        .unwrap_or_default();
    crate::outln!(
        "{}: simulated {:.0} s in {:.2} s ({:.0}x real time){live}; wrote {}",
        stats.scenario,
        stats.sim_time_s,
        stats.wall_s,
        stats.sim_s_per_wall_s,
        args.out.display()
    );
    Ok(())
}
