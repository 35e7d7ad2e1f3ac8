//! `benchmark`: the command line's benchmark from Python, through the same loop
//! (`plumetrace_campaign::benchmark::run_benchmark`): registered planners by name (in parallel),
//! or one planner written in Python, made afresh for every run by a callable and flown one run
//! at a time through the campaign's external-planner seam.

use crate::error::{located, msg};
use crate::planner::{ErrorSlot, PyPlanner};
use plumetrace_campaign::benchmark::{
    BenchmarkOptions, Given, Task, TaskDone, TaskSet, Watch, plan, run_benchmark,
};
use plumetrace_campaign::{CampaignReport, ExternalError, ExternalPlanners};
use plumetrace_core::Planner;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// A planner written in Python: `make(scenario, seed)` gives a fresh planner object per run.
struct PyFactory {
    name: String,
    make: Py<PyAny>,
    errors: ErrorSlot,
}

impl PyFactory {
    /// Keeps the first Python error (raised by `benchmark` at the end) and says what it was.
    fn keep(&self, py: Python<'_>, e: PyErr) -> ExternalError {
        let message = e
            .value(py)
            .repr()
            .map(|r| r.to_string())
            .unwrap_or_else(|_| e.to_string());
        if let Ok(mut slot) = self.errors.lock() {
            slot.get_or_insert(e);
        }
        ExternalError { message }
    }
}

impl ExternalPlanners for PyFactory {
    fn flies(&self, config: &str) -> bool {
        config == self.name
    }

    fn make(
        &self,
        _config: &str,
        scenario: &str,
        seed: u64,
    ) -> Result<Box<dyn Planner>, ExternalError> {
        Python::attach(|py| {
            let obj = self
                .make
                .bind(py)
                .call1((scenario, seed))
                .map_err(|e| self.keep(py, e))?;
            let p = PyPlanner::new(&obj, self.errors.clone()).map_err(|e| self.keep(py, e))?;
            Ok(Box::new(p) as Box<dyn Planner>)
        })
    }

    fn check(&self) -> Result<(), ExternalError> {
        Python::attach(|py| match self.errors.lock() {
            Ok(slot) => match slot.as_ref() {
                Some(e) => Err(ExternalError {
                    message: e
                        .value(py)
                        .repr()
                        .map(|r| r.to_string())
                        .unwrap_or_else(|_| e.to_string()),
                }),
                None => Ok(()),
            },
            Err(_) => Ok(()),
        })
    }
}

/// What Python hears: `progress(task, done, total)` after each run, and each task's report.
struct Heard {
    progress: Option<Py<PyAny>>,
    task: Mutex<String>,
    reports: Mutex<Vec<Flown>>,
}

/// One task's report: its name, what its campaign did, the wall time of its runs.
struct Flown {
    task: String,
    report: CampaignReport,
    wall_s: f64,
}

impl Watch for Heard {
    fn task_started(&self, task: &Task, _runs: u64) {
        if let Ok(mut t) = self.task.lock() {
            *t = task.name.clone();
        }
    }

    fn run_done(&self, done: u64, total: u64) {
        if let Some(p) = &self.progress {
            let task = self.task.lock().map(|t| t.clone()).unwrap_or_default();
            Python::attach(|py| {
                let _ = p.bind(py).call1((task, done, total));
            });
        }
    }

    fn task_done(&self, d: &TaskDone<'_>) {
        if let Ok(mut r) = self.reports.lock() {
            r.push(Flown {
                task: d.task.name.clone(),
                report: d.report.clone(),
                wall_s: d.wall_s,
            });
        }
    }
}

/// Flies (or resumes) the benchmark into `out` with the registered planners `names` (every
/// task's own planners when empty), or with the Python planner `factory` (called as
/// `factory(scenario, seed)` for each run) entered as `factory_name`. Returns a dict: `board`
/// (the leaderboard's JSON text, as written to `leaderboard.json`), `notes` (tasks left out)
/// and `tasks` (per task: `planned`, `skipped`, `ran`, `failed`, `wall_s`).
#[pyfunction]
#[pyo3(signature = (out, names=Vec::new(), factory=None, factory_name=None, tasks=Vec::new(), seeds_per_task=None, jobs=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn benchmark<'py>(
    py: Python<'py>,
    out: PathBuf,
    names: Vec<String>,
    factory: Option<&Bound<'py, PyAny>>,
    factory_name: Option<String>,
    tasks: Vec<String>,
    seeds_per_task: Option<u64>,
    jobs: Option<usize>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    if let Some(j) = jobs
        && !(1..=256).contains(&j)
    {
        return Err(msg(format!("jobs = {j} is outside 1..=256")));
    }
    if seeds_per_task == Some(0) {
        return Err(msg("seeds_per_task = 0: must be a whole number from 1"));
    }
    let fail = |e: &dyn std::error::Error| msg(located(e));
    let set = TaskSet::builtin().map_err(|e| fail(&e))?;
    let mut given = Vec::new();
    for n in &names {
        given.push(Given::named(&set, n).map_err(|e| fail(&e))?);
    }
    let factory = match factory {
        Some(f) => {
            let name = factory_name.unwrap_or_else(|| "python".into());
            given.push(Given::external(&name));
            Some(PyFactory {
                name,
                make: f.clone().unbind(),
                errors: Arc::new(Mutex::new(None)),
            })
        }
        None => None,
    };
    let plan = plan(&set, &tasks, &given).map_err(|e| fail(&e))?;
    let heard = Heard {
        progress: progress.map(|p| p.clone().unbind()),
        task: Mutex::new(String::new()),
        reports: Mutex::new(Vec::new()),
    };
    let opts = BenchmarkOptions {
        seeds_per_task,
        jobs,
    };
    let board = py.detach(|| {
        let ext = factory.as_ref().map(|f| f as &dyn ExternalPlanners);
        run_benchmark(&set, &plan, &out, opts, ext, &heard)
    });
    let board = match board {
        Ok(b) => b,
        Err(e) => {
            let err = fail(&e);
            // The Python planner's own exception is the cause.
            if let Some(cause) = factory
                .as_ref()
                .and_then(|f| f.errors.lock().ok().and_then(|mut s| s.take()))
            {
                err.set_cause(py, Some(cause));
            }
            return Err(err);
        }
    };
    let d = PyDict::new(py);
    d.set_item("board", board.to_json())?;
    d.set_item("notes", plan.notes.clone())?;
    let reports = PyList::empty(py);
    for f in heard.reports.into_inner().unwrap_or_default() {
        let r = PyDict::new(py);
        r.set_item("task", f.task)?;
        r.set_item("planned", f.report.planned)?;
        r.set_item("skipped", f.report.skipped)?;
        r.set_item("ran", f.report.ran)?;
        r.set_item("failed", f.report.failed)?;
        r.set_item("wall_s", f.wall_s)?;
        reports.append(r)?;
    }
    d.set_item("tasks", reports)?;
    Ok(d)
}
