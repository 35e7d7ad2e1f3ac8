//! Where everything goes on the map: its extent at one scale in x and y, the layers drawn of
//! each vehicle, the legend's corner (or the band below), the key's corner, the markers' labels,
//! and the polygons clipped to the map.

use super::DETECTION_GAP_S;
use super::legend::{LegendEntry, legend_px, map_legend};
use super::model::{
    BehaviourRun, EventMark, Overlays, Segment, TimeMark, detection_ticks, est_track, fault_pieces,
    flow_words, outside_pieces, thin, time_marks, time_step_min,
};
use super::raster::{hot_points, plume_cells, posterior_cells};
use super::style::{Icon, MAP_MAX_PX, MAP_MIN_PX, TIME_FONT_PX, TRACK_COLOURS, WIDTH_PX, text_px};
use crate::chart::map_chart;
use crate::error::ReportError;
use plotters::prelude::*;
use plumetrace_core::{Heading, PlannerEvent, Vec2};
use plumetrace_guidance::OpArea;
use plumetrace_mission::{EventKind, MissionRun, TrajectoryRow, lost_points};
use std::collections::BTreeMap;
use std::ops::Range;

/// The corner of the map panel where a box of `px` pixels hides the fewest of `points` (data
/// coordinates over `x` x `y` drawn on a panel of `panel_px`), lower right on ties; corners in
/// `taken` are not considered (all four taken: lower right).
pub(super) fn emptiest_corner(
    points: &[(f64, f64)],
    x: Range<f64>,
    y: Range<f64>,
    panel_px: (f64, f64),
    px: (f64, f64),
    taken: &[Corner],
) -> Corner {
    let fx = (px.0 / panel_px.0).min(1.0) * (x.end - x.start);
    let fy = (px.1 / panel_px.1).min(1.0) * (y.end - y.start);
    let mut best = (Corner::LowerRight, usize::MAX);
    for corner in Corner::ALL.into_iter().filter(|c| !taken.contains(c)) {
        let (cx, cy) = corner.box_in(&x, &y, fx, fy);
        let n = points
            .iter()
            .filter(|(px, py)| cx.contains(px) && cy.contains(py))
            .count();
        if n < best.1 {
            best = (corner, n);
        }
    }
    best.0
}

/// A corner of the map's plotting area.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Corner {
    LowerRight,
    UpperRight,
    LowerLeft,
    UpperLeft,
}

impl Corner {
    /// In the order ties are broken.
    pub(super) const ALL: [Corner; 4] = [
        Corner::LowerRight,
        Corner::UpperRight,
        Corner::LowerLeft,
        Corner::UpperLeft,
    ];

    pub(super) fn right(self) -> bool {
        matches!(self, Corner::LowerRight | Corner::UpperRight)
    }

    pub(super) fn upper(self) -> bool {
        matches!(self, Corner::UpperRight | Corner::UpperLeft)
    }

    /// The box `fx` x `fy` (data units) in this corner of `x` x `y`.
    pub(super) fn box_in(
        self,
        x: &Range<f64>,
        y: &Range<f64>,
        fx: f64,
        fy: f64,
    ) -> (Range<f64>, Range<f64>) {
        let cx = if self.right() {
            x.end - fx..x.end
        } else {
            x.start..x.start + fx
        };
        let cy = if self.upper() {
            y.end - fy..y.end
        } else {
            y.start..y.start + fy
        };
        (cx, cy)
    }

    pub(super) fn position(self) -> SeriesLabelPosition {
        match self {
            Corner::LowerRight => SeriesLabelPosition::LowerRight,
            Corner::UpperRight => SeriesLabelPosition::UpperRight,
            Corner::LowerLeft => SeriesLabelPosition::LowerLeft,
            Corner::UpperLeft => SeriesLabelPosition::UpperLeft,
        }
    }
}

/// What is drawn of one vehicle.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct VehicleLayer {
    pub(super) vehicle: u32,
    /// The vehicle's own colour (its track with several vehicles, its reading line).
    pub(super) colour: RGBColor,
    pub(super) truth: Vec<(f64, f64)>,
    /// The estimated track in runs under one behaviour.
    pub(super) runs: Vec<BehaviourRun>,
    /// The track flown during each fault window, estimated and true (index into the vehicle's
    /// faults).
    pub(super) faults: Vec<(usize, Vec<(f64, f64)>)>,
    /// The true track outside the op-area, in pieces.
    pub(super) outside: Vec<Vec<(f64, f64)>>,
    /// Where a position fix moved the estimate (from, to) and when, s.
    pub(super) jumps: Vec<(Segment, f64)>,
    pub(super) detections: Vec<Segment>,
    pub(super) times: Vec<TimeMark>,
}

/// Everything the map shows, in data coordinates, and where it goes.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct MapLayout {
    pub(super) x: Range<f64>,
    pub(super) y: Range<f64>,
    /// Plotting area, px.
    pub(super) plot_px: (u32, u32),
    /// The map panel's height, px.
    pub(super) map_h_px: u32,
    /// Metres per pixel, the same along x and y.
    pub(super) m_per_px: f64,
    /// Multi-vehicle: tracks in the vehicles' colours.
    pub(super) multi: bool,
    /// The mean plume's cells, and the source map's.
    pub(super) plume: Vec<([(f64, f64); 2], RGBColor)>,
    pub(super) source_map: Vec<([(f64, f64); 2], RGBColor)>,
    pub(super) obstacles: Vec<Vec<(f64, f64)>>,
    pub(super) layers: Vec<VehicleLayer>,
    pub(super) time_step_min: f64,
    /// Obstacle avoidance: each virtual path from where the obstacle was sensed, its course
    /// and its last reference target.
    pub(super) virtual_paths: Vec<(Vec2, Heading, Vec2)>,
    pub(super) targets: Vec<(f64, f64)>,
    pub(super) lost: Vec<(f64, f64)>,
    pub(super) declared: Vec<(f64, f64)>,
    pub(super) marks: Vec<EventMark>,
    pub(super) legend: Vec<LegendEntry>,
    /// The legend's corner of the map (`None`: below the map).
    pub(super) legend_corner: Option<Corner>,
    /// The flow arrow and scale bar: corner, size in px, scale bar length in m.
    pub(super) key_corner: Corner,
    pub(super) key_px: (u32, u32),
    pub(super) scale_m: f64,
}

