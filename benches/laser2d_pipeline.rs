//! Criterion benchmark of the people-tracking pipeline on 361-beam scans: grouping the returns
//! into person candidates alone, and grouping plus the LMB filter (500 particles per track)
//! over a whole simulated run of scenario one (240 scans, five walkers, a moving robot) and
//! over a crowd of twenty walkers (up to 20 tracks at 500 particles, 80 scans); and the moving
//! front end alone (background map, ICP against the local map, shape classes) in the lobby of
//! scenario two, where walls and pillars give ICP something to hold on to; and the legs front
//! end with the tracker on two shared real recordings. Throughput is reported per scan, so
//! criterion's "elem/s" reads as scans per second.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use smc_lmb::laser2d::{read_bag, BagOptions};
use smc_lmb::pipeline::people_tracking::front_end::{
    adapt_tracker_config, default_detector_config, FrontEnd, PersonFrontEnd,
};
use smc_lmb::pipeline::people_tracking::{
    config_for_scans, track_scans_with_model, PeopleTracker, PeopleTrackerConfig,
};
use smc_lmb::sim::{PeopleScenario, PersonLeg, PersonSpec, RobotLeg};
use std::time::Duration;

/// Twenty people (radius 0.2 m) on a 4 × 5 grid 3 m apart, 5–14 m ahead of a robot creeping
/// forward at 0.3 m/s for 10 s, each walking slowly (0.2–0.4 m/s) in its own direction: all
/// twenty in the field of view, partly hiding one another.
fn crowd_of_twenty() -> PeopleScenario {
    let mut s = PeopleScenario::one();
    s.name = "people2d-crowd-20".into();
    s.duration = 10.0;
    s.robot.legs = vec![RobotLeg {
        duration: 10.0,
        speed: 0.3,
        turn_rate: 0.0,
    }];
    s.people = (0..20)
        .map(|k| {
            let (row, col) = ((k / 5) as f64, (k % 5) as f64);
            let heading = 0.7 * k as f64;
            let speed = 0.2 + 0.01 * k as f64;
            PersonSpec {
                id: k + 1,
                radius: 0.2,
                enter: 0.0,
                leave: None,
                start: [5.0 + 3.0 * row, -6.0 + 3.0 * col],
                legs: vec![PersonLeg {
                    duration: 10.0,
                    velocity: [speed * heading.cos(), speed * heading.sin()],
                }],
            }
        })
        .collect();
    s
}

/// The people tracker's configuration for the scanner of `scenario`.
fn tracker_config(scenario: &PeopleScenario) -> PeopleTrackerConfig {
    let s = &scenario.scanner;
    PeopleTrackerConfig::for_scanner(
        s.sigma_range,
        s.sigma_bearing,
        s.range_max,
        s.fov / 2.0,
        scenario.mount,
    )
}

fn laser2d_pipeline(c: &mut Criterion) {
    let scenario = PeopleScenario::one();
    let run = scenario.generate(1).expect("scenario one");
    let cfg = tracker_config(&scenario);
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

    // The case: up to 20 tracks at 500 particles on 361-beam scans.
    let crowd = crowd_of_twenty();
    let crowd_run = crowd.generate(1).expect("crowd of twenty");
    let crowd_cfg = tracker_config(&crowd);
    let mut g = c.benchmark_group("laser2d_pipeline");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    g.throughput(Throughput::Elements(crowd_run.scans.len() as u64));
    g.bench_function(
        "grouping_and_tracking/361_beams_20_people_500_particles",
        |b| {
            b.iter(|| {
                let mut t = PeopleTracker::new(crowd_cfg.clone()).expect("tracker");
                crowd_run
                    .scans
                    .iter()
                    .map(|scan| t.step(scan).expect("step").len())
                    .sum::<usize>()
            })
        },
    );
    g.finish();

    // Segmentation + background + ICP + grouping in a structured scene, without tracking.
    let lobby = PeopleScenario::two();
    let lobby_run = lobby.generate(1).expect("lobby");
    let mut lobby_cfg = tracker_config(&lobby);
    adapt_tracker_config(&mut lobby_cfg, FrontEnd::Moving);
    let detector = default_detector_config(&lobby_cfg, lobby_run.scans[0].angle_increment);
    let mut g = c.benchmark_group("laser2d_pipeline");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    g.throughput(Throughput::Elements(lobby_run.scans.len() as u64));
    g.bench_function("moving_front_end/361_beams_lobby", |b| {
        b.iter(|| {
            let mut fe = PersonFrontEnd::new(FrontEnd::Moving, &lobby_cfg, Some(detector))
                .expect("front end");
            lobby_run
                .scans
                .iter()
                .map(|scan| {
                    fe.measure(scan, scan.odometry)
                        .expect("measure")
                        .measurements
                        .len()
                })
                .sum::<usize>()
        })
    });
    g.finish();

    legs_on_recordings(c);
}

/// The legs front end and the LMB tracker behind it (`track_scans_with_model`, as the
/// `laser2d` example runs them) on the first 200 scans of a shared recording: the annotated
/// `positive_1_extracted.bag` and the right laser of `negative_2.bag` (empty rooms, the
/// slowest). Skipped, with a note, when `../shared/data` is absent.
fn legs_on_recordings(c: &mut Criterion) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/laser2d/leg_annotated");
    let mut g = c.benchmark_group("laser2d_pipeline");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    for (name, bag, topic) in [
        ("positive_1", "positive_1_extracted.bag", "/training_scan"),
        ("negative_2_right", "negative_2.bag", "/right_scan"),
    ] {
        let path = dir.join(bag);
        if !path.is_file() {
            eprintln!("skipping legs/{name}: {} is absent", path.display());
            continue;
        }
        let mut scans = read_bag(&path, &BagOptions::topic(topic))
            .expect("bag")
            .scans;
        scans.truncate(200);
        let cfg = config_for_scans(&scans, 0.03, 0.005, 15.0, [0.0, 0.0]).expect("config");
        g.throughput(Throughput::Elements(scans.len() as u64));
        g.bench_function(format!("legs_front_end_and_tracker/{name}"), |b| {
            b.iter(|| {
                track_scans_with_model(&scans, cfg.clone(), FrontEnd::Legs, None)
                    .expect("run")
                    .scans
                    .len()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, laser2d_pipeline);
criterion_main!(benches);
