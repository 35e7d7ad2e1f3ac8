//! Enforces the dependency rules of ARCHITECTURE.md on the crates' manifests.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeSet;
use std::path::Path;

/// Which side of the simulator/vehicle boundary a crate is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Side {
    /// Value types both sides share; no randomness.
    Shared,
    /// Runs on a vehicle: sees only what a vehicle can know.
    Onboard,
    /// The simulated world.
    Simulator,
    /// Binaries and tools on top of everything.
    App,
}

/// Every crate, its side and the plumetrace crates it may depend on. A new crate must be added
/// here (and to ARCHITECTURE.md) or this test fails.
const RULES: &[(&str, Side, &[&str])] = &[
    ("plumetrace-core", Side::Shared, &[]),
    ("plumetrace-netcdf", Side::Shared, &[]),
    (
        "plumetrace-env",
        Side::Simulator,
        &["plumetrace-core", "plumetrace-netcdf"],
    ),
    ("plumetrace-guidance", Side::Onboard, &["plumetrace-core"]),
    (
        "plumetrace-planner",
        Side::Onboard,
        &["plumetrace-core", "plumetrace-guidance"],
    ),
    (
        "plumetrace-log",
        Side::Onboard,
        &["plumetrace-core", "plumetrace-planner"],
    ),
    (
        "plumetrace-onboard",
        Side::Onboard,
        &[
            "plumetrace-core",
            "plumetrace-guidance",
            "plumetrace-planner",
            "plumetrace-log",
        ],
    ),
    (
        "plumetrace-sim",
        Side::Simulator,
        &["plumetrace-core", "plumetrace-env"],
    ),
    (
        "plumetrace-scenario",
        Side::Simulator,
        &[
            "plumetrace-core",
            "plumetrace-netcdf",
            "plumetrace-env",
            "plumetrace-sim",
        ],
    ),
    (
        "plumetrace-mission",
        Side::App,
        &[
            "plumetrace-core",
            "plumetrace-env",
            "plumetrace-sim",
            "plumetrace-scenario",
            "plumetrace-guidance",
            "plumetrace-planner",
            "plumetrace-log",
        ],
    ),
    (
        "plumetrace-frontseat",
        Side::App,
        &[
            "plumetrace-core",
            "plumetrace-env",
            "plumetrace-sim",
            "plumetrace-scenario",
            "plumetrace-mission",
            "plumetrace-onboard",
        ],
    ),
    (
        "plumetrace-report",
        Side::App,
        &[
            "plumetrace-core",
            "plumetrace-env",
            "plumetrace-sim",
            "plumetrace-scenario",
            "plumetrace-guidance",
            "plumetrace-planner",
            "plumetrace-log",
            "plumetrace-mission",
        ],
    ),
    (
        "plumetrace-campaign",
        Side::App,
        &[
            "plumetrace-core",
            "plumetrace-env",
            "plumetrace-scenario",
            "plumetrace-mission",
            "plumetrace-report",
        ],
    ),
    (
        "plumetrace-plume-run",
        Side::App,
        &[
            "plumetrace-core",
            "plumetrace-netcdf",
            "plumetrace-env",
            "plumetrace-sim",
            "plumetrace-scenario",
            "plumetrace-mission",
        ],
    ),
    (
        "plumetrace-bench",
        Side::App,
        &[
            "plumetrace-core",
            "plumetrace-env",
            "plumetrace-scenario",
            "plumetrace-planner",
            "plumetrace-mission",
        ],
    ),
    (
        "plumetrace-cli",
        Side::App,
        &[
            "plumetrace-core",
            "plumetrace-env",
            "plumetrace-sim",
            "plumetrace-scenario",
            "plumetrace-planner",
            "plumetrace-log",
            "plumetrace-onboard",
            "plumetrace-mission",
            "plumetrace-frontseat",
            "plumetrace-report",
            "plumetrace-campaign",
            "plumetrace-plume-run",
            "plumetrace-bench",
        ],
    ),
    (
        "plumetrace-py",
        Side::App,
        &[
            "plumetrace-core",
            "plumetrace-env",
            "plumetrace-sim",
            "plumetrace-scenario",
            "plumetrace-guidance",
            "plumetrace-planner",
            "plumetrace-log",
            "plumetrace-mission",
            "plumetrace-report",
            "plumetrace-campaign",
            "plumetrace-plume-run",
        ],
    ),
    (
        "plumetrace-fuzz",
        Side::App,
        &[
            "plumetrace-core",
            "plumetrace-netcdf",
            "plumetrace-env",
            "plumetrace-scenario",
            "plumetrace-planner",
            "plumetrace-mission",
            "plumetrace-report",
            "plumetrace-campaign",
            "plumetrace-onboard",
        ],
    ),
];

