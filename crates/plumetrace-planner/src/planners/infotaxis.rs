//! Infotaxis on the source-likelihood map: each move is the one expected to tell the most about
//! where the source is (Vergassola, Villermaux and Shraiman 2007), or, space-aware, the one that
//! best weighs information against distance (Loisy and Eloy 2022), with moves of vehicle scale.
//!
//! The vehicle keeps the source-likelihood map ([`crate::estimate::map`]) over the op-area from
//! every sample. At each decision point it looks at `headings` candidate legs of `step_m` (equal
//! compass steps from North), each flown from the vehicle's pose as the vehicle can fly it: a
//! turn at the commanded turning limit (radius `speed_mps / max_turn_rate_deg_s`) onto the
//! candidate's course, then straight ([`leg_path`]). A leg is a candidate only when every point
//! of it lies inside the op-area and its end at least `edge_margin_m` inside. A leg's outcome
//! model comes from the map: the leg is sampled every map correlation time of travel (at least
//! one cell), each point a look at the time it is reached, so a source cell gives at least one
//! detection on the leg with probability `1 - prod_i (1 - P_i(c))`: a leg across the plume's
//! expected path is worth more than one along it. The leg chosen minimises the objective of
//! [`crate::estimate::infotaxis`] (the code the windy grid-world benchmark checks): the expected
//! entropy after the leg, or the space-aware value with distances in map cells. A leg ends on
//! arrival (within `r_m`), after twice its flight time, or at a detection after `contact_gap_s`
//! without one (a new contact is news; contacts inside the plume are not, and ending legs on them
//! left the vehicle circling in the plume).
//!
//! **The plume model.** The map's model decides where infotaxis flies, so it must not claim more
//! than a threshold detector can tell. In the simulated Duck plume the chance of a detection at
//! the vehicle's altitude, behind the bottom source, does not fall with distance over the first
//! few hundred metres: on `duck-2003-st`'s axis it is 0.25 within 10 m of the source, 0.45-0.55
//! from 25 to 200 m and 0.8 from 200 to 400 m downflow (docs/planners.md, "Its plume model").
//! A model with dilution (a detection favouring sources a few tens of metres upflow) let a
//! vehicle that met the plume far downflow concentrate the map there and declare there; without dilution a detection says "upflow, somewhere", and only non-detections
//! upflow of the plume's head place the source, so the information is at the head and the legs go
//! there. Infotaxis's map therefore has no dilution (`map_dilution_s = 0`, `map_dilution_m = 0`),
//! a detection chance of 0.2 in the plume (`map_p_detect`), a spread that grows as
//! `2 x 1.0 m^2/s x T` (`map_diffusivity_m2ps`: the meander) across the flow and as
//! `min(1, U / 0.45 m/s)` of that along it (`map_along_speed_mps = 0.45`, with `U` the measured
//! current: a round spread as wide as the meander lets a detection raise cells up to
//! `4.5 D / U + U spread0^2 / (2 D)` downflow of where it was taken (the footprint's three
//! spreads), 45 m at 0.1 m/s, which moved the declarations downflow; following the current keeps
//! that reach at its value at 0.45 m/s, 12 m, in every slower current), the AMP's vertical mixing, and
//! declares at half the mass within `map_radius_m` (`map_mass = 0.5`).
//!
//! **Declaration.** Once the map's rule holds (mass `map_mass` within `map_radius_m` of the most
//! likely cell, read every `map_check_s`, after `map_min_detections` detections and `map_hold_s`),
//! the vehicle flies a confirming pass through the estimate along the flow, from `confirm_m`
//! downflow of it to `confirm_m` upflow of it (points outside the op-area are pulled in to
//! `edge_margin_m` inside), and declares if, after the pass, the rule still holds with the most
//! likely cell within `map_radius_m` of where it was; otherwise the search goes on (a source
//! further upflow shows as detections upflow of the estimate, which move the map). Every
//! decision point reports the map's entropy, peak and mass; the whole map is reported every ten
//! minutes and at the declaration. Courses pass the shared [`Autopilot`] (cage, flow
//! compensation, rate filter).

