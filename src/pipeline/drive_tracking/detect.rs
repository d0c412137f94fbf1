//! One LiDAR frame → the detections the tracker sees: building-wall planes (from
//! [`extract_planes`]) and clusters of the points on neither the ground nor a wall, turned
//! into mixed measurements ([`crate::pipeline::drive_tracking::mixed`]).
//!
//! The ground is not tracked: it is always under the vehicle, so tracking it adds nothing a
//! per-frame fit does not give; its plane is used to drop the points near the road surface
//! before clustering. The clustering is chosen by [`ClusterMethod`]: by default the exact
//! Euclidean clustering, or the angle criterion on the scan's range image
//! ([`range_image_clusters`], linear in the points, `tolerance` the gap always joined). Every cluster within `max_range` of the sensor whose axis-aligned box is
//! object-sized (`max_footprint`, `max_height`) is a detection, nearest first: there is no cap
//! on their number, the size and range limits bound the filter's work. Before that, a face seen
//! at a grazing angle that the clustering left apart from its object is given back to it
//! ([`crate::cloud::fragments`], `merge_fragments`). Each detection then gets
//! its oriented box and class evidence ([`super::road_users::shape_of`]); its measured
//! position is the box's centre.
//!
//! Not for: the filter (see [`super::tracker`]).

use super::{ClusterMethod, TrackingConfig};
use crate::cloud::boxes::BoxScratch;
use crate::cloud::classes::ClassModel;
use crate::cloud::cluster::{euclidean_clusters_of, ClusterParams};
use crate::cloud::fragments::merge_grazing_fragments;
use crate::cloud::planes::{extract_planes, PlaneConfig};
use crate::cloud::range_image::{
    range_image_clusters, ImageClusterParams, RangeImage, RangeImageConfig,
};
use crate::cloud::PointCloud;
use crate::error::Result;
use crate::filter::Measurements;
use crate::geometry::{Plane, PlanePatch};
use crate::pipeline::drive_tracking::mixed::{
    cluster_measurement, plane_measurement, MEASUREMENT_DIM,
};
use crate::pipeline::drive_tracking::road_users::{shape_of, ClusterShape};
use crate::rng::FilterRng;
use rayon::prelude::*;
use std::time::Instant;

/// One cluster detection in the sensor frame.
#[derive(Clone, Debug, PartialEq)]
pub struct ClusterDetection {
    /// Centroid (m, sensor frame).
    pub centroid: [f64; 3],
    /// Smallest corner of the axis-aligned box (m, sensor frame).
    pub min: [f64; 3],
    /// Largest corner of the axis-aligned box (m, sensor frame).
    pub max: [f64; 3],
    /// Indices of the member points in the frame's cloud (empty for detections built by hand).
    pub indices: Vec<u32>,
    /// Oriented box and class evidence (`None` for detections built by hand without points).
    pub shape: Option<ClusterShape>,
}

impl ClusterDetection {
    /// The measured position: the centre of the box with the visible-face model when there is
    /// one, the centroid otherwise.
    pub fn position(&self) -> [f64; 3] {
        match &self.shape {
            Some(s) => [s.bbox.center.x, s.bbox.center.y, s.bbox.center.z],
            None => self.centroid,
        }
    }

    /// A detection with a box of `size` around `centroid` and no points (for benchmarks and
    /// tests that bypass the point cloud).
    pub fn around(centroid: [f64; 3], size: [f64; 3]) -> Self {
        ClusterDetection {
            centroid,
            min: std::array::from_fn(|i| centroid[i] - 0.5 * size[i]),
            max: std::array::from_fn(|i| centroid[i] + 0.5 * size[i]),
            indices: Vec::new(),
            shape: None,
        }
    }
}

/// One wall detection: its patch (sensor frame) and inlier indices.
#[derive(Clone, Debug, PartialEq)]
pub struct WallDetection {
    /// Bounding rectangle of the inliers (sensor frame).
    pub patch: PlanePatch,
    /// Indices of the inliers in the frame's cloud (empty for detections built by hand).
    pub indices: Vec<u32>,
}

/// The detections of one frame and the time each stage took.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameDetections {
    /// Building walls.
    pub walls: Vec<WallDetection>,
    /// Object clusters.
    pub clusters: Vec<ClusterDetection>,
    /// Ground inliers (not tracked; for labelled exports).
    pub ground: Vec<u32>,
    /// Milliseconds spent on plane segmentation.
    pub planes_ms: f64,
    /// Milliseconds spent on clustering.
    pub clusters_ms: f64,
}

impl FrameDetections {
    /// The mixed measurements: walls first (index `i`), then clusters (index
    /// `walls.len() + j`).
    pub fn measurements(&self) -> Result<Measurements> {
        let mut m = Measurements::empty(MEASUREMENT_DIM);
        for w in &self.walls {
            m.push(&plane_measurement(w.patch.plane.as_vector()))?;
        }
        for c in &self.clusters {
            m.push(&cluster_measurement(c.position()))?;
        }
        Ok(m)
    }
}

/// Segments walls and clusters in `cloud` (sensor frame).
pub fn detect_objects(
    cloud: &PointCloud,
    config: &TrackingConfig,
    rng: &mut FilterRng,
) -> Result<FrameDetections> {
    // The whole detection runs on one of rayon's threads: entered from outside the pool,
    // each of its many small parallel parts would hand its work to the pool and wait for it
    // (a thread wake-up each time); from inside, they start at once.
    rayon::scope(|_| detect_here(cloud, config, rng))
}

pub(super) fn detect_here(
    cloud: &PointCloud,
    config: &TrackingConfig,
    rng: &mut FilterRng,
) -> Result<FrameDetections> {
    segment_here(cloud, config, rng)?.finish(cloud, config)
}

