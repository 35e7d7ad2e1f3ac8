//! The build phase: turns a parsed [`ScenarioConfig`] into models, checking every value and
//! naming the key path of anything wrong.

use crate::config::{FlowKind, MeanFlowConfig, PlumeKind, ScenarioConfig, SeabedKind};
use crate::limits::show;
use crate::{Origin, ScenarioError};
use plumetrace_core::params::quoted_key;
use plumetrace_core::{Vec2, Vec3};
use plumetrace_env::flow::{FarrellFlow, GriddedFlow, MeanFlow, UniformFlow};
use plumetrace_env::plume::Dispersion;
use plumetrace_env::steady::{GaussianPlume, GriddedConcentration};
use plumetrace_env::{
    EnvError, Environment, FilamentParams, FilamentPlume, FlowModel, GridSpec, ObstacleSet, Plume,
    Rect, SoftObstacle, Source, VerticalBoundary,
};
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
    /// The table (`kind` and the planner's keys; a legacy `strategy` is read as `kind`).
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
}

/// Random stream of kelp field `k`: `StreamId::Custom(KELP_STREAM + k)`.
const KELP_STREAM: u64 = 0x6b65_6c70_0000;

/// Builds a scenario; `seed` overrides the file's seed.
pub fn build(
    cfg: &ScenarioConfig,
    origin: &Origin,
    seed: Option<u64>,
) -> Result<BuiltScenario, ScenarioError> {
    let invalid = |path: &str, message: String| ScenarioError::Invalid {
        origin: origin.to_string(),
        path: path.to_string(),
        message,
    };
    let env_err = |e: EnvError| match e {
        EnvError::InvalidParameter { key, message } => ScenarioError::Invalid {
            origin: origin.to_string(),
            path: key,
            message,
        },
        other => ScenarioError::Invalid {
            origin: origin.to_string(),
            path: String::new(),
            message: other.to_string(),
        },
    };
    let base_dir: PathBuf = match origin {
        Origin::File(p) => p.parent().map(Path::to_path_buf).unwrap_or_default(),
        Origin::Preset(_) => PathBuf::new(),
    };

    // Every number and list within its documented bound (crate::limits) before anything is made.
    match toml::Value::try_from(cfg) {
        Ok(toml::Value::Table(t)) => {
            crate::limits::check(&t).map_err(|(k, m)| invalid(&k, m))?;
        }
        Ok(_) => {}
        Err(e) => return Err(invalid("", format!("cannot be checked: {e}"))),
    }
    let dt_s = cfg.sim.dt_s;
    if !(dt_s.is_finite() && dt_s > 0.0) {
        return Err(invalid(
            "sim.dt_s",
            format!("must be a finite number > 0, got {dt_s:?}"),
        ));
    }
    let duration = cfg.sim.duration_s;
    if !(duration.is_finite() && duration >= dt_s) {
        return Err(invalid(
            "sim.duration_s",
            format!("must be a finite number >= sim.dt_s ({dt_s}), got {duration:?}"),
        ));
    }
    let env_dt_s = cfg
        .mission
        .as_ref()
        .and_then(|m| m.env_dt_s)
        .unwrap_or(dt_s);
    if let Some(m) = &cfg.mission
        && m.env_dt_s.is_some()
    {
        let ratio = env_dt_s / dt_s;
        if !(env_dt_s.is_finite() && ratio >= 1.0 - 1e-9 && (ratio - ratio.round()).abs() < 1e-9) {
            return Err(invalid(
                "mission.env_dt_s",
                format!("must be a whole multiple of sim.dt_s ({dt_s}), got {env_dt_s:?}"),
            ));
        }
    }
    let steps_f = (duration / dt_s).round();
    if steps_f > crate::limits::MAX_STEPS {
        return Err(invalid(
            "sim.duration_s",
            format!(
                "sim.duration_s / sim.dt_s = {steps_f:.3e} steps; at most {:.0e} (about a day of \
                 computing): shorten the run or lengthen the step",
                crate::limits::MAX_STEPS
            ),
        ));
    }
    let steps = steps_f as u64;

    let d = &cfg.domain;
    let domain = Rect::new(d.x_min_m, d.x_max_m, d.y_min_m, d.y_max_m).map_err(|e| match e {
        EnvError::InvalidParameter { key, message } => invalid(&format!("domain.{key}"), message),
        other => invalid("domain", other.to_string()),
    })?;
    if let Some(depth) = d.depth_m
        && !(depth.is_finite() && depth > 0.0)
    {
        return Err(invalid(
            "domain.depth_m",
            format!("must be a finite number > 0, got {depth:?}"),
        ));
    }

    let mean = |required: bool| -> Result<Option<MeanFlow>, ScenarioError> {
        match &cfg.flow.mean {
            Some(m) => mean_flow(m)
                .map(Some)
                .map_err(|(k, msg)| invalid(&format!("flow.mean.{k}"), msg)),
            None if required => Err(invalid(
                "flow.mean",
                format!(
                    "flow model '{:?}' needs a [flow.mean] table",
                    cfg.flow.model
                )
                .to_lowercase(),
            )),
            None => Ok(None),
        }
    };
    let flow = match cfg.flow.model {
        FlowKind::Uniform => {
            if cfg.flow.farrell.is_some() {
                return Err(invalid(
                    "flow.farrell",
                    "only applies to model = \"farrell\"".into(),
                ));
            }
            let m = mean(true)?.ok_or_else(|| invalid("flow.mean", "missing".into()))?;
            FlowModel::Uniform(UniformFlow::new(m).map_err(env_err)?)
        }
        FlowKind::Farrell => {
            let m = mean(true)?.ok_or_else(|| invalid("flow.mean", "missing".into()))?;
            let params = cfg.flow.farrell.unwrap_or_default();
            FlowModel::Farrell(Box::new(
                FarrellFlow::substepped(domain, m, params).map_err(env_err)?,
            ))
        }
        FlowKind::Gridded => {
            let Some(file) = &cfg.flow.file else {
                return Err(invalid(
                    "flow.file",
                    "model = \"gridded\" needs a file (CSV: x_m,y_m,u_mps,v_mps[,t_s])".into(),
                ));
            };
            FlowModel::Gridded(Box::new(
                GriddedFlow::from_csv(&base_dir.join(file))
                    .map_err(|e| invalid("flow.file", e.to_string()))?,
            ))
        }
    };
    if cfg.flow.file.is_some() && cfg.flow.model != FlowKind::Gridded {
        return Err(invalid(
            "flow.file",
            "only applies to model = \"gridded\"".into(),
        ));
    }

    let p = &cfg.plume;
    let vertical = match p.seabed {
        SeabedKind::Reflecting => VerticalBoundary::Reflecting { depth_m: d.depth_m },
        SeabedKind::None => VerticalBoundary::Unbounded,
    };
    let sources: Vec<Source> = cfg
        .sources
        .iter()
        .map(|s| Source {
            pos_m: Vec3::new(s.x_m, s.y_m, s.z_m),
            mass_rate_per_s: s.mass_rate_per_s,
            filament_rate_hz: s.filament_rate_hz,
        })
        .collect();
    if sources.is_empty() && p.model != PlumeKind::Gridded {
        return Err(invalid(
            "sources",
            "at least one [[sources]] entry is needed".into(),
        ));
    }
    let plume = match p.model {
        PlumeKind::Filaments => {
            let dispersion = if p.pompy_compatible {
                Dispersion::PompyCompatible {
                    scale_mps: [p.pompy_diff_scale_mps; 3],
                }
            } else {
                Dispersion::Physical {
                    horizontal_m2ps: p.horizontal_diffusivity_m2ps,
                    vertical_m2ps: p.vertical_diffusivity_m2ps,
                }
            };
            let params = FilamentParams {
                dispersion,
                init_radius_m: p.init_radius_m,
                growth_rate_m2ps: p.growth_rate_m2ps,
                cutoff_radii: p.cutoff_radii,
                max_filaments: p.max_filaments,
                vertical,
            };
            if p.initial_filaments.saturating_mul(sources.len() as u64) > p.max_filaments as u64 {
                return Err(invalid(
                    "plume.initial_filaments",
                    format!(
                        "{} per source for {} sources is more than plume.max_filaments ({})",
                        p.initial_filaments,
                        sources.len(),
                        p.max_filaments
                    ),
                ));
            }
            let mut fp = FilamentPlume::new(domain, sources, params).map_err(env_err)?;
            for k in 0..fp.sources().len() {
                fp.release_at_source(k, p.initial_filaments);
            }
            Plume::Filaments(Box::new(fp))
        }
        PlumeKind::Gaussian => {
            let m = mean(true)?.ok_or_else(|| invalid("flow.mean", "missing".into()))?;
            let v = m.velocity_at(0.0);
            let toward = plumetrace_core::Heading::of_vector(v).ok_or_else(|| {
                invalid(
                    "flow.mean",
                    "the gaussian plume needs a non-zero current".into(),
                )
            })?;
            if sources.len() > 1 {
                return Err(invalid(
                    "sources",
                    "the gaussian plume takes exactly one source".into(),
                ));
            }
            let s = sources[0];
            for (key, k) in [
                (
                    "plume.horizontal_diffusivity_m2ps",
                    p.horizontal_diffusivity_m2ps,
                ),
                (
                    "plume.vertical_diffusivity_m2ps",
                    p.vertical_diffusivity_m2ps,
                ),
            ] {
                if k < 1e-6 {
                    return Err(invalid(
                        key,
                        format!(
                            "the steady plume needs at least 1e-6 m^2/s (its width goes as the \
                             square root of it), got {k:?}"
                        ),
                    ));
                }
            }
            let g = GaussianPlume::new(
                s.pos_m,
                s.mass_rate_per_s,
                v.norm(),
                toward.deg(),
                p.horizontal_diffusivity_m2ps,
                p.vertical_diffusivity_m2ps,
                d.depth_m,
            )
            .map_err(|e| match e {
                EnvError::InvalidParameter { key, message } => invalid(
                    &key.replace("source.", "sources[0].")
                        .replace("flow.", "flow.mean."),
                    message,
                ),
                other => invalid("plume", other.to_string()),
            })?;
            Plume::Steady(Box::new(g))
        }
        PlumeKind::Gridded => {
            let Some(file) = &p.file else {
                return Err(invalid(
                    "plume.file",
                    "model = \"gridded\" needs a file (CSV: x_m,y_m[,z_m],concentration)".into(),
                ));
            };
            let g = GriddedConcentration::from_csv(&base_dir.join(file))
                .map_err(|e| invalid("plume.file", e.to_string()))?;
            Plume::Steady(Box::new(g))
        }
    };

    let mut obstacles = Vec::new();
    for (k, o) in cfg.obstacles.iter().enumerate() {
        let key = format!("obstacles[{k}]");
        let name = if o.name.is_empty() {
            key.clone()
        } else {
            o.name.clone()
        };
        obstacles.push(SoftObstacle::new(name, &o.vertices, &key).map_err(env_err)?);
    }
    let run_seed = seed.unwrap_or(cfg.seed);
    for (k, f) in cfg.kelp.iter().enumerate() {
        let key = format!("kelp[{k}]");
        let name = if f.name.is_empty() {
            key.clone()
        } else {
            f.name.clone()
        };
        let [r_lo, r_hi] = f.radius_m;
        if !(r_lo > 0.0 && r_hi >= r_lo) {
            return Err(invalid(
                &format!("{key}.radius_m"),
                format!("needs 0 < smallest <= largest, got [{r_lo}, {r_hi}]"),
            ));
        }
        if !(0.0..1.0).contains(&f.roughness) {
            return Err(invalid(
                &format!("{key}.roughness"),
                format!("must be in [0, 1), got {}", f.roughness),
            ));
        }
        if f.vertices < 3 {
            return Err(invalid(
                &format!("{key}.vertices"),
                format!("needs at least 3, got {}", f.vertices),
            ));
        }
        let keep_clear: Vec<(Vec2, f64)> = cfg
            .sources
            .iter()
            .map(|s| Vec2::new(s.x_m, s.y_m))
            .chain(cfg.vehicles.iter().map(|v| Vec2::new(v.x_m, v.y_m)))
            .map(|c| (c, f.clear_m))
            .collect();
        let params = plumetrace_env::KelpFieldParams {
            region: f.region.clone(),
            patches: f.patches,
            radius_m: f.radius_m,
            gap_m: f.gap_m,
            vertices: f.vertices,
            roughness: f.roughness,
        };
        let mut rng = plumetrace_env::stream_rng(
            f.seed.unwrap_or(run_seed),
            plumetrace_env::StreamId::Custom(KELP_STREAM + k as u64),
        );
        obstacles.extend(
            plumetrace_env::kelp_field(&params, &keep_clear, &name, &key, &mut rng)
                .map_err(env_err)?,
        );
    }

    let legacy = match &cfg.planner {
        Some(t) => Some(legacy_planner(t).map_err(|(k, m)| invalid(&k, m))?),
        None => None,
    };
    let mut vehicles = Vec::new();
    for (k, v) in cfg.vehicles.iter().enumerate() {
        let mut setup = vehicle_setup(v, k, &domain, d.depth_m).map_err(|e| match e {
            EnvError::InvalidParameter { key, message } => invalid(&key, message),
            other => invalid(&format!("vehicles[{k}]"), other.to_string()),
        })?;
        setup.planner = match &v.planner {
            Some(name) => {
                let table = cfg.planners.get(name).ok_or_else(|| {
                    let known: Vec<&str> = cfg.planners.keys().map(String::as_str).collect();
                    invalid(
                        &format!("vehicles[{k}].planner"),
                        if known.is_empty() {
                            format!(
                                "no [planners.{}] table (the scenario defines none)",
                                quoted_key(name)
                            )
                        } else {
                            format!(
                                "no [planners.{}] table (defined: {})",
                                quoted_key(name),
                                known.join(", ")
                            )
                        },
                    )
                })?;
                Some(PlannerRef {
                    key: format!("planners.{}", quoted_key(name)),
                    table: table.clone(),
                })
            }
            None if v.kind == plumetrace_core::VehicleKind::Auv => legacy.clone(),
            None => None,
        };
        vehicles.push(setup);
    }
    if cfg.planner.is_some()
        && !cfg
            .vehicles
            .iter()
            .any(|v| v.planner.is_none() && v.kind == plumetrace_core::VehicleKind::Auv)
    {
        return Err(invalid(
            "planner",
            "no vehicle flies it: [planner] is for the AUVs that name no planner, and every AUV \
             names one (or there is none); remove it or name it as [planners.NAME]"
                .into(),
        ));
    }
    if let Some(name) = cfg.planners.keys().find(|n| {
        !cfg.vehicles
            .iter()
            .any(|v| v.planner.as_deref() == Some(n.as_str()))
    }) {
        return Err(invalid(
            &format!("planners.{}", quoted_key(name)),
            "no vehicle flies it (name it in a vehicle: planner = \"NAME\")".into(),
        ));
    }
    let comms = plumetrace_sim::CommsParams {
        acoustic: channel(cfg.comms.acoustic.as_ref()),
        radio: channel(cfg.comms.radio.as_ref()),
        ranging: {
            let d = plumetrace_sim::RangingParams::default();
            cfg.comms
                .ranging
                .as_ref()
                .map_or(d, |r| plumetrace_sim::RangingParams {
                    timing_noise_sd_s: r.timing_noise_sd_s.unwrap_or(d.timing_noise_sd_s),
                    sound_speed_mps: r.sound_speed_mps.unwrap_or(d.sound_speed_mps),
                })
        },
    };
    comms
        .acoustic
        .validate("comms.acoustic")
        .and_then(|()| comms.radio.validate("comms.radio"))
        .and_then(|()| comms.ranging.validate("comms.ranging"))
        .map_err(env_err)?;

    let seed = seed.unwrap_or(cfg.seed);
    let mut env = Environment::new(
        domain,
        flow,
        plume,
        ObstacleSet::new(obstacles),
        env_dt_s,
        seed,
    )
    .map_err(env_err)?;
    // The flow takes sub-steps within its stable limit: bound the run's number of them.
    let flow_steps = duration / env_dt_s
        * plumetrace_env::environment::flow_substeps(env.flow(), env_dt_s) as f64;
    if flow_steps > crate::limits::MAX_STEPS {
        return Err(invalid(
            "flow.farrell",
            format!(
                "the flow grid's stable step is {:.4e} s, so the run would take {flow_steps:.3e} \
                 flow steps; at most {:.0e}: use a coarser grid or larger diffusivities",
                plumetrace_env::FlowField::max_stable_dt_s(env.flow()).unwrap_or(f64::INFINITY),
                crate::limits::MAX_STEPS
            ),
        ));
    }

    let flown = vehicles.iter().any(|v| v.planner.is_some());
    let mission = match &cfg.mission {
        None => {
            if flown {
                return Err(invalid(
                    "mission",
                    "a scenario with vehicles and a planner needs a [mission] table".into(),
                ));
            }
            None
        }
        Some(m) => Some(
            mission_spec(m, &domain, env_dt_s, dt_s, env.flow()).map_err(|e| match e {
                EnvError::InvalidParameter { key, message } => invalid(&key, message),
                other => invalid("mission", other.to_string()),
            })?,
        ),
    };
    if let (Some(spec), Some(m), Some(mean)) = (&mission, &cfg.mission, mean(false)?)
        && !matches!(cfg.flow.model, FlowKind::Gridded)
        && vehicles.iter().all(|v| v.planner.is_some())
        && let plumetrace_env::Plume::Filaments(plume) = env.plume_mut()
    {
        let starts: Vec<Vec2> = vehicles.iter().map(|v| v.vehicle.state.pos_m).collect();
        let margin = m.drop_margin_m.unwrap_or(DEFAULT_DROP_MARGIN_M);
        plume.set_sink(downflow_sink(&mean, spec, &starts, margin));
    }
    if mission.is_some() && !flown {
        return Err(invalid(
            if cfg.vehicles.is_empty() {
                "vehicles"
            } else {
                "planner"
            },
            "a [mission] needs a vehicle with a planner: a [planner] table (flown by every AUV) \
             or [planners.NAME] tables named by vehicles (planner = \"NAME\")"
                .into(),
        ));
    }

    let o = &cfg.output;
    let grid = GridSpec {
        x_min_m: d.x_min_m,
        x_max_m: d.x_max_m,
        y_min_m: d.y_min_m,
        y_max_m: d.y_max_m,
        nx: o.nx,
        ny: o.ny,
        z_m: o.z_m,
    };
    grid.validate("output").map_err(env_err)?;
    if !(o.average_interval_s.is_finite() && o.average_interval_s >= dt_s) {
        return Err(invalid(
            "output.average_interval_s",
            format!(
                "must be >= sim.dt_s ({dt_s}), got {:?}",
                o.average_interval_s
            ),
        ));
    }
    if !(o.average_start_s.is_finite() && o.average_start_s >= 0.0 && o.average_start_s < duration)
    {
        return Err(invalid(
            "output.average_start_s",
            format!(
                "must be in [0, sim.duration_s), got {:?}",
                o.average_start_s
            ),
        ));
    }
    if !(o.threshold.is_finite() && o.threshold >= 0.0) {
        return Err(invalid(
            "output.threshold",
            format!("must be a finite number >= 0, got {:?}", o.threshold),
        ));
    }
    let series = series_spec(cfg, &domain, dt_s, steps).map_err(|(k, m)| invalid(&k, m))?;
    let output = OutputSpec {
        grid,
        average_every_steps: ((o.average_interval_s / dt_s).round() as u64).max(1),
        average_start_step: (o.average_start_s / dt_s).round() as u64,
        threshold: o.threshold,
        probes: series.probes,
        probe_every_steps: series.probe_every_steps,
        filaments_every_steps: series.filaments_every_steps,
    };
    Ok(BuiltScenario {
        name: cfg.name.clone(),
        seed,
        env,
        steps,
        output,
        vehicles,
        mission,
        origin: origin.clone(),
        comms,
        dt_s,
        depth_m: d.depth_m,
    })
}

