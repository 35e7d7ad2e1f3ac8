//! Concentration fields and the time-averaged concentration grid.

use plumetrace_core::Vec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{EnvError, require_finite, require_positive};

/// Anything that gives a chemical concentration at a 3-D point (mass units per m^3).
pub trait ConcentrationField: Send + Sync {
    /// Concentration at `p` (`z` = height above the seabed).
    fn concentration(&self, p: Vec3) -> f64;

    /// The positions of the field's sources, where the field knows them (a model's; a field read
    /// from a file does not).
    fn source_positions(&self) -> Vec<Vec3> {
        Vec::new()
    }

    /// Concentrations at many points, evaluated in parallel; the result does not depend on the
    /// number of threads (each point is computed alone).
    fn concentrations(&self, points: &[Vec3], out: &mut [f64]) {
        out.par_iter_mut()
            .zip(points.par_iter())
            .with_min_len(256)
            .for_each(|(o, p)| *o = self.concentration(*p));
    }

    /// Concentrations at the points of `grid` (`points`, as [`GridSpec::points`] lists them):
    /// the same values as [`ConcentrationField::concentrations`] over `points`, which a field
    /// may compute faster knowing they form a grid (the filament plume does).
    fn grid_concentrations(&self, grid: &GridSpec, points: &[Vec3], out: &mut [f64]) {
        let _ = grid;
        self.concentrations(points, out);
    }

    /// [`ConcentrationField::grid_concentrations`] for a figure or a page, where a few units in
    /// the last place do not show: each of a point's terms may differ from the point query's by
    /// up to 2 units in its last place (the filament plume takes the exponentials in vector
    /// lanes, several times faster), and the result is the same bits on every CPU. A field
    /// without a faster way gives [`ConcentrationField::grid_concentrations`]'s values. Such a
    /// grid is small and seldom sampled, so a field may compute it on the calling thread (the
    /// filament plume does).
    fn display_grid_concentrations(&self, grid: &GridSpec, points: &[Vec3], out: &mut [f64]) {
        self.grid_concentrations(grid, points, out);
    }
}

/// A regular horizontal grid of sample points at one height.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GridSpec {
    /// West edge, m.
    pub x_min_m: f64,
    /// East edge, m.
    pub x_max_m: f64,
    /// South edge, m.
    pub y_min_m: f64,
    /// North edge, m.
    pub y_max_m: f64,
    /// Points along x.
    pub nx: usize,
    /// Points along y.
    pub ny: usize,
    /// Height above the seabed, m.
    pub z_m: f64,
}

impl GridSpec {
    /// Checks the grid; errors name its fields (`nx`; [`EnvError::under`] places them).
    pub fn validate(&self) -> Result<(), EnvError> {
        for (k, v) in [
            ("x_min_m", self.x_min_m),
            ("x_max_m", self.x_max_m),
            ("y_min_m", self.y_min_m),
            ("y_max_m", self.y_max_m),
            ("z_m", self.z_m),
        ] {
            require_finite(k, v)?;
        }
        require_positive("x_max_m - x_min_m", self.x_max_m - self.x_min_m)?;
        require_positive("y_max_m - y_min_m", self.y_max_m - self.y_min_m)?;
        if self.nx < 2 || self.ny < 2 || self.nx * self.ny > 16_000_000 {
            return Err(EnvError::invalid(
                "nx",
                "nx and ny must be >= 2 with nx * ny <= 16,000,000",
            ));
        }
        Ok(())
    }

    /// Sample points, row-major (x fastest).
    pub fn points(&self) -> Vec<Vec3> {
        let dx = (self.x_max_m - self.x_min_m) / (self.nx - 1) as f64;
        let dy = (self.y_max_m - self.y_min_m) / (self.ny - 1) as f64;
        let mut pts = Vec::with_capacity(self.nx * self.ny);
        for j in 0..self.ny {
            for i in 0..self.nx {
                pts.push(Vec3::new(
                    self.x_min_m + i as f64 * dx,
                    self.y_min_m + j as f64 * dy,
                    self.z_m,
                ));
            }
        }
        pts
    }
}

/// Time-averaged concentration on a grid, with the fraction of samples above a threshold
/// (intermittency) per point.
#[derive(Debug, Clone)]
pub struct MeanConcentrationGrid {
    spec: GridSpec,
    display: bool,
    points: Vec<Vec3>,
    scratch: Vec<f64>,
    sum: Vec<f64>,
    above: Vec<u32>,
    threshold: f64,
    samples: u32,
}

impl MeanConcentrationGrid {
    /// An empty average over `spec`, counting samples above `threshold`.
    pub fn new(spec: GridSpec, threshold: f64) -> Self {
        let points = spec.points();
        let n = points.len();
        MeanConcentrationGrid {
            spec,
            display: false,
            points,
            scratch: vec![0.0; n],
            sum: vec![0.0; n],
            above: vec![0; n],
            threshold,
            samples: 0,
        }
    }

    /// The same average for a figure: its samples are
    /// [`ConcentrationField::display_grid_concentrations`].
    pub fn for_display(mut self) -> Self {
        self.display = true;
        self
    }

    /// Adds one sample of `field` at every grid point.
    pub fn accumulate(&mut self, field: &dyn ConcentrationField) {
        if self.display {
            field.display_grid_concentrations(&self.spec, &self.points, &mut self.scratch);
        } else {
            field.grid_concentrations(&self.spec, &self.points, &mut self.scratch);
        }
        for ((s, a), c) in self
            .sum
            .iter_mut()
            .zip(self.above.iter_mut())
            .zip(&self.scratch)
        {
            *s += c;
            if *c > self.threshold {
                *a += 1;
            }
        }
        self.samples += 1;
    }

    /// The grid.
    pub fn spec(&self) -> &GridSpec {
        &self.spec
    }

    /// Number of samples taken.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Mean concentration per point (row-major, x fastest).
    pub fn mean(&self) -> Vec<f64> {
        let n = f64::from(self.samples.max(1));
        self.sum.iter().map(|s| s / n).collect()
    }

    /// Fraction of samples above the threshold per point.
    pub fn intermittency(&self) -> Vec<f64> {
        let n = f64::from(self.samples.max(1));
        self.above.iter().map(|&a| f64::from(a) / n).collect()
    }

    /// The most recent instantaneous sample.
    pub fn last_sample(&self) -> &[f64] {
        &self.scratch
    }
}
