//! Euclidean clustering of a point cloud: the connected components of the graph that joins
//! every two points at most `tolerance` apart, found by flood fill over a k-d tree (kiddo).
//! Each kept component becomes a [`Cluster`] with its point indices, centroid and
//! axis-aligned extent — the object detections of a lidar frame once ground and walls have
//! been removed.
//!
//! Not for: ground or plane removal, shape fitting, or tracking the clusters over time.

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

/// Flood fill over `subset` (ascending, distinct, in range).
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
    let tree = match ImmutableKdTree::<f32, 3>::new_from_slice(&points) {
        Ok(t) => t,
        Err(_) => return Vec::new(),
    };
    let r2 = params.tolerance * params.tolerance;
    let mut visited = vec![false; points.len()];
    let mut queue: Vec<u32> = Vec::new();
    let mut component: Vec<u32> = Vec::new();
    let mut out = Vec::new();
    for seed in 0..points.len() {
        if visited[seed] {
            continue;
        }
        visited[seed] = true;
        queue.clear();
        component.clear();
        queue.push(seed as u32);
        while let Some(local) = queue.pop() {
            component.push(local);
            tree.query(&points[local as usize])
                .within::<SquaredEuclidean<f32>>(r2)
                .unsorted()
                .visit(|hit| {
                    let j = hit.item as usize;
                    if !visited[j] {
                        visited[j] = true;
                        queue.push(j as u32);
                    }
                });
        }
        if component.len() < params.min_points || component.len() > params.max_points {
            continue;
        }
        // local positions are in ascending cloud-index order, so sorting them sorts indices
        component.sort_unstable();
        out.push(summarise(
            component.iter().map(|&l| members[l as usize]),
            xs,
            ys,
            zs,
        ));
    }
    // seeds run in ascending index order, so clusters already come by smallest index
    out
}

fn summarise(indices: impl Iterator<Item = u32>, xs: &[f32], ys: &[f32], zs: &[f32]) -> Cluster {
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
}
