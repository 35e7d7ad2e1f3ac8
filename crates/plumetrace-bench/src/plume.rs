//! The plume model's cost (`plumetrace bench plume`).
//!
//! The pompy case is pompy's own scenario (x 0-100 m, y -50-50 m, 21 x 21 Farrell grid, 1 m/s,
//! source at (5, 0), dt 0.01 s; the `pompy` preset, whose grid advances every 0.05 s, pompy's
//! at every step: a flow step of 0 for that); the field case is the `field-scale` preset. After a
//! warm-up the environment is stepped for `duration` simulated seconds; the CPU time of those
//! steps over the sum of live filaments gives the cost per filament-step (flow update included,
//! as in pompy's figure; `flow_ns_per_step` gives its share). Point queries are then timed on
//! the final filament set, apart from the one-off index build, at points drawn around live
//! filaments (inside the plume, the costly case) and uniformly over the domain. Cross-flow spread
//! statistics at x = 25, 50 and 75 m are gathered every simulated second for the comparison with
//! pompy.

use crate::{BenchError, median};
use cpu_time::ProcessTime;
use plumetrace_core::Vec3;
use plumetrace_env::{ConcentrationField, Environment, StreamId, stream_rng};
use rand::Rng;
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// Which scenario to benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Case {
    /// pompy's scenario.
    Pompy,
    /// The field-scale preset (1.1 km, ~50,000 filaments).
    Field,
}

/// What to time; `None` takes the case's default.
#[derive(Debug, Clone, PartialEq)]
pub struct PlumeBenchOptions {
    /// Scenario to time.
    pub case: Case,
    /// Filament release rate, per second (default: the scenario's).
    pub release_rate: Option<f64>,
    /// Simulated seconds timed after the warm-up (default: 20 for pompy, 200 for field).
    pub duration: Option<f64>,
    /// Time step, s (default: 0.01 for pompy, 0.1 for field).
    pub dt: Option<f64>,
    /// Simulated seconds before timing starts (default: 100 for pompy, 11000 for field).
    pub warmup: Option<f64>,
    /// Use pompy's dt-scaled dispersion.
    pub pompy_compatible: bool,
    /// Use physical dispersion (wins over the scenario's setting, not over `pompy_compatible`).
    pub physical: bool,
    /// The flow grid's own step, s (`flow.farrell.step_s`; 0 steps the grid with the plume).
    pub flow_step: Option<f64>,
    /// Number of point queries to time.
    pub queries: usize,
    /// The timed window is split into this many blocks; costs are medians over blocks.
    pub blocks: usize,
    /// Run seed.
    pub seed: u64,
}

