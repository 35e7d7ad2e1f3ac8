//! The reinforcement-learning environment's core, stepped in Rust: one mission per episode, the
//! agent flying one vehicle through the same `Planner` seam as every planner.
//!
//! The agent's planner is asked every `decision_period_s`; each environment step runs the
//! mission to the next decision. The action `(turn, speed)` in `[-1, 1]^2` becomes a heading
//! change of `turn * max_turn_deg` from the vehicle's measured heading and a speed from
//! `speed_min_mps` to `speed_max_mps`; it is applied at the next decision of the vehicle, one
//! decision period after the observation it answers (the vehicle's reaction time).
//!
//! The observation is what the vehicle knows, never the truth ([`OBS_NAMES`], bounds in
//! [`OBS_LOW`]/[`OBS_HIGH`]). The reward, which may use the truth (it is the experimenter's, not
//! the planner's): `-decision_period_s / time_limit_s` per step (a whole episode of waiting sums
//! to -1), `+detection_reward` for each step with a detection, `+1` and the end of the episode
//! (terminated) when the vehicle comes within `success_radius_m` of a source horizontally, `-1`
//! and the end (terminated) when it leaves the op-area or the mission ends otherwise (an
//! incident; a vehicle that starts outside the op-area may drive in first); truncated at the
//! scenario's time limit.

use crate::error::msg;
use crate::scenario::{Source, overrides};
use numpy::ndarray::Array2;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods,
};
use plumetrace_core::{
    Command, Decision, Heading, PlanStatus, Planner, SensorSnapshot, Vec2, VehicleKind,
    VerticalCommand,
};
use plumetrace_env::derive_seed;
use plumetrace_guidance::OpArea;
use plumetrace_mission::{EndReason, Mission, MissionOptions, MissionSetup, VehicleStatus};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::collections::VecDeque;
use std::sync::{Arc, Mutex};

/// Observation components, in order.
pub const OBS_NAMES: [&str; 12] = [
    "x_rel",
    "y_rel",
    "heading_sin",
    "heading_cos",
    "speed",
    "reading",
    "detection",
    "recent_detections",
    "since_detection",
    "flow_east",
    "flow_north",
    "time",
];
/// Lower bounds of the observation.
pub const OBS_LOW: [f32; 12] = [
    -2.0, -2.0, -1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, -2.0, -2.0, 0.0,
];
/// Upper bounds of the observation.
pub const OBS_HIGH: [f32; 12] = [2.0, 2.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 1.0];
/// Decisions over which `recent_detections` is the fraction with a detection.
const RECENT: usize = 10;
/// `since_detection` is the time since the last detection over this, capped at 1.
const SINCE_SCALE_S: f64 = 600.0;

/// What the agent's planner and the environment share.
#[derive(Default)]
struct Shared {
    action: [f64; 2],
    snapshot: Option<SensorSnapshot>,
    calls: u64,
}

/// The agent's side of the `Planner` seam.
struct AgentPlanner {
    shared: Arc<Mutex<Shared>>,
    settings: Settings,
    vertical: VerticalCommand,
}

impl Planner for AgentPlanner {
    fn decide(&mut self, snapshot: &SensorSnapshot) -> Decision {
        let mut s = match self.shared.lock() {
            Ok(s) => s,
            Err(p) => p.into_inner(),
        };
        let [turn, speed] = s.action;
        let st = &self.settings;
        let heading = Heading::from_deg(snapshot.nav.heading.deg() + turn * st.max_turn_deg);
        let speed_mps =
            st.speed_min_mps + 0.5 * (speed + 1.0) * (st.speed_max_mps - st.speed_min_mps);
        s.snapshot = Some(snapshot.clone());
        s.calls += 1;
        Decision::new(
            Command {
                heading,
                speed_mps,
                vertical: self.vertical,
            },
            PlanStatus::Running,
        )
    }

    fn decision_period_s(&self) -> f64 {
        self.settings.decision_period_s
    }
}

/// The environment's settings (documented in `plumetrace.gym`).
#[derive(Debug, Clone, Copy)]
struct Settings {
    vehicle: usize,
    decision_period_s: f64,
    max_turn_deg: f64,
    speed_min_mps: f64,
    speed_max_mps: f64,
    success_radius_m: f64,
    detection_reward: f64,
}

