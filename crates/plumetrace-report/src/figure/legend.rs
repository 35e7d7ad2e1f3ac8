//! The figure's legend: a row for everything drawn and nothing else, its size as plotters lays
//! it out, and the band below the map it goes into when no corner of the map is free.

use super::layout::MapLayout;
use super::layout::clip_polygon;
use super::model::{Overlays, behaviour_spans, est_track, fault_pieces, panel_vehicles};
use super::raster::{plume_cells, posterior_cells};
use super::style::{
    AVOID_MARK, DETECTION_MARK, FAULT_FILL, Icon, LEGEND_FONT_PX, LOST_MARK, OBSTACLE_FILL,
    OUTSIDE_TRACK, SOURCE_MARK, TRACK_COLOURS, TRUE_TRACK, WIDTH_PX, behaviour_colour,
    behaviour_label, icon_element, label_style, text_px,
};
use crate::error::ReportError;
use crate::marks::{self, Group};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plumetrace_core::BehaviourKind;
use plumetrace_mission::{MissionRun, TrajectoryRow};
use std::collections::BTreeMap;
use std::ops::Range;

/// One row of the legend.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct LegendEntry {
    pub(super) label: String,
    pub(super) icon: Icon,
}

/// The legend's size in pixels as plotters lays it out (12 px font, 30 px for the icons, 10 px
/// margins).
pub(super) fn legend_px(entries: &[LegendEntry]) -> (f64, f64) {
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

/// The names of the legend's rows that the map's series carry too (see [`crate::marks`]).
pub(super) mod names {
    use super::super::style::behaviour_label;
    use plumetrace_core::BehaviourKind;
    use plumetrace_mission::{FaultWindow, MissionRun};

    pub(in super::super) const PLUME: &str = "mean plume at vehicle altitude";
    pub(in super::super) const SOURCE_MAP: &str = "source map, log10 p (6 decades)";
    pub(in super::super) const OP_AREA: &str = "op-area";
    pub(in super::super) const SUBREGION: &str = "subregion";
    pub(in super::super) const OBSTACLE: &str = "obstacle (kelp)";
    pub(in super::super) const OUTSIDE: &str = "true track outside the op-area";
    pub(in super::super) const FIX: &str = "navigation fix (the estimate jumps)";
    pub(in super::super) const DETECTION: &str = "detection";
    pub(in super::super) const VIRTUAL_PATH: &str = "virtual path";
    pub(in super::super) const TARGET: &str = "reference target";
    pub(in super::super) const LOST: &str = "lost point";
    pub(in super::super) const SOURCE: &str = "true source";
    pub(in super::super) const DECLARED: &str = "declared source";

    /// The true tracks.
    pub(in super::super) fn truth(multi: bool) -> &'static str {
        if multi { "true tracks" } else { "true track" }
    }

    /// A vehicle among several with no estimate of its own to draw.
    pub(in super::super) fn truth_only(run: &MissionRun, vehicle: u32) -> Option<String> {
        run.vehicles
            .get(vehicle as usize)
            .map(|v| format!("{}: true track only (no position estimate)", v.name))
    }

    /// A run of a vehicle's estimated track: by behaviour (one vehicle), by vehicle (several).
    pub(in super::super) fn track(
        run: &MissionRun,
        vehicle: u32,
        b: Option<BehaviourKind>,
        multi: bool,
    ) -> String {
        match (b, run.vehicles.get(vehicle as usize)) {
            (Some(b), _) if !multi => format!("track: {}", behaviour_label(b)),
            (_, Some(v)) if multi => format!(
                "{} ({}) estimated track",
                v.name,
                v.planner.map_or("no planner", |k| k.name())
            ),
            _ => "track (navigation estimate)".into(),
        }
    }

    /// A fault window (`alone`: the only one drawn, so named with its times).
    pub(in super::super) fn fault(f: &FaultWindow, alone: bool) -> String {
        if alone {
            format!(
                "fault {:.1}-{:.1} min: {}",
                f.start_s / 60.0,
                f.end_s / 60.0,
                f.what
            )
        } else {
            format!("fault: {}", f.what)
        }
    }

    /// The time marks.
    pub(in super::super) fn times(step_min: f64) -> String {
        format!("time along the track, every {step_min:.0} min")
    }
}

