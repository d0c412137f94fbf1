//! Writes a simulated street drive in the KITTI tracking layout, with its road users (cars,
//! vans, trucks, pedestrians, cyclists; not the clutter) as `label_02` labels:
//!
//! ```text
//! ROOT/velodyne/NNNN/000000.bin ...
//! ROOT/oxts/NNNN.txt           one OXTS packet line per frame
//! ROOT/calib/NNNN.txt          the real 2011_09_26 rig (calib_files::TRACKING_CALIB)
//! ROOT/label_02/NNNN.txt       the truth as tracking labels (street_labels)
//! ```
//!
//! The frames must be [`FRAME_PERIOD`] apart (the layout keeps no time stamps). The scan folder
//! is filled under a hidden temporary name and renamed into place when complete; a sequence
//! whose scan folder, OXTS, calibration or label file already exists is never overwritten.
//!
//! Not for: the raw layout (see [`super::writer`]) or simulating (see
//! [`super::StreetSimulator`]).

use super::{calib_files, ObjectKind, StreetConfig, StreetSimulator, StreetTruth};
use crate::atomic::write_bytes;
use crate::cloud::write_kitti_bin;
use crate::error::{Error, Result};
use crate::geometry::wrap_angle;
use crate::kitti::labels::{write_tracking_labels, ObjectType, TrackingLabel, VelodyneBox};
use crate::kitti::tracking::{TrackingCalib, FRAME_PERIOD, IMAGE_SIZE as IMAGE};
use nalgebra::{Point3, Vector3};
use std::fs;
use std::path::{Path, PathBuf};

/// A sequence written by [`write_tracking_sequence`].
#[derive(Clone, Debug)]
pub struct WrittenSequence {
    /// The split folder, to hand to `TrackingSequence::open` with `sequence`.
    pub root: PathBuf,
    /// The sequence number.
    pub sequence: u32,
    /// The truth of the simulated street (not written; the labels are its objects).
    pub truth: StreetTruth,
    /// The labels written to `label_02/NNNN.txt`.
    pub labels: Vec<TrackingLabel>,
}

/// The KITTI class of a simulated object: cars, parked or moving, are `Car`; pedestrians
/// `Pedestrian`.
pub fn object_type(kind: ObjectKind) -> ObjectType {
    match kind {
        ObjectKind::Car | ObjectKind::ParkedCar => ObjectType::Car,
        ObjectKind::Van | ObjectKind::ParkedVan => ObjectType::Van,
        ObjectKind::Truck => ObjectType::Truck,
        ObjectKind::Cyclist => ObjectType::Cyclist,
        ObjectKind::Pedestrian => ObjectType::Pedestrian,
    }
}

/// The objects of `truth` as tracking labels, frame by frame: one label per object and frame
/// in which at least one lidar point hits it (the point counts come from writing the scans).
/// Unlike KITTI's, which cover the front camera's view only, these label every object the
/// lidar sees; an object not wholly in front of camera 2 gets the image box −1 −1 −1 −1 and
/// alpha −10, KITTI's values for "unset". Truncation is 0; the occlusion level is the
/// truth's, from the lidar's rays ([`super::truth::occlusion_level`]), not the camera's view;
/// the track id is the object's id.
pub fn street_labels(truth: &StreetTruth, calib: &TrackingCalib) -> Vec<TrackingLabel> {
    let rect_from_velo = calib.rect_from_velo();
    let mut labels = Vec::new();
    for frame in &truth.frames {
        let world_from_velo = frame.velodyne_pose.to_isometry();
        let velo_from_world = world_from_velo.inverse();
        for object in &truth.objects {
            let Some(state) = object
                .states
                .iter()
                .find(|s| s.frame == frame.index && s.points > 0)
            else {
                continue;
            };
            let [l, w, h] = object.size;
            let [x, y, z] = state.position;
            let center = velo_from_world * Point3::new(x, y, z + h / 2.0);
            let heading =
                velo_from_world.rotation * Vector3::new(state.yaw.cos(), state.yaw.sin(), 0.0);
            let b = VelodyneBox {
                center,
                size: [l, w, h],
                yaw: heading.y.atan2(heading.x),
            };
            let mut label = TrackingLabel {
                frame: frame.index,
                track_id: object.id as i64,
                object_type: object_type(object.kind),
                truncated: 0.0,
                occluded: state.occluded,
                alpha: -10.0,
                bbox: [-1.0; 4],
                dimensions: [0.0; 3],
                location: [0.0; 3],
                rotation_y: 0.0,
                score: None,
            };
            label.set_velodyne_box(&b, &rect_from_velo);
            let (s, c) = b.yaw.sin_cos();
            let corners: Option<Vec<[f64; 2]>> = [-0.5, 0.5]
                .iter()
                .flat_map(|&a| [-0.5, 0.5].iter().map(move |&b| (a, b)))
                .flat_map(|(a, bb)| [-0.5, 0.5].iter().map(move |&v| (a, bb, v)))
                .map(|(a, bb, v)| {
                    let p = center
                        + Vector3::new(c * a * l - s * bb * w, s * a * l + c * bb * w, v * h);
                    calib.project_to_image2(&p)
                })
                .collect();
            if let Some(uv) = corners {
                let clamp = |v: f64, max: f64| v.clamp(0.0, max - 1.0);
                let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
                for p in &uv {
                    for i in 0..2 {
                        lo[i] = lo[i].min(p[i]);
                        hi[i] = hi[i].max(p[i]);
                    }
                }
                if hi[0] >= 0.0 && lo[0] < IMAGE[0] && hi[1] >= 0.0 && lo[1] < IMAGE[1] {
                    label.bbox = [
                        clamp(lo[0], IMAGE[0]),
                        clamp(lo[1], IMAGE[1]),
                        clamp(hi[0], IMAGE[0]),
                        clamp(hi[1], IMAGE[1]),
                    ];
                    let [lx, _, lz] = label.location;
                    label.alpha = wrap_angle(label.rotation_y - lx.atan2(lz));
                }
            }
            labels.push(label);
        }
    }
    labels
}

