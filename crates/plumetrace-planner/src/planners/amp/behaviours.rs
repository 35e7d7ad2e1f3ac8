//! The AMP's own behaviours: Find, Track-In, Track-Out and Reacquire. (Go-To, Transit and
//! Mapping are the shared [`GoTo`](crate::behaviour::GoTo) and [`Legs`](crate::behaviour::Legs).)

use super::{AmpDone, FindPattern, LhsUpdate, Memory, bowtie, find};
use crate::behaviour::{Behaviour, Percept, Proposal};
use plumetrace_core::{BehaviourKind, Heading, Vec2};
use plumetrace_guidance::{FollowLine, GoToPoint, ModeStatus, Steer};

/// Sweep across the flow, reflecting at the subregion's boundary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Find {
    pub(super) heading: Heading,
}

impl Behaviour<Memory, AmpDone> for Find {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::Find
    }

    fn propose(&mut self, p: &Percept, m: &mut Memory) -> Proposal<AmpDone> {
        let e = m.regions[m.region].edge_info(p.pos_m);
        if (!e.inside || e.distance_m < m.p.find_margin_m)
            && self.heading.unit().dot(&e.outward_normal) > 0.0
        {
            self.heading = match m.p.find_pattern {
                FindPattern::Billiard => find::reflect(
                    self.heading,
                    e.outward_normal,
                    m.flow.toward(),
                    m.p.find_offset_deg,
                ),
                FindPattern::Zigzag => find::zigzag(
                    self.heading,
                    e.outward_normal,
                    m.flow.toward(),
                    m.find_offset_deg(),
                ),
            };
        }
        Proposal::Steer(Steer {
            heading: self.heading,
            speed_mps: m.p.speed_mps,
        })
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
                speed_mps: m.p.speed_mps,
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
    n: usize,
    leg: usize,
    bowtie: bowtie::Bowtie,
    line: Option<FollowLine>,
    started_s: Option<f64>,
}

impl Reacquire {
    /// The first Bowtie around `point`.
    pub(super) fn new(m: &Memory, point: Vec2) -> Self {
        let (bowtie, line) = new_bowtie(m, point, 0);
        Reacquire {
            point,
            n: 0,
            leg: 0,
            bowtie,
            line,
            started_s: None,
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
        let started = *self.started_s.get_or_insert(p.t_s);
        // Given up after its time, or when the point itself was dropped (aged out, or set
        // under a flow that has since turned).
        let dropped = !m.lost.iter().any(|l| l.pos == self.point);
        if dropped || (m.p.reacquire_timeout_s > 0.0 && p.t_s - started > m.p.reacquire_timeout_s) {
            return Proposal::Done(AmpDone::Searched { point: self.point });
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
                                        m.p.speed_mps,
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
                                return Proposal::Done(AmpDone::Searched { point: self.point });
                            }
                            let (bowtie, line) = new_bowtie(m, self.point, n);
                            *self = Reacquire {
                                point: self.point,
                                n,
                                leg: 0,
                                bowtie,
                                line,
                                started_s: Some(started),
                            };
                        }
                    }
                }
            }
        }
    }
}
