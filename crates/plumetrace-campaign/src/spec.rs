//! The campaign file and the run list it expands to.
//!
//! A campaign names scenarios (preset names or `.toml` files next to the campaign file), planner
//! configurations (a name and keys to set), an optional sweep (a grid over keys) and a number of
//! seeds. Every (scenario, configuration, sweep point) group runs the same seeds, derived from the
//! campaign seed and the seed index, so every configuration meets the same plume realisations.

use crate::error::CampaignError;
use plumetrace_scenario::overrides::{planner_path, set_key, set_path};
use plumetrace_scenario::{Family, Origin, PRESETS, Site, find_preset, is_family_path};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The campaign file as written (`deny_unknown_fields`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignFile {
    /// Campaign name (used in titles).
    pub name: String,
    /// One line about it.
    #[serde(default)]
    pub description: String,
    /// Campaign seed: run seeds derive from it and the seed index.
    pub seed: u64,
    /// Seeds per group (`--seeds` overrides).
    pub seeds: u64,
    /// Preset names, or paths relative to the campaign file: scenarios ending in `.toml`, families
    /// of sites ending in `.family.toml`.
    pub scenarios: Vec<String>,
    /// The success radius of every run, m: it replaces each scenario's
    /// `mission.success_radius_m` (a run succeeds when its first declaration lies within it of
    /// the true source; with several sources, when every source has a declaration within it).
    #[serde(default)]
    pub success_radius_m: Option<f64>,
    /// Planner configurations (none: one configuration, "default", as the scenario has it).
    #[serde(default)]
    pub configs: Vec<ConfigFile>,
    /// Grid of values per key (every combination is a sweep point).
    #[serde(default)]
    pub sweep: toml::Table,
}

/// One planner configuration.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConfigFile {
    /// Its name in tables and charts.
    pub name: String,
    /// A whole planner table (`kind` and its keys) that replaces the scenario's planner (its
    /// `[planner]`, or its only `[planners.NAME]`): to compare planners on the same scenarios.
    #[serde(default)]
    pub planner: Option<toml::Table>,
    /// Keys to set in the scenario: bare names are keys of the scenario's planner (`beta_deg`,
    /// `declaration`), dotted paths reach any table (`plume.vertical_diffusivity_m2ps`,
    /// `sources.0.z_m`, `planners.tracer.beta_deg`).
    #[serde(default)]
    pub set: toml::Table,
}

/// Whether a campaign may fly the test seeds of the benchmark's tasks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TestSeeds {
    /// Refuse a campaign that reaches one (tuning, the default).
    #[default]
    Refuse,
    /// Fly them (evaluation, asked for with `--test-seeds`).
    Allow,
}

/// Most seeds per group.
pub const MAX_SEEDS: u64 = 1_000_000;
/// Most runs of one campaign (its run list is made in memory).
pub const MAX_RUNS: u64 = 1_000_000;
/// Most sweep points.
pub const MAX_POINTS: usize = 10_000;
/// Most groups (scenarios x configurations x sweep points).
pub const MAX_GROUPS: usize = 10_000;
/// Most scenarios, and most configurations.
pub const MAX_LIST: usize = 1000;

/// A scenario of the campaign with its TOML, ready for overrides.
#[derive(Debug, Clone)]
pub struct ScenarioEntry {
    /// As written in the campaign (preset name or path).
    pub label: String,
    /// Where it came from.
    pub origin: Origin,
    /// Its TOML (a family's: its base scenario's).
    pub table: toml::Table,
    /// A family of sites (a `.family.toml` entry): each seed index flies its own site.
    pub family: Option<Family>,
    /// The scenario file's text, to name the line of a key it gives (empty for a preset, a
    /// family or a file not read).
    pub text: String,
}

/// One sweep point: the value of each swept key.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepPoint {
    /// `(key, value)` in the sweep's key order.
    pub values: Vec<(String, toml::Value)>,
}

impl SweepPoint {
    /// `key=value` pairs joined by `;` (empty without a sweep).
    pub fn label(&self) -> String {
        self.values
            .iter()
            .map(|(k, v)| format!("{k}={}", value_text(v)))
            .collect::<Vec<_>>()
            .join(";")
    }
}

/// A value as short text (strings without quotes).
pub fn value_text(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// A loaded, checked campaign.
#[derive(Debug, Clone)]
pub struct Campaign {
    /// The file as written.
    pub file: CampaignFile,
    /// Where it was read from.
    pub path: PathBuf,
    /// Its text, copied into the output directory.
    pub text: String,
    /// Scenarios with their TOML.
    pub scenarios: Vec<ScenarioEntry>,
    /// Configurations (at least one).
    pub configs: Vec<ConfigFile>,
    /// Sweep points (one empty point without a sweep).
    pub points: Vec<SweepPoint>,
    /// Planner keys a group gives that have no effect at its values, each naming the group
    /// (filled by [`Campaign::check_groups`]; the campaign command prints them).
    pub warnings: Vec<String>,
}

/// One run of the list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct RunKey {
    /// Scenario index.
    pub scenario: usize,
    /// Configuration index.
    pub config: usize,
    /// Sweep point index.
    pub point: usize,
    /// Seed index (0-based).
    pub seed_index: u64,
}

/// A shard: `index` of `count`, 1-based as written (`--shard 2/4`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// 1..=count.
    pub index: u64,
    /// Number of shards.
    pub count: u64,
}

/// Why a shard (`K/N`) was not understood.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ShardError {
    /// Not `K/N`.
    #[error("shard '{0}' is not K/N (e.g. 2/4)")]
    NotKOfN(String),
    /// K is not a whole number.
    #[error("shard '{0}': K is not a whole number")]
    BadIndex(String),
    /// N is not a whole number.
    #[error("shard '{0}': N is not a whole number")]
    BadCount(String),
    /// K is 0 or more than N.
    #[error("shard '{0}': need 1 <= K <= N")]
    OutOfRange(String),
}

