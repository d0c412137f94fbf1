//! The seeds' own trackers ([`crate::trackers`]: GNN, ML-RANSAC, JPDA-IMM) on a recording,
//! fed the very people the front end handed the LMB people tracker (a [`PeopleRun`]'s
//! detections, with its poses), so that all of them are scored the same way, side by side.
//!
//! Not for: simulated runs (see [`super::evaluate`], which feeds every tracker from the
//! front end itself), or choosing a tracker's settings.

use super::run::PeopleRun;
use crate::error::{Error, Result};
use crate::filter::{Label, Measurements};
use crate::geometry::pose2::{inverse, transform_point};
use crate::geometry::Pose2;
use crate::laser2d::Scan;
use crate::trackers::{BeamRanges, PointTracker, StepClock};

/// One scan's confirmed tracks of a tracker: label and position in the sensor frame of the
/// scan (m), as the LMB's estimates are scored.
pub type SensorFrameTracks = Vec<(Label, [f64; 2])>;

/// Runs `tracker` over the scans of `run` (`scans` are the scans `run` was made from): at
/// each scan it sees the scan's beams and gets the front end's people as range-bearing
/// measurements, with the run's pose of the scan. Returns, per scan of `run`, the tracker's
/// confirmed tracks in the sensor frame. Fails when `run` names a scan `scans` does not hold,
/// or when the tracker fails (with the scan's index and time).
pub fn track_front_end_people(
    run: &PeopleRun,
    scans: &[Scan],
    tracker: &mut dyn PointTracker,
) -> Result<Vec<SensorFrameTracks>> {
    let mut clock = StepClock::new();
    let mut beams = Vec::new();
    let mut out = Vec::with_capacity(run.scans.len());
    for s in &run.scans {
        let at =
            |e: Error| Error::invalid(format!("scan {} (time {})", s.scan, s.time), e.to_string());
        let scan = scans.get(s.scan).ok_or_else(|| {
            Error::invalid(
                "people run",
                format!("scan {} of {} recorded", s.scan, scans.len()),
            )
        })?;
        let rows: Vec<[f64; 2]> = s
            .detections
            .iter()
            .map(|p| [p[0].hypot(p[1]), p[1].atan2(p[0])])
            .collect();
        let z = Measurements::from_rows(2, &rows).map_err(at)?;
        let pose = s.pose.map(|[x, y, theta]| Pose2::new(x, y, theta));
        let ctx = clock.tick(s.time, pose).map_err(at)?;
        scan.ranges_into(&mut beams);
        tracker.observe_beams(BeamRanges {
            angle_min: scan.angle_min,
            angle_increment: scan.angle_increment,
            ranges: &beams,
        });
        let est = tracker.step(&z, &ctx).map_err(at)?;
        let to_sensor = pose.map(inverse);
        out.push(
            est.iter()
                .map(|e| {
                    let world = [e.state[0], e.state[2]];
                    (
                        e.label,
                        to_sensor.map_or(world, |t| transform_point(t, world)),
                    )
                })
                .collect(),
        );
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::RangeBearing;
    use crate::pipeline::people_tracking::run::ScanPeople;
    use crate::trackers::{GnnConfig, GnnTracker};

    /// A scanner driving along +x at 0.5 m/s, a person standing at (3, 1) in the world: the
    /// front end's people of each scan in the sensor frame.
    fn still_person_seen_from_a_moving_scanner() -> (PeopleRun, Vec<Scan>) {
        let mut run = PeopleRun::default();
        let mut scans = Vec::new();
        for k in 0..30 {
            let t = 0.1 * k as f64;
            let x = 0.5 * t;
            scans.push(Scan::new(t, -1.5, 0.01, vec![10.0; 301], 0.0, 30.0).unwrap());
            run.scans.push(ScanPeople {
                scan: k,
                time: t,
                pose: Some([x, 0.0, 0.0]),
                people: Vec::new(),
                detections: vec![[3.0 - x, 1.0]],
                pose_fallback: None,
            });
        }
        (run, scans)
    }

    #[test]
    fn a_baseline_tracks_the_front_end_people_in_the_sensor_frame() {
        let (run, scans) = still_person_seen_from_a_moving_scanner();
        let sensor = RangeBearing::new(0.05, 0.005).unwrap();
        let mut gnn = GnnTracker::new(GnnConfig::new(sensor)).unwrap();
        let out = track_front_end_people(&run, &scans, &mut gnn).unwrap();
        assert_eq!(out.len(), run.scans.len());
        // Confirmed after a few scans, then one track where the person is, scan after scan.
        let last = out.last().unwrap();
        assert_eq!(last.len(), 1, "{last:?}");
        let x = 0.5 * 2.9;
        let p = last[0].1;
        assert!(
            (p[0] - (3.0 - x)).abs() < 0.1 && (p[1] - 1.0).abs() < 0.1,
            "{p:?}"
        );
        let labels: std::collections::HashSet<_> = out.iter().flatten().map(|(l, _)| *l).collect();
        assert_eq!(labels.len(), 1);
    }

    #[test]
    fn a_run_naming_a_scan_not_recorded_is_refused() {
        let (mut run, scans) = still_person_seen_from_a_moving_scanner();
        run.scans[3].scan = 99;
        let sensor = RangeBearing::new(0.05, 0.005).unwrap();
        let mut gnn = GnnTracker::new(GnnConfig::new(sensor)).unwrap();
        let e = track_front_end_people(&run, &scans, &mut gnn).unwrap_err();
        assert!(e.to_string().contains("scan 99"), "{e}");
    }
}
