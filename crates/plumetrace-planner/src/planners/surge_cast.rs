//! Spiral-out then surge-cast: a small baseline planner after the moth's surge and cast.
//!
//! - **Find**: an Archimedean spiral (`r = spiral_spacing_m * theta / 2 pi`) around where the
//!   vehicle starts (brought `edge_margin_m` inside the op-area), its waypoints about half a
//!   spacing apart along the arms (20 m at most). Waypoints less than `edge_margin_m` inside the
//!   op-area are skipped, so where an arm leaves the area the vehicle cuts straight across to
//!   where it comes back in. Once a whole turn of the spiral lies outside the area, the spiral
//!   starts again from its centre, half a turn round (its arms then fall between the first ones).
//! - **Track-In** (surge), while the last detection is at most `lambda_s` old: straight up-flow
//!   against the shared flow estimate.
//! - **Reacquire** (cast), once contact is lost: casts across the flow, centred on the last
//!   detection (each cast's centre `cast_drift_m` further down-flow than the one before; negative:
//!   up-flow), to alternate sides, first back across the line the vehicle left the plume on. The
//!   first cast reaches `cast_width_m / 2` to the side, each next one `cast_growth` times wider, up
//!   to `max_cast_width_m`. Cast ends and centres are brought `edge_margin_m` inside the op-area. A
//!   detection surges again; the next loss starts narrow casts around the new last detection.
//! - **Declare**: every contact (a run of detections less than `lambda_s` apart) leaves its most
//!   up-flow detection. A cast counts as failed when it ends without a contact at least
//!   `progress_m` up-flow of the detection that last made such progress; after `max_casts` failed
//!   casts in a row the source is declared at the most up-flow contact point (along the mean of
//!   every flow measurement so far, the prior before the first), and the mission ends. Without
//!   any contact the search goes on until the mission's time limit.
//!
//! A waypoint (spiral or cast end) counts as reached within `r_m`, once passed along its leg, or
//! when it is not reached in twice the time to fly the leg plus a minute (the current or the cage
//! can keep the vehicle from it). Every course passes the shared [`Autopilot`] (cage, flow
//! compensation, rate filter); a reading above `threshold_v` is a detection.
//!
//! The defaults were chosen on ten sites of the coastal family (`examples/families/`), not on a
//! preset: a short `lambda_s` (3-5 s) and more casts before declaring (8-10) gave the smallest
//! errors; a spiral spacing of 40-60 m found the plume soonest (30 m took longest); the cast
//! widths, their drift, `progress_m` and the flow's averaging time made little difference.

use crate::FlowEstimate;
use crate::planners::{BuildContext, PlannerParams};
use crate::shared_keys::AutopilotKeys;
use plumetrace_core::params::{Bounds, ParamError, Params};
use plumetrace_core::{
    BehaviourKind, Decision, DeclarationKind, Heading, PlanStatus, Planner, PlannerEvent, RuleDoc,
    SensorSnapshot, Telemetry, Vec2, bearing_between,
};
use plumetrace_guidance::{Autopilot, OpArea, Steer};

/// The rule in events: the most up-flow contact point, after `max_casts` failed casts.
pub const MOST_UPFLOW_CONTACT: DeclarationKind = DeclarationKind::new("most_upflow_contact");

plumetrace_core::params! {
    /// Parameters of the spiral-out then surge-cast planner.
    pub struct SurgeCastParams {
        include autopilot: AutopilotKeys = AutopilotKeys { flow_average_s: 20.0, ..AutopilotKeys::default() };
        /// Distance between the arms of the search spiral.
        spiral_spacing_m: f64 = 40.0, "m", Bounds::closed(1.0, 10_000.0);
        /// How far inside the op-area's edges the spiral's waypoints, the casts and their centres stay.
        edge_margin_m: f64 = 10.0, "m", Bounds::non_negative(1000.0);
        /// Arrival radius of the spiral's waypoints and the cast ends.
        r_m: f64 = 5.0, "m", Bounds::positive(1000.0);
        /// Time after the last detection that ends a surge (the contact is lost).
        lambda_s: f64 = 5.0, "s", Bounds::positive(3600.0);
        /// Full width of the first cast across the flow (half of it to each side of the centre).
        cast_width_m: f64 = 20.0, "m", Bounds::positive(10_000.0);
        /// Each cast is this many times wider than the one before.
        cast_growth: f64 = 2.0, "", Bounds::closed(1.0, 10.0);
        /// Widest cast.
        max_cast_width_m: f64 = 160.0, "m", Bounds::positive(10_000.0);
        /// How much further down-flow each cast's centre is than the one before (negative: up-flow).
        cast_drift_m: f64 = 5.0, "m", Bounds::closed(-1000.0, 1000.0);
        /// Failed casts in a row that end the search with a declaration.
        max_casts: u32 = 10, "", Bounds::whole(1, 1000);
        /// A contact this far up-flow of the detection that last made progress makes progress: the count of failed casts starts again.
        progress_m: f64 = 5.0, "m", Bounds::non_negative(10_000.0);
    }
}

