//! Criterion benchmarks of one filter step.
//!
//! * `scaling/particles_targets`: a sweep over particles per track (100 … 10,000) and
//!   confirmed targets (1 … 50), each target measured once per step with light clutter, to
//!   show that the cost of a step grows linearly in both;
//! * `rfs/nonlinear` and `rfs/linear`: a step of the standard benchmark scenarios (the median
//!   of a step drawn from a whole run);
//! * `rfs/nonlinear/whole_run_1000_particles_smoothed_lag_5`: the same nonlinear run keeping
//!   five steps of particle history and handing every step's estimates out smoothed
//!   (`FixedLagSmoother`), against the run above for the smoother's cost.

mod common;

use common::FirstStepOnly;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use smc_lmb::filter::{
    AssociationMethod, FixedLagSmoother, Frame, LmbConfig, LmbFilter, Measurements, StaticBirth,
};
use smc_lmb::models::{ConstantDetection, ConstantVelocity, PositionMeasurement, UniformClutter};
use smc_lmb::rng::seeded;
use smc_lmb::sim::{Scenario, SimRun};
use std::time::Duration;

/// A filter already tracking `targets` objects on a grid 100 m apart, and the next frame.
fn tracking(targets: usize, particles: usize) -> (LmbFilter, Vec<Frame>) {
    let positions: Vec<[f64; 2]> = (0..targets)
        .map(|i| [100.0 * (i % 10) as f64, 100.0 * (i / 10) as f64])
        .collect();
    // A first frame with a confident birth term at every target starts the tracks.
    let terms = positions
        .iter()
        .map(|p| smc_lmb::filter::BirthTerm {
            existence: 0.9,
            mean: vec![p[0], 1.0, p[1], 0.0],
            std: vec![1.0, 0.5, 1.0, 0.5],
        })
        .collect();
    let mut filter = LmbFilter::builder()
        .transition(ConstantVelocity::new(2, 1.0).unwrap())
        .measurement(PositionMeasurement::new(2, 1.0).unwrap())
        .detection(ConstantDetection(0.95))
        .clutter(UniformClutter::rectangle(5.0, [-1000.0, 1000.0], [-1000.0, 1000.0]).unwrap())
        .birth(FirstStepOnly(StaticBirth::new(terms, particles).unwrap()))
        .config(LmbConfig {
            particles,
            ..LmbConfig::default()
        })
        .build()
        .unwrap();
    let frame = |k: usize| {
        let z: Vec<[f64; 2]> = positions.iter().map(|p| [p[0] + k as f64, p[1]]).collect();
        Frame::new(k as f64, Measurements::from_rows(2, &z).unwrap())
    };
    let mut rng = seeded(1);
    filter.step(&frame(0), &mut rng).unwrap();
    let frames = (1..4).map(frame).collect();
    (filter, frames)
}

fn scaling(c: &mut Criterion) {
    let mut g = c.benchmark_group("scaling/particles_targets");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(300));
    for &targets in &[1usize, 10, 50] {
        for &particles in &[100usize, 1000, 10_000] {
            g.throughput(Throughput::Elements((targets * particles) as u64));
            g.bench_with_input(
                BenchmarkId::new(format!("targets={targets}"), particles),
                &particles,
                |b, &particles| {
                    b.iter_batched(
                        || tracking(targets, particles),
                        |(mut f, frames)| {
                            let mut rng = seeded(2);
                            f.step(&frames[0], &mut rng).unwrap()
                        },
                        criterion::BatchSize::LargeInput,
                    )
                },
            );
        }
    }
    g.finish();
}

/// A whole run of `scenario`'s measurements `sim` with `particles` per track; with `lag` > 0
/// the tracks keep that many steps of history and every step's estimates are handed out
/// smoothed. Returns how many tracks (or smoothed estimates) there were, so nothing is
/// optimised away.
fn whole_run(scenario: &Scenario, sim: &SimRun, particles: usize, lag: usize) -> usize {
    let config = LmbConfig {
        particles,
        smoothing_lag: lag,
        ..LmbConfig::default()
    };
    let mut f = scenario
        .filter(config, AssociationMethod::default())
        .unwrap();
    let mut smoother = FixedLagSmoother::new(lag);
    let mut rng = seeded(3);
    let mut handed = 0;
    for (k, z) in sim.measurements.iter().enumerate() {
        let est = f
            .step(
                &Frame::new(k as f64, Measurements::from_rows(2, z).unwrap()),
                &mut rng,
            )
            .unwrap();
        if lag > 0 {
            handed += smoother.push(&f, est).unwrap().map_or(0, |e| e.len());
        }
    }
    if lag > 0 {
        handed + smoother.finish(&f).len()
    } else {
        f.tracks().len()
    }
}

fn rfs(c: &mut Criterion) {
    let mut g = c.benchmark_group("rfs");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(5))
        .warm_up_time(Duration::from_millis(500));
    for (name, scenario, particles) in [
        ("nonlinear", Scenario::nonlinear(), 1000),
        ("linear", Scenario::linear(), 500),
    ] {
        let sim = scenario.generate(1).unwrap();
        g.throughput(Throughput::Elements(scenario.steps as u64));
        g.bench_function(format!("{name}/whole_run_{particles}_particles"), |b| {
            b.iter(|| whole_run(&scenario, &sim, particles, 0))
        });
        if name == "nonlinear" {
            let lag = 5;
            g.bench_function(
                format!("{name}/whole_run_{particles}_particles_smoothed_lag_{lag}"),
                |b| b.iter(|| whole_run(&scenario, &sim, particles, lag)),
            );
        }
    }
    g.finish();
}

criterion_group!(benches, scaling, rfs);
criterion_main!(benches);
