//! `plumetrace replay LOG`: feed a snapshot log to fresh planners built from its header (or from
//! another planner table) and report where their decisions differ from the logged ones.
//!
//! Exit status: 0 when every decision is the same, 3 when some differ, 1 on an error.

use anyhow::{Context, Result};
use plumetrace_core::variant_name;
use std::path::PathBuf;

/// Arguments of `plumetrace replay`.
#[derive(Debug, clap::Args)]
pub struct ReplayArgs {
    /// The snapshot log (`snapshots.jsonl.gz` written by `plumetrace run`).
    pub log: PathBuf,
    /// A planner table (TOML: `kind` and its keys), or a scenario file with one planner table
    /// (`[planner]` or `[planners.NAME]`), to replay with instead of the logged configuration.
    #[arg(long)]
    pub planner_file: Option<PathBuf>,
    /// With `--planner-file`: replace only this vehicle's planner (its index in the scenario);
    /// the others replay their own.
    #[arg(long, requires = "planner_file", allow_hyphen_values = true, value_parser = crate::args::vehicle)]
    pub vehicle: Option<u32>,
    /// Also write a replay page (HTML) of the replayed mission here: the logged tracks with the
    /// replayed planners' behaviours and events (and the true sources, when the log sits in a
    /// run's output directory beside its `summary.json`).
    #[arg(long)]
    pub page: Option<PathBuf>,
}

/// The true sources of the run whose output directory holds `log`, read from the `summary.json`
/// beside it; none when there is no such file (a vehicle's log carries no truth) or it names
/// no sources.
fn sources_beside(log: &std::path::Path) -> Vec<[f64; 2]> {
    let Some(text) = log
        .parent()
        .and_then(|d| std::fs::read_to_string(d.join("summary.json")).ok())
    else {
        return Vec::new();
    };
    let Ok(summary) = serde_json::from_str::<serde_json::Value>(&text) else {
        return Vec::new();
    };
    summary["sources"]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|s| Some([s["x_m"].as_f64()?, s["y_m"].as_f64()?]))
                .collect()
        })
        .unwrap_or_default()
}

/// The planner table of a `--planner-file`: the file itself (`kind` and keys), or the one
/// planner table of a scenario file (`[planner]` or a single `[planners.NAME]`), with its key
/// path for errors.
fn planner_table(mut file: toml::Table) -> Result<(toml::Table, String)> {
    if file.contains_key("kind") || file.contains_key("strategy") {
        return Ok((file, String::new()));
    }
    if !file.contains_key("planner") && !file.contains_key("planners") {
        return Ok((file, String::new()));
    }
    let path = plumetrace_scenario::overrides::planner_path(&file)
        .map_err(|e| anyhow::anyhow!("{e}; give a file with one planner table"))?;
    let mut here = toml::Value::Table(std::mem::take(&mut file));
    for segment in path.split('.') {
        here = match here {
            toml::Value::Table(mut t) => t
                .remove(segment.trim_matches('"'))
                .unwrap_or(toml::Value::Table(toml::Table::new())),
            other => other,
        };
    }
    match here {
        toml::Value::Table(t) => Ok((t, path)),
        other => anyhow::bail!("{path} is a {}, not a table", other.type_str()),
    }
}

/// That the log's header names vehicle `o` among its planned vehicles: else `--vehicle o` would
/// replace no planner and every decision would replay as logged. A log whose header cannot be
/// read passes here; the replay then says what is wrong with it.
fn check_vehicle(log: &std::path::Path, o: u32) -> Result<()> {
    use std::io::BufRead;
    let mut first = String::new();
    let header = plumetrace_log::snapshot::open(log)
        .and_then(|mut r| r.read_line(&mut first))
        .ok()
        .and_then(|_| plumetrace_log::snapshot::read_header(first.trim_end()).ok());
    let Some(header) = header else {
        return Ok(());
    };
    if header.vehicles.iter().any(|v| v.id == o) {
        return Ok(());
    }
    let names: Vec<String> = header
        .vehicles
        .iter()
        .map(|v| format!("{} ({})", v.id, v.name))
        .collect();
    anyhow::bail!(
        "--vehicle {o}: {} has no vehicle {o} with a planner; its vehicles with planners: {}",
        log.display(),
        if names.is_empty() {
            "none".to_string()
        } else {
            names.join(", ")
        }
    )
}

/// The exit status when decisions differ.
pub const DIFFER: i32 = 3;

