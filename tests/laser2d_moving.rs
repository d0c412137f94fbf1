//! The moving-object detector (seed 003) on the simulated people scenarios: static structure
//! is removed and people are found (scenario two, a lobby), and ICP keeps the pose from
//! drifting with the odometry (scenario one).

use smc_lmb::geometry::Pose2;
use smc_lmb::laser2d::moving::{MovingDetectorConfig, MovingObjectDetector};
use smc_lmb::sim::people2d::{People2dRun, PeopleScenario};

/// Scans before the background and the votes have settled.
const WARM_UP: usize = 8;

/// A cluster is correct when its centroid lies within this distance of a visible person (m).
const HIT_RADIUS: f64 = 0.5;

struct Score {
    clusters: usize,
    correct_clusters: usize,
    visible: usize,
    found: usize,
}

impl Score {
    fn precision(&self) -> f64 {
        self.correct_clusters as f64 / self.clusters.max(1) as f64
    }
    fn recall(&self) -> f64 {
        self.found as f64 / self.visible.max(1) as f64
    }
}

fn detector_for(scenario: &PeopleScenario) -> MovingObjectDetector {
    let sc = &scenario.scanner;
    MovingObjectDetector::new(MovingDetectorConfig::for_scanner(
        sc.sigma_bearing,
        sc.angle_increment(),
        scenario.mount,
    ))
    .unwrap()
}

/// Runs the detector over the whole run; returns the score after the warm-up and the
/// corrected robot poses.
fn run_detector(scenario: &PeopleScenario, run: &People2dRun) -> (Score, Vec<Pose2>) {
    let mut det = detector_for(scenario);
    let mut score = Score {
        clusters: 0,
        correct_clusters: 0,
        visible: 0,
        found: 0,
    };
    let mut poses = Vec::new();
    let started = std::time::Instant::now();
    for (k, scan) in run.scans.iter().enumerate() {
        let d = det.process(scan, scan.odometry.unwrap()).unwrap();
        poses.push(d.pose);
        if k < WARM_UP {
            continue;
        }
        let visible: Vec<[f64; 2]> = run.people_truth[k]
            .iter()
            .filter(|p| run.visible[k].contains(&p.0))
            .map(|p| p.1)
            .collect();
        let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) <= HIT_RADIUS;
        score.clusters += d.clusters.len();
        score.correct_clusters += d
            .clusters
            .iter()
            .filter(|c| visible.iter().any(|&p| near(c.centroid, p)))
            .count();
        score.visible += visible.len();
        score.found += visible
            .iter()
            .filter(|&&p| d.clusters.iter().any(|c| near(c.centroid, p)))
            .count();
    }
    // Throughput, reported only (no timed assertions).
    let rate = run.scans.len() as f64 / started.elapsed().as_secs_f64().max(1e-9);
    eprintln!("{}: {rate:.0} scans/s", scenario.name);
    (score, poses)
}

fn position_error(a: Pose2, b: Pose2) -> f64 {
    (a.x - b.x).hypot(a.y - b.y)
}

#[test]
fn lobby_static_structure_is_removed_and_people_are_found() {
    let scenario = PeopleScenario::two();
    for seed in [1u64, 2] {
        let run = scenario.generate(seed).unwrap();
        let (score, _) = run_detector(&scenario, &run);
        eprintln!(
            "scenario two seed {seed}: {} clusters, precision {:.3}, recall {:.3} ({} of {} \
             visible people)",
            score.clusters,
            score.precision(),
            score.recall(),
            score.found,
            score.visible
        );
        assert!(score.visible > 500);
        // Measured (seeds 1, 2): precision 0.867 and 0.895, recall 0.225 and 0.190. The
        // simulated scanner's 2° bearing noise scatters the 3–6 returns of a person more than
        // 4 m away over as many beams as the person covers, so most distant people never form
        // a cluster of three candidates holding a local minimum; nearly every reported
        // cluster is a person. Bounds leave margin for other noise draws.
        assert!(score.precision() >= 0.75, "precision {}", score.precision());
        assert!(score.recall() >= 0.12, "recall {}", score.recall());
    }
}

