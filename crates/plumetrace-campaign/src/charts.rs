//! Campaign charts (SVG): success rates with Wilson intervals, error distributions, and one
//! example track per group.

use crate::error::CampaignError;
use crate::example::ExampleRun;
use crate::runs::RunRow;
use crate::spec::{Campaign, RunKey};
use crate::stats::{GroupSummary, multi_source, quantile};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor;
use plumetrace_core::Vec2;
use plumetrace_report::marks::{self, Group};
use plumetrace_report::{dashed, map_chart};
use std::path::Path;

fn err<E: std::fmt::Debug>(what: &str) -> impl Fn(E) -> CampaignError + '_ {
    move |e| CampaignError::Chart {
        what: what.to_string(),
        message: format!("{e:?}"),
    }
}

/// Distinct colours for series (colour-blind-safe set by Okabe and Ito).
const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(120, 120, 120),
    RGBColor(0, 0, 0),
];

/// The label of a group in charts: the configuration, then the sweep point, then the scenario
/// when the campaign has several.
fn group_label(c: &Campaign, g: &GroupSummary) -> String {
    let mut s = g.config.clone();
    if !g.point.is_empty() {
        s = format!("{s} · {}", g.point.replace(';', ", "));
    }
    if c.scenarios.len() > 1 {
        s = format!("{} · {s}", g.scenario);
    }
    s
}

fn label_width(labels: &[String]) -> u32 {
    let longest = labels.iter().map(|l| l.chars().count()).max().unwrap_or(4) as u32;
    (longest * 7 + 16).clamp(60, 420)
}

/// The sweep key and numeric values when the campaign sweeps exactly one numeric key.
fn numeric_sweep(c: &Campaign) -> Option<(String, Vec<f64>)> {
    if c.file.sweep.len() != 1 || c.points.len() < 2 {
        return None;
    }
    let (key, _) = c.file.sweep.iter().next()?;
    let values: Option<Vec<f64>> = c
        .points
        .iter()
        .map(|p| match &p.values[0].1 {
            toml::Value::Float(f) => Some(*f),
            toml::Value::Integer(i) => Some(*i as f64),
            _ => None,
        })
        .collect();
    Some((key.clone(), values?))
}

/// `success.svg`.
pub fn success_chart(c: &Campaign, groups: &[GroupSummary]) -> Result<String, CampaignError> {
    if let Some((key, values)) = numeric_sweep(c) {
        return success_vs_sweep(c, groups, &key, &values);
    }
    let e = err("success.svg");
    let labels: Vec<String> = groups.iter().map(|g| group_label(c, g)).collect();
    let n = groups.len().max(1);
    let lw = label_width(&labels);
    let (width, height) = (lw + 620, (n as u32 * 34 + 130).max(220));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(&e)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("{}: success rate with Wilson 95 % intervals", c.file.name),
                ("sans-serif", 17),
            )
            .margin(12)
            .margin_right(30)
            .x_label_area_size(40)
            .y_label_area_size(lw)
            .build_cartesian_2d(0.0..1.0, -0.6..(n as f64 - 0.4))
            .map_err(&e)?;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .y_labels(0)
            .x_desc(success_desc(c, groups))
            .label_style(("sans-serif", 15))
            .draw()
            .map_err(&e)?;
        for (i, g) in groups.iter().enumerate() {
            let y = (n - 1 - i) as f64;
            let col = PALETTE[i % PALETTE.len()];
            // The row is a series its label names.
            marks::open(chart.plotting_area(), (0.0, y), Group::Series, &labels[i]).map_err(&e)?;
            chart
                .draw_series([
                    PathElement::new(
                        vec![(g.success_ci_low, y), (g.success_ci_high, y)],
                        col.stroke_width(2),
                    ),
                    PathElement::new(
                        vec![(g.success_ci_low, y - 0.15), (g.success_ci_low, y + 0.15)],
                        col.stroke_width(2),
                    ),
                    PathElement::new(
                        vec![(g.success_ci_high, y - 0.15), (g.success_ci_high, y + 0.15)],
                        col.stroke_width(2),
                    ),
                ])
                .map_err(&e)?;
            if g.success_rate.is_finite() {
                chart
                    .draw_series([Circle::new((g.success_rate, y), 6, col.filled())])
                    .map_err(&e)?;
            }
            marks::close(chart.plotting_area(), (0.0, y)).map_err(&e)?;
            if g.success_rate.is_finite() {
                let (px, py) = chart.backend_coord(&(g.success_ci_high, y));
                root.draw(&Text::new(
                    format!(
                        "{}/{} = {:.2} ({:.2}–{:.2})",
                        g.successes, g.runs, g.success_rate, g.success_ci_low, g.success_ci_high
                    ),
                    (px.min(width as i32 - 190) + 8, py - 20),
                    ("sans-serif", 15).into_font().color(&BLACK),
                ))
                .map_err(&e)?;
            }
        }
        row_labels(&root, &chart, &labels).map_err(&e)?;
        root.present().map_err(&e)?;
    }
    Ok(marks::finish(&svg))
}

