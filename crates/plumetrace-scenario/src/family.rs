//! Scenario families: sites drawn at random around a base scenario, so that a planner is judged
//! on many sites rather than on one preset.
//!
//! A family file names a base scenario (a preset or a scenario file: it gives the plume model,
//! the vehicle and its sensors, the planner) and ranges for what varies from site to site: the
//! mean flow (any direction, a speed, a tidal swing of its direction, the meander), the op-area
//! (shape, size, orientation relative to the flow), the source (anywhere at least `inset_m`
//! inside the op-area, its strength), the vehicle's start (the down-flow corner, a point on the
//! edge, inside), the navigation (fix interval and accuracy) and faults (a reversed flow reading
//! for a window). Every range is `[low, high]`, drawn uniformly (a source strength log-uniformly);
//! `[x, x]` fixes a value. [`Family::draw`] turns a seed into a [`Site`], and [`Site::apply`]
//! writes the site into the base scenario's table: the domain (the op-area's bounding box with a
//! margin), the mean flow, the op-area and prior flow direction, the first source (the others are
//! dropped), the first vehicle's start, navigation and flow-sensor fault, the spin-up (long enough
//! for the plume to cross the op-area) and the time limit.
//!
//! The op-area is centred on the origin of the local frame. Its main axis points along the flow
//! turned by `axis_to_flow_deg`; `rectangle` is `length_m` along the axis by `width_m` across,
//! `convex` a polygon of 5 to 8 vertices at random angles on the ellipse of those axes (convex by
//! construction).
//!
//! A site is drawn from its seed alone (one random stream), so a campaign that draws site `k` from
//! `derive_seed(campaign seed, k)` gives every planner configuration the same sites, and
//! `plumetrace family FILE --sample N --seed S` writes the very sites a campaign with seed `S`
//! flies.

use crate::{Origin, ScenarioError, find_preset};
use plumetrace_core::Vec2;
use plumetrace_env::{StreamId, stream_rng};
use rand::Rng;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The random stream of a site draw.
const SITE_STREAM: u64 = 0x7369_7465;

/// A range `[low, high]` drawn uniformly.
pub type Range = [f64; 2];

/// The family file as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FamilyFile {
    /// Name (runs.csv and tables use it as the scenario label).
    pub name: String,
    /// One line about it.
    #[serde(default)]
    pub description: String,
    /// The base scenario: a preset name, or a path ending in `.toml` relative to the family file.
    pub base: String,
    /// Mission time limit, s (default: the base's).
    #[serde(default)]
    pub time_limit_s: Option<f64>,
    /// Room around the op-area in the simulated domain, m.
    #[serde(default = "default_margin")]
    pub domain_margin_m: f64,
    /// Error of the prior flow direction the planner is given, deg (drawn in this range).
    #[serde(default)]
    pub prior_flow_error_deg: Option<Range>,
    /// Vertical mixing that grows with the current: each site's plume gets a vertical diffusivity
    /// of this length times its flow speed, m (a bottom boundary layer's `kappa u* z`, with
    /// `u* = 0.063 U` for a drag coefficient of 0.004 and `z` = 1.5 m, gives 0.038 m). Default:
    /// the base's diffusivity at every site.
    #[serde(default)]
    pub vertical_mixing_length_m: Option<f64>,
    /// The mean flow.
    pub flow: FlowDraw,
    /// The op-area.
    pub area: AreaDraw,
    /// The source.
    #[serde(default)]
    pub source: SourceDraw,
    /// The vehicle's start.
    #[serde(default)]
    pub start: StartDraw,
    /// Navigation fixes (default: the base's).
    #[serde(default)]
    pub nav: Option<NavDraw>,
    /// Sensor faults (default: none).
    #[serde(default)]
    pub faults: Option<FaultDraw>,
    /// A formation team's draws (see [`crate::family_team`]).
    #[serde(default)]
    pub team: Option<crate::family_team::TeamDraw>,
    /// Several sources, one per subregion of a grid (see [`crate::family_regions`]).
    #[serde(default)]
    pub regions: Option<crate::family_regions::RegionsDraw>,
}

fn default_margin() -> f64 {
    200.0
}

/// `[flow]`: the mean flow of a site.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlowDraw {
    /// Direction the water goes towards, compass deg.
    #[serde(default = "all_directions")]
    pub toward_deg: Range,
    /// Speed, m/s.
    pub speed_mps: Range,
    /// Peak-to-peak swing of the direction over a tidal period, deg (0: steady).
    #[serde(default)]
    pub tidal_swing_deg: Option<Range>,
    /// Tidal period, s (the M2 tide's 12.42 h by default).
    #[serde(default = "m2_period")]
    pub tidal_period_s: f64,
    /// Meander: the noise gain of a Farrell base flow (default: the base's).
    #[serde(default)]
    pub meander_gain: Option<Range>,
}

fn all_directions() -> Range {
    [0.0, 360.0]
}

fn m2_period() -> f64 {
    44_712.0
}

/// Op-area shapes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// A rectangle along the main axis.
    Rectangle,
    /// A convex polygon of 5 to 8 vertices on the ellipse of the axes.
    Convex,
}

/// `[area]`: the op-area of a site.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AreaDraw {
    /// Shapes drawn from, equally likely.
    #[serde(default = "rectangle_only")]
    pub shapes: Vec<Shape>,
    /// Extent along the main axis, m.
    pub length_m: Range,
    /// Extent across it, m.
    pub width_m: Range,
    /// Angle of the main axis from the flow direction, deg (0: along the flow).
    #[serde(default)]
    pub axis_to_flow_deg: Option<Range>,
}

fn rectangle_only() -> Vec<Shape> {
    vec![Shape::Rectangle]
}

/// `[source]`: the source of a site.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SourceDraw {
    /// Least distance from every edge of the op-area, m.
    #[serde(default = "default_inset")]
    pub inset_m: f64,
    /// Release rate (drawn log-uniformly; default: the base's).
    #[serde(default)]
    pub mass_rate_per_s: Option<Range>,
}

fn default_inset() -> f64 {
    60.0
}

impl Default for SourceDraw {
    fn default() -> Self {
        SourceDraw {
            inset_m: default_inset(),
            mass_rate_per_s: None,
        }
    }
}

