//! An excerpt of a ROS 1 bag (format 2.0): the first `n` messages of every connection,
//! written as a new, indexed bag the way ROS's own bag writer lays one out.
//!
//! Records are `u32` header length, header (fields `u32` length + `name=value`), `u32` data
//! length, data. The excerpt is:
//!
//! - `#ROSBAG V2.0\n`, then the bag header record (`op` 0x03: `chunk_count`, `conn_count`,
//!   `index_pos`), its data spaces so that header and data make 4096 bytes;
//! - chunk records (`op` 0x05, `compression=none`, `size`), each followed by one index data
//!   record per connection in it (`op` 0x04, `ver` 1, `conn`, `count`; data: per message its
//!   receive time and its offset in the chunk), connections in id order. A chunk holds
//!   message data records (`op` 0x02) in the source's storage order, and before a
//!   connection's first message its connection record (`op` 0x07). A chunk is closed once
//!   its data exceeds the threshold;
//! - the index section at `index_pos`: every connection record (id order), then one chunk
//!   info record per chunk (`op` 0x06, `ver` 1, `chunk_pos`, `start_time`, `end_time`,
//!   `count`; data: per connection its id and message count in the chunk).
//!
//! Header fields are written in name order, as ROS writes them. Message and connection
//! records are copied byte for byte from the source, so every message keeps its content and
//! receive time. Only uncompressed source chunks are read.

use std::collections::BTreeMap;

const MAGIC: &[u8] = b"#ROSBAG V2.0\n";
/// Bag header record, header and data together.
const BAG_HEADER_LEN: usize = 4096;
const OP_MESSAGE: u8 = 0x02;
const OP_BAG_HEADER: u8 = 0x03;
const OP_INDEX_DATA: u8 = 0x04;
const OP_CHUNK: u8 = 0x05;
const OP_CHUNK_INFO: u8 = 0x06;
const OP_CONNECTION: u8 = 0x07;

/// What to keep and how to chunk it.
#[derive(Clone, Copy, Debug)]
pub struct CutOptions {
    /// Messages kept per connection (the first ones in storage order).
    pub messages: usize,
    /// A chunk is closed once its data exceeds this many bytes.
    pub chunk_threshold: usize,
}

/// One record of the source: its header fields and the whole record's bytes.
struct Record<'a> {
    fields: Vec<(&'a [u8], &'a [u8])>,
    data: &'a [u8],
    bytes: &'a [u8],
}

impl<'a> Record<'a> {
    fn field(&self, name: &str) -> Result<&'a [u8], String> {
        self.fields
            .iter()
            .find(|(n, _)| *n == name.as_bytes())
            .map(|(_, v)| *v)
            .ok_or_else(|| format!("a record without the `{name}` field"))
    }

    fn op(&self) -> Result<u8, String> {
        match self.field("op")? {
            [op] => Ok(*op),
            _ => Err("an `op` field that is not one byte".into()),
        }
    }

    fn u32(&self, name: &str) -> Result<u32, String> {
        let v = self.field(name)?;
        let b: [u8; 4] = v
            .try_into()
            .map_err(|_| format!("`{name}` is not 4 bytes"))?;
        Ok(u32::from_le_bytes(b))
    }

    fn u64(&self, name: &str) -> Result<u64, String> {
        let v = self.field(name)?;
        let b: [u8; 8] = v
            .try_into()
            .map_err(|_| format!("`{name}` is not 8 bytes"))?;
        Ok(u64::from_le_bytes(b))
    }

    /// A ROS time field (`u32` seconds, `u32` nanoseconds).
    fn time(&self, name: &str) -> Result<[u8; 8], String> {
        self.field(name)?
            .try_into()
            .map_err(|_| format!("`{name}` is not 8 bytes"))
    }
}

fn u32_at(b: &[u8], at: usize) -> Result<usize, String> {
    let s = b
        .get(at..at + 4)
        .ok_or_else(|| format!("the data ends inside a length at byte {at}"))?;
    Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]) as usize)
}

