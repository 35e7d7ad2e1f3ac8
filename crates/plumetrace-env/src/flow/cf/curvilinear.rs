//! A curvilinear horizontal grid (an ocean model's 2-D longitude and latitude, or projected x and
//! y, arrays such as ROMS's `lon_rho`/`lat_rho`): finding it, checking its cells, and placing a
//! point in it (a cell search through buckets, then inverse bilinear interpolation).
//!
//! A cell whose corners form a rectangle aligned with the axes is inverted by the same arithmetic
//! as a rectilinear axis, so a curvilinear file whose coordinates are an even grid samples, bit
//! for bit, as the rectilinear file does.

use super::{Axis, Cell, EvenGrid, axis_of, edge_points, err, length_scale};
use crate::{EnvError, Rect};
use plumetrace_core::geo::LocalFrame;
use plumetrace_netcdf::{NcFile, Var};
use std::path::Path;

/// A cell's local coordinates beyond `[0, 1]` by at most this much still place a point in it.
const INSIDE_TOL: f64 = 1e-9;

/// The 2-D coordinates of a curvilinear grid, node `(i, j)` at `[j * nxi + i]`.
#[derive(Debug, Clone)]
pub(crate) struct Curvilinear {
    /// The file's dimensions: `eta` (the slower, `j`) then `xi` (the faster, `i`).
    pub(crate) dims: [usize; 2],
    /// The coordinate variables' names, x (longitude) then y (latitude).
    pub(crate) names: [String; 2],
    /// Node coordinates in the file's units (degrees, or metres for a projected grid).
    pub(crate) px: Vec<f64>,
    pub(crate) py: Vec<f64>,
    pub(crate) nxi: usize,
    pub(crate) neta: usize,
    /// Longitude and latitude (else projected metres).
    pub(crate) geographic: bool,
    /// Metres per unit of x relative to y in the distance used for the nearest node (the cosine
    /// of the mean latitude on a geographic grid).
    x_weight: f64,
    /// Cells by bucket: the buckets' extent, their count a side and each one's cells.
    bucket: Buckets,
}

#[derive(Debug, Clone, Default)]
struct Buckets {
    x0: f64,
    y0: f64,
    sx: f64,
    sy: f64,
    nbx: usize,
    nby: usize,
    cells: Vec<Vec<u32>>,
}

/// Whether the missing-value attributes or the usual fill mark `r` as missing.
fn is_missing(r: f64, missing: &[f64]) -> bool {
    !r.is_finite() || missing.contains(&r) || r.abs() > 1e30
}

/// The curvilinear grid of `u`, if its horizontal dimensions have no 1-D coordinates and 2-D
/// coordinate variables (named in its `coordinates` attribute, or any with a longitude and
/// latitude standard name or units) span two of its dimensions.
pub(crate) fn find(file: &NcFile, u: &Var, path: &Path) -> Result<Option<Curvilinear>, EnvError> {
    let spans = |v: &&Var| v.dims.len() == 2 && v.dims.iter().all(|d| u.dims.contains(d));
    let listed: Vec<&Var> = u
        .text("coordinates")
        .map(|s| s.split_whitespace().filter_map(|n| file.var(n)).collect())
        .unwrap_or_default();
    let pool: Vec<&Var> = if listed.iter().any(spans) {
        listed
    } else {
        file.vars.iter().collect()
    };
    let pick = |want: [Axis; 2]| {
        pool.iter()
            .copied()
            .filter(spans)
            .find(|v| axis_of(v).is_some_and(|k| want.contains(&k)))
    };
    let (Some(xv), Some(yv)) = (pick([Axis::Lon, Axis::X]), pick([Axis::Lat, Axis::Y])) else {
        return Ok(None);
    };
    // Both horizontal dimensions with their own 1-D coordinates: a rectilinear grid.
    let has_1d = |d: usize| {
        file.var(&file.dims[d].name)
            .filter(|c| c.dims == [d])
            .and_then(axis_of)
            .is_some()
    };
    if xv.dims.iter().all(|&d| has_1d(d)) {
        return Ok(None);
    }
    let geographic = axis_of(xv) == Some(Axis::Lon);
    if (axis_of(yv) == Some(Axis::Lat)) != geographic || xv.dims != yv.dims {
        return Err(err(
            path,
            format!(
                "variable {}: its 2-D coordinates {} and {} need the same two dimensions and \
                 both be longitude and latitude, or both projected x and y",
                u.name, xv.name, yv.name
            ),
        ));
    }
    let (neta, nxi) = (file.dims[xv.dims[0]].len, file.dims[xv.dims[1]].len);
    if neta < 2 || nxi < 2 {
        return Err(err(
            path,
            format!(
                "variables {} and {}: a curvilinear grid needs at least 2 x 2 nodes, not {neta} x \
                 {nxi}",
                xv.name, yv.name
            ),
        ));
    }
    let read = |v: &Var| -> Result<Vec<f64>, EnvError> {
        let vals = file.values(v).map_err(|e| err(path, e.to_string()))?;
        let mut missing: Vec<f64> = Vec::new();
        for a in ["_FillValue", "missing_value"] {
            missing.extend(v.attr(a).and_then(|a| a.as_numbers()).unwrap_or_default());
        }
        if let Some(k) = vals.iter().position(|&r| is_missing(r, &missing)) {
            return Err(err(
                path,
                format!(
                    "variable {}: a missing or non-finite value at ({} {}, {} {}); a curvilinear \
                     grid's coordinates must be given at every node",
                    v.name,
                    file.dims[v.dims[0]].name,
                    k / nxi,
                    file.dims[v.dims[1]].name,
                    k % nxi
                ),
            ));
        }
        let s = if geographic {
            1.0
        } else {
            length_scale(v, path)?
        };
        Ok(vals.iter().map(|x| x * s).collect())
    };
    let (px, py) = (read(xv)?, read(yv)?);
    let x_weight = if geographic {
        let mean = py.iter().sum::<f64>() / py.len() as f64;
        mean.to_radians().cos().abs().max(1e-6)
    } else {
        1.0
    };
    let mut g = Curvilinear {
        dims: [xv.dims[0], xv.dims[1]],
        names: [xv.name.clone(), yv.name.clone()],
        px,
        py,
        nxi,
        neta,
        geographic,
        x_weight,
        bucket: Buckets::default(),
    };
    g.check_cells(file, path)?;
    g.bucket = g.buckets();
    Ok(Some(g))
}

