//! The KITTI layouts as [`Recording`]s: a raw drive (scans, Velodyne time stamps, OXTS poses and
//! vehicle states, the IMU → Velodyne calibration), a tracking sequence (the same from its
//! OXTS file and `calib/NNNN.txt`, frames 0.1 s apart) and an odometry sequence (scans,
//! `times.txt` and the ground-truth poses of sequences 00–10; no vehicle motion).
//!
//! Scans are read as every recording reads them ([`super::non_finite_policy`]).
//!
//! Not for: reading the layouts' files (see [`crate::kitti`]).

use super::{Recording, RecordingLabels, VehicleMotion};
use crate::cloud::PointCloud;
use crate::error::{Error, Result};
use crate::kitti::tracking::FRAME_PERIOD;
use crate::kitti::{read_tracklets, OdometrySequence, RawDrive, TrackingSequence};
use crate::sim::street::{StreetTruth, TRUTH_FILE};
use nalgebra::Isometry3;
use std::path::PathBuf;

/// The [`Recording`] methods of a layout whose scans are a [`crate::kitti::ScanFolder`]
/// (`scans()`): which frames have one, reading and naming them, their folder.
macro_rules! scans_in_folder {
    () => {
        fn has_scan(&self, k: usize) -> bool {
            self.scans().has_scan(k)
        }
        fn scan(&self, k: usize) -> Result<PointCloud> {
            let policy = super::non_finite_policy(&self.scans().path(k));
            Ok(self.scans().read(k, policy)?.cloud)
        }
        fn scan_name(&self, k: usize) -> String {
            self.scans().path(k).display().to_string()
        }
        fn scan_dir(&self) -> Option<PathBuf> {
            Some(self.scans().dir().to_path_buf())
        }
    };
}

impl Recording for RawDrive {
    fn name(&self) -> String {
        RawDrive::name(self)
    }
    fn describe(&self) -> String {
        format!("drive {}", self.dir().display())
    }
    fn frame_count(&self) -> usize {
        RawDrive::frame_count(self)
    }
    scans_in_folder!();
    /// The Velodyne time stamps (`velodyne_points/timestamps.txt`) when the drive has them.
    fn times(&self) -> Result<Option<Vec<f64>>> {
        if self.velodyne_timestamps_path().is_file() {
            Ok(Some(self.scan_times()?))
        } else {
            Ok(None)
        }
    }
    fn has_poses(&self) -> bool {
        self.has_oxts()
    }
    fn poses(&self) -> Result<Vec<Isometry3<f64>>> {
        RawDrive::poses(self)
    }
    fn pose_source(&self) -> &'static str {
        "oxts"
    }
    fn has_vehicle(&self) -> bool {
        self.has_oxts()
    }
    /// The OXTS vehicle states, `calib_imu_to_velo.txt` and the OXTS time stamps' intervals.
    fn vehicle(&self) -> Result<VehicleMotion> {
        if !self.has_oxts() {
            return Err(Error::invalid(
                Recording::describe(self),
                "the vehicle ego model needs OXTS packets (oxts/data)",
            ));
        }
        Ok(VehicleMotion {
            states: self.vehicle_states()?,
            vehicle_to_sensor: self.calib_imu_to_velo()?.isometry,
            intervals: self.oxts_timestamps()?.intervals(),
        })
    }
    /// A simulated street's truth ([`TRUTH_FILE`]) in the drive folder, else KITTI's
    /// `tracklet_labels.xml` there, else none.
    fn labels(&self) -> Result<Option<RecordingLabels>> {
        let (street, tracklets) = (
            self.dir().join(TRUTH_FILE),
            self.dir().join("tracklet_labels.xml"),
        );
        if street.is_file() {
            Ok(Some(RecordingLabels::Street(Box::new(StreetTruth::read(
                &street,
            )?))))
        } else if tracklets.is_file() {
            Ok(Some(RecordingLabels::Tracklets(read_tracklets(
                &tracklets,
            )?)))
        } else {
            Ok(None)
        }
    }
}

impl Recording for TrackingSequence {
    fn name(&self) -> String {
        format!("tracking_{}", TrackingSequence::name(self))
    }
    fn describe(&self) -> String {
        format!(
            "tracking sequence {} of {}",
            TrackingSequence::name(self),
            self.root().display()
        )
    }
    fn frame_count(&self) -> usize {
        TrackingSequence::frame_count(self)
    }
    scans_in_folder!();
    /// Frame k at k · [`FRAME_PERIOD`]: the layout has no time stamps.
    fn times(&self) -> Result<Option<Vec<f64>>> {
        Ok(Some(TrackingSequence::times(self)))
    }
    fn has_poses(&self) -> bool {
        self.has_oxts()
    }
    fn poses(&self) -> Result<Vec<Isometry3<f64>>> {
        TrackingSequence::poses(self)
    }
    fn pose_source(&self) -> &'static str {
        "oxts"
    }
    fn has_vehicle(&self) -> bool {
        self.has_oxts()
    }
    /// The OXTS vehicle states, `Tr_imu_velo` and steps of [`FRAME_PERIOD`].
    fn vehicle(&self) -> Result<VehicleMotion> {
        let states = self.vehicle_states()?;
        let steps = TrackingSequence::frame_count(self).saturating_sub(1);
        Ok(VehicleMotion {
            states,
            vehicle_to_sensor: self.calib()?.imu_to_velo,
            intervals: vec![FRAME_PERIOD; steps],
        })
    }
    /// `label_02/NNNN.txt` with `calib/NNNN.txt`, when the sequence has labels.
    fn labels(&self) -> Result<Option<RecordingLabels>> {
        if !self.has_labels() {
            return Ok(None);
        }
        Ok(Some(RecordingLabels::Camera {
            labels: TrackingSequence::labels(self)?,
            calib: Box::new(self.calib()?),
        }))
    }
}

impl Recording for OdometrySequence {
    fn name(&self) -> String {
        format!("odometry_{}", OdometrySequence::name(self))
    }
    fn describe(&self) -> String {
        format!("odometry sequence {}", self.dir().display())
    }
    fn frame_count(&self) -> usize {
        OdometrySequence::frame_count(self)
    }
    scans_in_folder!();
    /// `times.txt` when the sequence has it; fewer times than scans is an error naming it.
    fn times(&self) -> Result<Option<Vec<f64>>> {
        if !self.times_path().is_file() {
            return Ok(None);
        }
        let t = OdometrySequence::times(self)?;
        let n = OdometrySequence::frame_count(self);
        if t.len() < n {
            return Err(Error::invalid(
                format!("{}", self.times_path().display()),
                format!("has {} times for {n} scans", t.len()),
            ));
        }
        Ok(Some(t))
    }
    fn has_poses(&self) -> bool {
        self.poses_path().is_file()
    }
    /// The ground-truth poses of `poses/NN.txt` moved to the Velodyne frame; fewer poses than
    /// scans is an error naming the file.
    fn poses(&self) -> Result<Vec<Isometry3<f64>>> {
        let poses = self.velodyne_poses()?;
        let n = OdometrySequence::frame_count(self);
        if poses.len() < n {
            return Err(Error::invalid(
                format!("{}", self.poses_path().display()),
                format!("has {} poses for {n} scans", poses.len()),
            ));
        }
        Ok(poses)
    }
    fn pose_source(&self) -> &'static str {
        "odometry"
    }
    fn vehicle(&self) -> Result<VehicleMotion> {
        Err(Error::invalid(
            Recording::describe(self),
            "the vehicle ego model needs OXTS vehicle states, which the odometry layout has not",
        ))
    }
}
