//! Behaviours propose, an arbiter decides.
//!
//! A [`Behaviour`] looks at the vehicle's [`Percept`] and the planner's memory `M` and proposes a
//! course ([`Proposal::Steer`]), says it is finished ([`Proposal::Done`] with a reason of the
//! planner's type `D`), or has nothing to say ([`Proposal::Idle`]). An [`Arbiter`] owns the
//! behaviours and decides which proposal steers: the AMP's switching logic is one arbiter
//! ([`crate::amp`]), the [`Sequence`] (one behaviour after the other) another; subsumption and
//! fuzzy blending fit the same two traits.
//!
//! Behaviours that any planner can use live here: [`GoTo`] (drive to a point), [`Legs`] (fly a
//! list of lines, as in a survey or a mapping pattern) and [`Idle`] (the mission is over).

use plumetrace_core::{BehaviourKind, Heading, PlannerEvent, Vec2};
use plumetrace_guidance::{FollowLine, GoToPoint, ModeStatus, Pose, Steer};

/// What a behaviour sees at one decision: the vehicle's own estimates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Percept {
    /// Mission time, s.
    pub t_s: f64,
    /// Estimated position, m.
    pub pos_m: Vec2,
    /// Measured heading.
    pub heading: Heading,
    /// A chemical sample since the last decision exceeded the planner's detection threshold.
    pub detected: bool,
}

impl Percept {
    /// The estimated pose.
    pub fn pose(&self) -> Pose {
        Pose {
            pos_m: self.pos_m,
            heading: self.heading,
        }
    }
}

/// A goal was reached or a pattern flown to its end: the reason generic behaviours give when
/// they finish. A planner's own reason type converts from it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reached;

/// A behaviour's answer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Proposal<D> {
    /// Steer this way.
    Steer(Steer),
    /// Finished, for this reason.
    Done(D),
    /// Nothing to say (does not want control).
    Idle,
}

/// One behaviour of a planner with memory `M` and finishing reasons `D`.
pub trait Behaviour<M, D>: Send {
    /// Which behaviour this is (for logs and figures).
    fn kind(&self) -> BehaviourKind;

    /// Its proposal for this decision.
    fn propose(&mut self, p: &Percept, m: &mut M) -> Proposal<D>;
}

/// Decides which behaviour steers.
pub trait Arbiter<M> {
    /// The course for this decision; `None` when no behaviour steers (the planner then holds its
    /// last course).
    fn arbitrate(&mut self, p: &Percept, m: &mut M) -> Option<Steer>;

    /// The behaviour in control.
    fn active(&self) -> BehaviourKind;
}

/// Where a planner's memory keeps its events (arbiters log behaviour switches there).
pub trait EventLog {
    /// Appends an event.
    fn log(&mut self, e: PlannerEvent);
}

impl EventLog for Vec<PlannerEvent> {
    fn log(&mut self, e: PlannerEvent) {
        self.push(e);
    }
}

/// Drive to a point ([`GoToPoint`]); done on arrival.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GoTo {
    /// The guidance mode.
    pub goal: GoToPoint,
    /// Reported as (e.g. [`BehaviourKind::GoTo`] or [`BehaviourKind::Transit`]).
    pub kind: BehaviourKind,
}

impl<M, D: From<Reached>> Behaviour<M, D> for GoTo {
    fn kind(&self) -> BehaviourKind {
        self.kind
    }

    fn propose(&mut self, p: &Percept, _: &mut M) -> Proposal<D> {
        match self.goal.update(p.pos_m) {
            ModeStatus::Running(s) => Proposal::Steer(s),
            ModeStatus::Done(_) => Proposal::Done(Reached.into()),
        }
    }
}

/// How lines are flown: Follow Line settings shared by every leg.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineParams {
    /// Speed command, m/s.
    pub speed_mps: f64,
    /// Arrival radius `R`, m.
    pub radius_m: f64,
    /// Cross-track gain `K`, deg/m.
    pub gain_deg_per_m: f64,
    /// Turning radius of the approach to each line, m.
    pub min_turn_radius_m: f64,
    /// Re-plans of the approach to a line's start before it gives up and the line is joined
    /// from where the vehicle is (`u32::MAX`: never).
    pub approach_replans: u32,
}

