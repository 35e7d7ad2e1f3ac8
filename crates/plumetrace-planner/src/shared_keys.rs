//! Keys several planners share, declared once: the autopilot's (how the vehicle is flown and what
//! counts as a detection) and the source-likelihood map's. A planner includes a set in its own
//! table (`include autopilot: AutopilotKeys = ...` in its [`params!`](plumetrace_core::params!)),
//! with defaults of its own where they differ; in files the keys stand in the planner's table like
//! its other keys.

use crate::estimate::{MapModel, MapRule, MapTracker};
use crate::flow::FlowEstimate;
use plumetrace_core::params::{Bounds, ParamError};
use plumetrace_core::{Heading, VerticalCommand};
use plumetrace_guidance::{AutopilotParams, OpArea};

plumetrace_core::params! {
    /// The keys of the [`Autopilot`](plumetrace_guidance::Autopilot) a planner steers through,
    /// and the detection threshold.
    pub struct AutopilotKeys {
        /// Speed command.
        speed_mps: f64 = 2.0, "m/s", Bounds::positive(10.0);
        /// Altitude command (height above the seabed; surface craft stay at the surface).
        altitude_m: f64 = 2.0, "m", Bounds::non_negative(1000.0);
        /// A chemical reading above this is a detection (4 % of the field sensor's 5 V).
        threshold_v: f64 = 0.2, "V", Bounds::non_negative(1e6);
        /// Heading-rate limit of the commands.
        max_turn_rate_deg_s: f64 = 10.0, "deg/s", Bounds::positive(360.0);
        /// Time constant of the flow estimate.
        flow_average_s: f64 = 60.0, "s", Bounds::non_negative(100_000.0);
        /// Compensate courses for the measured flow (crab angle).
        flow_compensation: bool = true, "", Bounds::Any;
    }
}

impl AutopilotKeys {
    /// The autopilot's settings over `op_area` at `altitude_m`, with a cage that does not shrink
    /// for the navigation error (a planner that shrinks it sets `nav_drift_mps` and
    /// `max_inset_m`).
    pub fn autopilot(&self, op_area: OpArea) -> AutopilotParams {
        AutopilotParams {
            op_area,
            flow_compensation: self.flow_compensation,
            max_turn_rate_deg_s: self.max_turn_rate_deg_s,
            vertical: VerticalCommand::Altitude(self.altitude_m),
            nav_drift_mps: 0.0,
            max_inset_m: 0.0,
        }
    }

    /// The flow estimate, starting from the prior direction `prior_flow`.
    pub fn flow_estimate(&self, prior_flow: Heading) -> FlowEstimate {
        FlowEstimate::new(self.flow_average_s, prior_flow)
    }
}

plumetrace_core::params! {
    /// The keys of a planner's source-likelihood map ([`crate::estimate::map`]) and of its
    /// declaration rule ([`MapRule`]).
    pub struct MapKeys {
        /// Map declaration: radius around the map's most likely cell.
        map_radius_m: f64 = 10.0, "m", Bounds::closed(0.5, 10_000.0);
        /// Map declaration: posterior mass within map_radius_m that declares.
        map_mass: f64 = 0.5, "", Bounds::closed(0.01, 1.0);
        /// Map declaration: detections the map must have taken in first.
        map_min_detections: u32 = 50, "", Bounds::whole(0, 1_000_000);
        /// Map declaration: how long the rule must hold with the map's most likely cell staying within map_radius_m (the plume traced to its head, not a map read mid-plume).
        map_hold_s: f64 = 0.0, "s", Bounds::closed(0.0, 1e5);
        /// Map declaration: the declared position is the posterior mean within this radius of the most likely cell (0: that cell's centre, which leaves up to half a cell of error in each axis).
        map_estimate_radius_m: f64 = 0.0, "m", Bounds::closed(0.0, 10_000.0);
        /// Time between reads of the map for the declaration.
        map_check_s: f64 = 5.0, "s", Bounds::closed(0.0, 3600.0);
        /// Source map: cell size.
        map_resolution_m: f64 = 5.0, "m", Bounds::closed(0.5, 1000.0);
        /// Source map: probability that a sample inside the plume detects (intermittency).
        map_p_detect: f64 = 0.1, "", Bounds::closed(0.01, 1.0);
        /// Source map: samples closer together than this count as one look (the plume's meander keeps a vehicle in or out of it for seconds).
        map_correlation_s: f64 = 10.0, "s", Bounds::closed(0.0, 3600.0);
        /// Source map: growth of the back-projection spread, sigma^2 = (3 m)^2 + 2 D T.
        map_diffusivity_m2ps: f64 = 0.1, "m^2/s", Bounds::closed(0.0, 1000.0);
        /// Source map: growth of the spread along the flow as a fraction of map_diffusivity_m2ps, when map_along_speed_mps is 0 (1: the same spread in every direction; below 1 a sample says less about sources downflow of where the flow carried it from).
        map_along_ratio: f64 = 1.0, "", Bounds::closed(0.0, 1.0);
        /// Source map: when positive, the along-flow growth follows the current, min(1, U / map_along_speed_mps) of map_diffusivity_m2ps with U the speed of the vehicle's latest flow reading, replacing map_along_ratio (round in a current at least this fast, narrower along the flow the slower it runs).
        map_along_speed_mps: f64 = 0.0, "m/s", Bounds::closed(0.0, 10.0);
        /// Source map: vertical diffusivity that mixes a bottom source up to the vehicle's altitude, when map_mixing_length_m is 0 (0: no vertical model).
        map_vertical_diffusivity_m2ps: f64 = 0.01, "m^2/s", Bounds::closed(0.0, 100.0);
        /// Source map: when positive, the vertical diffusivity is this mixing length times the measured flow speed (bottom boundary-layer mixing grows with the current), replacing map_vertical_diffusivity_m2ps.
        map_mixing_length_m: f64 = 0.0, "m", Bounds::closed(0.0, 100.0);
        /// Source map: longest travel time a sample is back-projected over.
        map_window_s: f64 = 3600.0, "s", Bounds::closed(1.0, 1e6);
        /// Source map: travel time beyond which the chance of a detection falls as one over travel time (plume dilution; 0: off), when map_dilution_m is 0.
        map_dilution_s: f64 = 60.0, "s", Bounds::closed(0.0, 1e6);
        /// Source map: when positive, the distance downflow beyond which the chance of a detection falls as one over the distance (plume dilution measured along the flow, at the measured flow speed), replacing map_dilution_s.
        map_dilution_m: f64 = 0.0, "m", Bounds::closed(0.0, 1e6);
    }
}

