//! The follower's filtered range to one leader: a two-state Kalman filter (range and range rate,
//! the rate a random walk driven by white acceleration) on the acoustic ranges, predicted to the
//! present between them.
//!
//! The follower's ranges come every 4 s per leader (requests alternate every 2 s) with 0.3-3 m of
//! timing noise; the formation feedback (14)-(15) on the raw latest range chases that noise, and
//! after a ranging outage it mixes a fresh range to one leader with an old one to the other. On
//! the filtered state both terms use a range predicted to the same time, and a range far outside
//! its prediction (a packet from a stale exchange, a multipath echo) is set aside unless the next
//! ones agree with it.

/// Ranges in a row outside the gate that restart the filter on the latest one.
const RESTART_AFTER: u32 = 3;

/// A filtered range: estimate and rate with their covariance, at `t_s`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct RangeTrack {
    /// Range, m, and range rate, m/s, at `t_s`.
    x: [f64; 2],
    /// Covariance of `x`.
    p: [[f64; 2]; 2],
    t_s: f64,
    /// Time of the last range taken in, s.
    last_s: f64,
    rejected: u32,
    started: bool,
}

/// The filter's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct RangeNoise {
    /// Standard deviation of a range, m.
    pub measurement_sd_m: f64,
    /// Standard deviation of the white acceleration of the range, m/s^2.
    pub accel_sd_mps2: f64,
    /// Innovations beyond this many standard deviations are set aside.
    pub gate_sigmas: f64,
}

impl Default for RangeTrack {
    fn default() -> Self {
        RangeTrack {
            x: [0.0; 2],
            p: [[0.0; 2]; 2],
            t_s: 0.0,
            last_s: f64::NEG_INFINITY,
            rejected: 0,
            started: false,
        }
    }
}

impl RangeTrack {
    /// The state predicted to `t_s` (the rate constant, the covariance grown).
    fn predicted(&self, n: &RangeNoise, t_s: f64) -> ([f64; 2], [[f64; 2]; 2]) {
        let dt = (t_s - self.t_s).max(0.0);
        let q = n.accel_sd_mps2 * n.accel_sd_mps2;
        let p = self.p;
        let x = [self.x[0] + self.x[1] * dt, self.x[1]];
        let p00 = p[0][0] + 2.0 * dt * p[0][1] + dt * dt * p[1][1] + q * dt.powi(3) / 3.0;
        let p01 = p[0][1] + dt * p[1][1] + q * dt * dt / 2.0;
        let p11 = p[1][1] + q * dt;
        (x, [[p00, p01], [p01, p11]])
    }

    /// Takes in a range `z_m` measured at `t_s`; false when it was set aside.
    pub fn update(&mut self, n: &RangeNoise, t_s: f64, z_m: f64) -> bool {
        let r = n.measurement_sd_m * n.measurement_sd_m;
        if !self.started || self.rejected >= RESTART_AFTER {
            // A range rate of at most the vehicles' speeds, about 1 m/s, until ranges tell.
            *self = RangeTrack {
                x: [z_m, 0.0],
                p: [[r, 0.0], [0.0, 1.0]],
                t_s,
                last_s: t_s,
                rejected: 0,
                started: true,
            };
            return true;
        }
        let (x, p) = self.predicted(n, t_s);
        let s = p[0][0] + r;
        let y = z_m - x[0];
        if y * y > n.gate_sigmas * n.gate_sigmas * s {
            self.rejected += 1;
            return false;
        }
        let k = [p[0][0] / s, p[0][1] / s];
        self.x = [x[0] + k[0] * y, x[1] + k[1] * y];
        self.p = [
            [(1.0 - k[0]) * p[0][0], (1.0 - k[0]) * p[0][1]],
            [(1.0 - k[0]) * p[0][1], p[1][1] - k[1] * p[0][1]],
        ];
        self.t_s = t_s;
        self.last_s = t_s;
        self.rejected = 0;
        true
    }

    /// The range predicted to `t_s`, if a range was ever taken in.
    pub fn range_at(&self, n: &RangeNoise, t_s: f64) -> Option<f64> {
        self.started.then(|| self.predicted(n, t_s).0[0])
    }

    /// Time of the last range taken in (minus infinity before the first).
    pub fn last_s(&self) -> f64 {
        self.last_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const NOISE: RangeNoise = RangeNoise {
        measurement_sd_m: 1.0,
        accel_sd_mps2: 0.02,
        gate_sigmas: 4.0,
    };

    #[test]
    fn a_steady_range_rate_is_tracked_and_predicted_between_ranges() {
        let mut t = RangeTrack::default();
        assert_eq!(t.range_at(&NOISE, 0.0), None);
        // The range opens at 0.1 m/s from 10 m; ranges every 4 s, noise +-1 m alternating.
        for k in 0..40 {
            let ts = 4.0 * k as f64;
            let noise = if k % 2 == 0 { 1.0 } else { -1.0 };
            assert!(t.update(&NOISE, ts, 10.0 + 0.1 * ts + noise));
        }
        let at = t.range_at(&NOISE, 158.0).unwrap_or(f64::NAN);
        assert!((at - 25.8).abs() < 0.6, "{at}");
    }

    #[test]
    fn an_outlier_is_set_aside_and_a_lasting_jump_restarts_the_filter() {
        let mut t = RangeTrack::default();
        for k in 0..20 {
            t.update(&NOISE, 4.0 * k as f64, 10.0);
        }
        assert!(!t.update(&NOISE, 80.0, 40.0), "30 m off: set aside");
        assert!(t.update(&NOISE, 84.0, 10.2));
        for k in 0..RESTART_AFTER {
            assert!(!t.update(&NOISE, 88.0 + f64::from(k), 30.0));
        }
        assert!(t.update(&NOISE, 92.0, 30.0), "the jump lasted: restarted");
        assert_eq!(t.range_at(&NOISE, 92.0), Some(30.0));
    }
}
