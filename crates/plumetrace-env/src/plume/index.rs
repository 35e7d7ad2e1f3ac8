//! Uniform-grid spatial index over filaments for fast concentration queries.
//!
//! Filaments are sorted by cell (a counting sort) into one contiguous array, so the filaments of a
//! row of cells are adjacent in memory and a query scans a few short slices. The cell size is at
//! least the largest cut-off radius, so a query touches at most 3 x 3 cells (more only when the
//! cell size is raised to bound the number of cells).

use super::exp_lanes::ScaledExp;
use super::filament::{FilamentPlume, VerticalBoundary};
use crate::{GridSpec, Rect};
use plumetrace_core::Vec3;
use rayon::prelude::*;

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

/// The entries' positions and squared cut-offs, one column each, in the entries' order: what a
/// grid query's first pass reads (so that it runs in vector lanes).
#[derive(Debug, Default)]
struct Columns {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    lim2: Vec<f64>,
}

impl Columns {
    fn of(entries: &[Entry]) -> Self {
        let column = |f: fn(&Entry) -> f64| entries.iter().map(f).collect();
        Columns {
            x: column(|e| e.x),
            y: column(|e| e.y),
            z: column(|e| e.z),
            lim2: column(|e| e.lim2),
        }
    }
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
    columns: Columns,
    floor: Option<f64>,
    ceiling: Option<f64>,
}

