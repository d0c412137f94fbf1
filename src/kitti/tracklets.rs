//! KITTI raw-data object labels, `tracklet_labels.xml`: a Boost-serialised XML archive with one
//! `<item>` per object (a tracklet) under `<tracklets>`, each with its type, box size (h, w, l),
//! first frame, and one pose `<item>` per frame from there on:
//!
//! ```text
//! <boost_serialization ...><tracklets ...>
//!   <count>N</count> <item_version>1</item_version>
//!   <item ...>
//!     <objectType>Car</objectType> <h>1.5</h> <w>1.6</w> <l>3.9</l>
//!     <first_frame>12</first_frame>
//!     <poses ...> <count>M</count> <item_version>2</item_version>
//!       <item ...> <tx/> <ty/> <tz/> <rx/> <ry/> <rz/> <state/> <occlusion/> <occlusion_kf/>
//!                  <truncation/> <amt_occlusion/> ... </item> ...
//!     </poses>
//!     <finished>1</finished>
//!   </item> ...
//! </tracklets></boost_serialization>
//! ```
//!
//! Poses are in the Velodyne frame of their frame: (tx, ty, tz) is the centre of the box's
//! *bottom* face, (rx, ry, rz) rotation angles of which KITTI only uses rz (yaw about z).
//! Elements not listed above are ignored; `<count>` values are checked against the items found.
//!
//! Not for: the tracking benchmark's `label_02` text files (see [`super::labels`]), or
//! image-space boxes.

use crate::atomic::write_atomically;
use crate::error::{Error, Result};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use quick_xml::events::Event;
use quick_xml::Reader;
use std::io::Write;
use std::path::Path;

/// KITTI pose state "unset" (the other values: 1 interpolated, 2 labelled).
pub const STATE_UNSET: i32 = 0;
/// KITTI occlusion "unset" (the other values: 0 visible, 1 partly, 2 fully occluded).
pub const OCCLUSION_UNSET: i32 = -1;
/// KITTI truncation "unset" (the other values: 0 in image, 1 truncated, 2 out of image,
/// 3 behind the image plane).
pub const TRUNCATION_UNSET: i32 = 99;

/// The pose of one object in one frame.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TrackletPose {
    /// Centre of the box's bottom face in the Velodyne frame (tx, ty, tz), metres.
    pub translation: Vector3<f64>,
    /// Rotation angles (rx, ry, rz), rad; KITTI labels only set rz (yaw about z).
    pub rotation: Vector3<f64>,
    /// Pose state ([`STATE_UNSET`] when absent).
    pub state: i32,
    /// Occlusion level ([`OCCLUSION_UNSET`] when absent).
    pub occlusion: i32,
    /// Truncation level ([`TRUNCATION_UNSET`] when absent).
    pub truncation: i32,
}

impl TrackletPose {
    /// A pose at `translation` with yaw `rz` and unset state/occlusion/truncation.
    pub fn new(translation: Vector3<f64>, rz: f64) -> TrackletPose {
        TrackletPose {
            translation,
            rotation: Vector3::new(0.0, 0.0, rz),
            state: STATE_UNSET,
            occlusion: OCCLUSION_UNSET,
            truncation: TRUNCATION_UNSET,
        }
    }

    /// The box frame in the Velodyne frame: translation (tx, ty, tz), rotation
    /// Rz(rz)·Ry(ry)·Rx(rx). Its origin is the centre of the bottom face.
    pub fn isometry(&self) -> Isometry3<f64> {
        let r = self.rotation;
        Isometry3::from_parts(
            Translation3::from(self.translation),
            UnitQuaternion::from_euler_angles(r.x, r.y, r.z),
        )
    }
}

/// One labelled object over consecutive frames.
#[derive(Clone, Debug, PartialEq)]
pub struct Tracklet {
    /// `Car`, `Van`, `Truck`, `Pedestrian`, `Person (sitting)`, `Cyclist`, `Tram`, `Misc`, ...
    pub object_type: String,
    /// Box height, metres (along z).
    pub h: f64,
    /// Box width, metres (along the box's y).
    pub w: f64,
    /// Box length, metres (along the box's x).
    pub l: f64,
    /// Frame of the first pose.
    pub first_frame: usize,
    /// One pose per frame, from `first_frame` on.
    pub poses: Vec<TrackletPose>,
}

