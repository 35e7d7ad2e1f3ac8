//! Position fixes as the AMP sees them in its own navigation records (`fix_smoothing`): the jump
//! each fix makes, and the share of it that a lost point saved since the fix before had drifted
//! by when it was saved.
//!
//! Between fixes a dead-reckoned estimate drifts away from the truth; a fix puts it back (within
//! the fix's own error), and the jump it makes is, less that error, the drift accumulated since
//! the fix before. A lost point saved part-way through carries the drift of its own moment. The
//! drift the planner can place in time is the one while its current meter's readings are held
//! back (a wrong-layer meter reading the current reversed): a vehicle that dead-reckons with the
//! last plausible reading then drifts by however much the current has changed since, tens of
//! metres in a quarter of an hour, and little outside such a stretch. So a point's share is the
//! fraction of the held-back time since the fix before that had passed when it was saved; a
//! stretch without held-back readings moves nothing (spread over the time instead, the jumps,
//! mostly the fixes' own errors there, moved the declarations of the coastal and Duck-like
//! tuning sites no closer to their sources).

use plumetrace_core::{NavEstimate, Vec2};

/// The longest gap between two navigation records across which a fix's jump is measured: over a
/// longer one the motion between them is not known well enough to tell the jump from it.
const MAX_RECORD_GAP_S: f64 = 5.0;

/// One fix seen in the navigation records.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Fix {
    /// When the estimate jumped, s.
    pub t_s: f64,
    /// The jump less the motion the two records before it show, m.
    pub jump_m: Vec2,
    /// When the stretch the fix ends began (the fix before, or the first record), s.
    pub since_s: f64,
    /// Time the flow reading was held back in that stretch, s.
    pub held_back_s: f64,
}

impl Fix {
    /// The share of the jump by which a point saved at `t_s`, `held_back_s` into the stretch's
    /// held-back time, had drifted: 0 for a point from before the stretch, and for every point
    /// of a stretch in which no reading was held back.
    pub fn share(&self, t_s: f64, held_back_s: f64) -> f64 {
        if t_s < self.since_s {
            return 0.0;
        }
        let share = if self.held_back_s > 0.0 {
            held_back_s / self.held_back_s
        } else {
            0.0
        };
        if share.is_finite() {
            share.clamp(0.0, 1.0)
        } else {
            0.0
        }
    }
}

/// Watches the navigation records for fixes.
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct FixWatch {
    /// The two records before this one: time and position.
    last: Option<(f64, Vec2)>,
    before: Option<(f64, Vec2)>,
    /// The time of the last fix the navigation reported.
    last_fix_s: Option<f64>,
    /// When the current stretch began.
    since_s: Option<f64>,
    /// Time the flow reading was held back since then.
    held_back_s: f64,
    /// The last record at which it was, since then.
    last_held_back_s: Option<f64>,
    /// When the declaration first waited for a fix, since the last fix.
    first_wait_s: Option<f64>,
    /// How many fixes the navigation has reported.
    count: u64,
}

impl FixWatch {
    /// Held-back time since the last fix (or the first record), s.
    pub fn held_back_s(&self) -> f64 {
        self.held_back_s
    }

    /// How many fixes the navigation has reported so far: the frame the positions of now are in
    /// (each fix puts the estimate back on the truth within its own error, a new one each time).
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Whether a declaration checked at `t_s` waits for the next fix: flow readings were held
    /// back since the last fix (the navigation may have drifted with them), the navigation has
    /// reported a fix before (one that reports none gives nothing to wait for), and the wait,
    /// counted from the first check that waited since the last fix, has lasted at most `wait_s`.
    pub fn awaiting_fix(&mut self, t_s: f64, wait_s: f64) -> bool {
        if self.last_held_back_s.is_none() || self.last_fix_s.is_none() {
            return false;
        }
        let first = *self.first_wait_s.get_or_insert(t_s);
        t_s - first <= wait_s
    }

