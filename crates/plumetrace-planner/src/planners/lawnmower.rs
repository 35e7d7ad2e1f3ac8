//! A lawnmower survey: the exhaustive search that plume tracing should beat.
//!
//! The vehicle flies parallel lanes across the mean flow over the whole op-area, `lane_spacing_m`
//! apart and `edge_margin_m` inside its edges, in alternate directions, logging every reading.
//! When the last lane is flown it declares the source at the estimated position of the strongest
//! reading above `threshold_v` (no declaration if there was none) and finishes.
//!
//! Choices: the lanes are laid out at the first decision across the mission's prior flow direction
//! (a survey is planned from what is known of the site; one flow measurement in a meandering
//! current can be tens of degrees off the mean); the survey starts with the lane end nearest the
//! vehicle, so it may work up or down the flow. Each lane is a Follow Line leg
//! (approached with its heading); the shared [`Autopilot`] cages, compensates for the flow and
//! rate-filters every course. Behaviours: Go-To (to the first lane), Survey, then Done, run in
//! turn by the [`Sequence`] arbiter.

use crate::FlowEstimate;
use crate::behaviour::{Arbiter, Behaviour, GoTo, Legs, LineParams, Percept, Reached, Sequence};
use crate::planners::{BuildContext, PlannerParams};
use crate::shared_keys::AutopilotKeys;
use plumetrace_core::params::{Bounds, ParamError};
use plumetrace_core::{
    BehaviourKind, Decision, DeclarationKind, Heading, PlanStatus, Planner, PlannerEvent, RuleDoc,
    SensorSnapshot, Telemetry, Vec2,
};
use plumetrace_guidance::{Autopilot, GoToPoint, OpArea, Steer};

/// The lawnmower's rule in events: the position of the strongest reading of the survey.
pub const STRONGEST_READING: DeclarationKind = DeclarationKind::new("strongest_reading");

plumetrace_core::params! {
    /// Parameters of the lawnmower survey.
    pub struct LawnmowerParams {
        include autopilot: AutopilotKeys = AutopilotKeys::default();
        /// Distance between lanes, along the flow.
        lane_spacing_m: f64 = 40.0, "m", Bounds::closed(1.0, 10_000.0);
        /// How far inside the op-area's edges the lanes run.
        edge_margin_m: f64 = 10.0, "m", Bounds::non_negative(1000.0);
        /// Arrival radius at lane ends.
        r_m: f64 = 10.0, "m", Bounds::positive(1000.0);
        /// Follow Line cross-track gain.
        k_deg_per_m: f64 = 5.0, "deg/m", Bounds::positive(180.0);
        /// Turning radius of the approach to each lane.
        min_turn_radius_m: f64 = 12.0, "m", Bounds::positive(1000.0);
    }
}

impl PlannerParams for LawnmowerParams {
    const KIND: &'static str = "lawnmower";
    const SUMMARY: &'static str = "Lawnmower survey: lanes across the mean flow over the op-area, then a declaration at the strongest reading (the exhaustive baseline)";

    const THRESHOLD_KEY: Option<&'static str> = Some("threshold_v");
    const BEHAVIOURS: &'static [BehaviourKind] = &[
        BehaviourKind::GoTo,
        BehaviourKind::Survey,
        BehaviourKind::Done,
    ];
    const RULES: &'static [RuleDoc] = &[RuleDoc {
        rule: STRONGEST_READING,
        doc: "when the last lane is flown: the position of the strongest reading",
    }];

    fn detection_threshold_v(&self) -> Option<f64> {
        Some(self.autopilot.threshold_v)
    }

    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Planner>, ParamError> {
        let g = &ctx.geometry;
        // Whether any lane fits does not depend on where the vehicle starts.
        if lanes(
            &g.op_area,
            g.prior_flow_toward(),
            self.lane_spacing_m,
            self.edge_margin_m,
            Vec2::zeros(),
        )
        .is_empty()
        {
            return Err(ParamError {
                key: "edge_margin_m".into(),
                message: format!(
                    "no survey lane fits in the op-area {} m inside its edges",
                    self.edge_margin_m
                ),
            });
        }
        Ok(Box::new(Lawnmower::new(
            self.clone(),
            ctx.geometry.op_area.clone(),
            ctx.geometry.prior_flow_toward(),
        )))
    }
}

