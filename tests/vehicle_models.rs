//! A user's models reach a real drive: a vehicle model of one's own goes through the paper's
//! plane prediction (Gostar et al. 2019, Algorithm 1) and the drive tracker's wall
//! transition, and a road-user motion model of one's own moves the tracker's clusters. On the
//! shared frames of drive 0005 a deliberately poor vehicle model (the car stands still) predicts
//! the walls worse than the extended constant turn, and the tracker calls the user's road-user
//! model and its tracks change with it; so are its own detection and clutter models, each asked
//! only about its kind of object.

mod common;

use nalgebra::{Isometry3, Vector3};
use smc_lmb::filter::{ParticleSet, StepContext, TransitionModel};
use smc_lmb::kitti::RawDrive;
use smc_lmb::metrics::plane_prediction::PlanePredictionSummary;
use smc_lmb::models::{
    ConstantVelocity, ExtendedConstantTurn, KinematicBicycle, SharedVehicleModel, VehicleModel,
    VehicleState,
};
use smc_lmb::pipeline::drive_tracking::{
    track_recording, DriveTracks, EgoModel, OwnModels, RoadUserMotion, TrackingConfig,
};
use smc_lmb::pipeline::{predict_pairs, PlanePredictionConfig};
use smc_lmb::rng::seeded;
use smc_lmb::FilterRng;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

const DRIVE: &str = "kitti_raw/2011_09_26/2011_09_26_drive_0005_sync";

/// A car that never moves: state [X, Y, φ].
struct StandsStill;

impl VehicleModel for StandsStill {
    fn state_dim(&self) -> usize {
        3
    }
    fn state_of(&self, m: &VehicleState) -> Vec<f64> {
        vec![m.x, m.y, m.heading]
    }
    fn sample_step(&self, s: &[f64], _: f64, _: &mut FilterRng, next: &mut [f64]) {
        next.copy_from_slice(s);
    }
    fn mean_step(&self, s: &[f64], _: f64, next: &mut [f64]) {
        next.copy_from_slice(s);
    }
    fn pose_of(&self, s: &[f64]) -> Isometry3<f64> {
        Isometry3::new(Vector3::new(s[0], s[1], 0.0), Vector3::new(0.0, 0.0, s[2]))
    }
}

fn summary(drive: &RawDrive, vehicle: SharedVehicleModel) -> PlanePredictionSummary {
    let config = PlanePredictionConfig {
        vehicle,
        ..PlanePredictionConfig::default()
    };
    let results = predict_pairs(drive, Some(0..12), &config, 5, &mut seeded(2)).unwrap();
    let pairs: Vec<_> = results.iter().flat_map(|r| r.pairs.clone()).collect();
    PlanePredictionSummary::from_pairs(&pairs, &[])
}

#[test]
fn a_car_that_stands_still_predicts_the_walls_worse_than_ect() {
    let Some(dir) = common::shared_data(DRIVE) else {
        return;
    };
    let drive = RawDrive::open(&dir).unwrap();
    let ect = summary(
        &drive,
        SharedVehicleModel::new(ExtendedConstantTurn::new(0.5, 0.1).unwrap()),
    );
    let still = summary(&drive, SharedVehicleModel::new(StandsStill));
    let bicycle = summary(
        &drive,
        SharedVehicleModel::new(KinematicBicycle::new(2.7, 0.5, 0.05).unwrap()),
    );
    println!("ECT {ect:?}\nstands still {still:?}\nbicycle {bicycle:?}");
    // The car drives about 0.35 m a frame: a model that ignores it misplaces every vertex by
    // about that much, where the ECT's draws land within a few centimetres of it.
    assert!(ect.pairs >= 20, "{ect:?}");
    assert!(
        still.median_vertex_distance_m > ect.median_vertex_distance_m + 0.1,
        "stands still {still:?} vs ECT {ect:?}"
    );
    // A kinematic bicycle started from the same OXTS state follows the car too. (The two
    // runs segment the frames with what is left of one random stream after the vehicle
    // draws, so their walls differ a little: compare each with the car that stands still.)
    assert!(
        bicycle.median_vertex_distance_m < still.median_vertex_distance_m - 0.1,
        "bicycle {bicycle:?} vs stands still {still:?}"
    );
}

/// Constant velocity that counts the particle sets it moves.
struct Counting {
    inner: ConstantVelocity,
    calls: Arc<AtomicUsize>,
}

