//! `plumetrace run`: simulate a scenario and write its outputs.
//!
//! A mission scenario is flown ([`crate::mission`]); a scenario without vehicles simulates the
//! environment alone and writes a concentration snapshot, the time-averaged concentration and
//! intermittency, the final filaments, statistics and a figure.

use crate::output::write_atomic;
use crate::plot;
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
    /// The plume run's stages: advance environment, sense (sampling the time average), record
    /// (writing the outputs).
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
        crate::mission::run(sc, &args.out, args.stats, !args.no_snapshot_log)
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
];

/// Runs the plume alone and writes `stats.json`, `snapshot.csv`, `filaments.csv` and `plume.svg`.
fn run_plume(mut sc: BuiltScenario, args: &RunArgs) -> Result<()> {
    let started = Instant::now();
    let mut times = plumetrace_sim::StageTimes::default();
    let spec = sc.output;
    let mut mean = MeanConcentrationGrid::new(spec.grid, spec.threshold);
    let steady = matches!(sc.env.plume(), Plume::Steady(_));
    let progress = crate::progress::Progress::new(sc.steps, "steps");
    for step in 1..=sc.steps {
        let t0 = Instant::now();
        sc.env.step().with_context(|| format!("step {step}"))?;
        let t1 = Instant::now();
        if step >= spec.average_start_step
            && step % spec.average_every_steps == 0
            && !(steady && mean.samples() > 0)
        {
            mean.accumulate(sc.env.plume());
        }
        let t2 = Instant::now();
        times.advance_environment_s += (t1 - t0).as_secs_f64();
        times.sense_s += (t2 - t1).as_secs_f64();
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
    let svg = plot::plume_figure(&sc, &snapshot, &mean_c, mean.samples())?;
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
        stage_times: times,
    };
    if let Some(at) = plumetrace_mission::output::first_non_finite(&stats) {
        bail!("the run's statistics have a number that is not finite ({at})");
    }
    let json = serde_json::to_string_pretty(&stats)?;
    write_atomic(&args.out.join("stats.json"), json.as_bytes())?;
    if args.stats {
        eprintln!(
            "stage times: advance environment {:.3} s, sense (time average) {:.3} s, record {:.3} s",
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
