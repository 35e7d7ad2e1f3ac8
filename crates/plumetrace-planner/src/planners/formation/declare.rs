//! The formation's confirmed declaration: from the along-flow profile each member sensed, not
//! from a lull in time.
//!
//! Every reading a leader knows of (its own, its partner's, the follower's) is binned by where it
//! was taken along the up-flow axis, `bin_m` wide, keeping the largest per member and bin: the
//! profile the team has sensed on its way up-flow. A member's strong bins are those of at least
//! `significant_fraction` of its peak (and `min_peak`); the *edge* is the most up-flow strong bin
//! of any member, the *last trace* the most up-flow bin where any member read at least
//! `quiet_fraction` of its peak. The rule declares at the edge, on the formation's centre line,
//! once
//! - the strong bins of all members together span at least `min_strong_m` (one strong bin is a
//!   noise spike or a plume crossed sideways, not the run-up to an outlet),
//! - the midpoint has gone `confirm_m` up-flow of the last trace (a distance, so a team that slows
//!   down or hangs off the plume's side does not declare on a lull in time), and
//! - every member's latest reading is below `quiet_fraction` of its peak.
//!
//! Where: the members do not sample the plume's core (the follower is below the surface, the
//! leaders to its sides), so on the steady plume of a surface outlet each member's profile is
//! `c(x) ~ exp(-a / x) / x` at a distance `x` down-flow of the outlet, with `a` set by its depth or
//! offset: it peaks at `x = a` and falls to half its peak at `x = 0.37 a`, short of the outlet.
//! The declared point is therefore the strongest member's edge moved up-flow by `extrapolate`
//! times its peak-to-edge distance (0.59 = 0.37 / (1 - 0.37) puts it on the outlet for that
//! profile), and never down-flow of the team's edge. With the formation closing up on a fade
//! (the leader's `close_on_fade`, the default) the leaders read on to the outlet and the edge is
//! declared as it is (`extrapolate` 0).
//!
//! Its confidence, reported with the declaration (the leader's `formation` telemetry), is the
//! contrast of the drop times the share of members that saw the plume, `(1 - q / p) n / 3`: `p`
//! the strongest member's peak, `q` the largest reading any member took over the confirming
//! stretch (up-flow of the last trace), `n` the members whose peak reached `min_peak`. A
//! declaration from one member's readings, or with the plume still faintly read ahead, scores
//! low.

use plumetrace_core::Vec2;
use std::collections::BTreeMap;

/// The profile the team sensed along the up-flow axis.
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct Profile {
    /// Per member (self, partner, follower): bin index -> largest reading.
    bins: [BTreeMap<i64, f64>; 3],
    /// Peak per member.
    peaks: [f64; 3],
    /// The most up-flow along-flow coordinate the midpoint reached, m.
    front: Option<f64>,
}

/// The rule's settings (the leader's keys).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Rule {
    pub bin_m: f64,
    pub significant_fraction: f64,
    pub quiet_fraction: f64,
    pub min_peak: f64,
    pub min_strong_m: f64,
    pub confirm_m: f64,
    pub extrapolate: f64,
}

/// A confirmed declaration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Confirmed {
    /// Along-flow coordinate of the edge, m.
    pub along_m: f64,
    /// Confidence, 0 to 1.
    pub confidence: f64,
}

