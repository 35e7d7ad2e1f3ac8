//! Per-group statistics: success rate with a Wilson interval, error quantiles, times and path.

use crate::runs::{RunOutcome, RunRow};
use crate::spec::{Campaign, RunKey};
use serde::Serialize;
use std::fmt::Write as _;

/// z of a two-sided 95 % interval.
pub const Z95: f64 = 1.959_963_984_540_054;

/// Wilson score interval for `k` successes in `n` trials at normal quantile `z`;
/// `(0, 1)` when `n` is 0.
pub fn wilson(k: u64, n: u64, z: f64) -> (f64, f64) {
    if n == 0 {
        return (0.0, 1.0);
    }
    let n_f = n as f64;
    let p = k as f64 / n_f;
    let z2 = z * z;
    let denom = 1.0 + z2 / n_f;
    let centre = (p + z2 / (2.0 * n_f)) / denom;
    let half = z / denom * (p * (1.0 - p) / n_f + z2 / (4.0 * n_f * n_f)).sqrt();
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

/// Quantile `q` of sorted values by linear interpolation between order statistics (NumPy's
/// default); NaN for no values.
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    match sorted.len() {
        0 => f64::NAN,
        1 => sorted[0],
        n => {
            let h = q.clamp(0.0, 1.0) * (n - 1) as f64;
            let lo = h.floor() as usize;
            let hi = (lo + 1).min(n - 1);
            sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
        }
    }
}

fn sorted(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    v
}

/// The statistics of one (scenario, configuration, sweep point) group.
#[derive(Debug, Clone, Serialize)]
pub struct GroupSummary {
    /// Scenario label.
    pub scenario: String,
    /// Configuration name.
    pub config: String,
    /// Sweep point label.
    pub point: String,
    /// Runs recorded.
    pub runs: u64,
    /// Successful runs.
    pub successes: u64,
    /// successes / runs.
    pub success_rate: f64,
    /// Wilson 95 % interval, low end.
    pub success_ci_low: f64,
    /// Wilson 95 % interval, high end.
    pub success_ci_high: f64,
    /// True sources over all runs.
    pub sources: u64,
    /// Of them, located.
    pub sources_located: u64,
    /// Declarations over all runs.
    pub declarations: u64,
    /// Of them, farther than the success radius from every true source.
    pub declarations_off_source: u64,
    /// Runs that searched several subregions in turn (judged by the sources they located).
    pub subregion_runs: u64,
    /// Distance from each located source to its nearest declaration: median, m.
    pub located_error_median_m: f64,
    /// 90th percentile, m.
    pub located_error_p90_m: f64,
    /// Declaration error of declaring runs: median, m.
    pub error_median_m: f64,
    /// 90th percentile, m.
    pub error_p90_m: f64,
    /// |along-flow error|: median, m.
    pub along_median_m: f64,
    /// |along-flow error|: 90th percentile, m.
    pub along_p90_m: f64,
    /// Signed along-flow error: median (positive: declared downflow), m.
    pub along_signed_median_m: f64,
    /// |crossflow error|: median, m.
    pub cross_median_m: f64,
    /// |crossflow error|: 90th percentile, m.
    pub cross_p90_m: f64,
    /// Time to first detection (runs that detected): median, s.
    pub first_detection_median_s: f64,
    /// Time to declaration (declaring runs): median, s.
    pub declaration_median_s: f64,
    /// Path length over ground: median, m.
    pub path_length_median_m: f64,
    /// Traced path over the straight line from the first detection to the source: median.
    pub path_ratio_median: f64,
    /// Count of each outcome, in [`RunOutcome::all`] order.
    pub outcomes: Vec<u64>,
}

/// Whether some run had several sources or searched several subregions in turn: success then
/// means every source located, and the tables and charts show the sources rather than the
/// first declaration.
pub fn multi_source(groups: &[GroupSummary]) -> bool {
    groups
        .iter()
        .any(|g| g.sources > g.runs || g.subregion_runs > 0)
}

