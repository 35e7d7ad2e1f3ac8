//! The moth-inspired planner of Li and Zhang: behaviours in a subsumption architecture.
//!
//! Layers, from the highest priority (each inhibits those below it while it has something to
//! say):
//! 1. **Declare-Source**: every contact with the plume (a run of detections less than `lambda_s`
//!    apart) leaves one point, its most up-flow detection. The points are sorted along the mean
//!    of every flow measurement so far (the prior flow before the first), most up-flow first; the
//!    source is declared at the first of them when the first `declare_points` (M = 6) span less
//!    than `declare_spread_m` (epsilon = 5 m) along the flow and less than `declare_across_m`
//!    (10 m) across it, and the mission ends. Only the last
//!    `declare_window` contacts are sorted (0: all of them), so that a point left far up-flow by a
//!    navigation jump ages out instead of blocking the rule for ever.
//! 2. **Track-In** (eq. 5), while the last detection is at most `lambda_s` old: up-flow, offset by
//!    `track_in_offset_deg` in the *active* strategy (its sign flips at every new contact, a
//!    counter-turn across the plume), straight up-flow in the *passive* one.
//! 3. **Track-Out** (eq. 6), for `track_out_s` after that: up-flow offset by `track_out_offset_deg`
//!    (10 deg) towards the side the vehicle left the plume on (*active*), or alternately to either
//!    side at each loss (*passive*, a small cast).
//! 4. **Reacquire-Plume** (eq. 7), after Track-Out: subgoals on a cloverleaf around the last
//!    detection, four leaves of `leaf_m` (15 m) starting up-flow and turning clockwise, each flown
//!    out and back, `n_re` (3) times; then it gives way to Find.
//! 5. **Move-To-Field**: from a start outside the op-area, straight to the nearest point
//!    `find_margin_m` inside it; idle once there.
//! 6. **Find-Plume** (eq. 1-4): the flow direction plus `sign(eta)` times an offset, with eta the
//!    vehicle's offset across the flow from the op-area's centre line (positive on the left of the
//!    flow, looking down-flow, so that the clockwise offset brings the vehicle back); the offset is
//!    `find_up_offset_deg` (125 deg: across and up the flow) for `find_up_s`, then
//!    `find_down_offset_deg` (60 deg: across and down the flow) for `find_down_s`, in turn. The sign
//!    changes only once the vehicle is `find_swing_m` past the centre line (the pure sign makes
//!    the vehicle chatter along the line), within `find_margin_m` of the up-flow or down-flow
//!    edge the vehicle takes the offset that leads away from it, and a search that resumes after
//!    tracing starts with an up-flow leg.
//!
//! Durations the paper leaves open, chosen for its 100 m area at 1.2-1.5 m/s: `find_up_s` = 40 s and
//! `find_down_s` = 20 s (an up leg covers about half the area's width and 28 m up-flow, a down leg
//! gives back 12 m), `track_out_s` = 8.5 s (as long as `lambda_s`).
//!
//! Every course passes the shared [`Autopilot`]; a reading above `threshold_v` is a detection.
//!
//! Of the keys shared with other planners ([`AutopilotKeys`]), the moth flies at 1.5 m/s (the top
//! of the paper's 1.0-1.5 m/s: its current is 1 m/s, so speed is what gains ground up-flow), turns
//! at up to 20 deg/s and averages the flow over 10 s.

use crate::FlowEstimate;
use crate::behaviour::{Arbiter, Behaviour, EventLog, Percept, Proposal, Subsumption};
use crate::planners::{BuildContext, PlannerParams};
use crate::shared_keys::AutopilotKeys;
use plumetrace_core::params::{Bounds, Choice, ParamError, Params};
use plumetrace_core::{
    BehaviourKind, Decision, DeclarationKind, Heading, PlanStatus, Planner, PlannerEvent, RuleDoc,
    SensorSnapshot, Telemetry, Vec2, bearing_between,
};
use plumetrace_guidance::{Autopilot, OpArea, Steer};
use serde::{Deserialize, Serialize};

/// Which of Li, Farrell and Cardé's strategies Maintain-Plume flies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MothStrategy {
    /// Track-In straight up-flow; Track-Out casts to either side in turn.
    Passive,
    /// Track-In counter-turns across the plume; Track-Out turns back towards the side the
    /// vehicle left the plume on.
    Active,
}