/// The plume benchmark's result.
#[derive(Debug, Clone, Serialize)]
pub struct PlumeBench {
    /// The scenario timed.
    pub case: Case,
    /// Whether pompy's dt-scaled dispersion was used.
    pub pompy_compatible: bool,
    /// Filaments released per second, all sources.
    pub release_rate_hz: f64,
    /// Time step, s.
    pub dt_s: f64,
    /// Simulated seconds before timing.
    pub warmup_s: f64,
    /// Simulated seconds timed.
    pub duration_s: f64,
    /// Steps timed.
    pub steps_timed: u64,
    /// CPU time of the timed steps, s.
    pub cpu_s: f64,
    /// CPU ns per filament-step, the median over blocks.
    pub ns_per_filament_step: f64,
    /// The least over blocks.
    pub ns_per_filament_step_min: f64,
    /// Every block's.
    pub ns_per_filament_step_blocks: Vec<f64>,
    /// CPU ns per step.
    pub ns_per_step: f64,
    /// Of `ns_per_step`, the flow's own update (a copy of the flow stepped as the environment
    /// steps it, on its own), per plume step: the fixed cost per step that the filaments share.
    pub flow_ns_per_step: f64,
    /// The flow advances once every this many plume steps (`flow.farrell.step_s`).
    pub flow_every_steps: u64,
    /// Flow sub-steps per advance.
    pub flow_substeps: u64,
    /// Live filaments, mean over the timed steps.
    pub mean_live_filaments: f64,
    /// Live filaments at the end.
    pub final_live_filaments: usize,
    /// Simulated seconds per CPU second.
    pub sim_s_per_cpu_s: f64,
    /// Building the query index once, wall ns.
    pub index_build_ns: f64,
    /// CPU ns per point query in the plume, the median over blocks.
    pub point_query_ns: f64,
    /// The least over blocks.
    pub point_query_ns_min: f64,
    /// CPU ns per point query uniform over the domain, the median over blocks.
    pub point_query_uniform_ns: f64,
    /// The vehicles' sensor query (a scan that skips blocks of filaments out of reach), at the
    /// in-plume points, ns per query.
    pub sensor_scan_ns: f64,
    /// The same points by a scan of every filament (bit for bit the same results), ns.
    pub sensor_full_scan_ns: f64,
    /// Cross-flow standard deviation of filament positions at x = 25, 50 and 75 m.
    pub crossflow_spread_m: BTreeMap<String, f64>,
    /// Cross-flow mean there.
    pub crossflow_mean_m: BTreeMap<String, f64>,
    /// Filaments counted there.
    pub crossflow_samples: BTreeMap<String, u64>,
    /// Threads used.
    pub threads: usize,
    /// The vector unit the filament step ran on ([`plumetrace_env::vector_unit`]).
    pub vector_unit: &'static str,
}

/// The benchmark's environment: the case's preset with the options applied to its parsed config.
fn build_env(a: &PlumeBenchOptions) -> Result<(Environment, bool, f64, f64, f64), BenchError> {
    let (name, dt, duration, warmup) = match a.case {
        Case::Pompy => ("pompy", 0.01, 20.0, 100.0),
        Case::Field => ("field-scale", 0.1, 200.0, 11_000.0),
    };
    let dt = a.dt.unwrap_or(dt);
    let duration = a.duration.unwrap_or(duration);
    let warmup = a.warmup.unwrap_or(warmup);
    let finite = |flag: &'static str, value: f64| {
        if value.is_finite() && value >= 0.0 {
            Ok(())
        } else {
            Err(BenchError::NotFiniteOrNegative { flag, value })
        }
    };
    for (flag, v) in [("--dt", dt), ("--duration", duration), ("--warmup", warmup)] {
        finite(flag, v)?;
    }
    if dt <= 0.0 || duration < dt {
        return Err(BenchError::NoStep);
    }
    let mut cfg = plumetrace_scenario::load_preset(name)?;
    cfg.sim.dt_s = dt;
    cfg.sim.duration_s = warmup + duration;
    cfg.output.average_start_s = 0.0;
    cfg.output.average_interval_s = cfg.output.average_interval_s.max(dt);
    if let Some(rate) = a.release_rate {
        finite("--release-rate", rate)?;
        for s in &mut cfg.sources {
            // Keep one mass unit per filament, as in pompy.
            s.filament_rate_hz = rate;
            s.mass_rate_per_s = rate;
        }
    }
    if let Some(step) = a.flow_step {
        finite("--flow-step", step)?;
        match cfg.flow.farrell.as_mut() {
            Some(f) => f.step_s = step,
            None => return Err(BenchError::NoFarrellFlow { case: name }),
        }
    }
    if a.pompy_compatible {
        cfg.plume.pompy_compatible = true;
    }
    if a.physical {
        cfg.plume.pompy_compatible = false;
    }
    let origin = plumetrace_scenario::Origin::Preset(name.into());
    let env = plumetrace_scenario::build(&cfg, &origin, Some(a.seed))?.env;
    Ok((env, cfg.plume.pompy_compatible, dt, duration, warmup))
}

/// Spread statistics of filaments in slabs across the flow.
struct Slabs {
    xs: [f64; 3],
    /// Per slab: count, sum of y, sum of y^2.
    moments: [[f64; 3]; 3],
}

