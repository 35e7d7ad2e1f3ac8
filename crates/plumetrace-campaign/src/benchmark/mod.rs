//! The benchmark: a versioned set of tasks, each a scenario (a family of sites, or a preset)
//! with a test-seed set and a tuning-seed set that never overlap, flown as campaigns.
//!
//! The task set ships with the binary (`benchmarks/tasks-v1.toml` and the family files it names
//! are compiled in), so `plumetrace benchmark` runs anywhere and every copy of a version flies
//! the same runs. A task's test seeds are `derive_seed(test_seed, k)` for `k < test_seeds`: a
//! campaign with the test seed as its seed flies them in order, so the benchmark of a task is a
//! campaign ([`task_campaign`]) with one configuration per planner, every planner on the same
//! sites and plumes (common random numbers), parallel and resumable like any campaign. Campaigns
//! and family draws that would reach a test seed of a task's scenario are refused unless asked
//! ([`TaskSet::test_seed_use`]): tune on the tuning seeds, read the test seeds once.

pub mod board;
pub mod run;

pub use run::{BenchmarkOptions, Given, Plan, Quiet, TaskDone, Watch, plan, run_benchmark};

use crate::error::CampaignError;
use crate::spec::{Campaign, CampaignFile, ConfigFile};
use serde::{Deserialize, Serialize};
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// The task set's version of [`TASKS_V1`].
pub const VERSION: &str = "v1";

/// The task set, as shipped (`benchmarks/tasks-v1.toml`).
pub const TASKS_V1: &str = include_str!("../../../../benchmarks/tasks-v1.toml");

/// Where the shipped task set lives in the repository (named in errors).
pub const TASKS_V1_PATH: &str = "benchmarks/tasks-v1.toml";

/// The family files the task set names, by their path from the repository's root, compiled in.
const FILES: &[(&str, &str)] = &[
    (
        "examples/families/coastal.family.toml",
        include_str!("../../../../examples/families/coastal.family.toml"),
    ),
    (
        "examples/families/faults.family.toml",
        include_str!("../../../../examples/families/faults.family.toml"),
    ),
    (
        "examples/families/duck-like.family.toml",
        include_str!("../../../../examples/families/duck-like.family.toml"),
    ),
    (
        "examples/families/formation.family.toml",
        include_str!("../../../../examples/families/formation.family.toml"),
    ),
];

/// The entrant that flies a task's scenario with its own planners (a team).
pub const SCENARIO_TEAM: &str = "formation";

/// What can go wrong with a task set or a benchmark call.
#[derive(Debug, thiserror::Error)]
pub enum BenchmarkError {
    /// The task set file is malformed or inconsistent.
    #[error("{file}: {}{message}", if key.is_empty() { String::new() } else { format!("{key}: ") })]
    TaskSet {
        /// The task set file.
        file: String,
        /// Key path in it.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// `--tasks` names no task of the set.
    #[error("no task '{name}' in task set {version}{}; tasks: {known}", hint(.suggestion))]
    UnknownTask {
        /// The name given.
        name: String,
        /// The task set's version.
        version: String,
        /// The nearest task name.
        suggestion: Option<String>,
        /// Every task name.
        known: String,
    },
    /// `--planner` names no planner.
    #[error("no planner '{name}'{}; planners: {known}", hint(.suggestion))]
    UnknownPlanner {
        /// The name given.
        name: String,
        /// The nearest planner name.
        suggestion: Option<String>,
        /// Every planner that enters some task.
        known: String,
    },
    /// A planner does not enter a task that was asked for.
    #[error("task '{task}' is not flown by '{planner}': its planners are {planners}")]
    NotEntered {
        /// The task.
        task: String,
        /// The planner.
        planner: String,
        /// The task's planners.
        planners: String,
    },
    /// No task is flown by the planners asked for.
    #[error("no task of task set {version} is flown by {planners}")]
    NothingToFly {
        /// The task set's version.
        version: String,
        /// The planners asked for.
        planners: String,
    },
    /// More seeds per task than a task has test seeds.
    #[error("--seeds-per-task {given}: task '{task}' has {max} test seeds (1 to {max})")]
    TooManySeeds {
        /// The task.
        task: String,
        /// Seeds asked for.
        given: u64,
        /// Its test seeds.
        max: u64,
    },
    /// The output directory holds something other than a benchmark.
    #[error("{dir}: {what}; give a new, empty or benchmark output directory")]
    NotABenchmark {
        /// The directory.
        dir: String,
        /// What it is or holds.
        what: String,
    },
    /// The output directory holds a task flown by other entrants.
    #[error(
        "{dir}: holds task '{task}' flown by {had}; this call enters {now}: give another output \
         directory (or the same planners, to resume)"
    )]
    OtherEntrants {
        /// The directory.
        dir: String,
        /// The task.
        task: String,
        /// Who flew it there.
        had: String,
        /// Who this call enters.
        now: String,
    },
    /// An error flying one task.
    #[error("benchmark task '{task}': {error}")]
    InTask {
        /// The task.
        task: String,
        /// What went wrong.
        error: Box<BenchmarkError>,
    },
    /// A campaign error (a planner file, a group that does not build, the output directory).
    #[error(transparent)]
    Campaign(#[from] CampaignError),
}

