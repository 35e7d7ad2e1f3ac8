//! The serde layer: a mirror of the scenario TOML. Types only; values are checked in
//! [`crate::build`](mod@crate::build). Every key carries its unit (`_m`, `_s`, `_mps`, `_deg`,
//! `_m2ps`, `_hz`).

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// A whole scenario file.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioConfig {
    /// Short name.
    pub name: String,
    /// One line saying what the scenario is for.
    #[serde(default)]
    pub description: String,
    /// Run seed (overridable with `--seed`): a whole number, written as a string of digits
    /// beyond 2^63 - 1, where TOML integers stop ([`seed`]).
    #[serde(
        default,
        deserialize_with = "seed::read",
        serialize_with = "seed::write"
    )]
    pub seed: u64,
    /// Time stepping.
    pub sim: SimConfig,
    /// The simulated region.
    pub domain: DomainConfig,
    /// The flow field.
    pub flow: FlowConfig,
    /// A seabed that is not flat, from a bathymetry file (absent: flat at `z = 0`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bathymetry: Option<BathymetryConfig>,
    /// The plume model.
    #[serde(default)]
    pub plume: PlumeConfig,
    /// Chemical sources.
    #[serde(default)]
    pub sources: Vec<SourceConfig>,
    /// Soft obstacles (kelp).
    #[serde(default)]
    pub obstacles: Vec<ObstacleConfig>,
    /// Kelp fields drawn at random (their patches join the obstacles).
    #[serde(default)]
    pub kelp: Vec<KelpConfig>,
    /// Vehicles (AUVs and surface craft) with their navigation and sensors.
    #[serde(default)]
    pub vehicles: Vec<VehicleConfig>,
    /// The mission: op-area, subregions, time limit, plume spin-up (needed with vehicles).
    pub mission: Option<MissionConfig>,
    /// The planner flown by every AUV that names none (`strategy` or `kind` names it; its keys
    /// are checked by the planner registry when the mission is built).
    pub planner: Option<toml::Table>,
    /// Named planners, flown by the vehicles that name them (`planner = "NAME"`).
    #[serde(default)]
    pub planners: BTreeMap<String, toml::Table>,
    /// Message channels between vehicles.
    #[serde(default)]
    pub comms: CommsConfig,
    /// What a plume run writes.
    #[serde(default)]
    pub output: OutputConfig,
    /// The site's origin in latitude and longitude (where `x = y = 0`): positions may then be
    /// given as latitude and longitude, and outputs carry both frames.
    pub origin: Option<plumetrace_core::geo::Origin>,
}

/// `[sim]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimConfig {
    /// Time step, s.
    pub dt_s: f64,
    /// Simulated duration, s.
    pub duration_s: f64,
}

/// `[domain]`: the rectangle the simulation covers; filaments leaving it are removed.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DomainConfig {
    /// West edge, m.
    pub x_min_m: f64,
    /// East edge, m.
    pub x_max_m: f64,
    /// South edge, m.
    pub y_min_m: f64,
    /// North edge, m.
    pub y_max_m: f64,
    /// Water depth, m (the surface reflects filaments); absent = no surface.
    pub depth_m: Option<f64>,
}

/// `[bathymetry]`: the seabed's depth from a CF NetCDF file. Heights (`z_m` of sources, AUV
/// altitudes) are then above the seabed where they are, and the surface is the deepest water
/// over the domain.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BathymetryConfig {
    /// The file (relative to the scenario file): NetCDF classic, CF depths or elevations.
    pub file: PathBuf,
    /// The depth's variable (default: found by `standard_name`, or named depth, h,
    /// bathymetry, elevation or z).
    pub variable: Option<String>,
    /// Node spacing of the grid the seabed is sampled onto, m (default: the file's own spacing
    /// near the origin; at most 2000 nodes a side).
    pub spacing_m: Option<f64>,
}

