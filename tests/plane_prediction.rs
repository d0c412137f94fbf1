//! Plane prediction on a synthetic street: a ground plane and two building walls seen from a
//! vehicle before and after it drives 1 m forward while turning by 2°.

mod common;

use nalgebra::{Isometry3, Point3};
use smc_lmb::metrics::{PlanePairError, PlanePredictionSummary};
use smc_lmb::models::ExtendedConstantTurn;
use smc_lmb::pipeline::{predict_planes_between, PairPrediction, PlanePredictionConfig};
use smc_lmb::rng::seeded;

const SPACING: f64 = 0.1;
const DT: f64 = 0.1;

/// World points of the street: ground z = −1.73 for x ∈ [−5, 30], y ∈ [−10, 8); a 20 m × 6 m
/// wall on y = 8 (x ∈ [0, 20]); a 15 m × 5 m wall on x = 30 (y ∈ [−10, 5]).
fn street() -> Vec<Point3<f64>> {
    let mut pts = Vec::new();
    let steps = |len: f64| (len / SPACING).round() as usize;
    for i in 0..steps(35.0) {
        for j in 0..steps(18.0) {
            pts.push(Point3::new(
                -5.0 + i as f64 * SPACING,
                -10.0 + j as f64 * SPACING,
                -1.73,
            ));
        }
    }
    for i in 0..=steps(20.0) {
        for j in 0..=steps(6.0) {
            pts.push(Point3::new(
                i as f64 * SPACING,
                8.0,
                -1.73 + j as f64 * SPACING,
            ));
        }
    }
    for i in 0..=steps(15.0) {
        for j in 0..=steps(5.0) {
            pts.push(Point3::new(
                30.0,
                -10.0 + i as f64 * SPACING,
                -1.73 + j as f64 * SPACING,
            ));
        }
    }
    pts
}

/// Vehicle state at k (10 m/s along x, turning 2° per 0.1 s) and the two sensor poses.
fn scene() -> ([f64; 6], Isometry3<f64>, Isometry3<f64>) {
    let omega = 2f64.to_radians() / DT;
    let state = [0.0, 10.0, 0.0, 0.0, 0.0, omega];
    let next = ExtendedConstantTurn::step_noiseless(&state, DT);
    (
        state,
        ExtendedConstantTurn::pose_of(&state),
        ExtendedConstantTurn::pose_of(&next),
    )
}

fn check(result: &PairPrediction, label: &str) -> PlanePredictionSummary {
    let summary = PlanePredictionSummary::from_pairs(&result.pairs, &result.prediction_ms);
    eprintln!("{label}: {result:#?}\n{summary:#?}");
    assert_eq!(result.frame, 1);
    assert_eq!(result.predicted, 2, "{label}: walls segmented in frame k");
    assert_eq!(result.segmented, 2, "{label}: walls segmented in frame k+1");
    assert_eq!(result.pairs.len(), 2, "{label}: both walls associated");
    let mut areas: Vec<f64> = result.pairs.iter().map(|p| p.segmented_area).collect();
    areas.sort_by(f64::total_cmp);
    assert!((areas[0] - 75.0).abs() < 5.0, "{areas:?}");
    assert!((areas[1] - 120.0).abs() < 6.0, "{areas:?}");
    for p in &result.pairs {
        assert!((p.predicted_area - p.segmented_area).abs() < 3.0, "{p:?}");
    }
    assert!(summary.median_normal_angle_deg < 0.5, "{summary:?}");
    assert!(summary.median_vertex_distance_m < 0.25, "{summary:?}");
    // Every run timed its own prediction (a clock around real work reads above zero), and the
    // summary's mean is the mean of those times.
    assert!(
        result.prediction_ms.iter().all(|&ms| ms > 0.0),
        "{:?}",
        result.prediction_ms
    );
    let mean = result.prediction_ms.iter().sum::<f64>() / result.prediction_ms.len() as f64;
    assert!(
        (summary.mean_prediction_ms - mean).abs() <= 1e-12 * mean,
        "{summary:?}"
    );
    summary
}

