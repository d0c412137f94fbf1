//! Mounting poses of several planar lasers on one platform, estimated from the scans alone:
//! the pose `(x, y, heading)` of each laser in the frame of one *reference* laser, found by
//! registering the lasers' overlapping views of a static scene.
//!
//! For a recording where the lasers' mounting was not logged (the three lasers of the
//! `leg_tracker` training bag `negative_2.bag`, say), [`estimate_mounting`] pairs each scan of
//! the *sensor* laser with the reference scans just before and after it in time, and:
//!
//! 1. **Coarse search** ([`coarse_align`]), on [`MountingConfig::coarse_pairs`] pairs spread
//!    over the recording: every heading on a grid over the full turn and every translation on a
//!    grid within [`CoarseConfig::translation_range`] is scored by how many (subsampled) sensor
//!    points land within [`CoarseConfig::hit_radius`] of a reference point (a lookup in a
//!    dilated occupancy grid of the reference scan); the best few, kept apart by non-maximum
//!    suppression, are refined by ICP and rescored. No prior guess is used. The pairs vote: the
//!    candidate that most other pairs agree with (within [`CoarseConfig::agree_distance`] and
//!    [`CoarseConfig::agree_heading`]) wins and the median of its supporters is the initial
//!    guess.
//! 2. **Fine registration** of every pair by point-to-point ICP ([`super::icp`]) from that
//!    guess, then a point-to-line refinement (Gauss-Newton on the distances of the sensor
//!    points from the lines through their nearest reference points, [`MountingConfig::line_gate`]):
//!    point-to-point pairs of two lasers that sample a wall at different places leave a bias
//!    of a good part of the beam spacing along the wall, the lines do not. With [`MountingConfig::motion_compensation`] (default) the platform's motion
//!    between the two reference scans bracketing the sensor scan is itself measured by ICP and
//!    interpolated linearly to the sensor scan's time `t_s`: with `M(α)` the reference laser's
//!    pose at `t_s` in the frame of the earlier reference scan and `T` the sensor scan's
//!    registered pose in that frame, the mounting is `X = M(α)⁻¹ ∘ T`. Without it the nearest
//!    reference scan is used, and only when it is at most [`MountingConfig::max_time_offset`]
//!    away.
//! 3. **Robust aggregation.** A pair's fit is kept when it converged to within
//!    [`MountingConfig::max_jump`] / [`MountingConfig::max_heading_jump`] of the guess, with at
//!    least [`MountingConfig::min_overlap`] of the sensor points paired by the ICP and a
//!    point-to-line RMS at most [`MountingConfig::max_rms`]. The estimate is the
//!    component-wise median of the kept fits (headings as offsets from the guess, so the
//!    median does not straddle ±π). The spread is
//!    reported as robust standard deviations (1.4826 × median absolute deviation), the 5–95 %
//!    range, and the medians of [`MountingConfig::windows`] consecutive time windows.
//! 4. **Residuals.** With the final pose every kept pair's sensor points are moved into the
//!    reference scan; those within [`MountingConfig::overlap_gate`] of a reference point are
//!    the overlap, and their distances (RMS and median per pair) are the residual alignment
//!    error of [`MountingResiduals`].
//!
//! Not for: lasers whose views never overlap (nothing to register; chain through a third
//! laser whose view overlaps both), dynamic scenes dominated by moving objects, calibrating
//! range or bearing biases of a scanner, or 3-D lidars. The scans' own time stamps are trusted
//! (the lasers must share a clock); a scan's sweep is treated as instantaneous.

use super::icp::{Icp, IcpConfig, IcpFit};
use super::nearest::PlanarGrid;
use super::scan::Scan;
use crate::geometry::pose2::{compose, inverse, transform_point};
use crate::geometry::{wrap_angle, Pose2};
use rayon::prelude::*;
use std::f64::consts::TAU;