impl Choice for MothStrategy {
    const ALL: &'static [Self] = &[MothStrategy::Passive, MothStrategy::Active];
}

plumetrace_core::params! {
    /// Parameters of the moth-inspired planner. Defaults: Table II of the paper where it gives
    /// them (lambda, threshold, leaf, N_re, M, epsilon, offsets), otherwise documented choices.
    pub struct MothParams {
        include autopilot: AutopilotKeys = AutopilotKeys { speed_mps: 1.5, max_turn_rate_deg_s: 20.0, flow_average_s: 10.0, ..AutopilotKeys::default() };
        /// lambda: time after the last detection that ends Track-In.
        lambda_s: f64 = 8.5, "s", Bounds::positive(3600.0);
        /// Maintain-Plume strategy of Li, Farrell and Carde: passive (Track-In straight up-flow, Track-Out casts to either side in turn) or active (Track-In counter-turns across the plume, Track-Out turns back to the side the plume was lost on). Not `strategy`, which older `[planner]` tables use for the planner's kind.
        maintain_plume: MothStrategy = MothStrategy::Passive, "", Bounds::Any;
        /// Track-In offset from up-flow in the active strategy.
        track_in_offset_deg: f64 = 20.0, "deg", Bounds::closed(0.0, 80.0);
        /// Track-Out offset from up-flow.
        track_out_offset_deg: f64 = 10.0, "deg", Bounds::closed(0.0, 90.0);
        /// How long Track-Out lasts after Track-In.
        track_out_s: f64 = 8.5, "s", Bounds::non_negative(3600.0);
        /// Cloverleaf leaf length.
        leaf_m: f64 = 15.0, "m", Bounds::positive(1000.0);
        /// N_re: cloverleaf repetitions.
        n_re: u32 = 3, "", Bounds::whole(1, 50);
        /// Arrival radius of the cloverleaf subgoals and Move-To-Field (a subgoal passed along its leg counts as reached too).
        r_m: f64 = 3.0, "m", Bounds::positive(100.0);
        /// A cloverleaf subgoal not reached in this time is given up (a current or the op-area cage can keep the vehicle from it).
        subgoal_timeout_s: f64 = 60.0, "s", Bounds::positive(36_000.0);
        /// M: contact points the declaration looks at.
        declare_points: u32 = 6, "", Bounds::whole(2, 100);
        /// epsilon: the largest span along the flow of the M most up-flow points that declares.
        declare_spread_m: f64 = 5.0, "m", Bounds::positive(1000.0);
        /// The largest span across the flow of those points that declares (the paper sets none; it keeps points on both sides of a meandering plume apart).
        declare_across_m: f64 = 10.0, "m", Bounds::positive(1000.0);
        /// How many of the most recent contacts the rule sorts (0: all; otherwise at least M).
        declare_window: u32 = 0, "", Bounds::whole(0, 100_000);
        /// Find-Plume offset from the flow direction while searching up-flow.
        find_up_offset_deg: f64 = 125.0, "deg", Bounds::closed(90.0, 180.0);
        /// Find-Plume offset from the flow direction while searching down-flow.
        find_down_offset_deg: f64 = 60.0, "deg", Bounds::closed(0.0, 90.0);
        /// T_up: duration of an up-flow search leg.
        find_up_s: f64 = 40.0, "s", Bounds::positive(36_000.0);
        /// T_down: duration of a down-flow search leg.
        find_down_s: f64 = 20.0, "s", Bounds::non_negative(36_000.0);
        /// How far past the centre line the vehicle goes before Find-Plume turns back.
        find_swing_m: f64 = 20.0, "m", Bounds::non_negative(10_000.0);
        /// Distance from the op-area's edges that Find-Plume and Move-To-Field keep.
        find_margin_m: f64 = 8.0, "m", Bounds::non_negative(1000.0);
    }
}