use crate::FlowEstimate;
use crate::estimate::infotaxis::{choose, move_outcome};
use crate::estimate::{MapRead, MapTracker, Objective};
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
        include map: MapKeys = MapKeys { map_mass: 0.5, map_hold_s: 300.0, map_estimate_radius_m: 10.0, map_mixing_length_m: 0.12, map_p_detect: 0.2, map_diffusivity_m2ps: 1.0, map_along_speed_mps: 0.45, map_dilution_s: 0.0, ..MapKeys::default() };
        /// What a move minimises: infotaxis (the expected entropy of the map after it) or space_aware (expected log2(D + 2^(H - 1) - 1/2), distance D in map cells).
        objective: Objective = Objective::Infotaxis, "", Bounds::Any;
        /// Length of a candidate leg, its turn at the turning limit included (40 s at 2 m/s).
        step_m: f64 = 80.0, "m", Bounds::closed(2.0, 10_000.0);
        /// Candidate courses per decision, equally spaced from North.
        headings: u32 = 12, "", Bounds::whole(3, 72);
        /// A leg must end at least this far inside the op-area (and lie inside it throughout).
        edge_margin_m: f64 = 10.0, "m", Bounds::non_negative(1000.0);
        /// Arrival radius at a leg's end.
        r_m: f64 = 5.0, "m", Bounds::positive(1000.0);
        /// A detection after this long without one ends the leg (a new contact is news); 0: every detection after a gap of 5 s does.
        contact_gap_s: f64 = 30.0, "s", Bounds::non_negative(3600.0);
        /// Confirming pass: once the map's rule holds, fly through the estimate along the flow from this far downflow of it to this far upflow, and declare if the rule still holds there (0: declare when the rule holds).
        confirm_m: f64 = 20.0, "m", Bounds::non_negative(1000.0);
    }
}

impl InfotaxisParams {
    fn tracker(&self, area: &OpArea) -> Result<MapTracker, ParamError> {
        self.map.tracker(area, self.autopilot.threshold_v)
    }

    /// The turning radius at the commanded speed and turn-rate limit, m.
    pub fn turn_radius_m(&self) -> f64 {
        self.autopilot.speed_mps / self.autopilot.max_turn_rate_deg_s.to_radians()
    }
}

impl PlannerParams for InfotaxisParams {
    const KIND: &'static str = "infotaxis";
    const SUMMARY: &'static str = "Infotaxis on a source-likelihood map: legs of vehicle scale within the turning limit and the op-area, chosen to minimise the expected entropy of the map (or space-aware), declaration once the map concentrates and a confirming pass agrees";

