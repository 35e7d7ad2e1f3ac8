//! Obstacle avoidance for any planner: the fuzzy following-obstacle layer with dynamic reference
//! targets (seed 001), as the top layer over a whole planner.
//!
//! [`AvoidObstacles`] wraps a planner. The wrapped planner decides at every snapshot as usual (it
//! keeps sensing, timing and remembering); while no obstacle is near, its decision goes out as it
//! is. An obstacle is *sensed* when the front range group sees one closer than
//! [`AvoidParams::trigger_m`] or a side group one closer than [`AvoidParams::side_clear_m`]
//! (distances as the engine sees them, below). Then avoidance takes over:
//! - a virtual path is laid through the vehicle's estimated position along the course the wrapped
//!   planner was commanding (the course of the interrupted behaviour), and a dynamic reference
//!   target (DRT) 15 m ahead on it ([`Drt`]); the DRT advances 15 m each time the vehicle's
//!   projection on the path reaches it;
//! - every [`AvoidParams::period_s`] the fuzzy engine with its side lock ([`Avoider`]) turns the
//!   three range groups and the angle from the heading to the DRT into a heading change (10 deg
//!   per 0.5 s at most: 20 deg/s) and a speed; the heading command is the vehicle's heading
//!   turned by that change; and a side obstacle closer than [`AvoidParams::side_min_m`] (3 m;
//!   nearer than the other side's) turns the vehicle fully away from it, which the rules never
//!   do (they hold the heading along an edge, which in still water keeps the distance);
//! - when the vehicle reaches the DRT (its projection on the path gets there) with nothing in
//!   front closer than `trigger_m` (returns on the sides do not matter: the vehicle may pass
//!   alongside kelp), or after [`AvoidParams::max_detour_s`] in any case (a detour that has
//!   followed the edges of a large field for minutes has lost its purpose), the obstacle is
//!   passed: the wrapped planner is told ([`Planner::detour_ended`], so a planner that lost the
//!   plume meanwhile searches around that point) and its commands go out again.
//!
//! # In a current
//!
//! The engine was written for still water: its distances give the vehicle time to turn at its
//! own speeds, 0.25 to 2 m/s. Carried by a current the vehicle closes on an obstacle at its speed
//! over the ground, and a slow speed through the water lets the current sweep it backwards, into
//! kelp its forward-looking sensors cannot see. So:
//! - each group's distance is divided by its closing factor: the estimated ground velocity
//!   (heading and measured speed, plus the flow averaged over [`AvoidParams::flow_average_s`])
//!   along the group's middle direction (0 deg for the front, 60 deg to either side) over the
//!   engine's medium speed (1.2 m/s), when above 1: the vehicle gets the time it would have in
//!   still water;
//! - the speed through the water is never below what keeps the vehicle's authority, up to the
//!   wrapped planner's speed: the current's part from ahead plus its part across the heading plus
//!   [`AvoidParams::authority_mps`]. Heading into the current the vehicle keeps headway; heading
//!   with it the engine's slow speeds apply, so the vehicle does not close on an obstacle ahead at
//!   its full speed plus the current's while it decides on a side;
//! - the fuzzy heading is checked in the ground frame before it goes out ([`SafetyFilter`]): the
//!   returns of the last 3 s are kept as points over their groups' sectors, the track the heading
//!   gives over the next 6 s (at the turn rate, carried by the measured current) must keep 3 m
//!   from all of them, or the heading nearest to it whose track does is flown instead (the one
//!   with the most room when none does), still at most 10 deg per half second from the heading.
//!
//! Measured on 800 `li-zhang-kelp` missions (two campaigns of 200 seeds, passive and active):
//! 14 collisions with a floor of the current's whole speed and no ground-frame check, 5 with both
//! changes. On 400 of them either change alone gave about as many as before (3 and 4, against 5),
//! and a floor without the across part 93 (the current sweeps a slow vehicle sideways).
//!
//! Sonar pings miss kelp now and then: a group whose ping misses an obstacle it saw less than
//! [`AvoidParams::hold_s`] (1 s) ago keeps that return. A vehicle without range sensors, or
//! without a position estimate, is never diverted. Events: [`PlannerEvent::AvoidStart`] (the
//! path), [`PlannerEvent::ReferenceTarget`] (each DRT), [`PlannerEvent::AvoidEnd`], and behaviour
//! switches to [`BehaviourKind::Avoid`] and back to the wrapped planner's behaviour.

