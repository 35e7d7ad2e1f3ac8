//! The windy grid-world benchmark of infotaxis (`plumetrace bench infotaxis`; the windy case of
//! otto-benchmark, Loisy & Heinonen 2023), to check the planner's move choice against published
//! numbers.
//!
//! The model ([`plumetrace_planner::estimate::gridworld`]): 81 x 41 cells, wind along `+x`, start
//! (65, 20) after a first hit, mean hit rate `R / d exp(V (x - x_s) / 2 - d / lambda)` with
//! `V = 2`, `tau = 150`, binary hits `1 - exp(-mu)`, one move per step, the episode won when the
//! searcher steps onto the source and lost at 10,000 steps. Each episode draws its source from
//! the searcher's prior and its hits from the true source, with its own random stream
//! (`derive_seed(seed, episode)`), so the results do not depend on the thread count. The moves
//! are chosen by [`plumetrace_planner::estimate::infotaxis`], the code the `infotaxis` planner
//! uses.
//!
//! Published with otto-benchmark (10,000 episodes each, its "+-" being 1.96 standard errors):
//! `R = 2.5`, infotaxis 74.4 +- 2.0 steps (median 52), space-aware infotaxis 64.5 +- 2.2 (median
//! 49); `R = 0.25`, infotaxis 266 +- 14 (median 132, 0.1 % of episodes failed).

use crate::BenchError;
use cpu_time::ProcessTime;
use plumetrace_env::{StreamId, derive_seed, stream_rng};
use plumetrace_planner::estimate::gridworld::{HitTable, WindyGrid};
use plumetrace_planner::estimate::infotaxis::{bayes_update, choose, move_outcome};
use plumetrace_planner::estimate::{Objective, entropy_bits};
use rand::Rng;
use serde::Serialize;
use std::time::Instant;

/// What to run.
#[derive(Debug, Clone, PartialEq)]
pub struct InfotaxisBenchOptions {
    /// Episodes (each its own source and hits).
    pub episodes: u64,
    /// Dimensionless emission rate R (the benchmark's: 2.5 or 0.25; > 0 and <= 1000).
    pub rate: f64,
    /// Move choice.
    pub policy: Policy,
    /// Step limit of an episode (a failure when reached).
    pub max_steps: u64,
    /// Base seed.
    pub seed: u64,
    /// Worker threads (default: all cores); the results do not depend on it.
    pub jobs: Option<usize>,
}

/// The move choice of the benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Policy {
    /// Minimise the expected entropy.
    Infotaxis,
    /// Space-aware infotaxis.
    SpaceAware,
}

impl Policy {
    /// The objective the moves minimise.
    pub fn objective(self) -> Objective {
        match self {
            Policy::Infotaxis => Objective::Infotaxis,
            Policy::SpaceAware => Objective::SpaceAware,
        }
    }
}

/// What one episode came to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Episode {
    /// Steps taken.
    pub steps: u64,
    /// Whether the source was found within the limit.
    pub found: bool,
}

/// The benchmark's statistics.
#[derive(Debug, Clone, Serialize)]
pub struct InfotaxisBench {
    /// Emission rate.
    pub rate: f64,
    /// Move choice.
    pub policy: Policy,
    /// Episodes run.
    pub episodes: u64,
    /// Base seed.
    pub seed: u64,
    /// Step limit.
    pub max_steps: u64,
    /// Mean steps of the episodes that found the source.
    pub mean_steps: f64,
    /// Standard error of that mean.
    pub standard_error: f64,
    /// Median steps (every episode; failures count at the limit).
    pub median_steps: f64,
    /// 90th and 99th percentiles and the most steps (every episode).
    pub p90_steps: f64,
    /// 99th percentile.
    pub p99_steps: f64,
    /// Most steps.
    pub max_steps_seen: u64,
    /// Mean steps with failures counted at the limit.
    pub mean_steps_all: f64,
    /// Standard error of that mean.
    pub standard_error_all: f64,
    /// Fraction of episodes that reached the limit.
    pub failure_rate: f64,
    /// CPU time of the process over the decisions made, microseconds per move choice.
    pub cpu_us_per_decision: f64,
    /// Wall time of the whole benchmark, seconds.
    pub wall_s: f64,
    /// Threads used.
    pub threads: usize,
}

