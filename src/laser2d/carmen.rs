//! Reader for CARMEN log files (`.clf`): front-laser scans (`FLASER`), combined laser and
//! robot messages (`ROBOTLASER1`) and odometry (`ODOM`), from plain, gzip (`.gz`) or bzip2
//! (`.bz2`) files, chosen by extension and streamed line by line. Not for: writing CARMEN
//! logs, or any other CARMEN message (`PARAM`, `SYNC`, `RLASER`, `TRUEPOS`, `NMEA-…`, …:
//! those lines, blank lines and `#` comments are counted and ignored).
//!
//! # Line formats (fields separated by white space)
//!
//! * `FLASER n r_1 … r_n x y theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname
//!   logger_timestamp`
//! * `ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range
//!   accuracy remission_mode n r_1 … r_n m e_1 … e_m laser_pose_x laser_pose_y
//!   laser_pose_theta robot_pose_x robot_pose_y robot_pose_theta tv rv forward_safety
//!   side_safety turn_axis ipc_timestamp ipc_hostname logger_timestamp`
//! * `ODOM x y theta tv rv accel ipc_timestamp ipc_hostname logger_timestamp`
//!
//! Ranges are metres, angles radians. A record's time is its `ipc_timestamp`.
//!
//! # FLASER geometry
//!
//! A `FLASER` line does not state its angles; it covers the half plane in front of the
//! sensor. This reader puts beam 0 at `−π/2` (right) and steps by `π/n` counter-clockwise,
//! so 180 beams are 1° apart and 360 beams 0.5° apart, as the public CARMEN data sets
//! describe their scanners (the last beam then sits one step short of `+π/2`). `range_min`
//! is 0 (a zero range is "no return"), `range_max` is [`CarmenOptions::flaser_range_max`]
//! (default 80 m: SICK scanners write 81.83 m or 81.91 m when nothing reflected). The
//! pose `x y theta` becomes [`Scan::laser_pose`], `odom_x odom_y odom_theta` becomes
//! [`Scan::odometry`].
//!
//! `ROBOTLASER1` carries its own geometry: `angle_min = start_angle`, `angle_increment =
//! angular_resolution`, `range_max = maximum_range`; `laser_pose_*` becomes
//! [`Scan::laser_pose`] and `robot_pose_*` [`Scan::odometry`]. Its remissions are checked
//! to be numbers and then dropped.
//!
//! # Errors, lenient mode, time order
//!
//! A malformed line of a recognised type (wrong field count for the declared number of
//! beams, a field that is not a number, a non-finite pose or time) is an
//! [`Error::Parse`] naming file, line and field — or, with [`OnMalformed::Skip`], skipped
//! and counted in [`CarmenStats`]. A record whose time is earlier than the last kept
//! record *of the same type* is handled by [`TimeOrder`]: an error (default), skipped, or
//! kept in file order; or, reading a whole log with [`read_carmen`], the fewest records are
//! dropped that leave each type's stamps in order ([`TimeOrder::DropFewest`]). Real logs need
//! this: the Intel Research Lab log has hundreds of `FLASER` and `ODOM` stamps that jump
//! forward or back by up to 0.9 s while the poses in file order move on smoothly — the file
//! order is right and single stamps are off. Skipping against the last kept record then drops
//! every record after a stamp that jumped forward until the clock catches up (1,612 of 13,631
//! `FLASER` scans); dropping the fewest drops 787 for its 631 steps back. Different types are
//! not compared with one another.

use super::scan::{OdometryRecord, Scan};
use crate::error::{Error, Result};
use crate::geometry::Pose2;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

/// What to do with a malformed line of a recognised type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum OnMalformed {
    /// Stop with an error naming file, line and field.
    #[default]
    Error,
    /// Skip the line and count it in [`CarmenStats::malformed_skipped`].
    Skip,
}

/// What to do with a record whose time is earlier than the last kept record of its type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TimeOrder {
    /// Stop with an error naming the line.
    #[default]
    Error,
    /// Skip the record (counted in [`CarmenStats::backwards_skipped`]).
    Skip,
    /// Keep the record in file order (still counted in [`CarmenStats::time_backwards`]).
    Keep,
    /// Keep file order and drop, per record type, the fewest records that leave the time
    /// stamps non-decreasing (a longest non-decreasing subsequence; counted in
    /// [`CarmenStats::backwards_skipped`]). A single stamp that jumped forward costs that one
    /// record, not every record until the clock catches up. Needs the whole log: only
    /// [`read_carmen`] takes it ([`CarmenReader`] refuses it).
    DropFewest,
}