fn hint(s: &Option<String>) -> String {
    s.as_ref()
        .map(|s| format!(" (did you mean '{s}'?)"))
        .unwrap_or_default()
}

/// One task as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Task {
    /// Its name (`--tasks`, tables, the output directory).
    pub name: String,
    /// One line about it.
    pub description: String,
    /// A family file (a path from the repository's root ending in `.family.toml`) or a preset.
    pub scenario: String,
    /// What a planner is given: vehicles and sensors, in words.
    pub vehicles: String,
    /// The mission's time limit, s (the scenario's; [`task_campaign`] checks it).
    pub time_limit_s: f64,
    /// Success: a declaration within this distance of the source (of every source), m.
    pub success_radius_m: f64,
    /// The planners that enter the task: registered kinds at their defaults, or `formation`
    /// (the scenario's own team).
    pub planners: Vec<String>,
    /// The test seeds are `derive_seed(test_seed, k)`, `k < test_seeds`.
    pub test_seed: u64,
    /// How many test seeds the task has.
    pub test_seeds: u64,
    /// The tuning seeds are `derive_seed(tuning_seed, k)`, `k < tuning_seeds`.
    pub tuning_seed: u64,
    /// How many tuning seeds the task names (checked disjoint from the test seeds).
    pub tuning_seeds: u64,
    /// Test seeds the benchmark flies by default (the first ones).
    pub seeds: u64,
    /// Planner keys every entrant is given on this task (a campaign configuration's `set`:
    /// bare keys of the planner, e.g. `avoid_obstacles` where there are obstacles).
    #[serde(default, skip_serializing_if = "toml::Table::is_empty")]
    pub set: toml::Table,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TaskSetFile {
    version: String,
    tasks: Vec<Task>,
}

/// A task set: its version and tasks, with each task's test seeds and scenario name.
#[derive(Debug, Clone)]
pub struct TaskSet {
    /// The version results name (`v1`).
    pub version: String,
    /// The tasks, in file order.
    pub tasks: Vec<Task>,
    /// Per task: the name its scenario goes by (a family's `name`, a preset's name), which a
    /// campaign's scenario is matched against.
    pub scenario_names: Vec<String>,
    /// Per task: its test seeds.
    test_sets: Vec<HashSet<u64>>,
    /// The file it was read from (for errors).
    pub file: String,
}

/// A campaign or draw that reaches a test seed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TestSeedUse {
    /// The task whose test seed it is.
    pub task: String,
    /// The first seed index that reaches one.
    pub seed_index: u64,
    /// That run seed.
    pub seed: u64,
}

impl TaskSet {
    /// The shipped task set.
    pub fn builtin() -> Result<TaskSet, BenchmarkError> {
        TaskSet::parse(TASKS_V1, TASKS_V1_PATH)
    }

