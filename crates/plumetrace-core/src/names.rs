//! Names of enum values as serde writes them, so that text outside serialised files (tables,
//! legends, command-line output) uses exactly the names in the files, from one place.

use serde::ser::{Impossible, Serialize, Serializer};
use std::fmt;

/// The serde name of a unit enum variant (`BehaviourKind::TrackIn` -> `"track_in"`); `None` for
/// values that are not unit variants.
pub fn variant_name<T: Serialize + ?Sized>(value: &T) -> Option<&'static str> {
    value.serialize(NameOnly).ok()
}

/// A serializer that accepts only unit variants and returns their name.
struct NameOnly;

#[derive(Debug)]
struct NotAName;

impl fmt::Display for NotAName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("not a unit variant")
    }
}

impl std::error::Error for NotAName {}

impl serde::ser::Error for NotAName {
    fn custom<T: fmt::Display>(_: T) -> Self {
        NotAName
    }
}

macro_rules! refuse {
    ($($f:ident($t:ty)),*) => {$(
        fn $f(self, _: $t) -> Result<Self::Ok, Self::Error> {
            Err(NotAName)
        }
    )*};
}

impl Serializer for NameOnly {
    type Ok = &'static str;
    type Error = NotAName;
    type SerializeSeq = Impossible<&'static str, NotAName>;
    type SerializeTuple = Impossible<&'static str, NotAName>;
    type SerializeTupleStruct = Impossible<&'static str, NotAName>;
    type SerializeTupleVariant = Impossible<&'static str, NotAName>;
    type SerializeMap = Impossible<&'static str, NotAName>;
    type SerializeStruct = Impossible<&'static str, NotAName>;
    type SerializeStructVariant = Impossible<&'static str, NotAName>;

