//! Mutations of a corpus input, each drawn from the input's own random stream.
//!
//! Tree mutations edit the parsed TOML (`toml::Table`), which is serialised again afterwards;
//! raw mutations edit the bytes of the final text. Every mutation returns a one-line account of
//! what it did, so a finding's sidecar file says how its input was made.

use crate::corpus::Target;
use rand::Rng;
use rand_pcg::Pcg64Mcg;
use toml::{Table, Value};

/// Inputs are kept under this many bytes.
pub const MAX_INPUT_BYTES: usize = 1_000_000;

/// What tree mutations may grow the serialised text to (quoting and raw insertions add a
/// little on top).
const TREE_BUDGET: usize = 900_000;

/// Every kind of mutation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Kind {
    /// Delete a key (not a table).
    DeleteKey,
    /// Delete a whole table, array of tables or array-of-tables entry.
    DeleteTable,
    /// Duplicate an entry of an array.
    DuplicateArrayEntry,
    /// Insert a key the schema does not know.
    InsertUnknownKey,
    /// Give a value another type (number to string, table to number, date, ...).
    ChangeType,
    /// Replace a number by an extreme one (0, -0.0, +-1e300, 4.6e18, i64::MAX, ...).
    ExtremeNumber,
    /// Multiply a number by 1e3 or 1e-3.
    NearValue,
    /// Replace a number by `nan`, `inf` or `-inf`.
    NanInf,
    /// A polygon with 0, 1 or 2 points, collinear points or a repeated vertex.
    PolygonDegenerate,
    /// A self-intersecting (bow-tie) polygon.
    PolygonBowtie,
    /// A polygon with coordinates near 1e18.
    PolygonHuge,
    /// A polygon with vertices of 3 numbers.
    PolygonThreeNumbers,
    /// A polygon with an extra vertex far outside it.
    PolygonFarVertex,
    /// An array of up to 10^4 entries.
    HugeArray,
    /// A string of up to half a megabyte.
    HugeString,
    /// A planner key set at one end of its documented bounds, or just past it (the registry's
    /// bounds for the table's `kind`: an open end itself, `min - 1` and `max + 1` for counts).
    PlannerKeyAtBound,
    /// A name that becomes a file name (a vehicle's, a family's, an obstacle's) made hostile:
    /// `..`, a separator, an absolute path, NUL, a control character, 300 bytes, another's.
    HostileName,
    /// Campaign `seeds`: 0, negative, huge, wrong type.
    CampaignSeeds,
    /// Campaign `sweep`: many values, duplicates, empty, not an array, odd keys.
    CampaignSweep,
    /// Campaign configuration names: long, with `/`, duplicated, empty.
    CampaignConfigName,
    /// Campaign `success_radius_m`: extremes and wrong types.
    CampaignSuccessRadius,
    /// Campaign `scenarios`: unknown names, paths, duplicates, empty, many.
    CampaignScenarios,
    /// Campaign `[configs.planner]` and `[configs.set]` keys.
    CampaignPlannerKeys,
    /// Flip bits of the text.
    FlipBits,
    /// Insert bytes (TOML punctuation, control characters).
    InsertBytes,
    /// Delete a run of bytes.
    DeleteBytes,
    /// Insert an invalid UTF-8 sequence.
    InvalidUtf8,
    /// Cut the text short.
    Truncate,
}

impl Kind {
    /// Every kind, in declaration order.
    pub const ALL: [Kind; 28] = [
        Kind::DeleteKey,
        Kind::DeleteTable,
        Kind::DuplicateArrayEntry,
        Kind::InsertUnknownKey,
        Kind::ChangeType,
        Kind::ExtremeNumber,
        Kind::NearValue,
        Kind::NanInf,
        Kind::PolygonDegenerate,
        Kind::PolygonBowtie,
        Kind::PolygonHuge,
        Kind::PolygonThreeNumbers,
        Kind::PolygonFarVertex,
        Kind::HugeArray,
        Kind::HugeString,
        Kind::PlannerKeyAtBound,
        Kind::HostileName,
        Kind::CampaignSeeds,
        Kind::CampaignSweep,
        Kind::CampaignConfigName,
        Kind::CampaignSuccessRadius,
        Kind::CampaignScenarios,
        Kind::CampaignPlannerKeys,
        Kind::FlipBits,
        Kind::InsertBytes,
        Kind::DeleteBytes,
        Kind::InvalidUtf8,
        Kind::Truncate,
    ];

    /// Snake-case name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Kind::DeleteKey => "delete_key",
            Kind::DeleteTable => "delete_table",
            Kind::DuplicateArrayEntry => "duplicate_array_entry",
            Kind::InsertUnknownKey => "insert_unknown_key",
            Kind::ChangeType => "change_type",
            Kind::ExtremeNumber => "extreme_number",
            Kind::NearValue => "near_value",
            Kind::NanInf => "nan_inf",
            Kind::PolygonDegenerate => "polygon_degenerate",
            Kind::PolygonBowtie => "polygon_bowtie",
            Kind::PolygonHuge => "polygon_huge",
            Kind::PolygonThreeNumbers => "polygon_three_numbers",
            Kind::PolygonFarVertex => "polygon_far_vertex",
            Kind::HugeArray => "huge_array",
            Kind::HugeString => "huge_string",
            Kind::PlannerKeyAtBound => "planner_key_at_bound",
            Kind::HostileName => "hostile_name",
            Kind::CampaignSeeds => "campaign_seeds",
            Kind::CampaignSweep => "campaign_sweep",
            Kind::CampaignConfigName => "campaign_config_name",
            Kind::CampaignSuccessRadius => "campaign_success_radius",
            Kind::CampaignScenarios => "campaign_scenarios",
            Kind::CampaignPlannerKeys => "campaign_planner_keys",
            Kind::FlipBits => "flip_bits",
            Kind::InsertBytes => "insert_bytes",
            Kind::DeleteBytes => "delete_bytes",
            Kind::InvalidUtf8 => "invalid_utf8",
            Kind::Truncate => "truncate",
        }
    }

    /// Whether it edits bytes rather than the TOML tree.
    pub fn is_raw(self) -> bool {
        matches!(
            self,
            Kind::FlipBits
                | Kind::InsertBytes
                | Kind::DeleteBytes
                | Kind::InvalidUtf8
                | Kind::Truncate
        )
    }

    /// Whether it only applies to campaign files.
    pub fn campaign_only(self) -> bool {
        matches!(
            self,
            Kind::CampaignSeeds
                | Kind::CampaignSweep
                | Kind::CampaignConfigName
                | Kind::CampaignSuccessRadius
                | Kind::CampaignScenarios
                | Kind::CampaignPlannerKeys
        )
    }
}

/// A mutation as applied.
#[derive(Debug, Clone, PartialEq)]
pub struct Applied {
    /// Its kind.
    pub kind: Kind,
    /// What it did, e.g. `sources[0].mass_rate_per_s = 1e300`.
    pub detail: String,
}

// ---------------------------------------------------------------------------------------------
// Random helpers.

/// A uniform index below `n` (0 when `n` is 0).
fn below(rng: &mut Pcg64Mcg, n: usize) -> usize {
    if n == 0 { 0 } else { rng.random_range(0..n) }
}

