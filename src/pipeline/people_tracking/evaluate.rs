//! Scores a people tracker on a simulated run ([`People2dRun`]): every scan is turned into
//! range-bearing measurements by the front end ([`FrontEnd`]: every person-sized segment, or
//! only those the moving-object detector marks as moving), handed with the robot's pose to any
//! [`PointTracker`], and the estimates are compared with the people the scanner actually saw
//! (at least three beams on them).
//!
//! The pose is the odometry, the simulator's truth, or the moving-object detector's
//! ICP-corrected pose ([`PoseSource::Icp`]; a detector then runs whatever the front end).
//!
//! With the odometry pose the truth is, by default, moved into the tracker's frame scan by
//! scan ([`ScoreFrame::Robot`]): where the person is relative to the true robot pose is where
//! they should be relative to the pose the tracker got. None of the trackers localises the
//! robot, so drift is scored only with [`ScoreFrame::World`].
//!
//! The truth of a scan is the people the scanner saw (at least three beams ended on them).
//! People who are present but unseen — hidden behind others, too far, outside the field of
//! view — are "don't care" objects, as in the KITTI and MOT tracking benchmarks: an estimate
//! the optimal gated pairing gives to one of them is dropped, neither right nor false, so a
//! tracker is not punished for keeping a person through a short occlusion
//! ([`EvalConfig::ignore_unseen`], on by default).
//!
//! Per run: mean OSPA and OSPA(2) (cut-off c and order p, seed-independent defaults c = 2 m,
//! p = 1), label switches and whether every person kept one label ([`LabelConsistency`]),
//! scans per second of segmentation plus tracking, and, for trackers that report innovations,
//! the RMS prediction error (measured minus predicted position) and the time-averaged NIS with
//! its two-sided 95 % χ² interval, over the whole run and over windows of K steps (seed 003,
//! appendix, K = 20). [`summarise`] pools runs.
//!
//! Not for: real recordings without ground truth.

use super::front_end::{default_detector_config, FrontEnd, PersonFrontEnd};
use super::PeopleTrackerConfig;
use crate::error::{Error, Result};
use crate::filter::Label;
use crate::geometry::Pose2;
use crate::metrics::gospa::gated_pairing;
use crate::metrics::{average_nis, ospa, ospa2, tracks_from_frames, LabelConsistency, NisCheck};
use crate::sim::People2dRun;
use crate::trackers::{BeamRanges, PointTracker, StepClock};
use serde::Serialize;
use std::time::Instant;

/// Which robot pose the tracker is given.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PoseSource {
    /// The scan's noisy, drifting odometry (what a robot has).
    #[default]
    Odometry,
    /// The simulator's true robot pose (judges the tracker apart from localisation).
    Truth,
    /// The odometry refined by the moving-object detector's ICP against its local map.
    Icp,
}

/// The frame the estimates are scored in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ScoreFrame {
    /// Truth relative to the true robot pose, placed with the pose the tracker was handed:
    /// scores the tracking apart from the drift of that pose (identical to `World` when the
    /// tracker gets the true pose).
    #[default]
    Robot,
    /// The simulator's world frame: odometry drift counts as tracking error.
    World,
}

/// How runs are scored.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EvalConfig {
    /// OSPA / OSPA(2) cut-off (m); also the label-matching distance. Default 2 m.
    pub cutoff: f64,
    /// OSPA order. Default 1.
    pub order: f64,
    /// Robot pose source. Default odometry.
    pub pose: PoseSource,
    /// Scoring frame. Default [`ScoreFrame::Robot`].
    pub frame: ScoreFrame,
    /// Steps K per time-averaged NIS window. Default 20.
    pub nis_window: usize,
    /// Which returns become measurements. Default [`FrontEnd::Segments`].
    pub front_end: FrontEnd,
    /// Estimates of people who are present but not seen (module documentation) are dropped
    /// instead of scored as false. Default true.
    pub ignore_unseen: bool,
}

impl Default for EvalConfig {
    fn default() -> Self {
        EvalConfig {
            cutoff: 2.0,
            order: 1.0,
            pose: PoseSource::Odometry,
            frame: ScoreFrame::Robot,
            nis_window: 20,
            front_end: FrontEnd::Segments,
            ignore_unseen: true,
        }
    }
}

/// A person of one scan: id and position.
type Person = (u64, Vec<f64>);

