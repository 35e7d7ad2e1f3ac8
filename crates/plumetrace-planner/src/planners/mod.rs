//! The planner registry: every planner plumetrace can fly, with its parameters, defaults, bounds,
//! validation and construction, in one place.
//!
//! A planner is configured by a table whose `kind` names it (`kind = "amp"`) and whose other keys
//! are its parameters plus the keys every planner takes ([`CommonParams`]). Each planner's
//! parameters are one [`params!`](plumetrace_core::params!) table in its own module; this module
//! lists the planners once ([`registry!`]-generated [`PlannerSpec`] and [`PLANNERS`]), and
//! everything else reads that list: `plumetrace check`, campaign `set` and `sweep` keys,
//! `plumetrace planners`, the README's planner table and the vehicle process.
//!
//! Adding a planner: write its module (parameters with [`PlannerParams`], the planner behind
//! [`plumetrace_core::Planner`]) and add one line to the `registry!` call below.
//!
//! What a planner needs of the mission besides its parameters ([`MissionGeometry`]: op-area,
//! subregions, prior flow direction) is an onboard type, so a process on a vehicle builds any
//! planner without the simulator.

pub mod amp;
pub mod formation;
pub mod infotaxis;
pub mod lawnmower;
pub mod moth;
pub mod surge_cast;

use plumetrace_core::params::{Bounds, KeyDoc, ParamError, Params, key_path, markdown_rows};
use plumetrace_core::{
    BehaviourKind, Decision, Heading, Planner, RuleDoc, SensorSnapshot, Vec2, VehicleId,
    VehicleKind,
};
use plumetrace_guidance::OpArea;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// The mission as a planner needs it: where it may go and what it searches.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MissionGeometry {
    /// The op-area (the cage keeps the vehicle in it).
    pub op_area: OpArea,
    /// Subregions searched in turn (empty: the whole op-area).
    pub subregions: Vec<OpArea>,
    /// Flow direction assumed until the first flow measurement, compass degrees (towards).
    pub prior_flow_toward_deg: f64,
    /// Whether that direction was given (the mission plan's), not assumed: planners may then
    /// judge the first flow readings against it.
    #[serde(default)]
    pub prior_flow_given: bool,
}

impl MissionGeometry {
    /// The prior flow direction.
    pub fn prior_flow_toward(&self) -> Heading {
        Heading::from_deg(self.prior_flow_toward_deg)
    }

    /// The op-area's vertices.
    pub fn op_area_vertices(&self) -> &[Vec2] {
        self.op_area.vertices()
    }
}

/// Everything a planner is built from besides its parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BuildContext {
    /// The mission geometry.
    pub geometry: MissionGeometry,
    /// The vehicle the planner flies.
    pub vehicle: VehicleId,
    /// Its kind.
    pub vehicle_kind: VehicleKind,
    /// The names of the mission's vehicles, by index (empty where the planner flies alone, as on
    /// a vehicle link): planners that name other vehicles check them against it. Not written to
    /// snapshot logs (a replay builds without the check).
    #[serde(skip)]
    pub team: Vec<String>,
    /// When the mission ends, s of mission time (the scenario's `mission.time_limit_s`; on a
    /// vehicle link, `run.time_limit_s`), so that a planner holding a declaration makes it
    /// before then; `None`: no end is known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mission_end_s: Option<f64>,
}

