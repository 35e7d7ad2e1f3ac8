//! Fuzzy obstacle avoidance flown by a simple kinematic vehicle among polygon obstacles: a dense
//! sweep of the engine's inputs, a U-shaped obstacle, a narrow gap, a thousand random obstacle
//! fields, and the dump the Python cross-check (`scripts/fuzzy_crosscheck.sh`) compares with
//! scikit-fuzzy.
//!
//! The vehicle is a point: each 0.5 s step it turns by the fuzzy `head_c` (at most 10 deg) and
//! then moves `velocity_c` x 0.5 s along its new heading. Range sensing casts 7 rays in each of
//! three groups (front -30..30 deg, left -90..-30, right 30..90 about the heading, 20 m range)
//! against the obstacles' edges and keeps each group's nearest return (seed 001 eq. 8). A
//! collision is a step whose segment touches an obstacle's edge or ends inside one (stricter than
//! a position inside a polygon). The target is reached within 2.5 m.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_core::{Heading, RangeReturn, Vec2};
use plumetrace_planner::fuzzy::{
    Avoider, AvoiderParams, DRT_STEP_M, Drt, DrtStatus, FuzzyInputs, RULES, head_ang_deg, infer,
    infer_with,
};
use std::fmt::Write as _;

/// SplitMix64: a small deterministic generator for the random fields.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    fn below(&mut self, n: usize) -> usize {
        (self.unit() * n as f64) as usize % n.max(1)
    }
}

/// A closed polygon (the last vertex joins the first).
#[derive(Debug, Clone)]
struct Polygon(Vec<Vec2>);

impl Polygon {
    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Self {
        Polygon(vec![
            Vec2::new(x0, y0),
            Vec2::new(x1, y0),
            Vec2::new(x1, y1),
            Vec2::new(x0, y1),
        ])
    }

    fn edges(&self) -> impl Iterator<Item = (Vec2, Vec2)> + '_ {
        let n = self.0.len();
        (0..n).map(move |i| (self.0[i], self.0[(i + 1) % n]))
    }

    /// Even-odd point-in-polygon test.
    fn contains(&self, p: Vec2) -> bool {
        let mut inside = false;
        for (a, b) in self.edges() {
            if (a.y > p.y) != (b.y > p.y) {
                let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if p.x < x {
                    inside = !inside;
                }
            }
        }
        inside
    }

    /// Distance along the ray `p + t d` (unit `d`) to the first edge, if within `max_t`.
    fn ray(&self, p: Vec2, d: Vec2, max_t: f64) -> Option<f64> {
        let mut best: Option<f64> = None;
        for (a, b) in self.edges() {
            if let Some(t) = ray_segment(p, d, a, b)
                && t <= max_t
                && best.is_none_or(|b| t < b)
            {
                best = Some(t);
            }
        }
        best
    }

    /// Whether the segment `p q` touches an edge or ends inside.
    fn hit_by(&self, p: Vec2, q: Vec2) -> bool {
        self.contains(q) || self.edges().any(|(a, b)| segments_touch(p, q, a, b))
    }

    fn min_dist(&self, p: Vec2) -> f64 {
        if self.contains(p) {
            return 0.0;
        }
        self.edges()
            .map(|(a, b)| {
                let ab = b - a;
                let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                (a + ab * t - p).norm()
            })
            .fold(f64::INFINITY, f64::min)
    }
}

