//! The onboard file: only what the vehicle process needs (the planner table, the mission
//! geometry, the chemical input, the link and how time runs), read in two phases: a serde mirror
//! of the TOML that rejects unknown keys, then checks of every number that name the key path
//! and the file.
//!
//! ```toml
//! name = "demo on a vehicle"
//! [mission]
//! op_area = [[60.0, -80.0], [460.0, -80.0], [460.0, 80.0], [60.0, 80.0]]
//! prior_flow_toward_deg = 90.0
//! [planner]
//! kind = "amp"
//! [link]
//! protocol = "bluefin"          # or "iver", or "moos" (the `moos` feature)
//! address = "127.0.0.1:29500"   # bluefin; iver: device = "/dev/ttyUSB0"; moos: [link.moos]
//! origin = { lat_deg = 36.18, lon_deg = -75.75 }
//! [chemical]
//! format = "sentence"           # or "plain"
//! id = "PTCHM"
//! field = 2
//! [run]
//! mode = "lock_step"            # or "real_time"
//! ```

use crate::command::VehicleLimits;
use crate::geo::Origin;
use crate::protocol::chem::ChemFormat;
use plumetrace_core::params::ParamError;
use plumetrace_core::{Vec2, VehicleKind};
use plumetrace_guidance::OpArea;
use plumetrace_planner::{BuildContext, MissionGeometry, PlannerConfig};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// The whole file, as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OnboardFile {
    /// A name for logs.
    #[serde(default = "default_name")]
    pub name: String,
    /// The mission geometry.
    pub mission: MissionFile,
    /// The planner table (`kind` and its keys, as in a scenario).
    pub planner: toml::Table,
    /// The vehicle link.
    pub link: LinkFile,
    /// The chemical sensor.
    #[serde(default)]
    pub chemical: ChemicalFile,
    /// The current meter (`None`: no measured current; the planner keeps the prior flow).
    #[serde(default)]
    pub flow: Option<FlowFile>,
    /// How time runs.
    #[serde(default)]
    pub run: RunFile,
}

fn default_name() -> String {
    "onboard".into()
}

/// `[mission]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MissionFile {
    /// The op-area polygon, local metres `[east, north]`.
    #[serde(deserialize_with = "points")]
    pub op_area: Vec<[f64; 2]>,
    /// Subregions searched in turn.
    #[serde(default, deserialize_with = "regions")]
    pub subregions: Vec<Vec<[f64; 2]>>,
    /// Flow direction assumed until the first flow measurement, deg (towards); when left out,
    /// 0 and not "given".
    pub prior_flow_toward_deg: Option<f64>,
    /// The vehicle kind the planner is built for.
    #[serde(default = "default_kind")]
    pub vehicle_kind: VehicleKind,
}

/// A polygon's vertices, each exactly `[east, north]` (a third coordinate is refused, as a
/// scenario refuses it, rather than dropped).
fn points<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<[f64; 2]>, D::Error> {
    let raw: Vec<Vec<f64>> = Vec::deserialize(d)?;
    raw.iter()
        .enumerate()
        .map(|(k, p)| match p.as_slice() {
            [x, y] => Ok([*x, *y]),
            _ => Err(serde::de::Error::custom(format!(
                "vertex {k} has {} coordinates; give [east, north] in metres",
                p.len()
            ))),
        })
        .collect()
}

/// Subregions' vertices, as [`points`].
fn regions<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<Vec<[f64; 2]>>, D::Error> {
    let raw: Vec<Vec<Vec<f64>>> = Vec::deserialize(d)?;
    raw.into_iter()
        .enumerate()
        .map(|(r, poly)| {
            use serde::de::IntoDeserializer;
            let d: serde::de::value::SeqDeserializer<_, serde::de::value::Error> =
                poly.into_deserializer();
            points(d).map_err(|e| serde::de::Error::custom(format!("subregion {r}: {e}")))
        })
        .collect()
}

fn default_kind() -> VehicleKind {
    VehicleKind::Auv
}

/// The link's protocol.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProtocolKind {
    /// Bluefin standard payload interface over TCP.
    Bluefin,
    /// Iver remote helm over a serial line.
    Iver,
    /// A MOOS community client (a MOOSDB over TCP); needs the `moos` cargo feature.
    Moos,
}

