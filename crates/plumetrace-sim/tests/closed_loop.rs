//! Closed-loop tests: onboard guidance driving the simulated AUV in a current, seeing only its
//! navigation estimate.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_core::{Command, Heading, Vec2, VehicleId, VerticalCommand};
use plumetrace_env::{SimRng, StreamId, stream_rng};
use plumetrace_guidance::{
    Cage, CageAction, DoneReason, FollowLine, GoToPoint, ModeStatus, OpArea, Pose, RateFilter,
    compensate_flow, signed_cross_track_m,
};
use plumetrace_sim::{NavParams, Navigator, Vehicle, VehicleParams};
use proptest::prelude::*;

const DT: f64 = 0.1;

struct Rig {
    vehicle: Vehicle,
    nav: Navigator,
    filter: RateFilter,
    rng: SimRng,
    nav_rng: SimRng,
    t: f64,
}

impl Rig {
    fn new(pos: Vec2, heading_deg: f64, nav: NavParams, seed: u64) -> Self {
        let vehicle = Vehicle::new(
            VehicleId(0),
            VehicleParams::auv(),
            pos,
            2.0,
            Heading::from_deg(heading_deg),
        );
        let nav = Navigator::new(nav, &vehicle.state);
        let mut filter = RateFilter::new(10.0);
        filter.reset(vehicle.state.heading);
        Rig {
            vehicle,
            nav,
            filter,
            rng: stream_rng(seed, StreamId::Vehicle(0)),
            nav_rng: stream_rng(seed, StreamId::Sensor(0, 0)),
            t: 0.0,
        }
    }

    fn pose(&self) -> Pose {
        Pose {
            pos_m: self.nav.estimate_m(),
            heading: self.nav.heading(),
        }
    }

    /// One step: compensate the course for the (perfectly measured) flow, rate-filter, drive.
    fn drive(&mut self, course: Heading, speed: f64, flow: Vec2, compensate: bool) {
        let heading = if compensate {
            compensate_flow(course, speed, flow).heading
        } else {
            course
        };
        let heading = self.filter.filter(heading, DT);
        let cmd = Command {
            heading,
            speed_mps: speed,
            vertical: VerticalCommand::Altitude(2.0),
        };
        self.vehicle.step(&cmd, flow, None, DT, &mut self.rng);
        self.t += DT;
        self.nav.update(
            &self.vehicle.state,
            Some(flow),
            self.t,
            DT,
            &mut self.nav_rng,
        );
    }
}

fn perfect_nav() -> NavParams {
    NavParams {
        fix_interval_s: 1e9,
        fix_sigma_m: 0.0,
        velocity_error_sd_mps: 0.0,
        velocity_error_tau_s: 1200.0,
        heading_sd_deg: 0.0,
        ..NavParams::lbl()
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]

    #[test]
    fn go_to_point_arrives_from_any_start(x in -400.0..400.0f64, y in -400.0..400.0f64, h in 0.0..360.0f64, fdir in 0.0..360.0f64, fspeed in 0.0..0.3f64, seed in 0u64..1000) {
        let flow = Heading::from_deg(fdir).unit() * fspeed;
        let mut rig = Rig::new(Vec2::new(x, y), h, NavParams::lbl(), seed);
        let goal = GoToPoint { target_m: Vec2::zeros(), speed_mps: 2.0, radius_m: 10.0 };
        let mut arrived = false;
        for _ in 0..6_000 {
            match goal.update(rig.pose().pos_m) {
                ModeStatus::Running(s) => rig.drive(s.heading, s.speed_mps, flow, true),
                ModeStatus::Done(_) => { arrived = true; break; }
            }
        }
        prop_assert!(arrived, "did not arrive within 600 s from ({x:.0},{y:.0})");
        // Arrival is judged on the estimate; the truth is within the navigation error of it.
        prop_assert!(rig.vehicle.state.pos_m.norm() < 10.0 + 15.0);
    }
}

