//! `plumetrace bench plume` times the plume model; `plumetrace bench missions` times whole
//! missions on several thread counts; `plumetrace bench infotaxis` runs the windy grid-world
//! benchmark of infotaxis ([`crate::gridworld`]); `plumetrace bench map` times the
//! source-likelihood map's update at the Duck op-area size. Each prints one JSON object.
//!
//! The pompy case is pompy's own scenario (x 0-100 m, y -50-50 m, 21 x 21 Farrell grid, 1 m/s,
//! source at (5, 0), dt 0.01 s; the `pompy` preset, whose grid advances every 0.05 s, pompy's
//! at every step: `--flow-step 0` for that); the field case is the `field-scale` preset. After a
//! warm-up the environment is stepped for `--duration` simulated seconds; the CPU time of those
//! steps over the sum of live filaments gives the cost per filament-step (flow update included,
//! as in pompy's figure; `flow_ns_per_step` gives its share). Point queries are then timed on
//! the final filament set, apart from the one-off index build, at points drawn around live
//! filaments (inside the plume, the costly case) and uniformly over the domain. Cross-flow spread statistics at x = 25, 50 and 75 m are gathered every
//! simulated second for the comparison with pompy.

use anyhow::{Result, bail};
use cpu_time::ProcessTime;
use plumetrace_core::Vec3;
use plumetrace_env::{ConcentrationField, Environment, StreamId, stream_rng};
use rand::Rng;
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// Benchmarks.
#[derive(Debug, clap::Subcommand)]
pub enum BenchCommand {
    /// Time the filament plume (stepping and point queries).
    Plume(PlumeBenchArgs),
    /// Missions per second of a mission preset on 1, 2, ... threads (as a campaign runs them).
    Missions(MissionBenchArgs),
    /// Infotaxis in the windy grid world of the published benchmark: steps to the source.
    Infotaxis(crate::gridworld::InfotaxisBenchArgs),
    /// Cost of one update of the source-likelihood map over a preset's op-area.
    Map(MapBenchArgs),
}

/// Arguments of `plumetrace bench map`.
#[derive(Debug, clap::Args)]
pub struct MapBenchArgs {
    /// Mission preset whose op-area the map covers.
    #[arg(long, default_value = "duck-2003-st")]
    preset: String,
    /// Map cell size, m.
    #[arg(long, default_value_t = 5.0, allow_hyphen_values = true, value_parser = crate::args::number)]
    resolution: f64,
    /// Samples to time (at 10 Hz, along a line across the area, one in five a detection).
    #[arg(long, default_value_t = 20_000, allow_hyphen_values = true, value_parser = crate::args::runs)]
    samples: u64,
}

#[derive(Debug, Serialize)]
struct MapBench {
    preset: String,
    resolution_m: f64,
    candidate_cells: usize,
    samples: u64,
    us_per_update: f64,
    us_per_update_detection: f64,
    us_per_update_non_detection: f64,
    /// One candidate move's hit model (a footprint and the dense fill).
    us_per_hit_model: f64,
    /// One normalisation (paid by the first read after samples).
    us_per_normalisation: f64,
}

