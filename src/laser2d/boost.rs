//! Discrete AdaBoost of decision stumps (Freund & Schapire 1997), the learner Arras, Mozos &
//! Burgard (ICRA 2007) boost their segment features with: small enough to ship as a list of
//! stumps in a JSON file and to evaluate in a few nanoseconds per feature.
//!
//! A stump votes `+1` when `polarity · (x[feature] − threshold) > 0`, else `−1`; the model's
//! score is `Σ α_t h_t(x) / Σ α_t` in `[−1, 1]` and a sample is positive when the score
//! exceeds a threshold of the caller's choice (0 is AdaBoost's own rule).
//!
//! Training sorts every feature once and then finds each round's best stump by one sweep per
//! feature over the sorted values (weighted error, thresholds midway between distinct values),
//! so `rounds × features × samples` work after the sort.
//!
//! Regularised training ([`Boosted::train_with`], [`BoostConfig`]): each stump's vote is
//! shrunk by a learning rate `ν ≤ 1` (its weight `ν·α`, and the sample weights updated with
//! the shrunk vote, as in Friedman's 2001 shrinkage), and a split must leave at least
//! `min_leaf` samples on each side. [`Boosted::train`] is the plain learner (`ν = 1`, one
//! sample per side).
//!
//! Not for: multi-class problems, missing values (every feature must be finite).

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// One weak learner.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stump {
    /// Feature index.
    pub feature: usize,
    /// Threshold on the feature.
    pub threshold: f64,
    /// `+1.0`: positive above the threshold; `−1.0`: positive below.
    pub polarity: f64,
    /// Weight of the vote.
    pub alpha: f64,
}

impl Stump {
    fn vote(&self, x: &[f64]) -> f64 {
        if self.polarity * (x[self.feature] - self.threshold) > 0.0 {
            1.0
        } else {
            -1.0
        }
    }
}

/// Settings of [`Boosted::train_with`] (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoostConfig {
    /// Boosting rounds (stumps at most).
    pub rounds: usize,
    /// Learning rate `ν` in `(0, 1]`: each stump's weight is `ν·α`.
    pub shrinkage: f64,
    /// Fewest samples on either side of a split (≥ 1).
    pub min_leaf: usize,
}

impl BoostConfig {
    /// The plain learner: `rounds` rounds, no shrinkage, one sample per side.
    pub fn rounds(rounds: usize) -> Self {
        BoostConfig {
            rounds,
            shrinkage: 1.0,
            min_leaf: 1,
        }
    }
}

/// A boosted classifier.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Boosted {
    /// The weak learners in training order.
    pub stumps: Vec<Stump>,
}

impl Boosted {
    /// The normalised score in `[−1, 1]` of a feature vector (0 without stumps).
    pub fn score(&self, x: &[f64]) -> f64 {
        let total: f64 = self.stumps.iter().map(|s| s.alpha).sum();
        if total <= 0.0 {
            return 0.0;
        }
        self.stumps.iter().map(|s| s.alpha * s.vote(x)).sum::<f64>() / total
    }

    /// Trains `rounds` stumps on `samples` (rows of equally many finite features) with labels
    /// `positive`. Positives and negatives start with half the total weight each, so that a
    /// rare class is not ignored. Errors on empty or ragged input, non-finite values, or a
    /// single class.
    pub fn train(samples: &[Vec<f64>], positive: &[bool], rounds: usize) -> Result<Boosted> {
        Boosted::train_with(samples, positive, &BoostConfig::rounds(rounds))
    }

    /// The first `k` stumps (all of them when there are fewer): the model after `k` rounds.
    pub fn truncated(&self, k: usize) -> Boosted {
        Boosted {
            stumps: self.stumps[..k.min(self.stumps.len())].to_vec(),
        }
    }

