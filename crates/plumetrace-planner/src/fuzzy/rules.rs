//! The rule base: the ten rules of seed 001 §II.C and the rules added so that every input fires
//! some rule, as one plain table ([`RULES`]).
//!
//! # Signs
//!
//! `head_ang` is positive when the target is clockwise of the heading (to the right) and `head_c`
//! is positive for a clockwise turn (to the right). The paper's `neg`/`pos` are mapped to these
//! one to one, for both variables, in every rule; each rule was then checked for geometric sense:
//!
//! - Steer-Target 1-3: turn towards the target (neg -> neg, pos -> pos): sense in any convention.
//! - Avoid-Obstacle 1 (left med, front and right near -> `neg`) turns anticlockwise, towards the
//!   freer left side, and 2 mirrors it: sense as written. Avoid-Obstacle 3 (a corridor) holds
//!   course.
//! - Follow-Edge 1 (obstacle near on the right, target to the left -> hold course, slow) and 2
//!   (its mirror) hold course beside the obstacle: taken as written.
//! - **Follow-Edge 3 and 4 are interpreted.** As printed, rule 3 (left far, front near, right near,
//!   target to the left) concludes `head_c is pos`, a clockwise turn into the near front-right
//!   obstacle and away from the target; rule 4 mirrors it. Both are used with the turn reversed
//!   (rule 3 turns anticlockwise, towards the free side and the target; rule 4 clockwise). The
//!   paper's Follow-Edge rules come from its reference \[12\] and read consistently if their angles
//!   are anticlockwise-positive (as `atan2(y, x)` in its eq. 7), while its Avoid-Obstacle rules
//!   only make sense clockwise-positive; the one-to-one mapping keeps Avoid-Obstacle and
//!   Follow-Edge 1-2 as printed and reverses the two turns that would steer into an obstacle.
//!
//! # Completion
//!
//! With three terms per input there are 3 x 3 x 3 x 3 = 81 combinations of terms; the ten rules
//! cover 16 of them (Avoid-Obstacle's "any" covers three each). The 43 added rules cover the other
//! 65, so for every input the rule of each
//! combination of its non-zero terms fires with a strength above 0 (the input grades add up to 1,
//! so some term of every input is above 0). Each added rule carries its reason in
//! [`Rule::why`]. The principles:
//!
//! - front far: with an obstacle near on one side, hold course slowly whatever the target (follow
//!   the edge; Follow-Edge 1-2 say so for a target on the free side, and a target on the obstacle
//!   side lies behind it); with an obstacle at medium range on one side, steer to the target at
//!   medium speed when it is on the free side or on the obstacle's side (it may lie short of the
//!   obstacle: holding course there made the vehicle orbit targets within about 8 m of an
//!   obstacle in the random-field tests; if the turn brings the obstacle ahead the front rules take
//!   over), hold course when it is ahead;
//! - front med or near: turn towards the freer side (the side whose distance term is further);
//!   with both sides in the same term (far/far, med/med) turn towards the target's side, and with
//!   the target ahead (`head_ang` Z) fire *both* turns: the dead-ahead split, which the stateful
//!   [`crate::fuzzy::Avoider`] resolves by locking a side (the centroid of the two humps alone
//!   would steer straight at the obstacle);
//! - all three near: hold course slowly (a gap or corridor; a dead end is left by the
//!   [`crate::fuzzy::Avoider`]'s escape turn).

use std::fmt;

/// A term of a distance input (`left_obs`, `front_obs`, `right_obs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dist {
    /// Near (left shoulder).
    Near,
    /// Medium (triangle).
    Med,
    /// Far (right shoulder).
    Far,
}

/// A term of `head_ang`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Ang {
    /// The target is to the left (anticlockwise), around -50 deg and beyond.
    Neg,
    /// The target is ahead.
    Z,
    /// The target is to the right (clockwise), around +50 deg and beyond.
    Pos,
}

/// A term of `velocity_c`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Speed {
    /// 0.25 m/s.
    Slow,
    /// 1.2 m/s.
    Med,
    /// 2 m/s.
    Fast,
}