impl Profile {
    /// Adds the latest readings `(reading, along-flow coordinate)` of the members and the
    /// midpoint's along-flow coordinate; the declaration when the rule holds.
    pub fn update(
        &mut self,
        r: &Rule,
        members: [Option<(f64, f64)>; 3],
        mid_along: f64,
    ) -> Option<Confirmed> {
        self.front = Some(self.front.map_or(mid_along, |f| f.max(mid_along)));
        let mut faded = true;
        for (k, m) in members.iter().enumerate() {
            let Some((c, along)) = *m else { continue };
            if !c.is_finite() || !along.is_finite() {
                continue;
            }
            self.peaks[k] = self.peaks[k].max(c);
            let bin = (along / r.bin_m).floor() as i64;
            let e = self.bins[k].entry(bin).or_insert(c);
            *e = e.max(c);
            if reads_on(c, self.peaks[k], r.min_peak, r.quiet_fraction) {
                faded = false;
            }
        }
        if !faded {
            return None;
        }
        let mut strong = std::collections::BTreeSet::new();
        let (mut edge, mut trace) = (i64::MIN, i64::MIN);
        for k in 0..3 {
            let p = self.peaks[k];
            if p < r.min_peak {
                continue;
            }
            for (&b, &c) in &self.bins[k] {
                if c >= r.significant_fraction * p {
                    strong.insert(b);
                    edge = edge.max(b);
                }
                if c >= r.quiet_fraction * p {
                    trace = trace.max(b);
                }
            }
        }
        if edge == i64::MIN || (strong.len() as f64) * r.bin_m < r.min_strong_m {
            return None;
        }
        let trace_m = (trace as f64 + 1.0) * r.bin_m;
        if self.front? - trace_m < r.confirm_m {
            return None;
        }
        let (best, p) = (0..3)
            .map(|k| (k, self.peaks[k]))
            .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
        // The strongest member's own peak and edge, for the extrapolation to the outlet.
        let bins = &self.bins[best];
        let top = bins
            .iter()
            .fold(
                (edge, f64::MIN),
                |a, (&b, &c)| if c > a.1 { (b, c) } else { a },
            )
            .0;
        let own_edge = bins
            .iter()
            .filter(|(_, c)| **c >= r.significant_fraction * p)
            .map(|(&b, _)| b)
            .max()
            .unwrap_or(edge);
        let ahead = r.extrapolate * (own_edge - top).max(0) as f64;
        let along = (own_edge as f64 + 0.5 + ahead) * r.bin_m;
        let q = (0..3)
            .flat_map(|k| self.bins[k].range(trace + 1..).map(|(_, &c)| c))
            .fold(0.0_f64, f64::max);
        let seen = self.peaks.iter().filter(|&&x| x >= r.min_peak).count();
        let confidence = ((1.0 - q / p).clamp(0.0, 1.0) * seen as f64 / 3.0).clamp(0.0, 1.0);
        Some(Confirmed {
            along_m: along.max((edge as f64 + 0.5) * r.bin_m),
            confidence,
        })
    }
}

/// The point on the centre line through `mid` at along-flow coordinate `along` (axis `up`).
pub(super) fn on_centre_line(mid: Vec2, up: Vec2, along: f64) -> Vec2 {
    mid + up * (along - mid.dot(&up))
}

/// Whether a member reading `c` against its `peak` still reads the plume: its peak counts (at
/// least `min_peak`) and `c` has not faded below `quiet_fraction` of it. Both declaration rules
/// wait until no member does.
pub(super) fn reads_on(c: f64, peak: f64, min_peak: f64, quiet_fraction: f64) -> bool {
    peak >= min_peak && c >= quiet_fraction * peak
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule(extrapolate: f64) -> Rule {
        Rule {
            bin_m: 1.0,
            significant_fraction: 0.5,
            quiet_fraction: 0.2,
            min_peak: 0.01,
            min_strong_m: 3.0,
            confirm_m: 6.0,
            extrapolate,
        }
    }

    /// A member's profile `exp(-a / x) / x`, `x` down-flow of an outlet at 0 (`along` is up-flow).
    fn outlet(along: f64) -> f64 {
        let x = -along;
        if x > 0.0 { (-5.0 / x).exp() / x } else { 0.0 }
    }

    /// A team going up-flow over a plume whose profile is `c(along)` (the follower reading it,
    /// a leader half of it); the declaration, if the rule makes one.
    fn fly(extrapolate: f64, c: impl Fn(f64) -> f64) -> Option<Confirmed> {
        let mut p = Profile::default();
        for k in 0..5000 {
            let along = -100.0 + 0.025 * k as f64;
            let r = c(along);
            let members = [Some((r * 0.5, along)), None, Some((r, along))];
            if let Some(d) = p.update(&rule(extrapolate), members, along) {
                return Some(d);
            }
        }
        None
    }

    #[test]
    fn declares_past_the_end_of_a_steady_plume_at_the_outlet_extrapolated() {
        // At the half-peak edge (x = 0.37 a = 1.85 m) without the extrapolation, on the outlet
        // with it.
        let edge = fly(0.0, outlet).expect("declares");
        assert!((-2.5..=-1.0).contains(&edge.along_m), "{edge:?}");
        let d = fly(0.59, outlet).expect("declares");
        assert!(d.along_m.abs() < 1.0, "{d:?}");
        // Two of the three members read: at most 2/3.
        assert!(d.confidence > 0.6 && d.confidence <= 2.0 / 3.0, "{d:?}");
    }

    #[test]
    fn a_lull_shorter_than_the_confirmation_distance_does_not_declare() {
        // The plume fades for 4 m (the team off its side) and comes back stronger.
        let d = fly(0.0, |a| {
            if (-30.0..-26.0).contains(&a) {
                0.0
            } else {
                outlet(a)
            }
        })
        .expect("declares");
        assert!(d.along_m > -3.0, "declared at the lull: {d:?}");
    }

    #[test]
    fn a_single_spike_is_not_a_plume() {
        let spike = |a: f64| {
            if (-50.0..-49.5).contains(&a) {
                1.0
            } else {
                0.0
            }
        };
        assert_eq!(fly(0.0, spike), None);
    }
}
