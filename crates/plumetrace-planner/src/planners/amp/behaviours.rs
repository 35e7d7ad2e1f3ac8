//! The AMP's own behaviours: Find, Track-In, Track-Out and Reacquire. (Go-To, Transit and
//! Mapping are the shared [`GoTo`](crate::behaviour::GoTo) and [`Legs`](crate::behaviour::Legs).)

use super::{AmpDone, FindPattern, LhsUpdate, Memory, bowtie, find};
use crate::behaviour::{Behaviour, Percept, Proposal};
use plumetrace_core::{BehaviourKind, Heading, Vec2};
use plumetrace_guidance::{FollowLine, GoToPoint, ModeStatus, Steer};

/// Sweep the subregion for the plume. With lanes: first (on arriving at the search start) along
/// the subregion's downflow edge, which every plume crosses on its way out, then on lanes across
/// the flow, up it and back down, each pass between the lanes of the ones before (entered again
/// after the plume was lost for good: lanes from where the vehicle is, up the flow). With the
/// billiard (the field description, also the fallback when no lane fits the subregion): reflect
/// at the boundary.
#[derive(Debug, Clone)]
pub(super) struct Find {
    pub(super) heading: Heading,
    lanes: Option<Lanes>,
    /// The pass laid out next (0: the downflow edge), and whether from the vehicle's position.
    next: Option<(usize, bool)>,
}

/// The pass being flown and the flow estimate it was laid out for. Each lane is reached with
/// a plain go-to (no heading constraint: a turn onto the lane near the edge would need room the
/// cage may not give) and then followed; a lane not done in twice its time plus five minutes is
/// left (a lane the vehicle cannot reach never holds the search).
#[derive(Debug, Clone)]
struct Lanes {
    lanes: Vec<(Vec2, Vec2)>,
    k: usize,
    along: Option<FollowLine>,
    lane_started_s: Option<f64>,
    pass: usize,
    flow: Heading,
}

impl Lanes {
    /// The steer on the lanes, `None` when the pass is done.
    fn steer(&mut self, p: &Percept, m: &Memory) -> Option<Steer> {
        let params = m.p.line_params();
        // Two lanes may end at one decision (a fix that moves the vehicle past one).
        while let Some(&(a, b)) = self.lanes.get(self.k) {
            let started = *self.lane_started_s.get_or_insert(p.t_s);
            let budget =
                2.0 * ((a - p.pos_m).norm() + (b - a).norm()) / params.speed_mps.max(0.1) + 300.0;
            let status = if p.t_s - started > budget {
                None
            } else if let Some(line) = self.along.as_mut() {
                match line.update(p.pose()) {
                    ModeStatus::Running(s) => Some(s),
                    ModeStatus::Done(_) => None,
                }
            } else {
                let to_start = GoToPoint {
                    target_m: a,
                    speed_mps: params.speed_mps,
                    radius_m: params.radius_m,
                };
                match to_start.update(p.pos_m) {
                    ModeStatus::Running(s) => return Some(s),
                    ModeStatus::Done(_) => {
                        self.along = Some(FollowLine::tracking(
                            a,
                            b,
                            params.speed_mps,
                            params.radius_m,
                            params.gain_deg_per_m,
                        ));
                        continue;
                    }
                }
            };
            match status {
                Some(s) => return Some(s),
                None => {
                    self.k += 1;
                    self.along = None;
                    self.lane_started_s = None;
                }
            }
        }
        None
    }
}

/// A flow estimate this far from the one the lanes were laid out for lays them out again, deg.
const LANES_REPLAN_DEG: f64 = 30.0;

impl Find {
    /// Find from heading `heading` (the billiard's); `first`: the subregion's search starts.
    pub(super) fn new(heading: Heading, first: bool) -> Self {
        Find {
            heading,
            lanes: None,
            next: Some(if first { (0, false) } else { (1, true) }),
        }
    }

    /// Lays out pass `pass` for a vehicle at `pos`: 0 the downflow edge, then lanes (odd passes
    /// up the flow, even ones down; `from_here`: from about the vehicle's position on). When
    /// nothing of it is left, the next pass; `None` when no lane fits the subregion.
    fn lay_out(m: &Memory, pos: Vec2, pass: usize, from_here: bool) -> Option<Lanes> {
        let flow = m.flow.toward();
        let region = &m.regions[m.region];
        // The cage may hold the vehicle up to max_cage_inset_m inside the edge; lane ends within
        // R of there are still reached.
        let margin = m.p.find_margin_m.max(m.p.max_cage_inset_m - 0.5 * m.p.r_m);
        let spacing = m.p.find_spacing_m;
        [pass, pass + 1].into_iter().find_map(|pass| {
            let lanes = if pass == 0 {
                find::downflow_edge(region, flow, margin, 20.0, pos)
            } else {
                let all = find::lanes(region, flow, spacing, pass - 1, margin, 2.0 * m.p.r_m);
                find::order_lanes(&all, pos, flow, spacing, pass % 2 == 1, from_here)
            };
            (!lanes.is_empty()).then_some(Lanes {
                lanes,
                k: 0,
                along: None,
                lane_started_s: None,
                pass,
                flow,
            })
        })
    }

