//! Mounting poses of several lasers on one robot, estimated by registering their overlapping
//! views of a static scene (`smc_lmb::laser2d::mounting`), printed as the `[[sensors]]`
//! tables of a multi-sensor configuration.
//!
//! ```text
//! cargo run --release --example laser_mounting -- --bag ../shared/data/laser2d/leg_annotated/negative_2.bag \
//!     [--reference /left_scan] [--sensors /right_scan,/rear_scan] [--no-motion-compensation] [--report]
//! ```
//!
//! Without `--sensors` every other `sensor_msgs/LaserScan` topic of the bag is estimated.
//! Standard output is TOML: one `[[sensors]]` table per laser (the reference first, at the
//! origin) with `name` and `mounting = [x, y, heading]` (m, m, rad, in the reference laser's
//! frame). `--report` adds, as TOML comments, the pairs used, the spread over pairs and time
//! windows, the residual alignment error of the overlapping points and, with two or more
//! sensors, the loop check: the pose of the second sensor seen from the first, composed from
//! the two estimates, against its direct estimate.

use anyhow::{bail, Context, Result};
use clap::Parser;
use smc_lmb::geometry::pose2::{between, compose, inverse};
use smc_lmb::geometry::wrap_angle;
use smc_lmb::laser2d::mounting::{estimate_mounting, MountingConfig, MountingEstimate};
use smc_lmb::laser2d::rosbag::{bag_topics, read_bag, BagOptions, OdometryTopic};
use smc_lmb::laser2d::{Pose2, Scan};

#[derive(Parser, Debug)]
#[command(about = "Estimate the mounting poses of several lasers from a ROS 1 bag")]
struct Args {
    /// The ROS 1 bag.
    #[arg(long)]
    bag: std::path::PathBuf,
    /// The reference laser's topic (default: the first LaserScan topic in name order).
    #[arg(long)]
    reference: Option<String>,
    /// The other lasers' topics, comma separated (default: every other LaserScan topic).
    #[arg(long, value_delimiter = ',')]
    sensors: Vec<String>,
    /// Register each sensor scan against the nearest reference scan (within 0.02 s) instead
    /// of interpolating the robot's motion between the bracketing reference scans.
    #[arg(long)]
    no_motion_compensation: bool,
    /// Use every n'th sensor scan.
    #[arg(long, default_value_t = 1)]
    stride: usize,
    /// Add the quality figures as TOML comments.
    #[arg(long)]
    report: bool,
}

fn read(bag: &std::path::Path, topic: &str) -> Result<Vec<Scan>> {
    let scans = read_bag(
        bag,
        &BagOptions {
            scan_topic: Some(topic.to_string()),
            odometry: OdometryTopic::Ignore,
        },
    )
    .with_context(|| format!("reading {topic}"))?
    .scans;
    Ok(scans)
}

fn name_of(topic: &str) -> &str {
    topic.trim_start_matches('/')
}

fn report(e: &MountingEstimate) {
    let s = &e.spread;
    let r = &e.residuals;
    let m = e.mounting;
    println!(
        "# coarse guess [{:.3}, {:.3}, {:.4}] agreed by {} of {} coarse pairs",
        e.coarse_guess.x, e.coarse_guess.y, e.coarse_guess.theta, e.coarse_votes, e.coarse_tried
    );
    println!("# pairs kept {} of {}", e.pairs_kept, e.pairs_tried);
    println!(
        "# spread over pairs: robust std x {:.4} m, y {:.4} m, heading {:.5} rad ({:.3}°)",
        s.robust_std[0],
        s.robust_std[1],
        s.robust_std[2],
        s.robust_std[2].to_degrees()
    );
    println!(
        "# 5–95 %: x [{:.3}, {:.3}] m, y [{:.3}, {:.3}] m, heading [{:+.4}, {:+.4}] rad about the estimate",
        s.p05[0], s.p95[0], s.p05[1], s.p95[1], s.p05[2], s.p95[2]
    );
    let windows: Vec<String> = e
        .window_mountings
        .iter()
        .map(|w| format!("[{:.3}, {:.3}, {:.4}]", w.x, w.y, w.theta))
        .collect();
    println!(
        "# time windows: {} (largest deviation {:.4} m, {:.5} rad)",
        windows.join(" "),
        s.window_max_deviation[0],
        s.window_max_deviation[1]
    );
    println!(
        "# residuals of the overlap (points within the gate): point distance RMS median {:.4} m (p90 {:.4}), median distance {:.4} m, point-to-line RMS median {:.4} m, overlap share {:.2}",
        r.rms_median, r.rms_p90, r.median_distance, r.line_rms_median, r.overlap_share
    );
    let mut speeds: Vec<f64> = e
        .fits
        .iter()
        .filter(|f| f.kept && f.pair.next_reference.is_some())
        .map(|f| {
            let dt = 1.0 / 7.5;
            f.reference_motion.x.hypot(f.reference_motion.y) / dt
        })
        .collect();
    if !speeds.is_empty() {
        speeds.sort_by(f64::total_cmp);
        println!(
            "# reference laser speed (approx., 7.5 Hz assumed): median {:.2} m/s, max {:.2} m/s",
            speeds[speeds.len() / 2],
            speeds[speeds.len() - 1]
        );
    }
    println!(
        "# heading {:.4} rad = {:.2}°, distance from the reference {:.3} m",
        m.theta,
        m.theta.to_degrees(),
        m.x.hypot(m.y)
    );
}

