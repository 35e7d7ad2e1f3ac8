//! The source-map panels of the mission figure: the maps a planner reported at its declaration
//! and at the end, each zoomed on its most likely cell with the sources, the first declaration
//! and the estimated tracks up to the map's time.

use super::layout::map_overhead_px;
use super::model::{pieces_where, thin};
use super::raster::{Raster, raster_cells, raster_peak};
use super::style::{SOURCE_MARK, WIDTH_PX};
use crate::chart::{dashed_within, map_chart};
use crate::error::ReportError;
use plotters::prelude::*;
use plumetrace_core::Vec2;
use plumetrace_mission::{MissionRun, TrajectoryRow};
use std::collections::BTreeMap;

/// The height of the row of source-map panels, px.
pub(super) const POSTERIOR_PX: u32 = 316;
/// The key under each source-map panel, px.
const NOTE_PX: u32 = 16;

/// The source maps of `snaps` side by side, each zoomed on its most likely cell, the true
/// sources and the first declaration, with the estimated tracks over them.
pub(super) fn draw_posteriors<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
    snaps: &[(String, Raster<'_>)],
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    // Two columns: a lone map takes the left one (at the same scale as a pair would).
    let panels = area.split_evenly((1, 2));
    let (w_px, h_px) = panels
        .first()
        .map_or((WIDTH_PX, POSTERIOR_PX), |p| p.dim_in_pixel());
    let declared = run
        .summary
        .declarations
        .first()
        .map(|d| Vec2::new(d.x_m, d.y_m));
    for (whole, (title, r)) in panels.iter().zip(snaps) {
        // The key goes under the map, clear of its axis' name.
        let (panel, key) = whole.split_vertically(h_px.saturating_sub(NOTE_PX));
        let h_px = h_px.saturating_sub(NOTE_PX);
        let peak = raster_peak(r);
        let mut pts = vec![peak];
        pts.extend(run.sources.iter().map(|s| Vec2::new(s.x, s.y)));
        pts.extend(declared);
        let (mut lo, mut hi) = (peak, peak);
        for p in &pts {
            lo = Vec2::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Vec2::new(hi.x.max(p.x), hi.y.max(p.y));
        }
        // At least 150 m across, a quarter of the span around what matters, one scale.
        let (over_w, over_h) = map_overhead_px(w_px, title)?;
        let (pw, ph) = (
            f64::from(w_px.saturating_sub(over_w).max(1)),
            f64::from(h_px.saturating_sub(over_h).max(1)),
        );
        let span = (hi - lo) * 1.5;
        let half_y = (0.5 * span.y).max(0.5 * span.x * ph / pw).max(75.0);
        let half_x = half_y * pw / ph;
        let c = (lo + hi) * 0.5;
        let (x, y) = (c.x - half_x..c.x + half_x, c.y - half_y..c.y + half_y);
        let mut chart = map_chart(&panel, title, x.clone(), y.clone())?;
        chart
            .draw_series(
                raster_cells(r, &x, &y)
                    .into_iter()
                    .map(|(b, col)| Rectangle::new(b, col.filled())),
            )
            .map_err(ReportError::figure)?;
        chart
            .draw_series(dashed_within(&run.op_area, BLACK, 1, &x, &y))
            .map_err(ReportError::figure)?;
        // The estimated tracks up to the map's time, in pieces inside the window (a piece ends
        // where the track leaves it, so no line crosses the panel where the vehicle did not go).
        for rs in rows.values() {
            let pieces = pieces_where(
                rs.iter()
                    .filter(|q| q.t_s <= r.0)
                    .map(|q| q.est_x_m.zip(q.est_y_m)),
                |p| x.contains(&p.0) && y.contains(&p.1),
            );
            chart
                .draw_series(pieces.iter().map(|p| {
                    PathElement::new(
                        thin(p, 2.0 * half_x / pw),
                        RGBColor(70, 70, 70).mix(0.7).stroke_width(1),
                    )
                }))
                .map_err(ReportError::figure)?;
        }
        chart
            .draw_series(std::iter::once(Cross::new(
                (peak.x, peak.y),
                6,
                RGBColor(200, 0, 0).stroke_width(2),
            )))
            .map_err(ReportError::figure)?;
        chart
            .draw_series(
                run.sources
                    .iter()
                    .map(|s| TriangleMarker::new((s.x, s.y), 7, SOURCE_MARK.filled())),
            )
            .map_err(ReportError::figure)?;
        chart
            .draw_series(
                declared
                    .iter()
                    .map(|d| Circle::new((d.x, d.y), 5, BLACK.filled())),
            )
            .map_err(ReportError::figure)?;
        let (px0, _) = chart.plotting_area().get_pixel_range();
        let note = "\u{00d7} most likely cell   \u{25b2} source   \u{25cf} declared";
        key.draw(&Text::new(
            note,
            (px0.start + 4, 2),
            ("sans-serif", 11).into_font().color(&BLACK),
        ))
        .map_err(ReportError::figure)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::super::legend::legend_px;
    use super::super::mission_figure;
    use super::super::raster::{hot_points, posterior_snapshots, raster_peak};
    use super::super::test_support::{demo, layout, raster_event};
    use plumetrace_core::{DeclarationKind, PlannerEvent, Vec2};
    use plumetrace_mission::{EventKind, EventRecord};

    #[test]
    fn the_source_map_is_shown_at_the_declaration_and_at_the_end() {
        let mut run = demo(240.0);
        // No map: no panels.
        assert!(posterior_snapshots(&run).is_empty());
        let without = mission_figure(&run, "maps").unwrap();
        assert!(!without.contains("source map at"));
        // Maps at 60 s and 150 s, a declaration at 100 s, a last map at 200 s: the panels show
        // the 60 s map (the last before the declaration) and the 200 s one.
        run.events.push(raster_event(60.0, 3, 4));
        run.events.push(raster_event(150.0, 5, 5));
        run.events.push(EventRecord {
            t_s: 100.0,
            vehicle: 0,
            event: EventKind::Planner(PlannerEvent::Declared {
                pos_m: Vec2::new(17.5, -27.5),
                rule: DeclarationKind::new("source_map"),
            }),
        });
        run.events.push(raster_event(200.0, 10, 12));
        let snaps = posterior_snapshots(&run);
        let times: Vec<f64> = snaps.iter().map(|s| s.1.0).collect();
        assert_eq!(times, [60.0, 200.0]);
        assert_eq!(raster_peak(&snaps[0].1), Vec2::new(17.5, -27.5));
        assert_eq!(raster_peak(&snaps[1].1), Vec2::new(52.5, 12.5));
        let svg = mission_figure(&run, "maps").unwrap();
        assert!(
            svg.contains("source map at the declaration (60 s)"),
            "title"
        );
        assert!(svg.contains("source map at the end (200 s)"), "title");
        // Both panels carry their key; the figure without maps has none.
        assert_eq!(svg.matches("most likely cell").count(), 2);
        assert!(!without.contains("most likely cell"));
        // One map reported at the declaration and none after: one panel says so.
        run.events
            .retain(|e| !matches!(&e.event, EventKind::Telemetry(_)) || e.t_s < 100.0);
        let snaps = posterior_snapshots(&run);
        assert_eq!(snaps.len(), 1);
        assert!(
            snaps[0].0.contains("at the declaration and end"),
            "{}",
            snaps[0].0
        );
        // The legend stays off the map's likely cells.
        let lay = layout(&run);
        if let Some(c) = lay.legend_corner {
            let (lw, lh) = legend_px(&lay.legend);
            let fx = lw / f64::from(lay.plot_px.0) * (lay.x.end - lay.x.start);
            let fy = lh / f64::from(lay.plot_px.1) * (lay.y.end - lay.y.start);
            let (bx, by) = c.box_in(&lay.x, &lay.y, fx, fy);
            assert!(
                !hot_points(&run)
                    .iter()
                    .any(|p| bx.contains(&p.0) && by.contains(&p.1)),
                "the legend hides the map's peak"
            );
        }
    }
}