    fn billiard(&mut self, p: &Percept, m: &Memory) -> Proposal<AmpDone> {
        let e = m.regions[m.region].edge_info(p.pos_m);
        if (!e.inside || e.distance_m < m.p.find_margin_m)
            && self.heading.unit().dot(&e.outward_normal) > 0.0
        {
            self.heading = find::reflect(
                self.heading,
                e.outward_normal,
                m.flow.toward(),
                m.p.find_offset_deg,
            );
        }
        Proposal::Steer(Steer {
            heading: self.heading,
            speed_mps: m.p.autopilot.speed_mps,
        })
    }
}

impl Behaviour<Memory, AmpDone> for Find {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::Find
    }

    fn propose(&mut self, p: &Percept, m: &mut Memory) -> Proposal<AmpDone> {
        if m.p.find_pattern == FindPattern::Billiard {
            return self.billiard(p, m);
        }
        // A flow estimate that has turned lays the pass out again from here.
        if let Some(l) = &self.lanes
            && l.flow.diff_deg(m.flow.toward()).abs() > LANES_REPLAN_DEG
        {
            self.next = Some((l.pass, true));
            self.lanes = None;
        }
        // A pass that ends gives way to the next (two at most per decision: a pass may end at
        // its first step when a fix has moved the vehicle past it). No lane fits: the billiard.
        for _ in 0..2 {
            if let Some((pass, from_here)) = self.next.take() {
                self.lanes = Find::lay_out(m, p.pos_m, pass, from_here);
            }
            let Some(lanes) = self.lanes.as_mut() else {
                break;
            };
            match lanes.steer(p, m) {
                Some(s) => {
                    self.heading = s.heading;
                    return Proposal::Steer(s);
                }
                None => {
                    self.next = Some((lanes.pass + 1, false));
                    self.lanes = None;
                }
            }
        }
        self.billiard(p, m)
    }
}

/// Counter-turn up the plume: `upflow + LHS beta`, LHS updated from the heading at every
/// detection (Table 1); lost `lambda` after the last detection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct TrackIn {
    pub(super) heading: Heading,
}

impl Behaviour<Memory, AmpDone> for TrackIn {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::TrackIn
    }

    fn propose(&mut self, p: &Percept, m: &mut Memory) -> Proposal<AmpDone> {
        let steer = |heading| {
            Proposal::Steer(Steer {
                heading,
                speed_mps: m.p.autopilot.speed_mps,
            })
        };
        if p.detected {
            // Table 1: command with the current LHS, then update LHS from the heading.
            self.heading = m.flow.upflow().turned_deg(m.lhs * m.p.beta_deg);
            // Heading more than 90 deg off upflow (turning round from downflow), the side is
            // kept so that the turn completes: updated from the heading, the side flips as the
            // heading crosses the flow direction and the rate filter's short turns cancel out,
            // holding the vehicle on the downflow heading.
            let heading_upflow = p.heading.diff_deg(m.flow.upflow()).abs() < 90.0;
            if m.p.track_in_lhs == LhsUpdate::EveryDetection || heading_upflow {
                m.lhs = m.lhs_from_heading(p.heading);
            }
            m.last_detection = Some((p.t_s, p.pos_m));
            if let Some(at) = m.upflow_edge(p.pos_m) {
                return Proposal::Done(AmpDone::AtEdge { at });
            }
            return steer(self.heading);
        }
        match m.last_detection {
            Some((t_last, at)) if p.t_s - t_last > m.p.lambda_s => {
                Proposal::Done(AmpDone::Lost { at })
            }
            _ => steer(self.heading),
        }
    }
}

/// Go to the point `L_u` upflow and `L_c` across the flow from the most upflow lost point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct TrackOut {
    pub(super) goal: GoToPoint,
}

impl Behaviour<Memory, AmpDone> for TrackOut {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::TrackOut
    }

    fn propose(&mut self, p: &Percept, m: &mut Memory) -> Proposal<AmpDone> {
        match self.goal.update(p.pos_m) {
            ModeStatus::Running(s) => match m.upflow_edge(p.pos_m) {
                Some(at) => Proposal::Done(AmpDone::AtEdge { at }),
                None => Proposal::Steer(s),
            },
            ModeStatus::Done(_) => Proposal::Done(AmpDone::Reached),
        }
    }
}

/// `N_re` Bowties around one lost point: from `bowtie_offset_m` upflow of it down to it. With
/// `clip_patterns` each line is flown only where it lies inside the op-area (a line with no such
/// part is skipped), and after `reacquire_timeout_s` the point is given up.
#[derive(Debug, Clone)]
pub(super) struct Reacquire {
    point: Vec2,
    /// The lost point's id (its position moves with `fix_smoothing`; each Bowtie is centred
    /// where the point is when the Bowtie begins).
    id: u64,
    n: usize,
    leg: usize,
    bowtie: bowtie::Bowtie,
    line: Option<FollowLine>,
}

