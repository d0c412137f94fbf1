//! Reader for ROS 1 bag files (format 2.0): the `sensor_msgs/LaserScan` messages of one topic
//! and, when present, `nav_msgs/Odometry` messages, decoded from their ROS 1 serialisation.
//! The bag's record structure is walked with the `rosbag` crate. Not for: ROS 2 bags, bags
//! without an index (not closed properly: reindex them first), writing bags, or any other
//! message type.
//!
//! # Messages
//!
//! ROS 1 serialises little-endian, strings and arrays as a `u32` length followed by the
//! elements. A `sensor_msgs/LaserScan` is: header (`seq` u32, `stamp` = secs u32 + nsecs
//! u32, `frame_id` string), then `angle_min`, `angle_max`, `angle_increment`,
//! `time_increment`, `scan_time`, `range_min`, `range_max` (f32 each), `ranges` (f32
//! array) and `intensities` (f32 array). A `nav_msgs/Odometry` is: header,
//! `child_frame_id` string, pose (position x y z, orientation quaternion x y z w: f64),
//! 36 f64 pose covariance, twist (linear x y z, angular x y z: f64), 36 f64 twist
//! covariance. Every read is bounds-checked: a short message, leftover bytes, a beam count
//! that disagrees with `angle_min`/`angle_max`/`angle_increment` by more than one beam, or
//! an intensity array that is neither empty nor one per beam is an [`Error::Parse`] naming
//! the topic, the message's position on it and the field (line 0: a bag has no lines).
//!
//! # Mapping to [`Scan`]
//!
//! `time` is the header stamp (s), or the bag's receive time when the stamp is zero;
//! `angle_min`, `angle_increment`, `range_min`, `range_max` are copied; intensities are
//! dropped. Note that ROS counts a range equal to `range_min` or `range_max` as valid while
//! [`Scan`] treats it as "no return". Odometry poses become planar: `theta` is the yaw of
//! the quaternion; `linear_velocity` is twist.linear.x, `angular_velocity` twist.angular.z.
//! Each scan gets the latest odometry pose not after its time ([`attach_odometry`]).
//! [`read_pose_arrays`] reads the `geometry_msgs/PoseArray` messages of one topic (header,
//! `u32` count, then per pose position x y z and orientation x y z w, f64), e.g. the leg
//! annotations of a recording; a non-finite position is refused with the message's stamp.
//! Messages are returned in the bag's storage order; their stamps are not checked for order
//! (a scan stamped before the one preceding it is returned as it is, and the people tracker
//! then stops with an error naming that scan).

use super::scan::{attach_odometry, OdometryRecord, Scan};
use crate::error::{Error, Result};
use crate::geometry::Pose2;
use ::rosbag::{ChunkRecord, IndexRecord, MessageRecord, RosBag};
use std::collections::HashMap;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

const LASER_SCAN: &str = "sensor_msgs/LaserScan";
const ODOMETRY: &str = "nav_msgs/Odometry";
const POSE_ARRAY: &str = "geometry_msgs/PoseArray";

/// One `geometry_msgs/PoseArray` message: the positions of its poses (orientations are read
/// and dropped).
#[derive(Clone, Debug, PartialEq)]
pub struct PoseArrayRecord {
    /// Header stamp (s), or the bag's receive time when the stamp is zero.
    pub time: f64,
    /// The bag's receive time (s).
    pub receive_time: f64,
    /// `[x, y, z]` of every pose, in the header's frame.
    pub positions: Vec<[f64; 3]>,
}

/// Reads every `geometry_msgs/PoseArray` message of `topic` in storage order. A missing
/// topic, a topic of another type, a malformed message or a non-finite position is an
/// [`Error::Parse`] naming the bag, the topic and (for a bad message) its time stamp.
pub fn read_pose_arrays(path: impl AsRef<Path>, topic: &str) -> Result<Vec<PoseArrayRecord>> {
    let path = path.as_ref();
    let bag = open_bag(path)?;
    let conns = connections(&bag, path)?;
    let ids: Vec<u32> = conns
        .iter()
        .filter(|(_, t, ty)| t == topic && ty == POSE_ARRAY)
        .map(|(id, _, _)| *id)
        .collect();
    if ids.is_empty() {
        let names: Vec<String> = topics_of(&conns)
            .iter()
            .map(|t| format!("{} ({})", t.topic, t.message_type))
            .collect();
        return Err(Error::parse(
            path,
            0,
            "topic",
            format!(
                "`{topic}` is not a {POSE_ARRAY} topic of the bag; topics present: {}",
                names.join(", ")
            ),
        ));
    }
    let bag_err = |what: &str, e: ::rosbag::Error| Error::parse(path, 0, what, format!("{e}"));
    let mut out = Vec::new();
    for record in bag.chunk_records() {
        let ChunkRecord::Chunk(chunk) = record.map_err(|e| bag_err("chunk section", e))? else {
            continue;
        };
        for msg in chunk.messages() {
            let MessageRecord::MessageData(msg) = msg.map_err(|e| bag_err("chunk", e))? else {
                continue;
            };
            if !ids.contains(&msg.conn_id) {
                continue;
            }
            let k = out.len() + 1;
            let rec = decode_pose_array(msg.data, msg.time)
                .map_err(|(f, r)| Error::parse(path, 0, format!("{topic} message {k}: {f}"), r))?;
            out.push(rec);
        }
    }
    Ok(out)
}