/// A uniform element of `items`.
fn pick<'a, T>(rng: &mut Pcg64Mcg, items: &'a [T]) -> Option<&'a T> {
    if items.is_empty() {
        None
    } else {
        items.get(below(rng, items.len()))
    }
}

/// A whole number between `lo` and `hi`, uniform in its logarithm.
fn log_uniform(rng: &mut Pcg64Mcg, lo: usize, hi: usize) -> usize {
    let (a, b) = ((lo.max(1) as f64).ln(), (hi.max(lo + 1) as f64).ln());
    let x = (a + rng.random::<f64>() * (b - a)).exp();
    (x as usize).clamp(lo, hi)
}

const EXTREME_FLOATS: &[f64] = &[
    0.0,
    -0.0,
    -1.0,
    1e-300,
    -1e-300,
    1e300,
    -1e300,
    4.6e18,
    -4.6e18,
    f64::MAX,
    f64::MIN_POSITIVE,
    5e-324,
    1e-9,
    1e9,
    1e15,
    -1e15,
];

const EXTREME_INTS: &[i64] = &[
    0,
    -1,
    1,
    2,
    255,
    65_536,
    2_147_483_648,
    -2_147_483_648,
    4_294_967_296,
    1_000_000_000,
    9_007_199_254_740_993,
    i64::MAX,
    i64::MIN,
];

/// An extreme number, an integer more often when the value replaced was one.
fn extreme_value(rng: &mut Pcg64Mcg, integer: bool) -> Value {
    let want_int = if integer {
        rng.random_bool(0.7)
    } else {
        rng.random_bool(0.2)
    };
    if want_int {
        Value::Integer(pick(rng, EXTREME_INTS).copied().unwrap_or(0))
    } else {
        float(pick(rng, EXTREME_FLOATS).copied().unwrap_or(0.0))
    }
}

/// `nan`, `inf` or `-inf`.
fn nan_inf(rng: &mut Pcg64Mcg) -> Value {
    Value::Float(match below(rng, 4) {
        0 => f64::NAN,
        1 => -f64::NAN,
        2 => f64::INFINITY,
        _ => f64::NEG_INFINITY,
    })
}

/// A TOML date-time, date or time.
fn datetime(rng: &mut Pcg64Mcg) -> Value {
    let text = *pick(
        rng,
        &[
            "1979-05-27T07:32:00Z",
            "1979-05-27",
            "07:32:00",
            "1979-05-27T00:32:00.999999-07:00",
        ],
    )
    .unwrap_or(&"1979-05-27");
    text.parse::<toml::value::Datetime>()
        .map(Value::Datetime)
        .unwrap_or_else(|_| Value::String(text.into()))
}

/// Which of the seven TOML types a value has (0 string .. 6 date-time).
fn type_index(v: &Value) -> usize {
    match v {
        Value::String(_) => 0,
        Value::Integer(_) => 1,
        Value::Float(_) => 2,
        Value::Boolean(_) => 3,
        Value::Array(_) => 4,
        Value::Table(_) => 5,
        Value::Datetime(_) => 6,
    }
}

/// `v` as a value of another type.
fn retyped(rng: &mut Pcg64Mcg, v: &Value) -> Value {
    let mut t = below(rng, 6);
    if t >= type_index(v) {
        t += 1;
    }
    let number_text = || match v {
        Value::Integer(n) => Some(n.to_string()),
        Value::Float(x) => Some(x.to_string()),
        _ => None,
    };
    match t {
        0 => Value::String(number_text().unwrap_or_else(|| match v {
            Value::Boolean(b) => b.to_string(),
            _ => "fuzz".into(),
        })),
        1 => Value::Integer(match v {
            Value::String(s) => s.trim().parse::<f64>().map_or(7, |x| x as i64),
            Value::Float(x) => *x as i64,
            Value::Boolean(b) => i64::from(*b),
            _ => 42,
        }),
        2 => Value::Float(match v {
            Value::String(s) => s.trim().parse::<f64>().unwrap_or(0.5),
            Value::Integer(n) => *n as f64 + 0.5,
            _ => 0.5,
        }),
        3 => Value::Boolean(rng.random_bool(0.5)),
        4 => Value::Array(if rng.random_bool(0.7) {
            vec![v.clone()]
        } else {
            Vec::new()
        }),
        5 => {
            let mut t = Table::new();
            if rng.random_bool(0.7) {
                t.insert("value".into(), v.clone());
            }
            Value::Table(t)
        }
        _ => datetime(rng),
    }
}

/// A value of any type, extremes included.
fn any_value(rng: &mut Pcg64Mcg) -> Value {
    match below(rng, 10) {
        0 | 1 => {
            let int = rng.random_bool(0.5);
            extreme_value(rng, int)
        }
        2 => nan_inf(rng),
        3 => Value::Float(rng.random_range(-100.0..100.0)),
        4 => Value::String(
            (*pick(
                rng,
                &[
                    "",
                    "x",
                    "amp",
                    "lawnmower",
                    "along_flow",
                    "oldest",
                    "nope",
                    "1.5",
                ],
            )
            .unwrap_or(&"x"))
            .into(),
        ),
        5 => Value::Boolean(rng.random_bool(0.5)),
        6 => Value::Array(vec![Value::Integer(1), Value::Integer(2)]),
        7 => Value::Table(Table::new()),
        8 => datetime(rng),
        _ => Value::Integer(rng.random_range(-5..200)),
    }
}

// ---------------------------------------------------------------------------------------------
// Paths in the TOML tree.

/// One step of a path: a table key or an array index.
#[derive(Debug, Clone, PartialEq)]
pub enum Seg {
    /// Table key.
    Key(String),
    /// Array index.
    Idx(usize),
}

/// A path as text: `sources[0].x_m`.
pub fn path_text(path: &[Seg]) -> String {
    let mut s = String::new();
    for seg in path {
        match seg {
            Seg::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Seg::Idx(i) => s.push_str(&format!("[{i}]")),
        }
    }
    if s.is_empty() {
        "(top level)".into()
    } else {
        s
    }
}