    fn serialize_unit_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
    ) -> Result<&'static str, NotAName> {
        Ok(variant)
    }

    refuse!(
        serialize_bool(bool),
        serialize_i8(i8),
        serialize_i16(i16),
        serialize_i32(i32),
        serialize_i64(i64),
        serialize_u8(u8),
        serialize_u16(u16),
        serialize_u32(u32),
        serialize_u64(u64),
        serialize_f32(f32),
        serialize_f64(f64),
        serialize_char(char),
        serialize_str(&str),
        serialize_bytes(&[u8]),
        serialize_unit_struct(&'static str)
    );

    fn serialize_none(self) -> Result<&'static str, NotAName> {
        Err(NotAName)
    }
    fn serialize_some<T: Serialize + ?Sized>(self, _: &T) -> Result<&'static str, NotAName> {
        Err(NotAName)
    }
    fn serialize_unit(self) -> Result<&'static str, NotAName> {
        Err(NotAName)
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: &T,
    ) -> Result<&'static str, NotAName> {
        Err(NotAName)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> Result<&'static str, NotAName> {
        Err(NotAName)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Self::SerializeSeq, NotAName> {
        Err(NotAName)
    }
    fn serialize_tuple(self, _: usize) -> Result<Self::SerializeTuple, NotAName> {
        Err(NotAName)
    }
    fn serialize_tuple_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleStruct, NotAName> {
        Err(NotAName)
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleVariant, NotAName> {
        Err(NotAName)
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Self::SerializeMap, NotAName> {
        Err(NotAName)
    }
    fn serialize_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStruct, NotAName> {
        Err(NotAName)
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStructVariant, NotAName> {
        Err(NotAName)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rust_type_names_read_as_plain_words() {
        assert_eq!(
            plain_types("invalid type: string \"long\", expected f64\nin `x`"),
            "invalid type: string \"long\", expected a number\nin `x`"
        );
        assert_eq!(
            plain_types("invalid value: integer `-1`, expected u64"),
            "invalid value: integer `-1`, expected a whole number, 0 or more"
        );
        assert_eq!(
            plain_types("invalid value: integer `99999999999`, expected u32"),
            "invalid value: integer `99999999999`, expected a whole number from 0 to 4294967295"
        );
        // Other expectations, and words that only begin like a type, are left alone.
        for m in [
            "unknown field `a`, expected `b`",
            "expected f64x",
            "expected a boolean",
            "expected",
        ] {
            assert_eq!(plain_types(m), m);
        }
    }
    use crate::{BehaviourKind, PlanStatus};

    #[test]
    fn names_are_serdes() {
        assert_eq!(variant_name(&BehaviourKind::TrackIn), Some("track_in"));
        assert_eq!(variant_name(&BehaviourKind::GoTo), Some("go_to"));
        assert_eq!(variant_name(&PlanStatus::Finished), Some("finished"));
        assert_eq!(variant_name(&3.0), None);
        assert_eq!(variant_name("text"), None);
        for b in BehaviourKind::ALL {
            let json = serde_json::to_string(&b).unwrap_or_default();
            assert_eq!(
                json,
                format!("\"{}\"", variant_name(&b).unwrap_or_default())
            );
        }
    }
}

/// A deserializer's message with Rust's type names in plain words: `expected f64` reads
/// `expected a number`, `expected u32` `expected a whole number from 0 to 4294967295` (`u64` and
/// `usize`: `0 or more`, as every whole number TOML writes below zero is refused by its sign;
/// `i64` without a bound); the rest of the message is unchanged.
pub fn plain_types(message: &str) -> String {
    const NAMES: [(&str, &str); 12] = [
        ("f64", "a number"),
        ("f32", "a number"),
        ("usize", "a whole number, 0 or more"),
        ("u64", "a whole number, 0 or more"),
        ("u32", "a whole number from 0 to 4294967295"),
        ("u16", "a whole number from 0 to 65535"),
        ("u8", "a whole number from 0 to 255"),
        ("isize", "a whole number"),
        ("i64", "a whole number"),
        ("i32", "a whole number"),
        ("i16", "a whole number"),
        ("i8", "a whole number"),
    ];
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(at) = rest.find("expected ") {
        let (head, tail) = rest.split_at(at + "expected ".len());
        out.push_str(head);
        let word_end = tail
            .find(|c: char| !c.is_ascii_alphanumeric())
            .unwrap_or(tail.len());
        let word = &tail[..word_end];
        match NAMES.iter().find(|(rust, _)| *rust == word) {
            Some((_, plain)) => out.push_str(plain),
            None => out.push_str(word),
        }
        rest = &tail[word_end..];
    }
    out.push_str(rest);
    out
}

/// A TOML deserializer's error in plain words ([`plain_types`]): its message alone when the
/// caller names the key (and so the place), else the parser's whole report, which shows where.
pub fn toml_message(error: &toml::de::Error, at_key: bool) -> String {
    if at_key {
        plain_types(error.message())
    } else {
        plain_types(&error.to_string())
    }
}

/// The candidate nearest to `word`, when one is near enough to be what was meant: a typo of a
/// letter or two (more for long words), two letters swapped, or a candidate that `word` is a
/// part of. Used for "did you mean" in messages about unknown names.
pub fn closest<'a>(word: &str, candidates: &[&'a str]) -> Option<&'a str> {
    // Names are short; an edit distance between long strings costs their product in time and
    // memory (a 100,000-character value took 3.7 GB), and is no suggestion anyway.
    const LONGEST: usize = 200;
    if word.len() > LONGEST {
        return None;
    }
    let w = word.to_ascii_lowercase();
    let mut best: Option<(usize, &'a str)> = None;
    for &c in candidates.iter().filter(|c| c.len() <= LONGEST) {
        let lc = c.to_ascii_lowercase();
        let d = edit_distance(&w, &lc);
        let allowed = (w.chars().count().max(lc.chars().count()) / 3).max(1);
        let near = d <= allowed || (w.len() >= 3 && (lc.contains(&w) || w.contains(&lc)));
        if near && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

/// Edits (insert, delete, replace, swap two neighbours) that turn `a` into `b`.
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let (n, m) = (a.len(), b.len());
    let mut d = vec![vec![0usize; m + 1]; n + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=n {
        for j in 1..=m {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = v;
        }
    }
    d[n][m]
}

#[cfg(test)]
mod closest_tests {
    use super::closest;

    #[test]
    fn long_words_and_candidates_are_not_compared() {
        // a value of 100,000 characters with a backtick in it took 3.7 GB and 8 s
        let long = "a".repeat(100_000);
        assert_eq!(closest(&long, &["farrell", long.as_str()]), None);
        assert_eq!(
            closest("farel", &[long.as_str(), "farrell"]),
            Some("farrell")
        );
    }

    #[test]
    fn typos_find_the_key_meant_and_strangers_find_none() {
        let keys = [
            "mapping_lines",
            "mapping",
            "beta_deg",
            "lambda_s",
            "speed_mps",
        ];
        let cases = [
            ("maping_lines", Some("mapping_lines")),
            ("mapping_lnies", Some("mapping_lines")),
            ("beta", Some("beta_deg")),
            ("BETA_DEG", Some("beta_deg")),
            ("speed", Some("speed_mps")),
            ("lambda", Some("lambda_s")),
            ("colour", None),
            ("x", None),
        ];
        for (word, want) in cases {
            assert_eq!(closest(word, &keys), want, "{word}");
        }
    }
}
