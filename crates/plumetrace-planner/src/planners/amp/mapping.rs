//! Post-declaration mapping: parallel lines centred on the declared source, flown with Follow Line.

use plumetrace_core::{Heading, Vec2};

/// A lawnmower of `lines` parallel lines along the flow, `spacing_m` apart and `length_m` long,
/// centred on the declared source (the pattern a sidescan survey of the source would fly).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MappingParams {
    /// Number of lines.
    pub lines: usize,
    /// Line length, m.
    pub length_m: f64,
    /// Spacing between lines, m.
    pub spacing_m: f64,
}

impl MappingParams {
    /// The lines as `(start, end)` pairs, alternating direction, for flow towards `flow_toward`.
    pub fn legs(&self, centre_m: Vec2, flow_toward: Heading) -> Vec<(Vec2, Vec2)> {
        let along = flow_toward.unit();
        let across = flow_toward.turned_deg(90.0).unit();
        let n = self.lines.max(1);
        (0..n)
            .map(|k| {
                let offset = (k as f64 - (n - 1) as f64 / 2.0) * self.spacing_m;
                let mid = centre_m + across * offset;
                let (a, b) = (
                    mid - along * (self.length_m / 2.0),
                    mid + along * (self.length_m / 2.0),
                );
                if k % 2 == 0 { (a, b) } else { (b, a) }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lawnmower_is_centred_and_alternates() {
        let legs = MappingParams {
            lines: 3,
            length_m: 100.0,
            spacing_m: 20.0,
        }
        .legs(Vec2::new(10.0, 10.0), Heading::NORTH);
        assert_eq!(legs.len(), 3);
        assert_eq!(legs[0], (Vec2::new(-10.0, -40.0), Vec2::new(-10.0, 60.0)));
        assert_eq!(legs[1], (Vec2::new(10.0, 60.0), Vec2::new(10.0, -40.0)));
        let mean = legs.iter().fold(Vec2::zeros(), |a, (s, e)| a + s + e) / 6.0;
        assert!((mean - Vec2::new(10.0, 10.0)).norm() < 1e-12);
    }
}
