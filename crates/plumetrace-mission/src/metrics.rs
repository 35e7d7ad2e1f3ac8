//! The run metrics: every number a run is judged by, declared once in [`RunMetrics`] (name, type,
//! unit, meaning and how it is read from the mission's [`Summary`]). A campaign's `runs.csv`,
//! `runs.parquet` and tables, and the Python bindings, read their columns from it: adding a metric
//! is one entry there.
//!
//! The table is made by [`columns!`](crate::columns): a struct of columns, each a single value
//! ([`Leaf`]: text, a whole number, a flag or an optional number) or a group of columns made the
//! same way, whose columns it lists in order. Every such struct lists its columns with their kind
//! ([`columns_of`]) and values ([`values_of`]), and is written and read by serde as one flat
//! record (a group's columns take its place), which is how `runs.csv` is written.

use crate::summary::{DeclarationRecord, Summary};
use crate::team::TeamSummary;
use serde::de::{DeserializeOwned, MapAccess};
use serde::ser::SerializeStruct;
use serde::{Deserialize, Serialize};

/// What a column holds: its type in `runs.csv` and `runs.parquet`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ColumnKind {
    /// Text (UTF-8).
    Text,
    /// An unsigned 64-bit whole number.
    U64,
    /// An unsigned 32-bit count.
    U32,
    /// A yes/no.
    Bool,
    /// An optional yes/no (empty or null when missing).
    OptBool,
    /// An optional number (empty or null when missing).
    OptF64,
    /// An optional unsigned 64-bit whole number (empty when missing; a number in Parquet).
    OptU64,
}

impl ColumnKind {
    /// The name in listings (serde's).
    pub fn name(self) -> &'static str {
        plumetrace_core::variant_name(&self).unwrap_or("?")
    }
}

/// One column of a table: its name in files, what it holds, its unit and meaning.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Column {
    /// The name in files (the field's name).
    pub name: &'static str,
    /// What it holds.
    pub kind: ColumnKind,
    /// Its unit (`m`, `s`, ...; empty for counts, flags, text and ratios).
    pub unit: &'static str,
    /// What it means (the field's documentation).
    pub doc: &'static str,
}

impl Column {
    /// The documentation as one line.
    pub fn description(&self) -> String {
        self.doc.split_whitespace().collect::<Vec<_>>().join(" ")
    }
}

/// One value of a column, borrowed from its row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value<'a> {
    /// [`ColumnKind::Text`].
    Text(&'a str),
    /// [`ColumnKind::U64`].
    U64(u64),
    /// [`ColumnKind::U32`].
    U32(u32),
    /// [`ColumnKind::Bool`].
    Bool(bool),
    /// [`ColumnKind::OptBool`].
    OptBool(Option<bool>),
    /// [`ColumnKind::OptF64`].
    OptF64(Option<f64>),
    /// [`ColumnKind::OptU64`].
    OptU64(Option<u64>),
}

/// The type of a single column's values.
pub trait Leaf: Serialize + DeserializeOwned + Default {
    /// What the column holds.
    const KIND: ColumnKind;
    /// The value.
    fn value(&self) -> Value<'_>;
}

macro_rules! leaf {
    ($($ty:ty => $kind:ident, |$v:ident| $value:expr;)*) => {
        $(impl Leaf for $ty {
            const KIND: ColumnKind = ColumnKind::$kind;
            fn value(&self) -> Value<'_> {
                let $v = self;
                Value::$kind($value)
            }
        })*
    };
}

leaf! {
    String => Text, |v| v;
    u64 => U64, |v| *v;
    u32 => U32, |v| *v;
    bool => Bool, |v| *v;
    Option<bool> => OptBool, |v| *v;
    Option<f64> => OptF64, |v| *v;
    Option<u64> => OptU64, |v| *v;
}

/// A part of a row: a single column ([`Leaf`]) or a group of columns ([`columns!`](crate::columns)).
pub trait Columns: Default {
    /// How many columns.
    const WIDTH: usize;