impl std::str::FromStr for Shard {
    type Err = ShardError;
    fn from_str(s: &str) -> Result<Self, ShardError> {
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| ShardError::NotKOfN(s.into()))?;
        let k: u64 = k
            .trim()
            .parse()
            .map_err(|_| ShardError::BadIndex(s.into()))?;
        let n: u64 = n
            .trim()
            .parse()
            .map_err(|_| ShardError::BadCount(s.into()))?;
        if n == 0 || k == 0 || k > n {
            return Err(ShardError::OutOfRange(s.into()));
        }
        Ok(Shard { index: k, count: n })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Parses campaign text; errors name the key path.
pub fn parse_campaign(text: &str, path: &Path) -> Result<CampaignFile, CampaignError> {
    let file = path.display().to_string();
    if let Ok(table) = text.parse::<toml::Table>()
        && let Some((key, value)) =
            plumetrace_scenario::first_datetime(&toml::Value::Table(table), "")
    {
        return Err(CampaignError::Invalid {
            line: None,
            file,
            key,
            message: format!("is a date/time ({value}); no campaign key takes one"),
        });
    }
    let de = toml::Deserializer::parse(text).map_err(|e| CampaignError::Invalid {
        line: None,
        file: file.clone(),
        key: String::new(),
        message: e.to_string(),
    })?;
    let mut parsed: CampaignFile = serde_path_to_error::deserialize(de).map_err(|e| {
        let key = e.path().to_string();
        let inner = e.into_inner();
        // With a key path the message and its line; without one, the parser's whole report,
        // which shows where.
        if key == "." {
            // A key missing at the top needs no excerpt of the file.
            let message = if inner.message().starts_with("missing field") {
                missing_keys(text)
                    .unwrap_or_else(|| plumetrace_scenario::locate::suggest(inner.message()))
            } else {
                plumetrace_core::toml_message(&inner, false)
            };
            CampaignError::Invalid {
                line: None,
                file,
                key: String::new(),
                message,
            }
        } else {
            let mut message = plumetrace_scenario::locate::suggest(inner.message());
            if key == "seeds" {
                // Its bounds, not the type's (0 is refused too).
                message = message.replace(
                    "expected a whole number, 0 or more",
                    &format!("expected a whole number from 1 to {MAX_SEEDS}"),
                );
            }
            CampaignError::Invalid {
                line: inner
                    .span()
                    .map(|s| plumetrace_scenario::locate::line_at(text, s.start.min(text.len()))),
                file,
                key,
                message,
            }
        }
    })?;
    for c in &mut parsed.configs {
        c.set = dotted(std::mem::take(&mut c.set));
    }
    parsed.sweep = dotted(std::mem::take(&mut parsed.sweep));
    Ok(parsed)
}

/// The keys every campaign file has, each with what it is for.
const REQUIRED: [(&str, &str); 4] = [
    ("name", "the campaign's title"),
    ("seed", "the campaign seed its runs' seeds derive from"),
    ("seeds", "seeds per group"),
    ("scenarios", "preset names or scenario and family files"),
];

/// Every required key a campaign's text lacks at its top, in one message (serde names only the
/// first), or `None` when the text is not a table or lacks none.
fn missing_keys(text: &str) -> Option<String> {
    let table = text.parse::<toml::Table>().ok()?;
    let missing: Vec<&str> = REQUIRED
        .iter()
        .filter(|(k, _)| !table.contains_key(*k))
        .map(|(k, _)| *k)
        .collect();
    if missing.is_empty() {
        return None;
    }
    let listed: Vec<String> = missing.iter().map(|k| format!("`{k}`")).collect();
    let every: Vec<String> = REQUIRED
        .iter()
        .map(|(k, what)| format!("`{k}` ({what})"))
        .collect();
    Some(format!(
        "missing {} {}: every campaign file has {}; see docs/campaigns.md",
        if missing.len() == 1 { "key" } else { "keys" },
        listed.join(", "),
        every.join(", ")
    ))
}

/// `set` and `sweep` keys as dotted paths: `plume.vertical_diffusivity_m2ps = 0.002` written
/// without quotes is TOML for a table `plume` holding the key, which is read as the path it spells
/// (a bare key with a table value could only have been a planner key, and no planner key takes a
/// table). So an unquoted `flow.mean = { speed_mps = 0.2 }` sets `flow.mean.speed_mps` and keeps
/// the scenario's other `flow.mean` keys, where a quoted `"flow.mean" = { ... }` stays one key
/// whose table replaces the scenario's (docs/campaigns.md says so).
fn dotted(table: toml::Table) -> toml::Table {
    fn walk(prefix: &str, table: toml::Table, out: &mut toml::Table) {
        for (k, v) in table {
            let key = if prefix.is_empty() {
                k
            } else {
                format!("{prefix}.{k}")
            };
            match v {
                toml::Value::Table(inner) if !key.contains('.') || !prefix.is_empty() => {
                    walk(&key, inner, out)
                }
                v => {
                    out.insert(key, v);
                }
            }
        }
    }
    let mut out = toml::Table::new();
    walk("", table, &mut out);
    out
}

impl Campaign {
    /// Reads a campaign file, loads its scenarios and checks every group builds; a campaign
    /// that would fly a test seed of a benchmark task is refused ([`Campaign::load_with`]).
    pub fn load(path: &Path, seeds: Option<u64>) -> Result<Self, CampaignError> {
        Campaign::load_with(path, seeds, TestSeeds::Refuse)
    }

    /// [`Campaign::load`], saying whether the test seeds of the benchmark's tasks may be flown.
    pub fn load_with(
        path: &Path,
        seeds: Option<u64>,
        test_seeds: TestSeeds,
    ) -> Result<Self, CampaignError> {
        let text = plumetrace_env::input::read_text(path, plumetrace_env::input::MAX_TEXT_BYTES)
            .map_err(|e| CampaignError::Io {
                path: path.display().to_string(),
                message: e.to_string(),
            })?;
        let mut file = parse_campaign(&text, path)?;
        if let Some(n) = seeds {
            file.seeds = n;
        }
        let mut c =
            Campaign::resolve(file, path, text.clone(), true).map_err(|e| e.located(&text))?;
        if test_seeds == TestSeeds::Refuse {
            c.refuse_test_seeds().map_err(|e| e.located(&text))?;
        }
        c.check_groups().map_err(|e| e.located(&text))?;
        Ok(c)
    }

    /// Refuses a campaign whose runs reach a test seed of a benchmark task on that task's
    /// scenario (a family's name, or a scenario's `name`).
    pub fn refuse_test_seeds(&self) -> Result<(), CampaignError> {
        let Ok(set) = crate::benchmark::TaskSet::builtin() else {
            return Ok(());
        };
        for (i, s) in self.scenarios.iter().enumerate() {
            let name = match &s.family {
                Some(f) => Some(f.file.name.as_str()),
                None => s.table.get("name").and_then(toml::Value::as_str),
            };
            let Some(name) = name else { continue };
            if let Some(hit) = set.test_seed_use(name, self.file.seed, self.file.seeds) {
                let task = set.task(&hit.task).ok();
                return Err(CampaignError::Invalid {
                    line: None,
                    file: self.path.display().to_string(),
                    key: "seed".into(),
                    message: format!(
                        "seed {} with {} seeds flies test seeds of benchmark task '{}' (task \
                         set {}) on scenarios[{i}] '{}' (seed index {} is one); tune on its \
                         tuning seed{}, or pass --test-seeds to fly the test seeds on purpose",
                        self.file.seed,
                        self.file.seeds,
                        hit.task,
                        set.version,
                        s.label,
                        hit.seed_index,
                        task.map(|t| format!(" {}", t.tuning_seed))
                            .unwrap_or_default(),
                    ),
                });
            }
        }
        Ok(())
    }

