//! A safety check of the fuzzy command in the ground frame: does the course it sets, flown at the
//! vehicle's turn rate with the measured current, keep clear of what the range sensors saw?
//!
//! The fuzzy rules were written for still water; carried by a current the vehicle covers ground
//! faster than the rules expect and can be swept onto an obstacle while it holds a heading to
//! decide which side to take. [`SafetyFilter`] remembers recent returns as points in the local
//! frame and predicts, for the fuzzy heading and for a fan of other headings, the ground track over
//! the next seconds; the fuzzy heading goes out unchanged while its track keeps
//! [`SafetyParams::clearance_m`] from every remembered point, otherwise the heading nearest to it
//! whose track does (or, if none does, the one with the most clearance).
//!
//! A group's return says only that something lies at that distance somewhere in the group's
//! sector, so each return is kept as points spread over the sector at that distance (seed 001
//! eq. 8 sectors: left -90..-30 deg, front -30..30 deg, right 30..90 deg off the heading). This is
//! conservative: a sector's arc is treated as occupied along its whole width.

use plumetrace_core::{Heading, RangeReturn, Vec2};

/// Settings of the safety check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SafetyParams {
    /// Least distance a predicted track keeps from every remembered return, m.
    pub clearance_m: f64,
    /// How far ahead tracks are predicted, s.
    pub horizon_s: f64,
    /// Step of the prediction, s.
    pub step_s: f64,
    /// How long returns are remembered, s.
    pub memory_s: f64,
    /// The vehicle's turn rate in the prediction, deg/s.
    pub turn_rate_deg_s: f64,
    /// Headings tried besides the fuzzy one: every this many degrees around the current heading.
    pub fan_step_deg: f64,
}

impl Default for SafetyParams {
    fn default() -> Self {
        SafetyParams {
            clearance_m: 3.0,
            horizon_s: 6.0,
            step_s: 0.5,
            memory_s: 3.0,
            turn_rate_deg_s: 20.0,
            fan_step_deg: 15.0,
        }
    }
}

/// Sectors of the three range groups, deg off the heading: (from, to).
const SECTORS: [(f64, f64); 3] = [(-90.0, -30.0), (-30.0, 30.0), (30.0, 90.0)];
/// Points per sector arc.
const ARC_POINTS: usize = 5;

/// Remembered returns and the check.
#[derive(Debug, Clone, PartialEq)]
pub struct SafetyFilter {
    params: SafetyParams,
    /// (time, point) of every remembered return.
    points: Vec<(f64, Vec2)>,
}

impl SafetyFilter {
    /// An empty memory.
    pub fn new(params: SafetyParams) -> Self {
        SafetyFilter {
            params,
            points: Vec::new(),
        }
    }

    /// Forgets every return.
    pub fn clear(&mut self) {
        self.points.clear();
    }

    /// Remembers the returns of one ping from `pos_m` with the vehicle on `heading` at `t_s`
    /// (non-finite distances are ignored) and forgets those older than the memory.
    pub fn remember(&mut self, t_s: f64, pos_m: Vec2, heading: Heading, r: &RangeReturn) {
        let keep = self.params.memory_s;
        self.points.retain(|(t, _)| t_s - t <= keep);
        for (d, (from, to)) in [r.left_m, r.front_m, r.right_m].into_iter().zip(SECTORS) {
            let Some(d) = d.filter(|d| d.is_finite() && *d >= 0.0) else {
                continue;
            };
            for k in 0..ARC_POINTS {
                let a = from + (to - from) * k as f64 / (ARC_POINTS - 1) as f64;
                self.points
                    .push((t_s, pos_m + heading.turned_deg(a).unit() * d));
            }
        }
    }

