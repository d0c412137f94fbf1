//! The standard RFS benchmark scenarios end to end: the particle LMB must reach the accuracy
//! published for LMB filters on them (vo_scenarios: Gaussian-mixture LMBs score 11.8–12.8 m mean
//! OSPA on the linear scenario; the reference particle LMB 31–39 m on the nonlinear one).
//! Bounds leave room for a single run's spread; the example `rfs_benchmark` measures the means
//! over many runs.

use smc_lmb::filter::{AssociationMethod, Frame, LmbConfig, Measurements};
use smc_lmb::metrics::ospa;
use smc_lmb::rng::seeded;
use smc_lmb::sim::Scenario;

fn mean_ospa(
    scenario: &Scenario,
    seed: u64,
    particles: usize,
    associator: AssociationMethod,
) -> f64 {
    let sim = scenario.generate(seed).unwrap();
    let mut filter = scenario
        .filter(
            LmbConfig {
                particles,
                ..LmbConfig::default()
            },
            associator,
        )
        .unwrap();
    let mut rng = seeded(seed + 100);
    let mut total = 0.0;
    for (k, z) in sim.measurements.iter().enumerate() {
        let est = filter
            .step(
                &Frame::new(k as f64, Measurements::from_rows(2, z).unwrap()),
                &mut rng,
            )
            .unwrap();
        let x: Vec<Vec<f64>> = est.iter().map(|e| vec![e.state[0], e.state[2]]).collect();
        let y: Vec<Vec<f64>> = sim.truth[k].iter().map(|(_, s)| vec![s[0], s[2]]).collect();
        total += ospa(&y, &x, 100.0, 1.0).unwrap().distance;
    }
    total / sim.measurements.len() as f64
}

#[test]
fn linear_scenario_matches_published_lmb_accuracy() {
    for (seed, assoc) in [(1, "lbp"), (2, "murty"), (3, "gibbs")] {
        let d = mean_ospa(&Scenario::linear(), seed, 300, assoc.parse().unwrap());
        assert!(d < 15.0, "{assoc}: mean OSPA {d:.2} m");
    }
}

/// The reference MATLAB particle LMB's three runs on the nonlinear scenario
/// (`vo_scenarios.md`): 30.7, 39.0 and 35.7 m mean OSPA, 35.13 m on average.
const REFERENCE_PARTICLE_LMB_MEAN_OSPA: f64 = (30.7 + 39.0 + 35.7) / 3.0;

#[test]
fn nonlinear_scenario_beats_the_reference_particle_lmb() {
    // Our mean over four independent runs against the reference's mean over its three: a
    // single run spreads over 26–35 m, so one run alone would say little.
    let runs: Vec<f64> = (1..=4)
        .map(|seed| {
            mean_ospa(
                &Scenario::nonlinear(),
                seed,
                1000,
                AssociationMethod::default(),
            )
        })
        .collect();
    let mean = runs.iter().sum::<f64>() / runs.len() as f64;
    eprintln!("nonlinear: mean OSPA {mean:.2} m over runs {runs:.2?}");
    assert!(
        mean < REFERENCE_PARTICLE_LMB_MEAN_OSPA,
        "mean OSPA {mean:.2} m over runs {runs:.2?}, reference {REFERENCE_PARTICLE_LMB_MEAN_OSPA:.2} m"
    );
}
