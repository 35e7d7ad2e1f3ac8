//! The mission figure, drawn from the recorded run (like the field-test figures): op-area and
//! subregions dashed, obstacles (kelp) as filled green patches, each vehicle's estimated track as
//! it logged it coloured by the behaviour in control (a vehicle without a planner in a colour of
//! its own; the true tracks thin and grey; with several vehicles each track's start is labelled
//! with the vehicle's name), detections as x, lost points as open circles, obstacle avoidance's
//! virtual paths dotted with their reference targets as diamonds, declared sources as filled
//! dots, true sources as triangles, and the time-averaged plume at the first vehicle's altitude as
//! a light heat map. The legend lists only what is drawn.

use crate::mission::MissionRun;
use crate::record::{EventKind, MeanPlumeRecorder};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plumetrace_core::{BehaviourKind, Heading, PlannerEvent, Vec2};

fn err<E: std::fmt::Debug>(e: E) -> String {
    format!("drawing the figure: {e:?}")
}

/// A map panel: `title` above, East/North axes in metres over `x` and `y`, no grid lines. Shared
/// by every figure so that maps look the same.
pub fn map_chart<'a, DB: DrawingBackend + 'a>(
    area: &'a DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String>
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
        .map_err(err)?;
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
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(err)?;
    Ok(chart)
}

/// A closed polygon drawn dashed (dash length scaled to the edge, gaps 3/4 of a dash).
pub fn dashed(points: &[Vec2], colour: RGBColor, width: u32) -> Vec<PathElement<(f64, f64)>> {
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
            out.push(PathElement::new(
                vec![(p.x, p.y), (q.x, q.y)],
                colour.stroke_width(width),
            ));
            s += 1.75 * dash;
        }
    }
    out
}

/// The corner of the map panel where a legend of `px` pixels hides the fewest of `points` (data
/// coordinates over `x` x `y` drawn on a panel of `panel_px`), lower right on ties.
fn legend_corner(
    points: &[(f64, f64)],
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    panel_px: (f64, f64),
    px: (f64, f64),
) -> SeriesLabelPosition {
    let fx = (px.0 / panel_px.0).min(1.0) * (x.end - x.start);
    let fy = (px.1 / panel_px.1).min(1.0) * (y.end - y.start);
    let corners = [
        (
            SeriesLabelPosition::LowerRight,
            x.end - fx..x.end,
            y.start..y.start + fy,
        ),
        (
            SeriesLabelPosition::UpperRight,
            x.end - fx..x.end,
            y.end - fy..y.end,
        ),
        (
            SeriesLabelPosition::LowerLeft,
            x.start..x.start + fx,
            y.start..y.start + fy,
        ),
        (
            SeriesLabelPosition::UpperLeft,
            x.start..x.start + fx,
            y.end - fy..y.end,
        ),
    ];
    let mut best = (SeriesLabelPosition::LowerRight, usize::MAX);
    for (pos, cx, cy) in corners {
        let n = points
            .iter()
            .filter(|(px, py)| cx.contains(px) && cy.contains(py))
            .count();
        if n < best.1 {
            best = (pos, n);
        }
    }
    best.0
}

/// A stretch of a track flown under one behaviour (`None`: no planner), as plot points.
type BehaviourRun = (Option<BehaviourKind>, Vec<(f64, f64)>);

/// The colour of a track while `b` is in control.
pub(crate) fn behaviour_colour(b: BehaviourKind) -> RGBColor {
    match b {
        BehaviourKind::GoTo => RGBColor(0, 150, 60),
        BehaviourKind::Transit => RGBColor(90, 90, 90),
        BehaviourKind::Find => RGBColor(31, 100, 190),
        BehaviourKind::TrackIn => RGBColor(215, 30, 30),
        BehaviourKind::TrackOut => RGBColor(250, 140, 0),
        BehaviourKind::Reacquire => RGBColor(140, 80, 190),
        BehaviourKind::Survey => RGBColor(0, 160, 180),
        BehaviourKind::Mapping => RGBColor(140, 86, 75),
        BehaviourKind::Avoid => RGBColor(230, 60, 190),
        BehaviourKind::Done => RGBColor(0, 0, 0),
    }
}

/// How a behaviour reads in the legend.
pub(crate) fn behaviour_label(b: BehaviourKind) -> &'static str {
    match b {
        BehaviourKind::GoTo => "go to",
        BehaviourKind::Transit => "transit",
        BehaviourKind::Find => "find plume",
        BehaviourKind::TrackIn => "track in",
        BehaviourKind::TrackOut => "track out",
        BehaviourKind::Reacquire => "reacquire",
        BehaviourKind::Survey => "survey",
        BehaviourKind::Mapping => "mapping",
        BehaviourKind::Avoid => "avoid obstacle",
        BehaviourKind::Done => "done",
    }
}