    /// Parses and checks task-set text: names, seeds (test and tuning sets disjoint, within
    /// bounds), radii, planners, scenarios known.
    pub fn parse(text: &str, file: &str) -> Result<TaskSet, BenchmarkError> {
        let bad = |key: String, message: String| BenchmarkError::TaskSet {
            file: file.to_string(),
            key,
            message,
        };
        let de = toml::Deserializer::parse(text).map_err(|e| bad(String::new(), e.to_string()))?;
        let f: TaskSetFile = serde_path_to_error::deserialize(de).map_err(|e| {
            let key = e.path().to_string();
            let inner = e.into_inner();
            bad(
                key,
                plumetrace_scenario::locate::message_with_line(&inner, text),
            )
        })?;
        let mut scenario_names = Vec::new();
        let mut test_sets = Vec::new();
        for (i, t) in f.tasks.iter().enumerate() {
            let at = |k: &str| format!("tasks[{i}].{k}");
            if f.tasks[..i].iter().any(|u| u.name == t.name) {
                return Err(bad(at("name"), format!("'{}' is used twice", t.name)));
            }
            check_task(t, &at).map_err(|(k, m)| bad(k, m))?;
            let name = scenario_name(&t.scenario).map_err(|m| bad(at("scenario"), m))?;
            let test: HashSet<u64> = (0..t.test_seeds)
                .map(|k| plumetrace_env::derive_seed(t.test_seed, k))
                .collect();
            if let Some(k) = (0..t.tuning_seeds)
                .find(|&k| test.contains(&plumetrace_env::derive_seed(t.tuning_seed, k)))
            {
                return Err(bad(
                    at("tuning_seed"),
                    format!("tuning seed index {k} is one of the task's test seeds"),
                ));
            }
            scenario_names.push(name);
            test_sets.push(test);
        }
        Ok(TaskSet {
            version: f.version,
            tasks: f.tasks,
            scenario_names,
            test_sets,
            file: file.to_string(),
        })
    }

    /// The task called `name`, or an error with the nearest name.
    pub fn task(&self, name: &str) -> Result<&Task, BenchmarkError> {
        let known: Vec<&str> = self.tasks.iter().map(|t| t.name.as_str()).collect();
        self.tasks
            .iter()
            .find(|t| t.name == name)
            .ok_or_else(|| BenchmarkError::UnknownTask {
                name: name.to_string(),
                version: self.version.clone(),
                suggestion: plumetrace_core::closest(name, &known).map(str::to_string),
                known: known.join(", "),
            })
    }

    /// Whether the run seeds of a campaign or draw (`derive_seed(seed, k)`, `k < count`) on a
    /// scenario called `scenario` (a family's name, a scenario's `name`) reach a test seed of a
    /// task on that scenario; the first such seed if so.
    pub fn test_seed_use(&self, scenario: &str, seed: u64, count: u64) -> Option<TestSeedUse> {
        for (i, t) in self.tasks.iter().enumerate() {
            if self.scenario_names[i] != scenario {
                continue;
            }
            let test = &self.test_sets[i];
            if let Some(k) =
                (0..count).find(|&k| test.contains(&plumetrace_env::derive_seed(seed, k)))
            {
                return Some(TestSeedUse {
                    task: t.name.clone(),
                    seed_index: k,
                    seed: plumetrace_env::derive_seed(seed, k),
                });
            }
        }
        None
    }

    /// Every planner name that enters some task, each once, in task order.
    pub fn planner_names(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for p in self.tasks.iter().flat_map(|t| &t.planners) {
            if !out.contains(p) {
                out.push(p.clone());
            }
        }
        out
    }
}

