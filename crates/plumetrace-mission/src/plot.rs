//! The mission figure, drawn from the recorded run (like the field-test figures).
//!
//! The map covers everything that was recorded, with a margin and at one scale in x and y:
//! every vehicle's true and estimated track, the op-area (dashed; subregions dashed grey), true
//! sources (triangles) and declared sources (filled dots), so an excursion that made the cage
//! abort stays in view. On it: the time-averaged plume at the first vehicle's altitude as a
//! light heat map; kelp as filled green patches; each vehicle's estimated track as it logged it,
//! coloured by the behaviour in control (with several vehicles one colour each, each track's
//! start labelled with the vehicle's name) and broken where a position fix moved the estimate
//! (the jump dashed, a long one labelled); the true tracks thin and grey, darker outside the
//! op-area; detections as thin ticks across the track, at most one per [`DETECTION_GAP_S`] per
//! vehicle so that the track stays visible; the time every few minutes along each track; the
//! tracks flown during a sensor fault on a wide yellow underlay; lost points as open circles;
//! obstacle avoidance's virtual paths dotted with their reference targets as diamonds; cage
//! aborts, other aborts and incidents as labelled markers at the vehicle's true position; and a
//! key with the mean flow at the source (arrow, speed, direction) and a round scale bar. The
//! legend lists only what is drawn: in a corner of the map where it hides no track, else below
//! the map.
//!
//! Below, for the vehicles with a planner: the chemical reading against mission time, the
//! behaviour in control as a strip under it (the track's colours), fault windows shaded and
//! vertical lines at declarations, aborts and incidents.

use crate::mission::MissionRun;
use crate::outcome::MissionEvent;
use crate::record::{EventKind, TrajectoryRow};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plumetrace_core::{BehaviourKind, Heading, PlannerEvent, Vec2};
use plumetrace_guidance::OpArea;
use plumetrace_sim::{Incident, WorldEvent};
use std::collections::BTreeMap;
use std::ops::Range;

/// The source map's entropy in the reading panel.
const ENTROPY_LINE: RGBColor = RGBColor(40, 120, 60);

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

/// The corner of the map panel where a box of `px` pixels hides the fewest of `points` (data
/// coordinates over `x` x `y` drawn on a panel of `panel_px`), lower right on ties; corners in
/// `taken` are not considered (all four taken: lower right).
fn emptiest_corner(
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
enum Corner {
    LowerRight,
    UpperRight,
    LowerLeft,
    UpperLeft,
}

impl Corner {
    /// In the order ties are broken.
    const ALL: [Corner; 4] = [
        Corner::LowerRight,
        Corner::UpperRight,
        Corner::LowerLeft,
        Corner::UpperLeft,
    ];

    fn right(self) -> bool {
        matches!(self, Corner::LowerRight | Corner::UpperRight)
    }

    fn upper(self) -> bool {
        matches!(self, Corner::UpperRight | Corner::UpperLeft)
    }

    /// The box `fx` x `fy` (data units) in this corner of `x` x `y`.
    fn box_in(self, x: &Range<f64>, y: &Range<f64>, fx: f64, fy: f64) -> (Range<f64>, Range<f64>) {
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

    fn position(self) -> SeriesLabelPosition {
        match self {
            Corner::LowerRight => SeriesLabelPosition::LowerRight,
            Corner::UpperRight => SeriesLabelPosition::UpperRight,
            Corner::LowerLeft => SeriesLabelPosition::LowerLeft,
            Corner::UpperLeft => SeriesLabelPosition::UpperLeft,
        }
    }
}

/// Kelp.
const OBSTACLE_FILL: RGBColor = RGBColor(90, 160, 90);
/// Virtual paths and reference targets.
const AVOID_MARK: RGBColor = RGBColor(170, 0, 140);
/// Detection ticks (drawn at 60 % opacity).
const DETECTION_MARK: RGBColor = RGBColor(120, 0, 0);
/// The underlay of the track flown during a sensor fault, and fault windows in the reading panel.
const FAULT_FILL: RGBColor = RGBColor(255, 196, 0);
/// Cage aborts and other aborts.
const ABORT_MARK: RGBColor = RGBColor(225, 0, 0);
/// Lost points.
const LOST_MARK: RGBColor = RGBColor(230, 120, 0);
/// True sources.
const SOURCE_MARK: RGBColor = RGBColor(0, 140, 60);
/// True tracks.
const TRUE_TRACK: RGBColor = RGBColor(135, 135, 135);
/// The true track outside the op-area.
const OUTSIDE_TRACK: RGBColor = RGBColor(60, 60, 60);
/// The reading of a lone vehicle.
const READING_LINE: RGBColor = RGBColor(50, 50, 50);

/// Track colours, one per vehicle (cycled).
const TRACK_COLOURS: [RGBColor; 6] = [
    RGBColor(20, 60, 160),
    RGBColor(150, 40, 150),
    RGBColor(0, 120, 120),
    RGBColor(160, 90, 0),
    RGBColor(90, 90, 200),
    RGBColor(120, 40, 40),
];

/// Detection ticks: at most one per this many seconds of each vehicle's mission.
pub const DETECTION_GAP_S: f64 = 2.0;
/// The figure's width, px.
const WIDTH_PX: u32 = 900;
/// The map's plotting area is at least this high, px (the map's extent grows along y to keep
/// one scale).
const MAP_MIN_PX: f64 = 300.0;
/// And at most this high, px (the extent grows along x).
const MAP_MAX_PX: f64 = 1200.0;
/// The reading panel's plotting height, px.
const READING_PX: u32 = 150;
/// One vehicle's behaviour strip in the reading panel, px.
const STRIP_PX: u32 = 16;
/// The legend's font size, px (as given to plotters).
const LEGEND_FONT_PX: f64 = 12.0;
/// The time labels' font size, px.
const TIME_FONT_PX: f64 = 12.0;

/// A stretch of a track flown under one behaviour (`None`: no planner), as plot points.
type BehaviourRun = (Option<BehaviourKind>, Vec<(f64, f64)>);
/// A line from one point to another, data coordinates.
type Segment = [(f64, f64); 2];

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
        BehaviourKind::Infotaxis => RGBColor(110, 140, 20),
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
        BehaviourKind::Infotaxis => "infotaxis",
        BehaviourKind::Done => "done",
    }
}

/// How a legend entry is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Icon {
    /// A line of a colour and width.
    Line(RGBColor, u32),
    /// A dashed line.
    Dashed(RGBColor, u32),
    /// A dotted thin line.
    Dotted(RGBColor),
    /// A wide translucent band (the fault underlay).
    Band(RGBColor),
    /// A filled patch at an opacity.
    Patch(RGBColor, f64),
    /// A short tick across a track line.
    Tick(RGBColor, f64),
    /// A time mark: a black tick across a grey line.
    TimeTick,
    /// An open circle.
    Ring(RGBColor),
    /// A filled triangle.
    Triangle(RGBColor),
    /// A filled dot.
    Dot(RGBColor),
    /// A filled diamond.
    Diamond(RGBColor),
    /// A filled square with a black border.
    Square(RGBColor),
    /// A bold x.
    Cross(RGBColor),
}

/// An [`Icon`] as the parts it is drawn from, in pixels from its left end (unused parts
/// transparent, which plotters skips): a polygon, three lines and a circle.
struct IconParts {
    polygon: (Vec<(i32, i32)>, ShapeStyle),
    lines: [(Vec<(i32, i32)>, ShapeStyle); 3],
    circle: ((i32, i32), u32, ShapeStyle),
}

