//! An exponential for the terms of a display raster, computed in vector lanes.
//!
//! A grid query for a figure or a page adds millions of Gaussian terms; the standard library's
//! `exp` is a call per term that the compiler cannot run in vector lanes. This one is the usual
//! reduction `exp(x) = 2^k exp(r)` with `k` the whole number nearest `x / ln 2` and `|r| <= ln 2 /
//! 2`, `exp(r)` by its Taylor series to degree 13 (truncation below 5e-18 relative) in Horner's
//! form, and `2^k` put into the exponent's bits: no branch, no table, no fused multiply-add, so
//! every vector unit gives the same bits. Within 2 units in the last place of the standard
//! library's `exp` for `x` in `[-700, 0]` (test below); arguments below -700 (terms below 1e-304
//! of the filament's peak) give `exp(-700)`.

/// `exp(x)` for `x <= 0`, within 2 units in the last place (see the module).
#[inline(always)]
pub(crate) fn exp_nonpositive(x: f64) -> f64 {
    const LOG2_E: f64 = std::f64::consts::LOG2_E;
    // ln 2 split so that `k * LN2_HI` is exact for |k| < 2^21 (its low 21 bits are zero; here
    // |k| <= 1010).
    const LN2_HI: f64 = 6.931_471_803_691_238e-1;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    // 1.5 * 2^52: adding it rounds to a whole number, which then sits in the low bits.
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    // 1 / n! for n = 2..=13.
    const C: [f64; 12] = [
        1.0 / 2.0,
        1.0 / 6.0,
        1.0 / 24.0,
        1.0 / 120.0,
        1.0 / 720.0,
        1.0 / 5_040.0,
        1.0 / 40_320.0,
        1.0 / 362_880.0,
        1.0 / 3_628_800.0,
        1.0 / 39_916_800.0,
        1.0 / 479_001_600.0,
        1.0 / 6_227_020_800.0,
    ];
    // `max` and `min` keep NaN out of the bit arithmetic (NaN gives -700's value), where
    // `clamp` would pass it on.
    #[allow(clippy::manual_clamp)]
    let x = x.max(-700.0).min(0.0);
    let t = x * LOG2_E + SHIFT;
    let k = t - SHIFT;
    let r = (x - k * LN2_HI) - k * LN2_LO;
    let mut p = C[11];
    for &c in C[..11].iter().rev() {
        p = p * r + c;
    }
    let e_r = 1.0 + r + (r * r) * p;
    // The whole number k, from the low bits of t, into the exponent field: 2^k.
    let k_int = t.to_bits().wrapping_sub(SHIFT.to_bits()) as i64;
    let scale = f64::from_bits(((k_int + 1023) as u64) << 52);
    e_r * scale
}

/// `out[k] = amp[k] * exp(arg[k])` for `arg[k] <= 0`, as a [`pulp::WithSimd`] operation so that
/// the loop is compiled for the vector unit chosen (see `crate::simd`).
pub(crate) struct ScaledExp<'a> {
    pub(crate) arg: &'a mut [f64],
    pub(crate) amp: &'a [f64],
}

impl pulp::WithSimd for ScaledExp<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let n = self.arg.len().min(self.amp.len());
        let (arg, amp) = (&mut self.arg[..n], &self.amp[..n]);
        for (a, &m) in arg.iter_mut().zip(amp) {
            *a = m * exp_nonpositive(*a);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Units in the last place between `a` and `b` (both positive).
    fn ulps(a: f64, b: f64) -> u64 {
        a.to_bits().abs_diff(b.to_bits())
    }

    #[test]
    fn agrees_with_the_standard_exp_within_two_units_in_the_last_place() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let mut worst = 0;
        // The display rasters' range (a few cut-off radii: above -50) densely, then the rest.
        for k in 0..2_000_000 {
            let x = if k % 4 == 3 {
                -rng.random::<f64>() * 700.0
            } else {
                -rng.random::<f64>() * 50.0
            };
            let (fast, std) = (exp_nonpositive(x), x.exp());
            let u = ulps(fast, std);
            assert!(
                u <= 2,
                "exp({x:e}): {fast:e} against {std:e}, {u} ulps apart"
            );
            worst = worst.max(u);
        }
        // Edges: zero, the smallest steps below it, whole multiples of ln 2, the clamp.
        for x in [
            0.0,
            -0.0,
            -1e-300,
            -f64::EPSILON,
            -std::f64::consts::LN_2,
            -0.5 * std::f64::consts::LN_2,
            -10.0 * std::f64::consts::LN_2,
            -699.999,
            -700.0,
        ] {
            let u = ulps(exp_nonpositive(x), x.exp());
            assert!(u <= 2, "exp({x:e}) {u} ulps from the standard exp");
        }
        assert_eq!(exp_nonpositive(0.0), 1.0);
        assert_eq!(exp_nonpositive(-800.0), exp_nonpositive(-700.0));
        assert_eq!(exp_nonpositive(f64::NAN), exp_nonpositive(-700.0));
        assert!(exp_nonpositive(f64::NEG_INFINITY) > 0.0);
        // Most arguments land on the standard exp's bits, but not all (so this is not the
        // standard exp under another name).
        assert!(worst >= 1, "never a unit apart over 2,000,000 arguments");
    }

    #[test]
    fn every_vector_unit_gives_the_same_bits() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        let args: Vec<f64> = (0..4099).map(|_| -rng.random::<f64>() * 40.0).collect();
        let amp: Vec<f64> = (0..4099).map(|_| rng.random::<f64>() * 3.0).collect();
        let mut first: Option<Vec<u64>> = None;
        for arch in crate::simd::every() {
            let mut out = args.clone();
            arch.dispatch(ScaledExp {
                arg: &mut out,
                amp: &amp,
            });
            let bits: Vec<u64> = out.iter().map(|v| v.to_bits()).collect();
            for ((o, a), m) in out.iter().zip(&args).zip(&amp) {
                assert_eq!(o.to_bits(), (m * exp_nonpositive(*a)).to_bits());
            }
            match &first {
                None => first = Some(bits),
                Some(f) => assert_eq!(f, &bits, "{arch:?} differs"),
            }
        }
    }
}