/// Where a vehicle starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StartKind {
    /// 20 m inside the op-area's most down-flow vertex.
    DownflowCorner,
    /// 10 m inside a random point of the edge.
    Edge,
    /// A random point at least 30 m inside.
    Inside,
}

/// `[start]`: the vehicle's start.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartDraw {
    /// Kinds drawn from, equally likely.
    #[serde(default = "corner_only")]
    pub kinds: Vec<StartKind>,
}

fn corner_only() -> Vec<StartKind> {
    vec![StartKind::DownflowCorner]
}

impl Default for StartDraw {
    fn default() -> Self {
        StartDraw {
            kinds: corner_only(),
        }
    }
}

/// `[nav]`: navigation fixes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NavDraw {
    /// Time between fixes, s.
    pub fix_interval_s: Range,
    /// Fix error (standard deviation), m.
    pub fix_sigma_m: Range,
}

/// `[faults]`: sensor faults.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultDraw {
    /// Chance that a site's flow sensor reads the wrong layer (reversed) for a while.
    pub flow_sensor_probability: f64,
    /// How long the fault lasts, s.
    pub duration_s: Range,
}

/// One drawn site: every drawn value, and what follows from them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Site {
    /// Mean flow direction, compass deg.
    pub flow_toward_deg: f64,
    /// Mean flow speed, m/s.
    pub flow_speed_mps: f64,
    /// Tidal swing of the direction, deg.
    pub tidal_swing_deg: f64,
    /// Tidal phase, deg.
    pub tidal_phase_deg: f64,
    /// Meander noise gain, if drawn.
    pub meander_gain: Option<f64>,
    /// Op-area shape.
    pub shape: Shape,
    /// Compass direction of the op-area's main axis, deg.
    pub axis_deg: f64,
    /// The flow's angle from the main axis, folded to 0..90 deg (0: along it).
    pub flow_to_axis_deg: f64,
    /// Extent along the axis, m.
    pub length_m: f64,
    /// Extent across it, m.
    pub width_m: f64,
    /// Op-area vertices, m.
    pub op_area: Vec<[f64; 2]>,
    /// Source position, m.
    pub source: [f64; 2],
    /// Source's distance from the nearest op-area edge, m.
    pub source_edge_m: f64,
    /// Source strength, if drawn.
    pub mass_rate_per_s: Option<f64>,
    /// Start kind.
    pub start: StartKind,
    /// Start position, m.
    pub start_pos: [f64; 2],
    /// Start heading, compass deg.
    pub start_heading_deg: f64,
    /// Prior flow direction given to the planner, compass deg.
    pub prior_flow_deg: f64,
    /// Fix interval, s, if drawn.
    pub fix_interval_s: Option<f64>,
    /// Fix error, m, if drawn.
    pub fix_sigma_m: Option<f64>,
    /// Flow-sensor fault window `[start, end]`, s, if any.
    pub flow_fault_s: Option<[f64; 2]>,
    /// Spin-up time, s.
    pub spinup_s: f64,
    /// A formation team's draws, if the family has `[team]`.
    pub team: Option<crate::family_team::TeamSite>,
    /// The subregions and their sources, if the family has `[regions]` (then `source`,
    /// `source_edge_m` and `mass_rate_per_s` are the first source's).
    pub regions: Option<crate::family_regions::RegionsSite>,
}

/// A loaded, checked family.
#[derive(Debug, Clone, PartialEq)]
pub struct Family {
    /// The file as written.
    pub file: FamilyFile,
    /// Where it came from.
    pub path: PathBuf,
    /// Its text.
    pub text: String,
    /// The base scenario's origin.
    pub base_origin: Origin,
    /// The base scenario's table.
    pub base: toml::Table,
}

/// Bounds of a family key: `(key, low, high, why)`.
pub const FAMILY_LIMITS: &[(&str, f64, f64, &str)] = &[
    ("time_limit_s", 1.0, 1e6, "about 11 days at most"),
    (
        "domain_margin_m",
        1.0,
        10_000.0,
        "room for the plume and the cage (at least 1 m: the domain is written to 0.1 m, the op-area to 0.01 m)",
    ),
    (
        "vertical_mixing_length_m",
        0.0,
        200.0,
        "times a current of up to 5 m/s, within the scenario's vertical diffusivity bound (1000 m^2/s)",
    ),
    ("prior_flow_error_deg[]", -180.0, 180.0, "an angle"),
    ("flow.toward_deg[]", -720.0, 720.0, "compass degrees"),
    (
        "flow.speed_mps[]",
        0.001,
        5.0,
        "a current a vehicle can work in",
    ),
    ("flow.tidal_swing_deg[]", 0.0, 360.0, "at most a full turn"),
    (
        "flow.tidal_period_s",
        60.0,
        1e7,
        "a period of minutes to months",
    ),
    (
        "flow.meander_gain[]",
        0.0,
        1.0,
        "the Farrell noise gain; above 1 the meander reaches metres per second and the grid can diverge (plume-demo's does at 5 within two minutes)",
    ),
    (
        "area.length_m[]",
        10.0,
        100_000.0,
        "an op-area of metres to 100 km",
    ),
    (
        "area.width_m[]",
        10.0,
        100_000.0,
        "an op-area of metres to 100 km",
    ),
    ("area.axis_to_flow_deg[]", -180.0, 180.0, "an angle"),
    ("source.inset_m", 0.0, 50_000.0, "inside the op-area"),
    (
        "source.mass_rate_per_s[]",
        1e-9,
        1e9,
        "a positive release rate",
    ),
    (
        "nav.fix_interval_s[]",
        0.1,
        1e6,
        "as the scenario's fix_interval_s",
    ),
    (
        "nav.fix_sigma_m[]",
        0.0,
        10_000.0,
        "as the scenario's fix_sigma_m",
    ),
    ("faults.flow_sensor_probability", 0.0, 1.0, "a probability"),
    (
        "faults.duration_s[]",
        0.0,
        1e6,
        "a window within the mission",
    ),
    (
        "team.outlet_from_end_m[]",
        0.0,
        1e5,
        "inside the basin, from its up-flow end",
    ),
    (
        "team.outlet_cross_m[]",
        -1e5,
        1e5,
        "across the basin from its centre line",
    ),
    (
        "team.second_along_m[]",
        0.0,
        1e5,
        "the second outlet down-flow of the first",
    ),
    (
        "team.second_cross_m[]",
        -1e5,
        1e5,
        "the second outlet across from the first",
    ),
    (
        "team.second_fraction[]",
        0.0,
        100.0,
        "the second outlet's rate as a fraction of the first's",
    ),
    (
        "team.medium_ppt[]",
        0.1,
        1000.0,
        "the medium's salinity (the contrast the team senses), ppt",
    ),
    (
        "team.d_m[]",
        1.0,
        1000.0,
        "the formation's scale: a team of metres to a kilometre",
    ),
    (
        "team.reach_freshness_ppt",
        1e-9,
        1e3,
        "a freshness the plume's centre line reaches, ppt",
    ),
    (
        "team.start_along_fraction[]",
        0.0,
        1.0,
        "a fraction of the plume's reach",
    ),
    (
        "team.start_along_min_m",
        0.0,
        1e5,
        "a distance down-flow of the outlet",
    ),
    (
        "team.start_cross_sigmas",
        0.0,
        10.0,
        "plume widths off the centre line",
    ),
    (
        "team.consumer_sigma_m[]",
        0.0,
        100.0,
        "a GPS's error, from RTK to a poor receiver",
    ),
    ("team.acoustic_loss[]", 0.0, 1.0, "a probability"),
    (
        "team.ranging_noise_sd_s[]",
        0.0,
        1.0,
        "a second of timing error is no ranging",
    ),
    ("team.deaf_probability", 0.0, 1.0, "a probability"),
    ("team.deaf_s[]", 0.0, 1e6, "a window within the mission"),
    ("team.deaf_start_s[]", 0.0, 1e6, "a time within the mission"),
    (
        "regions.along",
        1.0,
        6.0,
        "cells along the op-area's axis (a whole number; along x across at least 2)",
    ),
    (
        "regions.across",
        1.0,
        6.0,
        "cells across the op-area's axis (a whole number)",
    ),
    (
        "regions.sources[]",
        1.0,
        36.0,
        "sources per site, whole numbers, at most one per cell",
    ),
    (
        "regions.inset_m",
        0.0,
        50_000.0,
        "inside a cell, leaving it room: 2 x inset + 10 m within the smallest cell",
    ),
];

