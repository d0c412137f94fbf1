//! The learned density of the `Other` class (street furniture, trunks, hedges, wall pieces:
//! every cluster that is no road user): a Gaussian mixture over four features of a cluster,
//!
//! * ln(length), ln(width) of the fitted footprint (sides floored at [`MIN_SIDE`]),
//! * the height above the ground (m),
//! * ln(points / the points expected at that range on a 1 m × 1 m × 1 m object),
//!
//! fitted on clusters of the KITTI object benchmark's training scans that lie in no labelled
//! box and in view of the labelled camera. The model is written by
//!
//! ```text
//! cargo run --release --example fit_other_class -- \
//!     --object ../shared/data/kitti_object/training --out src/cloud/other_class.json
//! ```
//!
//! and embedded here. [`OtherDensity::ln_density`] is the density over (length, width,
//! height, ln points), the coordinates the road-user classes' likelihoods live in: the
//! mixture's density times the Jacobian 1 / (length · width) of the log sides.
//!
//! Not for: fitting (the example does it), the road-user classes (see [`super::classes`]).

use crate::error::{Error, Result};
use nalgebra::{Matrix4, Vector4};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Smallest footprint side (m) the features use: a cluster on one scan line has a width of
/// about zero, which the log would send to −∞; 5 cm is below the scanner's azimuth spacing at
/// 10 m (0.0031 rad × 10 m ≈ 3 cm) plus its range noise.
pub const MIN_SIDE: f64 = 0.05;

/// Most components a model may have.
pub const MAX_COMPONENTS: usize = 16;

/// Names of the features, in order.
pub const OTHER_FEATURE_NAMES: [&str; 4] = ["ln_length", "ln_width", "height", "ln_density"];

/// The model file as written by the fitting example.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OtherModelFile {
    /// Where the examples came from and how they were chosen.
    pub source: String,
    /// Number of examples fitted.
    pub examples: usize,
    /// Feature names, [`OTHER_FEATURE_NAMES`].
    pub features: Vec<String>,
    /// The mixture's components.
    pub components: Vec<ComponentFile>,
}

/// One Gaussian component as stored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ComponentFile {
    /// Mixture weight.
    pub weight: f64,
    /// Mean of the features.
    pub mean: [f64; 4],
    /// Covariance, row by row.
    pub covariance: [[f64; 4]; 4],
}

#[derive(Clone, Debug, PartialEq)]
struct Component {
    /// ln weight − ½ ln det(2π Σ).
    ln_norm: f64,
    mean: Vector4<f64>,
    precision: Matrix4<f64>,
}

/// A Gaussian mixture over the `Other` features, ready to evaluate.
#[derive(Clone, Debug, PartialEq)]
pub struct OtherDensity {
    components: Vec<Component>,
}

/// The feature vector of a cluster: see the module notes; `ln_expected_unit` is ln of the
/// points expected at the cluster's range on a 1 m³ cube.
pub fn other_features(
    length: f64,
    width: f64,
    height: f64,
    ln_points: f64,
    ln_expected_unit: f64,
) -> [f64; 4] {
    [
        length.max(MIN_SIDE).ln(),
        width.max(MIN_SIDE).ln(),
        height,
        ln_points - ln_expected_unit,
    ]
}

impl OtherDensity {
    /// The density of a model file; fails on no components, weights that are not positive or
    /// do not sum to 1, or a covariance that is not symmetric positive definite.
    pub fn from_file(file: &OtherModelFile) -> Result<Self> {
        if file.components.is_empty() || file.components.len() > MAX_COMPONENTS {
            return Err(Error::invalid(
                "Other class model",
                format!(
                    "{} components (need 1 to {MAX_COMPONENTS})",
                    file.components.len()
                ),
            ));
        }
        let total: f64 = file.components.iter().map(|c| c.weight).sum();
        if (total - 1.0).abs() > 1e-6 {
            return Err(Error::invalid(
                "Other class model weights",
                format!("sum {total} (must be 1)"),
            ));
        }
        let mut components = Vec::with_capacity(file.components.len());
        for (k, c) in file.components.iter().enumerate() {
            let cov = Matrix4::from_fn(|i, j| c.covariance[i][j]);
            let finite = cov.iter().chain(c.mean.iter()).all(|v| v.is_finite());
            let symmetric = (cov - cov.transpose()).amax() <= 1e-9 * cov.amax();
            let chol = (finite && symmetric && c.weight > 0.0)
                .then(|| cov.cholesky())
                .flatten()
                .ok_or_else(|| {
                    Error::invalid(
                        "Other class model component",
                        format!("{k}: weight {} or covariance {cov:?} not valid", c.weight),
                    )
                })?;
            let ln_det: f64 = 2.0 * chol.l().diagonal().iter().map(|d| d.ln()).sum::<f64>();
            components.push(Component {
                ln_norm: c.weight.ln() - 0.5 * (ln_det + 4.0 * (2.0 * PI).ln()),
                mean: Vector4::from(c.mean),
                precision: chol.inverse(),
            });
        }
        Ok(Self { components })
    }