#[test]
fn measured_motion_predicts_both_walls() {
    let world = street();
    let (_, pose_k, pose_k1) = scene();
    let mut rng = seeded(11);
    let cloud_k = common::scan(&world, &pose_k, 0.01, &mut rng);
    let cloud_k1 = common::scan(&world, &pose_k1, 0.01, &mut rng);
    let config = PlanePredictionConfig::default();
    let result = predict_planes_between(
        0, &cloud_k, &cloud_k1, &pose_k, &pose_k1, None, &config, 5, &mut rng,
    )
    .unwrap();
    assert_eq!(result.prediction_ms.len(), 5);
    check(&result, "measured");
}

#[test]
fn monte_carlo_vehicle_model_predicts_both_walls() {
    let world = street();
    let (state, pose_k, pose_k1) = scene();
    let mut rng = seeded(12);
    let cloud_k = common::scan(&world, &pose_k, 0.01, &mut rng);
    let cloud_k1 = common::scan(&world, &pose_k1, 0.01, &mut rng);
    let config = PlanePredictionConfig {
        dt: DT,
        ..PlanePredictionConfig::default()
    };
    // The poses passed are deliberately wrong: the vehicle model must not use them.
    let identity = Isometry3::identity();
    let result = predict_planes_between(
        0,
        &cloud_k,
        &cloud_k1,
        &identity,
        &identity,
        Some(state),
        &config,
        50,
        &mut rng,
    )
    .unwrap();
    assert_eq!(result.prediction_ms.len(), 50);
    check(&result, "vehicle model");
}

#[test]
fn pair_errors_serialise_with_the_reported_keys() {
    let e = PlanePairError {
        frame: 4,
        predicted_area: 10.0,
        segmented_area: 11.0,
        vertex_distances: [0.1, 0.2, 0.3, 0.4],
        normal_angle_rad: 0.01,
        normal_angle_deg: 0.01f64.to_degrees(),
    };
    let v = serde_json::to_value(&e).unwrap();
    for key in [
        "frame",
        "predicted_area",
        "segmented_area",
        "vertex_distances",
        "normal_angle_rad",
        "normal_angle_deg",
    ] {
        assert!(v.get(key).is_some(), "{key}");
    }
    assert_eq!(v["vertex_distances"].as_array().unwrap().len(), 4);
    let s = serde_json::to_value(PlanePredictionSummary::from_pairs(&[e], &[0.5])).unwrap();
    for key in [
        "median_normal_angle_deg",
        "p90_normal_angle_deg",
        "median_vertex_distance_m",
        "p90_vertex_distance_m",
        "mean_prediction_ms",
    ] {
        assert!(s.get(key).is_some(), "{key}");
    }
}

/// Writes the two-frame street as a KITTI raw drive (OXTS from the vehicle states of
/// [`scene`], Velodyne clouds seen from the resulting Velodyne poses) and returns its folder.
fn write_drive(root: &std::path::Path) -> std::path::PathBuf {
    let (state, _, _) = scene();
    let states = [state, ExtendedConstantTurn::step_noiseless(&state, DT)];
    common::write_drive(root, 42, &states, DT, |_| street())
}

#[test]
fn synthetic_kitti_drive_round_trip() {
    use smc_lmb::kitti::RawDrive;
    use smc_lmb::pipeline::predict_pairs;
    let tmp = tempfile::tempdir().unwrap();
    let dir = write_drive(tmp.path());
    let drive = RawDrive::open(&dir).unwrap();
    assert!(drive.check().is_empty(), "{:?}", drive.check());
    let mut rng = seeded(22);
    for use_vehicle_model in [true, false] {
        let config = PlanePredictionConfig {
            use_vehicle_model,
            ..PlanePredictionConfig::default()
        };
        let results = predict_pairs(&drive, None, &config, 20, &mut rng).unwrap();
        assert_eq!(results.len(), 1);
        check(
            &results[0],
            if use_vehicle_model {
                "drive, vehicle model"
            } else {
                "drive, measured"
            },
        );
    }
    // A pair beyond the last frame is refused, naming the drive folder.
    let err = predict_pairs(
        &drive,
        Some(1..2),
        &PlanePredictionConfig::default(),
        1,
        &mut rng,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("2011_09_26_drive_0042_sync"), "{err}");
}
