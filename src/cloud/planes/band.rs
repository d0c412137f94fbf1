//! The wall rounds' pool on a bird's-eye grid, so that the points near a plane are found
//! without a pass over the whole pool: a cell is visited only when the tight box of its points
//! can reach the plane's band, and only its points still in the pool are tested. A steep plane's
//! band crosses few cells, so a pass touches a small part of the pool.
//!
//! The answer is exactly the one a pass over the pool gives: the same points, with the same f32
//! residuals, in the pool's (ascending) order. The box test is conservative by a margin far
//! above the f32 rounding of a residual, and the points it lets through are tested as the pass
//! tests them.
//!
//! Not for: the ground's round (its pool is the whole scan and its plane crosses every cell),
//! or neighbour queries (see [`crate::cloud::cluster`]).

use super::plane_f32::PlaneF32;
use crate::cloud::voxel_groups::VoxelGroups;

/// Edge of a grid cell (m).
const CELL: f32 = 2.0;

/// The wall rounds' pool on a bird's-eye grid. See the module documentation.
pub(super) struct BandGrid {
    /// Points grouped by cell, ascending within a cell.
    order: Vec<u32>,
    /// The positions of `order`'s points, in its order (a cell's points are read in a row).
    coords: Vec<[f32; 3]>,
    /// Per occupied cell `c`: its slice of `order` is `start[c]..start[c + 1]`.
    start: Vec<u32>,
    /// Per axis, per occupied cell: the low and high side of the tight box of its points
    /// (f64), as columns so that the test of every cell against a band runs on vector lanes.
    lo: [Vec<f64>; 3],
    /// See `lo`.
    hi: [Vec<f64>; 3],
    /// Per local point index: whether it is still in the pool.
    alive: Vec<bool>,
}