/// A term of `head_c`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Turn {
    /// Turn anticlockwise (left), -10 deg.
    Neg,
    /// Hold course.
    Z,
    /// Turn clockwise (right), +10 deg.
    Pos,
}

impl Dist {
    /// Index of the term in its variable (near 0, med 1, far 2).
    pub fn index(self) -> usize {
        self as usize
    }
}

impl Ang {
    /// Index of the term in its variable (neg 0, Z 1, pos 2).
    pub fn index(self) -> usize {
        self as usize
    }
}

impl Speed {
    /// Index of the term in its variable (slow 0, med 1, fast 2).
    pub fn index(self) -> usize {
        self as usize
    }
}

impl Turn {
    /// Index of the term in its variable (neg 0, Z 1, pos 2).
    pub fn index(self) -> usize {
        self as usize
    }
}

/// The fuzzy behaviour a rule belongs to (seed 001 §II.C).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Behaviour {
    /// Pass obstacles by following their bounds.
    FollowEdge,
    /// Turn away from close obstacles.
    AvoidObstacle,
    /// Head for the target when the way is clear.
    SteerTarget,
}

/// Where a rule comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Origin {
    /// The paper's rule of that number within its behaviour, as printed.
    Paper(u8),
    /// The paper's rule of that number with its `head_c` sign interpreted (see the module docs).
    PaperInterpreted(u8),
    /// Added here so that every input fires a rule.
    Added,
}

/// One Mamdani rule: `if left and front and right and head_ang then head_c and velocity_c`. An
/// antecedent of `None` is the paper's "any": that input is left out of the conjunction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rule {
    /// The behaviour it belongs to.
    pub behaviour: Behaviour,
    /// Paper or added.
    pub origin: Origin,
    /// `left_obs` term.
    pub left: Option<Dist>,
    /// `front_obs` term.
    pub front: Option<Dist>,
    /// `right_obs` term.
    pub right: Option<Dist>,
    /// `head_ang` term.
    pub head_ang: Option<Ang>,
    /// `head_c` conclusion.
    pub head_c: Turn,
    /// `velocity_c` conclusion.
    pub velocity_c: Speed,
    /// Why the rule is there (for added and interpreted rules).
    pub why: &'static str,
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fn d(t: Option<Dist>) -> &'static str {
            match t {
                None => "any",
                Some(Dist::Near) => "near",
                Some(Dist::Med) => "med",
                Some(Dist::Far) => "far",
            }
        }
        let a = match self.head_ang {
            None => "any",
            Some(Ang::Neg) => "neg",
            Some(Ang::Z) => "Z",
            Some(Ang::Pos) => "pos",
        };
        let t = match self.head_c {
            Turn::Neg => "neg",
            Turn::Z => "Z",
            Turn::Pos => "pos",
        };
        let v = match self.velocity_c {
            Speed::Slow => "slow",
            Speed::Med => "med",
            Speed::Fast => "fast",
        };
        write!(
            f,
            "if left {} and front {} and right {} and head_ang {} then head_c {} and velocity_c {}",
            d(self.left),
            d(self.front),
            d(self.right),
            a,
            t,
            v
        )
    }
}

use Behaviour::{AvoidObstacle as AO, FollowEdge as FE, SteerTarget as ST};
use Origin::{Added, Paper, PaperInterpreted};

const NEAR: Option<Dist> = Some(Dist::Near);
const MED: Option<Dist> = Some(Dist::Med);
const FAR: Option<Dist> = Some(Dist::Far);
const NEG: Option<Ang> = Some(Ang::Neg);
const ZA: Option<Ang> = Some(Ang::Z);
const POS: Option<Ang> = Some(Ang::Pos);
const ANY: Option<Ang> = None;
const TN: Turn = Turn::Neg;
const TZ: Turn = Turn::Z;
const TP: Turn = Turn::Pos;
const SLOW: Speed = Speed::Slow;
const SMED: Speed = Speed::Med;
const FAST: Speed = Speed::Fast;

