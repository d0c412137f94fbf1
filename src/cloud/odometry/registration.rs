//! Point-to-point ICP of a scan against the [`VoxelHashMap`], robustified with a Geman–McClure
//! kernel and solved by Gauss–Newton on SE(3) (paper, Sec. III-D, eqs. 7–9).
//!
//! Each iteration pairs every source point with its closest map point within the
//! correspondence distance, builds the normal equations JᵀWJ δ = −JᵀWr with J = [I, −p^]
//! (left perturbation of the transformed point p) and the weights
//! w = κ² / (κ + ‖r‖²)², solves them and applies exp(δ) on the left.
//!
//! # Determinism
//! The pairing and the normal equations are the only parallel parts: points are split into
//! fixed chunks of [`CHUNK`] whose sums are combined in chunk order, so the result does not
//! depend on the number of rayon threads.

use super::se3;
use super::voxel_map::VoxelHashMap;
use nalgebra::{Isometry3, Matrix3, Matrix6, Vector3, Vector6};
use rayon::prelude::*;

/// Points per chunk of the parallel passes. Fixed, so that sums do not depend on threads.
pub const CHUNK: usize = 1024;

/// Result of [`align_points_to_map`].
#[derive(Clone, Debug, PartialEq)]
pub struct Alignment {
    /// The estimated pose of the scan in the map frame.
    pub pose: Isometry3<f64>,
    /// Gauss–Newton iterations run.
    pub iterations: usize,
    /// Correspondences found in the last iteration.
    pub correspondences: usize,
    /// Point-to-plane alignments only: the translational information Σ w n nᵀ of the last
    /// iteration (n the planes' normals, w the kernel's weights).
    pub translation_information: Option<Matrix3<f64>>,
}

/// Stopping rules of the Gauss–Newton loop.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct IcpParams {
    /// Pairs farther apart than this are not correspondences (KISS-ICP: 3σ), metres.
    pub max_correspondence: f64,
    /// Geman–McClure scale κ (KISS-ICP: σ/3).
    pub kernel: f64,
    /// At most this many iterations.
    pub max_iterations: usize,
    /// Stop once ‖δ‖ is below this.
    pub convergence: f64,
}

/// Registers `source` (scan frame) to `map`, starting from `initial` (scan → map). An empty map
/// returns `initial` unchanged (the first scan defines the map frame); so does an iteration
/// whose normal equations are singular (too few correspondences).
pub fn align_points_to_map(
    source: &[Vector3<f64>],
    map: &VoxelHashMap,
    initial: &Isometry3<f64>,
    params: &IcpParams,
) -> Alignment {
    let mut out = Alignment::unmoved(initial);
    if map.is_empty() || source.is_empty() {
        return out;
    }
    let mut moved: Vec<Vector3<f64>> = source.iter().map(|p| transform(initial, p)).collect();
    let mut t_icp = Isometry3::identity();
    for _ in 0..params.max_iterations {
        let (jtj, jtr, n) = normal_equations(&moved, map, params);
        out.iterations += 1;
        out.correspondences = n;
        let Some(dx) = gauss_newton_step(&jtj, &jtr) else {
            break;
        };
        let step = se3::exp(&dx);
        move_points(&mut moved, &step);
        t_icp = se3::renormalized(&(step * t_icp));
        if dx.norm() < params.convergence {
            break;
        }
    }
    out.pose = se3::renormalized(&(t_icp * initial));
    out
}

impl Alignment {
    /// No iteration run yet: `initial`, no correspondences.
    pub(super) fn unmoved(initial: &Isometry3<f64>) -> Self {
        Alignment {
            pose: *initial,
            iterations: 0,
            correspondences: 0,
            translation_information: None,
        }
    }
}

fn transform(t: &Isometry3<f64>, p: &Vector3<f64>) -> Vector3<f64> {
    t.rotation * p + t.translation.vector
}

/// The Gauss–Newton step δ = −(JᵀWJ)⁻¹ JᵀWr, or `None` when the normal equations are
/// singular or the step is not finite.
pub(super) fn gauss_newton_step(jtj: &Matrix6<f64>, jtr: &Vector6<f64>) -> Option<Vector6<f64>> {
    let dx = -jtj.cholesky()?.solve(jtr);
    dx.iter().all(|v| v.is_finite()).then_some(dx)
}

