//! KITTI timestamp files: one `YYYY-MM-DD hh:mm:ss.fffffffff` a line (e.g.
//! `2011-09-26 13:02:25.964389445`), one line per frame. Parsed into exact calendar values
//! ([`Timestamp`]) and into seconds since the first line ([`Timestamps::seconds`]), computed
//! from integer nanoseconds so that no precision is lost to the large absolute epoch.
//!
//! The clock is taken as UTC without leap seconds (as the KITTI files are plain wall-clock
//! stamps). Not for: time zones or time-of-week GPS time.

use super::text::read_text;
use crate::atomic::write_atomically;
use crate::error::{Error, Result};
use std::fmt;
use std::io::Write;
use std::path::Path;

const NANOS_PER_SECOND: i128 = 1_000_000_000;
const SECONDS_PER_DAY: i128 = 86_400;

/// One calendar timestamp with nanosecond resolution.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Timestamp {
    /// Year, e.g. 2011.
    pub year: i32,
    /// Month, 1–12.
    pub month: u8,
    /// Day of month, 1–31.
    pub day: u8,
    /// Hour, 0–23.
    pub hour: u8,
    /// Minute, 0–59.
    pub minute: u8,
    /// Second, 0–60.
    pub second: u8,
    /// Nanoseconds, 0–999 999 999.
    pub nanosecond: u32,
}

fn is_leap(year: i32) -> bool {
    (year % 4 == 0 && year % 100 != 0) || year % 400 == 0
}

fn days_in_month(year: i32, month: u8) -> u8 {
    match month {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if is_leap(year) => 29,
        2 => 28,
        _ => 0,
    }
}

/// Days from 1970-01-01 to the given civil date (proleptic Gregorian calendar).
///
/// Counts in 400-year eras that start on 1 March, so that the leap day is the last day of a
/// shifted year and every month before it has a fixed length.
fn days_from_civil(year: i32, month: u8, day: u8) -> i64 {
    let y = year as i64 - if month <= 2 { 1 } else { 0 };
    let era = y.div_euclid(400);
    let year_of_era = y - era * 400; // 0..=399
    let m = month as i64;
    let shifted_month = if m > 2 { m - 3 } else { m + 9 }; // March = 0
    let day_of_year = (153 * shifted_month + 2) / 5 + day as i64 - 1;
    let day_of_era = year_of_era * 365 + year_of_era / 4 - year_of_era / 100 + day_of_year;
    era * 146_097 + day_of_era - 719_468
}

/// The civil date of a day count from 1970-01-01 (inverse of [`days_from_civil`]).
fn civil_from_days(days: i64) -> (i32, u8, u8) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let day_of_era = z - era * 146_097;
    let year_of_era =
        (day_of_era - day_of_era / 1460 + day_of_era / 36_524 - day_of_era / 146_096) / 365;
    let day_of_year = day_of_era - (365 * year_of_era + year_of_era / 4 - year_of_era / 100);
    let shifted_month = (5 * day_of_year + 2) / 153;
    let day = day_of_year - (153 * shifted_month + 2) / 5 + 1;
    let month = if shifted_month < 10 {
        shifted_month + 3
    } else {
        shifted_month - 9
    };
    let year = year_of_era + era * 400 + if month <= 2 { 1 } else { 0 };
    (year as i32, month as u8, day as u8)
}

