//! The seeds of the corpus: every built-in scenario preset and every example campaign, compiled
//! into the binary so the harness needs no files at run time.

use plumetrace_scenario::{PRESETS, find_preset};

/// What an input is read as.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Target {
    /// A scenario file, checked as `plumetrace check` does and then run briefly.
    Scenario,
    /// A campaign file, parsed, resolved and checked; its runs are counted, never flown.
    Campaign,
    /// A scenario family, parsed; a few of its sites are drawn and checked as `check` does.
    Family,
    /// An onboard file, checked as `plumetrace onboard FILE --check` does (nothing connected).
    Onboard,
    /// A CF NetCDF currents file, read by the example site's scenario as `check` does, and its
    /// flow queried.
    Netcdf,
    /// A CF NetCDF bathymetry file, read by the example site's scenario as `check` does, and its
    /// seabed queried.
    Seabed,
}

impl Target {
    /// The file name an input of this target is written to (errors must name it).
    pub fn file_name(self) -> &'static str {
        match self {
            Target::Scenario => "fuzz.toml",
            Target::Campaign => "fuzz-campaign.toml",
            Target::Family => "fuzz.family.toml",
            Target::Onboard => "fuzz.onboard.toml",
            Target::Netcdf => "fuzz.nc",
            Target::Seabed => "fuzz-bathymetry.nc",
        }
    }

    /// Lower-case name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Target::Scenario => "scenario",
            Target::Campaign => "campaign",
            Target::Family => "family",
            Target::Onboard => "onboard",
            Target::Netcdf => "netcdf",
            Target::Seabed => "seabed",
        }
    }
}

/// The name the example site's seabed is written under beside a NetCDF input (a `fuzz` name,
/// as every file beside an input has).
pub const NETCDF_SEABED: &str = "fuzz-seabed.nc";

/// The scenario a NetCDF input is read by: the example site with its currents file replaced,
/// over its own seabed written as [`NETCDF_SEABED`].
pub fn netcdf_scenario() -> String {
    include_str!("../../../examples/sites/site.toml")
        .replacen(
            "file = \"currents.nc\"",
            &format!("file = \"{}\"", Target::Netcdf.file_name()),
            1,
        )
        .replacen(
            "file = \"seabed.nc\"",
            &format!("file = \"{NETCDF_SEABED}\""),
            1,
        )
}

/// The name the example site's currents are written under beside a bathymetry input.
pub const SEABED_CURRENTS: &str = "fuzz-currents.nc";

/// The scenario a bathymetry input is read by: the example site with its seabed file replaced,
/// under its own currents written as [`SEABED_CURRENTS`].
pub fn seabed_scenario() -> String {
    include_str!("../../../examples/sites/site.toml")
        .replacen(
            "file = \"currents.nc\"",
            &format!("file = \"{SEABED_CURRENTS}\""),
            1,
        )
        .replacen(
            "file = \"seabed.nc\"",
            &format!("file = \"{}\"", Target::Seabed.file_name()),
            1,
        )
}

