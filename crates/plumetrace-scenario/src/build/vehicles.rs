//! `[[vehicles]]` with their planners (`[planner]`, `[planners.NAME]`): each vehicle's start,
//! dynamics, modem and planner (its navigation and sensors are [`super::sensors`]).

use super::sensors;
use super::{Invalid, PlannerRef, VehicleSetup};
use crate::config::{ModemConfig, ScenarioConfig, VehicleConfig};
use plumetrace_core::params::quoted_key;
use plumetrace_core::{Heading, Vec2, VehicleId, VehicleKind};
use plumetrace_env::{Rect, Seabed};
use plumetrace_sim::{Vehicle, VehicleParams};

/// Every vehicle, with the planner it flies; every planner table must be flown.
///
/// Over a seabed (`[bathymetry]`) an AUV starts at its altitude above the seabed where it is,
/// and a surface craft at the surface (the deepest water).
pub(super) fn vehicles(
    cfg: &ScenarioConfig,
    domain: &Rect,
    seabed: Option<&Seabed>,
) -> Result<Vec<VehicleSetup>, Invalid> {
    let legacy = cfg.planner.as_ref().map(legacy_planner).transpose()?;
    let mut vehicles = Vec::new();
    for (k, v) in cfg.vehicles.iter().enumerate() {
        check_name(cfg, k)?;
        let depth_m = match seabed {
            Some(sb) => Some(sb.surface_m()),
            None => cfg.domain.depth_m,
        };
        let mut setup = vehicle_setup(v, k, domain, depth_m)?;
        if let (Some(sb), VehicleKind::Auv) = (seabed, v.kind) {
            let p = setup.vehicle.state.pos_m;
            let z = setup.vehicle.state.z_m + sb.height_at(p.x, p.y);
            setup.vehicle.state.z_m = z.min(sb.surface_m());
        }
        setup.planner = match &v.planner {
            Some(name) => Some(named_planner(cfg, k, name)?),
            None if v.kind == VehicleKind::Auv => legacy.clone(),
            None => None,
        };
        vehicles.push(setup);
    }
    if cfg.planner.is_some()
        && !cfg
            .vehicles
            .iter()
            .any(|v| v.planner.is_none() && v.kind == VehicleKind::Auv)
    {
        return Err(Invalid::new(
            "planner",
            "no vehicle flies it: [planner] is for the AUVs that name no planner, and every AUV \
             names one (or there is none); remove it or name it as [planners.NAME]",
        ));
    }
    if let Some(name) = cfg.planners.keys().find(|n| {
        !cfg.vehicles
            .iter()
            .any(|v| v.planner.as_deref() == Some(n.as_str()))
    }) {
        // A `[planners.NAME]` without a kind beside a `[planner]` was made by a key set from
        // outside (an override, a campaign's `set`) that meant the `[planner]` table.
        let made_by_a_key = cfg.planners[name]
            .keys()
            .all(|k| k != "kind" && k != "strategy");
        let message = if cfg.planner.is_some() && cfg.planners.len() == 1 && made_by_a_key {
            "no vehicle flies it: this scenario's planner is its one [planner] table; give its \
             keys as `planner.KEY` (or bare, `KEY`, in --set and a campaign's set and sweep)"
        } else {
            "no vehicle flies it (name it in a vehicle: planner = \"NAME\")"
        };
        return Err(Invalid::new(
            format!("planners.{}", quoted_key(name)),
            message,
        ));
    }
    Ok(vehicles)
}

/// Vehicle `k`'s `name`, which becomes a file name (`NAME.alog`) and a label: the safe set of
/// [`plumetrace_core::file_name::check_name`], and no other vehicle's. An omitted name stays
/// `vehicles[K]`.
fn check_name(cfg: &ScenarioConfig, k: usize) -> Result<(), Invalid> {
    let name = &cfg.vehicles[k].name;
    if name.is_empty() {
        return Ok(());
    }
    let key = format!("vehicles[{k}].name");
    plumetrace_core::file_name::check_name(name)
        .map_err(|e| Invalid::new(&key, format!("{name:?} {e}")))?;
    if let Some(j) = cfg.vehicles[..k].iter().position(|v| &v.name == name) {
        return Err(Invalid::new(
            key,
            format!("{name:?} is also vehicles[{j}]'s name; give each vehicle its own"),
        ));
    }
    Ok(())
}

/// The `[planner]` table (flown by every AUV that names no planner); its kind may be given by
/// the older name `strategy` (the planner registry reads either, and names the one written).
fn legacy_planner(t: &toml::Table) -> Result<PlannerRef, Invalid> {
    Ok(PlannerRef {
        key: "planner".into(),
        table: t.clone(),
    })
}

