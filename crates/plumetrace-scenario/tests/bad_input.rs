//! Bad scenarios are rejected with the key path; nothing panics.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_scenario::{Origin, build, find_preset, parse};

fn demo_with(edit: impl Fn(&str) -> String) -> String {
    edit(find_preset("plume-demo").unwrap().toml)
}

fn error_of(text: &str) -> String {
    let origin = Origin::File("scenario.toml".into());
    match parse(text, &origin) {
        Err(e) => e.to_string(),
        Ok(cfg) => match build(&cfg, &origin, None) {
            Err(e) => e.to_string(),
            Ok(_) => String::from("accepted"),
        },
    }
}

#[test]
fn bad_values_are_rejected_with_their_key_path() {
    let cases: &[(&str, &str, &str)] = &[
        (
            "mass_rate_per_s = 5.0",
            "mass_rate_per_s = -5.0",
            "sources[0].mass_rate_per_s",
        ),
        (
            "filament_rate_hz = 5.0",
            "filament_rate_hz = -1.0",
            "sources[0].filament_rate_hz",
        ),
        ("x_max_m = 200.0", "x_max_m = 0.0", "domain.x_max_m"),
        ("y_max_m = 50.0", "y_max_m = -50.0", "domain.y_max_m"),
        ("dt_s = 0.1", "dt_s = 5.0", "sim.dt_s"),
        ("dt_s = 0.1", "dt_s = -0.1", "sim.dt_s"),
        ("nx = 21", "nx = 1", "flow.farrell.nx"),
        (
            "noise_gain = 0.3",
            "noise_gain = -0.3",
            "flow.farrell.noise_gain",
        ),
        ("speed_mps = 0.5", "speed_mps = -0.5", "flow.mean.speed_mps"),
        (
            "growth_rate_m2ps = 0.01",
            "growth_rate_m2ps = -0.01",
            "plume.growth_rate_m2ps",
        ),
        ("x_m = 10.0", "x_m = 500.0", "sources[0].x_m"),
        ("threshold = 0.05", "threshold = -1.0", "output.threshold"),
        ("depth_m = 10.0", "depth_m = 0.0", "domain.depth_m"),
    ];
    for (from, to, key) in cases {
        let text = demo_with(|t| t.replacen(from, to, 1));
        assert_ne!(
            text,
            find_preset("plume-demo").unwrap().toml,
            "edit {from} -> {to} did not apply"
        );
        let e = error_of(&text);
        assert!(
            e.contains(key) && e.starts_with("scenario.toml"),
            "{from} -> {to}: error {e:?} does not name {key}"
        );
    }
}

#[test]
fn unknown_and_mistyped_keys_are_rejected_with_their_path() {
    let cases: &[(&str, &str, &str)] = &[
        ("[sim]\n", "[sim]\ndt = 0.1\n", "sim"),
        (
            "[flow.farrell]\n",
            "[flow.farrell]\nnoise_gian = 1.0\n",
            "flow.farrell",
        ),
        ("[plume]\n", "[plume]\ngrowth_rate = 0.1\n", "plume"),
        ("model = \"farrell\"", "model = \"farel\"", "flow.model"),
        ("nx = 21", "nx = \"many\"", "flow.farrell.nx"),
        (
            "name = \"plume-demo\"",
            "name = \"plume-demo\"\ncolour = 3",
            "colour",
        ),
    ];
    for (from, to, key) in cases {
        let text = demo_with(|t| t.replacen(from, to, 1));
        let e = error_of(&text);
        assert!(
            e.contains(key) && e != "accepted",
            "{to}: error {e:?} does not name {key}"
        );
    }
}

#[test]
fn mistyped_values_say_what_was_expected_in_plain_words() {
    for (from, to, want) in [
        (
            "nx = 21",
            "nx = \"many\"",
            "flow.farrell.nx: invalid type: string \"many\", expected a whole number, 0 or more",
        ),
        (
            "dt_s = 0.1",
            "dt_s = \"fast\"",
            "sim.dt_s: invalid type: string \"fast\", expected a number",
        ),
    ] {
        let e = error_of(&demo_with(|t| t.replacen(from, to, 1)));
        assert!(e.contains(want), "{to}: {e}");
    }
}

#[test]
fn missing_tables_and_files_are_explained() {
    let no_mean = demo_with(|t| {
        t.replace(
            "[flow.mean]\nspeed_mps = 0.5\ntoward_deg = 90.0          # the water moves East\n",
            "",
        )
    });
    let e = error_of(&no_mean);
    assert!(e.contains("flow.mean"), "{e}");
    let gridded = demo_with(|t| {
        t.replacen(
            "model = \"farrell\"",
            "model = \"gridded\"\nfile = \"nope.csv\"",
            1,
        )
        .replace("[flow.farrell]\nnx = 21\nny = 11\n", "[flow.x]\n")
    });
    let e = error_of(&gridded);
    assert!(e.contains("flow"), "{e}");
    let missing = demo_with(|t| {
        t.replacen(
            "model = \"farrell\"",
            "model = \"gridded\"\nfile = \"nope.csv\"",
            1,
        )
    });
    let origin = Origin::File("scenario.toml".into());
    let cfg = parse(&missing, &origin).unwrap();
    let e = build(&cfg, &origin, None).unwrap_err().to_string();
    assert!(e.contains("flow.file") && e.contains("nope.csv"), "{e}");
    let not_toml = error_of("this is = = not toml");
    assert!(not_toml.contains("line 1"), "{not_toml}");
}

