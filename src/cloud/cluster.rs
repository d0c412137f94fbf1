//! Euclidean clustering of a point cloud: the connected components of the graph that joins
//! every two points at most `tolerance` apart (`dx² + dy² + dz² ≤ tolerance²` in f32). They
//! are found exactly on a voxel grid of edge `tolerance/√3` (every cell is connected within
//! itself; neighbouring cells are joined by a union-find when one point pair is close enough),
//! or by flood fill over a k-d tree (kiddo) when the grid does not apply (zero tolerance).
//! Each kept component becomes a [`Cluster`] with its point indices, centroid and
//! axis-aligned extent — the object detections of a lidar frame once ground and walls have
//! been removed.
//!
//! Not for: ground or plane removal, shape fitting, or tracking the clusters over time.

use super::voxel_groups::number_by_first_appearance;
use super::PointCloud;
use crate::error::{Error, Result};
use kiddo::{ImmutableKdTree, SquaredEuclidean};

/// Parameters of [`euclidean_clusters`].
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClusterParams {
    /// Largest distance between two neighbouring points of one cluster, metres (inclusive).
    pub tolerance: f32,
    /// Smallest number of points of a kept cluster.
    pub min_points: usize,
    /// Largest number of points of a kept cluster; larger components are dropped.
    pub max_points: usize,
}

impl Default for ClusterParams {
    /// tolerance 0.5 m, 10 to 100 000 points.
    fn default() -> Self {
        ClusterParams {
            tolerance: 0.5,
            min_points: 10,
            max_points: 100_000,
        }
    }
}

impl ClusterParams {
    fn validate(&self) -> Result<()> {
        if !(self.tolerance.is_finite() && self.tolerance >= 0.0) {
            return Err(Error::invalid(
                "cluster tolerance",
                format!("{} (must be finite and non-negative)", self.tolerance),
            ));
        }
        if self.min_points > self.max_points {
            return Err(Error::invalid(
                "cluster size limits",
                format!(
                    "min_points {} > max_points {}",
                    self.min_points, self.max_points
                ),
            ));
        }
        Ok(())
    }
}

/// One Euclidean cluster.
#[derive(Clone, Debug, PartialEq)]
pub struct Cluster {
    /// Indices of the member points in the cloud, ascending.
    pub indices: Vec<u32>,
    /// Mean position of the members (accumulated in f64).
    pub centroid: [f64; 3],
    /// Smallest x, y, z of the members (corner of the axis-aligned extent box).
    pub min: [f32; 3],
    /// Largest x, y, z of the members.
    pub max: [f32; 3],
    /// Number of members (`indices.len()`).
    pub count: usize,
}

/// Clusters the whole cloud. Points with a non-finite coordinate belong to no cluster.
///
/// Clusters are returned in ascending order of their smallest point index; indices inside a
/// cluster are ascending. The result does not depend on the order of the k-d tree queries.
pub fn euclidean_clusters(cloud: &PointCloud, params: &ClusterParams) -> Result<Vec<Cluster>> {
    params.validate()?;
    if cloud.len() > u32::MAX as usize {
        return Err(Error::invalid(
            "cluster input",
            format!("{} points (at most 2³² − 1)", cloud.len()),
        ));
    }
    let all: Vec<u32> = (0..cloud.len() as u32).collect();
    Ok(cluster_indices(cloud, &all, params))
}

/// Clusters the points of `cloud` listed in `indices` (e.g. the points left after removing
/// the ground). Duplicate indices count once; an index out of range is an error. Returned
/// indices refer to `cloud`; order as in [`euclidean_clusters`].
pub fn euclidean_clusters_of(
    cloud: &PointCloud,
    indices: &[u32],
    params: &ClusterParams,
) -> Result<Vec<Cluster>> {
    params.validate()?;
    if let Some(&bad) = indices.iter().find(|&&i| i as usize >= cloud.len()) {
        return Err(Error::invalid(
            "cluster indices",
            format!(
                "index {bad} out of range for a cloud of {} points",
                cloud.len()
            ),
        ));
    }
    let mut sorted = indices.to_vec();
    sorted.sort_unstable();
    sorted.dedup();
    Ok(cluster_indices(cloud, &sorted, params))
}

