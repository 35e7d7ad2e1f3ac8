//! `plumetrace run`: simulate a scenario and write its outputs.
//!
//! A mission scenario is flown ([`crate::mission`]); a scenario without vehicles simulates the
//! environment alone ([`plumetrace_plume_run`]) and writes a concentration snapshot, the
//! time-averaged concentration and intermittency, the final filaments, statistics and a figure,
//! and when `[output]` asks for them the probe series and filament snapshots (with the `netcdf`
//! feature also `plume.nc`).

use anyhow::Result;
use plumetrace_scenario::BuiltScenario;
use std::path::{Path, PathBuf};

/// Arguments of `plumetrace run`.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// The scenario, with `--preset`, `--planner` and `--set`.
    #[command(flatten)]
    scenario: crate::load::ScenarioArgs,
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

/// Loads a scenario from a file or preset (printing its warnings).
pub fn load(
    scenario: Option<&Path>,
    preset: Option<&str>,
    seed: Option<u64>,
) -> Result<BuiltScenario> {
    let a = crate::load::ScenarioArgs {
        scenario: scenario.map(Path::to_path_buf),
        preset: preset.map(str::to_string),
        ..Default::default()
    };
    Ok(crate::load::load(&a, seed)?.built)
}

/// Runs the scenario: a mission when it has one, otherwise the plume alone.
pub fn run(args: &RunArgs) -> Result<()> {
    let crate::load::Loaded { built: sc, place } = crate::load::load(&args.scenario, args.seed)?;
    crate::output::create_out_dir(&args.out)?;
    if let Some(path) = &args.scenario.scenario {
        crate::output::refuse_overwriting(path, &args.out, OUTPUTS)?;
    }
    if sc.mission.is_some() {
        crate::mission::run(sc, &args.out, args.stats, !args.no_snapshot_log, args.alog)
            .map_err(|e| place.locate(e))
    } else {
        let origin = sc.origin.clone();
        run_plume(sc, args).map_err(|e| place.at_origin(&origin, e))
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
    plumetrace_report::geo_outputs::GEOJSON,
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
