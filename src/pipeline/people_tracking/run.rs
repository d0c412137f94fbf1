//! People tracking over a whole recording: runs [`PeopleTracker`] on a sequence of scans
//! (CARMEN log, ROS bag, simulation), keeps every scan's people, sums each track up (how long
//! it lived, how fast it went, how often it was dynamic) and writes the per-scan estimates as
//! JSON.
//!
//! The measurements come from a front end ([`FrontEnd`]): every person-sized segment
//! ([`track_scans`]), or, with [`track_scans_with`] and [`FrontEnd::Moving`], only those the
//! moving-object detector marks as moving; the tracker then assumes that front end's
//! detection probability and clutter rate ([`adapt_tracker_config`]) and is handed the
//! detector's ICP-corrected pose instead of the raw odometry, so that odometry drift does not
//! make furniture look like walking people.
//!
//! Not for: reading the recordings (see [`crate::laser2d::carmen`], [`crate::laser2d::rosbag`]), plotting, or
//! scoring against ground truth.

use super::front_end::{adapt_tracker_config, default_detector_config, FrontEnd, PersonFrontEnd};
use super::tracker::{PeopleTracker, PeopleTrackerConfig, PersonEstimate};
use crate::error::{Error, Result};
use crate::filter::Label;
use crate::geometry::platform_isometry;
use crate::geometry::Pose2;
use crate::laser2d::legs::LegModel;
use crate::laser2d::{PoseFallback, Scan};
use std::collections::BTreeMap;
use std::path::Path;

/// The people of one scan.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ScanPeople {
    /// Index of the scan in the recording.
    pub scan: usize,
    /// Time stamp (s).
    pub time: f64,
    /// Robot pose used for the scan (the odometry, or with the moving front end the
    /// detector's ICP-corrected pose), if any.
    pub pose: Option<[f64; 3]>,
    /// Every person of the filter's estimate, visible or not (see
    /// [`PersonEstimate::visibility`]).
    pub people: Vec<PersonEstimate>,
    /// The front end's people of the scan, `[x, y]` in the sensor frame (what the tracker
    /// was handed).
    #[serde(default)]
    pub detections: Vec<[f64; 2]>,
    /// With the moving front end: why the scan matching's pose was not used, if it was not
    /// (the prediction, from odometry or constant velocity, stood instead).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pose_fallback: Option<PoseFallback>,
}

/// One track over the recording, counted over the scans in which it was reported as visible
/// (visibility at least the tracker's `min_visibility`).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PersonTrack {
    /// The label.
    pub label: Label,
    /// Scans in which the track was visible.
    pub scans: usize,
    /// First and last time it was visible (s).
    pub first_time: f64,
    /// Last time it was visible (s).
    pub last_time: f64,
    /// Mean estimated speed over those scans (m/s).
    pub mean_speed: f64,
    /// Share of those scans in which it was classed dynamic.
    pub dynamic_fraction: f64,
    /// Straight-line distance between its first and last visible position (m).
    pub displacement: f64,
}

/// A whole recording's people.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PeopleRun {
    /// Per scan.
    pub scans: Vec<ScanPeople>,
    /// Per track, by label.
    pub tracks: Vec<PersonTrack>,
}

impl PeopleRun {
    /// How many scans kept the predicted pose, by reason (reasons that never occurred are
    /// left out).
    pub fn pose_fallbacks(&self) -> BTreeMap<PoseFallback, usize> {
        let mut out = BTreeMap::new();
        for why in self.scans.iter().filter_map(|s| s.pose_fallback) {
            *out.entry(why).or_insert(0) += 1;
        }
        out
    }

    /// Tracks visible in at least `min_scans` scans.
    pub fn tracks_with(&self, min_scans: usize) -> impl Iterator<Item = &PersonTrack> {
        self.tracks.iter().filter(move |t| t.scans >= min_scans)
    }
}

/// Tracker settings for a recorded scanner: field of view and maximum range from the first
/// scan's header (its bearing span and `range_max`, capped at `max_range`), the given beam
/// noise, the sensor mounted at `mount` on the robot.
pub fn config_for_scans(
    scans: &[Scan],
    sigma_range: f64,
    sigma_bearing: f64,
    max_range: f64,
    mount: [f64; 2],
) -> Result<PeopleTrackerConfig> {
    let first = scans
        .first()
        .ok_or_else(|| Error::invalid("recording", "holds no scan"))?;
    let a0 = first.angle_min;
    let a1 = first.angle_max();
    let half = 0.5 * (a1 - a0).abs() + 0.5 * first.angle_increment.abs();
    let range = if first.range_max.is_finite() {
        first.range_max.min(max_range)
    } else {
        max_range
    };
    Ok(PeopleTrackerConfig::for_scanner(
        sigma_range,
        sigma_bearing,
        range,
        half.min(std::f64::consts::PI),
        mount,
    ))
}

/// Runs a tracker built from `config` over `scans` in order, on every person-sized segment.
pub fn track_scans(scans: &[Scan], config: PeopleTrackerConfig) -> Result<PeopleRun> {
    track_scans_with(scans, config, FrontEnd::Segments)
}

/// Runs a tracker built from `config` over `scans` in order, measuring through `front_end`
/// (see the module documentation; the moving detector takes [`default_detector_config`]).
pub fn track_scans_with(
    scans: &[Scan],
    config: PeopleTrackerConfig,
    front_end: FrontEnd,
) -> Result<PeopleRun> {
    track_scans_with_model(scans, config, front_end, None)
}

