//! On-line Fuzzy ART (Carpenter, Grossberg & Rosen 1991) as seed 003 uses it (Sec. IV,
//! Sec. VI): an unsupervised classifier that puts each input vector into a learned category
//! or opens a new one, learning as it goes.
//!
//! Not for: computing or normalising the inputs (see the features module) or deciding what a
//! category means (the moving-object detector's voting does that).
//!
//! # The algorithm
//!
//! An input `a ∈ [0, 1]^M` is complement coded as `I = (a, 1 − a)`, so `|I| = M` for every
//! input (`|·|` the L1 norm, `∧` the component-wise minimum). Each category `j` has a weight
//! vector `w_j ∈ [0, 1]^{2M}`. Categories are tried in decreasing order of the choice value
//! `T_j = |I ∧ w_j| / (α + |w_j|)` (ties: lower index first); the first whose match
//! `|I ∧ w_j| / |I|` reaches the vigilance `ρ` resonates and learns
//! `w_j ← β (I ∧ w_j) + (1 − β) w_j`. When none resonates a new category starts with
//! `w = I`.
//!
//! Seed 003's settings are the defaults: `ρ = 0.85`, `α = 10⁻⁶`, `β = 1` (fast learning), at
//! most ten categories.
//!
//! # When all categories are taken
//!
//! The seed does not say. Here an input that resonates with no category while the network is
//! full is given the category with the best match value (ties: lower index), *without*
//! learning, and the result says so ([`ArtResult::resonant`] is false). The learned
//! categories therefore stay stable once the network is full.

use crate::error::{Error, Result};

/// Fuzzy ART parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuzzyArtConfig {
    /// Vigilance ρ in `[0, 1]`; seed 003: 0.85.
    pub vigilance: f64,
    /// Choice parameter α > 0; seed 003: 1e-6.
    pub choice: f64,
    /// Learning rate β in `(0, 1]`; seed 003: 1.0.
    pub learning_rate: f64,
    /// Most categories; seed 003: 10.
    pub max_categories: usize,
}

impl Default for FuzzyArtConfig {
    fn default() -> Self {
        FuzzyArtConfig {
            vigilance: 0.85,
            choice: 1e-6,
            learning_rate: 1.0,
            max_categories: 10,
        }
    }
}

impl FuzzyArtConfig {
    /// Checks the ranges given on each field.
    pub fn validate(&self) -> Result<()> {
        if !(0.0..=1.0).contains(&self.vigilance) {
            return Err(Error::invalid(
                "FuzzyArtConfig::vigilance",
                format!("{} (must lie in [0, 1])", self.vigilance),
            ));
        }
        crate::error::ensure_positive("FuzzyArtConfig::choice", self.choice)?;
        if !(self.learning_rate > 0.0 && self.learning_rate <= 1.0) {
            return Err(Error::invalid(
                "FuzzyArtConfig::learning_rate",
                format!("{} (must lie in (0, 1])", self.learning_rate),
            ));
        }
        if self.max_categories == 0 {
            return Err(Error::invalid(
                "FuzzyArtConfig::max_categories",
                "0 (need at least 1)",
            ));
        }
        Ok(())
    }
}

/// The category an input went to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArtResult {
    /// Category index, `0..num_categories()`.
    pub category: usize,
    /// The match `|I ∧ w| / |I|` with the category before learning (1 for a new one).
    pub match_value: f64,
    /// True when the input resonated (or opened a new category) and was learned.
    pub resonant: bool,
    /// True when this input opened the category.
    pub new_category: bool,
}

/// A Fuzzy ART network over inputs of a fixed dimension.
#[derive(Clone, Debug)]
pub struct FuzzyArt {
    config: FuzzyArtConfig,
    dim: usize,
    /// Category weights, `2·dim` per category, contiguous.
    weights: Vec<f64>,
    coded: Vec<f64>,
    order: Vec<(f64, usize)>,
}

