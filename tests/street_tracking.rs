//! Walls and clusters of a simulated street tracked by one LMB run and scored against the
//! street's truth.
//!
//! The cluster bound. With p = 1 the OSPA of a frame splits into a localisation part
//! Σ_pairs min(d, c) / max(n, m) and a cardinality part c·|n − m| / max(n, m) (n truth
//! objects, m tracks). A cluster's centroid is the mean of the points on the object's faces
//! that the lidar sees, up to half the object's length from the box centre (2.25 m for the
//! 4.5 m cars); the detector measures the centre of a box whose unseen sides the visible-face
//! model extends to the class's mean size, so what is left is the spread of real sizes about
//! that mean: b = 0.235 m, half the spread of car lengths. A tracker that follows every
//! visible object within b therefore has a localisation part of at most
//! b · min(n, m) / max(n, m) in every frame — the bound asserted below, averaged over the
//! frames after the first two (a birth needs two detections to be confirmed). The cardinality
//! part is bounded through the miss count: after those two frames the tracker must miss fewer
//! than 0.5 visible objects per frame on average.

use smc_lmb::kitti::RawDrive;
use smc_lmb::pipeline::drive_evaluation::{
    evaluate_clusters, evaluate_recording, evaluate_walls, street_object_truth,
    ClusterEvaluationConfig, EvaluationOptions,
};
use smc_lmb::pipeline::{track_recording, TrackingConfig};
use smc_lmb::sim::street::{write_drive, StreetConfig};

const FRAMES: usize = 16;

#[test]
fn cluster_and_wall_tracks_of_a_simulated_street_meet_their_bounds() {
    let dir = tempfile::tempdir().unwrap();
    let written = write_drive(dir.path(), &StreetConfig::default(), FRAMES, 1, |_| {}).unwrap();
    let drive = RawDrive::open(&written.dir).unwrap();
    let tracks = track_recording(&drive, None, &TrackingConfig::default(), 1, |_| Ok(())).unwrap();
    assert_eq!(tracks.frames.len(), FRAMES);

    // Walls: every confirmed wall with a rectangle lies on a truth wall.
    let walls = evaluate_walls(&tracks, &written.truth).unwrap();
    eprintln!("walls: {walls:?}");
    assert!(walls.reports >= 2 * FRAMES, "{walls:?}");
    assert!(
        walls.matched as f64 >= 0.95 * walls.reports as f64,
        "{walls:?}"
    );
    assert!(walls.median_normal_angle_deg < 0.5, "{walls:?}");

    // Clusters.
    let truth = street_object_truth(&written.truth, 15, 40.0);
    let config = ClusterEvaluationConfig::default();
    let eval = evaluate_clusters(&tracks, &truth, &config).unwrap();
    let settled = &eval.frames[2..];
    assert!(settled.iter().map(|f| f.truth).sum::<usize>() >= settled.len());
    let n = settled.len() as f64;
    // A track's position is its detections' box centre (visible-face model): what is left is
    // the class size spread the model extends the unseen sides by, at most half the spread of
    // car lengths (0.47 m, `cloud::classes`), per matched pair.
    let box_error = 0.47 / 2.0;
    let bound: f64 = settled
        .iter()
        .map(|f| {
            let (lo, hi) = (f.truth.min(f.estimates), f.truth.max(f.estimates));
            if hi == 0 {
                0.0
            } else {
                box_error * lo as f64 / hi as f64
            }
        })
        .sum::<f64>()
        / n;
    let localisation = settled.iter().map(|f| f.ospa_localisation).sum::<f64>() / n;
    let missed = settled.iter().map(|f| f.missed).sum::<usize>() as f64 / n;
    let false_tracks = settled.iter().map(|f| f.false_tracks).sum::<usize>() as f64 / n;
    eprintln!(
        "clusters: mean OSPA {:.3} (localisation {localisation:.3}, bound {bound:.3}), missed \
         {missed:.2}/frame, false {false_tracks:.2}/frame, switches {}",
        eval.mean_ospa, eval.labels.switches
    );
    assert!(
        localisation <= bound,
        "localisation {localisation} > {bound}"
    );
    assert!(missed < 0.5, "missed {missed} per frame");

    // The drive as a recording scores the same through its own labels (its truth.json).
    let options = EvaluationOptions::default();
    let by_recording = evaluate_recording(&tracks, &drive, &options).unwrap();
    assert_eq!(by_recording.clusters, eval);
    assert_eq!(by_recording.walls.as_ref(), Some(&walls));
    // Only a tracking sequence's labels have a camera view.
    let camera = EvaluationOptions {
        camera_view: true,
        ..options
    };
    let err = evaluate_recording(&tracks, &drive, &camera)
        .unwrap_err()
        .to_string();
    assert!(err.contains("camera view"), "{err}");
    // Without its truth.json the drive has nothing to score against, and says which drive.
    std::fs::remove_file(written.dir.join("truth.json")).unwrap();
    let err = evaluate_recording(&tracks, &drive, &options)
        .unwrap_err()
        .to_string();
    assert!(err.contains("has no labels"), "{err}");
    assert!(err.contains(&written.dir.display().to_string()), "{err}");
}
