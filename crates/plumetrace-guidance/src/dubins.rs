//! Go To Point With Heading: the shortest CSC Dubins path, followed by pursuit.
//!
//! The path geometry comes from the `dubins_paths` crate, restricted to the four CSC words (LSL,
//! LSR, RSL, RSR) as on the field vehicle. That crate measures angles anticlockwise from East;
//! compass headings are converted at this module's boundary and nowhere else. The frame's axes
//! are the same (x East, y North), so a left turn is a left turn in both.

use crate::{DoneReason, ModeStatus, Steer};
use dubins_paths::PathType;
use dubins_paths::f64::{DubinsPath, PosRot};
use plumetrace_core::{Heading, Vec2, bearing_between};
use std::collections::VecDeque;
use std::f64::consts::FRAC_PI_2;

/// A position and a compass heading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// `(east, north)`, m.
    pub pos_m: Vec2,
    /// Compass heading.
    pub heading: Heading,
}

impl Pose {
    fn to_posrot(self) -> PosRot {
        PosRot::from_floats(self.pos_m.x, self.pos_m.y, FRAC_PI_2 - self.heading.rad())
    }

    fn from_posrot(q: PosRot) -> Self {
        Pose {
            pos_m: Vec2::new(q.x(), q.y()),
            heading: Heading::from_rad(FRAC_PI_2 - q.rot()),
        }
    }
}

/// The four turn-straight-turn words.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CscWord {
    /// Left, straight, left.
    Lsl,
    /// Left, straight, right.
    Lsr,
    /// Right, straight, left.
    Rsl,
    /// Right, straight, right.
    Rsr,
}

impl CscWord {
    /// All four words.
    pub const ALL: [CscWord; 4] = [CscWord::Lsl, CscWord::Lsr, CscWord::Rsl, CscWord::Rsr];

    fn path_type(self) -> PathType {
        match self {
            CscWord::Lsl => PathType::LSL,
            CscWord::Lsr => PathType::LSR,
            CscWord::Rsl => PathType::RSL,
            CscWord::Rsr => PathType::RSR,
        }
    }

    fn from_path_type(t: PathType) -> Option<Self> {
        match t {
            PathType::LSL => Some(CscWord::Lsl),
            PathType::LSR => Some(CscWord::Lsr),
            PathType::RSL => Some(CscWord::Rsl),
            PathType::RSR => Some(CscWord::Rsr),
            PathType::RLR | PathType::LRL => None,
        }
    }
}

/// A CSC path from one pose to another with a minimum turning radius.
#[derive(Debug, Clone, Copy)]
pub struct CscPath {
    inner: DubinsPath,
    word: CscWord,
}

impl CscPath {
    /// The path of one word, if that word connects the poses (LSR and RSL do not always).
    pub fn new(start: Pose, end: Pose, radius_m: f64, word: CscWord) -> Option<Self> {
        if !(radius_m.is_finite() && radius_m > 0.0) {
            return None;
        }
        let inner = DubinsPath::new(
            start.to_posrot(),
            end.to_posrot(),
            radius_m,
            word.path_type(),
        )
        .ok()?;
        inner
            .length()
            .is_finite()
            .then_some(CscPath { inner, word })
    }

    /// The word.
    pub fn word(&self) -> CscWord {
        self.word
    }

    /// Total length, m.
    pub fn length_m(&self) -> f64 {
        self.inner.length()
    }

    /// Lengths of the turn, straight and turn segments, m.
    pub fn segment_lengths_m(&self) -> [f64; 3] {
        [0, 1, 2].map(|i| self.inner.segment_length(i))
    }

    /// The turning radius, m.
    pub fn radius_m(&self) -> f64 {
        self.inner.rho
    }

    /// The pose `s_m` metres along the path (clamped to the path).
    pub fn sample(&self, s_m: f64) -> Pose {
        Pose::from_posrot(self.inner.sample(s_m.clamp(0.0, self.length_m())))
    }
}

