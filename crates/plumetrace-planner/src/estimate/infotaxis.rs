//! The expected-entropy choice of a move (infotaxis, Vergassola, Villermaux and Shraiman 2007),
//! and its space-aware variant (Loisy and Eloy 2022).
//!
//! A searcher holds a posterior `p` over candidate source cells. A candidate move has a binary
//! outcome model: for each cell `c`, the probability `hit[c]` that the move brings a hit if the
//! source is in `c`; optionally one cell that the move would reveal (reaching it finds the source
//! if it is there). [`move_outcome`] folds the posterior with that model in one pass: the chance
//! of finding the source, the chance of a hit otherwise, and the entropy (bits) and mean distance
//! of the posterior after a hit and after a miss. [`Objective::value`] ranks the move:
//!
//! - infotaxis: the expected posterior entropy, `(1 - p_end) (p_hit H_hit + p_miss H_miss)`
//!   (finding the source leaves no entropy);
//! - space-aware infotaxis: the expectation of `log2(D + 2^(H - 1) - 1/2)` over the outcomes
//!   (the value itself where it is not positive), with `D` the posterior mean distance to the
//!   source in moves: a rough count of the moves still needed, which makes the searcher weigh
//!   distance against information.
//!
//! [`choose`] takes the smallest value, the first of equal ones (within 1e-10), so the choice
//! is deterministic.

/// Probabilities at or below this are left out of entropies (as zero).
const P_FLOOR: f64 = 1e-10;

/// The entropy of a distribution, bits (cells at or below 1e-10 count as empty).
pub fn entropy_bits(p: &[f64]) -> f64 {
    p.iter()
        .filter(|&&q| q > P_FLOOR)
        .map(|&q| -q * q.log2())
        .sum()
}

/// What a candidate move can bring, under the posterior.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveOutcome {
    /// Probability that the move finds the source (it is in the revealed cell).
    pub p_end: f64,
    /// Probability of a hit, given the source is not found.
    pub p_hit: f64,
    /// Posterior entropy after a hit, bits.
    pub h_hit_bits: f64,
    /// Posterior entropy after a miss, bits.
    pub h_miss_bits: f64,
    /// Posterior mean distance to the source after a hit (in the units of `dist`; 0 without).
    pub d_hit: f64,
    /// Posterior mean distance to the source after a miss.
    pub d_miss: f64,
}

/// Folds the posterior `p` with a move's outcome model: `hit[c]` is the probability of a hit if
/// the source is in `c` (values outside 0..=1 are clamped), `found` the cell the move reveals (if
/// any), `dist[c]` the distance from the move's end to `c` (for the space-aware objective).
/// Slices shorter than `p` count as zero past their end.
pub fn move_outcome(
    p: &[f64],
    hit: &[f64],
    found: Option<usize>,
    dist: Option<&[f64]>,
) -> MoveOutcome {
    let p_end = found.and_then(|i| p.get(i).copied()).unwrap_or(0.0);
    let rest = (1.0 - p_end).max(0.0);
    // Sums over the cells, with q = p / (1 - p_end): a = q h, b = q (1 - h); and a log2 a, ...
    let (mut sa, mut sb, mut la, mut lb, mut da, mut db) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    if rest > P_FLOOR {
        for (i, &pi) in p.iter().enumerate() {
            if Some(i) == found || pi <= 0.0 {
                continue;
            }
            let q = pi / rest;
            let h = hit.get(i).copied().unwrap_or(0.0).clamp(0.0, 1.0);
            let (a, b) = (q * h, q * (1.0 - h));
            let d = dist.and_then(|d| d.get(i).copied()).unwrap_or(0.0);
            sa += a;
            sb += b;
            da += a * d;
            db += b * d;
            if a > 0.0 {
                la += a * a.log2();
            }
            if b > 0.0 {
                lb += b * b.log2();
            }
        }
    }
    // H = -sum (a / S) log2(a / S) = log2 S - (sum a log2 a) / S.
    let entropy = |s: f64, l: f64| {
        if s > P_FLOOR {
            (s.log2() - l / s).max(0.0)
        } else {
            0.0
        }
    };
    let mean = |s: f64, d: f64| if s > P_FLOOR { d / s } else { 0.0 };
    let total = sa + sb;
    MoveOutcome {
        p_end,
        p_hit: if total > 0.0 { sa / total } else { 0.0 },
        h_hit_bits: entropy(sa, la),
        h_miss_bits: entropy(sb, lb),
        d_hit: mean(sa, da),
        d_miss: mean(sb, db),
    }
}

/// What a searcher minimises over its candidate moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Objective {
    /// Expected posterior entropy.
    Infotaxis,
    /// Expected `log2(D + 2^(H - 1) - 1/2)`: distance weighed against information.
    SpaceAware,
}

impl plumetrace_core::params::Choice for Objective {
    const ALL: &'static [Self] = &[Objective::Infotaxis, Objective::SpaceAware];
}

impl Objective {
    /// The value of a move with this outcome (smaller is better).
    pub fn value(self, o: &MoveOutcome) -> f64 {
        let rest = 1.0 - o.p_end;
        if rest <= P_FLOOR {
            // The move surely finds the source.
            return -P_FLOOR;
        }
        let p_miss = 1.0 - o.p_hit;
        match self {
            Objective::Infotaxis => rest * (o.p_hit * o.h_hit_bits + p_miss * o.h_miss_bits),
            Objective::SpaceAware => {
                let f = |d: f64, h: f64| {
                    let v = d + (h - 1.0).exp2() - 0.5;
                    if v > 0.0 { v.log2() } else { v }
                };
                rest * (o.p_hit * f(o.d_hit, o.h_hit_bits) + p_miss * f(o.d_miss, o.h_miss_bits))
            }
        }
    }
}

