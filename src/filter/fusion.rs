//! How the updates of several sensors combine into one posterior per track: the four rules of
//! the multi-sensor LMB filters (Robertson et al., "Efficient approximations of the
//! multi-sensor labelled multi-Bernoulli filter", Signal Processing 2022), on particles.
//!
//! - **Iterated corrector (IC)**: each sensor's full LMB update in turn, the next sensor
//!   starting from the last one's posterior.
//! - **Parallel update (PU)**, **geometric average (GA)**, **arithmetic average (AA)**: every
//!   sensor's update starts from the same predicted tracks, and the per-sensor posteriors are
//!   combined. With particles every sensor reweights the same predicted particles of a label,
//!   so sensor s's posterior density is the prior times a weight ratio fₛ(xᵢ)/cₛ, with
//!   cₛ = Σᵢ wᵢ fₛ(xᵢ). The combined densities are then exact up to Monte-Carlo error:
//!   - PU: p ∝ p₀^(1−S) ∏ₛ pₛ, i.e. wᵢ ∏ₛ fₛ(xᵢ)/cₛ, with existence
//!     r = η r₀^(1−S) ∏ rₛ / (η r₀^(1−S) ∏ rₛ + (1 − r₀)^(1−S) ∏ (1 − rₛ)),
//!     η = Σᵢ wᵢ ∏ₛ fₛ(xᵢ)/cₛ;
//!   - GA with weights ωₛ (Σ ωₛ = 1): p ∝ ∏ₛ pₛ^ωₛ, i.e. wᵢ ∏ₛ (fₛ(xᵢ)/cₛ)^ωₛ, with
//!     r = η ∏ rₛ^ωₛ / (η ∏ rₛ^ωₛ + ∏ (1 − rₛ)^ωₛ), η = Σᵢ wᵢ ∏ₛ (fₛ(xᵢ)/cₛ)^ωₛ;
//!   - AA: r = Σ ωₛ rₛ and p = Σ ωₛ rₛ pₛ / r, i.e. wᵢ Σₛ ωₛ rₛ fₛ(xᵢ)/cₛ.
//!
//!   The existence formulas are those of the Gaussian-mixture filters (the same as the
//!   multisensor-lmb-filters crate's), with η, the integral of the combined density, summed
//!   over the particles instead of over products of Gaussians. PU and GA multiply in the log
//!   domain, so no product underflows.
//!
//! The filter resamples any track whose combined weights collapse (effective sample size
//! below [`super::LmbConfig::resample_threshold`] of its count), as after any update.
//!
//! Not for: one sensor's update itself (the filter's private `update` module), or the
//! sensors' models.

use super::ParticleSet;
use crate::error::{Error, Result};

/// The rule that combines the sensors' updates (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum FusionMethod {
    /// Each sensor's update in turn (`"ic"`).
    #[default]
    #[serde(rename = "ic")]
    IteratedCorrector,
    /// The product of the sensors' posteriors over the prior (`"pu"`).
    #[serde(rename = "pu")]
    ParallelUpdate,
    /// The weighted geometric average of the sensors' posteriors (`"ga"`).
    #[serde(rename = "ga")]
    GeometricAverage,
    /// The weighted arithmetic average of the sensors' posteriors (`"aa"`).
    #[serde(rename = "aa")]
    ArithmeticAverage,
}

impl FusionMethod {
    /// The short name used in configuration files: `ic`, `pu`, `ga` or `aa`.
    pub fn short_name(self) -> &'static str {
        match self {
            FusionMethod::IteratedCorrector => "ic",
            FusionMethod::ParallelUpdate => "pu",
            FusionMethod::GeometricAverage => "ga",
            FusionMethod::ArithmeticAverage => "aa",
        }
    }

    /// The rule of a short name ([`FusionMethod::short_name`]); an error naming the accepted
    /// names otherwise.
    pub fn from_short_name(name: &str) -> Result<Self> {
        [
            FusionMethod::IteratedCorrector,
            FusionMethod::ParallelUpdate,
            FusionMethod::GeometricAverage,
            FusionMethod::ArithmeticAverage,
        ]
        .into_iter()
        .find(|m| m.short_name() == name)
        .ok_or_else(|| Error::invalid("fusion", format!("`{name}` (expected ic, pu, ga or aa)")))
    }
}