fn cross(a: Vec2, b: Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// `t >= 0` where the ray `p + t d` meets the segment `a b`.
fn ray_segment(p: Vec2, d: Vec2, a: Vec2, b: Vec2) -> Option<f64> {
    let e = b - a;
    let den = cross(d, e);
    if den.abs() < 1e-12 {
        return None;
    }
    let w = a - p;
    let t = cross(w, e) / den;
    let s = cross(w, d) / den;
    (t >= 0.0 && (0.0..=1.0).contains(&s)).then_some(t)
}

fn segments_touch(p: Vec2, q: Vec2, a: Vec2, b: Vec2) -> bool {
    let (o1, o2) = (cross(q - p, a - p), cross(q - p, b - p));
    let (o3, o4) = (cross(b - a, p - a), cross(b - a, q - a));
    let opposite = |x: f64, y: f64| (x > 0.0 && y < 0.0) || (x < 0.0 && y > 0.0);
    if opposite(o1, o2) && opposite(o3, o4) {
        return true;
    }
    let on = |u: Vec2, v: Vec2, w: Vec2| {
        w.x >= u.x.min(v.x) && w.x <= u.x.max(v.x) && w.y >= u.y.min(v.y) && w.y <= u.y.max(v.y)
    };
    (o1 == 0.0 && on(p, q, a))
        || (o2 == 0.0 && on(p, q, b))
        || (o3 == 0.0 && on(a, b, p))
        || (o4 == 0.0 && on(a, b, q))
}

const MAX_RANGE_M: f64 = 20.0;
const RAYS: usize = 7;
const DT_S: f64 = 0.5;

/// The three range-sensor groups (seed 001 eq. 8).
fn sense(obstacles: &[Polygon], pos: Vec2, heading: Heading) -> RangeReturn {
    let group = |from: f64, to: f64| -> Option<f64> {
        (0..RAYS)
            .filter_map(|k| {
                let a = from + (to - from) * k as f64 / (RAYS - 1) as f64;
                let d = heading.turned_deg(a).unit();
                obstacles
                    .iter()
                    .filter_map(|o| o.ray(pos, d, MAX_RANGE_M))
                    .min_by(f64::total_cmp)
            })
            .min_by(f64::total_cmp)
    };
    RangeReturn {
        front_m: group(-30.0, 30.0),
        left_m: group(-90.0, -30.0),
        right_m: group(30.0, 90.0),
    }
}

/// How the target given to the fuzzy engine is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Targeting {
    /// Always the goal.
    Goal,
    /// A DRT (seed 001 §II.D, 15 m steps) from the moment an obstacle is first in view (the front
    /// group sees something, or a side group within 10 m) until it is reached with none in view;
    /// the goal otherwise, and also when the DRT has moved further along its path than the goal
    /// (it would lead past the goal).
    Drt,
}

/// What turns the fuzzy inputs into commands.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Controller {
    /// The stateful [`Avoider`] (side lock, escape, threading).
    Avoider,
    /// The stateless engine alone ([`infer`]), for comparison.
    Stateless,
    /// An empty rule base: keep the heading at medium speed (checks the collision test).
    Blind,
}

#[derive(Debug, Clone, Copy)]
struct Outcome {
    reached: bool,
    collided: bool,
    time_s: f64,
    path_m: f64,
    min_clearance_m: f64,
}

struct Mission<'a> {
    obstacles: &'a [Polygon],
    start: Vec2,
    heading: Heading,
    goal: Vec2,
    targeting: Targeting,
    controller: Controller,
    reach_m: f64,
    time_limit_s: f64,
}

impl<'a> Mission<'a> {
    /// A mission with the avoider, 2.5 m arrival radius, heading for the goal at the start.
    fn new(obstacles: &'a [Polygon], start: Vec2, goal: Vec2, targeting: Targeting) -> Self {
        Mission {
            obstacles,
            start,
            heading: Heading::of_vector(goal - start).unwrap_or(Heading::NORTH),
            goal,
            targeting,
            controller: Controller::Avoider,
            reach_m: 2.5,
            time_limit_s: 600.0,
        }
    }