/// Every path below the root (not the root itself) whose value satisfies `keep`.
fn paths_where(root: &Table, keep: &dyn Fn(&[Seg], &Value) -> bool) -> Vec<Vec<Seg>> {
    fn walk(
        v: &Value,
        path: &mut Vec<Seg>,
        keep: &dyn Fn(&[Seg], &Value) -> bool,
        out: &mut Vec<Vec<Seg>>,
    ) {
        if keep(path, v) {
            out.push(path.clone());
        }
        match v {
            Value::Table(t) => {
                for (k, c) in t {
                    path.push(Seg::Key(k.clone()));
                    walk(c, path, keep, out);
                    path.pop();
                }
            }
            Value::Array(a) => {
                for (i, c) in a.iter().enumerate() {
                    path.push(Seg::Idx(i));
                    walk(c, path, keep, out);
                    path.pop();
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    for (k, v) in root {
        let mut path = vec![Seg::Key(k.clone())];
        walk(v, &mut path, keep, &mut out);
    }
    out
}

/// The value at `path`.
fn get<'a>(root: &'a Table, path: &[Seg]) -> Option<&'a Value> {
    let (Seg::Key(first), rest) = path.split_first()? else {
        return None;
    };
    let mut v = root.get(first)?;
    for seg in rest {
        v = match (seg, v) {
            (Seg::Key(k), Value::Table(t)) => t.get(k)?,
            (Seg::Idx(i), Value::Array(a)) => a.get(*i)?,
            _ => return None,
        };
    }
    Some(v)
}

/// The value at `path`, mutably.
fn get_mut<'a>(root: &'a mut Table, path: &[Seg]) -> Option<&'a mut Value> {
    let (Seg::Key(first), rest) = path.split_first()? else {
        return None;
    };
    let mut v = root.get_mut(first)?;
    for seg in rest {
        v = match (seg, v) {
            (Seg::Key(k), Value::Table(t)) => t.get_mut(k)?,
            (Seg::Idx(i), Value::Array(a)) => a.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(v)
}

/// Replaces the value at `path`; false if there is none.
fn set(root: &mut Table, path: &[Seg], value: Value) -> bool {
    match get_mut(root, path) {
        Some(v) => {
            *v = value;
            true
        }
        None => false,
    }
}

/// Removes the value at `path` from its table or array.
fn remove(root: &mut Table, path: &[Seg]) -> bool {
    let Some((last, parent)) = path.split_last() else {
        return false;
    };
    if parent.is_empty() {
        return matches!(last, Seg::Key(k) if root.remove(k).is_some());
    }
    match (get_mut(root, parent), last) {
        (Some(Value::Table(t)), Seg::Key(k)) => t.remove(k).is_some(),
        (Some(Value::Array(a)), Seg::Idx(i)) if *i < a.len() => {
            a.remove(*i);
            true
        }
        _ => false,
    }
}

/// The table at `path` (the root for an empty path).
fn table_mut<'a>(root: &'a mut Table, path: &[Seg]) -> Option<&'a mut Table> {
    if path.is_empty() {
        Some(root)
    } else {
        get_mut(root, path)?.as_table_mut()
    }
}

fn is_number(v: &Value) -> bool {
    matches!(v, Value::Integer(_) | Value::Float(_))
}

fn is_array_of_tables(v: &Value) -> bool {
    matches!(v, Value::Array(a) if !a.is_empty() && a.iter().all(Value::is_table))
}

/// Roughly how many bytes `v` takes when serialised (on the high side).
pub fn approx_size(v: &Value) -> usize {
    match v {
        Value::String(s) => {
            2 + s
                .chars()
                .map(|c| match c {
                    '"' | '\\' | '\n' | '\t' | '\r' => 2,
                    c if c.is_control() => 6,
                    c => c.len_utf8(),
                })
                .sum::<usize>()
        }
        Value::Integer(_) => 21,
        Value::Float(_) => 25,
        Value::Boolean(_) => 5,
        Value::Datetime(_) => 36,
        Value::Array(a) => 2 + a.iter().map(|x| approx_size(x) + 2).sum::<usize>(),
        Value::Table(t) => table_size(t),
    }
}

/// [`approx_size`] of a table.
pub fn table_size(t: &Table) -> usize {
    2 + t
        .iter()
        .map(|(k, v)| k.len() * 2 + 6 + approx_size(v))
        .sum::<usize>()
}

// ---------------------------------------------------------------------------------------------
// Tree mutations.

/// Keys the schema does not know (typos, odd characters, a dotted literal key).
const UNKNOWN_KEYS: &[&str] = &[
    "unknown_key",
    "fuzz",
    "dt",
    "x",
    "speed_mps_",
    "X_M",
    "Name",
    "seed2",
    "a b",
    "ключ",
    "💧",
    "",
    "__proto__",
    "kind_",
    "extra.dotted",
];

/// Applies a tree mutation; `None` when the tree offers nothing for it to act on.
pub fn apply_tree(
    kind: Kind,
    root: &mut Table,
    target: Target,
    rng: &mut Pcg64Mcg,
) -> Option<String> {
    match kind {
        Kind::DeleteKey => {
            let c = paths_where(root, &|p, v| {
                matches!(p.last(), Some(Seg::Key(_))) && !v.is_table() && !is_array_of_tables(v)
            });
            let p = pick(rng, &c)?.clone();
            remove(root, &p).then(|| format!("deleted key {}", path_text(&p)))
        }
        Kind::DeleteTable => {
            let c = paths_where(root, &|_, v| v.is_table() || is_array_of_tables(v));
            let p = pick(rng, &c)?.clone();
            remove(root, &p).then(|| format!("deleted table {}", path_text(&p)))
        }
        Kind::DuplicateArrayEntry => {
            let c = paths_where(root, &|_, v| matches!(v, Value::Array(a) if !a.is_empty()));
            let p = pick(rng, &c)?.clone();
            let Some(Value::Array(a)) = get_mut(root, &p) else {
                return None;
            };
            let i = below(rng, a.len());
            let copy = a.get(i)?.clone();
            a.insert(i + 1, copy);
            Some(format!("duplicated {}[{i}]", path_text(&p)))
        }
        Kind::InsertUnknownKey => {
            let mut c = paths_where(root, &|_, v| v.is_table());
            c.push(Vec::new());
            let p = pick(rng, &c)?.clone();
            let mut key = (*pick(rng, UNKNOWN_KEYS)?).to_string();
            let value = any_value(rng);
            let t = table_mut(root, &p)?;
            while t.contains_key(&key) {
                key.push('_');
            }
            let what = format!(
                "inserted unknown key {:?} = {} in {}",
                key,
                show(&value),
                path_text(&p)
            );
            t.insert(key, value);
            Some(what)
        }
        Kind::ChangeType => {
            let c = paths_where(root, &|_, _| true);
            let p = pick(rng, &c)?.clone();
            let new = retyped(rng, get(root, &p)?);
            let what = format!("{} retyped to {}", path_text(&p), short(&new));
            set(root, &p, new).then_some(what)
        }
        Kind::ExtremeNumber => {
            let c = paths_where(root, &|_, v| is_number(v));
            let p = pick(rng, &c)?.clone();
            let int = matches!(get(root, &p), Some(Value::Integer(_)));
            let new = extreme_value(rng, int);
            let what = format!("{} = {}", path_text(&p), show(&new));
            set(root, &p, new).then_some(what)
        }
        Kind::NearValue => {
            let c = paths_where(root, &|_, v| is_number(v));
            let p = pick(rng, &c)?.clone();
            let up = rng.random_bool(0.5);
            let as_float = rng.random_bool(0.5);
            let new = match get(root, &p)? {
                Value::Float(x) => float(if up { x * 1e3 } else { x * 1e-3 }),
                Value::Integer(n) if as_float => float(*n as f64 * if up { 1e3 } else { 1e-3 }),
                Value::Integer(n) => {
                    Value::Integer(if up { n.saturating_mul(1000) } else { n / 1000 })
                }
                _ => return None,
            };
            let what = format!(
                "{} = {} (x 1e{})",
                path_text(&p),
                show(&new),
                if up { 3 } else { -3 }
            );
            set(root, &p, new).then_some(what)
        }
        Kind::NanInf => {
            let c = paths_where(root, &|_, v| is_number(v));
            let p = pick(rng, &c)?.clone();
            let new = nan_inf(rng);
            let what = format!("{} = {}", path_text(&p), show(&new));
            set(root, &p, new).then_some(what)
        }
        Kind::PolygonDegenerate
        | Kind::PolygonBowtie
        | Kind::PolygonHuge
        | Kind::PolygonThreeNumbers
        | Kind::PolygonFarVertex => polygon(kind, root, target, rng),
        Kind::HugeArray => huge_array(root, rng),
        Kind::HugeString => huge_string(root, rng),
        Kind::PlannerKeyAtBound => planner_key_at_bound(root, rng),
        Kind::HostileName => hostile_name(root, rng),
        Kind::CampaignSeeds
        | Kind::CampaignSweep
        | Kind::CampaignConfigName
        | Kind::CampaignSuccessRadius
        | Kind::CampaignScenarios
        | Kind::CampaignPlannerKeys => campaign(kind, root, rng),
        Kind::FlipBits
        | Kind::InsertBytes
        | Kind::DeleteBytes
        | Kind::InvalidUtf8
        | Kind::Truncate => None,
    }
}