const VEHICLES: &str = r#"
[[vehicles]]
kind = "auv"
name = "remus"
x_m = 150.0
y_m = 0.0
heading_deg = 270.0

[[vehicles]]
kind = "surface"
x_m = 20.0
y_m = 10.0

[vehicles.nav]
fix_sigma_m = 3.0
"#;

fn demo_with_vehicles(extra: &str) -> String {
    format!(
        "{}\n{VEHICLES}\n{extra}",
        find_preset("plume-demo").unwrap().toml
    )
}

#[test]
fn vehicles_take_the_field_defaults_of_their_kind() {
    let origin = Origin::File("scenario.toml".into());
    let cfg = parse(&demo_with_vehicles(""), &origin).unwrap();
    let built = build(&cfg, &origin, None).unwrap();
    assert_eq!(built.vehicles.len(), 2);
    let auv = &built.vehicles[0];
    assert_eq!(auv.name, "remus");
    assert_eq!(auv.vehicle.params.max_speed_mps, 2.0);
    assert_eq!(auv.vehicle.params.max_turn_rate_deg_s, 10.0);
    assert_eq!(auv.vehicle.state.z_m, 2.0);
    assert_eq!(auv.chem_sensor.rate_hz, 10.0);
    assert_eq!(auv.chem_sensor.full_scale_v, 5.0);
    assert_eq!(
        auv.detection_threshold_v, None,
        "the threshold is the planner's unless the file sets one on the sensor"
    );
    assert!(auv.planner.is_none() && auv.nav.position_estimate);
    assert!(auv.range_sensor.is_none());
    let boat = &built.vehicles[1];
    assert_eq!(
        boat.vehicle.state.z_m, 10.0,
        "at the surface of the 10 m deep demo"
    );
    assert_eq!(boat.nav.fix_interval_s, 1.0, "GPS");
    assert_eq!(boat.nav.fix_sigma_m, 3.0, "overridden");
}

#[test]
fn bad_vehicle_settings_are_rejected_with_their_key_path() {
    let cases: &[(&str, &str)] = &[
        (
            "[vehicles.dynamics]\nmax_speed_mps = -2.0",
            "vehicles[1].dynamics.max_speed_mps",
        ),
        (
            "[vehicles.chem_sensor]\nrate_hz = 0.0",
            "vehicles[1].chem_sensor.rate_hz",
        ),
        (
            "[vehicles.flow_sensor]\nfault_start_s = 10.0",
            "vehicles[1].flow_sensor.fault_end_s",
        ),
        (
            "[[vehicles]]\nkind = \"auv\"\nx_m = 9.0\ny_m = 0.0\n[vehicles.nav]\nfix_interval_s = -1.0",
            "vehicles[2].nav.fix_interval_s",
        ),
        (
            "[vehicles.range_sensor]\nrays_per_group = 0",
            "vehicles[1].range_sensor.rays_per_group",
        ),
        (
            "[[vehicles]]\nkind = \"auv\"\nx_m = 999.0\ny_m = 0.0",
            "vehicles[2].x_m",
        ),
        (
            "[[vehicles]]\nkind = \"auv\"\nx_m = 9.0\ny_m = 0.0\naltitude_m = 50.0",
            "vehicles[2].altitude_m",
        ),
        (
            "[[vehicles]]\nkind = \"glider\"\nx_m = 9.0\ny_m = 0.0",
            "vehicles[2].kind",
        ),
        (
            "[[vehicles]]\nkind = \"auv\"\nx_m = 9.0\ny_m = 0.0\nspeed = 3",
            "vehicles[2]",
        ),
    ];
    for (extra, key) in cases {
        let e = error_of(&demo_with_vehicles(extra));
        assert!(
            e.contains(key),
            "{extra:?}: error {e:?} does not name {key}"
        );
    }
}

