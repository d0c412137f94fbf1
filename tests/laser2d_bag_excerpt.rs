//! The vendored excerpt of a real ROS 1 bag, `tests/data/laser2d/positive_1_excerpt.bag`: the
//! first 39 messages of each of the three topics of the `leg_tracker` recording
//! `positive_1_extracted.bag` (its first continuous stretch: one person walking away from a
//! stationary scanner, 5.1 s), cut by `examples/cut_bag` into three chunks. It is read with
//! the library's bag reader, tracked and scored against its leg annotations as
//! `examples/laser2d.rs --bag B --topic /training_scan --truth-topic /leg_cluster_positions`
//! does, with nothing from `../shared/data`. When the source bag is there (it must be under
//! `CI=true`), the generator must cut exactly the committed file from it.

mod common;

#[path = "../examples/cut_bag/excerpt.rs"]
mod excerpt;

use smc_lmb::laser2d::{
    bag_topics, read_bag, read_pose_arrays, BagOptions, BagTopic, OdometryTopic, Scan,
};
use smc_lmb::pipeline::people_tracking::front_end::FrontEnd;
use smc_lmb::pipeline::people_tracking::score::{
    truth_for_scans, DetectionScore, TrackScore, TrackScoreSummary, FIRST_SCORED_SCAN,
};
use smc_lmb::pipeline::people_tracking::{config_for_scans, track_scans_with_model, PeopleRun};
use std::path::PathBuf;

const SCAN_TOPIC: &str = "/training_scan";
const TRUTH_TOPIC: &str = "/leg_cluster_positions";
/// Messages per topic in the excerpt.
const MESSAGES: usize = 39;
/// Chunk threshold the excerpt was cut with (bytes).
const CHUNK_THRESHOLD: usize = 64 * 1024;

fn excerpt_path() -> PathBuf {
    common::vendored_laser2d("positive_1_excerpt.bag")
}

fn scans() -> Vec<Scan> {
    read_bag(excerpt_path(), &BagOptions::topic(SCAN_TOPIC))
        .unwrap()
        .scans
}

/// People per scan from the annotations, paired with the scans by receive time.
fn truth() -> Vec<Vec<[f64; 2]>> {
    let bag = read_bag(excerpt_path(), &BagOptions::topic(SCAN_TOPIC)).unwrap();
    let annotations = read_pose_arrays(excerpt_path(), TRUTH_TOPIC).unwrap();
    truth_for_scans(&bag.receive_times, &annotations, "excerpt").unwrap()
}

#[test]
fn excerpt_lists_its_three_topics() {
    let topic = |t: &str, ty: &str| BagTopic {
        topic: t.into(),
        message_type: ty.into(),
    };
    assert_eq!(
        bag_topics(excerpt_path()).unwrap(),
        vec![
            topic(TRUTH_TOPIC, "geometry_msgs/PoseArray"),
            topic(SCAN_TOPIC, "sensor_msgs/LaserScan"),
            topic(
                "/visualization_marker_array",
                "visualization_msgs/MarkerArray"
            ),
        ]
    );
}

#[test]
fn excerpt_scans_read_back_with_the_scanner_header_and_rising_stamps() {
    // The only LaserScan topic is found without naming it; there is no odometry.
    let bag = read_bag(excerpt_path(), &BagOptions::default()).unwrap();
    assert_eq!(bag.scan_topic, SCAN_TOPIC);
    assert_eq!(bag.odometry_topic, None);
    assert!(bag.odometry.is_empty());
    assert_eq!(bag.topics.len(), 3);
    let named = read_bag(excerpt_path(), &BagOptions::topic(SCAN_TOPIC)).unwrap();
    assert_eq!(named, bag);

    let scans = &bag.scans;
    assert_eq!(scans.len(), MESSAGES);
    assert_eq!(bag.receive_times.len(), MESSAGES);
    let first = &scans[0];
    // 768 beams of 2π/1024 from −3π/4: 270° less one beam (the header's f32 values).
    let increment = std::f64::consts::TAU / 1024.0;
    for s in scans {
        assert_eq!(s.len(), 768);
        assert!((s.angle_min + 0.75 * std::f64::consts::PI).abs() < 1e-6);
        assert!((s.angle_increment - increment).abs() < 1e-9);
        assert!((s.angle_max() - (s.angle_min + 767.0 * increment)).abs() < 1e-6);
        assert_eq!((s.range_min, s.range_max), (first.range_min, 11.0));
        assert!((s.range_min - 0.03).abs() < 1e-6);
        assert!(s.odometry.is_none());
        // an indoor scene: most beams return
        let returns = s.points().count();
        assert!((600..=700).contains(&returns), "{returns} returns");
    }
    // Header stamps: the scanner's clock, about 7.5 Hz without a gap.
    assert!(
        (first.time - 1_393_615_837.429_165).abs() < 1e-5,
        "{}",
        first.time
    );
    for w in scans.windows(2) {
        let dt = w[1].time - w[0].time;
        assert!((0.125..0.14).contains(&dt), "{dt}");
    }
    let span = scans[MESSAGES - 1].time - first.time;
    assert!((4.9..5.2).contains(&span), "{span}");
    // Receive times: another clock (the bag was written in one go), rising too.
    assert!(bag.receive_times.windows(2).all(|w| w[1] > w[0]));
    assert!(bag.receive_times[0] > 1.426e9);
}

