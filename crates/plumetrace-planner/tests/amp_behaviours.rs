//! Each AMP behaviour and switch, driven by hand-built sensor snapshots.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_core::{
    BehaviourKind, ChemSample, FlowSample, Heading, NavEstimate, PlanStatus, Planner, PlannerEvent,
    SensorSnapshot, Vec2, VehicleId, bearing_between,
};
use plumetrace_guidance::OpArea;
use plumetrace_planner::amp::{DeclarationAcross, FindPattern, LhsUpdate};
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
    amp_with(AmpParams::default())
}

fn amp_with(p: AmpParams) -> Amp {
    let area = OpArea::rectangle(0.0, 400.0, 0.0, 1000.0).unwrap();
    Amp::new(p, area, vec![], Heading::NORTH)
}

/// The fix smoothing moving only what was saved while flow readings were held back (no fix
/// error, no drift between fixes assumed).
fn held_back_only(p: AmpParams) -> AmpParams {
    AmpParams {
        fix_error_m: 0.0,
        fix_drift_mps: 0.0,
        ..p
    }
}

/// The paper's behaviour where the defaults depart from it.
fn paper() -> AmpParams {
    AmpParams {
        track_in_lhs: LhsUpdate::EveryDetection,
        find_pattern: FindPattern::Billiard,
        lost_point_max_age_s: 0.0,
        lost_point_max_turn_deg: 180.0,
        reacquire_timeout_s: 0.0,
        clip_patterns: false,
        mapping_timeout_s: 0.0,
        flow_gate_deg: 180.0,
        nav_drift_mps: 0.0,
        approach_replans: 0,
        declaration_on_upflow_contact: true,
        track_altitude_m: 0.0,
        declaration_upflow_m: 0.0,
        declaration_across: DeclarationAcross::MostUpflow,
        ..AmpParams::default()
    }
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
    // Table 1 as printed (LHS from the heading at every detection).
    let mut a = amp_with(paper());
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
        events.extend(confirm_clean(a, &mut t));
    }
    events
}

/// Flies a confirming Track-Out, if one began, to its goal without a contact.
fn confirm_clean(a: &mut Amp, t: &mut f64) -> Vec<PlannerEvent> {
    let goals = a.confirming().map(|(_, g)| g.to_vec()).unwrap_or_default();
    let mut events = Vec::new();
    for goal in goals {
        *t += 20.0;
        events.extend(a.decide(&snap(*t, (goal.x, goal.y), 180.0, false)).events);
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
    // 2.5 m upflow (South) of the most upflow point, at the three points' mean across the flow.
    assert_eq!(declared.len(), 1, "{declared:?}");
    assert!(
        (declared[0] - Vec2::new(200.0, 294.0)).norm() < 1e-9,
        "upflow of the most upflow (southern) point, at the mean across: {declared:?}"
    );
    assert_eq!(a.declarations(), declared);
    assert_eq!(a.behaviour(), BehaviourKind::Mapping);
}

#[test]
fn the_field_placement_declares_the_most_upflow_lost_point() {
    let mut a = amp_with(AmpParams {
        declaration_upflow_m: 0.0,
        declaration_across: DeclarationAcross::MostUpflow,
        ..AmpParams::default()
    });
    a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    let events = lose_at(&mut a, &[(200.0, 300.0), (205.0, 298.0), (195.0, 296.5)]);
    let declared: Vec<_> = events
        .iter()
        .filter_map(|e| match e {
            PlannerEvent::Declared { pos_m, .. } => Some(*pos_m),
            _ => None,
        })
        .collect();
    assert_eq!(
        declared,
        vec![Vec2::new(195.0, 296.5)],
        "the most upflow (southern) point"
    );
}

#[test]
fn a_track_out_contact_upflow_of_the_lost_points_traces_on_instead_of_declaring() {
    // Three lost points within 6 m along the flow (North: upflow is South), then a contact during
    // Track-Out: upflow of them the plume goes on, so Track-In follows it; level with them (or
    // downflow) the check declares, as at every Track-Out contact in the field rule.
    let run = |p: AmpParams, contact: (f64, f64)| {
        let mut a = amp_with(p);
        a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
        let mut events = lose_at(&mut a, &[(200.0, 300.0), (205.0, 298.0)]);
        events.extend(a.decide(&snap(100.0, (195.0, 296.5), 180.0, true)).events);
        events.extend(a.decide(&snap(106.0, (195.0, 295.5), 180.0, false)).events);
        assert_eq!(a.behaviour(), BehaviourKind::TrackOut);
        events.extend(a.decide(&snap(108.0, contact, 180.0, true)).events);
        events.extend(confirm_clean(&mut a, &mut 110.0));
        let declared = events
            .iter()
            .any(|e| matches!(e, PlannerEvent::Declared { .. }));
        (declared, a.behaviour())
    };
    let upflow = (190.0, 285.0);
    assert_eq!(
        run(AmpParams::default(), upflow),
        (false, BehaviourKind::TrackIn),
        "upflow of the lost points: traced on"
    );
    // (The field rule flies no confirming Track-Out: by default the contact, more than
    // declaration_along_m upflow of the point, would itself hold the declaration back.)
    let field = AmpParams {
        declaration_on_upflow_contact: true,
        declaration_confirm_m: 0.0,
        ..AmpParams::default()
    };
    assert_eq!(
        run(field, upflow),
        (true, BehaviourKind::Mapping),
        "the field rule declares"
    );
    assert_eq!(
        run(AmpParams::default(), (190.0, 297.0)),
        (true, BehaviourKind::Mapping),
        "downflow of the most upflow lost point: declared"
    );
}

#[test]
fn a_patch_whose_plume_goes_on_upflow_is_traced_on_not_declared() {
    // Three lost points within 6 m along the flow (North: upflow is South), as the upflow ends of
    // one patch far downflow of a source leave them. At the Track-Out's arrival the field check
    // declares at once; by default a confirming Track-Out first flies upflow of the point, and
    // chemical there (the next patch) is traced on instead.
    let patch = [(200.0, 300.0), (205.0, 298.0), (195.0, 296.5)];
    let declared = |events: &[PlannerEvent]| {
        events
            .iter()
            .any(|e| matches!(e, PlannerEvent::Declared { .. }))
    };
    let fly = |p: AmpParams| {
        let mut a = amp_with(p);
        a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
        let mut events = Vec::new();
        let mut t = 10.0;
        for &(x, y) in &patch {
            events.extend(a.decide(&snap(t, (x, y), 180.0, true)).events);
            t += 6.0;
            events.extend(a.decide(&snap(t, (x, y - 1.0), 180.0, false)).events);
            let goal = a.track_out_goal().unwrap();
            t += 10.0;
            events.extend(a.decide(&snap(t, (goal.x, goal.y), 180.0, false)).events);
            t += 1.0;
        }
        (a, events, t)
    };
    let (a, events, _) = fly(AmpParams {
        declaration_confirm_m: 0.0,
        ..AmpParams::default()
    });
    assert!(declared(&events), "the field check declares the patch");
    assert!((a.declarations()[0] - Vec2::new(200.0, 294.0)).norm() < 1e-9);

    let (mut a, events, t) = fly(AmpParams::default());
    assert!(!declared(&events), "held back for the confirming leg");
    assert_eq!(a.behaviour(), BehaviourKind::TrackOut);
    let (at, goals) = a.confirming().expect("a confirming Track-Out");
    assert!((at - Vec2::new(200.0, 294.0)).norm() < 1e-9, "{at:?}");
    // Three legs, a third of 60 m upflow each, 30 m to either side of the axis in turn.
    assert_eq!(goals.len(), 3, "{goals:?}");
    for (k, g) in goals.iter().enumerate() {
        let up = 294.0 - g.y;
        assert!((up - 60.0 * (k + 1) as f64 / 3.0).abs() < 1e-9, "{goals:?}");
        assert!(((g.x - 200.0).abs() - 30.0).abs() < 1e-9, "{goals:?}");
    }
    assert!(
        (goals[0].x - 200.0) * (goals[1].x - 200.0) < 0.0,
        "zigzag: {goals:?}"
    );
    // Chemical within declaration_along_m of the point: still the patch; the leg flies on.
    let near = a.decide(&snap(t, (200.0, 290.0), 180.0, true)).events;
    assert!(!declared(&near));
    assert_eq!(a.behaviour(), BehaviourKind::TrackOut);
    assert!(a.confirming().is_some());
    // 20 m upflow: the plume goes on; Track-In follows it, nothing is declared.
    let upflow = a
        .decide(&snap(t + 10.0, (200.0, 274.0), 180.0, true))
        .events;
    assert!(!declared(&upflow));
    assert_eq!(a.behaviour(), BehaviourKind::TrackIn);
    assert_eq!(a.confirming(), None);
    assert!(a.declarations().is_empty());

    // Nothing on the way: the point is declared where the field check would have.
    let (mut a, _, mut t) = fly(AmpParams::default());
    let events = confirm_clean(&mut a, &mut t);
    assert!(declared(&events));
    assert!((a.declarations()[0] - Vec2::new(200.0, 294.0)).norm() < 1e-9);
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
                Some((*pos_m, rule.clone()))
            } else {
                None
            }
        })
        .collect();
    assert_eq!(declared.len(), 1, "{:?}", d.events);
    assert!(
        (declared[0].0 - Vec2::new(150.0, 500.0)).norm() < 1e-9
            && declared[0].1 == plumetrace_planner::amp::UPFLOW_EDGE
    );
    assert_eq!(a.behaviour(), BehaviourKind::Transit);
}