#[test]
fn altitude_hold_s_seabed_sensors_are_bounded() {
    for (extra, want) in [
        (
            "[vehicles.dynamics]\ndvl_beam_angle_deg = 75.0",
            "vehicles[1].dynamics.dvl_beam_angle_deg: must be >= 0.0 and <= 60.0 (a beam further \
             than 60 deg from the vertical grazes the seabed), got 75.0",
        ),
        (
            "[vehicles.dynamics]\nlook_ahead_m = -1.0",
            "vehicles[1].dynamics.look_ahead_m: must be >= 0.0 and <= 100.0 (a forward altimeter \
             reads tens of metres ahead), got -1.0",
        ),
        (
            "[vehicles.dynamics]\nmin_altitude_m = -0.5",
            "vehicles[1].dynamics.min_altitude_m: must be >= 0.0 and <= 100.0 (a minimum \
             altitude of 100 m is no altitude hold), got -0.5",
        ),
    ] {
        let e = error_of(&demo_with_vehicles(extra));
        assert!(e.contains(want), "{extra:?}: {e}");
    }
    assert_eq!(
        error_of(&demo_with_vehicles(
            "[vehicles.dynamics]\ndvl_beam_angle_deg = 20.0\nlook_ahead_m = 0.0"
        )),
        "accepted"
    );
}

#[test]
fn planner_tables_are_wired_to_vehicles_with_key_paths() {
    let mt = find_preset("duck-2003-mt").unwrap().toml;
    assert_eq!(error_of(mt), "accepted");
    // Planner keys themselves are the registry's to check (when the mission is set up); here
    // the tables are only attached to vehicles.
    let origin = Origin::File("scenario.toml".into());
    let cfg = parse(mt, &origin).unwrap();
    let built = build(&cfg, &origin, None).unwrap();
    let p = built.vehicles[0].planner.as_ref().unwrap();
    assert_eq!(p.key, "planner");
    assert_eq!(p.table.get("kind").and_then(|v| v.as_str()), Some("amp"));
    let named = |extra: &str| {
        format!(
            "{}\n[[vehicles]]\nkind = \"surface\"\nx_m = 300.0\ny_m = 0.0\nplanner = \"tracer\"\n{extra}",
            find_preset("demo").unwrap().toml
        )
    };
    let cases: &[(String, &str)] = &[
        (named(""), "vehicles[1].planner: no [planners.tracer] table"),
        (
            named("[planners.tracer]\nkind = \"amp\"\n[planners.spare]\nkind = \"amp\""),
            "planners.spare: no vehicle flies it",
        ),
        (
            {
                let demo = find_preset("demo").unwrap().toml;
                demo[..demo.find("[planner]").unwrap()].to_string()
            },
            "a [mission] needs a vehicle with a planner",
        ),
        (
            format!("{}\n[comms.acoustic]\nloss_probability = 1.5", mt),
            "comms.acoustic.loss_probability",
        ),
        (
            find_preset("demo")
                .unwrap()
                .toml
                .replace("x_m = 470.0", "x_m = 470.0\nplanner = \"tracer\"")
                + "\n[planners.tracer]\nkind = \"amp\"\n",
            "planner: no vehicle flies it",
        ),
        // Beside `[planner]`, a `[planners.NAME]` written with a kind and flown by no vehicle,
        // and one made by a key set from outside (no kind), which meant `[planner]`.
        (
            find_preset("demo").unwrap().toml.to_string() + "\n[planners.survey]\nkind = \"amp\"\n",
            "planners.survey: no vehicle flies it (name it in a vehicle: planner = \"NAME\")",
        ),
        (
            find_preset("demo").unwrap().toml.to_string()
                + "\n[planners.tracer]\nbeta_deg = 20.0\n",
            "planners.tracer: no vehicle flies it: this scenario's planner is its one [planner] table",
        ),
    ];
    for (text, want) in cases {
        let e = error_of(text);
        assert!(e.contains(want), "error {e:?} does not say {want:?}");
    }
    let ok = error_of(&named("[planners.tracer]\nkind = \"amp\""));
    assert_eq!(ok, "accepted");
}

/// `plume-demo` (600 s at 0.1 s, 200 m x 100 m, 10 m deep) with `keys` added to `[output]`.
fn demo_output(keys: &str) -> String {
    demo_with(|t| t.replacen("threshold = 0.05", &format!("threshold = 0.05\n{keys}"), 1))
}

