//! Documented parameters: one table per parameter set gives the defaults, the bounds that are
//! checked, and the docs that `plumetrace planners` and the README print.
//!
//! A parameter set is declared once with [`params!`](crate::params!): each key with its type,
//! default, unit, bounds and one line of doc. The macro makes the struct (serde, unknown keys
//! refused, omitted keys defaulted), its `Default`, and its [`Params`] implementation (the key
//! table and the bounds check), so the list of keys exists in one place only.

use serde::Serialize;
use std::fmt::Write as _;

/// The table a parameter set is read from (TOML's).
pub use toml::Table;

/// The bounds of one parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bounds {
    /// Any value of its type (booleans and choices).
    Any,
    /// A finite real number between `min` and `max`; `*_open` excludes the end.
    Real {
        /// Lower end.
        min: f64,
        /// The lower end itself is not allowed.
        min_open: bool,
        /// Upper end.
        max: f64,
        /// The upper end itself is not allowed.
        max_open: bool,
    },
    /// A whole number in `min..=max`.
    Whole {
        /// Smallest value.
        min: u64,
        /// Largest value.
        max: u64,
    },
}

impl Bounds {
    /// `min <= v <= max`.
    pub const fn closed(min: f64, max: f64) -> Self {
        Bounds::Real {
            min,
            min_open: false,
            max,
            max_open: false,
        }
    }

    /// `0 < v <= max`.
    pub const fn positive(max: f64) -> Self {
        Bounds::Real {
            min: 0.0,
            min_open: true,
            max,
            max_open: false,
        }
    }

    /// `0 <= v <= max`.
    pub const fn non_negative(max: f64) -> Self {
        Bounds::closed(0.0, max)
    }

    /// `min..=max` for whole numbers.
    pub const fn whole(min: u64, max: u64) -> Self {
        Bounds::Whole { min, max }
    }

    /// The bounds as text for docs and errors (`"> 0 and <= 10"`, `"1..=50"`, `""`).
    pub fn describe(&self) -> String {
        match *self {
            Bounds::Any => String::new(),
            Bounds::Real {
                min,
                min_open,
                max,
                max_open,
            } => format!(
                "{} {min} and {} {max}",
                if min_open { ">" } else { ">=" },
                if max_open { "<" } else { "<=" }
            ),
            Bounds::Whole { min, max } => format!("{min}..={max}"),
        }
    }

    fn check_real(&self, v: f64) -> Result<(), BoundsError> {
        if !v.is_finite() {
            return Err(BoundsError::NotFinite(v));
        }
        match *self {
            Bounds::Real {
                min,
                min_open,
                max,
                max_open,
            } => {
                let low = if min_open { v > min } else { v >= min };
                let high = if max_open { v < max } else { v <= max };
                if low && high {
                    Ok(())
                } else {
                    Err(BoundsError::Outside {
                        bounds: self.describe(),
                        value: v.to_string(),
                    })
                }
            }
            Bounds::Any => Ok(()),
            Bounds::Whole { .. } => Err(BoundsError::WrongKind("whole-number", "real-valued")),
        }
    }

    fn check_whole(&self, v: u64) -> Result<(), BoundsError> {
        match *self {
            Bounds::Whole { min, max } if !(min..=max).contains(&v) => Err(BoundsError::Outside {
                bounds: self.describe(),
                value: v.to_string(),
            }),
            Bounds::Whole { .. } | Bounds::Any => Ok(()),
            Bounds::Real { .. } => Err(BoundsError::WrongKind("real-valued", "whole-number")),
        }
    }
}

/// A value outside its key's bounds.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BoundsError {
    /// Not a finite number.
    #[error("must be a finite number, got {0}")]
    NotFinite(f64),
    /// Outside the bounds.
    #[error("must be {bounds}, got {value}")]
    Outside {
        /// The bounds as text.
        bounds: String,
        /// The value as written.
        value: String,
    },
    /// Bounds of one kind on a key of another (a mistake in a parameter table).
    #[error("{0} bounds on a {1} key")]
    WrongKind(&'static str, &'static str),
}