/// The bound of a family key (`[]` for a range's ends) from [`FAMILY_LIMITS`]: low, high and why.
pub(crate) fn family_bound(key: &str) -> (f64, f64, &'static str) {
    FAMILY_LIMITS
        .iter()
        .find(|l| l.0 == key)
        .map_or((f64::MIN, f64::MAX, ""), |l| (l.1, l.2, l.3))
}

pub(crate) fn invalid(file: &Path, key: &str, message: String) -> ScenarioError {
    ScenarioError::Parse {
        origin: file.display().to_string(),
        line: None,
        path: key.to_string(),
        message,
    }
}

impl Family {
    /// Reads a family file and its base scenario.
    pub fn load(path: &Path) -> Result<Self, ScenarioError> {
        let text = plumetrace_env::input::read_text(path, plumetrace_env::input::MAX_TEXT_BYTES)
            .map_err(|e| invalid(path, "", e.to_string()))?;
        Family::parse(&text, path)
    }

    /// Parses family text read from `path` (the base's relative path is taken from there).
    pub fn parse(text: &str, path: &Path) -> Result<Self, ScenarioError> {
        if let Ok(table) = text.parse::<toml::Table>()
            && let Some((key, value)) = crate::first_datetime(&toml::Value::Table(table), "")
        {
            return Err(invalid(
                path,
                &key,
                format!("is a date/time ({value}); no family key takes one"),
            ));
        }
        let de = toml::Deserializer::parse(text).map_err(|e| invalid(path, "", e.to_string()))?;
        let file: FamilyFile = serde_path_to_error::deserialize(de).map_err(|e| {
            let key = e.path().to_string();
            let inner = e.into_inner();
            // With a key path the message alone, at the key's line; without one, the parser's
            // whole report, which shows where.
            if key == "." && inner.message().starts_with("missing field") {
                // A key missing at the top needs no excerpt of the file.
                invalid(path, "", crate::locate::suggest(inner.message()))
            } else if key == "." {
                invalid(path, "", plumetrace_core::toml_message(&inner, false))
            } else {
                invalid(path, &key, crate::locate::suggest(inner.message())).located(text)
            }
        })?;
        check(&file, path).map_err(|e| e.located(text))?;
        let (base_origin, base_text) = if file.base.ends_with(".toml") {
            let p = path
                .parent()
                .map(Path::to_path_buf)
                .unwrap_or_default()
                .join(&file.base);
            let t = plumetrace_env::input::read_text(&p, plumetrace_env::input::MAX_TEXT_BYTES)
                .map_err(|m| invalid(path, "base", format!("{}: {m}", p.display())))?;
            (Origin::File(p), t)
        } else if let Some(p) = find_preset(&file.base) {
            (Origin::Preset(file.base.clone()), p.toml.to_string())
        } else {
            return Err(invalid(
                path,
                "base",
                format!(
                    "'{}' is neither a preset nor a path ending in .toml",
                    file.base
                ),
            ));
        };
        let base: toml::Table = base_text
            .parse()
            .map_err(|e: toml::de::Error| invalid(path, "base", format!("{base_origin}: {e}")))?;
        if !base.contains_key("mission") || base.get("vehicles").is_none() {
            return Err(invalid(
                path,
                "base",
                format!("{base_origin} is not a mission: it needs [mission] and [[vehicles]]"),
            ));
        }
        crate::family_team::check(&file, &base, &base_origin, path)?;
        crate::family_regions::check_base(&file, &base, path).map_err(|e| e.located(text))?;
        let family = Family {
            file,
            path: path.to_path_buf(),
            text: text.to_string(),
            base_origin,
            base,
        };
        check_extremes(&family).map_err(|e| e.located(text))?;
        Ok(family)
    }

    /// The site of `seed`.
    pub fn draw(&self, seed: u64) -> Site {
        let mut site = draw(&self.file, seed);
        if let Some(t) = &self.file.team {
            site.team = crate::family_team::draw(t, &self.base, &self.base_origin, &site, seed);
        }
        site
    }

