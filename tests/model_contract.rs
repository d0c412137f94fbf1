//! The contract between the filter and its models is checked: building a filter compares the
//! dimensions of the transition, the measurement model and the birth model and names both
//! models of a mismatch; every built-in transition handed a state that is too short returns an
//! error (never leaves the set as it was); a birth of the wrong length is an error of the step;
//! public constructors refuse bad input with an error instead of a panic.

use smc_lmb::filter::{
    AdaptiveBirth, BirthTerm, Frame, LmbConfig, LmbFilter, LmbFilterBuilder, Measurements,
    ParticleSet, PositionBirthSampler, StaticBirth, StepContext, TransitionModel,
};
use smc_lmb::models::plane::EgoSource;
use smc_lmb::models::{
    ConstantDetection, ConstantVelocity, CoordinatedTurn, ExtendedConstantTurn, PlaneTransition,
    PositionMeasurement, UniformClutter,
};
use smc_lmb::rng::seeded;
use smc_lmb::FilterRng;

fn parts(transition: impl TransitionModel + 'static, dims: usize) -> LmbFilterBuilder {
    LmbFilter::builder()
        .transition(transition)
        .measurement(PositionMeasurement::new(dims, 0.3).unwrap())
        .detection(ConstantDetection::new(0.9).unwrap())
        .clutter(UniformClutter::rectangle(1.0, [-50.0, 50.0], [-50.0, 50.0]).unwrap())
        .config(LmbConfig {
            particles: 200,
            ..LmbConfig::default()
        })
}

fn position_birth() -> AdaptiveBirth {
    AdaptiveBirth::new(
        PositionBirthSampler {
            position_std: 0.3,
            velocity_std: 2.0,
        },
        0.1,
        0.1,
        200,
    )
    .unwrap()
}

