//! KITTI tracking labels (`label_02/NNNN.txt`): one object in one frame per line, 17
//! space-separated fields and an optional 18th, the score of a detector's output:
//!
//! ```text
//! frame track_id type truncated occluded alpha left top right bottom h w l x y z rotation_y [score]
//! 0     2        Pedestrian 0 0 -2.523309 1106.14 166.58 1204.47 323.88 1.71 0.77 0.97 6.30 1.65 8.46 -1.90
//! ```
//!
//! `type` is one of [`ObjectType`]; `DontCare` lines mark image regions that were not labelled
//! (track id −1, the 3-D fields −1000 / −10). The box (h, w, l metres) stands on (x, y, z), the
//! centre of its *bottom* face in rectified camera-0 coordinates (x right, y down, z forward);
//! `rotation_y` turns the box's length axis about the camera's y axis, 0 pointing along the
//! camera's x. [`TrackingLabel::to_velodyne`] moves a label's box into the Velodyne frame with
//! a sequence's calibration (see [`super::tracking::TrackingCalib::rect_from_velo`]) and
//! [`TrackingLabel::set_velodyne_box`] moves one back. Writing prints every number with the
//! shortest text that reads back to the same `f64`, so writing then reading is lossless.
//!
//! Not for: the raw drives' `tracklet_labels.xml` (see [`super::tracklets`]), the object
//! benchmark's `label_2` (one frame per file and no track id), or image-space evaluation.

use super::text::{numbered_lines, parse_f64, read_text};
use crate::atomic::write_atomically;
use crate::error::{Error, Result};
use crate::geometry::{wrap_angle, Box3};
use nalgebra::{Isometry3, Point3, Vector3};
use std::fmt;
use std::io::Write;
use std::path::Path;

/// Names of the 17 fields of a label line, in file order (the optional 18th is `score`).
pub const LABEL_FIELDS: [&str; 17] = [
    "frame",
    "track_id",
    "type",
    "truncated",
    "occluded",
    "alpha",
    "bbox_left",
    "bbox_top",
    "bbox_right",
    "bbox_bottom",
    "height",
    "width",
    "length",
    "x",
    "y",
    "z",
    "rotation_y",
];

/// The object classes of the KITTI tracking and object benchmarks.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ObjectType {
    /// `Car`.
    Car,
    /// `Van`.
    Van,
    /// `Truck`.
    Truck,
    /// `Pedestrian`.
    Pedestrian,
    /// `Person_sitting`.
    PersonSitting,
    /// `Cyclist`.
    Cyclist,
    /// `Tram`.
    Tram,
    /// `Misc`.
    Misc,
    /// `DontCare`: an image region left unlabelled, not an object.
    DontCare,
}

impl ObjectType {
    /// Every type, in the order of the KITTI devkit.
    pub const ALL: [ObjectType; 9] = [
        ObjectType::Car,
        ObjectType::Van,
        ObjectType::Truck,
        ObjectType::Pedestrian,
        ObjectType::PersonSitting,
        ObjectType::Cyclist,
        ObjectType::Tram,
        ObjectType::Misc,
        ObjectType::DontCare,
    ];

    /// The name as written in label files (`Person_sitting`, `DontCare`, ...).
    pub fn name(self) -> &'static str {
        match self {
            ObjectType::Car => "Car",
            ObjectType::Van => "Van",
            ObjectType::Truck => "Truck",
            ObjectType::Pedestrian => "Pedestrian",
            ObjectType::PersonSitting => "Person_sitting",
            ObjectType::Cyclist => "Cyclist",
            ObjectType::Tram => "Tram",
            ObjectType::Misc => "Misc",
            ObjectType::DontCare => "DontCare",
        }
    }

    /// The type named `name` exactly as in label files; `None` for anything else. The
    /// tracking benchmark's label files write a sitting person as `Person` (the object
    /// benchmark as `Person_sitting`; TrackEval reads `Person`), so both names give
    /// [`ObjectType::PersonSitting`], which is written back as `Person_sitting`.
    pub fn from_name(name: &str) -> Option<ObjectType> {
        if name == "Person" {
            return Some(ObjectType::PersonSitting);
        }
        ObjectType::ALL.into_iter().find(|t| t.name() == name)
    }
}

