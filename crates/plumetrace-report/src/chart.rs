//! What every map shares: the map panel (East/North axes at one style) and dashed outlines. The
//! mission figure, the plume figure and the campaign's trajectory charts draw on these, so that
//! maps look the same everywhere.

use crate::error::ReportError;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plumetrace_core::Vec2;

/// A map panel's chart: East and North in metres.
pub type MapChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A map panel: `title` above, East/North axes in metres over `x` and `y`, no grid lines. Shared
/// by every figure so that maps look the same.
pub fn map_chart<'a, DB: DrawingBackend + 'a>(
    area: &'a DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
) -> Result<MapChart<'a, DB>, ReportError>
where
    DB::ErrorType: 'static,
{
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .margin_right(25)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x, y)
        .map_err(ReportError::figure)?;
    // Whole metres, and about one label per 90 pixels so that narrow panels stay readable.
    let (w, h) = area.dim_in_pixel();
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels((w / 90).clamp(3, 10) as usize)
        .y_labels((h / 60).clamp(3, 12) as usize)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .x_desc("East (m)")
        .y_desc("North (m)")
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(ReportError::figure)?;
    Ok(chart)
}

/// A closed polygon drawn dashed (dash length scaled to the edge, gaps 3/4 of a dash).
pub fn dashed(points: &[Vec2], colour: RGBColor, width: u32) -> Vec<PathElement<(f64, f64)>> {
    dashed_where(points, colour, width, |_| true)
}

/// [`dashed`], keeping only the dashes that lie wholly within `x` by `y` (a zoomed view: a dash
/// outside the view would otherwise be drawn pressed against its frame).
pub fn dashed_within(
    points: &[Vec2],
    colour: RGBColor,
    width: u32,
    x: &std::ops::Range<f64>,
    y: &std::ops::Range<f64>,
) -> Vec<PathElement<(f64, f64)>> {
    dashed_where(points, colour, width, |p| {
        x.contains(&p.x) && y.contains(&p.y)
    })
}

fn dashed_where(
    points: &[Vec2],
    colour: RGBColor,
    width: u32,
    keep: impl Fn(Vec2) -> bool,
) -> Vec<PathElement<(f64, f64)>> {
    let mut out = Vec::new();
    let n = points.len();
    for i in 0..n {
        let (a, b) = (points[i], points[(i + 1) % n]);
        let len = (b - a).norm();
        let dir = if len > 0.0 {
            (b - a) / len
        } else {
            Vec2::zeros()
        };
        let dash = (len / 60.0).clamp(4.0, 12.0);
        let mut s = 0.0;
        while s < len {
            let e = (s + dash).min(len);
            let p = a + dir * s;
            let q = a + dir * e;
            if keep(p) && keep(q) {
                out.push(PathElement::new(
                    vec![(p.x, p.y), (q.x, q.y)],
                    colour.stroke_width(width),
                ));
            }
            s += 1.75 * dash;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;
    use plotters::element::PointCollection;

    #[test]
    fn a_zoomed_outline_keeps_only_the_dashes_inside_the_view() {
        // A 400 x 160 m op-area seen through a 100 x 100 m window over its west end: only the
        // west edge and the parts of the north and south edges inside the window are drawn.
        let area = [
            Vec2::new(60.0, -80.0),
            Vec2::new(460.0, -80.0),
            Vec2::new(460.0, 80.0),
            Vec2::new(60.0, 80.0),
        ];
        let (x, y) = (20.0..120.0, -90.0..90.0);
        let all = dashed(&area, BLACK, 1);
        let kept = dashed_within(&area, BLACK, 1, &x, &y);
        assert!(!kept.is_empty() && kept.len() < all.len() / 2);
        for d in &kept {
            for (px, py) in d.point_iter() {
                assert!(
                    x.contains(px) && y.contains(py),
                    "({px}, {py}) outside the view"
                );
            }
        }
        assert_eq!(
            dashed_within(&area, BLACK, 1, &(-1e9..1e9), &(-1e9..1e9)).len(),
            all.len()
        );
    }
}
