//! The beams of one planar scan as the occlusion-aware detection model reads them
//! ([`super::OcclusionDetection`]): bearing of beam i = `angle_min + i · increment`, its range,
//! and how many beams of a bearing window end nearer than a limit, with range extremes of
//! power-of-two runs of beams so that most windows are answered by two lookups.
//!
//! Bearings count modulo 2π: a window that reaches past an end of the scan also takes the
//! beams a whole turn away, so a scan of a full turn has no seam, wherever it starts (−π, 0).
//!
//! Not for: reading scans from files ([`crate::laser2d`]) or deciding what blocks whom.

use crate::error::{ensure_finite, Error, Result};

/// The beams of one scan in the sensor frame: bearing of beam i = `angle_min + i · increment`,
/// its range (`+∞` for "no return").
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BeamView {
    pub(super) angle_min: f64,
    pub(super) angle_increment: f64,
    pub(super) ranges: Vec<f64>,
    /// Range extremes of power-of-two runs of beams, for whole-window answers.
    pub(super) extremes: WindowExtremes,
}

/// Sparse tables of the range minimum and maximum: level k holds, for every first beam i, the
/// extremes of beams i..i + 2^k. Any window is the union of two (overlapping) runs of one
/// level, so its extremes cost two lookups. Rebuilt once per scan, reusing its buffers.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct WindowExtremes {
    /// Level k starts at `offsets[k]` in `min` and `max` and has n − 2^k + 1 entries.
    offsets: Vec<usize>,
    min: Vec<f64>,
    max: Vec<f64>,
}

impl WindowExtremes {
    /// No beams.
    const EMPTY: WindowExtremes = WindowExtremes {
        offsets: Vec::new(),
        min: Vec::new(),
        max: Vec::new(),
    };

    fn rebuild(&mut self, ranges: &[f64]) {
        let n = ranges.len();
        self.offsets.clear();
        let mut total = 0;
        let mut width = 1;
        while width <= n {
            self.offsets.push(total);
            total += n + 1 - width;
            width *= 2;
        }
        self.min.resize(total, 0.0);
        self.max.resize(total, 0.0);
        if n == 0 {
            return;
        }
        self.min[..n].copy_from_slice(ranges);
        self.max[..n].copy_from_slice(ranges);
        for k in 1..self.offsets.len() {
            let half = 1 << (k - 1);
            let (prev, this) = (self.offsets[k - 1], self.offsets[k]);
            let len = n + 1 - 2 * half;
            let (done, next) = self.min.split_at_mut(this);
            for ((o, &a), &b) in next[..len]
                .iter_mut()
                .zip(&done[prev..prev + len])
                .zip(&done[prev + half..prev + half + len])
            {
                *o = a.min(b);
            }
            let (done, next) = self.max.split_at_mut(this);
            for ((o, &a), &b) in next[..len]
                .iter_mut()
                .zip(&done[prev..prev + len])
                .zip(&done[prev + half..prev + half + len])
            {
                *o = a.max(b);
            }
        }
    }

    /// (min, max) of beams `first..=last` (first ≤ last < n).
    #[inline(always)]
    pub(super) fn query(&self, first: usize, last: usize) -> (f64, f64) {
        let len = last - first + 1;
        let k = (usize::BITS - 1 - len.leading_zeros()) as usize;
        let o = self.offsets[k];
        let (a, b) = (o + first, o + last + 1 - (1 << k));
        (self.min[a].min(self.min[b]), self.max[a].max(self.max[b]))
    }
}

/// x rounded half away from zero, exact: the integer conversion is much cheaper than the
/// library call on targets without a rounding instruction.
#[inline]
fn round_exact(x: f64) -> f64 {
    if x.abs() < 4.5e15 {
        let t = x as i64 as f64;
        let frac = x - t;
        if frac >= 0.5 {
            t + 1.0
        } else if frac <= -0.5 {
            t - 1.0
        } else {
            t
        }
    } else {
        x.round()
    }
}

impl BeamView {
    /// A view of no beams (nothing blocks).
    pub const EMPTY: BeamView = BeamView {
        angle_min: 0.0,
        angle_increment: 0.0,
        ranges: Vec::new(),
        extremes: WindowExtremes::EMPTY,
    };

    /// A view from the scan header and its ranges; non-finite or non-positive ranges mean "no
    /// return" and never block.
    pub fn new(angle_min: f64, angle_increment: f64, ranges: &[f64]) -> Result<Self> {
        ensure_finite("beam view header", &[angle_min, angle_increment])?;
        if angle_increment == 0.0 && ranges.len() > 1 {
            return Err(Error::invalid(
                "beam view",
                "angle increment is zero with several beams",
            ));
        }
        let mut view = BeamView {
            angle_min,
            angle_increment,
            ranges: Vec::with_capacity(ranges.len()),
            extremes: WindowExtremes::default(),
        };
        view.set_ranges(ranges.iter().copied());
        Ok(view)
    }