/// The bathymetry seeds: the example site's seabed (CDF-1, GEBCO-style elevations on longitude
/// and latitude), a projected grid of depths (CDF-2, shorts packed with a scale, a fill value on
/// land far from the op-area), a curvilinear grid (2-D longitude and latitude turned 15°, as
/// ROMS writes `h` on `lon_rho` and `lat_rho`) and two GeoTIFFs (longitude and latitude; UTM
/// zone 30N), all covering the site's op-area.
pub fn seabed_seeds() -> Vec<(&'static str, Vec<u8>)> {
    use plumetrace_netcdf::{Dataset, NcType};
    // The projected grid: x -100..620 m, y -250..250 m, 40 m apart; depths 10 m to 18 m east.
    let mut p = Dataset::default();
    let (ny, nx) = (14usize, 19usize);
    let y = p.dim("y", ny);
    let x = p.dim("x", nx);
    let xs: Vec<f64> = (0..nx).map(|k| -100.0 + 40.0 * k as f64).collect();
    let ys: Vec<f64> = (0..ny).map(|k| -260.0 + 40.0 * k as f64).collect();
    p.var("y", &[y], ys.clone())
        .attr("standard_name", "projection_y_coordinate")
        .attr("units", "m");
    p.var("x", &[x], xs.clone())
        .attr("standard_name", "projection_x_coordinate")
        .attr("units", "m");
    let mut depth: Vec<f64> = Vec::new();
    for _ in &ys {
        for xx in &xs {
            depth.push(((10.0 + 8.0 * (xx + 100.0) / 720.0) * 100.0).round());
        }
    }
    depth[0] = -1.0;
    p.var("depth", &[y, x], depth)
        .of_type(NcType::Short)
        .attr("standard_name", "sea_floor_depth_below_sea_surface")
        .attr("units", "m")
        .attr("scale_factor", 0.01)
        .attr("_FillValue", -1i16);
    // The curvilinear grid, about the site's origin (50.35 N, 4.15 W).
    let mut c = Dataset::default();
    let (ne, nxi) = (16usize, 24usize);
    let eta = c.dim("eta_rho", ne);
    let xi = c.dim("xi_rho", nxi);
    let (sn, cs) = 15f64.to_radians().sin_cos();
    let (mut lon, mut lat, mut h) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..ne {
        for i in 0..nxi {
            let (a, b) = (40.0 * i as f64 - 460.0, 40.0 * j as f64 - 300.0);
            let (east, north) = (260.0 + cs * a - sn * b, sn * a + cs * b);
            lon.push(-4.15 + east / 71_090.0);
            lat.push(50.35 + north / 111_200.0);
            h.push(10.0 + 0.015 * (east + 100.0));
        }
    }
    c.var("lon_rho", &[eta, xi], lon)
        .attr("standard_name", "longitude")
        .attr("units", "degree_east");
    c.var("lat_rho", &[eta, xi], lat)
        .attr("standard_name", "latitude")
        .attr("units", "degree_north");
    c.var("h", &[eta, xi], h)
        .of_type(NcType::Float)
        .attr("units", "meter")
        .attr("coordinates", "lon_rho lat_rho");
    vec![
        (
            "site-seabed",
            include_bytes!("../../../examples/sites/seabed.nc").to_vec(),
        ),
        ("projected-seabed", p.to_bytes().unwrap_or_default()),
        ("curvilinear-seabed", c.to_bytes().unwrap_or_default()),
        ("geotiff-seabed", geotiff_seabed()),
        ("utm-geotiff-seabed", utm_geotiff_seabed()),
    ]
}

/// The site's seabed as a survey's GeoTIFF in WGS 84 / UTM zone 30N (EPSG:32630): depths
/// (positive) on 20 m pixels from 200 m west and 300 m north of the site's origin, pixels as
/// points, metres named by ProjLinearUnitsGeoKey.
fn utm_geotiff_seabed() -> Vec<u8> {
    use plumetrace_core::geo::TransverseMercator;
    use tiff::encoder::{TiffEncoder, colortype::Gray32Float};
    use tiff::tags::Tag;
    let Some((e0, n0)) = TransverseMercator::utm(30, true)
        .ok()
        .and_then(|tm| tm.forward(50.35, -4.15).ok())
    else {
        return Vec::new();
    };
    let (w, h) = (48u32, 31u32);
    let data: Vec<f32> = (0..w * h).map(|k| 10.0 + 0.3 * (k % w) as f32).collect();
    let mut out = std::io::Cursor::new(Vec::new());
    let write = |out: &mut std::io::Cursor<Vec<u8>>| -> tiff::TiffResult<()> {
        let mut enc = TiffEncoder::new(out)?;
        let mut image = enc.new_image::<Gray32Float>(w, h)?;
        let e = image.encoder();
        e.write_tag(Tag::ModelPixelScaleTag, &[20.0f64, 20.0, 0.0][..])?;
        e.write_tag(
            Tag::ModelTiepointTag,
            &[
                0.0f64,
                0.0,
                0.0,
                (e0 - 200.0).round(),
                (n0 + 300.0).round(),
                0.0,
            ][..],
        )?;
        e.write_tag(
            Tag::GeoKeyDirectoryTag,
            &[
                1u16, 1, 0, 4, 1024, 0, 1, 1, 1025, 0, 1, 2, 3072, 0, 1, 32630, 3076, 0, 1, 9001,
            ][..],
        )?;
        image.write_data(&data)
    };
    match write(&mut out) {
        Ok(()) => out.into_inner(),
        Err(_) => Vec::new(),
    }
}