/// A growing bounding box of finite points.
#[derive(Debug, Clone, Copy)]
struct Bounds {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
}

impl Bounds {
    fn new() -> Self {
        Bounds {
            x0: f64::INFINITY,
            x1: f64::NEG_INFINITY,
            y0: f64::INFINITY,
            y1: f64::NEG_INFINITY,
        }
    }

    fn add(&mut self, x: f64, y: f64) {
        if x.is_finite() && y.is_finite() {
            (self.x0, self.x1) = (self.x0.min(x), self.x1.max(x));
            (self.y0, self.y1) = (self.y0.min(y), self.y1.max(y));
        }
    }
}

/// The extent of everything the map shows (every vehicle's true and estimated track, the
/// op-area and subregions, true and declared sources, lost points and reference targets) with
/// a margin of 5 % of its larger side, at least 5 m.
fn map_bounds(run: &MissionRun) -> (Range<f64>, Range<f64>) {
    let mut b = Bounds::new();
    for r in &run.trajectory {
        b.add(r.true_x_m, r.true_y_m);
        if let Some((x, y)) = r.est_x_m.zip(r.est_y_m) {
            b.add(x, y);
        }
    }
    for p in run.op_area.iter().chain(run.subregions.iter().flatten()) {
        b.add(p.x, p.y);
    }
    for s in &run.sources {
        b.add(s.x, s.y);
    }
    for d in &run.summary.declarations {
        b.add(d.x_m, d.y_m);
    }
    for e in &run.events {
        if let EventKind::Planner(
            PlannerEvent::ReferenceTarget { pos_m } | PlannerEvent::Declared { pos_m, .. },
        ) = &e.event
        {
            b.add(pos_m.x, pos_m.y);
        }
    }
    for l in lost_points(&run.events) {
        b.add(l.now_m().x, l.now_m().y);
    }
    if b.x0 > b.x1 {
        return (-50.0..50.0, -50.0..50.0);
    }
    let pad = (0.05 * (b.x1 - b.x0).max(b.y1 - b.y0)).max(5.0);
    (b.x0 - pad..b.x1 + pad, b.y0 - pad..b.y1 + pad)
}

/// Grows `x` or `y` about its centre so that a plotting area `plot_w_px` wide and between
/// `min_h_px` and `max_h_px` high shows both at one scale; the ranges and the height, px.
pub(super) fn fit_aspect(
    x: Range<f64>,
    y: Range<f64>,
    plot_w_px: f64,
    min_h_px: f64,
    max_h_px: f64,
) -> (Range<f64>, Range<f64>, u32) {
    let (dx, dy) = (x.end - x.start, y.end - y.start);
    let h = (plot_w_px * dy / dx)
        .clamp(min_h_px, max_h_px.max(min_h_px))
        .round();
    let m = (dx / plot_w_px).max(dy / h);
    let grow = |r: Range<f64>, len: f64| {
        let c = 0.5 * (r.start + r.end);
        c - 0.5 * len..c + 0.5 * len
    };
    (grow(x, m * plot_w_px), grow(y, m * h), h as u32)
}

/// The pixels `map_chart` puts around its plotting area (width, height) on a panel
/// `width_px` wide with `title`.
pub(super) fn map_overhead_px(width_px: u32, title: &str) -> Result<(u32, u32), ReportError> {
    let mut scratch = String::new();
    let (w, h) = {
        let area = SVGBackend::with_string(&mut scratch, (width_px, 1000)).into_drawing_area();
        let chart = map_chart(&area, title, 0.0..1.0, 0.0..1.0)?;
        chart.plotting_area().dim_in_pixel()
    };
    Ok((width_px.saturating_sub(w), 1000u32.saturating_sub(h)))
}

/// A round scale-bar length, m: 1, 2 or 5 times a power of ten, at most a fifth of `width_m`.
pub(super) fn scale_bar_m(width_m: f64) -> f64 {
    let target = (width_m / 5.0).max(1e-3);
    let p = 10f64.powf(target.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|k| k * p)
        .find(|&l| l <= target)
        .unwrap_or(p)
}

/// The part of `poly` inside the rectangle `x` x `y` (Sutherland-Hodgman).
pub(super) fn clip_polygon(poly: &[(f64, f64)], x: &Range<f64>, y: &Range<f64>) -> Vec<(f64, f64)> {
    type Side = (fn((f64, f64), f64) -> f64, f64, bool);
    // Signed distance inside each edge, the edge's value, and whether it cuts along x.
    let sides: [Side; 4] = [
        (|p, v| p.0 - v, x.start, true),
        (|p, v| v - p.0, x.end, true),
        (|p, v| p.1 - v, y.start, false),
        (|p, v| v - p.1, y.end, false),
    ];
    let mut out = poly.to_vec();
    for (inside, v, along_x) in sides {
        let input = std::mem::take(&mut out);
        for (k, &p) in input.iter().enumerate() {
            let q = input[(k + 1) % input.len()];
            let (dp, dq) = (inside(p, v), inside(q, v));
            if dp >= 0.0 {
                out.push(p);
            }
            if (dp >= 0.0) != (dq >= 0.0) {
                let s = dp / (dp - dq);
                let c = (p.0 + s * (q.0 - p.0), p.1 + s * (q.1 - p.1));
                out.push(if along_x { (v, c.1) } else { (c.0, v) });
            }
        }
        if out.is_empty() {
            break;
        }
    }
    out
}

