//! The project's own plain-text scan format ("laser2d csv v1"): one scan per line, easy to
//! produce from any recorder and to diff. Read and written here; writing is atomic (a
//! temporary file beside the target, renamed into place). Not for: sensor-native formats
//! (CARMEN, ROS bags) or segment / track output.
//!
//! # Format
//!
//! ```text
//! # smc-lmb laser2d csv v1
//! time,angle_min,angle_increment,range_min,range_max,odom_x,odom_y,odom_theta,num_ranges,ranges...
//! 976052857.337284,-1.5707963267948966,0.017453292519943295,0,80,0,0,-0.002458,3,1.07,NaN,81.83
//! ```
//!
//! * Line 1 is exactly the version line above, line 2 exactly the column header. After
//!   them, blank lines and lines starting with `#` are ignored.
//! * `time` (s), `angle_min`, `angle_increment` (rad) and `range_min` (m) are finite;
//!   `range_max` (m) may be `inf`. They mean what the [`Scan`] fields of the same name mean.
//! * `odom_x,odom_y,odom_theta` are the odometry pose, or all three empty when there is none.
//! * `num_ranges` is the number of beams; exactly that many range fields follow. A range
//!   may be any number including `NaN` and `inf` ("no return" beams are kept as written).
//! * Times never decrease from one line to the next.
//!
//! [`Scan::laser_pose`] is not stored. Numbers are written in Rust's shortest round-trip
//! notation, so a written file reads back to identical values.

use super::scan::Scan;
use crate::error::{Error, Result};
use crate::geometry::Pose2;
use std::fmt::Write as _;
use std::io::{BufRead, BufReader};
use std::path::Path;

/// The first line of a v1 file.
pub const CSV_MAGIC: &str = "# smc-lmb laser2d csv v1";
/// The second line of a v1 file.
pub const CSV_HEADER: &str =
    "time,angle_min,angle_increment,range_min,range_max,odom_x,odom_y,odom_theta,num_ranges,ranges...";

/// Writes `scans` as laser2d csv v1, atomically. Every scan must pass [`Scan::validate`]
/// and times must not decrease; otherwise nothing is written.
pub fn write_scan_csv(path: impl AsRef<Path>, scans: &[Scan]) -> Result<()> {
    let mut text = String::new();
    text.push_str(CSV_MAGIC);
    text.push('\n');
    text.push_str(CSV_HEADER);
    text.push('\n');
    let mut prev = f64::NEG_INFINITY;
    for (k, s) in scans.iter().enumerate() {
        s.validate()
            .map_err(|e| Error::invalid(format!("scan {k}"), e.to_string()))?;
        if s.time < prev {
            return Err(Error::invalid(
                format!("scan {k}"),
                format!("time {} is earlier than the previous scan's {prev}", s.time),
            ));
        }
        prev = s.time;
        // Writing into a String cannot fail.
        let _ = write!(
            text,
            "{},{},{},{},{},",
            s.time, s.angle_min, s.angle_increment, s.range_min, s.range_max
        );
        match s.odometry {
            Some(p) => {
                let _ = write!(text, "{},{},{},", p.x, p.y, p.theta);
            }
            None => text.push_str(",,,"),
        }
        let _ = write!(text, "{}", s.ranges.len());
        for r in &s.ranges {
            let _ = write!(text, ",{r}");
        }
        text.push('\n');
    }
    crate::atomic::write_bytes(path.as_ref(), text.as_bytes())
}