/// Summarises sorted rows group by group, in campaign order; groups without rows are left out.
pub fn summarise(c: &Campaign, rows: &[(RunKey, RunRow)]) -> Vec<GroupSummary> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < rows.len() {
        let (k0, _) = &rows[i];
        let j = rows[i..]
            .iter()
            .position(|(k, _)| {
                (k.scenario, k.config, k.point) != (k0.scenario, k0.config, k0.point)
            })
            .map_or(rows.len(), |d| i + d);
        let group: Vec<&RunRow> = rows[i..j].iter().map(|(_, r)| r).collect();
        out.push(summarise_group(c, k0, &group));
        i = j;
    }
    out
}

fn summarise_group(c: &Campaign, key: &RunKey, rows: &[&RunRow]) -> GroupSummary {
    let n = rows.len() as u64;
    let k = rows.iter().filter(|r| r.metrics.success).count() as u64;
    let (lo, hi) = wilson(k, n, Z95);
    let dec: Vec<&&RunRow> = rows.iter().filter(|r| r.metrics.declared).collect();
    let err = sorted(dec.iter().filter_map(|r| r.metrics.error_m));
    let along = sorted(
        dec.iter()
            .filter_map(|r| r.metrics.error_along_m.map(f64::abs)),
    );
    let along_signed = sorted(dec.iter().filter_map(|r| r.metrics.error_along_m));
    let cross = sorted(
        dec.iter()
            .filter_map(|r| r.metrics.error_cross_m.map(f64::abs)),
    );
    let det = sorted(rows.iter().filter_map(|r| r.metrics.first_detection_s));
    let decl = sorted(dec.iter().filter_map(|r| r.metrics.declaration_s));
    let path = sorted(rows.iter().filter_map(|r| r.metrics.path_length_m));
    let ratio = sorted(dec.iter().filter_map(|r| r.metrics.path_ratio));
    let radius = c.located_radius_m(key.scenario, key.config, key.point);
    let located = sorted(
        rows.iter()
            .flat_map(|r| r.metrics.source_errors_m.split(';'))
            .filter_map(|e| e.parse::<f64>().ok())
            .filter(|e| *e <= radius),
    );
    GroupSummary {
        scenario: c.scenarios[key.scenario].label.clone(),
        config: c.configs[key.config].name.clone(),
        point: c.points[key.point].label(),
        runs: n,
        successes: k,
        success_rate: if n > 0 { k as f64 / n as f64 } else { f64::NAN },
        success_ci_low: lo,
        success_ci_high: hi,
        sources: rows.iter().map(|r| u64::from(r.metrics.sources)).sum(),
        sources_located: rows
            .iter()
            .map(|r| u64::from(r.metrics.sources_located))
            .sum(),
        declarations: rows.iter().map(|r| u64::from(r.metrics.declarations)).sum(),
        declarations_off_source: rows
            .iter()
            .map(|r| u64::from(r.metrics.declarations_off_source))
            .sum(),
        subregion_runs: rows.iter().filter(|r| r.metrics.subregions > 1).count() as u64,
        located_error_median_m: quantile(&located, 0.5),
        located_error_p90_m: quantile(&located, 0.9),
        error_median_m: quantile(&err, 0.5),
        error_p90_m: quantile(&err, 0.9),
        along_median_m: quantile(&along, 0.5),
        along_p90_m: quantile(&along, 0.9),
        along_signed_median_m: quantile(&along_signed, 0.5),
        cross_median_m: quantile(&cross, 0.5),
        cross_p90_m: quantile(&cross, 0.9),
        first_detection_median_s: quantile(&det, 0.5),
        declaration_median_s: quantile(&decl, 0.5),
        path_length_median_m: quantile(&path, 0.5),
        path_ratio_median: quantile(&ratio, 0.5),
        outcomes: RunOutcome::all()
            .into_iter()
            .map(|o| rows.iter().filter(|r| r.outcome == o).count() as u64)
            .collect(),
    }
}

fn num(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else {
        String::new()
    }
}