#[test]
fn icp_keeps_the_pose_closer_to_the_truth_than_odometry() {
    let base = PeopleScenario::one();
    // Seed 000's first experiment has no static objects, so there is nothing for scan
    // matching to hold on to; the same run is also made in a hall with pillars (the walls
    // alone would leave the motion along them unobservable).
    let mut hall = PeopleScenario {
        walls: smc_lmb::sim::people2d::box_walls([-5.0, 38.0], [-8.0, 26.0]).to_vec(),
        ..base.clone()
    };
    for (i, c) in [
        [6.0, -4.0],
        [14.0, 3.0],
        [18.0, -5.0],
        [26.0, 6.0],
        [30.0, -3.0],
        [10.0, 12.0],
        [22.0, 17.0],
    ]
    .into_iter()
    .enumerate()
    {
        let _ = i;
        hall.pillars.push(smc_lmb::sim::people2d::Disc {
            center: c,
            radius: 0.3,
        });
    }
    let lobby = PeopleScenario::two();
    let (mut sum_odometry, mut sum_corrected) = (0.0, 0.0);
    for (name, scenario) in [("open", &base), ("hall", &hall), ("lobby", &lobby)] {
        for seed in [1u64, 2] {
            let run = scenario.generate(seed).unwrap();
            let (_, poses) = run_detector(scenario, &run);
            let last = run.scans.len() - 1;
            let odo = position_error(run.scans[last].odometry.unwrap(), run.robot_truth[last]);
            let cor = position_error(poses[last], run.robot_truth[last]);
            let max_cor = poses
                .iter()
                .zip(&run.robot_truth)
                .map(|(&p, &t)| position_error(p, t))
                .fold(0.0, f64::max);
            eprintln!(
                "{name} seed {seed}: final error odometry {odo:.3} m, \
                 corrected {cor:.3} m (max {max_cor:.3} m)"
            );
            if name == "open" {
                // Too few returns to match: the detector keeps the odometry as it is.
                assert!((cor - odo).abs() < 1e-9, "{cor} vs {odo}");
            } else {
                // Measured: at most 0.99 m over the hall and lobby runs, while the odometry
                // drifts without bound (1.31 m after 30 s in the hall, seed 1).
                assert!(max_cor < 1.2, "{name} seed {seed}: {max_cor}");
                sum_odometry += odo;
                sum_corrected += cor;
            }
        }
    }
    // Measured: 1.79 m against 2.76 m over the four runs. The map-matched pose does not
    // reach a third of the odometry error in every run (the odometry of seed 2 happens to
    // drift only 0.22–0.28 m), so the bound is on the sum.
    assert!(
        sum_corrected < 0.8 * sum_odometry,
        "{sum_corrected} vs {sum_odometry}"
    );
}

/// Per-stage recall of the detector in the lobby: the share of visible people (after the
/// warm-up) that a candidate return, a cluster of enough returns, a cluster past the
/// local-minimum test, a persisting cluster and a moving cluster lies within `HIT_RADIUS` of.
fn stage_recall(
    scenario: &PeopleScenario,
    run: &People2dRun,
    rule: smc_lmb::laser2d::moving::MovingRule,
) -> [f64; 5] {
    use smc_lmb::laser2d::moving::ClusterStage;
    let mut det = MovingObjectDetector::new(MovingDetectorConfig {
        rule,
        ..detector_for(scenario).config().to_owned()
    })
    .unwrap();
    let mut hits = [0usize; 5];
    let mut visible_total = 0;
    for (k, scan) in run.scans.iter().enumerate() {
        let d = det.process(scan, scan.odometry.unwrap()).unwrap();
        if k < WARM_UP {
            continue;
        }
        let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) <= HIT_RADIUS;
        let candidates: Vec<[f64; 2]> = d
            .candidates
            .iter()
            .map(|&b| {
                smc_lmb::geometry::pose2::transform_point(d.sensor_pose, scan.point(b).unwrap())
            })
            .collect();
        // Clusters past each stage: past size, past local minimum, past persistence, moving.
        let past = |c: &ClusterStage, stage: usize| match c {
            ClusterStage::TooSmall => false,
            ClusterStage::NoLocalMinimum => stage < 1,
            ClusterStage::NotPersistent => stage < 2,
            ClusterStage::NotDominant => stage < 3,
            ClusterStage::Moving => true,
        };
        for (id, p, _) in &run.people_truth[k] {
            if !run.visible[k].contains(id) {
                continue;
            }
            visible_total += 1;
            hits[0] += candidates.iter().any(|&q| near(q, *p)) as usize;
            for stage in 0..4 {
                hits[stage + 1] += d
                    .all_clusters
                    .iter()
                    .any(|c| past(&c.stage, stage) && near(c.centroid, *p))
                    as usize;
            }
        }
    }
    hits.map(|h| h as f64 / visible_total.max(1) as f64)
}

