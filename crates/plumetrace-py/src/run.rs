//! `run`: fly a mission (or a preset) and hand back its summary, events and trajectory.

use crate::error::{msg, to_py};
use crate::planner::{ErrorSlot, PyPlanner};
use crate::scenario::{Source, overrides};
use numpy::{IntoPyArray, PyArray1};
use plumetrace_mission::{Mission, MissionOptions, MissionRun, MissionSetup};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::sync::{Arc, Mutex};

/// Flies a mission; returns a dict with `summary` and `metrics` (JSON text), `events` (JSON lines),
/// `trajectory` (a dict of numpy arrays) and `vehicles` (names). The Python wrapper
/// `plumetrace.run` turns it into a `RunResult`.
#[pyfunction]
#[pyo3(signature = (scenario, seed=None, set=None, planner=None, vehicle=0, trajectory=true, progress=None, **kwargs))]
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
    kwargs: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let source = Source::open(scenario)?;
    let sc = source.build(crate::scenario::seed(seed)?, &overrides(set, kwargs)?)?;
    let name = sc.name.clone();
    let setup = MissionSetup::new(sc).map_err(to_py)?;
    let warnings = setup.warnings.clone();
    let mut mission = py
        .detach(|| {
            Mission::new(
                setup,
                MissionOptions {
                    mean_plume: false,
                    trajectory,
                    plume_frames_every_s: None,
                },
            )
        })
        .map_err(to_py)?;
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
    result(py, &run, &name, &warnings)
}

fn result<'py>(
    py: Python<'py>,
    run: &MissionRun,
    name: &str,
    warnings: &[String],
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("name", name)?;
    let summary = serde_json::to_string(&run.summary).map_err(|e| msg(e.to_string()))?;
    out.set_item("summary", summary)?;
    // The run's metrics as a campaign records them (no success radius).
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
    let t = &run.trajectory;
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
