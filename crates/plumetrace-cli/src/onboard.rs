//! `plumetrace onboard FILE`: the planner on a vehicle. Reads an onboard file, connects to the
//! front seat it names and flies the planner against it until the planner finishes, aborts, the
//! time limit passes or the link gives up; writes the snapshot log, the raw link traffic and a
//! report. Everything it runs is the onboard crate's: no simulator code is involved.

use crate::output::write_atomic;
use anyhow::{Context, Result};
use plumetrace_log::alog::{AlogWriter, AltitudeHold};
use plumetrace_log::snapshot::{Header, SnapshotLogFile};
use plumetrace_onboard::config::Onboard;
use plumetrace_onboard::config::ProtocolKind;
use plumetrace_onboard::runner::{self, RunReport};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Arguments of `plumetrace onboard`.
#[derive(Debug, clap::Args)]
pub struct OnboardArgs {
    /// The onboard file (TOML: mission geometry, planner, link, chemical input, run mode).
    pub file: PathBuf,
    /// Output directory (created if needed): `snapshots.jsonl.gz`, `link.log` (raw traffic),
    /// `chem.log` (a separate chemical input's), `run.alog` (MOOS), `onboard.json` (the report).
    #[arg(long, default_value = "onboard-out")]
    pub out: PathBuf,
    /// Only check the file (planner built against its mission, limits, link settings) and say
    /// what it would fly; connects to nothing and writes nothing.
    #[arg(long)]
    pub check: bool,
}

#[derive(Serialize)]
struct ReportFile {
    end: String,
    time_s: f64,
    nav_records: u64,
    decisions: u64,
    commands_sent: u64,
    commands_rejected: u64,
    safe_commands: u64,
    acks_given_up: u64,
    connections: u64,
    pauses: Vec<(f64, Option<f64>, String)>,
    declarations: Vec<[f64; 2]>,
    lines_accepted: u64,
    lines_rejected: std::collections::BTreeMap<&'static str, u64>,
}

impl From<&RunReport> for ReportFile {
    fn from(r: &RunReport) -> Self {
        ReportFile {
            end: format!("{:?}", r.end).to_lowercase(),
            time_s: r.time_s,
            nav_records: r.nav_records,
            decisions: r.decisions,
            commands_sent: r.commands_sent,
            commands_rejected: r.commands_rejected,
            safe_commands: r.safe_commands,
            acks_given_up: r.acks_given_up,
            connections: r.connections,
            pauses: r
                .pauses
                .iter()
                .map(|p| (p.start_s, p.end_s, p.reason.clone()))
                .collect(),
            declarations: r.declarations.iter().map(|p| [p.x, p.y]).collect(),
            lines_accepted: r.lines.accepted,
            lines_rejected: r.lines.rejected.clone(),
        }
    }
}

/// Reads an onboard file, naming it (and the line of the key, where it is written) in errors,
/// and warns of planner keys it gives that have no effect.
pub fn load(path: &std::path::Path) -> Result<Onboard> {
    let text = plumetrace_env::input::read_text(path, plumetrace_env::input::MAX_TEXT_BYTES)
        .map_err(anyhow::Error::msg)
        .with_context(|| format!("reading {}", path.display()))?;
    let line = |key: &str| plumetrace_scenario::locate::line_of(&text, key);
    let at = plumetrace_scenario::locate::at_line::<usize>;
    let onboard = Onboard::from_toml(&text)
        .map_err(|e| anyhow::anyhow!("{}{}: {e}", path.display(), at(line(&e.key))))?;
    // Keys with no effect: flown as written, but said before the vehicle goes, in the file's
    // order.
    let mut warnings: Vec<(Option<usize>, String)> = onboard
        .inert_keys
        .iter()
        .map(|(key, why)| {
            let key = format!("planner.{key}");
            let l = line(&key);
            (
                l,
                format!("warning: {}{}: {key}: {why}", path.display(), at(l)),
            )
        })
        .collect();
    warnings.sort();
    for (_, w) in warnings {
        eprintln!("{w}");
    }
    Ok(onboard)
}

