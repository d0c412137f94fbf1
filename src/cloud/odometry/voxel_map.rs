//! [`VoxelHashMap`]: the local map of the odometry, a hash table from integer voxel coordinates
//! to at most `max_points_per_voxel` points (paper, Sec. III-B). Nearest neighbours are looked
//! up in the 27 voxels around a query, which finds every point within one voxel edge.
//!
//! Points are in the map frame (the Velodyne frame of the first scan), f64.

use crate::numerics::floor::floor_i32;
use nalgebra::{Isometry3, Point3, Vector3};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hash, Hasher};

/// Integer coordinates of a voxel: `floor(p / voxel_size)` per axis.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Voxel(pub [i32; 3]);

impl Voxel {
    /// The voxel of edge `size` holding `p`.
    pub fn of(p: &Vector3<f64>, size: f64) -> Voxel {
        Voxel([
            floor_i32(p.x / size),
            floor_i32(p.y / size),
            floor_i32(p.z / size),
        ])
    }
}

impl Hash for Voxel {
    fn hash<H: Hasher>(&self, state: &mut H) {
        // The spatial hash of Teschner et al. (2003), as KISS-ICP uses it.
        let [x, y, z] = self.0;
        let h = (x as u32).wrapping_mul(73_856_093)
            ^ (y as u32).wrapping_mul(19_349_669)
            ^ (z as u32).wrapping_mul(83_492_791);
        state.write_u32(h);
    }
}

/// A hasher for [`Voxel`] keys: spreads the spatial hash over 64 bits (Fibonacci hashing).
/// The same on every run, unlike the standard library's randomly seeded one.
#[derive(Default)]
pub struct VoxelHasher(u64);

impl Hasher for VoxelHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ b as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    fn write_u32(&mut self, v: u32) {
        self.0 = (self.0 ^ v as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
}

/// A hash map keyed by [`Voxel`] with the fixed [`VoxelHasher`].
pub type VoxelTable<V> = HashMap<Voxel, V, BuildHasherDefault<VoxelHasher>>;

/// The voxel-hash local map.
///
/// Invariants (checked by the tests): every voxel holds between 1 and `max_points_per_voxel`
/// points, each inside that voxel, and no two closer than the map resolution
/// `sqrt(voxel_size² / max_points_per_voxel)`.
#[derive(Clone, Debug)]
pub struct VoxelHashMap {
    voxel_size: f64,
    max_distance: f64,
    max_points_per_voxel: usize,
    map: VoxelTable<Vec<Vector3<f64>>>,
}

impl VoxelHashMap {
    /// An empty map of voxels of edge `voxel_size` that keeps voxels within `max_distance` of
    /// the last pose and at most `max_points_per_voxel` points in each.
    pub fn new(voxel_size: f64, max_distance: f64, max_points_per_voxel: usize) -> Self {
        VoxelHashMap {
            voxel_size,
            max_distance,
            max_points_per_voxel,
            map: VoxelTable::default(),
        }
    }

    /// The voxel edge, metres.
    pub fn voxel_size(&self) -> f64 {
        self.voxel_size
    }

    /// Whether the map holds no point.
    pub fn is_empty(&self) -> bool {
        self.map.is_empty()
    }

    /// Number of occupied voxels.
    pub fn voxel_count(&self) -> usize {
        self.map.len()
    }

    /// Number of points in the map.
    pub fn point_count(&self) -> usize {
        self.map.values().map(Vec::len).sum()
    }

    /// The occupied voxels and their points, ordered by voxel coordinates.
    pub fn voxels(&self) -> Vec<(Voxel, &[Vector3<f64>])> {
        let mut v: Vec<(Voxel, &[Vector3<f64>])> =
            self.map.iter().map(|(k, p)| (*k, p.as_slice())).collect();
        v.sort_by_key(|(k, _)| *k);
        v
    }

    /// The points of one voxel, or `None` when it is empty.
    pub fn cell(&self, voxel: &Voxel) -> Option<&[Vector3<f64>]> {
        self.map.get(voxel).map(Vec::as_slice)
    }

    /// Every point of the map, ordered by voxel coordinates, then by insertion.
    pub fn points(&self) -> Vec<Vector3<f64>> {
        self.voxels()
            .into_iter()
            .flat_map(|(_, p)| p.iter().copied())
            .collect()
    }