    /// Replaces the ranges, keeping the header (reuses the buffer).
    pub fn set_ranges(&mut self, ranges: impl IntoIterator<Item = f64>) {
        self.ranges.clear();
        self.ranges.extend(ranges.into_iter().map(|r| {
            if r.is_finite() && r > 0.0 {
                r
            } else {
                f64::INFINITY
            }
        }));
        self.extremes.rebuild(&self.ranges);
    }

    /// Replaces the header and the ranges in place (no allocation once the buffers are large
    /// enough); unlike [`BeamView::new`] the header is not checked (a view whose increment is
    /// not a positive finite number finds no window).
    pub fn reset(
        &mut self,
        angle_min: f64,
        angle_increment: f64,
        ranges: impl IntoIterator<Item = f64>,
    ) {
        self.angle_min = angle_min;
        self.angle_increment = angle_increment;
        self.set_ranges(ranges);
    }

    /// Number of beams.
    pub fn len(&self) -> usize {
        self.ranges.len()
    }

    /// True without beams.
    pub fn is_empty(&self) -> bool {
        self.ranges.is_empty()
    }

    /// (blocked, total) beams of the window `bearing ± half_width` whose return is shorter than
    /// `limit`, bearings modulo 2π (a window past an end of the scan takes the beams a whole
    /// turn away too); the window holds at least the beam nearest to `bearing` when that lies
    /// within half a spacing of it. (0, 0) when the window misses the scan.
    #[inline]
    pub fn blocked(&self, bearing: f64, half_width: f64, limit: f64) -> (usize, usize) {
        let (first, last) = self.window_ends(bearing, half_width);
        // With a beam on either side left out and the scan within one turn, no other copy of
        // the window, a turn away, meets the scan, and the nearest beam is a beam of the scan.
        let top = self.ranges.len() as f64 - 1.0;
        let span = top * self.angle_increment.abs();
        if first >= 1.0 && last <= top - 1.0 && span <= std::f64::consts::TAU {
            self.count_blocked(first, last, bearing, limit)
        } else {
            self.blocked_around(bearing, half_width, limit, first, last)
        }
    }

    /// [`BeamView::blocked`] for a window that reaches an end of the scan, or on a scan of more
    /// than a turn: the window and its copies a whole number of turns away, each clipped to
    /// the scan; without a beam in any of them, the beam within half a spacing of the bearing
    /// or of a copy of it. Non-finite windows and a zero increment take the window as it is.
    #[inline(never)]
    fn blocked_around(
        &self,
        bearing: f64,
        half_width: f64,
        limit: f64,
        first: f64,
        last: f64,
    ) -> (usize, usize) {
        let inc = self.angle_increment;
        let a = (bearing - half_width - self.angle_min) / inc;
        let b = (bearing + half_width - self.angle_min) / inc;
        let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
        // beams per turn; at least one, or the copies overlap beam by beam
        let turn = std::f64::consts::TAU / inc.abs();
        if self.ranges.is_empty() || !(lo.is_finite() && hi.is_finite() && turn >= 1.0) {
            return self.count_blocked(first, last, bearing, limit);
        }
        let top = (self.ranges.len() - 1) as f64;
        let (mut blocked, mut total) = (0, 0);
        // copies lo + k · turn ..= hi + k · turn that can meet 0..=top
        let mut k = (-hi / turn).ceil();
        let k_last = ((top - lo) / turn).floor();
        while k <= k_last {
            let first = (lo + k * turn).ceil().max(0.0);
            let last = (hi + k * turn).floor().min(top);
            if first <= last {
                let (b, t) = self.count_blocked(first, last, bearing, limit);
                blocked += b;
                total += t;
            }
            k += 1.0;
        }
        if total > 0 {
            return (blocked, total);
        }
        // No beam direction inside any copy: the nearest beam, from the first copy of the
        // bearing at or above index −½.
        let c = (bearing - self.angle_min) / inc;
        let nearest = round_exact(c + ((-0.5 - c) / turn).ceil() * turn);
        if (0.0..=top).contains(&nearest) {
            self.count_blocked(nearest, nearest, bearing, limit)
        } else {
            (0, 0)
        }
    }

    /// The unclipped first and last beam index of the window `bearing ± half_width`, ⌈lo⌉ and
    /// ⌊hi⌋ as whole floats (first > last when no beam direction falls inside it). Free of
    /// branches and calls, so a loop over many windows runs on vector lanes; the rest of
    /// [`BeamView::blocked`] is [`BeamView::count_blocked`] (or, past an end of the scan,
    /// [`BeamView::blocked_around`]).
    #[inline(always)]
    pub(super) fn window_ends(&self, bearing: f64, half_width: f64) -> (f64, f64) {
        let inc = if self.angle_increment == 0.0 {
            1.0
        } else {
            self.angle_increment
        };
        let a = (bearing - half_width - self.angle_min) / inc;
        let b = (bearing + half_width - self.angle_min) / inc;
        let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
        (ceil_lane(lo), floor_lane(hi))
    }

