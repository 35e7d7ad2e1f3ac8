//! `run`: fly a mission (or a preset) and hand back its summary, events and trajectory, and
//! the record its output files are written from (`RunRecord.save`, the same files as
//! `plumetrace run`); `run_plume`: a plume-only scenario's files.

use crate::error::{msg, to_py};
use crate::planner::{ErrorSlot, PyPlanner};
use crate::scenario::{Source, overrides};
use numpy::{IntoPyArray, PyArray1};
use plumetrace_log::snapshot::Header;
use plumetrace_mission::snapshot_log::SnapshotLogWriter;
use plumetrace_mission::{Mission, MissionOptions, MissionRun, MissionSetup};
use plumetrace_report::run_dir::SNAPSHOT_LOG;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// A flown mission kept for writing its files: the run, its wall time and its snapshot log
/// (written to a temporary directory as the mission flew, removed with the record).
#[pyclass(module = "plumetrace._plumetrace", frozen)]
pub struct RunRecord {
    run: MissionRun,
    name: String,
    wall_s: f64,
    log_dir: Option<PathBuf>,
}

impl Drop for RunRecord {
    fn drop(&mut self) {
        if let Some(d) = &self.log_dir {
            let _ = std::fs::remove_dir_all(d);
        }
    }
}

#[pymethods]
impl RunRecord {
    /// Writes the run's files into `out` (created if needed), as `plumetrace run` does:
    /// `summary.json`, `trajectory.csv`, `events.jsonl`, `plot.svg`, `team.svg` (a team
    /// mission), `replay.html` and `snapshots.jsonl.gz`. Returns the file names written.
    fn save(&self, py: Python<'_>, out: PathBuf) -> PyResult<Vec<String>> {
        py.detach(|| {
            std::fs::create_dir_all(&out)
                .map_err(|e| msg(format!("creating {}: {e}", out.display())))?;
            plumetrace_report::write_mission_outputs(&self.run, &out, &self.name, self.wall_s)
                .map_err(to_py)?;
            if let Some(d) = &self.log_dir {
                let to = out.join(SNAPSHOT_LOG);
                copy_atomic(&d.join(SNAPSHOT_LOG), &to)
                    .map_err(|e| msg(format!("writing {}: {e}", to.display())))?;
            }
            let team = self.run.summary.team.is_some();
            Ok(OUTPUT_NAMES
                .iter()
                .filter(|n| match **n {
                    "team.svg" => team,
                    SNAPSHOT_LOG => self.log_dir.is_some(),
                    _ => true,
                })
                .map(|n| n.to_string())
                .collect())
        })
    }

    fn __repr__(&self) -> String {
        format!("RunRecord('{}', seed={})", self.name, self.run.summary.seed)
    }
}

/// The files a mission run may write.
const OUTPUT_NAMES: [&str; 7] = [
    "summary.json",
    "trajectory.csv",
    "events.jsonl",
    "plot.svg",
    "team.svg",
    "replay.html",
    SNAPSHOT_LOG,
];

/// Copies `from` to `to` through a temporary file and a rename.
fn copy_atomic(from: &Path, to: &Path) -> std::io::Result<()> {
    let bytes = std::fs::read(from)?;
    plumetrace_mission::output::write_atomic(to, &bytes)
}

