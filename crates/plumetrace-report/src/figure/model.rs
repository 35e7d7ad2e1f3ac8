//! The data the mission figure is drawn from, read from the recorded run: each vehicle's rows,
//! its estimated track in runs under one behaviour and the navigation fixes that broke it, the
//! true track outside the op-area, detections and time marks along the track, aborts and
//! incidents as markers, the behaviour strips, and the key's words about the flow.

use super::style::{ABORT_MARK, Icon};
use plotters::prelude::*;
use plumetrace_core::{BehaviourKind, Heading, PlannerEvent, Vec2};
use plumetrace_guidance::OpArea;
use plumetrace_mission::{EventKind, MissionEvent, MissionRun, TrajectoryRow, lost_points};
use plumetrace_sim::{Incident, WorldEvent};
use std::collections::BTreeMap;

/// A stretch of a track flown under one behaviour (`None`: no planner), as plot points.
pub(super) type BehaviourRun = (Option<BehaviourKind>, Vec<(f64, f64)>);
/// A line from one point to another, data coordinates.
pub(super) type Segment = [(f64, f64); 2];

/// What stopped or aborted a vehicle, for its marker.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum MarkKind {
    /// The cage aborted the mission with the estimate this far outside the op-area, m.
    CageAbort { outside_m: f64 },
    /// The planner aborted for another reason.
    Aborted,
    /// The world stopped the vehicle.
    Incident(Incident),
}

impl MarkKind {
    pub(super) fn legend(self) -> &'static str {
        match self {
            MarkKind::CageAbort { .. } => "cage abort (true position)",
            MarkKind::Aborted => "planner aborted (true position)",
            MarkKind::Incident(_) => "incident (true position)",
        }
    }

    pub(super) fn icon(self) -> Icon {
        match self {
            MarkKind::CageAbort { .. } => Icon::Square(ABORT_MARK),
            MarkKind::Aborted => Icon::Square(RGBColor(255, 150, 150)),
            MarkKind::Incident(_) => Icon::Cross(BLACK),
        }
    }

    /// What the marker's label says.
    pub(super) fn text(self, t_s: f64) -> String {
        let what = match self {
            MarkKind::CageAbort { outside_m } => {
                format!("cage abort, {outside_m:.0} m outside")
            }
            MarkKind::Aborted => "planner aborted".to_string(),
            MarkKind::Incident(Incident::LeftDomain) => "left the domain".to_string(),
            MarkKind::Incident(Incident::Collided) => "collided with an obstacle".to_string(),
            MarkKind::Incident(Incident::HitBottom) => "hit the seabed".to_string(),
        };
        format!("{what} ({:.1} min)", t_s / 60.0)
    }

    /// The word at its line in the reading panel.
    pub(super) fn short(self) -> &'static str {
        match self {
            MarkKind::CageAbort { .. } => "cage abort",
            MarkKind::Aborted => "aborted",
            MarkKind::Incident(Incident::LeftDomain) => "left domain",
            MarkKind::Incident(Incident::Collided) => "collided",
            MarkKind::Incident(Incident::HitBottom) => "hit bottom",
        }
    }
}

/// An abort or incident of a vehicle, at its true position then.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct EventMark {
    pub(super) t_s: f64,
    pub(super) vehicle: u32,
    pub(super) pos: (f64, f64),
    pub(super) kind: MarkKind,
    /// The label's upper left corner, px from the marker (right, down).
    pub(super) label_px: (i32, i32),
}

/// A time mark on a track.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct TimeMark {
    pub(super) tick: Segment,
    pub(super) label_at: (f64, f64),
    pub(super) label: String,
    /// A label placed away from its tick: the line from the tick to the label's box.
    pub(super) leader: Option<Segment>,
}

