//! `[bathymetry]`: the example site's seabed under its plume and vehicles, and the errors of the
//! section, each located.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_scenario::{Origin, build, parse};
use std::path::{Path, PathBuf};

fn site_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/sites/site.toml")
}

fn site() -> String {
    std::fs::read_to_string(site_path()).unwrap()
}

/// The scenario's error, or "accepted" (read as if it were the example's file, so that its
/// data files are found).
fn error_of(text: &str) -> String {
    let origin = Origin::File(site_path());
    match parse(text, &origin) {
        Err(e) => e.to_string(),
        Ok(cfg) => match build(&cfg, &origin, None) {
            Err(e) => e.to_string(),
            Ok(_) => String::from("accepted"),
        },
    }
}

#[test]
fn the_example_site_puts_its_source_and_vehicle_over_its_seabed() {
    let origin = Origin::File(site_path());
    let cfg = parse(&site(), &origin).unwrap();
    let b = build(&cfg, &origin, None).unwrap();
    let sb = b.env.seabed().expect("a seabed");
    // 10 m deep at the coast to 18 m offshore (the domain reaches 16.7 m of it), a 3 m channel.
    assert!(
        sb.surface_m() > 16.0 && sb.surface_m() < 21.0,
        "{}",
        sb.surface_m()
    );
    assert_eq!(b.depth_m, Some(sb.surface_m()));
    let src = b.env.plume().filaments().unwrap().sources()[0].pos_m;
    assert!(
        (src.z - sb.height_at(src.x, src.y)).abs() < 1e-12,
        "{src:?}"
    );
    let depth_at_source = sb.depth_at(src.x, src.y);
    assert!(
        depth_at_source > 12.0 && depth_at_source < 18.0,
        "{depth_at_source}"
    );
    let v = &b.vehicles[0].vehicle.state;
    let alt = v.z_m - sb.height_at(v.pos_m.x, v.pos_m.y);
    assert!((alt - 2.0).abs() < 1e-9, "{alt}");
}

#[test]
fn the_errors_of_the_section_are_located() {
    let text = site();
    let cases: &[(&str, &str, &str)] = &[
        (
            "file = \"seabed.nc\"",
            "file = \"seabed.nc\"\nvariable = \"elevaton\"",
            "bathymetry.file: ",
        ),
        ("file = \"seabed.nc\"", "fiel = \"seabed.nc\"", "bathymetry"),
        (
            "file = \"seabed.nc\"",
            "file = \"seabed.nc\"\nspacing_m = 0.0",
            "bathymetry.spacing_m",
        ),
        (
            "file = \"seabed.nc\"",
            "file = \"no-such-seabed.nc\"",
            "bathymetry.file: ",
        ),
        (
            "file = \"seabed.nc\"",
            "file = \"currents.nc\"",
            "bathymetry.file: ",
        ),
        (
            "y_max_m = 150.0",
            "y_max_m = 150.0\ndepth_m = 12.0",
            "domain.depth_m",
        ),
        (
            "model = \"filaments\"",
            "model = \"filaments\"\nseabed = \"none\"",
            "bathymetry",
        ),
    ];
    let mut got = Vec::new();
    for (from, to, key) in cases {
        let edited = text.replacen(from, to, 1);
        assert_ne!(edited, text, "{from} -> {to} did not apply");
        let e = error_of(&edited);
        assert!(e.contains(key), "{to}: {e}");
        assert!(e.contains("site.toml:"), "{to}: {e}");
        got.push(e);
    }
    assert!(
        got[0].contains("no such variable; did you mean \"elevation\"?"),
        "{}",
        got[0]
    );
    assert!(got[1].contains("did you mean `file`?"), "{}", got[1]);
    assert!(got[3].contains("no-such-seabed.nc"), "{}", got[3]);
    assert!(
        got[4].contains("no seabed depth") && got[4].contains("bathymetry.variable"),
        "{}",
        got[4]
    );
    assert!(got[5].contains("remove domain.depth_m"), "{}", got[5]);
    assert!(got[6].contains("reflecting seabed"), "{}", got[6]);
}
