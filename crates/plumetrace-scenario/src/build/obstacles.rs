//! `[[obstacles]]` and `[[kelp]]`: soft obstacles as written and kelp fields drawn at random.

use super::Invalid;
use crate::config::{KelpConfig, ScenarioConfig};
use plumetrace_core::Vec2;
use plumetrace_env::{KelpFieldParams, SoftObstacle, StreamId};

/// Random stream of kelp field `k`: `StreamId::Custom(KELP_STREAM + k)`.
const KELP_STREAM: u64 = 0x6b65_6c70_0000;

/// The obstacles as written, then every kelp field's patches (drawn from `run_seed` unless the
/// field has a seed of its own).
pub(super) fn obstacles(cfg: &ScenarioConfig, run_seed: u64) -> Result<Vec<SoftObstacle>, Invalid> {
    let mut obstacles = Vec::new();
    for (k, o) in cfg.obstacles.iter().enumerate() {
        let key = format!("obstacles[{k}]");
        let name = if o.name.is_empty() {
            key.clone()
        } else {
            o.name.clone()
        };
        obstacles.push(SoftObstacle::new(name, &o.vertices).map_err(|e| Invalid::env(&key, e))?);
    }
    for (k, f) in cfg.kelp.iter().enumerate() {
        obstacles.extend(kelp_field(cfg, k, f, run_seed)?);
    }
    Ok(obstacles)
}

/// The patches of kelp field `k`, kept clear of the sources and the vehicles' starts.
fn kelp_field(
    cfg: &ScenarioConfig,
    k: usize,
    f: &KelpConfig,
    run_seed: u64,
) -> Result<Vec<SoftObstacle>, Invalid> {
    let key = format!("kelp[{k}]");
    let name = if f.name.is_empty() {
        key.clone()
    } else {
        f.name.clone()
    };
    let keep_clear: Vec<(Vec2, f64)> = cfg
        .sources
        .iter()
        .map(|s| Vec2::new(s.x_m, s.y_m))
        .chain(cfg.vehicles.iter().map(|v| Vec2::new(v.x_m, v.y_m)))
        .map(|c| (c, f.clear_m))
        .collect();
    let params = KelpFieldParams {
        region: f.region.clone(),
        patches: f.patches,
        radius_m: f.radius_m,
        gap_m: f.gap_m,
        vertices: f.vertices,
        roughness: f.roughness,
    };
    let mut rng = plumetrace_env::stream_rng(
        f.seed.unwrap_or(run_seed),
        StreamId::Custom(KELP_STREAM + k as u64),
    );
    plumetrace_env::kelp_field(&params, &keep_clear, &name, &mut rng)
        .map_err(|e| Invalid::env(&key, e))
}

/// Refuses a vehicle that starts inside an `[[obstacles]]` polygon: its mission would end
/// "collided" at the first step. (A kelp field keeps `clear_m` around every start.)
pub(super) fn starts_clear(
    cfg: &ScenarioConfig,
    obstacles: &[SoftObstacle],
) -> Result<(), Invalid> {
    for (k, v) in cfg.vehicles.iter().enumerate() {
        let p = Vec2::new(v.x_m, v.y_m);
        if let Some((j, o)) = obstacles.iter().enumerate().find(|(_, o)| o.contains(p)) {
            let which = if j < cfg.obstacles.len() {
                format!("obstacles[{j}]")
            } else {
                "a kelp patch".to_string()
            };
            return Err(Invalid::new(
                format!("vehicles[{k}].x_m"),
                format!(
                    "start ({}, {}) is inside {which} ('{}'): the mission would end collided at \
                     once; move the start or the obstacle",
                    v.x_m, v.y_m, o.name
                ),
            ));
        }
    }
    Ok(())
}