/// Flies the planner's commands with a point vehicle: the heading follows the command (the
/// autopilot rate-limits it already), the position moves 2 m/s along the heading in still water
/// plus the flow (0.1 m/s North); `detect(t, pos)` says when the sensor detects.
fn fly(
    a: &mut Amp,
    from: (f64, f64),
    heading_deg: f64,
    seconds: f64,
    detect: impl Fn(f64, Vec2) -> bool,
) -> Vec<(f64, Vec2, f64)> {
    fly_in(a, from, heading_deg, (0.0, seconds), detect, |_| {
        Vec2::new(0.0, 0.1)
    })
}

/// [`fly`] from `t0` to `t1`, with the measured flow `flow(t)` (the vehicle drifts with the
/// true 0.1 m/s northward flow whatever is measured), and the behaviour at each step.
fn fly_in(
    a: &mut Amp,
    from: (f64, f64),
    heading_deg: f64,
    (t0, t1): (f64, f64),
    detect: impl Fn(f64, Vec2) -> bool,
    flow: impl Fn(f64) -> Vec2,
) -> Vec<(f64, Vec2, f64)> {
    let (mut pos, mut h) = (Vec2::new(from.0, from.1), heading_deg);
    let mut track = Vec::new();
    let steps = ((t1 - t0) / 0.1).round() as usize;
    for k in 0..steps {
        let t = t0 + k as f64 * 0.1;
        let mut sn = snap(t, (pos.x, pos.y), h, detect(t, pos));
        sn.flow = Some(FlowSample {
            time_s: t,
            velocity_mps: flow(t),
        });
        let d = a.decide(&sn);
        if d.status != PlanStatus::Running {
            break;
        }
        h = d.command.heading.deg();
        pos += Heading::from_deg(h).unit() * (d.command.speed_mps * 0.1) + Vec2::new(0.0, 0.01);
        track.push((t, pos, h));
    }
    track
}

/// Seconds from `t0` until the behaviour is no longer `b` (or the end of the flight).
fn time_in(a_behaviours: &[(f64, BehaviourKind)], b: BehaviourKind, t0: f64) -> f64 {
    a_behaviours
        .iter()
        .find(|(t, k)| *t >= t0 && *k != b)
        .map_or(f64::INFINITY, |(t, _)| t - t0)
}

#[test]
fn track_in_locks_onto_the_downflow_heading() {
    // Track-In starts heading downflow (North, with the flow) and keeps detecting. Table 1 as
    // printed flips LHS as the heading crosses the flow direction and the rate filter's short
    // turns cancel: the vehicle runs downflow. With the default it turns round and goes upflow.
    let downflow_then = |p: AmpParams| {
        let mut a = amp_with(p);
        let track = fly(&mut a, (200.0, 500.0), 0.0, 60.0, |t, _| t > 1.0);
        let (_, _, h) = *track.last().unwrap();
        (
            Heading::from_deg(h)
                .diff_deg(Heading::from_deg(180.0))
                .abs(),
            a.behaviour(),
        )
    };
    let (off_upflow, b) = downflow_then(paper());
    assert_eq!(b, BehaviourKind::TrackIn);
    assert!(
        off_upflow > 150.0,
        "the paper's LHS holds downflow: {off_upflow}"
    );
    let (off_upflow, b) = downflow_then(AmpParams::default());
    assert_eq!(b, BehaviourKind::TrackIn);
    assert!(
        off_upflow <= 20.0 + 1e-6,
        "turned round to upflow +- beta: {off_upflow}"
    );
}

