//! Fast standard normal draws for the filament random walk: three from one 64-bit word.
//!
//! Stepping a filament takes three normal draws (one per axis), which made up about a quarter of
//! the cost of a filament step with a ziggurat sampler drawing one 64-bit word each. Here one
//! word gives three draws of 21 bits each, each turned into a normal value by the inverse of
//! the normal distribution function, read from a table:
//!
//! - the top 11 bits pick one of 2,048 equal-probability buckets, the low 10 bits a place
//!   within it, so a draw stands for the probability `p = (k + 1/2) / 2^21` of its 21 bits `k`;
//! - inside the 2,046 inner buckets the inverse is interpolated linearly between its values at
//!   the bucket edges (the inverse is smooth there: the interpolation moves a draw by less than
//!   0.02 in the two buckets next to the tails and by less than 1e-4 for `|z| < 2.5`; the bias
//!   it adds to the variance is corrected below);
//! - the two outer buckets (`|z|` beyond 3.30) are read from a table of the inverse at each of
//!   their 1,024 places, so the tails are there too, down to `p = 2^-22` (`|z|` up to 5.03);
//! - every value is then scaled so that the distribution of the 2^21 values has variance 1
//!   exactly (it is symmetric, so its mean is 0).
//!
//! The tables are single precision (20 kB in all), so they stay in the first-level cache beside
//! the flow's cells while filaments are stepped; the draws are single precision too (the
//! transport's), widened to `f64` by [`normal_triple`].
//!
//! The draws are therefore a discrete distribution of 2^21 values that follows the standard
//! normal distribution to the resolution of 21 bits, with the tails cut beyond 5.03 standard
//! deviations (probability 5e-7); tests check its moments and its distribution function. The
//! random walk of a filament sums hundreds of such draws, so only their variance matters to the
//! plume's spread, and that is exact.

use std::sync::OnceLock;

/// Bits per draw.
const BITS: u32 = 21;
/// Bits of the bucket index.
const BUCKET_BITS: u32 = 11;
/// Bits of the place within a bucket.
const PLACE_BITS: u32 = BITS - BUCKET_BITS;
const BUCKETS: usize = 1 << BUCKET_BITS;
const PLACES: usize = 1 << PLACE_BITS;

/// The tables of the inverse normal distribution function.
struct Tables {
    /// Per bucket, the line through the inverse at its two edges `i / 2048` and
    /// `(i + 1) / 2048` as `[value at the middle of the first place, rise per place]`, scaled to
    /// unit variance; the outer buckets' entries are unused.
    /// Packed in one 64-bit word per bucket (the value's bits low, the rise's high), so that a
    /// vector of draws gathers each line in one read.
    lines: Box<[u64; BUCKETS]>,
    /// The inverse at the places of the lowest bucket, scaled (the highest is its mirror image).
    low_tail: Box<[f32; PLACES]>,
}

fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(|| {
        let (lines, low_tail) = unscaled();
        let scale = UNIT_VARIANCE_SCALE;
        Tables {
            lines: Box::new(std::array::from_fn(|i| {
                let a = (lines[i][0] * scale) as f32;
                let rise = (lines[i][1] * scale) as f32;
                u64::from(a.to_bits()) | (u64::from(rise.to_bits()) << 32)
            })),
            low_tail: Box::new(std::array::from_fn(|f| (low_tail[f] * scale) as f32)),
        }
    })
}

/// The tables before scaling: per bucket, the line through the inverse at its two edges `i /
/// 2048` and `(i + 1) / 2048` as `[value at the middle of the first place, rise per place]`
/// (the outer buckets' zero), and the inverse at the places of the lowest bucket.
fn unscaled() -> (Vec<[f64; 2]>, Vec<f64>) {
    let edge = |i: usize| inverse_normal_cdf(i as f64 / BUCKETS as f64);
    let mut lines = vec![[0.0; 2]; BUCKETS];
    for (i, l) in lines.iter_mut().enumerate().take(BUCKETS - 1).skip(1) {
        let (a, b) = (edge(i), edge(i + 1));
        let rise = (b - a) / PLACES as f64;
        l[0] = a + 0.5 * rise;
        l[1] = rise;
    }
    let n = (BUCKETS * PLACES) as f64;
    let low_tail = (0..PLACES)
        .map(|f| inverse_normal_cdf((f as f64 + 0.5) / n))
        .collect();
    (lines, low_tail)
}

