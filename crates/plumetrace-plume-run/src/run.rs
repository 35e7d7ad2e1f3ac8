//! [`run_plume`]: a scenario's environment stepped alone, its outputs written.

use crate::series::{FilamentSeries, ProbeSeries, SeriesError, time_decimals};
use plumetrace_env::{ConcentrationField, EnvError, FlowField, MeanConcentrationGrid, Plume};
use plumetrace_scenario::{BuiltScenario, OutputSpec};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Why a figure could not be drawn (the caller's error).
pub type FigureError = Box<dyn std::error::Error + Send + Sync>;

/// What the plume figure shows, for the caller that draws it.
#[derive(Debug, Clone, Copy)]
pub struct PlumeFigure<'a> {
    /// The scenario at the end of the run.
    pub scenario: &'a BuiltScenario,
    /// The concentration on the output grid at the end, row-major (x fastest).
    pub snapshot: &'a [f64],
    /// The time-averaged concentration on the grid.
    pub mean: &'a [f64],
    /// Samples in the time average.
    pub mean_samples: u32,
}

/// Why a plume run failed.
#[derive(Debug, thiserror::Error)]
pub enum PlumeRunError {
    /// The environment failed at a step.
    #[error("step {step}")]
    Step {
        /// The step (from 1).
        step: u64,
        /// What failed.
        source: EnvError,
    },
    /// A probe or filament sample is not finite.
    #[error(transparent)]
    Series(#[from] SeriesError),
    /// A concentration on the output grid is not finite.
    #[error(
        "the concentration at grid point {0} is not a finite number: lower \
         sources[].mass_rate_per_s or raise plume.init_radius_m"
    )]
    GridNotFinite(usize),
    /// An output file could not be written.
    #[error("writing {}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// What failed.
        source: std::io::Error,
    },
    /// `plume.nc` could not be encoded.
    #[cfg(feature = "netcdf")]
    #[error("encoding plume.nc")]
    Netcdf(#[source] crate::netcdf::NetcdfError),
    /// The caller's figure failed.
    #[error(transparent)]
    Figure(FigureError),
    /// A statistic is not finite (its key path).
    #[error("the run's statistics have a number that is not finite ({0})")]
    StatsNotFinite(String),
    /// The statistics could not be encoded.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
}

/// `stats.json` of a plume run.
#[derive(Debug, Clone, Serialize)]
pub struct PlumeRunStats {
    /// Scenario name.
    pub scenario: String,
    /// Run seed.
    pub seed: u64,
    /// Steps run.
    pub steps: u64,
    /// The environment's step, s.
    pub dt_s: f64,
    /// Simulated time at the end, s.
    pub sim_time_s: f64,
    /// Wall time of the run, s.
    pub wall_s: f64,
    /// Simulated seconds per wall second.
    pub sim_s_per_wall_s: f64,
    /// The flow model's name.
    pub flow_model: &'static str,
    /// The flow's stable step, s, where it has one.
    pub flow_max_stable_dt_s: Option<f64>,
    /// `steady` or `filaments`.
    pub plume_model: &'static str,
    /// Filament statistics of a filament plume.
    pub filaments: Option<plumetrace_env::PlumeStats>,
    /// Samples in the time average.
    pub mean_samples: u32,
    /// Height of the output grid, m.
    pub snapshot_z_m: f64,
    /// Largest concentration of the final snapshot.
    pub max_concentration: f64,
    /// Largest time-averaged concentration.
    pub max_mean_concentration: f64,
    /// The intermittency threshold.
    pub intermittency_threshold: f64,
    /// Probe samples written to `probes.csv` (0 without probes).
    pub probe_samples: usize,
    /// Probes per sample.
    pub probes: usize,
    /// Filament snapshots written to `filament_series.csv`.
    pub filament_snapshots: u32,
    /// Filament snapshots not written because the file reached its row limit.
    pub filament_snapshots_skipped: u32,
    /// Rows of `filament_series.csv`.
    pub filament_series_rows: u64,
    /// The plume run's stages: advance environment, sense (sampling the time average and the
    /// probes), record (filament snapshots and writing the outputs).
    pub stage_times: plumetrace_sim::StageTimes,
}