    const THRESHOLD_KEY: Option<&'static str> = Some("threshold_v");
    const BEHAVIOURS: &'static [BehaviourKind] = &[BehaviourKind::Infotaxis, BehaviourKind::Done];
    const RULES: &'static [RuleDoc] = &[RuleDoc {
        rule: crate::estimate::tracker::SOURCE_MAP,
        doc: "the source map's most likely cell (the posterior mean within map_estimate_radius_m of it) once map_mass lies within map_radius_m of it for map_hold_s, and still after a confirming pass through it along the flow (confirm_m each way)",
    }];

    fn detection_threshold_v(&self) -> Option<f64> {
        Some(self.autopilot.threshold_v)
    }

    fn without_effect(&self) -> Vec<(&'static str, String)> {
        self.map.without_effect()
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

/// Points along a leg flown from `pos` on heading `from`: a turn of radius `radius_m` towards
/// `course` (the shorter way) until on it, then straight, `length_m` in all; one point every
/// `spacing_m` of path and one at the end, each with its distance along the path.
pub fn leg_path(
    pos: Vec2,
    from: Heading,
    course: Heading,
    length_m: f64,
    radius_m: f64,
    spacing_m: f64,
) -> Vec<(Vec2, f64)> {
    let turn = course.diff_deg(from).to_radians();
    let sign = turn.signum();
    let arc_m = (turn.abs() * radius_m).min(length_m);
    let h0 = from.rad();
    let at = |s: f64| -> Vec2 {
        if s <= arc_m {
            // Heading h(s) = h0 + sign s / R; position = pos + sign R (cos h0 - cos h, sin h - sin h0).
            let h = h0 + sign * s / radius_m;
            pos + Vec2::new(h0.cos() - h.cos(), h.sin() - h0.sin()) * (sign * radius_m)
        } else {
            let h = h0 + sign * arc_m / radius_m;
            let turned =
                pos + Vec2::new(h0.cos() - h.cos(), h.sin() - h0.sin()) * (sign * radius_m);
            turned + Heading::from_rad(h).unit() * (s - arc_m)
        }
    };
    let spacing = spacing_m.max(1e-3);
    let n = (length_m / spacing).ceil().max(1.0) as usize;
    (1..=n)
        .map(|k| {
            let s = (k as f64 * spacing).min(length_m);
            (at(s), s)
        })
        .collect()
}

/// The leg being flown: an infotaxis leg, or the confirming pass (its waypoints and the peak it
/// confirms).
#[derive(Debug, Clone, PartialEq)]
enum Leg {
    Search {
        goal: GoToPoint,
        started_s: f64,
    },
    Confirm {
        waypoints: Vec<Vec2>,
        next: usize,
        peak_m: Vec2,
        until_s: f64,
    },
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
    /// Scratch: one point's hit probabilities, a leg's miss probabilities, distances.
    hits: Vec<f64>,
    miss: Vec<f64>,
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
            miss: Vec::new(),
            dist: Vec::new(),
        }
    }

    /// The map.
    pub fn tracker(&mut self) -> &mut MapTracker {
        &mut self.tracker
    }

    /// The candidate legs from `pos` on `heading` (`None`: the leg leaves the op-area or ends
    /// within `edge_margin_m` of its edge), as points along them (see [`leg_path`]).
    pub fn candidates(&self, pos: Vec2, heading: Heading) -> Vec<Option<Vec<(Vec2, f64)>>> {
        let map = self.p.map.model();
        let spacing = (self.p.autopilot.speed_mps * map.correlation_s).max(map.resolution_m);
        (0..self.p.headings)
            .map(|k| {
                let course = Heading::from_deg(360.0 * f64::from(k) / f64::from(self.p.headings));
                let path = leg_path(
                    pos,
                    heading,
                    course,
                    self.p.step_m,
                    self.p.turn_radius_m(),
                    spacing,
                );
                let inside = path.iter().all(|(q, _)| self.area.contains(*q));
                let end = path.last().map(|(q, _)| self.area.edge_info(*q));
                (inside && end.is_some_and(|e| e.inside && e.distance_m >= self.p.edge_margin_m))
                    .then_some(path)
            })
            .collect()
    }

    /// Chooses the next leg's end from `pos` on `heading` at `t_s`: the candidate of smallest
    /// objective value, or the op-area's centre when no candidate fits.
    fn choose_leg(
        &mut self,
        pos: Vec2,
        heading: Heading,
        t_s: f64,
        altitude_m: Option<f64>,
    ) -> Vec2 {
        let speed = self.p.autopilot.speed_mps;
        let legs = self.candidates(pos, heading);
        let objective = self.p.objective;
        let mut values = Vec::with_capacity(legs.len());
        for leg in &legs {
            let Some(leg) = leg else {
                values.push(None);
                continue;
            };
            let map = self.tracker.map();
            self.miss.clear();
            self.miss.resize(map.len(), 1.0);
            for (q, s) in leg {
                map.hit_probabilities(*q, t_s + s / speed, altitude_m, 1.0, &mut self.hits);
                for (m, h) in self.miss.iter_mut().zip(&self.hits) {
                    *m *= 1.0 - h;
                }
            }
            for m in &mut self.miss {
                *m = 1.0 - *m;
            }
            let end = leg.last().map_or(pos, |(q, _)| *q);
            let dist = (objective == Objective::SpaceAware).then(|| {
                let r = map.model().resolution_m;
                self.dist.clear();
                self.dist
                    .extend(map.centres().iter().map(|c| (c - end).norm() / r));
                &self.dist[..]
            });
            let o = move_outcome(map.probabilities(), &self.miss, None, dist);
            values.push(Some(objective.value(&o)));
        }
        match choose(&values).and_then(|k| legs[k].as_ref()?.last().map(|(q, _)| *q)) {
            Some(end) => end,
            None => self.centre(),
        }
    }

    fn centre(&self) -> Vec2 {
        let v = self.area.vertices();
        v.iter().fold(Vec2::zeros(), |a, b| a + b) / v.len() as f64
    }

    /// `p` if it lies `edge_margin_m` inside the op-area, else the point that far inside on the
    /// way from `p` to `inner` (`inner` itself when none is).
    fn pulled_in(&self, p: Vec2, inner: Vec2) -> Vec2 {
        let ok = |q: Vec2| {
            let e = self.area.edge_info(q);
            e.inside && e.distance_m >= self.p.edge_margin_m
        };
        (0..=20)
            .map(|k| p + (inner - p) * (f64::from(k) / 20.0))
            .find(|q| ok(*q))
            .unwrap_or(inner)
    }

    /// The confirming pass through `r`'s estimate: from `confirm_m` downflow to `confirm_m`
    /// upflow of it, started at `t_s` from `pos`.
    fn confirm_leg(&self, r: &MapRead, pos: Vec2, t_s: f64) -> Leg {
        let up = self.flow.upflow().unit();
        let c = self.pulled_in(r.estimate_m, self.centre());
        let a = self.pulled_in(c - up * self.p.confirm_m, c);
        let b = self.pulled_in(c + up * self.p.confirm_m, c);
        let path_m = (a - pos).norm() + (b - a).norm();
        Leg::Confirm {
            waypoints: vec![a, b],
            next: 0,
            peak_m: r.peak_m,
            until_s: t_s + 3.0 * path_m / self.p.autopilot.speed_mps + 60.0,
        }
    }
}

