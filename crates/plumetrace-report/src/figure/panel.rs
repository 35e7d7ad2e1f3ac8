//! The reading panel of the mission figure: for the vehicles with a planner, the chemical
//! reading against mission time (thinned so that spikes survive), fault windows shaded, the
//! source map's entropy, lines at declarations, aborts and incidents, and the behaviour in
//! control as a strip under it.

use super::layout::MapLayout;
use super::model::{MarkKind, behaviour_spans};
use super::style::{
    ABORT_MARK, ENTROPY_LINE, FAULT_FILL, READING_LINE, READING_PX, STRIP_PX, TRACK_COLOURS,
    behaviour_colour, label_style,
};
use crate::error::ReportError;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plumetrace_mission::{EventKind, MissionRun, TrajectoryRow};
use std::collections::BTreeMap;

/// The reading panel's height, px, for `n` vehicles (0: no panel).
pub(super) fn panel_h_px(n: usize) -> u32 {
    if n == 0 {
        0
    } else {
        READING_PX + 20 + STRIP_PX * n as u32 + 56
    }
}

/// A reading series thinned to the lowest and the highest reading of each of `columns` time
/// columns over `0..t_max` (in time order), so that spikes survive.
pub(super) fn min_max_columns(
    points: &[(f64, f64)],
    t_max: f64,
    columns: usize,
) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    let col = |t: f64| ((t / t_max.max(1e-9)) * columns as f64).floor() as i64;
    let mut k = 0;
    while k < points.len() {
        let c = col(points[k].0);
        let mut e = k;
        let (mut lo, mut hi) = (k, k);
        while e < points.len() && col(points[e].0) == c {
            if points[e].1 < points[lo].1 {
                lo = e;
            }
            if points[e].1 > points[hi].1 {
                hi = e;
            }
            e += 1;
        }
        let (a, b) = (lo.min(hi), lo.max(hi));
        out.push(points[a]);
        if b != a {
            out.push(points[b]);
        }
        k = e;
    }
    out
}

/// A vertical line in the reading panel: when, what, and its colour.
type PanelLine = (f64, String, RGBColor, bool);

/// What the parts of the reading panel are drawn from.
#[derive(Clone, Copy)]
struct PanelData<'a> {
    run: &'a MissionRun,
    rows: &'a BTreeMap<u32, Vec<&'a TrajectoryRow>>,
    lay: &'a MapLayout,
    /// The vehicles shown, top to bottom.
    vehicles: &'a [u32],
    /// The time axis' end, min.
    t_max_min: f64,
    /// The reading axis' top.
    y_hi: f64,
}

/// The reading chart: mission time (min) against the reading.
type ReadingChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The reading panel: each vehicle's reading against time, the behaviour strips, fault windows
/// shaded, lines at declarations, aborts and incidents.
pub(super) fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
    lay: &MapLayout,
    vehicles: &[u32],
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    let n = vehicles.len();
    let t_max_min = (rows
        .values()
        .filter_map(|r| r.last())
        .map(|r| r.t_s)
        .fold(0.0, f64::max)
        / 60.0)
        .max(1e-3);
    let strips_h = STRIP_PX * n as u32 + 56;
    // The readings' unit: the sensors' when they share one.
    let units: Vec<&str> = vehicles
        .iter()
        .filter_map(|&v| run.vehicles.get(v as usize))
        .map(|v| v.reading_unit)
        .collect();
    let y_desc = match units.first() {
        Some(u) if units.iter().all(|x| x == u) => format!("reading ({u})"),
        _ => "reading".to_string(),
    };
    let (_, h) = area.dim_in_pixel();
    let (upper, lower) = area.split_vertically(h.saturating_sub(strips_h));
    let y_max = vehicles
        .iter()
        .filter_map(|v| rows.get(v))
        .flatten()
        .map(|r| r.reading_v)
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    let y_hi = if y_max > 0.0 { 1.08 * y_max } else { 1.0 };
    let mut chart = ChartBuilder::on(&upper)
        .margin(12)
        .margin_right(25)
        .margin_bottom(0)
        .x_label_area_size(0)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t_max_min, 0.0..y_hi)
        .map_err(ReportError::figure)?;
    let digits = if y_hi >= 10.0 {
        0
    } else if y_hi >= 1.0 {
        1
    } else {
        2
    };
    chart
        .configure_mesh()
        .disable_mesh()
        .y_labels(5)
        .y_label_formatter(&|v| format!("{v:.digits$}"))
        .y_desc(y_desc)
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(ReportError::figure)?;
    let p = PanelData {
        run,
        rows,
        lay,
        vehicles,
        t_max_min,
        y_hi,
    };
    draw_readings(&mut chart, p, upper.dim_in_pixel().0 as usize)?;
    draw_entropy(&mut chart, p)?;
    draw_lines(&mut chart, p)?;
    draw_strips(&lower, p)
}

