//! Statistical tests of the plume physics. Each asserts a number against theory with a tolerance.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_core::{Vec2, Vec3};
use plumetrace_env::flow::{FarrellFlow, FarrellParams, MeanFlow, UniformFlow};
use plumetrace_env::plume::Dispersion;
use plumetrace_env::steady::GaussianPlume;
use plumetrace_env::{
    ConcentrationField, Environment, FilamentParams, FilamentPlume, FlowModel, GridSpec,
    MeanConcentrationGrid, ObstacleSet, Plume, Rect, SoftObstacle, Source, StreamId,
    VerticalBoundary, stream_rng,
};

fn rect(x0: f64, x1: f64, y0: f64, y1: f64) -> Rect {
    Rect::new(x0, x1, y0, y1).unwrap()
}

fn east(speed: f64) -> MeanFlow {
    MeanFlow::Steady {
        speed_mps: speed,
        toward_deg: 90.0,
    }
}

fn filament_env(
    domain: Rect,
    flow: FlowModel,
    source: Source,
    params: FilamentParams,
    dt: f64,
    seed: u64,
) -> Environment {
    let plume = FilamentPlume::new(domain, vec![source], params).unwrap();
    Environment::new(
        domain,
        flow,
        Plume::Filaments(Box::new(plume)),
        ObstacleSet::default(),
        dt,
        seed,
    )
    .unwrap()
}

fn filaments(env: &Environment) -> &FilamentPlume {
    env.plume().filaments().unwrap()
}

/// The grid over `(x0, x1, y0, y1)` of `(nx, ny)` points at height `z`.
fn grid(bounds: (f64, f64, f64, f64), (nx, ny): (usize, usize), z: f64) -> GridSpec {
    let (x_min_m, x_max_m, y_min_m, y_max_m) = bounds;
    GridSpec {
        x_min_m,
        x_max_m,
        y_min_m,
        y_max_m,
        nx,
        ny,
        z_m: z,
    }
}

fn run(env: &mut Environment, seconds: f64) {
    let n = (seconds / env.dt_s()).round() as u64;
    for _ in 0..n {
        env.step().unwrap();
    }
}

#[test]
fn released_mass_matches_rate_times_time() {
    let domain = rect(0.0, 100.0, -50.0, 50.0);
    let src = Source {
        pos_m: Vec3::new(5.0, 0.0, 1.0),
        mass_rate_per_s: 3.0,
        filament_rate_hz: 20.0,
    };
    let flow = FlowModel::Uniform(UniformFlow::new(east(1.0)).unwrap());
    let mut env = filament_env(domain, flow, src, FilamentParams::default(), 0.05, 1);
    run(&mut env, 200.0);
    let s = filaments(&env).stats();
    // Poisson count over 200 s at 20 /s: mean 4000, sd 63.
    let expected = 20.0 * 200.0;
    let z = (s.released as f64 - expected) / expected.sqrt();
    assert!(
        z.abs() < 4.0,
        "released {} filaments, expected {expected} (z = {z:.2})",
        s.released
    );
    let mass_expected = 3.0 * 200.0;
    assert!(
        (s.released_mass - mass_expected).abs() / mass_expected < 4.0 / expected.sqrt(),
        "released mass {}",
        s.released_mass
    );
    // Every released filament is either alive or has left through the domain edge.
    assert_eq!(s.released, s.live as u64 + s.exited);
    let accounted = filaments(&env).live_mass() + s.exited_mass;
    assert!(
        (accounted - s.released_mass).abs() < 1e-9 * s.released_mass,
        "mass not conserved: {accounted} vs {}",
        s.released_mass
    );
    assert!(
        s.exited > 0,
        "nothing reached the downflow edge in 200 s at 1 m/s"
    );
}

#[test]
fn filament_cap_suppresses_and_counts() {
    let domain = rect(0.0, 100.0, -50.0, 50.0);
    let src = Source {
        pos_m: Vec3::new(5.0, 0.0, 1.0),
        mass_rate_per_s: 1.0,
        filament_rate_hz: 50.0,
    };
    let flow = FlowModel::Uniform(UniformFlow::new(east(0.5)).unwrap());
    let params = FilamentParams {
        max_filaments: 100,
        ..FilamentParams::default()
    };
    let mut env = filament_env(domain, flow, src, params, 0.1, 2);
    run(&mut env, 20.0);
    let s = filaments(&env).stats();
    assert_eq!(s.live, 100);
    assert!(s.suppressed > 800, "suppressed {}", s.suppressed);
}

#[test]
fn concentration_integrates_to_live_mass_with_seabed_reflection() {
    // Filaments near the seabed: the image term must return the mass that would leak below z = 0.
    let domain = rect(-20.0, 20.0, -20.0, 20.0);
    let src = Source {
        pos_m: Vec3::new(0.0, 0.0, 0.2),
        mass_rate_per_s: 2.0,
        filament_rate_hz: 1.0,
    };
    let params = FilamentParams {
        dispersion: Dispersion::Physical {
            horizontal_m2ps: 0.0,
            vertical_m2ps: 0.0,
        },
        init_radius_m: 0.5,
        growth_rate_m2ps: 0.0,
        cutoff_radii: 5.0,
        ..FilamentParams::default()
    };
    let mut plume = FilamentPlume::new(domain, vec![src], params).unwrap();
    plume.release_at_source(0, 3);
    let h = 0.05;
    let mut total = 0.0;
    for i in -60..=60 {
        for j in -60..=60 {
            for k in 0..=60 {
                let w = if k == 0 { 0.5 } else { 1.0 };
                total += w * plume.concentration(Vec3::new(
                    f64::from(i) * h,
                    f64::from(j) * h,
                    f64::from(k) * h,
                ));
            }
        }
    }
    total *= h * h * h;
    let mass = plume.live_mass();
    assert!((mass - 6.0).abs() < 1e-12);
    assert!(
        (total - mass).abs() / mass < 0.01,
        "integral {total}, mass {mass}"
    );
}