impl MapKeys {
    /// The map's model (the rest at its defaults).
    pub fn model(&self) -> MapModel {
        MapModel {
            resolution_m: self.map_resolution_m,
            p_detect: self.map_p_detect,
            diffusivity_m2ps: self.map_diffusivity_m2ps,
            along_ratio: self.map_along_ratio,
            along_speed_mps: self.map_along_speed_mps,
            vertical_diffusivity_m2ps: self.map_vertical_diffusivity_m2ps,
            vertical_mixing_length_m: self.map_mixing_length_m,
            window_s: self.map_window_s,
            correlation_s: self.map_correlation_s,
            dilution_s: self.map_dilution_s,
            dilution_m: self.map_dilution_m,
            ..MapModel::default()
        }
    }

    /// The map keys that have no effect at these values, with why.
    pub fn without_effect(&self) -> Vec<(&'static str, String)> {
        let mut out = Vec::new();
        if self.map_dilution_m > 0.0 {
            out.push((
                "map_dilution_s",
                format!(
                    "has no effect while map_dilution_m ({} m) is positive: dilution is then \
                     measured along the flow from there",
                    self.map_dilution_m
                ),
            ));
        }
        if self.map_diffusivity_m2ps == 0.0 {
            for key in ["map_along_ratio", "map_along_speed_mps"] {
                out.push((
                    key,
                    format!(
                        "has no effect while map_diffusivity_m2ps is 0: the spread does not grow \
                         in any direction (set map_diffusivity_m2ps above 0, or leave {key} out)"
                    ),
                ));
            }
        } else if self.map_along_speed_mps > 0.0 {
            out.push((
                "map_along_ratio",
                format!(
                    "has no effect while map_along_speed_mps ({} m/s) is positive: the ratio \
                     then follows the measured current (set map_along_speed_mps = 0 for a fixed \
                     ratio, or leave map_along_ratio out)",
                    self.map_along_speed_mps
                ),
            ));
        }
        if self.map_mixing_length_m > 0.0 {
            out.push((
                "map_vertical_diffusivity_m2ps",
                format!(
                    "has no effect while map_mixing_length_m ({} m) is positive: the vertical \
                     diffusivity is then that length times the measured flow speed",
                    self.map_mixing_length_m
                ),
            ));
        }
        out
    }

    /// The declaration rule.
    pub fn rule(&self) -> MapRule {
        MapRule {
            radius_m: self.map_radius_m,
            mass: self.map_mass,
            check_period_s: self.map_check_s,
            min_detections: u64::from(self.map_min_detections),
            hold_s: self.map_hold_s,
            estimate_radius_m: self.map_estimate_radius_m,
        }
    }

    /// The map with its rule over `area`, counting readings above `threshold_v` as detections;
    /// the error names `map_resolution_m` when no map fits the area.
    pub fn tracker(&self, area: &OpArea, threshold_v: f64) -> Result<MapTracker, ParamError> {
        let model = self.model();
        MapTracker::new(area, model, self.rule(), threshold_v).ok_or_else(|| ParamError {
            key: "map_resolution_m".into(),
            message: format!(
                "no source map fits the op-area at {} m cells (none inside, or more than {} cells)",
                model.resolution_m,
                crate::estimate::map::MAX_CELLS
            ),
        })
    }
}