/// What a build without the `moos` feature says of `protocol = "moos"`.
pub const MOOS_MISSING: &str = "this build has no MOOS link: build plumetrace with the `moos` feature (`cargo build --release -p plumetrace-cli --features moos`)";

/// `[link.moos]`: the MOOS community client's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MoosFile {
    /// The MOOSDB's host (`localhost`).
    #[serde(default = "default_moos_host")]
    pub host: String,
    /// The MOOSDB's port (1 to 65535; 9000).
    #[serde(default = "default_moos_port")]
    pub port: u16,
    /// The name the client connects as (a MOOS variable-like name, 1 to 64 characters;
    /// `pPlumetrace`).
    #[serde(default = "default_moos_app")]
    pub app_name: String,
    /// The variable carrying the chemical reading (a double, or a string holding a number);
    /// required unless `chemical.address` or `chemical.device` names a separate input.
    pub chem_variable: Option<String>,
}

fn default_moos_host() -> String {
    "localhost".into()
}
fn default_moos_port() -> u16 {
    9000
}
fn default_moos_app() -> String {
    "pPlumetrace".into()
}

impl Default for MoosFile {
    fn default() -> Self {
        MoosFile {
            host: default_moos_host(),
            port: default_moos_port(),
            app_name: default_moos_app(),
            chem_variable: None,
        }
    }
}

/// Whether `name` can be a MOOS variable or application name here: 1 to 64 printable ASCII
/// characters without spaces.
pub fn moos_name_ok(name: &str) -> bool {
    !name.is_empty() && name.len() <= 64 && name.bytes().all(|b| b.is_ascii_graphic())
}

/// What the link sends when the planner pauses (stale navigation, lost link).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SafeAction {
    /// The protocol's stop (`$BPRMB` stop, `$OMSTOP,0`).
    Stop,
    /// Nothing: the front seat's own timeout takes over.
    None,
}

/// `[link]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkFile {
    /// `bluefin`, `iver` or `moos`.
    pub protocol: ProtocolKind,
    /// Bluefin: the front seat's `host:port`.
    pub address: Option<String>,
    /// Iver: the serial device.
    pub device: Option<PathBuf>,
    /// Iver: baud rate (1200 to 921600).
    #[serde(default = "default_baud")]
    pub baud: u32,
    /// Iver: remote-helm major version (depth in feet below 5, metres from 5), 1 to 99.
    pub remote_helm_major: Option<u32>,
    /// The local frame's origin.
    pub origin: Origin,
    /// Navigation older than this pauses the planner, s (`(0, 600]`, 5).
    #[serde(default = "five")]
    pub stale_nav_s: f64,
    /// The link counts as lost after this long without a byte, s (`(0, 600]`, 10).
    #[serde(default = "ten")]
    pub silence_timeout_s: f64,
    /// What to send when the planner pauses.
    #[serde(default = "default_safe")]
    pub safe_command: SafeAction,
    /// Bluefin: resend an unacknowledged command after this long, s (`(0, 60]`, 5).
    #[serde(default = "five")]
    pub ack_timeout_s: f64,
    /// Bluefin: tries per command (1 to 10, 3).
    #[serde(default = "three")]
    pub ack_tries: u32,
    /// Bluefin: status keep-alive period, s (`(0, 60]`, 1).
    #[serde(default = "one")]
    pub status_period_s: f64,
    /// Iver: navigation poll period in real time, s (`(0, 60]`, 0.5).
    #[serde(default = "half")]
    pub poll_period_s: f64,
    /// Iver: the `$OMS` timeout field, s (1 to 60, 5).
    #[serde(default = "five_u")]
    pub oms_timeout_s: u32,
    /// First reconnection delay, s (`(0, 60]`, 0.1), doubled after each failure.
    #[serde(default = "tenth")]
    pub reconnect_min_s: f64,
    /// Longest reconnection delay, s (`[reconnect_min_s, 600]`, 5).
    #[serde(default = "five")]
    pub reconnect_max_s: f64,
    /// Give up (end the run) after the link has been down this long, s (`(0, 86400]`, 600).
    #[serde(default = "give_up")]
    pub give_up_s: f64,
    /// The vehicle's limits, checked at the chokepoint.
    #[serde(default)]
    pub limits: VehicleLimits,
    /// MOOS: the community client's settings (defaults when left out).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moos: Option<MoosFile>,
}