/// A topic stored in a bag, with its message type.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct BagTopic {
    /// Topic name, e.g. `/scan`.
    pub topic: String,
    /// Message type, e.g. `sensor_msgs/LaserScan`.
    pub message_type: String,
}

/// Which odometry topic to read.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub enum OdometryTopic {
    /// The only `nav_msgs/Odometry` topic if there is exactly one, none if there is none;
    /// an error if there are several.
    #[default]
    Auto,
    /// This topic, which must exist and carry `nav_msgs/Odometry`.
    Named(String),
    /// No odometry.
    Ignore,
}

/// What to read from a bag.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct BagOptions {
    /// The scan topic; `None` takes the only `sensor_msgs/LaserScan` topic of the bag (an
    /// error when there are several).
    pub scan_topic: Option<String>,
    /// The odometry topic.
    pub odometry: OdometryTopic,
}

impl BagOptions {
    /// Scans of `topic`, odometry chosen automatically.
    pub fn topic(topic: impl Into<String>) -> Self {
        BagOptions {
            scan_topic: Some(topic.into()),
            odometry: OdometryTopic::Auto,
        }
    }
}

/// What [`read_bag`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct BagScans {
    /// The scans, in storage order.
    pub scans: Vec<Scan>,
    /// The bag's receive time (s) of every scan, for pairing with other topics when the
    /// header stamps of the topics come from different clocks.
    pub receive_times: Vec<f64>,
    /// The odometry records, in storage order (empty without an odometry topic).
    pub odometry: Vec<OdometryRecord>,
    /// The topic the scans came from.
    pub scan_topic: String,
    /// The topic the odometry came from.
    pub odometry_topic: Option<String>,
    /// Every topic of the bag.
    pub topics: Vec<BagTopic>,
}

/// Lists the topics of a bag (sorted, each topic/type pair once).
pub fn bag_topics(path: impl AsRef<Path>) -> Result<Vec<BagTopic>> {
    let path = path.as_ref();
    let bag = open_bag(path)?;
    Ok(topics_of(&connections(&bag, path)?))
}

