//! Tracker output as KITTI tracking results: one `label_02`-style line per tracked object and
//! frame, one file `DIR/NNNN.txt` per sequence, as the official devkit and TrackEval read
//! them.
//!
//! A [`ResultObject`] (frame, track id, KITTI type, oriented box in the Velodyne frame of its
//! frame, score) becomes a [`TrackingLabel`] with the sequence's calibration:
//!
//! * dimensions, location (centre of the bottom face in rectified camera-0 coordinates) and
//!   rotation_y by [`TrackingLabel::set_velodyne_box`];
//! * alpha, the observation angle, `rotation_y − atan2(−y, x)` with (x, y) the bottom-face
//!   centre in the Velodyne frame, wrapped to (−π, π]: this is how KITTI's own tracking
//!   labels were made (sequence 0000 agrees to the labels' 6 decimals, whereas
//!   `rotation_y − atan2(x, z)` on the rectified camera-0 or camera-2 location is up to
//!   0.02 rad off);
//! * the 2-D box: the 8 corners of the label's 3-D box, cut at the plane 0.1 m in front of
//!   the camera ([`NEAR_PLANE`], edges crossing it are clipped there), projected by P2 and
//!   bounded, then clipped to the image `[0, width − 1] × [0, height − 1]` (KITTI's labels end
//!   at 1241 and 374 for its 1242 × 375 images, [`IMAGE_SIZE`]);
//! * truncated and occluded 0, as the AB3DMOT code writes them: TrackEval reads neither for
//!   tracker output and the devkit only parses them as integers;
//! * score: the object's score (existence probability for the LMB filter, the detection
//!   score for AB3DMOT), the 18th field TrackEval reads as the confidence.
//!
//! **Not written**: objects wholly behind the camera (no corner beyond the near plane) and
//! objects whose projection misses the image; both would be counted as false positives in
//! the image-based evaluation although no camera could have seen them. Track ids must be
//! non-negative (TrackEval drops negative ids); `DontCare` is not a result type.
//!
//! Not for: reading labels (see [`crate::kitti::labels`]), evaluating (see
//! [`crate::pipeline::drive_evaluation`]) or 3-D detection results (`label_2`).

use crate::error::{ensure_finite, Error, Result};
use crate::geometry::box3::Box3;
use crate::geometry::wrap_angle;
use crate::kitti::labels::{write_tracking_labels, ObjectType, TrackingLabel, VelodyneBox};
use crate::kitti::tracking::{TrackingCalib, IMAGE_SIZE};
use nalgebra::{Point3, Vector3};
use std::path::{Path, PathBuf};

/// Depth (m, rectified camera 0) of the plane the 3-D box is cut at before projecting.
pub const NEAR_PLANE: f64 = 0.1;

/// One tracked object in one frame, ready to be written.
#[derive(Clone, Debug, PartialEq)]
pub struct ResultObject {
    /// Frame number in the sequence.
    pub frame: usize,
    /// Track id (≥ 0 once written).
    pub track_id: u64,
    /// KITTI class (not `DontCare`).
    pub object_type: ObjectType,
    /// The box in the Velodyne frame of `frame`: centre of the box, length, width, height,
    /// heading about the Velodyne z axis.
    pub bbox: Box3,
    /// Score written as the 18th field.
    pub score: f64,
}

/// The path of a sequence's results in `dir`: `dir/NNNN.txt`.
pub fn results_path(dir: impl AsRef<Path>, sequence: u32) -> PathBuf {
    dir.as_ref().join(format!("{sequence:04}.txt"))
}

/// The result line of `obj` with the sequence's calibration and the image size (width,
/// height in pixels; [`IMAGE_SIZE`] for KITTI); `None` when the object is not written (see
/// the module notes). Errors: a non-finite value, a size that is not positive, `DontCare`, a
/// track id beyond `i64`.
pub fn result_label(
    obj: &ResultObject,
    calib: &TrackingCalib,
    image_size: [f64; 2],
) -> Result<Option<TrackingLabel>> {
    let what = || format!("result of track {} in frame {}", obj.track_id, obj.frame);
    let b = &obj.bbox;
    ensure_finite(
        &what(),
        &[b.center.x, b.center.y, b.center.z, b.yaw, obj.score],
    )?;
    if !b.size.iter().all(|s| s.is_finite() && *s > 0.0) {
        return Err(Error::invalid(
            what(),
            format!("box size {:?} (must be finite and positive)", b.size),
        ));
    }
    if obj.object_type == ObjectType::DontCare {
        return Err(Error::invalid(what(), "DontCare is not a result type"));
    }
    let track_id = i64::try_from(obj.track_id)
        .map_err(|_| Error::invalid(what(), "the track id does not fit a label"))?;
    if !image_size.iter().all(|s| s.is_finite() && *s >= 1.0) {
        return Err(Error::invalid(
            "image size",
            format!("{image_size:?} (must be at least one pixel each way)"),
        ));
    }
    let rect_from_velo = calib.rect_from_velo();
    let mut label = TrackingLabel {
        frame: obj.frame,
        track_id,
        object_type: obj.object_type,
        truncated: 0.0,
        occluded: 0,
        alpha: 0.0,
        bbox: [0.0; 4],
        dimensions: [0.0; 3],
        location: [0.0; 3],
        rotation_y: 0.0,
        score: Some(obj.score),
    };
    let vb = VelodyneBox {
        center: b.center,
        size: b.size,
        yaw: b.yaw,
    };
    label.set_velodyne_box(&vb, &rect_from_velo);
    let [x, y, z] = label.location;
    let bottom = rect_from_velo.inverse() * Point3::new(x, y, z);
    label.alpha = wrap_angle(label.rotation_y - (-bottom.y).atan2(bottom.x));
    match image_box(&label, calib, image_size) {
        Some(bbox) => {
            label.bbox = bbox;
            Ok(Some(label))
        }
        None => Ok(None),
    }
}

