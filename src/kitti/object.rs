//! The KITTI 3-D object benchmark layout (`training/` or `testing/`): single frames, each a
//! Velodyne scan `velodyne/NNNNNN.bin`, its box labels `label_2/NNNNNN.txt` and its
//! calibration `calib/NNNNNN.txt`.
//!
//! A label line has 15 fields (16 with a detector's score):
//!
//! ```text
//! type truncated occluded alpha left top right bottom h w l x y z rotation_y [score]
//! Pedestrian 0.00 0 -0.20 712.40 143.00 810.73 307.92 1.89 0.48 1.20 1.84 1.47 8.41 0.01
//! ```
//!
//! the tracking labels' fields less frame and track id, so a line is read into a
//! [`TrackingLabel`] (frame = the file's number, track id −1) and its box moved into the
//! Velodyne frame with [`TrackingLabel::to_velodyne`]. The calibration file has the object
//! benchmark's key names with colons (`R0_rect:`, `Tr_velo_to_cam:`, `Tr_imu_to_velo:`),
//! which [`TrackingCalib`] reads.
//!
//! Not for: sequences (see [`super::tracking`]), images, or evaluation.

use super::labels::{ObjectType, TrackingLabel, LABEL_FIELDS};
use super::text::{numbered_lines, parse_f64, read_text};
use super::tracking::TrackingCalib;
use crate::cloud::classes::ObjectClass;
use crate::cloud::{read_kitti_bin, PointCloud};
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// Names of the 15 fields of an object label line, in file order (an optional 16th is
/// `score`): a tracking label's fields without its frame and track id.
pub const OBJECT_LABEL_FIELDS: &[&str] = LABEL_FIELDS.split_at(2).1;

fn field_label(i: usize) -> String {
    match OBJECT_LABEL_FIELDS.get(i) {
        Some(name) => format!("{name} (value {} of 15)", i + 1),
        None => format!("score (value {})", i + 1),
    }
}

/// Parses one object label line of frame `frame`; `path` and `line` name the place in errors,
/// which also name the field: a line with other than 15 or 16 values, a value that is not a
/// number (or not an integer for occlusion), or an unknown type.
pub fn parse_object_label(
    text: &str,
    path: &Path,
    line: usize,
    frame: usize,
) -> Result<TrackingLabel> {
    let t: Vec<&str> = text.split_whitespace().collect();
    if t.len() != 15 && t.len() != 16 {
        return Err(Error::parse(
            path,
            line,
            "line",
            format!(
                "{} values, expected 15 (or 16 with a score): {}",
                t.len(),
                OBJECT_LABEL_FIELDS.join(" ")
            ),
        ));
    }
    let object_type = ObjectType::from_name(t[0]).ok_or_else(|| {
        let names: Vec<&str> = ObjectType::ALL.iter().map(|o| o.name()).collect();
        Error::parse(
            path,
            line,
            field_label(0),
            format!("unknown type `{}` (one of {})", t[0], names.join(", ")),
        )
    })?;
    let num = |i: usize| parse_f64(path, line, &field_label(i), t[i]);
    let occluded = t[2].parse::<i32>().map_err(|_| {
        Error::parse(
            path,
            line,
            field_label(2),
            format!("`{}` is not an integer", t[2]),
        )
    })?;
    Ok(TrackingLabel {
        frame,
        track_id: -1,
        object_type,
        truncated: num(1)?,
        occluded,
        alpha: num(3)?,
        bbox: [num(4)?, num(5)?, num(6)?, num(7)?],
        dimensions: [num(8)?, num(9)?, num(10)?],
        location: [num(11)?, num(12)?, num(13)?],
        rotation_y: num(14)?,
        score: if t.len() == 16 { Some(num(15)?) } else { None },
    })
}

/// Reads an object label file of frame `frame`; blank lines are skipped, a missing file is an
/// [`Error::Io`] naming it.
pub fn read_object_labels(path: impl AsRef<Path>, frame: usize) -> Result<Vec<TrackingLabel>> {
    let path = path.as_ref();
    let text = read_text(path)?;
    numbered_lines(&text)
        .map(|(line, l)| parse_object_label(l, path, line, frame))
        .collect()
}

/// The class a KITTI type is scored as: `Person_sitting` with pedestrians, `Tram` with trucks
/// (both long rail or road vehicles), `Misc` and `DontCare` as other.
pub fn object_class(t: ObjectType) -> ObjectClass {
    match t {
        ObjectType::Car => ObjectClass::Car,
        ObjectType::Van => ObjectClass::Van,
        ObjectType::Truck | ObjectType::Tram => ObjectClass::Truck,
        ObjectType::Pedestrian | ObjectType::PersonSitting => ObjectClass::Pedestrian,
        ObjectType::Cyclist => ObjectClass::Cyclist,
        ObjectType::Misc | ObjectType::DontCare => ObjectClass::Other,
    }
}

/// A split folder of the object benchmark (`.../training`).
#[derive(Clone, Debug)]
pub struct ObjectFrames {
    root: PathBuf,
}