fn success_desc(c: &Campaign, groups: &[GroupSummary]) -> String {
    if multi_source(groups) {
        "fraction of runs locating every source".into()
    } else if let Some(r) = c.success_radius_m() {
        format!("fraction of runs declaring within {r} m of a source")
    } else {
        format!(
            "fraction of runs declaring {} of a source",
            c.success_within_text().replace('`', "")
        )
    }
}

/// Writes `labels[i]` right-aligned left of row `n - 1 - i`.
fn row_labels<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    chart: &ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    labels: &[String],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let n = labels.len();
    let x0 = chart.x_range().start;
    for (i, l) in labels.iter().enumerate() {
        let (px, py) = chart.backend_coord(&(x0, (n - 1 - i) as f64));
        let style = ("sans-serif", 15)
            .into_font()
            .color(&BLACK)
            .pos(text_anchor::Pos::new(
                text_anchor::HPos::Right,
                text_anchor::VPos::Center,
            ));
        // The row's label is its key: a legend entry with no swatch.
        root.draw(
            &(EmptyElement::at((px - 8, py))
                + marks::open_text(Group::Legend, l)
                + Text::new(l.clone(), (0, 0), style)
                + marks::close_text()),
        )?;
    }
    Ok(())
}

fn success_vs_sweep(
    c: &Campaign,
    groups: &[GroupSummary],
    key: &str,
    values: &[f64],
) -> Result<String, CampaignError> {
    let e = err("success.svg");
    let (lo, hi) = values
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
    let pad = ((hi - lo) * 0.08).max(1e-9);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(&e)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "{}: success rate against {key} (Wilson 95 % intervals)",
                    c.file.name
                ),
                ("sans-serif", 17),
            )
            .margin(12)
            .margin_right(30)
            .x_label_area_size(40)
            .y_label_area_size(55)
            .build_cartesian_2d((lo - pad)..(hi + pad), 0.0..1.0)
            .map_err(&e)?;
        chart
            .configure_mesh()
            .x_desc(key)
            .y_desc(success_desc(c, groups))
            .label_style(("sans-serif", 15))
            .draw()
            .map_err(&e)?;
        let series: Vec<(String, String)> = {
            let mut s: Vec<(String, String)> = groups
                .iter()
                .map(|g| (g.scenario.clone(), g.config.clone()))
                .collect();
            s.dedup();
            s
        };
        let offset = (hi - lo).max(1e-9) * 0.006;
        for (k, (scenario, config)) in series.iter().enumerate() {
            let col = PALETTE[k % PALETTE.len()];
            let dx = (k as f64 - (series.len() as f64 - 1.0) / 2.0) * offset;
            let pts: Vec<(f64, &GroupSummary)> = groups
                .iter()
                .filter(|g| &g.scenario == scenario && &g.config == config)
                .filter_map(|g| {
                    let i = c.points.iter().position(|p| p.label() == g.point)?;
                    Some((values[i] + dx, g))
                })
                .collect();
            let name = if c.scenarios.len() > 1 {
                format!("{scenario} · {config}")
            } else {
                config.clone()
            };
            let at = (lo, 0.0);
            marks::open(chart.plotting_area(), at, Group::Series, &name).map_err(&e)?;
            let key = name.clone();
            chart
                .draw_series(LineSeries::new(
                    pts.iter().map(|(x, g)| (*x, g.success_rate)),
                    col.stroke_width(2),
                ))
                .map_err(&e)?
                .label(name)
                .legend(move |p| {
                    // The swatch is the series: its line and its dots.
                    EmptyElement::at(p)
                        + marks::open_text(Group::Legend, &key)
                        + PathElement::new(vec![(0, 0), (16, 0)], col.stroke_width(2))
                        + Circle::new((8, 0), 5, col.filled())
                        + marks::close_text()
                });
            chart
                .draw_series(pts.iter().map(|(x, g)| {
                    ErrorBar::new_vertical(
                        *x,
                        g.success_ci_low,
                        g.success_rate,
                        g.success_ci_high,
                        col.stroke_width(2),
                        10,
                    )
                }))
                .map_err(&e)?;
            chart
                .draw_series(
                    pts.iter()
                        .map(|(x, g)| Circle::new((*x, g.success_rate), 5, col.filled())),
                )
                .map_err(&e)?;
            marks::close(chart.plotting_area(), at).map_err(&e)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .position(SeriesLabelPosition::LowerRight)
            .draw()
            .map_err(&e)?;
        root.present().map_err(&e)?;
    }
    Ok(marks::finish(&svg))
}

