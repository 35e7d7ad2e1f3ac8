//! Uniform-grid spatial index over filaments for fast concentration queries.
//!
//! Filaments are sorted by cell (a counting sort) into one contiguous array, so the filaments of a
//! row of cells are adjacent in memory and a query scans a few short slices. The cell size is at
//! least the largest cut-off radius, so a query touches at most 3 x 3 cells (more only when the
//! cell size is raised to bound the number of cells).

use super::filament::{FilamentPlume, VerticalBoundary};
use crate::Rect;
use plumetrace_core::Vec3;

/// Most cells an index may have.
const MAX_CELLS: f64 = 1_048_576.0;

/// One filament, prepared for queries.
#[derive(Debug, Clone, Copy)]
struct Entry {
    x: f64,
    y: f64,
    z: f64,
    /// Squared cut-off distance.
    lim2: f64,
    /// `Q / ((2 pi)^(3/2) r^3)`.
    amp: f64,
    /// `-1 / (2 r^2)`.
    neg_inv_2r2: f64,
}

/// The index: cells of size `cell_m` over the domain, row-major, with `starts[c]..starts[c + 1]`
/// the entries of cell `c`.
#[derive(Debug)]
pub(crate) struct CellIndex {
    x0: f64,
    y0: f64,
    inv_cell: f64,
    ncx: usize,
    ncy: usize,
    search_m: f64,
    starts: Vec<u32>,
    entries: Vec<Entry>,
    floor: Option<f64>,
    ceiling: Option<f64>,
}

impl CellIndex {
    pub(crate) fn build(
        plume: &FilamentPlume,
        domain: Rect,
        cutoff_radii: f64,
        vertical: VerticalBoundary,
    ) -> Self {
        let n = plume.x.len();
        // The oldest filament is the largest (radii only grow).
        let r2_max = (0..n).map(|k| plume.radius_sq(k)).fold(0.0_f64, f64::max);
        let search_m = cutoff_radii * r2_max.sqrt();
        let (w, h) = (domain.width_m(), domain.height_m());
        let mut cell = search_m.max(w.max(h) / 1024.0);
        if (w / cell).ceil() * (h / cell).ceil() > MAX_CELLS {
            cell = (w * h / MAX_CELLS).sqrt() * 1.001;
        }
        let ncx = ((w / cell).ceil() as usize).max(1);
        let ncy = ((h / cell).ceil() as usize).max(1);
        let inv_cell = 1.0 / cell;
        let cell_of = |x: f64, y: f64| -> usize {
            let i = (((x - domain.x_min_m) * inv_cell) as usize).min(ncx - 1);
            let j = (((y - domain.y_min_m) * inv_cell) as usize).min(ncy - 1);
            j * ncx + i
        };
        let mut starts = vec![0u32; ncx * ncy + 1];
        let mut cells = Vec::with_capacity(n);
        for k in 0..n {
            let c = cell_of(plume.x[k], plume.y[k]);
            cells.push(c as u32);
            starts[c + 1] += 1;
        }
        for c in 0..ncx * ncy {
            starts[c + 1] += starts[c];
        }
        let mut fill = starts.clone();
        let blank = Entry {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            lim2: -1.0,
            amp: 0.0,
            neg_inv_2r2: 0.0,
        };
        let mut entries = vec![blank; n];
        let norm = (2.0 * std::f64::consts::PI).powf(1.5);
        let cut2 = cutoff_radii * cutoff_radii;
        for (k, &cell) in cells.iter().enumerate() {
            let c = cell as usize;
            let slot = fill[c] as usize;
            fill[c] += 1;
            let r2 = plume.radius_sq(k);
            entries[slot] = Entry {
                x: plume.x[k],
                y: plume.y[k],
                z: plume.z[k],
                lim2: cut2 * r2,
                amp: plume.mass[k] / (norm * r2 * r2.sqrt()),
                neg_inv_2r2: -0.5 / r2,
            };
        }
        let (floor, ceiling) = match vertical {
            VerticalBoundary::Reflecting { depth_m } => (Some(0.0), depth_m),
            VerticalBoundary::Unbounded => (None, None),
        };
        CellIndex {
            x0: domain.x_min_m,
            y0: domain.y_min_m,
            inv_cell,
            ncx,
            ncy,
            search_m,
            starts,
            entries,
            floor,
            ceiling,
        }
    }

    fn cell_range(&self, lo: f64, hi: f64, origin: f64, n: usize) -> Option<(usize, usize)> {
        let a = ((lo - origin) * self.inv_cell).floor();
        let b = ((hi - origin) * self.inv_cell).floor();
        if b < 0.0 || a > (n - 1) as f64 || a.is_nan() || b.is_nan() {
            return None;
        }
        Some((a.max(0.0) as usize, (b as usize).min(n - 1)))
    }

    pub(crate) fn concentration(&self, p: Vec3) -> f64 {
        if self.entries.is_empty() {
            return 0.0;
        }
        let r = self.search_m;
        let Some((i0, i1)) = self.cell_range(p.x - r, p.x + r, self.x0, self.ncx) else {
            return 0.0;
        };
        let Some((j0, j1)) = self.cell_range(p.y - r, p.y + r, self.y0, self.ncy) else {
            return 0.0;
        };
        let mut c = 0.0;
        for j in j0..=j1 {
            let a = self.starts[j * self.ncx + i0] as usize;
            let b = self.starts[j * self.ncx + i1 + 1] as usize;
            for e in &self.entries[a..b] {
                let dx = p.x - e.x;
                let dy = p.y - e.y;
                let dxy2 = dx * dx + dy * dy;
                if dxy2 > e.lim2 {
                    continue;
                }
                let dz = p.z - e.z;
                let d2 = dxy2 + dz * dz;
                if d2 < e.lim2 {
                    c += e.amp * (d2 * e.neg_inv_2r2).exp();
                }
                if let Some(f) = self.floor {
                    let dz = p.z - (2.0 * f - e.z);
                    let d2 = dxy2 + dz * dz;
                    if d2 < e.lim2 {
                        c += e.amp * (d2 * e.neg_inv_2r2).exp();
                    }
                }
                if let Some(s) = self.ceiling {
                    let dz = p.z - (2.0 * s - e.z);
                    let d2 = dxy2 + dz * dz;
                    if d2 < e.lim2 {
                        c += e.amp * (d2 * e.neg_inv_2r2).exp();
                    }
                }
            }
        }
        c
    }
}