/// Where a label of `size_px` next to a marker at `at` hides the fewest of `points` and stays
/// on the map: right of it, left of it, above or below it (centred, then starting or ending
/// at it), in that order on ties; its upper left corner, px from the marker (right, down).
fn label_place(
    at: (f64, f64),
    size_px: (i32, i32),
    points: &[(f64, f64)],
    (x, y): (&Range<f64>, &Range<f64>),
    m: f64,
) -> (i32, i32) {
    let (w, h) = size_px;
    let candidates = [
        (10, -h / 2),
        (-10 - w, -h / 2),
        (-w / 2, -h - 10),
        (-w / 2, 10),
        (-4, -h - 10),
        (-4, 10),
        (4 - w, -h - 10),
        (4 - w, 10),
    ];
    let mut best = (candidates[0], usize::MAX);
    for (ox, oy) in candidates {
        let (xa, xb) = (at.0 + f64::from(ox) * m, at.0 + f64::from(ox + w) * m);
        let (ya, yb) = (at.1 - f64::from(oy + h) * m, at.1 - f64::from(oy) * m);
        let on_map = xa >= x.start && xb <= x.end && ya >= y.start && yb <= y.end;
        let hidden = points
            .iter()
            .filter(|p| (xa..xb).contains(&p.0) && (ya..yb).contains(&p.1))
            .count();
        let cost = if on_map { hidden } else { usize::MAX - 1 };
        if cost < best.1 {
            best = ((ox, oy), cost);
        }
    }
    best.0
}

/// Everything the map shows and where.
pub(super) fn map_layout(
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
    title: &str,
) -> Result<MapLayout, ReportError> {
    let (bx, by) = map_bounds(run);
    let multi = rows.len() > 1;
    let duration_s = rows
        .values()
        .filter_map(|r| r.last())
        .map(|r| r.t_s)
        .fold(0.0, f64::max);
    let step_min = time_step_min(duration_s);
    let over = Overlays::of(run, rows);
    let area = OpArea::new(run.op_area.clone()).ok();
    let outside: BTreeMap<u32, Vec<Vec<(f64, f64)>>> = rows
        .iter()
        .map(|(&v, rs)| {
            (
                v,
                area.as_ref().map_or(Vec::new(), |a| outside_pieces(rs, a)),
            )
        })
        .collect();
    let any_outside = outside.values().any(|p| !p.is_empty());
    let mut legend = map_legend(run, rows, (&bx, &by), any_outside, step_min, &over);

    // The scale: one in x and y. The legend goes into a corner of the map (made tall enough
    // for it) where it hides nothing; with no such corner, below the map.
    let (over_w, over_h) = map_overhead_px(WIDTH_PX, title)?;
    let plot_w = f64::from(WIDTH_PX - over_w);
    let (_, lh) = legend_px(&legend);
    let (x, y, plot_h, legend_corner) = fit_map(run, rows, &over, &legend, (bx, by), plot_w);
    let m = (x.end - x.start) / plot_w;
    let mut layers = vehicle_layers(run, rows, &outside, m, step_min);
    // Jumps too short to see are not drawn, so not listed (the legend only shrinks).
    if layers.iter().all(|l| l.jumps.is_empty()) {
        legend.retain(|e| e.icon != Icon::Dotted(BLACK));
    }
    let mut mark_points: Vec<(f64, f64)> = run.sources.iter().map(|s| (s.x, s.y)).collect();
    mark_points.extend(&over.declared);
    mark_points.extend(&over.lost);
    mark_points.extend(&over.targets);
    mark_points.extend(over.marks.iter().map(|k| k.pos));
    // The legend in its corner (as plotters places it: 5 px in from the plotting area's edges).
    let taken: Vec<MapBox> = legend_corner
        .map(|c| {
            let (lw, lh) = legend_px(&legend);
            let (cx, cy) = c.box_in(&x, &y, (lw + 5.0) * m, (lh + 5.0) * m);
            (
                ((cx.start + cx.end) / 2.0, (cy.start + cy.end) / 2.0),
                (cx.end - cx.start) / 2.0,
                (cy.end - cy.start) / 2.0,
            )
        })
        .into_iter()
        .collect();
    place_time_labels(&mut layers, &mark_points, &taken, (&x, &y), m);
    let plume = plume_cells(run, &x, &y);
    let source_map = posterior_cells(run, &x, &y);
    let obstacles = run
        .obstacles
        .iter()
        .map(|o| clip_polygon(&o.iter().map(|v| (v.x, v.y)).collect::<Vec<_>>(), &x, &y))
        .filter(|o| o.len() > 2)
        .collect();

    // What the legend and the key could hide.
    let points = drawn_points(run, &layers, &over, m);
    let Overlays {
        virtual_paths,
        targets,
        lost,
        declared,
        mut marks,
    } = over;
    for k in &mut marks {
        let w = text_px(&k.kind.text(k.t_s), 12.0).round() as i32 + 4;
        k.label_px = label_place(k.pos, (w, 16), &points, (&x, &y), m);
    }
    let panel_px = (plot_w, f64::from(plot_h));
    let scale_m = scale_bar_m(x.end - x.start);
    let key_w = (44.0 + text_px(&flow_words(run.mean_flow_mps).0, 12.0) + 10.0)
        .max(12.0 + scale_m / m + 6.0 + text_px(&format!("{scale_m:.0} m"), 12.0) + 10.0);
    let key_px = (key_w.round() as u32, 62);
    // The key shares a side with the legend only where both fit one above the other.
    let fits = lh + f64::from(key_px.1) + 20.0 <= f64::from(plot_h);
    let taken: Vec<Corner> = match legend_corner {
        Some(l) => Corner::ALL
            .into_iter()
            .filter(|&c| c == l || (!fits && c.right() == l.right()))
            .collect(),
        None => Vec::new(),
    };
    let key_corner = emptiest_corner(
        &points,
        x.clone(),
        y.clone(),
        panel_px,
        (f64::from(key_px.0), f64::from(key_px.1)),
        &taken,
    );
    // With no free corner, the map grows by the key's height on the key's side, so the key
    // sits clear of what is drawn (the op-area's border, a track) rather than over it.
    let (fx, fy) = (f64::from(key_px.0 + 10) * m, f64::from(key_px.1 + 10) * m);
    let (kx, ky) = key_corner.box_in(&x, &y, fx, fy);
    let hides = points
        .iter()
        .any(|(px, py)| kx.contains(px) && ky.contains(py));
    let (y, plot_h) = if hides {
        let grow = key_px.1 + 14;
        let dy = f64::from(grow) * m;
        let y = if key_corner.upper() {
            y.start..y.end + dy
        } else {
            y.start - dy..y.end
        };
        (y, plot_h + grow)
    } else {
        (y, plot_h)
    };
    Ok(MapLayout {
        map_h_px: plot_h + over_h,
        plot_px: (WIDTH_PX - over_w, plot_h),
        x,
        y,
        m_per_px: m,
        multi,
        plume,
        source_map,
        obstacles,
        layers,
        time_step_min: step_min,
        virtual_paths,
        targets,
        lost,
        declared,
        marks,
        legend,
        legend_corner,
        key_corner,
        key_px,
        scale_m,
    })
}

