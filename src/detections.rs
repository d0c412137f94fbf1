//! Users' own detections and the filter's estimates as files.
//!
//! Two formats, chosen by file extension:
//!
//! **JSON** (`.json`): `{"frames": [{"time": 0.0, "measurements": [[x, y], ...],
//! "sensor_pose": [x, y, heading]}, ...]}`. `sensor_pose` is optional (a planar platform pose in
//! the world frame); a truth file may add `"ids": [7, 9, ...]`, one per measurement row.
//!
//! **CSV** (`.csv`): a header line, then one measurement per line:
//! `frame,time[,sensor],z0,z1[,z2...][,sensor_x,sensor_y,sensor_heading][,id]`. Columns are
//! found by name in the header (`z0`, `z1`, … for the measurement). A line whose `z` fields are
//! all empty declares an empty frame. Frames must appear in non-decreasing order of `frame`;
//! missing frame numbers in between are empty frames, their times interpolated between the
//! neighbouring listed frames' (at most [`MAX_FRAME_GAP`] of them in the whole file).
//!
//! **Several sensors**: a JSON entry may name its sensor (`"sensor": "front"`), and several
//! entries of one time (one per sensor) make one frame of the filter; in CSV the optional
//! `sensor` column does the same for the lines of one frame number. A line (or entry) with
//! empty measurement fields and a sensor name declares that the sensor saw nothing; a sensor
//! without a line in a frame did not report. Two entries of one sensor at one time are an
//! error. [`filter_frames`] groups the entries into the filter's frames.
//!
//! Estimates are written as JSON (`{"frames": [{"frame", "time", "estimates": [{"label":
//! {"birth_step", "index"}, "existence", "state", "age"}]}]}`) or CSV
//! (`frame,time,birth_step,index,existence,age,x0,x1,...`), always atomically: to a temporary
//! file beside the target, renamed into place when complete. Not for: sensor formats (see
//! the KITTI and laser readers).

use crate::error::{Error, Result};
use crate::filter::Estimate;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The most empty frames a CSV file may leave unlisted, counted over the whole file (between
/// listed frame numbers and before the first one): more are refused as a typo rather than
/// allocated, so that a few short lines cannot fill memory with empty frames.
pub const MAX_FRAME_GAP: usize = 1_000_000;

/// Appends empty frames up to and including `frame` (when it is not there yet). A frame
/// inside a gap gets its time interpolated linearly between the last listed frame's and
/// `time`; frames before the file's first listed frame get `time`.
fn push_gap_frames(frames: &mut Vec<DetectionFrame>, frame: usize, time: f64) {
    let last = frames.len().checked_sub(1).map(|k| (k, frames[k].time));
    while frames.len() <= frame {
        let k = frames.len();
        let t = match last {
            Some((k0, t0)) => t0 + (time - t0) * (k - k0) as f64 / (frame - k0) as f64,
            None => time,
        };
        frames.push(DetectionFrame {
            time: if k == frame { time } else { t },
            sensor: None,
            measurements: Vec::new(),
            sensor_pose: None,
            ids: None,
        });
    }
}

/// One frame of a detections (or truth) file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DetectionFrame {
    /// Time stamp, seconds.
    pub time: f64,
    /// The sensor that measured them (files of several sensors).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor: Option<String>,
    /// Measurement vectors.
    #[serde(default)]
    pub measurements: Vec<Vec<f64>>,
    /// Planar sensor (platform) pose `[x, y, heading]` in the world frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor_pose: Option<[f64; 3]>,
    /// Object identities, one per measurement (truth files).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ids: Option<Vec<u64>>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct DetectionFile {
    frames: Vec<DetectionFrame>,
}

/// The estimates of one frame, as written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EstimateFrame {
    /// Frame index.
    pub frame: usize,
    /// Time stamp, seconds.
    pub time: f64,
    /// Estimates.
    pub estimates: Vec<Estimate>,
}

/// What to do with a measurement row that holds NaN or an infinity.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum NonFinite {
    /// Refuse the file, naming frame/line and field (the default).
    #[default]
    Error,
    /// Leave the row out and count it.
    Skip,
}

