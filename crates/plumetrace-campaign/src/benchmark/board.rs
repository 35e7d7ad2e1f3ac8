//! The leaderboard: every task's campaign summarised per planner (the campaign's statistics:
//! success with its Wilson 95 % interval, error quantiles, times, path) plus what a benchmark
//! counts from the runs' outcomes (false declarations, collisions, cage aborts), as Markdown and
//! JSON naming the task set's version.

use super::{Task, TaskSet};
use crate::error::CampaignError;
use crate::runs::{RUNS_FILE, RunOutcome, RunRow, read_rows, sorted_unique};
use crate::spec::Campaign;
use crate::stats::summarise;
use plumetrace_mission::Outcome;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// One planner's results on one task.
#[derive(Debug, Clone, Serialize)]
pub struct Entry {
    /// The planner (entrant) name.
    pub planner: String,
    /// Runs recorded.
    pub runs: u64,
    /// Runs that succeeded (a declaration within the task's radius of the source; of every
    /// source with several).
    pub successes: u64,
    /// `successes / runs`.
    pub success_rate: f64,
    /// Wilson 95 % interval of the success rate.
    pub success_ci95: [f64; 2],
    /// Sources with a declaration within the radius, over all runs.
    pub sources_located: u64,
    /// Sources over all runs.
    pub sources: u64,
    /// Error of the first declaration, median and 90th percentile over the declaring runs, m.
    pub error_median_m: f64,
    /// See `error_median_m`.
    pub error_p90_m: f64,
    /// Absolute along-flow error, median, m.
    pub along_median_m: f64,
    /// Signed along-flow error, median (positive: declared downflow), m.
    pub along_signed_median_m: f64,
    /// Absolute crossflow error, median, m.
    pub cross_median_m: f64,
    /// Time to the first declaration, median over the declaring runs, s.
    pub declaration_median_s: f64,
    /// Path length, median over all runs, m.
    pub path_length_median_m: f64,
    /// Runs that declared but did not succeed.
    pub false_declarations: u64,
    /// Runs that ended in an obstacle (kelp).
    pub collisions: u64,
    /// Runs aborted by a planner's cage (far outside the op-area).
    pub cage_aborts: u64,
    /// Runs that could not run (outcome `error`).
    pub failed: u64,
}

/// One task's leaderboard.
#[derive(Debug, Clone, Serialize)]
pub struct TaskBoard {
    /// The task as the task set states it.
    pub task: Task,
    /// Test seeds flown per planner (the first ones).
    pub seeds_flown: u64,
    /// The entries, best first: success rate, then error median, then name.
    pub entries: Vec<Entry>,
}

/// The leaderboard of a benchmark directory.
#[derive(Debug, Clone, Serialize)]
pub struct Board {
    /// The task set's version.
    pub task_set: String,
    /// Per task flown, in the task set's order.
    pub tasks: Vec<TaskBoard>,
}

/// The entries of a task's finished campaign (its `runs.csv` in `dir`).
pub fn task_board(c: &Campaign, task: &Task, dir: &Path) -> Result<TaskBoard, CampaignError> {
    let path = dir.join(RUNS_FILE);
    let rows = sorted_unique(c, read_rows(&path)?.rows, &path)?;
    let groups = summarise(c, &rows);
    let mut entries: Vec<Entry> = groups
        .iter()
        .map(|g| {
            let mine: Vec<&RunRow> = rows
                .iter()
                .filter(|(_, r)| r.config == g.config)
                .map(|(_, r)| r)
                .collect();
            entry(g, &mine)
        })
        .collect();
    entries.sort_by(|a, b| {
        b.success_rate
            .total_cmp(&a.success_rate)
            .then(nan_last(a.error_median_m).total_cmp(&nan_last(b.error_median_m)))
            .then(a.planner.cmp(&b.planner))
    });
    Ok(TaskBoard {
        task: task.clone(),
        seeds_flown: c.file.seeds,
        entries,
    })
}

fn nan_last(v: f64) -> f64 {
    if v.is_nan() { f64::INFINITY } else { v }
}

