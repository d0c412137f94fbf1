//! OXTS RT3003 GPS/IMU packets of KITTI raw drives: one text file per frame
//! (`oxts/data/0000000042.txt`) holding one line of 30 space-separated values, in the order of
//! the drive's `oxts/dataformat.txt` (see [`OXTS_FIELDS`]). Reads single files and whole
//! folders, and writes packets back in the same layout.
//!
//! Not for: turning packets into poses (see [`super::poses`]).

use super::frames::{frame_file_name, list_frame_files, require_contiguous};
use super::text::{numbered_lines, parse_f64, read_text};
use crate::atomic::write_atomically;
use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Names of the 30 values of an OXTS line, in file order.
pub const OXTS_FIELDS: [&str; 30] = [
    "lat",
    "lon",
    "alt",
    "roll",
    "pitch",
    "yaw",
    "vn",
    "ve",
    "vf",
    "vl",
    "vu",
    "ax",
    "ay",
    "az",
    "af",
    "al",
    "au",
    "wx",
    "wy",
    "wz",
    "wf",
    "wl",
    "wu",
    "pos_accuracy",
    "vel_accuracy",
    "navstat",
    "numsats",
    "posmode",
    "velmode",
    "orimode",
];

/// Index in [`OXTS_FIELDS`] of the first integer-valued field (`navstat`).
const FIRST_INTEGER_FIELD: usize = 25;

/// One OXTS packet. Units as in KITTI's `dataformat.txt`: degrees for latitude and longitude,
/// metres, radians, m/s, m/s², rad/s. Body axes x/y/z are forward/left/up of the vehicle; the
/// f/l/u axes are forward/left/up parallel to the earth's surface.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct OxtsPacket {
    /// Latitude of the unit, degrees.
    pub lat: f64,
    /// Longitude of the unit, degrees.
    pub lon: f64,
    /// Altitude of the unit, metres.
    pub alt: f64,
    /// Roll, rad: 0 = level, positive = left side up.
    pub roll: f64,
    /// Pitch, rad: 0 = level, positive = front down.
    pub pitch: f64,
    /// Heading, rad: 0 = east, positive = counter-clockwise.
    pub yaw: f64,
    /// Velocity towards north, m/s.
    pub vn: f64,
    /// Velocity towards east, m/s.
    pub ve: f64,
    /// Forward velocity parallel to the earth's surface, m/s.
    pub vf: f64,
    /// Leftward velocity parallel to the earth's surface, m/s.
    pub vl: f64,
    /// Upward velocity perpendicular to the earth's surface, m/s.
    pub vu: f64,
    /// Acceleration along the body x axis (front), m/s².
    pub ax: f64,
    /// Acceleration along the body y axis (left), m/s².
    pub ay: f64,
    /// Acceleration along the body z axis (top), m/s².
    pub az: f64,
    /// Forward acceleration, m/s².
    pub af: f64,
    /// Leftward acceleration, m/s².
    pub al: f64,
    /// Upward acceleration, m/s².
    pub au: f64,
    /// Angular rate about the body x axis, rad/s.
    pub wx: f64,
    /// Angular rate about the body y axis, rad/s.
    pub wy: f64,
    /// Angular rate about the body z axis, rad/s.
    pub wz: f64,
    /// Angular rate about the forward axis, rad/s.
    pub wf: f64,
    /// Angular rate about the leftward axis, rad/s.
    pub wl: f64,
    /// Angular rate about the upward axis, rad/s.
    pub wu: f64,
    /// Position accuracy (north/east), metres.
    pub pos_accuracy: f64,
    /// Velocity accuracy (north/east), m/s.
    pub vel_accuracy: f64,
    /// Navigation status code.
    pub navstat: i32,
    /// Number of satellites tracked by the primary GPS receiver.
    pub numsats: i32,
    /// Position mode code of the primary GPS receiver.
    pub posmode: i32,
    /// Velocity mode code of the primary GPS receiver.
    pub velmode: i32,
    /// Orientation mode code of the primary GPS receiver.
    pub orimode: i32,
}

impl OxtsPacket {
    /// The 30 values in file order (integer fields converted to f64).
    pub fn to_values(&self) -> [f64; 30] {
        [
            self.lat,
            self.lon,
            self.alt,
            self.roll,
            self.pitch,
            self.yaw,
            self.vn,
            self.ve,
            self.vf,
            self.vl,
            self.vu,
            self.ax,
            self.ay,
            self.az,
            self.af,
            self.al,
            self.au,
            self.wx,
            self.wy,
            self.wz,
            self.wf,
            self.wl,
            self.wu,
            self.pos_accuracy,
            self.vel_accuracy,
            self.navstat as f64,
            self.numsats as f64,
            self.posmode as f64,
            self.velmode as f64,
            self.orimode as f64,
        ]
    }

