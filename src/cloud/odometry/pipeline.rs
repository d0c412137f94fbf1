//! [`LidarOdometry`]: the per-frame pipeline of KISS-ICP — preprocess, voxelize, threshold,
//! align, update — with a point-to-plane refinement after the alignment, and
//! [`odometry_of_files`], which runs it over a list of `.bin` scans.

use super::config::OdometryConfig;
use super::downsample::{crop_range, voxel_downsample};
use super::refine::{refine_point_to_plane, RefineParams};
use super::registration::{align_points_to_map, IcpParams};
use super::se3::renormalized;
use super::threshold::AdaptiveThreshold;
use super::voxel_map::VoxelHashMap;
use crate::cloud::{is_pcd, read_scan_with, NonFinite, PointCloud};
use crate::error::{Error, Result};
use nalgebra::{Isometry3, Matrix3};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What registering one scan produced.
#[derive(Clone, Debug, PartialEq)]
pub struct Registered {
    /// Pose of the scan in the frame of the first scan (scan → first scan).
    pub pose: Isometry3<f64>,
    /// The correspondence threshold σ used, metres (pairs within 3σ count).
    pub threshold: f64,
    /// Points used for registration (after the coarse downsampling).
    pub source_points: usize,
    /// Gauss–Newton iterations run.
    pub iterations: usize,
    /// Correspondences in the last iteration.
    pub correspondences: usize,
    /// Why the constant-velocity prediction was kept instead of the registration, if it was.
    pub fallback: Option<Fallback>,
    /// Smallest over largest eigenvalue of the refinement's translational information (1 for
    /// a scene that constrains every direction alike, 0 for a corridor); `None` without the
    /// refinement.
    pub information_ratio: Option<f64>,
}

/// Why a scan's registration was not trusted. The scan's pose is then the constant-velocity
/// prediction (the last motion repeated), the map is updated at that pose, and the motion
/// model keeps its velocity.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Fallback {
    /// Fewer correspondences than [`OdometryConfig::min_correspondences`].
    TooFewPoints,
    /// A direction no plane constrains ([`OdometryConfig::min_information_ratio`]).
    Degenerate,
    /// The registration moved the scan farther from the prediction than
    /// [`OdometryConfig::max_correction`] / [`OdometryConfig::max_correction_angle`].
    Jump,
}

impl Fallback {
    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Fallback::TooFewPoints => "too few points",
            Fallback::Degenerate => "degenerate geometry",
            Fallback::Jump => "jump",
        }
    }
}

/// Lidar odometry by scan-to-map registration (KISS-ICP, Vizzo et al., RA-L 2023), refined
/// point-to-plane against the local map's planes (see [`super::refine`]).
///
/// Feed the scans in order to [`register`](Self::register); the first scan gets the identity
/// pose and defines the map frame. Scans are not deskewed: KITTI `.bin` files carry no
/// per-point time, and at KITTI's speeds the paper's deskewing changes little.
#[derive(Clone, Debug)]
pub struct LidarOdometry {
    config: OdometryConfig,
    map: VoxelHashMap,
    threshold: AdaptiveThreshold,
    last_pose: Isometry3<f64>,
    last_delta: Isometry3<f64>,
    poses: Vec<Isometry3<f64>>,
    fallbacks: BTreeMap<Fallback, usize>,
}

impl LidarOdometry {
    /// A pipeline with an empty map; errors name an invalid configuration field.
    pub fn new(config: OdometryConfig) -> Result<Self> {
        config.validate()?;
        Ok(LidarOdometry {
            map: VoxelHashMap::new(
                config.voxel_size,
                config.max_range,
                config.max_points_per_voxel,
            ),
            threshold: AdaptiveThreshold::new(
                config.initial_threshold,
                config.min_motion,
                config.max_range,
            ),
            config,
            last_pose: Isometry3::identity(),
            last_delta: Isometry3::identity(),
            poses: Vec::new(),
            fallbacks: BTreeMap::new(),
        })
    }

    /// Registers the next scan and returns its pose.
    ///
    /// Errors: the scan has no finite point between `min_range` and `max_range`.
    pub fn register(&mut self, cloud: &PointCloud) -> Result<Registered> {
        self.register_after(cloud, 1)
    }