/// The site's seabed as a GeoTIFF (GEBCO-style elevations on WGS 84, 0.0005° pixels from
/// 4.153 W, 50.3535 N; GeoKeys, tiepoint, pixel scale and GDAL's no-data tag), as the tiff
/// crate writes it.
fn geotiff_seabed() -> Vec<u8> {
    use tiff::encoder::{TiffEncoder, colortype::Gray32Float};
    use tiff::tags::Tag;
    let (w, h) = (24u32, 14u32);
    let data: Vec<f32> = (0..w * h)
        .map(|k| -10.0 - 0.3 * (k % w) as f32 - if k == 0 { 9989.0 } else { 0.0 })
        .collect();
    let mut out = std::io::Cursor::new(Vec::new());
    let write = |out: &mut std::io::Cursor<Vec<u8>>| -> tiff::TiffResult<()> {
        let mut enc = TiffEncoder::new(out)?;
        let mut image = enc.new_image::<Gray32Float>(w, h)?;
        let e = image.encoder();
        e.write_tag(Tag::ModelPixelScaleTag, &[0.0005f64, 0.0005, 0.0][..])?;
        e.write_tag(
            Tag::ModelTiepointTag,
            &[0.0f64, 0.0, 0.0, -4.153, 50.3535, 0.0][..],
        )?;
        e.write_tag(
            Tag::GeoKeyDirectoryTag,
            &[
                1u16, 1, 0, 3, 1024, 0, 1, 2, 1025, 0, 1, 1, 2048, 0, 1, 4326,
            ][..],
        )?;
        e.write_tag(Tag::Unknown(42113), "-9999")?;
        image.write_data(&data)
    };
    match write(&mut out) {
        Ok(()) => out.into_inner(),
        Err(_) => Vec::new(),
    }
}

/// The NetCDF seeds: the example site's currents (CDF-1, shorts, fill values, longitude and
/// latitude, depth levels, a record dimension), the same site on a projected grid (CDF-2,
/// doubles, no depth) and as ROMS writes it (curvilinear, terrain-following levels), the last
/// two written by the codec.
pub fn netcdf_seeds() -> Vec<(&'static str, Vec<u8>)> {
    use plumetrace_netcdf::{Dataset, NcType};
    let mut d = Dataset::default();
    let t = d.record_dim("time", 3);
    let y = d.dim("y", 9);
    let x = d.dim("x", 15);
    d.var("time", &[t], vec![0.0, 3600.0, 7200.0])
        .attr("units", "seconds since 2026-06-01 01:00:00");
    d.var(
        "y",
        &[y],
        (0..9).map(|k| -200.0 + 50.0 * f64::from(k)).collect(),
    )
    .attr("standard_name", "projection_y_coordinate")
    .attr("units", "m");
    d.var(
        "x",
        &[x],
        (0..15).map(|k| -100.0 + 50.0 * f64::from(k)).collect(),
    )
    .attr("standard_name", "projection_x_coordinate")
    .attr("units", "m");
    let n = 3 * 9 * 15;
    d.var(
        "u",
        &[t, y, x],
        (0..n).map(|k| 0.1 + 1e-4 * f64::from(k)).collect(),
    )
    .attr("standard_name", "sea_water_x_velocity")
    .attr("units", "m s-1");
    d.var("v", &[t, y, x], vec![2.0; n as usize])
        .of_type(NcType::Short)
        .attr("standard_name", "sea_water_y_velocity")
        .attr("units", "cm s-1")
        .attr("_FillValue", -999i16);
    vec![
        (
            "site-currents",
            include_bytes!("../../../examples/sites/currents.nc").to_vec(),
        ),
        ("projected", d.to_bytes().unwrap_or_default()),
        ("roms-currents", roms_currents()),
    ]
}

