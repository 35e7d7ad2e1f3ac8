//! Terrain-following levels (CF `ocean_sigma_coordinate`, `ocean_s_coordinate_g1` and
//! `ocean_s_coordinate_g2`): each level's depth at each column from the level variable's
//! `formula_terms`, and the level and weight of a depth in a column.
//!
//! The CF formulas give each level's height `z` (up from the datum); the depth of a level is
//! taken below the moving surface, `eta - z`, as a vehicle's depth is:
//! - sigma: `z = eta + sigma * (depth + eta)`;
//! - g1: `S = depth_c * s + (depth - depth_c) * C`, `z = S + eta * (1 + S / depth)`;
//! - g2: `S = (depth_c * s + depth * C) / (depth_c + depth)`, `z = eta + (eta + depth) * S`.

use super::{err, length_scale};
use crate::EnvError;
use plumetrace_netcdf::{NcFile, Var, nearest};
use std::path::Path;

/// The three families of terrain-following levels read.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Sigma,
    G1,
    G2,
}

impl Kind {
    fn of(standard_name: &str) -> Option<Self> {
        match standard_name {
            "ocean_sigma_coordinate" => Some(Kind::Sigma),
            "ocean_s_coordinate_g1" => Some(Kind::G1),
            "ocean_s_coordinate_g2" => Some(Kind::G2),
            _ => None,
        }
    }

    /// The formula terms each needs.
    fn terms(self) -> &'static [&'static str] {
        match self {
            Kind::Sigma => &["sigma", "eta", "depth"],
            Kind::G1 | Kind::G2 => &["s", "C", "eta", "depth", "depth_c"],
        }
    }
}

/// Whether a level variable's standard name is a terrain-following level this reader knows.
pub(crate) fn is_known(standard_name: &str) -> bool {
    Kind::of(standard_name.trim()).is_some()
}

/// A formula term on the velocity's grid: its values and, for each of its dimensions, which of
/// the velocity's indices (time, x, y) it follows and its stride.
#[derive(Debug, Clone)]
struct Term {
    values: Vec<f64>,
    /// (0 time, 1 x, 2 y, 3 a dimension of length 1) and stride.
    index: Vec<(u8, usize)>,
}

impl Term {
    fn at(&self, t: usize, i: usize, j: usize) -> f64 {
        let mut k = 0;
        for &(role, stride) in &self.index {
            k += stride
                * match role {
                    0 => t,
                    1 => i,
                    2 => j,
                    _ => 0,
                };
        }
        self.values[k]
    }
}

/// Terrain-following levels: the formula and its terms.
#[derive(Debug, Clone)]
pub(crate) struct Sigma {
    kind: Kind,
    /// The level coordinate (`s` or `sigma`) of each level.
    s: Vec<f64>,
    /// The stretching `C` of each level (g1, g2).
    c: Vec<f64>,
    depth: Term,
    eta: Term,
    depth_c: f64,
}

/// The velocity's dimensions' roles: the time, x and y dimension ids.
pub(crate) struct Roles {
    pub(crate) time: Option<usize>,
    pub(crate) x: usize,
    pub(crate) y: usize,
}

impl Sigma {
    /// The levels of `level` (a level variable with a terrain-following standard name) for the
    /// velocity `u` whose time, x and y dimensions are `roles`.
    pub(crate) fn read(
        file: &NcFile,
        level: &Var,
        u: &Var,
        roles: &Roles,
        path: &Path,
    ) -> Result<Self, EnvError> {
        let sn = level.text("standard_name").unwrap_or("").trim();
        let kind = Kind::of(sn).ok_or_else(|| err(path, "not a terrain-following level"))?;
        let named = formula_terms(level, kind, sn, path)?;
        let var = |term: &str| -> Result<&Var, EnvError> {
            let name = named
                .iter()
                .find(|(n, _)| *n == term)
                .map_or("", |(_, v)| *v);
            file.var(name).ok_or_else(|| {
                let hint = nearest(name, file.vars.iter().map(|v| v.name.as_str()))
                    .map(|n| format!("; did you mean {n:?}?"))
                    .unwrap_or_default();
                err(
                    path,
                    format!(
                        "variable {}: formula term {term} names variable {name:?}, which the \
                         file does not have{hint}",
                        level.name
                    ),
                )
            })
        };
        let numbers = |v: &Var, scale: f64| -> Result<Vec<f64>, EnvError> {
            let vals = file.values(v).map_err(|e| err(path, e.to_string()))?;
            let mut missing: Vec<f64> = Vec::new();
            for a in ["_FillValue", "missing_value"] {
                missing.extend(v.attr(a).and_then(|a| a.as_numbers()).unwrap_or_default());
            }
            Ok(vals
                .iter()
                .map(|&r| {
                    if !r.is_finite() || missing.contains(&r) || r.abs() > 1e30 {
                        f64::NAN
                    } else {
                        r * scale
                    }
                })
                .collect())
        };
        let per_level = |term: &str| -> Result<Vec<f64>, EnvError> {
            let v = var(term)?;
            let vals = numbers(v, 1.0)?;
            if vals.len() != level_len(file, level) || vals.iter().any(|x| !x.is_finite()) {
                return Err(err(
                    path,
                    format!(
                        "variable {} (formula term {term}): needs one finite value for each of \
                         the {} levels of {}",
                        v.name,
                        level_len(file, level),
                        level.name
                    ),
                ));
            }
            Ok(vals)
        };
        let grid_term = |term: &str| -> Result<Term, EnvError> {
            let v = var(term)?;
            let values = numbers(v, length_scale(v, path)?)?;
            let shape = file.shape(v);
            let mut index = Vec::new();
            let mut stride = 1;
            for (k, &d) in v.dims.iter().enumerate().rev() {
                let role = if Some(d) == roles.time {
                    0
                } else if d == roles.x {
                    1
                } else if d == roles.y {
                    2
                } else if shape[k] == 1 {
                    3
                } else {
                    return Err(err(
                        path,
                        format!(
                            "variable {} (formula term {term}): its dimension {} is not one of \
                             variable {}'s time and horizontal dimensions (a staggered grid? \
                             interpolate the velocities to the points of {} first)",
                            v.name, file.dims[d].name, u.name, v.name
                        ),
                    ));
                };
                index.push((role, stride));
                stride *= shape[k];
            }
            Ok(Term { values, index })
        };
        let s = per_level(if kind == Kind::Sigma { "sigma" } else { "s" })?;
        let (c, depth_c) = if kind == Kind::Sigma {
            (Vec::new(), 0.0)
        } else {
            let dc = var("depth_c")?;
            let v = numbers(dc, length_scale(dc, path)?)?;
            let depth_c = match v.as_slice() {
                [x] if x.is_finite() && *x >= 0.0 => *x,
                _ => {
                    return Err(err(
                        path,
                        format!(
                            "variable {} (formula term depth_c): needs one finite value >= 0 m",
                            dc.name
                        ),
                    ));
                }
            };
            (per_level("C")?, depth_c)
        };
        Ok(Sigma {
            kind,
            s,
            c,
            depth: grid_term("depth")?,
            eta: grid_term("eta")?,
            depth_c,
        })
    }

