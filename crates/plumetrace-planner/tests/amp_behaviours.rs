//! Each AMP behaviour and switch, driven by hand-built sensor snapshots.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_core::{
    BehaviourKind, ChemSample, DeclarationKind, FlowSample, Heading, NavEstimate, PlanStatus,
    Planner, PlannerEvent, SensorSnapshot, Vec2, VehicleId, bearing_between,
};
use plumetrace_guidance::OpArea;
use plumetrace_planner::{Amp, AmpParams, LostPointEviction};

/// Flow towards North at 0.1 m/s: upflow is South.
fn snap(t: f64, pos: (f64, f64), heading_deg: f64, detection: bool) -> SensorSnapshot {
    SensorSnapshot {
        time_s: t,
        vehicle: VehicleId(0),
        nav: NavEstimate {
            pos_m: Some(Vec2::new(pos.0, pos.1)),
            heading: Heading::from_deg(heading_deg),
            speed_mps: 2.0,
            altitude_m: Some(2.0),
            depth_m: None,
            last_fix_s: None,
        },
        // Above and below the default 0.2 V detection threshold.
        chem: vec![ChemSample {
            time_s: t,
            reading: if detection { 1.0 } else { 0.1 },
        }],
        flow: Some(FlowSample {
            time_s: t,
            velocity_mps: Vec2::new(0.0, 0.1),
        }),
        ranges: None,
        inbox: vec![],
    }
}

fn amp() -> Amp {
    let area = OpArea::rectangle(0.0, 400.0, 0.0, 1000.0).unwrap();
    Amp::new(AmpParams::default(), area, vec![], Heading::NORTH)
}

fn behaviours(events: &[PlannerEvent]) -> Vec<BehaviourKind> {
    events.iter().filter_map(PlannerEvent::behaviour).collect()
}

#[test]
fn starts_by_going_to_the_most_downflow_corner_then_finds() {
    let mut a = amp();
    let d = a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    assert_eq!(a.behaviour(), BehaviourKind::GoTo);
    assert_eq!(d.status, PlanStatus::Running);
    assert_eq!(behaviours(&d.events), [BehaviourKind::GoTo]);
    // Near a North corner (flow goes North) the search starts across and up the flow, and
    // Go-To asks for the bearing to it.
    let start = a.search_start(0);
    assert!(
        start.y > 980.0 && (start.x < 20.0 || start.x > 380.0),
        "{start:?}"
    );
    let bearing = bearing_between(Vec2::new(200.0, 500.0), start).unwrap();
    assert!(
        a.last_course().diff_deg(bearing).abs() < 1e-9,
        "course {} towards the start {}",
        a.last_course().deg(),
        bearing.deg()
    );
    // The first command still heads where the vehicle points (the rate filter starts there);
    // a second later it has turned towards the start by at most 10 deg.
    assert_eq!(d.command.heading, Heading::NORTH);
    let d = a.decide(&snap(1.0, (200.0, 502.0), 0.0, false));
    let turned = d.command.heading.diff_deg(Heading::NORTH);
    assert!(
        turned.abs() > 9.99
            && turned.abs() <= 10.0 + 1e-9
            && turned.signum() == bearing.diff_deg(Heading::NORTH).signum(),
        "{turned}"
    );
    a.decide(&snap(1.0, (start.x, start.y), 0.0, false));
    assert_eq!(a.behaviour(), BehaviourKind::Find);
}

#[test]
fn track_in_flips_lhs_on_the_wrapped_heading_difference() {
    let mut a = amp();
    a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    // Heading 170: psi_v - psi_f = 170 < 180, so LHS = +1 after the detection.
    a.decide(&snap(1.0, (200.0, 500.0), 170.0, true));
    assert_eq!(a.behaviour(), BehaviourKind::TrackIn);
    a.decide(&snap(1.1, (200.0, 500.0), 170.0, true));
    assert_eq!(a.lhs(), 1.0);
    // Heading 190: the difference 190 is >= 180, so LHS = -1.
    a.decide(&snap(1.2, (200.0, 499.8), 190.0, true));
    assert_eq!(a.lhs(), -1.0);
    // Heading 350 (difference 350, not -10): LHS = -1; heading 5: LHS = +1.
    a.decide(&snap(1.3, (200.0, 499.6), 350.0, true));
    assert_eq!(a.lhs(), -1.0);
    a.decide(&snap(1.4, (200.0, 499.4), 5.0, true));
    assert_eq!(a.lhs(), 1.0);
}