/// Marks a float written in exponent form: the tree holds it as the string
/// `FLOAT_MARK 1e300 FLOAT_MARK`, and [`float_literals`] turns the quoted string back into the
/// TOML float `1e300` after serialisation (the serialiser writes every float in full decimal).
const FLOAT_MARK: &str = "~plumetrace-fuzz-float~";

/// A float value; very large or small magnitudes are written in exponent form.
fn float(x: f64) -> Value {
    let a = x.abs();
    if !x.is_finite() || a == 0.0 || (1e-4..1e15).contains(&a) {
        Value::Float(x)
    } else {
        Value::String(format!("{FLOAT_MARK}{x:e}{FLOAT_MARK}"))
    }
}

/// Serialised text with the marked floats of [`float`] turned into TOML floats.
pub fn float_literals(text: &str) -> String {
    text.replace(&format!("\"{FLOAT_MARK}"), "")
        .replace(&format!("{FLOAT_MARK}\""), "")
        .replace(&format!("'{FLOAT_MARK}"), "")
        .replace(&format!("{FLOAT_MARK}'"), "")
        .replace(FLOAT_MARK, "")
}

/// A value as short text for reports (marked floats as floats, long values cut).
fn show(v: &Value) -> String {
    match v {
        Value::String(s) if s.starts_with(FLOAT_MARK) => s.replace(FLOAT_MARK, ""),
        Value::Float(x) if x.is_finite() && x.abs() > 0.0 && !(1e-4..1e15).contains(&x.abs()) => {
            format!("{x:e}")
        }
        _ => short(v),
    }
}

/// A value as short text for reports.
fn short(v: &Value) -> String {
    let s = float_literals(&v.to_string());
    if s.len() > 80 {
        let mut end = 80;
        while !s.is_char_boundary(end) {
            end -= 1;
        }
        format!("{}... ({} bytes)", &s[..end], s.len())
    } else {
        s
    }
}

/// A list of `[x, y]` points, if `v` is one.
fn as_points(v: &Value) -> Option<Vec<[f64; 2]>> {
    v.as_array()?
        .iter()
        .map(|p| {
            let a = p.as_array()?;
            let num = |v: &Value| match v {
                Value::Float(x) => Some(*x),
                Value::Integer(n) => Some(*n as f64),
                _ => None,
            };
            match a.as_slice() {
                [x, y] => Some([num(x)?, num(y)?]),
                _ => None,
            }
        })
        .collect()
}

fn points_value(points: &[[f64; 2]]) -> Value {
    Value::Array(
        points
            .iter()
            .map(|p| Value::Array(vec![float(p[0]), float(p[1])]))
            .collect(),
    )
}

/// A square inside the scenario's domain (or a 100 m square).
fn default_square(root: &Table) -> Vec<[f64; 2]> {
    let d = |k: &str| match root.get("domain").and_then(|d| d.get(k)) {
        Some(Value::Float(x)) => Some(*x),
        Some(Value::Integer(n)) => Some(*n as f64),
        _ => None,
    };
    let (x0, x1, y0, y1) = match (d("x_min_m"), d("x_max_m"), d("y_min_m"), d("y_max_m")) {
        (Some(a), Some(b), Some(c), Some(e)) if b - a > 40.0 && e - c > 40.0 => {
            (a + 10.0, b - 10.0, c + 10.0, e - 10.0)
        }
        _ => (0.0, 100.0, 0.0, 100.0),
    };
    vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
}

/// Finds a polygon to mutate (`op_area`, `vertices`, an entry of `subregions`), or adds one:
/// a mission's op-area, an obstacle, or for a campaign a configuration's `set` of
/// `mission.op_area`.
fn polygon_target(
    root: &mut Table,
    target: Target,
    rng: &mut Pcg64Mcg,
) -> Option<(Vec<Seg>, Vec<[f64; 2]>)> {
    let mut c = paths_where(root, &|p, v| {
        v.is_array()
            && matches!(p.last(), Some(Seg::Key(k)) if k == "op_area" || k == "vertices" || k == "mission.op_area")
    });
    c.extend(paths_where(root, &|p, v| {
        v.is_array()
            && p.len() >= 2
            && matches!(p.last(), Some(Seg::Idx(_)))
            && matches!(&p[p.len() - 2], Seg::Key(k) if k == "subregions")
    }));
    if let Some(p) = pick(rng, &c) {
        let p = p.clone();
        let pts = get(root, &p)
            .and_then(as_points)
            .filter(|v| v.len() >= 3)
            .unwrap_or_else(|| default_square(root));
        return Some((p, pts));
    }
    let square = default_square(root);
    let path = match target {
        Target::Campaign => {
            let k = ensure_config(root, rng)?;
            let cfg = root
                .get_mut("configs")?
                .as_array_mut()?
                .get_mut(k)?
                .as_table_mut()?;
            let set = cfg
                .entry("set")
                .or_insert_with(|| Value::Table(Table::new()))
                .as_table_mut()?;
            set.insert("mission.op_area".into(), points_value(&square));
            vec![
                Seg::Key("configs".into()),
                Seg::Idx(k),
                Seg::Key("set".into()),
                Seg::Key("mission.op_area".into()),
            ]
        }
        // A family has no polygon of its own; a NetCDF input is not a table.
        Target::Family | Target::Netcdf | Target::Seabed => return None,
        Target::Onboard => {
            let m = root.get_mut("mission")?.as_table_mut()?;
            m.insert("op_area".into(), points_value(&square));
            vec![Seg::Key("mission".into()), Seg::Key("op_area".into())]
        }
        Target::Scenario => {
            if let Some(Value::Table(m)) = root.get_mut("mission") {
                m.insert("op_area".into(), points_value(&square));
                vec![Seg::Key("mission".into()), Seg::Key("op_area".into())]
            } else {
                let mut obstacle = Table::new();
                obstacle.insert("name".into(), Value::String("fuzz-obstacle".into()));
                obstacle.insert("vertices".into(), points_value(&square));
                let list = root
                    .entry("obstacles")
                    .or_insert_with(|| Value::Array(Vec::new()));
                if !list.is_array() {
                    *list = Value::Array(Vec::new());
                }
                let a = list.as_array_mut()?;
                a.push(Value::Table(obstacle));
                vec![
                    Seg::Key("obstacles".into()),
                    Seg::Idx(a.len() - 1),
                    Seg::Key("vertices".into()),
                ]
            }
        }
    };
    Some((path, square))
}

