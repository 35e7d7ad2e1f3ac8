//! A plausibility check of current measurements against their recent history.
//!
//! A current meter that reads the wrong layer (or a sensor glitch) can report the current reversed
//! from one sample to the next, while a real current turns slowly: a tide swings its direction
//! over hours. [`FlowGate`] keeps a reference, the exponential mean of the samples it accepted,
//! and holds back a sample that points more than `max_turn_deg` away from it (both faster than
//! `min_speed_mps`, so that a slack current's noise is not judged). If such samples keep coming
//! for `persist_s` without one plausible sample between them, the change is taken as real: the
//! gate accepts them and restarts its reference from them. A planner steering by the current and
//! a navigation dead-reckoning with it both use it; it has no randomness and no model of its own.

use crate::Vec2;

/// Settings of a [`FlowGate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlowGateParams {
    /// A sample further than this from the reference direction is implausible, deg.
    pub max_turn_deg: f64,
    /// Samples and references slower than this are not judged, m/s.
    pub min_speed_mps: f64,
    /// How long implausible samples must persist to be believed, s.
    pub persist_s: f64,
    /// Time constant of the reference, s.
    pub reference_s: f64,
}

impl Default for FlowGateParams {
    fn default() -> Self {
        FlowGateParams {
            max_turn_deg: 90.0,
            min_speed_mps: 0.03,
            persist_s: 1800.0,
            reference_s: 120.0,
        }
    }
}

/// The check and its state.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowGate {
    p: FlowGateParams,
    reference: Option<(f64, Vec2)>,
    doubting_since: Option<f64>,
}

impl FlowGate {
    /// A gate with no history (it accepts the first sample).
    pub fn new(p: FlowGateParams) -> Self {
        FlowGate {
            p,
            reference: None,
            doubting_since: None,
        }
    }

    /// The gate with a prior direction `toward` as its history: the first samples are judged
    /// against it (a current meter that reads reversed from the start is held back like one that
    /// turns later), and the first plausible sample replaces it. A zero or non-finite `toward`
    /// leaves the gate without history.
    pub fn with_reference(mut self, toward: Vec2) -> Self {
        let n = toward.norm();
        if n.is_finite() && n > 0.0 {
            // Only the direction is judged; the time makes the first sample replace it whole.
            self.reference = Some((f64::NEG_INFINITY, toward / n));
        }
        self
    }

    /// Whether the sample `v_mps` taken at `t_s` is plausible (to be used); non-finite samples
    /// never are.
    pub fn accept(&mut self, t_s: f64, v_mps: Vec2) -> bool {
        if !(v_mps.x.is_finite() && v_mps.y.is_finite() && t_s.is_finite()) {
            return false;
        }
        let Some((t0, r)) = self.reference else {
            self.reference = Some((t_s, v_mps));
            return true;
        };
        let judged = v_mps.norm() > self.p.min_speed_mps && r.norm() > self.p.min_speed_mps;
        if !judged && let Some(since) = self.doubting_since {
            // Too slow to judge while readings are being held back: a reversed reading's noise
            // would pass as a slack current. Held back too, and the doubt goes on, until it has
            // lasted persist_s (a current that stays slack is then believed like a lasting
            // change).
            if t_s - since < self.p.persist_s {
                return false;
            }
            self.doubting_since = None;
            self.reference = Some((t_s, v_mps));
            return true;
        }
        let cos = v_mps.dot(&r) / (v_mps.norm() * r.norm()).max(1e-12);
        let implausible = judged && cos < self.p.max_turn_deg.to_radians().cos();
        if implausible {
            let since = *self.doubting_since.get_or_insert(t_s);
            if t_s - since < self.p.persist_s {
                return false;
            }
            // Believed: the reference restarts from this sample.
            self.doubting_since = None;
            self.reference = Some((t_s, v_mps));
            return true;
        }
        self.doubting_since = None;
        let dt = (t_s - t0).max(0.0);
        let a = if self.p.reference_s > 0.0 {
            1.0 - (-dt / self.p.reference_s).exp()
        } else {
            1.0
        };
        self.reference = Some((t_s, r + (v_mps - r) * a));
        true
    }