impl PlannerParams for MothParams {
    const KIND: &'static str = "moth";
    const SUMMARY: &'static str = "Moth-inspired planner (Li and Zhang): Find-Plume, Track-In, Track-Out, cloverleaf Reacquire, declaration from recent contacts, in a subsumption architecture";
    const THRESHOLD_KEY: Option<&'static str> = Some("threshold_v");
    const BEHAVIOURS: &'static [BehaviourKind] = &[
        BehaviourKind::GoTo,
        BehaviourKind::Find,
        BehaviourKind::TrackIn,
        BehaviourKind::TrackOut,
        BehaviourKind::Reacquire,
        BehaviourKind::Done,
    ];
    const RULES: &'static [RuleDoc] = &[RuleDoc {
        rule: ALONG_FLOW,
        doc: "the declare_points most up-flow of the recent contacts lie within declare_spread_m along the flow and declare_across_m across it: the most up-flow one",
    }];

    fn validate(&self, prefix: &str) -> Result<(), ParamError> {
        self.check_bounds(prefix)?;
        if self.declare_window != 0 && self.declare_window < self.declare_points {
            return Err(ParamError::at(
                prefix,
                "declare_window",
                format!(
                    "must be 0 (all contacts) or at least declare_points ({}), not {}",
                    self.declare_points, self.declare_window
                ),
            ));
        }
        Ok(())
    }

    fn detection_threshold_v(&self) -> Option<f64> {
        Some(self.autopilot.threshold_v)
    }

    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Planner>, ParamError> {
        Ok(Box::new(Moth::new(
            self.clone(),
            ctx.geometry.op_area.clone(),
            ctx.geometry.prior_flow_toward(),
        )))
    }
}

/// The moth's rule in events: the M most up-flow recent contacts lie within epsilon of each other
/// along the flow (and within `declare_across_m` across it); written as the AMP's field rule,
/// the test it shares.
pub const ALONG_FLOW: DeclarationKind = DeclarationKind::new("along_flow");

/// Contacts kept for Declare-Source (one per `lambda_s` at most: 10,000 is over a day at the
/// default `lambda_s`).
const MAX_CONTACTS: usize = 10_000;

/// A contact with the plume: its most up-flow detection.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Contact {
    point: Vec2,
}

/// What the moth's behaviours share.
struct Memory {
    p: MothParams,
    area: OpArea,
    centroid: Vec2,
    flow: FlowEstimate,
    /// Sum and count of every flow measurement: their mean sorts the contact points.
    flow_sum: Vec2,
    flow_count: u64,
    prior_flow: Heading,
    last_detection: Option<(f64, Vec2)>,
    contacts: Vec<Contact>,
    /// +1: the vehicle left the plume on its left looking up-flow, -1 on its right.
    exit_side: f64,
    /// Sign of the active Track-In offset (flips at every new contact).
    counter_turn: f64,
    /// Side of the passive cast (flips at every loss).
    cast_side: f64,
    declared: Option<Vec2>,
    /// The last detection whose loss has been handled.
    loss_handled_for: Option<f64>,
    /// Where Reacquire searches instead of the last detection (the end of an obstacle detour),
    /// with the time of the detection it replaces.
    reacquire_at: Option<(f64, Vec2)>,
    events: Vec<PlannerEvent>,
}

impl EventLog for Memory {
    fn log(&mut self, e: PlannerEvent) {
        self.events.push(e);
    }
}

impl Memory {
    fn since_detection(&self, t: f64) -> Option<f64> {
        self.last_detection.map(|(tl, _)| t - tl)
    }

    fn upflow(&self) -> Heading {
        self.flow.upflow()
    }

    fn steer(&self, heading: Heading) -> Proposal<MothDone> {
        Proposal::Steer(Steer {
            heading,
            speed_mps: self.p.autopilot.speed_mps,
        })
    }

    /// Offset of `pos` across the flow from the op-area's centre line, positive on the left of
    /// the flow (looking down-flow).
    fn eta(&self, pos: Vec2) -> f64 {
        let left = self.flow.toward().turned_deg(-90.0).unit();
        (pos - self.centroid).dot(&left)
    }

    /// Up-flow unit vector of the mean of every flow measurement (the prior before the first).
    fn mean_upflow(&self) -> Vec2 {
        let sum = self.flow_sum;
        if self.flow_count == 0 || sum.norm() < 1e-9 {
            return self.prior_flow.reversed().unit();
        }
        -sum / sum.norm()
    }

    /// The most up-flow contact point of the last `declare_window` contacts.
    fn most_upflow_point(&self) -> Option<Vec2> {
        let w = self.p.declare_window as usize;
        let recent = match w {
            0 => &self.contacts[..],
            w => &self.contacts[self.contacts.len().saturating_sub(w)..],
        };
        let up = self.mean_upflow();
        recent
            .iter()
            .map(|c| c.point)
            .max_by(|a, b| a.dot(&up).total_cmp(&b.dot(&up)))
    }