/// Splits `b` into records.
fn records(b: &[u8]) -> Result<Vec<Record<'_>>, String> {
    let mut out = Vec::new();
    let mut pos = 0;
    while pos < b.len() {
        let start = pos;
        let header_len = u32_at(b, pos)?;
        let header = b
            .get(pos + 4..pos + 4 + header_len)
            .ok_or("a record header runs past the end")?;
        pos += 4 + header_len;
        let data_len = u32_at(b, pos)?;
        let data = b
            .get(pos + 4..pos + 4 + data_len)
            .ok_or("a record's data runs past the end")?;
        pos += 4 + data_len;
        let mut fields = Vec::new();
        let mut h = header;
        while !h.is_empty() {
            let n = u32_at(h, 0)?;
            let f = h
                .get(4..4 + n)
                .ok_or("a header field runs past its header")?;
            let eq = f
                .iter()
                .position(|&c| c == b'=')
                .ok_or("a header field without `=`")?;
            fields.push((&f[..eq], &f[eq + 1..]));
            h = &h[4 + n..];
        }
        out.push(Record {
            fields,
            data,
            bytes: &b[start..pos],
        });
    }
    Ok(out)
}

/// Appends a record with these header fields (written in the order given) and data.
fn write_record(out: &mut Vec<u8>, fields: &[(&str, &[u8])], data: &[u8]) {
    let header_len: usize = fields.iter().map(|(n, v)| 4 + n.len() + 1 + v.len()).sum();
    out.extend((header_len as u32).to_le_bytes());
    for (name, value) in fields {
        out.extend(((name.len() + 1 + value.len()) as u32).to_le_bytes());
        out.extend(name.as_bytes());
        out.push(b'=');
        out.extend(*value);
    }
    out.extend((data.len() as u32).to_le_bytes());
    out.extend(data);
}

/// A chunk being filled.
#[derive(Default)]
struct OpenChunk {
    data: Vec<u8>,
    /// Per connection: (receive time, offset in `data`) of its messages.
    index: BTreeMap<u32, Vec<([u8; 8], u32)>>,
    /// Earliest and latest receive time as (seconds, nanoseconds).
    span: Option<((u32, u32), (u32, u32))>,
}

/// What the index section says about a written chunk.
struct ChunkInfo {
    pos: u64,
    span: ((u32, u32), (u32, u32)),
    counts: Vec<(u32, u32)>,
}

fn time_bytes((s, ns): (u32, u32)) -> [u8; 8] {
    let mut b = [0u8; 8];
    b[..4].copy_from_slice(&s.to_le_bytes());
    b[4..].copy_from_slice(&ns.to_le_bytes());
    b
}

/// Writes the chunk and its index data records; returns its chunk info.
fn close_chunk(out: &mut Vec<u8>, chunk: OpenChunk) -> ChunkInfo {
    let pos = out.len() as u64;
    write_record(
        out,
        &[
            ("compression", b"none"),
            ("op", &[OP_CHUNK]),
            ("size", &(chunk.data.len() as u32).to_le_bytes()),
        ],
        &chunk.data,
    );
    let mut counts = Vec::new();
    for (conn, entries) in &chunk.index {
        let mut data = Vec::with_capacity(12 * entries.len());
        for (time, offset) in entries {
            data.extend(time);
            data.extend(offset.to_le_bytes());
        }
        let count = entries.len() as u32;
        write_record(
            out,
            &[
                ("conn", &conn.to_le_bytes()),
                ("count", &count.to_le_bytes()),
                ("op", &[OP_INDEX_DATA]),
                ("ver", &1u32.to_le_bytes()),
            ],
            &data,
        );
        counts.push((*conn, count));
    }
    ChunkInfo {
        pos,
        span: chunk
            .span
            .expect("a chunk is only closed with a message in it"),
        counts,
    }
}

