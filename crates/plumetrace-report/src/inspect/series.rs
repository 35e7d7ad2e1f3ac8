//! The series and legend entries a figure marks (see [`crate::marks`]), read back from its SVG:
//! which drawn series has no legend entry, which legend entry has no label, and which swatch is
//! not the mark it names (another shape, colour, width, or a solid line for a dashed one).
//!
//! Both legend layouts read alike: plotters' series labels (the label texts, then each swatch
//! in its group) and the figures' own (a group of the swatch and its label).

use super::{attr, unescape};
use std::collections::{BTreeMap, BTreeSet};

/// One drawn mark as a legend swatch would show it: its shape (`line`, `dashed line`, `dot`,
/// `ring`, `triangle`, `diamond`, `patch`), its colour (`#RRGGBB`, with `@opacity` below 1)
/// and its line width, px (empty for filled shapes).
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Mark {
    /// What it is.
    pub shape: String,
    /// Its colour.
    pub colour: String,
    /// Its line width (lines and rings).
    pub width: String,
}

/// A marked group of a figure: a drawn series or a legend entry.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MarkedGroup {
    /// `series` or `legend`.
    pub kind: String,
    /// The name it carries (unescaped).
    pub name: String,
    /// A series whose colour follows a scale: only shapes are compared.
    pub ramp: bool,
    /// Its marks (white and transparent fills, which back labels, left out).
    pub marks: BTreeSet<Mark>,
    /// Its texts.
    pub texts: Vec<String>,
}

/// A line's two ends, px.
type Ends = ((f64, f64), (f64, f64));

/// A 2-point line: colour and width, its ends, px.
type Piece = ((String, String), (f64, f64), (f64, f64));

fn points(tag: &str) -> Vec<(f64, f64)> {
    attr(tag, "points")
        .unwrap_or_default()
        .split_whitespace()
        .filter_map(|p| p.split_once(','))
        .filter_map(|(x, y)| Some((x.parse().ok()?, y.parse().ok()?)))
        .collect()
}

fn colour(tag: &str, key: &str) -> Option<String> {
    let c = attr(tag, key).filter(|c| c != "none")?;
    let o = attr(tag, "opacity")
        .and_then(|o| o.parse::<f64>().ok())
        .unwrap_or(1.0);
    if o <= 0.0 {
        return None;
    }
    Some(if o < 0.999 { format!("{c}@{o:.2}") } else { c })
}

/// The mark an element draws, and its ends when it is a 2-point line.
fn mark_of(tag: &str) -> (Option<Mark>, Option<Piece>) {
    let name = tag[1..].split(' ').next().unwrap_or("");
    let width = || attr(tag, "stroke-width").unwrap_or_else(|| "1".into());
    let filled = |shape: &str| {
        colour(tag, "fill")
            .filter(|c| !c.starts_with("#FFFFFF"))
            .map(|c| Mark {
                shape: shape.into(),
                colour: c,
                width: String::new(),
            })
    };
    match name {
        "polyline" => {
            let Some(c) = colour(tag, "stroke") else {
                return (None, None);
            };
            let pts = points(tag);
            // A line of no length draws nothing.
            if pts.iter().all(|p| *p == pts[0]) {
                return (None, None);
            }
            let piece = (pts.len() == 2).then(|| ((c.clone(), width()), pts[0], pts[1]));
            let m = Mark {
                shape: "line".into(),
                colour: c,
                width: width(),
            };
            (Some(m), piece)
        }
        "circle" => match filled("dot") {
            Some(m) => (Some(m), None),
            None => (
                colour(tag, "stroke").map(|c| Mark {
                    shape: "ring".into(),
                    colour: c,
                    width: width(),
                }),
                None,
            ),
        },
        "polygon" => {
            let pts = points(tag);
            let axis = pts.iter().all(|p| {
                pts.iter()
                    .filter(|q| (q.0 - p.0).abs() < 0.5 || (q.1 - p.1).abs() < 0.5)
                    .count()
                    >= 3
            });
            let shape = match pts.len() {
                3 => "triangle",
                4 if !axis => "diamond",
                _ => "patch",
            };
            (filled(shape), None)
        }
        "rect" => (filled("patch"), None),
        _ => (None, None),
    }
}

