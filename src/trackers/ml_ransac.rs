//! Multilevel RANSAC association (ML-RANSAC, seed 000, Algorithm 2) over EKF tracks with a
//! constant-velocity model, fed range-bearing measurements from the robot's odometry pose.
//!
//! Per step, after the EKF prediction (line 2):
//!
//! 1. Individual compatibility (lines 3–4): the squared Mahalanobis distance d²(i, j) of every
//!    measurement j to every track i; the association matrix J(i, j) = \[d² < d₁\].
//! 2. First level (lines 5–6): a track with exactly one compatible measurement that is
//!    compatible with no other track is updated with it.
//! 3. RANSAC (line 7) on what is left: a hypothesis starts from one randomly drawn compatible
//!    (track, measurement) pair — the minimal sample, m = 1 — and is completed by letting the
//!    remaining tracks, in random order, take their nearest compatible unused measurement. Its
//!    consensus is the number of its pairs inside d₁, ties broken by the smaller summed d². The
//!    number of hypotheses starts at N and shrinks by eq. 16,
//!    n_hyp = log(1 − p) / log(1 − (1 − ε)^m) with ε = 1 − N_in / N_IC (N_in the best
//!    consensus, N_IC the compatible measurements), whenever a better hypothesis is stored. The
//!    best hypothesis gives the second-level EKF updates (line 7e).
//! 4. Third level (line 9): tracks still without a measurement take the nearest unused
//!    measurement inside the wider gate d₂ > d₁, greedily by d².
//! 5. Deletion (line 11): tracks unobserved for 3.5 s; tentative tracks that miss their M of N.
//! 6. New tracks (line 13): a measurement outside the gate d_n of every track starts a track
//!    at rest; it is reported once confirmed (the track threshold T_th = M detections).
//!
//! Seed 000 estimates the robot pose jointly with the objects, so one EKF update there moves
//! every predicted measurement and the consensus counts measurements a hypothesis explains.
//! Here the pose comes from odometry and tracks are independent, so updating one track does not
//! move another's prediction: the hypothesis' EKF updates (lines 7c iii–iv) would not change its
//! consensus and are skipped; only the winning hypothesis is applied. The static/dynamic
//! classification (line 12) is not needed: every measurement is a person candidate.
//!
//! Deterministic: the draws of step k come from [`crate::rng::stream`]`(seed, k)`.
//!
//! Not for: SLAM (the robot pose is an input).

use super::ekf::{position_error, update, Gaussian, Linearisation};
use super::gnn::{EkfTrack, GATE_99};
use super::lifecycle::{LabelMaker, Lifecycle, LifecycleConfig};
use super::{ensure_range_bearing, Innovation, PointTracker};
use crate::error::{Error, Result};
use crate::filter::StepContext;
use crate::filter::{Estimate, Measurements};
use crate::models::RangeBearing;
use crate::rng::stream;
use rand::seq::SliceRandom;
use rand::RngExt;

/// ML-RANSAC tuning (names as in seed 000, Algorithm 2).
#[derive(Clone, Debug, PartialEq)]
pub struct MlRansacConfig {
    /// The sensor: noise, mounting offset, bearing convention.
    pub sensor: RangeBearing,
    /// White acceleration noise of the CV model (m/s²). Default 1.
    pub sigma_accel: f64,
    /// Velocity standard deviation of a new track (m/s). Default 1.
    pub velocity_std: f64,
    /// First gate d₁ on d². Default χ²₂(0.99) = 9.21.
    pub d1: f64,
    /// Second gate d₂ > d₁ on d². Default 16.
    pub d2: f64,
    /// New-track gate d_n on d²: measurements farther than this from every track start one.
    /// Default 25.
    pub dn: f64,
    /// Initial (maximum) number of hypotheses N. Default 1000.
    pub max_hypotheses: usize,
    /// Probability p that one hypothesis is outlier-free. Default 0.99.
    pub confidence: f64,
    /// Confirmation (T_th = `confirm_hits`) and deletion after 3.5 s unobserved.
    pub lifecycle: LifecycleConfig,
    /// Seed of the hypothesis draws.
    pub seed: u64,
}