impl PlannerParams for SurgeCastParams {
    const KIND: &'static str = "surge_cast";
    const SUMMARY: &'static str = "Spiral-out then surge-cast baseline: an Archimedean spiral from the start, straight up-flow while in contact, widening casts across the flow when contact is lost, a declaration at the most up-flow contact after max_casts failed casts";
    const THRESHOLD_KEY: Option<&'static str> = Some("threshold_v");
    const BEHAVIOURS: &'static [BehaviourKind] = &[
        BehaviourKind::Find,
        BehaviourKind::TrackIn,
        BehaviourKind::Reacquire,
        BehaviourKind::Done,
    ];
    const RULES: &'static [RuleDoc] = &[RuleDoc {
        rule: MOST_UPFLOW_CONTACT,
        doc: "max_casts casts in a row without a contact progress_m further up-flow: the most up-flow contact point",
    }];

    fn validate(&self, prefix: &str) -> Result<(), ParamError> {
        self.check_bounds(prefix)?;
        if self.max_cast_width_m < self.cast_width_m {
            return Err(ParamError::at(
                prefix,
                "max_cast_width_m",
                format!(
                    "must be at least cast_width_m ({}), not {}",
                    self.cast_width_m, self.max_cast_width_m
                ),
            ));
        }
        Ok(())
    }

    fn detection_threshold_v(&self) -> Option<f64> {
        Some(self.autopilot.threshold_v)
    }

    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Planner>, ParamError> {
        Ok(Box::new(SurgeCast::new(
            self.clone(),
            ctx.geometry.op_area.clone(),
            ctx.geometry.prior_flow_toward(),
        )))
    }
}

/// Contact points kept (one per `lambda_s` at most).
const MAX_CONTACTS: usize = 10_000;

/// Spiral steps tried for one waypoint (a spiral that has outgrown the area restarts first).
const MAX_SPIRAL_STEPS: usize = 100_000;

/// The source estimate is reported again once it moves this far, m (a surge moves it at the
/// vehicle's speed).
const ESTIMATE_STEP_M: f64 = 5.0;

/// Slack of a waypoint's time budget, s.
const WAYPOINT_SLACK_S: f64 = 60.0;

/// `p` brought `margin_m` inside `area` (a few steps across the nearest edge, for concave
/// corners); `p` itself when it is already.
fn pulled_inside(area: &OpArea, p: Vec2, margin_m: f64) -> Vec2 {
    let mut q = p;
    for _ in 0..4 {
        let e = area.edge_info(q);
        if e.inside && e.distance_m >= margin_m {
            break;
        }
        let depth = if e.inside {
            margin_m - e.distance_m
        } else {
            e.distance_m + margin_m
        };
        q -= e.outward_normal * (depth + 1e-6);
    }
    q
}

/// Whether `p` is inside `area` at least `margin_m` from every edge.
fn well_inside(area: &OpArea, p: Vec2, margin_m: f64) -> bool {
    let e = area.edge_info(p);
    e.inside && e.distance_m >= margin_m
}

/// An Archimedean spiral around `centre`, walked in steps along its arms.
#[derive(Debug, Clone, PartialEq)]
struct Spiral {
    centre: Vec2,
    /// Radius growth per radian: spacing / 2 pi.
    b: f64,
    theta: f64,
    /// Angle of the arm's start, rad (half a turn more at every restart).
    phase: f64,
    /// Step along the arm, m.
    step_m: f64,
    /// Angle walked since the last point inside the area, rad.
    outside_rad: f64,
}

impl Spiral {
    fn new(centre: Vec2, spacing_m: f64) -> Self {
        Spiral {
            centre,
            b: spacing_m / std::f64::consts::TAU,
            theta: 0.0,
            phase: 0.0,
            step_m: (0.5 * spacing_m).clamp(0.5, 20.0),
            outside_rad: 0.0,
        }
    }

    fn point(&self) -> Vec2 {
        let r = self.b * self.theta;
        let a = self.theta + self.phase;
        self.centre + Vec2::new(a.cos(), a.sin()) * r
    }

    /// The next waypoint well inside `area`: the spiral restarts (half a turn round) once a whole
    /// turn has been outside.
    fn next(&mut self, area: &OpArea, margin_m: f64) -> Vec2 {
        for _ in 0..MAX_SPIRAL_STEPS {
            let r = self.b * self.theta;
            let dtheta = self.step_m / (r * r + self.b * self.b).sqrt().max(1e-9);
            self.theta += dtheta;
            self.outside_rad += dtheta;
            if self.outside_rad > std::f64::consts::TAU {
                self.theta = 0.0;
                self.phase = (self.phase + std::f64::consts::PI) % std::f64::consts::TAU;
                self.outside_rad = 0.0;
            }
            let p = self.point();
            if well_inside(area, p, margin_m) {
                self.outside_rad = 0.0;
                return p;
            }
        }
        pulled_inside(area, self.point(), margin_m)
    }
}