fn error_of(b: LmbFilterBuilder) -> String {
    match b.build() {
        Ok(_) => panic!("the filter was built"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_transition_longer_than_the_births_is_refused_naming_both() {
    // The coordinated turn moves [x, ẋ, y, ẏ, ω]; the position birth draws [x, ẋ, y, ẏ].
    let e = error_of(parts(CoordinatedTurn::new(0.5, 0.1).unwrap(), 2).birth(position_birth()));
    for part in [
        "CoordinatedTurn",
        "PositionBirthSampler",
        "of 4 components",
        "of 5",
    ] {
        assert!(e.contains(part), "{part:?} missing from: {e}");
    }
    // the same parts with a constant-velocity transition build
    parts(ConstantVelocity::planar(0.5).unwrap(), 2)
        .birth(position_birth())
        .build()
        .unwrap();
}

#[test]
fn a_measurement_reading_more_than_the_state_is_refused_naming_both() {
    // A 3-D position (components 0, 2, 4) against a planar constant velocity (4 components);
    // the birth states are 3-D too, so the birth check alone would not see it.
    let static_birth = StaticBirth::new(
        vec![BirthTerm {
            existence: 0.1,
            mean: vec![0.0; 4],
            std: vec![1.0; 4],
        }],
        100,
    )
    .unwrap();
    let e = error_of(parts(ConstantVelocity::planar(0.5).unwrap(), 3).birth(static_birth));
    for part in [
        "PositionMeasurement",
        "ConstantVelocity",
        "5 components",
        "of 4",
    ] {
        assert!(e.contains(part), "{part:?} missing from: {e}");
    }
}

#[test]
fn static_birth_terms_of_different_lengths_are_refused() {
    let term = |d: usize| BirthTerm {
        existence: 0.1,
        mean: vec![0.0; d],
        std: vec![1.0; d],
    };
    let e = StaticBirth::new(vec![term(4), term(5)], 100)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("birth term 1") && e.contains("5 components"),
        "{e}"
    );
}

#[test]
fn every_built_in_transition_refuses_a_short_state() {
    let ctx = StepContext::new(1, 0.1, 0.1);
    let models: Vec<(Box<dyn TransitionModel>, &str, usize)> = vec![
        (
            Box::new(ConstantVelocity::planar(0.5).unwrap()),
            "ConstantVelocity",
            4,
        ),
        (
            Box::new(ConstantVelocity::spatial(0.5).unwrap()),
            "ConstantVelocity",
            6,
        ),
        (
            Box::new(CoordinatedTurn::new(0.5, 0.1).unwrap()),
            "CoordinatedTurn",
            5,
        ),
        (
            Box::new(ExtendedConstantTurn::new(0.5, 0.1).unwrap()),
            "ExtendedConstantTurn",
            6,
        ),
        (
            Box::new(PlaneTransition::new(EgoSource::Measured, 0.01, 0.01).unwrap()),
            "PlaneTransition",
            4,
        ),
    ];
    for (model, name, dim) in models {
        assert_eq!(model.state_dim(), dim);
        assert_eq!(model.name(), name);
        let short = vec![vec![1.0; dim - 1]; 3];
        let mut set = ParticleSet::from_rows(&short, &[1.0; 3]).unwrap();
        let before = set.clone();
        let e = model
            .predict(&mut set, &ctx, &mut seeded(1))
            .expect_err(name)
            .to_string();
        assert!(
            e.contains(name) && e.contains(&format!("{} components", dim - 1)),
            "{e}"
        );
        assert!(e.contains(&format!("states of {dim}")), "{e}");
        assert_eq!(set, before, "{name} changed the set it refused");
        // the right length (and a longer one: extra components are kept) is fine
        for d in [dim, dim + 1] {
            let mut ok = ParticleSet::from_rows(&vec![vec![0.5; d]; 3], &[1.0; 3]).unwrap();
            model.predict(&mut ok, &ctx, &mut seeded(1)).unwrap();
        }
    }
}

#[test]
fn a_birth_of_the_wrong_length_is_an_error_of_the_step() {
    // A closure sampler cannot tell its dimension when the filter is built: the step refuses
    // the 3-component states it draws for the 4-component transition.
    let sampler = |z: &[f64], _: &StepContext, n: usize, rng: &mut FilterRng| {
        ParticleSet::gaussian(&[z[0], 0.0, z[1]], &[0.1; 3], n, rng).unwrap()
    };
    let mut filter = parts(ConstantVelocity::planar(0.5).unwrap(), 2)
        .birth(AdaptiveBirth::new(sampler, 0.1, 0.1, 100).unwrap())
        .build()
        .unwrap();
    let mut rng = seeded(3);
    let z = Measurements::from_rows(2, &[[1.0, 2.0]]).unwrap();
    filter.step(&Frame::new(0.0, z.clone()), &mut rng).unwrap();
    let e = filter
        .step(&Frame::new(1.0, z), &mut rng)
        .unwrap_err()
        .to_string();
    for part in ["birth", "3 components", "ConstantVelocity", "states of 4"] {
        assert!(e.contains(part), "{part:?} missing from: {e}");
    }
}

#[test]
fn particle_set_constructors_refuse_bad_input() {
    let mut rng = seeded(1);
    assert!(ParticleSet::zeros(0, 5).is_err());
    assert!(ParticleSet::zeros(3, usize::MAX).is_err());
    assert_eq!(ParticleSet::zeros(3, 5).unwrap().len(), 5);
    let e = ParticleSet::gaussian(&[0.0, 1.0], &[1.0], 10, &mut rng).unwrap_err();
    assert!(e.to_string().contains("2 components"), "{e}");
    let e = ParticleSet::gaussian(&[0.0, f64::NAN], &[1.0, 1.0], 10, &mut rng).unwrap_err();
    assert!(e.to_string().contains("component 1"), "{e}");
    let e = ParticleSet::gaussian(&[0.0, 0.0], &[1.0, -1.0], 10, &mut rng).unwrap_err();
    assert!(e.to_string().contains("non-negative"), "{e}");
    assert!(ParticleSet::gaussian(&[], &[], 10, &mut rng).is_err());
    assert_eq!(
        ParticleSet::gaussian(&[1.0], &[0.0], 4, &mut rng)
            .unwrap()
            .component(0),
        &[1.0; 4]
    );
}