/// Reads the scans (and odometry) chosen by `options` from the bag at `path`.
pub fn read_bag(path: impl AsRef<Path>, options: &BagOptions) -> Result<BagScans> {
    let path = path.as_ref();
    let bag = open_bag(path)?;
    let conns = connections(&bag, path)?;
    let topics = topics_of(&conns);
    let listing = || {
        if topics.is_empty() {
            "the bag has no topics".to_string()
        } else {
            let names: Vec<String> = topics
                .iter()
                .map(|t| format!("{} ({})", t.topic, t.message_type))
                .collect();
            format!("topics present: {}", names.join(", "))
        }
    };
    let of_type =
        |ty: &str| -> Vec<&BagTopic> { topics.iter().filter(|t| t.message_type == ty).collect() };
    let topic_err = |reason: String| Error::parse(path, 0, "topic", reason);

    let scan_topic = match &options.scan_topic {
        Some(name) => {
            let found: Vec<&BagTopic> = topics.iter().filter(|t| &t.topic == name).collect();
            if found.is_empty() {
                return Err(topic_err(format!(
                    "`{name}` is not in the bag; {}",
                    listing()
                )));
            }
            if found.iter().any(|t| t.message_type != LASER_SCAN) {
                return Err(topic_err(format!(
                    "`{name}` does not carry {LASER_SCAN}; {}",
                    listing()
                )));
            }
            name.clone()
        }
        None => match of_type(LASER_SCAN).as_slice() {
            [one] => one.topic.clone(),
            [] => return Err(topic_err(format!("no {LASER_SCAN} topic; {}", listing()))),
            _ => {
                return Err(topic_err(format!(
                    "several {LASER_SCAN} topics, choose one with BagOptions::scan_topic; {}",
                    listing()
                )))
            }
        },
    };
    let odometry_topic = match &options.odometry {
        OdometryTopic::Ignore => None,
        OdometryTopic::Named(name) => {
            let ok = topics
                .iter()
                .any(|t| &t.topic == name && t.message_type == ODOMETRY);
            if !ok {
                return Err(topic_err(format!(
                    "`{name}` is not a {ODOMETRY} topic of the bag; {}",
                    listing()
                )));
            }
            Some(name.clone())
        }
        OdometryTopic::Auto => match of_type(ODOMETRY).as_slice() {
            [] => None,
            [one] => Some(one.topic.clone()),
            _ => {
                return Err(topic_err(format!(
                    "several {ODOMETRY} topics, choose one with OdometryTopic::Named; {}",
                    listing()
                )))
            }
        },
    };

    // Connection id → what it feeds.
    #[derive(Clone, Copy)]
    enum Feed {
        Scan,
        Odometry,
    }
    let feeds: HashMap<u32, Feed> = conns
        .iter()
        .filter_map(|(id, topic, ty)| {
            if *topic == scan_topic && ty == LASER_SCAN {
                Some((*id, Feed::Scan))
            } else if Some(topic) == odometry_topic.as_ref() && ty == ODOMETRY {
                Some((*id, Feed::Odometry))
            } else {
                None
            }
        })
        .collect();

    let bag_err = |what: &str, e: ::rosbag::Error| Error::parse(path, 0, what, format!("{e}"));
    let mut scans = Vec::new();
    let mut receive_times = Vec::new();
    let mut odometry = Vec::new();
    for record in bag.chunk_records() {
        let ChunkRecord::Chunk(chunk) = record.map_err(|e| bag_err("chunk section", e))? else {
            continue;
        };
        for msg in chunk.messages() {
            let MessageRecord::MessageData(msg) = msg.map_err(|e| bag_err("chunk", e))? else {
                continue;
            };
            match feeds.get(&msg.conn_id) {
                Some(Feed::Scan) => {
                    let k = scans.len() + 1;
                    let scan = laser_scan_to_scan(msg.data, msg.time).map_err(|(f, r)| {
                        Error::parse(path, 0, format!("{scan_topic} message {k}: {f}"), r)
                    })?;
                    scans.push(scan);
                    receive_times.push(msg.time as f64 * 1e-9);
                }
                Some(Feed::Odometry) => {
                    let k = odometry.len() + 1;
                    let o = decode_odometry(msg.data, msg.time).map_err(|(f, r)| {
                        let t = odometry_topic.as_deref().unwrap_or_default();
                        Error::parse(path, 0, format!("{t} message {k}: {f}"), r)
                    })?;
                    odometry.push(o);
                }
                None => {}
            }
        }
    }
    if !odometry.is_empty() {
        attach_odometry(&mut scans, &odometry);
    }
    Ok(BagScans {
        scans,
        receive_times,
        odometry,
        scan_topic,
        odometry_topic,
        topics,
    })
}

/// Opens a bag after checking its header ourselves, so that a truncated or unindexed file is
/// an error rather than an out-of-range slice inside the `rosbag` crate.
fn open_bag(path: &Path) -> Result<RosBag> {
    let bad = |reason: String| Error::parse(path, 0, "bag header", reason);
    let mut file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let file_len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    let mut read_exact = |n: usize, what: &str| -> Result<Vec<u8>> {
        let mut buf = vec![0u8; n];
        file.read_exact(&mut buf).map_err(|e| {
            if e.kind() == std::io::ErrorKind::UnexpectedEof {
                bad(format!("the file ends inside the {what}"))
            } else {
                Error::io(path, e)
            }
        })?;
        Ok(buf)
    };
    const MAGIC: &[u8] = b"#ROSBAG V2.0\n";
    if read_exact(MAGIC.len(), "version line")? != MAGIC {
        return Err(bad(
            "not a ROS bag of format 2.0 (first line is not `#ROSBAG V2.0`)".into(),
        ));
    }
    let u32_of = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    let header_len = u32_of(&read_exact(4, "bag header")?);
    if u64::from(header_len) > file_len {
        return Err(bad(format!("header length {header_len} exceeds the file")));
    }
    let header = read_exact(header_len as usize, "bag header")?;
    let data_len = u32_of(&read_exact(4, "bag header")?);
    let mut index_pos = None;
    let mut rest = &header[..];
    while rest.len() >= 4 {
        let n = u32_of(rest) as usize;
        rest = &rest[4..];
        if n > rest.len() {
            return Err(bad("a header field runs past the header".into()));
        }
        let (field, tail) = rest.split_at(n);
        rest = tail;
        if let Some(v) = field.strip_prefix(b"index_pos=") {
            if v.len() != 8 {
                return Err(bad("index_pos is not 8 bytes".into()));
            }
            let mut b = [0u8; 8];
            b.copy_from_slice(v);
            index_pos = Some(u64::from_le_bytes(b));
        }
    }
    let index_pos = index_pos.ok_or_else(|| bad("no index_pos field".into()))?;
    let start = MAGIC.len() as u64 + 4 + u64::from(header_len) + 4 + u64::from(data_len);
    if index_pos == 0 {
        return Err(bad(
            "the bag has no index (it was not closed properly; reindex it first)".into(),
        ));
    }
    if index_pos < start || index_pos > file_len {
        return Err(bad(format!(
            "index position {index_pos} lies outside the data ({start}..={file_len}): the file \
             is truncated or damaged"
        )));
    }
    check_chunk_sizes(path, &mut file, start, index_pos)?;
    RosBag::new(path).map_err(|e| Error::io(path, e))
}