/// Reads a laser2d csv v1 file. Every problem is an [`Error::Parse`] naming the line and
/// the field.
pub fn read_scan_csv(path: impl AsRef<Path>) -> Result<Vec<Scan>> {
    let path = path.as_ref();
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let reader = BufReader::new(file);
    let mut scans = Vec::new();
    let mut prev: Option<f64> = None;
    let mut saw_magic = false;
    for (k, line) in reader.lines().enumerate() {
        let line_no = k + 1;
        let line = line.map_err(|e| {
            Error::io(
                path,
                std::io::Error::new(e.kind(), format!("line {line_no}: {e}")),
            )
        })?;
        let text = line.trim_end_matches('\r');
        if line_no == 1 {
            if text.trim_end() != CSV_MAGIC {
                return Err(Error::parse(
                    path,
                    1,
                    "version line",
                    format!("expected `{CSV_MAGIC}`"),
                ));
            }
            saw_magic = true;
            continue;
        }
        if line_no == 2 {
            if text.trim() != CSV_HEADER {
                return Err(Error::parse(
                    path,
                    2,
                    "header",
                    format!("expected `{CSV_HEADER}`"),
                ));
            }
            continue;
        }
        let trimmed = text.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let scan = parse_row(trimmed, path, line_no)?;
        if let Some(p) = prev {
            if scan.time < p {
                return Err(Error::parse(
                    path,
                    line_no,
                    "time",
                    format!("{} is earlier than the previous scan's {p}", scan.time),
                ));
            }
        }
        prev = Some(scan.time);
        scans.push(scan);
    }
    if !saw_magic {
        return Err(Error::parse(path, 1, "version line", "the file is empty"));
    }
    Ok(scans)
}