impl BandGrid {
    /// The grid of the pool `pool` (ascending local indices into `pts`, finite points): the
    /// pool's points grouped by their cells as [`VoxelGroups`] groups them (a cell is a voxel
    /// of the points laid flat).
    pub(super) fn new(pts: &[[f32; 3]], pool: &[u32]) -> Self {
        let mut alive = vec![false; pts.len()];
        let flat: Vec<[f32; 3]> = pool
            .iter()
            .map(|&i| {
                alive[i as usize] = true;
                let p = pts[i as usize];
                [p[0], p[1], 0.0]
            })
            .collect();
        let cells = VoxelGroups::new(&flat, CELL);
        let mut order = Vec::with_capacity(pool.len());
        let mut coords = Vec::with_capacity(pool.len());
        let mut start = vec![0u32];
        let mut lo_cols: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(cells.len()));
        let mut hi_cols: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(cells.len()));
        for c in 0..cells.len() {
            // The box in f32 (widening to f64 keeps the order, so the extremes are the same).
            let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            // Positions in the pool, ascending: so are the local indices.
            for &k in cells.members(c) {
                let i = pool[k as usize];
                let p = pts[i as usize];
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
                order.push(i);
                coords.push(p);
            }
            for a in 0..3 {
                lo_cols[a].push(lo[a] as f64);
                hi_cols[a].push(hi[a] as f64);
            }
            start.push(order.len() as u32);
        }
        BandGrid {
            order,
            coords,
            start,
            lo: lo_cols,
            hi: hi_cols,
            alive,
        }
    }

    /// Takes the points `taken` out of the pool.
    pub(super) fn remove(&mut self, taken: &[u32]) {
        for &i in taken {
            self.alive[i as usize] = false;
        }
    }

    /// The points of the pool whose absolute residual to `plane` is at most `max` (compared
    /// in f64), with those residuals, both in ascending order of the points: what a pass over
    /// the pool in its order gives.
    pub(super) fn near_points(&self, plane: &PlaneF32, max: f64) -> (Vec<u32>, Vec<f32>) {
        let reach = self.cells_within(plane, max);
        let mut found: Vec<(u32, f32)> = Vec::new();
        for (c, _) in reach.iter().enumerate().filter(|(_, &r)| r) {
            let run = self.start[c] as usize..self.start[c + 1] as usize;
            for (&i, p) in self.order[run.clone()].iter().zip(&self.coords[run]) {
                if self.alive[i as usize] {
                    let r = plane.residual(p);
                    if r as f64 <= max {
                        found.push((i, r));
                    }
                }
            }
        }
        radsort::sort_by_key(&mut found, |&(i, _)| i);
        found.into_iter().unzip()
    }

    /// Per cell, whether its box can reach the band `|n·p + d| ≤ max` of `plane`: the range of
    /// n·p + d over the box, widened by far more than the f32 rounding of a residual (a few
    /// units of 2⁻²³ of the largest term). On x86-64 with AVX2 the same loop runs four lanes
    /// wide (the same operations in the same order, so the same answers).
    fn cells_within(&self, plane: &PlaneF32, max: f64) -> Vec<bool> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has just been found to support AVX2.
            return unsafe { self.cells_within_avx2(plane, max) };
        }
        self.cells_within_lanes(plane, max)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn cells_within_avx2(&self, plane: &PlaneF32, max: f64) -> Vec<bool> {
        self.cells_within_lanes(plane, max)
    }

    #[inline(always)]
    fn cells_within_lanes(&self, plane: &PlaneF32, max: f64) -> Vec<bool> {
        let n = plane.normal_f64();
        let d = plane.offset_f64();
        let cells = self.lo[0].len();
        let (lo, hi) = (&self.lo, &self.hi);
        let (lx, ly, lz) = (&lo[0][..cells], &lo[1][..cells], &lo[2][..cells]);
        let (hx, hy, hz) = (&hi[0][..cells], &hi[1][..cells], &hi[2][..cells]);
        // Plain compares instead of `f64::min`/`max` (the boxes are finite), so that the
        // loop vectorises.
        let smaller = |x: f64, y: f64| if x < y { x } else { y };
        let larger = |x: f64, y: f64| if x > y { x } else { y };
        let mut reach = vec![false; cells];
        for c in 0..cells {
            let (mut v_lo, mut v_hi, mut size) = (d, d, d.abs());
            for (a, (l, h)) in [(lx[c], hx[c]), (ly[c], hy[c]), (lz[c], hz[c])]
                .into_iter()
                .enumerate()
            {
                let (x, y) = (n[a] * l, n[a] * h);
                v_lo += smaller(x, y);
                v_hi += larger(x, y);
                size += larger(x.abs(), y.abs());
            }
            let margin = 1e-5 * size + 1e-6;
            reach[c] = !(v_lo - margin > max || v_hi + margin < -max);
        }
        reach
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Plane;
    use nalgebra::{Point3, Vector3};
    use proptest::prelude::*;

    /// What a pass over the pool gives.
    fn by_pass(pts: &[[f32; 3]], pool: &[u32], plane: &PlaneF32, max: f64) -> (Vec<u32>, Vec<f32>) {
        pool.iter()
            .map(|&i| (i, plane.residual(&pts[i as usize])))
            .filter(|&(_, r)| r as f64 <= max)
            .unzip()
    }

    proptest! {
        #[test]
        fn the_grid_finds_what_a_pass_finds(
            pts in proptest::collection::vec(
                (-60.0f32..60.0, -60.0f32..60.0, -2.0f32..12.0), 1..400),
            keep in proptest::collection::vec(proptest::bool::weighted(0.8), 400),
            taken in proptest::collection::vec(proptest::bool::weighted(0.2), 400),
            (nx, ny, nz) in (-1.0f64..1.0, -1.0f64..1.0, -0.3f64..0.3),
            offset in -50.0f64..50.0,
            max in 0.01f64..3.0,
        ) {
            prop_assume!(nx.abs() + ny.abs() + nz.abs() > 0.1);
            let pts: Vec<[f32; 3]> = pts.into_iter().map(|(x, y, z)| [x, y, z]).collect();
            let pool: Vec<u32> = (0..pts.len() as u32).filter(|&i| keep[i as usize]).collect();
            let mut grid = BandGrid::new(&pts, &pool);
            let gone: Vec<u32> = pool.iter().copied().filter(|&i| taken[i as usize]).collect();
            grid.remove(&gone);
            let left: Vec<u32> = pool.iter().copied().filter(|&i| !taken[i as usize]).collect();
            let plane = Plane::from_point_normal(
                &Point3::origin(),
                Vector3::new(nx, ny, nz),
            ).unwrap();
            let plane = PlaneF32::new(&Plane { offset, ..plane });
            prop_assert_eq!(grid.near_points(&plane, max), by_pass(&pts, &left, &plane, max));
        }
    }

    #[test]
    fn a_steep_plane_visits_few_cells_and_an_empty_pool_nothing() {
        // A wall along x = 10 among points spread over 100 m × 100 m.
        let mut pts = Vec::new();
        for k in 0..2000 {
            let t = k as f32 * 0.05;
            pts.push([10.0 + 0.01 * (k % 3) as f32, t - 50.0, (k % 7) as f32]);
            pts.push([t - 50.0, (k as f32 * 0.37) % 100.0 - 50.0, 1.0]);
        }
        let pool: Vec<u32> = (0..pts.len() as u32).collect();
        let grid = BandGrid::new(&pts, &pool);
        let plane = PlaneF32::new(
            &Plane::from_point_normal(&Point3::new(10.0, 0.0, 0.0), Vector3::x()).unwrap(),
        );
        let (near, _) = grid.near_points(&plane, 0.1);
        assert_eq!(near, by_pass(&pts, &pool, &plane, 0.1).0);
        assert!(near.len() >= 2000, "{}", near.len());
        let empty = BandGrid::new(&pts, &[]);
        assert!(empty.near_points(&plane, 0.1).0.is_empty());
    }
}