/// The excerpt of the bag `source` (its bytes) that `options` describe.
pub fn cut(source: &[u8], options: CutOptions) -> Result<Vec<u8>, String> {
    if options.messages == 0 {
        return Err("keep at least one message per connection".into());
    }
    let rest = source
        .strip_prefix(MAGIC)
        .ok_or("not a ROS bag of format 2.0")?;
    // The bag header record, then the chunk section up to the index.
    let header_len = u32_at(rest, 0)?;
    let first_len = 4 + header_len + 4 + u32_at(rest, 4 + header_len)?;
    let header_records = records(rest.get(..first_len).ok_or("truncated bag header")?)?;
    let header = &header_records[0];
    if header.op()? != OP_BAG_HEADER {
        return Err("the first record is not the bag header".into());
    }
    let index_pos = usize::try_from(header.u64("index_pos")?).map_err(|e| e.to_string())?;
    let chunk_section = source
        .get(MAGIC.len() + first_len..index_pos)
        .ok_or("index_pos lies outside the file")?;

    // Kept messages in storage order, and every connection record by id.
    let mut connections: BTreeMap<u32, &[u8]> = BTreeMap::new();
    let mut kept: Vec<(u32, (u32, u32), &[u8])> = Vec::new();
    let mut per_conn: BTreeMap<u32, usize> = BTreeMap::new();
    for record in records(chunk_section)? {
        match record.op()? {
            OP_CHUNK => {
                if record.field("compression")? != b"none" {
                    return Err("only uncompressed chunks can be cut".into());
                }
                for inner in records(record.data)? {
                    match inner.op()? {
                        OP_CONNECTION => {
                            connections.entry(inner.u32("conn")?).or_insert(inner.bytes);
                        }
                        OP_MESSAGE => {
                            let conn = inner.u32("conn")?;
                            let n = per_conn.entry(conn).or_default();
                            if *n < options.messages {
                                *n += 1;
                                let t = inner.time("time")?;
                                let secs = u32::from_le_bytes([t[0], t[1], t[2], t[3]]);
                                let nsecs = u32::from_le_bytes([t[4], t[5], t[6], t[7]]);
                                kept.push((conn, (secs, nsecs), inner.bytes));
                            }
                        }
                        op => return Err(format!("record op {op:#04x} inside a chunk")),
                    }
                }
            }
            OP_INDEX_DATA => {}
            op => return Err(format!("record op {op:#04x} in the chunk section")),
        }
    }

    let mut out = MAGIC.to_vec();
    let header_at = out.len();
    // Placeholder: rewritten with the index position and counts once they are known.
    write_bag_header(&mut out, 0, 0, 0);
    let mut written = std::collections::BTreeSet::new();
    let mut infos = Vec::new();
    let mut chunk = OpenChunk::default();
    for (conn, time, bytes) in kept {
        if !written.contains(&conn) {
            let record = connections
                .get(&conn)
                .ok_or_else(|| format!("connection {conn} has messages but no record"))?;
            chunk.data.extend(*record);
            written.insert(conn);
        }
        let offset = chunk.data.len() as u32;
        chunk.data.extend(bytes);
        chunk
            .index
            .entry(conn)
            .or_default()
            .push((time_bytes(time), offset));
        chunk.span = Some(match chunk.span {
            None => (time, time),
            Some((a, b)) => (a.min(time), b.max(time)),
        });
        if chunk.data.len() > options.chunk_threshold {
            infos.push(close_chunk(&mut out, std::mem::take(&mut chunk)));
        }
    }
    if chunk.span.is_some() {
        infos.push(close_chunk(&mut out, chunk));
    }
    let index_pos = out.len() as u64;
    for conn in &written {
        out.extend(connections[conn]);
    }
    for info in &infos {
        let mut data = Vec::new();
        for (conn, count) in &info.counts {
            data.extend(conn.to_le_bytes());
            data.extend(count.to_le_bytes());
        }
        write_record(
            &mut out,
            &[
                ("chunk_pos", &info.pos.to_le_bytes()),
                ("count", &(info.counts.len() as u32).to_le_bytes()),
                ("end_time", &time_bytes(info.span.1)),
                ("op", &[OP_CHUNK_INFO]),
                ("start_time", &time_bytes(info.span.0)),
                ("ver", &1u32.to_le_bytes()),
            ],
            &data,
        );
    }
    let mut header = Vec::new();
    write_bag_header(
        &mut header,
        index_pos,
        written.len() as u32,
        infos.len() as u32,
    );
    out[header_at..header_at + header.len()].copy_from_slice(&header);
    Ok(out)
}

/// The bag header record, padded with spaces to [`BAG_HEADER_LEN`] bytes.
fn write_bag_header(out: &mut Vec<u8>, index_pos: u64, conn_count: u32, chunk_count: u32) {
    let fields: [(&str, &[u8]); 4] = [
        ("chunk_count", &chunk_count.to_le_bytes()),
        ("conn_count", &conn_count.to_le_bytes()),
        ("index_pos", &index_pos.to_le_bytes()),
        ("op", &[OP_BAG_HEADER]),
    ];
    let header_len: usize = fields.iter().map(|(n, v)| 4 + n.len() + 1 + v.len()).sum();
    write_record(out, &fields, &vec![b' '; BAG_HEADER_LEN - header_len]);
}