    /// Expands a parsed file; `read_scenarios` false skips loading scenario files (merging needs
    /// only names and the sweep).
    pub fn resolve(
        file: CampaignFile,
        path: &Path,
        text: String,
        read_scenarios: bool,
    ) -> Result<Self, CampaignError> {
        let fname = path.display().to_string();
        let invalid = |key: String, message: String| CampaignError::Invalid {
            line: None,
            file: fname.clone(),
            key,
            message,
        };
        check_sizes(&file, &invalid)?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut scenarios: Vec<ScenarioEntry> = Vec::new();
        for (i, s) in file.scenarios.iter().enumerate() {
            if scenarios.iter().any(|e| &e.label == s) {
                return Err(invalid(
                    format!("scenarios[{i}]"),
                    format!("'{s}' is listed twice"),
                ));
            }
            scenarios.push(scenario_entry(i, s, &base, read_scenarios, &invalid)?);
        }
        let configs = resolve_configs(&file.configs, &invalid)?;
        let points = sweep_points(&file, configs.len() * scenarios.len(), &invalid)?;
        Ok(Campaign {
            file,
            path: path.to_path_buf(),
            text,
            scenarios,
            configs,
            points,
            warnings: Vec::new(),
        })
    }

    /// The success radius, if any.
    pub fn success_radius_m(&self) -> Option<f64> {
        self.file.success_radius_m
    }

    /// Within this distance of a declaration a source of a group's runs counts as located: the
    /// campaign's `success_radius_m`, or else the scenario's `mission.success_radius_m` (with the
    /// configuration's and the sweep point's keys set), or else its default.
    pub fn located_radius_m(&self, scenario: usize, config: usize, point: usize) -> f64 {
        if let Some(r) = self.file.success_radius_m {
            return r;
        }
        let table = self.group_table(scenario, config, point, 0).ok();
        let given = table.as_ref().and_then(|t| {
            let v = t.get("mission")?.get("success_radius_m")?;
            v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
        });
        given.unwrap_or(plumetrace_scenario::DEFAULT_SUCCESS_RADIUS_M)
    }

    /// Every group's located radius ([`Campaign::located_radius_m`]), sorted, each once.
    pub fn located_radii_m(&self) -> Vec<f64> {
        let mut radii = Vec::new();
        for scenario in 0..self.scenarios.len() {
            for config in 0..self.configs.len() {
                for point in 0..self.points.len() {
                    radii.push(self.located_radius_m(scenario, config, point));
                }
            }
        }
        radii.sort_by(f64::total_cmp);
        radii.dedup();
        radii
    }

    /// The success radius in words, after "a declaration": `within 10 m`, or without the
    /// campaign's key `within 50 m (the scenarios' mission.success_radius_m)`.
    pub fn success_within_text(&self) -> String {
        if let Some(r) = self.file.success_radius_m {
            return format!("within {r} m");
        }
        let radii: Vec<String> = self.located_radii_m().iter().map(f64::to_string).collect();
        match radii.as_slice() {
            [one] => format!("within {one} m (the scenarios' `mission.success_radius_m`)"),
            many => format!(
                "within its scenario's `mission.success_radius_m` ({} m)",
                many.join(", ")
            ),
        }
    }

    /// What runs are judged against besides their summaries (the success radius).
    pub fn metric_context(&self) -> plumetrace_mission::MetricContext {
        plumetrace_mission::MetricContext {
            success_radius_m: self.file.success_radius_m,
        }
    }

    /// Every run, in the canonical order: scenario, configuration, sweep point, seed index.
    pub fn runs(&self) -> Vec<RunKey> {
        let mut out = Vec::new();
        for scenario in 0..self.scenarios.len() {
            for config in 0..self.configs.len() {
                for point in 0..self.points.len() {
                    for seed_index in 0..self.file.seeds {
                        out.push(RunKey {
                            scenario,
                            config,
                            point,
                            seed_index,
                        });
                    }
                }
            }
        }
        out
    }

    /// The runs of one shard: every `count`-th run of the canonical list.
    pub fn shard_runs(&self, shard: Option<Shard>) -> Vec<RunKey> {
        let all = self.runs();
        match shard {
            None => all,
            Some(s) => all
                .into_iter()
                .enumerate()
                .filter(|(j, _)| (*j as u64) % s.count == s.index - 1)
                .map(|(_, k)| k)
                .collect(),
        }
    }

    /// The seed of a run: the same for every group at the same seed index.
    pub fn run_seed(&self, key: &RunKey) -> u64 {
        plumetrace_env::derive_seed(self.file.seed, key.seed_index)
    }

    /// The site a run flies, when its scenario is a family.
    pub fn site(&self, key: &RunKey) -> Option<Site> {
        self.scenarios[key.scenario]
            .family
            .as_ref()
            .map(|f| f.draw(self.run_seed(key)))
    }

    /// The scenario TOML of a group at a seed index (a family's site differs from seed to seed),
    /// with the configuration's and the sweep point's keys set.
    pub fn group_table(
        &self,
        scenario: usize,
        config: usize,
        point: usize,
        seed_index: u64,
    ) -> Result<toml::Table, CampaignError> {
        let entry = &self.scenarios[scenario];
        let mut t = match &entry.family {
            Some(f) => f.scenario(plumetrace_env::derive_seed(self.file.seed, seed_index)),
            None => entry.table.clone(),
        };
        let c = &self.configs[config];
        if let Some(p) = &c.planner {
            let path = planner_path(&t).map_err(|e| CampaignError::Invalid {
                line: None,
                file: self.path.display().to_string(),
                key: format!("configs[{config}].planner"),
                message: e.to_string(),
            })?;
            let segments: Vec<&str> = path.split('.').collect();
            set_path(&mut t, &segments, toml::Value::Table(p.clone())).map_err(|e| {
                CampaignError::Invalid {
                    line: None,
                    file: self.path.display().to_string(),
                    key: format!("configs[{config}].planner"),
                    message: e.to_string(),
                }
            })?;
        }
        for (k, v) in &c.set {
            set_key(&mut t, k, v.clone()).map_err(|e| CampaignError::Invalid {
                line: None,
                file: self.path.display().to_string(),
                key: format!("configs[{config}].set.{}", quoted(k)),
                message: e.to_string(),
            })?;
        }
        for (k, v) in &self.points[point].values {
            set_key(&mut t, k, v.clone()).map_err(|e| CampaignError::Invalid {
                line: None,
                file: self.path.display().to_string(),
                key: format!("sweep.{}", quoted(k)),
                message: e.to_string(),
            })?;
        }
        Ok(t)
    }