/// The four CSC candidates that exist between two poses.
pub fn csc_candidates(start: Pose, end: Pose, radius_m: f64) -> Vec<CscPath> {
    CscWord::ALL
        .iter()
        .filter_map(|&w| CscPath::new(start, end, radius_m, w))
        .collect()
}

/// The shortest CSC path between two poses; `None` for a non-positive radius or non-finite poses.
pub fn shortest_csc(start: Pose, end: Pose, radius_m: f64) -> Option<CscPath> {
    if !(radius_m.is_finite() && radius_m > 0.0) {
        return None;
    }
    let inner =
        DubinsPath::shortest_in(start.to_posrot(), end.to_posrot(), radius_m, &PathType::CSC)
            .ok()?;
    let word = CscWord::from_path_type(inner.path_type)?;
    inner
        .length()
        .is_finite()
        .then_some(CscPath { inner, word })
}

/// Spacing of the points the pursuit follows, m.
const SAMPLE_STEP_M: f64 = 0.5;

/// The sample of `path` nearest `pos`, among those every [`SAMPLE_STEP_M`] from `progress_m`
/// over `window_m` (clamped to the path's end): `(distance along, distance away)`. The samples'
/// positions come from `samples` where it holds them (see [`PathSamples`]).
///
/// Every fourth sample first, then the samples around the nearest of those: the same sample as
/// scanning them all wherever the distance has one minimum in the window (the path does not
/// come back near `pos` within the window), for about a third of the samples.
fn nearest_sample(
    path: &CscPath,
    progress_m: f64,
    window_m: f64,
    pos: Vec2,
    samples: &mut PathSamples,
) -> (f64, f64) {
    const COARSE: usize = 4;
    let len = path.length_m();
    let steps = (window_m / SAMPLE_STEP_M).ceil() as usize;
    let first = PathSamples::index_of(progress_m);
    let mut at = |k: usize| {
        let s_m = (progress_m + k as f64 * SAMPLE_STEP_M).min(len);
        // Below the end, `s_m` is sample `first + k`'s distance along, exactly.
        let p = match first {
            Some(n) if s_m < len => samples.position(path, n + k as u64),
            _ => path.sample(s_m).pos_m,
        };
        (s_m, (p - pos).norm())
    };
    let (kc, _) = first_nearest(
        (0..=steps).step_by(COARSE).chain([steps]),
        progress_m,
        &mut at,
    );
    let lo = kc.saturating_sub(COARSE - 1);
    let hi = (kc + COARSE - 1).min(steps);
    first_nearest(lo..=hi, progress_m, &mut at).1
}

/// The first strictly nearest of the samples `ks` (`at(k)`: distance along, distance away), as
/// a scan in order finds it; `(0, (progress_m, inf))` if none is nearer than infinity.
fn first_nearest(
    ks: impl Iterator<Item = usize>,
    progress_m: f64,
    at: &mut impl FnMut(usize) -> (f64, f64),
) -> (usize, (f64, f64)) {
    ks.map(|k| (k, at(k)))
        .fold((0, (progress_m, f64::INFINITY)), |best, c| {
            if c.1.1 < best.1.1 { c } else { best }
        })
}

/// The positions of a path's samples `n` (at `n` [`SAMPLE_STEP_M`] along it) from `first` on,
/// each worked out once, when a search first reads it, while the path is followed: the
/// nearest-sample search of successive decisions reads nearly the same window of samples (a
/// vehicle at 2 m/s deciding at 10 Hz moves 0.4 samples a decision), so a decision works out
/// about one new sample instead of about 30. A position is the one [`CscPath::sample`] gives at
/// that distance, bit for bit.
#[derive(Debug, Clone, Default)]
struct PathSamples {
    first: u64,
    positions: VecDeque<Option<Vec2>>,
}

