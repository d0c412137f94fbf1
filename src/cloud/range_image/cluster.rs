//! Clustering on a [`RangeImage`] with the angle criterion of Bogoslavskyi & Stachniss
//! (IROS 2016): two neighbouring cells are one object when the angle β between the longer
//! beam and the line joining the two points exceeds `min_angle` (β is near 90° on a surface
//! facing the sensor, small across a depth jump). Components are grown by breadth-first
//! search over the image, linear in the points.
//!
//! # Neighbours
//! Left and right: the nearest occupied cell of the same row within `reach` columns (a few
//! columns bridge dropouts), azimuth wrapping round. Up and down: the nearest row within
//! `row_reach` with an occupied cell at the same column or the nearest column within `reach`. Only cells held by a candidate
//! point take part (the caller's subset, e.g. the points on neither ground nor wall); a
//! candidate that shares a cell with a nearer candidate joins its cluster when their ranges
//! differ by at most `max_distance`.
//!
//! # The test
//! For points p₁ (the longer range d₁) and p₂: tan β = |p₁ × p₂| / (d₁² − p₁·p₂), so
//! β > θ ⇔ |p₁ × p₂| > tan θ · (d₁² − p₁·p₂), with no trigonometry per pair. Two points also
//! need to be within `max_distance` of each other, so that a reach over several columns at
//! long range cannot join things metres apart. Neighbours within `near_distance` are joined
//! whatever β: the angle alone splits every surface seen at grazing incidence (a car's roof
//! seen from 1.73 m, the side of a car parked down the street), which breaks one object
//! into several detections.
//!
//! # How it differs from the exact Euclidean clustering
//! [`crate::cloud::euclidean_clusters_of`] joins any two points within a fixed distance.
//! The angle criterion adapts to range (neighbours 0.3 m apart at 40 m are joined when they
//! lie on one surface; points 0.2 m apart in depth behind each other are not) and sees only
//! the image neighbours: it splits an object along a line of grazing incidence (a long side
//! seen almost edge-on) and where a nearer object hides its middle; it merges touching
//! objects at the same range that Euclidean clustering would merge too. The measured
//! agreement is in `tests/range_image_real.rs`.
//!
//! Not for: ground removal (see [`super::ground`]), or clouds that are not one scan.

use super::{RangeImage, NONE};
use crate::cloud::{Cluster, PointCloud};
use crate::error::{Error, Result};

/// Parameters of [`range_image_clusters`].
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ImageClusterParams {
    /// Smallest angle β between beam and neighbour line that joins (rad). Default 10°
    /// (Bogoslavskyi & Stachniss).
    pub min_angle: f64,
    /// Columns searched on either side for an occupied neighbour. Default 3.
    pub reach: usize,
    /// Rows searched above and below for a neighbour (a row whose cells there hold no
    /// candidate — a ground or wall point, a dropout — is bridged). Default 2.
    pub row_reach: usize,
    /// Neighbours at most this far apart are joined whatever the angle (m): a surface seen
    /// at grazing incidence (a parked car's side down the street) keeps its neighbours
    /// within a few decimetres, which the angle alone would split. Default 0.5.
    pub near_distance: f64,
    /// Largest distance between two points joined by the angle criterion (m). Default 1.0.
    pub max_distance: f64,
    /// Fewest points of a kept cluster. Default 10.
    pub min_points: usize,
    /// Most points of a kept cluster. Default 100 000.
    pub max_points: usize,
}

impl Default for ImageClusterParams {
    fn default() -> Self {
        ImageClusterParams {
            min_angle: 10f64.to_radians(),
            reach: 3,
            row_reach: 2,
            near_distance: 0.5,
            max_distance: 1.0,
            min_points: 10,
            max_points: 100_000,
        }
    }
}

impl ImageClusterParams {
    fn validate(&self) -> Result<()> {
        let ok = self.min_angle.is_finite()
            && (0.0..std::f64::consts::FRAC_PI_2).contains(&self.min_angle)
            && self.max_distance.is_finite()
            && self.max_distance > 0.0
            && self.near_distance.is_finite()
            && self.near_distance >= 0.0
            && self.min_points <= self.max_points;
        if ok {
            Ok(())
        } else {
            Err(Error::invalid(
                "range image cluster parameters",
                format!("{self:?} (angle in [0, 90°), distance > 0, min_points ≤ max_points)"),
            ))
        }
    }
}