/// The fields (`name=value`, each after its `u32` length) of a record header, up to the first
/// one that runs past the header.
fn header_fields(header: &[u8]) -> impl Iterator<Item = &[u8]> {
    let mut rest = header;
    std::iter::from_fn(move || {
        if rest.len() < 4 {
            return None;
        }
        let n = u32::from_le_bytes([rest[0], rest[1], rest[2], rest[3]]) as usize;
        if n > rest.len() - 4 {
            return None;
        }
        let (field, tail) = rest[4..].split_at(n);
        rest = tail;
        Some(field)
    })
}

/// Compressed chunks declaring at most this many uncompressed bytes are left to the `rosbag`
/// crate as they are (ROS closes a chunk at about 768 KiB).
const CHUNK_SIZE_TRUSTED: u64 = 64 << 20;

/// How far lz4 can expand its input at most (a match length grows by 255 per extra byte).
const LZ4_MAX_RATIO: u64 = 256;

/// Walks the records of the chunk section (`start..end`) and refuses a compressed chunk that
/// declares more than [`CHUNK_SIZE_TRUSTED`] uncompressed bytes unless its data can hold them:
/// the `rosbag` crate reserves the declared size before decompressing, so a chunk of a few
/// bytes declaring 4 GiB would reserve 4 GiB. bzip2 data is decoded (without keeping the
/// output) and must give exactly the declared size; lz4 data must be large enough to expand to
/// it. The walk stops at the first record that does not fit the section, where the crate
/// stops with its own error.
fn check_chunk_sizes(path: &Path, file: &mut File, start: u64, end: u64) -> Result<()> {
    let io = |e| Error::io(path, e);
    let mut pos = start;
    let mut chunk = 0;
    while end - pos >= 8 {
        file.seek(SeekFrom::Start(pos)).map_err(io)?;
        let mut len = [0u8; 4];
        file.read_exact(&mut len).map_err(io)?;
        let header_len = u64::from(u32::from_le_bytes(len));
        if header_len > end - pos - 8 {
            break;
        }
        let mut header = vec![0u8; header_len as usize];
        file.read_exact(&mut header).map_err(io)?;
        file.read_exact(&mut len).map_err(io)?;
        let data_len = u64::from(u32::from_le_bytes(len));
        if data_len > end - pos - 8 - header_len {
            break;
        }
        pos += 8 + header_len + data_len;
        let (mut op, mut compression, mut size) = (None, None, None);
        for field in header_fields(&header) {
            let Some(eq) = field.iter().position(|&b| b == b'=') else {
                continue;
            };
            match (&field[..eq], &field[eq + 1..]) {
                (b"op", &[v]) => op = Some(v),
                (b"compression", v) => compression = Some(v),
                (b"size", &[a, b, c, d]) => {
                    size = Some(u64::from(u32::from_le_bytes([a, b, c, d])))
                }
                _ => {}
            }
        }
        if op != Some(0x05) {
            continue;
        }
        chunk += 1;
        let (Some(compression), Some(size)) = (compression, size) else {
            continue;
        };
        if size <= CHUNK_SIZE_TRUSTED {
            continue;
        }
        let bad = |holds: String| {
            Error::parse(
                path,
                0,
                format!("chunk {chunk}"),
                format!(
                    "declares {size} bytes uncompressed, but its {data_len} bytes of {} data \
                     {holds}",
                    String::from_utf8_lossy(compression)
                ),
            )
        };
        match compression {
            b"bz2" => {
                let data = file.by_ref().take(data_len);
                let mut decoder = bzip2::read::BzDecoder::new(data).take(size + 1);
                match std::io::copy(&mut decoder, &mut std::io::sink()) {
                    Ok(n) if n == size => {}
                    Ok(n) => return Err(bad(format!("hold {n}"))),
                    Err(e) => return Err(bad(format!("do not decompress ({e})"))),
                }
            }
            b"lz4" if size > data_len.saturating_mul(LZ4_MAX_RATIO) => {
                return Err(bad("cannot hold that many".into()));
            }
            _ => {}
        }
    }
    Ok(())
}

