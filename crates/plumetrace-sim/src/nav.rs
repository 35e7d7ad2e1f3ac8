//! Navigation: what the vehicle believes about where it is.
//!
//! An AUV dead-reckons: it integrates its measured heading and water-relative speed plus the
//! measured current, with a slowly varying velocity error (a first-order Gauss-Markov process:
//! stationary, so the navigation is as good late in a long mission as early on), so the estimate
//! wanders away from the truth. Periodic long-baseline fixes reset it to the truth plus the fix error,
//! which makes the estimate jump (up to about 10 m in the field). A surface craft works the same
//! way with frequent, accurate GPS fixes. The planner sees only the estimate.

use crate::vehicle::VehicleState;
use plumetrace_core::{Heading, NavEstimate, Vec2, VehicleKind};
use plumetrace_env::error::{require_non_negative, require_positive};
use plumetrace_env::{EnvError, SimRng};
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// Parameters of a navigation system.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NavParams {
    /// Time between position fixes, s.
    pub fix_interval_s: f64,
    /// Standard deviation of a fix's error per axis, m.
    pub fix_sigma_m: f64,
    /// Standard deviation of the dead-reckoning velocity error per axis, m/s (its stationary
    /// value: the error starts at zero, as after a calibration, and settles there).
    pub velocity_error_sd_mps: f64,
    /// Correlation time of the dead-reckoning velocity error, s.
    pub velocity_error_tau_s: f64,
    /// Compass noise, degrees (standard deviation).
    pub heading_sd_deg: f64,
    /// Whether the vehicle has a position estimate at all (an underwater follower without fixes
    /// has none: its snapshots carry no position).
    pub position_estimate: bool,
    /// Speed-log noise of the reported water speed, m/s (standard deviation; its effect on dead
    /// reckoning is in the velocity error).
    pub speed_sd_mps: f64,
    /// Altimeter noise, m (standard deviation); surface craft report no altitude.
    pub altimeter_sd_m: f64,
    /// Check each measured current against the recent ones before dead-reckoning with it
    /// ([`plumetrace_core::FlowGate`]): a reading reversed from one sample to the next (a current
    /// meter reading the wrong layer) is replaced by the last plausible one.
    pub flow_check: bool,
}

impl NavParams {
    /// An AUV with long-baseline fixes every 5 minutes, 2 m fix error and a dead-reckoning
    /// velocity error of 1 cm/s per axis (half a percent of 2 m/s) correlated over 20 minutes:
    /// about 3 m of drift per axis between fixes, so fixes jump the estimate by up to about 10 m.
    pub fn lbl() -> Self {
        NavParams {
            fix_interval_s: 300.0,
            fix_sigma_m: 2.0,
            velocity_error_sd_mps: 0.01,
            velocity_error_tau_s: 1200.0,
            heading_sd_deg: 0.5,
            position_estimate: true,
            speed_sd_mps: 0.01,
            altimeter_sd_m: 0.05,
            flow_check: true,
        }
    }

    /// A surface craft with 1 Hz GPS fixes of 1.5 m error.
    pub fn gps() -> Self {
        NavParams {
            fix_interval_s: 1.0,
            fix_sigma_m: 1.5,
            velocity_error_sd_mps: 0.0,
            velocity_error_tau_s: 1200.0,
            heading_sd_deg: 1.0,
            position_estimate: true,
            speed_sd_mps: 0.02,
            altimeter_sd_m: 0.0,
            flow_check: true,
        }
    }

    /// Checks every parameter; errors name the field.
    pub fn validate(&self) -> Result<(), EnvError> {
        require_positive("fix_interval_s", self.fix_interval_s)?;
        require_non_negative("fix_sigma_m", self.fix_sigma_m)?;
        require_non_negative("velocity_error_sd_mps", self.velocity_error_sd_mps)?;
        require_positive("velocity_error_tau_s", self.velocity_error_tau_s)?;
        require_non_negative("heading_sd_deg", self.heading_sd_deg)?;
        require_non_negative("speed_sd_mps", self.speed_sd_mps)?;
        require_non_negative("altimeter_sd_m", self.altimeter_sd_m)
    }
}

/// A position fix that moved the estimate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FixEvent {
    /// Time of the fix, s.
    pub time_s: f64,
    /// Estimate before the fix.
    pub before_m: Vec2,
    /// Estimate after the fix.
    pub after_m: Vec2,
}

impl FixEvent {
    /// How far the estimate jumped, m.
    pub fn jump_m(&self) -> f64 {
        (self.after_m - self.before_m).norm()
    }
}

/// The navigation estimate of one vehicle.
#[derive(Debug, Clone, PartialEq)]
pub struct Navigator {
    params: NavParams,
    estimate_m: Vec2,
    velocity_error_mps: Vec2,
    next_fix_s: f64,
    last_fix_s: Option<f64>,
    heading: Heading,
    /// Measured water-relative velocity at the previous update (for the trapezoidal step).
    last_water_velocity: Vec2,
    /// The plausibility check of measured currents, and the last current it accepted.
    flow_gate: Option<plumetrace_core::FlowGate>,
    last_flow: Vec2,
}

impl Navigator {
    /// Starts with a perfect estimate at `start`; the first fix comes one interval later.
    pub fn new(params: NavParams, start: &VehicleState) -> Self {
        Navigator {
            params,
            estimate_m: start.pos_m,
            velocity_error_mps: Vec2::zeros(),
            next_fix_s: params.fix_interval_s,
            last_fix_s: None,
            heading: start.heading,
            last_water_velocity: start.heading.unit() * start.speed_mps,
            flow_gate: params.flow_check.then(|| {
                plumetrace_core::FlowGate::new(plumetrace_core::FlowGateParams::default())
            }),
            last_flow: Vec2::zeros(),
        }
    }