#[test]
fn track_in_commands_upflow_offset_by_beta_with_the_lhs_before_its_update() {
    let mut a = amp();
    a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    a.decide(&snap(1.0, (200.0, 500.0), 170.0, true)); // enters Track-In; LHS from heading 170: +1
    // Table 1: the course uses the current LHS (+1): upflow 180 + 20 = 200; then LHS updates
    // from the heading (190: difference 190 >= 180 gives -1).
    a.decide(&snap(1.1, (200.0, 499.8), 190.0, true));
    assert!(
        a.last_course().diff_deg(Heading::from_deg(200.0)).abs() < 1e-9,
        "{}",
        a.last_course().deg()
    );
    assert_eq!(a.lhs(), -1.0);
    a.decide(&snap(1.2, (200.0, 499.6), 190.0, true));
    assert!(
        a.last_course().diff_deg(Heading::from_deg(160.0)).abs() < 1e-9,
        "{}",
        a.last_course().deg()
    );
    // Between detections (within lambda) the course is held.
    a.decide(&snap(2.0, (200.0, 498.0), 170.0, false));
    assert!(a.last_course().diff_deg(Heading::from_deg(160.0)).abs() < 1e-9);
}

#[test]
fn losing_the_plume_saves_a_lost_point_and_tracks_out_to_the_opposite_side() {
    let mut a = amp();
    a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    a.decide(&snap(1.0, (200.0, 500.0), 170.0, true));
    a.decide(&snap(1.1, (200.0, 499.8), 170.0, true)); // last detection at (200, 499.8), LHS +1
    assert_eq!(a.lhs(), 1.0);
    // Still Track-In within lambda = 5 s.
    a.decide(&snap(5.0, (201.0, 494.0), 170.0, false));
    assert_eq!(a.behaviour(), BehaviourKind::TrackIn);
    let d = a.decide(&snap(6.2, (202.0, 492.0), 170.0, false));
    assert_eq!(a.behaviour(), BehaviourKind::TrackOut);
    assert_eq!(a.lost_points(), &[Vec2::new(200.0, 499.8)]);
    assert!(
        d.events
            .iter()
            .any(|e| matches!(e, PlannerEvent::LostPoint { .. }))
    );
    assert!(behaviours(&d.events).contains(&BehaviourKind::TrackOut));
    // LHS +1: it left on the left looking upflow (South): left is East. The goal is on the
    // other side (West), 18 m upflow (South) and 18 m across.
    let goal = a.track_out_goal().unwrap();
    assert!(
        (goal - Vec2::new(200.0 - 18.0, 499.8 - 18.0)).norm() < 0.5,
        "{goal:?}"
    );
}

#[test]
fn track_out_arrival_without_declaration_reacquires_and_detection_returns_to_track_in() {
    let mut a = amp();
    a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    a.decide(&snap(1.0, (200.0, 500.0), 170.0, true));
    a.decide(&snap(7.0, (200.0, 495.0), 170.0, false));
    assert_eq!(a.behaviour(), BehaviourKind::TrackOut);
    let goal = a.track_out_goal().unwrap();
    a.decide(&snap(20.0, (goal.x + 1.0, goal.y), 200.0, false));
    assert_eq!(a.behaviour(), BehaviourKind::Reacquire);
    a.decide(&snap(21.0, (goal.x, goal.y - 2.0), 200.0, true));
    assert_eq!(a.behaviour(), BehaviourKind::TrackIn);
}