fn default_baud() -> u32 {
    19_200
}
fn five() -> f64 {
    5.0
}
fn ten() -> f64 {
    10.0
}
fn one() -> f64 {
    1.0
}
fn half() -> f64 {
    0.5
}
fn tenth() -> f64 {
    0.1
}
fn three() -> u32 {
    3
}
fn five_u() -> u32 {
    5
}
fn give_up() -> f64 {
    600.0
}
fn default_safe() -> SafeAction {
    SafeAction::Stop
}

/// The chemical line formats, as the onboard file names them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChemKind {
    /// One plain number per line.
    Plain,
    /// A sentence with a checksum: `id`, the reading in `field`.
    #[default]
    Sentence,
}

/// `[chemical]`: the sensor's line format and where its lines come from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChemicalFile {
    /// `sentence` (default) or `plain`.
    #[serde(default)]
    pub format: ChemKind,
    /// The sentence id (1 to 10 letters or digits; `PTCHM`).
    #[serde(default = "default_chem_id")]
    pub id: String,
    /// The reading's field, 1-based after the id (1 to 40; 2).
    #[serde(default = "default_chem_field")]
    pub field: usize,
    /// A separate TCP source (`host:port`); neither this nor `device`: the lines travel on the
    /// vehicle link.
    pub address: Option<String>,
    /// A separate serial device.
    pub device: Option<PathBuf>,
}

fn default_chem_id() -> String {
    "PTCHM".into()
}
fn default_chem_field() -> usize {
    2
}

impl Default for ChemicalFile {
    fn default() -> Self {
        ChemicalFile {
            format: ChemKind::default(),
            id: default_chem_id(),
            field: default_chem_field(),
            address: None,
            device: None,
        }
    }
}

impl ChemicalFile {
    /// The line format.
    pub fn line_format(&self) -> ChemFormat {
        match self.format {
            ChemKind::Plain => ChemFormat::Plain,
            ChemKind::Sentence => ChemFormat::Sentence {
                id: self.id.clone(),
                field: self.field,
            },
        }
    }
}

/// `[flow]`: a current meter (ADCP or DVL) writing NMEA 0183 `$--CUR` sentences (see
/// [`crate::protocol::current`]), and where its lines come from.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlowFile {
    /// Only this layer's readings (0 to 99; left out: every reading).
    pub layer: Option<u32>,
    /// A separate TCP source (`host:port`); neither this nor `device`: the lines travel on the
    /// vehicle link.
    pub address: Option<String>,
    /// A separate serial device.
    pub device: Option<PathBuf>,
}

impl FlowFile {
    /// The line format.
    pub fn line_format(&self) -> crate::protocol::current::FlowFormat {
        crate::protocol::current::FlowFormat { layer: self.layer }
    }
}

/// How time runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RunMode {
    /// Wall-clock time; decisions at the planner's period.
    RealTime,
    /// The front seat's time: one decision opportunity per navigation record, one command
    /// back for each (deterministic rehearsals and tests).
    LockStep,
}

/// `[run]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunFile {
    /// `real_time` or `lock_step`.
    #[serde(default = "default_mode")]
    pub mode: RunMode,
    /// Lock-step over a protocol without times (Iver): seconds per navigation record
    /// (`(0, 60]`, 0.5).
    #[serde(default = "half")]
    pub lock_step_period_s: f64,
    /// End the run after this much mission time, s (`(0, 1e6]`, 86400).
    #[serde(default = "day")]
    pub time_limit_s: f64,
}

fn default_mode() -> RunMode {
    RunMode::RealTime
}
fn day() -> f64 {
    86_400.0
}

impl Default for RunFile {
    fn default() -> Self {
        RunFile {
            mode: default_mode(),
            lock_step_period_s: 0.5,
            time_limit_s: day(),
        }
    }
}