#[test]
fn bad_probe_and_series_keys_are_rejected_with_their_key_path() {
    let many = |n: usize| format!("probes = [{}]", vec!["[50.0, 0.0, 2.0]"; n].join(", "));
    let cases: Vec<(String, &str, &str)> = vec![
        (
            "probes = [[500.0, 0.0, 2.0]]".into(),
            "output.probes[0]",
            "outside the domain (0.0..200.0 East, -50.0..50.0 North)",
        ),
        (
            "probes = [[50.0, 0.0, 2.0], [50.0, 0.0, 20.0]]".into(),
            "output.probes[1]",
            "domain.depth_m = 10.0",
        ),
        (
            "probes = [[50.0, 0.0, -1.0]]".into(),
            "output.probes[0]",
            "height above the seabed",
        ),
        (
            "probes = [[50.0, 0.0]]".into(),
            "output.probes[0]",
            "length 3",
        ),
        (
            "probes = [[1.0, 0.0, 1.0], [1e18, 0.0, 0.0]]".into(),
            "output.probes[1][0]",
            "<= 10000000.0",
        ),
        (many(1001), "output.probes", "at most 1000 entries"),
        (
            "probes = [[50.0, 0.0, 2.0]]\nprobe_interval_s = 0.01".into(),
            "output.probe_interval_s",
            "[sim.dt_s, sim.duration_s] = [0.1, 600.0]",
        ),
        (
            "probe_interval_s = 601.0".into(),
            "output.probe_interval_s",
            "got 601.0",
        ),
        (
            "probe_interval_s = -1.0".into(),
            "output.probe_interval_s",
            "> 0.0",
        ),
        (
            format!("{}\nprobe_interval_s = 0.1", many(1000)),
            "output.probe_interval_s",
            "6000 samples x 1000 probes = 6000000 rows of probes.csv; at most 5000000",
        ),
        (
            "filaments_interval_s = 0.5".into(),
            "output.filaments_interval_s",
            "1200 snapshots of every filament; at most 1000",
        ),
        (
            "filaments_interval_s = 0.01".into(),
            "output.filaments_interval_s",
            "must be 0 (no snapshots) or in [sim.dt_s, sim.duration_s]",
        ),
        (
            "filaments_interval_s = -1.0".into(),
            "output.filaments_interval_s",
            ">= 0.0",
        ),
        (
            "filaments_interval_s = nan".into(),
            "output.filaments_interval_s",
            "got NaN",
        ),
        (
            "probs = [[50.0, 0.0, 2.0]]".into(),
            "output.probs",
            "unknown field `probs`",
        ),
    ];
    for (keys, key, message) in &cases {
        let e = error_of(&demo_output(keys));
        assert!(
            e.starts_with("scenario.toml:")
                && e.contains(&format!("{key}: "))
                && e.contains(message),
            "{keys}: error {e:?} does not name {key} with {message:?}"
        );
    }
    // The default interval is the time average's; an error says so.
    let text = demo_output("probes = [[50.0, 0.0, 2.0]]").replacen(
        "average_interval_s = 1.0",
        "average_interval_s = 700.0",
        1,
    );
    let e = error_of(&text);
    assert!(
        e.contains("output.probe_interval_s: ")
            && e.contains("(its default, output.average_interval_s)"),
        "{e}"
    );
    // A steady plume has no filaments.
    let steady = format!(
        "{}filaments_interval_s = 1.0\n",
        find_preset("freshwater").unwrap().toml
    );
    let e = error_of(&steady);
    assert!(
        e.contains("output.filaments_interval_s: ") && e.contains("steady plume"),
        "{e}"
    );
    // A mission writes no series.
    let mission = format!(
        "{}\n[output]\nprobes = [[100.0, 0.0, 2.0]]\n",
        find_preset("demo").unwrap().toml
    );
    let e = error_of(&mission);
    assert!(
        e.contains("output.probes: ") && e.contains("plume runs only"),
        "{e}"
    );
}

#[test]
fn probe_and_series_keys_are_built_into_steps() {
    let origin = Origin::File("scenario.toml".into());
    let built = |keys: &str| {
        let cfg = parse(&demo_output(keys), &origin).unwrap();
        build(&cfg, &origin, None).unwrap().output
    };
    let o = built("probes = [[50.0, 0.0, 2.0], [200, 50, 10]]");
    assert_eq!(o.probes.len(), 2);
    assert_eq!(
        (o.probes[1].x, o.probes[1].y, o.probes[1].z),
        (200.0, 50.0, 10.0)
    );
    assert_eq!(
        o.probe_every_steps, o.average_every_steps,
        "default: the average's"
    );
    assert_eq!(o.probe_every_steps, 10);
    assert_eq!(o.filaments_every_steps, None);
    let o = built("probes = [[50.0, 0.0, 2.0]]\nprobe_interval_s = 2.5\nfilaments_interval_s = 60");
    assert_eq!(o.probe_every_steps, 25);
    assert_eq!(o.filaments_every_steps, Some(600));
    let o = built("filaments_interval_s = 0.0");
    assert!(o.probes.is_empty());
    assert_eq!(o.filaments_every_steps, None);
    // Every preset keeps its outputs: no series unless asked for.
    for p in plumetrace_scenario::PRESETS {
        let origin = Origin::Preset(p.name.into());
        let cfg = parse(p.toml, &origin).unwrap();
        let o = build(&cfg, &origin, None).unwrap().output;
        assert!(
            o.probes.is_empty() && o.filaments_every_steps.is_none(),
            "{}",
            p.name
        );
    }
}