/// The parameters of one planner, and how to make the planner from them.
pub trait PlannerParams:
    Params + Serialize + DeserializeOwned + Clone + std::fmt::Debug + PartialEq + Send + Sync + 'static
{
    /// The `kind` that selects it.
    const KIND: &'static str;
    /// One line saying what it is.
    const SUMMARY: &'static str;
    /// It needs a position estimate (vehicles without one cannot fly it).
    const NEEDS_POSITION: bool = true;
    /// The key of its detection threshold, if it thresholds chemical readings (an older
    /// scenario's `[vehicles.chem_sensor] threshold_v` is passed to it).
    const THRESHOLD_KEY: Option<&'static str> = None;
    /// The behaviours it reports (of the shared vocabulary), in the order it flies them.
    const BEHAVIOURS: &'static [BehaviourKind];
    /// The declaration rules it reports, with what each means.
    const RULES: &'static [RuleDoc];

    /// Checks every value (bounds, and rules across keys); errors name `prefix.key`.
    fn validate(&self, prefix: &str) -> Result<(), ParamError> {
        self.check_bounds(prefix)
    }

    /// The reading above which a chemical sample is a detection, if the planner thresholds.
    fn detection_threshold_v(&self) -> Option<f64>;

    /// Keys that have no effect at these values, each with why: `check` and `run` warn of those
    /// a planner table gives ([`PlannerConfig::keys_without_effect`]).
    fn without_effect(&self) -> Vec<(&'static str, String)> {
        Vec::new()
    }

    /// The planner; errors name keys of the planner's table (without a prefix).
    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Planner>, ParamError>;
}

plumetrace_core::params! {
    /// Keys every planner takes, besides `kind`.
    pub struct CommonParams {
        /// Time between decisions; 0 decides at every simulation step (the field planner decided at the sensor's 10 Hz).
        decision_period_s: f64 = 0.0, "s", Bounds::non_negative(3600.0);
        /// Fly around obstacles seen by the range sensors: the fuzzy following-obstacle layer with dynamic reference targets takes over from the planner until the obstacle is passed.
        avoid_obstacles: bool = false, "", Bounds::Any;
        /// With avoid_obstacles, a front range return closer than this starts avoidance (a side return closer than 5 m does too).
        avoid_trigger_m: f64 = 10.0, "m", Bounds::closed(1.0, 1000.0);
    }
}

/// One planner of the registry, for lists and docs.
#[derive(Debug, Clone, Copy)]
pub struct PlannerEntry {
    /// Its kind.
    pub kind: PlannerKind,
    /// One line saying what it is.
    pub summary: &'static str,
    /// Its keys (without the common ones).
    pub keys: fn() -> Vec<KeyDoc>,
    /// It needs a position estimate.
    pub needs_position: bool,
    /// The key of its detection threshold, if it has one.
    pub threshold_key: Option<&'static str>,
    /// The behaviours it reports.
    pub behaviours: &'static [BehaviourKind],
    /// The declaration rules it reports.
    pub rules: &'static [RuleDoc],
}

/// Reads a parameter set from a table; errors name `prefix.key` (unknown keys, wrong types,
/// values out of bounds).
fn parse_params<T: PlannerParamsLike>(table: toml::Table, prefix: &str) -> Result<T, ParamError> {
    let parsed = T::read(table, prefix)?;
    parsed.validate_like(prefix)?;
    Ok(parsed)
}

/// What [`parse_params`] needs: the common keys and every planner's parameters.
trait PlannerParamsLike: Params {
    fn validate_like(&self, prefix: &str) -> Result<(), ParamError>;
}

impl<T: PlannerParams> PlannerParamsLike for T {
    fn validate_like(&self, prefix: &str) -> Result<(), ParamError> {
        self.validate(prefix)
    }
}

impl PlannerParamsLike for CommonParams {
    fn validate_like(&self, prefix: &str) -> Result<(), ParamError> {
        self.check_bounds(prefix)
    }
}