/// A frame's walls and clusters before the clusters' boxes and classes: what
/// [`segment_here`] hands on, completed by [`Segmented::finish`]. The tracking loop finishes
/// a frame on the filter's side, just before the update that needs it, so that the
/// segmentation's side is shorter.
pub(super) struct Segmented {
    detections: FrameDetections,
    ground: Option<Plane>,
}

impl Segmented {
    /// The segmentation's times so far: (planes, clusters) in milliseconds.
    pub(super) fn times(&self) -> (f64, f64) {
        (self.detections.planes_ms, self.detections.clusters_ms)
    }

    /// Every cluster's oriented box and class evidence ([`shape_of`]), in parallel; their
    /// time is added to `clusters_ms`.
    pub(super) fn finish(
        self,
        cloud: &PointCloud,
        config: &TrackingConfig,
    ) -> Result<FrameDetections> {
        let start = Instant::now();
        let Segmented {
            mut detections,
            ground,
        } = self;
        let c = &config.clusters;
        let ground_z = |x: f64, y: f64| -> Option<f64> {
            let g = ground.as_ref()?;
            (g.normal.z.abs() > 0.5)
                .then(|| -(g.normal.x * x + g.normal.y * y + g.offset) / g.normal.z)
        };
        let model = ClassModel::default();
        detections.clusters.par_iter_mut().try_for_each_init(
            BoxScratch::default,
            |scratch, d| -> Result<()> {
                let z0 = ground_z(d.centroid[0], d.centroid[1]).or(Some(-c.sensor_height));
                d.shape = Some(shape_of(cloud, &d.indices, z0, &model, scratch)?);
                Ok(())
            },
        )?;
        detections.clusters_ms += start.elapsed().as_secs_f64() * 1e3;
        Ok(detections)
    }
}

/// The walls and clusters of a frame without the clusters' shapes (see [`Segmented`]).
pub(super) fn segment_here(
    cloud: &PointCloud,
    config: &TrackingConfig,
    rng: &mut FilterRng,
) -> Result<Segmented> {
    let start = Instant::now();
    // The tracker uses the ground's plane and inliers, never its rectangle.
    let planes = PlaneConfig {
        ground_outline: false,
        ..config.planes.clone()
    };
    let seg = extract_planes(cloud, &planes, rng)?;
    let planes_ms = start.elapsed().as_secs_f64() * 1e3;

    let start = Instant::now();
    let c = &config.clusters;
    let (xs, ys, zs) = (cloud.xs(), cloud.ys(), cloud.zs());
    // Height above the ground plane (or above a flat road at the nominal mounting height).
    let ground = seg.ground.as_ref().map(|g| g.patch.plane);
    let above = |i: usize| -> f64 {
        let p = nalgebra::Point3::new(xs[i] as f64, ys[i] as f64, zs[i] as f64);
        match &ground {
            Some(plane) => {
                let h = plane.signed_distance(&p);
                // The canonical normal points towards the sensor, i.e. up.
                if plane.normal.z < 0.0 {
                    -h
                } else {
                    h
                }
            }
            None => p.z + c.sensor_height,
        }
    };
    let max_r2 = c.max_range * c.max_range;
    let candidates: Vec<u32> = seg
        .remaining
        .iter()
        .copied()
        .filter(|&i| {
            let i = i as usize;
            let r2 = (xs[i] * xs[i] + ys[i] * ys[i]) as f64;
            r2 <= max_r2 && above(i) > c.ground_clearance
        })
        .collect();
    let found = match c.method {
        ClusterMethod::Euclidean => {
            let params = ClusterParams {
                tolerance: c.tolerance as f32,
                min_points: c.min_points,
                max_points: c.max_points,
            };
            euclidean_clusters_of(cloud, &candidates, &params)?
        }
        ClusterMethod::RangeImage if candidates.is_empty() => Vec::new(),
        ClusterMethod::RangeImage => {
            let image = RangeImage::new(cloud, &RangeImageConfig::default())?;
            let params = ImageClusterParams {
                min_angle: c.min_angle_deg.to_radians(),
                reach: c.reach,
                near_distance: c.tolerance,
                max_distance: 2.0 * c.tolerance,
                min_points: c.min_points,
                max_points: c.max_points,
                ..ImageClusterParams::default()
            };
            range_image_clusters(&image, cloud, &candidates, &params)?
        }
    };
    let found = if c.merge_fragments {
        merge_grazing_fragments(cloud, found, &c.fragments)?
    } else {
        found
    };
    let mut clusters: Vec<ClusterDetection> = found
        .into_iter()
        .filter(|k| {
            let size: [f64; 3] = std::array::from_fn(|a| (k.max[a] - k.min[a]) as f64);
            size[0].max(size[1]) <= c.max_footprint && size[2] <= c.max_height
        })
        .map(|k| ClusterDetection {
            centroid: k.centroid,
            min: k.min.map(f64::from),
            max: k.max.map(f64::from),
            indices: k.indices,
            shape: None,
        })
        .collect();
    let range = |d: &ClusterDetection| d.centroid[0].hypot(d.centroid[1]);
    clusters.sort_by(|a, b| range(a).total_cmp(&range(b)));
    let clusters_ms = start.elapsed().as_secs_f64() * 1e3;

    let detections = FrameDetections {
        walls: seg
            .walls
            .into_iter()
            .map(|w| WallDetection {
                patch: w.patch,
                indices: w.inliers,
            })
            .collect(),
        clusters,
        ground: seg.ground.map(|g| g.inliers).unwrap_or_default(),
        planes_ms,
        clusters_ms,
    };
    Ok(Segmented { detections, ground })
}