/// One episode in flight.
struct Episode {
    mission: Mission,
    shared: Arc<Mutex<Shared>>,
    threshold: f64,
    area: OpArea,
    centre: Vec2,
    half: Vec2,
    sources: Vec<Vec2>,
    recent: VecDeque<bool>,
    last_detection_s: Option<f64>,
    calls: u64,
    over: bool,
    entered: bool,
}

/// What one step gives back.
struct StepOut {
    obs: [f32; 12],
    reward: f64,
    terminated: bool,
    truncated: bool,
    success: bool,
    reason: &'static str,
}

struct Maker {
    source: Source,
    overrides: Vec<(String, toml::Value)>,
    settings: Settings,
    /// The spun-up environments of the last few seeds reset to, newest last: a reset to one of
    /// them starts from a copy (the same bits as spinning up again) instead of spinning up.
    spun: Mutex<VecDeque<(u64, plumetrace_env::Environment)>>,
}

/// How many spun-up environments a [`Maker`] keeps (a Duck-sized plume is about 2 MB).
const SPUN_UP_KEPT: usize = 8;

impl Maker {
    /// Spins `setup` up, or gives it a copy of the environment kept for `seed`.
    fn spin_up(&self, seed: u64, setup: &mut MissionSetup) -> Result<(), String> {
        let kept = {
            let spun = self
                .spun
                .lock()
                .map_err(|_| "the spin-up cache is poisoned")?;
            spun.iter()
                .find(|(s, _)| *s == seed)
                .and_then(|(_, env)| env.try_clone())
        };
        match kept {
            Some(env) => setup.use_spun_up(env),
            None => {
                setup.spin_up().map_err(|e| crate::error::located(&e))?;
                if let Some(copy) = setup.env.try_clone() {
                    let mut spun = self
                        .spun
                        .lock()
                        .map_err(|_| "the spin-up cache is poisoned")?;
                    spun.retain(|(s, _)| *s != seed);
                    spun.push_back((seed, copy));
                    while spun.len() > SPUN_UP_KEPT {
                        spun.pop_front();
                    }
                }
            }
        }
        Ok(())
    }

    fn episode(&self, seed: u64) -> Result<(Episode, [f32; 12]), String> {
        let sc = self
            .source
            .build(Some(seed), &self.overrides)
            .map_err(|e| e.to_string())?;
        let mut setup = MissionSetup::new(sc).map_err(|e| crate::error::located(&e))?;
        self.spin_up(seed, &mut setup)?;
        let k = self.settings.vehicle;
        let v = setup.vehicles.get(k).ok_or_else(|| {
            format!(
                "vehicle {k}: the scenario has {} vehicles",
                setup.vehicles.len()
            )
        })?;
        let planned = setup
            .planners
            .get(k)
            .and_then(Option::as_ref)
            .ok_or_else(|| format!("vehicle {k} ({}) has no planner table", v.name))?;
        let threshold = planned.config.detection_threshold_v().ok_or_else(|| {
            format!(
                "vehicle {k}'s planner ({}) has no detection threshold",
                planned.config.kind()
            )
        })?;
        let vertical = match v.vehicle.params.kind {
            VehicleKind::Surface => VerticalCommand::Surface,
            _ => VerticalCommand::Altitude(v.vehicle.state.z_m),
        };
        let area = setup.geometry.op_area.clone();
        let (x0, x1, y0, y1) = plumetrace_mission::record::bounds_of(area.vertices());
        let mut mission = Mission::new(
            setup,
            MissionOptions {
                mean_plume: false,
                trajectory: false,
                plume_frames_every_s: None,
            },
        )
        .map_err(|e| crate::error::located(&e))?;
        let shared = Arc::new(Mutex::new(Shared::default()));
        mission
            .replace_planner(
                k,
                Box::new(AgentPlanner {
                    shared: shared.clone(),
                    settings: self.settings,
                    vertical,
                }),
            )
            .map_err(|e| crate::error::located(&e))?;
        let sources = plumetrace_mission::record::true_sources(mission.world())
            .iter()
            .map(|s| s.xy())
            .collect();
        let mut ep = Episode {
            mission,
            shared,
            threshold,
            area,
            centre: Vec2::new(0.5 * (x0 + x1), 0.5 * (y0 + y1)),
            half: Vec2::new((0.5 * (x1 - x0)).max(1.0), (0.5 * (y1 - y0)).max(1.0)),
            sources,
            recent: VecDeque::with_capacity(RECENT),
            last_detection_s: None,
            calls: 0,
            over: false,
            entered: false,
        };
        let first = ep.advance(self.settings)?;
        Ok((ep, first.obs))
    }
}

