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

mod coarse;
mod config;
mod register;

pub use coarse::{coarse_align, CoarseCandidate};
pub use config::{CoarseConfig, MountingConfig};
use register::{make_pairs, median, median_pose, point_to_line, quantile, PairWork, LINE_CELL};

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
                std::slice::from_ref(&s),
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
            estimate_mounting(&[s.clone(), s.clone()], std::slice::from_ref(&s), &bad),
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
