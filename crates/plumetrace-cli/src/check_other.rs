//! What kind of file a TOML file is (scenario, campaign, family), and `plumetrace check` on a
//! campaign or a family file: the checks `plumetrace campaign` and `plumetrace family` make
//! before they fly or write anything, with their messages. `run`, `campaign` and `family` refuse
//! a file of another kind with [`refuse_other_kind`].

use anyhow::{Result, bail};
use std::path::Path;

/// What a TOML file is, from its top-level keys.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    Scenario,
    Campaign,
    Family,
}

/// Top-level keys only a scenario file has: one of them makes a file a scenario, whatever else
/// it holds (a stray `seeds` or `[source]` there is a scenario's mistake, named as such).
/// (`flow` is a family's key too.)
const SCENARIO_KEYS: [&str; 13] = [
    "sim",
    "domain",
    "bathymetry",
    "plume",
    "sources",
    "obstacles",
    "kelp",
    "vehicles",
    "mission",
    "planner",
    "planners",
    "comms",
    "output",
];

/// Top-level keys only a campaign file has.
const CAMPAIGN_KEYS: [&str; 5] = ["scenarios", "seeds", "configs", "sweep", "success_radius_m"];

/// Top-level keys only a family file has.
const FAMILY_KEYS: [&str; 11] = [
    "base",
    "area",
    "source",
    "start",
    "nav",
    "faults",
    "team",
    "regions",
    "time_limit_s",
    "domain_margin_m",
    "prior_flow_error_deg",
];

impl FileKind {
    /// Reads `path`'s top-level keys: one only a scenario has (`domain`, `vehicles`, ...) keeps
    /// it a scenario; else one only a campaign has (`scenarios`, `seeds`, `configs`, ...) makes
    /// a campaign, one only a family has (`base`, `area`, ...) or a name ending in
    /// `.family.toml` a family; anything else, or a file that does not read (a directory, a
    /// pipe, too big) or parse, is left to the scenario check, which says what is wrong with it.
    pub fn of(path: &Path) -> FileKind {
        if path.to_string_lossy().ends_with(".family.toml") {
            return FileKind::Family;
        }
        FileKind::keyed(path).map_or(FileKind::Scenario, |(kind, _)| kind)
    }

    /// The kind `path`'s top-level keys tell (in the order of [`FileKind::of`]), with the key
    /// that told; `None` when no key tells or the file does not read or parse.
    fn keyed(path: &Path) -> Option<(FileKind, &'static str)> {
        let text =
            plumetrace_env::input::read_text(path, plumetrace_env::input::MAX_TEXT_BYTES).ok()?;
        let table = text.parse::<toml::Table>().ok()?;
        let has = |keys: &[&'static str]| keys.iter().find(|k| table.contains_key(**k)).copied();
        if let Some(k) = has(&SCENARIO_KEYS) {
            Some((FileKind::Scenario, k))
        } else if let Some(k) = has(&CAMPAIGN_KEYS) {
            Some((FileKind::Campaign, k))
        } else {
            has(&FAMILY_KEYS).map(|k| (FileKind::Family, k))
        }
    }

    /// What `path` is when its top-level keys tell ([`FileKind::keyed`]) or, failing them, its
    /// name ends in `.family.toml`; with what told. `None` when nothing tells, or the file does
    /// not read or parse (the command's own reading then says what is wrong).
    fn told(path: &Path) -> Option<(FileKind, String)> {
        match FileKind::keyed(path) {
            Some((kind, key)) => Some((kind, format!("it has `{key}`"))),
            None => path.to_string_lossy().ends_with(".family.toml").then(|| {
                (
                    FileKind::Family,
                    "its name ends in `.family.toml`".to_string(),
                )
            }),
        }
    }

    /// The kind, and the command that takes it.
    fn what(self, path: &Path) -> (&'static str, String) {
        let p = path.display();
        match self {
            FileKind::Scenario => ("a scenario file", format!("plumetrace run {p} --out DIR")),
            FileKind::Campaign => (
                "a campaign file",
                format!("plumetrace campaign {p} --out DIR"),
            ),
            FileKind::Family => (
                "a family file",
                format!("plumetrace family {p} --sample N --out DIR"),
            ),
        }
    }
}

/// Refuses a file that tells it is of another kind than `want` (a campaign given to `run`, a
/// scenario to `campaign`, ...), naming what it is and the command that takes it, instead of
/// letting `want`'s reader call its first key unknown.
pub fn refuse_other_kind(path: &Path, want: FileKind) -> Result<()> {
    match FileKind::told(path) {
        Some((kind, why)) if kind != want => {
            let (is, command) = kind.what(path);
            let (wanted, _) = want.what(path);
            bail!(
                "{}: is {is} ({why}), not {wanted}: run it with `{command}`",
                path.display()
            )
        }
        _ => Ok(()),
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
    let plural =
        |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
    let (flag, note) = match c.refuse_test_seeds() {
        Ok(()) => ("", ""),
        Err(_) => (" --test-seeds", " (it flies a benchmark task's test seeds)"),
    };
    crate::outln!(
        "{}: ok (campaign '{}': {} of {}, {}); run it with `plumetrace campaign {} --out \
         DIR{flag}`{note}",
        path.display(),
        c.file.name,
        plural(groups, "group", "groups"),
        plural(c.file.seeds as usize, "seed", "seeds"),
        plural(runs, "run", "runs"),
        path.display()
    );
    Ok(())
}

fn family(path: &Path) -> Result<()> {
    let f = plumetrace_scenario::Family::load(path)?;
    for k in 0..FAMILY_SITES {
        let (file, text) = f.site_file(1, k, 3);
        let origin = plumetrace_scenario::Origin::File(file.clone().into());
        if let Err(e) = plumetrace_scenario::builds(&text, &origin) {
            bail!(
                "{}: site {k} drawn at seed 1 cannot be built ({file} as `plumetrace family {} \
                 --sample {} --out DIR` writes it): {e}",
                path.display(),
                path.display(),
                k + 1
            );
        }
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
