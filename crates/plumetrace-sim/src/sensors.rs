//! Sensors: chemical (an analog reading, or salinity over a freshwater plume), flow and obstacle
//! range.

use plumetrace_core::{ChemSample, FlowSample, Heading, RangeReturn, Vec2};
use plumetrace_env::error::{require_non_negative, require_positive};
use plumetrace_env::{EnvError, ObstacleSet, SimRng};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// A periodic sampling schedule: samples at `k / rate` seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Schedule {
    period_s: f64,
    next_k: u64,
}

impl Schedule {
    fn new(rate_hz: f64) -> Self {
        Schedule {
            period_s: 1.0 / rate_hz,
            next_k: 0,
        }
    }

    /// Whether a sample is due at `t_s` (at most one per call; missed samples are skipped).
    fn due(&mut self, t_s: f64) -> bool {
        let next = self.next_k as f64 * self.period_s;
        if t_s + 1e-9 < next {
            return false;
        }
        self.next_k = ((t_s + 1e-9) / self.period_s).floor() as u64 + 1;
        true
    }
}

/// Parameters of the chemical sensor. Defaults: the field sensor, 10 Hz, 5 V full scale. The
/// sensor reports readings; what counts as a detection is the planner's threshold.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ChemSensorParams {
    /// Sampling rate, Hz.
    pub rate_hz: f64,
    /// Volts per unit of concentration.
    pub volts_per_unit: f64,
    /// Full scale, V (readings saturate there).
    pub full_scale_v: f64,
    /// Reading noise (standard deviation), V.
    pub noise_sd_v: f64,
    /// First-order lag of the sensor, s (0 = none).
    pub lag_time_constant_s: f64,
    /// A salinity probe instead of the analog chemical sensor (the volts keys then do not
    /// apply).
    #[serde(default)]
    pub salinity: Option<SalinityParams>,
}

/// A conductivity-temperature salinity probe over a freshwater plume.
///
/// The field's concentration is fresh water in kg per m^3; the fresh fraction `f = c / rho_f`
/// dilutes the medium, `S = S_medium (1 - f)`, and the probe reports `S + |n|` with `n` normal
/// of standard deviation `noise_sd_ppt` (half-normal noise), saturated at `S_medium`: fresh
/// water never raises the salinity, so no reading exceeds the medium's.
///
/// With `deficit` the probe reports the salinity contrast instead, `S_medium - (S + |n|)`
/// (the same probe's reading below the ambient, `S_medium f` less the noise, in `[0, S_medium]`):
/// the scalar a formation leader computes from the salinity by eq. (1), and a concentration that
/// grows into the plume for planners that trace one (a CTD-carrying AUV whose planner is told the
/// ambient salinity).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SalinityParams {
    /// Salinity of the medium, ppt.
    pub medium_ppt: f64,
    /// Density of the fresh water, kg/m^3.
    pub fresh_density_kgpm3: f64,
    /// Noise (the scale of the half-normal), ppt.
    pub noise_sd_ppt: f64,
    /// Report the deficit below the medium's salinity instead of the salinity.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub deficit: bool,
}

impl Default for SalinityParams {
    /// The formation-tracing case: 35 ppt sea water, 998.2 kg/m^3 fresh water, sigma 0.1 ppt.
    fn default() -> Self {
        SalinityParams {
            medium_ppt: 35.0,
            fresh_density_kgpm3: 998.2,
            noise_sd_ppt: 0.1,
            deficit: false,
        }
    }
}

impl Default for ChemSensorParams {
    fn default() -> Self {
        ChemSensorParams {
            rate_hz: 10.0,
            volts_per_unit: 1.0,
            full_scale_v: 5.0,
            noise_sd_v: 0.02,
            lag_time_constant_s: 0.0,
            salinity: None,
        }
    }
}