/// Reads a detections or truth file (`.json` or `.csv`), checking that every number is finite
/// and every frame's measurements have the same dimension as the first one.
pub fn read_frames(path: &Path) -> Result<Vec<DetectionFrame>> {
    read_frames_with(path, NonFinite::Error).map(|(frames, _)| frames)
}

/// Like [`read_frames`], with a policy for non-finite measurement values (JSON cannot hold them;
/// CSV cells such as `nan` or `inf` can). Returns the frames and the number of rows skipped.
pub fn read_frames_with(path: &Path, policy: NonFinite) -> Result<(Vec<DetectionFrame>, usize)> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let mut skipped = 0;
    let frames = match extension(path).as_str() {
        "json" => parse_json(path, &text)?,
        "csv" => parse_csv(path, &text, policy, &mut skipped)?,
        other => {
            return Err(Error::parse(
                path,
                0,
                "file name",
                format!("unknown extension `{other}` (expected .json or .csv)"),
            ))
        }
    };
    check_frames(path, &frames)?;
    Ok((frames, skipped))
}

fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

fn parse_json(path: &Path, text: &str) -> Result<Vec<DetectionFrame>> {
    let file: DetectionFile = serde_json::from_str(text)
        .map_err(|e| Error::parse(path, e.line(), "json", e.to_string()))?;
    Ok(file.frames)
}