/// Time-averaged cross-flow profile variance at `x` from a mean-concentration line.
fn profile_variance(grid: &MeanConcentrationGrid) -> f64 {
    let spec = grid.spec();
    let mean = grid.mean();
    let dy = (spec.y_max_m - spec.y_min_m) / (spec.ny - 1) as f64;
    let (mut m0, mut m1, mut m2) = (0.0, 0.0, 0.0);
    for j in 0..spec.ny {
        let y = spec.y_min_m + j as f64 * dy;
        let c: f64 = (0..spec.nx).map(|i| mean[j * spec.nx + i]).sum();
        m0 += c;
        m1 += c * y;
        m2 += c * y * y;
    }
    let mu = m1 / m0;
    m2 / m0 - mu * mu
}

/// The time-averaged cross-flow variance of a plume in a uniform 1 m/s current at 25, 55 and
/// 85 m from the source (5 m), the plume stepped at `dt` and sampled after each of `steps`
/// steps, with the theory `2 K t + r0^2 + gamma t` beside each.
fn crossflow_variances(dt: f64, steps: usize) -> Vec<(f64, f64, f64)> {
    let (k_h, gamma, u) = (0.05, 0.001, 1.0);
    let domain = rect(0.0, 100.0, -50.0, 50.0);
    let src = Source {
        pos_m: Vec3::new(5.0, 0.0, 5.0),
        mass_rate_per_s: 20.0,
        filament_rate_hz: 20.0,
    };
    let params = FilamentParams {
        dispersion: Dispersion::Physical {
            horizontal_m2ps: k_h,
            vertical_m2ps: 0.001,
        },
        growth_rate_m2ps: gamma,
        vertical: VerticalBoundary::Unbounded,
        ..FilamentParams::default()
    };
    let flow = FlowModel::Uniform(UniformFlow::new(east(u)).unwrap());
    let mut env = filament_env(domain, flow, src, params, dt, 3);
    run(&mut env, 100.0);
    let xs = [25.0, 55.0, 85.0];
    let mut grids: Vec<MeanConcentrationGrid> = xs
        .iter()
        .map(|&x| {
            let spec = GridSpec {
                x_min_m: x - 0.2,
                x_max_m: x + 0.2,
                y_min_m: -15.0,
                y_max_m: 15.0,
                nx: 3,
                ny: 301,
                z_m: 5.0,
            };
            MeanConcentrationGrid::new(spec, 0.0)
        })
        .collect();
    for _ in 0..steps {
        env.step().unwrap();
        for g in &mut grids {
            g.accumulate(env.plume());
        }
    }
    grids
        .iter()
        .zip(xs)
        .map(|(g, x)| {
            let t = (x - 5.0) / u;
            let theory = 2.0 * k_h * t + params.init_radius_m.powi(2) + gamma * t;
            (x, profile_variance(g), theory)
        })
        .collect()
}

#[test]
fn mean_crossflow_profile_widens_as_diffusivity_predicts() {
    let mut previous = 0.0;
    for (x, got, theory) in crossflow_variances(0.05, 6000) {
        eprintln!("x = {x} m: profile variance {got:.3} m^2, theory {theory:.3} m^2");
        assert!(
            (got - theory).abs() / theory < 0.10,
            "x = {x}: variance {got}, theory {theory}"
        );
        assert!(got > previous);
        previous = got;
    }
}

#[test]
fn a_coarse_plume_step_keeps_the_crossflow_spread() {
    // Steps 40 times longer (2 s: a filament moves 2 m per step, 4 % of the way to the
    // farthest section), sampled over 1,200 s: the same spread as theory within 10 %.
    for (x, got, theory) in crossflow_variances(2.0, 600) {
        eprintln!("dt 2 s, x = {x} m: profile variance {got:.3} m^2, theory {theory:.3} m^2");
        assert!(
            (got - theory).abs() / theory < 0.10,
            "x = {x}: variance {got}, theory {theory}"
        );
    }
}

