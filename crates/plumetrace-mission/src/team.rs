//! What a team of vehicles did together: formation keeping, where the team's centroid flew
//! against the plume's centre line, the distance it covered, its message losses.
//!
//! [`TeamStats`] is an observer like the others. It reads only what any multi-vehicle mission
//! has: true positions, world events (messages, non-finite commands) and planner telemetry
//! ([`Telemetry::Formation`]: a member's scale and, for a member that keeps ranges to others,
//! the vehicles and the set-point). It knows no planner kind.
//!
//! - **range error**: for every telemetry record with ranges, the true slant distance to each
//!   named vehicle less the set-point, while all three are active. The formation has
//!   *converged* at the first record whose every error is within 20 % of the set-point; the
//!   median and 90th percentile of the absolute errors are taken from then on;
//! - **centroid cross-flow distance**: the centroid of the active vehicles with planners, its
//!   distance across the flow from the line through the first source along the flow there
//!   (sampled every second; median and last value);
//! - **distance overhead**: the mean over vehicles with planners of the path flown up to the
//!   first declaration over the straight line from the vehicle's start to the first source;
//! - **scale**: the smallest, largest and last cross-flow scale reported;
//! - **acoustic losses**: acoustic messages lost (each recipient counts), and delivered;
//! - **non-finite commands**: commands the world refused;
//! - **declaration confidence**: the first `declaration_confidence` a planner reported (with its
//!   declaration), left out of `summary.json` when none was.

use crate::record::{Observer, StepView};
use plumetrace_core::{PlannerEvent, Telemetry, Vec2, Vec3, VehicleId};
use plumetrace_sim::WorldEvent;
use serde::Serialize;

/// The team's numbers (in `summary.json` as `team`, for missions with two or more planners).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TeamSummary {
    /// When the formation first held every range within 20 % of its set-point, s.
    pub converged_s: Option<f64>,
    /// Median absolute range error after convergence, m.
    pub range_error_median_m: Option<f64>,
    /// 90th percentile of the absolute range error after convergence, m.
    pub range_error_p90_m: Option<f64>,
    /// The range set-point (the latest reported), m.
    pub range_setpoint_m: Option<f64>,
    /// Median distance of the centroid across the flow from the plume's centre line, m.
    pub centroid_cross_median_m: Option<f64>,
    /// The last such distance, m.
    pub centroid_cross_final_m: Option<f64>,
    /// Path flown to the first declaration over the straight line from the start to the
    /// source, averaged over the vehicles with planners.
    pub distance_overhead: Option<f64>,
    /// Smallest cross-flow scale reported.
    pub scale_min: Option<f64>,
    /// Largest cross-flow scale reported.
    pub scale_max: Option<f64>,
    /// Last cross-flow scale reported.
    pub scale_final: Option<f64>,
    /// Acoustic messages lost (per recipient).
    pub acoustic_lost: u64,
    /// Acoustic messages delivered.
    pub acoustic_delivered: u64,
    /// Commands refused for a non-finite number.
    pub non_finite_commands: u64,
    /// The confidence a planner reported with the team's first declaration (telemetry
    /// `declaration_confidence`), when it reported one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub declaration_confidence: Option<f64>,
    /// The centroid's cross-flow distance over time: `(t, m)` every second.
    pub centroid_cross_series: Vec<(f64, f64)>,
    /// The scale over time: `(t, vehicle, s_cw)`.
    pub scale_series: Vec<(f64, u32, f64)>,
}

/// Records a [`TeamSummary`].
#[derive(Debug, Default)]
pub struct TeamStats {
    source: Option<Vec3>,
    planned: Vec<bool>,
    starts: Vec<Option<Vec2>>,
    paths: Vec<f64>,
    last: Vec<Option<Vec2>>,
    declared: bool,
    converged_s: Option<f64>,
    errors: Vec<f64>,
    setpoint: Option<f64>,
    cross: Vec<(f64, f64)>,
    next_cross_s: f64,
    scales: Vec<(f64, u32, f64)>,
    acoustic_lost: u64,
    acoustic_delivered: u64,
    non_finite: u64,
    confidence: Option<f64>,
}

impl TeamStats {
    /// Stats of a team whose vehicles with planners are marked in `planned`, tracing `source`.
    pub fn new(planned: Vec<bool>, source: Option<Vec3>) -> Self {
        let n = planned.len();
        TeamStats {
            source,
            planned,
            starts: vec![None; n],
            paths: vec![0.0; n],
            last: vec![None; n],
            ..TeamStats::default()
        }
    }

