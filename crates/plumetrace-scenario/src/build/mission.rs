//! `[mission]`: op-area, subregions, time limit, spin-up and the downflow filament sink.

use super::timing::{Timing, check_flow_steps};
use super::{Invalid, MissionSpec, VehicleSetup, flow};
use crate::config::{FlowKind, MissionConfig, ScenarioConfig};
use crate::limits::{MAX_SPINUP_STEPS, MAX_STEPS};
use plumetrace_core::Vec2;
use plumetrace_env::flow::MeanFlow;
use plumetrace_env::{Environment, FlowField, Rect};

/// The default of `mission.drop_margin_m`, m.
pub const DEFAULT_DROP_MARGIN_M: f64 = 200.0;

/// The default of `mission.success_radius_m`: a source counts as located when a declaration lies
/// within this distance of it, m. The field declarations were within 31 m of the sonar positions,
/// and the plume of a bottom source reaches a vehicle 1.5-2 m up only some tens of metres
/// downflow.
pub const DEFAULT_SUCCESS_RADIUS_M: f64 = 50.0;

/// How far outside the op-area a vehicle can be: the cage aborts a planner whose vehicle is more
/// than 30 m out (`plumetrace-guidance`'s `ABORT_DISTANCE_M`).
const CAGE_REACH_M: f64 = 30.0;

/// The mission, if the scenario has one (required when a vehicle flies a planner); sets the
/// plume's downflow sink where it applies ([`downflow_sink`]).
pub(super) fn mission(
    cfg: &ScenarioConfig,
    domain: &Rect,
    timing: &Timing,
    vehicles: &[VehicleSetup],
    env: &mut Environment,
) -> Result<Option<MissionSpec>, Invalid> {
    let flown = vehicles.iter().any(|v| v.planner.is_some());
    let mission = match &cfg.mission {
        None => {
            if flown {
                return Err(Invalid::new(
                    "mission",
                    "a scenario with vehicles and a planner needs a [mission] table",
                ));
            }
            None
        }
        Some(m) => {
            let spec = mission_spec(m, domain, timing, env.flow())?;
            // The spin-up's step moves the filaments by enough for their positions (by default
            // it is ten environment steps, which move them farther than one).
            env.check_spin_up(spec.spinup_s, spec.spinup_dt_s)
                .map_err(|e| Invalid::env("mission", e))?;
            Some(spec)
        }
    };
    let mean = flow::mean(&cfg.flow)?;
    if let (Some(spec), Some(m), Some(mean)) = (&mission, &cfg.mission, mean)
        && !matches!(cfg.flow.model, FlowKind::Gridded)
        && vehicles.iter().all(|v| v.planner.is_some())
        && let plumetrace_env::Plume::Filaments(plume) = env.plume_mut()
    {
        let starts: Vec<Vec2> = vehicles.iter().map(|v| v.vehicle.state.pos_m).collect();
        let margin = m.drop_margin_m.unwrap_or(DEFAULT_DROP_MARGIN_M);
        plume.set_sink(downflow_sink(&mean, spec, &starts, margin));
    }
    if mission.is_some() && !flown {
        return Err(Invalid::new(
            if cfg.vehicles.is_empty() {
                "vehicles"
            } else {
                "planner"
            },
            "a [mission] needs a vehicle with a planner: a [planner] table (flown by every AUV) \
             or [planners.NAME] tables named by vehicles (planner = \"NAME\")",
        ));
    }
    Ok(mission)
}

/// A simple polygon of the mission at `key`, inside the domain.
fn polygon(vertices: &[[f64; 2]], key: &str, domain: &Rect) -> Result<Vec<Vec2>, Invalid> {
    let points: Vec<Vec2> = vertices.iter().map(|v| Vec2::new(v[0], v[1])).collect();
    plumetrace_core::check_polygon(&points, true).map_err(|e| Invalid::env(key, e.into()))?;
    inside(&points, key, domain)?;
    Ok(points)
}

/// Refuses a vertex of the polygon at `key` outside the domain.
fn inside(points: &[Vec2], key: &str, domain: &Rect) -> Result<(), Invalid> {
    match points.iter().position(|p| !domain.contains(*p)) {
        Some(k) => Err(Invalid::new(
            format!("{key}[{k}]"),
            "lies outside the domain",
        )),
        None => Ok(()),
    }
}

/// The mission's spec, checked.
fn mission_spec(
    m: &MissionConfig,
    domain: &Rect,
    timing: &Timing,
    flow: &dyn FlowField,
) -> Result<MissionSpec, Invalid> {
    let op_area = match &m.op_area {
        Some(v) => polygon(v, "mission.op_area", domain)?,
        None => {
            let inset = 50.0f64.min(0.25 * domain.width_m().min(domain.height_m()));
            let r = Rect::new(
                domain.x_min_m + inset,
                domain.x_max_m - inset,
                domain.y_min_m + inset,
                domain.y_max_m - inset,
            )
            .map_err(|e| Invalid::env("mission", e))?;
            let corners = r.corners().to_vec();
            inside(&corners, "mission.op_area", domain)?;
            corners
        }
    };
    let mut subregions = Vec::new();
    for (k, r) in m.subregions.iter().enumerate() {
        subregions.push(polygon(r, &format!("mission.subregions[{k}]"), domain)?);
    }
    let steps = m.time_limit_s / timing.dt_s;
    if steps > MAX_STEPS {
        return Err(Invalid::new(
            "mission.time_limit_s",
            format!(
                "mission.time_limit_s / sim.dt_s = {steps:.3e} steps; at most {MAX_STEPS:.0e} \
                 (about a day of computing)"
            ),
        ));
    }
    // Given, it is the limits table's to bound; by default 10 environment steps.
    let spinup_dt_s = m.spinup_dt_s.unwrap_or(10.0 * timing.env_dt_s);
    let spinup_steps = m.spinup_s / spinup_dt_s;
    if spinup_steps > MAX_SPINUP_STEPS {
        return Err(Invalid::new(
            "mission.spinup_s",
            format!(
                "mission.spinup_s / spin-up step = {spinup_steps:.3e} steps; at most \
                 {MAX_SPINUP_STEPS:.0e}"
            ),
        ));
    }
    // The flow takes sub-steps within its stable limit: bound their number too.
    let sub = |dt: f64| plumetrace_env::environment::flow_substeps(flow, dt) as f64;
    let flow_steps =
        spinup_steps * sub(spinup_dt_s) + m.time_limit_s / timing.env_dt_s * sub(timing.env_dt_s);
    check_flow_steps(flow, flow_steps, "spin-up and mission")?;
    let prior = m.prior_flow_toward_deg.unwrap_or(0.0);
    Ok(MissionSpec {
        op_area,
        subregions,
        time_limit_s: m.time_limit_s,
        spinup_s: m.spinup_s,
        spinup_dt_s,
        prior_flow_toward_deg: prior,
        prior_flow_given: m.prior_flow_toward_deg.is_some(),
        success_radius_m: m.success_radius_m.unwrap_or(DEFAULT_SUCCESS_RADIUS_M),
    })
}

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
