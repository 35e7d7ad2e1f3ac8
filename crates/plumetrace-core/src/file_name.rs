//! Names that become file names (a vehicle's `.alog`, a family's sites): the one character set
//! and length every reader checks, and the join every writer uses so that no name, however
//! written, reaches outside its output directory.

use std::path::{Component, Path, PathBuf};

/// The longest name that may become part of a file name, in bytes.
pub const MAX_NAME_LEN: usize = 64;

/// Why a name cannot be part of a file name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum UnsafeName {
    /// The name is empty.
    #[error("is empty")]
    Empty,
    /// The name is longer than [`MAX_NAME_LEN`] bytes.
    #[error("is {0} bytes long; the limit is {MAX_NAME_LEN}")]
    TooLong(usize),
    /// The name starts with something other than a letter or digit.
    #[error("starts with {0:?}; start it with a letter or digit")]
    Start(char),
    /// The name holds a character outside the safe set.
    #[error("holds {0:?}; use only letters, digits, '-', '_' and '.'")]
    Character(char),
    /// The joined path would not be a plain file directly inside the directory.
    #[error("'{0}' is not a plain file name inside the output directory")]
    Escapes(String),
}

/// Checks that `name` can be part of a file name: 1 to [`MAX_NAME_LEN`] bytes of ASCII letters,
/// digits, `-`, `_` and `.`, starting with a letter or digit (so never `..`, a hidden file, a
/// path separator or a control character).
pub fn check_name(name: &str) -> Result<(), UnsafeName> {
    if name.is_empty() {
        return Err(UnsafeName::Empty);
    }
    if name.len() > MAX_NAME_LEN {
        return Err(UnsafeName::TooLong(name.len()));
    }
    for (i, c) in name.chars().enumerate() {
        if i == 0 && !c.is_ascii_alphanumeric() {
            return Err(UnsafeName::Start(c));
        }
        if !(c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.')) {
            return Err(UnsafeName::Character(c));
        }
    }
    Ok(())
}

/// `dir/file_name`, refused unless `file_name` is one plain component (no separator, `..`, root
/// or prefix), so the path stays directly inside `dir` whatever the name.
pub fn join_inside(dir: &Path, file_name: &str) -> Result<PathBuf, UnsafeName> {
    let mut parts = Path::new(file_name).components();
    match (parts.next(), parts.next()) {
        (Some(Component::Normal(p)), None)
            if p == file_name && !file_name.contains(['/', '\\', '\0']) =>
        {
            Ok(dir.join(file_name))
        }
        _ => Err(UnsafeName::Escapes(file_name.to_string())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_checked_against_the_safe_set() {
        for good in [
            "remus",
            "leader-left",
            "a",
            "auv_2",
            "v1.2",
            &"x".repeat(64),
        ] {
            assert_eq!(check_name(good), Ok(()), "{good}");
        }
        let cases: &[(&str, UnsafeName)] = &[
            ("", UnsafeName::Empty),
            ("..", UnsafeName::Start('.')),
            ("../x", UnsafeName::Start('.')),
            ("/etc/x", UnsafeName::Start('/')),
            ("a/b", UnsafeName::Character('/')),
            ("a\0b", UnsafeName::Character('\0')),
            ("a b", UnsafeName::Character(' ')),
            ("a\u{7}", UnsafeName::Character('\u{7}')),
            ("-x", UnsafeName::Start('-')),
            ("é", UnsafeName::Start('é')),
            ("aé", UnsafeName::Character('é')),
        ];
        for (name, want) in cases {
            assert_eq!(check_name(name).as_ref(), Err(want), "{name:?}");
        }
        assert_eq!(check_name(&"x".repeat(65)), Err(UnsafeName::TooLong(65)));
    }

    #[test]
    fn joins_stay_inside_the_directory() {
        let dir = Path::new("out");
        assert_eq!(join_inside(dir, "a.alog"), Ok(dir.join("a.alog")));
        assert_eq!(
            join_inside(dir, "vehicles[0].alog"),
            Ok(dir.join("vehicles[0].alog"))
        );
        for bad in [
            "",
            "..",
            ".",
            "../a.alog",
            "/a.alog",
            "a/b.alog",
            "a/",
            "./a",
            "a\0b",
        ] {
            assert!(join_inside(dir, bad).is_err(), "{bad:?}");
        }
    }
}