/// A value a parameter can hold: it knows its type name for docs and how to check bounds.
pub trait ParamValue {
    /// The type in words, for docs (`"number"`, `"whole number"`, `"true/false"`, `"one of ..."`).
    fn type_name() -> String;
    /// The value as it is written in a file.
    fn show(&self) -> String;
    /// Checks the value against its bounds; the message says what is wrong.
    fn check(&self, bounds: &Bounds) -> Result<(), BoundsError>;
}

impl ParamValue for f64 {
    fn type_name() -> String {
        "number".into()
    }
    fn show(&self) -> String {
        // Debug keeps the decimal point (`2.0`), as the value is written in TOML.
        format!("{self:?}")
    }
    fn check(&self, bounds: &Bounds) -> Result<(), BoundsError> {
        bounds.check_real(*self)
    }
}

macro_rules! whole_param {
    ($($t:ty),*) => {$(
        impl ParamValue for $t {
            fn type_name() -> String {
                "whole number".into()
            }
            fn show(&self) -> String {
                format!("{self}")
            }
            fn check(&self, bounds: &Bounds) -> Result<(), BoundsError> {
                bounds.check_whole(u64::try_from(*self).unwrap_or(u64::MAX))
            }
        }
    )*};
}
whole_param!(u32, u64, usize);

impl ParamValue for bool {
    fn type_name() -> String {
        "true/false".into()
    }
    fn show(&self) -> String {
        format!("{self}")
    }
    fn check(&self, _: &Bounds) -> Result<(), BoundsError> {
        Ok(())
    }
}

/// An enum parameter written as one of its variant names (serde's names).
pub trait Choice: Serialize + Copy + 'static {
    /// Every variant.
    const ALL: &'static [Self];
}

impl<T: Choice> ParamValue for T {
    fn type_name() -> String {
        let names: Vec<String> = T::ALL.iter().map(|v| format!("\"{}\"", v.show())).collect();
        format!("one of {}", names.join(", "))
    }
    fn show(&self) -> String {
        crate::names::variant_name(self).unwrap_or("?").to_string()
    }
    fn check(&self, _: &Bounds) -> Result<(), BoundsError> {
        Ok(())
    }
}

/// A bad parameter value; `key` is the full key path.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{key}: {message}")]
pub struct ParamError {
    /// Key path, e.g. `planners.tracer.beta_deg`.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl ParamError {
    /// An error at `prefix.name` (or `name` without a prefix).
    pub fn at(prefix: &str, name: &str, message: impl Into<String>) -> Self {
        ParamError {
            key: key_path(prefix, name),
            message: message.into(),
        }
    }
}

/// A key as written in a key path: plain words (ASCII letters, digits, `_`, `-`) as they are,
/// others quoted as TOML would (`""`, `"a b"`, `"a.b"`), so that the path reads back unambiguously.
pub fn quoted_key(key: &str) -> String {
    if !key.is_empty()
        && key
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-".contains(c))
    {
        key.to_string()
    } else {
        format!("{key:?}")
    }
}

/// `prefix.name`, or `name` when the prefix is empty.
pub fn key_path(prefix: &str, name: &str) -> String {
    if prefix.is_empty() {
        name.to_string()
    } else {
        format!("{prefix}.{name}")
    }
}

/// One documented key.
#[derive(Debug, Clone, PartialEq)]
pub struct KeyDoc {
    /// The key as written in files.
    pub name: &'static str,
    /// Unit (empty for counts, flags and choices).
    pub unit: &'static str,
    /// One line of doc.
    pub doc: &'static str,
    /// The type in words.
    pub type_name: String,
    /// The default as written in files.
    pub default: String,
    /// Allowed values (empty: any of its type).
    pub bounds: String,
}

impl KeyDoc {
    /// The doc of a key of type `T` with default `default`.
    pub fn new<T: ParamValue>(
        name: &'static str,
        unit: &'static str,
        doc: &'static str,
        default: &T,
        bounds: Bounds,
    ) -> Self {
        KeyDoc {
            name,
            unit,
            doc,
            type_name: T::type_name(),
            default: default.show(),
            bounds: bounds.describe(),
        }
    }
}

