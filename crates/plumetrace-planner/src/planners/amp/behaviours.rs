//! The AMP's own behaviours: Find, Track-In, Track-Out and Reacquire. (Go-To, Transit and
//! Mapping are the shared [`GoTo`](crate::behaviour::GoTo) and [`Legs`](crate::behaviour::Legs).)

use super::{AmpDone, Memory, bowtie, find};
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
            self.heading = find::reflect(
                self.heading,
                e.outward_normal,
                m.flow.toward(),
                m.p.find_offset_deg,
            );
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
            m.lhs = m.lhs_from_heading(p.heading);
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

/// `N_re` Bowties around one lost point: from `bowtie_offset_m` upflow of it down to it.
#[derive(Debug, Clone)]
pub(super) struct Reacquire {
    point: Vec2,
    n: usize,
    leg: usize,
    bowtie: bowtie::Bowtie,
    line: FollowLine,
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
        }
    }
}

fn new_bowtie(m: &Memory, point: Vec2, n: usize) -> (bowtie::Bowtie, FollowLine) {
    let up = m.flow.upflow();
    let n_re = (m.p.n_re as usize).max(1);
    let centres = bowtie::centres(point, up, m.p.bowtie_offset_m, n_re);
    let c = centres[n.min(centres.len() - 1)];
    let b = bowtie::Bowtie::new(c, up, m.lhs, m.p.bowtie_angle_deg, m.p.bowtie_half_width_m);
    let line = m.p.line(b.first.0, b.first.1);
    (b, line)
}

impl Behaviour<Memory, AmpDone> for Reacquire {
    fn kind(&self) -> BehaviourKind {
        BehaviourKind::Reacquire
    }

    fn propose(&mut self, p: &Percept, m: &mut Memory) -> Proposal<AmpDone> {
        // At most three legs per Bowtie and `N_re` Bowties: the loop ends.
        loop {
            match self.line.update(p.pose()) {
                ModeStatus::Running(s) => return Proposal::Steer(s),
                ModeStatus::Done(_) => {
                    self.leg += 1;
                    let b = self.bowtie;
                    match self.leg {
                        // The side of the Bowtie: from the end of the first line, downflow, to
                        // the start of the second.
                        1 => {
                            self.line = FollowLine::tracking(
                                b.first.1,
                                b.second.0,
                                m.p.speed_mps,
                                m.p.r_m,
                                m.p.k_deg_per_m,
                            )
                        }
                        2 => self.line = m.p.line(b.second.0, b.second.1),
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
                            };
                        }
                    }
                }
            }
        }
    }
}