    /// The declaration, if the M most up-flow contact points (of the last `declare_window`)
    /// agree along and across the flow.
    fn declaration(&self) -> Option<Vec2> {
        declaration(
            &self.contacts,
            self.mean_upflow(),
            self.p.declare_points as usize,
            self.p.declare_window as usize,
            self.p.declare_spread_m,
            self.p.declare_across_m,
        )
    }
}

/// Declare-Source's rule over `contacts` (oldest first): of the last `window` (0: all), sorted by
/// their coordinate along `upflow` (most up-flow first), the first `m` span less than `along_m`
/// along `upflow` and less than `across_m` across it; the declaration is at the first point.
fn declaration(
    contacts: &[Contact],
    upflow: Vec2,
    m: usize,
    window: usize,
    along_m: f64,
    across_m: f64,
) -> Option<Vec2> {
    let recent = match window {
        0 => contacts,
        w => &contacts[contacts.len().saturating_sub(w)..],
    };
    if m == 0 || recent.len() < m {
        return None;
    }
    let mut sorted: Vec<Vec2> = recent.iter().map(|c| c.point).collect();
    sorted.sort_by(|a, b| b.dot(&upflow).total_cmp(&a.dot(&upflow)));
    let span = |dir: Vec2| {
        let (lo, hi) = sorted[..m]
            .iter()
            .fold((f64::MAX, f64::MIN), |(lo, hi), q| {
                (lo.min(q.dot(&dir)), hi.max(q.dot(&dir)))
            });
        hi - lo
    };
    let across = Vec2::new(-upflow.y, upflow.x);
    (span(upflow) < along_m && span(across) < across_m).then_some(sorted[0])
}

/// Why a moth layer finished.
#[derive(Debug, Clone, Copy, PartialEq)]
enum MothDone {
    /// The declaration rule holds here.
    Declared(Vec2),
}

fn on_done(m: &mut Memory, d: MothDone) {
    match d {
        MothDone::Declared(at) => {
            m.declared = Some(at);
            m.events.push(PlannerEvent::Declared {
                pos_m: at,
                rule: ALONG_FLOW,
            });
        }
    }
}

struct Declare;

impl Behaviour<Memory, MothDone> for Declare {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::Done
    }

    fn propose(&mut self, _: &Percept, m: &mut Memory) -> Proposal<MothDone> {
        if m.declared.is_some() {
            return Proposal::Idle;
        }
        match m.declaration() {
            Some(at) => Proposal::Done(MothDone::Declared(at)),
            None => Proposal::Idle,
        }
    }
}

struct TrackIn;

impl Behaviour<Memory, MothDone> for TrackIn {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::TrackIn
    }

    fn propose(&mut self, p: &Percept, m: &mut Memory) -> Proposal<MothDone> {
        match m.since_detection(p.t_s) {
            Some(dt) if dt <= m.p.lambda_s && m.declared.is_none() => {
                let offset = match m.p.maintain_plume {
                    MothStrategy::Passive => 0.0,
                    MothStrategy::Active => m.counter_turn * m.p.track_in_offset_deg,
                };
                m.steer(m.upflow().turned_deg(offset))
            }
            _ => Proposal::Idle,
        }
    }
}

struct TrackOut;

impl Behaviour<Memory, MothDone> for TrackOut {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::TrackOut
    }

    fn propose(&mut self, p: &Percept, m: &mut Memory) -> Proposal<MothDone> {
        match m.since_detection(p.t_s) {
            Some(dt) if dt > m.p.lambda_s && dt <= m.p.lambda_s + m.p.track_out_s => {
                let side = match m.p.maintain_plume {
                    MothStrategy::Passive => m.cast_side,
                    // Back towards the side it left on: turning left (anticlockwise) when it left
                    // on its left.
                    MothStrategy::Active => -m.exit_side,
                };
                m.steer(m.upflow().turned_deg(side * m.p.track_out_offset_deg))
            }
            _ => Proposal::Idle,
        }
    }
}

/// The cloverleaf around one detection.
struct Reacquire {
    /// The detection it flies around, the subgoal index, and when that subgoal was set.
    around: Option<(Vec2, usize, f64)>,
}