/// Times the map's update: samples along a line through the op-area, in a 0.12 m/s current
/// along the area's long axis, at 2 m altitude, the map's default model.
fn map(a: &MapBenchArgs) -> Result<MapBench> {
    use plumetrace_planner::estimate::{MapModel, SourceMap};
    if !(a.resolution >= 0.5 && a.resolution <= 1000.0) {
        bail!(
            "--resolution must be >= 0.5 and <= 1000, got {}",
            a.resolution
        );
    }
    let cfg = plumetrace_scenario::load_preset(&a.preset)?;
    let origin = plumetrace_scenario::Origin::Preset(a.preset.clone());
    let Some(mission) = plumetrace_scenario::build(&cfg, &origin, None)?.mission else {
        bail!("preset '{}' is not a mission", a.preset);
    };
    let v = mission.op_area.clone();
    let model = MapModel {
        resolution_m: a.resolution,
        ..MapModel::default()
    };
    let Some(mut m) = SourceMap::from_vertices(&v, model) else {
        bail!("no map cell fits the op-area at {} m", a.resolution);
    };
    let (p0, p1) = (v[0], v[2]);
    let flow = (v[1] - v[0]).normalize() * 0.12;
    let (mut t_det, mut t_non, mut n_det) = (0.0, 0.0, 0u64);
    for k in 0..a.samples {
        let t = k as f64 * 0.1;
        if k % 10 == 0 {
            m.add_flow(t, flow);
        }
        let f = (k as f64 / a.samples as f64) * 0.9 + 0.05;
        let pos = p0 + (p1 - p0) * f;
        let detected = k % 5 == 0;
        let started = ProcessTime::now();
        m.observe(pos, t, Some(2.0), detected);
        let dt = started.elapsed().as_secs_f64();
        if detected {
            t_det += dt;
            n_det += 1;
        } else {
            t_non += dt;
        }
    }
    let mut out = Vec::new();
    let reps = 200;
    let started = ProcessTime::now();
    for k in 0..reps {
        let pos = p0 + (p1 - p0) * (0.3 + 0.002 * k as f64);
        m.hit_probabilities(
            pos,
            a.samples as f64 * 0.1 + 15.0,
            Some(2.0),
            15.0,
            &mut out,
        );
    }
    let t_hit = started.elapsed().as_secs_f64();
    // A read after each sample: the normalisation a reading of the map pays.
    let started = ProcessTime::now();
    let mut mass = 0.0;
    for k in 0..reps {
        let t = a.samples as f64 * 0.1 + 0.1 * f64::from(k);
        m.observe(p0 + (p1 - p0) * 0.5, t, Some(2.0), false);
        mass += m.probabilities()[0];
    }
    let t_norm =
        started.elapsed().as_secs_f64() - f64::from(reps) * (t_det + t_non) / a.samples as f64;
    std::hint::black_box(mass);
    let n_non = a.samples - n_det;
    Ok(MapBench {
        preset: a.preset.clone(),
        resolution_m: a.resolution,
        candidate_cells: m.len(),
        samples: a.samples,
        us_per_update: (t_det + t_non) / a.samples as f64 * 1e6,
        us_per_update_detection: t_det / n_det.max(1) as f64 * 1e6,
        us_per_update_non_detection: t_non / n_non.max(1) as f64 * 1e6,
        us_per_hit_model: t_hit / f64::from(reps) * 1e6,
        us_per_normalisation: t_norm / f64::from(reps) * 1e6,
    })
}

/// Arguments of `plumetrace bench missions`.
#[derive(Debug, clap::Args)]
pub struct MissionBenchArgs {
    /// Mission preset to fly.
    #[arg(long, default_value = "duck-2003-st")]
    preset: String,
    /// Missions per thread count (the same missions, seeds derived from `--seed`, each time).
    #[arg(long, default_value_t = 8, allow_hyphen_values = true, value_parser = crate::args::runs)]
    runs: u64,
    /// Thread counts to time, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2", allow_hyphen_values = true, value_parser = crate::args::jobs)]
    threads: Vec<usize>,
    /// Base seed.
    #[arg(long, default_value_t = 1, allow_hyphen_values = true, value_parser = crate::args::seed)]
    seed: u64,
    /// Override a scenario key, as a campaign's `set` does: `KEY=VALUE` with VALUE in TOML
    /// (`mission.env_dt_s=0.5`, `flow.farrell.noise_scheme="euler"`); repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
}

#[derive(Debug, Serialize)]
struct MissionBench {
    preset: String,
    /// The `--set` overrides.
    set: Vec<String>,
    runs: u64,
    mean_mission_s: f64,
    results: Vec<MissionBenchRow>,
    /// missions/s on the largest thread count over missions/s on the smallest.
    scaling: f64,
    /// The split by stage on the first thread count, seconds per mission (wall time measured
    /// inside each mission: on one thread, about its CPU time), spin-up included.
    stages_s_per_mission: StageSplit,
    /// The machine's load average (1 minute) when the benchmark ended, if known.
    load_average: Option<f64>,
}

