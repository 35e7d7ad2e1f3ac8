//! Property tests of the guidance modes.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_core::{Heading, Vec2};
use plumetrace_guidance::{
    Cage, FollowLine, GoToPoint, GoToPointWithHeading, ModeStatus, OpArea, Pose, RateFilter,
    compensate_flow, csc_candidates, shortest_csc,
};
use proptest::prelude::*;

fn pose() -> impl Strategy<Value = Pose> {
    (-200.0..200.0f64, -200.0..200.0f64, 0.0..360.0f64).prop_map(|(x, y, h)| Pose {
        pos_m: Vec2::new(x, y),
        heading: Heading::from_deg(h),
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn csc_paths_join_the_poses_respect_the_radius_and_the_shortest_is_chosen(a in pose(), b in pose(), r in 3.0..40.0f64) {
        let path = shortest_csc(a, b, r).expect("LSL and RSR always exist");
        let len = path.length_m();
        prop_assert!(len + 1e-9 >= (b.pos_m - a.pos_m).norm(), "shorter than the straight line: {len}");
        let s = path.sample(0.0);
        prop_assert!((s.pos_m - a.pos_m).norm() < 1e-6 && s.heading.diff_deg(a.heading).abs() < 1e-6);
        let e = path.sample(len);
        prop_assert!((e.pos_m - b.pos_m).norm() < 1e-6, "ends at {:?}, not {:?}", e.pos_m, b.pos_m);
        prop_assert!(e.heading.diff_deg(b.heading).abs() < 1e-6);
        // Curvature: heading change per metre never exceeds 1 / r.
        let step = 0.25;
        let n = (len / step).ceil() as usize;
        let mut prev = path.sample(0.0);
        for k in 1..=n {
            let s_m = (k as f64 * step).min(len);
            let q = path.sample(s_m);
            let ds = (q.pos_m - prev.pos_m).norm().max(1e-12);
            let turn = q.heading.diff_deg(prev.heading).abs().to_radians();
            prop_assert!(turn <= (s_m - ((k - 1) as f64 * step).min(len)) / r * (1.0 + 1e-6) + 1e-9, "turns tighter than r at {s_m} m (ds {ds})");
            prev = q;
        }
        let candidates = csc_candidates(a, b, r);
        prop_assert!(candidates.len() >= 2);
        let min = candidates.iter().map(|c| c.length_m()).fold(f64::INFINITY, f64::min);
        prop_assert!((min - len).abs() < 1e-9, "chosen {len}, shortest candidate {min}");
    }

    #[test]
    fn no_mode_returns_a_non_finite_command(
        x in -1e6..1e6f64, y in -1e6..1e6f64, h in -1e3..1e3f64,
        tx in -1e6..1e6f64, ty in -1e6..1e6f64, th in 0.0..360.0f64,
        fe in -5.0..5.0f64, fn_ in -5.0..5.0f64, speed in 0.0..3.0f64, dt in 0.0..10.0f64,
    ) {
        let p = Pose { pos_m: Vec2::new(x, y), heading: Heading::from_deg(h) };
        let target = Vec2::new(tx, ty);
        let check = |s: ModeStatus| -> Result<(), TestCaseError> {
            if let ModeStatus::Running(st) = s {
                prop_assert!(st.heading.rad().is_finite() && st.speed_mps.is_finite());
            }
            Ok(())
        };
        check(GoToPoint { target_m: target, speed_mps: speed, radius_m: 10.0 }.update(p.pos_m))?;
        check(FollowLine::new(Vec2::new(0.0, 0.0), target, speed, 10.0, 5.0, 12.0).update(p))?;
        check(FollowLine::tracking(target, target, speed, 10.0, 5.0).update(p))?;
        let mut g = GoToPointWithHeading::new(Pose { pos_m: target, heading: Heading::from_deg(th) }, speed, 10.0, 12.0);
        check(g.update(p))?;
        check(g.update(p))?;
        let cage = Cage::new(OpArea::rectangle(-500.0, 500.0, -300.0, 300.0).unwrap());
        if let Some(hh) = cage.apply(p.pos_m, p.heading).heading() {
            prop_assert!(hh.rad().is_finite());
        }
        let c = compensate_flow(p.heading, speed, Vec2::new(fe, fn_));
        prop_assert!(c.heading.rad().is_finite() && c.speed_mps.is_finite() && c.ground_speed_mps.is_finite());
        let mut f = RateFilter::new(10.0);
        f.reset(Heading::from_deg(th));
        prop_assert!(f.filter(p.heading, dt).rad().is_finite());
    }

    #[test]
    fn rate_filter_never_exceeds_its_limit(start in 0.0..360.0f64, cmds in proptest::collection::vec((0.0..720.0f64, 0.0..2.0f64), 1..60), rate in 0.5..30.0f64) {
        let mut f = RateFilter::new(rate);
        let mut last = Heading::from_deg(start);
        f.reset(last);
        for (c, dt) in cmds {
            let out = f.filter(Heading::from_deg(c), dt);
            prop_assert!(out.diff_deg(last).abs() <= rate * dt + 1e-9, "turned {} in {dt} s at {rate} deg/s", out.diff_deg(last));
            last = out;
        }
    }

    #[test]
    fn cage_never_points_further_out_than_the_command(x in -20.0..120.0f64, y in -20.0..120.0f64, h in 0.0..360.0f64) {
        let area = OpArea::rectangle(0.0, 100.0, 0.0, 100.0).unwrap();
        let cage = Cage::new(area.clone());
        let cmd = Heading::from_deg(h);
        let e = area.edge_info(Vec2::new(x, y));
        match cage.apply(Vec2::new(x, y), cmd).heading() {
            Some(out) if e.inside => prop_assert!(out.unit().dot(&e.outward_normal) <= cmd.unit().dot(&e.outward_normal).max(0.0) + 1e-9),
            Some(out) => prop_assert!(out.unit().dot(&e.outward_normal) < -0.999),
            None => prop_assert!(e.distance_m > 30.0),
        }
    }
}
