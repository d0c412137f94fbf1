//! Criterion benchmark of one fused step against the number of sensors: 20 confirmed objects
//! with 1,000 particles each, every sensor measuring each of them once per step with light
//! clutter, for 1, 2, 4 and 8 sensors and every fusion rule. The cost should grow linearly in
//! the sensors (one likelihood pass and one association per sensor; the fusion itself is one
//! pass over the particles per sensor).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use smc_lmb::filter::birth::BirthEvidence;
use smc_lmb::filter::{
    BirthModel, BirthTerm, BirthTrack, Frame, Fusion, FusionMethod, LmbConfig, LmbFilter,
    Measurements, Sensor, StaticBirth, StepContext,
};
use smc_lmb::models::{ConstantDetection, ConstantVelocity, PositionMeasurement, UniformClutter};
use smc_lmb::rng::seeded;
use smc_lmb::FilterRng;
use std::time::Duration;

const OBJECTS: usize = 20;
const PARTICLES: usize = 1000;

/// Births only at the first step: the tracks under test, and nothing new afterwards.
struct FirstStepOnly(StaticBirth);

impl BirthModel for FirstStepOnly {
    fn birth(
        &self,
        ctx: &StepContext,
        ev: Option<&BirthEvidence<'_>>,
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack> {
        if ctx.step == 0 {
            self.0.birth(ctx, ev, rng)
        } else {
            Vec::new()
        }
    }
}

/// A filter of `sensors` sensors already tracking the objects, and the next frame.
fn tracking(sensors: usize, method: FusionMethod) -> (LmbFilter, Frame) {
    let positions: Vec<[f64; 2]> = (0..OBJECTS)
        .map(|i| [100.0 * (i % 10) as f64, 100.0 * (i / 10) as f64])
        .collect();
    let terms = positions
        .iter()
        .map(|p| BirthTerm {
            existence: 0.9,
            mean: vec![p[0], 1.0, p[1], 0.0],
            std: vec![1.0, 0.5, 1.0, 0.5],
        })
        .collect();
    let mut b = LmbFilter::builder()
        .transition(ConstantVelocity::new(2, 1.0).unwrap())
        .birth(FirstStepOnly(StaticBirth::new(terms, PARTICLES).unwrap()))
        .fusion(Fusion::new(method))
        .config(LmbConfig {
            particles: PARTICLES,
            ..LmbConfig::default()
        });
    for s in 0..sensors {
        b = b.sensor(Sensor::new(
            format!("s{s}"),
            PositionMeasurement::new(2, 1.0).unwrap(),
            ConstantDetection(0.95),
            UniformClutter::rectangle(5.0, [-1000.0, 1000.0], [-1000.0, 1000.0]).unwrap(),
        ));
    }
    let mut filter = b.build().unwrap();
    let frame = |k: usize| {
        (0..sensors).fold(Frame::at_time(k as f64), |f, s| {
            let z: Vec<[f64; 2]> = positions
                .iter()
                .map(|p| [p[0] + k as f64 + 0.1 * s as f64, p[1]])
                .collect();
            f.with_sensor(s, Measurements::from_rows(2, &z).unwrap())
        })
    };
    let mut rng = seeded(1);
    filter.step(&frame(0), &mut rng).unwrap();
    (filter, frame(1))
}

fn sensors(c: &mut Criterion) {
    let mut g = c.benchmark_group("multisensor/step_20_objects_1000_particles");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(300));
    for method in [
        FusionMethod::IteratedCorrector,
        FusionMethod::ParallelUpdate,
        FusionMethod::GeometricAverage,
        FusionMethod::ArithmeticAverage,
    ] {
        for &n in &[1usize, 2, 4, 8] {
            g.throughput(Throughput::Elements(n as u64));
            g.bench_with_input(BenchmarkId::new(method.short_name(), n), &n, |b, &n| {
                b.iter_batched(
                    || tracking(n, method),
                    |(mut f, frame)| {
                        let mut rng = seeded(2);
                        f.step(&frame, &mut rng).unwrap()
                    },
                    criterion::BatchSize::LargeInput,
                )
            });
        }
    }
    g.finish();
}

criterion_group!(benches, sensors);
criterion_main!(benches);