impl IconParts {
    /// The parts of `icon`, shifted `dx` pixels right (on the map `dx = -8` centres the icon
    /// on its point).
    fn of(icon: Icon, dx: i32) -> Self {
        let none = TRANSPARENT.filled();
        let mut p = IconParts {
            polygon: (Vec::new(), none),
            lines: [(Vec::new(), none), (Vec::new(), none), (Vec::new(), none)],
            circle: ((0, 0), 0, none),
        };
        let rect = |x0: i32, x1: i32| vec![(x0, -5), (x1, -5), (x1, 5), (x0, 5)];
        match icon {
            Icon::Line(c, w) => p.lines[0] = (vec![(0, 0), (16, 0)], c.stroke_width(w)),
            Icon::Dashed(c, w) => p.lines[0] = (vec![(0, 0), (6, 0)], c.stroke_width(w)),
            Icon::Dotted(c) => {
                p.lines = [
                    (vec![(0, 0), (3, 0)], c.stroke_width(1)),
                    (vec![(6, 0), (9, 0)], c.stroke_width(1)),
                    (vec![(12, 0), (15, 0)], c.stroke_width(1)),
                ];
            }
            Icon::Band(c) => p.polygon = (rect(0, 16), c.mix(0.5).filled()),
            Icon::Patch(c, a) => p.polygon = (rect(0, 14), c.mix(a).filled()),
            Icon::Tick(c, a) => {
                p.lines = [
                    (vec![(0, 0), (16, 0)], TRUE_TRACK.stroke_width(1)),
                    (vec![(5, -5), (5, 5)], c.mix(a).stroke_width(1)),
                    (vec![(11, -5), (11, 5)], c.mix(a).stroke_width(1)),
                ];
            }
            Icon::TimeTick => {
                p.lines[0] = (vec![(0, 0), (16, 0)], TRUE_TRACK.stroke_width(2));
                p.lines[1] = (vec![(8, -5), (8, 5)], BLACK.stroke_width(2));
            }
            Icon::Ring(c) => p.circle = ((8, 0), 5, c.stroke_width(2)),
            Icon::Triangle(c) => p.polygon = (vec![(8, -6), (13, 4), (3, 4)], c.filled()),
            Icon::Dot(c) => p.circle = ((8, 0), 5, c.filled()),
            Icon::Diamond(c) => {
                p.polygon = (vec![(8, -5), (13, 0), (8, 5), (3, 0)], c.filled());
            }
            Icon::Square(c) => {
                p.polygon = (rect(3, 13), c.filled());
                p.lines[0] = (
                    vec![(3, -5), (13, -5), (13, 5), (3, 5), (3, -5)],
                    BLACK.stroke_width(1),
                );
            }
            Icon::Cross(c) => {
                p.lines[0] = (vec![(3, -5), (13, 5)], c.stroke_width(3));
                p.lines[1] = (vec![(3, 5), (13, -5)], c.stroke_width(3));
            }
        }
        let shift = |v: &mut Vec<(i32, i32)>| v.iter_mut().for_each(|q| q.0 += dx);
        shift(&mut p.polygon.0);
        p.lines.iter_mut().for_each(|(v, _)| shift(v));
        p.circle.0.0 += dx;
        p
    }
}

/// An icon as one plotters element at `$at` (any coordinate), shifted `$dx` pixels right.
macro_rules! icon_element {
    ($icon:expr, $at:expr, $dx:expr) => {{
        let IconParts {
            polygon,
            lines: [a, b, c],
            circle,
        } = IconParts::of($icon, $dx);
        EmptyElement::at($at)
            + Polygon::new(polygon.0, polygon.1)
            + PathElement::new(a.0, a.1)
            + PathElement::new(b.0, b.1)
            + PathElement::new(c.0, c.1)
            + Circle::new(circle.0, circle.1, circle.2)
    }};
}

/// One row of the legend.
#[derive(Debug, Clone, PartialEq)]
struct LegendEntry {
    label: String,
    icon: Icon,
}

/// What stopped or aborted a vehicle, for its marker.
#[derive(Debug, Clone, Copy, PartialEq)]
enum MarkKind {
    /// The cage aborted the mission with the estimate this far outside the op-area, m.
    CageAbort { outside_m: f64 },
    /// The planner aborted for another reason.
    Aborted,
    /// The world stopped the vehicle.
    Incident(Incident),
}

impl MarkKind {
    fn legend(self) -> &'static str {
        match self {
            MarkKind::CageAbort { .. } => "cage abort (true position)",
            MarkKind::Aborted => "planner aborted (true position)",
            MarkKind::Incident(_) => "incident (true position)",
        }
    }

    fn icon(self) -> Icon {
        match self {
            MarkKind::CageAbort { .. } => Icon::Square(ABORT_MARK),
            MarkKind::Aborted => Icon::Square(RGBColor(255, 150, 150)),
            MarkKind::Incident(_) => Icon::Cross(BLACK),
        }
    }

    /// What the marker's label says.
    fn text(self, t_s: f64) -> String {
        let what = match self {
            MarkKind::CageAbort { outside_m } => {
                format!("cage abort, {outside_m:.0} m outside")
            }
            MarkKind::Aborted => "planner aborted".to_string(),
            MarkKind::Incident(Incident::LeftDomain) => "left the domain".to_string(),
            MarkKind::Incident(Incident::Collided) => "collided with an obstacle".to_string(),
        };
        format!("{what} ({:.1} min)", t_s / 60.0)
    }

    /// The word at its line in the reading panel.
    fn short(self) -> &'static str {
        match self {
            MarkKind::CageAbort { .. } => "cage abort",
            MarkKind::Aborted => "aborted",
            MarkKind::Incident(Incident::LeftDomain) => "left domain",
            MarkKind::Incident(Incident::Collided) => "collided",
        }
    }
}

/// An abort or incident of a vehicle, at its true position then.
#[derive(Debug, Clone, PartialEq)]
struct EventMark {
    t_s: f64,
    vehicle: u32,
    pos: (f64, f64),
    kind: MarkKind,
    /// The label's upper left corner, px from the marker (right, down).
    label_px: (i32, i32),
}

/// A time mark on a track.
#[derive(Debug, Clone, PartialEq)]
struct TimeMark {
    tick: Segment,
    label_at: (f64, f64),
    label: String,
}

/// What is drawn of one vehicle.
#[derive(Debug, Clone, PartialEq)]
struct VehicleLayer {
    vehicle: u32,
    /// The vehicle's own colour (its track with several vehicles, its reading line).
    colour: RGBColor,
    truth: Vec<(f64, f64)>,
    /// The estimated track in runs under one behaviour.
    runs: Vec<BehaviourRun>,
    /// The track flown during each fault window, estimated and true (index into the vehicle's
    /// faults).
    faults: Vec<(usize, Vec<(f64, f64)>)>,
    /// The true track outside the op-area, in pieces.
    outside: Vec<Vec<(f64, f64)>>,
    /// Where a position fix moved the estimate (from, to) and when, s.
    jumps: Vec<(Segment, f64)>,
    detections: Vec<Segment>,
    times: Vec<TimeMark>,
}

/// Everything the map shows, in data coordinates, and where it goes.
#[derive(Debug, Clone, PartialEq)]
struct MapLayout {
    x: Range<f64>,
    y: Range<f64>,
    /// Plotting area, px.
    plot_px: (u32, u32),
    /// The map panel's height, px.
    map_h_px: u32,
    /// Metres per pixel, the same along x and y.
    m_per_px: f64,
    /// Multi-vehicle: tracks in the vehicles' colours.
    multi: bool,
    plume: Vec<([(f64, f64); 2], RGBColor)>,
    obstacles: Vec<Vec<(f64, f64)>>,
    layers: Vec<VehicleLayer>,
    time_step_min: f64,
    /// Obstacle avoidance: each virtual path from where the obstacle was sensed, its course
    /// and its last reference target.
    virtual_paths: Vec<(Vec2, Heading, Vec2)>,
    targets: Vec<(f64, f64)>,
    lost: Vec<(f64, f64)>,
    declared: Vec<(f64, f64)>,
    marks: Vec<EventMark>,
    legend: Vec<LegendEntry>,
    /// The legend's corner of the map (`None`: below the map).
    legend_corner: Option<Corner>,
    /// The flow arrow and scale bar: corner, size in px, scale bar length in m.
    key_corner: Corner,
    key_px: (u32, u32),
    scale_m: f64,
}

