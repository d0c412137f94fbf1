//! Multi-plane segmentation of a LiDAR point cloud: the ground plane and building-scale
//! vertical walls, as [`PlanePatch`]es with their inlier indices.
//!
//! # Method
//! Sequential RANSAC. Each round works on the points not yet assigned to a plane:
//! 1. a random subsample (`PlaneConfig::score_sample` points) is drawn with the caller's
//!    seeded [`FilterRng`]; plane hypotheses are spanned by point triples drawn by index from
//!    it, the second and third point from the same cell of a coarse voxel grid as the first
//!    (`PlaneConfig::sample_cell`), which makes triples on small walls likely;
//! 2. each hypothesis is scored by the number of subsample points within
//!    `PlaneConfig::score_threshold`; the best one (ties: the earliest drawn) wins;
//! 3. the inlier threshold of the winner is set by an MSSE scale estimate (Bab-Hadiashar &
//!    Suter 1999) from the sorted absolute residuals of all remaining points: with
//!    `σ_k² = Σ_{i≤k} r_i² / (k − 3)`, k grows from the count of residuals below
//!    `min_threshold` until the next residual exceeds `T·σ_k` (`T = msse_t`); the threshold is
//!    `T·σ_k`, clamped to `[min_threshold, max_threshold]`;
//! 4. least-squares refit on the inliers, a second MSSE/inlier pass with the refitted plane,
//!    and a final refit;
//! 5. the inliers leave the pool. Rounds stop when fewer than `min_points` inliers are found
//!    or `max_planes` rounds have run.
//!
//! Once a near-horizontal plane below the sensor has been extracted, later rounds look for
//! walls only: hypotheses are drawn from points more than `ground_clearance` above that plane
//! and only those within `max_wall_tilt` of vertical are kept (a real road is not one flat
//! plane, and its residual slabs would otherwise win every round). Points near the ground stay
//! available as inliers of later planes.
//!
//! Each extracted plane is then classified. Near-horizontal planes below the sensor are
//! ground candidates (the one with most inliers becomes the ground and is not split). Other
//! planes are split into spatially connected pieces (flood fill on a 2-D grid of
//! `PlaneConfig::grid_cell` in the plane's own coordinates, 8-connectivity), each piece is
//! refitted and kept as a wall when its normal is within `max_wall_tilt` of horizontal and its
//! patch is building-scale (`min_wall_area`, `min_wall_length`, `min_wall_height`). Everything
//! else is reported in [`PlaneSegmentation::rejected`] with a [`RejectReason`].
//!
//! # Determinism
//! Results depend only on the cloud, the configuration and the RNG state, never on the
//! number of rayon threads: hypotheses are drawn sequentially, scored in parallel into an
//! ordered vector, and sums over points are accumulated per fixed-size chunk and combined in
//! chunk order.
//!
//! # Non-finite points
//! Points with a NaN or infinite coordinate are skipped: they appear in no output list
//! (neither inliers nor `remaining`); their number is [`PlaneSegmentation::skipped`].
//!
//! Not for: clustering objects (cars, poles) or tracking planes over time.

use crate::cloud::PointCloud;
use crate::error::{Error, Result};
use crate::geometry::{Plane, PlanePatch};
use crate::rng::FilterRng;
use nalgebra::{Matrix3, Point3, Vector3};
use rand::RngExt;
use rayon::prelude::*;
use std::collections::HashMap;

/// Number of points per chunk for parallel passes over points. Fixed, so that sums are
/// combined in the same order for every thread count.
const CHUNK: usize = 4096;

/// Parameters of [`extract_planes`]. Lengths in metres, areas in m², angles in radians.
#[derive(Clone, Debug, PartialEq)]
pub struct PlaneConfig {
    /// Maximum number of RANSAC rounds (planes extracted, accepted or not).
    pub max_planes: usize,
    /// Minimum number of inliers of a plane and of a connected piece of a wall.
    pub min_points: usize,
    /// Hypotheses drawn per round.
    pub hypotheses: usize,
    /// Size of the random subsample on which hypotheses are drawn and scored.
    pub score_sample: usize,
    /// Edge of the voxel grid used to draw the 2nd and 3rd point of a triple near the 1st (m).
    pub sample_cell: f64,
    /// Distance within which a subsample point supports a hypothesis (m).
    pub score_threshold: f64,
    /// MSSE threshold factor `T` (inliers are within `T·σ`).
    pub msse_t: f64,
    /// Floor of the per-plane inlier threshold (m).
    pub min_threshold: f64,
    /// Ceiling of the per-plane inlier threshold (m).
    pub max_threshold: f64,
    /// Ground: maximum angle between the normal and the vertical (rad).
    pub max_ground_tilt: f64,
    /// Ground: the plane must lie at least this far below the sensor origin (m).
    pub min_ground_depth: f64,
    /// After the ground is found, hypotheses are drawn only from points more than this far
    /// above it (m); the points themselves stay available as inliers.
    pub ground_clearance: f64,
    /// Walls: maximum angle between the normal and the horizontal plane (rad).
    pub max_wall_tilt: f64,
    /// Walls: minimum patch area (m²).
    pub min_wall_area: f64,
    /// Walls: minimum patch length, the more horizontal side (m).
    pub min_wall_length: f64,
    /// Walls: minimum patch height, the more vertical side (m).
    pub min_wall_height: f64,
    /// Cell edge of the 2-D grid used to split a plane into connected pieces (m).
    pub grid_cell: f64,
    /// Grid cells with fewer points than this take no part in the pieces (their points stay
    /// unassigned); keeps stray clutter points on the infinite plane from stretching a patch.
    pub min_cell_points: usize,
}