/// [`track_scans_with`], the legs front end running `leg_model` instead of the shipped model
/// when one is given.
pub fn track_scans_with_model(
    scans: &[Scan],
    mut config: PeopleTrackerConfig,
    front_end: FrontEnd,
    leg_model: Option<LegModel>,
) -> Result<PeopleRun> {
    let min_visibility = config.min_visibility;
    let detector = match (front_end, scans.first()) {
        (FrontEnd::Moving, Some(first)) => {
            Some(default_detector_config(&config, first.angle_increment))
        }
        _ => None,
    };
    adapt_tracker_config(&mut config, front_end);
    let mut fe = PersonFrontEnd::new(front_end, &config, detector)?;
    if let Some(model) = leg_model {
        fe.set_leg_model(model)?;
    }
    let mut tracker = PeopleTracker::new(config)?;
    // The whole loop runs on one of rayon's threads: the filter's parallel steps are small
    // (a few tracks per scan), and entered from outside the pool each would hand its work
    // to the pool and wait for it, a thread wake-up per step.
    rayon::scope(|_| track_all(scans, &mut fe, &mut tracker, min_visibility))
}

fn track_all(
    scans: &[Scan],
    fe: &mut PersonFrontEnd,
    tracker: &mut PeopleTracker,
    min_visibility: f64,
) -> Result<PeopleRun> {
    let mut run = PeopleRun::default();
    for (i, scan) in scans.iter().enumerate() {
        let at = |e: Error| Error::invalid(format!("scan {i} (time {})", scan.time), e.to_string());
        let out = fe.measure(scan, scan.odometry).map_err(at)?;
        let detections = (0..out.measurements.len())
            .map(|j| {
                let z = out.measurements.get(j);
                [z[0] * z[1].cos(), z[0] * z[1].sin()]
            })
            .collect();
        let pose = out.corrected_pose.or(scan.odometry);
        tracker.observe(scan);
        let at_pose = pose.map(platform_isometry);
        let people = match out.weighed {
            Some(w) => tracker.step_measured_with_evidence(
                w.measurements,
                Some(&w.evidence),
                scan.time,
                at_pose,
            ),
            None => tracker.step_measured(out.measurements, scan.time, at_pose),
        }
        .map_err(at)?;
        run.scans.push(ScanPeople {
            scan: i,
            time: scan.time,
            pose: pose.map(|p: Pose2| [p.x, p.y, p.theta]),
            people,
            detections,
            pose_fallback: out.detections.as_ref().and_then(|d| d.fallback),
        });
    }
    run.tracks = summarise(&run.scans, min_visibility);
    Ok(run)
}

pub(crate) fn summarise(scans: &[ScanPeople], min_visibility: f64) -> Vec<PersonTrack> {
    struct Acc {
        n: usize,
        first: (f64, [f64; 2]),
        last: (f64, [f64; 2]),
        speed: f64,
        dynamic: usize,
    }
    let mut by_label: BTreeMap<Label, Acc> = BTreeMap::new();
    for s in scans {
        for p in s.people.iter().filter(|p| p.visibility >= min_visibility) {
            let speed = p.velocity[0].hypot(p.velocity[1]);
            let a = by_label.entry(p.label).or_insert(Acc {
                n: 0,
                first: (s.time, p.position),
                last: (s.time, p.position),
                speed: 0.0,
                dynamic: 0,
            });
            a.n += 1;
            a.last = (s.time, p.position);
            a.speed += speed;
            a.dynamic += p.moving as usize;
        }
    }
    by_label
        .into_iter()
        .map(|(label, a)| PersonTrack {
            label,
            scans: a.n,
            first_time: a.first.0,
            last_time: a.last.0,
            mean_speed: a.speed / a.n as f64,
            dynamic_fraction: a.dynamic as f64 / a.n as f64,
            displacement: (a.last.1[0] - a.first.1[0]).hypot(a.last.1[1] - a.first.1[1]),
        })
        .collect()
}

/// Writes `run` as pretty JSON, atomically.
pub fn write_people_json(path: &Path, run: &PeopleRun) -> Result<()> {
    let bytes = serde_json::to_vec_pretty(run)
        .map_err(|e| Error::invalid(format!("{}", path.display()), e.to_string()))?;
    crate::atomic::write_bytes(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_counts_visible_scans_only() {
        let person = |x: f64, vis: f64, moving: bool| PersonEstimate {
            label: Label::new(0, 0),
            existence: 0.9,
            position: [x, 0.0],
            velocity: [1.0, 0.0],
            p_moving: 0.9,
            moving,
            visibility: vis,
            age: 0,
        };
        let scans = vec![
            ScanPeople {
                scan: 0,
                time: 0.0,
                pose: None,
                people: vec![person(0.0, 0.9, false)],
                detections: Vec::new(),
                pose_fallback: None,
            },
            ScanPeople {
                scan: 1,
                time: 0.5,
                pose: None,
                people: vec![person(0.5, 0.1, true)],
                detections: Vec::new(),
                pose_fallback: None,
            },
            ScanPeople {
                scan: 2,
                time: 1.0,
                pose: None,
                people: vec![person(1.0, 0.8, true)],
                detections: Vec::new(),
                pose_fallback: None,
            },
        ];
        let t = summarise(&scans, 0.5);
        assert_eq!(t.len(), 1);
        assert_eq!(t[0].scans, 2);
        assert_eq!((t[0].first_time, t[0].last_time), (0.0, 1.0));
        assert!((t[0].displacement - 1.0).abs() < 1e-12);
        assert!((t[0].dynamic_fraction - 0.5).abs() < 1e-12);
        assert!((t[0].mean_speed - 1.0).abs() < 1e-12);
    }
}
