//! Membership functions of the fuzzy navigation engine: Table I of seed 001 as fixed arrays.
//!
//! Every variable has three terms. An input's outer terms are shoulders (`near` is 1 at and below
//! its centre, `far` is 1 at and above its centre) and its middle term is a triangle that reaches 0
//! at the two neighbouring centres, so the three grades of any input add up to 1. An output's three
//! terms are triangles; the outer ones are centred at the extreme values (0.25 m/s and 2 m/s, -10 and
//! +10 deg) with a half-width equal to the distance to the middle centre, so that an output with only
//! an outer term firing defuzzifies exactly to that term's centre. The output universe therefore runs
//! one half-width beyond each extreme centre (-0.7 to 2.8 m/s, -20 to 20 deg); the centroid never
//! leaves the interval between the extreme centres, because the aggregate is symmetric about an
//! extreme centre except for mass on the inner side.

/// The shape of one fuzzy set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// 1 at and below `full`, falling linearly to 0 at `zero` (`full < zero`).
    LeftShoulder {
        /// Where the grade starts to fall from 1.
        full: f64,
        /// Where the grade reaches 0.
        zero: f64,
    },
    /// 0 at and below `lo`, rising linearly to 1 at `peak`, falling to 0 at `hi`.
    Triangle {
        /// Left foot.
        lo: f64,
        /// Apex.
        peak: f64,
        /// Right foot.
        hi: f64,
    },
    /// 0 at and below `zero`, rising linearly to 1 at `full` and staying 1 above it.
    RightShoulder {
        /// Where the grade starts to rise from 0.
        zero: f64,
        /// Where the grade reaches 1.
        full: f64,
    },
}

impl Shape {
    /// The grade of `x`, in [0, 1]; 0 for NaN.
    pub fn grade(self, x: f64) -> f64 {
        if x.is_nan() {
            return 0.0;
        }
        let g = match self {
            Shape::LeftShoulder { full, zero } => {
                if x <= full {
                    1.0
                } else if x >= zero {
                    0.0
                } else {
                    (zero - x) / (zero - full)
                }
            }
            Shape::Triangle { lo, peak, hi } => {
                if x <= lo || x >= hi {
                    0.0
                } else if x <= peak {
                    (x - lo) / (peak - lo)
                } else {
                    (hi - x) / (hi - peak)
                }
            }
            Shape::RightShoulder { zero, full } => {
                if x >= full {
                    1.0
                } else if x <= zero {
                    0.0
                } else {
                    (x - zero) / (full - zero)
                }
            }
        };
        g.clamp(0.0, 1.0)
    }
}

/// The three terms of an input variable, in order (near, med, far) or (neg, Z, pos).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InputVar {
    /// The terms' shapes: left shoulder, triangle, right shoulder.
    pub sets: [Shape; 3],
}

impl InputVar {
    /// The variable with Table I centres `c` (increasing): a left shoulder at `c[0]`, a triangle
    /// `c[0]..c[1]..c[2]` and a right shoulder at `c[2]`.
    pub const fn from_centres(c: [f64; 3]) -> Self {
        InputVar {
            sets: [
                Shape::LeftShoulder {
                    full: c[0],
                    zero: c[1],
                },
                Shape::Triangle {
                    lo: c[0],
                    peak: c[1],
                    hi: c[2],
                },
                Shape::RightShoulder {
                    zero: c[1],
                    full: c[2],
                },
            ],
        }
    }

    /// The grades of `x` in the three terms.
    pub fn grades(&self, x: f64) -> [f64; 3] {
        [
            self.sets[0].grade(x),
            self.sets[1].grade(x),
            self.sets[2].grade(x),
        ]
    }
}

/// The most grid points an output universe may have (the size of the engine's scratch arrays).
pub const MAX_GRID_POINTS: usize = 256;

/// The three terms of an output variable and the grid its centroid is computed on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutputVar {
    /// The terms' shapes (triangles), in order (slow, med, fast) or (neg, Z, pos).
    pub sets: [Shape; 3],
    /// Lower end of the universe.
    pub min: f64,
    /// Upper end of the universe.
    pub max: f64,
    /// Number of evenly spaced grid points from `min` to `max`, both included (at most
    /// [`MAX_GRID_POINTS`]).
    pub points: usize,
    /// The smallest and largest value the centroid can take (the extreme centres).
    pub bounds: (f64, f64),
}

