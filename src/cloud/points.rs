//! [`PointCloud`]: a 3D point cloud with one reflectance (intensity) value per point, stored as a
//! structure of arrays (`x`, `y`, `z`, `intensity`, all `f32`).
//!
//! This file is about holding, filtering and moving points. It is not a reader or a writer
//! (see [`crate::cloud::kitti_bin`]) and it knows nothing of segmentation or clustering.

use crate::error::{Error, Result};
use nalgebra::{Isometry3, Point3};

/// One point of a [`PointCloud`], returned by value by [`PointCloud::get`] and
/// [`PointCloud::iter`].
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct Point {
    /// x coordinate, metres.
    pub x: f32,
    /// y coordinate, metres.
    pub y: f32,
    /// z coordinate, metres.
    pub z: f32,
    /// Reflectance / intensity (KITTI: in [0, 1]).
    pub intensity: f32,
}

/// Axis-aligned bounding box of a point cloud.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Bounds {
    /// Smallest x, y, z over all points.
    pub min: [f32; 3],
    /// Largest x, y, z over all points.
    pub max: [f32; 3],
}

impl Bounds {
    /// Edge lengths `max - min` along x, y, z.
    pub fn extent(&self) -> [f32; 3] {
        [
            self.max[0] - self.min[0],
            self.max[1] - self.min[1],
            self.max[2] - self.min[2],
        ]
    }

    /// Whether `p` lies inside the box (faces included).
    pub fn contains(&self, p: [f32; 3]) -> bool {
        (0..3).all(|i| p[i] >= self.min[i] && p[i] <= self.max[i])
    }
}

/// A point cloud as a structure of arrays: four columns of equal length.
///
/// The columns are private so that they always have the same length; read them with
/// [`xs`](Self::xs), [`ys`](Self::ys), [`zs`](Self::zs), [`intensities`](Self::intensities)
/// or all at once with [`columns`](Self::columns).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointCloud {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    intensity: Vec<f32>,
}

impl PointCloud {
    /// An empty cloud.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty cloud with room for `n` points.
    pub fn with_capacity(n: usize) -> Self {
        PointCloud {
            x: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
            z: Vec::with_capacity(n),
            intensity: Vec::with_capacity(n),
        }
    }

    /// Builds a cloud from four columns; they must have the same length.
    pub fn from_columns(
        x: Vec<f32>,
        y: Vec<f32>,
        z: Vec<f32>,
        intensity: Vec<f32>,
    ) -> Result<Self> {
        let n = x.len();
        if y.len() != n || z.len() != n || intensity.len() != n {
            return Err(Error::invalid(
                "point cloud columns",
                format!(
                    "lengths differ: x {}, y {}, z {}, intensity {}",
                    n,
                    y.len(),
                    z.len(),
                    intensity.len()
                ),
            ));
        }
        Ok(PointCloud { x, y, z, intensity })
    }

