//! `plumetrace check` on a campaign or a family file: the checks `plumetrace campaign` and
//! `plumetrace family` make before they fly or write anything, with their messages.

use anyhow::{Result, bail};
use std::path::Path;

/// What a TOML file is, from its top-level keys.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    Scenario,
    Campaign,
    Family,
}

impl FileKind {
    /// Reads `path`'s top-level keys: `scenarios` or `configs` make a campaign, `base` (or a
    /// name ending in `.family.toml`) a family; anything else, or a file that does not read or
    /// parse, is left to the scenario check, which says what is wrong with it.
    pub fn of(path: &Path) -> FileKind {
        if path.to_string_lossy().ends_with(".family.toml") {
            return FileKind::Family;
        }
        let Ok(text) = std::fs::read_to_string(path) else {
            return FileKind::Scenario;
        };
        let Ok(table) = text.parse::<toml::Table>() else {
            return FileKind::Scenario;
        };
        if table.contains_key("scenarios") || table.contains_key("configs") {
            FileKind::Campaign
        } else if table.contains_key("base") {
            FileKind::Family
        } else {
            FileKind::Scenario
        }
    }
}

/// How many sites `check` draws from a family (seed 1, as `plumetrace family` draws by default).
const FAMILY_SITES: u64 = 8;

/// Checks a campaign or family file (`kind`, not a scenario); `overrides` says whether
/// `--planner` or `--set` was given (they apply to scenarios: a campaign sets its own keys, a
/// family's sites are drawn whole).
pub fn check(path: &Path, kind: FileKind, overrides: bool) -> Result<()> {
    if overrides {
        let (what, why) = match kind {
            FileKind::Campaign => (
                "a campaign file",
                "a campaign gives keys in its configs' `set`",
            ),
            _ => ("a family file", "a family's sites are drawn whole"),
        };
        bail!(
            "{}: is {what}: --planner and --set apply to scenario files ({why}); check it \
             without them",
            path.display()
        );
    }
    match kind {
        FileKind::Campaign => campaign(path),
        _ => family(path),
    }
}

fn campaign(path: &Path) -> Result<()> {
    let c = plumetrace_campaign::Campaign::load_with(
        path,
        None,
        plumetrace_campaign::TestSeeds::Allow,
    )?;
    for w in &c.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    let groups = c.scenarios.len() * c.configs.len() * c.points.len();
    let runs = c.runs().len();
    let (flag, note) = match c.refuse_test_seeds() {
        Ok(()) => ("", ""),
        Err(_) => (" --test-seeds", " (it flies a benchmark task's test seeds)"),
    };
    crate::outln!(
        "{}: ok (campaign '{}': {groups} groups of {} seeds, {runs} runs); run it with \
         `plumetrace campaign {} --out DIR{flag}`{note}",
        path.display(),
        c.file.name,
        c.file.seeds,
        path.display()
    );
    Ok(())
}

fn family(path: &Path) -> Result<()> {
    let f = plumetrace_scenario::Family::load(path)?;
    for k in 0..FAMILY_SITES {
        let seed = plumetrace_env::derive_seed(1, k);
        let site = f.draw(seed);
        let name = format!("{}-site-{k:03}", f.file.name);
        let text = site.to_toml(&f.file, &f.base, seed, &name);
        let origin = plumetrace_scenario::Origin::File(path.join(format!("site-{k:03}.toml")));
        let cfg = plumetrace_scenario::parse(&text, &origin)
            .map_err(|e| anyhow::anyhow!("site {k} drawn at seed 1: {e}"))?;
        plumetrace_scenario::build(&cfg, &origin, None)
            .map_err(|e| anyhow::anyhow!("site {k} drawn at seed 1: {e}"))?;
    }
    crate::outln!(
        "{}: ok (family '{}'; the first {FAMILY_SITES} sites at seed 1 build); draw sites with \
         `plumetrace family {} --sample N --out DIR`",
        path.display(),
        f.file.name,
        path.display()
    );
    Ok(())
}