fn refuse_existing(path: &Path) -> Result<()> {
    if path.exists() {
        return Err(Error::invalid(
            format!("{}", path.display()),
            "already exists; remove it or choose another output folder or sequence number",
        ));
    }
    Ok(())
}

fn mkdir(path: &Path) -> Result<()> {
    fs::create_dir_all(path).map_err(|e| Error::io(path, e))
}

/// Simulates `frames` frames with `seed` and writes them under the split folder `root` as
/// tracking sequence `sequence`; `progress(k)` is called after frame k is written.
///
/// Errors: an invalid configuration or frame count (see [`StreetSimulator::new`]), a frame
/// period other than [`FRAME_PERIOD`], any of the sequence's files or its scan folder already
/// existing, or a write failure (naming the file).
pub fn write_tracking_sequence(
    root: impl AsRef<Path>,
    config: &StreetConfig,
    frames: usize,
    seed: u64,
    sequence: u32,
    mut progress: impl FnMut(usize),
) -> Result<WrittenSequence> {
    if (config.frame_period - FRAME_PERIOD).abs() > 1e-12 {
        return Err(Error::invalid(
            "street config field frame_period",
            format!(
                "{} s, but the tracking layout has no time stamps and means {FRAME_PERIOD} s",
                config.frame_period
            ),
        ));
    }
    let sim = StreetSimulator::new(config, frames, seed)?;
    let root = root.as_ref().to_path_buf();
    let name = format!("{sequence:04}");
    let vdir = root.join("velodyne").join(&name);
    let file = |sub: &str| root.join(sub).join(format!("{name}.txt"));
    let (oxts, calib_path, labels_path) = (file("oxts"), file("calib"), file("label_02"));
    for p in [&vdir, &oxts, &calib_path, &labels_path] {
        refuse_existing(p)?;
    }
    for sub in ["velodyne", "oxts", "calib", "label_02"] {
        mkdir(&root.join(sub))?;
    }
    let calib = TrackingCalib::parse(&calib_path, calib_files::TRACKING_CALIB)?;
    let tmp = root
        .join("velodyne")
        .join(format!(".{name}.partial.{}", std::process::id()));
    if tmp.exists() {
        fs::remove_dir_all(&tmp).map_err(|e| Error::io(&tmp, e))?;
    }
    mkdir(&tmp)?;
    let mut truth = sim.truth();
    let scans = (|| {
        for k in 0..sim.frames() {
            let scan = sim.scan(k);
            write_kitti_bin(tmp.join(format!("{k:06}.bin")), &scan.cloud)?;
            sim.record_scan(&mut truth, k, &scan);
            progress(k);
        }
        fs::rename(&tmp, &vdir).map_err(|e| Error::io(&vdir, e))
    })();
    if let Err(e) = scans {
        let _ = fs::remove_dir_all(&tmp);
        return Err(e);
    }
    let packets: String = (0..sim.frames())
        .map(|k| format!("{}\n", sim.packet(k).to_line()))
        .collect();
    write_bytes(&oxts, packets.as_bytes())?;
    write_bytes(&calib_path, calib_files::TRACKING_CALIB.as_bytes())?;
    let labels = street_labels(&truth, &calib);
    write_tracking_labels(&labels_path, &labels)?;
    Ok(WrittenSequence {
        root,
        sequence,
        truth,
        labels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kitti::TrackingSequence;

    #[test]
    fn written_sequence_reads_back_with_the_simulated_poses_and_objects() {
        let dir = tempfile::tempdir().unwrap();
        let config = StreetConfig::default();
        let w = write_tracking_sequence(dir.path(), &config, 3, 2, 7, |_| {}).unwrap();
        let seq = TrackingSequence::open(dir.path(), 7).unwrap();
        assert!(seq.check().is_empty(), "{:?}", seq.check());
        assert_eq!(seq.frame_count(), 3);
        let poses = seq.poses().unwrap();
        for (k, p) in poses.iter().enumerate() {
            let truth = w.truth.frames[k].drive_pose.to_isometry();
            let d = (p.to_homogeneous() - truth.to_homogeneous()).abs().max();
            assert!(d < 1e-6, "frame {k}: {d}");
        }
        let labels = seq.labels().unwrap();
        assert_eq!(labels, w.labels);
        assert!(!labels.is_empty());
        // Every label's box, back in the world, is its object's.
        let rect_from_velo = seq.calib().unwrap().rect_from_velo();
        for l in &labels {
            let o = w
                .truth
                .objects
                .iter()
                .find(|o| o.id as i64 == l.track_id)
                .unwrap();
            let s = o.states.iter().find(|s| s.frame == l.frame).unwrap();
            let b = l.to_velodyne(&rect_from_velo);
            let world = w.truth.frames[l.frame].velodyne_pose.to_isometry() * b.center;
            let expected = Point3::new(s.position[0], s.position[1], o.size[2] / 2.0);
            assert!((world - expected).norm() < 1e-6, "{l:?}");
            assert_eq!(l.object_type, object_type(o.kind));
        }
        // Nothing is overwritten.
        let err = write_tracking_sequence(dir.path(), &config, 3, 2, 7, |_| {}).unwrap_err();
        assert!(err.to_string().contains("0007"), "{err}");
    }
}