impl fmt::Display for ObjectType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One line of a tracking label file.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TrackingLabel {
    /// Frame number.
    pub frame: usize,
    /// Track id, constant over the object's frames (−1 for `DontCare`).
    pub track_id: i64,
    /// Object class.
    pub object_type: ObjectType,
    /// Truncation: 0 (inside the image) … 1 (leaving it); the tracking labels use the integer
    /// levels 0, 1, 2.
    pub truncated: f64,
    /// Occlusion: 0 visible, 1 partly, 2 largely occluded, 3 unknown (−1 for `DontCare`).
    pub occluded: i32,
    /// Observation angle, rad, in [−π, π].
    pub alpha: f64,
    /// 2-D box in the image of camera 2: left, top, right, bottom (pixels).
    pub bbox: [f64; 4],
    /// 3-D box size: height, width, length (m).
    pub dimensions: [f64; 3],
    /// Centre of the box's bottom face in rectified camera-0 coordinates (m).
    pub location: [f64; 3],
    /// Rotation about the camera's y axis, rad, in [−π, π].
    pub rotation_y: f64,
    /// Detection score (18th field; only in detector output).
    pub score: Option<f64>,
}

/// A label's 3-D box in the Velodyne frame of its frame.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct VelodyneBox {
    /// Centre of the box (not of its bottom face), metres.
    pub center: Point3<f64>,
    /// Length (along the heading), width, height (m).
    pub size: [f64; 3],
    /// Heading of the length axis about the Velodyne z axis, rad counter-clockwise from x.
    pub yaw: f64,
}

impl VelodyneBox {
    /// The same box as a [`Box3`] (identical fields), for the geometry and IoU code.
    pub fn to_box3(&self) -> Box3 {
        Box3::new(self.center, self.size, self.yaw)
    }

    /// Whether `p` (Velodyne frame) lies inside the box grown by `margin` metres on every side
    /// (the box's vertical axis taken as the Velodyne z axis).
    pub fn contains(&self, p: &Point3<f64>, margin: f64) -> bool {
        let d = p - self.center;
        let (s, c) = self.yaw.sin_cos();
        let along = c * d.x + s * d.y;
        let across = -s * d.x + c * d.y;
        along.abs() <= self.size[0] / 2.0 + margin
            && across.abs() <= self.size[1] / 2.0 + margin
            && d.z.abs() <= self.size[2] / 2.0 + margin
    }
}

fn field_label(i: usize) -> String {
    match LABEL_FIELDS.get(i) {
        Some(name) => format!("{name} (value {} of 17)", i + 1),
        None => format!("score (value {})", i + 1),
    }
}

fn parse_integer(path: &Path, line: usize, i: usize, token: &str) -> Result<i64> {
    token.parse::<i64>().map_err(|_| {
        Error::parse(
            path,
            line,
            field_label(i),
            format!("`{token}` is not an integer"),
        )
    })
}

impl TrackingLabel {
    /// Parses one label line; `path` and `line` are used in error messages, which name the
    /// field (`height (value 11 of 17)`) at fault: a line with other than 17 or 18 values, a
    /// value that is not a number (or not an integer for frame, track id and occlusion), a
    /// negative frame, or an unknown type.
    pub fn parse_line(text: &str, path: &Path, line: usize) -> Result<TrackingLabel> {
        let t: Vec<&str> = text.split_whitespace().collect();
        if t.len() != 17 && t.len() != 18 {
            return Err(Error::parse(
                path,
                line,
                "line",
                format!(
                    "{} values, expected 17 (or 18 with a score): {}",
                    t.len(),
                    LABEL_FIELDS.join(" ")
                ),
            ));
        }
        let frame = parse_integer(path, line, 0, t[0])?;
        let frame = usize::try_from(frame).map_err(|_| {
            Error::parse(path, line, field_label(0), format!("{frame} is negative"))
        })?;
        let track_id = parse_integer(path, line, 1, t[1])?;
        let object_type = ObjectType::from_name(t[2]).ok_or_else(|| {
            let names: Vec<&str> = ObjectType::ALL.iter().map(|o| o.name()).collect();
            Error::parse(
                path,
                line,
                field_label(2),
                format!("unknown type `{}` (one of {})", t[2], names.join(", ")),
            )
        })?;
        let num = |i: usize| parse_f64(path, line, &field_label(i), t[i]);
        let occluded = parse_integer(path, line, 4, t[4])?;
        let occluded = i32::try_from(occluded).map_err(|_| {
            Error::parse(
                path,
                line,
                field_label(4),
                format!("{occluded} is too large"),
            )
        })?;
        Ok(TrackingLabel {
            frame,
            track_id,
            object_type,
            truncated: num(3)?,
            occluded,
            alpha: num(5)?,
            bbox: [num(6)?, num(7)?, num(8)?, num(9)?],
            dimensions: [num(10)?, num(11)?, num(12)?],
            location: [num(13)?, num(14)?, num(15)?],
            rotation_y: num(16)?,
            score: if t.len() == 18 { Some(num(17)?) } else { None },
        })
    }

