//! Onboard fuzzy navigation past obstacles (seed 001 §II.B-II.D): a small Mamdani engine over the
//! paper's three fuzzy behaviours, a side lock for obstacles dead ahead, and dynamic reference
//! targets.
//!
//! The engine takes the nearest obstacle distance in each of the three range-sensor groups
//! (`left_obs`, `front_obs`, `right_obs`, m, from a [`plumetrace_core::RangeReturn`]) and the
//! angle to the target (`head_ang`, deg), and returns a speed (`velocity_c`, m/s) and a heading
//! change (`head_c`, deg). It is written here rather than taken from a crate: the fuzzy crates key
//! inputs by strings and return NaN when no rule fires.
//!
//! # Sign conventions
//!
//! Compass convention throughout (SEEDS-NOTES §1): headings clockwise from North, angle
//! differences wrapped to (-180, 180].
//! - `head_ang` = bearing of the target minus the heading: **positive when the target is to the
//!   right** (clockwise of the heading), negative when it is to the left ([`head_ang_deg`]).
//! - `head_c` = heading change: **positive turns clockwise (right)**, so the new heading command
//!   is `heading.turned_deg(turn_deg)`.
//! - The paper's `neg`/`pos` map one to one onto these (neg = left/anticlockwise for both
//!   variables); two Follow-Edge rules whose printed turn would steer into the obstacle are used
//!   with the turn reversed ([`rules`] documents each).
//!
//! # Engine
//!
//! - Membership functions ([`membership`]): Table I. Inputs: `near` and `far` are shoulders (1
//!   below / above their centres), `med` is a triangle reaching 0 at the neighbouring centres;
//!   sides 5/10/15 m, front 10/15/20 m, `head_ang` -50/0/50 deg. Outputs: triangles at 0.25/1.2/2
//!   m/s and -10/0/10 deg; the outer ones centred at the extreme values with a half-width equal to
//!   the distance to the middle centre, so the speed is always within [0.25, 2] m/s and the turn
//!   within [-10, 10] deg.
//! - Inference ([`engine`]): min for AND (an "any" antecedent is left out), min implication, max
//!   aggregation, centroid of the aggregate sampled on a fixed grid (211 points for speed, 201 for
//!   the turn, each holding the three centres) and taken as piecewise linear between points, as
//!   `skfuzzy` does (the cross-check `scripts/fuzzy_crosscheck.sh` compares the two).
//! - Inputs are sanitized: no obstacle within range (`None`), an infinite or NaN distance is fully
//!   far; a negative distance is 0; a non-finite `head_ang` is 0. The rule base fires for every
//!   input, and an output whose rules fire nowhere (possible only with another rule base) is
//!   [`NOTHING_FIRED`]: keep the heading at medium speed (1.2 m/s). No input gives NaN.
//! - Rules ([`rules`]): the paper's ten (Follow-Edge 4, Avoid-Obstacle 3, Steer-Target 3) and 43
//!   added so that every combination of terms has one, each with its reason.
//!
//! # Steering past an obstacle
//!
//! [`infer`] is stateless. With an obstacle ahead and both sides alike it fires a left and a right
//! turn whose centroid points at the obstacle; the [`Avoider`] locks a side with hysteresis (the
//! freer side, ties to the target's side), feeds only that side's turn until the front has been
//! clear for 5 s, forces a full turn when the front is under 3 m, and heads for the target between
//! obstacles when the way ahead is at least as open as the sides (a gap) ([`avoider`] gives the
//! rules and why the lock is taken late, under 5 m). The [`Drt`] gives the target to steer to
//! meanwhile ([`drt`]). `tests/fuzzy_avoidance.rs` flies them past a U, through an 8 m gap and
//! through a thousand random obstacle fields.
//!
//! In use: each decision, build [`FuzzyInputs::from_ranges`] from the range sensors with
//! [`head_ang_deg`] to the target (the [`Drt`] while passing an obstacle), call
//! [`Avoider::command`], and command `heading.turned_deg(turn_deg)` at `speed_mps`.
//!
//! ```
//! use plumetrace_planner::fuzzy::{Avoider, AvoiderParams, FuzzyInputs, infer};
//! // A wall 8 m dead ahead, nothing on either side, target ahead.
//! let x = FuzzyInputs { left_m: f64::INFINITY, front_m: 8.0, right_m: f64::INFINITY, head_ang_deg: 0.0 };
//! assert!(infer(&x).turn_deg.abs() < 1e-9); // the two turns cancel
//! let mut avoider = Avoider::new(AvoiderParams::default());
//! // Closer than 5 m and nearer than both sides: the avoider locks a side and turns fully.
//! let close = FuzzyInputs { front_m: 4.5, ..x };
//! assert!((avoider.command(&close, 0.5).turn_deg - 10.0).abs() < 1e-9);
//! ```

pub mod avoider;
pub mod drt;
pub mod engine;
pub mod membership;
pub mod rules;
pub mod safety;

