//! Steady plume fields: the freshwater case of formation tracing, and fields read from files.
//!
//! [`GaussianPlume`] is the steady solution for a continuous point source of `Q` mass units per
//! second in a uniform current of speed `U` with constant cross-flow and vertical diffusivities
//! `K_c`, `K_v`. Where the plume is slender (along-flow diffusion negligible against advection,
//! i.e. the Peclet number `U x / K` is large, which holds a few metres downstream for ocean
//! currents of centimetres per second) the steady advection-diffusion equation reduces to
//! `U dc/dx = K_c d2c/dy2 + K_v d2c/dz2`, whose exact solution is
//!
//! `c = Q / (4 pi x sqrt(K_c K_v)) exp(-U y^2 / (4 K_c x)) sum_images exp(-U (z - z_i)^2 / (4 K_v x))`
//!
//! with `x` the distance downstream of the source and `y` the cross-flow offset. The no-flux seabed
//! and surface are honoured exactly by mirror images of the source (`z_i = +-z_s + 2 n D`). A
//! grid solver of the same equation would add numerical diffusion and cost; the closed form is
//! exact for the model and cheap to evaluate, and [`GriddedConcentration`] can rasterise it or
//! stand in for any other steady field (e.g. a CFD result) read from a CSV file. Upstream of the
//! source the field is zero; closer than `min_downstream_m` it is evaluated at that distance to
//! avoid the point-source singularity.

use crate::csv_grid::{read_columns, regular_axis};
use crate::error::{EnvError, require_finite, require_non_negative, require_positive};
use crate::field::ConcentrationField;
use plumetrace_core::{Heading, Vec2, Vec3};
use std::path::Path;

/// The steady Gaussian plume of a continuous source in a uniform current.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussianPlume {
    source_m: Vec3,
    mass_rate_per_s: f64,
    speed_mps: f64,
    along: Vec2,
    k_cross_m2ps: f64,
    k_vert_m2ps: f64,
    depth_m: Option<f64>,
    min_downstream_m: f64,
}

/// Number of image pairs per side used with a surface (the terms decay as `exp(-n^2 D^2 U / (K x))`).
const IMAGE_PAIRS: i32 = 4;

impl GaussianPlume {
    /// The least diffusivity of a steady plume, m^2/s: its width goes as the square root of it.
    pub const MIN_DIFFUSIVITY_M2PS: f64 = 1e-6;

    /// A steady plume; `flow_toward_deg` is the direction the current moves towards. Errors name
    /// `source.*`, the current's `speed_mps` and `toward_deg`, the diffusivities as the
    /// scenario's `[plume]` keys and the water depth as `depth_m`.
    pub fn new(
        source_m: Vec3,
        mass_rate_per_s: f64,
        speed_mps: f64,
        flow_toward_deg: f64,
        k_cross_m2ps: f64,
        k_vert_m2ps: f64,
        depth_m: Option<f64>,
    ) -> Result<Self, EnvError> {
        require_finite("source.x_m", source_m.x)?;
        require_finite("source.y_m", source_m.y)?;
        require_non_negative("source.z_m", source_m.z)?;
        require_non_negative("source.mass_rate_per_s", mass_rate_per_s)?;
        require_positive("speed_mps", speed_mps)?;
        require_finite("toward_deg", flow_toward_deg)?;
        for (key, k) in [
            ("horizontal_diffusivity_m2ps", k_cross_m2ps),
            ("vertical_diffusivity_m2ps", k_vert_m2ps),
        ] {
            if !(k.is_finite() && k >= Self::MIN_DIFFUSIVITY_M2PS) {
                return Err(EnvError::invalid(
                    key,
                    format!(
                        "the steady plume needs at least {:e} m^2/s (its width goes as the \
                         square root of it), got {k:?}",
                        Self::MIN_DIFFUSIVITY_M2PS
                    ),
                ));
            }
        }
        if let Some(d) = depth_m {
            require_positive("depth_m", d)?;
            if source_m.z > d {
                return Err(EnvError::invalid(
                    "source.z_m",
                    format!("{} m is above the surface ({d} m)", source_m.z),
                ));
            }
        }
        Ok(GaussianPlume {
            source_m,
            mass_rate_per_s,
            speed_mps,
            along: Heading::from_deg(flow_toward_deg).unit(),
            k_cross_m2ps,
            k_vert_m2ps,
            depth_m,
            min_downstream_m: 0.5,
        })
    }