/// The file checked and its planner read through the registry.
#[derive(Debug, Clone)]
pub struct Onboard {
    /// What was written.
    pub file: OnboardFile,
    /// The planner's configuration.
    pub planner: PlannerConfig,
    /// What the planner is built with.
    pub context: BuildContext,
    /// Planner keys the file gives that have no effect at its values, with why (the vehicle
    /// flies, and the operator is warned before it does).
    pub inert_keys: Vec<(&'static str, String)>,
}

fn err(key: &str, message: impl Into<String>) -> ParamError {
    ParamError {
        key: key.into(),
        message: message.into(),
    }
}

fn in_range(key: &str, v: f64, lo: f64, hi: f64, lo_open: bool) -> Result<(), ParamError> {
    let above = if lo_open { v > lo } else { v >= lo };
    if v.is_finite() && above && v <= hi {
        Ok(())
    } else {
        let open = if lo_open { "(" } else { "[" };
        Err(err(key, format!("{v} is outside {open}{lo}, {hi}]")))
    }
}

fn polygon(points: &[[f64; 2]], key: &str) -> Result<OpArea, ParamError> {
    OpArea::new(points.iter().map(|p| Vec2::new(p[0], p[1])).collect())
        .map_err(|e| err(key, e.to_string()))
}

impl Onboard {
    /// Reads and checks an onboard file's text; errors name the key path.
    pub fn from_toml(text: &str) -> Result<Self, ParamError> {
        let de = toml::Deserializer::parse(text).map_err(|e| err("", e.to_string()))?;
        let file: OnboardFile = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            // With a key path the message alone (the caller adds the key's line).
            let at_key = path != ".";
            err(
                if at_key { &path } else { "" },
                plumetrace_core::toml_message(e.inner(), at_key),
            )
        })?;
        Onboard::check(file)
    }

    /// Checks a parsed file.
    pub fn check(file: OnboardFile) -> Result<Self, ParamError> {
        let m = &file.mission;
        if let Some(d) = m.prior_flow_toward_deg {
            in_range("mission.prior_flow_toward_deg", d, -360.0, 360.0, false)?;
        }
        let geometry = MissionGeometry {
            op_area: polygon(&m.op_area, "mission.op_area")?,
            subregions: m
                .subregions
                .iter()
                .enumerate()
                .map(|(k, r)| polygon(r, &format!("mission.subregions[{k}]")))
                .collect::<Result<_, _>>()?,
            prior_flow_toward_deg: m.prior_flow_toward_deg.unwrap_or(0.0),
            prior_flow_given: m.prior_flow_toward_deg.is_some(),
        };
        let planner = PlannerConfig::from_table(&file.planner, "planner")?;
        let l = &file.link;
        match l.protocol {
            ProtocolKind::Bluefin if l.address.is_none() => {
                return Err(err(
                    "link.address",
                    "missing: the front seat's host:port (bluefin)",
                ));
            }
            ProtocolKind::Iver if l.device.is_none() => {
                return Err(err("link.device", "missing: the serial device (iver)"));
            }
            ProtocolKind::Iver if l.remote_helm_major.is_none() => {
                return Err(err(
                    "link.remote_helm_major",
                    "missing: the vehicle's remote-helm major version (it sets the depth unit: feet below 5, metres from 5)",
                ));
            }
            ProtocolKind::Moos => check_moos(&file)?,
            _ => {}
        }
        if l.protocol != ProtocolKind::Moos && l.moos.is_some() {
            return Err(err("link.moos", "only for protocol = \"moos\""));
        }
        if let Some(v) = l.remote_helm_major {
            in_range("link.remote_helm_major", f64::from(v), 1.0, 99.0, false)?;
        }
        crate::geo::LocalFrame::new(l.origin).map_err(|e| err("link.origin", e.to_string()))?;
        in_range("link.baud", f64::from(l.baud), 1200.0, 921_600.0, false)?;
        for (key, v, hi) in [
            ("link.stale_nav_s", l.stale_nav_s, 600.0),
            ("link.silence_timeout_s", l.silence_timeout_s, 600.0),
            ("link.ack_timeout_s", l.ack_timeout_s, 60.0),
            ("link.status_period_s", l.status_period_s, 60.0),
            ("link.poll_period_s", l.poll_period_s, 60.0),
            ("link.reconnect_min_s", l.reconnect_min_s, 60.0),
            ("link.give_up_s", l.give_up_s, 86_400.0),
            ("run.lock_step_period_s", file.run.lock_step_period_s, 60.0),
            ("run.time_limit_s", file.run.time_limit_s, 1e6),
        ] {
            in_range(key, v, 0.0, hi, true)?;
        }
        in_range(
            "link.reconnect_max_s",
            l.reconnect_max_s,
            l.reconnect_min_s,
            600.0,
            false,
        )?;
        in_range("link.ack_tries", f64::from(l.ack_tries), 1.0, 10.0, false)?;
        in_range(
            "link.oms_timeout_s",
            f64::from(l.oms_timeout_s),
            1.0,
            60.0,
            false,
        )?;
        l.limits
            .validate()
            .map_err(|e| err(&format!("link.limits.{}", e.key), e.to_string()))?;
        let c = &file.chemical;
        if c.address.is_some() && c.device.is_some() {
            return Err(err("chemical", "give address or device, not both"));
        }
        if let ChemFormat::Sentence { id, field } = &c.line_format() {
            if id.is_empty() || id.len() > 10 || !id.bytes().all(|b| b.is_ascii_alphanumeric()) {
                return Err(err(
                    "chemical.id",
                    format!("'{id}' is not 1 to 10 letters or digits"),
                ));
            }
            in_range("chemical.field", *field as f64, 1.0, 40.0, false)?;
        }
        if let Some(fl) = &file.flow {
            if fl.address.is_some() && fl.device.is_some() {
                return Err(err("flow", "give address or device, not both"));
            }
            if let Some(layer) = fl.layer {
                in_range("flow.layer", f64::from(layer), 0.0, 99.0, false)?;
            }
        }
        let context = BuildContext {
            geometry,
            vehicle: plumetrace_core::VehicleId(0),
            vehicle_kind: m.vehicle_kind,
            team: Vec::new(),
            mission_end_s: Some(file.run.time_limit_s),
        };
        check_planner(&planner, &context, &l.limits)?;
        let inert_keys = planner.keys_without_effect(&file.planner);
        Ok(Onboard {
            file,
            planner,
            context,
            inert_keys,
        })
    }
}