/// Options of the CARMEN reader. The default is strict: every malformed line and every
/// backwards time stamp is an error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CarmenOptions {
    /// Malformed lines: error or skip.
    pub on_malformed: OnMalformed,
    /// Time stamps that go backwards within one record type.
    pub time_order: TimeOrder,
    /// `range_max` given to `FLASER` scans (m); ranges at or above it are "no return".
    pub flaser_range_max: f64,
    /// Read the scans as if the robot had no odometry: scans carry no odometry or laser
    /// pose, and `ODOM` lines are passed over (counted as ignored). For recordings whose
    /// odometry is missing or not to be trusted, and to test what the scans alone give.
    pub ignore_odometry: bool,
}

impl Default for CarmenOptions {
    fn default() -> Self {
        CarmenOptions {
            on_malformed: OnMalformed::Error,
            time_order: TimeOrder::Error,
            flaser_range_max: 80.0,
            ignore_odometry: false,
        }
    }
}

impl CarmenOptions {
    /// The default: errors on malformed lines and on backwards time stamps.
    pub fn strict() -> Self {
        Self::default()
    }

    /// Skips (and counts) malformed lines and records whose time goes backwards (streaming;
    /// a whole log keeps more records with [`TimeOrder::DropFewest`]).
    pub fn lenient() -> Self {
        CarmenOptions {
            on_malformed: OnMalformed::Skip,
            time_order: TimeOrder::Skip,
            ..Self::default()
        }
    }

    fn validate(&self) -> Result<()> {
        if !(self.flaser_range_max.is_finite() && self.flaser_range_max > 0.0) {
            return Err(Error::invalid(
                "CarmenOptions::flaser_range_max",
                format!("{} (must be positive and finite)", self.flaser_range_max),
            ));
        }
        Ok(())
    }
}

/// Counts gathered while reading a log.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CarmenStats {
    /// Lines read.
    pub lines: usize,
    /// `FLASER` records returned.
    pub flaser: usize,
    /// `ROBOTLASER1` records returned.
    pub robot_laser: usize,
    /// `ODOM` records returned.
    pub odometry: usize,
    /// Blank lines, comments and lines of other message types.
    pub ignored: usize,
    /// Malformed lines skipped ([`OnMalformed::Skip`]).
    pub malformed_skipped: usize,
    /// The message of the first skipped malformed line.
    pub first_malformed: Option<String>,
    /// Records whose time was earlier than the last kept record of their type (in every
    /// mode that did not stop at the first one).
    pub time_backwards: usize,
    /// Records dropped to keep time in order ([`TimeOrder::Skip`], [`TimeOrder::DropFewest`]).
    pub backwards_skipped: usize,
}

/// One record of a CARMEN log.
#[derive(Clone, Debug, PartialEq)]
pub enum CarmenRecord {
    /// A `FLASER` line.
    Flaser(Scan),
    /// A `ROBOTLASER1` line.
    RobotLaser(Scan),
    /// An `ODOM` line.
    Odometry(OdometryRecord),
}

impl CarmenRecord {
    /// The record's time stamp (s).
    pub fn time(&self) -> f64 {
        match self {
            CarmenRecord::Flaser(s) | CarmenRecord::RobotLaser(s) => s.time,
            CarmenRecord::Odometry(o) => o.time,
        }
    }

    fn kind(&self) -> usize {
        match self {
            CarmenRecord::Flaser(_) => 0,
            CarmenRecord::RobotLaser(_) => 1,
            CarmenRecord::Odometry(_) => 2,
        }
    }
}

const KIND_NAMES: [&str; 3] = ["FLASER", "ROBOTLASER1", "ODOM"];

/// A whole CARMEN log, collected by [`read_carmen`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CarmenLog {
    /// `FLASER` scans in file order.
    pub flaser: Vec<Scan>,
    /// `ROBOTLASER1` scans in file order.
    pub robot_laser: Vec<Scan>,
    /// `ODOM` records in file order.
    pub odometry: Vec<OdometryRecord>,
    /// What was read, ignored and skipped.
    pub stats: CarmenStats,
}

