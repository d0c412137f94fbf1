//! Invariants of the recursion under arbitrary frames: existence probabilities stay in [0, 1],
//! labels stay unique, weights stay normalised, particle sets never empty, and estimates are
//! drawn from the tracks.

use proptest::prelude::*;
use smc_lmb::filter::{
    AdaptiveBirth, AssociationMethod, Frame, LmbConfig, LmbFilter, Measurements,
    PositionBirthSampler, StepData,
};
use smc_lmb::models::{ConstantDetection, ConstantVelocity, PositionMeasurement, UniformClutter};
use smc_lmb::rng::seeded;
use std::collections::HashSet;

fn filter(assoc: AssociationMethod, pd: f64) -> LmbFilter {
    filter_detecting(assoc, ConstantDetection(pd))
}

fn filter_detecting(
    assoc: AssociationMethod,
    detection: impl smc_lmb::filter::DetectionModel + 'static,
) -> LmbFilter {
    LmbFilter::builder()
        .transition(ConstantVelocity::new(2, 1.0).unwrap())
        .measurement(PositionMeasurement::new(2, 1.0).unwrap())
        .detection(detection)
        .clutter(UniformClutter::rectangle(2.0, [-50.0, 50.0], [-50.0, 50.0]).unwrap())
        .birth(
            AdaptiveBirth::new(
                PositionBirthSampler {
                    position_std: 1.0,
                    velocity_std: 2.0,
                },
                0.5,
                0.3,
                64,
            )
            .unwrap(),
        )
        .associator(assoc)
        .config(LmbConfig {
            particles: 64,
            max_tracks: 12,
            ..LmbConfig::default()
        })
        .build()
        .unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]
    #[test]
    fn recursion_keeps_its_invariants(
        frames in proptest::collection::vec(proptest::collection::vec((-60.0f64..60.0, -60.0f64..60.0), 0..12), 1..10),
        method in 0usize..3,
        pd in prop_oneof![Just(1.0), 0.05f64..0.99],
        seed in 0u64..1000,
    ) {
        let assoc = ["lbp", "murty:20", "gibbs:50"][method].parse().unwrap();
        let mut f = filter(assoc, pd);
        let mut rng = seeded(seed);
        for (k, zs) in frames.iter().enumerate() {
            let rows: Vec<[f64; 2]> = zs.iter().map(|&(x, y)| [x, y]).collect();
            let est = f.step(&Frame::new(k as f64 * 0.5, Measurements::from_rows(2, &rows).unwrap()), &mut rng).unwrap();
            let tracks = f.tracks();
            prop_assert!(tracks.len() <= 12);
            let labels: HashSet<_> = tracks.iter().map(|t| t.label).collect();
            prop_assert_eq!(labels.len(), tracks.len(), "labels unique");
            for t in tracks {
                prop_assert!((0.0..=1.0).contains(&t.existence), "r = {}", t.existence);
                prop_assert_eq!(t.particles.len(), 64);
                let s: f64 = t.particles.weights().iter().sum();
                prop_assert!((s - 1.0).abs() < 1e-9);
                prop_assert!(t.particles.component(0).iter().all(|x| x.is_finite()));
            }
            for e in &est {
                prop_assert!(labels.contains(&e.label));
                prop_assert!(e.state.iter().all(|x| x.is_finite()));
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]
    /// A step split into its prediction and its update (what a caller does to predict while the
    /// measurements are being made) is the same step: the same estimates and the same tracks
    /// to the last bit, empty frames included.
    #[test]
    fn a_step_in_two_halves_is_the_same_step(
        frames in proptest::collection::vec(proptest::collection::vec((-60.0f64..60.0, -60.0f64..60.0), 0..8), 1..8),
        seed in 0u64..1000,
    ) {
        let (mut whole, mut halves) = (filter(AssociationMethod::default(), 0.9), filter(AssociationMethod::default(), 0.9));
        let (mut rng_a, mut rng_b) = (seeded(seed), seeded(seed));
        for (k, zs) in frames.iter().enumerate() {
            let rows: Vec<[f64; 2]> = zs.iter().map(|&(x, y)| [x, y]).collect();
            let z = Measurements::from_rows(2, &rows).unwrap();
            let t = k as f64 * 0.5;
            let a = whole.step(&Frame::new(t, z.clone()), &mut rng_a).unwrap();
            halves.predict_step(t, None, StepData::new(), &mut rng_b).unwrap();
            let b = halves.update_step(&z).unwrap();
            prop_assert_eq!(a.len(), b.len());
            for (ea, eb) in a.iter().zip(&b) {
                prop_assert_eq!(ea.label, eb.label);
                prop_assert_eq!(&ea.state, &eb.state);
            }
            prop_assert_eq!(whole.tracks().len(), halves.tracks().len());
            for (ta, tb) in whole.tracks().iter().zip(halves.tracks()) {
                prop_assert_eq!(ta.label, tb.label);
                prop_assert_eq!(ta.existence, tb.existence);
                prop_assert_eq!(ta.particles.weights(), tb.particles.weights());
                for c in 0..ta.particles.dim() {
                    prop_assert_eq!(ta.particles.component(c), tb.particles.component(c));
                }
            }
        }
    }
}

#[test]
fn halves_out_of_order_are_errors_that_change_nothing() {
    let mut f = filter(AssociationMethod::default(), 0.9);
    let mut rng = seeded(3);
    let z = Measurements::from_rows(2, &[[1.0, 2.0]]).unwrap();
    let err = f.update_step(&z).unwrap_err().to_string();
    assert!(err.contains("not predicted"), "{err}");
    f.predict_step(0.0, None, StepData::new(), &mut rng)
        .unwrap();
    let err = f
        .predict_step(0.5, None, StepData::new(), &mut rng)
        .unwrap_err()
        .to_string();
    assert!(err.contains("predicted already"), "{err}");
    let err = f
        .step(&Frame::new(0.5, z.clone()), &mut rng)
        .unwrap_err()
        .to_string();
    assert!(err.contains("predicted already"), "{err}");
    // Measurements of the wrong dimension leave the prediction pending.
    let wrong = Measurements::from_rows(3, &[[1.0, 2.0, 3.0]]).unwrap();
    let err = f.update_step(&wrong).unwrap_err().to_string();
    assert!(err.contains("dimension 3"), "{err}");
    f.update_step(&z).unwrap();
    assert_eq!(f.steps(), 1);
    // A reset forgets a pending prediction.
    f.predict_step(0.5, None, StepData::new(), &mut rng)
        .unwrap();
    f.reset();
    f.predict_step(0.0, None, StepData::new(), &mut rng)
        .unwrap();
    f.update_step(&z).unwrap();
}

/// Data handed with the update reaches the update's models: a detection model that reads a
/// p_D from the step data, handed only with `update_step_with`, decides how much a missed
/// track's existence falls (the LMB's missed-detection update r(1 − p_D) / (1 − r p_D)).
#[test]
fn data_handed_with_the_update_reaches_its_models() {
    use smc_lmb::filter::{DetectionModel, ParticleSet, StepContext};
    #[derive(Clone, Debug)]
    struct SeenShare(f64);
    #[derive(Clone, Debug)]
    struct ShareDetection;
    impl DetectionModel for ShareDetection {
        fn detection_probability(&self, p: &ParticleSet, ctx: &StepContext, out: &mut [f64]) {
            let pd = ctx.data.get::<SeenShare>().map_or(0.9, |s| s.0);
            out[..p.len()].fill(pd);
        }
    }
    let build = || filter_detecting(AssociationMethod::default(), ShareDetection);
    let z = Measurements::from_rows(2, &[[1.0, 2.0]]).unwrap();
    let none = Measurements::empty(2);
    let mut existence = Vec::new();
    for hidden in [None, Some(0.1)] {
        let mut f = build();
        let mut rng = seeded(5);
        f.step(&Frame::new(0.0, z.clone()), &mut rng).unwrap();
        f.step(&Frame::new(0.1, z.clone()), &mut rng).unwrap();
        let before = f.tracks()[0].existence;
        f.predict_step(0.2, None, StepData::new(), &mut rng)
            .unwrap();
        let data = hidden.map_or_else(StepData::new, |pd| StepData::new().with(SeenShare(pd)));
        f.update_step_with(&none, data).unwrap();
        let after = f.tracks()[0].existence;
        existence.push((before, after));
    }
    // Both steps predict the same track to the same existence r; the miss maps it to
    // r' = r (1 − p_D) / (1 − r p_D), so r = r' / (1 − p_D + r' p_D) is the same from both.
    let ((b0, a0), (b1, a1)) = (existence[0], existence[1]);
    assert_eq!(b0, b1);
    let r = |pd: f64, a: f64| a / (1.0 - pd + a * pd);
    let implied = [r(0.9, a0), r(0.1, a1)];
    assert!(
        (implied[0] - implied[1]).abs() < 1e-9 * implied[0].max(1e-12),
        "{implied:?} from {existence:?}"
    );
    assert!(a1 > a0, "{existence:?}");
}
