//! The reinforcement-learning environment's core, stepped in Rust: one mission per episode, the
//! agent flying one vehicle through the same `Planner` seam as every planner.
//!
//! The agent's planner is asked every `decision_period_s`; each environment step runs the
//! mission to the next decision. The action `(turn, speed, declare)` in `[-1, 1]^3` becomes a
//! heading change of `turn * max_turn_deg` from the vehicle's measured heading, a speed from
//! `speed_min_mps` to `speed_max_mps`, and, when `declare` is above `declare_threshold`, a
//! declaration of the source at the vehicle's position estimate; it is applied at the next
//! decision of the vehicle, one decision period after the observation it answers (the vehicle's
//! reaction time).
//!
//! The observation is what the vehicle knows, never the truth ([`OBS_NAMES`], bounds in
//! [`OBS_LOW`]/[`OBS_HIGH`]), built by [`Observer`] (which `ObsCore` gives Python, so a trained
//! policy flies through the Python planner seam on the same observations). The reward, which
//! may use the truth (it is the experimenter's, not the planner's): `-decision_period_s /
//! time_limit_s` per step (a whole episode of waiting sums to -1), `+detection_reward` for each
//! step with a detection until the episode's detection rewards reach `detection_reward_max`;
//! a declaration ends the episode (terminated) with `+1` when it lies within the success radius
//! of a source, `-1` otherwise; `-1` and the end (terminated) when the vehicle leaves the
//! op-area or the mission ends otherwise (an incident; a vehicle that starts outside the op-area
//! may drive in first); truncated at the scenario's time limit. So an episode with a correct
//! declaration returns at least 0, and any other at most `detection_reward_max - 1 +
//! decision_period_s / time_limit_s`: staying in the plume never pays as well as finding the
//! source.

use crate::error::msg;
use crate::scenario::{Source, overrides};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use plumetrace_core::{
    Command, Decision, DeclarationKind, Heading, PlanStatus, Planner, PlannerEvent, SensorSnapshot,
    Vec2, VehicleKind, VerticalCommand,
};
use plumetrace_guidance::OpArea;
use plumetrace_mission::{EndReason, Mission, MissionOptions, MissionSetup, VehicleStatus};
use pyo3::prelude::*;
use pyo3::types::PyDict;
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
    action: [f64; 3],
    snapshot: Option<SensorSnapshot>,
    calls: u64,
    /// Set at the decision that declares: the declared point (`None` without a position
    /// estimate, which counts as a false declaration).
    declared: Option<Option<Vec2>>,
}

/// The agent's side of the `Planner` seam.
struct AgentPlanner {
    shared: Arc<Mutex<Shared>>,
    settings: Settings,
    vertical: VerticalCommand,
}

/// The command an action gives at a decision with `snapshot`, and whether it declares.
fn command_of(
    st: &Settings,
    vertical: VerticalCommand,
    snapshot: &SensorSnapshot,
    [turn, speed, declare]: [f64; 3],
) -> (Command, bool) {
    let heading = Heading::from_deg(snapshot.nav.heading.deg() + turn * st.max_turn_deg);
    let speed_mps = st.speed_min_mps + 0.5 * (speed + 1.0) * (st.speed_max_mps - st.speed_min_mps);
    let command = Command {
        heading,
        speed_mps,
        vertical,
    };
    (command, declare > st.declare_threshold)
}

impl Planner for AgentPlanner {
    fn decide(&mut self, snapshot: &SensorSnapshot) -> Decision {
        let mut s = match self.shared.lock() {
            Ok(s) => s,
            Err(p) => p.into_inner(),
        };
        let (command, declare) = command_of(&self.settings, self.vertical, snapshot, s.action);
        s.snapshot = Some(snapshot.clone());
        s.calls += 1;
        let mut decision = Decision::new(command, PlanStatus::Running);
        if declare && s.declared.is_none() {
            s.declared = Some(snapshot.nav.pos_m);
            if let Some(p) = snapshot.nav.pos_m {
                decision.events.push(PlannerEvent::Declared {
                    pos_m: p,
                    rule: DeclarationKind::CUSTOM,
                });
            }
        }
        decision
    }

    fn decision_period_s(&self) -> f64 {
        self.settings.decision_period_s
    }
}

/// The environment's settings (documented in `plumetrace.gym`).
#[derive(Debug, Clone, Copy)]
pub struct Settings {
    vehicle: usize,
    decision_period_s: f64,
    max_turn_deg: f64,
    speed_min_mps: f64,
    speed_max_mps: f64,
    /// `None`: the scenario's `mission.success_radius_m`.
    success_radius_m: Option<f64>,
    detection_reward: f64,
    detection_reward_max: f64,
    declare_threshold: f64,
}

