//! Serde for numbers that may not be finite: finite values as numbers, the others as the strings
//! `"NaN"`, `"inf"` and `"-inf"` (JSON has no non-finite numbers). Used on commands, so that a
//! logged command a planner got wrong reads back exactly as it was.

use serde::de::{self, Visitor};
use serde::{Deserializer, Serializer};
use std::fmt;

/// Writes `v` as a number, or as `"NaN"`, `"inf"` or `"-inf"`.
pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
    if v.is_finite() {
        s.serialize_f64(*v)
    } else if v.is_nan() {
        s.serialize_str("NaN")
    } else if *v > 0.0 {
        s.serialize_str("inf")
    } else {
        s.serialize_str("-inf")
    }
}

/// Reads a number, or one of `"NaN"`, `"inf"`, `"-inf"`.
pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    d.deserialize_any(AnyF64)
}

struct AnyF64;

impl Visitor<'_> for AnyF64 {
    type Value = f64;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a number, or \"NaN\", \"inf\" or \"-inf\"")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<f64, E> {
        Ok(v)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<f64, E> {
        Ok(v as f64)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<f64, E> {
        Ok(v as f64)
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<f64, E> {
        match v {
            "NaN" => Ok(f64::NAN),
            "inf" => Ok(f64::INFINITY),
            "-inf" => Ok(f64::NEG_INFINITY),
            other => Err(E::invalid_value(de::Unexpected::Str(other), &self)),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::{Command, Heading, VerticalCommand};

    #[test]
    fn non_finite_commands_round_trip() {
        let c = Command {
            heading: Heading::from_rad(f64::NAN),
            speed_mps: f64::INFINITY,
            vertical: VerticalCommand::Depth(f64::NEG_INFINITY),
        };
        let text = serde_json::to_string(&c).unwrap_or_default();
        assert_eq!(
            text,
            r#"{"heading":{"rad":"NaN"},"speed_mps":"inf","vertical":{"depth":"-inf"}}"#
        );
        let back: Command = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}"));
        assert!(back.heading.rad().is_nan() && back.speed_mps == f64::INFINITY);
        assert_eq!(back.vertical, VerticalCommand::Depth(f64::NEG_INFINITY));
        // Finite values stay numbers.
        let ok = Command {
            heading: Heading::from_deg(90.0),
            speed_mps: 1.5,
            vertical: VerticalCommand::Altitude(2.0),
        };
        let text = serde_json::to_string(&ok).unwrap_or_default();
        assert!(text.contains(r#""speed_mps":1.5"#) && text.contains(r#"{"altitude":2.0}"#));
        assert!(serde_json::from_str::<Command>(&text.replace("1.5", "\"fast\"")).is_err());
    }
}