    /// Site `k` of a campaign with seed `seed`, as `plumetrace family` writes it: its file name
    /// (`site-K.toml`, K padded to `width` digits) and its text (named `NAME-site-K`, carrying
    /// its run seed).
    pub fn site_file(&self, seed: u64, k: u64, width: usize) -> (String, String) {
        let run_seed = plumetrace_env::derive_seed(seed, k);
        let name = format!("{}-site-{k:0width$}", self.file.name);
        let text = self
            .draw(run_seed)
            .to_toml(&self.file, &self.base, run_seed, &name);
        (format!("site-{k:0width$}.toml"), text)
    }

    /// The scenario table of the site of `seed`.
    pub fn scenario(&self, seed: u64) -> toml::Table {
        self.draw(seed).apply(&self.file, &self.base)
    }
}

/// Checks every bound and rule of a family file; errors name the key.
fn check(f: &FamilyFile, path: &Path) -> Result<(), ScenarioError> {
    let bound = family_bound;
    let num = |key: &str, v: f64| -> Result<(), ScenarioError> {
        let (lo, hi, why) = bound(key);
        if v.is_finite() && v >= lo && v <= hi {
            Ok(())
        } else {
            Err(invalid(
                path,
                key.trim_end_matches("[]"),
                format!("must be a finite number >= {lo} and <= {hi} ({why}), got {v}"),
            ))
        }
    };
    let range = |key: &str, r: Option<Range>| -> Result<(), ScenarioError> {
        let Some([a, b]) = r else { return Ok(()) };
        let k = format!("{key}[]");
        num(&k, a)?;
        num(&k, b)?;
        if a > b {
            return Err(invalid(
                path,
                key,
                format!("[low, high] needs low <= high, got [{a}, {b}]"),
            ));
        }
        Ok(())
    };
    // The name becomes every site's name and the campaign's scenario label (and file names
    // made of it), so it keeps to the safe set of names that become file names.
    plumetrace_core::file_name::check_name(&f.name)
        .map_err(|e| invalid(path, "name", format!("{:?} {e}", f.name)))?;
    if let Some(t) = f.time_limit_s {
        num("time_limit_s", t)?;
    }
    num("domain_margin_m", f.domain_margin_m)?;
    if let Some(l) = f.vertical_mixing_length_m {
        num("vertical_mixing_length_m", l)?;
    }
    range("prior_flow_error_deg", f.prior_flow_error_deg)?;
    range("flow.toward_deg", Some(f.flow.toward_deg))?;
    range("flow.speed_mps", Some(f.flow.speed_mps))?;
    range("flow.tidal_swing_deg", f.flow.tidal_swing_deg)?;
    num("flow.tidal_period_s", f.flow.tidal_period_s)?;
    range("flow.meander_gain", f.flow.meander_gain)?;
    range("area.length_m", Some(f.area.length_m))?;
    range("area.width_m", Some(f.area.width_m))?;
    range("area.axis_to_flow_deg", f.area.axis_to_flow_deg)?;
    if f.area.shapes.is_empty() {
        return Err(invalid(
            path,
            "area.shapes",
            "name at least one shape".into(),
        ));
    }
    if f.area.shapes.len() > 100 {
        return Err(invalid(path, "area.shapes", "at most 100 entries".into()));
    }
    num("source.inset_m", f.source.inset_m)?;
    range("source.mass_rate_per_s", f.source.mass_rate_per_s)?;
    // With [regions] each source keeps regions.inset_m inside its cell instead.
    if f.regions.is_none()
        && 2.0 * f.source.inset_m + 10.0 > f.area.width_m[0].min(f.area.length_m[0])
    {
        return Err(invalid(
            path,
            "source.inset_m",
            format!(
                "{} m from every edge leaves no room in the smallest op-area ({} m x {} m): \
                 lower it or enlarge area.length_m / area.width_m",
                f.source.inset_m, f.area.length_m[0], f.area.width_m[0]
            ),
        ));
    }
    if f.start.kinds.is_empty() || f.start.kinds.len() > 100 {
        return Err(invalid(
            path,
            "start.kinds",
            "name 1 to 100 start kinds".into(),
        ));
    }
    if let Some(n) = &f.nav {
        range("nav.fix_interval_s", Some(n.fix_interval_s))?;
        range("nav.fix_sigma_m", Some(n.fix_sigma_m))?;
    }
    if let Some(x) = &f.faults {
        num("faults.flow_sensor_probability", x.flow_sensor_probability)?;
        range("faults.duration_s", Some(x.duration_s))?;
    }
    if f.regions.is_some() && f.team.is_some() {
        return Err(invalid(
            path,
            "regions",
            "[regions] places sources for one vehicle's search; a formation team's outlets \
             come from [team]: give one or the other"
                .into(),
        ));
    }
    crate::family_regions::check(f, path)
}

/// Builds sites at the ends of the ranges that decide whether a site can be built at all (the
/// current's speed, the op-area's extents and the tide's swing set the domain, the spin-up and
/// so the flow's steps), a few draws each, so that a family whose sites would be refused at run
/// time (a long time limit over tiny op-areas exceeding the step budget of the base's flow grid,
/// say) is refused here, at the family file.
fn check_extremes(family: &Family) -> Result<(), ScenarioError> {
    let f = &family.file;
    let ends = |r: Range, high: bool| if high { [r[1], r[1]] } else { [r[0], r[0]] };
    for corner in 0..16_u32 {
        let mut g = f.clone();
        g.flow.speed_mps = ends(f.flow.speed_mps, corner & 1 != 0);
        g.area.length_m = ends(f.area.length_m, corner & 2 != 0);
        g.area.width_m = ends(f.area.width_m, corner & 4 != 0);
        g.flow.tidal_swing_deg = f.flow.tidal_swing_deg.map(|r| ends(r, true));
        // Axis-aligned op-areas make the narrowest domains (the finest flow grid), and a
        // convex op-area's domain can be half a rectangle's across, which takes up to four
        // times the flow's sub-steps: the probe flies four times the time limit.
        g.flow.toward_deg = [0.0, 0.0];
        g.area.axis_to_flow_deg = Some(if corner & 8 != 0 {
            [90.0, 90.0]
        } else {
            [0.0, 0.0]
        });
        let limit = f.time_limit_s.or_else(|| {
            family
                .base
                .get("mission")
                .and_then(|m| m.get("time_limit_s"))
                .and_then(toml::Value::as_float)
        });
        g.time_limit_s = Some(4.0 * limit.unwrap_or(7200.0));
        for seed in 0..3 {
            let mut site = draw(&g, seed);
            if let Some(t) = &g.team {
                site.team =
                    crate::family_team::draw(t, &family.base, &family.base_origin, &site, seed);
            }
            let text = site.to_toml(&g, &family.base, seed, &g.name);
            let origin = Origin::File(family.path.clone());
            if let Err(e) = builds(&text, &origin) {
                let e = e.to_string();
                let what = e.strip_prefix(&format!("{origin}: ")).unwrap_or(&e);
                return Err(invalid(
                    &family.path,
                    "area",
                    format!(
                        "a site at the ends of the ranges (flow.speed_mps {}, area.length_m {}, \
                         area.width_m {}) cannot be built: {what}; narrow the ranges or change \
                         time_limit_s or the base",
                        g.flow.speed_mps[0], g.area.length_m[0], g.area.width_m[0]
                    ),
                ));
            }
        }
    }
    Ok(())
}

