//! Multi-object estimates from an LMB density: the cardinality distribution, its MAP value, and
//! the tracks with the highest existence probabilities (Reuter et al. 2014, Sec. III-C).
//! Not for: metrics against ground truth (see `crate::metrics`).

use super::track::{Estimate, Track};
use rayon::prelude::*;

/// The cardinality distribution ρ(n), n = 0..=N, of independent Bernoulli components with
/// existence probabilities `r`: the coefficients of Πᵢ ((1 − rᵢ) + rᵢ·z).
pub fn cardinality_distribution(r: &[f64]) -> Vec<f64> {
    let mut rho = vec![0.0; r.len() + 1];
    rho[0] = 1.0;
    for (k, &ri) in r.iter().enumerate() {
        let ri = ri.clamp(0.0, 1.0);
        for n in (0..=k + 1).rev() {
            let keep = rho[n] * (1.0 - ri);
            let add = if n > 0 { rho[n - 1] * ri } else { 0.0 };
            rho[n] = keep + add;
        }
    }
    rho
}

/// The most probable cardinality (the smallest n on ties).
pub fn map_cardinality(r: &[f64]) -> usize {
    let rho = cardinality_distribution(r);
    let mut best = 0;
    for (n, &p) in rho.iter().enumerate() {
        if p > rho[best] {
            best = n;
        }
    }
    best
}

/// Estimates: the MAP number of tracks, chosen by decreasing existence probability (ties by
/// label), each with the weighted mean of its particles.
pub fn map_estimates(tracks: &[Track]) -> Vec<Estimate> {
    let r: Vec<f64> = tracks.iter().map(|t| t.existence).collect();
    let n = map_cardinality(&r);
    let mut order: Vec<usize> = (0..tracks.len()).collect();
    order.sort_by(|&a, &b| {
        tracks[b]
            .existence
            .total_cmp(&tracks[a].existence)
            .then(tracks[a].label.cmp(&tracks[b].label))
    });
    // The means are independent of one another: in parallel, each in particle order.
    let mut out: Vec<Estimate> = order[..n]
        .par_iter()
        .map(|&i| {
            let t = &tracks[i];
            Estimate {
                label: t.label,
                existence: t.existence,
                state: t.particles.mean(),
                age: t.age,
            }
        })
        .collect();
    out.sort_by_key(|e| e.label);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Enumerates all 2^N existence patterns.
    fn brute(r: &[f64]) -> Vec<f64> {
        let mut rho = vec![0.0; r.len() + 1];
        for mask in 0u32..(1 << r.len()) {
            let mut p = 1.0;
            for (i, ri) in r.iter().enumerate() {
                p *= if mask & (1 << i) != 0 { *ri } else { 1.0 - ri };
            }
            rho[mask.count_ones() as usize] += p;
        }
        rho
    }

    #[test]
    fn hand_case() {
        // r = (0.9, 0.6): ρ(0) = 0.1·0.4, ρ(1) = 0.9·0.4 + 0.1·0.6, ρ(2) = 0.54
        let rho = cardinality_distribution(&[0.9, 0.6]);
        assert!((rho[0] - 0.04).abs() < 1e-12);
        assert!((rho[1] - 0.42).abs() < 1e-12);
        assert!((rho[2] - 0.54).abs() < 1e-12);
        assert_eq!(map_cardinality(&[0.9, 0.6]), 2);
        // r = (0.9, 0.4, 0.3): ρ(1) = 0.378 + 0.028 + 0.018 = 0.424 < ρ(2) = 0.252 + 0.162 + 0.012 = 0.426
        assert_eq!(map_cardinality(&[0.9, 0.4, 0.3]), 2);
        // r = (0.9, 0.3, 0.2): ρ(1) = 0.504 + 0.024 + 0.014 = 0.542 is the largest
        assert_eq!(map_cardinality(&[0.9, 0.3, 0.2]), 1);
        assert_eq!(map_cardinality(&[]), 0);
    }

    proptest! {
        #[test]
        fn matches_enumeration(r in proptest::collection::vec(0.0f64..=1.0, 0..10)) {
            let a = cardinality_distribution(&r);
            let b = brute(&r);
            let total: f64 = a.iter().sum();
            prop_assert!((total - 1.0).abs() < 1e-12);
            for (x, y) in a.iter().zip(&b) {
                prop_assert!((x - y).abs() < 1e-12);
            }
        }
    }
}