fn polygon(kind: Kind, root: &mut Table, target: Target, rng: &mut Pcg64Mcg) -> Option<String> {
    let (path, pts) = polygon_target(root, target, rng)?;
    let (xs, ys): (Vec<f64>, Vec<f64>) = pts.iter().map(|p| (p[0], p[1])).unzip();
    let fold = |v: &[f64], f: fn(f64, f64) -> f64, init: f64| v.iter().copied().fold(init, f);
    let (x0, x1) = (
        fold(&xs, f64::min, f64::INFINITY),
        fold(&xs, f64::max, f64::NEG_INFINITY),
    );
    let (y0, y1) = (
        fold(&ys, f64::min, f64::INFINITY),
        fold(&ys, f64::max, f64::NEG_INFINITY),
    );
    let (a, b) = (*pts.first()?, *pts.get(1)?);
    let (value, what) = match kind {
        Kind::PolygonDegenerate => match below(rng, 6) {
            0 => (points_value(&[a, b]), "two points"),
            1 => (
                points_value(&[a, [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0], b]),
                "three collinear points",
            ),
            2 => {
                let mut p = pts.clone();
                let k = below(rng, p.len());
                p.insert(k, p[k]);
                (points_value(&p), "a repeated vertex")
            }
            3 => (points_value(&[a, a, a, a]), "four identical points"),
            4 => (points_value(&[]), "no points"),
            _ => (points_value(&[a]), "one point"),
        },
        Kind::PolygonBowtie => (
            points_value(&[[x0, y0], [x1, y1], [x1, y0], [x0, y1]]),
            "a bow-tie",
        ),
        Kind::PolygonHuge => match below(rng, 4) {
            0 => (
                points_value(&[[-1e18, -1e18], [1e18, -1e18], [1e18, 1e18], [-1e18, 1e18]]),
                "a square of side 2e18",
            ),
            1 => {
                let mut p = pts.clone();
                let k = below(rng, p.len());
                p[k] = [1e18, 1e18];
                (points_value(&p), "one vertex at (1e18, 1e18)")
            }
            2 => (
                points_value(
                    &pts.iter()
                        .map(|p| [p[0] * 1e15, p[1] * 1e15])
                        .collect::<Vec<_>>(),
                ),
                "coordinates x 1e15",
            ),
            _ => (
                points_value(&[
                    [x0, y0],
                    [x0 + 1e18, y0],
                    [x0 + 1e18, y0 + 1.0],
                    [x0, y0 + 1.0],
                ]),
                "a 1e18 m by 1 m sliver",
            ),
        },
        Kind::PolygonThreeNumbers => {
            let all = rng.random_bool(0.3);
            let k = below(rng, pts.len());
            let v = Value::Array(
                pts.iter()
                    .enumerate()
                    .map(|(i, p)| {
                        let mut xy = vec![float(p[0]), float(p[1])];
                        if all || i == k {
                            xy.push(Value::Float(0.0));
                        }
                        Value::Array(xy)
                    })
                    .collect(),
            );
            (
                v,
                if all {
                    "every vertex with 3 numbers"
                } else {
                    "a vertex with 3 numbers"
                },
            )
        }
        _ => {
            let far = *pick(rng, &[1e4, 1e6, 1e9, 1e12]).unwrap_or(&1e6);
            let mut p = pts.clone();
            let k = below(rng, p.len() + 1);
            p.insert(k, [x1 + far, y1 + far]);
            (points_value(&p), "an extra vertex far outside")
        }
    };
    let text = format!("{} = {what}", path_text(&path));
    set(root, &path, value).then_some(text)
}

fn huge_array(root: &mut Table, rng: &mut Pcg64Mcg) -> Option<String> {
    let budget = TREE_BUDGET.saturating_sub(table_size(root));
    if budget < 2_000 {
        return None;
    }
    let mut c = paths_where(root, &|_, v| v.is_array());
    if c.is_empty() {
        c = paths_where(root, &|_, v| is_number(v));
    }
    let p = pick(rng, &c)?.clone();
    let current = get(root, &p)?.clone();
    let want = log_uniform(rng, 10, 10_000);
    let (value, what) = match current.as_array() {
        Some(_) if as_points(&current).is_some_and(|v| v.len() >= 3) && rng.random_bool(0.5) => {
            let n = want.min(budget / 60).max(3);
            let pts = as_points(&current).unwrap_or_default();
            let (cx, cy) = pts.iter().fold((0.0, 0.0), |s, q| (s.0 + q[0], s.1 + q[1]));
            let (cx, cy) = (cx / pts.len() as f64, cy / pts.len() as f64);
            let r = pts
                .iter()
                .map(|q| ((q[0] - cx).powi(2) + (q[1] - cy).powi(2)).sqrt())
                .fold(1.0, f64::max)
                * 0.5;
            let circle: Vec<[f64; 2]> = (0..n)
                .map(|i| {
                    let t = std::f64::consts::TAU * i as f64 / n as f64;
                    [cx + r * t.cos(), cy + r * t.sin()]
                })
                .collect();
            (points_value(&circle), format!("a polygon of {n} vertices"))
        }
        Some(a) if !a.is_empty() => {
            let size = a.iter().map(approx_size).max().unwrap_or(25) + 2;
            let n = want.min(budget / size).max(a.len() + 1);
            let v: Vec<Value> = a.iter().cycle().take(n).cloned().collect();
            (Value::Array(v), format!("{n} entries (repeated)"))
        }
        _ => {
            let n = want.min(budget / 27).max(2);
            let v: Vec<Value> = (0..n)
                .map(|i| match i % 5 {
                    0 => extreme_value(rng, false),
                    1 => Value::Integer(i as i64),
                    _ => Value::Float(rng.random_range(-1e3..1e3)),
                })
                .collect();
            (Value::Array(v), format!("{n} numbers"))
        }
    };
    let text = format!("{} = {what}", path_text(&p));
    set(root, &p, value).then_some(text)
}

/// Names that must never reach outside an output directory or break a file written from them.
const HOSTILE_NAMES: &[&str] = &[
    "..",
    "../escaped",
    "../../escaped",
    "/tmp/escaped",
    "a/b",
    "a\\b",
    ".hidden",
    "a\u{0}b",
    "bell\u{7}",
    "new\nline",
    "-dash",
    "name with spaces",
    "é",
    "",
];

/// A key's documented bounds, read back from the registry's words for them
/// (`">= 0 and <= 100"`, `"> 0 and < 1"`, `"3..=72"`).
#[derive(Debug, Clone, Copy, PartialEq)]
enum KeyBounds {
    /// A real number: (min, min open, max, max open).
    Real(f64, bool, f64, bool),
    /// A whole number in `min..=max`.
    Whole(u64, u64),
}

