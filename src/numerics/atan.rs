//! A full-precision two-argument arctangent for per-particle loops: range reduction to
//! |t| ≤ 0.66 and the classic rational approximation of degree 4/5 in t² (the Cephes `atan`),
//! good to a few units in the last place. It costs a fraction of the C
//! library's `atan2`, which dominates a range-bearing likelihood otherwise.
//!
//! Not for: approximate angles where a cruder polynomial suffices (the occlusion window uses
//! one), or special-value semantics beyond what `f64::atan2` gives (non-finite or zero inputs
//! are handed to it).

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// tan(3π/8) = 1 + √2: above it the argument is reflected through 1/t.
const TAN_3PI_8: f64 = 2.414_213_562_373_095;
/// The low part of π/2 (π/2 = FRAC_PI_2 + this, to twice double precision).
const PI_2_LOW: f64 = 6.123_233_995_736_766e-17;

const P: [f64; 5] = [
    -8.750_608_600_031_904e-1,
    -1.615_753_718_733_365e1,
    -7.500_855_792_314_705e1,
    -1.228_866_684_490_136_2e2,
    -6.485_021_904_942_025e1,
];
const Q: [f64; 5] = [
    2.485_846_490_142_306e1,
    1.650_270_098_316_988_5e2,
    4.328_810_604_912_903e2,
    4.853_903_996_359_137e2,
    1.945_506_571_482_614e2,
];

/// atan(x) for x ≥ 0 (including +∞).
#[inline]
fn atan_nonnegative(x: f64) -> f64 {
    let (base, t, low) = if x > TAN_3PI_8 {
        (FRAC_PI_2, -1.0 / x, PI_2_LOW)
    } else if x <= 0.66 {
        (0.0, x, 0.0)
    } else {
        (FRAC_PI_4, (x - 1.0) / (x + 1.0), 0.5 * PI_2_LOW)
    };
    let z = t * t;
    let p = (((P[0] * z + P[1]) * z + P[2]) * z + P[3]) * z + P[4];
    let q = ((((z + Q[0]) * z + Q[1]) * z + Q[2]) * z + Q[3]) * z + Q[4];
    base + (t * (z * p / q) + t + low)
}

/// atan2(y, x) in (−π, π], within a few units in the last place of `f64::atan2`.
#[inline]
pub(crate) fn atan2(y: f64, x: f64) -> f64 {
    if !(x != 0.0 && y != 0.0 && x.is_finite() && y.is_finite()) {
        return y.atan2(x);
    }
    let a = atan_nonnegative((y / x).abs());
    match (x > 0.0, y > 0.0) {
        (true, true) => a,
        (true, false) => -a,
        (false, true) => PI - a,
        (false, false) => a - PI,
    }
}

/// [`atan2`] of every pair (`ys[i]`, `xs[i]`) into `out[i]`: the same numbers, computed in a
/// pass of selects without branches or calls (so it runs on vector lanes), then a pass that
/// hands the rare zero or non-finite inputs to the library.
pub(crate) fn atan2_slices(ys: &[f64], xs: &[f64], out: &mut [f64]) {
    // A plain map first, so that it runs on vector lanes; then the rare pairs that are not
    // both finite and non-zero are recomputed by the scalar function.
    for ((o, &y), &x) in out.iter_mut().zip(ys).zip(xs) {
        *o = atan2_lane(y, x);
    }
    let ordinary = |y: f64, x: f64| {
        let (ax, ay) = (x.abs(), y.abs());
        (ax > 0.0) & (ay > 0.0) & (ax < f64::INFINITY) & (ay < f64::INFINITY)
    };
    if !ys.iter().zip(xs).all(|(&y, &x)| ordinary(y, x)) {
        for ((o, &y), &x) in out.iter_mut().zip(ys).zip(xs) {
            if !ordinary(y, x) {
                *o = atan2(y, x);
            }
        }
    }
}