/// A goal flown to from `from`, since `since_s`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Waypoint {
    from: Vec2,
    goal: Vec2,
    since_s: f64,
}

impl Waypoint {
    /// Reached: within `r_m`, passed along its leg, or over its time budget at `speed_mps`.
    fn reached(&self, t_s: f64, pos: Vec2, r_m: f64, speed_mps: f64) -> bool {
        let leg = self.goal - self.from;
        let passed = leg.norm() > 1e-9 && (self.goal - pos).dot(&leg) < 0.0;
        let budget = 2.0 * leg.norm() / speed_mps.max(0.1) + WAYPOINT_SLACK_S;
        (self.goal - pos).norm() <= r_m || passed || t_s - self.since_s > budget
    }
}

/// The casts after one loss of contact.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Casts {
    /// The last detection (the first cast's centre).
    around: Vec2,
    /// Up-flow and across-flow unit vectors at the loss.
    up: Vec2,
    across: Vec2,
    /// Side of the first cast (+1: along `across`).
    side: f64,
    /// Index of the cast flown.
    k: u32,
    to: Waypoint,
}

/// What the planner is doing.
#[derive(Debug, Clone, PartialEq)]
enum Mode {
    Find,
    Surge,
    Cast(Casts),
    Done,
}

impl Mode {
    fn behaviour(&self) -> BehaviourKind {
        match self {
            Mode::Find => BehaviourKind::Find,
            Mode::Surge => BehaviourKind::TrackIn,
            Mode::Cast(_) => BehaviourKind::Reacquire,
            Mode::Done => BehaviourKind::Done,
        }
    }
}

/// The spiral-out then surge-cast planner for one vehicle.
pub struct SurgeCast {
    p: SurgeCastParams,
    area: OpArea,
    flow: FlowEstimate,
    /// Sum and count of every flow measurement: their mean sorts the contact points.
    flow_sum: Vec2,
    flow_count: u64,
    prior_flow: Heading,
    autopilot: Autopilot,
    mode: Mode,
    /// Reported behaviour (a switch is logged once).
    reported_behaviour: Option<BehaviourKind>,
    spiral: Option<Spiral>,
    find_to: Option<Waypoint>,
    last_detection: Option<(f64, Vec2)>,
    /// Each contact's most up-flow detection, oldest first.
    contacts: Vec<Vec2>,
    /// The detection that last made progress up-flow.
    progress_at: Option<Vec2>,
    /// Casts ended without progress since then.
    failed_casts: u32,
    declared: Option<Vec2>,
    events: Vec<PlannerEvent>,
    last_steer: Steer,
    reported_estimate: Option<Vec2>,
}

impl SurgeCast {
    /// A planner over `area`; `prior_flow` is the flow direction assumed until the first flow
    /// measurement.
    pub fn new(p: SurgeCastParams, area: OpArea, prior_flow: Heading) -> Self {
        SurgeCast {
            autopilot: Autopilot::new(p.autopilot.autopilot(area.clone())),
            flow: p.autopilot.flow_estimate(prior_flow),
            flow_sum: Vec2::zeros(),
            flow_count: 0,
            prior_flow,
            last_steer: Steer {
                heading: prior_flow.reversed(),
                speed_mps: p.autopilot.speed_mps,
            },
            p,
            area,
            mode: Mode::Find,
            reported_behaviour: None,
            spiral: None,
            find_to: None,
            last_detection: None,
            contacts: Vec::new(),
            progress_at: None,
            failed_casts: 0,
            declared: None,
            events: Vec::new(),
            reported_estimate: None,
        }
    }

    /// The behaviour in control.
    pub fn behaviour(&self) -> BehaviourKind {
        self.mode.behaviour()
    }

    /// The course asked for at the last decision (before the cage, flow compensation and the
    /// rate filter).
    pub fn last_course(&self) -> Heading {
        self.last_steer.heading
    }

    /// The waypoint flown to (spiral waypoint or cast end), if any.
    pub fn goal(&self) -> Option<Vec2> {
        match &self.mode {
            Mode::Find => self.find_to.map(|w| w.goal),
            Mode::Cast(c) => Some(c.to.goal),
            Mode::Surge | Mode::Done => None,
        }
    }

    /// The contact points so far (each contact's most up-flow detection), oldest first.
    pub fn contact_points(&self) -> &[Vec2] {
        &self.contacts
    }

    /// The declared source, if any.
    pub fn declared(&self) -> Option<Vec2> {
        self.declared
    }

