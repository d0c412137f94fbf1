//! The exponential of a whole slice at once, for per-particle loops: reduction to
//! r = x − k ln 2 with |r| ≤ ln 2 / 2 (ln 2 split in two parts, the Cody–Waite way), the Taylor
//! series of e^r to degree 13 (truncation below 1e-17 relative) and a scale by 2^k assembled
//! from its bits. Free of calls and branches, so the compiler runs it on vector lanes (four
//! wide where the CPU has AVX2, found at run time; the same operations, so the same results);
//! within two units in the last place of `f64::exp` wherever the result is at least 2^−1020.
//!
//! Not for: results below 2^−1020 ≈ 9e-308, which are returned as 0 (the filter only uses
//! these values relative to a maximum of 1), or single values (use `f64::exp`).

/// log₂ e.
const LOG2_E: f64 = std::f64::consts::LOG2_E;
/// ln 2 in two parts: the high one has trailing zero bits, so k·LN2_HI is exact for |k| < 2^11.
const LN2_HI: f64 = 6.931_471_803_691_238e-1;
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
/// 1.5 · 2^52: adding it rounds to an integer, which then sits in the low mantissa bits.
const ROUND: f64 = 6_755_399_441_055_744.0;
/// Below this the result is flushed to 0 (e^−707 ≈ 9e-308 > 2^−1020).
const LOWEST: f64 = -707.0;
/// Above this the result is +∞ (e^709.7 is the largest finite value).
const HIGHEST: f64 = 709.0;

/// Replaces every value x of `v` by e^x: within two units in the last place of `f64::exp` for
/// x ∈ [−707, 709], 0 below (and for −∞), `f64::exp` above and for NaN.
pub(crate) fn exp_in_place(v: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has just been found to support AVX2.
        unsafe { exp_avx2(v) };
        return;
    }
    exp_lanes(v);
}

/// [`exp_lanes`] compiled for AVX2: four lanes instead of two, the same operations (never
/// fused), so the same results.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn exp_avx2(v: &mut [f64]) {
    exp_lanes(v);
}

#[inline(always)]
fn exp_lanes(v: &mut [f64]) {
    for x in v.iter_mut() {
        *x = exp_lane(*x);
    }
}

/// 1/k! for k = 13, 12, …, 0.
const TAYLOR: [f64; 14] = [
    1.0 / 6_227_020_800.0,
    1.0 / 479_001_600.0,
    1.0 / 39_916_800.0,
    1.0 / 3_628_800.0,
    1.0 / 362_880.0,
    1.0 / 40_320.0,
    1.0 / 5_040.0,
    1.0 / 720.0,
    1.0 / 120.0,
    1.0 / 24.0,
    1.0 / 6.0,
    1.0 / 2.0,
    1.0,
    1.0,
];

/// One lane of [`exp_in_place`] (NaN in gives NaN out, through the arithmetic).
#[inline(always)]
fn exp_lane(x: f64) -> f64 {
    let c = x.clamp(LOWEST, HIGHEST);
    let t = c * LOG2_E + ROUND;
    let kf = t - ROUND;
    let r = (c - kf * LN2_HI) - kf * LN2_LO;
    // Horner from the highest term: 1/13!, 1/12!, …, 1/1!, 1/0!
    let mut p = TAYLOR[0];
    for c in &TAYLOR[1..] {
        p = p * r + c;
    }
    // k sits in the low bits of t; (k + 1023) << 52 is 2^k for k ∈ [−1020, 1023].
    let scale = f64::from_bits(t.to_bits().wrapping_add(1023) << 52);
    let e = p * scale;
    if x < LOWEST {
        0.0
    } else if x > HIGHEST {
        f64::INFINITY
    } else if x.is_nan() {
        x
    } else {
        e
    }
}

#[cfg(test)]
mod tests {
    use super::super::ulps;
    use super::*;
    use proptest::prelude::*;

    fn one(x: f64) -> f64 {
        let mut v = [x];
        exp_in_place(&mut v);
        v[0]
    }

    #[test]
    fn matches_the_library_and_flushes_the_tiny_results() {
        for x in [
            0.0, -0.0, 1.0, -1.0, 1e-300, -1e-10, 0.5, -0.346, 0.347, 88.7, -88.7, 708.9, -700.0,
            -706.9,
        ] {
            assert!(
                ulps(one(x), x.exp()) <= 2.0,
                "{x}: {} vs {}",
                one(x),
                x.exp()
            );
        }
        assert_eq!(one(0.0), 1.0);
        assert_eq!(one(-707.5), 0.0);
        assert_eq!(one(-1e4), 0.0);
        assert_eq!(one(f64::NEG_INFINITY), 0.0);
        assert_eq!(one(710.0), f64::INFINITY);
        assert_eq!(one(f64::INFINITY), f64::INFINITY);
        assert!(one(f64::NAN).is_nan());
    }

    proptest! {
        #[test]
        fn within_two_ulps_of_the_library(
            xs in proptest::collection::vec(-707.0f64..709.0, 1..20),
            small in -5.0f64..5.0,
        ) {
            let mut v = xs.clone();
            v.push(small);
            exp_in_place(&mut v);
            for (x, e) in xs.iter().chain([&small]).zip(&v) {
                prop_assert!(ulps(*e, x.exp()) <= 2.0, "{x}: {e} vs {}", x.exp());
            }
        }
    }
}
