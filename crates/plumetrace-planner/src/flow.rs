//! The planner's estimate of the current: from a current meter ([`FlowEstimate`]) or, without
//! one, from the vehicle's own track ([`TrackFlow`]).

use plumetrace_core::{FlowGate, FlowGateParams, Heading, NavEstimate, Vec2};

/// A running average of measured flow vectors (exponential, with a time constant), so that single
/// noisy ADCP samples do not swing the upflow direction; optionally behind a [`FlowGate`] that
/// holds back readings implausible against the recent ones (a reversed, wrong-layer reading).
#[derive(Debug, Clone, PartialEq)]
pub struct FlowEstimate {
    time_constant_s: f64,
    mean_mps: Option<Vec2>,
    last_t_s: f64,
    fallback: Heading,
    gate: Option<FlowGate>,
}

impl FlowEstimate {
    /// An estimate with time constant `time_constant_s`; until the first measurement the flow is
    /// taken to go towards `fallback`.
    pub fn new(time_constant_s: f64, fallback: Heading) -> Self {
        FlowEstimate {
            time_constant_s: time_constant_s.max(0.0),
            mean_mps: None,
            last_t_s: 0.0,
            fallback,
            gate: None,
        }
    }

    /// The same estimate with readings checked by a [`FlowGate`] first.
    pub fn with_gate(mut self, gate: FlowGateParams) -> Self {
        self.gate = Some(FlowGate::new(gate));
        self
    }

    /// The same estimate with its gate (if any) judging the first readings against the
    /// fallback direction (a prior that was given, not assumed).
    pub fn trusting_fallback(mut self) -> Self {
        let toward = self.fallback.unit();
        self.gate = self.gate.map(|g| g.with_reference(toward));
        self
    }

    /// Whether the gate is holding readings back now.
    pub fn doubting(&self) -> bool {
        self.gate.as_ref().is_some_and(FlowGate::doubting)
    }

    /// Adds a measurement taken at `t_s` (non-finite ones, and those the gate holds back, are
    /// ignored).
    pub fn add(&mut self, t_s: f64, v_mps: Vec2) {
        if !(v_mps.x.is_finite() && v_mps.y.is_finite() && t_s.is_finite()) {
            return;
        }
        if let Some(g) = self.gate.as_mut()
            && !g.accept(t_s, v_mps)
        {
            return;
        }
        self.mean_mps = Some(match self.mean_mps {
            None => v_mps,
            Some(m) => {
                let dt = (t_s - self.last_t_s).max(0.0);
                let a = if self.time_constant_s > 0.0 {
                    1.0 - (-dt / self.time_constant_s).exp()
                } else {
                    1.0
                };
                m + (v_mps - m) * a
            }
        });
        self.last_t_s = t_s;
    }

    /// The mean flow velocity, m/s (zero before any measurement).
    pub fn velocity_mps(&self) -> Vec2 {
        self.mean_mps.unwrap_or_else(Vec2::zeros)
    }

    /// The direction the water goes towards, `psi_f`.
    pub fn toward(&self) -> Heading {
        self.mean_mps
            .and_then(Heading::of_vector)
            .unwrap_or(self.fallback)
    }

    /// Upflow, `psi_u = psi_f + 180`.
    pub fn upflow(&self) -> Heading {
        self.toward().reversed()
    }
}

/// The settings of a [`TrackFlow`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackFlowParams {
    /// Length of the window over which one sample of the current is measured, s.
    pub window_s: f64,
    /// Samples slower than this are not used (they carry no direction), m/s.
    pub min_mps: f64,
    /// Samples faster than this are not used (a bad fix), m/s.
    pub max_mps: f64,
}

/// The largest gap between two navigation records bridged: over a longer one (a silent
/// navigation link) the water-relative displacement is unknown, and the window starts again.
const MAX_RECORD_GAP_S: f64 = 10.0;

