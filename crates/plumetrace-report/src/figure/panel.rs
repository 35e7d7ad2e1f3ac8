//! The reading panel of the mission figure: for the vehicles with a planner, the chemical
//! reading against mission time (thinned so that spikes survive), fault windows shaded, the
//! source map's entropy, lines at declarations, aborts and incidents, and the behaviour in
//! control as a strip under it.

use super::layout::MapLayout;
use super::model::{MarkKind, behaviour_spans};
use super::style::{
    ABORT_MARK, ENTROPY_LINE, FAULT_FILL, READING_LINE, READING_PX, STRIP_PX, TRACK_COLOURS,
    behaviour_colour, label_style, text_px,
};
use crate::error::ReportError;
use crate::marks::{self, Group};
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

/// A tick label with as many decimals as it needs (up to 2): `0.5`, `1`, `2.25`.
pub(crate) fn tick_label(v: f64) -> String {
    let s = format!("{v:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// The reading axis' range for readings `values`: from 0 to a little over the largest, or, for
/// readings that stay far from 0 (a salinity probe's 35 ppt), a little around their own range.
pub(super) fn reading_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() || hi <= 0.0 {
        return (0.0, 1.0);
    }
    if lo < 0.3 * hi {
        return (0.0, 1.08 * hi);
    }
    let pad = ((hi - lo) * 0.08).max(hi.abs() * 1e-3).max(1e-6);
    (lo - pad, hi + pad)
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
    /// The plotting area's width, px.
    plot_w_px: f64,
    /// The reading axis' bottom and top.
    y_lo: f64,
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
    let (y_lo, y_hi) = reading_range(
        vehicles
            .iter()
            .filter_map(|v| rows.get(v))
            .flatten()
            .map(|r| r.reading_v),
    );
    let mut chart = ChartBuilder::on(&upper)
        .margin(12)
        .margin_right(25)
        .margin_bottom(0)
        .x_label_area_size(0)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t_max_min, y_lo..y_hi)
        .map_err(ReportError::figure)?;
    let span = y_hi - y_lo;
    let digits = if span >= 10.0 {
        0
    } else if span >= 1.0 {
        1
    } else if span >= 0.1 {
        2
    } else {
        3
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
        plot_w_px: f64::from(upper.dim_in_pixel().0.saturating_sub(97)),
        y_lo,
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
        y_lo,
        y_hi,
        ..
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
                Rectangle::new([(a, y_lo), (b, y_hi)], FAULT_FILL.mix(0.35).filled())
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
        let colour = reading_colour(lay, v, k);
        // With several vehicles each line is a series its strip's name keys.
        let name = run.vehicles.get(v as usize).filter(|_| lay.multi);
        let at = (0.0, y_lo);
        if let Some(i) = name {
            marks::open(chart.plotting_area(), at, Group::Series, &i.name)
                .map_err(ReportError::figure)?;
        }
        chart
            .draw_series(std::iter::once(PathElement::new(
                min_max_columns(&pts, t_max_min, cols),
                colour.stroke_width(1),
            )))
            .map_err(ReportError::figure)?;
        if name.is_some() {
            marks::close(chart.plotting_area(), at).map_err(ReportError::figure)?;
        }
    }
    Ok(())
}

/// The entropy line's top, as a share of the panel's height: its label sits above it.
const ENTROPY_TOP: f64 = 0.8;

