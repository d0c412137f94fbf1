//! People in real CARMEN logs read without their odometry: the moving front end then takes
//! its poses from scan matching alone (a constant-velocity guess corrected by ICP against its
//! local map), and must report the same people as with the robot's odometry. Needs the Intel
//! and fr079 logs of `../shared/data/laser2d/` (a failure under `CI=true` when absent).

mod common;

use common::shared_laser2d;
use smc_lmb::laser2d::{read_carmen, CarmenOptions, Scan, TimeOrder};
use smc_lmb::pipeline::people_tracking::front_end::FrontEnd;
use smc_lmb::pipeline::people_tracking::{config_for_scans, track_scans_with};

fn scans(name: &str, ignore_odometry: bool) -> Option<Vec<Scan>> {
    let path = shared_laser2d(name)?;
    let options = CarmenOptions {
        time_order: TimeOrder::DropFewest,
        ignore_odometry,
        ..CarmenOptions::default()
    };
    Some(read_carmen(&path, options).unwrap().flaser)
}

/// People reported in each scan (those the tracker shows: visibility above its threshold).
fn people_per_scan(scans: &[Scan]) -> Vec<usize> {
    let mut cfg = config_for_scans(scans, 0.03, 0.005, 15.0, [0.0, 0.0]).unwrap();
    cfg.filter.seed = 1;
    let min_visibility = cfg.min_visibility;
    let run = track_scans_with(scans, cfg, FrontEnd::Moving).unwrap();
    run.scans
        .iter()
        .map(|s| {
            s.people
                .iter()
                .filter(|p| p.visibility >= min_visibility)
                .count()
        })
        .collect()
}

fn same_people_without_odometry(name: &str) {
    let (Some(with), Some(without)) = (scans(name, false), scans(name, true)) else {
        return;
    };
    assert!(with.iter().all(|s| s.odometry.is_some()));
    assert!(without.iter().all(|s| s.odometry.is_none()));
    assert_eq!(with.len(), without.len());
    let (a, b) = (people_per_scan(&with), people_per_scan(&without));
    let n = a.len() as f64;
    let differing = a.iter().zip(&b).filter(|(x, y)| x != y).count() as f64 / n;
    let extra = (b.iter().sum::<usize>() as f64 - a.iter().sum::<usize>() as f64) / n;
    eprintln!(
        "{name}: {} scans, people per scan {:.3} with odometry, {:.3} without; \
         {:.1} % of scans differ, {extra:.3} extra per scan",
        a.len(),
        a.iter().sum::<usize>() as f64 / n,
        b.iter().sum::<usize>() as f64 / n,
        100.0 * differing
    );
    assert!(differing <= 0.10, "{name}: {differing} of scans differ");
    assert!(extra <= 0.3, "{name}: {extra} extra people per scan");
}

#[test]
fn intel_people_without_odometry_match_those_with_it() {
    same_people_without_odometry("intel.clf.bz2");
}

#[test]
fn fr079_people_without_odometry_match_those_with_it() {
    same_people_without_odometry("fr079.clf.bz2");
}