/// Loses the plume at `points` in turn (each: detect there, then wait out lambda, then arrive at
/// the Track-Out goal), returning the decisions' events.
fn lose_at(a: &mut Amp, points: &[(f64, f64)]) -> Vec<PlannerEvent> {
    let mut events = Vec::new();
    let mut t = 10.0;
    for &(x, y) in points {
        events.extend(a.decide(&snap(t, (x, y), 180.0, true)).events);
        t += 6.0;
        events.extend(a.decide(&snap(t, (x, y - 1.0), 180.0, false)).events);
        if a.behaviour() != BehaviourKind::TrackOut {
            break;
        }
        let goal = a.track_out_goal().unwrap();
        t += 10.0;
        events.extend(a.decide(&snap(t, (goal.x, goal.y), 180.0, false)).events);
        t += 1.0;
    }
    events
}

#[test]
fn declares_when_three_lost_points_are_close_along_the_flow_then_maps() {
    let mut a = amp();
    a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    let events = lose_at(&mut a, &[(200.0, 300.0), (205.0, 298.0), (195.0, 296.5)]);
    let declared: Vec<_> = events
        .iter()
        .filter_map(|e| {
            if let PlannerEvent::Declared { pos_m, .. } = e {
                Some(*pos_m)
            } else {
                None
            }
        })
        .collect();
    assert_eq!(
        declared,
        vec![Vec2::new(195.0, 296.5)],
        "the most upflow (southern) point"
    );
    assert_eq!(a.declarations(), declared);
    assert_eq!(a.behaviour(), BehaviourKind::Mapping);
}

#[test]
fn does_not_declare_when_the_points_are_spread_along_the_flow() {
    let mut a = amp();
    a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    let events = lose_at(&mut a, &[(200.0, 300.0), (205.0, 290.0), (195.0, 280.0)]);
    assert!(
        !events
            .iter()
            .any(|e| matches!(e, PlannerEvent::Declared { .. }))
    );
    assert_eq!(a.behaviour(), BehaviourKind::Reacquire);
    assert_eq!(a.lost_points().len(), 3);
}

#[test]
fn keeps_at_most_six_lost_points_dropping_the_oldest() {
    let mut a = amp();
    a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    let pts: Vec<(f64, f64)> = (0..8)
        .map(|k| (200.0, 900.0 - 50.0 * f64::from(k)))
        .collect();
    lose_at(&mut a, &pts);
    let lost = a.lost_points();
    assert_eq!(lost.len(), 6);
    assert!(
        lost.iter().all(|p| p.y < 850.0),
        "the most downflow points were dropped: {lost:?}"
    );
}

#[test]
fn a_full_list_drops_the_oldest_or_the_most_downflow_older_point() {
    // Each loss 10 m further downflow (North) than the one before: never a declaration.
    let pts: Vec<(f64, f64)> = (0..8)
        .map(|k| (200.0, 300.0 + 10.0 * f64::from(k)))
        .collect();
    let ys = |eviction| {
        let area = OpArea::rectangle(0.0, 400.0, 0.0, 1000.0).unwrap();
        let params = AmpParams {
            lost_point_eviction: eviction,
            ..AmpParams::default()
        };
        let mut a = Amp::new(params, area, vec![], Heading::NORTH);
        a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
        let events = lose_at(&mut a, &pts);
        assert!(
            !events
                .iter()
                .any(|e| matches!(e, PlannerEvent::Declared { .. }))
        );
        let mut y: Vec<f64> = a.lost_points().iter().map(|p| p.y).collect();
        y.sort_by(f64::total_cmp);
        y
    };
    assert_eq!(
        ys(LostPointEviction::Oldest),
        vec![320.0, 330.0, 340.0, 350.0, 360.0, 370.0]
    );
    assert_eq!(
        ys(LostPointEviction::MostDownflow),
        vec![300.0, 310.0, 320.0, 330.0, 340.0, 370.0],
        "the five most upflow older points and the newest"
    );
}