    /// Builds a cloud from interleaved `[x, y, z, intensity]` records (the KITTI `.bin` layout).
    pub fn from_records(records: &[[f32; 4]]) -> Self {
        // One column at a time: plain maps, without a capacity check per value.
        let column = |k: usize| records.iter().map(|r| r[k]).collect::<Vec<f32>>();
        PointCloud {
            x: column(0),
            y: column(1),
            z: column(2),
            intensity: column(3),
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether the cloud has no points.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Appends one point.
    pub fn push(&mut self, x: f32, y: f32, z: f32, intensity: f32) {
        self.x.push(x);
        self.y.push(y);
        self.z.push(z);
        self.intensity.push(intensity);
    }

    /// Appends one [`Point`].
    pub fn push_point(&mut self, p: Point) {
        self.push(p.x, p.y, p.z, p.intensity);
    }

    /// Removes every point, keeping the allocations.
    pub fn clear(&mut self) {
        self.x.clear();
        self.y.clear();
        self.z.clear();
        self.intensity.clear();
    }

    /// The point at index `i`, or `None` past the end.
    pub fn get(&self, i: usize) -> Option<Point> {
        Some(Point {
            x: *self.x.get(i)?,
            y: self.y[i],
            z: self.z[i],
            intensity: self.intensity[i],
        })
    }

    /// The x column.
    pub fn xs(&self) -> &[f32] {
        &self.x
    }

    /// The y column.
    pub fn ys(&self) -> &[f32] {
        &self.y
    }

    /// The z column.
    pub fn zs(&self) -> &[f32] {
        &self.z
    }

    /// The intensity column.
    pub fn intensities(&self) -> &[f32] {
        &self.intensity
    }

    /// All four columns `(x, y, z, intensity)`.
    pub fn columns(&self) -> (&[f32], &[f32], &[f32], &[f32]) {
        (&self.x, &self.y, &self.z, &self.intensity)
    }

    /// All four columns, mutable (their lengths cannot change through slices).
    pub fn columns_mut(&mut self) -> (&mut [f32], &mut [f32], &mut [f32], &mut [f32]) {
        (&mut self.x, &mut self.y, &mut self.z, &mut self.intensity)
    }

    /// Splits the cloud into its four columns `(x, y, z, intensity)`.
    pub fn into_columns(self) -> (Vec<f32>, Vec<f32>, Vec<f32>, Vec<f32>) {
        (self.x, self.y, self.z, self.intensity)
    }

    /// Iterates over the points by value.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = Point> + '_ {
        (0..self.len()).map(move |i| Point {
            x: self.x[i],
            y: self.y[i],
            z: self.z[i],
            intensity: self.intensity[i],
        })
    }

    /// Iterates over the positions as `nalgebra` points (f32).
    pub fn positions(&self) -> impl ExactSizeIterator<Item = Point3<f32>> + '_ {
        (0..self.len()).map(move |i| Point3::new(self.x[i], self.y[i], self.z[i]))
    }

    /// Axis-aligned bounding box of the finite points; `None` when there is none.
    pub fn bounds(&self) -> Option<Bounds> {
        let mut min = [f32::INFINITY; 3];
        let mut max = [f32::NEG_INFINITY; 3];
        let mut any = false;
        for i in 0..self.len() {
            let p = [self.x[i], self.y[i], self.z[i]];
            if !p.iter().all(|v| v.is_finite()) {
                continue;
            }
            any = true;
            for k in 0..3 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        }
        any.then_some(Bounds { min, max })
    }

    /// Keeps the points whose entry in `mask` is `true`, preserving their order.
    ///
    /// Fails (and leaves the cloud unchanged) when `mask` does not have one entry per point.
    pub fn retain_by_mask(&mut self, mask: &[bool]) -> Result<()> {
        if mask.len() != self.len() {
            return Err(Error::invalid(
                "point mask",
                format!("{} entries for {} points", mask.len(), self.len()),
            ));
        }
        for column in [&mut self.x, &mut self.y, &mut self.z, &mut self.intensity] {
            let mut i = 0;
            column.retain(|_| {
                let keep = mask[i];
                i += 1;
                keep
            });
        }
        Ok(())
    }

    /// Keeps the points for which `keep(point)` is true, preserving their order.
    pub fn retain(&mut self, mut keep: impl FnMut(Point) -> bool) {
        let mask: Vec<bool> = self.iter().map(&mut keep).collect();
        // The mask has one entry per point by construction.
        let _ = self.retain_by_mask(&mask);
    }

    /// Applies the rigid transform `pose` to every point in place (`p ← R p + t`).
    ///
    /// The arithmetic is done in f64 and rounded back to f32, so a transform far from the origin
    /// loses no more precision than the f32 storage itself.
    pub fn transform(&mut self, pose: &Isometry3<f64>) {
        let m = pose.to_homogeneous();
        let (r, t) = (
            m.fixed_view::<3, 3>(0, 0).into_owned(),
            m.fixed_view::<3, 1>(0, 3).into_owned(),
        );
        for i in 0..self.len() {
            let (px, py, pz) = (self.x[i] as f64, self.y[i] as f64, self.z[i] as f64);
            self.x[i] = (r[(0, 0)] * px + r[(0, 1)] * py + r[(0, 2)] * pz + t[0]) as f32;
            self.y[i] = (r[(1, 0)] * px + r[(1, 1)] * py + r[(1, 2)] * pz + t[1]) as f32;
            self.z[i] = (r[(2, 0)] * px + r[(2, 1)] * py + r[(2, 2)] * pz + t[2]) as f32;
        }
    }

