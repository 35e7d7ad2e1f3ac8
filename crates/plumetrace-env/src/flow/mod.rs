//! Flow (current) fields: where the water goes.
//!
//! Every model answers the same two questions through [`FlowField`]: the water velocity at a
//! position at the field's current time, and how to advance to the next time. Stateful models
//! (the Farrell field) hold one snapshot in time; analytic ones evaluate any time but are still
//! advanced so that all models are driven the same way.
//!
//! Models:
//! - [`UniformFlow`]: the same velocity everywhere, steady or varying in time ([`MeanFlow`]);
//! - [`FarrellFlow`]: the meandering field of Farrell et al. (2002), driven by coloured noise at
//!   the corners of a grid and advanced by explicit advection-diffusion;
//! - [`GriddedFlow`]: a regular grid (optionally several time frames) read from a CSV file or
//!   sampled from CF currents in a NetCDF file ([`CfOptions`]).

pub(crate) mod cf;
mod farrell;
mod gridded;
mod mean;
mod uniform;

pub use cf::CfOptions;
pub use farrell::{ColouredNoise, FarrellFlow, FarrellParams, NoiseScheme, NoiseUpdates};
pub use gridded::GriddedFlow;
pub use mean::MeanFlow;
pub use uniform::UniformFlow;

use crate::{EnvError, SimRng};
use plumetrace_core::Vec2;

/// A water velocity field in the horizontal plane (`(east, north)` in m/s).
pub trait FlowField: Send + Sync + std::fmt::Debug {
    /// A short name for logs ("uniform", "farrell", ...).
    fn name(&self) -> &'static str;

    /// The field's current time, s.
    fn time_s(&self) -> f64;

    /// Water velocity at `pos_m` at the current time.
    fn velocity(&self, pos_m: Vec2) -> Vec2;

    /// Water velocities at many positions; `x`, `y`, `u`, `v` have the
    /// same length.
    fn velocities(&self, x: &[f64], y: &[f64], u: &mut [f64], v: &mut [f64]) {
        for i in 0..x.len().min(y.len()).min(u.len()).min(v.len()) {
            let w = self.velocity(Vec2::new(x[i], y[i]));
            u[i] = w.x;
            v[i] = w.y;
        }
    }

    /// [`FlowField::velocities`] in single precision at positions measured from `origin` (the
    /// filament hot path: the transport moves filaments in single precision, from the domain's
    /// centre). By default through [`FlowField::velocities`], 64 points at a time.
    fn velocities_f32(&self, origin: [f64; 2], x: &[f32], y: &[f32], u: &mut [f32], v: &mut [f32]) {
        const BATCH: usize = 64;
        let n = x.len().min(y.len()).min(u.len()).min(v.len());
        let (mut xd, mut yd, mut ud, mut vd) =
            ([0.0; BATCH], [0.0; BATCH], [0.0; BATCH], [0.0; BATCH]);
        for start in (0..n).step_by(BATCH) {
            let m = (n - start).min(BATCH);
            for k in 0..m {
                xd[k] = f64::from(x[start + k]) + origin[0];
                yd[k] = f64::from(y[start + k]) + origin[1];
            }
            self.velocities(&xd[..m], &yd[..m], &mut ud[..m], &mut vd[..m]);
            for k in 0..m {
                u[start + k] = ud[k] as f32;
                v[start + k] = vd[k] as f32;
            }
        }
    }

    /// Advances the field by `dt_s` to time `t_new_s` (the caller's step count times `dt_s`),
    /// drawing any noise from `rng`.
    fn advance(&mut self, t_new_s: f64, dt_s: f64, rng: &mut SimRng) -> Result<(), EnvError>;

    /// The largest time step the model can be advanced with stably, if it has a limit.
    fn max_stable_dt_s(&self) -> Option<f64> {
        None
    }

