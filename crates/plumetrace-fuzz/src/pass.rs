//! The parent of a pass: splits the index range into chunks, runs each chunk in a child
//! process of this binary (`batch`) under a memory limit, `J` children at a time, restarts a
//! child after the input that killed it (recorded as `abort`, or `hang` when the watchdog
//! fired), and prints one JSON report.
//!
//! Chunks are at most 1,000 inputs (about four per job for small passes), so the load stays
//! balanced, results files stay small and progress shows; each chunk's child is started with
//! `prlimit --as=BYTES` (address space, so a runaway allocation fails inside the child) and
//! `RAYON_NUM_THREADS=1` (the jobs are the parallelism).

use crate::batch::{HANG_EXIT_CODE, Line, cut, mutation_names, write_finding};
use crate::classify::Class;
use crate::generate::generate;
use anyhow::{Context, bail};
use serde_json::json;
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Arguments of `plumetrace-fuzz pass`.
#[derive(Debug, clap::Args)]
pub struct PassArgs {
    /// Number of inputs (default 1,000,000; 3,000 with --quick).
    #[arg(long)]
    pub inputs: Option<u64>,
    /// Pass seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// First index (the pass runs FIRST..FIRST+INPUTS).
    #[arg(long, default_value_t = 0)]
    pub first: u64,
    /// Child processes at a time (default: the number of CPUs; 2 with --quick).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Address-space limit of each child, MB.
    #[arg(long, default_value_t = 2048)]
    pub memory_mb: u64,
    /// Per-input time limit, s.
    #[arg(long, default_value_t = 30.0)]
    pub timeout_s: f64,
    /// Output directory (its `batches`, `logs` and `findings` are replaced).
    #[arg(long, default_value = "fuzz-out")]
    pub out: PathBuf,
    /// Quick defaults: 3,000 inputs on 2 jobs (explicit --inputs and --jobs win).
    #[arg(long)]
    pub quick: bool,
    /// Inputs per child process (default: about four chunks per job, at most 1,000).
    #[arg(long)]
    pub chunk: Option<u64>,
}

/// Finding messages kept in memory per class (for the examples).
const KEPT_PER_CLASS: usize = 2_000;
/// Examples per finding class in the report.
const EXAMPLES: usize = 10;

/// What the pass has seen so far.
#[derive(Default)]
struct Tally {
    counts: BTreeMap<Class, u64>,
    slow: u64,
    slow_examples: Vec<(u64, f64, String)>,
    findings: BTreeMap<Class, Vec<(u64, String, String)>>,
    by_corpus: BTreeMap<String, BTreeMap<Class, u64>>,
    by_mutation: BTreeMap<String, BTreeMap<Class, u64>>,
    done: u64,
}

impl Tally {
    fn add(&mut self, line: &Line) {
        let Some(class) = line.class else { return };
        let corpus = line.corpus.clone().unwrap_or_default();
        *self.counts.entry(class).or_default() += 1;
        *self
            .by_corpus
            .entry(corpus.clone())
            .or_default()
            .entry(class)
            .or_default() += 1;
        for m in &line.mutations {
            *self
                .by_mutation
                .entry(m.clone())
                .or_default()
                .entry(class)
                .or_default() += 1;
        }
        if line.slow {
            self.slow += 1;
            if self.slow_examples.len() < KEPT_PER_CLASS {
                self.slow_examples
                    .push((line.index, line.secs.unwrap_or(0.0), corpus.clone()));
            }
        }
        if class.is_finding() {
            let kept = self.findings.entry(class).or_default();
            if kept.len() < KEPT_PER_CLASS {
                kept.push((line.index, corpus, line.message.clone().unwrap_or_default()));
            }
        }
        self.done += 1;
    }

    fn finding_count(&self) -> u64 {
        self.counts
            .iter()
            .filter(|(c, _)| c.is_finding())
            .map(|(_, n)| n)
            .sum()
    }
}

/// Up to [`EXAMPLES`] findings, distinct messages first (digits ignored), in index order.
fn examples(kept: &[(u64, String, String)]) -> Vec<serde_json::Value> {
    let mut sorted: Vec<&(u64, String, String)> = kept.iter().collect();
    sorted.sort_by_key(|f| f.0);
    let shape = |m: &str| -> String {
        m.chars()
            .map(|c| if c.is_ascii_digit() { '#' } else { c })
            .take(100)
            .collect()
    };
    let mut shapes = BTreeSet::new();
    let mut chosen: Vec<&(u64, String, String)> = Vec::new();
    for f in &sorted {
        if chosen.len() < EXAMPLES && shapes.insert(shape(&f.2)) {
            chosen.push(f);
        }
    }
    for f in &sorted {
        if chosen.len() >= EXAMPLES {
            break;
        }
        if !chosen.iter().any(|c| c.0 == f.0) {
            chosen.push(f);
        }
    }
    chosen.sort_by_key(|f| f.0);
    chosen
        .iter()
        .map(|(index, corpus, message)| {
            json!({"index": index, "corpus": corpus, "message": cut(message, 600)})
        })
        .collect()
}