/// The lanes over `area` across the flow `flow_toward`: `spacing_m` apart along the flow, centred
/// between the edges that are `margin_m` inside the area, in alternate directions, starting with
/// the lane end nearest `from_m`. Where a lane crosses a concave area more than once it is split
/// into the stretches inside (each `margin_m` short of the edges); stretches shorter than a metre
/// are left out. An area narrower than two margins along the flow gets one lane through its middle.
pub fn lanes(
    area: &OpArea,
    flow_toward: Heading,
    spacing_m: f64,
    margin_m: f64,
    from_m: Vec2,
) -> Vec<(Vec2, Vec2)> {
    let u = flow_toward.unit();
    let c = flow_toward.turned_deg(90.0).unit();
    let v = area.vertices();
    let along: Vec<f64> = v.iter().map(|p| p.dot(&u)).collect();
    let (a_min, a_max) = along
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), a| (lo.min(*a), hi.max(*a)));
    let width = a_max - a_min - 2.0 * margin_m;
    let offsets: Vec<f64> = if width < 0.0 {
        vec![0.5 * (a_min + a_max)]
    } else {
        // As many lanes as fit, centred: the edges' strips are equal.
        let n = ((width / spacing_m).floor() as usize).min(100_000) + 1;
        let first = 0.5 * (a_min + a_max) - 0.5 * (n - 1) as f64 * spacing_m;
        (0..n).map(|k| first + k as f64 * spacing_m).collect()
    };
    let mut per_lane: Vec<Vec<(Vec2, Vec2)>> = offsets
        .iter()
        .map(|&a| {
            // Where the line p.u = a crosses the polygon's edges (each edge half-open, so a vertex
            // on the line counts once), as positions across the flow, in order.
            let mut across: Vec<f64> = (0..v.len())
                .filter_map(|i| {
                    let j = (i + 1) % v.len();
                    let (pa, qa) = (along[i], along[j]);
                    let crosses = (pa <= a && a < qa) || (qa <= a && a < pa);
                    crosses.then(|| (v[i] + (v[j] - v[i]) * ((a - pa) / (qa - pa))).dot(&c))
                })
                .collect();
            across.sort_by(f64::total_cmp);
            across
                .chunks_exact(2)
                .filter_map(|pair| {
                    let (lo, hi) = (pair[0] + margin_m, pair[1] - margin_m);
                    (hi - lo >= 1.0).then(|| (u * a + c * lo, u * a + c * hi))
                })
                .collect::<Vec<_>>()
        })
        .filter(|l: &Vec<(Vec2, Vec2)>| !l.is_empty())
        .collect();
    let (Some(first), Some(last)) = (per_lane.first(), per_lane.last()) else {
        return Vec::new();
    };
    let ends = |l: &Vec<(Vec2, Vec2)>| l.iter().flat_map(|s| [s.0, s.1]).collect::<Vec<_>>();
    let nearest = |l: &Vec<(Vec2, Vec2)>| {
        ends(l)
            .iter()
            .map(|p| (p - from_m).norm())
            .fold(f64::MAX, f64::min)
    };
    if nearest(last) < nearest(first) {
        per_lane.reverse();
    }
    // The first lane starts at its end nearest the vehicle; the others alternate.
    let l0 = &per_lane[0];
    let (s0, e0) = (l0[0].0, l0[l0.len() - 1].1);
    let mut forward = (s0 - from_m).norm() <= (e0 - from_m).norm();
    let mut out = Vec::new();
    for mut lane in per_lane {
        if !forward {
            lane.reverse();
            for s in &mut lane {
                *s = (s.1, s.0);
            }
        }
        out.extend(lane);
        forward = !forward;
    }
    out
}

/// The lawnmower survey for one vehicle.
pub struct Lawnmower {
    p: LawnmowerParams,
    area: OpArea,
    prior_flow: Heading,
    flow: FlowEstimate,
    autopilot: Autopilot,
    sequence: Option<Sequence<Vec<PlannerEvent>>>,
    events: Vec<PlannerEvent>,
    strongest: Option<(f64, Vec2)>,
    last_detection_s: Option<f64>,
    declared: bool,
    last_steer: Steer,
}

impl Lawnmower {
    /// A survey of `area`; `prior_flow` is the flow direction assumed until the first flow
    /// measurement.
    pub fn new(p: LawnmowerParams, area: OpArea, prior_flow: Heading) -> Self {
        let autopilot = Autopilot::new(p.autopilot.autopilot(area.clone()));
        Lawnmower {
            flow: p.autopilot.flow_estimate(prior_flow),
            last_steer: Steer {
                heading: Heading::NORTH,
                speed_mps: p.autopilot.speed_mps,
            },
            p,
            area,
            prior_flow,
            autopilot,
            sequence: None,
            events: Vec::new(),
            strongest: None,
            last_detection_s: None,
            declared: false,
        }
    }