/// `errors.svg`: per group, the total, along-flow and crossflow errors of the declaring runs as
/// boxes (quartiles, median line, whiskers from the 5th to the 95th percentile) over every run
/// as a dot. With several sources per run, one panel instead: the distance from each source to
/// its nearest declaration (the first declaration is often at a subregion's edge).
pub fn error_chart(
    c: &Campaign,
    groups: &[GroupSummary],
    rows: &[(RunKey, RunRow)],
) -> Result<String, CampaignError> {
    let e = err("errors.svg");
    let labels: Vec<String> = groups.iter().map(|g| group_label(c, g)).collect();
    let n = groups.len().max(1);
    let lw = label_width(&labels);
    let panel_w = 330u32;
    let values = |g: &GroupSummary, f: &dyn Fn(&RunRow) -> Vec<f64>| -> Vec<(u64, f64)> {
        rows.iter()
            .map(|(_, r)| r)
            .filter(|r| {
                r.metrics.declared
                    && r.scenario == g.scenario
                    && r.config == g.config
                    && r.point == g.point
            })
            .flat_map(|r| f(r).into_iter().map(|v| (r.seed_index, v)))
            .collect()
    };
    type Metric<'a> = (&'a str, &'a dyn Fn(&RunRow) -> Vec<f64>);
    let metrics: Vec<Metric> = if multi_source(groups) {
        vec![(
            "distance from each source to its nearest declaration (m; located: within the success radius, 50 m by default)",
            &|r: &RunRow| {
                r.metrics
                    .source_errors_m
                    .split(';')
                    .filter_map(|v| v.parse::<f64>().ok())
                    .collect()
            },
        )]
    } else {
        vec![
            ("declaration error (m)", &|r: &RunRow| {
                r.metrics.error_m.into_iter().collect()
            }),
            ("along-flow error (m, + downflow)", &|r: &RunRow| {
                r.metrics.error_along_m.into_iter().collect()
            }),
            ("crossflow error (m, + right of flow)", &|r: &RunRow| {
                r.metrics.error_cross_m.into_iter().collect()
            }),
        ]
    };
    let k = metrics.len() as u32;
    let panel_w = if k == 1 { 3 * panel_w } else { panel_w };
    let (width, height) = (lw + k * panel_w + 20, (n as u32 * 46 + 140).max(240));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(&e)?;
        let (title, body) = root.split_vertically(36);
        title
            .draw(&Text::new(
                format!(
                    "{}: {} (box: quartiles and median, for 5 or more; whiskers: 5th–95th percentile; dots: {})",
                    c.file.name,
                    if k == 1 {
                        "nearest declaration to each source"
                    } else {
                        "declaration errors of declaring runs"
                    },
                    if k == 1 { "sources" } else { "runs" }
                ),
                (12, 10),
                ("sans-serif", 16).into_font().color(&BLACK),
            ))
            .map_err(&e)?;
        let mut panels = Vec::new();
        let mut rest = body;
        for m in 0..metrics.len() {
            let (panel, r) = rest.split_horizontally(if m == 0 { lw + panel_w } else { panel_w });
            panels.push(panel);
            rest = r;
        }
        for (m, (name, f)) in metrics.iter().enumerate() {
            let per_group: Vec<Vec<(u64, f64)>> = groups.iter().map(|g| values(g, *f)).collect();
            let (lo, hi, limit, all) = axis_range(&per_group, m == 0);
            let beyond = all.iter().filter(|v| v.abs() > limit).count();
            let desc = if beyond > 0 {
                format!("{name}; {beyond} beyond the axis: ▷ ◁ at its edge")
            } else {
                name.to_string()
            };
            let pad = ((hi - lo) * 0.05).max(0.5);
            let area = &panels[m];
            let mut chart = ChartBuilder::on(area)
                .margin(8)
                .margin_right(14)
                .x_label_area_size(40)
                .y_label_area_size(if m == 0 { lw } else { 4 })
                .build_cartesian_2d((lo - pad)..(hi + pad), -0.6..(n as f64 - 0.4))
                .map_err(&e)?;
            chart
                .configure_mesh()
                .disable_y_mesh()
                .y_labels(0)
                .x_labels(6)
                .x_label_formatter(&|v| axis_number(*v))
                .x_desc(desc)
                .label_style(("sans-serif", 15))
                .draw()
                .map_err(&e)?;
            if m > 0 && lo < 0.0 && hi > 0.0 {
                chart
                    .draw_series([PathElement::new(
                        vec![(0.0, -0.6), (0.0, n as f64 - 0.4)],
                        RGBColor(190, 190, 190).stroke_width(1),
                    )])
                    .map_err(&e)?;
            }
            for (i, vals) in per_group.iter().enumerate() {
                let y = (n - 1 - i) as f64;
                marks::open(chart.plotting_area(), (0.0, y), Group::Series, &labels[i])
                    .map_err(&e)?;
                draw_box(&mut chart, y, PALETTE[i % PALETTE.len()], vals, limit).map_err(&e)?;
                marks::close(chart.plotting_area(), (0.0, y)).map_err(&e)?;
            }
            if m == 0 {
                row_labels(&root, &chart, &labels).map_err(&e)?;
            }
        }
        root.present().map_err(&e)?;
    }
    Ok(marks::finish(&svg))
}

