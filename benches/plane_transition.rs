//! Criterion benchmark of the plane transition's hot loop: moving every particle of a plane
//! landmark (β = [n_x, n_y, n_z, d]) from the vehicle frame at k to the frame at k+1.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::{Isometry3, Vector3};
use smc_lmb::filter::ParticleSet;
use smc_lmb::geometry::FrameChange;
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
    )
    .expect("finite mean and deviations");
    // The vehicle moves 1 m forward and turns 2° between the frames.
    let prev = Isometry3::identity();
    let cur = Isometry3::new(
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.0, 0.0, 2f64.to_radians()),
    );
    let m = FrameChange::between(&prev, &cur);
    let mut g = c.benchmark_group("plane_transition");
    g.sample_size(20).measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Elements(n as u64));
    g.bench_function("transform_planes/100k_particles", |b| {
        b.iter(|| {
            let mut c = planes.components_mut();
            if let [nx, ny, nz, d] = c.as_mut_slice() {
                m.move_planes(nx, ny, nz, d);
            }
        })
    });
    g.finish();
}

criterion_group!(benches, plane_transition);
criterion_main!(benches);
