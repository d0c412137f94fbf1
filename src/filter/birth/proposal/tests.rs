//! Checks of the measurement-guided birth sample against the birth density it stands for.

use super::*;
use crate::filter::Measurements;
use crate::rng::seeded;

/// The birth term shape: position std 50 m, velocity std 10 m/s.
fn term() -> BirthTerm {
    BirthTerm {
        existence: 0.01,
        mean: vec![25.0, 0.0, -25.0, 0.0],
        std: vec![50.0, 10.0, 50.0, 10.0],
    }
}

fn proposal() -> BirthProposal {
    BirthProposal::new(vec![0, 2], vec![1.0, 1.0]).unwrap()
}

/// Two measurements far from the term's mean (1.5 and 1.1 standard deviations).
fn far_measurements() -> Measurements {
    Measurements::from_rows(2, &[[90.0, 40.0], [-20.0, -75.0]]).unwrap()
}

fn guided(n: usize, seed: u64) -> ParticleSet {
    let z = far_measurements();
    let current = CurrentMeasurements {
        measurements: &z,
        unexplained: &[1.0, 0.5],
    };
    proposal().sample(&term(), &current, n, &mut seeded(seed))
}

fn ess(p: &ParticleSet) -> f64 {
    1.0 / p.weights().iter().map(|w| w * w).sum::<f64>()
}

#[test]
fn weighted_sample_has_the_priors_mean_and_covariance() {
    // The prior is N(mean, diag(std²)) by construction; compare the weighted moments of a
    // large guided sample with it, within four Monte-Carlo standard errors of the sample's
    // effective size (mean: s/√ESS; variance: s²·√(2/ESS); covariance: s_a·s_b/√ESS).
    let t = term();
    let p = guided(200_000, 11);
    let e = ess(&p);
    assert!(e > 0.2 * 200_000.0, "ESS {e}");
    let mean = p.mean();
    let cov = p.covariance();
    for c in 0..4 {
        let s = t.std[c];
        assert!(
            (mean[c] - t.mean[c]).abs() < 4.0 * s / e.sqrt(),
            "mean {c}: {} vs {}",
            mean[c],
            t.mean[c]
        );
        let v = cov[(c, c)];
        assert!(
            (v - s * s).abs() < 4.0 * s * s * (2.0 / e).sqrt(),
            "variance {c}: {v} vs {}",
            s * s
        );
        for d in 0..c {
            let bound = 4.0 * s * t.std[d] / e.sqrt();
            assert!(
                cov[(c, d)].abs() < bound,
                "covariance {c},{d}: {}",
                cov[(c, d)]
            );
        }
    }
}

#[test]
fn guided_sample_puts_particles_at_the_unexplained_measurements() {
    // The prior puts ≈ 2.5·10⁻⁴ of its mass within 2 m of (90, 40); the proposal gives that
    // measurement's component (1 − 0.2) · 1/(1 + 0.5·pred ratio) of the particles.
    let p = guided(4000, 3);
    let (x, y) = (p.component(0), p.component(2));
    let near = x
        .iter()
        .zip(y)
        .filter(|(x, y)| (*x - 90.0).hypot(*y - 40.0) < 2.0)
        .count();
    assert!(near > 1000, "{near} of 4000 particles near the measurement");
}

#[test]
fn likelihood_integral_matches_the_closed_form() {
    // η = ∫ b(x) g(z | x) dx = N(z; H m, H P Hᵀ + R) for a Gaussian term and position
    // measurement: per axis N(z_k; m_k, 50² + 1²). Computed here from that formula.
    let t = term();
    let z = [90.0, 40.0];
    let var: f64 = 50.0 * 50.0 + 1.0;
    let exact: f64 = [(z[0] - t.mean[0]), (z[1] - t.mean[2])]
        .iter()
        .map(|d| (-0.5 * d * d / var).exp() / (2.0 * std::f64::consts::PI * var).sqrt())
        .product();
    let eta = |p: &ParticleSet| -> f64 {
        let (x, y) = (p.component(0), p.component(2));
        p.weights()
            .iter()
            .zip(x.iter().zip(y))
            .map(|(w, (x, y))| {
                let r2 = (x - z[0]).powi(2) + (y - z[1]).powi(2);
                w * (-0.5 * r2).exp() / (2.0 * std::f64::consts::PI)
            })
            .sum()
    };
    // 1000 particles per draw, 20 draws: every guided estimate within 10 %, whereas plain
    // sampling of the prior misses by far more in most draws.
    let mut plain_off = 0;
    for seed in 0..20 {
        let g = eta(&guided(1000, seed));
        assert!((g / exact - 1.0).abs() < 0.1, "seed {seed}: {g} vs {exact}");
        let plain = ParticleSet::sampled(&t.mean, &t.std, 1000, &mut seeded(seed));
        if (eta(&plain) / exact - 1.0).abs() > 0.1 {
            plain_off += 1;
        }
    }
    assert!(
        plain_off >= 15,
        "plain sampling within 10 % in {} of 20",
        20 - plain_off
    );
}