    /// Flies the mission; `track` collects the positions when given.
    fn fly(&self, mut track: Option<&mut Vec<Vec2>>) -> Outcome {
        let mut avoider = Avoider::new(AvoiderParams::default());
        let (mut pos, mut heading) = (self.start, self.heading);
        let mut drt: Option<Drt> = None;
        let mut out = Outcome {
            reached: false,
            collided: false,
            time_s: 0.0,
            path_m: 0.0,
            min_clearance_m: f64::INFINITY,
        };
        let steps = (self.time_limit_s / DT_S) as usize;
        for k in 0..steps {
            out.time_s = k as f64 * DT_S;
            if (pos - self.goal).norm() <= self.reach_m {
                out.reached = true;
                break;
            }
            let ranges = sense(self.obstacles, pos, heading);
            let mut inputs = FuzzyInputs::from_ranges(&ranges, 0.0);
            let mut target = self.goal;
            if self.targeting == Targeting::Drt {
                let in_view = Drt::obstacle_in_view(&inputs, 10.0);
                if drt.is_none() && in_view {
                    drt = Some(Drt::new(pos, heading, DRT_STEP_M));
                }
                if let Some(d) = drt.as_mut() {
                    match d.step(pos, in_view) {
                        // A DRT further along its path than the goal would lead past it.
                        DrtStatus::Target(t) if d.along_m(self.goal) > d.along_m(t) => target = t,
                        DrtStatus::Target(_) => {}
                        DrtStatus::Passed => drt = None,
                    }
                }
            }
            inputs.head_ang_deg = head_ang_deg(pos, heading, target);
            let cmd = match self.controller {
                Controller::Avoider => avoider.command(&inputs, DT_S),
                Controller::Stateless => infer(&inputs),
                Controller::Blind => infer_with(&[], &inputs),
            };
            assert!(cmd.speed_mps.is_finite() && cmd.turn_deg.is_finite());
            heading = heading.turned_deg(cmd.turn_deg);
            let next = pos + heading.unit() * (cmd.speed_mps * DT_S);
            if self.obstacles.iter().any(|o| o.hit_by(pos, next)) {
                out.collided = true;
            }
            out.path_m += (next - pos).norm();
            pos = next;
            for o in self.obstacles {
                out.min_clearance_m = out.min_clearance_m.min(o.min_dist(pos));
            }
            if let Some(t) = track.as_deref_mut() {
                t.push(pos);
            }
            if out.collided {
                break;
            }
        }
        out
    }
}

/// A U open towards the South: base along y 40..42 from x -15 to 15, arms down to y 20.
fn u_shape() -> Polygon {
    Polygon(
        [
            (-15.0, 20.0),
            (-13.0, 20.0),
            (-13.0, 40.0),
            (13.0, 40.0),
            (13.0, 20.0),
            (15.0, 20.0),
            (15.0, 42.0),
            (-15.0, 42.0),
        ]
        .iter()
        .map(|&(x, y)| Vec2::new(x, y))
        .collect(),
    )
}