impl Slabs {
    fn add(&mut self, plume: &plumetrace_env::FilamentPlume) {
        for (p, _) in plume.filaments() {
            for (s, &x) in self.xs.iter().enumerate() {
                if (p.x - x).abs() <= 2.5 {
                    self.moments[s][0] += 1.0;
                    self.moments[s][1] += p.y;
                    self.moments[s][2] += p.y * p.y;
                }
            }
        }
    }

    /// Spread, centre and sample count per slab, keyed by the slab's x.
    #[allow(clippy::type_complexity)]
    fn maps(
        &self,
    ) -> (
        BTreeMap<String, f64>,
        BTreeMap<String, f64>,
        BTreeMap<String, u64>,
    ) {
        let mut spread = BTreeMap::new();
        let mut centre = BTreeMap::new();
        let mut samples = BTreeMap::new();
        for (s, x) in self.xs.iter().enumerate() {
            let [n, sy, syy] = self.moments[s];
            let key = format!("{x:.0}");
            samples.insert(key.clone(), n as u64);
            if n > 1.0 {
                let m = sy / n;
                centre.insert(key.clone(), m);
                spread.insert(key, (syy / n - m * m).max(0.0).sqrt());
            }
        }
        (spread, centre, samples)
    }
}

/// Times the plume; `progress(done, total)` is told the steps done after each step of the
/// warm-up and of the timed window, and `(total, total)` when stepping ends.
pub fn plume(
    a: &PlumeBenchOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<PlumeBench, BenchError> {
    let (mut env, pompy_compatible, dt, duration, warmup) = build_env(a)?;
    let warm_steps = (warmup / dt).round() as u64;
    let timed_steps = ((duration / dt).round() as u64).max(1);
    let total = warm_steps + timed_steps;
    for k in 0..warm_steps {
        env.step()?;
        progress(k, total);
    }
    let mut slabs = Slabs {
        xs: [25.0, 50.0, 75.0],
        moments: [[0.0; 3]; 3],
    };
    let sample_every = ((1.0 / dt).round() as u64).max(1);
    let mut live_sum = 0u64;
    let mut cpu = 0.0;
    let blocks = a.blocks.clamp(1, timed_steps as usize) as u64;
    let block_len = timed_steps.div_ceil(blocks);
    let (mut block_cpu, mut block_live) = (0.0, 0u64);
    let mut per_block = Vec::new();
    // CPU time is read once per block of steps between statistics samples, so neither the
    // clock nor the sampling is charged to the model.
    let mut block = ProcessTime::now();
    for k in 0..timed_steps {
        env.step()?;
        let f = env.plume().filaments();
        live_sum += f.map_or(0, |f| f.len() as u64);
        block_live += f.map_or(0, |f| f.len() as u64);
        let end_of_block = (k + 1).is_multiple_of(block_len) || k + 1 == timed_steps;
        if k.is_multiple_of(sample_every) || end_of_block {
            let c = block.elapsed().as_secs_f64();
            cpu += c;
            block_cpu += c;
            block = ProcessTime::now();
        }
        if end_of_block {
            per_block.push(block_cpu * 1e9 / block_live.max(1) as f64);
            (block_cpu, block_live) = (0.0, 0);
        }
        if k.is_multiple_of(sample_every)
            && let Some(f) = f
        {
            slabs.add(f);
        }
        if k.is_multiple_of(sample_every) {
            block = ProcessTime::now();
        }
        progress(warm_steps + k, total);
    }
    progress(total, total);
    let queries = time_queries(&env, a.seed, a.queries, blocks as usize)?;
    let Some(f) = env.plume().filaments() else {
        return Err(BenchError::NotFilaments);
    };
    let (spread, centre, samples) = slabs.maps();
    let mean_live = live_sum as f64 / timed_steps as f64;
    let (flow_every_steps, flow_substeps) = plumetrace_env::flow_schedule(env.flow(), env.dt_s());
    let flow_ns_per_step = time_flow(&env, timed_steps, blocks as usize)?;
    Ok(PlumeBench {
        case: a.case,
        pompy_compatible,
        release_rate_hz: f.sources().iter().map(|s| s.filament_rate_hz).sum(),
        dt_s: dt,
        warmup_s: warmup,
        duration_s: timed_steps as f64 * dt,
        steps_timed: timed_steps,
        cpu_s: cpu,
        ns_per_filament_step: median(&per_block),
        ns_per_filament_step_min: per_block.iter().copied().fold(f64::INFINITY, f64::min),
        ns_per_filament_step_blocks: per_block.clone(),
        ns_per_step: cpu * 1e9 / timed_steps as f64,
        flow_ns_per_step,
        flow_every_steps,
        flow_substeps,
        mean_live_filaments: mean_live,
        final_live_filaments: f.len(),
        sim_s_per_cpu_s: timed_steps as f64 * dt / cpu.max(1e-12),
        index_build_ns: queries.index_build_ns,
        point_query_ns: median(&queries.in_plume_ns),
        point_query_ns_min: queries
            .in_plume_ns
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min),
        point_query_uniform_ns: median(&queries.uniform_ns),
        sensor_scan_ns: median(&queries.scan_ns),
        sensor_full_scan_ns: median(&queries.full_ns),
        crossflow_spread_m: spread,
        crossflow_mean_m: centre,
        crossflow_samples: samples,
        threads: 1,
        vector_unit: plumetrace_env::vector_unit(),
    })
}