/// A fresh temporary directory for a run's snapshot log.
fn log_dir() -> PyResult<PathBuf> {
    static RUNS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let d = std::env::temp_dir().join(format!("plumetrace-run-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&d).map_err(|e| msg(format!("creating {}: {e}", d.display())))?;
    Ok(d)
}

/// Flies a mission; returns a dict with `summary` and `metrics` (JSON text), `events` (JSON lines),
/// `trajectory` (a dict of numpy arrays) and `vehicles` (names). The Python wrapper
/// `plumetrace.run` turns it into a `RunResult`.
#[pyfunction]
#[pyo3(signature = (scenario, seed=None, set=None, planner=None, vehicle=0, trajectory=true, progress=None, outputs=true, **kwargs))]
#[allow(clippy::too_many_arguments)]
pub fn run<'py>(
    py: Python<'py>,
    scenario: &str,
    seed: Option<&Bound<'py, PyAny>>,
    set: Option<&Bound<'py, PyDict>>,
    planner: Option<&Bound<'py, PyAny>>,
    vehicle: usize,
    trajectory: bool,
    progress: Option<&Bound<'py, PyAny>>,
    outputs: bool,
    kwargs: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let started = Instant::now();
    let source = Source::open(scenario)?;
    let sc = source.build(crate::scenario::seed(seed)?, &overrides(set, kwargs)?)?;
    let name = sc.name.clone();
    if sc.mission.is_none() {
        return Err(msg(format!(
            "{}: '{name}' is a plume-only scenario (no [mission] table, no vehicles): use \
             plumetrace.run_plume(scenario, out) for the files `plumetrace run` writes, or \
             plumetrace.Plume(scenario) to step and query it",
            sc.origin
        )));
    }
    let setup = MissionSetup::new(sc).map_err(to_py)?;
    let warnings = setup.warnings.clone();
    // With `outputs`, the mission records what `plumetrace run` draws (the time-averaged plume,
    // the replay's plume frames) and its snapshot log.
    let options = if outputs {
        MissionOptions::default()
    } else {
        MissionOptions {
            mean_plume: false,
            trajectory,
            plume_frames_every_s: None,
            // `summary.json` shows them.
            stage_times: true,
        }
    };
    let mut mission = py.detach(|| Mission::new(setup, options)).map_err(to_py)?;
    let log_dir = if outputs {
        let d = log_dir()?;
        let header = Header::new(
            &name,
            mission.seed(),
            &mission.vehicle_names(),
            mission.planned(),
        )
        .map_err(|e| msg(format!("writing the snapshot log's header: {e}")))?;
        let path = d.join(SNAPSHOT_LOG);
        let writer = SnapshotLogWriter::create(&path, &header)
            .map_err(|e| msg(format!("creating {}: {e}", path.display())))?;
        mission.observe(Box::new(writer)).map_err(to_py)?;
        Some(d)
    } else {
        None
    };
    let errors: ErrorSlot = Arc::new(Mutex::new(None));
    if let Some(p) = planner {
        let planner = PyPlanner::new(p, errors.clone())?;
        mission
            .replace_planner(vehicle, Box::new(planner))
            .map_err(to_py)?;
    }
    let progress = progress.map(|p| p.clone().unbind());
    let ended = py.detach(|| {
        let mut last = 0u64;
        mission.run(&mut |t, _| {
            let now = t.floor() as u64;
            if let Some(p) = &progress
                && now >= last + 60
            {
                Python::attach(|py| {
                    let _ = p.bind(py).call1((now - last,));
                });
                last = now;
            }
        })
    });
    if let Some(e) = errors.lock().ok().and_then(|mut s| s.take()) {
        return Err(e);
    }
    ended.map_err(to_py)?;
    let run = py.detach(|| mission.finish()).map_err(to_py)?;
    let out = result(py, &run, &name, &warnings, trajectory)?;
    if outputs {
        let record = RunRecord {
            run,
            name,
            wall_s: started.elapsed().as_secs_f64(),
            log_dir,
        };
        out.set_item("record", Bound::new(py, record)?)?;
    }
    Ok(out)
}

fn result<'py>(
    py: Python<'py>,
    run: &MissionRun,
    name: &str,
    warnings: &[String],
    trajectory: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("name", name)?;
    let summary = serde_json::to_string(&run.summary).map_err(|e| msg(e.to_string()))?;
    out.set_item("summary", summary)?;
    // The run's verdict in the command line's words.
    out.set_item("verdict", run.summary.verdict())?;
    // The run's metrics as a campaign records them (success within the scenario's radius).
    let metrics = plumetrace_mission::RunMetrics::new(
        &run.summary,
        &plumetrace_mission::MetricContext::default(),
    );
    let metrics = serde_json::to_string(&metrics).map_err(|e| msg(e.to_string()))?;
    out.set_item("metrics", metrics)?;
    let events = PyList::empty(py);
    for e in &run.events {
        events.append(serde_json::to_string(e).map_err(|e| msg(e.to_string()))?)?;
    }
    out.set_item("events", events)?;
    let names: Vec<&str> = run.vehicles.iter().map(|v| v.name.as_str()).collect();
    out.set_item("vehicles", names)?;
    out.set_item("warnings", warnings.to_vec())?;
    let t: &[plumetrace_mission::TrajectoryRow] = if trajectory { &run.trajectory } else { &[] };
    let col = |f: &dyn Fn(&plumetrace_mission::TrajectoryRow) -> f64| -> Vec<f64> {
        t.iter().map(f).collect()
    };
    let tr = PyDict::new(py);
    let put = |k: &str, v: Vec<f64>| -> PyResult<()> {
        let a: Bound<'py, PyArray1<f64>> = v.into_pyarray(py);
        tr.set_item(k, a)
    };
    put("t_s", col(&|r| r.t_s))?;
    tr.set_item(
        "vehicle",
        t.iter()
            .map(|r| r.vehicle)
            .collect::<Vec<u32>>()
            .into_pyarray(py),
    )?;
    put("true_x_m", col(&|r| r.true_x_m))?;
    put("true_y_m", col(&|r| r.true_y_m))?;
    put("true_z_m", col(&|r| r.true_z_m))?;
    // Vehicles without a position estimate have NaN here (and `has_estimate` false).
    put("est_x_m", col(&|r| r.est_x_m.unwrap_or(f64::NAN)))?;
    put("est_y_m", col(&|r| r.est_y_m.unwrap_or(f64::NAN)))?;
    tr.set_item(
        "has_estimate",
        t.iter()
            .map(|r| r.est_x_m.is_some())
            .collect::<Vec<bool>>()
            .into_pyarray(py),
    )?;
    put("heading_deg", col(&|r| r.heading_deg))?;
    put("speed_mps", col(&|r| r.speed_mps))?;
    tr.set_item(
        "behaviour",
        t.iter()
            .map(|r| {
                r.behaviour
                    .and_then(|b| plumetrace_core::variant_name(&b))
                    .unwrap_or("")
            })
            .collect::<Vec<&str>>(),
    )?;
    put("reading_v", col(&|r| r.reading_v))?;
    tr.set_item(
        "detection",
        t.iter()
            .map(|r| r.detection)
            .collect::<Vec<bool>>()
            .into_pyarray(py),
    )?;
    out.set_item("trajectory", tr)?;
    Ok(out)
}