/// Which flow model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FlowKind {
    /// Uniform in space (steady or tidal).
    Uniform,
    /// Farrell meandering field.
    Farrell,
    /// From a CSV file.
    Gridded,
}

/// `[flow]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlowConfig {
    /// Model name: "uniform", "farrell" or "gridded".
    pub model: FlowKind,
    /// Mean flow (uniform and farrell).
    pub mean: Option<MeanFlowConfig>,
    /// Farrell grid and noise parameters.
    pub farrell: Option<plumetrace_env::flow::FarrellParams>,
    /// File for "gridded" (relative to the scenario file): a CSV grid or CF currents in a
    /// NetCDF classic file (told apart by its first bytes).
    pub file: Option<PathBuf>,
    /// How to read CF currents from a NetCDF `file`.
    pub netcdf: Option<NetcdfFlowConfig>,
    /// "gridded": the strength of a Farrell meander added to the grid (its departure from its
    /// mean times this; `[flow.farrell]` sets the field; default none).
    pub meander: Option<f64>,
}

/// `[flow.netcdf]`: how CF currents are read from a NetCDF file (every key optional).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NetcdfFlowConfig {
    /// The date the vehicles start (a plume run: its start), UTC, `YYYY-MM-DD[Thh:mm:ss][Z]`
    /// (default: the file's first time).
    pub start: Option<String>,
    /// Depth below the surface the levels are interpolated to, m (default: `domain.depth_m`
    /// minus the first source's height, the plume's layer).
    pub depth_m: Option<f64>,
    /// Spacing of the grid the field is resampled onto, m (default: a projected, evenly spaced
    /// grid is used node for node; otherwise the file's own spacing near the origin).
    pub spacing_m: Option<f64>,
    /// The eastward velocity's variable (default: found by `standard_name`).
    pub u_variable: Option<String>,
    /// The northward velocity's variable (default: found by `standard_name`).
    pub v_variable: Option<String>,
}

/// `[flow.mean]`: steady (`speed_mps`, `toward_deg`) or tidal (`speed_min_mps`, `speed_max_mps`,
/// `toward_min_deg`, `toward_max_deg`, `period_s`, optional `phase_deg`).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeanFlowConfig {
    /// Steady speed, m/s.
    pub speed_mps: Option<f64>,
    /// Steady direction (towards), compass degrees.
    pub toward_deg: Option<f64>,
    /// Tidal: lowest speed, m/s.
    pub speed_min_mps: Option<f64>,
    /// Tidal: highest speed, m/s.
    pub speed_max_mps: Option<f64>,
    /// Tidal: one end of the direction swing, degrees.
    pub toward_min_deg: Option<f64>,
    /// Tidal: other end of the direction swing, degrees.
    pub toward_max_deg: Option<f64>,
    /// Tidal: period, s.
    pub period_s: Option<f64>,
    /// Tidal: phase at t = 0, degrees.
    pub phase_deg: Option<f64>,
}

/// Which plume model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlumeKind {
    /// Farrell filaments.
    Filaments,
    /// Steady Gaussian plume (first source, mean flow at t = 0).
    Gaussian,
    /// Steady grid from a CSV file.
    Gridded,
}

/// What the seabed does to filaments.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SeabedKind {
    /// Reflects (no chemical lost into the seabed).
    Reflecting,
    /// No boundary (pompy).
    None,
}

