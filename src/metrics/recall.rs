//! Found-of-how-many counts of labelled objects ([`Tally`]) and the recall of cars and vans
//! split by KITTI occlusion level and by range ([`RecallBreakdown`]), as `kitti-tools
//! objects` reports its detector's and the tracking evaluation its tracks'.
//!
//! Not for: deciding which label was found (the caller's matching).

use serde::{Deserialize, Serialize};

/// Found of how many.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Tally {
    /// Found (or true).
    pub hits: usize,
    /// Of how many.
    pub total: usize,
}

impl Tally {
    /// `hits / total`, `None` when there are none.
    pub fn ratio(&self) -> Option<f64> {
        (self.total > 0).then(|| self.hits as f64 / self.total as f64)
    }

    /// Counts one more, found or not.
    pub fn add(&mut self, hit: bool) {
        self.total += 1;
        self.hits += usize::from(hit);
    }
}

/// Edges of the range bins (m): 0–10, 10–20, 20–30, 30–40.
pub const RANGE_BINS: [f64; 5] = [0.0, 10.0, 20.0, 30.0, 40.0];

/// Recall of labelled objects within [`RANGE_BINS`]' last edge (40 m), counted per frame: in
/// all, by KITTI occlusion level (0 fully visible, 1 partly occluded, 2 largely occluded,
/// 3 unknown) and by range bin (the last bin holds 40 m itself), so that each split adds up
/// to `recall`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RecallBreakdown {
    /// Every label counted.
    pub recall: Tally,
    /// By occlusion level 0, 1, 2, 3.
    pub by_occlusion: [Tally; 4],
    /// By range bin of [`RANGE_BINS`].
    pub by_range: [Tally; 4],
}

impl RecallBreakdown {
    /// Counts a label at `range` (m) with occlusion level `occluded` (levels outside 0–3 are
    /// unknown), found or not; a label beyond 40 m (or at a range that is not a number) is
    /// left out. Returns whether it was counted.
    pub fn add(&mut self, occluded: i32, range: f64, found: bool) -> bool {
        let Some(bin) = range_bin(range) else {
            return false;
        };
        let level = if (0..=3).contains(&occluded) {
            occluded as usize
        } else {
            3
        };
        self.recall.add(found);
        self.by_occlusion[level].add(found);
        self.by_range[bin].add(found);
        true
    }

    /// Adds another breakdown's counts.
    pub fn merge(&mut self, other: &RecallBreakdown) {
        let add = |a: &mut Tally, b: &Tally| {
            a.hits += b.hits;
            a.total += b.total;
        };
        add(&mut self.recall, &other.recall);
        for (a, b) in self.by_occlusion.iter_mut().zip(&other.by_occlusion) {
            add(a, b);
        }
        for (a, b) in self.by_range.iter_mut().zip(&other.by_range) {
            add(a, b);
        }
    }
}

/// The bin of [`RANGE_BINS`] holding `range` (m), the last one closed: `None` beyond 40 m,
/// below 0 or for NaN.
pub fn range_bin(range: f64) -> Option<usize> {
    let last = RANGE_BINS.len() - 2;
    if range == RANGE_BINS[last + 1] {
        return Some(last);
    }
    RANGE_BINS
        .windows(2)
        .position(|w| range >= w[0] && range < w[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_by_hand() {
        assert_eq!(range_bin(0.0), Some(0));
        assert_eq!(range_bin(9.99), Some(0));
        assert_eq!(range_bin(10.0), Some(1));
        assert_eq!(range_bin(29.5), Some(2));
        assert_eq!(range_bin(40.0), Some(3));
        assert_eq!(range_bin(40.01), None);
        assert_eq!(range_bin(-0.1), None);
        assert_eq!(range_bin(f64::NAN), None);
    }

    #[test]
    fn the_splits_add_up_to_the_whole() {
        let mut r = RecallBreakdown::default();
        // (level, range, found): five counted, one beyond 40 m.
        for (o, d, f) in [
            (0, 5.0, true),
            (2, 25.0, false),
            (2, 35.0, true),
            (1, 40.0, false),
            (7, 12.0, true),
            (0, 41.0, true),
        ] {
            r.add(o, d, f);
        }
        assert_eq!(r.recall, Tally { hits: 3, total: 5 });
        assert_eq!(r.by_occlusion[2], Tally { hits: 1, total: 2 });
        assert_eq!(r.by_occlusion[3], Tally { hits: 1, total: 1 });
        assert_eq!(r.by_range[3], Tally { hits: 1, total: 2 });
        let mut twice = r.clone();
        twice.merge(&r);
        assert_eq!(twice.recall, Tally { hits: 6, total: 10 });
        assert_eq!(Tally { hits: 1, total: 4 }.ratio(), Some(0.25));
        assert_eq!(Tally::default().ratio(), None);
    }
}