#[derive(Debug, Serialize)]
struct MissionBenchRow {
    threads: usize,
    wall_s: f64,
    /// CPU time of the process (all threads) over the row, s.
    cpu_s: f64,
    cpu_per_mission_s: f64,
    /// CPU per second of mission flown, ms.
    cpu_per_mission_second_ms: f64,
    missions_per_s: f64,
    real_time_factor: f64,
}

#[derive(Debug, Default, Serialize)]
struct StageSplit {
    spin_up: f64,
    advance_environment: f64,
    sense: f64,
    communicate: f64,
    decide: f64,
    control: f64,
    integrate: f64,
    check: f64,
    record: f64,
}

impl StageSplit {
    fn add(&mut self, run: &plumetrace_mission::MissionRun, weight: f64) {
        let t = &run.stage_times;
        self.spin_up += run.spinup_wall_s * weight;
        self.advance_environment += t.advance_environment_s * weight;
        self.sense += t.sense_s * weight;
        self.communicate += t.communicate_s * weight;
        self.decide += t.decide_s * weight;
        self.control += t.control_s * weight;
        self.integrate += t.integrate_s * weight;
        self.check += t.check_s * weight;
        self.record += t.record_s * weight;
    }
}

/// The 1-minute load average from `/proc/loadavg`, where there is one.
fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// The preset's scenario with `KEY=VALUE` overrides applied.
fn preset_with_sets(
    preset: &str,
    sets: &[String],
) -> Result<plumetrace_scenario::config::ScenarioConfig> {
    let text = plumetrace_scenario::find_preset(preset)
        .ok_or_else(|| anyhow::anyhow!("unknown preset '{preset}' (see `plumetrace presets`)"))?
        .toml;
    let mut table: toml::Table = toml::from_str(text)?;
    for s in sets {
        let (key, value) = s
            .split_once('=')
            .ok_or_else(|| anyhow::anyhow!("--set {s:?}: expected KEY=VALUE"))?;
        let value: toml::Value = toml::from_str::<toml::Table>(&format!("v = {value}"))
            .map_err(|e| anyhow::anyhow!("--set {s:?}: the value is not TOML: {e}"))?
            .remove("v")
            .ok_or_else(|| anyhow::anyhow!("--set {s:?}: no value"))?;
        plumetrace_scenario::set_key(&mut table, key.trim(), value)
            .map_err(|e| anyhow::anyhow!("--set {s:?}: {e}"))?;
    }
    Ok(plumetrace_scenario::from_table(
        table,
        &plumetrace_scenario::Origin::Preset(preset.to_string()),
    )?)
}

/// Flies `runs` missions of the preset on each thread count, as a campaign does (no mean-plume
/// grid, no trajectory kept).
fn missions(a: &MissionBenchArgs) -> Result<MissionBench> {
    use rayon::prelude::*;
    if a.runs == 0 || a.threads.is_empty() || a.threads.contains(&0) {
        bail!("--runs and every --threads value must be at least 1");
    }
    let cfg = preset_with_sets(&a.preset, &a.set)?;
    let origin = plumetrace_scenario::Origin::Preset(a.preset.clone());
    if plumetrace_scenario::build(&cfg, &origin, None)?
        .mission
        .is_none()
    {
        bail!("preset '{}' is not a mission", a.preset);
    }
    let options = plumetrace_mission::MissionOptions {
        mean_plume: false,
        trajectory: false,
        plume_frames_every_s: None,
    };
    let mut results = Vec::new();
    let mut sim_s = 0.0;
    let mut stages = StageSplit::default();
    for (row, &t) in a.threads.iter().enumerate() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build()?;
        let started = Instant::now();
        let cpu = ProcessTime::now();
        let runs: Vec<Result<plumetrace_mission::MissionRun>> = pool.install(|| {
            (0..a.runs)
                .into_par_iter()
                .map(|i| {
                    let seed = plumetrace_env::derive_seed(a.seed, i);
                    let sc = plumetrace_scenario::build(&cfg, &origin, Some(seed))?;
                    Ok(plumetrace_mission::run_mission_with(
                        sc,
                        options,
                        &mut |_, _| {},
                    )?)
                })
                .collect()
        });
        let cpu_s = cpu.elapsed().as_secs_f64();
        let wall = started.elapsed().as_secs_f64();
        sim_s = 0.0;
        for run in runs {
            let run = run?;
            sim_s += run.summary.sim_time_s;
            if row == 0 {
                stages.add(&run, 1.0 / a.runs as f64);
            }
        }
        results.push(MissionBenchRow {
            threads: t,
            wall_s: wall,
            cpu_s,
            cpu_per_mission_s: cpu_s / a.runs as f64,
            cpu_per_mission_second_ms: cpu_s / sim_s * 1e3,
            missions_per_s: a.runs as f64 / wall,
            real_time_factor: sim_s / wall,
        });
    }
    let first = results.first().map_or(f64::NAN, |r| r.missions_per_s);
    let last = results.last().map_or(f64::NAN, |r| r.missions_per_s);
    Ok(MissionBench {
        preset: a.preset.clone(),
        set: a.set.clone(),
        runs: a.runs,
        mean_mission_s: sim_s / a.runs as f64,
        results,
        scaling: last / first,
        stages_s_per_mission: stages,
        load_average: load_average(),
    })
}