#[test]
fn harness_senses_and_detects_collisions() {
    // A 20 m x 10 m block 10 m North of the origin.
    let square = [Polygon::rect(-10.0, 10.0, 10.0, 20.0)];
    let r = sense(&square, Vec2::zeros(), Heading::NORTH);
    assert!(r.front_m.is_some_and(|f| (f - 10.0).abs() < 1e-9), "{r:?}");
    // The side groups' nearest rays are the shared ones at -30 and 30 deg: 10 / cos 30 to the
    // face (reached at x -5.77 and 5.77).
    let oblique = 10.0 / 30f64.to_radians().cos();
    assert!(
        r.left_m.is_some_and(|l| (l - oblique).abs() < 1e-9),
        "{r:?}"
    );
    assert!(
        r.right_m.is_some_and(|l| (l - oblique).abs() < 1e-9),
        "{r:?}"
    );
    // Heading East the block is on the left: the -90 deg ray (bearing 0) meets it at 10 m; the
    // front group's -30 deg ray (bearing 60) passes its corner; nothing on the right.
    let r = sense(&square, Vec2::zeros(), Heading::from_deg(90.0));
    assert_eq!((r.front_m, r.right_m), (None, None), "{r:?}");
    assert!(r.left_m.is_some_and(|l| (l - 10.0).abs() < 1e-9), "{r:?}");
    // Collisions: a step across an edge, a step ending inside; not a step beside it.
    assert!(square[0].hit_by(Vec2::new(0.0, 9.0), Vec2::new(0.0, 11.0)));
    assert!(square[0].hit_by(Vec2::new(0.0, 15.0), Vec2::new(0.0, 16.0)));
    assert!(!square[0].hit_by(Vec2::new(11.0, 9.0), Vec2::new(11.0, 21.0)));
    // A vehicle that holds its heading (an empty rule base: keep heading, 1.2 m/s) hits it.
    let m = Mission::new(
        &square,
        Vec2::zeros(),
        Vec2::new(0.0, 30.0),
        Targeting::Goal,
    );
    let mut track = Vec::new();
    let mut avoider_free = m.fly(Some(&mut track));
    assert!(
        !avoider_free.collided && avoider_free.reached,
        "{avoider_free:?}"
    );
    avoider_free = Mission {
        controller: Controller::Blind,
        ..m
    }
    .fly(None);
    assert!(avoider_free.collided, "{avoider_free:?}");
}

#[test]
fn dense_sweep_gives_finite_outputs_in_range() {
    // 25 values per distance input (0..24 m, with the special values) and 25 angles, plus
    // non-finite and negative inputs.
    let mut dists: Vec<f64> = (0..21).map(|k| f64::from(k) * 1.25).collect();
    dists.extend([f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -3.0]);
    let mut angs: Vec<f64> = (0..21).map(|k| -180.0 + f64::from(k) * 18.0).collect();
    angs.extend([f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e9]);
    assert_eq!((dists.len(), angs.len()), (25, 25));
    let mut n = 0usize;
    for &l in &dists {
        for &f in &dists {
            for &r in &dists {
                for &h in &angs {
                    let x = FuzzyInputs {
                        left_m: l,
                        front_m: f,
                        right_m: r,
                        head_ang_deg: h,
                    };
                    let o = infer(&x);
                    assert!(
                        o.speed_mps.is_finite() && (0.25..=2.0).contains(&o.speed_mps),
                        "{x:?} -> {o:?}"
                    );
                    assert!(
                        o.turn_deg.is_finite() && (-10.0..=10.0).contains(&o.turn_deg),
                        "{x:?} -> {o:?}"
                    );
                    n += 1;
                }
            }
        }
    }
    assert_eq!(n, 25usize.pow(4));
}

#[test]
fn avoider_outputs_stay_finite_in_a_random_walk_of_inputs() {
    let mut rng = SplitMix64(7);
    let mut a = Avoider::default();
    for _ in 0..100_000 {
        let mut d = || match rng.below(10) {
            0 => f64::NAN,
            1 => f64::INFINITY,
            2 => -1.0,
            _ => rng.range(0.0, 25.0),
        };
        let x = FuzzyInputs {
            left_m: d(),
            front_m: d(),
            right_m: d(),
            head_ang_deg: rng.range(-400.0, 400.0),
        };
        let o = a.command(&x, 0.5);
        assert!((0.25..=2.0).contains(&o.speed_mps), "{x:?} {o:?}");
        assert!((-10.0..=10.0).contains(&o.turn_deg), "{x:?} {o:?}");
    }
}

