//! The plume figure of a plume-only run: the instantaneous and the time-averaged concentration
//! as two stacked heat maps, with the sources, obstacles and mean flow.

use crate::chart::map_chart;
use crate::error::ReportError;
use crate::marks::{self, Group};
use plotters::prelude::*;
use plumetrace_env::{FlowField, GridSpec, Plume};
use plumetrace_scenario::BuiltScenario;

fn plume_err<E: std::fmt::Debug>(e: E) -> ReportError {
    ReportError::PlumeFigure(format!("{e:?}"))
}

/// Colour stops of the light heat map, from the lowest shown value to the highest.
const STOPS: [(f64, (u8, u8, u8)); 5] = [
    (0.0, (255, 247, 236)),
    (0.3, (253, 212, 158)),
    (0.55, (252, 141, 89)),
    (0.8, (215, 48, 31)),
    (1.0, (127, 0, 0)),
];

/// Concentrations below this fraction of the panel's maximum are left white.
const FLOOR: f64 = 1e-3;

fn heat(level: f64) -> RGBColor {
    let l = level.clamp(0.0, 1.0);
    for w in STOPS.windows(2) {
        let ((a, ca), (b, cb)) = (w[0], w[1]);
        if l <= b {
            let t = (l - a) / (b - a);
            let mix =
                |p: u8, q: u8| (f64::from(p) + t * (f64::from(q) - f64::from(p))).round() as u8;
            return RGBColor(mix(ca.0, cb.0), mix(ca.1, cb.1), mix(ca.2, cb.2));
        }
    }
    RGBColor(127, 0, 0)
}

/// Level in [0, 1] of a concentration on a square-root scale (it shows both the patchy peaks and
/// the dilute edges); `None` below `FLOOR` of the maximum.
fn level(c: f64, max: f64) -> Option<f64> {
    if max <= 0.0 || c < FLOOR * max {
        return None;
    }
    Some((c / max).sqrt())
}

/// The plume's concentration unit: the release rate's mass unit per cubic metre (a source
/// releases mass units a second).
pub const CONCENTRATION_UNIT: &str = "mass units/m³";

/// Two stacked heat maps (instantaneous and time-averaged concentration) with the source,
/// obstacles and mean flow, as an SVG string.
pub fn plume_figure(
    sc: &BuiltScenario,
    snapshot: &[f64],
    mean: &[f64],
    samples: u32,
) -> Result<String, ReportError> {
    let g = sc.output.grid;
    let d = sc.env.domain();
    let width = 1000u32;
    let panel_w = f64::from(width - 140);
    let panel_h = (panel_w * d.height_m() / d.width_m()).clamp(160.0, 700.0);
    let height = (2.0 * (panel_h + 90.0)) as u32;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(plume_err)?;
        let (top, bottom) = root.split_vertically(height / 2);
        let t = sc.env.time_s();
        let steady = matches!(sc.env.plume(), Plume::Steady(_));
        let top_title = if steady {
            format!(
                "{}: steady concentration ({CONCENTRATION_UNIT}) at z = {} m",
                sc.name, g.z_m
            )
        } else {
            format!(
                "{}: concentration ({CONCENTRATION_UNIT}) at z = {} m, t = {:.0} s",
                sc.name, g.z_m, t
            )
        };
        let bottom_title =
            format!("time-averaged concentration ({CONCENTRATION_UNIT}; {samples} samples)");
        panel(&top, sc, &g, snapshot, &top_title)?;
        panel(&bottom, sc, &g, mean, &bottom_title)?;
        root.present().map_err(plume_err)?;
    }
    Ok(marks::finish(&svg))
}

