//! Joins the pieces of one object that the scanner's sampling splits apart: a face seen at a
//! grazing angle.
//!
//! A spinning lidar samples a surface once per azimuth step Δφ; on a face whose direction
//! makes the angle β with the line of sight, at range r, the samples lie r·Δφ / sin β apart
//! along the face. A car seen end-on at 36 m shows its front across the line of sight, densely
//! sampled, and its side along it: at β = 5° its points are 1.3 m apart, more than a
//! clustering tolerance of 0.5 m bridges, so the side becomes a cluster of its own, long and
//! thin and pointing at the sensor, and a tracker sees two objects.
//!
//! [`merge_grazing_fragments`] gives such a fragment back to the cluster at its near end: a
//! cluster at least [`FragmentParams::min_elongation`] times as long as wide, whose long axis
//! lies within [`FragmentParams::max_angle_deg`] of the line of sight, is joined to the nearest
//! other cluster with a point within the sampling gap of its near end
//! (`gap_factor`·r·Δφ / sin β, at most `max_gap`), when both stand at least `min_height` tall
//! and their union fits a vehicle (`max_diagonal`, `max_height`). Thin clutter lying low (kerbs,
//! low walls) and fragments across the line of sight are left as they are.
//!
//! Not for: the clustering itself (see [`super::cluster`]) or splitting merged objects.

use super::cluster::{summarise, Cluster};
use super::PointCloud;
use crate::error::{Error, Result};

/// When a thin cluster is taken for a grazing face of its neighbour.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FragmentParams {
    /// The scanner's azimuth step (rad). Default [`super::HDL64E_AZIMUTH_STEP`].
    pub azimuth_step: f64,
    /// Largest angle between a fragment's long axis and the line of sight (degrees). Default
    /// 20: beyond it a face's samples lie closer than 3·r·Δφ ≈ 0.3 m at 36 m apart and the
    /// clustering joins them anyway.
    pub max_angle_deg: f64,
    /// Shortest fragment (m). Default 1.
    pub min_length: f64,
    /// Least length over width of a fragment. Default 4.
    pub min_elongation: f64,
    /// The gap allowed at the near end, in sampling steps along the face (the scanner drops
    /// returns, so a gap of a few steps is one face). Default 3.
    pub gap_factor: f64,
    /// Largest gap bridged (m). Default 2.
    pub max_gap: f64,
    /// Shortest height of either piece (m): a vehicle's faces stand taller than kerbs and low
    /// walls. Default 0.8.
    pub min_height: f64,
    /// Largest footprint diagonal of the union (m): a van's 6 m by 2 m. Default 6.5.
    pub max_diagonal: f64,
    /// Largest height of the union (m). Default 3.5.
    pub max_height: f64,
}

impl Default for FragmentParams {
    fn default() -> Self {
        Self {
            azimuth_step: super::HDL64E_AZIMUTH_STEP,
            max_angle_deg: 20.0,
            min_length: 1.0,
            min_elongation: 4.0,
            gap_factor: 3.0,
            max_gap: 2.0,
            min_height: 0.8,
            max_diagonal: 6.5,
            max_height: 3.5,
        }
    }
}

impl FragmentParams {
    /// Checks that every setting is finite and in its range.
    pub fn validate(&self) -> Result<()> {
        let fields = [
            ("azimuth_step", self.azimuth_step),
            ("min_length", self.min_length),
            ("min_elongation", self.min_elongation),
            ("gap_factor", self.gap_factor),
            ("max_gap", self.max_gap),
            ("min_height", self.min_height),
            ("max_diagonal", self.max_diagonal),
            ("max_height", self.max_height),
        ];
        for (name, v) in fields {
            crate::error::ensure_non_negative(&format!("fragment {name}"), v)?;
        }
        if !(self.max_angle_deg > 0.0 && self.max_angle_deg < 90.0) {
            return Err(Error::invalid(
                "fragment max_angle_deg",
                format!("{} (must lie in (0, 90))", self.max_angle_deg),
            ));
        }
        Ok(())
    }
}

/// A cluster's footprint along its principal axis.
#[derive(Copy, Clone, Debug)]
struct Footprint {
    /// Middle of the extent along the axis (x, y).
    mid: [f64; 2],
    /// Unit principal axis.
    axis: [f64; 2],
    /// Extent along the axis.
    length: f64,
    /// Extent across it.
    width: f64,
}

