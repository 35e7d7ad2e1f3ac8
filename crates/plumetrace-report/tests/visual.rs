//! The visual check of rendered outputs: every SVG figure under `PLUMETRACE_VISUAL_DIR` (written
//! by `scripts/visual_check.sh`) has no two labels overlapping, no label over a marker or a
//! track, distinct, increasing tick labels on every axis, and a legend entry for each drawn
//! series whose swatch is the series' mark; every replay page's state (read from the browser
//! into `*.state.txt`) names its timeline rows. Ignored: the script runs it with `--ignored`.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_report::inspect::{
    bad_tick_rows, legend_faults, marked_groups, overlapping_texts, texts_over_marks,
    texts_over_tracks,
};
use std::path::{Path, PathBuf};

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files(&p, out);
        } else {
            out.push(p);
        }
    }
}

#[test]
#[ignore = "checks the renders of scripts/visual_check.sh, which runs it with --ignored"]
fn rendered_figures_have_no_overlapping_labels_and_sound_axes() {
    let dir = std::env::var("PLUMETRACE_VISUAL_DIR")
        .expect("PLUMETRACE_VISUAL_DIR names the renders: run scripts/visual_check.sh");
    let mut all = Vec::new();
    files(Path::new(&dir), &mut all);
    all.sort();
    let mut faults = Vec::new();
    let mut svgs = 0;
    for p in &all {
        let name = p.display().to_string();
        if name.ends_with(".svg") {
            svgs += 1;
            let svg = std::fs::read_to_string(p).unwrap();
            for (a, b) in overlapping_texts(&svg) {
                faults.push(format!("{name}: labels overlap: {a:?} and {b:?}"));
            }
            for t in texts_over_marks(&svg) {
                faults.push(format!("{name}: a label over a mark: {t:?}"));
            }
            for t in texts_over_tracks(&svg) {
                faults.push(format!("{name}: a label over a track: {t:?}"));
            }
            for r in bad_tick_rows(&svg) {
                faults.push(format!("{name}: tick labels not increasing: {r:?}"));
            }
            // Each drawn series has a legend entry, and its swatch is the series' mark.
            if !marked_groups(&svg).iter().any(|g| g.kind == "series") {
                faults.push(format!("{name}: no series marked"));
            }
            for f in legend_faults(&svg) {
                faults.push(format!("{name}: {f}"));
            }
        } else if name.ends_with(".state.txt") {
            let state = std::fs::read_to_string(p).unwrap();
            for key in ["data-timeline-rows=", "data-legend="] {
                if !state.contains(key) {
                    faults.push(format!("{name}: no {key}"));
                }
            }
            // Each legend entry's key is the mark it names.
            let legend = state
                .split("data-legend=\"")
                .nth(1)
                .and_then(|r| r.split('"').next())
                .unwrap_or("");
            for entry in legend.split('|').filter(|e| !e.is_empty()) {
                let (kind, label) = entry.split_once(':').unwrap_or(("", entry));
                let want = match label {
                    "true source" => "triangle",
                    "declared source" => "dot",
                    "lost point" => "circle",
                    "reference target" => "diamond",
                    "detection" => "square",
                    "flow" => "arrow",
                    l if l.starts_with("track") => "line",
                    _ => kind,
                };
                if kind != want {
                    faults.push(format!("{name}: legend {label:?} keyed {kind}, not {want}"));
                }
            }
            if state.contains("data-timeline-rows=\"\"") && state.contains("data-events=\"0\"") {
                continue;
            }
            if state.contains("data-timeline-rows=\"\"") {
                faults.push(format!("{name}: the timeline rows have no labels"));
            }
            if state.contains("data-replayed=\"true\"") && !state.contains("data-divergence=\"") {
                faults.push(format!("{name}: a replayed page with no divergence marker"));
            }
        }
    }
    assert!(svgs > 0, "no figures under {dir}");
    assert!(faults.is_empty(), "{}", faults.join("\n"));
}