    /// Registers a scan taken `steps` frame periods after the last one: more than one when
    /// the scans between them were dropped (KITTI's drive 0009 lacks four). The
    /// constant-velocity prediction repeats the last frame's motion `steps` times, and the
    /// motion kept for the next scan is one of `steps` equal steps that make the registered
    /// one (its `steps`-th root: the rotation angle divided by `steps` about the same axis,
    /// the translation that the steps add up to). `steps` 0 counts as 1.
    pub fn register_after(&mut self, cloud: &PointCloud, steps: usize) -> Result<Registered> {
        // On one of rayon's threads: each ICP iteration's parallel pass then starts without
        // handing its work to the pool and waiting for it.
        rayon::scope(|_| self.register_here(cloud, steps.max(1)))
    }

    fn register_here(&mut self, cloud: &PointCloud, steps: usize) -> Result<Registered> {
        let c = &self.config;
        // Preprocess: range crop (Sec. III-A; no deskewing, see the type's docs).
        let frame = crop_range(cloud, c.min_range, c.max_range);
        if frame.is_empty() {
            return Err(Error::invalid(
                format!("scan {}", self.poses.len()),
                format!(
                    "no finite point between {} m and {} m of the sensor ({} points in all)",
                    c.min_range,
                    c.max_range,
                    cloud.len()
                ),
            ));
        }
        // Voxelize: the map keeps a fine sampling, registration a coarse one (Sec. III-B).
        let frame_down = voxel_downsample(&frame, 0.5 * c.voxel_size);
        let source = voxel_downsample(&frame_down, 1.5 * c.voxel_size);
        // Threshold (Sec. III-C, eq. 6).
        let sigma = c
            .fixed_threshold
            .unwrap_or_else(|| self.threshold.threshold());
        // Constant-velocity prediction (Sec. III-A) and alignment (Sec. III-D).
        let motion = (1..steps).fold(self.last_delta, |m, _| m * self.last_delta);
        let initial = renormalized(&(self.last_pose * motion));
        let refine = c.refine_iterations > 0 && c.refine_passes > 0;
        let params = IcpParams {
            max_correspondence: 3.0 * sigma,
            kernel: sigma / 3.0,
            max_iterations: c.max_iterations,
            convergence: if refine {
                c.convergence.max(c.refine_coarse_convergence)
            } else {
                c.convergence
            },
        };
        let aligned = align_points_to_map(&source, &self.map, &initial, &params);
        let (registered, correspondences, information) = if refine {
            let fine = RefineParams {
                scale: c.refine_scale,
                thickness: c.refine_thickness,
                radius: c.refine_radius.min(c.voxel_size),
                passes: c.refine_passes,
                max_iterations: c.refine_iterations,
                convergence: 1e-6,
            };
            let r = refine_point_to_plane(&frame_down, &self.map, &aligned.pose, &fine);
            // Without planes (an empty map, the first scan) the coarse alignment stands.
            let n = if r.iterations > 0 {
                r.correspondences
            } else {
                aligned.correspondences
            };
            (r.pose, n, r.translation_information)
        } else {
            (aligned.pose, aligned.correspondences, None)
        };
        let information_ratio = information.map(|m| eigen_ratio(&m));
        // The first scan has no map to register against: it is the origin, never a fallback.
        let fallback = if self.map.is_empty() {
            None
        } else {
            self.fallback(&initial, &registered, correspondences, information_ratio)
        };
        let pose = if fallback.is_some() {
            initial
        } else {
            registered
        };
        // Update: threshold from the model deviation, map, velocity, pose.
        self.threshold.update(&(initial.inverse() * pose));
        self.map.update(&frame_down, &pose);
        let moved = self.last_pose.inverse() * pose;
        self.last_delta = renormalized(&if steps == 1 {
            moved
        } else {
            one_step_of(&moved, steps)
        });
        self.last_pose = pose;
        self.poses.push(pose);
        if let Some(f) = fallback {
            *self.fallbacks.entry(f).or_insert(0) += 1;
        }
        Ok(Registered {
            pose,
            threshold: sigma,
            source_points: source.len(),
            iterations: aligned.iterations,
            correspondences: aligned.correspondences,
            fallback,
            information_ratio,
        })
    }

