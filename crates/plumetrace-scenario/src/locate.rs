//! Where a key path is written in a scenario's text (its line, from the TOML parser's spans), and
//! "did you mean" for the serde layer's unknown keys and names.

use toml::de::{DeTable, DeValue};

/// The 1-based line at which `path` (`planner.beta_deg`, `vehicles[0].x_m`,
/// `planners."a b".kind`) is written in `text`: the key itself, or when it is absent (a missing
/// key, a key set from elsewhere) the deepest table on its way that is written. `None` when the
/// text does not parse or nothing of the path is in it.
pub fn line_of(text: &str, path: &str) -> Option<usize> {
    walk(text, path).map(|(line, _)| line)
}

/// The 1-based line at which `path` itself is written in `text`; `None` when it is not (unlike
/// [`line_of`], no table on its way stands in for it).
pub fn line_of_key(text: &str, path: &str) -> Option<usize> {
    walk(text, path).and_then(|(line, whole)| whole.then_some(line))
}

/// The line of the deepest step of `path` written in `text`, and whether that is all of it.
fn walk(text: &str, path: &str) -> Option<(usize, bool)> {
    let root = DeValue::Table(DeTable::parse(text).ok()?.into_inner());
    let mut here = &root;
    let mut found: Option<usize> = None;
    let steps = segments(path);
    let mut taken = 0;
    for segment in steps.iter() {
        let next = match (segment, here) {
            (Segment::Key(k), DeValue::Table(t)) => t
                .iter()
                .find(|(name, _)| name.get_ref().as_ref() == k.as_str())
                .map(|(name, value)| (name.span().start, value.get_ref())),
            (Segment::Index(i), DeValue::Array(a)) => {
                a.get(*i).map(|v| (v.span().start, v.get_ref()))
            }
            _ => None,
        };
        let Some((start, value)) = next else { break };
        found = Some(start);
        here = value;
        taken += 1;
    }
    found.map(|start| (line_at(text, start), taken == steps.len()))
}

/// The steps of a key path, however it is written: `sources[0].z_m`, `sources.0.z_m` and
/// `"sources".0."z_m"` all give `sources`, `0`, `z_m`.
pub fn path_steps(path: &str) -> Vec<String> {
    segments(path)
        .into_iter()
        .map(|s| match s {
            Segment::Key(k) => k,
            Segment::Index(i) => i.to_string(),
        })
        .collect()
}

/// The 1-based line of byte `offset` in `text`.
pub fn line_at(text: &str, offset: usize) -> usize {
    text.get(..offset)
        .map_or(0, |head| head.matches('\n').count())
        + 1
}

/// One step of a key path.
#[derive(Debug, PartialEq)]
enum Segment {
    Key(String),
    Index(usize),
}

/// The steps of a key path as the errors write them: dotted keys (quoted when not plain words)
/// and `[N]` indices.
fn segments(path: &str) -> Vec<Segment> {
    let mut out = Vec::new();
    let mut chars = path.chars().peekable();
    let mut key = String::new();
    let flush = |key: &mut String, out: &mut Vec<Segment>| {
        if !key.is_empty() {
            out.push(Segment::Key(std::mem::take(key)));
        }
    };
    while let Some(c) = chars.next() {
        match c {
            '"' => {
                while let Some(q) = chars.next() {
                    match q {
                        '"' => break,
                        '\\' => key.extend(chars.next()),
                        _ => key.push(q),
                    }
                }
            }
            '.' => flush(&mut key, &mut out),
            '[' => {
                flush(&mut key, &mut out);
                let index: String = chars.by_ref().take_while(|&d| d != ']').collect();
                if let Ok(i) = index.parse() {
                    out.push(Segment::Index(i));
                }
            }
            _ => key.push(c),
        }
    }
    flush(&mut key, &mut out);
    out
}

/// A TOML deserializer's message for a key of `text` ([`suggest`]'s words) with the line it
/// points at, `... (line 3)`, for files whose errors carry no line of their own.
pub fn message_with_line(error: &toml::de::Error, text: &str) -> String {
    let line = error
        .span()
        .map(|s| format!(" (line {})", line_at(text, s.start.min(text.len()))))
        .unwrap_or_default();
    format!("{}{line}", suggest(error.message()))
}

/// `:LINE` after a file name (`site.toml:12: ...`, the form editors jump to), or nothing.
pub fn at_line<L: std::fmt::Display>(line: Option<L>) -> String {
    line.map(|l| format!(":{l}")).unwrap_or_default()
}

/// serde's message for an unknown key or name (`unknown field `dtt_s`, expected `dt_s` or
/// `duration_s``, `unknown variant ...`) with the nearest known one suggested in place of the
/// list when one is near; Rust's type names in plain words ([`plumetrace_core::plain_types`]).
pub fn suggest(message: &str) -> String {
    plumetrace_core::plain_types(&suggest_near(message))
}

/// [`suggest`]'s "did you mean", any other message unchanged.
fn suggest_near(message: &str) -> String {
    let Some((what, rest)) = ["unknown field `", "unknown variant `"]
        .iter()
        .find_map(|p| message.strip_prefix(p).map(|rest| (*p, rest)))
    else {
        return message.to_string();
    };
    let Some((word, list)) = rest.split_once('`') else {
        return message.to_string();
    };
    let known: Vec<&str> = list.split('`').skip(1).step_by(2).collect();
    match plumetrace_core::closest(word, &known) {
        Some(near) => format!("{what}{word}`; did you mean `{near}`?"),
        None => message.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "name = \"x\"\n[sim]\ndt_s = 0.1\n\n[[vehicles]]\nx_m = 1.0\n\n\
                        [[vehicles]]\nx_m = 2.0\n[planners.\"a b\"]\nkind = \"amp\"\n";

    #[test]
    fn key_paths_find_their_lines_or_the_table_they_belong_to() {
        let cases = [
            ("sim.dt_s", Some(3)),
            ("sim", Some(2)),
            ("vehicles[1].x_m", Some(9)),
            ("vehicles[1]", Some(8)),
            ("planners.\"a b\".kind", Some(11)),
            ("planners.\"a b\".beta_deg", Some(10)),
            ("sim.duration_s", Some(2)),
            ("mission.time_limit_s", None),
        ];
        for (path, line) in cases {
            assert_eq!(line_of(TEXT, path), line, "{path}");
        }
        assert_eq!(line_of("not = = toml", "not"), None);
    }

    #[test]
    fn unknown_keys_and_names_get_the_nearest_known_one() {
        assert_eq!(
            suggest("unknown field `dtt_s`, expected `dt_s` or `duration_s`"),
            "unknown field `dtt_s`; did you mean `dt_s`?"
        );
        assert_eq!(
            suggest("unknown variant `farel`, expected one of `uniform`, `farrell`, `gridded`"),
            "unknown variant `farel`; did you mean `farrell`?"
        );
        let far = "unknown field `zzz`, expected `dt_s` or `duration_s`";
        assert_eq!(suggest(far), far);
        assert_eq!(suggest("invalid type"), "invalid type");
    }
}