    /// Builds the scenario of a run.
    pub fn build(&self, key: &RunKey) -> Result<plumetrace_scenario::BuiltScenario, CampaignError> {
        let cfg = self.group_config(key.scenario, key.config, key.point, key.seed_index)?;
        let origin = &self.scenarios[key.scenario].origin;
        plumetrace_scenario::build(&cfg, origin, Some(self.run_seed(key)))
            .map_err(|e| self.group_error(key.scenario, key.config, key.point, e.to_string()))
    }

    fn group_config(
        &self,
        scenario: usize,
        config: usize,
        point: usize,
        seed_index: u64,
    ) -> Result<plumetrace_scenario::ScenarioConfig, CampaignError> {
        let t = self.group_table(scenario, config, point, seed_index)?;
        let origin = &self.scenarios[scenario].origin;
        plumetrace_scenario::from_table(t, origin)
            .map_err(|e| self.group_error_at(scenario, config, point, e.to_string(), e.key_path()))
    }

    /// A readable name of a group for errors and tables.
    pub fn group_name(&self, scenario: usize, config: usize, point: usize) -> String {
        let p = self.points[point].label();
        let mut s = format!(
            "scenario '{}', config '{}'",
            self.scenarios[scenario].label, self.configs[config].name
        );
        if !p.is_empty() {
            s.push_str(&format!(", sweep {p}"));
        }
        s
    }

    fn group_error(
        &self,
        scenario: usize,
        config: usize,
        point: usize,
        message: String,
    ) -> CampaignError {
        self.group_error_at(scenario, config, point, message, None)
    }

    /// [`Campaign::group_error`] for the scenario key `key` (`planner.beta_deg`,
    /// `plume.vertical_diffusivity_m2ps`), with the line of the campaign file that sets it.
    fn group_error_at(
        &self,
        scenario: usize,
        config: usize,
        point: usize,
        message: String,
        key: Option<&str>,
    ) -> CampaignError {
        let line = key.and_then(|k| self.line_setting(config, point, k));
        // A key the campaign does not give comes from the scenario's own file: its line there,
        // after the file's name that starts the scenario's message.
        let entry = &self.scenarios[scenario];
        let in_scenario = key
            .filter(|_| line.is_none())
            .and_then(|k| plumetrace_scenario::locate::line_of_key(&entry.text, k));
        let message = match in_scenario {
            Some(l) => {
                let origin = format!("{}: ", entry.origin);
                message.replacen(&origin, &format!("{}:{l}: ", entry.origin), 1)
            }
            None => message,
        };
        CampaignError::Group {
            file: self.path.display().to_string(),
            line,
            group: self.group_name(scenario, config, point),
            message,
        }
    }

    /// The line of the campaign file that gives scenario key `key` to configuration `config`
    /// at sweep point `point`: the sweep's key, else the configuration's `set`, else its planner
    /// table (the order they are applied in, last first). A bare key of `set` and of the sweep is
    /// the planner's; a planner key is the last part of `planner.NAME` or `planners.P.NAME`.
    fn line_setting(&self, config: usize, point: usize, key: &str) -> Option<usize> {
        // `name` in the table at `table`: written as one quoted key, or as the dotted path it
        // spells when written unquoted.
        let locate = |table: String, name: &str| {
            let at = |p: String| plumetrace_scenario::locate::line_of_key(&self.text, &p);
            at(format!("{table}.{}", quoted(name)))
                .or_else(|| at(format!("{table}.{}", dotted_path(name))))
        };
        let planner_key = key.strip_prefix("planner.").or_else(|| {
            key.strip_prefix("planners.")
                .and_then(|k| k.split_once('.'))
                .map(|(_, k)| k)
        });
        // A key the error names, one under a table it names (`plumes` for a `set` of
        // `plumes.vertical_diffusivity_m2ps`) or a table over it (a `set` of `flow.mean` for
        // `flow.mean.speed_mps`), however the paths are written (`sources[0]`, `sources.0`).
        let steps = plumetrace_scenario::locate::path_steps(key);
        let gives = |k: &str| {
            let given = plumetrace_scenario::locate::path_steps(k);
            let n = given.len().min(steps.len());
            (k.contains('.') && given[..n] == steps[..n])
                || k == key
                || (!k.contains('.') && Some(k) == planner_key)
        };
        if let Some((k, _)) = self.points[point].values.iter().find(|(k, _)| gives(k)) {
            return locate("sweep".into(), k);
        }
        let c = &self.configs[config];
        if let Some(k) = c.set.keys().find(|k| gives(k)) {
            return locate(format!("configs[{config}].set"), k);
        }
        // The configuration's planner table replaces the scenario's: a planner key it lacks
        // (`kind`, missing) belongs there too.
        let name = planner_key?;
        c.planner.as_ref()?;
        let table = format!("configs[{config}].planner");
        locate(table.clone(), name)
            .or_else(|| plumetrace_scenario::locate::line_of(&self.text, &table))
    }