/// The factor that gives the unscaled tables' 2^21 values a variance of 1 (the test
/// `the_scale_is_the_sum_of_squares_one` sums their squares again and compares the bits):
/// written down, so that a process does not sum 2^21 squares (about 8 ms) before its first
/// draw.
const UNIT_VARIANCE_SCALE: f64 = f64::from_bits(0x3fef_ff77_5058_c515);

/// The factor that gives the 2^21 values of the unscaled `lines` (per bucket, the value at its
/// first place's middle and the rise per place) and lowest bucket's `low_tail` a variance of 1,
/// summed in double precision in the order of the numbers `k`.
#[cfg(test)]
fn unit_variance_scale(lines: &[[f64; 2]], low_tail: &[f64]) -> f64 {
    let mut sum_sq = 0.0;
    for k in 0..(1u32 << BITS) {
        let (bucket, place) = (bucket(k), place(k));
        let z = if bucket == 0 {
            low_tail[place]
        } else if bucket == BUCKETS - 1 {
            -low_tail[PLACES - 1 - place]
        } else {
            lines[bucket][0] + lines[bucket][1] * place as f64
        };
        sum_sq += z * z;
    }
    ((BUCKETS * PLACES) as f64 / sum_sq).sqrt()
}

impl Tables {
    /// The normal value of the 21-bit number `k` (its low 21 bits).
    #[inline(always)]
    fn draw(&self, k: u32) -> f32 {
        let bucket = bucket(k);
        if bucket == 0 {
            self.low_tail[place(k)]
        } else if bucket == BUCKETS - 1 {
            -self.low_tail[PLACES - 1 - place(k)]
        } else {
            self.line(k)
        }
    }
}

/// The bucket of the 21-bit number `k`.
#[inline(always)]
fn bucket(k: u32) -> usize {
    (k >> PLACE_BITS) as usize & (BUCKETS - 1)
}

/// The place within its bucket of the 21-bit number `k`.
#[inline(always)]
fn place(k: u32) -> usize {
    (k as usize) & (PLACES - 1)
}

/// The three 21-bit numbers of a 64-bit word (its top 63 bits).
#[inline(always)]
fn parts(word: u64) -> [u32; 3] {
    let mask = (1u64 << BITS) - 1;
    [
        (word >> 43) as u32,
        ((word >> 22) & mask) as u32,
        ((word >> 1) & mask) as u32,
    ]
}

/// Three standard normal draws from the 64-bit word `word` (its top 63 bits, 21 per draw).
#[inline]
pub fn normal_triple(word: u64) -> [f64; 3] {
    tables().triple(word).map(f64::from)
}

/// Three columns of standard normal draws, row `k` from `words[k]` (as [`normal_triple`]);
/// the columns are as long as `words`. Loops without branches or bounds checks, so that
/// compiled for a vector unit they draw several rows at once: every draw is first read from its
/// bucket's line, then the rows of any group of eight with a draw in a tail bucket (one draw in
/// 1,024) are drawn again in full.
#[inline(always)]
pub fn fill_normal_columns<T: From<f32> + Copy>(
    words: &[u64],
    first: &mut [T],
    second: &mut [T],
    third: &mut [T],
) {
    const GROUP: usize = 8;
    let t = tables();
    let n = words.len();
    let (first, second, third) = (&mut first[..n], &mut second[..n], &mut third[..n]);
    for k in 0..n {
        let [a, b, c] = t.triple_from_lines(words[k]);
        first[k] = T::from(a);
        second[k] = T::from(b);
        third[k] = T::from(c);
    }
    for (g, group) in words.chunks(GROUP).enumerate() {
        let mut tails = false;
        for w in group {
            tails |= in_a_tail(*w);
        }
        if tails {
            for (j, w) in group.iter().enumerate() {
                let k = g * GROUP + j;
                [first[k], second[k], third[k]] = t.triple(*w).map(T::from);
            }
        }
    }
}