use crate::FlowEstimate;
use crate::fuzzy::{
    Avoider, AvoiderParams, Drt, DrtStatus, FuzzyInputs, SafetyFilter, SafetyParams, head_ang_deg,
};
use plumetrace_core::{
    BehaviourKind, Decision, Heading, Planner, PlannerEvent, RangeReturn, SensorSnapshot, Vec2,
};

/// The fuzzy engine's largest heading change (the `pos` centre of `head_c`), deg.
const MAX_TURN_DEG: f64 = 10.0;
/// Exponent of the side groups' closing factor.
const SIDE_EXPONENT: f64 = 2.0;
/// Exponent of the front group's closing factor.
const CLOSING_EXPONENT: f64 = 2.0;
/// The fuzzy engine's medium speed, m/s.
const ENGINE_MEDIUM_MPS: f64 = 1.2;
/// Middle directions of the left, front and right range groups, deg off the heading.
const GROUP_MIDDLE_DEG: [f64; 3] = [-60.0, 0.0, 60.0];

/// Settings of obstacle avoidance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AvoidParams {
    /// A front return closer than this starts avoidance, m.
    pub trigger_m: f64,
    /// A side return closer than this starts avoidance, m.
    pub side_clear_m: f64,
    /// During a detour, a side closer than this (and nearer than the other) turns the vehicle
    /// fully away from it, m.
    pub side_min_m: f64,
    /// Time between fuzzy commands, s (the engine's heading change is per command).
    pub period_s: f64,
    /// Distance between successive reference targets, m.
    pub drt_step_m: f64,
    /// Time constant of the flow estimate, s.
    pub flow_average_s: f64,
    /// Speed through the water kept above the current's speed, m/s.
    pub authority_mps: f64,
    /// Longest detour, s.
    pub max_detour_s: f64,
    /// How long a range return is held when the next pings miss the obstacle, s.
    pub hold_s: f64,
}

impl Default for AvoidParams {
    fn default() -> Self {
        AvoidParams {
            trigger_m: 10.0,
            side_clear_m: 5.0,
            side_min_m: 3.0,
            period_s: 0.5,
            drt_step_m: crate::fuzzy::DRT_STEP_M,
            flow_average_s: 10.0,
            authority_mps: 0.5,
            max_detour_s: 120.0,
            hold_s: 1.0,
        }
    }
}

/// Avoidance in progress.
struct Detour {
    drt: Drt,
    /// When it started, s.
    start_s: f64,
    /// Time and command (heading, speed) of the last fuzzy evaluation.
    last: Option<(f64, Heading, f64)>,
}

/// A planner with obstacle avoidance on top.
pub struct AvoidObstacles {
    inner: Box<dyn Planner>,
    params: AvoidParams,
    avoider: Avoider,
    detour: Option<Detour>,
    flow: FlowEstimate,
    /// The last return of each group (left, front, right) with its time.
    held: [Option<(f64, f64)>; 3],
    /// The wrapped planner's behaviour (restored in the logs when a detour ends).
    inner_behaviour: Option<BehaviourKind>,
    /// Recent returns and the ground-frame check of the fuzzy command.
    safety: SafetyFilter,
    /// The last ping remembered (a snapshot repeats it until the next one).
    last_ping: Option<RangeReturn>,
}