/// The line styles of `pieces` drawn broken: most of their successive pieces lie on one line
/// with a gap between them (dashes along an outline, not ticks across a track).
fn broken_styles(pieces: &[Piece]) -> BTreeSet<(String, String)> {
    let mut by_style: BTreeMap<&(String, String), Vec<Ends>> = BTreeMap::new();
    for (s, a, b) in pieces {
        by_style.entry(s).or_default().push((*a, *b));
    }
    let mut out = BTreeSet::new();
    for (style, segs) in by_style {
        let pairs = segs.len().saturating_sub(1);
        let dashes = segs
            .windows(2)
            .filter(|w| {
                let ((a, b), (c, d)) = (w[0], w[1]);
                let len = (b.0 - a.0).hypot(b.1 - a.1);
                if len < 0.5 {
                    return false;
                }
                let u = ((b.0 - a.0) / len, (b.1 - a.1) / len);
                let off = |p: (f64, f64)| (u.0 * (p.1 - a.1) - u.1 * (p.0 - a.0)).abs();
                let gap = u.0 * (c.0 - b.0) + u.1 * (c.1 - b.1);
                // (Within 1.5 px: the ends are rounded to whole pixels.)
                off(c) < 1.5 && off(d) < 1.5 && gap > 1.0
            })
            .count();
        if pairs > 0 && 2 * dashes >= pairs {
            out.insert(style.clone());
        }
    }
    out
}

/// Every group of `svg` that [`crate::marks`] wrapped, in the order drawn.
pub fn marked_groups(svg: &str) -> Vec<MarkedGroup> {
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(a) = rest.find("<g class=\"") {
        rest = &rest[a..];
        let Some(open_end) = rest.find('>') else {
            break;
        };
        let Some(close) = rest.find("</g>") else {
            break;
        };
        let tag = &rest[..open_end];
        let body = &rest[open_end + 1..close];
        rest = &rest[close..];
        let kind = attr(tag, "class").unwrap_or_default();
        let mut g = MarkedGroup {
            name: unescape(&attr(tag, &format!("data-{kind}")).unwrap_or_default()),
            ramp: attr(tag, "data-colour").is_some_and(|c| c == "ramp"),
            kind,
            ..MarkedGroup::default()
        };
        let mut pieces = Vec::new();
        let mut lines: BTreeMap<(String, String), usize> = BTreeMap::new();
        let mut b = body;
        while let Some(s) = b.find('<') {
            b = &b[s..];
            let Some(e) = b.find('>') else { break };
            let tag = &b[..e];
            if tag.starts_with("<text") {
                let end = b.find("</text>").unwrap_or(e);
                g.texts.push(unescape(b[e + 1..end].trim()));
            } else {
                let (m, piece) = mark_of(tag);
                if let Some(m) = m.as_ref().filter(|m| m.shape == "line") {
                    *lines
                        .entry((m.colour.clone(), m.width.clone()))
                        .or_default() += 1;
                }
                g.marks.extend(m);
                pieces.extend(piece);
            }
            b = &b[e + 1..];
        }
        for style in broken_styles(&pieces) {
            let n_pieces = pieces.iter().filter(|p| p.0 == style).count();
            let (colour, width) = style.clone();
            // A style drawn only as dashes is a dashed line, not a line too.
            if lines.get(&style) == Some(&n_pieces) {
                g.marks.remove(&Mark {
                    shape: "line".into(),
                    colour: colour.clone(),
                    width: width.clone(),
                });
            }
            g.marks.insert(Mark {
                shape: "dashed line".into(),
                colour,
                width,
            });
        }
        out.push(g);
    }
    out
}

/// Groups of one kind merged by name.
fn by_name(groups: &[MarkedGroup], kind: &str) -> BTreeMap<String, MarkedGroup> {
    let mut out: BTreeMap<String, MarkedGroup> = BTreeMap::new();
    for g in groups.iter().filter(|g| g.kind == kind) {
        let e = out.entry(g.name.clone()).or_insert_with(|| MarkedGroup {
            kind: g.kind.clone(),
            name: g.name.clone(),
            ..MarkedGroup::default()
        });
        e.ramp |= g.ramp;
        e.marks.extend(g.marks.iter().cloned());
        e.texts.extend(g.texts.iter().cloned());
    }
    out
}