#[test]
fn a_long_step_releases_a_stream_not_a_clump() {
    // 50 filaments/s for one 10 s step in a 0.2 m/s current: births spread over the step, each
    // filament carried for its own age, so the new filaments lie along the 2 m the water moved.
    let domain = rect(0.0, 100.0, -50.0, 50.0);
    let src = Source {
        pos_m: Vec3::new(10.0, 0.0, 5.0),
        mass_rate_per_s: 1.0,
        filament_rate_hz: 50.0,
    };
    let params = FilamentParams {
        dispersion: Dispersion::Physical {
            horizontal_m2ps: 1e-6,
            vertical_m2ps: 1e-6,
        },
        ..FilamentParams::default()
    };
    let flow = FlowModel::Uniform(UniformFlow::new(east(0.2)).unwrap());
    let mut env = filament_env(domain, flow, src, params, 10.0, 4);
    env.step().unwrap();
    let p = filaments(&env);
    let d: Vec<f64> = p.filaments().map(|(q, _)| q.x - 10.0).collect();
    assert!(d.len() > 400, "{} filaments", d.len());
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    let (lo, hi) = d
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(*x), b.max(*x))
        });
    // Uniform over [0, 2 m]: mean 1 m (sd of the mean 0.03 m), extremes near the ends.
    assert!((mean - 1.0).abs() < 0.15, "mean distance {mean}");
    assert!(
        (-0.01..0.05).contains(&lo) && hi > 1.95 && hi <= 2.01,
        "{lo} .. {hi}"
    );
    // Their radii follow their own ages: from r0 up to the radius after 10 s.
    let r2: Vec<f64> = p.filaments().map(|(_, r2)| r2).collect();
    let r0sq = params.init_radius_m.powi(2);
    let oldest = r0sq + params.growth_rate_m2ps * 10.0;
    assert!(r2.iter().all(|r| *r >= r0sq && *r <= oldest + 1e-12));
    assert!(r2.iter().any(|r| *r < r0sq + 0.1 * (oldest - r0sq)));
}

#[test]
fn dropping_filaments_beyond_the_sink_changes_no_other_filament() {
    // The same plume with and without a sink 300 m downflow (source at 50 m, 0.1 m/s east):
    // each filament's random walk depends on its own key only, so the plume that keeps its
    // filaments holds, in order, every filament of the one that drops them, bit for bit, and
    // readings short of the sink are the same bits.
    let domain = rect(0.0, 1000.0, -100.0, 100.0);
    let src = Source {
        pos_m: Vec3::new(50.0, 0.0, 0.0),
        mass_rate_per_s: 2.0,
        filament_rate_hz: 2.0,
    };
    let flow = || FlowModel::Uniform(UniformFlow::new(east(0.1)).unwrap());
    let params = FilamentParams {
        dispersion: Dispersion::Physical {
            horizontal_m2ps: 0.05,
            vertical_m2ps: 0.002,
        },
        growth_rate_m2ps: 0.002,
        init_radius_m: 0.1,
        ..FilamentParams::default()
    };
    let mut keep = filament_env(domain, flow(), src, params, 1.0, 8);
    let mut drop = filament_env(domain, flow(), src, params, 1.0, 8);
    if let Plume::Filaments(p) = drop.plume_mut() {
        p.set_sink(Some(plumetrace_env::DownflowSink {
            dir: [1.0, 0.0],
            beyond_m: 300.0,
        }));
    }
    run(&mut keep, 4000.0);
    run(&mut drop, 4000.0);
    let (a, b) = (filaments(&keep), filaments(&drop));
    assert!(b.stats().dropped > 500, "{:?}", b.stats());
    assert_eq!(a.stats().released, b.stats().released);
    // Every filament is accounted for: live, exited or dropped, and so is the mass.
    let sb = b.stats();
    assert_eq!(sb.released, sb.live as u64 + sb.exited + sb.dropped);
    let accounted = b.live_mass() + sb.exited_mass + sb.dropped_mass;
    assert!((accounted - sb.released_mass).abs() <= 1e-9 * sb.released_mass);
    // Filaments beyond the sink go in batches (when they are a thirty-second of the plume), so
    // a few may still be there, none of them within reach of x < 300 m.
    let widest = (0.1f64.powi(2) + 0.002 * 4000.0).sqrt() * 3.0;
    let lingering = b
        .filaments()
        .filter(|(q, r2)| q.x - 3.0 * r2.sqrt() > 300.0 + widest)
        .count();
    assert!(lingering * 32 <= b.len(), "{lingering} of {}", b.len());
    let mut all = a.filaments();
    let mut matched = 0;
    for (q, r2) in b.filaments() {
        assert!(
            all.any(|(p, s2)| p == q && s2 == r2),
            "filament {q:?} of the dropping plume is not in the other"
        );
        matched += 1;
    }
    assert_eq!(matched, b.len());
    assert!(a.len() > b.len() + 500);
    for k in 0..400 {
        let p = Vec3::new(60.0 + 0.6 * k as f64, -3.0 + 0.015 * k as f64, 0.5);
        assert_eq!(
            keep.sample_concentration(p).to_bits(),
            drop.sample_concentration(p).to_bits(),
            "at {p:?}"
        );
    }
}

fn pompy_farrell(domain: Rect, dt: f64) -> FlowModel {
    FlowModel::Farrell(Box::new(
        FarrellFlow::new(domain, east(1.0), FarrellParams::default(), dt).unwrap(),
    ))
}