/// The source map's entropy (a planner that keeps a map reports it), scaled to the panel's
/// height: 0 at the bottom, the largest reported value at [`ENTROPY_TOP`] with its label above.
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
        y_lo,
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
        // Bits to the reading axis: 0 at the foot, `h_max` at ENTROPY_TOP of the height.
        let to_y = |h: f64| y_lo + h / h_max * (y_hi - y_lo) * ENTROPY_TOP;
        let scaled: Vec<(f64, f64)> = entropy.iter().map(|&(t, h)| (t, to_y(h))).collect();
        chart
            .draw_series(std::iter::once(PathElement::new(
                scaled,
                ENTROPY_LINE.stroke_width(2),
            )))
            .map_err(ReportError::figure)?;
        chart
            .draw_series(std::iter::once(Text::new(
                "source map entropy (bits: the scale at the right)",
                (t_max_min * 0.01, y_hi),
                ("sans-serif", 12).into_font().color(&ENTROPY_LINE),
            )))
            .map_err(ReportError::figure)?;
        // Its own scale: ticks on the panel's right edge, labelled in the margin beside it.
        let tick = t_max_min * 5.0 / p.plot_w_px.max(1.0);
        let ticks = entropy_ticks(h_max);
        let top = ticks.last().map_or(y_lo, |&h| to_y(h));
        chart
            .draw_series(std::iter::once(
                EmptyElement::at((t_max_min, top))
                    + Text::new(
                        "bits",
                        (3, -14),
                        label_style(11, ENTROPY_LINE, Pos::new(HPos::Left, VPos::Center)),
                    ),
            ))
            .map_err(ReportError::figure)?;
        for h in ticks {
            let y = to_y(h);
            chart
                .draw_series([PathElement::new(
                    vec![(t_max_min - tick, y), (t_max_min, y)],
                    ENTROPY_LINE.stroke_width(2),
                )])
                .map_err(ReportError::figure)?;
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at((t_max_min, y))
                        + Text::new(
                            tick_label(h),
                            (3, 0),
                            label_style(11, ENTROPY_LINE, Pos::new(HPos::Left, VPos::Center)),
                        ),
                ))
                .map_err(ReportError::figure)?;
        }
    }
    Ok(())
}

