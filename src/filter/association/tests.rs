//! Tests that hold every association method to the same conventions (the list in the
//! module documentation), side by side on the same problems.
//!
//! Not for: tests of one method's own behaviour (next to that method) or of the problem and
//! marginal types (in `problem.rs`) or of method parsing (in `method.rs`).

use super::testutil::*;
use super::*;
use crate::rng::seeded;
use proptest::prelude::*;

fn all_methods() -> Vec<AssociationMethod> {
    vec![
        AssociationMethod::Murty {
            k: 1000,
            min_weight: 0.0,
        },
        AssociationMethod::Gibbs { samples: 500 },
        AssociationMethod::default(),
        AssociationMethod::Exhaustive,
    ]
}

#[test]
fn trivial_groups_are_exact_for_every_method() {
    let mut rng = seeded(1);
    // One track: φ normalised. Weights 1, 2, 0 (forbidden), 5 scaled by e^-700.
    let p = AssociationProblem::new(
        1,
        3,
        vec![-700.0],
        vec![-700.0 + 2f64.ln(), f64::NEG_INFINITY, -700.0 + 5f64.ln()],
    )
    .unwrap();
    for method in all_methods() {
        let mg = method.marginals(&p, &mut rng);
        // −700 + ln 2 is only represented to about 1e−13.
        assert!((mg.miss[0] - 0.125).abs() < 1e-12, "{method:?}");
        assert!((mg.detect[0] - 0.25).abs() < 1e-12);
        assert_eq!(mg.detect[1], 0.0);
        assert!((mg.detect[2] - 0.625).abs() < 1e-12);
    }
    // No measurements: everything missed.
    let p = AssociationProblem::new(3, 0, vec![-1.0, -2.0, -3.0], vec![]).unwrap();
    for method in all_methods() {
        assert_eq!(method.marginals(&p, &mut rng), Marginals::all_missed(3, 0));
    }
    // No tracks.
    let p = AssociationProblem::new(0, 2, vec![], vec![]).unwrap();
    for method in all_methods() {
        assert_eq!(method.marginals(&p, &mut rng), Marginals::all_missed(0, 2));
    }
}

#[test]
fn infeasible_and_malformed_give_all_missed() {
    let mut rng = seeded(2);
    let ninf = f64::NEG_INFINITY;
    // Both tracks must be detected but only measurement 0 is allowed for either.
    let p = AssociationProblem::new(2, 2, vec![ninf, ninf], vec![0.0, ninf, -1.0, ninf]).unwrap();
    // A row with nothing admissible.
    let q = AssociationProblem::new(2, 1, vec![0.0, ninf], vec![0.0, ninf]).unwrap();
    let malformed = AssociationProblem {
        n_tracks: 2,
        n_meas: 2,
        log_miss: vec![0.0],
        log_detect: vec![0.0; 3],
    };
    for method in all_methods() {
        assert_eq!(method.marginals(&p, &mut rng), Marginals::all_missed(2, 2));
        assert_eq!(method.marginals(&q, &mut rng), Marginals::all_missed(2, 1));
        assert_eq!(
            method.marginals(&malformed, &mut rng),
            Marginals::all_missed(2, 2)
        );
    }
}

#[test]
fn underflowing_weights_give_normalised_marginals() {
    use rand::RngExt;
    let mut gen = seeded(4);
    for round in 0..20 {
        let (n, m) = (3, 3);
        let base: Vec<f64> = (0..n * (m + 1))
            .map(|_| -20.0 * gen.random::<f64>())
            .collect();
        // The same problem at three scales; e^−1000 and e^−100000 underflow in f64.
        for shift in [0.0, -1000.0, -1e5] {
            let p = AssociationProblem::new(
                n,
                m,
                base[..n].iter().map(|v| v + shift).collect(),
                base[n..].iter().map(|v| v + shift).collect(),
            )
            .unwrap();
            let exact = brute_marginals(&p).unwrap();
            for method in all_methods() {
                let mut rng = seeded(round);
                let mg = method.marginals(&p, &mut rng);
                assert_valid(&p, &mg);
                let err = max_diff(&mg, &exact);
                match method {
                    AssociationMethod::Murty { .. } | AssociationMethod::Exhaustive => {
                        // The reference itself sums log weights of size ~3·10⁵ at the
                        // largest shift, which costs about 10⁻¹⁰.
                        let tol = if shift < -1e4 { 1e-9 } else { 1e-12 };
                        assert!(err < tol, "{method:?} {shift}: {err}");
                    }
                    AssociationMethod::Gibbs { samples } => {
                        // Off by at most the mass of the hypotheses never visited.
                        let visited = distinct_hypotheses(&p, samples, &mut seeded(round));
                        let all = brute_hypotheses(&p);
                        let max = all.iter().map(|h| h.1).fold(f64::NEG_INFINITY, f64::max);
                        let z: f64 = all.iter().map(|h| (h.1 - max).exp()).sum();
                        let seen: f64 = visited.iter().map(|h| (h.log_weight - max).exp()).sum();
                        assert!(err <= 1.0 - seen / z + 1e-9, "{err}");
                    }
                    AssociationMethod::Lbp { .. } => {
                        // Scale-free: the same answer as the unshifted problem.
                        let q =
                            AssociationProblem::new(n, m, base[..n].to_vec(), base[n..].to_vec())
                                .unwrap();
                        let unshifted = method.marginals(&q, &mut rng);
                        assert!(max_diff(&mg, &unshifted) < 1e-9);
                    }
                }
            }
        }
    }
}

#[test]
fn forced_detection_and_forbidden_pairs() {
    // Track 0 must take measurement 0 (its only admissible option), so track 1 — which
    // could take measurement 0 — must miss or take measurement 1.
    let ninf = f64::NEG_INFINITY;
    let p = AssociationProblem::new(2, 2, vec![ninf, -1.0], vec![-2.0, ninf, 0.0, -0.5]).unwrap();
    // Hypotheses: (1, 0) with weight e^(-2-1) and (1, 2) with weight e^(-2-0.5).
    let a = (-3.0f64).exp();
    let b = (-2.5f64).exp();
    let mut rng = seeded(5);
    for method in all_methods() {
        let mg = method.marginals(&p, &mut rng);
        assert_valid(&p, &mg);
        assert_eq!(mg.miss[0], 0.0);
        assert_eq!(mg.detect[1], 0.0);
        if !matches!(method, AssociationMethod::Lbp { .. }) {
            assert_eq!(mg.detect[2], 0.0, "{method:?}");
            assert!((mg.miss[1] - a / (a + b)).abs() < 1e-12);
            assert!((mg.detect[3] - b / (a + b)).abs() < 1e-12);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn every_method_gives_valid_marginals(p in problems(5, 5, -30.0, 10.0, 4, true)) {
        let mut rng = seeded(6);
        for method in all_methods() {
            let mg = method.marginals(&p, &mut rng);
            assert_valid(&p, &mg);
            if brute_hypotheses(&p).is_empty() {
                prop_assert_eq!(mg, Marginals::all_missed(p.n_tracks, p.n_meas));
            }
        }
    }
}
