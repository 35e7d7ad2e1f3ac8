//! Running one input in-process, as the CLI would, and classifying what happened.
//!
//! - Scenario inputs are written to `fuzz.toml` in a temporary directory and go through
//!   `plumetrace check`'s path: parse (or, for bytes that are not UTF-8, the CLI's own loader
//!   `load_file`), build, and for missions `MissionSetup::new`. An accepted scenario is then
//!   run briefly. Missions: the parsed config's `mission.spinup_s` is capped at
//!   [`SPINUP_CAP_S`] and `mission.time_limit_s` at [`TIME_LIMIT_CAP_S`] (only values above the
//!   caps are lowered, so a NaN that `check` let through still reaches the run), the scenario
//!   is built again and flown without the mean-plume grid, every number of the summary and
//!   every trajectory row is checked, and the figure is drawn. Plume-only scenarios step the
//!   environment at most [`PLUME_STEP_CAP`] times and query the output grid.
//! - Campaign inputs are written to `fuzz-campaign.toml` next to `scenario.toml` (the `demo`
//!   preset) and `plume.toml` (`plume-demo`), parsed, resolved (scenario files read), checked
//!   group by group, and their runs counted; no mission is flown.
//!
//! The loops the harness drives (mission steps, plume steps) stop at the per-input deadline
//! and report a hang themselves; anything else that runs past it is left to the batch's
//! watchdog.

use crate::classify::{Class, classify_rejection};
use crate::corpus::{Target, campaign_side_files, family_side_files, site_side_files};
use crate::generate::Input;
use plumetrace_campaign::spec::{Campaign, parse_campaign};
use plumetrace_env::ConcentrationField;
use plumetrace_mission::{Mission, MissionOptions, MissionRun, MissionSetup};
use plumetrace_scenario::{BuiltScenario, Origin};
use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Spin-up of the short run at most, s.
pub const SPINUP_CAP_S: f64 = 60.0;
/// Mission time of the short run at most, s.
pub const TIME_LIMIT_CAP_S: f64 = 30.0;
/// Environment steps of a plume-only short run at most.
pub const PLUME_STEP_CAP: u64 = 200;
/// An input that takes longer than this (but finishes) is reported as slow, s.
pub const SLOW_S: f64 = 1.0;

/// Summary fields that may be JSON null (the `Option` fields of
/// `plumetrace_mission::summary` and of its team summary, `plumetrace_mission::team`; array
/// indices written `[]`). Any other null is a number
/// that was not finite.
const NULLABLE: &[&str] = &[
    "first_declaration",
    "first_detection_s",
    "trace_length_m",
    "detection_to_source_m",
    "longest_quiet_s",
    "sources[].nearest_error_m",
    "vehicles[].planner",
    "vehicles[].first_detection_s",
    "vehicles[].longest_quiet_s",
    "vehicles[].longest_quiet_behaviour",
    "team",
    "team.converged_s",
    "team.range_error_median_m",
    "team.range_error_p90_m",
    "team.range_setpoint_m",
    "team.centroid_cross_median_m",
    "team.centroid_cross_final_m",
    "team.distance_overhead",
    "team.scale_min",
    "team.scale_max",
    "team.scale_final",
];

/// What happened to one input.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Its class.
    pub class: Class,
    /// The error, panic or check message (for accepted inputs: what ran).
    pub message: String,
    /// Wall time, s.
    pub secs: f64,
}

impl Outcome {
    /// Finished, but took longer than [`SLOW_S`].
    pub fn slow(&self) -> bool {
        self.secs > SLOW_S
    }
}

/// The temporary directory inputs are written to.
pub struct Workdir {
    dir: tempfile::TempDir,
    scenario: PathBuf,
    campaign: PathBuf,
    families: PathBuf,
}