/// `[plume]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlumeConfig {
    /// Model name: "filaments", "gaussian" or "gridded".
    pub model: PlumeKind,
    /// Horizontal (cross-flow) diffusivity, m^2/s.
    pub horizontal_diffusivity_m2ps: f64,
    /// Vertical diffusivity, m^2/s.
    pub vertical_diffusivity_m2ps: f64,
    /// Filament radius at release, m.
    pub init_radius_m: f64,
    /// Growth of the squared filament radius, m^2/s.
    pub growth_rate_m2ps: f64,
    /// Concentration cut-off, in filament radii.
    pub cutoff_radii: f64,
    /// Most live filaments.
    pub max_filaments: usize,
    /// Filaments released at each source at t = 0 (pompy releases 10).
    pub initial_filaments: u64,
    /// Use pompy's dt-scaled random walk instead of the diffusivities.
    pub pompy_compatible: bool,
    /// pompy's `centre_rel_diff_scale`, m/s (with `pompy_compatible`).
    pub pompy_diff_scale_mps: f64,
    /// Seabed behaviour.
    pub seabed: SeabedKind,
    /// CSV file for "gridded".
    pub file: Option<PathBuf>,
}

impl Default for PlumeConfig {
    fn default() -> Self {
        let p = plumetrace_env::FilamentParams::default();
        let (h, v) = match p.dispersion {
            plumetrace_env::plume::Dispersion::Physical {
                horizontal_m2ps,
                vertical_m2ps,
            } => (horizontal_m2ps, vertical_m2ps),
            plumetrace_env::plume::Dispersion::PompyCompatible { .. } => (0.02, 0.002),
        };
        PlumeConfig {
            model: PlumeKind::Filaments,
            horizontal_diffusivity_m2ps: h,
            vertical_diffusivity_m2ps: v,
            init_radius_m: p.init_radius_m,
            growth_rate_m2ps: p.growth_rate_m2ps,
            cutoff_radii: p.cutoff_radii,
            max_filaments: p.max_filaments,
            initial_filaments: 0,
            pompy_compatible: false,
            pompy_diff_scale_mps: 2.0,
            seabed: SeabedKind::Reflecting,
            file: None,
        }
    }
}

/// `[[sources]]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SourceConfig {
    /// East, m.
    pub x_m: f64,
    /// North, m.
    pub y_m: f64,
    /// Height above the seabed, m (0 = on the bottom).
    #[serde(default)]
    pub z_m: f64,
    /// Chemical released per second.
    #[serde(default = "one")]
    pub mass_rate_per_s: f64,
    /// Filaments released per second.
    #[serde(default = "five")]
    pub filament_rate_hz: f64,
}

fn one() -> f64 {
    1.0
}
fn five() -> f64 {
    5.0
}

/// `[[obstacles]]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleConfig {
    /// Name for logs and plots.
    #[serde(default)]
    pub name: String,
    /// Polygon vertices `[east, north]`, m.
    #[serde(deserialize_with = "points::list")]
    pub vertices: Vec<[f64; 2]>,
}

/// `[[kelp]]`: a field of kelp patches drawn at random in a region, with gaps between them.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KelpConfig {
    /// Name for logs and plots (patches are `NAME.patch[j]`; default `kelp[k]`).
    #[serde(default)]
    pub name: String,
    /// Where the patch centres go: a polygon `[[east, north], ...]`, m.
    #[serde(deserialize_with = "points::list")]
    pub region: Vec<[f64; 2]>,
    /// Number of patches.
    pub patches: usize,
    /// Smallest and largest patch radius, m (default `[3, 6]`).
    #[serde(default = "kelp_radius")]
    pub radius_m: [f64; 2],
    /// Least distance between two patches' bounding circles, m (default 5).
    #[serde(default = "five")]
    pub gap_m: f64,
    /// Vertices of each patch outline (default 12).
    #[serde(default = "twelve")]
    pub vertices: usize,
    /// Raggedness: vertex radii fall between `(1 - roughness) R` and `R` (default 0.3).
    #[serde(default = "kelp_roughness")]
    pub roughness: f64,
    /// Radius kept free of kelp around every source and every vehicle's start, m (default 10).
    #[serde(default = "ten")]
    pub clear_m: f64,
    /// Seed of the draw (default: the run seed, so each run has its own field); any whole
    /// number 0..2^64, as the run seed ([`seed`]).
    #[serde(
        default,
        deserialize_with = "seed::read_some",
        serialize_with = "seed::write_some",
        skip_serializing_if = "Option::is_none"
    )]
    pub seed: Option<u64>,
}