/// Whether any of the three draws of `word` lies in a tail bucket.
#[inline(always)]
fn in_a_tail(word: u64) -> bool {
    let [a, b, c] = parts(word).map(|k| (bucket(k) + 1) & (BUCKETS - 1) <= 1);
    a | b | c
}

impl Tables {
    /// Draw `k` read from its bucket's line: the draw itself unless the bucket is a tail one.
    #[inline(always)]
    fn line(&self, k: u32) -> f32 {
        let packed = self.lines[bucket(k)];
        let (a, rise) = (
            f32::from_bits(packed as u32),
            f32::from_bits((packed >> 32) as u32),
        );
        a + rise * place(k) as f32
    }

    /// [`Tables::triple`] read from the lines only (see [`Tables::line`]).
    #[inline(always)]
    fn triple_from_lines(&self, word: u64) -> [f32; 3] {
        parts(word).map(|k| self.line(k))
    }

    /// The three draws of `word`.
    #[inline(always)]
    fn triple(&self, word: u64) -> [f32; 3] {
        parts(word).map(|k| self.draw(k))
    }
}

/// The inverse of the standard normal distribution function at `p` in (0, 1), to about 1e-15:
/// Newton's method on `Phi(x) = erfc(-x / sqrt 2) / 2` from a rational start (only used to
/// build the tables).
fn inverse_normal_cdf(p: f64) -> f64 {
    if p > 0.5 {
        return -inverse_normal_cdf(1.0 - p);
    }
    // A start within about 0.005 (Abramowitz and Stegun 26.2.23), then Newton steps in the
    // log domain of the lower tail, which converge from there.
    let t = (-2.0 * p.ln()).sqrt();
    let mut x = -(t
        - (2.515517 + 0.802853 * t + 0.010328 * t * t)
            / (1.0 + 1.432788 * t + 0.189269 * t * t + 0.001308 * t * t * t));
    for _ in 0..50 {
        let cdf = 0.5 * libm::erfc(-x / std::f64::consts::SQRT_2);
        let pdf = (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt();
        // d ln(cdf) / dx = pdf / cdf.
        let step = (cdf.ln() - p.ln()) * cdf / pdf;
        x -= step;
        if step.abs() < 1e-15 * (1.0 + x.abs()) {
            break;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_is_the_sum_of_squares_one() {
        let (lines, low_tail) = unscaled();
        let scale = unit_variance_scale(&lines, &low_tail);
        assert_eq!(
            scale.to_bits(),
            UNIT_VARIANCE_SCALE.to_bits(),
            "the sum gives {scale:e} ({:#018x})",
            scale.to_bits()
        );
    }

    #[test]
    fn inverse_cdf_matches_known_quantiles() {
        // (p, z) pairs from standard tables.
        for (p, z) in [
            (0.5, 0.0),
            (0.975, 1.959_963_984_540_054),
            (0.841_344_746_068_542_9, 1.0),
            (0.001, -3.090_232_306_167_813_5),
            (1e-7, -5.199_337_582_192_817),
        ] {
            let got = inverse_normal_cdf(p);
            assert!((got - z).abs() < 1e-9, "p {p}: {got} against {z}");
        }
    }

    #[test]
    fn the_distribution_has_the_moments_of_a_standard_normal() {
        let t = tables();
        let n = f64::from(1u32 << BITS);
        let (mut s1, mut s2, mut s4, mut max) = (0.0, 0.0, 0.0, 0.0f64);
        for k in 0..(1u32 << BITS) {
            let z = f64::from(t.draw(k));
            s1 += z;
            s2 += z * z;
            s4 += z * z * z * z;
            max = max.max(z.abs());
        }
        assert!((s1 / n).abs() < 1e-7, "mean {}", s1 / n);
        // Unit variance up to the tables' single-precision rounding.
        assert!((s2 / n - 1.0).abs() < 1e-6, "variance {}", s2 / n);
        // Kurtosis 3 within what cutting the tails at 5 sigma removes.
        assert!((s4 / n - 3.0).abs() < 2e-3, "fourth moment {}", s4 / n);
        assert!(max > 4.9 && max < 5.1, "largest |z| {max}");
    }

    #[test]
    fn every_draw_is_the_inverse_at_its_probability() {
        // Draw k stands for p = (k + 1/2) / 2^21: within 0.02 everywhere, 1e-4 in the body
        // (after the variance scaling, which is within 1e-3 of 1).
        let t = tables();
        let n = f64::from(1u32 << BITS);
        for k in (0..(1u32 << BITS)).step_by(7) {
            let exact = inverse_normal_cdf((f64::from(k) + 0.5) / n);
            let err = (f64::from(t.draw(k)) - exact).abs();
            let bound = if exact.abs() < 2.5 {
                1e-4 + 1e-3 * exact.abs()
            } else {
                0.02
            };
            assert!(err < bound, "k {k}: {} against {exact}", t.draw(k));
        }
    }

    #[test]
    fn the_distribution_function_is_the_normal_one() {
        // The fraction of the 2^21 values below z equals Phi(z) to within a bucket's share.
        let t = tables();
        let mut all: Vec<f64> = (0..(1u32 << BITS)).map(|k| f64::from(t.draw(k))).collect();
        all.sort_by(f64::total_cmp);
        for z in [-4.0, -3.0, -2.0, -1.0, -0.3, 0.0, 0.7, 1.5, 2.5, 3.5] {
            let below = all.partition_point(|v| *v < z) as f64 / all.len() as f64;
            let phi = 0.5 * libm::erfc(-z / std::f64::consts::SQRT_2);
            assert!(
                (below - phi).abs() < 2e-5,
                "P(Z < {z}): {below} against {phi}"
            );
        }
    }

    #[test]
    fn the_lines_give_every_draw_outside_the_tail_buckets() {
        let t = tables();
        let mut tails = 0;
        // A word whose first two draws are at the middle (bucket 1,024) and whose third is `k`.
        let middle = 1u64 << (BITS - 1);
        let word = |k: u32| (middle << 43) | (middle << 22) | (u64::from(k) << 1);
        for k in 0..(1u32 << BITS) {
            let bucket = k >> PLACE_BITS;
            if bucket == 0 || bucket == BUCKETS as u32 - 1 {
                tails += 1;
                assert!(in_a_tail(word(k)), "k {k}");
            } else {
                assert_eq!(t.line(k).to_bits(), t.draw(k).to_bits(), "k {k}");
                assert!(!in_a_tail(word(k)), "k {k}");
            }
        }
        assert_eq!(tails, 2 * PLACES);
    }

    #[test]
    fn triples_use_every_bit_group_and_columns_hold_them() {
        let w = 0x8000_0000_0000_0000u64;
        // Only the first draw's top bit set: the first draw is in the upper half, the other two
        // at the bottom of the range.
        let [a, b, c] = normal_triple(w);
        assert!(a > 0.0 && b < -4.9 && c < -4.9, "{a} {b} {c}");
        // The columns hold the triples of their words, row by row: 150 rows, the first group
        // of eight with no draw in a tail bucket, `w` (two tail draws) in the second group, in
        // a middle one and in the last (partial) one.
        let mut words: Vec<u64> = (1..=150u64)
            .map(|n| n.wrapping_mul(0x9e37_79b9_7f4a_7c15))
            .collect();
        for k in [11, 70, 149] {
            words[k] = w;
        }
        assert!(!words[..8].iter().any(|w| in_a_tail(*w)));
        assert!(in_a_tail(w));
        let mut cols = [[0.0; 150]; 3];
        let [c0, c1, c2] = &mut cols;
        fill_normal_columns(&words, c0, c1, c2);
        for (k, w) in words.iter().enumerate() {
            let row = [cols[0][k], cols[1][k], cols[2][k]];
            assert_eq!(row, normal_triple(*w), "row {k}");
            assert!(row.iter().all(|z| z.is_finite() && *z != 0.0));
        }
    }
}