/// A parameter set made by [`params!`](crate::params!).
pub trait Params: Sized {
    /// Every key, in declaration order (the keys of included sets first), with the set's
    /// defaults.
    fn keys() -> Vec<KeyDoc>;
    /// Every key with this value of it as its default (what [`Params::keys`] gives for the
    /// default set; an included set shows the defaults of the set that includes it).
    fn docs(&self) -> Vec<KeyDoc>;
    /// Checks every value against its bounds; errors name `prefix.key`.
    fn check_bounds(&self, prefix: &str) -> Result<(), ParamError>;
    /// Reads the set from a table, keys omitted taking this set's defaults; errors name
    /// `prefix.key` (unknown keys, with the nearest known key; wrong types).
    fn read(table: Table, prefix: &str) -> Result<Self, ParamError>;
}

/// Reads `table` as the serde struct `T` (own keys only: an included set's fields take their
/// values from `T`'s default); errors name `prefix.key`. Unknown keys are refused with the nearest
/// of `known`.
#[doc(hidden)]
pub fn read_own<T: serde::de::DeserializeOwned>(
    table: Table,
    prefix: &str,
    known: &[KeyDoc],
) -> Result<T, ParamError> {
    if let Some(unknown) = table
        .keys()
        .find(|k| !known.iter().any(|d| d.name == k.as_str()))
    {
        let names: Vec<&str> = known.iter().map(|d| d.name).collect();
        let hint = match crate::names::closest(unknown, &names) {
            Some(near) => format!("; did you mean `{near}`?"),
            None => String::new(),
        };
        return Err(ParamError::at(
            prefix,
            &quoted_key(unknown),
            format!("unknown field `{unknown}`{hint} (`plumetrace planners` lists every key)"),
        ));
    }
    serde_path_to_error::deserialize(toml::Value::Table(table)).map_err(|e| {
        let path = e.path().to_string();
        let message = crate::toml_message(&e.into_inner(), true);
        ParamError {
            key: if path == "." {
                prefix.to_string()
            } else {
                key_path(prefix, &path)
            },
            message: match known.iter().find(|d| d.name == path) {
                Some(doc) => expecting_key_bounds(&message, doc),
                None => message,
            },
        }
    })
}

/// A type error's message for the key `doc` expecting what the key takes rather than what its
/// Rust type takes: the key's own bounds and unit (`expected a whole number from 0 to 4294967295`
/// reads `expected a whole number in 1..=10`; a whole number written with a decimal point is told
/// so), or a choice's names (`expected one of "oldest", "most_downflow"`, where serde speaks of
/// a `unit variant`). A key without bounds, or a message that expects nothing, is left as it is.
fn expecting_key_bounds(message: &str, doc: &KeyDoc) -> String {
    const EXPECTED: &str = ", expected ";
    let Some(at) = message.find(EXPECTED) else {
        return message.to_string();
    };
    let head = &message[..at];
    if doc.type_name.starts_with("one of ") {
        // A name that is not one of them keeps serde's list (and its words).
        if head.starts_with("unknown variant") {
            return message.to_string();
        }
        let head = if head.contains("unit variant") {
            "invalid value: not a name"
        } else {
            head
        };
        return format!("{head}{EXPECTED}{} (a name in quotes)", doc.type_name);
    }
    if doc.bounds.is_empty() {
        return message.to_string();
    }
    // Bounded keys are numbers or whole numbers (choices and flags have none).
    let within = if doc.bounds.starts_with(|c: char| c.is_ascii_digit()) {
        "in "
    } else {
        ""
    };
    let unit = shown_unit(doc.unit).map_or(String::new(), |u| format!(" {u}"));
    // `floating point `4.0``: a whole number with a decimal point.
    let whole_float = head
        .split_once("floating point `")
        .and_then(|(_, rest)| rest.split('`').next())
        .and_then(|v| v.parse::<f64>().ok())
        .is_some_and(|v| v.is_finite() && v.fract() == 0.0);
    let hint = if whole_float && doc.type_name == "whole number" {
        " (written without a decimal point)"
    } else {
        ""
    };
    format!(
        "{head}{EXPECTED}a {} {within}{}{unit}{hint}",
        doc.type_name, doc.bounds
    )
}

/// A key's unit as its messages show it: none for counts, flags and choices, nor for the
/// sensor's own unit (`unit`, `1/(s unit)`: the reading's unit, which the key does not know).
fn shown_unit(unit: &str) -> Option<&str> {
    (!unit.is_empty() && !unit.contains("unit")).then_some(unit)
}