/// The fault windows shaded and each vehicle's reading, thinned to `cols` columns.
fn draw_readings<DB: DrawingBackend>(
    chart: &mut ReadingChart<'_, DB>,
    p: PanelData<'_>,
    cols: usize,
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    let PanelData {
        run,
        rows,
        lay,
        vehicles,
        t_max_min,
        y_hi,
    } = p;
    // Fault windows.
    let windows: Vec<(f64, f64)> = vehicles
        .iter()
        .filter_map(|&v| run.vehicles.get(v as usize))
        .flat_map(|v| v.faults.iter())
        .map(|f| ((f.start_s / 60.0).max(0.0), (f.end_s / 60.0).min(t_max_min)))
        .filter(|(a, b)| a < b)
        .collect();
    chart
        .draw_series(
            windows.iter().map(|&(a, b)| {
                Rectangle::new([(a, 0.0), (b, y_hi)], FAULT_FILL.mix(0.35).filled())
            }),
        )
        .map_err(ReportError::figure)?;
    for (k, &v) in vehicles.iter().enumerate() {
        let Some(rs) = rows.get(&v) else { continue };
        let pts: Vec<(f64, f64)> = rs
            .iter()
            .filter(|r| r.reading_v.is_finite())
            .map(|r| (r.t_s / 60.0, r.reading_v))
            .collect();
        let colour = if lay.multi {
            lay.layers
                .iter()
                .find(|l| l.vehicle == v)
                .map_or(TRACK_COLOURS[k % TRACK_COLOURS.len()], |l| l.colour)
        } else {
            READING_LINE
        };
        chart
            .draw_series(std::iter::once(PathElement::new(
                min_max_columns(&pts, t_max_min, cols),
                colour.stroke_width(1),
            )))
            .map_err(ReportError::figure)?;
    }
    Ok(())
}

/// The source map's entropy (a planner that keeps a map reports it), scaled to the panel's
/// height: 0 at the bottom, the largest reported value at the top.
fn draw_entropy<DB: DrawingBackend>(
    chart: &mut ReadingChart<'_, DB>,
    p: PanelData<'_>,
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    let PanelData {
        run,
        vehicles,
        t_max_min,
        y_hi,
        ..
    } = p;
    let entropy: Vec<(f64, f64)> = run
        .events
        .iter()
        .filter(|e| vehicles.contains(&e.vehicle))
        .filter_map(|e| match &e.event {
            EventKind::Telemetry(plumetrace_core::Telemetry::SourceMap {
                entropy_bits, ..
            }) if entropy_bits.is_finite() => Some((e.t_s / 60.0, *entropy_bits)),
            _ => None,
        })
        .collect();
    let h_max = entropy.iter().map(|p| p.1).fold(0.0, f64::max);
    if entropy.len() > 1 && h_max > 0.0 {
        let scaled: Vec<(f64, f64)> = entropy
            .iter()
            .map(|&(t, h)| (t, h / h_max * y_hi * 0.95))
            .collect();
        chart
            .draw_series(std::iter::once(PathElement::new(
                scaled,
                ENTROPY_LINE.stroke_width(2),
            )))
            .map_err(ReportError::figure)?;
        chart
            .draw_series(std::iter::once(Text::new(
                format!("source map entropy (0-{h_max:.1} bits)"),
                (t_max_min * 0.01, y_hi * 0.99),
                ("sans-serif", 12).into_font().color(&ENTROPY_LINE),
            )))
            .map_err(ReportError::figure)?;
    }
    Ok(())
}