/// Components of `subset` (ascending, distinct, in range), size-filtered and summarised.
fn cluster_indices(cloud: &PointCloud, subset: &[u32], params: &ClusterParams) -> Vec<Cluster> {
    let (xs, ys, zs, _) = cloud.columns();
    // local position → cloud index, finite points only
    let members: Vec<u32> = subset
        .iter()
        .copied()
        .filter(|&i| {
            let i = i as usize;
            xs[i].is_finite() && ys[i].is_finite() && zs[i].is_finite()
        })
        .collect();
    if members.is_empty() {
        return Vec::new();
    }
    let points: Vec<[f32; 3]> = members
        .iter()
        .map(|&i| {
            let i = i as usize;
            [xs[i], ys[i], zs[i]]
        })
        .collect();
    let labels = grid_components(&points, params.tolerance)
        .unwrap_or_else(|| kdtree_components(&points, params.tolerance));
    // Number the components by their first (smallest) local position, then bucket the
    // members: local positions ascend with cloud indices, so clusters come out ordered by
    // smallest index with ascending indices inside.
    let (of_point, sizes) =
        number_by_first_appearance(labels.iter().map(|&l| l as usize), points.len());
    let kept = |n: u32| (params.min_points..=params.max_points).contains(&(n as usize));
    let mut buckets: Vec<Vec<u32>> = sizes
        .iter()
        .map(|&n| {
            if kept(n) {
                Vec::with_capacity(n as usize)
            } else {
                Vec::new()
            }
        })
        .collect();
    for (&o, &cloud_index) in of_point.iter().zip(&members) {
        if kept(sizes[o as usize]) {
            buckets[o as usize].push(cloud_index);
        }
    }
    buckets
        .into_iter()
        .filter(|b| !b.is_empty())
        .map(|b| summarise(b.into_iter(), xs, ys, zs))
        .collect()
}

/// Cells per axis above which the grid is not used (so that the mixed-radix keys stay below
/// 2⁶³).
const GRID_AXIS_LIMIT: f64 = ((1u64 << 21) - 8) as f64;

