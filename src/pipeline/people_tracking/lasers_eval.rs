//! Scores the people tracker of several lasers ([`super::lasers`]) on a simulated robot with
//! several lasers ([`crate::sim::people2d::lasers`]): any subset of the rig's lasers (one laser
//! alone, or all of them fused by a rule) runs on the same simulated run, and every subset is
//! scored against the same truth.
//!
//! The truth of a frame (at its anchor scan's time) is every person present that some laser
//! of the whole rig saw (at least the simulator's minimum of beams on them) in its scan nearest
//! that time, within half its period; people present but seen by none are "don't care", as in
//! [`super::evaluate`]. The truth is placed relative to the pose the tracker was handed
//! ([`super::evaluate::ScoreFrame::Robot`]: odometry drift is not scored). Reported: detection
//! precision, recall and F1 (pairs within [`super::score::MATCH_DISTANCE`]), mean OSPA and
//! OSPA(2) (c = 2 m, p = 1) and label switches.
//!
//! Not for: real recordings (see [`super::score`]).

use super::evaluate::{drop_unseen, relocate};
use super::front_end::FrontEnd;
use super::lasers::{group_scans, track_lasers, LaserMount, LaserRecording};
use super::score::DetectionScore;
use super::tracker::PeopleTrackerConfig;
use crate::error::{Error, Result};
use crate::filter::{Fusion, Label};
use crate::metrics::{ospa, ospa2, tracks_from_frames, LabelConsistency};
use crate::sim::people2d::lasers::{LaserRig, MultiLaserRun};
use serde::Serialize;

/// A person of one frame: id and position.
type Person = (u64, Vec<f64>);

/// OSPA cut-off (m) and order of [`evaluate_lasers`].
pub const OSPA_CUTOFF: f64 = 2.0;
/// OSPA order.
pub const OSPA_ORDER: f64 = 1.0;

/// The scores of one subset of lasers on one run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LasersScore {
    /// Frames scored.
    pub frames: usize,
    /// Detection counts over the frames.
    pub detection: DetectionScore,
    /// Mean over frames of the OSPA distance (m).
    pub mean_ospa: f64,
    /// OSPA(2) over the run (m).
    pub ospa2: f64,
    /// Label switches summed over people.
    pub label_switches: usize,
    /// Wall-clock seconds of front end and tracking.
    pub seconds: f64,
}

/// The people some laser of `run` saw at time `t`: for every laser, the visible people of its
/// scan nearest `t` when within half its median period.
fn seen_at(run: &MultiLaserRun, t: f64) -> Vec<u64> {
    let mut ids = Vec::new();
    for l in &run.lasers {
        let times: Vec<f64> = l.scans.iter().map(|s| s.time).collect();
        let period = if times.len() >= 2 {
            (times[times.len() - 1] - times[0]) / (times.len() - 1) as f64
        } else {
            f64::INFINITY
        };
        let after = times.partition_point(|&a| a < t);
        let best = [after.checked_sub(1), (after < times.len()).then_some(after)]
            .into_iter()
            .flatten()
            .min_by(|&a, &b| (times[a] - t).abs().total_cmp(&(times[b] - t).abs()));
        if let Some(k) = best {
            if (times[k] - t).abs() <= 0.5 * period + 1e-9 {
                ids.extend(l.visible[k].iter().copied());
            }
        }
    }
    ids.sort_unstable();
    ids.dedup();
    ids
}

