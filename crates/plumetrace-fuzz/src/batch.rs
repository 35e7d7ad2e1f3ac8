//! A child process of a pass: runs a range of inputs in-process and appends one JSON line per
//! input to its results file, a `started` line (flushed) before the input and its
//! classification after, so the parent can tell which input killed it.
//!
//! A watchdog thread ends the process with [`HANG_EXIT_CODE`] when an input runs
//! [`WATCHDOG_GRACE_S`] past the per-input limit (the harness's own loops stop at the limit
//! itself and record a `hang` without dying; the watchdog catches everything else).

use crate::classify::Class;
use crate::generate::{Input, generate};
use crate::target::{Outcome, Workdir, install_panic_hook, run};
use anyhow::Context;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Exit status of a child whose watchdog fired.
pub const HANG_EXIT_CODE: i32 = 86;
/// The watchdog fires this long after the per-input limit, s.
pub const WATCHDOG_GRACE_S: f64 = 2.0;
/// Messages in results files are cut to this many bytes (sidecar files get more).
const RESULT_MESSAGE_BYTES: usize = 2_000;
/// Sidecar messages are cut to this many bytes.
const SIDECAR_MESSAGE_BYTES: usize = 100_000;

/// Arguments of `plumetrace-fuzz batch`.
#[derive(Debug, clap::Args)]
pub struct BatchArgs {
    /// First index.
    #[arg(long)]
    pub from: u64,
    /// One past the last index.
    #[arg(long)]
    pub to: u64,
    /// Pass seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Per-input time limit, s.
    #[arg(long, default_value_t = 30.0)]
    pub timeout_s: f64,
    /// Output directory of the pass (findings go to `DIR/findings`).
    #[arg(long)]
    pub out: PathBuf,
    /// Results file (default `DIR/batches/FROM-TO.jsonl`).
    #[arg(long)]
    pub results: Option<PathBuf>,
}

/// One line of a results file: `{"index":i,"started":true}` or the classification.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Line {
    /// Input index.
    pub index: u64,
    /// Written before the input runs.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub started: bool,
    /// The class, once finished.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub class: Option<Class>,
    /// Wall time, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub secs: Option<f64>,
    /// Took over a second.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub slow: bool,
    /// Corpus seed name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub corpus: Option<String>,
    /// The kinds of its mutations.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub mutations: Vec<String>,
    /// The message (cut).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub message: Option<String>,
}

impl Line {
    /// The line of a finished input.
    pub fn finished(input: &Input, o: &Outcome) -> Self {
        Line {
            index: input.index,
            started: false,
            class: Some(o.class),
            secs: Some(o.secs),
            slow: o.slow(),
            corpus: Some(input.corpus.to_string()),
            mutations: mutation_names(input),
            message: Some(cut(&o.message, RESULT_MESSAGE_BYTES)),
        }
    }
}

/// The names of an input's mutation kinds, without repeats.
pub fn mutation_names(input: &Input) -> Vec<String> {
    let mut names: Vec<String> = input
        .mutations
        .iter()
        .map(|m| m.kind.name().to_string())
        .collect();
    names.sort();
    names.dedup();
    names
}

/// `s` cut to at most `max` bytes at a character boundary, saying so.
pub fn cut(s: &str, max: usize) -> String {
    if s.len() <= max {
        return s.to_string();
    }
    let mut end = max;
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}... [{} bytes in all]", &s[..end], s.len())
}

/// Writes a finding: the input as `DIR/findings/CLASS/INDEX.toml` (`.bin` when not UTF-8) and
/// a sidecar `INDEX.txt` with the message, the input's making and how to replay it.
pub fn write_finding(out: &Path, input: &Input, class: Class, message: &str) -> anyhow::Result<()> {
    let dir = out.join("findings").join(class.name());
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let ext = if input.is_utf8() { "toml" } else { "bin" };
    std::fs::write(dir.join(format!("{}.{ext}", input.index)), &input.bytes)?;
    let sidecar = format!(
        "{}: {}\n\n{}\nreplay: plumetrace-fuzz one --index {} --seed {}\n",
        class.name(),
        cut(message, SIDECAR_MESSAGE_BYTES),
        input.describe(),
        input.index,
        input.seed
    );
    std::fs::write(dir.join(format!("{}.txt", input.index)), sidecar)?;
    Ok(())
}

/// The input being run and since when, for the watchdog.
type Current = Arc<Mutex<Option<(u64, Instant)>>>;

/// Starts the watchdog: ends the process with [`HANG_EXIT_CODE`] when the current input runs
/// longer than `timeout_s` + [`WATCHDOG_GRACE_S`].
pub fn start_watchdog(timeout_s: f64) -> Current {
    let current: Current = Arc::new(Mutex::new(None));
    let limit = Duration::try_from_secs_f64(timeout_s + WATCHDOG_GRACE_S)
        .unwrap_or(Duration::from_secs(32));
    let seen = Arc::clone(&current);
    std::thread::spawn(move || {
        loop {
            std::thread::sleep(Duration::from_millis(100));
            let over = seen
                .lock()
                .ok()
                .and_then(|g| *g)
                .filter(|(_, t0)| t0.elapsed() > limit);
            if let Some((index, t0)) = over {
                eprintln!(
                    "watchdog: input {index} still running after {:.1} s; exiting",
                    t0.elapsed().as_secs_f64()
                );
                std::process::exit(HANG_EXIT_CODE);
            }
        }
    });
    current
}

