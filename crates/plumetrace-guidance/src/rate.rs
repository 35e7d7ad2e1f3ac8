//! Heading-rate filtering: commands never turn faster than the vehicle can.

use plumetrace_core::Heading;

/// Limits how fast the commanded heading may change (10 deg/s on the field vehicle). The filter
/// turns the short way round.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateFilter {
    max_rate_deg_s: f64,
    last: Option<Heading>,
}

impl RateFilter {
    /// A filter with a rate limit in degrees per second (non-finite or negative limits become 0).
    pub fn new(max_rate_deg_s: f64) -> Self {
        let max_rate_deg_s = if max_rate_deg_s.is_finite() && max_rate_deg_s > 0.0 {
            max_rate_deg_s
        } else {
            0.0
        };
        RateFilter {
            max_rate_deg_s,
            last: None,
        }
    }

    /// Starts the filter from the vehicle's current heading.
    pub fn reset(&mut self, heading: Heading) {
        self.last = Some(heading);
    }

    /// The filtered command after `dt_s` seconds; the first call passes the command through unless
    /// the filter was reset to a heading.
    pub fn filter(&mut self, command: Heading, dt_s: f64) -> Heading {
        let out = match self.last {
            None => command,
            Some(last) => {
                let dt = if dt_s.is_finite() && dt_s > 0.0 {
                    dt_s
                } else {
                    0.0
                };
                let max_step = self.max_rate_deg_s * dt;
                let wanted = command.diff_deg(last);
                let step = if wanted.is_finite() {
                    wanted.clamp(-max_step, max_step)
                } else {
                    0.0
                };
                last.turned_deg(step)
            }
        };
        self.last = Some(out);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_rate_and_turns_the_short_way() {
        let mut f = RateFilter::new(10.0);
        f.reset(Heading::from_deg(350.0));
        let h = f.filter(Heading::from_deg(30.0), 1.0);
        assert!((h.deg() - 0.0).abs() < 1e-9, "{}", h.deg());
        let h = f.filter(Heading::from_deg(30.0), 0.5);
        assert!((h.deg() - 5.0).abs() < 1e-9);
        let h = f.filter(Heading::from_deg(7.0), 1.0);
        assert!(
            (h.deg() - 7.0).abs() < 1e-9,
            "reaches a close command exactly"
        );
        let h = f.filter(Heading::from_deg(7.0), f64::NAN);
        assert!((h.deg() - 7.0).abs() < 1e-9);
    }
}
