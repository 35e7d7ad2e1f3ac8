//! `plumetrace benchmark`: every task of the shipped task set flown on its test seeds by the
//! planners asked for, each task a campaign (parallel, resumable), then the leaderboard.

use anyhow::{Context, Result};
use plumetrace_campaign::benchmark::board::{Board, task_board};
use plumetrace_campaign::benchmark::{
    BenchmarkError, Entrant, Task, TaskSet, task_campaign, task_dir,
};
use plumetrace_campaign::{RunOptions, Share, run_campaign};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `plumetrace benchmark`.
#[derive(Debug, clap::Args)]
pub struct BenchmarkArgs {
    /// Tasks to fly, comma-separated (default: every task of the set).
    #[arg(long, value_delimiter = ',')]
    pub tasks: Vec<String>,
    /// Planners to enter, comma-separated: registered kinds at their defaults, or `formation`
    /// (a team task's own planners). Default: every planner of each task.
    #[arg(long, value_delimiter = ',', conflicts_with = "planner_file")]
    pub planner: Vec<String>,
    /// A planner table to enter (TOML: `kind` and its keys, or a `[planner]` table), named
    /// after the file; it flies the tasks its kind enters.
    #[arg(long)]
    pub planner_file: Vec<PathBuf>,
    /// Test seeds per task, the first ones (default: each task's `seeds`; at most its
    /// `test_seeds`).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::seeds)]
    pub seeds_per_task: Option<u64>,
    /// Worker threads, 1 to 256 (default: one per core). Results do not depend on it.
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::jobs)]
    pub jobs: Option<usize>,
    /// Output directory: a campaign directory per task, `leaderboard.md` and
    /// `leaderboard.json`; running again into it resumes.
    #[arg(long, required_unless_present = "list")]
    pub out: Option<PathBuf>,
    /// Print the task set (tasks, scenarios, seeds, planners) and stop.
    #[arg(long)]
    pub list: bool,
}

/// Runs (or resumes) the benchmark and writes the leaderboard.
pub fn run(a: &BenchmarkArgs) -> Result<()> {
    let set = TaskSet::builtin()?;
    if a.list {
        crate::out!("{}", list(&set));
        return Ok(());
    }
    let out = a.out.as_deref().unwrap_or(Path::new("."));
    refuse_foreign(out)?;
    let plan = plan(&set, a)?;
    let mut boards = Vec::new();
    let started = Instant::now();
    for (task, entrants) in &plan {
        let seeds = a.seeds_per_task.unwrap_or(task.seeds);
        let c = task_campaign(&set, task, entrants, seeds, out)
            .with_context(|| format!("benchmark task '{}'", task.name))?;
        let dir = task_dir(out, task);
        let t0 = Instant::now();
        let progress = crate::progress::Progress::new(c.runs().len() as u64, "runs");
        let report = run_campaign(
            &c,
            &dir,
            RunOptions {
                jobs: a.jobs,
                shard: None,
                share: Share::Plume,
            },
            &|done, _| progress.tick(done),
        )
        .with_context(|| format!("benchmark task '{}'", task.name))?;
        progress.finish();
        crate::outln!(
            "{}: {} planners x {seeds} test seeds: {} runs, {} already recorded, {} run now ({} \
             failed) in {:.1} s",
            task.name,
            entrants.len(),
            report.planned,
            report.skipped,
            report.ran,
            report.failed,
            t0.elapsed().as_secs_f64()
        );
        boards.push(task_board(&c, task, &dir)?);
    }
    let board = Board {
        task_set: set.version.clone(),
        tasks: boards,
    };
    let write = |name: &str, text: String| -> Result<()> {
        let p = out.join(name);
        plumetrace_mission::output::write_atomic(&p, text.as_bytes())
            .with_context(|| format!("writing {}", p.display()))
    };
    write("leaderboard.md", board.to_markdown(&set))?;
    write("leaderboard.json", board.to_json())?;
    crate::outln!(
        "task set {}: {} tasks in {:.1} s; wrote {}",
        set.version,
        plan.len(),
        started.elapsed().as_secs_f64(),
        out.join("leaderboard.md").display()
    );
    Ok(())
}