/// One row of [`RULES`]: `[left, front, right]`, `head_ang`, `head_c`, `velocity_c`.
#[allow(clippy::too_many_arguments)]
const fn rule(
    behaviour: Behaviour,
    origin: Origin,
    obs: [Option<Dist>; 3],
    head_ang: Option<Ang>,
    head_c: Turn,
    velocity_c: Speed,
    why: &'static str,
) -> Rule {
    Rule {
        behaviour,
        origin,
        left: obs[0],
        front: obs[1],
        right: obs[2],
        head_ang,
        head_c,
        velocity_c,
        why,
    }
}

const HOLD_EDGE: &str = "follow the edge: an obstacle near on one side, front clear: hold course slowly whatever the target";
const STEER_FREE: &str =
    "front clear, obstacle at medium range on the other side: steer to the target on the free side";
const STEER_MED: &str = "front clear, obstacle at medium range on the target's side: steer to the target (it may lie short of the obstacle; the front rules take over if the turn brings the obstacle ahead)";
const HOLD_MED: &str =
    "front clear, obstacle at medium range on one side, target ahead: hold course past it";
const SPLIT: &str = "obstacle ahead, both sides alike, target ahead: either turn (the dead-ahead split the Avoider resolves)";
const TO_TARGET_SIDE: &str = "obstacle ahead, both sides alike: turn towards the target's side";
const TO_FREER: &str = "obstacle ahead: turn towards the freer side";