    /// The model shipped with the library (`src/cloud/other_class.json`), parsed once.
    pub fn embedded() -> Result<&'static OtherDensity> {
        static MODEL: OnceLock<std::result::Result<OtherDensity, String>> = OnceLock::new();
        MODEL
            .get_or_init(|| {
                let file: OtherModelFile = serde_json::from_str(include_str!("other_class.json"))
                    .map_err(|e| e.to_string())?;
                OtherDensity::from_file(&file).map_err(|e| e.to_string())
            })
            .as_ref()
            .map_err(|e| Error::invalid("embedded Other class model", e.clone()))
    }

    /// ln of the mixture's density at the feature vector `z`.
    pub fn ln_mixture(&self, z: &[f64; 4]) -> f64 {
        let z = Vector4::from(*z);
        let mut top = f64::NEG_INFINITY;
        let mut terms = [0.0; MAX_COMPONENTS];
        let n = self.components.len();
        for (t, c) in terms.iter_mut().zip(&self.components) {
            let d = z - c.mean;
            *t = c.ln_norm - 0.5 * d.dot(&(c.precision * d));
            top = top.max(*t);
        }
        let sum: f64 = terms[..n].iter().map(|t| (t - top).exp()).sum();
        top + sum.ln()
    }

    /// ln p(length, width, height, ln points) of a cluster; `ln_expected_unit` as in
    /// [`other_features`].
    pub fn ln_density(
        &self,
        length: f64,
        width: f64,
        height: f64,
        ln_points: f64,
        ln_expected_unit: f64,
    ) -> f64 {
        let z = other_features(length, width, height, ln_points, ln_expected_unit);
        // Jacobian of (ln l, ln w): 1/(l w), with the sides floored as in the features.
        self.ln_mixture(&z) - z[0] - z[1]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one_component(mean: [f64; 4], diag: [f64; 4]) -> OtherModelFile {
        let mut covariance = [[0.0; 4]; 4];
        for i in 0..4 {
            covariance[i][i] = diag[i];
        }
        OtherModelFile {
            source: "test".into(),
            examples: 0,
            features: OTHER_FEATURE_NAMES.map(String::from).to_vec(),
            components: vec![ComponentFile {
                weight: 1.0,
                mean,
                covariance,
            }],
        }
    }

    #[test]
    fn single_gaussian_by_hand() {
        let m = OtherDensity::from_file(&one_component([0.0; 4], [1.0, 4.0, 0.25, 1.0])).unwrap();
        // At the mean: −½ ln((2π)⁴ · 1 · 4 · 0.25 · 1) = −2 ln 2π.
        let want = -2.0 * (2.0 * PI).ln();
        assert!((m.ln_mixture(&[0.0; 4]) - want).abs() < 1e-12);
        // One step of (1, 2, 0.5, 1) = one σ on every axis: −½ · 4 more.
        assert!((m.ln_mixture(&[1.0, 2.0, 0.5, 1.0]) - (want - 2.0)).abs() < 1e-12);
        // Density over sides: a 2 × 0.5 m footprint adds −ln(2 · 0.5) = 0 and a 1 × 1 m one
        // is at ln-sides 0.
        let z = other_features(1.0, 1.0, 0.0, 3.0, 3.0);
        assert_eq!(z, [0.0, 0.0, 0.0, 0.0]);
        assert!((m.ln_density(1.0, 1.0, 0.0, 3.0, 3.0) - want).abs() < 1e-12);
        let e = 1f64.exp();
        assert!((m.ln_density(e, 1.0, 0.0, 3.0, 3.0) - (want - 0.5 - 1.0)).abs() < 1e-12);
    }

    #[test]
    fn two_equal_components_sum() {
        let mut f = one_component([0.0; 4], [1.0; 4]);
        let mut c = f.components[0].clone();
        c.mean = [10.0, 0.0, 0.0, 0.0];
        c.weight = 0.5;
        f.components[0].weight = 0.5;
        f.components.push(c);
        let m = OtherDensity::from_file(&f).unwrap();
        // Half of one Gaussian at its mean plus ~nothing from the other 10 σ away.
        let one = -2.0 * (2.0 * PI).ln();
        let got = m.ln_mixture(&[0.0; 4]);
        let want = (0.5 * one.exp() + 0.5 * (one - 50.0).exp()).ln();
        assert!((got - want).abs() < 1e-12);
    }

    #[test]
    fn bad_models_are_errors() {
        let mut f = one_component([0.0; 4], [1.0; 4]);
        f.components[0].covariance[0][0] = -1.0;
        assert!(OtherDensity::from_file(&f).is_err());
        let mut f = one_component([0.0; 4], [1.0; 4]);
        f.components[0].weight = 0.3;
        assert!(OtherDensity::from_file(&f).is_err());
        let mut f = one_component([0.0; 4], [1.0; 4]);
        f.components.clear();
        assert!(OtherDensity::from_file(&f).is_err());
    }

    #[test]
    fn embedded_model_loads() {
        let m = OtherDensity::embedded().unwrap();
        assert!(!m.components.is_empty() && m.components.len() <= MAX_COMPONENTS);
    }
}