/// Lines at declarations, aborts and incidents, each labelled.
fn draw_lines<DB: DrawingBackend>(
    chart: &mut ReadingChart<'_, DB>,
    p: PanelData<'_>,
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    let PanelData {
        run,
        lay,
        vehicles,
        t_max_min,
        y_hi,
        ..
    } = p;
    let mut lines: Vec<PanelLine> = run
        .summary
        .declarations
        .iter()
        .filter(|d| vehicles.contains(&d.vehicle))
        .map(|d| (d.t_s / 60.0, "declared".to_string(), BLACK, false))
        .collect();
    lines.extend(
        lay.marks
            .iter()
            .filter(|k| vehicles.contains(&k.vehicle))
            .map(|k| {
                let c = match k.kind {
                    MarkKind::Incident(_) => BLACK,
                    _ => ABORT_MARK,
                };
                (k.t_s / 60.0, k.kind.short().to_string(), c, true)
            }),
    );
    for (t, label, c, dash) in &lines {
        let segs: Vec<PathElement<(f64, f64)>> = if *dash {
            let d = y_hi / 24.0;
            (0..24)
                .step_by(2)
                .map(|i| {
                    PathElement::new(
                        vec![(*t, f64::from(i) * d), (*t, f64::from(i + 1) * d)],
                        c.stroke_width(2),
                    )
                })
                .collect()
        } else {
            vec![PathElement::new(
                vec![(*t, 0.0), (*t, y_hi)],
                c.stroke_width(1),
            )]
        };
        chart.draw_series(segs).map_err(ReportError::figure)?;
        let (dx, h) = if *t < 0.8 * t_max_min {
            (4, HPos::Left)
        } else {
            (-4, HPos::Right)
        };
        chart
            .draw_series(std::iter::once(
                EmptyElement::at((*t, y_hi))
                    + Text::new(
                        label.clone(),
                        (dx, 3),
                        label_style(11, *c, Pos::new(h, VPos::Top)),
                    ),
            ))
            .map_err(ReportError::figure)?;
    }
    Ok(())
}

/// The behaviour strips, first vehicle on top.
fn draw_strips<DB: DrawingBackend>(
    lower: &DrawingArea<DB, plotters::coord::Shift>,
    p: PanelData<'_>,
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    let PanelData {
        run,
        rows,
        vehicles,
        t_max_min,
        ..
    } = p;
    let n = vehicles.len();
    let mut strips = ChartBuilder::on(lower)
        .margin_left(12)
        .margin_right(25)
        .margin_top(4)
        .margin_bottom(6)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t_max_min, 0.0..n as f64)
        .map_err(ReportError::figure)?;
    strips
        .configure_mesh()
        .disable_mesh()
        .disable_y_axis()
        .x_labels(12)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .x_desc("mission time (min)")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(ReportError::figure)?;
    for (k, &v) in vehicles.iter().enumerate() {
        let Some(rs) = rows.get(&v) else { continue };
        let y0 = (n - 1 - k) as f64;
        strips
            .draw_series(behaviour_spans(rs).into_iter().map(|(b, a, e)| {
                Rectangle::new(
                    [(a / 60.0, y0 + 0.12), (e / 60.0, y0 + 0.88)],
                    behaviour_colour(b).filled(),
                )
            }))
            .map_err(ReportError::figure)?;
        let name = if n > 1 {
            run.vehicles
                .get(v as usize)
                .map_or("behaviour".to_string(), |i| i.name.clone())
        } else {
            "behaviour".to_string()
        };
        strips
            .draw_series(std::iter::once(
                EmptyElement::at((0.0, y0 + 0.5))
                    + Text::new(
                        name,
                        (-6, 0),
                        label_style(11, BLACK, Pos::new(HPos::Right, VPos::Center)),
                    ),
            ))
            .map_err(ReportError::figure)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::super::mission_figure;
    use super::super::test_support::demo;
    use super::*;

    #[test]
    fn thinned_readings_keep_their_spikes() {
        let mut pts: Vec<(f64, f64)> = (0..10_000).map(|k| (f64::from(k) * 0.01, 0.1)).collect();
        pts[5_003].1 = 7.0;
        let thinned = min_max_columns(&pts, 100.0, 200);
        assert!(thinned.len() <= 400, "{}", thinned.len());
        assert!(thinned.iter().any(|p| p.1 == 7.0));
        assert!(
            thinned.windows(2).all(|w| w[0].0 <= w[1].0),
            "in time order"
        );
    }

    #[test]
    fn the_reading_panel_names_the_sensors_unit() {
        let mut run = demo(60.0);
        assert!(
            mission_figure(&run, "volts")
                .unwrap()
                .contains("reading (V)")
        );
        run.vehicles[0].reading_unit = "ppt";
        let svg = mission_figure(&run, "salinity").unwrap();
        assert!(svg.contains("reading (ppt)") && !svg.contains("reading (V)"));
    }
}