/// Whether the estimate jumped from row `a` to the next row `b` (a position fix): it moved
/// `min_m` more than three times what the vehicle truly moved.
fn jumped(a: &TrajectoryRow, b: &TrajectoryRow, min_m: f64) -> bool {
    match (a.est_x_m.zip(a.est_y_m), b.est_x_m.zip(b.est_y_m)) {
        (Some(p), Some(q)) => {
            let est = (q.0 - p.0).hypot(q.1 - p.1);
            let truth = (b.true_x_m - a.true_x_m).hypot(b.true_y_m - a.true_y_m);
            est > min_m + 3.0 * truth
        }
        _ => false,
    }
}

/// A vehicle's estimated track in runs under one behaviour (each run ends on the next one's
/// first point so that the track stays joined), broken where the estimate jumped by `min_m`
/// or more; and the jumps (from, to) with their times, s.
fn est_track(rows: &[&TrajectoryRow], min_m: f64) -> (Vec<BehaviourRun>, Vec<(Segment, f64)>) {
    let mut runs: Vec<BehaviourRun> = Vec::new();
    let mut jumps: Vec<(Segment, f64)> = Vec::new();
    let mut prev: Option<(&TrajectoryRow, (f64, f64))> = None;
    for &r in rows {
        let Some(p) = r.est_x_m.zip(r.est_y_m) else {
            continue;
        };
        let jump = prev.is_some_and(|(q, _)| jumped(q, r, min_m));
        if let (true, Some((_, q))) = (jump, prev) {
            jumps.push(([q, p], r.t_s));
        }
        prev = Some((r, p));
        match runs.last_mut() {
            Some((b, pts)) if *b == r.behaviour && !jump => pts.push(p),
            last => {
                if let (Some((_, pts)), false) = (last, jump) {
                    pts.push(p);
                }
                runs.push((r.behaviour, vec![p]));
            }
        }
    }
    (runs, jumps)
}

/// A track point: the estimate when the vehicle has one, else the true position.
fn track_pos(r: &TrajectoryRow) -> (f64, f64) {
    r.est_x_m.zip(r.est_y_m).unwrap_or((r.true_x_m, r.true_y_m))
}

/// The pieces of a true track outside `area`.
fn outside_pieces(rows: &[&TrajectoryRow], area: &OpArea) -> Vec<Vec<(f64, f64)>> {
    let mut pieces: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut was_out = false;
    for r in rows {
        let p = (r.true_x_m, r.true_y_m);
        let out = !area.contains(Vec2::new(p.0, p.1));
        match (out, was_out, pieces.last_mut()) {
            (true, true, Some(piece)) => piece.push(p),
            (true, _, _) => pieces.push(vec![p]),
            _ => {}
        }
        was_out = out;
    }
    pieces.retain(|p| p.len() > 1);
    pieces
}

/// Each vehicle's rows in time order.
fn rows_by_vehicle(run: &MissionRun) -> BTreeMap<u32, Vec<&TrajectoryRow>> {
    let mut by: BTreeMap<u32, Vec<&TrajectoryRow>> = BTreeMap::new();
    for r in &run.trajectory {
        by.entry(r.vehicle).or_default().push(r);
    }
    by
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
            PlannerEvent::LostPoint { pos_m }
            | PlannerEvent::ReferenceTarget { pos_m }
            | PlannerEvent::Declared { pos_m, .. },
        ) = &e.event
        {
            b.add(pos_m.x, pos_m.y);
        }
    }
    if b.x0 > b.x1 {
        return (-50.0..50.0, -50.0..50.0);
    }
    let pad = (0.05 * (b.x1 - b.x0).max(b.y1 - b.y0)).max(5.0);
    (b.x0 - pad..b.x1 + pad, b.y0 - pad..b.y1 + pad)
}

/// Grows `x` or `y` about its centre so that a plotting area `plot_w_px` wide and between
/// `min_h_px` and `max_h_px` high shows both at one scale; the ranges and the height, px.
fn fit_aspect(
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
fn map_overhead_px(width_px: u32, title: &str) -> Result<(u32, u32), String> {
    let mut scratch = String::new();
    let (w, h) = {
        let area = SVGBackend::with_string(&mut scratch, (width_px, 1000)).into_drawing_area();
        let chart = map_chart(&area, title, 0.0..1.0, 0.0..1.0)?;
        chart.plotting_area().dim_in_pixel()
    };
    Ok((width_px.saturating_sub(w), 1000u32.saturating_sub(h)))
}

/// Minutes between time marks: the shortest of 1, 2, 5, 10, 15, 20, 30, 60 min and longer
/// that gives at most 12 marks over `duration_s`.
fn time_step_min(duration_s: f64) -> f64 {
    const STEPS_MIN: [f64; 12] = [
        1.0, 2.0, 5.0, 10.0, 15.0, 20.0, 30.0, 60.0, 120.0, 240.0, 480.0, 960.0,
    ];
    let minutes = duration_s / 60.0;
    STEPS_MIN
        .into_iter()
        .find(|s| minutes / s <= 12.0)
        .unwrap_or(1920.0)
}

/// A round scale-bar length, m: 1, 2 or 5 times a power of ten, at most a fifth of `width_m`.
fn scale_bar_m(width_m: f64) -> f64 {
    let target = (width_m / 5.0).max(1e-3);
    let p = 10f64.powf(target.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|k| k * p)
        .find(|&l| l <= target)
        .unwrap_or(p)
}

/// Points no closer than `min_m` to the last one kept; the last point is always kept.
fn thin(points: &[(f64, f64)], min_m: f64) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    for (k, &p) in points.iter().enumerate() {
        let far = out
            .last()
            .is_none_or(|q| (p.0 - q.0).hypot(p.1 - q.1) >= min_m);
        if far || k + 1 == points.len() {
            out.push(p);
        }
    }
    out
}

/// The unit direction of the track at row `i`, over `k` rows each way (the heading when the
/// track stands still), and its left normal.
fn track_dir(rows: &[&TrajectoryRow], i: usize, k: usize) -> (Vec2, Vec2) {
    let (a, b) = (
        track_pos(rows[i.saturating_sub(k)]),
        track_pos(rows[(i + k).min(rows.len() - 1)]),
    );
    let d = Vec2::new(b.0 - a.0, b.1 - a.1);
    let n = d.norm();
    let d = if n > 1e-9 && n.is_finite() {
        d / n
    } else {
        Heading::from_deg(rows[i].heading_deg).unit()
    };
    (d, Vec2::new(-d.y, d.x))
}

/// Rows spanning about a second.
fn rows_per_s(rows: &[&TrajectoryRow]) -> usize {
    match (rows.first(), rows.last()) {
        (Some(a), Some(b)) if rows.len() > 1 && b.t_s > a.t_s => {
            let dt = (b.t_s - a.t_s) / (rows.len() - 1) as f64;
            ((1.0 / dt).round() as usize).max(1)
        }
        _ => 1,
    }
}

/// Detections as ticks across the track, `half_m` to each side: at most one per `gap_s`, and
/// none closer than `min_m` to the last one (a vehicle standing still).
fn detection_ticks(rows: &[&TrajectoryRow], gap_s: f64, half_m: f64, min_m: f64) -> Vec<Segment> {
    let k = rows_per_s(rows);
    let mut out = Vec::new();
    let mut last: Option<(f64, (f64, f64))> = None;
    for (i, r) in rows.iter().enumerate().filter(|(_, r)| r.detection) {
        let p = track_pos(r);
        if let Some((t, q)) = last
            && (r.t_s < t + gap_s - 1e-9 || (p.0 - q.0).hypot(p.1 - q.1) < min_m)
        {
            continue;
        }
        last = Some((r.t_s, p));
        let (_, n) = track_dir(rows, i, k);
        out.push([
            (p.0 - n.x * half_m, p.1 - n.y * half_m),
            (p.0 + n.x * half_m, p.1 + n.y * half_m),
        ]);
    }
    out
}