impl ChemSensorParams {
    /// Checks every parameter; errors name the field.
    pub fn validate(&self) -> Result<(), EnvError> {
        require_positive("rate_hz", self.rate_hz)?;
        require_positive("volts_per_unit", self.volts_per_unit)?;
        require_positive("full_scale_v", self.full_scale_v)?;
        require_non_negative("noise_sd_v", self.noise_sd_v)?;
        require_non_negative("lag_time_constant_s", self.lag_time_constant_s)?;
        if let Some(s) = &self.salinity {
            require_positive("medium_salinity_ppt", s.medium_ppt)?;
            require_positive("fresh_density_kgpm3", s.fresh_density_kgpm3)?;
            require_non_negative("noise_sd_ppt", s.noise_sd_ppt)?;
        }
        Ok(())
    }
}

/// The chemical sensor: an analog reading with noise, lag and saturation.
#[derive(Debug, Clone, PartialEq)]
pub struct ChemSensor {
    params: ChemSensorParams,
    schedule: Schedule,
    lagged_v: f64,
    last_t_s: Option<f64>,
}

impl ChemSensor {
    /// A sensor whose first sample is at t = 0.
    pub fn new(params: ChemSensorParams) -> Self {
        ChemSensor {
            params,
            schedule: Schedule::new(params.rate_hz),
            lagged_v: 0.0,
            last_t_s: None,
        }
    }

    /// The parameters.
    pub fn params(&self) -> &ChemSensorParams {
        &self.params
    }

    /// Whether a sample is due at `t_s`; if so the caller must call [`ChemSensor::sample`].
    pub fn due(&mut self, t_s: f64) -> bool {
        self.schedule.due(t_s)
    }

    /// A sample of `concentration` (taken at the sensor's true position) at `t_s`.
    pub fn sample(&mut self, concentration: f64, t_s: f64, rng: &mut SimRng) -> ChemSample {
        let p = self.params;
        if let Some(s) = p.salinity {
            let fresh = (concentration / s.fresh_density_kgpm3).clamp(0.0, 1.0);
            let n: f64 = StandardNormal.sample(rng);
            let reading =
                (s.medium_ppt * (1.0 - fresh) + s.noise_sd_ppt * n.abs()).clamp(0.0, s.medium_ppt);
            let reading = if reading.is_finite() {
                reading
            } else {
                s.medium_ppt
            };
            return ChemSample {
                time_s: t_s,
                reading: if s.deficit {
                    s.medium_ppt - reading
                } else {
                    reading
                },
            };
        }
        let raw = p.volts_per_unit * concentration.max(0.0);
        self.lagged_v = match (self.last_t_s, p.lag_time_constant_s > 0.0) {
            (Some(t0), true) => {
                self.lagged_v
                    + (raw - self.lagged_v)
                        * (1.0 - (-(t_s - t0).max(0.0) / p.lag_time_constant_s).exp())
            }
            _ => raw,
        };
        self.last_t_s = Some(t_s);
        let n: f64 = StandardNormal.sample(rng);
        let reading = (self.lagged_v + p.noise_sd_v * n).clamp(0.0, p.full_scale_v);
        let reading = if reading.is_finite() { reading } else { 0.0 };
        ChemSample {
            time_s: t_s,
            reading,
        }
    }
}

/// A window during which the flow sensor measures the wrong layer (the reading is reversed).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FlowFault {
    /// Start, s.
    pub start_s: f64,
    /// End, s.
    pub end_s: f64,
}

/// Parameters of the flow sensor (ADCP-like).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FlowSensorParams {
    /// Sampling rate, Hz.
    pub rate_hz: f64,
    /// Noise per axis (standard deviation), m/s.
    pub noise_sd_mps: f64,
    /// Constant bias `(east, north)`, m/s.
    pub bias_mps: [f64; 2],
    /// Wrong-layer fault window, if any.
    pub fault: Option<FlowFault>,
}

impl Default for FlowSensorParams {
    fn default() -> Self {
        FlowSensorParams {
            rate_hz: 1.0,
            noise_sd_mps: 0.02,
            bias_mps: [0.0, 0.0],
            fault: None,
        }
    }
}