/// Which scenario to benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Case {
    /// pompy's scenario.
    Pompy,
    /// The field-scale preset (1.1 km, ~50,000 filaments).
    Field,
}

/// Arguments of `plumetrace bench plume`.
#[derive(Debug, clap::Args)]
pub struct PlumeBenchArgs {
    /// Scenario to time.
    #[arg(long, value_enum, default_value = "pompy")]
    case: Case,
    /// Filament release rate, per second (default: 5, the scenario's).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::number)]
    release_rate: Option<f64>,
    /// Simulated seconds timed after the warm-up (default: 20 for pompy, 200 for field).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::number)]
    duration: Option<f64>,
    /// Time step, s (default: 0.01 for pompy, 0.1 for field).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::number)]
    dt: Option<f64>,
    /// Simulated seconds before timing starts, to fill the domain (default: 100 for pompy,
    /// 11000 for field).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::number)]
    warmup: Option<f64>,
    /// Use pompy's dt-scaled dispersion (the pompy case always does; this switches it on for field).
    #[arg(long)]
    pompy_compatible: bool,
    /// Use physical dispersion in the pompy case instead of pompy's scaling.
    #[arg(long, conflicts_with = "pompy_compatible")]
    physical: bool,
    /// The flow grid's own step, s (`flow.farrell.step_s`; default: the scenario's, 0.05 s in
    /// the pompy case; 0 steps the grid with the plume).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::number)]
    flow_step: Option<f64>,
    /// Number of point queries to time.
    #[arg(long, default_value_t = 200_000)]
    queries: usize,
    /// The timed window is split into this many blocks; the reported costs are the medians over
    /// blocks (the minimum is reported too), which shields them from a noisy machine.
    #[arg(long, default_value_t = 5)]
    blocks: usize,
    /// Run seed.
    #[arg(long, default_value_t = 1, allow_hyphen_values = true, value_parser = crate::args::seed)]
    seed: u64,
}

#[derive(Debug, Serialize)]
struct PlumeBench {
    case: Case,
    pompy_compatible: bool,
    release_rate_hz: f64,
    dt_s: f64,
    warmup_s: f64,
    duration_s: f64,
    steps_timed: u64,
    cpu_s: f64,
    ns_per_filament_step: f64,
    ns_per_filament_step_min: f64,
    ns_per_filament_step_blocks: Vec<f64>,
    ns_per_step: f64,
    /// Of `ns_per_step`, the flow's own update (a copy of the flow stepped as the environment
    /// steps it, on its own), per plume step: the fixed cost per step that the filaments share.
    flow_ns_per_step: f64,
    /// The flow advances once every this many plume steps (`flow.farrell.step_s`).
    flow_every_steps: u64,
    /// Flow sub-steps per advance.
    flow_substeps: u64,
    mean_live_filaments: f64,
    final_live_filaments: usize,
    sim_s_per_cpu_s: f64,
    index_build_ns: f64,
    point_query_ns: f64,
    point_query_ns_min: f64,
    point_query_uniform_ns: f64,
    /// The vehicles' sensor query (a scan that skips blocks of filaments out of reach), at the
    /// in-plume points, ns per query.
    sensor_scan_ns: f64,
    /// The same points by a scan of every filament (bit for bit the same results), ns.
    sensor_full_scan_ns: f64,
    crossflow_spread_m: BTreeMap<String, f64>,
    crossflow_mean_m: BTreeMap<String, f64>,
    crossflow_samples: BTreeMap<String, u64>,
    threads: usize,
}