/// Why an estimation failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MountingError {
    /// A configuration value is unusable.
    #[error("invalid mounting configuration {field}: {reason}")]
    Config {
        /// The field, e.g. `MountingConfig::windows`.
        field: &'static str,
        /// Why.
        reason: String,
    },
    /// A laser has fewer scans than the estimation needs.
    #[error("the {which} laser has {count} scans (need at least {needed})")]
    TooFewScans {
        /// `reference` or `sensor`.
        which: &'static str,
        /// Scans given.
        count: usize,
        /// Scans needed.
        needed: usize,
    },
    /// No sensor scan has reference scans close enough in time.
    #[error("no sensor scan lies between two reference scans at most {max_gap} s apart (or within {max_time_offset} s of one without motion compensation)")]
    NoPairs {
        /// The longest reference period accepted (s).
        max_gap: f64,
        /// The largest time offset accepted without motion compensation (s).
        max_time_offset: f64,
    },
    /// The coarse search found nothing on any of the pairs it tried.
    #[error("the coarse search aligned none of {tried} scan pairs")]
    NoCoarseAlignment {
        /// Pairs tried.
        tried: usize,
    },
    /// Too few pairs passed the fine registration's checks.
    #[error(
        "only {kept} of {tried} scan pairs aligned near the coarse guess {guess:?} (need {needed})"
    )]
    TooFewFits {
        /// Pairs that passed.
        kept: usize,
        /// Pairs tried.
        tried: usize,
        /// Pairs needed ([`MountingConfig::min_fits`]).
        needed: usize,
        /// The coarse guess `[x, y, heading]`.
        guess: [f64; 3],
    },
    /// Estimating one laser of several failed.
    #[error("laser {name}: {source}")]
    Laser {
        /// The laser (topic) name.
        name: String,
        /// The failure.
        #[source]
        source: Box<MountingError>,
    },
    /// Reading the recording (or a library check) failed.
    #[error(transparent)]
    Library(#[from] crate::Error),
}

impl From<MountingError> for crate::Error {
    fn from(e: MountingError) -> Self {
        match e {
            MountingError::Library(inner) => inner,
            other => crate::Error::invalid("laser mounting", other.to_string()),
        }
    }
}

/// The coarse (global) search of [`coarse_align`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoarseConfig {
    /// Heading grid step over the full turn (rad). Default 2°.
    pub heading_step: f64,
    /// Translations are searched in `[−range, range]²` (m). Default 1.5 m.
    pub translation_range: f64,
    /// Translation grid step (m). Default 0.05 m.
    pub translation_step: f64,
    /// A sensor point scores when it lands within this of a reference point (m). Default 0.1 m.
    pub hit_radius: f64,
    /// The sensor scan is thinned to at most this many points for the search. Default 200.
    pub max_points: usize,
    /// Candidates refined by ICP per pair. Default 5.
    pub candidates: usize,
    /// Two pairs' results agree when their positions are at most this far apart (m). Default 0.1 m.
    pub agree_distance: f64,
    /// ... and their headings at most this far apart (rad). Default 3°.
    pub agree_heading: f64,
}

impl Default for CoarseConfig {
    fn default() -> Self {
        CoarseConfig {
            heading_step: 2f64.to_radians(),
            translation_range: 1.5,
            translation_step: 0.05,
            hit_radius: 0.1,
            max_points: 200,
            candidates: 5,
            agree_distance: 0.1,
            agree_heading: 3f64.to_radians(),
        }
    }
}

/// Parameters of [`estimate_mounting`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MountingConfig {
    /// Returns farther than this are not used (m); far returns are sparse and noisy. Default 8 m.
    pub max_range: f64,
    /// Use every n'th sensor scan. Default 1 (all).
    pub pair_stride: usize,
    /// Interpolate the platform's motion between the bracketing reference scans (module
    /// documentation, step 2). Default true.
    pub motion_compensation: bool,
    /// Reference scans more than this many median reference periods apart do not bracket a
    /// sensor scan (a gap in the recording). Default 1.5.
    pub max_gap_periods: f64,
    /// Without motion compensation, the largest time offset between a sensor scan and its
    /// reference scan (s). Default 0.02 s.
    pub max_time_offset: f64,
    /// Pairs used by the coarse search, spread evenly over the recording. Default 9.
    pub coarse_pairs: usize,
    /// The coarse search.
    pub coarse: CoarseConfig,
    /// ICP of the fine registration (and of the reference laser's own motion).
    pub icp: IcpConfig,
    /// A fit farther than this from the coarse guess is rejected (m). Default 0.3 m.
    pub max_jump: f64,
    /// ... or turned farther than this (rad). Default 10°.
    pub max_heading_jump: f64,
    /// Least share of sensor points paired for a fit to count. Default 0.2.
    pub min_overlap: f64,
    /// Largest RMS of the point-to-line residuals for a fit to count (m). Default 0.05 m.
    pub max_rms: f64,
    /// Fewest kept fits for an estimate. Default 10.
    pub min_fits: usize,
    /// Time windows whose medians are reported. Default 4.
    pub windows: usize,
    /// Pairs of the point-to-line refinement that follows each ICP are at most this far apart
    /// (m). Default 0.15 m.
    pub line_gate: f64,
    /// Sensor points within this of a reference point, at the final pose, are the overlap
    /// whose distances are the residuals (m). Default 0.2 m.
    pub overlap_gate: f64,
}