    /// Up-flow unit vector of the mean of every flow measurement (the prior before the first).
    fn mean_upflow(&self) -> Vec2 {
        let sum = self.flow_sum;
        let norm = sum.norm();
        if self.flow_count == 0 || !norm.is_finite() || norm < 1e-9 {
            return self.prior_flow.reversed().unit();
        }
        -sum / norm
    }

    /// The most up-flow contact point.
    fn most_upflow_contact(&self) -> Option<Vec2> {
        let up = self.mean_upflow();
        self.contacts
            .iter()
            .copied()
            .max_by(|a, b| a.dot(&up).total_cmp(&b.dot(&up)))
    }

    fn set_mode(&mut self, mode: Mode) {
        self.mode = mode;
        let kind = self.mode.behaviour();
        if self.reported_behaviour != Some(kind) {
            self.reported_behaviour = Some(kind);
            self.events
                .push(PlannerEvent::Behaviour { behaviour: kind });
        }
    }

    /// Records this decision's detection: contacts, and progress up-flow.
    fn sense(&mut self, t: f64, pos: Vec2, detected: bool) {
        if !detected {
            return;
        }
        let up = self.mean_upflow();
        let new_contact = self
            .last_detection
            .is_none_or(|(tl, _)| t - tl > self.p.lambda_s);
        if new_contact {
            self.events.push(PlannerEvent::Detection { pos_m: pos });
            self.contacts.push(pos);
            if self.contacts.len() > MAX_CONTACTS {
                self.contacts.drain(..self.contacts.len() - MAX_CONTACTS);
            }
        } else if let Some(c) = self.contacts.last_mut()
            && pos.dot(&up) > c.dot(&up)
        {
            *c = pos;
        }
        if self
            .progress_at
            .is_none_or(|a| (pos - a).dot(&up) >= self.p.progress_m)
        {
            self.progress_at = Some(pos);
            self.failed_casts = 0;
        }
        self.last_detection = Some((t, pos));
    }

    /// The next spiral waypoint after `from` (`from` itself before the spiral is laid out).
    fn next_spiral_waypoint(&mut self, t: f64, from: Vec2) -> Waypoint {
        let margin = self.p.edge_margin_m;
        let goal = match self.spiral.as_mut() {
            Some(spiral) => spiral.next(&self.area, margin),
            None => from,
        };
        Waypoint {
            from,
            goal,
            since_s: t,
        }
    }

    fn find(&mut self, t: f64, pos: Vec2) -> Vec2 {
        if self.spiral.is_none() {
            // The spiral's first waypoint is its centre: where the vehicle starts, brought inside.
            let centre = pulled_inside(&self.area, pos, self.p.edge_margin_m);
            self.spiral = Some(Spiral::new(centre, self.p.spiral_spacing_m));
            self.find_to = Some(Waypoint {
                from: pos,
                goal: centre,
                since_s: t,
            });
        }
        let (r, v) = (self.p.r_m, self.p.autopilot.speed_mps);
        for _ in 0..1000 {
            match self.find_to {
                Some(w) if !w.reached(t, pos, r, v) => return w.goal,
                Some(w) => self.find_to = Some(self.next_spiral_waypoint(t, w.goal)),
                None => self.find_to = Some(self.next_spiral_waypoint(t, pos)),
            }
        }
        self.find_to.map_or(pos, |w| w.goal)
    }

    /// The end of cast `k` of `c`.
    fn cast_end(&self, c: &Casts, k: u32) -> Vec2 {
        let p = &self.p;
        let width =
            (p.cast_width_m * p.cast_growth.powi(k.min(1000) as i32)).min(p.max_cast_width_m);
        let side = if k.is_multiple_of(2) { c.side } else { -c.side };
        let centre = pulled_inside(
            &self.area,
            c.around - c.up * (p.cast_drift_m * f64::from(k)),
            p.edge_margin_m,
        );
        pulled_inside(
            &self.area,
            centre + c.across * (side * 0.5 * width),
            p.edge_margin_m,
        )
    }

    /// Starts casting around the last detection `around` from `pos`.
    fn start_casts(&mut self, t: f64, pos: Vec2, around: Vec2) {
        self.events.push(PlannerEvent::LostPoint { pos_m: around });
        let up = self.flow.upflow().unit();
        let across = self.flow.upflow().turned_deg(90.0).unit();
        // First back across the line the vehicle left the plume on.
        let side = if (pos - around).dot(&across) > 0.0 {
            -1.0
        } else {
            1.0
        };
        let mut c = Casts {
            around,
            up,
            across,
            side,
            k: 0,
            to: Waypoint {
                from: pos,
                goal: pos,
                since_s: t,
            },
        };
        c.to.goal = self.cast_end(&c, 0);
        self.set_mode(Mode::Cast(c));
    }