impl LineParams {
    /// A Follow Line leg from `a` to `b`, approached with the line's heading.
    pub fn line(&self, a: Vec2, b: Vec2) -> FollowLine {
        FollowLine::new(
            a,
            b,
            self.speed_mps,
            self.radius_m,
            self.gain_deg_per_m,
            self.min_turn_radius_m,
        )
        .with_approach_replans(self.approach_replans)
    }
}

/// Fly a list of lines in order (each approached with its heading); done after the last.
#[derive(Debug, Clone)]
pub struct Legs {
    legs: Vec<(Vec2, Vec2)>,
    k: usize,
    line: Option<Box<FollowLine>>,
    params: LineParams,
    kind: BehaviourKind,
    /// Longest time the pattern is flown, s, and when it started.
    timeout_s: Option<f64>,
    started_s: Option<f64>,
    /// Leg budgets on ([`Legs::with_leg_budgets`]), and the time and position the leg began at.
    leg_budgets: bool,
    leg_started: Option<(f64, Vec2)>,
}

/// Slack of a leg's time budget, s.
const LEG_SLACK_S: f64 = 300.0;

impl Legs {
    /// The pattern `legs` (start, end) flown with `params`, reported as `kind`.
    pub fn new(legs: Vec<(Vec2, Vec2)>, params: LineParams, kind: BehaviourKind) -> Self {
        let line = legs.first().map(|(a, b)| Box::new(params.line(*a, *b)));
        Legs {
            legs,
            k: 0,
            line,
            params,
            kind,
            timeout_s: None,
            started_s: None,
            leg_budgets: false,
            leg_started: None,
        }
    }

    /// Each leg given up (the pattern goes on with the next) when not done in twice the time
    /// to fly from where it began to its start and along it, plus five minutes: a leg the
    /// vehicle cannot finish (the cage or the current in the way) never holds the pattern.
    pub fn with_leg_budgets(mut self) -> Self {
        self.leg_budgets = true;
        self
    }

    /// The pattern, given up `timeout_s` after its first decision (done as if flown).
    pub fn with_timeout(mut self, timeout_s: f64) -> Self {
        self.timeout_s = Some(timeout_s);
        self
    }

    /// The legs.
    pub fn legs(&self) -> &[(Vec2, Vec2)] {
        &self.legs
    }

    /// Index of the leg being flown.
    pub fn current(&self) -> usize {
        self.k
    }
}

impl<M, D: From<Reached>> Behaviour<M, D> for Legs {
    fn kind(&self) -> BehaviourKind {
        self.kind
    }

    fn propose(&mut self, p: &Percept, _: &mut M) -> Proposal<D> {
        let started = *self.started_s.get_or_insert(p.t_s);
        if self.timeout_s.is_some_and(|t| p.t_s - started > t) {
            self.line = None;
            return Proposal::Done(Reached.into());
        }
        // Several legs may end at one decision (short legs, a fix that jumps past them).
        while let Some(line) = self.line.as_mut() {
            let (t0, from) = *self.leg_started.get_or_insert((p.t_s, p.pos_m));
            let over_budget = self.leg_budgets && {
                let length = (line.start_m - from).norm() + (line.end_m - line.start_m).norm();
                p.t_s - t0 > 2.0 * length / self.params.speed_mps.max(0.1) + LEG_SLACK_S
            };
            let status = if over_budget {
                ModeStatus::Done(plumetrace_guidance::DoneReason::GaveUp)
            } else {
                line.update(p.pose())
            };
            match status {
                ModeStatus::Running(s) => return Proposal::Steer(s),
                ModeStatus::Done(_) => {
                    self.leg_started = None;
                    self.k += 1;
                    self.line = self
                        .legs
                        .get(self.k)
                        .map(|(a, b)| Box::new(self.params.line(*a, *b)));
                }
            }
        }
        Proposal::Done(Reached.into())
    }
}

/// No more commands: the mission is over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Idle;

impl<M, D> Behaviour<M, D> for Idle {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::Done
    }

    fn propose(&mut self, _: &Percept, _: &mut M) -> Proposal<D> {
        Proposal::Idle
    }
}

/// The simplest arbiter: one behaviour after the other, each until it is done; then [`Idle`].
pub struct Sequence<M> {
    queue: std::collections::VecDeque<Box<dyn Behaviour<M, Reached>>>,
    active: Box<dyn Behaviour<M, Reached>>,
}

