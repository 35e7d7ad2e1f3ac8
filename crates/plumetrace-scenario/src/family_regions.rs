//! Several sources at a family's sites: `[regions]` splits a rectangular op-area into a grid of
//! subregions, searched in turn as a multi-source mission's are, and puts a source in some of
//! them.
//!
//! The grid is `along` cells along the op-area's main axis by `across` cells across it. The
//! search goes column by column, a column being a strip of cells along whichever grid axis lies
//! nearer the flow: within a column from the cell furthest downflow to the one furthest upflow,
//! and the columns in the order of their most downflow cell (as the Duck 2003 multi-source
//! mission flew its four, and so that the first subregion holds the op-area's most downflow
//! corner, where a search begins). A site holds between `sources[0]` and `sources[1]` sources (whole numbers, drawn
//! evenly), each in its own cell (the cells drawn at random), uniformly at least `inset_m` from
//! that cell's edges, each with its own release rate when `[source] mass_rate_per_s` is given.
//! The draws come from a random stream of their own, after everything else of the site, so a
//! family without `[regions]` draws the same sites as before.

use crate::ScenarioError;
use crate::family::{FamilyFile, Shape, Site, float, invalid, round, unit};
use plumetrace_core::Vec2;
use plumetrace_env::{StreamId, stream_rng};
use rand::Rng;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The random stream of the regions' draws.
const REGIONS_STREAM: u64 = 0x7265_6769;

/// The most cells along or across.
pub const MAX_CELLS: i64 = 6;

/// `[regions]`: the subregions and the sources in them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionsDraw {
    /// Cells along the op-area's main axis (1 to [`MAX_CELLS`]).
    pub along: i64,
    /// Cells across it.
    pub across: i64,
    /// How many cells hold a source, `[low, high]` (whole numbers, drawn evenly).
    pub sources: [i64; 2],
    /// Least distance of a source from its cell's edges, m.
    #[serde(default = "default_inset")]
    pub inset_m: f64,
}

fn default_inset() -> f64 {
    40.0
}

/// The regions of one site.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RegionsSite {
    /// The subregions in search order, each a rectangle's four vertices, m.
    pub cells: Vec<Vec<[f64; 2]>>,
    /// The sources: position (m), the index of its cell in `cells`, and its release rate when
    /// drawn.
    pub sources: Vec<RegionSource>,
}

/// One source of a site with regions.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RegionSource {
    /// Position, m.
    pub pos: [f64; 2],
    /// Its subregion (an index into the search order).
    pub cell: usize,
    /// Release rate, if drawn.
    pub mass_rate_per_s: Option<f64>,
}

/// Checks `[regions]` against the rest of the family; errors name the key.
pub(crate) fn check(f: &FamilyFile, path: &Path) -> Result<(), ScenarioError> {
    let Some(r) = &f.regions else { return Ok(()) };
    for (key, n) in [("regions.along", r.along), ("regions.across", r.across)] {
        if !(1..=MAX_CELLS).contains(&n) {
            return Err(invalid(
                path,
                key,
                format!("must be a whole number from 1 to {MAX_CELLS}, got {n}"),
            ));
        }
    }
    let cells = r.along * r.across;
    if cells < 2 {
        return Err(invalid(
            path,
            "regions",
            "a grid of 1 x 1 is the op-area itself: give at least two cells (along or across 2 \
             or more), or leave [regions] out for one source"
                .into(),
        ));
    }
    let [lo, hi] = r.sources;
    if lo < 1 || lo > hi || hi > cells {
        return Err(invalid(
            path,
            "regions.sources",
            format!(
                "[low, high] needs 1 <= low <= high <= {cells} (the cells of the {} x {} grid), \
                 got [{lo}, {hi}]",
                r.along, r.across
            ),
        ));
    }
    if f.area.shapes.iter().any(|s| *s != Shape::Rectangle) {
        return Err(invalid(
            path,
            "area.shapes",
            "[regions] splits a rectangle into its grid: set area.shapes = [\"rectangle\"]".into(),
        ));
    }
    let (cell_l, cell_w) = (
        f.area.length_m[0] / r.along as f64,
        f.area.width_m[0] / r.across as f64,
    );
    if !(r.inset_m.is_finite() && r.inset_m >= 0.0 && 2.0 * r.inset_m + 10.0 <= cell_l.min(cell_w))
    {
        return Err(invalid(
            path,
            "regions.inset_m",
            format!(
                "must be a number >= 0 that leaves room in the smallest cell ({cell_l:.1} m x \
                 {cell_w:.1} m: at most {:.1} m), got {}; lower it, use fewer cells or enlarge \
                 area.length_m / area.width_m",
                ((cell_l.min(cell_w) - 10.0) / 2.0).max(0.0),
                r.inset_m
            ),
        ));
    }
    Ok(())
}

