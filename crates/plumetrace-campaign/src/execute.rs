//! Running a campaign: parallel over runs, appending each result as it finishes, resuming from
//! what a directory already holds, and writing the summary, charts and example tracks at the end.

use crate::error::{CampaignError, RunError};
use crate::example::{EXAMPLES_DIR, ExampleRun};
use crate::runs::{Appender, RUNS_FILE, RunRow, row_key};
use crate::spec::{Campaign, RunKey, Shard};
use plumetrace_core::Planner;
use plumetrace_env::Environment;
use plumetrace_mission::{Mission, MissionOptions, MissionRun, MissionSetup, fly_shared};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// The name of the file that ties a directory to its campaign.
pub const META_FILE: &str = "campaign.json";
/// The copy of the campaign file kept in the directory (for `merge`).
pub const CAMPAIGN_COPY: &str = "campaign.toml";

/// What a directory records about the campaign it holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Meta {
    /// Campaign name.
    pub name: String,
    /// [`Campaign::fingerprint`].
    pub fingerprint: String,
    /// Seeds per group of the latest call (`--seeds` may change it; results stay valid).
    pub seeds: u64,
}

/// What runs of one seed share where their environments are built from the same settings
/// ([`share_groups`]). The results are the same bits whatever is shared; sharing saves CPU.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Share {
    /// One world: the plume is spun up once and stepped once per step for all the runs of a
    /// group, each run's vehicles flying against it with their own random streams.
    #[default]
    Plume,
    /// The spin-up only: the first run of a group develops the plume, the others start from a
    /// copy and step their own.
    SpinUp,
    /// Nothing: every run spins up and steps its own plume.
    Nothing,
}

/// How to run.
#[derive(Debug, Clone, Copy, Default)]
pub struct RunOptions {
    /// Worker threads (None: one per core).
    pub jobs: Option<usize>,
    /// Only this shard's runs.
    pub shard: Option<Shard>,
    /// What runs of the same seed share (the results are the same bits either way).
    pub share: Share,
}

/// What a campaign call did.
#[derive(Debug, Clone, Default)]
pub struct CampaignReport {
    /// Runs in this shard's list.
    pub planned: u64,
    /// Found already recorded and skipped.
    pub skipped: u64,
    /// Run now.
    pub ran: u64,
    /// Of those, runs that failed (outcome `error`).
    pub failed: u64,
    /// A partial row left by a killed process was cut off.
    pub cut_partial_line: bool,
}

/// Planners from outside the registry (written in Python, say), flown by the configurations
/// they name: every run of such a configuration gets a fresh planner for its first vehicle,
/// made before its first step, in place of the configuration's planner table. A campaign with
/// them runs one run at a time, on the calling thread, and shares nothing between runs (the
/// results are the same bits as sharing's: see [`Share`]).
pub trait ExternalPlanners {
    /// Whether the configuration called `config` is flown by one of them.
    fn flies(&self, config: &str) -> bool;
    /// A fresh planner for a run of `config` on `scenario` (the campaign's scenario: its file's
    /// path, or a preset's name) with run seed `seed`.
    fn make(
        &self,
        config: &str,
        scenario: &str,
        seed: u64,
    ) -> Result<Box<dyn Planner>, ExternalError>;
    /// Asked after each of their runs: an error (the planner failed during the run) stops the
    /// campaign, and that run is not recorded (a later call flies it again).
    fn check(&self) -> Result<(), ExternalError>;
}

/// Why a planner from outside the registry could not be made or failed in a run.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct ExternalError {
    /// What went wrong, in the planner's own words.
    pub message: String,
}

/// Checks or records that `out` belongs to this campaign.
pub fn claim_dir(c: &Campaign, out: &Path) -> Result<(), CampaignError> {
    std::fs::create_dir_all(out).map_err(|e| CampaignError::io(out, e))?;
    let meta_path = out.join(META_FILE);
    let meta = Meta {
        name: c.file.name.clone(),
        fingerprint: c.fingerprint(),
        seeds: c.file.seeds,
    };
    if !meta_path.exists() {
        refuse_foreign(out)?;
    }
    if meta_path.exists() {
        let text =
            std::fs::read_to_string(&meta_path).map_err(|e| CampaignError::io(&meta_path, e))?;
        let old: Meta = serde_json::from_str(&text).map_err(|e| CampaignError::Results {
            path: meta_path.display().to_string(),
            line: Some(e.line() as u64),
            message: e.to_string(),
        })?;
        if old.fingerprint != meta.fingerprint {
            return Err(CampaignError::Results {
                path: meta_path.display().to_string(),
                line: None,
                message: format!(
                    "{} holds results of a different campaign ('{}', fingerprint {}; this one is \
                     '{}', {}): the campaign file, one of its scenarios or a planner's defaults \
                     changed. Use a new --out directory.",
                    out.display(),
                    old.name,
                    old.fingerprint,
                    meta.name,
                    meta.fingerprint
                ),
            });
        }
    }
    write_meta(out, &meta, &c.text)
}