impl PlumeRunStats {
    /// The warning to print when `filament_series.csv` is cut at its row limit.
    pub fn filament_series_warning(&self) -> Option<String> {
        (self.filament_snapshots_skipped > 0).then(|| {
            format!(
                "filament_series.csv: the last {} of {} snapshots are not written (the file \
                 would pass {} rows); lengthen output.filaments_interval_s",
                self.filament_snapshots_skipped,
                self.filament_snapshots_skipped + self.filament_snapshots,
                plumetrace_scenario::limits::MAX_FILAMENT_ROWS
            )
        })
    }
}

/// Writes `bytes` to `path` atomically, naming the file in errors.
fn write(path: &Path, bytes: &[u8]) -> Result<(), PlumeRunError> {
    plumetrace_mission::output::write_atomic(path, bytes).map_err(|source| PlumeRunError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// What the stepping recorded.
struct Recorded {
    mean: MeanConcentrationGrid,
    probes: ProbeSeries,
    filament_series: Option<FilamentSeries>,
    times: plumetrace_sim::StageTimes,
}

/// Steps the environment to the end, sampling the time average, the probes and the filament
/// snapshots at their steps; `progress(step, steps)` after each step.
fn step_all(
    sc: &mut BuiltScenario,
    spec: &OutputSpec,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Recorded, PlumeRunError> {
    let mut times = plumetrace_sim::StageTimes::default();
    let mut mean = MeanConcentrationGrid::new(spec.grid, spec.threshold);
    let steady = matches!(sc.env.plume(), Plume::Steady(_));
    let t_decimals = time_decimals(sc.env.dt_s());
    let mut probes = ProbeSeries::new(spec.probes.clone(), spec.probe_every_steps);
    let mut filament_series = spec
        .filaments_every_steps
        .map(|every| FilamentSeries::new(every, t_decimals));
    for step in 1..=sc.steps {
        let t0 = Instant::now();
        sc.env
            .step()
            .map_err(|source| PlumeRunError::Step { step, source })?;
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
        progress(step, sc.steps);
    }
    Ok(Recorded {
        mean,
        probes,
        filament_series,
        times,
    })
}

/// Runs the plume alone and writes into `out` `snapshot.csv`, `filaments.csv` (a filament
/// plume), `plume.svg` (drawn by `figure`) and `stats.json`, and with `[output]` series
/// `probes.csv`, `filament_series.csv` and (feature `netcdf`) `plume.nc`.
/// `progress(step, steps)` is told of each step; the last call has `step == steps`.
pub fn run_plume(
    mut sc: BuiltScenario,
    out: &Path,
    progress: &mut dyn FnMut(u64, u64),
    figure: &mut dyn FnMut(&PlumeFigure<'_>) -> Result<String, FigureError>,
) -> Result<PlumeRunStats, PlumeRunError> {
    let started = Instant::now();
    let spec = sc.output.clone();
    let steady = matches!(sc.env.plume(), Plume::Steady(_));
    let t_decimals = time_decimals(sc.env.dt_s());
    let Recorded {
        mut mean,
        probes,
        filament_series,
        mut times,
    } = step_all(&mut sc, &spec, progress)?;
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
        return Err(PlumeRunError::GridNotFinite(k % snapshot.len().max(1)));
    }
    let mut csv = String::from("x_m,y_m,concentration,mean_concentration,intermittency\n");
    for (k, p) in spec.grid.points().iter().enumerate() {
        let _ = writeln!(
            csv,
            "{:.3},{:.3},{:.6e},{:.6e},{:.4}",
            p.x, p.y, snapshot[k], mean_c[k], inter[k]
        );
    }
    write(&out.join("snapshot.csv"), csv.as_bytes())?;
    if let Some(f) = sc.env.plume().filaments() {
        let mut csv = String::from("x_m,y_m,z_m,radius_m\n");
        for (p, r2) in f.filaments() {
            let _ = writeln!(csv, "{:.4},{:.4},{:.4},{:.4}", p.x, p.y, p.z, r2.sqrt());
        }
        write(&out.join("filaments.csv"), csv.as_bytes())?;
    }
    if !probes.is_empty() {
        write(&out.join("probes.csv"), probes.csv(t_decimals).as_bytes())?;
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
            .map_err(PlumeRunError::Netcdf)?;
            write(&out.join("plume.nc"), &nc)?;
        }
    }
    if let Some(series) = &filament_series {
        write(&out.join("filament_series.csv"), series.csv().as_bytes())?;
    }
    let svg = figure(&PlumeFigure {
        scenario: &sc,
        snapshot: &snapshot,
        mean: &mean_c,
        mean_samples: mean.samples(),
    })
    .map_err(PlumeRunError::Figure)?;
    write(&out.join("plume.svg"), svg.as_bytes())?;
    times.record_s += t_rec.elapsed().as_secs_f64();

    let wall = started.elapsed().as_secs_f64();
    let flow = sc.env.flow();
    let stats = PlumeRunStats {
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
    if let Some(at) = plumetrace_core::first_non_finite(&stats) {
        return Err(PlumeRunError::StatsNotFinite(at));
    }
    let json = serde_json::to_string_pretty(&stats)?;
    write(&out.join("stats.json"), json.as_bytes())?;
    Ok(stats)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;
    use plumetrace_scenario::Origin;

    /// `plume-demo` cut to `duration_s`, the time average from the start, with probes and
    /// filament snapshots every second.
    fn short(duration_s: f64) -> BuiltScenario {
        let mut cfg = plumetrace_scenario::load_preset("plume-demo").unwrap();
        cfg.sim.duration_s = duration_s;
        cfg.output.average_start_s = 0.0;
        cfg.output.probes = vec![[20.0, 0.0, 2.0], [40.0, 1.0, 2.0]];
        cfg.output.probe_interval_s = Some(1.0);
        cfg.output.filaments_interval_s = Some(1.0);
        plumetrace_scenario::build(&cfg, &Origin::Preset("plume-demo".into()), Some(7)).unwrap()
    }

    #[test]
    fn a_plume_run_writes_its_outputs_and_has_its_figure_drawn_by_the_caller() {
        let dir = tempfile::tempdir().unwrap();
        let sc = short(5.0);
        let steps = sc.steps;
        let mut told = Vec::new();
        let mut figure_samples = 0;
        let stats = run_plume(sc, dir.path(), &mut |s, n| told.push((s, n)), &mut |f| {
            figure_samples = f.mean_samples;
            assert_eq!(f.snapshot.len(), f.mean.len());
            Ok("<svg/>".to_string())
        })
        .unwrap();
        assert_eq!(told.len() as u64, steps);
        assert_eq!(
            told.last(),
            Some(&(steps, steps)),
            "the last step ends the run"
        );
        assert_eq!(stats.steps, steps);
        assert_eq!(stats.mean_samples, figure_samples);
        assert_eq!((stats.probes, stats.probe_samples), (2, 5));
        assert_eq!(stats.filament_snapshots, 5);
        assert!(stats.filament_series_warning().is_none());
        let read = |name: &str| std::fs::read_to_string(dir.path().join(name)).unwrap();
        assert_eq!(read("plume.svg"), "<svg/>");
        assert!(read("snapshot.csv").starts_with("x_m,y_m,concentration,"));
        assert!(read("filaments.csv").starts_with("x_m,y_m,z_m,radius_m\n"));
        assert_eq!(read("probes.csv").lines().count(), 1 + 2 * 5);
        assert!(read("filament_series.csv").starts_with("t_s,x_m,y_m,z_m,radius_m\n"));
        let json: serde_json::Value = serde_json::from_str(&read("stats.json")).unwrap();
        assert_eq!(json["steps"], steps);
        assert_eq!(json["plume_model"], "filaments");
        #[cfg(feature = "netcdf")]
        assert!(dir.path().join("plume.nc").is_file());
    }

    #[test]
    fn a_failing_figure_fails_the_run_with_its_message_and_no_statistics() {
        let dir = tempfile::tempdir().unwrap();
        let e = run_plume(short(1.0), dir.path(), &mut |_, _| {}, &mut |_| {
            Err("no figure".into())
        })
        .unwrap_err();
        assert_eq!(e.to_string(), "no figure");
        assert!(!dir.path().join("stats.json").exists());
    }

    #[test]
    fn a_write_error_names_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing");
        let e = run_plume(short(1.0), &missing, &mut |_, _| {}, &mut |_| {
            Ok(String::new())
        })
        .unwrap_err();
        assert!(
            e.to_string().starts_with("writing ") && e.to_string().ends_with("snapshot.csv"),
            "{e}"
        );
    }
}
