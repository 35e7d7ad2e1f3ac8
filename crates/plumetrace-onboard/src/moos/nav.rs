//! Navigation from MOOS postings: the `NAV_*` variables, the chemical variable and the manual
//! override taken as they arrive, a navigation record assembled once a new position is complete,
//! and the depth an altitude hold goes out as.

use super::wire::{Message, data};
use crate::command::{CheckedCommand, Vertical};
use crate::geo::LocalFrame;
use crate::link::{LinkEvent, NavFix};
use crate::protocol::sentence::UtcTime;
use plumetrace_core::Vec2;

/// The variables the client registers for, besides the chemical one.
pub const NAV_VARIABLES: &[&str] = &[
    "NAV_X",
    "NAV_Y",
    "NAV_HEADING",
    "NAV_SPEED",
    "NAV_DEPTH",
    "NAV_ALTITUDE",
    "MOOS_MANUAL_OVERRIDE",
];

/// The latest navigation postings (each position with its posting time).
#[derive(Debug, Default)]
pub(crate) struct NavState {
    x: Option<(f64, f64)>,
    y: Option<(f64, f64)>,
    heading: Option<f64>,
    speed: Option<f64>,
    depth: Option<f64>,
    altitude: Option<f64>,
    x_new: bool,
    y_new: bool,
}

impl NavState {
    /// Takes one notification (a navigation variable, the manual override, or the chemical
    /// variable `chem_variable`); `Err` with a count kind when it is not acted on.
    pub(crate) fn take(
        &mut self,
        m: &Message,
        chem_variable: Option<&str>,
        events: &mut Vec<LinkEvent>,
    ) -> Result<(), &'static str> {
        let key = m.key.as_str();
        let chem = chem_variable == Some(key);
        if !chem && !NAV_VARIABLES.contains(&key) {
            return Err("unknown");
        }
        if key == "MOOS_MANUAL_OVERRIDE" {
            let on = match (m.data_type, m.text().map(|t| t.trim().to_ascii_lowercase())) {
                (data::STRING, Some(t)) if t == "true" => true,
                (data::STRING, Some(t)) if t == "false" => false,
                (data::DOUBLE, _) if m.double.is_finite() => m.double != 0.0,
                _ => return Err("bad_field"),
            };
            events.push(LinkEvent::Accepting(!on));
            return Ok(());
        }
        let v = m.number().ok_or("bad_field")?;
        let within = |lo: f64, hi: f64| {
            if (lo..=hi).contains(&v) {
                Ok(v)
            } else {
                Err("out_of_range")
            }
        };
        let t = m.time;
        match key {
            "NAV_X" => {
                self.x = Some((within(-1e6, 1e6)?, t));
                self.x_new = true;
            }
            "NAV_Y" => {
                self.y = Some((within(-1e6, 1e6)?, t));
                self.y_new = true;
            }
            "NAV_HEADING" => self.heading = Some(within(-3600.0, 3600.0)?),
            "NAV_SPEED" => self.speed = Some(within(-100.0, 100.0)?),
            "NAV_DEPTH" => self.depth = Some(within(-100.0, 12_000.0)?),
            "NAV_ALTITUDE" => self.altitude = Some(within(0.0, 12_000.0)?),
            // The chemical reading: the line inputs' range.
            _ if !(-1e6..=1e9).contains(&v) => return Err("out_of_range"),
            _ => events.push(LinkEvent::Chem(v)),
        }
        Ok(())
    }

    /// The navigation record, once both `NAV_X` and `NAV_Y` are new since the last one and a
    /// heading and a speed are known; its position as latitude and longitude about `frame`.
    pub(crate) fn assemble(&mut self, frame: &LocalFrame) -> Option<NavFix> {
        let (Some((x, tx)), Some((y, ty)), Some(heading), Some(speed)) =
            (self.x, self.y, self.heading, self.speed)
        else {
            return None;
        };
        if !(self.x_new && self.y_new) {
            return None;
        }
        self.x_new = false;
        self.y_new = false;
        let t = tx.max(ty);
        let (lat_deg, lon_deg) = frame.to_geographic(Vec2::new(x, y));
        Some(NavFix {
            time: (t.is_finite() && t > 0.0).then(|| UtcTime::from_seconds(t.rem_euclid(86_400.0))),
            lat_deg,
            lon_deg,
            heading_deg: heading,
            speed_mps: speed,
            altitude_m: self.altitude,
            depth_m: self.depth,
            gps: false,
        })
    }

    /// The depth a checked command's vertical set-point goes out as (`None`: an altitude hold
    /// without a water depth).
    pub(crate) fn depth_of(&self, c: &CheckedCommand) -> Option<f64> {
        match c.vertical() {
            Vertical::Depth(d) => Some(d),
            Vertical::Altitude(a) => {
                let water = self.depth? + self.altitude?;
                Some((water - a).max(0.0))
            }
        }
    }
}