/// Replays and prints the report; returns whether every decision was the same.
pub fn run(args: &ReplayArgs) -> Result<bool> {
    let other: Option<toml::Table> = match &args.planner_file {
        Some(p) => {
            let text = plumetrace_env::input::read_text(p, plumetrace_env::input::MAX_TEXT_BYTES)
                .map_err(anyhow::Error::msg)
                .with_context(|| format!("reading {}", p.display()))?;
            let table: toml::Table = text.parse().with_context(|| format!("{}", p.display()))?;
            let (table, prefix) =
                planner_table(table).with_context(|| format!("{}", p.display()))?;
            // Checked here so that errors name this file (and the key's line), not the log's
            // planner.
            plumetrace_planner::PlannerConfig::from_table(&table, &prefix).map_err(|e| {
                let line = plumetrace_scenario::locate::at_line(
                    plumetrace_scenario::locate::line_of(&text, &e.key),
                );
                anyhow::anyhow!("{}{line}: {e}", p.display())
            })?;
            Some(table)
        }
        None => None,
    };
    if let Some(o) = args.vehicle {
        check_vehicle(&args.log, o)?;
    }
    let log = plumetrace_log::snapshot::open(&args.log)
        .with_context(|| format!("opening {}", args.log.display()))?;
    let only = args.vehicle;
    let mut page = args
        .page
        .as_ref()
        .map(|_| plumetrace_report::LogPageBuilder::default());
    let report = plumetrace_log::snapshot::replay_with(
        log,
        &|v| other.clone().filter(|_| only.is_none_or(|o| o == v)),
        &mut |r| {
            if let Some(p) = page.as_mut() {
                p.add(r);
            }
        },
    )
    .with_context(|| format!("{}", args.log.display()))?;
    if let (Some(path), Some(builder)) = (&args.page, page) {
        let planner = match &args.planner_file {
            Some(f) => format!("replayed with {}", f.display()),
            None => "replayed with the logged planners".into(),
        };
        let subtitle = format!(
            "{planner}: {} decisions, {} differ from the log",
            report.decisions, report.differing
        );
        let mut data = builder.page(&format!("replay of {}", args.log.display()), &subtitle);
        data.sources = sources_beside(&args.log);
        let html = data.html()?;
        crate::output::write_atomic(path, html.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    crate::outln!(
        "{}: {} decisions replayed, {} differ",
        args.log.display(),
        report.decisions,
        report.differing
    );
    for d in &report.defaulted {
        let keys: Vec<String> = d.keys.iter().map(|k| format!("`{k}`")).collect();
        let one = keys.len() == 1;
        crate::outln!(
            "  note: vehicle {} ({})'s logged planner table has no {} (the log predates {}): {} \
             with today's {}, which may not be how it flew; to replay it as flown, give \
             `--planner-file F --vehicle {}` with F its logged table (the log's first line, \
             `vehicles[].planner`) and {} as flown",
            d.vehicle,
            d.name,
            keys.join(", "),
            if one { "the key" } else { "these keys" },
            if one { "it replays" } else { "they replay" },
            if one { "default" } else { "defaults" },
            d.vehicle,
            if one {
                "the key's value"
            } else {
                "these keys' values"
            },
        );
    }
    for d in &report.first {
        crate::outln!(
            "  line {}, vehicle {}, t = {:.1} s: logged heading {:.2} deg, speed {:.2} m/s, {}; replayed heading {:.2} deg, speed {:.2} m/s, {}; {}",
            d.line,
            d.vehicle,
            d.t_s,
            d.logged.command.heading.deg(),
            d.logged.command.speed_mps,
            variant_name(&d.logged.status).unwrap_or("?"),
            d.replayed.command.heading.deg(),
            d.replayed.command.speed_mps,
            variant_name(&d.replayed.status).unwrap_or("?"),
            what_differs(d),
        );
    }
    Ok(report.differing == 0)
}

/// Which parts of a differing decision differ, the events' kinds on each side when they do
/// (the command printed before may look the same to two decimals, or be the same).
fn what_differs(d: &plumetrace_log::snapshot::Difference) -> String {
    let parts = d.parts();
    if parts.is_empty() {
        return "differs in its text only".into();
    }
    let mut text = format!("differs in {}", parts.join(", "));
    if parts.contains(&"events") {
        let kinds = |events: &[plumetrace_core::PlannerEvent]| -> String {
            let names: Vec<String> = events
                .iter()
                .map(|e| {
                    serde_json::to_value(e)
                        .ok()
                        .and_then(|v| v.get("event")?.as_str().map(String::from))
                        .unwrap_or_else(|| "?".into())
                })
                .collect();
            if names.is_empty() {
                "none".into()
            } else {
                names.join(" ")
            }
        };
        text += &format!(
            " (logged: {}; replayed: {})",
            kinds(&d.logged.events),
            kinds(&d.replayed.events)
        );
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_core::{
        Command, Decision, Heading, PlanStatus, PlannerEvent, Vec2, VerticalCommand,
    };
    use plumetrace_log::snapshot::Difference;

    #[test]
    fn a_difference_says_what_differs_and_the_events_kinds() {
        let logged = Decision::new(
            Command {
                heading: Heading::from_deg(10.0),
                speed_mps: 1.0,
                vertical: VerticalCommand::Depth(3.0),
            },
            PlanStatus::Running,
        );
        let mut replayed = logged.clone();
        replayed.events.push(PlannerEvent::LostPointMoved {
            from_m: Vec2::new(0.0, 0.0),
            to_m: Vec2::new(1.0, 0.0),
        });
        replayed.events.push(PlannerEvent::LostPoint {
            pos_m: Vec2::new(2.0, 0.0),
        });
        let d = Difference {
            line: 3,
            vehicle: 0,
            t_s: 0.1,
            logged: logged.clone(),
            replayed,
        };
        assert_eq!(
            what_differs(&d),
            "differs in events (logged: none; replayed: lost_point_moved lost_point)"
        );
        let same = Difference {
            replayed: logged,
            ..d
        };
        assert_eq!(what_differs(&same), "differs in its text only");
    }
}
