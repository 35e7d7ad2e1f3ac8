//! Reading input files safely: only regular files (a FIFO or a device would block or never
//! end), of a bounded size, and text that is valid UTF-8 (an error says where it is not).

use std::path::Path;

/// Largest scenario, campaign or planner file read, bytes.
pub const MAX_TEXT_BYTES: u64 = 64 << 20;
/// Largest data file (gridded flow or concentration) read, bytes.
pub const MAX_DATA_BYTES: u64 = 1 << 30;

/// Why an input file was not read.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// The file system refused (missing file, no permission, ...); its message is the whole
    /// error (it is not a separate cause, so a chain of causes does not repeat it).
    #[error("{0}")]
    Io(std::io::Error),
    /// A directory, FIFO or device.
    #[error("is not a regular file (a directory, FIFO or device cannot be read as input)")]
    NotRegularFile,
    /// Larger than the bound.
    #[error("is {size} bytes; at most {max} bytes are read")]
    TooLarge {
        /// Its size, bytes.
        size: u64,
        /// The bound, bytes.
        max: u64,
    },
    /// Not UTF-8 from byte `at` on.
    #[error("byte {at} (line {line}, column {column}) is not valid UTF-8")]
    NotUtf8 {
        /// Offset of the first invalid byte.
        at: usize,
        /// Its line, from 1.
        line: usize,
        /// Its column in characters, from 1.
        column: usize,
    },
}

impl From<std::io::Error> for InputError {
    fn from(e: std::io::Error) -> Self {
        InputError::Io(e)
    }
}

/// Checks that `path` is a regular file of at most `max_bytes`; returns its size.
pub fn check_file(path: &Path, max_bytes: u64) -> Result<u64, InputError> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(InputError::NotRegularFile);
    }
    if meta.len() > max_bytes {
        return Err(InputError::TooLarge {
            size: meta.len(),
            max: max_bytes,
        });
    }
    Ok(meta.len())
}

/// The UTF-8 text of a regular file of at most `max_bytes`; errors say what is wrong and, for
/// invalid UTF-8, the byte offset, line and column.
pub fn read_text(path: &Path, max_bytes: u64) -> Result<String, InputError> {
    check_file(path, max_bytes)?;
    let bytes = std::fs::read(path)?;
    utf8(bytes)
}

/// The bytes as text, or where they stop being UTF-8.
pub fn utf8(bytes: Vec<u8>) -> Result<String, InputError> {
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let before = &e.as_bytes()[..at];
        let line = before.iter().filter(|b| **b == b'\n').count() + 1;
        let start = before
            .iter()
            .rposition(|b| *b == b'\n')
            .map_or(0, |p| p + 1);
        let column = String::from_utf8_lossy(&before[start..]).chars().count() + 1;
        InputError::NotUtf8 { at, line, column }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invalid_utf8_is_located() {
        let e = utf8(b"name = \"a\"\nx = \"\xff\"".to_vec())
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert_eq!(e, "byte 16 (line 2, column 6) is not valid UTF-8");
        assert_eq!(utf8(b"ok".to_vec()).ok().as_deref(), Some("ok"));
    }

    #[test]
    fn only_regular_files_of_bounded_size_are_read() {
        let dir = std::env::temp_dir();
        assert!(check_file(&dir, 10).is_err_and(|e| e.to_string().contains("not a regular file")));
        let f = dir.join(format!("plumetrace-input-test-{}", std::process::id()));
        let _ = std::fs::write(&f, "0123456789");
        assert!(check_file(&f, 9).is_err_and(|e| e.to_string().contains("10 bytes")));
        assert_eq!(read_text(&f, 10).ok().as_deref(), Some("0123456789"));
        let _ = std::fs::remove_file(&f);
    }
}