/// The rule base: the paper's ten rules (three groups) and the added rules, one combination of
/// terms each (with "any" standing for all three terms of an input). Grouped by `front_obs`.
#[rustfmt::skip]
pub const RULES: [Rule; 53] = [
    // ---- the paper's ten rules (seed 001 §II.C) ----
    rule(FE, Paper(1), [FAR, FAR, NEAR], NEG, TZ, SLOW, "obstacle near on the right, target on the left: hold course beside it"),
    rule(FE, Paper(2), [NEAR, FAR, FAR], POS, TZ, SLOW, "obstacle near on the left, target on the right: hold course beside it"),
    rule(FE, PaperInterpreted(3), [FAR, NEAR, NEAR], NEG, TN, SLOW, "printed head_c pos would turn into the front-right obstacle: turn left, to the free side and the target"),
    rule(FE, PaperInterpreted(4), [NEAR, NEAR, FAR], POS, TP, SLOW, "printed head_c neg would turn into the front-left obstacle: turn right, to the free side and the target"),
    rule(AO, Paper(1), [MED, NEAR, NEAR], ANY, TN, SLOW, "front and right near, left med: turn left, to the freer side"),
    rule(AO, Paper(2), [NEAR, NEAR, MED], ANY, TP, SLOW, "front and left near, right med: turn right, to the freer side"),
    rule(AO, Paper(3), [NEAR, MED, NEAR], ANY, TZ, SMED, "a corridor: hold course"),
    rule(ST, Paper(1), [FAR, FAR, FAR], ZA, TZ, FAST, "clear, target ahead: straight on, fast"),
    rule(ST, Paper(2), [FAR, FAR, FAR], NEG, TN, FAST, "clear, target left: turn left, fast"),
    rule(ST, Paper(3), [FAR, FAR, FAR], POS, TP, FAST, "clear, target right: turn right, fast"),
    // ---- added: front far ----
    rule(FE, Added, [FAR, FAR, NEAR], ZA, TZ, SLOW, HOLD_EDGE),
    rule(FE, Added, [FAR, FAR, NEAR], POS, TZ, SLOW, HOLD_EDGE),
    rule(FE, Added, [NEAR, FAR, FAR], NEG, TZ, SLOW, HOLD_EDGE),
    rule(FE, Added, [NEAR, FAR, FAR], ZA, TZ, SLOW, HOLD_EDGE),
    rule(ST, Added, [FAR, FAR, MED], NEG, TN, SMED, STEER_FREE),
    rule(FE, Added, [FAR, FAR, MED], ZA, TZ, SMED, HOLD_MED),
    rule(ST, Added, [FAR, FAR, MED], POS, TP, SMED, STEER_MED),
    rule(ST, Added, [MED, FAR, FAR], POS, TP, SMED, STEER_FREE),
    rule(FE, Added, [MED, FAR, FAR], ZA, TZ, SMED, HOLD_MED),
    rule(ST, Added, [MED, FAR, FAR], NEG, TN, SMED, STEER_MED),
    rule(FE, Added, [MED, FAR, MED], ANY, TZ, SMED, "obstacles at medium range on both sides, front clear: hold course"),
    rule(FE, Added, [NEAR, FAR, NEAR], ANY, TZ, SMED, "a corridor open ahead: hold course"),
    rule(FE, Added, [NEAR, FAR, MED], ANY, TZ, SLOW, HOLD_EDGE),
    rule(FE, Added, [MED, FAR, NEAR], ANY, TZ, SLOW, HOLD_EDGE),
    // ---- added: front med ----
    rule(AO, Added, [FAR, MED, FAR], NEG, TN, SMED, TO_TARGET_SIDE),
    rule(AO, Added, [FAR, MED, FAR], POS, TP, SMED, TO_TARGET_SIDE),
    rule(AO, Added, [FAR, MED, FAR], ZA, TN, SMED, SPLIT),
    rule(AO, Added, [FAR, MED, FAR], ZA, TP, SMED, SPLIT),
    rule(AO, Added, [MED, MED, MED], NEG, TN, SMED, TO_TARGET_SIDE),
    rule(AO, Added, [MED, MED, MED], POS, TP, SMED, TO_TARGET_SIDE),
    rule(AO, Added, [MED, MED, MED], ZA, TN, SMED, SPLIT),
    rule(AO, Added, [MED, MED, MED], ZA, TP, SMED, SPLIT),
    rule(AO, Added, [FAR, MED, NEAR], ANY, TN, SLOW, TO_FREER),
    rule(AO, Added, [NEAR, MED, FAR], ANY, TP, SLOW, TO_FREER),
    rule(AO, Added, [FAR, MED, MED], ANY, TN, SMED, TO_FREER),
    rule(AO, Added, [MED, MED, FAR], ANY, TP, SMED, TO_FREER),
    rule(AO, Added, [MED, MED, NEAR], ANY, TN, SLOW, TO_FREER),
    rule(AO, Added, [NEAR, MED, MED], ANY, TP, SLOW, TO_FREER),
    // ---- added: front near ----
    rule(AO, Added, [FAR, NEAR, NEAR], ZA, TN, SLOW, TO_FREER),
    rule(AO, Added, [FAR, NEAR, NEAR], POS, TN, SLOW, TO_FREER),
    rule(AO, Added, [NEAR, NEAR, FAR], NEG, TP, SLOW, TO_FREER),
    rule(AO, Added, [NEAR, NEAR, FAR], ZA, TP, SLOW, TO_FREER),
    rule(AO, Added, [FAR, NEAR, FAR], NEG, TN, SLOW, TO_TARGET_SIDE),
    rule(AO, Added, [FAR, NEAR, FAR], POS, TP, SLOW, TO_TARGET_SIDE),
    rule(AO, Added, [FAR, NEAR, FAR], ZA, TN, SLOW, SPLIT),
    rule(AO, Added, [FAR, NEAR, FAR], ZA, TP, SLOW, SPLIT),
    rule(AO, Added, [MED, NEAR, MED], NEG, TN, SLOW, TO_TARGET_SIDE),
    rule(AO, Added, [MED, NEAR, MED], POS, TP, SLOW, TO_TARGET_SIDE),
    rule(AO, Added, [MED, NEAR, MED], ZA, TN, SLOW, SPLIT),
    rule(AO, Added, [MED, NEAR, MED], ZA, TP, SLOW, SPLIT),
    rule(AO, Added, [FAR, NEAR, MED], ANY, TN, SLOW, TO_FREER),
    rule(AO, Added, [MED, NEAR, FAR], ANY, TP, SLOW, TO_FREER),
    rule(AO, Added, [NEAR, NEAR, NEAR], ANY, TZ, SLOW, "boxed in on all three sides: creep straight on (a gap); the Avoider's escape turn leaves a dead end"),
];

