//! A fine point-to-plane refinement after the point-to-point alignment: the denser map
//! sampling of the scan (the points that go into the map) against a plane fitted to each map
//! voxel, a few Gauss–Newton steps on SE(3).
//!
//! Point-to-point ICP on a scan sampled at 1.5 voxel edges pairs each point with a map point
//! up to a map spacing away along the surface; those tangential offsets do not average out
//! exactly and leave centimetres of error per frame. Distances to planes have no tangential
//! part, so the refinement measures only what the scan says about its pose.
//!
//! **Planes.** For every map voxel that holds a moved scan point, the normal is the eigenvector
//! with the smallest eigenvalue of the covariance of the map points within `radius` of the
//! voxel's centre (the voxel and its neighbours: enough points even when the map holds only the
//! first scan's). The plane is kept when there are at least [`MIN_PLANE_POINTS`] points, it is
//! thin (smallest eigenvalue below `thickness²`) and extended (middle eigenvalue at least 10×
//! the smallest and (1 cm)²): neighbourhoods across an edge, a corner, a pole or a moving car's smear have
//! no plane, and their points take no part. The plane passes through the centroid of the
//! voxel's own map points, the same patch of surface the scan's points in that voxel sample:
//! range noise tilts fitted normals a little towards the rays that saw the points, and a
//! tilted normal through the centroid of a wider neighbourhood leaves a residual that
//! does not average out (on the simulated street, 50 frames, that centroid drifted 3.8 cm
//! along the path, the voxel's own 1.1 cm; without range noise both 0.1 cm).
//!
//! **Passes.** Each point keeps its voxel's plane for the iterations of a pass; a second pass
//! fits the planes again at the pose the first reached (the point-to-point alignment may be
//! off by decimetres in a turn, enough to change voxels).
//!
//! **Steps.** Residual r = n·(p − c) for the moved point p, Jacobian [nᵀ, (p × n)ᵀ] (left
//! perturbation), Geman–McClure weight s⁴ / (s² + r²)² with scale s, pairs with |r| ≥ 3s
//! left out; the normal equations are solved and exp(δ) applied on the left until ‖δ‖ is
//! below the convergence criterion.
//!
//! # Determinism
//! Voxels are fitted in sorted order and every sum is taken over fixed chunks of
//! [`super::registration::CHUNK`] points combined in chunk order: the result does not
//! depend on the number of rayon threads.

use super::registration::{gauss_newton_step, move_points, sum_in_order, Alignment, CHUNK};
use super::se3;
use super::voxel_map::{Voxel, VoxelHashMap, VoxelTable};
use nalgebra::{Isometry3, Matrix3, Matrix6, SymmetricEigen, Vector3, Vector6};
use rayon::prelude::*;

/// A voxel needs at least this many map points to carry a plane.
pub const MIN_PLANE_POINTS: usize = 5;

/// Settings of [`refine_point_to_plane`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct RefineParams {
    /// Geman–McClure scale s of the point-to-plane distance, metres.
    pub scale: f64,
    /// A voxel's plane is kept when its points' RMS distance to it is below this, metres.
    pub thickness: f64,
    /// A voxel's plane is fitted to the map points within this distance of the voxel's
    /// centre (in it and its 26 neighbours), metres; at most one voxel edge.
    pub radius: f64,
    /// Passes: each fits the planes anew at the pose the last one reached.
    pub passes: usize,
    /// At most this many Gauss–Newton steps per pass.
    pub max_iterations: usize,
    /// Stop once ‖δ‖ is below this.
    pub convergence: f64,
}

/// A plane: a point on it and its unit normal.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Plane {
    /// The centroid of the voxel's points.
    pub point: Vector3<f64>,
    /// Unit normal (sign arbitrary).
    pub normal: Vector3<f64>,
}