/// The scores of one run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunMetrics {
    /// Mean over scans of the OSPA distance (m).
    pub mean_ospa: f64,
    /// OSPA(2) over the whole run (m).
    pub ospa2: f64,
    /// Label switches summed over people.
    pub label_switches: usize,
    /// Whether every person that was ever matched kept a single label.
    pub all_labels_kept: bool,
    /// Scans processed.
    pub scans: usize,
    /// Wall-clock seconds of segmentation and tracking.
    pub seconds: f64,
    /// Squared position innovations summed, and their number (for the RMS prediction error).
    pub squared_error_sum: f64,
    /// Number of innovations.
    pub innovations: usize,
    /// Every NIS value of the run, in order.
    #[serde(skip)]
    pub nis: Vec<f64>,
    /// NIS windows of K steps with at least one value, and how many of them lay inside their
    /// 95 % interval.
    pub nis_windows: (usize, usize),
}

impl RunMetrics {
    /// RMS prediction error (m), or `None` without innovations.
    pub fn rms_prediction_error(&self) -> Option<f64> {
        (self.innovations > 0).then(|| (self.squared_error_sum / self.innovations as f64).sqrt())
    }
}

/// Runs `tracker` over `run`, measuring with `detector` (its segmentation settings) through
/// the front end `config.front_end`; the moving-object detector, when one runs, takes
/// [`default_detector_config`].
pub fn evaluate_run(
    tracker: &mut dyn PointTracker,
    run: &People2dRun,
    detector: &PeopleTrackerConfig,
    config: &EvalConfig,
) -> Result<RunMetrics> {
    let needs_detector = config.front_end == FrontEnd::Moving || config.pose == PoseSource::Icp;
    let moving = match run.scans.first() {
        Some(scan) if needs_detector => {
            Some(default_detector_config(detector, scan.angle_increment))
        }
        _ => None,
    };
    let mut front_end = PersonFrontEnd::new(config.front_end, detector, moving)?;
    evaluate_run_with(tracker, run, &mut front_end, config)
}

/// [`evaluate_run`] with a front end of the caller's (`config.front_end` is not read; a
/// [`PoseSource::Icp`] run needs a front end that runs a detector).
pub fn evaluate_run_with(
    tracker: &mut dyn PointTracker,
    run: &People2dRun,
    front_end: &mut PersonFrontEnd,
    config: &EvalConfig,
) -> Result<RunMetrics> {
    let (c, p) = (config.cutoff, config.order);
    let mut labels = LabelConsistency::new(c)?;
    let mut clock = StepClock::new();
    let (mut truth_frames, mut est_frames) = (Vec::new(), Vec::new());
    let mut ospa_sum = 0.0;
    let mut seconds = 0.0;
    let mut beam_ranges = Vec::new();
    let (mut sq, mut count) = (0.0, 0usize);
    let mut nis = Vec::new();
    let mut windows = (0, 0);
    let mut window: Vec<f64> = Vec::new();
    for (k, scan) in run.scans.iter().enumerate() {
        let true_pose = *run.robot_truth.get(k).ok_or_else(|| {
            Error::invalid("people run", format!("no true robot pose for scan {k}"))
        })?;
        let t0 = Instant::now();
        let out = front_end.measure(scan, scan.odometry)?;
        let pose = match config.pose {
            PoseSource::Odometry => scan.odometry,
            PoseSource::Truth => Some(true_pose),
            PoseSource::Icp => Some(out.corrected_pose.ok_or_else(|| {
                Error::invalid(
                    "pose source icp",
                    "the front end runs no moving-object detector",
                )
            })?),
        };
        let place = match (config.frame, pose) {
            (ScoreFrame::Robot, Some(given)) => Some((true_pose, given)),
            _ => None,
        };
        let ctx = clock.tick(scan.time, pose)?;
        scan.ranges_into(&mut beam_ranges);
        tracker.observe_beams(BeamRanges {
            angle_min: scan.angle_min,
            angle_increment: scan.angle_increment,
            ranges: &beam_ranges,
        });
        let est = tracker.step(&out.measurements, &ctx)?;
        seconds += t0.elapsed().as_secs_f64();
        for inn in tracker.innovations() {
            sq += inn.position_error[0].powi(2) + inn.position_error[1].powi(2);
            count += 1;
            if inn.nis.is_finite() {
                nis.push(inn.nis);
                window.push(inn.nis);
            }
        }
        if (k + 1) % config.nis_window.max(1) == 0 && !window.is_empty() {
            windows.0 += 1;
            windows.1 += average_nis(&window, 2)?.consistent as usize;
            window.clear();
        }
        let seen = run.visible.get(k).map(Vec::as_slice).unwrap_or(&[]);
        let (truth, unseen): (Vec<Person>, Vec<Person>) = run
            .people_truth
            .get(k)
            .into_iter()
            .flatten()
            .map(|(id, p, _)| {
                let p = place.map_or(*p, |(from, to)| relocate(*p, from, to));
                (*id, p.to_vec())
            })
            .partition(|(id, _)| seen.contains(id));
        let mut x: Vec<_> = est
            .iter()
            .map(|e| (e.label, vec![e.state[0], e.state[2]]))
            .collect();
        if config.ignore_unseen {
            x = drop_unseen(&truth, &unseen, x, c, p)?;
        }
        let tp: Vec<&Vec<f64>> = truth.iter().map(|(_, p)| p).collect();
        let xp: Vec<&Vec<f64>> = x.iter().map(|(_, p)| p).collect();
        ospa_sum += ospa(&tp, &xp, c, p)?.distance;
        labels.add_step(&truth, &x)?;
        truth_frames.push(truth);
        est_frames.push(x);
    }
    let steps = run.scans.len();
    let tt = tracks_from_frames(&truth_frames)?;
    let te = tracks_from_frames(&est_frames)?;
    let stats = labels.finish();
    Ok(RunMetrics {
        mean_ospa: ospa_sum / steps.max(1) as f64,
        ospa2: ospa2(&tt, &te, 0..steps, c, p, 1.0)?,
        label_switches: stats.switches,
        all_labels_kept: stats.all_kept,
        scans: steps,
        seconds,
        squared_error_sum: sq,
        innovations: count,
        nis,
        nis_windows: windows,
    })
}