impl ObjectFrames {
    /// The split folder `root`; fails when it is not a folder.
    pub fn open(root: impl AsRef<Path>) -> Result<ObjectFrames> {
        let root = root.as_ref().to_path_buf();
        let meta = std::fs::metadata(&root).map_err(|e| Error::io(&root, e))?;
        if !meta.is_dir() {
            return Err(Error::invalid(
                format!("object folder {}", root.display()),
                "is not a folder",
            ));
        }
        Ok(ObjectFrames { root })
    }

    /// The split folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The frame numbers with a scan (`velodyne/NNNNNN.bin`), ascending.
    pub fn frames(&self) -> Result<Vec<usize>> {
        let files = super::frames::list_frame_files(&self.root.join("velodyne"), "bin")?;
        Ok(files.into_iter().map(|(k, _)| k as usize).collect())
    }

    /// Path of the scan of frame `k`.
    pub fn velodyne_path(&self, k: usize) -> PathBuf {
        self.root.join("velodyne").join(format!("{k:06}.bin"))
    }

    /// Path of the labels of frame `k`.
    pub fn labels_path(&self, k: usize) -> PathBuf {
        self.root.join("label_2").join(format!("{k:06}.txt"))
    }

    /// Path of the calibration of frame `k`.
    pub fn calib_path(&self, k: usize) -> PathBuf {
        self.root.join("calib").join(format!("{k:06}.txt"))
    }

    /// The scan of frame `k` (a non-finite value is an error naming the file and point).
    pub fn velodyne(&self, k: usize) -> Result<PointCloud> {
        read_kitti_bin(self.velodyne_path(k))
    }

    /// The labels of frame `k`.
    pub fn labels(&self, k: usize) -> Result<Vec<TrackingLabel>> {
        read_object_labels(self.labels_path(k), k)
    }

    /// The calibration of frame `k`; its
    /// [`rect_from_velo`](TrackingCalib::rect_from_velo) moves label boxes to the Velodyne
    /// frame.
    pub fn calib(&self, k: usize) -> Result<TrackingCalib> {
        TrackingCalib::read(self.calib_path(k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LINE: &str =
        "Pedestrian 0.00 0 -0.20 712.40 143.00 810.73 307.92 1.89 0.48 1.20 1.84 1.47 8.41 0.01";

    #[test]
    fn parses_a_real_line() {
        let l = parse_object_label(LINE, Path::new("x"), 1, 7).unwrap();
        assert_eq!(l.frame, 7);
        assert_eq!(l.track_id, -1);
        assert_eq!(l.object_type, ObjectType::Pedestrian);
        assert_eq!(l.occluded, 0);
        assert_eq!(l.bbox, [712.40, 143.00, 810.73, 307.92]);
        assert_eq!(l.dimensions, [1.89, 0.48, 1.20]);
        assert_eq!(l.location, [1.84, 1.47, 8.41]);
        assert_eq!(l.rotation_y, 0.01);
        assert_eq!(l.score, None);
        let scored = parse_object_label(&format!("{LINE} 0.75"), Path::new("x"), 1, 0).unwrap();
        assert_eq!(scored.score, Some(0.75));
    }

    #[test]
    fn errors_name_file_line_and_field() {
        let p = Path::new("label_2/000003.txt");
        let msg = parse_object_label("Car 0 0", p, 4, 3)
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("label_2/000003.txt:4: line: 3 values"),
            "{msg}"
        );
        let bad = LINE.replace("1.89", "tall");
        let msg = parse_object_label(&bad, p, 2, 3).unwrap_err().to_string();
        assert!(msg.contains(":2: height (value 9 of 15)"), "{msg}");
        let msg = parse_object_label(&LINE.replace("Pedestrian", "Bus"), p, 1, 3)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("type (value 1 of 15): unknown type `Bus`"),
            "{msg}"
        );
        let msg = parse_object_label(&LINE.replace(" 0 -0.20", " 0.5 -0.20"), p, 1, 3)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("occluded (value 3 of 15)"), "{msg}");
    }

    #[test]
    fn files_and_folders() {
        let dir = tempfile::tempdir().unwrap();
        for sub in ["velodyne", "label_2", "calib"] {
            std::fs::create_dir(dir.path().join(sub)).unwrap();
        }
        std::fs::write(
            dir.path().join("label_2/000002.txt"),
            format!("{LINE}\n\n{LINE}\n"),
        )
        .unwrap();
        let frames = ObjectFrames::open(dir.path()).unwrap();
        assert_eq!(frames.labels(2).unwrap().len(), 2);
        assert!(frames
            .labels(3)
            .unwrap_err()
            .to_string()
            .contains("000003.txt"));
        assert!(frames.frames().unwrap().is_empty());
        assert!(ObjectFrames::open(dir.path().join("nope")).is_err());
        assert_eq!(
            object_class(ObjectType::PersonSitting),
            ObjectClass::Pedestrian
        );
        assert_eq!(object_class(ObjectType::Misc), ObjectClass::Other);
    }
}