/// Adds a row to the legend unless it is there already.
pub(super) fn add(legend: &mut Vec<LegendEntry>, label: String, icon: Icon) {
    if !legend.iter().any(|e| e.label == label) {
        legend.push(LegendEntry { label, icon });
    }
}

/// The legend's rows: everything the map and the reading panel draw, in the order they are
/// drawn. `(bx, by)` are the map's bounds before its aspect is fitted; `any_outside` says
/// whether a true track leaves the op-area; `step_min` is the time marks' step.
pub(super) fn map_legend(
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
    (bx, by): (&Range<f64>, &Range<f64>),
    any_outside: bool,
    step_min: f64,
    over: &Overlays,
) -> Vec<LegendEntry> {
    let mut legend: Vec<LegendEntry> = Vec::new();
    area_rows(&mut legend, run, rows, (bx, by), any_outside);
    let has_jumps = track_rows(&mut legend, run, rows);
    mark_rows(&mut legend, run, rows, has_jumps, step_min, over);
    legend
}

/// The rows of the map's background: plume, source map, op-area, subregions, obstacles and the
/// true tracks.
fn area_rows(
    legend: &mut Vec<LegendEntry>,
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
    (bx, by): (&Range<f64>, &Range<f64>),
    any_outside: bool,
) {
    let multi = rows.len() > 1;
    // The plume's cells over the bounds before the aspect is fitted: fitting only grows them.
    if !plume_cells(run, bx, by).is_empty() {
        add(
            legend,
            names::PLUME.into(),
            Icon::Patch(RGBColor(255, 170, 100), 1.0),
        );
    }
    if !posterior_cells(run, bx, by).is_empty() {
        add(
            legend,
            names::SOURCE_MAP.into(),
            Icon::Patch(RGBColor(35, 85, 185), 1.0),
        );
    }
    if run.op_area.len() > 1 {
        add(legend, names::OP_AREA.into(), Icon::Dashed(BLACK, 2));
    }
    if run.subregions.iter().any(|r| r.len() > 1) {
        add(
            legend,
            names::SUBREGION.into(),
            Icon::Dashed(RGBColor(120, 120, 120), 1),
        );
    }
    if run
        .obstacles
        .iter()
        .any(|o| clip_polygon(&o.iter().map(|v| (v.x, v.y)).collect::<Vec<_>>(), bx, by).len() > 2)
    {
        add(
            legend,
            names::OBSTACLE.into(),
            Icon::Patch(OBSTACLE_FILL, 0.55),
        );
    }
    if rows.values().any(|r| r.len() > 1) {
        add(
            legend,
            names::truth(multi).into(),
            Icon::Line(TRUE_TRACK, 1),
        );
    }
    if any_outside {
        add(legend, names::OUTSIDE.into(), Icon::Line(OUTSIDE_TRACK, 2));
    }
}

/// The rows of the estimated tracks (by vehicle with several, by behaviour with one), the
/// behaviour strips and the fault windows; whether the estimate jumped anywhere.
fn track_rows(
    legend: &mut Vec<LegendEntry>,
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
) -> bool {
    let multi = rows.len() > 1;
    // Estimated tracks: by vehicle (several) or by behaviour (one); a run counts when it
    // joins two different points.
    let moves = |pts: &[(f64, f64)]| pts.iter().any(|p| *p != pts[0]);
    let mut has_jumps = false;
    for (n, (&vid, rs)) in rows.iter().enumerate() {
        let colour = TRACK_COLOURS[n % TRACK_COLOURS.len()];
        let (runs, _) = est_track(rs, f64::INFINITY);
        // Jumps of 5 m or more may be drawn (those shorter than 10 px are not).
        has_jumps |= !est_track(rs, 5.0).1.is_empty();
        if multi && !runs.iter().any(|(_, p)| moves(p)) {
            // No estimate of its own to draw: its true track is all the map has of it.
            if let Some(label) = names::truth_only(run, vid) {
                add(legend, label, Icon::Line(TRUE_TRACK, 1));
            }
        }
        for (b, _) in runs.iter().filter(|(_, p)| moves(p)) {
            let icon = match b {
                Some(b) if !multi => Icon::Line(behaviour_colour(*b), 2),
                _ => Icon::Line(colour, 2),
            };
            add(legend, names::track(run, vid, *b, multi), icon);
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
                legend,
                format!("behaviour: {}", behaviour_label(b)),
                Icon::Patch(behaviour_colour(b), 1.0),
            );
        }
    }
    let mut faults_drawn: Vec<(u32, usize)> = rows
        .iter()
        .flat_map(|(&vid, rs)| {
            fault_pieces(run, vid, rs, f64::INFINITY)
                .into_iter()
                .map(move |(k, _)| (vid, k))
        })
        .collect();
    faults_drawn.dedup();
    for &(vid, k) in &faults_drawn {
        if let Some(f) = run.vehicles.get(vid as usize).and_then(|v| v.faults.get(k)) {
            let label = names::fault(f, faults_drawn.len() == 1);
            add(legend, label, Icon::Band(FAULT_FILL));
        }
    }
    has_jumps
}

