//! The `plumetrace` command.
//!
//! Subcommands: `run` (fly a mission, or simulate a plume, and write the outputs), `presets` (list
//! the built-in scenarios), `planners` (the planner registry: every planner and its keys),
//! `check` (validate a scenario file), `replay` (run a snapshot log through a planner again),
//! `campaign` and `merge` (Monte Carlo campaigns), `family` (draw sites of a scenario family),
//! `bench plume` (time the plume model on pompy's
//! scenario or a field-scale one) and `bench missions` (missions per second on 1 and more
//! threads); benchmarks print JSON.

/// Writes to standard output; a closed pipe (`plumetrace planners | head`) is not an error.
#[macro_export]
macro_rules! out {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stdout(), $($t)*);
    }};
}

/// [`out!`] with a newline.
#[macro_export]
macro_rules! outln {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($t)*);
    }};
}

mod args;
mod bench;
mod benchmark;
mod campaign;
mod check_other;
mod frontseat;
mod load;
mod mission;
mod onboard;
mod output;
mod progress;
mod replay;
mod run;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Chemical plume tracing with marine robots: plume simulation, planners, campaigns.
#[derive(Debug, Parser)]
#[command(name = "plumetrace", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run a scenario (a file or a built-in preset) and write its outputs into a directory.
    Run(run::RunArgs),
    /// List the built-in scenarios, one line each.
    Presets {
        /// Print this preset's TOML file (to copy as a starting point).
        #[arg(long, value_name = "NAME", conflicts_with = "markdown")]
        show: Option<String>,
        /// Print the README's Markdown table instead.
        #[arg(long)]
        markdown: bool,
    },
    /// List every planner with its keys, defaults, units, bounds and a line of doc.
    Planners {
        /// Print the guide's Markdown tables instead (docs/planners.md).
        #[arg(long)]
        markdown: bool,
    },
    /// Print the bounds of every number and list in a scenario file, with the reason for each.
    Limits {
        /// Print the guide's Markdown table instead (docs/scenarios.md).
        #[arg(long)]
        markdown: bool,
    },
    /// Validate a scenario file or preset (planners included), a campaign file or a family file,
    /// and print the first error with its key path and line, and a warning for each key that has
    /// no effect.
    Check(load::ScenarioArgs),
    /// Feed a snapshot log (`snapshots.jsonl.gz` of a run) to fresh planners and report the
    /// decisions that differ from the logged ones.
    Replay(replay::ReplayArgs),
    /// Fly a planner on a vehicle: read navigation and the chemical sensor from a front-seat link
    /// (Bluefin over TCP, Iver over a serial line) and send the planner's commands back.
    Onboard(onboard::OnboardArgs),
    /// A simulated front seat: fly a scenario's vehicle and plume and speak a front-seat
    /// protocol (Bluefin on TCP, Iver on a pseudo-terminal) to `plumetrace onboard`.
    Frontseat(frontseat::FrontseatArgs),
    /// Run a Monte Carlo campaign (resumable, parallel, shardable) and summarise it.
    Campaign(campaign::CampaignArgs),
    /// Merge the output directories of a campaign's shards.
    Merge(campaign::MergeArgs),
    /// Fly the benchmark's tasks on their test seeds with the planners asked for (every
    /// planner on the same sites) and write the leaderboard.
    Benchmark(benchmark::BenchmarkArgs),
    /// Draw sites of a scenario family and write each as a scenario file (to fly or inspect).
    Family(FamilyArgs),
    /// Benchmarks; print one JSON object.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
}

fn main() {
    let cli = Cli::parse();
    if let Err(e) = dispatch(cli) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn dispatch(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Run(args) => run::run(&args),
        Command::Presets { show, markdown } => presets(show.as_deref(), markdown),
        Command::Planners { markdown } => {
            if markdown {
                crate::out!("{}", plumetrace_planner::registry_markdown());
            } else {
                crate::out!("{}", planners_text());
            }
            Ok(())
        }
        Command::Limits { markdown } => {
            if markdown {
                crate::out!("{}", plumetrace_scenario::limits::markdown());
            } else {
                crate::out!("{}", plumetrace_scenario::limits::text());
            }
            Ok(())
        }
        Command::Check(args) => check(&args),
        Command::Replay(args) => {
            if !replay::run(&args)? {
                std::process::exit(replay::DIFFER);
            }
            Ok(())
        }
        Command::Onboard(args) => onboard::run(&args),
        Command::Frontseat(args) => frontseat::run(&args),
        Command::Campaign(args) => campaign::run(&args),
        Command::Merge(args) => campaign::run_merge(&args),
        Command::Family(args) => family(&args),
        Command::Benchmark(args) => benchmark::run(&args),
        Command::Bench(b) => bench::run(&b),
    }
}