    /// Appends the part's columns; a single value is the column `name` with `unit` and `doc`
    /// (a group lists its own).
    fn columns(name: &'static str, unit: &'static str, doc: &'static str, out: &mut Vec<Column>);

    /// Appends the part's values, in column order.
    fn values<'a>(&'a self, out: &mut Vec<Value<'a>>);

    /// Writes the part's fields into a flat record (a single value as the field `name`).
    fn serialize_fields<S: SerializeStruct>(
        &self,
        name: &'static str,
        record: &mut S,
    ) -> Result<(), S::Error>;

    /// Reads the value of the field `key` of a flat record if it is one of this part's (a single
    /// value is the field `name`); false when it is not.
    fn deserialize_field<'de, A: MapAccess<'de>>(
        &mut self,
        name: &'static str,
        key: &str,
        map: &mut A,
    ) -> Result<bool, A::Error>;
}

impl<T: Leaf> Columns for T {
    const WIDTH: usize = 1;

    fn columns(name: &'static str, unit: &'static str, doc: &'static str, out: &mut Vec<Column>) {
        out.push(Column {
            name,
            kind: T::KIND,
            unit,
            doc,
        });
    }

    fn values<'a>(&'a self, out: &mut Vec<Value<'a>>) {
        out.push(self.value());
    }

    fn serialize_fields<S: SerializeStruct>(
        &self,
        name: &'static str,
        record: &mut S,
    ) -> Result<(), S::Error> {
        record.serialize_field(name, self)
    }

    fn deserialize_field<'de, A: MapAccess<'de>>(
        &mut self,
        name: &'static str,
        key: &str,
        map: &mut A,
    ) -> Result<bool, A::Error> {
        if key != name {
            return Ok(false);
        }
        *self = map.next_value()?;
        Ok(true)
    }
}

/// Every column of a table, in order.
pub fn columns_of<T: Columns>() -> Vec<Column> {
    let mut out = Vec::with_capacity(T::WIDTH);
    T::columns("", "", "", &mut out);
    out
}

/// A row's values, in column order.
pub fn values_of<T: Columns>(row: &T) -> Vec<Value<'_>> {
    let mut out = Vec::with_capacity(T::WIDTH);
    row.values(&mut out);
    out
}