impl Episode {
    /// Runs the mission to the agent's next decision and scores it.
    fn advance(&mut self, st: Settings) -> Result<StepOut, String> {
        let mut ended = None;
        loop {
            if let Some(end) = self.mission.step().map_err(|e| crate::error::located(&e))? {
                ended = Some(end);
                break;
            }
            let calls = self.shared.lock().map(|s| s.calls).unwrap_or(self.calls);
            if calls > self.calls {
                self.calls = calls;
                break;
            }
        }
        let snap = self
            .shared
            .lock()
            .ok()
            .and_then(|s| s.snapshot.clone())
            .ok_or_else(|| "the vehicle never reached a decision".to_string())?;
        let obs = self.observe(&snap);
        let detected = obs[6] > 0.5;
        let mut out = StepOut {
            obs,
            reward: -st.decision_period_s / self.mission.time_limit_s().max(1.0)
                + if detected { st.detection_reward } else { 0.0 },
            terminated: false,
            truncated: false,
            success: false,
            reason: "",
        };
        let truth = self.mission.world().vehicles()[st.vehicle]
            .vehicle
            .state
            .pos_m;
        // A vehicle may start outside the op-area (it drives in first): leaving counts only
        // once it has been inside.
        self.entered |= self.area.contains(truth);
        if self
            .sources
            .iter()
            .any(|s| (*s - truth).norm() <= st.success_radius_m)
        {
            out.reward += 1.0;
            out.terminated = true;
            out.success = true;
            out.reason = "reached_source";
        } else if ended.is_some_and(|e| !matches!(e.reason, EndReason::TimeLimit)) {
            // An incident (leaving the domain, a collision) names itself, even where the
            // vehicle also left the op-area.
            out.reward -= 1.0;
            out.terminated = true;
            out.reason = end_reason(self.mission.statuses(), st.vehicle);
        } else if !self.area.contains(truth) && self.entered {
            out.reward -= 1.0;
            out.terminated = true;
            out.reason = "left_op_area";
        } else if ended.is_some()
            || self.mission.time_s() + st.decision_period_s > self.mission.time_limit_s()
        {
            out.truncated = true;
            out.reason = "time_limit";
        }
        self.over = out.terminated || out.truncated;
        Ok(out)
    }

    fn observe(&mut self, s: &SensorSnapshot) -> [f32; 12] {
        let max_reading = s.chem.iter().map(|c| c.reading).fold(0.0_f64, f64::max);
        let detected = max_reading > self.threshold;
        if detected {
            self.last_detection_s = Some(s.time_s);
        }
        if self.recent.len() == RECENT {
            self.recent.pop_front();
        }
        self.recent.push_back(detected);
        let rel = s.nav.pos_m.map_or(Vec2::new(0.0, 0.0), |p| {
            Vec2::new(
                (p.x - self.centre.x) / self.half.x,
                (p.y - self.centre.y) / self.half.y,
            )
        });
        let h = s.nav.heading.rad();
        let flow = s.flow.map_or(Vec2::new(0.0, 0.0), |f| f.velocity_mps);
        let latest = s.chem.last().map_or(0.0, |c| c.reading);
        let raw = [
            rel.x,
            rel.y,
            h.sin(),
            h.cos(),
            s.nav.speed_mps / 3.0,
            (latest / self.threshold.max(1e-12)).tanh(),
            f64::from(u8::from(detected)),
            self.recent.iter().filter(|d| **d).count() as f64 / RECENT as f64,
            self.last_detection_s
                .map_or(1.0, |t| ((s.time_s - t) / SINCE_SCALE_S).min(1.0)),
            flow.x,
            flow.y,
            s.time_s / self.mission.time_limit_s().max(1.0),
        ];
        let mut obs = [0.0_f32; 12];
        for i in 0..12 {
            let v = if raw[i].is_finite() { raw[i] } else { 0.0 };
            obs[i] = (v as f32).clamp(OBS_LOW[i], OBS_HIGH[i]);
        }
        obs
    }

    fn act(&mut self, action: [f64; 2]) {
        if let Ok(mut s) = self.shared.lock() {
            s.action = action.map(|a| {
                if a.is_finite() {
                    a.clamp(-1.0, 1.0)
                } else {
                    0.0
                }
            });
        }
    }
}