/// `plumetrace presets`: a line per preset, its TOML file (`--show`) or the README's table
/// (`--markdown`).
fn presets(show: Option<&str>, markdown: bool) -> Result<()> {
    use plumetrace_scenario::PRESETS;
    if let Some(name) = show {
        let p = plumetrace_scenario::find_preset(name).ok_or_else(|| {
            plumetrace_scenario::load_preset(name)
                .err()
                .map_or_else(|| anyhow::anyhow!("no preset named '{name}'"), Into::into)
        })?;
        crate::out!("{}", p.toml);
    } else if markdown {
        crate::out!("{}", presets_markdown());
    } else {
        let width = PRESETS.iter().map(|p| p.name.len()).max().unwrap_or(0);
        for p in PRESETS {
            crate::outln!("{:width$}  {}", p.name, p.summary);
        }
    }
    Ok(())
}

/// The README's preset table.
fn presets_markdown() -> String {
    let mut out = String::from("| preset | what it is |\n| --- | --- |\n");
    for p in plumetrace_scenario::PRESETS {
        let _ = writeln!(out, "| `{}` | {} |", p.name, p.summary.replace('|', "\\|"));
    }
    out
}

/// `plumetrace family`.
#[derive(Debug, clap::Args)]
struct FamilyArgs {
    /// The family file (`*.family.toml`).
    file: PathBuf,
    /// How many sites to draw (1 to 10,000).
    #[arg(long, value_parser = args::sample)]
    sample: u64,
    /// Seed: site k is drawn from derive_seed(seed, k), as in a campaign with this seed.
    #[arg(long, default_value_t = 1, value_parser = args::seed, allow_hyphen_values = true)]
    seed: u64,
    /// Where to write `site-K.toml` (a new or empty directory).
    #[arg(long)]
    out: PathBuf,
    /// Allow drawing the test seeds of a benchmark task (refused by default: they are for
    /// evaluation, not tuning).
    #[arg(long)]
    test_seeds: bool,
}

/// `plumetrace family FILE --sample N --out DIR`: draws N sites and writes each as a scenario
/// file (with the drawn values in its opening comment), checked by the same build as `run`.
fn family(a: &FamilyArgs) -> Result<()> {
    check_other::refuse_other_kind(&a.file, check_other::FileKind::Family)?;
    let f = plumetrace_scenario::Family::load(&a.file)?;
    if !a.test_seeds {
        let set = plumetrace_campaign::benchmark::TaskSet::builtin()?;
        if let Some(hit) = set.test_seed_use(&f.file.name, a.seed, a.sample) {
            let tuning = set.task(&hit.task).map(|t| t.tuning_seed)?;
            anyhow::bail!(
                "{}: --seed {} with --sample {} draws test seeds of benchmark task '{}' (task set \
                 {}; site {} is one); draw its tuning seed {tuning}, or pass --test-seeds to draw \
                 the test sites on purpose",
                a.file.display(),
                a.seed,
                a.sample,
                hit.task,
                set.version,
                hit.seed_index
            );
        }
    }
    if a.out.exists() && !a.out.is_dir() {
        anyhow::bail!(
            "{}: is a file, not a directory; give a new or empty --out directory",
            a.out.display()
        );
    }
    if a.out.exists()
        && std::fs::read_dir(&a.out)
            .with_context(|| format!("reading {}", a.out.display()))?
            .next()
            .is_some()
    {
        anyhow::bail!(
            "{}: holds files already; give a new or empty --out directory",
            a.out.display()
        );
    }
    // Every site is drawn and checked before the first is written, so a site that cannot be
    // built leaves no partial set behind.
    let width = (a.sample.max(1) - 1).to_string().len().max(3);
    let mut sites = Vec::new();
    for k in 0..a.sample {
        let (file, text) = f.site_file(a.seed, k, width);
        let path = a.out.join(file);
        plumetrace_scenario::builds(&text, &plumetrace_scenario::Origin::File(path.clone()))?;
        sites.push((path, text));
    }
    crate::output::create_out_dir(&a.out)?;
    for (path, text) in &sites {
        crate::output::write_atomic(path, text.as_bytes())?;
    }
    crate::outln!(
        "{}: wrote {} sites of '{}' (seed {}) to {}",
        a.file.display(),
        a.sample,
        f.file.name,
        a.seed,
        a.out.display()
    );
    Ok(())
}