/// What would stop the planner flying once connected: a table the registry reads but cannot
/// build against this mission (no survey lane fits, say), or a speed above the vehicle's limit,
/// which the command chokepoint would refuse in every command.
fn check_planner(
    planner: &PlannerConfig,
    context: &BuildContext,
    limits: &VehicleLimits,
) -> Result<(), ParamError> {
    planner.build(context, "planner")?;
    let table = planner
        .to_table()
        .map_err(|e| err("planner", e.to_string()))?;
    for key in ["speed_mps", "max_speed_mps"] {
        if let Some(v) = table.get(key).and_then(toml::Value::as_float)
            && v > limits.max_speed_mps
        {
            return Err(err(
                &format!("planner.{key}"),
                format!(
                    "{v} m/s is above the vehicle's limit link.limits.max_speed_mps ({} m/s), \
                     so every command would be refused; lower it or raise the limit",
                    limits.max_speed_mps
                ),
            ));
        }
    }
    Ok(())
}

/// The MOOS link's keys.
fn check_moos(file: &OnboardFile) -> Result<(), ParamError> {
    let l = &file.link;
    if !cfg!(feature = "moos") {
        return Err(err("link.protocol", MOOS_MISSING));
    }
    if l.address.is_some() {
        return Err(err(
            "link.address",
            "not used by the moos link: give link.moos.host and link.moos.port",
        ));
    }
    if l.device.is_some() {
        return Err(err("link.device", "not used by the moos link"));
    }
    let m = l.moos.clone().unwrap_or_default();
    let h = &m.host;
    if h.is_empty() || h.len() > 253 || !h.bytes().all(|b| b.is_ascii_graphic()) {
        return Err(err(
            "link.moos.host",
            format!("'{h}' is not a host name or address"),
        ));
    }
    in_range("link.moos.port", f64::from(m.port), 1.0, 65_535.0, false)?;
    if !moos_name_ok(&m.app_name) {
        return Err(err(
            "link.moos.app_name",
            format!(
                "'{}' is not 1 to 64 printable characters without spaces",
                m.app_name
            ),
        ));
    }
    let c = &file.chemical;
    let separate = c.address.is_some() || c.device.is_some();
    match &m.chem_variable {
        Some(v) if !moos_name_ok(v) => Err(err(
            "link.moos.chem_variable",
            format!("'{v}' is not 1 to 64 printable characters without spaces"),
        )),
        Some(_) if separate => Err(err(
            "link.moos.chem_variable",
            "give the MOOS chemical variable or a separate chemical input (chemical.address, chemical.device), not both",
        )),
        None if !separate => Err(err(
            "link.moos.chem_variable",
            "missing: the MOOS variable carrying the chemical reading (or give chemical.address or chemical.device)",
        )),
        _ => Ok(()),
    }
}

