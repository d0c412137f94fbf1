//! Weighted particle sets — the single-object densities of the filter.
//!
//! States are stored as a structure of arrays: component `c` of all particles is one
//! contiguous slice (`component(c)`), so transition and likelihood loops stream through memory
//! and vectorise. Weights are kept normalised in the linear domain. Likelihoods reweight
//! through the log domain ([`ParticleSet::reweight_log`]) so that those that underflow never
//! empty a set; factors already in [0, 1] such as p_S and p_D reweight linearly
//! ([`ParticleSet::reweight`]), which leaves the weights unchanged when the weighted sum is 0
//! or not finite. Resampling is systematic, followed by optional roughening or a
//! regularised Gaussian kernel ([`Jitter`]). A set can also carry its particles' ancestral
//! states over the last few steps ([`ParticleSet::keep_history`]): resampling copies a
//! particle's past along with it, so the weighted particles of step k with their pasts
//! approximate the joint posterior of the last steps' states given every measurement up to k
//! (the genealogy, or path-space, fixed-lag smoother: Kitagawa 1996; Doucet & Johansen 2011,
//! Sec. 4.4). Not for: the association or existence logic.

mod history;

use crate::error::{ensure_finite, Error, Result};
use crate::rng::FilterRng;
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};

/// Components summed in one pass by the weighted means and spreads (the drive tracker's
/// states have seven).
const FUSED: usize = 8;

/// A weighted particle set of fixed state dimension.
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleSet {
    dim: usize,
    len: usize,
    /// Component-major: `states[c * len + i]` is component `c` of particle `i`.
    states: Vec<f64>,
    /// Normalised weights (sum 1).
    weights: Vec<f64>,
    /// Ancestral states in a ring of `history_lag` slots, slot-major:
    /// `history[(s * dim + c) * len + i]` is component `c` of the state particle `i`'s
    /// ancestor had `k` steps back, where `s = (history_head + k − 1) mod history_lag`.
    /// Empty unless kept.
    history: Vec<f64>,
    /// Steps of history kept (the lag); 0 keeps none.
    history_lag: usize,
    /// Slots filled so far (at most `history_lag`).
    history_depth: usize,
    /// The slot holding the states one step back.
    history_head: usize,
    /// What kind of object the set describes, when a user marks it ([`ParticleSet::tag`]).
    tag: Option<u32>,
}

/// What is added to resampled particles to restore diversity.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Jitter {
    /// Nothing: duplicates stay duplicates (the transition noise spreads them).
    None,
    /// Gordon's roughening: component `c` gets N(0, (k·E_c·N^(−1/d))²), where E_c is the
    /// spread (max − min) of that component after resampling.
    Roughening {
        /// Tuning constant `k` (typically 0.01 … 0.2).
        k: f64,
    },
    /// Regularised particle filter with a diagonal Gaussian kernel: component `c` gets
    /// N(0, (scale·h_opt·σ_c)²) with h_opt = (4 / (N (d + 2)))^(1/(d + 4)) and σ_c the weighted
    /// standard deviation before resampling.
    Regularised {
        /// Multiplier of the optimal bandwidth (1 = optimal for a Gaussian).
        scale: f64,
    },
}

impl Default for Jitter {
    fn default() -> Self {
        Jitter::Regularised { scale: 0.2 }
    }
}

impl ParticleSet {
    /// `len` particles of dimension `dim`, all at the origin, equally weighted. Fails on a
    /// dimension of 0 or a set larger than memory can hold.
    pub fn zeros(dim: usize, len: usize) -> Result<Self> {
        if dim == 0 {
            return Err(Error::invalid(
                "particle set",
                "dimension 0 (must be positive)",
            ));
        }
        if dim
            .checked_mul(len)
            .is_none_or(|n| n > isize::MAX as usize / 8)
        {
            return Err(Error::invalid(
                "particle set",
                format!("{len} particles of {dim} components do not fit in memory"),
            ));
        }
        Ok(Self::zeroed(dim, len))
    }