#[test]
fn bad_salinity_modem_and_ranging_keys_name_themselves() {
    let base = find_preset("soares-freshwater").unwrap().toml;
    let cases = [
        // Salinity keys on a voltage sensor would be ignored.
        (
            base.replacen(
                "[vehicles.chem_sensor]\nmodel = \"salinity\"",
                "[vehicles.chem_sensor]\nnoise_sd_ppt = 0.2",
                1,
            ),
            "vehicles[0].chem_sensor.noise_sd_ppt",
        ),
        (
            base.replacen(
                "[vehicles.nav]\nposition_estimate = false",
                "[vehicles.nav]\nposition_estimate = false\n\n[vehicles.modem]\ndeaf_start_s = 10.0",
                1,
            ),
            "vehicles[0].modem.deaf_end_s",
        ),
        (
            base.replacen(
                "[vehicles.nav]\nposition_estimate = false",
                "[vehicles.nav]\nposition_estimate = false\n\n[vehicles.modem]\ndeaf_start_s = 10.0\ndeaf_end_s = 5.0",
                1,
            ),
            "vehicles[0].modem.deaf_end_s",
        ),
        (
            base.replace("timing_noise_sd_s = 0.0005", "timing_noise_sd_s = -1.0"),
            "comms.ranging.timing_noise_sd_s",
        ),
    ];
    for (text, key) in cases {
        let e = error_of(&text);
        assert!(e.contains(key), "{key}: {e}");
    }
}

/// The models name only their own fields; the scenario places their errors under the section's
/// key path, with the models' messages as they are.
#[test]
fn model_errors_are_placed_under_their_section() {
    let plume = find_preset("plume-demo").unwrap().toml;
    let demo = find_preset("demo").unwrap().toml;
    let vehicle = |table: &str| {
        format!("{plume}\n[[vehicles]]\nkind = \"auv\"\nx_m = 20.0\ny_m = 0.0\n{table}")
    };
    let cases: Vec<(String, &str)> = vec![
        (
            plume
                .replace("model = \"filaments\"", "model = \"gaussian\"")
                .replace(
                    "vertical_diffusivity_m2ps = 0.005",
                    "vertical_diffusivity_m2ps = 0.0",
                ),
            "plume.vertical_diffusivity_m2ps: the steady plume needs at least 1e-6 m^2/s (its \
             width goes as the square root of it), got 0.0",
        ),
        (
            plume
                .replace("model = \"filaments\"", "model = \"gaussian\"")
                .replace("z_m = 0.0 ", "z_m = 5000.0"),
            "sources[0].z_m: 5000 m is above the surface (10 m)",
        ),
        (
            format!(
                "{plume}\n[[obstacles]]\nvertices = [[0.0, 0.0], [9.0, 9.0], [9.0, 0.0], [0.0, 9.0]]\n"
            ),
            "obstacles[0].vertices: the polygon crosses itself: edges 0 and 2 meet (edge k runs \
             from vertex k to the next)",
        ),
        (
            format!(
                "{plume}\n[[kelp]]\nregion = [[0.0, 0.0], [90.0, 0.0], [90.0, 40.0]]\npatches = 2\nradius_m = [5.0, 1.0]\n"
            ),
            "kelp[0].radius_m: needs 0 < smallest <= largest, got [5, 1]",
        ),
        (
            format!("{plume}\n[[kelp]]\nregion = [[0.0, 0.0], [90.0, 0.0]]\npatches = 2\n"),
            "kelp[0].region: needs at least 3 vertices, got 2",
        ),
        (
            vehicle("[vehicles.range_sensor]\ndetection_probability = 0.0\n"),
            "vehicles[0].range_sensor.detection_probability: must be in (0, 1]",
        ),
        (
            vehicle("[vehicles.range_sensor]\nfront_half_angle_deg = 100.0\n"),
            "vehicles[0].range_sensor.side_outer_angle_deg: needs 0 < front_half_angle_deg < \
             side_outer_angle_deg <= 180",
        ),
        (
            demo.replace(
                "op_area = [[60.0, -80.0], [460.0, -80.0], [460.0, 80.0], [60.0, 80.0]]",
                "op_area = [[60.0, -80.0], [460.0, 80.0], [460.0, -40.0], [60.0, 80.0]]",
            ),
            "mission.op_area: the polygon crosses itself: edges 0 and 2 meet (edge k runs from \
             vertex k to the next)",
        ),
        (
            demo.replace(
                "op_area = [[60.0, -80.0], [460.0, -80.0], [460.0, 80.0], [60.0, 80.0]]",
                "op_area = [[60.0, -80.0], [260.0, -80.0], [460.0, -80.0]]",
            ),
            "mission.op_area: has zero area",
        ),
        (
            demo.replace("env_dt_s = 5.0", "env_dt_s = 0.25"),
            "mission.env_dt_s: must be a whole multiple of sim.dt_s (0.1), got 0.25",
        ),
        (
            demo.replace(
                "[planner]",
                "[comms.ranging]\nsound_speed_mps = 0.0\n[planner]",
            ),
            "comms.ranging.sound_speed_mps: must be > 0.0 and <= 1000000000.0 (finite), got 0.0",
        ),
    ];
    for (text, want) in cases {
        let got = error_of(&text);
        let got = got.strip_prefix("scenario.toml: ").unwrap_or(&got);
        assert_eq!(got, want);
    }
}