impl AvoidObstacles {
    /// `inner` with avoidance.
    pub fn new(inner: Box<dyn Planner>, params: AvoidParams) -> Self {
        AvoidObstacles {
            inner,
            params,
            avoider: Avoider::new(AvoiderParams::default()),
            detour: None,
            flow: FlowEstimate::new(params.flow_average_s, Heading::NORTH),
            held: [None; 3],
            inner_behaviour: None,
            safety: SafetyFilter::new(SafetyParams::default()),
            last_ping: None,
        }
    }

    /// Whether a detour is being flown.
    pub fn avoiding(&self) -> bool {
        self.detour.is_some()
    }

    /// The ranges with missed returns filled from the held ones (and the held ones updated).
    fn hold(&mut self, t_s: f64, r: Option<RangeReturn>) -> Option<RangeReturn> {
        let r = r?;
        let mut out = [r.left_m, r.front_m, r.right_m];
        for (g, held) in out.iter_mut().zip(self.held.iter_mut()) {
            match *g {
                Some(d) if d.is_finite() => *held = Some((t_s, d)),
                _ => {
                    *g = held
                        .filter(|(t, _)| t_s - t <= self.params.hold_s)
                        .map(|h| h.1);
                }
            }
        }
        Some(RangeReturn {
            left_m: out[0],
            front_m: out[1],
            right_m: out[2],
        })
    }

    /// The distances as the engine sees them: each group's divided by its closing factor.
    fn effective(&self, s: &SensorSnapshot, r: RangeReturn) -> RangeReturn {
        let ground = s.nav.heading.unit() * s.nav.speed_mps + self.flow.velocity_mps();
        let scale = |d: Option<f64>, middle_deg: f64, exponent: f64| {
            let v = ground.dot(&s.nav.heading.turned_deg(middle_deg).unit());
            let k = if v.is_finite() {
                (v / ENGINE_MEDIUM_MPS).max(1.0).powf(exponent)
            } else {
                1.0
            };
            d.map(|d| d / k)
        };
        RangeReturn {
            left_m: scale(r.left_m, GROUP_MIDDLE_DEG[0], SIDE_EXPONENT),
            front_m: scale(r.front_m, GROUP_MIDDLE_DEG[1], CLOSING_EXPONENT),
            right_m: scale(r.right_m, GROUP_MIDDLE_DEG[2], SIDE_EXPONENT),
        }
    }

    /// Whether these (effective) ranges call for avoidance.
    fn sensed(&self, r: &RangeReturn) -> bool {
        r.front_m.is_some_and(|d| d < self.params.trigger_m)
            || r.left_m.is_some_and(|d| d < self.params.side_clear_m)
            || r.right_m.is_some_and(|d| d < self.params.side_clear_m)
    }
}