/// Flies `a` from `from` for `(t0, t1)` without detections, recording the behaviour each step.
fn behaviours_flying(
    a: &mut Amp,
    from: (f64, f64),
    heading_deg: f64,
    (t0, t1): (f64, f64),
) -> Vec<(f64, BehaviourKind)> {
    let (mut pos, mut h) = (Vec2::new(from.0, from.1), heading_deg);
    let mut out = Vec::new();
    let steps = ((t1 - t0) / 0.1).round() as usize;
    for k in 0..steps {
        let t = t0 + k as f64 * 0.1;
        let d = a.decide(&snap(t, (pos.x, pos.y), h, false));
        out.push((t, a.behaviour()));
        if d.status != PlanStatus::Running {
            break;
        }
        h = d.command.heading.deg();
        pos += Heading::from_deg(h).unit() * (d.command.speed_mps * 0.1) + Vec2::new(0.0, 0.01);
    }
    out
}

#[test]
fn reacquire_never_ends_at_an_op_area_edge() {
    // A lost point 20 m inside the upflow (South) edge: the first Bowtie's centre 10 m upflow of
    // it, its lines reach 48 m further upflow, outside the op-area.
    let run = |p: AmpParams| {
        let mut a = amp_with(p);
        a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
        lose_at(&mut a, &[(200.0, 20.0)]);
        assert_eq!(a.behaviour(), BehaviourKind::Reacquire);
        let goal = a.track_out_goal().unwrap();
        let b = behaviours_flying(&mut a, (goal.x, goal.y), 180.0, (30.0, 3630.0));
        time_in(&b, BehaviourKind::Reacquire, 30.0)
    };
    let paper = run(paper());
    assert!(
        paper.is_infinite(),
        "the paper's Reacquire circles at the edge: {paper}"
    );
    let now = run(AmpParams::default());
    assert!(now < 900.0 + 1.0, "Reacquire ends: {now} s");
}

#[test]
fn reacquire_around_every_lost_point_hands_over_to_find() {
    // Four lost points far apart along the plume, and the plume gone: Reacquire moves from one
    // to the next, at most 15 minutes in all since the last detection, then Find searches on.
    let mut a = amp();
    a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    lose_at(
        &mut a,
        &[
            (200.0, 400.0),
            (150.0, 300.0),
            (250.0, 200.0),
            (200.0, 100.0),
        ],
    );
    assert_eq!(a.behaviour(), BehaviourKind::Reacquire);
    // The last Track-Out arrived at t = 77 s, where Reacquire began.
    let goal = a.track_out_goal().unwrap();
    let b = behaviours_flying(&mut a, (goal.x, goal.y), 180.0, (77.1, 3677.1));
    let t = time_in(&b, BehaviourKind::Reacquire, 77.1);
    assert!(t <= 900.0, "Reacquire for {t} s");
    let next = b.iter().find(|(_, k)| *k != BehaviourKind::Reacquire);
    assert_eq!(next.map(|n| n.1), Some(BehaviourKind::Find));
}

#[test]
fn mapping_never_ends_near_an_edge() {
    // A declaration 5 m inside the East edge: the mapping lines 10 m and 30 m further East lie
    // outside, beyond the cage's reach.
    let run = |p: AmpParams| {
        let mut a = amp_with(p);
        a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
        lose_at(&mut a, &[(395.0, 300.0), (396.0, 298.0), (394.0, 296.5)]);
        assert_eq!(a.behaviour(), BehaviourKind::Mapping);
        let b = behaviours_flying(&mut a, (394.0, 296.5), 180.0, (100.0, 3700.0));
        time_in(&b, BehaviourKind::Mapping, 100.0)
    };
    let paper = run(paper());
    assert!(
        paper.is_infinite(),
        "the paper's mapping never ends: {paper}"
    );
    let now = run(AmpParams::default());
    assert!(now < 1800.0 + 1.0, "mapping ends: {now} s");
}

#[test]
fn a_reversed_flow_reading_does_not_turn_the_search_round() {
    // The flow goes North at 0.1 m/s; from t = 100 s to 400 s the current meter reads it
    // reversed. The paper's planner takes the reading: its upflow turns North.
    let run = |p: AmpParams| {
        let mut a = amp_with(p);
        let reversed = |t: f64| {
            if (100.0..400.0).contains(&t) {
                Vec2::new(0.0, -0.1)
            } else {
                Vec2::new(0.0, 0.1)
            }
        };
        fly_in(
            &mut a,
            (200.0, 500.0),
            0.0,
            (0.0, 350.0),
            |_, _| false,
            reversed,
        );
        // Track-In's course is the upflow direction it believes, offset by beta.
        a.decide(&snap(350.0, (200.0, 500.0), 180.0, true));
        a.last_course().diff_deg(Heading::from_deg(180.0)).abs()
    };
    assert!(
        run(paper()) > 90.0,
        "the paper's upflow follows the faulty reading"
    );
    assert!(
        run(AmpParams::default()) <= 20.0 + 1e-6,
        "upflow stays South"
    );
}

#[test]
fn a_flow_reading_reversed_from_the_start_is_held_back_against_a_given_prior() {
    // The meter reads the northward flow reversed from the first sample. With no history the
    // gate believes it; judged against the mission plan's prior (North) it is held back.
    let run = |trust: bool| {
        let a = amp();
        let mut a = if trust { a.trusting_prior() } else { a };
        fly_in(
            &mut a,
            (200.0, 500.0),
            0.0,
            (0.0, 300.0),
            |_, _| false,
            |_| Vec2::new(0.0, -0.1),
        );
        a.decide(&snap(300.0, (200.0, 500.0), 180.0, true));
        a.last_course().diff_deg(Heading::from_deg(180.0)).abs()
    };
    assert!(
        run(false) > 90.0,
        "no prior: the reversed reading is believed"
    );
    assert!(run(true) <= 20.0 + 1e-6, "upflow stays South");
}

