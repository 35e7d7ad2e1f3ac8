//! What the front seat saw (written as `frontseat.json`), and the generator of its fault draws.

use serde::Serialize;

/// What the front seat saw, for `frontseat.json` and the tests.
#[derive(Debug, Clone, Default, Serialize)]
pub struct FrontSeatStats {
    /// Navigation records sent.
    pub nav_records: u64,
    /// Commands received (heading/speed set-points).
    pub commands: u64,
    /// Stop commands received.
    pub stops: u64,
    /// Commands outside the vehicle's limits or not finite (never steered by).
    pub unsafe_commands: u64,
    /// Lines received that did not parse.
    pub bad_lines: u64,
    /// Connections accepted.
    pub connections: u64,
    /// Restarts injected (`--restart-at`).
    pub restarts: u64,
    /// Navigation records that got no answer in time (lock-step).
    pub unanswered: u64,
    /// Whether the back seat said it finished.
    pub finished: bool,
    /// Whether the back seat went away for longer than `--wait-s` (lock-step).
    pub back_seat_gone: bool,
    /// Mission time at the end, s.
    pub end_s: f64,
}

/// A small deterministic generator for fault draws (splitmix64).
pub(crate) struct FaultRng(pub(crate) u64);

impl FaultRng {
    /// The next draw, uniform in `[0, 1)`.
    pub(crate) fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fault_draws_are_uniform_in_the_unit_interval_and_repeat_with_their_seed() {
        let draws = |seed| {
            let mut r = FaultRng(seed);
            (0..10_000).map(|_| r.unit()).collect::<Vec<f64>>()
        };
        let a = draws(1);
        assert_eq!(a, draws(1));
        assert_ne!(a, draws(2));
        assert!(a.iter().all(|u| (0.0..1.0).contains(u)));
        let mean = a.iter().sum::<f64>() / a.len() as f64;
        assert!((mean - 0.5).abs() < 0.02, "{mean}");
    }
}