/// Why the mission ended before its time limit, from the vehicles' statuses: the agent's own
/// end (`left_domain`, `collided`) or, failing that, the first other vehicle's.
fn end_reason(statuses: &[VehicleStatus], agent: usize) -> &'static str {
    let named = |s: &VehicleStatus| match s {
        VehicleStatus::LeftDomain => Some("left_domain"),
        VehicleStatus::Collided => Some("collided"),
        VehicleStatus::Aborted => Some("aborted"),
        VehicleStatus::Finished => Some("finished"),
        VehicleStatus::Active | VehicleStatus::NoPlanner => None,
    };
    statuses
        .get(agent)
        .and_then(named)
        .or_else(|| statuses.iter().find_map(named))
        .unwrap_or("mission_ended")
}

/// The environment's settings, as `gym.make` takes them.
pub const SETTINGS: [&str; 7] = [
    "vehicle",
    "decision_period_s",
    "max_turn_deg",
    "speed_min_mps",
    "speed_max_mps",
    "success_radius_m",
    "detection_reward",
];

fn settings<'py>(
    kw: Option<&Bound<'py, PyDict>>,
) -> PyResult<(Settings, Option<Bound<'py, PyDict>>)> {
    let mut st = Settings {
        vehicle: 0,
        decision_period_s: 1.0,
        max_turn_deg: 30.0,
        speed_min_mps: 0.3,
        speed_max_mps: 1.5,
        success_radius_m: 10.0,
        detection_reward: 0.01,
    };
    let rest = kw.map(|k| k.copy()).transpose()?;
    if let Some(d) = &rest {
        let take = |name: &str, lo: f64, hi: f64| -> PyResult<Option<f64>> {
            let Some(v) = d.get_item(name)? else {
                return Ok(None);
            };
            d.del_item(name)?;
            let x: f64 = v
                .extract()
                .map_err(|_| msg(format!("{name} = {v} is not a number")))?;
            if !(x.is_finite() && (lo..=hi).contains(&x)) {
                return Err(msg(format!("{name} = {x} is outside {lo}..={hi}")));
            }
            Ok(Some(x))
        };
        if let Some(x) = take("vehicle", 0.0, 1000.0)? {
            st.vehicle = x as usize;
        }
        if let Some(x) = take("decision_period_s", 0.1, 600.0)? {
            st.decision_period_s = x;
        }
        if let Some(x) = take("max_turn_deg", 0.0, 180.0)? {
            st.max_turn_deg = x;
        }
        if let Some(x) = take("speed_min_mps", 0.0, 10.0)? {
            st.speed_min_mps = x;
        }
        if let Some(x) = take("speed_max_mps", 0.0, 10.0)? {
            st.speed_max_mps = x;
        }
        if let Some(x) = take("success_radius_m", 0.0, 10_000.0)? {
            st.success_radius_m = x;
        }
        if let Some(x) = take("detection_reward", -1.0, 1.0)? {
            st.detection_reward = x;
        }
    }
    if st.speed_min_mps > st.speed_max_mps {
        return Err(msg(format!(
            "speed_min_mps = {} is above speed_max_mps = {}",
            st.speed_min_mps, st.speed_max_mps
        )));
    }
    Ok((st, rest))
}

fn maker(
    scenario: &str,
    set: Option<&Bound<'_, PyDict>>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<Maker> {
    let (settings, rest) = settings(kwargs)?;
    let maker = Maker {
        source: Source::open(scenario)?,
        overrides: overrides(set, rest.as_ref())?,
        settings,
        spun: Mutex::new(VecDeque::new()),
    };
    check_overrides(&maker, rest.as_ref())?;
    Ok(maker)
}

/// Builds the scenario and its mission once (without spinning up), so that a bad keyword fails
/// at `gym.make`, naming the environment's settings and the one a typo meant.
fn check_overrides(maker: &Maker, rest: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
    let built = maker
        .source
        .build(Some(0), &maker.overrides)
        .and_then(|sc| {
            MissionSetup::new(sc)
                .map(|_| ())
                .map_err(crate::error::to_py)
        });
    let Err(e) = built else { return Ok(()) };
    let keys: Vec<String> = rest
        .map(|d| d.keys().iter().filter_map(|k| k.extract().ok()).collect())
        .unwrap_or_default();
    let reason = Python::attach(|py| e.value(py).to_string());
    if keys.is_empty() {
        return Err(msg(reason));
    }
    for k in &keys {
        if let Some(near) = plumetrace_core::closest(k, &SETTINGS) {
            return Err(msg(format!(
                "{k}: not a setting of {ENV_ID}; did you mean {near}? (its settings: {}; any \
                 other keyword is a scenario override, and as one {k} fails: {reason})",
                SETTINGS.join(", ")
            )));
        }
    }
    Err(msg(format!(
        "{reason} (the settings of {ENV_ID} are {}; any other keyword is a scenario override)",
        SETTINGS.join(", ")
    )))
}

