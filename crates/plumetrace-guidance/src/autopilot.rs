//! The autopilot every planner steers through: the op-area cage, flow compensation and the
//! heading-rate filter, in that order, turning a desired course over ground into a command.

use crate::{Cage, CageAction, OpArea, RateFilter, Steer, compensate_flow};
use plumetrace_core::{Command, Heading, Vec2, VerticalCommand};

/// Settings of the [`Autopilot`].
#[derive(Debug, Clone, PartialEq)]
pub struct AutopilotParams {
    /// The area the cage keeps the vehicle in.
    pub op_area: OpArea,
    /// Turn the desired course over ground into a water-relative heading (crab angle).
    pub flow_compensation: bool,
    /// Heading-rate limit of the commands, deg/s.
    pub max_turn_rate_deg_s: f64,
    /// The vertical command sent with every heading.
    pub vertical: VerticalCommand,
    /// How fast the navigation error may grow between fixes, m/s: [`Autopilot::command_nav`]
    /// shrinks the cage's area by this times the time since the last fix (0: never).
    pub nav_drift_mps: f64,
    /// The most the area is shrunk by, m.
    pub max_inset_m: f64,
}

/// The cage aborted: the vehicle is too far outside the op-area.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CageAbort {
    /// How far outside the estimate is, m.
    pub distance_outside_m: f64,
    /// The command to send: hold the measured heading at zero speed.
    pub command: Command,
}

/// Cage, flow compensation and rate filter with their state.
///
/// - the cage (eq. 11-13) acts on the desired course at the estimated position (skipped when the
///   vehicle has no position estimate);
/// - flow compensation solves for the water-relative heading whose sum with the measured current
///   points along that course;
/// - the rate filter limits the heading change between commands; it starts from the vehicle's
///   measured heading at the first command.
#[derive(Debug, Clone, PartialEq)]
pub struct Autopilot {
    cage: Cage,
    nav_drift_mps: f64,
    max_inset_m: f64,
    inset_m: f64,
    flow_compensation: bool,
    filter: RateFilter,
    vertical: VerticalCommand,
    last_t_s: Option<f64>,
}

impl Autopilot {
    /// An autopilot with the field vehicle's cage (5 m band, 30 m abort).
    pub fn new(p: AutopilotParams) -> Self {
        Autopilot {
            cage: Cage::new(p.op_area),
            nav_drift_mps: p.nav_drift_mps,
            max_inset_m: p.max_inset_m,
            inset_m: 0.0,
            flow_compensation: p.flow_compensation,
            filter: RateFilter::new(p.max_turn_rate_deg_s),
            vertical: p.vertical,
            last_t_s: None,
        }
    }

    /// Sets the vertical command sent from now on (a planner that changes altitude by behaviour).
    pub fn set_vertical(&mut self, vertical: VerticalCommand) {
        self.vertical = vertical;
    }

    /// The cage.
    pub fn cage(&self) -> &Cage {
        &self.cage
    }

    /// The command that flies `steer` from estimated position `pos_m` (with the vehicle's measured
    /// `heading` and the measured current `flow_mps`) at time `t_s`; an error when the cage
    /// aborts.
    pub fn command(
        &mut self,
        t_s: f64,
        pos_m: Option<Vec2>,
        heading: Heading,
        steer: Steer,
        flow_mps: Vec2,
    ) -> Result<Command, CageAbort> {
        let dt = match self.last_t_s {
            Some(last) => (t_s - last).max(0.0),
            None => {
                self.filter.reset(heading);
                0.0
            }
        };
        self.last_t_s = Some(t_s);
        let caged = match pos_m.map(|p| self.cage.apply_inset(p, steer.heading, self.inset_m)) {
            Some(CageAction::Abort { distance_outside_m }) => {
                return Err(CageAbort {
                    distance_outside_m,
                    command: self.hold(heading),
                });
            }
            Some(action) => action.heading().unwrap_or(steer.heading),
            None => steer.heading,
        };
        let water = if self.flow_compensation {
            compensate_flow(caged, steer.speed_mps, flow_mps).heading
        } else {
            caged
        };
        Ok(Command {
            heading: self.filter.filter(water, dt),
            speed_mps: steer.speed_mps,
            vertical: self.vertical,
        })
    }

