//! Several sensors in one filter: a street of objects seen by three sensors that each miss
//! many of them; every fusion rule against the sensors alone, one sensor as a sensor list
//! against the single-sensor filter, thread counts, rates, mountings and bad input.

use rand::RngExt;
use smc_lmb::filter::{
    AdaptiveBirth, Frame, Fusion, FusionMethod, LmbConfig, LmbFilter, LmbFilterBuilder,
    Measurements, Mounting, PositionBirthSampler, Sensor,
};
use smc_lmb::metrics::ospa::ospa;
use smc_lmb::models::{ConstantDetection, ConstantVelocity, PositionMeasurement, UniformClutter};
use smc_lmb::rng::seeded;

const SENSORS: usize = 3;
const STEPS: usize = 40;
const SIGMA: f64 = 1.0;
const P_D: f64 = 0.6;
const CLUTTER: f64 = 2.0;

/// Truth positions per step and each sensor's measurements per step (platform frame).
struct Scenario {
    truth: Vec<Vec<Vec<f64>>>,
    scans: Vec<Vec<Vec<[f64; 2]>>>,
}

fn normal(rng: &mut impl RngExt) -> f64 {
    let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// Four objects crossing a 100 m square at constant velocity, one appearing at step 10.
fn scenario(seed: u64) -> Scenario {
    let mut rng = seeded(seed);
    let starts = [
        ([-40.0, -30.0], [1.5, 0.5], 0),
        ([30.0, -40.0], [-0.5, 1.5], 0),
        ([-35.0, 35.0], [1.0, -1.2], 0),
        ([0.0, 0.0], [-1.0, -1.0], 10),
    ];
    let mut truth = Vec::new();
    let mut scans = vec![Vec::new(); SENSORS];
    for k in 0..STEPS {
        let t = k as f64;
        let here: Vec<Vec<f64>> = starts
            .iter()
            .filter(|(_, _, born)| k >= *born)
            .map(|(p, v, born)| {
                let dt = t - *born as f64;
                vec![p[0] + v[0] * dt, p[1] + v[1] * dt]
            })
            .collect();
        for scan in scans.iter_mut() {
            let mut z: Vec<[f64; 2]> = Vec::new();
            for x in &here {
                if rng.random::<f64>() < P_D {
                    z.push([
                        x[0] + SIGMA * normal(&mut rng),
                        x[1] + SIGMA * normal(&mut rng),
                    ]);
                }
            }
            for _ in 0..(CLUTTER as usize) {
                z.push([rng.random_range(-50.0..50.0), rng.random_range(-50.0..50.0)]);
            }
            scan.push(z);
        }
        truth.push(here);
    }
    Scenario { truth, scans }
}

fn base() -> LmbFilterBuilder {
    LmbFilter::builder()
        .transition(ConstantVelocity::new(2, 0.3).unwrap())
        .birth(
            AdaptiveBirth::new(
                PositionBirthSampler {
                    position_std: SIGMA,
                    velocity_std: 2.0,
                },
                0.05,
                0.1,
                300,
            )
            .unwrap(),
        )
        .config(LmbConfig {
            particles: 300,
            ..LmbConfig::default()
        })
}

fn sensor(name: &str) -> Sensor {
    Sensor::new(
        name,
        PositionMeasurement::new(2, SIGMA).unwrap(),
        ConstantDetection::new(P_D).unwrap(),
        UniformClutter::rectangle(CLUTTER, [-50.0, 50.0], [-50.0, 50.0]).unwrap(),
    )
}

fn fused(method: FusionMethod) -> LmbFilter {
    let mut b = base().fusion(Fusion::new(method));
    for s in 0..SENSORS {
        b = b.sensor(sensor(&format!("s{s}")));
    }
    b.build().unwrap()
}

fn rows(z: &[[f64; 2]]) -> Measurements {
    Measurements::from_rows(2, z).unwrap()
}

/// Mean OSPA (c = 10 m, p = 1) over steps 5.. of `filter` fed the scans of `sensors`.
fn mean_ospa(filter: &mut LmbFilter, sc: &Scenario, sensors: &[usize], seed: u64) -> f64 {
    let mut rng = seeded(seed);
    let mut sum = 0.0;
    for k in 0..STEPS {
        let mut frame = Frame::at_time(k as f64);
        for (i, &s) in sensors.iter().enumerate() {
            frame = frame.with_sensor(i, rows(&sc.scans[s][k]));
        }
        let est = filter.step(&frame, &mut rng).unwrap();
        let x: Vec<Vec<f64>> = est.iter().map(|e| vec![e.state[0], e.state[2]]).collect();
        if k >= 5 {
            sum += ospa(&sc.truth[k], &x, 10.0, 1.0).unwrap().distance;
        }
    }
    sum / (STEPS - 5) as f64
}

/// Every rule against each sensor alone, over three scenarios: the sensors miss 40 % of
/// the objects each, so IC and PU (which multiply the evidence) must beat every sensor
/// alone, and the averages must beat at least the worst.
#[test]
fn fusion_beats_every_sensor_alone() {
    let mut alone = [0.0; SENSORS];
    let mut rule = std::collections::BTreeMap::new();
    for seed in 1..=3 {
        let sc = scenario(seed);
        for (s, a) in alone.iter_mut().enumerate() {
            let mut f = base().sensor(sensor("only")).build().unwrap();
            *a += mean_ospa(&mut f, &sc, &[s], seed) / 3.0;
        }
        for m in [
            FusionMethod::IteratedCorrector,
            FusionMethod::ParallelUpdate,
            FusionMethod::GeometricAverage,
            FusionMethod::ArithmeticAverage,
        ] {
            let d = mean_ospa(&mut fused(m), &sc, &[0, 1, 2], seed);
            *rule.entry(m.short_name()).or_insert(0.0) += d / 3.0;
        }
    }
    let best = alone.iter().copied().fold(f64::INFINITY, f64::min);
    let worst = alone.iter().copied().fold(0.0, f64::max);
    eprintln!("alone {alone:?}, fused {rule:?}");
    assert!(rule["ic"] < best, "IC {} vs best single {best}", rule["ic"]);
    assert!(rule["pu"] < best, "PU {} vs best single {best}", rule["pu"]);
    assert!(
        rule["ga"] < worst,
        "GA {} vs worst single {worst}",
        rule["ga"]
    );
    assert!(rule["aa"] < best, "AA {} vs best single {best}", rule["aa"]);
}

/// A filter of one sensor given as a sensor list runs exactly as the single-sensor filter,
/// whatever the fusion rule.
#[test]
fn one_sensor_as_a_list_is_the_single_sensor_filter() {
    let sc = scenario(7);
    let run = |mut f: LmbFilter| {
        let mut rng = seeded(3);
        (0..STEPS)
            .map(|k| {
                f.step(&Frame::new(k as f64, rows(&sc.scans[0][k])), &mut rng)
                    .unwrap()
            })
            .collect::<Vec<_>>()
    };
    let single = run(base()
        .measurement(PositionMeasurement::new(2, SIGMA).unwrap())
        .detection(ConstantDetection::new(P_D).unwrap())
        .clutter(UniformClutter::rectangle(CLUTTER, [-50.0, 50.0], [-50.0, 50.0]).unwrap())
        .build()
        .unwrap());
    assert!(single.iter().any(|e| !e.is_empty()));
    for m in [
        FusionMethod::IteratedCorrector,
        FusionMethod::ParallelUpdate,
    ] {
        let listed = run(base()
            .sensor(sensor("lidar"))
            .fusion(Fusion::new(m))
            .build()
            .unwrap());
        assert_eq!(single, listed, "{m:?}");
    }
}

/// The same seed gives the same estimates on one thread and on several, for every rule.
#[test]
fn fused_runs_do_not_depend_on_the_thread_count() {
    let sc = scenario(4);
    for m in [
        FusionMethod::IteratedCorrector,
        FusionMethod::ParallelUpdate,
        FusionMethod::GeometricAverage,
        FusionMethod::ArithmeticAverage,
    ] {
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut f = fused(m);
                let mut rng = seeded(9);
                (0..15)
                    .map(|k| {
                        let frame = (0..SENSORS).fold(Frame::at_time(k as f64), |fr, s| {
                            fr.with_sensor(s, rows(&sc.scans[s][k]))
                        });
                        f.step(&frame, &mut rng).unwrap()
                    })
                    .collect::<Vec<_>>()
            })
        };
        assert_eq!(run(1), run(3), "{m:?}");
    }
}