impl FuzzyArt {
    /// An empty network for inputs of `dim` components.
    pub fn new(dim: usize, config: FuzzyArtConfig) -> Result<Self> {
        config.validate()?;
        if dim == 0 {
            return Err(Error::invalid("Fuzzy ART input dimension", "0"));
        }
        Ok(FuzzyArt {
            config,
            dim,
            weights: Vec::with_capacity(2 * dim * config.max_categories),
            coded: vec![0.0; 2 * dim],
            order: Vec::with_capacity(config.max_categories),
        })
    }

    /// Number of categories learned so far.
    pub fn num_categories(&self) -> usize {
        self.weights.len() / (2 * self.dim)
    }

    /// Weights of category `j` (`2·dim` values), when it exists.
    pub fn category_weights(&self, j: usize) -> Option<&[f64]> {
        let m2 = 2 * self.dim;
        self.weights.get(j * m2..(j + 1) * m2)
    }

    /// Classifies `input` (components in `[0, 1]`) and learns it (see the module docs).
    pub fn classify(&mut self, input: &[f64]) -> Result<ArtResult> {
        if input.len() != self.dim {
            return Err(Error::invalid(
                "Fuzzy ART input",
                format!("{} components (expected {})", input.len(), self.dim),
            ));
        }
        if let Some(v) = input.iter().find(|v| !(0.0..=1.0).contains(*v)) {
            return Err(Error::invalid(
                "Fuzzy ART input",
                format!("component {v} outside [0, 1]"),
            ));
        }
        complement_code(input, &mut self.coded);
        let m2 = 2 * self.dim;
        let norm_i = self.dim as f64;
        self.order.clear();
        for j in 0..self.num_categories() {
            let w = &self.weights[j * m2..(j + 1) * m2];
            let (overlap, norm_w) = overlap_and_norm(&self.coded, w);
            self.order
                .push((overlap / (self.config.choice + norm_w), j));
        }
        // Decreasing choice value, lower index first on ties.
        self.order
            .sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let mut best_match: Option<(f64, usize)> = None;
        for &(_, j) in &self.order {
            let w = &self.weights[j * m2..(j + 1) * m2];
            let (overlap, _) = overlap_and_norm(&self.coded, w);
            let m = overlap / norm_i;
            if m >= self.config.vigilance {
                let beta = self.config.learning_rate;
                for (wk, &ik) in self.weights[j * m2..(j + 1) * m2]
                    .iter_mut()
                    .zip(&self.coded)
                {
                    *wk = beta * ik.min(*wk) + (1.0 - beta) * *wk;
                }
                return Ok(ArtResult {
                    category: j,
                    match_value: m,
                    resonant: true,
                    new_category: false,
                });
            }
            if best_match.is_none_or(|(bm, bj)| m > bm || (m == bm && j < bj)) {
                best_match = Some((m, j));
            }
        }
        if self.num_categories() < self.config.max_categories {
            self.weights.extend_from_slice(&self.coded);
            return Ok(ArtResult {
                category: self.num_categories() - 1,
                match_value: 1.0,
                resonant: true,
                new_category: true,
            });
        }
        let (m, j) = best_match.expect("a full network has at least one category");
        Ok(ArtResult {
            category: j,
            match_value: m,
            resonant: false,
            new_category: false,
        })
    }
}

/// Complement coding: `out = (a, 1 − a)`; `out` must hold `2·a.len()` values.
pub fn complement_code(a: &[f64], out: &mut [f64]) {
    let m = a.len();
    for (k, &v) in a.iter().enumerate() {
        out[k] = v;
        out[m + k] = 1.0 - v;
    }
}