    /// The second half of [`BeamView::blocked`], from the window ends that
    /// [`BeamView::window_ends`] gives for `bearing`.
    #[inline]
    pub(super) fn count_blocked(
        &self,
        first: f64,
        last: f64,
        bearing: f64,
        limit: f64,
    ) -> (usize, usize) {
        let n = self.ranges.len();
        if n == 0 {
            return (0, 0);
        }
        let (mut first, mut last) = (first, last);
        if first > last {
            let inc = if self.angle_increment == 0.0 {
                1.0
            } else {
                self.angle_increment
            };
            let c = round_exact((bearing - self.angle_min) / inc);
            first = c;
            last = c;
        }
        let first = first.max(0.0);
        let last = last.min((n - 1) as f64);
        if first > last {
            return (0, 0);
        }
        // Both are whole numbers in [0, n − 1] here (max/min drop a NaN), so the conversion
        // through i64 is exact and cheaper than the saturating one to usize.
        let (first, last) = (first as i64 as usize, last as i64 as usize);
        let total = last - first + 1;
        // Whole-window answers first: most windows are entirely clear or entirely blocked.
        let (min, max) = self.extremes.query(first, last);
        if min >= limit {
            return (0, total);
        }
        if max < limit {
            return (total, total);
        }
        let window = &self.ranges[first..=last];
        let blocked = window.iter().map(|&r| usize::from(r < limit)).sum();
        (blocked, total)
    }
}

/// Beyond this magnitude window ends are clamped before rounding: they lie far outside any
/// scan either way, and below it adding [`ROUND_SHIFT`] rounds exactly.
const LANE_CLAMP: f64 = 1.0e15;
/// 1.5 · 2^52: x + this − this is x rounded to the nearest integer (ties to even) for
/// |x| ≤ 2^51.
const ROUND_SHIFT: f64 = 6_755_399_441_055_744.0;

/// ⌈x⌉ without branches or calls (x clamped to ±[`LANE_CLAMP`] first; NaN stays NaN): the
/// nearest integer r, plus one when r < x.
#[inline(always)]
fn ceil_lane(x: f64) -> f64 {
    let x = x.clamp(-LANE_CLAMP, LANE_CLAMP);
    let r = (x + ROUND_SHIFT) - ROUND_SHIFT;
    r + if r < x { 1.0 } else { 0.0 }
}