/// Components by a voxel grid: a component label (a local position) for every point, or
/// `None` when the tolerance is zero or the cloud spans too many cells for the packed keys.
///
/// Cells have edge `tolerance/√3` (shrunk by 10⁻⁴ against rounding), so any two points of a
/// cell are within the tolerance and each occupied cell is connected as a whole. Two points
/// within the tolerance lie at most two cells apart on every axis, so only the 124
/// surrounding cells can hold a neighbour; each pair of occupied cells is examined once (the
/// 62 "forward" offsets) and joined in a union-find as soon as one point pair is within the
/// tolerance, with the same `dx² + dy² + dz² ≤ tol²` test (f32) as the definition. Cells are
/// sorted by key (z, y, x major to minor); for each forward row offset a cursor walks
/// the sorted cells in step with the current cell, so neighbours are found without hashing.
fn grid_components(points: &[[f32; 3]], tolerance: f32) -> Option<Vec<u32>> {
    if tolerance <= 0.0 {
        return None;
    }
    let r2 = tolerance * tolerance;
    let cell = tolerance as f64 / 3f64.sqrt() * (1.0 - 1e-4);
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a] as f64);
            hi[a] = hi[a].max(p[a] as f64);
        }
    }
    let inv = 1.0 / cell;
    // (The points are finite, so the extents are too.)
    if (0..3).any(|a| (hi[a] - lo[a]) * inv >= GRID_AXIS_LIMIT) {
        return None;
    }
    // Cell coordinates start at 2 so that offsets down to −2 stay non-negative, and each
    // axis has room up to 2 past its last cell; keys are mixed-radix (z, y, x major to
    // minor), so their order is that of the cells' coordinates and a neighbour's key is the
    // cell's plus a fixed offset.
    let span = |a: usize| ((hi[a] - lo[a]) * inv) as u64 + 5;
    let (nx, ny) = (span(0), span(1));
    let key_of = |p: &[f32; 3]| -> u64 {
        let c = |a: usize| (((p[a] as f64 - lo[a]) * inv) as u64) + 2;
        (c(2) * ny + c(1)) * nx + c(0)
    };
    // (cell key, local position), sorted by key with positions ascending inside a cell: a
    // stable radix sort of the keys taken in position order (only the keys' occupied bytes
    // are passed over).
    let mut order: Vec<(u64, u32)> = points
        .iter()
        .enumerate()
        .map(|(i, p)| (key_of(p), i as u32))
        .collect();
    radsort::sort_by_key(&mut order, |&(key, _)| key);
    // Occupied cells: key and range into `sorted`.
    let sorted: Vec<[f32; 3]> = order.iter().map(|&(_, i)| points[i as usize]).collect();
    let mut cell_keys: Vec<u64> = Vec::new();
    let mut cell_start: Vec<u32> = Vec::new();
    for (k, &(key, _)) in order.iter().enumerate() {
        if cell_keys.last() != Some(&key) {
            cell_keys.push(key);
            cell_start.push(k as u32);
        }
    }
    cell_start.push(order.len() as u32);
    let n_cells = cell_keys.len();
    let members = |c: usize| &sorted[cell_start[c] as usize..cell_start[c + 1] as usize];
    // The tight box of each cell's points. Two cells whose boxes lie farther apart than the
    // tolerance cannot touch, two whose boxes lie within it everywhere do, and a point farther
    // from the other cell's box than the tolerance has no neighbour there. f32 subtraction,
    // squaring and addition are monotone, so these bounds, computed in the order of the
    // point test, never decide otherwise than the point pairs would.
    let boxes: Vec<CellBox> = (0..n_cells).map(|c| CellBox::of(members(c))).collect();
    let touches = |a: usize, b: usize| {
        let (ba, bb) = (&boxes[a], &boxes[b]);
        if ba.gap2(bb) > r2 {
            return false;
        }
        if ba.span2(bb) <= r2 {
            return true;
        }
        let pb = members(b);
        members(a).iter().any(|p| {
            bb.gap2_to(p) <= r2
                && pb.iter().any(|q| {
                    let (dx, dy, dz) = (p[0] - q[0], p[1] - q[1], p[2] - q[2]);
                    dx * dx + dy * dy + dz * dz <= r2
                })
        })
    };
    let mut parent: Vec<u32> = (0..n_cells as u32).collect();
    fn find(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            let up = parent[parent[i as usize] as usize];
            parent[i as usize] = up;
            i = up;
        }
        i
    }
    // Forward rows: (dy, dz) with dz > 0, or dz = 0 and dy > 0; dx from −2 to 2.
    let (nx, ny) = (nx as i64, ny as i64);
    let rows: Vec<u64> = (0..=2i64)
        .flat_map(|dz| (-2..=2i64).map(move |dy| (dz, dy)))
        .filter(|&(dz, dy)| dz > 0 || dy > 0)
        .map(|(dz, dy)| ((dz * ny + dy) * nx) as u64)
        .collect();
    let mut cursors = vec![0usize; rows.len()];
    for c in 0..n_cells {
        let key = cell_keys[c];
        // The root of `c`'s set: only this cell's own unions below change it, and a union
        // makes the smaller root the root of both (so every root is its set's smallest cell).
        let mut rc = find(&mut parent, c as u32);
        let mut visit = |d: usize, parent: &mut Vec<u32>| {
            let rd = find(parent, d as u32);
            if rc != rd && touches(c, d) {
                parent[rc.max(rd) as usize] = rc.min(rd);
                rc = rc.min(rd);
            }
        };
        // Same row, dx = 1, 2.
        for d in c + 1..c + 1 + count_up_to(&cell_keys[c + 1..], key + 2) {
            visit(d, &mut parent);
        }
        for (row, cur) in rows.iter().zip(cursors.iter_mut()) {
            // Cell (x − 2, y + dy, z + dz); no coordinate under- or overflows its axis
            // (coordinates start at 2 and stay 2 below the axis' span).
            let start = key + row - 2;
            *cur += count_up_to(&cell_keys[*cur..], start - 1);
            for d in *cur..*cur + count_up_to(&cell_keys[*cur..], start + 4) {
                visit(d, &mut parent);
            }
        }
    }
    let mut labels = vec![0u32; points.len()];
    for c in 0..n_cells {
        let root = find(&mut parent, c as u32);
        // Any point of the root cell labels the whole component.
        let rep = order[cell_start[root as usize] as usize].1;
        for &(_, i) in &order[cell_start[c] as usize..cell_start[c + 1] as usize] {
            labels[i as usize] = rep;
        }
    }
    Some(labels)
}

