//! Found-of-how-many counts of labelled objects ([`Tally`]) and the recall of cars and vans
//! split by KITTI occlusion level and by range ([`RecallBreakdown`]), as `kitti-tools
//! objects` reports its detector's and the tracking evaluation its tracks'.
//!
//! One way of deciding which label was found is here too: the one-to-one nearest matching of
//! bird's-eye positions within a gate ([`match_nearest`]) that `kitti-tools objects` and the
//! drive evaluation count by; the tracking evaluation uses CLEAR's own matching instead.

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

/// One-to-one matching of `found_by` (detections, tracks) to `labels` by horizontal distance:
/// pairs within `gate` (m), nearest first (ties by the index in `found_by`, then in
/// `labels`), each side used once. Returns the label of each of `found_by` and whether each
/// label was found.
pub fn match_nearest(
    found_by: &[[f64; 2]],
    labels: &[[f64; 2]],
    gate: f64,
) -> (Vec<Option<usize>>, Vec<bool>) {
    let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
    for (i, p) in found_by.iter().enumerate() {
        for (j, q) in labels.iter().enumerate() {
            let d = (p[0] - q[0]).hypot(p[1] - q[1]);
            if d <= gate {
                pairs.push((d, i, j));
            }
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut label_of = vec![None; found_by.len()];
    let mut found = vec![false; labels.len()];
    for (_, i, j) in pairs {
        if label_of[i].is_none() && !found[j] {
            label_of[i] = Some(j);
            found[j] = true;
        }
    }
    (label_of, found)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_matching_is_one_to_one_nearest_first() {
        // Tracks at (0, 0) and (2.5, 0); labels at (1, 0), (2, 0) and (10, 0), gate 3 m. The
        // nearest pair is track 2 – label 2 (0.5 m), then track 1 – label 1 (1 m); label 3
        // is beyond every gate. With one track at (1.5, 0), equidistant from labels 1 and 2,
        // the tie goes to the lower index.
        let labels = [[1.0, 0.0], [2.0, 0.0], [10.0, 0.0]];
        assert_eq!(
            match_nearest(&[[0.0, 0.0], [2.5, 0.0]], &labels, 3.0),
            (vec![Some(0), Some(1)], vec![true, true, false])
        );
        assert_eq!(
            match_nearest(&[[1.5, 0.0]], &labels, 3.0),
            (vec![Some(0)], vec![true, false, false])
        );
        assert_eq!(
            match_nearest(&[[0.0, 0.0]], &labels, 0.9),
            (vec![None], vec![false; 3])
        );
        assert_eq!(match_nearest(&[], &[], 3.0), (vec![], vec![]));
    }

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