/// Reads a whole CARMEN log (plain, `.gz` or `.bz2`).
pub fn read_carmen(path: impl AsRef<Path>, options: CarmenOptions) -> Result<CarmenLog> {
    let drop_fewest = options.time_order == TimeOrder::DropFewest;
    let streamed = CarmenOptions {
        time_order: if drop_fewest {
            TimeOrder::Keep
        } else {
            options.time_order
        },
        ..options
    };
    let mut reader = CarmenReader::open(path, streamed)?;
    let mut log = CarmenLog::default();
    for record in reader.by_ref() {
        match record? {
            CarmenRecord::Flaser(s) => log.flaser.push(s),
            CarmenRecord::RobotLaser(s) => log.robot_laser.push(s),
            CarmenRecord::Odometry(o) => log.odometry.push(o),
        }
    }
    log.stats = reader.stats().clone();
    if drop_fewest {
        let mut dropped = 0;
        dropped += keep_in_time_order(&mut log.flaser, |s| s.time);
        dropped += keep_in_time_order(&mut log.robot_laser, |s| s.time);
        dropped += keep_in_time_order(&mut log.odometry, |o| o.time);
        log.stats.backwards_skipped = dropped;
        log.stats.flaser = log.flaser.len();
        log.stats.robot_laser = log.robot_laser.len();
        log.stats.odometry = log.odometry.len();
    }
    Ok(log)
}

/// Keeps the records of a longest subsequence whose times never decrease (file order kept)
/// and returns how many were dropped.
fn keep_in_time_order<T>(records: &mut Vec<T>, time: impl Fn(&T) -> f64) -> usize {
    let times: Vec<f64> = records.iter().map(&time).collect();
    let keep = longest_non_decreasing(&times);
    let before = records.len();
    let mut k = keep.iter();
    records.retain(|_| *k.next().expect("one flag per record"));
    before - records.len()
}

/// Flags of a longest non-decreasing subsequence of `t` (patience sorting, O(n log n)); among
/// the longest, the one ending in the smallest values is chosen at every length.
pub(crate) fn longest_non_decreasing(t: &[f64]) -> Vec<bool> {
    // tails[l]: index of the smallest last value of a run of length l + 1 found so far.
    let mut tails: Vec<usize> = Vec::new();
    let mut previous = vec![usize::MAX; t.len()];
    for (i, &v) in t.iter().enumerate() {
        let l = tails.partition_point(|&j| t[j] <= v);
        if l > 0 {
            previous[i] = tails[l - 1];
        }
        if l == tails.len() {
            tails.push(i);
        } else {
            tails[l] = i;
        }
    }
    let mut keep = vec![false; t.len()];
    let mut at = tails.last().copied().unwrap_or(usize::MAX);
    while at != usize::MAX {
        keep[at] = true;
        at = previous[at];
    }
    keep
}

/// A streaming reader: an iterator over the records of a CARMEN log, one line at a time.
/// After the first error it yields nothing more.
pub struct CarmenReader<R> {
    input: R,
    path: PathBuf,
    options: CarmenOptions,
    line: usize,
    buf: Vec<u8>,
    /// Last kept time and its line, per record kind.
    last: [Option<(f64, usize)>; 3],
    stats: CarmenStats,
    done: bool,
}

impl CarmenReader<Box<dyn BufRead + Send>> {
    /// Opens `path`; a name ending in `.gz` is read through gzip, `.bz2` through bzip2
    /// (both allowing concatenated streams), anything else as plain text.
    pub fn open(path: impl AsRef<Path>, options: CarmenOptions) -> Result<Self> {
        let path = path.as_ref();
        let file = File::open(path).map_err(|e| Error::io(path, e))?;
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        const CAP: usize = 1 << 16;
        let input: Box<dyn BufRead + Send> = match ext.as_str() {
            "gz" => Box::new(BufReader::with_capacity(
                CAP,
                flate2::read::MultiGzDecoder::new(file),
            )),
            "bz2" => Box::new(BufReader::with_capacity(
                CAP,
                bzip2::read::MultiBzDecoder::new(file),
            )),
            _ => Box::new(BufReader::with_capacity(CAP, file)),
        };
        CarmenReader::new(input, path, options)
    }
}

impl<R: BufRead> CarmenReader<R> {
    /// Reads CARMEN text from `input`; `path` is only used to name the source in errors.
    pub fn new(input: R, path: impl Into<PathBuf>, options: CarmenOptions) -> Result<Self> {
        options.validate()?;
        if options.time_order == TimeOrder::DropFewest {
            return Err(Error::invalid(
                "CarmenOptions::time_order",
                "DropFewest needs the whole log: read it with read_carmen",
            ));
        }
        Ok(CarmenReader {
            input,
            path: path.into(),
            options,
            line: 0,
            buf: Vec::new(),
            last: [None; 3],
            stats: CarmenStats::default(),
            done: false,
        })
    }