/// How a filter with several sensors combines them: the rule, the fusion weights of GA and AA,
/// and the order of IC's updates.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Fusion {
    /// The rule (default: iterated corrector).
    pub method: FusionMethod,
    /// One weight per sensor, in the sensors' order, ≥ 0 and summing to one (default:
    /// uniform). GA and AA use them; in a frame that only some sensors report, the reporting
    /// sensors' weights are scaled to sum to one.
    pub weights: Option<Vec<f64>>,
    /// The order of IC's updates, as sensor indices, each at most once; sensors not named
    /// follow in index order (default: index order).
    pub order: Option<Vec<usize>>,
}

impl Fusion {
    /// Fusion by `method` with uniform weights and sensors in index order.
    pub fn new(method: FusionMethod) -> Self {
        Fusion {
            method,
            weights: None,
            order: None,
        }
    }

    /// The same with fusion `weights` (one per sensor).
    pub fn with_weights(mut self, weights: Vec<f64>) -> Self {
        self.weights = Some(weights);
        self
    }

    /// The same with IC's update `order` (sensor indices).
    pub fn with_order(mut self, order: Vec<usize>) -> Self {
        self.order = Some(order);
        self
    }

    /// Checks the weights and order against `sensors` sensors: one weight per sensor, each
    /// finite and ≥ 0, summing to one within 1e-9; order indices in range and not repeated.
    pub fn validate(&self, sensors: usize) -> Result<()> {
        if let Some(w) = &self.weights {
            if w.len() != sensors {
                return Err(Error::invalid(
                    "fusion weights",
                    format!("{} weights given for {sensors} sensors", w.len()),
                ));
            }
            if let Some((i, v)) = w
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.is_finite() && **v >= 0.0))
            {
                return Err(Error::invalid(
                    "fusion weights",
                    format!("weight {i} is {v}; weights must be finite and ≥ 0"),
                ));
            }
            let sum: f64 = w.iter().sum();
            if (sum - 1.0).abs() > 1e-9 {
                return Err(Error::invalid(
                    "fusion weights",
                    format!("sum to {sum}, not one"),
                ));
            }
        }
        if let Some(order) = &self.order {
            for (k, &i) in order.iter().enumerate() {
                if i >= sensors {
                    return Err(Error::invalid(
                        "fusion order",
                        format!("names sensor {i}, but there are {sensors} sensors"),
                    ));
                }
                if order[..k].contains(&i) {
                    return Err(Error::invalid(
                        "fusion order",
                        format!("names sensor {i} twice"),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The sensors of `present` (sorted sensor indices) in IC's update order.
    pub(crate) fn ordered(&self, present: &[usize]) -> Vec<usize> {
        let mut out: Vec<usize> = self
            .order
            .iter()
            .flatten()
            .copied()
            .filter(|i| present.contains(i))
            .collect();
        let rest: Vec<usize> = present
            .iter()
            .copied()
            .filter(|i| !out.contains(i))
            .collect();
        out.extend(rest);
        out
    }

    /// The weights of the sensors of `present`, scaled to sum to one (uniform by default).
    pub(crate) fn weights_of(&self, present: &[usize]) -> Vec<f64> {
        let raw: Vec<f64> = match &self.weights {
            None => vec![1.0; present.len()],
            Some(w) => present.iter().map(|&i| w[i]).collect(),
        };
        let sum: f64 = raw.iter().sum();
        if sum > 0.0 {
            raw.iter().map(|w| w / sum).collect()
        } else {
            vec![1.0 / present.len() as f64; present.len()]
        }
    }
}

/// One sensor's posterior of one track, as its update left it: the existence, the expected
/// number of its detections of the track, and the factor fₛ(xᵢ) by which it reweights the
/// predicted particles (`None`: weights unchanged, the same as a constant factor).
pub(crate) struct SensorPosterior {
    pub existence: f64,
    pub detected: f64,
    pub factor: Option<Vec<f64>>,
}

/// The existence floor and ceiling of PU and GA's formulas, which divide by r and 1 − r.
const R_CLAMP: f64 = 1e-10;

/// Combines the per-sensor posteriors `posts` of one track whose predicted existence is `r0`
/// and whose particles are `particles` (reweighted in place) by `method` with `weights`
/// (one per posterior, summing to one); returns the combined existence. Not for IC, which
/// updates in turn.
pub(crate) fn fuse_track(
    method: FusionMethod,
    weights: &[f64],
    r0: f64,
    particles: &mut ParticleSet,
    posts: &[SensorPosterior],
) -> f64 {
    debug_assert_eq!(weights.len(), posts.len());
    let n = particles.len();
    let norm: Vec<f64> = posts
        .iter()
        .map(|p| match &p.factor {
            Some(f) => particles.weights().iter().zip(f).map(|(w, f)| w * f).sum(),
            None => 1.0,
        })
        .collect();
    match method {
        FusionMethod::IteratedCorrector => unreachable!("IC updates the sensors in turn"),
        FusionMethod::ArithmeticAverage => {
            let r: f64 = posts
                .iter()
                .zip(weights)
                .map(|(p, w)| w * p.existence)
                .sum();
            if r > 0.0 && posts.iter().any(|p| p.factor.is_some()) {
                let mut factor = vec![0.0; n];
                for ((p, w), c) in posts.iter().zip(weights).zip(&norm) {
                    let a = w * p.existence;
                    match &p.factor {
                        Some(f) if *c > 0.0 => {
                            factor.iter_mut().zip(f).for_each(|(x, f)| *x += a * f / c)
                        }
                        Some(_) => {}
                        None => factor.iter_mut().for_each(|x| *x += a),
                    }
                }
                particles.reweight(&factor);
            }
            r.clamp(0.0, 1.0)
        }
        FusionMethod::ParallelUpdate | FusionMethod::GeometricAverage => {
            let pu = method == FusionMethod::ParallelUpdate;
            let power = |w: f64| if pu { 1.0 } else { w };
            let mut log_ratio = vec![0.0; n];
            for ((p, &w), c) in posts.iter().zip(weights).zip(&norm) {
                if let Some(f) = &p.factor {
                    let lc = c.ln();
                    let e = power(w);
                    log_ratio
                        .iter_mut()
                        .zip(f)
                        .for_each(|(l, f)| *l += e * (f.ln() - lc));
                }
            }
            let log_eta = if posts.iter().any(|p| p.factor.is_some()) {
                particles.reweight_log(&log_ratio)
            } else {
                0.0
            };
            if !log_eta.is_finite() {
                return 0.0;
            }
            let clamp = |r: f64| r.clamp(R_CLAMP, 1.0 - R_CLAMP);
            let (mut num, mut den) = (log_eta, 0.0);
            if pu {
                let s = posts.len() as f64;
                let r0 = clamp(r0);
                num += (1.0 - s) * r0.ln();
                den += (1.0 - s) * (1.0 - r0).ln();
            }
            for (p, &w) in posts.iter().zip(weights) {
                let r = clamp(p.existence);
                num += power(w) * r.ln();
                den += power(w) * (1.0 - r).ln();
            }
            // r = e^num / (e^num + e^den), without overflow.
            (1.0 / (1.0 + (den - num).exp())).clamp(0.0, 1.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;

    #[test]
    fn rules_are_found_by_their_short_names_only() {
        for m in [
            FusionMethod::IteratedCorrector,
            FusionMethod::ParallelUpdate,
            FusionMethod::GeometricAverage,
            FusionMethod::ArithmeticAverage,
        ] {
            assert_eq!(FusionMethod::from_short_name(m.short_name()).unwrap(), m);
        }
        let err = FusionMethod::from_short_name("PU").unwrap_err().to_string();
        assert!(
            err.contains("`PU`") && err.contains("ic, pu, ga or aa"),
            "{err}"
        );
    }

    fn post(r: f64, f: Option<Vec<f64>>) -> SensorPosterior {
        SensorPosterior {
            existence: r,
            detected: 0.0,
            factor: f,
        }
    }

    fn uniform(n: usize) -> ParticleSet {
        ParticleSet::gaussian(&[0.0], &[1.0], n, &mut seeded(1)).unwrap()
    }

    #[test]
    fn weights_and_order_are_checked() {
        assert!(Fusion::new(FusionMethod::GeometricAverage)
            .with_weights(vec![0.25, 0.75])
            .validate(2)
            .is_ok());
        for bad in [
            vec![0.5],
            vec![-0.5, 1.5],
            vec![0.5, 0.6],
            vec![f64::NAN, 1.0],
        ] {
            assert!(Fusion::new(FusionMethod::ArithmeticAverage)
                .with_weights(bad)
                .validate(2)
                .is_err());
        }
        assert!(Fusion::default()
            .with_order(vec![1, 1])
            .validate(2)
            .is_err());
        assert!(Fusion::default().with_order(vec![2]).validate(2).is_err());
        let f = Fusion::default().with_order(vec![2, 0]);
        assert_eq!(f.ordered(&[0, 1, 2]), vec![2, 0, 1]);
        assert_eq!(f.ordered(&[1]), vec![1]);
        let w = Fusion::new(FusionMethod::GeometricAverage).with_weights(vec![0.2, 0.3, 0.5]);
        let got = w.weights_of(&[1, 2]);
        assert!((got[0] - 0.375).abs() < 1e-12 && (got[1] - 0.625).abs() < 1e-12);
    }

    /// PU on two particles against the Bernoulli product written out by hand.
    #[test]
    fn parallel_update_is_the_product_over_the_prior() {
        let mut p = uniform(2);
        let w0 = p.weights().to_vec();
        let (f1, f2) = (vec![2.0, 1.0], vec![1.0, 3.0]);
        let (r0, r1, r2) = (0.4, 0.7, 0.6);
        let r = fuse_track(
            FusionMethod::ParallelUpdate,
            &[0.5, 0.5],
            r0,
            &mut p,
            &[post(r1, Some(f1.clone())), post(r2, Some(f2.clone()))],
        );
        let c1: f64 = w0.iter().zip(&f1).map(|(w, f)| w * f).sum();
        let c2: f64 = w0.iter().zip(&f2).map(|(w, f)| w * f).sum();
        let g: Vec<f64> = (0..2).map(|i| w0[i] * f1[i] / c1 * f2[i] / c2).collect();
        let eta: f64 = g.iter().sum();
        let num = eta * r1 * r2 / r0;
        let den = (1.0 - r1) * (1.0 - r2) / (1.0 - r0);
        assert!((r - num / (num + den)).abs() < 1e-12);
        assert!((p.weights()[0] - g[0] / eta).abs() < 1e-12);
    }

    /// GA with equal posteriors gives them back; AA is the weighted mixture.
    #[test]
    fn averages_of_equal_posteriors_are_that_posterior() {
        let f = vec![0.5, 2.0, 1.0];
        for method in [
            FusionMethod::GeometricAverage,
            FusionMethod::ArithmeticAverage,
        ] {
            let mut p = uniform(3);
            let mut single = p.clone();
            single.reweight(&f);
            let r = fuse_track(
                method,
                &[0.3, 0.7],
                0.5,
                &mut p,
                &[post(0.8, Some(f.clone())), post(0.8, Some(f.clone()))],
            );
            assert!((r - 0.8).abs() < 1e-9, "{method:?}: {r}");
            for (a, b) in p.weights().iter().zip(single.weights()) {
                assert!((a - b).abs() < 1e-12);
            }
        }
        let mut p = uniform(2);
        let w0 = p.weights().to_vec();
        let r = fuse_track(
            FusionMethod::ArithmeticAverage,
            &[0.25, 0.75],
            0.5,
            &mut p,
            &[post(0.8, Some(vec![1.0, 0.0])), post(0.4, None)],
        );
        assert!((r - (0.25 * 0.8 + 0.75 * 0.4)).abs() < 1e-12);
        let a = 0.25 * 0.8 / w0[0];
        let b = 0.75 * 0.4;
        let want0 = w0[0] * (a + b) / (w0[0] * (a + b) + w0[1] * b);
        assert!((p.weights()[0] - want0).abs() < 1e-12);
    }

    /// Particles every sensor rules out leave PU with no support: existence zero.
    #[test]
    fn disjoint_supports_give_zero_existence() {
        let mut p = uniform(2);
        let r = fuse_track(
            FusionMethod::ParallelUpdate,
            &[0.5, 0.5],
            0.5,
            &mut p,
            &[
                post(0.9, Some(vec![1.0, 0.0])),
                post(0.9, Some(vec![0.0, 1.0])),
            ],
        );
        assert_eq!(r, 0.0);
        assert!(p.weights().iter().all(|w| w.is_finite()));
    }
}