    /// The strongest reading so far above the threshold, with where it was taken.
    pub fn strongest(&self) -> Option<(f64, Vec2)> {
        self.strongest
    }

    fn start(&mut self, pos: Vec2) {
        let legs = lanes(
            &self.area,
            self.prior_flow,
            self.p.lane_spacing_m,
            self.p.edge_margin_m,
            pos,
        );
        let line = LineParams {
            speed_mps: self.p.autopilot.speed_mps,
            radius_m: self.p.r_m,
            gain_deg_per_m: self.p.k_deg_per_m,
            min_turn_radius_m: self.p.min_turn_radius_m,
            approach_replans: plumetrace_guidance::GoToPointWithHeading::MAX_REPLANS,
        };
        let mut plan: Vec<Box<dyn Behaviour<Vec<PlannerEvent>, Reached>>> = Vec::new();
        if let Some((start, _)) = legs.first() {
            plan.push(Box::new(GoTo {
                goal: GoToPoint {
                    target_m: *start,
                    speed_mps: self.p.autopilot.speed_mps,
                    radius_m: self.p.r_m,
                },
                kind: BehaviourKind::GoTo,
            }));
            plan.push(Box::new(Legs::new(legs, line, BehaviourKind::Survey)));
        }
        let mut s = Sequence::new(plan);
        s.start(&mut self.events);
        self.sequence = Some(s);
    }
}

