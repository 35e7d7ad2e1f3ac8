//! The figure's rasters as cells to draw: the time-averaged plume (a light heat map) and the
//! source-likelihood maps planners reported (shades of blue); the maps worth a panel of their
//! own; and the hot cells the legend must not hide.

use plotters::prelude::*;
use plumetrace_core::{PlannerEvent, Vec2};
use plumetrace_mission::{EventKind, MissionRun};
use std::ops::Range;

/// The time-averaged plume as light cells over `x` x `y` (square-root scale, 24 shades; equal
/// neighbours along a row merged into one rectangle).
pub(super) fn plume_cells(
    run: &MissionRun,
    x: &Range<f64>,
    y: &Range<f64>,
) -> Vec<([(f64, f64); 2], RGBColor)> {
    let Some(mp) = &run.mean_plume else {
        return Vec::new();
    };
    let g = *mp.spec();
    if g.nx < 2 || g.ny < 2 {
        return Vec::new();
    }
    let mean = mp.mean();
    let max = finite_peak(&mean);
    if max <= 0.0 {
        return Vec::new();
    }
    let (dx, dy) = (
        (g.x_max_m - g.x_min_m) / (g.nx - 1) as f64,
        (g.y_max_m - g.y_min_m) / (g.ny - 1) as f64,
    );
    let shade = |i: usize, j: usize| -> Option<u32> {
        let c = mean.get(j * g.nx + i).copied().unwrap_or(0.0) / max;
        (c.is_finite() && c > 1e-3).then(|| (c.sqrt() * 24.0).round().max(1.0) as u32)
    };
    let mut cells = Vec::new();
    for j in 0..g.ny {
        let yc = g.y_min_m + j as f64 * dy;
        let (ya, yb) = ((yc - dy / 2.0).max(y.start), (yc + dy / 2.0).min(y.end));
        if ya >= yb {
            continue;
        }
        let mut i = 0;
        while i < g.nx {
            let Some(s) = shade(i, j) else {
                i += 1;
                continue;
            };
            let mut e = i + 1;
            while e < g.nx && shade(e, j) == Some(s) {
                e += 1;
            }
            let xa = (g.x_min_m + i as f64 * dx - dx / 2.0).max(x.start);
            let xb = (g.x_min_m + (e - 1) as f64 * dx + dx / 2.0).min(x.end);
            if xa < xb {
                let l = f64::from(s) / 24.0;
                let col = RGBColor(255, (246.0 - 120.0 * l) as u8, (236.0 - 190.0 * l) as u8);
                cells.push(([(xa, ya), (xb, yb)], col));
            }
            i = e;
        }
    }
    cells
}

/// One source-likelihood map a planner reported: its time, origin, cell size, cells along x and
/// y, and `log10 p` per cell.
pub(super) type Raster<'a> = (f64, Vec2, f64, usize, usize, &'a [f32]);

/// Every whole source-likelihood map the planners reported, in time order.
fn rasters(run: &MissionRun) -> Vec<Raster<'_>> {
    run.events
        .iter()
        .filter_map(|e| match &e.event {
            EventKind::Telemetry(plumetrace_core::Telemetry::SourceMapRaster {
                origin_m,
                cell_m,
                nx,
                ny,
                log10_p,
            }) => Some((e.t_s, *origin_m, *cell_m, *nx, *ny, log10_p.as_slice())),
            _ => None,
        })
        .filter(|r| r.5.len() == r.3 * r.4 && r.2.is_finite() && r.2 > 0.0)
        .collect()
}

/// The maps worth showing on their own: the one reported at (or last before) the first
/// declaration and the last one, labelled; one map when they are the same.
pub(super) fn posterior_snapshots(run: &MissionRun) -> Vec<(String, Raster<'_>)> {
    let all = rasters(run);
    let Some(&last) = all.last() else {
        return Vec::new();
    };
    let declared_s = run.events.iter().find_map(|e| match e.event {
        EventKind::Planner(PlannerEvent::Declared { .. }) => Some(e.t_s),
        _ => None,
    });
    let at_declaration = declared_s.and_then(|t| all.iter().rev().find(|r| r.0 <= t).copied());
    match at_declaration {
        Some(d) if d.0 < last.0 => vec![
            (format!("source map at the declaration ({:.0} s)", d.0), d),
            (format!("source map at the end ({:.0} s)", last.0), last),
        ],
        Some(d) => vec![(
            format!("source map at the declaration and end ({:.0} s)", d.0),
            d,
        )],
        None => vec![(format!("source map at the end ({:.0} s)", last.0), last)],
    }
}