/// The site's currents as ROMS writes them: `u_eastward` and `v_northward` on a curvilinear
/// grid (2-D `lon_rho` and `lat_rho`, turned 15°) and four `ocean_s_coordinate_g2` levels with
/// `Cs_r`, `zeta`, `h` and `hc`, hourly frames from midnight.
fn roms_currents() -> Vec<u8> {
    use plumetrace_netcdf::{Dataset, NcType};
    let mut d = Dataset::default();
    let (nt, ns, ne, nxi) = (7usize, 4usize, 12usize, 18usize);
    let t = d.record_dim("ocean_time", nt);
    let s = d.dim("s_rho", ns);
    let eta = d.dim("eta_rho", ne);
    let xi = d.dim("xi_rho", nxi);
    d.var(
        "ocean_time",
        &[t],
        (0..nt).map(|k| 3600.0 * k as f64).collect(),
    )
    .attr("units", "seconds since 2026-06-01 00:00:00");
    let sv = [-0.875, -0.625, -0.375, -0.125];
    d.var("s_rho", &[s], sv.to_vec())
        .attr("standard_name", "ocean_s_coordinate_g2")
        .attr("positive", "up")
        .attr(
            "formula_terms",
            "s: s_rho C: Cs_r eta: zeta depth: h depth_c: hc",
        );
    d.var("Cs_r", &[s], sv.iter().map(|v| -v * v).collect());
    d.var("hc", &[], vec![5.0]).attr("units", "meter");
    let (sn, cs) = 15f64.to_radians().sin_cos();
    let (mut lon, mut lat, mut h) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..ne {
        for i in 0..nxi {
            let (a, b) = (55.0 * i as f64 - 470.0, 55.0 * j as f64 - 300.0);
            let (east, north) = (260.0 + cs * a - sn * b, sn * a + cs * b);
            lon.push(-4.15 + east / 71_090.0);
            lat.push(50.35 + north / 111_200.0);
            h.push(12.0 + 0.012 * (east + 100.0));
        }
    }
    let n2 = ne * nxi;
    d.var("lon_rho", &[eta, xi], lon)
        .attr("standard_name", "longitude")
        .attr("units", "degree_east");
    d.var("lat_rho", &[eta, xi], lat)
        .attr("standard_name", "latitude")
        .attr("units", "degree_north");
    d.var("h", &[eta, xi], h).attr("units", "meter");
    let zeta: Vec<f64> = (0..nt * n2)
        .map(|k| 0.8 * (k / n2) as f64 / nt as f64 - 0.4)
        .collect();
    d.var("zeta", &[t, eta, xi], zeta)
        .of_type(NcType::Float)
        .attr("units", "meter");
    let n = nt * ns * n2;
    for (name, sn, base) in [
        ("u_eastward", "eastward_sea_water_velocity", 0.2),
        ("v_northward", "northward_sea_water_velocity", 0.02),
    ] {
        d.var(
            name,
            &[t, s, eta, xi],
            (0..n)
                .map(|k| base + 0.01 * ((k / n2) % ns) as f64)
                .collect(),
        )
        .of_type(NcType::Float)
        .attr("standard_name", sn)
        .attr("units", "meter second-1")
        .attr("coordinates", "lon_rho lat_rho s_rho ocean_time");
    }
    d.to_bytes().unwrap_or_default()
}

