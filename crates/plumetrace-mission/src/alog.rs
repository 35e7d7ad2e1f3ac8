//! MOOS `.alog` files of a mission: one per vehicle with a planner, written as the mission runs
//! by the log crate's [`AlogWriter`] (navigation estimate, the planner's set-points and the
//! plume-tracing variables).

use crate::record::{Observer, RecordError, StepView};
use plumetrace_log::alog::AlogWriter;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// Writes `NAME.alog` for every named vehicle, each into a temporary file beside it that is
/// renamed when the mission finishes (an earlier run's log stays whole until then; a failed run
/// leaves no partial log).
pub struct AlogObserver {
    writers: Vec<Option<AlogFile>>,
    error: Option<RecordError>,
}

/// One vehicle's log: the writer into `partial`, renamed to `path` at the end.
struct AlogFile {
    path: PathBuf,
    partial: PathBuf,
    writer: AlogWriter<BufWriter<File>>,
}

/// Why the logs could not be started.
#[derive(Debug, thiserror::Error)]
pub enum AlogError {
    /// A vehicle's name cannot be a file name in the directory.
    #[error("vehicle {index} ({name:?}): its name cannot be a file name: {reason}")]
    Name {
        /// The vehicle's index.
        index: usize,
        /// Its name.
        name: String,
        /// Why not.
        reason: plumetrace_core::file_name::UnsafeName,
    },
    /// Two vehicles with planners share a name, so they would share a log.
    #[error("vehicles {first} and {second} are both named {name:?}; each needs its own .alog")]
    Duplicate {
        /// The first vehicle's index.
        first: usize,
        /// The second's.
        second: usize,
        /// The shared name.
        name: String,
    },
    /// A file could not be created.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// What failed.
        source: std::io::Error,
    },
}

impl AlogObserver {
    /// One log per vehicle with a planner (`planned[k]`), named after it, in `dir`. A name that
    /// is not one plain file name inside `dir` (a separator, `..`, a NUL), or that two such
    /// vehicles share, is refused before anything is written.
    pub fn create(dir: &Path, names: &[String], planned: &[bool]) -> Result<Self, AlogError> {
        let mut paths = Vec::new();
        for (k, (name, p)) in names.iter().zip(planned).enumerate() {
            if !p {
                paths.push(None);
                continue;
            }
            let path = plumetrace_core::file_name::join_inside(dir, &format!("{name}.alog"))
                .map_err(|reason| AlogError::Name {
                    index: k,
                    name: name.clone(),
                    reason,
                })?;
            if let Some(j) = (0..k).find(|&j| planned[j] && names[j] == *name) {
                return Err(AlogError::Duplicate {
                    first: j,
                    second: k,
                    name: name.clone(),
                });
            }
            paths.push(Some((name, path)));
        }
        let mut obs = AlogObserver {
            writers: Vec::new(),
            error: None,
        };
        for entry in paths {
            let Some((name, path)) = entry else {
                obs.writers.push(None);
                continue;
            };
            let partial = path.with_extension(format!("alog.{}.partial", std::process::id()));
            let io = |e| AlogError::Io {
                path: partial.display().to_string(),
                source: e,
            };
            let file = File::create(&partial).map_err(io)?;
            // pushed before the header is written, so that a failure removes the file
            let writer =
                AlogWriter::new(BufWriter::new(file), &path.display().to_string(), 0.0, name);
            match writer {
                Ok(writer) => obs.writers.push(Some(AlogFile {
                    path,
                    partial,
                    writer,
                })),
                Err(e) => {
                    let _ = std::fs::remove_file(&partial);
                    return Err(io(e));
                }
            }
        }
        Ok(obs)
    }
}

impl Drop for AlogObserver {
    /// A mission that ends in an error leaves no partial logs behind.
    fn drop(&mut self) {
        for f in self.writers.iter().flatten() {
            let _ = std::fs::remove_file(&f.partial);
        }
    }
}

impl Observer for AlogObserver {
    fn observe(&mut self, step: &StepView<'_>) {
        if self.error.is_some() {
            return;
        }
        for (k, s, d) in step.decided() {
            let Some(Some(f)) = self.writers.get_mut(k) else {
                continue;
            };
            if let Err(e) = f.writer.decision(s, d) {
                self.error = Some(RecordError::file(&f.path, e));
                return;
            }
        }
        // What a planner reported as the world ended its run (a declaration it held).
        for (k, events) in step.ended {
            let Some(Some(f)) = self.writers.get_mut(*k) else {
                continue;
            };
            if let Err(e) = f.writer.events(step.report.t_s, events) {
                self.error = Some(RecordError::file(&f.path, e));
                return;
            }
        }
    }

    fn wants_snapshots(&self) -> bool {
        true
    }

    fn finish(&mut self) -> Result<(), RecordError> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        for f in self.writers.drain(..).flatten() {
            let AlogFile {
                path,
                partial,
                writer,
            } = f;
            let done = writer
                .finish()
                .and_then(|w| w.into_inner().map_err(|e| e.into_error()))
                .and_then(|file| file.sync_all())
                .and_then(|()| std::fs::rename(&partial, &path));
            if let Err(e) = done {
                let _ = std::fs::remove_file(&partial);
                return Err(RecordError::file(&path, e));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn names_that_would_leave_the_directory_or_share_a_log_are_refused_before_writing() {
        let root =
            std::env::temp_dir().join(format!("plumetrace-alog-names-{}", std::process::id()));
        let dir = root.join("out");
        std::fs::create_dir_all(&dir).unwrap();
        for bad in ["../up", "/abs", "a/b", "../..", "a\0b"] {
            let names = vec!["ok".to_string(), bad.to_string()];
            let e = AlogObserver::create(&dir, &names, &[true, true])
                .err()
                .unwrap();
            assert!(e.to_string().starts_with("vehicle 1 ("), "{bad:?}: {e}");
        }
        let twins = vec!["auv".to_string(), "auv".to_string()];
        let e = AlogObserver::create(&dir, &twins, &[true, true])
            .err()
            .unwrap();
        assert_eq!(
            e.to_string(),
            "vehicles 0 and 1 are both named \"auv\"; each needs its own .alog"
        );
        assert!(AlogObserver::create(&dir, &twins, &[true, false]).is_ok());
        let listed = |d: &Path| std::fs::read_dir(d).unwrap().count();
        assert_eq!(
            listed(&dir),
            0,
            "nothing written, partial logs removed on drop"
        );
        assert_eq!(listed(&root), 1, "nothing beside the directory");
        let _ = std::fs::remove_dir_all(&root);
    }
}