/// A JSON value whose objects keep their keys in the order given (the report reads top-down).
enum Node {
    /// Any JSON value.
    Leaf(serde_json::Value),
    /// An object, keys in order.
    Obj(Vec<(String, Node)>),
}

impl serde::Serialize for Node {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        match self {
            Node::Leaf(v) => v.serialize(s),
            Node::Obj(entries) => {
                let mut m = s.serialize_map(Some(entries.len()))?;
                for (k, v) in entries {
                    m.serialize_entry(k, v)?;
                }
                m.end()
            }
        }
    }
}

/// Whether `prlimit` can be run.
fn have_prlimit() -> bool {
    Command::new("prlimit")
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// A readable account of how a child ended.
fn describe_status(status: ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match (status.code(), status.signal()) {
        (Some(HANG_EXIT_CODE), _) => {
            format!("the watchdog ended the child (exit status {HANG_EXIT_CODE})")
        }
        (Some(c), _) => format!("the child exited with status {c}"),
        (None, Some(s)) => {
            let name = match s {
                4 => " (SIGILL)",
                6 => " (SIGABRT)",
                7 => " (SIGBUS)",
                8 => " (SIGFPE)",
                9 => " (SIGKILL)",
                11 => " (SIGSEGV)",
                _ => "",
            };
            format!("the child was killed by signal {s}{name}")
        }
        (None, None) => "the child ended".into(),
    }
}

/// The last lines of a child's standard error.
fn stderr_tail(path: &Path) -> String {
    let text = std::fs::read(path).unwrap_or_default();
    let text = String::from_utf8_lossy(&text);
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    let tail = lines[lines.len().saturating_sub(5)..].join(" | ");
    cut(&tail, 1_000)
}

/// Everything a worker needs.
struct Shared<'a> {
    args: &'a PassArgs,
    exe: PathBuf,
    memory_bytes: Option<u64>,
    queue: Mutex<VecDeque<(u64, u64)>>,
    tally: Mutex<Tally>,
    errors: Mutex<Vec<String>>,
    started: Instant,
    total: u64,
}

/// Runs one chunk to its end, restarting the child after each input that kills it; returns
/// the lines of every input of the chunk.
fn run_chunk(sh: &Shared<'_>, from: u64, to: u64) -> anyhow::Result<Vec<Line>> {
    let args = sh.args;
    let mut lines: Vec<Line> = Vec::new();
    let mut cur = from;
    let mut attempt = 0u32;
    let mut fruitless = 0u32;
    while cur < to {
        let results = args
            .out
            .join("batches")
            .join(format!("{from}-{to}.{attempt}.jsonl"));
        let log = args
            .out
            .join("logs")
            .join(format!("{from}-{to}.{attempt}.stderr"));
        let mut cmd = match sh.memory_bytes {
            Some(bytes) => {
                let mut c = Command::new("prlimit");
                c.arg(format!("--as={bytes}")).arg("--").arg(&sh.exe);
                c
            }
            None => Command::new(&sh.exe),
        };
        cmd.arg("batch")
            .args(["--from", &cur.to_string(), "--to", &to.to_string()])
            .args(["--seed", &args.seed.to_string()])
            .args(["--timeout-s", &args.timeout_s.to_string()])
            .arg("--out")
            .arg(&args.out)
            .arg("--results")
            .arg(&results)
            .env("RAYON_NUM_THREADS", "1")
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(
                std::fs::File::create(&log)
                    .with_context(|| format!("creating {}", log.display()))?,
            );
        let mut child = cmd.spawn().context("starting a batch child")?;
        // Wait, killing the child if its results stop growing for well past the time limit.
        let stall =
            Duration::try_from_secs_f64(args.timeout_s + 30.0).unwrap_or(Duration::from_secs(60));
        let mut last_len = 0u64;
        let mut last_change = Instant::now();
        let mut killed_by_parent = false;
        let status = loop {
            if let Some(s) = child.try_wait()? {
                break s;
            }
            std::thread::sleep(Duration::from_millis(50));
            let len = std::fs::metadata(&results).map_or(0, |m| m.len());
            if len != last_len {
                last_len = len;
                last_change = Instant::now();
            } else if last_change.elapsed() > stall {
                child.kill().ok();
                killed_by_parent = true;
                break child.wait()?;
            }
        };
        let text = std::fs::read(&results).unwrap_or_default();
        let mut started = BTreeSet::new();
        let mut finished = BTreeSet::new();
        for raw in String::from_utf8_lossy(&text).lines() {
            // A line cut short by the child's death does not parse and is skipped.
            let Ok(line) = serde_json::from_str::<Line>(raw) else {
                continue;
            };
            if line.class.is_some() {
                finished.insert(line.index);
                lines.push(line);
            } else if line.started {
                started.insert(line.index);
            }
        }
        let killer = started
            .iter()
            .rev()
            .find(|i| !finished.contains(i))
            .copied();
        match killer {
            Some(k) => {
                let hang = killed_by_parent || status.code() == Some(HANG_EXIT_CODE);
                let class = if hang { Class::Hang } else { Class::Abort };
                let how = if killed_by_parent {
                    format!(
                        "no progress for {:.0} s: the parent killed the child",
                        stall.as_secs_f64()
                    )
                } else {
                    describe_status(status)
                };
                let tail = stderr_tail(&log);
                let message = if tail.is_empty() {
                    format!("{how} while running input {k}")
                } else {
                    format!("{how} while running input {k}; stderr: {tail}")
                };
                let input = generate(args.seed, k);
                write_finding(&args.out, &input, class, &message)?;
                lines.push(Line {
                    index: k,
                    started: false,
                    class: Some(class),
                    secs: None,
                    slow: false,
                    corpus: Some(input.corpus.to_string()),
                    mutations: mutation_names(&input),
                    message: Some(message),
                });
                cur = k + 1;
                fruitless = 0;
            }
            None => {
                let next = finished.iter().next_back().map_or(cur, |i| i + 1);
                if status.success() && next >= to {
                    cur = to;
                } else {
                    fruitless += if next > cur { 0 } else { 1 };
                    if fruitless >= 3 {
                        bail!(
                            "the batch child for {cur}..{to} keeps failing without starting an \
                             input ({}; stderr: {})",
                            describe_status(status),
                            stderr_tail(&log)
                        );
                    }
                    cur = next;
                }
            }
        }
        attempt += 1;
    }
    Ok(lines)
}