/// The x range of an error panel: the bulk of the values (at most 2.5 times the 95th percentile
/// of |value|, at least 5 m; from 0 for the first, unsigned panel), the limit beyond which runs
/// are drawn at the edge, and every value sorted.
fn axis_range(per_group: &[Vec<(u64, f64)>], from_zero: bool) -> (f64, f64, f64, Vec<f64>) {
    let mut all: Vec<f64> = per_group.iter().flatten().map(|(_, v)| *v).collect();
    all.sort_by(f64::total_cmp);
    let mut abs: Vec<f64> = all.iter().map(|v| v.abs()).collect();
    abs.sort_by(f64::total_cmp);
    let limit = (2.5 * quantile(&abs, 0.95)).max(5.0);
    let (mut lo, mut hi) = all
        .iter()
        .map(|v| v.clamp(-limit, limit))
        .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    if all.is_empty() {
        (lo, hi) = (0.0, 1.0);
    }
    if from_zero {
        lo = 0.0;
    }
    (lo, hi, limit, all)
}

/// One group's row of an error panel at `y`: a box over the quartiles with the median, whiskers
/// from the 5th to the 95th percentile, a dot per value (jittered by seed index) and a triangle
/// at the axis's edge for a value beyond `limit`.
fn draw_box<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    y: f64,
    col: RGBColor,
    vals: &[(u64, f64)],
    limit: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let mut sorted: Vec<f64> = vals.iter().map(|(_, v)| *v).collect();
    sorted.sort_by(f64::total_cmp);
    if sorted.is_empty() {
        return Ok(());
    }
    let q = |p| quantile(&sorted, p);
    let (p5, q1, q2, q3, p95) = (q(0.05), q(0.25), q(0.5), q(0.75), q(0.95));
    if sorted.len() < MIN_BOX_VALUES {
        // Too few for quartiles: the values themselves and their median.
        chart.draw_series([PathElement::new(
            vec![(q2, y - 0.28), (q2, y + 0.28)],
            col.stroke_width(3),
        )])?;
    } else {
        draw_quartiles(chart, y, col, (p5, q1, q2, q3, p95))?;
    }
    dots(chart, y, col, vals, limit)
}

/// An axis number with the decimals it needs (up to 2), and never "-0".
fn axis_number(v: f64) -> String {
    let s = format!("{v:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// Fewer values than this in a group are drawn as dots and a median, without a box.
const MIN_BOX_VALUES: usize = 5;

/// The box (quartiles, median) and whiskers (5th to 95th percentile) of one group's row.
fn draw_quartiles<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    y: f64,
    col: RGBColor,
    (p5, q1, q2, q3, p95): (f64, f64, f64, f64, f64),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    chart.draw_series([
        PathElement::new(vec![(p5, y), (q1, y)], col.stroke_width(1)),
        PathElement::new(vec![(q3, y), (p95, y)], col.stroke_width(1)),
        PathElement::new(vec![(p5, y - 0.1), (p5, y + 0.1)], col.stroke_width(1)),
        PathElement::new(vec![(p95, y - 0.1), (p95, y + 0.1)], col.stroke_width(1)),
    ])?;
    chart.draw_series([Rectangle::new(
        [(q1, y - 0.28), (q3, y + 0.28)],
        col.mix(0.18).filled(),
    )])?;
    chart.draw_series([
        Rectangle::new([(q1, y - 0.28), (q3, y + 0.28)], col.stroke_width(1)),
        Rectangle::new([(q2, y - 0.28), (q2, y + 0.28)], col.stroke_width(3)),
    ])?;
    Ok(())
}

/// A dot per value of one group's row (jittered by seed index), a triangle at the axis's edge
/// for a value beyond `limit`.
fn dots<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    y: f64,
    col: RGBColor,
    vals: &[(u64, f64)],
    limit: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    // Dots jittered by seed index (deterministic), inside the box's height; values beyond the
    // axis as triangles at its edge.
    let jitter = |s: u64| ((s.wrapping_mul(2_654_435_761) % 1000) as f64 / 1000.0 - 0.5) * 0.4;
    chart.draw_series(
        vals.iter()
            .filter(|(_, v)| v.abs() <= limit)
            .map(|(s, v)| Circle::new((*v, y + jitter(*s)), 3, col.mix(0.7).filled())),
    )?;
    chart.draw_series(vals.iter().filter(|(_, v)| v.abs() > limit).map(|(s, v)| {
        let x = v.clamp(-limit, limit);
        let tip = if *v > 0.0 { 7 } else { -7 };
        EmptyElement::at((x, y + jitter(*s)))
            + Polygon::new(vec![(0, -5), (0, 5), (tip, 0)], col.filled())
    }))?;
    Ok(())
}