/// The observation of a vehicle's snapshots: what it knows, scaled to the bounds; it keeps the
/// recent detections, so one observer serves one episode.
pub struct Observer {
    threshold: f64,
    centre: Vec2,
    half: Vec2,
    time_limit_s: f64,
    recent: VecDeque<bool>,
    last_detection_s: Option<f64>,
}

impl Observer {
    /// The observer of vehicle `k` of `setup` (its planner's detection threshold, the op-area,
    /// the time limit), and the vertical command the agent keeps.
    fn of(setup: &MissionSetup, k: usize) -> Result<(Observer, VerticalCommand), String> {
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
        let (x0, x1, y0, y1) =
            plumetrace_mission::record::bounds_of(setup.geometry.op_area.vertices());
        let observer = Observer {
            threshold,
            centre: Vec2::new(0.5 * (x0 + x1), 0.5 * (y0 + y1)),
            half: Vec2::new((0.5 * (x1 - x0)).max(1.0), (0.5 * (y1 - y0)).max(1.0)),
            time_limit_s: setup.spec.time_limit_s,
            recent: VecDeque::with_capacity(RECENT),
            last_detection_s: None,
        };
        Ok((observer, vertical))
    }

    /// The observation of `s` (and it joins the recent detections).
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
            s.time_s / self.time_limit_s.max(1.0),
        ];
        let mut obs = [0.0_f32; 12];
        for i in 0..12 {
            let v = if raw[i].is_finite() { raw[i] } else { 0.0 };
            obs[i] = (v as f32).clamp(OBS_LOW[i], OBS_HIGH[i]);
        }
        obs
    }
}

/// One episode in flight.
pub(crate) struct Episode {
    mission: Mission,
    shared: Arc<Mutex<Shared>>,
    observer: Observer,
    area: OpArea,
    sources: Vec<Vec2>,
    radius_m: f64,
    seed: u64,
    bonus: f64,
    calls: u64,
    over: bool,
    entered: bool,
}

/// `error_m` without a declaration (or of one without a position estimate): -1, not NaN, so
/// that two equal episodes have equal `info` (as the checkers compare them).
pub(crate) const NO_ERROR: f64 = -1.0;

/// What `info` holds at every step and reset, in every vector mode.
#[derive(Debug, Clone, Copy)]
pub(crate) struct InfoRow {
    pub run_seed: u64,
    pub time_s: f64,
    pub success: bool,
    pub reason: &'static str,
    /// Distance of the declaration from the nearest source, m ([`NO_ERROR`] without one).
    pub error_m: f64,
}

impl InfoRow {
    /// The keys of `info`, in order.
    pub const KEYS: [&'static str; 5] = ["run_seed", "time_s", "success", "reason", "error_m"];

    pub fn to_dict<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("run_seed", self.run_seed)?;
        d.set_item("time_s", self.time_s)?;
        d.set_item("success", self.success)?;
        d.set_item("reason", self.reason)?;
        d.set_item("error_m", self.error_m)?;
        Ok(d)
    }
}

/// What one step gives back.
pub(crate) struct StepOut {
    pub obs: [f32; 12],
    pub reward: f64,
    pub terminated: bool,
    pub truncated: bool,
    pub info: InfoRow,
}

impl StepOut {
    /// The first observation of an episode, as a step's result (reward 0).
    pub fn first(ep: &Episode, obs: [f32; 12]) -> StepOut {
        StepOut {
            obs,
            reward: 0.0,
            terminated: false,
            truncated: false,
            info: ep.info(false, "", NO_ERROR),
        }
    }
}

pub(crate) struct Maker {
    source: Source,
    overrides: Vec<(String, toml::Value)>,
    pub settings: Settings,
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

    pub fn episode(&self, seed: u64) -> Result<(Episode, [f32; 12]), String> {
        let sc = self
            .source
            .build(Some(seed), &self.overrides)
            .map_err(|e| e.to_string())?;
        let mut setup = MissionSetup::new(sc).map_err(|e| crate::error::located(&e))?;
        self.spin_up(seed, &mut setup)?;
        let k = self.settings.vehicle;
        let (observer, vertical) = Observer::of(&setup, k)?;
        let radius_m = self
            .settings
            .success_radius_m
            .unwrap_or(setup.spec.success_radius_m);
        let area = setup.geometry.op_area.clone();
        let mut mission = Mission::new(
            setup,
            MissionOptions {
                mean_plume: false,
                trajectory: false,
                plume_frames_every_s: None,
                stage_times: false,
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
            observer,
            area,
            sources,
            radius_m,
            seed,
            bonus: 0.0,
            calls: 0,
            over: false,
            entered: false,
        };
        let first = ep.advance(self.settings)?;
        Ok((ep, first.obs))
    }
}

impl Episode {
    /// The `info` of this episode now.
    fn info(&self, success: bool, reason: &'static str, error_m: f64) -> InfoRow {
        InfoRow {
            run_seed: self.seed,
            time_s: self.mission.time_s(),
            success,
            reason,
            error_m,
        }
    }