impl Infotaxis {
    /// Reads the map when due and moves the declaration on: starts a confirming pass when the
    /// rule holds, judges the pass when it is over; the read that declares, if any.
    fn declaration(
        &mut self,
        t: f64,
        pos: Vec2,
        telemetry: &mut Vec<Telemetry>,
    ) -> Option<MapRead> {
        let confirming = matches!(self.leg, Some(Leg::Confirm { .. }));
        if let Some(r) = self.tracker.read_due(t, telemetry)
            && !confirming
            && self.tracker.declares(t, &r)
        {
            if self.p.confirm_m <= 0.0 {
                return Some(r);
            }
            self.leg = Some(self.confirm_leg(&r, pos, t));
            return None;
        }
        let Some(Leg::Confirm {
            waypoints,
            next,
            peak_m,
            until_s,
        }) = &mut self.leg
        else {
            return None;
        };
        while *next < waypoints.len() && (waypoints[*next] - pos).norm() <= self.p.r_m {
            *next += 1;
        }
        if *next < waypoints.len() && t <= *until_s {
            return None;
        }
        let peak = *peak_m;
        self.leg = None;
        let r = self.tracker.read(t);
        self.tracker.report(t, &r, telemetry, false);
        (self.tracker.declares(t, &r) && (r.peak_m - peak).norm() <= self.p.map.map_radius_m)
            .then_some(r)
    }