/// `summary.csv`: one row per group, numbers rounded for reading (the raw runs are in runs.csv).
pub fn summary_csv(groups: &[GroupSummary]) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut head: Vec<String> = [
        "scenario",
        "config",
        "point",
        "runs",
        "successes",
        "success_rate",
        "success_ci_low",
        "success_ci_high",
        "sources",
        "sources_located",
        "declarations",
        "declarations_off_source",
        "located_error_median_m",
        "located_error_p90_m",
        "error_median_m",
        "error_p90_m",
        "along_median_m",
        "along_p90_m",
        "along_signed_median_m",
        "cross_median_m",
        "cross_p90_m",
        "first_detection_median_s",
        "declaration_median_s",
        "path_length_median_m",
        "path_ratio_median",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    head.extend(RunOutcome::all().iter().map(|o| format!("n_{}", o.name())));
    let _ = w.write_record(&head);
    for g in groups {
        let mut rec = vec![
            g.scenario.clone(),
            g.config.clone(),
            g.point.clone(),
            g.runs.to_string(),
            g.successes.to_string(),
            num(g.success_rate, 4),
            num(g.success_ci_low, 4),
            num(g.success_ci_high, 4),
            g.sources.to_string(),
            g.sources_located.to_string(),
            g.declarations.to_string(),
            g.declarations_off_source.to_string(),
            num(g.located_error_median_m, 2),
            num(g.located_error_p90_m, 2),
            num(g.error_median_m, 2),
            num(g.error_p90_m, 2),
            num(g.along_median_m, 2),
            num(g.along_p90_m, 2),
            num(g.along_signed_median_m, 2),
            num(g.cross_median_m, 2),
            num(g.cross_p90_m, 2),
            num(g.first_detection_median_s, 1),
            num(g.declaration_median_s, 1),
            num(g.path_length_median_m, 1),
            num(g.path_ratio_median, 3),
        ];
        rec.extend(g.outcomes.iter().map(u64::to_string));
        let _ = w.write_record(&rec);
    }
    String::from_utf8(w.into_inner().unwrap_or_default()).unwrap_or_default()
}

fn cell(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else {
        "–".to_string()
    }
}

/// `summary.md`: a Markdown table per campaign.
pub fn summary_md(c: &Campaign, groups: &[GroupSummary], expected_runs: u64) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Campaign `{}`\n", c.file.name);
    if !c.file.description.is_empty() {
        let _ = writeln!(s, "{}\n", c.file.description);
    }
    let recorded: u64 = groups.iter().map(|g| g.runs).sum();
    let multi_source = multi_source(groups);
    let within = c.success_within_text();
    let _ = writeln!(
        s,
        "{recorded} of {expected_runs} runs recorded; campaign seed {}, {} seeds per group. \
         Success: {}. Errors are of the first declaration, in metres, over the declaring runs; \
         along/across are absolute values along and across the mean flow at the source \
         (signed along median: positive = declared downflow). Times are medians in seconds. \
         Path ratio: path flown from the first detection to the declaration over the straight \
         line from the first detection to the source.\n",
        c.file.seed,
        c.file.seeds,
        if multi_source {
            format!(
                "with one source, a declaration {within}; with several, or with subregions \
                 searched in turn, every source located (a declaration {within} of it; edge \
                 declarations of subregions count for the source they are nearest to)"
            )
        } else {
            format!("a declaration {within} of a true source")
        }
    );
    if multi_source {
        let _ = writeln!(
            s,
            "Several sources: the first declaration is often at the edge of a subregion, so \
             its error says little; `sources located` counts sources with a declaration \
             {within}, `located error` is the distance from each located source to its \
             nearest declaration (all runs' sources pooled), and `declarations (off a source)` \
             counts every declaration of the runs and, in brackets, those {within} of no \
             source (a subregion's declaration at its upflow edge among them).\n"
        );
    }
    let multi_scenario = c.scenarios.len() > 1;
    let sweep = c.points.len() > 1;
    let mut head = Vec::new();
    if multi_scenario {
        head.push("scenario");
    }
    head.push("config");
    if sweep {
        head.push("sweep");
    }
    head.extend(["runs", "success (95 % CI)"]);
    if multi_source {
        head.push("sources located");
        head.push("located error median / p90");
        head.push("declarations (off a source)");
    }
    head.extend([
        "error median / p90",
        "along median / p90",
        "signed along median",
        "across median / p90",
        "first detection",
        "declaration",
        "path (m)",
        "path ratio",
        "outcomes",
    ]);
    let _ = writeln!(s, "| {} |", head.join(" | "));
    let _ = writeln!(
        s,
        "|{}|",
        head.iter().map(|_| " --- ").collect::<Vec<_>>().join("|")
    );
    for g in groups {
        let mut row = Vec::new();
        if multi_scenario {
            row.push(g.scenario.clone());
        }
        row.push(g.config.clone());
        if sweep {
            row.push(g.point.clone());
        }
        let outcomes: Vec<String> = RunOutcome::all()
            .iter()
            .zip(&g.outcomes)
            .filter(|(_, n)| **n > 0)
            .map(|(o, n)| format!("{} {n}", o.name()))
            .collect();
        row.extend([
            g.runs.to_string(),
            format!(
                "{}/{} = {} ({} – {})",
                g.successes,
                g.runs,
                cell(g.success_rate, 2),
                cell(g.success_ci_low, 2),
                cell(g.success_ci_high, 2)
            ),
        ]);
        if multi_source {
            row.push(format!("{}/{}", g.sources_located, g.sources));
            row.push(format!(
                "{} / {}",
                cell(g.located_error_median_m, 1),
                cell(g.located_error_p90_m, 1)
            ));
            row.push(format!(
                "{} ({})",
                g.declarations, g.declarations_off_source
            ));
        }
        row.extend([
            format!("{} / {}", cell(g.error_median_m, 1), cell(g.error_p90_m, 1)),
            format!("{} / {}", cell(g.along_median_m, 1), cell(g.along_p90_m, 1)),
            cell(g.along_signed_median_m, 1),
            format!("{} / {}", cell(g.cross_median_m, 1), cell(g.cross_p90_m, 1)),
            cell(g.first_detection_median_s, 0),
            cell(g.declaration_median_s, 0),
            cell(g.path_length_median_m, 0),
            cell(g.path_ratio_median, 2),
            outcomes.join(", "),
        ]);
        let _ = writeln!(s, "| {} |", row.join(" | "));
    }
    s
}