impl Default for PlaneConfig {
    fn default() -> Self {
        PlaneConfig {
            max_planes: 16,
            min_points: 150,
            hypotheses: 256,
            score_sample: 6000,
            sample_cell: 2.0,
            score_threshold: 0.10,
            msse_t: 2.5,
            min_threshold: 0.05,
            max_threshold: 0.20,
            max_ground_tilt: 10f64.to_radians(),
            min_ground_depth: 0.5,
            ground_clearance: 0.3,
            max_wall_tilt: 15f64.to_radians(),
            min_wall_area: 15.0,
            min_wall_length: 4.0,
            min_wall_height: 2.0,
            grid_cell: 1.0,
            min_cell_points: 3,
        }
    }
}

impl PlaneConfig {
    /// Checks every field for a usable value.
    pub fn validate(&self) -> Result<()> {
        let positive = [
            ("sample_cell", self.sample_cell),
            ("score_threshold", self.score_threshold),
            ("msse_t", self.msse_t),
            ("min_threshold", self.min_threshold),
            ("grid_cell", self.grid_cell),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    format!("plane config field {name}"),
                    format!("must be finite and positive, got {v}"),
                ));
            }
        }
        let non_negative = [
            ("max_ground_tilt", self.max_ground_tilt),
            ("min_ground_depth", self.min_ground_depth),
            ("ground_clearance", self.ground_clearance),
            ("max_wall_tilt", self.max_wall_tilt),
            ("min_wall_area", self.min_wall_area),
            ("min_wall_length", self.min_wall_length),
            ("min_wall_height", self.min_wall_height),
        ];
        for (name, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    format!("plane config field {name}"),
                    format!("must be finite and non-negative, got {v}"),
                ));
            }
        }
        if !(self.max_threshold.is_finite() && self.max_threshold >= self.min_threshold) {
            return Err(Error::invalid(
                "plane config field max_threshold",
                "must be finite and at least min_threshold",
            ));
        }
        if self.min_points < 3 || self.hypotheses == 0 || self.score_sample < 3 {
            return Err(Error::invalid(
                "plane config",
                "min_points and score_sample must be at least 3, hypotheses at least 1",
            ));
        }
        Ok(())
    }
}

/// One segmented plane piece.
#[derive(Clone, Debug, PartialEq)]
pub struct PlaneDetection {
    /// Bounding rectangle of the inliers on the least-squares plane.
    pub patch: PlanePatch,
    /// Indices of the inlier points in the input cloud, ascending.
    pub inliers: Vec<u32>,
    /// Root-mean-square point-to-plane distance of the inliers (m).
    pub rms: f64,
}

/// Why an extracted plane (or a connected piece of one) is not the ground or a wall.
#[derive(Clone, Debug, PartialEq)]
pub enum RejectReason {
    /// A near-horizontal plane below the sensor with fewer points than the chosen ground.
    SecondaryGround,
    /// A near-horizontal plane that is not below the sensor by `min_ground_depth`.
    HorizontalNotGround,
    /// Neither near-horizontal nor near-vertical; `tilt` is the normal's angle from vertical.
    Oblique {
        /// Angle between the normal and `+z` (rad).
        tilt: f64,
    },
    /// A connected piece with fewer than `min_points` points.
    TooFewPoints {
        /// Number of points in the piece.
        points: usize,
    },
    /// A vertical piece below building scale (area, length or height too small).
    TooSmall {
        /// Patch area (m²).
        area: f64,
        /// Patch length (m).
        length: f64,
        /// Patch height (m).
        height: f64,
    },
}