fn parse_row(text: &str, path: &Path, line: usize) -> Result<Scan> {
    let cells: Vec<&str> = text.split(',').map(str::trim).collect();
    let err = |field: &str, reason: String| Error::parse(path, line, field, reason);
    let cell = |i: usize, name: &str| -> Result<&str> {
        cells.get(i).copied().ok_or_else(|| {
            err(
                name,
                format!("missing (the line has {} fields)", cells.len()),
            )
        })
    };
    let number = |i: usize, name: &str, allow_inf: bool| -> Result<f64> {
        let c = cell(i, name)?;
        let v: f64 = c
            .parse()
            .map_err(|_| err(name, format!("`{c}` is not a number")))?;
        if v.is_nan() || (v.is_infinite() && !allow_inf) {
            return Err(err(name, format!("`{c}` is not finite")));
        }
        Ok(v)
    };
    let time = number(0, "time", false)?;
    let angle_min = number(1, "angle_min", false)?;
    let angle_increment = number(2, "angle_increment", false)?;
    let range_min = number(3, "range_min", false)?;
    let range_max = number(4, "range_max", true)?;
    let names = ["odom_x", "odom_y", "odom_theta"];
    let odom_cells = [cell(5, names[0])?, cell(6, names[1])?, cell(7, names[2])?];
    let odometry = if odom_cells.iter().all(|c| c.is_empty()) {
        None
    } else {
        let mut v = [0.0; 3];
        for (j, name) in names.iter().enumerate() {
            if odom_cells[j].is_empty() {
                return Err(err(
                    name,
                    "empty while another odometry field is set (all three or none)".into(),
                ));
            }
            v[j] = number(5 + j, name, false)?;
        }
        Some(Pose2::new(v[0], v[1], v[2]))
    };
    let n_text = cell(8, "num_ranges")?;
    let n: usize = n_text
        .parse()
        .map_err(|_| err("num_ranges", format!("`{n_text}` is not a count")))?;
    if cells.len() - 9 != n {
        return Err(err(
            "num_ranges",
            format!("declares {n} ranges, but {} follow", cells.len() - 9),
        ));
    }
    let mut ranges = Vec::with_capacity(n);
    for (j, c) in cells[9..].iter().enumerate() {
        let r: f32 = c
            .parse()
            .map_err(|_| err(&format!("range[{j}]"), format!("`{c}` is not a number")))?;
        ranges.push(r);
    }
    let mut scan = Scan::new(
        time,
        angle_min,
        angle_increment,
        ranges,
        range_min,
        range_max,
    )
    .map_err(|e| {
        let reason = match e {
            Error::InvalidInput { reason, .. } => reason,
            other => other.to_string(),
        };
        err("header values", reason)
    })?;
    scan.odometry = odometry;
    Ok(scan)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir() -> tempfile::TempDir {
        tempfile::tempdir().unwrap()
    }

    fn sample() -> Vec<Scan> {
        let mut a = Scan::new(
            976052857.337284,
            -std::f64::consts::FRAC_PI_2,
            std::f64::consts::PI / 3.0,
            vec![1.07, f32::NAN, 81.83],
            0.0,
            80.0,
        )
        .unwrap();
        a.odometry = Some(Pose2::new(0.1, -0.2, 1e-7));
        let b = Scan::new(
            976052857.5,
            0.0,
            -0.01,
            vec![f32::INFINITY, 0.0],
            0.02,
            f64::INFINITY,
        )
        .unwrap();
        vec![a, b]
    }

    fn same(a: &Scan, b: &Scan) -> bool {
        a.time == b.time
            && a.angle_min == b.angle_min
            && a.angle_increment == b.angle_increment
            && a.range_min == b.range_min
            && a.range_max == b.range_max
            && a.odometry == b.odometry
            && a.ranges.len() == b.ranges.len()
            && a.ranges
                .iter()
                .zip(&b.ranges)
                .all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()))
    }

    #[test]
    fn round_trip() {
        let d = dir();
        let p = d.path().join("scans.csv");
        let scans = sample();
        write_scan_csv(&p, &scans).unwrap();
        let back = read_scan_csv(&p).unwrap();
        assert_eq!(back.len(), 2);
        assert!(same(&scans[0], &back[0]) && same(&scans[1], &back[1]));
        // Nothing else left in the folder (the temporary file was renamed).
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 1);
    }

    #[test]
    fn write_rejects_bad_scans_and_leaves_target_alone() {
        let d = dir();
        let p = d.path().join("scans.csv");
        let mut scans = sample();
        scans.swap(0, 1);
        assert!(write_scan_csv(&p, &scans).is_err());
        assert!(!p.exists());
    }

    fn err_of(content: &str) -> (usize, String) {
        let d = dir();
        let p = d.path().join("x.csv");
        std::fs::write(&p, content).unwrap();
        match read_scan_csv(&p) {
            Err(Error::Parse { line, field, .. }) => (line, field),
            other => panic!("expected a parse error, got {other:?}"),
        }
    }

    #[test]
    fn read_errors_name_line_and_field() {
        let head = format!("{CSV_MAGIC}\n{CSV_HEADER}\n");
        assert_eq!(err_of(""), (1, "version line".into()));
        assert_eq!(err_of("time,angle_min\n"), (1, "version line".into()));
        assert_eq!(
            err_of(&format!("{CSV_MAGIC}\ntime\n")),
            (2, "header".into())
        );
        assert_eq!(
            err_of(&format!("{head}0,0,0.1,0,10,,,,3,1,2\n")),
            (3, "num_ranges".into())
        );
        assert_eq!(
            err_of(&format!("{head}0,0,0.1,0,10,,,,2,1,x\n")),
            (3, "range[1]".into())
        );
        assert_eq!(
            err_of(&format!("{head}0,0,0.1,0,10,1,,,1,1\n")),
            (3, "odom_y".into())
        );
        assert_eq!(
            err_of(&format!("{head}nan,0,0.1,0,10,,,,1,1\n")),
            (3, "time".into())
        );
        assert_eq!(
            err_of(&format!("{head}0,0,0,0,10,,,,1,1\n")),
            (3, "header values".into())
        );
        assert_eq!(
            err_of(&format!(
                "{head}1,0,0.1,0,10,,,,1,1\n# c\n\n0,0,0.1,0,10,,,,1,1\n"
            )),
            (6, "time".into())
        );
        assert_eq!(err_of(&format!("{head}1,0,0.1\n")), (3, "range_min".into()));
        // A file with only the two header lines holds zero scans.
        let d = dir();
        let p = d.path().join("e.csv");
        std::fs::write(&p, &head).unwrap();
        assert!(read_scan_csv(&p).unwrap().is_empty());
        assert!(matches!(
            read_scan_csv(d.path().join("missing.csv")),
            Err(Error::Io { .. })
        ));
    }
}
