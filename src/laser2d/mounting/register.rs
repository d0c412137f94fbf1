//! The fine registration of one scan pair (point-to-point ICP, then point-to-line
//! Gauss-Newton), the pairing of sensor scans with reference scans in time, and the robust
//! statistics the estimate is made of.
//!
//! Not for: the coarse search (`coarse`) or the aggregation over pairs (the parent module).

use super::*;
/// The returns of `scan` within `max_range`, into `out` (cleared first).
pub(super) fn scan_points_into(scan: &Scan, max_range: f64, out: &mut Vec<[f64; 2]>) {
    out.clear();
    out.extend(
        scan.points()
            .filter(|(_, p)| p[0] * p[0] + p[1] * p[1] <= max_range * max_range)
            .map(|(_, p)| p),
    );
}

pub(super) fn median(values: &mut [f64]) -> f64 {
    quantile(values, 0.5)
}

/// Linear-interpolated quantile `q` of `values` (sorted in place); NaN when empty.
pub(super) fn quantile(values: &mut [f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    let pos = q.clamp(0.0, 1.0) * (values.len() - 1) as f64;
    let lo = pos.floor() as usize;
    let hi = pos.ceil() as usize;
    let w = pos - lo as f64;
    values[lo] * (1.0 - w) + values[hi] * w
}

/// Component-wise median of poses, headings as offsets from `about`.
pub(super) fn median_pose(poses: &[Pose2], about: f64) -> Pose2 {
    let mut xs: Vec<f64> = poses.iter().map(|p| p.x).collect();
    let mut ys: Vec<f64> = poses.iter().map(|p| p.y).collect();
    let mut hs: Vec<f64> = poses.iter().map(|p| wrap_angle(p.theta - about)).collect();
    Pose2::new(
        median(&mut xs),
        median(&mut ys),
        wrap_angle(about + median(&mut hs)),
    )
}

/// The pairs of the module documentation (step 2).
pub(super) fn make_pairs(
    reference: &[Scan],
    sensor: &[Scan],
    config: &MountingConfig,
) -> Result<Vec<ScanPair>, MountingError> {
    let mut periods: Vec<f64> = reference
        .windows(2)
        .map(|w| w[1].time - w[0].time)
        .filter(|d| *d > 0.0)
        .collect();
    let max_gap = config.max_gap_periods * median(&mut periods);
    let mut pairs = Vec::new();
    for (k, s) in sensor.iter().enumerate().step_by(config.pair_stride) {
        // First reference scan after the sensor scan (references need not be sorted
        // strictly: the search is over the neighbours only).
        let after = reference.partition_point(|r| r.time <= s.time);
        if config.motion_compensation {
            if after == 0 || after >= reference.len() {
                continue;
            }
            let (t0, t1) = (reference[after - 1].time, reference[after].time);
            let gap = t1 - t0;
            if !(gap > 0.0 && gap <= max_gap) {
                continue;
            }
            pairs.push(ScanPair {
                sensor: k,
                reference: after - 1,
                next_reference: Some(after),
                time_offset: s.time - t0,
                alpha: (s.time - t0) / gap,
            });
        } else {
            let nearest = [after.checked_sub(1), Some(after)]
                .into_iter()
                .flatten()
                .filter(|&i| i < reference.len())
                .min_by(|&a, &b| {
                    (reference[a].time - s.time)
                        .abs()
                        .total_cmp(&(reference[b].time - s.time).abs())
                });
            if let Some(i) = nearest {
                let dt = s.time - reference[i].time;
                if dt.abs() <= config.max_time_offset {
                    pairs.push(ScanPair {
                        sensor: k,
                        reference: i,
                        next_reference: None,
                        time_offset: dt,
                        alpha: 0.0,
                    });
                }
            }
        }
    }
    if pairs.is_empty() {
        return Err(MountingError::NoPairs {
            max_gap,
            max_time_offset: config.max_time_offset,
        });
    }
    Ok(pairs)
}

/// The reference laser's pose at `alpha` of the way along `motion` (linear in x, y, heading).
pub(super) fn interpolate(motion: Pose2, alpha: f64) -> Pose2 {
    Pose2::new(alpha * motion.x, alpha * motion.y, alpha * motion.theta)
}

/// Scratch buffers of one pair's registration.
pub(super) struct PairWork {
    pub(super) icp: Icp,
    pub(super) lines: Option<PlanarGrid>,
    pub(super) source: Vec<[f64; 2]>,
    pub(super) target: Vec<[f64; 2]>,
    pub(super) next: Vec<[f64; 2]>,
}

impl PairWork {
    pub(super) fn new(icp: IcpConfig) -> Result<Self, MountingError> {
        Ok(PairWork {
            icp: Icp::new(icp)?,
            lines: None,
            source: Vec::new(),
            target: Vec::new(),
            next: Vec::new(),
        })
    }

    /// Loads the pair's points and measures the reference motion; `None` when a scan has too
    /// few points or the reference motion cannot be measured.
    pub(super) fn load(
        &mut self,
        pair: &ScanPair,
        reference: &[Scan],
        sensor: &[Scan],
        config: &MountingConfig,
    ) -> Option<Pose2> {
        let min = config.icp.min_pairs;
        scan_points_into(&sensor[pair.sensor], config.max_range, &mut self.source);
        scan_points_into(
            &reference[pair.reference],
            config.max_range,
            &mut self.target,
        );
        if self.source.len() < min || self.target.len() < min {
            return None;
        }
        self.icp.set_target(&self.target).ok()?;
        self.lines = PlanarGrid::new(&self.target, LINE_CELL);
        let mut motion = Pose2::new(0.0, 0.0, 0.0);
        if let Some(n) = pair.next_reference {
            scan_points_into(&reference[n], config.max_range, &mut self.next);
            if self.next.len() < min {
                return None;
            }
            let fit = self.icp.align(&self.next, motion).ok()?;
            motion = fit.transform;
            if let Some(grid) = self.lines.as_mut() {
                if let Some(r) = point_to_line(grid, &self.target, &self.next, motion, config) {
                    motion = r.0;
                }
            }
        }
        Some(interpolate(motion, pair.alpha))
    }

    /// ICP of the sensor points from `start`, then the point-to-line refinement: the
    /// transform, the ICP fit, and the point-to-line RMS and pairs.
    pub(super) fn register(
        &mut self,
        start: Pose2,
        config: &MountingConfig,
    ) -> Option<(Pose2, IcpFit, f64, usize)> {
        let fit = self.icp.align(&self.source, start).ok()?;
        let grid = self.lines.as_mut()?;
        let (pose, rms, pairs) =
            point_to_line(grid, &self.target, &self.source, fit.transform, config)?;
        Some((pose, fit, rms, pairs))
    }
}

/// Cell of the grid whose lines the point-to-line refinement uses: a target point's normal
/// comes from its neighbours within this distance (m).
pub(super) const LINE_CELL: f64 = 0.15;

/// Iterations of the point-to-line refinement at most.
pub(super) const LINE_ITERATIONS: usize = 30;

/// Point-to-line refinement of `start` (source → target): each moved source point within
/// [`MountingConfig::line_gate`] of its nearest target point that has a line normal `n` adds
/// the residual `n·(q − t)`; the Gauss-Newton step in `(x, y, θ)` is solved with a small
/// damping, so a direction no line constrains (a corridor's length) keeps its start value.
/// Returns the pose, the RMS of the residuals and their number; `None` with fewer than
/// [`IcpConfig::min_pairs`] pairs.
pub(super) fn point_to_line(
    grid: &mut PlanarGrid,
    target: &[[f64; 2]],
    source: &[[f64; 2]],
    start: Pose2,
    config: &MountingConfig,
) -> Option<(Pose2, f64, usize)> {
    let gate2 = config.line_gate * config.line_gate;
    let mut pose = start;
    let mut last = (f64::INFINITY, 0usize);
    for _ in 0..LINE_ITERATIONS {
        let mut h = nalgebra::Matrix3::<f64>::zeros();
        let mut b = nalgebra::Vector3::<f64>::zeros();
        let (mut sum2, mut n) = (0.0, 0usize);
        for &p in source {
            let q = transform_point(pose, p);
            let Some((j, _)) = grid.nearest(q, gate2) else {
                continue;
            };
            let Some(nv) = grid.line_normal(j) else {
                continue;
            };
            let t = target[j];
            let r = nv[0] * (q[0] - t[0]) + nv[1] * (q[1] - t[1]);
            let jac = nalgebra::Vector3::new(nv[0], nv[1], nv[1] * q[0] - nv[0] * q[1]);
            h += jac * jac.transpose();
            b += jac * r;
            sum2 += r * r;
            n += 1;
        }
        if n < config.icp.min_pairs {
            return None;
        }
        last = ((sum2 / n as f64).sqrt(), n);
        let damping = 1e-6 * h.trace().max(1e-12);
        let hd = h + nalgebra::Matrix3::identity() * damping;
        let step = hd.cholesky()?.solve(&(-b));
        pose = compose(Pose2::new(step[0], step[1], step[2]), pose);
        if step[0].hypot(step[1]) < 1e-6 && step[2].abs() < 1e-7 {
            break;
        }
    }
    Some((pose, last.0, last.1))
}