/// The map's extent over the bounds `(bx, by)` at one scale in x and y on a plotting area
/// `plot_w` px wide, its plotting height, px, and the legend's corner: a corner of the map (made
/// tall enough for the legend) where the legend hides nothing marked; with no such corner,
/// `None` (the legend goes below the map, and the map is not made taller for it).
fn fit_map(
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
    over: &Overlays,
    legend: &[LegendEntry],
    (bx, by): (Range<f64>, Range<f64>),
    plot_w: f64,
) -> (Range<f64>, Range<f64>, u32, Option<Corner>) {
    let (lw, lh) = legend_px(legend);
    let mut marked: Vec<(f64, f64)> = rows
        .values()
        .flat_map(|rs| rs.iter().step_by(5))
        .flat_map(|r| [Some((r.true_x_m, r.true_y_m)), r.est_x_m.zip(r.est_y_m)])
        .flatten()
        .collect();
    marked.extend(&over.lost);
    marked.extend(&over.declared);
    marked.extend(run.sources.iter().map(|s| (s.x, s.y)));
    marked.extend(over.marks.iter().map(|k| k.pos));
    // Nor the plume's core or the source map's likely cells, nor the op-area's border.
    marked.extend(hot_points(run));
    marked.extend(outline_points(&run.op_area));
    let (x, y, plot_h) = fit_aspect(
        bx.clone(),
        by.clone(),
        plot_w,
        MAP_MIN_PX.max(lh + 20.0),
        MAP_MAX_PX,
    );
    let (fx, fy) = (
        lw / plot_w * (x.end - x.start),
        lh / f64::from(plot_h) * (y.end - y.start),
    );
    let inside = Corner::ALL.into_iter().find(|c| {
        let (cx, cy) = c.box_in(&x, &y, fx, fy);
        !legend.is_empty()
            && !marked
                .iter()
                .any(|(px, py)| cx.contains(px) && cy.contains(py))
    });
    match inside {
        Some(_) => (x, y, plot_h, inside),
        None => {
            let (x, y, plot_h) = fit_aspect(bx, by, plot_w, MAP_MIN_PX, MAP_MAX_PX);
            (x, y, plot_h, inside)
        }
    }
}

/// What is drawn of each vehicle at `m` metres a pixel (`outside`: each vehicle's true track
/// outside the op-area; `step_min`: minutes between time marks).
fn vehicle_layers(
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
    outside: &BTreeMap<u32, Vec<Vec<(f64, f64)>>>,
    m: f64,
    step_min: f64,
) -> Vec<VehicleLayer> {
    let mut layers: Vec<VehicleLayer> = Vec::new();
    for (n, (&vid, rs)) in rows.iter().enumerate() {
        let truth: Vec<(f64, f64)> = rs.iter().map(|r| (r.true_x_m, r.true_y_m)).collect();
        // Jumps of 10 px or more break the track and are drawn.
        let (runs, jumps) = est_track(rs, (10.0 * m).max(5.0));
        let runs = runs
            .into_iter()
            .map(|(b, pts)| (b, thin(&pts, m)))
            .collect();
        layers.push(VehicleLayer {
            vehicle: vid,
            colour: TRACK_COLOURS[n % TRACK_COLOURS.len()],
            truth: thin(&truth, m),
            runs,
            faults: fault_pieces(run, vid, rs, (10.0 * m).max(5.0))
                .into_iter()
                .map(|(k, pts)| (k, thin(&pts, m)))
                .collect(),
            outside: outside
                .get(&vid)
                .map_or(Vec::new(), |p| p.iter().map(|p| thin(p, m)).collect()),
            jumps,
            detections: detection_ticks(rs, DETECTION_GAP_S, 4.0 * m, 1.5 * m),
            times: time_marks(rs, step_min, 5.0 * m, 15.0 * m, 4.0 * m),
        });
    }
    layers
}

/// Whether the segments `a`-`b` and `p`-`q` cross.
fn segments_cross(a: (f64, f64), b: (f64, f64), p: (f64, f64), q: (f64, f64)) -> bool {
    let side = |o: (f64, f64), u: (f64, f64), v: (f64, f64)| {
        (u.0 - o.0) * (v.1 - o.1) - (u.1 - o.1) * (v.0 - o.0)
    };
    let (d1, d2) = (side(p, q, a), side(p, q, b));
    let (d3, d4) = (side(a, b, p), side(a, b, q));
    d1 * d2 < 0.0 && d3 * d4 < 0.0
}

/// Whether the segment `a`-`b` meets the box `r` (left, bottom, right, top).
fn segment_meets_box(a: (f64, f64), b: (f64, f64), r: (f64, f64, f64, f64)) -> bool {
    let inside = |p: (f64, f64)| r.0 <= p.0 && p.0 <= r.2 && r.1 <= p.1 && p.1 <= r.3;
    let corners = [(r.0, r.1), (r.2, r.1), (r.2, r.3), (r.0, r.3)];
    inside(a) || inside(b) || (0..4).any(|k| segments_cross(a, b, corners[k], corners[(k + 1) % 4]))
}