/// Every connection of the index section as (id, topic, type).
fn connections(bag: &RosBag, path: &Path) -> Result<Vec<(u32, String, String)>> {
    let mut out = Vec::new();
    for record in bag.index_records() {
        let record = record.map_err(|e| Error::parse(path, 0, "index section", format!("{e}")))?;
        if let IndexRecord::Connection(c) = record {
            out.push((c.id, c.topic.to_string(), c.tp.to_string()));
        }
    }
    Ok(out)
}

fn topics_of(conns: &[(u32, String, String)]) -> Vec<BagTopic> {
    let mut topics: Vec<BagTopic> = conns
        .iter()
        .map(|(_, topic, ty)| BagTopic {
            topic: topic.clone(),
            message_type: ty.clone(),
        })
        .collect();
    topics.sort();
    topics.dedup();
    topics
}

/// A decoding failure: (field, reason).
type DecodeResult<T> = std::result::Result<T, (String, String)>;

/// Bounds-checked little-endian reads over one serialised message.
struct Bytes<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Bytes<'a> {
    fn new(data: &'a [u8]) -> Self {
        Bytes { data, pos: 0 }
    }

    fn take(&mut self, n: usize, field: &str) -> DecodeResult<&'a [u8]> {
        let left = self.data.len() - self.pos;
        if n > left {
            return Err((
                field.to_string(),
                format!(
                    "message truncated: needs {n} bytes at offset {}, {left} left",
                    self.pos
                ),
            ));
        }
        let s = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn u32(&mut self, field: &str) -> DecodeResult<u32> {
        let b = self.take(4, field)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn f32(&mut self, field: &str) -> DecodeResult<f32> {
        Ok(f32::from_bits(self.u32(field)?))
    }

    fn f64(&mut self, field: &str) -> DecodeResult<f64> {
        let b = self.take(8, field)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(f64::from_le_bytes(a))
    }

    fn string(&mut self, field: &str) -> DecodeResult<String> {
        let n = self.u32(field)? as usize;
        let b = self.take(n, field)?;
        Ok(String::from_utf8_lossy(b).into_owned())
    }

    fn f32_array(&mut self, field: &str) -> DecodeResult<Vec<f32>> {
        let n = self.u32(field)? as usize;
        let bytes = n
            .checked_mul(4)
            .ok_or_else(|| (field.to_string(), format!("length {n} is impossible")))?;
        let b = self.take(bytes, field)?;
        Ok(b.chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect())
    }

    fn finish(&self, what: &str) -> DecodeResult<()> {
        let left = self.data.len() - self.pos;
        if left != 0 {
            return Err((
                what.to_string(),
                format!("{left} unexpected bytes after the last field"),
            ));
        }
        Ok(())
    }

    /// A `std_msgs/Header`; returns the stamp in seconds, or `fallback_ns` when it is zero.
    fn header(&mut self, fallback_ns: u64) -> DecodeResult<f64> {
        self.u32("header.seq")?;
        let secs = self.u32("header.stamp.secs")?;
        let nsecs = self.u32("header.stamp.nsecs")?;
        if nsecs >= 1_000_000_000 {
            return Err((
                "header.stamp.nsecs".into(),
                format!("{nsecs} is not below 10^9"),
            ));
        }
        self.string("header.frame_id")?;
        Ok(if secs == 0 && nsecs == 0 {
            fallback_ns as f64 * 1e-9
        } else {
            f64::from(secs) + f64::from(nsecs) * 1e-9
        })
    }
}