/// A plane or piece that was not kept, with its reason.
#[derive(Clone, Debug, PartialEq)]
pub struct RejectedPlane {
    /// The piece's plane.
    pub plane: Plane,
    /// Its patch, when one was computed.
    pub patch: Option<PlanePatch>,
    /// Number of points in the piece.
    pub points: usize,
    /// Why it was rejected.
    pub reason: RejectReason,
}

/// Result of [`extract_planes`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlaneSegmentation {
    /// The ground plane, if one was found.
    pub ground: Option<PlaneDetection>,
    /// Building-scale vertical planes, in extraction order.
    pub walls: Vec<PlaneDetection>,
    /// Indices of the finite points on neither the ground nor a wall, ascending.
    pub remaining: Vec<u32>,
    /// Extracted planes and pieces that were rejected, with reasons.
    pub rejected: Vec<RejectedPlane>,
    /// Number of points skipped for a non-finite coordinate.
    pub skipped: usize,
}

/// Plane with f32 coefficients for fast residuals.
#[derive(Copy, Clone)]
struct PlaneF32 {
    n: [f32; 3],
    d: f32,
}

impl PlaneF32 {
    fn new(p: &Plane) -> Self {
        PlaneF32 {
            n: [p.normal.x as f32, p.normal.y as f32, p.normal.z as f32],
            d: p.offset as f32,
        }
    }
    #[inline]
    fn residual_signed(&self, p: &[f32; 3]) -> f32 {
        self.n[0] * p[0] + self.n[1] * p[1] + self.n[2] * p[2] + self.d
    }
    #[inline]
    fn residual(&self, p: &[f32; 3]) -> f32 {
        (self.n[0] * p[0] + self.n[1] * p[1] + self.n[2] * p[2] + self.d).abs()
    }
}

