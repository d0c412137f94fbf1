//! The natural logarithm of a whole slice at once, for per-particle loops: x = m·2^e with
//! m ∈ [√½, √2) read off the bits, ln m = 2 atanh s with s = (m − 1)/(m + 1) (|s| ≤ 0.172) from
//! the odd series of atanh to s²³ (truncation below 1e-18 relative), and e·ln 2 added in two
//! parts (Cody–Waite). Free of calls and branches, so the compiler runs it on vector lanes
//! (four wide with AVX2, as [`super::exp`]); within two units in the last place of `f64::ln`
//! for normal positive numbers. Zero, negative, subnormal and non-finite inputs go to
//! `f64::ln`: a slice holding any of them takes a branch per value.
//!
//! Not for: single values (use `f64::ln`).

/// ln 2 in two parts: the high one has trailing zero bits, so e·LN2_HI is exact for |e| < 2^11.
const LN2_HI: f64 = 6.931_471_803_691_238e-1;
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
/// Mask of the 52 mantissa bits.
const MANTISSA: u64 = (1 << 52) - 1;
/// Exponent bits of 1.0.
const ONE_BITS: u64 = 1023 << 52;
/// 2^52 and its bits.
const TWO_52: f64 = 4_503_599_627_370_496.0;
const TWO_52_BITS: u64 = 0x4330_0000_0000_0000;

/// 2/(2k + 1) for k = 11, 10, …, 0: 2 atanh s = Σ 2 s^(2k+1) / (2k + 1).
const ATANH: [f64; 12] = [
    2.0 / 23.0,
    2.0 / 21.0,
    2.0 / 19.0,
    2.0 / 17.0,
    2.0 / 15.0,
    2.0 / 13.0,
    2.0 / 11.0,
    2.0 / 9.0,
    2.0 / 7.0,
    2.0 / 5.0,
    2.0 / 3.0,
    2.0,
];

/// Replaces every value x of `v` by ln x: within two units in the last place of `f64::ln`
/// for normal positive x; `f64::ln` for every other value (−∞ at 0, NaN below, +∞ at +∞).
pub(crate) fn ln_in_place(v: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has just been found to support AVX2.
        unsafe { ln_avx2(v) };
        return;
    }
    ln_lanes(v);
}

/// [`ln_lanes`] compiled for AVX2: four lanes instead of two, the same operations (never
/// fused), so the same results.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn ln_avx2(v: &mut [f64]) {
    ln_lanes(v);
}

#[inline(always)]
fn ln_lanes(v: &mut [f64]) {
    let normal = |x: f64| (f64::MIN_POSITIVE..=f64::MAX).contains(&x);
    if v.iter().all(|&x| normal(x)) {
        for x in v.iter_mut() {
            *x = ln_lane(*x);
        }
    } else {
        for x in v.iter_mut() {
            *x = if normal(*x) { ln_lane(*x) } else { x.ln() };
        }
    }
}

/// One lane of [`ln_in_place`] for a normal positive `x`.
#[inline(always)]
fn ln_lane(x: f64) -> f64 {
    let bits = x.to_bits();
    // The biased exponent as a float without an integer conversion (which has no vector
    // instruction before AVX-512): its bits under 2^52's exponent, less 2^52.
    let biased = f64::from_bits((bits >> 52) | TWO_52_BITS) - TWO_52;
    let m0 = f64::from_bits((bits & MANTISSA) | ONE_BITS);
    // m0 ∈ [1, 2); move to [√½, √2).
    let big = m0 > std::f64::consts::SQRT_2;
    let m = if big { m0 * 0.5 } else { m0 };
    let e = biased - if big { 1022.0 } else { 1023.0 };
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let mut p = ATANH[0];
    for c in &ATANH[1..] {
        p = p * s2 + c;
    }
    e * LN2_HI + (s * p + e * LN2_LO)
}

#[cfg(test)]
mod tests {
    use super::super::ulps;
    use super::*;
    use proptest::prelude::*;

    fn one(x: f64) -> f64 {
        let mut v = [x];
        ln_in_place(&mut v);
        v[0]
    }

    #[test]
    fn matches_the_library_at_the_edges() {
        for x in [
            1.0,
            2.0,
            0.5,
            std::f64::consts::SQRT_2,
            std::f64::consts::FRAC_1_SQRT_2,
            1.0 + f64::EPSILON,
            1.0 - f64::EPSILON / 2.0,
            std::f64::consts::E,
            10.0,
            1e-300,
            f64::MIN_POSITIVE,
            f64::MAX,
            1e300,
            0.999,
            1.001,
        ] {
            assert!(ulps(one(x), x.ln()) <= 2.0, "{x}: {} vs {}", one(x), x.ln());
        }
        assert_eq!(one(1.0), 0.0);
        assert_eq!(one(0.0), f64::NEG_INFINITY);
        assert_eq!(one(f64::INFINITY), f64::INFINITY);
        assert!(one(-1.0).is_nan());
        assert!(one(f64::NAN).is_nan());
        // Subnormals go to the library.
        assert_eq!(one(1e-310), 1e-310f64.ln());
        // A slice mixing both kinds keeps the normal lanes exact too.
        let mut v = [0.0, 3.0, 1e-310, 7.5];
        ln_in_place(&mut v);
        assert_eq!(v[0], f64::NEG_INFINITY);
        assert!(ulps(v[1], 3f64.ln()) <= 2.0 && ulps(v[3], 7.5f64.ln()) <= 2.0);
    }

    proptest! {
        #[test]
        fn within_two_ulps_of_the_library(
            mantissa in 0.5f64..2.0,
            exponent in -1000i32..1000,
            near_one in -1e-6f64..1e-6,
        ) {
            let x = mantissa * 2f64.powi(exponent);
            prop_assert!(ulps(one(x), x.ln()) <= 2.0, "{} vs {}", one(x), x.ln());
            let y = 1.0 + near_one;
            prop_assert!(ulps(one(y), y.ln()) <= 2.0, "{} vs {}", one(y), y.ln());
        }
    }
}