    /// The least distance from the predicted ground track to a remembered point, m (infinite
    /// with nothing remembered): the vehicle at `pos_m` on `heading` turns towards `course` at
    /// the turn rate, at `speed_mps` through the water, carried by `flow_mps`.
    pub fn clearance_m(
        &self,
        pos_m: Vec2,
        heading: Heading,
        course: Heading,
        speed_mps: f64,
        flow_mps: Vec2,
    ) -> f64 {
        let p = self.params;
        let steps = (p.horizon_s / p.step_s).ceil().max(1.0) as usize;
        let max_turn = p.turn_rate_deg_s * p.step_s;
        let mut h = heading;
        let mut q = pos_m;
        let mut least = f64::INFINITY;
        for _ in 0..steps {
            let turn = course.diff_deg(h).clamp(-max_turn, max_turn);
            h = h.turned_deg(turn);
            q += (h.unit() * speed_mps + flow_mps) * p.step_s;
            for (_, o) in &self.points {
                least = least.min((q - o).norm());
            }
        }
        least
    }

    /// The course to fly instead of `proposed` (or `proposed` itself when its track is clear).
    pub fn check(
        &self,
        pos_m: Vec2,
        heading: Heading,
        proposed: Heading,
        speed_mps: f64,
        flow_mps: Vec2,
    ) -> Heading {
        if self.points.is_empty() || !(speed_mps.is_finite() && flow_mps.norm().is_finite()) {
            return proposed;
        }
        let need = self.params.clearance_m;
        let clear = |c: Heading| self.clearance_m(pos_m, heading, c, speed_mps, flow_mps);
        if clear(proposed) >= need {
            return proposed;
        }
        let n = (180.0 / self.params.fan_step_deg.max(1.0)).floor() as i32;
        let mut best: Option<(bool, f64, f64, Heading)> = None;
        for k in -n..=n {
            let c = heading.turned_deg(f64::from(k) * self.params.fan_step_deg);
            let room = clear(c);
            let ok = room >= need;
            let off = c.diff_deg(proposed).abs();
            // Clear ones first, nearest the proposal; else the most room.
            let better = match best {
                None => true,
                Some((bok, broom, boff, _)) => match (ok, bok) {
                    (true, false) => true,
                    (false, true) => false,
                    (true, true) => off < boff,
                    (false, false) => room > broom,
                },
            };
            if better {
                best = Some((ok, room, off, c));
            }
        }
        best.map_or(proposed, |b| b.3)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wall_ahead(f: &mut SafetyFilter, d: f64) {
        f.remember(
            0.0,
            Vec2::zeros(),
            Heading::NORTH,
            &RangeReturn {
                front_m: Some(d),
                left_m: None,
                right_m: None,
            },
        );
    }

    #[test]
    fn a_clear_course_is_kept_and_one_onto_a_return_is_turned_away() {
        let mut f = SafetyFilter::new(SafetyParams::default());
        // Nothing seen: anything goes.
        let north = Heading::NORTH;
        assert_eq!(
            f.check(Vec2::zeros(), north, north, 1.5, Vec2::zeros()),
            north
        );
        // Something 8 m ahead in still water: straight on reaches it within 6 s at 1.5 m/s
        // (9 m): turned away, onto a course that keeps 2 m from it.
        wall_ahead(&mut f, 8.0);
        let c = f.check(Vec2::zeros(), north, north, 1.5, Vec2::zeros());
        assert!(c.diff_deg(north).abs() >= 15.0, "{}", c.deg());
        let room = f.clearance_m(Vec2::zeros(), north, c, 1.5, Vec2::zeros());
        assert!(room >= 2.0, "{room}");
        // A current from behind makes a farther return dangerous too.
        let mut g = SafetyFilter::new(SafetyParams::default());
        wall_ahead(&mut g, 14.0);
        assert_eq!(
            g.check(Vec2::zeros(), north, north, 1.5, Vec2::zeros()),
            north
        );
        let c = g.check(Vec2::zeros(), north, north, 1.5, Vec2::new(0.0, 1.0));
        assert!(c.diff_deg(north).abs() >= 15.0, "{}", c.deg());
    }

    #[test]
    fn returns_are_forgotten_after_the_memory() {
        let mut f = SafetyFilter::new(SafetyParams::default());
        wall_ahead(&mut f, 8.0);
        let north = Heading::NORTH;
        let empty = RangeReturn::default();
        f.remember(5.0, Vec2::zeros(), north, &empty);
        assert_eq!(
            f.check(Vec2::zeros(), north, north, 1.5, Vec2::zeros()),
            north
        );
    }
}