/// A range of inputs to run.
#[derive(Debug, Clone, Copy)]
pub struct Span {
    /// Pass seed.
    pub seed: u64,
    /// First index.
    pub from: u64,
    /// One past the last index.
    pub to: u64,
    /// Per-input time limit, s.
    pub timeout_s: f64,
}

/// Runs the inputs of `span` in-process, calling `before` ahead of each and `after` with its
/// outcome; `current` (if any) tells the watchdog which input runs.
pub fn run_range(
    span: Span,
    wd: &Workdir,
    current: Option<&Current>,
    before: &mut dyn FnMut(u64) -> anyhow::Result<()>,
    after: &mut dyn FnMut(&Input, &Outcome) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let Span {
        seed,
        from,
        to,
        timeout_s,
    } = span;
    for index in from..to {
        before(index)?;
        if let Some(c) = current
            && let Ok(mut g) = c.lock()
        {
            *g = Some((index, Instant::now()));
        }
        self_test(index);
        let input = generate(seed, index);
        let outcome = run(&input, wd, timeout_s)?;
        if let Some(c) = current
            && let Ok(mut g) = c.lock()
        {
            *g = None;
        }
        after(&input, &outcome)?;
    }
    Ok(())
}

/// The harness's own test of aborts and hangs: `PLUMETRACE_FUZZ_SELFTEST=abort:3,hang:8` makes
/// the process abort at input 3 and sleep forever at input 8 (for the watchdog), so the tests
/// can check that the parent records them and carries on. Unset, it does nothing.
fn self_test(index: u64) {
    static PLAN: std::sync::OnceLock<Vec<(String, u64)>> = std::sync::OnceLock::new();
    let plan = PLAN.get_or_init(|| {
        std::env::var("PLUMETRACE_FUZZ_SELFTEST")
            .unwrap_or_default()
            .split(',')
            .filter_map(|item| {
                let (what, at) = item.split_once(':')?;
                Some((what.trim().to_string(), at.trim().parse().ok()?))
            })
            .collect()
    });
    for (what, at) in plan {
        if *at == index {
            match what.as_str() {
                "abort" => std::process::abort(),
                "hang" => loop {
                    std::thread::sleep(Duration::from_secs(3600));
                },
                _ => {}
            }
        }
    }
}

/// `plumetrace-fuzz batch`.
pub fn main(args: &BatchArgs) -> anyhow::Result<()> {
    install_panic_hook();
    let wd = Workdir::new().context("creating the work directory")?;
    let path = args.results.clone().unwrap_or_else(|| {
        args.out
            .join("batches")
            .join(format!("{}-{}.jsonl", args.from, args.to))
    });
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .with_context(|| format!("opening {}", path.display()))?;
    let file = std::cell::RefCell::new(file);
    let write = |line: &Line| -> anyhow::Result<()> {
        let mut text = serde_json::to_string(line)?;
        text.push('\n');
        let mut f = file.borrow_mut();
        f.write_all(text.as_bytes())?;
        f.flush()?;
        Ok(())
    };
    let current = start_watchdog(args.timeout_s);
    let span = Span {
        seed: args.seed,
        from: args.from,
        to: args.to,
        timeout_s: args.timeout_s,
    };
    run_range(
        span,
        &wd,
        Some(&current),
        &mut |index| {
            write(&Line {
                index,
                started: true,
                class: None,
                secs: None,
                slow: false,
                corpus: None,
                mutations: Vec::new(),
                message: None,
            })
        },
        &mut |input, outcome| {
            if outcome.class.is_finding() {
                write_finding(&args.out, input, outcome.class, &outcome.message)?;
            }
            write(&Line::finished(input, outcome))
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    #[test]
    fn a_tiny_in_process_pass_completes() -> anyhow::Result<()> {
        install_panic_hook();
        let wd = Workdir::new()?;
        let out = tempfile::tempdir()?;
        let mut started = Vec::new();
        let mut counts: BTreeMap<Class, usize> = BTreeMap::new();
        let span = Span {
            seed: 1,
            from: 0,
            to: 50,
            timeout_s: 20.0,
        };
        run_range(
            span,
            &wd,
            None,
            &mut |i| {
                started.push(i);
                Ok(())
            },
            &mut |input, o| {
                *counts.entry(o.class).or_default() += 1;
                if o.class.is_finding() {
                    write_finding(out.path(), input, o.class, &o.message)?;
                }
                Ok(())
            },
        )?;
        assert_eq!(started, (0..50).collect::<Vec<_>>());
        assert_eq!(counts.values().sum::<usize>(), 50);
        assert!(counts.contains_key(&Class::RejectedLocated), "{counts:?}");
        Ok(())
    }

    #[test]
    fn lines_round_trip() -> anyhow::Result<()> {
        let l = Line {
            index: 3,
            started: true,
            class: None,
            secs: None,
            slow: false,
            corpus: None,
            mutations: Vec::new(),
            message: None,
        };
        assert_eq!(serde_json::to_string(&l)?, r#"{"index":3,"started":true}"#);
        let back: Line =
            serde_json::from_str(r#"{"index":3,"class":"hang","secs":1.5,"slow":true}"#)?;
        assert_eq!(back.class, Some(Class::Hang));
        assert!(back.slow && !back.started);
        assert_eq!(cut("héllo", 2), "h... [6 bytes in all]");
        Ok(())
    }
}
