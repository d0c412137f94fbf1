//! Points grouped by the voxel (a cube of a given edge, aligned to the origin) they fall
//! into, in linear time: voxels are numbered in the order their first point appears (on a
//! dense array over the points' bounding box of voxels when that box is small, else by a hash
//! table), then the point indices are placed by a counting sort on that number. The members
//! of a voxel are one contiguous, ascending slice.
//!
//! Used by the plane RANSAC's triple sampling (the points of a coarse cell) and by the wall
//! rounds' bird's-eye grid (the pool's points laid flat); its numbering by first appearance
//! (`number_by_first_appearance`) also numbers the exact clustering's components.
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
        let coords = floor_scaled(points.as_flattened(), 1.0 / edge);
        let (keys, _) = coords.as_chunks::<3>();
        let (group_of, count) = match dense_extent(keys) {
            Some((lo, span)) => number_on_grid(keys, lo, span),
            None => number_by_hash(keys),
        };
        let m = points.len();
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
        // Run by run: points in scan order come in runs of one voxel, and an increment per
        // point would wait for the one before it.
        let mut first = 0u32;
        for run in group_of.chunk_by(|a, b| a == b) {
            let id = run[0] as usize;
            let to = next[id] as usize;
            for (k, slot) in (first..).zip(&mut order[to..to + run.len()]) {
                *slot = k;
            }
            next[id] += run.len() as u32;
            first += run.len() as u32;
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

/// `⌊v · inv⌋` of every coordinate, as `floor_f32_i32` gives it; on x86-64 with AVX2 eight
/// lanes at a time (a rounding instruction and a saturating conversion: the same integers).
fn floor_scaled(v: &[f32], inv: f32) -> Vec<i32> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has just been found to support AVX2.
        return unsafe { floor_scaled_avx2(v, inv) };
    }
    v.iter().map(|&x| floor_f32_i32(x * inv)).collect()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn floor_scaled_avx2(v: &[f32], inv: f32) -> Vec<i32> {
    // With AVX2 (and so SSE4.1) `floor` is an instruction, not a call.
    v.iter().map(|&x| (x * inv).floor() as i32).collect()
}

/// The keys' smallest corner and their extent per axis, when a dense array over that box
/// (at most [`DENSE_CELLS`] voxels, and no more than 16 per point) is cheaper than hashing.
fn dense_extent(keys: &[[i32; 3]]) -> Option<([i32; 3], [usize; 3])> {
    let first = keys.first()?;
    let (mut lo, mut hi) = (*first, *first);
    for k in keys {
        for a in 0..3 {
            lo[a] = lo[a].min(k[a]);
            hi[a] = hi[a].max(k[a]);
        }
    }
    let span: [usize; 3] = std::array::from_fn(|a| (hi[a] as i64 - lo[a] as i64 + 1) as usize);
    let cells = span.iter().try_fold(1usize, |acc, &s| acc.checked_mul(s))?;
    (cells <= DENSE_CELLS && cells <= 16 * keys.len()).then_some((lo, span))
}

/// Largest dense array of voxel numbers [`VoxelGroups::new`] allocates.
const DENSE_CELLS: usize = 1 << 20;

/// Voxel numbers in order of first appearance, and each voxel's count, from a dense array over
/// the keys' box.
fn number_on_grid(keys: &[[i32; 3]], lo: [i32; 3], span: [usize; 3]) -> (Vec<u32>, Vec<u32>) {
    let slots = keys.iter().map(|k| {
        ((k[2] - lo[2]) as usize * span[1] + (k[1] - lo[1]) as usize) * span[0]
            + (k[0] - lo[0]) as usize
    });
    number_by_first_appearance(slots, span[0] * span[1] * span[2])
}

/// For items that each name a slot in `0..slot_count`: the slots numbered in the order their
/// first item appears, every item's number, and how many items each number has. Used for the
/// voxels of a dense grid and for the components of [`crate::cloud::cluster`].
pub(crate) fn number_by_first_appearance(
    slots: impl ExactSizeIterator<Item = usize>,
    slot_count: usize,
) -> (Vec<u32>, Vec<u32>) {
    let mut number_at = vec![u32::MAX; slot_count];
    let mut numbers = 0u32;
    let mut number_of = vec![0u32; slots.len()];
    for (n, at) in number_of.iter_mut().zip(slots) {
        let slot = &mut number_at[at];
        if *slot == u32::MAX {
            *slot = numbers;
            numbers += 1;
        }
        *n = *slot;
    }
    // The counts in a pass of their own, run by run: the numbering's loop then carries no
    // store that the next item may have to wait for, and neither does this one (items in
    // scan order come in runs of one number).
    let mut count = vec![0u32; numbers as usize];
    for run in number_of.chunk_by(|a, b| a == b) {
        count[run[0] as usize] += run.len() as u32;
    }
    (number_of, count)
}

/// Voxel numbers in order of first appearance, and each voxel's count, by open addressing
/// with linear probing (at most half full; a slot holds a voxel number and the voxel's
/// coordinates are kept once per voxel).
fn number_by_hash(keys: &[[i32; 3]]) -> (Vec<u32>, Vec<u32>) {
    let slots = (2 * keys.len()).next_power_of_two().max(2);
    let mask = slots - 1;
    let mut table: Vec<u32> = vec![u32::MAX; slots];
    let mut key_of: Vec<[i32; 3]> = Vec::new();
    let mut count: Vec<u32> = Vec::new();
    let mut group_of: Vec<u32> = Vec::with_capacity(keys.len());
    for &key in keys {
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
    (group_of, count)
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

    #[test]
    fn far_apart_points_are_grouped_by_hashing_alike() {
        // A box of 2·10⁶ voxels a side: too large for the dense array.
        let p: [[f32; 3]; 4] = [
            [1e6, 0.0, 0.0],
            [-1e6, 0.5, 0.0],
            [1e6, 0.2, 0.9],
            [-1e6, 0.0, 0.1],
        ];
        let keys: Vec<[i32; 3]> = p.iter().map(|q| q.map(|v| v.floor() as i32)).collect();
        assert!(dense_extent(&keys).is_none());
        let g = VoxelGroups::new(&p, 1.0);
        assert_eq!(g.len(), 2);
        assert_eq!(g.members(0), &[0, 2]);
        assert_eq!(g.members(1), &[1, 3]);
    }

    proptest! {
        /// The lanes' floors are `floor_f32_i32`'s, out to the saturated ends.
        #[test]
        fn lane_floors_are_the_scalar_ones(
            v in prop::collection::vec(prop_oneof![-5.0f32..5.0, -1e12f32..1e12], 0..100),
            inv in prop_oneof![Just(0.5f32), 0.01f32..100.0],
        ) {
            let want: Vec<i32> = v.iter().map(|&x| floor_f32_i32(x * inv)).collect();
            prop_assert_eq!(floor_scaled(&v, inv), want);
        }

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
