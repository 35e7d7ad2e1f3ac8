//! Measurable properties of a drawn figure, read back from its SVG text: where each label sits
//! (its box estimated from its font size and length), which labels overlap, whether every
//! axis's tick labels are distinct and increasing, and (in [`series`]) whether each drawn series
//! has a legend entry whose swatch is its mark. The figures' tests and the visual check of
//! rendered presets use them; nothing here draws.

pub mod series;

pub use series::{
    MarkedGroup, legend_entries_without_text, legend_faults, marked_groups, series_without_legend,
    swatches_unlike_series,
};

/// One `<text>` element of a figure and the box it covers, px (y down).
#[derive(Debug, Clone, PartialEq)]
pub struct TextBox {
    /// What it says.
    pub text: String,
    /// Its anchor point, px.
    pub at: (f64, f64),
    /// `start`, `middle` or `end`.
    pub anchor: String,
    /// The vertical offset as written (`0.76em`: hangs from `at`; `0.5ex`: centred; `-0.5ex`:
    /// stands on it; empty: the baseline).
    pub dy: String,
    /// The font size, px.
    pub size: f64,
    /// Turned by a quarter.
    pub rotated: bool,
    /// Left, top, right, bottom, px.
    pub rect: (f64, f64, f64, f64),
}

/// The average advance of a sans-serif character, in font sizes (a fair estimate for labels of
/// digits and lower-case words).
const CHAR_EM: f64 = 0.55;

pub(crate) fn attr(tag: &str, name: &str) -> Option<String> {
    let key = format!(" {name}=\"");
    let a = tag.find(&key)? + key.len();
    let b = tag[a..].find('"')? + a;
    Some(tag[a..b].to_string())
}

pub(crate) fn unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// Every non-empty `<text>` element of `svg` with its estimated box.
pub fn text_boxes(svg: &str) -> Vec<TextBox> {
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(a) = rest.find("<text") {
        rest = &rest[a..];
        let Some(close) = rest.find('>') else { break };
        let tag = &rest[..close];
        let Some(end) = rest.find("</text>") else {
            break;
        };
        let text = unescape(rest[close + 1..end].trim());
        rest = &rest[end..];
        let num = |n: &str| attr(tag, n).and_then(|v| v.parse::<f64>().ok());
        let (Some(x), Some(y)) = (num("x"), num("y")) else {
            continue;
        };
        if text.is_empty() {
            continue;
        }
        let size = num("font-size").unwrap_or(12.0);
        let anchor = attr(tag, "text-anchor").unwrap_or_else(|| "start".into());
        let dy = attr(tag, "dy").unwrap_or_default();
        let rotated = attr(tag, "transform").is_some_and(|t| t.starts_with("rotate"));
        let w = text.chars().count() as f64 * CHAR_EM * size;
        let (a0, a1) = match anchor.as_str() {
            "middle" => (-w / 2.0, w / 2.0),
            "end" => (-w, 0.0),
            _ => (0.0, w),
        };
        let (b0, b1) = match dy.as_str() {
            "0.76em" => (0.0, size),
            "0.5ex" => (-0.5 * size, 0.5 * size),
            "-0.5ex" => (-size, 0.0),
            _ => (-0.8 * size, 0.2 * size),
        };
        let rect = if rotated {
            (x + b0, y - a1, x + b1, y - a0)
        } else {
            (x + a0, y + b0, x + a1, y + b1)
        };
        out.push(TextBox {
            text,
            at: (x, y),
            anchor,
            dy,
            size,
            rotated,
            rect,
        });
    }
    out
}

/// Whether two boxes overlap by more than `slack` px each way.
pub fn boxes_overlap(a: (f64, f64, f64, f64), b: (f64, f64, f64, f64), slack: f64) -> bool {
    a.0 + slack < b.2 && b.0 + slack < a.2 && a.1 + slack < b.3 && b.1 + slack < a.3
}

/// The pairs of labels of `svg` whose boxes overlap (by more than 1 px each way).
pub fn overlapping_texts(svg: &str) -> Vec<(String, String)> {
    let boxes = text_boxes(svg);
    let mut out = Vec::new();
    for (i, a) in boxes.iter().enumerate() {
        for b in &boxes[i + 1..] {
            if boxes_overlap(a.rect, b.rect, 1.0) {
                out.push((a.text.clone(), b.text.clone()));
            }
        }
    }
    out
}