/// `trajectories.svg`: each group's example run (seed index 0) on a small map, with a team's
/// other members' tracks (for formation runs: the team from each start offset, as in the
/// formation paper's Fig. 4).
pub fn trajectory_chart(c: &Campaign, examples: &[ExampleRun]) -> Result<String, CampaignError> {
    let e = err("trajectories.svg");
    let shown = &examples[..examples.len().min(12)];
    let cols = shown.len().clamp(1, 3);
    let rows = shown.len().div_ceil(cols).max(1);
    // Each panel its own extent (its op-area, sources, tracks and declarations), at one scale
    // in x and y: a campaign over several scenarios keeps every panel's runs readable.
    let extents: Vec<[f64; 4]> = shown.iter().map(panel_extent).collect();
    let panel_w = 430u32;
    let plot_w = f64::from(panel_w) - 97.0;
    let tallest = extents
        .iter()
        .map(|b| (b[3] - b[2]) / (b[1] - b[0]))
        .fold(0.0, f64::max);
    let panel_h = (plot_w * tallest + 110.0).clamp(260.0, 900.0) as u32;
    let plot_h = f64::from(panel_h) - 110.0;
    let (width, height) = (panel_w * cols as u32, panel_h * rows as u32 + TITLE_PX);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(&e)?;
        let (title, body) = root.split_vertically(TITLE_PX);
        let more = if examples.len() > shown.len() {
            format!(" (first {} of {} groups)", shown.len(), examples.len())
        } else {
            String::new()
        };
        title
            .draw(&Text::new(
                format!(
                    "{}: one example run per group (seed index 0){more}",
                    c.file.name
                ),
                (12, 12),
                ("sans-serif", 15).into_font().color(&BLACK),
            ))
            .map_err(&e)?;
        trajectory_key(&title, shown).map_err(&e)?;
        let panels = body.split_evenly((rows, cols));
        for (k, (ex, area)) in shown.iter().zip(panels.iter()).enumerate() {
            let mut name = ex.config.clone();
            if !ex.point.is_empty() {
                name = format!("{name} · {}", ex.point.replace(';', ", "));
            }
            if c.scenarios.len() > 1 {
                name = format!("{} · {name}", ex.scenario);
            }
            let result = match ex.error_m {
                Some(d) => format!("{}, {d:.1} m", ex.outcome.name()),
                None => ex.outcome.name().to_string(),
            };
            let radius = c
                .scenarios
                .iter()
                .position(|s| s.label == ex.scenario)
                .zip(c.configs.iter().position(|k| k.name == ex.config))
                .zip(c.points.iter().position(|p| p.label() == ex.point))
                .map(|((s, k), p)| c.located_radius_m(s, k, p));
            let failed = !example_located(ex, radius);
            let title = if failed {
                format!("FAILED · {name}: {result}")
            } else {
                format!("{name}: {result}")
            };
            let (x, y) = fit_panel(extents[k], plot_w, plot_h);
            if failed {
                // A failed run's panel is framed in red, as well as named so.
                area.draw(&Rectangle::new(
                    [(1, 1), (panel_w as i32 - 2, panel_h as i32 - 2)],
                    RGBColor(210, 0, 0).stroke_width(3),
                ))
                .map_err(&e)?;
            }
            let mut chart = map_chart(area, &title, x, y).map_err(|m| CampaignError::Chart {
                what: "trajectories.svg".into(),
                message: m.to_string(),
            })?;
            let poly = |pts: &[[f64; 2]]| -> Vec<Vec2> {
                pts.iter().map(|p| Vec2::new(p[0], p[1])).collect()
            };
            let at = (chart.x_range().start, chart.y_range().start);
            let mut series = |name: &str,
                              draw: &dyn Fn(&mut TrajectoryPanel<'_, '_>) -> Result<(), _>|
             -> Result<(), CampaignError> {
                marks::open(chart.plotting_area(), at, Group::Series, name).map_err(&e)?;
                draw(&mut chart).map_err(&e)?;
                marks::close(chart.plotting_area(), at).map_err(&e)
            };
            series(KEY_OP_AREA, &|ch| {
                ch.draw_series(dashed(&poly(&ex.op_area), BLACK, 1))
                    .map(|_| ())
            })?;
            for r in &ex.subregions {
                series(KEY_SUBREGION, &|ch| {
                    ch.draw_series(dashed(&poly(r), SUBREGION, 1)).map(|_| ())
                })?;
            }
            for other in &ex.others {
                series(KEY_OTHERS, &|ch| {
                    ch.draw_series([PathElement::new(
                        other.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>(),
                        OTHERS.stroke_width(1),
                    )])
                    .map(|_| ())
                })?;
            }
            series(KEY_TRACK, &|ch| {
                ch.draw_series([PathElement::new(
                    ex.track.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>(),
                    TRACK.stroke_width(1),
                )])
                .map(|_| ())
            })?;
            series(KEY_LOST, &|ch| {
                ch.draw_series(
                    ex.lost_points
                        .iter()
                        .map(|p| Circle::new((p[0], p[1]), 4, LOST.stroke_width(1))),
                )
                .map(|_| ())
            })?;
            series(KEY_SOURCE, &|ch| {
                ch.draw_series(
                    ex.sources
                        .iter()
                        .map(|p| TriangleMarker::new((p[0], p[1]), 7, SOURCE.filled())),
                )
                .map(|_| ())
            })?;
            series(KEY_DECLARED, &|ch| {
                ch.draw_series(
                    ex.declared
                        .iter()
                        .map(|p| Circle::new((p[0], p[1]), 5, BLACK.filled())),
                )
                .map(|_| ())
            })?;
        }
        root.present().map_err(&e)?;
    }
    Ok(marks::finish(&svg))
}