impl Tracklet {
    /// The pose in `frame`, if the object is labelled there.
    pub fn pose_at(&self, frame: usize) -> Option<&TrackletPose> {
        self.poses.get(frame.checked_sub(self.first_frame)?)
    }

    /// One past the last labelled frame.
    pub fn end_frame(&self) -> usize {
        self.first_frame + self.poses.len()
    }
}

/// One object present in a frame, as returned by [`Tracklets::objects_at`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ObjectAt<'a> {
    /// Index of the tracklet in the file (a stable object identity).
    pub id: usize,
    /// The object type.
    pub object_type: &'a str,
    /// Box size (h, w, l), metres.
    pub size: [f64; 3],
    /// The pose in this frame.
    pub pose: &'a TrackletPose,
}

impl ObjectAt<'_> {
    /// The box centre in the Velodyne frame (bottom-face centre raised by h/2 along the box's z).
    pub fn center(&self) -> Point3<f64> {
        self.pose.isometry() * Point3::new(0.0, 0.0, self.size[0] / 2.0)
    }
}

/// All tracklets of a drive.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tracklets {
    /// The tracklets in file order.
    pub items: Vec<Tracklet>,
}

impl Tracklets {
    /// The objects labelled in `frame`, in file order.
    pub fn objects_at(&self, frame: usize) -> Vec<ObjectAt<'_>> {
        self.items
            .iter()
            .enumerate()
            .filter_map(|(id, t)| {
                t.pose_at(frame).map(|pose| ObjectAt {
                    id,
                    object_type: &t.object_type,
                    size: [t.h, t.w, t.l],
                    pose,
                })
            })
            .collect()
    }

    /// One past the last labelled frame of any tracklet (0 when there is none).
    pub fn end_frame(&self) -> usize {
        self.items
            .iter()
            .map(Tracklet::end_frame)
            .max()
            .unwrap_or(0)
    }
}

/// Line numbers of byte offsets, counted incrementally.
struct LineCounter<'a> {
    src: &'a [u8],
    pos: usize,
    line: usize,
}

impl LineCounter<'_> {
    fn at(&mut self, offset: u64) -> usize {
        let offset = (offset as usize).min(self.src.len());
        if offset >= self.pos {
            self.line += self.src[self.pos..offset]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
        } else {
            self.line = 1 + self.src[..offset].iter().filter(|&&b| b == b'\n').count();
        }
        self.pos = offset;
        self.line
    }
}

#[derive(Default)]
struct PartialPose {
    t: [Option<f64>; 3],
    r: [Option<f64>; 3],
    state: Option<i32>,
    occlusion: Option<i32>,
    truncation: Option<i32>,
}

#[derive(Default)]
struct PartialTracklet {
    object_type: Option<String>,
    hwl: [Option<f64>; 3],
    first_frame: Option<usize>,
    pose_count: Option<usize>,
    poses: Vec<TrackletPose>,
    pose: Option<PartialPose>,
}

/// Reads `tracklet_labels.xml`. Errors name the file, the line and the element (e.g.
/// `tracklet 3 pose 17: tx`) that is missing, not a number, or malformed XML.
pub fn read_tracklets(path: impl AsRef<Path>) -> Result<Tracklets> {
    let path = path.as_ref();
    let text = super::text::read_text(path)?;
    parse_tracklets(path, &text)
}