#[test]
fn sparse_fixes_let_the_vehicle_drift_out_before_the_cage_acts() {
    // 8 m inside the East edge, heading East, the last fix 900 s ago: with the assumed drift
    // of 0.02 m/s the navigation may be 18 m off, so the cage turns the vehicle back already.
    let run = |p: AmpParams| {
        let mut a = amp_with(p);
        let mut s = snap(0.0, (392.0, 500.0), 90.0, false);
        a.decide(&s);
        // Find sweeps at psi_f +- 110: heading it East keeps the course East-South-East.
        s.time_s = 900.0;
        s.nav.last_fix_s = Some(0.0);
        for k in 0..20 {
            s.time_s = 900.0 + f64::from(k) * 0.1;
            a.decide(&s);
        }
        let d = a.decide(&s);
        d.command.heading.unit().x
    };
    assert!(run(paper()) > 0.0, "the paper's cage lets the course out");
    assert!(run(AmpParams::default()) < 0.0, "turned back inside");
}

#[test]
fn stale_lost_points_are_searched_after_the_tide_turns() {
    // Lost points set with the flow going North; then the tide turns the flow East over five
    // minutes, and it stays East.
    let run = |p: AmpParams| {
        let mut a = amp_with(p);
        a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
        lose_at(&mut a, &[(200.0, 300.0), (205.0, 280.0)]);
        assert_eq!(a.behaviour(), BehaviourKind::Reacquire);
        let east = |t: f64| {
            let turned = ((t - 40.0) / 300.0).clamp(0.0, 1.0) * std::f64::consts::FRAC_PI_2;
            Vec2::new(turned.sin(), turned.cos()) * 0.1
        };
        fly_in(
            &mut a,
            (205.0, 280.0),
            180.0,
            (40.0, 500.0),
            |_, _| false,
            east,
        );
        (a.behaviour(), a.lost_points().len())
    };
    let (b, n) = run(paper());
    assert!(b == BehaviourKind::Reacquire && n > 0, "{b:?} {n}");
    let (b, n) = run(AmpParams::default());
    assert_eq!((b, n), (BehaviourKind::Find, 0));
}

#[test]
fn no_convergence_near_the_source_in_strong_currents() {
    // Losses near a source in a strong current scatter along the flow. The field list (the
    // oldest point dropped) follows the latest losses, which keep landing downflow: three points
    // within 4 m never coexist. Keeping the most upflow points (most_downflow eviction) lets the
    // points near the source accumulate until three agree. Flow North: upflow is South, so the
    // points nearest the source have the smallest y.
    let losses = [
        (200.0, 300.0),
        (201.0, 340.0),
        (199.0, 302.5),
        (200.0, 360.0),
        (202.0, 330.0),
        (198.0, 350.0),
        (200.0, 345.0),
        (201.0, 355.0),
        (199.0, 303.5),
    ];
    let declared = |p: AmpParams| {
        let mut a = amp_with(p);
        a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
        lose_at(&mut a, &losses).iter().find_map(|e| match e {
            PlannerEvent::Declared { pos_m, .. } => Some(*pos_m),
            _ => None,
        })
    };
    let field = AmpParams {
        lost_point_eviction: LostPointEviction::Oldest,
        ..paper()
    };
    assert_eq!(declared(field), None, "the oldest dropped: no three agree");
    assert_eq!(
        declared(AmpParams {
            declaration_upflow_m: 0.0,
            declaration_across: DeclarationAcross::MostUpflow,
            ..AmpParams::default()
        }),
        Some(Vec2::new(200.0, 300.0))
    );
}

#[test]
fn a_lost_point_that_never_agrees_ages_out() {
    // The most-downflow list keeps an early point 30 m upflow of where the plume is lost from
    // then on; without ageing it blocks the declaration for good.
    let losses = [
        (200.0, 270.0),
        (200.0, 300.0),
        (201.0, 301.5),
        (199.0, 302.5),
    ];
    let run = |age_s: f64| {
        let mut a = amp_with(AmpParams {
            lost_point_max_age_s: age_s,
            ..AmpParams::default()
        });
        a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
        let mut events = lose_at(&mut a, &losses[..1]);
        // Half an hour later the plume is lost three times 30 m downflow of the first point.
        let mut t = 2000.0;
        for &(x, y) in &losses[1..] {
            events.extend(a.decide(&snap(t, (x, y), 180.0, true)).events);
            t += 6.0;
            events.extend(a.decide(&snap(t, (x, y - 1.0), 180.0, false)).events);
            if let Some(goal) = a.track_out_goal() {
                t += 10.0;
                events.extend(a.decide(&snap(t, (goal.x, goal.y), 180.0, false)).events);
            }
            t += 1.0;
            events.extend(confirm_clean(&mut a, &mut t));
        }
        events
            .iter()
            .any(|e| matches!(e, PlannerEvent::Declared { .. }))
    };
    assert!(!run(0.0), "never aged: the upflow point blocks the rule");
    assert!(run(1800.0), "aged out after 30 min: the three agree");
}

/// For the sources on a 20 m grid at least 60 m inside `area`, when `track` first crosses each
/// one's straight plume (from the source northward, the flow's direction, to the edge): the
/// number of sources, and the time by which every plume was crossed (`None`: some never were).
fn plumes_crossed_by(area: &OpArea, track: &[(f64, Vec2, f64)]) -> (usize, Option<f64>) {
    let (mut sources, mut last) = (0, Some(0.0_f64));
    for i in -30..=30 {
        for j in -30..=30 {
            let s = Vec2::new(20.0 * i as f64, 20.0 * j as f64);
            let e = area.edge_info(s);
            if !e.inside || e.distance_m < 60.0 {
                continue;
            }
            sources += 1;
            let mut exit = s.y;
            while area.edge_info(Vec2::new(s.x, exit)).inside {
                exit += 1.0;
            }
            let first = track.windows(2).find_map(|w| {
                let (p, q) = (w[0].1, w[1].1);
                if (p.x - s.x) * (q.x - s.x) > 0.0 || p.x == q.x {
                    return None;
                }
                let y = p.y + (q.y - p.y) * (s.x - p.x) / (q.x - p.x);
                (s.y..=exit).contains(&y).then_some(w[1].0)
            });
            last = last.zip(first).map(|(a, b)| a.max(b));
        }
    }
    (sources, last)
}