    /// Adds `points` (map frame) as KISS-ICP does: a point goes into its voxel unless the voxel
    /// is full or already holds a point closer than the map resolution.
    pub fn add_points(&mut self, points: &[Vector3<f64>]) {
        let resolution2 = self.voxel_size * self.voxel_size / self.max_points_per_voxel as f64;
        for p in points {
            let cell = self
                .map
                .entry(Voxel::of(p, self.voxel_size))
                .or_insert_with(|| Vec::with_capacity(self.max_points_per_voxel.min(32)));
            if cell.len() >= self.max_points_per_voxel
                || cell.iter().any(|q| (q - p).norm_squared() < resolution2)
            {
                continue;
            }
            cell.push(*p);
        }
    }

    /// Drops every voxel whose first point is `max_distance` or more from `origin`.
    pub fn remove_far_from(&mut self, origin: &Vector3<f64>) {
        let max2 = self.max_distance * self.max_distance;
        self.map
            .retain(|_, pts| (pts[0] - origin).norm_squared() < max2);
    }

    /// Moves `points` (scan frame) into the map frame with `pose`, adds them and drops what is
    /// out of range of the pose.
    pub fn update(&mut self, points: &[Vector3<f64>], pose: &Isometry3<f64>) {
        let moved: Vec<Vector3<f64>> = points
            .iter()
            .map(|p| (pose * Point3::from(*p)).coords)
            .collect();
        self.add_points(&moved);
        self.remove_far_from(&pose.translation.vector);
    }