/// Draws a cell from the distribution `p` with a uniform number `u` in `[0, 1)`.
fn draw(p: &[f64], u: f64) -> usize {
    let mut acc = 0.0;
    for (i, &q) in p.iter().enumerate() {
        acc += q;
        if u < acc {
            return i;
        }
    }
    // Rounding: the last cell with mass.
    p.iter().rposition(|&q| q > 0.0).unwrap_or(0)
}

/// One episode of the windy grid world.
pub fn episode(
    grid: &WindyGrid,
    table: &HitTable,
    prior: &[f64],
    objective: Objective,
    max_steps: u64,
    seed: u64,
) -> Episode {
    let mut rng = stream_rng(seed, StreamId::Custom(0x6772_6964)); // "grid"
    let source = grid.cell(draw(prior, rng.random::<f64>()));
    let mut p = prior.to_vec();
    let mut at = grid.start;
    let mut hits: [Vec<f64>; 4] = Default::default();
    let mut dist = vec![0.0; grid.cells()];
    for steps in 1..=max_steps {
        let mut values = [None; 4];
        for (mv, value) in values.iter_mut().enumerate() {
            let Some((x, y)) = grid.step(at, mv) else {
                continue;
            };
            table.fill_hits_at(x, y, &mut hits[mv]);
            let d = (objective == Objective::SpaceAware).then(|| {
                for (i, di) in dist.iter_mut().enumerate() {
                    let (cx, cy) = grid.cell(i);
                    *di = (cx.abs_diff(x) + cy.abs_diff(y)) as f64;
                }
                &dist[..]
            });
            let o = move_outcome(&p, &hits[mv], Some(grid.index(x, y)), d);
            *value = Some(objective.value(&o));
        }
        let Some(mv) = choose(&values) else {
            break;
        };
        let Some(next) = grid.step(at, mv) else {
            break;
        };
        at = next;
        if at == source {
            return Episode { steps, found: true };
        }
        let hit = rng.random::<f64>() < table.hit(at, source);
        bayes_update(&mut p, &hits[mv], hit, Some(grid.index(at.0, at.1)));
        debug_assert!(entropy_bits(&p).is_finite());
    }
    Episode {
        steps: max_steps,
        found: false,
    }
}

/// Runs `episodes` episodes in parallel (each from `derive_seed(seed, index)`), in index order.
pub fn run_episodes(
    rate: f64,
    objective: Objective,
    episodes: u64,
    max_steps: u64,
    seed: u64,
) -> Vec<Episode> {
    use rayon::prelude::*;
    let grid = WindyGrid::benchmark(rate);
    let table = grid.hit_table();
    let prior = grid.prior(&table);
    (0..episodes)
        .into_par_iter()
        .map(|i| {
            episode(
                &grid,
                &table,
                &prior,
                objective,
                max_steps,
                derive_seed(seed, i),
            )
        })
        .collect()
}

/// The statistics of a set of episodes.
pub fn statistics(
    a: &InfotaxisBenchOptions,
    runs: &[Episode],
    cpu_s: f64,
    wall_s: f64,
    threads: usize,
) -> InfotaxisBench {
    let found: Vec<f64> = runs
        .iter()
        .filter(|e| e.found)
        .map(|e| e.steps as f64)
        .collect();
    let n = found.len() as f64;
    let mean = found.iter().sum::<f64>() / n.max(1.0);
    let var = found.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    let mut all: Vec<f64> = runs.iter().map(|e| e.steps as f64).collect();
    all.sort_by(f64::total_cmp);
    let quantile = |q: f64| {
        if all.is_empty() {
            return 0.0;
        }
        let pos = q * (all.len() - 1) as f64;
        let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
        all[lo] + (all[hi] - all[lo]) * (pos - lo as f64)
    };
    let decisions: f64 = all.iter().sum();
    let n_all = (all.len() as f64).max(1.0);
    let mean_all = decisions / n_all;
    let var_all = all.iter().map(|s| (s - mean_all).powi(2)).sum::<f64>() / (n_all - 1.0).max(1.0);
    InfotaxisBench {
        rate: a.rate,
        policy: a.policy,
        episodes: a.episodes,
        seed: a.seed,
        max_steps: a.max_steps,
        mean_steps: mean,
        standard_error: (var / n.max(1.0)).sqrt(),
        median_steps: quantile(0.5),
        p90_steps: quantile(0.9),
        p99_steps: quantile(0.99),
        max_steps_seen: runs.iter().map(|e| e.steps).max().unwrap_or(0),
        mean_steps_all: mean_all,
        standard_error_all: (var_all / n_all).sqrt(),
        failure_rate: runs.iter().filter(|e| !e.found).count() as f64
            / (runs.len() as f64).max(1.0),
        cpu_us_per_decision: cpu_s / decisions.max(1.0) * 1e6,
        wall_s,
        threads,
    }
}

