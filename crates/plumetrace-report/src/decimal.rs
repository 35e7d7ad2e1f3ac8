//! Fixed-point decimals written as `format!("{v:.N}")` writes them, several times faster: the
//! outputs' tables write hundreds of thousands of them.
//!
//! The standard library rounds the exact binary value to `N` places. Here the value is scaled
//! by `10^N` in double precision and rounded to a whole number, which gives the same digits
//! unless the scaled value lies within a millionth of a half (where the product's rounding
//! could tip it) or beyond 10^9; those few take the standard library's way.

use std::fmt::Write as _;

/// Powers of ten up to the most places written this way.
const POW10: [f64; 7] = [1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6];

/// Appends `v` with `places` decimal places, as `write!(out, "{v:.places$}")`.
pub fn push_fixed(out: &mut String, v: f64, places: usize) {
    let Some(&scale) = POW10.get(places) else {
        let _ = write!(out, "{v:.places$}");
        return;
    };
    let scaled = v.abs() * scale;
    let whole = scaled.floor();
    let frac = scaled - whole;
    // Below 10^9 the product is within half a unit in its last place (6e-8) of the exact
    // one, so only a fraction within 1e-6 of a half could round the other way; `frac` is
    // exact. NaN and infinities fail the first test.
    let plain = scaled < 1e9 && (frac - 0.5).abs() >= 1e-6;
    if !plain {
        let _ = write!(out, "{v:.places$}");
        return;
    }
    let mut n = whole as u64 + u64::from(frac > 0.5);
    // At most 10 whole digits (below 10^9 + 1), the point, 6 places and a sign.
    let mut buf = [0u8; 24];
    let mut at = buf.len();
    for _ in 0..places {
        at -= 1;
        buf[at] = b'0' + (n % 10) as u8;
        n /= 10;
    }
    if places > 0 {
        at -= 1;
        buf[at] = b'.';
    }
    at = digits_before(&mut buf, at, n);
    if v.is_sign_negative() {
        at -= 1;
        buf[at] = b'-';
    }
    out.push_str(std::str::from_utf8(&buf[at..]).unwrap_or_default());
}

/// Appends the decimal digits of `n`, as `write!(out, "{n}")`.
pub fn push_whole(out: &mut String, n: u64) {
    let mut buf = [0u8; 20];
    let end = buf.len();
    let at = digits_before(&mut buf, end, n);
    out.push_str(std::str::from_utf8(&buf[at..]).unwrap_or_default());
}

/// Writes the decimal digits of `n` into `buf` so that they end before `end`; where they start.
fn digits_before(buf: &mut [u8], end: usize, mut n: u64) -> usize {
    let mut at = end;
    loop {
        at -= 1;
        buf[at] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            return at;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn check(v: f64, places: usize) {
        let mut got = String::new();
        push_fixed(&mut got, v, places);
        assert_eq!(
            got,
            format!("{v:.places$}"),
            "{v:e} ({:#x}) to {places}",
            v.to_bits()
        );
    }

    #[test]
    fn whole_numbers_are_written_as_the_standard_formatting_writes_them() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(4);
        let mut got = String::new();
        for n in [0, 1, 9, 10, 99, 100, u64::from(u32::MAX), u64::MAX]
            .into_iter()
            .chain((0..10_000).map(|_| rng.random::<u64>() >> rng.random_range(0..64)))
        {
            got.clear();
            push_whole(&mut got, n);
            assert_eq!(got, n.to_string());
        }
    }

    #[test]
    fn writes_what_the_standard_formatting_writes() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        for places in 0..=8 {
            // Every magnitude a table holds, both signs, and whole numbers of hundredths.
            for _ in 0..40_000 {
                let magnitude = 10f64.powi(rng.random_range(-9..17));
                let v = (rng.random::<f64>() - 0.5) * magnitude;
                check(v, places);
                check((v * 100.0).round() / 100.0, places);
            }
            // Exact halves (ties: the standard rounds them to even) and their neighbours.
            for k in 0..4_000u32 {
                for half in [
                    (f64::from(k) + 0.5) / 8.0,
                    (f64::from(k) + 0.5) / 1024.0,
                    f64::from(k) + 0.5,
                    (f64::from(k) * 2.0 + 1.0) / 2f64.powi(places as i32 + 1),
                ] {
                    for v in [half, half.next_up(), half.next_down()] {
                        check(v, places);
                        check(-v, places);
                    }
                }
            }
            // Decimal halves that are not exact in binary (0.125 exact, 0.15 not, 2.675 not).
            for k in 0..20_000u32 {
                let v = (f64::from(k) + 0.5) / POW10[places.min(6)];
                check(v, places);
                check(-v, places);
            }
            for v in [
                0.0,
                -0.0,
                1e-300,
                -1e-300,
                0.5,
                1.5,
                2.5,
                -2.5,
                2.675,
                1.005,
                4.5e15,
                4.503_599_627_370_495e15,
                9.007_199_254_740_993e15,
                1e300,
                -1e300,
                f64::MAX,
                f64::MIN_POSITIVE,
            ] {
                check(v, places);
            }
        }
    }
}
