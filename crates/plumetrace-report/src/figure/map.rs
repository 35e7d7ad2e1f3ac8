//! The map panel of the mission figure: the plume and source map, obstacles, op-area and
//! subregions; the tracks, navigation fixes, detections and time marks; the markers; the key
//! (mean flow and scale bar) and the legend in its corner.

use super::layout::MapLayout;
use super::legend::names;
use super::model::flow_words;
use super::style::{
    AVOID_MARK, DETECTION_MARK, FAULT_FILL, LEGEND_FONT_PX, LOST_MARK, OBSTACLE_FILL,
    OUTSIDE_TRACK, SOURCE_MARK, TIME_FONT_PX, TRUE_TRACK, behaviour_colour, icon_element,
    label_style, text_px,
};
use crate::chart::{MapChart, dashed, map_chart};
use crate::error::ReportError;
use crate::marks::{self, Group};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plumetrace_mission::MissionRun;

/// The map panel.
pub(super) fn draw_map<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    run: &MissionRun,
    lay: &MapLayout,
    title: &str,
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    let mut chart = map_chart(area, title, lay.x.clone(), lay.y.clone())?;
    draw_area(&mut chart, run, lay)?;
    draw_tracks(&mut chart, run, lay)?;
    draw_fixes(&mut chart, lay)?;
    draw_along_tracks(&mut chart, run, lay)?;
    draw_markers(&mut chart, run, lay)?;
    draw_key(&mut chart, run, lay)?;
    for e in lay.legend.iter().filter(|_| lay.legend_corner.is_some()) {
        let icon = e.icon;
        let label = e.label.clone();
        chart
            .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
            .map_err(ReportError::figure)?
            .label(e.label.clone())
            .legend(move |p| {
                EmptyElement::at(p)
                    + marks::open_text(Group::Legend, &label)
                    + icon_element!(icon, (0, 0), 0)
                    + marks::close_text()
            });
    }
    if let (Some(corner), false) = (lay.legend_corner, lay.legend.is_empty()) {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", LEGEND_FONT_PX))
            .position(corner.position())
            .draw()
            .map_err(ReportError::figure)?;
    }
    Ok(())
}

/// Draws what `draw` draws on the map as one marked group of `kind` named `name` (see
/// [`crate::marks`]).
fn marked<'a, DB: DrawingBackend>(
    chart: &mut MapChart<'a, DB>,
    kind: Group,
    name: &str,
    draw: impl FnOnce(&mut MapChart<'a, DB>) -> Result<(), ReportError>,
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    let at = (chart.x_range().start, chart.y_range().start);
    marks::open(chart.plotting_area(), at, kind, name).map_err(ReportError::figure)?;
    draw(chart)?;
    marks::close(chart.plotting_area(), at).map_err(ReportError::figure)
}

/// The map's background: the mean plume and source map, obstacles, the op-area and subregions.
fn draw_area<DB: DrawingBackend>(
    chart: &mut MapChart<'_, DB>,
    run: &MissionRun,
    lay: &MapLayout,
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    for (cells, name) in [
        (&lay.plume, names::PLUME),
        (&lay.source_map, names::SOURCE_MAP),
    ] {
        if cells.is_empty() {
            continue;
        }
        marked(chart, Group::Ramp, name, |chart| {
            chart
                .draw_series(cells.iter().map(|(r, c)| Rectangle::new(*r, c.filled())))
                .map(|_| ())
                .map_err(ReportError::figure)
        })?;
    }
    if !lay.obstacles.is_empty() {
        marked(chart, Group::Series, names::OBSTACLE, |chart| {
            chart
                .draw_series(
                    lay.obstacles
                        .iter()
                        .map(|o| Polygon::new(o.clone(), OBSTACLE_FILL.mix(0.55).filled())),
                )
                .map(|_| ())
                .map_err(ReportError::figure)
        })?;
    }
    if run.op_area.len() > 1 {
        marked(chart, Group::Series, names::OP_AREA, |chart| {
            chart
                .draw_series(dashed(&run.op_area, BLACK, 2))
                .map(|_| ())
                .map_err(ReportError::figure)
        })?;
    }
    for r in run.subregions.iter().filter(|r| r.len() > 1) {
        marked(chart, Group::Series, names::SUBREGION, |chart| {
            chart
                .draw_series(dashed(r, RGBColor(120, 120, 120), 1))
                .map(|_| ())
                .map_err(ReportError::figure)
        })?;
    }
    Ok(())
}

