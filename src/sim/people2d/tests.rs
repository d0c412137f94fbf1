//! Tests of the people simulator: ray casting, occlusion, truth, determinism, odometry and
//! agreement with the breakpoint segmentation.

use super::*;
use crate::laser2d::{segment_scan, BreakpointConfig};

/// A still robot at the origin, no walls, noise-free scanner and odometry, for 1 s.
fn still(people: Vec<PersonSpec>) -> PeopleScenario {
    PeopleScenario {
        name: "test".into(),
        duration: 1.0,
        robot: RobotSpec {
            start: [0.0, 0.0, 0.0],
            legs: Vec::new(),
        },
        people,
        walls: Vec::new(),
        pillars: Vec::new(),
        scanner: ScannerSpec::default().noise_free(),
        mount: [0.2, 0.0],
        odometry_noise: OdometryNoise::none(),
    }
}

fn standing(id: u64, at: [f64; 2]) -> PersonSpec {
    PersonSpec {
        id,
        radius: 0.2,
        enter: 0.0,
        leave: None,
        start: at,
        legs: Vec::new(),
    }
}

#[test]
fn ray_geometry() {
    let t = ray_circle([0.0, 0.0], [1.0, 0.0], [5.0, 0.0], 0.2).unwrap();
    assert!((t - 4.8).abs() < 1e-12);
    assert!(ray_circle([0.0, 0.0], [-1.0, 0.0], [5.0, 0.0], 0.2).is_none());
    assert!(ray_circle([0.0, 0.0], [0.0, 1.0], [5.0, 0.0], 0.2).is_none());
    let t = ray_circle([5.0, 0.0], [1.0, 0.0], [5.0, 0.0], 0.2).unwrap();
    assert!((t - 0.2).abs() < 1e-12);
    let t = ray_segment([0.0, 0.0], [1.0, 0.0], [3.0, -1.0], [3.0, 1.0]).unwrap();
    assert!((t - 3.0).abs() < 1e-12);
    assert!(ray_segment([0.0, 0.0], [1.0, 0.0], [3.0, 0.5], [3.0, 1.0]).is_none());
    assert!(ray_segment([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [2.0, 0.0]).is_none());
    assert!(ray_segment([0.0, 0.0], [-1.0, 0.0], [3.0, -1.0], [3.0, 1.0]).is_none());
    let p = sensor_pose(Pose2::new(1.0, 2.0, FRAC_PI_2), [0.2, 0.1]);
    assert!((p.x - 0.9).abs() < 1e-12 && (p.y - 2.2).abs() < 1e-12);
}

#[test]
fn disc_straight_ahead_at_five_metres() {
    // The sensor sits at (0.2, 0); the person's centre is 5 m ahead of it.
    let sc = still(vec![standing(7, [5.2, 0.0])]);
    let run = sc.generate(1).unwrap();
    assert_eq!(run.scans.len(), 8);
    let scan = &run.scans[0];
    assert_eq!(scan.len(), 361);
    let mid = 180;
    assert!(scan.bearing(mid).abs() < 1e-12);
    assert!((scan.ranges[mid] as f64 - 4.8).abs() < 1e-5);
    for i in [mid - 1, mid + 1] {
        let r = scan.ranges[i] as f64;
        assert!((r - 4.8).abs() < 0.01, "beam {i}: {r}");
    }
    // Far off to the side there is nothing: "no return".
    assert_eq!(scan.ranges[0] as f64, 30.0);
    assert!(!scan.is_valid(0));
    assert_eq!(run.visible[0], vec![7]);
    // 0.4 m at 4.8 m spans about 4.8°, i.e. 9 or 10 beams.
    let returns = scan.valid_count();
    assert!((9..=10).contains(&returns), "{returns}");
}

#[test]
fn nearer_person_hides_farther_one() {
    let sc = still(vec![
        standing(1, [6.2, 0.0]),
        standing(2, [3.2, 0.0]),
        standing(3, [4.0, 3.0]),
    ]);
    let run = sc.generate(5).unwrap();
    for (k, vis) in run.visible.iter().enumerate() {
        assert_eq!(vis, &vec![2, 3], "scan {k}");
        assert_eq!(run.people_truth[k].len(), 3);
    }
    // With noise, the hidden one stays hidden.
    let mut noisy = sc.clone();
    noisy.scanner = ScannerSpec::default();
    let run = noisy.generate(5).unwrap();
    assert!(run.visible.iter().all(|v| !v.contains(&1)));
}

#[test]
fn static_objects_hide_people_and_fov_limits() {
    let mut sc = still(vec![standing(1, [6.0, 0.0]), standing(2, [-3.0, 0.0])]);
    sc.walls.push([[4.0, -1.0], [4.0, 1.0]]);
    let run = sc.generate(0).unwrap();
    // Person 1 behind the wall, person 2 behind the sensor.
    assert!(run.visible[0].is_empty());
    let r = run.scans[0].ranges[180] as f64;
    assert!((r - 3.8).abs() < 1e-5);
    sc.walls.clear();
    sc.pillars.push(Disc {
        center: [4.2, 0.0],
        radius: 0.5,
    });
    let run = sc.generate(0).unwrap();
    assert!(run.visible[0].is_empty());
    assert!((run.scans[0].ranges[180] as f64 - 3.5).abs() < 1e-5);
}

#[test]
fn scenario_one_truth_follows_the_velocity_table() {
    let sc = PeopleScenario::one();
    sc.validate().unwrap();
    let run = sc.generate(3).unwrap();
    assert_eq!(run.scans.len(), 240);
    let table = [
        (1, [0.625, 0.625]),
        (2, [0.625, 0.0]),
        (3, [-0.1, -0.75]),
        (4, [-0.25, -0.8]),
        (5, [-0.75, 0.6]),
    ];
    for (k, people) in run.people_truth.iter().enumerate() {
        let t = run.scans[k].time;
        assert!((t - k as f64 / 8.0).abs() < 1e-12);
        assert_eq!(people.len(), 5);
        for (&(id, pos, vel), &(tid, v)) in people.iter().zip(&table) {
            assert_eq!(id, tid);
            assert_eq!(vel, v);
            let start = sc.people[id as usize - 1].start;
            assert!((pos[0] - (start[0] + v[0] * t)).abs() < 1e-9);
            assert!((pos[1] - (start[1] + v[1] * t)).abs() < 1e-9);
        }
    }
}

#[test]
fn scenario_one_people_pass_each_other_closely_but_never_collide() {
    let run = PeopleScenario::one().generate(0).unwrap();
    let mut close_pairs = std::collections::BTreeSet::new();
    for people in &run.people_truth {
        for (i, (a, pa, _)) in people.iter().enumerate() {
            for (b, pb, _) in &people[i + 1..] {
                let d = (pa[0] - pb[0]).hypot(pa[1] - pb[1]);
                assert!(d > 0.8, "people {a} and {b} are {d:.2} m apart");
                if d < 2.0 {
                    close_pairs.insert((*a, *b));
                }
            }
        }
    }
    assert!(close_pairs.len() >= 7, "{close_pairs:?}");
}

#[test]
fn scenario_one_has_crossings_and_occlusions() {
    let sc = PeopleScenario::one();
    let run = sc.generate(11).unwrap();
    let speed_ok = sc.robot.legs.iter().all(|l| l.speed.abs() <= 2.0);
    assert!(speed_ok);
    // Every person is seen at some point.
    for id in 1..=5 {
        assert!(run.visible.iter().any(|v| v.contains(&id)), "person {id}");
    }
    // Some person is in range and in the field of view but hidden.
    let mut hidden = 0;
    for k in 0..run.scans.len() {
        let s = run.sensor_truth[k];
        for &(id, p, _) in &run.people_truth[k] {
            let (dx, dy) = (p[0] - s.x, p[1] - s.y);
            let bearing = wrap_angle(dy.atan2(dx) - s.theta);
            if dx.hypot(dy) < 12.0 && bearing.abs() < 1.4 && !run.visible[k].contains(&id) {
                hidden += 1;
            }
        }
    }
    assert!(hidden > 0);
    // The robot keeps clear of everybody.
    for k in 0..run.scans.len() {
        let r = run.robot_truth[k];
        for &(id, p, _) in &run.people_truth[k] {
            let d = (p[0] - r.x).hypot(p[1] - r.y);
            assert!(d > 0.8, "scan {k}: person {id} at {d} m");
        }
    }
}

#[test]
fn scenario_two_is_consistent() {
    let sc = PeopleScenario::two();
    sc.validate().unwrap();
    assert!(sc.people.len() >= 10);
    let run = sc.generate(2).unwrap();
    let mut entered = HashSet::new();
    let mut left = HashSet::new();
    for k in 0..run.scans.len() {
        let r = run.robot_truth[k];
        assert!(
            r.x > 0.5 && r.x < 29.5 && r.y > -9.5 && r.y < 9.5,
            "robot {r:?}"
        );
        for d in &sc.pillars {
            assert!((d.center[0] - r.x).hypot(d.center[1] - r.y) > d.radius + 0.5);
        }
        for &(id, p, _) in &run.people_truth[k] {
            assert!(p[0] > 0.0 && p[0] < 30.0 && p[1] > -10.0 && p[1] < 10.0);
            let d = (p[0] - r.x).hypot(p[1] - r.y);
            assert!(d > 0.8, "scan {k}: person {id} at {d} m");
            for pl in &sc.pillars {
                let dp = (pl.center[0] - p[0]).hypot(pl.center[1] - p[1]);
                assert!(dp > pl.radius + 0.2, "person {id} walks into a pillar");
            }
        }
        if k > 0 {
            let before: HashSet<u64> = run.people_truth[k - 1].iter().map(|e| e.0).collect();
            let now: HashSet<u64> = run.people_truth[k].iter().map(|e| e.0).collect();
            entered.extend(now.difference(&before).copied());
            left.extend(before.difference(&now).copied());
        }
    }
    assert!(entered.len() >= 4, "{entered:?}");
    assert!(left.len() >= 4, "{left:?}");
    // Most people are seen at some point (one may stay behind the robot throughout).
    let seen = (1..=10)
        .filter(|id| run.visible.iter().any(|v| v.contains(id)))
        .count();
    assert!(seen >= 8, "{seen}");
    // Turn-arounds: some person's velocity flips sign between scans.
    let mut turns = 0;
    for k in 1..run.people_truth.len() {
        for &(id, _, v) in &run.people_truth[k] {
            if let Some(&(_, _, u)) = run.people_truth[k - 1].iter().find(|e| e.0 == id) {
                if u[0] * v[0] + u[1] * v[1] < 0.0 {
                    turns += 1;
                }
            }
        }
    }
    assert!(turns >= 4, "{turns}");
    // Walls close the room: most beams return.
    let scan = &run.scans[40];
    assert!(scan.valid_count() > 250, "{}", scan.valid_count());
}

#[test]
fn deterministic_by_seed() {
    let sc = PeopleScenario::two();
    let a = sc.generate(9).unwrap();
    let b = sc.generate(9).unwrap();
    let c = sc.generate(10).unwrap();
    assert_eq!(a, b);
    assert_ne!(a.scans, c.scans);
    assert_eq!(a.robot_truth, c.robot_truth);
}

#[test]
fn odometry_noise_off_repeats_truth() {
    let mut sc = PeopleScenario::one();
    sc.odometry_noise = OdometryNoise::none();
    let run = sc.generate(4).unwrap();
    for (scan, truth) in run.scans.iter().zip(&run.robot_truth) {
        let o = scan.odometry.unwrap();
        assert!((o.x - truth.x).abs() < 1e-9 && (o.y - truth.y).abs() < 1e-9);
        assert!(wrap_angle(o.theta - truth.theta).abs() < 1e-9);
        let l = scan.laser_pose.unwrap();
        let s = sensor_pose(*truth, sc.mount);
        assert!((l.x - s.x).abs() < 1e-9 && (l.y - s.y).abs() < 1e-9);
    }
    // With noise the odometry drifts, but not wildly.
    let run = PeopleScenario::one().generate(4).unwrap();
    let last = run.scans.last().unwrap().odometry.unwrap();
    let truth = run.robot_truth.last().unwrap();
    let err = (last.x - truth.x).hypot(last.y - truth.y);
    assert!(err > 1e-4 && err < 5.0, "{err}");
}

#[test]
fn rejects_invalid_scenarios() {
    let mut sc = still(vec![standing(1, [2.0, 0.0]), standing(1, [3.0, 0.0])]);
    assert!(sc.generate(0).is_err());
    sc.people.pop();
    sc.scanner.beams = 1;
    assert!(sc.generate(0).is_err());
    sc.scanner.beams = 361;
    sc.scanner.sigma_range = -1.0;
    assert!(sc.generate(0).is_err());
    sc.scanner.sigma_range = 0.0;
    sc.people[0].radius = 0.0;
    assert!(sc.generate(0).is_err());
    sc.people[0].radius = 0.2;
    sc.people[0].leave = Some(0.0);
    assert!(sc.generate(0).is_err());
    sc.people[0].leave = None;
    sc.duration = f64::NAN;
    assert!(sc.generate(0).is_err());
}

/// Every visible person has a segment whose centre, taken to the world with the true sensor
/// pose, lies within `tol` of the person's surface.
fn segments_match_visible_people(sc: &PeopleScenario, seed: u64, scans: &[usize], tol: f64) {
    let run = sc.generate(seed).unwrap();
    for &k in scans {
        let scan = &run.scans[k];
        let segments = segment_scan(scan, &BreakpointConfig::default()).unwrap();
        let s = run.sensor_truth[k];
        let (sn, cs) = s.theta.sin_cos();
        let centres: Vec<[f64; 2]> = segments
            .iter()
            .map(|g| {
                let [x, y] = g.center;
                [s.x + cs * x - sn * y, s.y + sn * x + cs * y]
            })
            .collect();
        for &id in &run.visible[k] {
            let (_, p, _) = run.people_truth[k]
                .iter()
                .find(|e| e.0 == id)
                .copied()
                .unwrap();
            let radius = sc.people.iter().find(|q| q.id == id).unwrap().radius;
            let best = centres
                .iter()
                .map(|c| ((c[0] - p[0]).hypot(c[1] - p[1]) - radius).abs())
                .fold(f64::INFINITY, f64::min);
            assert!(best < tol, "scan {k}: person {id}: nearest centre {best} m");
        }
    }
}

#[test]
fn segmentation_finds_visible_people_in_scenario_one() {
    let mut sc = PeopleScenario::one();
    sc.scanner = sc.scanner.noise_free();
    let scans: Vec<usize> = (0..240).step_by(10).collect();
    segments_match_visible_people(&sc, 1, &scans, 0.3);
    // At the default noise (0.2 m, 2°: about 0.4 m sideways at 12 m) the nearest centre
    // stays close.
    let noisy = PeopleScenario::one();
    segments_match_visible_people(&noisy, 1, &[40, 80, 120], 0.75);
}
