//! Dynamic reference targets (seed 001 §II.D): the targets the fuzzy engine steers to while it
//! passes an obstacle, on the course the vehicle had when it first sensed it.
//!
//! When an obstacle is first sensed at `(x0, y0)` with the vehicle on compass course `psi0`, a
//! virtual path is laid through `(x0, y0)` along `psi0`. Eq. (9) writes it
//! `y = actan(theta0) (x - x0) + y0`; "actan" is read as `tan` and `theta0` as the paper's
//! anticlockwise-from-East angle, `theta0 = 90 deg - psi0`, so the slope is
//! `tan(90 deg - psi0) = cot(psi0)` (see [`Drt::path_north_at`]). The DRT sits on the path
//! [`Drt::step_m`] (15 m) ahead of the origin; each time the vehicle's projection on the path
//! reaches it, it moves another step along. Reaching it with no obstacle in view means the
//! obstacle is passed: the caller resumes what it was doing.

use super::engine::FuzzyInputs;
use plumetrace_core::{Heading, Vec2};

/// The paper's DRT spacing, m.
pub const DRT_STEP_M: f64 = 15.0;

/// What [`Drt::step`] says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DrtStatus {
    /// Steer to this target.
    Target(Vec2),
    /// The target was reached with no obstacle in view: the obstacle is passed.
    Passed,
}

/// A dynamic reference target on its virtual path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drt {
    /// Where the obstacle was first sensed, m.
    pub origin: Vec2,
    /// The vehicle's course then: the direction of the virtual path.
    pub course: Heading,
    /// The current target, m.
    pub target: Vec2,
    /// The distance the target moves along the path each time it is reached, m.
    pub step_m: f64,
}

impl Drt {
    /// A DRT `step_m` ahead of `origin` along `course` (a non-finite or non-positive step is
    /// [`DRT_STEP_M`]).
    pub fn new(origin: Vec2, course: Heading, step_m: f64) -> Self {
        let step_m = if step_m.is_finite() && step_m > 0.0 {
            step_m
        } else {
            DRT_STEP_M
        };
        Drt {
            origin,
            course,
            target: origin + course.unit() * step_m,
            step_m,
        }
    }

    /// Distance of `pos_m`'s projection on the path from the origin, m (negative behind it).
    pub fn along_m(&self, pos_m: Vec2) -> f64 {
        (pos_m - self.origin).dot(&self.course.unit())
    }

    /// Signed distance of `pos_m` from the path, m: positive to the right of the path (clockwise of
    /// the course), like `head_ang`.
    pub fn cross_m(&self, pos_m: Vec2) -> f64 {
        let u = self.course.unit();
        let r = pos_m - self.origin;
        // z of u x r is positive when r is anticlockwise (left) of u.
        -(u.x * r.y - u.y * r.x)
    }

    /// The projection of `pos_m` on the path.
    pub fn projection(&self, pos_m: Vec2) -> Vec2 {
        self.origin + self.course.unit() * self.along_m(pos_m)
    }

    /// Distance of the target from the origin along the path, m.
    pub fn target_along_m(&self) -> f64 {
        self.along_m(self.target)
    }

    /// Whether the projection of `pos_m` on the path has reached the target.
    pub fn reached(&self, pos_m: Vec2) -> bool {
        self.along_m(pos_m) >= self.target_along_m()
    }

    /// Moves the target one step along the path for each time the vehicle at `pos_m` has reached
    /// it (so the target ends up ahead of the projection) and returns it; a non-finite position
    /// changes nothing.
    pub fn update(&mut self, pos_m: Vec2) -> Vec2 {
        let along = self.along_m(pos_m);
        let t = self.target_along_m();
        if along.is_finite() && along >= t {
            let k = ((along - t) / self.step_m).floor() + 1.0;
            self.target = self.origin + self.course.unit() * (t + k * self.step_m);
        }
        self.target
    }

    /// Whether the obstacle is passed: the projection of `pos_m` has reached the target and no
    /// obstacle is in view (`obstacle_in_view` is the caller's judgement, for example
    /// `!inputs.clear_within(10.0)`, see [`Drt::obstacle_in_view`]).
    pub fn passed_obstacle(&self, pos_m: Vec2, obstacle_in_view: bool) -> bool {
        self.reached(pos_m) && !obstacle_in_view
    }

    /// Whether an obstacle is in view for [`Drt::passed_obstacle`]: something in the front group,
    /// or a side group closer than `side_clear_m`.
    pub fn obstacle_in_view(inputs: &FuzzyInputs, side_clear_m: f64) -> bool {
        let s = inputs.sanitized();
        s.front_m < super::engine::NO_OBSTACLE_M
            || s.left_m < side_clear_m
            || s.right_m < side_clear_m
    }

    /// One decision: [`DrtStatus::Passed`] when [`Drt::passed_obstacle`], otherwise the target
    /// after [`Drt::update`].
    pub fn step(&mut self, pos_m: Vec2, obstacle_in_view: bool) -> DrtStatus {
        if self.passed_obstacle(pos_m, obstacle_in_view) {
            DrtStatus::Passed
        } else {
            DrtStatus::Target(self.update(pos_m))
        }
    }

