//! Tests of reading and writing whole PCD files and byte buffers: round trips in every
//! encoding, other field types and layouts, corrupt or truncated data and malformed headers.
//!
//! Not for: the LZF codec on its own (tested in [`super::lzf`]).

use super::*;
use proptest::prelude::*;

fn sample() -> PointCloud {
    let mut c = PointCloud::new();
    c.push(1.2345, -20.5, 0.25, 0.0);
    c.push(-3.0, 4.0, -1.75, 0.5);
    c.push(60.0, 0.001, 2.0, 1.0);
    c.push(1e-7, -1e30, 3.25, 0.123_456_79);
    c
}

const ALL: [PcdEncoding; 3] = [
    PcdEncoding::Ascii,
    PcdEncoding::Binary,
    PcdEncoding::BinaryCompressed,
];

fn header(fields: &str, sizes: &str, types: &str, counts: &str, n: usize, data: &str) -> String {
    format!(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS {fields}\nSIZE {sizes}\nTYPE {types}\n\
         COUNT {counts}\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\n\
         DATA {data}\n"
    )
}

fn decode(bytes: &[u8]) -> Result<PcdScan> {
    decode_pcd("mem.pcd", bytes, NonFinite::Error)
}

#[test]
fn round_trips_are_exact_in_every_encoding() {
    let dir = tempfile::tempdir().unwrap();
    for encoding in ALL {
        let path = dir.path().join("c.pcd");
        write_pcd(&path, &sample(), encoding).unwrap();
        assert_eq!(read_pcd(&path).unwrap(), sample(), "{encoding:?}");
        write_pcd(&path, &PointCloud::new(), encoding).unwrap();
        assert!(read_pcd(&path).unwrap().is_empty(), "{encoding:?}");
    }
}

#[test]
fn labelled_round_trip_returns_the_labels() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("l.pcd");
    for encoding in ALL {
        write_pcd_labelled(&path, &sample(), &[0, 7, u32::MAX, 3], encoding).unwrap();
        let scan = read_pcd_with(&path, NonFinite::Error).unwrap();
        assert_eq!(scan.cloud, sample());
        assert_eq!(scan.labels, Some(vec![0, 7, u32::MAX, 3]));
    }
    assert!(write_pcd_labelled(&path, &sample(), &[1], PcdEncoding::Binary).is_err());
    write_pcd(&path, &sample(), PcdEncoding::Binary).unwrap();
    assert_eq!(read_pcd_with(&path, NonFinite::Error).unwrap().labels, None);
}

#[test]
fn reads_other_types_and_skips_other_fields() {
    // rgb (F 4), a 3-count normal (F 8), padding, U 2 intensity, I 1 z, U 2 label.
    let mut text = header(
        "rgb x normal _ y z intensity label",
        "4 8 8 1 4 1 2 2",
        "F F F U F I U U",
        "1 1 3 2 1 1 1 1",
        2,
        "ascii",
    );
    text.push_str("4.2e6 1.5 0.1 0.2 0.3 0 0 -2.5 -3 65535 12\n");
    text.push_str("\n0 -7 1 1 1 9 9 2 127 0 0\n");
    let scan = decode(text.as_bytes()).unwrap();
    assert_eq!(scan.cloud.xs(), &[1.5, -7.0]);
    assert_eq!(scan.cloud.ys(), &[-2.5, 2.0]);
    assert_eq!(scan.cloud.zs(), &[-3.0, 127.0]);
    assert_eq!(scan.cloud.intensities(), &[1.0, 0.0]);
    assert_eq!(scan.labels, Some(vec![12, 0]));

    // The same points as binary records.
    let mut bytes = header(
        "rgb x normal _ y z intensity label",
        "4 8 8 1 4 1 2 2",
        "F F F U F I U U",
        "1 1 3 2 1 1 1 1",
        2,
        "binary",
    )
    .into_bytes();
    for (x, y, z, i, l) in [
        (1.5f64, -2.5f32, -3i8, 65535u16, 12u16),
        (-7.0, 2.0, 127, 0, 0),
    ] {
        bytes.extend_from_slice(&4.2e6f32.to_le_bytes());
        bytes.extend_from_slice(&x.to_le_bytes());
        bytes.extend_from_slice(&[0u8; 24]);
        bytes.extend_from_slice(&[9, 9]);
        bytes.extend_from_slice(&y.to_le_bytes());
        bytes.extend_from_slice(&z.to_le_bytes());
        bytes.extend_from_slice(&i.to_le_bytes());
        bytes.extend_from_slice(&l.to_le_bytes());
    }
    assert_eq!(decode(&bytes).unwrap(), scan);
}

