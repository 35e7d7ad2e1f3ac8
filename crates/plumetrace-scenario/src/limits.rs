//! The bounds of every number and list in a scenario file, with the reason for each: one table
//! ([`LIMITS`]) that the check uses and the README prints (`plumetrace limits --markdown`).
//!
//! A scenario is checked against the table before any model is made: every number in the file is
//! matched to its key (array indices written `[]`), so a value out of range is refused with its key
//! path and the bound, and a number whose key has no entry is refused too (a key added to the file
//! format without a bound fails the tests). Planner keys are the planner registry's to check.
//! Bounds that involve several keys (steps per run, positions inside the domain, stable steps, a
//! filament plume's steps long enough for its single-precision positions)
//! are checked when the models are built.
//!
//! Each key's bound lives here alone: the build checks no number against a bound of its own.
//! A model checks what it needs to be valid (finite, positive, in order); where a model has a
//! capacity of its own (grid nodes of the Farrell flow, sources of a filament plume, vertices
//! and roughness of a kelp outline, rays of a range sensor), it is a constant of the model and
//! the row here takes its numbers from it.

use plumetrace_env::flow::FarrellParams;
use plumetrace_env::{FilamentPlume, KelpFieldParams};
use plumetrace_sim::RangeSensorParams;
use std::fmt::Write as _;

/// What a limit bounds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bound {
    /// A number in `[min, max]`; `min_open` excludes `min`.
    Number {
        /// Lower end.
        min: f64,
        /// `min` itself is not allowed.
        min_open: bool,
        /// Upper end (included).
        max: f64,
    },
    /// A list of at most this many entries.
    Count(usize),
    /// Any value of its type.
    Any,
}

/// One row of the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limit {
    /// Key path with `[]` for array indices, e.g. `vehicles[].nav.fix_interval_s`.
    pub key: &'static str,
    /// The bound.
    pub bound: Bound,
    /// Why.
    pub why: &'static str,
}

const fn num(key: &'static str, min: f64, max: f64, why: &'static str) -> Limit {
    Limit {
        key,
        bound: Bound::Number {
            min,
            min_open: false,
            max,
        },
        why,
    }
}

const fn pos(key: &'static str, max: f64, why: &'static str) -> Limit {
    Limit {
        key,
        bound: Bound::Number {
            min: 0.0,
            min_open: true,
            max,
        },
        why,
    }
}

const fn count(key: &'static str, n: usize, why: &'static str) -> Limit {
    Limit {
        key,
        bound: Bound::Count(n),
        why,
    }
}

/// Coordinates of a local tangent plane: 10,000 km is no longer local.
const COORD: f64 = 1e7;
/// The deepest ocean, m.
const DEPTH: f64 = 11_000.0;
/// A year and a third, s: longer runs are not missions.
const LONG: f64 = 1e7;
/// Angles may be written with any number of turns, within reason.
const TURNS: f64 = 3600.0;

const COORD_WHY: &str = "a local frame: 10,000 km is not local";
const ANGLE_WHY: &str = "compass degrees, any number of turns up to ten";
const TIME_WHY: &str = "115 days: longer is not a mission or a plume run";
const DEPTH_WHY: &str = "the deepest ocean";
const LAT_WHY: &str = "a latitude, north positive (turned into metres around [origin])";
const LON_WHY: &str = "a longitude, east positive (turned into metres around [origin])";