/// Segments the ground and building walls from `cloud`. See the module documentation for
/// the method. An empty cloud gives an empty result; only an invalid configuration is an
/// error.
pub fn extract_planes(
    cloud: &PointCloud,
    config: &PlaneConfig,
    rng: &mut FilterRng,
) -> Result<PlaneSegmentation> {
    config.validate()?;
    if cloud.len() > u32::MAX as usize {
        return Err(Error::invalid("point cloud", "more than u32::MAX points"));
    }
    let (xs, ys, zs) = (cloud.xs(), cloud.ys(), cloud.zs());
    let mut pts: Vec<[f32; 3]> = Vec::with_capacity(cloud.len());
    let mut orig: Vec<u32> = Vec::with_capacity(cloud.len());
    for i in 0..cloud.len() {
        let p = [xs[i], ys[i], zs[i]];
        if p.iter().all(|v| v.is_finite()) {
            pts.push(p);
            orig.push(i as u32);
        }
    }
    let mut out = PlaneSegmentation {
        skipped: cloud.len() - pts.len(),
        ..Default::default()
    };

    // Local indices (into `pts`) of the points still in the pool.
    let mut active: Vec<u32> = (0..pts.len() as u32).collect();
    // Extracted planes: (final plane, local inlier indices).
    let mut extracted: Vec<(Plane, Vec<u32>)> = Vec::new();
    let ground_like = |p: &Plane| {
        p.tilt() <= config.max_ground_tilt
            && p.normal.z > 0.0
            && p.offset >= config.min_ground_depth
    };
    let mut first_ground: Option<PlaneF32> = None;
    for _ in 0..config.max_planes {
        if active.len() < config.min_points {
            break;
        }
        // Once a ground plane is out, the search is for walls: hypotheses are drawn only from
        // points clearly above that plane and only near-vertical ones are kept.
        let pool: Vec<u32> = match &first_ground {
            Some(g) => active
                .iter()
                .copied()
                .filter(|&i| g.residual_signed(&pts[i as usize]) > config.ground_clearance as f32)
                .collect(),
            None => active.clone(),
        };
        let min_tilt = if first_ground.is_some() {
            std::f64::consts::FRAC_PI_2 - config.max_wall_tilt
        } else {
            0.0
        };
        if pool.len() < config.min_points {
            break;
        }
        let Some((plane, inliers)) = one_round(&pts, &active, &pool, min_tilt, config, rng) else {
            break;
        };
        if first_ground.is_none() && ground_like(&plane) {
            first_ground = Some(PlaneF32::new(&plane));
        }
        let mut is_inlier = vec![false; pts.len()];
        for &i in &inliers {
            is_inlier[i as usize] = true;
        }
        active.retain(|&i| !is_inlier[i as usize]);
        extracted.push((plane, inliers));
    }

    // Ground: most inliers among near-horizontal planes below the sensor.
    let ground_idx = extracted
        .iter()
        .enumerate()
        .filter(|(_, (p, _))| ground_like(p))
        .max_by(|a, b| a.1 .1.len().cmp(&b.1 .1.len()).then(b.0.cmp(&a.0)))
        .map(|(i, _)| i);

    let mut assigned = vec![false; pts.len()];
    let to_points = |idx: &[u32]| -> Vec<Point3<f64>> {
        idx.iter()
            .map(|&i| {
                let p = pts[i as usize];
                Point3::new(p[0] as f64, p[1] as f64, p[2] as f64)
            })
            .collect()
    };
    let to_orig = |idx: &[u32]| -> Vec<u32> {
        let mut v: Vec<u32> = idx.iter().map(|&i| orig[i as usize]).collect();
        v.sort_unstable();
        v
    };

    for (k, (plane, inliers)) in extracted.iter().enumerate() {
        if Some(k) == ground_idx {
            let points = to_points(inliers);
            let patch = PlanePatch::from_points(*plane, &points)?;
            for &i in inliers {
                assigned[i as usize] = true;
            }
            out.ground = Some(PlaneDetection {
                patch,
                inliers: to_orig(inliers),
                rms: rms(plane, &points),
            });
            continue;
        }
        if plane.tilt() <= config.max_ground_tilt {
            let reason = if ground_like(plane) {
                RejectReason::SecondaryGround
            } else {
                RejectReason::HorizontalNotGround
            };
            out.rejected.push(RejectedPlane {
                plane: *plane,
                patch: None,
                points: inliers.len(),
                reason,
            });
            continue;
        }
        if plane.tilt() < std::f64::consts::FRAC_PI_2 - config.max_wall_tilt {
            out.rejected.push(RejectedPlane {
                plane: *plane,
                patch: None,
                points: inliers.len(),
                reason: RejectReason::Oblique { tilt: plane.tilt() },
            });
            continue;
        }
        for piece in connected_pieces(
            plane,
            inliers,
            &pts,
            config.grid_cell,
            config.min_cell_points,
        ) {
            let points = to_points(&piece);
            if piece.len() < config.min_points {
                out.rejected.push(RejectedPlane {
                    plane: *plane,
                    patch: None,
                    points: piece.len(),
                    reason: RejectReason::TooFewPoints {
                        points: piece.len(),
                    },
                });
                continue;
            }
            let piece_plane = fit_chunked(&pts, &piece).unwrap_or(*plane);
            let patch = PlanePatch::from_points(piece_plane, &points)?;
            let tilt = piece_plane.tilt();
            let (length, height) = patch.extent;
            if tilt < std::f64::consts::FRAC_PI_2 - config.max_wall_tilt {
                out.rejected.push(RejectedPlane {
                    plane: piece_plane,
                    points: piece.len(),
                    patch: Some(patch),
                    reason: RejectReason::Oblique { tilt },
                });
            } else if patch.area < config.min_wall_area
                || length < config.min_wall_length
                || height < config.min_wall_height
            {
                out.rejected.push(RejectedPlane {
                    plane: piece_plane,
                    points: piece.len(),
                    reason: RejectReason::TooSmall {
                        area: patch.area,
                        length,
                        height,
                    },
                    patch: Some(patch),
                });
            } else {
                for &i in &piece {
                    assigned[i as usize] = true;
                }
                out.walls.push(PlaneDetection {
                    rms: rms(&piece_plane, &points),
                    patch,
                    inliers: to_orig(&piece),
                });
            }
        }
    }
    out.remaining = (0..pts.len())
        .filter(|&i| !assigned[i])
        .map(|i| orig[i])
        .collect();
    Ok(out)
}

/// RMS distance of `points` to `plane`.
fn rms(plane: &Plane, points: &[Point3<f64>]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let s: f64 = points
        .iter()
        .map(|p| plane.signed_distance(p).powi(2))
        .sum();
    (s / points.len() as f64).sqrt()
}