fn footprint(cloud: &PointCloud, c: &Cluster) -> Footprint {
    let (xs, ys) = (cloud.xs(), cloud.ys());
    let [mx, my, _] = c.centroid;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for &i in &c.indices {
        let (dx, dy) = (xs[i as usize] as f64 - mx, ys[i as usize] as f64 - my);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let axis = [theta.cos(), theta.sin()];
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut wlo, mut whi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &i in &c.indices {
        let (dx, dy) = (xs[i as usize] as f64 - mx, ys[i as usize] as f64 - my);
        let a = dx * axis[0] + dy * axis[1];
        let b = -dx * axis[1] + dy * axis[0];
        lo = lo.min(a);
        hi = hi.max(a);
        wlo = wlo.min(b);
        whi = whi.max(b);
    }
    let m = 0.5 * (lo + hi);
    Footprint {
        mid: [mx + m * axis[0], my + m * axis[1]],
        axis,
        length: hi - lo,
        width: whi - wlo,
    }
}

/// The clusters with every grazing fragment joined to the cluster at its near end (see the
/// module notes). A fragment joins at most one cluster, and a cluster that is itself a joined
/// fragment takes none; the others are returned as they came, in their order.
pub fn merge_grazing_fragments(
    cloud: &PointCloud,
    mut clusters: Vec<Cluster>,
    params: &FragmentParams,
) -> Result<Vec<Cluster>> {
    params.validate()?;
    let (xs, ys, zs) = (cloud.xs(), cloud.ys(), cloud.zs());
    let n_points = xs.len();
    if let Some(&i) = clusters
        .iter()
        .flat_map(|c| &c.indices)
        .find(|&&i| i as usize >= n_points)
    {
        return Err(Error::invalid(
            "cluster indices",
            format!("index {i} with {n_points} points in the cloud"),
        ));
    }
    let shapes: Vec<Footprint> = clusters.iter().map(|c| footprint(cloud, c)).collect();
    let tall = |c: &Cluster| (c.max[2] - c.min[2]) as f64 >= params.min_height;
    let sin_max = params.max_angle_deg.to_radians().sin();
    let mut target: Vec<Option<usize>> = vec![None; clusters.len()];
    for (b, f) in shapes.iter().enumerate() {
        let r = f.mid[0].hypot(f.mid[1]);
        if f.length < params.min_length
            || f.length < params.min_elongation * f.width
            || r <= 0.0
            || !tall(&clusters[b])
        {
            continue;
        }
        let sight = [f.mid[0] / r, f.mid[1] / r];
        let sin_beta = (sight[0] * f.axis[1] - sight[1] * f.axis[0]).abs();
        if sin_beta > sin_max {
            continue;
        }
        // The fragment's end nearer the sensor.
        let toward = if f.axis[0] * sight[0] + f.axis[1] * sight[1] > 0.0 {
            -0.5
        } else {
            0.5
        };
        let end = [
            f.mid[0] + toward * f.length * f.axis[0],
            f.mid[1] + toward * f.length * f.axis[1],
        ];
        // One sampling step along the face; a face along the line of sight itself is taken
        // at 2°, not at 0°.
        let step = r * params.azimuth_step / sin_beta.max(2f64.to_radians().sin());
        let allowed = (params.gap_factor * step).min(params.max_gap);
        let mut best: Option<(f64, usize)> = None;
        for (a, ca) in clusters.iter().enumerate() {
            let g = &shapes[a];
            let near = (g.mid[0] - end[0]).hypot(g.mid[1] - end[1]) <= 0.5 * g.length + allowed;
            if a == b || !near || !tall(ca) {
                continue;
            }
            let d = ca
                .indices
                .iter()
                .map(|&i| (xs[i as usize] as f64 - end[0]).hypot(ys[i as usize] as f64 - end[1]))
                .fold(f64::INFINITY, f64::min);
            if d <= allowed && best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, a));
            }
        }
        let Some((_, a)) = best else { continue };
        let (ca, cb) = (&clusters[a], &clusters[b]);
        let ext: [f64; 3] =
            std::array::from_fn(|k| (ca.max[k].max(cb.max[k]) - ca.min[k].min(cb.min[k])) as f64);
        if ext[0].hypot(ext[1]) <= params.max_diagonal && ext[2] <= params.max_height {
            target[b] = Some(a);
        }
    }
    let mut joined: Vec<Vec<u32>> = vec![Vec::new(); clusters.len()];
    for b in 0..clusters.len() {
        if let Some(a) = target[b].filter(|&a| target[a].is_none()) {
            joined[a].append(&mut clusters[b].indices);
        }
    }
    Ok(clusters
        .into_iter()
        .zip(joined)
        .filter(|(c, _)| !c.indices.is_empty())
        .map(|(c, extra)| {
            if extra.is_empty() {
                return c;
            }
            let mut indices = c.indices;
            indices.extend(extra);
            indices.sort_unstable();
            summarise(indices.into_iter(), xs, ys, zs)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::cluster::{euclidean_clusters, ClusterParams};

    /// Points of a vertical face from (x0, y0) to (x1, y1), `n` columns of heights 0.2…h.
    fn face(pts: &mut Vec<[f32; 3]>, a: [f64; 2], b: [f64; 2], n: usize, h: f64) {
        for i in 0..n {
            let t = if n > 1 {
                i as f64 / (n - 1) as f64
            } else {
                0.0
            };
            let (x, y) = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
            for k in 0..8 {
                let z = -1.73 + 0.2 + (h - 0.2) * k as f64 / 7.0;
                pts.push([x as f32, y as f32, z as f32]);
            }
        }
    }

    fn clusters_of(pts: &[[f32; 3]]) -> (PointCloud, Vec<Cluster>) {
        let records: Vec<[f32; 4]> = pts.iter().map(|p| [p[0], p[1], p[2], 0.0]).collect();
        let cloud = PointCloud::from_records(&records);
        let params = ClusterParams {
            tolerance: 0.5,
            min_points: 5,
            max_points: 100_000,
        };
        let c = euclidean_clusters(&cloud, &params).unwrap();
        (cloud, c)
    }

    /// A car's rear face at 35 m straight ahead, across the line of sight, densely sampled,
    /// and a second face from `from` to `to` of height `h`: the clusters before and after
    /// joining fragments.
    fn rear_and(from: [f64; 2], to: [f64; 2], h: f64) -> (Vec<Cluster>, Vec<Cluster>) {
        let mut pts = Vec::new();
        face(&mut pts, [35.0, -0.9], [35.0, 0.9], 20, 1.5);
        face(&mut pts, from, to, 9, h);
        let (cloud, clusters) = clusters_of(&pts);
        let merged =
            merge_grazing_fragments(&cloud, clusters.clone(), &FragmentParams::default()).unwrap();
        (clusters, merged)
    }

    #[test]
    fn a_car_seen_end_on_is_one_cluster_again() {
        // The car heads along x; its left side lies along the line of sight, its first
        // samples 1.2 m behind the corner (one azimuth step there spans 35 · 0.0031 / sin 1.5°
        // ≈ 4 m of the side; the lasers at other elevations fill it in further back).
        let (before, merged) = rear_and([36.2, 0.9], [38.6, 0.9], 1.5);
        assert_eq!(before.len(), 2, "the side is a cluster of its own");
        assert_eq!(merged.len(), 1);
        assert_eq!(merged[0].count, before[0].count + before[1].count);
        assert!((merged[0].max[0] - merged[0].min[0] - 3.6).abs() < 0.01);
    }

    #[test]
    fn a_fragment_across_the_line_of_sight_or_low_or_far_stays_apart() {
        for (what, from, to, h) in [
            // A neighbour beside the rear, across the line of sight: not a side.
            ("across", [35.0, 1.6], [35.0, 3.6], 1.5),
            // A kerb along the line of sight behind the car: too low to be one of its faces.
            ("kerb", [36.2, 0.9], [38.6, 0.9], 0.4),
            // The side 2.5 m behind the rear: farther than the largest gap bridged.
            ("far", [37.5, 0.9], [39.9, 0.9], 1.5),
        ] {
            let (before, merged) = rear_and(from, to, h);
            assert_eq!(before.len(), 2, "{what}");
            assert_eq!(merged.len(), 2, "{what}");
        }
    }

    #[test]
    fn bad_settings_and_indices_are_errors() {
        let pts = [[1.0f32, 0.0, 0.0], [1.1, 0.0, 0.0]];
        let (cloud, mut clusters) = clusters_of(&pts);
        let bad = FragmentParams {
            max_angle_deg: 90.0,
            ..FragmentParams::default()
        };
        assert!(merge_grazing_fragments(&cloud, clusters.clone(), &bad).is_err());
        let bad = FragmentParams {
            max_gap: f64::NAN,
            ..FragmentParams::default()
        };
        assert!(merge_grazing_fragments(&cloud, clusters.clone(), &bad).is_err());
        clusters.push(Cluster {
            indices: vec![7],
            centroid: [0.0; 3],
            min: [0.0; 3],
            max: [0.0; 3],
            count: 1,
        });
        let err = merge_grazing_fragments(&cloud, clusters, &FragmentParams::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("index 7"), "{err}");
    }
}