/// The registered environment's id.
const ENV_ID: &str = "plumetrace/PlumeTracing-v0";

fn info<'py>(py: Python<'py>, ep: &Episode, out: &StepOut) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("time_s", ep.mission.time_s())?;
    d.set_item("success", out.success)?;
    d.set_item("reason", out.reason)?;
    Ok(d)
}

/// One environment: `reset(seed)` builds the episode's mission (every random stream of the
/// episode comes from that seed), `step(action)` runs it to the agent's next decision.
#[pyclass(module = "plumetrace._plumetrace", unsendable)]
pub struct EnvCore {
    maker: Maker,
    episode: Option<Episode>,
}

#[pymethods]
impl EnvCore {
    /// An environment on `scenario` (a preset, a scenario file or a family file); keyword
    /// arguments are the environment's settings and then scenario overrides.
    #[new]
    #[pyo3(signature = (scenario, set=None, **kwargs))]
    fn new(
        scenario: &str,
        set: Option<&Bound<'_, PyDict>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        Ok(EnvCore {
            maker: maker(scenario, set, kwargs)?,
            episode: None,
        })
    }

    /// Observation component names.
    #[staticmethod]
    fn obs_names() -> Vec<&'static str> {
        OBS_NAMES.to_vec()
    }

    /// Observation bounds `(low, high)`.
    #[staticmethod]
    fn obs_bounds() -> (Vec<f32>, Vec<f32>) {
        (OBS_LOW.to_vec(), OBS_HIGH.to_vec())
    }

    /// The decision period, s.
    #[getter]
    fn decision_period_s(&self) -> f64 {
        self.maker.settings.decision_period_s
    }

    /// Starts an episode with run seed `seed`; returns the first observation.
    fn reset<'py>(&mut self, py: Python<'py>, seed: u64) -> PyResult<Bound<'py, PyArray1<f32>>> {
        self.episode = None;
        let maker = &self.maker;
        let (ep, obs) = py.detach(|| maker.episode(seed)).map_err(msg)?;
        self.episode = Some(ep);
        Ok(obs.to_vec().into_pyarray(py))
    }

    /// Applies `action` (turn, speed in [-1, 1]) and runs to the next decision; returns
    /// `(observation, reward, terminated, truncated, info)`.
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        action: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f32>>,
        f64,
        bool,
        bool,
        Bound<'py, PyDict>,
    )> {
        let a = action.as_array();
        if a.len() != 2 {
            return Err(msg(format!("the action has {} components, not 2", a.len())));
        }
        let ep = self
            .episode
            .as_mut()
            .ok_or_else(|| msg("call reset() before step()".to_string()))?;
        if ep.over {
            return Err(msg(
                "the episode is over (terminated or truncated): call reset()".to_string(),
            ));
        }
        ep.act([a[0], a[1]]);
        let settings = self.maker.settings;
        let out = py.detach(|| ep.advance(settings)).map_err(msg)?;
        let info = info(py, ep, &out)?;
        Ok((
            out.obs.to_vec().into_pyarray(py),
            out.reward,
            out.terminated,
            out.truncated,
            info,
        ))
    }
}

/// `n` environments stepped together in Rust (in parallel; results do not depend on the
/// thread count). An environment whose episode ended resets at the next step (that step's
/// action is ignored and its reward is 0), with the seed `derive_seed(base, episode index)`
/// of its own sequence.
#[pyclass(module = "plumetrace._plumetrace", unsendable)]
pub struct VecEnvCore {
    maker: Maker,
    episodes: Vec<Option<Episode>>,
    base_seeds: Vec<u64>,
    counts: Vec<u64>,
    needs_reset: Vec<bool>,
}