    /// Whether it is holding samples back now.
    pub fn doubting(&self) -> bool {
        self.doubting_since.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_prior_judges_the_first_samples_and_the_first_plausible_one_replaces_it() {
        let p = FlowGateParams {
            persist_s: 100.0,
            ..FlowGateParams::default()
        };
        let east = Vec2::new(0.2, 0.0);
        let mut g = FlowGate::new(p).with_reference(Vec2::new(1.0, 0.1));
        for k in 0..100 {
            assert!(
                !g.accept(f64::from(k), -east),
                "reversed from the start, t = {k}"
            );
        }
        let mut g = FlowGate::new(p).with_reference(Vec2::new(1.0, 0.1));
        assert!(g.accept(0.0, east));
        // The history is now the sample: a turn of 80 deg from the prior's direction that is
        // 90+ from the sample's is held back.
        assert!(!g.accept(1.0, Vec2::new(-0.01, 0.2)));
        // No prior: the first sample is believed.
        let mut g = FlowGate::new(p).with_reference(Vec2::zeros());
        assert!(g.accept(0.0, -east));
    }

    #[test]
    fn a_reversal_is_held_back_a_slow_turn_passes_and_a_lasting_change_is_believed() {
        let mut g = FlowGate::new(FlowGateParams {
            persist_s: 100.0,
            ..FlowGateParams::default()
        });
        let east = Vec2::new(0.2, 0.0);
        for k in 0..60 {
            assert!(g.accept(f64::from(k), east));
        }
        // Reversed for 50 s: held back; then back to normal.
        for k in 60..110 {
            assert!(!g.accept(f64::from(k), -east), "t = {k}");
        }
        assert!(g.accept(110.0, east) && !g.doubting());
        // A tide turning 90 degrees over an hour passes sample by sample.
        for k in 0..3600 {
            let a = f64::from(k) / 3600.0 * std::f64::consts::FRAC_PI_2;
            let v = Vec2::new(a.cos(), a.sin()) * 0.2;
            assert!(g.accept(111.0 + f64::from(k), v), "turning, {k} s in");
        }
        // A lasting reversal is believed after 100 s.
        let t0 = 4001.0;
        let north = Vec2::new(0.0, 0.2);
        for k in 0..100 {
            assert!(!g.accept(t0 + f64::from(k), -north));
        }
        assert!(g.accept(t0 + 100.0, -north));
        assert!(g.accept(t0 + 101.0, -north));
        assert!(!g.accept(t0 + 102.0, Vec2::new(f64::NAN, 0.0)));
        // Slack water is not judged.
        assert!(g.accept(t0 + 103.0, Vec2::new(0.01, 0.0)));
    }

    #[test]
    fn a_slow_sample_while_readings_are_held_back_is_held_back_too() {
        let mut g = FlowGate::new(FlowGateParams::default());
        let v = Vec2::new(0.08, 0.09);
        for k in 0..60 {
            assert!(g.accept(f64::from(k), v));
        }
        // A wrong-layer meter reads the current reversed; its noise now and then gives a sample
        // too slow to judge (this one from a faulty run at 0.1 m/s), which must not pass as the
        // current, nor end the doubt.
        assert!(!g.accept(60.0, -v));
        assert!(!g.accept(61.0, Vec2::new(-0.018, -0.024)));
        assert!(g.doubting());
        assert!(!g.accept(62.0, -v));
        // Slow samples outside a doubt still pass, and a plausible one ends the doubt.
        assert!(g.accept(63.0, v) && !g.doubting());
        assert!(g.accept(64.0, Vec2::new(0.01, 0.0)));
        // A current that goes slack while readings are held back is believed once the doubt
        // has lasted persist_s, as a lasting change is.
        let mut g = FlowGate::new(FlowGateParams {
            persist_s: 100.0,
            ..FlowGateParams::default()
        });
        assert!(g.accept(0.0, v));
        assert!(!g.accept(1.0, -v));
        let slack = Vec2::new(0.01, -0.01);
        for k in 2..101 {
            assert!(!g.accept(f64::from(k), slack), "t = {k}");
        }
        assert!(g.accept(101.0, slack) && !g.doubting());
        assert!(g.accept(102.0, slack));
    }
}