#[test]
fn follow_line_converges_and_stays_on_the_line() {
    let flow = Vec2::new(0.15, -0.1);
    let (start, end) = (Vec2::new(0.0, 0.0), Vec2::new(0.0, 600.0));
    let mut rig = Rig::new(Vec2::new(-80.0, -60.0), 200.0, perfect_nav(), 1);
    let mut mode = FollowLine::new(start, end, 2.0, 10.0, 5.0, 12.0);
    let mut worst_after_settling = 0.0f64;
    let mut tracked_from = None;
    let mut result = None;
    for _ in 0..8_000 {
        match mode.update(rig.pose()) {
            ModeStatus::Running(s) => rig.drive(s.heading, s.speed_mps, flow, true),
            ModeStatus::Done(r) => {
                result = Some(r);
                break;
            }
        }
        let along = rig.vehicle.state.pos_m.y;
        if matches!(mode.phase(), plumetrace_guidance::FollowLinePhase::Tracking) {
            tracked_from.get_or_insert(along);
            if along > tracked_from.unwrap_or(0.0) + 60.0 {
                worst_after_settling = worst_after_settling
                    .max(signed_cross_track_m(rig.vehicle.state.pos_m, start, end).abs());
            }
        }
    }
    assert_eq!(result, Some(DoneReason::Arrived));
    assert!(
        tracked_from.is_some(),
        "never reached the start of the line"
    );
    eprintln!("largest cross-track error after settling: {worst_after_settling:.2} m");
    assert!(
        worst_after_settling < 3.0,
        "cross-track error {worst_after_settling} m"
    );
}

#[test]
fn a_fix_that_jumps_past_the_end_still_exits_by_condition_10() {
    let (start, end) = (Vec2::new(0.0, 0.0), Vec2::new(0.0, 200.0));
    let mut rig = Rig::new(Vec2::new(0.0, 0.0), 0.0, perfect_nav(), 2);
    let mut mode = FollowLine::tracking(start, end, 2.0, 10.0, 5.0);
    let mut jumped = false;
    let mut result = None;
    for _ in 0..3_000 {
        let pose = rig.pose();
        if !jumped && pose.pos_m.y > 185.0 {
            // A fix puts the vehicle 15 m past the end and 12 m to the side: never within R.
            rig.nav.force_fix(rig.t, Vec2::new(12.0, 215.0));
            jumped = true;
            continue;
        }
        match mode.update(pose) {
            ModeStatus::Running(s) => rig.drive(s.heading, s.speed_mps, Vec2::zeros(), false),
            ModeStatus::Done(r) => {
                result = Some(r);
                break;
            }
        }
    }
    assert!(jumped);
    assert_eq!(result, Some(DoneReason::PassedEnd));
}

/// Drives random heading commands (a new one every 15 s) through the field cage for an hour in a
/// current; returns the fraction of time outside, the furthest excursion and the longest
/// continuous time outside, judged on the estimated position (what the cage sees) and on the
/// true one.
fn random_commands_through_cage(
    nav: NavParams,
    seed: u64,
    judge_estimate: bool,
) -> (f64, f64, f64) {
    let area = OpArea::rectangle(0.0, 300.0, 0.0, 200.0).unwrap();
    let cage = Cage::new(area.clone());
    let flow = Vec2::new(0.1, 0.05);
    let mut rig = Rig::new(Vec2::new(150.0, 100.0), 0.0, nav, seed);
    let mut cmd_rng = stream_rng(seed, StreamId::Custom(1));
    let mut wanted = Heading::NORTH;
    let (mut worst_outside, mut steps_outside, total) = (0.0f64, 0u32, 36_000u32);
    let (mut run, mut longest) = (0u32, 0u32);
    for k in 0..total {
        if k % 150 == 0 {
            use rand::Rng;
            wanted = Heading::from_deg(cmd_rng.random_range(0.0..360.0));
        }
        let pose = rig.pose();
        let action = cage.apply(pose.pos_m, wanted);
        let Some(h) = action.heading() else {
            panic!("aborted at t = {}: {action:?}", rig.t)
        };
        rig.drive(h, 2.0, flow, true);
        let judged = if judge_estimate {
            rig.pose().pos_m
        } else {
            rig.vehicle.state.pos_m
        };
        let e = area.edge_info(judged);
        if e.inside {
            run = 0;
        } else {
            steps_outside += 1;
            run += 1;
            longest = longest.max(run);
            worst_outside = worst_outside.max(e.distance_m);
        }
    }
    (
        f64::from(steps_outside) / f64::from(total),
        worst_outside,
        f64::from(longest) * DT,
    )
}

