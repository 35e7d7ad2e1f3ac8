//! Missions per second of a mission preset on several thread counts (`plumetrace bench
//! missions`), flown as a campaign flies them (no mean-plume grid, no trajectory kept).

use crate::BenchError;
use cpu_time::ProcessTime;
use plumetrace_mission::MissionRun;
use plumetrace_scenario::config::ScenarioConfig;
use serde::Serialize;
use std::time::Instant;

/// What to fly.
#[derive(Debug, Clone, PartialEq)]
pub struct MissionBenchOptions {
    /// Mission preset to fly.
    pub preset: String,
    /// Missions per thread count (the same missions, seeds derived from `seed`, each time).
    pub runs: u64,
    /// Thread counts to time.
    pub threads: Vec<usize>,
    /// Base seed.
    pub seed: u64,
    /// Overrides of scenario keys, `KEY=VALUE` with VALUE in TOML, as a campaign's `set`.
    pub set: Vec<String>,
}

/// The missions benchmark's result.
#[derive(Debug, Clone, Serialize)]
pub struct MissionBench {
    /// The preset flown.
    pub preset: String,
    /// The `--set` overrides.
    pub set: Vec<String>,
    /// Missions per thread count.
    pub runs: u64,
    /// Simulated seconds per mission, mean.
    pub mean_mission_s: f64,
    /// One row per thread count.
    pub results: Vec<MissionBenchRow>,
    /// missions/s on the largest thread count over missions/s on the smallest.
    pub scaling: f64,
    /// The split by stage on the first thread count, seconds per mission (wall time measured
    /// inside each mission: on one thread, about its CPU time), spin-up included.
    pub stages_s_per_mission: StageSplit,
    /// The machine's load average (1 minute) when the benchmark ended, if known.
    pub load_average: Option<f64>,
    /// The vector unit the filament step ran on ([`plumetrace_env::vector_unit`]).
    pub vector_unit: &'static str,
}

/// The missions of one thread count.
#[derive(Debug, Clone, Serialize)]
pub struct MissionBenchRow {
    /// Threads.
    pub threads: usize,
    /// Wall time of the row, s.
    pub wall_s: f64,
    /// CPU time of the process (all threads) over the row, s.
    pub cpu_s: f64,
    /// CPU per mission, s.
    pub cpu_per_mission_s: f64,
    /// CPU per second of mission flown, ms.
    pub cpu_per_mission_second_ms: f64,
    /// Missions per wall second.
    pub missions_per_s: f64,
    /// Simulated seconds per wall second, all missions.
    pub real_time_factor: f64,
}

/// Time per stage of a mission's step, s.
#[derive(Debug, Clone, Default, Serialize)]
pub struct StageSplit {
    /// The plume's spin-up.
    pub spin_up: f64,
    /// Stepping the environment.
    pub advance_environment: f64,
    /// Sensing.
    pub sense: f64,
    /// Messages between vehicles.
    pub communicate: f64,
    /// The planners' decisions.
    pub decide: f64,
    /// Control.
    pub control: f64,
    /// Integrating the vehicles' motion.
    pub integrate: f64,
    /// Checking the mission's end.
    pub check: f64,
    /// Recording.
    pub record: f64,
}

impl StageSplit {
    /// Adds a run's stage times, times `weight`.
    fn add(&mut self, run: &MissionRun, weight: f64) {
        let t = &run.stage_times;
        self.spin_up += run.spinup_wall_s * weight;
        self.advance_environment += t.advance_environment_s * weight;
        self.sense += t.sense_s * weight;
        self.communicate += t.communicate_s * weight;
        self.decide += t.decide_s * weight;
        self.control += t.control_s * weight;
        self.integrate += t.integrate_s * weight;
        self.check += t.check_s * weight;
        self.record += t.record_s * weight;
    }
}

/// The 1-minute load average from `/proc/loadavg`, where there is one.
fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// The preset's scenario with `KEY=VALUE` overrides applied.
fn preset_with_sets(preset: &str, sets: &[String]) -> Result<ScenarioConfig, BenchError> {
    let text = plumetrace_scenario::preset(preset)?.toml;
    let mut table: toml::Table = toml::from_str(text)?;
    plumetrace_scenario::overrides::apply_sets(&mut table, sets)?;
    Ok(plumetrace_scenario::from_table(
        table,
        &plumetrace_scenario::Origin::Preset(preset.to_string()),
    )?)
}

