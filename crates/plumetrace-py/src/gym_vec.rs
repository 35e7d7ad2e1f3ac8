//! The vectorised environment's core: `n` environments of [`crate::gym`] stepped together in
//! Rust, in parallel (results do not depend on the thread count), with Gymnasium's two autoreset
//! modes (next step: the step after an episode's end resets it; same step: the step that ends
//! an episode starts the next and gives the ended one's last observation and `info` apart, as
//! Stable-Baselines3 expects) and a reset of any subset of the environments.

use crate::error::msg;
use crate::gym::{Episode, InfoRow, Maker, NO_ERROR, StepOut, action3, maker};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use plumetrace_env::derive_seed;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

/// `info` of `n` environments: one array per key (`reason` a list of strings).
fn info_arrays<'py>(py: Python<'py>, rows: &[InfoRow]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let seeds: Vec<u64> = rows.iter().map(|r| r.run_seed).collect();
    let times: Vec<f64> = rows.iter().map(|r| r.time_s).collect();
    let success: Vec<bool> = rows.iter().map(|r| r.success).collect();
    let reasons: Vec<&str> = rows.iter().map(|r| r.reason).collect();
    let errors: Vec<f64> = rows.iter().map(|r| r.error_m).collect();
    d.set_item("run_seed", seeds.into_pyarray(py))?;
    d.set_item("time_s", times.into_pyarray(py))?;
    d.set_item("success", success.into_pyarray(py))?;
    d.set_item("reason", reasons)?;
    d.set_item("error_m", errors.into_pyarray(py))?;
    Ok(d)
}