/// The centre of the most likely cell of a map.
pub(super) fn raster_peak(r: &Raster<'_>) -> Vec2 {
    let (_, origin, cell, nx, _, lp) = *r;
    let k = lp
        .iter()
        .enumerate()
        .fold((0, f32::MIN), |b, (k, &l)| if l > b.1 { (k, l) } else { b })
        .0;
    Vec2::new(
        origin.x + ((k % nx) as f64 + 0.5) * cell,
        origin.y + ((k / nx) as f64 + 0.5) * cell,
    )
}

/// The largest finite value of a mean-plume raster (0 when there is none).
fn finite_peak(values: &[f64]) -> f64 {
    values
        .iter()
        .copied()
        .filter(|c| c.is_finite())
        .fold(0.0, f64::max)
}

/// Centres of the cells the legend must not hide: the mean plume above a tenth of its peak and
/// the last source map within 3 decades of its peak.
pub(super) fn hot_points(run: &MissionRun) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    if let Some(mp) = &run.mean_plume {
        let g = *mp.spec();
        let mean = mp.mean();
        let max = finite_peak(&mean);
        if g.nx >= 2 && g.ny >= 2 && max > 0.0 {
            let dx = (g.x_max_m - g.x_min_m) / (g.nx - 1) as f64;
            let dy = (g.y_max_m - g.y_min_m) / (g.ny - 1) as f64;
            for (k, &c) in mean.iter().enumerate() {
                if c.is_finite() && c > 0.1 * max {
                    let (i, j) = (k % g.nx, k / g.nx);
                    out.push((g.x_min_m + i as f64 * dx, g.y_min_m + j as f64 * dy));
                }
            }
        }
    }
    if let Some(&(_, origin, cell, nx, _, lp)) = rasters(run).last() {
        let peak = lp.iter().copied().fold(f32::MIN, f32::max);
        for (k, &l) in lp.iter().enumerate() {
            if l >= peak - 3.0 {
                out.push((
                    origin.x + ((k % nx) as f64 + 0.5) * cell,
                    origin.y + ((k / nx) as f64 + 0.5) * cell,
                ));
            }
        }
    }
    out
}

/// The last source-likelihood map a planner reported (its whole raster), as cells over `x` x `y`
/// (see [`raster_cells`]).
pub(super) fn posterior_cells(
    run: &MissionRun,
    x: &Range<f64>,
    y: &Range<f64>,
) -> Vec<([(f64, f64); 2], RGBColor)> {
    rasters(run)
        .last()
        .map_or(Vec::new(), |r| raster_cells(r, x, y))
}

/// A source-likelihood map as cells over `x` x `y`: `log10 p` from 6 decades below the peak to
/// the peak in 12 shades of blue (equal neighbours along a row merged into one rectangle). Drawn
/// under the tracks, over the mean plume.
pub(super) fn raster_cells(
    r: &Raster<'_>,
    x: &Range<f64>,
    y: &Range<f64>,
) -> Vec<([(f64, f64); 2], RGBColor)> {
    let (_, origin, cell, nx, ny, lp) = *r;
    let peak = lp.iter().copied().fold(f32::MIN, f32::max);
    let shade = |i: usize, j: usize| -> Option<u32> {
        let l = f64::from(lp[j * nx + i] - peak) / 6.0 + 1.0;
        (l > 0.0).then(|| (l * 12.0).ceil().clamp(1.0, 12.0) as u32)
    };
    let mut cells = Vec::new();
    for j in 0..ny {
        let ya = (origin.y + j as f64 * cell).max(y.start);
        let yb = (origin.y + (j + 1) as f64 * cell).min(y.end);
        if ya >= yb {
            continue;
        }
        let mut i = 0;
        while i < nx {
            let Some(s) = shade(i, j) else {
                i += 1;
                continue;
            };
            let mut e = i + 1;
            while e < nx && shade(e, j) == Some(s) {
                e += 1;
            }
            let xa = (origin.x + i as f64 * cell).max(x.start);
            let xb = (origin.x + e as f64 * cell).min(x.end);
            if xa < xb {
                let l = f64::from(s) / 12.0;
                let col = RGBColor(
                    (225.0 - 190.0 * l) as u8,
                    (235.0 - 150.0 * l) as u8,
                    (255.0 - 70.0 * l) as u8,
                );
                cells.push(([(xa, ya), (xb, yb)], col));
            }
            i = e;
        }
    }
    cells
}
