//! What happened to an input, and the rule that decides whether an error message is located.
//!
//! # The location rule
//!
//! An error message is *located* when it names the input's file (`fuzz.toml` or
//! `fuzz-campaign.toml`) **and** at least one of:
//!
//! 1. a position: `line N`, `column N`, `byte N` or `offset N` (N digits; TOML syntax errors,
//!    and byte offsets for invalid UTF-8), or the file's name followed by `:N` (`fuzz.toml:3:`);
//! 2. a key named by serde, ``field `NAME` `` (`missing field`, `unknown field`), or by a campaign's
//!    list of missing keys, ``missing key `NAME` `` or ``missing keys `NAME` ``;
//! 3. a key path: a `": "`-separated part of the message that starts with a key path,
//!    `IDENT` followed by `.segment` or `[N]` steps (`sources[0].x_m`, `sweep.beta_deg`,
//!    `configs.paper.set.mapping`), where a path of one key (`seeds`), or a path whose first
//!    key is not an identifier (`a b`), only counts when that key is a key of the corpus or is
//!    written as a key in the input (so `error: ...` or `invalid type: ...` never count).
//!    Parts that are file names (ending in `.toml` or `.csv`) are skipped, and a `.` must be
//!    followed by a segment (`output.: ...` names no key).
//!
//! Anything else that rejects an input is *unlocated* (a finding).

use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;
use std::sync::OnceLock;

/// The class of an input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Class {
    /// Checked (and run briefly) without complaint.
    Accepted,
    /// Rejected with a message that names the file and a key path or position.
    RejectedLocated,
    /// Rejected with a message that does not say where (a finding).
    RejectedUnlocated,
    /// Panicked (a finding).
    Panic,
    /// Accepted, but a summary, trajectory or concentration was not finite (a finding).
    NonfiniteOutput,
    /// Exceeded the per-input time limit (a finding).
    Hang,
    /// Killed its process: failed allocation, stack overflow, ... (a finding).
    Abort,
}

impl Class {
    /// Every class, in report order.
    pub const ALL: [Class; 7] = [
        Class::Accepted,
        Class::RejectedLocated,
        Class::RejectedUnlocated,
        Class::Panic,
        Class::NonfiniteOutput,
        Class::Hang,
        Class::Abort,
    ];

    /// Snake-case name (serde's).
    pub fn name(self) -> &'static str {
        match self {
            Class::Accepted => "accepted",
            Class::RejectedLocated => "rejected_located",
            Class::RejectedUnlocated => "rejected_unlocated",
            Class::Panic => "panic",
            Class::NonfiniteOutput => "nonfinite_output",
            Class::Hang => "hang",
            Class::Abort => "abort",
        }
    }

    /// Whether it is a finding (something to fix).
    pub fn is_finding(self) -> bool {
        !matches!(self, Class::Accepted | Class::RejectedLocated)
    }
}

/// The class of a rejection with `message` of an input written to `file_name` with text
/// `input`.
pub fn classify_rejection(message: &str, file_name: &str, input: &str) -> Class {
    if is_located(message, file_name, input) {
        Class::RejectedLocated
    } else {
        Class::RejectedUnlocated
    }
}

/// The location rule (see the module documentation).
pub fn is_located(message: &str, file_name: &str, input: &str) -> bool {
    if !names_file(message, file_name) {
        return false;
    }
    if has_position(message)
        || at_line(message, file_name)
        || ["field `", "missing key `", "missing keys `"]
            .iter()
            .any(|w| message.contains(w))
    {
        return true;
    }
    message
        .split(": ")
        .any(|part| key_path_part(part.trim(), input))
}

/// What follows each place `message` names `file_name` as a whole file name (not a longer name
/// ending in it).
fn after_file<'a>(message: &'a str, file_name: &'a str) -> impl Iterator<Item = &'a str> + 'a {
    message.match_indices(file_name).filter_map(move |(i, _)| {
        let before = message[..i].chars().next_back();
        before
            .is_none_or(|c| !(c.is_alphanumeric() || c == '-' || c == '_' || c == '.'))
            .then(|| &message[i + file_name.len()..])
    })
}

