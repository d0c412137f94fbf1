//! The recording path of people tracking: a vendored excerpt of the Intel Research Lab CARMEN
//! log goes through reading, tracking and the JSON writer.

use smc_lmb::laser2d::{
    config_for_scans, read_carmen, track_scans, write_people_json, CarmenOptions, PeopleRun,
    TimeOrder,
};

#[test]
fn intel_excerpt_runs_end_to_end_and_round_trips_as_json() {
    // the log has an ODOM record whose time stamp steps back: skip such records
    let options = CarmenOptions {
        time_order: TimeOrder::Skip,
        ..CarmenOptions::default()
    };
    let log = read_carmen("tests/data/laser2d/intel_head.clf", options).unwrap();
    let scans = log.flaser;
    // 20 FLASER lines, two of which step back in time
    assert_eq!(scans.len(), 18);
    let cfg = config_for_scans(&scans, 0.03, 0.005, 30.0, [0.0, 0.0]).unwrap();
    // 180 beams of 1° from −90°: a ±90° field of view
    let smc_lmb::config::DetectionConfig::FieldOfView { half_angle, .. } = cfg.filter.detection
    else {
        panic!("field-of-view detection expected");
    };
    assert!(
        (half_angle - std::f64::consts::FRAC_PI_2).abs() < 1e-6,
        "{half_angle}"
    );
    let run = track_scans(&scans, cfg).unwrap();
    assert_eq!(run.scans.len(), scans.len());
    for (i, s) in run.scans.iter().enumerate() {
        assert_eq!(s.scan, i);
        assert_eq!(s.time, scans[i].time);
        let pose = s.pose.expect("FLASER lines carry odometry");
        for p in &s.people {
            assert!(p.existence > 0.0 && p.existence <= 1.0);
            assert!((0.0..=1.0).contains(&p.visibility) && (0.0..=1.0).contains(&p.p_moving));
            // every person the scanner is said to see lies within its range
            if p.visibility > 0.0 {
                let d = (p.position[0] - pose[0]).hypot(p.position[1] - pose[1]);
                assert!(d < 30.5, "{p:?} at {d} m");
            }
        }
    }
    // something person-sized is seen in a lab full of furniture legs and door frames
    assert!(run.scans.iter().any(|s| !s.people.is_empty()));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("people.json");
    write_people_json(&path, &run).unwrap();
    let back: PeopleRun = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    assert_eq!(back.scans.len(), run.scans.len());
    assert_eq!(back.tracks.len(), run.tracks.len());
    for (a, b) in back.scans.iter().zip(&run.scans) {
        assert_eq!(a.people.len(), b.people.len());
        for (p, q) in a.people.iter().zip(&b.people) {
            assert_eq!(p.label, q.label);
            assert!((p.position[0] - q.position[0]).abs() < 1e-9);
            assert!((p.position[1] - q.position[1]).abs() < 1e-9);
        }
    }
}