#[test]
fn find_crosses_every_plume_of_a_rotated_area() {
    // A 760 m x 330 m area whose long axis lies 67 deg from the flow (towards North), as on the
    // coastal site where the search before the downflow edge came first never found the plume
    // in two hours. Along the downflow edge the vehicle crosses every plume of a source 60 m or
    // more inside within about 11 minutes (the billiard: about 13).
    let axis = Heading::from_deg(67.0).unit();
    let side = Heading::from_deg(157.0).unit();
    let corners = [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)];
    let area = OpArea::new(
        corners
            .iter()
            .map(|(a, b)| axis * (380.0 * a) + side * (165.0 * b))
            .collect(),
    )
    .unwrap();
    let run = |pattern: FindPattern| {
        let p = AmpParams {
            find_pattern: pattern,
            ..AmpParams::default()
        };
        let mut a = Amp::new(p, area.clone(), vec![], Heading::NORTH);
        let start = a.search_start(0);
        let track = fly(&mut a, (start.x, start.y), 90.0, 7200.0, |_, _| false);
        assert_eq!(a.behaviour(), BehaviourKind::Find);
        plumes_crossed_by(&area, &track)
    };
    let (sources, lanes) = run(FindPattern::Lanes);
    let (_, billiard) = run(FindPattern::Billiard);
    assert!(sources > 200, "{sources} sources");
    let lanes = lanes.expect("lanes: every plume crossed");
    assert!(lanes < 900.0, "lanes: every plume crossed after {lanes} s");
    assert!(
        billiard.is_none_or(|b| b > lanes),
        "billiard {billiard:?} s, lanes {lanes} s"
    );
}

#[test]
fn the_search_start_follows_the_flow_estimate() {
    // The prior says the flow goes North, the current meter says East: the way to the search
    // start turns from the northern corners to the eastern ones as the estimate settles.
    let mut a = amp();
    let east = |_: f64| Vec2::new(0.1, 0.0);
    let track = fly_in(
        &mut a,
        (200.0, 500.0),
        0.0,
        (0.0, 150.0),
        |_, _| false,
        east,
    );
    assert_eq!(a.behaviour(), BehaviourKind::GoTo);
    let start = a.search_start(0);
    assert!(start.x > 380.0, "an eastern corner: {start:?}");
    // Still on the way, and heading for it.
    let (_, pos, _) = *track.last().unwrap();
    let bearing = bearing_between(pos, start).unwrap();
    assert!(
        a.last_course().diff_deg(bearing).abs() < 1.0,
        "{}",
        a.last_course().deg()
    );
}

#[test]
fn mapping_from_a_declaration_near_the_upflow_edge_is_flown_without_fixes() {
    // A declaration 40 m inside the upflow (South) edge: the mapping lines start 10 m inside it,
    // heading North. Without navigation fixes the cage acts 20 m inside the edge, so the turn
    // onto each line's start lies where the cage does not let the vehicle go. The approach
    // re-planned for good and the vehicle ran up and down along the cage until the mapping
    // timed out; now each approach gives up after its re-plans and the line is joined from where
    // the vehicle is.
    let mut a = amp();
    a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    lose_at(&mut a, &[(200.0, 42.0), (203.0, 41.0), (197.0, 40.0)]);
    assert_eq!(a.behaviour(), BehaviourKind::Mapping);
    // The mapping starts once the cage has shrunk its area by the full 20 m (t >= 1000 s).
    let (t0, mut pos, mut h) = (1000.0, Vec2::new(197.0, 40.0), 180.0);
    let (mut ended, mut lowest) = (None, f64::INFINITY);
    for k in 0..30_000 {
        let t = t0 + k as f64 * 0.1;
        let d = a.decide(&snap(t, (pos.x, pos.y), h, false));
        if a.behaviour() != BehaviourKind::Mapping {
            ended = Some(t - t0);
            break;
        }
        assert_eq!(d.status, PlanStatus::Running);
        h = d.command.heading.deg();
        pos += Heading::from_deg(h).unit() * (d.command.speed_mps * 0.1) + Vec2::new(0.0, 0.01);
        lowest = lowest.min(pos.y);
    }
    let ended = ended.expect("the mapping ends");
    assert!(
        ended < 600.0,
        "four 70 m lines flown in {ended} s (the mapping timeout is 1,800 s from the declaration)"
    );
    assert!(lowest > 0.0, "stays inside the op-area: y down to {lowest}");
}

#[test]
fn tracing_flies_at_the_track_altitude_and_the_search_at_the_altitude() {
    use plumetrace_core::VerticalCommand;
    let altitude = |d: &plumetrace_core::Decision| match d.command.vertical {
        VerticalCommand::Altitude(a) => a,
        v => panic!("{v:?}"),
    };
    let mut a = amp();
    let d = a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    assert_eq!(altitude(&d), 2.0);
    let d = a.decide(&snap(1.0, (200.0, 500.0), 170.0, true));
    assert_eq!(a.behaviour(), BehaviourKind::TrackIn);
    assert_eq!(altitude(&d), 1.0);
    let d = a.decide(&snap(7.0, (200.0, 495.0), 170.0, false));
    assert_eq!(a.behaviour(), BehaviourKind::TrackOut);
    assert_eq!(altitude(&d), 1.0);
    assert_eq!(AmpParams::default().track_altitude_m, 1.0, "the default");
    // At 0 (the field behaviour) the whole mission flies at altitude_m.
    let mut a = amp_with(AmpParams {
        track_altitude_m: 0.0,
        ..AmpParams::default()
    });
    a.decide(&snap(0.0, (200.0, 500.0), 0.0, false));
    let d = a.decide(&snap(1.0, (200.0, 500.0), 170.0, true));
    assert_eq!(a.behaviour(), BehaviourKind::TrackIn);
    assert_eq!(altitude(&d), 2.0);
}

#[test]
fn a_lost_point_saved_while_flow_readings_were_held_back_moves_with_the_next_fix() {
    // One record a second. The current meter reads North (upflow South) for 20 s, then reads it
    // reversed (held back by the flow gate) until a fix at 60 s jumps the estimate 8 m East.
    // The lost point, saved 16 s into the 40 s held back, had drifted by 16/40 of the jump.
    let fly = |p: AmpParams| {
        let mut a = amp_with(p);
        for k in 0..=60 {
            let t = f64::from(k);
            let mut s = snap(t, (200.0, 299.0), 180.0, k == 30);
            if k == 30 {
                s.nav.pos_m = Some(Vec2::new(200.0, 300.0));
            }
            if k > 20 {
                s.flow = s.flow.map(|f| FlowSample {
                    velocity_mps: -f.velocity_mps,
                    ..f
                });
            }
            if k == 60 {
                s.nav.pos_m = Some(Vec2::new(208.0, 299.0));
                s.nav.last_fix_s = Some(60.0);
            }
            a.decide(&s);
            if k == 36 {
                assert_eq!(a.lost_points(), [Vec2::new(200.0, 300.0)]);
            }
        }
        a.lost_points()
    };
    let moved = fly(held_back_only(AmpParams::default()));
    assert_eq!(moved.len(), 1);
    assert!(
        (moved[0] - Vec2::new(203.2, 300.0)).norm() < 1e-9,
        "{moved:?}"
    );
    let kept = fly(AmpParams {
        fix_smoothing: false,
        ..AmpParams::default()
    });
    assert_eq!(kept, [Vec2::new(200.0, 300.0)]);
}