/// The plane of `points` (see the module docs), or `None` when they are too few, too thick
/// or not extended in two directions.
pub fn fit_plane(points: &[Vector3<f64>], thickness: f64) -> Option<Plane> {
    if points.len() < MIN_PLANE_POINTS {
        return None;
    }
    let n = points.len() as f64;
    let centroid = points.iter().sum::<Vector3<f64>>() / n;
    let mut cov = Matrix3::zeros();
    for p in points {
        let d = p - centroid;
        cov += d * d.transpose();
    }
    cov /= n;
    let eig = SymmetricEigen::new(cov);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let (l0, l1) = (eig.eigenvalues[order[0]], eig.eigenvalues[order[1]]);
    // Extended: the middle eigenvalue 10× the smallest and at least (1 cm)², so that points
    // on a line (both small eigenvalues zero up to rounding) are no plane.
    if l0 >= thickness * thickness || l1 < (10.0 * l0).max(1e-4) {
        return None;
    }
    let normal = eig.eigenvectors.column(order[0]).normalize();
    Some(Plane {
        point: centroid,
        normal,
    })
}

/// Refines `initial` (scan → map) by point-to-plane Gauss–Newton of `source` (scan frame)
/// against the planes of the map's voxels; see the module docs. Returns `initial` when the
/// map is empty; a pass whose normal equations are singular (no plane constrains some
/// direction) ends the refinement at the pose the passes before it reached.
pub fn refine_point_to_plane(
    source: &[Vector3<f64>],
    map: &VoxelHashMap,
    initial: &Isometry3<f64>,
    params: &RefineParams,
) -> Alignment {
    let mut out = Alignment::unmoved(initial);
    if map.is_empty() || source.is_empty() {
        return out;
    }
    let size = map.voxel_size();
    let mut pose = *initial;
    // Planes (or their absence) of the voxels met so far: the map does not change between
    // passes, so a later pass fits only the voxels it meets first.
    let mut planes: VoxelTable<Option<Plane>> = VoxelTable::default();
    for _ in 0..params.passes {
        let step = refine_pass(source, map, &pose, params, size, &mut planes);
        out.iterations += step.iterations;
        out.correspondences = step.correspondences;
        out.translation_information = step.translation_information.or(out.translation_information);
        match step.pose {
            Some(p) => pose = p,
            None => break,
        }
    }
    out.pose = pose;
    out
}

/// One pass: planes of the voxels the points fall into at `initial`, then Gauss–Newton with
/// each point's plane fixed. `pose` is `None` when the normal equations are singular.
struct Pass {
    pose: Option<Isometry3<f64>>,
    iterations: usize,
    correspondences: usize,
    /// The top-left block of the last iteration's normal matrix: Σ w n nᵀ.
    translation_information: Option<Matrix3<f64>>,
}