impl plumetrace_log::snapshot::LoggablePlanner for Onboard {
    fn key(&self) -> &str {
        "planner"
    }
    fn config(&self) -> &PlannerConfig {
        &self.planner
    }
    fn context(&self) -> &BuildContext {
        &self.context
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
name = "t"
[mission]
op_area = [[60.0, -80.0], [460.0, -80.0], [460.0, 80.0], [60.0, 80.0]]
prior_flow_toward_deg = 90.0
[planner]
kind = "amp"
[link]
protocol = "bluefin"
address = "127.0.0.1:29500"
origin = { lat_deg = 36.18, lon_deg = -75.75 }
"#;

    #[test]
    fn a_good_file_reads_with_its_defaults() {
        let o = Onboard::from_toml(GOOD).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(o.file.link.stale_nav_s, 5.0);
        assert_eq!(o.file.run.mode, RunMode::RealTime);
        assert!(o.context.geometry.prior_flow_given);
        assert_eq!(o.file.chemical.line_format(), ChemFormat::default());
    }

    #[test]
    fn the_chemical_table_reads_both_formats() {
        let plain =
            format!("{GOOD}\n[chemical]\nformat = \"plain\"\naddress = \"127.0.0.1:4000\"\n");
        let o = Onboard::from_toml(&plain).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(o.file.chemical.line_format(), ChemFormat::Plain);
        assert_eq!(o.file.chemical.address.as_deref(), Some("127.0.0.1:4000"));
        let sentence =
            format!("{GOOD}\n[chemical]\nformat = \"sentence\"\nid = \"CHEM\"\nfield = 3\n");
        let o = Onboard::from_toml(&sentence).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            o.file.chemical.line_format(),
            ChemFormat::Sentence {
                id: "CHEM".into(),
                field: 3
            }
        );
        let bad = format!("{GOOD}\n[chemical]\nformat = \"sentence\"\nid = \"C H\"\nfield = 3\n");
        assert_eq!(
            Onboard::from_toml(&bad).err().map(|e| e.key),
            Some("chemical.id".into())
        );
        let unknown = format!("{GOOD}\n[chemical]\nformat = \"plain\"\nrate = 3\n");
        assert!(
            Onboard::from_toml(&unknown).is_err(),
            "unknown keys are refused"
        );
    }

    fn moos_file(link_moos: &str, chemical: &str) -> String {
        let link = "protocol = \"bluefin\"\naddress = \"127.0.0.1:29500\"";
        let text = GOOD.replacen(link, "protocol = \"moos\"", 1);
        format!("{text}{link_moos}{chemical}")
    }

    #[cfg(not(feature = "moos"))]
    #[test]
    fn without_the_feature_the_moos_link_says_how_to_build_it() {
        let text = moos_file("[link.moos]\nchem_variable = \"CHEM\"\n", "");
        let e = Onboard::from_toml(&text).err();
        assert_eq!(e.as_ref().map(|e| e.key.as_str()), Some("link.protocol"));
        assert!(
            e.is_some_and(|e| e.message.contains("--features moos")),
            "the error says how to build with it"
        );
    }

    #[cfg(feature = "moos")]
    #[test]
    fn the_moos_keys_have_defaults_and_bounds() {
        let text = moos_file("[link.moos]\nchem_variable = \"CHEM\"\n", "");
        let o = Onboard::from_toml(&text).unwrap_or_else(|e| panic!("{e}"));
        let m = o.file.link.moos.unwrap_or_default();
        assert_eq!((m.host.as_str(), m.port), ("localhost", 9000));
        assert_eq!(m.app_name, "pPlumetrace");
        let separate = moos_file("", "[chemical]\naddress = \"127.0.0.1:4000\"\n");
        assert!(Onboard::from_toml(&separate).is_ok());
        let cases = [
            (moos_file("", ""), "link.moos.chem_variable"),
            (
                moos_file(
                    "[link.moos]\nchem_variable = \"C\"\n",
                    "[chemical]\naddress = \"127.0.0.1:4000\"\n",
                ),
                "link.moos.chem_variable",
            ),
            (
                moos_file("[link.moos]\nchem_variable = \"A B\"\n", ""),
                "link.moos.chem_variable",
            ),
            (
                moos_file("[link.moos]\nchem_variable = \"C\"\nport = 0\n", ""),
                "link.moos.port",
            ),
            (
                moos_file("[link.moos]\nchem_variable = \"C\"\nport = 70000\n", ""),
                "link.moos.port",
            ),
            (
                moos_file("[link.moos]\nchem_variable = \"C\"\napp_name = \"\"\n", ""),
                "link.moos.app_name",
            ),
            (
                moos_file("[link.moos]\nchem_variable = \"C\"\nhost = \"a b\"\n", ""),
                "link.moos.host",
            ),
            (
                moos_file("[link.moos]\nchem_variable = \"C\"\nrate = 1\n", ""),
                "link.moos",
            ),
            (
                moos_file("[link.moos]\nchem_variable = \"C\"\n", "").replacen(
                    "protocol = \"moos\"",
                    "protocol = \"moos\"\naddress = \"h:1\"",
                    1,
                ),
                "link.address",
            ),
            (
                format!("{GOOD}[link.moos]\nchem_variable = \"C\"\n"),
                "link.moos",
            ),
        ];
        for (text, key) in cases {
            let e = Onboard::from_toml(&text).err();
            let got = e.as_ref().map(|e| e.key.clone());
            assert!(
                got.as_deref().is_some_and(|g| g.starts_with(key)),
                "{text}: {e:?}"
            );
        }
    }

