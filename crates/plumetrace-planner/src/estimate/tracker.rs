//! The source-likelihood map as a planner keeps it: fed from each snapshot, checked for a
//! declaration, reported as telemetry.
//!
//! Each chemical sample of a snapshot is placed where the vehicle was when it was taken (dead
//! reckoned back from the snapshot's estimate with the vehicle's velocity over ground) and
//! thresholded at the planner's `threshold_v`; the flow history is the planner's own flow
//! estimate at each decision. The map is read (normalised, peak found, mass summed) once per
//! `check_period_s`, not at every decision: a read costs one pass over the cells.
//!
//! The declaration rule: the most likely cell, once the posterior mass within `radius_m` of it
//! reaches `mass` and the map has taken in at least `min_detections` detections (without them,
//! non-detections alone pile the mass up where the vehicle has not looked).

use crate::estimate::{MapModel, SourceMap};
use plumetrace_core::{SensorSnapshot, Telemetry, Vec2};
use plumetrace_guidance::OpArea;

/// When a map read is reported as a whole raster besides its summary.
const RASTER_EVERY_S: f64 = 600.0;

/// The map declaration rule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapRule {
    /// Radius around the most likely cell, m.
    pub radius_m: f64,
    /// Posterior mass within the radius that declares.
    pub mass: f64,
    /// Time between reads of the map, s.
    pub check_period_s: f64,
    /// Detections the map must have taken in before it may declare (non-detections alone
    /// concentrate the map where the vehicle has not looked, which is no evidence of a source).
    pub min_detections: u64,
}

/// A planner's map with its declaration rule.
#[derive(Debug, Clone)]
pub struct MapTracker {
    map: SourceMap,
    rule: MapRule,
    threshold_v: f64,
    last_read_s: Option<f64>,
    last_raster_s: Option<f64>,
    detections: u64,
}

/// What one read of the map found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapRead {
    /// Entropy, bits.
    pub entropy_bits: f64,
    /// Centre of the most likely cell.
    pub peak_m: Vec2,
    /// Mass within the rule's radius of it.
    pub mass: f64,
    /// Detections taken in so far.
    pub detections: u64,
}

impl MapRead {
    /// Whether the rule declares.
    pub fn declares(&self, rule: &MapRule) -> bool {
        self.mass >= rule.mass && self.detections >= rule.min_detections
    }
}

impl MapTracker {
    /// A uniform map over `area`; `None` when the map does not fit (no cell centre inside, or
    /// too many cells).
    pub fn new(area: &OpArea, model: MapModel, rule: MapRule, threshold_v: f64) -> Option<Self> {
        Some(MapTracker {
            map: SourceMap::new(area, model)?,
            rule,
            threshold_v,
            last_read_s: None,
            last_raster_s: None,
            detections: 0,
        })
    }

    /// The map.
    pub fn map(&mut self) -> &mut SourceMap {
        &mut self.map
    }

    /// The rule.
    pub fn rule(&self) -> &MapRule {
        &self.rule
    }

    /// Takes a snapshot's samples in: `pos_m` is the estimate at the snapshot, `ground_mps` the
    /// vehicle's velocity over ground, `flow_mps` the planner's flow estimate.
    pub fn feed(&mut self, s: &SensorSnapshot, pos_m: Vec2, ground_mps: Vec2, flow_mps: Vec2) {
        self.map.add_flow(s.time_s, flow_mps);
        for c in &s.chem {
            let at = pos_m - ground_mps * (s.time_s - c.time_s).max(0.0);
            let detected = c.reading > self.threshold_v;
            self.detections += u64::from(detected);
            self.map.observe(at, c.time_s, s.nav.altitude_m, detected);
        }
    }

    /// Reads the map now.
    pub fn read(&mut self, t_s: f64) -> MapRead {
        self.last_read_s = Some(t_s);
        let (peak_m, _) = self.map.most_likely();
        MapRead {
            entropy_bits: self.map.entropy_bits(),
            peak_m,
            mass: self.map.mass_within(peak_m, self.rule.radius_m),
            detections: self.detections,
        }
    }

    /// Reads the map if `check_period_s` has passed since the last read, pushing its telemetry
    /// (and, every ten minutes, the raster) onto `telemetry`.
    pub fn read_due(&mut self, t_s: f64, telemetry: &mut Vec<Telemetry>) -> Option<MapRead> {
        if self
            .last_read_s
            .is_some_and(|l| t_s - l < self.rule.check_period_s)
        {
            return None;
        }
        let r = self.read(t_s);
        self.report(t_s, &r, telemetry, false);
        Some(r)
    }

    /// Pushes a read's telemetry; the raster too when `raster` or when it is due.
    pub fn report(&mut self, t_s: f64, r: &MapRead, telemetry: &mut Vec<Telemetry>, raster: bool) {
        telemetry.push(Telemetry::SourceMap {
            entropy_bits: r.entropy_bits,
            peak_m: r.peak_m,
            mass: r.mass,
        });
        if raster || self.last_raster_s.is_none_or(|l| t_s - l >= RASTER_EVERY_S) {
            self.last_raster_s = Some(t_s);
            telemetry.push(self.map.raster());
        }
    }

    /// Starts again from the uniform prior (after a declaration in a multi-source mission).
    pub fn reset(&mut self) {
        self.detections = 0;
        self.map.reset();
    }
}