/// Time marks every `step_min` minutes along a track: ticks `half_m` to each side, labels
/// `label_m` to the left of the track; none closer than `min_m` to the last (a vehicle standing
/// still).
fn time_marks(
    rows: &[&TrajectoryRow],
    step_min: f64,
    half_m: f64,
    label_m: f64,
    min_m: f64,
) -> Vec<TimeMark> {
    let Some(end) = rows.last() else {
        return Vec::new();
    };
    let k = rows_per_s(rows);
    let mut out: Vec<TimeMark> = Vec::new();
    let mut last: Option<(f64, f64)> = None;
    let n_max = (end.t_s / (step_min * 60.0) + 1e-9).floor();
    let n_max = if n_max.is_finite() {
        n_max.max(0.0) as u32
    } else {
        0
    };
    for n in 1..=n_max {
        let t = f64::from(n) * step_min * 60.0;
        let i = rows
            .partition_point(|r| r.t_s < t - 1e-6)
            .min(rows.len() - 1);
        let p = track_pos(rows[i]);
        if last.is_some_and(|q| (p.0 - q.0).hypot(p.1 - q.1) < min_m) {
            continue;
        }
        last = Some(p);
        let (_, nrm) = track_dir(rows, i, k);
        out.push(TimeMark {
            tick: [
                (p.0 - nrm.x * half_m, p.1 - nrm.y * half_m),
                (p.0 + nrm.x * half_m, p.1 + nrm.y * half_m),
            ],
            label_at: (p.0 + nrm.x * label_m, p.1 + nrm.y * label_m),
            label: format!("{:.0} min", t / 60.0),
        });
    }
    out
}

/// The row of a vehicle at (or just after) `t_s`.
fn row_at<'a>(rows: &[&'a TrajectoryRow], t_s: f64) -> Option<&'a TrajectoryRow> {
    let i = rows.partition_point(|r| r.t_s < t_s - 1e-6);
    rows.get(i.min(rows.len().saturating_sub(1))).copied()
}

/// Aborts and incidents, each at the vehicle's true position then; a planner abort in the
/// step of a cage abort is the cage abort.
fn event_marks(run: &MissionRun, rows: &BTreeMap<u32, Vec<&TrajectoryRow>>) -> Vec<EventMark> {
    let cage: Vec<(u32, f64)> = run
        .events
        .iter()
        .filter(|e| matches!(e.event, EventKind::Planner(PlannerEvent::CageAbort { .. })))
        .map(|e| (e.vehicle, e.t_s))
        .collect();
    run.events
        .iter()
        .filter_map(|e| {
            let kind = match &e.event {
                EventKind::Planner(PlannerEvent::CageAbort { distance_outside_m }) => {
                    MarkKind::CageAbort {
                        outside_m: *distance_outside_m,
                    }
                }
                EventKind::Mission(MissionEvent::PlannerAborted)
                    if !cage
                        .iter()
                        .any(|&(v, t)| v == e.vehicle && (t - e.t_s).abs() <= 1.0) =>
                {
                    MarkKind::Aborted
                }
                EventKind::World(WorldEvent::Incident { what }) => MarkKind::Incident(*what),
                _ => return None,
            };
            let r = row_at(rows.get(&e.vehicle)?, e.t_s)?;
            Some(EventMark {
                t_s: e.t_s,
                vehicle: e.vehicle,
                pos: (r.true_x_m, r.true_y_m),
                kind,
                label_px: (10, -8),
            })
        })
        .collect()
}