    /// What has been read so far.
    pub fn stats(&self) -> &CarmenStats {
        &self.stats
    }

    /// Reads lines until the next record, the end of input, or an error.
    fn next_record(&mut self) -> Result<Option<CarmenRecord>> {
        loop {
            self.buf.clear();
            let n = self.input.read_until(b'\n', &mut self.buf).map_err(|e| {
                Error::io(
                    &self.path,
                    std::io::Error::new(e.kind(), format!("after line {}: {e}", self.line)),
                )
            })?;
            if n == 0 {
                return Ok(None);
            }
            self.line += 1;
            self.stats.lines += 1;
            let parsed = parse_line(&self.buf, &self.path, self.line, &self.options);
            let record = match parsed {
                Ok(Some(r)) => r,
                Ok(None) => {
                    self.stats.ignored += 1;
                    continue;
                }
                Err(e) => match self.options.on_malformed {
                    OnMalformed::Error => return Err(e),
                    OnMalformed::Skip => {
                        self.stats.malformed_skipped += 1;
                        if self.stats.first_malformed.is_none() {
                            self.stats.first_malformed = Some(e.to_string());
                        }
                        continue;
                    }
                },
            };
            let kind = record.kind();
            let t = record.time();
            if let Some((prev, prev_line)) = self.last[kind] {
                if t < prev {
                    self.stats.time_backwards += 1;
                    match self.options.time_order {
                        TimeOrder::Error => {
                            return Err(Error::parse(
                                &self.path,
                                self.line,
                                "ipc_timestamp",
                                format!(
                                    "{t} is earlier than {prev} of the {} record at line \
                                     {prev_line} (time goes backwards; \
                                     CarmenOptions::time_order can skip or keep such records)",
                                    KIND_NAMES[kind]
                                ),
                            ))
                        }
                        TimeOrder::Skip => {
                            self.stats.backwards_skipped += 1;
                            continue;
                        }
                        TimeOrder::Keep | TimeOrder::DropFewest => {}
                    }
                }
            }
            self.last[kind] = Some((t, self.line));
            let record = match record {
                CarmenRecord::Odometry(_) if self.options.ignore_odometry => {
                    self.stats.ignored += 1;
                    continue;
                }
                CarmenRecord::Flaser(s) if self.options.ignore_odometry => {
                    CarmenRecord::Flaser(without_odometry(s))
                }
                CarmenRecord::RobotLaser(s) if self.options.ignore_odometry => {
                    CarmenRecord::RobotLaser(without_odometry(s))
                }
                r => r,
            };
            match &record {
                CarmenRecord::Flaser(_) => self.stats.flaser += 1,
                CarmenRecord::RobotLaser(_) => self.stats.robot_laser += 1,
                CarmenRecord::Odometry(_) => self.stats.odometry += 1,
            }
            return Ok(Some(record));
        }
    }
}

fn without_odometry(scan: Scan) -> Scan {
    Scan {
        odometry: None,
        laser_pose: None,
        ..scan
    }
}

impl<R: BufRead> Iterator for CarmenReader<R> {
    type Item = Result<CarmenRecord>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        match self.next_record() {
            Ok(Some(r)) => Some(Ok(r)),
            Ok(None) => {
                self.done = true;
                None
            }
            Err(e) => {
                self.done = true;
                Some(Err(e))
            }
        }
    }
}

/// The fields of one line with what is needed to name a bad one.
struct Fields<'a> {
    tokens: Vec<&'a str>,
    path: &'a Path,
    line: usize,
}

