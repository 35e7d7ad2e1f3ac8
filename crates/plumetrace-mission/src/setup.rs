//! From a built scenario to a mission ready to fly: every vehicle's planner read and checked by
//! the planner registry, the mission geometry made, nothing run yet.
//!
//! `plumetrace check` stops here, so everything a mission would reject is rejected before a
//! single step, with the file and the key path.

use plumetrace_core::params::ParamError;
use plumetrace_env::{EnvError, Environment};
use plumetrace_guidance::OpArea;
use plumetrace_planner::{BuildContext, MissionGeometry, PlannerConfig, PlannerKind, planners};
use plumetrace_scenario::{BuiltScenario, MissionSpec, Origin, VehicleSetup};
use plumetrace_sim::CommsParams;

/// Why a mission could not be set up or run.
#[derive(Debug, thiserror::Error)]
pub enum MissionError {
    /// The scenario is not a mission (no `[mission]`, no planner).
    #[error("{origin}: {message}")]
    NotAMission {
        /// The scenario.
        origin: String,
        /// What is missing.
        message: String,
    },
    /// A planner or mission setting is bad.
    #[error("{origin}: {error}")]
    Invalid {
        /// The scenario.
        origin: String,
        /// Key path and message.
        error: ParamError,
    },
    /// The environment failed (a bad setting or a diverging flow).
    #[error("{origin}: {error}")]
    Env {
        /// The scenario.
        origin: String,
        /// What failed.
        error: EnvError,
    },
    /// An observer could not write its output.
    #[error("writing {what}: {message}")]
    Output {
        /// Which output.
        what: String,
        /// What went wrong.
        message: String,
    },
}

/// One vehicle's planner, checked and ready to build.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedVehicle {
    /// The key path of its table (`planner` or `planners.NAME`).
    pub key: String,
    /// Its configuration (every key, defaults filled in).
    pub config: PlannerConfig,
    /// What it is built with.
    pub context: BuildContext,
}