    /// Runs the mission to the agent's next decision and scores it.
    pub fn advance(&mut self, st: Settings) -> Result<StepOut, String> {
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
        let (snap, declared) = self
            .shared
            .lock()
            .ok()
            .and_then(|mut s| Some((s.snapshot.clone()?, s.declared.take())))
            .ok_or_else(|| "the vehicle never reached a decision".to_string())?;
        let obs = self.observer.observe(&snap);
        let bonus = if obs[6] > 0.5 {
            st.detection_reward
                .min(st.detection_reward_max - self.bonus)
                .max(0.0)
        } else {
            0.0
        };
        self.bonus += bonus;
        let mut out = StepOut {
            obs,
            reward: -st.decision_period_s / self.mission.time_limit_s().max(1.0) + bonus,
            terminated: false,
            truncated: false,
            info: self.info(false, "", NO_ERROR),
        };
        let truth = self.mission.world().vehicles()[st.vehicle]
            .vehicle
            .state
            .pos_m;
        // A vehicle may start outside the op-area (it drives in first): leaving counts only
        // once it has been inside.
        self.entered |= self.area.contains(truth);
        if let Some(at) = declared {
            let error = at.and_then(|p| {
                self.sources
                    .iter()
                    .map(|s| (*s - p).norm())
                    .min_by(f64::total_cmp)
            });
            let error_m = error.unwrap_or(NO_ERROR);
            out.terminated = true;
            if error.is_some_and(|e| e <= self.radius_m) {
                out.reward += 1.0;
                out.info = self.info(true, "declared", error_m);
            } else {
                out.reward -= 1.0;
                out.info = self.info(false, "false_declaration", error_m);
            }
        } else if ended.is_some_and(|e| !matches!(e.reason, EndReason::TimeLimit)) {
            // An incident (leaving the domain, a collision) names itself, even where the
            // vehicle also left the op-area.
            out.reward -= 1.0;
            out.terminated = true;
            out.info.reason = end_reason(self.mission.statuses(), st.vehicle);
        } else if !self.area.contains(truth) && self.entered {
            out.reward -= 1.0;
            out.terminated = true;
            out.info.reason = "left_op_area";
        } else if ended.is_some()
            || self.mission.time_s() + st.decision_period_s > self.mission.time_limit_s()
        {
            out.truncated = true;
            out.info.reason = "time_limit";
        }
        self.over = out.terminated || out.truncated;
        Ok(out)
    }