/// The trajectory chart's title band, px: the title and a row of keys.
const TITLE_PX: u32 = 64;
/// The trajectory chart's colours: the track as logged, a team's other members (true), lost
/// points, true sources, subregions.
const TRACK: RGBColor = RGBColor(20, 60, 160);
const OTHERS: RGBColor = RGBColor(60, 150, 80);
const LOST: RGBColor = RGBColor(230, 120, 0);
const SOURCE: RGBColor = RGBColor(0, 140, 60);
const SUBREGION: RGBColor = RGBColor(150, 150, 150);
/// The trajectory chart's key entries.
const KEY_TRACK: &str = "track as logged";
const KEY_OTHERS: &str = "a team's other members (true track)";
const KEY_OP_AREA: &str = "op-area";
const KEY_SUBREGION: &str = "subregion";
const KEY_LOST: &str = "lost point";
const KEY_DECLARED: &str = "declared source";
const KEY_SOURCE: &str = "true source";

/// A panel of the trajectory chart.
type TrajectoryPanel<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The trajectory chart's key, in a row under its title: a swatch (the mark as the panels draw
/// it) and a label for each kind of mark drawn in any of `shown`.
fn trajectory_key<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    shown: &[ExampleRun],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let any = |f: &dyn Fn(&ExampleRun) -> bool| shown.iter().any(f);
    let line = |c: RGBColor| PathElement::new(vec![(0, 0), (16, 0)], c.stroke_width(1));
    let dash = |c: RGBColor| {
        EmptyElement::at((0, 0))
            + PathElement::new(vec![(0, 0), (6, 0)], c.stroke_width(1))
            + PathElement::new(vec![(10, 0), (16, 0)], c.stroke_width(1))
    };
    let style = ("sans-serif", 14)
        .into_font()
        .color(&BLACK)
        .pos(text_anchor::Pos::new(
            text_anchor::HPos::Left,
            text_anchor::VPos::Center,
        ));
    let mut x = 14;
    let y = 46;
    let mut entry =
        |name: &str,
         swatch: &dyn Fn((i32, i32)) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>|
         -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
            marks::open(area, (x, y), Group::Legend, name)?;
            swatch((x, y))?;
            area.draw(&Text::new(name.to_string(), (x + 24, y), style.clone()))?;
            marks::close(area, (x, y))?;
            x += 24 + (name.chars().count() as f64 * 14.0 * 0.5).round() as i32 + 22;
            Ok(())
        };
    entry(KEY_TRACK, &|p| {
        area.draw(&(EmptyElement::at(p) + line(TRACK)))
    })?;
    if any(&|e| !e.others.is_empty()) {
        entry(KEY_OTHERS, &|p| {
            area.draw(&(EmptyElement::at(p) + line(OTHERS)))
        })?;
    }
    entry(KEY_OP_AREA, &|p| {
        area.draw(&(EmptyElement::at(p) + dash(BLACK)))
    })?;
    if any(&|e| !e.subregions.is_empty()) {
        entry(KEY_SUBREGION, &|p| {
            area.draw(&(EmptyElement::at(p) + dash(SUBREGION)))
        })?;
    }
    if any(&|e| !e.lost_points.is_empty()) {
        entry(KEY_LOST, &|p| {
            area.draw(&(EmptyElement::at(p) + Circle::new((8, 0), 4, LOST.stroke_width(1))))
        })?;
    }
    if any(&|e| !e.declared.is_empty()) {
        entry(KEY_DECLARED, &|p| {
            area.draw(&(EmptyElement::at(p) + Circle::new((8, 0), 5, BLACK.filled())))
        })?;
    }
    if any(&|e| !e.sources.is_empty()) {
        entry(KEY_SOURCE, &|p| {
            area.draw(&(EmptyElement::at(p) + TriangleMarker::new((8, 0), 5, SOURCE.filled())))
        })?;
    }
    Ok(())
}