fn kelp_radius() -> [f64; 2] {
    [3.0, 6.0]
}
fn twelve() -> usize {
    12
}
fn ten() -> f64 {
    10.0
}
fn kelp_roughness() -> f64 {
    0.3
}

/// `[output]`: the concentration snapshot, the time average, the probe series and the filament
/// snapshots written by a plume run (`plumetrace run` on a scenario without a mission).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OutputConfig {
    /// Snapshot grid points along x.
    pub nx: usize,
    /// Snapshot grid points along y.
    pub ny: usize,
    /// Height of the snapshot plane above the seabed, m.
    pub z_m: f64,
    /// Time between samples of the time average, s.
    pub average_interval_s: f64,
    /// Start of the time average, s (lets the plume fill the domain first).
    pub average_start_s: f64,
    /// Threshold for the intermittency map (fraction of samples above it).
    pub threshold: f64,
    /// Probe points `[x_m, y_m, z_m]` (z above the seabed) whose concentrations a plume run
    /// writes at every probe sample (`probes.csv`).
    pub probes: Vec<[f64; 3]>,
    /// Time between probe samples, s, from the start of the run (default: `average_interval_s`,
    /// so that from `average_start_s` on the probes are sampled at the time average's steps).
    pub probe_interval_s: Option<f64>,
    /// Time between snapshots of every filament (`filament_series.csv`), s; absent or 0: none.
    pub filaments_interval_s: Option<f64>,
}

impl Default for OutputConfig {
    fn default() -> Self {
        OutputConfig {
            nx: 201,
            ny: 201,
            z_m: 0.0,
            average_interval_s: 1.0,
            average_start_s: 0.0,
            threshold: 0.1,
            probes: Vec::new(),
            probe_interval_s: None,
            filaments_interval_s: None,
        }
    }
}

/// `[[vehicles]]`: one vehicle. Every omitted parameter takes the default of its kind (the REMUS
/// field values for an AUV).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleConfig {
    /// "auv" or "surface".
    pub kind: plumetrace_core::VehicleKind,
    /// Name for logs and plots.
    #[serde(default)]
    pub name: String,
    /// Start East, m.
    pub x_m: f64,
    /// Start North, m.
    pub y_m: f64,
    /// Start heading, compass degrees.
    #[serde(default)]
    pub heading_deg: f64,
    /// Start height above the seabed, m (AUV; default 2). Surface craft start at the surface.
    pub altitude_m: Option<f64>,
    /// The planner it flies: a `[planners.NAME]` table (absent: an AUV flies `[planner]`, if
    /// any; otherwise the vehicle has no planner and keeps its last command).
    pub planner: Option<String>,
    /// Dynamics.
    #[serde(default)]
    pub dynamics: DynamicsConfig,
    /// Navigation.
    #[serde(default)]
    pub nav: NavConfig,
    /// Chemical sensor.
    #[serde(default)]
    pub chem_sensor: ChemSensorConfig,
    /// Flow sensor.
    #[serde(default)]
    pub flow_sensor: FlowSensorConfig,
    /// Obstacle range sensors (absent: none).
    pub range_sensor: Option<RangeSensorConfig>,
    /// Its modem's faults.
    #[serde(default)]
    pub modem: ModemConfig,
}

/// `[vehicles.modem]`: a window in which the vehicle's modem hears nothing.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModemConfig {
    /// Start of the deaf window, s of mission time.
    pub deaf_start_s: Option<f64>,
    /// End of the deaf window, s.
    pub deaf_end_s: Option<f64>,
}