/// Sensors at different rates: the second reports every third frame only, and a frame with
/// no scan predicts without updating.
#[test]
fn sensors_missing_from_a_frame_are_not_used() {
    let sc = scenario(5);
    let mut f = base()
        .sensor(sensor("fast"))
        .sensor(sensor("slow"))
        .fusion(Fusion::new(FusionMethod::ParallelUpdate))
        .build()
        .unwrap();
    let mut rng = seeded(1);
    for k in 0..STEPS {
        let mut frame = Frame::at_time(k as f64).with_sensor(0, rows(&sc.scans[0][k]));
        if k % 3 == 0 {
            frame = frame.with_sensor(1, rows(&sc.scans[1][k]));
        }
        f.step(&frame, &mut rng).unwrap();
    }
    let before: Vec<(f64, Vec<f64>)> = f
        .tracks()
        .iter()
        .map(|t| (t.existence, t.particles.weights().to_vec()))
        .collect();
    f.step(&Frame::at_time(STEPS as f64), &mut rng).unwrap();
    let confirmed = f.tracks().iter().filter(|t| t.existence > 0.5).count();
    assert_eq!(confirmed, 4, "the four objects stay confirmed");
    // No scan: survival only (p_S = 0.99 by default), weights as they were.
    for (t, (r, w)) in f.tracks().iter().zip(&before) {
        assert!((t.existence - 0.99 * r).abs() < 1e-12);
        assert_eq!(t.particles.weights(), &w[..]);
    }
}