/// The probe and filament series of `[output]`, checked.
struct SeriesSpec {
    probes: Vec<Vec3>,
    probe_every_steps: u64,
    filaments_every_steps: Option<u64>,
}

/// Checks `output.probes`, `output.probe_interval_s` and `output.filaments_interval_s` of a
/// scenario that has passed [`crate::limits`] and whose time average has been checked; `steps`
/// of `dt_s` make the run. On error returns `(key, message)`.
fn series_spec(
    cfg: &ScenarioConfig,
    domain: &Rect,
    dt_s: f64,
    steps: u64,
) -> Result<SeriesSpec, (String, String)> {
    let o = &cfg.output;
    let depth_m = cfg.domain.depth_m;
    let duration_s = cfg.sim.duration_s;
    let to_steps = |s: f64| ((s / dt_s).round() as u64).max(1);
    if cfg.mission.is_some() {
        let given = [
            ("output.probes", !o.probes.is_empty()),
            ("output.probe_interval_s", o.probe_interval_s.is_some()),
            (
                "output.filaments_interval_s",
                o.filaments_interval_s.is_some_and(|s| s != 0.0),
            ),
        ];
        if let Some((key, _)) = given.iter().find(|(_, g)| *g) {
            return Err((
                (*key).into(),
                "probe and filament series are written by plume runs only (a scenario without \
                 [mission]); a mission records its own outputs"
                    .into(),
            ));
        }
    }

    let mut probes = Vec::with_capacity(o.probes.len());
    for (k, &[x, y, z]) in o.probes.iter().enumerate() {
        let key = format!("output.probes[{k}]");
        let at = format!("[{}, {}, {}]", show(x), show(y), show(z));
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            return Err((
                key,
                format!("{at} is not a point (every coordinate finite)"),
            ));
        }
        if !domain.contains_xy(x, y) {
            return Err((
                key,
                format!(
                    "{at} is outside the domain ({}..{} East, {}..{} North)",
                    show(domain.x_min_m),
                    show(domain.x_max_m),
                    show(domain.y_min_m),
                    show(domain.y_max_m)
                ),
            ));
        }
        if z < 0.0 || depth_m.is_some_and(|h| z > h) {
            return Err((
                key,
                match depth_m {
                    Some(h) => format!(
                        "{at}: z_m (height above the seabed) must be in [0, domain.depth_m = {}]",
                        show(h)
                    ),
                    None => format!("{at}: z_m (height above the seabed) must be >= 0"),
                },
            ));
        }
        probes.push(Vec3::new(x, y, z));
    }

    let probe_interval_s = o.probe_interval_s.unwrap_or(o.average_interval_s);
    let probe_every_steps = to_steps(probe_interval_s);
    if o.probe_interval_s.is_some() || !probes.is_empty() {
        let default = if o.probe_interval_s.is_none() {
            " (its default, output.average_interval_s)".to_string()
        } else {
            String::new()
        };
        if !(probe_interval_s.is_finite()
            && probe_interval_s >= dt_s
            && probe_interval_s <= duration_s)
        {
            return Err((
                "output.probe_interval_s".into(),
                format!(
                    "must be in [sim.dt_s, sim.duration_s] = [{}, {}] so that the probes are \
                     sampled at least once, got {}{default}",
                    show(dt_s),
                    show(duration_s),
                    show(probe_interval_s)
                ),
            ));
        }
        let rows = (steps / probe_every_steps).saturating_mul(probes.len() as u64);
        if rows > crate::limits::MAX_PROBE_ROWS {
            return Err((
                "output.probe_interval_s".into(),
                format!(
                    "{} samples x {} probes = {rows} rows of probes.csv; at most {}: lengthen \
                     the interval{default} or use fewer probes",
                    steps / probe_every_steps,
                    probes.len(),
                    crate::limits::MAX_PROBE_ROWS
                ),
            ));
        }
    }

    // 0 is the same as absent: no snapshots.
    let filaments_every_steps = match o.filaments_interval_s.filter(|&s| s != 0.0) {
        None => None,
        Some(s) => {
            let key = "output.filaments_interval_s";
            if !(s.is_finite() && s >= dt_s && s <= duration_s) {
                return Err((
                    key.into(),
                    format!(
                        "must be 0 (no snapshots) or in [sim.dt_s, sim.duration_s] = [{}, {}], \
                         got {}",
                        show(dt_s),
                        show(duration_s),
                        show(s)
                    ),
                ));
            }
            if cfg.plume.model != PlumeKind::Filaments {
                return Err((
                    key.into(),
                    "a steady plume (plume.model = \"gaussian\" or \"gridded\") has no \
                     filaments; remove it or use plume.model = \"filaments\""
                        .into(),
                ));
            }
            let every = to_steps(s);
            let snapshots = steps / every;
            if snapshots > crate::limits::MAX_FILAMENT_SNAPSHOTS {
                return Err((
                    key.into(),
                    format!(
                        "sim.duration_s / {} = {snapshots} snapshots of every filament; at most \
                         {}: lengthen the interval",
                        show(s),
                        crate::limits::MAX_FILAMENT_SNAPSHOTS
                    ),
                ));
            }
            Some(every)
        }
    };
    Ok(SeriesSpec {
        probes,
        probe_every_steps,
        filaments_every_steps,
    })
}