/// One RANSAC round on the pool `active`: the refined plane and its inliers (local indices),
/// or `None` when no plane with `min_points` inliers is found.
fn one_round(
    pts: &[[f32; 3]],
    active: &[u32],
    pool: &[u32],
    min_tilt: f64,
    config: &PlaneConfig,
    rng: &mut FilterRng,
) -> Option<(Plane, Vec<u32>)> {
    // 1. Subsample (with replacement when the pool is small) and voxel grid.
    let m = config.score_sample.min(pool.len());
    let sample: Vec<[f32; 3]> = if m == pool.len() {
        pool.iter().map(|&i| pts[i as usize]).collect()
    } else {
        (0..m)
            .map(|_| pts[pool[rng.random_range(0..pool.len())] as usize])
            .collect()
    };
    let inv = 1.0 / config.sample_cell as f32;
    let key = |p: &[f32; 3]| {
        (
            (p[0] * inv).floor() as i32,
            (p[1] * inv).floor() as i32,
            (p[2] * inv).floor() as i32,
        )
    };
    let mut voxels: HashMap<(i32, i32, i32), Vec<u32>> = HashMap::new();
    for (i, p) in sample.iter().enumerate() {
        voxels.entry(key(p)).or_default().push(i as u32);
    }

    // 2. Hypotheses, drawn sequentially.
    let mut hyps: Vec<PlaneF32> = Vec::with_capacity(config.hypotheses);
    let mut attempts = 0usize;
    while hyps.len() < config.hypotheses && attempts < config.hypotheses * 20 {
        attempts += 1;
        let a = rng.random_range(0..m);
        let cell = &voxels[&key(&sample[a])];
        if cell.len() < 3 {
            continue;
        }
        let b = cell[rng.random_range(0..cell.len())] as usize;
        let c = cell[rng.random_range(0..cell.len())] as usize;
        if a == b || b == c || a == c {
            continue;
        }
        let to64 = |p: &[f32; 3]| Vector3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        let (pa, pb, pc) = (to64(&sample[a]), to64(&sample[b]), to64(&sample[c]));
        let n = (pb - pa).cross(&(pc - pa));
        if n.norm() < 1e-6 {
            continue;
        }
        if let Ok(p) = Plane::from_point_normal(&Point3::from(pa), n) {
            if p.tilt() >= min_tilt {
                hyps.push(PlaneF32::new(&p));
            }
        }
    }
    if hyps.is_empty() {
        return None;
    }

    // 3. Score in parallel into an ordered vector; best = most support, earliest on ties.
    let thr = config.score_threshold as f32;
    let scores: Vec<usize> = hyps
        .par_iter()
        .map(|h| sample.iter().filter(|p| h.residual(p) < thr).count())
        .collect();
    let (best, best_score) = scores
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(&a.0)))
        .map(|(i, s)| (i, *s))?;
    // Expected support in the whole pool far below min_points: stop early.
    let expected = best_score as f64 * pool.len() as f64 / m as f64;
    if expected < 0.5 * config.min_points as f64 {
        return None;
    }

    // 4. MSSE threshold, inliers, refit; twice.
    let mut plane = hyps[best];
    let mut fitted: Option<Plane> = None;
    let mut inliers: Vec<u32> = Vec::new();
    for _ in 0..2 {
        let residuals = residuals_chunked(pts, active, &plane);
        let tau = msse_threshold(&residuals, config);
        inliers = active
            .iter()
            .zip(&residuals)
            .filter(|(_, &r)| r <= tau)
            .map(|(&i, _)| i)
            .collect();
        if inliers.len() < config.min_points {
            return None;
        }
        let p = fit_chunked(pts, &inliers)?;
        plane = PlaneF32::new(&p);
        fitted = Some(p);
    }
    fitted.map(|p| (p, inliers))
}

/// Absolute residuals of the points `idx` to `plane`, in the order of `idx`.
fn residuals_chunked(pts: &[[f32; 3]], idx: &[u32], plane: &PlaneF32) -> Vec<f32> {
    let mut out = vec![0.0f32; idx.len()];
    out.par_chunks_mut(CHUNK)
        .zip(idx.par_chunks(CHUNK))
        .for_each(|(o, ix)| {
            for (r, &i) in o.iter_mut().zip(ix) {
                *r = plane.residual(&pts[i as usize]);
            }
        });
    out
}

/// Inlier threshold from the MSSE scale of the sorted residuals (see the module docs).
fn msse_threshold(residuals: &[f32], config: &PlaneConfig) -> f32 {
    let (lo, hi, t) = (config.min_threshold, config.max_threshold, config.msse_t);
    let mut r: Vec<f64> = residuals
        .iter()
        .filter(|&&r| (r as f64) <= hi)
        .map(|&r| r as f64)
        .collect();
    r.sort_unstable_by(|a, b| a.total_cmp(b));
    const P: usize = 3;
    let start = r.partition_point(|&x| x <= lo).max(P + 2).min(r.len());
    if start < P + 2 {
        return hi as f32;
    }
    let mut sum_sq: f64 = r[..start].iter().map(|x| x * x).sum();
    let mut k = start;
    while k < r.len() {
        let sigma2 = sum_sq / (k - P) as f64;
        if r[k] * r[k] > t * t * sigma2 {
            break;
        }
        sum_sq += r[k] * r[k];
        k += 1;
    }
    if k == r.len() {
        return hi as f32;
    }
    let sigma = (sum_sq / (k - P) as f64).sqrt();
    (t * sigma).clamp(lo, hi) as f32
}