#[test]
fn intermittency_falls_with_downflow_distance() {
    let domain = rect(0.0, 100.0, -50.0, 50.0);
    // Field-like release (5 /s) and a growth rate that dilutes filaments as they age.
    let src = Source {
        pos_m: Vec3::new(5.0, 0.0, 0.0),
        mass_rate_per_s: 5.0,
        filament_rate_hz: 5.0,
    };
    let params = FilamentParams {
        vertical: VerticalBoundary::Unbounded,
        growth_rate_m2ps: 0.02,
        ..FilamentParams::default()
    };
    // An ocean-like meander: corner noise sd 0.35 m/s against a 1 m/s mean.
    let fp = FarrellParams {
        noise_gain: 0.5,
        ..FarrellParams::default()
    };
    let flow = FlowModel::Farrell(Box::new(
        FarrellFlow::new(domain, east(1.0), fp, 0.05).unwrap(),
    ));
    let mut env = filament_env(domain, flow, src, params, 0.05, 4);
    run(&mut env, 100.0);
    let spec = GridSpec {
        x_min_m: 15.0,
        x_max_m: 75.0,
        y_min_m: -2.0,
        y_max_m: 2.0,
        nx: 3,
        ny: 3,
        z_m: 0.0,
    };
    // Threshold 0.5: about an eighth of the near-source ribbon concentration.
    let mut grid = MeanConcentrationGrid::new(spec, 0.5);
    for k in 0..12_000 {
        env.step().unwrap();
        if k % 2 == 0 {
            grid.accumulate(env.plume()); // 10 Hz, like the field sensor
        }
    }
    let inter = grid.intermittency();
    // Average over the three cross-flow points of each column (x = 15, 45, 75 m).
    let col = |i: usize| (0..3).map(|j| inter[j * 3 + i]).sum::<f64>() / 3.0;
    let (near, mid, far) = (col(0), col(1), col(2));
    eprintln!("fraction above threshold: x=15 m {near:.3}, x=45 m {mid:.3}, x=75 m {far:.3}");
    assert!(
        near > mid && mid > far,
        "not decreasing: {near} {mid} {far}"
    );
    assert!(far < 0.5 * near, "far {far} vs near {near}");
    assert!(
        near < 0.9,
        "near-source points are not intermittent: {near}"
    );
}

/// Standard deviation over time of the mean cross-flow position of filaments in a slab.
fn centroid_wander(env: &mut Environment, x0: f64, x1: f64, samples: usize) -> f64 {
    let mut centroids = Vec::new();
    for _ in 0..samples {
        run(env, 1.0);
        let ys: Vec<f64> = filaments(env)
            .filaments()
            .filter(|(p, _)| p.x >= x0 && p.x < x1)
            .map(|(p, _)| p.y)
            .collect();
        if ys.len() >= 5 {
            centroids.push(ys.iter().sum::<f64>() / ys.len() as f64);
        }
    }
    let m = centroids.iter().sum::<f64>() / centroids.len() as f64;
    (centroids.iter().map(|c| (c - m).powi(2)).sum::<f64>() / centroids.len() as f64).sqrt()
}

#[test]
fn centreline_meanders_under_farrell_flow_but_not_uniform_flow() {
    let domain = rect(0.0, 100.0, -50.0, 50.0);
    let src = Source {
        pos_m: Vec3::new(5.0, 0.0, 0.0),
        mass_rate_per_s: 20.0,
        filament_rate_hz: 20.0,
    };
    let params = FilamentParams::default();
    let mut farrell = filament_env(domain, pompy_farrell(domain, 0.05), src, params, 0.05, 5);
    let mut uniform = filament_env(
        domain,
        FlowModel::Uniform(UniformFlow::new(east(1.0)).unwrap()),
        src,
        params,
        0.05,
        5,
    );
    run(&mut farrell, 100.0);
    run(&mut uniform, 100.0);
    let wf = centroid_wander(&mut farrell, 55.0, 65.0, 400);
    let wu = centroid_wander(&mut uniform, 55.0, 65.0, 400);
    eprintln!("centreline wander at 60 m: farrell {wf:.2} m, uniform {wu:.2} m");
    assert!(wu < 0.5, "uniform flow plume wanders {wu} m");
    assert!(
        wf > 3.0 && wf > 10.0 * wu,
        "farrell {wf} m vs uniform {wu} m"
    );
}