    /// [`Autopilot::command`] from a navigation estimate, with the cage's area shrunk by the
    /// navigation's possible error: `nav_drift_mps` times the time since the last fix (since the
    /// start before the first), at most `max_inset_m`.
    pub fn command_nav(
        &mut self,
        t_s: f64,
        nav: &plumetrace_core::NavEstimate,
        steer: Steer,
        flow_mps: Vec2,
    ) -> Result<Command, CageAbort> {
        let since = (t_s - nav.last_fix_s.unwrap_or(0.0)).max(0.0);
        let inset = (self.nav_drift_mps * since).min(self.max_inset_m);
        self.inset_m = if inset.is_finite() {
            inset.max(0.0)
        } else {
            0.0
        };
        let out = self.command(t_s, nav.pos_m, nav.heading, steer, flow_mps);
        self.inset_m = 0.0;
        out
    }

    /// Hold `heading` at zero speed.
    pub fn hold(&self, heading: Heading) -> Command {
        Command {
            heading,
            speed_mps: 0.0,
            vertical: self.vertical,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pilot(flow_compensation: bool) -> Autopilot {
        Autopilot::new(AutopilotParams {
            op_area: OpArea::rectangle(0.0, 100.0, 0.0, 100.0).unwrap_or_else(|e| panic!("{e}")),
            flow_compensation,
            max_turn_rate_deg_s: 10.0,
            vertical: VerticalCommand::Altitude(2.0),
            nav_drift_mps: 0.0,
            max_inset_m: 0.0,
        })
    }

    fn steer(deg: f64) -> Steer {
        Steer {
            heading: Heading::from_deg(deg),
            speed_mps: 2.0,
        }
    }

    #[test]
    fn rate_limits_from_the_measured_heading() {
        let mut a = pilot(false);
        let north = Heading::NORTH;
        let p = Some(Vec2::new(50.0, 50.0));
        let c = a.command(0.0, p, north, steer(90.0), Vec2::zeros());
        assert_eq!(c.map(|c| c.heading.deg()), Ok(0.0), "no time has passed");
        let c = a.command(1.0, p, north, steer(90.0), Vec2::zeros());
        assert!(c.is_ok_and(|c| (c.heading.deg() - 10.0).abs() < 1e-9 && c.speed_mps == 2.0));
    }

    #[test]
    fn compensates_the_flow_and_cages_then_aborts() {
        let mut a = pilot(true);
        let east = Heading::from_deg(90.0);
        // Course East with 1 m/s from the South: crab to the South of East (30 deg).
        a.command(
            0.0,
            Some(Vec2::new(50.0, 50.0)),
            Heading::from_deg(120.0),
            steer(90.0),
            Vec2::zeros(),
        )
        .ok();
        let c = a
            .command(
                10.0,
                Some(Vec2::new(50.0, 50.0)),
                east,
                steer(90.0),
                Vec2::new(0.0, 1.0),
            )
            .map(|c| c.heading.deg());
        assert!(c.is_ok_and(|h| (h - 120.0).abs() < 1e-9), "{c:?}");
        // Outside: the inward normal; far outside: abort, holding the heading at zero speed.
        let c = a.command(
            20.0,
            Some(Vec2::new(110.0, 50.0)),
            east,
            steer(90.0),
            Vec2::zeros(),
        );
        // The inward normal is West (270); the filter turns from 120 by at most 100 deg in 10 s.
        assert!(
            c.is_ok_and(|c| (c.heading.deg() - 220.0).abs() < 1e-9),
            "{c:?}"
        );
        let e = a.command(
            21.0,
            Some(Vec2::new(140.0, 50.0)),
            east,
            steer(90.0),
            Vec2::zeros(),
        );
        match e {
            Err(abort) => {
                assert!((abort.distance_outside_m - 40.0).abs() < 1e-9);
                assert_eq!(abort.command.speed_mps, 0.0);
                assert_eq!(abort.command.heading, east);
            }
            Ok(c) => panic!("no abort 40 m outside: {c:?}"),
        }
        // Without a position estimate there is no cage.
        let c = a.command(22.0, None, east, steer(90.0), Vec2::zeros());
        assert!(c.is_ok());
    }
}