    /// `len` equally weighted particles drawn from N(mean, diag(std²)). Fails when `mean` and
    /// `std` differ in length or are empty, or a value is not finite or a deviation negative,
    /// naming the component.
    pub fn gaussian(mean: &[f64], std: &[f64], len: usize, rng: &mut FilterRng) -> Result<Self> {
        if mean.len() != std.len() {
            return Err(Error::invalid(
                "Gaussian particle set",
                format!(
                    "a mean of {} components and a std of {}",
                    mean.len(),
                    std.len()
                ),
            ));
        }
        ensure_finite("mean of a Gaussian particle set", mean)?;
        ensure_finite("std of a Gaussian particle set", std)?;
        if let Some(c) = std.iter().position(|s| *s < 0.0) {
            return Err(Error::invalid(
                "std of a Gaussian particle set",
                format!("component {c} is {} (must be non-negative)", std[c]),
            ));
        }
        Self::zeros(mean.len(), len)?;
        Ok(Self::sampled(mean, std, len, rng))
    }

    /// [`ParticleSet::zeros`] for a dimension the caller has checked.
    pub(crate) fn zeroed(dim: usize, len: usize) -> Self {
        debug_assert!(dim > 0, "particle dimension must be positive");
        let w = if len > 0 { 1.0 / len as f64 } else { 0.0 };
        ParticleSet {
            dim,
            len,
            states: vec![0.0; dim * len],
            weights: vec![w; len],
            history: Vec::new(),
            history_lag: 0,
            history_depth: 0,
            history_head: 0,
            tag: None,
        }
    }

    /// [`ParticleSet::gaussian`] for a mean and deviations the caller has checked.
    pub(crate) fn sampled(mean: &[f64], std: &[f64], len: usize, rng: &mut FilterRng) -> Self {
        debug_assert_eq!(mean.len(), std.len());
        let mut set = Self::zeroed(mean.len(), len);
        for (c, (&m, &s)) in mean.iter().zip(std).enumerate() {
            for v in set.component_mut(c) {
                let e: f64 = StandardNormal.sample(rng);
                *v = m + s * e;
            }
        }
        set
    }

    /// Builds a set from particle-major rows (`rows[i]` is particle `i`) and weights, which
    /// are normalised here. Returns `None` if shapes disagree or no weight is positive.
    pub fn from_rows(rows: &[Vec<f64>], weights: &[f64]) -> Option<Self> {
        let len = rows.len();
        let dim = rows.first()?.len();
        if dim == 0 || weights.len() != len || rows.iter().any(|r| r.len() != dim) {
            return None;
        }
        let mut set = Self::zeroed(dim, len);
        for (i, row) in rows.iter().enumerate() {
            for (c, &v) in row.iter().enumerate() {
                set.states[c * len + i] = v;
            }
        }
        let total: f64 = weights.iter().sum();
        if !(total > 0.0 && total.is_finite()) || weights.iter().any(|w| *w < 0.0) {
            return None;
        }
        for (dst, &w) in set.weights.iter_mut().zip(weights) {
            *dst = w / total;
        }
        Some(set)
    }

    /// State dimension.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// What kind of object the set describes, when its maker marked it: a typed tag beside
    /// the states (the drive tracker marks walls and clusters so), never a state component.
    /// Every operation that keeps particles keeps it (prediction, reweighting, resampling,
    /// merging, a clone); a set resampled to nothing is left empty and untagged. The filter
    /// itself never reads it, except that sets of different tags are never merged as
    /// duplicates ([`crate::filter::MergeDistance::tagged_distance2`]).
    pub fn tag(&self) -> Option<u32> {
        self.tag
    }