    /// The label as one line in KITTI's layout (no newline); see the module notes on numbers.
    pub fn to_line(&self) -> String {
        let mut parts = vec![
            self.frame.to_string(),
            self.track_id.to_string(),
            self.object_type.name().to_string(),
            self.truncated.to_string(),
            self.occluded.to_string(),
            self.alpha.to_string(),
        ];
        let numbers = self
            .bbox
            .iter()
            .chain(&self.dimensions)
            .chain(&self.location)
            .chain(std::iter::once(&self.rotation_y))
            .chain(&self.score);
        parts.extend(numbers.map(|v| v.to_string()));
        parts.join(" ")
    }

    /// Whether this is an object (anything but `DontCare`).
    pub fn is_object(&self) -> bool {
        self.object_type != ObjectType::DontCare
    }

    /// The box in the Velodyne frame. `rect_from_velo` maps Velodyne coordinates to rectified
    /// camera-0 coordinates (`R_rect·Tr_velo_cam`). The centre is the bottom-face centre
    /// raised by h/2 along the camera's −y axis; the yaw is the heading of the box's length
    /// axis, R·(cos ry, 0, −sin ry) with R the calibration's rotation, about the Velodyne z
    /// axis — for KITTI's calibration within 1 mrad of −rotation_y − π/2.
    pub fn to_velodyne(&self, rect_from_velo: &Isometry3<f64>) -> VelodyneBox {
        let [h, w, l] = self.dimensions;
        let [x, y, z] = self.location;
        let velo_from_rect = rect_from_velo.inverse();
        let center = velo_from_rect * Point3::new(x, y - h / 2.0, z);
        let (s, c) = self.rotation_y.sin_cos();
        let heading = velo_from_rect.rotation * Vector3::new(c, 0.0, -s);
        VelodyneBox {
            center,
            size: [l, w, h],
            yaw: heading.y.atan2(heading.x),
        }
    }

    /// Sets dimensions, location and rotation_y from a box in the Velodyne frame; the inverse
    /// of [`to_velodyne`](Self::to_velodyne) (exact up to rounding): rotation_y is the angle
    /// about the camera's y axis whose length axis, seen in the Velodyne frame, has heading
    /// `b.yaw`. The other fields (alpha, the image box) are left alone.
    pub fn set_velodyne_box(&mut self, b: &VelodyneBox, rect_from_velo: &Isometry3<f64>) {
        let [l, w, h] = b.size;
        let c = rect_from_velo * b.center;
        self.dimensions = [h, w, l];
        self.location = [c.x, c.y + h / 2.0, c.z];
        // Heading of R·(cos ry, 0, −sin ry) = cos ry·a − sin ry·b must be (cos yaw, sin yaw).
        let r = rect_from_velo.inverse().rotation;
        let a = r * Vector3::x();
        let bz = r * Vector3::z();
        let (sy, cy) = b.yaw.sin_cos();
        let across = |v: &Vector3<f64>| v.y * cy - v.x * sy;
        let along = |v: &Vector3<f64>| v.x * cy + v.y * sy;
        let mut ry = across(&a).atan2(across(&bz));
        if ry.cos() * along(&a) - ry.sin() * along(&bz) < 0.0 {
            ry += std::f64::consts::PI;
        }
        self.rotation_y = wrap_angle(ry);
    }
}

/// Reads a tracking label file; blank lines are skipped. Errors name the file, the line and
/// the field (see [`TrackingLabel::parse_line`]); a missing file is an [`Error::Io`] naming it.
pub fn read_tracking_labels(path: impl AsRef<Path>) -> Result<Vec<TrackingLabel>> {
    let path = path.as_ref();
    let text = read_text(path)?;
    numbered_lines(&text)
        .map(|(line, l)| TrackingLabel::parse_line(l, path, line))
        .collect()
}

