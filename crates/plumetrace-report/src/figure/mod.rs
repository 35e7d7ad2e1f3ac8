//! The mission figure, drawn from the recorded run (like the field-test figures).
//!
//! The map covers everything that was recorded, with a margin and at one scale in x and y:
//! every vehicle's true and estimated track, the op-area (dashed; subregions dashed grey), true
//! sources (triangles) and declared sources (filled dots), so an excursion that made the cage
//! abort stays in view. On it: the time-averaged plume at the first vehicle's altitude as a
//! light heat map; kelp as filled green patches; each vehicle's estimated track as it logged it,
//! coloured by the behaviour in control (with several vehicles one colour each, each track's
//! start labelled with the vehicle's name) and broken where a position fix moved the estimate
//! (the jump dashed, a long one labelled); the true tracks thin and grey, darker outside the
//! op-area; detections as thin ticks across the track, at most one per [`DETECTION_GAP_S`] per
//! vehicle so that the track stays visible; the time every few minutes along each track; the
//! tracks flown during a sensor fault on a wide yellow underlay; lost points as open circles;
//! obstacle avoidance's virtual paths dotted with their reference targets as diamonds; cage
//! aborts, other aborts and incidents as labelled markers at the vehicle's true position; and a
//! key with the mean flow at the source (arrow, speed, direction) and a round scale bar. The
//! legend lists only what is drawn: in a corner of the map where it hides no track, else below
//! the map.
//!
//! Below, for the vehicles with a planner: the chemical reading against mission time, the
//! behaviour in control as a strip under it (the track's colours), fault windows shaded and
//! vertical lines at declarations, aborts and incidents.
//!
//! The parts: `model` reads what is drawn from the run, `raster` makes the plume's and the source
//! maps' cells, `layout` places everything on the map, `legend` lists what is drawn, `style`
//! holds the colours, sizes and icons; `map`, `posterior` and `panel` draw the map, the
//! source-map panels and the reading panel.

mod layout;
mod legend;
mod map;
mod model;
mod panel;
mod posterior;
mod raster;
pub(crate) mod style;
#[cfg(test)]
mod test_support;

use crate::error::ReportError;
use layout::{MapLayout, map_layout};
use legend::{draw_legend_band, legend_band};
use map::draw_map;
use model::{panel_vehicles, rows_by_vehicle};
use panel::{draw_panel, panel_h_px};
use plotters::prelude::*;
use plumetrace_mission::{MissionRun, TrajectoryRow};
use posterior::{POSTERIOR_PX, draw_posteriors};
use raster::posterior_snapshots;
use std::collections::BTreeMap;
use style::WIDTH_PX;

/// Detection ticks: at most one per this many seconds of each vehicle's mission.
pub const DETECTION_GAP_S: f64 = 2.0;

/// The figure as an SVG string.
pub fn mission_figure(run: &MissionRun, title: &str) -> Result<String, ReportError> {
    let rows = rows_by_vehicle(run);
    let lay = map_layout(run, &rows, title)?;
    draw_figure(run, &rows, &lay, title)
}

/// The figure of `run` laid out as `lay`.
fn draw_figure(
    run: &MissionRun,
    rows: &BTreeMap<u32, Vec<&TrajectoryRow>>,
    lay: &MapLayout,
    title: &str,
) -> Result<String, ReportError> {
    let panel = panel_vehicles(run, rows);
    let (_, _, band_h) = legend_band(lay);
    let snaps = posterior_snapshots(run);
    let snaps_h = if snaps.is_empty() { 0 } else { POSTERIOR_PX };
    let height = lay.map_h_px + band_h + snaps_h + panel_h_px(panel.len());
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH_PX, height)).into_drawing_area();
        root.fill(&WHITE).map_err(ReportError::figure)?;
        let (top, rest) = root.split_vertically(lay.map_h_px);
        let (band, rest) = rest.split_vertically(band_h);
        let (maps, bottom) = rest.split_vertically(snaps_h);
        draw_map(&top, run, lay, title)?;
        draw_legend_band(&band, lay)?;
        if !snaps.is_empty() {
            draw_posteriors(&maps, run, rows, &snaps)?;
        }
        if !panel.is_empty() {
            draw_panel(&bottom, run, rows, lay, &panel)?;
        }
        root.present().map_err(ReportError::figure)?;
    }
    Ok(crate::marks::finish(&svg))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::test_support::{layout, preset_run};
    use super::*;
    use crate::inspect::{legend_faults, series_without_legend};

    #[test]
    fn every_series_of_the_demo_has_a_legend_entry_whose_swatch_is_its_mark() {
        let run = preset_run("demo", 900.0);
        let svg = mission_figure(&run, "demo").unwrap();
        let groups = crate::inspect::marked_groups(&svg);
        for name in [
            "true track",
            "op-area",
            "true source",
            "mean plume at vehicle altitude",
        ] {
            assert!(
                groups.iter().any(|g| g.kind == "series" && g.name == name),
                "{name} is marked"
            );
        }
        assert_eq!(legend_faults(&svg), Vec::<String>::new());
    }

    #[test]
    fn a_formations_leaders_without_a_legend_entry_are_found() {
        let run = preset_run("soares-freshwater", 300.0);
        let rows = rows_by_vehicle(&run);
        let lay = layout(&run);
        let svg = draw_figure(&run, &rows, &lay, "formation").unwrap();
        assert_eq!(legend_faults(&svg), Vec::<String>::new());
        // Each vehicle's reading line is keyed by its strip's swatch.
        let groups = crate::inspect::marked_groups(&svg);
        for v in &run.vehicles {
            assert!(
                groups
                    .iter()
                    .any(|g| g.kind == "legend" && g.name == v.name),
                "{}",
                v.name
            );
        }
        // The legend as it once was: the first vehicle's track only.
        let tracks: Vec<String> = lay
            .legend
            .iter()
            .map(|e| e.label.clone())
            .filter(|l| l.ends_with("estimated track"))
            .collect();
        assert!(tracks.len() > 1, "{tracks:?}");
        let mut old = lay.clone();
        old.legend.retain(|e| !tracks[1..].contains(&e.label));
        let svg = draw_figure(&run, &rows, &old, "formation").unwrap();
        let missing = series_without_legend(&svg);
        assert_eq!(missing, tracks[1..].to_vec());
    }
}