    /// The grid nodes one step of the model updates (1 for a field without a grid): the cost of
    /// a step, which a run's budget counts with its sub-steps.
    fn nodes(&self) -> usize {
        1
    }

    /// The step the model asks to be advanced with when the plume steps more finely, s (`None`:
    /// with every plume step); see [`crate::environment::flow_schedule`].
    fn own_step_s(&self) -> Option<f64> {
        None
    }
}

/// The flow models known to plumetrace, for static dispatch and for the model registry.
#[derive(Debug, Clone)]
pub enum FlowModel {
    /// Uniform in space, steady or varying in time.
    Uniform(UniformFlow),
    /// Farrell et al. (2002) meandering field.
    Farrell(Box<FarrellFlow>),
    /// Read from a file.
    Gridded(Box<GriddedFlow>),
}

impl FlowModel {
    fn inner(&self) -> &dyn FlowField {
        match self {
            FlowModel::Uniform(f) => f,
            FlowModel::Farrell(f) => f.as_ref(),
            FlowModel::Gridded(f) => f.as_ref(),
        }
    }

    fn inner_mut(&mut self) -> &mut dyn FlowField {
        match self {
            FlowModel::Uniform(f) => f,
            FlowModel::Farrell(f) => f.as_mut(),
            FlowModel::Gridded(f) => f.as_mut(),
        }
    }
}

impl FlowField for FlowModel {
    fn name(&self) -> &'static str {
        self.inner().name()
    }
    fn time_s(&self) -> f64 {
        self.inner().time_s()
    }
    fn velocity(&self, pos_m: Vec2) -> Vec2 {
        self.inner().velocity(pos_m)
    }
    fn velocities(&self, x: &[f64], y: &[f64], u: &mut [f64], v: &mut [f64]) {
        self.inner().velocities(x, y, u, v)
    }
    fn velocities_f32(&self, origin: [f64; 2], x: &[f32], y: &[f32], u: &mut [f32], v: &mut [f32]) {
        self.inner().velocities_f32(origin, x, y, u, v)
    }
    fn advance(&mut self, t_new_s: f64, dt_s: f64, rng: &mut SimRng) -> Result<(), EnvError> {
        self.inner_mut().advance(t_new_s, dt_s, rng)
    }
    fn max_stable_dt_s(&self) -> Option<f64> {
        self.inner().max_stable_dt_s()
    }
    fn nodes(&self) -> usize {
        self.inner().nodes()
    }
    fn own_step_s(&self) -> Option<f64> {
        self.inner().own_step_s()
    }
}

/// Bilinear interpolation weights on a regular axis: index of the lower node (clamped to the grid)
/// and the fraction towards the next node (in [0, 1]). Positions outside the grid take the value
/// at the nearest edge; NaN positions take the first node.
///
/// The position is clamped to [0, n - 1] before truncation, so truncation equals `floor` and no
/// libm call is needed in the filament hot path.
#[inline(always)]
pub(crate) fn axis_weight(pos: f64, origin: f64, inv_step: f64, n: usize) -> (usize, f64) {
    cell_weight((pos - origin) * inv_step, n)
}

/// [`axis_weight`] of a position already in node units, `f = (pos - origin) / step` (the seabed
/// divides where the flow multiplies by the inverse step; each keeps its own arithmetic).
#[inline(always)]
pub(crate) fn cell_weight(f: f64, n: usize) -> (usize, f64) {
    if n < 2 {
        return (0, 0.0);
    }
    // `f > 0.0` is false for NaN, which therefore maps to 0.
    let f = if f > 0.0 { f } else { 0.0 };
    let last = (n - 1) as f64;
    let f = if f < last { f } else { last };
    // `f` is in [0, n - 1] with n <= 4e6, so the i32 cast is exact truncation (and cheaper than a
    // cast to usize, which needs unsigned saturation).
    let i = (f as i32 as usize).min(n - 2);
    (i, f - i as f64)
}