/// The current as the vehicle's own track shows it, for a vehicle without a current meter: the
/// velocity over the ground (navigation positions over time) minus the velocity through the water
/// (measured heading and water speed). It uses nothing a real vehicle lacks.
///
/// Two navigations are met and both are read right. One dead-reckons with a measured current or
/// bottom-tracks (its positions follow the ground between fixes): the current is the drift of the
/// positions against the water track. The other dead-reckons through the water alone: its positions
/// drift with the water and the current shows only as the jump at each position fix, so the jump
/// divided by the time since the previous fix (or the first record) is the current's share the
/// drift missed. The estimate is the drift over the last window plus the fix correction (an
/// exponential mean of the jumps' velocities with the window as time constant, so frequent GPS
/// fixes, whose jumps are mostly fix noise, average out). One sample comes out per window; the
/// planner filters them as it would a current meter's readings.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackFlow {
    p: TrackFlowParams,
    /// The previous record: time, position, water velocity.
    last: Option<(f64, Vec2, Vec2)>,
    /// The last fix seen, and the time the fix correction counts from.
    last_fix_s: Option<f64>,
    since_fix_s: f64,
    /// Start of the window, and the drift displacement and time summed over it (steps without a
    /// fix).
    window_start_s: f64,
    drift_m: Vec2,
    drift_s: f64,
    /// The drift velocity of the last window (for the fix step's own share), m/s.
    last_drift_mps: Vec2,
    /// The fix correction, m/s.
    correction_mps: Vec2,
}

impl TrackFlow {
    /// An estimator that has seen nothing yet.
    pub fn new(p: TrackFlowParams) -> Self {
        TrackFlow {
            p,
            last: None,
            last_fix_s: None,
            since_fix_s: 0.0,
            window_start_s: 0.0,
            drift_m: Vec2::zeros(),
            drift_s: 0.0,
            last_drift_mps: Vec2::zeros(),
            correction_mps: Vec2::zeros(),
        }
    }

    /// Takes one navigation record at `t_s`; returns a sample of the current, m/s, when a window
    /// ends with one that is usable (between `min_mps` and `max_mps`). Records without a position,
    /// out of time order or non-finite are skipped.
    pub fn add(&mut self, t_s: f64, nav: &NavEstimate) -> Option<Vec2> {
        let pos = nav.pos_m?;
        let water = nav.heading.unit() * nav.speed_mps;
        let finite = [t_s, pos.x, pos.y, water.x, water.y];
        if !finite.iter().all(|v| v.is_finite()) {
            return None;
        }
        let fixed = nav
            .last_fix_s
            .is_some_and(|f| self.last_fix_s.is_none_or(|l| f > l));
        if fixed {
            self.last_fix_s = nav.last_fix_s;
        }
        let Some((t0, p0, w0)) = self.last.replace((t_s, pos, water)) else {
            self.restart(t_s);
            self.since_fix_s = t_s;
            return None;
        };
        let dt = t_s - t0;
        if dt <= 0.0 || dt > MAX_RECORD_GAP_S {
            self.restart(t_s);
            if fixed {
                self.since_fix_s = t_s;
            }
            return None;
        }
        // What the water track does not explain.
        let residual = (pos - p0) - (water + w0) * (0.5 * dt);
        if fixed {
            let interval = (t_s - self.since_fix_s).max(dt);
            let jump_mps = (residual - self.last_drift_mps * dt) / interval;
            let a = 1.0 - (-interval / self.p.window_s.max(1e-9)).exp();
            self.correction_mps = self.correction_mps + (jump_mps - self.correction_mps) * a;
            self.since_fix_s = t_s;
        } else {
            self.drift_m += residual;
            self.drift_s += dt;
        }
        if t_s - self.window_start_s < self.p.window_s {
            return None;
        }
        if self.drift_s > 0.0 {
            self.last_drift_mps = self.drift_m / self.drift_s;
        }
        self.restart(t_s);
        let sample = self.last_drift_mps + self.correction_mps;
        let speed = sample.norm();
        (speed.is_finite() && speed >= self.p.min_mps && speed <= self.p.max_mps).then_some(sample)
    }