    /// The depth below the surface of level `k` in column `(t, i, j)`, m (NaN where a term is
    /// missing: land).
    fn level_depth(&self, k: usize, t: usize, i: usize, j: usize) -> f64 {
        let (h, eta) = (self.depth.at(t, i, j), self.eta.at(t, i, j));
        let s = self.s[k];
        let z = match self.kind {
            Kind::Sigma => eta + s * (h + eta),
            Kind::G1 => {
                let big_s = self.depth_c * s + (h - self.depth_c) * self.c[k];
                big_s + eta * (1.0 + big_s / h)
            }
            Kind::G2 => {
                let big_s = (self.depth_c * s + h * self.c[k]) / (self.depth_c + h);
                eta + (eta + h) * big_s
            }
        };
        eta - z
    }

    /// The level at or above `depth_m` in column `(t, i, j)` and the weight towards the next
    /// level; `None` where the column is shallower than `depth_m` or missing.
    pub(crate) fn weight(
        &self,
        depth_m: f64,
        t: usize,
        i: usize,
        j: usize,
    ) -> Option<(usize, f64)> {
        let n = self.s.len();
        let d = |k: usize| self.level_depth(k, t, i, j);
        if n == 1 {
            return d(0).is_finite().then_some((0, 0.0));
        }
        let (shallow, deep) = if d(0) < d(n - 1) {
            (0, n - 1)
        } else {
            (n - 1, 0)
        };
        let bottom = self.depth.at(t, i, j) + self.eta.at(t, i, j);
        if !(bottom.is_finite() && depth_m <= bottom && d(deep).is_finite()) {
            return None;
        }
        if depth_m <= d(shallow) {
            return Some((shallow, 0.0));
        }
        if depth_m >= d(deep) {
            return Some((deep, 0.0));
        }
        for k in 0..n - 1 {
            let (a, b) = (d(k), d(k + 1));
            if (a.min(b)..=a.max(b)).contains(&depth_m) {
                let w = (depth_m - a) / (b - a);
                return Some(if w >= 1.0 { (k + 1, 0.0) } else { (k, w) });
            }
        }
        None
    }
}

/// The `term: variable` pairs of `level`'s `formula_terms`, every term `kind` needs present.
fn formula_terms<'v>(
    level: &'v Var,
    kind: Kind,
    sn: &str,
    path: &Path,
) -> Result<Vec<(&'v str, &'v str)>, EnvError> {
    let needs = kind.terms().join(", ");
    let ft = level.text("formula_terms").ok_or_else(|| {
        err(
            path,
            format!(
                "variable {} (standard_name {sn}): no attribute formula_terms; its levels' \
                 depths need the terms {needs}",
                level.name
            ),
        )
    })?;
    // "s: s_rho C: Cs_r eta: zeta depth: h depth_c: hc"
    let words: Vec<&str> = ft.split_whitespace().collect();
    let mut named: Vec<(&str, &str)> = Vec::new();
    for w in words.chunks(2) {
        match w {
            [term, var] if term.ends_with(':') => named.push((&term[..term.len() - 1], var)),
            _ => {
                return Err(err(
                    path,
                    format!(
                        "variable {}: attribute formula_terms = {ft:?} is not a list of \
                         `term: variable` pairs",
                        level.name
                    ),
                ));
            }
        }
    }
    let missing: Vec<&str> = kind
        .terms()
        .iter()
        .copied()
        .filter(|t| !named.iter().any(|(n, _)| n == t))
        .collect();
    if missing.is_empty() {
        return Ok(named);
    }
    Err(err(
        path,
        format!(
            "variable {} (standard_name {sn}): attribute formula_terms = {ft:?} lacks the \
             term{} {}; its levels' depths need {needs}",
            level.name,
            if missing.len() == 1 { "" } else { "s" },
            missing.join(" and ")
        ),
    ))
}

fn level_len(file: &NcFile, level: &Var) -> usize {
    file.shape(level).iter().product()
}