/// Least-squares plane through the points `idx`, with sums per fixed chunk combined in order.
fn fit_chunked(pts: &[[f32; 3]], idx: &[u32]) -> Option<Plane> {
    if idx.len() < 3 {
        return None;
    }
    // Shift by the first point for numerical accuracy.
    let o = pts[idx[0] as usize];
    let partial: Vec<([f64; 3], [f64; 6])> = idx
        .par_chunks(CHUNK)
        .map(|ix| {
            let mut s = [0.0f64; 3];
            let mut q = [0.0f64; 6];
            for &i in ix {
                let p = pts[i as usize];
                let (x, y, z) = (
                    (p[0] - o[0]) as f64,
                    (p[1] - o[1]) as f64,
                    (p[2] - o[2]) as f64,
                );
                s[0] += x;
                s[1] += y;
                s[2] += z;
                q[0] += x * x;
                q[1] += x * y;
                q[2] += x * z;
                q[3] += y * y;
                q[4] += y * z;
                q[5] += z * z;
            }
            (s, q)
        })
        .collect();
    let mut s = [0.0f64; 3];
    let mut q = [0.0f64; 6];
    for (ps, pq) in &partial {
        for k in 0..3 {
            s[k] += ps[k];
        }
        for k in 0..6 {
            q[k] += pq[k];
        }
    }
    let n = idx.len() as f64;
    let c = Vector3::new(s[0] / n, s[1] / n, s[2] / n);
    let cov = Matrix3::new(
        q[0] / n - c.x * c.x,
        q[1] / n - c.x * c.y,
        q[2] / n - c.x * c.z,
        q[1] / n - c.x * c.y,
        q[3] / n - c.y * c.y,
        q[4] / n - c.y * c.z,
        q[2] / n - c.x * c.z,
        q[4] / n - c.y * c.z,
        q[5] / n - c.z * c.z,
    );
    let centroid = c + Vector3::new(o[0] as f64, o[1] as f64, o[2] as f64);
    Plane::from_moments(&centroid, &cov).ok()
}