    /// The cast end to fly to, or `None` once `max_casts` casts in a row have failed (declared).
    fn cast(&mut self, t: f64, pos: Vec2) -> Option<Vec2> {
        let Mode::Cast(mut c) = self.mode.clone() else {
            return None;
        };
        let (r, v) = (self.p.r_m, self.p.autopilot.speed_mps);
        while c.to.reached(t, pos, r, v) {
            self.failed_casts += 1;
            if self.failed_casts >= self.p.max_casts {
                self.declare();
                return None;
            }
            c.k = c.k.saturating_add(1);
            c.to = Waypoint {
                from: c.to.goal,
                goal: self.cast_end(&c, c.k),
                since_s: t,
            };
        }
        self.mode = Mode::Cast(c);
        Some(c.to.goal)
    }

    fn declare(&mut self) {
        if let Some(at) = self.most_upflow_contact() {
            self.declared = Some(at);
            self.events.push(PlannerEvent::Declared {
                pos_m: at,
                rule: MOST_UPFLOW_CONTACT,
            });
        }
        self.set_mode(Mode::Done);
    }

    /// The course for this decision (`None`: hold the last one).
    fn steer(&mut self, t: f64, pos: Vec2) -> Option<Steer> {
        let speed = self.p.autopilot.speed_mps;
        let last = self.last_steer.heading;
        let toward = move |goal: Vec2| Steer {
            heading: bearing_between(pos, goal).unwrap_or(last),
            speed_mps: speed,
        };
        if self.mode == Mode::Done {
            return None;
        }
        match self.last_detection {
            None => {
                self.set_mode(Mode::Find);
                let goal = self.find(t, pos);
                Some(toward(goal))
            }
            Some((tl, _)) if t - tl <= self.p.lambda_s => {
                self.set_mode(Mode::Surge);
                Some(Steer {
                    heading: self.flow.upflow(),
                    speed_mps: speed,
                })
            }
            Some((_, at)) => {
                if !matches!(self.mode, Mode::Cast(_)) {
                    self.start_casts(t, pos, at);
                }
                self.cast(t, pos).map(toward)
            }
        }
    }
}

impl Planner for SurgeCast {
    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        let t = s.time_s;
        if let Some(f) = s.flow {
            self.flow.add(f.time_s, f.velocity_mps);
            if f.velocity_mps.x.is_finite() && f.velocity_mps.y.is_finite() {
                self.flow_sum += f.velocity_mps;
                self.flow_count += 1;
            }
        }
        let flow = self.flow.velocity_mps();
        let pos = s
            .nav
            .pos_m
            .filter(|p| p.x.is_finite() && p.y.is_finite() && t.is_finite());
        let Some(pos) = pos else {
            let command = self
                .autopilot
                .command(t, None, s.nav.heading, self.last_steer, flow)
                .unwrap_or_else(|a| a.command);
            let status = if self.mode == Mode::Done {
                PlanStatus::Finished
            } else {
                PlanStatus::Running
            };
            return Decision::new(command, status);
        };
        if self.mode != Mode::Done {
            let threshold = self.p.autopilot.threshold_v;
            let detected = s.chem.iter().any(|c| c.reading > threshold);
            self.sense(t, pos, detected);
        }
        if let Some(steer) = self.steer(t, pos) {
            self.last_steer = steer;
        }
        let mut telemetry = Vec::new();
        // The source estimate: the declaration, or else the most up-flow contact point; reported
        // when it first exists, when it moves by ESTIMATE_STEP_M or more, and at the declaration.
        if let Some(pos_m) = self.declared.or_else(|| self.most_upflow_contact()) {
            let moved = self
                .reported_estimate
                .is_none_or(|r| (r - pos_m).norm() >= ESTIMATE_STEP_M);
            if moved || (self.declared.is_some() && self.reported_estimate != Some(pos_m)) {
                self.reported_estimate = Some(pos_m);
                telemetry.push(Telemetry::SourceEstimate { pos_m });
            }
        }
        let done = self.mode == Mode::Done;
        let (command, status) =
            match self
                .autopilot
                .command(t, Some(pos), s.nav.heading, self.last_steer, flow)
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

    /// The op-area of the tests: 0..400 m East by 0..200 m North; the flow goes East (90 deg),
    /// so up-flow is West (270 deg) and across the flow is North-South.
    fn area() -> OpArea {
        OpArea::rectangle(0.0, 400.0, 0.0, 200.0).unwrap_or_else(|e| panic!("{e}"))
    }

    fn planner(p: SurgeCastParams) -> SurgeCast {
        SurgeCast::new(p, area(), Heading::from_deg(90.0))
    }