impl CellIndex {
    pub(crate) fn build(
        plume: &FilamentPlume,
        domain: Rect,
        cutoff_radii: f64,
        vertical: VerticalBoundary,
        seabed: Option<&crate::seabed::Seabed>,
    ) -> Self {
        let n = plume.x.len();
        let (px, py, pz, pb, pm) = (
            &*plume.x,
            &*plume.y,
            &*plume.z,
            &*plume.birth_s,
            &*plume.mass,
        );
        // Filament k's position in the plane, back from the plume's origin.
        let [ox, oy] = plume.origin;
        let wide_x = |k: usize| f64::from(px[k]) + ox;
        let wide_y = |k: usize| f64::from(py[k]) + oy;
        // Over a seabed each filament's image in the seabed where it is joins the index as an
        // entry of its own (after the filaments), and no image is taken at z = 0.
        let images: Vec<f64> = match (seabed, vertical) {
            (Some(sb), VerticalBoundary::Reflecting { .. }) => (0..n)
                .map(|k| 2.0 * sb.height_at(wide_x(k), wide_y(k)) - f64::from(pz[k]))
                .collect(),
            _ => Vec::new(),
        };
        let total = n + images.len();
        // Entry `e`'s filament and height.
        let of = |e: usize| -> (usize, f64) {
            if e < n {
                (e, f64::from(pz[e]))
            } else {
                (e - n, images[e - n])
            }
        };
        // The oldest filament is the largest (radii only grow).
        let r2_max = (0..n)
            .map(|k| plume.radius_sq_born(pb[k]))
            .fold(0.0_f64, f64::max);
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
            let i = floor_index((x - domain.x_min_m) * inv_cell).min(ncx - 1);
            let j = floor_index((y - domain.y_min_m) * inv_cell).min(ncy - 1);
            j * ncx + i
        };
        let mut starts = vec![0u32; ncx * ncy + 1];
        let mut cells = Vec::with_capacity(total);
        for e in 0..total {
            let k = of(e).0;
            let c = cell_of(wide_x(k), wide_y(k));
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
        let mut entries = vec![blank; total];
        let norm = (2.0 * std::f64::consts::PI).powf(1.5);
        let cut2 = cutoff_radii * cutoff_radii;
        for (e, &cell) in cells.iter().enumerate() {
            let c = cell as usize;
            let slot = fill[c] as usize;
            fill[c] += 1;
            let (k, z) = of(e);
            let r2 = plume.radius_sq_born(pb[k]);
            entries[slot] = Entry {
                x: wide_x(k),
                y: wide_y(k),
                z,
                lim2: cut2 * r2,
                amp: pm[k] / (norm * r2 * r2.sqrt()),
                neg_inv_2r2: -0.5 / r2,
            };
        }
        // (An image's own image in the surface lies above the surface by the water's depth
        // and more: out of reach of any point in the water but for filaments as wide as the
        // water is deep.)
        let (floor, ceiling) = match vertical {
            VerticalBoundary::Reflecting { .. } if !images.is_empty() => {
                (None, ceiling_of(vertical))
            }
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
            columns: Columns::of(&entries),
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

/// What a grid query needs of one grid: the points' coordinates and, per cell column and cell
/// row of the index, the grid columns and rows whose window of cells (the cells
/// [`CellIndex::concentration`] scans for a point) holds it.
struct GridAxes {
    xs: Vec<f64>,
    ys: Vec<f64>,
    z: f64,
    inv_dx: f64,
    inv_dy: f64,
    col_span: Vec<(usize, usize)>,
    row_span: Vec<(usize, usize)>,
}

/// The indices `lo..hi` along an axis of spacing `1 / inv_step` from `origin` that may lie
/// within `half` of `c` (a millionth of a spacing to spare, far above the rounding of the
/// coordinates; the exact test decides), before they are made whole ([`whole_span`]): in
/// floating point only, so that a loop of them runs in vector lanes.
#[inline(always)]
fn axis_span(c: f64, half: f64, origin: f64, inv_step: f64) -> [f64; 2] {
    let slack = 1e-6 + 1e-14 * (c.abs() + half + origin.abs()) * inv_step;
    let lo = (c - half - origin) * inv_step - slack;
    let hi = (c + half - origin) * inv_step + slack;
    [lo, hi]
}

/// The floor of `f`, at least zero (NaN too; truncation is the floor of a value that is not
/// negative). Through `i64`, which x86-64 converts in one instruction where `usize` takes
/// several: a value that does not fit either way (beyond 2^63) is cut to the grid or the cells
/// by the caller just the same.
#[inline(always)]
fn floor_index(f: f64) -> usize {
    if f > 0.0 { f as i64 as usize } else { 0 }
}

/// The whole indices `a..b` of an [`axis_span`]: the floor of `lo` and one past the floor of
/// `hi`, neither below zero ([`floor_index`]).
#[inline(always)]
fn whole_span([lo, hi]: [f64; 2]) -> (usize, usize) {
    let a = floor_index(lo);
    let b = if hi >= 0.0 {
        (hi as i64 as usize).saturating_add(1)
    } else {
        0
    };
    (a, b)
}

/// Per cell `0..cells`, the points `lo..hi` whose window (`windows`, one per point) holds it;
/// `None` unless every such set is one run of points.
fn spans(windows: &[Option<(usize, usize)>], cells: usize) -> Option<Vec<(usize, usize)>> {
    let mut span = vec![(usize::MAX, 0); cells];
    let mut count = vec![0usize; cells];
    for (k, w) in windows.iter().enumerate() {
        let Some((a, b)) = *w else { continue };
        for c in a..=b.min(cells - 1) {
            span[c] = (span[c].0.min(k), span[c].1.max(k + 1));
            count[c] += 1;
        }
    }
    span.iter_mut()
        .zip(&count)
        .map(|(s, &n)| {
            if n == 0 {
                Some((0, 0))
            } else {
                (s.1 - s.0 == n).then_some(*s)
            }
        })
        .collect()
}

/// How a grid query computes each term's exponential.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum TermExp {
    /// The standard library's `exp`, as [`CellIndex::concentration`]: bit for bit what point
    /// queries give.
    Standard,
    /// [`super::exp_lanes::exp_nonpositive`] in vector lanes: each term within 2 units in the last place of the
    /// standard one, the same bits on every CPU (for figures and pages).
    Lanes,
}

/// A grid query's terms, gathered in the order the points add them and then evaluated and added
/// in that order, in batches of at most `cap`.
struct Gathered {
    /// The grid point (in the band) each term is added to.
    at: Vec<u32>,
    /// The exponential's argument, then the term.
    arg: Vec<f64>,
    /// The filament's peak.
    amp: Vec<f64>,
    n: usize,
    /// Room for this many terms, a power of two (the columns' length).
    cap: usize,
}

impl Gathered {
    /// Room for at least `room` terms.
    fn with_room(room: usize) -> Self {
        let cap = room.next_power_of_two();
        Gathered {
            at: vec![0; cap],
            arg: vec![0.0; cap],
            amp: vec![0.0; cap],
            n: 0,
            cap,
        }
    }

    /// The terms of filament `e` at the points `xs` of a row (`at`: the first one's place),
    /// `dy2` from the row, with the `N` heights `dz2` (in order); the caller has made room for
    /// them all. Each is kept if it is within the cut-off: the slot past the last kept term is
    /// written either way and only a kept term takes it (no branch to mispredict on a
    /// filament's ragged edge). The slots are taken modulo the room, which changes none of
    /// them (there is room) but lets the compiler drop the bounds checks.
    #[inline(always)]
    fn row<const N: usize>(&mut self, e: &Entry, xs: &[f64], at: usize, dy2: f64, dz2: &[f64; 3]) {
        debug_assert!(
            self.n + xs.len() * N <= self.cap,
            "no room for a row's terms"
        );
        let mask = self.cap - 1;
        let (ats, args, amps) = (
            &mut self.at[..=mask],
            &mut self.arg[..=mask],
            &mut self.amp[..=mask],
        );
        let mut n = self.n;
        for (i, &x) in xs.iter().enumerate() {
            let dx = x - e.x;
            // The point query's sums: d2 = (dx^2 + dy^2) + dz^2, a term where d2 is below
            // the cut-off.
            let dxy2 = dx * dx + dy2;
            for &t in &dz2[..N] {
                let d2 = dxy2 + t;
                let slot = n & mask;
                ats[slot] = (at + i) as u32;
                args[slot] = d2 * e.neg_inv_2r2;
                amps[slot] = e.amp;
                n += usize::from(d2 < e.lim2);
            }
        }
        self.n = n;
    }

    /// Evaluates the terms gathered and adds each to its point, in order.
    fn flush(&mut self, how: TermExp, arch: pulp::Arch, out: &mut [f64]) {
        let n = self.n;
        let (arg, amp) = (&mut self.arg[..n], &self.amp[..n]);
        match how {
            TermExp::Standard => {
                for (a, &m) in arg.iter_mut().zip(amp) {
                    *a = m * a.exp();
                }
            }
            TermExp::Lanes => arch.dispatch(ScaledExp { arg, amp }),
        }
        for (&at, &term) in self.at[..n].iter().zip(&self.arg[..n]) {
            out[at as usize] += term;
        }
        self.n = 0;
    }
}

/// Entries per run of a grid query's first pass.
const REACH_RUN: usize = 256;

/// A run of entries' reach (see [`CellIndex::reaches`]).
struct Reaches {
    /// Heights in reach.
    n: [usize; REACH_RUN],
    /// Their squared distances, the first `n` of the three (a column each).
    heights: [[f64; REACH_RUN]; 3],
    /// The grid rows and columns in reach, as [`axis_span`]s (a column each for the rows'
    /// ends and the columns').
    spans: [[f64; REACH_RUN]; 4],
}

impl Default for Reaches {
    fn default() -> Self {
        Reaches {
            n: [0; REACH_RUN],
            heights: [[0.0; REACH_RUN]; 3],
            spans: [[0.0; REACH_RUN]; 4],
        }
    }
}

/// One band of a grid query, as a [`pulp::WithSimd`] operation so that all of it is compiled
/// for the vector unit chosen.
struct Band<'a> {
    index: &'a CellIndex,
    axes: &'a GridAxes,
    rows: (usize, usize),
    out: &'a mut [f64],
    how: TermExp,
    arch: pulp::Arch,
}

impl pulp::WithSimd for Band<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let (j0, j1) = self.rows;
        self.index
            .scatter_band(self.axes, j0, j1, self.out, self.how, self.arch);
    }
}

