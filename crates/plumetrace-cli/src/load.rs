//! Reading the scenario of `run` and `check`: a file or a preset, with `--planner` and `--set`
//! applied as a campaign applies its configurations; errors are given the line of their key in
//! the file, and the keys that have no effect in this kind of run are printed as warnings.

use anyhow::{Result, anyhow, bail};
use plumetrace_scenario::{BuiltScenario, Origin, ScenarioError};
use std::path::{Path, PathBuf};

/// Which scenario, and what to change in it.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ScenarioArgs {
    /// Scenario file (TOML; `check` also takes campaign and family files); give this or
    /// --preset.
    pub scenario: Option<PathBuf>,
    /// Built-in scenario (see `plumetrace presets`).
    #[arg(long, conflicts_with = "scenario")]
    pub preset: Option<String>,
    /// Fly this planner kind at its defaults in place of the scenario's planner table (as a
    /// campaign's `[configs.planner]` with only `kind`): every vehicle that flew that table flies
    /// it. A scenario with several planner tables (a team, a formation) is refused.
    #[arg(long, value_name = "KIND")]
    pub planner: Option<String>,
    /// Override a scenario key, as a campaign's `set` does (repeatable, applied in order after
    /// --planner): `KEY=VALUE` with VALUE in TOML; a bare KEY is the planner's
    /// (`--set beta_deg=30`), a dotted one a path (`--set mission.time_limit_s=600`,
    /// `--set sources.0.x_m=120`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

/// A scenario read and built, with what is needed to place errors found later (when the
/// mission is set up) at their line.
pub struct Loaded {
    /// The built scenario.
    pub built: BuiltScenario,
    /// Where errors point.
    pub place: Place,
}

/// The file's text (when the scenario is a file) and the keys changed from the command line.
#[derive(Debug, Default)]
pub struct Place {
    text: Option<String>,
    changed: Vec<String>,
}

impl Place {
    /// `:LINE` of `path` in the file, or nothing (a preset, a key changed from the command line,
    /// a key not written).
    fn line(&self, path: &str) -> Option<usize> {
        let last = |p: &str| {
            p.rsplit(['.', '['])
                .next()
                .unwrap_or(p)
                .trim_end_matches(']')
                .to_string()
        };
        if self.changed.iter().any(|c| {
            c == "planner" && (path.starts_with("planner") || path.starts_with("vehicles"))
                || last(c) == last(path)
        }) {
            return None;
        }
        plumetrace_scenario::locate::line_of(self.text.as_deref()?, path)
    }

    /// `e` with its key's line, when it names a key written in the file (and, for an unknown
    /// planner key after `--set planner.kind=...`, why: [`Place::kind_set_hint`]).
    pub fn locate(&self, e: anyhow::Error) -> anyhow::Error {
        let e = self.locate_key(e);
        self.kind_set_hint(e)
    }

    /// An unknown key after `--set planner.kind=...` (or `strategy`, or a named planner's): the
    /// table kept the keys of the planner before, which the new kind does not read; `--planner
    /// KIND` replaces the whole table.
    fn kind_set_hint(&self, e: anyhow::Error) -> anyhow::Error {
        let kind_set = self.changed.iter().find(|key| {
            let last = key.rsplit('.').next().unwrap_or(key);
            key.starts_with("planner") && (last == "kind" || last == "strategy")
        });
        match kind_set {
            Some(key) if e.to_string().contains("unknown field") => anyhow!(
                "{e:#}; --set {key} changes the planner's kind but keeps the keys of the one \
                 before, which this kind does not read: `--planner KIND` replaces the whole \
                 planner table"
            ),
            _ => e,
        }
    }

    fn locate_key(&self, e: anyhow::Error) -> anyhow::Error {
        let e = match e.downcast::<ScenarioError>() {
            Ok(se) => {
                return match (&self.text, se.key_path().map(str::to_string)) {
                    (Some(_), Some(path)) if self.line(&path).is_none() => se.into(),
                    (Some(text), Some(_)) => se.located(text).into(),
                    _ => se.into(),
                };
            }
            Err(e) => e,
        };
        match e.downcast::<plumetrace_mission::MissionError>() {
            Ok(plumetrace_mission::MissionError::Invalid { origin, error }) => {
                match self.line(&error.key) {
                    Some(line) => anyhow!("{origin}:{line}: {error}"),
                    None => anyhow!("{origin}: {error}"),
                }
            }
            Ok(other) => other.into(),
            Err(e) => e,
        }
    }