/// The tracks: flown during faults (under the rest), true, estimated, and true outside the
/// op-area.
fn draw_tracks<DB: DrawingBackend>(
    chart: &mut MapChart<'_, DB>,
    run: &MissionRun,
    lay: &MapLayout,
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    // Under the tracks: the track flown during faults.
    let faults: std::collections::BTreeSet<(u32, usize)> = lay
        .layers
        .iter()
        .flat_map(|l| l.faults.iter().map(|(k, _)| (l.vehicle, *k)))
        .collect();
    for l in &lay.layers {
        for (k, pts) in &l.faults {
            let Some(f) = run
                .vehicles
                .get(l.vehicle as usize)
                .and_then(|v| v.faults.get(*k))
            else {
                continue;
            };
            marked(
                chart,
                Group::Series,
                &names::fault(f, faults.len() == 1),
                |chart| {
                    chart
                        .draw_series(std::iter::once(PathElement::new(
                            pts.clone(),
                            FAULT_FILL.mix(0.5).stroke_width(10),
                        )))
                        .map(|_| ())
                        .map_err(ReportError::figure)
                },
            )?;
        }
    }
    let moves = |pts: &[(f64, f64)]| pts.iter().any(|p| *p != pts[0]);
    for l in &lay.layers {
        let own = l.runs.iter().any(|(_, p)| moves(p));
        let name = match names::truth_only(run, l.vehicle) {
            Some(only) if lay.multi && !own => only,
            _ => names::truth(lay.multi).to_string(),
        };
        marked(chart, Group::Series, &name, |chart| {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    l.truth.clone(),
                    TRUE_TRACK.stroke_width(1),
                )))
                .map(|_| ())
                .map_err(ReportError::figure)
        })?;
    }
    for l in &lay.layers {
        for (b, pts) in &l.runs {
            let c = match b {
                Some(b) if !lay.multi => behaviour_colour(*b),
                _ => l.colour,
            };
            let name = names::track(run, l.vehicle, *b, lay.multi);
            marked(chart, Group::Series, &name, |chart| {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        pts.clone(),
                        c.stroke_width(2),
                    )))
                    .map(|_| ())
                    .map_err(ReportError::figure)
            })?;
        }
    }
    for l in lay.layers.iter().filter(|l| !l.outside.is_empty()) {
        marked(chart, Group::Series, names::OUTSIDE, |chart| {
            chart
                .draw_series(
                    l.outside
                        .iter()
                        .map(|p| PathElement::new(p.clone(), OUTSIDE_TRACK.stroke_width(2))),
                )
                .map(|_| ())
                .map_err(ReportError::figure)
        })?;
    }
    Ok(())
}

