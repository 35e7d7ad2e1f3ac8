//! Spatially uniform flow that may vary in time (steady, or tidal rotation).

use crate::error::{EnvError, require_finite, require_non_negative, require_positive};
use plumetrace_core::{Heading, Vec2, wrap_deg_180};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// A spatially uniform water velocity as a function of time.
///
/// The tidal form swings the speed between `speed_min_mps` and `speed_max_mps` and the direction
/// (towards which the water moves) between `toward_min_deg` and `toward_max_deg` sinusoidally with
/// the same period and phase, e.g. the Duck 2003 single-source ranges 0.10-0.15 m/s towards
/// 110-147 deg.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum MeanFlow {
    /// Constant velocity.
    Steady {
        /// Speed, m/s.
        speed_mps: f64,
        /// Direction the water moves towards, compass degrees.
        toward_deg: f64,
    },
    /// Sinusoidal variation of speed and direction.
    Tidal {
        /// Lowest speed, m/s.
        speed_min_mps: f64,
        /// Highest speed, m/s.
        speed_max_mps: f64,
        /// One end of the direction swing, compass degrees.
        toward_min_deg: f64,
        /// The other end of the direction swing (reached clockwise from `toward_min_deg`), degrees.
        toward_max_deg: f64,
        /// Period of the variation, s.
        period_s: f64,
        /// Phase at t = 0, degrees (0: half way, rising).
        phase_deg: f64,
    },
}

impl MeanFlow {
    /// Checks the parameters; errors name the field (`speed_mps`).
    pub fn validate(&self) -> Result<(), EnvError> {
        match *self {
            MeanFlow::Steady {
                speed_mps,
                toward_deg,
            } => {
                require_non_negative("speed_mps", speed_mps)?;
                require_finite("toward_deg", toward_deg)
            }
            MeanFlow::Tidal {
                speed_min_mps,
                speed_max_mps,
                toward_min_deg,
                toward_max_deg,
                period_s,
                phase_deg,
            } => {
                require_non_negative("speed_min_mps", speed_min_mps)?;
                require_non_negative("speed_max_mps", speed_max_mps)?;
                if speed_max_mps < speed_min_mps {
                    return Err(EnvError::invalid(
                        "speed_max_mps",
                        format!("must be >= speed_min_mps ({speed_min_mps}), got {speed_max_mps}"),
                    ));
                }
                require_finite("toward_min_deg", toward_min_deg)?;
                require_finite("toward_max_deg", toward_max_deg)?;
                require_positive("period_s", period_s)?;
                require_finite("phase_deg", phase_deg)
            }
        }
    }

    /// Water velocity `(east, north)` at time `t_s`.
    pub fn velocity_at(&self, t_s: f64) -> Vec2 {
        match *self {
            MeanFlow::Steady {
                speed_mps,
                toward_deg,
            } => Heading::from_deg(toward_deg).unit() * speed_mps,
            MeanFlow::Tidal {
                speed_min_mps,
                speed_max_mps,
                toward_min_deg,
                toward_max_deg,
                period_s,
                phase_deg,
            } => {
                let s = (TAU * t_s / period_s + phase_deg.to_radians()).sin();
                let speed = 0.5 * (speed_min_mps + speed_max_mps)
                    + 0.5 * (speed_max_mps - speed_min_mps) * s;
                let swing = wrap_deg_180(toward_max_deg - toward_min_deg);
                let dir = toward_min_deg + 0.5 * swing + 0.5 * swing * s;
                Heading::from_deg(dir).unit() * speed
            }
        }
    }

    /// The largest speed the mean flow reaches, m/s.
    pub fn max_speed_mps(&self) -> f64 {
        match *self {
            MeanFlow::Steady { speed_mps, .. } => speed_mps,
            MeanFlow::Tidal { speed_max_mps, .. } => speed_max_mps,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tidal_stays_in_its_ranges() {
        let m = MeanFlow::Tidal {
            speed_min_mps: 0.10,
            speed_max_mps: 0.15,
            toward_min_deg: 110.0,
            toward_max_deg: 147.0,
            period_s: 3600.0,
            phase_deg: 0.0,
        };
        assert!(m.validate().is_ok());
        let (mut smin, mut smax, mut dmin, mut dmax) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for k in 0..3600 {
            let v = m.velocity_at(f64::from(k));
            let s = v.norm();
            let d = Heading::of_vector(v).map(Heading::deg).unwrap_or(f64::NAN);
            smin = smin.min(s);
            smax = smax.max(s);
            dmin = dmin.min(d);
            dmax = dmax.max(d);
        }
        assert!(
            (smin - 0.10).abs() < 1e-4 && (smax - 0.15).abs() < 1e-4,
            "speed range {smin}..{smax}"
        );
        assert!(
            (dmin - 110.0).abs() < 0.1 && (dmax - 147.0).abs() < 0.1,
            "direction range {dmin}..{dmax}"
        );
    }

    #[test]
    fn tidal_swing_across_north_is_short_way() {
        let m = MeanFlow::Tidal {
            speed_min_mps: 1.0,
            speed_max_mps: 1.0,
            toward_min_deg: 350.0,
            toward_max_deg: 10.0,
            period_s: 100.0,
            phase_deg: 0.0,
        };
        for k in 0..100 {
            let d = Heading::of_vector(m.velocity_at(f64::from(k)))
                .map(Heading::deg)
                .unwrap_or(f64::NAN);
            assert!(
                !(10.01..349.99).contains(&d),
                "direction {d} left the 350..10 swing"
            );
        }
    }

    #[test]
    fn rejects_bad_ranges() {
        let m = MeanFlow::Tidal {
            speed_min_mps: 0.2,
            speed_max_mps: 0.1,
            toward_min_deg: 0.0,
            toward_max_deg: 10.0,
            period_s: 100.0,
            phase_deg: 0.0,
        };
        let e = m
            .validate()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.starts_with("speed_max_mps:"), "{e}");
        let s = MeanFlow::Steady {
            speed_mps: -1.0,
            toward_deg: 0.0,
        };
        assert!(s.validate().is_err());
    }
}