impl Planner for Lawnmower {
    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        let t = s.time_s;
        if let Some(f) = s.flow {
            self.flow.add(f.time_s, f.velocity_mps);
        }
        let flow = self.flow.velocity_mps();
        let Some(pos) = s.nav.pos_m else {
            let command = self
                .autopilot
                .command(t, None, s.nav.heading, self.last_steer, flow)
                .unwrap_or_else(|a| a.command);
            return Decision::new(command, PlanStatus::Running);
        };
        if self.sequence.is_none() {
            self.start(pos);
        }
        let mut telemetry = Vec::new();
        // The strongest sample since the last decision, placed where the vehicle was when it was
        // taken (dead-reckoned back from now: it may be a decision period ago).
        let velocity = s.nav.heading.unit() * s.nav.speed_mps + flow;
        if let Some(best) = s
            .chem
            .iter()
            .filter(|c| c.reading > self.p.autopilot.threshold_v)
            .max_by(|a, b| a.reading.total_cmp(&b.reading))
        {
            let at = pos - velocity * (t - best.time_s).max(0.0);
            // One detection event per contact (none within 5 s before): the log stays small.
            if self.last_detection_s.is_none_or(|l| t - l > 5.0) {
                self.events.push(PlannerEvent::Detection { pos_m: at });
            }
            self.last_detection_s = Some(t);
            if self.strongest.is_none_or(|(r, _)| best.reading > r) && !self.declared {
                self.strongest = Some((best.reading, at));
                telemetry.push(Telemetry::SourceEstimate { pos_m: at });
            }
        }
        let percept = Percept {
            t_s: t,
            pos_m: pos,
            heading: s.nav.heading,
            detected: false,
        };
        let sequence = self.sequence.as_mut();
        let steer = sequence.and_then(|q| q.arbitrate(&percept, &mut self.events));
        let done = self
            .sequence
            .as_ref()
            .is_none_or(|q| q.active() == BehaviourKind::Done);
        if done && !self.declared {
            self.declared = true;
            if let Some((_, at)) = self.strongest {
                self.events.push(PlannerEvent::Declared {
                    pos_m: at,
                    rule: STRONGEST_READING,
                });
            }
        }
        let steer = steer.unwrap_or(self.last_steer);
        self.last_steer = steer;
        let (command, status) =
            match self
                .autopilot
                .command(t, Some(pos), s.nav.heading, steer, flow)
            {
                Ok(c) if done => (self.autopilot.hold(c.heading), PlanStatus::Finished),
                Ok(c) => (c, PlanStatus::Running),
                Err(abort) => {
                    self.events.push(PlannerEvent::CageAbort {
                        distance_outside_m: abort.distance_outside_m,
                    });
                    (abort.command, PlanStatus::Abort)
                }
            };
        Decision {
            command,
            outbox: Vec::new(),
            events: std::mem::take(&mut self.events),
            telemetry,
            status,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_core::{ChemSample, FlowSample, NavEstimate, VehicleId};

    fn area() -> OpArea {
        OpArea::rectangle(0.0, 400.0, 0.0, 200.0).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn lanes_run_across_the_flow_inside_the_margins_and_alternate() {
        // Flow towards East: lanes run North-South, stepping East every 40 m.
        let l = lanes(
            &area(),
            Heading::from_deg(90.0),
            40.0,
            10.0,
            Vec2::new(0.0, 0.0),
        );
        // Centred between x = 10 and 390: strips of 20 m at both edges.
        assert_eq!(l.len(), 10, "x = 20, 60, ..., 380");
        for (k, (a, b)) in l.iter().enumerate() {
            assert!((a.x - (20.0 + 40.0 * k as f64)).abs() < 1e-9 && (a.x - b.x).abs() < 1e-9);
            let (lo, hi) = (a.y.min(b.y), a.y.max(b.y));
            assert!(
                (lo - 10.0).abs() < 1e-9 && (hi - 190.0).abs() < 1e-9,
                "{a:?} {b:?}"
            );
        }
        // From the South-West corner the first lane starts at its southern end, then alternates.
        assert!(l[0].0.y < l[0].1.y && l[1].0.y > l[1].1.y);
        // From the North-East corner the survey starts there instead.
        let l = lanes(
            &area(),
            Heading::from_deg(90.0),
            40.0,
            10.0,
            Vec2::new(400.0, 200.0),
        );
        assert!(
            (l[0].0 - Vec2::new(380.0, 190.0)).norm() < 1e-9,
            "{:?}",
            l[0]
        );
        // A rotated flow over a triangle: every lane end inside the area.
        let tri = OpArea::new(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(300.0, 0.0),
            Vec2::new(0.0, 300.0),
        ])
        .unwrap_or_else(|e| panic!("{e}"));
        let l = lanes(&tri, Heading::from_deg(33.0), 25.0, 5.0, Vec2::zeros());
        assert!(l.len() > 5);
        for (a, b) in l {
            assert!(tri.contains(a) && tri.contains(b), "{a:?} {b:?}");
            let dir = Heading::of_vector(b - a).unwrap_or(Heading::NORTH);
            assert!((dir.diff_deg(Heading::from_deg(33.0)).abs() - 90.0).abs() < 1e-6);
        }
        // An area narrower than two margins along the flow: one lane through its middle.
        let thin = OpArea::rectangle(0.0, 400.0, 0.0, 15.0).unwrap_or_else(|e| panic!("{e}"));
        let l = lanes(&thin, Heading::NORTH, 40.0, 10.0, Vec2::zeros());
        assert_eq!(l.len(), 1);
        assert!((l[0].0 - Vec2::new(10.0, 7.5)).norm() < 1e-9 && (l[0].1.x - 390.0).abs() < 1e-9);
        // A U-shaped area: lanes across its two arms are split, never crossing the gap.
        let u = OpArea::new(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(300.0, 0.0),
            Vec2::new(300.0, 200.0),
            Vec2::new(200.0, 200.0),
            Vec2::new(200.0, 60.0),
            Vec2::new(100.0, 60.0),
            Vec2::new(100.0, 200.0),
            Vec2::new(0.0, 200.0),
        ])
        .unwrap_or_else(|e| panic!("{e}"));
        let l = lanes(&u, Heading::NORTH, 30.0, 10.0, Vec2::zeros());
        let split = l.iter().filter(|(a, _)| a.y > 60.0).count();
        assert!(split >= 8, "{l:?}");
        for (a, b) in &l {
            for k in 0..=20 {
                let p = a + (b - a) * (f64::from(k) / 20.0);
                assert!(u.contains(p), "{p:?} on {a:?}-{b:?} is outside");
            }
        }
        // Too narrow across the flow too: no lane at all.
        let dot = OpArea::rectangle(0.0, 15.0, 0.0, 15.0).unwrap_or_else(|e| panic!("{e}"));
        assert!(lanes(&dot, Heading::NORTH, 40.0, 10.0, Vec2::zeros()).is_empty());
    }