/// How many of the ascending `keys` are at most `limit`, counted four at a time: the
/// cursors of [`grid_components`] mostly move by a few cells, and a count of comparisons
/// costs less there than a loop that branches on each one.
fn count_up_to(keys: &[u64], limit: u64) -> usize {
    let mut n = 0;
    while let Some(four) = keys.get(n..n + 4) {
        let k = four.iter().map(|&v| usize::from(v <= limit)).sum::<usize>();
        n += k;
        if k < 4 {
            return n;
        }
    }
    n + keys[n..].iter().take_while(|&&v| v <= limit).count()
}

/// Axis-aligned box of one grid cell's points.
struct CellBox {
    lo: [f32; 3],
    hi: [f32; 3],
}

impl CellBox {
    fn of(points: &[[f32; 3]]) -> Self {
        let mut b = CellBox {
            lo: [f32::INFINITY; 3],
            hi: [f32::NEG_INFINITY; 3],
        };
        for p in points {
            b.lo = std::array::from_fn(|a| b.lo[a].min(p[a]));
            b.hi = std::array::from_fn(|a| b.hi[a].max(p[a]));
        }
        b
    }

    /// Squared distance between the boxes (a lower bound of every point pair's, as the point
    /// test computes it).
    fn gap2(&self, other: &CellBox) -> f32 {
        let g = |a: usize| {
            (other.lo[a] - self.hi[a])
                .max(self.lo[a] - other.hi[a])
                .max(0.0)
        };
        let (gx, gy, gz) = (g(0), g(1), g(2));
        gx * gx + gy * gy + gz * gz
    }

    /// Squared largest distance between the boxes (an upper bound of every point pair's).
    fn span2(&self, other: &CellBox) -> f32 {
        let s = |a: usize| (other.hi[a] - self.lo[a]).max(self.hi[a] - other.lo[a]);
        let (sx, sy, sz) = (s(0), s(1), s(2));
        sx * sx + sy * sy + sz * sz
    }

    /// Squared distance from `p` to the box (a lower bound of its distance to every point).
    fn gap2_to(&self, p: &[f32; 3]) -> f32 {
        let g = |a: usize| (self.lo[a] - p[a]).max(p[a] - self.hi[a]).max(0.0);
        let (gx, gy, gz) = (g(0), g(1), g(2));
        gx * gx + gy * gy + gz * gz
    }
}

/// Components by flood fill over a k-d tree (kiddo): a component label (a local position)
/// for every point. Used when the grid cannot be (zero tolerance, enormous extent).
fn kdtree_components(points: &[[f32; 3]], tolerance: f32) -> Vec<u32> {
    let mut labels = vec![u32::MAX; points.len()];
    let tree = match ImmutableKdTree::<f32, 3>::new_from_slice(points) {
        Ok(t) => t,
        // Each point alone (kiddo refuses only degenerate inputs).
        Err(_) => return (0..points.len() as u32).collect(),
    };
    let r2 = tolerance * tolerance;
    let mut queue: Vec<u32> = Vec::new();
    for seed in 0..points.len() {
        if labels[seed] != u32::MAX {
            continue;
        }
        labels[seed] = seed as u32;
        queue.push(seed as u32);
        while let Some(local) = queue.pop() {
            tree.query(&points[local as usize])
                .within::<SquaredEuclidean<f32>>(r2)
                .unsorted()
                .visit(|hit| {
                    let j = hit.item as usize;
                    if labels[j] == u32::MAX {
                        labels[j] = seed as u32;
                        queue.push(j as u32);
                    }
                });
        }
    }
    labels
}

