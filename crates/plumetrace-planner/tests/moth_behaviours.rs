//! Each behaviour of the moth-inspired planner, driven by hand-built sensor snapshots.
//!
//! The op-area is the square 0..100 m x 0..100 m; the flow goes East (90 deg) at 0.5 m/s, so
//! up-flow is West (270 deg) and the offset across the flow from the centre line is `y - 50`
//! (positive on the left of the flow, looking down-flow). Courses are read before flow
//! compensation and the rate filter (`Moth::last_course`).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_core::{
    BehaviourKind, ChemSample, FlowSample, Heading, NavEstimate, PlanStatus, Planner, PlannerEvent,
    SensorSnapshot, Vec2, VehicleId, bearing_between,
};
use plumetrace_guidance::OpArea;
use plumetrace_planner::{Moth, MothParams, MothStrategy};

fn snap(t: f64, pos: Vec2, detection: bool) -> SensorSnapshot {
    SensorSnapshot {
        time_s: t,
        vehicle: VehicleId(0),
        nav: NavEstimate {
            pos_m: Some(pos),
            heading: Heading::from_deg(270.0),
            speed_mps: 1.2,
            altitude_m: Some(2.0),
            depth_m: None,
            last_fix_s: None,
        },
        // Above and below the default 0.2 V threshold.
        chem: vec![ChemSample {
            time_s: t,
            reading: if detection { 1.0 } else { 0.05 },
        }],
        flow: Some(FlowSample {
            time_s: t,
            velocity_mps: Vec2::new(0.5, 0.0),
        }),
        ranges: None,
        inbox: vec![],
    }
}

fn moth(strategy: MothStrategy) -> Moth {
    let area = OpArea::rectangle(0.0, 100.0, 0.0, 100.0).unwrap();
    Moth::new(
        MothParams {
            maintain_plume: strategy,
            ..MothParams::default()
        },
        area,
        Heading::from_deg(90.0),
    )
}

/// Wrapped difference of two compass angles, deg.
fn diff(a: Heading, b_deg: f64) -> f64 {
    a.diff_deg(Heading::from_deg(b_deg)).abs()
}

/// Decisions every 0.5 s from `t0` to `t1` (inclusive) at `pos`, without detections.
fn hold(m: &mut Moth, t0: f64, t1: f64, pos: Vec2) -> Vec<PlannerEvent> {
    let mut events = Vec::new();
    let mut k = 0;
    while t0 + 0.5 * f64::from(k) <= t1 + 1e-9 {
        events.extend(m.decide(&snap(t0 + 0.5 * f64::from(k), pos, false)).events);
        k += 1;
    }
    events
}

#[test]
fn find_plume_alternates_up_and_down_flow_legs_towards_the_centre_line() {
    let mut m = moth(MothStrategy::Passive);
    // North of the centre line (eta = +30 m): flow direction + 125 deg = 215 deg (across and
    // up-flow, back towards the line) for T_up = 40 s ...
    let north = Vec2::new(50.0, 80.0);
    let events = hold(&mut m, 0.0, 39.5, north);
    assert_eq!(m.behaviour(), BehaviourKind::Find);
    assert!(events.contains(&PlannerEvent::Behaviour {
        behaviour: BehaviourKind::Find
    }));
    assert!(
        diff(m.last_course(), 215.0) < 1e-9,
        "{}",
        m.last_course().deg()
    );
    // ... then + 60 deg = 150 deg (across and down-flow) for T_down = 20 s, then up again.
    hold(&mut m, 40.0, 59.5, north);
    assert!(
        diff(m.last_course(), 150.0) < 1e-9,
        "{}",
        m.last_course().deg()
    );
    hold(&mut m, 60.0, 60.0, north);
    assert!(
        diff(m.last_course(), 215.0) < 1e-9,
        "{}",
        m.last_course().deg()
    );
    // South of the line (eta = -30 m) the sign flips: 90 - 125 = 325 deg.
    hold(&mut m, 60.5, 61.0, Vec2::new(50.0, 20.0));
    assert!(
        diff(m.last_course(), 325.0) < 1e-9,
        "{}",
        m.last_course().deg()
    );
    // Within 20 m of the line the side is kept (no chatter along the line).
    hold(&mut m, 61.5, 62.0, Vec2::new(50.0, 60.0));
    assert!(
        diff(m.last_course(), 325.0) < 1e-9,
        "{}",
        m.last_course().deg()
    );
    // At the up-flow (West) edge an up-flow leg becomes a down-flow one: 90 - 60 = 30 deg.
    hold(&mut m, 62.5, 63.0, Vec2::new(4.0, 20.0));
    assert!(
        diff(m.last_course(), 30.0) < 1e-9,
        "{}",
        m.last_course().deg()
    );
}