impl CellIndex {
    /// Concentrations at every point of `grid`, row by row with x fastest (the order of
    /// [`GridSpec::points`]): with [`TermExp::Standard`], bit for bit what
    /// [`CellIndex::concentration`] gives at each point.
    ///
    /// A point's sum adds its filaments in the index's memory order (cell rows, then cells, then
    /// the filaments of a cell), which is one order for every point; so the filaments can be
    /// taken one at a time, each adding its terms to the grid points it reaches, and every point
    /// still sums the same terms in the same order. Each filament visits only the grid points
    /// near it instead of every point scanning every filament of its 3 x 3 cells. What each
    /// filament reaches (its heights within the cut-off and its box of grid points) is worked
    /// out for runs of filaments in vector lanes first; the terms are gathered and their
    /// exponentials taken in batches, then added in the same order. A
    /// grid that is not a proper lattice (a single row or column, a spacing that is not finite
    /// and positive) is queried point by point.
    ///
    /// The rows are split into `bands` bands taken in parallel (one: all on the calling thread);
    /// every point sums the same terms in the same order whatever the number.
    pub(crate) fn grid_concentrations(
        &self,
        grid: &GridSpec,
        out: &mut [f64],
        how: TermExp,
        bands: usize,
    ) {
        // A band's points are numbered in 32 bits (`Gathered::at`).
        let axes = self
            .grid_axes(grid)
            .filter(|_| grid.nx.saturating_mul(grid.ny) <= u32::MAX as usize);
        let Some(axes) = axes else {
            for (o, p) in out.iter_mut().zip(grid.points()) {
                *o = self.concentration(p);
            }
            return;
        };
        let arch = crate::simd::best();
        // A filament is visited once per band its cells reach.
        let band_rows = grid.ny.div_ceil(bands.max(1));
        let band = |(band, rows): (usize, &mut [f64])| {
            rows.fill(0.0);
            let j0 = band * band_rows;
            arch.dispatch(Band {
                index: self,
                axes: &axes,
                rows: (j0, j0 + rows.len() / grid.nx),
                out: rows,
                how,
                arch,
            });
        };
        if band_rows >= grid.ny {
            band((0, out));
        } else {
            out.par_chunks_mut(grid.nx * band_rows)
                .enumerate()
                .for_each(band);
        }
    }

