//! Criterion benchmark of the plane transition's hot loop: moving every particle of a plane
//! landmark (β = [n_x, n_y, n_z, d]) from the vehicle frame at k to the frame at k+1.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::{Isometry3, Vector3};
use smc_lmb::filter::ParticleSet;
use smc_lmb::models::plane::{relative_motion, transform_planes};
use smc_lmb::rng::seeded;
use std::time::Duration;

fn plane_transition(c: &mut Criterion) {
    let n = 100_000;
    let mut rng = seeded(1);
    let mut planes = ParticleSet::gaussian(
        &[-1.0, 0.0, 0.0, 10.0],
        &[0.01, 0.01, 0.01, 0.05],
        n,
        &mut rng,
    );
    // The vehicle moves 1 m forward and turns 2° between the frames.
    let prev = Isometry3::identity();
    let cur = Isometry3::new(
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.0, 0.0, 2f64.to_radians()),
    );
    let m = relative_motion(&prev, &cur);
    let mut g = c.benchmark_group("plane_transition");
    g.sample_size(20).measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Elements(n as u64));
    g.bench_function("transform_planes/100k_particles", |b| {
        b.iter(|| transform_planes(&mut planes, &m))
    });
    g.finish();
}

criterion_group!(benches, plane_transition);
criterion_main!(benches);
