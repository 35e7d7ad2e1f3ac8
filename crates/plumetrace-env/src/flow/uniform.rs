//! Uniform flow: the same velocity everywhere, steady or varying in time.

use super::{FlowField, MeanFlow};
use crate::{EnvError, SimRng};
use plumetrace_core::Vec2;

/// Spatially uniform flow following a [`MeanFlow`] in time.
#[derive(Debug, Clone)]
pub struct UniformFlow {
    mean: MeanFlow,
    time_s: f64,
    current_mps: Vec2,
}

impl UniformFlow {
    /// A uniform flow starting at t = 0; errors name the mean flow's field under `mean`.
    pub fn new(mean: MeanFlow) -> Result<Self, EnvError> {
        mean.validate().map_err(|e| e.under("mean"))?;
        Ok(UniformFlow {
            mean,
            time_s: 0.0,
            current_mps: mean.velocity_at(0.0),
        })
    }

    /// The mean-flow description.
    pub fn mean(&self) -> &MeanFlow {
        &self.mean
    }
}

impl FlowField for UniformFlow {
    fn name(&self) -> &'static str {
        "uniform"
    }
    fn time_s(&self) -> f64 {
        self.time_s
    }
    fn velocity(&self, _pos_m: Vec2) -> Vec2 {
        self.current_mps
    }
    fn velocities(&self, _x: &[f64], _y: &[f64], u: &mut [f64], v: &mut [f64]) {
        u.fill(self.current_mps.x);
        v.fill(self.current_mps.y);
    }
    fn velocities_f32(
        &self,
        _origin: [f64; 2],
        _x: &[f32],
        _y: &[f32],
        u: &mut [f32],
        v: &mut [f32],
    ) {
        u.fill(self.current_mps.x as f32);
        v.fill(self.current_mps.y as f32);
    }
    fn advance(&mut self, t_new_s: f64, _dt_s: f64, _rng: &mut SimRng) -> Result<(), EnvError> {
        self.time_s = t_new_s;
        self.current_mps = self.mean.velocity_at(t_new_s);
        Ok(())
    }
}