/// Declares the registry: the [`PlannerSpec`] enum with one variant per planner, its dispatch,
/// and [`PLANNERS`].
macro_rules! registry {
    ($($variant:ident($ty:ty)),* $(,)?) => {
        /// Which planner: written in files as its `kind` name.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum PlannerKind {
            $(
                #[doc = concat!("See [`", stringify!($ty), "`].")]
                $variant,
            )*
        }

        impl PlannerKind {
            /// Every planner, in registry order.
            pub const ALL: &'static [PlannerKind] = &[$(PlannerKind::$variant,)*];

            /// The `kind` name in files.
            pub fn name(self) -> &'static str {
                match self {
                    $(PlannerKind::$variant => <$ty as PlannerParams>::KIND,)*
                }
            }

            /// The kind called `name`.
            pub fn from_name(name: &str) -> Option<Self> {
                Self::ALL.iter().copied().find(|k| k.name() == name)
            }
        }

        /// The parameters of one planner, by kind.
        // Configuration, built once per vehicle: the size of the largest planner's table is fine.
        #[allow(clippy::large_enum_variant)]
        #[derive(Debug, Clone, PartialEq)]
        pub enum PlannerSpec {
            $(
                #[doc = concat!("See [`", stringify!($ty), "`].")]
                $variant($ty),
            )*
        }

        /// Every planner, in registry order.
        pub const PLANNERS: &[PlannerEntry] = &[$(
            PlannerEntry {
                kind: PlannerKind::$variant,
                summary: <$ty as PlannerParams>::SUMMARY,
                keys: <$ty as Params>::keys,
                needs_position: <$ty as PlannerParams>::NEEDS_POSITION,
                threshold_key: <$ty as PlannerParams>::THRESHOLD_KEY,
                behaviours: <$ty as PlannerParams>::BEHAVIOURS,
                rules: <$ty as PlannerParams>::RULES,
            },
        )*];

        impl PlannerSpec {
            fn parse(kind: PlannerKind, table: toml::Table, prefix: &str) -> Result<Self, ParamError> {
                match kind {
                    $(PlannerKind::$variant => parse_params::<$ty>(table, prefix).map(PlannerSpec::$variant),)*
                }
            }

            /// The planner's kind.
            pub fn kind(&self) -> PlannerKind {
                match self {
                    $(PlannerSpec::$variant(_) => PlannerKind::$variant,)*
                }
            }

            /// The detection threshold, if the planner thresholds readings.
            pub fn detection_threshold_v(&self) -> Option<f64> {
                match self {
                    $(PlannerSpec::$variant(p) => p.detection_threshold_v(),)*
                }
            }

            fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Planner>, ParamError> {
                match self {
                    $(PlannerSpec::$variant(p) => p.build(ctx),)*
                }
            }

            fn without_effect(&self) -> Vec<(&'static str, String)> {
                match self {
                    $(PlannerSpec::$variant(p) => p.without_effect(),)*
                }
            }

            fn to_table(&self) -> Result<toml::Table, toml::ser::Error> {
                match self {
                    $(PlannerSpec::$variant(p) => toml::Table::try_from(p),)*
                }
            }
        }
    };
}

registry! {
    Amp(amp::AmpParams),
    Infotaxis(infotaxis::InfotaxisParams),
    Lawnmower(lawnmower::LawnmowerParams),
    Moth(moth::MothParams),
    FormationLeader(formation::FormationLeaderParams),
    FormationFollower(formation::FormationFollowerParams),
    SurgeCast(surge_cast::SurgeCastParams),
}

impl std::fmt::Display for PlannerKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for PlannerKind {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for PlannerKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        PlannerKind::from_name(&name)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown planner '{name}'")))
    }
}

/// The registry entry of a kind.
pub fn entry(kind: PlannerKind) -> &'static PlannerEntry {
    PLANNERS
        .iter()
        .find(|p| p.kind == kind)
        .unwrap_or(&PLANNERS[0])
}

/// The kind a planner table names (`kind`, or the older `strategy`), if it names one by a string.
pub fn kind_name(table: &toml::Table) -> Option<&str> {
    table
        .get("kind")
        .or_else(|| table.get("strategy"))
        .and_then(toml::Value::as_str)
}

/// The kinds as `"amp", "lawnmower"` for messages.
fn kinds() -> String {
    PlannerKind::ALL
        .iter()
        .map(|k| format!("\"{}\"", k.name()))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A planner's whole configuration: its kind and parameters, and the common keys.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannerConfig {
    /// Kind and parameters.
    pub spec: PlannerSpec,
    /// Keys every planner takes.
    pub common: CommonParams,
}