/// The 2-D box (left, top, right, bottom) in camera 2's image of a label's 3-D box, clipped
/// to the image; `None` when no part of the box lies beyond [`NEAR_PLANE`], its projection
/// misses the image, or the image size is less than a pixel (or not finite).
pub fn image_box(
    label: &TrackingLabel,
    calib: &TrackingCalib,
    image_size: [f64; 2],
) -> Option<[f64; 4]> {
    if !image_size.iter().all(|s| s.is_finite() && *s >= 1.0) {
        return None;
    }
    let [h, w, l] = label.dimensions;
    let [x, y, z] = label.location;
    let (s, c) = label.rotation_y.sin_cos();
    // Corner i: bit 0 length side, bit 1 width side, bit 2 top (y = −h); edges join corners
    // differing in one bit.
    let corner = |i: usize| -> Vector3<f64> {
        let a = if i & 1 == 0 { l / 2.0 } else { -l / 2.0 };
        let b = if i & 2 == 0 { w / 2.0 } else { -w / 2.0 };
        let dy = if i & 4 == 0 { 0.0 } else { -h };
        // R_y(ry)·(a, dy, b): x = cos·a + sin·b, z = −sin·a + cos·b.
        Vector3::new(x + c * a + s * b, y + dy, z - s * a + c * b)
    };
    let corners: [Vector3<f64>; 8] = std::array::from_fn(corner);
    let p2 = &calib.projections[2];
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    let mut add = |p: &Vector3<f64>| {
        let u = p2 * p.push(1.0);
        let px = [u.x / u.z, u.y / u.z];
        for k in 0..2 {
            lo[k] = lo[k].min(px[k]);
            hi[k] = hi[k].max(px[k]);
        }
    };
    let mut any = false;
    for (i, p) in corners.iter().enumerate() {
        if p.z >= NEAR_PLANE {
            add(p);
            any = true;
        }
        for bit in [1, 2, 4] {
            let j = i ^ bit;
            let q = &corners[j];
            if j > i && (p.z >= NEAR_PLANE) != (q.z >= NEAR_PLANE) {
                let t = (NEAR_PLANE - p.z) / (q.z - p.z);
                add(&(p + (q - p) * t));
            }
        }
    }
    if !any {
        return None;
    }
    let [wd, ht] = image_size;
    let left = lo[0].clamp(0.0, wd - 1.0);
    let right = hi[0].clamp(0.0, wd - 1.0);
    let top = lo[1].clamp(0.0, ht - 1.0);
    let bottom = hi[1].clamp(0.0, ht - 1.0);
    (left < right && top < bottom).then_some([left, top, right, bottom])
}

/// The result lines of `objects` (those written, see [`result_label`]) in frame order, then
/// track id order.
pub fn result_labels(
    objects: &[ResultObject],
    calib: &TrackingCalib,
    image_size: [f64; 2],
) -> Result<Vec<TrackingLabel>> {
    let mut out = Vec::with_capacity(objects.len());
    for o in objects {
        if let Some(l) = result_label(o, calib, image_size)? {
            out.push(l);
        }
    }
    out.sort_by_key(|l| (l.frame, l.track_id));
    Ok(out)
}