/// Reads an included set: the keys of `table` that belong to it are taken out and read over
/// `base` (the including set's defaults for it).
#[doc(hidden)]
pub fn read_included<T: Params + serde::Serialize>(
    table: &mut Table,
    base: &T,
    prefix: &str,
) -> Result<T, ParamError> {
    let mut own = Table::try_from(base).map_err(|e| ParamError::at(prefix, "", e.to_string()))?;
    for k in T::keys() {
        if let Some(v) = table.remove(k.name) {
            own.insert(k.name.to_string(), v);
        }
    }
    T::read(own, prefix)
}

/// Checks one value (used by [`params!`](crate::params!)); a value outside its bounds is named
/// with the key's unit as `shown_unit` shows it (`must be > 0 and <= 10 m/s, got 50 m/s`).
pub fn check<T: ParamValue>(
    prefix: &str,
    name: &str,
    value: &T,
    bounds: &Bounds,
    unit: &str,
) -> Result<(), ParamError> {
    value.check(bounds).map_err(|e| {
        let message = match (e, shown_unit(unit)) {
            (BoundsError::Outside { bounds, value }, Some(unit)) => {
                format!("must be {bounds} {unit}, got {value} {unit}")
            }
            (e, _) => e.to_string(),
        };
        ParamError::at(prefix, name, message)
    })
}

/// The keys as Markdown table rows (`| key | type | default | unit | bounds | doc |`).
pub fn markdown_rows(keys: &[KeyDoc]) -> String {
    let mut out = String::new();
    for k in keys {
        let _ = writeln!(
            out,
            "| `{}` | {} | `{}` | {} | {} | {} |",
            k.name, k.type_name, k.default, k.unit, k.bounds, k.doc
        );
    }
    out
}