/// Refuses a directory that holds files but no campaign: results are never written over someone
/// else's files.
pub fn refuse_foreign(out: &Path) -> Result<(), CampaignError> {
    let entries = std::fs::read_dir(out).map_err(|e| CampaignError::io(out, e))?;
    if let Some(first) = entries.flatten().next() {
        return Err(CampaignError::Results {
            path: out.display().to_string(),
            line: None,
            message: format!(
                "holds files ({} among them) but no {META_FILE}: it is not a campaign directory; \
                 use a new or empty --out directory",
                first.file_name().to_string_lossy()
            ),
        });
    }
    Ok(())
}

/// Writes `campaign.json` and the copy of the campaign file into `out`.
pub fn write_meta(out: &Path, meta: &Meta, campaign_text: &str) -> Result<(), CampaignError> {
    let json = serde_json::to_string_pretty(meta).unwrap_or_default();
    for (name, bytes) in [
        (META_FILE, json.as_bytes()),
        (CAMPAIGN_COPY, campaign_text.as_bytes()),
    ] {
        let p = out.join(name);
        plumetrace_mission::output::write_atomic(&p, bytes)
            .map_err(|e| CampaignError::io(&p, e))?;
    }
    Ok(())
}

/// Runs (the rest of) a campaign into `out`, calling `progress(done, total)` after each run, then
/// writes the sorted `runs.csv`, summaries and charts.
pub fn run_campaign(
    c: &Campaign,
    out: &Path,
    opts: RunOptions,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<CampaignReport, CampaignError> {
    run_campaign_with(c, out, opts, None, progress)
}

/// [`run_campaign`], with planners from outside the registry flying the configurations they
/// name (one run at a time; `opts.jobs` and `opts.share` then have no effect).
pub fn run_campaign_with(
    c: &Campaign,
    out: &Path,
    opts: RunOptions,
    external: Option<&dyn ExternalPlanners>,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<CampaignReport, CampaignError> {
    claim_dir(c, out)?;
    let runs_path = out.join(RUNS_FILE);
    let (appender, existing) = Appender::open(&runs_path)?;
    let mut done = BTreeSet::new();
    for row in &existing.rows {
        done.insert(row_key(c, row, &runs_path)?);
    }
    let planned = c.shard_runs(opts.shard);
    let todo: Vec<RunKey> = planned
        .iter()
        .filter(|k| !done.contains(k))
        .copied()
        .collect();
    let mut report = CampaignReport {
        planned: planned.len() as u64,
        skipped: (planned.len() - todo.len()) as u64,
        cut_partial_line: existing.cut_partial_line,
        ..CampaignReport::default()
    };
    std::fs::create_dir_all(out.join(EXAMPLES_DIR))
        .map_err(|e| CampaignError::io(&out.join(EXAMPLES_DIR), e))?;

    let appender = Mutex::new(appender);
    let first_error: Mutex<Option<CampaignError>> = Mutex::new(None);
    let stop = AtomicBool::new(false);
    let finished = AtomicU64::new(0);
    let failed = AtomicU64::new(0);
    let total = todo.len() as u64;
    let groups = match opts.share {
        Share::Nothing => todo.iter().map(|k| vec![*k]).collect(),
        Share::Plume | Share::SpinUp => share_groups(c, &todo),
    };
    // Each row is appended the moment its run ends, so an interrupted group keeps the rows of
    // the runs that ended before it.
    let emit = |row: RunRow| {
        if stop.load(Ordering::Relaxed) {
            return;
        }
        if row.outcome == crate::runs::RunOutcome::ERROR {
            failed.fetch_add(1, Ordering::Relaxed);
        }
        let written = appender
            .lock()
            .map_err(|_| CampaignError::io(&runs_path, "a worker panicked while writing"))
            .and_then(|mut a| a.append(&row));
        if let Err(e) = written {
            stop.store(true, Ordering::Relaxed);
            if let Ok(mut slot) = first_error.lock() {
                slot.get_or_insert(e);
            }
            return;
        }
        progress(finished.fetch_add(1, Ordering::Relaxed) + 1, total);
    };
    let work = || {
        groups.par_iter().for_each(|group| {
            if stop.load(Ordering::Relaxed) {
                return;
            }
            match opts.share {
                Share::Plume if group.len() > 1 => run_shared(c, group, out, &mut |r| emit(r)),
                _ => {
                    let mut shared: Option<Environment> = None;
                    for (i, key) in group.iter().enumerate() {
                        if stop.load(Ordering::Relaxed) {
                            return;
                        }
                        let more = i + 1 < group.len();
                        emit(run_one(c, key, out, &mut shared, more, None));
                    }
                }
            }
        });
    };
    if let Some(ext) = external {
        if let Err(e) = fly_in_turn(c, &todo, out, ext, &|| stop.load(Ordering::Relaxed), &emit)
            && let Ok(mut slot) = first_error.lock()
        {
            slot.get_or_insert(e);
        }
    } else {
        run_in_pool(opts.jobs, out, work)?;
    }
    if let Some(e) = first_error.into_inner().ok().flatten() {
        return Err(e);
    }
    report.ran = finished.load(Ordering::Relaxed);
    report.failed = failed.load(Ordering::Relaxed);
    drop(appender);
    crate::finish::finish_dir(c, out)?;
    Ok(report)
}

/// Runs `work` on `jobs` threads (None: the global pool's).
fn run_in_pool(
    jobs: Option<usize>,
    out: &Path,
    work: impl FnOnce() + Send,
) -> Result<(), CampaignError> {
    match jobs {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n.max(1))
            .build()
            .map_err(|e| CampaignError::io(out, e))?
            .install(work),
        None => work(),
    }
    Ok(())
}

/// Flies `todo` one run at a time on this thread, the configurations of `ext` with its
/// planners. A planner that cannot be made, or that failed during its run, stops here with the
/// run unrecorded.
fn fly_in_turn(
    c: &Campaign,
    todo: &[RunKey],
    out: &Path,
    ext: &dyn ExternalPlanners,
    stopped: &dyn Fn() -> bool,
    emit: &dyn Fn(RunRow),
) -> Result<(), CampaignError> {
    for key in todo {
        if stopped() {
            break;
        }
        let config = &c.configs[key.config].name;
        if !ext.flies(config) {
            emit(run_one(c, key, out, &mut None, false, None));
            continue;
        }
        let seed = c.run_seed(key);
        let failed = |e: ExternalError| CampaignError::External {
            config: config.clone(),
            seed,
            message: e.message,
        };
        // A family's file (not its base scenario's): the planner builds the run's site from it.
        let entry = &c.scenarios[key.scenario];
        let scenario = match (&entry.family, &entry.origin) {
            (Some(f), _) => f.path.display().to_string(),
            (None, plumetrace_scenario::Origin::File(p)) => p.display().to_string(),
            (None, plumetrace_scenario::Origin::Preset(n)) => n.clone(),
        };
        let planner = ext.make(config, &scenario, seed).map_err(failed)?;
        let row = run_one(c, key, out, &mut None, false, Some(planner));
        ext.check().map_err(failed)?;
        emit(row);
    }
    Ok(())
}

/// The runs that can share one environment (its spin-up, or the whole world): runs of the same
/// scenario and seed whose scenario tables differ only in what the environment is not built
/// from (planner tables, outputs, message channels, the mission's time limit and prior flow).
/// Everything else (domain, flow, plume, sources, obstacles, kelp, vehicles, whose start
/// positions keep kelp clear, the op-area and subregions, which place the plume's downflow
/// sink, the simulation, environment and spin-up steps) must be equal, so
/// the environment each run sees is, step for step, the one it would build alone. A time limit
/// may differ: a run that ends stops looking, and the environment steps on for the others. Groups
/// come in run order.
pub fn share_groups(c: &Campaign, todo: &[RunKey]) -> Vec<Vec<RunKey>> {
    let mut groups: BTreeMap<(usize, u64, String), Vec<RunKey>> = BTreeMap::new();
    let mut alone = Vec::new();
    for k in todo {
        match c.group_table(k.scenario, k.config, k.point, k.seed_index) {
            Ok(t) => groups
                .entry((k.scenario, k.seed_index, env_fingerprint(t)))
                .or_default()
                .push(*k),
            // A table that cannot be made fails in its run, alone.
            Err(_) => alone.push(vec![*k]),
        }
    }
    let mut out: Vec<Vec<RunKey>> = groups.into_values().chain(alone).collect();
    out.sort_by_key(|g| g[0]);
    out
}

/// What a scenario table builds its environment from, as text.
fn env_fingerprint(mut t: toml::Table) -> String {
    for k in [
        "name",
        "description",
        "planner",
        "planners",
        "output",
        "comms",
    ] {
        t.remove(k);
    }
    if let Some(toml::Value::Table(m)) = t.get_mut("mission") {
        // The op-area and subregions place the plume's downflow sink (see the scenario's
        // `mission.drop_margin_m`), so they are part of the environment too.
        m.retain(|k, _| {
            [
                "spinup_s",
                "spinup_dt_s",
                "env_dt_s",
                "op_area",
                "subregions",
                "drop_margin_m",
            ]
            .contains(&k)
        });
    }
    toml::to_string(&t).unwrap_or_default()
}

/// Flies one run and makes its row; never panics (a panic inside becomes outcome `error`).
/// `shared` holds a spun-up environment of an earlier run of the same spin-up group, or
/// receives this run's when `more` runs of the group follow. `planner` replaces the first
/// vehicle's.
fn run_one(
    c: &Campaign,
    key: &RunKey,
    out: &Path,
    shared: &mut Option<Environment>,
    more: bool,
    planner: Option<Box<dyn Planner>>,
) -> RunRow {
    let attempt = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let (mut setup, options) = prepare(c, key)?;
        match shared.as_ref().and_then(Environment::try_clone) {
            Some(env) => setup.use_spun_up(env),
            None => {
                setup.spin_up()?;
                if more {
                    *shared = setup.env.try_clone();
                }
            }
        }
        let mut mission = Mission::new(setup, options)?;
        if let Some(p) = planner {
            mission.replace_planner(0, p)?;
        }
        mission.run(&mut |_, _| {})?;
        let run = mission.finish()?;
        row_of(c, key, out, run)
    }));
    row_or_failure(c, key, attempt)
}