    /// The grid's axes and spans, or `None` for a grid that is not a proper lattice.
    fn grid_axes(&self, g: &GridSpec) -> Option<GridAxes> {
        if g.nx < 2 || g.ny < 2 || self.entries.is_empty() {
            return None;
        }
        let dx = (g.x_max_m - g.x_min_m) / (g.nx - 1) as f64;
        let dy = (g.y_max_m - g.y_min_m) / (g.ny - 1) as f64;
        let scale = g.x_min_m.abs() + g.x_max_m.abs() + g.y_min_m.abs() + g.y_max_m.abs() + 1.0;
        let finite = [g.x_min_m, g.y_min_m, g.z_m, dx, dy]
            .iter()
            .all(|v| v.is_finite());
        if !(finite && dx > 1e-9 * scale && dy > 1e-9 * scale) {
            return None;
        }
        // The same coordinates as `GridSpec::points`, so the same windows and distances.
        let xs: Vec<f64> = (0..g.nx).map(|i| g.x_min_m + i as f64 * dx).collect();
        let ys: Vec<f64> = (0..g.ny).map(|j| g.y_min_m + j as f64 * dy).collect();
        let r = self.search_m;
        let cols: Vec<_> = xs
            .iter()
            .map(|&x| self.cell_range(x - r, x + r, self.x0, self.ncx))
            .collect();
        let rows: Vec<_> = ys
            .iter()
            .map(|&y| self.cell_range(y - r, y + r, self.y0, self.ncy))
            .collect();
        Some(GridAxes {
            col_span: spans(&cols, self.ncx)?,
            row_span: spans(&rows, self.ncy)?,
            xs,
            ys,
            z: g.z_m,
            inv_dx: 1.0 / dx,
            inv_dy: 1.0 / dy,
        })
    }

    /// Adds every filament's terms to the grid rows `j0..j1` (`out`, row by row), filament by
    /// filament in the index's order. Each row of cells is taken in runs of entries: a first
    /// pass works out every entry's heights in reach and the grid rows and columns it may reach
    /// (in vector lanes, [`CellIndex::reaches`]), then the entries visit their grid points in
    /// order.
    #[inline(always)]
    fn scatter_band(
        &self,
        axes: &GridAxes,
        j0: usize,
        j1: usize,
        out: &mut [f64],
        how: TermExp,
        arch: pulp::Arch,
    ) {
        let nx = axes.xs.len();
        // Room for a few thousand terms, and for every term of a whole row.
        let mut terms_of = Gathered::with_room((3 * nx).max(4096));
        let mut reach = Box::new(Reaches::default());
        // The cell columns from the first to the last whose entries may reach the grid (a
        // column between them that cannot has an empty span, which passes its entries over).
        let reaches_grid = |s: &(usize, usize)| s.0 < s.1;
        let (Some(ci0), Some(ci1)) = (
            axes.col_span.iter().position(reaches_grid),
            axes.col_span.iter().rposition(reaches_grid),
        ) else {
            return;
        };
        for (cj, &(rs0, rs1)) in axes.row_span.iter().enumerate() {
            let (rs0, rs1) = (rs0.max(j0), rs1.min(j1));
            if rs0 >= rs1 {
                continue;
            }
            let row_cells = cj * self.ncx;
            let (a, b) = (
                self.starts[row_cells + ci0] as usize,
                self.starts[row_cells + ci1 + 1] as usize,
            );
            // The cell of the entry at hand.
            let mut ci = ci0;
            for start in (a..b).step_by(REACH_RUN) {
                let m = (b - start).min(REACH_RUN);
                self.reaches(start, m, axes, &mut reach);
                for r in 0..m {
                    let k = start + r;
                    while k >= self.starts[row_cells + ci + 1] as usize {
                        ci += 1;
                    }
                    let (cs0, cs1) = axes.col_span[ci];
                    let n = reach.n[r];
                    if n == 0 {
                        continue;
                    }
                    let [ra, rb, ca, cb] = [0, 1, 2, 3].map(|i| reach.spans[i][r]);
                    let (ra, rb) = whole_span([ra, rb]);
                    let (ca, cb) = whole_span([ca, cb]);
                    let (ra, rb) = (ra.max(rs0), rb.min(rs1));
                    let (ca, cb) = (ca.max(cs0), cb.min(cs1));
                    if ca >= cb {
                        continue;
                    }
                    let e = &self.entries[k];
                    let all_terms = [0, 1, 2].map(|i| reach.heights[i][r]);
                    for j in ra..rb {
                        let dy = axes.ys[j] - e.y;
                        let dy2 = dy * dy;
                        // dx * dx + dy2 is at least dy2, so this skips nothing the sum adds.
                        if dy2 > e.lim2 {
                            continue;
                        }
                        if terms_of.n + (cb - ca) * n > terms_of.cap {
                            terms_of.flush(how, arch, out);
                        }
                        let row = (j - j0) * nx;
                        let xs = &axes.xs[ca..cb];
                        match n {
                            1 => terms_of.row::<1>(e, xs, row + ca, dy2, &all_terms),
                            2 => terms_of.row::<2>(e, xs, row + ca, dy2, &all_terms),
                            _ => terms_of.row::<3>(e, xs, row + ca, dy2, &all_terms),
                        }
                    }
                }
            }
        }
        terms_of.flush(how, arch, out);
    }