impl PlannerConfig {
    /// Reads a planner table (`kind`, or its older name `strategy`, plus keys); errors name
    /// `prefix.key`, the kind's key as written.
    pub fn from_table(table: &toml::Table, prefix: &str) -> Result<Self, ParamError> {
        let mut t = table.clone();
        let (name, value) = match (t.remove("kind"), t.remove("strategy")) {
            (Some(_), Some(_)) => {
                return Err(ParamError::at(
                    prefix,
                    "strategy",
                    "give `kind` (or the older `strategy`), not both",
                ));
            }
            (Some(v), None) => ("kind", v),
            (None, Some(v)) => ("strategy", v),
            (None, None) => {
                return Err(ParamError::at(
                    prefix,
                    "kind",
                    format!("missing: name the planner, one of {}", kinds()),
                ));
            }
        };
        let kind = match value {
            toml::Value::String(s) => PlannerKind::from_name(&s).ok_or_else(|| {
                let names: Vec<&str> = PlannerKind::ALL.iter().map(|k| k.name()).collect();
                let hint = plumetrace_core::closest(&s, &names)
                    .map(|n| format!("; did you mean '{n}'?"))
                    .unwrap_or_default();
                ParamError::at(
                    prefix,
                    name,
                    format!("unknown planner '{s}'{hint} (known: {})", kinds()),
                )
            })?,
            other => {
                return Err(ParamError::at(
                    prefix,
                    name,
                    format!("must be a string, one of {}; got {other}", kinds()),
                ));
            }
        };
        let mut common = toml::Table::new();
        for k in CommonParams::keys() {
            if let Some(v) = t.remove(k.name) {
                common.insert(k.name.to_string(), v);
            }
        }
        Ok(PlannerConfig {
            common: parse_params(common, prefix)?,
            spec: PlannerSpec::parse(kind, t, prefix)?,
        })
    }

    /// The configuration as a table (every key, defaults included): what
    /// [`PlannerConfig::from_table`] reads back to an equal configuration.
    pub fn to_table(&self) -> Result<toml::Table, toml::ser::Error> {
        let mut t = toml::Table::new();
        t.insert(
            "kind".into(),
            toml::Value::String(self.kind().name().into()),
        );
        t.extend(toml::Table::try_from(&self.common)?);
        t.extend(self.spec.to_table()?);
        Ok(t)
    }

    /// The planner's kind.
    pub fn kind(&self) -> PlannerKind {
        self.spec.kind()
    }

    /// The detection threshold, if the planner thresholds readings.
    pub fn detection_threshold_v(&self) -> Option<f64> {
        self.spec.detection_threshold_v()
    }

    /// The keys `table` (the table this configuration was read from) gives that have no effect
    /// at the configuration's values, each with why.
    pub fn keys_without_effect(&self, table: &toml::Table) -> Vec<(&'static str, String)> {
        self.spec
            .without_effect()
            .into_iter()
            .filter(|(key, _)| table.contains_key(*key))
            .collect()
    }

    /// It needs a position estimate.
    pub fn needs_position(&self) -> bool {
        entry(self.kind()).needs_position
    }

    /// The planner, ready to fly; errors name `prefix.key` (`prefix`: the key path the table was
    /// read from).
    pub fn build(&self, ctx: &BuildContext, prefix: &str) -> Result<Box<dyn Planner>, ParamError> {
        let inner = self.spec.build(ctx).map_err(|e| ParamError {
            key: key_path(prefix, &e.key),
            message: e.message,
        })?;
        let inner: Box<dyn Planner> = if self.common.avoid_obstacles {
            Box::new(crate::avoid::AvoidObstacles::new(
                inner,
                crate::avoid::AvoidParams {
                    trigger_m: self.common.avoid_trigger_m,
                    ..crate::avoid::AvoidParams::default()
                },
            ))
        } else {
            inner
        };
        let period = self.common.decision_period_s;
        Ok(if period > 0.0 {
            Box::new(Periodic {
                inner,
                period_s: period,
            })
        } else {
            inner
        })
    }
}