    fn snap(t: f64, pos: Vec2, reading: f64) -> SensorSnapshot {
        SensorSnapshot {
            time_s: t,
            vehicle: VehicleId(0),
            nav: NavEstimate {
                pos_m: Some(pos),
                heading: Heading::from_deg(270.0),
                speed_mps: 2.0,
                altitude_m: Some(2.0),
                depth_m: None,
                last_fix_s: None,
            },
            chem: vec![ChemSample { time_s: t, reading }],
            flow: Some(FlowSample {
                time_s: t,
                velocity_mps: Vec2::new(0.2, 0.0),
            }),
            ranges: None,
            inbox: vec![],
        }
    }

    fn finite(d: &Decision) -> bool {
        d.command.heading.deg().is_finite() && d.command.speed_mps.is_finite()
    }

    #[test]
    fn the_spiral_grows_from_the_start_and_keeps_inside_the_op_area() {
        // From outside the South-East corner: the first waypoint is that corner brought inside.
        let mut m = planner(SurgeCastParams::default());
        let d = m.decide(&snap(0.0, Vec2::new(420.0, -10.0), 0.0));
        assert!(finite(&d));
        assert_eq!(m.behaviour(), BehaviourKind::Find);
        assert_eq!(
            d.events,
            [PlannerEvent::Behaviour {
                behaviour: BehaviourKind::Find
            }]
        );
        let centre = m.goal().unwrap_or_else(|| panic!("no goal"));
        assert!(
            (centre - Vec2::new(390.0, 10.0)).norm() < 1e-3,
            "{centre:?}"
        );
        // Fly to every waypoint in turn (the vehicle placed on it): each one is at least the
        // margin inside; the spiral's radius grows by about a spacing per turn until it covers
        // the area, then it starts again from its centre.
        let mut far = 0.0_f64;
        let mut restarts = 0;
        let mut last_r = 0.0;
        for k in 0..3000 {
            let Some(goal) = m.goal() else {
                panic!("no goal at waypoint {k}");
            };
            let e = area().edge_info(goal);
            assert!(e.inside && e.distance_m >= 10.0 - 1e-6, "{goal:?} at {k}");
            let r = (goal - centre).norm();
            if r + 50.0 < last_r {
                restarts += 1;
            }
            last_r = r;
            far = far.max(r);
            let d = m.decide(&snap(f64::from(k) + 1.0, goal, 0.0));
            assert!(finite(&d) && d.status == PlanStatus::Running);
            assert_eq!(m.behaviour(), BehaviourKind::Find);
        }
        assert!(far > 380.0, "the spiral reached only {far} m out");
        assert!(restarts >= 1, "the spiral never started again");
    }

    #[test]
    fn a_contact_surges_up_flow() {
        let mut m = planner(SurgeCastParams::default());
        m.decide(&snap(0.0, Vec2::new(200.0, 100.0), 0.0));
        let d = m.decide(&snap(1.0, Vec2::new(200.0, 100.0), 1.0));
        assert_eq!(m.behaviour(), BehaviourKind::TrackIn);
        assert!(m.last_course().diff_deg(Heading::from_deg(270.0)).abs() < 1e-6);
        assert!(d.events.contains(&PlannerEvent::Detection {
            pos_m: Vec2::new(200.0, 100.0)
        }));
        assert!(d.events.contains(&PlannerEvent::Behaviour {
            behaviour: BehaviourKind::TrackIn
        }));
        // Still in contact lambda_s after the detection, with the flow turned North: up-flow is
        // South now.
        let mut s = snap(6.0, Vec2::new(190.0, 100.0), 0.0);
        s.flow = Some(FlowSample {
            time_s: 6.0,
            velocity_mps: Vec2::new(0.0, 0.2),
        });
        let p = SurgeCastParams {
            autopilot: AutopilotKeys {
                flow_average_s: 0.0,
                ..AutopilotKeys::default()
            },
            ..SurgeCastParams::default()
        };
        let mut m = planner(p);
        m.decide(&snap(1.0, Vec2::new(200.0, 100.0), 1.0));
        m.decide(&s);
        assert_eq!(m.behaviour(), BehaviourKind::TrackIn);
        assert!(m.last_course().diff_deg(Heading::from_deg(180.0)).abs() < 1e-6);
    }