    /// Builds every group once (scenario and planner settings), so a bad key fails before any
    /// run; keeps in `warnings` the planner keys a group gives that have no effect.
    pub fn check_groups(&mut self) -> Result<(), CampaignError> {
        let mut warnings = Vec::new();
        for s in 0..self.scenarios.len() {
            for c in 0..self.configs.len() {
                for p in 0..self.points.len() {
                    // A family is checked on its first site (every site has the same keys).
                    let cfg = self.group_config(s, c, p, 0)?;
                    let origin = &self.scenarios[s].origin;
                    let built = plumetrace_scenario::build(&cfg, origin, None)
                        .map_err(|e| self.group_error_at(s, c, p, e.to_string(), e.key_path()))?;
                    if built.mission.is_none() {
                        return Err(self.group_error(
                            s,
                            c,
                            p,
                            format!(
                                "scenarios[{s}]: '{}' has no [mission] table: campaigns run \
                                 missions",
                                self.scenarios[s].label
                            ),
                        ));
                    }
                    // The planner registry checks every planner key (set and sweep included).
                    let setup = plumetrace_mission::MissionSetup::new(built).map_err(|e| {
                        let key = match &e {
                            plumetrace_mission::MissionError::Invalid { error, .. } => {
                                Some(error.key.as_str())
                            }
                            _ => None,
                        };
                        self.group_error_at(s, c, p, e.to_string(), key)
                    })?;
                    for (_, key, why) in setup.inert_keys {
                        // Named by config (and sweep point): every scenario gives its keys.
                        let mut group = format!("config '{}'", self.configs[c].name);
                        let point = self.points[p].label();
                        if !point.is_empty() {
                            group.push_str(&format!(", sweep {point}"));
                        }
                        let w = format!("{group}: planner key {key} {why}");
                        if !warnings.contains(&w) {
                            warnings.push(w);
                        }
                    }
                }
            }
        }
        self.warnings = warnings;
        Ok(())
    }

    /// A digest of everything that decides the runs' results except the number of seeds: seed,
    /// scenarios' TOML, configurations, sweep, success radius, and the defaults of the planners
    /// the campaign flies (a build whose defaults differ does not resume or merge results
    /// recorded by another; a build that only adds a planner does). Resuming or merging requires
    /// equal fingerprints.
    pub fn fingerprint(&self) -> String {
        let flown = self.planner_kinds();
        let mut defaults = plumetrace_mission::planner_defaults();
        defaults.retain(|kind, _| flown.contains(kind));
        self.fingerprint_with(defaults)
    }

    /// The planner kinds the groups name: every `kind` in a group's table (at its first seed)
    /// that is a registered planner's.
    fn planner_kinds(&self) -> std::collections::BTreeSet<String> {
        fn collect(v: &toml::Value, out: &mut std::collections::BTreeSet<String>) {
            match v {
                toml::Value::Table(t) => {
                    // `kind`, or its older name `strategy`, as the planner registry reads them.
                    if let Some(k) = plumetrace_mission::planner_kind_name(t)
                        && plumetrace_mission::PlannerKind::from_name(k).is_some()
                    {
                        out.insert(k.to_owned());
                    }
                    t.values().for_each(|v| collect(v, out));
                }
                toml::Value::Array(a) => a.iter().for_each(|v| collect(v, out)),
                _ => {}
            }
        }
        let mut out = std::collections::BTreeSet::new();
        for s in 0..self.scenarios.len() {
            for c in 0..self.configs.len() {
                for p in 0..self.points.len() {
                    if let Ok(t) = self.group_table(s, c, p, 0) {
                        collect(&toml::Value::Table(t), &mut out);
                    }
                }
            }
        }
        out
    }

    /// [`Campaign::fingerprint`] with the planners' defaults given.
    fn fingerprint_with(&self, planner_defaults: toml::Table) -> String {
        #[derive(Serialize)]
        struct Canon<'a> {
            seed: u64,
            scenarios: Vec<(&'a str, &'a toml::Table)>,
            #[serde(skip_serializing_if = "Vec::is_empty")]
            families: Vec<&'a str>,
            configs: &'a [ConfigFile],
            sweep: &'a toml::Table,
            success_radius_m: Option<f64>,
            planner_defaults: toml::Table,
        }
        let canon = Canon {
            seed: self.file.seed,
            scenarios: self
                .scenarios
                .iter()
                .map(|s| (s.label.as_str(), &s.table))
                .collect(),
            families: self
                .scenarios
                .iter()
                .filter_map(|s| s.family.as_ref().map(|f| f.text.as_str()))
                .collect(),
            configs: &self.configs,
            sweep: &self.file.sweep,
            success_radius_m: self.file.success_radius_m,
            planner_defaults,
        };
        let text = serde_json::to_string(&canon).unwrap_or_default();
        format!("{:016x}", fnv1a(text.as_bytes()))
    }
}

/// Makes a [`CampaignError::Invalid`] from a key path and a message.
type Invalid<'a> = dyn Fn(String, String) -> CampaignError + 'a;

/// Checks the seeds, the lengths of the lists and the success radius.
fn check_sizes(file: &CampaignFile, invalid: &Invalid<'_>) -> Result<(), CampaignError> {
    if !(1..=MAX_SEEDS).contains(&file.seeds) {
        return Err(invalid(
            "seeds".into(),
            format!("must be 1 to {MAX_SEEDS}, got {}", file.seeds),
        ));
    }
    for (key, n, max) in [
        ("scenarios", file.scenarios.len(), MAX_LIST),
        ("configs", file.configs.len(), MAX_LIST),
        ("sweep", file.sweep.len(), 16),
    ] {
        if n > max {
            return Err(invalid(key.into(), format!("{n} entries; at most {max}")));
        }
    }
    if file.scenarios.is_empty() {
        return Err(invalid(
            "scenarios".into(),
            "name at least one scenario".into(),
        ));
    }
    if let Some(r) = file.success_radius_m
        && !(r.is_finite() && r > 0.0)
    {
        return Err(invalid(
            "success_radius_m".into(),
            format!("must be a finite number > 0, got {r}"),
        ));
    }
    Ok(())
}

/// The scenario `s` (entry `i` of the list): a family, a file next to the campaign file, or a
/// preset. `read` false leaves files and families unread.
fn scenario_entry(
    i: usize,
    s: &str,
    base: &Path,
    read: bool,
    invalid: &Invalid<'_>,
) -> Result<ScenarioEntry, CampaignError> {
    if is_family_path(s) {
        let p = base.join(s);
        let family = if read {
            Some(Family::load(&p).map_err(|e| invalid(format!("scenarios[{i}]"), e.to_string()))?)
        } else {
            None
        };
        return Ok(ScenarioEntry {
            label: s.to_string(),
            origin: family
                .as_ref()
                .map_or(Origin::File(p), |f| f.base_origin.clone()),
            table: family.as_ref().map(|f| f.base.clone()).unwrap_or_default(),
            family,
            text: String::new(),
        });
    }
    let (origin, text) = if s.ends_with(".toml") {
        let p = base.join(s);
        let text = if read {
            plumetrace_env::input::read_text(&p, plumetrace_env::input::MAX_TEXT_BYTES)
                .map_err(|e| invalid(format!("scenarios[{i}]"), format!("{}: {e}", p.display())))?
        } else {
            String::new()
        };
        (Origin::File(p), text)
    } else if let Some(p) = find_preset(s) {
        (Origin::Preset(s.to_string()), p.toml.to_string())
    } else {
        let known: Vec<&str> = PRESETS.iter().map(|p| p.name).collect();
        let near = plumetrace_core::closest(s, &known)
            .map(|n| format!("; did you mean '{n}'?"))
            .unwrap_or_default();
        return Err(invalid(
            format!("scenarios[{i}]"),
            format!(
                "'{s}' is neither a preset ({}) nor a path ending in .toml{near}",
                known.join(", ")
            ),
        ));
    };
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        invalid(format!("scenarios[{i}]"), format!("{origin}: {e}"))
    })?;
    let text = match origin {
        Origin::File(_) => text,
        _ => String::new(),
    };
    Ok(ScenarioEntry {
        label: s.to_string(),
        origin,
        table,
        family: None,
        text,
    })
}