    /// Whether the registration `registered` of a scan predicted at `initial` is untrusted,
    /// and why (checked in the order too few points, degenerate, jump).
    fn fallback(
        &self,
        initial: &Isometry3<f64>,
        registered: &Isometry3<f64>,
        correspondences: usize,
        information_ratio: Option<f64>,
    ) -> Option<Fallback> {
        let c = &self.config;
        if correspondences < c.min_correspondences {
            return Some(Fallback::TooFewPoints);
        }
        if information_ratio.is_some_and(|r| r < c.min_information_ratio) {
            return Some(Fallback::Degenerate);
        }
        let correction = initial.inverse() * registered;
        if correction.translation.vector.norm() > c.max_correction
            || correction.rotation.angle() > c.max_correction_angle
        {
            return Some(Fallback::Jump);
        }
        None
    }

    /// How many scans fell back to the constant-velocity prediction, by reason.
    pub fn fallbacks(&self) -> &BTreeMap<Fallback, usize> {
        &self.fallbacks
    }

    /// The poses of all scans registered so far (scan → first scan).
    pub fn poses(&self) -> &[Isometry3<f64>] {
        &self.poses
    }

    /// The local map.
    pub fn map(&self) -> &VoxelHashMap {
        &self.map
    }

    /// The configuration.
    pub fn config(&self) -> &OdometryConfig {
        &self.config
    }
}

/// The motion of one of `steps` equal steps that together make `motion`: the rotation of
/// angle / `steps` about the same axis, and the translation t_s that the steps add up to the
/// whole one, Σ_{i<n} R_sⁱ t_s = t (t / `steps` if that sum cannot be inverted).
fn one_step_of(motion: &Isometry3<f64>, steps: usize) -> Isometry3<f64> {
    let n = steps as f64;
    let rotation = nalgebra::UnitQuaternion::from_scaled_axis(motion.rotation.scaled_axis() / n);
    let r = rotation.to_rotation_matrix().into_inner();
    let (mut sum, mut power) = (Matrix3::zeros(), Matrix3::identity());
    for _ in 0..steps {
        sum += power;
        power *= r;
    }
    let t = motion.translation.vector;
    let step = sum.try_inverse().map_or(t / n, |inv| inv * t);
    Isometry3::from_parts(step.into(), rotation)
}

/// Runs the odometry over the scans `paths` in order and returns one pose per scan;
/// `on_scan(k)` is called after scan k. Files ending in `.pcd` (any case) are read as PCD,
/// leaving out points with NaN or infinite values (the invalid points of an organised cloud);
/// every other file as a KITTI `.bin` scan.
///
/// Errors: no scans at all, a scan that cannot be read, or a scan with no point in range —
/// each naming the file.
pub fn odometry_of_files(
    paths: &[PathBuf],
    config: &OdometryConfig,
    on_scan: impl FnMut(usize, &Registered),
) -> Result<Vec<Isometry3<f64>>> {
    let frames: Vec<usize> = (0..paths.len()).collect();
    odometry_of_files_at(paths, &frames, config, on_scan)
}

/// [`odometry_of_files`] for scans taken at the frame numbers `frames` (ascending, one per
/// path): where scans were dropped between two of them, the second is registered after the
/// longer step ([`LidarOdometry::register_after`]). Errors as [`odometry_of_files`], and
/// `frames` that do not match `paths` or do not increase.
pub fn odometry_of_files_at(
    paths: &[PathBuf],
    frames: &[usize],
    config: &OdometryConfig,
    on_scan: impl FnMut(usize, &Registered),
) -> Result<Vec<Isometry3<f64>>> {
    if paths.is_empty() {
        return Err(Error::invalid("odometry scans", "no scans given"));
    }
    if frames.len() != paths.len() || frames.windows(2).any(|w| w[1] <= w[0]) {
        return Err(Error::invalid(
            "odometry frame numbers",
            format!(
                "{} increasing numbers needed, one per scan, got {}",
                paths.len(),
                frames.len()
            ),
        ));
    }
    odometry_of_scans_at(
        frames,
        &|i| read_scan(&paths[i]),
        &|i| paths[i].display().to_string(),
        config,
        on_scan,
    )
}