/// The colour key's entries: a fraction of the panel's maximum and its name.
const KEY: [(f64, &str); 4] = [(0.01, "1 %"), (0.1, "10 %"), (0.5, "50 %"), (1.0, "100 %")];

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    sc: &BuiltScenario,
    g: &GridSpec,
    values: &[f64],
    title: &str,
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    let err = plume_err::<DrawingAreaErrorKind<DB::ErrorType>>;
    let d = sc.env.domain();
    let mut chart = map_chart(area, title, d.x_min_m..d.x_max_m, d.y_min_m..d.y_max_m)?;
    let max = values.iter().copied().fold(0.0, f64::max);
    // At most ~250 x 250 cells are drawn: coarser grids are subsampled.
    let stride_x = g.nx.div_ceil(250).max(1);
    let stride_y = g.ny.div_ceil(250).max(1);
    let dx = (g.x_max_m - g.x_min_m) / (g.nx - 1) as f64 * stride_x as f64;
    let dy = (g.y_max_m - g.y_min_m) / (g.ny - 1) as f64 * stride_y as f64;
    // The cells by the colour key's entry they are nearest (at or above it).
    let mut cells: [Vec<Rectangle<(f64, f64)>>; 4] = Default::default();
    for j in (0..g.ny).step_by(stride_y) {
        for i in (0..g.nx).step_by(stride_x) {
            let v = values[j * g.nx + i];
            if let Some(l) = level(v, max) {
                let x = g.x_min_m + i as f64 * (g.x_max_m - g.x_min_m) / (g.nx - 1) as f64;
                let y = g.y_min_m + j as f64 * (g.y_max_m - g.y_min_m) / (g.ny - 1) as f64;
                let band = KEY.iter().rposition(|k| v >= k.0 * max).unwrap_or(0);
                cells[band].push(Rectangle::new(
                    [(x - dx / 2.0, y - dy / 2.0), (x + dx / 2.0, y + dy / 2.0)],
                    heat(l).filled(),
                ));
            }
        }
    }
    let at = (d.x_min_m, d.y_min_m);
    let key_label = move |name: &str| format!("{name} of max {max:.3} {CONCENTRATION_UNIT}");
    for (band, (_, name)) in cells.into_iter().zip(KEY) {
        if !band.is_empty() {
            marks::open(chart.plotting_area(), at, Group::Ramp, &key_label(name)).map_err(err)?;
            chart.draw_series(band).map_err(err)?;
            marks::close(chart.plotting_area(), at).map_err(err)?;
        }
    }
    let obstacles = sc.env.obstacles();
    if !obstacles.is_empty() {
        marks::open(chart.plotting_area(), at, Group::Series, "obstacle").map_err(err)?;
    }
    for o in obstacles.iter() {
        let pts: Vec<(f64, f64)> = o
            .polygon
            .exterior()
            .points()
            .map(|p| (p.x(), p.y()))
            .collect();
        chart
            .draw_series(std::iter::once(PathElement::new(
                pts,
                GREEN.stroke_width(2),
            )))
            .map_err(err)?;
    }
    if !obstacles.is_empty() {
        marks::close(chart.plotting_area(), at).map_err(err)?;
        // A key entry drawn by an empty series.
        chart
            .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
            .map_err(err)?
            .label("obstacle")
            .legend(|p| {
                EmptyElement::at(p)
                    + marks::open_text(Group::Legend, "obstacle")
                    + PathElement::new(vec![(0, 0), (16, 0)], GREEN.stroke_width(2))
                    + marks::close_text()
            });
    }
    if let Some(f) = sc.env.plume().filaments() {
        marks::open(chart.plotting_area(), at, Group::Series, "source").map_err(err)?;
        chart
            .draw_series(
                f.sources()
                    .iter()
                    .map(|s| TriangleMarker::new((s.pos_m.x, s.pos_m.y), 7, BLACK.filled())),
            )
            .map_err(err)?
            .label("source")
            .legend(|p| {
                EmptyElement::at(p)
                    + marks::open_text(Group::Legend, "source")
                    + TriangleMarker::new((8, 0), 5, BLACK.filled())
                    + marks::close_text()
            });
        marks::close(chart.plotting_area(), at).map_err(err)?;
    }
    // Mean flow arrow in the upper-left corner, 10 % of the width long.
    let v = sc.env.flow().velocity(plumetrace_core::Vec2::new(
        0.5 * (d.x_min_m + d.x_max_m),
        0.5 * (d.y_min_m + d.y_max_m),
    ));
    if v.norm() > 0.0 {
        let len = 0.1 * d.width_m();
        let start = (
            d.x_min_m + 0.06 * d.width_m(),
            d.y_max_m - 0.15 * d.height_m(),
        );
        let u = v / v.norm() * len;
        let end = (start.0 + u.x, start.1 + u.y);
        // An arrow: the shaft and a head of two strokes a quarter of its length.
        let head = |turn: f64| {
            let (s, c) = turn.sin_cos();
            let b = -u * 0.25;
            (end.0 + b.x * c - b.y * s, end.1 + b.x * s + b.y * c)
        };
        let name = format!("mean flow {:.2} m/s", v.norm());
        marks::open(chart.plotting_area(), at, Group::Series, &name).map_err(err)?;
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![start, end, head(0.45), end, head(-0.45)],
                BLUE.stroke_width(2),
            )))
            .map_err(err)?
            .label(name.clone())
            .legend(move |p| {
                EmptyElement::at(p)
                    + marks::open_text(Group::Legend, &name)
                    + PathElement::new(
                        vec![(0, 0), (16, 0), (11, -4), (16, 0), (11, 4)],
                        BLUE.stroke_width(2),
                    )
                    + marks::close_text()
            });
        marks::close(chart.plotting_area(), at).map_err(err)?;
    }
    // Colour key: swatches at 1 %, 10 %, 50 % and 100 % of the maximum.
    if max > 0.0 {
        for (frac, name) in KEY {
            let c = heat(level(frac * max, max).unwrap_or(0.0));
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(d.x_min_m, d.y_min_m), (d.x_min_m, d.y_min_m)],
                    c.filled(),
                )))
                .map_err(err)?
                .label(key_label(name))
                .legend(move |p| {
                    EmptyElement::at(p)
                        + marks::open_text(Group::Legend, &key_label(name))
                        + Rectangle::new([(0, -5), (14, 5)], c.filled())
                        + marks::close_text()
                });
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 12))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;
    use plumetrace_scenario::{Origin, build, load_preset};

    #[test]
    fn the_plume_figure_names_the_concentrations_unit_and_draws_the_flow_as_an_arrow() {
        let cfg = load_preset("plume-demo").unwrap();
        let sc = build(&cfg, &Origin::Preset("plume-demo".into()), Some(1)).unwrap();
        let g = sc.output.grid;
        let field: Vec<f64> = (0..g.nx * g.ny).map(|k| (k % 7) as f64).collect();
        let svg = plume_figure(&sc, &field, &field, 3).unwrap();
        assert!(svg.contains(&format!("of max 6.000 {CONCENTRATION_UNIT}")));
        assert!(svg.contains(&format!(
            "time-averaged concentration ({CONCENTRATION_UNIT}"
        )));
        // The flow: a shaft and a two-stroke head (five points), not a line ending in a dot.
        let arrow = svg
            .split("<polyline")
            .filter(|p| p.contains("stroke=\"#0000FF\""))
            .filter(|p| {
                let pts = p.split("points=\"").nth(1).unwrap_or("");
                pts.split('"')
                    .next()
                    .unwrap_or("")
                    .split_whitespace()
                    .count()
                    == 5
            })
            .count();
        assert!(arrow >= 2, "{arrow} arrows");
        assert!(!svg.contains("<circle"), "no dot at the flow's end");
        assert!(crate::inspect::bad_tick_rows(&svg).is_empty());
    }

    #[test]
    fn every_series_of_the_plume_figure_has_a_legend_entry_the_kelp_too() {
        let cfg = load_preset("li-zhang-kelp").unwrap();
        let sc = build(&cfg, &Origin::Preset("li-zhang-kelp".into()), Some(1)).unwrap();
        let g = sc.output.grid;
        let field: Vec<f64> = (0..g.nx * g.ny).map(|k| (k % 97) as f64).collect();
        let svg = plume_figure(&sc, &field, &field, 3).unwrap();
        let series: Vec<String> = crate::inspect::marked_groups(&svg)
            .into_iter()
            .filter(|g| g.kind == "series")
            .map(|g| g.name)
            .collect();
        assert!(series.iter().any(|s| s == "obstacle"), "{series:?}");
        assert!(
            series.iter().any(|s| s.starts_with("50 % of max")),
            "{series:?}"
        );
        assert_eq!(crate::inspect::legend_faults(&svg), Vec::<String>::new());
        // Without its key entry the kelp is found.
        let unkeyed = svg.replace("data-legend=\"obstacle\"", "data-legend=\"kelp\"");
        assert_eq!(
            crate::inspect::series_without_legend(&unkeyed),
            ["obstacle"]
        );
    }
}