/// The query timings of [`time_queries`], ns per query, one value per block.
struct QueryTimes {
    index_build_ns: f64,
    in_plume_ns: Vec<f64>,
    uniform_ns: Vec<f64>,
    scan_ns: Vec<f64>,
    full_ns: Vec<f64>,
}

/// Times `queries` point queries of the final filament set at points drawn around live filaments
/// and uniformly over the domain, and the sensor's scans at some of the in-plume points, in
/// `blocks` rounds (the index built once first, timed apart).
fn time_queries(
    env: &Environment,
    seed: u64,
    queries: usize,
    blocks: usize,
) -> Result<QueryTimes, BenchError> {
    let Some(f) = env.plume().filaments() else {
        return Err(BenchError::NotFilaments);
    };
    let t0 = Instant::now();
    f.prepare_queries();
    let index_build_ns = t0.elapsed().as_secs_f64() * 1e9;
    let mut rng = stream_rng(seed, StreamId::Custom(77));
    let centres: Vec<Vec3> = f.filaments().map(|(p, _)| p).collect();
    let n = queries.max(1);
    let in_plume: Vec<Vec3> = (0..n)
        .map(|_| {
            let c = if centres.is_empty() {
                Vec3::zeros()
            } else {
                centres[rng.random_range(0..centres.len())]
            };
            Vec3::new(
                c.x + rng.random_range(-0.5..0.5),
                c.y + rng.random_range(-0.5..0.5),
                c.z,
            )
        })
        .collect();
    let d = env.domain();
    let uniform: Vec<Vec3> = (0..n)
        .map(|_| {
            Vec3::new(
                rng.random_range(d.x_min_m..d.x_max_m),
                rng.random_range(d.y_min_m..d.y_max_m),
                0.0,
            )
        })
        .collect();
    let time_queries = |pts: &[Vec3]| {
        let c0 = ProcessTime::now();
        let mut sink = 0.0;
        for p in pts {
            sink += f.concentration(*p);
        }
        let ns = c0.elapsed().as_secs_f64() * 1e9 / pts.len() as f64;
        (ns, sink)
    };
    let time_scans = |pts: &[Vec3], full: bool| {
        let c0 = ProcessTime::now();
        let mut sink = 0.0;
        for p in pts {
            sink += if full {
                f.concentration_full_scan(*p)
            } else {
                f.concentration_scan(*p)
            };
        }
        (c0.elapsed().as_secs_f64() * 1e9 / pts.len() as f64, sink)
    };
    // Scans cost thousands of times an indexed query: a slice of the points is enough.
    let scan_pts = &in_plume[..in_plume.len().min(2_000)];
    let mut t = QueryTimes {
        index_build_ns,
        in_plume_ns: Vec::new(),
        uniform_ns: Vec::new(),
        scan_ns: Vec::new(),
        full_ns: Vec::new(),
    };
    for _ in 0..blocks {
        let (ns, s1) = time_queries(&in_plume);
        let (ns_u, s2) = time_queries(&uniform);
        let (ns_s, s3) = time_scans(scan_pts, false);
        let (ns_f, s4) = time_scans(scan_pts, true);
        std::hint::black_box(s1 + s2 + s3 + s4);
        t.in_plume_ns.push(ns);
        t.uniform_ns.push(ns_u);
        t.scan_ns.push(ns_s);
        t.full_ns.push(ns_f);
    }
    Ok(t)
}