/// Output files written under a temporary name beside their own and renamed together once the
/// flight is over, so that an earlier flight's files stay whole until a new one has flown; the
/// temporary files of a flight that never started are removed.
struct Pending {
    files: Vec<(PathBuf, PathBuf)>,
}

impl Pending {
    /// Creates `dir/name` under its temporary name.
    fn create(&mut self, dir: &Path, name: &str) -> Result<(std::fs::File, PathBuf)> {
        let path = plumetrace_core::file_name::join_inside(dir, name)
            .with_context(|| format!("writing into {}", dir.display()))?;
        let partial = path.with_extension(format!(
            "{}.{}.partial",
            path.extension().and_then(|e| e.to_str()).unwrap_or("out"),
            std::process::id()
        ));
        let f = std::fs::File::create(&partial)
            .with_context(|| format!("creating {}", partial.display()))?;
        self.files.push((partial, path.clone()));
        Ok((f, path))
    }

    /// Moves every file into place.
    fn commit(mut self) -> Result<()> {
        for (partial, path) in std::mem::take(&mut self.files) {
            std::fs::rename(&partial, &path)
                .with_context(|| format!("writing {}", path.display()))?;
        }
        Ok(())
    }
}

impl Drop for Pending {
    fn drop(&mut self) {
        for (partial, _) in &self.files {
            let _ = std::fs::remove_file(partial);
        }
    }
}

/// Runs the onboard process (or with `--check`, only checks its file).
pub fn run(args: &OnboardArgs) -> Result<()> {
    let onboard = load(&args.file)?;
    if args.check {
        let l = &onboard.file.link;
        crate::outln!(
            "{}: ok: planner {} over {}, commands at most {} m/s; connected to nothing",
            args.file.display(),
            onboard.planner.kind().name(),
            format!("{:?}", l.protocol).to_lowercase(),
            l.limits.max_speed_mps
        );
        return Ok(());
    }
    crate::output::create_out_dir(&args.out)?;
    fly(&onboard, args)
}