/// The built-in scenarios: `(name, summary)` pairs.
#[pyfunction]
pub fn presets() -> Vec<(&'static str, &'static str)> {
    plumetrace_scenario::PRESETS
        .iter()
        .map(|p| (p.name, p.summary))
        .collect()
}

/// The registered planners: `(kind, summary)` pairs.
#[pyfunction]
pub fn planners() -> Vec<(String, &'static str)> {
    plumetrace_planner::planners::PLANNERS
        .iter()
        .map(|p| (p.kind.to_string(), p.summary))
        .collect()
}

/// Runs a plume-only scenario (no vehicles) and writes its files into `out`, as `plumetrace run`
/// does; returns its statistics (`stats.json`) as JSON text.
#[pyfunction]
#[pyo3(signature = (scenario, out, seed=None, set=None, **kwargs))]
pub fn run_plume(
    py: Python<'_>,
    scenario: &str,
    out: PathBuf,
    seed: Option<&Bound<'_, PyAny>>,
    set: Option<&Bound<'_, PyDict>>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let source = Source::open(scenario)?;
    let sc = source.build(crate::scenario::seed(seed)?, &overrides(set, kwargs)?)?;
    if sc.mission.is_some() {
        return Err(msg(format!(
            "{}: '{}' is a mission scenario: use plumetrace.run(scenario).save(out)",
            sc.origin, sc.name
        )));
    }
    let stats = py.detach(|| {
        std::fs::create_dir_all(&out)
            .map_err(|e| msg(format!("creating {}: {e}", out.display())))?;
        plumetrace_plume_run::run_plume(sc, &out, &mut |_, _| {}, &mut |f| {
            Ok(plumetrace_report::plume_figure(
                f.scenario,
                f.snapshot,
                f.mean,
                f.mean_samples,
            )?)
        })
        .map_err(to_py)
    })?;
    serde_json::to_string(&stats).map_err(|e| msg(e.to_string()))
}

/// `"mission"` for a scenario with a `[mission]` table, `"plume"` for a plume-only one.
#[pyfunction]
pub fn scenario_kind(scenario: &str) -> PyResult<&'static str> {
    let (table, _) = Source::open(scenario)?.table(0);
    Ok(if table.contains_key("mission") {
        "mission"
    } else {
        "plume"
    })
}

/// The `k`-th run seed derived from `seed`, as campaigns and the benchmark derive them (a
/// campaign with `seed = s` flies `derive_seed(s, 0)`, `derive_seed(s, 1)`, ...).
#[pyfunction]
pub fn derive_seed(seed: u64, k: u64) -> u64 {
    plumetrace_env::derive_seed(seed, k)
}
