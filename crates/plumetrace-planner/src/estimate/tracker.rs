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
//! non-detections alone pile the mass up where the vehicle has not looked), and has kept doing so
//! for `hold_s` with the most likely cell within `radius_m` of where it was when the rule first
//! held. The hold is the map's version of the lost-point rule's agreement: a map read while the
//! vehicle is still tracing the plume concentrates just upflow of the newest detections, and the
//! next detections upflow move it on; at the plume's head further search (Track-Out, Reacquire)
//! brings non-detections upflow and detections at the head, and the peak stays.

use crate::estimate::{MapModel, SourceMap};
use plumetrace_core::{DeclarationKind, SensorSnapshot, Telemetry, Vec2};
use plumetrace_guidance::OpArea;

/// The map's rule in events: the most likely cell (or the posterior mean around it), once the
/// map's mass within a radius of that cell has passed a threshold.
pub const SOURCE_MAP: DeclarationKind = DeclarationKind::new("source_map");

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
    /// How long the rule must hold, the most likely cell staying within `radius_m` of where it
    /// was when the rule first held, before it declares (0: at once), s.
    pub hold_s: f64,
    /// The declared position: the posterior mean within this radius of the most likely cell
    /// (0: that cell's centre), m.
    pub estimate_radius_m: f64,
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
    /// Since when and where the rule has held, while it holds.
    holding: Option<(f64, Vec2)>,
}

/// What one read of the map found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapRead {
    /// Entropy, bits.
    pub entropy_bits: f64,
    /// Centre of the most likely cell.
    pub peak_m: Vec2,
    /// The source position the map gives: the posterior mean within the rule's
    /// `estimate_radius_m` of the peak (the peak itself when that is 0).
    pub estimate_m: Vec2,
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
            holding: None,
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

    /// Whether the rule declares on `r`, read at `t_s`: it holds and has held for `hold_s` with
    /// the peak within `radius_m` of where it was when it first held (see the module docs).
    /// Call it on every read (it keeps the hold's start).
    pub fn declares(&mut self, t_s: f64, r: &MapRead) -> bool {
        if !r.declares(&self.rule) {
            self.holding = None;
            return false;
        }
        match self.holding {
            Some((_, at)) if (r.peak_m - at).norm() <= self.rule.radius_m => {}
            _ => self.holding = Some((t_s, r.peak_m)),
        }
        self.holding
            .is_some_and(|(since, _)| t_s - since >= self.rule.hold_s)
    }

    /// Reads the map now.
    pub fn read(&mut self, t_s: f64) -> MapRead {
        self.last_read_s = Some(t_s);
        let (peak_m, _) = self.map.most_likely();
        let estimate_m = if self.rule.estimate_radius_m > 0.0 {
            self.map.mean_within(peak_m, self.rule.estimate_radius_m)
        } else {
            peak_m
        };
        MapRead {
            entropy_bits: self.map.entropy_bits(),
            peak_m,
            estimate_m,
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
        self.holding = None;
        self.map.reset();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tracker(hold_s: f64) -> MapTracker {
        let area = OpArea::rectangle(0.0, 100.0, 0.0, 100.0).unwrap_or_else(|e| panic!("{e}"));
        let rule = MapRule {
            radius_m: 10.0,
            mass: 0.5,
            check_period_s: 5.0,
            min_detections: 2,
            hold_s,
            estimate_radius_m: 0.0,
        };
        MapTracker::new(&area, MapModel::default(), rule, 0.2).unwrap_or_else(|| panic!("no map"))
    }

    fn read(x: f64, mass: f64) -> MapRead {
        MapRead {
            entropy_bits: 1.0,
            peak_m: Vec2::new(x, 50.0),
            estimate_m: Vec2::new(x, 50.0),
            mass,
            detections: 5,
        }
    }

    #[test]
    fn the_rule_declares_once_it_has_held_with_the_peak_in_place() {
        let mut t = tracker(300.0);
        assert!(!t.declares(0.0, &read(50.0, 0.6)));
        assert!(!t.declares(200.0, &read(55.0, 0.6)));
        assert!(t.declares(300.0, &read(58.0, 0.6)));
        // Without the hold: at once; short of mass or detections: never.
        let mut t = tracker(0.0);
        assert!(t.declares(0.0, &read(50.0, 0.6)));
        assert!(!t.declares(0.0, &read(50.0, 0.4)));
        let few = MapRead {
            detections: 1,
            ..read(50.0, 0.9)
        };
        assert!(!t.declares(0.0, &few));
    }

    #[test]
    fn the_hold_starts_again_when_the_peak_moves_or_the_mass_drops() {
        let mut t = tracker(300.0);
        assert!(!t.declares(0.0, &read(20.0, 0.6)));
        // The peak moved more than the radius: the hold starts again at 250 s.
        assert!(!t.declares(250.0, &read(40.0, 0.6)));
        assert!(!t.declares(500.0, &read(40.0, 0.6)));
        assert!(t.declares(550.0, &read(40.0, 0.6)));
        // A read short of the mass breaks the hold.
        let mut t = tracker(300.0);
        assert!(!t.declares(0.0, &read(20.0, 0.6)));
        assert!(!t.declares(100.0, &read(20.0, 0.3)));
        assert!(!t.declares(300.0, &read(20.0, 0.6)));
        assert!(t.declares(600.0, &read(20.0, 0.6)));
    }
}
