//! Criterion benchmarks of the association methods on random groups.
//!
//! * `murty_k200/NxM`: Murty's ranked assignment (k = 200) on one random group of N tracks
//!   and M measurements;
//! * `murty_k200/mixed`: the same on 16 random groups of 5–15 tracks × 5–20 measurements,
//!   the sizes the nonlinear benchmark's larger groups reach;
//! * `lbp/mixed`: belief propagation on the same 16 groups, for scale.
//!
//! The log weights are uniform in [−12, 2] with about one pairing in three gated out (−∞),
//! and the miss weights in [−3, 0].

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use rand::RngExt;
use smc_lmb::filter::association::{
    ranked_hypotheses, AssociationProblem, Associator, LbpAssociator, MurtyAssociator,
};
use smc_lmb::rng::seeded;
use std::hint::black_box;
use std::time::Duration;

/// A random group of `n` tracks and `m` measurements.
fn problem(n: usize, m: usize, seed: u64) -> AssociationProblem {
    let mut rng = seeded(seed);
    let log_miss = (0..n).map(|_| -3.0 * rng.random::<f64>()).collect();
    let log_detect = (0..n * m)
        .map(|_| {
            if rng.random::<f64>() < 1.0 / 3.0 {
                f64::NEG_INFINITY
            } else {
                -12.0 + 14.0 * rng.random::<f64>()
            }
        })
        .collect();
    AssociationProblem::new(n, m, log_miss, log_detect).unwrap()
}

/// 16 groups of 5–15 tracks × 5–20 measurements.
fn mixed() -> Vec<AssociationProblem> {
    let mut rng = seeded(99);
    (0..16)
        .map(|s| {
            let n = rng.random_range(5..=15);
            let m = rng.random_range(5..=20);
            problem(n, m, 1000 + s)
        })
        .collect()
}

fn murty(c: &mut Criterion) {
    let mut g = c.benchmark_group("murty_k200");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_millis(500));
    for &(n, m) in &[(5usize, 5usize), (10, 10), (15, 20)] {
        let p = problem(n, m, 7);
        g.bench_with_input(
            BenchmarkId::from_parameter(format!("{n}x{m}")),
            &p,
            |b, p| b.iter(|| black_box(ranked_hypotheses(p, 200))),
        );
    }
    let groups = mixed();
    let murty = MurtyAssociator::default();
    g.bench_function("mixed", |b| {
        b.iter(|| {
            let mut rng = seeded(0);
            for p in &groups {
                black_box(murty.marginals(p, &mut rng));
            }
        })
    });
    g.finish();

    let mut g = c.benchmark_group("lbp");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(300));
    let lbp = LbpAssociator::default();
    g.bench_function("mixed", |b| {
        b.iter(|| {
            let mut rng = seeded(0);
            for p in &groups {
                black_box(lbp.marginals(p, &mut rng));
            }
        })
    });
    g.finish();
}

criterion_group!(benches, murty);
criterion_main!(benches);
