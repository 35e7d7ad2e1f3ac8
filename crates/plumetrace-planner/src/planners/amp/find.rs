//! Find: sweep across the flow from the most downflow corner, reflecting at the boundary (the
//! field description's billiard, or a zigzag that always makes way up or down the flow).

use plumetrace_core::{Heading, Vec2};
use plumetrace_guidance::OpArea;

/// The four Find headings `psi_f +- 90 +- offset`.
pub fn candidates(flow_toward: Heading, offset_deg: f64) -> [Heading; 4] {
    [
        flow_toward.turned_deg(90.0 + offset_deg),
        flow_toward.turned_deg(90.0 - offset_deg),
        flow_toward.turned_deg(-90.0 + offset_deg),
        flow_toward.turned_deg(-90.0 - offset_deg),
    ]
}

/// The first Find heading from `pos_m`: the candidate with an upflow component that points most
/// towards the inside of the area (from the most downflow corner: across and up the flow).
pub fn initial_heading(
    area: &OpArea,
    pos_m: Vec2,
    flow_toward: Heading,
    offset_deg: f64,
) -> Heading {
    let centre =
        area.vertices().iter().fold(Vec2::zeros(), |a, v| a + v) / area.vertices().len() as f64;
    let inward = centre - pos_m;
    let up = flow_toward.reversed().unit();
    let mut best = candidates(flow_toward, offset_deg)[0];
    let mut best_score = f64::MIN;
    for c in candidates(flow_toward, offset_deg) {
        let u = c.unit();
        let score = u.dot(&inward) + if u.dot(&up) > 0.0 { 1e6 } else { 0.0 };
        if score > best_score {
            best_score = score;
            best = c;
        }
    }
    best
}

/// The heading after meeting a boundary with outward normal `normal` while on `heading`: the
/// candidate that keeps the sign of the velocity along the boundary and reverses it across; when
/// none does, the direction along the boundary (until a candidate fits or another boundary is met).
pub fn reflect(heading: Heading, normal: Vec2, flow_toward: Heading, offset_deg: f64) -> Heading {
    let h = heading.unit();
    let tangent = Vec2::new(-normal.y, normal.x);
    let along = h.dot(&tangent);
    let along_sign = if along >= 0.0 { 1.0 } else { -1.0 };
    let fits = candidates(flow_toward, offset_deg).into_iter().filter(|c| {
        let u = c.unit();
        u.dot(&normal) < 0.0 && u.dot(&tangent) * along_sign > 0.0
    });
    // Of the candidates that fit, the one closest to the billiard reflection.
    let mirrored = h - normal * (2.0 * h.dot(&normal));
    fits.max_by(|a, b| a.unit().dot(&mirrored).total_cmp(&b.unit().dot(&mirrored)))
        .unwrap_or_else(|| Heading::of_vector(tangent * along_sign).unwrap_or(heading))
}

/// The zigzag Find's heading after meeting a boundary with outward normal `normal` while on
/// `heading`. Going up the flow (`heading` has an upflow component): the other across-flow side
/// at `psi_f +- (90 + offset)` if it points back inside (the sweep goes on up the flow), else the
/// way down, `psi_f +- (90 - offset)`, that points inside most (the sweep has reached the up-flow
/// end). Going down the flow: the same with the roles swapped. When no candidate points inside
/// (a narrow corner), the direction along the boundary.
pub fn zigzag(heading: Heading, normal: Vec2, flow_toward: Heading, offset_deg: f64) -> Heading {
    let up = flow_toward.reversed().unit();
    let going_up = heading.unit().dot(&up) > 0.0;
    let across = flow_toward.turned_deg(90.0).unit();
    let side = if heading.unit().dot(&across) >= 0.0 {
        1.0
    } else {
        -1.0
    };
    let up_other = flow_toward.turned_deg(-side * (90.0 + offset_deg));
    let down_other = flow_toward.turned_deg(-side * (90.0 - offset_deg));
    let down_same = flow_toward.turned_deg(side * (90.0 - offset_deg));
    let up_same = flow_toward.turned_deg(side * (90.0 + offset_deg));
    let inward = |h: &Heading| h.unit().dot(&normal) < 0.0;
    let order = if going_up {
        [up_other, down_other, down_same, up_same]
    } else {
        [down_other, up_other, up_same, down_same]
    };
    // The first candidate of the order that points inside; the sweep's direction along the flow
    // changes only when the same direction across the flow cannot go on.
    if let Some(h) = order.iter().take(1).find(|h| inward(h)) {
        return *h;
    }
    order[1..]
        .iter()
        .filter(|h| inward(h))
        .max_by(|a, b| (-a.unit().dot(&normal)).total_cmp(&(-b.unit().dot(&normal))))
        .copied()
        .unwrap_or_else(|| {
            let tangent = Vec2::new(-normal.y, normal.x);
            let along = if heading.unit().dot(&tangent) >= 0.0 {
                1.0
            } else {
                -1.0
            };
            Heading::of_vector(tangent * along).unwrap_or(heading)
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn billiard_reflection_table() {
        // Flow towards North (0 deg): candidates 110, 70, 290, 250.
        let north = Heading::NORTH;
        let cases = [
            // (heading, outward normal, expected)
            (110.0, (1.0, 0.0), 250.0), // hits the East edge going ESE: keep southward, go West
            (70.0, (1.0, 0.0), 290.0),  // hits the East edge going ENE: keep northward, go West
            (250.0, (-1.0, 0.0), 110.0), // the West edge
            (110.0, (0.0, -1.0), 70.0), // the South edge going ESE: keep eastward, go North
        ];
        for (h, (nx, ny), want) in cases {
            let got = reflect(Heading::from_deg(h), Vec2::new(nx, ny), north, 20.0);
            assert!(
                got.diff_deg(Heading::from_deg(want)).abs() < 1e-9,
                "{h} off ({nx},{ny}): {}",
                got.deg()
            );
        }
        // Flow parallel to the boundary: heading along the flow, hitting the North edge with
        // flow towards East: candidates 20, 340, 160, 200 after reflection keeps East... none of the
        // across-flow candidates runs along it, one reverses across.
        let got = reflect(
            Heading::from_deg(20.0),
            Vec2::new(0.0, 1.0),
            Heading::from_deg(90.0),
            20.0,
        );
        assert!(
            got.diff_deg(Heading::from_deg(160.0)).abs() < 1e-9,
            "{}",
            got.deg()
        );
    }

    #[test]
    fn starts_across_and_up_the_flow_into_the_area() {
        let area = OpArea::rectangle(0.0, 300.0, 0.0, 1000.0).unwrap();
        // Flow towards North: most downflow corners are on the North edge; from the North-West one
        // the sweep goes East and South: 110 deg.
        let h = initial_heading(&area, Vec2::new(0.0, 1000.0), Heading::NORTH, 20.0);
        assert!(
            h.diff_deg(Heading::from_deg(110.0)).abs() < 1e-9,
            "{}",
            h.deg()
        );
        let h = initial_heading(&area, Vec2::new(300.0, 1000.0), Heading::NORTH, 20.0);
        assert!(
            h.diff_deg(Heading::from_deg(250.0)).abs() < 1e-9,
            "{}",
            h.deg()
        );
    }
}
