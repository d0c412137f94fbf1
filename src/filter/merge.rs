//! Duplicate tracks merged: two tracks that compete for the same measurements and whose
//! posterior densities nearly coincide describe one object twice.
//!
//! Duplicates arise from measurement-driven birth: when an object's measurement jumps (its
//! visible part changes, its track lags behind a manoeuvre), the measurement is poorly
//! explained, a new track is proposed at it, and from then on the two tracks share the
//! object's detections, each keeping about half of its existence. Which of them the MAP
//! estimate reports can then change from frame to frame: an identity switch with no second
//! object in sight. The merge is the label-preserving counterpart of the Gaussian-mixture
//! merging of Vo & Ma (IEEE TSP 2006, Table II): two tracks are merged when the squared
//! distance between their posterior means, each component scaled by the sum of the two
//! tracks' variances of it, is at most a threshold; the label of the more probable track
//! survives (the one the MAP estimate reports), with existence r₁ + r₂ (at most 1: the
//! expected number of objects the two held) and the mixture density
//! (r₁ p₁ + r₂ p₂) / (r₁ + r₂).
//!
//! Only tracks whose most probable measurement in the step is the same one are compared, so
//! the cost follows the contested measurements, not the number of tracks, and two tracks that
//! each explain a measurement of their own stay apart even when their states coincide (two
//! stretches of one facade are one plane, measured twice). Two distinct objects side by side
//! are kept apart because each of their tracks is confident: the distance is scaled by the
//! sum of their spreads, which is small once both are established.
//!
//! Not for: the association (see [`super::association`]), pruning or estimation.

use super::track::Track;
use super::ParticleSet;

/// How far apart two tracks' posteriors are, for the duplicate merge: the seam for state
/// spaces in which two distinct objects can share a state (two stretches of one facade are
/// one plane) and so must never merge, or that want another distance.
pub trait MergeDistance: Send + Sync {
    /// Squared distance between two densities, each summarised by its mean and the standard
    /// deviation of every component; `None` when the two may not merge.
    fn distance2(&self, a: (&[f64], &[f64]), b: (&[f64], &[f64])) -> Option<f64>;

    /// [`MergeDistance::distance2`] for two densities with the tags of their particle sets
    /// ([`crate::filter::ParticleSet::tag`]), which is what the filter calls: by default sets
    /// of different tags never merge and the tags say nothing else.
    fn tagged_distance2(
        &self,
        a: (Option<u32>, &[f64], &[f64]),
        b: (Option<u32>, &[f64], &[f64]),
    ) -> Option<f64> {
        if a.0 != b.0 {
            return None;
        }
        self.distance2((a.1, a.2), (b.1, b.2))
    }
}

/// [`scaled_distance2`] for every pair of tracks: the default [`MergeDistance`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ScaledDistance;

impl MergeDistance for ScaledDistance {
    fn distance2(&self, a: (&[f64], &[f64]), b: (&[f64], &[f64])) -> Option<f64> {
        scaled_distance2(a, b)
    }
}

/// Squared distance between two densities' means, component `c` scaled by `σ²_a,c + σ²_b,c`.
/// Components that neither density spreads (such as a kind code) must be equal; otherwise the
/// densities are of different things and `None` is returned. "Not spread" and "equal" are
/// judged to rounding ([`CONSTANT_TOLERANCE`] of the component's magnitude): a weighted mean of
/// equal values is not always exactly that value, and the spread it leaves (about 1e-16) must
/// not count as a distance.
pub fn scaled_distance2(a: (&[f64], &[f64]), b: (&[f64], &[f64])) -> Option<f64> {
    let ((ma, sa), (mb, sb)) = (a, b);
    let mut d2 = 0.0;
    for c in 0..ma.len().min(mb.len()) {
        let var = sa[c] * sa[c] + sb[c] * sb[c];
        let diff = ma[c] - mb[c];
        let rounding = CONSTANT_TOLERANCE * ma[c].abs().max(mb[c].abs()).max(1.0);
        if var > rounding * rounding {
            d2 += diff * diff / var;
        } else if diff.abs() > rounding {
            return None;
        }
    }
    d2.is_finite().then_some(d2)
}