/// Moves `points` by `step`, in parallel chunks.
pub(super) fn move_points(points: &mut [Vector3<f64>], step: &Isometry3<f64>) {
    points.par_chunks_mut(CHUNK).for_each(|c| {
        for p in c {
            *p = transform(step, p);
        }
    });
}

/// Per-chunk normal equations (JᵀWJ, JᵀWr, pairs) summed in chunk order, so that the sum
/// does not depend on the number of threads.
pub(super) fn sum_in_order(
    partial: Vec<(Matrix6<f64>, Vector6<f64>, usize)>,
) -> (Matrix6<f64>, Vector6<f64>, usize) {
    partial.into_iter().fold(
        (Matrix6::zeros(), Vector6::zeros(), 0),
        |(a, b, n), (x, y, m)| (a + x, b + y, n + m),
    )
}

/// JᵀWJ, JᵀWr and the number of correspondences, summed per chunk and combined in order.
fn normal_equations(
    points: &[Vector3<f64>],
    map: &VoxelHashMap,
    params: &IcpParams,
) -> (Matrix6<f64>, Vector6<f64>, usize) {
    let max2 = params.max_correspondence * params.max_correspondence;
    let k = params.kernel;
    let partial: Vec<(Matrix6<f64>, Vector6<f64>, usize)> = points
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut jtj = Matrix6::zeros();
            let mut jtr = Vector6::zeros();
            let mut n = 0usize;
            for p in chunk {
                let Some((q, d2)) = map.closest_within(p, max2) else {
                    continue;
                };
                let r = p - q;
                let w = k * k / ((k + d2) * (k + d2));
                // J = [I, −p^]: rows are the three residual components.
                let mut j = nalgebra::Matrix3x6::zeros();
                j.fixed_view_mut::<3, 3>(0, 0)
                    .copy_from(&Matrix3::identity());
                j.fixed_view_mut::<3, 3>(0, 3)
                    .copy_from(&(-p.cross_matrix()));
                let jt = j.transpose();
                jtj += jt * j * w;
                jtr += jt * r * w;
                n += 1;
            }
            (jtj, jtr, n)
        })
        .collect();
    sum_in_order(partial)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::odometry::test_scene::yard;
    use nalgebra::Point3;

    #[test]
    fn recovers_a_known_motion_of_a_synthetic_room() {
        // A dense map and a scan drawn independently from the same surfaces.
        let mut map = VoxelHashMap::new(1.0, 100.0, 1000);
        map.add_points(&yard(0.1, 1));
        // The scan is the room seen from a sensor at `truth` (scan → map).
        let truth = Isometry3::new(
            Vector3::new(0.6, -0.25, 0.05),
            Vector3::new(0.01, -0.005, 0.08),
        );
        let inv = truth.inverse();
        let scan: Vec<Vector3<f64>> = yard(0.3, 2)
            .iter()
            .map(|p| (inv * Point3::from(*p)).coords)
            .collect();
        let params = IcpParams {
            max_correspondence: 3.0,
            kernel: 1.0 / 3.0,
            max_iterations: 500,
            convergence: 1e-6,
        };
        let a = align_points_to_map(&scan, &map, &Isometry3::identity(), &params);
        let err = truth.inverse() * a.pose;
        assert!(err.translation.vector.norm() < 0.01, "{err:?}");
        assert!(err.rotation.angle().to_degrees() < 0.05, "{err:?}");
    }

    #[test]
    fn an_empty_map_returns_the_initial_guess() {
        let map = VoxelHashMap::new(1.0, 100.0, 20);
        let init = Isometry3::translation(1.0, 0.0, 0.0);
        let params = IcpParams {
            max_correspondence: 3.0,
            kernel: 1.0,
            max_iterations: 10,
            convergence: 1e-4,
        };
        let a = align_points_to_map(&[Vector3::zeros()], &map, &init, &params);
        assert_eq!(a.pose, init);
        assert_eq!(a.iterations, 0);
    }
}