/// Decodes a `sensor_msgs/LaserScan` into a [`Scan`]; `receive_ns` is the bag's time of the
/// message, used when the header stamp is zero.
fn laser_scan_to_scan(data: &[u8], receive_ns: u64) -> DecodeResult<Scan> {
    let mut b = Bytes::new(data);
    let time = b.header(receive_ns)?;
    let angle_min = f64::from(b.f32("angle_min")?);
    let angle_max = f64::from(b.f32("angle_max")?);
    let angle_increment = f64::from(b.f32("angle_increment")?);
    b.f32("time_increment")?;
    b.f32("scan_time")?;
    let range_min = f64::from(b.f32("range_min")?);
    let range_max = f64::from(b.f32("range_max")?);
    let ranges = b.f32_array("ranges")?;
    let intensities = b.f32_array("intensities")?;
    b.finish("intensities")?;
    let n = ranges.len();
    if n == 0 {
        return Err(("ranges".into(), "no beams".into()));
    }
    let implied = (angle_max - angle_min) / angle_increment + 1.0;
    if !(implied.is_finite() && (implied - n as f64).abs() <= 1.0 + 1e-6) {
        return Err((
            "ranges".into(),
            format!(
                "{n} beams, but angle_min {angle_min}, angle_max {angle_max} and \
                 angle_increment {angle_increment} imply {implied:.1}"
            ),
        ));
    }
    if !intensities.is_empty() && intensities.len() != n {
        return Err((
            "intensities".into(),
            format!(
                "{} values for {n} beams (must be 0 or {n})",
                intensities.len()
            ),
        ));
    }
    Scan::new(
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
        ("header values".to_string(), reason)
    })
}

/// Decodes a `geometry_msgs/PoseArray`: header, then a `u32` count of poses, each position
/// x y z and orientation x y z w (f64). A non-finite position is refused with the stamp.
fn decode_pose_array(data: &[u8], receive_ns: u64) -> DecodeResult<PoseArrayRecord> {
    let mut b = Bytes::new(data);
    let time = b.header(receive_ns)?;
    let n = b.u32("poses")? as usize;
    if n.saturating_mul(56) > data.len() {
        return Err((
            "poses".into(),
            format!("{n} poses cannot fit in a message of {} bytes", data.len()),
        ));
    }
    let mut positions = Vec::with_capacity(n);
    for i in 0..n {
        let x = b.f64("poses.position.x")?;
        let y = b.f64("poses.position.y")?;
        let z = b.f64("poses.position.z")?;
        for f in ["x", "y", "z", "w"] {
            b.f64(&format!("poses.orientation.{f}"))?;
        }
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            return Err((
                format!("poses[{i}].position"),
                format!("[{x}, {y}, {z}] is not finite (stamp {time:.9} s)"),
            ));
        }
        positions.push([x, y, z]);
    }
    b.finish("poses")?;
    Ok(PoseArrayRecord {
        time,
        receive_time: receive_ns as f64 * 1e-9,
        positions,
    })
}