/// The small marks of `svg` (circles and polygons at most 20 px across: sources, declared
/// points, lost points, legend icons), as boxes, px.
pub fn mark_boxes(svg: &str) -> Vec<(f64, f64, f64, f64)> {
    let mut out = Vec::new();
    for (open, tag_end) in [("<circle ", "/>"), ("<polygon ", "/>")] {
        let mut rest = svg;
        while let Some(a) = rest.find(open) {
            rest = &rest[a..];
            let Some(e) = rest.find(tag_end) else { break };
            let tag = &rest[..e];
            rest = &rest[e..];
            let num = |n: &str| attr(tag, n).and_then(|v| v.parse::<f64>().ok());
            let rect = if open == "<circle " {
                match (num("cx"), num("cy"), num("r")) {
                    (Some(x), Some(y), Some(r)) => (x - r, y - r, x + r, y + r),
                    _ => continue,
                }
            } else {
                let pts: Vec<(f64, f64)> = attr(tag, "points")
                    .unwrap_or_default()
                    .split_whitespace()
                    .filter_map(|p| p.split_once(','))
                    .filter_map(|(x, y)| Some((x.parse().ok()?, y.parse().ok()?)))
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                pts.iter().fold(
                    (
                        f64::INFINITY,
                        f64::INFINITY,
                        f64::NEG_INFINITY,
                        f64::NEG_INFINITY,
                    ),
                    |b, p| (b.0.min(p.0), b.1.min(p.1), b.2.max(p.0), b.3.max(p.1)),
                )
            };
            if rect.2 - rect.0 <= 20.0 && rect.3 - rect.1 <= 20.0 {
                out.push(rect);
            }
        }
    }
    out
}

/// The labels of `svg` drawn over (or under) a small mark, by more than 1 px each way.
pub fn texts_over_marks(svg: &str) -> Vec<String> {
    let marks = mark_boxes(svg);
    text_boxes(svg)
        .into_iter()
        .filter(|t| marks.iter().any(|&m| boxes_overlap(t.rect, m, 1.0)))
        .map(|t| t.text)
        .collect()
}

/// The segments of every drawn track of `svg`: the lines of each marked series (see
/// [`crate::marks`]) whose name says it is a track, px.
pub fn track_segments(svg: &str) -> Vec<((f64, f64), (f64, f64))> {
    let mut out = Vec::new();
    for part in svg.split("<g class=\"series\"").skip(1) {
        let Some(close) = part.find("</g>") else {
            continue;
        };
        let group = &part[..close];
        let name = attr(&format!(" {}", group.trim_start()), "data-series").unwrap_or_default();
        if !name.contains("track") {
            continue;
        }
        for line in group.split("<polyline").skip(1) {
            let pts: Vec<(f64, f64)> = attr(line, "points")
                .unwrap_or_default()
                .split_whitespace()
                .filter_map(|p| p.split_once(','))
                .filter_map(|(x, y)| Some((x.parse().ok()?, y.parse().ok()?)))
                .collect();
            out.extend(pts.windows(2).map(|w| (w[0], w[1])));
        }
    }
    out
}

/// Whether the segment `a`-`b` passes through the box `r` (left, top, right, bottom).
fn segment_crosses(a: (f64, f64), b: (f64, f64), r: (f64, f64, f64, f64)) -> bool {
    // Liang-Barsky: clip the segment's parameter range to each side of the box.
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - r.0),
        (dx, r.2 - a.0),
        (-dy, a.1 - r.1),
        (dy, r.3 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return false;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    t0 <= t1
}

/// The labels of `svg` that a drawn track passes through (their boxes shrunk by 1 px each way),
/// with the vehicles' names written at their tracks' starts left out.
pub fn texts_over_tracks(svg: &str) -> Vec<String> {
    let tracks = track_segments(svg);
    let starts: Vec<(f64, f64)> = tracks.iter().map(|s| s.0).collect();
    text_boxes(svg)
        .into_iter()
        .filter(|t| {
            !starts
                .iter()
                .any(|p| (p.0 - t.at.0).abs() < 0.5 && (p.1 - t.at.1).abs() < 0.5)
        })
        .filter(|t| {
            let r = (
                t.rect.0 + 1.0,
                t.rect.1 + 1.0,
                t.rect.2 - 1.0,
                t.rect.3 - 1.0,
            );
            tracks.iter().any(|&(a, b)| segment_crosses(a, b, r))
        })
        .map(|t| t.text)
        .collect()
}