    /// The estimated position.
    pub fn estimate_m(&self) -> Vec2 {
        self.estimate_m
    }

    /// The measured heading (compass with its noise) at the last update.
    pub fn heading(&self) -> Heading {
        self.heading
    }

    /// The parameters.
    pub fn params(&self) -> &NavParams {
        &self.params
    }

    /// Advances the estimate over a step of `dt_s` ending at `t_s`, given the true state and the
    /// flow the vehicle measured (none: the current is ignored). Returns the fix, if one happened.
    pub fn update(
        &mut self,
        truth: &VehicleState,
        measured_flow_mps: Option<Vec2>,
        t_s: f64,
        dt_s: f64,
        rng: &mut SimRng,
    ) -> Option<FixEvent> {
        let p = self.params;
        let nh: f64 = StandardNormal.sample(rng);
        self.heading = truth.heading.turned_deg(p.heading_sd_deg * nh);
        let flow = match (measured_flow_mps, self.flow_gate.as_mut()) {
            (Some(f), Some(g)) => {
                if g.accept(t_s, f) {
                    self.last_flow = f;
                }
                self.last_flow
            }
            (f, None) => f
                .filter(|f| f.x.is_finite() && f.y.is_finite())
                .unwrap_or_else(Vec2::zeros),
            (None, Some(_)) => Vec2::zeros(),
        };
        // Trapezoidal integration of the measured water-relative velocity, as the vehicle moves:
        // without noise the estimate then follows the truth exactly.
        let water = self.heading.unit() * truth.speed_mps;
        let v = (water + self.last_water_velocity) * 0.5 + flow + self.velocity_error_mps;
        self.last_water_velocity = water;
        self.estimate_m += v * dt_s;
        let (ex, ey): (f64, f64) = (StandardNormal.sample(rng), StandardNormal.sample(rng));
        // Exact discretisation of dv = -v / tau dt + sd sqrt(2 / tau) dW.
        let a = (-dt_s / p.velocity_error_tau_s).exp();
        let kick = p.velocity_error_sd_mps * (1.0 - a * a).sqrt();
        self.velocity_error_mps = self.velocity_error_mps * a + Vec2::new(ex, ey) * kick;
        if t_s + 1e-9 >= self.next_fix_s {
            // Far behind (a clock jump): skip to the current interval at once, not fix by fix.
            if (t_s - self.next_fix_s) / p.fix_interval_s > 1e3 {
                self.next_fix_s = (t_s / p.fix_interval_s).floor() * p.fix_interval_s;
            }
            while self.next_fix_s <= t_s + 1e-9 {
                self.next_fix_s += p.fix_interval_s;
            }
            let (fx, fy): (f64, f64) = (StandardNormal.sample(rng), StandardNormal.sample(rng));
            let before = self.estimate_m;
            self.estimate_m = truth.pos_m + Vec2::new(fx, fy) * p.fix_sigma_m;
            self.last_fix_s = Some(t_s);
            return Some(FixEvent {
                time_s: t_s,
                before_m: before,
                after_m: self.estimate_m,
            });
        }
        None
    }

    /// Forces a fix now with a given error (tests and scripted scenarios: "a fix that jumps").
    pub fn force_fix(&mut self, t_s: f64, fix_m: Vec2) -> FixEvent {
        let before = self.estimate_m;
        self.estimate_m = fix_m;
        self.last_fix_s = Some(t_s);
        FixEvent {
            time_s: t_s,
            before_m: before,
            after_m: fix_m,
        }
    }

    /// What the onboard side sees: the position estimate (if the vehicle has one), the measured
    /// heading, the speed log's and the altimeter's readings (drawn from `rng`, the vehicle's
    /// measurement stream) and the depth (`water_depth_m` minus the height; 0 at the surface).
    pub fn estimate(
        &self,
        truth: &VehicleState,
        kind: VehicleKind,
        water_depth_m: Option<f64>,
        rng: &mut SimRng,
    ) -> NavEstimate {
        self.estimate_over(truth, kind, water_depth_m, None, rng)
    }

    /// [`NavEstimate::estimate`] over a seabed that is not flat: `seabed_m` is the seabed's
    /// height under the vehicle (`None`: flat at 0), from which the altimeter measures.
    pub fn estimate_over(
        &self,
        truth: &VehicleState,
        kind: VehicleKind,
        water_depth_m: Option<f64>,
        seabed_m: Option<f64>,
        rng: &mut SimRng,
    ) -> NavEstimate {
        let p = self.params;
        let (ns, na): (f64, f64) = (StandardNormal.sample(rng), StandardNormal.sample(rng));
        let height = match seabed_m {
            None => truth.z_m,
            Some(f) => truth.z_m - f,
        };
        let (altitude_m, depth_m) = match kind {
            VehicleKind::Auv => (
                Some((height + p.altimeter_sd_m * na).max(0.0)),
                water_depth_m.map(|d| (d - truth.z_m).max(0.0)),
            ),
            VehicleKind::Surface => (None, Some(0.0)),
        };
        NavEstimate {
            pos_m: p.position_estimate.then_some(self.estimate_m),
            heading: self.heading,
            speed_mps: (truth.speed_mps + p.speed_sd_mps * ns).max(0.0),
            altitude_m,
            depth_m,
            last_fix_s: self.last_fix_s.filter(|_| p.position_estimate),
        }
    }
}