/// The part of `poly` inside the rectangle `x` x `y` (Sutherland-Hodgman).
fn clip_polygon(poly: &[(f64, f64)], x: &Range<f64>, y: &Range<f64>) -> Vec<(f64, f64)> {
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

/// The time-averaged plume as light cells over `x` x `y` (square-root scale, 24 shades; equal
/// neighbours along a row merged into one rectangle).
fn plume_cells(
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
type Raster<'a> = (f64, Vec2, f64, usize, usize, &'a [f32]);

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
fn posterior_snapshots(run: &MissionRun) -> Vec<(String, Raster<'_>)> {
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
fn raster_peak(r: &Raster<'_>) -> Vec2 {
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
fn hot_points(run: &MissionRun) -> Vec<(f64, f64)> {
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
fn posterior_cells(
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
fn raster_cells(
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

/// The legend's size in pixels as plotters lays it out (12 px font, 30 px for the icons, 10 px
/// margins).
fn legend_px(entries: &[LegendEntry]) -> (f64, f64) {
    if entries.is_empty() {
        return (0.0, 0.0);
    }
    // plotters' estimate for fonts it cannot measure: em = size / 1.24^2, 0.7 em a character.
    let em = LEGEND_FONT_PX / 1.24 / 1.24;
    let chars = entries
        .iter()
        .map(|e| e.label.chars().count())
        .max()
        .unwrap_or(0);
    let w = (em * 0.7 * chars as f64).round() + 30.0 + 20.0;
    let h = LEGEND_FONT_PX * 1.25 * (entries.len() - 1) as f64 + (em * 1.24).round() + 20.0;
    (w, h)
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

/// The vehicles with a planner and a recorded track: the reading panel's rows.
fn panel_vehicles(run: &MissionRun, rows: &BTreeMap<u32, Vec<&TrajectoryRow>>) -> Vec<u32> {
    rows.keys()
        .copied()
        .filter(|&v| {
            run.vehicles
                .get(v as usize)
                .is_some_and(|i| i.planner.is_some())
        })
        .collect()
}

/// The behaviour strip of a vehicle: each behaviour in control from when to when, s (none of
/// zero length).
fn behaviour_spans(rows: &[&TrajectoryRow]) -> Vec<(BehaviourKind, f64, f64)> {
    let mut out: Vec<(BehaviourKind, f64, f64)> = Vec::new();
    let mut cur: Option<(Option<BehaviourKind>, f64)> = None;
    for r in rows {
        match cur {
            Some((b, _)) if b == r.behaviour => {}
            _ => {
                if let Some((Some(b), t0)) = cur {
                    out.push((b, t0, r.t_s));
                }
                cur = Some((r.behaviour, r.t_s));
            }
        }
    }
    if let (Some((Some(b), t0)), Some(last)) = (cur, rows.last()) {
        out.push((b, t0, last.t_s));
    }
    out.retain(|(_, a, e)| e > a);
    out
}

/// Adds a row to the legend unless it is there already.
fn add(legend: &mut Vec<LegendEntry>, label: String, icon: Icon) {
    if !legend.iter().any(|e| e.label == label) {
        legend.push(LegendEntry { label, icon });
    }
}

/// Everything the map shows and where.
fn map_layout(
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
    title: &str,
) -> Result<MapLayout, String> {
    let (bx, by) = map_bounds(run);
    let multi = rows.len() > 1;
    let duration_s = rows
        .values()
        .filter_map(|r| r.last())
        .map(|r| r.t_s)
        .fold(0.0, f64::max);
    let step_min = time_step_min(duration_s);
    let marks = event_marks(run, rows);

    // What is drawn (independent of the scale), for the legend.
    let mut virtual_paths: Vec<(Vec2, Heading, Vec2)> = Vec::new();
    let mut targets: Vec<(f64, f64)> = Vec::new();
    let mut lost: Vec<(f64, f64)> = Vec::new();
    for e in &run.events {
        match &e.event {
            EventKind::Planner(PlannerEvent::AvoidStart { pos_m, course_deg }) => {
                virtual_paths.push((*pos_m, Heading::from_deg(*course_deg), *pos_m));
            }
            EventKind::Planner(PlannerEvent::ReferenceTarget { pos_m }) => {
                targets.push((pos_m.x, pos_m.y));
                if let Some((_, _, end)) = virtual_paths.last_mut() {
                    *end = *pos_m;
                }
            }
            EventKind::Planner(PlannerEvent::LostPoint { pos_m }) => lost.push((pos_m.x, pos_m.y)),
            _ => {}
        }
    }
    let declared: Vec<(f64, f64)> = run
        .summary
        .declarations
        .iter()
        .map(|d| (d.x_m, d.y_m))
        .collect();
    let in_fault = |vid: u32, rs: &[&TrajectoryRow], min_jump_m: f64| {
        let Some(info) = run.vehicles.get(vid as usize) else {
            return Vec::new();
        };
        info.faults
            .iter()
            .enumerate()
            .flat_map(|(k, f)| {
                let inside: Vec<&TrajectoryRow> = rs
                    .iter()
                    .copied()
                    .filter(|r| r.t_s >= f.start_s && r.t_s <= f.end_s)
                    .collect();
                let mut pieces: Vec<Vec<(f64, f64)>> = Vec::new();
                for (i, r) in inside.iter().enumerate() {
                    match pieces.last_mut() {
                        Some(piece) if !jumped(inside[i - 1], r, min_jump_m) => {
                            piece.push(track_pos(r));
                        }
                        _ => pieces.push(vec![track_pos(r)]),
                    }
                }
                // Where the vehicle truly was, too, when its track is the estimate.
                if inside.iter().any(|r| r.est_x_m.is_some()) {
                    pieces.push(inside.iter().map(|r| (r.true_x_m, r.true_y_m)).collect());
                }
                pieces
                    .into_iter()
                    .filter(|p| p.len() > 1)
                    .map(move |p| (k, p))
            })
            .collect::<Vec<(usize, Vec<(f64, f64)>)>>()
    };

    let mut legend: Vec<LegendEntry> = Vec::new();
    // The plume's cells over the bounds before the aspect is fitted: fitting only grows them.
    if !plume_cells(run, &bx, &by).is_empty() {
        add(
            &mut legend,
            "mean plume at vehicle altitude".into(),
            Icon::Patch(RGBColor(255, 170, 100), 1.0),
        );
    }
    if !posterior_cells(run, &bx, &by).is_empty() {
        add(
            &mut legend,
            "source map, log10 p (6 decades)".into(),
            Icon::Patch(RGBColor(35, 85, 185), 1.0),
        );
    }
    if run.op_area.len() > 1 {
        add(&mut legend, "op-area".into(), Icon::Dashed(BLACK, 2));
    }
    if run.subregions.iter().any(|r| r.len() > 1) {
        add(
            &mut legend,
            "subregion".into(),
            Icon::Dashed(RGBColor(120, 120, 120), 1),
        );
    }
    if run.obstacles.iter().any(|o| {
        clip_polygon(&o.iter().map(|v| (v.x, v.y)).collect::<Vec<_>>(), &bx, &by).len() > 2
    }) {
        add(
            &mut legend,
            "obstacle (kelp)".into(),
            Icon::Patch(OBSTACLE_FILL, 0.55),
        );
    }
    if rows.values().any(|r| r.len() > 1) {
        add(
            &mut legend,
            if multi { "true tracks" } else { "true track" }.into(),
            Icon::Line(TRUE_TRACK, 1),
        );
    }
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
    if outside.values().any(|p| !p.is_empty()) {
        add(
            &mut legend,
            "true track outside the op-area".into(),
            Icon::Line(OUTSIDE_TRACK, 2),
        );
    }
    // Estimated tracks: by vehicle (several) or by behaviour (one); a run counts when it
    // joins two different points.
    let moves = |pts: &[(f64, f64)]| pts.iter().any(|p| *p != pts[0]);
    let mut has_jumps = false;
    for (n, (&vid, rs)) in rows.iter().enumerate() {
        let colour = TRACK_COLOURS[n % TRACK_COLOURS.len()];
        let (runs, _) = est_track(rs, f64::INFINITY);
        // Jumps of 5 m or more may be drawn (those shorter than 10 px are not).
        has_jumps |= !est_track(rs, 5.0).1.is_empty();
        let info = run.vehicles.get(vid as usize);
        for (b, _) in runs.iter().filter(|(_, p)| moves(p)) {
            match (b, info) {
                (Some(b), _) if !multi => add(
                    &mut legend,
                    format!("track: {}", behaviour_label(*b)),
                    Icon::Line(behaviour_colour(*b), 2),
                ),
                (_, Some(v)) if multi => add(
                    &mut legend,
                    format!(
                        "{} ({}) estimated track",
                        v.name,
                        v.planner.map_or("no planner", |k| k.name())
                    ),
                    Icon::Line(colour, 2),
                ),
                _ => add(
                    &mut legend,
                    "track (navigation estimate)".into(),
                    Icon::Line(colour, 2),
                ),
            }
        }
    }
    // The reading panel's behaviour strips: the colours the track does not explain (with
    // several vehicles, all of them).
    let mut seen = std::collections::BTreeSet::new();
    for v in &panel_vehicles(run, rows) {
        if let Some(rs) = rows.get(v) {
            seen.extend(behaviour_spans(rs).into_iter().map(|(b, _, _)| b));
        }
    }
    for b in BehaviourKind::ALL.into_iter().filter(|b| seen.contains(b)) {
        let on_track = format!("track: {}", behaviour_label(b));
        if multi || !legend.iter().any(|e| e.label == on_track) {
            add(
                &mut legend,
                format!("behaviour: {}", behaviour_label(b)),
                Icon::Patch(behaviour_colour(b), 1.0),
            );
        }
    }
    let mut faults_drawn: Vec<(u32, usize)> = rows
        .iter()
        .flat_map(|(&vid, rs)| {
            in_fault(vid, rs, f64::INFINITY)
                .into_iter()
                .map(move |(k, _)| (vid, k))
        })
        .collect();
    faults_drawn.dedup();
    for &(vid, k) in &faults_drawn {
        if let Some(f) = run.vehicles.get(vid as usize).and_then(|v| v.faults.get(k)) {
            let label = if faults_drawn.len() == 1 {
                format!(
                    "fault {:.1}-{:.1} min: {}",
                    f.start_s / 60.0,
                    f.end_s / 60.0,
                    f.what
                )
            } else {
                format!("fault: {}", f.what)
            };
            add(&mut legend, label, Icon::Band(FAULT_FILL));
        }
    }
    if has_jumps {
        add(
            &mut legend,
            "navigation fix (the estimate jumps)".into(),
            Icon::Dotted(BLACK),
        );
    }
    if rows.values().flatten().any(|r| r.detection) {
        // (Thinned to one per DETECTION_GAP_S; the module's docs say so.)
        add(
            &mut legend,
            "detection".into(),
            Icon::Tick(DETECTION_MARK, 0.6),
        );
    }
    if rows
        .values()
        .filter_map(|r| r.last())
        .any(|r| r.t_s + 1e-6 >= step_min * 60.0)
    {
        add(
            &mut legend,
            format!("time along the track, every {step_min:.0} min"),
            Icon::TimeTick,
        );
    }
    if !virtual_paths.is_empty() {
        add(
            &mut legend,
            "virtual path".into(),
            Icon::Dashed(AVOID_MARK, 1),
        );
    }
    if !targets.is_empty() {
        add(
            &mut legend,
            "reference target".into(),
            Icon::Diamond(AVOID_MARK),
        );
    }
    if !lost.is_empty() {
        add(&mut legend, "lost point".into(), Icon::Ring(LOST_MARK));
    }
    if !run.sources.is_empty() {
        add(
            &mut legend,
            "true source".into(),
            Icon::Triangle(SOURCE_MARK),
        );
    }
    if !declared.is_empty() {
        add(&mut legend, "declared source".into(), Icon::Dot(BLACK));
    }
    for m in &marks {
        add(&mut legend, m.kind.legend().into(), m.kind.icon());
    }

    // The scale: one in x and y. The legend goes into a corner of the map (made tall enough
    // for it) where it hides nothing; with no such corner, below the map.
    let (over_w, over_h) = map_overhead_px(WIDTH_PX, title)?;
    let plot_w = f64::from(WIDTH_PX - over_w);
    let (lw, lh) = legend_px(&legend);
    let mut marked: Vec<(f64, f64)> = rows
        .values()
        .flat_map(|rs| rs.iter().step_by(5))
        .flat_map(|r| [Some((r.true_x_m, r.true_y_m)), r.est_x_m.zip(r.est_y_m)])
        .flatten()
        .collect();
    marked.extend(&lost);
    marked.extend(&declared);
    marked.extend(run.sources.iter().map(|s| (s.x, s.y)));
    marked.extend(marks.iter().map(|k| k.pos));
    // Nor the plume's core or the source map's likely cells.
    marked.extend(hot_points(run));
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
    let (x, y, plot_h) = match inside {
        Some(_) => (x, y, plot_h),
        None => fit_aspect(bx, by, plot_w, MAP_MIN_PX, MAP_MAX_PX),
    };
    let m = (x.end - x.start) / plot_w;

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
            faults: in_fault(vid, rs, (10.0 * m).max(5.0))
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
    // Jumps too short to see are not drawn, so not listed (the legend only shrinks).
    if layers.iter().all(|l| l.jumps.is_empty()) {
        legend.retain(|e| e.icon != Icon::Dotted(BLACK));
    }
    // Time labels that would overlap an earlier one are left out (their ticks stay).
    let mut boxes: Vec<(f64, f64, f64)> = Vec::new();
    for l in &mut layers {
        for t in &mut l.times {
            let half_w = (text_px(&t.label, TIME_FONT_PX) / 2.0 + 2.0) * m;
            let half_h = 7.0 * m;
            let (cx, cy) = t.label_at;
            if boxes
                .iter()
                .any(|&(x, y, w)| (cx - x).abs() < half_w + w && (cy - y).abs() < 2.0 * half_h)
            {
                t.label.clear();
            } else {
                boxes.push((cx, cy, half_w));
            }
        }
    }
    let mut plume = plume_cells(run, &x, &y);
    plume.extend(posterior_cells(run, &x, &y));
    let obstacles = run
        .obstacles
        .iter()
        .map(|o| clip_polygon(&o.iter().map(|v| (v.x, v.y)).collect::<Vec<_>>(), &x, &y))
        .filter(|o| o.len() > 2)
        .collect();

    // What the legend and the key could hide.
    let mut points: Vec<(f64, f64)> = Vec::new();
    for l in &layers {
        points.extend(&l.truth);
        points.extend(l.runs.iter().flat_map(|(_, p)| p.iter().copied()));
        points.extend(l.outside.iter().flatten());
        points.extend(l.times.iter().map(|t| t.label_at));
    }
    points.extend(&lost);
    points.extend(&declared);
    points.extend(run.sources.iter().map(|s| (s.x, s.y)));
    points.extend(marks.iter().map(|k| k.pos));
    let mut marks = marks;
    for k in &mut marks {
        let w = text_px(&k.kind.text(k.t_s), 12.0).round() as i32 + 4;
        k.label_px = label_place(k.pos, (w, 16), &points, (&x, &y), m);
    }
    let panel_px = (plot_w, f64::from(plot_h));
    let legend_corner = inside;
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
    Ok(MapLayout {
        map_h_px: plot_h + over_h,
        plot_px: (WIDTH_PX - over_w, plot_h),
        x,
        y,
        m_per_px: m,
        multi,
        plume,
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

/// How wide `text` in a sans-serif font of `font_px` (as given to plotters, which writes it
/// 1.24 times smaller into the SVG) is drawn, px: about 0.6 em a character (plotters cannot
/// measure SVG text).
fn text_px(text: &str, font_px: f64) -> f64 {
    0.6 * font_px / 1.24 * text.chars().count() as f64
}

/// The key's words about the mean flow at the source, and the flow's direction (a unit vector;
/// `None`: too weak or unknown to draw).
fn flow_words(flow: Vec2) -> (String, Option<Vec2>) {
    let speed = flow.norm();
    if speed.is_finite() && speed >= 0.005 {
        let to_deg = flow.x.atan2(flow.y).to_degrees().rem_euclid(360.0);
        (
            format!("mean flow {speed:.2} m/s to {to_deg:.0}°"),
            Some(flow / speed),
        )
    } else if speed.is_finite() {
        ("mean flow below 0.01 m/s".to_string(), None)
    } else {
        ("mean flow unknown".to_string(), None)
    }
}

/// The legend below the map: columns, rows and height, px (no rows: none).
fn legend_band(lay: &MapLayout) -> (usize, usize, u32) {
    if lay.legend_corner.is_some() || lay.legend.is_empty() {
        return (0, 0, 0);
    }
    let col_px = lay
        .legend
        .iter()
        .map(|e| text_px(&e.label, LEGEND_FONT_PX))
        .fold(0.0, f64::max)
        + 30.0
        + 16.0;
    let avail = f64::from(WIDTH_PX) - 72.0 - 25.0;
    let cols = ((avail / col_px).floor() as usize).clamp(1, 4);
    let rows = lay.legend.len().div_ceil(cols);
    (cols, rows, 16 * rows as u32 + 16)
}

/// The legend below the map, in columns filled downwards, aligned with the map's plotting
/// area.
fn draw_legend_band<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    lay: &MapLayout,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let (cols, rows, h) = legend_band(lay);
    if rows == 0 {
        return Ok(());
    }
    let (x0, x1) = (72, WIDTH_PX as i32 - 25);
    area.draw(&Rectangle::new(
        [(x0, 2), (x1, h as i32 - 4)],
        BLACK.stroke_width(1),
    ))
    .map_err(err)?;
    let col_w = (x1 - x0 - 10) / cols as i32;
    let style = label_style(
        LEGEND_FONT_PX as u32,
        BLACK,
        Pos::new(HPos::Left, VPos::Center),
    );
    for (k, e) in lay.legend.iter().enumerate() {
        let (c, r) = ((k / rows) as i32, (k % rows) as i32);
        let (x, y) = (x0 + 10 + c * col_w, 12 + 16 * r);
        area.draw(&icon_element!(e.icon, (x, y), 0)).map_err(err)?;
        area.draw(&Text::new(e.label.clone(), (x + 26, y), style.clone()))
            .map_err(err)?;
    }
    Ok(())
}

/// The reading panel's height, px, for `n` vehicles (0: no panel).
fn panel_h_px(n: usize) -> u32 {
    if n == 0 {
        0
    } else {
        READING_PX + 20 + STRIP_PX * n as u32 + 56
    }
}

/// The figure as an SVG string.
pub fn mission_figure(run: &MissionRun, title: &str) -> Result<String, String> {
    let rows = rows_by_vehicle(run);
    let lay = map_layout(run, &rows, title)?;
    let panel = panel_vehicles(run, &rows);
    let (_, _, band_h) = legend_band(&lay);
    let snaps = posterior_snapshots(run);
    let snaps_h = if snaps.is_empty() { 0 } else { POSTERIOR_PX };
    let height = lay.map_h_px + band_h + snaps_h + panel_h_px(panel.len());
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH_PX, height)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let (top, rest) = root.split_vertically(lay.map_h_px);
        let (band, rest) = rest.split_vertically(band_h);
        let (maps, bottom) = rest.split_vertically(snaps_h);
        draw_map(&top, run, &lay, title)?;
        draw_legend_band(&band, &lay)?;
        if !snaps.is_empty() {
            draw_posteriors(&maps, run, &rows, &snaps)?;
        }
        if !panel.is_empty() {
            draw_panel(&bottom, run, &rows, &lay, &panel)?;
        }
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// The height of the row of source-map panels, px.
const POSTERIOR_PX: u32 = 300;

/// The source maps of `snaps` side by side, each zoomed on its most likely cell, the true
/// sources and the first declaration, with the estimated tracks over them.
fn draw_posteriors<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
    snaps: &[(String, Raster<'_>)],
) -> Result<(), String>
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
    for (panel, (title, r)) in panels.iter().zip(snaps) {
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
        let mut chart = map_chart(panel, title, x.clone(), y.clone())?;
        chart
            .draw_series(
                raster_cells(r, &x, &y)
                    .into_iter()
                    .map(|(b, col)| Rectangle::new(b, col.filled())),
            )
            .map_err(err)?;
        chart
            .draw_series(dashed(&run.op_area, BLACK, 1))
            .map_err(err)?;
        // The estimated tracks up to the map's time (outside the window: clipped by plotters).
        for rs in rows.values() {
            let pts: Vec<(f64, f64)> = rs
                .iter()
                .filter(|q| q.t_s <= r.0)
                .filter_map(|q| q.est_x_m.zip(q.est_y_m))
                .filter(|p| x.contains(&p.0) && y.contains(&p.1))
                .collect();
            chart
                .draw_series(std::iter::once(PathElement::new(
                    thin(&pts, 2.0 * half_x / pw),
                    RGBColor(70, 70, 70).mix(0.7).stroke_width(1),
                )))
                .map_err(err)?;
        }
        chart
            .draw_series(std::iter::once(Cross::new(
                (peak.x, peak.y),
                6,
                RGBColor(200, 0, 0).stroke_width(2),
            )))
            .map_err(err)?;
        chart
            .draw_series(
                run.sources
                    .iter()
                    .map(|s| TriangleMarker::new((s.x, s.y), 7, SOURCE_MARK.filled())),
            )
            .map_err(err)?;
        chart
            .draw_series(
                declared
                    .iter()
                    .map(|d| Circle::new((d.x, d.y), 5, BLACK.filled())),
            )
            .map_err(err)?;
        let (px0, _) = chart.plotting_area().get_pixel_range();
        let note = "+ most likely cell   \u{25b2} source   \u{25cf} declared";
        panel
            .draw(&Text::new(
                note,
                (px0.start + 4, h_px as i32 - 14),
                ("sans-serif", 11).into_font().color(&BLACK),
            ))
            .map_err(err)?;
    }
    Ok(())
}

/// Text of `px` pixels at a point, anchored by `pos`.
fn label_style(px: u32, colour: RGBColor, pos: Pos) -> TextStyle<'static> {
    ("sans-serif", px).into_font().color(&colour).pos(pos)
}

/// The map panel.
fn draw_map<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    run: &MissionRun,
    lay: &MapLayout,
    title: &str,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let mut chart = map_chart(area, title, lay.x.clone(), lay.y.clone())?;
    let m = lay.m_per_px;
    if !lay.plume.is_empty() {
        chart
            .draw_series(
                lay.plume
                    .iter()
                    .map(|(r, c)| Rectangle::new(*r, c.filled())),
            )
            .map_err(err)?;
    }
    chart
        .draw_series(
            lay.obstacles
                .iter()
                .map(|o| Polygon::new(o.clone(), OBSTACLE_FILL.mix(0.55).filled())),
        )
        .map_err(err)?;
    chart
        .draw_series(dashed(&run.op_area, BLACK, 2))
        .map_err(err)?;
    for r in &run.subregions {
        chart
            .draw_series(dashed(r, RGBColor(120, 120, 120), 1))
            .map_err(err)?;
    }
    // Under the tracks: the track flown during faults.
    for l in &lay.layers {
        chart
            .draw_series(l.faults.iter().map(|(_, pts)| {
                PathElement::new(pts.clone(), FAULT_FILL.mix(0.5).stroke_width(10))
            }))
            .map_err(err)?;
    }
    for l in &lay.layers {
        chart
            .draw_series(std::iter::once(PathElement::new(
                l.truth.clone(),
                TRUE_TRACK.stroke_width(1),
            )))
            .map_err(err)?;
    }
    for l in &lay.layers {
        chart
            .draw_series(l.runs.iter().map(|(b, pts)| {
                let c = match b {
                    Some(b) if !lay.multi => behaviour_colour(*b),
                    _ => l.colour,
                };
                PathElement::new(pts.clone(), c.stroke_width(2))
            }))
            .map_err(err)?;
    }
    for l in &lay.layers {
        chart
            .draw_series(
                l.outside
                    .iter()
                    .map(|p| PathElement::new(p.clone(), OUTSIDE_TRACK.stroke_width(2))),
            )
            .map_err(err)?;
    }
    // Position fixes: dotted from the estimate before to the estimate after.
    for l in &lay.layers {
        chart
            .draw_series(l.jumps.iter().flat_map(|&([a, b], _)| {
                let len = (b.0 - a.0).hypot(b.1 - a.1);
                // Dashes of 6 px, gaps of 4 px.
                let n = (len / (10.0 * m)).ceil().max(1.0) as usize;
                (0..n).map(move |k| {
                    let s = k as f64 / n as f64;
                    let e = (s + 0.6 / n as f64).min(1.0);
                    PathElement::new(
                        vec![
                            (a.0 + s * (b.0 - a.0), a.1 + s * (b.1 - a.1)),
                            (a.0 + e * (b.0 - a.0), a.1 + e * (b.1 - a.1)),
                        ],
                        BLACK.stroke_width(1),
                    )
                })
            }))
            .map_err(err)?;
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
            .map_err(err)?;
    }
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
                    .map_err(err)?;
            }
        }
    }
    for l in &lay.layers {
        chart
            .draw_series(
                l.detections
                    .iter()
                    .map(|s| PathElement::new(s.to_vec(), DETECTION_MARK.mix(0.6).stroke_width(1))),
            )
            .map_err(err)?;
    }
    for l in &lay.layers {
        chart
            .draw_series(
                l.times
                    .iter()
                    .map(|t| PathElement::new(t.tick.to_vec(), BLACK.stroke_width(2))),
            )
            .map_err(err)?;
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
            .map_err(err)?;
    }
    if !lay.virtual_paths.is_empty() {
        let segments: Vec<PathElement<(f64, f64)>> = lay
            .virtual_paths
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
        chart.draw_series(segments).map_err(err)?;
    }
    chart
        .draw_series(lay.targets.iter().map(|&(x, y)| {
            Polygon::new(
                vec![(x, y + 1.2), (x + 1.2, y), (x, y - 1.2), (x - 1.2, y)],
                AVOID_MARK.filled(),
            )
        }))
        .map_err(err)?;
    chart
        .draw_series(
            lay.lost
                .iter()
                .map(|&p| Circle::new(p, 5, LOST_MARK.stroke_width(2))),
        )
        .map_err(err)?;
    chart
        .draw_series(
            run.sources
                .iter()
                .map(|s| TriangleMarker::new((s.x, s.y), 9, SOURCE_MARK.filled())),
        )
        .map_err(err)?;
    chart
        .draw_series(
            lay.declared
                .iter()
                .map(|&p| Circle::new(p, 7, BLACK.filled())),
        )
        .map_err(err)?;
    for k in &lay.marks {
        let icon = k.kind.icon();
        let text = k.kind.text(k.t_s);
        let (ox, oy) = k.label_px;
        let w = text_px(&text, 12.0).round() as i32;
        let style = label_style(12, BLACK, Pos::new(HPos::Left, VPos::Center));
        chart
            .draw_series(std::iter::once(
                icon_element!(icon, k.pos, -8)
                    + Rectangle::new(
                        [(ox - 2, oy), (ox + w + 2, oy + 16)],
                        WHITE.mix(0.8).filled(),
                    )
                    + Text::new(text, (ox, oy + 8), style),
            ))
            .map_err(err)?;
    }
    draw_key(&mut chart, run, lay)?;
    for e in lay.legend.iter().filter(|_| lay.legend_corner.is_some()) {
        let icon = e.icon;
        chart
            .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
            .map_err(err)?
            .label(e.label.clone())
            .legend(move |p| icon_element!(icon, p, 0));
    }
    if let (Some(corner), false) = (lay.legend_corner, lay.legend.is_empty()) {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", LEGEND_FONT_PX))
            .position(corner.position())
            .draw()
            .map_err(err)?;
    }
    Ok(())
}

/// The key: the mean flow at the source as an arrow with its speed and direction, and a scale
/// bar, in a box in `lay.key_corner`.
fn draw_key<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    run: &MissionRun,
    lay: &MapLayout,
) -> Result<(), String>
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
        .map_err(err)?;
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
            .map_err(err)?;
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
        .map_err(err)?;
    Ok(())
}

/// A reading series thinned to the lowest and the highest reading of each of `columns` time
/// columns over `0..t_max` (in time order), so that spikes survive.
fn min_max_columns(points: &[(f64, f64)], t_max: f64, columns: usize) -> Vec<(f64, f64)> {
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

/// The reading panel: each vehicle's reading against time, the behaviour strips, fault windows
/// shaded, lines at declarations, aborts and incidents.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
    lay: &MapLayout,
    vehicles: &[u32],
) -> Result<(), String>
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
        .map_err(err)?;
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
        .map_err(err)?;
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
        .map_err(err)?;
    let cols = upper.dim_in_pixel().0 as usize;
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
            .map_err(err)?;
    }
    // The source map's entropy (a planner that keeps a map reports it), scaled to the panel's
    // height: 0 at the bottom, the largest reported value at the top.
    let entropy: Vec<(f64, f64)> = run
        .events
        .iter()
        .filter(|e| vehicles.contains(&e.vehicle))
        .filter_map(|e| match &e.event {
            crate::record::EventKind::Telemetry(plumetrace_core::Telemetry::SourceMap {
                entropy_bits,
                ..
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
            .map_err(err)?;
        chart
            .draw_series(std::iter::once(Text::new(
                format!("source map entropy (0-{h_max:.1} bits)"),
                (t_max_min * 0.01, y_hi * 0.99),
                ("sans-serif", 12).into_font().color(&ENTROPY_LINE),
            )))
            .map_err(err)?;
    }
    // Declarations, aborts and incidents.
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
        chart.draw_series(segs).map_err(err)?;
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
            .map_err(err)?;
    }

    // The behaviour strips, first vehicle on top.
    let mut strips = ChartBuilder::on(&lower)
        .margin_left(12)
        .margin_right(25)
        .margin_top(4)
        .margin_bottom(6)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t_max_min, 0.0..n as f64)
        .map_err(err)?;
    strips
        .configure_mesh()
        .disable_mesh()
        .disable_y_axis()
        .x_labels(12)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .x_desc("mission time (min)")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(err)?;
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
            .map_err(err)?;
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
            .map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mission::{FaultWindow, run_mission};
    use crate::record::EventRecord;
    use crate::summary::DeclarationRecord;
    use plumetrace_core::DeclarationKind;
    use plumetrace_scenario::{Origin, build, load_preset};

    /// The demo mission cut short: 600 s of spin-up, `limit_s` of mission, seed 3.
    fn demo(limit_s: f64) -> MissionRun {
        let mut cfg = load_preset("demo").unwrap();
        if let Some(m) = cfg.mission.as_mut() {
            m.spinup_s = m.spinup_s.min(600.0);
            m.time_limit_s = limit_s;
        }
        let sc = build(&cfg, &Origin::Preset("demo".into()), Some(3)).unwrap();
        run_mission(sc, &mut |_, _| {}).unwrap()
    }

    fn layout(run: &MissionRun) -> MapLayout {
        map_layout(run, &rows_by_vehicle(run), "test").unwrap()
    }

    fn labels(lay: &MapLayout) -> Vec<String> {
        lay.legend.iter().map(|e| e.label.clone()).collect()
    }

    /// A row of vehicle 0 at `t_s`, true and estimated position `(x, y)`.
    fn row(t_s: f64, x: f64, y: f64, detection: bool) -> TrajectoryRow {
        TrajectoryRow {
            t_s,
            vehicle: 0,
            true_x_m: x,
            true_y_m: y,
            true_z_m: 2.0,
            est_x_m: Some(x),
            est_y_m: Some(y),
            heading_deg: 90.0,
            speed_mps: 1.0,
            behaviour: Some(BehaviourKind::TrackIn),
            reading_v: 1.0,
            detection,
        }
    }

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
    fn time_marks_come_every_round_number_of_minutes() {
        // (mission, s; minutes between marks)
        let cases = [
            (240.0, 1.0),
            (720.0, 1.0),
            (900.0, 2.0),
            (2295.0, 5.0),
            (3600.0, 5.0),
            (4000.0, 10.0),
            (7200.0, 10.0),
            (7300.0, 15.0),
            (36000.0, 60.0),
        ];
        for (duration_s, step) in cases {
            let got = time_step_min(duration_s);
            assert_eq!(got, step, "{duration_s} s");
            let marks = (duration_s / 60.0 / got).floor();
            assert!(
                marks <= 12.0 && (duration_s < 1500.0 || marks >= 5.0),
                "{duration_s} s: {marks} marks"
            );
        }
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
    fn detection_ticks_are_thinned_to_one_per_gap() {
        // 100 s at 10 Hz, every reading a detection, moving east at 1 m/s.
        let moving: Vec<TrajectoryRow> = (0..1000)
            .map(|k| row(f64::from(k) * 0.1, f64::from(k) * 0.1, 0.0, true))
            .collect();
        let refs: Vec<&TrajectoryRow> = moving.iter().collect();
        let ticks = detection_ticks(&refs, DETECTION_GAP_S, 1.0, 0.5);
        assert!((45..=51).contains(&ticks.len()), "{}", ticks.len());
        // Across the track: a track along x gets ticks along y.
        for [a, b] in &ticks {
            assert!((a.0 - b.0).abs() < 1e-9 && ((a.1 - b.1).abs() - 2.0).abs() < 1e-9);
        }
        // Standing still: one tick.
        let still: Vec<TrajectoryRow> = (0..1000)
            .map(|k| row(f64::from(k) * 0.1, 5.0, 5.0, true))
            .collect();
        let refs: Vec<&TrajectoryRow> = still.iter().collect();
        assert_eq!(detection_ticks(&refs, DETECTION_GAP_S, 1.0, 0.5).len(), 1);
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
    fn the_legend_lists_only_what_is_drawn() {
        let mut run = demo(240.0);
        assert!(
            run.summary.declarations.is_empty(),
            "the short demo declares nothing"
        );
        let lay = layout(&run);
        let l = labels(&lay);
        assert!(!l.iter().any(|s| s == "declared source"), "{l:?}");
        assert!(l.iter().all(|s| !s.starts_with("fault")), "{l:?}");
        assert!(l.iter().all(|s| !s.contains("abort")), "{l:?}");
        let lost = run
            .events
            .iter()
            .any(|e| matches!(e.event, EventKind::Planner(PlannerEvent::LostPoint { .. })));
        assert_eq!(l.iter().any(|s| s == "lost point"), lost);
        let detected = run.trajectory.iter().any(|r| r.detection);
        assert_eq!(l.iter().any(|s| s == "detection"), detected);
        // Every behaviour in the legend colours a stretch of the drawn track.
        for b in BehaviourKind::ALL {
            let listed = l.contains(&format!("track: {}", behaviour_label(b)));
            let drawn = lay.layers[0]
                .runs
                .iter()
                .any(|(k, p)| *k == Some(b) && p.iter().any(|q| *q != p[0]));
            assert_eq!(listed, drawn, "{b:?}");
        }
        let svg = mission_figure(&run, "no declaration").unwrap();
        assert!(!svg.contains("declared source"));
        // A legend in the map has room there; one below the map has a place for every row.
        match lay.legend_corner {
            Some(_) => {
                let (_, h) = legend_px(&lay.legend);
                assert!(
                    f64::from(lay.plot_px.1) >= h,
                    "{} px for {h} px",
                    lay.plot_px.1
                );
            }
            None => {
                let (cols, rows, h) = legend_band(&lay);
                assert!(cols * rows >= lay.legend.len() && rows < lay.legend.len() + 1);
                assert!(h >= 16 * rows as u32);
            }
        }

        run.summary.declarations.push(DeclarationRecord {
            t_s: 200.0,
            vehicle: 0,
            x_m: 120.0,
            y_m: 0.0,
            source_x_m: 100.0,
            source_y_m: 0.0,
            error_m: 20.0,
            error_along_m: 20.0,
            error_cross_m: 0.0,
            rule: DeclarationKind::new("along_flow"),
        });
        let l = labels(&layout(&run));
        assert_eq!(l.iter().filter(|s| *s == "declared source").count(), 1);
        let svg = mission_figure(&run, "declared").unwrap();
        assert!(
            svg.contains("declared"),
            "the declaration's line in the reading panel"
        );
    }

    /// A 20 x 20 map of 5 m cells from (0, -50) peaked at cell `(i, j)`.
    fn raster_event(t_s: f64, i: usize, j: usize) -> EventRecord {
        let (nx, ny) = (20, 20);
        let log10_p = (0..nx * ny)
            .map(|k| {
                let (di, dj) = ((k % nx) as f32 - i as f32, (k / nx) as f32 - j as f32);
                -1.0 - 0.2 * (di * di + dj * dj)
            })
            .collect();
        EventRecord {
            t_s,
            vehicle: 0,
            event: EventKind::Telemetry(plumetrace_core::Telemetry::SourceMapRaster {
                origin_m: Vec2::new(0.0, -50.0),
                cell_m: 5.0,
                nx,
                ny,
                log10_p,
            }),
        }
    }

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
}