    /// A run-time error of the scenario from `origin` (a plume run's diverging flow, say), named
    /// with the file, and the line of `[flow.farrell]` when the flow diverged.
    pub fn at_origin(
        &self,
        origin: &plumetrace_scenario::Origin,
        e: anyhow::Error,
    ) -> anyhow::Error {
        let diverged = e.chain().any(|c| {
            matches!(
                c.downcast_ref::<plumetrace_env::EnvError>(),
                Some(plumetrace_env::EnvError::Diverged { .. })
            )
        });
        match diverged.then(|| self.line("flow.farrell")).flatten() {
            Some(line) => anyhow!("{origin}:{line}: {e:#}"),
            None => anyhow!("{origin}: {e:#}"),
        }
    }

    /// Prints the scenario's warnings (keys with no effect in this kind of run) on stderr.
    pub fn warn(&self, built: &BuiltScenario) {
        // A time limit changed from the command line leaves the file's duration behind: not news.
        let shortened = self.changed.iter().any(|c| c == "mission.time_limit_s");
        for w in &built.warnings {
            if shortened && w.path == "sim.duration_s" {
                continue;
            }
            let line = plumetrace_scenario::locate::at_line(self.line(&w.path));
            eprintln!("warning: {}{line}: {w}", built.origin);
        }
    }
}

/// Reads, changes and builds the scenario; `seed` overrides the file's.
pub fn load(a: &ScenarioArgs, seed: Option<u64>) -> Result<Loaded> {
    let (text, origin) = match (&a.scenario, &a.preset) {
        (Some(path), None) => {
            crate::check_other::refuse_other_kind(path, crate::check_other::FileKind::Scenario)?;
            (read_file(path)?, Origin::File(path.clone()))
        }
        (None, Some(name)) => (
            plumetrace_scenario::preset(name)?.toml.to_string(),
            Origin::Preset(name.clone()),
        ),
        (None, None) => bail!("give a scenario file or --preset NAME (see `plumetrace presets`)"),
        (Some(_), Some(_)) => bail!("give a scenario file or --preset, not both"),
    };
    let place = Place {
        text: matches!(origin, Origin::File(_)).then(|| text.clone()),
        changed: a
            .planner
            .iter()
            .map(|_| "planner".to_string())
            .chain(a.set.iter().map(|s| {
                s.split_once('=')
                    .map_or(s.as_str(), |(k, _)| k)
                    .trim()
                    .to_string()
            }))
            .collect(),
    };
    let cfg = if a.planner.is_none() && a.set.is_empty() {
        plumetrace_scenario::parse(&text, &origin)
    } else {
        let mut table: toml::Table = text.parse().map_err(|e| anyhow!("{origin}: {e}"))?;
        if let Some(kind) = &a.planner {
            planner_kind(&mut table, kind)?;
        }
        plumetrace_scenario::overrides::apply_sets(&mut table, &a.set)?;
        plumetrace_scenario::from_table(table, &origin)
    };
    let built = cfg
        .and_then(|cfg| plumetrace_scenario::build(&cfg, &origin, seed))
        .map_err(|e| place.locate(e.into()))?;
    place.warn(&built);
    Ok(Loaded { built, place })
}

/// `--planner KIND`: a known kind (or the nearest one suggested) in place of the planner table.
fn planner_kind(table: &mut toml::Table, kind: &str) -> Result<()> {
    if plumetrace_mission::PlannerKind::from_name(kind).is_none() {
        let names: Vec<&str> = plumetrace_mission::PlannerKind::ALL
            .iter()
            .map(|k| k.name())
            .collect();
        let hint = plumetrace_core::closest(kind, &names)
            .map(|n| format!("; did you mean '{n}'?"))
            .unwrap_or_default();
        bail!(
            "--planner {kind}: no such planner{hint} (known: {}; see `plumetrace planners`)",
            names.join(", ")
        );
    }
    use plumetrace_scenario::OverrideError;
    plumetrace_scenario::overrides::set_planner_kind(table, kind).map_err(|e| match e {
        OverrideError::SeveralPlanners(list) => anyhow!(
            "--planner {kind}: the scenario has several planner tables ({list}) and --planner \
             replaces a scenario's one planner table; change one of them with --set \
             planners.NAME.kind='\"{kind}\"'"
        ),
        other => anyhow!("--planner {kind}: {other}"),
    })?;
    Ok(())
}

/// The file's text; a missing file named like a preset suggests `--preset`.
fn read_file(path: &Path) -> Result<String> {
    plumetrace_env::input::read_text(path, plumetrace_env::input::MAX_TEXT_BYTES).map_err(|e| {
        let name = path.to_string_lossy();
        let names: Vec<&str> = plumetrace_scenario::PRESETS
            .iter()
            .map(|p| p.name)
            .collect();
        let stem = name.strip_suffix(".toml").unwrap_or(&name);
        match (path.exists(), plumetrace_core::closest(stem, &names)) {
            (false, Some(p)) if !name.contains(['/', '\\']) => anyhow!(
                "{name}: no such file; did you mean the built-in scenario `--preset {p}`? \
                 (`plumetrace presets` lists them)"
            ),
            _ => anyhow!("{name}: {e}"),
        }
    })
}