/// Interprets `[flow.mean]`: steady or tidal; on error returns `(key, message)`.
fn mean_flow(m: &MeanFlowConfig) -> Result<MeanFlow, (String, String)> {
    let tidal_keys = [
        m.speed_min_mps,
        m.speed_max_mps,
        m.toward_min_deg,
        m.toward_max_deg,
        m.period_s,
        m.phase_deg,
    ];
    let any_tidal = tidal_keys.iter().any(Option::is_some);
    let any_steady = m.speed_mps.is_some() || m.toward_deg.is_some();
    let mean = match (any_steady, any_tidal) {
        (true, true) => {
            return Err((
                "speed_mps".into(),
                "give either speed_mps and toward_deg (steady) or the tidal keys, not both".into(),
            ));
        }
        (false, false) => {
            return Err(("speed_mps".into(), "give speed_mps and toward_deg (steady) or speed_min_mps, speed_max_mps, toward_min_deg, toward_max_deg, period_s (tidal)".into()));
        }
        (true, false) => MeanFlow::Steady {
            speed_mps: m
                .speed_mps
                .ok_or(("speed_mps".to_string(), "missing".to_string()))?,
            toward_deg: m
                .toward_deg
                .ok_or(("toward_deg".to_string(), "missing".to_string()))?,
        },
        (false, true) => {
            let need = |v: Option<f64>, k: &str| {
                v.ok_or((
                    k.to_string(),
                    "missing (needed for a tidal mean flow)".to_string(),
                ))
            };
            MeanFlow::Tidal {
                speed_min_mps: need(m.speed_min_mps, "speed_min_mps")?,
                speed_max_mps: need(m.speed_max_mps, "speed_max_mps")?,
                toward_min_deg: need(m.toward_min_deg, "toward_min_deg")?,
                toward_max_deg: need(m.toward_max_deg, "toward_max_deg")?,
                period_s: need(m.period_s, "period_s")?,
                phase_deg: m.phase_deg.unwrap_or(0.0),
            }
        }
    };
    mean.validate("flow.mean").map_err(|e| match e {
        EnvError::InvalidParameter { key, message } => {
            (key.trim_start_matches("flow.mean.").to_string(), message)
        }
        other => ("speed_mps".into(), other.to_string()),
    })?;
    Ok(mean)
}