impl Default for MountingConfig {
    fn default() -> Self {
        MountingConfig {
            max_range: 8.0,
            pair_stride: 1,
            motion_compensation: true,
            max_gap_periods: 1.5,
            max_time_offset: 0.02,
            coarse_pairs: 9,
            coarse: CoarseConfig::default(),
            icp: IcpConfig {
                max_pair_distance: 0.5,
                ..IcpConfig::default()
            },
            max_jump: 0.3,
            max_heading_jump: 10f64.to_radians(),
            min_overlap: 0.2,
            max_rms: 0.05,
            min_fits: 10,
            windows: 4,
            line_gate: 0.15,
            overlap_gate: 0.2,
        }
    }
}

fn positive(field: &'static str, v: f64) -> Result<(), MountingError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(MountingError::Config {
            field,
            reason: format!("{v} (must be finite and positive)"),
        })
    }
}

fn at_least(field: &'static str, v: usize, min: usize) -> Result<(), MountingError> {
    if v >= min {
        Ok(())
    } else {
        Err(MountingError::Config {
            field,
            reason: format!("{v} (need at least {min})"),
        })
    }
}

impl CoarseConfig {
    /// Checks that steps, ranges and radii are positive and finite and the counts non-zero.
    pub fn validate(&self) -> Result<(), MountingError> {
        positive("CoarseConfig::heading_step", self.heading_step)?;
        positive("CoarseConfig::translation_range", self.translation_range)?;
        positive("CoarseConfig::translation_step", self.translation_step)?;
        positive("CoarseConfig::hit_radius", self.hit_radius)?;
        positive("CoarseConfig::agree_distance", self.agree_distance)?;
        positive("CoarseConfig::agree_heading", self.agree_heading)?;
        at_least("CoarseConfig::max_points", self.max_points, 3)?;
        at_least("CoarseConfig::candidates", self.candidates, 1)?;
        if self.translation_range / self.translation_step > 1000.0 {
            return Err(MountingError::Config {
                field: "CoarseConfig::translation_step",
                reason: format!(
                    "{} m over a range of {} m: more than 1000 steps a side",
                    self.translation_step, self.translation_range
                ),
            });
        }
        Ok(())
    }
}

impl MountingConfig {
    /// Checks every value (see the field documentation for the ranges).
    pub fn validate(&self) -> Result<(), MountingError> {
        positive("MountingConfig::max_range", self.max_range)?;
        positive("MountingConfig::max_gap_periods", self.max_gap_periods)?;
        positive("MountingConfig::max_time_offset", self.max_time_offset)?;
        positive("MountingConfig::max_jump", self.max_jump)?;
        positive("MountingConfig::max_heading_jump", self.max_heading_jump)?;
        positive("MountingConfig::max_rms", self.max_rms)?;
        positive("MountingConfig::overlap_gate", self.overlap_gate)?;
        positive("MountingConfig::line_gate", self.line_gate)?;
        if !(0.0..=1.0).contains(&self.min_overlap) {
            return Err(MountingError::Config {
                field: "MountingConfig::min_overlap",
                reason: format!("{} (must lie in [0, 1])", self.min_overlap),
            });
        }
        at_least("MountingConfig::pair_stride", self.pair_stride, 1)?;
        at_least("MountingConfig::coarse_pairs", self.coarse_pairs, 1)?;
        at_least("MountingConfig::min_fits", self.min_fits, 1)?;
        at_least("MountingConfig::windows", self.windows, 1)?;
        self.coarse.validate()?;
        self.icp.validate()?;
        Ok(())
    }
}

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
struct HitGrid {
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

/// One sensor scan and the reference scans it was registered against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScanPair {
    /// Index of the sensor scan.
    pub sensor: usize,
    /// Index of the reference scan registered against (the earlier bracketing one with motion
    /// compensation, the nearest one without).
    pub reference: usize,
    /// With motion compensation, the later bracketing reference scan.
    pub next_reference: Option<usize>,
    /// Sensor time minus reference time (s).
    pub time_offset: f64,
    /// Where the sensor scan lies between the two reference scans (0 without compensation).
    pub alpha: f64,
}