impl Timestamp {
    /// Parses `YYYY-MM-DD hh:mm:ss[.fraction]` (fraction of up to 9 digits). The error string
    /// names the part that was wrong.
    pub fn parse(text: &str) -> std::result::Result<Timestamp, String> {
        let text = text.trim();
        let (date, time) = text
            .split_once(' ')
            .ok_or_else(|| format!("`{text}` is not `YYYY-MM-DD hh:mm:ss.fffffffff`"))?;
        let time = time.trim_start();
        let num = |s: &str, what: &str| -> std::result::Result<i64, String> {
            if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) || s.len() > 9 {
                return Err(format!("{what} `{s}` is not a number in `{text}`"));
            }
            s.parse::<i64>()
                .map_err(|_| format!("{what} `{s}` is not a number in `{text}`"))
        };
        let d: Vec<&str> = date.split('-').collect();
        if d.len() != 3 {
            return Err(format!("date `{date}` is not YYYY-MM-DD"));
        }
        let (year, month, day) = (num(d[0], "year")?, num(d[1], "month")?, num(d[2], "day")?);
        let (hms, fraction) = match time.split_once('.') {
            Some((a, b)) => (a, Some(b)),
            None => (time, None),
        };
        let t: Vec<&str> = hms.split(':').collect();
        if t.len() != 3 {
            return Err(format!("time `{time}` is not hh:mm:ss"));
        }
        let (hour, minute, second) = (
            num(t[0], "hour")?,
            num(t[1], "minute")?,
            num(t[2], "second")?,
        );
        let nanosecond = match fraction {
            None => 0,
            Some(f) => {
                let digits = num(f, "fraction of a second")?;
                digits * 10i64.pow(9 - f.len() as u32)
            }
        };
        if !(1..=9999).contains(&year) {
            return Err(format!("year {year} out of range"));
        }
        let year = year as i32;
        if !(1..=12).contains(&month) {
            return Err(format!("month {month} out of range 1–12"));
        }
        let month = month as u8;
        if day < 1 || day > days_in_month(year, month) as i64 {
            return Err(format!("day {day} does not exist in {year}-{month:02}"));
        }
        if hour > 23 || minute > 59 || second > 60 {
            return Err(format!("time {hour}:{minute}:{second} out of range"));
        }
        Ok(Timestamp {
            year,
            month,
            day: day as u8,
            hour: hour as u8,
            minute: minute as u8,
            second: second as u8,
            nanosecond: nanosecond as u32,
        })
    }

    /// Nanoseconds since 1970-01-01 00:00:00 (UTC, no leap seconds).
    pub fn unix_nanos(&self) -> i128 {
        let days = days_from_civil(self.year, self.month, self.day) as i128;
        let secs = days * SECONDS_PER_DAY
            + self.hour as i128 * 3600
            + self.minute as i128 * 60
            + self.second as i128;
        secs * NANOS_PER_SECOND + self.nanosecond as i128
    }

    /// Seconds since 1970-01-01 00:00:00 as f64 (resolution about 0.2 µs in 2011; use
    /// [`seconds_since`](Self::seconds_since) for differences).
    pub fn unix_seconds(&self) -> f64 {
        self.unix_nanos() as f64 / 1e9
    }

    /// `self − earlier` in seconds, computed exactly in integer nanoseconds first.
    pub fn seconds_since(&self, earlier: &Timestamp) -> f64 {
        (self.unix_nanos() - earlier.unix_nanos()) as f64 / 1e9
    }

    /// The timestamp `nanos` nanoseconds after 1970-01-01 00:00:00 (inverse of
    /// [`unix_nanos`](Self::unix_nanos); `None` outside years 1–9999).
    pub fn from_unix_nanos(nanos: i128) -> Option<Timestamp> {
        let secs = nanos.div_euclid(NANOS_PER_SECOND);
        let nanosecond = nanos.rem_euclid(NANOS_PER_SECOND) as u32;
        let days = secs.div_euclid(SECONDS_PER_DAY);
        let in_day = secs.rem_euclid(SECONDS_PER_DAY);
        let days = i64::try_from(days).ok()?;
        if days.abs() > 4_000_000 {
            return None;
        }
        let (year, month, day) = civil_from_days(days);
        if !(1..=9999).contains(&year) {
            return None;
        }
        Some(Timestamp {
            year,
            month,
            day,
            hour: (in_day / 3600) as u8,
            minute: (in_day % 3600 / 60) as u8,
            second: (in_day % 60) as u8,
            nanosecond,
        })
    }

    /// The timestamp `seconds` later (rounded to the nanosecond); `None` if out of range or not
    /// finite.
    pub fn plus_seconds(&self, seconds: f64) -> Option<Timestamp> {
        if !seconds.is_finite() || seconds.abs() > 1e11 {
            return None;
        }
        Timestamp::from_unix_nanos(self.unix_nanos() + (seconds * 1e9).round() as i128)
    }
}

impl fmt::Display for Timestamp {
    /// KITTI's format, with all nine fraction digits.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:04}-{:02}-{:02} {:02}:{:02}:{:02}.{:09}",
            self.year, self.month, self.day, self.hour, self.minute, self.second, self.nanosecond
        )
    }
}