fn worker(sh: &Shared<'_>) {
    loop {
        let next = sh.queue.lock().ok().and_then(|mut q| q.pop_front());
        let Some((from, to)) = next else { return };
        match run_chunk(sh, from, to) {
            Ok(lines) => {
                if let Ok(mut t) = sh.tally.lock() {
                    lines.iter().for_each(|l| t.add(l));
                    let secs = sh.started.elapsed().as_secs_f64();
                    eprintln!(
                        "[plumetrace-fuzz] {}/{} inputs, {:.1}/s, {} findings",
                        t.done,
                        sh.total,
                        t.done as f64 / secs.max(1e-9),
                        t.finding_count()
                    );
                }
            }
            Err(e) => {
                if let Ok(mut errs) = sh.errors.lock() {
                    errs.push(format!("{e:#}"));
                }
                // Stop handing out work: the harness itself is broken.
                if let Ok(mut q) = sh.queue.lock() {
                    q.clear();
                }
                return;
            }
        }
    }
}

/// Replaces `dir` by an empty directory.
fn fresh_dir(dir: &Path) -> anyhow::Result<()> {
    if dir.exists() {
        std::fs::remove_dir_all(dir).with_context(|| format!("removing {}", dir.display()))?;
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))
}

/// `plumetrace-fuzz pass`: prints the report; `Ok(true)` when there are findings.
pub fn main(args: &PassArgs) -> anyhow::Result<bool> {
    if !(args.timeout_s.is_finite() && args.timeout_s > 0.0) {
        bail!("--timeout-s must be a positive number of seconds");
    }
    let inputs = args
        .inputs
        .unwrap_or(if args.quick { 3_000 } else { 1_000_000 });
    let jobs = args
        .jobs
        .unwrap_or_else(|| {
            if args.quick {
                2
            } else {
                std::thread::available_parallelism().map_or(2, |n| n.get())
            }
        })
        .max(1);
    for sub in ["batches", "logs", "findings"] {
        fresh_dir(&args.out.join(sub))?;
    }
    let memory_bytes = if have_prlimit() {
        Some(args.memory_mb.saturating_mul(1 << 20))
    } else {
        eprintln!(
            "[plumetrace-fuzz] prlimit (util-linux) not found: children run WITHOUT a memory limit"
        );
        None
    };
    let chunk = args
        .chunk
        .unwrap_or_else(|| inputs.div_ceil(jobs as u64 * 4).clamp(1, 1_000))
        .max(1);
    let end = args.first.saturating_add(inputs);
    let queue: VecDeque<(u64, u64)> = (args.first..end)
        .step_by(usize::try_from(chunk).unwrap_or(1_000))
        .map(|a| (a, a.saturating_add(chunk).min(end)))
        .collect();
    let sh = Shared {
        args,
        exe: std::env::current_exe().context("finding this executable")?,
        memory_bytes,
        queue: Mutex::new(queue),
        tally: Mutex::new(Tally::default()),
        errors: Mutex::new(Vec::new()),
        started: Instant::now(),
        total: inputs,
    };
    eprintln!(
        "[plumetrace-fuzz] pass of {inputs} inputs (seed {}, indices {}..{end}) on {jobs} jobs, \
         chunks of {chunk}, {} s per input, {}",
        args.seed,
        args.first,
        args.timeout_s,
        match memory_bytes {
            Some(_) => format!("{} MB per child", args.memory_mb),
            None => "no memory limit".into(),
        }
    );
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| worker(&sh));
        }
    });
    let wall = sh.started.elapsed().as_secs_f64();
    let errors = sh.errors.into_inner().unwrap_or_default();
    if !errors.is_empty() {
        bail!("the pass failed: {}", errors.join("; "));
    }
    let tally = sh.tally.into_inner().unwrap_or_default();
    let leaf = Node::Leaf;
    let mut counts: Vec<(String, Node)> = Class::ALL
        .iter()
        .map(|c| {
            let n = tally.counts.get(c).copied().unwrap_or(0);
            (c.name().to_string(), leaf(json!(n)))
        })
        .collect();
    counts.push(("slow".into(), leaf(json!(tally.slow))));
    let examples_by_class: Vec<(String, Node)> = Class::ALL
        .iter()
        .filter(|c| c.is_finding())
        .filter_map(|c| {
            let kept = tally.findings.get(c)?;
            Some((c.name().to_string(), leaf(json!(examples(kept)))))
        })
        .collect();
    let mut slow = tally.slow_examples.clone();
    slow.sort_by(|a, b| b.1.total_cmp(&a.1));
    let slow: Vec<serde_json::Value> = slow
        .iter()
        .take(EXAMPLES)
        .map(|(i, s, c)| json!({"index": i, "secs": (s * 1000.0).round() / 1000.0, "corpus": c}))
        .collect();
    let breakdown = |by: &BTreeMap<String, BTreeMap<Class, u64>>| -> Node {
        Node::Obj(
            by.iter()
                .map(|(k, m)| {
                    let per: Vec<(String, Node)> = Class::ALL
                        .iter()
                        .filter_map(|c| Some((c.name().to_string(), leaf(json!(m.get(c)?)))))
                        .collect();
                    (k.clone(), Node::Obj(per))
                })
                .collect(),
        )
    };
    let findings = tally.finding_count();
    let entries: Vec<(&str, Node)> = vec![
        ("seed", leaf(json!(args.seed))),
        ("first_index", leaf(json!(args.first))),
        ("inputs", leaf(json!(tally.done))),
        ("jobs", leaf(json!(jobs))),
        ("timeout_s", leaf(json!(args.timeout_s))),
        (
            "memory_limit",
            leaf(json!(match memory_bytes {
                Some(b) => format!(
                    "{} MB address space per child (prlimit --as={b})",
                    args.memory_mb
                ),
                None => "none (prlimit not found)".into(),
            })),
        ),
        ("wall_s", leaf(json!((wall * 10.0).round() / 10.0))),
        (
            "inputs_per_s",
            leaf(json!(
                ((tally.done as f64 / wall.max(1e-9)) * 10.0).round() / 10.0
            )),
        ),
        ("counts", Node::Obj(counts)),
        ("findings", leaf(json!(findings))),
        ("examples", Node::Obj(examples_by_class)),
        ("slowest", leaf(json!(slow))),
        ("by_corpus", breakdown(&tally.by_corpus)),
        ("by_mutation", breakdown(&tally.by_mutation)),
        ("out", leaf(json!(args.out.display().to_string()))),
    ];
    let report = Node::Obj(
        entries
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
    );
    println!("{}", serde_json::to_string_pretty(&report)?);
    Ok(findings > 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn examples_prefer_distinct_messages() {
        let kept: Vec<(u64, String, String)> = (0..30)
            .map(|i| {
                let m = if i % 10 == 0 {
                    format!("rare {i}")
                } else {
                    format!("common {i}")
                };
                (i, "demo".to_string(), m)
            })
            .collect();
        let ex = examples(&kept);
        assert_eq!(ex.len(), EXAMPLES);
        let rare = ex
            .iter()
            .filter(|e| e["message"].as_str().is_some_and(|m| m.starts_with("rare")))
            .count();
        assert!(rare >= 1, "{ex:?}");
    }
}