    /// Takes the navigation record at `t_s`, with `held_back` telling whether the flow reading
    /// is being held back now; returns the fix made since the record before, if one was and its
    /// jump can be measured. Records without a position or not finite are skipped.
    pub fn observe(&mut self, t_s: f64, nav: &NavEstimate, held_back: bool) -> Option<Fix> {
        let pos = nav.pos_m?;
        if !(t_s.is_finite() && pos.x.is_finite() && pos.y.is_finite()) {
            return None;
        }
        if let Some((t1, _)) = self.last {
            let dt = t_s - t1;
            if held_back && dt > 0.0 && dt <= MAX_RECORD_GAP_S {
                self.held_back_s += dt;
                self.last_held_back_s = Some(t_s);
            }
        }
        let since = *self.since_s.get_or_insert(t_s);
        let fixed = nav
            .last_fix_s
            .is_some_and(|f| f.is_finite() && self.last_fix_s.is_none_or(|l| f > l));
        let mut fix = None;
        if fixed {
            self.last_fix_s = nav.last_fix_s;
            self.count += 1;
            if let (Some((t0, p0)), Some((t1, p1))) = (self.before, self.last) {
                let (d01, d1) = (t1 - t0, t_s - t1);
                if d01 > 0.0 && d1 > 0.0 && d01 <= MAX_RECORD_GAP_S && d1 <= MAX_RECORD_GAP_S {
                    let moved = (p1 - p0) * (d1 / d01);
                    fix = Some(Fix {
                        t_s,
                        jump_m: (pos - p1) - moved,
                        since_s: since,
                        held_back_s: self.held_back_s,
                    });
                }
            }
            self.since_s = Some(t_s);
            self.held_back_s = 0.0;
            self.last_held_back_s = None;
            self.first_wait_s = None;
        }
        self.before = self.last.replace((t_s, pos));
        fix
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_core::Heading;

    fn nav(pos: Vec2, last_fix_s: Option<f64>) -> NavEstimate {
        NavEstimate {
            pos_m: Some(pos),
            heading: Heading::NORTH,
            speed_mps: 1.0,
            altitude_m: None,
            depth_m: None,
            last_fix_s,
        }
    }

    #[test]
    fn a_fix_jump_is_measured_against_the_motion_and_shared_by_held_back_time() {
        let mut w = FixWatch::default();
        // Northward at 1 m/s, records every 0.5 s; readings held back from 10 s to 20 s.
        let mut fix = None;
        for k in 0..=60 {
            let t = f64::from(k) * 0.5;
            let mut pos = Vec2::new(0.0, t);
            let last_fix = (t >= 30.0).then_some(30.0);
            if t >= 30.0 {
                pos += Vec2::new(4.0, -3.0);
            }
            let f = w.observe(t, &nav(pos, last_fix), (10.0..20.0).contains(&t));
            assert_eq!(f.is_some(), t == 30.0, "t = {t}");
            fix = fix.or(f);
        }
        let fix = fix.unwrap();
        assert!((fix.jump_m - Vec2::new(4.0, -3.0)).norm() < 1e-9);
        assert_eq!(fix.since_s, 0.0);
        assert!((fix.held_back_s - 10.0).abs() < 1e-9);
        // Before the stretch, at its start, half-way through it and after it.
        assert_eq!(fix.share(5.0, 0.0), 0.0);
        assert!((fix.share(15.0, 5.0) - 0.5).abs() < 1e-12);
        assert_eq!(fix.share(25.0, 10.0), 1.0);
        // A point from before the stretch (an earlier one) is not moved.
        assert_eq!(fix.share(-1.0, 0.0), 0.0);
        // The next stretch starts at the fix, with nothing held back and no fix awaited.
        assert_eq!(w.held_back_s(), 0.0);
        assert!(!w.awaiting_fix(31.0, 600.0));
    }

    #[test]
    fn a_fix_is_awaited_for_a_while_after_readings_were_held_back() {
        let mut w = FixWatch::default();
        for k in 0..=40 {
            let t = f64::from(k);
            w.observe(t, &nav(Vec2::new(0.0, t), None), (10.0..20.0).contains(&t));
        }
        // Readings were held back, but no fix has been reported yet: nothing to wait for.
        assert!(!w.awaiting_fix(40.0, 600.0));
        let mut w = FixWatch::default();
        for k in 0..=40 {
            let t = f64::from(k);
            let fix = (k >= 5).then_some(5.0);
            w.observe(t, &nav(Vec2::new(0.0, t), fix), (10.0..20.0).contains(&t));
        }
        // Counted from the first check that waited (at 40 s).
        assert!(w.awaiting_fix(40.0, 600.0));
        assert!(w.awaiting_fix(640.0, 600.0));
        assert!(!w.awaiting_fix(640.5, 600.0));
        // A fix ends the wait.
        assert!(
            w.observe(41.0, &nav(Vec2::new(3.0, 41.0), Some(41.0)), false)
                .is_some()
        );
        assert!(!w.awaiting_fix(42.0, 600.0));
    }

    #[test]
    fn without_a_held_back_stretch_nothing_moves() {
        let fix = Fix {
            t_s: 100.0,
            jump_m: Vec2::new(1.0, 0.0),
            since_s: 60.0,
            held_back_s: 0.0,
        };
        for t in [60.0, 90.0, 100.0] {
            assert_eq!(fix.share(t, 0.0), 0.0);
        }
    }

    #[test]
    fn a_gap_in_the_records_leaves_the_jump_unmeasured() {
        let mut w = FixWatch::default();
        assert!(w.observe(0.0, &nav(Vec2::zeros(), None), false).is_none());
        assert!(
            w.observe(1.0, &nav(Vec2::new(0.0, 1.0), None), false)
                .is_none()
        );
        // Eight seconds of silence, then a fix.
        let f = w.observe(9.0, &nav(Vec2::new(5.0, 9.0), Some(9.0)), false);
        assert!(f.is_none());
        // The fix still starts a stretch: the next one is measured from it.
        assert!(
            w.observe(9.5, &nav(Vec2::new(5.0, 9.5), Some(9.0)), false)
                .is_none()
        );
        let f = w.observe(10.0, &nav(Vec2::new(7.0, 10.0), Some(10.0)), false);
        let f = f.unwrap();
        assert_eq!(f.since_s, 9.0);
        assert!((f.jump_m - Vec2::new(2.0, 0.0)).norm() < 1e-9);
        // Records without a position, or not finite, are skipped.
        let none = NavEstimate {
            pos_m: None,
            ..nav(Vec2::zeros(), None)
        };
        assert!(w.observe(11.0, &none, false).is_none());
        assert!(
            w.observe(f64::NAN, &nav(Vec2::zeros(), Some(12.0)), false)
                .is_none()
        );
    }
}