    /// A transformed copy; see [`transform`](Self::transform).
    pub fn transformed(&self, pose: &Isometry3<f64>) -> PointCloud {
        let mut out = self.clone();
        out.transform(pose);
        out
    }

    /// Appends all points of `other`.
    pub fn extend_from(&mut self, other: &PointCloud) {
        self.x.extend_from_slice(&other.x);
        self.y.extend_from_slice(&other.y);
        self.z.extend_from_slice(&other.z);
        self.intensity.extend_from_slice(&other.intensity);
    }

    /// Index of the first point with a NaN or infinite coordinate or intensity.
    pub fn first_non_finite(&self) -> Option<usize> {
        (0..self.len()).find(|&i| {
            !(self.x[i].is_finite()
                && self.y[i].is_finite()
                && self.z[i].is_finite()
                && self.intensity[i].is_finite())
        })
    }
}

impl FromIterator<Point> for PointCloud {
    fn from_iter<I: IntoIterator<Item = Point>>(iter: I) -> Self {
        let mut cloud = PointCloud::new();
        for p in iter {
            cloud.push_point(p);
        }
        cloud
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion, Vector3};

    fn three() -> PointCloud {
        let mut c = PointCloud::new();
        c.push(1.0, 2.0, 3.0, 0.1);
        c.push(-1.0, 0.5, 7.0, 0.2);
        c.push(4.0, -3.0, 0.0, 0.3);
        c
    }

    #[test]
    fn push_len_get_iter() {
        let c = three();
        assert_eq!(c.len(), 3);
        assert!(!c.is_empty());
        assert_eq!(c.get(1).unwrap().z, 7.0);
        assert!(c.get(3).is_none());
        let zs: Vec<f32> = c.iter().map(|p| p.z).collect();
        assert_eq!(zs, vec![3.0, 7.0, 0.0]);
        assert!(PointCloud::new().is_empty());
    }

    #[test]
    fn bounds_cover_all_points_and_skip_nan() {
        let mut c = three();
        c.push(f32::NAN, 100.0, 0.0, 0.0);
        let b = c.bounds().unwrap();
        assert_eq!(b.min, [-1.0, -3.0, 0.0]);
        assert_eq!(b.max, [4.0, 2.0, 7.0]);
        assert_eq!(b.extent(), [5.0, 5.0, 7.0]);
        assert!(b.contains([0.0, 0.0, 1.0]));
        assert!(PointCloud::new().bounds().is_none());
    }

    #[test]
    fn retain_by_mask_keeps_order_and_checks_length() {
        let mut c = three();
        c.retain_by_mask(&[true, false, true]).unwrap();
        assert_eq!(c.xs(), &[1.0, 4.0]);
        assert_eq!(c.intensities(), &[0.1, 0.3]);
        let err = c.retain_by_mask(&[true]).unwrap_err();
        assert!(err.to_string().contains("1 entries for 2 points"), "{err}");
        assert_eq!(c.len(), 2);
        c.retain(|p| p.x > 2.0);
        assert_eq!(c.ys(), &[-3.0]);
    }

    #[test]
    fn transform_rotates_then_translates() {
        let mut c = three();
        let pose = Isometry3::from_parts(
            Translation3::new(10.0, 0.0, -1.0),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2),
        );
        c.transform(&pose);
        // (1, 2, 3) → rotated (−2, 1, 3) → translated (8, 1, 2)
        let p = c.get(0).unwrap();
        assert!((p.x - 8.0).abs() < 1e-5 && (p.y - 1.0).abs() < 1e-5 && (p.z - 2.0).abs() < 1e-5);
        assert_eq!(p.intensity, 0.1);
        let back = c.transformed(&pose.inverse());
        for (a, b) in back.iter().zip(three().iter()) {
            assert!((a.x - b.x).abs() < 1e-5 && (a.y - b.y).abs() < 1e-5);
        }
    }

    #[test]
    fn columns_must_agree() {
        assert!(PointCloud::from_columns(vec![1.0], vec![], vec![1.0], vec![1.0]).is_err());
        let c = PointCloud::from_records(&[[1.0, 2.0, 3.0, 4.0]]);
        assert_eq!(c.columns().3, &[4.0]);
        assert_eq!(c.first_non_finite(), None);
    }
}