/// Connects and flies; writes every output under a temporary name ([`Pending`]).
fn fly(onboard: &Onboard, args: &OnboardArgs) -> Result<()> {
    let header = Header::new(
        &onboard.file.name,
        0,
        std::slice::from_ref(&onboard.file.name),
        &[Some(onboard.clone())],
    )?;
    let log_path = args.out.join(crate::mission::SNAPSHOT_LOG);
    let mut log = SnapshotLogFile::create(&log_path, &header)
        .with_context(|| format!("creating {}", log_path.display()))?;
    let mut pending = Pending { files: Vec::new() };
    let (traffic, _) = pending.create(&args.out, "link.log")?;
    let mut link = runner::link_for(onboard, Some(Box::new(std::io::BufWriter::new(traffic))))
        .with_context(|| format!("{}", args.file.display()))?;
    let chem_traffic = match &onboard.file.chemical {
        c if c.address.is_some() || c.device.is_some() => {
            let (f, _) = pending.create(&args.out, "chem.log")?;
            Some(Box::new(std::io::BufWriter::new(f)) as Box<dyn std::io::Write + Send>)
        }
        _ => None,
    };
    let mut chem = runner::chem_link_for(onboard, chem_traffic);
    let flow_traffic = match &onboard.file.flow {
        Some(f) if f.address.is_some() || f.device.is_some() => {
            let (f, _) = pending.create(&args.out, "flow.log")?;
            Some(Box::new(std::io::BufWriter::new(f)) as Box<dyn std::io::Write + Send>)
        }
        _ => None,
    };
    let mut flow = runner::flow_link_for(onboard, flow_traffic);
    let (alog_file, alog_path) = pending.create(&args.out, "run.alog")?;
    let start_unix = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64());
    let mut alog = run_alog(onboard, &*link, alog_file, &alog_path, start_unix)?;
    let mut log_error = None;
    let mut inputs: Vec<&mut dyn plumetrace_onboard::link::Link> = Vec::new();
    inputs.extend(chem.as_mut().map(|c| c as _));
    inputs.extend(flow.as_mut().map(|c| c as _));
    let report = runner::run_with_inputs(onboard, &mut *link, &mut inputs, &mut |s, d| {
        if log_error.is_none() {
            let written = log
                .write(0, s, d)
                .map_err(|e| e.to_string())
                .and_then(|()| alog.decision(s, d).map_err(|e| format!("run.alog: {e}")));
            if let Err(e) = written {
                log_error = Some(e);
            }
        }
    })
    .with_context(|| format!("{}", args.file.display()))?;
    drop(link);
    drop(chem);
    drop(flow);
    if let Some(e) = log_error {
        anyhow::bail!("writing {}: {e}", log_path.display());
    }
    log.finish()?;
    // What the planner reported as the run ended (a declaration it held) is posted too.
    alog.events(report.time_s, &report.ended_events)
        .and_then(|()| alog.finish())
        .and_then(|w| w.into_inner().map_err(|e| e.into_error()))
        .with_context(|| format!("writing {}", alog_path.display()))?;
    pending.commit()?;
    let file = ReportFile::from(&report);
    let json = serde_json::to_string_pretty(&file)?;
    write_atomic(&args.out.join("onboard.json"), json.as_bytes())?;
    // A flight that never heard the vehicle's navigation did nothing: what happened, and what
    // link.log says of it.
    let unheard =
        (report.end == runner::RunEnd::LinkGaveUp && report.nav_records == 0).then_some({
            if report.connections == 0 {
                ("never connected to the front seat", "link.log says why")
            } else {
                (
                    "connected, but no navigation record came from the front seat",
                    "link.log says what did",
                )
            }
        });
    let end = match report.end {
        runner::RunEnd::Finished => "the planner finished",
        runner::RunEnd::Aborted => "the planner aborted",
        runner::RunEnd::TimeLimit => "run.time_limit_s reached",
        runner::RunEnd::LinkGaveUp => match unheard {
            Some((what, log)) => &format!("the link gave up ({what} in link.give_up_s; {log})"),
            None => "the link gave up (down for link.give_up_s)",
        },
    };
    crate::outln!(
        "{}: {end}, after {:.1} s; {} navigation records, {} decisions, {} commands sent, {} rejected by the chokepoint, {} pauses, {} declarations; {} lines accepted, {} rejected; wrote {}",
        args.file.display(),
        report.time_s,
        report.nav_records,
        report.decisions,
        report.commands_sent,
        report.commands_rejected,
        report.pauses.len(),
        report.declarations.len(),
        report.lines.accepted,
        report.lines.rejected_total(),
        args.out.display()
    );
    // Said in the exit status too, so that a script (or a watch on the vehicle) does not take it
    // for a flight.
    if let Some((what, _)) = unheard {
        anyhow::bail!(
            "{}: {what} in link.give_up_s ({} s); {} says why, and the other files of the \
             attempt are beside it",
            args.file.display(),
            onboard.file.link.give_up_s,
            args.out.join("link.log").display()
        );
    }
    Ok(())
}

/// `run.alog` as the vehicle's MOOS community would log the run: the planner's postings under
/// its MOOS name, the vehicle's under the process the link learns posts them, an altitude hold
/// as the set-point the link sends.
fn run_alog(
    onboard: &Onboard,
    link: &dyn plumetrace_onboard::link::Link,
    file: std::fs::File,
    path: &Path,
    start_unix: f64,
) -> std::io::Result<AlogWriter<std::io::BufWriter<std::fs::File>>> {
    let l = &onboard.file.link;
    let (name, hold) = match l.protocol {
        ProtocolKind::Moos => (
            l.moos
                .as_ref()
                .map_or("pPlumetrace", |m| m.app_name.as_str()),
            AltitudeHold::AsDepth,
        ),
        ProtocolKind::Iver => ("pPlumetrace", AltitudeHold::AsDepth),
        ProtocolKind::Bluefin => ("pPlumetrace", AltitudeHold::AsAltitude),
    };
    let mut alog = AlogWriter::new(
        std::io::BufWriter::new(file),
        &path.display().to_string(),
        start_unix,
        name,
    )?
    .altitude_hold(hold);
    if let Some(source) = link.sensor_source() {
        alog = alog.learned_sensor_source(source);
    }
    Ok(alog)
}
