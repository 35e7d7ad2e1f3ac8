//! Flow compensation (eq. 1-3): the water-relative command that keeps the ground track on course.

use plumetrace_core::{Heading, Vec2};

/// The water-relative heading and speed to command so that the ground track follows a course.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlowCompensation {
    /// Heading to command (through the water).
    pub heading: Heading,
    /// Water-relative speed to command, m/s.
    pub speed_mps: f64,
    /// Resulting speed over ground along the course, m/s (negative: pushed backwards).
    pub ground_speed_mps: f64,
    /// False when the current is too strong: its cross-course part exceeds the vehicle's speed,
    /// or the vehicle cannot make headway along the course. The heading is then the best effort
    /// (all speed spent against the cross-course current, or straight along the course).
    pub feasible: bool,
}

/// Solves for a water-relative velocity `w` with `|w| = speed_mps` such that `w + flow` points
/// along `course` (the crab angle). Non-finite flows are treated as zero and reported infeasible.
pub fn compensate_flow(course: Heading, speed_mps: f64, flow_mps: Vec2) -> FlowCompensation {
    let d = course.unit();
    let speed = if speed_mps.is_finite() {
        speed_mps.max(0.0)
    } else {
        0.0
    };
    if !(flow_mps.x.is_finite() && flow_mps.y.is_finite()) {
        return FlowCompensation {
            heading: course,
            speed_mps: speed,
            ground_speed_mps: speed,
            feasible: false,
        };
    }
    let along = flow_mps.dot(&d);
    let cross = flow_mps - d * along;
    let cross_mag = cross.norm();
    if cross_mag > speed {
        // Cannot cancel the cross-course current: fight it with everything.
        let heading = Heading::of_vector(-cross).unwrap_or(course);
        return FlowCompensation {
            heading,
            speed_mps: speed,
            ground_speed_mps: along,
            feasible: false,
        };
    }
    let w_along = (speed * speed - cross_mag * cross_mag).sqrt();
    let w = d * w_along - cross;
    let heading = Heading::of_vector(w).unwrap_or(course);
    let ground = w_along + along;
    FlowCompensation {
        heading,
        speed_mps: speed,
        ground_speed_mps: ground,
        feasible: ground > 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crab_angle_table() {
        // (course, speed, flow east, flow north) -> (heading, ground speed, feasible)
        let cases = [
            (0.0, 2.0, 0.0, 0.0, 0.0, 2.0, true),
            (0.0, 2.0, 0.0, 0.5, 0.0, 2.5, true),
            (0.0, 2.0, 0.0, -0.5, 0.0, 1.5, true),
            (0.0, 2.0, 1.0, 0.0, 330.0, 3f64.sqrt(), true),
            (90.0, 2.0, 0.0, 1.0, 120.0, 3f64.sqrt(), true),
            (0.0, 1.0, 2.0, 0.0, 270.0, 0.0, false),
            (0.0, 1.0, 0.0, -2.0, 0.0, -1.0, false),
        ];
        for (course, speed, fe, fn_, want_h, want_g, feasible) in cases {
            let c = compensate_flow(Heading::from_deg(course), speed, Vec2::new(fe, fn_));
            assert!(
                c.heading.diff_deg(Heading::from_deg(want_h)).abs() < 1e-9,
                "course {course} flow ({fe},{fn_}): heading {}",
                c.heading.deg()
            );
            assert!(
                (c.ground_speed_mps - want_g).abs() < 1e-9,
                "ground {}",
                c.ground_speed_mps
            );
            assert_eq!(c.feasible, feasible);
            if feasible {
                // The resulting ground velocity points along the course.
                let g = c.heading.unit() * c.speed_mps + Vec2::new(fe, fn_);
                assert!(
                    Heading::of_vector(g)
                        .unwrap()
                        .diff_deg(Heading::from_deg(course))
                        .abs()
                        < 1e-9
                );
            }
        }
        assert!(!compensate_flow(Heading::NORTH, 2.0, Vec2::new(f64::NAN, 0.0)).feasible);
    }
}