    /// Eq. (9): the northing of the virtual path at easting `east_m`,
    /// `y0 + tan(90 deg - psi0) (x - x0)`; `None` for a course due North or South (a vertical line
    /// in eq. 9's form).
    pub fn path_north_at(&self, east_m: f64) -> Option<f64> {
        let u = self.course.unit();
        if u.x.abs() < 1e-12 {
            return None;
        }
        let theta0 = std::f64::consts::FRAC_PI_2 - self.course.rad();
        Some(self.origin.y + theta0.tan() * (east_m - self.origin.x))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec2, b: Vec2) -> bool {
        (a - b).norm() < 1e-9
    }

    #[test]
    fn target_starts_one_step_ahead_on_the_course() {
        // (origin, course deg, expected target)
        let cases = [
            ((0.0, 0.0), 0.0, (0.0, 15.0)),
            ((10.0, 5.0), 90.0, (25.0, 5.0)),
            ((0.0, 0.0), 180.0, (0.0, -15.0)),
            ((0.0, 0.0), 45.0, (15.0 / 2f64.sqrt(), 15.0 / 2f64.sqrt())),
        ];
        for (o, c, t) in cases {
            let d = Drt::new(Vec2::new(o.0, o.1), Heading::from_deg(c), 15.0);
            assert!(
                close(d.target, Vec2::new(t.0, t.1)),
                "{o:?} {c}: {:?}",
                d.target
            );
        }
    }

    #[test]
    fn target_advances_when_the_projection_reaches_it() {
        let mut d = Drt::new(Vec2::zeros(), Heading::from_deg(90.0), 15.0); // path due East
        // Off the path by 8 m, projection 14 m: not yet.
        assert!(close(d.update(Vec2::new(14.0, 8.0)), Vec2::new(15.0, 0.0)));
        // Projection exactly 15 m: reached, one step on.
        assert!(close(d.update(Vec2::new(15.0, -8.0)), Vec2::new(30.0, 0.0)));
        // Behind the origin: unchanged.
        assert!(close(d.update(Vec2::new(-5.0, 3.0)), Vec2::new(30.0, 0.0)));
        // A jump of 40 m: the target lands ahead of the projection, on the 15 m ladder.
        assert!(close(d.update(Vec2::new(70.0, 0.0)), Vec2::new(75.0, 0.0)));
        assert!(close(
            d.update(Vec2::new(f64::NAN, 0.0)),
            Vec2::new(75.0, 0.0)
        ));
    }

    #[test]
    fn passed_only_when_reached_and_clear() {
        let mut d = Drt::new(Vec2::zeros(), Heading::NORTH, 15.0);
        assert!(!d.passed_obstacle(Vec2::new(3.0, 16.0), true));
        assert!(d.passed_obstacle(Vec2::new(3.0, 16.0), false));
        assert!(!d.passed_obstacle(Vec2::new(3.0, 10.0), false));
        assert_eq!(
            d.step(Vec2::new(3.0, 16.0), true),
            DrtStatus::Target(Vec2::new(0.0, 30.0))
        );
        assert_eq!(d.step(Vec2::new(3.0, 31.0), false), DrtStatus::Passed);
    }

    #[test]
    fn cross_track_is_positive_to_the_right() {
        let d = Drt::new(Vec2::zeros(), Heading::NORTH, 15.0);
        assert!((d.cross_m(Vec2::new(4.0, 1.0)) - 4.0).abs() < 1e-12);
        assert!((d.cross_m(Vec2::new(-2.0, 1.0)) + 2.0).abs() < 1e-12);
        assert!(close(
            d.projection(Vec2::new(-2.0, 7.0)),
            Vec2::new(0.0, 7.0)
        ));
    }

    #[test]
    fn eq_9_holds_on_the_path() {
        for course in [30.0, 90.0, 135.0, 250.0, 300.0] {
            let d = Drt::new(Vec2::new(3.0, -4.0), Heading::from_deg(course), 15.0);
            for k in 1..4 {
                let p = d.origin + d.course.unit() * (7.0 * f64::from(k));
                let y = d.path_north_at(p.x);
                assert!(
                    y.is_some_and(|y| (y - p.y).abs() < 1e-9),
                    "{course}: {y:?} vs {}",
                    p.y
                );
            }
        }
        let north = Drt::new(Vec2::zeros(), Heading::from_deg(180.0), 15.0);
        assert_eq!(north.path_north_at(1.0), None);
    }

    #[test]
    fn obstacle_in_view_table() {
        let i = |l: f64, f: f64, r: f64| FuzzyInputs {
            left_m: l,
            front_m: f,
            right_m: r,
            head_ang_deg: 0.0,
        };
        let inf = f64::INFINITY;
        assert!(!Drt::obstacle_in_view(&i(inf, inf, inf), 10.0));
        assert!(!Drt::obstacle_in_view(&i(12.0, inf, f64::NAN), 10.0));
        assert!(Drt::obstacle_in_view(&i(inf, 19.0, inf), 10.0));
        assert!(Drt::obstacle_in_view(&i(inf, inf, 9.0), 10.0));
    }
}