/// One seed of the corpus.
#[derive(Debug, Clone, Copy)]
pub struct Seed {
    /// Preset or campaign name.
    pub name: &'static str,
    /// What it is read as.
    pub target: Target,
    /// Its TOML text.
    pub text: &'static str,
}

/// The example campaigns (`examples/campaigns/*.toml`; a test checks the list is complete).
pub const CAMPAIGNS: &[(&str, &str)] = &[
    (
        "amp-declaration",
        include_str!("../../../examples/campaigns/amp-declaration.toml"),
    ),
    (
        "amp-vs-lawnmower",
        include_str!("../../../examples/campaigns/amp-vs-lawnmower.toml"),
    ),
    (
        "amp-unbiased-tuning-coastal",
        include_str!("../../../examples/campaigns/amp-unbiased-tuning-coastal.toml"),
    ),
    (
        "amp-unbiased-tuning-duck-like",
        include_str!("../../../examples/campaigns/amp-unbiased-tuning-duck-like.toml"),
    ),
    (
        "amp-unbiased-tuning-faults",
        include_str!("../../../examples/campaigns/amp-unbiased-tuning-faults.toml"),
    ),
    (
        "amp-fix-frames",
        include_str!("../../../examples/campaigns/amp-fix-frames.toml"),
    ),
    (
        "amp-fix-smoothing",
        include_str!("../../../examples/campaigns/amp-fix-smoothing.toml"),
    ),
    (
        "multi-source",
        include_str!("../../../examples/campaigns/multi-source.toml"),
    ),
    (
        "moth-comparison",
        include_str!("../../../examples/campaigns/moth-comparison.toml"),
    ),
    (
        "amp-families",
        include_str!("../../../examples/campaigns/amp-families.toml"),
    ),
    (
        "mt-lost-points",
        include_str!("../../../examples/campaigns/mt-lost-points.toml"),
    ),
    (
        "formation-soares",
        include_str!("../../../examples/campaigns/formation-soares.toml"),
    ),
    (
        "formation-soares-filaments",
        include_str!("../../../examples/campaigns/formation-soares-filaments.toml"),
    ),
    (
        "formation-family",
        include_str!("../../../examples/campaigns/formation-family.toml"),
    ),
    (
        "formation-family-tuning",
        include_str!("../../../examples/campaigns/formation-family-tuning.toml"),
    ),
    (
        "map-declaration-coastal",
        include_str!("../../../examples/campaigns/map-declaration-coastal.toml"),
    ),
    (
        "map-declaration-duck",
        include_str!("../../../examples/campaigns/map-declaration-duck.toml"),
    ),
    (
        "probabilistic",
        include_str!("../../../examples/campaigns/probabilistic.toml"),
    ),
    (
        "map-tuning",
        include_str!("../../../examples/campaigns/map-tuning.toml"),
    ),
    (
        "infotaxis-tuning",
        include_str!("../../../examples/campaigns/infotaxis-tuning.toml"),
    ),
    (
        "infotaxis-along",
        include_str!("../../../examples/campaigns/infotaxis-along.toml"),
    ),
    (
        "infotaxis-along-speed",
        include_str!("../../../examples/campaigns/infotaxis-along-speed.toml"),
    ),
    (
        "ten-planners-one-plume",
        include_str!("../../../examples/campaigns/ten-planners-one-plume.toml"),
    ),
    (
        "amp-mapping",
        include_str!("../../../examples/campaigns/amp-mapping.toml"),
    ),
    (
        "meander-noise",
        include_str!("../../../examples/campaigns/meander-noise.toml"),
    ),
    (
        "plume-steps",
        include_str!("../../../examples/campaigns/plume-steps.toml"),
    ),
    (
        "map-declaration-duck-like",
        include_str!("../../../examples/campaigns/map-declaration-duck-like.toml"),
    ),
    (
        "map-mixing",
        include_str!("../../../examples/campaigns/map-mixing.toml"),
    ),
    (
        "map-rule",
        include_str!("../../../examples/campaigns/map-rule.toml"),
    ),
    (
        "site",
        include_str!("../../../examples/campaigns/site.toml"),
    ),
    (
        "track-altitude",
        include_str!("../../../examples/campaigns/track-altitude.toml"),
    ),
];

