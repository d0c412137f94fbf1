//! The coarse (global) search of one scan pair: every heading and translation on a grid,
//! scored in a dilated occupancy grid of the reference points, the best refined by ICP.
//!
//! Not for: the fine registration of every pair (`register`) or the vote between pairs.

use super::*;
/// One candidate of the coarse search, after its ICP refinement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoarseCandidate {
    /// The sensor's pose in the reference scan's frame.
    pub pose: Pose2,
    /// Share of the sensor points within [`CoarseConfig::hit_radius`] of a reference point at
    /// that pose.
    pub score: f64,
}

/// The dilated occupancy grid of a target point set: cell `(i, j)` is set when a target point
/// lies within the hit radius of the cell's centre (up to half a cell).
pub(super) struct HitGrid {
    origin: [f64; 2],
    cell: f64,
    nx: usize,
    ny: usize,
    hits: Vec<bool>,
}

impl HitGrid {
    fn new(target: &[[f64; 2]], radius: f64) -> Option<Self> {
        let cell = 0.5 * radius;
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in target {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        if !(lo[0].is_finite() && lo[1].is_finite()) {
            return None;
        }
        let origin = [lo[0] - radius - cell, lo[1] - radius - cell];
        let nx = ((hi[0] - origin[0] + radius + cell) / cell).ceil() as usize + 1;
        let ny = ((hi[1] - origin[1] + radius + cell) / cell).ceil() as usize + 1;
        let mut hits = vec![false; nx * ny];
        let reach = (radius / cell).ceil() as isize;
        let r2 = (radius + 0.5 * cell) * (radius + 0.5 * cell);
        for p in target {
            let ci = ((p[0] - origin[0]) / cell) as isize;
            let cj = ((p[1] - origin[1]) / cell) as isize;
            for di in -reach..=reach {
                for dj in -reach..=reach {
                    let (i, j) = (ci + di, cj + dj);
                    if i < 0 || j < 0 || i as usize >= nx || j as usize >= ny {
                        continue;
                    }
                    let cx = origin[0] + (i as f64 + 0.5) * cell;
                    let cy = origin[1] + (j as f64 + 0.5) * cell;
                    let (dx, dy) = (cx - p[0], cy - p[1]);
                    if dx * dx + dy * dy <= r2 {
                        hits[j as usize * nx + i as usize] = true;
                    }
                }
            }
        }
        Some(HitGrid {
            origin,
            cell,
            nx,
            ny,
            hits,
        })
    }

    #[inline]
    fn hit(&self, x: f64, y: f64) -> bool {
        let fx = (x - self.origin[0]) / self.cell;
        let fy = (y - self.origin[1]) / self.cell;
        if fx < 0.0 || fy < 0.0 {
            return false;
        }
        let (i, j) = (fx as usize, fy as usize);
        i < self.nx && j < self.ny && self.hits[j * self.nx + i]
    }
}

/// The global search of the module documentation (step 1) for one pair: the sensor points
/// `source` and the reference points `target`, both in their own laser's frame, searched as
/// [`MountingConfig::coarse`] says and refined by ICP and point-to-line. Returns the
/// refined candidates, best score first (at most [`CoarseConfig::candidates`]; candidates whose
/// ICP failed are left out). Deterministic.
pub fn coarse_align(
    source: &[[f64; 2]],
    target: &[[f64; 2]],
    config: &MountingConfig,
) -> Result<Vec<CoarseCandidate>, MountingError> {
    config.validate()?;
    let coarse = &config.coarse;
    let icp = &config.icp;
    if source.len() < icp.min_pairs || target.len() < icp.min_pairs {
        return Ok(Vec::new());
    }
    let Some(grid) = HitGrid::new(target, coarse.hit_radius) else {
        return Ok(Vec::new());
    };
    let stride = source.len().div_ceil(coarse.max_points).max(1);
    let thin: Vec<[f64; 2]> = source.iter().step_by(stride).copied().collect();
    let n_head = (TAU / coarse.heading_step).round().max(1.0) as usize;
    let n_side = (coarse.translation_range / coarse.translation_step).round() as isize;
    let mut rotated = vec![[0.0; 2]; thin.len()];
    // Best translation per heading: (score, heading index, tx, ty).
    let mut best: Vec<(usize, usize, f64, f64)> = Vec::with_capacity(n_head);
    for h in 0..n_head {
        let theta = h as f64 * TAU / n_head as f64;
        let (s, c) = theta.sin_cos();
        for (r, p) in rotated.iter_mut().zip(&thin) {
            *r = [c * p[0] - s * p[1], s * p[0] + c * p[1]];
        }
        let mut top = (0usize, h, 0.0, 0.0);
        for i in -n_side..=n_side {
            let tx = i as f64 * coarse.translation_step;
            for j in -n_side..=n_side {
                let ty = j as f64 * coarse.translation_step;
                let mut count = 0usize;
                for r in &rotated {
                    count += usize::from(grid.hit(r[0] + tx, r[1] + ty));
                }
                if count > top.0 {
                    top = (count, h, tx, ty);
                }
            }
        }
        best.push(top);
    }
    // Non-maximum suppression over headings (a peak is kept when no heading within three
    // steps scores higher), then the best few peaks.
    let mut peaks: Vec<(usize, usize, f64, f64)> = (0..n_head)
        .filter(|&h| {
            (1..=3).all(|d| {
                let a = best[(h + d) % n_head].0;
                let b = best[(h + n_head - d) % n_head].0;
                best[h].0 >= a && best[h].0 >= b
            })
        })
        .map(|h| best[h])
        .filter(|b| b.0 > 0)
        .collect();
    peaks.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    peaks.truncate(coarse.candidates);
    let mut aligner = Icp::new(*icp)?;
    aligner.set_target(target)?;
    let mut lines = PlanarGrid::new(target, LINE_CELL);
    let mut out = Vec::with_capacity(peaks.len());
    for (_, h, tx, ty) in peaks {
        let start = Pose2::new(tx, ty, wrap_angle(h as f64 * TAU / n_head as f64));
        let Ok(fit) = aligner.align(source, start) else {
            continue;
        };
        let pose = lines
            .as_mut()
            .and_then(|g| point_to_line(g, target, source, fit.transform, config))
            .map_or(fit.transform, |r| r.0);
        let mut count = 0usize;
        for &p in source {
            let q = transform_point(pose, p);
            if aligner
                .nearest_target_distance(q)
                .is_some_and(|d| d <= coarse.hit_radius)
            {
                count += 1;
            }
        }
        out.push(CoarseCandidate {
            pose,
            score: count as f64 / source.len() as f64,
        });
    }
    out.sort_by(|a, b| b.score.total_cmp(&a.score));
    Ok(out)
}