/// Parses tracklet XML held in memory (`path` is used in messages).
pub fn parse_tracklets(path: &Path, xml: &str) -> Result<Tracklets> {
    let mut reader = Reader::from_str(xml);
    let mut lines = LineCounter {
        src: xml.as_bytes(),
        pos: 0,
        line: 1,
    };
    let mut stack: Vec<String> = Vec::new();
    let mut text = String::new();
    let mut out = Tracklets::default();
    let mut tracklet_count: Option<usize> = None;
    let mut current: Option<PartialTracklet> = None;
    let mut seen_tracklets = false;

    loop {
        let event = reader.read_event().map_err(|e| {
            let line = lines.at(reader.error_position());
            Error::parse(path, line, "XML", e.to_string())
        })?;
        let line = lines.at(reader.buffer_position());
        let err = |field: String, reason: String| Error::parse(path, line, field, reason);
        // (name, opened, closed)
        let (name, opened, closed) = match &event {
            Event::Start(e) => (
                String::from_utf8_lossy(e.local_name().as_ref()).into_owned(),
                true,
                false,
            ),
            Event::Empty(e) => (
                String::from_utf8_lossy(e.local_name().as_ref()).into_owned(),
                true,
                true,
            ),
            Event::End(e) => (
                String::from_utf8_lossy(e.local_name().as_ref()).into_owned(),
                false,
                true,
            ),
            Event::Text(t) => {
                let s = t.decode().map_err(|e| err("text".into(), e.to_string()))?;
                text.push_str(&s);
                continue;
            }
            Event::CData(t) => {
                text.push_str(&String::from_utf8_lossy(t.as_ref()));
                continue;
            }
            Event::GeneralRef(r) => {
                let s = String::from_utf8_lossy(r.as_ref()).into_owned();
                let c = match s.as_str() {
                    "amp" => '&',
                    "lt" => '<',
                    "gt" => '>',
                    "quot" => '"',
                    "apos" => '\'',
                    _ => return Err(err("text".into(), format!("unsupported entity `&{s};`"))),
                };
                text.push(c);
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        if opened {
            stack.push(name.clone());
            text.clear();
            // Path relative to <tracklets>.
            let rel = relative_path(&stack);
            match rel.as_deref() {
                Some([t]) if t == "tracklets" => seen_tracklets = true,
                Some([_, item]) if item == "item" => current = Some(PartialTracklet::default()),
                Some([_, item, poses, pitem])
                    if item == "item" && poses == "poses" && pitem == "item" =>
                {
                    if let Some(c) = current.as_mut() {
                        c.pose = Some(PartialPose::default());
                    }
                }
                _ => {}
            }
        }
        if !closed {
            continue;
        }
        // Closing: the element's full path is still on the stack.
        let value = std::mem::take(&mut text);
        let value = value.trim();
        let rel = relative_path(&stack).unwrap_or_default();
        let rel: Vec<&str> = rel.iter().map(String::as_str).collect();
        let ti = out.items.len();
        match rel.as_slice() {
            ["tracklets", "count"] => {
                tracklet_count =
                    Some(parse_num(value).map_err(|r| err("tracklets: count".into(), r))?);
            }
            ["tracklets", "item", "poses"] => {
                let c = current.get_or_insert_with(Default::default);
                if let Some(n) = c.pose_count {
                    if n != c.poses.len() {
                        return Err(err(
                            format!("tracklet {ti}: poses: count"),
                            format!("says {n} but {} pose items follow", c.poses.len()),
                        ));
                    }
                }
            }
            ["tracklets", "item", field] => {
                let c = current.get_or_insert_with(Default::default);
                let fname = || format!("tracklet {ti}: {field}");
                match *field {
                    "objectType" => c.object_type = Some(value.to_string()),
                    "h" => c.hwl[0] = Some(parse_real(value).map_err(|r| err(fname(), r))?),
                    "w" => c.hwl[1] = Some(parse_real(value).map_err(|r| err(fname(), r))?),
                    "l" => c.hwl[2] = Some(parse_real(value).map_err(|r| err(fname(), r))?),
                    "first_frame" => {
                        c.first_frame = Some(parse_num(value).map_err(|r| err(fname(), r))?)
                    }
                    _ => {}
                }
            }
            ["tracklets", "item", "poses", "count"] => {
                let c = current.get_or_insert_with(Default::default);
                c.pose_count = Some(
                    parse_num(value).map_err(|r| err(format!("tracklet {ti}: poses: count"), r))?,
                );
            }
            ["tracklets", "item", "poses", "item", field] => {
                let c = current.get_or_insert_with(Default::default);
                let pi = c.poses.len();
                let fname = || format!("tracklet {ti} pose {pi}: {field}");
                let p = c.pose.get_or_insert_with(Default::default);
                match *field {
                    "tx" | "ty" | "tz" | "rx" | "ry" | "rz" => {
                        let v = parse_real(value).map_err(|r| err(fname(), r))?;
                        let k = match &field[1..] {
                            "x" => 0,
                            "y" => 1,
                            _ => 2,
                        };
                        if field.starts_with('t') {
                            p.t[k] = Some(v);
                        } else {
                            p.r[k] = Some(v);
                        }
                    }
                    "state" => p.state = Some(parse_int(value).map_err(|r| err(fname(), r))?),
                    "occlusion" => {
                        p.occlusion = Some(parse_int(value).map_err(|r| err(fname(), r))?)
                    }
                    "truncation" => {
                        p.truncation = Some(parse_int(value).map_err(|r| err(fname(), r))?)
                    }
                    _ => {}
                }
            }
            ["tracklets", "item", "poses", "item"] => {
                let c = current.get_or_insert_with(Default::default);
                let pi = c.poses.len();
                let p = c.pose.take().unwrap_or_default();
                let names = ["tx", "ty", "tz", "rx", "ry", "rz"];
                let all: Vec<Option<f64>> = p.t.iter().chain(p.r.iter()).copied().collect();
                if let Some(k) = all.iter().position(Option::is_none) {
                    return Err(err(
                        format!("tracklet {ti} pose {pi}: {}", names[k]),
                        "missing".into(),
                    ));
                }
                let v: Vec<f64> = all.into_iter().flatten().collect();
                c.poses.push(TrackletPose {
                    translation: Vector3::new(v[0], v[1], v[2]),
                    rotation: Vector3::new(v[3], v[4], v[5]),
                    state: p.state.unwrap_or(STATE_UNSET),
                    occlusion: p.occlusion.unwrap_or(OCCLUSION_UNSET),
                    truncation: p.truncation.unwrap_or(TRUNCATION_UNSET),
                });
            }
            ["tracklets", "item"] => {
                let c = current.take().unwrap_or_default();
                let f = |what: &str| format!("tracklet {ti}: {what}");
                let object_type = c
                    .object_type
                    .ok_or_else(|| err(f("objectType"), "missing".into()))?;
                let mut hwl = [0.0; 3];
                for (k, name) in ["h", "w", "l"].iter().enumerate() {
                    hwl[k] = c.hwl[k].ok_or_else(|| err(f(name), "missing".into()))?;
                }
                let first_frame = c
                    .first_frame
                    .ok_or_else(|| err(f("first_frame"), "missing".into()))?;
                if first_frame.checked_add(c.poses.len()).is_none() {
                    return Err(err(
                        f("first_frame"),
                        format!("{first_frame} plus {} poses overflows", c.poses.len()),
                    ));
                }
                out.items.push(Tracklet {
                    object_type,
                    h: hwl[0],
                    w: hwl[1],
                    l: hwl[2],
                    first_frame,
                    poses: c.poses,
                });
            }
            ["tracklets"] => {
                if let Some(n) = tracklet_count {
                    if n != out.items.len() {
                        return Err(err(
                            "tracklets: count".into(),
                            format!("says {n} but {} tracklet items follow", out.items.len()),
                        ));
                    }
                }
            }
            _ => {}
        }
        stack.pop();
    }
    if !stack.is_empty() {
        let line = lines.at(xml.len() as u64);
        return Err(Error::parse(
            path,
            line,
            stack.last().cloned().unwrap_or_default(),
            "element not closed before the end of the file",
        ));
    }
    if !seen_tracklets {
        return Err(Error::parse(path, 0, "tracklets", "no <tracklets> element"));
    }
    Ok(out)
}

/// The deepest element path the reader looks at (`tracklets/item/poses/item/tx`).
const MAX_RELATIVE_DEPTH: usize = 5;

/// The element path from `<tracklets>` on, when `<tracklets>` is the root or the root's child
/// and the path is no deeper than [`MAX_RELATIVE_DEPTH`]. Deeper elements are of no interest
/// and their paths are not copied, so that deeply nested input costs linear time.
fn relative_path(stack: &[String]) -> Option<Vec<String>> {
    let start = stack.iter().take(2).position(|s| s == "tracklets")?;
    let path = &stack[start..];
    (path.len() <= MAX_RELATIVE_DEPTH).then(|| path.to_vec())
}

fn parse_real(s: &str) -> std::result::Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("`{s}` is not a finite number")),
    }
}

