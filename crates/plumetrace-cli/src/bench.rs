//! `plumetrace bench plume` times the plume model; `plumetrace bench missions` times whole
//! missions on several thread counts; `plumetrace bench infotaxis` runs the windy grid-world
//! benchmark of infotaxis; `plumetrace bench map` times the source-likelihood map's update at the
//! Duck op-area size; `plumetrace bench raster` times the display rasters a run draws. Each prints
//! one JSON object. The benchmarks are in [`plumetrace_bench`];
//! here are their flags.

use anyhow::Result;
use plumetrace_bench::{
    InfotaxisBenchOptions, MapBenchOptions, MissionBenchOptions, PlumeBenchOptions,
    RasterBenchOptions,
};

/// Benchmarks.
#[derive(Debug, clap::Subcommand)]
pub enum BenchCommand {
    /// Time the filament plume (stepping and point queries).
    Plume(PlumeBenchArgs),
    /// Missions per second of a mission preset on 1, 2, ... threads (as a campaign runs them).
    Missions(MissionBenchArgs),
    /// Infotaxis in the windy grid world of the published benchmark: steps to the source.
    Infotaxis(InfotaxisBenchArgs),
    /// Cost of one update of the source-likelihood map over a preset's op-area.
    Map(MapBenchArgs),
    /// Cost of one query of the display rasters a run draws (the figure's averaged plume, the
    /// replay page's frames) and of the index they read, on a preset's plume after its spin-up,
    /// on one thread.
    Raster(RasterBenchArgs),
}

/// Arguments of `plumetrace bench raster`.
#[derive(Debug, clap::Args)]
pub struct RasterBenchArgs {
    /// Mission preset whose plume and op-area are drawn.
    #[arg(long, default_value = "duck-2003-st")]
    preset: String,
    /// Run seed (the plume's realisation).
    #[arg(long, default_value_t = 7, allow_hyphen_values = true, value_parser = crate::args::seed)]
    seed: u64,
    /// Queries of each grid to time, in each precision (and builds of the index they read).
    #[arg(long, default_value_t = 50, allow_hyphen_values = true, value_parser = crate::args::runs)]
    queries: u64,
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

/// Which scenario to benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
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

/// Arguments of `plumetrace bench infotaxis`.
#[derive(Debug, clap::Args)]
pub struct InfotaxisBenchArgs {
    /// Episodes (each its own source and hits).
    #[arg(long, default_value_t = 1000, allow_hyphen_values = true, value_parser = crate::args::runs)]
    episodes: u64,
    /// Dimensionless emission rate R (the benchmark's: 2.5 or 0.25).
    #[arg(long, default_value_t = 2.5, allow_hyphen_values = true, value_parser = crate::args::number)]
    rate: f64,
    /// Move choice.
    #[arg(long, value_enum, default_value = "infotaxis")]
    policy: Policy,
    /// Step limit of an episode (a failure when reached).
    #[arg(long, default_value_t = 10_000, allow_hyphen_values = true, value_parser = crate::args::runs)]
    max_steps: u64,
    /// Base seed.
    #[arg(long, default_value_t = 1, allow_hyphen_values = true, value_parser = crate::args::seed)]
    seed: u64,
    /// Worker threads (default: all cores); the results do not depend on it.
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::jobs)]
    jobs: Option<usize>,
}

/// The move choice of the benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Policy {
    /// Minimise the expected entropy.
    Infotaxis,
    /// Space-aware infotaxis.
    SpaceAware,
}

/// Runs a benchmark and prints its JSON.
pub fn run(cmd: &BenchCommand) -> Result<()> {
    let json = match cmd {
        BenchCommand::Plume(a) => {
            let options = PlumeBenchOptions {
                case: match a.case {
                    Case::Pompy => plumetrace_bench::Case::Pompy,
                    Case::Field => plumetrace_bench::Case::Field,
                },
                release_rate: a.release_rate,
                duration: a.duration,
                dt: a.dt,
                warmup: a.warmup,
                pompy_compatible: a.pompy_compatible,
                physical: a.physical,
                flow_step: a.flow_step,
                queries: a.queries,
                blocks: a.blocks,
                seed: a.seed,
            };
            let mut progress = crate::progress::reporter("steps");
            serde_json::to_string_pretty(&plumetrace_bench::plume(&options, &mut progress)?)?
        }
        BenchCommand::Missions(a) => {
            serde_json::to_string_pretty(&plumetrace_bench::missions(&MissionBenchOptions {
                preset: a.preset.clone(),
                runs: a.runs,
                threads: a.threads.clone(),
                seed: a.seed,
                set: a.set.clone(),
            })?)?
        }
        BenchCommand::Map(a) => {
            serde_json::to_string_pretty(&plumetrace_bench::map(&MapBenchOptions {
                preset: a.preset.clone(),
                resolution: a.resolution,
                samples: a.samples,
            })?)?
        }
        BenchCommand::Raster(a) => {
            serde_json::to_string_pretty(&plumetrace_bench::raster(&RasterBenchOptions {
                preset: a.preset.clone(),
                seed: a.seed,
                queries: a.queries,
            })?)?
        }
        BenchCommand::Infotaxis(a) => {
            serde_json::to_string_pretty(&plumetrace_bench::infotaxis(&InfotaxisBenchOptions {
                episodes: a.episodes,
                rate: a.rate,
                policy: match a.policy {
                    Policy::Infotaxis => plumetrace_bench::Policy::Infotaxis,
                    Policy::SpaceAware => plumetrace_bench::Policy::SpaceAware,
                },
                max_steps: a.max_steps,
                seed: a.seed,
                jobs: a.jobs,
            })?)?
        }
    };
    crate::outln!("{json}");
    Ok(())
}