    /// [`Boosted::train`] with shrinkage and a minimum leaf size. Errors as
    /// [`Boosted::train`] does, and on a learning rate outside `(0, 1]` or a zero `min_leaf`.
    pub fn train_with(
        samples: &[Vec<f64>],
        positive: &[bool],
        config: &BoostConfig,
    ) -> Result<Boosted> {
        let n = samples.len();
        let bad = |r: String| Error::invalid("boosting", r);
        if !(config.shrinkage > 0.0 && config.shrinkage <= 1.0) || config.min_leaf == 0 {
            return Err(bad(format!(
                "learning rate {} (must lie in (0, 1]), min_leaf {} (must be ≥ 1)",
                config.shrinkage, config.min_leaf
            )));
        }
        let (rounds, min_leaf) = (config.rounds, config.min_leaf);
        if n == 0 || positive.len() != n {
            return Err(bad(format!("{n} samples, {} labels", positive.len())));
        }
        let dim = samples[0].len();
        if dim == 0 || samples.iter().any(|s| s.len() != dim) {
            return Err(bad("feature vectors of different lengths".into()));
        }
        if samples.iter().flatten().any(|v| !v.is_finite()) {
            return Err(bad("a non-finite feature".into()));
        }
        let n_pos = positive.iter().filter(|&&p| p).count();
        if n_pos == 0 || n_pos == n {
            return Err(bad("both classes are needed".into()));
        }
        let y: Vec<f64> = positive
            .iter()
            .map(|&p| if p { 1.0 } else { -1.0 })
            .collect();
        let mut w: Vec<f64> = positive
            .iter()
            .map(|&p| {
                if p {
                    0.5 / n_pos as f64
                } else {
                    0.5 / (n - n_pos) as f64
                }
            })
            .collect();
        let order: Vec<Vec<usize>> = (0..dim)
            .map(|f| {
                let mut o: Vec<usize> = (0..n).collect();
                o.sort_by(|&a, &b| samples[a][f].total_cmp(&samples[b][f]));
                o
            })
            .collect();
        let mut model = Boosted::default();
        for _ in 0..rounds {
            // Best stump: for a threshold after sorted position i, "positive above" errs on
            // positives at or below and negatives above.
            let w_pos: f64 = (0..n).filter(|&i| positive[i]).map(|i| w[i]).sum();
            let w_neg: f64 = (0..n).filter(|&i| !positive[i]).map(|i| w[i]).sum();
            let mut best = (f64::INFINITY, 0usize, 0.0, 1.0);
            for (f, o) in order.iter().enumerate() {
                // Threshold below everything: all "positive above" → error = w_neg.
                let (mut pos_below, mut neg_below) = (0.0, 0.0);
                for k in 0..n {
                    let i = o[k];
                    if positive[i] {
                        pos_below += w[i];
                    } else {
                        neg_below += w[i];
                    }
                    let v = samples[i][f];
                    if k + 1 < n && samples[o[k + 1]][f] == v {
                        continue;
                    }
                    // k + 1 samples at or below the threshold, n − k − 1 above (the plain
                    // learner also tries the threshold above everything).
                    if min_leaf > 1 && (k + 1 < min_leaf || n - k - 1 < min_leaf) {
                        continue;
                    }
                    let thr = if k + 1 < n {
                        0.5 * (v + samples[o[k + 1]][f])
                    } else {
                        v
                    };
                    let above = pos_below + (w_neg - neg_below);
                    let below = neg_below + (w_pos - pos_below);
                    if above < best.0 {
                        best = (above, f, thr, 1.0);
                    }
                    if below < best.0 {
                        best = (below, f, thr, -1.0);
                    }
                }
            }
            let total = w_pos + w_neg;
            let err = (best.0 / total).clamp(1e-10, 1.0 - 1e-10);
            if err >= 0.5 {
                break;
            }
            let stump = Stump {
                feature: best.1,
                threshold: best.2,
                polarity: best.3,
                alpha: config.shrinkage * 0.5 * ((1.0 - err) / err).ln(),
            };
            let mut sum = 0.0;
            for i in 0..n {
                w[i] *= (-stump.alpha * y[i] * stump.vote(&samples[i])).exp();
                sum += w[i];
            }
            w.iter_mut().for_each(|v| *v /= sum);
            model.stumps.push(stump);
        }
        Ok(model)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boosting_separates_a_box_from_its_surroundings() {
        // Positive inside 0.3 < x < 0.7 and y < 0.5: no single stump does it.
        let mut xs = Vec::new();
        let mut ys = Vec::new();
        for i in 0..20 {
            for j in 0..20 {
                let (x, y) = (i as f64 / 19.0, j as f64 / 19.0);
                xs.push(vec![x, y]);
                ys.push(x > 0.3 && x < 0.7 && y < 0.5);
            }
        }
        let m = Boosted::train(&xs, &ys, 60).unwrap();
        let wrong = xs
            .iter()
            .zip(&ys)
            .filter(|(x, &p)| (m.score(x) > 0.0) != p)
            .count();
        assert!(wrong <= 8, "{wrong} of 400 wrong");
        // A JSON round trip keeps every decision.
        let back: Boosted = serde_json::from_str(&serde_json::to_string(&m).unwrap()).unwrap();
        assert_eq!(back.stumps.len(), m.stumps.len());
        for x in &xs {
            assert!((back.score(x) - m.score(x)).abs() < 1e-9);
        }
    }

    #[test]
    fn shrinkage_and_leaf_size_regularise() {
        // One positive outlier among negatives at x = 0.9 and a clean split at 0.5.
        let mut xs: Vec<Vec<f64>> = (0..40).map(|i| vec![i as f64 / 39.0]).collect();
        let mut ys: Vec<bool> = xs.iter().map(|x| x[0] < 0.5).collect();
        xs.push(vec![0.95]);
        ys.push(true);
        let plain = Boosted::train(&xs, &ys, 30).unwrap();
        let same = Boosted::train_with(&xs, &ys, &BoostConfig::rounds(30)).unwrap();
        assert_eq!(plain, same);
        // The plain learner isolates the outlier; with 5 samples per leaf it cannot.
        assert!(plain.score(&[0.95]) > 0.0);
        let cfg = BoostConfig {
            rounds: 30,
            shrinkage: 1.0,
            min_leaf: 5,
        };
        let leafy = Boosted::train_with(&xs, &ys, &cfg).unwrap();
        assert!(leafy.score(&[0.95]) < 0.0);
        assert!(leafy.score(&[0.1]) > 0.0 && leafy.score(&[0.8]) < 0.0);
        // Shrinkage scales the first stump's weight and keeps its split.
        let slow = Boosted::train_with(
            &xs,
            &ys,
            &BoostConfig {
                shrinkage: 0.1,
                ..BoostConfig::rounds(30)
            },
        )
        .unwrap();
        assert_eq!(slow.stumps[0].threshold, plain.stumps[0].threshold);
        assert!((slow.stumps[0].alpha - 0.1 * plain.stumps[0].alpha).abs() < 1e-12);
        assert_eq!(plain.truncated(3).stumps, plain.stumps[..3].to_vec());
        assert_eq!(plain.truncated(1000), plain);
        for bad in [0.0, 1.5, f64::NAN] {
            let c = BoostConfig {
                shrinkage: bad,
                ..BoostConfig::rounds(3)
            };
            assert!(Boosted::train_with(&xs, &ys, &c).is_err());
        }
        let c = BoostConfig {
            min_leaf: 0,
            ..BoostConfig::rounds(3)
        };
        assert!(Boosted::train_with(&xs, &ys, &c).is_err());
    }

    #[test]
    fn bad_training_input_is_refused() {
        let xs = vec![vec![0.0], vec![1.0]];
        assert!(Boosted::train(&xs, &[true, true], 5).is_err());
        assert!(Boosted::train(&xs, &[true], 5).is_err());
        assert!(Boosted::train(&[vec![0.0], vec![f64::NAN]], &[true, false], 5).is_err());
        assert!(Boosted::train(&[vec![0.0], vec![1.0, 2.0]], &[true, false], 5).is_err());
        assert_eq!(Boosted::default().score(&[1.0]), 0.0);
    }
}