fn obs_array<'py>(py: Python<'py>, obs: &[[f32; 12]]) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let flat: Vec<f32> = obs.iter().flatten().copied().collect();
    let a = Array2::from_shape_vec((obs.len(), 12), flat).map_err(|e| msg(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// The run seed that seed `s` of an environment's sequence flies: `s`, or with a pool of
/// seeds, `pool[s % len]`.
fn pick(pool: &Option<Vec<u64>>, s: u64) -> u64 {
    match pool {
        Some(p) if !p.is_empty() => p[(s % p.len() as u64) as usize],
        _ => s,
    }
}

/// What one environment does at a vector step.
enum Work {
    /// Starts an episode with this seed (next-step autoreset).
    Reset(u64),
    /// Applies the action; in the same-step mode, an ended episode is followed at once by the
    /// next, with this seed.
    Step([f64; 3], Option<u64>),
}

/// One environment's result of a vector step: the step, the ended episode's last step (same
/// step), whether a new episode started.
type Done = (StepOut, Option<StepOut>, bool);

fn work_on(maker: &Maker, ep: &mut Option<Episode>, work: &Work) -> Result<Done, String> {
    let start = |seed: u64, ep: &mut Option<Episode>| -> Result<StepOut, String> {
        let (e, obs) = maker.episode(seed)?;
        let first = StepOut::first(&e, obs);
        *ep = Some(e);
        Ok(first)
    };
    match work {
        Work::Reset(seed) => Ok((start(*seed, ep)?, None, true)),
        Work::Step(action, next) => {
            let e = ep.as_mut().ok_or("no episode")?;
            e.act(*action);
            let out = e.advance(maker.settings)?;
            match next {
                Some(seed) if out.terminated || out.truncated => {
                    let mut first = start(*seed, ep)?;
                    first.reward = out.reward;
                    first.terminated = out.terminated;
                    first.truncated = out.truncated;
                    Ok((first, Some(out), true))
                }
                _ => Ok((out, None, false)),
            }
        }
    }
}

/// `n` environments stepped together in Rust. Environment `i`, reset with base seed `s`, flies
/// its episodes with the seeds `s`, then `derive_seed(s, 1)`, `derive_seed(s, 2)`, ...
#[pyclass(module = "plumetrace._plumetrace", unsendable)]
pub struct VecEnvCore {
    maker: Maker,
    same_step: bool,
    /// Run seeds to fly: a derived seed `d` flies `pool[d % len]`.
    pool: Option<Vec<u64>>,
    episodes: Vec<Option<Episode>>,
    base_seeds: Vec<u64>,
    counts: Vec<u64>,
    needs_reset: Vec<bool>,
    last_obs: Vec<[f32; 12]>,
    last_info: Vec<InfoRow>,
}

#[pymethods]
impl VecEnvCore {
    /// `n` environments on `scenario`, with settings and overrides as for `EnvCore`;
    /// `same_step` chooses the same-step autoreset (otherwise next-step); `seeds`, a list of
    /// run seeds, makes every episode fly one of them (seed `d` of the sequence above flies
    /// `seeds[d % len(seeds)]`), e.g. a benchmark task's tuning seeds.
    #[new]
    #[pyo3(signature = (scenario, n, same_step=false, seeds=None, set=None, **kwargs))]
    fn new(
        scenario: &str,
        n: usize,
        same_step: bool,
        seeds: Option<Vec<u64>>,
        set: Option<&Bound<'_, PyDict>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        if !(1..=4096).contains(&n) {
            return Err(msg(format!("n = {n} environments is outside 1..=4096")));
        }
        if seeds.as_ref().is_some_and(Vec::is_empty) {
            return Err(msg("seeds is empty: give at least one run seed".to_string()));
        }
        let none = InfoRow {
            run_seed: 0,
            time_s: 0.0,
            success: false,
            reason: "",
            error_m: NO_ERROR,
        };
        Ok(VecEnvCore {
            maker: maker(scenario, set, kwargs)?,
            same_step,
            pool: seeds,
            episodes: (0..n).map(|_| None).collect(),
            base_seeds: vec![0; n],
            counts: vec![0; n],
            needs_reset: vec![true; n],
            last_obs: vec![[0.0; 12]; n],
            last_info: vec![none; n],
        })
    }

    /// Number of environments.
    #[getter]
    fn num_envs(&self) -> usize {
        self.episodes.len()
    }

    /// Resets the environments where `mask` is true (all without a mask): environment `i`
    /// gets run seed `seeds[i]` for this episode and derives its later episodes from it.
    /// Returns the observations of every environment, shape `(n, 12)` (the others' latest),
    /// and `info` (arrays; the others' latest).
    #[pyo3(signature = (seeds, mask=None))]
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seeds: Vec<u64>,
        mask: Option<Vec<bool>>,
    ) -> PyResult<(Bound<'py, PyArray2<f32>>, Bound<'py, PyDict>)> {
        let n = self.episodes.len();
        let mask = mask.unwrap_or_else(|| vec![true; n]);
        if seeds.len() != n || mask.len() != n {
            return Err(msg(format!(
                "reset needs {n} seeds and a mask of {n}, not {} and {}",
                seeds.len(),
                mask.len()
            )));
        }
        let maker = &self.maker;
        let pool = &self.pool;
        let mut work: Vec<(&mut Option<Episode>, Option<Work>)> = self
            .episodes
            .iter_mut()
            .zip(&seeds)
            .zip(&mask)
            .map(|((ep, s), m)| (ep, m.then_some(Work::Reset(pick(pool, *s)))))
            .collect();
        let outs: Vec<Option<Result<Done, String>>> = py.detach(|| {
            work.par_iter_mut()
                .map(|(ep, w)| w.as_ref().map(|w| work_on(maker, ep, w)))
                .collect()
        });
        drop(work);
        for (i, o) in outs.into_iter().enumerate() {
            let Some(o) = o else { continue };
            let (out, _, _) = o.map_err(|e| msg(format!("environment {i}: {e}")))?;
            self.base_seeds[i] = seeds[i];
            self.counts[i] = 0;
            self.needs_reset[i] = false;
            self.last_obs[i] = out.obs;
            self.last_info[i] = out.info;
        }
        Ok((
            obs_array(py, &self.last_obs)?,
            info_arrays(py, &self.last_info)?,
        ))
    }

    /// Steps every environment with `actions` of shape `(n, 3)`; returns `(observations,
    /// rewards, terminated, truncated, info, final)`: `info` arrays of every key, `final`
    /// (same-step mode, where an episode ended) `(ended, last observations, last info)`, else
    /// None.
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f32>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyDict>,
        Option<(
            Bound<'py, PyArray1<bool>>,
            Bound<'py, PyArray2<f32>>,
            Bound<'py, PyDict>,
        )>,
    )> {
        let n = self.episodes.len();
        let shape = actions.shape();
        if shape != [n, 3] {
            return Err(msg(format!(
                "actions must have shape ({n}, 3) (turn, speed, declare), not {shape:?}"
            )));
        }
        let acts = actions.as_array();
        let mut plan = Vec::with_capacity(n);
        for i in 0..n {
            let next = pick(
                &self.pool,
                derive_seed(self.base_seeds[i], self.counts[i] + 1),
            );
            let row = action3(&acts.row(i).to_vec())?;
            plan.push(if self.needs_reset[i] || self.episodes[i].is_none() {
                Work::Reset(next)
            } else {
                Work::Step(row, self.same_step.then_some(next))
            });
        }
        let maker = &self.maker;
        let mut work: Vec<(&mut Option<Episode>, &Work)> =
            self.episodes.iter_mut().zip(&plan).collect();
        let outs: Vec<Result<Done, String>> = py.detach(|| {
            work.par_iter_mut()
                .map(|(ep, w)| work_on(maker, ep, w))
                .collect()
        });
        drop(work);
        let (mut rew, mut term, mut trunc) = (vec![0.0; n], vec![false; n], vec![false; n]);
        let mut ended = vec![false; n];
        let (mut final_obs, mut final_info) = (self.last_obs.clone(), self.last_info.clone());
        for (i, o) in outs.into_iter().enumerate() {
            let (out, last, started) = o.map_err(|e| msg(format!("environment {i}: {e}")))?;
            if started {
                self.counts[i] += 1;
            }
            if let Some(last) = last {
                ended[i] = true;
                final_obs[i] = last.obs;
                final_info[i] = last.info;
            }
            self.needs_reset[i] = !self.same_step && (out.terminated || out.truncated);
            rew[i] = out.reward;
            term[i] = out.terminated;
            trunc[i] = out.truncated;
            self.last_obs[i] = out.obs;
            self.last_info[i] = out.info;
        }
        let last = if ended.iter().any(|e| *e) {
            Some((
                ended.into_pyarray(py),
                obs_array(py, &final_obs)?,
                info_arrays(py, &final_info)?,
            ))
        } else {
            None
        };
        Ok((
            obs_array(py, &self.last_obs)?,
            rew.into_pyarray(py),
            term.into_pyarray(py),
            trunc.into_pyarray(py),
            info_arrays(py, &self.last_info)?,
            last,
        ))
    }
}