impl MlRansacConfig {
    /// Defaults for `sensor`, seed 0.
    pub fn new(sensor: RangeBearing) -> Self {
        MlRansacConfig {
            sensor,
            sigma_accel: 1.0,
            velocity_std: 1.0,
            d1: GATE_99,
            d2: 16.0,
            dn: 25.0,
            max_hypotheses: 1000,
            confidence: 0.99,
            lifecycle: LifecycleConfig::default(),
            seed: 0,
        }
    }

    fn validate(&self) -> Result<()> {
        crate::error::ensure_non_negative("ML-RANSAC sigma_accel", self.sigma_accel)?;
        crate::error::ensure_positive("ML-RANSAC velocity_std", self.velocity_std)?;
        crate::error::ensure_positive("ML-RANSAC d1", self.d1)?;
        if !(self.d2 >= self.d1 && self.dn >= self.d1 && self.d2.is_finite() && self.dn.is_finite())
        {
            return Err(Error::invalid(
                "ML-RANSAC gates",
                format!(
                    "d1 {}, d2 {}, dn {} (need d1 ≤ d2 and d1 ≤ dn, finite)",
                    self.d1, self.d2, self.dn
                ),
            ));
        }
        if self.max_hypotheses == 0 || !(self.confidence > 0.0 && self.confidence < 1.0) {
            return Err(Error::invalid(
                "ML-RANSAC hypotheses",
                format!(
                    "N = {}, p = {} (need N ≥ 1, 0 < p < 1)",
                    self.max_hypotheses, self.confidence
                ),
            ));
        }
        self.lifecycle.validate()
    }
}

/// Counters of the last step, for tests and diagnostics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MlRansacStats {
    /// Tracks updated at the first level.
    pub first_level: usize,
    /// Tracks updated from the RANSAC hypothesis.
    pub second_level: usize,
    /// Tracks updated through the wider gate d₂.
    pub third_level: usize,
    /// Hypotheses drawn.
    pub hypotheses: usize,
}

/// The ML-RANSAC tracker.
#[derive(Clone, Debug)]
pub struct MlRansacTracker {
    config: MlRansacConfig,
    tracks: Vec<EkfTrack>,
    labels: LabelMaker,
    innovations: Vec<Innovation>,
    stats: MlRansacStats,
}

/// One hypothesis: (track, measurement) pairs, its consensus and summed d².
#[derive(Clone, Debug, Default)]
struct Hypothesis {
    pairs: Vec<(usize, usize)>,
    consensus: usize,
    cost: f64,
}

impl Hypothesis {
    fn beats(&self, other: &Hypothesis) -> bool {
        self.consensus > other.consensus
            || (self.consensus == other.consensus && self.cost < other.cost)
    }
}

/// Eq. 16: hypotheses needed so that one is outlier-free with probability `p`, for inlier
/// ratio `inliers` and minimal sample size `m`.
pub fn hypotheses_needed(p: f64, inliers: f64, m: i32) -> f64 {
    let good = inliers.clamp(0.0, 1.0).powi(m);
    if good >= 1.0 {
        1.0
    } else if good <= 0.0 {
        f64::INFINITY
    } else {
        ((1.0 - p).ln() / (1.0 - good).ln()).ceil().max(1.0)
    }
}

impl MlRansacTracker {
    /// A tracker with no tracks.
    pub fn new(config: MlRansacConfig) -> Result<Self> {
        config.validate()?;
        Ok(MlRansacTracker {
            config,
            tracks: Vec::new(),
            labels: LabelMaker::default(),
            innovations: Vec::new(),
            stats: MlRansacStats::default(),
        })
    }

    /// Counters of the last step.
    pub fn stats(&self) -> MlRansacStats {
        self.stats
    }