/// The navigation fixes: dotted from the estimate before to the estimate after, long ones
/// labelled.
fn draw_fixes<DB: DrawingBackend>(
    chart: &mut MapChart<'_, DB>,
    lay: &MapLayout,
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    let m = lay.m_per_px;
    // Position fixes: dotted from the estimate before to the estimate after.
    for l in &lay.layers {
        if !l.jumps.is_empty() {
            marked(chart, Group::Series, names::FIX, |chart| {
                chart
                    .draw_series(l.jumps.iter().flat_map(|&([a, b], _)| {
                        let len = (b.0 - a.0).hypot(b.1 - a.1);
                        // Dotted as its legend swatch: dots of 3 px, gaps of 3 px.
                        let n = (len / (6.0 * m)).ceil().max(2.0) as usize;
                        (0..n).map(move |k| {
                            let s = k as f64 / n as f64;
                            let e = (s + 0.5 / n as f64).min(1.0);
                            PathElement::new(
                                vec![
                                    (a.0 + s * (b.0 - a.0), a.1 + s * (b.1 - a.1)),
                                    (a.0 + e * (b.0 - a.0), a.1 + e * (b.1 - a.1)),
                                ],
                                BLACK.stroke_width(1),
                            )
                        })
                    }))
                    .map(|_| ())
                    .map_err(ReportError::figure)
            })?;
        }
        // Jumps of 40 px or more say how far and when.
        chart
            .draw_series(
                l.jumps
                    .iter()
                    .filter(|([a, b], _)| (b.0 - a.0).hypot(b.1 - a.1) >= 40.0 * m)
                    .map(|&([a, b], t)| {
                        let text = format!(
                            "fix at {:.1} min: {:.0} m",
                            t / 60.0,
                            (b.0 - a.0).hypot(b.1 - a.1)
                        );
                        let w = (text_px(&text, 12.0) / 2.0).round() as i32 + 3;
                        EmptyElement::at((0.5 * (a.0 + b.0), 0.5 * (a.1 + b.1)))
                            + Rectangle::new([(-w, 4), (w, 20)], WHITE.mix(0.8).filled())
                            + Text::new(
                                text,
                                (0, 12),
                                label_style(12, BLACK, Pos::new(HPos::Center, VPos::Center)),
                            )
                    }),
            )
            .map_err(ReportError::figure)?;
    }
    Ok(())
}

/// Along the tracks: each vehicle's name at its start (several vehicles), detection ticks and
/// time marks.
fn draw_along_tracks<DB: DrawingBackend>(
    chart: &mut MapChart<'_, DB>,
    run: &MissionRun,
    lay: &MapLayout,
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    // Several vehicles: each track's start named.
    if lay.multi {
        for l in &lay.layers {
            let start = l
                .runs
                .first()
                .and_then(|(_, p)| p.first())
                .or(l.truth.first());
            if let (Some(v), Some(&p)) = (run.vehicles.get(l.vehicle as usize), start) {
                chart
                    .draw_series(std::iter::once(Text::new(
                        v.name.clone(),
                        p,
                        ("sans-serif", 12).into_font().color(&BLACK),
                    )))
                    .map_err(ReportError::figure)?;
            }
        }
    }
    for l in lay.layers.iter().filter(|l| !l.detections.is_empty()) {
        marked(chart, Group::Series, names::DETECTION, |chart| {
            chart
                .draw_series(
                    l.detections.iter().map(|s| {
                        PathElement::new(s.to_vec(), DETECTION_MARK.mix(0.6).stroke_width(1))
                    }),
                )
                .map(|_| ())
                .map_err(ReportError::figure)
        })?;
    }
    for l in &lay.layers {
        if !l.times.is_empty() {
            marked(
                chart,
                Group::Series,
                &names::times(lay.time_step_min),
                |chart| {
                    chart
                        .draw_series(
                            l.times
                                .iter()
                                .map(|t| PathElement::new(t.tick.to_vec(), BLACK.stroke_width(2))),
                        )
                        .map(|_| ())
                        .map_err(ReportError::figure)
                },
            )?;
        }
        // Leaders from ticks to labels placed away from them.
        chart
            .draw_series(
                l.times
                    .iter()
                    .filter(|t| !t.label.is_empty())
                    .filter_map(|t| t.leader)
                    .map(|s| PathElement::new(s.to_vec(), BLACK.stroke_width(1))),
            )
            .map_err(ReportError::figure)?;
        chart
            .draw_series(l.times.iter().filter(|t| !t.label.is_empty()).map(|t| {
                let w = (text_px(&t.label, TIME_FONT_PX) / 2.0).round() as i32 + 2;
                EmptyElement::at(t.label_at)
                    + Rectangle::new([(-w, -6), (w, 6)], WHITE.mix(0.75).filled())
                    + Text::new(
                        t.label.clone(),
                        (0, 0),
                        label_style(
                            TIME_FONT_PX as u32,
                            BLACK,
                            Pos::new(HPos::Center, VPos::Center),
                        ),
                    )
            }))
            .map_err(ReportError::figure)?;
    }
    Ok(())
}