/// Runs the lasers `use_lasers` of `rig` (indices into it and into `run`'s streams) fused by
/// `fusion`, through `front_end`, with the people settings `config` (the scanner's noise;
/// each laser's field of view and range come from its scans), and scores them (module
/// documentation).
pub fn evaluate_lasers(
    run: &MultiLaserRun,
    rig: &LaserRig,
    use_lasers: &[usize],
    config: &PeopleTrackerConfig,
    front_end: FrontEnd,
    fusion: Fusion,
) -> Result<LasersScore> {
    if run.lasers.len() != rig.lasers.len() {
        return Err(Error::invalid(
            "laser evaluation",
            format!(
                "the run has {} lasers, the rig {}",
                run.lasers.len(),
                rig.lasers.len()
            ),
        ));
    }
    let mut recordings = Vec::with_capacity(use_lasers.len());
    for &j in use_lasers {
        let (Some(laser), Some(stream)) = (rig.lasers.get(j), run.lasers.get(j)) else {
            return Err(Error::invalid(
                "laser evaluation",
                format!("no laser {j} in a rig of {}", rig.lasers.len()),
            ));
        };
        let first = stream
            .scans
            .first()
            .ok_or_else(|| Error::invalid(format!("laser {:?}", laser.name), "has no scan"))?;
        recordings.push(LaserRecording {
            mount: LaserMount::for_scan(
                laser.name.clone(),
                laser.mounting_pose(),
                first,
                laser.scanner.range_max,
            ),
            scans: stream.scans.clone(),
        });
    }
    let times: Vec<Vec<f64>> = recordings
        .iter()
        .map(|r| r.scans.iter().map(|s| s.time).collect())
        .collect();
    let (anchor, _) = group_scans(&times)?;
    let anchor = use_lasers[anchor];
    let min_visibility = config.min_visibility;
    let t0 = std::time::Instant::now();
    let people = track_lasers(&recordings, config.clone(), front_end, fusion)?;
    let seconds = t0.elapsed().as_secs_f64();
    let (c, p) = (OSPA_CUTOFF, OSPA_ORDER);
    let stream = &run.lasers[anchor];
    let mut labels = LabelConsistency::new(c)?;
    let mut detection = DetectionScore::default();
    let (mut truth_frames, mut est_frames) = (Vec::new(), Vec::new());
    let mut ospa_sum = 0.0;
    for frame in &people.scans {
        let k = frame.scan;
        let true_pose = stream.robot_truth[k];
        let given = frame
            .pose
            .map(|[x, y, th]| crate::geometry::Pose2::new(x, y, th));
        let seen = seen_at(run, frame.time);
        let (truth, unseen): (Vec<Person>, Vec<Person>) = stream.people_truth[k]
            .iter()
            .map(|(id, pos, _)| {
                let q = given.map_or(*pos, |g| relocate(*pos, true_pose, g));
                (*id, q.to_vec())
            })
            .partition(|(id, _)| seen.contains(id));
        let x: Vec<(Label, Vec<f64>)> = frame
            .people
            .iter()
            .filter(|e| e.visibility >= min_visibility)
            .map(|e| (e.label, e.position.to_vec()))
            .collect();
        let x = drop_unseen(&truth, &unseen, x, c, p)?;
        let tp: Vec<&Vec<f64>> = truth.iter().map(|(_, q)| q).collect();
        let xp: Vec<&Vec<f64>> = x.iter().map(|(_, q)| q).collect();
        ospa_sum += ospa(&tp, &xp, c, p)?.distance;
        let t2: Vec<[f64; 2]> = truth.iter().map(|(_, q)| [q[0], q[1]]).collect();
        let x2: Vec<[f64; 2]> = x.iter().map(|(_, q)| [q[0], q[1]]).collect();
        detection.add_scan(&t2, &x2)?;
        labels.add_step(&truth, &x)?;
        truth_frames.push(truth);
        est_frames.push(x);
    }
    let steps = people.scans.len();
    let tt = tracks_from_frames(&truth_frames)?;
    let te = tracks_from_frames(&est_frames)?;
    Ok(LasersScore {
        frames: steps,
        detection,
        mean_ospa: ospa_sum / steps.max(1) as f64,
        ospa2: ospa2(&tt, &te, 0..steps, c, p, 1.0)?,
        label_switches: labels.finish().switches,
        seconds,
    })
}

/// One way of running the rig's lasers: a subset, fused by a rule.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LaserVariant {
    /// How it is reported: a laser's name alone, or `fused <rule>`.
    pub name: String,
    /// The lasers (indices into the rig).
    pub lasers: Vec<usize>,
    /// Their fusion rule (`ic`, `pu`, `ga` or `aa`).
    pub fusion: crate::filter::FusionMethod,
}

impl LaserVariant {
    /// Every laser of `rig` alone, then all of them fused by each of `rules`.
    pub fn singles_and_fused(rig: &LaserRig, rules: &[crate::filter::FusionMethod]) -> Vec<Self> {
        let all: Vec<usize> = (0..rig.lasers.len()).collect();
        rig.lasers
            .iter()
            .enumerate()
            .map(|(j, l)| LaserVariant {
                name: l.name.clone(),
                lasers: vec![j],
                fusion: crate::filter::FusionMethod::IteratedCorrector,
            })
            .chain(rules.iter().map(|&m| LaserVariant {
                name: format!("fused {}", m.short_name()),
                lasers: all.clone(),
                fusion: m,
            }))
            .collect()
    }
}

/// A variant's scores pooled over runs: means over runs of each run's value (detection
/// counts summed).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VariantSummary {
    /// The variant.
    pub variant: LaserVariant,
    /// Runs pooled.
    pub runs: usize,
    /// Mean over runs of the per-run F1.
    pub f1: f64,
    /// Mean over runs of the per-run precision.
    pub precision: f64,
    /// Mean over runs of the per-run recall.
    pub recall: f64,
    /// Mean over runs of the per-run mean OSPA (m).
    pub mean_ospa: f64,
    /// Mean over runs of OSPA(2) (m).
    pub ospa2: f64,
    /// Label switches summed over runs.
    pub label_switches: usize,
    /// Frames per second of front end and tracking, over all runs.
    pub frames_per_second: f64,
    /// The per-run scores.
    pub per_run: Vec<LasersScore>,
}

/// Pools the scores of one variant's runs; an error without runs.
pub fn summarise_variant(variant: LaserVariant, runs: Vec<LasersScore>) -> Result<VariantSummary> {
    if runs.is_empty() {
        return Err(Error::invalid(
            format!("laser variant {}", variant.name),
            "no runs to pool",
        ));
    }
    let n = runs.len() as f64;
    let mean = |f: &dyn Fn(&LasersScore) -> f64| runs.iter().map(f).sum::<f64>() / n;
    let frames: usize = runs.iter().map(|r| r.frames).sum();
    let secs: f64 = runs.iter().map(|r| r.seconds).sum();
    Ok(VariantSummary {
        runs: runs.len(),
        f1: mean(&|r| r.detection.f1()),
        precision: mean(&|r| r.detection.precision()),
        recall: mean(&|r| r.detection.recall()),
        mean_ospa: mean(&|r| r.mean_ospa),
        ospa2: mean(&|r| r.ospa2),
        label_switches: runs.iter().map(|r| r.label_switches).sum(),
        frames_per_second: if secs > 0.0 {
            frames as f64 / secs
        } else {
            0.0
        },
        variant,
        per_run: runs,
    })
}
