//! Flying a benchmark: which tasks each entrant enters ([`plan`]), then every task a campaign
//! on its test seeds into one directory (parallel and resumable, or one run at a time with
//! planners from outside the registry), then the leaderboard. The command line and the Python
//! package both call [`run_benchmark`], so the two give the same numbers.

use super::board::{Board, task_board};
use super::{BenchmarkError, Entrant, SCENARIO_TEAM, Task, TaskSet, task_campaign, task_dir};
use crate::execute::{CAMPAIGN_COPY, CampaignReport, ExternalPlanners, RunOptions, Share};
use crate::spec::CampaignFile;
use std::path::Path;
use std::time::Instant;

/// The leaderboard's file names in a benchmark directory.
pub const LEADERBOARD_MD: &str = "leaderboard.md";
/// See [`LEADERBOARD_MD`].
pub const LEADERBOARD_JSON: &str = "leaderboard.json";

/// An entrant as asked for, with the tasks it enters.
#[derive(Debug, Clone, PartialEq)]
pub struct Given {
    /// The entrant.
    pub entrant: Entrant,
    /// The name it enters tasks under (a task's `planners` names it); `None`: a planner from
    /// outside the registry, which flies the first vehicle of every task a registered planner
    /// enters (every task but the team's).
    pub enters_as: Option<String>,
}

impl Given {
    /// A planner of the task set by name (a registered kind, or `formation`), or an error
    /// with the nearest name.
    pub fn named(set: &TaskSet, name: &str) -> Result<Given, BenchmarkError> {
        let name = name.trim();
        let known = set.planner_names();
        if !known.iter().any(|k| k == name) {
            let names: Vec<&str> = known.iter().map(String::as_str).collect();
            return Err(BenchmarkError::UnknownPlanner {
                name: name.to_string(),
                suggestion: plumetrace_core::closest(name, &names).map(str::to_string),
                known: names.join(", "),
            });
        }
        Ok(Given {
            entrant: Entrant::named(name),
            enters_as: Some(name.to_string()),
        })
    }

    /// A planner table from a file; it enters the tasks its kind enters.
    pub fn file(entrant: Entrant) -> Given {
        let kind = entrant
            .planner
            .as_ref()
            .and_then(super::kind_of)
            .unwrap_or("")
            .to_string();
        Given {
            entrant,
            enters_as: Some(kind),
        }
    }

    /// A planner from outside the registry called `name` (see [`ExternalPlanners`]); its
    /// configurations keep the scenario's planner table, which the planner replaces.
    pub fn external(name: &str) -> Given {
        Given {
            entrant: Entrant {
                name: name.to_string(),
                planner: None,
            },
            enters_as: None,
        }
    }

    fn enters(&self, t: &Task) -> bool {
        match &self.enters_as {
            Some(n) => t.planners.contains(n),
            None => t.planners.iter().any(|p| p != SCENARIO_TEAM),
        }
    }
}

/// The tasks to fly and each one's entrants, with notes on tasks left out.
#[derive(Debug, Clone)]
pub struct Plan<'a> {
    /// Each task flown, in the order asked (the set's without names), with its entrants.
    pub tasks: Vec<(&'a Task, Vec<Entrant>)>,
    /// Tasks left out because no entrant enters them (only without task names).
    pub notes: Vec<String>,
}