impl PathSamples {
    /// The sample whose distance along is `s_m`, if `s_m` is a whole number of samples (below
    /// 2^50 of them, so every sum of such distances is exact).
    fn index_of(s_m: f64) -> Option<u64> {
        let n = s_m / SAMPLE_STEP_M;
        (n >= 0.0 && n < (1u64 << 50) as f64 && n.fract() == 0.0).then_some(n as u64)
    }

    /// Sample `n`'s position on `path`.
    fn position(&mut self, path: &CscPath, n: u64) -> Vec2 {
        let at = |n: u64| path.sample(n as f64 * SAMPLE_STEP_M).pos_m;
        if n < self.first {
            return at(n);
        }
        let k = (n - self.first) as usize;
        if self.positions.len() <= k {
            self.positions.resize(k + 1, None);
        }
        *self.positions[k].get_or_insert_with(|| at(n))
    }

    /// Forgets the samples before `n` (the search never goes back).
    fn forget_before(&mut self, n: u64) {
        let behind = n
            .saturating_sub(self.first)
            .min(self.positions.len() as u64);
        self.positions.drain(..behind as usize);
        self.first = self.first.max(n);
    }

    /// Forgets every sample (a new path).
    fn clear(&mut self) {
        self.first = 0;
        self.positions.clear();
    }
}

/// Drive to a position with a given heading on arrival, along the shortest CSC path with the
/// minimum turning radius, followed by pursuit of a point a look-ahead distance along the path.
/// The path is planned from the vehicle's pose on the first decision and planned again when a
/// navigation fix puts the vehicle more than `replan_offtrack_m` from it or when the vehicle runs
/// off its end without arriving. A path that has to be planned again more than `max_replans`
/// times cannot be flown from where the vehicle keeps ending up (its turns lie beyond the cage,
/// or the current carries the vehicle off them): the mode then ends with
/// [`DoneReason::GaveUp`] rather than circle for good.
#[derive(Debug, Clone)]
pub struct GoToPointWithHeading {
    /// Destination pose.
    pub target: Pose,
    /// Speed command, m/s.
    pub speed_mps: f64,
    /// Arrival radius `R`, m.
    pub radius_m: f64,
    /// Arrival heading tolerance, degrees (15 on the field vehicle).
    pub heading_tolerance_deg: f64,
    /// Minimum turning radius `R_m`, m.
    pub min_turn_radius_m: f64,
    /// Pursuit look-ahead along the path, m.
    pub lookahead_m: f64,
    /// Distance from the path beyond which it is planned again, m.
    pub replan_offtrack_m: f64,
    /// Re-plans (after the first path) before the mode gives up; `u32::MAX`: never.
    pub max_replans: u32,
    plan: Option<CscPath>,
    /// Distance along the path of the point nearest the vehicle, m.
    progress_m: f64,
    plans: u32,
    /// The positions of the path's samples the search reads.
    samples: PathSamples,
}

impl GoToPointWithHeading {
    /// A mode with the look-ahead at half the turning radius, replanning beyond one radius, and
    /// giving up after [`GoToPointWithHeading::MAX_REPLANS`] re-plans.
    pub fn new(target: Pose, speed_mps: f64, radius_m: f64, min_turn_radius_m: f64) -> Self {
        GoToPointWithHeading {
            target,
            speed_mps,
            radius_m,
            heading_tolerance_deg: 15.0,
            min_turn_radius_m,
            lookahead_m: 0.5 * min_turn_radius_m,
            replan_offtrack_m: min_turn_radius_m.max(radius_m),
            max_replans: Self::MAX_REPLANS,
            plan: None,
            progress_m: 0.0,
            plans: 0,
            samples: PathSamples::default(),
        }
    }

    /// Re-plans allowed by default. A path flown as planned needs none; a navigation fix that
    /// moves the estimate off it, one or two.
    pub const MAX_REPLANS: u32 = 4;

    /// The path being followed, if planned.
    pub fn path(&self) -> Option<&CscPath> {
        self.plan.as_ref()
    }