fn main() -> Result<()> {
    let args = Args::parse();
    let topics: Vec<String> = bag_topics(&args.bag)
        .with_context(|| format!("listing {}", args.bag.display()))?
        .into_iter()
        .filter(|t| t.message_type == "sensor_msgs/LaserScan")
        .map(|t| t.topic)
        .collect();
    let reference = match &args.reference {
        Some(r) => r.clone(),
        None => topics
            .first()
            .cloned()
            .context("the bag has no sensor_msgs/LaserScan topic")?,
    };
    let sensors: Vec<String> = if args.sensors.is_empty() {
        topics
            .iter()
            .filter(|t| **t != reference)
            .cloned()
            .collect()
    } else {
        args.sensors.clone()
    };
    if sensors.is_empty() {
        bail!("no sensor topic besides the reference {reference}");
    }
    let config = MountingConfig {
        motion_compensation: !args.no_motion_compensation,
        pair_stride: args.stride,
        ..MountingConfig::default()
    };
    let ref_scans = read(&args.bag, &reference)?;
    let mut scans = Vec::with_capacity(sensors.len());
    let mut estimates = Vec::with_capacity(sensors.len());
    for topic in &sensors {
        let s = read(&args.bag, topic)?;
        let e = estimate_mounting(&ref_scans, &s, &config)
            .with_context(|| format!("estimating the mounting of {topic}"))?;
        scans.push(s);
        estimates.push(e);
    }
    println!(
        "# mounting poses relative to {reference}, estimated from {}",
        args.bag.display()
    );
    println!(
        "[[sensors]]\nname = \"{}\"\nmounting = [0.0, 0.0, 0.0]\n",
        name_of(&reference)
    );
    for (topic, e) in sensors.iter().zip(&estimates) {
        let m = e.mounting;
        println!("[[sensors]]\nname = \"{}\"", name_of(topic));
        println!("mounting = [{:.4}, {:.4}, {:.4}]", m.x, m.y, m.theta);
        if args.report {
            report(e);
        }
        println!();
    }
    if args.report && sensors.len() >= 2 {
        // Loop check: sensor 1 seen from sensor 0, composed vs direct.
        let composed = between(estimates[0].mounting, estimates[1].mounting);
        let direct = estimate_mounting(&scans[0], &scans[1], &config)
            .with_context(|| format!("estimating {} from {}", sensors[1], sensors[0]))?;
        let d: Pose2 = compose(inverse(direct.mounting), composed);
        println!(
            "# loop check: {} in the frame of {}: composed [{:.4}, {:.4}, {:.4}], direct [{:.4}, {:.4}, {:.4}] ({} pairs kept); gap {:.4} m, {:.5} rad",
            sensors[1],
            sensors[0],
            composed.x,
            composed.y,
            composed.theta,
            direct.mounting.x,
            direct.mounting.y,
            direct.mounting.theta,
            direct.pairs_kept,
            d.x.hypot(d.y),
            wrap_angle(d.theta).abs()
        );
    }
    Ok(())
}
