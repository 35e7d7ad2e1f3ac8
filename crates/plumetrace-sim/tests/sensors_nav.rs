//! Statistical tests of the chemical detector and the navigation estimate.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_core::{Command, Heading, Vec2, VehicleId, VerticalCommand};
use plumetrace_env::{StreamId, stream_rng};
use plumetrace_sim::{ChemSensor, ChemSensorParams, NavParams, Navigator, Vehicle, VehicleParams};

/// Standard normal CDF (Abramowitz and Stegun 7.1.26, error below 1.5e-7).
fn phi(x: f64) -> f64 {
    let z = x.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * z);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erfc = poly * (-z * z).exp();
    if x >= 0.0 {
        1.0 - 0.5 * erfc
    } else {
        0.5 * erfc
    }
}

#[test]
fn readings_exceed_a_threshold_at_the_rate_the_noise_gives() {
    // A planner's 0.2 V threshold, noise 0.05 V, 1 V per unit: P(detect) = 1 - Phi((0.2 - c) / 0.05).
    let params = ChemSensorParams {
        noise_sd_v: 0.05,
        ..ChemSensorParams::default()
    };
    let mut rng = stream_rng(3, StreamId::Sensor(0, 0));
    for c in [0.0, 0.1, 0.15, 0.2, 0.25, 0.3, 1.0] {
        let mut s = ChemSensor::new(params);
        let n = 40_000;
        let hits = (0..n)
            .filter(|k| s.sample(c, f64::from(*k) * 0.1, &mut rng).reading > 0.2)
            .count();
        let rate = hits as f64 / f64::from(n);
        let want = 1.0 - phi((0.2 - c) / 0.05);
        assert!(
            (rate - want).abs() < 0.01,
            "c = {c}: detection rate {rate:.4}, expected {want:.4}"
        );
    }
}

#[test]
fn navigation_error_grows_between_fixes_and_jumps_back_at_each() {
    let params = NavParams {
        fix_interval_s: 200.0,
        fix_sigma_m: 0.5,
        velocity_error_sd_mps: 0.03,
        velocity_error_tau_s: 600.0,
        heading_sd_deg: 0.5,
        ..NavParams::lbl()
    };
    let mut v = Vehicle::new(
        VehicleId(0),
        VehicleParams::auv(),
        Vec2::zeros(),
        2.0,
        Heading::from_deg(45.0),
    );
    let mut nav = Navigator::new(params, &v.state);
    let mut rng = stream_rng(4, StreamId::Vehicle(0));
    let mut nav_rng = stream_rng(4, StreamId::Sensor(0, 9));
    let cmd = Command {
        heading: Heading::from_deg(45.0),
        speed_mps: 2.0,
        vertical: VerticalCommand::Altitude(2.0),
    };
    let dt = 0.1;
    let mut fixes = Vec::new();
    let mut error_before_fix = Vec::new();
    let mut error_after_fix = Vec::new();
    let mut error_mid = Vec::new();
    for k in 1..=20_000u32 {
        let t = f64::from(k) * dt;
        v.step(&cmd, Vec2::new(0.1, 0.0), None, dt, &mut rng);
        let before = (nav.estimate_m() - v.state.pos_m).norm();
        // Measured flow without bias: the error comes from the drifting dead-reckoning velocity.
        if let Some(fix) = nav.update(&v.state, Some(Vec2::new(0.1, 0.0)), t, dt, &mut nav_rng) {
            fixes.push(fix);
            error_before_fix.push(before);
            error_after_fix.push((nav.estimate_m() - v.state.pos_m).norm());
        }
        if (t % 200.0 - 100.0).abs() < dt / 2.0 {
            error_mid.push((nav.estimate_m() - v.state.pos_m).norm());
        }
    }
    assert_eq!(fixes.len(), 10, "fixes at 200, 400, ..., 2000 s");
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (b, m, a) = (
        mean(&error_before_fix),
        mean(&error_mid),
        mean(&error_after_fix),
    );
    eprintln!("navigation error: mid-interval {m:.2} m, before fix {b:.2} m, after fix {a:.2} m");
    assert!(
        b > m && m > a,
        "error should grow between fixes and drop at them: {a} {m} {b}"
    );
    assert!(
        b > 3.0 * a,
        "fixes should pull the estimate back: before {b}, after {a}"
    );
    assert!(fixes.iter().all(|f| (f.jump_m() - 0.0).abs() > 0.0));
}

#[test]
fn dead_reckoning_drift_is_stationary_and_matches_the_gauss_markov_variance() {
    // A vehicle at rest: every metre the estimate moves between fixes is velocity error.
    let params = NavParams {
        fix_interval_s: 300.0,
        fix_sigma_m: 0.0,
        velocity_error_sd_mps: 0.01,
        velocity_error_tau_s: 1200.0,
        heading_sd_deg: 0.0,
        ..NavParams::lbl()
    };
    let v = Vehicle::new(
        VehicleId(0),
        VehicleParams::auv(),
        Vec2::zeros(),
        0.0,
        Heading::NORTH,
    );
    let mut nav = Navigator::new(params, &v.state);
    let mut rng = stream_rng(11, StreamId::Sensor(0, 9));
    let dt = 0.5;
    let mut drifts = Vec::new();
    for k in 1..=(1_200_000 / 5) as u32 {
        let t = f64::from(k) * dt;
        if let Some(fix) = nav.update(&v.state, None, t, dt, &mut rng) {
            drifts.push(fix.before_m - fix.after_m);
        }
    }
    // Skip the first two correlation times (the error starts at zero).
    let drifts = &drifts[8..];
    let sd = |d: &[Vec2]| {
        (d.iter().map(|p| p.x * p.x + p.y * p.y).sum::<f64>() / (2.0 * d.len() as f64)).sqrt()
    };
    // Variance of the integral of a stationary Gauss-Markov process over T:
    // 2 s^2 tau^2 (T / tau - 1 + exp(-T / tau)).
    let (s, tau, t) = (0.01_f64, 1200.0_f64, 300.0_f64);
    let want = (2.0 * s * s * tau * tau * (t / tau - 1.0 + (-t / tau).exp())).sqrt();
    let (first, second) = drifts.split_at(drifts.len() / 2);
    let (all, a, b) = (sd(drifts), sd(first), sd(second));
    eprintln!("drift per axis over 300 s: {all:.2} m (theory {want:.2}); halves {a:.2}, {b:.2}");
    assert!((all / want - 1.0).abs() < 0.15, "{all} vs {want}");
    assert!(
        (a / b - 1.0).abs() < 0.3,
        "drift should not grow with mission time: {a} then {b}"
    );
}