#[test]
fn keys_with_no_effect_in_this_kind_of_run_are_warned_of() {
    let warnings = |text: &str| {
        let origin = Origin::File("scenario.toml".into());
        let cfg = parse(text, &origin).unwrap();
        let built = build(&cfg, &origin, None).unwrap();
        built
            .warnings
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
    };
    let demo = find_preset("demo").unwrap().toml;
    let plume = find_preset("plume-demo").unwrap().toml;
    let vehicle = "\n[[vehicles]]\nkind = \"auv\"\nx_m = 50.0\ny_m = 0.0\n";
    let cases: Vec<(String, Vec<&str>)> = vec![
        (
            demo.replace("duration_s = 2400.0", "duration_s = 100.0"),
            vec![
                "sim.duration_s: 100 s has no effect on a mission, which runs until its vehicles \
                 are done or mission.time_limit_s (2400 s); set that instead (or make the two equal)",
            ],
        ),
        (
            format!("{demo}\n[output]\nnx = 50\nz_m = 2.0\nthreshold = 0.2\n"),
            vec![
                "output.nx: has no effect on a mission: the [output] grid and time average are \
                 written by plume runs only (a scenario without [mission]); remove it",
                "output.z_m: has no effect on a mission: the [output] grid and time average are \
                 written by plume runs only (a scenario without [mission]); remove it",
            ],
        ),
        (
            format!("{plume}{vehicle}"),
            vec![
                "vehicles: 1 vehicle(s) not flown: a scenario without [mission] is a plume run \
                 (give [mission] and a planner to fly them)",
            ],
        ),
        (
            format!("{plume}\n[comms.acoustic]\nlatency_s = 1.0\n"),
            vec![
                "comms: has no effect on a plume run (a scenario without [mission]): no vehicle \
                 sends messages",
            ],
        ),
        (
            format!("{demo}\n[vehicles.dynamics]\nlook_ahead_m = 20.0\n"),
            vec![
                "vehicles[0].dynamics.look_ahead_m: has no effect over a flat seabed: altitude \
                 hold uses its seabed sensors and minimum altitude only over a [bathymetry] grid",
            ],
        ),
        (demo.to_string(), vec![]),
        (plume.to_string(), vec![]),
    ];
    for (text, want) in cases {
        assert_eq!(warnings(&text), want);
    }
}

#[test]
fn unknown_keys_name_their_line_and_the_nearest_key() {
    let demo = find_preset("demo").unwrap().toml;
    let line = |needle: &str| demo.lines().position(|l| l.starts_with(needle)).unwrap() + 1;
    let e = error_of(&demo.replace("dt_s = 0.1", "dtt_s = 0.1"));
    assert_eq!(
        e,
        format!(
            "scenario.toml:{}: sim.dtt_s: unknown field `dtt_s`; did you mean `dt_s`?",
            line("dt_s")
        )
    );
    let e = error_of(&demo.replace("model = \"farrell\"", "model = \"farel\""));
    assert_eq!(
        e,
        format!(
            "scenario.toml:{}: flow.model: unknown variant `farel`; did you mean `farrell`?",
            line("model = \"farrell\"")
        )
    );
    // Nothing near: the known keys are listed.
    let e = error_of(&demo.replace("dt_s = 0.1", "zzzzzz = 0.1"));
    assert!(
        e.ends_with("unknown field `zzzzzz`, expected `dt_s` or `duration_s`"),
        "{e}"
    );
    let e = plumetrace_scenario::load_preset("dmeo")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("no preset named 'dmeo'; did you mean 'demo'? (known: demo, "),
        "{e}"
    );
}

#[test]
fn seeds_beyond_toml_integers_are_strings_of_digits() {
    let origin = Origin::File("scenario.toml".into());
    let with_seed =
        |seed: &str| demo_with(|t| t.replacen("seed = 1\n", &format!("seed = {seed}\n"), 1));
    assert_ne!(with_seed("2"), find_preset("plume-demo").unwrap().toml);
    for (written, seed) in [
        ("7", 7),
        ("\"18446744073709551615\"", u64::MAX),
        ("\"10451216379200822465\"", 10_451_216_379_200_822_465),
    ] {
        let cfg = parse(&with_seed(written), &origin).unwrap();
        assert_eq!(cfg.seed, seed, "{written}");
        assert_eq!(build(&cfg, &origin, None).unwrap().seed, seed, "{written}");
        let back = plumetrace_scenario::config::seed::value(seed);
        assert_eq!(back.to_string(), written);
    }
    for bad in ["-1", "\"12x\"", "\"18446744073709551616\"", "1.5"] {
        let e = error_of(&with_seed(bad));
        assert!(
            e.starts_with("scenario.toml:4: seed:") && e.contains("a whole number from 0 to"),
            "{bad}: {e}"
        );
    }
}