#[cfg(test)]
mod tests {
    use super::*;

    const DISTS: [Dist; 3] = [Dist::Near, Dist::Med, Dist::Far];
    const ANGS: [Ang; 3] = [Ang::Neg, Ang::Z, Ang::Pos];

    fn matches<T: PartialEq>(a: Option<T>, t: T) -> bool {
        a.is_none_or(|a| a == t)
    }

    /// The rules matching one combination of terms.
    fn matching(l: Dist, f: Dist, r: Dist, h: Ang) -> Vec<&'static Rule> {
        RULES
            .iter()
            .filter(|x| {
                matches(x.left, l)
                    && matches(x.front, f)
                    && matches(x.right, r)
                    && matches(x.head_ang, h)
            })
            .collect()
    }

    #[test]
    fn every_combination_of_terms_has_a_rule() {
        for l in DISTS {
            for f in DISTS {
                for r in DISTS {
                    for h in ANGS {
                        let m = matching(l, f, r, h);
                        assert!(!m.is_empty(), "no rule for {l:?} {f:?} {r:?} {h:?}");
                        // Within one combination the conclusions agree, except for the
                        // dead-ahead split (neg and pos turns, same speed).
                        let speeds: Vec<_> = m.iter().map(|x| x.velocity_c).collect();
                        assert!(speeds.windows(2).all(|w| w[0] == w[1]), "{m:?}");
                        let turns: Vec<_> = m.iter().map(|x| x.head_c).collect();
                        let split = turns.contains(&Turn::Neg) && turns.contains(&Turn::Pos);
                        if split {
                            assert_eq!(h, Ang::Z, "split only with the target ahead: {m:?}");
                            assert_eq!(l, r, "split only with both sides alike: {m:?}");
                        } else {
                            assert!(turns.windows(2).all(|w| w[0] == w[1]), "{m:?}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn the_ten_paper_rules_are_there_once() {
        for (b, n) in [(FE, 4), (AO, 3), (ST, 3)] {
            let count = RULES
                .iter()
                .filter(|r| r.behaviour == b && matches!(r.origin, Paper(_) | PaperInterpreted(_)))
                .count();
            assert_eq!(count, n, "{b:?}");
        }
    }

    #[test]
    fn mirrored_rules_mirror() {
        // Swapping left and right and negating head_ang must negate head_c: the table is
        // symmetric, so a mirrored obstacle field gives a mirrored path.
        let mirror_ang = |a: Ang| match a {
            Ang::Neg => Ang::Pos,
            Ang::Z => Ang::Z,
            Ang::Pos => Ang::Neg,
        };
        let mirror_turn = |t: Turn| match t {
            Turn::Neg => Turn::Pos,
            Turn::Z => Turn::Z,
            Turn::Pos => Turn::Neg,
        };
        for l in DISTS {
            for f in DISTS {
                for r in DISTS {
                    for h in ANGS {
                        let mut a: Vec<_> = matching(l, f, r, h)
                            .iter()
                            .map(|x| (mirror_turn(x.head_c).index(), x.velocity_c.index()))
                            .collect();
                        let mut b: Vec<_> = matching(r, f, l, mirror_ang(h))
                            .iter()
                            .map(|x| (x.head_c.index(), x.velocity_c.index()))
                            .collect();
                        a.sort_unstable();
                        a.dedup();
                        b.sort_unstable();
                        b.dedup();
                        assert_eq!(a, b, "{l:?} {f:?} {r:?} {h:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn display_reads_like_the_paper() {
        assert_eq!(
            RULES[0].to_string(),
            "if left far and front far and right near and head_ang neg then head_c Z and velocity_c slow"
        );
        assert_eq!(
            RULES[4].to_string(),
            "if left med and front near and right near and head_ang any then head_c neg and velocity_c slow"
        );
    }
}