    /// The same set marked with `tag` ([`ParticleSet::tag`]).
    pub fn with_tag(mut self, tag: u32) -> Self {
        self.tag = Some(tag);
        self
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when the set holds no particle.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Component `c` of every particle.
    pub fn component(&self, c: usize) -> &[f64] {
        &self.states[c * self.len..(c + 1) * self.len]
    }

    /// Component `c` of every particle, mutable.
    pub fn component_mut(&mut self, c: usize) -> &mut [f64] {
        let len = self.len;
        &mut self.states[c * len..(c + 1) * len]
    }

    /// All components as mutable slices, in order (for transitions that couple components).
    pub fn components_mut(&mut self) -> Vec<&mut [f64]> {
        if self.len == 0 {
            return (0..self.dim).map(|_| &mut [][..]).collect();
        }
        self.states.chunks_mut(self.len).collect()
    }

    /// All components as slices, in order.
    pub fn components(&self) -> Vec<&[f64]> {
        if self.len == 0 {
            return (0..self.dim).map(|_| &[][..]).collect();
        }
        self.states.chunks(self.len).collect()
    }

    /// Copies particle `i` into `out` (length `dim`).
    pub fn state_into(&self, i: usize, out: &mut [f64]) {
        for (c, o) in out.iter_mut().enumerate().take(self.dim) {
            *o = self.states[c * self.len + i];
        }
    }

    /// Particle `i` as a new vector.
    pub fn state(&self, i: usize) -> Vec<f64> {
        let mut v = vec![0.0; self.dim];
        self.state_into(i, &mut v);
        v
    }

    /// Normalised weights.
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// Multiplies weight `i` by `exp(log_factor[i])` and renormalises, in the log domain.
    ///
    /// Returns the log of Σᵢ wᵢ·exp(log_factor\[i\]) (the normalising constant, possibly far below
    /// `f64::MIN_POSITIVE` without underflowing). If every factor is −∞ (or NaN) the weights
    /// are left unchanged and −∞ is returned: the set is never emptied.
    pub fn reweight_log(&mut self, log_factor: &[f64]) -> f64 {
        debug_assert_eq!(log_factor.len(), self.len);
        let mut max = f64::NEG_INFINITY;
        for (w, l) in self.weights.iter().zip(log_factor) {
            if *w > 0.0 && *l > max {
                max = *l;
            }
        }
        if !max.is_finite() {
            return if max == f64::INFINITY {
                f64::INFINITY
            } else {
                f64::NEG_INFINITY
            };
        }
        let mut total = 0.0;
        for (w, l) in self.weights.iter_mut().zip(log_factor) {
            let f = if l.is_nan() { 0.0 } else { (l - max).exp() };
            *w *= f;
            total += *w;
        }
        // total ≥ the weight of the maximising particle (> 0), so this division is safe.
        let inv = 1.0 / total;
        for w in &mut self.weights {
            *w *= inv;
        }
        max + total.ln()
    }

    /// Multiplies weight `i` by `factor[i]` (finite, ≥ 0) and renormalises; returns
    /// Σᵢ wᵢ·factor\[i\]. When that sum is zero or not finite the weights are left unchanged.
    pub fn reweight(&mut self, factor: &[f64]) -> f64 {
        debug_assert_eq!(factor.len(), self.len);
        let total: f64 = self.weights.iter().zip(factor).map(|(w, f)| w * f).sum();
        if !(total > 0.0 && total.is_finite()) {
            return total;
        }
        let inv = 1.0 / total;
        for (w, f) in self.weights.iter_mut().zip(factor) {
            *w *= f * inv;
        }
        total
    }

    /// Weighted mean of every component into `out`.
    pub fn mean_into(&self, out: &mut [f64]) {
        let dims = self.dim.min(out.len());
        for (c, o) in (0..dims).step_by(FUSED).zip(out.chunks_mut(FUSED)) {
            let k = (dims - c).min(FUSED);
            self.fused_sums(c, k, &mut o[..k], |x, w, _| x * w, &[0.0; FUSED]);
        }
    }

    /// Σᵢ term(xᵢ, wᵢ, shift[j]) of the `k` ≤ [`FUSED`] components `first..first + k` into
    /// `out`: one pass over the particles with one running sum per component, each added in
    /// particle order from −0.0 as `Iterator::sum` does, so the numbers equal separate sums
    /// while the additions of different components overlap (each sum is a chain of dependent
    /// additions; several chains keep the adder busy where one would wait on each result).
    /// Four lanes for up to four components, eight above: a lane that repeats a component is
    /// work thrown away.
    #[inline(always)]
    fn fused_sums(
        &self,
        first: usize,
        k: usize,
        out: &mut [f64],
        term: impl Fn(f64, f64, f64) -> f64,
        shift: &[f64; FUSED],
    ) {
        if k <= 4 {
            self.fused_lanes::<4>(first, k, out, term, shift)
        } else {
            self.fused_lanes::<FUSED>(first, k, out, term, shift)
        }
    }

    /// [`ParticleSet::fused_sums`] on `L` ≥ `k` lanes, the lanes past `k` repeating the last
    /// component.
    #[inline(always)]
    fn fused_lanes<const L: usize>(
        &self,
        first: usize,
        k: usize,
        out: &mut [f64],
        term: impl Fn(f64, f64, f64) -> f64,
        shift: &[f64; FUSED],
    ) {
        let n = self.len;
        let w = &self.weights[..n];
        let cols: [&[f64]; L] = std::array::from_fn(|j| &self.component(first + j.min(k - 1))[..n]);
        let mut s = [-0.0f64; L];
        for i in 0..n {
            let wi = w[i];
            for j in 0..L {
                s[j] += term(cols[j][i], wi, shift[j]);
            }
        }
        out[..k].copy_from_slice(&s[..k]);
    }

    /// Weighted mean as a new vector.
    pub fn mean(&self) -> Vec<f64> {
        let mut m = vec![0.0; self.dim];
        self.mean_into(&mut m);
        m
    }

    /// Weighted standard deviation of every component.
    pub fn std_dev(&self) -> Vec<f64> {
        self.mean_and_std_dev().1
    }

    /// Weighted mean and standard deviation of every component, the mean computed once.
    pub fn mean_and_std_dev(&self) -> (Vec<f64>, Vec<f64>) {
        let mean = self.mean();
        let mut std = vec![0.0; self.dim];
        for (c, o) in (0..self.dim).step_by(FUSED).zip(std.chunks_mut(FUSED)) {
            let k = (self.dim - c).min(FUSED);
            let mut shift = [0.0; FUSED];
            shift[..k].copy_from_slice(&mean[c..c + k]);
            self.fused_sums(c, k, o, |x, w, m| w * (x - m) * (x - m), &shift);
        }
        std.iter_mut().for_each(|v| *v = v.max(0.0).sqrt());
        (mean, std)
    }

    /// Weighted covariance matrix (dim × dim).
    pub fn covariance(&self) -> nalgebra::DMatrix<f64> {
        let mean = self.mean();
        let mut cov = nalgebra::DMatrix::zeros(self.dim, self.dim);
        for a in 0..self.dim {
            for b in a..self.dim {
                let (xa, xb) = (self.component(a), self.component(b));
                let s: f64 = (0..self.len)
                    .map(|i| self.weights[i] * (xa[i] - mean[a]) * (xb[i] - mean[b]))
                    .sum();
                cov[(a, b)] = s;
                cov[(b, a)] = s;
            }
        }
        cov
    }

    /// Joins `other`'s particles to these as one mixture: this set's weights times
    /// (1 − `share`), `other`'s times `share` (`share` in [0, 1]). Histories are joined
    /// particle by particle. Returns false, changing nothing, when the dimensions differ, the
    /// two keep histories of different lag, depth or position, or `share` is outside [0, 1].
    pub fn mix(&mut self, other: &ParticleSet, share: f64) -> bool {
        let same_history = (self.history_lag, self.history_depth, self.history_head)
            == (other.history_lag, other.history_depth, other.history_head);
        if other.dim != self.dim || !same_history || !(0.0..=1.0).contains(&share) {
            return false;
        }
        if other.len == 0 {
            return true;
        }
        let len = self.len + other.len;
        let mut states = Vec::with_capacity(self.dim * len);
        for c in 0..self.dim {
            states.extend_from_slice(self.component(c));
            states.extend_from_slice(other.component(c));
        }
        if self.history_lag > 0 {
            let mut history = Vec::with_capacity(self.history.len() + other.history.len());
            let rows = self.history_lag * self.dim;
            for r in 0..rows {
                history.extend_from_slice(&self.history[r * self.len..(r + 1) * self.len]);
                history.extend_from_slice(&other.history[r * other.len..(r + 1) * other.len]);
            }
            self.history = history;
        }
        let keep = if self.len == 0 { 0.0 } else { 1.0 - share };
        let share = if self.len == 0 { 1.0 } else { share };
        let mut weights = Vec::with_capacity(len);
        weights.extend(self.weights.iter().map(|w| w * keep));
        weights.extend(other.weights.iter().map(|w| w * share));
        let total: f64 = weights.iter().sum();
        weights.iter_mut().for_each(|w| *w /= total);
        self.states = states;
        self.weights = weights;
        self.len = len;
        true
    }

    /// Effective sample size 1 / Σ wᵢ².
    pub fn effective_sample_size(&self) -> f64 {
        let s: f64 = self.weights.iter().map(|w| w * w).sum();
        if s > 0.0 {
            1.0 / s
        } else {
            0.0
        }
    }

    /// Systematic resampling to `n` equally weighted particles.
    pub fn resample_systematic(&mut self, n: usize, rng: &mut FilterRng) {
        if self.len == 0 || n == 0 {
            *self = Self::zeroed(self.dim, 0);
            return;
        }
        let step = 1.0 / n as f64;
        let u0: f64 = rng.random::<f64>() * step;
        // The running sums first (the same additions in the same order), so that the walk
        // below carries only its position from one step to the next.
        let cum: Vec<f64> = self
            .weights
            .iter()
            .scan(0.0, |acc, &w| {
                *acc += w;
                Some(*acc)
            })
            .collect();
        let mut idx = vec![0usize; n];
        let mut i = 0;
        let last = self.len - 1;
        for (k, slot) in idx.iter_mut().enumerate() {
            let u = u0 + k as f64 * step;
            while i < last && u > cum[i] {
                i += 1;
            }
            *slot = i;
        }
        let mut states = Vec::with_capacity(self.dim * n);
        for c in 0..self.dim {
            let src = self.component(c);
            states.extend(idx.iter().map(|&j| src[j]));
        }
        if self.history_lag > 0 {
            // Each new particle takes its ancestor's past along.
            let mut history = Vec::with_capacity(self.history.len() / self.len.max(1) * n);
            for row in self.history.chunks(self.len) {
                history.extend(idx.iter().map(|&j| row[j]));
            }
            self.history = history;
        }
        self.states = states;
        self.len = n;
        self.weights = vec![step; n];
    }

    /// Resamples to `n` particles and applies `jitter`.
    #[allow(clippy::needless_range_loop)] // `c` selects a component and its spread alike
    pub fn resample(&mut self, n: usize, jitter: Jitter, rng: &mut FilterRng) {
        let sigma_before = match jitter {
            Jitter::Regularised { .. } => self.std_dev(),
            _ => Vec::new(),
        };
        self.resample_systematic(n, rng);
        if self.len == 0 {
            return;
        }
        let d = self.dim as f64;
        let nf = self.len as f64;
        for c in 0..self.dim {
            let sigma = match jitter {
                Jitter::None => 0.0,
                Jitter::Roughening { k } => {
                    let comp = self.component(c);
                    let (lo, hi) = comp
                        .iter()
                        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                            (lo.min(x), hi.max(x))
                        });
                    k * (hi - lo) * nf.powf(-1.0 / d)
                }
                Jitter::Regularised { scale } => {
                    let h = (4.0 / (nf * (d + 2.0))).powf(1.0 / (d + 4.0));
                    scale * h * sigma_before[c]
                }
            };
            if sigma > 0.0 && sigma.is_finite() {
                for v in self.component_mut(c) {
                    let e: f64 = StandardNormal.sample(rng);
                    *v += sigma * e;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;
    use proptest::prelude::*;

    #[test]
    fn reweight_with_no_usable_total_leaves_the_weights() {
        let mut rng = seeded(2);
        let mut p = ParticleSet::sampled(&[0.0], &[1.0], 4, &mut rng);
        p.reweight(&[1.0, 2.0, 3.0, 4.0]);
        let before = p.weights().to_vec();
        assert_eq!(p.reweight(&[0.0; 4]), 0.0);
        assert_eq!(p.weights(), &before[..]);
        assert!(p.reweight(&[1.0, f64::NAN, 1.0, 1.0]).is_nan());
        assert_eq!(p.weights(), &before[..]);
        assert_eq!(p.reweight(&[1.0, f64::INFINITY, 1.0, 1.0]), f64::INFINITY);
        assert_eq!(p.weights(), &before[..]);
        // A usable total renormalises: weights ∝ w·f.
        let total = p.reweight(&[0.0, 0.0, 1.0, 1.0]);
        assert!((total - (before[2] + before[3])).abs() < 1e-15);
        assert!((p.weights()[2] - before[2] / total).abs() < 1e-15);
        assert_eq!(p.weights()[0], 0.0);
    }

    #[test]
    fn reweight_survives_total_underflow() {
        let mut rng = seeded(1);
        let mut p = ParticleSet::sampled(&[0.0, 0.0], &[1.0, 1.0], 100, &mut rng);
        let logs: Vec<f64> = (0..100).map(|i| -5000.0 - i as f64).collect();
        let lz = p.reweight_log(&logs);
        assert!(lz.is_finite());
        assert!((lz - (-5000.0 + (p.len() as f64).recip().ln())).abs() < 1.0);
        let s: f64 = p.weights().iter().sum();
        assert!((s - 1.0).abs() < 1e-12);
        assert!(p.weights()[0] > p.weights()[1]);
        // every factor −∞: weights unchanged, never emptied
        let before = p.weights().to_vec();
        assert_eq!(
            p.reweight_log(&vec![f64::NEG_INFINITY; 100]),
            f64::NEG_INFINITY
        );
        assert_eq!(p.weights(), &before[..]);
    }

    #[test]
    fn mean_and_covariance_match_hand_computation() {
        let rows = vec![vec![0.0, 1.0], vec![2.0, 3.0], vec![4.0, -1.0]];
        let p = ParticleSet::from_rows(&rows, &[1.0, 2.0, 1.0]).unwrap();
        // mean x = (0 + 4 + 4)/4 = 2, y = (1 + 6 - 1)/4 = 1.5
        assert_eq!(p.mean(), vec![2.0, 1.5]);
        let c = p.covariance();
        // var x = (4 + 0 + 4)/4 = 2; cov = (−2·−0.5 + 0 + 2·−2.5)/4 = −1
        assert!((c[(0, 0)] - 2.0).abs() < 1e-12);
        assert!((c[(0, 1)] + 1.0).abs() < 1e-12);
        assert!((p.std_dev()[0] - 2f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn systematic_resampling_copies_in_proportion() {
        let rows = vec![vec![0.0], vec![1.0], vec![2.0], vec![3.0]];
        let mut p = ParticleSet::from_rows(&rows, &[0.5, 0.25, 0.25, 0.0]).unwrap();
        p.resample_systematic(8, &mut seeded(3));
        let comp = p.component(0);
        assert_eq!(comp.iter().filter(|&&x| x == 0.0).count(), 4);
        assert_eq!(comp.iter().filter(|&&x| x == 1.0).count(), 2);
        assert_eq!(comp.iter().filter(|&&x| x == 2.0).count(), 2);
        assert_eq!(comp.iter().filter(|&&x| x == 3.0).count(), 0);
        assert!((p.effective_sample_size() - 8.0).abs() < 1e-9);
    }

    proptest! {
        /// The fused passes give bit for bit the component-by-component sums.
        #[test]
        fn fused_mean_and_spread_equal_separate_sums(
            dim in 1usize..20,
            values in proptest::collection::vec(-1e3f64..1e3, 0..600),
            seed in 0u64..1000,
        ) {
            let len = values.len() / dim;
            let rows: Vec<Vec<f64>> =
                (0..len).map(|i| values[i * dim..(i + 1) * dim].to_vec()).collect();
            let mut rng = crate::rng::seeded(seed);
            let weights: Vec<f64> = (0..len).map(|_| rng.random::<f64>() + 1e-3).collect();
            let Some(set) = ParticleSet::from_rows(&rows, &weights) else {
                return Ok(());
            };
            let (mean, std) = set.mean_and_std_dev();
            for c in 0..dim {
                let w = set.weights();
                let m: f64 = set.component(c).iter().zip(w).map(|(x, w)| x * w).sum();
                let var: f64 = set
                    .component(c)
                    .iter()
                    .zip(w)
                    .map(|(x, w)| w * (x - m) * (x - m))
                    .sum();
                prop_assert_eq!(mean[c].to_bits(), m.to_bits());
                prop_assert_eq!(std[c].to_bits(), var.max(0.0).sqrt().to_bits());
            }
        }

        #[test]
        fn weights_stay_normalised(logs in proptest::collection::vec(-1e4f64..1e4, 1..64), n in 1usize..200, seed in 0u64..1000) {
            let mut rng = seeded(seed);
            let mut p = ParticleSet::sampled(&[1.0, -2.0, 0.5], &[1.0, 2.0, 0.1], logs.len(), &mut rng);
            p.reweight_log(&logs);
            let s: f64 = p.weights().iter().sum();
            prop_assert!((s - 1.0).abs() < 1e-9);
            prop_assert!(p.weights().iter().all(|w| *w >= 0.0));
            p.resample(n, Jitter::Regularised { scale: 1.0 }, &mut rng);
            prop_assert_eq!(p.len(), n);
            let s: f64 = p.weights().iter().sum();
            prop_assert!((s - 1.0).abs() < 1e-9);
            prop_assert!(p.component(1).iter().all(|x| x.is_finite()));
        }
    }
}