/// Checks one task's values; an error is (key, message).
fn check_task(t: &Task, at: &dyn Fn(&str) -> String) -> Result<(), (String, String)> {
    let name_ok = !t.name.is_empty()
        && t.name.len() <= 64
        && t.name.starts_with(|c: char| c.is_ascii_alphanumeric())
        && t.name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
    if !name_ok {
        return Err((
            at("name"),
            format!(
                "'{}': 1 to 64 ASCII letters, digits, '-' and '_', starting with a letter or \
                 digit (it names a directory)",
                t.name
            ),
        ));
    }
    if !(t.success_radius_m.is_finite() && t.success_radius_m > 0.0) {
        return Err((
            at("success_radius_m"),
            format!("must be a positive number, got {}", t.success_radius_m),
        ));
    }
    if !(1..=crate::spec::MAX_SEEDS).contains(&t.test_seeds) {
        return Err((
            at("test_seeds"),
            format!(
                "must be 1 to {}, got {}",
                crate::spec::MAX_SEEDS,
                t.test_seeds
            ),
        ));
    }
    if !(1..=t.test_seeds).contains(&t.seeds) {
        return Err((
            at("seeds"),
            format!(
                "must be 1 to test_seeds ({}), got {}",
                t.test_seeds, t.seeds
            ),
        ));
    }
    if t.tuning_seeds > crate::spec::MAX_SEEDS {
        return Err((
            at("tuning_seeds"),
            format!(
                "must be at most {}, got {}",
                crate::spec::MAX_SEEDS,
                t.tuning_seeds
            ),
        ));
    }
    if t.planners.is_empty() {
        return Err((at("planners"), "names no planner".into()));
    }
    for (j, p) in t.planners.iter().enumerate() {
        if p != SCENARIO_TEAM && plumetrace_mission::PlannerKind::from_name(p).is_none() {
            let mut known: Vec<&str> = plumetrace_mission::PlannerKind::ALL
                .iter()
                .map(|k| k.name())
                .collect();
            known.push(SCENARIO_TEAM);
            return Err((
                format!("{}[{j}]", at("planners")),
                format!(
                    "'{p}' is not a planner{}; planners: {}",
                    hint(&plumetrace_core::closest(p, &known).map(str::to_string)),
                    known.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// The text of a family file the task set names (compiled in).
fn family_text(path: &str) -> Option<&'static str> {
    FILES.iter().find(|(p, _)| *p == path).map(|(_, t)| *t)
}

/// The name a task's scenario goes by: a family's `name`, or the preset's.
fn scenario_name(scenario: &str) -> Result<String, String> {
    if plumetrace_scenario::is_family_path(scenario) {
        let text = family_text(scenario).ok_or_else(|| {
            let known: Vec<&str> = FILES.iter().map(|(p, _)| *p).collect();
            format!(
                "'{scenario}' is not a family the task set ships ({})",
                known.join(", ")
            )
        })?;
        let table: toml::Table = text.parse().map_err(|e| format!("{scenario}: {e}"))?;
        return table
            .get("name")
            .and_then(toml::Value::as_str)
            .map(str::to_string)
            .ok_or_else(|| format!("{scenario}: has no name"));
    }
    if plumetrace_scenario::find_preset(scenario).is_some() {
        return Ok(scenario.to_string());
    }
    let known: Vec<&str> = plumetrace_scenario::PRESETS
        .iter()
        .map(|p| p.name)
        .collect();
    Err(format!(
        "'{scenario}' is neither a shipped family file nor a preset{}",
        hint(&plumetrace_core::closest(scenario, &known).map(str::to_string))
    ))
}

/// A planner entered in the benchmark: its name in tables and the planner table it flies
/// (`None`: the scenario's own planners).
#[derive(Debug, Clone, PartialEq)]
pub struct Entrant {
    /// Its name (a registered kind, `formation`, or a planner file's stem).
    pub name: String,
    /// The planner table replacing the scenario's; `None` keeps the scenario's planners.
    pub planner: Option<toml::Table>,
}

impl Entrant {
    /// A registered planner at its defaults, or `formation` (the scenario's team).
    pub fn named(name: &str) -> Entrant {
        let planner = (name != SCENARIO_TEAM).then(|| {
            let mut t = toml::Table::new();
            t.insert("kind".into(), toml::Value::String(name.to_string()));
            t
        });
        Entrant {
            name: name.to_string(),
            planner,
        }
    }

    /// A planner table read from a file (`kind` and its keys), named after the file's stem.
    pub fn from_file(path: &Path) -> Result<Entrant, CampaignError> {
        let text = plumetrace_env::input::read_text(path, plumetrace_env::input::MAX_TEXT_BYTES)
            .map_err(|e| CampaignError::io(path, e))?;
        let mut table: toml::Table =
            text.parse()
                .map_err(|e: toml::de::Error| CampaignError::Invalid {
                    line: None,
                    file: path.display().to_string(),
                    key: String::new(),
                    message: e.to_string(),
                })?;
        // A file holding a `[planner]` table (a scenario's section) is taken as that table.
        if let Some(toml::Value::Table(inner)) = table.remove("planner") {
            table = inner;
        }
        let given = kind_of(&table);
        if given
            .and_then(plumetrace_mission::PlannerKind::from_name)
            .is_none()
        {
            let known: Vec<&str> = plumetrace_mission::PlannerKind::ALL
                .iter()
                .map(|k| k.name())
                .collect();
            let line = ["kind", "planner.kind"]
                .iter()
                .find_map(|k| plumetrace_scenario::locate::line_of_key(&text, k));
            return Err(CampaignError::Invalid {
                line,
                file: path.display().to_string(),
                key: "kind".into(),
                message: match given {
                    None => format!(
                        "missing: a planner file names its planner (kind = \"amp\"; one of {})",
                        known.join(", ")
                    ),
                    Some(g) => format!(
                        "'{g}' is not a planner{}; planners: {}",
                        hint(&plumetrace_core::closest(g, &known).map(str::to_string)),
                        known.join(", ")
                    ),
                },
            });
        }
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().trim_end_matches(".planner").to_string())
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "planner-file".into());
        Ok(Entrant {
            name,
            planner: Some(table),
        })
    }
}

/// The `kind` a planner table names.
fn kind_of(t: &toml::Table) -> Option<&str> {
    t.get("kind").and_then(toml::Value::as_str)
}

/// The campaign of one task: its test seed, `seeds` test seeds, one configuration per entrant,
/// its success radius. The task's family file and the campaign file are written under
/// `dir/tasks/` (the campaign reads its scenario from there, and a user can read what was
/// flown); the campaign is checked (every group builds) but not refused for its test seeds.
pub fn task_campaign(
    set: &TaskSet,
    task: &Task,
    entrants: &[Entrant],
    seeds: u64,
    dir: &Path,
) -> Result<Campaign, BenchmarkError> {
    if !(1..=task.test_seeds).contains(&seeds) {
        return Err(BenchmarkError::TooManySeeds {
            task: task.name.clone(),
            given: seeds,
            max: task.test_seeds,
        });
    }
    let tasks_dir = dir.join("tasks");
    std::fs::create_dir_all(&tasks_dir).map_err(|e| CampaignError::io(&tasks_dir, e))?;
    let scenario = match family_text(&task.scenario) {
        Some(text) => {
            let file_name = Path::new(&task.scenario)
                .file_name()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_else(|| format!("{}.family.toml", task.name));
            write_if_changed(&tasks_dir.join(&file_name), text)?;
            file_name
        }
        None => task.scenario.clone(),
    };
    let file = CampaignFile {
        name: format!("benchmark-{}-{}", set.version, task.name),
        description: format!(
            "benchmark task set {}, task '{}': {}",
            set.version, task.name, task.description
        ),
        seed: task.test_seed,
        seeds,
        scenarios: vec![scenario],
        success_radius_m: Some(task.success_radius_m),
        configs: entrants
            .iter()
            .map(|e| ConfigFile {
                name: e.name.clone(),
                planner: e.planner.clone(),
                set: task.set.clone(),
            })
            .collect(),
        sweep: toml::Table::new(),
    };
    let text = format!(
        "# Written by `plumetrace benchmark`: task '{}' of task set {} on its test seeds.\n{}",
        task.name,
        set.version,
        toml::to_string(&file).map_err(|e| CampaignError::io(&tasks_dir, e))?
    );
    let path = tasks_dir.join(format!("{}.campaign.toml", task.name));
    write_if_changed(&path, &text)?;
    let mut c = Campaign::resolve(file, &path, text, true)?;
    c.check_groups()?;
    check_time_limit(set, &c, task)?;
    Ok(c)
}

/// The task's stated time limit is its scenario's.
fn check_time_limit(set: &TaskSet, c: &Campaign, task: &Task) -> Result<(), BenchmarkError> {
    let t = c.group_table(0, 0, 0, 0)?;
    let limit = t
        .get("mission")
        .and_then(|m| m.get("time_limit_s"))
        .and_then(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)));
    if limit != Some(task.time_limit_s) {
        return Err(BenchmarkError::TaskSet {
            file: set.file.clone(),
            key: format!("task '{}'.time_limit_s", task.name),
            message: format!(
                "says {} s, but its scenario's time limit is {}",
                task.time_limit_s,
                limit.map_or("not set".into(), |l| format!("{l} s"))
            ),
        });
    }
    Ok(())
}

fn write_if_changed(path: &Path, text: &str) -> Result<(), CampaignError> {
    if std::fs::read_to_string(path).is_ok_and(|t| t == text) {
        return Ok(());
    }
    plumetrace_mission::output::write_atomic(path, text.as_bytes())
        .map_err(|e| CampaignError::io(path, e))
}

/// The output directory of a task's campaign under a benchmark directory.
pub fn task_dir(dir: &Path, task: &Task) -> PathBuf {
    dir.join(&task.name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_task_set_reads_and_its_seed_sets_are_disjoint() {
        let set = TaskSet::builtin().unwrap();
        assert_eq!(set.version, VERSION);
        assert_eq!(set.tasks.len(), 6);
        for (i, t) in set.tasks.iter().enumerate() {
            assert_ne!(t.test_seed, t.tuning_seed, "{}", t.name);
            let tuning: HashSet<u64> = (0..t.tuning_seeds)
                .map(|k| plumetrace_env::derive_seed(t.tuning_seed, k))
                .collect();
            assert!(set.test_sets[i].is_disjoint(&tuning), "{}", t.name);
            assert_eq!(set.test_sets[i].len() as u64, t.test_seeds, "{}", t.name);
        }
    }

    #[test]
    fn every_registered_planner_enters_some_task() {
        let set = TaskSet::builtin().unwrap();
        let names = set.planner_names();
        for k in plumetrace_mission::PlannerKind::ALL {
            // The formation's leaders and follower enter together, as the scenario's team.
            let entered = names.iter().any(|n| n == k.name())
                || (k.name().starts_with("formation_") && names.iter().any(|n| n == SCENARIO_TEAM));
            assert!(entered, "{} enters no task", k.name());
        }
    }

    #[test]
    fn a_draw_reaches_test_seeds_only_with_the_test_seed() {
        let set = TaskSet::builtin().unwrap();
        let coastal = set.task("coastal").unwrap();
        let hit = set.test_seed_use("coastal", coastal.test_seed, 1).unwrap();
        assert_eq!(hit.task, "coastal");
        assert_eq!(hit.seed_index, 0);
        assert_eq!(
            set.test_seed_use("coastal", coastal.tuning_seed, 1000),
            None
        );
        // Another scenario on the same seed is not the task's.
        assert_eq!(set.test_seed_use("duck-like", coastal.test_seed, 10), None);
        assert!(
            set.test_seed_use("li-zhang-kelp", set.task("kelp").unwrap().test_seed, 3)
                .is_some()
        );
    }

    #[test]
    fn task_set_errors_name_the_key() {
        let good = TASKS_V1;
        let cases = [
            (
                good.replacen("\nseeds = 100\n", "\nseeds = 300\n", 1),
                "tasks[0].seeds: must be 1 to test_seeds (200), got 300",
            ),
            (
                good.replacen("tuning_seed = 3201", "tuning_seed = 3202", 1),
                "tasks[0].tuning_seed: tuning seed index 0 is one of the task's test seeds",
            ),
            (
                good.replacen("\"moth\"", "\"mothh\"", 1),
                "tasks[0].planners[3]: 'mothh' is not a planner (did you mean 'moth'?)",
            ),
            (
                good.replacen("li-zhang-kelp", "li-zhang-kelpp", 1),
                "tasks[2].scenario: 'li-zhang-kelpp' is neither a shipped family file nor a preset (did you mean 'li-zhang-kelp'?)",
            ),
            (
                good.replacen("success_radius_m = 50.0", "success_radius_m = -1.0", 1),
                "tasks[0].success_radius_m: must be a positive number, got -1",
            ),
            (
                good.replacen("vehicles =", "vehicle =", 1),
                "tasks[0].vehicle: unknown field `vehicle`; did you mean `vehicles`? (line #)",
            ),
        ];
        let vehicles_line = good[..good.find("vehicles =").unwrap()]
            .matches('\n')
            .count()
            + 1;
        for (text, want) in cases {
            let want = want.replace('#', &vehicles_line.to_string());
            let e = TaskSet::parse(&text, "t.toml").unwrap_err().to_string();
            assert!(e.starts_with("t.toml: "), "{e}");
            assert!(e.contains(&want), "{e}\nwant: {want}");
        }
    }

    #[test]
    fn every_task_builds_with_every_planner_and_states_its_time_limit() {
        let set = TaskSet::builtin().unwrap();
        let dir = tempfile::tempdir().unwrap();
        for t in &set.tasks {
            let entrants: Vec<Entrant> = t.planners.iter().map(|p| Entrant::named(p)).collect();
            let c = task_campaign(&set, t, &entrants, 3, dir.path()).unwrap();
            assert_eq!(c.file.seed, t.test_seed);
            assert_eq!(c.configs.len(), t.planners.len());
            // The benchmark's own campaign is the one `campaign` refuses without --test-seeds.
            assert!(c.refuse_test_seeds().is_err(), "{}", t.name);
        }
        let mut wrong = set.clone();
        wrong.tasks[0].time_limit_s = 3600.0;
        let e = task_campaign(
            &wrong,
            &wrong.tasks[0],
            &[Entrant::named("amp")],
            1,
            dir.path(),
        )
        .unwrap_err()
        .to_string();
        assert_eq!(
            e,
            "benchmarks/tasks-v1.toml: task 'coastal'.time_limit_s: says 3600 s, but its \
             scenario's time limit is 7200 s"
        );
    }

    #[test]
    fn unknown_tasks_are_named_with_the_nearest() {
        let set = TaskSet::builtin().unwrap();
        let e = set.task("coastel").unwrap_err().to_string();
        assert_eq!(
            e,
            "no task 'coastel' in task set v1 (did you mean 'coastal'?); tasks: coastal, faults, \
             kelp, duck-like, multi-source, freshwater-team"
        );
    }
}