/// A table of columns: a struct whose fields are columns ([`Leaf`] values) or groups of columns
/// (structs made by this macro), each with its documentation and, optionally, its unit in
/// brackets. With `from (args)`, every field also says how it is made from the arguments, and
/// the struct gets `new(args)`.
///
/// ```ignore
/// plumetrace_mission::columns! {
///     /// A run's place.
///     pub struct Place from (x: f64) {
///         /// Position, m.
///         x_m: Option<f64> ["m"] = Some(x);
///         /// What it is.
///         label: String = String::new();
///     }
/// }
/// ```
///
/// The struct derives `Debug`, `Clone`, `Default` and `PartialEq`, and implements [`Columns`]
/// and serde's `Serialize` and `Deserialize` as one flat record of its columns.
#[macro_export]
macro_rules! columns {
    (
        $(#[$attr:meta])*
        $vis:vis struct $name:ident from ($($arg:ident : $argty:ty),* $(,)?) {
            $(
                $(#[doc = $doc:literal])+
                $field:ident : $ty:ty $([$unit:literal])? = $make:expr;
            )*
        }
    ) => {
        $crate::columns! {
            $(#[$attr])*
            $vis struct $name {
                $($(#[doc = $doc])+ $field : $ty $([$unit])?;)*
            }
        }

        impl $name {
            /// Every column made from the arguments.
            pub fn new($($arg: $argty),*) -> Self {
                $name { $($field: $make,)* }
            }
        }
    };
    (
        $(#[$attr:meta])*
        $vis:vis struct $name:ident {
            $(
                $(#[doc = $doc:literal])+
                $field:ident : $ty:ty $([$unit:literal])?;
            )*
        }
    ) => {
        $(#[$attr])*
        #[derive(Debug, Clone, Default, PartialEq)]
        $vis struct $name {
            $($(#[doc = $doc])+ pub $field: $ty,)*
        }

        impl $crate::metrics::Columns for $name {
            const WIDTH: usize = 0 $(+ <$ty as $crate::metrics::Columns>::WIDTH)*;

            fn columns(
                _name: &'static str,
                _unit: &'static str,
                _doc: &'static str,
                out: &mut ::std::vec::Vec<$crate::metrics::Column>,
            ) {
                $(<$ty as $crate::metrics::Columns>::columns(
                    stringify!($field),
                    concat!("" $(, $unit)?),
                    concat!($($doc),+),
                    out,
                );)*
            }

            fn values<'a>(&'a self, out: &mut ::std::vec::Vec<$crate::metrics::Value<'a>>) {
                $($crate::metrics::Columns::values(&self.$field, out);)*
            }

            fn serialize_fields<S: $crate::__serde::ser::SerializeStruct>(
                &self,
                _name: &'static str,
                record: &mut S,
            ) -> ::std::result::Result<(), S::Error> {
                $($crate::metrics::Columns::serialize_fields(
                    &self.$field,
                    stringify!($field),
                    record,
                )?;)*
                Ok(())
            }

            fn deserialize_field<'de, A: $crate::__serde::de::MapAccess<'de>>(
                &mut self,
                _name: &'static str,
                key: &str,
                map: &mut A,
            ) -> ::std::result::Result<bool, A::Error> {
                $(if $crate::metrics::Columns::deserialize_field(
                    &mut self.$field,
                    stringify!($field),
                    key,
                    map,
                )? {
                    return Ok(true);
                })*
                Ok(false)
            }
        }

        impl $crate::__serde::Serialize for $name {
            fn serialize<S: $crate::__serde::Serializer>(
                &self,
                serializer: S,
            ) -> ::std::result::Result<S::Ok, S::Error> {
                use $crate::__serde::ser::SerializeStruct as _;
                let mut record = serializer.serialize_struct(
                    stringify!($name),
                    <Self as $crate::metrics::Columns>::WIDTH,
                )?;
                $crate::metrics::Columns::serialize_fields(self, "", &mut record)?;
                record.end()
            }
        }

        impl<'de> $crate::__serde::Deserialize<'de> for $name {
            fn deserialize<D: $crate::__serde::Deserializer<'de>>(
                deserializer: D,
            ) -> ::std::result::Result<Self, D::Error> {
                struct Record;
                impl<'de> $crate::__serde::de::Visitor<'de> for Record {
                    type Value = $name;
                    fn expecting(
                        &self,
                        f: &mut ::std::fmt::Formatter<'_>,
                    ) -> ::std::fmt::Result {
                        f.write_str(concat!("a record of ", stringify!($name)))
                    }
                    fn visit_map<A: $crate::__serde::de::MapAccess<'de>>(
                        self,
                        mut map: A,
                    ) -> ::std::result::Result<$name, A::Error> {
                        let mut row = <$name as ::std::default::Default>::default();
                        while let Some(key) = map.next_key::<::std::string::String>()? {
                            if !$crate::metrics::Columns::deserialize_field(
                                &mut row, "", &key, &mut map,
                            )? {
                                map.next_value::<$crate::__serde::de::IgnoredAny>()?;
                            }
                        }
                        Ok(row)
                    }
                }
                deserializer.deserialize_struct(stringify!($name), &[], Record)
            }
        }
    };
}

/// What a run is judged against besides its summary.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MetricContext {
    /// A success radius that replaces the mission's own (its scenario's
    /// `mission.success_radius_m`, in [`Summary::success_radius_m`]), m: a campaign's
    /// `success_radius_m`.
    pub success_radius_m: Option<f64>,
}

impl MetricContext {
    /// Within this distance of a declaration a source of this run counts as located: the
    /// context's success radius, or the mission's own without one.
    pub fn located_radius_m(&self, s: &Summary) -> f64 {
        self.success_radius_m.unwrap_or(s.success_radius_m)
    }
}

crate::columns! {
    /// A run's metrics: one field per column of a campaign's `runs.csv` after its keys and
    /// outcome. Missing numbers (no declaration, no detection, no team) are `None`.
    pub struct RunMetrics from (s: &Summary, cx: &MetricContext) {
        /// Single source: the first declaration lies within the success radius (the campaign's,
        /// or the scenario's `mission.success_radius_m`). Several sources, or subregions
        /// searched in turn: every source located (`sources_located == sources`).
        success: bool = s.success_within(cx.located_radius_m(s));
        /// Declared at all.
        declared: bool = s.declared;
        /// Number of declarations (several on multi-source missions).
        declarations: u32 = count(s.declarations.len());
        /// Number of true sources.
        sources: u32 = count(s.sources.len());
        /// Sources with a declaration within the success radius.
        sources_located: u32 = count(s.located_within(cx.located_radius_m(s)));
        /// Declarations farther than the success radius from every true source (with several
        /// sources, a subregion's declaration at its upflow edge counts when no source is near).
        declarations_off_source: u32 = count(
            s.declarations
                .iter()
                .filter(|d| d.error_m > cx.located_radius_m(s))
                .count(),
        );
        /// Subregions searched in turn (`mission.subregions`; 0 without them). With more than
        /// one the run is judged by the sources it located, as with several sources.
        subregions: u32 = count(s.subregions);
        /// First declared position, m.
        declared_x: Option<f64> ["m"] = first(s).map(|d| d.x_m);
        /// First declared position, m.
        declared_y: Option<f64> ["m"] = first(s).map(|d| d.y_m);
        /// Nearest true source, m.
        source_x: Option<f64> ["m"] = first(s)
            .map(|d| d.source_x_m)
            .or_else(|| s.sources.first().map(|src| src.x_m));
        /// Nearest true source, m.
        source_y: Option<f64> ["m"] = first(s)
            .map(|d| d.source_y_m)
            .or_else(|| s.sources.first().map(|src| src.y_m));
        /// Declaration error, m.
        error_m: Option<f64> ["m"] = first(s).map(|d| d.error_m);
        /// Along-flow error (positive downflow), m.
        error_along_m: Option<f64> ["m"] = first(s).map(|d| d.error_along_m);
        /// Crossflow error (positive to the right looking downflow), m.
        error_cross_m: Option<f64> ["m"] = first(s).map(|d| d.error_cross_m);
        /// Time of the first detection, s.
        first_detection_s: Option<f64> ["s"] = s.first_detection_s;
        /// Time of the first declaration, s.
        declaration_s: Option<f64> ["s"] = first(s).map(|d| d.t_s);
        /// Distance over ground, m.
        path_length_m: Option<f64> ["m"] = Some(s.path_length_m).filter(|v| v.is_finite());
        /// Distance over ground from the first detection to the first declaration, m.
        trace_length_m: Option<f64> ["m"] = s.trace_length_m;
        /// Straight line from the first detection to the source, m.
        detection_to_source_m: Option<f64> ["m"] = s.detection_to_source_m;
        /// `trace_length_m / detection_to_source_m`.
        path_ratio: Option<f64> = path_ratio(s);
        /// Mission time, s.
        sim_time_s: Option<f64> ["s"] = Some(s.sim_time_s);
        /// Distance from each true source to its nearest declaration, m, `;`-separated in the
        /// scenario's source order (empty entries for sources without one).
        source_errors_m: String ["m"] = source_errors(s);
        /// The longest any vehicle spent in one behaviour without a detection, s.
        longest_quiet_s: Option<f64> ["s"] = s.longest_quiet_s;
        /// The farthest any vehicle went outside the op-area (true position), m.
        max_outside_m: Option<f64> ["m"] = Some(s.max_outside_m);
        /// Team (two or more planners): when the formation first held its ranges within 20 %, s.
        team_converged_s: Option<f64> ["s"] = team(s, |t| t.converged_s);
        /// Team: median absolute range error after convergence, m.
        team_range_error_median_m: Option<f64> ["m"] = team(s, |t| t.range_error_median_m);
        /// Team: 90th percentile of the absolute range error after convergence, m.
        team_range_error_p90_m: Option<f64> ["m"] = team(s, |t| t.range_error_p90_m);
        /// Team: the range set-point, m.
        team_range_setpoint_m: Option<f64> ["m"] = team(s, |t| t.range_setpoint_m);
        /// Team: median cross-flow distance of the centroid from the plume's centre line, m.
        team_centroid_cross_median_m: Option<f64> ["m"] = team(s, |t| t.centroid_cross_median_m);
        /// Team: path to the first declaration over the straight line from start to source.
        team_distance_overhead: Option<f64> = team(s, |t| t.distance_overhead);
        /// Team: largest cross-flow scale reported.
        team_scale_max: Option<f64> = team(s, |t| t.scale_max);
        /// Team: last cross-flow scale reported.
        team_scale_final: Option<f64> = team(s, |t| t.scale_final);
        /// Team: acoustic messages lost (per recipient).
        team_acoustic_lost: Option<u64> = team(s, |t| Some(t.acoustic_lost));
        /// Team: acoustic messages delivered.
        team_acoustic_delivered: Option<u64> = team(s, |t| Some(t.acoustic_delivered));
        /// Team: commands refused for a non-finite number.
        team_non_finite_commands: Option<u64> = team(s, |t| Some(t.non_finite_commands));
    }
}

impl RunMetrics {
    /// Every metric column, in order.
    pub fn columns() -> Vec<Column> {
        columns_of::<RunMetrics>()
    }
}

/// A count as a column value (saturating).
fn count(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// The first declaration.
fn first(s: &Summary) -> Option<&DeclarationRecord> {
    s.first_declaration.as_ref()
}

/// The traced path over the straight line from the first detection to the source.
fn path_ratio(s: &Summary) -> Option<f64> {
    s.trace_length_m
        .zip(s.detection_to_source_m)
        .filter(|(_, d)| *d > 0.0)
        .map(|(t, d)| t / d)
}

/// Each source's nearest declaration distance, `;`-separated (3 decimals, empty for none).
fn source_errors(s: &Summary) -> String {
    s.sources
        .iter()
        .map(|src| {
            src.nearest_error_m
                .map_or(String::new(), |e| format!("{e:.3}"))
        })
        .collect::<Vec<_>>()
        .join(";")
}

/// A number of the team summary (`None` without a team).
fn team<T>(s: &Summary, get: impl Fn(&TeamSummary) -> Option<T>) -> Option<T> {
    s.team.as_ref().and_then(get)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_lists_every_field_once_with_its_kind_and_unit() {
        let cols = RunMetrics::columns();
        assert_eq!(cols.len(), <RunMetrics as Columns>::WIDTH);
        assert_eq!(cols[0].name, "success");
        assert_eq!(cols[0].kind, ColumnKind::Bool);
        let err = cols.iter().find(|c| c.name == "error_m");
        assert!(err.is_some_and(|c| c.kind == ColumnKind::OptF64 && c.unit == "m"));
        let lost = cols.iter().find(|c| c.name == "team_acoustic_lost");
        assert!(lost.is_some_and(|c| c.kind == ColumnKind::OptU64));
        let names: std::collections::BTreeSet<&str> = cols.iter().map(|c| c.name).collect();
        assert_eq!(names.len(), cols.len(), "names are unique");
        assert!(cols.iter().all(|c| !c.description().is_empty()));
        assert_eq!(
            cols[0].description(),
            "Single source: the first declaration lies within the success radius (the \
             campaign's, or the scenario's `mission.success_radius_m`). Several sources, or \
             subregions searched in turn: every source located (`sources_located == sources`)."
        );
        let m = RunMetrics {
            error_m: Some(2.5),
            team_acoustic_lost: Some(3),
            ..RunMetrics::default()
        };
        let values = values_of(&m);
        assert_eq!(values.len(), cols.len());
        let at = |name: &str| cols.iter().position(|c| c.name == name).unwrap_or(0);
        assert_eq!(values[at("error_m")], Value::OptF64(Some(2.5)));
        assert_eq!(values[at("team_acoustic_lost")], Value::OptU64(Some(3)));
    }

    #[test]
    fn metrics_are_one_flat_record() {
        let m = RunMetrics {
            success: true,
            declarations: 2,
            error_m: Some(1.25),
            source_errors_m: "1.250;".into(),
            ..RunMetrics::default()
        };
        let json = serde_json::to_value(&m).unwrap_or_default();
        assert_eq!(json["error_m"], serde_json::json!(1.25));
        assert_eq!(json["team_scale_max"], serde_json::Value::Null);
        let back: RunMetrics = serde_json::from_value(json).unwrap_or_default();
        assert_eq!(back, m);
    }
}