#[test]
fn passive_track_in_runs_up_flow_and_track_out_casts_to_either_side_in_turn() {
    let mut m = moth(MothStrategy::Passive);
    hold(&mut m, 0.0, 5.0, Vec2::new(60.0, 50.0));
    let d = m.decide(&snap(5.5, Vec2::new(60.0, 50.0), true));
    assert_eq!(m.behaviour(), BehaviourKind::TrackIn);
    assert!(d.events.contains(&PlannerEvent::Detection {
        pos_m: Vec2::new(60.0, 50.0)
    }));
    assert!(
        diff(m.last_course(), 270.0) < 1e-9,
        "{}",
        m.last_course().deg()
    );
    // Still Track-In 8.5 s (lambda) after the detection, Track-Out after it.
    hold(&mut m, 6.0, 14.0, Vec2::new(55.0, 50.0));
    assert_eq!(m.behaviour(), BehaviourKind::TrackIn);
    hold(&mut m, 14.5, 14.5, Vec2::new(55.0, 50.0));
    assert_eq!(m.behaviour(), BehaviourKind::TrackOut);
    let first = m.last_course().diff_deg(Heading::from_deg(270.0));
    assert!((first.abs() - 10.0).abs() < 1e-9, "{first}");
    // A second contact and loss: the cast goes to the other side.
    m.decide(&snap(20.0, Vec2::new(50.0, 50.0), true));
    assert!(diff(m.last_course(), 270.0) < 1e-9);
    hold(&mut m, 20.5, 29.0, Vec2::new(45.0, 50.0));
    assert_eq!(m.behaviour(), BehaviourKind::TrackOut);
    let second = m.last_course().diff_deg(Heading::from_deg(270.0));
    assert!((second + first).abs() < 1e-9, "{first} then {second}");
    // Track-Out lasts track_out_s (8.5 s); then Reacquire.
    hold(&mut m, 29.5, 37.0, Vec2::new(45.0, 50.0));
    assert_eq!(m.behaviour(), BehaviourKind::TrackOut);
    hold(&mut m, 37.5, 37.5, Vec2::new(45.0, 50.0));
    assert_eq!(m.behaviour(), BehaviourKind::Reacquire);
}

#[test]
fn active_track_in_counter_turns_and_track_out_turns_back_to_the_side_it_left_on() {
    let mut m = moth(MothStrategy::Active);
    hold(&mut m, 0.0, 1.0, Vec2::new(60.0, 50.0));
    // First contact: up-flow offset by 20 deg one way, the next contact the other way.
    m.decide(&snap(1.5, Vec2::new(60.0, 50.0), true));
    let a = m.last_course().diff_deg(Heading::from_deg(270.0));
    assert!((a.abs() - 20.0).abs() < 1e-9, "{a}");
    // The vehicle leaves the plume on its left looking up-flow (West): South of the last
    // detection. Track-Out turns left of up-flow, towards that side: 260 deg.
    hold(&mut m, 2.0, 10.0, Vec2::new(55.0, 50.0));
    hold(&mut m, 10.5, 10.5, Vec2::new(55.0, 46.0));
    assert_eq!(m.behaviour(), BehaviourKind::TrackOut);
    assert!(
        diff(m.last_course(), 260.0) < 1e-9,
        "{}",
        m.last_course().deg()
    );
    m.decide(&snap(15.0, Vec2::new(50.0, 50.0), true));
    let b = m.last_course().diff_deg(Heading::from_deg(270.0));
    assert!((a + b).abs() < 1e-9, "counter-turn: {a} then {b}");
    // Left on the right (North): Track-Out turns right of up-flow, 280 deg.
    hold(&mut m, 15.5, 23.5, Vec2::new(45.0, 50.0));
    hold(&mut m, 24.0, 24.0, Vec2::new(45.0, 54.0));
    assert_eq!(m.behaviour(), BehaviourKind::TrackOut);
    assert!(
        diff(m.last_course(), 280.0) < 1e-9,
        "{}",
        m.last_course().deg()
    );
}