/// Every bound of the scenario file format.
pub const LIMITS: &[Limit] = &[
    Limit {
        key: "seed",
        bound: Bound::Any,
        why: "any whole number 0..2^64 (beyond 2^63 - 1, where TOML integers stop, a string of digits)",
    },
    pos(
        "sim.dt_s",
        60.0,
        "a step of more than a minute skips the vehicles' dynamics",
    ),
    pos("sim.duration_s", LONG, TIME_WHY),
    num("domain.x_min_m", -COORD, COORD, COORD_WHY),
    num("domain.x_max_m", -COORD, COORD, COORD_WHY),
    num("domain.y_min_m", -COORD, COORD, COORD_WHY),
    num("domain.y_max_m", -COORD, COORD, COORD_WHY),
    pos("domain.depth_m", DEPTH, DEPTH_WHY),
    num(
        "flow.mean.speed_mps",
        0.0,
        10.0,
        "ocean currents stay below 10 m/s",
    ),
    num("flow.mean.toward_deg", -TURNS, TURNS, ANGLE_WHY),
    num(
        "flow.mean.speed_min_mps",
        0.0,
        10.0,
        "ocean currents stay below 10 m/s",
    ),
    num(
        "flow.mean.speed_max_mps",
        0.0,
        10.0,
        "ocean currents stay below 10 m/s",
    ),
    num("flow.mean.toward_min_deg", -TURNS, TURNS, ANGLE_WHY),
    num("flow.mean.toward_max_deg", -TURNS, TURNS, ANGLE_WHY),
    pos("flow.mean.period_s", LONG, TIME_WHY),
    num(
        "flow.meander",
        0.0,
        5.0,
        "a multiple of the Farrell field's own meander; 0 is none, beyond 5 the noise is the flow",
    ),
    num(
        "flow.netcdf.depth_m",
        0.0,
        DEPTH,
        "below the surface, at most the deepest ocean",
    ),
    num(
        "flow.netcdf.spacing_m",
        0.01,
        COORD,
        "a centimetre to the widest domain (the grid is capped at 2000 nodes a side anyway)",
    ),
    num(
        "bathymetry.spacing_m",
        0.01,
        COORD,
        "a centimetre to the widest domain (the grid is capped at 2000 nodes a side anyway)",
    ),
    num(
        "origin.lat_deg",
        -89.0,
        89.0,
        "the poles have no east: the local frame needs a latitude in [-89, 89]",
    ),
    num(
        "origin.lon_deg",
        -180.0,
        180.0,
        "a longitude, east positive",
    ),
    num("sources[].lat_deg", -90.0, 90.0, LAT_WHY),
    num("sources[].lon_deg", -180.0, 180.0, LON_WHY),
    num("vehicles[].lat_deg", -90.0, 90.0, LAT_WHY),
    num("vehicles[].lon_deg", -180.0, 180.0, LON_WHY),
    num("mission.op_area_lat_lon[][0]", -90.0, 90.0, LAT_WHY),
    num("mission.op_area_lat_lon[][1]", -180.0, 180.0, LON_WHY),
    num("mission.subregions_lat_lon[][][0]", -90.0, 90.0, LAT_WHY),
    num("mission.subregions_lat_lon[][][1]", -180.0, 180.0, LON_WHY),
    num("flow.mean.phase_deg", -TURNS, TURNS, ANGLE_WHY),
    num(
        "flow.farrell.nx",
        FarrellParams::MIN_NODES as f64,
        FarrellParams::MAX_NODES as f64,
        "a million grid nodes at most (memory and step time)",
    ),
    num(
        "flow.farrell.ny",
        FarrellParams::MIN_NODES as f64,
        FarrellParams::MAX_NODES as f64,
        "a million grid nodes at most (memory and step time)",
    ),
    pos(
        "flow.farrell.diffusivity_x_m2ps",
        1e4,
        "eddy diffusivities of the ocean are far below",
    ),
    pos(
        "flow.farrell.diffusivity_y_m2ps",
        1e4,
        "eddy diffusivities of the ocean are far below",
    ),
    num(
        "flow.farrell.noise_gain",
        0.0,
        100.0,
        "meander velocities stay far below 100 m/s",
    ),
    pos(
        "flow.farrell.noise_damping",
        100.0,
        "a damping ratio; above 100 the noise vanishes",
    ),
    pos(
        "flow.farrell.noise_bandwidth_radps",
        100.0,
        "a meander faster than 100 rad/s is not a meander",
    ),
    num(
        "flow.farrell.step_s",
        0.0,
        3600.0,
        "capped at half the grid's stable limit anyway; an hour is far past any meander's time scale",
    ),
    num(
        "plume.horizontal_diffusivity_m2ps",
        0.0,
        1e3,
        "eddy diffusivities of the ocean are far below",
    ),
    num(
        "plume.vertical_diffusivity_m2ps",
        0.0,
        1e3,
        "eddy diffusivities of the ocean are far below",
    ),
    num(
        "plume.init_radius_m",
        1e-3,
        1e3,
        "a filament's peak goes as 1 / r^3: below a millimetre it overflows; a kilometre is no longer a filament",
    ),
    num(
        "plume.growth_rate_m2ps",
        0.0,
        1e3,
        "eddy diffusivities of the ocean are far below",
    ),
    num(
        "plume.cutoff_radii",
        1.0,
        10.0,
        "beyond 10 radii a Gaussian is below 1e-21 of its peak",
    ),
    num(
        "plume.max_filaments",
        1.0,
        1e7,
        "memory: 10 million filaments take about 0.5 GB",
    ),
    num(
        "plume.initial_filaments",
        0.0,
        1e6,
        "a million per source at the start at most",
    ),
    num(
        "plume.pompy_diff_scale_mps",
        0.0,
        100.0,
        "pompy's random-walk scale; its default is 2",
    ),
    count(
        "sources",
        FilamentPlume::MAX_SOURCES,
        "the step and the query time grow with the sources",
    ),
    num("sources[].x_m", -COORD, COORD, COORD_WHY),
    num("sources[].y_m", -COORD, COORD, COORD_WHY),
    num("sources[].z_m", 0.0, DEPTH, DEPTH_WHY),
    num(
        "sources[].mass_rate_per_s",
        0.0,
        1e9,
        "concentrations must stay finite after summing many filaments",
    ),
    num(
        "sources[].filament_rate_hz",
        1e-3,
        1e4,
        "each filament carries mass_rate / rate: one per 1,000 s at least, 10,000 per second at most",
    ),
    count(
        "obstacles",
        10_000,
        "the range sensors cast rays against every obstacle",
    ),
    count(
        "obstacles[].vertices",
        100_000,
        "the range sensors cast rays against every edge",
    ),
    num("obstacles[].vertices[][]", -COORD, COORD, COORD_WHY),
    count(
        "kelp",
        100,
        "each field is drawn with a bounded number of tries per patch",
    ),
    count(
        "kelp[].region",
        10_000,
        "each drawn centre is tested against every edge",
    ),
    num("kelp[].region[][]", -COORD, COORD, COORD_WHY),
    num(
        "kelp[].patches",
        0.0,
        1000.0,
        "the range sensors cast rays against every patch",
    ),
    num(
        "kelp[].radius_m[]",
        0.0,
        1e4,
        "kelp patches are metres to hundreds of metres across",
    ),
    num(
        "kelp[].gap_m",
        0.0,
        1e4,
        "kelp patches are metres to hundreds of metres apart",
    ),
    num(
        "kelp[].vertices",
        KelpFieldParams::MIN_VERTICES as f64,
        KelpFieldParams::MAX_VERTICES as f64,
        "an outline of 64 vertices is round enough",
    ),
    num(
        "kelp[].roughness",
        0.0,
        KelpFieldParams::MAX_ROUGHNESS,
        "vertex radii stay above 1 % of the radius",
    ),
    num(
        "kelp[].clear_m",
        0.0,
        1e4,
        "kelp patches are metres to hundreds of metres apart",
    ),
    Limit {
        key: "kelp[].seed",
        bound: Bound::Any,
        why: "any whole number 0..2^64, as the run seed (beyond 2^63 - 1 a string of digits)",
    },
    num(
        "output.nx",
        2.0,
        2000.0,
        "four million grid points at most (memory)",
    ),
    num(
        "output.ny",
        2.0,
        2000.0,
        "four million grid points at most (memory)",
    ),
    num("output.z_m", 0.0, DEPTH, DEPTH_WHY),
    pos("output.average_interval_s", LONG, TIME_WHY),
    num("output.average_start_s", 0.0, LONG, TIME_WHY),
    num(
        "output.threshold",
        0.0,
        1e12,
        "a concentration threshold; finite",
    ),
    count(
        "output.probes",
        1000,
        "every probe is queried at every probe sample",
    ),
    num("output.probes[][]", -COORD, COORD, COORD_WHY),
    pos(
        "output.probe_interval_s",
        LONG,
        "115 days; probes.csv holds at most 5,000,000 rows (samples x probes)",
    ),
    num(
        "output.filaments_interval_s",
        0.0,
        LONG,
        "0 writes no filament snapshots; at most 1,000 snapshots per run",
    ),
    count(
        "vehicles",
        100,
        "every vehicle is stepped and sensed at every step",
    ),
    num("vehicles[].x_m", -COORD, COORD, COORD_WHY),
    num("vehicles[].y_m", -COORD, COORD, COORD_WHY),
    num("vehicles[].heading_deg", -TURNS, TURNS, ANGLE_WHY),
    num("vehicles[].altitude_m", 0.0, DEPTH, DEPTH_WHY),
    pos(
        "vehicles[].dynamics.max_speed_mps",
        20.0,
        "marine robots stay below 20 m/s",
    ),
    pos(
        "vehicles[].dynamics.max_turn_rate_deg_s",
        360.0,
        "a turn a second at most",
    ),
    pos(
        "vehicles[].dynamics.speed_time_constant_s",
        1e4,
        "a response slower than hours is no response",
    ),
    pos(
        "vehicles[].dynamics.vertical_time_constant_s",
        1e4,
        "a response slower than hours is no response",
    ),
    num(
        "vehicles[].dynamics.altitude_error_sd_m",
        0.0,
        100.0,
        "an altitude error of 100 m is no altitude hold",
    ),
    pos(
        "vehicles[].dynamics.altitude_error_time_s",
        1e5,
        "a correlation time of a day at most",
    ),
    num(
        "vehicles[].dynamics.dvl_beam_angle_deg",
        0.0,
        60.0,
        "a beam further than 60 deg from the vertical grazes the seabed",
    ),
    num(
        "vehicles[].dynamics.look_ahead_m",
        0.0,
        100.0,
        "a forward altimeter reads tens of metres ahead",
    ),
    num(
        "vehicles[].dynamics.min_altitude_m",
        0.0,
        100.0,
        "a minimum altitude of 100 m is no altitude hold",
    ),
    num(
        "vehicles[].nav.fix_interval_s",
        0.01,
        LONG,
        "fixes at 100 Hz at most (the estimate is updated at each step)",
    ),
    num(
        "vehicles[].nav.fix_sigma_m",
        0.0,
        1e4,
        "a fix 10 km off is no fix",
    ),
    num(
        "vehicles[].nav.velocity_error_sd_mps",
        0.0,
        10.0,
        "a dead-reckoning error of 10 m/s is no navigation",
    ),
    pos("vehicles[].nav.velocity_error_tau_s", LONG, TIME_WHY),
    num(
        "vehicles[].nav.heading_sd_deg",
        0.0,
        180.0,
        "a compass error of half a turn is no compass",
    ),
    num(
        "vehicles[].nav.speed_sd_mps",
        0.0,
        10.0,
        "a speed-log error of 10 m/s is no speed log",
    ),
    num(
        "vehicles[].nav.altimeter_sd_m",
        0.0,
        100.0,
        "an altimeter error of 100 m is no altimeter",
    ),
    pos(
        "vehicles[].chem_sensor.rate_hz",
        1000.0,
        "samples at 1 kHz at most (one per step is taken)",
    ),
    pos(
        "vehicles[].chem_sensor.volts_per_unit",
        1e9,
        "readings must stay finite",
    ),
    pos(
        "vehicles[].chem_sensor.full_scale_v",
        1e6,
        "readings must stay finite",
    ),
    num(
        "vehicles[].chem_sensor.noise_sd_v",
        0.0,
        1e6,
        "readings must stay finite",
    ),
    num(
        "vehicles[].chem_sensor.lag_time_constant_s",
        0.0,
        1e5,
        "a lag of a day at most",
    ),
    num(
        "vehicles[].chem_sensor.threshold_v",
        0.0,
        1e6,
        "readings must stay finite",
    ),
    pos(
        "vehicles[].chem_sensor.medium_salinity_ppt",
        1000.0,
        "parts per thousand",
    ),
    pos(
        "vehicles[].chem_sensor.fresh_density_kgpm3",
        1e5,
        "a density of water",
    ),
    num(
        "vehicles[].chem_sensor.noise_sd_ppt",
        0.0,
        1000.0,
        "parts per thousand",
    ),
    num("vehicles[].modem.deaf_start_s", 0.0, LONG, "mission time"),
    num("vehicles[].modem.deaf_end_s", 0.0, LONG, "mission time"),
    pos(
        "vehicles[].flow_sensor.rate_hz",
        1000.0,
        "samples at 1 kHz at most (one per step is taken)",
    ),
    num(
        "vehicles[].flow_sensor.noise_sd_mps",
        0.0,
        10.0,
        "ocean currents stay below 10 m/s",
    ),
    num(
        "vehicles[].flow_sensor.bias_mps[]",
        -10.0,
        10.0,
        "ocean currents stay below 10 m/s",
    ),
    num(
        "vehicles[].flow_sensor.fault_start_s",
        -LONG,
        LONG,
        TIME_WHY,
    ),
    num("vehicles[].flow_sensor.fault_end_s", -LONG, LONG, TIME_WHY),
    pos(
        "vehicles[].range_sensor.max_range_m",
        1e4,
        "sonars see kilometres at most",
    ),
    num(
        "vehicles[].range_sensor.rays_per_group",
        1.0,
        RangeSensorParams::MAX_RAYS_PER_GROUP as f64,
        "rays are cast at every step",
    ),
    pos(
        "vehicles[].range_sensor.front_half_angle_deg",
        180.0,
        "half a turn at most",
    ),
    pos(
        "vehicles[].range_sensor.side_outer_angle_deg",
        180.0,
        "half a turn at most",
    ),
    pos(
        "vehicles[].range_sensor.rate_hz",
        1000.0,
        "pings at 1 kHz at most (one per step is taken)",
    ),
    num(
        "vehicles[].range_sensor.noise_sd_m",
        0.0,
        1e4,
        "sonars see kilometres at most",
    ),
    num(
        "vehicles[].range_sensor.detection_probability",
        0.0,
        1.0,
        "a probability (0 is refused: a sensor that never sees is no sensor)",
    ),
    count(
        "mission.op_area",
        10_000,
        "the cage measures every edge at every decision",
    ),
    num("mission.op_area[][]", -COORD, COORD, COORD_WHY),
    count("mission.subregions", 100, "subregions are searched in turn"),
    count(
        "mission.subregions[]",
        10_000,
        "every edge is measured at every decision",
    ),
    num("mission.subregions[][][]", -COORD, COORD, COORD_WHY),
    pos("mission.time_limit_s", LONG, TIME_WHY),
    num("mission.spinup_s", 0.0, LONG, TIME_WHY),
    pos(
        "mission.spinup_dt_s",
        3600.0,
        "the plume's step; an hour at most",
    ),
    pos(
        "mission.env_dt_s",
        60.0,
        "a step of more than a minute skips the plume's motion",
    ),
    num("mission.prior_flow_toward_deg", -TURNS, TURNS, ANGLE_WHY),
    num(
        "mission.drop_margin_m",
        50.0,
        COORD,
        "filaments this far beyond every vehicle's reach are dropped; at least 50 m",
    ),
    pos(
        "mission.success_radius_m",
        COORD,
        "a radius > 0 in a local frame: 10,000 km is not local",
    ),
    num("comms.acoustic.latency_s", 0.0, 1e5, "a day at most"),
    pos("comms.acoustic.sound_speed_mps", 1e9, "finite"),
    num("comms.acoustic.loss_probability", 0.0, 1.0, "a probability"),
    pos("comms.acoustic.max_range_m", 1e8, "finite"),
    num("comms.radio.latency_s", 0.0, 1e5, "a day at most"),
    pos("comms.radio.sound_speed_mps", 1e9, "finite"),
    num("comms.radio.loss_probability", 0.0, 1.0, "a probability"),
    pos("comms.radio.max_range_m", 1e8, "finite"),
    num(
        "comms.ranging.timing_noise_sd_s",
        0.0,
        10.0,
        "ten seconds of timing error is no ranging",
    ),
    pos("comms.ranging.sound_speed_mps", 1e9, "finite"),
    count("planners", 100, "planners are per vehicle"),
];