/// The estimates left after removing those that the optimal gated pairing of all present
/// people (`seen` then `unseen`) gives to an unseen person.
pub(crate) fn drop_unseen(
    seen: &[Person],
    unseen: &[Person],
    estimates: Vec<(Label, Vec<f64>)>,
    c: f64,
    p: f64,
) -> Result<Vec<(Label, Vec<f64>)>> {
    if unseen.is_empty() || estimates.is_empty() {
        return Ok(estimates);
    }
    let people: Vec<&[f64]> = seen
        .iter()
        .chain(unseen)
        .map(|(_, x)| x.as_slice())
        .collect();
    let ys: Vec<&[f64]> = estimates.iter().map(|(_, y)| y.as_slice()).collect();
    let pairing = gated_pairing(&people, &ys, c, p)?;
    let mut drop = vec![false; estimates.len()];
    for j in pairing[seen.len()..].iter().flatten() {
        drop[*j] = true;
    }
    Ok(estimates
        .into_iter()
        .zip(drop)
        .filter_map(|(e, d)| (!d).then_some(e))
        .collect())
}

/// The world point `p` seen from robot pose `from`, placed at the same spot relative to `to`.
pub(crate) fn relocate(p: [f64; 2], from: Pose2, to: Pose2) -> [f64; 2] {
    let (s, c) = from.theta.sin_cos();
    let (dx, dy) = (p[0] - from.x, p[1] - from.y);
    let local = [c * dx + s * dy, -s * dx + c * dy];
    let (s, c) = to.theta.sin_cos();
    [
        to.x + c * local[0] - s * local[1],
        to.y + s * local[0] + c * local[1],
    ]
}

/// Runs pooled per tracker.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// Runs pooled.
    pub runs: usize,
    /// Mean over runs of the per-run mean OSPA (m).
    pub mean_ospa: f64,
    /// Mean over runs of OSPA(2) (m).
    pub mean_ospa2: f64,
    /// Label switches summed over runs.
    pub label_switches: usize,
    /// Fraction of runs in which every person kept one label.
    pub all_labels_kept_fraction: f64,
    /// Scans per second of segmentation plus tracking.
    pub scans_per_second: f64,
    /// RMS prediction error over all innovations of all runs (m).
    pub rms_prediction_error: Option<f64>,
    /// Time-averaged NIS over all runs with its 95 % interval (2 degrees of freedom per value).
    pub nis: Option<NisCheck>,
    /// Fraction of K-step NIS windows inside their 95 % interval.
    pub nis_window_consistent_fraction: Option<f64>,
}