/// Declares a documented parameter set: a struct whose fields carry type, default, unit, bounds
/// and one line of doc. The struct deserialises from a table with every key optional (defaults
/// fill the rest) and unknown keys refused.
///
/// A set may include other sets first (`include name: Type = default;`): their keys are read,
/// written, checked and documented as keys of this set (one flat table), with the defaults this
/// set gives them, and the code reads them as `self.name.key`. Keys shared by several planners
/// are declared once this way.
///
/// ```
/// use plumetrace_core::params::{Bounds, Params};
/// plumetrace_core::params! {
///     /// Keys several sets share.
///     pub struct Shared {
///         /// Speed command.
///         speed_mps: f64 = 2.0, "m/s", Bounds::positive(10.0);
///     }
/// }
/// plumetrace_core::params! {
///     /// A planner's settings.
///     pub struct Example {
///         include shared: Shared = Shared { speed_mps: 1.5 };
///         /// Repetitions.
///         n: u32 = 2, "", Bounds::whole(1, 50);
///     }
/// }
/// assert_eq!(Example::default().shared.speed_mps, 1.5);
/// assert_eq!(Example::keys()[0].default, "1.5");
/// assert_eq!(Example::keys()[1].bounds, "1..=50");
/// let bad = Example { n: 0, ..Example::default() };
/// assert_eq!(bad.check_bounds("p").unwrap_err().to_string(), "p.n: must be 1..=50, got 0");
/// let read = Example::read("speed_mps = 1.0".parse().unwrap(), "p").unwrap();
/// assert_eq!((read.shared.speed_mps, read.n), (1.0, 2));
/// ```
#[macro_export]
macro_rules! params {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $(
                include $inc:ident : $ity:ty = $idefault:expr;
            )*
            $(
                #[doc = $doc:literal]
                $field:ident : $ty:ty = $default:expr, $unit:literal, $bounds:expr;
            )*
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
        #[serde(deny_unknown_fields, default)]
        $vis struct $name {
            $(
                #[doc = concat!("The included [`", stringify!($ity), "`] keys.")]
                #[serde(flatten, skip_deserializing)]
                pub $inc: $ity,
            )*
            $(
                #[doc = $doc]
                pub $field: $ty,
            )*
        }

        impl Default for $name {
            fn default() -> Self {
                $name {
                    $( $inc: $idefault, )*
                    $( $field: $default, )*
                }
            }
        }

        impl $crate::params::Params for $name {
            fn keys() -> Vec<$crate::params::KeyDoc> {
                <$name as Default>::default().docs()
            }

            #[allow(clippy::vec_init_then_push)]
            fn docs(&self) -> Vec<$crate::params::KeyDoc> {
                #[allow(unused_mut)]
                let mut out: Vec<$crate::params::KeyDoc> = Vec::new();
                $( out.extend($crate::params::Params::docs(&self.$inc)); )*
                $(
                    out.push($crate::params::KeyDoc::new::<$ty>(
                        stringify!($field),
                        $unit,
                        $doc.trim(),
                        &self.$field,
                        $bounds,
                    ));
                )*
                out
            }

            fn check_bounds(&self, prefix: &str) -> Result<(), $crate::params::ParamError> {
                $( $crate::params::Params::check_bounds(&self.$inc, prefix)?; )*
                $( $crate::params::check(prefix, stringify!($field), &self.$field, &$bounds, $unit)?; )*
                Ok(())
            }

            #[allow(unused_mut, unused_variables)]
            fn read(mut table: $crate::params::Table, prefix: &str) -> Result<Self, $crate::params::ParamError> {
                let base = <$name as Default>::default();
                $( let $inc = $crate::params::read_included(&mut table, &base.$inc, prefix)?; )*
                let mut out: $name = $crate::params::read_own(
                    table,
                    prefix,
                    &<$name as $crate::params::Params>::keys(),
                )?;
                $( out.$inc = $inc; )*
                Ok(out)
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
    #[serde(rename_all = "snake_case")]
    enum Mode {
        Oldest,
        MostDownflow,
    }

    impl Choice for Mode {
        const ALL: &'static [Self] = &[Mode::Oldest, Mode::MostDownflow];
    }

    crate::params! {
        /// Test set.
        struct Set {
            /// A rate.
            rate_hz: f64 = 10.0, "Hz", Bounds::positive(100.0);
            /// A count.
            count: usize = 3, "", Bounds::whole(3, 10);
            /// A switch.
            on: bool = true, "", Bounds::Any;
            /// A choice.
            mode: Mode = Mode::Oldest, "", Bounds::Any;
        }
    }

    #[test]
    fn bounds_table() {
        let cases: [(Bounds, f64, bool); 8] = [
            (Bounds::positive(10.0), 0.0, false),
            (Bounds::positive(10.0), 1e-300, true),
            (Bounds::positive(10.0), 10.0, true),
            (Bounds::positive(10.0), 10.000_001, false),
            (Bounds::non_negative(1.0), 0.0, true),
            (Bounds::closed(-1.0, 1.0), -1.0, true),
            (Bounds::closed(-1.0, 1.0), f64::NAN, false),
            (Bounds::closed(-1.0, 1.0), f64::INFINITY, false),
        ];
        for (b, v, ok) in cases {
            assert_eq!(b.check_real(v).is_ok(), ok, "{b:?} {v}");
        }
        assert!(Bounds::whole(1, 5).check_whole(0).is_err());
        assert!(
            Bounds::whole(1, 5).check_real(3.0).is_err(),
            "bounds of the wrong type"
        );
        assert!(Bounds::positive(5.0).check_whole(3).is_err());
        assert!(Bounds::whole(1, 5).check_whole(5).is_ok());
    }

    crate::params! {
        /// A set that includes `Set` with other defaults.
        struct Outer {
            include inner: Set = Set { rate_hz: 20.0, ..Set::default() };
            /// Its own key.
            gain: f64 = 1.0, "", Bounds::closed(0.0, 2.0);
        }
    }

    fn table(text: &str) -> Table {
        text.parse().unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn an_included_set_reads_writes_checks_and_documents_as_one_table() {
        let keys: Vec<(&str, String)> = Outer::keys()
            .into_iter()
            .map(|k| (k.name, k.default))
            .collect();
        assert_eq!(
            keys[0],
            ("rate_hz", "20.0".to_string()),
            "the includer's default"
        );
        assert_eq!(keys.len(), 5);
        assert_eq!(keys[4].0, "gain");
        let o = Outer::read(table("gain = 2.0\ncount = 4"), "p").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((o.inner.rate_hz, o.inner.count, o.gain), (20.0, 4, 2.0));
        let back = Table::try_from(&o).unwrap_or_default();
        assert_eq!(back.len(), 5, "written flat: {back:?}");
        assert_eq!(Outer::read(back, "p").ok(), Some(o.clone()));
        let bad = Outer {
            inner: Set {
                count: 1,
                ..o.inner
            },
            ..o
        };
        assert_eq!(
            bad.check_bounds("q").map_err(|e| e.key),
            Err("q.count".to_string())
        );
        let cases = [
            (
                "rate_hz = \"x\"",
                "p.rate_hz",
                "invalid type: string \"x\", expected a number",
            ),
            ("gain = \"x\"", "p.gain", "invalid type"),
            ("cuont = 3", "p.cuont", "did you mean `count`?"),
            ("gian = 1.0", "p.gian", "did you mean `gain`?"),
            ("zzz = 1", "p.zzz", "unknown field `zzz` ("),
            // A type error expects the key's bounds, not its type's range.
            (
                "count = 2.5",
                "p.count",
                "invalid type: floating point `2.5`, expected a whole number in 3..=10",
            ),
            (
                "count = -1",
                "p.count",
                "invalid value: integer `-1`, expected a whole number in 3..=10",
            ),
            (
                "gain = true",
                "p.gain",
                "invalid type: boolean `true`, expected a number >= 0 and <= 2",
            ),
            // With the key's unit, and a whole number written with a decimal point told so.
            (
                "rate_hz = true",
                "p.rate_hz",
                "invalid type: boolean `true`, expected a number > 0 and <= 100 Hz",
            ),
            (
                "count = 4.0",
                "p.count",
                "invalid type: floating point `4.0`, expected a whole number in 3..=10 (written \
                 without a decimal point)",
            ),
            // A choice expects its names.
            (
                "mode = 3",
                "p.mode",
                r#"expected one of "oldest", "most_downflow" (a name in quotes)"#,
            ),
            // Keys without bounds keep serde's words.
            (
                "on = 1",
                "p.on",
                "invalid type: integer `1`, expected a boolean",
            ),
        ];
        for (text, key, message) in cases {
            let e = Outer::read(table(text), "p")
                .err()
                .unwrap_or_else(|| panic!("{text}"));
            assert_eq!(e.key, key, "{text}: {e}");
            assert!(e.message.contains(message), "{text}: {e}");
        }
    }

    #[test]
    fn the_table_drives_docs_defaults_and_checks() {
        let keys = Set::keys();
        let names: Vec<&str> = keys.iter().map(|k| k.name).collect();
        assert_eq!(names, ["rate_hz", "count", "on", "mode"]);
        assert_eq!(keys[0].default, "10.0");
        assert_eq!(keys[0].bounds, "> 0 and <= 100");
        assert_eq!(keys[0].doc, "A rate.");
        assert_eq!(keys[3].type_name, r#"one of "oldest", "most_downflow""#);
        assert_eq!(keys[3].default, "oldest");
        assert!(Set::default().check_bounds("p").is_ok());
        let e = Set {
            count: 2,
            ..Set::default()
        }
        .check_bounds("planners.a")
        .unwrap_err();
        assert_eq!(e.key, "planners.a.count");
        assert_eq!(e.message, "must be 3..=10, got 2");
        // A key with a unit says it on both sides.
        let e = Set {
            rate_hz: 200.0,
            ..Set::default()
        }
        .check_bounds("p")
        .unwrap_err();
        assert_eq!(e.message, "must be > 0 and <= 100 Hz, got 200 Hz");
        let rows = markdown_rows(&keys);
        assert!(
            rows.starts_with("| `rate_hz` | number | `10.0` | Hz | > 0 and <= 100 | A rate. |")
        );
        let t: Set = serde_json::from_str(r#"{"mode":"most_downflow"}"#).unwrap_or_default();
        assert_eq!(t.mode, Mode::MostDownflow);
        assert_eq!(t.rate_hz, 10.0, "omitted keys take their default");
        assert!(serde_json::from_str::<Set>(r#"{"rat_hz":1}"#).is_err());
    }
}