fn key_bounds(words: &str) -> Option<KeyBounds> {
    if let Some((a, b)) = words.split_once("..=") {
        return Some(KeyBounds::Whole(
            a.trim().parse().ok()?,
            b.trim().parse().ok()?,
        ));
    }
    let (low, high) = words.split_once(" and ")?;
    let (min_open, min) = match low.trim().strip_prefix(">=") {
        Some(v) => (false, v),
        None => (true, low.trim().strip_prefix('>')?),
    };
    let (max_open, max) = match high.trim().strip_prefix("<=") {
        Some(v) => (false, v),
        None => (true, high.trim().strip_prefix('<')?),
    };
    Some(KeyBounds::Real(
        min.trim().parse().ok()?,
        min_open,
        max.trim().parse().ok()?,
        max_open,
    ))
}

/// Sets a key of a planner table (any table with a registered `kind`) to one end of its
/// bounds or just past it.
fn planner_key_at_bound(root: &mut Table, rng: &mut Pcg64Mcg) -> Option<String> {
    let kinds: Vec<&str> = plumetrace_planner::PLANNERS
        .iter()
        .map(|p| p.kind.name())
        .collect();
    let c = paths_where(root, &|_, v| {
        v.as_table()
            .and_then(|t| t.get("kind"))
            .and_then(Value::as_str)
            .is_some_and(|k| kinds.contains(&k))
    });
    let p = pick(rng, &c)?.clone();
    let kind = get(root, &p)?.get("kind")?.as_str()?.to_string();
    let entry = plumetrace_planner::PLANNERS
        .iter()
        .find(|e| e.kind.name() == kind)?;
    let keys: Vec<(&'static str, KeyBounds)> =
        <plumetrace_planner::CommonParams as plumetrace_core::params::Params>::keys()
            .into_iter()
            .chain((entry.keys)())
            .filter_map(|k| Some((k.name, key_bounds(&k.bounds)?)))
            .collect();
    let &(key, bounds) = pick(rng, &keys)?;
    let (value, at) = match (bounds, below(rng, 4)) {
        (KeyBounds::Whole(min, _), 0) => (
            Value::Integer(min.min(i64::MAX as u64) as i64),
            "at its minimum",
        ),
        (KeyBounds::Whole(_, max), 1) => (
            Value::Integer(max.min(i64::MAX as u64) as i64),
            "at its maximum",
        ),
        (KeyBounds::Whole(min, _), 2) => (Value::Integer(min as i64 - 1), "just below its minimum"),
        (KeyBounds::Whole(_, max), _) => (
            Value::Integer((max.min(i64::MAX as u64 - 1) + 1) as i64),
            "just above its maximum",
        ),
        (KeyBounds::Real(min, _, _, _), 0) => (float(min), "at its lower end"),
        (KeyBounds::Real(_, _, max, _), 1) => (float(max), "at its upper end"),
        (KeyBounds::Real(min, _, _, _), 2) => (
            float(min - (min.abs() * 1e-9).max(1e-9)),
            "just below its lower end",
        ),
        (KeyBounds::Real(_, _, max, _), _) => (
            float(max + (max.abs() * 1e-9).max(1e-9)),
            "just above its upper end",
        ),
    };
    let what = format!("{}.{key} = {} ({at})", path_text(&p), show(&value));
    table_mut(root, &p)?.insert(key.to_string(), value);
    Some(what)
}

fn hostile_name(root: &mut Table, rng: &mut Pcg64Mcg) -> Option<String> {
    let c = paths_where(root, &|p, v| {
        matches!(v, Value::String(_)) && matches!(p.last(), Some(Seg::Key(k)) if k == "name")
    });
    let p = pick(rng, &c)?.clone();
    let name = if below(rng, 8) == 0 {
        "x".repeat(300)
    } else if below(rng, 8) == 0 {
        // another vehicle's (or the first entry's) name: duplicates
        match get(
            root,
            &[
                Seg::Key("vehicles".into()),
                Seg::Idx(0),
                Seg::Key("name".into()),
            ],
        ) {
            Some(Value::String(s)) => s.clone(),
            _ => "auv".into(),
        }
    } else {
        (*pick(rng, HOSTILE_NAMES)?).to_string()
    };
    let what = format!("{} = {name:?}", path_text(&p));
    set(root, &p, Value::String(name)).then_some(what)
}

fn huge_string(root: &mut Table, rng: &mut Pcg64Mcg) -> Option<String> {
    let budget = TREE_BUDGET.saturating_sub(table_size(root));
    if budget < 2_000 {
        return None;
    }
    let mut c = paths_where(root, &|_, v| matches!(v, Value::String(_)));
    if c.is_empty() {
        c = paths_where(root, &|_, v| !v.is_table());
    }
    let p = pick(rng, &c)?.clone();
    let want = log_uniform(rng, 1_000, 500_000);
    let pattern = *pick(
        rng,
        &[
            "a", "é", "💧", "\\", "\"", "\n", "/", "${x}", "'", "\u{0}", "\t", "ab cd ", "\u{202e}",
        ],
    )?;
    let unit = approx_size(&Value::String(pattern.into())) - 2;
    let n = (want.min(budget) / unit.max(1)).max(1);
    let s = pattern.repeat(n);
    let what = format!(
        "{} = a string of {} x {:?} ({} bytes)",
        path_text(&p),
        n,
        pattern,
        s.len()
    );
    set(root, &p, Value::String(s)).then_some(what)
}

// ---------------------------------------------------------------------------------------------
// Campaign mutations.

/// Keys for `[configs.set]` and `[sweep]`: planner keys (bare), scenario paths (dotted), and
/// malformed paths.
const SET_KEYS: &[&str] = &[
    "beta_deg",
    "mapping",
    "threshold_v",
    "declaration",
    "declaration_along_m",
    "lane_spacing_m",
    "lost_point_eviction",
    "mapping_lines",
    "max_lost_points",
    "unknown_key",
    "kind",
    "strategy",
    "plume.vertical_diffusivity_m2ps",
    "sources.0.z_m",
    "sources.0.mass_rate_per_s",
    "sources.9.z_m",
    "sources.x.z_m",
    "mission.time_limit_s",
    "mission.op_area",
    "mission.spinup_s",
    "sim.dt_s",
    "vehicles.0.x_m",
    "vehicles.0.kind",
    "planners.nope.beta_deg",
    "planner.kind",
    "domain.x_max_m",
    "flow.mean.speed_mps",
    "output.nx",
    "seed",
    "name",
    "a..b",
    ".",
    "x.",
    ".x",
];

const PLANNER_KEYS: &[&str] = &[
    "kind",
    "speed_mps",
    "threshold_v",
    "lane_spacing_m",
    "beta_deg",
    "n_re",
    "mapping",
    "declaration",
    "max_lost_points",
    "region_timeout_s",
    "unknown_key",
    "strategy",
];

/// Index of a configuration to edit, adding `[[configs]]` (and replacing a malformed
/// `configs`) when there is none.
fn ensure_config(root: &mut Table, rng: &mut Pcg64Mcg) -> Option<usize> {
    let list = root
        .entry("configs")
        .or_insert_with(|| Value::Array(Vec::new()));
    if !is_array_of_tables(list) && !matches!(list, Value::Array(a) if a.is_empty()) {
        *list = Value::Array(Vec::new());
    }
    let a = list.as_array_mut()?;
    if a.is_empty() {
        let mut t = Table::new();
        t.insert("name".into(), Value::String("fuzz-config".into()));
        a.push(Value::Table(t));
    }
    Some(below(rng, a.len()))
}

fn config_mut(root: &mut Table, k: usize) -> Option<&mut Table> {
    root.get_mut("configs")?
        .as_array_mut()?
        .get_mut(k)?
        .as_table_mut()
}

fn campaign(kind: Kind, root: &mut Table, rng: &mut Pcg64Mcg) -> Option<String> {
    match kind {
        Kind::CampaignSeeds => {
            let v = match below(rng, 10) {
                0 => Value::Integer(0),
                1 => Value::Integer(-1),
                2 => float(4.6e18),
                3 => Value::Integer(i64::MAX),
                4 => Value::Integer(i64::MIN),
                5 => Value::Integer(*pick(rng, &[1_000, 1_000_000, 100_000_000, 4_294_967_296])?),
                6 => Value::String("10".into()),
                7 => Value::Float(1.5),
                8 => nan_inf(rng),
                _ => Value::Integer(1),
            };
            let what = format!("seeds = {}", show(&v));
            root.insert("seeds".into(), v);
            Some(what)
        }
        Kind::CampaignSuccessRadius => {
            let v = match below(rng, 4) {
                0 => nan_inf(rng),
                1 => Value::String("50".into()),
                2 => Value::Integer(50),
                _ => extreme_value(rng, false),
            };
            let what = format!("success_radius_m = {}", show(&v));
            root.insert("success_radius_m".into(), v);
            Some(what)
        }
        Kind::CampaignScenarios => {
            const NAMES: &[&str] = &[
                "nope",
                "DEMO",
                "demo ",
                "",
                "demo.toml",
                "duck-2003",
                "pompy",
            ];
            const PATHS: &[&str] = &[
                "scenario.toml",
                "plume.toml",
                "missing.toml",
                "../missing.toml",
                "sub/dir/x.toml",
                "/nonexistent-plumetrace-fuzz/x.toml",
                "fuzz-campaign.toml",
                ".toml",
                "scenario.TOML",
            ];
            let mut list: Vec<Value> = root
                .get("scenarios")
                .and_then(Value::as_array)
                .cloned()
                .unwrap_or_default();
            let s = |x: &str| Value::String(x.into());
            let what = match below(rng, 6) {
                0 => {
                    list = vec![s(pick(rng, NAMES)?)];
                    "an unknown name"
                }
                1 => {
                    list = vec![s(pick(rng, PATHS)?)];
                    "a path"
                }
                2 => {
                    let d = list.first().cloned().unwrap_or_else(|| s("demo"));
                    list.push(d);
                    "a duplicate"
                }
                3 => {
                    list.clear();
                    "an empty list"
                }
                4 => {
                    list = plumetrace_scenario::PRESETS
                        .iter()
                        .map(|p| s(p.name))
                        .collect();
                    list.push(s("scenario.toml"));
                    list.push(s("plume.toml"));
                    let n = list.len();
                    for i in (1..n).rev() {
                        list.swap(i, below(rng, i + 1));
                    }
                    "every preset and both side files"
                }
                _ => {
                    let extra = if rng.random_bool(0.5) {
                        pick(rng, NAMES)?
                    } else {
                        pick(rng, PATHS)?
                    };
                    list.push(s(extra));
                    "one more entry"
                }
            };
            let text = format!(
                "scenarios = {} ({what})",
                short(&Value::Array(list.clone()))
            );
            root.insert("scenarios".into(), Value::Array(list));
            Some(text)
        }
        Kind::CampaignConfigName => {
            let k = ensure_config(root, rng)?;
            let budget = TREE_BUDGET.saturating_sub(table_size(root)).max(100);
            let v = match below(rng, 10) {
                0 => Value::String("n".repeat(log_uniform(rng, 100, 100_000).min(budget))),
                1 => Value::String("a/b".into()),
                2 => Value::String("../../etc".into()),
                3 => Value::String("/abs".into()),
                4 => {
                    let other = root
                        .get("configs")
                        .and_then(Value::as_array)
                        .and_then(|a| a.iter().find_map(|c| c.get("name").cloned()));
                    let name = other.unwrap_or_else(|| Value::String("fuzz-config".into()));
                    // A second configuration of the same name.
                    let mut t = Table::new();
                    t.insert("name".into(), name.clone());
                    root.get_mut("configs")?
                        .as_array_mut()?
                        .push(Value::Table(t));
                    let what = format!("configs: another configuration named {name}");
                    return Some(what);
                }
                5 => Value::String(String::new()),
                6 => Value::String("   ".into()),
                7 => Value::String("a\nb".into()),
                8 => Value::String("名前, \"q\"; x=1 \\".into()),
                _ => Value::Integer(5),
            };
            let what = format!("configs[{k}].name = {}", short(&v));
            config_mut(root, k)?.insert("name".into(), v);
            Some(what)
        }
        Kind::CampaignSweep => {
            let mut sweep = match root.get("sweep") {
                Some(Value::Table(t)) if rng.random_bool(0.5) => t.clone(),
                _ => Table::new(),
            };
            let key = (*pick(rng, SET_KEYS)?).to_string();
            let budget = TREE_BUDGET.saturating_sub(table_size(root)).max(100);
            let (v, what) = match below(rng, 6) {
                0 => {
                    let n = log_uniform(rng, 2, 1_000).min(budget / 27);
                    let v = (0..n)
                        .map(|i| {
                            if i % 7 == 3 {
                                extreme_value(rng, false)
                            } else {
                                Value::Float(i as f64 * 0.5)
                            }
                        })
                        .collect();
                    (Value::Array(v), format!("{n} values"))
                }
                1 => {
                    let x = any_value(rng);
                    (
                        Value::Array(vec![x.clone(), x.clone(), x]),
                        "a value three times".into(),
                    )
                }
                2 => (Value::Array(Vec::new()), "no values".into()),
                3 => (any_value(rng), "not an array".into()),
                4 => (
                    Value::Array(vec![
                        Value::Integer(1),
                        Value::String("a".into()),
                        Value::Boolean(true),
                        Value::Array(vec![Value::Integer(1)]),
                        Value::Table(Table::new()),
                    ]),
                    "values of five types".into(),
                ),
                _ => (Value::Array(vec![any_value(rng)]), "one odd value".into()),
            };
            let text = format!("sweep.{key:?} = {} ({what})", short(&v));
            sweep.insert(key, v);
            root.insert("sweep".into(), Value::Table(sweep));
            Some(text)
        }
        Kind::CampaignPlannerKeys => {
            let k = ensure_config(root, rng)?;
            let cfg = config_mut(root, k)?;
            let what = match below(rng, 5) {
                0 | 1 => {
                    let mut t = Table::new();
                    if rng.random_bool(0.8) {
                        let kind = match below(rng, 5) {
                            0 | 1 => Value::String("lawnmower".into()),
                            2 => Value::String("amp".into()),
                            3 => Value::String("nope".into()),
                            _ => Value::Integer(3),
                        };
                        t.insert("kind".into(), kind);
                    }
                    for _ in 0..below(rng, 4) {
                        let key = (*pick(rng, PLANNER_KEYS)?).to_string();
                        t.insert(key, any_value(rng));
                    }
                    let what =
                        format!("configs[{k}].planner = {}", short(&Value::Table(t.clone())));
                    cfg.insert("planner".into(), Value::Table(t));
                    what
                }
                2 => {
                    let key = (*pick(rng, SET_KEYS)?).to_string();
                    let v = any_value(rng);
                    let what = format!("configs[{k}].set.{key:?} = {}", short(&v));
                    let set = cfg
                        .entry("set")
                        .or_insert_with(|| Value::Table(Table::new()));
                    if !set.is_table() {
                        *set = Value::Table(Table::new());
                    }
                    set.as_table_mut()?.insert(key, v);
                    what
                }
                3 => {
                    cfg.insert("planner".into(), Value::String("amp".into()));
                    format!("configs[{k}].planner = \"amp\" (not a table)")
                }
                _ => {
                    cfg.insert("set".into(), Value::Array(vec![Value::Integer(1)]));
                    format!("configs[{k}].set = [1] (not a table)")
                }
            };
            Some(what)
        }
        _ => None,
    }
}

// ---------------------------------------------------------------------------------------------
// Raw mutations.

/// Bytes worth inserting into TOML text.
const PUNCTUATION: &[u8] = b"[]\"'=\n#\\.{},\0\t\r+-eE_:";

/// Invalid UTF-8: stray bytes, bad continuations, a surrogate, an overlong encoding, a
/// five-byte form, a truncated sequence.
const INVALID_UTF8: &[&[u8]] = &[
    b"\xff",
    b"\xfe",
    b"\xc3\x28",
    b"\xa0\xa1",
    b"\xe2\x28\xa1",
    b"\xf0\x28\x8c\xbc",
    b"\xed\xa0\x80",
    b"\xc0\xaf",
    b"\xf8\x88\x80\x80\x80",
    b"\xe2\x82",
];

/// Applies a raw mutation to `bytes` and says what it did.
pub fn apply_raw(kind: Kind, bytes: &mut Vec<u8>, rng: &mut Pcg64Mcg) -> String {
    match kind {
        Kind::FlipBits => {
            let n = 1 + below(rng, 8);
            let mut at = Vec::new();
            for _ in 0..n {
                if bytes.is_empty() {
                    break;
                }
                let i = below(rng, bytes.len());
                let bit = below(rng, 8);
                bytes[i] ^= 1 << bit;
                at.push(i);
            }
            format!("flipped bits at byte offsets {at:?}")
        }
        Kind::InsertBytes => {
            let n = 1 + below(rng, 8);
            let i = below(rng, bytes.len() + 1);
            let ins: Vec<u8> = (0..n)
                .map(|_| {
                    if rng.random_bool(0.7) {
                        PUNCTUATION[below(rng, PUNCTUATION.len())]
                    } else {
                        rng.random::<u8>()
                    }
                })
                .collect();
            let what = format!("inserted {ins:?} at byte offset {i}");
            bytes.splice(i..i, ins);
            what
        }
        Kind::DeleteBytes => {
            let i = below(rng, bytes.len());
            let n = (1 + below(rng, 32)).min(bytes.len() - i);
            bytes.drain(i..i + n);
            format!("deleted {n} bytes at byte offset {i}")
        }
        Kind::InvalidUtf8 => {
            let seq = INVALID_UTF8[below(rng, INVALID_UTF8.len())];
            // Often inside a string value, where a parser might not look twice.
            let quotes: Vec<usize> = bytes
                .iter()
                .enumerate()
                .filter(|(_, b)| **b == b'"')
                .map(|(i, _)| i + 1)
                .collect();
            let i = match pick(rng, &quotes) {
                Some(q) if rng.random_bool(0.5) => *q,
                _ => below(rng, bytes.len() + 1),
            };
            bytes.splice(i..i, seq.iter().copied());
            format!("inserted invalid UTF-8 {seq:?} at byte offset {i}")
        }
        _ => {
            let n = below(rng, bytes.len() + 1);
            bytes.truncate(n);
            format!("truncated to {n} bytes")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::input_rng;

    fn demo() -> Table {
        plumetrace_scenario::find_preset("demo")
            .map(|p| p.toml)
            .unwrap_or_default()
            .parse()
            .unwrap_or_default()
    }

    #[test]
    fn paths_reach_values_and_remove_them() {
        let mut t = demo();
        let p = vec![
            Seg::Key("sources".into()),
            Seg::Idx(0),
            Seg::Key("x_m".into()),
        ];
        assert_eq!(path_text(&p), "sources[0].x_m");
        assert!(matches!(get(&t, &p), Some(Value::Float(_))));
        assert!(remove(&mut t, &p));
        assert!(get(&t, &p).is_none());
        let numbers = paths_where(&t, &|_, v| is_number(v));
        assert!(numbers.len() > 20);
    }

    #[test]
    fn every_tree_mutation_applies_to_its_seeds_and_serialises() {
        for kind in Kind::ALL.iter().filter(|k| !k.is_raw()) {
            let (mut t, target) = if kind.campaign_only() {
                (
                    crate::corpus::CAMPAIGNS[0].1.parse().unwrap_or_default(),
                    Target::Campaign,
                )
            } else {
                (demo(), Target::Scenario)
            };
            let mut rng = input_rng(3, 4);
            let what = apply_tree(*kind, &mut t, target, &mut rng);
            assert!(what.is_some(), "{kind:?}");
            let text = toml::to_string(&t).unwrap_or_default();
            assert!(!text.is_empty() && text.len() < MAX_INPUT_BYTES, "{kind:?}");
        }
    }

    #[test]
    fn the_registrys_bound_words_are_read_back() {
        assert_eq!(
            key_bounds(">= 0 and <= 100"),
            Some(KeyBounds::Real(0.0, false, 100.0, false))
        );
        assert_eq!(
            key_bounds("> 0 and < 1"),
            Some(KeyBounds::Real(0.0, true, 1.0, true))
        );
        assert_eq!(key_bounds("3..=72"), Some(KeyBounds::Whole(3, 72)));
        assert_eq!(key_bounds(""), None);
        // Every bounded key of every planner is understood.
        for e in plumetrace_planner::PLANNERS {
            for k in <plumetrace_planner::CommonParams as plumetrace_core::params::Params>::keys()
                .into_iter()
                .chain((e.keys)())
            {
                assert!(
                    k.bounds.is_empty() || key_bounds(&k.bounds).is_some(),
                    "{}.{}: {:?}",
                    e.kind.name(),
                    k.name,
                    k.bounds
                );
            }
        }
    }

    #[test]
    fn raw_mutations_handle_empty_text() {
        for kind in Kind::ALL.iter().filter(|k| k.is_raw()) {
            let mut rng = input_rng(1, 1);
            let mut b = Vec::new();
            apply_raw(*kind, &mut b, &mut rng);
        }
    }
}