/// The odometry over scans read by `load(i)`, the i-th taken at frame number `frames[i]`
/// (ascending; a gap is registered over the longer step, [`LidarOdometry::register_after`]),
/// and one pose per scan; `name(i)` names scan i in errors (its file, say); `on_scan(i)` is
/// called after scan i. What [`odometry_of_files_at`] does for files, for any recording.
/// Errors: no scans, `frames` that do not increase, an error of `load`, a scan with no point
/// in range (named).
pub fn odometry_of_scans_at(
    frames: &[usize],
    load: &dyn Fn(usize) -> Result<PointCloud>,
    name: &dyn Fn(usize) -> String,
    config: &OdometryConfig,
    mut on_scan: impl FnMut(usize, &Registered),
) -> Result<Vec<Isometry3<f64>>> {
    if frames.is_empty() {
        return Err(Error::invalid("odometry scans", "no scans given"));
    }
    if frames.windows(2).any(|w| w[1] <= w[0]) {
        return Err(Error::invalid(
            "odometry frame numbers",
            "must increase from scan to scan",
        ));
    }
    let mut odometry = LidarOdometry::new(config.clone())?;
    for (i, &frame) in frames.iter().enumerate() {
        let cloud = load(i)?;
        let steps = if i == 0 { 1 } else { frame - frames[i - 1] };
        let registered = odometry
            .register_after(&cloud, steps)
            .map_err(|e| named(&name(i), e))?;
        on_scan(i, &registered);
    }
    Ok(odometry.poses.clone())
}

/// Runs the odometry over frames `0..count` given by `load` (e.g. a drive's Velodyne
/// scans) and returns one pose per frame (scan → first scan). Errors from `load` pass
/// through; a scan with no point in range is an error naming its frame number.
pub fn odometry_of_frames(
    count: usize,
    load: &dyn Fn(usize) -> Result<PointCloud>,
    config: &OdometryConfig,
) -> Result<Vec<Isometry3<f64>>> {
    odometry_of_frames_with(count, &|_| true, load, config)
}

/// [`odometry_of_frames`] for a recording whose frames without a scan (`has_scan` false:
/// KITTI drops one now and then) are not loaded: the scan after them is registered over the
/// longer step ([`LidarOdometry::register_after`]), and each of them gets the pose of equal
/// steps between the scans around it. Frames after the last scan keep its pose. Errors as
/// [`odometry_of_frames`], and no scan among the frames.
pub fn odometry_of_frames_with(
    count: usize,
    has_scan: &dyn Fn(usize) -> bool,
    load: &dyn Fn(usize) -> Result<PointCloud>,
    config: &OdometryConfig,
) -> Result<Vec<Isometry3<f64>>> {
    let scans: Vec<usize> = (0..count).filter(|&k| has_scan(k)).collect();
    if scans.is_empty() {
        return Err(Error::invalid("odometry scans", "no scans given"));
    }
    let mut odometry = LidarOdometry::new(config.clone())?;
    // Frames before the first scan take its pose (the identity).
    let mut poses = vec![Isometry3::identity(); count];
    let mut last: Option<(usize, Isometry3<f64>)> = None;
    for &k in &scans {
        let steps = last.map_or(1, |(l, _)| k - l);
        let pose = odometry.register_after(&load(k)?, steps)?.pose;
        if let Some((l, before)) = last {
            let step = one_step_of(&(before.inverse() * pose), steps);
            let mut p = before;
            for between in poses.iter_mut().take(k).skip(l + 1) {
                p *= step;
                *between = p;
            }
        }
        poses[k] = pose;
        last = Some((k, pose));
    }
    if let Some((l, pose)) = last {
        for after in poses.iter_mut().skip(l + 1) {
            *after = pose;
        }
    }
    Ok(poses)
}