fn check_frames(path: &Path, frames: &[DetectionFrame]) -> Result<()> {
    let dim = frames
        .iter()
        .flat_map(|f| f.measurements.first())
        .map(|m| m.len())
        .next();
    let mut last_time = f64::NEG_INFINITY;
    for (k, f) in frames.iter().enumerate() {
        let field = |s: &str| format!("frames[{k}].{s}");
        if !f.time.is_finite() {
            return Err(Error::parse(
                path,
                0,
                field("time"),
                format!("{} is not finite", f.time),
            ));
        }
        if f.time < last_time {
            return Err(Error::parse(
                path,
                0,
                field("time"),
                format!("{} is before the previous frame's {}", f.time, last_time),
            ));
        }
        if let Some(name) = &f.sensor {
            let same_time = frames[..k].iter().rev().take_while(|o| o.time == f.time);
            if same_time.clone().any(|o| o.sensor.as_ref() == Some(name)) {
                return Err(Error::parse(
                    path,
                    0,
                    field("sensor"),
                    format!("sensor {name:?} has two frames at time {}", f.time),
                ));
            }
        }
        last_time = f.time;
        for (j, m) in f.measurements.iter().enumerate() {
            if Some(m.len()) != dim || m.is_empty() {
                return Err(Error::parse(
                    path,
                    0,
                    field(&format!("measurements[{j}]")),
                    format!("has {} components, expected {}", m.len(), dim.unwrap_or(0)),
                ));
            }
            if let Some(v) = m.iter().find(|v| !v.is_finite()) {
                return Err(Error::parse(
                    path,
                    0,
                    field(&format!("measurements[{j}]")),
                    format!("value {v} is not finite"),
                ));
            }
        }
        if let Some(p) = f.sensor_pose {
            if p.iter().any(|v| !v.is_finite()) {
                return Err(Error::parse(path, 0, field("sensor_pose"), "is not finite"));
            }
        }
        if let Some(ids) = &f.ids {
            if ids.len() != f.measurements.len() {
                return Err(Error::parse(
                    path,
                    0,
                    field("ids"),
                    format!(
                        "{} ids for {} measurements",
                        ids.len(),
                        f.measurements.len()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The columns of a detections CSV file, found by name in its header line.
struct CsvColumns<'a> {
    names: Vec<&'a str>,
    frame: usize,
    time: usize,
    z: Vec<usize>,
    pose: Option<[usize; 3]>,
    id: Option<usize>,
    sensor: Option<usize>,
}

impl<'a> CsvColumns<'a> {
    fn parse(path: &Path, header: &'a str) -> Result<Self> {
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        let col = |name: &str| names.iter().position(|n| *n == name);
        let frame =
            col("frame").ok_or_else(|| Error::parse(path, 1, "header", "no `frame` column"))?;
        let time =
            col("time").ok_or_else(|| Error::parse(path, 1, "header", "no `time` column"))?;
        let z: Vec<usize> = (0..).map_while(|i| col(&format!("z{i}"))).collect();
        if z.is_empty() {
            return Err(Error::parse(
                path,
                1,
                "header",
                "no measurement columns `z0`, `z1`, ...",
            ));
        }
        let pose = match (col("sensor_x"), col("sensor_y"), col("sensor_heading")) {
            (Some(a), Some(b), Some(c)) => Some([a, b, c]),
            (None, None, None) => None,
            _ => {
                return Err(Error::parse(
                    path,
                    1,
                    "header",
                    "sensor pose needs all of sensor_x, sensor_y, sensor_heading",
                ))
            }
        };
        let id = col("id");
        let sensor = col("sensor");
        Ok(CsvColumns {
            names,
            frame,
            time,
            z,
            pose,
            id,
            sensor,
        })
    }
}

/// One data line's cells, with what an error about one of them names: the file, the line
/// and the column.
struct CsvRow<'a> {
    path: &'a Path,
    line: usize,
    names: &'a [&'a str],
    cells: Vec<&'a str>,
}

impl<'a> CsvRow<'a> {
    fn split(path: &'a Path, line: usize, names: &'a [&'a str], text: &'a str) -> Result<Self> {
        let cells: Vec<&str> = text.split(',').map(str::trim).collect();
        if cells.len() != names.len() {
            return Err(Error::parse(
                path,
                line,
                "line",
                format!("{} fields, the header has {}", cells.len(), names.len()),
            ));
        }
        Ok(CsvRow {
            path,
            line,
            names,
            cells,
        })
    }

    fn is_empty(&self, c: usize) -> bool {
        self.cells[c].is_empty()
    }

    /// The number in column `c`, whatever its value.
    fn raw(&self, c: usize) -> Result<f64> {
        self.parsed(c, "a number")
    }

    /// The finite number in column `c`.
    fn num(&self, c: usize) -> Result<f64> {
        let v = self.raw(c)?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.error(self.names[c], format!("{v} is not finite")))
        }
    }

    /// Column `c` parsed as a `T`; an error says the cell is not `what` (a number, a frame
    /// number, an id) and names the column.
    fn parsed<T: std::str::FromStr>(&self, c: usize, what: &str) -> Result<T> {
        self.cells[c]
            .parse()
            .map_err(|_| self.error(self.names[c], format!("`{}` is not {what}", self.cells[c])))
    }

    fn error(&self, field: &str, message: String) -> Error {
        Error::parse(self.path, self.line, field, message)
    }
}

fn parse_csv(
    path: &Path,
    text: &str,
    policy: NonFinite,
    skipped: &mut usize,
) -> Result<Vec<DetectionFrame>> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'));
    let Some((_, header)) = lines.next() else {
        return Err(Error::parse(path, 1, "header", "the file is empty"));
    };
    let columns = CsvColumns::parse(path, header)?;
    // One entry per frame number, or per (frame number, sensor) with a `sensor` column;
    // `numbers[k]` is entry k's frame number.
    let mut frames: Vec<DetectionFrame> = Vec::new();
    let mut numbers: Vec<usize> = Vec::new();
    let mut unlisted = 0usize;
    for (i, line) in lines {
        let row = CsvRow::split(path, i + 1, &columns.names, line)?;
        let frame: usize = row.parsed(columns.frame, "a frame number")?;
        let time = row.num(columns.time)?;
        let sensor = columns
            .sensor
            .map(|c| row.cells[c])
            .filter(|s| !s.is_empty())
            .map(str::to_string);
        let last = numbers.last().copied();
        if let Some(n) = last.filter(|&n| frame < n) {
            return Err(row.error("frame", format!("frame {frame} after frame {n}")));
        }
        if last != Some(frame) {
            let next = last.map_or(0, |n| n + 1);
            let gap = frame - next;
            unlisted = unlisted.saturating_add(gap);
            if unlisted > MAX_FRAME_GAP {
                return Err(row.error(
                    "frame",
                    format!(
                        "frame {frame} would leave {gap} empty frames before it, {unlisted} in \
                         the file so far; at most {MAX_FRAME_GAP} are accepted"
                    ),
                ));
            }
            let listed = frames.len();
            let mut padded: Vec<DetectionFrame> =
                frames.last().map(|f| vec![f.clone()]).unwrap_or_default();
            let target = frame - next + padded.len();
            push_gap_frames(&mut padded, target, time);
            // `padded` is [last listed entry, gap frames.., this frame]; keep the new ones.
            let skip = usize::from(listed > 0);
            numbers.extend((next..=frame).take(padded.len() - skip));
            frames.extend(padded.into_iter().skip(skip));
            frames.last_mut().expect("just pushed").sensor = sensor.clone();
        }
        // This frame number's entries start where its number does.
        let start = numbers
            .iter()
            .rposition(|&n| n != frame)
            .map_or(0, |k| k + 1);
        if frames[start].time != time {
            return Err(row.error(
                "time",
                format!(
                    "{time} differs from {} earlier in frame {frame}",
                    frames[start].time
                ),
            ));
        }
        let k = match (start..frames.len()).find(|&k| frames[k].sensor == sensor) {
            Some(k) => k,
            None => {
                frames.push(DetectionFrame {
                    time,
                    sensor: sensor.clone(),
                    measurements: Vec::new(),
                    sensor_pose: None,
                    ids: None,
                });
                numbers.push(frame);
                frames.len() - 1
            }
        };
        if let Some(name) = &sensor {
            let earlier = frames[..start].iter().rev().take_while(|o| o.time == time);
            if earlier.clone().any(|o| o.sensor.as_ref() == Some(name)) {
                return Err(row.error(
                    "sensor",
                    format!("sensor {name:?} has two frames at time {time}"),
                ));
            }
        }
        let f = &mut frames[k];
        if let Some(pc) = columns.pose {
            if pc.iter().all(|&c| !row.is_empty(c)) {
                f.sensor_pose = Some([row.num(pc[0])?, row.num(pc[1])?, row.num(pc[2])?]);
            }
        }
        if columns.z.iter().all(|&c| row.is_empty(c)) {
            continue;
        }
        let z = match policy {
            NonFinite::Error => columns
                .z
                .iter()
                .map(|&c| row.num(c))
                .collect::<Result<Vec<f64>>>()?,
            NonFinite::Skip => {
                let z = columns
                    .z
                    .iter()
                    .map(|&c| row.raw(c))
                    .collect::<Result<Vec<f64>>>()?;
                if z.iter().any(|v| !v.is_finite()) {
                    *skipped += 1;
                    continue;
                }
                z
            }
        };
        f.measurements.push(z);
        if let Some(c) = columns.id {
            let id: u64 = row.parsed(c, "an id")?;
            f.ids.get_or_insert_with(Vec::new).push(id);
        }
    }
    Ok(frames)
}

/// The filter's frames of a detections file's entries, as ranges of entry indices:
/// consecutive entries of one time that name their sensors make one frame (one scan each);
/// an entry without a sensor name is a frame of its own.
pub fn filter_frames(frames: &[DetectionFrame]) -> Vec<std::ops::Range<usize>> {
    let mut out: Vec<std::ops::Range<usize>> = Vec::new();
    for (k, f) in frames.iter().enumerate() {
        match out.last_mut() {
            Some(r)
                if f.sensor.is_some()
                    && frames[r.start].sensor.is_some()
                    && frames[r.start].time == f.time =>
            {
                r.end = k + 1
            }
            _ => out.push(k..k + 1),
        }
    }
    out
}

/// Writes estimates as JSON or CSV (by extension), atomically.
pub fn write_estimates(path: &Path, frames: &[EstimateFrame]) -> Result<()> {
    let bytes = match extension(path).as_str() {
        "json" => {
            #[derive(Serialize)]
            struct Out<'a> {
                frames: &'a [EstimateFrame],
            }
            serde_json::to_vec_pretty(&Out { frames })
                .map_err(|e| Error::invalid("estimates", e.to_string()))?
        }
        "csv" => {
            let dim = frames
                .iter()
                .flat_map(|f| f.estimates.first())
                .map(|e| e.state.len())
                .next()
                .unwrap_or(0);
            let mut s = String::from("frame,time,birth_step,index,existence,age");
            for c in 0..dim {
                s.push_str(&format!(",x{c}"));
            }
            s.push('\n');
            for f in frames {
                for e in &f.estimates {
                    s.push_str(&format!(
                        "{},{},{},{},{},{}",
                        f.frame, f.time, e.label.birth_step, e.label.index, e.existence, e.age
                    ));
                    for v in &e.state {
                        s.push_str(&format!(",{v}"));
                    }
                    s.push('\n');
                }
            }
            s.into_bytes()
        }
        other => {
            return Err(Error::invalid(
                "output path",
                format!("unknown extension `{other}` (expected .json or .csv)"),
            ))
        }
    };
    crate::atomic::write_bytes(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::Label;

    fn tmp(name: &str, content: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("smc-lmb-det-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, content).unwrap();
        p
    }

    #[test]
    fn hostile_frame_numbers_are_refused_and_gaps_interpolated() {
        let p = tmp("gap.csv", "frame,time,z0,z1\n0,0.0,1,2\n4,2.0,1,2\n");
        let f = read_frames(&p).unwrap();
        let times: Vec<f64> = f.iter().map(|f| f.time).collect();
        assert_eq!(times, vec![0.0, 0.5, 1.0, 1.5, 2.0]);
        assert!(f[1..4].iter().all(|f| f.measurements.is_empty()));
        for frame in ["4000000000", "18446744073709551615"] {
            let p = tmp(
                "huge.csv",
                &format!("frame,time,z0,z1\n0,0.0,1,2\n{frame},1.0,1,2\n"),
            );
            let e = read_frames(&p).unwrap_err().to_string();
            assert!(e.contains("huge.csv:3") && e.contains("at most"), "{e}");
        }
        let p = tmp(
            "over.csv",
            "frame,time,z0,z1\n18446744073709551616,1.0,1,2\n",
        );
        let e = read_frames(&p).unwrap_err().to_string();
        assert!(
            e.contains("over.csv:2") && e.contains("not a frame number"),
            "{e}"
        );
        // Gaps each within the limit add up: three lines may not fill 88 MB each.
        let p = tmp(
            "gaps.csv",
            "frame,time,z0,z1\n600000,0.0,1,2\n1200000,1.0,1,2\n1800000,2.0,1,2\n",
        );
        let e = read_frames(&p).unwrap_err().to_string();
        assert!(
            e.contains("gaps.csv:3") && e.contains("1199999 in the file"),
            "{e}"
        );
    }

    #[test]
    fn csv_with_empty_and_skipped_frames() {
        let p = tmp(
            "a.csv",
            "frame,time,z0,z1,id\n0,0.0,1,2,7\n0,0.0,3,4,8\n1,1.0,,,\n3,3.0,5,6,7\n",
        );
        let f = read_frames(&p).unwrap();
        assert_eq!(f.len(), 4);
        assert_eq!(f[0].measurements, vec![vec![1.0, 2.0], vec![3.0, 4.0]]);
        assert_eq!(f[0].ids, Some(vec![7, 8]));
        assert!(f[1].measurements.is_empty());
        assert!(f[2].measurements.is_empty());
        assert_eq!(f[3].measurements, vec![vec![5.0, 6.0]]);
    }

    #[test]
    fn csv_errors_name_line_and_field() {
        let p = tmp("b.csv", "frame,time,z0,z1\n0,0.0,1,2\n0,0.0,nan,2\n");
        let e = read_frames(&p).unwrap_err().to_string();
        assert!(
            e.contains("b.csv:3") && e.contains("z0") && e.contains("not finite"),
            "{e}"
        );
        let (f, skipped) = read_frames_with(&p, NonFinite::Skip).unwrap();
        assert_eq!((f[0].measurements.len(), skipped), (1, 1));
        let p = tmp("c.csv", "frame,time,z0,z1\n0,0.0,1\n");
        let e = read_frames(&p).unwrap_err().to_string();
        assert!(e.contains("c.csv:2") && e.contains("fields"), "{e}");
        let p = tmp("d.csv", "frame,time,z0,z1\n1,1.0,1,2\n0,0.0,1,2\n");
        assert!(read_frames(&p)
            .unwrap_err()
            .to_string()
            .contains("frame 0 after frame 1"));
        for (name, text, expected) in [
            (
                "e.csv",
                "frame,time,z0\nx,0.0,1\n",
                ["e.csv:2", "frame", "`x` is not a frame number"],
            ),
            (
                "f.csv",
                "frame,time,z0,id\n0,0.0,1,-3\n",
                ["f.csv:2", "id", "`-3` is not an id"],
            ),
            (
                "g.csv",
                "frame,z0\n0,1\n",
                ["g.csv:1", "header", "no `time` column"],
            ),
            (
                "h.csv",
                "frame,time,z0,sensor_x\n0,0.0,1,2\n",
                ["h.csv:1", "header", "sensor_heading"],
            ),
            (
                "i.csv",
                "frame,time,z0\n0,0.0,1\n0,0.5,2\n",
                ["i.csv:3", "time", "differs from 0"],
            ),
        ] {
            let e = read_frames(&tmp(name, text)).unwrap_err().to_string();
            assert!(expected.iter().all(|x| e.contains(x)), "{e}");
        }
    }

    #[test]
    fn json_errors_name_the_frame() {
        let p = tmp(
            "a.json",
            r#"{"frames": [{"time": 0, "measurements": [[1, 2]]}, {"time": 1, "measurements": [[1, 2, 3]]}]}"#,
        );
        let e = read_frames(&p).unwrap_err().to_string();
        assert!(e.contains("frames[1].measurements[0]"), "{e}");
        let p = tmp(
            "b.json",
            "{\"frames\": [\n{\"time\": 0, \"measurements\": [[1, 2]]},\n{\"time\": x}]}",
        );
        let e = read_frames(&p).unwrap_err().to_string();
        assert!(e.contains("b.json:3"), "{e}");
        let p = tmp("c.json", r#"{"frames": [{"time": 2}, {"time": 1}]}"#);
        assert!(read_frames(&p)
            .unwrap_err()
            .to_string()
            .contains("before the previous frame"));
    }

    #[test]
    fn estimates_round_trip_through_json_and_csv() {
        let frames = vec![EstimateFrame {
            frame: 0,
            time: 0.5,
            estimates: vec![Estimate {
                label: Label::new(0, 1),
                existence: 0.9,
                state: vec![1.0, 2.0],
                age: 0,
            }],
        }];
        let p = tmp("out.json", "");
        write_estimates(&p, &frames).unwrap();
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
        assert_eq!(v["frames"][0]["estimates"][0]["label"]["index"], 1);
        let p = tmp("out.csv", "");
        write_estimates(&p, &frames).unwrap();
        let s = std::fs::read_to_string(&p).unwrap();
        assert_eq!(
            s,
            "frame,time,birth_step,index,existence,age,x0,x1\n0,0.5,0,1,0.9,0,1,2\n"
        );
        assert!(write_estimates(&tmp("x.txt", ""), &frames).is_err());
    }

    #[test]
    fn sensors_share_frames_and_are_grouped() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("d.csv");
        std::fs::write(
            &p,
            "frame,time,sensor,z0,z1\n0,0.0,front,1,2\n0,0.0,rear,3,4\n0,0.0,front,5,6\n\
             1,0.1,front,,\n3,0.3,rear,7,8\n",
        )
        .unwrap();
        let f = read_frames(&p).unwrap();
        let got: Vec<(f64, Option<&str>, usize)> = f
            .iter()
            .map(|f| (f.time, f.sensor.as_deref(), f.measurements.len()))
            .collect();
        assert_eq!(
            got,
            vec![
                (0.0, Some("front"), 2),
                (0.0, Some("rear"), 1),
                (0.1, Some("front"), 0),
                (0.2, None, 0),
                (0.3, Some("rear"), 1),
            ]
        );
        assert_eq!(filter_frames(&f), vec![0..2, 2..3, 3..4, 4..5]);
        // One sensor twice at one time, in CSV (line named) and in JSON (entry named).
        std::fs::write(&p, "frame,time,sensor,z0,z1\n0,0.0,a,1,2\n1,0.0,a,3,4\n").unwrap();
        let e = read_frames(&p).unwrap_err().to_string();
        assert!(
            e.contains(":3:") && e.contains("\"a\" has two frames"),
            "{e}"
        );
        let j = dir.path().join("d.json");
        std::fs::write(
            &j,
            r#"{"frames": [{"time": 0.0, "sensor": "a", "measurements": [[1, 2]]},
                           {"time": 0.0, "sensor": "b", "measurements": []},
                           {"time": 0.0, "sensor": "a", "measurements": []}]}"#,
        )
        .unwrap();
        let e = read_frames(&j).unwrap_err().to_string();
        assert!(e.contains("frames[2].sensor") && e.contains("\"a\""), "{e}");
    }
}