/// [`atan2`] for finite, non-zero `x` and `y` as selects: each reduction of
/// [`atan_nonnegative`] is one quotient, picked before the single division.
#[inline(always)]
fn atan2_lane(y: f64, x: f64) -> f64 {
    let v = (y / x).abs();
    let (big, small) = (v > TAN_3PI_8, v <= 0.66);
    let num = if big {
        -1.0
    } else if small {
        v
    } else {
        v - 1.0
    };
    let den = if big {
        v
    } else if small {
        1.0
    } else {
        v + 1.0
    };
    let base = if big {
        FRAC_PI_2
    } else if small {
        0.0
    } else {
        FRAC_PI_4
    };
    let low = if big {
        PI_2_LOW
    } else if small {
        0.0
    } else {
        0.5 * PI_2_LOW
    };
    let t = num / den;
    let z = t * t;
    let p = (((P[0] * z + P[1]) * z + P[2]) * z + P[3]) * z + P[4];
    let q = ((((z + Q[0]) * z + Q[1]) * z + Q[2]) * z + Q[3]) * z + Q[4];
    let a = base + (t * (z * p / q) + t + low);
    let (xp, yp) = (x > 0.0, y > 0.0);
    let signed = if yp { a } else { -a };
    let flipped = if yp { PI - a } else { a - PI };
    if xp {
        signed
    } else {
        flipped
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn matches_the_library_around_the_circle_and_at_the_seams() {
        let mut worst: f64 = 0.0;
        for i in 0..100_000 {
            let a = -PI + (i as f64 + 0.5) * (2.0 * PI / 100_000.0);
            for r in [1e-3, 1.0, 37.0, 1e6] {
                let (y, x) = (r * a.sin(), r * a.cos());
                worst = worst.max((atan2(y, x) - y.atan2(x)).abs());
            }
        }
        assert!(worst < 1e-15, "{worst}");
        // the reduction boundaries and the special values handed to the library
        for t in [
            0.66,
            0.660_000_000_000_001,
            TAN_3PI_8,
            2.414_213_562_373_096,
            1.0,
        ] {
            assert!((atan2(t, 1.0) - t.atan()).abs() < 1e-15, "{t}");
        }
        assert_eq!(atan2(0.0, -1.0), PI);
        assert_eq!(atan2(-0.0, 1.0), -0.0f64.atan2(1.0));
        assert_eq!(atan2(1.0, 0.0), FRAC_PI_2);
        assert!(atan2(f64::NAN, 1.0).is_nan());
        assert_eq!(atan2(f64::INFINITY, f64::INFINITY), FRAC_PI_4);
        assert!((atan2(1e300, 1e-300) - FRAC_PI_2).abs() < 1e-15);
    }

    proptest! {
        /// The pass over slices gives exactly the scalar function's numbers, special values
        /// included.
        #[test]
        fn slices_equal_the_scalar_function(
            pairs in proptest::collection::vec((-1e3f64..1e3, -1e3f64..1e3, 0u8..8), 1..40),
        ) {
            let pick = |v: f64, k: u8| match k {
                0 => 0.0,
                1 => f64::INFINITY,
                2 => f64::NAN,
                3 => v * 1e-300,
                4 => v * 1e300,
                _ => v,
            };
            let ys: Vec<f64> = pairs.iter().map(|p| pick(p.0, p.2)).collect();
            let xs: Vec<f64> = pairs.iter().map(|p| pick(p.1, p.2 / 2)).collect();
            let mut out = vec![0.0; ys.len()];
            atan2_slices(&ys, &xs, &mut out);
            for ((o, &y), &x) in out.iter().zip(&ys).zip(&xs) {
                let want = atan2(y, x);
                prop_assert!(o.to_bits() == want.to_bits() || (o.is_nan() && want.is_nan()), "{y} {x}: {o} vs {want}");
            }
        }

        #[test]
        fn close_to_the_library_anywhere(y in -1e3f64..1e3, x in -1e3f64..1e3) {
            let want = y.atan2(x);
            prop_assert!((atan2(y, x) - want).abs() <= 4.0 * f64::EPSILON * want.abs().max(1e-300) + 1e-300);
        }
    }
}