/// Builds one vehicle, filling omitted parameters with its kind's defaults.
fn vehicle_setup(
    v: &crate::config::VehicleConfig,
    k: usize,
    domain: &Rect,
    depth_m: Option<f64>,
) -> Result<VehicleSetup, EnvError> {
    use plumetrace_core::{Heading, Vec2, VehicleId, VehicleKind};
    use plumetrace_sim::{
        ChemSensorParams, FlowFault, FlowSensorParams, NavParams, RangeSensorParams, Vehicle,
        VehicleParams,
    };
    let key = format!("vehicles[{k}]");
    plumetrace_env::error::require_finite(&format!("{key}.x_m"), v.x_m)?;
    plumetrace_env::error::require_finite(&format!("{key}.y_m"), v.y_m)?;
    plumetrace_env::error::require_finite(&format!("{key}.heading_deg"), v.heading_deg)?;
    if !domain.contains_xy(v.x_m, v.y_m) {
        let off_x = v.x_m < domain.x_min_m || v.x_m > domain.x_max_m;
        return Err(EnvError::invalid(
            format!("{key}.{}", if off_x { "x_m" } else { "y_m" }),
            format!(
                "start ({}, {}) is outside the domain ({}..{} East, {}..{} North)",
                v.x_m, v.y_m, domain.x_min_m, domain.x_max_m, domain.y_min_m, domain.y_max_m
            ),
        ));
    }
    let base = match v.kind {
        VehicleKind::Auv => VehicleParams::auv(),
        VehicleKind::Surface => VehicleParams::surface(),
    };
    let dy = &v.dynamics;
    let params = VehicleParams {
        kind: v.kind,
        max_speed_mps: dy.max_speed_mps.unwrap_or(base.max_speed_mps),
        max_turn_rate_deg_s: dy.max_turn_rate_deg_s.unwrap_or(base.max_turn_rate_deg_s),
        speed_time_constant_s: dy
            .speed_time_constant_s
            .unwrap_or(base.speed_time_constant_s),
        vertical_time_constant_s: dy
            .vertical_time_constant_s
            .unwrap_or(base.vertical_time_constant_s),
        altitude_error_sd_m: dy.altitude_error_sd_m.unwrap_or(base.altitude_error_sd_m),
        altitude_error_time_s: dy
            .altitude_error_time_s
            .unwrap_or(base.altitude_error_time_s),
    };
    params.validate(&format!("{key}.dynamics"))?;
    let z_m = match v.kind {
        VehicleKind::Auv => {
            let a = v.altitude_m.unwrap_or(2.0);
            plumetrace_env::error::require_non_negative(&format!("{key}.altitude_m"), a)?;
            if let Some(d) = depth_m
                && a > d
            {
                return Err(EnvError::invalid(
                    format!("{key}.altitude_m"),
                    format!("{a} m is above the surface ({d} m)"),
                ));
            }
            a
        }
        VehicleKind::Surface => {
            if v.altitude_m.is_some() {
                return Err(EnvError::invalid(
                    format!("{key}.altitude_m"),
                    "surface craft stay at the surface",
                ));
            }
            depth_m.unwrap_or(0.0)
        }
    };
    let nb = match v.kind {
        VehicleKind::Auv => NavParams::lbl(),
        VehicleKind::Surface => NavParams::gps(),
    };
    let n = &v.nav;
    let nav = NavParams {
        fix_interval_s: n.fix_interval_s.unwrap_or(nb.fix_interval_s),
        fix_sigma_m: n.fix_sigma_m.unwrap_or(nb.fix_sigma_m),
        velocity_error_sd_mps: n.velocity_error_sd_mps.unwrap_or(nb.velocity_error_sd_mps),
        velocity_error_tau_s: n.velocity_error_tau_s.unwrap_or(nb.velocity_error_tau_s),
        heading_sd_deg: n.heading_sd_deg.unwrap_or(nb.heading_sd_deg),
        position_estimate: n.position_estimate.unwrap_or(nb.position_estimate),
        speed_sd_mps: n.speed_sd_mps.unwrap_or(nb.speed_sd_mps),
        altimeter_sd_m: n.altimeter_sd_m.unwrap_or(nb.altimeter_sd_m),
        flow_check: n.flow_check.unwrap_or(nb.flow_check),
    };
    nav.validate(&format!("{key}.nav"))?;
    let cb = ChemSensorParams::default();
    let c = &v.chem_sensor;
    let chem_sensor = ChemSensorParams {
        rate_hz: c.rate_hz.unwrap_or(cb.rate_hz),
        volts_per_unit: c.volts_per_unit.unwrap_or(cb.volts_per_unit),
        full_scale_v: c.full_scale_v.unwrap_or(cb.full_scale_v),
        noise_sd_v: c.noise_sd_v.unwrap_or(cb.noise_sd_v),
        lag_time_constant_s: c.lag_time_constant_s.unwrap_or(cb.lag_time_constant_s),
        salinity: salinity(c, &key)?,
    };
    chem_sensor.validate(&format!("{key}.chem_sensor"))?;
    let deaf_window_s = match (v.modem.deaf_start_s, v.modem.deaf_end_s) {
        (None, None) => None,
        (Some(a), Some(b)) => {
            plumetrace_env::error::require_non_negative(&format!("{key}.modem.deaf_start_s"), a)?;
            if !(b.is_finite() && b >= a) {
                return Err(EnvError::invalid(
                    format!("{key}.modem.deaf_end_s"),
                    format!("must be at or after deaf_start_s ({a}), got {b}"),
                ));
            }
            Some((a, b))
        }
        _ => {
            return Err(EnvError::invalid(
                format!("{key}.modem.deaf_end_s"),
                "give both deaf_start_s and deaf_end_s",
            ));
        }
    };
    if let Some(t) = c.threshold_v {
        plumetrace_env::error::require_non_negative(&format!("{key}.chem_sensor.threshold_v"), t)?;
    }
    let fb = FlowSensorParams::default();
    let f = &v.flow_sensor;
    let fault = match (f.fault_start_s, f.fault_end_s) {
        (Some(start_s), Some(end_s)) => Some(FlowFault { start_s, end_s }),
        (None, None) => None,
        _ => {
            return Err(EnvError::invalid(
                format!("{key}.flow_sensor.fault_end_s"),
                "give both fault_start_s and fault_end_s",
            ));
        }
    };
    let flow_sensor = FlowSensorParams {
        rate_hz: f.rate_hz.unwrap_or(fb.rate_hz),
        noise_sd_mps: f.noise_sd_mps.unwrap_or(fb.noise_sd_mps),
        bias_mps: f.bias_mps.unwrap_or(fb.bias_mps),
        fault,
    };
    flow_sensor.validate(&format!("{key}.flow_sensor"))?;
    let range_sensor = match &v.range_sensor {
        None => None,
        Some(r) => {
            let rb = RangeSensorParams::default();
            let p = RangeSensorParams {
                max_range_m: r.max_range_m.unwrap_or(rb.max_range_m),
                rays_per_group: r.rays_per_group.unwrap_or(rb.rays_per_group),
                front_half_angle_deg: r.front_half_angle_deg.unwrap_or(rb.front_half_angle_deg),
                side_outer_angle_deg: r.side_outer_angle_deg.unwrap_or(rb.side_outer_angle_deg),
                rate_hz: r.rate_hz.unwrap_or(rb.rate_hz),
                noise_sd_m: r.noise_sd_m.unwrap_or(rb.noise_sd_m),
                detection_probability: r.detection_probability.unwrap_or(rb.detection_probability),
            };
            plumetrace_env::error::require_positive(
                &format!("{key}.range_sensor.rate_hz"),
                p.rate_hz,
            )?;
            plumetrace_env::error::require_non_negative(
                &format!("{key}.range_sensor.noise_sd_m"),
                p.noise_sd_m,
            )?;
            if !(p.detection_probability > 0.0 && p.detection_probability <= 1.0) {
                return Err(EnvError::invalid(
                    format!("{key}.range_sensor.detection_probability"),
                    "must be in (0, 1]",
                ));
            }
            plumetrace_env::error::require_positive(
                &format!("{key}.range_sensor.max_range_m"),
                p.max_range_m,
            )?;
            if p.rays_per_group == 0 || p.rays_per_group > 1000 {
                return Err(EnvError::invalid(
                    format!("{key}.range_sensor.rays_per_group"),
                    "must be 1..=1000",
                ));
            }
            if !(p.front_half_angle_deg > 0.0
                && p.side_outer_angle_deg > p.front_half_angle_deg
                && p.side_outer_angle_deg <= 180.0)
            {
                return Err(EnvError::invalid(
                    format!("{key}.range_sensor.side_outer_angle_deg"),
                    "needs 0 < front_half_angle_deg < side_outer_angle_deg <= 180",
                ));
            }
            Some(p)
        }
    };
    let vehicle = Vehicle::new(
        VehicleId(k as u32),
        params,
        Vec2::new(v.x_m, v.y_m),
        z_m,
        Heading::from_deg(v.heading_deg),
    );
    let name = if v.name.is_empty() {
        key.clone()
    } else {
        v.name.clone()
    };
    Ok(VehicleSetup {
        name,
        vehicle,
        nav,
        chem_sensor,
        flow_sensor,
        range_sensor,
        planner: None,
        detection_threshold_v: c.threshold_v,
        deaf_window_s,
    })
}