#[test]
fn the_success_radius_is_a_mission_key_with_a_default() {
    let origin = Origin::File("scenario.toml".into());
    let demo = find_preset("demo").unwrap().toml;
    let radius = |text: &str| {
        let cfg = parse(text, &origin).unwrap();
        build(&cfg, &origin, None)
            .unwrap()
            .mission
            .unwrap()
            .success_radius_m
    };
    assert_eq!(radius(demo), plumetrace_scenario::DEFAULT_SUCCESS_RADIUS_M);
    assert_eq!(plumetrace_scenario::DEFAULT_SUCCESS_RADIUS_M, 50.0);
    let set = demo.replacen("[mission]\n", "[mission]\nsuccess_radius_m = 12.5\n", 1);
    assert_eq!(radius(&set), 12.5);
    let bad = demo.replacen("[mission]\n", "[mission]\nsuccess_radius_m = -3.0\n", 1);
    let e = error_of(&bad);
    assert!(
        e.contains("mission.success_radius_m") && e.contains("> 0.0"),
        "{e}"
    );
}

#[test]
fn kelp_seeds_take_every_64_bit_value_as_the_run_seed_does() {
    let kelp = find_preset("li-zhang-kelp").unwrap().toml;
    for v in [
        "9223372036854775808",
        "\"9223372036854775808\"",
        "18446744073709551615",
        "\"18446744073709551615\"",
    ] {
        let text = kelp.replacen(
            "name = \"kelp\"",
            &format!("name = \"kelp\"\nseed = {v}"),
            1,
        );
        assert_ne!(text, kelp);
        assert_eq!(error_of(&text), "accepted", "seed = {v}");
    }
    let text = kelp.replacen("name = \"kelp\"", "name = \"kelp\"\nseed = -1", 1);
    assert!(error_of(&text).contains("kelp[0].seed: expected a whole number"));
}

#[test]
fn a_count_beyond_toml_integers_is_shown_where_it_is_written() {
    // A count read as a 64-bit unsigned number takes 2^63, which TOML's integers cannot hold:
    // the error shows the line and the number, where it used to name no key at all.
    let text = demo_with(|t| {
        t.replacen(
            "[plume]\n",
            "[plume]\nmax_filaments = 9223372036854775808\n",
            1,
        )
    });
    let e = error_of(&text);
    assert!(
        e.starts_with("scenario.toml: TOML parse error at line ")
            && e.contains("max_filaments = 9223372036854775808")
            && e.ends_with("(TOML's whole numbers go up to 9223372036854775807)"),
        "{e}"
    );
    // Within TOML's integers, the key's bound says what is wrong.
    let text = demo_with(|t| {
        t.replacen(
            "[plume]\n",
            "[plume]\nmax_filaments = 9223372036854775807\n",
            1,
        )
    });
    let e = error_of(&text);
    assert!(
        e.contains("plume.max_filaments: must be >= 1.0 and <= 10000000.0"),
        "{e}"
    );
}

#[test]
fn flow_sub_steps_count_in_the_step_budget_with_their_grid() {
    // A 0.1 s plume run on a fine grid whose stable step needs about 250,000 sub-steps per step
    // is within the budget; a 10 s one would take about 2.5e13 node updates and ran for days.
    let fine = |duration: &str| {
        demo_with(|t| {
            t.replacen("duration_s = 600.0", &format!("duration_s = {duration}"), 1)
                .replacen("nx = 21", "nx = 1000", 1)
                .replacen("ny = 11", "ny = 1000", 1)
                .replacen(
                    "noise_gain = 0.3",
                    "noise_gain = 0.3\ndiffusivity_x_m2ps = 10000.0\ndiffusivity_y_m2ps = 10000.0",
                    1,
                )
                .replacen("average_start_s = 300.0", "average_start_s = 0.0", 1)
        })
    };
    assert_eq!(error_of(&fine("0.1")), "accepted");
    let e = error_of(&fine("10.0"));
    assert!(
        e.contains("scenario.toml: flow.farrell:")
            && e.contains(
                "flow steps of 1000000 grid nodes each, 2.495e13 node updates; at most 1e12"
            ),
        "{e}"
    );
}