/// A box on the map: centre and half sizes, m.
type MapBox = ((f64, f64), f64, f64);

/// How far from its tick a time label may be placed, px: it is moved out in steps of 10 px up
/// to this, in twelve directions.
const LEADER_MAX_PX: f64 = 65.0;

/// Places each time label on the side of its tick where it hides no marker (true and declared
/// sources, lost points, reference targets, aborts and incidents: `marks`, each about 9 px
/// across), overlaps no earlier label and no box in `taken` (the legend) and stays on the map
/// `(x, y)`, on a side that no track crosses. With both sides crossed, the label goes further
/// out (up to [`LEADER_MAX_PX`]) where no track crosses it, with a leader line to its tick that
/// crosses no other leader or label; with no such place, it is left out (its tick stays).
fn place_time_labels(
    layers: &mut [VehicleLayer],
    marks: &[(f64, f64)],
    taken: &[MapBox],
    (x, y): (&Range<f64>, &Range<f64>),
    m: f64,
) {
    let mark_half = 9.0 * m;
    let mut boxes: Vec<MapBox> = marks.iter().map(|&p| (p, mark_half, mark_half)).collect();
    boxes.extend(taken);
    let tracks = track_points(layers, 2.0 * m);
    let (mut labels, mut leaders): (Vec<MapBox>, Vec<Segment>) = (Vec::new(), Vec::new());
    for l in layers {
        for t in &mut l.times {
            let half = ((text_px(&t.label, TIME_FONT_PX) / 2.0 + 2.0) * m, 7.0 * m);
            let mid = (
                (t.tick[0].0 + t.tick[1].0) / 2.0,
                (t.tick[0].1 + t.tick[1].1) / 2.0,
            );
            let sides = [
                t.label_at,
                (2.0 * mid.0 - t.label_at.0, 2.0 * mid.1 - t.label_at.1),
            ];
            let overlaps = |c: (f64, f64), (p, w, h): MapBox| {
                (c.0 - p.0).abs() < half.0 + w && (c.1 - p.1).abs() < half.1 + h
            };
            let clear = |c: (f64, f64)| !boxes.iter().any(|&b| overlaps(c, b));
            let off_tracks = |c: (f64, f64)| !tracks.iter().any(|&p| overlaps(c, (p, 0.0, 0.0)));
            let on_map = |c: (f64, f64)| {
                c.0 - half.0 >= x.start
                    && c.0 + half.0 <= x.end
                    && c.1 - half.1 >= y.start
                    && c.1 + half.1 <= y.end
            };
            let near = sides.into_iter().find(|&c| clear(c) && off_tracks(c));
            // A leader crosses no other leader and no other label.
            let free_leader = |c: (f64, f64)| {
                let [a, b] = leader_line(mid, c, half, m);
                !leaders.iter().any(|&[p, q]| segments_cross(a, b, p, q))
                    && !labels.iter().any(|&(p, w, h)| {
                        segment_meets_box(a, b, (p.0 - w, p.1 - h, p.0 + w, p.1 + h))
                    })
            };
            let far = || {
                further_out(mid, t.label_at, m)
                    .find(|&c| on_map(c) && clear(c) && off_tracks(c) && free_leader(c))
            };
            match near
                .map(|c| (c, false))
                .or_else(|| far().map(|c| (c, true)))
            {
                Some((at, leader)) => {
                    t.label_at = at;
                    t.leader = leader.then(|| leader_line(mid, at, half, m));
                    boxes.push((at, half.0, half.1));
                    labels.push((at, half.0, half.1));
                    leaders.extend(t.leader);
                }
                None => t.label.clear(),
            }
        }
    }
}

/// Places further out from a tick at `mid` whose label would sit at `label_at`: in steps of
/// 10 px from 25 px up to [`LEADER_MAX_PX`] from the tick, along the tick (either side)
/// first, then the ten other directions 30 degrees apart, nearest the tick's first.
fn further_out(mid: (f64, f64), label_at: (f64, f64), m: f64) -> impl Iterator<Item = (f64, f64)> {
    let (dx, dy) = (label_at.0 - mid.0, label_at.1 - mid.1);
    let len = dx.hypot(dy).max(1e-9);
    let (ux, uy) = (dx / len, dy / len);
    // Along the tick, the other side, then the diagonals and along the track.
    let turns = [
        0.0, 180.0, 30.0, -30.0, 150.0, -150.0, 60.0, -60.0, 120.0, -120.0, 90.0, -90.0,
    ];
    (0..)
        .map(|k| 25.0 + 10.0 * f64::from(k))
        .take_while(|d| *d <= LEADER_MAX_PX)
        .flat_map(move |d| {
            turns.into_iter().map(move |deg: f64| {
                let (s, c) = deg.to_radians().sin_cos();
                let (vx, vy) = (ux * c - uy * s, ux * s + uy * c);
                (mid.0 + vx * d * m, mid.1 + vy * d * m)
            })
        })
}

/// The leader from a tick at `mid` to its label's box centred at `at` (half sizes `half`, m):
/// from 6 px off the tick to the box's edge.
fn leader_line(mid: (f64, f64), at: (f64, f64), half: (f64, f64), m: f64) -> Segment {
    let (dx, dy) = (at.0 - mid.0, at.1 - mid.1);
    let len = dx.hypot(dy).max(1e-9);
    // How far back from the centre the line leaves the box.
    let back = (half.0 / dx.abs().max(1e-9)).min(half.1 / dy.abs().max(1e-9));
    let from = (mid.0 + dx / len * 6.0 * m, mid.1 + dy / len * 6.0 * m);
    let to = (at.0 - dx * back.min(1.0), at.1 - dy * back.min(1.0));
    [from, to]
}

