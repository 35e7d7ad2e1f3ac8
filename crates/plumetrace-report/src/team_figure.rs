//! The team figure of a mission with two or more planners (like Fig. 5-7 of the formation
//! paper): against mission time, every member's filtered reading as its planner reported it
//! (telemetry), every vehicle's speed and heading (true, from the trajectory), and the
//! cross-flow scale each member reported with the team centroid's cross-flow distance from the
//! plume's centre line.

use crate::error::ReportError;
use crate::marks::{self, Group};
use plotters::prelude::*;
use plumetrace_core::Telemetry;
use plumetrace_mission::{EventKind, MissionRun};
use std::collections::BTreeMap;

const WIDTH_PX: u32 = 900;
const PANEL_PX: u32 = 210;

fn err<E: std::fmt::Debug>(e: E) -> ReportError {
    ReportError::TeamFigure(format!("{e:?}"))
}

type Series = BTreeMap<u32, Vec<(f64, f64)>>;

/// One panel: a line per entry of `series` (coloured by vehicle), over `t` on the x axis.
fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    y_desc: &str,
    t_max: f64,
    series: &Series,
    names: &[String],
) -> Result<(), ReportError>
where
    DB::ErrorType: 'static,
{
    let values = series.values().flatten().map(|p| p.1);
    let (lo, hi) = values.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    let (lo, hi) = if lo <= hi {
        let pad = ((hi - lo) * 0.05).max(1e-6);
        (lo - pad, hi + pad)
    } else {
        (0.0, 1.0)
    };
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 15))
        .margin(8)
        .margin_right(20)
        .x_label_area_size(30)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t_max.max(1.0), lo..hi)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("time (s)")
        .y_desc(y_desc)
        .label_style(("sans-serif", 12))
        .draw()
        .map_err(err)?;
    for (v, pts) in series {
        // One colour per vehicle in every panel (a panel may leave a vehicle out).
        let colour = Palette99::pick(*v as usize).to_rgba();
        let name = names
            .get(*v as usize)
            .cloned()
            .unwrap_or_else(|| format!("vehicle {v}"));
        let at = (0.0, lo);
        marks::open(chart.plotting_area(), at, Group::Series, &name).map_err(err)?;
        chart
            .draw_series(LineSeries::new(pts.iter().copied(), colour.stroke_width(1)))
            .map_err(err)?
            .label(name.clone())
            .legend(move |p| {
                EmptyElement::at(p)
                    + marks::open_text(Group::Legend, &name)
                    + PathElement::new(vec![(0, 0), (16, 0)], colour.stroke_width(1))
                    + marks::close_text()
            });
        marks::close(chart.plotting_area(), at).map_err(err)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK.mix(0.3))
        .label_font(("sans-serif", 12))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// The team figure, for runs whose summary has a team (two or more planners); `None` otherwise.
pub fn team_figure(run: &MissionRun, title: &str) -> Option<Result<String, ReportError>> {
    let team = run.summary.team.as_ref()?;
    let names: Vec<String> = run
        .summary
        .vehicles
        .iter()
        .map(|v| v.name.clone())
        .collect();
    let mut reading = Series::new();
    for e in &run.events {
        if let EventKind::Telemetry(Telemetry::Formation { reading: c, .. }) = &e.event
            && c.is_finite()
        {
            reading.entry(e.vehicle).or_default().push((e.t_s, *c));
        }
    }
    let (mut speed, mut heading) = (Series::new(), Series::new());
    for r in &run.trajectory {
        // One point a second keeps the file small.
        if (r.t_s * 10.0).round() as i64 % 10 == 0 {
            speed
                .entry(r.vehicle)
                .or_default()
                .push((r.t_s, r.speed_mps));
            heading
                .entry(r.vehicle)
                .or_default()
                .push((r.t_s, r.heading_deg));
        }
    }
    let mut scale = Series::new();
    for (t, v, s) in &team.scale_series {
        scale.entry(*v).or_default().push((*t, *s));
    }
    let cross: Series = [(u32::MAX, team.centroid_cross_series.clone())].into();
    let t_max = run.summary.sim_time_s;
    let mut svg = String::new();
    let out = (|| {
        let root =
            SVGBackend::with_string(&mut svg, (WIDTH_PX, 5 * PANEL_PX + 30)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let (head, body) = root.split_vertically(30);
        head.draw(&Text::new(
            title.to_string(),
            (10, 6),
            ("sans-serif", 17).into_font(),
        ))
        .map_err(err)?;
        let areas = body.split_evenly((5, 1));
        panel(
            &areas[0],
            "filtered reading (planner's)",
            "reading",
            t_max,
            &reading,
            &names,
        )?;
        panel(&areas[1], "speed", "m/s", t_max, &speed, &names)?;
        panel(&areas[2], "heading", "deg", t_max, &heading, &names)?;
        panel(
            &areas[3],
            "cross-flow scale s_cw",
            "s_cw",
            t_max,
            &scale,
            &names,
        )?;
        let cross_names = vec!["centroid".to_string(); 1];
        let cross_named: Series = cross.into_values().map(|v| (0, v)).collect();
        panel(
            &areas[4],
            "team centroid across the flow from the centre line (+ right looking down-flow)",
            "m",
            t_max,
            &cross_named,
            &cross_names,
        )?;
        root.present().map_err(err)
    })();
    Some(out.map(|()| marks::finish(&svg)))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;
    use crate::inspect::{legend_faults, marked_groups, series_without_legend};
    use plumetrace_mission::run_mission;
    use plumetrace_scenario::{Origin, build, load_preset};

    #[test]
    fn every_vehicles_line_in_the_team_figure_has_a_legend_entry() {
        let mut cfg = load_preset("soares-freshwater").unwrap();
        if let Some(m) = cfg.mission.as_mut() {
            m.spinup_s = m.spinup_s.min(600.0);
            m.time_limit_s = 200.0;
        }
        let sc = build(&cfg, &Origin::Preset("soares-freshwater".into()), Some(3)).unwrap();
        let run = run_mission(sc, &mut |_, _| {}).unwrap();
        let svg = team_figure(&run, "team").unwrap().unwrap();
        assert_eq!(legend_faults(&svg), Vec::<String>::new());
        let series: Vec<String> = marked_groups(&svg)
            .into_iter()
            .filter(|g| g.kind == "series" && !g.marks.is_empty())
            .map(|g| g.name)
            .collect();
        for v in run
            .vehicles
            .iter()
            .map(|v| &v.name)
            .chain([&"centroid".to_string()])
        {
            assert!(series.contains(v), "{v}: {series:?}");
        }
        // Each vehicle is drawn in one colour in every panel.
        for v in &run.vehicles {
            let colours: std::collections::BTreeSet<String> = marked_groups(&svg)
                .into_iter()
                .filter(|g| g.kind == "series" && g.name == v.name)
                .flat_map(|g| g.marks.into_iter().map(|m| m.colour))
                .collect();
            assert_eq!(colours.len(), 1, "{}: {colours:?}", v.name);
        }
        // A leader's line with its key entry gone is found.
        let leader = &run.vehicles[1].name;
        let unkeyed = svg.replace(&format!("data-legend=\"{leader}\""), "data-legend=\"\"");
        assert_eq!(series_without_legend(&unkeyed), [leader.as_str()]);
    }
}
