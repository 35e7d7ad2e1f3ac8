//! Find: sweep across the flow from the most downflow corner, either on planned lanes across
//! the flow or reflecting at the boundary (the field description's billiard).

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

/// Offsets of successive Find passes, in lane spacings: each pass's lanes lie between those
/// of the passes before it.
const PASS_OFFSETS: [f64; 4] = [0.0, 0.5, 0.25, 0.75];

/// The lanes of Find pass `pass` (0, 1, ...) over `area`: lines across the flow `spacing_m`
/// apart along it, the first `margin_m` plus the pass's offset up the flow from the most
/// downflow point, each the longest part of the line at least `margin_m` inside the area (lanes
/// shorter than `min_length_m` are left out). Ordered from the most downflow lane up the flow,
/// each from left to right looking up the flow.
pub fn lanes(
    area: &OpArea,
    flow_toward: Heading,
    spacing_m: f64,
    pass: usize,
    margin_m: f64,
    min_length_m: f64,
) -> Vec<(Vec2, Vec2)> {
    let down = flow_toward.unit();
    let right = flow_toward.turned_deg(90.0).unit();
    let (d_lo, d_hi) = area.extent_along(down);
    let (c_lo, c_hi) = area.extent_along(right);
    let spacing = spacing_m.max(1.0);
    let first = d_hi - margin_m - PASS_OFFSETS[pass % PASS_OFFSETS.len()] * spacing;
    // Bounded by the area's extent along the flow (at most 100,000 m / 1 m lanes).
    let n = (((first - d_lo - margin_m) / spacing).floor() as i64).clamp(-1, 100_000);
    (0..=n)
        .filter_map(|k| {
            let d = first - k as f64 * spacing;
            // Looking up the flow, left is the flow's right.
            let a = down * d + right * (c_hi + 1.0);
            let b = down * d + right * (c_lo - 1.0);
            area.clip_segment(a, b, margin_m, min_length_m)
        })
        .collect()
}

/// The downflow edge of `area` as a path of segments, for a vehicle at `pos_m`: for across-flow
/// positions `step_m` apart, the most downflow point at least `margin_m` inside the area (the
/// plume of every source further inside crosses it on its way out). Flown from the point nearest
/// the vehicle to the nearer end of the edge, then along the whole edge to the other end.
pub fn downflow_edge(
    area: &OpArea,
    flow_toward: Heading,
    margin_m: f64,
    step_m: f64,
    pos_m: Vec2,
) -> Vec<(Vec2, Vec2)> {
    let down = flow_toward.unit();
    let right = flow_toward.turned_deg(90.0).unit();
    let (d_lo, d_hi) = area.extent_along(down);
    let (c_lo, c_hi) = area.extent_along(right);
    // From end to end of what lies margin_m inside (half a metre more, against rounding), at
    // most 10,000 points (bounded by the area's extent across the flow).
    let (c0, c1) = (c_lo + margin_m + 0.5, c_hi - margin_m - 0.5);
    if c1 <= c0 {
        return Vec::new();
    }
    let n = (((c1 - c0) / step_m.max(1.0)).ceil() as i64).clamp(1, 10_000);
    let points: Vec<Vec2> = (0..=n)
        .filter_map(|k| {
            let c = c0 + (c1 - c0) * (k as f64 / n as f64);
            let a = down * (d_lo - 1.0) + right * c;
            let b = down * (d_hi + 1.0) + right * c;
            area.clip_segment(a, b, margin_m, 0.0).map(|(_, q)| q)
        })
        .collect();
    if points.len() < 2 {
        return Vec::new();
    }
    let near = points
        .iter()
        .enumerate()
        .min_by(|a, b| (a.1 - pos_m).norm().total_cmp(&(b.1 - pos_m).norm()))
        .map_or(0, |(i, _)| i);
    let length = |w: &[Vec2]| w.windows(2).map(|p| (p[1] - p[0]).norm()).sum::<f64>();
    let last = points.len() - 1;
    let order: Vec<usize> = if length(&points[..=near]) <= length(&points[near..]) {
        (0..=near).rev().chain(1..=last).collect()
    } else {
        (near..=last).chain((0..last).rev()).collect()
    };
    order
        .windows(2)
        .map(|w| (points[w[0]], points[w[1]]))
        .collect()
}

