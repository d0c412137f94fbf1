//! LZF, the compression of `binary_compressed` PCD data: reading the block's two sizes and
//! checking them against the header and the file, decompressing the stream (liblzf's format)
//! and compressing one for writing.
//!
//! Not for: the column-major layout of the decompressed fields (see [`super::decode_pcd`] and
//! [`super::encode_pcd`]) or any other compression.

use super::header::{data_bytes, Header};
use crate::error::{Error, Result};
use std::path::Path;

/// Largest output of an LZF stream per input byte: a three-byte back-reference copies up to
/// 264 bytes.
const LZF_MAX_RATIO: usize = 88;

/// Reads the sizes of a binary_compressed block, checks them against the header and the file,
/// and decompresses it.
pub(super) fn decompress_data(path: &Path, header: &Header, data: &[u8]) -> Result<Vec<u8>> {
    if data.len() < 8 {
        return Err(Error::parse(
            path,
            0,
            "data",
            format!(
                "truncated: {} bytes after the header, the two sizes need 8",
                data.len()
            ),
        ));
    }
    let word = |k: usize| u32::from_le_bytes([data[k], data[k + 1], data[k + 2], data[k + 3]]);
    let (packed, unpacked) = (word(0) as usize, word(4) as usize);
    let need = data_bytes(path, header)?;
    if unpacked != need {
        return Err(Error::parse(
            path,
            0,
            "data",
            format!(
                "uncompressed size {unpacked} bytes, but {} points of {} bytes need {need}",
                header.points, header.record
            ),
        ));
    }
    let body = &data[8..];
    if packed > body.len() {
        return Err(Error::parse(
            path,
            0,
            "data",
            format!(
                "truncated: compressed size {packed} bytes, {} follow the sizes",
                body.len()
            ),
        ));
    }
    if unpacked > packed.saturating_mul(LZF_MAX_RATIO) {
        return Err(Error::parse(
            path,
            0,
            "data",
            format!("{packed} compressed bytes cannot hold {unpacked} bytes of LZF output"),
        ));
    }
    lzf_decompress(&body[..packed], unpacked)
        .map_err(|reason| Error::parse(path, 0, "LZF data", reason))
}

/// Decompresses an LZF stream (liblzf's format) that must produce exactly `len` bytes.
///
/// Each control byte `c` starts either a literal run (`c < 32`: the next `c + 1` bytes) or a
/// back-reference: length `c >> 5` (7 means: add the next byte), plus 2; distance
/// `((c & 31) << 8 | next byte) + 1` back from the end of the output.
fn lzf_decompress(input: &[u8], len: usize) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(len);
    let mut at = 0;
    while at < input.len() {
        let ctrl = usize::from(input[at]);
        at += 1;
        if ctrl < 32 {
            let run = ctrl + 1;
            let lit = input
                .get(at..at + run)
                .ok_or_else(|| format!("literal run of {run} bytes at byte {} is cut", at - 1))?;
            if out.len() + run > len {
                return Err(format!("output exceeds the announced {len} bytes"));
            }
            out.extend_from_slice(lit);
            at += run;
        } else {
            let start = at - 1;
            let mut n = ctrl >> 5;
            if n == 7 {
                n += usize::from(
                    *input
                        .get(at)
                        .ok_or_else(|| format!("back-reference at byte {start} is cut"))?,
                );
                at += 1;
            }
            let low = usize::from(
                *input
                    .get(at)
                    .ok_or_else(|| format!("back-reference at byte {start} is cut"))?,
            );
            at += 1;
            let distance = ((ctrl & 31) << 8 | low) + 1;
            let n = n + 2;
            if distance > out.len() {
                return Err(format!(
                    "back-reference at byte {start} reaches {distance} bytes back, only {} \
                     decoded",
                    out.len()
                ));
            }
            if out.len() + n > len {
                return Err(format!("output exceeds the announced {len} bytes"));
            }
            let from = out.len() - distance;
            for k in 0..n {
                out.push(out[from + k]);
            }
        }
    }
    if out.len() != len {
        return Err(format!(
            "stream ends after {} bytes of the announced {len}",
            out.len()
        ));
    }
    Ok(out)
}

/// Compresses `input` as an LZF stream (greedy, one hash-table probe per position).
pub(super) fn lzf_compress(input: &[u8]) -> Vec<u8> {
    const HASH_BITS: u32 = 14;
    const MAX_DISTANCE: usize = 1 << 13;
    const MAX_LEN: usize = 7 + 255 + 2;
    fn literals(out: &mut Vec<u8>, mut lit: &[u8]) {
        while !lit.is_empty() {
            let n = lit.len().min(32);
            out.push((n - 1) as u8);
            out.extend_from_slice(&lit[..n]);
            lit = &lit[n..];
        }
    }
    let mut out = Vec::with_capacity(input.len() + input.len() / 32 + 1);
    let mut table = vec![usize::MAX; 1 << HASH_BITS];
    let (mut i, mut lit_start) = (0, 0);
    while i + 3 <= input.len() {
        let key =
            u32::from(input[i]) << 16 | u32::from(input[i + 1]) << 8 | u32::from(input[i + 2]);
        let h = (key.wrapping_mul(2_654_435_761) >> (32 - HASH_BITS)) as usize;
        let candidate = table[h];
        table[h] = i;
        if candidate != usize::MAX
            && i - candidate <= MAX_DISTANCE
            && input[candidate..candidate + 3] == input[i..i + 3]
        {
            let max = MAX_LEN.min(input.len() - i);
            let mut n = 3;
            while n < max && input[candidate + n] == input[i + n] {
                n += 1;
            }
            literals(&mut out, &input[lit_start..i]);
            let distance = i - candidate - 1;
            let l = n - 2;
            if l < 7 {
                out.push((l << 5 | distance >> 8) as u8);
            } else {
                out.push((7 << 5 | distance >> 8) as u8);
                out.push((l - 7) as u8);
            }
            out.push(distance as u8);
            i += n;
            lit_start = i;
        } else {
            i += 1;
        }
    }
    literals(&mut out, &input[lit_start..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lzf_compress_then_decompress_is_identity() {
        let mut data: Vec<u8> = (0..5000u32).flat_map(|k| (k % 97).to_le_bytes()).collect();
        data.extend(std::iter::repeat_n(7u8, 1000));
        let packed = lzf_compress(&data);
        assert!(packed.len() < data.len() / 2);
        assert_eq!(lzf_decompress(&packed, data.len()).unwrap(), data);
        assert_eq!(lzf_decompress(&lzf_compress(b""), 0).unwrap(), b"");
        assert_eq!(lzf_decompress(&lzf_compress(b"ab"), 2).unwrap(), b"ab");
    }
}