/// The tasks named (every task without names) and who flies each: the given entrants where
/// they enter it, or every planner of the task when none is given. An entrant that does not
/// enter a task named is an error; without names, that task is left out (with a note).
pub fn plan<'a>(
    set: &'a TaskSet,
    names: &[String],
    given: &[Given],
) -> Result<Plan<'a>, BenchmarkError> {
    let mut tasks: Vec<&Task> = Vec::new();
    for name in names {
        let t = set.task(name.trim())?;
        if !tasks.iter().any(|u| u.name == t.name) {
            tasks.push(t);
        }
    }
    let explicit = !tasks.is_empty();
    if !explicit {
        tasks = set.tasks.iter().collect();
    }
    let mut plan = Plan {
        tasks: Vec::new(),
        notes: Vec::new(),
    };
    for t in tasks {
        let entrants: Vec<Entrant> = if given.is_empty() {
            t.planners.iter().map(|p| Entrant::named(p)).collect()
        } else {
            let mut v = Vec::new();
            for g in given {
                if g.enters(t) {
                    v.push(g.entrant.clone());
                } else if explicit {
                    let team = g.enters_as.is_none();
                    return Err(BenchmarkError::NotEntered {
                        task: t.name.clone(),
                        planner: g.entrant.name.clone(),
                        planners: format!(
                            "{}{}",
                            t.planners.join(", "),
                            if team {
                                " (a team: a planner from outside the registry flies one vehicle)"
                            } else {
                                ""
                            }
                        ),
                    });
                }
            }
            v
        };
        if entrants.is_empty() {
            plan.notes.push(format!(
                "task '{}' left out: it is flown by {} only",
                t.name,
                t.planners.join(", ")
            ));
            continue;
        }
        plan.tasks.push((t, entrants));
    }
    if plan.tasks.is_empty() {
        let names: Vec<&str> = given.iter().map(|g| g.entrant.name.as_str()).collect();
        return Err(BenchmarkError::NothingToFly {
            version: set.version.clone(),
            planners: names.join(", "),
        });
    }
    Ok(plan)
}

/// How to fly a benchmark.
#[derive(Debug, Clone, Copy, Default)]
pub struct BenchmarkOptions {
    /// Test seeds per task, the first ones (None: each task's `seeds`).
    pub seeds_per_task: Option<u64>,
    /// Worker threads (None: one per core). Results do not depend on it.
    pub jobs: Option<usize>,
}

/// One task flown.
#[derive(Debug, Clone)]
pub struct TaskDone<'a> {
    /// The task.
    pub task: &'a Task,
    /// Its entrants.
    pub planners: usize,
    /// Test seeds flown per entrant.
    pub seeds: u64,
    /// What its campaign did.
    pub report: CampaignReport,
    /// Wall time of this call's runs, s.
    pub wall_s: f64,
}

