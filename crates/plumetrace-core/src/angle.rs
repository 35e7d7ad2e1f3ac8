//! Compass headings and angle wrapping.
//!
//! A [`Heading`] is a compass direction, clockwise from North. Every angle difference is wrapped to
//! (-180, 180] degrees before it is compared or scaled.

use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// Wraps an angle in degrees to (-180, 180].
pub fn wrap_deg_180(deg: f64) -> f64 {
    let w = deg.rem_euclid(360.0);
    if w > 180.0 { w - 360.0 } else { w }
}

/// Wraps an angle in degrees to [0, 360).
pub fn wrap_deg_360(deg: f64) -> f64 {
    let w = deg.rem_euclid(360.0);
    // rem_euclid can return 360.0 for tiny negative inputs because of rounding.
    if w >= 360.0 { 0.0 } else { w }
}

/// Wraps an angle in radians to (-pi, pi].
pub fn wrap_rad_pi(rad: f64) -> f64 {
    let w = rad.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

/// A compass heading: clockwise from North, stored in radians in [0, 2 pi).
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Serialize, Deserialize)]
pub struct Heading {
    #[serde(with = "crate::any_f64")]
    rad: f64,
}

impl Heading {
    /// North.
    pub const NORTH: Heading = Heading { rad: 0.0 };

    /// A heading from compass degrees (any value; wrapped to [0, 360)).
    pub fn from_deg(deg: f64) -> Self {
        Heading {
            rad: wrap_deg_360(deg).to_radians(),
        }
    }

    /// A heading from compass radians (any value; wrapped to [0, 2 pi)).
    pub fn from_rad(rad: f64) -> Self {
        let w = rad.rem_euclid(TAU);
        Heading {
            rad: if w >= TAU { 0.0 } else { w },
        }
    }

    /// Compass degrees in [0, 360).
    pub fn deg(self) -> f64 {
        wrap_deg_360(self.rad.to_degrees())
    }

    /// Compass radians in [0, 2 pi).
    pub fn rad(self) -> f64 {
        self.rad
    }

    /// The opposite heading (e.g. upflow from the flow direction).
    pub fn reversed(self) -> Self {
        Heading::from_rad(self.rad + PI)
    }

    /// This heading turned clockwise by `deg` degrees (negative turns anticlockwise).
    pub fn turned_deg(self, deg: f64) -> Self {
        Heading::from_rad(self.rad + deg.to_radians())
    }

    /// Signed difference `self - other` in degrees, wrapped to (-180, 180]. Positive means `self`
    /// is clockwise of `other`.
    pub fn diff_deg(self, other: Heading) -> f64 {
        wrap_deg_180((self.rad - other.rad).to_degrees())
    }

    /// Unit vector `(east, north) = (sin psi, cos psi)`.
    pub fn unit(self) -> crate::Vec2 {
        crate::frame::heading_vector(self)
    }

    /// The compass heading of a non-zero `(east, north)` vector; `None` for a zero or non-finite one.
    pub fn of_vector(v: crate::Vec2) -> Option<Heading> {
        let n = v.norm();
        if n > 0.0 && n.is_finite() {
            Some(Heading::from_rad(v.x.atan2(v.y)))
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_180_table() {
        let cases = [
            (0.0, 0.0),
            (180.0, 180.0),
            (-180.0, 180.0),
            (190.0, -170.0),
            (-190.0, 170.0),
            (540.0, 180.0),
            (359.0, -1.0),
            (-721.0, -1.0),
        ];
        for (input, want) in cases {
            let got = wrap_deg_180(input);
            assert!(
                (got - want).abs() < 1e-9,
                "wrap_deg_180({input}) = {got}, want {want}"
            );
        }
    }

    #[test]
    fn wrap_360_table() {
        let cases = [
            (0.0, 0.0),
            (360.0, 0.0),
            (-1.0, 359.0),
            (725.0, 5.0),
            (-1e-15, 0.0),
        ];
        for (input, want) in cases {
            let got = wrap_deg_360(input);
            assert!(
                (got - want).abs() < 1e-9,
                "wrap_deg_360({input}) = {got}, want {want}"
            );
            assert!((0.0..360.0).contains(&got));
        }
    }

    #[test]
    fn heading_diff_is_wrapped() {
        let cases = [
            (10.0, 350.0, 20.0),
            (350.0, 10.0, -20.0),
            (180.0, 0.0, 180.0),
            (90.0, 270.0, 180.0),
        ];
        for (a, b, want) in cases {
            let got = Heading::from_deg(a).diff_deg(Heading::from_deg(b));
            assert!((got - want).abs() < 1e-9, "{a} - {b} = {got}, want {want}");
        }
    }

    #[test]
    fn heading_of_vector_table() {
        let cases = [
            ((0.0, 1.0), 0.0),
            ((1.0, 0.0), 90.0),
            ((0.0, -1.0), 180.0),
            ((-1.0, 0.0), 270.0),
            ((1.0, 1.0), 45.0),
        ];
        for ((e, n), want) in cases {
            let h = Heading::of_vector(crate::Vec2::new(e, n)).map(Heading::deg);
            let got = h.unwrap_or(f64::NAN);
            assert!(
                (got - want).abs() < 1e-9,
                "heading of ({e},{n}) = {got}, want {want}"
            );
        }
        assert!(Heading::of_vector(crate::Vec2::zeros()).is_none());
        assert!(Heading::of_vector(crate::Vec2::new(f64::NAN, 1.0)).is_none());
    }
}