/// A mission ready to fly.
#[derive(Debug)]
pub struct MissionSetup {
    /// Scenario name.
    pub name: String,
    /// Run seed.
    pub seed: u64,
    /// Where the scenario came from.
    pub origin: Origin,
    /// The environment before spin-up.
    pub env: Environment,
    /// The vehicles, in file order.
    pub vehicles: Vec<VehicleSetup>,
    /// Each vehicle's planner (`None`: it keeps its last command).
    pub planners: Vec<Option<PlannedVehicle>>,
    /// Op-area, subregions and prior flow, as the planners get them.
    pub geometry: MissionGeometry,
    /// Time limit, spin-up and the polygons as written.
    pub spec: MissionSpec,
    /// The vehicles' step, s.
    pub dt_s: f64,
    /// Water depth, m.
    pub depth_m: Option<f64>,
    /// Message channels.
    pub comms: CommsParams,
    /// What `check` should tell the user: missions that cannot succeed, defaults that matter,
    /// and [`MissionSetup::inert_keys`].
    pub warnings: Vec<String>,
    /// Planner keys the scenario gives that have no effect at its values (also among
    /// `warnings`): the planner table's path, the key, and why.
    pub inert_keys: Vec<(String, &'static str, String)>,
    /// Whether `env` has had its spin-up already ([`MissionSetup::spin_up`],
    /// [`MissionSetup::use_spun_up`]); [`crate::Mission::new`] then starts at once.
    pub spun_up: bool,
}

impl MissionSetup {
    /// Checks the scenario's mission and planners with the registry.
    pub fn new(sc: BuiltScenario) -> Result<Self, MissionError> {
        let origin = sc.origin.to_string();
        let invalid = |error: ParamError| MissionError::Invalid {
            origin: origin.clone(),
            error,
        };
        let spec = sc.mission.ok_or_else(|| MissionError::NotAMission {
            origin: origin.clone(),
            message: "the scenario has no [mission] table".into(),
        })?;
        let area = |vertices: &[plumetrace_core::Vec2], key: String| {
            OpArea::new(vertices.to_vec()).map_err(|e| {
                invalid(ParamError {
                    key,
                    message: e.to_string(),
                })
            })
        };
        let geometry = MissionGeometry {
            op_area: area(&spec.op_area, "mission.op_area".into())?,
            subregions: spec
                .subregions
                .iter()
                .enumerate()
                .map(|(k, r)| area(r, format!("mission.subregions[{k}]")))
                .collect::<Result<_, _>>()?,
            prior_flow_toward_deg: spec.prior_flow_toward_deg,
            prior_flow_given: spec.prior_flow_given,
        };
        let mut planned = Vec::with_capacity(sc.vehicles.len());
        // Planner keys given that have no effect at the table's values.
        let mut inert = Vec::new();
        for (k, v) in sc.vehicles.iter().enumerate() {
            let Some(r) = &v.planner else {
                if v.detection_threshold_v.is_some() {
                    return Err(invalid(ParamError {
                        key: format!("vehicles[{k}].chem_sensor.threshold_v"),
                        message: "the vehicle has no planner to take the detection threshold \
                                  (the sensor reports readings; thresholds are the planner's)"
                            .into(),
                    }));
                }
                planned.push(None);
                continue;
            };
            let table = with_sensor_threshold(&r.table, &r.key, k, v.detection_threshold_v)
                .map_err(&invalid)?;
            let config = PlannerConfig::from_table(&table, &r.key).map_err(&invalid)?;
            if config.needs_position() && !v.nav.position_estimate {
                return Err(invalid(ParamError {
                    key: format!("vehicles[{k}].nav.position_estimate"),
                    message: format!(
                        "the vehicle flies '{}' ({}), which needs a position estimate",
                        config.kind(),
                        r.key
                    ),
                }));
            }
            let context = BuildContext {
                geometry: geometry.clone(),
                vehicle: v.vehicle.id,
                vehicle_kind: v.vehicle.params.kind,
                team: sc.vehicles.iter().map(|v| v.name.clone()).collect(),
                mission_end_s: Some(spec.time_limit_s),
            };
            // Build once here so that `check` catches what building would reject.
            config.build(&context, &r.key).map_err(&invalid)?;
            for (key, why) in config.keys_without_effect(&r.table) {
                let w = (r.key.clone(), key, why);
                if !inert.contains(&w) {
                    inert.push(w);
                }
            }
            planned.push(Some(PlannedVehicle {
                key: r.key.clone(),
                config,
                context,
            }));
        }
        let mut warnings = warnings(&sc.vehicles, &planned, &spec, &geometry, &sc.env);
        warnings.extend(
            inert
                .iter()
                .map(|(table, key, why)| format!("{table}.{key}: {why}")),
        );
        if planned.iter().all(Option::is_none) {
            return Err(MissionError::NotAMission {
                origin,
                message: "no vehicle has a planner".into(),
            });
        }
        Ok(MissionSetup {
            name: sc.name,
            seed: sc.seed,
            origin: sc.origin,
            env: sc.env,
            vehicles: sc.vehicles,
            planners: planned,
            geometry,
            spec,
            dt_s: sc.dt_s,
            depth_m: sc.depth_m,
            comms: sc.comms,
            warnings,
            inert_keys: inert,
            spun_up: false,
        })
    }

    /// Develops the plume now (the mission's `spinup_s` in steps of `spinup_dt_s`), so that the
    /// spun-up environment can be copied into other setups of the same scenario and seed.
    pub fn spin_up(&mut self) -> Result<(), MissionError> {
        if !self.spun_up {
            self.env
                .spin_up(self.spec.spinup_s, self.spec.spinup_dt_s)
                .map_err(|error| MissionError::Env {
                    origin: self.origin.to_string(),
                    error,
                })?;
            self.spun_up = true;
        }
        Ok(())
    }