/// Clusters the points of `cloud` listed in `indices` on `image` (built from `cloud`).
/// Duplicate indices count once; an index out of range is an error; points without a cell
/// belong to no cluster. Clusters come in ascending order of their smallest index, indices
/// inside a cluster ascending, as [`crate::cloud::euclidean_clusters_of`] returns them.
pub fn range_image_clusters(
    image: &RangeImage,
    cloud: &PointCloud,
    indices: &[u32],
    params: &ImageClusterParams,
) -> Result<Vec<Cluster>> {
    params.validate()?;
    image.check_cloud(cloud)?;
    if let Some(&bad) = indices.iter().find(|&&i| i as usize >= cloud.len()) {
        return Err(Error::invalid(
            "cluster indices",
            format!(
                "index {bad} out of range for a cloud of {} points",
                cloud.len()
            ),
        ));
    }
    let (xs, ys, zs) = (cloud.xs(), cloud.ys(), cloud.zs());
    let (rows, cols) = (image.rows(), image.cols());
    let cell_of = image.cells_of_points();
    let range2 = |i: usize| xs[i] * xs[i] + ys[i] * ys[i] + zs[i] * zs[i];

    // Candidate holders: the nearest candidate of each cell.
    let mut holder = vec![NONE; rows * cols];
    for &i in indices {
        let c = cell_of[i as usize];
        if c == NONE {
            continue;
        }
        let h = &mut holder[c as usize];
        if *h == NONE || range2(i as usize) < range2(*h as usize) {
            *h = i;
        }
    }

    let tan = params.min_angle.tan() as f32;
    let max_d2 = (params.max_distance * params.max_distance) as f32;
    let near_d2 = (params.near_distance * params.near_distance) as f32;
    let joined = |a: usize, b: usize| -> bool {
        let (pa, pb) = ([xs[a], ys[a], zs[a]], [xs[b], ys[b], zs[b]]);
        let d = [pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]];
        let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        d2 <= near_d2 || (d2 <= max_d2 && angle_exceeds(pa, pb, tan))
    };

    let reach = params.reach.min(cols / 2);
    let row_reach = params.row_reach;
    let mut label = vec![NONE; rows * cols];
    let mut queue: Vec<u32> = Vec::new();
    let mut next = 0u32;
    for seed in 0..rows * cols {
        if holder[seed] == NONE || label[seed] != NONE {
            continue;
        }
        label[seed] = next;
        queue.clear();
        queue.push(seed as u32);
        let mut head = 0;
        while head < queue.len() {
            let cell = queue[head] as usize;
            head += 1;
            let (row, col) = (cell / cols, cell % cols);
            let p = holder[cell] as usize;
            let visit = |n: usize, label: &mut [u32], queue: &mut Vec<u32>| {
                if label[n] == NONE && joined(p, holder[n] as usize) {
                    label[n] = next;
                    queue.push(n as u32);
                }
            };
            // Same row: the nearest occupied cell within reach on either side.
            for side in [1, cols - 1] {
                for k in 1..=reach {
                    let c = (col + side * k) % cols;
                    let n = row * cols + c;
                    if holder[n] != NONE {
                        visit(n, &mut label, &mut queue);
                        break;
                    }
                }
            }
            // Rows above and below: the nearest row within `row_reach` that has an occupied
            // cell within `reach` columns (the same column first).
            for up in [true, false] {
                'rows: for k in 1..=row_reach {
                    let r = if up { row.wrapping_sub(k) } else { row + k };
                    if r >= rows {
                        break;
                    }
                    let base = r * cols;
                    for j in 0..=reach {
                        for c in [(col + j) % cols, (col + cols - j) % cols] {
                            if holder[base + c] != NONE {
                                visit(base + c, &mut label, &mut queue);
                                break 'rows;
                            }
                        }
                    }
                }
            }
        }
        next += 1;
    }

    // Members: every candidate with a labelled cell (the holder, or a point close to it).
    let mut seen = vec![false; cloud.len()];
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); next as usize];
    let mut sorted: Vec<u32> = indices.to_vec();
    sorted.sort_unstable();
    let max_d = params.max_distance as f32;
    let near_d = params.near_distance as f32;
    for &i in &sorted {
        let iu = i as usize;
        if seen[iu] {
            continue;
        }
        seen[iu] = true;
        let c = cell_of[iu];
        if c == NONE || holder[c as usize] == NONE {
            continue;
        }
        let h = holder[c as usize] as usize;
        if h != iu && range2(iu).sqrt() - range2(h).sqrt() > max_d.max(near_d) {
            continue;
        }
        members[label[c as usize] as usize].push(i);
    }
    let mut out: Vec<Cluster> = members
        .into_iter()
        .filter(|m| !m.is_empty() && (params.min_points..=params.max_points).contains(&m.len()))
        .map(|m| summarise(cloud, m))
        .collect();
    out.sort_by_key(|c| c.indices[0]);
    Ok(out)
}

/// Whether the angle β between the longer of the beams to `pa`, `pb` and the line joining
/// them exceeds the angle whose tangent is `tan` (see the module documentation).
fn angle_exceeds(pa: [f32; 3], pb: [f32; 3], tan: f32) -> bool {
    let dot = pa[0] * pb[0] + pa[1] * pb[1] + pa[2] * pb[2];
    let cross = [
        pa[1] * pb[2] - pa[2] * pb[1],
        pa[2] * pb[0] - pa[0] * pb[2],
        pa[0] * pb[1] - pa[1] * pb[0],
    ];
    let cross = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
    let na = pa[0] * pa[0] + pa[1] * pa[1] + pa[2] * pa[2];
    let nb = pb[0] * pb[0] + pb[1] * pb[1] + pb[2] * pb[2];
    cross > tan * (na.max(nb) - dot)
}

/// Centroid and extent of ascending member indices.
fn summarise(cloud: &PointCloud, indices: Vec<u32>) -> Cluster {
    let (xs, ys, zs) = (cloud.xs(), cloud.ys(), cloud.zs());
    let mut sum = [0f64; 3];
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for &i in &indices {
        let p = [xs[i as usize], ys[i as usize], zs[i as usize]];
        for a in 0..3 {
            sum[a] += p[a] as f64;
            min[a] = min[a].min(p[a]);
            max[a] = max[a].max(p[a]);
        }
    }
    let n = indices.len();
    Cluster {
        centroid: sum.map(|s| s / n as f64),
        min,
        max,
        count: n,
        indices,
    }
}

#[cfg(test)]
pub(super) fn angle_exceeds_for_tests(pa: [f32; 3], pb: [f32; 3], tan: f32) -> bool {
    angle_exceeds(pa, pb, tan)
}