impl OutputVar {
    /// The variable with Table I centres `c` (increasing) on a grid of `points` points: triangles
    /// centred at `c[0]`, `c[1]` and `c[2]`, each reaching 0 at its neighbouring centres, the outer
    /// ones mirrored (half-width `c[1] - c[0]` and `c[2] - c[1]`); the universe spans the outer
    /// triangles' feet.
    pub const fn from_centres(c: [f64; 3], points: usize) -> Self {
        let lo = c[0] - (c[1] - c[0]);
        let hi = c[2] + (c[2] - c[1]);
        OutputVar {
            sets: [
                Shape::Triangle {
                    lo,
                    peak: c[0],
                    hi: c[1],
                },
                Shape::Triangle {
                    lo: c[0],
                    peak: c[1],
                    hi: c[2],
                },
                Shape::Triangle {
                    lo: c[1],
                    peak: c[2],
                    hi,
                },
            ],
            min: lo,
            max: hi,
            points,
            bounds: (c[0], c[2]),
        }
    }

    /// The `i`-th grid point, `(min (points - 1 - i) + max i) / (points - 1)`: the points of
    /// `numpy.linspace(min, max, points)` (to rounding), symmetric about 0 when the universe is.
    pub fn grid_x(&self, i: usize) -> f64 {
        let n = self.points.clamp(2, MAX_GRID_POINTS);
        let i = i.min(n - 1);
        let (a, b) = ((n - 1 - i) as f64, i as f64);
        (self.min * a + self.max * b) / (n - 1) as f64
    }

    /// The aggregated output set at `x`: the maximum over the terms of each term's grade clipped at
    /// its cut (Mamdani min implication, max aggregation).
    pub fn aggregate(&self, cuts: [f64; 3], x: f64) -> f64 {
        let mut y: f64 = 0.0;
        for (set, cut) in self.sets.iter().zip(cuts) {
            y = y.max(set.grade(x).min(cut));
        }
        y
    }

    /// Centroid of the aggregated set with term cuts `cuts` (each in [0, 1], the largest firing
    /// strength of the rules concluding that term), sampled on the grid and taken as piecewise
    /// linear between grid points (the same formula as `skfuzzy.defuzzify.centroid`): each
    /// interval is a trapezoid of area `dx (y1 + y2) / 2` with its centroid at
    /// `x1 + dx (y1 + 2 y2) / (3 (y1 + y2))`. `None` when the aggregate is empty (no rule fired).
    pub fn centroid(&self, cuts: [f64; 3]) -> Option<f64> {
        let cuts = cuts.map(|c| if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) });
        let n = self.points.clamp(2, MAX_GRID_POINTS);
        let mut ys = [0.0; MAX_GRID_POINTS];
        let mut xs = [0.0; MAX_GRID_POINTS];
        for i in 0..n {
            xs[i] = self.grid_x(i);
            ys[i] = self.aggregate(cuts, xs[i]);
        }
        let (mut moment, mut area) = (0.0, 0.0);
        for i in 1..n {
            let (x1, x2, y1, y2) = (xs[i - 1], xs[i], ys[i - 1], ys[i]);
            let sum = y1 + y2;
            if sum <= 0.0 || x2 <= x1 {
                continue;
            }
            let a = 0.5 * (x2 - x1) * sum;
            let c = x1 + (x2 - x1) * (y1 + 2.0 * y2) / (3.0 * sum);
            moment += a * c;
            area += a;
        }
        if area > 0.0 && moment.is_finite() {
            Some((moment / area).clamp(self.bounds.0, self.bounds.1))
        } else {
            None
        }
    }
}