/// What a caller hears while a benchmark flies (each method does nothing by default).
pub trait Watch: Sync {
    /// A task starts: `runs` runs in its list.
    fn task_started(&self, _task: &Task, _runs: u64) {}
    /// `done` of the task's `total` runs still to fly are done.
    fn run_done(&self, _done: u64, _total: u64) {}
    /// A task is done.
    fn task_done(&self, _done: &TaskDone<'_>) {}
}

/// A [`Watch`] that hears nothing.
pub struct Quiet;

impl Watch for Quiet {}

/// Flies (or resumes) every task of `plan` into `out` (a campaign directory per task, the
/// tasks' files under `tasks/`) and writes the leaderboard there (`leaderboard.md`,
/// `leaderboard.json`); returns it. `external` flies the entrants it names.
pub fn run_benchmark(
    set: &TaskSet,
    plan: &Plan<'_>,
    out: &Path,
    opts: BenchmarkOptions,
    external: Option<&dyn ExternalPlanners>,
    watch: &dyn Watch,
) -> Result<Board, BenchmarkError> {
    refuse_foreign(out)?;
    for (task, entrants) in &plan.tasks {
        refuse_other_entrants(out, task, entrants)?;
    }
    let mut boards = Vec::new();
    for (task, entrants) in &plan.tasks {
        let in_task = |e: BenchmarkError| BenchmarkError::InTask {
            task: task.name.clone(),
            error: Box::new(e),
        };
        let seeds = opts.seeds_per_task.unwrap_or(task.seeds);
        let c = task_campaign(set, task, entrants, seeds, out).map_err(in_task)?;
        let dir = task_dir(out, task);
        let t0 = Instant::now();
        watch.task_started(task, c.runs().len() as u64);
        let report = crate::execute::run_campaign_with(
            &c,
            &dir,
            RunOptions {
                jobs: opts.jobs,
                shard: None,
                share: Share::Plume,
            },
            external,
            &|done, total| watch.run_done(done, total),
        )
        .map_err(|e| in_task(e.into()))?;
        watch.task_done(&TaskDone {
            task,
            planners: entrants.len(),
            seeds,
            report,
            wall_s: t0.elapsed().as_secs_f64(),
        });
        boards.push(task_board(&c, task, &dir).map_err(|e| in_task(e.into()))?);
    }
    let board = Board {
        task_set: set.version.clone(),
        tasks: boards,
    };
    for (name, text) in [
        (LEADERBOARD_MD, board.to_markdown(set)),
        (LEADERBOARD_JSON, board.to_json()),
    ] {
        let p = out.join(name);
        plumetrace_mission::output::write_atomic(&p, text.as_bytes())
            .map_err(|e| crate::CampaignError::io(&p, e))?;
    }
    Ok(board)
}

/// A directory that holds files but no benchmark is refused (results never overwrite other
/// files).
fn refuse_foreign(out: &Path) -> Result<(), BenchmarkError> {
    let foreign = |what: String| BenchmarkError::NotABenchmark {
        dir: out.display().to_string(),
        what,
    };
    if out.exists() && !out.is_dir() {
        return Err(foreign("is a file, not a directory".into()));
    }
    if out.is_dir() && !out.join("tasks").is_dir() {
        let first = std::fs::read_dir(out)
            .map_err(|e| crate::CampaignError::io(out, e))?
            .flatten()
            .next();
        if let Some(f) = first {
            return Err(foreign(format!(
                "holds files ({} among them) but no benchmark (no tasks/)",
                f.file_name().to_string_lossy()
            )));
        }
    }
    Ok(())
}

/// A task already flown in `out` by other entrants is refused before anything is written (its
/// campaign would be refused too, but in a campaign's words).
fn refuse_other_entrants(
    out: &Path,
    task: &Task,
    entrants: &[Entrant],
) -> Result<(), BenchmarkError> {
    let copy = task_dir(out, task).join(CAMPAIGN_COPY);
    let Ok(text) = std::fs::read_to_string(&copy) else {
        return Ok(());
    };
    let Ok(file) = toml::from_str::<CampaignFile>(&text) else {
        return Ok(());
    };
    let had: Vec<&str> = file.configs.iter().map(|c| c.name.as_str()).collect();
    let now: Vec<&str> = entrants.iter().map(|e| e.name.as_str()).collect();
    if had != now {
        return Err(BenchmarkError::OtherEntrants {
            dir: out.display().to_string(),
            task: task.name.clone(),
            had: had.join(", "),
            now: now.join(", "),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(p: &Plan<'_>) -> Vec<(String, Vec<String>)> {
        p.tasks
            .iter()
            .map(|(t, e)| (t.name.clone(), e.iter().map(|e| e.name.clone()).collect()))
            .collect()
    }

    #[test]
    fn an_external_planner_enters_every_task_but_the_team() {
        let set = TaskSet::builtin().unwrap();
        let p = plan(&set, &[], &[Given::external("mine")]).unwrap();
        let got = names(&p);
        assert_eq!(got.len(), 5);
        assert!(
            got.iter()
                .all(|(t, e)| t != "freshwater-team" && e == &["mine"])
        );
        assert_eq!(
            p.notes,
            ["task 'freshwater-team' left out: it is flown by formation only"]
        );
        let e = plan(
            &set,
            &["freshwater-team".into()],
            &[Given::external("mine")],
        )
        .unwrap_err()
        .to_string();
        assert_eq!(
            e,
            "task 'freshwater-team' is not flown by 'mine': its planners are formation (a team: \
             a planner from outside the registry flies one vehicle)"
        );
    }

    #[test]
    fn a_named_planner_is_checked_and_enters_its_tasks() {
        let set = TaskSet::builtin().unwrap();
        let e = Given::named(&set, "amq").unwrap_err().to_string();
        assert_eq!(
            e,
            "no planner 'amq' (did you mean 'amp'?); planners: amp, infotaxis, lawnmower, moth, \
             surge_cast, formation"
        );
        let p = plan(
            &set,
            &["kelp".into()],
            &[Given::named(&set, "moth").unwrap()],
        )
        .unwrap();
        assert_eq!(names(&p), [("kelp".to_string(), vec!["moth".to_string()])]);
    }

    #[test]
    fn a_directory_of_other_entrants_is_refused_before_anything_is_written() {
        let set = TaskSet::builtin().unwrap();
        let dir = tempfile::tempdir().unwrap();
        let task = set.task("coastal").unwrap();
        let d = task_dir(dir.path(), task);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::create_dir_all(dir.path().join("tasks")).unwrap();
        let c = task_campaign(&set, task, &[Entrant::named("amp")], 1, dir.path()).unwrap();
        std::fs::write(d.join(CAMPAIGN_COPY), &c.text).unwrap();
        let before =
            std::fs::read_to_string(dir.path().join("tasks/coastal.campaign.toml")).unwrap();
        let p = plan(
            &set,
            &["coastal".into()],
            &[Given::named(&set, "moth").unwrap()],
        )
        .unwrap();
        let e = run_benchmark(
            &set,
            &p,
            dir.path(),
            BenchmarkOptions::default(),
            None,
            &Quiet,
        )
        .unwrap_err()
        .to_string();
        assert_eq!(
            e,
            format!(
                "{}: holds task 'coastal' flown by amp; this call enters moth: give another \
                 output directory (or the same planners, to resume)",
                dir.path().display()
            )
        );
        let after =
            std::fs::read_to_string(dir.path().join("tasks/coastal.campaign.toml")).unwrap();
        assert_eq!(before, after);
    }

    /// Records what each run's planner was made for; its planner stops at once.
    struct Recorder {
        seen: std::sync::Mutex<Vec<(String, u64)>>,
    }

    struct Stop;

    impl plumetrace_core::Planner for Stop {
        fn decide(&mut self, s: &plumetrace_core::SensorSnapshot) -> plumetrace_core::Decision {
            plumetrace_core::Decision::new(
                plumetrace_core::Command {
                    heading: s.nav.heading,
                    speed_mps: 0.0,
                    vertical: plumetrace_core::VerticalCommand::Altitude(3.0),
                },
                plumetrace_core::PlanStatus::Finished,
            )
        }
    }

    impl ExternalPlanners for Recorder {
        fn flies(&self, config: &str) -> bool {
            config == "mine"
        }
        fn make(
            &self,
            _config: &str,
            scenario: &str,
            seed: u64,
        ) -> Result<Box<dyn plumetrace_core::Planner>, crate::ExternalError> {
            self.seen.lock().unwrap().push((scenario.to_string(), seed));
            Ok(Box::new(Stop))
        }
        fn check(&self) -> Result<(), crate::ExternalError> {
            Ok(())
        }
    }

    #[test]
    fn an_external_planner_is_made_for_each_test_seed_with_the_tasks_family_file() {
        let set = TaskSet::builtin().unwrap();
        let dir = tempfile::tempdir().unwrap();
        let p = plan(
            &set,
            &["coastal".into(), "kelp".into()],
            &[Given::external("mine")],
        )
        .unwrap();
        let rec = Recorder {
            seen: std::sync::Mutex::new(Vec::new()),
        };
        let opts = BenchmarkOptions {
            seeds_per_task: Some(2),
            jobs: Some(1),
        };
        let board = run_benchmark(&set, &p, dir.path(), opts, Some(&rec), &Quiet).unwrap();
        let seen = rec.seen.into_inner().unwrap();
        let family = dir.path().join("tasks").join("coastal.family.toml");
        let d = plumetrace_env::derive_seed;
        assert_eq!(
            seen,
            [
                (family.display().to_string(), d(3202, 0)),
                (family.display().to_string(), d(3202, 1)),
                ("li-zhang-kelp".to_string(), d(3222, 0)),
                ("li-zhang-kelp".to_string(), d(3222, 1)),
            ]
        );
        assert_eq!(board.tasks.len(), 2);
        assert_eq!(board.tasks[0].entries[0].planner, "mine");
        assert_eq!(board.tasks[0].entries[0].runs, 2);
    }
}