    fn restart(&mut self, t_s: f64) {
        self.window_start_s = t_s;
        self.drift_m = Vec2::zeros();
        self.drift_s = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn averages_and_falls_back() {
        let mut f = FlowEstimate::new(10.0, Heading::from_deg(90.0));
        assert_eq!(f.toward().deg(), 90.0);
        f.add(0.0, Vec2::new(0.0, 0.1));
        assert!(f.toward().diff_deg(Heading::NORTH).abs() < 1e-9);
        for k in 1..=100 {
            f.add(f64::from(k), Vec2::new(0.1, 0.0));
        }
        assert!(
            f.toward().diff_deg(Heading::from_deg(90.0)).abs() < 0.1,
            "{}",
            f.toward().deg()
        );
        assert!(f.upflow().diff_deg(Heading::from_deg(270.0)).abs() < 0.1);
        f.add(101.0, Vec2::new(f64::NAN, 0.0));
        assert!(f.velocity_mps().x.is_finite());
    }

    /// A vehicle crossing a 0.3 m/s current toward 45 deg on a square track at 1.5 m/s through
    /// the water, recorded every 0.5 s: `dr_current` true dead-reckons with the current (the
    /// positions follow the ground), false through the water alone with a fix every
    /// `fix_every_s` putting it back on the truth.
    fn fly(dr_current: bool, fix_every_s: f64, until_s: f64) -> Vec<(f64, Vec2)> {
        let current = Heading::from_deg(45.0).unit() * 0.3;
        let mut f = TrackFlow::new(TrackFlowParams {
            window_s: 60.0,
            min_mps: 0.05,
            max_mps: 3.0,
        });
        let (mut truth, mut est) = (Vec2::zeros(), Vec2::zeros());
        let mut last_fix = None;
        let mut out = Vec::new();
        let dt = 0.5;
        for k in 0..=((until_s / dt) as usize) {
            let t = k as f64 * dt;
            let heading = Heading::from_deg(90.0 * ((t / 100.0).floor() % 4.0));
            let water = heading.unit() * 1.5;
            if k > 0 {
                truth += (water + current) * dt;
                est += if dr_current { water + current } else { water } * dt;
                if !dr_current && (t / fix_every_s).fract() < 1e-9 {
                    est = truth;
                    last_fix = Some(t);
                }
            }
            let nav = NavEstimate {
                pos_m: Some(est),
                heading,
                speed_mps: 1.5,
                altitude_m: None,
                depth_m: None,
                last_fix_s: last_fix,
            };
            if let Some(v) = f.add(t, &nav) {
                out.push((t, v));
            }
        }
        out
    }

    #[test]
    fn track_flow_reads_the_current_from_drift_and_from_fix_jumps() {
        for (dr_current, label) in [(true, "drift"), (false, "fix jumps")] {
            let samples = fly(dr_current, 200.0, 2000.0);
            let late: Vec<_> = samples.iter().filter(|(t, _)| *t > 500.0).collect();
            assert!(late.len() >= 20, "{label}: {} samples", late.len());
            for (t, v) in late {
                assert!(
                    (v.norm() - 0.3).abs() < 0.08
                        && Heading::of_vector(*v)
                            .is_some_and(|h| h.diff_deg(Heading::from_deg(45.0)).abs() < 15.0),
                    "{label}: {v:?} at {t} s"
                );
            }
        }
    }

    #[test]
    fn track_flow_says_nothing_before_a_fix_shows_the_current() {
        // Dead reckoning through the water alone: before the first fix the track shows no
        // current, and no (slow, directionless) sample comes out.
        let samples = fly(false, 400.0, 390.0);
        assert!(samples.is_empty(), "{samples:?}");
    }

    #[test]
    fn track_flow_skips_gaps_and_bad_records() {
        let mut f = TrackFlow::new(TrackFlowParams {
            window_s: 10.0,
            min_mps: 0.0,
            max_mps: 3.0,
        });
        let nav = |x: f64| NavEstimate {
            pos_m: Some(Vec2::new(x, 0.0)),
            heading: Heading::NORTH,
            speed_mps: 0.0,
            altitude_m: None,
            depth_m: None,
            last_fix_s: None,
        };
        assert_eq!(f.add(0.0, &nav(0.0)), None);
        // A 100 m leap across a 60 s silence is not read as a current.
        assert_eq!(f.add(60.0, &nav(100.0)), None);
        assert_eq!(f.add(f64::NAN, &nav(100.0)), None);
        assert_eq!(f.add(61.0, &nav(f64::INFINITY)), None);
        let mut last = None;
        for k in 1..=20 {
            last = f
                .add(60.0 + f64::from(k), &nav(100.0 + 0.2 * f64::from(k)))
                .or(last);
        }
        let v = last.expect("a sample after the gap");
        assert!((v.x - 0.2).abs() < 1e-9 && v.y.abs() < 1e-9, "{v:?}");
    }
}
