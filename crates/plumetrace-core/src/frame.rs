//! The local tangent frame: `x` East, `y` North, `z` height above the seabed.

use crate::Heading;

pub use crate::vector::{Vec2, Vec3};

/// Unit vector of a compass heading: `(east, north) = (sin psi, cos psi)`.
pub fn heading_vector(h: Heading) -> Vec2 {
    let (s, c) = h.rad().sin_cos();
    Vec2::new(s, c)
}

/// Compass bearing from `from` to `to`; `None` when the two points coincide.
pub fn bearing_between(from: Vec2, to: Vec2) -> Option<Heading> {
    Heading::of_vector(to - from)
}

/// The first pair of edges `(i, j)` (edge `i` runs from vertex `i` to vertex `i + 1`, the last
/// back to the first) of a closed polygon that touch or cross without being neighbours, or that
/// overlap as neighbours; `None` for a simple polygon.
pub fn self_intersection(poly: &[Vec2]) -> Option<(usize, usize)> {
    let n = poly.len();
    if n < 3 {
        return None;
    }
    let edge = |i: usize| (poly[i], poly[(i + 1) % n]);
    for i in 0..n {
        let (a, b) = edge(i);
        for j in i + 1..n {
            let (c, d) = edge(j);
            let neighbours = j == i + 1 || (i == 0 && j == n - 1);
            if neighbours {
                // Neighbours share a vertex; they must not fold back onto each other.
                let (shared, other_a, other_b) = if j == i + 1 { (b, a, d) } else { (a, b, c) };
                let (u, v) = (other_a - shared, other_b - shared);
                if u.x * v.y - u.y * v.x == 0.0 && u.dot(&v) > 0.0 {
                    return Some((i, j));
                }
            } else if segments_touch(a, b, c, d) {
                return Some((i, j));
            }
        }
    }
    None
}

/// Why a list of vertices is not a simple polygon.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum PolygonError {
    /// Fewer than three vertices.
    #[error("needs at least 3 vertices, got {0}")]
    TooFewVertices(usize),
    /// Vertex `k` is not finite.
    #[error("vertex {0} is not finite")]
    NonFinite(usize),
    /// The vertices enclose no area.
    #[error("has zero area")]
    ZeroArea,
    /// Edges `i` and `j` touch or cross ([`self_intersection`]).
    #[error(
        "the polygon crosses itself: edges {0} and {1} meet (edge k runs from vertex k to the next)"
    )]
    SelfIntersecting(usize, usize),
}

/// Twice the signed area of a closed polygon: positive for anticlockwise vertices.
pub fn signed_area2(poly: &[Vec2]) -> f64 {
    (0..poly.len())
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            a.x * b.y - b.x * a.y
        })
        .sum()
}

/// Checks that `poly` is a simple polygon, in this order: at least 3 vertices, every one finite,
/// an area (when `need_area`: twice the area at least 1e-9 m^2), no two edges that touch or
/// cross. Returns twice its signed area ([`signed_area2`]).
pub fn check_polygon(poly: &[Vec2], need_area: bool) -> Result<f64, PolygonError> {
    if poly.len() < 3 {
        return Err(PolygonError::TooFewVertices(poly.len()));
    }
    if let Some(k) = poly
        .iter()
        .position(|v| !(v.x.is_finite() && v.y.is_finite()))
    {
        return Err(PolygonError::NonFinite(k));
    }
    let area2 = signed_area2(poly);
    if need_area && area2.abs() < 1e-9 {
        return Err(PolygonError::ZeroArea);
    }
    if let Some((a, b)) = self_intersection(poly) {
        return Err(PolygonError::SelfIntersecting(a, b));
    }
    Ok(area2)
}