fn refine_pass(
    source: &[Vector3<f64>],
    map: &VoxelHashMap,
    initial: &Isometry3<f64>,
    params: &RefineParams,
    size: f64,
    planes: &mut VoxelTable<Option<Plane>>,
) -> Pass {
    let mut out = Pass {
        pose: None,
        iterations: 0,
        correspondences: 0,
        translation_information: None,
    };
    let moved: Vec<Vector3<f64>> = source
        .iter()
        .map(|p| initial.rotation * p + initial.translation.vector)
        .collect();
    // The planes of the voxels the moved points fall into, fitted in sorted voxel order.
    let mut voxels: Vec<Voxel> = moved
        .iter()
        .map(|p| Voxel::of(p, size))
        .filter(|v| !planes.contains_key(v))
        .collect();
    voxels.sort_unstable();
    voxels.dedup();
    let fitted: Vec<Option<Plane>> = voxels
        .par_iter()
        .map_init(Vec::new, |near: &mut Vec<Vector3<f64>>, v| {
            voxel_plane(map, v, params, near)
        })
        .collect();
    planes.extend(voxels.into_iter().zip(fitted));
    // Each point's plane, fixed for the iterations.
    let pairs: Vec<(Vector3<f64>, Plane)> = source
        .iter()
        .zip(&moved)
        .filter_map(|(s, m)| {
            planes
                .get(&Voxel::of(m, size))
                .copied()
                .flatten()
                .map(|pl| (*s, pl))
        })
        .collect();
    let mut moved: Vec<Vector3<f64>> = pairs
        .iter()
        .map(|(s, _)| initial.rotation * s + initial.translation.vector)
        .collect();
    let s2 = params.scale * params.scale;
    let max2 = 9.0 * s2;
    let mut t = Isometry3::identity();
    for _ in 0..params.max_iterations {
        let partial: Vec<(Matrix6<f64>, Vector6<f64>, usize)> = moved
            .par_chunks(CHUNK)
            .zip(pairs.par_chunks(CHUNK))
            .map(|(pts, prs)| {
                let mut jtj = Matrix6::zeros();
                let mut jtr = Vector6::zeros();
                let mut n = 0usize;
                for (p, (_, pl)) in pts.iter().zip(prs) {
                    let r = pl.normal.dot(&(p - pl.point));
                    let r2 = r * r;
                    if r2 >= max2 {
                        continue;
                    }
                    let w = s2 * s2 / ((s2 + r2) * (s2 + r2));
                    let pn = p.cross(&pl.normal);
                    let j = Vector6::new(pl.normal.x, pl.normal.y, pl.normal.z, pn.x, pn.y, pn.z);
                    jtj += j * j.transpose() * w;
                    jtr += j * (r * w);
                    n += 1;
                }
                (jtj, jtr, n)
            })
            .collect();
        let (jtj, jtr, n) = sum_in_order(partial);
        out.iterations += 1;
        out.correspondences = n;
        out.translation_information = Some(jtj.fixed_view::<3, 3>(0, 0).into_owned());
        let Some(dx) = gauss_newton_step(&jtj, &jtr) else {
            return out;
        };
        let step = se3::exp(&dx);
        move_points(&mut moved, &step);
        t = se3::renormalized(&(step * t));
        if dx.norm() < params.convergence {
            break;
        }
    }
    out.pose = Some(se3::renormalized(&(t * initial)));
    out
}

