//! Several lasers' recordings run through [`LasersTracker`]: the lasers' scans read from a ROS
//! bag at their mountings and tracked frame by frame.
//!
//! Not for: the tracker itself (the parent module) or the mountings file (`mountings`).

use super::*;

/// One laser's recording for [`track_lasers`]: its mount and its scans (its own frame, its
/// own times, with the robot's odometry when there is one).
#[derive(Clone, Debug)]
pub struct LaserRecording {
    /// The laser.
    pub mount: LaserMount,
    /// Its scans, in time order.
    pub scans: Vec<Scan>,
}

/// Runs a [`LasersTracker`] over the recordings of several lasers of one robot: every scan
/// through its own laser's front end `front_end`, grouped into frames by [`group_scans`].
/// The robot's pose of a frame is the pose the anchor laser's front end corrects, when it
/// does (its moving-object detector's ICP, or without odometry the legs detector's
/// scan-to-scan alignments; moved back from the laser to the robot by its mounting), else the
/// anchor scan's odometry; each other laser's scan gets the robot's pose at its own time (the
/// anchor's pose moved on by the odometry's motion between the two scans, or without odometry
/// at the robot's last velocity) composed with its mounting. `config` gives the people
/// models and tuning (adapted to the front end here); the result has one [`ScanPeople`] per
/// frame (`scan` = the anchor scan's index, `detections` = the anchor laser's people in its
/// own frame).
pub fn track_lasers(
    recordings: &[LaserRecording],
    mut config: PeopleTrackerConfig,
    front_end: FrontEnd,
    fusion: Fusion,
) -> Result<PeopleRun> {
    adapt_tracker_config(&mut config, front_end);
    let min_visibility = config.min_visibility;
    let mut front_ends = recordings
        .iter()
        .map(|r| {
            let detector = match (front_end, r.scans.first()) {
                (FrontEnd::Moving, Some(first)) => {
                    Some(super::super::front_end::default_detector_config(
                        &laser_config(&config),
                        first.angle_increment,
                    ))
                }
                _ => None,
            };
            PersonFrontEnd::new(front_end, &laser_config(&config), detector)
        })
        .collect::<Result<Vec<_>>>()?;
    let mounts = recordings.iter().map(|r| r.mount.clone()).collect();
    let mut tracker = LasersTracker::new(config, mounts, fusion)?;
    let times: Vec<Vec<f64>> = recordings
        .iter()
        .map(|r| r.scans.iter().map(|s| s.time).collect())
        .collect();
    let (anchor, frames) = group_scans(&times)?;
    rayon::scope(|_| {
        let mut run = PeopleRun::default();
        let mut previous: Option<(Pose2, f64)> = None;
        for frame in &frames {
            let at = |e: Error| {
                Error::invalid(
                    format!("frame {} (time {})", frame.anchor, frame.time),
                    e.to_string(),
                )
            };
            // the anchor first: it gives the robot's pose
            let mut order = frame.scans.clone();
            order.sort_by_key(|&(j, _)| j != anchor);
            let mut inputs = Vec::with_capacity(order.len());
            let mut robot = None;
            let mut anchor_odometry = None;
            let mut detections = Vec::new();
            for (j, k) in order {
                let rec = &recordings[j];
                let scan = &rec.scans[k];
                let mount = rec.mount.mounting;
                let laser_odometry = scan.odometry.map(|o| compose(o, mount));
                let out = front_ends[j].measure(scan, laser_odometry).map_err(at)?;
                let laser_pose = if j == anchor {
                    let laser = out.corrected_pose.or(laser_odometry).unwrap_or(mount);
                    robot = Some(compose(laser, inverse(mount)));
                    anchor_odometry = scan.odometry;
                    detections = (0..out.measurements.len())
                        .map(|i| {
                            let z = out.measurements.get(i);
                            [z[0] * z[1].cos(), z[0] * z[1].sin()]
                        })
                        .collect();
                    laser
                } else {
                    let r = robot.expect("the anchor comes first");
                    match (anchor_odometry, scan.odometry) {
                        // the odometry's motion since the anchor scan, from the anchor's pose
                        (Some(a), Some(o)) => compose(compose(r, between(a, o)), mount),
                        _ => compose(extrapolate(r, frame.time, previous, scan.time), mount),
                    }
                };
                let (measurements, evidence) = match out.weighed {
                    Some(w) => (w.measurements, Some(w.evidence)),
                    None => (out.measurements, None),
                };
                let mut view = BeamView::EMPTY;
                view.reset(scan.angle_min, scan.angle_increment, scan.beam_ranges());
                inputs.push(LaserInput {
                    laser: j,
                    measurements,
                    evidence,
                    view,
                    pose: laser_pose,
                });
            }
            let robot = robot.expect("every frame has its anchor scan");
            let people = tracker.step(inputs, frame.time, Some(robot)).map_err(at)?;
            previous = Some((robot, frame.time));
            run.scans.push(ScanPeople {
                scan: frame.anchor,
                time: frame.time,
                pose: Some([robot.x, robot.y, robot.theta]),
                people,
                detections,
                pose_fallback: None,
            });
        }
        run.tracks = super::super::run::summarise(&run.scans, min_visibility);
        Ok(run)
    })
}