impl Reacquire {
    /// Subgoal `k` of the cloverleaf: even ones out at the leaf tips (four leaves, clockwise
    /// from up-flow), odd ones back at the centre; a tip beyond `find_margin_m` inside the
    /// op-area is drawn back towards the centre until it is not.
    fn subgoal(m: &Memory, centre: Vec2, k: usize) -> Vec2 {
        let ok = |q: Vec2| {
            let e = m.area.edge_info(q);
            e.inside && e.distance_m >= m.p.find_margin_m
        };
        // A centre near or beyond the edge is first brought `find_margin_m` inside (a few
        // steps across the nearest edge, for concave corners).
        let mut centre = centre;
        for _ in 0..4 {
            if ok(centre) {
                break;
            }
            let e = m.area.edge_info(centre);
            let depth = if e.inside {
                m.p.find_margin_m - e.distance_m
            } else {
                e.distance_m + m.p.find_margin_m
            };
            centre -= e.outward_normal * (depth + 1e-6);
        }
        if k % 2 == 1 {
            return centre;
        }
        let leaf = (k / 2) % 4;
        let tip = centre + m.upflow().turned_deg(90.0 * leaf as f64).unit() * m.p.leaf_m;
        if ok(tip) || !ok(centre) {
            return tip;
        }
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..30 {
            let mid = 0.5 * (lo + hi);
            if ok(centre + (tip - centre) * mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        centre + (tip - centre) * lo
    }
}

impl Behaviour<Memory, MothDone> for Reacquire {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::Reacquire
    }

    fn propose(&mut self, p: &Percept, m: &mut Memory) -> Proposal<MothDone> {
        let Some((t_last, mut at)) = m.last_detection else {
            return Proposal::Idle;
        };
        if let Some((t, p)) = m.reacquire_at
            && t == t_last
        {
            at = p;
        }
        if p.t_s - t_last <= m.p.lambda_s + m.p.track_out_s {
            return Proposal::Idle;
        }
        let total = 8 * m.p.n_re as usize;
        let (centre, mut k, mut since) = match self.around {
            Some((c, k, since)) if c == at => (c, k, since),
            _ => (at, 0, p.t_s),
        };
        while k < total {
            let goal = Reacquire::subgoal(m, centre, k);
            let from = match k {
                0 => centre,
                _ => Reacquire::subgoal(m, centre, k - 1),
            };
            // Reached within r_m, or passed: beyond the goal along its leg (a vehicle that
            // cannot turn inside r_m would otherwise circle it, drifting with the flow).
            let passed = (goal - p.pos_m).dot(&(goal - from)) < 0.0;
            // A subgoal the current or the cage keeps the vehicle from is given up.
            let late = p.t_s - since > m.p.subgoal_timeout_s;
            if (goal - p.pos_m).norm() > m.p.r_m && !passed && !late {
                self.around = Some((centre, k, since));
                let heading = bearing_between(p.pos_m, goal).unwrap_or(p.heading);
                return m.steer(heading);
            }
            k += 1;
            since = p.t_s;
        }
        self.around = Some((centre, total, since));
        Proposal::Idle
    }
}

struct MoveToField {
    arrived: bool,
}

impl Behaviour<Memory, MothDone> for MoveToField {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::GoTo
    }

    fn propose(&mut self, p: &Percept, m: &mut Memory) -> Proposal<MothDone> {
        if self.arrived {
            return Proposal::Idle;
        }
        let e = m.area.edge_info(p.pos_m);
        if e.inside && e.distance_m >= m.p.find_margin_m.min(1.0) {
            self.arrived = true;
            return Proposal::Idle;
        }
        // The nearest point a margin inside: across the nearest edge.
        let goal = if e.inside {
            p.pos_m - e.outward_normal * (m.p.find_margin_m - e.distance_m)
        } else {
            p.pos_m - e.outward_normal * (e.distance_m + m.p.find_margin_m)
        };
        m.steer(bearing_between(p.pos_m, goal).unwrap_or(p.heading))
    }
}

struct Find {
    /// +1 or -1: the side the offset is taken to (sign of eta, with hysteresis).
    sign: f64,
    /// Start of the current up/down cycle, s.
    cycle_start_s: Option<f64>,
    /// Time of its last proposal: a search resumed after tracing starts with an up-flow leg.
    last_s: Option<f64>,
}

