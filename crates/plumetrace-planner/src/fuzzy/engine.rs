//! The stateless Mamdani engine: fuzzify the inputs, fire the rules (min for AND), aggregate
//! each output term (max), defuzzify (centroid on the output's grid).

use super::membership::{FRONT_OBS, HEAD_ANG, HEAD_C, SIDE_OBS, VELOCITY_C};
use super::rules::{RULES, Rule};
use plumetrace_core::{Heading, RangeReturn, Vec2, bearing_between, wrap_deg_180};

/// The largest distance input kept, m: any larger (or infinite, or NaN) distance is "no obstacle"
/// and is fully far for every distance variable.
pub const NO_OBSTACLE_M: f64 = 1.0e6;

/// The engine's inputs: obstacle distances in the three sensor groups and the angle to the target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FuzzyInputs {
    /// `left_obs`: nearest obstacle in the left group, m (infinite: none within range).
    pub left_m: f64,
    /// `front_obs`: nearest obstacle in the front group (-30..30 deg about the heading), m.
    pub front_m: f64,
    /// `right_obs`: nearest obstacle in the right group, m.
    pub right_m: f64,
    /// `head_ang`: the signed angle from the heading to the bearing of the target, deg, wrapped
    /// to (-180, 180]; positive when the target is clockwise of the heading (to the right).
    pub head_ang_deg: f64,
}

impl FuzzyInputs {
    /// Inputs from the range sensors' nearest returns; a group that sees nothing within range
    /// (`None`) is "no obstacle", fully far.
    pub fn from_ranges(ranges: &RangeReturn, head_ang_deg: f64) -> Self {
        let d = |r: Option<f64>| r.unwrap_or(f64::INFINITY);
        FuzzyInputs {
            left_m: d(ranges.left_m),
            front_m: d(ranges.front_m),
            right_m: d(ranges.right_m),
            head_ang_deg,
        }
    }

    /// The inputs the engine uses: a NaN or infinite distance is "no obstacle"
    /// ([`NO_OBSTACLE_M`]), a negative one is 0 (touching); a non-finite angle is 0 (no
    /// preference: the target is taken to be ahead) and a finite one is wrapped to (-180, 180].
    pub fn sanitized(&self) -> Self {
        let d = |x: f64| {
            if x.is_nan() {
                NO_OBSTACLE_M
            } else {
                x.clamp(0.0, NO_OBSTACLE_M)
            }
        };
        let a = if self.head_ang_deg.is_finite() {
            wrap_deg_180(self.head_ang_deg)
        } else {
            0.0
        };
        FuzzyInputs {
            left_m: d(self.left_m),
            front_m: d(self.front_m),
            right_m: d(self.right_m),
            head_ang_deg: a,
        }
    }

    /// Whether no group sees an obstacle closer than `m` metres.
    pub fn clear_within(&self, m: f64) -> bool {
        let s = self.sanitized();
        s.left_m >= m && s.front_m >= m && s.right_m >= m
    }
}

/// `head_ang` for a vehicle at `pos_m` on `heading` and a target at `target_m`: the bearing of the
/// target minus the heading, deg, in (-180, 180], positive when the target is to the right; 0 when
/// the two points coincide.
pub fn head_ang_deg(pos_m: Vec2, heading: Heading, target_m: Vec2) -> f64 {
    bearing_between(pos_m, target_m).map_or(0.0, |b| b.diff_deg(heading))
}

/// The grades of the four inputs in their three terms each: `[near, med, far]` for distances,
/// `[neg, Z, pos]` for `head_ang`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grades {
    /// `left_obs`.
    pub left: [f64; 3],
    /// `front_obs`.
    pub front: [f64; 3],
    /// `right_obs`.
    pub right: [f64; 3],
    /// `head_ang`.
    pub head_ang: [f64; 3],
}

/// Fuzzifies the (sanitized) inputs with the Table I membership functions.
pub fn fuzzify(inputs: &FuzzyInputs) -> Grades {
    let s = inputs.sanitized();
    Grades {
        left: SIDE_OBS.grades(s.left_m),
        front: FRONT_OBS.grades(s.front_m),
        right: SIDE_OBS.grades(s.right_m),
        head_ang: HEAD_ANG.grades(s.head_ang_deg),
    }
}

/// The firing strength of `rule`: the minimum of its antecedents' grades (an "any" antecedent is
/// left out; a rule without antecedents fires with strength 1).
pub fn strength(rule: &Rule, g: &Grades) -> f64 {
    let mut w: f64 = 1.0;
    if let Some(t) = rule.left {
        w = w.min(g.left[t.index()]);
    }
    if let Some(t) = rule.front {
        w = w.min(g.front[t.index()]);
    }
    if let Some(t) = rule.right {
        w = w.min(g.right[t.index()]);
    }
    if let Some(t) = rule.head_ang {
        w = w.min(g.head_ang[t.index()]);
    }
    w
}

/// The cut of every output term: the largest strength of the rules that conclude it (max
/// aggregation of the min-clipped sets).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Cuts {
    /// `velocity_c`: `[slow, med, fast]`.
    pub velocity_c: [f64; 3],
    /// `head_c`: `[neg, Z, pos]`.
    pub head_c: [f64; 3],
}

/// Fires `rules` on `inputs`.
pub fn fire(rules: &[Rule], inputs: &FuzzyInputs) -> Cuts {
    let g = fuzzify(inputs);
    let mut c = Cuts::default();
    for r in rules {
        let w = strength(r, &g);
        let v = &mut c.velocity_c[r.velocity_c.index()];
        *v = v.max(w);
        let t = &mut c.head_c[r.head_c.index()];
        *t = t.max(w);
    }
    c
}

/// The engine's command.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FuzzyOutput {
    /// `velocity_c`: commanded speed, m/s, in [0.25, 2].
    pub speed_mps: f64,
    /// `head_c`: heading change, deg, in [-10, 10]; positive turns clockwise (right).
    pub turn_deg: f64,
}

/// The output of an output variable whose rules do not fire at all: keep the heading at medium
/// speed. [`RULES`] fires for every input, so this is only reached with other rule bases (or
/// masked cuts).
pub const NOTHING_FIRED: FuzzyOutput = FuzzyOutput {
    speed_mps: 1.2,
    turn_deg: 0.0,
};

/// Defuzzifies cuts: the centroid of each output's aggregate, or [`NOTHING_FIRED`]'s value for
/// an output with no term above 0.
pub fn defuzzify(cuts: &Cuts) -> FuzzyOutput {
    FuzzyOutput {
        speed_mps: VELOCITY_C
            .centroid(cuts.velocity_c)
            .unwrap_or(NOTHING_FIRED.speed_mps),
        turn_deg: HEAD_C
            .centroid(cuts.head_c)
            .unwrap_or(NOTHING_FIRED.turn_deg),
    }
}

/// The command of the rule base [`RULES`] for `inputs` (stateless; with an obstacle dead ahead
/// and the target ahead both turns fire and cancel: use [`crate::fuzzy::Avoider`] to steer).
pub fn infer(inputs: &FuzzyInputs) -> FuzzyOutput {
    infer_with(&RULES, inputs)
}

/// The command of any rule base for `inputs`.
pub fn infer_with(rules: &[Rule], inputs: &FuzzyInputs) -> FuzzyOutput {
    defuzzify(&fire(rules, inputs))
}