/// The most flow grid-node updates a run may take (sub-steps times nodes, spin-up included):
/// about an hour of computing at a few hundred million node updates a second. Counting sub-steps
/// alone let a fine grid with a short stable step run for days within [`MAX_STEPS`].
pub const MAX_FLOW_NODE_STEPS: f64 = 1e12;

/// The most steps of a run (plume run or mission), the spin-up apart: about a day of computing.
pub const MAX_STEPS: f64 = 1e8;
/// The most steps of a spin-up.
pub const MAX_SPINUP_STEPS: f64 = 1e7;
/// The most rows of a plume run's `probes.csv` (samples times probes): about 250 MB of text,
/// held in memory until the run ends.
pub const MAX_PROBE_ROWS: u64 = 5_000_000;
/// The most filament snapshots of a plume run (`output.filaments_interval_s`).
pub const MAX_FILAMENT_SNAPSHOTS: u64 = 1000;
/// The most rows of a plume run's `filament_series.csv`: snapshots that would go beyond are not
/// written (the run says so), since the live filaments are only known as the run goes.
pub const MAX_FILAMENT_ROWS: u64 = 5_000_000;

/// The row for a key path (array indices written `[]`).
pub fn limit(key: &str) -> Option<&'static Limit> {
    LIMITS.iter().find(|l| l.key == key)
}

