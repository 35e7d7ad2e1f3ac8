//! The build phase: turns a parsed [`ScenarioConfig`] into models, checking every value and
//! naming the key path of anything wrong.
//!
//! One module per section of the file, in the order the sections are built (the first error
//! found is the one reported): `timing` (`[sim]`, `mission.env_dt_s`), `domain`,
//! `bathymetry`, `flow`,
//! `plume` (with `[[sources]]`), `obstacles` (with `[[kelp]]`), `vehicles` (their `sensors` and
//! planners), `comms`, `mission` and `output`. Each section's key paths are spelled in its
//! module: the models' errors name only their own fields
//! ([`plumetrace_env::EnvError::under`]), and the section places them under its path. Every
//! number's own bound is the limits table's ([`crate::limits`]), checked before anything is
//! built; the sections check what involves several keys or a model's own validity.

mod bathymetry;
mod comms;
mod domain;
mod flow;
mod mission;
mod obstacles;
mod output;
mod plume;
mod sensors;
mod timing;
mod unused;
mod vehicles;

pub use mission::{DEFAULT_DROP_MARGIN_M, DEFAULT_SUCCESS_RADIUS_M};

use crate::config::ScenarioConfig;
use crate::{Origin, ScenarioError};
use plumetrace_core::Vec3;
use plumetrace_env::{EnvError, Environment, GridSpec, ObstacleSet};
use std::path::{Path, PathBuf};

/// What a plume run writes and how often it samples.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputSpec {
    /// The snapshot / time-average grid.
    pub grid: GridSpec,
    /// Steps between time-average samples.
    pub average_every_steps: u64,
    /// First step of the time average.
    pub average_start_step: u64,
    /// Intermittency threshold.
    pub threshold: f64,
    /// Probe points (z above the seabed), each inside the domain; empty: no probe series.
    pub probes: Vec<Vec3>,
    /// Steps between probe samples: every step that is a multiple of it, from the first.
    pub probe_every_steps: u64,
    /// Steps between filament snapshots; `None`: no filament series.
    pub filaments_every_steps: Option<u64>,
}

/// A vehicle ready to be put in a world: the truth at t = 0 and its navigation and sensors.
#[derive(Debug, Clone)]
pub struct VehicleSetup {
    /// Name for logs and plots.
    pub name: String,
    /// Dynamics and true initial state.
    pub vehicle: plumetrace_sim::Vehicle,
    /// Navigation.
    pub nav: plumetrace_sim::NavParams,
    /// Chemical sensor.
    pub chem_sensor: plumetrace_sim::ChemSensorParams,
    /// Flow sensor.
    pub flow_sensor: plumetrace_sim::FlowSensorParams,
    /// Obstacle range sensors, if fitted.
    pub range_sensor: Option<plumetrace_sim::RangeSensorParams>,
    /// The planner it flies, as written (checked by the planner registry when the mission is
    /// built); `None`: no planner, the vehicle keeps its last command.
    pub planner: Option<PlannerRef>,
    /// `[vehicles.chem_sensor] threshold_v`, if given: the detection threshold its planner gets.
    pub detection_threshold_v: Option<f64>,
    /// Mission time `[start, end)` in which its modem hears nothing, s.
    pub deaf_window_s: Option<(f64, f64)>,
}

/// A vehicle's planner table as written in the scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannerRef {
    /// Its key path: `planner` or `planners.NAME`.
    pub key: String,
    /// The table as written (`kind`, or the older `strategy`, and the planner's keys).
    pub table: toml::Table,
}

/// The mission part of a scenario (present when it has vehicles to fly).
#[derive(Debug, Clone, PartialEq)]
pub struct MissionSpec {
    /// Op-area polygon.
    pub op_area: Vec<plumetrace_core::Vec2>,
    /// Subregions searched in turn (empty: the whole op-area).
    pub subregions: Vec<Vec<plumetrace_core::Vec2>>,
    /// Time limit, s.
    pub time_limit_s: f64,
    /// Plume spin-up, s.
    pub spinup_s: f64,
    /// Spin-up step, s.
    pub spinup_dt_s: f64,
    /// Flow direction the planner assumes before measuring it, deg.
    pub prior_flow_toward_deg: f64,
    /// Whether the file gave it (otherwise it is North, 0).
    pub prior_flow_given: bool,
    /// A source counts as located when a declaration lies within this distance of it, m
    /// (`mission.success_radius_m`).
    pub success_radius_m: f64,
}

/// A scenario ready to run.
#[derive(Debug)]
pub struct BuiltScenario {
    /// Scenario name.
    pub name: String,
    /// The run seed actually used.
    pub seed: u64,
    /// The environment at t = 0.
    pub env: Environment,
    /// Number of steps to run.
    pub steps: u64,
    /// Output settings.
    pub output: OutputSpec,
    /// Vehicles, in the order of the file (their index is their `VehicleId`).
    pub vehicles: Vec<VehicleSetup>,
    /// The mission, if the scenario flies vehicles.
    pub mission: Option<MissionSpec>,
    /// Where the scenario came from (for errors found later, e.g. by the planner registry).
    pub origin: Origin,
    /// Message channels between vehicles.
    pub comms: plumetrace_sim::CommsParams,
    /// The vehicles' step, s (`sim.dt_s`; the environment may step more coarsely).
    pub dt_s: f64,
    /// Water depth, m.
    pub depth_m: Option<f64>,
    /// The site's origin in latitude and longitude (`[origin]`), for outputs in both frames.
    pub site: Option<plumetrace_core::geo::Origin>,
    /// Keys that have no effect in this kind of run (`check` and `run` print them).
    pub warnings: Vec<Warning>,
}