#[test]
fn cage_brings_the_vehicle_back_under_random_commands_without_aborting() {
    let cases = [
        ("perfect navigation, truth", perfect_nav(), false),
        ("lbl navigation, estimate", NavParams::lbl(), true),
        ("lbl navigation, truth", NavParams::lbl(), false),
    ];
    for (name, nav, judge_estimate) in cases {
        let (frac, worst, longest) = random_commands_through_cage(nav, 3, judge_estimate);
        eprintln!(
            "cage, {name}: {:.1} % of the hour outside, at most {worst:.1} m out, longest excursion {longest:.0} s",
            100.0 * frac
        );
        // Never at the abort distance (the run would have panicked), and never close to it.
        assert!(worst < 30.0, "{name}: {worst} m outside");
        if name == "lbl navigation, truth" {
            // The truth can stay outside while the estimate is inside: only the distance counts.
            continue;
        }
        if !judge_estimate {
            // About 1.6 turning radii: the turn a straight-out command needs at the edge.
            assert!(worst < 20.0, "{name}: {worst} m outside");
        }
        assert!(longest < 60.0, "{name}: outside for {longest} s in a row");
        assert!(
            frac < 0.25,
            "{name}: outside {:.1} % of the time",
            100.0 * frac
        );
    }
}

#[test]
fn cage_aborts_when_a_fix_puts_the_vehicle_far_outside() {
    let cage = Cage::new(OpArea::rectangle(0.0, 300.0, 0.0, 200.0).unwrap());
    let mut rig = Rig::new(Vec2::new(150.0, 190.0), 0.0, perfect_nav(), 4);
    rig.nav.force_fix(0.0, Vec2::new(150.0, 235.0));
    assert!(
        matches!(cage.apply(rig.pose().pos_m, Heading::NORTH), CageAction::Abort { distance_outside_m } if (distance_outside_m - 35.0).abs() < 1e-9)
    );
    rig.nav.force_fix(0.0, Vec2::new(150.0, 225.0));
    assert_eq!(
        cage.apply(rig.pose().pos_m, Heading::NORTH),
        CageAction::ReturnInside(Heading::from_deg(180.0))
    );
}

#[test]
fn flow_compensation_holds_the_ground_track_in_a_strong_cross_current() {
    // 0.5 m/s cross current (East) at 2 m/s, goal 600 m North.
    let flow = Vec2::new(0.5, 0.0);
    let run = |compensate: bool| {
        let mut rig = Rig::new(Vec2::zeros(), 0.0, perfect_nav(), 5);
        let goal = GoToPoint {
            target_m: Vec2::new(0.0, 600.0),
            speed_mps: 2.0,
            radius_m: 10.0,
        };
        let mut worst = 0.0f64;
        for _ in 0..10_000 {
            match goal.update(rig.pose().pos_m) {
                ModeStatus::Running(s) => rig.drive(s.heading, s.speed_mps, flow, compensate),
                ModeStatus::Done(_) => return (true, worst, rig.t),
            }
            worst = worst.max(rig.vehicle.state.pos_m.x.abs());
        }
        (false, worst, rig.t)
    };
    let (arrived, off_track, t) = run(true);
    let (_, off_track_plain, t_plain) = run(false);
    eprintln!(
        "cross current: compensated {off_track:.2} m off track in {t:.0} s; uncompensated {off_track_plain:.1} m in {t_plain:.0} s"
    );
    assert!(arrived);
    assert!(off_track < 2.0, "compensated track strays {off_track} m");
    assert!(
        off_track_plain > 5.0 * off_track.max(0.5),
        "compensation made no difference"
    );
    // Ground speed along the track: sqrt(2^2 - 0.5^2) = 1.94 m/s, so about 590 m / 1.94 = 305 s.
    assert!((t - 590.0 / 1.936).abs() < 20.0, "took {t} s");
}