/// One contact and its loss at `at`, then the Track-Out flown to its goal; `edit` changes each
/// snapshot (the flow reading, the navigation's last fix).
fn lose_edited(
    a: &mut Amp,
    t: &mut f64,
    at: (f64, f64),
    edit: &dyn Fn(SensorSnapshot) -> SensorSnapshot,
) -> Vec<PlannerEvent> {
    let mut events = Vec::new();
    events.extend(a.decide(&edit(snap(*t, at, 180.0, true))).events);
    *t += 6.0;
    events.extend(
        a.decide(&edit(snap(*t, (at.0, at.1 - 1.0), 180.0, false)))
            .events,
    );
    if a.behaviour() == BehaviourKind::TrackOut {
        let goal = a.track_out_goal().unwrap();
        *t += 10.0;
        events.extend(
            a.decide(&edit(snap(*t, (goal.x, goal.y), 180.0, false)))
                .events,
        );
    }
    *t += 1.0;
    events
}

#[test]
fn after_held_back_flow_readings_the_declaration_waits_for_the_next_fix() {
    // A fix at 5 s; from 21 s the current meter reads the current reversed (held back). Three
    // losses within 6 m along the flow would declare at once (no confirming leg here); after
    // held-back readings the check waits for the next fix, and declares at the first Track-Out
    // after it. A navigation that reports no fixes, or fix_wait_s = 0, declares at once.
    let declared = |events: &[PlannerEvent]| {
        events
            .iter()
            .filter(|e| matches!(e, PlannerEvent::Declared { .. }))
            .count()
    };
    let fly = |p: AmpParams, fixes: bool| {
        let mut a = amp_with(held_back_only(AmpParams {
            declaration_confirm_m: 0.0,
            declaration_fix_frames: 1,
            ..p
        }));
        let held_back = move |mut s: SensorSnapshot| {
            if fixes && s.time_s >= 5.0 {
                s.nav.last_fix_s = Some(5.0);
            }
            if s.time_s > 20.0 {
                s.flow = s.flow.map(|f| FlowSample {
                    velocity_mps: -f.velocity_mps,
                    ..f
                });
            }
            s
        };
        let mut events = Vec::new();
        for k in 0..=40 {
            let s = snap(f64::from(k), (200.0, 500.0), 0.0, false);
            events.extend(a.decide(&held_back(s)).events);
        }
        let mut t = 50.0;
        for at in [(200.0, 300.0), (205.0, 298.0), (195.0, 296.5)] {
            events.extend(lose_edited(&mut a, &mut t, at, &held_back));
        }
        (a, events, t)
    };
    let (_, events, _) = fly(AmpParams::default(), false);
    assert_eq!(declared(&events), 1, "no fix reported: nothing to wait for");
    let (_, events, _) = fly(
        AmpParams {
            fix_wait_s: 0.0,
            ..AmpParams::default()
        },
        true,
    );
    assert_eq!(declared(&events), 1, "fix_wait_s = 0: declared at once");

    let (mut a, events, mut t) = fly(AmpParams::default(), true);
    assert_eq!(declared(&events), 0, "waiting for the next fix");
    assert!(a.declarations().is_empty());
    // Readings plausible again, and a fix that does not move the estimate.
    let fixed = move |mut s: SensorSnapshot| {
        s.nav.last_fix_s = Some(if s.time_s >= t + 2.0 { t + 2.0 } else { 5.0 });
        s
    };
    let t0 = t;
    for k in 0..3 {
        let s = snap(t0 + f64::from(k), (195.0, 295.5), 180.0, false);
        a.decide(&fixed(s));
    }
    t = t0 + 3.0;
    let events = lose_edited(&mut a, &mut t, (200.0, 297.0), &fixed);
    assert_eq!(declared(&events), 1, "declared after the fix");
    // 2.5 m upflow (South) of the most upflow of the three most upflow points, at their mean
    // across the flow.
    assert!(
        (a.declarations()[0] - Vec2::new(200.0, 294.0)).norm() < 1e-9,
        "{:?}",
        a.declarations()
    );
}

/// Three losses within 6 m along the flow: a point 2.5 m South of the most upflow, at their mean
/// across, (200, 294).
const THREE_LOSSES: [(f64, f64); 3] = [(200.0, 300.0), (205.0, 298.0), (195.0, 296.5)];

/// Flies `a` for 40 s, then loses the plume at `THREE_LOSSES`, every snapshot edited by `nav`;
/// returns the events and the time after.
fn three_losses(
    a: &mut Amp,
    nav: &dyn Fn(SensorSnapshot) -> SensorSnapshot,
) -> (Vec<PlannerEvent>, f64) {
    let mut events = Vec::new();
    for k in 0..=40 {
        let s = snap(f64::from(k), (200.0, 500.0), 0.0, false);
        events.extend(a.decide(&nav(s)).events);
    }
    let mut t = 50.0;
    for at in THREE_LOSSES {
        events.extend(lose_edited(a, &mut t, at, nav));
    }
    (events, t)
}

/// The declarations among `events`.
fn declared_at(events: &[PlannerEvent]) -> Vec<Vec2> {
    events
        .iter()
        .filter_map(|e| match e {
            PlannerEvent::Declared { pos_m, .. } => Some(*pos_m),
            _ => None,
        })
        .collect()
}

