//! Infotaxis on the source-likelihood map: each move is the one expected to tell the most about
//! where the source is (Vergassola, Villermaux and Shraiman 2007), or, space-aware, the one that
//! best weighs information against distance (Loisy and Eloy 2022).
//!
//! The vehicle keeps the source-likelihood map ([`crate::estimate::map`]) over the op-area from
//! every sample. At each decision point it looks at `headings` candidate legs of `step_m` (equal
//! compass steps from North; a leg whose end lies less than `edge_margin_m` inside the op-area is
//! not a candidate). A leg's outcome model comes from the map: the samples of the leg (one per
//! map correlation time of travel) are taken as independent looks from the leg's end at the time
//! it is reached, so a source cell gives at least one detection on the leg with probability
//! `1 - (1 - P(c))^n`. The leg chosen minimises the objective of [`crate::estimate::infotaxis`]
//! (the code the windy grid-world benchmark checks): the expected entropy after the leg, or the
//! space-aware value with distances in map cells. A leg ends on arrival (within `r_m`), after
//! twice its flight time, or at the first detection after a gap (contact is news: the next leg is
//! chosen with it).
//!
//! The planner declares the most likely cell once the map's mass within `map_radius_m` of it
//! reaches `map_mass` (read every `map_check_s`), and finishes. Every decision point reports the
//! map's entropy, peak and mass; the whole map is reported every ten minutes and at the
//! declaration. Courses pass the shared [`Autopilot`] (cage, flow compensation, rate filter).

use crate::FlowEstimate;
use crate::estimate::infotaxis::{choose, move_outcome};
use crate::estimate::{MapTracker, Objective};
use crate::planners::{BuildContext, PlannerParams};
use crate::shared_keys::{AutopilotKeys, MapKeys};
use plumetrace_core::params::{Bounds, ParamError};
use plumetrace_core::{
    BehaviourKind, Decision, Heading, PlanStatus, Planner, PlannerEvent, RuleDoc, SensorSnapshot,
    Telemetry, Vec2,
};
use plumetrace_guidance::{Autopilot, GoToPoint, ModeStatus, OpArea, Steer};

plumetrace_core::params! {
    /// Parameters of the infotaxis planner.
    pub struct InfotaxisParams {
        include autopilot: AutopilotKeys = AutopilotKeys::default();
        include map: MapKeys = MapKeys::default();
        /// What a move minimises: infotaxis (the expected entropy of the map after it) or space_aware (expected log2(D + 2^(H - 1) - 1/2), distance D in map cells).
        objective: Objective = Objective::Infotaxis, "", Bounds::Any;
        /// Length of a candidate leg (about 20 s at 2 m/s, three turning radii of the field vehicle).
        step_m: f64 = 40.0, "m", Bounds::closed(2.0, 10_000.0);
        /// Candidate headings per decision, equally spaced from North.
        headings: u32 = 8, "", Bounds::whole(3, 72);
        /// A leg must end at least this far inside the op-area.
        edge_margin_m: f64 = 10.0, "m", Bounds::non_negative(1000.0);
        /// Arrival radius at a leg's end.
        r_m: f64 = 5.0, "m", Bounds::positive(1000.0);
    }
}

impl InfotaxisParams {
    fn tracker(&self, area: &OpArea) -> Result<MapTracker, ParamError> {
        self.map.tracker(area, self.autopilot.threshold_v)
    }
}

impl PlannerParams for InfotaxisParams {
    const KIND: &'static str = "infotaxis";
    const SUMMARY: &'static str = "Infotaxis on a source-likelihood map: legs chosen to minimise the expected entropy of the map (or space-aware), declaration once the map concentrates";

    const THRESHOLD_KEY: Option<&'static str> = Some("threshold_v");
    const BEHAVIOURS: &'static [BehaviourKind] = &[BehaviourKind::Infotaxis, BehaviourKind::Done];
    const RULES: &'static [RuleDoc] = &[RuleDoc {
        rule: crate::estimate::tracker::SOURCE_MAP,
        doc: "the source map's most likely cell (the posterior mean within map_estimate_radius_m of it) once map_mass lies within map_radius_m of it for map_hold_s",
    }];

    fn detection_threshold_v(&self) -> Option<f64> {
        Some(self.autopilot.threshold_v)
    }

    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Planner>, ParamError> {
        let area = ctx.geometry.op_area.clone();
        let tracker = self.tracker(&area)?;
        Ok(Box::new(Infotaxis::new(
            self.clone(),
            area,
            ctx.geometry.prior_flow_toward(),
            tracker,
        )))
    }
}

