//! Preprocessing of a scan: range cropping and voxel downsampling (paper, Sec. III-B). Both
//! keep the input order, so their output does not depend on hashing.

use super::voxel_map::{Voxel, VoxelTable};
use crate::cloud::PointCloud;
use nalgebra::Vector3;

/// The points of `cloud` whose distance to the sensor lies strictly between `min_range` and
/// `max_range`, as f64 vectors in the input order. Non-finite points are dropped.
pub fn crop_range(cloud: &PointCloud, min_range: f64, max_range: f64) -> Vec<Vector3<f64>> {
    let (lo2, hi2) = (min_range * min_range, max_range * max_range);
    cloud
        .xs()
        .iter()
        .zip(cloud.ys())
        .zip(cloud.zs())
        .map(|((&x, &y), &z)| Vector3::new(x as f64, y as f64, z as f64))
        .filter(|p| {
            let r2 = p.norm_squared();
            r2.is_finite() && r2 > lo2 && r2 < hi2
        })
        .collect()
}

/// One point per voxel of edge `voxel_size`: the first of the input that falls into it, in
/// the input order.
pub fn voxel_downsample(points: &[Vector3<f64>], voxel_size: f64) -> Vec<Vector3<f64>> {
    let mut seen: VoxelTable<()> = VoxelTable::default();
    seen.reserve(points.len() / 4);
    points
        .iter()
        .filter(|p| seen.insert(Voxel::of(p, voxel_size), ()).is_none())
        .copied()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crop_keeps_the_open_range_and_drops_nan() {
        let mut c = PointCloud::new();
        c.push(0.5, 0.0, 0.0, 0.0);
        c.push(3.0, 4.0, 0.0, 0.0);
        c.push(f32::NAN, 0.0, 0.0, 0.0);
        c.push(100.0, 0.0, 0.0, 0.0);
        let kept = crop_range(&c, 1.0, 100.0);
        assert_eq!(kept, vec![Vector3::new(3.0, 4.0, 0.0)]);
    }

    #[test]
    fn downsampling_keeps_the_first_point_of_each_voxel() {
        let p = vec![
            Vector3::new(0.1, 0.1, 0.1),
            Vector3::new(0.9, 0.2, 0.3),
            Vector3::new(1.1, 0.0, 0.0),
            Vector3::new(0.5, 0.5, 0.5),
        ];
        let d = voxel_downsample(&p, 1.0);
        assert_eq!(d, vec![p[0], p[2]]);
    }
}