#[test]
fn u_shape_is_escaped_and_the_target_reached() {
    // The U opens towards the start; the target is 18 m behind its base.
    let obstacles = [u_shape()];
    let (start, goal) = (Vec2::new(0.0, 0.0), Vec2::new(0.0, 60.0));
    for targeting in [Targeting::Goal, Targeting::Drt] {
        let m = Mission::new(&obstacles, start, goal, targeting);
        let mut track = Vec::new();
        let o = m.fly(Some(&mut track));
        println!("U-shape, avoider, {targeting:?}: {o:?}");
        assert!(!o.collided, "{targeting:?}: {o:?}");
        assert!(o.reached, "{targeting:?}: {o:?}");
        // It went into the U (past the arms' ends) before getting out.
        assert!(
            track.iter().any(|p| p.y > 22.0 && p.x.abs() < 13.0),
            "{targeting:?}"
        );
    }
    // For comparison (not asserted): the stateless engine, whose split cancels at the base.
    let m = Mission {
        controller: Controller::Stateless,
        ..Mission::new(&obstacles, start, goal, Targeting::Goal)
    };
    println!("U-shape, stateless engine: {:?}", m.fly(None));
}

/// Where a track first crosses `y` going North, if it does.
fn crossing_x(track: &[Vec2], y: f64) -> Option<f64> {
    track
        .windows(2)
        .find(|w| w[0].y < y && w[1].y >= y)
        .map(|w| w[0].x + (w[1].x - w[0].x) * (y - w[0].y) / (w[1].y - w[0].y))
}

#[test]
fn narrow_gap_is_passed() {
    // A wall along y 30..32 from x -100 to 100 with an 8 m gap at x -4..4; going round is a
    // detour of 200 m. Each mission flies a straight line through (offset, 31) at `angle` from
    // North, from 31 m before the wall to 31 m after it.
    let obstacles = [
        Polygon::rect(-100.0, 30.0, -4.0, 32.0),
        Polygon::rect(4.0, 30.0, 100.0, 32.0),
    ];
    let fly = |offset: f64, angle: f64, targeting: Targeting| {
        let h = Heading::from_deg(angle);
        let at = Vec2::new(offset, 31.0);
        let (start, goal) = (at - h.unit() * 31.0, at + h.unit() * 31.0);
        let m = Mission {
            time_limit_s: 150.0,
            ..Mission::new(&obstacles, start, goal, targeting)
        };
        let mut track = vec![start];
        let o = m.fly(Some(&mut track));
        let through = crossing_x(&track, 31.0).is_some_and(|x| x.abs() < 4.0);
        (o, through)
    };
    // Asserted: lines within 2 m of the gap's centre line, within 10 deg (1 m) or 5 deg (2 m)
    // of square to the wall, and along the centre line within 15 deg.
    let cases = [
        (0.0, 0.0),
        (0.0, 15.0),
        (0.0, -15.0),
        (1.0, 0.0),
        (-1.0, 0.0),
        (1.0, 10.0),
        (1.0, -10.0),
        (-1.0, 10.0),
        (-1.0, -10.0),
        (2.0, 0.0),
        (-2.0, 0.0),
        (2.0, 5.0),
        (-2.0, -5.0),
    ];
    for (offset, angle) in cases {
        for targeting in [Targeting::Goal, Targeting::Drt] {
            let (o, through) = fly(offset, angle, targeting);
            assert!(
                !o.collided && o.reached && through,
                "offset {offset} m, angle {angle} deg, {targeting:?}: through the gap {through}, {o:?}"
            );
        }
    }
    // Printed (run with --nocapture): the map of offsets x angles that pass through the gap.
    println!(
        "8 m gap, avoider, goal targeting: 'o' through the gap, '.' round the wall or timed out, 'X' collided"
    );
    println!("offset m \\ angle deg -30..30 by 5");
    for offset in [-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0] {
        let row: String = (-6..=6)
            .map(|k| {
                let (o, through) = fly(offset, f64::from(k) * 5.0, Targeting::Goal);
                if o.collided {
                    'X'
                } else if through && o.reached {
                    'o'
                } else {
                    '.'
                }
            })
            .collect();
        println!("{offset:6.1}  {row}");
    }
}

