//! From the scenario's `[planner]` table to planner parameters, with key paths in errors.

use plumetrace_planner::{AmpParams, DeclarationRule, LostPointEviction, MappingParams};
use plumetrace_scenario::config::{DeclarationKind, EvictionKind, PlannerConfig};

/// A bad planner setting.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{key}: {message}")]
pub struct PlannerError {
    /// Key path, e.g. `planner.beta_deg`.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

/// `v` if finite and > 0 (the environment's check, with the planner's key path).
fn positive(key: &str, v: f64) -> Result<f64, PlannerError> {
    plumetrace_env::error::require_positive(&format!("planner.{key}"), v)
        .map(|()| v)
        .map_err(PlannerError::from_env)
}

/// `v` if finite and >= 0.
fn non_negative(key: &str, v: f64) -> Result<f64, PlannerError> {
    plumetrace_env::error::require_non_negative(&format!("planner.{key}"), v)
        .map(|()| v)
        .map_err(PlannerError::from_env)
}

impl PlannerError {
    fn from_env(e: plumetrace_env::EnvError) -> Self {
        match e {
            plumetrace_env::EnvError::InvalidParameter { key, message } => {
                PlannerError { key, message }
            }
            other => PlannerError {
                key: "planner".into(),
                message: other.to_string(),
            },
        }
    }
}

/// The AMP parameters of a `[planner]` table: Table 4 defaults, overridden key by key.
pub fn amp_params(c: &PlannerConfig) -> Result<AmpParams, PlannerError> {
    let d = AmpParams::default();
    let along = positive("declaration_along_m", c.declaration_along_m.unwrap_or(4.0))?;
    let declaration = match c.declaration.unwrap_or(DeclarationKind::AlongFlow) {
        DeclarationKind::AlongFlow => DeclarationRule::AlongFlow { along_m: along },
        DeclarationKind::AlongAndCrossFlow => DeclarationRule::AlongAndCrossFlow {
            along_m: along,
            cross_m: positive("declaration_cross_m", c.declaration_cross_m.unwrap_or(8.0))?,
        },
    };
    let md = MappingParams::default();
    let mapping = if c.mapping.unwrap_or(true) {
        let lines = c.mapping_lines.unwrap_or(md.lines);
        if lines == 0 || lines > 100 {
            return Err(PlannerError {
                key: "planner.mapping_lines".into(),
                message: format!("must be 1..=100, got {lines}"),
            });
        }
        Some(MappingParams {
            lines,
            length_m: positive(
                "mapping_length_m",
                c.mapping_length_m.unwrap_or(md.length_m),
            )?,
            spacing_m: positive(
                "mapping_spacing_m",
                c.mapping_spacing_m.unwrap_or(md.spacing_m),
            )?,
        })
    } else {
        None
    };
    let n_re = c.n_re.unwrap_or(d.n_re);
    if n_re == 0 || n_re > 50 {
        return Err(PlannerError {
            key: "planner.n_re".into(),
            message: format!("must be 1..=50, got {n_re}"),
        });
    }
    let max_lost = c.max_lost_points.unwrap_or(d.max_lost_points);
    if max_lost < 3 {
        return Err(PlannerError {
            key: "planner.max_lost_points".into(),
            message: format!("must be at least 3 (declaration needs three), got {max_lost}"),
        });
    }
    let speed = positive("speed_mps", c.speed_mps.unwrap_or(d.speed_mps))?;
    let beta = non_negative("beta_deg", c.beta_deg.unwrap_or(d.beta_deg))?;
    if beta > 90.0 {
        return Err(PlannerError {
            key: "planner.beta_deg".into(),
            message: format!("must be at most 90, got {beta}"),
        });
    }
    Ok(AmpParams {
        speed_mps: speed,
        altitude_m: non_negative("altitude_m", c.altitude_m.unwrap_or(d.altitude_m))?,
        lambda_s: positive("lambda_s", c.lambda_s.unwrap_or(d.lambda_s))?,
        beta_deg: beta,
        l_u_m: non_negative("l_u_m", c.l_u_m.unwrap_or(d.l_u_m))?,
        l_c_m: non_negative("l_c_m", c.l_c_m.unwrap_or(d.l_c_m))?,
        n_re,
        k_deg_per_m: positive("k_deg_per_m", c.k_deg_per_m.unwrap_or(d.k_deg_per_m))?,
        r_m: positive("r_m", c.r_m.unwrap_or(d.r_m))?,
        min_turn_radius_m: positive(
            "min_turn_radius_m",
            c.min_turn_radius_m.unwrap_or(d.min_turn_radius_m),
        )?,
        max_lost_points: max_lost,
        lost_point_eviction: match c.lost_point_eviction {
            None => d.lost_point_eviction,
            Some(EvictionKind::MostDownflow) => LostPointEviction::MostDownflow,
            Some(EvictionKind::Oldest) => LostPointEviction::Oldest,
        },
        declaration,
        mapping,
        region_timeout_s: positive(
            "region_timeout_s",
            c.region_timeout_s.unwrap_or(d.region_timeout_s),
        )?,
        flow_average_s: non_negative(
            "flow_average_s",
            c.flow_average_s.unwrap_or(d.flow_average_s),
        )?,
        flow_compensation: c.flow_compensation.unwrap_or(d.flow_compensation),
        ..d
    })
}
