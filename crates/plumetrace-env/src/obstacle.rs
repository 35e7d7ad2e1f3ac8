//! Soft obstacles: regions the vehicles must not enter but chemical passes through (kelp).
//!
//! The plume never sees obstacles; vehicles and range sensors do, through [`ObstacleSet`].

use crate::error::EnvError;
use geo::{Contains, Coord, Distance, Euclidean, Line, LineString, Point, Polygon};
use plumetrace_core::{Heading, Vec2};

/// One obstacle: a simple polygon in the local frame.
#[derive(Debug, Clone, PartialEq)]
pub struct SoftObstacle {
    /// A name for logs and plots.
    pub name: String,
    /// The outline.
    pub polygon: Polygon<f64>,
}

impl SoftObstacle {
    /// An obstacle from its vertices `(east, north)` in order (closed automatically): a simple
    /// polygon ([`plumetrace_core::check_polygon`]); errors name `vertices`.
    pub fn new(name: impl Into<String>, vertices: &[[f64; 2]]) -> Result<Self, EnvError> {
        let points: Vec<Vec2> = vertices.iter().map(|v| Vec2::new(v[0], v[1])).collect();
        plumetrace_core::check_polygon(&points, false)
            .map_err(|e| EnvError::from(e).under("vertices"))?;
        let ring: Vec<Coord<f64>> = vertices
            .iter()
            .map(|v| Coord { x: v[0], y: v[1] })
            .collect();
        Ok(SoftObstacle {
            name: name.into(),
            polygon: Polygon::new(LineString::from(ring), vec![]),
        })
    }

    /// Whether `p` is inside it (as [`ObstacleSet::contains`] counts a collision).
    pub fn contains(&self, p: Vec2) -> bool {
        self.polygon.contains(&Point::new(p.x, p.y))
    }
}

/// All obstacles of a world.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ObstacleSet {
    obstacles: Vec<SoftObstacle>,
}

impl ObstacleSet {
    /// A set of obstacles.
    pub fn new(obstacles: Vec<SoftObstacle>) -> Self {
        ObstacleSet { obstacles }
    }

    /// The obstacles.
    pub fn iter(&self) -> impl Iterator<Item = &SoftObstacle> {
        self.obstacles.iter()
    }

    /// Whether there are no obstacles.
    pub fn is_empty(&self) -> bool {
        self.obstacles.is_empty()
    }

    /// Whether `p` is inside any obstacle.
    pub fn contains(&self, p: Vec2) -> bool {
        let pt = Point::new(p.x, p.y);
        self.obstacles.iter().any(|o| o.polygon.contains(&pt))
    }

    /// Distance from `p` to the nearest obstacle (0 inside one); `None` without obstacles.
    pub fn distance_m(&self, p: Vec2) -> Option<f64> {
        let pt = Point::new(p.x, p.y);
        self.obstacles
            .iter()
            .map(|o| Euclidean.distance(&pt, &o.polygon))
            .min_by(f64::total_cmp)
    }

    /// Distance along a ray from `origin` on `heading` to the first obstacle edge within
    /// `max_range_m`, as a range sensor's beam would see it.
    pub fn ray_range_m(&self, origin: Vec2, heading: Heading, max_range_m: f64) -> Option<f64> {
        let mut best: Option<f64> = None;
        self.ray_hits(origin, heading, max_range_m, |_, d| {
            best = Some(best.map_or(d, |b: f64| b.min(d)));
        });
        best
    }

    /// Calls `hit(k, d)` for every obstacle `k` the ray from `origin` on `heading` meets within
    /// `max_range_m`, with `d` the distance to its nearest edge on the ray (obstacles in order).
    pub fn ray_hits(
        &self,
        origin: Vec2,
        heading: Heading,
        max_range_m: f64,
        mut hit: impl FnMut(usize, f64),
    ) {
        let end = origin + heading.unit() * max_range_m;
        let beam = Line::new(
            Coord {
                x: origin.x,
                y: origin.y,
            },
            Coord { x: end.x, y: end.y },
        );
        for (k, o) in self.obstacles.iter().enumerate() {
            let nearest = o
                .polygon
                .exterior()
                .lines()
                .filter_map(|edge| segment_hit(&beam, &edge))
                .map(|h| (Vec2::new(h.x, h.y) - origin).norm())
                .min_by(f64::total_cmp);
            if let Some(d) = nearest {
                hit(k, d);
            }
        }
    }
}

/// First point where segment `a` meets segment `b` (nearest to `a.start` when collinear).
fn segment_hit(a: &Line<f64>, b: &Line<f64>) -> Option<Coord<f64>> {
    use geo::line_intersection::{LineIntersection, line_intersection};
    match line_intersection(*a, *b)? {
        LineIntersection::SinglePoint { intersection, .. } => Some(intersection),
        LineIntersection::Collinear { intersection } => {
            let (p, q) = (intersection.start, intersection.end);
            let dp = (p.x - a.start.x).hypot(p.y - a.start.y);
            let dq = (q.x - a.start.x).hypot(q.y - a.start.y);
            Some(if dp <= dq { p } else { q })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kelp() -> ObstacleSet {
        ObstacleSet::new(vec![
            SoftObstacle::new(
                "kelp",
                &[[10.0, -5.0], [20.0, -5.0], [20.0, 5.0], [10.0, 5.0]],
            )
            .unwrap(),
        ])
    }

    #[test]
    fn contains_and_distance() {
        let k = kelp();
        assert!(k.contains(Vec2::new(15.0, 0.0)));
        assert!(!k.contains(Vec2::new(5.0, 0.0)));
        assert!((k.distance_m(Vec2::new(5.0, 0.0)).unwrap() - 5.0).abs() < 1e-9);
        assert!(ObstacleSet::default().distance_m(Vec2::zeros()).is_none());
    }

    #[test]
    fn ray_ranges_table() {
        let k = kelp();
        let o = Vec2::new(0.0, 0.0);
        let cases = [
            (90.0, 30.0, Some(10.0)),
            (90.0, 8.0, None),
            (270.0, 30.0, None),
            (0.0, 30.0, None),
        ];
        for (hdg, range, want) in cases {
            let got = k.ray_range_m(o, Heading::from_deg(hdg), range);
            match (got, want) {
                (Some(g), Some(w)) => assert!((g - w).abs() < 1e-9, "heading {hdg}: {g} vs {w}"),
                (None, None) => {}
                _ => panic!("heading {hdg} range {range}: got {got:?}, want {want:?}"),
            }
        }
    }

    #[test]
    fn rejects_degenerate_polygons() {
        let cases = [
            (
                vec![[0.0, 0.0], [1.0, 1.0]],
                "vertices: needs at least 3 vertices, got 2",
            ),
            (
                vec![[0.0, 0.0], [1.0, f64::NAN], [1.0, 1.0]],
                "vertices[1]: is not finite",
            ),
            (
                vec![[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]],
                "vertices: the polygon crosses itself: edges 0 and 2 meet (edge k runs from \
                 vertex k to the next)",
            ),
        ];
        for (vertices, want) in cases {
            let e = SoftObstacle::new("x", &vertices)
                .unwrap_err()
                .under("obstacles[2]")
                .to_string();
            assert_eq!(e, format!("obstacles[2].{want}"));
        }
    }
}