/// What a chemical sensor measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChemModel {
    /// An analog reading proportional to the concentration (volts).
    Voltage,
    /// Salinity over a freshwater plume (ppt), with half-normal noise.
    Salinity,
    /// The same salinity probe read as its contrast: the medium's salinity less the reading
    /// (ppt below the ambient, 0 outside the plume), a concentration for the single-vehicle
    /// planners.
    SalinityDeficit,
}

/// `[vehicles.dynamics]`
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicsConfig {
    /// Highest water-relative speed, m/s.
    pub max_speed_mps: Option<f64>,
    /// Highest turn rate, deg/s.
    pub max_turn_rate_deg_s: Option<f64>,
    /// Speed response time constant, s.
    pub speed_time_constant_s: Option<f64>,
    /// Depth/altitude response time constant, s.
    pub vertical_time_constant_s: Option<f64>,
    /// Altitude-keeping error (standard deviation), m.
    pub altitude_error_sd_m: Option<f64>,
    /// Altitude-keeping error correlation time, s.
    pub altitude_error_time_s: Option<f64>,
    /// The DVL's beams' angle from the vertical, deg (0: altitude hold sees no slope).
    pub dvl_beam_angle_deg: Option<f64>,
    /// The forward altimeter's range ahead along the heading, m (0: none).
    pub look_ahead_m: Option<f64>,
    /// The lowest altitude the altitude hold aims at over a seabed grid, m.
    pub min_altitude_m: Option<f64>,
}

/// `[vehicles.nav]`
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NavConfig {
    /// Time between fixes, s.
    pub fix_interval_s: Option<f64>,
    /// Fix error per axis, m.
    pub fix_sigma_m: Option<f64>,
    /// Dead-reckoning velocity error, standard deviation per axis, m/s.
    pub velocity_error_sd_mps: Option<f64>,
    /// Its correlation time, s.
    pub velocity_error_tau_s: Option<f64>,
    /// Compass noise, deg.
    pub heading_sd_deg: Option<f64>,
    /// Whether the vehicle has a position estimate at all.
    pub position_estimate: Option<bool>,
    /// Speed-log noise, m/s.
    pub speed_sd_mps: Option<f64>,
    /// Altimeter noise, m.
    pub altimeter_sd_m: Option<f64>,
    /// Check measured currents for plausibility before dead-reckoning with them.
    pub flow_check: Option<bool>,
}

/// `[vehicles.chem_sensor]`
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChemSensorConfig {
    /// Sampling rate, Hz.
    pub rate_hz: Option<f64>,
    /// Volts per unit of concentration.
    pub volts_per_unit: Option<f64>,
    /// Full scale, V.
    pub full_scale_v: Option<f64>,
    /// Noise, V.
    pub noise_sd_v: Option<f64>,
    /// First-order lag, s.
    pub lag_time_constant_s: Option<f64>,
    /// Detection threshold, V: passed to the vehicle's planner as its `threshold_v` (the
    /// threshold belongs to the planner; this key is kept for older scenario files).
    pub threshold_v: Option<f64>,
    /// What it measures: "voltage" (default), "salinity" or "salinity_deficit".
    pub model: Option<ChemModel>,
    /// Salinity: the medium's salinity, ppt (35).
    pub medium_salinity_ppt: Option<f64>,
    /// Salinity: density of the fresh water, kg/m^3 (998.2).
    pub fresh_density_kgpm3: Option<f64>,
    /// Salinity: scale of the half-normal noise, ppt (0.1).
    pub noise_sd_ppt: Option<f64>,
}

/// `[vehicles.flow_sensor]`
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlowSensorConfig {
    /// Sampling rate, Hz.
    pub rate_hz: Option<f64>,
    /// Noise per axis, m/s.
    pub noise_sd_mps: Option<f64>,
    /// Bias `[east, north]`, m/s.
    #[serde(default, deserialize_with = "points::optional")]
    pub bias_mps: Option<[f64; 2]>,
    /// Start of a wrong-layer (reversed) fault, s.
    pub fault_start_s: Option<f64>,
    /// End of the fault, s.
    pub fault_end_s: Option<f64>,
}