    /// The steer of the leg being flown, choosing a new leg when the last one is over.
    fn steer(
        &mut self,
        s: &SensorSnapshot,
        pos: Vec2,
        new_contact: bool,
        telemetry: &mut Vec<Telemetry>,
    ) -> Steer {
        let t = s.time_s;
        let leg_s = self.p.step_m / self.p.autopilot.speed_mps;
        let leg_over = match &self.leg {
            None => true,
            Some(Leg::Search { goal, started_s }) => {
                matches!(goal.update(pos), ModeStatus::Done(_))
                    || t - started_s > 2.0 * leg_s
                    || new_contact
            }
            Some(Leg::Confirm { .. }) => false,
        };
        if leg_over {
            let target_m = self.choose_leg(pos, s.nav.heading, t, s.nav.altitude_m);
            self.leg = Some(Leg::Search {
                goal: GoToPoint {
                    target_m,
                    speed_mps: self.p.autopilot.speed_mps,
                    radius_m: self.p.r_m,
                },
                started_s: t,
            });
            if telemetry.is_empty() {
                let r = self.tracker.read(t);
                self.tracker.report(t, &r, telemetry, false);
            }
        }
        let goal = match &self.leg {
            Some(Leg::Search { goal, .. }) => Some(*goal),
            Some(Leg::Confirm {
                waypoints, next, ..
            }) => waypoints.get(*next).map(|&target_m| GoToPoint {
                target_m,
                speed_mps: self.p.autopilot.speed_mps,
                radius_m: self.p.r_m,
            }),
            None => None,
        };
        match goal.map(|g| g.update(pos)) {
            Some(ModeStatus::Running(steer)) => steer,
            _ => self.last_steer,
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
        let gap_s = if self.p.contact_gap_s > 0.0 {
            self.p.contact_gap_s
        } else {
            5.0
        };
        let new_contact = detected && self.last_detection_s.is_none_or(|l| t - l > 5.0);
        let news = detected && self.last_detection_s.is_none_or(|l| t - l > gap_s);
        if new_contact {
            events.push(PlannerEvent::Detection { pos_m: pos });
        }
        if detected {
            self.last_detection_s = Some(t);
        }
        if !self.declared
            && let Some(r) = self.declaration(t, pos, &mut telemetry)
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
        let steer = self.steer(s, pos, news, &mut telemetry);
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
            mission_end_s: None,
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

    fn planner(p: InfotaxisParams) -> Infotaxis {
        let g = ctx().geometry;
        let tracker = p.tracker(&g.op_area).unwrap_or_else(|e| panic!("{e}"));
        Infotaxis::new(p, g.op_area.clone(), Heading::from_deg(90.0), tracker)
    }

    #[test]
    fn candidates_keep_inside_the_margin() {
        let p = InfotaxisParams {
            headings: 8,
            ..InfotaxisParams::default()
        };
        let planner = planner(p);
        // Heading East at x = 20: every leg that comes round to the West would end or pass
        // outside the area; East stays in.
        let c = planner.candidates(Vec2::new(20.0, 100.0), Heading::from_deg(90.0));
        assert_eq!(c.len(), 8);
        assert!(c[6].is_none());
        assert!(c[2].is_some());
        for leg in c.iter().flatten() {
            for (q, _) in leg {
                assert!(planner.area.contains(*q), "{q:?}");
            }
        }
    }

    #[test]
    fn a_leg_turns_within_the_turning_limit_from_the_vehicle_s_heading() {
        // Heading North at (200, 100), the candidate due South: the vehicle cannot reverse on
        // the spot; the leg turns on the turning radius (2 m/s at 10 deg/s: 11.5 m), so its end
        // lies one turning diameter to the side of the straight reversal and its path never
        // turns faster than the limit.
        let p = InfotaxisParams::default();
        let radius = p.turn_radius_m();
        assert!((radius - 2.0 / 10f64.to_radians()).abs() < 1e-9);
        let (pos, north) = (Vec2::new(200.0, 100.0), Heading::NORTH);
        let path = leg_path(pos, north, Heading::from_deg(180.0), 80.0, radius, 1.0);
        let end = path.last().map(|(q, _)| *q).unwrap_or(pos);
        let straight_reversal = pos + Heading::from_deg(180.0).unit() * 80.0;
        assert!((end - straight_reversal).norm() > radius, "{end:?}");
        // The half-turn takes pi R of the 80 m; the rest runs South, 2 R to the East.
        let arc = std::f64::consts::PI * radius;
        let expected = pos + Vec2::new(2.0 * radius, -(80.0 - arc));
        assert!((end - expected).norm() < 1e-6, "{end:?} vs {expected:?}");
        // Consecutive points 1 m apart along the path: the heading changes by at most 1 m / R.
        let mut prev = (pos, north);
        for (q, _) in &path {
            let Some(h) = Heading::of_vector(*q - prev.0) else {
                panic!("a repeated point")
            };
            let change = h.diff_deg(prev.1).abs().to_radians();
            assert!(change <= 1.0 / radius + 1e-6, "{change} at {q:?}");
            assert!(((*q - prev.0).norm() - 1.0).abs() < 1e-2, "{q:?}");
            prev = (*q, h);
        }
        // The planner's candidates are those paths: the southbound one from this pose.
        let c = planner(p).candidates(pos, north);
        let south = c[6].as_ref().unwrap_or_else(|| panic!("no southbound leg"));
        let south_end = south.last().map(|(q, _)| *q).unwrap_or(pos);
        assert!((south_end - expected).norm() < 1e-6, "{south_end:?}");
    }

    /// A planner whose map has concentrated upflow (West) of (300, 100) from detections there,
    /// ten looks 10 s apart, and the map's read at 600 s (no hold; the AMP's dilution, 30 m).
    fn concentrated() -> (Infotaxis, MapRead) {
        let mut p = planner(InfotaxisParams {
            map: MapKeys {
                map_min_detections: 1,
                map_hold_s: 0.0,
                map_dilution_m: 30.0,
                ..InfotaxisParams::default().map
            },
            confirm_m: 60.0,
            ..InfotaxisParams::default()
        });
        let at = Vec2::new(300.0, 100.0);
        for k in 50..60 {
            let t = f64::from(k) * 10.0;
            let s = snapshot(t, at, Heading::from_deg(270.0), 1.0);
            p.tracker.feed(&s, at, Vec2::zeros(), Vec2::new(0.2, 0.0));
        }
        let r = p.tracker.read(600.0);
        (p, r)
    }

    /// Flies the confirming pass kinematically from where it starts, a sample every second that
    /// detects when `detects` says so; what the declaration step returns at the end.
    fn fly_pass(p: &mut Infotaxis, detects: &dyn Fn(Vec2) -> bool) -> Option<MapRead> {
        let mut telemetry = Vec::new();
        let mut pos = Vec2::new(300.0, 100.0);
        assert!(p.declaration(610.0, pos, &mut telemetry).is_none());
        let Some(Leg::Confirm { waypoints, .. }) = p.leg.clone() else {
            panic!("the rule held but no confirming pass started: {:?}", p.leg);
        };
        let mut t = 610.0;
        for w in waypoints {
            while (w - pos).norm() > 1.0 {
                t += 1.0;
                pos += (w - pos) / (w - pos).norm() * 2.0_f64.min((w - pos).norm());
                let reading = if detects(pos) { 1.0 } else { 0.0 };
                let s = snapshot(t, pos, Heading::from_deg(270.0), reading);
                p.tracker.feed(&s, pos, Vec2::zeros(), Vec2::new(0.2, 0.0));
                if let Some(r) = p.declaration(t, pos, &mut telemetry) {
                    return Some(r);
                }
                if !matches!(p.leg, Some(Leg::Confirm { .. })) {
                    return None;
                }
            }
        }
        panic!("the pass did not end at its last waypoint")
    }

    #[test]
    fn the_rule_declares_only_after_a_confirming_pass_that_agrees() {
        let (mut p, r) = concentrated();
        assert!(
            p.tracker.declares(600.0, &r),
            "the map did not concentrate: {r:?}"
        );
        // Clean water upflow of the estimate: the pass agrees and declares the read after it.
        let declared = fly_pass(&mut p, &|_| false).unwrap_or_else(|| panic!("no declaration"));
        assert!(
            (declared.peak_m - r.peak_m).norm() <= 10.0,
            "{declared:?} vs {r:?}"
        );
        // The plume goes on upflow (contacts all along the pass): the mass spreads upflow and the
        // pass declares nothing; the search resumes.
        let (mut p, _) = concentrated();
        let declared = fly_pass(&mut p, &|_| true);
        assert!(declared.is_none(), "{declared:?}");
        assert!(p.leg.is_none(), "{:?}", p.leg);
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