pub use avoider::{AvoidMode, Avoider, AvoiderParams, Side};
pub use drt::{DRT_STEP_M, Drt, DrtStatus};
pub use engine::{
    Cuts, FuzzyInputs, FuzzyOutput, Grades, NO_OBSTACLE_M, NOTHING_FIRED, defuzzify, fire, fuzzify,
    head_ang_deg, infer, infer_with, strength,
};
pub use membership::{
    FRONT_OBS, HEAD_ANG, HEAD_C, InputVar, OutputVar, SIDE_OBS, Shape, VELOCITY_C,
};
pub use rules::{Ang, Behaviour, Dist, Origin, RULES, Rule, Speed, Turn};
pub use safety::{SafetyFilter, SafetyParams};

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_core::{Heading, RangeReturn, Vec2};

    const INF: f64 = f64::INFINITY;

    fn x(l: f64, f: f64, r: f64, h: f64) -> FuzzyInputs {
        FuzzyInputs {
            left_m: l,
            front_m: f,
            right_m: r,
            head_ang_deg: h,
        }
    }

    /// Hand-computed outputs. `tol` covers the grid where a clip corner falls between grid points.
    #[test]
    fn hand_computed_outputs() {
        let cases = [
            // (1) All clear, target ahead: Steer-Target 1 alone (strength 1): Z and fast, both
            //     symmetric triangles: turn 0, speed 2.
            (x(INF, INF, INF, 0.0), 2.0, 0.0, 1e-9),
            // (2) All clear, target 25 deg left: head_ang neg 0.5, Z 0.5. Steer-Target 2 (neg,
            //     fast) and 1 (Z, fast) fire at 0.5. head_c: neg clipped at 0.5 (plateau -15..-5)
            //     and Z clipped at 0.5 (plateau -5..5): one trapezoid, feet -20 and 10, plateau
            //     -15..5, symmetric about -5: turn -5. Speed: fast at 0.5: 2.
            (x(INF, INF, INF, -25.0), 2.0, -5.0, 1e-9),
            // (3) Obstacle 4 m on the right, target 60 deg left: Follow-Edge 1 (right near 1,
            //     head_ang neg 1) alone: hold course (0), slow (0.25).
            (x(INF, INF, 4.0, -60.0), 0.25, 0.0, 1e-9),
            // (4) Left 10 m (med 1), front 8 (near 1), right 4 (near 1): Avoid-Obstacle 1 alone
            //     (any head_ang): turn neg, -10, slow.
            (x(10.0, 8.0, 4.0, 35.0), 0.25, -10.0, 1e-9),
            // (5) A corridor: left and right 4 m, front 15 (med 1): Avoid-Obstacle 3: Z and med;
            //     the med speed triangle 0.25..1.2..2 has its centroid at (0.25+1.2+2)/3 = 1.15.
            (x(4.0, 15.0, 4.0, 40.0), 1.15, 0.0, 1e-9),
            // (6) The dead-ahead split: front 8, sides clear, target 30 deg right: head_ang Z 0.4,
            //     pos 0.6. (far,near,far,pos) -> pos 0.6; (far,near,far,Z) -> neg 0.4 and pos 0.4.
            //     Cuts neg 0.4, pos 0.6. A triangle of base 20 clipped at h has area
            //     10 (1 - (1 - h)^2): 6.4 at -10 and 8.4 at +10 (clip points -16, -4, 6, 14 are on
            //     the grid): turn (8.4 - 6.4) 10 / 14.8 = 1.3514. Speed slow: 0.25.
            (x(INF, 8.0, INF, 30.0), 0.25, 20.0 / 14.8, 1e-9),
            // (7) Front 12 m (near 0.6, med 0.4), sides clear, target 60 deg right (pos 1):
            //     (far,near,far,pos) -> pos, slow 0.6; (far,med,far,pos) -> pos, med 0.4. Turn 10.
            //     Speed: slow clipped at 0.6 (rises -0.7..-0.13, plateau to 0.63, falls) and med
            //     clipped at 0.4 (plateau 0.63..1.68, falls to 0 at 2); the aggregate's pieces
            //     (area, centroid): (0.171, -0.32), (0.456, 0.25), (0.095, 0.71867) from 0.63 to
            //     0.82 where slow falls to 0.4, (0.344, 1.25), (0.064, 1.78667); total moment
            //     0.67190 over area 1.13: 0.59460. The clip points -0.13, 0.82 and 1.68 are not
            //     grid points: 2e-3 tolerance.
            (x(INF, 12.0, INF, 60.0), 0.59460, 10.0, 2e-3),
        ];
        for (i, (inp, speed, turn, tol)) in cases.into_iter().enumerate() {
            let out = infer(&inp);
            assert!(
                (out.speed_mps - speed).abs() < tol && (out.turn_deg - turn).abs() < tol,
                "case {}: {inp:?} -> {out:?}, want speed {speed} turn {turn}",
                i + 1
            );
        }
    }

    #[test]
    fn paper_rules_fire_alone_in_their_cells() {
        // One input at the centre of each of the ten rules' terms: that rule fires at 1 and the
        // output is its conclusion's centre (the med speed term's centroid is 1.15).
        let centre_dist = |d: Option<Dist>, front: bool| match (d, front) {
            (Some(Dist::Near), false) => 5.0,
            (Some(Dist::Med), false) => 10.0,
            (Some(Dist::Far), false) => 15.0,
            (Some(Dist::Near), true) => 10.0,
            (Some(Dist::Med), true) => 15.0,
            (Some(Dist::Far), true) => 20.0,
            (None, _) => 12.0,
        };
        for r in RULES.iter().filter(|r| !matches!(r.origin, Origin::Added)) {
            let h = match r.head_ang {
                Some(Ang::Neg) => -50.0,
                Some(Ang::Pos) => 50.0,
                _ => 0.0,
            };
            let inp = x(
                centre_dist(r.left, false),
                centre_dist(r.front, true),
                centre_dist(r.right, false),
                h,
            );
            let out = infer(&inp);
            let turn = [-10.0, 0.0, 10.0][r.head_c.index()];
            let speed = [0.25, 1.15, 2.0][r.velocity_c.index()];
            assert!(
                (out.turn_deg - turn).abs() < 1e-9 && (out.speed_mps - speed).abs() < 1e-9,
                "{r}: {out:?}"
            );
        }
    }

    #[test]
    fn non_finite_and_out_of_range_inputs() {
        let cases = [
            x(f64::NAN, f64::NAN, f64::NAN, f64::NAN),
            x(-5.0, -1e300, f64::NEG_INFINITY, f64::INFINITY),
            x(INF, INF, INF, f64::NEG_INFINITY),
            x(1e308, 0.0, 1e-300, 1e300),
            x(0.0, 0.0, 0.0, -1e-300),
        ];
        for inp in cases {
            let out = infer(&inp);
            assert!(
                out.speed_mps.is_finite() && out.turn_deg.is_finite(),
                "{inp:?}"
            );
            assert!((0.25..=2.0).contains(&out.speed_mps), "{inp:?} {out:?}");
            assert!((-10.0..=10.0).contains(&out.turn_deg), "{inp:?} {out:?}");
        }
        // NaN everywhere: no obstacle, target ahead: Steer-Target 1.
        let out = infer(&cases[0]);
        assert!(
            (out.speed_mps - 2.0).abs() < 1e-9 && out.turn_deg.abs() < 1e-9,
            "{out:?}"
        );
        // head_ang wraps: 350 deg is 10 deg left.
        assert_eq!(
            infer(&x(INF, INF, INF, 350.0)),
            infer(&x(INF, INF, INF, -10.0))
        );
    }

    #[test]
    fn empty_rule_base_gives_the_default() {
        assert_eq!(infer_with(&[], &x(3.0, 3.0, 3.0, 3.0)), NOTHING_FIRED);
    }

    #[test]
    fn from_ranges_treats_none_as_far() {
        let r = RangeReturn {
            front_m: Some(8.0),
            left_m: None,
            right_m: Some(30.0),
        };
        let inp = FuzzyInputs::from_ranges(&r, 12.0);
        assert_eq!(inp.left_m, INF);
        let g = fuzzify(&inp);
        assert_eq!(g.left, [0.0, 0.0, 1.0]);
        assert_eq!(g.right, [0.0, 0.0, 1.0]);
        assert_eq!(g.front, [1.0, 0.0, 0.0]);
    }

    #[test]
    fn head_ang_sign_table() {
        // Vehicle at the origin heading North: a target to the East is to the right (+).
        let o = Vec2::zeros();
        let cases = [
            (0.0, (10.0, 10.0), 45.0),
            (0.0, (-10.0, 10.0), -45.0),
            (90.0, (0.0, 10.0), -90.0),
            (270.0, (0.0, -10.0), -90.0),
            (0.0, (0.0, -10.0), 180.0),
            (0.0, (0.0, 0.0), 0.0),
        ];
        for (hdg, (e, n), want) in cases {
            let got = head_ang_deg(o, Heading::from_deg(hdg), Vec2::new(e, n));
            assert!((got - want).abs() < 1e-9, "{hdg} ({e},{n}): {got}");
        }
    }

    #[test]
    fn steering_turns_towards_the_target() {
        // With nothing around, the sign of head_c follows head_ang (-180 wraps to 180: right).
        for k in -17..=17 {
            let h = f64::from(k) * 10.0;
            let t = infer(&x(INF, INF, INF, h)).turn_deg;
            assert_eq!(t.abs() < 1e-9, k == 0, "{h}: {t}");
            assert!(k == 0 || t.signum() == h.signum(), "{h}: {t}");
        }
    }
}
