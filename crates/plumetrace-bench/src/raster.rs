//! The display rasters' cost (`plumetrace bench raster`): one query of the figure's
//! time-averaged plume grid and of the replay page's frame grid, as a run of a mission preset
//! draws them, on the preset's plume after its spin-up, and one build of the query index they
//! read.

use crate::BenchError;
use cpu_time::ProcessTime;
use plumetrace_env::{ConcentrationField, GridSpec};
use plumetrace_mission::PlumeFrames;
use plumetrace_mission::record::MeanPlumeRecorder;
use serde::Serialize;

/// What to time.
#[derive(Debug, Clone, PartialEq)]
pub struct RasterBenchOptions {
    /// Mission preset whose plume and op-area are drawn.
    pub preset: String,
    /// Run seed (the plume's realisation).
    pub seed: u64,
    /// Queries of each grid to time, in each precision, and index builds to time (at least 1).
    pub queries: u64,
}

/// One grid's cost.
#[derive(Debug, Clone, Serialize)]
pub struct RasterGrid {
    /// Points along x and y.
    pub points: [usize; 2],
    /// CPU milliseconds per query at display precision (what a run draws).
    pub ms_per_query_display: f64,
    /// Per query at the point queries' precision (bit for bit theirs; what the plume products
    /// and the Python package's averages use).
    pub ms_per_query_standard: f64,
    /// The largest relative difference between the two over the grid's points.
    pub max_relative_difference: f64,
}

/// The raster benchmark's result.
#[derive(Debug, Clone, Serialize)]
pub struct RasterBench {
    /// The preset.
    pub preset: String,
    /// Run seed.
    pub seed: u64,
    /// Live filaments after the spin-up.
    pub filaments: usize,
    /// Queries timed per grid and precision, and index builds timed.
    pub queries: u64,
    /// CPU milliseconds per build of the query index the grids read (a run builds one for each
    /// time it samples the two grids, as the first query after a step does).
    pub ms_per_index_build: f64,
    /// What one sample of a run costs: an index build and a display query of each grid, ms.
    pub ms_per_sample: f64,
    /// The figure's time-averaged plume grid.
    pub figure: RasterGrid,
    /// The replay page's frame grid.
    pub page: RasterGrid,
    /// The vector unit the queries ran on ([`plumetrace_env::vector_unit`]).
    pub vector_unit: &'static str,
}

/// Times the two display grids of a run of `a.preset` on one thread, after the plume's
/// spin-up: the grids a run samples (over the op-area, at the first planned vehicle's height).
pub fn raster(a: &RasterBenchOptions) -> Result<RasterBench, BenchError> {
    if a.queries == 0 {
        return Err(BenchError::NoRuns);
    }
    let cfg = plumetrace_scenario::load_preset(&a.preset)?;
    let origin = plumetrace_scenario::Origin::Preset(a.preset.clone());
    let built = plumetrace_scenario::build(&cfg, &origin, Some(a.seed))?;
    if built.mission.is_none() {
        return Err(BenchError::NotAMission(a.preset.clone()));
    }
    let mut setup = plumetrace_mission::MissionSetup::new(built)?;
    setup.spin_up()?;
    let z = setup
        .planners
        .iter()
        .position(Option::is_some)
        .and_then(|k| setup.vehicles.get(k))
        .map_or(0.0, |v| v.vehicle.state.z_m);
    let env = &setup.env;
    let area = &setup.spec.op_area;
    let figure = MeanPlumeRecorder::grid_over(area, env.domain(), z);
    let page = PlumeFrames::over(area, env.domain(), z, 1).grid;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let time = |grid: &GridSpec| {
        pool.install(|| {
            let points = grid.points();
            let mut display = vec![0.0; points.len()];
            let mut standard = vec![0.0; points.len()];
            let plume = env.plume();
            let started = ProcessTime::now();
            for _ in 0..a.queries {
                plume.display_grid_concentrations(grid, &points, &mut display);
            }
            let t_display = started.elapsed().as_secs_f64();
            let started = ProcessTime::now();
            for _ in 0..a.queries {
                plume.grid_concentrations(grid, &points, &mut standard);
            }
            let t_standard = started.elapsed().as_secs_f64();
            let max_relative_difference = display
                .iter()
                .zip(&standard)
                .filter(|(_, s)| **s > 0.0)
                .map(|(d, s)| ((d - s) / s).abs())
                .fold(0.0, f64::max);
            let per = |t: f64| t / a.queries as f64 * 1e3;
            RasterGrid {
                points: [grid.nx, grid.ny],
                ms_per_query_display: per(t_display),
                ms_per_query_standard: per(t_standard),
                max_relative_difference,
            }
        })
    };
    let filaments = env.plume().filaments();
    let ms_per_index_build = match filaments {
        Some(f) => {
            // The plume's own index is built here, so the grids' first queries do not pay for it.
            f.prepare_queries();
            pool.install(|| {
                let started = ProcessTime::now();
                for _ in 0..a.queries {
                    f.build_query_index_apart();
                }
                started.elapsed().as_secs_f64() / a.queries as f64 * 1e3
            })
        }
        // A steady plume has no index: its grids are computed point by point.
        None => 0.0,
    };
    let (figure, page) = (time(&figure), time(&page));
    Ok(RasterBench {
        preset: a.preset.clone(),
        seed: a.seed,
        filaments: filaments.map_or(0, |f| f.len()),
        queries: a.queries,
        ms_per_index_build,
        ms_per_sample: ms_per_index_build + figure.ms_per_query_display + page.ms_per_query_display,
        figure,
        page,
        vector_unit: plumetrace_env::vector_unit(),
    })
}