    #[test]
    fn the_flow_table_is_optional_and_checked() {
        let o = Onboard::from_toml(GOOD).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            o.file.flow, None,
            "no current meter unless a [flow] table is given"
        );
        let on_link = format!("{GOOD}\n[flow]\n");
        let o = Onboard::from_toml(&on_link).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(o.file.flow, Some(FlowFile::default()));
        let own = format!("{GOOD}\n[flow]\nlayer = 3\naddress = \"127.0.0.1:4001\"\n");
        let o = Onboard::from_toml(&own).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(o.file.flow.as_ref().and_then(|f| f.layer), Some(3));
        for (bad, key) in [
            ("layer = 100", "flow.layer"),
            ("address = \"a:1\"\ndevice = \"/dev/ttyS1\"", "flow"),
            ("rate = 1", "flow"),
        ] {
            let text = format!("{GOOD}\n[flow]\n{bad}\n");
            let e = Onboard::from_toml(&text).err();
            assert!(
                e.as_ref().is_some_and(|e| e.key.starts_with(key)),
                "{bad}: {e:?}"
            );
        }
    }

    #[test]
    fn bad_files_name_the_key() {
        let cases = [
            ("protocol = \"bluefin\"", "protocl = \"bluefin\"", "link"),
            (
                "name = \"t\"",
                "name = \"t\"\n[run]\nmode = \"sideways\"",
                "run.mode",
            ),
            (
                "address = \"127.0.0.1:29500\"",
                "address = \"127.0.0.1:29500\"\nstale_nav_s = -1.0",
                "link.stale_nav_s",
            ),
            (
                "address = \"127.0.0.1:29500\"",
                "address = \"127.0.0.1:29500\"\nlimits = { max_speed_mps = nan }",
                "link.limits.max_speed_mps",
            ),
            (
                "kind = \"amp\"",
                "kind = \"amp\"\nbeta_deg = 1000.0",
                "planner.beta_deg",
            ),
            ("lat_deg = 36.18", "lat_deg = 95.0", "link.origin"),
            (
                "protocol = \"bluefin\"",
                "protocol = \"iver\"\ndevice = \"/dev/null\"",
                "link.remote_helm_major",
            ),
            // the file's checks passed these, and the flight then failed or sent nothing
            (
                "kind = \"amp\"",
                "kind = \"lawnmower\"\nedge_margin_m = 1000.0",
                "planner.edge_margin_m",
            ),
            (
                "kind = \"amp\"",
                "kind = \"amp\"\nspeed_mps = 10.0",
                "planner.speed_mps",
            ),
            (
                "[460.0, 80.0], [60.0, 80.0]]",
                "[460.0, 80.0, 3.0], [60.0, 80.0]]",
                "mission.op_area",
            ),
            (
                "prior_flow_toward_deg = 90.0",
                "prior_flow_toward_deg = 90.0\nsubregions = [[[60.0, -80.0], [460.0, -80.0], [460.0]]]",
                "mission.subregions",
            ),
        ];
        for (from, to, key) in cases {
            let text = GOOD.replacen(from, to, 1);
            assert_ne!(text, GOOD);
            let e = Onboard::from_toml(&text).err();
            let got = e.as_ref().map(|e| e.key.clone());
            assert!(
                got.as_deref().is_some_and(|g| g.starts_with(key)),
                "{to}: {e:?}"
            );
        }
    }
}