/// The `[planners.NAME]` table vehicle `k` names.
fn named_planner(cfg: &ScenarioConfig, k: usize, name: &str) -> Result<PlannerRef, Invalid> {
    let table = cfg.planners.get(name).ok_or_else(|| {
        let known: Vec<&str> = cfg.planners.keys().map(String::as_str).collect();
        Invalid::new(
            format!("vehicles[{k}].planner"),
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
    Ok(PlannerRef {
        key: format!("planners.{}", quoted_key(name)),
        table: table.clone(),
    })
}

/// Builds vehicle `k`, filling omitted parameters with its kind's defaults (its planner is set
/// by the caller).
fn vehicle_setup(
    v: &VehicleConfig,
    k: usize,
    domain: &Rect,
    depth_m: Option<f64>,
) -> Result<VehicleSetup, Invalid> {
    let key = format!("vehicles[{k}]");
    if !domain.contains_xy(v.x_m, v.y_m) {
        let off_x = v.x_m < domain.x_min_m || v.x_m > domain.x_max_m;
        return Err(Invalid::new(
            format!("{key}.{}", if off_x { "x_m" } else { "y_m" }),
            format!(
                "start ({}, {}) is outside the domain ({}..{} East, {}..{} North)",
                v.x_m, v.y_m, domain.x_min_m, domain.x_max_m, domain.y_min_m, domain.y_max_m
            ),
        ));
    }
    let params = dynamics(v, &key)?;
    let z_m = start_height(v, &key, depth_m)?;
    let nav = sensors::nav(v, &key)?;
    let chem_sensor = sensors::chem_sensor(&v.chem_sensor, &key)?;
    let deaf_window_s = deaf_window(&v.modem, &key)?;
    let flow_sensor = sensors::flow_sensor(&v.flow_sensor, &key)?;
    let range_sensor = sensors::range_sensor(v.range_sensor.as_ref(), &key)?;
    let vehicle = Vehicle::new(
        VehicleId(k as u32),
        params,
        Vec2::new(v.x_m, v.y_m),
        z_m,
        Heading::from_deg(v.heading_deg),
    );
    let name = if v.name.is_empty() {
        key
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
        detection_threshold_v: v.chem_sensor.threshold_v,
        deaf_window_s,
    })
}

/// `[vehicles.dynamics]` over its kind's defaults.
fn dynamics(v: &VehicleConfig, key: &str) -> Result<VehicleParams, Invalid> {
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
        dvl_beam_angle_deg: dy.dvl_beam_angle_deg.unwrap_or(base.dvl_beam_angle_deg),
        look_ahead_m: dy.look_ahead_m.unwrap_or(base.look_ahead_m),
        min_altitude_m: dy.min_altitude_m.unwrap_or(base.min_altitude_m),
    };
    params
        .validate()
        .map_err(|e| Invalid::env(&format!("{key}.dynamics"), e))?;
    Ok(params)
}

/// The start's height above the seabed: an AUV's `altitude_m` (2 m by default), a surface
/// craft's the water depth (0 without one).
fn start_height(v: &VehicleConfig, key: &str, depth_m: Option<f64>) -> Result<f64, Invalid> {
    match v.kind {
        VehicleKind::Auv => {
            let a = v.altitude_m.unwrap_or(2.0);
            if let Some(d) = depth_m
                && a > d
            {
                return Err(Invalid::new(
                    format!("{key}.altitude_m"),
                    format!("{a} m is above the surface ({d} m)"),
                ));
            }
            Ok(a)
        }
        VehicleKind::Surface => {
            if v.altitude_m.is_some() {
                return Err(Invalid::new(
                    format!("{key}.altitude_m"),
                    "surface craft stay at the surface",
                ));
            }
            Ok(depth_m.unwrap_or(0.0))
        }
    }
}

/// `[vehicles.modem]`: the mission time in which it hears nothing, if any.
fn deaf_window(m: &ModemConfig, key: &str) -> Result<Option<(f64, f64)>, Invalid> {
    match (m.deaf_start_s, m.deaf_end_s) {
        (None, None) => Ok(None),
        (Some(a), Some(b)) => {
            if !(b.is_finite() && b >= a) {
                return Err(Invalid::new(
                    format!("{key}.modem.deaf_end_s"),
                    format!("must be at or after deaf_start_s ({a}), got {b}"),
                ));
            }
            Ok(Some((a, b)))
        }
        _ => Err(Invalid::new(
            format!("{key}.modem.deaf_end_s"),
            "give both deaf_start_s and deaf_end_s",
        )),
    }
}