/// The configurations (one, "default", when none is given), their names checked.
fn resolve_configs(
    given: &[ConfigFile],
    invalid: &Invalid<'_>,
) -> Result<Vec<ConfigFile>, CampaignError> {
    let configs = if given.is_empty() {
        vec![ConfigFile {
            name: "default".into(),
            planner: None,
            set: toml::Table::new(),
        }]
    } else {
        given.to_vec()
    };
    for (i, c) in configs.iter().enumerate() {
        if c.name.trim().is_empty() {
            return Err(invalid(
                format!("configs[{i}].name"),
                "must not be empty".into(),
            ));
        }
        if c.name.chars().any(char::is_control) || c.name.chars().count() > 200 {
            return Err(invalid(
                format!("configs[{i}].name"),
                "must be one line of at most 200 characters (it names the group in tables \
                 and charts)"
                    .into(),
            ));
        }
        if configs[..i].iter().any(|d| d.name == c.name) {
            return Err(invalid(
                format!("configs[{i}].name"),
                format!("'{}' is used twice", c.name),
            ));
        }
    }
    Ok(configs)
}

/// The sweep's points (every combination of its values; one empty point without a sweep), its
/// size, and the number of runs of `groups_per_point` groups per point, checked first.
fn sweep_points(
    file: &CampaignFile,
    groups_per_point: usize,
    invalid: &Invalid<'_>,
) -> Result<Vec<SweepPoint>, CampaignError> {
    let mut n_points: usize = 1;
    for (key, values) in &file.sweep {
        let toml::Value::Array(values) = values else {
            continue;
        };
        for (i, v) in values.iter().enumerate() {
            if values[..i].iter().any(|w| value_text(w) == value_text(v)) {
                return Err(invalid(
                    format!("sweep.{}[{i}]", quoted(key)),
                    format!("{} is listed twice", value_text(v)),
                ));
            }
        }
        n_points = n_points.saturating_mul(values.len().max(1));
    }
    let groups = n_points.saturating_mul(groups_per_point);
    if n_points > MAX_POINTS || groups > MAX_GROUPS {
        return Err(invalid(
            "sweep".into(),
            format!(
                "{n_points} sweep points, {groups} groups (scenarios x configs x points); at \
                 most {MAX_POINTS} points and {MAX_GROUPS} groups"
            ),
        ));
    }
    let runs = (groups as u64).saturating_mul(file.seeds);
    if runs > MAX_RUNS {
        return Err(invalid(
            "seeds".into(),
            format!(
                "{groups} groups x {} seeds = {runs} runs; at most {MAX_RUNS} in one campaign \
                 (split it into several)",
                file.seeds
            ),
        ));
    }
    let mut points = vec![SweepPoint { values: Vec::new() }];
    for (key, values) in &file.sweep {
        let toml::Value::Array(values) = values else {
            return Err(invalid(
                format!("sweep.{}", quoted(key)),
                "must be an array of values".into(),
            ));
        };
        if values.is_empty() {
            return Err(invalid(
                format!("sweep.{}", quoted(key)),
                "must not be empty".into(),
            ));
        }
        let mut next = Vec::new();
        for p in &points {
            for v in values {
                let mut q = p.clone();
                q.values.push((key.clone(), v.clone()));
                next.push(q);
            }
        }
        points = next;
    }
    Ok(points)
}

/// A dotted key's parts, each quoted as a key path needs.
fn dotted_path(key: &str) -> String {
    key.split('.').map(quoted).collect::<Vec<_>>().join(".")
}

/// A key as written in a key path.
fn quoted(key: &str) -> String {
    plumetrace_core::params::quoted_key(key)
}

