//! Writing output files without ever leaving a half-written file behind.

use anyhow::{Context, Result};
use std::path::Path;

/// Writes `bytes` to `path` through a temporary file and a rename, naming the file in errors.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    plumetrace_mission::output::write_atomic(path, bytes)
        .with_context(|| format!("writing {}", path.display()))
}