/// `[vehicles.range_sensor]`
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeSensorConfig {
    /// Detection range, m.
    pub max_range_m: Option<f64>,
    /// Rays per group.
    pub rays_per_group: Option<usize>,
    /// Front group half-angle, deg.
    pub front_half_angle_deg: Option<f64>,
    /// Side groups' outer angle, deg.
    pub side_outer_angle_deg: Option<f64>,
    /// Pings per second, Hz.
    pub rate_hz: Option<f64>,
    /// Range noise (standard deviation), m.
    pub noise_sd_m: Option<f64>,
    /// Probability that a ray sees an obstacle it crosses, per ping.
    pub detection_probability: Option<f64>,
}

/// `[mission]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MissionConfig {
    /// Op-area polygon `[[east, north], ...]`, m (default: the domain shrunk by 50 m).
    #[serde(default, deserialize_with = "points::optional_list")]
    pub op_area: Option<Vec<[f64; 2]>>,
    /// Subregions searched in turn (a multi-source mission), each a polygon.
    #[serde(default, deserialize_with = "points::lists")]
    pub subregions: Vec<Vec<[f64; 2]>>,
    /// Mission time limit, s.
    pub time_limit_s: f64,
    /// Plume development before the vehicles start, s.
    #[serde(default)]
    pub spinup_s: f64,
    /// Step of the spin-up, s (default: 10 x `env_dt_s`, within the flow's stable limit).
    pub spinup_dt_s: Option<f64>,
    /// Step of the flow and plume during the mission, s (a whole multiple of `sim.dt_s`;
    /// default `sim.dt_s`).
    pub env_dt_s: Option<f64>,
    /// Flow direction the planner assumes before its first flow measurement, deg (not given:
    /// North, with a warning).
    pub prior_flow_toward_deg: Option<f64>,
    /// Filaments farther than this beyond the downflow edge of every vehicle's reach are
    /// dropped, m (default 200; see the README's plume model).
    pub drop_margin_m: Option<f64>,
    /// A source counts as located when a declaration lies within this distance of it, m
    /// (default [`DEFAULT_SUCCESS_RADIUS_M`](crate::DEFAULT_SUCCESS_RADIUS_M)).
    pub success_radius_m: Option<f64>,
}

/// `[comms]`: one channel model per link kind (absent: ideal, no delay and no loss).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CommsConfig {
    /// Acoustic modems.
    pub acoustic: Option<ChannelConfig>,
    /// Radio between surface craft.
    pub radio: Option<ChannelConfig>,
    /// Acoustic ranging.
    pub ranging: Option<RangingConfig>,
}

/// `[comms.ranging]`
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangingConfig {
    /// Standard deviation of the round-trip time, s (0).
    pub timing_noise_sd_s: Option<f64>,
    /// Sound speed the modem assumes, m/s (1500).
    pub sound_speed_mps: Option<f64>,
}

/// `[comms.acoustic]`, `[comms.radio]`
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelConfig {
    /// Fixed delay, s (0).
    pub latency_s: Option<f64>,
    /// Propagation speed, m/s (none: no travel time; 1500 for sound in sea water).
    pub sound_speed_mps: Option<f64>,
    /// Probability that a message is lost on its way to one recipient (0).
    pub loss_probability: Option<f64>,
    /// Longest distance a message carries, m (none: any).
    pub max_range_m: Option<f64>,
    /// One packet per sender on the water at a time (false): a message sent while the
    /// previous one travels is lost.
    pub one_in_flight: Option<bool>,
}

/// Pairs of numbers (`[east, north]`) read strictly: exactly two numbers each, so that a third
/// number is an error rather than dropped.
mod points {
    use serde::Deserialize;
    use serde::de::{Deserializer, Error, SeqAccess, Visitor};
    use std::fmt;