/// Points along every drawn track (true and estimated), no more than `step` apart, so a label
/// box that a track crosses holds at least one of them.
fn track_points(layers: &[VehicleLayer], step: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut along = |line: &[(f64, f64)]| {
        for w in line.windows(2) {
            let (a, b) = (w[0], w[1]);
            let n = ((b.0 - a.0).hypot(b.1 - a.1) / step)
                .ceil()
                .clamp(1.0, 10_000.0) as usize;
            out.extend((0..n).map(|i| {
                let f = i as f64 / n as f64;
                (a.0 + (b.0 - a.0) * f, a.1 + (b.1 - a.1) * f)
            }));
        }
        out.extend(line.last().copied());
    };
    for l in layers {
        along(&l.truth);
        for (_, p) in &l.runs {
            along(p);
        }
    }
    out
}

/// Every point drawn on the map that the legend, the key or a marker's label could hide.
fn drawn_points(
    run: &MissionRun,
    layers: &[VehicleLayer],
    over: &Overlays,
    m: f64,
) -> Vec<(f64, f64)> {
    let mut points: Vec<(f64, f64)> = Vec::new();
    for l in layers {
        points.extend(&l.truth);
        points.extend(l.runs.iter().flat_map(|(_, p)| p.iter().copied()));
        points.extend(l.outside.iter().flatten());
        // Each time label's box (its centre and corners) and leader.
        for t in l.times.iter().filter(|t| !t.label.is_empty()) {
            let (w, h) = ((text_px(&t.label, TIME_FONT_PX) / 2.0 + 2.0) * m, 7.0 * m);
            let (cx, cy) = t.label_at;
            points.extend([
                (cx, cy),
                (cx - w, cy - h),
                (cx + w, cy - h),
                (cx - w, cy + h),
                (cx + w, cy + h),
            ]);
            points.extend(t.leader.iter().flatten());
        }
    }
    points.extend(&over.lost);
    points.extend(&over.declared);
    points.extend(run.sources.iter().map(|s| (s.x, s.y)));
    points.extend(over.marks.iter().map(|k| k.pos));
    // The op-area's border, and the plume's core: a key over them hides them.
    points.extend(outline_points(&run.op_area));
    points.extend(hot_points(run));
    points
}