pub(crate) fn uniform(rng: &mut impl Rng, r: Range) -> f64 {
    if r[1] > r[0] {
        rng.random_range(r[0]..=r[1])
    } else {
        r[0]
    }
}

/// A unit vector along compass `deg`.
pub(crate) fn unit(deg: f64) -> Vec2 {
    let a = deg.to_radians();
    Vec2::new(a.sin(), a.cos())
}

/// Distance from `p` to the nearest edge of the polygon `v` (positive inside for a convex one).
pub(crate) fn edge_distance(v: &[[f64; 2]], p: Vec2) -> f64 {
    let mut best = f64::INFINITY;
    for k in 0..v.len() {
        let a = Vec2::new(v[k][0], v[k][1]);
        let b = Vec2::new(v[(k + 1) % v.len()][0], v[(k + 1) % v.len()][1]);
        let ab = b - a;
        let t = ((p - a).dot(&ab) / ab.norm_squared().max(1e-12)).clamp(0.0, 1.0);
        best = best.min((a + ab * t - p).norm());
    }
    best
}

/// Whether `p` is inside the convex polygon `v` (either winding).
fn inside_convex(v: &[[f64; 2]], p: Vec2) -> bool {
    let mut sign = 0.0_f64;
    for k in 0..v.len() {
        let a = Vec2::new(v[k][0], v[k][1]);
        let b = Vec2::new(v[(k + 1) % v.len()][0], v[(k + 1) % v.len()][1]);
        let c = (b - a).x * (p - a).y - (b - a).y * (p - a).x;
        if c.abs() < 1e-12 {
            continue;
        }
        if sign == 0.0 {
            sign = c.signum();
        } else if c.signum() != sign {
            return false;
        }
    }
    true
}

/// The source: uniform in the op-area, at least `inset` from every edge (the check made sure the
/// smallest area has room; the ellipse of a convex area is smaller, so the inset shrinks after
/// many tries rather than loop for ever).
fn place_source(rng: &mut impl Rng, op_area: &[[f64; 2]], half: f64, inset: f64) -> Vec2 {
    let mut inset = inset;
    for _ in 0..20 {
        for _ in 0..200 {
            let q = Vec2::new(
                rng.random_range(-half..=half),
                rng.random_range(-half..=half),
            );
            if inside_convex(op_area, q) && edge_distance(op_area, q) >= inset {
                return q;
            }
        }
        inset *= 0.8;
    }
    Vec2::zeros()
}

/// The vehicle's start of kind `start` in the op-area, `toward` the flow's direction.
fn start_position(
    rng: &mut impl Rng,
    start: StartKind,
    op_area: &[[f64; 2]],
    toward: f64,
    half: f64,
) -> Vec2 {
    let centroid = op_area
        .iter()
        .fold(Vec2::zeros(), |s, v| s + Vec2::new(v[0], v[1]))
        / op_area.len() as f64;
    let towards_centre = |p: Vec2, d: f64| {
        let c = centroid - p;
        let n = c.norm();
        if n > d { p + c / n * d } else { centroid }
    };
    match start {
        StartKind::DownflowCorner => {
            let down = unit(toward);
            let corner = op_area
                .iter()
                .map(|v| Vec2::new(v[0], v[1]))
                .max_by(|a, b| a.dot(&down).total_cmp(&b.dot(&down)))
                .unwrap_or(centroid);
            towards_centre(corner, 20.0)
        }
        StartKind::Edge => {
            let k = rng.random_range(0..op_area.len());
            let a = Vec2::new(op_area[k][0], op_area[k][1]);
            let b = Vec2::new(
                op_area[(k + 1) % op_area.len()][0],
                op_area[(k + 1) % op_area.len()][1],
            );
            towards_centre(a + (b - a) * rng.random_range(0.0..1.0), 10.0)
        }
        StartKind::Inside => {
            let mut p = centroid;
            for _ in 0..1000 {
                let q = Vec2::new(
                    rng.random_range(-half..=half),
                    rng.random_range(-half..=half),
                );
                if inside_convex(op_area, q) && edge_distance(op_area, q) >= 30.0 {
                    p = q;
                    break;
                }
            }
            p
        }
    }
}

