//! The simulated region: an axis-aligned rectangle in the local frame.

use crate::error::{EnvError, require_finite};
use plumetrace_core::Vec2;
use serde::{Deserialize, Serialize};

/// An axis-aligned rectangle `[x_min, x_max] x [y_min, y_max]`, metres East and North.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rect {
    /// West edge, m.
    pub x_min_m: f64,
    /// East edge, m.
    pub x_max_m: f64,
    /// South edge, m.
    pub y_min_m: f64,
    /// North edge, m.
    pub y_max_m: f64,
}

impl Rect {
    /// A rectangle, checked to have a finite, non-zero extent on both axes.
    pub fn new(x_min_m: f64, x_max_m: f64, y_min_m: f64, y_max_m: f64) -> Result<Self, EnvError> {
        for (k, v) in [
            ("x_min_m", x_min_m),
            ("x_max_m", x_max_m),
            ("y_min_m", y_min_m),
            ("y_max_m", y_max_m),
        ] {
            require_finite(k, v)?;
        }
        if x_max_m <= x_min_m {
            return Err(EnvError::invalid(
                "x_max_m",
                format!("must be > x_min_m ({x_min_m}), got {x_max_m}"),
            ));
        }
        if y_max_m <= y_min_m {
            return Err(EnvError::invalid(
                "y_max_m",
                format!("must be > y_min_m ({y_min_m}), got {y_max_m}"),
            ));
        }
        Ok(Rect {
            x_min_m,
            x_max_m,
            y_min_m,
            y_max_m,
        })
    }

    /// East-West extent, m.
    pub fn width_m(&self) -> f64 {
        self.x_max_m - self.x_min_m
    }

    /// North-South extent, m.
    pub fn height_m(&self) -> f64 {
        self.y_max_m - self.y_min_m
    }

    /// Whether `(x, y)` lies inside or on the edge.
    #[inline]
    pub fn contains_xy(&self, x: f64, y: f64) -> bool {
        x >= self.x_min_m && x <= self.x_max_m && y >= self.y_min_m && y <= self.y_max_m
    }

    /// Whether `p` lies inside or on the edge.
    pub fn contains(&self, p: Vec2) -> bool {
        self.contains_xy(p.x, p.y)
    }

    /// The four corners, counter-clockwise from South-West.
    pub fn corners(&self) -> [Vec2; 4] {
        [
            Vec2::new(self.x_min_m, self.y_min_m),
            Vec2::new(self.x_max_m, self.y_min_m),
            Vec2::new(self.x_max_m, self.y_max_m),
            Vec2::new(self.x_min_m, self.y_max_m),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_zero_size() {
        assert!(Rect::new(0.0, 0.0, 0.0, 1.0).is_err());
        assert!(Rect::new(0.0, 1.0, 5.0, 5.0).is_err());
        assert!(Rect::new(0.0, f64::NAN, 0.0, 1.0).is_err());
        let r = Rect::new(0.0, 100.0, -50.0, 50.0).map(|r| r.width_m() * r.height_m());
        assert_eq!(r.ok(), Some(10_000.0));
    }
}