/// Runs a benchmark and prints its JSON.
pub fn run(cmd: &BenchCommand) -> Result<()> {
    match cmd {
        BenchCommand::Plume(a) => {
            let r = plume(a)?;
            crate::outln!("{}", serde_json::to_string_pretty(&r)?);
            Ok(())
        }
        BenchCommand::Missions(a) => {
            let r = missions(a)?;
            crate::outln!("{}", serde_json::to_string_pretty(&r)?);
            Ok(())
        }
        BenchCommand::Map(a) => {
            let r = map(a)?;
            crate::outln!("{}", serde_json::to_string_pretty(&r)?);
            Ok(())
        }
        BenchCommand::Infotaxis(a) => {
            let r = crate::gridworld::run(a)?;
            crate::outln!("{}", serde_json::to_string_pretty(&r)?);
            Ok(())
        }
    }
}

/// The benchmark's environment: the case's preset with the flags applied to its parsed config.
fn build_env(a: &PlumeBenchArgs) -> Result<(Environment, bool, f64, f64, f64)> {
    let (name, dt, duration, warmup) = match a.case {
        Case::Pompy => ("pompy", 0.01, 20.0, 100.0),
        Case::Field => ("field-scale", 0.1, 200.0, 11_000.0),
    };
    let dt = a.dt.unwrap_or(dt);
    let duration = a.duration.unwrap_or(duration);
    let warmup = a.warmup.unwrap_or(warmup);
    for (what, v) in [("--dt", dt), ("--duration", duration), ("--warmup", warmup)] {
        if !(v.is_finite() && v >= 0.0) {
            bail!("{what} must be a finite number >= 0, got {v}");
        }
    }
    if dt <= 0.0 || duration < dt {
        bail!("--dt must be > 0 and --duration at least one step");
    }
    let mut cfg = plumetrace_scenario::load_preset(name)?;
    cfg.sim.dt_s = dt;
    cfg.sim.duration_s = warmup + duration;
    cfg.output.average_start_s = 0.0;
    cfg.output.average_interval_s = cfg.output.average_interval_s.max(dt);
    if let Some(rate) = a.release_rate {
        if !(rate.is_finite() && rate >= 0.0) {
            bail!("--release-rate must be a finite number >= 0, got {rate}");
        }
        for s in &mut cfg.sources {
            // Keep one mass unit per filament, as in pompy.
            s.filament_rate_hz = rate;
            s.mass_rate_per_s = rate;
        }
    }
    if let Some(step) = a.flow_step {
        if !(step.is_finite() && step >= 0.0) {
            bail!("--flow-step must be a finite number >= 0, got {step}");
        }
        match cfg.flow.farrell.as_mut() {
            Some(f) => f.step_s = step,
            None => bail!("--flow-step needs a Farrell flow; the {name} case has none"),
        }
    }
    if a.pompy_compatible {
        cfg.plume.pompy_compatible = true;
    }
    if a.physical {
        cfg.plume.pompy_compatible = false;
    }
    let origin = plumetrace_scenario::Origin::Preset(name.into());
    let env = plumetrace_scenario::build(&cfg, &origin, Some(a.seed))?.env;
    Ok((env, cfg.plume.pompy_compatible, dt, duration, warmup))
}

