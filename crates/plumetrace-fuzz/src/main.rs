//! `plumetrace-fuzz`: mutated scenario, campaign, family and onboard files against `check`,
//! short runs (with `--alog`), campaign parsing, family sites and `onboard FILE --check`.
//!
//! Every input is made from (pass seed, index) alone: a seed of the corpus (the built-in
//! presets, the example campaigns and families, and onboard files) and one to three mutations
//! drawn from a random stream of its own, so a finding is replayed with
//! `plumetrace-fuzz one --index I --seed S`. Among the mutations, hostile names (`..`, a
//! separator, an absolute path, NUL, 300 bytes, another vehicle's): every short run writes its
//! `.alog` files, and a file outside their directory is a finding.
//!
//! - `pass`: the parent; runs a range of inputs in child processes under a memory limit and
//!   prints a JSON report (exit status 1 when anything was found);
//! - `batch`: a child; runs a range in-process and appends results to a JSONL file;
//! - `one`: replays one input in-process and says what happened.
//!
//! `scripts/fuzz.sh` builds this in release mode and runs a pass.

mod batch;
mod classify;
mod corpus;
mod generate;
mod mutate;
mod pass;
mod rng;
mod target;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Fuzzing of plumetrace's scenario and campaign files.
#[derive(Debug, Parser)]
#[command(name = "plumetrace-fuzz", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Debug, Subcommand)]
enum Cmd {
    /// Runs a pass of many inputs in child processes and prints a JSON report.
    Pass(pass::PassArgs),
    /// Runs a range of inputs in this process (what `pass` starts; not for direct use).
    Batch(batch::BatchArgs),
    /// Replays one input in-process: prints it and what happened.
    One(OneArgs),
}

/// Arguments of `plumetrace-fuzz one`.
#[derive(Debug, clap::Args)]
struct OneArgs {
    /// Input index.
    #[arg(long)]
    index: u64,
    /// Pass seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Time limit, s (the watchdog ends the process a little after it).
    #[arg(long, default_value_t = 30.0)]
    timeout_s: f64,
    /// Print the whole input (otherwise the first 20,000 bytes).
    #[arg(long)]
    full: bool,
    /// Also write the input's bytes to this file (e.g. for `plumetrace check`).
    #[arg(long)]
    save: Option<PathBuf>,
    /// Do not print the input.
    #[arg(long)]
    no_input: bool,
}

/// `plumetrace-fuzz one`; `Ok(true)` when the input is a finding.
fn one(args: &OneArgs) -> anyhow::Result<bool> {
    target::install_panic_hook();
    let input = generate::generate(args.seed, args.index);
    print!("{}", input.describe());
    if let Some(p) = &args.save {
        std::fs::write(p, &input.bytes)?;
        println!("written to {}", p.display());
    }
    if !args.no_input {
        let text = input.text_lossy();
        let shown = if args.full {
            text.to_string()
        } else {
            batch::cut(&text, 20_000)
        };
        println!("----- {} -----\n{shown}\n-----", input.target.file_name());
    }
    let wd = target::Workdir::new()?;
    let current = batch::start_watchdog(args.timeout_s);
    let mut result = None;
    let span = batch::Span {
        seed: args.seed,
        from: args.index,
        to: args.index + 1,
        timeout_s: args.timeout_s,
    };
    batch::run_range(span, &wd, Some(&current), &mut |_| Ok(()), &mut |_, o| {
        result = Some(o.clone());
        Ok(())
    })?;
    let Some(o) = result else {
        anyhow::bail!("the input did not run");
    };
    println!(
        "result: {} in {:.3} s{}\n{}",
        o.class.name(),
        o.secs,
        if o.slow() { " (slow)" } else { "" },
        o.message
    );
    Ok(o.class.is_finding())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Cmd::Pass(a) => pass::main(a),
        Cmd::Batch(a) => batch::main(a).map(|()| false),
        Cmd::One(a) => one(a),
    };
    match result {
        Ok(false) => ExitCode::SUCCESS,
        Ok(true) => ExitCode::from(1),
        Err(e) => {
            eprintln!("plumetrace-fuzz: {e:#}");
            ExitCode::from(2)
        }
    }
}
