//! Writing output files without ever leaving a half-written file behind.

use anyhow::{Context, Result};
use std::path::Path;

/// Writes `bytes` to `path` through a temporary file and a rename, naming the file in errors.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    plumetrace_mission::output::write_atomic(path, bytes)
        .with_context(|| format!("writing {}", path.display()))
}

/// Creates the output directory `out` (and its parents) if needed; a file already there is
/// refused as such, rather than with the system's "File exists".
pub fn create_out_dir(out: &Path) -> Result<()> {
    if out.exists() && !out.is_dir() {
        anyhow::bail!(
            "--out {}: is a file, not a directory; give a directory (created if needed)",
            out.display()
        );
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))
}

/// Refuses a run whose output directory would overwrite its own input file.
pub fn refuse_overwriting(input: &Path, out: &Path, outputs: &[&str]) -> Result<()> {
    let Ok(input) = std::fs::canonicalize(input) else {
        return Ok(());
    };
    for name in outputs {
        if std::fs::canonicalize(out.join(name)).is_ok_and(|p| p == input) {
            anyhow::bail!(
                "{}: the run would write its {name} over this input file; choose another --out",
                input.display()
            );
        }
    }
    Ok(())
}