impl Workdir {
    /// A fresh directory with the campaign side files.
    pub fn new() -> anyhow::Result<Self> {
        let dir = tempfile::Builder::new()
            .prefix("plumetrace-fuzz-")
            .tempdir()?;
        let scenario = dir.path().join("scenario");
        let campaign = dir.path().join("campaign");
        std::fs::create_dir_all(&scenario)?;
        std::fs::create_dir_all(&campaign)?;
        for (name, text) in campaign_side_files() {
            std::fs::write(campaign.join(name), text)?;
        }
        let sites = dir.path().join("sites");
        std::fs::create_dir_all(&sites)?;
        for (name, bytes) in site_side_files() {
            std::fs::write(sites.join(name), bytes)?;
        }
        let families = dir.path().join("families");
        std::fs::create_dir_all(&families)?;
        for (name, text) in family_side_files() {
            std::fs::write(families.join(name), text)?;
        }
        Ok(Workdir {
            dir,
            scenario,
            campaign,
            families,
        })
    }

    /// Where an input of `target` is written.
    pub fn path(&self, target: Target) -> PathBuf {
        match target {
            Target::Scenario => self.scenario.join(target.file_name()),
            Target::Campaign => self.campaign.join(target.file_name()),
            Target::Family => self.families.join(target.file_name()),
            Target::Onboard => self.scenario.join(target.file_name()),
            Target::Netcdf | Target::Seabed => self.scenario.join(target.file_name()),
        }
    }

    /// `message` with the directory replaced by `<tmp>`, so messages compare across runs.
    pub fn normalise(&self, message: &str) -> String {
        message.replace(&self.dir.path().display().to_string(), "<tmp>")
    }
}

/// Why a run stopped short of acceptance.
enum Stop {
    /// An error message (classified by the location rule).
    Rejected(String),
    /// A number that should be finite is not.
    Nonfinite(String),
    /// The deadline passed.
    Deadline(String),
}

fn rejected(e: impl std::fmt::Display) -> Stop {
    Stop::Rejected(e.to_string())
}

fn check_deadline(deadline: Instant, what: impl FnOnce() -> String) -> Result<(), Stop> {
    if Instant::now() > deadline {
        Err(Stop::Deadline(format!("past the time limit {}", what())))
    } else {
        Ok(())
    }
}

/// The message of the last panic (set by the hook, taken by [`run`]).
static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);

/// Installs a panic hook that records the message and location instead of printing them (a
/// panic is a finding, reported by the pass).
pub fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        let p = info.payload();
        let msg = p
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "(a panic without a message)".into());
        let at = info
            .location()
            .map(|l| format!(" at {}:{}:{}", l.file(), l.line(), l.column()))
            .unwrap_or_default();
        if let Ok(mut g) = LAST_PANIC.lock() {
            *g = Some(format!("panicked: {msg}{at}"));
        }
    }));
}

/// Runs `input` in-process with a deadline `timeout_s` from now; `Err` only when the harness
/// itself fails (the input file cannot be written).
pub fn run(input: &Input, wd: &Workdir, timeout_s: f64) -> anyhow::Result<Outcome> {
    let path = wd.path(input.target);
    std::fs::write(&path, &input.bytes)?;
    if let Ok(mut g) = LAST_PANIC.lock() {
        *g = None;
    }
    let start = Instant::now();
    let deadline =
        start + Duration::try_from_secs_f64(timeout_s).unwrap_or(Duration::from_secs(30));
    let result = std::panic::catch_unwind(AssertUnwindSafe(|| match input.target {
        Target::Scenario => scenario(input, &path, deadline),
        Target::Campaign => campaign(input, &path, deadline),
        Target::Family => family(input, &path, deadline),
        Target::Onboard => onboard(input, &path),
        Target::Netcdf => netcdf(&path),
        Target::Seabed => seabed(&path),
    }));
    let secs = start.elapsed().as_secs_f64();
    let (class, message) = match result {
        Ok(Ok(m)) => (Class::Accepted, m),
        Ok(Err(Stop::Rejected(m))) => {
            let m = wd.normalise(&m);
            let class = classify_rejection(&m, input.target.file_name(), &input.text_lossy());
            (class, m)
        }
        Ok(Err(Stop::Nonfinite(m))) => (Class::NonfiniteOutput, m),
        Ok(Err(Stop::Deadline(m))) => (Class::Hang, m),
        Err(payload) => {
            let recorded = LAST_PANIC.lock().ok().and_then(|mut g| g.take());
            let m = recorded.unwrap_or_else(|| {
                payload
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| payload.downcast_ref::<&str>().map(|s| (*s).to_string()))
                    .unwrap_or_else(|| "panicked".into())
            });
            (Class::Panic, m)
        }
    };
    Ok(Outcome {
        class,
        message: wd.normalise(&message),
        secs,
    })
}