impl TransitionModel for Counting {
    fn state_dim(&self) -> usize {
        6
    }
    fn predict(
        &self,
        p: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> smc_lmb::Result<()> {
        self.calls.fetch_add(1, Ordering::Relaxed);
        self.inner.predict(p, ctx, rng)
    }
}

fn track(drive: &RawDrive, config: &TrackingConfig) -> DriveTracks {
    track_recording(drive, Some(0..6), config, 3, |_| Ok(())).unwrap()
}

fn cluster_positions(t: &DriveTracks) -> Vec<[f64; 3]> {
    t.frames
        .iter()
        .flat_map(|f| f.clusters.iter().map(|c| c.position_world))
        .collect()
}

#[test]
fn the_tracker_moves_road_users_with_the_users_model() {
    let Some(dir) = common::shared_data(DRIVE) else {
        return;
    };
    let drive = RawDrive::open(&dir).unwrap();
    let default = track(&drive, &TrackingConfig::default());

    // The same constant velocity as the default (without its manoeuvre fringe), counted.
    let calls = Arc::new(AtomicUsize::new(0));
    let mut config = TrackingConfig::default();
    config.cluster.motion = RoadUserMotion::custom(Counting {
        inner: ConstantVelocity::spatial(config.cluster.sigma_accel).unwrap(),
        calls: calls.clone(),
    });
    let counted = track(&drive, &config);
    let n = calls.load(Ordering::Relaxed);
    // every cluster track is predicted once a frame after its first
    assert!(n > 100, "the user's model was called {n} times");
    assert_ne!(cluster_positions(&counted), cluster_positions(&default));
    // walls are not the road users' business: the same wall reports in both runs
    let walls = |t: &DriveTracks| t.frames.iter().map(|f| f.planes.len()).collect::<Vec<_>>();
    assert!(walls(&counted).iter().sum::<usize>() > 0);
}

#[test]
fn a_road_user_model_of_the_wrong_length_is_refused_naming_it() {
    let mut config = TrackingConfig::default();
    config.cluster.motion = RoadUserMotion::custom(
        smc_lmb::models::CoordinatedTurn::new(0.5, 0.1).unwrap(), // 5 components
    );
    let e = smc_lmb::pipeline::DriveTracker::new(&config, 1)
        .unwrap_err()
        .to_string();
    assert!(e.contains("CoordinatedTurn") && e.contains("5"), "{e}");
}

#[test]
fn a_vehicle_model_named_in_a_configuration_moves_the_walls() {
    let Some(dir) = common::shared_data(DRIVE) else {
        return;
    };
    let drive = RawDrive::open(&dir).unwrap();
    let text =
        r#"{"ego": {"kind": "vehicle", "model": "bicycle", "parameters": {"wheelbase": 2.9}}}"#;
    let config: TrackingConfig = serde_json::from_str(text).unwrap();
    assert_eq!(
        config.ego,
        EgoModel::Vehicle {
            model: "bicycle".into(),
            parameters: [("wheelbase".to_string(), 2.9)].into_iter().collect(),
        }
    );
    let t = track(&drive, &config);
    assert_eq!(t.ego, "oxts+bicycle");
    assert!(t.frames.iter().any(|f| !f.planes.is_empty()));
    // a user's own vehicle model, and an unknown name
    let own = TrackingConfig {
        ego: EgoModel::custom(StandsStill),
        ..TrackingConfig::default()
    };
    assert_eq!(track(&drive, &own).ego, "oxts+StandsStill");
    let bad = r#"{"ego": {"kind": "vehicle", "model": "hovercraft"}}"#;
    let config: TrackingConfig = serde_json::from_str(bad).unwrap();
    let e = track_recording(&drive, Some(0..2), &config, 1, |_| Ok(()))
        .unwrap_err()
        .to_string();
    assert!(e.contains("hovercraft") && e.contains("bicycle"), "{e}");
}

/// A constant p_D that counts the particle sets it is asked about.
struct CountedDetection {
    p: f64,
    calls: Arc<AtomicUsize>,
}

impl smc_lmb::filter::DetectionModel for CountedDetection {
    fn detection_probability(&self, p: &ParticleSet, _: &StepContext, out: &mut [f64]) {
        self.calls.fetch_add(1, Ordering::Relaxed);
        out[..p.len()].fill(self.p);
    }
}

/// A uniform clutter density that checks it is only asked about walls.
struct WallClutter {
    log_density: f64,
    calls: Arc<AtomicUsize>,
}

impl smc_lmb::filter::ClutterModel for WallClutter {
    fn log_intensity(&self, z: &[f64], _: &StepContext) -> f64 {
        assert_eq!(z.len(), 5);
        assert_eq!(
            z[4], 0.0,
            "a cluster measurement reached the wall clutter model"
        );
        self.calls.fetch_add(1, Ordering::Relaxed);
        self.log_density
    }
}

#[test]
fn the_tracker_takes_the_users_detection_and_clutter_models() {
    let Some(dir) = common::shared_data(DRIVE) else {
        return;
    };
    let drive = RawDrive::open(&dir).unwrap();
    let default = track(&drive, &TrackingConfig::default());
    let (detections, clutter) = (Arc::new(AtomicUsize::new(0)), Arc::new(AtomicUsize::new(0)));
    let mut config = TrackingConfig::default();
    // clusters seen half as often as the default 0.8 says; false walls as likely as the
    // default's (0.5 per frame over π/2 · 50 rad·m)
    config.cluster.own_models = OwnModels::default().detection(CountedDetection {
        p: 0.4,
        calls: detections.clone(),
    });
    config.plane.own_models = OwnModels::default().clutter(WallClutter {
        log_density: (0.5 / (std::f64::consts::FRAC_PI_2 * 50.0)).ln(),
        calls: clutter.clone(),
    });
    let own = track(&drive, &config);
    let (d, c) = (
        detections.load(Ordering::Relaxed),
        clutter.load(Ordering::Relaxed),
    );
    assert!(d > 100 && c > 10, "detection {d} calls, clutter {c} calls");
    assert_ne!(cluster_positions(&own), cluster_positions(&default));
}

#[test]
fn a_measurement_model_of_the_wrong_dimension_is_refused_naming_it() {
    let mut config = TrackingConfig::default();
    // a 2-D position model measures 2 components, not the tracker's 5
    config.cluster.own_models = OwnModels::default()
        .measurement(smc_lmb::models::PositionMeasurement::new(2, 0.3).unwrap());
    let e = smc_lmb::pipeline::DriveTracker::new(&config, 1)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("cluster measurement model")
            && e.contains("PositionMeasurement")
            && e.contains("2"),
        "{e}"
    );
}