/// Whether an example run located its source: it declared, within `radius` (m) when it is
/// known.
fn example_located(ex: &ExampleRun, radius: Option<f64>) -> bool {
    ex.outcome == plumetrace_mission::Outcome::Declared
        && match (ex.error_m, radius) {
            (Some(d), Some(r)) => d <= r,
            _ => true,
        }
}

/// A panel's extent: west, east, south, north over its op-area, sources, tracks, declarations
/// and lost points, with a margin of 4 % of its larger side (at least 1 m).
fn panel_extent(ex: &ExampleRun) -> [f64; 4] {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    let points = ex
        .op_area
        .iter()
        .chain(&ex.sources)
        .chain(&ex.track)
        .chain(&ex.declared)
        .chain(&ex.lost_points)
        .chain(ex.others.iter().flatten())
        .filter(|p| p[0].is_finite() && p[1].is_finite());
    for p in points {
        (x0, x1, y0, y1) = (x0.min(p[0]), x1.max(p[0]), y0.min(p[1]), y1.max(p[1]));
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let pad = (0.04 * (x1 - x0).max(y1 - y0)).max(1.0);
    [x0 - pad, x1 + pad, y0 - pad, y1 + pad]
}

/// The ranges that show extent `b` at one scale in x and y on a plotting area of `w` x `h` px
/// (the shorter side widened about its middle).
fn fit_panel(b: [f64; 4], w: f64, h: f64) -> (std::ops::Range<f64>, std::ops::Range<f64>) {
    let m = ((b[1] - b[0]) / w).max((b[3] - b[2]) / h);
    let (cx, cy) = ((b[0] + b[1]) / 2.0, (b[2] + b[3]) / 2.0);
    (
        cx - m * w / 2.0..cx + m * w / 2.0,
        cy - m * h / 2.0..cy + m * h / 2.0,
    )
}

/// Writes the three charts into `out`.
pub fn write_charts(
    c: &Campaign,
    out: &Path,
    groups: &[GroupSummary],
    rows: &[(RunKey, RunRow)],
) -> Result<(), CampaignError> {
    let write = |name: &str, svg: String| {
        let p = out.join(name);
        plumetrace_mission::output::write_atomic(&p, svg.as_bytes())
            .map_err(|e| CampaignError::io(&p, e))
    };
    write("success.svg", success_chart(c, groups)?)?;
    write("errors.svg", error_chart(c, groups, rows)?)?;
    let examples: Vec<ExampleRun> = groups
        .iter()
        .filter_map(|g| ExampleRun::read(out, &g.scenario, &g.config, &g.point))
        .collect();
    write("trajectories.svg", trajectory_chart(c, &examples)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::summarise;
    use crate::stats::tests::multi_source_fixture;

    #[test]
    fn multi_source_charts_show_each_source_and_every_source_success() {
        let (c, rows) = multi_source_fixture();
        let groups = summarise(&c, &rows);
        let errors = error_chart(&c, &groups, &rows).unwrap();
        assert!(errors.contains("nearest declaration to each source"));
        assert!(
            !errors.contains("along-flow error"),
            "no first-declaration panels"
        );
        let success = success_chart(&c, &groups).unwrap();
        assert!(success.contains("fraction of runs locating every source"));
    }

    /// An example run over a square op-area `side` metres wide, its track along the diagonal.
    fn example(
        side: f64,
        outcome: plumetrace_mission::Outcome,
        error_m: Option<f64>,
    ) -> ExampleRun {
        ExampleRun {
            scenario: "duck-2003-mt".into(),
            config: "default".into(),
            point: String::new(),
            seed: 1,
            outcome,
            error_m,
            op_area: vec![[0.0, 0.0], [side, 0.0], [side, side], [0.0, side]],
            subregions: Vec::new(),
            sources: vec![[0.1 * side, 0.5 * side]],
            declared: Vec::new(),
            lost_points: Vec::new(),
            track: (0..10).map(|k| [f64::from(k) * side / 10.0; 2]).collect(),
            others: Vec::new(),
        }
    }

    #[test]
    fn each_trajectory_panel_fits_its_own_runs_and_failed_runs_are_marked() {
        use plumetrace_mission::Outcome;
        let (c, _) = multi_source_fixture();
        let small = example(100.0, Outcome::Declared, Some(2.0));
        let big = example(1200.0, Outcome::TimedOut, None);
        let svg = trajectory_chart(&c, &[small, big]).unwrap();
        let rows = plumetrace_report::inspect::tick_rows(&svg);
        let top = |r: &Vec<String>| {
            r.iter()
                .filter_map(|v| v.parse::<f64>().ok())
                .fold(f64::MIN, f64::max)
        };
        // The first panel's East axis ends near its 100 m op-area, the second's near 1200 m.
        let east: Vec<f64> = rows.iter().step_by(2).map(top).collect();
        assert!(east[0] <= 150.0, "{rows:?}");
        assert!(east[1] >= 1000.0, "{rows:?}");
        assert_eq!(svg.matches("FAILED").count(), 1, "the timed-out run only");
        assert!(plumetrace_report::inspect::bad_tick_rows(&svg).is_empty());
    }

    #[test]
    fn every_series_of_the_charts_has_a_legend_entry_whose_swatch_is_its_mark() {
        use plumetrace_mission::Outcome;
        use plumetrace_report::inspect::{legend_faults, marked_groups, series_without_legend};
        let (c, rows) = multi_source_fixture();
        let groups = summarise(&c, &rows);
        let mut team = example(100.0, Outcome::Declared, Some(2.0));
        team.lost_points = vec![[20.0, 30.0], [40.0, 50.0]];
        team.declared = vec![[12.0, 50.0]];
        team.others = vec![vec![[5.0, 5.0], [50.0, 60.0]]];
        team.subregions = vec![vec![[10.0, 10.0], [30.0, 10.0], [30.0, 30.0]]];
        let charts = [
            ("success", success_chart(&c, &groups).unwrap()),
            ("errors", error_chart(&c, &groups, &rows).unwrap()),
            ("trajectories", trajectory_chart(&c, &[team]).unwrap()),
        ];
        for (name, svg) in &charts {
            let series = marked_groups(svg)
                .into_iter()
                .filter(|g| g.kind == "series" && !g.marks.is_empty())
                .count();
            // (The fixture's runs declare nothing: its error panel has no marks.)
            assert!(series > 0 || *name == "errors", "{name}: no series marked");
            assert_eq!(legend_faults(svg), Vec::<String>::new(), "{name}");
        }
        // Every kind of mark of the trajectory panels is keyed (once only in the title's words).
        let traj = &charts[2].1;
        for key in [
            KEY_TRACK,
            KEY_OTHERS,
            KEY_OP_AREA,
            KEY_SUBREGION,
            KEY_LOST,
            KEY_DECLARED,
            KEY_SOURCE,
        ] {
            assert!(
                marked_groups(traj)
                    .iter()
                    .any(|g| g.kind == "series" && g.name == key && !g.marks.is_empty()),
                "{key} drawn"
            );
        }
        let unkeyed = traj.replace("data-legend=\"lost point\"", "data-legend=\"\"");
        assert_eq!(series_without_legend(&unkeyed), ["lost point"]);
    }

    #[test]
    fn a_group_of_few_runs_has_dots_and_a_median_but_no_box() {
        let draw = |n: u64| {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, (300, 100)).into_drawing_area();
                let mut chart = ChartBuilder::on(&root)
                    .build_cartesian_2d(0.0..10.0, -1.0..1.0)
                    .unwrap();
                let vals: Vec<(u64, f64)> = (0..n).map(|k| (k, 1.0 + k as f64)).collect();
                draw_box(&mut chart, 0.0, PALETTE[0], &vals, 100.0).unwrap();
                root.present().unwrap();
            }
            svg
        };
        let boxed = |svg: &str| svg.contains("fill-opacity") || svg.contains("opacity=\"0.18\"");
        assert!(!boxed(&draw(3)), "{}", draw(3));
        assert!(boxed(&draw(6)), "{}", draw(6));
        assert_eq!(draw(3).matches("<circle").count(), 3);
        assert!(draw(3).contains("stroke-width=\"3\""), "the median");
        assert_eq!(
            [-0.0, 0.2, -0.4, 1.0].map(axis_number),
            ["0", "0.2", "-0.4", "1"]
        );
    }
}