    /// How many times a path was planned.
    pub fn plans(&self) -> u32 {
        self.plans
    }

    fn replan(&mut self, pose: Pose) {
        self.plan = shortest_csc(pose, self.target, self.min_turn_radius_m);
        self.progress_m = 0.0;
        self.plans += 1;
        self.samples.clear();
    }

    /// The mode's decision at the vehicle's estimated pose.
    pub fn update(&mut self, pose: Pose) -> ModeStatus {
        let to_go = (self.target.pos_m - pose.pos_m).norm();
        if to_go < self.radius_m
            && pose.heading.diff_deg(self.target.heading).abs() < self.heading_tolerance_deg
        {
            return ModeStatus::Done(DoneReason::ArrivedWithHeading);
        }
        let mut need_plan = true;
        if let Some(path) = &self.plan {
            // Nearest point within a window ahead of the progress so far (the window keeps it from
            // jumping to a later part of the path that passes close by); cost is constant.
            let window = 4.0 * self.min_turn_radius_m.max(self.radius_m);
            let (best_s, best_d) =
                nearest_sample(path, self.progress_m, window, pose.pos_m, &mut self.samples);
            let len = path.length_m();
            self.progress_m = best_s;
            if let Some(n) = PathSamples::index_of(best_s) {
                self.samples.forget_before(n);
            }
            need_plan = best_d > self.replan_offtrack_m || best_s >= len - SAMPLE_STEP_M;
        }
        if need_plan {
            if self.plans > self.max_replans {
                return ModeStatus::Done(DoneReason::GaveUp);
            }
            self.replan(pose);
        }
        let heading = match &self.plan {
            Some(path) => {
                let aim = path.sample(self.progress_m + self.lookahead_m);
                bearing_between(pose.pos_m, aim.pos_m).unwrap_or(aim.heading)
            }
            // No path (degenerate input): head straight for the target.
            None => bearing_between(pose.pos_m, self.target.pos_m).unwrap_or(self.target.heading),
        };
        ModeStatus::Running(Steer {
            heading,
            speed_mps: self.speed_mps,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_coarse_then_fine_search_finds_the_nearest_sample_of_a_full_scan() {
        // Vehicles off an LSR-like path by up to a turning radius, at every stage of it: the
        // sample found is the one a scan of every sample finds.
        let path = shortest_csc(pose(0.0, 0.0, 0.0), pose(60.0, 40.0, 180.0), 10.0)
            .unwrap_or_else(|| panic!("no path"));
        let len = path.length_m();
        let window = 40.0;
        let mut checked = 0;
        for i in 0..200 {
            let progress = len * f64::from(i) / 200.0;
            let on = path.sample((progress + 3.0).min(len)).pos_m;
            for (dx, dy) in [
                (0.0, 0.0),
                (4.0, -3.0),
                (-7.0, 2.0),
                (1.0, 9.0),
                (-9.5, -0.5),
            ] {
                let p = Vec2::new(on.x + dx, on.y + dy);
                let steps = (window / SAMPLE_STEP_M).ceil() as usize;
                let full = (0..=steps)
                    .map(|k| (progress + k as f64 * SAMPLE_STEP_M).min(len))
                    .map(|s| (s, (path.sample(s).pos_m - p).norm()))
                    .fold(
                        (progress, f64::INFINITY),
                        |b, c| if c.1 < b.1 { c } else { b },
                    );
                let mut samples = PathSamples::default();
                let found = nearest_sample(&path, progress, window, p, &mut samples);
                assert_eq!(found, full, "at {p:?}");
                checked += 1;
            }
        }
        assert_eq!(checked, 1000);
    }

    #[test]
    fn samples_kept_between_searches_are_the_ones_worked_out_afresh() {
        // Progress on whole samples, moving ahead (as decisions move it), standing still and
        // going back; one store of samples across the searches, forgetting those behind as a
        // mode does: every search finds what it finds with a fresh store, bit for bit, and the
        // store holds no sample it did not need.
        let path = shortest_csc(pose(5.0, -3.0, 40.0), pose(-50.0, 70.0, 250.0), 12.0)
            .unwrap_or_else(|| panic!("no path"));
        let len = path.length_m();
        let window = 48.0;
        let mut samples = PathSamples::default();
        let mut n = 0u64;
        let mut searched = 0;
        for step in 0..400u64 {
            // Ahead by 0-2 samples, and back by 3 every 50th search.
            n = if step % 50 == 49 {
                n.saturating_sub(3)
            } else {
                n + step % 3
            };
            let progress = n as f64 * SAMPLE_STEP_M;
            if progress >= len {
                break;
            }
            let on = path.sample((progress + 2.0).min(len)).pos_m;
            let p = Vec2::new(on.x + 3.0, on.y - 2.0);
            let kept = nearest_sample(&path, progress, window, p, &mut samples);
            let fresh = nearest_sample(&path, progress, window, p, &mut PathSamples::default());
            assert_eq!(kept.0.to_bits(), fresh.0.to_bits(), "step {step}");
            assert_eq!(kept.1.to_bits(), fresh.1.to_bits(), "step {step}");
            let held = samples.positions.len() as f64;
            // The window's samples from the last index forgotten (at most 2 behind this search).
            assert!(held <= window / SAMPLE_STEP_M + 3.0, "{held} samples held");
            if let Some(k) = PathSamples::index_of(kept.0) {
                samples.forget_before(k);
            }
            searched += 1;
        }
        assert!(searched > 200, "{searched} searches");
        // A distance along that is not a whole number of samples has no index.
        assert_eq!(PathSamples::index_of(3.5), Some(7));
        assert_eq!(PathSamples::index_of(3.25), None);
        assert_eq!(PathSamples::index_of(-0.5), None);
        assert_eq!(PathSamples::index_of(f64::NAN), None);
    }

    fn pose(x: f64, y: f64, h: f64) -> Pose {
        Pose {
            pos_m: Vec2::new(x, y),
            heading: Heading::from_deg(h),
        }
    }

    #[test]
    fn straight_ahead_is_a_straight_path() {
        let p = shortest_csc(pose(0.0, 0.0, 0.0), pose(0.0, 100.0, 0.0), 10.0).unwrap();
        assert!((p.length_m() - 100.0).abs() < 1e-6, "{}", p.length_m());
        let mid = p.sample(50.0);
        assert!(
            (mid.pos_m - Vec2::new(0.0, 50.0)).norm() < 1e-6
                && mid.heading.diff_deg(Heading::NORTH).abs() < 1e-6
        );
    }

    #[test]
    fn u_turn_is_a_half_circle_and_turn_directions_match_compass() {
        // Heading North, end 20 m East heading South with R = 10: a right (clockwise) half circle.
        let p = shortest_csc(pose(0.0, 0.0, 0.0), pose(20.0, 0.0, 180.0), 10.0).unwrap();
        assert!(
            (p.length_m() - std::f64::consts::PI * 10.0).abs() < 1e-6,
            "{}",
            p.length_m()
        );
        assert!(
            matches!(p.word(), CscWord::Rsr | CscWord::Rsl | CscWord::Lsr),
            "{:?}",
            p.word()
        );
        let q = p.sample(0.5 * p.length_m());
        assert!(
            (q.pos_m - Vec2::new(10.0, 10.0)).norm() < 1e-6
                && q.heading.diff_deg(Heading::from_deg(90.0)).abs() < 1e-6,
            "{q:?}"
        );
    }

    #[test]
    fn degenerate_radius_gives_no_path() {
        assert!(shortest_csc(pose(0.0, 0.0, 0.0), pose(5.0, 5.0, 0.0), 0.0).is_none());
        assert!(shortest_csc(pose(0.0, 0.0, 0.0), pose(5.0, 5.0, 0.0), f64::NAN).is_none());
    }
}