/// Points along a closed outline, 40 to an edge (so a box over its border counts as hiding it).
fn outline_points(poly: &[Vec2]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for (k, a) in poly.iter().enumerate() {
        let b = poly[(k + 1) % poly.len()];
        out.extend((0..40).map(|i| {
            let f = f64::from(i) / 40.0;
            (a.x + (b.x - a.x) * f, a.y + (b.y - a.y) * f)
        }));
    }
    out
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::super::test_support::{demo, labels, layout, row};
    use super::super::{DETECTION_GAP_S, mission_figure};
    use super::*;
    use plumetrace_mission::{EventRecord, FaultWindow, MissionEvent};

    #[test]
    fn boxes_go_to_the_emptiest_free_corner() {
        let panel = (800.0, 800.0);
        let legend = (200.0, 200.0);
        let pick = |pts: &[(f64, f64)], taken: &[Corner]| {
            emptiest_corner(pts, 0.0..100.0, 0.0..100.0, panel, legend, taken)
        };
        assert_eq!(pick(&[], &[]), Corner::LowerRight);
        // A track through the lower right and upper right corners.
        let track: Vec<(f64, f64)> = (0..100).map(|k| (90.0, f64::from(k))).collect();
        assert_eq!(pick(&track, &[]), Corner::LowerLeft);
        let mut more = track.clone();
        more.push((10.0, 10.0));
        assert_eq!(pick(&more, &[]), Corner::UpperLeft);
        assert_eq!(pick(&more, &[Corner::UpperLeft]), Corner::LowerLeft);
        assert_eq!(pick(&[], &[Corner::LowerRight]), Corner::UpperRight);
    }

    #[test]
    fn scale_bars_are_round_and_at_most_a_fifth_of_the_map() {
        let cases = [
            (420.0, 50.0),
            (1100.0, 200.0),
            (250.0, 50.0),
            (1000.0, 200.0),
            (90.0, 10.0),
            (3000.0, 500.0),
        ];
        for (width_m, bar_m) in cases {
            assert_eq!(scale_bar_m(width_m), bar_m, "{width_m} m");
        }
    }

    #[test]
    fn fitting_keeps_one_scale_in_x_and_y() {
        // (x extent, y extent, plot width px) -> the same metres per pixel along both
        let cases = [
            (400.0, 200.0, 800.0),
            (400.0, 10.0, 800.0),
            (100.0, 2000.0, 800.0),
            (1100.0, 950.0, 803.0),
        ];
        for (dx, dy, w) in cases {
            let (x, y, h) = fit_aspect(0.0..dx, 0.0..dy, w, 300.0, 1200.0);
            assert!((300..=1200).contains(&h), "{dx} x {dy}: {h} px");
            let (mx, my) = ((x.end - x.start) / w, (y.end - y.start) / f64::from(h));
            assert!((mx - my).abs() < 1e-9 * mx, "{dx} x {dy}: {mx} vs {my}");
            assert!(x.start <= 0.0 && x.end >= dx && y.start <= 0.0 && y.end >= dy);
        }
    }

    #[test]
    fn polygons_are_clipped_to_the_map() {
        let square = [(-10.0, -10.0), (10.0, -10.0), (10.0, 10.0), (-10.0, 10.0)];
        let inside = clip_polygon(&square, &(-20.0..20.0), &(-20.0..20.0));
        assert_eq!(inside.len(), 4);
        let half = clip_polygon(&square, &(0.0..20.0), &(-20.0..20.0));
        assert!(half.iter().all(|p| p.0 >= 0.0 && p.0 <= 10.0), "{half:?}");
        assert!(clip_polygon(&square, &(30.0..40.0), &(0.0..1.0)).is_empty());
    }

    #[test]
    fn the_map_covers_an_excursion_and_marks_the_cage_abort() {
        let mut run = demo(240.0);
        let op_x_max = run.op_area.iter().map(|p| p.x).fold(f64::MIN, f64::max);
        let last = run.trajectory.iter().map(|r| r.t_s).fold(0.0, f64::max);
        // The vehicle truly flies on 600 m east of the op-area while its estimate stays where
        // it was; a position fix then moves the estimate out there, and the cage aborts.
        let (ex, ey) = run
            .trajectory
            .iter()
            .rev()
            .find(|r| r.vehicle == 0)
            .and_then(|r| r.est_x_m.zip(r.est_y_m))
            .unwrap();
        for k in 1..=600 {
            let t = last + f64::from(k);
            let mut r = row(t, op_x_max + f64::from(k), -20.0, false);
            if k < 600 {
                (r.est_x_m, r.est_y_m) = (Some(ex), Some(ey));
            }
            run.trajectory.push(r);
        }
        let t_abort = last + 600.0;
        run.events.push(EventRecord {
            t_s: t_abort,
            vehicle: 0,
            event: EventKind::Planner(PlannerEvent::CageAbort {
                distance_outside_m: 600.0,
            }),
        });
        run.events.push(EventRecord {
            t_s: t_abort,
            vehicle: 0,
            event: EventKind::Mission(MissionEvent::PlannerAborted),
        });
        let lay = layout(&run);
        let far = op_x_max + 600.0;
        assert!(lay.x.end > far + 10.0, "{:?} misses {far}", lay.x);
        let (mx, my) = (
            (lay.x.end - lay.x.start) / f64::from(lay.plot_px.0),
            (lay.y.end - lay.y.start) / f64::from(lay.plot_px.1),
        );
        assert!((mx - my).abs() < 1e-9 * mx, "one scale: {mx} vs {my}");
        // One marker (the planner's abort in the same step is the cage abort), where the
        // vehicle truly was.
        assert_eq!(lay.marks.len(), 1, "{:?}", lay.marks);
        assert_eq!(lay.marks[0].pos, (far, -20.0));
        let l = labels(&lay);
        for entry in [
            "cage abort (true position)",
            "true track outside the op-area",
            "navigation fix (the estimate jumps)",
        ] {
            assert!(l.contains(&entry.to_string()), "{entry}: {l:?}");
        }
        let out: usize = lay.layers[0].outside.iter().map(Vec::len).sum();
        assert!(out > 10, "the excursion is drawn: {out} points");
        assert_eq!(lay.layers[0].jumps.len(), 1, "{:?}", lay.layers[0].jumps);
        let ([_, to], t) = lay.layers[0].jumps[0];
        assert_eq!((to, t), ((far, -20.0), t_abort));
        let svg = mission_figure(&run, "excursion").unwrap();
        assert!(svg.contains("fix at "), "the jump's label");
        assert!(
            svg.contains("cage abort, 600 m outside"),
            "the marker's label"
        );
        assert!(svg.contains("cage abort (true position)"), "the legend");
    }

    #[test]
    fn a_fault_window_is_highlighted_and_named() {
        let mut run = demo(240.0);
        run.vehicles[0].faults = vec![FaultWindow {
            start_s: 60.0,
            end_s: 150.0,
            what: "flow sensor reads the wrong layer",
        }];
        let lay = layout(&run);
        let label = "fault 1.0-2.5 min: flow sensor reads the wrong layer";
        assert!(
            labels(&lay).contains(&label.to_string()),
            "{:?}",
            labels(&lay)
        );
        let (k, pts) = &lay.layers[0].faults[0];
        assert_eq!(*k, 0);
        assert!(
            pts.len() > 10,
            "the track flown in the window: {} points",
            pts.len()
        );
        let svg = mission_figure(&run, "fault").unwrap();
        assert!(svg.contains(label));
        // A window after the mission is not drawn, so not listed.
        run.vehicles[0].faults[0].start_s = 1000.0;
        run.vehicles[0].faults[0].end_s = 1200.0;
        let lay = layout(&run);
        assert!(lay.layers[0].faults.is_empty());
        assert!(labels(&lay).iter().all(|s| !s.starts_with("fault")));
    }

    #[test]
    fn tracks_carry_time_marks_and_thinned_detections() {
        let run = demo(240.0);
        let lay = layout(&run);
        assert_eq!(lay.time_step_min, 1.0);
        let times: Vec<&str> = lay.layers[0]
            .times
            .iter()
            .map(|t| t.label.as_str())
            .collect();
        // A mark every minute; a label that would overlap an earlier one is left out.
        assert_eq!(times.len(), 4, "{times:?}");
        for (k, t) in times.iter().enumerate() {
            assert!(t.is_empty() || *t == format!("{} min", k + 1), "{times:?}");
        }
        assert!(times[0] == "1 min" && times.iter().filter(|t| !t.is_empty()).count() >= 2);
        let duration_s = run.trajectory.iter().map(|r| r.t_s).fold(0.0, f64::max);
        let ticks = lay.layers[0].detections.len();
        assert!(
            ticks as f64 <= duration_s / DETECTION_GAP_S + 1.0,
            "{ticks} ticks in {duration_s} s"
        );
        let rows = run.trajectory.iter().filter(|r| r.vehicle == 0).count();
        assert!(lay.layers[0].truth.len() < rows, "the track is thinned");
        let svg = mission_figure(&run, "times").unwrap();
        for s in [
            "\n1 min\n",
            "time along the track, every 1 min",
            "reading (V)",
            "mean flow ",
        ] {
            assert!(svg.contains(s), "{s}");
        }
        assert!(
            svg.contains(&format!("\n{:.0} m\n", lay.scale_m)),
            "the scale bar"
        );
    }

    #[test]
    fn a_time_label_moves_off_a_marker_in_its_place() {
        let mut run = demo(240.0);
        let before = layout(&run);
        let first = before.layers[0].times[0].clone();
        assert_eq!(first.label, "1 min");
        // A true source just where the label went.
        let (x, y) = first.label_at;
        run.sources = vec![plumetrace_core::Vec3::new(x, y, 0.0)];
        let lay = layout(&run);
        let t = &lay.layers[0].times[0];
        let half = 9.0 * lay.m_per_px;
        assert!(
            t.label.is_empty()
                || (t.label_at.0 - x).abs() > half + 10.0 * lay.m_per_px
                || (t.label_at.1 - y).abs() > half + 6.0 * lay.m_per_px,
            "{t:?} over the source at ({x}, {y})"
        );
        let svg = mission_figure(&run, "marks").unwrap();
        let over = crate::inspect::texts_over_marks(&svg);
        assert!(over.iter().all(|t| !t.ends_with(" min")), "{over:?}");
    }

    #[test]
    fn a_time_label_moves_off_a_track_through_its_place() {
        let run = demo(240.0);
        let lay = layout(&run);
        let m = lay.m_per_px;
        let mut layers = lay.layers.clone();
        let first = layers[0].times[0].clone();
        assert!(!first.label.is_empty());
        let at = first.label_at;
        let mid = (
            (first.tick[0].0 + first.tick[1].0) / 2.0,
            (first.tick[0].1 + first.tick[1].1) / 2.0,
        );
        let other = (2.0 * mid.0 - at.0, 2.0 * mid.1 - at.1);
        // Only a short track straight through the label's place: the label goes to the other
        // side of its tick.
        for l in &mut layers {
            l.truth.clear();
            l.runs.clear();
        }
        let mut crossing = layers[0].clone();
        crossing.times.clear();
        crossing.truth = vec![(at.0, at.1 - 3.0 * m), (at.0, at.1 + 3.0 * m)];
        layers.push(crossing);
        let map = (&lay.x, &lay.y);
        place_time_labels(&mut layers, &[], &[], map, m);
        let t = &layers[0].times[0];
        assert_eq!(
            t.label_at, other,
            "the label moves to the side no track crosses"
        );
        assert_eq!(t.leader, None, "beside its tick, no leader");
        assert_eq!(t.label, first.label);
    }

    #[test]
    fn a_time_label_crossed_on_both_sides_goes_further_out_with_a_leader() {
        let run = demo(240.0);
        let rows = super::super::model::rows_by_vehicle(&run);
        let lay = layout(&run);
        let m = lay.m_per_px;
        let first = lay.layers[0].times[0].clone();
        let at = first.label_at;
        let mid = (
            (first.tick[0].0 + first.tick[1].0) / 2.0,
            (first.tick[0].1 + first.tick[1].1) / 2.0,
        );
        let other = (2.0 * mid.0 - at.0, 2.0 * mid.1 - at.1);
        // Two tracks along the vehicle's, one through each side of the tick (lanes of a
        // survey, or the track flown back).
        let (nx, ny) = ((at.0 - mid.0) / (15.0 * m), (at.1 - mid.1) / (15.0 * m));
        let lane = |c: (f64, f64)| {
            vec![
                (c.0 + ny * 60.0 * m, c.1 - nx * 60.0 * m),
                (c.0 - ny * 60.0 * m, c.1 + nx * 60.0 * m),
            ]
        };
        let mut old = lay.clone();
        for l in &mut old.layers {
            l.truth.clear();
            l.runs.clear();
            l.faults.clear();
            l.outside.clear();
        }
        old.layers[0].times.truncate(1);
        for c in [at, other] {
            let mut crossing = old.layers[0].clone();
            crossing.times.clear();
            crossing.truth = lane(c);
            old.layers.push(crossing);
        }
        // Placed as before: on its first side, over a track; the visual check's property
        // finds it.
        let svg = super::super::draw_figure(&run, &rows, &old, "crossed").unwrap();
        assert_eq!(
            crate::inspect::texts_over_tracks(&svg),
            [first.label.as_str()]
        );
        let mut new = old.clone();
        place_time_labels(&mut new.layers, &[], &[], (&lay.x, &lay.y), m);
        let t = &new.layers[0].times[0];
        assert_eq!(t.label, first.label, "kept, not left out");
        let tracks = track_points(&new.layers, m);
        let half = ((text_px(&t.label, TIME_FONT_PX) / 2.0 + 2.0) * m, 7.0 * m);
        assert!(
            tracks
                .iter()
                .all(|p| (p.0 - t.label_at.0).abs() >= half.0
                    || (p.1 - t.label_at.1).abs() >= half.1),
            "{t:?} over a track"
        );
        let [from, to] = t.leader.expect("a leader to its tick");
        assert!(
            (from.0 - mid.0).hypot(from.1 - mid.1) < 7.0 * m,
            "{from:?} from the tick"
        );
        let d = (t.label_at.0 - mid.0).hypot(t.label_at.1 - mid.1) / m;
        assert!((24.9..=LEADER_MAX_PX + 0.1).contains(&d), "{d} px out");
        assert!(segments_cross(
            (0.0, 0.0),
            (2.0, 2.0),
            (0.0, 2.0),
            (2.0, 0.0)
        ));
        assert!(!segments_cross(
            (0.0, 0.0),
            (1.0, 0.0),
            (0.0, 1.0),
            (1.0, 1.0)
        ));
        assert!(segment_meets_box(
            (-1.0, 0.5),
            (2.0, 0.5),
            (0.0, 0.0, 1.0, 1.0)
        ));
        assert!(!segment_meets_box(
            (-1.0, 2.0),
            (2.0, 2.0),
            (0.0, 0.0, 1.0, 1.0)
        ));
        assert!(
            (to.0 - t.label_at.0).abs() <= half.0 + 1e-9
                && (to.1 - t.label_at.1).abs() <= half.1 + 1e-9,
            "{to:?} at the label's box"
        );
        let svg = super::super::draw_figure(&run, &rows, &new, "crossed").unwrap();
        assert!(crate::inspect::texts_over_tracks(&svg).is_empty());
        assert!(crate::inspect::overlapping_texts(&svg).is_empty());
    }

    #[test]
    fn the_key_and_legend_keep_off_the_op_areas_border() {
        let run = demo(240.0);
        let area = outline_points(&run.op_area);
        assert_eq!(area.len(), 40 * run.op_area.len());
        let points = drawn_points(
            &run,
            &layout(&run).layers,
            &Overlays::of(&run, &super::super::model::rows_by_vehicle(&run)),
            1.0,
        );
        assert!(area.iter().all(|p| points.contains(p)));
    }
}
