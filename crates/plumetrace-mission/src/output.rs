//! Writing output files without ever leaving a half-written file behind.

use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` through a temporary file beside it and a rename, so a crash never
/// leaves a truncated file where a complete one was. The temporary file's name is unique to the
/// process and the call, so two writers never share one.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    static CALLS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = path.with_extension(format!(
        "{}.{}-{n}.tmp",
        path.extension().and_then(|e| e.to_str()).unwrap_or("out"),
        std::process::id()
    ));
    let written = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// The key path of the first number in `value` that is not finite; outputs are checked with it
/// before they are written.
pub use plumetrace_core::first_non_finite;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporary_files_are_unique_and_cleaned_up() {
        let dir = std::env::temp_dir().join(format!("plumetrace-atomic-{}", std::process::id()));
        let _ = std::fs::create_dir_all(&dir);
        let p = dir.join("a.json");
        assert!(write_atomic(&p, b"1").is_ok());
        assert!(write_atomic(&dir.join("missing/b.json"), b"1").is_err());
        let names: Vec<String> = std::fs::read_dir(&dir)
            .map(|d| {
                d.flatten()
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        assert_eq!(names, ["a.json"], "no temporary file left");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