/// A random convex polygon around `c`: 5-9 vertices at sorted angles, radii 0.6-1 of `r`.
fn random_blob(rng: &mut SplitMix64, c: Vec2, r: f64) -> Polygon {
    let n = 5 + rng.below(5);
    let mut angles: Vec<f64> = (0..n).map(|_| rng.range(0.0, 360.0)).collect();
    angles.sort_by(f64::total_cmp);
    Polygon(
        angles
            .iter()
            .map(|&a| c + Heading::from_deg(a).unit() * (r * rng.range(0.6, 1.0)))
            .collect(),
    )
}

/// A random wall (a long thin rectangle) centred at `c`, `len` long, 1-3 m thick.
fn random_wall(rng: &mut SplitMix64, c: Vec2, len: f64) -> Polygon {
    let h = Heading::from_deg(rng.range(0.0, 180.0));
    let (u, v) = (h.unit(), h.turned_deg(90.0).unit());
    let w = rng.range(1.0, 3.0);
    Polygon(vec![
        c - u * (len / 2.0) - v * (w / 2.0),
        c + u * (len / 2.0) - v * (w / 2.0),
        c + u * (len / 2.0) + v * (w / 2.0),
        c - u * (len / 2.0) + v * (w / 2.0),
    ])
}

/// A random field: start and goal at least 40 m apart in a 100 m square; 3 to 8 obstacles
/// (70 % convex blobs of radius 3-12 m, 30 % walls 10-40 m long) placed anywhere in the square
/// with at least `gap_m` between their bounding circles (so every passage between obstacles is at
/// least that wide and the goal can always be reached) and at least 5 m from the start and goal.
fn random_field(rng: &mut SplitMix64, gap_m: f64) -> (Vec<Polygon>, Vec2, Vec2) {
    let (start, goal) = loop {
        let s = Vec2::new(rng.range(0.0, 100.0), rng.range(0.0, 100.0));
        let g = Vec2::new(rng.range(0.0, 100.0), rng.range(0.0, 100.0));
        if (g - s).norm() >= 40.0 {
            break (s, g);
        }
    };
    let count = 3 + rng.below(6);
    let mut circles: Vec<(Vec2, f64)> = Vec::new();
    let mut obstacles = Vec::new();
    let mut tries = 0;
    while obstacles.len() < count && tries < 1000 {
        tries += 1;
        let c = Vec2::new(rng.range(0.0, 100.0), rng.range(0.0, 100.0));
        let wall = rng.unit() < 0.3;
        let r = if wall {
            rng.range(5.0, 20.0)
        } else {
            rng.range(3.0, 12.0)
        };
        let clear = |p: Vec2| (p - c).norm() >= r + 5.0;
        if !clear(start)
            || !clear(goal)
            || circles
                .iter()
                .any(|&(o, ro)| (o - c).norm() < r + ro + gap_m)
        {
            continue;
        }
        let poly = if wall {
            random_wall(rng, c, 2.0 * r)
        } else {
            random_blob(rng, c, r)
        };
        circles.push((c, r));
        obstacles.push(poly);
    }
    (obstacles, start, goal)
}

#[derive(Debug)]
struct FieldStats {
    runs: usize,
    reached: usize,
    collided: usize,
    min_clearance_m: f64,
    failures: Vec<String>,
}

/// Flies `runs` random fields from `seed`.
fn random_fields(
    seed: u64,
    runs: usize,
    targeting: Targeting,
    controller: Controller,
) -> FieldStats {
    let mut rng = SplitMix64(seed);
    let mut s = FieldStats {
        runs,
        reached: 0,
        collided: 0,
        min_clearance_m: f64::INFINITY,
        failures: Vec::new(),
    };
    for i in 0..runs {
        let (obstacles, start, goal) = random_field(&mut rng, 8.0);
        let m = Mission {
            controller,
            ..Mission::new(&obstacles, start, goal, targeting)
        };
        let o = m.fly(None);
        s.reached += usize::from(o.reached);
        s.collided += usize::from(o.collided);
        s.min_clearance_m = s.min_clearance_m.min(o.min_clearance_m);
        if !o.reached || o.collided {
            s.failures.push(format!("field {i}: {o:?}"));
        }
    }
    s
}

