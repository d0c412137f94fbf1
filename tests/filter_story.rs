//! Whole-filter stories on small hand-built scenes: a target is found, followed and released;
//! the same seed gives identical results at any thread count; hostile frames do not break it.

use rand::RngExt;
use smc_lmb::filter::{
    AdaptiveBirth, AssociationMethod, BirthTerm, Frame, LmbConfig, LmbFilter, Measurements,
    PositionBirthSampler, StaticBirth,
};
use smc_lmb::models::{ConstantDetection, ConstantVelocity, PositionMeasurement, UniformClutter};
use smc_lmb::rng::seeded;

/// Two targets on straight lines, position measurements (σ = 1 m), p_D = 0.95, 5 clutter
/// points a frame on [−100, 100]²; target A lives for all 30 steps, B from step 5 to 24.
fn scene(seed: u64) -> Vec<(Frame, Vec<[f64; 2]>)> {
    let mut rng = seeded(seed);
    (0..30)
        .map(|k| {
            let t = k as f64;
            let mut truth = vec![[-50.0 + 2.0 * t, 10.0]];
            if (5..25).contains(&k) {
                truth.push([20.0, 60.0 - 3.0 * (t - 5.0)]);
            }
            let mut z: Vec<[f64; 2]> = Vec::new();
            for p in &truth {
                if rng.random::<f64>() < 0.95 {
                    let nx: f64 =
                        rand_distr::Distribution::sample(&rand_distr::StandardNormal, &mut rng);
                    let ny: f64 =
                        rand_distr::Distribution::sample(&rand_distr::StandardNormal, &mut rng);
                    z.push([p[0] + nx, p[1] + ny]);
                }
            }
            for _ in 0..5 {
                z.push([
                    rng.random_range(-100.0..100.0),
                    rng.random_range(-100.0..100.0),
                ]);
            }
            (
                Frame::new(t, Measurements::from_rows(2, &z).unwrap()),
                truth,
            )
        })
        .collect()
}

fn adaptive_filter(assoc: AssociationMethod) -> LmbFilter {
    adaptive_filter_with(
        assoc,
        LmbConfig {
            particles: 500,
            ..LmbConfig::default()
        },
    )
}

fn adaptive_filter_with(assoc: AssociationMethod, config: LmbConfig) -> LmbFilter {
    LmbFilter::builder()
        .transition(ConstantVelocity::new(2, 0.5).unwrap())
        .measurement(PositionMeasurement::new(2, 1.0).unwrap())
        .detection(ConstantDetection(0.95))
        .clutter(UniformClutter::rectangle(5.0, [-100.0, 100.0], [-100.0, 100.0]).unwrap())
        .birth(
            AdaptiveBirth::new(
                PositionBirthSampler {
                    position_std: 1.0,
                    velocity_std: 3.0,
                },
                0.1,
                0.05,
                500,
            )
            .unwrap(),
        )
        .associator(assoc)
        .config(config)
        .build()
        .unwrap()
}

fn run(
    filter: &mut LmbFilter,
    frames: &[(Frame, Vec<[f64; 2]>)],
    seed: u64,
) -> Vec<Vec<smc_lmb::filter::Estimate>> {
    let mut rng = seeded(seed);
    frames
        .iter()
        .map(|(f, _)| filter.step(f, &mut rng).unwrap())
        .collect()
}

#[test]
fn adaptive_birth_finds_follows_and_releases_two_targets() {
    for assoc in ["lbp", "murty", "gibbs"] {
        let frames = scene(11);
        let mut filter = adaptive_filter(assoc.parse().unwrap());
        let est = run(&mut filter, &frames, 5);
        // After a short confirmation delay the cardinality is right and positions are close.
        let good = frames_right(&est, &frames);
        assert!(good >= 20, "{assoc}: only {good} of 22 frames right");
        // Target A keeps one label from step 3 to the end.
        let label_a: std::collections::BTreeSet<_> = est[3..]
            .iter()
            .zip(&frames[3..])
            .flat_map(|(e, (_, truth))| {
                let a = truth[0];
                e.iter()
                    .filter(move |x| {
                        ((x.state[0] - a[0]).powi(2) + (x.state[2] - a[1]).powi(2)).sqrt() < 3.0
                    })
                    .map(|x| x.label)
            })
            .collect();
        assert_eq!(label_a.len(), 1, "{assoc}: target A had labels {label_a:?}");
    }
}

/// How many targets of the scene an estimate set gets right (within 3 m, right cardinality),
/// over the frames where births and deaths have had time to show.
fn frames_right(
    est: &[Vec<smc_lmb::filter::Estimate>],
    frames: &[(Frame, Vec<[f64; 2]>)],
) -> usize {
    est.iter()
        .zip(frames)
        .enumerate()
        .filter(|(k, _)| !(*k < 3 || (5..8).contains(k) || (25..27).contains(k)))
        .filter(|(_, (e, (_, truth)))| {
            e.len() == truth.len()
                && truth.iter().all(|t| {
                    e.iter().any(|x| {
                        ((x.state[0] - t[0]).powi(2) + (x.state[2] - t[1]).powi(2)).sqrt() < 3.0
                    })
                })
        })
        .count()
}