/// Dependencies no row may ever allow, whatever else changes, with the reason.
const NEVER: &[(&str, &str, &str)] = &[
    (
        "plumetrace-onboard",
        "plumetrace-env",
        "what flies a vehicle never sees the simulated world",
    ),
    (
        "plumetrace-onboard",
        "plumetrace-sim",
        "what flies a vehicle never sees the simulated world",
    ),
    (
        "plumetrace-onboard",
        "plumetrace-scenario",
        "what flies a vehicle never sees the simulated world",
    ),
    (
        "plumetrace-onboard",
        "plumetrace-mission",
        "what flies a vehicle never sees the simulated world",
    ),
    (
        "plumetrace-mission",
        "plumetrace-onboard",
        "missions write their logs through plumetrace-log, not the vehicle link",
    ),
    (
        "plumetrace-log",
        "plumetrace-onboard",
        "the simulator's apps write the log formats too, so they hold no link",
    ),
    (
        "plumetrace-log",
        "plumetrace-mission",
        "the simulator's apps write the log formats too, so they hold no link",
    ),
];

#[test]
fn the_vehicle_link_and_the_simulated_world_stay_apart() {
    for (from, to, why) in NEVER {
        let allowed = RULES.iter().find(|r| r.0 == *from).map(|r| r.2);
        assert!(
            allowed.is_some_and(|a| !a.contains(to)),
            "{from} may not depend on {to}: {why}"
        );
    }
}
/// The crates that may draw (depend on `plotters`): the report crate, and the campaign's charts
/// (which draw their maps with the report crate's map panel). The mission runner records and
/// never draws.
const DRAWING: &[&str] = &["plumetrace-report", "plumetrace-campaign"];

fn manifest_deps(path: &Path, table: &str) -> BTreeSet<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let value: toml::Value = toml::from_str(&text).unwrap();
    value
        .get(table)
        .and_then(|d| d.as_table())
        .map(|t| t.keys().cloned().collect())
        .unwrap_or_default()
}

#[test]
fn crates_depend_only_on_what_their_side_allows() {
    let crates_dir = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let mut seen = BTreeSet::new();
    for entry in std::fs::read_dir(crates_dir).unwrap() {
        let dir = entry.unwrap().path();
        let manifest = dir.join("Cargo.toml");
        if !manifest.is_file() {
            continue;
        }
        let name = dir.file_name().unwrap().to_string_lossy().to_string();
        let Some(&(_, side, allowed)) = RULES.iter().find(|r| r.0 == name) else {
            panic!(
                "crate {name} is not in the dependency rules (tests/architecture.rs and ARCHITECTURE.md)"
            );
        };
        seen.insert(name.clone());
        let deps = manifest_deps(&manifest, "dependencies");
        for dep in deps.iter().filter(|d| d.starts_with("plumetrace-")) {
            assert!(
                allowed.contains(&dep.as_str()),
                "{name} may not depend on {dep}"
            );
            let dep_side = RULES.iter().find(|r| r.0 == dep).map(|r| r.1);
            match side {
                Side::Shared => assert!(
                    dep_side == Some(Side::Shared),
                    "shared crate {name} depends on {dep}, which is not shared"
                ),
                Side::Onboard => assert!(
                    matches!(dep_side, Some(Side::Shared | Side::Onboard)),
                    "onboard crate {name} depends on {dep}, which is not onboard or shared"
                ),
                Side::Simulator => assert!(
                    matches!(dep_side, Some(Side::Shared | Side::Simulator)),
                    "simulator crate {name} depends on {dep}, which is not simulator or shared"
                ),
                Side::App => {}
            }
        }
        assert!(
            !deps.contains("plotters") || DRAWING.contains(&name.as_str()),
            "{name} may not draw (depend on plotters): drawing belongs in plumetrace-report"
        );
        if side == Side::Shared || side == Side::Onboard {
            for banned in ["rand", "rand_pcg", "rand_distr"] {
                assert!(
                    !deps.contains(banned),
                    "{name} ({side:?}) must not use randomness ({banned})"
                );
            }
        }
    }
    let expected: BTreeSet<String> = RULES.iter().map(|r| r.0.to_string()).collect();
    assert_eq!(seen, expected, "a crate in the rules has no directory");
}