/// The fine registration of one pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairFit {
    /// The pair.
    pub pair: ScanPair,
    /// The sensor scan's time (s).
    pub time: f64,
    /// The mounting this pair gives (after motion compensation).
    pub mounting: Pose2,
    /// The point-to-point ICP fit of sensor onto reference points (before the point-to-line
    /// refinement).
    pub fit: IcpFit,
    /// RMS of the point-to-line residuals after the refinement (m).
    pub line_rms: f64,
    /// Pairs of the point-to-line refinement.
    pub line_pairs: usize,
    /// The reference laser's motion between the bracketing scans (identity without
    /// compensation).
    pub reference_motion: Pose2,
    /// Whether the fit passed the checks of the module documentation (step 3).
    pub kept: bool,
}

/// Spread of the kept per-pair mountings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MountingSpread {
    /// Robust standard deviation (1.4826 × MAD) of x, y (m) and heading (rad).
    pub robust_std: [f64; 3],
    /// 5 % and 95 % quantiles of x, y (m) and heading (rad; as offsets from the estimate).
    pub p05: [f64; 3],
    /// See `p05`.
    pub p95: [f64; 3],
    /// Largest distance (m) and heading difference (rad) of a window's median from the
    /// estimate.
    pub window_max_deviation: [f64; 2],
}

/// Residual alignment error of the overlapping points at the final estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MountingResiduals {
    /// Median over the kept pairs of the RMS distance of the overlapping points to their
    /// nearest reference point (m).
    pub rms_median: f64,
    /// 90 % quantile over pairs of that RMS (m).
    pub rms_p90: f64,
    /// Median over pairs of the median distance of the overlapping points (m).
    pub median_distance: f64,
    /// Median over pairs of the share of sensor points that overlap.
    pub overlap_share: f64,
    /// Median over pairs of the RMS distance of the overlapping points from the reference
    /// scan's lines (where the nearest reference point has a line normal; m). Unlike the
    /// point distances it does not include the spacing of the reference beams.
    pub line_rms_median: f64,
}

/// What [`estimate_mounting`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct MountingEstimate {
    /// The sensor laser's pose in the reference laser's frame.
    pub mounting: Pose2,
    /// The coarse search's consensus (the fine stage's initial guess).
    pub coarse_guess: Pose2,
    /// Coarse pairs that agreed with the guess, of `coarse_tried`.
    pub coarse_votes: usize,
    /// Coarse pairs tried.
    pub coarse_tried: usize,
    /// Every fine fit, in sensor-scan order (pairs whose ICP failed are left out).
    pub fits: Vec<PairFit>,
    /// Pairs tried by the fine stage.
    pub pairs_tried: usize,
    /// Fits kept.
    pub pairs_kept: usize,
    /// Spread of the kept fits.
    pub spread: MountingSpread,
    /// Medians of the time windows, in time order.
    pub window_mountings: Vec<Pose2>,
    /// Residual alignment error at the estimate.
    pub residuals: MountingResiduals,
}

/// The returns of `scan` within `max_range`, into `out` (cleared first).
fn scan_points_into(scan: &Scan, max_range: f64, out: &mut Vec<[f64; 2]>) {
    out.clear();
    out.extend(
        scan.points()
            .filter(|(_, p)| p[0] * p[0] + p[1] * p[1] <= max_range * max_range)
            .map(|(_, p)| p),
    );
}

fn median(values: &mut [f64]) -> f64 {
    quantile(values, 0.5)
}