/// Orders one pass's `lanes` (most downflow first) for a vehicle at `pos_m`: up the flow
/// (`upflow`) or down it, all of them or (`from_here`) those from about the vehicle's position
/// on; the first lane starts at its end nearer the vehicle, each next one at the end nearer the
/// last one's end (a boustrophedon).
pub fn order_lanes(
    lanes: &[(Vec2, Vec2)],
    pos_m: Vec2,
    flow_toward: Heading,
    spacing_m: f64,
    upflow: bool,
    from_here: bool,
) -> Vec<(Vec2, Vec2)> {
    let down = flow_toward.unit();
    let at = if from_here {
        pos_m.dot(&down)
    } else if upflow {
        f64::INFINITY
    } else {
        f64::NEG_INFINITY
    };
    let half = 0.5 * spacing_m.max(1.0);
    let mut out: Vec<(Vec2, Vec2)> = if upflow {
        lanes
            .iter()
            .filter(|(a, _)| a.dot(&down) <= at + half)
            .copied()
            .collect()
    } else {
        lanes
            .iter()
            .rev()
            .filter(|(a, _)| a.dot(&down) >= at - half)
            .copied()
            .collect()
    };
    let mut from = pos_m;
    for lane in &mut out {
        if (lane.1 - from).norm() < (lane.0 - from).norm() {
            *lane = (lane.1, lane.0);
        }
        from = lane.1;
    }
    out
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
    fn lanes_and_the_downflow_edge_of_a_rectangle() {
        // Flow towards North over 0..300 x 0..500: lanes run East-West from y = 490 down in
        // steps of 120 m (the second pass halfway between), 10 m inside the side edges.
        let area = OpArea::rectangle(0.0, 300.0, 0.0, 500.0).unwrap();
        let l = lanes(&area, Heading::NORTH, 120.0, 0, 10.0, 24.0);
        let ys: Vec<f64> = l.iter().map(|(a, _)| a.y).collect();
        assert_eq!(ys.len(), 5, "{ys:?}");
        for (y, want) in ys.iter().zip([490.0, 370.0, 250.0, 130.0, 10.0]) {
            assert!((y - want).abs() < 1e-9, "{ys:?}");
        }
        for (a, b) in &l {
            assert!((a.x.min(b.x) - 10.0).abs() <= 1.0 && (a.x.max(b.x) - 290.0).abs() <= 1.0);
        }
        let l = lanes(&area, Heading::NORTH, 120.0, 1, 10.0, 24.0);
        assert!((l[0].0.y - 430.0).abs() < 1e-9, "{:?}", l[0]);
        // Up the flow from y = 200: the lanes from about there up, boustrophedon.
        let o = order_lanes(
            &lanes(&area, Heading::NORTH, 120.0, 0, 10.0, 24.0),
            Vec2::new(280.0, 200.0),
            Heading::NORTH,
            120.0,
            true,
            true,
        );
        let ys: Vec<f64> = o.iter().map(|(a, _)| a.y.round()).collect();
        assert_eq!(ys, [250.0, 130.0, 10.0]);
        assert!(o[0].0.x > o[0].1.x && o[1].0.x < o[1].1.x, "{o:?}");
        // The downflow edge: y = 490 from x = 10 to 290, from the nearer end on.
        let e = downflow_edge(&area, Heading::NORTH, 10.0, 20.0, Vec2::new(250.0, 480.0));
        assert!(
            e.iter()
                .all(|(a, b)| (a.y - 490.0).abs() <= 1.0 && (b.y - 490.0).abs() <= 1.0)
        );
        let xs: Vec<f64> = e.iter().map(|(a, _)| a.x).collect();
        assert!(xs[0] > 240.0 && xs.iter().any(|&x| x >= 289.0), "{xs:?}");
        let (_, last) = e[e.len() - 1];
        assert!(last.x <= 11.0, "ends at the western end: {last:?}");
        // Nothing lies 200 m inside a 300 m wide area.
        assert!(downflow_edge(&area, Heading::NORTH, 200.0, 20.0, Vec2::zeros()).is_empty());
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