/// A mounted sensor's measurements, given in its own frame, track exactly as the same
/// measurements given in the platform frame to a sensor at the origin.
#[test]
fn mounted_sensors_measure_in_their_own_frame() {
    let sc = scenario(6);
    let m = Mounting::new(2.0, -1.0, 2.5).unwrap();
    let (s, c) = m.heading.sin_cos();
    let to_sensor = |p: &[f64; 2]| {
        let (dx, dy) = (p[0] - m.x, p[1] - m.y);
        [c * dx + s * dy, -s * dx + c * dy]
    };
    let mut plain = base().sensor(sensor("a")).build().unwrap();
    let mut mounted = base().sensor(sensor("a").mounted(m)).build().unwrap();
    let (mut r1, mut r2) = (seeded(2), seeded(2));
    for k in 0..STEPS {
        let z = &sc.scans[0][k];
        let local: Vec<[f64; 2]> = z.iter().map(to_sensor).collect();
        let a = plain.step(&Frame::new(k as f64, rows(z)), &mut r1).unwrap();
        let b = mounted
            .step(&Frame::new(k as f64, rows(&local)), &mut r2)
            .unwrap();
        assert_eq!(a.len(), b.len(), "step {k}");
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.label, y.label);
            assert!((x.state[0] - y.state[0]).abs() < 1e-6, "step {k}");
            assert!((x.existence - y.existence).abs() < 1e-6, "step {k}");
        }
    }
}

#[test]
fn bad_sensor_input_is_refused_and_named() {
    let err = |r: Result<LmbFilter, smc_lmb::Error>| r.unwrap_err().to_string();
    let e = err(base().sensor(sensor("a")).sensor(sensor("a")).build());
    assert!(e.contains("same name"), "{e}");
    let e = err(base()
        .sensor(sensor("a"))
        .sensor(Sensor::new(
            "b",
            PositionMeasurement::new(3, SIGMA).unwrap(),
            ConstantDetection::new(P_D).unwrap(),
            UniformClutter::rectangle(CLUTTER, [-50.0, 50.0], [-50.0, 50.0]).unwrap(),
        ))
        .build());
    assert!(e.contains("\"b\"") && e.contains("3 components"), "{e}");
    let e = err(base()
        .sensor(sensor("a"))
        .sensor(sensor("b"))
        .fusion(Fusion::new(FusionMethod::ArithmeticAverage).with_weights(vec![0.7, 0.7]))
        .build());
    assert!(e.contains("fusion weights") && e.contains("sum"), "{e}");
    let e = err(base()
        .sensor(sensor("a"))
        .measurement(PositionMeasurement::new(2, SIGMA).unwrap())
        .build());
    assert!(e.contains("both sensors"), "{e}");

    let mut f = fused(FusionMethod::ParallelUpdate);
    let mut rng = seeded(1);
    let z = rows(&[[0.0, 0.0]]);
    let e = f
        .step(&Frame::at_time(0.0).with_sensor(3, z.clone()), &mut rng)
        .unwrap_err()
        .to_string();
    assert!(e.contains("sensor 3") && e.contains("3 sensors"), "{e}");
    let e = f
        .step(
            &Frame::at_time(0.0)
                .with_sensor(1, z.clone())
                .with_sensor(1, z.clone()),
            &mut rng,
        )
        .unwrap_err()
        .to_string();
    assert!(e.contains("two scans of sensor 1 (\"s1\")"), "{e}");
    let z3 = Measurements::from_rows(3, &[[0.0, 0.0, 0.0]]).unwrap();
    let e = f
        .step(&Frame::at_time(0.0).with_sensor(2, z3), &mut rng)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("sensor 2 (\"s2\")") && e.contains("dimension 3"),
        "{e}"
    );
    // Nothing was half-done: the refused frames left the filter at step 0.
    assert_eq!(f.steps(), 0);
    assert!(f
        .step(&Frame::at_time(0.0).with_sensor(0, z), &mut rng)
        .is_ok());
}