    /// The cross-flow standard deviation `sqrt(2 K_c x / U)` at `x` m downstream.
    pub fn crossflow_sigma_m(&self, downstream_m: f64) -> f64 {
        (2.0 * self.k_cross_m2ps * downstream_m.max(0.0) / self.speed_mps).sqrt()
    }

    /// `(downstream, crossflow)` coordinates of `p` relative to the source (cross-flow positive
    /// to the right of the flow direction).
    pub fn plume_coords(&self, p: Vec2) -> (f64, f64) {
        let d = p - self.source_m.xy();
        let x = d.dot(&self.along);
        let y = d.x * self.along.y - d.y * self.along.x;
        (x, y)
    }
}

impl ConcentrationField for GaussianPlume {
    fn source_positions(&self) -> Vec<Vec3> {
        vec![self.source_m]
    }

    fn concentration(&self, p: Vec3) -> f64 {
        let (x, y) = self.plume_coords(p.xy());
        if x <= 0.0 {
            return 0.0;
        }
        let x = x.max(self.min_downstream_m);
        let u = self.speed_mps;
        let lateral = (-u * y * y / (4.0 * self.k_cross_m2ps * x)).exp();
        let a = u / (4.0 * self.k_vert_m2ps * x);
        let zs = self.source_m.z;
        let vertical = match self.depth_m {
            None => (-a * (p.z - zs).powi(2)).exp() + (-a * (p.z + zs).powi(2)).exp(),
            Some(d) => (-IMAGE_PAIRS..=IMAGE_PAIRS)
                .map(|n| {
                    let shift = 2.0 * f64::from(n) * d;
                    (-a * (p.z - (zs + shift)).powi(2)).exp()
                        + (-a * (p.z - (-zs + shift)).powi(2)).exp()
                })
                .sum(),
        };
        self.mass_rate_per_s
            / (4.0 * std::f64::consts::PI * x * (self.k_cross_m2ps * self.k_vert_m2ps).sqrt())
            * lateral
            * vertical
    }
}

/// A concentration field on a regular grid: 2-D (the same at every height) or 3-D; bilinear or
/// trilinear between nodes, zero outside the grid.
#[derive(Debug, Clone, PartialEq)]
pub struct GriddedConcentration {
    axes: Vec<(f64, f64, usize)>,
    values: Vec<f64>,
}

impl GriddedConcentration {
    /// Samples `field` on a grid: `x` and `y` axes as `(min, max, n)`, and an optional `z` axis.
    pub fn rasterise(
        field: &dyn ConcentrationField,
        x: (f64, f64, usize),
        y: (f64, f64, usize),
        z: Option<(f64, f64, usize)>,
    ) -> Result<Self, EnvError> {
        let mut axes = vec![x, y];
        axes.extend(z);
        let mut steps = Vec::new();
        for (k, &(lo, hi, n)) in axes.iter().enumerate() {
            let name = ["x", "y", "z"][k];
            if n < 2 || hi <= lo || !lo.is_finite() || !hi.is_finite() {
                return Err(EnvError::invalid(
                    format!("grid.{name}"),
                    "needs finite min < max and n >= 2",
                ));
            }
            steps.push((lo, (hi - lo) / (n - 1) as f64, n));
        }
        let nz = z.map_or(1, |a| a.2);
        let mut points = Vec::with_capacity(x.2 * y.2 * nz);
        for kz in 0..nz {
            let pz = if steps.len() == 3 {
                steps[2].0 + kz as f64 * steps[2].1
            } else {
                0.0
            };
            for j in 0..y.2 {
                for i in 0..x.2 {
                    points.push(Vec3::new(
                        steps[0].0 + i as f64 * steps[0].1,
                        steps[1].0 + j as f64 * steps[1].1,
                        pz,
                    ));
                }
            }
        }
        let mut values = vec![0.0; points.len()];
        field.concentrations(&points, &mut values);
        Ok(GriddedConcentration {
            axes: steps,
            values,
        })
    }