impl Behaviour<Memory, MothDone> for Find {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::Find
    }

    fn propose(&mut self, p: &Percept, m: &mut Memory) -> Proposal<MothDone> {
        let eta = m.eta(p.pos_m);
        if eta > m.p.find_swing_m {
            self.sign = 1.0;
        } else if eta < -m.p.find_swing_m {
            self.sign = -1.0;
        }
        if self.last_s.is_none_or(|l| p.t_s - l > 1.0) {
            self.cycle_start_s = Some(p.t_s);
        }
        self.last_s = Some(p.t_s);
        let start = *self.cycle_start_s.get_or_insert(p.t_s);
        let period = m.p.find_up_s + m.p.find_down_s;
        let phase = (p.t_s - start).rem_euclid(period.max(1e-9));
        let mut up = phase < m.p.find_up_s;
        // Near the up-flow or down-flow edge, the offset that leads away from it.
        let e = m.area.edge_info(p.pos_m);
        if e.distance_m < m.p.find_margin_m || !e.inside {
            let toward = m.flow.toward().unit();
            let along = e.outward_normal.dot(&toward);
            if along < -0.5 {
                up = false;
            } else if along > 0.5 {
                up = true;
            }
        }
        let offset = if up {
            m.p.find_up_offset_deg
        } else {
            m.p.find_down_offset_deg
        };
        m.steer(m.flow.toward().turned_deg(self.sign * offset))
    }
}

/// The moth-inspired planner for one vehicle.
pub struct Moth {
    m: Memory,
    arbiter: Subsumption<Memory, MothDone>,
    autopilot: Autopilot,
    last_steer: Steer,
    reported: Option<Vec2>,
}

impl Moth {
    /// A planner searching `area`; `prior_flow` is the flow direction assumed until the first
    /// flow measurement.
    pub fn new(p: MothParams, area: OpArea, prior_flow: Heading) -> Self {
        let autopilot = Autopilot::new(p.autopilot.autopilot(area.clone()));
        let centroid =
            area.vertices().iter().fold(Vec2::zeros(), |a, v| a + v) / area.vertices().len() as f64;
        let layers: Vec<Box<dyn Behaviour<Memory, MothDone>>> = vec![
            Box::new(Declare),
            Box::new(TrackIn),
            Box::new(TrackOut),
            Box::new(Reacquire { around: None }),
            Box::new(MoveToField { arrived: false }),
            Box::new(Find {
                sign: 1.0,
                cycle_start_s: None,
                last_s: None,
            }),
        ];
        Moth {
            last_steer: Steer {
                heading: prior_flow.reversed(),
                speed_mps: p.autopilot.speed_mps,
            },
            m: Memory {
                flow: p.autopilot.flow_estimate(prior_flow),
                flow_sum: Vec2::zeros(),
                flow_count: 0,
                prior_flow,
                p,
                area,
                centroid,
                last_detection: None,
                contacts: Vec::new(),
                exit_side: 1.0,
                counter_turn: 1.0,
                cast_side: 1.0,
                declared: None,
                loss_handled_for: None,
                reacquire_at: None,
                events: Vec::new(),
            },
            arbiter: Subsumption::new(layers, on_done),
            autopilot,
            reported: None,
        }
    }

    /// The behaviour in control.
    pub fn behaviour(&self) -> BehaviourKind {
        self.arbiter.active()
    }

    /// The course the behaviours asked for at the last decision (before flow compensation and
    /// the rate filter).
    pub fn last_course(&self) -> Heading {
        self.last_steer.heading
    }

    /// The contact points so far (each contact's most up-flow detection), oldest first.
    pub fn contact_points(&self) -> Vec<Vec2> {
        self.m.contacts.iter().map(|c| c.point).collect()
    }

    /// The declared source, if any.
    pub fn declared(&self) -> Option<Vec2> {
        self.m.declared
    }

