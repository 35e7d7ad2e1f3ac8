//! Helpers of the crate's unit tests that read files: a file written under the system's
//! temporary directory, and an op-area rectangle.

use crate::domain::Rect;
use std::path::PathBuf;

/// Writes `bytes` as `name` in `dir` under the temporary directory (made if needed).
pub fn tmp_in(dir: &str, name: &str, bytes: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(dir);
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// The rectangle `x0..x1` x `y0..y1`, which a test knows to be valid.
pub fn rect(x0: f64, x1: f64, y0: f64, y1: f64) -> Rect {
    Rect::new(x0, x1, y0, y1).unwrap()
}