/// Draws a site.
fn draw(f: &FamilyFile, seed: u64) -> Site {
    let mut rng = stream_rng(seed, StreamId::Custom(SITE_STREAM));
    let toward = uniform(&mut rng, f.flow.toward_deg).rem_euclid(360.0);
    let speed = uniform(&mut rng, f.flow.speed_mps);
    let swing = f.flow.tidal_swing_deg.map_or(0.0, |r| uniform(&mut rng, r));
    let phase = rng.random_range(0.0..360.0);
    let meander = f.flow.meander_gain.map(|r| uniform(&mut rng, r));
    let shape = f.area.shapes[rng.random_range(0..f.area.shapes.len())];
    let length = uniform(&mut rng, f.area.length_m);
    let width = uniform(&mut rng, f.area.width_m);
    let rel = f
        .area
        .axis_to_flow_deg
        .map_or(0.0, |r| uniform(&mut rng, r));
    let axis = (toward + rel).rem_euclid(360.0);
    let (u, w) = (unit(axis), unit(axis + 90.0));
    let at = |a: f64, b: f64| {
        let p = u * a + w * b;
        [p.x, p.y]
    };
    let op_area: Vec<[f64; 2]> = match shape {
        Shape::Rectangle => {
            let (l, h) = (length / 2.0, width / 2.0);
            vec![at(-l, -h), at(l, -h), at(l, h), at(-l, h)]
        }
        Shape::Convex => {
            let n = rng.random_range(5..=8);
            let mut angles: Vec<f64> = (0..n)
                .map(|k| {
                    let step = std::f64::consts::TAU / n as f64;
                    step * (k as f64 + rng.random_range(-0.35..0.35))
                })
                .collect();
            angles.sort_by(f64::total_cmp);
            angles
                .into_iter()
                .map(|t| at(length / 2.0 * t.cos(), width / 2.0 * t.sin()))
                .collect()
        }
    };
    let half = length.max(width) / 2.0;
    let source = place_source(&mut rng, &op_area, half, f.source.inset_m);
    let source_edge_m = edge_distance(&op_area, source);
    let mass = f.source.mass_rate_per_s.map(|[a, b]| {
        if b > a {
            (rng.random_range(a.ln()..=b.ln())).exp()
        } else {
            a
        }
    });
    let start = f.start.kinds[rng.random_range(0..f.start.kinds.len())];
    let start_pos = start_position(&mut rng, start, &op_area, toward, half);
    let start_heading = rng.random_range(0.0..360.0);
    let prior_error = f.prior_flow_error_deg.map_or(0.0, |r| uniform(&mut rng, r));
    let (fix_interval, fix_sigma) = match &f.nav {
        Some(n) => (
            Some(uniform(&mut rng, n.fix_interval_s)),
            Some(uniform(&mut rng, n.fix_sigma_m)),
        ),
        None => (None, None),
    };
    let limit = f.time_limit_s.unwrap_or(7200.0);
    let fault = f.faults.as_ref().and_then(|x| {
        let on = rng.random::<f64>() < x.flow_sensor_probability;
        let d = uniform(&mut rng, x.duration_s);
        let t0 = rng.random_range(0.0..(limit / 2.0).max(1.0));
        on.then_some([t0, t0 + d])
    });
    // Long enough for the plume to reach the op-area's far down-flow side (with a tide the
    // direction swings, so the whole extent counts), at least ten minutes.
    let down = unit(toward);
    let reach = op_area
        .iter()
        .map(|v| (Vec2::new(v[0], v[1]) - source).dot(&down))
        .fold(0.0_f64, f64::max)
        .max(length.max(width) * if swing > 0.0 { 1.0 } else { 0.0 });
    let spinup_s = (1.2 * (reach + 50.0) / speed).clamp(600.0, 100_000.0);
    let flow_to_axis_deg = {
        let d = (toward - axis).rem_euclid(180.0);
        if d > 90.0 { 180.0 - d } else { d }
    };
    let mut site = Site {
        flow_toward_deg: toward,
        flow_speed_mps: speed,
        tidal_swing_deg: swing,
        tidal_phase_deg: phase,
        meander_gain: meander,
        shape,
        axis_deg: axis,
        flow_to_axis_deg,
        length_m: length,
        width_m: width,
        op_area,
        source: [source.x, source.y],
        source_edge_m,
        mass_rate_per_s: mass,
        start,
        start_pos: [start_pos.x, start_pos.y],
        start_heading_deg: start_heading,
        prior_flow_deg: (toward + prior_error).rem_euclid(360.0),
        fix_interval_s: fix_interval,
        fix_sigma_m: fix_sigma,
        flow_fault_s: fault,
        spinup_s,
        team: None,
        regions: None,
    };
    if let Some(r) = &f.regions {
        crate::family_regions::draw(r, f, &mut site, seed);
    }
    site
}

/// `t[key]` as a table, made (or replacing a value of another type) if needed.
pub(crate) fn table_at<'a>(t: &'a mut toml::Table, key: &str) -> Option<&'a mut toml::Table> {
    if !t.get(key).is_some_and(toml::Value::is_table) {
        t.insert(key.to_string(), toml::Value::Table(toml::Table::new()));
    }
    t.get_mut(key).and_then(toml::Value::as_table_mut)
}

/// The first entry of the array `t[key]` as a table, if there is one.
fn first_of<'a>(t: &'a mut toml::Table, key: &str) -> Option<&'a mut toml::Table> {
    match t.get_mut(key) {
        Some(toml::Value::Array(a)) => {
            a.truncate(1);
            a.first_mut().and_then(toml::Value::as_table_mut)
        }
        _ => None,
    }
}

pub(crate) fn float(v: f64) -> toml::Value {
    toml::Value::Float(v)
}

pub(crate) fn round(v: f64, digits: i32) -> f64 {
    let k = 10f64.powi(digits);
    (v * k).round() / k
}

impl Site {
    /// The names of [`Site::values`], as `runs.csv` columns.
    pub const COLUMNS: [&'static str; 14] = [
        "site_flow_toward_deg",
        "site_flow_speed_mps",
        "site_tidal_swing_deg",
        "site_shape",
        "site_flow_to_axis_deg",
        "site_length_m",
        "site_width_m",
        "site_source_edge_m",
        "site_mass_rate_per_s",
        "site_start",
        "site_fix_interval_s",
        "site_fix_sigma_m",
        "site_flow_fault",
        "site_spinup_s",
    ];

