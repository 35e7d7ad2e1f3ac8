//! The onboard file a rehearsal's back seat flies: the planner table, mission geometry and run
//! settings of the scenario's first planned vehicle, and the link to this front seat.

use crate::FrontSeatError;
use plumetrace_mission::MissionSetup;

/// The onboard file for a scenario's first planned vehicle and this link.
pub(crate) fn onboard_file(
    setup: &MissionSetup,
    link: &toml::Table,
    lock_step: bool,
    nav_period_s: f64,
    flow: bool,
) -> Result<String, FrontSeatError> {
    let p = setup
        .planners
        .iter()
        .flatten()
        .next()
        .ok_or(FrontSeatError::NoPlanner)?;
    let poly = |v: &[plumetrace_core::Vec2]| {
        toml::Value::Array(
            v.iter()
                .map(|p| toml::Value::Array(vec![p.x.into(), p.y.into()]))
                .collect(),
        )
    };
    let g = &p.context.geometry;
    let mut mission = toml::Table::new();
    mission.insert("op_area".into(), poly(g.op_area.vertices()));
    mission.insert(
        "subregions".into(),
        toml::Value::Array(g.subregions.iter().map(|r| poly(r.vertices())).collect()),
    );
    if g.prior_flow_given {
        mission.insert(
            "prior_flow_toward_deg".into(),
            g.prior_flow_toward_deg.into(),
        );
    }
    mission.insert(
        "vehicle_kind".into(),
        plumetrace_core::variant_name(&p.context.vehicle_kind)
            .unwrap_or("auv")
            .into(),
    );
    let mut run = toml::Table::new();
    run.insert(
        "mode".into(),
        if lock_step { "lock_step" } else { "real_time" }.into(),
    );
    run.insert("lock_step_period_s".into(), nav_period_s.into());
    run.insert("time_limit_s".into(), setup.spec.time_limit_s.into());
    let mut file = toml::Table::new();
    file.insert("name".into(), format!("{} on a vehicle", setup.name).into());
    file.insert("mission".into(), mission.into());
    // Every key the planner reads, but those that have no effect at its values (say, the AMP's
    // map keys without a map declaration): they would take their defaults just the same, and a
    // file this command writes checks without a warning.
    let mut planner = p.config.to_table()?;
    for (key, _) in p.config.keys_without_effect(&planner) {
        planner.remove(key);
    }
    file.insert("planner".into(), planner.into());
    file.insert("link".into(), link.clone().into());
    if flow {
        // The current meter's sentences travel on the vehicle link.
        file.insert("flow".into(), toml::Table::new().into());
    }
    file.insert("run".into(), run.into());
    Ok(format!(
        "# Written by `plumetrace frontseat` for scenario '{}': the planner table, mission geometry\n# and link of its first planned vehicle.\n{}",
        setup.name,
        toml::to_string(&file)?
    ))
}