#[pymethods]
impl VecEnvCore {
    /// `n` environments on `scenario`, with settings and overrides as for `EnvCore`.
    #[new]
    #[pyo3(signature = (scenario, n, set=None, **kwargs))]
    fn new(
        scenario: &str,
        n: usize,
        set: Option<&Bound<'_, PyDict>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        if !(1..=4096).contains(&n) {
            return Err(msg(format!("n = {n} environments is outside 1..=4096")));
        }
        Ok(VecEnvCore {
            maker: maker(scenario, set, kwargs)?,
            episodes: (0..n).map(|_| None).collect(),
            base_seeds: vec![0; n],
            counts: vec![0; n],
            needs_reset: vec![true; n],
        })
    }

    /// Number of environments.
    #[getter]
    fn num_envs(&self) -> usize {
        self.episodes.len()
    }

    /// Resets every environment: environment `i` gets seed `seed + i` for this episode and
    /// derives its later episodes from it. Returns observations of shape `(n, 12)`.
    fn reset<'py>(&mut self, py: Python<'py>, seed: u64) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let n = self.episodes.len();
        for i in 0..n {
            self.base_seeds[i] = seed.wrapping_add(i as u64);
            self.counts[i] = 0;
        }
        let maker = &self.maker;
        let seeds = self.base_seeds.clone();
        let made: Vec<Result<(Episode, [f32; 12]), String>> =
            py.detach(|| seeds.par_iter().map(|s| maker.episode(*s)).collect());
        let mut flat = Vec::with_capacity(n * 12);
        for (i, m) in made.into_iter().enumerate() {
            let (ep, obs) = m.map_err(|e| msg(format!("environment {i}: {e}")))?;
            self.episodes[i] = Some(ep);
            self.needs_reset[i] = false;
            flat.extend_from_slice(&obs);
        }
        let a = Array2::from_shape_vec((n, 12), flat).map_err(|e| msg(e.to_string()))?;
        Ok(a.into_pyarray(py))
    }

    /// Steps every environment with `actions` of shape `(n, 2)`; returns `(observations,
    /// rewards, terminated, truncated, successes, reasons)` (a reason is empty while an episode
    /// goes on).
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
        Bound<'py, PyArray1<bool>>,
        Vec<&'static str>,
    )> {
        let n = self.episodes.len();
        let shape = actions.shape();
        if shape != [n, 2] {
            return Err(msg(format!(
                "actions must have shape ({n}, 2), not {shape:?}"
            )));
        }
        let acts = actions.as_array();
        let maker = &self.maker;
        let settings = maker.settings;
        let mut work: Vec<(usize, &mut Option<Episode>, bool, u64, [f64; 2])> = self
            .episodes
            .iter_mut()
            .enumerate()
            .map(|(i, ep)| {
                let seed = derive_seed(self.base_seeds[i], self.counts[i] + 1);
                (
                    i,
                    ep,
                    self.needs_reset[i],
                    seed,
                    [acts[[i, 0]], acts[[i, 1]]],
                )
            })
            .collect();
        type Out = Result<(StepOut, bool), String>;
        let outs: Vec<Out> = py.detach(|| {
            work.par_iter_mut()
                .map(|(_, ep, reset, seed, action)| -> Out {
                    if *reset || ep.is_none() {
                        let (e, obs) = maker.episode(*seed)?;
                        **ep = Some(e);
                        return Ok((
                            StepOut {
                                obs,
                                reward: 0.0,
                                terminated: false,
                                truncated: false,
                                success: false,
                                reason: "",
                            },
                            true,
                        ));
                    }
                    let e = ep.as_mut().ok_or("no episode")?;
                    e.act(*action);
                    Ok((e.advance(settings)?, false))
                })
                .collect()
        });
        drop(work);
        let mut flat = Vec::with_capacity(n * 12);
        let (mut rew, mut term, mut trunc, mut succ) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        let mut reasons = Vec::with_capacity(n);
        for (i, o) in outs.into_iter().enumerate() {
            let (out, was_reset) = o.map_err(|e| msg(format!("environment {i}: {e}")))?;
            if was_reset {
                self.counts[i] += 1;
            }
            self.needs_reset[i] = out.terminated || out.truncated;
            flat.extend_from_slice(&out.obs);
            rew.push(out.reward);
            term.push(out.terminated);
            trunc.push(out.truncated);
            succ.push(out.success);
            reasons.push(out.reason);
        }
        let obs = Array2::from_shape_vec((n, 12), flat).map_err(|e| msg(e.to_string()))?;
        Ok((
            obs.into_pyarray(py),
            rew.into_pyarray(py),
            term.into_pyarray(py),
            trunc.into_pyarray(py),
            succ.into_pyarray(py),
            reasons,
        ))
    }
}
