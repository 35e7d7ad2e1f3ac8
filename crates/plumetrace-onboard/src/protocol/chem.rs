//! The chemical sensor as a line-oriented input: either a sentence of its own (a configured id,
//! the reading in a configured field, checksum required) or the instrument's plain ASCII reading
//! (one number per line). Readings are timestamped on arrival by the caller.

use crate::protocol::sentence::{Fields, READING, SentenceError};
use serde::{Deserialize, Serialize};

/// How chemical readings arrive.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "format", deny_unknown_fields)]
pub enum ChemFormat {
    /// One plain decimal number per line (white space around it allowed).
    Plain,
    /// A sentence `$ID,...*hh` with the reading in field `field` (1-based after the id).
    Sentence {
        /// The sentence id, e.g. `PTCHM`.
        id: String,
        /// The reading's field, 1-based after the id.
        field: usize,
    },
}

impl Default for ChemFormat {
    fn default() -> Self {
        ChemFormat::Sentence {
            id: "PTCHM".into(),
            field: 2,
        }
    }
}

impl ChemFormat {
    /// Whether `line` looks like this input's (a sentence with its id, or anything for plain
    /// readings), so a link that carries other sentences too can route it.
    pub fn claims(&self, line: &str) -> bool {
        match self {
            ChemFormat::Plain => !line.trim_start().starts_with('$'),
            ChemFormat::Sentence { id, .. } => line
                .strip_prefix('$')
                .and_then(|r| r.strip_prefix(id.as_str()))
                .is_some_and(|r| r.starts_with([',', '*'])),
        }
    }

    /// The reading in `line`.
    pub fn parse(&self, line: &str) -> Result<f64, SentenceError> {
        match self {
            ChemFormat::Plain => {
                let t = line.trim();
                if t.is_empty() {
                    return Err(SentenceError::Empty);
                }
                let ok = t.len() <= 32
                    && t.bytes()
                        .all(|b| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+'));
                let v = ok
                    .then(|| t.parse::<f64>().ok())
                    .flatten()
                    .filter(|v| v.is_finite())
                    .ok_or(SentenceError::BadField {
                        id: "chemical",
                        index: 1,
                        name: "reading",
                        text: t.chars().take(32).collect(),
                        what: "a number",
                    })?;
                READING.check("chemical", "reading", v)
            }
            ChemFormat::Sentence { id, field } => {
                let f = Fields::parse(line)?;
                if f.id != id {
                    return Err(SentenceError::Unknown(f.id.to_string()));
                }
                f.expect_at_least("chemical", *field)?;
                f.f64("chemical", *field, "reading", READING)
            }
        }
    }

    /// A line carrying `reading` (what a simulated front seat sends); sentence formats put the
    /// time of day in every field before the reading's.
    pub fn encode(&self, time: crate::protocol::sentence::UtcTime, reading: f64) -> String {
        match self {
            ChemFormat::Plain => format!("{reading:.6}\r\n"),
            ChemFormat::Sentence { id, field } => {
                let mut body = crate::protocol::sentence::clean_text(id);
                for _ in 1..*field {
                    body.push_str(&format!(",{time}"));
                }
                body.push_str(&format!(",{reading:.6}"));
                crate::protocol::sentence::frame(&body)
            }
        }
    }
}