fn plume(a: &PlumeBenchArgs) -> Result<PlumeBench> {
    let (mut env, pompy_compatible, dt, duration, warmup) = build_env(a)?;
    let warm_steps = (warmup / dt).round() as u64;
    let timed_steps = ((duration / dt).round() as u64).max(1);
    let progress = crate::progress::Progress::new(warm_steps + timed_steps, "steps");
    for k in 0..warm_steps {
        env.step()?;
        progress.tick(k);
    }
    let slabs = [25.0, 50.0, 75.0];
    let mut moments = [[0.0f64; 3]; 3];
    let sample_every = ((1.0 / dt).round() as u64).max(1);
    let mut live_sum = 0u64;
    let mut cpu = 0.0;
    let blocks = a.blocks.clamp(1, timed_steps as usize) as u64;
    let block_len = timed_steps.div_ceil(blocks);
    let (mut block_cpu, mut block_live) = (0.0, 0u64);
    let mut per_block = Vec::new();
    // CPU time is read once per block of steps between statistics samples, so neither the
    // clock nor the sampling is charged to the model.
    let mut block = ProcessTime::now();
    for k in 0..timed_steps {
        env.step()?;
        let f = env.plume().filaments();
        live_sum += f.map_or(0, |f| f.len() as u64);
        block_live += f.map_or(0, |f| f.len() as u64);
        let end_of_block = (k + 1).is_multiple_of(block_len) || k + 1 == timed_steps;
        if k.is_multiple_of(sample_every) || end_of_block {
            let c = block.elapsed().as_secs_f64();
            cpu += c;
            block_cpu += c;
            block = ProcessTime::now();
        }
        if end_of_block {
            per_block.push(block_cpu * 1e9 / block_live.max(1) as f64);
            (block_cpu, block_live) = (0.0, 0);
        }
        if k.is_multiple_of(sample_every)
            && let Some(f) = f
        {
            for (p, _) in f.filaments() {
                for (s, &x) in slabs.iter().enumerate() {
                    if (p.x - x).abs() <= 2.5 {
                        moments[s][0] += 1.0;
                        moments[s][1] += p.y;
                        moments[s][2] += p.y * p.y;
                    }
                }
            }
        }
        if k.is_multiple_of(sample_every) {
            block = ProcessTime::now();
        }
        progress.tick(warm_steps + k);
    }
    progress.finish();
    let Some(f) = env.plume().filaments() else {
        bail!("the benchmark needs a filament plume")
    };
    let t0 = Instant::now();
    f.prepare_queries();
    let index_build_ns = t0.elapsed().as_secs_f64() * 1e9;
    let mut rng = stream_rng(a.seed, StreamId::Custom(77));
    let centres: Vec<Vec3> = f.filaments().map(|(p, _)| p).collect();
    let n = a.queries.max(1);
    let in_plume: Vec<Vec3> = (0..n)
        .map(|_| {
            let c = if centres.is_empty() {
                Vec3::zeros()
            } else {
                centres[rng.random_range(0..centres.len())]
            };
            Vec3::new(
                c.x + rng.random_range(-0.5..0.5),
                c.y + rng.random_range(-0.5..0.5),
                c.z,
            )
        })
        .collect();
    let d = env.domain();
    let uniform: Vec<Vec3> = (0..n)
        .map(|_| {
            Vec3::new(
                rng.random_range(d.x_min_m..d.x_max_m),
                rng.random_range(d.y_min_m..d.y_max_m),
                0.0,
            )
        })
        .collect();
    let time_queries = |pts: &[Vec3]| {
        let c0 = ProcessTime::now();
        let mut sink = 0.0;
        for p in pts {
            sink += f.concentration(*p);
        }
        let ns = c0.elapsed().as_secs_f64() * 1e9 / pts.len() as f64;
        (ns, sink)
    };
    let time_scans = |pts: &[Vec3], full: bool| {
        let c0 = ProcessTime::now();
        let mut sink = 0.0;
        for p in pts {
            sink += if full {
                f.concentration_full_scan(*p)
            } else {
                f.concentration_scan(*p)
            };
        }
        (c0.elapsed().as_secs_f64() * 1e9 / pts.len() as f64, sink)
    };
    // Scans cost thousands of times an indexed query: a slice of the points is enough.
    let scan_pts = &in_plume[..in_plume.len().min(2_000)];
    let mut in_plume_ns = Vec::new();
    let mut uniform_ns = Vec::new();
    let (mut scan_ns, mut full_ns) = (Vec::new(), Vec::new());
    for _ in 0..blocks {
        let (ns, s1) = time_queries(&in_plume);
        let (ns_u, s2) = time_queries(&uniform);
        let (ns_s, s3) = time_scans(scan_pts, false);
        let (ns_f, s4) = time_scans(scan_pts, true);
        std::hint::black_box(s1 + s2 + s3 + s4);
        in_plume_ns.push(ns);
        uniform_ns.push(ns_u);
        scan_ns.push(ns_s);
        full_ns.push(ns_f);
    }
    let mut spread = BTreeMap::new();
    let mut centre = BTreeMap::new();
    let mut samples = BTreeMap::new();
    for (s, x) in slabs.iter().enumerate() {
        let [n, sy, syy] = moments[s];
        let key = format!("{x:.0}");
        samples.insert(key.clone(), n as u64);
        if n > 1.0 {
            let m = sy / n;
            centre.insert(key.clone(), m);
            spread.insert(key, (syy / n - m * m).max(0.0).sqrt());
        }
    }
    let mean_live = live_sum as f64 / timed_steps as f64;
    let (flow_every_steps, flow_substeps) = plumetrace_env::flow_schedule(env.flow(), env.dt_s());
    let flow_ns_per_step = time_flow(&env, timed_steps, blocks as usize)?;
    Ok(PlumeBench {
        case: a.case,
        pompy_compatible,
        release_rate_hz: env.plume().filaments().map_or(0.0, |f| {
            f.sources().iter().map(|s| s.filament_rate_hz).sum()
        }),
        dt_s: dt,
        warmup_s: warmup,
        duration_s: timed_steps as f64 * dt,
        steps_timed: timed_steps,
        cpu_s: cpu,
        ns_per_filament_step: median(&per_block),
        ns_per_filament_step_min: per_block.iter().copied().fold(f64::INFINITY, f64::min),
        ns_per_filament_step_blocks: per_block.clone(),
        ns_per_step: cpu * 1e9 / timed_steps as f64,
        flow_ns_per_step,
        flow_every_steps,
        flow_substeps,
        mean_live_filaments: mean_live,
        final_live_filaments: f.len(),
        sim_s_per_cpu_s: timed_steps as f64 * dt / cpu.max(1e-12),
        index_build_ns,
        point_query_ns: median(&in_plume_ns),
        point_query_ns_min: in_plume_ns.iter().copied().fold(f64::INFINITY, f64::min),
        point_query_uniform_ns: median(&uniform_ns),
        sensor_scan_ns: median(&scan_ns),
        sensor_full_scan_ns: median(&full_ns),
        crossflow_spread_m: spread,
        crossflow_mean_m: centre,
        crossflow_samples: samples,
        threads: 1,
    })
}

/// CPU ns per plume step of the environment's flow alone: a copy of the flow and of its stepper
/// advanced over `steps` more plume steps as the environment would advance them, the median over
/// `blocks`.
fn time_flow(env: &Environment, steps: u64, blocks: usize) -> Result<f64> {
    let mut flow = env.flow().clone();
    let mut stepper = env.flow_stepper().clone();
    let mut rng = stream_rng(1, StreamId::Custom(78));
    let dt = env.dt_s();
    let mut t = env.elapsed_s();
    let per_block = steps.div_ceil(blocks.max(1) as u64).max(1);
    let mut ns = Vec::new();
    let mut done = 0;
    while done < steps {
        let k = per_block.min(steps - done);
        let c0 = ProcessTime::now();
        for _ in 0..k {
            t += dt;
            stepper.advance(&mut flow, t, dt, &mut rng)?;
        }
        ns.push(c0.elapsed().as_secs_f64() * 1e9 / k as f64);
        done += k;
    }
    Ok(median(&ns))
}

/// The median of a non-empty list (NaN for an empty one).
fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}