/// A number as it is best read in a message: `-1e-300`, `0.25`, `2.0`.
pub fn show(v: f64) -> String {
    format!("{v:?}")
}

impl Bound {
    /// The bound in words.
    pub fn describe(&self) -> String {
        match *self {
            Bound::Number { min, min_open, max } => format!(
                "{} {} and <= {}",
                if min_open { ">" } else { ">=" },
                show(min),
                show(max)
            ),
            Bound::Count(n) => format!("at most {n} entries"),
            Bound::Any => "any".into(),
        }
    }
}

/// A number or list of a scenario out of its bound, by key path.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{path}: {kind}")]
pub struct LimitError {
    /// Key path, e.g. `vehicles[0].nav.fix_interval_s`.
    pub path: String,
    /// What is wrong.
    pub kind: LimitErrorKind,
}

/// What is wrong with a number or list ([`LimitError`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LimitErrorKind {
    /// A list longer than its row allows.
    #[error("{count} entries; {bound} ({why})")]
    TooManyEntries {
        /// Its length.
        count: usize,
        /// The bound in words ([`Bound::describe`]).
        bound: String,
        /// Why.
        why: &'static str,
    },
    /// More `[planners.NAME]` tables than the `planners` row allows.
    #[error("{count} tables; {bound} ({why})")]
    TooManyTables {
        /// How many.
        count: usize,
        /// The bound in words.
        bound: String,
        /// Why.
        why: &'static str,
    },
    /// A number whose key has no row.
    #[error("this number has no documented bound (a key of the format without one)")]
    NoBound,
    /// A number outside its row's bound (or not finite).
    #[error("must be {bound} ({why}), got {got}")]
    OutOfBound {
        /// The bound in words.
        bound: String,
        /// Why.
        why: &'static str,
        /// The value, as [`show`] writes it.
        got: String,
    },
    /// A number where the row bounds a list.
    #[error("expected a list, got a number")]
    NotAList,
}