    #[test]
    fn a_survey_with_no_lane_is_refused_when_it_is_built() {
        let ctx = BuildContext {
            geometry: crate::MissionGeometry {
                op_area: area(),
                subregions: vec![],
                prior_flow_toward_deg: 90.0,
                prior_flow_given: true,
            },
            vehicle: VehicleId(0),
            vehicle_kind: plumetrace_core::VehicleKind::Auv,
            team: Vec::new(),
            mission_end_s: None,
        };
        let p = LawnmowerParams {
            edge_margin_m: 150.0,
            ..LawnmowerParams::default()
        };
        let e = p.build(&ctx).err().unwrap_or_else(|| panic!("built"));
        assert_eq!(e.key, "edge_margin_m");
        assert!(LawnmowerParams::default().build(&ctx).is_ok());
    }

    /// Flies the planner on a kinematic vehicle (turn-rate limited, 0.5 s steps) over a plume
    /// whose readings peak at `source`, and returns its decisions' events and its last status.
    fn fly(p: LawnmowerParams, source: Vec2) -> (Vec<PlannerEvent>, PlanStatus, f64) {
        let mut planner = Lawnmower::new(p, area(), Heading::from_deg(90.0));
        let mut pos = Vec2::new(390.0, 5.0);
        let mut heading = Heading::from_deg(270.0);
        let mut events = Vec::new();
        let dt = 0.5;
        for k in 0..20_000 {
            let t = f64::from(k) * dt;
            let d = pos - source;
            // Readings only downflow (East) of the source, strongest near it.
            let reading = if d.x > 0.0 {
                3.0 * (-(d.y * d.y) / (2.0 * (5.0 + 0.2 * d.x).powi(2))).exp() / (1.0 + 0.02 * d.x)
            } else {
                0.0
            };
            let s = SensorSnapshot {
                time_s: t,
                vehicle: VehicleId(0),
                nav: NavEstimate {
                    pos_m: Some(pos),
                    heading,
                    speed_mps: 2.0,
                    altitude_m: Some(2.0),
                    depth_m: None,
                    last_fix_s: None,
                },
                chem: vec![ChemSample { time_s: t, reading }],
                flow: Some(FlowSample {
                    time_s: t,
                    velocity_mps: Vec2::new(0.1, 0.0),
                }),
                ranges: None,
                inbox: vec![],
            };
            let d = planner.decide(&s);
            events.extend(d.events);
            if d.status != PlanStatus::Running {
                return (events, d.status, t);
            }
            let turn = d.command.heading.diff_deg(heading).clamp(-5.0, 5.0);
            heading = heading.turned_deg(turn);
            pos += heading.unit() * d.command.speed_mps * dt;
        }
        (events, PlanStatus::Running, f64::INFINITY)
    }

    #[test]
    fn surveys_every_lane_then_declares_at_the_strongest_reading() {
        let source = Vec2::new(120.0, 100.0);
        let (events, status, t) = fly(LawnmowerParams::default(), source);
        assert_eq!(status, PlanStatus::Finished, "after {t} s");
        let kinds: Vec<BehaviourKind> = events.iter().filter_map(PlannerEvent::behaviour).collect();
        assert_eq!(
            kinds,
            [
                BehaviourKind::GoTo,
                BehaviourKind::Survey,
                BehaviourKind::Done
            ]
        );
        let declared: Vec<Vec2> = events
            .iter()
            .filter_map(|e| match e {
                PlannerEvent::Declared { pos_m, rule } => {
                    assert_eq!(*rule, STRONGEST_READING);
                    Some(*pos_m)
                }
                _ => None,
            })
            .collect();
        assert_eq!(declared.len(), 1);
        // The nearest lane downflow of the source is at most one spacing away.
        let e = declared[0] - source;
        assert!(e.x > 0.0 && e.x <= 40.0 + 5.0 && e.y.abs() < 10.0, "{e:?}");
        // Ten lanes of 180 m plus the turns: about 2,300 m at 2 m/s.
        assert!(t > 900.0 && t < 2000.0, "{t} s");
    }

    #[test]
    fn no_reading_above_the_threshold_no_declaration() {
        let p = LawnmowerParams {
            autopilot: AutopilotKeys {
                threshold_v: 10.0,
                ..AutopilotKeys::default()
            },
            lane_spacing_m: 100.0,
            ..LawnmowerParams::default()
        };
        let (events, status, _) = fly(p, Vec2::new(120.0, 100.0));
        assert_eq!(status, PlanStatus::Finished);
        assert!(!events.iter().any(|e| matches!(
            e,
            PlannerEvent::Declared { .. } | PlannerEvent::Detection { .. }
        )));
    }
}