    /// Line 7: the best of the random hypotheses over the compatible pairs of `tracks` and
    /// `free` measurements.
    fn ransac(
        &self,
        d2: &[Vec<f64>],
        tracks: &[usize],
        free: &[bool],
        step: u32,
    ) -> (Hypothesis, usize) {
        let cfg = &self.config;
        let pairs: Vec<(usize, usize)> = tracks
            .iter()
            .flat_map(|&i| {
                d2[i]
                    .iter()
                    .enumerate()
                    .filter(move |&(j, &d)| free[j] && d < cfg.d1)
                    .map(move |(j, _)| (i, j))
            })
            .collect();
        let mut compatible: Vec<usize> = pairs.iter().map(|p| p.1).collect();
        compatible.sort_unstable();
        compatible.dedup();
        let n_ic = compatible.len().max(1) as f64;
        let mut rng = stream(cfg.seed, step as u64);
        let mut best = Hypothesis::default();
        let mut n_hyp = cfg.max_hypotheses as f64;
        let mut drawn = 0;
        let mut order = tracks.to_vec();
        let mut taken = free.to_vec();
        while (drawn as f64) < n_hyp && !pairs.is_empty() {
            drawn += 1;
            let (i0, j0) = pairs[rng.random_range(0..pairs.len())];
            let mut h = Hypothesis {
                pairs: vec![(i0, j0)],
                consensus: 1,
                cost: d2[i0][j0],
            };
            taken.copy_from_slice(free);
            taken[j0] = false;
            order.shuffle(&mut rng);
            for &i in order.iter().filter(|&&i| i != i0) {
                let nearest = d2[i]
                    .iter()
                    .enumerate()
                    .filter(|&(j, &d)| taken[j] && d < cfg.d1)
                    .min_by(|a, b| a.1.total_cmp(b.1));
                if let Some((j, &d)) = nearest {
                    taken[j] = false;
                    h.pairs.push((i, j));
                    h.consensus += 1;
                    h.cost += d;
                }
            }
            if h.beats(&best) {
                let inliers = h.consensus as f64 / n_ic;
                best = h;
                n_hyp = n_hyp.min(hypotheses_needed(cfg.confidence, inliers, 1));
            }
        }
        (best, drawn)
    }
}

impl PointTracker for MlRansacTracker {
    fn name(&self) -> &str {
        "ml_ransac"
    }

