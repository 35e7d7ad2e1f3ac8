//! `plumetrace campaign` and `plumetrace merge`.

use anyhow::{Context, Result};
use plumetrace_campaign::{Campaign, RunOptions, Shard, Share, TestSeeds, merge, run_campaign};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `plumetrace campaign`.
#[derive(Debug, clap::Args)]
pub struct CampaignArgs {
    /// The campaign file (TOML).
    pub file: PathBuf,
    /// Output directory; running again into it resumes (finished runs are skipped).
    #[arg(long)]
    pub out: PathBuf,
    /// Worker threads, 1 to 256 (default: one per core). Results do not depend on it.
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::jobs)]
    pub jobs: Option<usize>,
    /// Run only shard K of N (1-based, e.g. `--shard 2/4`): every N-th run of the list.
    #[arg(long)]
    pub shard: Option<Shard>,
    /// Seeds per group, 1 to 1,000,000 (overrides the file's `seeds`).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::seeds)]
    pub seeds: Option<u64>,
    /// What runs of the same seed share where their scenarios differ only in planner keys,
    /// outputs, message channels or mission geometry and time limit: `plume` (default: one
    /// world, the plume spun up and stepped once for all of them), `spin-up` (one spin-up, then
    /// a plume each) or `none`. The results are the same bits whatever is shared.
    #[arg(long, value_enum, default_value = "plume")]
    pub share: ShareArg,
    /// The same as `--share none`.
    #[arg(long, conflicts_with = "share")]
    pub separate_spinups: bool,
    /// Allow flying the test seeds of a benchmark task (refused by default: they are for
    /// evaluation, not tuning).
    #[arg(long)]
    pub test_seeds: bool,
}

/// What runs of the same seed share (`--share`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ShareArg {
    /// One world: one spin-up and one plume stepped for all the runs of a group.
    Plume,
    /// One spin-up, then each run steps its own copy of the plume.
    SpinUp,
    /// Every run spins up and steps its own plume.
    None,
}

/// Runs (or resumes) a campaign and prints where the results are.
pub fn run(args: &CampaignArgs) -> Result<()> {
    crate::check_other::refuse_other_kind(&args.file, crate::check_other::FileKind::Campaign)?;
    let c = Campaign::load_with(
        &args.file,
        args.seeds,
        if args.test_seeds {
            TestSeeds::Allow
        } else {
            TestSeeds::Refuse
        },
    )?;
    for w in &c.warnings {
        eprintln!("warning: {}: {w}", args.file.display());
    }
    crate::output::create_out_dir(&args.out)?;
    let started = Instant::now();
    let planned = c.shard_runs(args.shard).len() as u64;
    let progress = crate::progress::Progress::new(planned, "runs");
    let report = run_campaign(
        &c,
        &args.out,
        RunOptions {
            jobs: args.jobs,
            shard: args.shard,
            share: match (args.separate_spinups, args.share) {
                (true, _) | (_, ShareArg::None) => Share::Nothing,
                (_, ShareArg::SpinUp) => Share::SpinUp,
                (_, ShareArg::Plume) => Share::Plume,
            },
        },
        &|done, _| progress.tick(done),
    )
    .with_context(|| format!("campaign {}", args.file.display()))?;
    progress.finish();
    let wall = started.elapsed().as_secs_f64();
    if report.cut_partial_line {
        eprintln!("note: cut off a partial last row left by an interrupted run (it was run again)");
    }
    let shard = args
        .shard
        .map(|s| format!(" (shard {s})"))
        .unwrap_or_default();
    crate::outln!(
        "{}{shard}: {} runs planned, {} already recorded, {} run now ({} failed) in {wall:.1} s{}; wrote {}",
        c.file.name,
        report.planned,
        report.skipped,
        report.ran,
        report.failed,
        if report.ran > 0 && wall > 0.0 {
            format!(" ({:.2} runs/s)", report.ran as f64 / wall)
        } else {
            String::new()
        },
        args.out.display()
    );
    Ok(())
}

/// Arguments of `plumetrace merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// Shard output directories of one campaign.
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// Where to write the merged results.
    #[arg(long)]
    pub out: PathBuf,
}

/// Merges shard directories.
pub fn run_merge(args: &MergeArgs) -> Result<()> {
    let report = merge(&args.dirs, &args.out)?;
    for d in &report.cut_partial_lines {
        eprintln!(
            "note: {} ends with a partial row (an interrupted shard); resume it to complete it",
            d.display()
        );
    }
    let missing = report.expected.saturating_sub(report.runs);
    crate::outln!(
        "merged {} {}: {} of {} runs{}; wrote {}",
        args.dirs.len(),
        if args.dirs.len() == 1 {
            "directory"
        } else {
            "directories"
        },
        report.runs,
        report.expected,
        if missing > 0 {
            format!(" ({missing} missing: resume the shards that lack them)")
        } else {
            String::new()
        },
        args.out.display()
    );
    Ok(())
}