/// A planner that decides every `period_s`.
struct Periodic {
    inner: Box<dyn Planner>,
    period_s: f64,
}

impl Planner for Periodic {
    fn decide(&mut self, snapshot: &SensorSnapshot) -> Decision {
        self.inner.decide(snapshot)
    }

    fn decision_period_s(&self) -> f64 {
        self.period_s
    }

    fn detour_ended(&mut self, pos_m: Vec2) {
        self.inner.detour_ended(pos_m);
    }

    fn run_ended(&mut self, t_s: f64) -> Vec<plumetrace_core::PlannerEvent> {
        self.inner.run_ended(t_s)
    }
}

/// Every planner's parameters at their defaults, by kind name (campaigns digest it, so results
/// recorded under other defaults are never resumed or merged with new ones).
pub fn registry_defaults() -> toml::Table {
    let mut out = toml::Table::new();
    for kind in PlannerKind::ALL {
        let mut t = toml::Table::new();
        t.insert("kind".into(), toml::Value::String(kind.name().into()));
        let resolved = PlannerConfig::from_table(&t, "planner")
            .map_err(|e| e.to_string())
            .and_then(|c| c.to_table().map_err(|e| e.to_string()));
        let value = match resolved {
            Ok(t) => toml::Value::Table(t),
            Err(e) => toml::Value::String(e),
        };
        out.insert(kind.name().into(), value);
    }
    out
}

/// A planner's behaviours and declaration rules as Markdown lines (after its key table).
fn behaviours_and_rules(p: &PlannerEntry) -> String {
    let names: Vec<String> = p
        .behaviours
        .iter()
        .map(|b| format!("`{}`", plumetrace_core::variant_name(b).unwrap_or("?")))
        .collect();
    let mut out = String::new();
    if !names.is_empty() {
        let _ = write!(out, "\nBehaviours: {}.\n", names.join(", "));
    }
    if !p.rules.is_empty() {
        out.push_str("\nDeclaration rules:\n");
        for r in p.rules {
            let _ = writeln!(out, "- `{}`: {}", r.rule, r.doc);
        }
    }
    out
}