impl LimitError {
    fn new(path: impl Into<String>, kind: LimitErrorKind) -> Self {
        LimitError {
            path: path.into(),
            kind,
        }
    }
}

/// Checks every number and list of a scenario's table against [`LIMITS`]; errors name the key
/// path. Tables of planners are left to the planner registry.
pub fn check(table: &toml::Table) -> Result<(), LimitError> {
    walk(&toml::Value::Table(table.clone()), "", "")
}

fn join(a: &str, b: &str) -> String {
    if a.is_empty() {
        b.to_string()
    } else {
        format!("{a}.{b}")
    }
}

fn walk(v: &toml::Value, path: &str, pattern: &str) -> Result<(), LimitError> {
    match v {
        toml::Value::Table(t) => {
            for (k, x) in t {
                if pattern.is_empty() && (k == "planner" || k == "planners") {
                    if let (Some(n), toml::Value::Table(p)) = (limit("planners"), x)
                        && k == "planners"
                        && let Bound::Count(max) = n.bound
                        && p.len() > max
                    {
                        return Err(LimitError::new(
                            "planners",
                            LimitErrorKind::TooManyTables {
                                count: p.len(),
                                bound: n.bound.describe(),
                                why: n.why,
                            },
                        ));
                    }
                    continue;
                }
                walk(x, &join(path, k), &join(pattern, k))?;
            }
            Ok(())
        }
        toml::Value::Array(a) => {
            if let Some(l) = limit(pattern)
                && let Bound::Count(max) = l.bound
                && a.len() > max
            {
                return Err(LimitError::new(
                    path,
                    LimitErrorKind::TooManyEntries {
                        count: a.len(),
                        bound: l.bound.describe(),
                        why: l.why,
                    },
                ));
            }
            for (i, x) in a.iter().enumerate() {
                walk(x, &format!("{path}[{i}]"), &format!("{pattern}[]"))?;
            }
            Ok(())
        }
        toml::Value::Integer(i) => number(*i as f64, path, pattern),
        toml::Value::Float(f) => number(*f, path, pattern),
        _ => Ok(()),
    }
}