#[test]
fn the_declared_point_is_the_mean_of_points_from_two_fix_frames() {
    // A fix at 5 s. Three losses within 6 m along the flow make a point (2.5 m South of the most
    // upflow, at the mean across: (200, 294)); it is held. Losses in the same frame do not make
    // the next point. A fix at `t_fix` moves the estimate 3 m East and 4 m South: the same three
    // losses, seen there, make (203, 290), and the mean (201.5, 292) is declared. (The held
    // point's lost points stay in the list of six while the next frame's are more upflow.)
    // Only held-back stretches move here (a fix and its smoothing: the next test).
    let p = held_back_only(AmpParams {
        declaration_confirm_m: 0.0,
        ..AmpParams::default()
    });
    assert_eq!(p.declaration_fix_frames, 2, "the default");
    let t_fix = 400.0;
    let nav = move |mut s: SensorSnapshot| {
        if s.time_s >= t_fix {
            s.nav.last_fix_s = Some(t_fix);
            s.nav.pos_m = s.nav.pos_m.map(|q| q + Vec2::new(3.0, -4.0));
        } else if s.time_s >= 5.0 {
            s.nav.last_fix_s = Some(5.0);
        }
        s
    };
    let mut a = amp_with(p.clone());
    let (mut events, mut t) = three_losses(&mut a, &nav);
    let losses = THREE_LOSSES;
    assert!(declared_at(&events).is_empty(), "the first point is held");
    assert!(a.declarations().is_empty());
    for at in losses {
        events.extend(lose_edited(&mut a, &mut t, at, &nav));
    }
    assert!(
        declared_at(&events).is_empty(),
        "losses of the same frame make no second point"
    );
    assert!(t < t_fix, "{t}");
    t = t_fix;
    for at in losses {
        events.extend(lose_edited(&mut a, &mut t, at, &nav));
    }
    let declared = declared_at(&events);
    assert_eq!(declared.len(), 1, "{declared:?}");
    assert!(
        (declared[0] - Vec2::new(201.5, 292.0)).norm() < 1e-9,
        "the mean of (200, 294) and (203, 290): {declared:?}"
    );

    // One frame: declared at once, at the first point (at the defaults too: the point is not
    // held for the fix that ends its frame).
    let mut once = amp_with(AmpParams {
        declaration_fix_frames: 1,
        declaration_confirm_m: 0.0,
        ..AmpParams::default()
    });
    let (events, _) = three_losses(&mut once, &nav);
    let declared = declared_at(&events);
    assert_eq!(declared.len(), 1, "{declared:?}");
    assert!((declared[0] - Vec2::new(200.0, 294.0)).norm() < 1e-9);
}

#[test]
fn each_held_point_moves_with_the_fix_that_ends_its_frame() {
    // Fixes at 5, 400 and 800 s; the estimate jumps by j1 = (3, -4) at 400 s and by
    // j2 = (4, 2) at 800 s, records every second. Frame 1's three losses (saved at 56, 73 and
    // 90 s) make (200, 294), held; frame 2's (at 407, 424 and 441 s), seen 3 m East and 4 m
    // South, make (203, 290), held until the fix at 800 s ends its frame. Each moves by the
    // mean of its lost points' shares of the jump that ends its frame, (16 + 1e-4 t T) /
    // (32 + 1e-4 T^2) at the defaults (fix_error_m 4, fix_drift_mps 0.01), t into a stretch of T;
    // their mean is declared at the fix.
    let p = AmpParams {
        declaration_confirm_m: 0.0,
        ..AmpParams::default()
    };
    assert_eq!(
        (p.fix_error_m, p.fix_drift_mps),
        (4.0, 0.01),
        "the defaults"
    );
    let (j1, j2) = (Vec2::new(3.0, -4.0), Vec2::new(4.0, 2.0));
    let nav = move |mut s: SensorSnapshot| {
        let (fix, offset) = match s.time_s {
            t if t >= 800.0 => (Some(800.0), j1 + j2),
            t if t >= 400.0 => (Some(400.0), j1),
            t if t >= 5.0 => (Some(5.0), Vec2::zeros()),
            _ => (None, Vec2::zeros()),
        };
        s.nav.last_fix_s = fix;
        s.nav.pos_m = s.nav.pos_m.map(|q| q + offset);
        s
    };
    let mut a = amp_with(p);
    // Records every second from `from` up to (not including) `to`, standing still.
    let wait = |a: &mut Amp, from: f64, to: f64| {
        let mut events = Vec::new();
        let mut t = from;
        while t < to {
            events.extend(a.decide(&nav(snap(t, (150.0, 250.0), 90.0, false))).events);
            t += 1.0;
        }
        events
    };
    let (mut events, t) = three_losses(&mut a, &nav);
    assert!(declared_at(&events).is_empty(), "the first point is held");
    // The fix's record where the records before it were: the jump is measured against them.
    events.extend(wait(&mut a, t, 401.0));
    // The fix at 400 s moved each of frame 1's lost points by its share of j1, an event each
    // (the latest saved first) from where it was saved to where the planner now holds it.
    let saved: Vec<Vec2> = events
        .iter()
        .filter_map(|e| match e {
            PlannerEvent::LostPoint { pos_m } => Some(*pos_m),
            _ => None,
        })
        .collect();
    let moved: Vec<(Vec2, Vec2)> = events
        .iter()
        .filter_map(|e| match e {
            PlannerEvent::LostPointMoved { from_m, to_m } => Some((*from_m, *to_m)),
            _ => None,
        })
        .collect();
    assert_eq!((saved.len(), moved.len()), (3, 3), "{events:?}");
    let saved_at = saved.iter().zip([51.0, 68.0, 85.0]);
    for ((from, to), (p, since)) in moved.iter().rev().zip(saved_at) {
        assert_eq!(from, p);
        let share = (16.0 + 1e-4 * since * 395.0) / (32.0 + 1e-4 * 395.0 * 395.0);
        assert!(
            (*to - (*p + j1 * share)).norm() < 1e-9,
            "{from:?} to {to:?}"
        );
        assert!(a.lost_points().contains(to), "{:?}", a.lost_points());
    }
    let mut t = 401.0;
    for at in THREE_LOSSES {
        events.extend(lose_edited(&mut a, &mut t, at, &nav));
    }
    events.extend(wait(&mut a, t, 800.0));
    assert!(
        declared_at(&events).is_empty(),
        "the second point waits for the fix that ends its frame"
    );
    let at_fix = a.decide(&nav(snap(800.0, (150.0, 250.0), 90.0, false)));
    let declared = declared_at(&at_fix.events);
    assert_eq!(
        declared.len(),
        1,
        "declared at the fix: {:?}",
        at_fix.events
    );
    let share = |saved: [f64; 3], span: f64| {
        saved
            .iter()
            .map(|t| (16.0 + 1e-4 * t * span) / (32.0 + 1e-4 * span * span))
            .sum::<f64>()
            / 3.0
    };
    let first = Vec2::new(200.0, 294.0) + j1 * share([51.0, 68.0, 85.0], 395.0);
    let second = Vec2::new(203.0, 290.0) + j2 * share([7.0, 24.0, 41.0], 400.0);
    let expected = (first + second) / 2.0;
    assert!(
        (declared[0] - expected).norm() < 1e-9,
        "expected {expected:?}, declared {declared:?}"
    );
    assert!((expected - Vec2::new(201.5, 292.0)).norm() > 1.0, "moved");
}