/// Linear-interpolated quantile `q` of `values` (sorted in place); NaN when empty.
fn quantile(values: &mut [f64], q: f64) -> f64 {
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
fn median_pose(poses: &[Pose2], about: f64) -> Pose2 {
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
fn make_pairs(
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
fn interpolate(motion: Pose2, alpha: f64) -> Pose2 {
    Pose2::new(alpha * motion.x, alpha * motion.y, alpha * motion.theta)
}

/// Scratch buffers of one pair's registration.
struct PairWork {
    icp: Icp,
    lines: Option<PlanarGrid>,
    source: Vec<[f64; 2]>,
    target: Vec<[f64; 2]>,
    next: Vec<[f64; 2]>,
}

impl PairWork {
    fn new(icp: IcpConfig) -> Result<Self, MountingError> {
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
    fn load(
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
    fn register(
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
const LINE_CELL: f64 = 0.15;

/// Iterations of the point-to-line refinement at most.
const LINE_ITERATIONS: usize = 30;

/// Point-to-line refinement of `start` (source → target): each moved source point within
/// [`MountingConfig::line_gate`] of its nearest target point that has a line normal `n` adds
/// the residual `n·(q − t)`; the Gauss-Newton step in `(x, y, θ)` is solved with a small
/// damping, so a direction no line constrains (a corridor's length) keeps its start value.
/// Returns the pose, the RMS of the residuals and their number; `None` with fewer than
/// [`IcpConfig::min_pairs`] pairs.
fn point_to_line(
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

/// Estimates the pose of the `sensor` laser in the frame of the `reference` laser from their
/// scans (each in time order, on one clock), as the module documentation describes.
/// Deterministic whatever the number of threads.
pub fn estimate_mounting(
    reference: &[Scan],
    sensor: &[Scan],
    config: &MountingConfig,
) -> Result<MountingEstimate, MountingError> {
    config.validate()?;
    for (which, scans) in [("reference", reference), ("sensor", sensor)] {
        if scans.len() < 2 {
            return Err(MountingError::TooFewScans {
                which,
                count: scans.len(),
                needed: 2,
            });
        }
    }
    let pairs = make_pairs(reference, sensor, config)?;

    // 1. Coarse search on pairs spread over the recording, then the vote.
    let n_coarse = config.coarse_pairs.min(pairs.len());
    let coarse_idx: Vec<usize> = (0..n_coarse)
        .map(|i| ((2 * i + 1) * pairs.len()) / (2 * n_coarse))
        .collect();
    let coarse_results: Vec<Option<CoarseCandidate>> = coarse_idx
        .par_iter()
        .map(|&i| -> Result<Option<CoarseCandidate>, MountingError> {
            let pair = &pairs[i];
            let mut work = PairWork::new(config.icp)?;
            let Some(motion) = work.load(pair, reference, sensor, config) else {
                return Ok(None);
            };
            let found = coarse_align(&work.source, &work.target, config)?;
            // Undo the reference motion so that all pairs vote on the mounting itself.
            Ok(found.first().map(|c| CoarseCandidate {
                pose: compose(inverse(motion), c.pose),
                score: c.score,
            }))
        })
        .collect::<Result<_, _>>()?;
    let found: Vec<CoarseCandidate> = coarse_results.into_iter().flatten().collect();
    if found.is_empty() {
        return Err(MountingError::NoCoarseAlignment { tried: n_coarse });
    }
    let agrees = |a: &Pose2, b: &Pose2| {
        (a.x - b.x).hypot(a.y - b.y) <= config.coarse.agree_distance
            && wrap_angle(a.theta - b.theta).abs() <= config.coarse.agree_heading
    };
    let (winner, votes) = found
        .iter()
        .map(|c| {
            let votes = found.iter().filter(|o| agrees(&c.pose, &o.pose)).count();
            (c, votes)
        })
        // Most votes, then best score; ties to the earliest pair.
        .fold(None::<(&CoarseCandidate, usize)>, |acc, (c, v)| match acc {
            Some((b, bv)) if bv > v || (bv == v && b.score >= c.score) => Some((b, bv)),
            _ => Some((c, v)),
        })
        .expect("found is not empty");
    let supporters: Vec<Pose2> = found
        .iter()
        .filter(|o| agrees(&winner.pose, &o.pose))
        .map(|o| o.pose)
        .collect();
    let guess = median_pose(&supporters, winner.pose.theta);

    // 2. Fine registration of every pair from the guess.
    let fits: Vec<Option<PairFit>> = pairs
        .par_iter()
        .map_init(
            || PairWork::new(config.icp),
            |work, pair| {
                let work = work.as_mut().ok()?;
                let motion = work.load(pair, reference, sensor, config)?;
                let (pose, fit, line_rms, line_pairs) =
                    work.register(compose(motion, guess), config)?;
                let mounting = compose(inverse(motion), pose);
                let kept = (mounting.x - guess.x).hypot(mounting.y - guess.y) <= config.max_jump
                    && wrap_angle(mounting.theta - guess.theta).abs() <= config.max_heading_jump
                    && fit.inlier_fraction >= config.min_overlap
                    && line_rms <= config.max_rms;
                Some(PairFit {
                    pair: *pair,
                    time: sensor[pair.sensor].time,
                    mounting,
                    fit,
                    line_rms,
                    line_pairs,
                    reference_motion: if pair.next_reference.is_some() && pair.alpha > 0.0 {
                        Pose2::new(
                            motion.x / pair.alpha,
                            motion.y / pair.alpha,
                            motion.theta / pair.alpha,
                        )
                    } else {
                        Pose2::new(0.0, 0.0, 0.0)
                    },
                    kept,
                })
            },
        )
        .collect();
    // A configuration error in the scratch set-up would have failed above already.
    let fits: Vec<PairFit> = fits.into_iter().flatten().collect();
    let kept: Vec<&PairFit> = fits.iter().filter(|f| f.kept).collect();
    if kept.len() < config.min_fits {
        return Err(MountingError::TooFewFits {
            kept: kept.len(),
            tried: pairs.len(),
            needed: config.min_fits,
            guess: [guess.x, guess.y, guess.theta],
        });
    }

    // 3. Robust aggregation and spread.
    let poses: Vec<Pose2> = kept.iter().map(|f| f.mounting).collect();
    let mounting = median_pose(&poses, guess.theta);
    let mut comps: [Vec<f64>; 3] = [
        poses.iter().map(|p| p.x).collect(),
        poses.iter().map(|p| p.y).collect(),
        poses
            .iter()
            .map(|p| wrap_angle(p.theta - mounting.theta))
            .collect(),
    ];
    let centre = [mounting.x, mounting.y, 0.0];
    let mut robust_std = [0.0; 3];
    let mut p05 = [0.0; 3];
    let mut p95 = [0.0; 3];
    for a in 0..3 {
        let mut dev: Vec<f64> = comps[a].iter().map(|v| (v - centre[a]).abs()).collect();
        robust_std[a] = 1.4826 * median(&mut dev);
        p05[a] = quantile(&mut comps[a], 0.05);
        p95[a] = quantile(&mut comps[a], 0.95);
    }
    let n_win = config.windows.min(poses.len());
    let window_mountings: Vec<Pose2> = (0..n_win)
        .map(|w| {
            let lo = w * poses.len() / n_win;
            let hi = (w + 1) * poses.len() / n_win;
            median_pose(&poses[lo..hi], mounting.theta)
        })
        .collect();
    let window_max_deviation = window_mountings.iter().fold([0.0f64; 2], |acc, w| {
        [
            acc[0].max((w.x - mounting.x).hypot(w.y - mounting.y)),
            acc[1].max(wrap_angle(w.theta - mounting.theta).abs()),
        ]
    });

    // 4. Residuals of the overlapping points at the estimate.
    let per_pair: Vec<Option<(f64, f64, f64, f64)>> = kept
        .par_iter()
        .map_init(
            || (PairWork::new(config.icp), Vec::<f64>::new()),
            |(work, dists), f| {
                let work = work.as_mut().ok()?;
                let motion = work.load(&f.pair, reference, sensor, config)?;
                let pose = compose(motion, mounting);
                let grid = work.lines.as_mut()?;
                let gate2 = config.overlap_gate * config.overlap_gate;
                dists.clear();
                let (mut line2, mut lines) = (0.0, 0usize);
                for &p in &work.source {
                    let q = transform_point(pose, p);
                    if let Some((j, d2)) = grid.nearest(q, gate2) {
                        dists.push(d2.sqrt());
                        if let Some(n) = grid.line_normal(j) {
                            let t = work.target[j];
                            let r = n[0] * (q[0] - t[0]) + n[1] * (q[1] - t[1]);
                            line2 += r * r;
                            lines += 1;
                        }
                    }
                }
                if dists.is_empty() {
                    return None;
                }
                let rms = (dists.iter().map(|d| d * d).sum::<f64>() / dists.len() as f64).sqrt();
                let share = dists.len() as f64 / work.source.len() as f64;
                let line_rms = (line2 / lines.max(1) as f64).sqrt();
                Some((rms, median(dists), share, line_rms))
            },
        )
        .collect();
    let per_pair: Vec<(f64, f64, f64, f64)> = per_pair.into_iter().flatten().collect();
    let mut rms: Vec<f64> = per_pair.iter().map(|r| r.0).collect();
    let mut med: Vec<f64> = per_pair.iter().map(|r| r.1).collect();
    let mut share: Vec<f64> = per_pair.iter().map(|r| r.2).collect();
    let mut line: Vec<f64> = per_pair.iter().map(|r| r.3).collect();
    let residuals = MountingResiduals {
        line_rms_median: median(&mut line),
        rms_median: median(&mut rms),
        rms_p90: quantile(&mut rms, 0.9),
        median_distance: median(&mut med),
        overlap_share: median(&mut share),
    };
    let pairs_kept = kept.len();
    Ok(MountingEstimate {
        mounting,
        coarse_guess: guess,
        coarse_votes: votes,
        coarse_tried: n_coarse,
        pairs_tried: pairs.len(),
        pairs_kept,
        spread: MountingSpread {
            robust_std,
            p05,
            p95,
            window_max_deviation,
        },
        window_mountings,
        residuals,
        fits,
    })
}

/// One laser's estimate from [`estimate_bag_mountings`].
#[derive(Clone, Debug, PartialEq)]
pub struct LaserMounting {
    /// The laser's topic.
    pub topic: String,
    /// The estimate in the reference laser's frame.
    pub estimate: MountingEstimate,
}

/// Reads the `sensor_msgs/LaserScan` topics `reference` and each of `sensors` from the ROS 1
/// bag at `path` (header stamps as times, odometry ignored) and estimates each sensor's
/// mounting in the reference laser's frame.
pub fn estimate_bag_mountings(
    path: impl AsRef<std::path::Path>,
    reference: &str,
    sensors: &[&str],
    config: &MountingConfig,
) -> Result<Vec<LaserMounting>, MountingError> {
    use super::rosbag::{read_bag, BagOptions, OdometryTopic};
    let path = path.as_ref();
    let read = |topic: &str| {
        read_bag(
            path,
            &BagOptions {
                scan_topic: Some(topic.to_string()),
                odometry: OdometryTopic::Ignore,
            },
        )
        .map(|b| b.scans)
    };
    let ref_scans = read(reference)?;
    let mut out = Vec::with_capacity(sensors.len());
    for &topic in sensors {
        let scans = read(topic)?;
        let estimate =
            estimate_mounting(&ref_scans, &scans, config).map_err(|e| MountingError::Laser {
                name: topic.to_string(),
                source: Box::new(e),
            })?;
        out.push(LaserMounting {
            topic: topic.to_string(),
            estimate,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A room 8 × 5 m with an inner box, seen by a 270° laser at `pose` (room frame), beams
    /// 0.5° apart, exact ranges (ray casting against the wall segments).
    fn room_scan(pose: Pose2, time: f64) -> Scan {
        let walls: Vec<[[f64; 2]; 2]> = {
            let mut w = crate::sim::people2d::box_walls([-3.0, 5.0], [-2.0, 3.0]).to_vec();
            w.extend(crate::sim::people2d::box_walls([1.0, 1.6], [1.0, 1.4]));
            w.push([[-3.0, -0.5], [-2.0, -1.5]]);
            w
        };
        let n = 541;
        let inc = 0.5f64.to_radians();
        let amin = -135f64.to_radians();
        let ranges: Vec<f32> = (0..n)
            .map(|i| {
                let a = pose.theta + amin + i as f64 * inc;
                let dir = [a.cos(), a.sin()];
                walls
                    .iter()
                    .filter_map(|w| {
                        crate::sim::people2d::ray_segment([pose.x, pose.y], dir, w[0], w[1])
                    })
                    .fold(f64::INFINITY, f64::min) as f32
            })
            .collect();
        Scan::new(time, amin, inc, ranges, 0.02, 20.0).unwrap()
    }

    #[test]
    fn recovers_a_rear_laser_on_a_moving_platform() {
        let mount = Pose2::new(-0.4, 0.1, 3.0);
        // Platform drives along x at 0.3 m/s and turns at 0.1 rad/s; reference at 10 Hz from
        // t = 0, the sensor 0.04 s later.
        let platform = |t: f64| Pose2::new(0.3 * t, 0.05 * t, 0.1 * t);
        let reference: Vec<Scan> = (0..40)
            .map(|k| room_scan(platform(0.1 * k as f64), 0.1 * k as f64))
            .collect();
        let sensor: Vec<Scan> = (0..40)
            .map(|k| {
                let t = 0.1 * k as f64 + 0.04;
                room_scan(compose(platform(t), mount), t)
            })
            .collect();
        let est = estimate_mounting(&reference, &sensor, &MountingConfig::default()).unwrap();
        let m = est.mounting;
        assert!((m.x - mount.x).abs() < 0.01, "{est:?}");
        assert!((m.y - mount.y).abs() < 0.01, "{m:?}");
        assert!(wrap_angle(m.theta - mount.theta).abs() < 0.005, "{m:?}");
        assert!(est.pairs_kept >= 30 && est.coarse_votes >= 3, "{est:?}");
        // Exact ranges: the overlap lies on the reference lines (the point distances also
        // hold the beam spacing).
        assert!(est.residuals.line_rms_median < 0.002, "{:?}", est.residuals);
        assert!(est.residuals.median_distance < 0.02, "{:?}", est.residuals);
        // Without motion compensation (and a loose time gate) the 0.04 s offset shows.
        let loose = MountingConfig {
            motion_compensation: false,
            max_time_offset: 0.05,
            ..MountingConfig::default()
        };
        let raw = estimate_mounting(&reference, &sensor, &loose).unwrap();
        let err = |p: Pose2| (p.x - mount.x).hypot(p.y - mount.y);
        assert!(
            err(raw.mounting) > err(m) + 0.005,
            "{:?} vs {m:?}",
            raw.mounting
        );
    }

    #[test]
    fn coarse_search_finds_any_heading() {
        let reference = room_scan(Pose2::new(0.0, 0.0, 0.0), 0.0);
        let target: Vec<[f64; 2]> = reference.points().map(|(_, p)| p).collect();
        for mount in [
            Pose2::new(0.3, -0.2, 1.2),
            Pose2::new(-0.5, 0.4, -2.5),
            Pose2::new(0.1, 0.6, 0.4),
        ] {
            let s = room_scan(mount, 0.0);
            let source: Vec<[f64; 2]> = s.points().map(|(_, p)| p).collect();
            let found = coarse_align(&source, &target, &MountingConfig::default()).unwrap();
            let best = found[0].pose;
            assert!(
                (best.x - mount.x).hypot(best.y - mount.y) < 0.02
                    && wrap_angle(best.theta - mount.theta).abs() < 0.01,
                "{mount:?}: {found:?}"
            );
        }
    }

    #[test]
    fn bad_input_is_a_typed_error() {
        let s = room_scan(Pose2::new(0.0, 0.0, 0.0), 0.0);
        assert!(matches!(
            estimate_mounting(
                &[s.clone()],
                &[s.clone(), s.clone()],
                &MountingConfig::default()
            ),
            Err(MountingError::TooFewScans {
                which: "reference",
                ..
            })
        ));
        let bad = MountingConfig {
            windows: 0,
            ..MountingConfig::default()
        };
        assert!(matches!(
            estimate_mounting(&[s.clone(), s.clone()], &[s.clone()], &bad),
            Err(MountingError::Config {
                field: "MountingConfig::windows",
                ..
            })
        ));
        // Sensor scans long after the reference ones: nothing pairs.
        let mut late = s.clone();
        late.time = 100.0;
        let mut r1 = s.clone();
        r1.time = 0.1;
        assert!(matches!(
            estimate_mounting(
                &[s.clone(), r1],
                &[late.clone(), late],
                &MountingConfig::default()
            ),
            Err(MountingError::NoPairs { .. })
        ));
        let e: crate::Error = MountingError::NoCoarseAlignment { tried: 3 }.into();
        assert!(e.to_string().contains("coarse"), "{e}");
    }
}