/// The leg being flown.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Leg {
    goal: GoToPoint,
    started_s: f64,
}

/// The infotaxis planner for one vehicle.
pub struct Infotaxis {
    p: InfotaxisParams,
    area: OpArea,
    flow: FlowEstimate,
    autopilot: Autopilot,
    tracker: MapTracker,
    leg: Option<Leg>,
    last_detection_s: Option<f64>,
    started: bool,
    declared: bool,
    last_steer: Steer,
    /// Scratch: one candidate's hit probabilities and distances.
    hits: Vec<f64>,
    dist: Vec<f64>,
}

impl Infotaxis {
    /// A planner over `area` with its map; `prior_flow` is the flow direction assumed until the
    /// first flow measurement.
    pub fn new(p: InfotaxisParams, area: OpArea, prior_flow: Heading, tracker: MapTracker) -> Self {
        let autopilot = Autopilot::new(p.autopilot.autopilot(area.clone()));
        Infotaxis {
            flow: p.autopilot.flow_estimate(prior_flow),
            last_steer: Steer {
                heading: Heading::NORTH,
                speed_mps: p.autopilot.speed_mps,
            },
            p,
            area,
            autopilot,
            tracker,
            leg: None,
            last_detection_s: None,
            started: false,
            declared: false,
            hits: Vec::new(),
            dist: Vec::new(),
        }
    }

    /// The map.
    pub fn tracker(&mut self) -> &mut MapTracker {
        &mut self.tracker
    }

    /// The candidate leg ends from `pos` (`None`: too near the op-area's edge).
    pub fn candidates(&self, pos: Vec2) -> Vec<Option<Vec2>> {
        (0..self.p.headings)
            .map(|k| {
                let h = Heading::from_deg(360.0 * f64::from(k) / f64::from(self.p.headings));
                let end = pos + h.unit() * self.p.step_m;
                let e = self.area.edge_info(end);
                (e.inside && e.distance_m >= self.p.edge_margin_m).then_some(end)
            })
            .collect()
    }

    /// Chooses the next leg's end from `pos` at `t_s`: the candidate of smallest objective
    /// value, or the op-area's centre when no candidate fits.
    fn choose_leg(&mut self, pos: Vec2, t_s: f64, altitude_m: Option<f64>) -> Vec2 {
        let leg_s = self.p.step_m / self.p.autopilot.speed_mps;
        let samples = (leg_s / self.tracker.map().model().correlation_s.max(1e-3)).max(1.0);
        let ends = self.candidates(pos);
        let objective = self.p.objective;
        let mut values = Vec::with_capacity(ends.len());
        for end in &ends {
            let Some(end) = *end else {
                values.push(None);
                continue;
            };
            let map = self.tracker.map();
            map.hit_probabilities(end, t_s + leg_s, altitude_m, samples, &mut self.hits);
            let dist = (objective == Objective::SpaceAware).then(|| {
                let r = map.model().resolution_m;
                self.dist.clear();
                self.dist
                    .extend(map.centres().iter().map(|c| (c - end).norm() / r));
                &self.dist[..]
            });
            let o = move_outcome(map.probabilities(), &self.hits, None, dist);
            values.push(Some(objective.value(&o)));
        }
        match choose(&values).and_then(|k| ends[k]) {
            Some(end) => end,
            None => {
                let v = self.area.vertices();
                v.iter().fold(Vec2::zeros(), |a, b| a + b) / v.len() as f64
            }
        }
    }
}