fn overlap_and_norm(i: &[f64], w: &[f64]) -> (f64, f64) {
    i.iter()
        .zip(w)
        .fold((0.0, 0.0), |(o, n), (&a, &b)| (o + a.min(b), n + b))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn net() -> FuzzyArt {
        FuzzyArt::new(4, FuzzyArtConfig::default()).unwrap()
    }

    #[test]
    fn identical_inputs_share_a_category() {
        let mut art = net();
        let a = [0.2, 0.4, 0.6, 0.8];
        let r1 = art.classify(&a).unwrap();
        let r2 = art.classify(&a).unwrap();
        assert!(r1.new_category && !r2.new_category);
        assert_eq!(r1.category, r2.category);
        assert_eq!(r2.match_value, 1.0);
        assert_eq!(art.num_categories(), 1);
    }

    #[test]
    fn distant_inputs_open_new_categories_and_learning_is_the_minimum() {
        let mut art = net();
        assert_eq!(art.classify(&[0.1, 0.1, 0.1, 0.1]).unwrap().category, 0);
        // Match with category 0: |(0.9,..) ∧ (0.1,..)| + |(0.1,..) ∧ (0.9,..)| = 0.8 of 4.
        let r = art.classify(&[0.9, 0.9, 0.9, 0.9]).unwrap();
        assert!(r.new_category);
        assert_eq!(r.category, 1);
        // A near input: match with category 0 is (4·0.1 + 3·0.9 + 0.8) / 4 = 0.975 ≥ 0.85.
        let r = art.classify(&[0.1, 0.1, 0.1, 0.2]).unwrap();
        assert_eq!(r.category, 0);
        assert!((r.match_value - 0.975).abs() < 1e-12);
        // Fast learning: w₀ = I ∧ w₀.
        let w = art.category_weights(0).unwrap();
        assert_eq!(w, &[0.1, 0.1, 0.1, 0.1, 0.9, 0.9, 0.9, 0.8]);
    }

    #[test]
    fn category_cap_is_respected() {
        let config = FuzzyArtConfig {
            max_categories: 3,
            ..FuzzyArtConfig::default()
        };
        let mut art = FuzzyArt::new(1, config).unwrap();
        for (k, v) in [0.0, 0.5, 1.0].into_iter().enumerate() {
            assert_eq!(art.classify(&[v]).unwrap().category, k);
        }
        // 0.8 resonates with nobody (best match 1 − 0.2 = 0.8 with the 1.0 category).
        let r = art.classify(&[0.8]).unwrap();
        assert_eq!(art.num_categories(), 3);
        assert!(!r.resonant && !r.new_category);
        assert_eq!(r.category, 2);
        assert!((r.match_value - 0.8).abs() < 1e-12);
        // Not learned: the category still matches 1.0 exactly.
        assert_eq!(art.category_weights(2).unwrap(), &[1.0, 0.0]);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let mut art = net();
        assert!(art.classify(&[0.1, 0.2]).is_err());
        assert!(art.classify(&[0.1, 0.2, 1.2, 0.0]).is_err());
        assert!(art.classify(&[0.1, f64::NAN, 0.2, 0.0]).is_err());
        assert!(FuzzyArt::new(0, FuzzyArtConfig::default()).is_err());
    }

    proptest! {
        #[test]
        fn complement_coding_has_norm_m(a in proptest::collection::vec(0.0f64..=1.0, 1..20)) {
            let mut out = vec![0.0; 2 * a.len()];
            complement_code(&a, &mut out);
            let norm: f64 = out.iter().sum();
            prop_assert!((norm - a.len() as f64).abs() < 1e-9);
            prop_assert!(out.iter().all(|v| (0.0..=1.0).contains(v)));
        }

        #[test]
        fn categories_never_exceed_the_cap(
            inputs in proptest::collection::vec(proptest::collection::vec(0.0f64..=1.0, 3), 1..60)
        ) {
            let mut art = FuzzyArt::new(3, FuzzyArtConfig::default()).unwrap();
            for a in &inputs {
                let r = art.classify(a).unwrap();
                prop_assert!(r.category < art.num_categories());
            }
            prop_assert!(art.num_categories() <= 10);
        }
    }
}