impl<M: EventLog + 'static> Sequence<M> {
    /// A sequence of behaviours, started when [`Sequence::start`] is called.
    pub fn new(behaviours: Vec<Box<dyn Behaviour<M, Reached>>>) -> Self {
        Sequence {
            queue: behaviours.into(),
            active: Box::new(Idle),
        }
    }

    /// Makes the first behaviour active (and logs it).
    pub fn start(&mut self, m: &mut M) {
        self.next(m);
    }

    fn next(&mut self, m: &mut M) {
        let next = self.queue.pop_front().unwrap_or_else(|| Box::new(Idle));
        let changed = next.kind() != self.active.kind();
        self.active = next;
        if changed {
            m.log(PlannerEvent::Behaviour {
                behaviour: self.active.kind(),
            });
        }
    }
}

impl<M: EventLog + 'static> Arbiter<M> for Sequence<M> {
    fn arbitrate(&mut self, p: &Percept, m: &mut M) -> Option<Steer> {
        loop {
            match self.active.propose(p, m) {
                Proposal::Steer(s) => return Some(s),
                Proposal::Idle => return None,
                Proposal::Done(Reached) => self.next(m),
            }
        }
    }

    fn active(&self) -> BehaviourKind {
        self.active.kind()
    }
}

/// Subsumption: behaviours in layers of priority, the highest that has something to say wins
/// and inhibits every layer below it for this decision. A layer's `Done` is handed to the
/// planner's `on_done` (which may change the memory, e.g. record a declaration) and the layers
/// are asked again, at most once per layer, so that a finished layer gives way below it.
pub struct Subsumption<M, D> {
    layers: Vec<Box<dyn Behaviour<M, D>>>,
    on_done: fn(&mut M, D),
    active: BehaviourKind,
}

impl<M: EventLog + 'static, D: 'static> Subsumption<M, D> {
    /// Layers from the highest priority to the lowest; `on_done` receives every finished layer's
    /// reason.
    pub fn new(layers: Vec<Box<dyn Behaviour<M, D>>>, on_done: fn(&mut M, D)) -> Self {
        Subsumption {
            layers,
            on_done,
            active: BehaviourKind::Done,
        }
    }

    fn switch_to(&mut self, m: &mut M, kind: BehaviourKind) {
        if kind != self.active {
            self.active = kind;
            m.log(PlannerEvent::Behaviour { behaviour: kind });
        }
    }
}

impl<M: EventLog + 'static, D: 'static> Arbiter<M> for Subsumption<M, D> {
    fn arbitrate(&mut self, p: &Percept, m: &mut M) -> Option<Steer> {
        for _ in 0..=self.layers.len() {
            let mut finished = false;
            for k in 0..self.layers.len() {
                match self.layers[k].propose(p, m) {
                    Proposal::Idle => continue,
                    Proposal::Steer(s) => {
                        let kind = self.layers[k].kind();
                        self.switch_to(m, kind);
                        return Some(s);
                    }
                    Proposal::Done(d) => {
                        (self.on_done)(m, d);
                        finished = true;
                        break;
                    }
                }
            }
            if !finished {
                break;
            }
        }
        self.switch_to(m, BehaviourKind::Done);
        None
    }