#[test]
fn weights_are_finite_positive_and_bounded_by_the_prior_share() {
    let p = guided(1000, 5);
    let n = p.len() as f64;
    assert!(p.weights().iter().all(|w| w.is_finite() && *w > 0.0));
    // Unnormalised weights b/q ≤ 1/0.2 = 5 and average ≈ 1, so normalised ones stay below
    // 5/n up to the sample's mean weight (within 20 % at this size).
    let max = p.weights().iter().copied().fold(0.0, f64::max);
    assert!(max * n <= 5.0 * 1.2, "largest weight {} × n", max * n);
}

#[test]
fn same_seed_same_sample() {
    assert_eq!(guided(500, 9), guided(500, 9));
    assert_ne!(guided(500, 9), guided(500, 10));
}

#[test]
fn without_usable_measurements_it_is_plain_prior_sampling() {
    let t = term();
    let plain = ParticleSet::sampled(&t.mean, &t.std, 300, &mut seeded(2));
    let z = far_measurements();
    // Every measurement explained by a track.
    let explained = CurrentMeasurements {
        measurements: &z,
        unexplained: &[0.0, 0.0],
    };
    assert_eq!(
        proposal().sample(&t, &explained, 300, &mut seeded(2)),
        plain
    );
    // A measurement far outside the term (6 predictive standard deviations).
    let far = Measurements::from_rows(2, &[[25.0 + 6.0 * 50.01, -25.0]]).unwrap();
    let current = CurrentMeasurements {
        measurements: &far,
        unexplained: &[],
    };
    assert_eq!(proposal().sample(&t, &current, 300, &mut seeded(2)), plain);
    // The prior share 1 never guides.
    let all_prior = proposal().with_prior_share(1.0).unwrap();
    let current = CurrentMeasurements {
        measurements: &z,
        unexplained: &[],
    };
    assert_eq!(all_prior.sample(&t, &current, 300, &mut seeded(2)), plain);
}

#[test]
fn bad_proposals_are_refused() {
    assert!(BirthProposal::new(vec![0, 0], vec![1.0, 1.0]).is_err());
    assert!(BirthProposal::new(vec![0, 2], vec![1.0]).is_err());
    assert!(BirthProposal::new(vec![0, 2], vec![1.0, 0.0]).is_err());
    assert!(BirthProposal::new(vec![0, 2], vec![1.0, f64::NAN]).is_err());
    assert!(proposal().with_prior_share(0.0).is_err());
    assert!(proposal().with_prior_share(1.5).is_err());
    let msg = BirthProposal::new(vec![0, 4], vec![1.0, 1.0])
        .unwrap()
        .check_state_dim(4)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("component 4"), "{msg}");
}

#[test]
fn converted_points_with_their_own_spread_keep_the_prior() {
    // Two points with different spreads (as range-bearing points at different ranges would
    // have); the weighted sample still has the prior's mean and variances, and the particles
    // drawn near the wide point spread as its conditional: sd = 50·8/√(50² + 8²) ≈ 7.90.
    let t = term();
    let pts = Measurements::from_rows(2, &[[90.0, 40.0], [-20.0, -75.0]]).unwrap();
    let noise = [0.5, 0.5, 8.0, 8.0];
    let p = proposal().sample_points(&t, &pts, &noise, &[], 100_000, &mut seeded(21));
    let e = ess(&p);
    let mean = p.mean();
    let sd = p.std_dev();
    for c in 0..4 {
        let s = t.std[c];
        assert!(
            (mean[c] - t.mean[c]).abs() < 4.0 * s / e.sqrt(),
            "mean {c}: {mean:?}"
        );
        assert!(
            (sd[c] * sd[c] - s * s).abs() < 4.0 * s * s * (2.0 / e).sqrt(),
            "sd {c}: {sd:?}"
        );
    }
    let (x, y) = (p.component(0), p.component(2));
    let near: Vec<f64> = x
        .iter()
        .zip(y)
        .filter(|(x, y)| (*x + 20.0).hypot(*y + 75.0) < 30.0)
        .map(|(x, _)| *x)
        .collect();
    assert!(near.len() > 10_000, "{} near the wide point", near.len());
    let m = near.iter().sum::<f64>() / near.len() as f64;
    let v = near.iter().map(|x| (x - m).powi(2)).sum::<f64>() / near.len() as f64;
    let expected = 50.0 * 8.0 / (50.0f64 * 50.0 + 64.0).sqrt();
    assert!(
        (v.sqrt() / expected - 1.0).abs() < 0.1,
        "sd {} vs {expected}",
        v.sqrt()
    );
    // A point whose spread is not usable gets no component: plain prior sampling.
    let bad = [f64::NAN, 1.0, 0.0, 1.0];
    let plain = ParticleSet::sampled(&t.mean, &t.std, 300, &mut seeded(2));
    assert_eq!(
        proposal().sample_points(&t, &pts, &bad, &[], 300, &mut seeded(2)),
        plain
    );
}