/// Reads one scan by its extension: `.pcd` without its non-finite points (an organised
/// cloud's invalid points), else `.bin`.
fn read_scan(path: &Path) -> Result<PointCloud> {
    let policy = if is_pcd(path) {
        NonFinite::Skip
    } else {
        NonFinite::Error
    };
    Ok(read_scan_with(path, policy)?.cloud)
}

fn named(scan: &str, e: Error) -> Error {
    match e {
        Error::InvalidInput { reason, .. } => Error::invalid(format!("scan {scan}"), reason),
        other => other,
    }
}

/// Smallest over largest eigenvalue of a symmetric positive semi-definite matrix (0 when it
/// is zero).
fn eigen_ratio(m: &Matrix3<f64>) -> f64 {
    let e = m.symmetric_eigenvalues();
    let (lo, hi) = e.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &v| {
        (lo.min(v), hi.max(v))
    });
    if hi > 0.0 {
        (lo / hi).max(0.0)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_step_of_a_screw_motion_repeats_into_it() {
        // A turn of 0.3 rad about z with a translation along z: exact.
        let screw = Isometry3::new(
            nalgebra::Vector3::new(0.0, 0.0, 3.0),
            nalgebra::Vector3::new(0.0, 0.0, 0.3),
        );
        let step = one_step_of(&screw, 3);
        let back = step * step * step;
        assert!((back.to_homogeneous() - screw.to_homogeneous()).abs().max() < 1e-12);
        // A vehicle's 3 m with a 0.03 rad turn (translation across the axis): exact too.
        let drive = Isometry3::new(
            nalgebra::Vector3::new(3.0, 0.05, 0.0),
            nalgebra::Vector3::new(0.0, 0.0, 0.03),
        );
        let step = one_step_of(&drive, 3);
        let back = step * step * step;
        assert!((back.to_homogeneous() - drive.to_homogeneous()).abs().max() < 1e-12);
        // No motion stays none.
        let still = one_step_of(&Isometry3::identity(), 4);
        assert_eq!(
            still.to_homogeneous(),
            Isometry3::identity().to_homogeneous()
        );
    }

    use crate::cloud::odometry::test_scene::yard;
    use nalgebra::{Point3, Vector3};

    fn seen_from(world: &[Vector3<f64>], pose: &Isometry3<f64>) -> PointCloud {
        let inv = pose.inverse();
        let mut c = PointCloud::with_capacity(world.len());
        for p in world {
            let q = inv * Point3::from(*p);
            c.push(q.x as f32, q.y as f32, q.z as f32, 0.0);
        }
        c
    }

    #[test]
    fn follows_a_synthetic_drive_through_the_yard() {
        // 0.4 m and 0.6° a frame, a slow left bend like KITTI drive 0005.
        let step = Isometry3::new(Vector3::new(0.4, 0.02, 0.0), Vector3::new(0.0, 0.0, 0.0105));
        let mut truth = vec![Isometry3::identity()];
        for _ in 0..7 {
            truth.push(truth.last().unwrap() * step);
        }
        let config = OdometryConfig {
            voxel_size: 0.5,
            ..OdometryConfig::default()
        };
        let mut odo = LidarOdometry::new(config).unwrap();
        let mut previous = Isometry3::identity();
        for (k, t) in truth.iter().enumerate() {
            // Every frame sees its own sampling of the yard.
            let world = yard(0.1, k as u64);
            let r = odo.register(&seen_from(&world, t)).unwrap();
            assert_eq!(r.fallback, None, "frame {k}: {r:?}");
            let pose = r.pose;
            // Each frame-to-frame motion to < 1 cm / 0.05°, the drift after 7 frames below
            // 3 cm / 0.15°.
            let step_err =
                (truth[k.saturating_sub(1)].inverse() * t).inverse() * (previous.inverse() * pose);
            assert!(
                step_err.translation.vector.norm() < 0.01,
                "frame {k}: {step_err:?}"
            );
            assert!(
                step_err.rotation.angle().to_degrees() < 0.05,
                "frame {k}: {step_err:?}"
            );
            let err = t.inverse() * pose;
            assert!(err.translation.vector.norm() < 0.03, "frame {k}: {err:?}");
            assert!(
                err.rotation.angle().to_degrees() < 0.15,
                "frame {k}: {err:?}"
            );
            previous = pose;
        }
    }

    #[test]
    fn frames_without_a_scan_get_poses_between_their_neighbours() {
        // The yard's slow bend at 0.6 m a frame; frames 2 to 4 have no scan.
        let step = Isometry3::new(Vector3::new(0.6, 0.03, 0.0), Vector3::new(0.0, 0.0, 0.0105));
        let mut truth = vec![Isometry3::identity()];
        for _ in 0..6 {
            truth.push(truth.last().unwrap() * step);
        }
        let config = OdometryConfig {
            voxel_size: 0.5,
            max_correction: 1.0,
            ..OdometryConfig::default()
        };
        let dropped = |k: usize| (2..=4).contains(&k);
        let load = |k: usize| -> Result<PointCloud> {
            assert!(!dropped(k), "frame {k} has no scan");
            Ok(seen_from(&yard(0.1, k as u64), &truth[k]))
        };
        let poses = odometry_of_frames_with(7, &|k| !dropped(k), &load, &config).unwrap();
        assert_eq!(poses.len(), 7);
        for (k, (p, t)) in poses.iter().zip(&truth).enumerate() {
            let err = t.inverse() * p;
            assert!(err.translation.vector.norm() < 0.05, "frame {k}: {err:?}");
            assert!(
                err.rotation.angle().to_degrees() < 0.2,
                "frame {k}: {err:?}"
            );
        }
        // Registered as the next frame, the scan after the gap starts from a guess 1.8 m
        // short: beyond the correction bound, a jump, and its pose stays the guess.
        let mut odo = LidarOdometry::new(config).unwrap();
        for k in [0, 1, 5] {
            let r = odo.register(&load(k).unwrap()).unwrap();
            if k == 5 {
                assert_eq!(r.fallback, Some(Fallback::Jump), "{r:?}");
            }
        }
    }

    #[test]
    fn poses_do_not_depend_on_the_number_of_threads() {
        let step = Isometry3::new(Vector3::new(0.4, 0.02, 0.0), Vector3::new(0.0, 0.0, 0.0105));
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut odo = LidarOdometry::new(OdometryConfig {
                    voxel_size: 0.5,
                    ..OdometryConfig::default()
                })
                .unwrap();
                let mut truth = Isometry3::identity();
                for k in 0..3 {
                    odo.register(&seen_from(&yard(0.1, k), &truth)).unwrap();
                    truth *= step;
                }
                odo.poses().to_vec()
            })
        };
        assert_eq!(run(1), run(3));
    }

    /// An endless corridor along x (walls y = ±2 m, floor −1.5 m, ceiling 2.5 m; no end
    /// walls), about one point per `spacing`² of surface, sampled by `seed`.
    fn corridor(spacing: f64, seed: u64) -> Vec<Vector3<f64>> {
        use rand::RngExt;
        let mut rng = crate::rng::seeded(seed);
        let n = (120.0 * 4.0 / (spacing * spacing)) as usize;
        let mut out = Vec::with_capacity(4 * n);
        for face in 0..4 {
            for _ in 0..n {
                let x = rng.random_range(-60.0..60.0);
                let t: f64 = rng.random_range(0.0..4.0);
                out.push(match face {
                    0 => Vector3::new(x, -2.0, -1.5 + t),
                    1 => Vector3::new(x, 2.0, -1.5 + t),
                    2 => Vector3::new(x, -2.0 + t, -1.5),
                    _ => Vector3::new(x, -2.0 + t, 2.5),
                });
            }
        }
        out
    }

    #[test]
    fn a_featureless_corridor_keeps_the_constant_velocity_pose() {
        // The sensor moves 0.5 m a frame along the corridor, which no scan can show: every
        // scan after the first is degenerate along x and keeps the prediction (here the
        // origin, as nothing has moved yet), instead of whatever ICP slid to.
        let config = OdometryConfig {
            voxel_size: 0.5,
            ..OdometryConfig::default()
        };
        let mut odo = LidarOdometry::new(config).unwrap();
        for k in 0..5u64 {
            let truth = Isometry3::translation(0.5 * k as f64, 0.0, 0.0);
            let r = odo.register(&seen_from(&corridor(0.2, k), &truth)).unwrap();
            if k == 0 {
                assert_eq!(r.fallback, None);
                continue;
            }
            assert_eq!(r.fallback, Some(Fallback::Degenerate), "scan {k}: {r:?}");
            assert!(r.information_ratio.unwrap() < 1e-3, "scan {k}: {r:?}");
            assert_eq!(r.pose, Isometry3::identity(), "scan {k}");
        }
        assert_eq!(odo.fallbacks().get(&Fallback::Degenerate), Some(&4));
        assert_eq!(odo.fallbacks().len(), 1);
    }

    #[test]
    fn a_scan_with_too_few_points_keeps_the_prediction() {
        let mut odo = LidarOdometry::new(OdometryConfig {
            voxel_size: 0.5,
            ..OdometryConfig::default()
        })
        .unwrap();
        let step = Isometry3::translation(0.4, 0.0, 0.0);
        odo.register(&seen_from(&yard(0.1, 0), &Isometry3::identity()))
            .unwrap();
        let second = odo.register(&seen_from(&yard(0.1, 1), &step)).unwrap();
        assert_eq!(second.fallback, None);
        // Twenty points of one wall: far below 50 correspondences.
        let few: Vec<Vector3<f64>> = yard(0.1, 2)
            .into_iter()
            .filter(|p| (p.x - 20.0).abs() < 1e-9)
            .take(20)
            .collect();
        assert_eq!(few.len(), 20);
        let third = odo.register(&seen_from(&few, &(step * step))).unwrap();
        assert_eq!(third.fallback, Some(Fallback::TooFewPoints), "{third:?}");
        // The prediction: the second pose moved on by the same motion once more.
        let predicted = renormalized(&(second.pose * second.pose));
        assert_eq!(third.pose, predicted);
        assert_eq!(odo.fallbacks().get(&Fallback::TooFewPoints), Some(&1));
    }

    #[test]
    fn a_correction_beyond_the_bound_is_a_jump_that_keeps_the_prediction() {
        // A 0.4 m motion from standstill is a correction of 0.4 m to the prediction.
        let second = |max_correction: f64| {
            let mut odo = LidarOdometry::new(OdometryConfig {
                voxel_size: 0.5,
                max_correction,
                ..OdometryConfig::default()
            })
            .unwrap();
            odo.register(&seen_from(&yard(0.1, 0), &Isometry3::identity()))
                .unwrap();
            odo.register(&seen_from(
                &yard(0.1, 1),
                &Isometry3::translation(0.4, 0.0, 0.0),
            ))
            .unwrap()
        };
        // With the bound at 5 cm it is refused and the prediction kept …
        let r = second(0.05);
        assert_eq!(r.fallback, Some(Fallback::Jump), "{r:?}");
        assert_eq!(r.pose, Isometry3::identity());
        // … with the default bound it is taken.
        let r = second(OdometryConfig::default().max_correction);
        assert_eq!(r.fallback, None);
        assert!((r.pose.translation.vector.x - 0.4).abs() < 0.01, "{r:?}");
    }

    #[test]
    fn an_empty_scan_is_an_error_naming_the_scan() {
        let mut odo = LidarOdometry::new(OdometryConfig::default()).unwrap();
        let e = odo.register(&PointCloud::new()).unwrap_err().to_string();
        assert!(e.contains("scan 0") && e.contains("no finite point"), "{e}");
    }

    #[test]
    fn an_empty_list_and_an_empty_file_are_errors() {
        let e = odometry_of_files(&[], &OdometryConfig::default(), |_, _| {}).unwrap_err();
        assert!(e.to_string().contains("no scans"), "{e}");
        let dir = std::env::temp_dir().join(format!("odometry-empty-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("0000000000.bin");
        std::fs::write(&f, b"").unwrap();
        let e = odometry_of_files(
            std::slice::from_ref(&f),
            &OdometryConfig::default(),
            |_, _| {},
        )
        .unwrap_err()
        .to_string();
        let _ = std::fs::remove_dir_all(&dir);
        assert!(e.contains("0000000000.bin"), "{e}");
    }
}