/// The figure's axes: each run of numeric tick labels along one line (x axes: centred labels
/// hanging from one y; y axes: right-aligned labels centred on one x) that follow each other in
/// the drawing with no other label between them, in order along the axis (left to right, bottom
/// to top).
pub fn tick_rows(svg: &str) -> Vec<Vec<String>> {
    let mut rows: Vec<Vec<(f64, String)>> = Vec::new();
    let mut last: Option<(bool, i64)> = None;
    for b in text_boxes(svg) {
        let key = match (b.anchor.as_str(), b.dy.as_str(), b.rotated) {
            _ if b.text.trim().parse::<f64>().is_err() => None,
            ("middle", "0.76em", false) => Some((true, b.at.1.round() as i64)),
            ("end", "0.5ex", false) => Some((false, b.at.0.round() as i64)),
            _ => None,
        };
        let Some(k) = key else {
            last = None;
            continue;
        };
        let pos = if k.0 { b.at.0 } else { -b.at.1 };
        if last != key {
            rows.push(Vec::new());
        }
        if let Some(r) = rows.last_mut() {
            r.push((pos, b.text.clone()));
        }
        last = key;
    }
    rows.into_iter()
        .filter(|r| r.len() > 1)
        .map(|mut r| {
            r.sort_by(|a, b| a.0.total_cmp(&b.0));
            r.into_iter().map(|p| p.1).collect()
        })
        .collect()
}

/// The axes of `svg` whose tick labels are not distinct and increasing, each as its labels.
pub fn bad_tick_rows(svg: &str) -> Vec<Vec<String>> {
    tick_rows(svg)
        .into_iter()
        .filter(|r| {
            let v: Vec<f64> = r.iter().filter_map(|s| s.trim().parse().ok()).collect();
            v.windows(2).any(|w| w[1] <= w[0])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_label_a_track_passes_through_is_found() {
        let svg = r##"<svg><g class="series" data-series="true track">
<polyline fill="none" opacity="1" stroke="#878787" stroke-width="1" points="0,50 200,50 "/>
</g>
<g class="series" data-series="op-area">
<polyline fill="none" opacity="1" stroke="#000000" stroke-width="2" points="0,80 200,80 "/>
</g>
<text x="100" y="50" dy="0.5ex" text-anchor="middle" font-size="10">8 min</text>
<text x="100" y="30" dy="0.5ex" text-anchor="middle" font-size="10">6 min</text>
<text x="100" y="80" dy="0.5ex" text-anchor="middle" font-size="10">border</text>
<text x="0" y="50" font-size="10">AUV 1</text>
</svg>"##;
        // The op-area is not a track; a name at its track's start is meant to be there.
        assert_eq!(texts_over_tracks(svg), ["8 min"]);
        assert_eq!(track_segments(svg).len(), 1);
    }

    const SVG: &str = r##"<svg><text x="100" y="50" dy="0.76em" text-anchor="middle" font-size="10">0</text>
<text x="150" y="50" dy="0.76em" text-anchor="middle" font-size="10">
0
</text>
<text x="200" y="50" dy="0.76em" text-anchor="middle" font-size="10">1</text>
<text x="40" y="100" dy="0.5ex" text-anchor="end" font-size="10">10</text>
<text x="40" y="60" dy="0.5ex" text-anchor="end" font-size="10">20</text>
<text x="10" y="10" font-size="12">a long label here</text>
<text x="30" y="12" font-size="12">over it</text>
</svg>"##;

    #[test]
    fn axes_with_repeated_ticks_are_found() {
        let rows = tick_rows(SVG);
        assert_eq!(rows.len(), 2, "{rows:?}");
        assert_eq!(bad_tick_rows(SVG), vec![vec!["0", "0", "1"]]);
    }

    #[test]
    fn overlapping_labels_are_found() {
        assert_eq!(
            overlapping_texts(SVG),
            vec![("a long label here".to_string(), "over it".to_string())]
        );
        assert!(!boxes_overlap(
            (0.0, 0.0, 10.0, 10.0),
            (10.0, 0.0, 20.0, 10.0),
            1.0
        ));
    }
}