/// The series of `svg` drawn (with at least one mark) that no legend entry names.
pub fn series_without_legend(svg: &str) -> Vec<String> {
    let groups = marked_groups(svg);
    let legend = by_name(&groups, "legend");
    by_name(&groups, "series")
        .into_values()
        .filter(|s| !s.marks.is_empty() && !legend.contains_key(&s.name))
        .map(|s| s.name)
        .collect()
}

/// The legend entries of `svg` whose label is written nowhere (neither in the entry nor as a
/// text of the figure).
pub fn legend_entries_without_text(svg: &str) -> Vec<String> {
    let texts: BTreeSet<String> = super::text_boxes(svg).into_iter().map(|t| t.text).collect();
    by_name(&marked_groups(svg), "legend")
        .into_values()
        .filter(|l| !l.texts.contains(&l.name) && !texts.contains(&l.name))
        .map(|l| l.name)
        .collect()
}

/// The legend entries of `svg` whose swatch is not the mark of the series they name: every
/// mark of the series (its shape, colour, line width, and dashes) is among the swatch's marks;
/// of a series whose colour follows a scale, every shape. An entry with no swatch (a row's
/// label, which keys the row's marks by place) is not compared. Each as `name: drawn as ...,
/// keyed as ...`.
pub fn swatches_unlike_series(svg: &str) -> Vec<String> {
    let groups = marked_groups(svg);
    let legend = by_name(&groups, "legend");
    let mut out = Vec::new();
    for s in by_name(&groups, "series").into_values() {
        // An entry with no swatch (a row's label on its axis) keys its series by place.
        let Some(l) = legend.get(&s.name).filter(|l| !l.marks.is_empty()) else {
            continue;
        };
        let fits = if s.ramp {
            let shapes = |g: &MarkedGroup| -> BTreeSet<String> {
                g.marks.iter().map(|m| m.shape.clone()).collect()
            };
            shapes(&s).is_subset(&shapes(l))
        } else {
            s.marks.is_subset(&l.marks)
        };
        if !fits {
            let show = |g: &MarkedGroup| {
                g.marks
                    .iter()
                    .map(|m| {
                        format!("{} {} {}", m.shape, m.colour, m.width)
                            .trim()
                            .to_string()
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            out.push(format!(
                "{}: drawn as [{}], keyed as [{}]",
                s.name,
                show(&s),
                show(l)
            ));
        }
    }
    out
}

/// Everything wrong with the legend of `svg`, one line each: a series with no entry
/// ([`series_without_legend`]), an entry with no label ([`legend_entries_without_text`]), a
/// swatch unlike its series ([`swatches_unlike_series`]).
pub fn legend_faults(svg: &str) -> Vec<String> {
    let mut out: Vec<String> = series_without_legend(svg)
        .into_iter()
        .map(|s| format!("a series with no legend entry: {s:?}"))
        .collect();
    out.extend(
        legend_entries_without_text(svg)
            .into_iter()
            .map(|s| format!("a legend entry with no label: {s:?}")),
    );
    out.extend(
        swatches_unlike_series(svg)
            .into_iter()
            .map(|s| format!("a swatch unlike its series: {s}")),
    );
    out
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;

    /// A figure in both legend layouts: plotters' (the label text apart, the swatch in its
    /// group) and the figures' own (swatch and label in one group).
    const SVG: &str = r##"<svg>
<g class="series" data-series="true source">
<polygon opacity="1" fill="#008C3C" points="179,207 172,221 187,221 "/>
</g>
<g class="series" data-series="op-area">
<polyline fill="none" opacity="1" stroke="#000000" stroke-width="2" points="10,10 20,10 "/>
<polyline fill="none" opacity="1" stroke="#000000" stroke-width="2" points="30,10 40,10 "/>
<polyline fill="none" opacity="1" stroke="#000000" stroke-width="2" points="50,10 60,10 "/>
</g>
<g class="series" data-series="track: find">
<polyline fill="none" opacity="1" stroke="#1F64BE" stroke-width="2" points="1,1 5,9 20,30 "/>
</g>
<g class="series" data-series="track: done">
<polyline fill="none" opacity="1" stroke="#000000" stroke-width="2" points="20,30 20,30 "/>
</g>
<g class="series" data-series="heat" data-colour="ramp">
<rect x="1" y="1" width="5" height="5" opacity="1" fill="#FFF1E4" stroke="none"/>
<rect x="6" y="1" width="5" height="5" opacity="1" fill="#FFAA64" stroke="none"/>
</g>
<text x="600" y="20" font-size="12">true source</text>
<g class="legend" data-legend="true source">
<polygon opacity="1" fill="#008C3C" points="588,14 583,24 593,24 "/>
</g>
<g class="legend" data-legend="op-area">
<polyline fill="none" opacity="1" stroke="#000000" stroke-width="2" points="80,200 86,200 "/>
<text x="106" y="200" font-size="12">op-area</text>
</g>
<g class="legend" data-legend="heat">
<polygon opacity="1" fill="#FFAA64" points="82,530 96,530 96,540 82,540 "/>
<text x="106" y="530" font-size="12">heat</text>
</g>
</svg>"##;

    #[test]
    fn groups_are_read_with_their_marks() {
        let g = marked_groups(SVG);
        assert_eq!(g.len(), 8);
        assert_eq!(g[0].kind, "series");
        let shape = |k: usize| {
            g[k].marks
                .iter()
                .map(|m| m.shape.clone())
                .collect::<Vec<_>>()
        };
        assert_eq!(shape(0), ["triangle"]);
        assert_eq!(shape(1), ["dashed line"], "three dashes on one line");
        // Dashes along a slope, their ends rounded to whole pixels.
        let sloped = r##"<g class="series" data-series="v">
<polyline fill="none" opacity="1" stroke="#AA008C" stroke-width="1" points="545,417 530,417 "/>
<polyline fill="none" opacity="1" stroke="#AA008C" stroke-width="1" points="515,416 500,416 "/>
<polyline fill="none" opacity="1" stroke="#AA008C" stroke-width="1" points="485,416 470,415 "/>
</g>"##;
        let m = &marked_groups(sloped)[0].marks;
        assert_eq!(
            m.iter().map(|m| m.shape.as_str()).collect::<Vec<_>>(),
            ["dashed line"]
        );
        assert_eq!(shape(2), ["line"]);
        assert!(g[3].marks.is_empty(), "a line of no length draws nothing");
        assert!(g[4].ramp);
        assert_eq!(g[6].texts, ["op-area"]);
    }

    #[test]
    fn a_series_with_no_legend_entry_is_found() {
        assert_eq!(series_without_legend(SVG), ["track: find"]);
        assert!(legend_entries_without_text(SVG).is_empty());
        let no_label = SVG.replace(">true source</text>", ">source</text>");
        assert_eq!(legend_entries_without_text(&no_label), ["true source"]);
    }

    #[test]
    fn a_swatch_unlike_its_series_is_found() {
        // The op-area's swatch is one dash: a solid line, not the dashed outline it names.
        let bad = swatches_unlike_series(SVG);
        assert_eq!(bad.len(), 1, "{bad:?}");
        assert!(
            bad[0].starts_with("op-area: drawn as [dashed line #000000 2]"),
            "{bad:?}"
        );
        let two_dashes = SVG.replace(
            "points=\"80,200 86,200 \"/>",
            "points=\"80,200 86,200 \"/>\n<polyline fill=\"none\" opacity=\"1\" stroke=\"#000000\" stroke-width=\"2\" points=\"90,200 96,200 \"/>",
        );
        assert!(swatches_unlike_series(&two_dashes).is_empty());
        // A row's label keys its row by place: no swatch to compare.
        let row_label = SVG.replace(
            "<polygon opacity=\"1\" fill=\"#008C3C\" points=\"588,14 583,24 593,24 \"/>\n",
            "",
        );
        assert!(
            swatches_unlike_series(&row_label)
                .iter()
                .all(|b| !b.starts_with("true source"))
        );
        // A source keyed by a dot, or in another colour.
        for wrong in [
            SVG.replace(
                "fill=\"#008C3C\" points=\"588",
                "fill=\"#000000\" points=\"588",
            ),
            SVG.replace(
                "points=\"588,14 583,24 593,24 \"",
                "points=\"588,14 583,24 593,24 600,14\"",
            ),
        ] {
            let bad = swatches_unlike_series(&wrong);
            assert!(bad.iter().any(|b| b.starts_with("true source")), "{bad:?}");
        }
    }
}
