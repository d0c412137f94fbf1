//! `floor` to an integer without the libm call that `floor` costs on the baseline x86-64
//! target (no SSE4.1 rounding instruction), for the grid and voxel keys of point loops. The
//! results are those of `v.floor() as i32` / `as i64` (f64 and f32), bit for bit: saturating,
//! NaN to 0.
//!
//! Not for: floors that stay floating point.

/// `v.floor() as i32`: truncate towards zero, then step down when that rounded a negative
/// value up.
#[inline]
#[cfg_attr(not(feature = "kitti"), allow(dead_code))] // voxel keys of the point clouds
pub(crate) fn floor_i32(v: f64) -> i32 {
    let t = v as i32;
    t.saturating_sub((v < t as f64) as i32)
}

/// `v.floor() as i32` for an `f32` (see [`floor_i32`]).
#[inline]
#[cfg_attr(not(feature = "kitti"), allow(dead_code))] // the plane RANSAC's cells
pub(crate) fn floor_f32_i32(v: f32) -> i32 {
    let t = v as i32;
    t.saturating_sub((v < t as f32) as i32)
}

/// `v.floor() as i64` (see [`floor_i32`]). Beyond 2⁵³ every f64 is an integer, so the
/// truncation is exact wherever `t as f64` rounds.
#[inline]
#[cfg_attr(not(any(feature = "kitti", feature = "laser2d")), allow(dead_code))]
pub(crate) fn floor_i64(v: f64) -> i64 {
    let t = v as i64;
    t.saturating_sub((v < t as f64) as i64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const EDGES: [f64; 20] = [
        0.0,
        -0.0,
        0.5,
        -0.5,
        -1.0,
        1.0,
        -1e-300,
        2_147_483_647.9,
        2_147_483_648.0,
        -2_147_483_648.0,
        -2_147_483_648.5,
        9_007_199_254_740_993.0,
        -9_223_372_036_854_775_808.0,
        9_223_372_036_854_775_807.0,
        -3e20,
        3e20,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
        f64::MIN_POSITIVE,
    ];

    #[test]
    fn edge_cases_match_floor() {
        for v in EDGES
            .into_iter()
            .chain([f64::MAX, f64::MIN, -f64::MIN_POSITIVE])
        {
            assert_eq!(floor_i32(v), v.floor() as i32, "{v}");
            assert_eq!(floor_i64(v), v.floor() as i64, "{v}");
            let w = v as f32;
            assert_eq!(floor_f32_i32(w), w.floor() as i32, "{w}");
        }
    }

    proptest! {
        #[test]
        fn any_value_matches_floor(v in prop::num::f64::ANY) {
            prop_assert_eq!(floor_i32(v), v.floor() as i32);
            prop_assert_eq!(floor_i64(v), v.floor() as i64);
        }

        #[test]
        fn any_f32_matches_floor(v in prop::num::f32::ANY) {
            prop_assert_eq!(floor_f32_i32(v), v.floor() as i32);
        }

        #[test]
        fn values_near_integers_match_floor(k in -3_000_000_000i64..3_000_000_000, d in -1e-6f64..1e-6) {
            let v = k as f64 + d;
            prop_assert_eq!(floor_i32(v), v.floor() as i32);
            prop_assert_eq!(floor_i64(v), v.floor() as i64);
        }
    }
}