/// A run's setup and what it records (everything for the example run at seed index 0).
fn prepare(c: &Campaign, key: &RunKey) -> Result<(MissionSetup, MissionOptions), RunError> {
    let sc = c.build(key)?;
    let example = key.seed_index == 0;
    let options = MissionOptions {
        mean_plume: false,
        trajectory: example,
        plume_frames_every_s: example.then_some(plumetrace_mission::PLUME_FRAME_EVERY_S),
        // Nothing a campaign writes shows the stage times.
        stage_times: false,
    };
    let setup = MissionSetup::new(sc)?;
    Ok((setup, options))
}

/// A finished run's row; the example run's files are written on the way.
fn row_of(c: &Campaign, key: &RunKey, out: &Path, run: MissionRun) -> Result<RunRow, RunError> {
    if let Some(at) = plumetrace_mission::output::first_non_finite(&run.summary) {
        return Err(RunError::NonFinite { at });
    }
    if key.seed_index == 0 {
        let ex = ExampleRun::from_run(c, key, &run);
        ex.write(out).map_err(RunError::Example)?;
        crate::example::write_page(c, key, &run, out)?;
    }
    Ok(RunRow::from_summary(c, key, &run.summary))
}

/// Flies a group's runs in one world ([`fly_shared`]) and emits each run's row as it ends. If
/// anything panics, the runs without a row yet are flown again one by one (each then fails or
/// not on its own, as it would in a campaign that shares nothing).
fn run_shared(c: &Campaign, group: &[RunKey], out: &Path, emit: &mut dyn FnMut(RunRow)) {
    let mut written = vec![false; group.len()];
    let attempt = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let mut missions = Vec::with_capacity(group.len());
        let mut keys = Vec::with_capacity(group.len());
        for (i, key) in group.iter().enumerate() {
            match prepare(c, key) {
                Ok(m) => {
                    missions.push(m);
                    keys.push(i);
                }
                Err(e) => {
                    written[i] = true;
                    emit(RunRow::failed(c, key, e.to_string()));
                }
            }
        }
        fly_shared(missions, &mut |k, result| {
            let Some(&i) = keys.get(k) else { return };
            let key = &group[i];
            let row = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                row_of(c, key, out, result?)
            }));
            written[i] = true;
            emit(row_or_failure(c, key, row));
        });
    }));
    if attempt.is_err() {
        for (key, _) in group.iter().zip(&written).filter(|(_, w)| !**w) {
            emit(run_one(c, key, out, &mut None, false, None));
        }
    }
}

/// The row of an attempt: its own, or a failed row naming the error or the panic.
fn row_or_failure(
    c: &Campaign,
    key: &RunKey,
    attempt: std::thread::Result<Result<RunRow, RunError>>,
) -> RunRow {
    match attempt {
        Ok(Ok(row)) => row,
        Ok(Err(e)) => RunRow::failed(c, key, e.to_string()),
        Err(panic) => {
            let what = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown panic".into());
            RunRow::failed(c, key, format!("internal error (panic): {what}"))
        }
    }
}
