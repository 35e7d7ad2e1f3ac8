//! Writing a snapshot log to a file (gzip-compressed, named only once complete) and opening one
//! for reading, compressed or plain.

use super::Header;
use crate::LogError;
use flate2::Compression;
use flate2::read::MultiGzDecoder;
use flate2::write::GzEncoder;
use plumetrace_core::{Decision, SensorSnapshot};
use serde::Serialize;
use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

/// One decision line (borrowed, for writing).
#[derive(Serialize)]
struct LineRef<'a> {
    vehicle: u32,
    snapshot: &'a SensorSnapshot,
    decision: &'a Decision,
}

/// Writes the log: gzip-compressed into a temporary file beside `path`, renamed to `path` by
/// [`SnapshotLogFile::finish`] (a crash leaves no partial log under the name).
pub struct SnapshotLogFile {
    // serde_json writes token by token; the encoder is fed in large blocks (it clears its
    // output buffer at every write).
    out: Option<BufWriter<GzEncoder<BufWriter<File>>>>,
    tmp: PathBuf,
    path: PathBuf,
}

impl SnapshotLogFile {
    /// Starts the log at `path` (conventionally `snapshots.jsonl.gz`) with `header`.
    pub fn create(path: &Path, header: &Header) -> std::io::Result<Self> {
        let tmp = path.with_extension("gz.tmp");
        let file = File::create(&tmp)?;
        let gz = GzEncoder::new(BufWriter::new(file), Compression::fast());
        let mut out = BufWriter::with_capacity(1 << 16, gz);
        serde_json::to_writer(&mut out, header)?;
        out.write_all(b"\n")?;
        Ok(SnapshotLogFile {
            out: Some(out),
            tmp,
            path: path.to_path_buf(),
        })
    }

    /// Where the log goes.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Appends one decision line.
    pub fn write(
        &mut self,
        vehicle: u32,
        snapshot: &SensorSnapshot,
        decision: &Decision,
    ) -> Result<(), LogError> {
        let Some(out) = self.out.as_mut() else {
            return Err(LogError::Finished);
        };
        let line = LineRef {
            vehicle,
            snapshot,
            decision,
        };
        serde_json::to_writer(&mut *out, &line)?;
        out.write_all(b"\n")?;
        Ok(())
    }

    /// Completes the file and gives it its name.
    pub fn finish(&mut self) -> Result<(), LogError> {
        let what = |error: std::io::Error| LogError::Finish {
            path: self.path.clone(),
            error,
        };
        let Some(out) = self.out.take() else {
            return Ok(());
        };
        let gz = out.into_inner().map_err(|e| what(e.into_error()))?;
        let mut inner = gz.finish().map_err(what)?;
        inner.flush().map_err(what)?;
        drop(inner);
        std::fs::rename(&self.tmp, &self.path).map_err(what)
    }
}

impl Drop for SnapshotLogFile {
    /// A log that was never finished is removed, not left half-written.
    fn drop(&mut self) {
        if self.out.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Opens a snapshot log for reading, gzip-compressed or plain.
pub fn open(path: &Path) -> std::io::Result<Box<dyn BufRead>> {
    let mut file = File::open(path)?;
    let mut magic = [0u8; 2];
    let n = file.read(&mut magic)?;
    let file = File::open(path)?;
    Ok(if n == 2 && magic == [0x1f, 0x8b] {
        Box::new(BufReader::new(MultiGzDecoder::new(file)))
    } else {
        Box::new(BufReader::new(file))
    })
}

#[cfg(test)]
mod tests {
    use super::super::{FORMAT, Line, VERSION, read_header};
    use super::*;
    use plumetrace_core::{Command, Heading, NavEstimate, PlanStatus, VehicleId, VerticalCommand};

    fn header() -> Header {
        Header {
            format: FORMAT.into(),
            version: VERSION,
            scenario: "t".into(),
            seed: 3,
            vehicles: Vec::new(),
        }
    }

    fn snapshot(t: f64) -> SensorSnapshot {
        SensorSnapshot {
            time_s: t,
            vehicle: VehicleId(0),
            nav: NavEstimate {
                pos_m: None,
                heading: Heading::from_deg(10.0),
                speed_mps: 1.0,
                altitude_m: None,
                depth_m: None,
                last_fix_s: None,
            },
            chem: Vec::new(),
            flow: None,
            ranges: None,
            inbox: Vec::new(),
        }
    }

    #[test]
    fn a_finished_log_reads_back_line_by_line_and_an_unfinished_one_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
        let path = dir.path().join("snapshots.jsonl.gz");
        let decision = Decision::new(
            Command {
                heading: Heading::from_deg(90.0),
                speed_mps: 1.5,
                vertical: VerticalCommand::Depth(2.0),
            },
            PlanStatus::Running,
        );
        let mut log = SnapshotLogFile::create(&path, &header()).unwrap_or_else(|e| panic!("{e}"));
        for t in [0.0, 0.5] {
            assert!(log.write(0, &snapshot(t), &decision).is_ok());
        }
        assert!(
            !path.exists(),
            "no log under its name before it is finished"
        );
        assert!(log.finish().is_ok());
        assert!(matches!(
            log.write(0, &snapshot(1.0), &decision),
            Err(LogError::Finished)
        ));
        let lines: Vec<String> = open(&path)
            .unwrap_or_else(|e| panic!("{e}"))
            .lines()
            .map(|l| l.unwrap_or_default())
            .collect();
        assert_eq!(lines.len(), 3);
        assert_eq!(read_header(&lines[0]).ok(), Some(header()));
        let second: Line = serde_json::from_str(&lines[2]).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(second.snapshot, snapshot(0.5));
        assert_eq!(second.decision, decision);

        let other = dir.path().join("other.jsonl.gz");
        drop(SnapshotLogFile::create(&other, &header()).unwrap_or_else(|e| panic!("{e}")));
        let left: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap_or_else(|e| panic!("{e}"))
            .flatten()
            .map(|e| e.file_name())
            .collect();
        assert_eq!(left, vec![std::ffi::OsString::from("snapshots.jsonl.gz")]);
    }
}