/// The index of the smallest value (`None`: not a possible move), the first of values within
/// 1e-10 of it; `None` when no move is possible.
pub fn choose(values: &[Option<f64>]) -> Option<usize> {
    let best = values
        .iter()
        .flatten()
        .copied()
        .filter(|v| v.is_finite())
        .fold(f64::INFINITY, f64::min);
    values
        .iter()
        .position(|v| v.is_some_and(|v| (v - best).abs() < 1e-10))
}

/// Bayes' rule on a linear-domain posterior after a move that did not find the source: the
/// revealed cell (if any) is emptied, then every cell is weighed by the probability of what was
/// observed and the whole renormalised. A posterior with no mass left is left as it is.
pub fn bayes_update(p: &mut [f64], hit: &[f64], observed_hit: bool, revealed: Option<usize>) {
    if let Some(c) = revealed.and_then(|i| p.get_mut(i)) {
        *c = 0.0;
    }
    for (i, pi) in p.iter_mut().enumerate() {
        let h = hit.get(i).copied().unwrap_or(0.0).clamp(0.0, 1.0);
        *pi *= if observed_hit { h } else { 1.0 - h };
    }
    let s: f64 = p.iter().sum();
    if s > P_FLOOR {
        for pi in p.iter_mut() {
            *pi /= s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The outcome by brute force: condition, split, normalise, then measure.
    fn brute(p: &[f64], hit: &[f64], found: Option<usize>, dist: &[f64]) -> MoveOutcome {
        let mut q = p.to_vec();
        let p_end = found.map_or(0.0, |i| q[i]);
        if let Some(i) = found {
            q[i] = 0.0;
        }
        let s: f64 = q.iter().sum();
        q.iter_mut().for_each(|x| *x /= s);
        let a: Vec<f64> = q.iter().zip(hit).map(|(x, h)| x * h).collect();
        let b: Vec<f64> = q.iter().zip(hit).map(|(x, h)| x * (1.0 - h)).collect();
        let (sa, sb): (f64, f64) = (a.iter().sum(), b.iter().sum());
        let na: Vec<f64> = a.iter().map(|x| x / sa).collect();
        let nb: Vec<f64> = b.iter().map(|x| x / sb).collect();
        let md = |n: &[f64]| n.iter().zip(dist).map(|(x, d)| x * d).sum::<f64>();
        MoveOutcome {
            p_end,
            p_hit: sa,
            h_hit_bits: entropy_bits(&na),
            h_miss_bits: entropy_bits(&nb),
            d_hit: md(&na),
            d_miss: md(&nb),
        }
    }

    #[test]
    fn the_one_pass_outcome_equals_conditioning_by_hand() {
        let p = [0.1, 0.2, 0.3, 0.15, 0.25];
        let hit = [0.9, 0.5, 0.01, 0.3, 0.0];
        let dist = [4.0, 3.0, 2.0, 1.0, 0.0];
        for found in [None, Some(2), Some(4)] {
            let o = move_outcome(&p, &hit, found, Some(&dist));
            let b = brute(&p, &hit, found, &dist);
            for (x, y) in [
                (o.p_end, b.p_end),
                (o.p_hit, b.p_hit),
                (o.h_hit_bits, b.h_hit_bits),
                (o.h_miss_bits, b.h_miss_bits),
                (o.d_hit, b.d_hit),
                (o.d_miss, b.d_miss),
            ] {
                assert!((x - y).abs() < 1e-12, "{found:?}: {o:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn infotaxis_prefers_the_informative_move_and_ties_go_to_the_first() {
        let p = [0.25; 4];
        // Move 0 tells nothing (same hit chance everywhere); move 1 splits the cells in halves.
        let flat = [0.5; 4];
        let split = [1.0, 1.0, 0.0, 0.0];
        let v: Vec<Option<f64>> = [&flat, &split, &split]
            .iter()
            .map(|h| Some(Objective::Infotaxis.value(&move_outcome(&p, &h[..], None, None))))
            .collect();
        assert!((v[0].unwrap_or(0.0) - 2.0).abs() < 1e-12, "{v:?}");
        assert!((v[1].unwrap_or(0.0) - 1.0).abs() < 1e-12, "{v:?}");
        assert_eq!(choose(&v), Some(1));
        assert_eq!(choose(&[None, Some(3.0), Some(1.0)]), Some(2));
        assert_eq!(choose(&[None, None]), None);
    }

    #[test]
    fn a_move_that_surely_finds_the_source_wins() {
        let p = [0.0, 1.0, 0.0];
        let o = move_outcome(&p, &[0.5; 3], Some(1), None);
        assert_eq!(o.p_end, 1.0);
        for obj in [Objective::Infotaxis, Objective::SpaceAware] {
            assert!(obj.value(&o) < 0.0);
        }
    }

    #[test]
    fn bayes_update_keeps_mass_and_empties_the_revealed_cell() {
        let mut p = vec![0.25; 4];
        bayes_update(&mut p, &[0.8, 0.4, 0.2, 0.0], true, Some(0));
        assert_eq!(p[0], 0.0);
        assert_eq!(
            p[3], 0.0,
            "a cell that cannot give a hit is ruled out by one"
        );
        assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!((p[1] - 2.0 / 3.0).abs() < 1e-12, "{p:?}");
    }
}