impl FlowSensorParams {
    /// Checks every parameter; errors name the field.
    pub fn validate(&self) -> Result<(), EnvError> {
        require_positive("rate_hz", self.rate_hz)?;
        require_non_negative("noise_sd_mps", self.noise_sd_mps)?;
        if !(self.bias_mps[0].is_finite() && self.bias_mps[1].is_finite()) {
            return Err(EnvError::invalid("bias_mps", "must be finite"));
        }
        if let Some(f) = self.fault
            && !(f.start_s.is_finite() && f.end_s.is_finite() && f.end_s >= f.start_s)
        {
            return Err(EnvError::invalid(
                "fault_end_s",
                "needs finite fault_start_s <= fault_end_s",
            ));
        }
        Ok(())
    }
}

/// The flow sensor.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowSensor {
    params: FlowSensorParams,
    schedule: Schedule,
}

impl FlowSensor {
    /// A sensor whose first sample is at t = 0.
    pub fn new(params: FlowSensorParams) -> Self {
        FlowSensor {
            params,
            schedule: Schedule::new(params.rate_hz),
        }
    }

    /// Whether a sample is due at `t_s`.
    pub fn due(&mut self, t_s: f64) -> bool {
        self.schedule.due(t_s)
    }

    /// A measurement of the true local flow at `t_s`.
    pub fn sample(&self, true_flow_mps: Vec2, t_s: f64, rng: &mut SimRng) -> FlowSample {
        let p = self.params;
        let (nx, ny): (f64, f64) = (StandardNormal.sample(rng), StandardNormal.sample(rng));
        let faulty = p.fault.is_some_and(|f| t_s >= f.start_s && t_s < f.end_s);
        let base = if faulty {
            -true_flow_mps
        } else {
            true_flow_mps + Vec2::new(p.bias_mps[0], p.bias_mps[1])
        };
        FlowSample {
            time_s: t_s,
            velocity_mps: base + Vec2::new(nx, ny) * p.noise_sd_mps,
        }
    }
}

/// Parameters of the obstacle range sensors: three groups of rays (front, left, right), pinged
/// together at `rate_hz`. Defaults: a small forward-looking sonar; kelp is a weak, patchy target,
/// so each ray sees each obstacle it crosses with `detection_probability` at each ping.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RangeSensorParams {
    /// Detection range `R`, m (20: the "far" of the front group).
    pub max_range_m: f64,
    /// Rays per group (7).
    pub rays_per_group: usize,
    /// The front group covers +-this angle about the heading, deg (30).
    pub front_half_angle_deg: f64,
    /// The side groups reach this far from the heading, deg (90).
    pub side_outer_angle_deg: f64,
    /// Pings per second, Hz (5).
    pub rate_hz: f64,
    /// Range noise (standard deviation), m (0.2).
    pub noise_sd_m: f64,
    /// Probability that one ray sees one obstacle it crosses at one ping (0.8).
    pub detection_probability: f64,
}

impl Default for RangeSensorParams {
    fn default() -> Self {
        RangeSensorParams {
            max_range_m: 20.0,
            rays_per_group: 7,
            front_half_angle_deg: 30.0,
            side_outer_angle_deg: 90.0,
            rate_hz: 5.0,
            noise_sd_m: 0.2,
            detection_probability: 0.8,
        }
    }
}

impl RangeSensorParams {
    /// The most rays per group: rays are cast at every step.
    pub const MAX_RAYS_PER_GROUP: usize = 1000;

    /// Checks every parameter; errors name the field (`rate_hz`).
    pub fn validate(&self) -> Result<(), EnvError> {
        require_positive("rate_hz", self.rate_hz)?;
        require_non_negative("noise_sd_m", self.noise_sd_m)?;
        if !(self.detection_probability > 0.0 && self.detection_probability <= 1.0) {
            return Err(EnvError::invalid(
                "detection_probability",
                "must be in (0, 1]",
            ));
        }
        require_positive("max_range_m", self.max_range_m)?;
        if !(1..=Self::MAX_RAYS_PER_GROUP).contains(&self.rays_per_group) {
            return Err(EnvError::invalid(
                "rays_per_group",
                format!("must be 1..={}", Self::MAX_RAYS_PER_GROUP),
            ));
        }
        if !(self.front_half_angle_deg > 0.0
            && self.side_outer_angle_deg > self.front_half_angle_deg
            && self.side_outer_angle_deg <= 180.0)
        {
            return Err(EnvError::invalid(
                "side_outer_angle_deg",
                "needs 0 < front_half_angle_deg < side_outer_angle_deg <= 180",
            ));
        }
        Ok(())
    }
}