/// `config` for one laser's front end: the laser at the robot's origin (its measurements and
/// the pose it is handed are its own).
fn laser_config(config: &PeopleTrackerConfig) -> PeopleTrackerConfig {
    let mut c = config.clone();
    if let Some(MeasurementConfig::RangeBearing { offset, .. }) = &mut c.filter.measurement {
        *offset = [0.0, 0.0];
    }
    if let Some(DetectionConfig::FieldOfView { offset, .. }) = &mut c.filter.detection {
        *offset = [0.0, 0.0];
    }
    c
}

/// The recordings of the lasers `topics` of the ROS bag at `bag`, each at its mounting in
/// the mountings file `mountings_path` ([`read_mountings`]; the first topic is usually the
/// reference laser, at the origin), people seen up to `max_range`. Errors name the file and
/// the problem: a topic that is not a `sensor_msgs/LaserScan` topic of the bag, a mountings
/// table naming no laser of the bag, a topic without a table, a laser without scans.
pub fn read_bag_lasers(
    bag: &std::path::Path,
    topics: &[String],
    mountings_path: &std::path::Path,
    max_range: f64,
) -> Result<Vec<LaserRecording>> {
    use crate::laser2d::rosbag::{bag_topics, read_bag, BagOptions};
    if topics.is_empty() {
        return Err(Error::invalid("laser topics", "none given"));
    }
    let mountings = read_mountings(mountings_path)?;
    let lasers: Vec<String> = bag_topics(bag)?
        .into_iter()
        .filter(|t| t.message_type == "sensor_msgs/LaserScan")
        .map(|t| t.topic)
        .collect();
    for t in topics {
        if !lasers.contains(t) {
            return Err(Error::invalid(
                format!("topic {t}"),
                format!(
                    "not a sensor_msgs/LaserScan topic of {} (it has {})",
                    bag.display(),
                    lasers.join(", ")
                ),
            ));
        }
    }
    for m in &mountings {
        if !lasers.iter().any(|t| t.trim_start_matches('/') == m.name) {
            return Err(Error::parse(
                mountings_path,
                m.line,
                "name",
                format!(
                    "{:?} is not a laser of {} (its LaserScan topics: {})",
                    m.name,
                    bag.display(),
                    lasers.join(", ")
                ),
            ));
        }
    }
    let poses = mountings_for_topics(&mountings, topics, mountings_path)?;
    topics
        .iter()
        .zip(poses)
        .map(|(t, mounting)| {
            let scans = read_bag(bag, &BagOptions::topic(t.clone()))?.scans;
            let first = scans.first().ok_or_else(|| {
                Error::invalid(format!("topic {t} of {}", bag.display()), "holds no scan")
            })?;
            Ok(LaserRecording {
                mount: LaserMount::for_scan(t.trim_start_matches('/'), mounting, first, max_range),
                scans,
            })
        })
        .collect()
}