/// `left_obs` and `right_obs`, m: near 5, med 10, far 15 (Table I).
pub const SIDE_OBS: InputVar = InputVar::from_centres([5.0, 10.0, 15.0]);
/// `front_obs`, m: near 10, med 15, far 20 (Table I).
pub const FRONT_OBS: InputVar = InputVar::from_centres([10.0, 15.0, 20.0]);
/// `head_ang`, deg: neg -50, Z 0, pos 50 (Table I). Positive: the target is clockwise of the
/// heading (to the right).
pub const HEAD_ANG: InputVar = InputVar::from_centres([-50.0, 0.0, 50.0]);
/// `velocity_c`, m/s: slow 0.25, med 1.2, fast 2 (Table I), on 211 points from -0.7 to 2.8 m/s
/// (a step of 1/60 m/s, so that 0.25, 1.2 and 2 are grid points).
pub const VELOCITY_C: OutputVar = OutputVar::from_centres([0.25, 1.2, 2.0], 211);
/// `head_c`, deg: neg -10, Z 0, pos 10 (Table I), on 201 points from -20 to 20 deg (a step of
/// 0.2 deg). Positive: turn clockwise (to the right).
pub const HEAD_C: OutputVar = OutputVar::from_centres([-10.0, 0.0, 10.0], 201);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_grades_table() {
        // (x, [near, med, far])
        let cases = [
            (0.0, [1.0, 0.0, 0.0]),
            (5.0, [1.0, 0.0, 0.0]),
            (7.5, [0.5, 0.5, 0.0]),
            (10.0, [0.0, 1.0, 0.0]),
            (12.0, [0.0, 0.6, 0.4]),
            (15.0, [0.0, 0.0, 1.0]),
            (1e9, [0.0, 0.0, 1.0]),
            (f64::INFINITY, [0.0, 0.0, 1.0]),
        ];
        for (x, want) in cases {
            let got = SIDE_OBS.grades(x);
            for k in 0..3 {
                assert!(
                    (got[k] - want[k]).abs() < 1e-12,
                    "side {x}: {got:?} != {want:?}"
                );
            }
        }
    }

    #[test]
    fn front_and_angle_grades_table() {
        let front = [
            (9.0, [1.0, 0.0, 0.0]),
            (11.0, [0.8, 0.2, 0.0]),
            (17.5, [0.0, 0.5, 0.5]),
            (25.0, [0.0, 0.0, 1.0]),
        ];
        for (x, want) in front {
            let got = FRONT_OBS.grades(x);
            for k in 0..3 {
                assert!((got[k] - want[k]).abs() < 1e-12, "front {x}: {got:?}");
            }
        }
        let angle = [
            (-180.0, [1.0, 0.0, 0.0]),
            (-50.0, [1.0, 0.0, 0.0]),
            (-20.0, [0.4, 0.6, 0.0]),
            (0.0, [0.0, 1.0, 0.0]),
            (30.0, [0.0, 0.4, 0.6]),
            (90.0, [0.0, 0.0, 1.0]),
        ];
        for (x, want) in angle {
            let got = HEAD_ANG.grades(x);
            for k in 0..3 {
                assert!((got[k] - want[k]).abs() < 1e-12, "head_ang {x}: {got:?}");
            }
        }
    }

    #[test]
    fn input_grades_sum_to_one() {
        for var in [SIDE_OBS, FRONT_OBS, HEAD_ANG] {
            for k in -400..=400 {
                let x = f64::from(k) * 0.5;
                let s: f64 = var.grades(x).iter().sum();
                assert!((s - 1.0).abs() < 1e-12, "{x}: {s}");
            }
        }
    }

    #[test]
    fn grade_of_nan_is_zero() {
        for set in HEAD_ANG.sets.iter().chain(VELOCITY_C.sets.iter()) {
            assert_eq!(set.grade(f64::NAN), 0.0);
        }
    }

    #[test]
    fn grids_hold_the_centres() {
        for (var, centres) in [(VELOCITY_C, [0.25, 1.2, 2.0]), (HEAD_C, [-10.0, 0.0, 10.0])] {
            assert!(var.points <= MAX_GRID_POINTS);
            for c in centres {
                let hit = (0..var.points).any(|i| (var.grid_x(i) - c).abs() < 1e-9);
                assert!(hit, "{c} is not a grid point");
            }
            assert_eq!(var.grid_x(0), var.min);
            assert_eq!(var.grid_x(var.points - 1), var.max);
        }
    }

    #[test]
    fn single_terms_defuzzify_to_their_centres() {
        // A lone outer term is a symmetric triangle, so its centroid is its centre at any cut; the
        // middle velocity term is asymmetric (0.25..1.2..2): its centroid is (0.25 + 1.2 + 2) / 3.
        let cases = [
            (VELOCITY_C, [1.0, 0.0, 0.0], 0.25),
            (VELOCITY_C, [0.0, 0.0, 0.3], 2.0),
            (VELOCITY_C, [0.0, 1.0, 0.0], (0.25 + 1.2 + 2.0) / 3.0),
            (HEAD_C, [0.7, 0.0, 0.0], -10.0),
            (HEAD_C, [0.0, 0.2, 0.0], 0.0),
            (HEAD_C, [0.0, 0.0, 1.0], 10.0),
            // Equal cuts on neg and pos: the two humps balance at 0 (the dead-ahead split).
            (HEAD_C, [0.5, 0.0, 0.5], 0.0),
        ];
        for (var, cuts, want) in cases {
            let got = var.centroid(cuts);
            assert!(
                got.is_some_and(|g| (g - want).abs() < 1e-9),
                "{cuts:?}: {got:?}, want {want}"
            );
        }
        assert_eq!(HEAD_C.centroid([0.0; 3]), None);
        assert_eq!(HEAD_C.centroid([f64::NAN; 3]), None);
    }
}