/// The relative size below which a component's spread, or two means' difference, is rounding
/// ([`scaled_distance2`]).
pub const CONSTANT_TOLERANCE: f64 = 1e-12;

/// The pairs `(survivor, absorbed)` of track indices to merge: among the pairs of tracks that
/// claim the same measurement (`claims[i]` is the measurement track `i` most probably
/// generated, if any), those whose `distance` is at most `threshold`, taken in
/// ascending distance (ties: lower indices), each track in at most one pair. The survivor is
/// the more probable track (ties: the older label).
pub fn duplicate_pairs(
    tracks: &[Track],
    claims: &[Option<usize>],
    distance: &dyn MergeDistance,
    threshold: f64,
) -> Vec<(usize, usize)> {
    let mut claimed: Vec<(usize, usize)> = claims
        .iter()
        .enumerate()
        .filter_map(|(i, c)| c.map(|j| (j, i)))
        .collect();
    claimed.sort_unstable();
    let mut candidates: Vec<(usize, usize)> = Vec::new();
    for run in claimed.chunk_by(|x, y| x.0 == y.0) {
        for (k, &(_, a)) in run.iter().enumerate() {
            candidates.extend(run[k + 1..].iter().map(|&(_, b)| (a, b)));
        }
    }
    if candidates.is_empty() {
        return Vec::new();
    }
    let mut summary: Vec<Option<(Vec<f64>, Vec<f64>)>> = vec![None; tracks.len()];
    for &(a, b) in &candidates {
        for i in [a, b] {
            if summary[i].is_none() && !tracks[i].particles.is_empty() {
                summary[i] = Some(tracks[i].particles.mean_and_std_dev());
            }
        }
    }
    let mut close: Vec<(f64, usize, usize)> = candidates
        .into_iter()
        .filter_map(|(a, b)| {
            let (ma, sa) = summary[a].as_ref()?;
            let (mb, sb) = summary[b].as_ref()?;
            let (ta, tb) = (tracks[a].particles.tag(), tracks[b].particles.tag());
            let d2 = distance.tagged_distance2((ta, ma, sa), (tb, mb, sb))?;
            (d2 <= threshold).then_some((d2, a, b))
        })
        .collect();
    close.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    let mut used = vec![false; tracks.len()];
    let mut out = Vec::new();
    for (_, a, b) in close {
        if used[a] || used[b] {
            continue;
        }
        used[a] = true;
        used[b] = true;
        if survives(&tracks[a], &tracks[b]) {
            out.push((a, b));
        } else {
            out.push((b, a));
        }
    }
    out
}

/// Whether `a` keeps its label when merged with `b`: the higher existence, on a tie the
/// older (smaller) label. The more probable of two duplicates is the one the MAP estimate
/// reports, so its label is the one a reader has been seeing.
fn survives(a: &Track, b: &Track) -> bool {
    a.existence > b.existence || (a.existence == b.existence && a.label <= b.label)
}