    /// Takes `env`, a copy of a spun-up environment of the same scenario and seed (the
    /// caller's promise: a campaign checks that the two scenarios differ in nothing the
    /// environment is built from), instead of spinning up its own.
    pub fn use_spun_up(&mut self, env: Environment) {
        self.env = env;
        self.spun_up = true;
    }
}

/// Missions that cannot succeed, and defaults that matter.
fn warnings(
    vehicles: &[VehicleSetup],
    planned: &[Option<PlannedVehicle>],
    spec: &MissionSpec,
    geometry: &MissionGeometry,
    env: &Environment,
) -> Vec<String> {
    let mut out = Vec::new();
    if !spec.prior_flow_given {
        out.push(
            "mission.prior_flow_toward_deg is not given: planners assume the flow goes North \
             (0 deg) until their first flow measurement"
                .into(),
        );
    }
    let area = &geometry.op_area;
    if let Some(f) = env.plume().filaments() {
        for (k, s) in f.sources().iter().enumerate() {
            if !area.contains(s.pos_m.xy()) {
                out.push(format!(
                    "sources[{k}] at ({}, {}) is outside the op-area: no planner searches there",
                    s.pos_m.x, s.pos_m.y
                ));
            }
        }
    }
    for (k, (v, p)) in vehicles.iter().zip(planned).enumerate() {
        let Some(p) = p else { continue };
        if let Some(t) = p.config.detection_threshold_v()
            && t >= v.chem_sensor.full_scale_v
        {
            out.push(format!(
                "vehicles[{k}]: its planner's detection threshold ({t} V, {}) is at or above the \
                 sensor's full scale ({} V): no reading ever exceeds it",
                p.key, v.chem_sensor.full_scale_v
            ));
        }
        let start = v.vehicle.state.pos_m;
        let e = area.edge_info(start);
        if !e.inside && e.distance_m > 30.0 {
            out.push(format!(
                "vehicles[{k}] starts {:.0} m outside the op-area: its cage aborts beyond 30 m",
                e.distance_m
            ));
        }
    }
    out
}

/// The planner table with `[vehicles.chem_sensor] threshold_v` passed on as the planner's
/// `threshold_v` (older scenario files set the threshold on the sensor).
fn with_sensor_threshold(
    table: &toml::Table,
    key: &str,
    vehicle: usize,
    threshold_v: Option<f64>,
) -> Result<toml::Table, ParamError> {
    let Some(v) = threshold_v else {
        return Ok(table.clone());
    };
    let sensor_key = format!("vehicles[{vehicle}].chem_sensor.threshold_v");
    let kind = planners::kind_name(table).unwrap_or("");
    match PlannerKind::from_name(kind).map(planners::entry) {
        Some(e) if e.threshold_key.is_some() => {
            let name = e.threshold_key.unwrap_or_default();
            match table.get(name) {
                Some(own)
                    if own.as_float() == Some(v)
                        || own.as_integer().map(|i| i as f64) == Some(v) =>
                {
                    Ok(table.clone())
                }
                Some(own) => Err(ParamError {
                    key: sensor_key,
                    message: format!(
                        "{v} conflicts with {key}.{name} = {own}: the detection threshold is \
                         the planner's; set it there only"
                    ),
                }),
                None => {
                    let mut t = table.clone();
                    t.insert(name.into(), toml::Value::Float(v));
                    Ok(t)
                }
            }
        }
        Some(_) => Err(ParamError {
            key: sensor_key,
            message: format!(
                "the vehicle's planner ('{kind}', {key}) takes no detection threshold"
            ),
        }),
        // An unknown kind: the registry names it when the table is read.
        None => Ok(table.clone()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sensor_threshold_reaches_the_planner_or_conflicts() {
        let t: toml::Table = "kind = \"amp\"".parse().unwrap_or_default();
        let out = with_sensor_threshold(&t, "planner", 0, Some(0.3)).unwrap_or_default();
        assert_eq!(
            out.get("threshold_v").and_then(toml::Value::as_float),
            Some(0.3)
        );
        let own: toml::Table = "kind = \"amp\"\nthreshold_v = 0.2"
            .parse()
            .unwrap_or_default();
        let e = with_sensor_threshold(&own, "planners.a", 1, Some(0.3));
        assert!(
            e.is_err_and(|e| e.key == "vehicles[1].chem_sensor.threshold_v"
                && e.message.contains("planners.a.threshold_v"))
        );
        assert!(with_sensor_threshold(&own, "planners.a", 1, Some(0.2)).is_ok());
        assert_eq!(with_sensor_threshold(&t, "planner", 0, None).ok(), Some(t));
    }
}