#[test]
fn random_fields_no_collision_and_reach_95_percent() {
    let configs = [
        (Targeting::Goal, Controller::Avoider),
        (Targeting::Drt, Controller::Avoider),
        (Targeting::Goal, Controller::Stateless),
    ];
    let results: Vec<FieldStats> = std::thread::scope(|scope| {
        let handles: Vec<_> = configs
            .iter()
            .map(|&(t, c)| scope.spawn(move || random_fields(2024, 1000, t, c)))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for ((targeting, controller), s) in configs.iter().zip(&results) {
        println!(
            "{controller:?}, {targeting:?}: {} fields, reached {} ({:.1} %), collided {}, min clearance {:.2} m",
            s.runs,
            s.reached,
            100.0 * s.reached as f64 / s.runs as f64,
            s.collided,
            s.min_clearance_m
        );
        for f in s.failures.iter().take(5) {
            println!("  {f}");
        }
    }
    // Asserted for the avoider; the stateless engine is printed for comparison.
    for ((targeting, controller), s) in configs.iter().zip(&results) {
        if *controller == Controller::Avoider {
            assert_eq!(s.collided, 0, "{targeting:?}: {s:?}");
            assert!(s.reached * 100 >= s.runs * 95, "{targeting:?}: {s:?}");
        }
    }
}

/// Reads `FUZZY_INPUTS` (CSV `left_m,front_m,right_m,head_ang_deg` with a header line), writes
/// `FUZZY_OUTPUTS` (`speed_mps,turn_deg`, one line per input) from the stateless engine, and,
/// when `FUZZY_RULES` is set, the rule table as CSV for the cross-check to build the same rules.
#[test]
#[ignore = "run by scripts/fuzzy_crosscheck.sh"]
fn crosscheck_dump() {
    let input = std::env::var("FUZZY_INPUTS").expect("FUZZY_INPUTS: a CSV path");
    let output = std::env::var("FUZZY_OUTPUTS").expect("FUZZY_OUTPUTS: a CSV path");
    let text = std::fs::read_to_string(&input).unwrap();
    let mut out = String::from("speed_mps,turn_deg\n");
    for (i, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        let v: Vec<f64> = line
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .unwrap_or_else(|e| panic!("{input} line {}: {e}", i + 1));
        assert_eq!(v.len(), 4, "{input} line {}", i + 1);
        let o = infer(&FuzzyInputs {
            left_m: v[0],
            front_m: v[1],
            right_m: v[2],
            head_ang_deg: v[3],
        });
        writeln!(out, "{:.17e},{:.17e}", o.speed_mps, o.turn_deg).unwrap();
    }
    std::fs::write(&output, out).unwrap();
    if let Ok(rules_path) = std::env::var("FUZZY_RULES") {
        let term = |t: String| t.to_lowercase();
        let mut csv =
            String::from("behaviour,origin,left,front,right,head_ang,head_c,velocity_c\n");
        for r in &RULES {
            let d = |x: Option<plumetrace_planner::fuzzy::Dist>| {
                x.map_or("any".to_string(), |t| term(format!("{t:?}")))
            };
            writeln!(
                csv,
                "{:?},{:?},{},{},{},{},{},{}",
                r.behaviour,
                r.origin,
                d(r.left),
                d(r.front),
                d(r.right),
                r.head_ang
                    .map_or("any".to_string(), |t| term(format!("{t:?}"))),
                term(format!("{:?}", r.head_c)),
                term(format!("{:?}", r.velocity_c)),
            )
            .unwrap();
        }
        std::fs::write(rules_path, csv).unwrap();
    }
}