#[test]
fn a_fix_during_the_confirming_track_out_moves_the_point_it_confirms() {
    // One frame (declared once the confirming Track-Out ends), a fix at 5 s and another at
    // 300 s that jumps the estimate by j = (6, -3). The three losses (saved at 56, 73 and 90 s)
    // make (200, 294); the confirming leg starts, and the fix during it moves that point by the
    // mean of its lost points' shares of j, (16 + 1e-4 t T) / (32 + 1e-4 T^2) with T = 295 s;
    // the leg then flown to its end declares the moved point.
    let p = AmpParams {
        declaration_fix_frames: 1,
        ..AmpParams::default()
    };
    assert!(p.declaration_confirm_m > 0.0, "the default confirms");
    let j = Vec2::new(6.0, -3.0);
    let offset = move |t: f64| if t >= 300.0 { j } else { Vec2::zeros() };
    let nav = move |mut s: SensorSnapshot| {
        s.nav.last_fix_s = match s.time_s {
            t if t >= 300.0 => Some(300.0),
            t if t >= 5.0 => Some(5.0),
            _ => None,
        };
        s.nav.pos_m = s.nav.pos_m.map(|q| q + offset(s.time_s));
        s
    };
    let mut a = amp_with(p);
    let (events, t) = three_losses(&mut a, &nav);
    assert!(declared_at(&events).is_empty());
    let (at, _) = a.confirming().expect("the confirming leg flies");
    assert!((at - Vec2::new(200.0, 294.0)).norm() < 1e-9, "{at:?}");
    // Standing still (records every second) until the fix: its jump is measured against them.
    let here = (150.0, 250.0);
    let mut t = t;
    while t <= 300.0 {
        a.decide(&nav(snap(t, here, 90.0, false)));
        t += 1.0;
    }
    let share = [51.0, 68.0, 85.0]
        .iter()
        .map(|s| (16.0 + 1e-4 * s * 295.0) / (32.0 + 1e-4 * 295.0 * 295.0))
        .sum::<f64>()
        / 3.0;
    let moved = at + j * share;
    let (now, goals) = a.confirming().expect("still confirming");
    assert!(
        (now - moved).norm() < 1e-9,
        "expected {moved:?}, confirming {now:?}"
    );
    // Fly the legs to their ends (in the estimate's frame, which the fix moved by j).
    let goals = goals.to_vec();
    let mut events = Vec::new();
    for g in goals {
        let true_pos = g - j;
        events.extend(
            a.decide(&nav(snap(t, (true_pos.x, true_pos.y), 90.0, false)))
                .events,
        );
        t += 1.0;
    }
    let declared = declared_at(&events);
    assert_eq!(declared.len(), 1, "{events:?}");
    assert!((declared[0] - moved).norm() < 1e-9, "{declared:?}");
    assert!((moved - at).norm() > 1.0, "the fix moved it");
}

#[test]
fn a_held_point_is_declared_after_the_wait_or_in_the_missions_last_minute() {
    // Fixes at 5 s and never again: the held point waits for a frame that never comes.
    let nav = |mut s: SensorSnapshot| {
        if s.time_s >= 5.0 {
            s.nav.last_fix_s = Some(5.0);
        }
        s
    };
    let fly = |a: &mut Amp, until: f64| {
        let (mut events, mut t) = three_losses(a, &nav);
        assert!(declared_at(&events).is_empty(), "held");
        let held_at = t;
        while t < until && declared_at(&events).is_empty() {
            t += 1.0;
            events.extend(a.decide(&nav(snap(t, (150.0, 250.0), 90.0, false))).events);
        }
        (declared_at(&events), held_at, t)
    };
    let p = AmpParams {
        declaration_confirm_m: 0.0,
        declaration_frame_wait_s: 300.0,
        ..AmpParams::default()
    };
    let mut a = amp_with(p.clone());
    let (declared, held_at, t) = fly(&mut a, 2000.0);
    assert_eq!(declared.len(), 1, "declared after the wait");
    assert!(
        (declared[0] - Vec2::new(200.0, 294.0)).norm() < 1e-9,
        "{declared:?}"
    );
    assert!(t > held_at + 290.0 && t <= held_at + 310.0, "{held_at} {t}");

    // A mission that ends at 500 s: declared in its last minute, before the wait is out.
    let mut a = amp_with(AmpParams {
        declaration_frame_wait_s: 3600.0,
        ..p
    })
    .ending_at(Some(500.0));
    let (declared, _, t) = fly(&mut a, 2000.0);
    assert_eq!(declared.len(), 1);
    assert!((439.0..=441.0).contains(&t), "{t}");
}

/// The AMP at its defaults but declaring without a confirming Track-Out.
fn unconfirmed_amp() -> Amp {
    amp_with(AmpParams {
        declaration_confirm_m: 0.0,
        ..AmpParams::default()
    })
}

/// A navigation that reports one fix, at 5 s.
fn one_fix_at_5_s(mut s: SensorSnapshot) -> SensorSnapshot {
    if s.time_s >= 5.0 {
        s.nav.last_fix_s = Some(5.0);
    }
    s
}

#[test]
fn a_held_point_is_declared_before_a_cage_abort() {
    let nav = one_fix_at_5_s;
    let mut a = unconfirmed_amp();
    let (events, t) = three_losses(&mut a, &nav);
    assert!(declared_at(&events).is_empty(), "held");
    let d = a.decide(&nav(snap(t + 1.0, (-40.0, 300.0), 0.0, false)));
    assert_eq!(d.status, PlanStatus::Abort);
    let declared = declared_at(&d.events);
    assert_eq!(declared.len(), 1, "{:?}", d.events);
    assert!((declared[0] - Vec2::new(200.0, 294.0)).norm() < 1e-9);
    assert_eq!(a.declarations(), declared);
}

#[test]
fn a_run_that_ends_on_its_own_gets_the_held_point_declared() {
    let nav = one_fix_at_5_s;
    let mut a = unconfirmed_amp();
    assert!(a.run_ended(1.0).is_empty(), "nothing held yet");
    let (events, t) = three_losses(&mut a, &nav);
    assert!(declared_at(&events).is_empty(), "held");
    let declared = declared_at(&a.run_ended(t));
    assert_eq!(declared.len(), 1, "{declared:?}");
    assert!((declared[0] - Vec2::new(200.0, 294.0)).norm() < 1e-9);
    assert_eq!(a.declarations(), declared);
    assert!(a.run_ended(t + 1.0).is_empty(), "declared once");
}