fn entry(g: &crate::stats::GroupSummary, rows: &[&RunRow]) -> Entry {
    let count = |o: Outcome| {
        rows.iter()
            .filter(|r| r.outcome == RunOutcome::Mission(o))
            .count() as u64
    };
    Entry {
        planner: g.config.clone(),
        runs: g.runs,
        successes: g.successes,
        success_rate: g.success_rate,
        success_ci95: [g.success_ci_low, g.success_ci_high],
        sources_located: g.sources_located,
        sources: g.sources,
        error_median_m: g.error_median_m,
        error_p90_m: g.error_p90_m,
        along_median_m: g.along_median_m,
        along_signed_median_m: g.along_signed_median_m,
        cross_median_m: g.cross_median_m,
        declaration_median_s: g.declaration_median_s,
        path_length_median_m: g.path_length_median_m,
        false_declarations: rows
            .iter()
            .filter(|r| r.metrics.declared && !r.metrics.success)
            .count() as u64,
        collisions: count(Outcome::Collided),
        cage_aborts: count(Outcome::AbortedByCage),
        failed: rows
            .iter()
            .filter(|r| r.outcome == RunOutcome::ERROR)
            .count() as u64,
    }
}

/// A number for a table: `–` when there is none.
fn num(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else {
        "–".into()
    }
}

impl Board {
    /// The board as JSON (numbers that do not exist are `null`).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default() + "\n"
    }

    /// The board as Markdown: per task, what it is, then a table best first and its charts
    /// (the task's campaign charts, linked relative to the benchmark directory).
    pub fn to_markdown(&self, set: &TaskSet) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "# Benchmark leaderboard, task set {}\n", self.task_set);
        let _ = writeln!(
            s,
            "Every planner flies the same test seeds of each task (common random numbers). \
             Success: a declaration within the task's radius of the source (with several \
             sources, every source located), with its Wilson 95 % interval. Errors are of the \
             first declaration over the declaring runs, in metres (signed along: positive = \
             declared downflow); times are medians in seconds. False declarations: runs that \
             declared and did not succeed. Task set: `{}`.\n",
            set.file
        );
        for tb in &self.tasks {
            task_markdown(&mut s, tb);
        }
        s
    }
}

fn task_markdown(s: &mut String, tb: &TaskBoard) {
    let t = &tb.task;
    let _ = writeln!(s, "## `{}`\n", t.name);
    let _ = writeln!(s, "{}.\n", t.description);
    let _ = writeln!(
        s,
        "Scenario `{}`; {}; time limit {} s; success within {} m; test seeds: the first {} of \
         {} (campaign seed {}).\n",
        t.scenario,
        t.vehicles,
        t.time_limit_s,
        t.success_radius_m,
        tb.seeds_flown,
        t.test_seeds,
        t.test_seed
    );
    s.push_str(
        "| rank | planner | runs | success (95 % CI) | sources located | error median / p90 | \
         along / cross median | signed along | declaration (s) | path (m) | false declarations | \
         collisions | cage aborts | errors |\n",
    );
    s.push_str(
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for (i, e) in tb.entries.iter().enumerate() {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {}/{} = {} ({} – {}) | {}/{} | {} / {} | {} / {} | {} | {} | {} | {} | {} | {} | {} |",
            i + 1,
            e.planner,
            e.runs,
            e.successes,
            e.runs,
            num(e.success_rate, 2),
            num(e.success_ci95[0], 2),
            num(e.success_ci95[1], 2),
            e.sources_located,
            e.sources,
            num(e.error_median_m, 1),
            num(e.error_p90_m, 1),
            num(e.along_median_m, 1),
            num(e.cross_median_m, 1),
            num(e.along_signed_median_m, 1),
            num(e.declaration_median_s, 0),
            num(e.path_length_median_m, 0),
            e.false_declarations,
            e.collisions,
            e.cage_aborts,
            e.failed,
        );
    }
    let _ = writeln!(
        s,
        "\n![success of each planner on `{0}`]({0}/success.svg) ![errors of each planner on \
         `{0}`]({0}/errors.svg)\n",
        t.name
    );
}