/// Writes a sequence's results to `path` (an empty file when nothing is written, which the
/// evaluations need for every sequence) with KITTI's [`IMAGE_SIZE`]; returns the number of
/// lines written.
pub fn write_tracking_results(
    path: impl AsRef<Path>,
    objects: &[ResultObject],
    calib: &TrackingCalib,
) -> Result<usize> {
    let labels = result_labels(objects, calib, IMAGE_SIZE)?;
    write_tracking_labels(path, &labels)?;
    Ok(labels.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Matrix3x4};

    /// The ideal rig (velo x → rect z, velo y → rect −x, velo z → rect −y, no offset) with
    /// f = 700 px, principal point (600, 180) and no camera-2 offset.
    fn ideal_calib() -> TrackingCalib {
        let k = Matrix3x4::new(
            700.0, 0.0, 600.0, 0.0, 0.0, 700.0, 180.0, 0.0, 0.0, 0.0, 1.0, 0.0,
        );
        let text = |m: &Matrix3x4<f64>| -> String {
            (0..3)
                .flat_map(|r| (0..4).map(move |c| (r, c)))
                .map(|(r, c)| m[(r, c)].to_string())
                .collect::<Vec<_>>()
                .join(" ")
        };
        let r = Matrix3::<f64>::identity();
        let r_text: Vec<String> = r.transpose().iter().map(|v| v.to_string()).collect();
        let file = format!(
            "P0: {p}\nP1: {p}\nP2: {p}\nP3: {p}\nR_rect {}\nTr_velo_cam 0 -1 0 0 0 0 -1 0 1 0 0 0\n\
             Tr_imu_velo 1 0 0 0 0 1 0 0 0 0 1 0\n",
            r_text.join(" "),
            p = text(&k)
        );
        TrackingCalib::parse(Path::new("ideal.txt"), &file).unwrap()
    }

    fn object(x: f64, y: f64, z: f64, yaw: f64) -> ResultObject {
        ResultObject {
            frame: 3,
            track_id: 7,
            object_type: ObjectType::Car,
            bbox: Box3 {
                center: Point3::new(x, y, z),
                size: [4.0, 2.0, 1.5],
                yaw,
            },
            score: 0.5,
        }
    }

    #[test]
    fn a_box_ahead_by_hand() {
        // Velodyne box 10 m ahead, centre 0.25 m below the sensor, heading along x (yaw 0).
        // Rect: bottom centre (0, 0.25 + 0.75, 10) = (0, 1, 10); length along rect z, so
        // rotation_y = −π/2 (rect x axis turned to −z... heading (cos ry, 0, −sin ry) = (0, 0, 1)).
        let l = result_label(&object(10.0, 0.0, -0.25, 0.0), &ideal_calib(), IMAGE_SIZE)
            .unwrap()
            .unwrap();
        assert_eq!(l.dimensions, [1.5, 2.0, 4.0]);
        for (a, b) in l.location.iter().zip([0.0, 1.0, 10.0]) {
            assert!((a - b).abs() < 1e-12, "{:?}", l.location);
        }
        assert!((l.rotation_y + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        // Straight ahead: alpha = rotation_y − atan2(0, 10) = −π/2.
        assert!((l.alpha + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        // Image box: nearest face at z = 8, x = ±1, y from −0.5 to 1 (rect): u = 600 ± 700/8,
        // v from 180 − 0.5·700/8 to 180 + 700/8 (far face is inside those).
        let want = [600.0 - 87.5, 180.0 - 43.75, 600.0 + 87.5, 180.0 + 87.5];
        for (a, b) in l.bbox.iter().zip(want) {
            assert!((a - b).abs() < 1e-9, "{:?}", l.bbox);
        }
        assert_eq!((l.truncated, l.occluded, l.score), (0.0, 0, Some(0.5)));
        assert_eq!((l.frame, l.track_id), (3, 7));
    }

    #[test]
    fn behind_outside_and_straddling() {
        let calib = ideal_calib();
        // Wholly behind the camera.
        assert!(
            result_label(&object(-8.0, 0.0, 0.0, 0.3), &calib, IMAGE_SIZE)
                .unwrap()
                .is_none()
        );
        // In front but far to the side: the projection misses the image.
        assert!(
            result_label(&object(5.0, 40.0, 0.0, 0.0), &calib, IMAGE_SIZE)
                .unwrap()
                .is_none()
        );
        // Straddling the camera plane beside the car: clipped at the near plane, box reaches
        // the image's left border (velo +y is image left).
        let l = result_label(&object(0.5, 2.5, 0.0, 0.0), &calib, IMAGE_SIZE)
            .unwrap()
            .unwrap();
        assert_eq!(l.bbox[0], 0.0);
        assert!(l.bbox[2] < 600.0 && l.bbox[2] > 0.0, "{:?}", l.bbox);
    }

    #[test]
    fn bad_objects_are_errors() {
        let calib = ideal_calib();
        let mut o = object(10.0, 0.0, 0.0, 0.0);
        o.score = f64::NAN;
        assert!(result_label(&o, &calib, IMAGE_SIZE).is_err());
        let mut o = object(10.0, 0.0, 0.0, 0.0);
        o.bbox.size[0] = 0.0;
        assert!(result_label(&o, &calib, IMAGE_SIZE).is_err());
        let mut o = object(10.0, 0.0, 0.0, 0.0);
        o.object_type = ObjectType::DontCare;
        assert!(result_label(&o, &calib, IMAGE_SIZE).is_err());
        let mut o = object(10.0, 0.0, 0.0, 0.0);
        o.track_id = u64::MAX;
        assert!(result_label(&o, &calib, IMAGE_SIZE).is_err());
        let o = object(10.0, 0.0, 0.0, 0.0);
        assert!(result_label(&o, &calib, [0.5, 375.0]).is_err());
        let l = result_label(&o, &calib, IMAGE_SIZE).unwrap().unwrap();
        assert!(image_box(&l, &calib, [f64::NAN, 375.0]).is_none());
        assert_eq!(image_box(&l, &calib, IMAGE_SIZE), Some(l.bbox));
    }
}