/// A labelled test that puts a run in a bin.
type Bin = (String, Box<dyn Fn(&RunRow) -> bool>);

/// One way of splitting a family's runs by what was drawn.
struct SiteSplit {
    title: &'static str,
    bins: Vec<Bin>,
}

/// One bin per distinct value of `get` over `runs` (in order; runs where it gives `None` fall in
/// none), labelled with the value.
fn value_bins<T>(runs: &[&(RunKey, RunRow)], get: fn(&RunRow) -> Option<T>) -> Vec<Bin>
where
    T: Ord + Clone + std::fmt::Display + 'static,
{
    let mut values: Vec<T> = runs.iter().filter_map(|(_, r)| get(r)).collect();
    values.sort();
    values.dedup();
    values
        .into_iter()
        .map(|v| {
            let label = v.to_string();
            (
                label,
                Box::new(move |r: &RunRow| get(r).as_ref() == Some(&v))
                    as Box<dyn Fn(&RunRow) -> bool>,
            )
        })
        .collect()
}

/// Bins of a drawn number at the given edges (`[a, b)`, the last closed), labelled with `unit`.
fn number_bins(
    get: fn(&RunRow) -> Option<f64>,
    edges: &[f64],
    digits: usize,
    unit: &str,
) -> Vec<Bin> {
    let mut bins: Vec<Bin> = Vec::new();
    for w in edges.windows(2) {
        let (a, b) = (w[0], w[1]);
        let last = b >= edges[edges.len() - 1];
        bins.push((
            format!("{a:.digits$}-{b:.digits$} {unit}"),
            Box::new(move |r: &RunRow| {
                get(r).is_some_and(|v| v >= a && (v < b || (last && v <= b)))
            }),
        ));
    }
    bins
}

/// Tercile edges of the values (min, two terciles, max), or `None` with too few distinct values.
fn terciles(mut v: Vec<f64>) -> Option<Vec<f64>> {
    v.sort_by(f64::total_cmp);
    let (lo, hi) = (*v.first()?, *v.last()?);
    (hi > lo).then(|| vec![lo, quantile(&v, 1.0 / 3.0), quantile(&v, 2.0 / 3.0), hi])
}