    fn active(&self) -> BehaviourKind {
        self.active
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn percept(x: f64, y: f64, heading_deg: f64) -> Percept {
        Percept {
            t_s: 0.0,
            pos_m: Vec2::new(x, y),
            heading: Heading::from_deg(heading_deg),
            detected: false,
        }
    }

    #[test]
    fn a_sequence_runs_each_behaviour_to_its_end_then_idles() {
        let params = LineParams {
            speed_mps: 2.0,
            radius_m: 5.0,
            gain_deg_per_m: 5.0,
            min_turn_radius_m: 5.0,
            approach_replans: 4,
        };
        let go: Box<dyn Behaviour<Vec<PlannerEvent>, Reached>> = Box::new(GoTo {
            goal: GoToPoint {
                target_m: Vec2::new(0.0, 100.0),
                speed_mps: 2.0,
                radius_m: 5.0,
            },
            kind: BehaviourKind::GoTo,
        });
        let legs = Box::new(Legs::new(
            vec![(Vec2::new(0.0, 100.0), Vec2::new(100.0, 100.0))],
            params,
            BehaviourKind::Survey,
        ));
        let mut log: Vec<PlannerEvent> = Vec::new();
        let mut s = Sequence::new(vec![go, legs]);
        s.start(&mut log);
        assert_eq!(s.active(), BehaviourKind::GoTo);
        let steer = s.arbitrate(&percept(0.0, 0.0, 0.0), &mut log);
        assert!(
            steer.is_some_and(|s| s.heading.deg().abs() < 1e-9),
            "{steer:?}"
        );
        // At the goal: the survey takes over at once and steers along its line.
        let steer = s.arbitrate(&percept(0.0, 98.0, 90.0), &mut log);
        assert_eq!(s.active(), BehaviourKind::Survey);
        assert!(steer.is_some());
        // Past the end of the only line: done, then idle for good.
        assert_eq!(s.arbitrate(&percept(120.0, 100.0, 90.0), &mut log), None);
        assert_eq!(s.active(), BehaviourKind::Done);
        let kinds: Vec<BehaviourKind> = log.iter().filter_map(PlannerEvent::behaviour).collect();
        assert_eq!(
            kinds,
            [
                BehaviourKind::GoTo,
                BehaviourKind::Survey,
                BehaviourKind::Done
            ]
        );
    }

    /// A layer that steers on `heading_deg` while `on(m)`, or finishes once with `Reached`.
    struct Layer {
        kind: BehaviourKind,
        heading_deg: f64,
        on: fn(&[PlannerEvent]) -> bool,
        finishes: bool,
    }

    impl Behaviour<Vec<PlannerEvent>, Reached> for Layer {
        fn kind(&self) -> BehaviourKind {
            self.kind
        }

        fn propose(&mut self, _: &Percept, m: &mut Vec<PlannerEvent>) -> Proposal<Reached> {
            if !(self.on)(m) {
                return Proposal::Idle;
            }
            if self.finishes {
                self.finishes = false;
                return Proposal::Done(Reached);
            }
            Proposal::Steer(Steer {
                heading: Heading::from_deg(self.heading_deg),
                speed_mps: 1.0,
            })
        }
    }

    #[test]
    fn subsumption_lets_the_highest_layer_with_a_proposal_inhibit_the_rest() {
        // Layer 0 steers once the log holds a detection; layer 1 finishes once (its Done reaches
        // on_done, which logs a lost point) and then steers; layer 2 always steers.
        fn detected(m: &[PlannerEvent]) -> bool {
            m.iter()
                .any(|e| matches!(e, PlannerEvent::Detection { .. }))
        }
        fn always(_: &[PlannerEvent]) -> bool {
            true
        }
        fn lost(m: &[PlannerEvent]) -> bool {
            !m.iter()
                .any(|e| matches!(e, PlannerEvent::LostPoint { .. }))
        }
        let layers: Vec<Box<dyn Behaviour<Vec<PlannerEvent>, Reached>>> = vec![
            Box::new(Layer {
                kind: BehaviourKind::TrackIn,
                heading_deg: 10.0,
                on: detected,
                finishes: false,
            }),
            Box::new(Layer {
                kind: BehaviourKind::Reacquire,
                heading_deg: 20.0,
                on: lost,
                finishes: true,
            }),
            Box::new(Layer {
                kind: BehaviourKind::Find,
                heading_deg: 30.0,
                on: always,
                finishes: false,
            }),
        ];
        let mut s = Subsumption::new(layers, |m: &mut Vec<PlannerEvent>, Reached| {
            m.push(PlannerEvent::LostPoint {
                pos_m: Vec2::zeros(),
            });
        });
        let mut log: Vec<PlannerEvent> = Vec::new();
        // Layer 1 finishes (on_done logs a lost point, which turns it off): the layers are asked
        // again in the same decision and the lowest one steers.
        let steer = s.arbitrate(&percept(0.0, 0.0, 0.0), &mut log);
        assert_eq!(steer.map(|s| s.heading.deg().round()), Some(30.0));
        assert_eq!(s.active(), BehaviourKind::Find);
        // A detection switches the top layer on: it inhibits the one below.
        log.push(PlannerEvent::Detection {
            pos_m: Vec2::zeros(),
        });
        let steer = s.arbitrate(&percept(0.0, 0.0, 0.0), &mut log);
        assert_eq!(steer.map(|s| s.heading.deg().round()), Some(10.0));
        assert_eq!(s.active(), BehaviourKind::TrackIn);
        let kinds: Vec<BehaviourKind> = log.iter().filter_map(PlannerEvent::behaviour).collect();
        assert_eq!(kinds, [BehaviourKind::Find, BehaviourKind::TrackIn]);
    }
}