#[test]
fn excerpt_refuses_topics_of_the_wrong_type_by_name() {
    let e = read_bag(excerpt_path(), &BagOptions::topic(TRUTH_TOPIC))
        .unwrap_err()
        .to_string();
    assert!(e.contains("does not carry sensor_msgs/LaserScan"), "{e}");
    let options = BagOptions {
        scan_topic: None,
        odometry: OdometryTopic::Named(SCAN_TOPIC.into()),
    };
    let e = read_bag(excerpt_path(), &options).unwrap_err().to_string();
    assert!(e.contains("is not a nav_msgs/Odometry topic"), "{e}");
    let e = read_pose_arrays(excerpt_path(), SCAN_TOPIC)
        .unwrap_err()
        .to_string();
    assert!(e.contains("topics present"), "{e}");
}

#[test]
fn excerpt_annotations_give_one_walking_person_per_scan() {
    let bag = read_bag(excerpt_path(), &BagOptions::topic(SCAN_TOPIC)).unwrap();
    let annotations = read_pose_arrays(excerpt_path(), TRUTH_TOPIC).unwrap();
    assert_eq!(annotations.len(), MESSAGES);
    for (k, a) in annotations.iter().enumerate() {
        assert!((1..=2).contains(&a.positions.len()), "{k}: {a:?}");
        // Zero header stamps: the receive time stands in.
        assert_eq!(a.time, a.receive_time);
        // Each annotation is received just before its scan.
        assert!(a.receive_time < bag.receive_times[k]);
        if k > 0 {
            assert!(a.receive_time > bag.receive_times[k - 1]);
        }
        assert!(a.positions.iter().all(|p| p[2] == 0.0));
    }
    let legs: usize = annotations.iter().map(|a| a.positions.len()).sum();
    assert_eq!(legs, 62);
    let truth = truth_for_scans(&bag.receive_times, &annotations, "excerpt").unwrap();
    assert!(truth.iter().all(|people| people.len() == 1));
    // The person walks away from the scanner, from 2 m to nearly 5 m.
    let dist = |p: [f64; 2]| p[0].hypot(p[1]);
    let (d0, d1) = (dist(truth[0][0]), dist(truth[MESSAGES - 1][0]));
    assert!((1.9..2.2).contains(&d0), "{d0}");
    assert!((4.6..5.0).contains(&d1), "{d1}");
}

/// What `laser2d --bag ... --truth-topic ...` does after reading: settings from the first
/// scan (0.03 m, 0.005 rad, 15 m), seed 1, the front end, the shipped leg model.
fn track(scans: &[Scan], front_end: FrontEnd) -> (PeopleRun, f64) {
    let mut cfg = config_for_scans(scans, 0.03, 0.005, 15.0, [0.0, 0.0]).unwrap();
    cfg.filter.seed = 1;
    let min_visibility = cfg.min_visibility;
    (
        track_scans_with_model(scans, cfg, front_end, None).unwrap(),
        min_visibility,
    )
}

/// The command's scores: the front end's people, the tracker's visible people (back in the
/// scan's frame) and those of them classed moving.
fn score(
    run: &PeopleRun,
    truth: &[Vec<[f64; 2]>],
    min_visibility: f64,
) -> (DetectionScore, TrackScoreSummary, TrackScoreSummary) {
    let mut detector = DetectionScore::default();
    let (mut tracks, mut walking) = (TrackScore::default(), TrackScore::default());
    for (s, people) in run.scans.iter().zip(truth) {
        let scored = s.scan >= FIRST_SCORED_SCAN;
        if scored {
            detector.add_scan(people, &s.detections).unwrap();
        }
        let [x, y, th] = s.pose.expect("both front ends give poses");
        let (sn, cs) = th.sin_cos();
        let to_sensor = |p: [f64; 2]| {
            let (dx, dy) = (p[0] - x, p[1] - y);
            [cs * dx + sn * dy, -sn * dx + cs * dy]
        };
        let visible: Vec<_> = s
            .people
            .iter()
            .filter(|p| p.visibility >= min_visibility)
            .collect();
        let est: Vec<_> = visible
            .iter()
            .map(|p| (p.label, to_sensor(p.position)))
            .collect();
        tracks.add_scan(people, &est, scored).unwrap();
        let est: Vec<_> = visible
            .iter()
            .filter(|p| p.moving)
            .map(|p| (p.label, to_sensor(p.position)))
            .collect();
        walking.add_scan(people, &est, scored).unwrap();
    }
    (detector, tracks.summary(), walking.summary())
}

