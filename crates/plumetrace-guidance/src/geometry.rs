//! Distances to lines, in the local East/North frame.

use plumetrace_core::Vec2;

/// Signed distance from `p` to the line through `start` and `end`: positive when `p` is on the left
/// looking from `start` to `end`, negative on the right; 0 when the two ends coincide.
pub fn signed_cross_track_m(p: Vec2, start: Vec2, end: Vec2) -> f64 {
    let d = end - start;
    let len = d.norm();
    if len == 0.0 || !len.is_finite() {
        return 0.0;
    }
    let r = p - start;
    // z of the cross product d x r: positive when r is anticlockwise of d, i.e. to the left.
    (d.x * r.y - d.y * r.x) / len
}

/// Distance of `p` along the line from `start` towards `end`, measured from `end` (positive once
/// past the end: the `V . h` of eq. 10); 0 when the two ends coincide.
pub fn along_track_m(p: Vec2, start: Vec2, end: Vec2) -> f64 {
    let d = end - start;
    let len = d.norm();
    if len == 0.0 || !len.is_finite() {
        return 0.0;
    }
    (p - end).dot(&(d / len))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signed_cross_track_table() {
        let (s, e) = (Vec2::new(0.0, 0.0), Vec2::new(0.0, 10.0)); // a line heading North
        let cases = [
            ((-3.0, 5.0), 3.0),
            ((3.0, 5.0), -3.0),
            ((0.0, 7.0), 0.0),
            ((-2.0, -5.0), 2.0),
            ((4.0, 20.0), -4.0),
        ];
        for ((x, y), want) in cases {
            let got = signed_cross_track_m(Vec2::new(x, y), s, e);
            assert!((got - want).abs() < 1e-12, "({x},{y}): {got}, want {want}");
        }
        // A line heading East: left is North.
        let got = signed_cross_track_m(Vec2::new(5.0, 2.0), Vec2::zeros(), Vec2::new(10.0, 0.0));
        assert!((got - 2.0).abs() < 1e-12);
        assert_eq!(
            signed_cross_track_m(Vec2::new(1.0, 1.0), Vec2::zeros(), Vec2::zeros()),
            0.0
        );
    }

    #[test]
    fn along_track_table() {
        let (s, e) = (Vec2::new(0.0, 0.0), Vec2::new(10.0, 0.0));
        let cases = [((12.0, 3.0), 2.0), ((10.0, -1.0), 0.0), ((4.0, 0.0), -6.0)];
        for ((x, y), want) in cases {
            let got = along_track_m(Vec2::new(x, y), s, e);
            assert!((got - want).abs() < 1e-12, "({x},{y}): {got}, want {want}");
        }
    }
}