    /// A packet from 30 values in file order. The last five (status codes) must be integers;
    /// every value must be finite. The error names the field.
    pub fn from_values(v: &[f64; 30]) -> Result<OxtsPacket> {
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(Error::invalid(
                format!("OXTS field {}", OXTS_FIELDS[i]),
                format!("{} is not finite", v[i]),
            ));
        }
        let int = |i: usize| -> Result<i32> {
            let x = v[i];
            if x.fract() != 0.0 || x.abs() > i32::MAX as f64 {
                return Err(Error::invalid(
                    format!("OXTS field {}", OXTS_FIELDS[i]),
                    format!("{x} is not an integer code"),
                ));
            }
            Ok(x as i32)
        };
        Ok(OxtsPacket {
            lat: v[0],
            lon: v[1],
            alt: v[2],
            roll: v[3],
            pitch: v[4],
            yaw: v[5],
            vn: v[6],
            ve: v[7],
            vf: v[8],
            vl: v[9],
            vu: v[10],
            ax: v[11],
            ay: v[12],
            az: v[13],
            af: v[14],
            al: v[15],
            au: v[16],
            wx: v[17],
            wy: v[18],
            wz: v[19],
            wf: v[20],
            wl: v[21],
            wu: v[22],
            pos_accuracy: v[23],
            vel_accuracy: v[24],
            navstat: int(25)?,
            numsats: int(26)?,
            posmode: int(27)?,
            velmode: int(28)?,
            orimode: int(29)?,
        })
    }

    /// Parses one OXTS line; `path` and `line` are used in error messages, which name the
    /// field (`vf (value 9 of 30)`) that is missing, not a number, not finite, or not an
    /// integer where one is required.
    pub fn parse_line(text: &str, path: &Path, line: usize) -> Result<OxtsPacket> {
        let tokens: Vec<&str> = text.split_whitespace().collect();
        if tokens.len() < 30 {
            let i = tokens.len();
            return Err(Error::parse(
                path,
                line,
                field_label(i),
                format!("missing: the line has {} values, expected 30", tokens.len()),
            ));
        }
        if tokens.len() > 30 {
            return Err(Error::parse(
                path,
                line,
                "line",
                format!("{} values, expected 30", tokens.len()),
            ));
        }
        let mut values = [0.0; 30];
        for (i, tok) in tokens.iter().enumerate() {
            values[i] = parse_f64(path, line, &field_label(i), tok)?;
            if i >= FIRST_INTEGER_FIELD && values[i].fract() != 0.0 {
                return Err(Error::parse(
                    path,
                    line,
                    field_label(i),
                    format!("`{tok}` is not an integer code"),
                ));
            }
        }
        OxtsPacket::from_values(&values)
            .map_err(|e| Error::parse(path, line, "line", e.to_string()))
    }

    /// The packet as one line in KITTI's layout. Floating-point values are printed with the
    /// shortest text that reads back to the same `f64`, so writing then reading is lossless.
    pub fn to_line(&self) -> String {
        let v = self.to_values();
        let mut parts: Vec<String> = v[..FIRST_INTEGER_FIELD]
            .iter()
            .map(|x| format!("{x:?}"))
            .collect();
        for &code in &v[FIRST_INTEGER_FIELD..] {
            parts.push(format!("{}", code as i64));
        }
        parts.join(" ")
    }
}

fn field_label(i: usize) -> String {
    format!("{} (value {} of 30)", OXTS_FIELDS[i], i + 1)
}

/// Reads one OXTS file (one packet on one line; blank lines ignored).
pub fn read_oxts_file(path: impl AsRef<Path>) -> Result<OxtsPacket> {
    let path = path.as_ref();
    let text = read_text(path)?;
    let mut lines = numbered_lines(&text);
    let Some((line_no, line)) = lines.next() else {
        return Err(Error::parse(path, 1, "packet", "file is empty"));
    };
    let packet = OxtsPacket::parse_line(line, path, line_no)?;
    if let Some((extra, _)) = lines.next() {
        return Err(Error::parse(
            path,
            extra,
            "packet",
            "more than one line (expected one packet per file)",
        ));
    }
    Ok(packet)
}

/// Reads a folder of OXTS files (`0000000000.txt`, `0000000001.txt`, ...), in frame order.
///
/// Errors: the folder is missing ([`Error::Io`] naming it), a file in the numbering is missing
/// (naming that file), or any file is malformed (naming file, line and field).
pub fn read_oxts_dir(dir: impl AsRef<Path>) -> Result<Vec<OxtsPacket>> {
    let dir = dir.as_ref();
    let files = list_frame_files(dir, "txt")?;
    require_contiguous(dir, &files, "txt")?;
    files.iter().map(|(_, p)| read_oxts_file(p)).collect()
}