/// Whether `message` names `file_name` as a whole file name.
fn names_file(message: &str, file_name: &str) -> bool {
    after_file(message, file_name).next().is_some()
}

/// Whether `message` gives a line of `file_name` as `FILE:N`.
fn at_line(message: &str, file_name: &str) -> bool {
    after_file(message, file_name).any(|rest| {
        rest.strip_prefix(':')
            .is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()))
    })
}

/// `line N`, `column N`, `byte N` or `offset N`, case-insensitively.
fn has_position(message: &str) -> bool {
    let lower = message.to_lowercase();
    ["line ", "column ", "byte ", "offset "].iter().any(|w| {
        lower
            .match_indices(w)
            .any(|(i, _)| lower[i + w.len()..].starts_with(|c: char| c.is_ascii_digit()))
    })
}

fn is_ident_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '_'
}

fn is_ident_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '-'
}

/// Whether a `": "`-separated part of a message starts with a key path.
fn key_path_part(part: &str, input: &str) -> bool {
    if part.ends_with(".toml") || part.ends_with(".csv") {
        return false;
    }
    if part.is_empty() || part.starts_with(char::is_whitespace) || part.contains('\n') {
        return false;
    }
    let end = part.find(['.', '[']).unwrap_or(part.len());
    let (first, rest) = part.split_at(end);
    let ident = first.starts_with(is_ident_start) && first.chars().all(is_ident_char);
    // A bare identifier, or any first segment that is not one (a quoted key such as `"a b"`),
    // must be a known key; an identifier followed by `.x` or `[N]` is a path as it stands.
    if (rest.is_empty() || !ident) && !is_known_key(first, input) {
        return false;
    }
    if rest.is_empty() {
        return true;
    }
    let mut chars = rest.chars();
    match chars.next() {
        Some('.') => chars.next().is_some_and(|c| !c.is_whitespace()),
        Some('[') => {
            let inner: String = chars.take_while(|c| *c != ']').collect();
            !inner.is_empty() && inner.chars().all(|c| c.is_ascii_digit())
        }
        _ => false,
    }
}

/// Whether `ident` is a key of some corpus seed or appears as a key in `input`.
fn is_known_key(ident: &str, input: &str) -> bool {
    corpus_keys().contains(ident) || appears_as_key(input, ident)
}

/// Every key of every corpus seed (and its side files).
fn corpus_keys() -> &'static BTreeSet<String> {
    static KEYS: OnceLock<BTreeSet<String>> = OnceLock::new();
    KEYS.get_or_init(|| {
        fn walk(v: &toml::Value, out: &mut BTreeSet<String>) {
            match v {
                toml::Value::Table(t) => {
                    for (k, c) in t {
                        out.insert(k.clone());
                        walk(c, out);
                    }
                }
                toml::Value::Array(a) => a.iter().for_each(|c| walk(c, out)),
                _ => {}
            }
        }
        let mut out = BTreeSet::new();
        for s in crate::corpus::seeds() {
            if let Ok(t) = s.text.parse::<toml::Table>() {
                walk(&toml::Value::Table(t), &mut out);
            }
        }
        out
    })
}