    /// Reads a grid from CSV with header `x_m,y_m,concentration` or `x_m,y_m,z_m,concentration`;
    /// every combination of the distinct coordinates must appear once.
    pub fn from_csv(path: &Path) -> Result<Self, EnvError> {
        let file_err = |message: String| EnvError::File {
            path: path.to_path_buf(),
            message,
        };
        let (table, present) = read_columns(path, &["x_m", "y_m", "concentration"], &["z_m"])?;
        let has_z = present[0];
        let mut rows: Vec<[f64; 4]> = Vec::with_capacity(table.len());
        for (k, r) in table.iter().enumerate() {
            if r[2] < 0.0 {
                return Err(file_err(format!(
                    "line {}: concentration {} is negative",
                    k + 2,
                    r[2]
                )));
            }
            rows.push([r[0], r[1], if has_z { r[3] } else { 0.0 }, r[2]]);
        }
        let dims = if has_z { 3 } else { 2 };
        let mut axes = Vec::new();
        for (d, name) in ["x_m", "y_m", "z_m"].iter().enumerate().take(dims) {
            axes.push(regular_axis(rows.iter().map(|r| r[d]), name, path)?);
        }
        let total: usize = axes.iter().map(|a| a.2).product();
        let mut values = vec![f64::NAN; total];
        for r in &rows {
            let mut k = 0;
            let mut stride = 1;
            for (d, &(lo, step, n)) in axes.iter().enumerate() {
                let i = (((r[d] - lo) / step).round() as usize).min(n - 1);
                k += i * stride;
                stride *= n;
            }
            if !values[k].is_nan() {
                return Err(file_err(format!(
                    "node ({}, {}, {}) appears twice",
                    r[0], r[1], r[2]
                )));
            }
            values[k] = r[3];
        }
        if values.iter().any(|v| v.is_nan()) {
            return Err(file_err(format!(
                "grid is incomplete: {} rows for {} nodes",
                rows.len(),
                total
            )));
        }
        Ok(GriddedConcentration { axes, values })
    }
}