/// The entropy scale's ticks: 0 and every multiple of a round step up to `h_max`, at most five.
fn entropy_ticks(h_max: f64) -> Vec<f64> {
    let step = [0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0]
        .into_iter()
        .find(|s| h_max / s <= 4.0)
        .unwrap_or(h_max.max(1.0));
    (0..)
        .map(|k| f64::from(k) * step)
        .take_while(|h| *h <= h_max * (1.0 + 1e-9))
        .take(5)
        .collect()
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
        y_lo,
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
    // One line for the same event at the same time (several vehicles declaring together).
    lines.sort_by(|a, b| a.0.total_cmp(&b.0));
    let same = t_max_min * 0.005;
    lines.dedup_by(|b, a| a.1 == b.1 && (b.0 - a.0).abs() < same);
    let min_per_px = t_max_min / p.plot_w_px.max(1.0);
    // Labels taken, per row from the top: their extents, min.
    let mut taken: Vec<Vec<(f64, f64)>> = Vec::new();
    for (t, label, c, dash) in &lines {
        let segs: Vec<PathElement<(f64, f64)>> = if *dash {
            let d = (y_hi - y_lo) / 24.0;
            (0..24)
                .step_by(2)
                .map(|i| {
                    PathElement::new(
                        vec![
                            (*t, y_lo + f64::from(i) * d),
                            (*t, y_lo + f64::from(i + 1) * d),
                        ],
                        c.stroke_width(2),
                    )
                })
                .collect()
        } else {
            vec![PathElement::new(
                vec![(*t, y_lo), (*t, y_hi)],
                c.stroke_width(1),
            )]
        };
        chart.draw_series(segs).map_err(ReportError::figure)?;
        let w = (text_px(label, 11.0) + 6.0) * min_per_px;
        let (dx, h, span) = if *t < 0.8 * t_max_min {
            (4, HPos::Left, (*t, *t + w))
        } else {
            (-4, HPos::Right, (*t - w, *t))
        };
        // The first row where the label meets no other.
        let row = (0..)
            .find(|&r| {
                taken.get(r).is_none_or(|row: &Vec<(f64, f64)>| {
                    row.iter().all(|&(a, b)| span.1 <= a || b <= span.0)
                })
            })
            .unwrap_or(0);
        if taken.len() <= row {
            taken.resize(row + 1, Vec::new());
        }
        taken[row].push(span);
        chart
            .draw_series(std::iter::once(
                EmptyElement::at((*t, y_hi))
                    + Text::new(
                        label.clone(),
                        (dx, 3 + 13 * row as i32),
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
        lay,
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
        .x_label_formatter(&|v| tick_label(*v))
        .x_desc("mission time (min)")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(ReportError::figure)?;
    for (k, &v) in vehicles.iter().enumerate() {
        let Some(rs) = rows.get(&v) else { continue };
        let y0 = (n - 1 - k) as f64;
        let spans = behaviour_spans(rs);
        strips
            .draw_series(spans.iter().map(|&(b, a, e)| {
                Rectangle::new(
                    [(a / 60.0, y0 + 0.12), (e / 60.0, y0 + 0.88)],
                    behaviour_colour(b).filled(),
                )
            }))
            .map_err(ReportError::figure)?;
        if spans.is_empty() {
            // A planner that reports no behaviour: said so, not an empty strip.
            strips
                .draw_series(std::iter::once(Rectangle::new(
                    [(0.0, y0 + 0.12), (t_max_min, y0 + 0.88)],
                    RGBColor(235, 235, 235).filled(),
                )))
                .map_err(ReportError::figure)?;
            strips
                .draw_series(std::iter::once(
                    EmptyElement::at((t_max_min / 2.0, y0 + 0.5))
                        + Text::new(
                            "no behaviour reported".to_string(),
                            (0, 0),
                            label_style(
                                11,
                                RGBColor(90, 90, 90),
                                Pos::new(HPos::Center, VPos::Center),
                            ),
                        ),
                ))
                .map_err(ReportError::figure)?;
        }
        let name = if n > 1 {
            run.vehicles
                .get(v as usize)
                .map_or("behaviour".to_string(), |i| i.name.clone())
        } else {
            "behaviour".to_string()
        };
        // With several vehicles the name is their reading line's key: a swatch of the line.
        let (name_dx, swatch) = if lay.multi {
            (-24, Some(reading_colour(lay, v, k)))
        } else {
            (-6, None)
        };
        let text = Text::new(
            name.clone(),
            (name_dx, 0),
            label_style(11, BLACK, Pos::new(HPos::Right, VPos::Center)),
        );
        let at = EmptyElement::at((0.0, y0 + 0.5));
        let drawn = match swatch {
            // The swatch is the reading line: its colour and width.
            Some(c) => strips.draw_series(std::iter::once(
                at + marks::open_text(Group::Legend, &name)
                    + PathElement::new(vec![(-20, 0), (-6, 0)], c.stroke_width(1))
                    + text
                    + marks::close_text(),
            )),
            None => strips.draw_series(std::iter::once(at + text)),
        };
        drawn.map_err(ReportError::figure)?;
    }
    Ok(())
}

/// The colour of vehicle `v`'s reading line (`k`: its place in the panel).
fn reading_colour(lay: &MapLayout, v: u32, k: usize) -> RGBColor {
    if lay.multi {
        lay.layers
            .iter()
            .find(|l| l.vehicle == v)
            .map_or(TRACK_COLOURS[k % TRACK_COLOURS.len()], |l| l.colour)
    } else {
        READING_LINE
    }
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

    use crate::inspect::{bad_tick_rows, overlapping_texts, text_boxes};
    use plumetrace_mission::DeclarationRecord;

    #[test]
    fn tick_labels_have_the_decimals_they_need() {
        let labels: Vec<String> = [0.0, 0.5, 1.0, 1.5, 2.25, -0.0].map(tick_label).to_vec();
        assert_eq!(labels, ["0", "0.5", "1", "1.5", "2.25", "0"]);
    }

    #[test]
    fn a_short_missions_time_axis_reads_distinct_increasing_minutes() {
        // 150 s: half-minute ticks, which whole minutes would read 0, 0, 1, 1, 2, 2.
        let svg = mission_figure(&demo(150.0), "short").unwrap();
        assert!(bad_tick_rows(&svg).is_empty(), "{:?}", bad_tick_rows(&svg));
        assert!(svg.contains(">\n0.5\n<"), "a half-minute tick");
    }

    #[test]
    fn readings_far_from_zero_get_an_axis_around_them() {
        let (lo, hi) = reading_range([35.0, 34.9, 31.2].into_iter());
        assert!(
            lo > 30.0 && lo < 31.2 && hi > 35.0 && hi < 36.0,
            "{lo} {hi}"
        );
        assert_eq!(reading_range([0.0, 2.0].into_iter()), (0.0, 2.16));
        assert_eq!(reading_range(std::iter::empty()), (0.0, 1.0));
        assert_eq!(reading_range([f64::NAN].into_iter()), (0.0, 1.0));
        // A salinity probe's readings: the axis no longer starts at 0.
        let mut run = demo(120.0);
        run.vehicles[0].reading_unit = "ppt";
        for r in &mut run.trajectory {
            r.reading_v = 35.0 - r.reading_v.min(4.0);
        }
        let svg = mission_figure(&run, "salinity").unwrap();
        let ticks = crate::inspect::tick_rows(&svg);
        assert!(
            ticks.iter().any(|r| r
                .iter()
                .all(|v| v.parse::<f64>().is_ok_and(|v| (28.0..37.0).contains(&v)))),
            "{ticks:?}"
        );
    }

    /// A declaration by vehicle `v` at `t_s`.
    fn declaration(t_s: f64, v: u32) -> DeclarationRecord {
        DeclarationRecord {
            t_s,
            vehicle: v,
            x_m: 0.0,
            y_m: 0.0,
            source_x_m: 0.0,
            source_y_m: 0.0,
            error_m: 1.0,
            error_along_m: 1.0,
            error_cross_m: 0.0,
            rule: plumetrace_core::DeclarationKind::new("test"),
        }
    }

    #[test]
    fn declarations_together_are_labelled_once_and_near_ones_apart() {
        let mut run = demo(120.0);
        run.summary.declarations = vec![
            declaration(60.0, 0),
            declaration(60.0, 0),
            declaration(62.0, 0),
        ];
        let svg = mission_figure(&run, "two declarations").unwrap();
        assert!(
            overlapping_texts(&svg).is_empty(),
            "{:?}",
            overlapping_texts(&svg)
        );
        let labels: Vec<_> = text_boxes(&svg)
            .into_iter()
            .filter(|t| t.text == "declared")
            .collect();
        assert_eq!(labels.len(), 2, "{labels:?}");
    }

    #[test]
    fn the_entropy_label_sits_above_its_line() {
        let mut run = demo(120.0);
        for (t, h) in [(10.0, 11.0), (60.0, 9.0), (110.0, 7.0)] {
            run.events.push(plumetrace_mission::EventRecord {
                t_s: t,
                vehicle: 0,
                event: EventKind::Telemetry(plumetrace_core::Telemetry::SourceMap {
                    entropy_bits: h,
                    peak_m: plumetrace_core::Vec2::new(0.0, 0.0),
                    mass: 0.1,
                }),
            });
        }
        let svg = mission_figure(&run, "entropy").unwrap();
        let label = text_boxes(&svg)
            .into_iter()
            .find(|t| t.text.starts_with("source map entropy"))
            .unwrap();
        // The entropy line: its highest point (smallest y) is below the label's box.
        let line = svg
            .split("<polyline")
            .find(|p| p.contains("stroke=\"#28783C\"") && p.contains("stroke-width=\"2\""))
            .unwrap();
        let pts = line.split("points=\"").nth(1).unwrap();
        let top = pts
            .split_whitespace()
            .filter_map(|p| p.split_once(','))
            .filter_map(|(_, y)| y.trim_end_matches('"').parse::<f64>().ok())
            .fold(f64::MAX, f64::min);
        assert!(
            top > label.rect.3,
            "line top {top}, label bottom {}",
            label.rect.3
        );
        // Its scale at the right: 0, 5 and 10 bits, beside the panel, the highest nearest the
        // top; no text meets another.
        let ticks: Vec<_> = text_boxes(&svg)
            .into_iter()
            .filter(|t| ["0", "5", "10"].contains(&t.text.as_str()) && t.rect.0 > 850.0)
            .collect();
        assert_eq!(ticks.len(), 3, "{ticks:?}");
        let unit = text_boxes(&svg)
            .into_iter()
            .find(|t| t.text == "bits" && t.rect.0 > 850.0)
            .unwrap();
        assert!(
            unit.rect.3 <= ticks[2].rect.1,
            "{unit:?} above {:?}",
            ticks[2]
        );
        assert!(
            ticks[2].rect.1 < ticks[1].rect.1 && ticks[1].rect.1 < ticks[0].rect.1,
            "{ticks:?}"
        );
        assert!(
            overlapping_texts(&svg).is_empty(),
            "{:?}",
            overlapping_texts(&svg)
        );
    }

    #[test]
    fn the_entropy_scale_has_round_ticks_up_to_the_largest_value() {
        assert_eq!(entropy_ticks(11.3), vec![0.0, 5.0, 10.0]);
        assert_eq!(entropy_ticks(4.0), vec![0.0, 1.0, 2.0, 3.0, 4.0]);
        assert_eq!(entropy_ticks(1.2), vec![0.0, 0.5, 1.0]);
        assert_eq!(entropy_ticks(0.3), vec![0.0]);
        assert_eq!(entropy_ticks(16.6), vec![0.0, 5.0, 10.0, 15.0]);
    }

    #[test]
    fn a_vehicle_with_no_behaviour_says_so_in_its_strip() {
        let mut run = demo(60.0);
        for r in &mut run.trajectory {
            r.behaviour = None;
        }
        let svg = mission_figure(&run, "none").unwrap();
        assert!(svg.contains("no behaviour reported"));
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