impl Fields<'_> {
    fn err(&self, field: impl Into<String>, reason: impl Into<String>) -> Error {
        Error::parse(self.path, self.line, field, reason)
    }

    fn token(&self, i: usize, name: &str) -> Result<&str> {
        self.tokens.get(i).copied().ok_or_else(|| {
            self.err(
                name,
                format!("missing (the line has {} fields)", self.tokens.len()),
            )
        })
    }

    /// A finite number.
    fn number(&self, i: usize, name: &str) -> Result<f64> {
        let t = self.token(i, name)?;
        let v: f64 = t
            .parse()
            .map_err(|_| self.err(name, format!("`{t}` is not a number")))?;
        if !v.is_finite() {
            return Err(self.err(name, format!("`{t}` is not finite")));
        }
        Ok(v)
    }

    /// A number that may be NaN or infinite (a range or remission).
    fn reading(&self, i: usize, name: impl Fn() -> String) -> Result<f32> {
        let t = self.token(i, &name())?;
        t.parse()
            .map_err(|_| self.err(name(), format!("`{t}` is not a number")))
    }

    fn count(&self, i: usize, name: &str) -> Result<usize> {
        let t = self.token(i, name)?;
        t.parse()
            .map_err(|_| self.err(name, format!("`{t}` is not a non-negative integer")))
    }

    fn pose(&self, i: usize, names: [&str; 3]) -> Result<Pose2> {
        Ok(Pose2::new(
            self.number(i, names[0])?,
            self.number(i + 1, names[1])?,
            self.number(i + 2, names[2])?,
        ))
    }

    fn ranges(&self, start: usize, n: usize, what: &str) -> Result<Vec<f32>> {
        (0..n)
            .map(|k| self.reading(start + k, || format!("{what}[{k}]")))
            .collect()
    }

    /// Checks that the line ends with the three IPC fields at `i` and returns the time.
    fn trailer(&self, i: usize) -> Result<f64> {
        let t = self.number(i, "ipc_timestamp")?;
        self.token(i + 1, "ipc_hostname")?;
        self.number(i + 2, "logger_timestamp")?;
        if self.tokens.len() > i + 3 {
            return Err(self.err(
                "logger_timestamp",
                format!(
                    "{} unexpected field(s) after it",
                    self.tokens.len() - (i + 3)
                ),
            ));
        }
        Ok(t)
    }

    fn expect_len(&self, expected: usize, field: &str, declared: String) -> Result<()> {
        if self.tokens.len() != expected {
            return Err(self.err(
                field,
                format!(
                    "{declared}, so the line needs {expected} fields, but it has {}",
                    self.tokens.len()
                ),
            ));
        }
        Ok(())
    }
}

/// Parses one line; `Ok(None)` for lines this reader ignores.
fn parse_line(
    bytes: &[u8],
    path: &Path,
    line: usize,
    options: &CarmenOptions,
) -> Result<Option<CarmenRecord>> {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace());
    let Some(start) = start else { return Ok(None) };
    let rest = &bytes[start..];
    let end = rest
        .iter()
        .position(|b| b.is_ascii_whitespace())
        .unwrap_or(rest.len());
    let kind = &rest[..end];
    if !matches!(kind, b"FLASER" | b"ROBOTLASER1" | b"ODOM") {
        return Ok(None);
    }
    let text = std::str::from_utf8(bytes)
        .map_err(|e| Error::parse(path, line, "line", format!("not UTF-8 text ({e})")))?;
    let f = Fields {
        tokens: text.split_ascii_whitespace().collect(),
        path,
        line,
    };
    let record = match kind {
        b"FLASER" => CarmenRecord::Flaser(parse_flaser(&f, options)?),
        b"ROBOTLASER1" => CarmenRecord::RobotLaser(parse_robot_laser(&f)?),
        _ => CarmenRecord::Odometry(parse_odom(&f)?),
    };
    Ok(Some(record))
}

fn parse_flaser(f: &Fields<'_>, options: &CarmenOptions) -> Result<Scan> {
    let n = f.count(1, "num_readings")?;
    if n == 0 {
        return Err(f.err("num_readings", "a scan needs at least one beam"));
    }
    let expected = n
        .checked_add(11)
        .ok_or_else(|| f.err("num_readings", "too large"))?;
    f.expect_len(expected, "num_readings", format!("it declares {n} ranges"))?;
    let ranges = f.ranges(2, n, "range")?;
    let laser_pose = f.pose(2 + n, ["x", "y", "theta"])?;
    let odometry = f.pose(5 + n, ["odom_x", "odom_y", "odom_theta"])?;
    let time = f.trailer(8 + n)?;
    Ok(Scan {
        time,
        angle_min: -std::f64::consts::FRAC_PI_2,
        angle_increment: std::f64::consts::PI / n as f64,
        ranges,
        range_min: 0.0,
        range_max: options.flaser_range_max,
        odometry: Some(odometry),
        laser_pose: Some(laser_pose),
    })
}

