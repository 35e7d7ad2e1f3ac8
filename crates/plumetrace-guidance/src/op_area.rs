//! The operating area: a simple polygon (convex or not) the vehicle must stay in.

use plumetrace_core::Vec2;
use serde::{Deserialize, Serialize};

/// Why an op-area could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OpAreaError {
    /// Fewer than three vertices.
    #[error("an op-area needs at least 3 vertices, got {0}")]
    TooFewVertices(usize),
    /// A vertex is not finite.
    #[error("op-area vertex {0} is not finite")]
    NonFinite(usize),
    /// The polygon has no area.
    #[error("the op-area has zero area")]
    ZeroArea,
    /// Two edges cross or touch (edge `k` runs from vertex `k` to the next).
    #[error("the op-area crosses itself: edges {0} and {1} meet")]
    SelfIntersecting(usize, usize),
}

impl From<plumetrace_core::PolygonError> for OpAreaError {
    fn from(e: plumetrace_core::PolygonError) -> Self {
        use plumetrace_core::PolygonError as P;
        match e {
            P::TooFewVertices(n) => OpAreaError::TooFewVertices(n),
            P::NonFinite(k) => OpAreaError::NonFinite(k),
            P::ZeroArea => OpAreaError::ZeroArea,
            P::SelfIntersecting(a, b) => OpAreaError::SelfIntersecting(a, b),
        }
    }
}

/// Where a point is relative to the nearest edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeInfo {
    /// Distance to the nearest edge, m (always >= 0).
    pub distance_m: f64,
    /// Unit normal of the nearest edge pointing out of the area.
    pub outward_normal: Vec2,
    /// Whether the point is inside the area.
    pub inside: bool,
}

/// A simple polygon, vertices in order (either winding), `(east, north)` in metres. It is written
/// as its list of vertices and read back through [`OpArea::new`], so a file cannot make an
/// invalid one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Vec<Vec2>", into = "Vec<Vec2>")]
pub struct OpArea {
    vertices: Vec<Vec2>,
    /// +1 for anticlockwise vertex order, -1 for clockwise.
    orientation: f64,
}

impl TryFrom<Vec<Vec2>> for OpArea {
    type Error = OpAreaError;
    fn try_from(vertices: Vec<Vec2>) -> Result<Self, OpAreaError> {
        OpArea::new(vertices)
    }
}

impl From<OpArea> for Vec<Vec2> {
    fn from(a: OpArea) -> Self {
        a.vertices
    }
}

impl OpArea {
    /// An op-area from its vertices (the closing edge is implied).
    pub fn new(vertices: Vec<Vec2>) -> Result<Self, OpAreaError> {
        let area2 = plumetrace_core::check_polygon(&vertices, true)?;
        Ok(OpArea {
            vertices,
            orientation: area2.signum(),
        })
    }

    /// An axis-aligned rectangle.
    pub fn rectangle(
        x_min_m: f64,
        x_max_m: f64,
        y_min_m: f64,
        y_max_m: f64,
    ) -> Result<Self, OpAreaError> {
        OpArea::new(vec![
            Vec2::new(x_min_m, y_min_m),
            Vec2::new(x_max_m, y_min_m),
            Vec2::new(x_max_m, y_max_m),
            Vec2::new(x_min_m, y_max_m),
        ])
    }

    /// The vertices.
    pub fn vertices(&self) -> &[Vec2] {
        &self.vertices
    }