    /// Updates contacts and sides from this decision's detection.
    fn sense(&mut self, t: f64, pos: Vec2, detected: bool) {
        let m = &mut self.m;
        let lambda = m.p.lambda_s;
        let up = m.mean_upflow();
        if detected {
            let new_contact = m.last_detection.is_none_or(|(tl, _)| t - tl > lambda);
            if new_contact {
                m.events.push(PlannerEvent::Detection { pos_m: pos });
                m.contacts.push(Contact { point: pos });
                m.counter_turn = -m.counter_turn;
                if m.contacts.len() > MAX_CONTACTS {
                    m.contacts.drain(..m.contacts.len() - MAX_CONTACTS);
                }
            } else if let Some(c) = m.contacts.last_mut()
                && pos.dot(&up) > c.point.dot(&up)
            {
                c.point = pos;
            }
            m.last_detection = Some((t, pos));
        } else if let Some((tl, at)) = m.last_detection
            && t - tl > lambda
            && m.last_detection_side_pending(t, tl)
        {
            // Contact lost: which side did the vehicle leave on, looking up-flow?
            let left = m.upflow().turned_deg(-90.0).unit();
            m.exit_side = if (pos - at).dot(&left) >= 0.0 {
                1.0
            } else {
                -1.0
            };
            m.cast_side = -m.cast_side;
            m.events.push(PlannerEvent::LostPoint { pos_m: at });
        }
    }
}

impl Memory {
    /// True at the first decision after a contact was lost (the loss is handled once).
    fn last_detection_side_pending(&mut self, t: f64, t_last: f64) -> bool {
        let pending = self.loss_handled_for != Some(t_last);
        if pending {
            self.loss_handled_for = Some(t_last);
        }
        pending && t - t_last > self.p.lambda_s
    }
}

impl Planner for Moth {
    /// After an obstacle detour that interrupted Maintain-Plume, Reacquire (when the plume is
    /// lost) searches around the point the detour ended at rather than the last detection, now
    /// far behind. A detour that interrupted a search (Reacquire, Find) leaves it as it was: the
    /// cloverleaf keeps its centre.
    fn detour_ended(&mut self, pos_m: Vec2) {
        let tracing = matches!(
            self.arbiter.active(),
            BehaviourKind::TrackIn | BehaviourKind::TrackOut
        );
        if let Some((t, _)) = self.m.last_detection
            && tracing
        {
            self.m.reacquire_at = Some((t, pos_m));
        }
    }

    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        let t = s.time_s;
        if let Some(f) = s.flow {
            self.m.flow.add(f.time_s, f.velocity_mps);
            if f.velocity_mps.x.is_finite() && f.velocity_mps.y.is_finite() {
                self.m.flow_sum += f.velocity_mps;
                self.m.flow_count += 1;
            }
        }
        let flow = self.m.flow.velocity_mps();
        let Some(pos) = s.nav.pos_m else {
            let command = self
                .autopilot
                .command(t, None, s.nav.heading, self.last_steer, flow)
                .unwrap_or_else(|a| a.command);
            return Decision::new(command, PlanStatus::Running);
        };
        let threshold = self.m.p.autopilot.threshold_v;
        let detected = s.chem.iter().any(|c| c.reading > threshold);
        self.sense(t, pos, detected);
        let percept = Percept {
            t_s: t,
            pos_m: pos,
            heading: s.nav.heading,
            detected,
        };
        let steer = self.arbiter.arbitrate(&percept, &mut self.m);
        let steer = steer.unwrap_or(self.last_steer);
        self.last_steer = steer;
        let mut telemetry = Vec::new();
        // The source estimate: the declaration, or else the most up-flow contact point; reported
        // when it first exists, at the declaration, and when it moves by a metre or more.
        let estimate = self.m.declared.or_else(|| self.m.most_upflow_point());
        if let Some(pos_m) = estimate {
            let moved = self.reported.is_none_or(|r| (r - pos_m).norm() >= 1.0);
            if moved || (self.m.declared.is_some() && self.reported != Some(pos_m)) {
                self.reported = Some(pos_m);
                telemetry.push(Telemetry::SourceEstimate { pos_m });
            }
        }
        let (command, status) =
            match self
                .autopilot
                .command(t, Some(pos), s.nav.heading, steer, flow)
            {
                Ok(c) if self.m.declared.is_some() => {
                    (self.autopilot.hold(c.heading), PlanStatus::Finished)
                }
                Ok(c) => (c, PlanStatus::Running),
                Err(abort) => {
                    self.m.log(PlannerEvent::CageAbort {
                        distance_outside_m: abort.distance_outside_m,
                    });
                    (abort.command, PlanStatus::Abort)
                }
            };
        Decision {
            command,
            outbox: Vec::new(),
            events: std::mem::take(&mut self.m.events),
            telemetry,
            status,
        }
    }
}
