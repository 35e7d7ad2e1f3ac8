//! `campaign` and `merge`: the command line's campaign runs from Python.

use crate::error::{msg, to_py};
use plumetrace_campaign::{Campaign, RunOptions, Shard, merge as merge_dirs, run_campaign};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// A shard from Python: `"2/4"` or `(2, 4)`.
fn shard(v: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Shard>> {
    let Some(v) = v else { return Ok(None) };
    if v.is_none() {
        return Ok(None);
    }
    let text = if let Ok(s) = v.extract::<String>() {
        s
    } else if let Ok((k, n)) = v.extract::<(u64, u64)>() {
        format!("{k}/{n}")
    } else {
        return Err(msg(format!("shard {v} is neither 'K/N' nor (K, N)")));
    };
    text.parse::<Shard>()
        .map(Some)
        .map_err(|e| msg(format!("shard '{text}': {e}")))
}

/// Runs (or resumes) the campaign `file` into `out`; `progress(done, total)` is called after
/// each run. Returns what it did as a dict.
#[pyfunction]
#[pyo3(signature = (file, out, jobs=None, shard=None, seeds=None, progress=None))]
pub fn campaign<'py>(
    py: Python<'py>,
    file: PathBuf,
    out: PathBuf,
    jobs: Option<usize>,
    shard: Option<&Bound<'py, PyAny>>,
    seeds: Option<u64>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    if let Some(j) = jobs
        && !(1..=256).contains(&j)
    {
        return Err(msg(format!("jobs = {j} is outside 1..=256")));
    }
    if let Some(s) = seeds
        && !(1..=1_000_000).contains(&s)
    {
        return Err(msg(format!("seeds = {s} is outside 1..=1,000,000")));
    }
    let shard = self::shard(shard)?;
    let c = Campaign::load(&file, seeds).map_err(to_py)?;
    let planned = c.shard_runs(shard).len() as u64;
    let progress = progress.map(|p| p.clone().unbind());
    let report = py
        .detach(|| {
            run_campaign(
                &c,
                &out,
                RunOptions {
                    jobs,
                    shard,
                    ..RunOptions::default()
                },
                &|done, total| {
                    if let Some(p) = &progress {
                        Python::attach(|py| {
                            let _ = p.bind(py).call1((done, total));
                        });
                    }
                },
            )
        })
        .map_err(|e| {
            msg(format!(
                "campaign {}: {}",
                file.display(),
                crate::error::located(&e)
            ))
        })?;
    let d = PyDict::new(py);
    d.set_item("name", &c.file.name)?;
    d.set_item("planned", planned)?;
    d.set_item("skipped", report.skipped)?;
    d.set_item("ran", report.ran)?;
    d.set_item("failed", report.failed)?;
    d.set_item("cut_partial_line", report.cut_partial_line)?;
    d.set_item("out", out)?;
    Ok(d)
}

/// The columns of a campaign's `runs.csv` (and `runs.parquet`), in order, as `(name, kind, unit,
/// description)`: the run's keys and outcome, the mission's metrics, the drawn site and the
/// failure message. `read_runs` reads each column by its kind.
#[pyfunction]
pub fn run_columns() -> Vec<(&'static str, &'static str, &'static str, String)> {
    plumetrace_campaign::runs::columns()
        .iter()
        .map(|c| (c.name, c.kind.name(), c.unit, c.description()))
        .collect()
}

/// Merges shard directories of one campaign into `out`.
#[pyfunction]
pub fn merge<'py>(
    py: Python<'py>,
    dirs: Vec<PathBuf>,
    out: PathBuf,
) -> PyResult<Bound<'py, PyDict>> {
    let report = py.detach(|| merge_dirs(&dirs, &out)).map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("runs", report.runs)?;
    d.set_item("expected", report.expected)?;
    d.set_item("partial", report.cut_partial_lines)?;
    d.set_item("out", out)?;
    Ok(d)
}