/// FNV-1a, 64 bits: a stable digest (std's hasher may change between releases).
pub(crate) fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_campaign_missing_its_keys_names_them_all_at_once() {
        let path = Path::new("c.toml");
        let message = |text: &str| match parse_campaign(text, path) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("{text:?} parsed"),
        };
        let m = message("scenarios = [\"demo\"]\nseeds = 2\n");
        assert!(m.contains("c.toml: missing keys `name`, `seed`: every campaign file has `name` (the campaign's title), `seed` ("), "{m}");
        assert!(m.contains("docs/campaigns.md"), "{m}");
        let m = message("name = \"c\"\nseed = 1\nscenarios = [\"demo\"]\n");
        assert!(m.contains("missing key `seeds`:"), "{m}");
        // A field missing deeper is serde's message, with its place.
        let m = message(
            "name = \"c\"\nseed = 1\nseeds = 1\nscenarios = [\"demo\"]\n[[configs]]\nset = {}\n",
        );
        assert!(m.contains("missing field `name`"), "{m}");
        assert!(m.contains("configs"), "{m}");
    }

    #[test]
    fn the_campaigns_success_radius_replaces_the_scenarios() {
        let text = "name = \"c\"\nseed = 1\nseeds = 1\nscenarios = [\"demo\", \"li-zhang-open\"]\n\
                    [[configs]]\nname = \"a\"\n[[configs]]\nname = \"wide\"\n\
                    [configs.set]\n\"mission.success_radius_m\" = 80\n";
        let path = Path::new("c.toml");
        let resolve = |text: &str| {
            let file = parse_campaign(text, path).unwrap();
            Campaign::resolve(file, path, text.to_string(), true).unwrap()
        };
        let c = resolve(text);
        // Without the campaign's key: each group's scenario (and configuration) says.
        assert_eq!(c.located_radius_m(0, 0, 0), 50.0, "the default");
        assert_eq!(c.located_radius_m(1, 0, 0), 10.0, "the preset's");
        assert_eq!(c.located_radius_m(1, 1, 0), 80.0, "the configuration's");
        assert_eq!(c.located_radii_m(), vec![10.0, 50.0, 80.0]);
        assert_eq!(
            c.success_within_text(),
            "within its scenario's `mission.success_radius_m` (10, 50, 80 m)"
        );
        assert_eq!(c.metric_context().success_radius_m, None);
        // With it: every run's.
        let c = resolve(&format!("success_radius_m = 5.0\n{text}"));
        assert_eq!(c.located_radius_m(1, 1, 0), 5.0);
        assert_eq!(c.located_radii_m(), vec![5.0]);
        assert_eq!(c.success_within_text(), "within 5 m");
        assert_eq!(c.metric_context().success_radius_m, Some(5.0));
    }

    #[test]
    fn a_config_can_replace_the_scenarios_planner_and_the_registry_checks_it() {
        let text = "name = \"c\"\nseed = 1\nseeds = 1\nscenarios = [\"demo\"]\n\
                    [[configs]]\nname = \"survey\"\n[configs.planner]\nkind = \"lawnmower\"\n\
                    [configs.set]\nlane_spacing_m = 30.0\n";
        let path = Path::new("c.toml");
        let file = parse_campaign(text, path).unwrap();
        let mut c = Campaign::resolve(file, path, text.to_string(), true).unwrap();
        let t = c.group_table(0, 0, 0, 0).unwrap();
        let planner = t["planner"].as_table().unwrap();
        assert_eq!(planner["kind"].as_str(), Some("lawnmower"));
        assert_eq!(planner["lane_spacing_m"].as_float(), Some(30.0));
        assert!(
            !planner.contains_key("mapping_lines"),
            "the AMP's keys are gone"
        );
        assert!(c.check_groups().is_ok());
        // A key the lawnmower does not have is refused with its path.
        let bad = text.replace("lane_spacing_m = 30.0", "beta_deg = 30.0");
        let file = parse_campaign(&bad, path).unwrap();
        let mut c = Campaign::resolve(file, path, bad.clone(), true).unwrap();
        let e = c.check_groups().unwrap_err().to_string();
        assert!(
            e.contains("planner.beta_deg") && e.contains("unknown field"),
            "{e}"
        );
    }

    #[test]
    fn a_bad_key_is_named_with_the_campaign_line_that_gives_it() {
        let head = "name = \"c\"\nseed = 1\nseeds = 1\nscenarios = [\"demo\"]\n\n\
                    [[configs]]\nname = \"ok\"\n\n";
        let path = Path::new("c.toml");
        let error = |tail: &str| {
            let text = format!("{head}{tail}");
            let file = parse_campaign(&text, path).unwrap();
            let mut c = Campaign::resolve(file, path, text, true).unwrap();
            c.check_groups().unwrap_err().to_string()
        };
        // A planner table's key (line 13), a bare `set` key, a dotted `set` path to a planner
        // and to another table (line 11), a swept key (line 10).
        let cases = [
            (
                "[[configs]]\nname = \"b\"\n[configs.planner]\nkind = \"amp\"\nbeta_dgs = 3.0\n",
                "c.toml:13: scenario 'demo', config 'b'",
                "planner.beta_dgs: unknown field",
            ),
            (
                "[[configs]]\nname = \"b\"\nset = { beta_deg = 300.0 }\n",
                "c.toml:11: scenario 'demo', config 'b'",
                "planner.beta_deg: must be >= 0",
            ),
            (
                "[[configs]]\nname = \"b\"\nset = { \"planner.l_u_m\" = \"x\" }\n",
                "c.toml:11: scenario 'demo', config 'b'",
                "planner.l_u_m: invalid type",
            ),
            (
                "[[configs]]\nname = \"b\"\nset = { \"plume.vertical_diffusivity_m2ps\" = -1.0 }\n",
                "c.toml:11: scenario 'demo', config 'b'",
                "plume.vertical_diffusivity_m2ps: must be >= 0",
            ),
            (
                "[sweep]\nl_c_m = [\n  10.0,\n  -1.0,\n]\n",
                "c.toml:10: scenario 'demo', config 'ok', sweep l_c_m=-1.0",
                "planner.l_c_m: must be >= 0",
            ),
            // More places: an index the error writes `sources[0]`, a table whose key is at
            // fault, an unquoted dotted path (TOML's nested table) in `set`, a misspelled table
            // in one, a planner table without `kind` (its own line).
            (
                "[[configs]]\nname = \"b\"\nset = { \"sources.0.z_m\" = -3.0 }\n",
                "c.toml:11: scenario 'demo', config 'b'",
                "sources[0].z_m: must be >= 0",
            ),
            (
                "[[configs]]\nname = \"b\"\n\
                 set = { \"flow.mean\" = { speed_mps = -1.0, toward_deg = 80.0 } }\n",
                "c.toml:11: scenario 'demo', config 'b'",
                "flow.mean.speed_mps: must be >= 0",
            ),
            (
                "[[configs]]\nname = \"b\"\n[configs.set]\nplume.vertical_diffusivity_m2s = 1.0\n",
                "c.toml:12: scenario 'demo', config 'b'",
                "plume.vertical_diffusivity_m2s: unknown field",
            ),
            (
                "[[configs]]\nname = \"b\"\nset = { \"plumes.vertical_diffusivity_m2ps\" = 1.0 }\n",
                "c.toml:11: scenario 'demo', config 'b'",
                "plumes: unknown field",
            ),
            (
                "[[configs]]\nname = \"b\"\n[configs.planner]\nbeta_deg = 30.0\n",
                "c.toml:11: scenario 'demo', config 'b'",
                "planner.kind: missing",
            ),
        ];
        for (tail, head_of_error, what) in cases {
            let e = error(tail);
            assert!(e.starts_with(head_of_error), "{e}");
            assert!(e.contains(what), "{e}");
        }
    }

    #[test]
    fn dotted_keys_written_without_quotes_are_the_paths_they_spell() {
        let text = "name = \"c\"\nseed = 1\nseeds = 1\nscenarios = [\"demo\"]\n\
                    [[configs]]\nname = \"b\"\n[configs.set]\n\
                    plume.vertical_diffusivity_m2ps = 0.002\nmission.time_limit_s = 600\n\
                    beta_deg = 25.0\n\"flow.mean\" = { speed_mps = 0.2, toward_deg = 80.0 }\n\
                    [sweep]\nplanner.l_u_m = [12.0, 18.0]\n";
        let path = Path::new("c.toml");
        let file = parse_campaign(text, path).unwrap();
        let set: Vec<&str> = file.configs[0].set.keys().map(String::as_str).collect();
        assert_eq!(
            set,
            [
                "beta_deg",
                "flow.mean",
                "mission.time_limit_s",
                "plume.vertical_diffusivity_m2ps"
            ]
        );
        assert!(
            file.configs[0].set["flow.mean"].is_table(),
            "a quoted key keeps its table"
        );
        assert_eq!(file.sweep.keys().collect::<Vec<_>>(), ["planner.l_u_m"]);
        let mut c = Campaign::resolve(file, path, text.to_string(), true).unwrap();
        c.check_groups().unwrap();
        let t = c.group_table(0, 0, 1, 0).unwrap();
        assert_eq!(
            t["plume"]["vertical_diffusivity_m2ps"].as_float(),
            Some(0.002)
        );
        assert_eq!(t["mission"]["time_limit_s"].as_integer(), Some(600));
        assert_eq!(t["planner"]["l_u_m"].as_float(), Some(18.0));
        assert_eq!(t["flow"]["mean"]["toward_deg"].as_float(), Some(80.0));
    }

    #[test]
    fn a_key_of_the_scenario_file_is_named_with_its_line_there_and_file_errors_with_theirs() {
        let dir = tempfile::tempdir().unwrap();
        let scenario = plumetrace_scenario::find_preset("demo")
            .unwrap()
            .toml
            .replace("kind = \"amp\"", "kind = \"amp\"\nbeta_dgs = 20.0");
        std::fs::write(dir.path().join("s.toml"), &scenario).unwrap();
        let line = scenario
            .lines()
            .position(|l| l.starts_with("beta_dgs"))
            .unwrap()
            + 1;
        let path = dir.path().join("c.toml");
        let text = "name = \"c\"\nseed = 1\nseeds = 1\nscenarios = [\"s.toml\"]\n";
        std::fs::write(&path, text).unwrap();
        let e = Campaign::load(&path, None).unwrap_err().to_string();
        assert!(
            e.contains(&format!("s.toml:{line}: planner.beta_dgs: unknown field")),
            "{e}"
        );
        // The key is the scenario's, not the campaign file's: no line of c.toml is given.
        assert!(
            !e.split("c.toml:")
                .skip(1)
                .any(|rest| rest.starts_with(|c: char| c.is_ascii_digit())),
            "{e}"
        );
        // The campaign file's own bad values name their lines.
        for (bad, want) in [
            ("seeds = 0", "c.toml:3: seeds: must be 1 to"),
            (
                "seeds = 2.5",
                "c.toml:3: seeds: invalid type: floating point `2.5`, expected a whole \
                 number from 1 to 1000000",
            ),
            (
                "seeds = 1\nsuccess_radius_m = -5.0",
                "c.toml:4: success_radius_m:",
            ),
        ] {
            std::fs::write(&path, text.replace("seeds = 1", bad)).unwrap();
            let e = Campaign::load(&path, None).unwrap_err().to_string();
            assert!(e.contains(want), "{e}");
        }
    }

    #[test]
    fn planner_keys_without_effect_are_kept_as_warnings_naming_the_config() {
        let text = "name = \"c\"\nseed = 1\nseeds = 1\nscenarios = [\"demo\", \"demo-survey\"]\n\
                    [[configs]]\nname = \"no-smoothing\"\n[configs.planner]\nkind = \"amp\"\n\
                    fix_smoothing = false\nfix_wait_s = 300.0\n\
                    [[configs]]\nname = \"default\"\n[configs.planner]\nkind = \"amp\"\n";
        let path = Path::new("c.toml");
        let file = parse_campaign(text, path).unwrap();
        let mut c = Campaign::resolve(file, path, text.to_string(), true).unwrap();
        assert!(c.warnings.is_empty(), "filled by check_groups");
        c.check_groups().unwrap();
        // Once, however many scenarios give the key.
        assert_eq!(c.warnings.len(), 1, "{:?}", c.warnings);
        assert!(
            c.warnings[0].starts_with(
                "config 'no-smoothing': planner key fix_wait_s has no effect with fix_smoothing = \
                 false"
            ),
            "{:?}",
            c.warnings
        );
    }

    #[test]
    fn the_fingerprint_changes_with_a_planners_default() {
        let text = "name = \"c\"\nseed = 1\nseeds = 1\nscenarios = [\"demo\"]\n\
                    [[configs]]\nname = \"amp\"\n[configs.planner]\nkind = \"amp\"\n";
        let path = Path::new("c.toml");
        let file = parse_campaign(text, path).unwrap();
        let c = Campaign::resolve(file, path, text.to_string(), true).unwrap();
        let mut defaults = plumetrace_mission::planner_defaults();
        defaults.retain(|kind, _| kind == "amp");
        assert_eq!(c.fingerprint(), c.fingerprint_with(defaults.clone()));
        let mut other = defaults;
        if let Some(toml::Value::Table(amp)) = other.get_mut("amp") {
            amp.insert("map_mass".into(), toml::Value::Float(0.123));
        }
        assert_ne!(c.fingerprint(), c.fingerprint_with(other));
        // Only the planners the campaign flies count: one added to the registry changes nothing.
        assert_eq!(c.planner_kinds().into_iter().collect::<Vec<_>>(), ["amp"]);
    }

    #[test]
    fn a_planner_named_by_its_older_key_counts_in_the_fingerprint() {
        let kinds = |key: &str| {
            let text = format!(
                "name = \"c\"\nseed = 1\nseeds = 1\nscenarios = [\"demo\"]\n\
                 [[configs]]\nname = \"m\"\n[configs.planner]\n{key} = \"moth\"\n"
            );
            let path = Path::new("c.toml");
            let file = parse_campaign(&text, path).unwrap();
            let c = Campaign::resolve(file, path, text.clone(), true).unwrap();
            (
                c.planner_kinds().into_iter().collect::<Vec<_>>(),
                c.fingerprint(),
            )
        };
        let (by_kind, print_kind) = kinds("kind");
        let (by_strategy, print_strategy) = kinds("strategy");
        assert_eq!(by_kind, ["moth"]);
        assert_eq!(
            by_strategy,
            ["moth"],
            "`strategy` names the planner as `kind` does"
        );
        // The two files differ only in the key's spelling, which the configurations record.
        assert_ne!(print_kind, print_strategy);
    }

    #[test]
    fn shards_parse_and_reject_nonsense() {
        assert_eq!("2/4".parse::<Shard>(), Ok(Shard { index: 2, count: 4 }));
        for bad in ["0/4", "5/4", "2", "a/b", "1/0"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }
}