    /// The map point closest to `p` among the 27 voxels around it and its squared distance,
    /// or `None` when they are empty. Ties go to the first point met (voxels in x, y, z order).
    pub fn closest(&self, p: &Vector3<f64>) -> Option<(Vector3<f64>, f64)> {
        let Voxel([x, y, z]) = Voxel::of(p, self.voxel_size);
        let mut best: Option<(Vector3<f64>, f64)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(cell) = self.map.get(&Voxel([x + dx, y + dy, z + dz])) else {
                        continue;
                    };
                    for q in cell {
                        let d2 = (q - p).norm_squared();
                        if best.is_none_or(|(_, b)| d2 < b) {
                            best = Some((*q, d2));
                        }
                    }
                }
            }
        }
        best
    }

    /// What [`closest`](Self::closest) finds, kept only when its squared distance is below
    /// `max2`: the same point, ties included, or `None`.
    ///
    /// Faster: the query's own voxel is searched first, and a neighbour voxel is not looked
    /// up when its box is no nearer than the best point so far or than `max2`. Ties between
    /// equally distant points still go to the voxel first in x, y, z order.
    pub fn closest_within(&self, p: &Vector3<f64>, max2: f64) -> Option<(Vector3<f64>, f64)> {
        let size = self.voxel_size;
        let Voxel([x, y, z]) = Voxel::of(p, size);
        // Squared distance from p to the slab of the neighbour at offset −1, 0, +1, per axis.
        let gaps = |c: i32, v: f64| -> [f64; 3] {
            let lo = v - c as f64 * size;
            let hi = (c + 1) as f64 * size - v;
            [lo * lo, 0.0, hi * hi]
        };
        let (gx, gy, gz) = (gaps(x, p.x), gaps(y, p.y), gaps(z, p.z));
        // (point, squared distance, rank of its voxel in x, y, z order)
        let mut best: Option<(Vector3<f64>, f64, usize)> = None;
        let scan = |best: &mut Option<(Vector3<f64>, f64, usize)>, cell: &[Vector3<f64>], rank| {
            for q in cell {
                let d2 = (q - p).norm_squared();
                if d2 < max2 && best.is_none_or(|(_, b, r)| d2 < b || (d2 == b && rank < r)) {
                    *best = Some((*q, d2, rank));
                }
            }
        };
        const OWN: usize = 13;
        if let Some(cell) = self.map.get(&Voxel([x, y, z])) {
            scan(&mut best, cell, OWN);
        }
        let mut rank = 0;
        for (ox, gx) in (-1..=1).zip(gx) {
            for (oy, gy) in (-1..=1).zip(gy) {
                for (oz, gz) in (-1..=1).zip(gz) {
                    let here = rank;
                    rank += 1;
                    if here == OWN {
                        continue;
                    }
                    let gap = gx + gy + gz;
                    if gap >= max2 || best.is_some_and(|(_, b, _)| gap > b) {
                        continue;
                    }
                    if let Some(cell) = self.map.get(&Voxel([x + ox, y + oy, z + oz])) {
                        scan(&mut best, cell, here);
                    }
                }
            }
        }
        best.map(|(q, d2, _)| (q, d2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn pts(raw: &[(f64, f64, f64)]) -> Vec<Vector3<f64>> {
        raw.iter().map(|&(x, y, z)| Vector3::new(x, y, z)).collect()
    }

    fn brute_closest(all: &[Vector3<f64>], p: &Vector3<f64>) -> f64 {
        all.iter()
            .map(|q| (q - p).norm_squared())
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn negative_coordinates_floor_into_their_own_voxel() {
        assert_eq!(
            Voxel::of(&Vector3::new(-0.1, 0.1, -1.0), 1.0),
            Voxel([-1, 0, -1])
        );
    }

    #[test]
    fn far_voxels_are_dropped() {
        let mut m = VoxelHashMap::new(1.0, 10.0, 5);
        m.add_points(&pts(&[(1.0, 0.0, 0.0), (20.0, 0.0, 0.0)]));
        m.remove_far_from(&Vector3::zeros());
        assert_eq!(m.points(), pts(&[(1.0, 0.0, 0.0)]));
    }

    proptest! {
        #[test]
        fn voxels_respect_capacity_membership_and_spacing(
            raw in prop::collection::vec((-5.0f64..5.0, -5.0f64..5.0, -2.0f64..2.0), 1..400),
            size in 0.3f64..2.0,
            cap in 1usize..8,
        ) {
            let mut m = VoxelHashMap::new(size, 1e9, cap);
            m.add_points(&pts(&raw));
            let res2 = size * size / cap as f64;
            for (v, ps) in m.voxels() {
                prop_assert!(!ps.is_empty() && ps.len() <= cap);
                for (i, p) in ps.iter().enumerate() {
                    prop_assert_eq!(Voxel::of(p, size), v);
                    for q in &ps[..i] {
                        prop_assert!((p - q).norm_squared() >= res2);
                    }
                }
            }
        }

        #[test]
        fn closest_agrees_with_brute_force_within_one_voxel(
            raw in prop::collection::vec((-5.0f64..5.0, -5.0f64..5.0, -2.0f64..2.0), 1..300),
            queries in prop::collection::vec((-5.0f64..5.0, -5.0f64..5.0, -2.0f64..2.0), 1..30),
        ) {
            let mut m = VoxelHashMap::new(1.0, 1e9, 1000);
            let all = pts(&raw);
            m.add_points(&all);
            let kept = m.points();
            for q in pts(&queries) {
                let truth = brute_closest(&kept, &q);
                match m.closest(&q) {
                    Some((_, d2)) => {
                        prop_assert!(d2 >= truth - 1e-12);
                        if truth < 1.0 {
                            prop_assert!((d2 - truth).abs() < 1e-12);
                        }
                    }
                    None => prop_assert!(truth >= 1.0),
                }
            }
        }

        #[test]
        fn closest_within_is_closest_below_the_bound(
            raw in prop::collection::vec((-3.0f64..3.0, -3.0f64..3.0, -1.0f64..1.0), 1..300),
            queries in prop::collection::vec((-3.0f64..3.0, -3.0f64..3.0, -1.0f64..1.0), 1..30),
            size in 0.3f64..1.5,
            bound in 0.01f64..2.0,
            grid in any::<bool>(),
        ) {
            // On a grid many points tie for closest; they must resolve as in `closest`.
            let snap = |v: f64| if grid { (v * 4.0).round() / 4.0 } else { v };
            let raw: Vec<(f64, f64, f64)> =
                raw.iter().map(|&(x, y, z)| (snap(x), snap(y), snap(z))).collect();
            let mut m = VoxelHashMap::new(size, 1e9, 20);
            m.add_points(&pts(&raw));
            let max2 = bound * bound;
            for q in pts(&queries) {
                let q = q.map(snap);
                let slow = m.closest(&q).filter(|&(_, d2)| d2 < max2);
                prop_assert_eq!(m.closest_within(&q, max2), slow);
            }
        }
    }
}