    /// The summary, for teams of two or more vehicles with planners.
    pub fn summary(&self) -> Option<TeamSummary> {
        if self.planned.iter().filter(|p| **p).count() < 2 {
            return None;
        }
        let mut errors = self.errors.clone();
        errors.sort_by(f64::total_cmp);
        let quantile = |q: f64| {
            (!errors.is_empty()).then(|| errors[((errors.len() - 1) as f64 * q).round() as usize])
        };
        let mut cross: Vec<f64> = self.cross.iter().map(|c| c.1.abs()).collect();
        cross.sort_by(f64::total_cmp);
        let overheads: Vec<f64> = (0..self.planned.len())
            .filter(|&k| self.planned[k])
            .filter_map(|k| {
                let straight = (self.source?.xy() - self.starts[k]?).norm();
                (straight > 1e-9).then(|| self.paths[k] / straight)
            })
            .collect();
        let scales = self.scales.iter().map(|s| s.2);
        Some(TeamSummary {
            converged_s: self.converged_s,
            range_error_median_m: quantile(0.5),
            range_error_p90_m: quantile(0.9),
            range_setpoint_m: self.setpoint,
            centroid_cross_median_m: (!cross.is_empty()).then(|| cross[cross.len() / 2]),
            centroid_cross_final_m: self.cross.last().map(|c| c.1),
            distance_overhead: (!overheads.is_empty())
                .then(|| overheads.iter().sum::<f64>() / overheads.len() as f64),
            scale_min: scales.clone().reduce(f64::min),
            scale_max: scales.clone().reduce(f64::max),
            scale_final: self.scales.last().map(|s| s.2),
            acoustic_lost: self.acoustic_lost,
            acoustic_delivered: self.acoustic_delivered,
            non_finite_commands: self.non_finite,
            declaration_confidence: self.confidence,
            centroid_cross_series: self.cross.clone(),
            scale_series: self.scales.clone(),
        })
    }
}

/// True slant distance between two vehicles, m.
fn slant(world: plumetrace_sim::WorldView<'_>, a: VehicleId, b: VehicleId) -> Option<f64> {
    let v = world.vehicles();
    let (p, q) = (
        &v.get(a.0 as usize)?.vehicle.state,
        &v.get(b.0 as usize)?.vehicle.state,
    );
    Some(((p.pos_m - q.pos_m).norm_squared() + (p.z_m - q.z_m).powi(2)).sqrt())
}

impl Observer for TeamStats {
    fn observe(&mut self, step: &StepView<'_>) {
        let world = step.world;
        let t = step.report.t_s;
        let active = |k: usize| world.vehicles().get(k).is_some_and(|v| v.active);
        for (k, v) in world.vehicles().iter().enumerate() {
            let p = v.vehicle.state.pos_m;
            if k >= self.planned.len() {
                break;
            }
            self.starts[k].get_or_insert(p);
            if let Some(q) = self.last[k]
                && !self.declared
            {
                self.paths[k] += (p - q).norm();
            }
            self.last[k] = Some(p);
        }
        for (id, e) in &step.report.events {
            let _ = id;
            match e {
                WorldEvent::MessageLost { link, .. }
                    if *link == plumetrace_core::Link::Acoustic =>
                {
                    self.acoustic_lost += 1;
                }
                WorldEvent::MessageDelivered { link, .. }
                    if *link == plumetrace_core::Link::Acoustic =>
                {
                    self.acoustic_delivered += 1;
                }
                WorldEvent::NonFiniteCommand { .. } => self.non_finite += 1,
                _ => {}
            }
        }
        if step
            .planner_events()
            .any(|(_, e)| matches!(e, PlannerEvent::Declared { .. }))
        {
            self.declared = true;
        }
        for (k, d) in step.report.decisions.iter().enumerate() {
            let Some(d) = d else { continue };
            for tel in &d.telemetry {
                let Telemetry::Formation {
                    scale_cw,
                    ranges_to,
                    setpoint_m,
                    declaration_confidence,
                    ..
                } = tel
                else {
                    continue;
                };
                if self.confidence.is_none() {
                    self.confidence = declaration_confidence.filter(|c| c.is_finite());
                }
                if let Some(s) = scale_cw.filter(|s| s.is_finite()) {
                    self.scales.push((t, k as u32, s));
                }
                let (Some(to), Some(set)) = (ranges_to, setpoint_m.filter(|s| *s > 0.0)) else {
                    continue;
                };
                self.setpoint = Some(set);
                if !(active(k) && to.iter().all(|v| active(v.0 as usize))) {
                    continue;
                }
                let me = VehicleId(k as u32);
                let errs: Vec<f64> = to
                    .iter()
                    .filter_map(|v| slant(world, me, *v))
                    .map(|r| (r - set).abs())
                    .collect();
                if self.converged_s.is_none() && errs.iter().all(|e| *e <= 0.2 * set) {
                    self.converged_s = Some(t);
                }
                if self.converged_s.is_some() {
                    self.errors.extend(errs);
                }
            }
        }
        if t + 1e-9 >= self.next_cross_s {
            self.next_cross_s = t + 1.0;
            let members: Vec<Vec2> = world
                .vehicles()
                .iter()
                .enumerate()
                .filter(|(k, v)| v.active && self.planned.get(*k).copied().unwrap_or(false))
                .map(|(_, v)| v.vehicle.state.pos_m)
                .collect();
            if let (Some(src), false) = (self.source, members.is_empty()) {
                use plumetrace_env::FlowField;
                let c = members.iter().sum::<Vec2>() / members.len() as f64;
                let flow = world.env().flow().velocity(src.xy());
                if let Some(h) = plumetrace_core::Heading::of_vector(flow) {
                    let along = h.unit();
                    let d = c - src.xy();
                    // Positive to the right looking down-flow.
                    self.cross.push((t, d.x * along.y - d.y * along.x));
                }
            }
        }
    }
}