/// Flies `runs` missions of the preset on each thread count, as a campaign does (no mean-plume
/// grid, no trajectory kept).
pub fn missions(a: &MissionBenchOptions) -> Result<MissionBench, BenchError> {
    use rayon::prelude::*;
    if a.runs == 0 || a.threads.is_empty() || a.threads.contains(&0) {
        return Err(BenchError::NoRuns);
    }
    let cfg = preset_with_sets(&a.preset, &a.set)?;
    let origin = plumetrace_scenario::Origin::Preset(a.preset.clone());
    if plumetrace_scenario::build(&cfg, &origin, None)?
        .mission
        .is_none()
    {
        return Err(BenchError::NotAMission(a.preset.clone()));
    }
    let options = plumetrace_mission::MissionOptions {
        mean_plume: false,
        trajectory: false,
        plume_frames_every_s: None,
        // The split by stage: seven clock readings a step, which a campaign does not take
        // (about 4 % of a `duck-2003-st` mission).
        stage_times: true,
    };
    let mut results = Vec::new();
    let mut sim_s = 0.0;
    let mut stages = StageSplit::default();
    for (row, &t) in a.threads.iter().enumerate() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build()?;
        let started = Instant::now();
        let cpu = ProcessTime::now();
        let runs: Vec<Result<MissionRun, BenchError>> = pool.install(|| {
            (0..a.runs)
                .into_par_iter()
                .map(|i| {
                    let seed = plumetrace_env::derive_seed(a.seed, i);
                    let sc = plumetrace_scenario::build(&cfg, &origin, Some(seed))?;
                    Ok(plumetrace_mission::run_mission_with(
                        sc,
                        options,
                        &mut |_, _| {},
                    )?)
                })
                .collect()
        });
        let cpu_s = cpu.elapsed().as_secs_f64();
        let wall = started.elapsed().as_secs_f64();
        sim_s = 0.0;
        for run in runs {
            let run = run?;
            sim_s += run.summary.sim_time_s;
            if row == 0 {
                stages.add(&run, 1.0 / a.runs as f64);
            }
        }
        results.push(MissionBenchRow {
            threads: t,
            wall_s: wall,
            cpu_s,
            cpu_per_mission_s: cpu_s / a.runs as f64,
            cpu_per_mission_second_ms: cpu_s / sim_s * 1e3,
            missions_per_s: a.runs as f64 / wall,
            real_time_factor: sim_s / wall,
        });
    }
    let first = results.first().map_or(f64::NAN, |r| r.missions_per_s);
    let last = results.last().map_or(f64::NAN, |r| r.missions_per_s);
    Ok(MissionBench {
        preset: a.preset.clone(),
        set: a.set.clone(),
        runs: a.runs,
        mean_mission_s: sim_s / a.runs as f64,
        results,
        scaling: last / first,
        stages_s_per_mission: stages,
        load_average: load_average(),
        vector_unit: plumetrace_env::vector_unit(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn options(preset: &str, set: &[&str]) -> MissionBenchOptions {
        MissionBenchOptions {
            preset: preset.to_string(),
            runs: 1,
            threads: vec![1],
            seed: 1,
            set: set.iter().map(|s| s.to_string()).collect(),
        }
    }

    fn refused(o: &MissionBenchOptions) -> String {
        missions(o).err().map(|e| e.to_string()).unwrap_or_default()
    }

    #[test]
    fn overrides_apply_to_the_preset_and_bad_ones_name_themselves() {
        let cfg = preset_with_sets("demo", &["sim.dt_s=0.5".to_string()])
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(cfg.sim.dt_s, 0.5);
        assert_eq!(
            refused(&options("demo", &["sim.dt_s"])),
            "--set \"sim.dt_s\": expected KEY=VALUE"
        );
        let e = refused(&options("demo", &["sim.dt_s=[1,"]));
        assert!(
            e.starts_with("--set \"sim.dt_s=[1,\": the value is not TOML: "),
            "{e}"
        );
        assert!(
            refused(&options("nowhere", &[]))
                .starts_with("no preset named 'nowhere' (known: demo,"),
            "{}",
            refused(&options("nowhere", &[]))
        );
        assert!(
            refused(&options("dmeo", &[]))
                .starts_with("no preset named 'dmeo'; did you mean 'demo'?"),
            "{}",
            refused(&options("dmeo", &[]))
        );
    }

    #[test]
    fn a_plume_preset_or_no_runs_is_refused() {
        assert_eq!(
            refused(&options("plume-demo", &[])),
            "preset 'plume-demo' is not a mission"
        );
        let mut o = options("demo", &[]);
        o.threads = vec![1, 0];
        assert_eq!(
            refused(&o),
            "--runs and every --threads value must be at least 1"
        );
    }
}