/// Whether segments `ab` and `cd` share at least one point.
fn segments_touch(a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> bool {
    let cross = |o: Vec2, p: Vec2, q: Vec2| (p.x - o.x) * (q.y - o.y) - (p.y - o.y) * (q.x - o.x);
    let on = |p: Vec2, q: Vec2, r: Vec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    let (d1, d2) = (cross(c, d, a), cross(c, d, b));
    let (d3, d4) = (cross(a, b, c), cross(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bearing_table() {
        let o = Vec2::new(10.0, 20.0);
        let cases = [
            ((10.0, 30.0), 0.0),
            ((20.0, 20.0), 90.0),
            ((10.0, 10.0), 180.0),
            ((0.0, 20.0), 270.0),
            ((0.0, 10.0), 225.0),
        ];
        for ((x, y), want) in cases {
            let got = bearing_between(o, Vec2::new(x, y))
                .map(Heading::deg)
                .unwrap_or(f64::NAN);
            assert!(
                (got - want).abs() < 1e-9,
                "bearing to ({x},{y}) = {got}, want {want}"
            );
        }
        assert!(bearing_between(o, o).is_none());
    }

    #[test]
    fn polygon_checks_table() {
        let p = |v: &[(f64, f64)]| v.iter().map(|(x, y)| Vec2::new(*x, *y)).collect::<Vec<_>>();
        let square = p(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]);
        assert_eq!(check_polygon(&square, true), Ok(2.0));
        let line = p(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)]);
        let cases = [
            (
                p(&[(0.0, 0.0), (1.0, 0.0)]),
                true,
                PolygonError::TooFewVertices(2),
            ),
            (
                p(&[(0.0, 0.0), (f64::NAN, 0.0), (1.0, 1.0)]),
                true,
                PolygonError::NonFinite(1),
            ),
            (line, true, PolygonError::ZeroArea),
            (
                p(&[(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)]),
                false,
                PolygonError::SelfIntersecting(0, 2),
            ),
        ];
        for (poly, need_area, want) in cases {
            assert_eq!(check_polygon(&poly, need_area), Err(want), "{poly:?}");
        }
        // A tiny triangle is simple: only `need_area` refuses it.
        let tiny = p(&[(0.0, 0.0), (1e-5, 0.0), (0.0, 1e-5)]);
        assert!(check_polygon(&tiny, false).is_ok());
        assert_eq!(check_polygon(&tiny, true), Err(PolygonError::ZeroArea));
    }

    #[test]
    fn self_intersections_table() {
        let p = |v: &[(f64, f64)]| v.iter().map(|(x, y)| Vec2::new(*x, *y)).collect::<Vec<_>>();
        type Case<'a> = (&'a [(f64, f64)], Option<(usize, usize)>);
        let cases: [Case; 6] = [
            (&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)], None),
            // A bow-tie: edges 0 and 2 cross.
            (
                &[(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)],
                Some((0, 2)),
            ),
            // An asymmetric bow-tie.
            (
                &[(0.0, 0.0), (3.0, 2.0), (3.0, 0.0), (0.0, 5.0)],
                Some((0, 2)),
            ),
            // A concave (U-shaped) polygon is simple.
            (
                &[
                    (0.0, 0.0),
                    (3.0, 0.0),
                    (3.0, 2.0),
                    (2.0, 2.0),
                    (2.0, 1.0),
                    (1.0, 1.0),
                    (1.0, 2.0),
                    (0.0, 2.0),
                ],
                None,
            ),
            // A vertex on another edge.
            (
                &[(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (1.0, 0.0), (0.0, 2.0)],
                Some((0, 2)),
            ),
            // A spike folding back on its neighbour.
            (
                &[(0.0, 0.0), (2.0, 0.0), (1.0, 0.0), (1.0, 1.0)],
                Some((0, 1)),
            ),
        ];
        for (poly, want) in cases {
            assert_eq!(self_intersection(&p(poly)), want, "{poly:?}");
        }
    }

    #[test]
    fn heading_vector_round_trips() {
        for deg in [0.0, 1.0, 89.0, 90.0, 181.0, 270.0, 359.5] {
            let h = Heading::from_deg(deg);
            let back = Heading::of_vector(heading_vector(h))
                .map(Heading::deg)
                .unwrap_or(f64::NAN);
            assert!(
                Heading::from_deg(back).diff_deg(h).abs() < 1e-9,
                "{deg} -> {back}"
            );
        }
    }
}
