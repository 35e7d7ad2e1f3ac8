//! Go To Point (eq. 4-6): head for a destination, done within a radius.

use crate::{DoneReason, ModeStatus, Steer};
use plumetrace_core::{Heading, Vec2, bearing_between};

/// Drive to a point without regard to the heading on arrival. It recomputes the bearing from the
/// current position estimate at every decision, so navigation fixes and turning limits only
/// bend the path; it is the most robust mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GoToPoint {
    /// Destination `(east, north)`, m.
    pub target_m: Vec2,
    /// Constant speed command (eq. 5), m/s.
    pub speed_mps: f64,
    /// Arrival radius `R` (eq. 6), m.
    pub radius_m: f64,
}

impl GoToPoint {
    /// The mode's decision at estimated position `pos_m`.
    pub fn update(&self, pos_m: Vec2) -> ModeStatus {
        let to_go = (self.target_m - pos_m).norm();
        if to_go < self.radius_m {
            return ModeStatus::Done(DoneReason::Arrived);
        }
        // Non-finite positions have no bearing; hold North rather than emit NaN.
        let heading = bearing_between(pos_m, self.target_m).unwrap_or(Heading::NORTH);
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
    fn heading_table() {
        let g = GoToPoint {
            target_m: Vec2::new(100.0, 100.0),
            speed_mps: 2.0,
            radius_m: 10.0,
        };
        let cases = [
            ((100.0, 0.0), 0.0),
            ((0.0, 100.0), 90.0),
            ((200.0, 200.0), 225.0),
            ((100.0, 200.0), 180.0),
            ((200.0, 100.0), 270.0),
        ];
        for ((x, y), want) in cases {
            match g.update(Vec2::new(x, y)) {
                ModeStatus::Running(s) => {
                    assert!(
                        s.heading.diff_deg(Heading::from_deg(want)).abs() < 1e-9,
                        "from ({x},{y}): {}",
                        s.heading.deg()
                    );
                    assert_eq!(s.speed_mps, 2.0);
                }
                other => panic!("from ({x},{y}): {other:?}"),
            }
        }
        assert_eq!(
            g.update(Vec2::new(95.0, 95.0)),
            ModeStatus::Done(DoneReason::Arrived)
        );
        assert!(
            matches!(g.update(Vec2::new(100.0, 110.0)), ModeStatus::Running(_)),
            "exactly R away is not arrived"
        );
    }
}