    /// For the `m` entries from `start`: their squared vertical distances to the grid's height
    /// below their cut-off (from the filament and its images in the seabed and the surface, in
    /// the order [`CellIndex::concentration`] adds them) and how many, and the grid rows and
    /// columns within their reach left in the plane (before the cells' windows cut them). A
    /// loop without branches, so that compiled for a vector unit it takes several entries at
    /// once; the same operations as one entry at a time.
    #[inline(always)]
    fn reaches(&self, start: usize, m: usize, axes: &GridAxes, out: &mut Reaches) {
        let e = &self.columns;
        let (x, y, z, lim2) = (
            &e.x[start..start + m],
            &e.y[start..start + m],
            &e.z[start..start + m],
            &e.lim2[start..start + m],
        );
        // A missing boundary's image is at NaN: its distance is never below the cut-off.
        let floor = self.floor.unwrap_or(f64::NAN);
        let ceiling = self.ceiling.unwrap_or(f64::NAN);
        let (x_origin, y_origin) = (axes.xs[0], axes.ys[0]);
        let n = &mut out.n[..m];
        let [h0, h1, h2] = &mut out.heights;
        let (h0, h1, h2) = (&mut h0[..m], &mut h1[..m], &mut h2[..m]);
        let [ra, rb, ca, cb] = &mut out.spans;
        let (ra, rb) = (&mut ra[..m], &mut rb[..m]);
        let (ca, cb) = (&mut ca[..m], &mut cb[..m]);
        for k in 0..m {
            let all = [
                axes.z - z[k],
                axes.z - (2.0 * floor - z[k]),
                axes.z - (2.0 * ceiling - z[k]),
            ]
            .map(|dz| dz * dz);
            // The distances in reach, first, in order (by selects, so that the loop runs in
            // lanes); the nearest of them.
            let [d0, d1, d2] = all;
            let [k0, k1, k2] = all.map(|d2| d2 < lim2[k]);
            h0[k] = if k0 {
                d0
            } else if k1 {
                d1
            } else {
                d2
            };
            h1[k] = if k0 && k1 { d1 } else { d2 };
            h2[k] = d2;
            n[k] = usize::from(k0) + usize::from(k1) + usize::from(k2);
            let near = if k0 { d0 } else { f64::INFINITY };
            let near = if k1 && d1 < near { d1 } else { near };
            let near = if k2 && d2 < near { d2 } else { near };
            // At least the reach left in the plane (the rounding of the difference is below
            // the added billionth).
            let left = lim2[k] - near;
            let left = if left > 0.0 { left } else { 0.0 };
            let half = (left + 1e-9 * lim2[k]).sqrt();
            [ra[k], rb[k]] = axis_span(y[k], half, y_origin, axes.inv_dy);
            [ca[k], cb[k]] = axis_span(x[k], half, x_origin, axes.inv_dx);
        }
    }
}

/// The surface's height of a vertical boundary, if it has one.
fn ceiling_of(vertical: VerticalBoundary) -> Option<f64> {
    match vertical {
        VerticalBoundary::Reflecting { depth_m } => depth_m,
        VerticalBoundary::Unbounded => None,
    }
}