#[test]
fn reacquire_flies_the_cloverleaf_around_the_last_detection_then_finds() {
    let mut m = moth(MothStrategy::Passive);
    let centre = Vec2::new(60.0, 50.0);
    hold(&mut m, 0.0, 1.0, centre);
    m.decide(&snap(1.5, centre, true));
    // lambda + Track-Out = 17 s after the detection: Reacquire.
    hold(&mut m, 2.0, 18.5, Vec2::new(52.0, 50.0));
    assert_eq!(m.behaviour(), BehaviourKind::TrackOut);
    // Subgoals: leaf tips 15 m from the centre, starting up-flow (West) and turning clockwise
    // (North, East, South), each flown out and back; N_re = 3 times.
    let tips = [(-15.0, 0.0), (0.0, 15.0), (15.0, 0.0), (0.0, -15.0)];
    let mut goals = Vec::new();
    for _ in 0..3 {
        for (dx, dy) in tips {
            goals.push(centre + Vec2::new(dx, dy));
            goals.push(centre);
        }
    }
    let mut t = 19.0;
    let mut pos = Vec2::new(52.0, 50.0);
    for (k, goal) in goals.iter().enumerate() {
        m.decide(&snap(t, pos, false));
        assert_eq!(m.behaviour(), BehaviourKind::Reacquire, "subgoal {k}");
        let want = bearing_between(pos, *goal).unwrap();
        assert!(
            m.last_course().diff_deg(want).abs() < 1e-6,
            "subgoal {k} at {goal:?}: course {} from {pos:?}, want {}",
            m.last_course().deg(),
            want.deg()
        );
        // Half-way there, still the same subgoal.
        t += 0.5;
        let half = pos + (goal - pos) * 0.5;
        m.decide(&snap(t, half, false));
        assert!(m.last_course().diff_deg(want).abs() < 1e-6, "subgoal {k}");
        // Reached within r_m (3 m): the next one. Arrive 1 m short, slightly off the leg.
        t += 0.5;
        let dir = (goal - half) / (goal - half).norm();
        pos = goal - dir + Vec2::new(dir.y, -dir.x) * 0.5;
    }
    // After the last leaf, Find.
    m.decide(&snap(t, pos, false));
    assert_eq!(m.behaviour(), BehaviourKind::Find);
}

#[test]
fn a_cloverleaf_tip_beyond_the_edge_is_drawn_inside() {
    let mut m = moth(MothStrategy::Passive);
    // A detection 5 m from the up-flow (West) edge: the first tip (15 m West) would be 10 m
    // outside; it is drawn back to the margin (8 m inside the edge), on the same leaf.
    let centre = Vec2::new(12.0, 50.0);
    hold(&mut m, 0.0, 1.0, centre);
    m.decide(&snap(1.5, centre, true));
    hold(&mut m, 2.0, 18.5, Vec2::new(20.0, 50.0));
    m.decide(&snap(19.0, Vec2::new(20.0, 50.0), false));
    assert_eq!(m.behaviour(), BehaviourKind::Reacquire);
    // Heading West, towards (8, 50); 4 m from it, still West.
    assert!(diff(m.last_course(), 270.0) < 1e-6);
    m.decide(&snap(19.5, Vec2::new(12.0, 50.0), false));
    assert!(diff(m.last_course(), 270.0) < 1e-6);
    // Within r_m (3 m) of x = 8: the tip is reached, and so is the centre 1.5 m away; the next
    // goal is the North tip (a tip at x = -3 would still lie ahead, West).
    let at = Vec2::new(10.5, 50.0);
    m.decide(&snap(20.0, at, false));
    let north_tip = bearing_between(at, Vec2::new(12.0, 65.0)).unwrap();
    assert!(
        m.last_course().diff_deg(north_tip).abs() < 1e-6,
        "the tip is at x = 8: on to the next leaf, {}",
        m.last_course().deg()
    );
}