/// The markers: obstacle avoidance's virtual paths and reference targets, lost points, true
/// and declared sources, aborts and incidents with their labels.
fn draw_markers<DB: DrawingBackend>(
    chart: &mut MapChart<'_, DB>,
    run: &MissionRun,
    lay: &MapLayout,
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    if !lay.virtual_paths.is_empty() {
        let segments: Vec<PathElement<(f64, f64)>> = lay
            .virtual_paths
            .iter()
            .flat_map(|(a, course, b)| {
                // Dashed as its legend swatch, at least two dashes: 2 m on and 2 m off, or
                // finer on a path shorter than 8 m.
                let len = (b - a).dot(&course.unit()).max(0.0);
                let n = if len > 0.0 {
                    (len / 4.0).ceil().max(2.0) as usize
                } else {
                    0
                };
                let period = len / n.max(1) as f64;
                (0..n).map(move |k| {
                    let p = a + course.unit() * (period * k as f64);
                    let q = a + course.unit() * (period * (k as f64 + 0.5));
                    PathElement::new(vec![(p.x, p.y), (q.x, q.y)], AVOID_MARK.stroke_width(1))
                })
            })
            .collect();
        marked(chart, Group::Series, names::VIRTUAL_PATH, |chart| {
            chart
                .draw_series(segments)
                .map(|_| ())
                .map_err(ReportError::figure)
        })?;
    }
    if !lay.targets.is_empty() {
        marked(chart, Group::Series, names::TARGET, |chart| {
            chart
                .draw_series(lay.targets.iter().map(|&(x, y)| {
                    Polygon::new(
                        vec![(x, y + 1.2), (x + 1.2, y), (x, y - 1.2), (x - 1.2, y)],
                        AVOID_MARK.filled(),
                    )
                }))
                .map(|_| ())
                .map_err(ReportError::figure)
        })?;
    }
    if !lay.lost.is_empty() {
        marked(chart, Group::Series, names::LOST, |chart| {
            chart
                .draw_series(
                    lay.lost
                        .iter()
                        .map(|&p| Circle::new(p, 5, LOST_MARK.stroke_width(2))),
                )
                .map(|_| ())
                .map_err(ReportError::figure)
        })?;
    }
    if !run.sources.is_empty() {
        marked(chart, Group::Series, names::SOURCE, |chart| {
            chart
                .draw_series(
                    run.sources
                        .iter()
                        .map(|s| TriangleMarker::new((s.x, s.y), 9, SOURCE_MARK.filled())),
                )
                .map(|_| ())
                .map_err(ReportError::figure)
        })?;
    }
    if !lay.declared.is_empty() {
        marked(chart, Group::Series, names::DECLARED, |chart| {
            chart
                .draw_series(
                    lay.declared
                        .iter()
                        .map(|&p| Circle::new(p, 7, BLACK.filled())),
                )
                .map(|_| ())
                .map_err(ReportError::figure)
        })?;
    }
    for k in &lay.marks {
        let icon = k.kind.icon();
        let text = k.kind.text(k.t_s);
        let (ox, oy) = k.label_px;
        let w = text_px(&text, 12.0).round() as i32;
        let style = label_style(12, BLACK, Pos::new(HPos::Left, VPos::Center));
        marked(chart, Group::Series, k.kind.legend(), |chart| {
            chart
                .draw_series(std::iter::once(
                    icon_element!(icon, k.pos, -8)
                        + Rectangle::new(
                            [(ox - 2, oy), (ox + w + 2, oy + 16)],
                            WHITE.mix(0.8).filled(),
                        )
                        + Text::new(text, (ox, oy + 8), style),
                ))
                .map(|_| ())
                .map_err(ReportError::figure)
        })?;
    }
    Ok(())
}

