//! Points grouped by the voxel (a cube of a given edge, aligned to the origin) they fall
//! into, in linear time: voxels are numbered by a hash table in the order their first point
//! appears, then the point indices are placed by a counting sort on that number. The members
//! of a voxel are one contiguous, ascending slice.
//!
//! Used by the plane RANSAC's triple sampling (the points of a coarse cell).
//!
//! Not for: neighbour queries across voxels (see [`crate::cloud::cluster`]), or points with a
//! non-finite coordinate (the caller drops them first).

use crate::numerics::floor::floor_f32_i32;

/// Point indices grouped by voxel. See the module documentation.
#[derive(Clone, Debug)]
pub struct VoxelGroups {
    /// Point indices grouped by voxel, ascending within a voxel.
    order: Vec<u32>,
    /// Per voxel `g`: its slice of `order` is `start[g]..start[g + 1]`.
    start: Vec<u32>,
    /// Per point: its voxel.
    group_of: Vec<u32>,
}

impl VoxelGroups {
    /// Groups `points` (finite coordinates; at most `u32::MAX` of them) by voxels of edge
    /// `edge` (positive). A coordinate beyond `edge · 2³¹` shares the outermost voxel of its
    /// axis.
    pub fn new(points: &[[f32; 3]], edge: f32) -> Self {
        let inv = 1.0 / edge;
        let m = points.len();
        // Open addressing with linear probing, at most half full; a slot holds a voxel number
        // and the voxel's coordinates are kept once per voxel.
        let slots = (2 * m).next_power_of_two().max(2);
        let mask = slots - 1;
        let mut table: Vec<u32> = vec![u32::MAX; slots];
        let mut key_of: Vec<[i32; 3]> = Vec::new();
        let mut count: Vec<u32> = Vec::new();
        let mut group_of: Vec<u32> = Vec::with_capacity(m);
        for p in points {
            let key = [
                floor_f32_i32(p[0] * inv),
                floor_f32_i32(p[1] * inv),
                floor_f32_i32(p[2] * inv),
            ];
            let mut slot = voxel_hash(key) as usize & mask;
            let id = loop {
                let id = table[slot];
                if id == u32::MAX {
                    let id = key_of.len() as u32;
                    table[slot] = id;
                    key_of.push(key);
                    count.push(0);
                    break id;
                }
                if key_of[id as usize] == key {
                    break id;
                }
                slot = (slot + 1) & mask;
            };
            count[id as usize] += 1;
            group_of.push(id);
        }
        // Start of every voxel's run, then the indices in ascending order into their runs.
        let mut start: Vec<u32> = Vec::with_capacity(count.len() + 1);
        let mut acc = 0u32;
        for &c in &count {
            start.push(acc);
            acc += c;
        }
        start.push(acc);
        let mut next = start.clone();
        let mut order = vec![0u32; m];
        for (i, &id) in group_of.iter().enumerate() {
            let id = id as usize;
            order[next[id] as usize] = i as u32;
            next[id] += 1;
        }
        VoxelGroups {
            order,
            start,
            group_of,
        }
    }

    /// Number of occupied voxels.
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    /// Whether no point was grouped.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The points of voxel `g`, ascending (never empty).
    pub fn members(&self, g: usize) -> &[u32] {
        &self.order[self.start[g] as usize..self.start[g + 1] as usize]
    }

    /// The voxel of point `i`.
    pub fn group_of(&self, i: usize) -> usize {
        self.group_of[i] as usize
    }
}

/// A 64-bit mix of a voxel's three coordinates.
#[inline]
fn voxel_hash(key: [i32; 3]) -> u64 {
    let packed =
        (key[0] as u32 as u64) ^ ((key[1] as u32 as u64) << 21) ^ ((key[2] as u32 as u64) << 42);
    crate::rng::mix64(packed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn members_are_the_points_of_each_voxel_ascending() {
        let p = [
            [0.1, 0.1, 0.1],
            [1.5, 0.2, 0.3],
            [0.9, 0.9, 0.0],
            [-0.1, 0.5, 0.5],
            [1.2, 0.8, 0.9],
        ];
        let g = VoxelGroups::new(&p, 1.0);
        assert_eq!(g.len(), 3);
        assert_eq!(g.members(0), &[0, 2]);
        assert_eq!(g.members(1), &[1, 4]);
        assert_eq!(g.members(2), &[3]);
        assert_eq!(g.group_of(4), 1);
        assert!(VoxelGroups::new(&[], 1.0).is_empty());
    }

    proptest! {
        /// Against the definition: two points share a group exactly when their floored
        /// coordinates agree; groups are numbered by first appearance.
        #[test]
        fn groups_are_the_voxels(
            pts in prop::collection::vec(prop::array::uniform3(-5.0f32..5.0), 0..200),
            edge in 0.3f32..3.0,
        ) {
            let g = VoxelGroups::new(&pts, edge);
            let key = |p: &[f32; 3]| p.map(|v| (v * (1.0 / edge)).floor() as i32);
            let mut seen: Vec<[i32; 3]> = Vec::new();
            for (i, p) in pts.iter().enumerate() {
                let k = key(p);
                let first = seen.iter().position(|s| *s == k).unwrap_or_else(|| {
                    seen.push(k);
                    seen.len() - 1
                });
                prop_assert_eq!(g.group_of(i), first);
            }
            prop_assert_eq!(g.len(), seen.len());
            for (v, k) in seen.iter().enumerate() {
                let want: Vec<u32> = (0..pts.len() as u32)
                    .filter(|&i| key(&pts[i as usize]) == *k)
                    .collect();
                prop_assert_eq!(g.members(v), &want[..]);
            }
        }
    }
}