fn parse_int(s: &str) -> std::result::Result<i32, String> {
    s.parse::<i32>()
        .map_err(|_| format!("`{s}` is not an integer"))
}

fn parse_num(s: &str) -> std::result::Result<usize, String> {
    s.parse::<usize>()
        .map_err(|_| format!("`{s}` is not a non-negative integer"))
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Writes tracklets in KITTI's Boost XML layout (readable by [`read_tracklets`] and by KITTI's
/// own tools), atomically. Fields this crate does not model are written with KITTI's "unset"
/// values.
pub fn write_tracklets(path: impl AsRef<Path>, tracklets: &Tracklets) -> Result<()> {
    write_atomically(path.as_ref(), |w| {
        writeln!(
            w,
            r#"<?xml version="1.0" encoding="UTF-8" standalone="yes" ?>"#
        )?;
        writeln!(w, "<!DOCTYPE boost_serialization>")?;
        writeln!(
            w,
            r#"<boost_serialization signature="serialization::archive" version="9">"#
        )?;
        writeln!(
            w,
            r#"<tracklets class_id="0" tracking_level="0" version="0">"#
        )?;
        writeln!(w, "\t<count>{}</count>", tracklets.items.len())?;
        writeln!(w, "\t<item_version>1</item_version>")?;
        for (i, t) in tracklets.items.iter().enumerate() {
            if i == 0 {
                writeln!(
                    w,
                    "\t<item class_id=\"1\" tracking_level=\"0\" version=\"1\">"
                )?;
            } else {
                writeln!(w, "\t<item>")?;
            }
            writeln!(w, "\t\t<objectType>{}</objectType>", escape(&t.object_type))?;
            writeln!(w, "\t\t<h>{:?}</h>", t.h)?;
            writeln!(w, "\t\t<w>{:?}</w>", t.w)?;
            writeln!(w, "\t\t<l>{:?}</l>", t.l)?;
            writeln!(w, "\t\t<first_frame>{}</first_frame>", t.first_frame)?;
            if i == 0 {
                writeln!(
                    w,
                    "\t\t<poses class_id=\"2\" tracking_level=\"0\" version=\"0\">"
                )?;
            } else {
                writeln!(w, "\t\t<poses>")?;
            }
            writeln!(w, "\t\t\t<count>{}</count>", t.poses.len())?;
            writeln!(w, "\t\t\t<item_version>2</item_version>")?;
            for (j, p) in t.poses.iter().enumerate() {
                if i == 0 && j == 0 {
                    writeln!(
                        w,
                        "\t\t\t<item class_id=\"3\" tracking_level=\"0\" version=\"2\">"
                    )?;
                } else {
                    writeln!(w, "\t\t\t<item>")?;
                }
                let (tr, r) = (p.translation, p.rotation);
                for (name, v) in [
                    ("tx", tr.x),
                    ("ty", tr.y),
                    ("tz", tr.z),
                    ("rx", r.x),
                    ("ry", r.y),
                    ("rz", r.z),
                ] {
                    writeln!(w, "\t\t\t\t<{name}>{v:?}</{name}>")?;
                }
                writeln!(w, "\t\t\t\t<state>{}</state>", p.state)?;
                writeln!(w, "\t\t\t\t<occlusion>{}</occlusion>", p.occlusion)?;
                writeln!(w, "\t\t\t\t<occlusion_kf>0</occlusion_kf>")?;
                writeln!(w, "\t\t\t\t<truncation>{}</truncation>", p.truncation)?;
                writeln!(w, "\t\t\t\t<amt_occlusion>-1</amt_occlusion>")?;
                writeln!(w, "\t\t\t\t<amt_occlusion_kf>-1</amt_occlusion_kf>")?;
                writeln!(w, "\t\t\t\t<amt_border_l>-1</amt_border_l>")?;
                writeln!(w, "\t\t\t\t<amt_border_r>-1</amt_border_r>")?;
                writeln!(w, "\t\t\t\t<amt_border_kf>-1</amt_border_kf>")?;
                writeln!(w, "\t\t\t</item>")?;
            }
            writeln!(w, "\t\t</poses>")?;
            writeln!(w, "\t\t<finished>1</finished>")?;
            writeln!(w, "\t</item>")?;
        }
        writeln!(w, "</tracklets>")?;
        writeln!(w, "</boost_serialization>")?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two() -> Tracklets {
        let mut car = Tracklet {
            object_type: "Car".into(),
            h: 1.5,
            w: 1.6,
            l: 3.9,
            first_frame: 1,
            poses: vec![],
        };
        for k in 0..3 {
            let mut p = TrackletPose::new(Vector3::new(10.0 + k as f64, 2.0, -1.7), 0.1);
            p.state = 2;
            p.occlusion = 0;
            p.truncation = 0;
            car.poses.push(p);
        }
        let ped = Tracklet {
            object_type: "Pedestrian & dog".into(),
            h: 1.8,
            w: 0.6,
            l: 0.8,
            first_frame: 0,
            poses: vec![TrackletPose::new(Vector3::new(5.0, -3.0, -1.6), -0.5)],
        };
        Tracklets {
            items: vec![car, ped],
        }
    }

    #[test]
    fn write_read_round_trip_and_objects_at() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("tracklet_labels.xml");
        write_tracklets(&p, &two()).unwrap();
        let back = read_tracklets(&p).unwrap();
        assert_eq!(back, two());
        assert_eq!(back.objects_at(0).len(), 1);
        assert_eq!(back.objects_at(0)[0].object_type, "Pedestrian & dog");
        let at2 = back.objects_at(2);
        assert_eq!(at2.len(), 1);
        assert_eq!(at2[0].id, 0);
        assert_eq!(at2[0].pose.translation.x, 11.0);
        assert!((at2[0].center().z - (-1.7 + 0.75)).abs() < 1e-12);
        assert!(back.objects_at(4).is_empty());
        assert_eq!(back.end_frame(), 4);
    }

    #[test]
    fn a_first_frame_that_overflows_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.xml");
        write_tracklets(&p, &two()).unwrap();
        let good = std::fs::read_to_string(&p).unwrap();
        let first = good.find("<first_frame>").unwrap();
        let end = good[first..].find("</first_frame>").unwrap() + first;
        let bad = format!(
            "{}<first_frame>{}{}",
            &good[..first],
            usize::MAX,
            &good[end..]
        );
        let msg = parse_tracklets(Path::new("t.xml"), &bad)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("t.xml") && msg.contains("overflows"), "{msg}");
    }

    #[test]
    fn errors_name_line_and_element() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.xml");
        write_tracklets(&p, &two()).unwrap();
        let good = std::fs::read_to_string(&p).unwrap();
        let bad = good.replacen("<ty>3.0</ty>", "<ty>three</ty>", 1).replacen(
            "<ty>2.0</ty>",
            "<ty>x</ty>",
            1,
        );
        let msg = parse_tracklets(Path::new("t.xml"), &bad)
            .unwrap_err()
            .to_string();
        let line = bad.lines().position(|l| l.contains("<ty>x</ty>")).unwrap() + 1;
        assert_eq!(
            msg,
            format!("t.xml:{line}: tracklet 0 pose 0: ty: `x` is not a finite number")
        );
        let no_tz = good.replacen("<tz>-1.7</tz>", "", 1);
        let msg = parse_tracklets(Path::new("t.xml"), &no_tz)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("tracklet 0 pose 0: tz: missing"), "{msg}");
        let wrong_count = good.replacen("<count>2</count>", "<count>3</count>", 1);
        let msg = parse_tracklets(Path::new("t.xml"), &wrong_count)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("says 3 but 2"), "{msg}");
        let broken = good.replacen("</poses>", "</posse>", 1);
        assert!(parse_tracklets(Path::new("t.xml"), &broken).is_err());
        let truncated = &good[..good.len() / 2];
        assert!(parse_tracklets(Path::new("t.xml"), truncated).is_err());
        assert!(parse_tracklets(Path::new("t.xml"), "<a/>").is_err());
    }

    #[test]
    fn deep_nesting_costs_linear_time() {
        // Copying the element path at every level made this quadratic (minutes for 50 000).
        let n = 100_000;
        let xml = format!(
            "<tracklets>{}{}</tracklets>",
            "<a>".repeat(n),
            "</a>".repeat(n)
        );
        let start = std::time::Instant::now();
        let t = parse_tracklets(Path::new("t.xml"), &xml).unwrap();
        assert!(t.items.is_empty());
        assert!(start.elapsed().as_secs() < 30, "{:?}", start.elapsed());
    }
}
