//! Building walls of a simulated street drive, where the truth is known: the plane extraction
//! finds every wall that shows at least 2,000 points in at least 90 % of the frames, and the
//! plane prediction from frame k to k + 1 (measured ego motion and the ECT vehicle model,
//! seed 001 Algorithm 1) lands within 0.5° (median normal angle) and 0.25 m (median vertex
//! distance) of the planes segmented at k + 1.

use nalgebra::Vector3;
use smc_lmb::cloud::planes::{extract_planes, PlaneConfig};
use smc_lmb::kitti::RawDrive;
use smc_lmb::metrics::plane_prediction::{PlanePairError, PlanePredictionSummary};
use smc_lmb::pipeline::plane_prediction::{predict_pairs, PlanePredictionConfig};
use smc_lmb::sim::street::{generate, write_drive, StreetConfig, Surface};

const FRAMES: usize = 12;
const SEED: u64 = 3;

#[test]
fn every_wall_with_2000_points_in_view_is_found_in_90_percent_of_frames() {
    let run = generate(&StreetConfig::default(), FRAMES, SEED).unwrap();
    let truth = &run.truth;
    let (mut chances, mut found) = (0usize, 0usize);
    let mut missed = Vec::new();
    for (k, scan) in run.scans.iter().enumerate() {
        let pose = truth.frames[k].velodyne_pose.to_isometry();
        let mut rng = smc_lmb::rng::seeded(k as u64);
        let seg = extract_planes(&scan.cloud, &PlaneConfig::default(), &mut rng).unwrap();
        // A detected wall "is" the truth wall that holds most of its inliers, when its normal
        // agrees within 2°.
        let mut detected = std::collections::BTreeSet::new();
        for det in &seg.walls {
            let mut votes = std::collections::BTreeMap::new();
            for &i in &det.inliers {
                if let Surface::Wall(id) = scan.surfaces[i as usize] {
                    *votes.entry(id).or_insert(0usize) += 1;
                }
            }
            let Some((&id, _)) = votes.iter().max_by_key(|(_, n)| **n) else {
                continue;
            };
            let normal = (pose * det.patch.plane.normal).normalize();
            let truth_normal = Vector3::from(truth.walls[id as usize].normal);
            if normal.dot(&truth_normal).abs() > 2f64.to_radians().cos() {
                detected.insert(id);
            }
        }
        for wall in truth.walls.iter().filter(|w| w.points[k] >= 2000) {
            chances += 1;
            if detected.contains(&wall.id) {
                found += 1;
            } else {
                missed.push((k, wall.id, wall.points[k]));
            }
        }
    }
    assert!(chances >= FRAMES, "too few big walls in view: {chances}");
    let rate = found as f64 / chances as f64;
    eprintln!(
        "walls with ≥ 2000 points found: {found} of {chances} ({rate:.3}); missed {missed:?}"
    );
    assert!(rate >= 0.9, "found {found} of {chances}; missed {missed:?}");
}

fn summary(config: &PlanePredictionConfig, runs: usize) -> PlanePredictionSummary {
    let dir = tempfile::tempdir().unwrap();
    let written = write_drive(dir.path(), &StreetConfig::default(), FRAMES, SEED, |_| {}).unwrap();
    let drive = RawDrive::open(&written.dir).unwrap();
    let mut rng = smc_lmb::rng::seeded(SEED);
    let results = predict_pairs(&drive, None, config, runs, &mut rng).unwrap();
    assert_eq!(results.len(), FRAMES - 1);
    let pairs: Vec<PlanePairError> = results.iter().flat_map(|r| r.pairs.clone()).collect();
    let timings: Vec<f64> = results
        .iter()
        .flat_map(|r| r.prediction_ms.iter().copied())
        .collect();
    // Most frame pairs associate several walls.
    assert!(pairs.len() >= 2 * (FRAMES - 1), "{} pairs", pairs.len());
    PlanePredictionSummary::from_pairs(&pairs, &timings)
}

#[test]
fn measured_ego_motion_predicts_the_next_frames_walls() {
    let config = PlanePredictionConfig {
        use_vehicle_model: false,
        ..PlanePredictionConfig::default()
    };
    let s = summary(&config, 1);
    eprintln!("measured motion: {s:?}");
    assert!(s.median_normal_angle_deg < 0.5, "{s:?}");
    assert!(s.median_vertex_distance_m < 0.25, "{s:?}");
}

#[test]
fn ect_vehicle_model_predicts_the_next_frames_walls() {
    let s = summary(&PlanePredictionConfig::default(), 5);
    eprintln!("ECT Monte Carlo: {s:?}");
    assert!(s.median_normal_angle_deg < 0.5, "{s:?}");
    assert!(s.median_vertex_distance_m < 0.25, "{s:?}");
}