/// A directory that holds files but no benchmark is refused (results never overwrite other
/// files).
fn refuse_foreign(out: &Path) -> Result<()> {
    if out.exists() && !out.is_dir() {
        anyhow::bail!(
            "{}: is a file, not a directory; give a new, empty or benchmark --out directory",
            out.display()
        );
    }
    if out.is_dir() && !out.join("tasks").is_dir() {
        let first = std::fs::read_dir(out)
            .with_context(|| format!("reading {}", out.display()))?
            .flatten()
            .next();
        if let Some(f) = first {
            anyhow::bail!(
                "{}: holds files ({} among them) but no benchmark (no tasks/); give a new, empty \
                 or benchmark --out directory",
                out.display(),
                f.file_name().to_string_lossy()
            );
        }
    }
    Ok(())
}

/// The tasks to fly and each one's entrants. A planner that does not enter a task named by
/// `--tasks` is an error; without `--tasks`, that task is left out (with a note).
fn plan<'a>(set: &'a TaskSet, a: &BenchmarkArgs) -> Result<Vec<(&'a Task, Vec<Entrant>)>> {
    let mut tasks: Vec<&Task> = Vec::new();
    for name in &a.tasks {
        let t = set.task(name.trim())?;
        if !tasks.iter().any(|u| u.name == t.name) {
            tasks.push(t);
        }
    }
    let explicit = !tasks.is_empty();
    if !explicit {
        tasks = set.tasks.iter().collect();
    }
    // Each given entrant with the name it enters tasks under (its kind for a file).
    let mut given: Vec<(String, Entrant)> = Vec::new();
    for p in &a.planner {
        let p = p.trim();
        let known = set.planner_names();
        if !known.iter().any(|k| k == p) {
            let names: Vec<&str> = known.iter().map(String::as_str).collect();
            return Err(BenchmarkError::UnknownPlanner {
                name: p.to_string(),
                suggestion: plumetrace_core::closest(p, &names).map(str::to_string),
                known: names.join(", "),
            }
            .into());
        }
        given.push((p.to_string(), Entrant::named(p)));
    }
    for f in &a.planner_file {
        let e = Entrant::from_file(f)?;
        // Every key checked by the registry here, so an error names this file.
        if let Some(t) = &e.planner {
            plumetrace_planner::PlannerConfig::from_table(t, "")
                .with_context(|| f.display().to_string())?;
        }
        let kind = e
            .planner
            .as_ref()
            .and_then(|t| t.get("kind"))
            .and_then(toml::Value::as_str)
            .unwrap_or("")
            .to_string();
        given.push((kind, e));
    }
    let mut plan = Vec::new();
    for t in tasks {
        let entrants: Vec<Entrant> = if given.is_empty() {
            t.planners.iter().map(|p| Entrant::named(p)).collect()
        } else {
            let mut v = Vec::new();
            for (enters_as, e) in &given {
                if t.planners.contains(enters_as) {
                    v.push(e.clone());
                } else if explicit {
                    return Err(BenchmarkError::NotEntered {
                        task: t.name.clone(),
                        planner: e.name.clone(),
                        planners: t.planners.join(", "),
                    }
                    .into());
                }
            }
            v
        };
        if entrants.is_empty() {
            eprintln!(
                "note: task '{}' left out: it is flown by {} only",
                t.name,
                t.planners.join(", ")
            );
            continue;
        }
        plan.push((t, entrants));
    }
    if plan.is_empty() {
        let names: Vec<&str> = given.iter().map(|(_, e)| e.name.as_str()).collect();
        return Err(BenchmarkError::NothingToFly {
            version: set.version.clone(),
            planners: names.join(", "),
        }
        .into());
    }
    Ok(plan)
}

/// The task set as text: one block per task.
fn list(set: &TaskSet) -> String {
    use std::fmt::Write as _;
    let mut s = format!("task set {} ({})\n", set.version, set.file);
    for t in &set.tasks {
        let _ = writeln!(
            s,
            "\n{}: {}\n  scenario   {}\n  vehicles   {}\n  time limit {} s; success within {} m\n  \
             test seeds {} (campaign seed {}; {} flown by default)\n  tuning     {} seeds \
             (campaign seed {})\n  planners   {}",
            t.name,
            t.description,
            t.scenario,
            t.vehicles,
            t.time_limit_s,
            t.success_radius_m,
            t.test_seeds,
            t.test_seed,
            t.seeds,
            t.tuning_seeds,
            t.tuning_seed,
            t.planners.join(", ")
        );
    }
    s
}