/// Whether `key` is written as a key in `text`: preceded by the start of a line, a space, `[`,
/// `.`, `{`, `,` or a quote, and followed (after spaces and a closing quote) by `=`, `.` or `]`.
fn appears_as_key(text: &str, key: &str) -> bool {
    if key.is_empty() {
        return false;
    }
    text.match_indices(key).any(|(i, _)| {
        let before = text[..i].chars().next_back();
        let ok_before = before
            .is_none_or(|c| matches!(c, ' ' | '\t' | '\n' | '[' | '.' | '{' | ',' | '"' | '\''));
        let after = text[i + key.len()..]
            .trim_start_matches(['"', '\''])
            .trim_start();
        ok_before && after.starts_with(['=', '.', ']'])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const INPUT: &str = "seed = 1\nseeds = 3\n\"a b\" = 1979-05-27\n[sim]\ndt_s = 0.1\n";

    #[test]
    fn located_messages() {
        for m in [
            "/tmp/x/fuzz.toml: sources[0].mass_rate_per_s: must be a finite number >= 0, got -5",
            "/tmp/x/fuzz.toml: TOML parse error at line 3, column 7\n  |\n3 | x = \n  |     ^\n",
            "<tmp>/fuzz.toml: mission.op_area: the polygon intersects itself",
            "/tmp/x/fuzz.toml: missing field `sim`",
            "/tmp/x/fuzz.toml: sim: unknown field `dt`, expected one of `dt_s`, `duration_s`",
            "/tmp/x/fuzz.toml: invalid UTF-8 at byte 1234",
            "/tmp/x/fuzz.toml: spinup_dt_s: must be positive",
        ] {
            assert!(is_located(m, "fuzz.toml", INPUT), "{m}");
        }
        for m in [
            "/tmp/c/fuzz-campaign.toml: seeds: must be at least 1",
            "/tmp/c/fuzz-campaign.toml: scenario 'demo', config 'a': preset 'demo': planner.beta_deg: must be in [0, 90], got 200",
            "/tmp/c/fuzz-campaign.toml: configs.my config.set.x: not a key",
            "/tmp/c/fuzz-campaign.toml: scenarios[2]: 'nope' is neither a preset nor a path",
            "/tmp/c/fuzz-campaign.toml: a b: is a date/time",
            "/tmp/c/fuzz-campaign.toml: missing keys `name`, `seed`: every campaign file has ...",
            "/tmp/c/fuzz-campaign.toml: missing key `seeds`: every campaign file has ...",
            "/tmp/c/fuzz-campaign.toml:13: scenario 'demo', config 'b': preset 'demo': must be positive",
        ] {
            assert!(is_located(m, "fuzz-campaign.toml", INPUT), "{m}");
        }
    }

    #[test]
    fn unlocated_messages() {
        for m in [
            // No file name.
            "invalid type: string \"x\", expected f64",
            "sources[0].x_m: must be finite",
            "step 5: the flow diverged",
            // File name but nothing else.
            "/tmp/x/fuzz.toml: stream did not contain valid UTF-8",
            "/tmp/x/fuzz.toml: : the flow diverged",
            "/tmp/x/fuzz.toml: error: something went wrong",
            // Another file's line, and a key not said to be missing.
            "/tmp/x/fuzz.toml: see /tmp/x/notfuzz.toml:3: it failed",
            "/tmp/x/fuzz.toml: the key `x` failed",
            "/tmp/x/fuzz.toml: invalid type: integer `5`, expected a string",
            // An empty key segment is not a path.
            "/tmp/x/fuzz.toml: output.: is a date/time",
            // Another file (a longer name ending in the input's).
            "/tmp/x/other.toml: line 3",
            "/tmp/x/notfuzz.toml: line 3",
            "/tmp/x/fuzz-campaign.toml: seeds: must be at least 1",
        ] {
            assert!(!is_located(m, "fuzz.toml", INPUT), "{m}");
        }
        // A file name is not a key path.
        assert!(!is_located(
            "/tmp/c/fuzz-campaign.toml: scenario.toml: no such file",
            "fuzz-campaign.toml",
            INPUT
        ));
    }

    #[test]
    fn classes_and_findings() {
        assert_eq!(
            classify_rejection("fuzz.toml: line 1", "fuzz.toml", ""),
            Class::RejectedLocated
        );
        assert_eq!(
            classify_rejection("fuzz.toml: oops", "fuzz.toml", ""),
            Class::RejectedUnlocated
        );
        let findings: Vec<Class> = Class::ALL.into_iter().filter(|c| c.is_finding()).collect();
        assert_eq!(findings.len(), 5);
        assert_eq!(
            serde_json::to_string(&Class::NonfiniteOutput).unwrap_or_default(),
            "\"nonfinite_output\""
        );
    }
}