/// Writes one packet as an OXTS file (one line, newline-terminated), atomically.
pub fn write_oxts_file(path: impl AsRef<Path>, packet: &OxtsPacket) -> Result<()> {
    let line = packet.to_line();
    write_atomically(path.as_ref(), |w| writeln!(w, "{line}"))
}

/// Writes packets as `dir/0000000000.txt`, `dir/0000000001.txt`, ... (the folder must exist).
pub fn write_oxts_dir(dir: impl AsRef<Path>, packets: &[OxtsPacket]) -> Result<()> {
    let dir = dir.as_ref();
    for (k, p) in packets.iter().enumerate() {
        write_oxts_file(dir.join(frame_file_name(k as u64, "txt")), p)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const LINE: &str = "49.015003823272 8.4342971002335 116.43032836914 0.035752 0.00903 \
        -2.6087069803847 -6.811441479104 -11.275641809511 13.172716663769 -0.12475264293164 \
        -0.032919903047354 -0.44519814607457 0.042957369847256 10.209865300506 -0.34030092211055 \
        -0.31686915378551 10.209117821189 0.0090951755733632 -0.023140741253985 \
        -0.017909034508194 0.0089018002187228 -0.022495299354602 -0.018809330937153 \
        0.027658633371879 0.012727922061358 4 11 6 6 6";

    #[test]
    fn parses_a_real_line_field_by_field() {
        let p = OxtsPacket::parse_line(LINE, Path::new("x.txt"), 1).unwrap();
        assert_eq!(p.lat, 49.015003823272);
        assert_eq!(p.yaw, -2.6087069803847);
        assert_eq!(p.vf, 13.172716663769);
        assert_eq!(p.wu, -0.018809330937153);
        assert_eq!(
            (p.navstat, p.numsats, p.posmode, p.velmode, p.orimode),
            (4, 11, 6, 6, 6)
        );
    }

    #[test]
    fn line_round_trip_is_lossless() {
        let p = OxtsPacket::parse_line(LINE, Path::new("x.txt"), 1).unwrap();
        let q = OxtsPacket::parse_line(&p.to_line(), Path::new("y.txt"), 1).unwrap();
        assert_eq!(p, q);
    }

    #[test]
    fn short_line_names_the_missing_field() {
        let short: Vec<&str> = LINE.split_whitespace().take(29).collect();
        let msg = OxtsPacket::parse_line(&short.join(" "), Path::new("d/0000000003.txt"), 1)
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("d/0000000003.txt:1: orimode (value 30 of 30)"),
            "{msg}"
        );
        assert!(msg.contains("29 values"), "{msg}");
    }

    #[test]
    fn bad_values_name_the_field() {
        let mut tokens: Vec<&str> = LINE.split_whitespace().collect();
        tokens[8] = "fast";
        let msg = OxtsPacket::parse_line(&tokens.join(" "), Path::new("f.txt"), 1)
            .unwrap_err()
            .to_string();
        assert_eq!(msg, "f.txt:1: vf (value 9 of 30): `fast` is not a number");
        tokens[8] = "1.0";
        tokens[26] = "11.5";
        let msg = OxtsPacket::parse_line(&tokens.join(" "), Path::new("f.txt"), 1)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("numsats"), "{msg}");
        tokens[26] = "11";
        tokens.push("7");
        assert!(OxtsPacket::parse_line(&tokens.join(" "), Path::new("f.txt"), 1).is_err());
    }

    #[test]
    fn files_and_folders() {
        let dir = tempfile::tempdir().unwrap();
        let p = OxtsPacket::parse_line(LINE, Path::new("x.txt"), 1).unwrap();
        let mut q = p;
        q.lat += 1e-5;
        write_oxts_dir(dir.path(), &[p, q]).unwrap();
        let back = read_oxts_dir(dir.path()).unwrap();
        assert_eq!(back, vec![p, q]);
        std::fs::write(
            dir.path().join("0000000001.txt"),
            format!("{LINE}\n{LINE}\n"),
        )
        .unwrap();
        let msg = read_oxts_dir(dir.path()).unwrap_err().to_string();
        assert!(msg.contains("0000000001.txt:2"), "{msg}");
        std::fs::write(dir.path().join("0000000001.txt"), "").unwrap();
        assert!(read_oxts_dir(dir.path()).is_err());
        let msg = read_oxts_dir(dir.path().join("nope"))
            .unwrap_err()
            .to_string();
        assert!(msg.contains("nope"), "{msg}");
    }
}
