//! The local tangent frame: `x` East, `y` North, `z` height above the seabed.

use crate::Heading;

/// A horizontal vector or position `(east, north)` in metres (or m/s for velocities).
pub type Vec2 = nalgebra::Vector2<f64>;

/// A 3-D vector or position `(east, north, up)`; for positions `z` is the height above the seabed.
pub type Vec3 = nalgebra::Vector3<f64>;

/// Unit vector of a compass heading: `(east, north) = (sin psi, cos psi)`.
pub fn heading_vector(h: Heading) -> Vec2 {
    let (s, c) = h.rad().sin_cos();
    Vec2::new(s, c)
}

/// Compass bearing from `from` to `to`; `None` when the two points coincide.
pub fn bearing_between(from: Vec2, to: Vec2) -> Option<Heading> {
    Heading::of_vector(to - from)
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
