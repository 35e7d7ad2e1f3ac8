//! The planner's estimate of the current.

use plumetrace_core::{FlowGate, FlowGateParams, Heading, Vec2};

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
}