/// Sites drawn from a family input, each built and checked as `check` does.
fn family(input: &Input, path: &Path, deadline: Instant) -> Result<String, Stop> {
    let f = match std::str::from_utf8(&input.bytes) {
        Ok(text) => plumetrace_scenario::Family::parse(text, path).map_err(rejected)?,
        Err(_) => plumetrace_scenario::Family::load(path).map_err(rejected)?,
    };
    for seed in 0..FAMILY_SITES {
        let origin = Origin::File(path.to_path_buf());
        let cfg = plumetrace_scenario::from_table(f.scenario(seed), &origin)
            .map_err(|e| rejected(format!("site of seed {seed}: {e}")))?;
        let built = plumetrace_scenario::build(&cfg, &origin, Some(seed))
            .map_err(|e| rejected(format!("site of seed {seed}: {e}")))?;
        MissionSetup::new(built).map_err(|e| rejected(format!("site of seed {seed}: {e}")))?;
        check_deadline(deadline, || format!("checking the site of seed {seed}"))?;
    }
    Ok(format!("family: {FAMILY_SITES} sites built"))
}

/// An onboard file checked as `plumetrace onboard FILE --check` does: every key, the planner
/// built against the file's mission; nothing is connected. Errors are placed as the command
/// places them (the file, the key's line, the key).
fn onboard(input: &Input, path: &Path) -> Result<String, Stop> {
    let text = std::str::from_utf8(&input.bytes).map_err(|e| {
        rejected(format!(
            "{}: not UTF-8 at byte {}",
            path.display(),
            e.valid_up_to()
        ))
    })?;
    let o = plumetrace_onboard::config::Onboard::from_toml(text).map_err(|e| {
        let line = plumetrace_scenario::locate::at_line(plumetrace_scenario::locate::line_of(
            text, &e.key,
        ));
        rejected(format!("{}{line}: {e}", path.display()))
    })?;
    Ok(format!("onboard: {} checked", o.planner.kind().name()))
}

/// The example site's scenario over the input as its currents (over the site's own seabed):
/// read and sampled as `check` does, then the flow queried over the domain (every velocity
/// finite).
fn netcdf(path: &Path) -> Result<String, Stop> {
    let scenario = path.with_file_name("fuzz-currents.toml");
    let text = crate::corpus::netcdf_scenario();
    std::fs::write(&scenario, &text).map_err(rejected)?;
    // The site's seabed, which its scenario reads beside the currents (not the input).
    std::fs::write(
        path.with_file_name(crate::corpus::NETCDF_SEABED),
        include_bytes!("../../../examples/sites/seabed.nc"),
    )
    .map_err(rejected)?;
    let origin = Origin::File(scenario.clone());
    let cfg = plumetrace_scenario::parse(&text, &origin).map_err(rejected)?;
    let built = plumetrace_scenario::build(&cfg, &origin, None).map_err(rejected)?;
    use plumetrace_env::FlowField as _;
    let flow = built.env.flow();
    for k in 0..=20 {
        let p =
            plumetrace_core::Vec2::new(-50.0 + 30.0 * f64::from(k), -160.0 + 16.0 * f64::from(k));
        let v = flow.velocity(p);
        if !(v.x.is_finite() && v.y.is_finite()) {
            return Err(Stop::Nonfinite(format!("flow velocity at {p:?}: {v:?}")));
        }
    }
    Ok("netcdf: currents read and sampled".into())
}

