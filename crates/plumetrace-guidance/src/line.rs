//! Follow Line (eq. 7-10): approach the start with the line's heading, then hold the line.

use crate::dubins::{GoToPointWithHeading, Pose};
use crate::geometry::{along_track_m, signed_cross_track_m};
use crate::{DoneReason, ModeStatus, Steer};
use plumetrace_core::{Heading, Vec2, bearing_between};

/// Where a Follow Line mode is.
#[derive(Debug, Clone)]
pub enum FollowLinePhase {
    /// Driving to the start of the line with its heading (Go To Point With Heading).
    Approach(Box<GoToPointWithHeading>),
    /// Holding the line with the cross-track law of eq. 8.
    Tracking,
}

/// Follow the segment from `start_m` to `end_m`.
///
/// On the line the heading command is `alpha + K d` when `|d| < d1 = 45 / K` and
/// `alpha + sign(d) 45` beyond, with `alpha` the compass bearing of the line and `d` the signed
/// cross-track distance (positive left of the line, so adding it turns clockwise, back towards
/// the line). The mode ends within `radius_m` of the end (eq. 6) or once more than `pass_m` past
/// it along the line (eq. 10), which catches navigation fixes that jump over the end.
///
/// An approach that gives up ([`DoneReason::GaveUp`]: the Dubins path to the start could not be
/// flown, e.g. with its turns beyond the cage near an edge) hands over to the cross-track law
/// from wherever the vehicle is: it joins the line at up to 45 deg and holds it to the end.
#[derive(Debug, Clone)]
pub struct FollowLine {
    /// Start of the line.
    pub start_m: Vec2,
    /// End of the line.
    pub end_m: Vec2,
    /// Speed command, m/s.
    pub speed_mps: f64,
    /// Arrival radius `R`, m (also the approach radius at the start).
    pub radius_m: f64,
    /// `R_L`: distance past the end (along the line) that ends the mode, m.
    pub pass_m: f64,
    /// Cross-track gain `K`, degrees per metre.
    pub gain_deg_per_m: f64,
    phase: FollowLinePhase,
}

impl FollowLine {
    /// A mode that first approaches the start with the line's heading using turning radius
    /// `min_turn_radius_m`.
    pub fn new(
        start_m: Vec2,
        end_m: Vec2,
        speed_mps: f64,
        radius_m: f64,
        gain_deg_per_m: f64,
        min_turn_radius_m: f64,
    ) -> Self {
        let alpha = bearing_between(start_m, end_m).unwrap_or(Heading::NORTH);
        let approach = GoToPointWithHeading::new(
            Pose {
                pos_m: start_m,
                heading: alpha,
            },
            speed_mps,
            radius_m,
            min_turn_radius_m,
        );
        FollowLine {
            start_m,
            end_m,
            speed_mps,
            radius_m,
            pass_m: radius_m,
            gain_deg_per_m,
            phase: FollowLinePhase::Approach(Box::new(approach)),
        }
    }

    /// The mode with its approach giving up after `n` re-plans (`u32::MAX`: never).
    pub fn with_approach_replans(mut self, n: u32) -> Self {
        if let FollowLinePhase::Approach(a) = &mut self.phase {
            a.max_replans = n;
        }
        self
    }

    /// A mode that starts on the line, without the approach (e.g. the next leg of a pattern).
    pub fn tracking(
        start_m: Vec2,
        end_m: Vec2,
        speed_mps: f64,
        radius_m: f64,
        gain_deg_per_m: f64,
    ) -> Self {
        let mut f = FollowLine::new(start_m, end_m, speed_mps, radius_m, gain_deg_per_m, 1.0);
        f.phase = FollowLinePhase::Tracking;
        f
    }

    /// The current phase.
    pub fn phase(&self) -> &FollowLinePhase {
        &self.phase
    }

    /// The compass bearing of the line, `alpha_sd` (eq. 7).
    pub fn line_heading(&self) -> Heading {
        bearing_between(self.start_m, self.end_m).unwrap_or(Heading::NORTH)
    }

    /// The cross-track heading law of eq. 8 at position `pos_m`.
    pub fn tracking_heading(&self, pos_m: Vec2) -> Heading {
        let alpha = self.line_heading();
        let d = signed_cross_track_m(pos_m, self.start_m, self.end_m);
        let k = self.gain_deg_per_m;
        let d1 = if k > 0.0 { 45.0 / k } else { f64::INFINITY };
        let offset = if d.abs() < d1 {
            k * d
        } else if d >= 0.0 {
            45.0
        } else {
            -45.0
        };
        alpha.turned_deg(if offset.is_finite() { offset } else { 0.0 })
    }