#[test]
fn bottom_source_reaches_vehicle_altitude_only_downflow_as_theory_says() {
    // Source on the seabed, vehicle 2 m above it: the time-averaged concentration at 2 m
    // must match the seabed-reflected Gaussian plume with the filament growth folded in.
    let (u, k_h, k_v, gamma) = (0.5, 0.02, 0.005, 0.001);
    let domain = rect(0.0, 150.0, -40.0, 40.0);
    let src = Source {
        pos_m: Vec3::new(5.0, 0.0, 0.0),
        mass_rate_per_s: 10.0,
        filament_rate_hz: 10.0,
    };
    let params = FilamentParams {
        dispersion: Dispersion::Physical {
            horizontal_m2ps: k_h,
            vertical_m2ps: k_v,
        },
        growth_rate_m2ps: gamma,
        ..FilamentParams::default()
    };
    let mut env = filament_env(
        domain,
        FlowModel::Uniform(UniformFlow::new(east(u)).unwrap()),
        src,
        params,
        0.1,
        6,
    );
    run(&mut env, 300.0);
    let xs = [10.0, 30.0, 60.0, 120.0];
    let mut grids: Vec<MeanConcentrationGrid> = xs
        .iter()
        .map(|&x| {
            let spec = GridSpec {
                x_min_m: x - 0.5,
                x_max_m: x + 0.5,
                y_min_m: -12.0,
                y_max_m: 12.0,
                nx: 3,
                ny: 97,
                z_m: 2.0,
            };
            MeanConcentrationGrid::new(spec, 0.0)
        })
        .collect();
    for _ in 0..15_000 {
        env.step().unwrap();
        for g in &mut grids {
            g.accumulate(env.plume());
        }
    }
    // Equivalent steady plume: the filament's own growth adds gamma / 2 to each diffusivity.
    let theory = GaussianPlume::new(
        src.pos_m,
        10.0,
        u,
        90.0,
        k_h + gamma / 2.0,
        k_v + gamma / 2.0,
        None,
    )
    .unwrap();
    let mut integrals = Vec::new();
    for (g, x) in grids.iter().zip(xs) {
        // Cross-flow integral of the mean concentration at 2 m, against theory.
        let spec = g.spec();
        let dy = (spec.y_max_m - spec.y_min_m) / (spec.ny - 1) as f64;
        let mean = g.mean();
        let got: f64 = (0..spec.ny).map(|j| mean[j * 3 + 1]).sum::<f64>() * dy;
        let want: f64 = (0..spec.ny)
            .map(|j| theory.concentration(Vec3::new(x, spec.y_min_m + j as f64 * dy, 2.0)))
            .sum::<f64>()
            * dy;
        eprintln!("x = {x} m: integral at 2 m {got:.4e}, theory {want:.4e}");
        integrals.push((got, want));
    }
    // Within 2 m of... the source the plume has not reached 2 m yet.
    assert!(
        integrals[0].0 < 0.05 * integrals[2].0,
        "near-source {:.3e} vs 60 m {:.3e}",
        integrals[0].0,
        integrals[2].0
    );
    for &(got, want) in &integrals[1..] {
        assert!(
            (got - want).abs() / want < 0.2,
            "integral {got} vs theory {want}"
        );
    }
}

#[test]
fn pompy_scaling_depends_on_dt_and_physical_does_not() {
    // Spread after 20 s with no flow: physical K gives variance 2 K t whatever dt is;
    // pompy's scale * N * dt gives scale^2 dt t, ten times smaller at a ten times smaller dt.
    let domain = rect(-100.0, 100.0, -100.0, 100.0);
    let src = Source {
        pos_m: Vec3::new(0.0, 0.0, 10.0),
        mass_rate_per_s: 1.0,
        filament_rate_hz: 1.0,
    };
    let still = || FlowModel::Uniform(UniformFlow::new(east(0.0)).unwrap());
    let spread = |dispersion: Dispersion, dt: f64| {
        let params = FilamentParams {
            dispersion,
            vertical: VerticalBoundary::Unbounded,
            ..FilamentParams::default()
        };
        let mut plume = FilamentPlume::new(domain, vec![src], params).unwrap();
        plume.release_at_source(0, 4000);
        let mut rng = stream_rng(9, StreamId::Plume);
        let mut flow = still();
        let steps = (20.0 / dt).round() as usize;
        let _ = &mut flow;
        // Release nothing more: the Poisson rate of 1 /s adds a few filaments; keep the first 4000.
        let mut p = plume;
        for k in 1..=steps {
            p.step(&flow, k as f64 * dt, dt, &mut rng);
        }
        let xs: Vec<f64> = p.filaments().take(4000).map(|(q, _)| q.x).collect();
        xs.iter().map(|x| x * x).sum::<f64>() / xs.len() as f64
    };
    let phys = Dispersion::Physical {
        horizontal_m2ps: 0.1,
        vertical_m2ps: 0.1,
    };
    let (a, b) = (spread(phys, 0.1), spread(phys, 0.01));
    assert!(
        (a - 4.0).abs() / 4.0 < 0.1 && (b - 4.0).abs() / 4.0 < 0.1,
        "physical: {a} and {b}, theory 4.0"
    );
    let pompy = Dispersion::PompyCompatible {
        scale_mps: [2.0; 3],
    };
    let (c, d) = (spread(pompy, 0.1), spread(pompy, 0.01));
    // scale^2 dt t = 4 * 0.1 * 20 = 8 and 0.8.
    assert!(
        (c - 8.0).abs() / 8.0 < 0.1 && (d - 0.8).abs() / 0.8 < 0.1,
        "pompy mode: {c} and {d}"
    );
}

#[test]
fn filaments_pass_through_soft_obstacles() {
    let domain = rect(0.0, 100.0, -50.0, 50.0);
    let src = Source {
        pos_m: Vec3::new(5.0, 0.0, 0.0),
        mass_rate_per_s: 5.0,
        filament_rate_hz: 5.0,
    };
    let kelp = SoftObstacle::new(
        "kelp",
        &[[30.0, -10.0], [40.0, -10.0], [40.0, 10.0], [30.0, 10.0]],
    )
    .unwrap();
    let build = |obstacles: ObstacleSet| {
        let plume = FilamentPlume::new(domain, vec![src], FilamentParams::default()).unwrap();
        Environment::new(
            domain,
            pompy_farrell(domain, 0.05),
            Plume::Filaments(Box::new(plume)),
            obstacles,
            0.05,
            8,
        )
        .unwrap()
    };
    let mut with = build(ObstacleSet::new(vec![kelp]));
    let mut without = build(ObstacleSet::default());
    run(&mut with, 80.0);
    run(&mut without, 80.0);
    let inside = filaments(&with)
        .filaments()
        .filter(|(p, _)| with.obstacles().contains(Vec2::new(p.x, p.y)))
        .count();
    let beyond = filaments(&with)
        .filaments()
        .filter(|(p, _)| p.x > 40.0)
        .count();
    assert!(inside > 0 || beyond > 0, "no filament reached the kelp");
    let a: Vec<_> = filaments(&with).filaments().collect();
    let b: Vec<_> = filaments(&without).filaments().collect();
    assert_eq!(a, b, "obstacles changed the plume");
}