/// The example site's scenario over the input as its bathymetry (under the site's own
/// currents): read and sampled as `check` does (its variable, units, sign, land and coverage of
/// the op-area), then the seabed queried over the domain (every height finite, between the
/// datum and the surface).
fn seabed(path: &Path) -> Result<String, Stop> {
    let scenario = path.with_file_name("fuzz-bathymetry.toml");
    let text = crate::corpus::seabed_scenario();
    std::fs::write(&scenario, &text).map_err(rejected)?;
    // The site's currents, which its scenario reads beside the seabed (not the input).
    std::fs::write(
        path.with_file_name(crate::corpus::SEABED_CURRENTS),
        include_bytes!("../../../examples/sites/currents.nc"),
    )
    .map_err(rejected)?;
    let origin = Origin::File(scenario.clone());
    let cfg = plumetrace_scenario::parse(&text, &origin).map_err(rejected)?;
    let built = plumetrace_scenario::build(&cfg, &origin, None).map_err(rejected)?;
    let Some(seabed) = built.env.seabed() else {
        return Err(Stop::Nonfinite(
            "the site's scenario built no seabed".into(),
        ));
    };
    let top = seabed.surface_m();
    for k in 0..=20 {
        let (x, y) = (-50.0 + 30.0 * f64::from(k), -160.0 + 16.0 * f64::from(k));
        let h = seabed.height_at(x, y);
        if !(h.is_finite() && (0.0..=top).contains(&h) && top.is_finite()) {
            return Err(Stop::Nonfinite(format!(
                "seabed height at ({x}, {y}) m: {h} (surface {top})"
            )));
        }
    }
    Ok("seabed: bathymetry read and sampled".into())
}

/// Sites drawn and checked per family input.
const FAMILY_SITES: u64 = 3;

/// `check`, then a short run.
fn scenario(input: &Input, path: &Path, deadline: Instant) -> Result<String, Stop> {
    let origin = Origin::File(path.to_path_buf());
    let cfg = match std::str::from_utf8(&input.bytes) {
        Ok(text) => plumetrace_scenario::parse(text, &origin).map_err(rejected)?,
        Err(_) => plumetrace_scenario::load_file(path).map_err(rejected)?,
    };
    let built = plumetrace_scenario::build(&cfg, &origin, None).map_err(rejected)?;
    check_deadline(deadline, || "building the scenario".into())?;
    if built.mission.is_none() {
        // As `plumetrace run` places a run-time error: the file, and the line of the flow's
        // table when the flow diverged.
        let text = String::from_utf8_lossy(&input.bytes).into_owned();
        return plume_run(built, deadline).map_err(|stop| match stop {
            Stop::Rejected(m) => {
                let line = plumetrace_scenario::locate::at_line(
                    m.contains("flow.farrell: the field diverged")
                        .then(|| plumetrace_scenario::locate::line_of(&text, "flow.farrell"))
                        .flatten(),
                );
                Stop::Rejected(format!("{}{line}: {m}", path.display()))
            }
            other => other,
        });
    }
    MissionSetup::new(built).map_err(rejected)?;
    check_deadline(deadline, || "checking the mission".into())?;

    // The short run.
    let mut short = cfg;
    if let Some(m) = short.mission.as_mut() {
        if m.spinup_s > SPINUP_CAP_S {
            m.spinup_s = SPINUP_CAP_S;
        }
        if m.time_limit_s > TIME_LIMIT_CAP_S {
            m.time_limit_s = TIME_LIMIT_CAP_S;
        }
    }
    let in_run = |e: &dyn std::fmt::Display| Stop::Rejected(format!("short run: {e}"));
    let built = plumetrace_scenario::build(&short, &origin, None).map_err(|e| in_run(&e))?;
    let setup = MissionSetup::new(built).map_err(|e| in_run(&e))?;
    let options = MissionOptions {
        mean_plume: false,
        trajectory: true,
        plume_frames_every_s: Some(plumetrace_mission::PLUME_FRAME_EVERY_S),
        stage_times: false,
    };
    let mut mission = Mission::new(setup, options).map_err(|e| in_run(&e))?;
    let alog_dir = alog_observer(&mut mission, path)?;
    check_deadline(deadline, || "in the spin-up".into())?;
    while mission.step().map_err(|e| in_run(&e))?.is_none() {
        check_deadline(deadline, || {
            format!(
                "flying the mission (t = {} s of {} s)",
                mission.time_s(),
                mission.time_limit_s()
            )
        })?;
    }
    let run = mission.finish().map_err(|e| in_run(&e))?;
    check_alogs(&alog_dir, path)?;
    check_summary(&run)?;
    check_trajectory(&run)?;
    let t0 = Instant::now();
    let svg = plumetrace_report::mission_figure(&run, "fuzz")
        .map_err(|e| Stop::Rejected(format!("short run: drawing the figure: {e}")))?;
    check_deadline(deadline, || "drawing the figure".into())?;
    // The replay page refuses data that is not finite: a flown mission must always have one.
    let page =
        plumetrace_report::replay_page(&run, "fuzz").map_err(|e| Stop::Nonfinite(e.to_string()))?;
    check_deadline(deadline, || "writing the replay page".into())?;
    Ok(format!(
        "mission: {} at t = {} s, {} trajectory rows, figure of {} bytes and replay page of {} bytes in {:.2} s",
        run.outcome.name(),
        run.summary.sim_time_s,
        run.trajectory.len(),
        svg.len(),
        page.len(),
        t0.elapsed().as_secs_f64()
    ))
}