/// The obstacle range sensors: the nearest obstacle distance in each group (seed 001, eq. 8).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RangeSensor {
    /// Parameters.
    pub params: RangeSensorParams,
    schedule: Schedule,
}

impl RangeSensor {
    /// A sensor whose first ping is at t = 0.
    pub fn new(params: RangeSensorParams) -> Self {
        RangeSensor {
            params,
            schedule: Schedule::new(params.rate_hz),
        }
    }

    /// Whether a ping is due at `t_s` (call once per step).
    pub fn due(&mut self, t_s: f64) -> bool {
        self.schedule.due(t_s)
    }

    /// One ping from `pos_m` with the vehicle on `heading`: along each ray, every obstacle it
    /// crosses within range is seen with the detection probability (a draw per ray and
    /// obstacle); a group reports its nearest seen edge plus noise (never below 0, and a range
    /// pushed beyond `max_range_m` by the noise is reported at `max_range_m`).
    pub fn sample(
        &self,
        obstacles: &ObstacleSet,
        pos_m: Vec2,
        heading: Heading,
        rng: &mut SimRng,
    ) -> RangeReturn {
        let p = self.params;
        let n = p.rays_per_group.max(1);
        let angle = |from: f64, to: f64, k: usize| {
            if n == 1 {
                0.5 * (from + to)
            } else {
                from + (to - from) * k as f64 / (n - 1) as f64
            }
        };
        let nearest = |from: f64, to: f64, rng: &mut SimRng| -> Option<f64> {
            let mut best: Option<f64> = None;
            for k in 0..n {
                let a = angle(from, to, k);
                obstacles.ray_hits(pos_m, heading.turned_deg(a), p.max_range_m, |_, d| {
                    let seen = p.detection_probability >= 1.0
                        || rng.random::<f64>() < p.detection_probability;
                    if seen {
                        best = Some(best.map_or(d, |b: f64| b.min(d)));
                    }
                });
            }
            best.map(|d| {
                let noise: f64 = StandardNormal.sample(rng);
                (d + noise * p.noise_sd_m).clamp(0.0, p.max_range_m)
            })
        };
        let (f, s) = (p.front_half_angle_deg, p.side_outer_angle_deg);
        RangeReturn {
            front_m: nearest(-f, f, rng),
            left_m: nearest(-s, -f, rng),
            right_m: nearest(f, s, rng),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_env::{SoftObstacle, StreamId, stream_rng};

    #[test]
    fn schedule_samples_at_the_rate() {
        let mut s = ChemSensor::new(ChemSensorParams::default());
        let due = (0..1000).filter(|k| s.due(f64::from(*k) * 0.01)).count();
        assert_eq!(due, 100, "10 Hz over 10 s of 100 Hz steps");
    }

    #[test]
    fn readings_saturate_and_lag() {
        let mut rng = stream_rng(1, StreamId::Sensor(0, 0));
        let mut s = ChemSensor::new(ChemSensorParams {
            noise_sd_v: 0.0,
            ..ChemSensorParams::default()
        });
        assert_eq!(s.sample(100.0, 0.0, &mut rng).reading, 5.0);
        let mut lag = ChemSensor::new(ChemSensorParams {
            noise_sd_v: 0.0,
            lag_time_constant_s: 1.0,
            ..ChemSensorParams::default()
        });
        lag.sample(0.0, 0.0, &mut rng);
        let r = lag.sample(1.0, 1.0, &mut rng).reading;
        assert!((r - (1.0 - (-1.0f64).exp())).abs() < 1e-12, "{r}");
    }

    #[test]
    fn salinity_is_diluted_by_fresh_water_with_half_normal_noise_saturated_at_the_medium() {
        let mut rng = stream_rng(2, StreamId::Sensor(0, 1));
        let mut s = ChemSensor::new(ChemSensorParams {
            salinity: Some(SalinityParams::default()),
            ..ChemSensorParams::default()
        });
        // Outside the plume every reading is the medium's: the noise only raises salinity.
        assert!((0..100).all(|k| s.sample(0.0, f64::from(k), &mut rng).reading == 35.0));
        // 2.852 kg/m^3 of fresh water: 35 (1 - 2.852 / 998.2) = 34.9 ppt. The half-normal mean
        // is sigma sqrt(2 / pi) = 0.0798; readings above 35 are cut back to 35.
        let n = 20_000;
        let r: Vec<f64> = (0..n)
            .map(|k| s.sample(2.852, f64::from(k), &mut rng).reading)
            .collect();
        assert!(r.iter().all(|x| (34.9 - 1e-9..=35.0).contains(x)));
        let saturated = r.iter().filter(|x| **x == 35.0).count() as f64 / f64::from(n);
        // P(|n| > 0.1 ppt) = P(|z| > 1) = 0.3173.
        assert!((saturated - 0.3173).abs() < 0.015, "{saturated}");
        let mean_below: f64 = r.iter().map(|x| x.min(35.0)).sum::<f64>() / f64::from(n);
        // E[min(34.9 + |n|, 35)] = 34.9 + 0.1 (E[|z|; |z| < 1] + P(|z| > 1)).
        let want =
            34.9 + 0.1 * ((2.0 / std::f64::consts::PI).sqrt() * (1.0 - (-0.5f64).exp()) + 0.3173);
        assert!((mean_below - want).abs() < 0.002, "{mean_below} vs {want}");
    }

    #[test]
    fn salinity_deficit_is_the_same_probe_read_below_the_medium() {
        // The same stream through a salinity probe and its deficit twin: every deficit reading
        // is the medium less the salinity reading, zero outside the plume, never negative.
        let probe = |deficit| {
            ChemSensor::new(ChemSensorParams {
                salinity: Some(SalinityParams {
                    medium_ppt: 32.0,
                    deficit,
                    ..SalinityParams::default()
                }),
                ..ChemSensorParams::default()
            })
        };
        let (mut s, mut d) = (probe(false), probe(true));
        let (mut rs, mut rd) = (
            stream_rng(3, StreamId::Sensor(0, 1)),
            stream_rng(3, StreamId::Sensor(0, 1)),
        );
        for k in 0..2000 {
            let c = [0.0, 0.5, 3.0, 2000.0][k % 4];
            let t = f64::from(k as u32);
            let (a, b) = (
                s.sample(c, t, &mut rs).reading,
                d.sample(c, t, &mut rd).reading,
            );
            assert!((a + b - 32.0).abs() < 1e-12, "{a} + {b}");
            assert!((0.0..=32.0).contains(&b), "{b}");
            if c == 0.0 {
                assert_eq!(b, 0.0);
            }
            if c == 2000.0 {
                // Pure fresh water: the whole contrast, less the half-normal noise.
                assert!(b > 31.0, "{b}");
            }
        }
    }

    #[test]
    fn flow_fault_reverses_the_reading_in_its_window() {
        let mut rng = stream_rng(1, StreamId::Sensor(0, 1));
        let s = FlowSensor::new(FlowSensorParams {
            noise_sd_mps: 0.0,
            fault: Some(FlowFault {
                start_s: 10.0,
                end_s: 20.0,
            }),
            ..FlowSensorParams::default()
        });
        let f = Vec2::new(0.1, 0.2);
        assert_eq!(s.sample(f, 5.0, &mut rng).velocity_mps, f);
        assert_eq!(s.sample(f, 15.0, &mut rng).velocity_mps, -f);
        assert_eq!(s.sample(f, 20.0, &mut rng).velocity_mps, f);
        let biased = FlowSensor::new(FlowSensorParams {
            noise_sd_mps: 0.0,
            bias_mps: [0.05, 0.0],
            ..FlowSensorParams::default()
        });
        assert!(
            (biased.sample(f, 0.0, &mut rng).velocity_mps - Vec2::new(0.15, 0.2)).norm() < 1e-12
        );
    }

    #[test]
    fn range_groups_see_their_sides() {
        // A wall 10 m East, running North-South; vehicle heading North at the origin.
        let wall = SoftObstacle::new(
            "wall",
            &[[10.0, -50.0], [12.0, -50.0], [12.0, 50.0], [10.0, 50.0]],
        )
        .unwrap();
        let obstacles = ObstacleSet::new(vec![wall]);
        // An ideal sensor (every ray sees every obstacle, no noise).
        let r = RangeSensor::new(RangeSensorParams {
            noise_sd_m: 0.0,
            detection_probability: 1.0,
            ..RangeSensorParams::default()
        });
        let mut rng = stream_rng(1, StreamId::Sensor(0, 4));
        let north = r.sample(&obstacles, Vec2::zeros(), Heading::NORTH, &mut rng);
        assert_eq!(north.left_m, None);
        assert!((north.right_m.unwrap() - 10.0).abs() < 1e-9, "{north:?}");
        assert!(
            north.front_m.is_none(),
            "30 deg off the heading the wall is 20 m away: out of range"
        );
        let east = r.sample(&obstacles, Vec2::zeros(), Heading::from_deg(90.0), &mut rng);
        assert!((east.front_m.unwrap() - 10.0).abs() < 1e-9);
        let south = r.sample(
            &obstacles,
            Vec2::zeros(),
            Heading::from_deg(180.0),
            &mut rng,
        );
        assert!((south.left_m.unwrap() - 10.0).abs() < 1e-9 && south.right_m.is_none());
    }

    #[test]
    fn range_pings_are_noisy_patchy_and_at_their_rate() {
        // A wall 10 m East; the vehicle heads East so all seven front rays cross it.
        let wall = SoftObstacle::new(
            "wall",
            &[[10.0, -50.0], [12.0, -50.0], [12.0, 50.0], [10.0, 50.0]],
        )
        .unwrap();
        let obstacles = ObstacleSet::new(vec![wall]);
        let mut r = RangeSensor::new(RangeSensorParams {
            rays_per_group: 1,
            noise_sd_m: 0.5,
            detection_probability: 0.3,
            ..RangeSensorParams::default()
        });
        let mut rng = stream_rng(7, StreamId::Sensor(0, 4));
        let pings: Vec<Option<f64>> = (0..4000)
            .map(|_| {
                r.sample(&obstacles, Vec2::zeros(), Heading::from_deg(90.0), &mut rng)
                    .front_m
            })
            .collect();
        let seen: Vec<f64> = pings.iter().flatten().copied().collect();
        // One ray, p = 0.3: about 1,200 of 4,000 pings see the wall (sd of the count 29).
        assert!((1050..1350).contains(&seen.len()), "{}", seen.len());
        let mean = seen.iter().sum::<f64>() / seen.len() as f64;
        let sd = (seen.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / seen.len() as f64).sqrt();
        assert!(
            (mean - 10.0).abs() < 0.1 && (sd - 0.5).abs() < 0.05,
            "{mean} {sd}"
        );
        // Five pings per second at a 0.1 s step.
        let due = (0..100).filter(|k| r.due(f64::from(*k) * 0.1)).count();
        assert_eq!(due, 50);
        // Seven rays each with p = 0.3: the group misses the wall only with 0.7^7 = 8 %.
        let seven = RangeSensor::new(RangeSensorParams {
            detection_probability: 0.3,
            ..RangeSensorParams::default()
        });
        let misses = (0..4000)
            .filter(|_| {
                seven
                    .sample(&obstacles, Vec2::zeros(), Heading::from_deg(90.0), &mut rng)
                    .front_m
                    .is_none()
            })
            .count();
        assert!((250..420).contains(&misses), "{misses}");
    }
}
