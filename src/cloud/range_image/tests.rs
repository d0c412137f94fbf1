//! Unit tests of the range image, its ground and its clustering on synthetic scans whose
//! rings, ground and objects are known by construction.

use super::*;
use crate::cloud::range_image::cluster::angle_exceeds_for_tests;
use proptest::prelude::*;

const HEIGHT: f64 = 1.73;

/// An axis-aligned box `[min, max]`.
type Aabb = ([f64; 3], [f64; 3]);

/// What a synthetic ray hit.
#[derive(Copy, Clone, Debug, PartialEq)]
enum Hit {
    Ground,
    Box(usize),
}

/// Ray from the origin along `d`: nearest hit among the ground z = −HEIGHT and `boxes`.
fn cast(d: [f64; 3], boxes: &[Aabb]) -> Option<(f64, Hit)> {
    let mut best: Option<(f64, Hit)> = None;
    if d[2] < 0.0 {
        best = Some((-HEIGHT / d[2], Hit::Ground));
    }
    for (k, (lo, hi)) in boxes.iter().enumerate() {
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        for a in 0..3 {
            if d[a].abs() < 1e-12 {
                if 0.0 < lo[a] || 0.0 > hi[a] {
                    t0 = f64::INFINITY;
                }
                continue;
            }
            let (u, v) = (lo[a] / d[a], hi[a] / d[a]);
            t0 = t0.max(u.min(v));
            t1 = t1.min(u.max(v));
        }
        if t0 <= t1 && t0 > 0.0 && best.is_none_or(|(t, _)| t0 < t) {
            best = Some((t0, Hit::Box(k)));
        }
    }
    best.filter(|(t, _)| *t < 80.0)
}

/// Elevations (rad) of `beams` beams from −2° down to −24.8°, highest first (every beam
/// reaches the ground within the 80 m range limit, so every ring has points).
fn elevations(beams: usize) -> Vec<f64> {
    (0..beams)
        .map(|b| (-2.0 - 22.8 * b as f64 / (beams - 1) as f64).to_radians())
        .collect()
}

/// A scan of `beams` × `cols` rays; `ring_major` stores ring after ring (KITTI), otherwise
/// column after column. Ring b starts at column `start[b]` (late starts), azimuth grows
/// counter-clockwise from 0. Returns the cloud, each point's beam and what it hit.
fn scan(
    beams: usize,
    cols: usize,
    boxes: &[Aabb],
    ring_major: bool,
    first_ring_start: usize,
) -> (PointCloud, Vec<usize>, Vec<Hit>) {
    let el = elevations(beams);
    let mut rays: Vec<(usize, usize)> = Vec::new();
    if ring_major {
        for b in 0..beams {
            let s = if b == 0 { first_ring_start } else { 0 };
            rays.extend((s..cols).map(|c| (b, c)));
        }
    } else {
        for c in 0..cols {
            rays.extend((0..beams).map(|b| (b, c)));
        }
    }
    let mut cloud = PointCloud::new();
    let (mut beam, mut hit) = (Vec::new(), Vec::new());
    for (b, c) in rays {
        // Half a bin in, so that rounding never moves a point across a bin edge.
        let a = TAU * (c as f64 + 0.5) / cols as f64;
        let d = [el[b].cos() * a.cos(), el[b].cos() * a.sin(), el[b].sin()];
        if let Some((t, h)) = cast(d, boxes) {
            cloud.push((d[0] * t) as f32, (d[1] * t) as f32, (d[2] * t) as f32, 0.0);
            beam.push(b);
            hit.push(h);
        }
    }
    (cloud, beam, hit)
}

/// Two boxes on the road, each showing the sensor one face head-on (the sensor lies inside
/// both boxes' slabs across their visible face, so no side is seen edge-on: the angle
/// criterion splits a side seen at grazing incidence by design).
fn two_cars() -> Vec<Aabb> {
    vec![
        ([6.0, -1.0, -HEIGHT], [10.0, 1.0, -0.2]),
        ([-1.0, 8.0, -HEIGHT], [1.0, 12.0, 0.3]),
    ]
}