/// Kelp.
const OBSTACLE_FILL: RGBColor = RGBColor(90, 160, 90);
/// Virtual paths and reference targets.
const AVOID_MARK: RGBColor = RGBColor(170, 0, 140);

/// Track colours, one per vehicle (cycled).
const TRACK_COLOURS: [RGBColor; 6] = [
    RGBColor(20, 60, 160),
    RGBColor(150, 40, 150),
    RGBColor(0, 120, 120),
    RGBColor(160, 90, 0),
    RGBColor(90, 90, 200),
    RGBColor(120, 40, 40),
];

/// The figure as an SVG string.
pub fn mission_figure(run: &MissionRun, title: &str) -> Result<String, String> {
    let g = match &run.mean_plume {
        Some(m) => *m.spec(),
        None => {
            let all: Vec<Vec2> = run.op_area.clone();
            let wide = plumetrace_env::Rect::new(-1e12, 1e12, -1e12, 1e12).map_err(err)?;
            MeanPlumeRecorder::grid_over(&all, wide, 0.0)
        }
    };
    let (x0, x1, y0, y1) = (g.x_min_m, g.x_max_m, g.y_min_m, g.y_max_m);
    let width = 900u32;
    let plot_w = f64::from(width - 90);
    let height = ((plot_w * (y1 - y0) / (x1 - x0)).clamp(300.0, 1400.0) + 120.0) as u32;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = map_chart(&root, title, x0..x1, y0..y1)?;

        // Plume: square-root scale of the time-averaged concentration, light.
        if let Some(mp) = &run.mean_plume {
            let mean = mp.mean();
            let max = mean.iter().copied().fold(0.0, f64::max);
            let (dx, dy) = ((x1 - x0) / (g.nx - 1) as f64, (y1 - y0) / (g.ny - 1) as f64);
            let mut cells = Vec::new();
            for j in 0..g.ny {
                for i in 0..g.nx {
                    let c = if max > 0.0 {
                        mean[j * g.nx + i] / max
                    } else {
                        0.0
                    };
                    if c > 1e-3 {
                        let l = c.sqrt();
                        let col =
                            RGBColor(255, (246.0 - 120.0 * l) as u8, (236.0 - 190.0 * l) as u8);
                        let (x, y) = (x0 + i as f64 * dx, y0 + j as f64 * dy);
                        cells.push(Rectangle::new(
                            [(x - dx / 2.0, y - dy / 2.0), (x + dx / 2.0, y + dy / 2.0)],
                            col.filled(),
                        ));
                    }
                }
            }
            if !cells.is_empty() {
                chart
                    .draw_series(cells)
                    .map_err(err)?
                    .label("mean plume at vehicle altitude")
                    .legend(|(x, y)| {
                        Rectangle::new(
                            [(x, y - 5), (x + 14, y + 5)],
                            RGBColor(255, 170, 100).filled(),
                        )
                    });
            }
        }
        chart
            .draw_series(dashed(&run.op_area, BLACK, 2))
            .map_err(err)?
            .label("op-area")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 6, y)], BLACK.stroke_width(2)));
        for r in &run.subregions {
            chart
                .draw_series(dashed(r, RGBColor(120, 120, 120), 1))
                .map_err(err)?;
        }
        if !run.obstacles.is_empty() {
            chart
                .draw_series(run.obstacles.iter().map(|o| {
                    Polygon::new(
                        o.iter().map(|v| (v.x, v.y)).collect::<Vec<_>>(),
                        OBSTACLE_FILL.mix(0.55).filled(),
                    )
                }))
                .map_err(err)?
                .label("obstacle (kelp)")
                .legend(|(x, y)| {
                    Rectangle::new(
                        [(x, y - 5), (x + 14, y + 5)],
                        OBSTACLE_FILL.mix(0.55).filled(),
                    )
                });
        }

        let vehicles: Vec<u32> = {
            let mut v: Vec<u32> = run.trajectory.iter().map(|r| r.vehicle).collect();
            v.sort_unstable();
            v.dedup();
            v
        };
        let grey = RGBColor(150, 150, 150);
        let mut hits: Vec<(f64, f64)> = Vec::new();
        let mut behaviours_drawn = std::collections::BTreeSet::new();
        let mut track_labels: Vec<(String, RGBColor)> = Vec::new();
        for (n, &vid) in vehicles.iter().enumerate() {
            let rows: Vec<_> = run.trajectory.iter().filter(|r| r.vehicle == vid).collect();
            let step = (rows.len() / 20_000).max(1);
            let truth: Vec<(f64, f64)> = rows
                .iter()
                .step_by(step)
                .map(|r| (r.true_x_m, r.true_y_m))
                .collect();
            // Runs of the estimated track under one behaviour (None: no planner); each run
            // ends on the next one's first point so that the track stays joined.
            let mut runs: Vec<BehaviourRun> = Vec::new();
            for r in rows.iter().step_by(step) {
                let Some(p) = r.est_x_m.zip(r.est_y_m) else {
                    continue;
                };
                match runs.last_mut() {
                    Some((b, pts)) if *b == r.behaviour => pts.push(p),
                    last => {
                        if let Some((_, pts)) = last {
                            pts.push(p);
                        }
                        runs.push((r.behaviour, vec![p]));
                    }
                }
            }
            let true_track = chart
                .draw_series(std::iter::once(PathElement::new(
                    truth,
                    grey.stroke_width(1),
                )))
                .map_err(err)?;
            if n == 0 {
                true_track
                    .label(if vehicles.len() > 1 {
                        "true tracks"
                    } else {
                        "true track"
                    })
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 16, y)], grey.stroke_width(1))
                    });
            }
            let colour = TRACK_COLOURS[n % TRACK_COLOURS.len()];
            let info = run.vehicles.get(vid as usize);
            // One vehicle: its track coloured by behaviour. Several: one colour each, named in
            // the legend (and at each track's start), so the vehicles can be told apart.
            let multi = vehicles.len() > 1;
            for (b, pts) in runs.iter() {
                let c = match b {
                    Some(b) if !multi => behaviour_colour(*b),
                    _ => colour,
                };
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        pts.clone(),
                        c.stroke_width(2),
                    )))
                    .map_err(err)?;
                match (b, info) {
                    (Some(b), _) if !multi => {
                        behaviours_drawn.insert(*b);
                    }
                    (_, Some(v)) if multi => track_labels.push((
                        format!(
                            "{} ({}) estimated track",
                            v.name,
                            v.planner.map_or("no planner", |k| k.name())
                        ),
                        colour,
                    )),
                    _ => track_labels.push(("track (navigation estimate)".to_string(), colour)),
                }
            }
            if vehicles.len() > 1
                && let (Some(v), Some((_, pts))) = (info, runs.first())
            {
                let (x, y) = pts[0];
                chart
                    .draw_series(std::iter::once(Text::new(
                        v.name.clone(),
                        (x, y),
                        ("sans-serif", 12).into_font().color(&BLACK),
                    )))
                    .map_err(err)?;
            }
            hits.extend(
                rows.iter()
                    .filter(|r| r.detection)
                    .filter_map(|r| r.est_x_m.zip(r.est_y_m)),
            );
        }
        track_labels.dedup_by(|a, b| a.0 == b.0);
        let n_track_labels = track_labels.len();
        for (label, c) in track_labels {
            chart
                .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
                .map_err(err)?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(2))
                });
        }
        for b in BehaviourKind::ALL
            .into_iter()
            .filter(|b| behaviours_drawn.contains(b))
        {
            let c = behaviour_colour(b);
            chart
                .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
                .map_err(err)?
                .label(format!("track: {}", behaviour_label(b)))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(2))
                });
        }
        // Obstacle avoidance: each virtual path from where the obstacle was sensed to its last
        // reference target, and the targets.
        let mut paths: Vec<(Vec2, Heading, Vec2)> = Vec::new();
        let mut targets: Vec<(f64, f64)> = Vec::new();
        for e in &run.events {
            match &e.event {
                EventKind::Planner(PlannerEvent::AvoidStart { pos_m, course_deg }) => {
                    paths.push((*pos_m, Heading::from_deg(*course_deg), *pos_m));
                }
                EventKind::Planner(PlannerEvent::ReferenceTarget { pos_m }) => {
                    targets.push((pos_m.x, pos_m.y));
                    if let Some((_, _, end)) = paths.last_mut() {
                        *end = *pos_m;
                    }
                }
                _ => {}
            }
        }
        if !paths.is_empty() {
            let segments: Vec<PathElement<(f64, f64)>> = paths
                .iter()
                .flat_map(|(a, course, b)| {
                    let len = (b - a).dot(&course.unit()).max(0.0);
                    let n = (len / 2.0).ceil() as usize;
                    (0..n).step_by(2).map(move |k| {
                        let p = a + course.unit() * (2.0 * k as f64);
                        let q = a + course.unit() * (2.0 * (k + 1) as f64).min(len);
                        PathElement::new(vec![(p.x, p.y), (q.x, q.y)], AVOID_MARK.stroke_width(1))
                    })
                })
                .collect();
            chart
                .draw_series(segments)
                .map_err(err)?
                .label("virtual path")
                .legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 5, y)], AVOID_MARK.stroke_width(1))
                });
        }
        if !targets.is_empty() {
            chart
                .draw_series(targets.iter().map(|&(x, y)| {
                    Polygon::new(
                        vec![(x, y + 1.2), (x + 1.2, y), (x, y - 1.2), (x - 1.2, y)],
                        AVOID_MARK.filled(),
                    )
                }))
                .map_err(err)?
                .label("reference target")
                .legend(|(x, y)| {
                    Polygon::new(
                        vec![(x + 7, y - 5), (x + 12, y), (x + 7, y + 5), (x + 2, y)],
                        AVOID_MARK.filled(),
                    )
                });
        }
        if !hits.is_empty() {
            chart
                .draw_series(
                    hits.iter()
                        .map(|&p| Cross::new(p, 3, RGBColor(110, 0, 0).stroke_width(1))),
                )
                .map_err(err)?
                .label("detection")
                .legend(|(x, y)| Cross::new((x + 8, y), 4, RGBColor(110, 0, 0).stroke_width(2)));
        }
        let lost: Vec<(f64, f64)> = run
            .events
            .iter()
            .filter_map(|e| match &e.event {
                EventKind::Planner(PlannerEvent::LostPoint { pos_m }) => Some((pos_m.x, pos_m.y)),
                _ => None,
            })
            .collect();
        if !lost.is_empty() {
            chart
                .draw_series(
                    lost.iter()
                        .map(|&p| Circle::new(p, 5, RGBColor(230, 120, 0).stroke_width(2))),
                )
                .map_err(err)?
                .label("lost point")
                .legend(|(x, y)| Circle::new((x + 8, y), 5, RGBColor(230, 120, 0).stroke_width(2)));
        }
        if !run.sources.is_empty() {
            chart
                .draw_series(
                    run.sources
                        .iter()
                        .map(|s| TriangleMarker::new((s.x, s.y), 9, RGBColor(0, 140, 60).filled())),
                )
                .map_err(err)?
                .label("true source")
                .legend(|(x, y)| TriangleMarker::new((x + 8, y), 6, RGBColor(0, 140, 60).filled()));
        }
        let declared: Vec<(f64, f64)> = run
            .summary
            .declarations
            .iter()
            .map(|d| (d.x_m, d.y_m))
            .collect();
        if !declared.is_empty() {
            chart
                .draw_series(declared.iter().map(|&p| Circle::new(p, 7, BLACK.filled())))
                .map_err(err)?
                .label("declared source")
                .legend(|(x, y)| Circle::new((x + 8, y), 5, BLACK.filled()));
        }
        // What the legend could hide: the tracks (every 10th step), lost points, sources and
        // declarations.
        let mut marks: Vec<(f64, f64)> = run
            .trajectory
            .iter()
            .step_by(10)
            .filter_map(|r| r.est_x_m.zip(r.est_y_m))
            .collect();
        marks.extend(&lost);
        marks.extend(&declared);
        marks.extend(run.sources.iter().map(|s| (s.x, s.y)));
        // Rows of the legend: everything that may be drawn, counted as drawn.
        let legend_rows = usize::from(run.mean_plume.is_some())
            + 2
            + usize::from(!run.obstacles.is_empty())
            + behaviours_drawn.len()
            + n_track_labels
            + usize::from(!paths.is_empty())
            + usize::from(!targets.is_empty())
            + usize::from(!hits.is_empty())
            + usize::from(!lost.is_empty())
            + usize::from(!run.sources.is_empty())
            + usize::from(!declared.is_empty());
        let (pw, ph) = chart.plotting_area().dim_in_pixel();
        let corner = legend_corner(
            &marks,
            x0..x1,
            y0..y1,
            (f64::from(pw), f64::from(ph)),
            (
                if vehicles.len() > 1 { 330.0 } else { 250.0 },
                20.0 * legend_rows as f64 + 10.0,
            ),
        );
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", 12))
            .position(corner)
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_legend_goes_to_the_emptiest_corner() {
        let panel = (800.0, 800.0);
        let legend = (200.0, 200.0);
        let pick = |pts: &[(f64, f64)]| legend_corner(pts, 0.0..100.0, 0.0..100.0, panel, legend);
        assert!(matches!(pick(&[]), SeriesLabelPosition::LowerRight));
        // A track through the lower right and upper right corners.
        let track: Vec<(f64, f64)> = (0..100).map(|k| (90.0, f64::from(k))).collect();
        assert!(matches!(pick(&track), SeriesLabelPosition::LowerLeft));
        let mut more = track.clone();
        more.push((10.0, 10.0));
        assert!(matches!(pick(&more), SeriesLabelPosition::UpperLeft));
    }
}