/// The rows of what is marked on the tracks and the map: navigation fixes, detections, time
/// marks, obstacle avoidance, lost points, sources, declarations, aborts and incidents.
fn mark_rows(
    legend: &mut Vec<LegendEntry>,
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
    has_jumps: bool,
    step_min: f64,
    over: &Overlays,
) {
    if has_jumps {
        add(legend, names::FIX.into(), Icon::Dotted(BLACK));
    }
    if rows.values().flatten().any(|r| r.detection) {
        // (Thinned to one per DETECTION_GAP_S; the module's docs say so.)
        add(
            legend,
            names::DETECTION.into(),
            Icon::Tick(DETECTION_MARK, 0.6),
        );
    }
    if rows
        .values()
        .filter_map(|r| r.last())
        .any(|r| r.t_s + 1e-6 >= step_min * 60.0)
    {
        add(legend, names::times(step_min), Icon::TimeTick);
    }
    if !over.virtual_paths.is_empty() {
        add(
            legend,
            names::VIRTUAL_PATH.into(),
            Icon::Dashed(AVOID_MARK, 1),
        );
    }
    if !over.targets.is_empty() {
        add(legend, names::TARGET.into(), Icon::Diamond(AVOID_MARK));
    }
    if !over.lost.is_empty() {
        add(legend, names::LOST.into(), Icon::Ring(LOST_MARK));
    }
    if !run.sources.is_empty() {
        add(legend, names::SOURCE.into(), Icon::Triangle(SOURCE_MARK));
    }
    if !over.declared.is_empty() {
        add(legend, names::DECLARED.into(), Icon::Dot(BLACK));
    }
    for m in &over.marks {
        add(legend, m.kind.legend().into(), m.kind.icon());
    }
}

/// The legend below the map: columns, rows and height, px (no rows: none).
pub(super) fn legend_band(lay: &MapLayout) -> (usize, usize, u32) {
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
pub(super) fn draw_legend_band<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    lay: &MapLayout,
) -> Result<(), ReportError>
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
    .map_err(ReportError::figure)?;
    let col_w = (x1 - x0 - 10) / cols as i32;
    let style = label_style(
        LEGEND_FONT_PX as u32,
        BLACK,
        Pos::new(HPos::Left, VPos::Center),
    );
    for (k, e) in lay.legend.iter().enumerate() {
        let (c, r) = ((k / rows) as i32, (k % rows) as i32);
        let (x, y) = (x0 + 10 + c * col_w, 12 + 16 * r);
        // The swatch and its label, as one legend entry.
        area.draw(
            &(EmptyElement::at((x, y))
                + marks::open_text(Group::Legend, &e.label)
                + icon_element!(e.icon, (0, 0), 0)
                + Text::new(e.label.clone(), (26, 0), style.clone())
                + marks::close_text()),
        )
        .map_err(ReportError::figure)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::super::mission_figure;
    use super::super::test_support::{demo, labels, layout};
    use super::*;
    use plumetrace_core::{DeclarationKind, PlannerEvent};
    use plumetrace_mission::{DeclarationRecord, EventKind};

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
}
