//! Position fixes as the AMP sees them in its own navigation records (`fix_smoothing`): the jump
//! each fix makes, and the share of it that a point saved since the fix before carried as its own
//! navigation error.
//!
//! Between fixes a dead-reckoned estimate drifts away from the truth; a fix puts it back within
//! the fix's own error, and the jump it makes is the new fix's error less the stretch's own error
//! (the fix before's, and the drift since). A point saved part-way through carries the fix
//! before's error and the drift of its own moment, so the jump tells how far it was off: under
//! Gaussian errors ([`DriftModel`]) the expected error given the jump is a share of the jump.
//! The drift has two parts the planner can place in time: a dead-reckoning velocity error that
//! holds over a stretch (its share grows with the time since the fix before), and the drift
//! while the current meter's readings are held back (a wrong-layer meter reading the current
//! reversed: the vehicle dead-reckons with the last plausible reading and drifts by however much
//! the current has changed since, tens of metres in a quarter of an hour).

use plumetrace_core::{NavEstimate, Vec2};

/// The longest gap between two navigation records across which a fix's jump is measured: over a
/// longer one the motion between them is not known well enough to tell the jump from it.
const MAX_RECORD_GAP_S: f64 = 5.0;

/// What the smoothing assumes of the navigation's errors, each a standard deviation per axis:
/// a fix's own error, the dead-reckoning drift between fixes (a velocity error that holds over a
/// stretch) and the drift while flow readings are held back. A point saved part-way through a
/// stretch is moved by the share of the next fix's jump that, under these errors, is its own
/// error: the conditional mean of the error given the jump (with only the held-back drift, the
/// share of the held-back time that had passed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct DriftModel {
    /// A fix's error, m.
    pub fix_m: f64,
    /// The drift rate between fixes, m/s.
    pub drift_mps: f64,
    /// The drift rate while flow readings are held back, m/s.
    pub held_back_mps: f64,
}

impl DriftModel {
    /// Whether a fix moves points of a stretch without held-back readings: a held point then
    /// waits for the fix that ends its stretch.
    pub fn moves_every_stretch(&self) -> bool {
        self.fix_m > 0.0 || self.drift_mps > 0.0
    }
}

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
    /// Whether the stretch began at a fix (false: at the first record, where the navigation
    /// starts on the truth, without a fix's error).
    pub after_fix: bool,
}