    /// The site's values for the columns, as text.
    pub fn values(&self) -> Vec<String> {
        let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.3}"));
        vec![
            format!("{:.2}", self.flow_toward_deg),
            format!("{:.4}", self.flow_speed_mps),
            format!("{:.2}", self.tidal_swing_deg),
            plumetrace_core::variant_name(&self.shape)
                .unwrap_or("?")
                .into(),
            format!("{:.2}", self.flow_to_axis_deg),
            format!("{:.1}", self.length_m),
            format!("{:.1}", self.width_m),
            format!("{:.1}", self.source_edge_m),
            opt(self.mass_rate_per_s),
            plumetrace_core::variant_name(&self.start)
                .unwrap_or("?")
                .into(),
            opt(self.fix_interval_s),
            opt(self.fix_sigma_m),
            self.flow_fault_s.is_some().to_string(),
            format!("{:.0}", self.spinup_s),
        ]
    }

    /// The base scenario's table with this site written into it.
    pub fn apply(&self, f: &FamilyFile, base: &toml::Table) -> toml::Table {
        let mut t = base.clone();
        let name = t
            .get("name")
            .and_then(toml::Value::as_str)
            .unwrap_or("base")
            .to_string();
        t.insert("name".into(), toml::Value::String(f.name.clone()));
        t.insert(
            "description".into(),
            toml::Value::String(format!("a site of family '{}' on '{name}'", f.name)),
        );
        // Domain: the op-area, source and start with a margin.
        let pts = self
            .op_area
            .iter()
            .chain([&self.source, &self.start_pos])
            .copied();
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for p in pts {
            x0 = x0.min(p[0]);
            x1 = x1.max(p[0]);
            y0 = y0.min(p[1]);
            y1 = y1.max(p[1]);
        }
        let m = f.domain_margin_m;
        if let Some(domain) = table_at(&mut t, "domain") {
            for (k, v) in [
                ("x_min_m", x0 - m),
                ("x_max_m", x1 + m),
                ("y_min_m", y0 - m),
                ("y_max_m", y1 + m),
            ] {
                domain.insert(k.into(), float(round(v, 1)));
            }
        }
        // Mean flow.
        let mut mean = toml::Table::new();
        if self.tidal_swing_deg > 0.0 {
            let h = self.tidal_swing_deg / 2.0;
            for (k, v) in [
                ("speed_min_mps", self.flow_speed_mps),
                ("speed_max_mps", self.flow_speed_mps),
                ("toward_min_deg", self.flow_toward_deg - h),
                ("toward_max_deg", self.flow_toward_deg + h),
                ("period_s", f.flow.tidal_period_s),
                ("phase_deg", self.tidal_phase_deg),
            ] {
                mean.insert(k.into(), float(round(v, 4)));
            }
        } else {
            mean.insert("speed_mps".into(), float(round(self.flow_speed_mps, 4)));
            mean.insert("toward_deg".into(), float(round(self.flow_toward_deg, 3)));
        }
        if let Some(flow) = table_at(&mut t, "flow") {
            flow.insert("mean".into(), toml::Value::Table(mean));
            if let Some(g) = self.meander_gain
                && let Some(toml::Value::Table(farrell)) = flow.get_mut("farrell")
            {
                farrell.insert("noise_gain".into(), float(round(g, 4)));
            }
        }
        if let Some(l) = f.vertical_mixing_length_m
            && let Some(plume) = table_at(&mut t, "plume")
        {
            plume.insert(
                "vertical_diffusivity_m2ps".into(),
                float(round(l * self.flow_speed_mps, 6)),
            );
        }
        // Source.
        if let Some(s) = first_of(&mut t, "sources") {
            s.insert("x_m".into(), float(round(self.source[0], 2)));
            s.insert("y_m".into(), float(round(self.source[1], 2)));
            if let Some(q) = self.mass_rate_per_s {
                s.insert("mass_rate_per_s".into(), float(round(q, 4)));
            }
        }
        // Vehicle (a base of several keeps them all: the team moves as one, or as `[team]` draws).
        let several = t
            .get("vehicles")
            .and_then(toml::Value::as_array)
            .is_some_and(|a| a.len() > 1);
        if several && self.team.is_none() {
            crate::family_team::move_team(self, &mut t);
        }
        let first = if several {
            t.get_mut("vehicles")
                .and_then(toml::Value::as_array_mut)
                .and_then(|a| a.first_mut())
                .and_then(toml::Value::as_table_mut)
        } else {
            first_of(&mut t, "vehicles")
        };
        if self.team.is_none()
            && let Some(v) = first
        {
            v.insert("x_m".into(), float(round(self.start_pos[0], 2)));
            v.insert("y_m".into(), float(round(self.start_pos[1], 2)));
            v.insert(
                "heading_deg".into(),
                float(round(self.start_heading_deg, 2)),
            );
            if self.fix_interval_s.is_some()
                && let Some(nav) = table_at(v, "nav")
            {
                if let Some(x) = self.fix_interval_s {
                    nav.insert("fix_interval_s".into(), float(round(x, 2)));
                }
                if let Some(x) = self.fix_sigma_m {
                    nav.insert("fix_sigma_m".into(), float(round(x, 3)));
                }
            }
            if let Some([a, b]) = self.flow_fault_s
                && let Some(fs) = table_at(v, "flow_sensor")
            {
                fs.insert("fault_start_s".into(), float(round(a, 1)));
                fs.insert("fault_end_s".into(), float(round(b, 1)));
            }
        }
        // Mission.
        let limit = f.time_limit_s.or_else(|| {
            t.get("mission")
                .and_then(|m| m.get("time_limit_s"))
                .and_then(toml::Value::as_float)
        });
        if let Some(mission) = table_at(&mut t, "mission") {
            mission.insert(
                "op_area".into(),
                toml::Value::Array(
                    self.op_area
                        .iter()
                        .map(|p| {
                            toml::Value::Array(vec![float(round(p[0], 2)), float(round(p[1], 2))])
                        })
                        .collect(),
                ),
            );
            mission.remove("subregions");
            mission.insert(
                "prior_flow_toward_deg".into(),
                float(round(self.prior_flow_deg, 3)),
            );
            mission.insert("spinup_s".into(), float(self.spinup_s.round()));
            if let Some(l) = limit {
                mission.insert("time_limit_s".into(), float(l));
            }
        }
        if let Some(l) = limit
            && let Some(sim) = table_at(&mut t, "sim")
        {
            sim.insert("duration_s".into(), float(l));
        }
        if let Some(r) = &self.regions {
            crate::family_regions::apply(r, &mut t);
        }
        t.remove("output");
        if let Some(team) = &self.team {
            crate::family_team::apply(team, f, self, base, &mut t);
        }
        t
    }

    /// The site as a commented scenario file, named `NAME` (unique among the family's sites,
    /// e.g. `faults-site-003`) and carrying `seed`: flown as written it is the campaign's run of
    /// the site drawn from `seed`.
    pub fn to_toml(&self, f: &FamilyFile, base: &toml::Table, seed: u64, name: &str) -> String {
        let mut table = self.apply(f, base);
        table.insert("name".into(), toml::Value::String(name.to_string()));
        table.insert("seed".into(), crate::config::seed::value(seed));
        let mut out = format!(
            "# Site '{name}' of family '{}', drawn from seed {seed}, which is also its run seed:\n\
             # flown as written (plumetrace run FILE) it is the campaign's run of this site.\n\
             # Drawn:\n",
            f.name.replace('\n', " ")
        );
        for (k, v) in Site::COLUMNS.iter().zip(self.values()) {
            let k = k.trim_start_matches("site_");
            // An empty value is a key the family does not draw (its column is empty too).
            if v.is_empty() {
                out.push_str(&format!("#   {k}: not drawn (the base scenario's)\n"));
            } else {
                out.push_str(&format!("#   {k} = {v}\n"));
            }
        }
        for (k, v) in self
            .team
            .iter()
            .flat_map(crate::family_team::TeamSite::values)
            .chain(
                self.regions
                    .iter()
                    .flat_map(crate::family_regions::RegionsSite::values),
            )
        {
            out.push_str(&format!("#   {k} = {v}\n"));
        }
        out.push_str(&toml::to_string(&table).unwrap_or_default());
        out
    }
}