/// The example families (`examples/families/*.family.toml`; a test checks the list is complete).
pub const FAMILIES: &[(&str, &str)] = &[
    (
        "coastal",
        include_str!("../../../examples/families/coastal.family.toml"),
    ),
    (
        "duck-like",
        include_str!("../../../examples/families/duck-like.family.toml"),
    ),
    (
        "faults",
        include_str!("../../../examples/families/faults.family.toml"),
    ),
    (
        "formation",
        include_str!("../../../examples/families/formation.family.toml"),
    ),
    (
        "multi-source",
        include_str!("../../../examples/families/multi-source.family.toml"),
    ),
];

/// Onboard files: a Bluefin link flying the AMP in lock-step, an Iver link flying the moth with
/// a separate chemical input and a current meter, and a lawnmower with subregions and limits.
pub const ONBOARDS: &[(&str, &str)] = &[
    (
        "bluefin-amp",
        r#"name = "demo on a vehicle"
[mission]
op_area = [[60.0, -80.0], [460.0, -80.0], [460.0, 80.0], [60.0, 80.0]]
prior_flow_toward_deg = 90.0
[planner]
kind = "amp"
speed_mps = 1.5
mapping_lines = 3
[link]
protocol = "bluefin"
address = "127.0.0.1:29500"
origin = { lat_deg = 36.18, lon_deg = -75.75 }
[chemical]
format = "sentence"
id = "PTCHM"
field = 2
[run]
mode = "lock_step"
"#,
    ),
    (
        "iver-moth",
        r#"name = "iver"
[mission]
op_area = [[0.0, 0.0], [300.0, 0.0], [300.0, 200.0], [0.0, 200.0]]
vehicle_kind = "auv"
[planner]
kind = "moth"
[link]
protocol = "iver"
device = "/dev/ttyUSB0"
remote_helm_major = 5
baud = 57600
origin = { lat_deg = 44.0, lon_deg = -68.0 }
limits = { max_speed_mps = 2.0, max_depth_m = 50.0, min_altitude_m = 2.0, max_altitude_m = 20.0 }
[chemical]
format = "plain"
address = "127.0.0.1:29501"
[flow]
address = "127.0.0.1:29502"
layer = 3
[run]
mode = "real_time"
time_limit_s = 3600.0
"#,
    ),
    (
        "bluefin-lawnmower",
        r#"name = "survey"
[mission]
op_area = [[0.0, 0.0], [400.0, 0.0], [400.0, 300.0], [0.0, 300.0]]
subregions = [[[0.0, 0.0], [200.0, 0.0], [200.0, 300.0], [0.0, 300.0]]]
prior_flow_toward_deg = 45.0
[planner]
kind = "lawnmower"
lane_spacing_m = 20.0
[link]
protocol = "bluefin"
address = "10.0.0.2:29500"
origin = { lat_deg = -33.9, lon_deg = 151.2 }
stale_nav_s = 10.0
ack_tries = 5
"#,
    ),
];

/// Every seed: the presets in registry order, then the campaigns, the families and the onboard
/// files.
pub fn seeds() -> Vec<Seed> {
    PRESETS
        .iter()
        .map(|p| Seed {
            name: p.name,
            target: Target::Scenario,
            text: p.toml,
        })
        .chain(CAMPAIGNS.iter().map(|(name, text)| Seed {
            name,
            target: Target::Campaign,
            text,
        }))
        .chain(FAMILIES.iter().map(|(name, text)| Seed {
            name,
            target: Target::Family,
            text,
        }))
        .chain(ONBOARDS.iter().map(|(name, text)| Seed {
            name,
            target: Target::Onboard,
            text,
        }))
        .collect()
}