    #[test]
    fn a_loss_casts_across_the_flow_ever_wider_around_the_last_detection() {
        let p = SurgeCastParams {
            max_casts: 20,
            cast_drift_m: 2.0,
            ..SurgeCastParams::default()
        };
        let mut m = planner(p.clone());
        let at = Vec2::new(200.0, 100.0);
        m.decide(&snap(0.0, at, 1.0));
        // Lost lambda_s later, a little North of the plume's line (left of it, looking up-flow).
        let d = m.decide(&snap(5.5, Vec2::new(190.0, 103.0), 0.0));
        assert_eq!(m.behaviour(), BehaviourKind::Reacquire);
        assert!(d.events.contains(&PlannerEvent::LostPoint { pos_m: at }));
        let mut t = 6.0;
        let mut ends = Vec::new();
        for _ in 0..8 {
            let goal = m.goal().unwrap_or_else(|| panic!("no cast end"));
            ends.push(goal);
            m.decide(&snap(t, goal, 0.0));
            t += 1.0;
        }
        for (k, end) in ends.iter().enumerate() {
            let width = (20.0 * 2.0_f64.powi(k as i32)).min(160.0);
            // Across the flow from a centre k * 2 m down-flow (East) of the last detection,
            // first back South, then to alternate sides.
            let side = if k % 2 == 0 { -1.0 } else { 1.0 };
            let want = Vec2::new(200.0 + 2.0 * k as f64, 100.0 + side * 0.5 * width);
            assert!(
                (end - want).norm() < 1e-6,
                "cast {k}: {end:?}, not {want:?}"
            );
        }
        assert_eq!(m.behaviour(), BehaviourKind::Reacquire);
        // A new contact surges again; the next loss starts narrow casts around it.
        let again = Vec2::new(210.0, 140.0);
        m.decide(&snap(t, again, 1.0));
        assert_eq!(m.behaviour(), BehaviourKind::TrackIn);
        // Lost South of it this time: the first cast goes North.
        m.decide(&snap(t + 6.0, Vec2::new(200.0, 137.0), 0.0));
        assert_eq!(m.behaviour(), BehaviourKind::Reacquire);
        let goal = m.goal().unwrap_or_else(|| panic!("no cast end"));
        assert!((goal - Vec2::new(210.0, 150.0)).norm() < 1e-6, "{goal:?}");
    }

    #[test]
    fn casts_stay_inside_the_op_area() {
        let mut m = planner(SurgeCastParams {
            max_casts: 10,
            ..SurgeCastParams::default()
        });
        let at = Vec2::new(5.0, 195.0);
        m.decide(&snap(0.0, at, 1.0));
        m.decide(&snap(6.0, at, 0.0));
        for k in 0..9 {
            let goal = m.goal().unwrap_or_else(|| panic!("no cast end"));
            let e = area().edge_info(goal);
            assert!(e.inside && e.distance_m >= 10.0 - 1e-6, "{goal:?} at {k}");
            m.decide(&snap(7.0 + f64::from(k), goal, 0.0));
        }
    }

    #[test]
    fn max_casts_without_progress_declare_at_the_most_up_flow_contact() {
        let p = SurgeCastParams::default();
        let mut m = planner(p.clone());
        let mut events = Vec::new();
        let mut t = 0.0;
        // Contacts at x = 300, then 150 (progress), then 152 and 156 (less than progress_m up-flow
        // of 150 or down-flow of it: no progress), one cast after each loss.
        for (x, casts) in [(300.0, 2), (150.0, 1), (156.0, 1), (152.0, 1)] {
            let d = m.decide(&snap(t, Vec2::new(x, 100.0), 1.0));
            events.extend(d.events);
            t += 6.0;
            for _ in 0..casts {
                let d = m.decide(&snap(t, Vec2::new(x, 100.0), 0.0));
                events.extend(d.events);
                t += 1.0;
                let goal = m.goal().unwrap_or_else(|| panic!("no cast end"));
                let d = m.decide(&snap(t, goal, 0.0));
                events.extend(d.events);
                t += 1.0;
            }
        }
        // Two casts after 300 (before the progress at 150), then one after each of 150, 156 and
        // 152: three failed casts in a row so far.
        assert_eq!(m.failed_casts, 3);
        assert_eq!(m.declared(), None);
        let mut status = PlanStatus::Running;
        for _ in 0..20 {
            let goal = m.goal().unwrap_or_else(|| Vec2::new(150.0, 100.0));
            let d = m.decide(&snap(t, goal, 0.0));
            t += 1.0;
            events.extend(d.events);
            status = d.status;
            if status == PlanStatus::Finished {
                assert_eq!(d.command.speed_mps, 0.0);
                break;
            }
        }
        assert_eq!(status, PlanStatus::Finished);
        assert_eq!(m.failed_casts, p.max_casts);
        let declared: Vec<&PlannerEvent> = events
            .iter()
            .filter(|e| matches!(e, PlannerEvent::Declared { .. }))
            .collect();
        assert_eq!(
            declared,
            [&PlannerEvent::Declared {
                pos_m: Vec2::new(150.0, 100.0),
                rule: MOST_UPFLOW_CONTACT
            }]
        );
        assert_eq!(m.behaviour(), BehaviourKind::Done);
        assert_eq!(m.contact_points().len(), 4);
        // Finished for good: no more events, no more motion, a reading changes nothing.
        let d = m.decide(&snap(t, Vec2::new(100.0, 100.0), 1.0));
        assert_eq!(d.status, PlanStatus::Finished);
        assert_eq!(d.command.speed_mps, 0.0);
        assert!(d.events.is_empty());
        // Every behaviour reported is one the planner declares.
        for e in &events {
            if let Some(b) = e.behaviour() {
                assert!(SurgeCastParams::BEHAVIOURS.contains(&b), "{b:?}");
            }
        }
    }