#[test]
fn ring_major_scan_gives_rings_from_the_order() {
    let (cloud, beam, _) = scan(16, 720, &two_cars(), true, 40);
    let img = RangeImage::new(&cloud, &RangeImageConfig::default()).unwrap();
    assert_eq!(img.source(), RingSource::ScanOrder);
    assert_eq!(img.rows(), 16);
    assert_eq!(img.cols(), 720);
    for (i, &b) in beam.iter().enumerate() {
        let (row, _) = img.cell_of(i).unwrap();
        assert_eq!(row, b, "point {i}");
    }
    assert_eq!(img.occupied(), cloud.len());
}

#[test]
fn column_major_scan_falls_back_to_elevation() {
    let (cloud, beam, _) = scan(16, 360, &two_cars(), false, 0);
    let img = RangeImage::new(&cloud, &RangeImageConfig::default()).unwrap();
    assert_eq!(img.source(), RingSource::Elevation);
    assert_eq!(img.rows(), 16);
    assert_eq!(img.cols(), 360);
    for (i, &b) in beam.iter().enumerate() {
        assert_eq!(img.cell_of(i).unwrap().0, b);
    }
}

#[test]
fn shuffled_scan_falls_back_to_elevation() {
    let (cloud, beam, _) = scan(16, 360, &two_cars(), true, 0);
    // A fixed pseudo-random permutation: the points sorted by a hash of their index.
    let n = cloud.len();
    let mut perm: Vec<usize> = (0..n).collect();
    perm.sort_by_key(|&i| {
        (i as u64 + 1)
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .rotate_left(29)
    });
    let mut shuffled = PointCloud::new();
    for &i in &perm {
        let p = cloud.get(i).unwrap();
        shuffled.push(p.x, p.y, p.z, 0.0);
    }
    let img = RangeImage::new(&shuffled, &RangeImageConfig::default()).unwrap();
    assert_eq!(img.source(), RingSource::Elevation);
    for (k, &i) in perm.iter().enumerate() {
        assert_eq!(img.cell_of(k).unwrap().0, beam[i]);
    }
}