/// The key: the mean flow at the source as an arrow with its speed and direction, and a scale
/// bar, in a box in `lay.key_corner`.
fn draw_key<DB: DrawingBackend>(
    chart: &mut MapChart<'_, DB>,
    run: &MissionRun,
    lay: &MapLayout,
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    let m = lay.m_per_px;
    let (w, h) = (lay.key_px.0 as i32, lay.key_px.1 as i32);
    let (pw, ph) = (f64::from(lay.plot_px.0), f64::from(lay.plot_px.1));
    // The box's upper left corner, px from the plotting area's upper left, 5 px from its edges
    // (as plotters places the legend).
    let left = if lay.key_corner.right() {
        pw - f64::from(w) - 5.0
    } else {
        5.0
    };
    let top = if lay.key_corner.upper() {
        5.0
    } else {
        ph - f64::from(h) - 5.0
    };
    let at = (lay.x.start + left * m, lay.y.end - top * m);
    let style = |h: HPos| label_style(12, BLACK, Pos::new(h, VPos::Center));
    chart
        .draw_series(std::iter::once(
            EmptyElement::at(at)
                + Rectangle::new([(0, 0), (w, h)], WHITE.mix(0.9).filled())
                + Rectangle::new([(0, 0), (w, h)], BLACK.stroke_width(1)),
        ))
        .map_err(ReportError::figure)?;
    let (flow_text, dir) = flow_words(run.mean_flow_mps);
    if let Some(u) = dir {
        let (ux, uy) = (u.x, -u.y);
        let (cx, cy) = (22.0, 20.0);
        let px = |f: f64| {
            (
                (cx + f * ux * 14.0).round() as i32,
                (cy + f * uy * 14.0).round() as i32,
            )
        };
        let tip = px(1.0);
        // The head: two strokes 7 px back from the tip, 30 degrees either side of the shaft.
        let head = |side: f64| {
            let (ca, sa) = (30f64.to_radians().cos(), side * 30f64.to_radians().sin());
            let (bx, by) = (-(ux * ca - uy * sa), -(ux * sa + uy * ca));
            (
                (f64::from(tip.0) + 7.0 * bx).round() as i32,
                (f64::from(tip.1) + 7.0 * by).round() as i32,
            )
        };
        chart
            .draw_series(std::iter::once(
                EmptyElement::at(at)
                    + PathElement::new(vec![px(-1.0), tip], BLACK.stroke_width(2))
                    + PathElement::new(vec![head(1.0), tip, head(-1.0)], BLACK.stroke_width(2)),
            ))
            .map_err(ReportError::figure)?;
    }
    let bar = (lay.scale_m / m).round() as i32;
    let (bx, by) = (12, 44);
    chart
        .draw_series(std::iter::once(
            EmptyElement::at(at)
                + Text::new(flow_text, (44, 20), style(HPos::Left))
                + PathElement::new(vec![(bx, by), (bx + bar, by)], BLACK.stroke_width(3))
                + PathElement::new(vec![(bx, by - 5), (bx, by + 5)], BLACK.stroke_width(1))
                + PathElement::new(
                    vec![(bx + bar, by - 5), (bx + bar, by + 5)],
                    BLACK.stroke_width(1),
                )
                + Text::new(
                    format!("{:.0} m", lay.scale_m),
                    (bx + bar + 6, by),
                    style(HPos::Left),
                ),
        ))
        .map_err(ReportError::figure)?;
    Ok(())
}