/// Pools the runs of one tracker; an error for no runs.
pub fn summarise(runs: &[RunMetrics]) -> Result<Summary> {
    if runs.is_empty() {
        return Err(Error::invalid("run summary", "no runs"));
    }
    let n = runs.len() as f64;
    let scans: usize = runs.iter().map(|r| r.scans).sum();
    let seconds: f64 = runs.iter().map(|r| r.seconds).sum();
    let count: usize = runs.iter().map(|r| r.innovations).sum();
    let sq: f64 = runs.iter().map(|r| r.squared_error_sum).sum();
    let all_nis: Vec<f64> = runs.iter().flat_map(|r| r.nis.iter().copied()).collect();
    let (w_all, w_ok) = runs.iter().fold((0, 0), |(a, b), r| {
        (a + r.nis_windows.0, b + r.nis_windows.1)
    });
    Ok(Summary {
        runs: runs.len(),
        mean_ospa: runs.iter().map(|r| r.mean_ospa).sum::<f64>() / n,
        mean_ospa2: runs.iter().map(|r| r.ospa2).sum::<f64>() / n,
        label_switches: runs.iter().map(|r| r.label_switches).sum(),
        all_labels_kept_fraction: runs.iter().filter(|r| r.all_labels_kept).count() as f64 / n,
        scans_per_second: if seconds > 0.0 {
            scans as f64 / seconds
        } else {
            f64::INFINITY
        },
        rms_prediction_error: (count > 0).then(|| (sq / count as f64).sqrt()),
        nis: if all_nis.is_empty() {
            None
        } else {
            Some(average_nis(&all_nis, 2)?)
        },
        nis_window_consistent_fraction: (w_all > 0).then(|| w_ok as f64 / w_all as f64),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(ospa: f64, kept: bool, scans: usize, seconds: f64) -> RunMetrics {
        RunMetrics {
            mean_ospa: ospa,
            ospa2: 2.0 * ospa,
            label_switches: 3,
            all_labels_kept: kept,
            scans,
            seconds,
            squared_error_sum: 8.0,
            innovations: 2,
            nis: vec![2.0, 2.0],
            nis_windows: (1, 1),
        }
    }

    #[test]
    fn relocate_keeps_the_point_where_it_is_relative_to_the_robot() {
        // Robot truly at the origin facing +y; a person 2 m ahead is at (0, 2).
        let from = Pose2::new(0.0, 0.0, std::f64::consts::FRAC_PI_2);
        // The odometry believes the robot is at (5, 1) facing +x: 2 m ahead is (7, 1).
        let to = Pose2::new(5.0, 1.0, 0.0);
        let q = relocate([0.0, 2.0], from, to);
        assert!(
            (q[0] - 7.0).abs() < 1e-12 && (q[1] - 1.0).abs() < 1e-12,
            "{q:?}"
        );
        // Same pose: unchanged.
        let q = relocate([3.0, -4.0], to, to);
        assert!(
            (q[0] - 3.0).abs() < 1e-12 && (q[1] + 4.0).abs() < 1e-12,
            "{q:?}"
        );
    }

    #[test]
    fn estimates_of_unseen_people_are_dropped_not_scored() {
        let l = |i| Label {
            birth_step: 0,
            index: i,
        };
        let seen = vec![(1, vec![0.0, 0.0])];
        let unseen = vec![(2, vec![5.0, 0.0])];
        let est = vec![
            (l(0), vec![0.1, 0.0]),  // the seen person
            (l(1), vec![5.2, 0.1]),  // the hidden person: dropped
            (l(2), vec![20.0, 0.0]), // nobody: stays, a false estimate
        ];
        let kept = drop_unseen(&seen, &unseen, est.clone(), 2.0, 1.0).unwrap();
        let labels: Vec<u32> = kept.iter().map(|(l, _)| l.index).collect();
        assert_eq!(labels, vec![0, 2]);
        // Nobody unseen: nothing dropped.
        assert_eq!(drop_unseen(&seen, &[], est.clone(), 2.0, 1.0).unwrap(), est);
    }

    #[test]
    fn summary_pools_runs() {
        let s = summarise(&[run(1.0, true, 100, 1.0), run(0.5, false, 100, 3.0)]).unwrap();
        assert!((s.mean_ospa - 0.75).abs() < 1e-12 && (s.mean_ospa2 - 1.5).abs() < 1e-12);
        assert_eq!(s.label_switches, 6);
        assert_eq!(s.all_labels_kept_fraction, 0.5);
        // 200 scans in 4 s
        assert_eq!(s.scans_per_second, 50.0);
        // √(16 / 4)
        assert_eq!(s.rms_prediction_error, Some(2.0));
        assert_eq!(s.nis.unwrap().mean, 2.0);
        assert!(summarise(&[]).is_err());
    }
}