#[test]
fn bad_input_is_an_error_or_skipped() {
    let empty = PointCloud::new();
    assert!(RangeImage::new(&empty, &RangeImageConfig::default()).is_err());
    let nan = PointCloud::from_records(&[[f32::NAN, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]);
    assert!(RangeImage::new(&nan, &RangeImageConfig::default()).is_err());
    let (mut cloud, _, _) = scan(8, 90, &[], true, 0);
    let n = cloud.len();
    cloud.push(f32::NAN, 1.0, 1.0, 0.0);
    cloud.push(1.0, f32::INFINITY, 1.0, 0.0);
    let img = RangeImage::new(&cloud, &RangeImageConfig::default()).unwrap();
    assert_eq!(img.skipped(), 2);
    assert_eq!(img.cell_of(n), None);
    assert_eq!(img.cell_of(n + 5), None);
    assert_eq!(img.point_at(100, 0), None);
    let bad = RangeImageConfig {
        columns: Some(0),
        ..Default::default()
    };
    assert!(RangeImage::new(&cloud, &bad).is_err());
    let mask = ground_mask(&img, &PointCloud::new(), &GroundParams::default());
    assert!(mask.is_err(), "a cloud the image was not built from");
}

#[test]
fn ground_is_the_road_and_not_the_cars() {
    let (cloud, _, hit) = scan(32, 720, &two_cars(), true, 0);
    let img = RangeImage::new(&cloud, &RangeImageConfig::default()).unwrap();
    let mask = ground_mask(&img, &cloud, &GroundParams::default()).unwrap();
    // A car's foot within the slope allowance of the road before it may pass for road:
    // the bottom 0.25 m (tan 10° × the ring spacing there + the step tolerance).
    let wrong: Vec<(usize, Hit, bool, [f32; 3])> = hit
        .iter()
        .enumerate()
        .filter(|&(i, h)| {
            let foot = matches!(h, Hit::Box(_)) && cloud.zs()[i] < (0.25 - HEIGHT) as f32;
            mask[i] != (*h == Hit::Ground) && !foot
        })
        .map(|(i, h)| {
            (
                i,
                *h,
                mask[i],
                [cloud.xs()[i], cloud.ys()[i], cloud.zs()[i]],
            )
        })
        .collect();
    assert!(wrong.is_empty(), "{wrong:?}");
    assert!(mask.iter().filter(|&&g| g).count() > cloud.len() / 2);
}

#[test]
fn clusters_are_the_cars() {
    let (cloud, _, hit) = scan(32, 720, &two_cars(), true, 0);
    let img = RangeImage::new(&cloud, &RangeImageConfig::default()).unwrap();
    let mask = ground_mask(&img, &cloud, &GroundParams::default()).unwrap();
    let candidates: Vec<u32> = (0..cloud.len() as u32)
        .filter(|&i| !mask[i as usize])
        .collect();
    let found =
        range_image_clusters(&img, &cloud, &candidates, &ImageClusterParams::default()).unwrap();
    assert_eq!(
        found.len(),
        2,
        "{:?}",
        found.iter().map(|c| c.count).collect::<Vec<_>>()
    );
    for c in &found {
        let first = hit[c.indices[0] as usize];
        assert!(matches!(first, Hit::Box(_)));
        assert!(c.indices.iter().all(|&i| hit[i as usize] == first));
        // Every point of the car more than 0.25 m above the road is in its cluster.
        let above: Vec<usize> = (0..hit.len())
            .filter(|&i| hit[i] == first && cloud.zs()[i] >= (0.25 - HEIGHT) as f32)
            .collect();
        let missing = above
            .iter()
            .filter(|&&i| c.indices.binary_search(&(i as u32)).is_err())
            .count();
        assert_eq!(missing, 0, "{missing} of {} points", above.len());
    }
}

#[test]
fn a_box_behind_another_is_its_own_cluster() {
    // A wall facing the sensor at 5 m and one 3 m behind it, overlapping in azimuth.
    let boxes = vec![
        ([5.0, -1.0, -1.0], [5.2, 1.0, 1.0]),
        ([8.0, -3.0, -1.0], [8.2, 3.0, 1.0]),
    ];
    let (cloud, _, hit) = scan(32, 720, &boxes, true, 0);
    let img = RangeImage::new(&cloud, &RangeImageConfig::default()).unwrap();
    let all: Vec<u32> = (0..cloud.len() as u32)
        .filter(|&i| hit[i as usize] != Hit::Ground)
        .collect();
    let params = ImageClusterParams {
        max_distance: 10.0,
        ..Default::default()
    };
    let found = range_image_clusters(&img, &cloud, &all, &params).unwrap();
    // The far wall is seen on both sides of the near one: two pieces, never merged with it.
    for c in &found {
        let first = hit[c.indices[0] as usize];
        assert!(c.indices.iter().all(|&i| hit[i as usize] == first));
    }
    assert!(found
        .iter()
        .any(|c| hit[c.indices[0] as usize] == Hit::Box(0)));
    assert!(range_image_clusters(&img, &cloud, &[u32::MAX], &params).is_err());
}

proptest! {
    /// The cross/dot form of the angle test equals β computed with trigonometry.
    #[test]
    fn angle_test_matches_trigonometry(
        a in prop::array::uniform3(-30.0f64..30.0),
        b in prop::array::uniform3(-30.0f64..30.0),
        theta in 1.0f64..60.0,
    ) {
        let na = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        let nb = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
        prop_assume!(na > 0.5 && nb > 0.5);
        let (far, near, d1, d2) = if na >= nb { (a, b, na, nb) } else { (b, a, nb, na) };
        let _ = (far, near);
        let psi = ((a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (na * nb)).clamp(-1.0, 1.0).acos();
        let beta = (d2 * psi.sin()).atan2(d1 - d2 * psi.cos());
        let theta = theta.to_radians();
        prop_assume!((beta - theta).abs() > 1e-3);
        let fa = a.map(|v| v as f32);
        let fb = b.map(|v| v as f32);
        prop_assert_eq!(angle_exceeds_for_tests(fa, fb, theta.tan() as f32), beta > theta);
    }
}