/// For every family scenario of the campaign: success against what was drawn (flow direction to
/// the op-area's axis, flow speed, the source's distance from the edge, the start, a flow-sensor
/// fault), per configuration and sweep point. Empty without families.
pub fn sites_md(c: &Campaign, rows: &[(RunKey, RunRow)]) -> String {
    let mut s = String::new();
    for (si, entry) in c.scenarios.iter().enumerate() {
        if entry.family.is_none() {
            continue;
        }
        let runs: Vec<&(RunKey, RunRow)> = rows.iter().filter(|(k, _)| k.scenario == si).collect();
        if runs.is_empty() {
            continue;
        }
        let values = |get: fn(&RunRow) -> Option<f64>| -> Vec<f64> {
            runs.iter().filter_map(|(_, r)| get(r)).collect()
        };
        let mut splits = vec![SiteSplit {
            title: "flow direction from the op-area's long axis",
            bins: number_bins(
                |r| r.site.site_flow_to_axis_deg,
                &[0.0, 30.0, 60.0, 90.0],
                0,
                "deg",
            ),
        }];
        if let Some(e) = terciles(values(|r| r.site.site_flow_speed_mps)) {
            splits.push(SiteSplit {
                title: "flow speed (terciles)",
                bins: number_bins(|r| r.site.site_flow_speed_mps, &e, 2, "m/s"),
            });
        }
        if let Some(e) = terciles(values(|r| r.site.site_source_edge_m)) {
            splits.push(SiteSplit {
                title: "source's distance from the op-area's edge (terciles)",
                bins: number_bins(|r| r.site.site_source_edge_m, &e, 0, "m"),
            });
        }
        splits.push(SiteSplit {
            title: "start",
            bins: value_bins(&runs, |r| Some(r.site.site_start.clone())),
        });
        if runs
            .iter()
            .any(|(_, r)| r.site.site_flow_fault == Some(true))
        {
            splits.push(SiteSplit {
                title: "flow-sensor fault",
                bins: vec![
                    (
                        "no fault".into(),
                        Box::new(|r: &RunRow| r.site.site_flow_fault == Some(false)),
                    ),
                    (
                        "fault".into(),
                        Box::new(|r: &RunRow| r.site.site_flow_fault == Some(true)),
                    ),
                ],
            });
        }
        if runs.iter().any(|(_, r)| r.metrics.sources > 1) {
            splits.push(SiteSplit {
                title: "sources at the site",
                // Runs that ended in an error report no sources: no bin of their own.
                bins: value_bins(&runs, |r| Some(r.metrics.sources).filter(|n| *n > 0)),
            });
        }
        let _ = writeln!(
            s,
            "\n## Sites of `{}`\n\nSuccess (as above) by what was drawn: successes / runs (rate).\n",
            entry.label
        );
        for split in &splits {
            let _ = writeln!(s, "**{}**\n", split.title);
            let mut head = vec!["config".to_string()];
            if c.points.len() > 1 {
                head.push("sweep".into());
            }
            head.extend(split.bins.iter().map(|b| b.0.clone()));
            let _ = writeln!(s, "| {} |", head.join(" | "));
            let _ = writeln!(
                s,
                "|{}|",
                head.iter().map(|_| " --- ").collect::<Vec<_>>().join("|")
            );
            for config in 0..c.configs.len() {
                for point in 0..c.points.len() {
                    let group: Vec<&RunRow> = runs
                        .iter()
                        .filter(|(k, _)| k.config == config && k.point == point)
                        .map(|(_, r)| r)
                        .collect();
                    if group.is_empty() {
                        continue;
                    }
                    let mut row = vec![c.configs[config].name.clone()];
                    if c.points.len() > 1 {
                        row.push(c.points[point].label());
                    }
                    for (_, test) in &split.bins {
                        let n = group.iter().filter(|r| test(r)).count();
                        let k = group
                            .iter()
                            .filter(|r| test(r) && r.metrics.success)
                            .count();
                        row.push(if n == 0 {
                            "-".into()
                        } else {
                            format!("{k}/{n} ({:.0} %)", 100.0 * k as f64 / n as f64)
                        });
                    }
                    let _ = writeln!(s, "| {} |", row.join(" | "));
                }
            }
            s.push('\n');
        }
    }
    s
}