/// The plane of voxel `v`: its normal fitted to the map points within `params.radius` of
/// the voxel's centre, through the centroid of the voxel's own points (of the neighbourhood's
/// when the voxel is empty). `near` is scratch space.
fn voxel_plane(
    map: &VoxelHashMap,
    v: &Voxel,
    params: &RefineParams,
    near: &mut Vec<Vector3<f64>>,
) -> Option<Plane> {
    let size = map.voxel_size();
    let r2 = params.radius * params.radius;
    let [x, y, z] = v.0;
    let centre = Vector3::new(
        (x as f64 + 0.5) * size,
        (y as f64 + 0.5) * size,
        (z as f64 + 0.5) * size,
    );
    near.clear();
    for dx in -1..=1 {
        for dy in -1..=1 {
            for dz in -1..=1 {
                if let Some(cell) = map.cell(&Voxel([x + dx, y + dy, z + dz])) {
                    near.extend(cell.iter().filter(|q| (*q - centre).norm_squared() < r2));
                }
            }
        }
    }
    let mut plane = fit_plane(near, params.thickness)?;
    if let Some(own) = map.cell(v) {
        plane.point = own.iter().sum::<Vector3<f64>>() / own.len() as f64;
    }
    Some(plane)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::odometry::registration::{align_points_to_map, IcpParams};
    use crate::cloud::odometry::test_scene::yard;
    use nalgebra::Point3;

    #[test]
    fn fits_a_tilted_plane_and_rejects_a_line_and_a_blob() {
        // z = 0.1 x + 0.2 y + 1 on a 5 × 5 grid, points alternately 1 mm above and below:
        // the normal is (−0.1, −0.2, 1) up to sign and scale.
        let mut pts = Vec::new();
        for i in 0..5 {
            for j in 0..5 {
                let (x, y) = (0.2 * i as f64, 0.2 * j as f64);
                let e = if (i + j) % 2 == 0 { 0.001 } else { -0.001 };
                pts.push(Vector3::new(x, y, 0.1 * x + 0.2 * y + 1.0 + e));
            }
        }
        let p = fit_plane(&pts, 0.05).unwrap();
        let truth = Vector3::new(-0.1, -0.2, 1.0).normalize();
        assert!(
            p.normal.dot(&truth).abs() > (0.01f64.to_radians()).cos(),
            "{p:?}"
        );
        assert!((p.point - Vector3::new(0.4, 0.4, 1.0 + 0.04 + 0.08)).norm() < 1e-3);
        // Points along a line are not extended in two directions.
        let line: Vec<_> = (0..10)
            .map(|k| Vector3::new(0.1 * k as f64, 0.0, 0.0))
            .collect();
        assert_eq!(fit_plane(&line, 0.05), None);
        // A cube's corners are not thin.
        let blob: Vec<_> = (0..8)
            .map(|k| Vector3::new((k & 1) as f64, ((k >> 1) & 1) as f64, (k >> 2) as f64))
            .collect();
        assert_eq!(fit_plane(&blob, 0.05), None);
        // Too few points.
        assert_eq!(fit_plane(&pts[..4], 0.05), None);
    }

    /// Noise of ±`amplitude` along each point's ray from the sensor at `origin`
    /// (deterministic, alternating sign and size).
    fn along_rays(points: &mut [Vector3<f64>], origin: &Vector3<f64>, amplitude: f64) {
        for (k, p) in points.iter_mut().enumerate() {
            let ray = (*p - origin).normalize();
            let e = amplitude * [1.0, -0.5, 0.25, -0.75][k % 4];
            *p += ray * e;
        }
    }

    #[test]
    fn refinement_recovers_a_known_motion_more_precisely_than_point_to_point() {
        // A KISS-ICP-like map: the yard sampled every 0.5 m with 2 cm of range noise, at most
        // 20 points per 1 m voxel; the scan is another sampling seen from `truth`.
        let mut map = VoxelHashMap::new(1.0, 100.0, 20);
        let mut first = yard(0.5, 1);
        along_rays(&mut first, &Vector3::zeros(), 0.02);
        map.add_points(&first);
        let truth = Isometry3::new(
            Vector3::new(0.9, -0.15, 0.02),
            Vector3::new(0.002, -0.003, 0.03),
        );
        let mut world = yard(0.5, 2);
        along_rays(&mut world, &truth.translation.vector, 0.02);
        let inv = truth.inverse();
        let scan: Vec<Vector3<f64>> = world
            .iter()
            .map(|p| (inv * Point3::from(*p)).coords)
            .collect();
        let icp = IcpParams {
            max_correspondence: 3.0,
            kernel: 1.0 / 3.0,
            max_iterations: 500,
            convergence: 1e-4,
        };
        let coarse = align_points_to_map(&scan, &map, &Isometry3::identity(), &icp);
        let fine = refine_point_to_plane(&scan, &map, &coarse.pose, &params());
        let err = |pose: &Isometry3<f64>| {
            let e = truth.inverse() * pose;
            (e.translation.vector.norm(), e.rotation.angle().to_degrees())
        };
        let (ct, cr) = err(&coarse.pose);
        let (ft, fr) = err(&fine.pose);
        eprintln!("point-to-point {ct:.4} m {cr:.4}°, refined {ft:.4} m {fr:.4}°");
        assert!(ft < 0.003 && fr < 0.01, "refined {ft} m {fr}°");
        assert!(ft < 0.5 * ct, "refined {ft} m, point-to-point {ct} m");
    }

    /// The refinement's settings in these tests.
    fn params() -> RefineParams {
        RefineParams {
            scale: 0.1,
            thickness: 0.05,
            radius: 1.0,
            passes: 2,
            max_iterations: 10,
            convergence: 1e-6,
        }
    }

    #[test]
    fn an_empty_map_returns_the_initial_guess() {
        let map = VoxelHashMap::new(1.0, 100.0, 20);
        let init = Isometry3::translation(1.0, 0.0, 0.0);
        let a = refine_point_to_plane(&[Vector3::zeros()], &map, &init, &params());
        assert_eq!(a.pose, init);
        assert_eq!(a.iterations, 0);
    }
}