/// Every planner with its keys as Markdown (the README's planner section is this text).
pub fn registry_markdown() -> String {
    let mut out = String::new();
    out.push_str(
        "Every planner table takes `kind` (which planner) and these keys:\n\n\
         | key | type | default | unit | bounds | what it is |\n| --- | --- | --- | --- | --- | --- |\n",
    );
    out.push_str(&markdown_rows(&CommonParams::keys()));
    for p in PLANNERS {
        let _ = write!(
            out,
            "\n### `kind = \"{}\"`\n\n{}.\n\n| key | type | default | unit | bounds | what it is |\n| --- | --- | --- | --- | --- | --- |\n",
            p.kind.name(),
            p.summary
        );
        out.push_str(&markdown_rows(&(p.keys)()));
        out.push_str(&behaviours_and_rules(p));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> toml::Table {
        text.parse().unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn the_registry_defaults_hold_every_planner_with_every_key() {
        let d = registry_defaults();
        for p in PLANNERS {
            let t = d[p.kind.name()]
                .as_table()
                .unwrap_or_else(|| panic!("{}: {:?}", p.kind, d[p.kind.name()]));
            for k in (p.keys)() {
                assert!(t.contains_key(k.name), "{}: {}", p.kind, k.name);
            }
        }
        assert_eq!(d["amp"]["lambda_s"].as_float(), Some(5.0));
    }

    #[test]
    fn a_table_becomes_a_config_and_back() {
        let c = PlannerConfig::from_table(
            &table("kind = \"amp\"\nbeta_deg = 30.0\ndecision_period_s = 0.5\nlost_point_eviction = \"most_downflow\""),
            "planners.tracer",
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(c.kind(), PlannerKind::Amp);
        assert_eq!(c.common.decision_period_s, 0.5);
        let t = c.to_table().unwrap_or_default();
        assert_eq!(t["beta_deg"].as_float(), Some(30.0));
        assert_eq!(t["lost_point_eviction"].as_str(), Some("most_downflow"));
        assert_eq!(
            t["lambda_s"].as_float(),
            Some(5.0),
            "omitted keys take their default"
        );
        let back = PlannerConfig::from_table(&t, "x").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(back, c);
    }

    #[test]
    fn every_planner_reads_its_defaults_and_writes_them_back() {
        for p in PLANNERS {
            let mut t = toml::Table::new();
            t.insert("kind".into(), toml::Value::String(p.kind.name().into()));
            // The defaults pass their own bounds (a bound of the wrong type would not).
            let c = PlannerConfig::from_table(&t, "p").unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(c.kind(), p.kind);
            let full = c.to_table().unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(
                full.len(),
                1 + CommonParams::keys().len() + (p.keys)().len(),
                "kind, common and own keys"
            );
            let back = PlannerConfig::from_table(&full, "p").unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(back, c);
            let text = toml::to_string(&full).unwrap_or_default();
            let reread: toml::Table = text.parse().unwrap_or_default();
            assert_eq!(
                reread, full,
                "{}: the TOML text reads back the same",
                p.kind
            );
            assert_eq!(PlannerKind::from_name(p.kind.name()), Some(p.kind));
        }
    }

    #[test]
    fn bad_tables_name_the_key() {
        let cases = [
            ("beta_deg = 3.0", "planners.a.kind", "missing"),
            (
                "kind = \"butterfly\"",
                "planners.a.kind",
                "unknown planner 'butterfly'",
            ),
            ("kind = 3", "planners.a.kind", "must be a string"),
            // The older name of `kind` is read too, and errors name the key as written.
            (
                "strategy = \"ampp\"",
                "planners.a.strategy",
                "unknown planner 'ampp'; did you mean 'amp'? (known: ",
            ),
            (
                "strategy = \"amp\"\nkind = \"amp\"",
                "planners.a.strategy",
                "give `kind` (or the older `strategy`), not both",
            ),
            (
                "strategy = \"amp\"\nmaping_lines = 3",
                "planners.a.maping_lines",
                "unknown field `maping_lines`; did you mean `mapping_lines`? (`plumetrace planners` lists every key)",
            ),
            (
                "kind = \"amp\"\nbeta = 3.0",
                "planners.a.beta",
                "unknown field `beta`",
            ),
            (
                "kind = \"amp\"\nbeta_deg = \"x\"",
                "planners.a.beta_deg",
                "invalid type",
            ),
            (
                "kind = \"amp\"\nbeta_deg = 95.0",
                "planners.a.beta_deg",
                "<= 90",
            ),
            ("kind = \"amp\"\nn_re = 0", "planners.a.n_re", "1..=50"),
            (
                "kind = \"amp\"\ndecision_period_s = -1.0",
                "planners.a.decision_period_s",
                ">= 0",
            ),
            (
                "kind = \"amp\"\ndeclaration = \"nearest\"",
                "planners.a.declaration",
                "unknown variant",
            ),
        ];
        for (text, key, message) in cases {
            let e = PlannerConfig::from_table(&table(text), "planners.a")
                .err()
                .unwrap_or_else(|| panic!("accepted: {text}"));
            assert_eq!(e.key, key, "{text}: {e}");
            assert!(e.message.contains(message), "{text}: {e}");
        }
    }

    #[test]
    fn the_markdown_lists_every_planner_and_key() {
        let md = registry_markdown();
        for p in PLANNERS {
            assert!(md.contains(&format!("`kind = \"{}\"`", p.kind.name())));
            for k in (p.keys)() {
                assert!(md.contains(&format!("| `{}` |", k.name)), "{}", k.name);
            }
        }
        assert!(md.contains("| `decision_period_s` |"));
    }
}