fn number(v: f64, path: &str, pattern: &str) -> Result<(), LimitError> {
    let Some(l) = limit(pattern) else {
        return Err(LimitError::new(path, LimitErrorKind::NoBound));
    };
    match l.bound {
        Bound::Number { min, min_open, max } => {
            let low = if min_open { v > min } else { v >= min };
            if v.is_finite() && low && v <= max {
                Ok(())
            } else {
                Err(LimitError::new(
                    path,
                    LimitErrorKind::OutOfBound {
                        bound: l.bound.describe(),
                        why: l.why,
                        got: show(v),
                    },
                ))
            }
        }
        Bound::Count(_) => Err(LimitError::new(path, LimitErrorKind::NotAList)),
        Bound::Any => Ok(()),
    }
}

/// The table as aligned text (`plumetrace limits`): key, bound and why, then the family keys'.
pub fn text() -> String {
    let family: Vec<(String, String, &str)> = crate::family::FAMILY_LIMITS
        .iter()
        .map(|(key, lo, hi, why)| {
            let bound = format!(">= {} and <= {}", show(*lo), show(*hi));
            (key.to_string(), bound, *why)
        })
        .collect();
    let width = LIMITS
        .iter()
        .map(|l| l.key.len())
        .chain(family.iter().map(|f| f.0.len()))
        .max()
        .unwrap_or(0);
    let mut out = String::new();
    for l in LIMITS {
        let _ = writeln!(out, "{:width$}  {} ({})", l.key, l.bound.describe(), l.why);
    }
    out.push_str(
        "\nScenario families (*.family.toml); a range [low, high] needs low <= high, both within \
         the bound:\n",
    );
    for (key, bound, why) in &family {
        let _ = writeln!(out, "{key:width$}  {bound} ({why})");
    }
    out
}

