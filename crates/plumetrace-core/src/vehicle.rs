//! What a vehicle knows and what it is told to do.
//!
//! A [`SensorSnapshot`] is everything the onboard side of one vehicle may see at a decision time:
//! its navigation estimate (never the true position), its latest sensor samples and the messages
//! that reached it. A [`Command`] is what the onboard side returns. Both are plain values so the
//! same planner code runs against the simulator, a logged mission or a vehicle link.

use crate::{Heading, Message, Vec2};
use serde::{Deserialize, Serialize};

/// Identifies one vehicle in a world (index into the world's vehicle list).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct VehicleId(pub u32);

/// The kinds of vehicle a world can hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VehicleKind {
    /// An autonomous underwater vehicle: dead-reckoned, flies at an altitude above the seabed.
    Auv,
    /// A surface vehicle with GPS.
    Surface,
}

/// The vehicle's own estimate of where it is and how it moves, as its instruments report it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NavEstimate {
    /// Estimated position `(east, north)`, m (dead reckoning plus fixes, or GPS); `None` for a
    /// vehicle without a position estimate (an underwater follower without fixes).
    pub pos_m: Option<Vec2>,
    /// Compass heading, as measured by the vehicle.
    pub heading: Heading,
    /// Water-relative speed as the speed log reports it, m/s.
    pub speed_mps: f64,
    /// Height above the seabed as the altimeter reports it, m (`None`: no altimeter, as on
    /// surface craft).
    pub altitude_m: Option<f64>,
    /// Depth below the surface as the depth sensor reports it, m (`None` when unknown).
    pub depth_m: Option<f64>,
    /// Time of the last position fix, s (`None` before the first one).
    pub last_fix_s: Option<f64>,
}

/// One chemical sensor sample: the analog reading only. Whether it counts as a detection is the
/// planner's decision (the field planner thresholded the sensor's voltage itself).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ChemSample {
    /// Sample time, s.
    pub time_s: f64,
    /// Analog reading in sensor units (volts for the field sensor).
    pub reading: f64,
}

/// One flow (current) measurement, as an ADCP would give it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FlowSample {
    /// Sample time, s.
    pub time_s: f64,
    /// Measured water velocity `(east, north)`, m/s.
    pub velocity_mps: Vec2,
}

/// Nearest obstacle distances in the three sensor groups (front, left, right); `None` = nothing
/// within range.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct RangeReturn {
    /// Front group (-30..30 deg about the heading), m.
    pub front_m: Option<f64>,
    /// Left group, m.
    pub left_m: Option<f64>,
    /// Right group, m.
    pub right_m: Option<f64>,
}

/// Everything the onboard side of one vehicle sees at one decision time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorSnapshot {
    /// Mission time, s.
    pub time_s: f64,
    /// Which vehicle this is.
    pub vehicle: VehicleId,
    /// Navigation estimate (never the truth).
    pub nav: NavEstimate,
    /// Chemical samples taken since the previous snapshot, oldest first.
    pub chem: Vec<ChemSample>,
    /// Latest flow measurement, if the vehicle has a flow sensor.
    pub flow: Option<FlowSample>,
    /// Latest obstacle ranges, if the vehicle has range sensors.
    pub ranges: Option<RangeReturn>,
    /// Messages delivered since the previous snapshot, in delivery order.
    pub inbox: Vec<Message>,
}

/// Vertical command: hold an altitude above the seabed or a depth below the surface.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VerticalCommand {
    /// Height above the seabed, m.
    Altitude(#[serde(with = "crate::any_f64")] f64),
    /// Depth below the surface, m.
    Depth(#[serde(with = "crate::any_f64")] f64),
    /// Stay at the surface.
    Surface,
}

/// What the onboard side asks the vehicle to do until the next decision.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Command {
    /// Commanded compass heading.
    pub heading: Heading,
    /// Commanded water-relative speed, m/s.
    #[serde(with = "crate::any_f64")]
    pub speed_mps: f64,
    /// Commanded vertical behaviour.
    pub vertical: VerticalCommand,
}

impl Command {
    /// Whether every number in the command is finite (the chokepoint check before a command
    /// reaches a vehicle).
    pub fn is_finite(&self) -> bool {
        let v = match self.vertical {
            VerticalCommand::Altitude(a) | VerticalCommand::Depth(a) => a.is_finite(),
            VerticalCommand::Surface => true,
        };
        self.heading.rad().is_finite() && self.speed_mps.is_finite() && v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn command_finiteness_check() {
        let ok = Command {
            heading: Heading::from_deg(10.0),
            speed_mps: 2.0,
            vertical: VerticalCommand::Altitude(2.0),
        };
        assert!(ok.is_finite());
        let bad_speed = Command {
            speed_mps: f64::NAN,
            ..ok
        };
        assert!(!bad_speed.is_finite());
        let bad_alt = Command {
            vertical: VerticalCommand::Depth(f64::INFINITY),
            ..ok
        };
        assert!(!bad_alt.is_finite());
    }
}