fn parse_robot_laser(f: &Fields<'_>) -> Result<Scan> {
    f.number(1, "laser_type")?;
    let start_angle = f.number(2, "start_angle")?;
    f.number(3, "field_of_view")?;
    let resolution = f.number(4, "angular_resolution")?;
    if resolution == 0.0 {
        return Err(f.err("angular_resolution", "must not be zero"));
    }
    let maximum_range = f.number(5, "maximum_range")?;
    if maximum_range <= 0.0 {
        return Err(f.err(
            "maximum_range",
            format!("{maximum_range} (must be positive)"),
        ));
    }
    f.number(6, "accuracy")?;
    f.number(7, "remission_mode")?;
    let n = f.count(8, "num_readings")?;
    if n == 0 {
        return Err(f.err("num_readings", "a scan needs at least one beam"));
    }
    // The remission count follows the ranges; it must exist before it can be read.
    let at_remissions = n
        .checked_add(9)
        .ok_or_else(|| f.err("num_readings", "too large"))?;
    if f.tokens.len() <= at_remissions {
        return Err(f.err(
            "num_readings",
            format!(
                "it declares {n} ranges, but the line has only {} fields",
                f.tokens.len()
            ),
        ));
    }
    let m = f.count(at_remissions, "num_remissions")?;
    let expected = at_remissions
        .checked_add(m)
        .and_then(|v| v.checked_add(15))
        .ok_or_else(|| f.err("num_remissions", "too large"))?;
    f.expect_len(
        expected,
        "num_remissions",
        format!("it declares {n} ranges and {m} remissions"),
    )?;
    let ranges = f.ranges(9, n, "range")?;
    f.ranges(at_remissions + 1, m, "remission")?;
    let mut i = at_remissions + 1 + m;
    let laser_pose = f.pose(i, ["laser_pose_x", "laser_pose_y", "laser_pose_theta"])?;
    i += 3;
    let robot_pose = f.pose(i, ["robot_pose_x", "robot_pose_y", "robot_pose_theta"])?;
    i += 3;
    for name in ["tv", "rv", "forward_safety", "side_safety", "turn_axis"] {
        f.number(i, name)?;
        i += 1;
    }
    let time = f.trailer(i)?;
    Ok(Scan {
        time,
        angle_min: start_angle,
        angle_increment: resolution,
        ranges,
        range_min: 0.0,
        range_max: maximum_range,
        odometry: Some(robot_pose),
        laser_pose: Some(laser_pose),
    })
}