    fn step(&mut self, z: &Measurements, ctx: &StepContext) -> Result<Vec<Estimate>> {
        ensure_range_bearing(z)?;
        self.innovations.clear();
        self.stats = MlRansacStats::default();
        self.labels.start_step(ctx.step);
        let (sigma_accel, sensor) = (self.config.sigma_accel, self.config.sensor);
        // Line 2: prediction.
        for t in &mut self.tracks {
            t.density.predict_cv(ctx.dt, sigma_accel);
        }
        let lins: Vec<_> = self
            .tracks
            .iter()
            .map(|t| Linearisation::new(&t.density, &sensor, ctx))
            .collect();
        let (n, m) = (self.tracks.len(), z.len());
        // Lines 3–4: individual compatibility and the association matrix J = [d² < d₁].
        let d2: Vec<Vec<f64>> = lins
            .iter()
            .map(|lin| match lin {
                Some(lin) => z
                    .iter()
                    .map(|zj| lin.mahalanobis2(&lin.innovation(zj)))
                    .collect(),
                None => vec![f64::INFINITY; m],
            })
            .collect();
        let d1 = self.config.d1;
        let row_count = |i: usize| d2[i].iter().filter(|&&d| d < d1).count();
        let col_count = |j: usize| (0..n).filter(|&i| d2[i][j] < d1).count();
        let mut chosen: Vec<Option<usize>> = vec![None; n];
        let mut free = vec![true; m];
        // Lines 5–6: first level, unambiguous pairs.
        for (i, c) in chosen.iter_mut().enumerate() {
            if row_count(i) == 1 {
                let j = d2[i].iter().position(|&d| d < d1).expect("one compatible");
                if col_count(j) == 1 {
                    *c = Some(j);
                    free[j] = false;
                    self.stats.first_level += 1;
                }
            }
        }
        // Line 7: RANSAC over the ambiguous rest.
        let ambiguous: Vec<usize> = (0..n)
            .filter(|&i| chosen[i].is_none() && (0..m).any(|j| free[j] && d2[i][j] < d1))
            .collect();
        if !ambiguous.is_empty() {
            let (best, drawn) = self.ransac(&d2, &ambiguous, &free, ctx.step);
            self.stats.hypotheses = drawn;
            for (i, j) in best.pairs {
                chosen[i] = Some(j);
                free[j] = false;
                self.stats.second_level += 1;
            }
        }
        // Line 9: third level through the wider gate d₂, greedily by distance.
        let mut wide: Vec<(f64, usize, usize)> = (0..n)
            .filter(|&i| chosen[i].is_none())
            .flat_map(|i| (0..m).map(move |j| (i, j)))
            .filter(|&(i, j)| free[j] && d2[i][j] < self.config.d2)
            .map(|(i, j)| (d2[i][j], i, j))
            .collect();
        wide.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, i, j) in wide {
            if chosen[i].is_none() && free[j] {
                chosen[i] = Some(j);
                free[j] = false;
                self.stats.third_level += 1;
            }
        }
        // EKF updates of all levels.
        for (i, track) in self.tracks.iter_mut().enumerate() {
            if let (Some(j), Some(lin)) = (chosen[i], &lins[i]) {
                let zj = z.get(j);
                let nu = lin.innovation(zj);
                self.innovations.push(Innovation {
                    label: track.label,
                    position_error: position_error(&track.density, zj, &sensor, ctx),
                    nis: d2[i][j],
                });
                update(&mut track.density, lin, &nu, &sensor);
            }
            track
                .life
                .record(chosen[i].is_some(), ctx.time, &self.config.lifecycle);
        }
        // Line 11: deletion.
        let lifecycle = self.config.lifecycle;
        let keep: Vec<bool> = self
            .tracks
            .iter()
            .map(|t| !t.life.is_dead(ctx.time, &lifecycle))
            .collect();
        // Line 13: new tracks outside d_n of every (pre-deletion) track.
        for (j, zj) in z.iter().enumerate() {
            if free[j] && (0..n).all(|i| d2[i][j] > self.config.dn) {
                self.tracks.push(EkfTrack {
                    label: self.labels.next_label(),
                    density: Gaussian::from_measurement(
                        [zj[0], zj[1]],
                        &sensor,
                        ctx,
                        self.config.velocity_std,
                    ),
                    life: Lifecycle::born(ctx.time),
                    born_step: ctx.step,
                });
            }
        }
        let mut k = 0;
        self.tracks.retain(|_| {
            k += 1;
            keep.get(k - 1).copied().unwrap_or(true)
        });
        Ok(self
            .tracks
            .iter()
            .filter(|t| t.life.confirmed())
            .map(|t| t.estimate(ctx.step))
            .collect())
    }

    fn innovations(&self) -> &[Innovation] {
        &self.innovations
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trackers::gnn::tests::{
        check_crossing, check_deletion, check_single_target, run, sensor,
    };

    fn tracker(seed: u64) -> MlRansacTracker {
        let mut c = MlRansacConfig::new(sensor());
        c.seed = seed;
        MlRansacTracker::new(c).unwrap()
    }

    #[test]
    fn eq_16_hand_values() {
        // p = 0.99, half inliers, m = 1: ln 0.01 / ln 0.5 = 6.64 → 7
        assert_eq!(hypotheses_needed(0.99, 0.5, 1), 7.0);
        // m = 2: ln 0.01 / ln 0.75 = 16.01 → 17
        assert_eq!(hypotheses_needed(0.99, 0.5, 2), 17.0);
        assert_eq!(hypotheses_needed(0.99, 1.0, 1), 1.0);
        assert!(hypotheses_needed(0.99, 0.0, 1).is_infinite());
    }

    #[test]
    fn single_target_one_label_small_error() {
        check_single_target(&mut tracker(1));
    }

    #[test]
    fn crossing_targets_keep_labels() {
        check_crossing(&mut tracker(1));
    }

    #[test]
    fn deleted_after_3_5_s_unobserved() {
        check_deletion(&mut tracker(1));
    }

    /// Three people walking side by side 0.7 m apart make every association ambiguous.
    fn abreast(t: f64) -> Vec<[f64; 2]> {
        (0..3)
            .map(|i| [7.0 + 0.8 * t, -0.7 + 0.7 * i as f64 + 0.1 * t])
            .collect()
    }

    #[test]
    fn ambiguous_groups_go_through_ransac_and_stay_tracked() {
        let mut t = tracker(3);
        let est = run(&mut t, 40, abreast, |_| true);
        assert_eq!(est[39].len(), 3, "{:?}", est[39]);
        let labels: std::collections::BTreeSet<_> =
            est[10..].iter().flatten().map(|e| e.label).collect();
        assert_eq!(labels.len(), 3);
    }

    #[test]
    fn same_seed_same_output() {
        let a = run(&mut tracker(9), 40, abreast, |_| true);
        let b = run(&mut tracker(9), 40, abreast, |_| true);
        assert_eq!(a, b);
    }
}