/// The content of one timestamp file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timestamps {
    /// The stamps, one per frame: as written, or interpolated for a blank line (see `blank`).
    pub absolute: Vec<Timestamp>,
    /// Seconds since the first stamp (so `seconds[0] == 0`), one per frame.
    pub seconds: Vec<f64>,
    /// Frames whose line is blank, ascending. KITTI leaves the line of a dropped frame empty
    /// (drive 2011_09_26_drive_0009's Velodyne scans 177–180); its stamp is interpolated
    /// between the nearest written ones before and after it.
    pub blank: Vec<usize>,
}

impl Timestamps {
    /// Builds the relative seconds from absolute stamps.
    pub fn from_absolute(absolute: Vec<Timestamp>) -> Timestamps {
        let seconds = match absolute.first() {
            None => Vec::new(),
            Some(first) => absolute.iter().map(|t| t.seconds_since(first)).collect(),
        };
        Timestamps {
            absolute,
            seconds,
            blank: Vec::new(),
        }
    }

    /// Number of stamps.
    pub fn len(&self) -> usize {
        self.absolute.len()
    }

    /// Whether there is no stamp.
    pub fn is_empty(&self) -> bool {
        self.absolute.is_empty()
    }

    /// Time differences between consecutive frames, seconds (`len() − 1` values).
    pub fn intervals(&self) -> Vec<f64> {
        self.seconds.windows(2).map(|w| w[1] - w[0]).collect()
    }

    /// Index of the first stamp that is not later than its predecessor.
    pub fn first_non_increasing(&self) -> Option<usize> {
        self.absolute
            .windows(2)
            .position(|w| w[1] <= w[0])
            .map(|i| i + 1)
    }
}

/// Fills each blank entry (`None`) by linear interpolation, in integer nanoseconds, between
/// the written stamps before and after it. `stamps` starts and ends with a written stamp.
fn interpolate_blanks(stamps: &[Option<Timestamp>]) -> Vec<Timestamp> {
    let mut out: Vec<Timestamp> = Vec::with_capacity(stamps.len());
    let mut i = 0;
    while i < stamps.len() {
        match stamps[i] {
            Some(t) => {
                out.push(t);
                i += 1;
            }
            None => {
                let before = out.last().copied().expect("the first line has a stamp");
                let after_at = i + stamps[i..]
                    .iter()
                    .position(Option::is_some)
                    .expect("so has the last");
                let after = stamps[after_at].expect("found written");
                let (a, b) = (before.unix_nanos(), after.unix_nanos());
                let span = (after_at - i + 1) as i128;
                for j in 1..=(after_at - i) as i128 {
                    // Between two valid stamps, so in range.
                    out.push(Timestamp::from_unix_nanos(a + (b - a) * j / span).unwrap_or(before));
                }
                i = after_at;
            }
        }
    }
    out
}

/// Reads a timestamp file: one stamp a line; trailing blank lines are ignored. A blank line
/// between two stamps is a dropped frame ([`Timestamps::blank`]).
///
/// Errors (naming file and line): a line that is not a stamp, or a blank line before the
/// first stamp (its frame's time could not be placed).
pub fn read_timestamps(path: impl AsRef<Path>) -> Result<Timestamps> {
    let path = path.as_ref();
    let text = read_text(path)?;
    let lines: Vec<&str> = text.lines().map(str::trim).collect();
    let end = lines
        .iter()
        .rposition(|l| !l.is_empty())
        .map_or(0, |i| i + 1);
    let mut stamps = Vec::with_capacity(end);
    let mut blank = Vec::new();
    for (i, line) in lines[..end].iter().enumerate() {
        if line.is_empty() {
            if i == 0 {
                return Err(Error::parse(
                    path,
                    1,
                    "timestamp",
                    "blank before the first stamp: the frame's time cannot be placed",
                ));
            }
            blank.push(i);
            stamps.push(None);
        } else {
            let t =
                Timestamp::parse(line).map_err(|e| Error::parse(path, i + 1, "timestamp", e))?;
            stamps.push(Some(t));
        }
    }
    let mut out = Timestamps::from_absolute(interpolate_blanks(&stamps));
    out.blank = blank;
    Ok(out)
}