#[test]
fn lobby_recall_by_stage_and_rule() {
    use smc_lmb::laser2d::moving::MovingRule;
    let scenario = PeopleScenario::two();
    let run = scenario.generate(1).unwrap();
    let voting = stage_recall(&scenario, &run, MovingRule::Voting);
    let attenuation = stage_recall(&scenario, &run, MovingRule::Attenuation { veto: false });
    let veto = stage_recall(&scenario, &run, MovingRule::Attenuation { veto: true });
    for (name, r) in [
        ("voting", voting),
        ("attenuation", attenuation),
        ("veto", veto),
    ] {
        eprintln!(
            "{name}: recall of candidates {:.3}, clusters {:.3}, local minima {:.3}, \
             persistence {:.3}, moving {:.3}",
            r[0], r[1], r[2], r[3], r[4]
        );
    }
    // Each stage can only lose people.
    for r in [voting, attenuation, veto] {
        assert!(r.windows(2).all(|w| w[1] <= w[0] + 1e-12), "{r:?}");
    }
    // The same background and clustering feed both rules.
    assert!((voting[0] - attenuation[0]).abs() < 0.1 && (voting[1] - attenuation[1]).abs() < 0.1);
    // Attenuation keeps what the clusters found; the paper's rule loses most of it.
    assert!((attenuation[4] - attenuation[1]).abs() < 1e-12);
    assert!(
        attenuation[4] > 2.0 * voting[4],
        "{attenuation:?} vs {voting:?}"
    );
}

/// The first `scans` scans of `run`.
fn slice(run: &People2dRun, scans: usize) -> People2dRun {
    let n = scans.min(run.scans.len());
    People2dRun {
        scans: run.scans[..n].to_vec(),
        robot_truth: run.robot_truth[..n].to_vec(),
        sensor_truth: run.sensor_truth[..n].to_vec(),
        people_truth: run.people_truth[..n].to_vec(),
        visible: run.visible[..n].to_vec(),
    }
}

#[test]
fn in_the_lobby_the_lmb_tracks_far_better_on_the_moving_front_end() {
    use smc_lmb::pipeline::people_tracking::evaluate::{evaluate_run, EvalConfig};
    use smc_lmb::pipeline::people_tracking::front_end::{adapt_tracker_config, FrontEnd};
    use smc_lmb::pipeline::people_tracking::{PeopleTracker, PeopleTrackerConfig};
    let scenario = PeopleScenario::two();
    // The first 20 s (160 scans): on every segment the LMB follows a crowd of wall and
    // pillar pieces and is slow, so the whole run would be too long for a test.
    let run = slice(&scenario.generate(1).unwrap(), 160);
    let s = &scenario.scanner;
    let score = |front_end: FrontEnd| {
        let mut people = PeopleTrackerConfig::for_scanner(
            s.sigma_range,
            s.sigma_bearing,
            s.range_max,
            s.fov / 2.0,
            scenario.mount,
        );
        people.filter.seed = 1;
        adapt_tracker_config(&mut people, front_end);
        let mut lmb = PeopleTracker::new(people.clone()).unwrap();
        let eval = EvalConfig {
            front_end,
            ..EvalConfig::default()
        };
        evaluate_run(&mut lmb, &run, &people, &eval).unwrap()
    };
    let segments = score(FrontEnd::Segments);
    let moving = score(FrontEnd::Moving);
    eprintln!(
        "lobby, 160 scans, LMB: segments OSPA {:.3} OSPA(2) {:.3}; moving OSPA {:.3} OSPA(2) {:.3}",
        segments.mean_ospa, segments.ospa2, moving.mean_ospa, moving.ospa2
    );
    assert_eq!(moving.scans, 160);
    // Whole run, seeds 1–3: mean OSPA 1.75 on segments against 0.77 on the moving front end
    // (cut-off 2 m). On every segment the LMB sits near the cut-off.
    assert!(segments.mean_ospa > 1.4, "{}", segments.mean_ospa);
    assert!(
        moving.mean_ospa < segments.mean_ospa - 0.5,
        "moving {} vs segments {}",
        moving.mean_ospa,
        segments.mean_ospa
    );
    assert!(
        moving.ospa2 < segments.ospa2,
        "{} vs {}",
        moving.ospa2,
        segments.ospa2
    );
}
