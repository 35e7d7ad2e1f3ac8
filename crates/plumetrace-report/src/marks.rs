//! What a figure says about its own marks, so that a test can measure them: each drawn series
//! and each legend entry is wrapped in an SVG group naming it (`<g class="series"
//! data-series="true source">`, `<g class="legend" data-legend="true source">`), and
//! [`crate::inspect`] reads the groups back to check that every series has a legend entry whose
//! swatch is the mark it names.
//!
//! plotters writes its elements one after another and has no groups, so a figure draws a
//! zero-size text holding a sentinel where a group opens and closes ([`open`], [`close`], or
//! [`open_text`] and [`close_text`] inside a composed element such as a legend swatch), and
//! [`finish`] turns the sentinels into `<g>` and `</g>` once the SVG is written.

use plotters::coord::CoordTranslate;
use plotters::prelude::*;

/// What a group holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Group {
    /// A drawn series: everything drawn of one thing the legend names.
    Series,
    /// A series whose colour follows a scale (a heat map): only its shapes are compared with
    /// its swatch.
    Ramp,
    /// A legend entry: its swatch, and its label when the figure draws both together.
    Legend,
}

impl Group {
    fn word(self) -> &'static str {
        match self {
            Group::Series => "series",
            Group::Ramp => "ramp",
            Group::Legend => "legend",
        }
    }
}

/// The sentinel's first character (a private-use code point no label holds).
const SENTINEL: char = '\u{E000}';

/// The sentinel text that opens a group of `kind` named `name`.
fn open_sentinel(kind: Group, name: &str) -> String {
    format!("{SENTINEL}{} {name}", kind.word())
}

fn close_sentinel() -> String {
    format!("{SENTINEL}/")
}

fn sentinel_style() -> TextStyle<'static> {
    ("sans-serif", 1).into_font().color(&BLACK)
}

/// The sentinel that opens a group, as a text element to compose into a drawn element (at the
/// element's own point).
pub fn open_text(kind: Group, name: &str) -> Text<'static, (i32, i32), String> {
    Text::new(open_sentinel(kind, name), (0, 0), sentinel_style())
}

/// The sentinel that closes the group [`open_text`] opened.
pub fn close_text() -> Text<'static, (i32, i32), String> {
    Text::new(close_sentinel(), (0, 0), sentinel_style())
}

/// Opens a group of `kind` named `name` on `area` (`at`: any point of the area).
pub fn open<DB: DrawingBackend, CT: CoordTranslate>(
    area: &DrawingArea<DB, CT>,
    at: CT::From,
    kind: Group,
    name: &str,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    area.draw(&Text::new(open_sentinel(kind, name), at, sentinel_style()))
}

/// Closes the group [`open`] opened.
pub fn close<DB: DrawingBackend, CT: CoordTranslate>(
    area: &DrawingArea<DB, CT>,
    at: CT::From,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    area.draw(&Text::new(close_sentinel(), at, sentinel_style()))
}

/// The SVG with every sentinel text turned into the group it stands for (a figure calls it on
/// what plotters wrote; an SVG without sentinels comes back unchanged).
pub fn finish(svg: &str) -> String {
    let mut out = String::with_capacity(svg.len() + svg.len() / 64);
    let mut rest = svg;
    while let Some(a) = rest.find("<text") {
        let Some(len) = rest[a..].find("</text>") else {
            break;
        };
        let end = a + len + "</text>".len();
        let element = &rest[a..end];
        let body = element.find('>').map_or("", |c| element[c + 1..len].trim());
        match body.strip_prefix(SENTINEL) {
            Some("/") => {
                out.push_str(&rest[..a]);
                out.push_str("</g>");
            }
            Some(s) => {
                let (word, name) = s.split_once(' ').unwrap_or((s, ""));
                let class = if word == "ramp" { "series" } else { word };
                let ramp = if word == "ramp" {
                    " data-colour=\"ramp\""
                } else {
                    ""
                };
                out.push_str(&rest[..a]);
                // The name is as plotters escaped it for text, so it is safe in an attribute.
                out.push_str(&format!(
                    "<g class=\"{class}\" data-{class}=\"{name}\"{ramp}>"
                ));
            }
            None => out.push_str(&rest[..end]),
        }
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;

    #[test]
    fn sentinels_become_groups() {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (100, 100)).into_drawing_area();
            open(&root, (0, 0), Group::Series, "a \"b\" <c>").unwrap();
            root.draw(&Circle::new((5, 5), 3, BLACK.filled())).unwrap();
            close(&root, (0, 0)).unwrap();
            root.draw(
                &(EmptyElement::at((10, 10))
                    + open_text(Group::Legend, "dot")
                    + Circle::new((0, 0), 3, BLACK.filled())
                    + close_text()),
            )
            .unwrap();
            open(&root, (0, 0), Group::Ramp, "heat").unwrap();
            close(&root, (0, 0)).unwrap();
            root.present().unwrap();
        }
        let out = finish(&svg);
        assert!(!out.contains(SENTINEL), "{out}");
        assert!(
            out.contains("<g class=\"series\" data-series=\"a &quot;b&quot; &lt;c&gt;\">\n<circle"),
            "{out}"
        );
        assert!(
            out.contains("<g class=\"legend\" data-legend=\"dot\">"),
            "{out}"
        );
        assert!(
            out.contains("data-series=\"heat\" data-colour=\"ramp\">\n</g>"),
            "{out}"
        );
        assert_eq!(out.matches("<g ").count(), out.matches("</g>").count());
        assert_eq!(
            finish("<svg><text x=\"1\">a</text></svg>"),
            "<svg><text x=\"1\">a</text></svg>"
        );
    }
}