/// The cluster of the points `indices` (in that order): their centroid and axis-aligned extent.
pub(crate) fn summarise(
    indices: impl Iterator<Item = u32>,
    xs: &[f32],
    ys: &[f32],
    zs: &[f32],
) -> Cluster {
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    let mut sum = [0.0f64; 3];
    let mut list = Vec::new();
    for i in indices {
        let p = [xs[i as usize], ys[i as usize], zs[i as usize]];
        for a in 0..3 {
            min[a] = min[a].min(p[a]);
            max[a] = max[a].max(p[a]);
            sum[a] += p[a] as f64;
        }
        list.push(i);
    }
    let n = list.len();
    let inv = 1.0 / n as f64;
    Cluster {
        indices: list,
        centroid: [sum[0] * inv, sum[1] * inv, sum[2] * inv],
        min,
        max,
        count: n,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;
    use rand::RngExt;

    /// O(n²) union-find reference: the partition of `subset` into components.
    fn brute_force(cloud: &PointCloud, subset: &[u32], tol: f32) -> Vec<Vec<u32>> {
        let (xs, ys, zs, _) = cloud.columns();
        let n = subset.len();
        let mut parent: Vec<usize> = (0..n).collect();
        fn find(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        for a in 0..n {
            for b in a + 1..n {
                let (i, j) = (subset[a] as usize, subset[b] as usize);
                let (dx, dy, dz) = (xs[i] - xs[j], ys[i] - ys[j], zs[i] - zs[j]);
                if dx * dx + dy * dy + dz * dz <= tol * tol {
                    let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                    parent[ra.max(rb)] = ra.min(rb);
                }
            }
        }
        let mut groups: std::collections::BTreeMap<usize, Vec<u32>> = Default::default();
        for (a, &idx) in subset.iter().enumerate() {
            let r = find(&mut parent, a);
            groups.entry(r).or_default().push(idx);
        }
        let mut out: Vec<Vec<u32>> = groups.into_values().collect();
        for g in &mut out {
            g.sort_unstable();
        }
        out.sort_by_key(|g| g[0]);
        out
    }

    fn random_cloud(rng: &mut crate::rng::FilterRng, n: usize, side: f32) -> PointCloud {
        let mut c = PointCloud::with_capacity(n);
        for _ in 0..n {
            c.push(
                rng.random_range(0.0..side),
                rng.random_range(0.0..side),
                rng.random_range(0.0..side * 0.2),
                0.0,
            );
        }
        c
    }

    #[test]
    fn matches_brute_force_on_random_clouds() {
        let mut rng = seeded(42);
        for trial in 0..60 {
            let n = rng.random_range(1..=500usize);
            let side = rng.random_range(2.0f32..20.0);
            let cloud = random_cloud(&mut rng, n, side);
            let tol = rng.random_range(0.2f32..1.5);
            let params = ClusterParams {
                tolerance: tol,
                min_points: 1,
                max_points: usize::MAX,
            };
            let got: Vec<Vec<u32>> = euclidean_clusters(&cloud, &params)
                .unwrap()
                .into_iter()
                .map(|c| c.indices)
                .collect();
            let all: Vec<u32> = (0..n as u32).collect();
            assert_eq!(got, brute_force(&cloud, &all, tol), "trial {trial}");
            // a random subset, given unsorted and with duplicates
            let mut subset: Vec<u32> = (0..n as u32).filter(|_| rng.random_bool(0.6)).collect();
            let reference = brute_force(&cloud, &subset, tol);
            subset.reverse();
            if let Some(&first) = subset.first() {
                subset.push(first);
            }
            let got: Vec<Vec<u32>> = euclidean_clusters_of(&cloud, &subset, &params)
                .unwrap()
                .into_iter()
                .map(|c| c.indices)
                .collect();
            assert_eq!(got, reference, "subset trial {trial}");
        }
    }

    /// Partition of local positions implied by a label vector, in the reference's order.
    fn partition(labels: &[u32]) -> Vec<Vec<u32>> {
        let mut groups: std::collections::BTreeMap<u32, Vec<u32>> = Default::default();
        for (i, &l) in labels.iter().enumerate() {
            groups.entry(l).or_default().push(i as u32);
        }
        let mut out: Vec<Vec<u32>> = groups.into_values().collect();
        out.sort_by_key(|g| g[0]);
        out
    }

    #[test]
    fn grid_matches_brute_force_on_dense_blobs_and_boundary_distances() {
        let mut rng = seeded(8);
        for trial in 0..20 {
            // Dense blobs (many points per cell) plus points on a lattice whose spacing is
            // exactly the tolerance, so that many pairs sit on the boundary of the test.
            let tol = rng.random_range(0.1f32..1.0);
            let mut cloud = PointCloud::new();
            for _ in 0..4 {
                let c: [f32; 3] = [
                    rng.random_range(0.0..10.0),
                    rng.random_range(0.0..10.0),
                    rng.random_range(0.0..2.0),
                ];
                for _ in 0..150 {
                    cloud.push(
                        c[0] + rng.random_range(-0.5..0.5),
                        c[1] + rng.random_range(-0.5..0.5),
                        c[2] + rng.random_range(-0.2..0.2),
                        0.0,
                    );
                }
            }
            for i in 0..10 {
                for j in 0..3 {
                    cloud.push(20.0 + i as f32 * tol, j as f32 * tol * 1.5, 1.0, 0.0);
                }
            }
            let (xs, ys, zs, _) = cloud.columns();
            let pts: Vec<[f32; 3]> = (0..cloud.len()).map(|i| [xs[i], ys[i], zs[i]]).collect();
            let all: Vec<u32> = (0..cloud.len() as u32).collect();
            let want = brute_force(&cloud, &all, tol);
            let grid = grid_components(&pts, tol).expect("grid applies");
            assert_eq!(partition(&grid), want, "grid, trial {trial}");
            assert_eq!(
                partition(&kdtree_components(&pts, tol)),
                want,
                "k-d tree, trial {trial}"
            );
        }
    }

    #[test]
    fn zero_tolerance_and_huge_extent_use_the_kdtree() {
        let mut cloud = PointCloud::new();
        cloud.push(1.0, 1.0, 1.0, 0.0);
        cloud.push(1.0, 1.0, 1.0, 0.0);
        cloud.push(1.0, 1.0, 1.5, 0.0);
        cloud.push(3.0e9, 0.0, 0.0, 0.0);
        cloud.push(3.0e9, 0.0, 0.0, 0.0);
        let (xs, ys, zs, _) = cloud.columns();
        let pts: Vec<[f32; 3]> = (0..cloud.len()).map(|i| [xs[i], ys[i], zs[i]]).collect();
        assert!(grid_components(&pts, 0.0).is_none());
        assert!(grid_components(&pts, 0.5).is_none());
        let params = |tolerance| ClusterParams {
            tolerance,
            min_points: 1,
            max_points: 10,
        };
        let sets = |tol| -> Vec<Vec<u32>> {
            euclidean_clusters(&cloud, &params(tol))
                .unwrap()
                .into_iter()
                .map(|c| c.indices)
                .collect()
        };
        assert_eq!(sets(0.0), vec![vec![0, 1], vec![2], vec![3, 4]]);
        assert_eq!(sets(0.5), vec![vec![0, 1, 2], vec![3, 4]]);
    }

    #[test]
    fn size_limits_filter_components() {
        let mut rng = seeded(5);
        let cloud = random_cloud(&mut rng, 400, 12.0);
        let params = ClusterParams {
            tolerance: 0.8,
            min_points: 3,
            max_points: 20,
        };
        let all: Vec<u32> = (0..400).collect();
        let want: Vec<Vec<u32>> = brute_force(&cloud, &all, 0.8)
            .into_iter()
            .filter(|g| (3..=20).contains(&g.len()))
            .collect();
        let got: Vec<Vec<u32>> = euclidean_clusters(&cloud, &params)
            .unwrap()
            .into_iter()
            .map(|c| c.indices)
            .collect();
        assert_eq!(got, want);
    }

    #[test]
    fn two_blobs_and_an_isolated_point() {
        let mut cloud = PointCloud::new();
        cloud.push(0.0, 0.0, 0.0, 0.0); // 0: blob A
        cloud.push(10.0, 10.0, 0.0, 0.0); // 1: isolated
        cloud.push(2.0, 0.0, 0.0, 0.0); // 2: blob B
        cloud.push(0.3, 0.0, 0.0, 0.0); // 3: blob A
        cloud.push(2.0, 0.4, 0.2, 0.0); // 4: blob B
        cloud.push(0.0, 0.3, 0.0, 0.0); // 5: blob A
        cloud.push(f32::NAN, 0.0, 0.0, 0.0); // 6: invalid
        let params = ClusterParams {
            tolerance: 0.5,
            min_points: 2,
            max_points: 100,
        };
        let got = euclidean_clusters(&cloud, &params).unwrap();
        assert_eq!(got.len(), 2);
        assert_eq!(got[0].indices, vec![0, 3, 5]);
        assert_eq!(got[0].count, 3);
        assert_eq!(got[0].min, [0.0, 0.0, 0.0]);
        assert_eq!(got[0].max, [0.3, 0.3, 0.0]);
        let c = got[0].centroid;
        assert!((c[0] - 0.1).abs() < 1e-7 && (c[1] - 0.1).abs() < 1e-7 && c[2] == 0.0);
        assert_eq!(got[1].indices, vec![2, 4]);
        assert_eq!(got[1].min, [2.0, 0.0, 0.0]);
        assert_eq!(got[1].max, [2.0, 0.4, 0.2]);
        // with min_points = 1 the isolated point is a cluster of its own
        let params = ClusterParams {
            min_points: 1,
            ..params
        };
        let got = euclidean_clusters(&cloud, &params).unwrap();
        let sets: Vec<Vec<u32>> = got.into_iter().map(|c| c.indices).collect();
        assert_eq!(sets, vec![vec![0, 3, 5], vec![1], vec![2, 4]]);
    }

    #[test]
    fn rejects_bad_input() {
        let cloud = PointCloud::from_records(&[[0.0, 0.0, 0.0, 0.0]]);
        let p = ClusterParams::default();
        assert!(euclidean_clusters_of(&cloud, &[1], &p).is_err());
        let bad = ClusterParams {
            tolerance: -1.0,
            ..p
        };
        assert!(euclidean_clusters(&cloud, &bad).is_err());
        assert!(euclidean_clusters(&PointCloud::new(), &p)
            .unwrap()
            .is_empty());
    }

    proptest::proptest! {
        #[test]
        fn counted_cursor_steps_match_a_plain_count(
            mut keys in proptest::collection::vec(0u64..60, 0..40),
            limit in 0u64..70,
        ) {
            keys.sort_unstable();
            let want = keys.iter().filter(|&&k| k <= limit).count();
            proptest::prop_assert_eq!(count_up_to(&keys, limit), want);
        }

        /// The cell boxes' bounds hold for the squared distance of every point pair as the
        /// point test computes it (f32, the same order): gap² ≤ d² ≤ span², and a point's gap
        /// to the other box ≤ d².
        #[test]
        fn cell_box_bounds_hold_for_every_pair(
            a in proptest::collection::vec(proptest::array::uniform3(-3.0f32..3.0), 1..12),
            b in proptest::collection::vec(proptest::array::uniform3(-3.0f32..3.0), 1..12),
            shift in proptest::array::uniform3(-1.0f32..1.0),
        ) {
            let b: Vec<[f32; 3]> = b
                .iter()
                .map(|q| [q[0] * 0.1 + shift[0], q[1] * 0.1 + shift[1], q[2] * 0.1 + shift[2]])
                .collect();
            let (ba, bb) = (CellBox::of(&a), CellBox::of(&b));
            for p in &a {
                for q in &b {
                    let (dx, dy, dz) = (p[0] - q[0], p[1] - q[1], p[2] - q[2]);
                    let d2 = dx * dx + dy * dy + dz * dz;
                    proptest::prop_assert!(ba.gap2(&bb) <= d2);
                    proptest::prop_assert!(d2 <= ba.span2(&bb));
                    proptest::prop_assert!(bb.gap2_to(p) <= d2);
                }
            }
        }
    }
}
