//! The Bowtie of Reacquire: two lines crossing at a centre, angled +-15 degrees to upflow.

use plumetrace_core::{Heading, Vec2};

/// The geometry of one Bowtie.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bowtie {
    /// Centre, m.
    pub centre_m: Vec2,
    /// First line: start and end (through the centre), on the side the vehicle is estimated to be.
    pub first: (Vec2, Vec2),
    /// Second line: start and end (through the centre), angled the other way.
    pub second: (Vec2, Vec2),
}

impl Bowtie {
    /// A Bowtie about `centre_m` for upflow direction `upflow`, with lines `angle_deg` off upflow
    /// reaching `half_width_m` across the flow on each side. `lhs` (+1: the vehicle is on the left
    /// looking upflow, -1: on the right) picks which line comes first: the one that starts on the
    /// vehicle's side. For `lhs = -1` the first line is at -15 deg to upflow, as in the field
    /// description.
    pub fn new(
        centre_m: Vec2,
        upflow: Heading,
        lhs: f64,
        angle_deg: f64,
        half_width_m: f64,
    ) -> Self {
        let half_len = half_width_m / angle_deg.to_radians().sin().abs().max(1e-6);
        let side = if lhs >= 0.0 { 1.0 } else { -1.0 };
        let line = |sign: f64| {
            let dir = upflow.turned_deg(sign * angle_deg).unit();
            (centre_m - dir * half_len, centre_m + dir * half_len)
        };
        // A line turned clockwise from upflow (to the right looking upflow) starts on the left.
        Bowtie {
            centre_m,
            first: line(side),
            second: line(-side),
        }
    }
}

/// The Bowtie centres for one lost point: the first `offset_m` upflow of it, the last on it, the
/// others evenly spaced between (`n >= 2`; `n = 1` gives the lost point itself).
pub fn centres(lost_point: Vec2, upflow: Heading, offset_m: f64, n: usize) -> Vec<Vec2> {
    let u = upflow.unit();
    if n <= 1 {
        return vec![lost_point];
    }
    (0..n)
        .map(|k| lost_point + u * (offset_m * (n - 1 - k) as f64 / (n - 1) as f64))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_guidance::signed_cross_track_m;

    #[test]
    fn centres_run_from_10_m_upflow_to_the_point() {
        // Flow towards North: upflow is South.
        let c = centres(Vec2::new(5.0, 100.0), Heading::from_deg(180.0), 10.0, 2);
        assert_eq!(c.len(), 2);
        assert!(
            (c[0] - Vec2::new(5.0, 90.0)).norm() < 1e-9
                && (c[1] - Vec2::new(5.0, 100.0)).norm() < 1e-9,
            "{c:?}"
        );
        let c = centres(Vec2::new(0.0, 0.0), Heading::from_deg(180.0), 10.0, 3);
        assert!((c[1] - Vec2::new(0.0, -5.0)).norm() < 1e-12);
    }

    #[test]
    fn legs_are_where_the_paper_puts_them() {
        let up = Heading::from_deg(180.0); // flow towards North
        let centre = Vec2::new(0.0, 0.0);
        // Vehicle on the right looking upflow (looking South, right is West): first line at -15.
        let b = Bowtie::new(centre, up, -1.0, 15.0, 13.0);
        let (s, e) = b.first;
        let h = Heading::of_vector(e - s).unwrap();
        assert!(
            h.diff_deg(up.turned_deg(-15.0)).abs() < 1e-9,
            "first line heading {}",
            h.deg()
        );
        assert!(
            s.x < 0.0,
            "first line starts on the West (right) side: {s:?}"
        );
        // Both lines pass through the centre and reach 13 m across the flow on each side.
        for (s, e) in [b.first, b.second] {
            assert!(signed_cross_track_m(centre, s, e).abs() < 1e-9);
            assert!(
                (s.x.abs() - 13.0).abs() < 1e-9 && (e.x.abs() - 13.0).abs() < 1e-9,
                "{s:?} {e:?}"
            );
            assert!(s.y > e.y, "lines run upflow (southwards)");
        }
        let h2 = Heading::of_vector(b.second.1 - b.second.0).unwrap();
        assert!(h2.diff_deg(up.turned_deg(15.0)).abs() < 1e-9);
        // On the left: mirrored.
        let l = Bowtie::new(centre, up, 1.0, 15.0, 13.0);
        assert!(l.first.0.x > 0.0);
    }
}