/// The salinity probe of a `[vehicles.chem_sensor]` table, if its model is "salinity"; the
/// salinity keys without it are an error (they would be ignored).
fn salinity(
    c: &crate::config::ChemSensorConfig,
    key: &str,
) -> Result<Option<plumetrace_sim::sensors::SalinityParams>, EnvError> {
    use crate::config::ChemModel;
    let d = plumetrace_sim::sensors::SalinityParams::default();
    match c.model.unwrap_or(ChemModel::Voltage) {
        ChemModel::Salinity => Ok(Some(plumetrace_sim::sensors::SalinityParams {
            medium_ppt: c.medium_salinity_ppt.unwrap_or(d.medium_ppt),
            fresh_density_kgpm3: c.fresh_density_kgpm3.unwrap_or(d.fresh_density_kgpm3),
            noise_sd_ppt: c.noise_sd_ppt.unwrap_or(d.noise_sd_ppt),
        })),
        ChemModel::Voltage => {
            let given = [
                ("medium_salinity_ppt", c.medium_salinity_ppt),
                ("fresh_density_kgpm3", c.fresh_density_kgpm3),
                ("noise_sd_ppt", c.noise_sd_ppt),
            ];
            match given.iter().find(|(_, v)| v.is_some()) {
                Some((name, _)) => Err(EnvError::invalid(
                    format!("{key}.chem_sensor.{name}"),
                    "only a salinity sensor has it (set model = \"salinity\")",
                )),
                None => Ok(None),
            }
        }
    }
}