/// `--alog` as `run` writes it: a `.alog` per vehicle with a planner, into `alog/` beside the
/// input (emptied first).
fn alog_observer(mission: &mut Mission, path: &Path) -> Result<PathBuf, Stop> {
    let dir = path.with_file_name("alog");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).map_err(|e| rejected(format!("harness: {e}")))?;
    let planned: Vec<bool> = mission.planned().iter().map(Option::is_some).collect();
    let w =
        plumetrace_mission::alog::AlogObserver::create(&dir, &mission.vehicle_names(), &planned)
            .map_err(|e| rejected(format!("creating the .alog files: {e}")))?;
    mission
        .observe(Box::new(w))
        .map_err(|e| rejected(format!("short run: {e}")))?;
    Ok(dir)
}

/// Every `.alog` is a plain file in `alog/`, and nothing else appeared beside the input's
/// directory (a vehicle name that escaped it would show there).
fn check_alogs(dir: &Path, path: &Path) -> Result<(), Stop> {
    let names = |d: &Path| -> Vec<String> {
        std::fs::read_dir(d)
            .map(|r| {
                r.flatten()
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default()
    };
    let escaped =
        |what: String| Stop::Rejected(format!("--alog wrote outside its directory: {what}"));
    if let Some(bad) = names(dir)
        .into_iter()
        .find(|n| !n.ends_with(".alog") || n.contains(".partial"))
    {
        return Err(escaped(format!("alog/{bad}")));
    }
    let root = path.parent().and_then(Path::parent).unwrap_or(path);
    if let Some(bad) = names(root)
        .into_iter()
        .find(|n| !["scenario", "campaign", "families", "sites"].contains(&n.as_str()))
    {
        return Err(escaped(bad));
    }
    let beside = path.parent().unwrap_or(path);
    if let Some(bad) = names(beside)
        .into_iter()
        .find(|n| n != "alog" && !n.starts_with("fuzz"))
    {
        return Err(escaped(bad));
    }
    Ok(())
}

/// Plume only: a few steps, then the output grid.
fn plume_run(mut built: BuiltScenario, deadline: Instant) -> Result<String, Stop> {
    let steps = built.steps.min(PLUME_STEP_CAP);
    for step in 1..=steps {
        // As `plumetrace run` reports it.
        built
            .env
            .step()
            .map_err(|e| Stop::Rejected(format!("step {step}: {e}")))?;
        check_deadline(deadline, || format!("at plume step {step} of {steps}"))?;
    }
    let grid = built.output.grid;
    let points = grid.points();
    let mut out = vec![0.0; points.len()];
    built.env.plume().concentrations(&points, &mut out);
    check_deadline(deadline, || "querying the output grid".into())?;
    if let Some(k) = out.iter().position(|c| !c.is_finite()) {
        return Err(Stop::Nonfinite(format!(
            "concentration {} at output grid point {k} ({}, {}, {}) after {steps} steps",
            out[k], points[k].x, points[k].y, points[k].z
        )));
    }
    let max = out.iter().copied().fold(0.0, f64::max);
    Ok(format!(
        "plume: {steps} steps, {} grid points, max concentration {max:.3e}",
        out.len()
    ))
}

/// Every number of the summary is finite: serde_json writes a non-finite number as null, so
/// any null outside [`NULLABLE`] is one.
fn check_summary(run: &MissionRun) -> Result<(), Stop> {
    let v = serde_json::to_value(&run.summary)
        .map_err(|e| Stop::Nonfinite(format!("the summary does not serialise: {e}")))?;
    let mut bad = Vec::new();
    null_paths(&v, &mut String::new(), &mut String::new(), &mut bad);
    if bad.is_empty() {
        Ok(())
    } else {
        Err(Stop::Nonfinite(format!(
            "summary fields not finite (null in JSON): {}",
            bad.join(", ")
        )))
    }
}

/// Collects the paths of unexpected nulls; `pattern` is `path` with indices written `[]`.
fn null_paths(
    v: &serde_json::Value,
    path: &mut String,
    pattern: &mut String,
    out: &mut Vec<String>,
) {
    match v {
        serde_json::Value::Null if !NULLABLE.contains(&pattern.as_str()) => {
            out.push(path.clone());
        }
        serde_json::Value::Object(m) => {
            for (k, c) in m {
                let (pl, ql) = (path.len(), pattern.len());
                if !path.is_empty() {
                    path.push('.');
                    pattern.push('.');
                }
                path.push_str(k);
                pattern.push_str(k);
                null_paths(c, path, pattern, out);
                path.truncate(pl);
                pattern.truncate(ql);
            }
        }
        serde_json::Value::Array(a) => {
            for (i, c) in a.iter().enumerate() {
                let (pl, ql) = (path.len(), pattern.len());
                path.push_str(&format!("[{i}]"));
                pattern.push_str("[]");
                null_paths(c, path, pattern, out);
                path.truncate(pl);
                pattern.truncate(ql);
            }
        }
        _ => {}
    }
}

/// Every number of every trajectory row is finite.
fn check_trajectory(run: &MissionRun) -> Result<(), Stop> {
    for (k, r) in run.trajectory.iter().enumerate() {
        let fields = [
            ("t_s", Some(r.t_s)),
            ("true_x_m", Some(r.true_x_m)),
            ("true_y_m", Some(r.true_y_m)),
            ("true_z_m", Some(r.true_z_m)),
            ("est_x_m", r.est_x_m),
            ("est_y_m", r.est_y_m),
            ("heading_deg", Some(r.heading_deg)),
            ("speed_mps", Some(r.speed_mps)),
            ("reading_v", Some(r.reading_v)),
        ];
        let bad: Vec<String> = fields
            .iter()
            .filter_map(|(name, v)| {
                v.filter(|x| !x.is_finite())
                    .map(|x| format!("{name} = {x}"))
            })
            .collect();
        if !bad.is_empty() {
            return Err(Stop::Nonfinite(format!(
                "trajectory row {k} (vehicle {}, t = {} s): {}",
                r.vehicle,
                r.t_s,
                bad.join(", ")
            )));
        }
    }
    Ok(())
}

/// Parse, resolve, check the groups, count the runs.
fn campaign(input: &Input, path: &Path, deadline: Instant) -> Result<String, Stop> {
    let c = match std::str::from_utf8(&input.bytes) {
        Ok(text) => {
            let file = parse_campaign(text, path).map_err(rejected)?;
            let mut c = Campaign::resolve(file, path, text.to_string(), true).map_err(rejected)?;
            c.check_groups().map_err(rejected)?;
            c
        }
        // As `plumetrace campaign` reads a file.
        Err(_) => Campaign::load(path, None).map_err(rejected)?,
    };
    check_deadline(deadline, || "checking the campaign".into())?;
    let runs = c.runs().len();
    Ok(format!(
        "campaign: {} scenarios x {} configs x {} sweep points x {} seeds = {runs} runs",
        c.scenarios.len(),
        c.configs.len(),
        c.points.len(),
        c.file.seeds
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::generate;

    fn unmutated(target: Target, text: &str) -> Input {
        let mut i = generate(1, 0);
        i.target = target;
        i.corpus = "test";
        i.mutations.clear();
        i.bytes = text.as_bytes().to_vec();
        i
    }

    #[test]
    fn presets_and_campaigns_are_accepted() -> anyhow::Result<()> {
        install_panic_hook();
        let wd = Workdir::new()?;
        for p in ["demo", "plume-demo", "freshwater"] {
            let text = plumetrace_scenario::find_preset(p).map_or("", |p| p.toml);
            let o = run(&unmutated(Target::Scenario, text), &wd, 60.0)?;
            assert_eq!(o.class, Class::Accepted, "{p}: {}", o.message);
        }
        let o = run(
            &unmutated(Target::Campaign, crate::corpus::CAMPAIGNS[1].1),
            &wd,
            60.0,
        )?;
        assert_eq!(o.class, Class::Accepted, "{}", o.message);
        assert!(o.message.contains("= 80 runs"), "{}", o.message);
        Ok(())
    }

    #[test]
    fn every_netcdf_and_seabed_seed_is_accepted_and_a_cut_one_is_located() -> anyhow::Result<()> {
        install_panic_hook();
        let wd = Workdir::new()?;
        let seeds = [
            (Target::Netcdf, crate::corpus::netcdf_seeds()),
            (Target::Seabed, crate::corpus::seabed_seeds()),
        ];
        for (target, list) in seeds {
            for (name, bytes) in list {
                let mut i = unmutated(target, "");
                i.bytes = bytes.clone();
                let o = run(&i, &wd, 60.0)?;
                assert_eq!(o.class, Class::Accepted, "{name}: {}", o.message);
                i.bytes.truncate(bytes.len() / 2);
                let o = run(&i, &wd, 60.0)?;
                assert_eq!(o.class, Class::RejectedLocated, "{name}: {}", o.message);
                assert!(o.message.contains(target.file_name()), "{}", o.message);
            }
        }
        Ok(())
    }

    #[test]
    fn a_mission_that_ends_at_once_has_only_nullable_nulls() -> anyhow::Result<()> {
        // Starts beyond the cage and aborts on the first step: every `Option` of the summary is
        // `None`.
        install_panic_hook();
        let wd = Workdir::new()?;
        let text = plumetrace_scenario::find_preset("demo")
            .map_or(String::new(), |p| p.toml.to_string())
            .replace("x_m = 470.0", "x_m = 515.0");
        assert!(text.contains("x_m = 515.0"));
        let o = run(&unmutated(Target::Scenario, &text), &wd, 60.0)?;
        assert_eq!(o.class, Class::Accepted, "{}", o.message);
        Ok(())
    }

    #[test]
    fn a_syntax_error_is_located_and_paths_are_normalised() -> anyhow::Result<()> {
        let wd = Workdir::new()?;
        let o = run(&unmutated(Target::Scenario, "name = \n"), &wd, 10.0)?;
        assert_eq!(o.class, Class::RejectedLocated, "{}", o.message);
        assert!(
            o.message.starts_with("<tmp>/scenario/fuzz.toml"),
            "{}",
            o.message
        );
        Ok(())
    }

    #[test]
    fn unexpected_nulls_are_found() {
        let v = serde_json::json!({
            "first_detection_s": null,
            "path_length_m": null,
            "sources": [{"nearest_error_m": null, "x_m": null}],
        });
        let mut bad = Vec::new();
        null_paths(&v, &mut String::new(), &mut String::new(), &mut bad);
        assert_eq!(bad, ["path_length_m", "sources[0].x_m"]);
    }
}
