//! `plumetrace benchmark`: every task of the shipped task set flown on its test seeds by the
//! planners asked for, each task a campaign (parallel, resumable), then the leaderboard.

use anyhow::Result;
use plumetrace_campaign::benchmark::{
    BenchmarkOptions, Entrant, Given, Task, TaskDone, TaskSet, Watch, plan, run_benchmark,
};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
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
    let given = given(&set, a)?;
    let plan = plan(&set, &a.tasks, &given)?;
    for n in &plan.notes {
        eprintln!("note: {n}");
    }
    let started = Instant::now();
    let opts = BenchmarkOptions {
        seeds_per_task: a.seeds_per_task,
        jobs: a.jobs,
    };
    run_benchmark(&set, &plan, out, opts, None, &Printed::default())?;
    crate::outln!(
        "task set {}: {} tasks in {:.1} s; wrote {}",
        set.version,
        plan.tasks.len(),
        started.elapsed().as_secs_f64(),
        out.join(plumetrace_campaign::benchmark::run::LEADERBOARD_MD)
            .display()
    );
    Ok(())
}

/// The entrants asked for: names, or planner files (each key checked by the registry here, so
/// an error names the file).
fn given(set: &TaskSet, a: &BenchmarkArgs) -> Result<Vec<Given>> {
    let mut given = Vec::new();
    for p in &a.planner {
        given.push(Given::named(set, p)?);
    }
    for f in &a.planner_file {
        let e = Entrant::from_file(f)?;
        if let Some(t) = &e.planner
            && let Err(error) = plumetrace_planner::PlannerConfig::from_table(t, "")
        {
            // The key's line in the file (written bare or under `[planner]`).
            let text = std::fs::read_to_string(f).unwrap_or_default();
            let line = [error.key.clone(), format!("planner.{}", error.key)]
                .iter()
                .find_map(|k| plumetrace_scenario::locate::line_of_key(&text, k));
            let at = plumetrace_scenario::locate::at_line(line);
            return Err(anyhow::anyhow!("{}{at}: {error}", f.display()));
        }
        given.push(Given::file(e));
    }
    Ok(given)
}

/// Each task's progress bar and its line when done.
#[derive(Default)]
struct Printed {
    bar: Mutex<Option<crate::progress::Progress>>,
}

impl Watch for Printed {
    fn task_started(&self, _task: &Task, runs: u64) {
        if let Ok(mut b) = self.bar.lock() {
            *b = Some(crate::progress::Progress::new(runs, "runs"));
        }
    }

    fn run_done(&self, done: u64, _total: u64) {
        if let Ok(b) = self.bar.lock()
            && let Some(b) = b.as_ref()
        {
            b.tick(done);
        }
    }

    fn task_done(&self, d: &TaskDone<'_>) {
        if let Ok(mut b) = self.bar.lock()
            && let Some(b) = b.take()
        {
            b.finish();
        }
        let r = &d.report;
        crate::outln!(
            "{}: {} planners x {} test seeds: {} runs, {} already recorded, {} run now ({} \
             failed) in {:.1} s",
            d.task.name,
            d.planners,
            d.seeds,
            r.planned,
            r.skipped,
            r.ran,
            r.failed,
            d.wall_s
        );
    }
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