#[test]
fn cage_abort_ends_the_mission() {
    let mut a = amp();
    a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    let d = a.decide(&snap(1.0, (-40.0, 500.0), 0.0, false));
    assert_eq!(d.status, PlanStatus::Abort);
    assert_eq!(d.command.speed_mps, 0.0);
    assert!(
        d.events.iter().any(|e| matches!(
            e,
            PlannerEvent::CageAbort { distance_outside_m } if (distance_outside_m - 40.0).abs() < 1e-9
        )),
        "{:?}",
        d.events
    );
}

#[test]
fn multi_source_missions_ignore_detections_in_transit_and_time_out_regions() {
    let area = OpArea::rectangle(0.0, 400.0, 0.0, 1000.0).unwrap();
    let regions = vec![
        OpArea::rectangle(0.0, 200.0, 0.0, 500.0).unwrap(),
        OpArea::rectangle(200.0, 400.0, 0.0, 500.0).unwrap(),
    ];
    let p = AmpParams {
        region_timeout_s: 100.0,
        ..AmpParams::default()
    };
    let mut a = Amp::new(p, area, regions, Heading::NORTH);
    let d = a.decide(&snap(0.0, (100.0, 100.0), 0.0, false));
    assert_eq!(a.behaviour(), BehaviourKind::Transit);
    assert!(
        d.events
            .iter()
            .any(|e| matches!(e, PlannerEvent::Region { index: 0, .. }))
    );
    a.decide(&snap(1.0, (100.0, 110.0), 0.0, true));
    assert_eq!(
        a.behaviour(),
        BehaviourKind::Transit,
        "detections are ignored while transiting"
    );
    let start = a.search_start(0);
    a.decide(&snap(2.0, (start.x, start.y), 0.0, false));
    assert_eq!(a.behaviour(), BehaviourKind::Find);
    let d = a.decide(&snap(103.0, (100.0, 200.0), 0.0, false));
    assert!(d.events.iter().any(|e| matches!(
        e,
        PlannerEvent::Region {
            index: 0,
            what: plumetrace_core::RegionEvent::TimedOut
        }
    )));
    assert!(d.events.iter().any(|e| matches!(
        e,
        PlannerEvent::Region {
            index: 1,
            what: plumetrace_core::RegionEvent::Started
        }
    )));
}

#[test]
fn multi_source_tracing_to_the_upflow_edge_declares_there() {
    let area = OpArea::rectangle(0.0, 400.0, 0.0, 1000.0).unwrap();
    // Flow North, so a region's upflow edge is its southern edge.
    let regions = vec![
        OpArea::rectangle(0.0, 400.0, 500.0, 1000.0).unwrap(),
        OpArea::rectangle(0.0, 400.0, 0.0, 500.0).unwrap(),
    ];
    let mut a = Amp::new(AmpParams::default(), area, regions, Heading::NORTH);
    a.decide(&snap(0.0, (100.0, 900.0), 0.0, false));
    let start = a.search_start(0);
    a.decide(&snap(1.0, (start.x, start.y), 0.0, false));
    assert_eq!(a.behaviour(), BehaviourKind::Find);
    a.decide(&snap(2.0, (150.0, 700.0), 180.0, true));
    assert_eq!(a.behaviour(), BehaviourKind::TrackIn);
    let d = a.decide(&snap(3.0, (150.0, 504.0), 180.0, true));
    let declared: Vec<_> = d
        .events
        .iter()
        .filter_map(|e| {
            if let PlannerEvent::Declared { pos_m, rule } = e {
                Some((*pos_m, *rule))
            } else {
                None
            }
        })
        .collect();
    assert_eq!(declared.len(), 1, "{:?}", d.events);
    assert!(
        (declared[0].0 - Vec2::new(150.0, 500.0)).norm() < 1e-9
            && declared[0].1 == DeclarationKind::UpflowEdge
    );
    assert_eq!(a.behaviour(), BehaviourKind::Transit);
}