/// Runs the benchmark on a pool of `jobs` threads.
pub fn infotaxis(a: &InfotaxisBenchOptions) -> Result<InfotaxisBench, BenchError> {
    if !(a.rate > 0.0 && a.rate <= 1000.0) {
        return Err(BenchError::Rate(a.rate));
    }
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(j) = a.jobs {
        b = b.num_threads(j);
    }
    let pool = b.build()?;
    let threads = pool.current_num_threads();
    let started = Instant::now();
    let cpu = ProcessTime::now();
    let runs = pool.install(|| {
        run_episodes(
            a.rate,
            a.policy.objective(),
            a.episodes,
            a.max_steps,
            a.seed,
        )
    });
    Ok(statistics(
        a,
        &runs,
        cpu.elapsed().as_secs_f64(),
        started.elapsed().as_secs_f64(),
        threads,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(rate: f64, policy: Policy, episodes: u64, seed: u64) -> InfotaxisBenchOptions {
        InfotaxisBenchOptions {
            episodes,
            rate,
            policy,
            max_steps: 10_000,
            seed,
            jobs: None,
        }
    }

    /// Checks the mean against the published one within three combined standard errors.
    /// `half_width` is the published interval as otto-benchmark prints it: 1.96 standard errors.
    fn parity(run: (f64, Policy, u64, u64), mean: f64, half_width: f64, fail_max: f64) {
        let (rate, policy, episodes, seed) = run;
        let se = half_width / 1.96;
        let a = args(rate, policy, episodes, seed);
        let runs = run_episodes(rate, policy.objective(), episodes, a.max_steps, a.seed);
        let s = statistics(&a, &runs, 1.0, 1.0, 1);
        let tol = 3.0 * (s.standard_error.powi(2) + se * se).sqrt();
        assert!(
            (s.mean_steps - mean).abs() < tol,
            "R = {rate} {policy:?}: {} +- {} against {mean} +- {se}",
            s.mean_steps,
            s.standard_error
        );
        assert!(s.failure_rate <= fail_max, "{}", s.failure_rate);
    }

    #[test]
    fn infotaxis_in_the_windy_grid_world_matches_the_published_mean_on_100_episodes() {
        parity((2.5, Policy::Infotaxis, 100, 1), 74.4, 2.0, 0.03);
    }

    #[test]
    #[ignore = "7,000 episodes: minutes in release; run with --ignored"]
    fn the_windy_grid_world_matches_the_published_numbers_on_the_recorded_cases() {
        // The cases of docs/results/infotaxis-grid-world.md. At R = 0.25 the long tail needs
        // 5,000 episodes: 1,000 at seed 1 read 223.6 +- 9.3, 3.6 combined standard errors low.
        parity((2.5, Policy::Infotaxis, 1000, 1), 74.4, 2.0, 0.01);
        parity((2.5, Policy::SpaceAware, 1000, 1), 64.5, 2.2, 0.01);
        parity((0.25, Policy::Infotaxis, 5000, 3), 266.0, 14.0, 0.01);
    }

    #[test]
    fn a_rate_out_of_range_is_refused() {
        let e = infotaxis(&args(0.0, Policy::Infotaxis, 1, 1))
            .err()
            .map(|e| e.to_string());
        assert_eq!(e.as_deref(), Some("--rate must be > 0 and <= 1000, got 0"));
    }

    #[test]
    fn episodes_do_not_depend_on_the_thread_count() {
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap_or_else(|e| panic!("{e}"));
        let two = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap_or_else(|e| panic!("{e}"));
        let a = one.install(|| run_episodes(2.5, Objective::SpaceAware, 12, 10_000, 7));
        let b = two.install(|| run_episodes(2.5, Objective::SpaceAware, 12, 10_000, 7));
        assert_eq!(a, b);
        assert!(a.iter().all(|e| e.found));
    }
}