/// CPU ns per plume step of the environment's flow alone: a copy of the flow and of its stepper
/// advanced over `steps` more plume steps as the environment would advance them, the median over
/// `blocks`.
fn time_flow(env: &Environment, steps: u64, blocks: usize) -> Result<f64, BenchError> {
    let mut flow = env.flow().clone();
    let mut stepper = env.flow_stepper().clone();
    let mut rng = stream_rng(1, StreamId::Custom(78));
    let dt = env.dt_s();
    let mut t = env.elapsed_s();
    let per_block = steps.div_ceil(blocks.max(1) as u64).max(1);
    let mut ns = Vec::new();
    let mut done = 0;
    while done < steps {
        let k = per_block.min(steps - done);
        let c0 = ProcessTime::now();
        for _ in 0..k {
            t += dt;
            stepper.advance(&mut flow, t, dt, &mut rng)?;
        }
        ns.push(c0.elapsed().as_secs_f64() * 1e9 / k as f64);
        done += k;
    }
    Ok(median(&ns))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn options() -> PlumeBenchOptions {
        PlumeBenchOptions {
            case: Case::Pompy,
            release_rate: None,
            duration: Some(0.5),
            dt: Some(0.05),
            warmup: Some(2.0),
            pompy_compatible: false,
            physical: false,
            flow_step: None,
            queries: 50,
            blocks: 2,
            seed: 3,
        }
    }

    #[test]
    fn a_short_pompy_run_reports_its_steps_and_filaments() {
        let mut last = (0, 0);
        let r = plume(&options(), &mut |done, total| last = (done, total))
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(last, (50, 50), "the end of stepping is reported");
        assert_eq!(r.steps_timed, 10);
        assert_eq!(r.ns_per_filament_step_blocks.len(), 2);
        assert!(r.final_live_filaments > 0 && r.mean_live_filaments > 0.0);
        assert!(
            r.pompy_compatible,
            "the pompy preset uses pompy's dispersion"
        );
        assert_eq!(r.release_rate_hz, 5.0);
        assert_eq!(r.crossflow_samples.len(), 3);
    }

    #[test]
    fn bad_options_are_refused_with_their_flag() {
        let refused = |o: PlumeBenchOptions| {
            plume(&o, &mut |_, _| {})
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default()
        };
        let e = refused(PlumeBenchOptions {
            dt: Some(-1.0),
            ..options()
        });
        assert_eq!(e, "--dt must be a finite number >= 0, got -1");
        let e = refused(PlumeBenchOptions {
            duration: Some(0.01),
            ..options()
        });
        assert_eq!(e, "--dt must be > 0 and --duration at least one step");
        let e = refused(PlumeBenchOptions {
            release_rate: Some(f64::NAN),
            ..options()
        });
        assert_eq!(e, "--release-rate must be a finite number >= 0, got NaN");
    }
}