/// Decodes a `nav_msgs/Odometry` into a planar [`OdometryRecord`].
fn decode_odometry(data: &[u8], receive_ns: u64) -> DecodeResult<OdometryRecord> {
    let mut b = Bytes::new(data);
    let time = b.header(receive_ns)?;
    b.string("child_frame_id")?;
    let x = b.f64("pose.position.x")?;
    let y = b.f64("pose.position.y")?;
    b.f64("pose.position.z")?;
    let qx = b.f64("pose.orientation.x")?;
    let qy = b.f64("pose.orientation.y")?;
    let qz = b.f64("pose.orientation.z")?;
    let qw = b.f64("pose.orientation.w")?;
    b.take(36 * 8, "pose.covariance")?;
    let vx = b.f64("twist.linear.x")?;
    b.f64("twist.linear.y")?;
    b.f64("twist.linear.z")?;
    b.f64("twist.angular.x")?;
    b.f64("twist.angular.y")?;
    let wz = b.f64("twist.angular.z")?;
    b.take(36 * 8, "twist.covariance")?;
    b.finish("twist.covariance")?;
    // Yaw of the quaternion (rotation about z of the z-y-x Euler decomposition).
    let theta = (2.0 * (qw * qz + qx * qy)).atan2(1.0 - 2.0 * (qy * qy + qz * qz));
    let pose = Pose2::new(x, y, theta);
    if !pose.is_finite() || !time.is_finite() {
        return Err(("pose".into(), format!("{pose:?} is not finite")));
    }
    Ok(OdometryRecord {
        time,
        pose,
        linear_velocity: vx,
        angular_velocity: wz,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(out: &mut Vec<u8>, secs: u32, nsecs: u32) {
        out.extend(7u32.to_le_bytes());
        out.extend(secs.to_le_bytes());
        out.extend(nsecs.to_le_bytes());
        out.extend(5u32.to_le_bytes());
        out.extend(b"laser");
    }

    fn laser_bytes(ranges: &[f32], intensities: usize, amax: f32) -> Vec<u8> {
        let mut m = Vec::new();
        header(&mut m, 10, 500_000_000);
        for v in [-1.0f32, amax, 0.5, 0.0, 0.1, 0.05, 20.0] {
            m.extend(v.to_le_bytes());
        }
        m.extend((ranges.len() as u32).to_le_bytes());
        for r in ranges {
            m.extend(r.to_le_bytes());
        }
        m.extend((intensities as u32).to_le_bytes());
        for _ in 0..intensities {
            m.extend(1.0f32.to_le_bytes());
        }
        m
    }

    #[test]
    fn laser_scan_decodes() {
        let m = laser_bytes(&[1.0, 2.0, 3.0, 4.0, 5.0], 5, 1.0);
        let s = laser_scan_to_scan(&m, 0).unwrap();
        assert_eq!(s.time, 10.5);
        assert_eq!((s.angle_min, s.angle_increment), (-1.0, 0.5));
        assert_eq!((s.range_min, s.range_max), (0.05f32 as f64, 20.0));
        assert_eq!(s.ranges, vec![1.0, 2.0, 3.0, 4.0, 5.0]);
        // A zero stamp falls back to the receive time.
        let mut z = m.clone();
        z[4..12].fill(0);
        assert_eq!(laser_scan_to_scan(&z, 3_250_000_000).unwrap().time, 3.25);
    }

    #[test]
    fn odd_ranges_are_kept_and_odd_headers_refused() {
        // NaN, +∞, zero (below range_min), range_max itself: kept in place, none a return.
        let m = laser_bytes(&[f32::NAN, f32::INFINITY, 0.0, 20.0, 3.0], 0, 1.0);
        let s = laser_scan_to_scan(&m, 0).unwrap();
        assert_eq!(s.len(), 5);
        assert!(s.ranges[0].is_nan());
        assert_eq!(s.points().map(|(i, _)| i).collect::<Vec<_>>(), vec![4]);
        // Header floats at byte 21 on: angle_min, angle_max, angle_increment, time_increment,
        // scan_time, range_min, range_max.
        let set = |at: usize, v: f32| {
            let mut b = m.clone();
            b[21 + 4 * at..25 + 4 * at].copy_from_slice(&v.to_le_bytes());
            b
        };
        assert_eq!(
            laser_scan_to_scan(&set(2, f32::NAN), 0).unwrap_err().0,
            "ranges"
        );
        assert_eq!(laser_scan_to_scan(&set(2, 0.0), 0).unwrap_err().0, "ranges");
        assert_eq!(
            laser_scan_to_scan(&set(0, f32::NAN), 0).unwrap_err().0,
            "ranges"
        );
        let (field, reason) = laser_scan_to_scan(&set(6, f32::NAN), 0).unwrap_err();
        assert_eq!(field, "header values");
        assert!(reason.contains("range_max"), "{reason}");
        let (field, reason) = laser_scan_to_scan(&set(5, 30.0), 0).unwrap_err();
        assert_eq!(field, "header values");
        assert!(reason.contains("range_max"), "{reason}");
    }

    #[test]
    fn every_truncation_is_an_error() {
        let m = laser_bytes(&[1.0, 2.0, 3.0, 4.0, 5.0], 5, 1.0);
        for cut in 0..m.len() {
            let r = laser_scan_to_scan(&m[..cut], 0);
            assert!(r.is_err(), "cut at {cut} decoded");
        }
        let (field, reason) = laser_scan_to_scan(&m[..m.len() - 2], 0).unwrap_err();
        assert_eq!(field, "intensities");
        assert!(reason.contains("truncated"), "{reason}");
        let mut long = m.clone();
        long.push(0);
        assert!(laser_scan_to_scan(&long, 0).is_err());
        // A huge declared array length must not allocate or panic.
        let mut huge = m[..49].to_vec(); // header 21 bytes + 7 floats
        huge.extend(u32::MAX.to_le_bytes());
        assert_eq!(laser_scan_to_scan(&huge, 0).unwrap_err().0, "ranges");
    }

    #[test]
    fn beam_count_must_match_header() {
        let m = laser_bytes(&[1.0, 2.0, 3.0], 0, 1.0); // header implies 5 beams
        assert_eq!(laser_scan_to_scan(&m, 0).unwrap_err().0, "ranges");
        let m = laser_bytes(&[1.0, 2.0, 3.0, 4.0], 0, 1.0); // one short: tolerated
        assert!(laser_scan_to_scan(&m, 0).is_ok());
        let m = laser_bytes(&[1.0, 2.0, 3.0, 4.0, 5.0], 3, 1.0);
        assert_eq!(laser_scan_to_scan(&m, 0).unwrap_err().0, "intensities");
    }

    fn odom_bytes(yaw: f64) -> Vec<u8> {
        let mut m = Vec::new();
        header(&mut m, 2, 0);
        m.extend(9u32.to_le_bytes());
        m.extend(b"base_link");
        let (s, c) = (yaw / 2.0).sin_cos();
        for v in [1.5, -2.0, 0.0, 0.0, 0.0, s, c] {
            m.extend(f64::to_le_bytes(v));
        }
        m.extend([0u8; 36 * 8]);
        for v in [0.7, 0.0, 0.0, 0.0, 0.0, -0.3] {
            m.extend(f64::to_le_bytes(v));
        }
        m.extend([0u8; 36 * 8]);
        m
    }

    #[test]
    fn odometry_decodes() {
        let m = odom_bytes(2.5);
        let o = decode_odometry(&m, 0).unwrap();
        assert_eq!(o.time, 2.0);
        assert_eq!((o.pose.x, o.pose.y), (1.5, -2.0));
        assert!((o.pose.theta - 2.5).abs() < 1e-12);
        assert_eq!((o.linear_velocity, o.angular_velocity), (0.7, -0.3));
        assert_eq!(
            decode_odometry(&m[..m.len() - 1], 0).unwrap_err().0,
            "twist.covariance"
        );
    }

    fn pose_array_bytes(points: &[[f64; 3]]) -> Vec<u8> {
        let mut m = Vec::new();
        header(&mut m, 4, 250_000_000);
        m.extend((points.len() as u32).to_le_bytes());
        for p in points {
            for v in [p[0], p[1], p[2], 0.0, 0.0, 0.0, 1.0] {
                m.extend(f64::to_le_bytes(v));
            }
        }
        m
    }

    #[test]
    fn pose_arrays_decode_and_nan_is_refused_with_its_stamp() {
        let m = pose_array_bytes(&[[1.0, 2.0, 0.0], [-0.5, 0.25, 0.1]]);
        let r = decode_pose_array(&m, 9_000_000_000).unwrap();
        assert_eq!(r.time, 4.25);
        assert_eq!(r.receive_time, 9.0);
        assert_eq!(r.positions, vec![[1.0, 2.0, 0.0], [-0.5, 0.25, 0.1]]);
        assert!(decode_pose_array(&pose_array_bytes(&[]), 0)
            .unwrap()
            .positions
            .is_empty());
        let (field, reason) =
            decode_pose_array(&pose_array_bytes(&[[f64::NAN, 0.0, 0.0]]), 0).unwrap_err();
        assert_eq!(field, "poses[0].position");
        assert!(reason.contains("4.25"), "{reason}");
        for cut in 0..m.len() {
            assert!(decode_pose_array(&m[..cut], 0).is_err(), "cut at {cut}");
        }
        let mut huge = m[..21].to_vec();
        huge.extend(u32::MAX.to_le_bytes());
        assert_eq!(decode_pose_array(&huge, 0).unwrap_err().0, "poses");
    }

    #[test]
    fn damaged_bag_files_are_errors() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("x.bag");
        std::fs::write(&p, b"#ROSBAG V1.2\n").unwrap();
        assert!(matches!(
            read_bag(&p, &BagOptions::default()),
            Err(Error::Parse { .. })
        ));
        std::fs::write(&p, b"#ROSBAG V2.0\n\x10\x00").unwrap();
        assert!(matches!(bag_topics(&p), Err(Error::Parse { .. })));
        // A header whose index position points past the end of the file.
        let mut b = b"#ROSBAG V2.0\n".to_vec();
        let field = [b"index_pos=".as_slice(), &9999u64.to_le_bytes()].concat();
        b.extend((field.len() as u32 + 4).to_le_bytes());
        b.extend((field.len() as u32).to_le_bytes());
        b.extend(&field);
        b.extend(0u32.to_le_bytes());
        std::fs::write(&p, &b).unwrap();
        let e = bag_topics(&p).unwrap_err().to_string();
        assert!(e.contains("truncated"), "{e}");
        assert!(matches!(
            bag_topics(d.path().join("none.bag")),
            Err(Error::Io { .. })
        ));
    }
}