    /// The mode's decision at the vehicle's estimated pose.
    pub fn update(&mut self, pose: Pose) -> ModeStatus {
        if let FollowLinePhase::Approach(approach) = &mut self.phase {
            match approach.update(pose) {
                ModeStatus::Running(steer) => return ModeStatus::Running(steer),
                ModeStatus::Done(_) => self.phase = FollowLinePhase::Tracking,
            }
        }
        if (pose.pos_m - self.end_m).norm() < self.radius_m {
            return ModeStatus::Done(DoneReason::Arrived);
        }
        if along_track_m(pose.pos_m, self.start_m, self.end_m) > self.pass_m {
            return ModeStatus::Done(DoneReason::PassedEnd);
        }
        ModeStatus::Running(Steer {
            heading: self.tracking_heading(pose.pos_m),
            speed_mps: self.speed_mps,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tracking_heading_table() {
        // A line heading North along x = 0, K = 5 deg/m, d1 = 9 m.
        let f = FollowLine::tracking(Vec2::new(0.0, 0.0), Vec2::new(0.0, 100.0), 2.0, 10.0, 5.0);
        let cases = [
            (0.0, 0.0),
            (-2.0, 10.0),
            (2.0, 350.0),
            (-8.9, 44.5),
            (-9.0, 45.0),
            (-50.0, 45.0),
            (50.0, 315.0),
        ];
        for (x, want) in cases {
            let got = f.tracking_heading(Vec2::new(x, 50.0));
            assert!(
                got.diff_deg(Heading::from_deg(want)).abs() < 1e-9,
                "x = {x}: {}",
                got.deg()
            );
        }
    }

    #[test]
    fn exits_on_either_condition() {
        let mut f =
            FollowLine::tracking(Vec2::new(0.0, 0.0), Vec2::new(0.0, 100.0), 2.0, 10.0, 5.0);
        let at = |x: f64, y: f64| Pose {
            pos_m: Vec2::new(x, y),
            heading: Heading::NORTH,
        };
        assert!(matches!(f.update(at(0.0, 50.0)), ModeStatus::Running(_)));
        assert_eq!(
            f.update(at(3.0, 95.0)),
            ModeStatus::Done(DoneReason::Arrived)
        );
        // A fix that jumps past the end, wide of the arrival circle: eq. 10 ends the mode.
        assert_eq!(
            f.update(at(30.0, 112.0)),
            ModeStatus::Done(DoneReason::PassedEnd)
        );
        assert!(
            matches!(f.update(at(30.0, 105.0)), ModeStatus::Running(_)),
            "5 m past is within R_L"
        );
    }

    /// Flies `line` through the autopilot with a point vehicle (2 m/s through the water, the
    /// heading set to each rate-limited command, carried by `current`), navigation without fixes
    /// (the cage's area shrunk by its full 20 m); the time it ended and the farthest it went
    /// outside `area`, or `None` if still running after `seconds`.
    fn fly_line(
        mut line: FollowLine,
        area: &crate::OpArea,
        from: Pose,
        current: Vec2,
        seconds: f64,
    ) -> (Option<f64>, f64) {
        let mut autopilot = crate::Autopilot::new(crate::AutopilotParams {
            op_area: area.clone(),
            flow_compensation: true,
            max_turn_rate_deg_s: 10.0,
            vertical: plumetrace_core::VerticalCommand::Altitude(2.0),
            nav_drift_mps: 0.02,
            max_inset_m: 20.0,
        });
        let mut pose = from;
        let mut outside = 0.0_f64;
        let dt = 0.1;
        for k in 0..(seconds / dt) as usize {
            let t = 1000.0 + k as f64 * dt;
            let steer = match line.update(pose) {
                ModeStatus::Running(s) => s,
                ModeStatus::Done(_) => return (Some(t - 1000.0), outside),
            };
            let nav = plumetrace_core::NavEstimate {
                pos_m: Some(pose.pos_m),
                heading: pose.heading,
                speed_mps: 2.0,
                altitude_m: None,
                depth_m: None,
                last_fix_s: None,
            };
            let Ok(c) = autopilot.command_nav(t, &nav, steer, current) else {
                return (None, outside);
            };
            pose.heading = c.heading;
            pose.pos_m += (c.heading.unit() * c.speed_mps + current) * dt;
            let e = area.edge_info(pose.pos_m);
            if !e.inside {
                outside = outside.max(e.distance_m);
            }
        }
        (None, outside)
    }

    #[test]
    fn a_line_whose_start_the_cage_keeps_out_of_reach_is_still_flown() {
        // A line 10 m inside the West edge, flown East, as the AMP's mapping lays one out near an
        // edge; the vehicle comes from the North-East across a 0.15 m/s current to the North.
        // Without fixes the cage acts 20 m inside the edge, so the Dubins turn onto the line's
        // start lies where the cage does not let the vehicle go: re-planned for good, the
        // approach circles along the cage. Given up after its re-plans, the line is joined from
        // where the vehicle is and flown to its end.
        let area = crate::OpArea::rectangle(0.0, 400.0, -200.0, 200.0).unwrap();
        let current = Vec2::new(0.0, 0.15);
        let make = || {
            FollowLine::new(
                Vec2::new(10.0, 0.0),
                Vec2::new(70.0, 0.0),
                2.0,
                10.0,
                5.0,
                12.0,
            )
        };
        let from = Pose {
            pos_m: Vec2::new(60.0, 40.0),
            heading: Heading::from_deg(200.0),
        };
        let (t, _) = fly_line(
            make().with_approach_replans(u32::MAX),
            &area,
            from,
            current,
            3600.0,
        );
        assert_eq!(t, None, "the approach never gives up: it never arrives");
        let (t, outside) = fly_line(make(), &area, from, current, 3600.0);
        let t = t.expect("the line is flown");
        assert!(t < 600.0, "flown in {t} s");
        assert!(outside < 1e-9, "{outside} m outside");
    }
}