fn parse_odom(f: &Fields<'_>) -> Result<OdometryRecord> {
    let pose = f.pose(1, ["x", "y", "theta"])?;
    let linear_velocity = f.number(4, "tv")?;
    let angular_velocity = f.number(5, "rv")?;
    f.number(6, "accel")?;
    let time = f.trailer(7)?;
    Ok(OdometryRecord {
        time,
        pose,
        linear_velocity,
        angular_velocity,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str, options: CarmenOptions) -> Result<(Vec<CarmenRecord>, CarmenStats)> {
        let mut r = CarmenReader::new(text.as_bytes(), "mem.clf", options)?;
        let records = r.by_ref().collect::<Result<Vec<_>>>()?;
        Ok((records, r.stats().clone()))
    }

    fn parse_error(text: &str) -> (usize, String, String) {
        match read(text, CarmenOptions::default()) {
            Err(Error::Parse {
                line,
                field,
                reason,
                ..
            }) => (line, field, reason),
            other => panic!("expected a parse error, got {other:?}"),
        }
    }

    const FLASER4: &str = "FLASER 4 1.0 2.0 0.0 81.83 0.5 0.25 0.1 0.4 0.2 0.05 100.5 host 0.01\n";

    #[test]
    fn flaser_fields() {
        let (recs, stats) = read(FLASER4, CarmenOptions::default()).unwrap();
        assert_eq!(stats.flaser, 1);
        let CarmenRecord::Flaser(s) = &recs[0] else {
            panic!()
        };
        assert_eq!(s.ranges, vec![1.0, 2.0, 0.0, 81.83]);
        assert_eq!(s.time, 100.5);
        assert!((s.angle_min + std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert!((s.angle_increment - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
        assert_eq!(s.laser_pose, Some(Pose2::new(0.5, 0.25, 0.1)));
        assert_eq!(s.odometry, Some(Pose2::new(0.4, 0.2, 0.05)));
        // Zero and the scanner's maximum are "no return".
        assert_eq!(s.valid_count(), 2);
    }

    #[test]
    fn robot_laser_fields() {
        let line = "ROBOTLASER1 0 -1.5 3.0 0.75 30.0 0.01 0 5 1 2 3 30 nan 2 10 20 \
                    1 2 0.5 3 4 0.6 0.1 0.2 0.3 0.4 0.5 7.25 host 0.1\n";
        let (recs, _) = read(line, CarmenOptions::default()).unwrap();
        let CarmenRecord::RobotLaser(s) = &recs[0] else {
            panic!()
        };
        assert_eq!(s.len(), 5);
        assert_eq!(
            (s.angle_min, s.angle_increment, s.range_max),
            (-1.5, 0.75, 30.0)
        );
        assert_eq!(s.laser_pose, Some(Pose2::new(1.0, 2.0, 0.5)));
        assert_eq!(s.odometry, Some(Pose2::new(3.0, 4.0, 0.6)));
        assert_eq!(s.time, 7.25);
        assert_eq!(s.valid_count(), 3);
        // One remission missing.
        let short = line.replace(" 2 10 20 ", " 2 10 ");
        let (l, field, _) = parse_error(&short);
        assert_eq!((l, field.as_str()), (1, "num_remissions"));
    }

    #[test]
    fn odom_and_ignored_lines() {
        let text = "# comment\n\nPARAM a b\nODOM 1 2 0.5 0.3 0.1 0 5.0 host 0.2\nSYNC x\n";
        let (recs, stats) = read(text, CarmenOptions::default()).unwrap();
        assert_eq!(recs.len(), 1);
        assert_eq!(stats.ignored, 4);
        assert_eq!(stats.lines, 5);
        let CarmenRecord::Odometry(o) = recs[0] else {
            panic!()
        };
        assert_eq!(o.pose, Pose2::new(1.0, 2.0, 0.5));
        assert_eq!(
            (o.linear_velocity, o.angular_velocity, o.time),
            (0.3, 0.1, 5.0)
        );
    }

    #[test]
    fn malformed_lines_name_line_and_field() {
        let (l, f, r) = parse_error(&format!("# c\n{}", FLASER4.replace(" 81.83", "")));
        assert_eq!((l, f.as_str()), (2, "num_readings"));
        assert!(r.contains("declares 4 ranges"), "{r}");
        let (l, f, _) = parse_error(&FLASER4.replace("2.0", "2.x"));
        assert_eq!((l, f.as_str()), (1, "range[1]"));
        let (_, f, _) = parse_error(&FLASER4.replace("0.25", "inf"));
        assert_eq!(f, "y");
        let (_, f, _) = parse_error("FLASER x 1\n");
        assert_eq!(f, "num_readings");
        let (_, f, _) = parse_error("ODOM 1 2 0.5 0.3 0.1 0 5.0 host\n");
        assert_eq!(f, "logger_timestamp");
        let (_, f, _) = parse_error("ODOM 1 2 0.5 0.3 0.1 0 5.0 host 0.2 9\n");
        assert_eq!(f, "logger_timestamp");
        let (_, f, _) = parse_error("ODOM 1 2 0.5 0.3 0.1 0 t host 0.2\n");
        assert_eq!(f, "ipc_timestamp");
        let (_, f, _) = parse_error("FLASER 0 0 0 0 0 0 0 1 h 1\n");
        assert_eq!(f, "num_readings");
        let (_, f, _) = parse_error("FLASER 99999999999999999999999 1\n");
        assert_eq!(f, "num_readings");
        let (_, f, _) = parse_error("FLASER 18446744073709551615 1\n");
        assert_eq!(f, "num_readings");
    }

    #[test]
    fn time_order_policies() {
        let text = "ODOM 0 0 0 0 0 0 2.0 h 0\n\
                    FLASER 1 1.0 0 0 0 0 0 0 1.0 h 0\n\
                    ODOM 0 0 0 0 0 0 1.5 h 0\n\
                    ODOM 0 0 0 0 0 0 3.0 h 0\n";
        let (l, f, r) = parse_error(text);
        assert_eq!((l, f.as_str()), (3, "ipc_timestamp"));
        assert!(r.contains("line 1"), "{r}");
        let (recs, stats) = read(text, CarmenOptions::lenient()).unwrap();
        assert_eq!(recs.len(), 3);
        assert_eq!((stats.time_backwards, stats.backwards_skipped), (1, 1));
        let keep = CarmenOptions {
            time_order: TimeOrder::Keep,
            ..CarmenOptions::default()
        };
        let (recs, stats) = read(text, keep).unwrap();
        assert_eq!(recs.len(), 4);
        assert_eq!((stats.time_backwards, stats.backwards_skipped), (1, 0));
    }

    #[test]
    fn drop_fewest_drops_only_the_stamp_that_jumped() {
        // The third scan's stamp jumped 0.8 s ahead; skipping against the last kept stamp
        // loses the three scans after it, dropping the fewest loses only that one.
        let times = [1.0, 1.2, 2.2, 1.6, 1.8, 2.0, 2.4, 2.6];
        let text: String = times
            .iter()
            .enumerate()
            .map(|(i, t)| format!("FLASER 1 1.0 0 0 0 {i} 0 0 {t} h 0\n"))
            .collect();
        let (skipped, stats) = read(&text, CarmenOptions::lenient()).unwrap();
        assert_eq!((skipped.len(), stats.backwards_skipped), (5, 3));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("jump.clf");
        std::fs::write(&path, &text).unwrap();
        let fewest = CarmenOptions {
            time_order: TimeOrder::DropFewest,
            ..CarmenOptions::default()
        };
        let log = read_carmen(&path, fewest).unwrap();
        let xs: Vec<f64> = log.flaser.iter().map(|s| s.odometry.unwrap().x).collect();
        assert_eq!(xs, [0.0, 1.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
        assert_eq!(
            (
                log.stats.flaser,
                log.stats.backwards_skipped,
                log.stats.time_backwards
            ),
            (7, 1, 1)
        );
        // The streaming reader cannot look ahead: it refuses the option.
        assert!(CarmenReader::new(text.as_bytes(), "jump.clf", fewest).is_err());
    }

    /// The length of a longest non-decreasing subsequence by trying every subset.
    fn brute_longest(t: &[f64]) -> usize {
        (0u32..1 << t.len())
            .filter(|mask| {
                let picked: Vec<f64> = (0..t.len())
                    .filter(|i| mask & (1 << i) != 0)
                    .map(|i| t[i])
                    .collect();
                picked.windows(2).all(|w| w[0] <= w[1])
            })
            .map(|mask| mask.count_ones() as usize)
            .max()
            .unwrap_or(0)
    }

    proptest::proptest! {
        /// The kept stamps never decrease and are as many as any ordered choice can keep.
        #[test]
        fn longest_non_decreasing_is_ordered_and_longest(
            t in proptest::collection::vec(0u8..6, 0..12)
        ) {
            let t: Vec<f64> = t.into_iter().map(f64::from).collect();
            let keep = longest_non_decreasing(&t);
            let kept: Vec<f64> = t.iter().zip(&keep).filter(|(_, k)| **k).map(|(v, _)| *v).collect();
            proptest::prop_assert!(kept.windows(2).all(|w| w[0] <= w[1]));
            proptest::prop_assert_eq!(kept.len(), brute_longest(&t));
        }
    }

    #[test]
    fn ignoring_odometry_strips_poses_and_passes_over_odom_lines() {
        let text = "ODOM 1.0 2.0 0.5 0 0 0 10.0 h 10.0\n\
                    FLASER 3 1.0 2.0 3.0 1.0 2.0 0.5 1.0 2.0 0.5 10.1 h 10.1\n";
        let options = CarmenOptions {
            ignore_odometry: true,
            ..CarmenOptions::default()
        };
        let (recs, stats) = read(text, options).unwrap();
        assert_eq!(recs.len(), 1);
        let CarmenRecord::Flaser(s) = &recs[0] else {
            panic!("{recs:?}")
        };
        assert!(s.odometry.is_none() && s.laser_pose.is_none());
        assert_eq!(s.ranges, vec![1.0, 2.0, 3.0]);
        assert_eq!((stats.odometry, stats.ignored), (0, 1));
        let (recs, _) = read(text, CarmenOptions::default()).unwrap();
        assert_eq!(recs.len(), 2);
    }

    #[test]
    fn invalid_options_rejected() {
        let bad = CarmenOptions {
            flaser_range_max: f64::NAN,
            ..CarmenOptions::default()
        };
        assert!(CarmenReader::new(&b""[..], "x", bad).is_err());
    }

    #[test]
    fn not_utf8_is_malformed() {
        let mut bytes = b"ODOM 1 2 0.5 0.3 0.1 0 5.0 h\xff 0.2\n".to_vec();
        bytes.extend_from_slice(b"PARAM \xff\n");
        let r = CarmenReader::new(&bytes[..], "x", CarmenOptions::default())
            .unwrap()
            .collect::<Result<Vec<_>>>();
        assert!(matches!(r, Err(Error::Parse { line: 1, .. })));
        let mut r = CarmenReader::new(&bytes[..], "x", CarmenOptions::lenient()).unwrap();
        assert_eq!(r.by_ref().count(), 0);
        assert_eq!(r.stats().malformed_skipped, 1);
        assert_eq!(r.stats().ignored, 1);
    }
}