/// Reads and builds a site's scenario text, as `plumetrace run` would the file (`origin` names
/// it in errors).
pub fn builds(text: &str, origin: &Origin) -> Result<(), ScenarioError> {
    crate::parse(text, origin).and_then(|cfg| crate::build(&cfg, origin, None).map(|_| ()))
}

/// Whether a campaign's scenario entry names a family (a path ending in `.family.toml`).
pub fn is_family_path(s: &str) -> bool {
    s.ends_with(".family.toml")
}

#[cfg(test)]
mod tests {
    use super::*;

    const COASTAL: &str = include_str!("../../../examples/families/coastal.family.toml");

    fn coastal() -> Family {
        Family::parse(COASTAL, Path::new("examples/families/coastal.family.toml"))
            .unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn sites_are_drawn_from_their_seed_and_build() {
        let f = coastal();
        assert_eq!(f.draw(7), f.draw(7));
        assert_ne!(f.draw(7), f.draw(8));
        for seed in 0..40 {
            let site = f.draw(seed);
            let table = site.apply(&f.file, &f.base);
            let cfg = crate::from_table(table, &Origin::Preset("coastal".into()))
                .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
            let built = crate::build(&cfg, &Origin::Preset("coastal".into()), Some(seed))
                .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
            let m = built
                .mission
                .as_ref()
                .unwrap_or_else(|| panic!("seed {seed}"));
            assert!((m.time_limit_s - 7200.0).abs() < 1e-9);
            // The source at least 60 m inside (a convex area may take a little less room).
            assert!(
                site.source_edge_m >= 60.0 * 0.8 - 1e-9,
                "seed {seed}: {site:?}"
            );
            assert!(inside_convex(
                &site.op_area,
                Vec2::new(site.source[0], site.source[1])
            ));
            assert!((0.05..=0.45).contains(&site.flow_speed_mps));
            assert!((0.0..=90.0).contains(&site.flow_to_axis_deg));
            assert_eq!(site.values().len(), Site::COLUMNS.len());
        }
    }

    #[test]
    fn a_site_file_says_what_it_draws_and_what_it_leaves_to_the_base() {
        let f = coastal();
        let site = f.draw(3);
        assert!(
            site.mass_rate_per_s.is_none(),
            "coastal draws no release rate"
        );
        let text = site.to_toml(&f.file, &f.base, 3, "coastal-site-003");
        assert!(
            text.contains("\n#   mass_rate_per_s: not drawn (the base scenario's)\n"),
            "{text}"
        );
        assert!(text.contains("\n#   length_m = "), "{text}");
        assert!(
            text.lines()
                .filter(|l| l.starts_with("#   "))
                .all(|l| !l.trim_end().ends_with('=')),
            "a drawn line without its value: {text}"
        );
    }

    #[test]
    fn bad_family_keys_are_located() {
        let p = Path::new("f.family.toml");
        let cases = [
            (
                COASTAL.replace("speed_mps = [0.05, 0.45]", "speed_mps = [0.5, 0.1]"),
                "flow.speed_mps",
                "low <= high",
            ),
            (
                COASTAL.replace("speed_mps = [0.05, 0.45]", "speed_mps = [0.05, 1e9]"),
                "flow.speed_mps",
                "<= 5",
            ),
            (
                COASTAL.replace("inset_m = 60.0", "inset_m = 200.0"),
                "source.inset_m",
                "no room",
            ),
            (
                COASTAL.replace("base = \"duck-2003-st\"", "base = \"nowhere\""),
                "base",
                "neither a preset",
            ),
            (
                COASTAL.replace("base = \"duck-2003-st\"", "base = \"plume-demo\""),
                "base",
                "not a mission",
            ),
            (
                COASTAL.replace("[start]", "[start]\ncolour = 1"),
                "start",
                "unknown field",
            ),
            (
                COASTAL.replace("shapes = [\"rectangle\", \"convex\"]", "shapes = []"),
                "area.shapes",
                "at least one",
            ),
            // each of these passed, and every site then failed, blaming the base
            (
                COASTAL.replace("domain_margin_m = 150.0", "domain_margin_m = 0.0"),
                "domain_margin_m",
                ">= 1",
            ),
            (
                COASTAL.replace(
                    "vertical_mixing_length_m = 0.038",
                    "vertical_mixing_length_m = -0.038",
                ),
                "vertical_mixing_length_m",
                ">= 0",
            ),
            (
                COASTAL.replace("name = \"coastal\"", "name = \"coast\\u0007al\""),
                "name",
                "holds '\\u{7}'",
            ),
            (
                COASTAL.replace("[area]", "meander_gain = [0.1, 100.0]\n\n[area]"),
                "flow.meander_gain",
                "<= 1",
            ),
            (
                COASTAL.replace("name = \"coastal\"", "name = \"../coastal\""),
                "name",
                "starts with '.'",
            ),
        ];
        for (text, key, what) in cases {
            let e = Family::parse(&text, p).map(|_| ()).unwrap_err().to_string();
            assert!(e.contains(key) && e.contains(what), "{key}: {e}");
            assert!(e.contains("f.family.toml"), "{e}");
        }
        // with the line of the key
        let text = COASTAL.replace("domain_margin_m = 150.0", "domain_margin_m = 0.0");
        let line = text
            .lines()
            .position(|l| l.starts_with("domain_margin_m"))
            .unwrap_or(0)
            + 1;
        let e = Family::parse(&text, p).map(|_| ()).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("f.family.toml:{line}: domain_margin_m:")),
            "{e}"
        );
    }
}
