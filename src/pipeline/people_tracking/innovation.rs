//! Innovations of a particle track for the consistency checks of seed 003's appendix (RMS
//! prediction error, normalised innovation squared), as the Gaussian baselines report them.
//!
//! A particle filter has no innovation covariance of its own; here it comes from the
//! predicted particle cloud itself. Each predicted particle xᵢ (weight wᵢ) reads
//! h(xᵢ) = [range, bearing]; with dᵢ = h(xᵢ) − z (bearing wrapped to (−π, π]) the predicted
//! measurement misses z by d̄ = Σ wᵢ dᵢ, so the innovation is ν = −d̄, and
//!
//! S = Σ wᵢ (dᵢ − d̄)(dᵢ − d̄)ᵀ + R,  NIS = νᵀ S⁻¹ ν,
//!
//! R = diag(σ_range², σ_bearing²) the sensor's nominal noise. Taking differences to z before
//! averaging keeps bearings near ±π in one piece. For a consistent filter the NIS averages two
//! (two degrees of freedom). The position error is the measurement's world point minus the
//! weighted mean of the predicted positions.
//!
//! Not for: deciding which measurement a track generated (that is the filter's association)
//! or Gaussian tracks (the baselines compute theirs from their own covariances).

use crate::filter::StepContext;
use crate::filter::{Label, ParticleSet};
use crate::models::RangeBearing;
use crate::trackers::Innovation;

/// The innovation of measurement `z` = [range, bearing] for the predicted cloud `predicted`
/// of track `label` (position in components 0 and 2), or `None` when the cloud is empty,
/// has no weight, or gives a singular S.
pub fn particle_innovation(
    label: Label,
    predicted: &ParticleSet,
    z: [f64; 2],
    sensor: &RangeBearing,
    ctx: &StepContext,
) -> Option<Innovation> {
    if predicted.is_empty() || predicted.dim() < 3 {
        return None;
    }
    let n = predicted.len();
    let (mut dr, mut db) = (vec![0.0; n], vec![0.0; n]);
    sensor.residuals(z, predicted, ctx, &mut dr, &mut db);
    let w = predicted.weights();
    let total: f64 = w.iter().sum();
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    let mean = |v: &[f64]| v.iter().zip(w).map(|(v, w)| v * w).sum::<f64>() / total;
    let d = [mean(&dr), mean(&db)];
    let position = [mean(predicted.component(0)), mean(predicted.component(2))];
    let (sr, sb) = (sensor.sigma_range(), sensor.sigma_bearing());
    let mut s = [sr * sr, 0.0, sb * sb];
    for ((&a, &b), &wi) in dr.iter().zip(&db).zip(w) {
        let (a, b, wi) = (a - d[0], b - d[1], wi / total);
        s[0] += wi * a * a;
        s[1] += wi * a * b;
        s[2] += wi * b * b;
    }
    let det = s[0] * s[2] - s[1] * s[1];
    if det.is_nan() || det <= 0.0 {
        return None;
    }
    let nu = [-d[0], -d[1]];
    let nis = (s[2] * nu[0] * nu[0] - 2.0 * s[1] * nu[0] * nu[1] + s[0] * nu[1] * nu[1]) / det;
    let point = sensor.to_cartesian(z, ctx);
    Some(Innovation {
        label,
        position_error: [point[0] - position[0], point[1] - position[1]],
        nis,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;
    use rand_distr::{Distribution, StandardNormal};

    fn ctx() -> StepContext {
        StepContext::new(1, 0.125, 0.125)
    }

    /// A cloud of `n` equally weighted particles around (x, y) with position spread `sigma`.
    fn cloud(x: f64, y: f64, sigma: f64, n: usize, seed: u64) -> ParticleSet {
        let mut rng = seeded(seed);
        let rows: Vec<Vec<f64>> = (0..n)
            .map(|_| {
                let ex: f64 = StandardNormal.sample(&mut rng);
                let ey: f64 = StandardNormal.sample(&mut rng);
                vec![x + sigma * ex, 0.0, y + sigma * ey, 0.0]
            })
            .collect();
        ParticleSet::from_rows(&rows, &vec![1.0; n]).unwrap()
    }

    #[test]
    fn a_point_cloud_gives_the_sensor_noise_alone() {
        // Every particle at (3, 4): h = [5, atan2(4, 3)], S = R, ν = z − h.
        let sensor = RangeBearing::new(0.1, 0.02).unwrap();
        let p = ParticleSet::from_rows(&vec![vec![3.0, 0.0, 4.0, 0.0]; 4], &[1.0; 4]).unwrap();
        let b = 4f64.atan2(3.0);
        let inn =
            particle_innovation(Label::new(0, 0), &p, [5.2, b - 0.01], &sensor, &ctx()).unwrap();
        let expected = (0.2f64 / 0.1).powi(2) + (0.01f64 / 0.02).powi(2);
        assert!((inn.nis - expected).abs() < 1e-9, "{}", inn.nis);
        let (c, s) = ((b - 0.01).cos(), (b - 0.01).sin());
        let e = [5.2 * c - 3.0, 5.2 * s - 4.0];
        assert!((inn.position_error[0] - e[0]).abs() < 1e-12);
        assert!((inn.position_error[1] - e[1]).abs() < 1e-12);
    }

    #[test]
    fn bearings_across_the_back_stay_in_one_piece() {
        // A person right behind the sensor: bearings of the particles straddle ±π.
        let sensor = RangeBearing::new(0.1, 0.02).unwrap();
        let p = cloud(-5.0, 0.0, 0.05, 400, 3);
        let inn = particle_innovation(
            Label::new(0, 0),
            &p,
            [5.0, -std::f64::consts::PI],
            &sensor,
            &ctx(),
        )
        .unwrap();
        assert!(inn.nis < 5.0, "{}", inn.nis);
    }

    #[test]
    fn nis_averages_two_when_the_cloud_is_the_truth() {
        // Truth drawn from the predicted density and measured with the assumed noise: the
        // NIS is χ² with two degrees of freedom, mean 2 (a loose bound for 400 draws: the
        // standard error of the mean is 0.1).
        let sensor = RangeBearing::new(0.05, 0.01).unwrap();
        let mut rng = seeded(11);
        let mut sum = 0.0;
        let n = 400;
        for k in 0..n {
            let p = cloud(6.0, 2.0, 0.15, 500, 100 + k);
            let ex: f64 = StandardNormal.sample(&mut rng);
            let ey: f64 = StandardNormal.sample(&mut rng);
            let truth = [6.0 + 0.15 * ex, 0.0, 2.0 + 0.15 * ey];
            let h = sensor.predict_measurement(&truth, &ctx());
            let er: f64 = StandardNormal.sample(&mut rng);
            let eb: f64 = StandardNormal.sample(&mut rng);
            let z = [h[0] + 0.05 * er, h[1] + 0.01 * eb];
            sum += particle_innovation(Label::new(0, 0), &p, z, &sensor, &ctx())
                .unwrap()
                .nis;
        }
        let mean = sum / n as f64;
        assert!((mean - 2.0).abs() < 0.35, "mean NIS {mean}");
    }

    #[test]
    fn an_empty_cloud_gives_none() {
        let sensor = RangeBearing::new(0.1, 0.02).unwrap();
        let empty = ParticleSet::zeroed(4, 0);
        let inn = particle_innovation(Label::new(0, 0), &empty, [5.0, 0.9], &sensor, &ctx());
        assert!(inn.is_none());
    }
}