#[test]
fn same_seed_same_bits_and_thread_count_does_not_matter() {
    let domain = rect(0.0, 100.0, -50.0, 50.0);
    let src = Source {
        pos_m: Vec3::new(5.0, 0.0, 0.0),
        mass_rate_per_s: 5.0,
        filament_rate_hz: 10.0,
    };
    let make = |seed| {
        let mut env = filament_env(
            domain,
            pompy_farrell(domain, 0.05),
            src,
            FilamentParams::default(),
            0.05,
            seed,
        );
        run(&mut env, 60.0);
        env
    };
    let (a, b, c) = (make(11), make(11), make(12));
    let bits = |e: &Environment| -> Vec<u64> {
        filaments(e)
            .filaments()
            .flat_map(|(p, r2)| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits(), r2.to_bits()])
            .collect()
    };
    assert_eq!(bits(&a), bits(&b));
    assert_ne!(bits(&a), bits(&c));
    let spec = GridSpec {
        x_min_m: 0.0,
        x_max_m: 100.0,
        y_min_m: -20.0,
        y_max_m: 20.0,
        nx: 201,
        ny: 81,
        z_m: 0.0,
    };
    let pts = spec.points();
    let eval = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut out = vec![0.0; pts.len()];
        pool.install(|| a.plume().concentrations(&pts, &mut out));
        out.iter().map(|c| c.to_bits()).collect::<Vec<_>>()
    };
    let one = eval(1);
    assert_eq!(one, eval(2));
    assert!(one.iter().any(|&c| f64::from_bits(c) > 0.0));
}

#[test]
fn scanned_and_indexed_queries_agree() {
    let domain = rect(0.0, 100.0, -50.0, 50.0);
    let src = Source {
        pos_m: Vec3::new(5.0, 0.0, 0.5),
        mass_rate_per_s: 5.0,
        filament_rate_hz: 10.0,
    };
    let params = FilamentParams {
        vertical: VerticalBoundary::Reflecting { depth_m: Some(6.0) },
        growth_rate_m2ps: 0.01,
        ..FilamentParams::default()
    };
    let mut env = filament_env(domain, pompy_farrell(domain, 0.05), src, params, 0.05, 21);
    env.spin_up(60.0, 0.2).unwrap();
    run(&mut env, 10.0);
    assert!((env.elapsed_s() - 70.0).abs() < 1e-9 && (env.time_s() - 10.0).abs() < 1e-9);
    let f = filaments(&env);
    assert!(f.len() > 300);
    let mut nonzero = 0;
    for (k, (c, _)) in f.filaments().enumerate().step_by(7) {
        for q in [
            Vec3::new(c.x + 0.1, c.y - 0.05, 0.3),
            Vec3::new(c.x, c.y, 5.9),
            Vec3::new(f64::from(k as u32 % 90), 3.0, 1.0),
        ] {
            let (a, b) = (f.concentration(q), env.sample_concentration(q));
            assert!(
                (a - b).abs() <= 1e-12 * a.abs().max(1e-300),
                "{a} vs {b} at {q:?}"
            );
            if a > 0.0 {
                nonzero += 1;
            }
        }
    }
    assert!(nonzero > 50);
}

/// A 20 Hz source's plume spun up for two minutes under a seabed at 6 m, a surface only and no
/// bound, each with a height near its boundary to probe at.
fn spun_up_under_each_boundary() -> Vec<(Environment, f64)> {
    let domain = rect(0.0, 200.0, -60.0, 60.0);
    let src = Source {
        pos_m: Vec3::new(10.0, 0.0, 0.5),
        mass_rate_per_s: 5.0,
        filament_rate_hz: 20.0,
    };
    [
        (VerticalBoundary::Reflecting { depth_m: Some(6.0) }, 5.9),
        (VerticalBoundary::Reflecting { depth_m: None }, 0.2),
        (VerticalBoundary::Unbounded, 0.5),
    ]
    .into_iter()
    .map(|(vertical, z)| {
        let params = FilamentParams {
            vertical,
            growth_rate_m2ps: 0.02,
            ..FilamentParams::default()
        };
        let mut env = filament_env(domain, pompy_farrell(domain, 0.1), src, params, 0.1, 3);
        env.spin_up(120.0, 0.2).unwrap();
        (env, z)
    })
    .collect()
}