impl Planner for Infotaxis {
    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        let t = s.time_s;
        if let Some(f) = s.flow {
            self.flow.add(f.time_s, f.velocity_mps);
        }
        let flow = self.flow.velocity_mps();
        let mut events = Vec::new();
        let mut telemetry = Vec::new();
        let Some(pos) = s.nav.pos_m else {
            let command = self
                .autopilot
                .command(t, None, s.nav.heading, self.last_steer, flow)
                .unwrap_or_else(|a| a.command);
            return Decision::new(command, PlanStatus::Running);
        };
        if !self.started {
            self.started = true;
            events.push(PlannerEvent::Behaviour {
                behaviour: BehaviourKind::Infotaxis,
            });
        }
        let ground = s.nav.heading.unit() * s.nav.speed_mps + flow;
        if !self.declared {
            self.tracker.feed(s, pos, ground, flow);
        }
        let detected = s
            .chem
            .iter()
            .any(|c| c.reading > self.p.autopilot.threshold_v);
        let new_contact = detected && self.last_detection_s.is_none_or(|l| t - l > 5.0);
        if new_contact {
            events.push(PlannerEvent::Detection { pos_m: pos });
        }
        if detected {
            self.last_detection_s = Some(t);
        }
        if !self.declared
            && let Some(r) = self.tracker.read_due(t, &mut telemetry)
            && self.tracker.declares(t, &r)
        {
            self.declared = true;
            self.tracker.report(t, &r, &mut telemetry, true);
            telemetry.push(Telemetry::SourceEstimate {
                pos_m: r.estimate_m,
            });
            events.push(PlannerEvent::Declared {
                pos_m: r.estimate_m,
                rule: crate::estimate::tracker::SOURCE_MAP,
            });
            events.push(PlannerEvent::Behaviour {
                behaviour: BehaviourKind::Done,
            });
        }
        if self.declared {
            let command = self.autopilot.hold(s.nav.heading);
            return Decision {
                command,
                outbox: Vec::new(),
                events,
                telemetry,
                status: PlanStatus::Finished,
            };
        }
        let leg_s = self.p.step_m / self.p.autopilot.speed_mps;
        let leg_over = match self.leg {
            None => true,
            Some(l) => {
                matches!(l.goal.update(pos), ModeStatus::Done(_))
                    || t - l.started_s > 2.0 * leg_s
                    || new_contact
            }
        };
        if leg_over {
            let target_m = self.choose_leg(pos, t, s.nav.altitude_m);
            self.leg = Some(Leg {
                goal: GoToPoint {
                    target_m,
                    speed_mps: self.p.autopilot.speed_mps,
                    radius_m: self.p.r_m,
                },
                started_s: t,
            });
            if telemetry.is_empty() {
                let r = self.tracker.read(t);
                self.tracker.report(t, &r, &mut telemetry, false);
            }
        }
        let steer = match self.leg.map(|l| l.goal.update(pos)) {
            Some(ModeStatus::Running(steer)) => steer,
            _ => self.last_steer,
        };
        self.last_steer = steer;
        let (command, status) = match self.autopilot.command_nav(t, &s.nav, steer, flow) {
            Ok(c) => (c, PlanStatus::Running),
            Err(abort) => {
                events.push(PlannerEvent::CageAbort {
                    distance_outside_m: abort.distance_outside_m,
                });
                (abort.command, PlanStatus::Abort)
            }
        };
        Decision {
            command,
            outbox: Vec::new(),
            events,
            telemetry,
            status,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planners::MissionGeometry;
    use plumetrace_core::{ChemSample, FlowSample, NavEstimate, VehicleId, VehicleKind};

    fn ctx() -> BuildContext {
        BuildContext {
            geometry: MissionGeometry {
                op_area: OpArea::rectangle(0.0, 400.0, 0.0, 200.0)
                    .unwrap_or_else(|e| panic!("{e}")),
                subregions: Vec::new(),
                prior_flow_toward_deg: 90.0,
                prior_flow_given: true,
            },
            vehicle: VehicleId(0),
            vehicle_kind: VehicleKind::Auv,
            team: Vec::new(),
        }
    }

    fn snapshot(t: f64, pos: Vec2, heading: Heading, reading: f64) -> SensorSnapshot {
        SensorSnapshot {
            time_s: t,
            vehicle: VehicleId(0),
            nav: NavEstimate {
                pos_m: Some(pos),
                heading,
                speed_mps: 2.0,
                altitude_m: Some(2.0),
                depth_m: None,
                last_fix_s: Some(0.0),
            },
            chem: vec![ChemSample { time_s: t, reading }],
            flow: Some(FlowSample {
                time_s: t,
                velocity_mps: Vec2::new(0.2, 0.0),
            }),
            ranges: None,
            inbox: Vec::new(),
        }
    }

    /// Flies the planner with a kinematic vehicle (no dynamics) in a straight-edged plume: a
    /// band 20 m wide along y = 100 East of x = 80 (source at (80, 100)), where every second
    /// sample detects, however far from the source (so the map's model has no vertical mixing
    /// and no dilution either, and a sample in the plume detects half the time).
    fn fly(objective: Objective) -> (Vec<PlannerEvent>, Vec<Telemetry>) {
        let params = InfotaxisParams {
            objective,
            map: MapKeys {
                map_vertical_diffusivity_m2ps: 0.0,
                map_dilution_s: 0.0,
                map_p_detect: 0.5,
                ..MapKeys::default()
            },
            ..InfotaxisParams::default()
        };
        let mut planner = params.build(&ctx()).unwrap_or_else(|e| panic!("{e}"));
        let (mut pos, mut heading) = (Vec2::new(350.0, 40.0), Heading::NORTH);
        let (mut events, mut telemetry) = (Vec::new(), Vec::new());
        for k in 0..30_000 {
            let t = f64::from(k) * 0.1;
            let inside = pos.x > 80.0 && (pos.y - 100.0).abs() < 10.0;
            let reading = if inside && k % 20 < 10 { 1.0 } else { 0.0 };
            let d = planner.decide(&snapshot(t, pos, heading, reading));
            events.extend(d.events);
            telemetry.extend(d.telemetry);
            if d.status != PlanStatus::Running {
                break;
            }
            heading = d.command.heading;
            pos += heading.unit() * 0.2 + Vec2::new(0.02, 0.0);
        }
        (events, telemetry)
    }

    #[test]
    fn infotaxis_finds_and_declares_a_source_at_the_head_of_a_plume() {
        for objective in [Objective::Infotaxis, Objective::SpaceAware] {
            let (events, telemetry) = fly(objective);
            let declared = events.iter().find_map(|e| match e {
                PlannerEvent::Declared { pos_m, rule } => Some((*pos_m, rule.clone())),
                _ => None,
            });
            let Some((at, rule)) = declared else {
                panic!("{objective:?}: no declaration; {} events", events.len());
            };
            assert_eq!(rule, crate::estimate::tracker::SOURCE_MAP);
            assert!(
                (at - Vec2::new(80.0, 100.0)).norm() < 25.0,
                "{objective:?}: declared at {at:?}"
            );
            let entropies: Vec<f64> = telemetry
                .iter()
                .filter_map(|t| match t {
                    Telemetry::SourceMap { entropy_bits, .. } => Some(*entropy_bits),
                    _ => None,
                })
                .collect();
            assert!(entropies.len() > 3);
            assert!(entropies.last() < entropies.first(), "{entropies:?}");
            assert!(
                telemetry
                    .iter()
                    .any(|t| matches!(t, Telemetry::SourceMapRaster { .. }))
            );
        }
    }

    #[test]
    fn candidates_keep_inside_the_margin() {
        let p = InfotaxisParams::default();
        let g = ctx().geometry;
        let tracker = p.tracker(&g.op_area).unwrap_or_else(|e| panic!("{e}"));
        let planner = Infotaxis::new(p, g.op_area.clone(), Heading::from_deg(90.0), tracker);
        let c = planner.candidates(Vec2::new(20.0, 100.0));
        assert_eq!(c.len(), 8);
        // West (index 6) would end at x = -20.
        assert!(c[6].is_none());
        assert!(c[2].is_some());
    }

    #[test]
    fn a_map_that_does_not_fit_is_an_error_naming_the_key() {
        let p = InfotaxisParams {
            map: MapKeys {
                map_resolution_m: 0.5,
                ..MapKeys::default()
            },
            ..InfotaxisParams::default()
        };
        let mut g = ctx();
        g.geometry.op_area =
            OpArea::rectangle(0.0, 5000.0, 0.0, 5000.0).unwrap_or_else(|e| panic!("{e}"));
        let e = p.build(&g).err().unwrap_or_else(|| panic!("built"));
        assert_eq!(e.key, "map_resolution_m");
    }
}