#[test]
fn particles_follow_existence_when_scaled() {
    let frames = scene(11);
    let config = LmbConfig {
        particles: 500,
        min_particles: Some(40),
        ..LmbConfig::default()
    };
    let mut filter = adaptive_filter_with(AssociationMethod::default(), config);
    let mut rng = seeded(5);
    let (mut scaled, mut fixed) = (0usize, 0usize);
    let mut est = Vec::new();
    for (f, _) in &frames {
        est.push(filter.step(f, &mut rng).unwrap());
        for t in filter.tracks() {
            // Resampling leaves every track within a factor of two of max(40, ⌈500 r⌉).
            let target = ((500.0 * t.existence).ceil() as usize).clamp(40, 500);
            let n = t.particles.len();
            assert!(
                2 * n >= target && n <= 2 * target,
                "track {} with r = {:.3}: {n} particles for a target of {target}",
                t.label,
                t.existence
            );
            scaled += n;
            fixed += 500;
        }
    }
    // The clutter's unlikely tracks are cheap, and the targets are found as well as with a
    // fixed count (the fixed-count story asks for 20 of 22 frames).
    assert!(
        (scaled as f64) < 0.8 * fixed as f64,
        "{scaled} particle-steps against {fixed} with a fixed count"
    );
    let good = frames_right(&est, &frames);
    assert!(good >= 20, "only {good} of 22 frames right");
    // 0 is refused; more than `particles` is `particles`.
    let err = LmbConfig {
        particles: 500,
        min_particles: Some(0),
        ..LmbConfig::default()
    }
    .validate()
    .unwrap_err();
    assert!(err.to_string().contains("min_particles"), "{err}");
    let above = LmbConfig {
        particles: 50,
        min_particles: Some(200),
        ..LmbConfig::default()
    };
    assert!(above.validate().is_ok());
    let mut filter = adaptive_filter_with(AssociationMethod::default(), above);
    let mut rng = seeded(5);
    for (f, _) in &frames[..5] {
        filter.step(f, &mut rng).unwrap();
        assert!(filter.tracks().iter().all(|t| t.particles.len() == 50));
    }
}

#[test]
fn capped_tracks_carry_fewer_particles_until_the_cap_is_lifted() {
    let frames = scene(11);
    let config = LmbConfig {
        particles: 500,
        ..LmbConfig::default()
    };
    let mut filter = adaptive_filter_with(AssociationMethod::default(), config);
    let mut rng = seeded(5);
    for (f, _) in &frames[..6] {
        filter.step(f, &mut rng).unwrap();
    }
    // Cap the most certain track; the others keep their fixed count.
    let capped = filter
        .tracks()
        .iter()
        .max_by(|a, b| a.existence.total_cmp(&b.existence))
        .map(|t| t.label)
        .expect("tracks after six frames");
    filter.set_particle_caps(std::collections::HashMap::from([(capped, 60)]));
    let mut est = Vec::new();
    for (f, _) in &frames[6..12] {
        est.push(filter.step(f, &mut rng).unwrap());
        for t in filter.tracks() {
            let expected = if t.label == capped { 60 } else { 500 };
            assert_eq!(t.particles.len(), expected, "track {}", t.label);
        }
    }
    // The capped track is still followed.
    assert!(est.iter().all(|e| e.iter().any(|x| x.label == capped)));
    // Lifted: back to the configured count at the next resampling.
    filter.set_particle_caps(std::collections::HashMap::new());
    filter.step(&frames[12].0, &mut rng).unwrap();
    assert!(filter.tracks().iter().all(|t| t.particles.len() == 500));
}

#[test]
fn same_seed_same_estimates_at_one_and_two_threads() {
    let frames = scene(3);
    let go = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut f = adaptive_filter(AssociationMethod::default());
            let est = run(&mut f, &frames, 99);
            (est, f.tracks().to_vec())
        })
    };
    let (e1, t1) = go(1);
    let (e2, t2) = go(2);
    assert_eq!(e1, e2);
    assert_eq!(t1, t2, "track particle sets differ between thread counts");
    let (e3, _) = go(2);
    assert_eq!(e1, e3);
}