/// Family files written where campaign inputs look for them (`../families/NAME.family.toml`
/// from the campaign directory, as in `examples/`).
pub fn family_side_files() -> Vec<(String, &'static str)> {
    FAMILIES
        .iter()
        .map(|(name, text)| (format!("{name}.family.toml"), *text))
        .collect()
}

/// The example site's files, written to a `sites` directory beside the campaign inputs' one, so
/// that a campaign naming `../sites/site.toml` (the shipped `site` campaign) finds them.
pub fn site_side_files() -> Vec<(&'static str, &'static [u8])> {
    vec![
        (
            "site.toml",
            include_str!("../../../examples/sites/site.toml").as_bytes(),
        ),
        (
            "currents.nc",
            include_bytes!("../../../examples/sites/currents.nc"),
        ),
        (
            "seabed.nc",
            include_bytes!("../../../examples/sites/seabed.nc"),
        ),
    ]
}

/// Scenario files written next to every campaign input, so that campaign inputs naming
/// `scenario.toml` (a mission) or `plume.toml` (plume only) find a real file.
pub fn campaign_side_files() -> Vec<(&'static str, &'static str)> {
    let text = |name: &str| find_preset(name).map_or("", |p| p.toml);
    vec![
        ("scenario.toml", text("demo")),
        ("plume.toml", text("plume-demo")),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_netcdf_scenario_reads_the_input_over_the_fuzz_named_seabed() {
        let text = netcdf_scenario();
        assert!(text.contains(&format!("file = \"{}\"", Target::Netcdf.file_name())));
        assert!(
            text.contains(&format!("file = \"{NETCDF_SEABED}\"")),
            "{text}"
        );
        assert!(!text.contains("\"currents.nc\"") && !text.contains("\"seabed.nc\""));
    }

    #[test]
    fn every_example_family_is_a_seed() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/families");
        let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
            .map(|d| {
                d.filter_map(Result::ok)
                    .filter_map(|e| e.file_name().into_string().ok())
                    .filter_map(|n| n.strip_suffix(".family.toml").map(str::to_string))
                    .collect()
            })
            .unwrap_or_default();
        on_disk.sort();
        let mut embedded: Vec<String> = FAMILIES.iter().map(|c| c.0.to_string()).collect();
        embedded.sort();
        assert_eq!(on_disk, embedded, "embed every file of {}", dir.display());
    }

    #[test]
    fn every_example_campaign_is_a_seed() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/campaigns");
        let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
            .map(|d| {
                d.filter_map(Result::ok)
                    .filter_map(|e| e.file_name().into_string().ok())
                    .filter_map(|n| n.strip_suffix(".toml").map(str::to_string))
                    .collect()
            })
            .unwrap_or_default();
        on_disk.sort();
        let mut embedded: Vec<String> = CAMPAIGNS.iter().map(|c| c.0.to_string()).collect();
        embedded.sort();
        assert_eq!(on_disk, embedded, "embed every file of {}", dir.display());
    }

    #[test]
    fn every_seed_is_toml_and_side_files_exist() {
        let all = seeds();
        assert_eq!(
            all.len(),
            PRESETS.len() + CAMPAIGNS.len() + FAMILIES.len() + ONBOARDS.len()
        );
        for (name, text) in ONBOARDS {
            assert!(
                plumetrace_onboard::config::Onboard::from_toml(text).is_ok(),
                "{name}"
            );
        }
        for s in &all {
            assert!(s.text.parse::<toml::Table>().is_ok(), "{}", s.name);
        }
        assert!(campaign_side_files().iter().all(|(_, t)| !t.is_empty()));
    }
}