/// Merges track `absorbed` into `survivor`: existence r₁ + r₂ (at most 1), the particles of
/// both with weights in proportion r·w, and the survivor's label, age and history; the
/// absorbed track is left with existence 0 (to be pruned). Returns false, changing nothing,
/// when the two sets cannot be joined (different dimension or particle histories).
pub fn merge_into(survivor: &mut Track, absorbed: &mut Track) -> bool {
    let (r1, r2) = (survivor.existence, absorbed.existence);
    let total = r1 + r2;
    if !(total > 0.0 && total.is_finite()) {
        return false;
    }
    if !survivor.particles.mix(&absorbed.particles, r2 / total) {
        return false;
    }
    survivor.existence = total.min(1.0);
    survivor.expected_detections = survivor
        .expected_detections
        .max(absorbed.expected_detections);
    absorbed.existence = 0.0;
    absorbed.particles = ParticleSet::zeroed(absorbed.particles.dim(), 0);
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::Label;
    use proptest::prelude::*;

    /// A one-component track whose particles sit at `xs`, equally weighted.
    fn track(step: u32, existence: f64, xs: &[f64]) -> Track {
        let rows: Vec<Vec<f64>> = xs.iter().map(|&x| vec![x]).collect();
        let particles = ParticleSet::from_rows(&rows, &vec![1.0; xs.len()]).unwrap();
        Track::new(Label::new(step, 0), existence, particles)
    }

    #[test]
    fn sets_of_different_tags_never_merge() {
        let (m, sd) = ([0.0, 0.0], [1.0, 1.0]);
        let d = ScaledDistance;
        assert_eq!(
            d.tagged_distance2((None, &m, &sd), (None, &m, &sd)),
            Some(0.0)
        );
        assert_eq!(
            d.tagged_distance2((Some(1), &m, &sd), (Some(1), &m, &sd)),
            Some(0.0)
        );
        assert_eq!(
            d.tagged_distance2((Some(0), &m, &sd), (Some(1), &m, &sd)),
            None
        );
        assert_eq!(
            d.tagged_distance2((Some(0), &m, &sd), (None, &m, &sd)),
            None
        );
    }

    #[test]
    fn distance_scales_each_component_by_the_summed_variances() {
        // (3² + 4²) / (1 + 1) = 12.5
        let d2 = scaled_distance2((&[0.0, 0.0], &[1.0, 1.0]), (&[3.0, 4.0], &[1.0, 1.0]));
        assert_eq!(d2, Some(12.5));
        // A component neither spreads counts only by being equal.
        let same_kind = scaled_distance2((&[1.0, 2.0], &[0.0, 1.0]), (&[1.0, 4.0], &[0.0, 1.0]));
        assert_eq!(same_kind, Some(2.0));
        let other_kind = scaled_distance2((&[1.0, 2.0], &[0.0, 1.0]), (&[2.0, 2.0], &[0.0, 1.0]));
        assert_eq!(other_kind, None);
    }

    #[test]
    fn a_constant_component_left_with_rounding_spread_counts_only_by_being_equal() {
        // Six equal weights of 1/6 sum to 0.9999999999999999: the weighted mean of a constant
        // 1.0 misses it by one rounding step and leaves a spread of about 1e-16.
        let rows = vec![vec![1.0, 0.0]; 6];
        let set = ParticleSet::from_rows(&rows, &[1.0; 6]).unwrap();
        let (mean, std) = set.mean_and_std_dev();
        assert!(mean[0] < 1.0 && std[0] > 0.0, "mean {mean:?} std {std:?}");
        let exact = ([1.0, 0.5], [0.0, 1.0]);
        let d2 = scaled_distance2((&mean, &std), (&exact.0, &exact.1)).unwrap();
        assert!((d2 - 0.25).abs() < 1e-12, "{d2}");
        let other = ([2.0, 0.5], [1e-17, 1.0]);
        assert_eq!(scaled_distance2((&mean, &std), (&other.0, &other.1)), None);
    }

    #[test]
    fn only_close_tracks_claiming_one_measurement_are_paired() {
        let tracks = vec![
            track(0, 0.5, &[-0.1, 0.1]), // mean 0, σ 0.1
            track(1, 0.7, &[0.1, 0.3]),  // mean 0.2: d² = 0.04 / 0.02 = 2
            track(2, 0.9, &[5.0, 5.2]),  // far from both
            track(3, 0.9, &[-0.1, 0.1]), // on the first, but claiming another measurement
        ];
        let pairs = |t: &[Track], claims: &[Option<usize>], threshold: f64| {
            duplicate_pairs(t, claims, &ScaledDistance, threshold)
        };
        let claims = [Some(0), Some(0), Some(0), Some(2)];
        // The more probable track (index 1) keeps its label.
        assert_eq!(pairs(&tracks, &claims, 9.0), vec![(1, 0)]);
        assert!(pairs(&tracks, &claims, 1.9).is_empty());
        // Tracks that claim no measurement, or different ones, stay apart.
        assert!(pairs(&tracks, &[None, Some(0), Some(1), Some(3)], 9.0).is_empty());
        // Equal existence: the older label survives.
        let tied = vec![track(4, 0.5, &[0.1, 0.3]), track(3, 0.5, &[-0.1, 0.1])];
        assert_eq!(pairs(&tied, &[Some(0), Some(0)], 9.0), vec![(1, 0)]);
        // Each track merges at most once a step: the closest pair wins.
        let three = vec![
            track(0, 0.5, &[-0.1, 0.1]),
            track(1, 0.5, &[0.0, 0.2]),
            track(2, 0.5, &[0.3, 0.5]),
        ];
        assert_eq!(
            pairs(&three, &[Some(0), Some(0), Some(0)], 9.0),
            vec![(0, 1)]
        );
        // A distance that refuses a pair keeps it apart.
        struct Never;
        impl MergeDistance for Never {
            fn distance2(&self, _: (&[f64], &[f64]), _: (&[f64], &[f64])) -> Option<f64> {
                None
            }
        }
        assert!(duplicate_pairs(&tracks, &claims, &Never, 9.0).is_empty());
    }

    #[test]
    fn merged_track_holds_both_existences_and_the_mixture() {
        let mut a = track(0, 0.6, &[0.0, 0.0]);
        let mut b = track(1, 0.3, &[0.3, 0.3]);
        assert!(merge_into(&mut a, &mut b));
        assert!((a.existence - 0.9).abs() < 1e-12);
        assert_eq!(a.label, Label::new(0, 0));
        assert_eq!(a.particles.len(), 4);
        // (0.6 · 0 + 0.3 · 0.3) / 0.9
        assert!((a.particles.mean()[0] - 0.1).abs() < 1e-12);
        assert_eq!(b.existence, 0.0);
        assert!(b.particles.is_empty());
        // Existences that add up past 1 give a certain track.
        let mut c = track(0, 0.7, &[0.0]);
        let mut d = track(1, 0.6, &[0.0]);
        assert!(merge_into(&mut c, &mut d));
        assert_eq!(c.existence, 1.0);
    }

    #[test]
    fn sets_of_different_dimension_are_not_merged() {
        let mut a = track(0, 0.6, &[0.0, 0.0]);
        let mut b = Track::new(
            Label::new(1, 0),
            0.3,
            ParticleSet::from_rows(&[vec![0.0, 1.0]], &[1.0]).unwrap(),
        );
        assert!(!merge_into(&mut a, &mut b));
        assert_eq!((a.existence, b.existence), (0.6, 0.3));
        assert_eq!(a.particles.len(), 2);
        // Nor sets whose particles carry pasts of different length.
        let mut c = track(2, 0.3, &[0.0]);
        c.particles.keep_history(2);
        assert!(!merge_into(&mut a, &mut c));
        assert_eq!(a.particles.len(), 2);
    }

    proptest! {
        #[test]
        fn a_mixture_has_the_weighted_mean_and_normalised_weights(
            xs in prop::collection::vec(-10.0f64..10.0, 1..20),
            ys in prop::collection::vec(-10.0f64..10.0, 1..20),
            wx in prop::collection::vec(0.01f64..1.0, 20),
            share in 0.0f64..=1.0,
        ) {
            let rows = |v: &[f64]| v.iter().map(|&x| vec![x, 2.0 * x]).collect::<Vec<_>>();
            let mut a = ParticleSet::from_rows(&rows(&xs), &wx[..xs.len()]).unwrap();
            let b = ParticleSet::from_rows(&rows(&ys), &vec![1.0; ys.len()]).unwrap();
            let (ma, mb) = (a.mean(), b.mean());
            prop_assert!(a.mix(&b, share));
            prop_assert_eq!(a.len(), xs.len() + ys.len());
            let total: f64 = a.weights().iter().sum();
            prop_assert!((total - 1.0).abs() < 1e-9);
            let m = a.mean();
            for c in 0..2 {
                let expected = (1.0 - share) * ma[c] + share * mb[c];
                prop_assert!((m[c] - expected).abs() < 1e-9, "{} vs {}", m[c], expected);
            }
        }
    }
}