/// A key that has no effect in this kind of run (a mission or a plume run): the run goes on, and
/// `check` and `run` say so.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Warning {
    /// Key path, as errors name it.
    pub path: String,
    /// Why it has no effect and what to do instead.
    pub message: String,
}

impl Warning {
    fn new(path: impl Into<String>, message: impl Into<String>) -> Self {
        Warning {
            path: path.into(),
            message: message.into(),
        }
    }
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.path, self.message)
    }
}

/// A value out of range or inconsistent with another, by key path ([`build`] adds the file).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{path}: {message}")]
pub(crate) struct Invalid {
    /// Key path.
    pub path: String,
    /// What is wrong.
    pub message: String,
}

impl Invalid {
    /// The value at `path` is wrong.
    pub(crate) fn new(path: impl Into<String>, message: impl Into<String>) -> Self {
        Invalid {
            path: path.into(),
            message: message.into(),
        }
    }

    /// A model's error, placed under `path`: a parameter's key joined to it
    /// ([`plumetrace_env::error::join_key`]), any other error whole at `path`.
    pub(crate) fn env(path: &str, e: EnvError) -> Self {
        match e {
            EnvError::InvalidParameter { key, message } => Invalid {
                path: plumetrace_env::error::join_key(path, &key),
                message,
            },
            other => Invalid::new(path, other.to_string()),
        }
    }

    /// The error of the scenario from `origin`.
    fn at(self, origin: &Origin) -> ScenarioError {
        ScenarioError::Invalid {
            origin: origin.to_string(),
            line: None,
            path: self.path,
            message: self.message,
        }
    }
}

/// Builds a scenario; `seed` overrides the file's seed.
pub fn build(
    cfg: &ScenarioConfig,
    origin: &Origin,
    seed: Option<u64>,
) -> Result<BuiltScenario, ScenarioError> {
    build_sections(cfg, origin, seed).map_err(|e| e.at(origin))
}

/// [`build`], section by section.
fn build_sections(
    cfg: &ScenarioConfig,
    origin: &Origin,
    seed: Option<u64>,
) -> Result<BuiltScenario, Invalid> {
    // Every number and list within its documented bound (crate::limits) before anything is made.
    check_limits(cfg)?;
    let base_dir: PathBuf = match origin {
        Origin::File(p) => p.parent().map(Path::to_path_buf).unwrap_or_default(),
        Origin::Preset(_) => PathBuf::new(),
    };
    let seed = seed.unwrap_or(cfg.seed);
    let timing = timing::timing(cfg)?;
    let domain = domain::domain(&cfg.domain)?;
    let seabed = bathymetry::seabed(cfg, domain, &base_dir)?;
    let flow = flow::flow(cfg, domain, &base_dir, seabed.as_deref())?;
    let plume = plume::plume(cfg, domain, &base_dir, seabed.clone())?;
    let obstacles = obstacles::obstacles(cfg, seed)?;
    let vehicles = vehicles::vehicles(cfg, &domain, seabed.as_deref())?;
    obstacles::starts_clear(cfg, &obstacles)?;
    let comms = comms::comms(&cfg.comms)?;
    // The environment's step is `mission.env_dt_s` where given, else `sim.dt_s`.
    let env_dt_key = match cfg.mission.as_ref().and_then(|m| m.env_dt_s) {
        Some(_) => ("mission", "env_dt_s"),
        None => ("sim", "dt_s"),
    };
    let mut env = Environment::new(
        domain,
        flow,
        plume,
        ObstacleSet::new(obstacles),
        timing.env_dt_s,
        seed,
    )
    .map_err(|e| {
        let mut e = Invalid::env(env_dt_key.0, e.renamed(env_dt_key.1));
        if e.path == "sim.dt_s" && cfg.mission.is_some() {
            // The vehicles keep their step; the plume may take a longer one.
            e.message.push_str(
                " (in a mission, mission.env_dt_s steps the plume and flow apart from the \
                 vehicles)",
            );
        }
        e
    })?;
    let depth_m = seabed
        .as_ref()
        .map(|s| s.surface_m())
        .or(cfg.domain.depth_m);
    if seabed.is_some() {
        env.set_seabed(seabed);
    }
    timing.check_run_flow_steps(env.flow())?;
    let mission = mission::mission(cfg, &domain, &timing, &vehicles, &mut env)?;
    let output = output::output(cfg, &domain, &timing)?;
    let warnings = unused::unused_keys(cfg, mission.is_some());
    Ok(BuiltScenario {
        name: cfg.name.clone(),
        seed,
        env,
        steps: timing.steps,
        output,
        vehicles,
        mission,
        origin: origin.clone(),
        comms,
        dt_s: timing.dt_s,
        depth_m,
        site: cfg.origin,
        warnings,
    })
}

/// Every number and list of the scenario against [`crate::limits::LIMITS`].
fn check_limits(cfg: &ScenarioConfig) -> Result<(), Invalid> {
    match toml::Value::try_from(cfg) {
        Ok(toml::Value::Table(t)) => {
            crate::limits::check(&t).map_err(|e| Invalid::new(e.path, e.kind.to_string()))
        }
        Ok(_) => Ok(()),
        Err(e) => Err(Invalid::new("", format!("cannot be checked: {e}"))),
    }
}