impl ConcentrationField for GriddedConcentration {
    fn concentration(&self, p: Vec3) -> f64 {
        let coords = [p.x, p.y, p.z];
        let mut idx = [0usize; 3];
        let mut frac = [0.0f64; 3];
        for (d, &(lo, step, n)) in self.axes.iter().enumerate() {
            let f = (coords[d] - lo) / step;
            if !(f >= 0.0 && f <= (n - 1) as f64) {
                if d == 2 {
                    // Outside the vertical span: hold the nearest layer.
                    let fc = f.clamp(0.0, (n - 1) as f64);
                    let i = (fc.floor() as usize).min(n - 2);
                    idx[d] = i;
                    frac[d] = fc - i as f64;
                    continue;
                }
                return 0.0;
            }
            let i = (f.floor() as usize).min(n - 2);
            idx[d] = i;
            frac[d] = f - i as f64;
        }
        let dims = self.axes.len();
        let (nx, ny) = (self.axes[0].2, self.axes[1].2);
        let mut c = 0.0;
        for corner in 0..(1usize << dims) {
            let mut w = 1.0;
            let mut k = 0;
            let mut stride = 1;
            for d in 0..dims {
                let bit = (corner >> d) & 1;
                w *= if bit == 1 { frac[d] } else { 1.0 - frac[d] };
                k += (idx[d] + bit) * stride;
                stride *= [nx, ny, 1][d];
            }
            c += w * self.values[k];
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plume(depth: Option<f64>) -> GaussianPlume {
        GaussianPlume::new(
            Vec3::new(0.0, 0.0, 3.0),
            1.0,
            0.05,
            90.0,
            0.01,
            0.002,
            depth,
        )
        .unwrap()
    }

    /// Mass flux through a cross-flow plane: integral of U c over y and z.
    fn flux(p: &GaussianPlume, x: f64, depth: f64) -> f64 {
        let sig = p.crossflow_sigma_m(x);
        let (ny, nz) = (401, 401);
        let (y0, y1) = (-8.0 * sig, 8.0 * sig);
        let dy = (y1 - y0) / (ny - 1) as f64;
        let dz = depth / (nz - 1) as f64;
        let mut total = 0.0;
        for j in 0..ny {
            for k in 0..nz {
                let w = if j == 0 || j == ny - 1 { 0.5 } else { 1.0 }
                    * if k == 0 || k == nz - 1 { 0.5 } else { 1.0 };
                // Flow towards East: downstream is +x, cross-flow is -y (to the right is South).
                total += w * p.concentration(Vec3::new(x, y0 + j as f64 * dy, k as f64 * dz));
            }
        }
        total * dy * dz * 0.05
    }

    #[test]
    fn mass_flux_equals_release_rate_at_every_distance() {
        let p = plume(Some(4.0));
        for x in [5.0, 20.0, 60.0] {
            let f = flux(&p, x, 4.0);
            assert!((f - 1.0).abs() < 0.01, "flux at {x} m = {f}");
        }
    }

    #[test]
    fn satisfies_the_slender_plume_equation() {
        let p = plume(Some(4.0));
        let (h, hz) = (0.01, 0.01);
        for (x, y, z) in [(10.0, 0.3, 2.5), (30.0, -1.0, 1.0), (50.0, 0.0, 3.9)] {
            let c = |x: f64, y: f64, z: f64| p.concentration(Vec3::new(x, y, z));
            let dcdx = (c(x + h, y, z) - c(x - h, y, z)) / (2.0 * h);
            let d2y = (c(x, y + h, z) - 2.0 * c(x, y, z) + c(x, y - h, z)) / (h * h);
            let d2z = (c(x, y, z + hz) - 2.0 * c(x, y, z) + c(x, y, z - hz)) / (hz * hz);
            let lhs = 0.05 * dcdx;
            let rhs = 0.01 * d2y + 0.002 * d2z;
            assert!(
                (lhs - rhs).abs() <= 1e-3 * lhs.abs().max(rhs.abs()) + 1e-9,
                "at ({x},{y},{z}): {lhs} vs {rhs}"
            );
        }
    }

    #[test]
    fn zero_upstream_and_widening_downstream() {
        let p = plume(None);
        assert_eq!(p.concentration(Vec3::new(-5.0, 0.0, 3.0)), 0.0);
        assert!(p.crossflow_sigma_m(40.0) > p.crossflow_sigma_m(10.0));
    }

    #[test]
    fn rasterised_grid_matches_field_on_nodes_and_reads_back() {
        let p = plume(Some(4.0));
        let g = GriddedConcentration::rasterise(
            &p,
            (0.0, 50.0, 51),
            (-10.0, 10.0, 41),
            Some((0.0, 4.0, 9)),
        )
        .unwrap();
        for q in [Vec3::new(10.0, 0.0, 3.0), Vec3::new(25.0, -2.5, 1.0)] {
            let (a, b) = (g.concentration(q), p.concentration(q));
            assert!((a - b).abs() <= 1e-9 * b.max(1e-12), "{a} vs {b}");
        }
        assert_eq!(g.concentration(Vec3::new(60.0, 0.0, 3.0)), 0.0);
        let dir = std::env::temp_dir().join(format!("plumetrace-steady-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("c.csv");
        let mut text = String::from("x_m,y_m,concentration\n");
        for j in 0..3 {
            for i in 0..4 {
                text += &format!("{},{},{}\n", i as f64 * 2.0, j as f64, (i + 10 * j) as f64);
            }
        }
        std::fs::write(&path, text).unwrap();
        let g = GriddedConcentration::from_csv(&path).unwrap();
        assert!((g.concentration(Vec3::new(3.0, 1.5, 7.0)) - (1.5 + 15.0)).abs() < 1e-12);
        std::fs::write(&path, "x_m,y_m,concentration\n0,0,1\n1,0,2\n0,1,3\n").unwrap();
        let e = GriddedConcentration::from_csv(&path)
            .unwrap_err()
            .to_string();
        assert!(e.contains("incomplete"), "{e}");
    }
}