/// The legacy `[planner]` table (flown by every AUV that names no planner): `strategy` is read
/// as `kind`. On error returns `(key, message)`.
fn legacy_planner(t: &toml::Table) -> Result<PlannerRef, (String, String)> {
    let mut table = t.clone();
    if let Some(s) = table.remove("strategy") {
        if table.contains_key("kind") {
            return Err((
                "planner.strategy".into(),
                "give `kind` (or the older `strategy`), not both".into(),
            ));
        }
        table.insert("kind".into(), s);
    }
    Ok(PlannerRef {
        key: "planner".into(),
        table,
    })
}

/// A channel model from its table (absent keys: ideal).
fn channel(c: Option<&crate::config::ChannelConfig>) -> plumetrace_sim::ChannelParams {
    let ideal = plumetrace_sim::ChannelParams::IDEAL;
    c.map_or(ideal, |c| plumetrace_sim::ChannelParams {
        latency_s: c.latency_s.unwrap_or(ideal.latency_s),
        sound_speed_mps: c.sound_speed_mps,
        loss_probability: c.loss_probability.unwrap_or(ideal.loss_probability),
        max_range_m: c.max_range_m,
        one_in_flight: c.one_in_flight.unwrap_or(ideal.one_in_flight),
    })
}

fn polygon(vertices: &[[f64; 2]], key: &str) -> Result<Vec<plumetrace_core::Vec2>, EnvError> {
    if vertices.len() < 3 {
        return Err(EnvError::invalid(
            key,
            format!("needs at least 3 vertices, got {}", vertices.len()),
        ));
    }
    if let Some(k) = vertices
        .iter()
        .position(|v| !(v[0].is_finite() && v[1].is_finite()))
    {
        return Err(EnvError::invalid(format!("{key}[{k}]"), "is not finite"));
    }
    let area2: f64 = (0..vertices.len())
        .map(|i| {
            let (a, b) = (vertices[i], vertices[(i + 1) % vertices.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum();
    if area2.abs() < 1e-9 {
        return Err(EnvError::invalid(key, "has zero area"));
    }
    let points: Vec<plumetrace_core::Vec2> = vertices
        .iter()
        .map(|v| plumetrace_core::Vec2::new(v[0], v[1]))
        .collect();
    if let Some((a, b)) = plumetrace_core::self_intersection(&points) {
        return Err(EnvError::invalid(
            key,
            format!(
                "the polygon crosses itself: edges {a} and {b} meet (edge k runs from vertex k \
                 to the next)"
            ),
        ));
    }
    Ok(points)
}

fn mission_spec(
    m: &crate::config::MissionConfig,
    domain: &Rect,
    env_dt_s: f64,
    dt_s: f64,
    flow: &dyn plumetrace_env::FlowField,
) -> Result<MissionSpec, EnvError> {
    let op_area = match &m.op_area {
        Some(v) => polygon(v, "mission.op_area")?,
        None => {
            let inset = 50.0f64.min(0.25 * domain.width_m().min(domain.height_m()));
            let r = Rect::new(
                domain.x_min_m + inset,
                domain.x_max_m - inset,
                domain.y_min_m + inset,
                domain.y_max_m - inset,
            )?;
            r.corners().to_vec()
        }
    };
    if let Some(k) = op_area.iter().position(|p| !domain.contains(*p)) {
        return Err(EnvError::invalid(
            format!("mission.op_area[{k}]"),
            "lies outside the domain",
        ));
    }
    let mut subregions = Vec::new();
    for (k, r) in m.subregions.iter().enumerate() {
        let key = format!("mission.subregions[{k}]");
        let region = polygon(r, &key)?;
        if let Some(i) = region.iter().position(|p| !domain.contains(*p)) {
            return Err(EnvError::invalid(
                format!("{key}[{i}]"),
                "lies outside the domain",
            ));
        }
        subregions.push(region);
    }
    plumetrace_env::error::require_positive("mission.time_limit_s", m.time_limit_s)?;
    plumetrace_env::error::require_non_negative("mission.spinup_s", m.spinup_s)?;
    let steps = m.time_limit_s / dt_s;
    if steps > crate::limits::MAX_STEPS {
        return Err(EnvError::invalid(
            "mission.time_limit_s",
            format!(
                "mission.time_limit_s / sim.dt_s = {steps:.3e} steps; at most {:.0e} (about a day \
                 of computing)",
                crate::limits::MAX_STEPS
            ),
        ));
    }
    let (spinup_dt_s, spinup_key) = match m.spinup_dt_s {
        Some(v) => (v, "mission.spinup_dt_s".to_string()),
        None => (
            10.0 * env_dt_s,
            format!(
                "mission.spinup_dt_s (not given: 10 x mission.env_dt_s = {} s)",
                crate::limits::show(10.0 * env_dt_s)
            ),
        ),
    };
    plumetrace_env::error::require_positive(&spinup_key, spinup_dt_s)?;
    let spinup_steps = m.spinup_s / spinup_dt_s;
    if spinup_steps > crate::limits::MAX_SPINUP_STEPS {
        return Err(EnvError::invalid(
            "mission.spinup_s",
            format!(
                "mission.spinup_s / spin-up step = {spinup_steps:.3e} steps; at most {:.0e}",
                crate::limits::MAX_SPINUP_STEPS
            ),
        ));
    }
    // The flow takes sub-steps within its stable limit: bound their number too.
    let sub = |dt: f64| plumetrace_env::environment::flow_substeps(flow, dt) as f64;
    let flow_steps = spinup_steps * sub(spinup_dt_s) + m.time_limit_s / env_dt_s * sub(env_dt_s);
    if flow_steps > crate::limits::MAX_STEPS {
        let limit = flow.max_stable_dt_s().unwrap_or(f64::INFINITY);
        return Err(EnvError::invalid(
            "flow.farrell",
            format!(
                "the flow grid's stable step is {limit:.4e} s, so spin-up and mission would take \
                 {flow_steps:.3e} flow steps; at most {:.0e}: use a coarser grid or larger \
                 diffusivities",
                crate::limits::MAX_STEPS
            ),
        ));
    }
    let prior = m.prior_flow_toward_deg.unwrap_or(0.0);
    plumetrace_env::error::require_finite("mission.prior_flow_toward_deg", prior)?;
    Ok(MissionSpec {
        op_area,
        subregions,
        time_limit_s: m.time_limit_s,
        spinup_s: m.spinup_s,
        spinup_dt_s,
        prior_flow_toward_deg: prior,
        prior_flow_given: m.prior_flow_toward_deg.is_some(),
    })
}

/// The default of `mission.drop_margin_m`, m.
pub const DEFAULT_DROP_MARGIN_M: f64 = 200.0;

/// How far outside the op-area a vehicle can be: the cage aborts a planner whose vehicle is more
/// than 30 m out (`plumetrace-guidance`'s `ABORT_DISTANCE_M`).
const CAGE_REACH_M: f64 = 30.0;

/// Where the plume's filaments can be dropped as out of every sensor's reach, if anywhere.
///
/// The condition: the mean flow always has a component of at least `u_min > 0` along one
/// direction `d` (a steady flow, or a tidal one whose direction swings by less than 120
/// degrees in all, `d` the middle of the swing: `u_min = speed_min cos(half swing)`); every
/// vehicle flies a planner, so it stays within the cage's 30 m of the op-area once there, and
/// it starts somewhere known. Then nothing samples the plume farther along `d` than the
/// farthest op-area or subregion vertex or start (`reach`) plus 30 m, and a filament whose
/// cut-off sphere lies more than `margin_m` beyond that is carried on away from it by the mean
/// flow; to come back it would have to travel the margin against the flow, which the meander
/// (zero-mean, correlated over minutes) and the random walk (`exp(-u_min margin / K)`, the
/// chance that drifting diffusion ever goes that far back) practically never do.
fn downflow_sink(
    mean: &MeanFlow,
    spec: &MissionSpec,
    starts: &[Vec2],
    margin_m: f64,
) -> Option<plumetrace_env::DownflowSink> {
    let (toward_deg, u_min) = match *mean {
        MeanFlow::Steady {
            speed_mps,
            toward_deg,
        } => (toward_deg, speed_mps),
        MeanFlow::Tidal {
            speed_min_mps,
            toward_min_deg,
            toward_max_deg,
            ..
        } => {
            let swing = (toward_max_deg - toward_min_deg).rem_euclid(360.0);
            if swing >= 120.0 {
                return None;
            }
            let half = 0.5 * swing;
            (
                toward_min_deg + half,
                speed_min_mps * half.to_radians().cos(),
            )
        }
    };
    if !(u_min > 0.0 && margin_m.is_finite()) {
        return None;
    }
    let h = toward_deg.to_radians();
    let dir = [h.sin(), h.cos()];
    let reach = spec
        .op_area
        .iter()
        .chain(spec.subregions.iter().flatten())
        .chain(starts)
        .map(|p| dir[0] * p.x + dir[1] * p.y)
        .fold(f64::NEG_INFINITY, f64::max);
    reach.is_finite().then_some(plumetrace_env::DownflowSink {
        dir,
        beyond_m: reach + CAGE_REACH_M + margin_m,
    })
}