/// ⌊x⌋ without branches or calls (see [`ceil_lane`]).
#[inline(always)]
fn floor_lane(x: f64) -> f64 {
    let x = x.clamp(-LANE_CLAMP, LANE_CLAMP);
    let r = (x + ROUND_SHIFT) - ROUND_SHIFT;
    r - if r > x { 1.0 } else { 0.0 }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// 181 beams over ±90°, 1° apart, all at 20 m except a wall piece at 3 m over beams
    /// 85..=95 (bearings −5°..=5°). Shared with the occlusion model's tests.
    pub(crate) fn view() -> BeamView {
        let ranges: Vec<f64> = (0..181)
            .map(|i| if (85..=95).contains(&i) { 3.0 } else { 20.0 })
            .collect();
        BeamView::new(-FRAC_PI_2, PI / 180.0, &ranges).unwrap()
    }

    #[test]
    fn window_counts_blocked_beams() {
        let v = view();
        // straight ahead, ±2°: beams 88..=92, all at 3 m < 5 m
        assert_eq!(v.blocked(0.0, 2f64.to_radians(), 5.0), (5, 5));
        // 10° left, ±2°: beams 98..=102 at 20 m
        assert_eq!(
            v.blocked(10f64.to_radians(), 2f64.to_radians(), 5.0),
            (0, 5)
        );
        // straddling the wall's edge at 5°: beams 93..=97 → 93, 94, 95 blocked
        assert_eq!(v.blocked(5f64.to_radians(), 2f64.to_radians(), 5.0), (3, 5));
        // a window narrower than a beam takes the nearest beam
        assert_eq!(v.blocked(0.2f64.to_radians(), 1e-4, 5.0), (1, 1));
        // behind the scanner: nothing
        assert_eq!(v.blocked(PI, 0.01, 5.0), (0, 0));
    }

    #[test]
    fn windows_run_on_past_the_ends_of_a_full_turn() {
        // 360 beams 1° apart from 0°, a wall at 3 m over beams 355..=359 and 0..=4
        let ranges: Vec<f64> = (0..360)
            .map(|i| if !(5..355).contains(&i) { 3.0 } else { 20.0 })
            .collect();
        let deg = |a: f64| a.to_radians();
        let v = BeamView::new(0.0, deg(1.0), &ranges).unwrap();
        // straight ahead, ±2.5°: beams 358, 359, 0, 1, 2
        assert_eq!(v.blocked(0.0, deg(2.5), 5.0), (5, 5));
        // at −6°, ±2.5°: beams 352..=356, of which 355 and 356 blocked
        assert_eq!(v.blocked(deg(-6.0), deg(2.5), 5.0), (2, 5));
        // narrower than a beam at −0.8°: the nearest beam is 359
        assert_eq!(v.blocked(deg(-0.8), 1e-4, 5.0), (1, 1));
        assert_eq!(v.blocked(deg(-0.8), 1e-4, 2.0), (0, 1));
        // the same ranges from −180°: astride ±180°, beams 358, 359 (178°, 179°) and 0, 1, 2
        let v = BeamView::new(-PI, deg(1.0), &ranges).unwrap();
        assert_eq!(v.blocked(PI, deg(2.5), 5.0), (5, 5));
        assert_eq!(v.blocked(-PI, deg(2.5), 5.0), (5, 5));
        // 361 beams from −180° to 180°: the beam at ±180° is there twice
        let v = BeamView::new(-PI, deg(1.0), &[vec![3.0; 3], vec![20.0; 358]].concat()).unwrap();
        assert_eq!(v.blocked(PI, deg(2.5), 5.0), (3, 6));
        // a half-turn scan has nothing behind it, and its first beam is beam 0 (−90°)
        let v = BeamView::new(-FRAC_PI_2, deg(1.0), &ranges[..181]).unwrap();
        assert_eq!(v.blocked(PI, deg(2.5), 5.0), (0, 0));
        assert_eq!(v.blocked(deg(-88.9), deg(2.5), 5.0), (4, 4));
    }

    /// The window rule evaluated beam by beam with the library's rounding.
    fn blocked_by_hand(v: &BeamView, bearing: f64, half: f64, limit: f64) -> (usize, usize) {
        let n = v.len() as f64;
        let inc = v.angle_increment;
        let (mut first, mut last) = (
            ((bearing - half - v.angle_min) / inc).ceil(),
            ((bearing + half - v.angle_min) / inc).floor(),
        );
        if first > last {
            first = ((bearing - v.angle_min) / inc).round();
            last = first;
        }
        let (first, last) = (first.max(0.0), last.min(n - 1.0));
        if first > last {
            return (0, 0);
        }
        let window = &v.ranges[first as usize..=last as usize];
        (window.iter().filter(|&&r| r < limit).count(), window.len())
    }

    proptest::proptest! {
        #[test]
        fn lane_rounding_matches_the_library(x in -1e15f64..1e15, k in -60i32..60) {
            let v = x * 2f64.powi(k.min(0));
            proptest::prop_assert_eq!(ceil_lane(v), v.ceil());
            proptest::prop_assert_eq!(floor_lane(v), v.floor());
        }

        #[test]
        fn window_rounding_matches_the_library(
            ranges in proptest::collection::vec(0.5f64..12.0, 1..400),
            bearing in -2.0f64..2.0,
            half in 0.0f64..0.8,
            limit in 0.0f64..13.0,
        ) {
            let v = BeamView::new(-FRAC_PI_2, PI / 360.0, &ranges).unwrap();
            proptest::prop_assert_eq!(
                v.blocked(bearing, half, limit),
                blocked_by_hand(&v, bearing, half, limit)
            );
        }
    }

    #[test]
    fn exact_rounding_matches_the_library() {
        for x in [
            0.0, -0.0, 0.5, -0.5, 1.5, 2.5, -2.5, 3.0, -3.0, 1e-300, -7.999, 7.999, 1e17,
        ] {
            assert_eq!(round_exact(x), x.round(), "{x}");
        }
        for x in [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            2.5,
            -2.5,
            3.0,
            -3.0,
            1e-300,
            -7.999,
            7.999,
            4.5e14,
            -4.5e14,
            0.499_999_999_999_999_94,
            -0.499_999_999_999_999_94,
            1e15,
            -1e15,
        ] {
            assert_eq!(ceil_lane(x), x.ceil(), "{x}");
            assert_eq!(floor_lane(x), x.floor(), "{x}");
        }
        assert!(ceil_lane(f64::NAN).is_nan() && floor_lane(f64::NAN).is_nan());
        // far outside any scan the ends are clamped
        assert_eq!(ceil_lane(1e17), LANE_CLAMP);
        assert_eq!(floor_lane(f64::NEG_INFINITY), -LANE_CLAMP);
    }
}