/// `plumetrace planners`: every planner and its keys, as plain text.
fn planners_text() -> String {
    use plumetrace_core::params::{KeyDoc, Params};
    use std::fmt::Write as _;
    let mut out = String::new();
    let keys = |out: &mut String, keys: &[KeyDoc]| {
        let width = keys.iter().map(|k| k.name.len()).max().unwrap_or(0);
        for k in keys {
            let unit = if k.unit.is_empty() {
                String::new()
            } else {
                format!(" {}", k.unit)
            };
            let bounds = if k.bounds.is_empty() {
                String::new()
            } else {
                format!(", {}", k.bounds)
            };
            let _ = writeln!(
                out,
                "  {:width$}  {}{unit} ({}{bounds}): {}",
                k.name, k.default, k.type_name, k.doc
            );
        }
    };
    let _ = writeln!(out, "every planner (kind = \"NAME\" selects one):");
    keys(&mut out, &plumetrace_planner::CommonParams::keys());
    for p in plumetrace_planner::PLANNERS {
        let _ = writeln!(out, "\n{}: {}", p.kind, p.summary);
        keys(&mut out, &(p.keys)());
    }
    out
}

/// How the flow steps along plume steps of `dt_s`, for `check` ([`plumetrace_env::flow_schedule`]).
fn flow_steps(flow: &dyn plumetrace_env::FlowField, dt_s: f64) -> String {
    match plumetrace_env::flow_schedule(flow, dt_s) {
        (1, 1) => "once per plume step".into(),
        (1, n) => format!("{n} times per plume step"),
        (every, _) => format!("once per {every} plume steps"),
    }
}

/// `plumetrace check FILE` (or `--preset NAME`, with `--planner` and `--set` as for `run`):
/// everything `run` would reject, rejected here with the same message, and the same warnings.
fn check(args: &load::ScenarioArgs) -> Result<()> {
    if let Some(path) = &args.scenario {
        let kind = check_other::FileKind::of(path);
        if kind != check_other::FileKind::Scenario {
            let overrides = args.planner.is_some() || !args.set.is_empty();
            return check_other::check(path, kind, overrides);
        }
    }
    let load::Loaded { built, place } = load::load(args, None)?;
    let file = &built.origin.clone();
    let (steps, dt) = (built.steps, built.dt_s);
    if built.mission.is_none() {
        let o = &built.output;
        let d = plumetrace_plume_run::time_decimals(dt);
        let mut series = String::new();
        if !o.probes.is_empty() {
            let _ = write!(
                series,
                "; {} probes sampled every {:.d$} s",
                o.probes.len(),
                o.probe_every_steps as f64 * dt
            );
        }
        if let Some(every) = o.filaments_every_steps {
            let _ = write!(
                series,
                "; filament snapshots every {:.d$} s",
                every as f64 * dt
            );
        }
        if plumetrace_env::flow_schedule(built.env.flow(), dt) != (1, 1) {
            let _ = write!(
                series,
                "; the flow steps {}",
                flow_steps(built.env.flow(), dt)
            );
        }
        crate::outln!("{file}: ok (plume run, {steps} steps of {dt} s{series})");
        return Ok(());
    }
    let setup = plumetrace_mission::MissionSetup::new(built).map_err(|e| place.locate(e.into()))?;
    for w in &setup.warnings {
        eprintln!("warning: {file}: {w}");
    }
    let vehicles: Vec<String> = setup
        .vehicles
        .iter()
        .zip(&setup.planners)
        .map(|(v, p)| match p {
            Some(p) => format!("{} flies {} ({})", v.name, p.config.kind(), p.key),
            None => format!("{} has no planner", v.name),
        })
        .collect();
    let env = &setup.env;
    let flow = plumetrace_env::FlowField::max_stable_dt_s(env.flow());
    let sub = |step: f64| flow_steps(env.flow(), step);
    let plume_steps = format!(
        "plume steps of {} s, {} s in the spin-up{}",
        env.dt_s(),
        setup.spec.spinup_dt_s,
        match flow {
            Some(limit) => format!(
                " (the flow's stable limit is {limit:.1} s and it steps at most half of that: \
                 {} in the mission, {} in the spin-up)",
                sub(env.dt_s()),
                sub(setup.spec.spinup_dt_s)
            ),
            None => String::new(),
        }
    );
    let dropping = match env.plume().filaments().and_then(|p| p.sink()) {
        Some(s) => format!(
            "; filaments out of reach dropped downflow (towards {:.0} deg)",
            s.dir[0].atan2(s.dir[1]).to_degrees().rem_euclid(360.0)
        ),
        None => String::new(),
    };
    crate::outln!(
        "{}: ok (mission of up to {} s after {} s of plume spin-up, steps of {dt} s, {plume_steps}{dropping}; {})",
        file,
        setup.spec.time_limit_s,
        setup.spec.spinup_s,
        vehicles.join("; ")
    );
    Ok(())
}