    /// One `[east, north]` pair.
    struct Point([f64; 2]);

    impl<'de> Deserialize<'de> for Point {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            struct Pair;
            impl<'de> Visitor<'de> for Pair {
                type Value = Point;
                fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                    f.write_str("a pair of numbers [east, north]")
                }
                fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Point, A::Error> {
                    let x: f64 = seq
                        .next_element()?
                        .ok_or_else(|| A::Error::invalid_length(0, &self))?;
                    let y: f64 = seq
                        .next_element()?
                        .ok_or_else(|| A::Error::invalid_length(1, &self))?;
                    if seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
                        return Err(A::Error::custom(
                            "expected a pair of numbers [east, north], got more than two",
                        ));
                    }
                    Ok(Point([x, y]))
                }
            }
            d.deserialize_seq(Pair)
        }
    }

    pub fn list<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[f64; 2]>, D::Error> {
        Ok(Vec::<Point>::deserialize(d)?
            .into_iter()
            .map(|p| p.0)
            .collect())
    }

    pub fn optional<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
        Ok(Some(Point::deserialize(d)?.0))
    }

    pub fn optional_list<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<Option<Vec<[f64; 2]>>, D::Error> {
        list(d).map(Some)
    }

    pub fn lists<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Vec<[f64; 2]>>, D::Error> {
        Ok(Vec::<Vec<Point>>::deserialize(d)?
            .into_iter()
            .map(|l| l.into_iter().map(|p| p.0).collect())
            .collect())
    }
}

/// Run seeds: any whole number 0..2^64. TOML integers stop at 2^63 - 1, so a larger seed (half
/// of those a campaign derives) is written as a string of digits: `seed = "10451216379200822465"`.
pub mod seed {
    use serde::de::{Deserializer, Error, Visitor};
    use serde::ser::Serializer;
    use std::fmt;

    const EXPECTED: &str = "a whole number from 0 to 18446744073709551615 (beyond \
                            9223372036854775807 a string of digits, \"18446744073709551615\")";

    /// The seed as a TOML value: an integer where TOML has one, else a string of digits.
    pub fn value(seed: u64) -> toml::Value {
        match i64::try_from(seed) {
            Ok(i) => toml::Value::Integer(i),
            Err(_) => toml::Value::String(seed.to_string()),
        }
    }

    /// Reads a seed written as an integer or a string of digits.
    pub fn read<'de, D: Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
        struct Seed;
        impl Visitor<'_> for Seed {
            type Value = u64;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(EXPECTED)
            }
            fn visit_u64<E: Error>(self, v: u64) -> Result<u64, E> {
                Ok(v)
            }
            fn visit_i64<E: Error>(self, v: i64) -> Result<u64, E> {
                u64::try_from(v).map_err(|_| E::custom(format!("expected {EXPECTED}, got {v}")))
            }
            fn visit_str<E: Error>(self, v: &str) -> Result<u64, E> {
                v.parse()
                    .map_err(|_| E::custom(format!("expected {EXPECTED}, got \"{v}\"")))
            }
        }
        d.deserialize_any(Seed)
    }

    /// Reads a seed that may be left out ([`read`]).
    pub fn read_some<'de, D: Deserializer<'de>>(d: D) -> Result<Option<u64>, D::Error> {
        read(d).map(Some)
    }

    /// Writes a seed that may be left out ([`write`]).
    pub fn write_some<S: Serializer>(seed: &Option<u64>, s: S) -> Result<S::Ok, S::Error> {
        match seed {
            Some(v) => write(v, s),
            None => s.serialize_none(),
        }
    }

    /// Writes a seed as [`value`] does.
    pub fn write<S: Serializer>(seed: &u64, s: S) -> Result<S::Ok, S::Error> {
        match i64::try_from(*seed) {
            Ok(i) => s.serialize_i64(i),
            Err(_) => s.serialize_str(&seed.to_string()),
        }
    }
}