impl Planner for AvoidObstacles {
    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        let mut events = Vec::new();
        let pos = s.nav.pos_m;
        if let Some(f) = s.flow {
            self.flow.add(f.time_s, f.velocity_mps);
        }
        if let (Some(p), Some(r)) = (pos, s.ranges)
            && self.last_ping != Some(r)
        {
            self.last_ping = Some(r);
            self.safety.remember(s.time_s, p, s.nav.heading, &r);
        }
        let raw = self.hold(s.time_s, s.ranges);
        let ranges = raw.map(|r| self.effective(s, r));
        // 1. A detour that is over hands control back before the wrapped planner decides.
        let ahead = raw.is_some_and(|r| r.front_m.is_some_and(|d| d < self.params.trigger_m));
        if let (Some(d), Some(p)) = (&mut self.detour, pos) {
            let before = d.drt.target;
            let status = if s.time_s - d.start_s > self.params.max_detour_s {
                DrtStatus::Passed
            } else {
                d.drt.step(p, ahead)
            };
            match status {
                DrtStatus::Passed => {
                    self.detour = None;
                    self.avoider.reset();
                    events.push(PlannerEvent::AvoidEnd { pos_m: p });
                    if let Some(b) = self.inner_behaviour {
                        events.push(PlannerEvent::Behaviour { behaviour: b });
                    }
                    self.inner.detour_ended(p);
                }
                DrtStatus::Target(t) if t != before => {
                    events.push(PlannerEvent::ReferenceTarget { pos_m: t });
                }
                DrtStatus::Target(_) => {}
            }
        }
        // 2. The wrapped planner decides (its behaviour switches are remembered, and logged
        //    only while it is in control).
        let mut decision = self.inner.decide(s);
        for e in std::mem::take(&mut decision.events) {
            if let Some(b) = e.behaviour() {
                self.inner_behaviour = Some(b);
                if self.detour.is_some() {
                    continue;
                }
            }
            events.push(e);
        }
        // 3. An obstacle sensed: a detour starts on the course the wrapped planner commands.
        if let (Some(p), Some(r)) = (pos, ranges)
            && self.detour.is_none()
            && self.sensed(&r)
        {
            let course = decision.command.heading;
            let drt = Drt::new(p, course, self.params.drt_step_m);
            events.push(PlannerEvent::Behaviour {
                behaviour: BehaviourKind::Avoid,
            });
            events.push(PlannerEvent::AvoidStart {
                pos_m: p,
                course_deg: course.deg(),
            });
            events.push(PlannerEvent::ReferenceTarget { pos_m: drt.target });
            self.detour = Some(Detour {
                drt,
                start_s: s.time_s,
                last: None,
            });
        }
        // 4. During a detour the fuzzy layer steers.
        if let (Some(p), Some(d)) = (pos, self.detour.as_ref()) {
            let (target, last) = (d.drt.target, d.last);
            let due = last.is_none_or(|(t, _, _)| s.time_s - t >= self.params.period_s - 1e-9);
            let (heading, speed) = match (due, last) {
                (false, Some((_, h, v))) => (h, v),
                _ => {
                    let head_ang = head_ang_deg(p, s.nav.heading, target);
                    let inputs =
                        FuzzyInputs::from_ranges(&ranges.unwrap_or_default(), head_ang).sanitized();
                    let mut out = self.avoider.command(&inputs, self.params.period_s);
                    // Drift toward a side obstacle: the rules hold the heading along an edge
                    // (still water keeps the distance), so a side closer than `side_min_m`
                    // (and nearer than the other) turns the vehicle fully away from it.
                    let m = self.params.side_min_m;
                    let max_turn = MAX_TURN_DEG;
                    if inputs.left_m < m && inputs.left_m < inputs.right_m {
                        out.turn_deg = out.turn_deg.max(max_turn);
                    } else if inputs.right_m < m && inputs.right_m < inputs.left_m {
                        out.turn_deg = out.turn_deg.min(-max_turn);
                    }
                    let max = decision.command.speed_mps.max(0.0);
                    // Speed through the water that keeps the vehicle's authority: enough to
                    // stand against the current's part from ahead and the part across.
                    let flow = self.flow.velocity_mps();
                    let along = flow.dot(&s.nav.heading.unit());
                    let across = (flow - s.nav.heading.unit() * along).norm();
                    let floor = (-along).max(0.0) + across + self.params.authority_mps;
                    let v = out.speed_mps.max(floor).min(max);
                    let fuzzy = s.nav.heading.turned_deg(out.turn_deg);
                    let safe = self.safety.check(p, s.nav.heading, fuzzy, v, flow);
                    let h = s.nav.heading.turned_deg(
                        safe.diff_deg(s.nav.heading)
                            .clamp(-MAX_TURN_DEG, MAX_TURN_DEG),
                    );
                    if let Some(d) = self.detour.as_mut() {
                        d.last = Some((s.time_s, h, v));
                    }
                    (h, v)
                }
            };
            decision.command.heading = heading;
            decision.command.speed_mps = speed;
        }
        decision.events = events;
        decision
    }

    fn decision_period_s(&self) -> f64 {
        self.inner.decision_period_s()
    }

    fn detour_ended(&mut self, pos_m: Vec2) {
        self.inner.detour_ended(pos_m);
    }

    fn run_ended(&mut self, t_s: f64) -> Vec<PlannerEvent> {
        self.inner.run_ended(t_s)
    }
}
