//! Criterion benchmark of the people-tracking pipeline on 361-beam scans: grouping the returns
//! into person candidates alone, and grouping plus the LMB filter (500 particles per track)
//! over a whole simulated run of scenario one (240 scans, five walkers, a moving robot).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use smc_lmb::laser2d::{PeopleTracker, PeopleTrackerConfig};
use smc_lmb::sim::PeopleScenario;
use std::time::Duration;

fn laser2d_pipeline(c: &mut Criterion) {
    let scenario = PeopleScenario::one();
    let run = scenario.generate(1).expect("scenario one");
    let s = &scenario.scanner;
    let cfg = PeopleTrackerConfig::for_scanner(
        s.sigma_range,
        s.sigma_bearing,
        s.range_max,
        s.fov / 2.0,
        scenario.mount,
    );
    let mut g = c.benchmark_group("laser2d_pipeline");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    g.throughput(Throughput::Elements(run.scans.len() as u64));
    let tracker = PeopleTracker::new(cfg.clone()).expect("tracker");
    g.bench_function("grouping/361_beams", |b| {
        b.iter(|| {
            run.scans
                .iter()
                .map(|scan| tracker.measurements(scan).expect("measurements").len())
                .sum::<usize>()
        })
    });
    g.bench_function("grouping_and_tracking/361_beams_500_particles", |b| {
        b.iter(|| {
            let mut t = PeopleTracker::new(cfg.clone()).expect("tracker");
            run.scans
                .iter()
                .map(|scan| t.step(scan).expect("step").len())
                .sum::<usize>()
        })
    });
    g.finish();
}

criterion_group!(benches, laser2d_pipeline);
criterion_main!(benches);