#[test]
fn hostile_frames_do_not_break_the_filter() {
    let mut filter = LmbFilter::builder()
        .transition(ConstantVelocity::new(2, 1.0).unwrap())
        .measurement(PositionMeasurement::new(2, 1.0).unwrap())
        .detection(ConstantDetection(0.9))
        .clutter(UniformClutter::rectangle(500.0, [-1000.0, 1000.0], [-1000.0, 1000.0]).unwrap())
        .birth(
            StaticBirth::new(
                vec![BirthTerm {
                    existence: 0.1,
                    mean: vec![0.0; 4],
                    std: vec![10.0, 1.0, 10.0, 1.0],
                }],
                200,
            )
            .unwrap(),
        )
        .config(LmbConfig {
            particles: 200,
            ..LmbConfig::default()
        })
        .build()
        .unwrap();
    let mut rng = seeded(1);
    // empty frame at the start
    filter
        .step(&Frame::new(0.0, Measurements::empty(2)), &mut rng)
        .unwrap();
    // hundreds of clutter points
    let z: Vec<[f64; 2]> = (0..600)
        .map(|i| {
            [
                (i as f64 * 3.7) % 2000.0 - 1000.0,
                (i as f64 * 7.3) % 2000.0 - 1000.0,
            ]
        })
        .collect();
    filter
        .step(
            &Frame::new(1.0, Measurements::from_rows(2, &z).unwrap()),
            &mut rng,
        )
        .unwrap();
    // a measurement so far from every particle that all likelihoods underflow
    let far = Measurements::from_rows(2, &[[1e6, -1e6]]).unwrap();
    filter.step(&Frame::new(2.0, far), &mut rng).unwrap();
    for t in filter.tracks() {
        assert!(t.existence.is_finite() && (0.0..=1.0).contains(&t.existence));
        assert!(!t.particles.is_empty());
        assert!(t.particles.weights().iter().all(|w| w.is_finite()));
    }
    // time going backwards and wrong dimensions are errors, not panics
    let err = filter
        .step(&Frame::new(1.0, Measurements::empty(2)), &mut rng)
        .unwrap_err();
    assert!(err.to_string().contains("backwards"), "{err}");
    let err = filter
        .step(
            &Frame::new(3.0, Measurements::from_rows(3, &[[0.0; 3]]).unwrap()),
            &mut rng,
        )
        .unwrap_err();
    assert!(err.to_string().contains("dimension"), "{err}");
    let err = filter
        .step(&Frame::new(f64::NAN, Measurements::empty(2)), &mut rng)
        .unwrap_err();
    assert!(err.to_string().contains("not finite"), "{err}");
}

#[test]
fn missing_models_and_bad_config_are_named() {
    let err = LmbFilter::builder().build().err().unwrap();
    assert!(err.to_string().contains("transition"));
    let err = LmbFilter::builder()
        .transition(ConstantVelocity::new(2, 1.0).unwrap())
        .config(LmbConfig {
            prune_threshold: f64::NAN,
            ..LmbConfig::default()
        })
        .build()
        .err()
        .unwrap();
    assert!(err.to_string().contains("prune_threshold"), "{err}");
}

/// Two birth terms on one object: without merging both tracks live on, sharing its
/// detections; with [`LmbConfig::merge_threshold`] they become one track that holds their
/// summed existence, and a second object 8 m away keeps its own track.
#[test]
fn duplicate_tracks_of_one_object_are_merged() {
    let filter_with = |merge: Option<f64>| {
        let term = |x: f64, y: f64| BirthTerm {
            existence: 0.3,
            mean: vec![x, 0.0, y, 0.0],
            std: vec![0.5, 0.3, 0.5, 0.3],
        };
        LmbFilter::builder()
            .transition(ConstantVelocity::new(2, 0.5).unwrap())
            .measurement(PositionMeasurement::new(2, 0.5).unwrap())
            .detection(ConstantDetection(0.9))
            .clutter(UniformClutter::rectangle(1.0, [-50.0, 50.0], [-50.0, 50.0]).unwrap())
            .birth(
                StaticBirth::new(vec![term(0.0, 0.0), term(0.2, 0.1), term(8.0, 0.0)], 500)
                    .unwrap(),
            )
            .config(LmbConfig {
                particles: 500,
                merge_threshold: merge,
                ..LmbConfig::default()
            })
            .build()
            .unwrap()
    };
    let frame = Frame::new(
        0.0,
        Measurements::from_rows(2, &[[0.1, 0.0], [8.0, 0.1]]).unwrap(),
    );
    let near_origin = |f: &LmbFilter| {
        f.tracks()
            .iter()
            .filter(|t| t.particles.mean()[0].abs() < 1.0)
            .map(|t| t.existence)
            .collect::<Vec<_>>()
    };
    let mut plain = filter_with(None);
    plain.step(&frame, &mut seeded(3)).unwrap();
    let apart = near_origin(&plain);
    assert_eq!(apart.len(), 2, "{apart:?}");
    let mut merging = filter_with(Some(9.0));
    merging.step(&frame, &mut seeded(3)).unwrap();
    let one = near_origin(&merging);
    assert_eq!(one.len(), 1, "{one:?}");
    assert!(
        (one[0] - (apart[0] + apart[1]).min(1.0)).abs() < 1e-9,
        "{one:?} vs {apart:?}"
    );
    // The object 8 m away keeps its track.
    assert_eq!(merging.tracks().len(), 2);
}