/// Checks that the base scenario can hold several sources: a Gaussian plume takes one.
pub(crate) fn check_base(
    f: &FamilyFile,
    base: &toml::Table,
    path: &Path,
) -> Result<(), ScenarioError> {
    let gaussian = base
        .get("plume")
        .and_then(|p| p.get("model"))
        .and_then(toml::Value::as_str)
        == Some("gaussian");
    if f.regions.is_some() && gaussian {
        return Err(invalid(
            path,
            "regions",
            format!(
                "the base '{}' has a Gaussian plume, which takes one source: give a base with a \
                 filament plume (duck-2003-mt, say) or leave [regions] out",
                f.base
            ),
        ));
    }
    Ok(())
}

/// Draws the regions of `site` (drawn from `seed` without them), and moves the site's source,
/// its distance from the edge and its spin-up to the sources drawn (the spin-up long enough for
/// the most upflow source's plume to cross the op-area).
pub(crate) fn draw(r: &RegionsDraw, f: &FamilyFile, site: &mut Site, seed: u64) {
    let mut rng = stream_rng(seed, StreamId::Custom(REGIONS_STREAM));
    let (u, w) = (unit(site.axis_deg), unit(site.axis_deg + 90.0));
    let down = unit(site.flow_toward_deg);
    let (l, h) = (site.length_m, site.width_m);
    // The check kept both within 1..=MAX_CELLS.
    let (along, across) = (
        r.along.clamp(1, MAX_CELLS) as u32,
        r.across.clamp(1, MAX_CELLS) as u32,
    );
    let (dl, dw) = (l / f64::from(along), h / f64::from(across));
    let at = |a: f64, b: f64| {
        let p = u * a + w * b;
        [p.x, p.y]
    };
    // Columns run along whichever grid axis lies nearer the flow; within a column the cells go
    // downflow first, and the columns go in the order of their most downflow cell.
    let flow_along_axis = down.dot(&u).abs() >= down.dot(&w).abs();
    // (column, downflow order key, cell corners in the axis frame)
    let mut cells: Vec<(u32, f64, [f64; 4])> = Vec::new();
    for j in 0..across {
        for i in 0..along {
            let (a0, b0) = (-l / 2.0 + dl * f64::from(i), -h / 2.0 + dw * f64::from(j));
            let centre = u * (a0 + dl / 2.0) + w * (b0 + dw / 2.0);
            let column = if flow_along_axis { j } else { i };
            cells.push((column, -centre.dot(&down), [a0, a0 + dl, b0, b0 + dw]));
        }
    }
    let columns = if flow_along_axis { across } else { along };
    let lead: Vec<f64> = (0..columns)
        .map(|c| {
            cells
                .iter()
                .filter(|x| x.0 == c)
                .map(|x| x.1)
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    cells.sort_by(|x, y| {
        lead[x.0 as usize]
            .total_cmp(&lead[y.0 as usize])
            .then(x.0.cmp(&y.0))
            .then(x.1.total_cmp(&y.1))
    });
    let polygons: Vec<Vec<[f64; 2]>> = cells
        .iter()
        .map(|(_, _, [a0, a1, b0, b1])| {
            vec![at(*a0, *b0), at(*a1, *b0), at(*a1, *b1), at(*a0, *b1)]
        })
        .collect();
    let cells_n = i64::from(along * across);
    let (lo, hi) = (
        r.sources[0].clamp(1, cells_n),
        r.sources[1].clamp(1, cells_n),
    );
    let n = rng.random_range(lo..=hi.max(lo)) as usize;
    // The first n of a random permutation of the cells.
    let mut order: Vec<usize> = (0..polygons.len()).collect();
    for k in 0..n.min(order.len()) {
        let pick = rng.random_range(k..order.len());
        order.swap(k, pick);
    }
    let mut chosen: Vec<usize> = order[..n.min(order.len())].to_vec();
    chosen.sort_unstable();
    let sources: Vec<RegionSource> = chosen
        .into_iter()
        .map(|cell| {
            let [a0, a1, b0, b1] = cells[cell].2;
            let inset = r.inset_m.min((a1 - a0).min(b1 - b0) / 2.0);
            let a = rng.random_range((a0 + inset)..=(a1 - inset));
            let b = rng.random_range((b0 + inset)..=(b1 - inset));
            let mass = f.source.mass_rate_per_s.map(|[lo, hi]| {
                if hi > lo {
                    rng.random_range(lo.ln()..=hi.ln()).exp()
                } else {
                    lo
                }
            });
            RegionSource {
                pos: at(a, b),
                cell,
                mass_rate_per_s: mass,
            }
        })
        .collect();
    if let Some(first) = sources.first() {
        site.source = first.pos;
        site.source_edge_m = crate::family::edge_distance(&site.op_area, v(first.pos));
        site.mass_rate_per_s = first.mass_rate_per_s;
    }
    let reach = sources
        .iter()
        .flat_map(|s| {
            site.op_area
                .iter()
                .map(move |c| (v(*c) - v(s.pos)).dot(&down))
        })
        .fold(0.0_f64, f64::max)
        .max(l.max(h) * if site.tidal_swing_deg > 0.0 { 1.0 } else { 0.0 });
    site.spinup_s = (1.2 * (reach + 50.0) / site.flow_speed_mps).clamp(600.0, 100_000.0);
    site.regions = Some(RegionsSite {
        cells: polygons,
        sources,
    });
}

fn v(p: [f64; 2]) -> Vec2 {
    Vec2::new(p[0], p[1])
}

fn polygon(p: &[[f64; 2]]) -> toml::Value {
    toml::Value::Array(
        p.iter()
            // `+ 0.0` writes a corner on an axis as 0.0, not -0.0.
            .map(|q| {
                toml::Value::Array(vec![
                    float(round(q[0], 2) + 0.0),
                    float(round(q[1], 2) + 0.0),
                ])
            })
            .collect(),
    )
}

/// Writes the regions into the site's scenario table `t`: one source table per source (each a
/// copy of the base's first, moved), and the subregions.
pub(crate) fn apply(r: &RegionsSite, t: &mut toml::Table) {
    let template = t
        .get("sources")
        .and_then(toml::Value::as_array)
        .and_then(|a| a.first())
        .and_then(toml::Value::as_table)
        .cloned()
        .unwrap_or_default();
    let sources = r
        .sources
        .iter()
        .map(|s| {
            let mut table = template.clone();
            table.insert("x_m".into(), float(round(s.pos[0], 2)));
            table.insert("y_m".into(), float(round(s.pos[1], 2)));
            if let Some(q) = s.mass_rate_per_s {
                table.insert("mass_rate_per_s".into(), float(round(q, 4)));
            }
            toml::Value::Table(table)
        })
        .collect();
    t.insert("sources".into(), toml::Value::Array(sources));
    if let Some(mission) = crate::family::table_at(t, "mission") {
        mission.insert(
            "subregions".into(),
            toml::Value::Array(r.cells.iter().map(|c| polygon(c)).collect()),
        );
    }
}

impl RegionsSite {
    /// What was drawn, as `(name, value)` lines of a site file's header.
    pub fn values(&self) -> Vec<(&'static str, String)> {
        let cells: Vec<String> = self.sources.iter().map(|s| s.cell.to_string()).collect();
        vec![
            ("regions_subregions", self.cells.len().to_string()),
            ("regions_sources", self.sources.len().to_string()),
            ("regions_source_subregions", cells.join(", ")),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::family::Family;
    use crate::{Origin, ScenarioError};

    const MULTI: &str = include_str!("../../../examples/families/multi-source.family.toml");

    fn family(text: &str) -> Result<Family, ScenarioError> {
        Family::parse(
            text,
            Path::new("examples/families/multi-source.family.toml"),
        )
    }

    fn inside(cell: &[[f64; 2]], p: [f64; 2], inset: f64) -> bool {
        // A convex polygon: the point lies at least `inset` inside every edge (the sign of the
        // polygon's area says which side is inside).
        let n = cell.len();
        let orientation = (0..n)
            .map(|k| {
                let (a, b) = (cell[k], cell[(k + 1) % n]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum::<f64>()
            .signum();
        (0..n).all(|k| {
            let (a, b) = (v(cell[k]), v(cell[(k + 1) % n]));
            let (e, q) = (b - a, v(p) - a);
            (e.x * q.y - e.y * q.x) * orientation / e.norm() >= inset - 1e-9
        })
    }

    #[test]
    fn sites_hold_one_to_three_sources_each_in_its_own_subregion() {
        let f = family(MULTI).unwrap_or_else(|e| panic!("{e}"));
        let mut counts = [0_usize; 4];
        for seed in 0..60 {
            let site = f.draw(seed);
            let r = site.regions.as_ref().expect("regions drawn");
            assert_eq!(r.cells.len(), 4);
            let n = r.sources.len();
            assert!((1..=3).contains(&n), "seed {seed}: {n} sources");
            counts[n] += 1;
            let mut cells: Vec<usize> = r.sources.iter().map(|s| s.cell).collect();
            cells.dedup();
            assert_eq!(cells.len(), n, "seed {seed}: one source per cell");
            for s in &r.sources {
                assert!(inside(&r.cells[s.cell], s.pos, 60.0), "seed {seed}: {s:?}");
                let q = s.mass_rate_per_s.expect("drawn");
                assert!((10.0..=40.0).contains(&q), "{q}");
            }
            // The cells tile the op-area: their areas add up to its area.
            let area = |p: &[[f64; 2]]| {
                (0..p.len())
                    .map(|k| {
                        let (a, b) = (p[k], p[(k + 1) % p.len()]);
                        a[0] * b[1] - b[0] * a[1]
                    })
                    .sum::<f64>()
                    .abs()
                    / 2.0
            };
            let total: f64 = r.cells.iter().map(|c| area(c)).sum();
            assert!(
                (total - area(&site.op_area)).abs() < 1e-6 * total,
                "seed {seed}"
            );
            // The first subregion holds the op-area's most downflow corner (where the search
            // begins), and within each column the downflow cell comes first.
            let down = unit(site.flow_toward_deg);
            let corner = site
                .op_area
                .iter()
                .copied()
                .max_by(|a, b| v(*a).dot(&down).total_cmp(&v(*b).dot(&down)))
                .expect("corners");
            assert!(
                r.cells[0].iter().any(|c| (v(*c) - v(corner)).norm() < 1e-6),
                "seed {seed}: the first subregion misses the downflow corner"
            );
            let centre = |c: &[[f64; 2]]| c.iter().fold(Vec2::zeros(), |s, p| s + v(*p)) / 4.0;
            for pair in [(0, 1), (2, 3)] {
                assert!(
                    centre(&r.cells[pair.0]).dot(&down) >= centre(&r.cells[pair.1]).dot(&down),
                    "seed {seed}"
                );
            }
            // The site's first source is the first drawn.
            assert_eq!(site.source, r.sources[0].pos);
            // It builds, with every source and the four subregions.
            let table = site.apply(&f.file, &f.base);
            let origin = Origin::Preset("multi-source".into());
            let cfg = crate::from_table(table, &origin).unwrap_or_else(|e| panic!("{e}"));
            let built = crate::build(&cfg, &origin, Some(seed)).unwrap_or_else(|e| panic!("{e}"));
            let mission = built.mission.as_ref().expect("a mission");
            assert_eq!(mission.subregions.len(), 4, "seed {seed}");
            assert_eq!(cfg.sources.len(), n, "seed {seed}");
        }
        assert!(
            counts[1] > 5 && counts[2] > 5 && counts[3] > 5,
            "{counts:?}"
        );
    }

    #[test]
    fn regions_leave_the_rest_of_a_site_as_drawn_without_them() {
        let with = family(MULTI).unwrap_or_else(|e| panic!("{e}"));
        let without_text = MULTI[..MULTI.find("[regions]").expect("a [regions] table")].to_string();
        let without = family(&without_text).unwrap_or_else(|e| panic!("{e}"));
        for seed in 0..20 {
            let (a, b) = (with.draw(seed), without.draw(seed));
            assert!(b.regions.is_none());
            let strip = |s: &Site| Site {
                source: [0.0; 2],
                source_edge_m: 0.0,
                mass_rate_per_s: None,
                spinup_s: 0.0,
                regions: None,
                ..s.clone()
            };
            assert_eq!(strip(&a), strip(&b), "seed {seed}");
        }
    }

    #[test]
    fn bad_regions_are_refused_naming_the_key() {
        let refused = |from: &str, to: &str, key: &str, says: &str| {
            assert!(MULTI.contains(from), "{from}");
            let e = family(&MULTI.replace(from, to)).expect_err(to).to_string();
            assert!(e.contains(key) && e.contains(says), "{to}: {e}");
        };
        refused(
            "sources = [1, 3]",
            "sources = [1, 5]",
            "regions.sources",
            "<= 4",
        );
        refused(
            "sources = [1, 3]",
            "sources = [0, 2]",
            "regions.sources",
            "1 <= low",
        );
        refused(
            "sources = [1, 3]",
            "sources = [3, 2]",
            "regions.sources",
            "low <= high",
        );
        refused("along = 2", "along = 7", "regions.along", "from 1 to 6");
        refused(
            "along = 2\nacross = 2",
            "along = 1\nacross = 1",
            "regions",
            "at least two cells",
        );
        refused(
            "shapes = [\"rectangle\"]",
            "shapes = [\"rectangle\", \"convex\"]",
            "area.shapes",
            "splits a rectangle",
        );
        refused(
            "inset_m = 60.0\n",
            "inset_m = 200.0\n",
            "regions.inset_m",
            "at most 145.0 m",
        );
        refused(
            "sources = [1, 3]",
            "sources = [1, 3]\nsoruces = 2",
            "regions",
            "unknown field",
        );
        refused("along = 2", "along = 2.0", "regions.along", "invalid type");
        refused(
            "base = \"duck-2003-mt\"",
            "base = \"soares-freshwater\"",
            "regions",
            "Gaussian plume, which takes one source",
        );
        // regions.inset_m replaces [source] inset_m: a small area with a 2 x 1 grid of 50 m
        // cells and 20 m insets is read, though the default source inset (60 m) would not fit.
        let small = MULTI
            .replace("length_m = [700.0, 1000.0]", "length_m = [100.0, 100.0]")
            .replace("width_m = [600.0, 900.0]", "width_m = [100.0, 100.0]")
            .replace("across = 2", "across = 1")
            .replace("sources = [1, 3]", "sources = [1, 2]")
            .replace("inset_m = 60.0\n", "inset_m = 20.0\n");
        let f = family(&small).unwrap_or_else(|e| panic!("{e}"));
        assert!(f.draw(3).regions.is_some_and(|r| r.cells.len() == 2));
    }
}