    fn edges(&self) -> impl Iterator<Item = (Vec2, Vec2)> + '_ {
        let n = self.vertices.len();
        (0..n).map(move |i| (self.vertices[i], self.vertices[(i + 1) % n]))
    }

    /// Crossing-number test (points exactly on an edge may fall either way).
    fn crossing_inside(&self, p: Vec2) -> bool {
        let mut inside = false;
        for (a, b) in self.edges() {
            if (a.y > p.y) != (b.y > p.y) {
                let x_cross = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if p.x < x_cross {
                    inside = !inside;
                }
            }
        }
        inside
    }

    /// Whether `p` is inside (points on an edge count as inside).
    pub fn contains(&self, p: Vec2) -> bool {
        self.crossing_inside(p) || self.edge_info(p).distance_m < 1e-9
    }

    /// How far `p` lies outside the area (`None` inside it or on its boundary): the distance of
    /// [`OpArea::edge_info`] where that says outside, found without the edges' distances for a
    /// point inside.
    pub fn outside_by(&self, p: Vec2) -> Option<f64> {
        if self.crossing_inside(p) {
            return None;
        }
        let e = self.edge_info(p);
        (!e.inside).then_some(e.distance_m)
    }

    /// Distance to the nearest edge and the outward normal there.
    ///
    /// The normal is the edge's outward normal when the nearest point is inside an edge, and the
    /// direction from the point to the nearest vertex (or away from it, outside) at a corner, so
    /// it is well defined for non-convex areas too.
    pub fn edge_info(&self, p: Vec2) -> EdgeInfo {
        let mut best = (f64::INFINITY, Vec2::new(1.0, 0.0), Vec2::zeros());
        for (a, b) in self.edges() {
            let ab = b - a;
            let len2 = ab.norm_squared();
            let t = if len2 > 0.0 {
                ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let q = a + ab * t;
            let d = (p - q).norm();
            if d < best.0 {
                // Outward normal of the edge: to the right of the edge for anticlockwise order.
                let n = Vec2::new(ab.y, -ab.x) * self.orientation;
                let n = if n.norm() > 0.0 {
                    n / n.norm()
                } else {
                    Vec2::new(1.0, 0.0)
                };
                best = (d, n, q);
            }
        }
        let (d, edge_normal, q) = best;
        let inside = self.crossing_inside(p) || d < 1e-9;
        // Away from an edge's interior (near a corner) the edge normal is not the direction to
        // the boundary; use the direction between the point and its nearest boundary point.
        let normal = if d > 1e-9 {
            let towards = (q - p) / d;
            if inside { towards } else { -towards }
        } else {
            edge_normal
        };
        EdgeInfo {
            distance_m: d,
            outward_normal: normal,
            inside,
        }
    }

    /// Every edge closer than `band_m` to `p`: distance to the edge segment and the edge's outward
    /// normal, nearest first.
    pub fn edges_within(&self, p: Vec2, band_m: f64) -> Vec<(f64, Vec2)> {
        let mut out: Vec<(f64, Vec2)> = self
            .edges()
            .filter_map(|(a, b)| {
                let ab = b - a;
                let len2 = ab.norm_squared();
                if len2 == 0.0 {
                    return None;
                }
                let t = ((p - a).dot(&ab) / len2).clamp(0.0, 1.0);
                let d = (p - (a + ab * t)).norm();
                let n = Vec2::new(ab.y, -ab.x) * self.orientation / len2.sqrt();
                (d < band_m).then_some((d, n))
            })
            .collect();
        out.sort_by(|x, y| x.0.total_cmp(&y.0));
        out
    }

    /// The longest part of the segment `a`-`b` that lies inside the area at least `margin_m` from
    /// every edge, found on a grid of at most 1 m steps (2,000 at most); `None` when that part is
    /// shorter than `min_length_m`. A pattern leg that reaches out of the area is flown as this
    /// part, so that the vehicle never aims at a point the cage keeps it from.
    pub fn clip_segment(
        &self,
        a: Vec2,
        b: Vec2,
        margin_m: f64,
        min_length_m: f64,
    ) -> Option<(Vec2, Vec2)> {
        let len = (b - a).norm();
        if !len.is_finite() {
            return None;
        }
        let n = (len.ceil() as usize).clamp(1, 2000);
        let ok = |k: usize| {
            let p = a + (b - a) * (k as f64 / n as f64);
            let e = self.edge_info(p);
            e.inside && e.distance_m >= margin_m
        };
        let (mut best, mut run_start) = (None::<(usize, usize)>, None::<usize>);
        for k in 0..=n {
            match (ok(k), run_start) {
                (true, None) => run_start = Some(k),
                (false, Some(s)) => {
                    if best.is_none_or(|(bs, be)| k - 1 - s > be - bs) {
                        best = Some((s, k - 1));
                    }
                    run_start = None;
                }
                _ => {}
            }
        }
        if let Some(s) = run_start
            && best.is_none_or(|(bs, be)| n - s > be - bs)
        {
            best = Some((s, n));
        }
        let (s, e) = best?;
        let at = |k: usize| a + (b - a) * (k as f64 / n as f64);
        let (p, q) = (at(s), at(e));
        ((q - p).norm() >= min_length_m).then_some((p, q))
    }

    /// The smallest and largest projection of the vertices on `direction` (the area's extent
    /// along it, for a unit `direction`).
    pub fn extent_along(&self, direction: Vec2) -> (f64, f64) {
        self.vertices
            .iter()
            .map(|v| v.dot(&direction))
            .fold((f64::MAX, f64::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)))
    }

    /// The vertex furthest along `direction` (e.g. the most downflow corner).
    pub fn furthest_vertex_along(&self, direction: Vec2) -> Vec2 {
        let mut best = self.vertices[0];
        for v in &self.vertices {
            if v.dot(&direction) > best.dot(&direction) {
                best = *v;
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_back_only_valid_areas() {
        let a = OpArea::rectangle(0.0, 10.0, 0.0, 5.0).unwrap_or_else(|e| panic!("{e}"));
        let text = serde_json::to_string(&a).unwrap_or_default();
        assert_eq!(text, "[[0.0,0.0],[10.0,0.0],[10.0,5.0],[0.0,5.0]]");
        let back: OpArea = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(back, a);
        for bad in ["[[0.0,0.0],[1.0,0.0]]", "[[0,0],[1,0],[2,0]]", "[]"] {
            assert!(serde_json::from_str::<OpArea>(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn rectangle_edge_info_table() {
        let a = OpArea::rectangle(0.0, 100.0, 0.0, 50.0).unwrap();
        // (point, distance, normal, inside)
        let cases = [
            ((50.0, 48.0), 2.0, (0.0, 1.0), true),
            ((1.0, 25.0), 1.0, (-1.0, 0.0), true),
            ((50.0, 60.0), 10.0, (0.0, 1.0), false),
            ((110.0, 25.0), 10.0, (1.0, 0.0), false),
            ((-3.0, -4.0), 5.0, (-0.6, -0.8), false),
        ];
        for ((x, y), d, (nx, ny), inside) in cases {
            let e = a.edge_info(Vec2::new(x, y));
            assert!(
                (e.distance_m - d).abs() < 1e-9,
                "({x},{y}) distance {}",
                e.distance_m
            );
            assert!(
                (e.outward_normal - Vec2::new(nx, ny)).norm() < 1e-9,
                "({x},{y}) normal {:?}",
                e.outward_normal
            );
            assert_eq!(e.inside, inside, "({x},{y})");
            assert_eq!(a.contains(Vec2::new(x, y)), inside);
        }
        // How far outside: what the edges' distances say, on a grid over and around a concave
        // area, its corners and edges among the points (on the boundary counts as inside).
        let l = OpArea::new(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(40.0, 0.0),
            Vec2::new(40.0, 10.0),
            Vec2::new(10.0, 10.0),
            Vec2::new(10.0, 30.0),
            Vec2::new(0.0, 30.0),
        ])
        .unwrap();
        let (mut outside, mut on) = (0, 0);
        for i in -10..=50 {
            for j in -10..=40 {
                let p = Vec2::new(f64::from(i), f64::from(j));
                let e = l.edge_info(p);
                assert_eq!(
                    l.outside_by(p),
                    (!e.inside).then_some(e.distance_m),
                    "{p:?}"
                );
                outside += usize::from(!e.inside);
                on += usize::from(e.distance_m == 0.0);
            }
        }
        assert!(
            outside > 1000 && on > 50,
            "{outside} outside, {on} on the boundary"
        );
    }

    #[test]
    fn winding_does_not_matter_and_concave_areas_work() {
        // An L shape, clockwise.
        let l = OpArea::new(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(0.0, 20.0),
            Vec2::new(10.0, 20.0),
            Vec2::new(10.0, 10.0),
            Vec2::new(20.0, 10.0),
            Vec2::new(20.0, 0.0),
        ])
        .unwrap();
        assert!(l.contains(Vec2::new(5.0, 15.0)));
        assert!(!l.contains(Vec2::new(15.0, 15.0)));
        let e = l.edge_info(Vec2::new(15.0, 9.0));
        assert!(e.inside && (e.distance_m - 1.0).abs() < 1e-9);
        assert!(
            (e.outward_normal - Vec2::new(0.0, 1.0)).norm() < 1e-9,
            "{:?}",
            e.outward_normal
        );
        let e = l.edge_info(Vec2::new(12.0, 12.0)); // in the notch: outside
        assert!(!e.inside);
        assert!(
            e.outward_normal.dot(&Vec2::new(1.0, 1.0)) > 0.0,
            "{:?}",
            e.outward_normal
        );
    }

    #[test]
    fn rejects_degenerate_areas() {
        assert_eq!(
            OpArea::new(vec![Vec2::zeros(), Vec2::new(1.0, 0.0)]),
            Err(OpAreaError::TooFewVertices(2))
        );
        assert_eq!(
            OpArea::new(vec![
                Vec2::zeros(),
                Vec2::new(1.0, 0.0),
                Vec2::new(2.0, 0.0)
            ]),
            Err(OpAreaError::ZeroArea)
        );
        assert!(matches!(
            OpArea::new(vec![
                Vec2::zeros(),
                Vec2::new(f64::NAN, 0.0),
                Vec2::new(0.0, 1.0)
            ]),
            Err(OpAreaError::NonFinite(1))
        ));
    }

    #[test]
    fn furthest_vertex() {
        let a = OpArea::rectangle(0.0, 100.0, 0.0, 50.0).unwrap();
        assert_eq!(
            a.furthest_vertex_along(Vec2::new(1.0, -1.0)),
            Vec2::new(100.0, 0.0)
        );
    }
}