#[test]
fn the_pruned_sensor_scan_is_bit_for_bit_the_full_scan() {
    for (mut env, z_probe) in spun_up_under_each_boundary() {
        let mut checked = 0u32;
        let mut nonzero = 0u32;
        for round in 0..4 {
            run(&mut env, 5.0);
            let f = filaments(&env);
            assert!(f.len() > 1000, "{} filaments", f.len());
            let centres: Vec<Vec3> = f.filaments().map(|(c, _)| c).collect();
            // Points on filaments, just beside them, between the plume and the edges, on the
            // boxes' corners (offsets of whole and half metres), and far away.
            for (k, c) in centres.iter().enumerate().step_by(13) {
                let o = f64::from((k % 7) as u32) - 3.0;
                for q in [
                    *c,
                    Vec3::new(c.x + 0.5 * o, c.y - 0.25 * o, z_probe),
                    Vec3::new(c.x, c.y + 4.0 * o, c.z),
                    Vec3::new(f64::from(round * 40 + (k % 40) as u32), 30.0 * o / 3.0, 1.0),
                ] {
                    let (a, b) = (f.concentration_scan(q), f.concentration_full_scan(q));
                    assert_eq!(a.to_bits(), b.to_bits(), "{a} vs {b} at {q:?}");
                    checked += 1;
                    nonzero += u32::from(a > 0.0);
                }
            }
        }
        assert!(
            checked > 1000 && nonzero > 300,
            "{checked} points, {nonzero} in the plume"
        );
    }
}

fn farrell_with_step(domain: Rect, mean: MeanFlow, params: FarrellParams) -> FlowModel {
    FlowModel::Farrell(Box::new(
        FarrellFlow::substepped(domain, mean, params).unwrap(),
    ))
}

#[test]
fn a_grid_with_its_own_step_advances_once_per_block_of_plume_steps() {
    use plumetrace_env::{FlowField, flow_schedule};
    let domain = rect(0.0, 100.0, -50.0, 50.0);
    let with_step = |step_s| FarrellParams {
        step_s,
        ..FarrellParams::default()
    };
    let flow = farrell_with_step(domain, east(1.0), with_step(0.1));
    // pompy's grid: stable below about 0.25 s, so 0.1 s is within half the limit.
    let limit = flow.max_stable_dt_s().unwrap();
    assert!(0.2 < limit && limit < 0.3, "limit {limit}");
    assert_eq!(flow_schedule(&flow, 0.01), (10, 1));
    assert_eq!(flow_schedule(&flow, 0.1), (1, 1));
    assert_eq!(flow_schedule(&flow, 0.03), (3, 1));
    // Capped at half the stable limit; a plume step beyond that takes sub-steps as before.
    let long = farrell_with_step(domain, east(1.0), with_step(10.0));
    let cap = (0.5 * limit / 0.01).floor() as u64;
    assert_eq!(flow_schedule(&long, 0.01), (cap, 1));
    assert_eq!(flow_schedule(&long, 1.0).0, 1);
    assert!(flow_schedule(&long, 1.0).1 > 1);
    let along = farrell_with_step(domain, east(1.0), with_step(0.0));
    assert_eq!(flow_schedule(&along, 0.01), (1, 1));

    // The environment advances the grid at the first step of each block, to the block's
    // middle plus half a plume step.
    let src = Source {
        pos_m: Vec3::new(5.0, 0.0, 0.0),
        mass_rate_per_s: 5.0,
        filament_rate_hz: 5.0,
    };
    let mut env = filament_env(domain, flow, src, FilamentParams::default(), 0.01, 3);
    let mut times = Vec::new();
    for _ in 0..21 {
        env.step().unwrap();
        times.push(env.flow().time_s());
    }
    for (k, t) in times.iter().enumerate() {
        let want = 0.1 * (k / 10) as f64 + 0.055;
        assert!(
            (t - want).abs() < 1e-9,
            "after step {}: flow at {t} s, want {want}",
            k + 1
        );
    }
}

#[test]
fn the_grid_s_own_step_leaves_the_filaments_step_alone() {
    // Without noise the grid keeps the uniform mean flow exactly, whatever its step: the
    // filaments must then be the same bits whether the grid steps with them or once per block
    // (their release, walk and removal follow the plume's step, not the grid's).
    let domain = rect(0.0, 100.0, -50.0, 50.0);
    let src = Source {
        pos_m: Vec3::new(5.0, 0.0, 0.0),
        mass_rate_per_s: 5.0,
        filament_rate_hz: 20.0,
    };
    let run_with = |step_s, pompy| {
        let fp = FarrellParams {
            noise_gain: 0.0,
            step_s,
            ..FarrellParams::default()
        };
        let params = FilamentParams {
            dispersion: if pompy {
                Dispersion::PompyCompatible {
                    scale_mps: [2.0, 2.0, 2.0],
                }
            } else {
                FilamentParams::default().dispersion
            },
            ..FilamentParams::default()
        };
        let flow = farrell_with_step(domain, east(1.0), fp);
        let mut env = filament_env(domain, flow, src, params, 0.01, 8);
        run(&mut env, 30.0);
        let f = filaments(&env);
        assert!(f.len() > 300, "{} filaments", f.len());
        f.filaments()
            .flat_map(|(p, r2)| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits(), r2.to_bits()])
            .collect::<Vec<u64>>()
    };
    for pompy in [false, true] {
        assert_eq!(
            run_with(0.0, pompy),
            run_with(0.1, pompy),
            "pompy mode {pompy}"
        );
    }
}