/// Whether the estimate jumped from row `a` to the next row `b` (a position fix): it moved
/// `min_m` more than three times what the vehicle truly moved.
pub(super) fn jumped(a: &TrajectoryRow, b: &TrajectoryRow, min_m: f64) -> bool {
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
pub(super) fn est_track(
    rows: &[&TrajectoryRow],
    min_m: f64,
) -> (Vec<BehaviourRun>, Vec<(Segment, f64)>) {
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
pub(super) fn track_pos(r: &TrajectoryRow) -> (f64, f64) {
    r.est_x_m.zip(r.est_y_m).unwrap_or((r.true_x_m, r.true_y_m))
}

/// The pieces of a true track outside `area`.
pub(super) fn outside_pieces(rows: &[&TrajectoryRow], area: &OpArea) -> Vec<Vec<(f64, f64)>> {
    pieces_where(rows.iter().map(|r| Some((r.true_x_m, r.true_y_m))), |p| {
        !area.contains(Vec2::new(p.0, p.1))
    })
}

/// The runs of consecutive points that are given and `keep` holds for, each of two points or
/// more (a point left out, or not given, ends a run).
pub(super) fn pieces_where(
    points: impl Iterator<Item = Option<(f64, f64)>>,
    keep: impl Fn((f64, f64)) -> bool,
) -> Vec<Vec<(f64, f64)>> {
    let mut pieces: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut was_kept = false;
    for p in points {
        let kept = p.filter(|p| keep(*p));
        match (kept, was_kept, pieces.last_mut()) {
            (Some(p), true, Some(piece)) => piece.push(p),
            (Some(p), _, _) => pieces.push(vec![p]),
            _ => {}
        }
        was_kept = kept.is_some();
    }
    pieces.retain(|p| p.len() > 1);
    pieces
}

/// Each vehicle's rows in time order.
pub(super) fn rows_by_vehicle(run: &MissionRun) -> BTreeMap<u32, Vec<&TrajectoryRow>> {
    let mut by: BTreeMap<u32, Vec<&TrajectoryRow>> = BTreeMap::new();
    for r in &run.trajectory {
        by.entry(r.vehicle).or_default().push(r);
    }
    by
}

/// Minutes between time marks: the shortest of 1, 2, 5, 10, 15, 20, 30, 60 min and longer
/// that gives at most 12 marks over `duration_s`.
pub(super) fn time_step_min(duration_s: f64) -> f64 {
    const STEPS_MIN: [f64; 12] = [
        1.0, 2.0, 5.0, 10.0, 15.0, 20.0, 30.0, 60.0, 120.0, 240.0, 480.0, 960.0,
    ];
    let minutes = duration_s / 60.0;
    STEPS_MIN
        .into_iter()
        .find(|s| minutes / s <= 12.0)
        .unwrap_or(1920.0)
}

/// Points no closer than `min_m` to the last one kept; the last point is always kept.
pub(super) fn thin(points: &[(f64, f64)], min_m: f64) -> Vec<(f64, f64)> {
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
pub(super) fn detection_ticks(
    rows: &[&TrajectoryRow],
    gap_s: f64,
    half_m: f64,
    min_m: f64,
) -> Vec<Segment> {
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
pub(super) fn time_marks(
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
            leader: None,
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

/// The vehicles with a planner and a recorded track: the reading panel's rows.
pub(super) fn panel_vehicles(
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
) -> Vec<u32> {
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
pub(super) fn behaviour_spans(rows: &[&TrajectoryRow]) -> Vec<(BehaviourKind, f64, f64)> {
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

/// The key's words about the mean flow at the source, and the flow's direction (a unit vector;
/// `None`: too weak or unknown to draw).
pub(super) fn flow_words(flow: Vec2) -> (String, Option<Vec2>) {
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

/// The track flown during each of a vehicle's fault windows (with the window's index into its
/// faults): the track in pieces broken where the estimate jumped by `min_jump_m` or more, and
/// where the vehicle truly was too when its track is the estimate.
pub(super) fn fault_pieces(
    run: &MissionRun,
    vid: u32,
    rs: &[&TrajectoryRow],
    min_jump_m: f64,
) -> Vec<(usize, Vec<(f64, f64)>)> {
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
        .collect()
}

/// What the map marks besides the tracks, read from the run's events and summary.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Overlays {
    /// Obstacle avoidance: each virtual path from where the obstacle was sensed, its course
    /// and its last reference target.
    pub(super) virtual_paths: Vec<(Vec2, Heading, Vec2)>,
    /// Reference targets.
    pub(super) targets: Vec<(f64, f64)>,
    /// Lost points, where their planner last put them.
    pub(super) lost: Vec<(f64, f64)>,
    /// Declared sources.
    pub(super) declared: Vec<(f64, f64)>,
    /// Aborts and incidents.
    pub(super) marks: Vec<EventMark>,
}

impl Overlays {
    /// The overlays of `run` (`rows`: its rows by vehicle).
    pub(super) fn of(run: &MissionRun, rows: &BTreeMap<u32, Vec<&TrajectoryRow>>) -> Self {
        let marks = event_marks(run, rows);
        let mut virtual_paths: Vec<(Vec2, Heading, Vec2)> = Vec::new();
        let mut targets: Vec<(f64, f64)> = Vec::new();
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
                _ => {}
            }
        }
        let declared: Vec<(f64, f64)> = run
            .summary
            .declarations
            .iter()
            .map(|d| (d.x_m, d.y_m))
            .collect();
        Overlays {
            virtual_paths,
            targets,
            lost: lost_points(&run.events)
                .into_iter()
                .map(|l| (l.now_m().x, l.now_m().y))
                .collect(),
            declared,
            marks,
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::super::DETECTION_GAP_S;
    use super::super::test_support::{demo, row};
    use super::*;
    use plumetrace_mission::EventRecord;

    #[test]
    fn a_lost_point_is_drawn_where_its_planner_last_moved_it() {
        let mut run = demo(60.0);
        run.events.retain(|e| {
            !matches!(
                e.event,
                EventKind::Planner(
                    PlannerEvent::LostPoint { .. } | PlannerEvent::LostPointMoved { .. }
                )
            )
        });
        let (saved, kept, moved) = (
            Vec2::new(100.0, 5.0),
            Vec2::new(90.0, 0.0),
            Vec2::new(103.0, 1.0),
        );
        let planner = |t_s: f64, e: PlannerEvent| EventRecord {
            t_s,
            vehicle: 0,
            event: EventKind::Planner(e),
        };
        run.events.extend([
            planner(10.0, PlannerEvent::LostPoint { pos_m: saved }),
            planner(15.0, PlannerEvent::LostPoint { pos_m: kept }),
            planner(
                20.0,
                PlannerEvent::LostPointMoved {
                    from_m: saved,
                    to_m: moved,
                },
            ),
        ]);
        let over = Overlays::of(&run, &rows_by_vehicle(&run));
        assert_eq!(over.lost, vec![(103.0, 1.0), (90.0, 0.0)]);
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
}
