//! MOOS `.alog` files of a mission: one per vehicle with a planner, written as the mission runs
//! by the log crate's [`AlogWriter`] (navigation estimate, the planner's set-points and the
//! plume-tracing variables).

use crate::record::{Observer, RecordError, StepView};
use plumetrace_log::alog::AlogWriter;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// Writes `NAME.alog` for every named vehicle.
pub struct AlogObserver {
    writers: Vec<Option<(PathBuf, AlogWriter<BufWriter<File>>)>>,
    error: Option<RecordError>,
}

impl AlogObserver {
    /// One log per vehicle with a planner (`planned[k]`), named after it, in `dir`.
    pub fn create(dir: &Path, names: &[String], planned: &[bool]) -> std::io::Result<Self> {
        let mut writers = Vec::new();
        for (name, p) in names.iter().zip(planned) {
            if !p {
                writers.push(None);
                continue;
            }
            let path = dir.join(format!("{name}.alog"));
            let w = AlogWriter::new(
                BufWriter::new(File::create(&path)?),
                &path.display().to_string(),
                0.0,
                name,
            )?;
            writers.push(Some((path, w)));
        }
        Ok(AlogObserver {
            writers,
            error: None,
        })
    }
}

impl Observer for AlogObserver {
    fn observe(&mut self, step: &StepView<'_>) {
        if self.error.is_some() {
            return;
        }
        for (k, s, d) in step.decided() {
            let Some(Some((path, w))) = self.writers.get_mut(k) else {
                continue;
            };
            if let Err(e) = w.decision(s, d) {
                self.error = Some(RecordError::file(path, e));
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
        for (path, w) in self.writers.drain(..).flatten() {
            w.finish().map_err(|e| RecordError::file(&path, e))?;
        }
        Ok(())
    }
}
