//! `plumetrace run`: simulate a scenario and write its outputs.
//!
//! A mission scenario is flown ([`crate::mission`]); a scenario without vehicles simulates the
//! environment alone and writes a concentration snapshot, the time-averaged concentration and
//! intermittency, the final filaments, statistics and a figure, and when `[output]` asks for them
//! the probe series and filament snapshots ([`crate::series`]; with the `netcdf` feature also
//! `plume.nc`, [`crate::netcdf`]).

use crate::output::write_atomic;
use crate::series::{FilamentSeries, ProbeSeries, time_decimals};
use anyhow::{Context, Result, bail};
use plumetrace_env::{ConcentrationField, FlowField, MeanConcentrationGrid, Plume};
use plumetrace_scenario::{BuiltScenario, Origin};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

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

#[derive(Debug, Serialize)]
struct RunStats {
    scenario: String,
    seed: u64,
    steps: u64,
    dt_s: f64,
    sim_time_s: f64,
    wall_s: f64,
    sim_s_per_wall_s: f64,
    flow_model: &'static str,
    flow_max_stable_dt_s: Option<f64>,
    plume_model: &'static str,
    filaments: Option<plumetrace_env::PlumeStats>,
    mean_samples: u32,
    snapshot_z_m: f64,
    max_concentration: f64,
    max_mean_concentration: f64,
    intermittency_threshold: f64,
    /// Probe samples written to `probes.csv` (0 without probes).
    probe_samples: usize,
    /// Probes per sample.
    probes: usize,
    /// Filament snapshots written to `filament_series.csv`.
    filament_snapshots: u32,
    /// Filament snapshots not written because the file reached its row limit.
    filament_snapshots_skipped: u32,
    /// Rows of `filament_series.csv`.
    filament_series_rows: u64,
    /// The plume run's stages: advance environment, sense (sampling the time average and the
    /// probes), record (filament snapshots and writing the outputs).
    stage_times: plumetrace_sim::StageTimes,
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

/// Runs the plume alone and writes `stats.json`, `snapshot.csv`, `filaments.csv` and `plume.svg`,
/// and with `[output]` series `probes.csv`, `filament_series.csv` and (feature `netcdf`)
/// `plume.nc`.
fn run_plume(mut sc: BuiltScenario, args: &RunArgs) -> Result<()> {
    let started = Instant::now();
    let mut times = plumetrace_sim::StageTimes::default();
    let spec = sc.output.clone();
    let mut mean = MeanConcentrationGrid::new(spec.grid, spec.threshold);
    let steady = matches!(sc.env.plume(), Plume::Steady(_));
    let t_decimals = time_decimals(sc.env.dt_s());
    let mut probes = ProbeSeries::new(spec.probes.clone(), spec.probe_every_steps);
    let mut filament_series = spec
        .filaments_every_steps
        .map(|every| FilamentSeries::new(every, t_decimals));
    let progress = crate::progress::Progress::new(sc.steps, "steps");
    for step in 1..=sc.steps {
        let t0 = Instant::now();
        sc.env.step().with_context(|| format!("step {step}"))?;
        let t1 = Instant::now();
        if step >= spec.average_start_step
            && step.is_multiple_of(spec.average_every_steps)
            && !(steady && mean.samples() > 0)
        {
            mean.accumulate(sc.env.plume());
        }
        if probes.is_due(step) {
            probes.sample(sc.env.time_s(), sc.env.plume())?;
        }
        let t2 = Instant::now();
        if let Some(series) = &mut filament_series
            && series.is_due(step)
            && let Some(f) = sc.env.plume().filaments()
        {
            series.record(sc.env.time_s(), f)?;
        }
        times.advance_environment_s += (t1 - t0).as_secs_f64();
        times.sense_s += (t2 - t1).as_secs_f64();
        times.record_s += t2.elapsed().as_secs_f64();
        progress.tick(step);
    }
    progress.finish();
    let t_rec = Instant::now();
    let mut snapshot = vec![0.0; spec.grid.nx * spec.grid.ny];
    sc.env
        .plume()
        .concentrations(&spec.grid.points(), &mut snapshot);
    if mean.samples() == 0 {
        mean.accumulate(sc.env.plume());
    }
    let mean_c = mean.mean();
    let inter = mean.intermittency();
    // Nothing non-finite reaches a file: a plume whose concentrations overflow is an error here.
    if let Some(k) = snapshot.iter().chain(&mean_c).position(|c| !c.is_finite()) {
        bail!(
            "the concentration at grid point {} is not a finite number: lower \
             sources[].mass_rate_per_s or raise plume.init_radius_m",
            k % snapshot.len().max(1)
        );
    }
    let mut csv = String::from("x_m,y_m,concentration,mean_concentration,intermittency\n");
    for (k, p) in spec.grid.points().iter().enumerate() {
        let _ = writeln!(
            csv,
            "{:.3},{:.3},{:.6e},{:.6e},{:.4}",
            p.x, p.y, snapshot[k], mean_c[k], inter[k]
        );
    }
    write_atomic(&args.out.join("snapshot.csv"), csv.as_bytes())?;
    if let Some(f) = sc.env.plume().filaments() {
        let mut csv = String::from("x_m,y_m,z_m,radius_m\n");
        for (p, r2) in f.filaments() {
            let _ = writeln!(csv, "{:.4},{:.4},{:.4},{:.4}", p.x, p.y, p.z, r2.sqrt());
        }
        write_atomic(&args.out.join("filaments.csv"), csv.as_bytes())?;
    }
    if !probes.is_empty() {
        write_atomic(
            &args.out.join("probes.csv"),
            probes.csv(t_decimals).as_bytes(),
        )?;
        #[cfg(feature = "netcdf")]
        {
            let nc = crate::netcdf::plume_file(&crate::netcdf::PlumeFile {
                scenario: &sc.name,
                seed: sc.seed,
                probes: &probes,
                grid: &spec.grid,
                mean: &mean_c,
                mean_samples: mean.samples(),
            })
            .context("encoding plume.nc")?;
            write_atomic(&args.out.join("plume.nc"), &nc)?;
        }
    }
    if let Some(series) = &filament_series {
        write_atomic(
            &args.out.join("filament_series.csv"),
            series.csv().as_bytes(),
        )?;
        if series.skipped() > 0 {
            eprintln!(
                "filament_series.csv: the last {} of {} snapshots are not written (the file \
                 would pass {} rows); lengthen output.filaments_interval_s",
                series.skipped(),
                series.skipped() + series.snapshots(),
                plumetrace_scenario::limits::MAX_FILAMENT_ROWS
            );
        }
    }
    let svg = plumetrace_report::plume_figure(&sc, &snapshot, &mean_c, mean.samples())?;
    write_atomic(&args.out.join("plume.svg"), svg.as_bytes())?;
    times.record_s += t_rec.elapsed().as_secs_f64();

    let wall = started.elapsed().as_secs_f64();
    let flow = sc.env.flow();
    let stats = RunStats {
        scenario: sc.name.clone(),
        seed: sc.seed,
        steps: sc.steps,
        dt_s: sc.env.dt_s(),
        sim_time_s: sc.env.time_s(),
        wall_s: wall,
        sim_s_per_wall_s: sc.env.time_s() / wall.max(1e-9),
        flow_model: flow.name(),
        flow_max_stable_dt_s: flow.max_stable_dt_s(),
        plume_model: if steady { "steady" } else { "filaments" },
        filaments: sc.env.plume().filaments().map(|f| f.stats()),
        mean_samples: mean.samples(),
        snapshot_z_m: spec.grid.z_m,
        max_concentration: snapshot.iter().copied().fold(0.0, f64::max),
        max_mean_concentration: mean_c.iter().copied().fold(0.0, f64::max),
        intermittency_threshold: spec.threshold,
        probe_samples: probes.times_s().len(),
        probes: probes.points().len(),
        filament_snapshots: filament_series
            .as_ref()
            .map_or(0, FilamentSeries::snapshots),
        filament_snapshots_skipped: filament_series.as_ref().map_or(0, FilamentSeries::skipped),
        filament_series_rows: filament_series.as_ref().map_or(0, FilamentSeries::rows),
        stage_times: times,
    };
    if let Some(at) = plumetrace_mission::output::first_non_finite(&stats) {
        bail!("the run's statistics have a number that is not finite ({at})");
    }
    let json = serde_json::to_string_pretty(&stats)?;
    write_atomic(&args.out.join("stats.json"), json.as_bytes())?;
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
        wall,
        stats.sim_s_per_wall_s,
        args.out.display()
    );
    Ok(())
}