fn assert_sane(d: &DetectionScore) {
    for v in [d.precision(), d.recall(), d.f1()] {
        assert!(v.is_finite() && (0.0..=1.0).contains(&v), "{d:?}");
    }
    assert!(d.false_per_scan().is_finite() && d.false_per_scan() >= 0.0);
    assert!(d.matched <= d.people.min(d.estimates));
}

#[test]
fn excerpt_is_tracked_and_scored_as_the_command_line_does() {
    let scans = scans();
    let truth = truth();
    // No --front-end: a recording gets the moving front end.
    let (run, min_visibility) = track(&scans, FrontEnd::Moving);
    assert_eq!(run.scans.len(), MESSAGES);
    for (k, s) in run.scans.iter().enumerate() {
        assert_eq!((s.scan, s.time), (k, scans[k].time));
        // the scanner stands still: the scan matching keeps it within centimetres
        let [x, y, th] = s.pose.unwrap();
        assert!(x.hypot(y) < 0.05 && th.abs() < 0.02, "{:?}", s.pose);
        for p in &s.people {
            assert!(p.existence > 0.0 && p.existence <= 1.0, "{p:?}");
            assert!((0.0..=1.0).contains(&p.visibility) && (0.0..=1.0).contains(&p.p_moving));
            assert!(p.position.iter().chain(&p.velocity).all(|v| v.is_finite()));
        }
        assert!(s.detections.iter().flatten().all(|v| v.is_finite()));
    }
    let (detector, tracks, walking) = score(&run, &truth, min_visibility);
    // Scans 9..=38 are scored, one annotated person in each.
    let scored = MESSAGES - FIRST_SCORED_SCAN;
    for d in [&detector, &tracks.detection, &walking.detection] {
        assert_eq!((d.scans, d.people), (scored, scored));
        assert_sane(d);
    }
    for t in [&tracks, &walking] {
        assert!(t.mota.is_finite() && t.mota <= 1.0, "{t:?}");
        assert!((0.0..=1.0).contains(&t.idf1), "{t:?}");
    }
}

#[test]
fn shipped_leg_model_finds_the_walker_of_the_excerpt() {
    // These scans are part of the shipped model's training data: this checks the legs path
    // end to end on real bytes, not how well the model generalises.
    let scans = scans();
    let (run, min_visibility) = track(&scans, FrontEnd::Legs);
    let (detector, tracks, _) = score(&run, &truth(), min_visibility);
    assert_sane(&detector);
    assert!(detector.recall() >= 0.9, "{detector:?}");
    assert!(detector.precision() >= 0.9, "{detector:?}");
    assert!(tracks.detection.f1() >= 0.9, "{tracks:?}");
    assert_eq!(tracks.id_switches, 0);
    // The walker is one long, moving track at walking pace.
    let walker: Vec<_> = run
        .tracks_with(20)
        .filter(|t| t.dynamic_fraction >= 0.5)
        .collect();
    assert_eq!(walker.len(), 1, "{:?}", run.tracks);
    let t = walker[0];
    assert!((0.5..1.6).contains(&t.mean_speed), "{t:?}");
    assert!(t.displacement > 2.0, "{t:?}");
}

#[test]
fn generator_cuts_the_committed_excerpt_from_the_source_bag() {
    let Some(source) = common::shared_laser2d("leg_annotated/positive_1_extracted.bag") else {
        return;
    };
    let options = excerpt::CutOptions {
        messages: MESSAGES,
        chunk_threshold: CHUNK_THRESHOLD,
    };
    let cut = excerpt::cut(&std::fs::read(&source).unwrap(), options).unwrap();
    let committed = std::fs::read(excerpt_path()).unwrap();
    assert!(
        cut == committed,
        "examples/cut_bag no longer reproduces {} ({} bytes cut, {} committed)",
        excerpt_path().display(),
        cut.len(),
        committed.len()
    );
    // And what the reader makes of it is the head of the source.
    let whole = read_bag(&source, &BagOptions::topic(SCAN_TOPIC)).unwrap();
    let part = read_bag(excerpt_path(), &BagOptions::topic(SCAN_TOPIC)).unwrap();
    assert_eq!(part.scans, whole.scans[..MESSAGES]);
    assert_eq!(part.receive_times, whole.receive_times[..MESSAGES]);
    let whole = read_pose_arrays(&source, TRUTH_TOPIC).unwrap();
    let part = read_pose_arrays(excerpt_path(), TRUTH_TOPIC).unwrap();
    assert_eq!(part, whole[..MESSAGES]);
}