    #[test]
    fn no_position_no_flow_or_nonsense_readings_never_give_nan() {
        let mut m = planner(SurgeCastParams::default());
        let mut s = snap(0.0, Vec2::new(100.0, 100.0), f64::NAN);
        s.nav.pos_m = None;
        s.flow = None;
        let d = m.decide(&s);
        assert!(finite(&d) && d.status == PlanStatus::Running);
        s.nav.pos_m = Some(Vec2::new(f64::NAN, 1.0));
        s.flow = Some(FlowSample {
            time_s: 1.0,
            velocity_mps: Vec2::new(f64::INFINITY, 0.0),
        });
        s.time_s = 1.0;
        assert!(finite(&m.decide(&s)));
        for k in 0..200 {
            let s = snap(2.0 + f64::from(k), Vec2::new(100.0, 100.0), f64::NAN);
            assert!(finite(&m.decide(&s)));
        }
        assert_eq!(m.behaviour(), BehaviourKind::Find);
        // A spiral in an op-area narrower than two margins: waypoints still finite.
        let thin = OpArea::rectangle(0.0, 400.0, 0.0, 15.0).unwrap_or_else(|e| panic!("{e}"));
        let mut m = SurgeCast::new(SurgeCastParams::default(), thin, Heading::NORTH);
        for k in 0..50 {
            let d = m.decide(&snap(f64::from(k), Vec2::new(50.0, 7.0), 0.0));
            assert!(finite(&d));
            let g = m.goal().unwrap_or_else(|| panic!("no goal"));
            assert!(g.x.is_finite() && g.y.is_finite());
        }
    }

    #[test]
    fn a_narrower_widest_cast_than_the_first_is_refused() {
        let p = SurgeCastParams {
            max_cast_width_m: 10.0,
            ..SurgeCastParams::default()
        };
        let e = p.validate("p").err().unwrap_or_else(|| panic!("accepted"));
        assert_eq!(e.key, "p.max_cast_width_m");
        assert!(SurgeCastParams::default().validate("p").is_ok());
    }

    /// Flies the planner on a kinematic vehicle (turn-rate limited, 0.5 s steps) from the
    /// South-East corner over a plume whose readings lie only down-flow of `source`, and returns
    /// its events, last status and time.
    fn fly(source: Vec2) -> (Vec<PlannerEvent>, PlanStatus, f64) {
        let mut m = planner(SurgeCastParams::default());
        let mut pos = Vec2::new(395.0, 5.0);
        let mut heading = Heading::from_deg(270.0);
        let mut events = Vec::new();
        let dt = 0.5;
        for k in 0..20_000 {
            let t = f64::from(k) * dt;
            let d = pos - source;
            let reading = if d.x > 0.0 {
                3.0 * (-(d.y * d.y) / (2.0 * (3.0 + 0.1 * d.x).powi(2))).exp()
            } else {
                0.0
            };
            let decision = m.decide(&snap(t, pos, reading));
            assert!(finite(&decision));
            events.extend(decision.events);
            if decision.status != PlanStatus::Running {
                return (events, decision.status, t);
            }
            let turn = decision.command.heading.diff_deg(heading).clamp(-5.0, 5.0);
            heading = heading.turned_deg(turn);
            pos += heading.unit() * decision.command.speed_mps * dt + Vec2::new(0.2, 0.0) * dt;
            assert!(area().edge_info(pos).distance_m < 30.0 || area().contains(pos));
        }
        (events, PlanStatus::Running, f64::INFINITY)
    }

    #[test]
    fn spirals_surges_casts_and_declares_near_the_source() {
        let source = Vec2::new(100.0, 120.0);
        let (events, status, t) = fly(source);
        assert_eq!(status, PlanStatus::Finished, "after {t} s");
        let kinds: Vec<BehaviourKind> = events.iter().filter_map(PlannerEvent::behaviour).collect();
        assert_eq!(
            kinds[..3],
            [
                BehaviourKind::Find,
                BehaviourKind::TrackIn,
                BehaviourKind::Reacquire
            ]
        );
        assert_eq!(kinds.last(), Some(&BehaviourKind::Done));
        let declared: Vec<Vec2> = events
            .iter()
            .filter_map(|e| match e {
                PlannerEvent::Declared { pos_m, .. } => Some(*pos_m),
                _ => None,
            })
            .collect();
        assert_eq!(declared.len(), 1);
        assert!((declared[0] - source).norm() < 10.0, "{:?}", declared[0]);
    }
}