#[test]
fn a_grid_query_is_bit_for_bit_the_point_by_point_query() {
    for (mut env, z) in spun_up_under_each_boundary() {
        run(&mut env, 5.0);
        let mut nonzero = 0;
        // Grids inside the domain, over its edge, beyond it, finer and coarser than the
        // filaments, a single row (queried point by point) and spacings that are not round.
        for (x0, x1, y0, y1, nx, ny) in [
            (0.0, 200.0, -60.0, 60.0, 160, 96),
            (-30.0, 120.0, -10.0, 75.0, 77, 41),
            (5.0, 60.0, -8.0, 8.0, 301, 133),
            (210.0, 400.0, -60.0, 60.0, 20, 20),
            (0.0, 200.0, 0.0, 1.0, 50, 1),
            (13.7, 151.3, -47.1, 33.3, 3, 2),
            (-20.0, 220.0, -70.0, 70.0, 401, 201),
        ] {
            let spec = grid((x0, x1, y0, y1), (nx, ny), z);
            let pts = spec.points();
            // In one band on one thread, and in bands of rows taken by three threads.
            for threads in [1, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let mut grid = vec![f64::NAN; pts.len()];
                pool.install(|| env.plume().grid_concentrations(&spec, &pts, &mut grid));
                for (p, g) in pts.iter().zip(&grid) {
                    let c = env.plume().concentration(*p);
                    assert_eq!(
                        c.to_bits(),
                        g.to_bits(),
                        "{c} vs {g} at {p:?} of {spec:?}, {threads} threads"
                    );
                    nonzero += usize::from(c > 0.0);
                }
            }
        }
        assert!(
            nonzero > 100,
            "{nonzero} points with a concentration at z = {z}"
        );
    }
}

#[test]
fn a_display_grid_is_within_a_few_units_in_the_last_place_and_the_same_whatever_the_threads() {
    for (mut env, z) in spun_up_under_each_boundary() {
        run(&mut env, 5.0);
        let mut nonzero = 0;
        // A grid as fine as the filaments and one coarser than them, both over the domain's edge.
        for (x0, x1, y0, y1, nx, ny) in [
            (-10.0, 200.0, -60.0, 60.0, 211, 121),
            (13.7, 151.3, -47.1, 33.3, 19, 11),
        ] {
            let spec = grid((x0, x1, y0, y1), (nx, ny), z);
            let pts = spec.points();
            let on = |threads: usize| {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let mut out = vec![f64::NAN; pts.len()];
                pool.install(|| {
                    env.plume()
                        .display_grid_concentrations(&spec, &pts, &mut out)
                });
                out
            };
            // (The display query runs on the calling thread whatever the pool: this guards that
            // it stays the same bits should it ever be split again.)
            let display = on(1);
            let bits = |v: &[f64]| v.iter().map(|c| c.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&display), bits(&on(3)), "{spec:?}");
            let mut exact = vec![f64::NAN; pts.len()];
            env.plume().grid_concentrations(&spec, &pts, &mut exact);
            for ((p, d), e) in pts.iter().zip(&display).zip(&exact) {
                // Every term is positive and within 2 units in the last place (2.2e-16 each),
                // so the sums are too, but for the rounding of the additions themselves.
                assert!(
                    (d - e).abs() <= 1e-15 * e,
                    "{d:e} against {e:e} at {p:?} of {spec:?}"
                );
                assert_eq!(*d > 0.0, *e > 0.0, "at {p:?}");
                nonzero += usize::from(*e > 0.0);
            }
        }
        assert!(nonzero > 100, "{nonzero} points with a concentration");
    }
}

#[test]
fn the_environment_refuses_steps_too_short_for_single_precision_positions() {
    // A 200 km strip: positions 100 km from its centre round to 3.9 mm, and a walk of 0.01
    // m^2/s moves filaments 1.4 cm in 0.01 s (refused) and 4.5 cm in 0.1 s.
    let domain = rect(0.0, 200_000.0, 0.0, 100.0);
    let src = Source {
        pos_m: Vec3::new(150_000.0, 50.0, 1.0),
        mass_rate_per_s: 1.0,
        filament_rate_hz: 1.0,
    };
    let params = FilamentParams {
        dispersion: Dispersion::Physical {
            horizontal_m2ps: 0.01,
            vertical_m2ps: 0.001,
        },
        ..FilamentParams::default()
    };
    let env = |dt: f64| {
        let plume = FilamentPlume::new(domain, vec![src], params).unwrap();
        let flow = FlowModel::Uniform(UniformFlow::new(east(0.1)).unwrap());
        let plume = Plume::Filaments(Box::new(plume));
        Environment::new(domain, flow, plume, ObstacleSet::default(), dt, 1)
    };
    let e = env(0.01).err().map(|e| e.to_string()).unwrap_or_default();
    assert!(
        e.starts_with("dt_s: a step of 0.01 s moves filaments east"),
        "{e}"
    );
    let mut ok = env(0.1).unwrap();
    // The spin-up checks its own step, and a spin-up of no time has none.
    let e = ok
        .spin_up(10.0, 0.01)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        e.starts_with("spinup_dt_s: a step of 0.01 s moves filaments east"),
        "{e}"
    );
    assert_eq!(ok.elapsed_s(), 0.0, "nothing stepped before the error");
    ok.spin_up(0.0, 0.01).unwrap();
    // 0.004 s in steps of 0.01 s rounds to no step: nothing to check.
    ok.spin_up(0.004, 0.01).unwrap();
    assert_eq!(ok.elapsed_s(), 0.0);
    ok.spin_up(1.0, 0.1).unwrap();
    assert!((ok.elapsed_s() - 1.0).abs() < 1e-12);
}