/// Splits the points `idx` of `plane` into spatially connected pieces: flood fill with
/// 8-connectivity over the occupied cells of a 2-D grid (edge `cell`) in the plane's
/// coordinates. Cells holding fewer than `min_cell` points are left out (their points are in
/// no piece). Pieces are ordered by their first point in `idx`, points keep their order.
fn connected_pieces(
    plane: &Plane,
    idx: &[u32],
    pts: &[[f32; 3]],
    cell: f64,
    min_cell: usize,
) -> Vec<Vec<u32>> {
    let (u, v) = plane.basis();
    let inv = 1.0 / cell;
    let cell_of = |i: u32| {
        let p = pts[i as usize];
        let q = Vector3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        (
            (q.dot(&u) * inv).floor() as i64,
            (q.dot(&v) * inv).floor() as i64,
        )
    };
    let cells: Vec<(i64, i64)> = idx.iter().map(|&i| cell_of(i)).collect();
    let mut counts: HashMap<(i64, i64), usize> = HashMap::with_capacity(idx.len() / 4);
    for c in &cells {
        *counts.entry(*c).or_default() += 1;
    }
    // Occupied cell -> component id (usize::MAX = not yet labelled).
    let mut label: HashMap<(i64, i64), usize> = counts
        .iter()
        .filter(|(_, &n)| n >= min_cell.max(1))
        .map(|(c, _)| (*c, usize::MAX))
        .collect();
    let mut n_comp = 0usize;
    let mut stack: Vec<(i64, i64)> = Vec::new();
    for c in &cells {
        if label.get(c).is_none_or(|&l| l != usize::MAX) {
            continue;
        }
        label.insert(*c, n_comp);
        stack.push(*c);
        while let Some((cx, cy)) = stack.pop() {
            for dx in -1..=1 {
                for dy in -1..=1 {
                    let nb = (cx + dx, cy + dy);
                    if let Some(l) = label.get_mut(&nb) {
                        if *l == usize::MAX {
                            *l = n_comp;
                            stack.push(nb);
                        }
                    }
                }
            }
        }
        n_comp += 1;
    }
    let mut pieces: Vec<Vec<u32>> = vec![Vec::new(); n_comp];
    for (&i, c) in idx.iter().zip(&cells) {
        if let Some(&l) = label.get(c) {
            pieces[l].push(i);
        }
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;
    use rand_distr::{Distribution, Normal};

    /// Adds `n` points uniformly on the rectangle `origin + s·a + t·b` (s, t in [0, 1]) with
    /// Gaussian noise of `sigma` along `normal`.
    #[allow(clippy::too_many_arguments)]
    fn add_rect(
        cloud: &mut PointCloud,
        rng: &mut FilterRng,
        origin: [f64; 3],
        a: [f64; 3],
        b: [f64; 3],
        normal: [f64; 3],
        sigma: f64,
        n: usize,
    ) {
        let noise = Normal::new(0.0, sigma).unwrap();
        for _ in 0..n {
            let (s, t): (f64, f64) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
            let e = noise.sample(rng);
            let p: Vec<f64> = (0..3)
                .map(|k| origin[k] + s * a[k] + t * b[k] + e * normal[k])
                .collect();
            cloud.push(p[0] as f32, p[1] as f32, p[2] as f32, 0.5);
        }
    }

    const H: f64 = -1.73;

    fn ground(cloud: &mut PointCloud, rng: &mut FilterRng, n: usize) {
        add_rect(
            cloud,
            rng,
            [-30.0, -30.0, H],
            [60.0, 0.0, 0.0],
            [0.0, 60.0, 0.0],
            [0.0, 0.0, 1.0],
            0.02,
            n,
        );
    }

    /// Ground, wall x = 10 (20 m × 6 m), wall y = −8 (15 m × 5 m), a car side y = 3
    /// (4 m × 1.5 m) and clutter. Returns the cloud and the index range of the car side.
    fn street(seed: u64) -> (PointCloud, std::ops::Range<usize>) {
        let mut rng = seeded(seed);
        let mut c = PointCloud::new();
        ground(&mut c, &mut rng, 30_000);
        add_rect(
            &mut c,
            &mut rng,
            [10.0, -10.0, H],
            [0.0, 20.0, 0.0],
            [0.0, 0.0, 6.0],
            [1.0, 0.0, 0.0],
            0.02,
            6000,
        );
        add_rect(
            &mut c,
            &mut rng,
            [-7.0, -8.0, H],
            [15.0, 0.0, 0.0],
            [0.0, 0.0, 5.0],
            [0.0, 1.0, 0.0],
            0.02,
            4000,
        );
        let car_start = c.len();
        add_rect(
            &mut c,
            &mut rng,
            [2.0, 3.0, -1.5],
            [4.0, 0.0, 0.0],
            [0.0, 0.0, 1.5],
            [0.0, 1.0, 0.0],
            0.02,
            800,
        );
        let car = car_start..c.len();
        for _ in 0..2000 {
            c.push(
                rng.random_range(-20.0..20.0),
                rng.random_range(-20.0..20.0),
                rng.random_range(-1.5..3.0),
                0.1,
            );
        }
        (c, car)
    }

    fn angle(n: &Vector3<f64>, axis: Vector3<f64>) -> f64 {
        n.dot(&axis).abs().min(1.0).acos()
    }

    #[test]
    fn street_scene_ground_walls_and_car() {
        let (cloud, car) = street(11);
        let seg = extract_planes(&cloud, &PlaneConfig::default(), &mut seeded(5)).unwrap();
        let g = seg.ground.as_ref().expect("ground");
        assert!(angle(&g.patch.plane.normal, Vector3::z()) < 1f64.to_radians());
        assert!((g.patch.plane.offset - 1.73).abs() < 0.02);
        assert!(g.inliers.len() > 27_000, "{}", g.inliers.len());
        assert!(g.rms < 0.05);

        let find = |axis: Vector3<f64>| {
            seg.walls
                .iter()
                .filter(|w| angle(&w.patch.plane.normal, axis) < 1f64.to_radians())
                .collect::<Vec<_>>()
        };
        let wx = find(Vector3::x());
        assert_eq!(wx.len(), 1, "{:?}", seg.walls);
        assert!((wx[0].patch.plane.offset - 10.0).abs() < 0.05);
        assert!(
            (wx[0].patch.area / 120.0 - 1.0).abs() < 0.1,
            "{}",
            wx[0].patch.area
        );
        let (len, h) = wx[0].patch.extent;
        assert!(
            (len - 20.0).abs() < 1.0 && (h - 6.0).abs() < 0.6,
            "{len} {h}"
        );
        let wy = find(Vector3::y());
        assert_eq!(wy.len(), 1, "{:?}", seg.walls);
        assert!((wy[0].patch.plane.offset - 8.0).abs() < 0.05);
        assert!(
            (wy[0].patch.area / 75.0 - 1.0).abs() < 0.1,
            "{}",
            wy[0].patch.area
        );
        assert_eq!(seg.walls.len(), 2);

        // The car side is on no wall and (if extracted at all) rejected as too small.
        let on_wall = |i: usize| seg.walls.iter().any(|w| w.inliers.contains(&(i as u32)));
        assert!(car.clone().all(|i| !on_wall(i)));
        let car_piece = seg.rejected.iter().find(|r| {
            r.patch
                .as_ref()
                .is_some_and(|p| (p.centre() - Point3::new(4.0, 3.0, -0.75)).norm() < 1.0)
        });
        if let Some(r) = car_piece {
            assert!(matches!(r.reason, RejectReason::TooSmall { .. }), "{r:?}");
        }
        // Every finite point is in exactly one of ground, walls, remaining.
        let total = g.inliers.len()
            + seg.walls.iter().map(|w| w.inliers.len()).sum::<usize>()
            + seg.remaining.len();
        assert_eq!(total, cloud.len());
        assert_eq!(seg.skipped, 0);
    }

    #[test]
    fn collinear_walls_with_a_gap_are_two_patches() {
        let mut rng = seeded(2);
        let mut c = PointCloud::new();
        ground(&mut c, &mut rng, 20_000);
        for y0 in [-15.0, 2.5] {
            add_rect(
                &mut c,
                &mut rng,
                [12.0, y0, H],
                [0.0, 12.5, 0.0],
                [0.0, 0.0, 5.0],
                [1.0, 0.0, 0.0],
                0.02,
                3000,
            );
        }
        let seg = extract_planes(&c, &PlaneConfig::default(), &mut seeded(9)).unwrap();
        assert!(seg.ground.is_some());
        assert_eq!(seg.walls.len(), 2, "{:?}", seg.walls);
        let mut ys: Vec<f64> = seg.walls.iter().map(|w| w.patch.centre().y).collect();
        ys.sort_by(f64::total_cmp);
        assert!(
            (ys[0] + 8.75).abs() < 0.5 && (ys[1] - 8.75).abs() < 0.5,
            "{ys:?}"
        );
        for w in &seg.walls {
            assert!(
                (w.patch.extent.0 - 12.5).abs() < 0.7,
                "{:?}",
                w.patch.extent
            );
        }
    }

    #[test]
    fn same_seed_same_output_for_any_thread_count() {
        let (cloud, _) = street(4);
        let cfg = PlaneConfig::default();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| extract_planes(&cloud, &cfg, &mut seeded(77)).unwrap())
        };
        let one = run(1);
        assert_eq!(one, run(2));
        assert_eq!(one, run(1));
        assert!(one.ground.is_some() && one.walls.len() == 2);
    }

    #[test]
    fn empty_and_non_finite_input() {
        let cfg = PlaneConfig::default();
        let seg = extract_planes(&PointCloud::new(), &cfg, &mut seeded(1)).unwrap();
        assert_eq!(seg, PlaneSegmentation::default());
        let mut c = PointCloud::new();
        c.push(f32::NAN, 0.0, 0.0, 0.0);
        c.push(1.0, f32::INFINITY, 0.0, 0.0);
        c.push(1.0, 2.0, 3.0, 0.0);
        let seg = extract_planes(&c, &cfg, &mut seeded(1)).unwrap();
        assert_eq!(seg.skipped, 2);
        assert_eq!(seg.remaining, vec![2]);
        assert!(seg.ground.is_none() && seg.walls.is_empty());
    }

    #[test]
    fn invalid_config_is_an_error() {
        let cfg = PlaneConfig {
            grid_cell: 0.0,
            ..Default::default()
        };
        assert!(extract_planes(&PointCloud::new(), &cfg, &mut seeded(1)).is_err());
        let cfg = PlaneConfig {
            max_threshold: 0.01,
            ..Default::default()
        };
        assert!(cfg.validate().is_err());
    }

    #[test]
    fn msse_threshold_tracks_noise_scale() {
        let mut rng = seeded(3);
        let noise = Normal::new(0.0, 0.03).unwrap();
        let mut r: Vec<f32> = (0..5000)
            .map(|_| (noise.sample(&mut rng) as f32).abs())
            .collect();
        r.extend((0..5000).map(|_| rng.random_range(0.0f32..5.0)));
        let cfg = PlaneConfig {
            min_threshold: 0.01,
            max_threshold: 0.5,
            ..Default::default()
        };
        let t = msse_threshold(&r, &cfg);
        // About 2.5 σ of a Gaussian with σ = 0.03.
        assert!(t > 0.05 && t < 0.11, "{t}");
    }
}