impl Reacquire {
    /// The first Bowtie around `point`.
    pub(super) fn new(m: &Memory, point: Vec2, id: u64) -> Self {
        let (bowtie, line) = new_bowtie(m, point, 0);
        Reacquire {
            point,
            id,
            n: 0,
            leg: 0,
            bowtie,
            line,
        }
    }
}

fn new_bowtie(m: &Memory, point: Vec2, n: usize) -> (bowtie::Bowtie, Option<FollowLine>) {
    let up = m.flow.upflow();
    let n_re = (m.p.n_re as usize).max(1);
    let centres = bowtie::centres(point, up, m.p.bowtie_offset_m, n_re);
    let c = centres[n.min(centres.len() - 1)];
    let b = bowtie::Bowtie::new(c, up, m.lhs, m.p.bowtie_angle_deg, m.p.bowtie_half_width_m);
    let line = m
        .pattern_line(b.first.0, b.first.1)
        .map(|(s, e)| m.p.line(s, e));
    (b, line)
}

impl Behaviour<Memory, AmpDone> for Reacquire {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::Reacquire
    }

    fn propose(&mut self, p: &Percept, m: &mut Memory) -> Proposal<AmpDone> {
        // Given up when Reacquire (around this point and those before it since the last
        // detection) has taken its time, or when the point itself was dropped (aged out, or set
        // under a flow that has since turned).
        m.reacquire_since.get_or_insert(p.t_s);
        let dropped = !m.lost.iter().any(|l| l.id == self.id);
        if dropped || m.reacquire_timed_out(p.t_s) {
            return Proposal::Done(AmpDone::Searched { id: self.id });
        }
        // At most three legs per Bowtie and `N_re` Bowties: the loop ends.
        loop {
            let status = match self.line.as_mut() {
                Some(line) => line.update(p.pose()),
                // A leg with no part inside the op-area is skipped.
                None => ModeStatus::Done(plumetrace_guidance::DoneReason::Arrived),
            };
            match status {
                ModeStatus::Running(s) => return Proposal::Steer(s),
                ModeStatus::Done(_) => {
                    self.leg += 1;
                    let b = self.bowtie;
                    match self.leg {
                        // The side of the Bowtie: from the end of the first line, downflow, to
                        // the start of the second (both clipped like the lines).
                        1 => {
                            let second = m.pattern_line(b.second.0, b.second.1);
                            self.line = m.pattern_line(b.first.0, b.first.1).zip(second).map(
                                |((_, first_end), (second_start, _))| {
                                    FollowLine::tracking(
                                        first_end,
                                        second_start,
                                        m.p.autopilot.speed_mps,
                                        m.p.r_m,
                                        m.p.k_deg_per_m,
                                    )
                                },
                            );
                        }
                        2 => {
                            self.line = m
                                .pattern_line(b.second.0, b.second.1)
                                .map(|(s, e)| m.p.line(s, e));
                        }
                        _ => {
                            let n = self.n + 1;
                            if n >= (m.p.n_re as usize).max(1) {
                                return Proposal::Done(AmpDone::Searched { id: self.id });
                            }
                            // Around where the point is now (a fix may have moved it).
                            let point = m
                                .lost
                                .iter()
                                .find(|l| l.id == self.id)
                                .map_or(self.point, |l| l.pos);
                            let (bowtie, line) = new_bowtie(m, point, n);
                            *self = Reacquire {
                                point,
                                id: self.id,
                                n,
                                leg: 0,
                                bowtie,
                                line,
                            };
                        }
                    }
                }
            }
        }
    }
}

/// The confirming Track-Out before a declaration: go-tos through the legs' ends upflow of the
/// point to declare (`declaration_confirm_m`, zigzagging `declaration_confirm_width_m` across
/// the flow); the switching logic watches its contacts.
#[derive(Debug, Clone)]
pub(super) struct ConfirmLeg {
    goals: Vec<GoToPoint>,
    k: usize,
}

impl ConfirmLeg {
    /// The legs through `goals`, in order.
    pub(super) fn new(goals: Vec<GoToPoint>) -> Self {
        ConfirmLeg { goals, k: 0 }
    }
}

impl Behaviour<Memory, AmpDone> for ConfirmLeg {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::TrackOut
    }

    fn propose(&mut self, p: &Percept, m: &mut Memory) -> Proposal<AmpDone> {
        if let Some(at) = m.upflow_edge(p.pos_m) {
            return Proposal::Done(AmpDone::AtEdge { at });
        }
        while let Some(goal) = self.goals.get(self.k) {
            match goal.update(p.pos_m) {
                ModeStatus::Running(s) => return Proposal::Steer(s),
                ModeStatus::Done(_) => self.k += 1,
            }
        }
        Proposal::Done(AmpDone::Reached)
    }
}