#[test]
fn a_step_too_short_for_single_precision_positions_names_its_key() {
    // Filament positions are single precision, from the domain's centre: in a 200 km domain
    // a walk of 1.4 cm a step (0.01 m^2/s over 0.01 s) is less than five roundings (3.9 mm).
    let wide = demo_with(|t| {
        t.replacen("x_max_m = 200.0", "x_max_m = 200000.0", 1)
            .replacen("dt_s = 0.1", "dt_s = 0.01", 1)
            .replacen(
                "horizontal_diffusivity_m2ps = 0.02",
                "horizontal_diffusivity_m2ps = 0.01",
                1,
            )
    });
    let e = error_of(&wide);
    assert!(
        e.contains("scenario.toml: sim.dt_s: a step of 0.01 s moves filaments east by about")
            && e.contains("it takes a step of at least 1.908e-2 s")
            && !e.contains("mission.env_dt_s"),
        "{e}"
    );
    let longer_step = demo_with(|t| {
        t.replacen("x_max_m = 200.0", "x_max_m = 200000.0", 1)
            .replacen(
                "horizontal_diffusivity_m2ps = 0.02",
                "horizontal_diffusivity_m2ps = 0.01",
                1,
            )
    });
    assert_eq!(error_of(&longer_step), "accepted");
    // A mission's plume steps at mission.env_dt_s, and at mission.spinup_dt_s in its spin-up:
    // heights 7 m up (the source) round to 0.24 micrometres, and a vertical walk of 1e-6 m a
    // step is lost.
    let demo = |kv: &str, spinup_dt: &str| {
        find_preset("demo")
            .unwrap()
            .toml
            .replacen(
                "vertical_diffusivity_m2ps = 0.001",
                &format!("vertical_diffusivity_m2ps = {kv}"),
                1,
            )
            .replacen(
                "spinup_dt_s = 30.0",
                &format!("spinup_dt_s = {spinup_dt}"),
                1,
            )
            .replacen("z_m = 0.0", "z_m = 7.0", 1)
    };
    let e = error_of(&demo("1e-13", "30.0"));
    assert!(
        e.contains("mission.env_dt_s: a step of 5 s moves filaments up by about 1.000e-6 m")
            && e.contains("at the highest a filament is carried to, 7.0 m up")
            && e.contains("a larger plume.vertical_diffusivity_m2ps"),
        "{e}"
    );
    let e = error_of(&demo("5e-13", "1.0"));
    assert!(
        e.contains("mission.spinup_dt_s: a step of 1 s moves filaments up"),
        "{e}"
    );
    assert_eq!(error_of(&demo("5e-13", "30.0")), "accepted");
    // Without mission.env_dt_s the plume steps at sim.dt_s, and the error says where the
    // plume's own step is set.
    let e = error_of(&demo("5e-13", "30.0").replacen("env_dt_s = 5.0", "", 1));
    assert!(
        e.contains("sim.dt_s: a step of 0.1 s moves filaments up")
            && e.contains("mission.env_dt_s steps the plume and flow apart from the vehicles"),
        "{e}"
    );
}

#[test]
fn a_key_that_is_not_bare_is_quoted_in_the_error_path() {
    let demo = find_preset("demo").unwrap().toml;
    let text = format!("{demo}\n[planners]\n\"\" = \"x\"\n");
    let e = error_of(&text);
    assert!(
        e.contains("scenario.toml:67: planners.\"\": invalid type"),
        "{e}"
    );
    let text = format!("{demo}\n[planners]\n\"a b\" = 1\n");
    let e = error_of(&text);
    assert!(e.contains("planners.\"a b\": invalid type"), "{e}");
}

/// `model = "salinity_deficit"` is the salinity probe read as its contrast below the medium:
/// the same keys, the deficit flag set; a typo of it names the models, and the salinity keys on
/// a voltage sensor name both salinity models.
#[test]
fn a_salinity_deficit_sensor_builds_and_its_mistakes_name_themselves() {
    let base = find_preset("soares-freshwater").unwrap().toml;
    let deficit = base.replacen(
        "[vehicles.chem_sensor]\nmodel = \"salinity\"",
        "[vehicles.chem_sensor]\nmodel = \"salinity_deficit\"\nmedium_salinity_ppt = 31.5\nnoise_sd_ppt = 0.05",
        1,
    );
    let origin = Origin::File("scenario.toml".into());
    let built = build(&parse(&deficit, &origin).unwrap(), &origin, None).unwrap();
    let s = built.vehicles[0].chem_sensor.salinity.unwrap();
    assert!(
        s.deficit && s.medium_ppt == 31.5 && s.noise_sd_ppt == 0.05,
        "{s:?}"
    );
    let leader = built.vehicles[1].chem_sensor.salinity.unwrap();
    assert!(!leader.deficit && leader.medium_ppt == 35.0, "{leader:?}");

    let typo = error_of(&base.replacen("model = \"salinity\"", "model = \"salinity_defict\"", 1));
    assert!(
        typo.contains("vehicles[0].chem_sensor.model")
            && typo.contains("did you mean `salinity_deficit`"),
        "{typo}"
    );
    let voltage = error_of(&base.replacen(
        "[vehicles.chem_sensor]\nmodel = \"salinity\"",
        "[vehicles.chem_sensor]\nmedium_salinity_ppt = 34.0",
        1,
    ));
    assert!(
        voltage.contains("vehicles[0].chem_sensor.medium_salinity_ppt")
            && voltage.contains("model = \"salinity\" or \"salinity_deficit\""),
        "{voltage}"
    );
    let negative = error_of(&deficit.replace("noise_sd_ppt = 0.05", "noise_sd_ppt = -0.05"));
    assert!(
        negative.contains("vehicles[0].chem_sensor.noise_sd_ppt"),
        "{negative}"
    );
}
