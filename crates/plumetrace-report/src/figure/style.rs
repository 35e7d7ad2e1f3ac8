//! How the mission figure looks: its colours, sizes and fonts, the behaviours' colours and
//! names (the replay page uses them too), and the icons of legend entries and markers.

use plotters::prelude::*;
use plotters::style::text_anchor::Pos;
use plumetrace_core::BehaviourKind;

/// The source map's entropy in the reading panel.
pub(super) const ENTROPY_LINE: RGBColor = RGBColor(40, 120, 60);

/// Kelp.
pub(super) const OBSTACLE_FILL: RGBColor = RGBColor(90, 160, 90);
/// Virtual paths and reference targets.
pub(super) const AVOID_MARK: RGBColor = RGBColor(170, 0, 140);
/// Detection ticks (drawn at 60 % opacity).
pub(super) const DETECTION_MARK: RGBColor = RGBColor(120, 0, 0);
/// The underlay of the track flown during a sensor fault, and fault windows in the reading panel.
pub(super) const FAULT_FILL: RGBColor = RGBColor(255, 196, 0);
/// Cage aborts and other aborts.
pub(super) const ABORT_MARK: RGBColor = RGBColor(225, 0, 0);
/// Lost points.
pub(super) const LOST_MARK: RGBColor = RGBColor(230, 120, 0);
/// True sources.
pub(super) const SOURCE_MARK: RGBColor = RGBColor(0, 140, 60);
/// True tracks.
pub(super) const TRUE_TRACK: RGBColor = RGBColor(135, 135, 135);
/// The true track outside the op-area.
pub(super) const OUTSIDE_TRACK: RGBColor = RGBColor(60, 60, 60);
/// The reading of a lone vehicle.
pub(super) const READING_LINE: RGBColor = RGBColor(50, 50, 50);

/// Track colours, one per vehicle (cycled).
pub(super) const TRACK_COLOURS: [RGBColor; 6] = [
    RGBColor(20, 60, 160),
    RGBColor(150, 40, 150),
    RGBColor(0, 120, 120),
    RGBColor(160, 90, 0),
    RGBColor(90, 90, 200),
    RGBColor(120, 40, 40),
];

/// The figure's width, px.
pub(super) const WIDTH_PX: u32 = 900;
/// The map's plotting area is at least this high, px (the map's extent grows along y to keep
/// one scale).
pub(super) const MAP_MIN_PX: f64 = 300.0;
/// And at most this high, px (the extent grows along x).
pub(super) const MAP_MAX_PX: f64 = 1200.0;
/// The reading panel's plotting height, px.
pub(super) const READING_PX: u32 = 150;
/// One vehicle's behaviour strip in the reading panel, px.
pub(super) const STRIP_PX: u32 = 16;
/// The legend's font size, px (as given to plotters).
pub(super) const LEGEND_FONT_PX: f64 = 12.0;
/// The time labels' font size, px.
pub(super) const TIME_FONT_PX: f64 = 12.0;

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
pub(super) enum Icon {
    /// A line of a colour and width.
    Line(RGBColor, u32),
    /// A dashed line.
    Dashed(RGBColor, u32),
    /// A dotted thin line.
    Dotted(RGBColor),
    /// A wide translucent line (the fault underlay).
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
pub(super) struct IconParts {
    pub(super) polygon: (Vec<(i32, i32)>, ShapeStyle),
    pub(super) lines: [(Vec<(i32, i32)>, ShapeStyle); 3],
    pub(super) circle: ((i32, i32), u32, ShapeStyle),
}

impl IconParts {
    /// The parts of `icon`, shifted `dx` pixels right (on the map `dx = -8` centres the icon
    /// on its point).
    pub(super) fn of(icon: Icon, dx: i32) -> Self {
        let none = TRANSPARENT.filled();
        let mut p = IconParts {
            polygon: (Vec::new(), none),
            lines: [(Vec::new(), none), (Vec::new(), none), (Vec::new(), none)],
            circle: ((0, 0), 0, none),
        };
        let rect = |x0: i32, x1: i32| vec![(x0, -5), (x1, -5), (x1, 5), (x0, 5)];
        match icon {
            Icon::Line(c, w) => p.lines[0] = (vec![(0, 0), (16, 0)], c.stroke_width(w)),
            Icon::Dashed(c, w) => {
                p.lines[0] = (vec![(0, 0), (6, 0)], c.stroke_width(w));
                p.lines[1] = (vec![(10, 0), (16, 0)], c.stroke_width(w));
            }
            Icon::Dotted(c) => {
                p.lines = [
                    (vec![(0, 0), (3, 0)], c.stroke_width(1)),
                    (vec![(6, 0), (9, 0)], c.stroke_width(1)),
                    (vec![(12, 0), (15, 0)], c.stroke_width(1)),
                ];
            }
            Icon::Band(c) => p.lines[0] = (vec![(0, 0), (16, 0)], c.mix(0.5).stroke_width(10)),
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
        let $crate::figure::style::IconParts {
            polygon,
            lines: [a, b, c],
            circle,
        } = $crate::figure::style::IconParts::of($icon, $dx);
        ::plotters::prelude::EmptyElement::at($at)
            + ::plotters::prelude::Polygon::new(polygon.0, polygon.1)
            + ::plotters::prelude::PathElement::new(a.0, a.1)
            + ::plotters::prelude::PathElement::new(b.0, b.1)
            + ::plotters::prelude::PathElement::new(c.0, c.1)
            + ::plotters::prelude::Circle::new(circle.0, circle.1, circle.2)
    }};
}
pub(crate) use icon_element;

/// How wide `text` in a sans-serif font of `font_px` (as given to plotters, which writes it
/// 1.24 times smaller into the SVG) is drawn, px: about 0.6 em a character (plotters cannot
/// measure SVG text).
pub(super) fn text_px(text: &str, font_px: f64) -> f64 {
    0.6 * font_px / 1.24 * text.chars().count() as f64
}

/// Text of `px` pixels at a point, anchored by `pos`.
pub(super) fn label_style(px: u32, colour: RGBColor, pos: Pos) -> TextStyle<'static> {
    ("sans-serif", px).into_font().color(&colour).pos(pos)
}