#[cfg(test)]
pub(crate) mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// A two-run campaign on the multi-source preset: the first run located both sources, the
    /// second only one (the other has only a far edge declaration).
    pub(crate) fn multi_source_fixture() -> (Campaign, Vec<(RunKey, RunRow)>) {
        let path = std::path::Path::new("mt.toml");
        let text = "name = \"mt\"\nseed = 1\nseeds = 2\nscenarios = [\"duck-2003-mt\"]\n";
        let file = crate::spec::parse_campaign(text, path).unwrap();
        let c = Campaign::resolve(file, path, text.to_string(), true).unwrap();
        let row = |seed_index: u64, located: u32, errors: &str| {
            let key = RunKey {
                scenario: 0,
                config: 0,
                point: 0,
                seed_index,
            };
            let r = RunRow {
                outcome: RunOutcome::Mission(plumetrace_mission::Outcome::Declared),
                metrics: plumetrace_mission::RunMetrics {
                    declared: true,
                    success: located == 2,
                    sources: 2,
                    sources_located: located,
                    declarations: 3,
                    declarations_off_source: 3 - located,
                    source_errors_m: errors.into(),
                    error_m: Some(313.0),
                    ..Default::default()
                },
                ..RunRow::default()
            };
            (key, r)
        };
        (
            c,
            vec![row(0, 2, "4.000;6.000"), row(1, 1, "3.000;290.000")],
        )
    }

    #[test]
    fn multi_source_groups_count_located_sources_and_pool_their_errors() {
        let (c, rows) = multi_source_fixture();
        let g = summarise(&c, &rows);
        assert_eq!(
            (g[0].sources, g[0].sources_located, g[0].successes),
            (4, 3, 1)
        );
        assert_eq!(g[0].located_error_median_m, 4.0);
        let md = summary_md(&c, &g, 2);
        assert!(md.contains("| sources located |"), "{md}");
        assert!(md.contains("| 3/4 | 4.0 / 5.6 | 6 (3) |"), "{md}");
        assert!(md.contains("every source located"), "{md}");
    }

    #[test]
    fn one_source_searched_by_subregions_is_shown_by_its_sources() {
        let (c, mut rows) = multi_source_fixture();
        for (_, r) in &mut rows {
            r.metrics.sources = 1;
            r.metrics.sources_located = 1;
        }
        assert!(
            !multi_source(&summarise(&c, &rows)),
            "one source each, no subregions"
        );
        for (_, r) in &mut rows {
            r.metrics.subregions = 4;
        }
        let g = summarise(&c, &rows);
        assert_eq!(g[0].subregion_runs, 2);
        assert!(multi_source(&g));
        assert!(summary_md(&c, &g, 2).contains("| 2/2 |"));
    }

    #[test]
    fn wilson_matches_published_values() {
        // Reference values (z = 1.96): Newcombe (1998), Table I, and direct evaluation.
        let cases = [
            (81, 263, 0.2553, 0.3662),
            (15, 148, 0.0624, 0.1605),
            (0, 20, 0.0, 0.1611),
            (1, 29, 0.0061, 0.1718),
            (10, 10, 0.7225, 1.0),
            (8, 10, 0.4902, 0.9433),
        ];
        for (k, n, lo, hi) in cases {
            let (a, b) = wilson(k, n, 1.96);
            assert!(
                (a - lo).abs() < 5e-4 && (b - hi).abs() < 5e-4,
                "{k}/{n}: ({a:.4}, {b:.4}), expected ({lo}, {hi})"
            );
        }
        assert_eq!(wilson(0, 0, Z95), (0.0, 1.0));
    }

    #[test]
    fn quantiles_interpolate_like_numpy() {
        let v = [1.0, 2.0, 3.0, 4.0, 10.0];
        assert_eq!(quantile(&v, 0.5), 3.0);
        assert!((quantile(&v, 0.9) - 7.6).abs() < 1e-12);
        assert_eq!(quantile(&v, 0.0), 1.0);
        assert_eq!(quantile(&v, 1.0), 10.0);
        assert!(quantile(&[], 0.5).is_nan());
        assert!((quantile(&[1.0, 2.0], 0.5) - 1.5).abs() < 1e-12);
    }
}