#[test]
fn reflectance_and_old_headers_are_read() {
    let text = "VERSION .5\nCOLUMNS x y z reflectance\nSIZE 4 4 4 4\nTYPE F F F F\n\
                WIDTH 1\nDATA ascii\n1 2 3 0.25\n";
    let scan = decode(text.as_bytes()).unwrap();
    assert_eq!(scan.cloud.intensities(), &[0.25]);
    let text = "VERSION 0.6\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nPOINTS 1\nDATA ascii\n\
                1 2 3\n";
    let scan = decode(text.as_bytes()).unwrap();
    assert_eq!(scan.cloud.intensities(), &[0.0]);
    // A comment in Latin-1 and a CRLF header.
    let mut bytes = b"# caf\xe9\r\n".to_vec();
    bytes.extend_from_slice(text.replace('\n', "\r\n").as_bytes());
    assert_eq!(decode(&bytes).unwrap().cloud.xs(), &[1.0]);
}

/// A binary_compressed file of `n` points with fields `x y z` (F 4) and the given stream.
fn compressed(n: usize, raw_len: usize, stream: &[u8]) -> Vec<u8> {
    let mut bytes = header("x y z", "4 4 4", "F F F", "1 1 1", n, "binary_compressed").into_bytes();
    bytes.extend_from_slice(&(stream.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&(raw_len as u32).to_le_bytes());
    bytes.extend_from_slice(stream);
    bytes
}

#[test]
fn binary_compressed_with_literals_only() {
    // Two points, column-major: x0 x1 y0 y1 z0 z1, 24 bytes in one literal run of 24
    // (control byte 23).
    let mut raw = Vec::new();
    for v in [1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0] {
        raw.extend_from_slice(&v.to_le_bytes());
    }
    let mut stream = vec![23u8];
    stream.extend_from_slice(&raw);
    let scan = decode(&compressed(2, 24, &stream)).unwrap();
    assert_eq!(scan.cloud.xs(), &[1.0, 2.0]);
    assert_eq!(scan.cloud.ys(), &[3.0, 4.0]);
    assert_eq!(scan.cloud.zs(), &[5.0, 6.0]);
}

#[test]
fn binary_compressed_with_back_references() {
    // Four points at (1, 1, 1), (1, 1, 1), (0, 0, 0), (0, 0, 0) hold, column-major,
    // x: 1 1 0 0, y: 1 1 0 0, z: 1 1 0 0 (1.0 = 00 00 80 3f).
    //   literal 4 bytes: 00 00 80 3f                          -> 1.0
    //   back-ref len 4 dist 4: ctrl (4-2)<<5 = 0x40, dist-1 = 3   -> 1.0 again
    //   literal 1 byte: 00; back-ref len 7 dist 1: (7-2)<<5 = 0xa0, 0 -> eight zeros
    //   back-ref len 16 dist 16: 7<<5 = 0xe0, extra 16-2-7 = 7, dist-1 = 15
    //                                                        -> y column = x column
    //   back-ref len 16 dist 16 again                          -> z column
    let stream = [
        0x03, 0x00, 0x00, 0x80, 0x3f, // literal 1.0
        0x40, 0x03, // copy 4 from 4 back
        0x00, 0x00, // literal 0x00
        0xa0, 0x00, // copy 7 from 1 back
        0xe0, 0x07, 0x0f, // copy 16 from 16 back
        0xe0, 0x07, 0x0f, // copy 16 from 16 back
    ];
    let scan = decode(&compressed(4, 48, &stream)).unwrap();
    let expected = [1.0, 1.0, 0.0, 0.0];
    assert_eq!(scan.cloud.xs(), &expected);
    assert_eq!(scan.cloud.ys(), &expected);
    assert_eq!(scan.cloud.zs(), &expected);
}

#[test]
fn corrupt_lzf_is_an_error_naming_the_file() {
    for (stream, raw_len) in [
        (&[0x05u8, 1, 2][..], 12),        // literal run cut
        (&[0x00, 1, 0x20, 0x05][..], 12), // reference beyond the start
        (&[0xe0][..], 12),                // reference cut
        (&[0x02, 1, 2, 3][..], 12),       // ends early
        (&[0x0b, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x20, 0][..], 12), // too long
    ] {
        let err = decode(&compressed(1, raw_len, stream))
            .unwrap_err()
            .to_string();
        assert!(err.contains("mem.pcd") && err.contains("LZF"), "{err}");
    }
    // Sizes disagreeing with the header or the file.
    for (bytes, fault) in [
        (compressed(1, 16, &[0x00, 1]), "uncompressed size 16"),
        (compressed(1, 12, &[]), "cannot hold"),
    ] {
        let err = decode(&bytes).unwrap_err().to_string();
        assert!(err.contains("mem.pcd") && err.contains(fault), "{err}");
    }
    let mut huge = compressed(1, 12, &[]);
    let at = huge.len() - 8;
    huge[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    let err = decode(&huge).unwrap_err().to_string();
    assert!(err.contains("truncated"), "{err}");
}

#[test]
fn every_truncation_is_an_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.pcd");
    for encoding in ALL {
        write_pcd_labelled(&path, &sample(), &[1, 2, 3, 4], encoding).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        for n in 0..bytes.len() {
            // Without its final newline an ascii file is still whole.
            if encoding == PcdEncoding::Ascii && n == bytes.len() - 1 {
                continue;
            }
            let res = decode(&bytes[..n]);
            assert!(res.is_err(), "{encoding:?} cut at {n} of {}", bytes.len());
            assert!(res.unwrap_err().to_string().contains("mem.pcd"));
        }
    }
}

#[test]
fn bad_headers_are_errors_naming_the_file_and_the_fault() {
    let good = header("x y z", "4 4 4", "F F F", "1 1 1", 1, "ascii") + "1 2 3\n";
    assert!(decode(good.as_bytes()).is_ok());
    let cases: Vec<(String, &str)> = vec![
        (
            good.replace("DATA ascii", "DATA binary_lz4"),
            "unknown encoding",
        ),
        (
            good.replace("SIZE 4 4 4", "SIZE 4 4"),
            "2 entries for 3 fields",
        ),
        (
            good.replace("TYPE F F F", "TYPE F F F F"),
            "4 entries for 3 fields",
        ),
        (
            good.replace("COUNT 1 1 1", "COUNT 1 1"),
            "2 entries for 3 fields",
        ),
        (good.replace("COUNT 1 1 1", "COUNT 1 0 1"), "count `0`"),
        (good.replace("FIELDS x y z", "FIELDS x y w"), "no `z` field"),
        (good.replace("POINTS 1", "POINTS 2"), "WIDTH × HEIGHT"),
        (
            good.replace("VERSION 0.7", "VERSION 2.0"),
            "unsupported version",
        ),
        (good.replace("SIZE 4 4 4", "SIZE 4 4 3"), "size `3`"),
        (good.replace("SIZE 4 4 4", "SIZE 4 4 2"), "must be 4 or 8"),
        (good.replace("TYPE F F F", "TYPE F F Q"), "type `Q`"),
        (
            good.replace("VIEWPOINT 0 0 0 1 0 0 0", "VIEWPOINT 0 0"),
            "7 finite",
        ),
        (
            good.replace("HEIGHT 1", "HEIGHT 1\nSCALE 1"),
            "unknown header keyword",
        ),
        (good.replace("COUNT 1 1 1", "COUNT 2 1 1"), "COUNT is 2"),
        (
            good.replace("DATA ascii\n1 2 3\n", ""),
            "ends before the DATA line",
        ),
        (good.replace("1 2 3\n", "1 2\n"), "2 values on the line"),
        (good.replace("1 2 3\n", "1 2 x\n"), "`x` is not a float"),
        (good.replace("1 2 3\n", "1 2 3\n4 5 6\n"), "more lines"),
        (good.replace("1 2 3\n", "1 2 nan\n"), "must be finite"),
        (
            good.replace("POINTS 1", "POINTS 4000000000")
                .replace("WIDTH 1", "WIDTH 4000000000"),
            "bytes follow the header",
        ),
        (
            good.replace("POINTS 1", "POINTS 3")
                .replace("WIDTH 1", "WIDTH 3"),
            "cannot fit",
        ),
    ];
    for (text, fault) in cases {
        let err = decode(text.as_bytes()).unwrap_err().to_string();
        assert!(
            err.contains("mem.pcd") && err.contains(fault),
            "{fault}: {err}"
        );
    }
    // Line numbers of ascii data: the point is on line 12.
    let err = decode(good.replace("1 2 3\n", "1 2 x\n").as_bytes())
        .unwrap_err()
        .to_string();
    assert!(err.contains("mem.pcd:12:"), "{err}");
}

#[test]
fn huge_binary_counts_are_refused_before_allocating() {
    for n in ["4000000000", "18446744073709551615"] {
        let text = header("x y z", "4 4 4", "F F F", "1 1 1", 1, "binary")
            .replace("WIDTH 1", &format!("WIDTH {n}"))
            .replace("POINTS 1", &format!("POINTS {n}"));
        let err = decode(text.as_bytes()).unwrap_err().to_string();
        assert!(err.contains("mem.pcd") && err.contains("POINTS"), "{err}");
    }
    // Within the file's size in points but not in bytes.
    let mut bytes = header("x y z", "4 4 4", "F F F", "1 1 1", 20, "binary").into_bytes();
    bytes.extend_from_slice(&[0u8; 100]);
    let err = decode(&bytes).unwrap_err().to_string();
    assert!(err.contains("truncated"), "{err}");
}

#[test]
fn nan_points_are_refused_or_skipped() {
    let mut c = sample();
    c.push(f32::NAN, f32::NAN, f32::NAN, 0.0);
    c.push(5.0, 6.0, 7.0, f32::INFINITY);
    c.push(8.0, 9.0, 10.0, 0.5);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("nan.pcd");
    for encoding in ALL {
        write_pcd_labelled(&path, &c, &[0, 1, 2, 3, 4, 5, 6], encoding).unwrap();
        let err = read_pcd(&path).unwrap_err().to_string();
        assert!(
            err.contains("nan.pcd") && err.contains("point 4 (x)"),
            "{err}"
        );
        let scan = read_pcd_with(&path, NonFinite::Skip).unwrap();
        assert_eq!(scan.skipped, 2);
        assert_eq!(scan.cloud.len(), 5);
        assert_eq!(scan.cloud.xs()[4], 8.0);
        assert_eq!(scan.labels, Some(vec![0, 1, 2, 3, 6]));
    }
}

fn finite() -> impl Strategy<Value = f32> {
    prop_oneof![
        proptest::num::f32::NORMAL | proptest::num::f32::SUBNORMAL | proptest::num::f32::ZERO,
        -100.0..100.0f32,
    ]
}

proptest! {
    #[test]
    fn random_clouds_round_trip_exactly(
        points in proptest::collection::vec((finite(), finite(), finite(), finite(), any::<u32>()), 0..80),
        encoding in prop_oneof![
            Just(PcdEncoding::Ascii),
            Just(PcdEncoding::Binary),
            Just(PcdEncoding::BinaryCompressed),
        ],
        labelled in any::<bool>(),
    ) {
        let mut cloud = PointCloud::new();
        for p in &points {
            cloud.push(p.0, p.1, p.2, p.3);
        }
        let labels: Vec<u32> = points.iter().map(|p| p.4).collect();
        let bytes = encode_pcd(&cloud, labelled.then_some(&labels[..]), encoding).unwrap();
        let scan = decode(&bytes).unwrap();
        // Bit for bit, so that -0.0 and subnormals count too.
        let bits = |c: &PointCloud| {
            c.iter().map(|p| [p.x, p.y, p.z, p.intensity].map(f32::to_bits)).collect::<Vec<_>>()
        };
        prop_assert_eq!(bits(&scan.cloud), bits(&cloud));
        prop_assert_eq!(scan.labels, labelled.then_some(labels));
        prop_assert_eq!(scan.skipped, 0);
    }
}

#[test]
fn missing_file_names_the_file() {
    let err = read_pcd("/nonexistent/dir/scan.pcd")
        .unwrap_err()
        .to_string();
    assert!(err.contains("scan.pcd"), "{err}");
}
