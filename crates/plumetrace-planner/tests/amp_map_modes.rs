//! The AMP's `map_declaration` modes (off, instead, also, refine), driven by hand-built sensor
//! snapshots: which rule declares, when, and where.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_core::{
    BehaviourKind, ChemSample, DeclarationKind, FlowSample, Heading, NavEstimate, PlanStatus,
    Planner, PlannerEvent, SensorSnapshot, Telemetry, Vec2, VehicleId,
};
use plumetrace_guidance::OpArea;
use plumetrace_planner::amp::{DeclarationAcross, MapDeclaration};
use plumetrace_planner::{Amp, AmpParams, MapKeys};

/// Flow towards North at 0.1 m/s: upflow is South.
fn snap(t: f64, pos: Vec2, heading_deg: f64, detection: bool) -> SensorSnapshot {
    SensorSnapshot {
        time_s: t,
        vehicle: VehicleId(0),
        nav: NavEstimate {
            pos_m: Some(pos),
            heading: Heading::from_deg(heading_deg),
            speed_mps: 2.0,
            altitude_m: Some(2.0),
            depth_m: None,
            last_fix_s: None,
        },
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

fn amp(mode: MapDeclaration, map_can_declare: bool) -> Amp {
    let p = AmpParams {
        map_declaration: mode,
        map: MapKeys {
            // A map rule that holds after a handful of detections, or one that never does.
            map_mass: if map_can_declare { 0.01 } else { 1.0 },
            map_min_detections: if map_can_declare { 3 } else { 1_000_000 },
            map_check_s: 0.0,
            // At once (the hold has its own tests with the map's tracker).
            map_hold_s: 0.0,
            // The most likely cell's centre is declared (the local mean has its own test with
            // the map).
            map_estimate_radius_m: 0.0,
            ..AmpParams::default().map
        },
        // The lost-point rule declares the most upflow lost point itself (the field placement).
        declaration_upflow_m: 0.0,
        declaration_across: DeclarationAcross::MostUpflow,
        // At the check's own time (the confirming Track-Out has its own test).
        declaration_confirm_m: 0.0,
        ..AmpParams::default()
    };
    let area = OpArea::rectangle(0.0, 400.0, 0.0, 1000.0).unwrap();
    Amp::new(p, area, vec![], Heading::NORTH)
}

/// What a run of decisions produced.
#[derive(Default)]
struct Log {
    /// `(time, position, rule)` of every declaration.
    declared: Vec<(f64, Vec2, DeclarationKind)>,
    /// `(time, peak)` of every map read reported.
    peaks: Vec<(f64, Vec2)>,
    /// Times at which a map raster was reported.
    rasters: Vec<f64>,
}

impl Log {
    fn take(&mut self, t: f64, a: &mut Amp, s: &SensorSnapshot) {
        let d = a.decide(s);
        for e in &d.events {
            if let PlannerEvent::Declared { pos_m, rule } = e {
                self.declared.push((t, *pos_m, rule.clone()));
            }
        }
        for x in &d.telemetry {
            match x {
                Telemetry::SourceMap { peak_m, .. } => self.peaks.push((t, *peak_m)),
                Telemetry::SourceMapRaster { .. } => self.rasters.push(t),
                _ => {}
            }
        }
    }
}

/// Loses the plume at `points` in turn (detect at each, wait out lambda, arrive at the Track-Out
/// goal), as the lost-point tests do: three points close along the flow declare under the field
/// rule. Returns the time of each Track-Out arrival.
fn lose_at(a: &mut Amp, log: &mut Log, points: &[(f64, f64)]) -> Vec<f64> {
    let mut arrivals = Vec::new();
    log.take(0.0, a, &snap(0.0, Vec2::new(200.0, 500.0), 0.0, false));
    let mut t = 10.0;
    for &(x, y) in points {
        // A short burst of detections (the map needs a few), then silence.
        for k in 0..5 {
            let tk = t + k as f64 * 0.2;
            log.take(tk, a, &snap(tk, Vec2::new(x, y), 180.0, true));
        }
        t += 6.0;
        log.take(t, a, &snap(t, Vec2::new(x, y - 1.0), 180.0, false));
        if a.behaviour() != BehaviourKind::TrackOut {
            break;
        }
        let goal = a.track_out_goal().unwrap();
        t += 10.0;
        log.take(t, a, &snap(t, goal, 180.0, false));
        arrivals.push(t);
        t += 1.0;
    }
    arrivals
}

const CLOSE: [(f64, f64); 3] = [(200.0, 300.0), (205.0, 298.0), (195.0, 296.5)];

/// When the lost-point rule alone declares on [`CLOSE`].
fn lost_point_declaration_s() -> f64 {
    let mut a = amp(MapDeclaration::Off, false);
    let mut log = Log::default();
    lose_at(&mut a, &mut log, &CLOSE);
    log.declared[0].0
}

#[test]
fn off_keeps_no_map_and_declares_by_lost_points() {
    let mut a = amp(MapDeclaration::Off, true);
    assert!(a.source_map().is_none());
    let mut log = Log::default();
    lose_at(&mut a, &mut log, &CLOSE);
    assert_eq!(
        log.declared
            .iter()
            .map(|d| (d.1, d.2.clone()))
            .collect::<Vec<_>>(),
        vec![(Vec2::new(195.0, 296.5), plumetrace_planner::amp::ALONG_FLOW)]
    );
    assert!(log.peaks.is_empty() && log.rasters.is_empty());
}

#[test]
fn instead_ignores_the_lost_point_rule() {
    // The map's rule never holds: three close lost points do not declare, the AMP reacquires.
    let mut a = amp(MapDeclaration::Instead, false);
    assert!(a.source_map().is_some());
    let mut log = Log::default();
    let arrivals = lose_at(&mut a, &mut log, &CLOSE);
    assert_eq!(arrivals.len(), 3);
    assert!(log.declared.is_empty(), "{:?}", log.declared);
    assert_eq!(a.behaviour(), BehaviourKind::Reacquire);
    // The map is read and reported all along.
    assert!(!log.peaks.is_empty());
}

#[test]
fn instead_declares_the_maps_peak_as_soon_as_its_rule_holds() {
    let mut a = amp(MapDeclaration::Instead, true);
    let mut log = Log::default();
    let arrivals = lose_at(&mut a, &mut log, &CLOSE);
    assert_eq!(log.declared.len(), 1, "{:?}", log.declared);
    let (t, at, rule) = log.declared[0].clone();
    assert_eq!(rule, plumetrace_planner::estimate::tracker::SOURCE_MAP);
    // During a burst of detections, before the lost points agree (the lost-point rule alone
    // declares at the third Track-Out arrival).
    assert!(t < lost_point_declaration_s(), "{t}");
    assert!(arrivals.len() < 3, "{arrivals:?}");
    // At the map's most likely cell as reported at that decision, with its raster.
    let peak = log.peaks.iter().rev().find(|p| p.0 == t).unwrap().1;
    assert_eq!(at, peak);
    assert!(log.rasters.contains(&t));
    assert_eq!(a.declarations(), [at]);
    assert_eq!(a.behaviour(), BehaviourKind::Mapping);
}

#[test]
fn also_declares_by_whichever_rule_holds_first() {
    // The map's rule holds first.
    let mut a = amp(MapDeclaration::Also, true);
    let mut log = Log::default();
    lose_at(&mut a, &mut log, &CLOSE);
    assert_eq!(log.declared.len(), 1, "{:?}", log.declared);
    assert_eq!(
        log.declared[0].2,
        plumetrace_planner::estimate::tracker::SOURCE_MAP
    );
    assert!(log.declared[0].0 < lost_point_declaration_s());
    // The map's rule never holds: the lost-point rule declares at the most upflow point.
    let mut a = amp(MapDeclaration::Also, false);
    let mut log = Log::default();
    let arrivals = lose_at(&mut a, &mut log, &CLOSE);
    assert_eq!(
        log.declared,
        vec![(
            arrivals[2],
            Vec2::new(195.0, 296.5),
            plumetrace_planner::amp::ALONG_FLOW
        )]
    );
}

#[test]
fn refine_declares_when_the_lost_points_agree_at_the_maps_peak_if_its_rule_holds() {
    let mut a = amp(MapDeclaration::Refine, true);
    let mut log = Log::default();
    let arrivals = lose_at(&mut a, &mut log, &CLOSE);
    // Not at the first bursts (the map's rule held there already): at the third Track-Out
    // arrival, where the lost-point rule holds.
    assert_eq!(arrivals.len(), 3);
    assert_eq!(log.declared.len(), 1, "{:?}", log.declared);
    let (t, at, rule) = log.declared[0].clone();
    assert_eq!(
        (t, rule),
        (
            arrivals[2],
            plumetrace_planner::estimate::tracker::SOURCE_MAP
        )
    );
    let peak = log.peaks.iter().rev().find(|p| p.0 == t).unwrap().1;
    assert_eq!(at, peak);
    assert_ne!(at, Vec2::new(195.0, 296.5));
    // The map's most likely cell lies upflow (South) of the detections, near them across.
    assert!(at.y < 300.0 && (at.x - 200.0).abs() < 15.0, "{at:?}");
    // Without the map's rule, the lost point is declared.
    let mut a = amp(MapDeclaration::Refine, false);
    let mut log = Log::default();
    let arrivals = lose_at(&mut a, &mut log, &CLOSE);
    assert_eq!(
        log.declared,
        vec![(
            arrivals[2],
            Vec2::new(195.0, 296.5),
            plumetrace_planner::amp::ALONG_FLOW
        )]
    );
}

#[test]
fn the_map_declares_only_in_a_searching_behaviour() {
    // Once declared, the AMP maps and further map reads declare nothing more.
    let mut a = amp(MapDeclaration::Instead, true);
    let mut log = Log::default();
    lose_at(&mut a, &mut log, &CLOSE);
    assert_eq!(a.behaviour(), BehaviourKind::Mapping);
    let mut t = 200.0;
    for _ in 0..50 {
        log.take(t, &mut a, &snap(t, Vec2::new(200.0, 290.0), 180.0, true));
        t += 1.0;
    }
    assert_eq!(log.declared.len(), 1);
    assert_eq!(a.declarations().len(), 1);
    let d = a.decide(&snap(t, Vec2::new(200.0, 290.0), 180.0, false));
    assert_eq!(d.status, PlanStatus::Running);
}
