//! The one chokepoint every command passes before it leaves for a vehicle: finite numbers,
//! within the vehicle's limits. A [`CheckedCommand`] can only be made here, and the links take
//! nothing else.

use plumetrace_core::{Command, VerticalCommand, wrap_deg_360};
use serde::{Deserialize, Serialize};

/// What the vehicle accepts.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct VehicleLimits {
    /// Highest speed commanded, m/s (`(0, 10]`).
    pub max_speed_mps: f64,
    /// Deepest depth commanded, m (`(0, 6000]`).
    pub max_depth_m: f64,
    /// Lowest altitude commanded, m (`[0, max_altitude_m]`).
    pub min_altitude_m: f64,
    /// Highest altitude commanded, m (`(0, 1000]`).
    pub max_altitude_m: f64,
}

impl Default for VehicleLimits {
    fn default() -> Self {
        VehicleLimits {
            max_speed_mps: 2.5,
            max_depth_m: 100.0,
            min_altitude_m: 1.0,
            max_altitude_m: 50.0,
        }
    }
}

impl VehicleLimits {
    /// The limits' own bounds, with the key that breaks them.
    pub fn validate(&self) -> Result<(), LimitError> {
        let checks = [
            ("max_speed_mps", self.max_speed_mps, 0.0, 10.0, false),
            ("max_depth_m", self.max_depth_m, 0.0, 6000.0, false),
            ("max_altitude_m", self.max_altitude_m, 0.0, 1000.0, false),
            (
                "min_altitude_m",
                self.min_altitude_m,
                0.0,
                self.max_altitude_m,
                true,
            ),
        ];
        for (key, value, lo, hi, lo_inclusive) in checks {
            let above = if lo_inclusive {
                value >= lo
            } else {
                value > lo
            };
            if !(value.is_finite() && above && value <= hi) {
                return Err(LimitError {
                    key,
                    value,
                    lo,
                    hi,
                    lo_inclusive,
                });
            }
        }
        Ok(())
    }
}

/// A vehicle limit outside its own bounds; the message leaves the key out ([`LimitError::key`]
/// gives it).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("{value} is outside {}{lo}, {hi}]", if *lo_inclusive { "[" } else { "(" })]
pub struct LimitError {
    /// The limit's key (`max_speed_mps`, ...).
    pub key: &'static str,
    /// Its value.
    pub value: f64,
    /// The lower bound.
    pub lo: f64,
    /// The upper bound (inclusive).
    pub hi: f64,
    /// Whether the lower bound is allowed.
    pub lo_inclusive: bool,
}

/// How the vertical set-point is held.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Vertical {
    /// Depth below the surface, m.
    Depth(f64),
    /// Height above the seabed, m.
    Altitude(f64),
}

/// A command that passed [`check`]: finite, heading in `[0, 360)`, speed and depth or altitude
/// within the vehicle's limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckedCommand {
    heading_deg: f64,
    speed_mps: f64,
    vertical: Vertical,
}

impl CheckedCommand {
    /// Compass heading, deg, in `[0, 360)`.
    pub fn heading_deg(&self) -> f64 {
        self.heading_deg
    }
    /// Speed through the water, m/s.
    pub fn speed_mps(&self) -> f64 {
        self.speed_mps
    }
    /// The vertical set-point.
    pub fn vertical(&self) -> Vertical {
        self.vertical
    }
}

/// Why a command was not sent.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CommandError {
    /// A number is NaN or infinite.
    #[error("the command has a non-finite number")]
    NotFinite,
    /// A value outside the vehicle's limits.
    #[error("{what} {value} is outside the vehicle's limits [{lo}, {hi}]")]
    OutOfLimits {
        /// Which set-point.
        what: &'static str,
        /// The value.
        value: f64,
        /// Lowest allowed.
        lo: f64,
        /// Highest allowed.
        hi: f64,
    },
}

/// The chokepoint: a planner's command checked against `limits`.
pub fn check(command: &Command, limits: &VehicleLimits) -> Result<CheckedCommand, CommandError> {
    if !command.is_finite() {
        return Err(CommandError::NotFinite);
    }
    let within = |what, value: f64, lo: f64, hi: f64| {
        if value >= lo && value <= hi {
            Ok(value)
        } else {
            Err(CommandError::OutOfLimits {
                what,
                value,
                lo,
                hi,
            })
        }
    };
    let speed_mps = within("speed_mps", command.speed_mps, 0.0, limits.max_speed_mps)?;
    let vertical = match command.vertical {
        VerticalCommand::Depth(d) => {
            Vertical::Depth(within("depth_m", d, 0.0, limits.max_depth_m)?)
        }
        VerticalCommand::Altitude(a) => Vertical::Altitude(within(
            "altitude_m",
            a,
            limits.min_altitude_m,
            limits.max_altitude_m,
        )?),
        VerticalCommand::Surface => Vertical::Depth(0.0),
    };
    let h = wrap_deg_360(command.heading.deg());
    Ok(CheckedCommand {
        heading_deg: if h >= 360.0 { 0.0 } else { h },
        speed_mps,
        vertical,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_core::Heading;

    fn cmd(h: f64, s: f64, v: VerticalCommand) -> Command {
        Command {
            heading: Heading::from_deg(h),
            speed_mps: s,
            vertical: v,
        }
    }

    #[test]
    fn the_chokepoint_passes_good_commands_and_stops_bad_ones() {
        let l = VehicleLimits::default();
        let ok = check(&cmd(-90.0, 1.5, VerticalCommand::Altitude(3.0)), &l);
        let ok = ok.unwrap_or_else(|e| panic!("{e}"));
        assert!((ok.heading_deg() - 270.0).abs() < 1e-9);
        assert_eq!(ok.vertical(), Vertical::Altitude(3.0));
        let cases = [
            cmd(f64::NAN, 1.0, VerticalCommand::Depth(1.0)),
            cmd(0.0, f64::INFINITY, VerticalCommand::Depth(1.0)),
            cmd(0.0, 1.0, VerticalCommand::Depth(f64::NAN)),
            cmd(0.0, 3.0, VerticalCommand::Depth(1.0)),
            cmd(0.0, -0.1, VerticalCommand::Depth(1.0)),
            cmd(0.0, 1.0, VerticalCommand::Depth(101.0)),
            cmd(0.0, 1.0, VerticalCommand::Altitude(0.5)),
        ];
        for c in cases {
            assert!(check(&c, &l).is_err(), "{c:?}");
        }
        assert_eq!(
            check(&cmd(0.0, 1.0, VerticalCommand::Surface), &l).map(|c| c.vertical()),
            Ok(Vertical::Depth(0.0))
        );
    }

    #[test]
    fn limits_are_checked() {
        assert!(VehicleLimits::default().validate().is_ok());
        let bad = VehicleLimits {
            min_altitude_m: 60.0,
            ..VehicleLimits::default()
        };
        let e = bad.validate().err();
        assert_eq!(e.map(|e| e.key), Some("min_altitude_m"));
        assert_eq!(
            e.map(|e| e.to_string()).as_deref(),
            Some("60 is outside [0, 50]")
        );
    }
}