/// Writes labels, one line each in the given order, atomically.
pub fn write_tracking_labels(path: impl AsRef<Path>, labels: &[TrackingLabel]) -> Result<()> {
    write_atomically(path.as_ref(), |w| {
        for l in labels {
            writeln!(w, "{}", l.to_line())?;
        }
        Ok(())
    })
}

/// One past the largest frame number of `labels` (0 for none).
pub fn label_frame_count(labels: &[TrackingLabel]) -> usize {
    labels.iter().map(|l| l.frame + 1).max().unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Translation3, UnitQuaternion};
    use std::f64::consts::{FRAC_PI_2, PI};

    const PEDESTRIAN: &str = "0 2 Pedestrian 0 0 -2.523309 1106.137292 166.576807 1204.470628 \
        323.876144 1.714062 0.767881 0.972283 6.301919 1.652419 8.455685 -1.900245";

    /// The ideal KITTI rig: velo x → cam z, velo y → cam −x, velo z → cam −y, plus an offset.
    fn ideal() -> Isometry3<f64> {
        let r = Matrix3::new(0.0, -1.0, 0.0, 0.0, 0.0, -1.0, 1.0, 0.0, 0.0);
        Isometry3::from_parts(
            Translation3::new(0.0, -0.08, -0.27),
            UnitQuaternion::from_matrix(&r),
        )
    }

    #[test]
    fn parses_a_real_line() {
        let l = TrackingLabel::parse_line(PEDESTRIAN, Path::new("0000.txt"), 3).unwrap();
        assert_eq!((l.frame, l.track_id), (0, 2));
        assert_eq!(l.object_type, ObjectType::Pedestrian);
        assert_eq!(l.bbox[2], 1204.470628);
        assert_eq!(l.dimensions, [1.714062, 0.767881, 0.972283]);
        assert_eq!(l.location, [6.301919, 1.652419, 8.455685]);
        assert_eq!(l.rotation_y, -1.900245);
        assert_eq!(l.score, None);
        assert!(l.is_object());
        let scored = format!("{PEDESTRIAN} 0.75");
        let s = TrackingLabel::parse_line(&scored, Path::new("0000.txt"), 3).unwrap();
        assert_eq!(s.score, Some(0.75));
    }

    #[test]
    fn lines_round_trip() {
        for text in [PEDESTRIAN.to_string(), format!("{PEDESTRIAN} 0.1")] {
            let l = TrackingLabel::parse_line(&text, Path::new("a.txt"), 1).unwrap();
            let back = TrackingLabel::parse_line(&l.to_line(), Path::new("b.txt"), 1).unwrap();
            assert_eq!(l, back);
        }
        for t in ObjectType::ALL {
            assert_eq!(ObjectType::from_name(t.name()), Some(t));
        }
        assert_eq!(ObjectType::PersonSitting.to_string(), "Person_sitting");
    }

    #[test]
    fn tracking_labels_name_sitting_people_person() {
        let line = PEDESTRIAN.replacen("Pedestrian", "Person", 1);
        assert_ne!(line, PEDESTRIAN);
        let l = TrackingLabel::parse_line(&line, Path::new("a.txt"), 1).unwrap();
        assert_eq!(l.object_type, ObjectType::PersonSitting);
        assert_eq!(ObjectType::from_name("person"), None);
    }

    #[test]
    fn errors_name_file_line_and_field() {
        let p = Path::new("label_02/0000.txt");
        let short: Vec<&str> = PEDESTRIAN.split_whitespace().take(16).collect();
        let msg = TrackingLabel::parse_line(&short.join(" "), p, 7)
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("label_02/0000.txt:7: line: 16 values, expected 17"),
            "{msg}"
        );
        let bad = PEDESTRIAN.replace("1.714062", "tall");
        let msg = TrackingLabel::parse_line(&bad, p, 2)
            .unwrap_err()
            .to_string();
        assert_eq!(
            msg,
            "label_02/0000.txt:2: height (value 11 of 17): `tall` is not a number"
        );
        let bad = PEDESTRIAN.replace("Pedestrian", "Bus");
        let msg = TrackingLabel::parse_line(&bad, p, 4)
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("label_02/0000.txt:4: type (value 3 of 17): unknown type `Bus`"),
            "{msg}"
        );
        let bad = PEDESTRIAN.replacen("0 2", "0 2.5", 1);
        let msg = TrackingLabel::parse_line(&bad, p, 1)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("track_id"), "{msg}");
        let bad = PEDESTRIAN.replacen("0 2", "-3 2", 1);
        assert!(TrackingLabel::parse_line(&bad, p, 1).is_err());
    }

    #[test]
    fn ideal_rig_box_by_hand() {
        // Bottom centre 10 m ahead, 2 m right and 1.65 m below the camera; h = 1.5 m.
        let mut l = TrackingLabel::parse_line(PEDESTRIAN, Path::new("x"), 1).unwrap();
        l.dimensions = [1.5, 1.6, 4.0];
        l.location = [2.0, 1.65, 10.0];
        l.rotation_y = 0.0;
        let b = l.to_velodyne(&ideal());
        // rect (2, 0.9, 10) → velo (x = z, y = −x, z = −y) after removing the offset:
        // velo = Rᵀ(rect − t) = (10 + 0.27, −2, −(0.9 + 0.08)).
        assert!((b.center - Point3::new(10.27, -2.0, -0.98)).norm() < 1e-12);
        assert_eq!(b.size, [4.0, 1.6, 1.5]);
        // rotation_y = 0: length along camera x = velo −y, yaw −π/2 = −0 − π/2.
        assert!((b.yaw + FRAC_PI_2).abs() < 1e-12);
        for ry in [-3.0, -1.9, -0.3, 0.0, 1.2, 2.9] {
            l.rotation_y = ry;
            let yaw = l.to_velodyne(&ideal()).yaw;
            assert!(wrap_angle(yaw - (-ry - FRAC_PI_2)).abs() < 1e-12, "{ry}");
        }
    }

    #[test]
    fn velodyne_box_round_trip_with_a_tilted_rig() {
        let tilt = UnitQuaternion::from_euler_angles(0.01, -0.015, 0.007);
        let rect_from_velo = Isometry3::from_parts(ideal().translation, ideal().rotation * tilt);
        let l0 = TrackingLabel::parse_line(PEDESTRIAN, Path::new("x"), 1).unwrap();
        for ry in [-PI + 0.01, -1.900245, 0.0, 0.4, 3.1] {
            let mut l = l0;
            l.rotation_y = ry;
            let b = l.to_velodyne(&rect_from_velo);
            let mut back = l0;
            back.rotation_y = 0.0;
            back.set_velodyne_box(&b, &rect_from_velo);
            assert!(wrap_angle(back.rotation_y - ry).abs() < 1e-12, "{ry}");
            for i in 0..3 {
                assert!((back.location[i] - l.location[i]).abs() < 1e-12);
                assert!((back.dimensions[i] - l.dimensions[i]).abs() < 1e-15);
            }
            // Tilt moves the yaw off −ry − π/2 by no more than a few mrad.
            assert!(wrap_angle(b.yaw + ry + FRAC_PI_2).abs() < 0.03, "{ry}");
        }
    }

    #[test]
    fn containment() {
        let b = VelodyneBox {
            center: Point3::new(5.0, 0.0, 0.0),
            size: [4.0, 2.0, 1.0],
            yaw: FRAC_PI_2,
        };
        assert!(b.contains(&Point3::new(5.9, 1.9, 0.4), 0.0));
        assert!(!b.contains(&Point3::new(6.1, 0.0, 0.0), 0.0));
        assert!(b.contains(&Point3::new(6.1, 0.0, 0.0), 0.2));
        assert!(!b.contains(&Point3::new(5.0, 0.0, 0.6), 0.0));
    }

    #[test]
    fn files() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("0000.txt");
        let a = TrackingLabel::parse_line(PEDESTRIAN, Path::new("x"), 1).unwrap();
        let mut b = a;
        b.frame = 4;
        b.object_type = ObjectType::DontCare;
        b.track_id = -1;
        write_tracking_labels(&p, &[a, b]).unwrap();
        let back = read_tracking_labels(&p).unwrap();
        assert_eq!(back, vec![a, b]);
        assert_eq!(label_frame_count(&back), 5);
        std::fs::write(&p, format!("{PEDESTRIAN}\n\n0 1 Van 0 0\n")).unwrap();
        let msg = read_tracking_labels(&p).unwrap_err().to_string();
        assert!(msg.contains("0000.txt:3: line: 5 values"), "{msg}");
    }
}