impl Fix {
    /// The share of the jump that a point saved at `t_s`, `held_back_s` into the stretch's
    /// held-back time, carried as its own error under `model`: 0 for a point from before the
    /// stretch, and for every point of a stretch in which nothing the model holds could err.
    pub fn share(&self, t_s: f64, held_back_s: f64, model: &DriftModel) -> f64 {
        if t_s < self.since_s {
            return 0.0;
        }
        let (t, span) = (t_s - self.since_s, self.t_s - self.since_s);
        let (h, held) = (held_back_s, self.held_back_s);
        let fix_var = model.fix_m * model.fix_m;
        let (dv, hv) = (
            model.drift_mps * model.drift_mps,
            model.held_back_mps * model.held_back_mps,
        );
        // The point's error is the stretch's starting fix error plus the drift by then; the
        // jump is the new fix's error less the stretch's whole error.
        let start_var = if self.after_fix { fix_var } else { 0.0 };
        let covariance = start_var + dv * t * span + hv * h * held;
        let jump_var = start_var + fix_var + dv * span * span + hv * held * held;
        let share = covariance / jump_var;
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
                        after_fix: self.count > 1,
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
        let m = &HELD_BACK_ONLY;
        assert_eq!(fix.share(5.0, 0.0, m), 0.0);
        assert!((fix.share(15.0, 5.0, m) - 0.5).abs() < 1e-12);
        assert_eq!(fix.share(25.0, 10.0, m), 1.0);
        // A point from before the stretch (an earlier one) is not moved.
        assert_eq!(fix.share(-1.0, 0.0, m), 0.0);
        assert!(!fix.after_fix);
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

    /// Only the drift while readings are held back.
    const HELD_BACK_ONLY: DriftModel = DriftModel {
        fix_m: 0.0,
        drift_mps: 0.0,
        held_back_mps: 0.03,
    };

    #[test]
    fn with_only_held_back_drift_a_stretch_without_it_moves_nothing() {
        let fix = Fix {
            t_s: 100.0,
            jump_m: Vec2::new(1.0, 0.0),
            since_s: 60.0,
            held_back_s: 0.0,
            after_fix: true,
        };
        assert!(!HELD_BACK_ONLY.moves_every_stretch());
        for t in [60.0, 90.0, 100.0] {
            assert_eq!(fix.share(t, 0.0, &HELD_BACK_ONLY), 0.0);
        }
    }

    #[test]
    fn the_share_is_the_error_the_jump_implies() {
        let fix = |after_fix| Fix {
            t_s: 700.0,
            jump_m: Vec2::new(1.0, 0.0),
            since_s: 100.0,
            held_back_s: 0.0,
            after_fix,
        };
        let drift = DriftModel {
            fix_m: 0.0,
            drift_mps: 0.01,
            held_back_mps: 0.03,
        };
        let fixes = DriftModel {
            fix_m: 4.0,
            drift_mps: 0.0,
            held_back_mps: 0.03,
        };
        let both = DriftModel {
            fix_m: 4.0,
            drift_mps: 0.01,
            held_back_mps: 0.03,
        };
        assert!(drift.moves_every_stretch() && fixes.moves_every_stretch());
        // A drift alone grows with time: the share is the time that had passed.
        assert!((fix(true).share(400.0, 0.0, &drift) - 0.5).abs() < 1e-12);
        assert!((fix(true).share(250.0, 0.0, &drift) - 0.25).abs() < 1e-12);
        // Fix errors alone: half the jump is the fix before's error, at any time...
        assert!((fix(true).share(150.0, 0.0, &fixes) - 0.5).abs() < 1e-12);
        assert!((fix(true).share(650.0, 0.0, &fixes) - 0.5).abs() < 1e-12);
        // ...but the first stretch starts on the truth: none of it was.
        assert_eq!(fix(false).share(400.0, 0.0, &fixes), 0.0);
        // Both: (16 + 1e-4 * 300 * 600) / (32 + 1e-4 * 600^2) = 34 / 68 at mid-stretch, and
        // 16 / 68 at its start.
        assert!((fix(true).share(400.0, 0.0, &both) - 0.5).abs() < 1e-12);
        assert!((fix(true).share(100.0, 0.0, &both) - 16.0 / 68.0).abs() < 1e-12);
    }

    /// A small deterministic generator (the test needs no crate for it).
    fn normal(state: &mut u64) -> f64 {
        let mut uniform = || {
            *state ^= *state << 13;
            *state ^= *state >> 7;
            *state ^= *state << 17;
            (*state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (u1, u2) = (uniform().max(1e-300), uniform());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }

    #[test]
    fn moved_points_are_nearer_the_truth_than_as_saved() {
        // Stretches of 600 s between fixes of 4 m error with a velocity error of 1 cm/s that
        // holds over each: the error of a point saved at a random time, as saved and as moved.
        let model = DriftModel {
            fix_m: 4.0,
            drift_mps: 0.01,
            held_back_mps: 0.03,
        };
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let (mut saved, mut moved) = (0.0, 0.0);
        let n = 20_000;
        for k in 0..n {
            let start_error = normal(&mut state) * 4.0;
            let velocity = normal(&mut state) * 0.01;
            let new_fix_error = normal(&mut state) * 4.0;
            let t = 600.0 * f64::from(k % 97) / 96.0;
            let error = start_error + velocity * t;
            let jump = new_fix_error - (start_error + velocity * 600.0);
            let fix = Fix {
                t_s: 600.0,
                jump_m: Vec2::new(jump, 0.0),
                since_s: 0.0,
                held_back_s: 0.0,
                after_fix: true,
            };
            saved += error * error;
            let e = error + fix.share(t, 0.0, &model) * jump;
            moved += e * e;
        }
        let (saved, moved) = ((saved / f64::from(n)).sqrt(), (moved / f64::from(n)).sqrt());
        // Expected: 5.3 m as saved (16 + 1e-4 E[t^2] = 28 m^2) and 3.1 m as moved (28 less
        // E[(16 + 0.06 t)^2] / 68 = 18.6 m^2).
        assert!(
            moved < 0.7 * saved,
            "as saved {saved:.2} m, as moved {moved:.2} m"
        );
        assert!(
            moved > 2.5,
            "as moved {moved:.2} m: below what the fixes' errors allow"
        );
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