/// Six contacts (detections more than lambda apart) whose most up-flow points span `span_m`
/// along the flow; returns the decision events and the final status.
fn six_contacts(span_m: f64) -> (Vec<PlannerEvent>, PlanStatus, Moth) {
    let mut m = moth(MothStrategy::Passive);
    let mut events = Vec::new();
    let mut status = PlanStatus::Running;
    for k in 0..6 {
        let t = 20.0 * f64::from(k) + 1.0;
        // Contacts in a shuffled order along the flow, 0.3 m apart across it.
        let along = [0.0, 1.0, 0.2, 0.6, 0.8, 0.4][k as usize] * span_m;
        let p = Vec2::new(60.0 - along, 50.0 + 0.3 * f64::from(k));
        let d = m.decide(&snap(t, p, true));
        events.extend(d.events);
        status = d.status;
        if status != PlanStatus::Running {
            break;
        }
        // Out of the plume until the next contact.
        for j in 1..38 {
            let d = m.decide(&snap(t + 0.5 * f64::from(j), Vec2::new(70.0, 50.0), false));
            events.extend(d.events);
        }
    }
    (events, status, m)
}

#[test]
fn declaration_fires_at_4_9_m_and_not_at_5_1_m() {
    let (events, status, m) = six_contacts(4.9);
    assert_eq!(status, PlanStatus::Finished);
    // Declared at the most up-flow point (West: the smallest x), 4.9 m up-flow of the first.
    let want = Vec2::new(60.0 - 4.9, 50.0 + 0.3);
    assert!(events.contains(&PlannerEvent::Declared {
        pos_m: want,
        rule: plumetrace_planner::amp::ALONG_FLOW
    }));
    assert_eq!(m.declared(), Some(want));
    assert_eq!(m.contact_points().len(), 6);

    let (events, status, m) = six_contacts(5.1);
    assert_eq!(status, PlanStatus::Running);
    assert!(
        !events
            .iter()
            .any(|e| matches!(e, PlannerEvent::Declared { .. }))
    );
    assert_eq!(m.declared(), None);
}

#[test]
fn five_contacts_never_declare_and_a_contact_keeps_its_most_up_flow_detection() {
    let mut m = moth(MothStrategy::Passive);
    for k in 0..5 {
        let t = 20.0 * f64::from(k) + 1.0;
        // Within one contact the vehicle moves up-flow 2 m between two detections.
        m.decide(&snap(t, Vec2::new(60.0, 50.0), true));
        let d = m.decide(&snap(t + 1.0, Vec2::new(58.0, 50.0), true));
        assert_eq!(d.status, PlanStatus::Running);
        hold(&mut m, t + 11.0, t + 11.0, Vec2::new(70.0, 50.0));
    }
    assert_eq!(m.contact_points(), vec![Vec2::new(58.0, 50.0); 5]);
    assert_eq!(m.declared(), None);
}

#[test]
fn the_planner_moves_to_the_field_from_outside_it() {
    let mut m = moth(MothStrategy::Passive);
    // 20 m South of the area: straight North, to 8 m inside.
    m.decide(&snap(0.0, Vec2::new(50.0, -20.0), false));
    assert_eq!(m.behaviour(), BehaviourKind::GoTo);
    assert!(diff(m.last_course(), 0.0) < 1e-9);
    m.decide(&snap(0.5, Vec2::new(50.0, 9.0), false));
    assert_eq!(m.behaviour(), BehaviourKind::Find);
}