/// The table as Markdown (`| key | bound | why |`), then the family keys' table.
pub fn markdown() -> String {
    let mut out = String::from("| key | bound | why |\n| --- | --- | --- |\n");
    for l in LIMITS {
        let _ = writeln!(out, "| `{}` | {} | {} |", l.key, l.bound.describe(), l.why);
    }
    out.push_str(
        "\nScenario families (`*.family.toml`, see [Scenario families](campaigns.md#scenario-families)); \
         a range `[low, high]` needs `low <= high`, both within the bound:\n\n\
         | key | bound | why |\n| --- | --- | --- |\n",
    );
    for (key, lo, hi, why) in crate::family::FAMILY_LIMITS {
        let _ = writeln!(
            out,
            "| `{key}` | >= {} and <= {} | {why} |",
            show(*lo),
            show(*hi)
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(s: &str) -> toml::Table {
        s.parse().unwrap_or_default()
    }

    #[test]
    fn numbers_and_lists_are_checked_against_their_row() {
        assert!(check(&table("[sim]\ndt_s = 0.1\nduration_s = 10.0")).is_ok());
        let cases = [
            ("[sim]\ndt_s = 0.0", "sim.dt_s", "> 0.0 and <= 60.0"),
            ("[sim]\ndt_s = nan", "sim.dt_s", "got NaN"),
            (
                "[mission]\ntime_limit_s = 1e300",
                "mission.time_limit_s",
                "got 1e300",
            ),
            (
                "[[vehicles]]\nx_m = 0.0\n[vehicles.nav]\nfix_interval_s = 1e-12",
                "vehicles[0].nav.fix_interval_s",
                "got 1e-12",
            ),
            (
                "[mission]\nop_area = [[0.0, 0.0], [1e18, 0.0], [0.0, 1.0]]",
                "mission.op_area[1][0]",
                "<= 10000000.0",
            ),
            (
                "[plume]\nmax_filaments = 4611686018427387904",
                "plume.max_filaments",
                "memory",
            ),
            (
                "[domain]\nwidth_m = 3.0",
                "domain.width_m",
                "no documented bound",
            ),
            (
                "[mission]\nsuccess_radius_m = 0.0",
                "mission.success_radius_m",
                "> 0.0 and <= 10000000.0",
            ),
        ];
        let error = |text: &str| {
            check(&table(text))
                .err()
                .map(|e| (e.path, e.kind.to_string()))
                .unwrap_or_default()
        };
        for (text, key, message) in cases {
            let e = error(text);
            assert_eq!(e.0, key, "{text}");
            assert!(e.1.contains(message), "{text}: {}", e.1);
        }
        let many = format!("vehicles = [{}]", vec!["{ x_m = 1.0 }"; 101].join(", "));
        assert_eq!(error(&many).0, "vehicles");
        // Planner tables are the registry's.
        assert!(
            check(&table(
                "[planner]\nbeta_deg = 1e300\n[planners.a]\nspeed_mps = -1.0"
            ))
            .is_ok()
        );
    }

    #[test]
    fn every_preset_number_has_a_bound_and_is_within_it() {
        for p in crate::PRESETS {
            let t = table(p.toml);
            assert!(!t.is_empty());
            assert_eq!(check(&t), Ok(()), "{}", p.name);
        }
        assert!(show(-1e-300).len() < 10);
        assert!(markdown().contains("| `sim.dt_s` | > 0.0 and <= 60.0 |"));
    }

    #[test]
    fn series_bounds_say_the_limits_the_build_checks() {
        let why = |k: &str| limit(k).map(|l| l.why).unwrap_or_default();
        assert_eq!(MAX_PROBE_ROWS, 5_000_000);
        assert!(why("output.probe_interval_s").contains("5,000,000 rows"));
        assert_eq!(MAX_FILAMENT_SNAPSHOTS, 1000);
        assert!(why("output.filaments_interval_s").contains("1,000 snapshots"));
    }
}