/// Writes a timestamp file (one stamp a line, nine fraction digits), atomically.
pub fn write_timestamps(path: impl AsRef<Path>, stamps: &[Timestamp]) -> Result<()> {
    write_atomically(path.as_ref(), |w| {
        for t in stamps {
            writeln!(w, "{t}")?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_kitti_stamp_and_prints_it_back() {
        let t = Timestamp::parse("2011-09-26 13:02:25.964389445").unwrap();
        assert_eq!((t.year, t.month, t.day), (2011, 9, 26));
        assert_eq!(
            (t.hour, t.minute, t.second, t.nanosecond),
            (13, 2, 25, 964_389_445)
        );
        assert_eq!(t.to_string(), "2011-09-26 13:02:25.964389445");
        // 2011-09-26 00:00:00 UTC is 1317 * 10^6 + ... : check against a known value.
        let midnight = Timestamp::parse("2011-09-26 00:00:00").unwrap();
        assert_eq!(midnight.unix_nanos(), 1_316_995_200 * NANOS_PER_SECOND);
        let short = Timestamp::parse("2011-09-26 13:02:25.5").unwrap();
        assert_eq!(short.nanosecond, 500_000_000);
    }

    #[test]
    fn unix_nanos_round_trips_across_leap_days() {
        for s in [
            "1970-01-01 00:00:00.000000000",
            "2000-02-29 23:59:59.999999999",
            "2011-09-26 13:02:25.964389445",
            "1969-12-31 12:00:00.000000001",
            "2100-03-01 00:00:00.000000000",
        ] {
            let t = Timestamp::parse(s).unwrap();
            assert_eq!(
                Timestamp::from_unix_nanos(t.unix_nanos()).unwrap(),
                t,
                "{s}"
            );
        }
        let t = Timestamp::parse("2011-09-26 23:59:59.950000000").unwrap();
        assert_eq!(
            t.plus_seconds(0.1).unwrap().to_string(),
            "2011-09-27 00:00:00.050000000"
        );
    }

    #[test]
    fn differences_are_exact() {
        let a = Timestamp::parse("2011-09-26 13:02:25.964389445").unwrap();
        let b = Timestamp::parse("2011-09-26 13:02:26.074347616").unwrap();
        assert!((b.seconds_since(&a) - 0.109958171).abs() < 1e-12);
    }

    #[test]
    fn bad_stamps_are_rejected() {
        for s in [
            "2011-09-26",
            "2011-09-26 13:02",
            "2011-13-26 13:02:25.1",
            "2011-02-29 13:02:25.1",
            "2011-09-26 25:02:25.1",
            "2011-09-26 13:02:xx.1",
            "2011-09-26 13:02:25.1234567890",
        ] {
            assert!(Timestamp::parse(s).is_err(), "{s}");
        }
    }

    #[test]
    fn file_errors_name_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("timestamps.txt");
        std::fs::write(
            &p,
            "2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26.074347616\n2011-09-26 13:0x:26.1\n",
        )
        .unwrap();
        let msg = read_timestamps(&p).unwrap_err().to_string();
        assert!(msg.contains("timestamps.txt:3: timestamp"), "{msg}");
    }

    #[test]
    fn a_blank_line_between_stamps_is_a_dropped_frame() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("timestamps.txt");
        // Frames 1 and 2 dropped; 0.3 s from frame 0 to frame 3, so 0.1 s steps.
        std::fs::write(
            &p,
            "2011-09-26 13:02:25.900000000\n\n  \n2011-09-26 13:02:26.200000000\n\n\n",
        )
        .unwrap();
        let t = read_timestamps(&p).unwrap();
        assert_eq!(t.blank, vec![1, 2]);
        assert_eq!(t.len(), 4);
        assert_eq!(t.absolute[1].to_string(), "2011-09-26 13:02:26.000000000");
        assert_eq!(t.absolute[2].to_string(), "2011-09-26 13:02:26.100000000");
        assert!((t.seconds[3] - 0.3).abs() < 1e-12);
        std::fs::write(&p, "\n2011-09-26 13:02:26.200000000\n").unwrap();
        let msg = read_timestamps(&p).unwrap_err().to_string();
        assert!(msg.contains("timestamps.txt:1: timestamp: blank"), "{msg}");
    }

    #[test]
    fn write_then_read() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("timestamps.txt");
        let t0 = Timestamp::parse("2011-09-26 13:02:25.964389445").unwrap();
        let stamps: Vec<_> = (0..5)
            .map(|k| t0.plus_seconds(0.1 * k as f64).unwrap())
            .collect();
        write_timestamps(&p, &stamps).unwrap();
        let back = read_timestamps(&p).unwrap();
        assert_eq!(back.absolute, stamps);
        assert!((back.seconds[4] - 0.4).abs() < 1e-9);
        assert_eq!(back.intervals().len(), 4);
        assert_eq!(back.first_non_increasing(), None);
    }
}