    /// Sets the action the agent's next decision applies (non-finite components held at 0).
    pub fn act(&mut self, action: [f64; 3]) {
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
pub const SETTINGS: [&str; 9] = [
    "vehicle",
    "decision_period_s",
    "max_turn_deg",
    "speed_min_mps",
    "speed_max_mps",
    "success_radius_m",
    "detection_reward",
    "detection_reward_max",
    "declare_threshold",
];

pub(crate) fn settings<'py>(
    kw: Option<&Bound<'py, PyDict>>,
) -> PyResult<(Settings, Option<Bound<'py, PyDict>>)> {
    let mut st = Settings {
        vehicle: 0,
        decision_period_s: 1.0,
        max_turn_deg: 30.0,
        speed_min_mps: 0.3,
        speed_max_mps: 1.5,
        success_radius_m: None,
        detection_reward: 0.01,
        detection_reward_max: 0.2,
        declare_threshold: 0.5,
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
            st.success_radius_m = Some(x);
        }
        if let Some(x) = take("detection_reward", 0.0, 1.0)? {
            st.detection_reward = x;
        }
        // Below 1, so that no episode without a correct declaration returns as much as one with.
        if let Some(x) = take("detection_reward_max", 0.0, 0.9)? {
            st.detection_reward_max = x;
        }
        if let Some(x) = take("declare_threshold", -1.0, 1.0)? {
            st.declare_threshold = x;
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

pub(crate) fn maker(
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
const ENV_ID: &str = "plumetrace/PlumeTracing-v1";

/// Reads an action of three components (turn, speed, declare).
pub(crate) fn action3(a: &[f64]) -> PyResult<[f64; 3]> {
    match a {
        [t, s, d] => Ok([*t, *s, *d]),
        _ => Err(msg(format!(
            "the action has {} components, not 3 (turn, speed, declare)",
            a.len()
        ))),
    }
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

    /// The keys of `info`, at every reset and step.
    #[staticmethod]
    fn info_keys() -> Vec<&'static str> {
        InfoRow::KEYS.to_vec()
    }

    /// The decision period, s.
    #[getter]
    fn decision_period_s(&self) -> f64 {
        self.maker.settings.decision_period_s
    }

    /// Starts an episode with run seed `seed`; returns the first observation and `info`.
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: u64,
    ) -> PyResult<(Bound<'py, PyArray1<f32>>, Bound<'py, PyDict>)> {
        self.episode = None;
        let maker = &self.maker;
        let (ep, obs) = py.detach(|| maker.episode(seed)).map_err(msg)?;
        let info = StepOut::first(&ep, obs).info.to_dict(py)?;
        self.episode = Some(ep);
        Ok((obs.to_vec().into_pyarray(py), info))
    }

    /// Applies `action` (turn, speed, declare in [-1, 1]) and runs to the next decision;
    /// returns `(observation, reward, terminated, truncated, info)`.
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
        let a = action3(&action.as_array().to_vec())?;
        let ep = self
            .episode
            .as_mut()
            .ok_or_else(|| msg("call reset() before step()".to_string()))?;
        if ep.over {
            return Err(msg(
                "the episode is over (terminated or truncated): call reset()".to_string(),
            ));
        }
        ep.act(a);
        let settings = self.maker.settings;
        let out = py.detach(|| ep.advance(settings)).map_err(msg)?;
        Ok((
            out.obs.to_vec().into_pyarray(py),
            out.reward,
            out.terminated,
            out.truncated,
            out.info.to_dict(py)?,
        ))
    }
}

/// The environment's observation and command outside the environment, for a policy flown
/// through the Python planner seam: built for one scenario and run seed (the site of a family),
/// it turns each snapshot into the observation the environment gives and an action into the
/// command the environment's agent gives.
#[pyclass(module = "plumetrace._plumetrace", unsendable)]
pub struct ObsCore {
    settings: Settings,
    observer: Observer,
    vertical: VerticalCommand,
}

#[pymethods]
impl ObsCore {
    /// The observer of `scenario` at run seed `seed`, with the environment's settings and
    /// scenario overrides as for `EnvCore`.
    #[new]
    #[pyo3(signature = (scenario, seed, set=None, **kwargs))]
    fn new(
        scenario: &str,
        seed: u64,
        set: Option<&Bound<'_, PyDict>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let maker = maker(scenario, set, kwargs)?;
        let sc = maker.source.build(Some(seed), &maker.overrides)?;
        let setup = MissionSetup::new(sc).map_err(crate::error::to_py)?;
        let (observer, vertical) = Observer::of(&setup, maker.settings.vehicle).map_err(msg)?;
        Ok(ObsCore {
            settings: maker.settings,
            observer,
            vertical,
        })
    }

    /// The decision period, s.
    #[getter]
    fn decision_period_s(&self) -> f64 {
        self.settings.decision_period_s
    }

    /// The observation of a snapshot (JSON, the snapshot log's layout); it joins the recent
    /// detections, so call it once per decision.
    fn observe<'py>(
        &mut self,
        py: Python<'py>,
        snapshot: &str,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        let s = snapshot_of(snapshot)?;
        Ok(self.observer.observe(&s).to_vec().into_pyarray(py))
    }

    /// The command (a Python planner's dict) that `action` gives at the decision with
    /// `snapshot`: a declaration at the position estimate ends the vehicle's mission.
    fn command<'py>(
        &self,
        py: Python<'py>,
        snapshot: &str,
        action: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let s = snapshot_of(snapshot)?;
        let a = action3(&action.as_array().to_vec())?;
        let a = a.map(|x| {
            if x.is_finite() {
                x.clamp(-1.0, 1.0)
            } else {
                0.0
            }
        });
        let (c, declare) = command_of(&self.settings, self.vertical, &s, a);
        let d = PyDict::new(py);
        d.set_item("heading_deg", c.heading.deg())?;
        d.set_item("speed_mps", c.speed_mps)?;
        match c.vertical {
            VerticalCommand::Altitude(z) => d.set_item("altitude_m", z)?,
            VerticalCommand::Depth(z) => d.set_item("depth_m", z)?,
            VerticalCommand::Surface => d.set_item("surface", true)?,
        }
        if declare {
            if let Some(p) = s.nav.pos_m {
                d.set_item("declare", (p.x, p.y))?;
            }
            d.set_item("done", true)?;
        }
        Ok(d)
    }
}

fn snapshot_of(text: &str) -> PyResult<SensorSnapshot> {
    serde_json::from_str(text).map_err(|e| msg(format!("the snapshot is not a snapshot: {e}")))
}