impl Curvilinear {
    fn node(&self, i: usize, j: usize) -> (f64, f64) {
        let k = j * self.nxi + i;
        (self.px[k], self.py[k])
    }

    /// The corners of cell `(i, j)`: (i, j), (i+1, j), (i+1, j+1), (i, j+1).
    fn corners(&self, i: usize, j: usize) -> [(f64, f64); 4] {
        [
            self.node(i, j),
            self.node(i + 1, j),
            self.node(i + 1, j + 1),
            self.node(i, j + 1),
        ]
    }

    /// Every cell convex, with area, and turning the same way as the first.
    fn check_cells(&self, file: &NcFile, path: &Path) -> Result<(), EnvError> {
        let mut sign = 0.0;
        for j in 0..self.neta - 1 {
            for i in 0..self.nxi - 1 {
                let c = self.corners(i, j);
                let mut turn = [0.0; 4];
                for (k, t) in turn.iter_mut().enumerate() {
                    let (a, b, n) = (c[k], c[(k + 1) % 4], c[(k + 2) % 4]);
                    *t = (b.0 - a.0) * (n.1 - b.1) - (b.1 - a.1) * (n.0 - b.0);
                }
                if sign == 0.0 {
                    sign = turn[0].signum();
                }
                if !turn.iter().all(|t| t * sign > 0.0) {
                    return Err(err(
                        path,
                        format!(
                            "variables {} and {}: the grid's cell at ({} {j}, {} {i}) is folded \
                             or degenerate (its corners do not turn the same way as the rest of \
                             the grid's, or it has no area); a curvilinear grid must be a mesh \
                             of convex cells",
                            self.names[0],
                            self.names[1],
                            file.dims[self.dims[0]].name,
                            file.dims[self.dims[1]].name,
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Cells by bucket over the grid's extent, about one cell a bucket.
    fn buckets(&self) -> Buckets {
        let range = |a: &[f64]| {
            a.iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                    (lo.min(v), hi.max(v))
                })
        };
        let ((x0, x1), (y0, y1)) = (range(&self.px), range(&self.py));
        let cells = (self.nxi - 1) * (self.neta - 1);
        let side = ((cells as f64).sqrt().ceil() as usize).clamp(1, 1024);
        let (nbx, nby) = (side, side);
        let sx = ((x1 - x0) / nbx as f64).max(f64::MIN_POSITIVE);
        let sy = ((y1 - y0) / nby as f64).max(f64::MIN_POSITIVE);
        let mut b = Buckets {
            x0,
            y0,
            sx,
            sy,
            nbx,
            nby,
            cells: vec![Vec::new(); nbx * nby],
        };
        for j in 0..self.neta - 1 {
            for i in 0..self.nxi - 1 {
                let c = self.corners(i, j);
                let (lo, hi) = c.iter().fold(
                    (
                        (f64::INFINITY, f64::INFINITY),
                        (f64::NEG_INFINITY, f64::NEG_INFINITY),
                    ),
                    |(lo, hi), p| {
                        (
                            (lo.0.min(p.0), lo.1.min(p.1)),
                            (hi.0.max(p.0), hi.1.max(p.1)),
                        )
                    },
                );
                let (bi0, bj0) = b.index(lo.0, lo.1);
                let (bi1, bj1) = b.index(hi.0, hi.1);
                for bj in bj0..=bj1 {
                    for bi in bi0..=bi1 {
                        b.cells[bj * nbx + bi].push((j * (self.nxi - 1) + i) as u32);
                    }
                }
            }
        }
        b
    }

    /// The cell holding `(x, y)` (file units) and its local coordinates: `((i, s), (j, t))`;
    /// `None` outside the grid. On an edge shared by two cells, the one of higher index.
    pub(crate) fn locate(&self, x: f64, y: f64) -> Option<((usize, f64), (usize, f64))> {
        let b = &self.bucket;
        if !(x.is_finite() && y.is_finite()) {
            return None;
        }
        let (fx, fy) = ((x - b.x0) / b.sx, (y - b.y0) / b.sy);
        let tol = 1e-9;
        if fx < -tol || fy < -tol || fx > b.nbx as f64 + tol || fy > b.nby as f64 + tol {
            return None;
        }
        let (bi, bj) = b.index(x, y);
        let mut best: Option<((usize, f64), (usize, f64))> = None;
        for &c in &b.cells[bj * b.nbx + bi] {
            let (i, j) = (c as usize % (self.nxi - 1), c as usize / (self.nxi - 1));
            let Some((s, t)) = inverse_bilinear(&self.corners(i, j), x, y) else {
                continue;
            };
            if best.is_none_or(|((bi, _), (bj, _))| (j, i) > (bj, bi)) {
                best = Some(((i, s), (j, t)));
            }
        }
        best
    }

    /// The node nearest `(x, y)` on the grid's boundary, as a cell with zero weights.
    pub(crate) fn nearest_edge(&self, x: f64, y: f64) -> ((usize, f64), (usize, f64)) {
        let (ni, nj) = (self.nxi, self.neta);
        let boundary = (0..ni)
            .flat_map(|i| [(i, 0), (i, nj - 1)])
            .chain((0..nj).flat_map(|j| [(0, j), (ni - 1, j)]));
        let d2 = |(i, j): (usize, usize)| {
            let (px, py) = self.node(i, j);
            let dx = (px - x) * self.x_weight;
            dx * dx + (py - y) * (py - y)
        };
        let (i, j) = boundary
            .min_by(|a, b| d2(*a).total_cmp(&d2(*b)))
            .unwrap_or((0, 0));
        ((i, 0.0), (j, 0.0))
    }

    /// The smallest cell edge in metres (degrees through the site's frame's scale at its
    /// origin on a geographic grid: `m_per_deg` east and north).
    pub(crate) fn native_spacing(&self, m_per_deg: (f64, f64)) -> f64 {
        let (ex, ny) = if self.geographic {
            m_per_deg
        } else {
            (1.0, 1.0)
        };
        let len = |a: (f64, f64), b: (f64, f64)| ((b.0 - a.0) * ex).hypot((b.1 - a.1) * ny);
        let mut s = f64::INFINITY;
        for j in 0..self.neta {
            for i in 0..self.nxi {
                if i + 1 < self.nxi {
                    s = s.min(len(self.node(i, j), self.node(i + 1, j)));
                }
                if j + 1 < self.neta {
                    s = s.min(len(self.node(i, j), self.node(i, j + 1)));
                }
            }
        }
        s
    }

    /// The grid's extent: (x min, x max), (y min, y max).
    pub(crate) fn extent(&self) -> ((f64, f64), (f64, f64)) {
        let b = &self.bucket;
        (
            (b.x0, b.x0 + b.sx * b.nbx as f64),
            (b.y0, b.y0 + b.sy * b.nby as f64),
        )
    }
}

/// The even grid over `area` and each node's cell in the curvilinear grid `c` (see
/// [`super::place`]): the op-area's edge and every node in it must lie in a cell.
#[allow(clippy::too_many_arguments)]
pub(crate) fn place<'a>(
    c: &Curvilinear,
    frame: Option<&'a LocalFrame>,
    spacing_m: Option<f64>,
    area: Rect,
    must_cover: Rect,
    what: &str,
    on_lon_lat: &str,
    path: &Path,
) -> Result<(EvenGrid<'a>, Vec<Cell>), EnvError> {
    let ((x0, x1), (y0, y1)) = c.extent();
    let m_per_deg = frame.map_or((1.0, 1.0), |f| {
        let (o, d) = (f.origin(), 1e-3);
        (
            f.to_local(o.lat_deg, o.lon_deg + d).x.abs() / d,
            f.to_local(o.lat_deg + d, o.lon_deg).y.abs() / d,
        )
    });
    let spacing = spacing_m.unwrap_or_else(|| c.native_spacing(m_per_deg));
    let g = EvenGrid::new(
        &[x0, x1],
        &[y0, y1],
        c.geographic,
        frame,
        Some(spacing),
        area,
        on_lon_lat,
        path,
    )?;
    let (xn, yn) = if c.geographic {
        ("lon", "lat")
    } else {
        ("x", "y")
    };
    let outside = |x: f64, y: f64, (fx, fy): (f64, f64)| {
        err(
            path,
            format!(
                "{what} curvilinear grid ({} and {}: {xn} {x0:.6} to {x1:.6}, {yn} {y0:.6} to \
                 {y1:.6}) does not cover the op-area: its point ({x:.1}, {y:.1}) m is at {xn} \
                 {fx:.6}, {yn} {fy:.6}, in none of the grid's cells",
                c.names[0], c.names[1]
            ),
        )
    };
    for (x, y) in edge_points(must_cover, g.spacing) {
        let f = g.to_file(x, y);
        if c.locate(f.0, f.1).is_none() {
            return Err(outside(x, y, f));
        }
    }
    let mut cells = Vec::with_capacity(g.nx * g.ny);
    for j in 0..g.ny {
        for i in 0..g.nx {
            let (x, y) = (
                area.x_min_m + i as f64 * g.dx,
                area.y_min_m + j as f64 * g.dy,
            );
            let f = g.to_file(x, y);
            cells.push(match c.locate(f.0, f.1) {
                Some(cell) => cell,
                None if must_cover.contains_xy(x, y) => return Err(outside(x, y, f)),
                None => c.nearest_edge(f.0, f.1),
            });
        }
    }
    Ok((g, cells))
}

impl Buckets {
    fn index(&self, x: f64, y: f64) -> (usize, usize) {
        let f = |v: f64, o: f64, s: f64, n: usize| {
            let k = ((v - o) / s).floor();
            if k > 0.0 { (k as usize).min(n - 1) } else { 0 }
        };
        (
            f(x, self.x0, self.sx, self.nbx),
            f(y, self.y0, self.sy, self.nby),
        )
    }
}

/// The local coordinates `(s, t)` in `[0, 1]` of `(x, y)` in the cell with corners
/// `c` = (0, 0), (1, 0), (1, 1), (0, 1); `None` outside it.
pub(crate) fn inverse_bilinear(c: &[(f64, f64); 4], x: f64, y: f64) -> Option<(f64, f64)> {
    let [p00, p10, p11, p01] = *c;
    // A rectangle along the axes: each coordinate alone, as a rectilinear axis locates.
    if p10.1 == p00.1 && p11.1 == p01.1 && p01.0 == p00.0 && p11.0 == p10.0 {
        let s = (x - p00.0) / (p10.0 - p00.0);
        let t = (y - p00.1) / (p01.1 - p00.1);
        let inside = |w: f64| (0.0..=1.0).contains(&w);
        return (inside(s) && inside(t)).then_some((s.clamp(0.0, 1.0), t.clamp(0.0, 1.0)));
    }
    let b = (p10.0 - p00.0, p10.1 - p00.1);
    let cc = (p01.0 - p00.0, p01.1 - p00.1);
    let d = (p11.0 - p10.0 - p01.0 + p00.0, p11.1 - p10.1 - p01.1 + p00.1);
    let (mut s, mut t) = (0.5, 0.5);
    for _ in 0..30 {
        let r = (
            p00.0 + b.0 * s + cc.0 * t + d.0 * s * t - x,
            p00.1 + b.1 * s + cc.1 * t + d.1 * s * t - y,
        );
        let (j00, j01) = (b.0 + d.0 * t, cc.0 + d.0 * s);
        let (j10, j11) = (b.1 + d.1 * t, cc.1 + d.1 * s);
        let det = j00 * j11 - j01 * j10;
        if !(det.is_finite() && det != 0.0) {
            return None;
        }
        let ds = (r.0 * j11 - r.1 * j01) / det;
        let dt = (r.1 * j00 - r.0 * j10) / det;
        s -= ds;
        t -= dt;
        if ds.abs() < 1e-14 && dt.abs() < 1e-14 {
            break;
        }
    }
    let inside = |w: f64| (-INSIDE_TOL..=1.0 + INSIDE_TOL).contains(&w);
    (inside(s) && inside(t)).then_some((s.clamp(0.0, 1.0), t.clamp(0.0, 1.0)))
}
