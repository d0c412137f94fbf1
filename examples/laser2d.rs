//! Walking people seen by a planar laser on a moving robot (seed 000's simulated scenarios),
//! tracked with the particle LMB: segment each scan, keep person-sized segments, filter with
//! constant velocity and range-bearing measurements from the robot's odometry pose.
//!
//! ```text
//! cargo run --release --example laser2d -- --scenario one --runs 10 --seed 1 [--json]
//! ```
//!
//! Reports mean OSPA and OSPA(2) (c = 2 m, p = 1; truth = the people the scanner actually sees,
//! at least 3 beams), label switches, the fraction of runs in which every person kept a single
//! label, and scans per second (segmentation + tracking).

use anyhow::{Context, Result};
use clap::Parser;
use smc_lmb::laser2d::{PeopleTracker, PeopleTrackerConfig};
use smc_lmb::metrics::{ospa, ospa2, tracks_from_frames, LabelConsistency};
use smc_lmb::sim::PeopleScenario;
use std::time::Instant;

#[derive(Parser, Debug)]
#[command(about = "People tracking with a planar laser: simulated scenarios")]
struct Args {
    /// `one` (five people crossing) or `two` (a lobby).
    #[arg(long, default_value = "one")]
    scenario: String,
    /// Monte-Carlo runs.
    #[arg(long, default_value_t = 1)]
    runs: usize,
    /// Seed of the first run (run i uses seed + i).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Robot pose handed to the tracker: `odometry` (noisy, drifting — what a robot has) or
    /// `truth` (the simulator's pose, to judge the tracker apart from localisation).
    #[arg(long, default_value = "odometry")]
    pose: String,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

const C: f64 = 2.0;

fn main() -> Result<()> {
    let args = Args::parse();
    let scenario = match args.scenario.as_str() {
        "one" => PeopleScenario::one(),
        "two" => PeopleScenario::two(),
        other => anyhow::bail!("unknown scenario `{other}` (expected one or two)"),
    };
    anyhow::ensure!(args.runs > 0, "--runs must be at least 1");
    let (mut ospa_all, mut ospa2_all, mut switches, mut kept, mut scans, mut seconds) =
        (vec![], vec![], 0, 0, 0, 0.0);
    for r in 0..args.runs {
        let seed = args.seed + r as u64;
        let run = scenario
            .generate(seed)
            .with_context(|| format!("scenario {} seed {seed}", args.scenario))?;
        let s = &scenario.scanner;
        let mut cfg = PeopleTrackerConfig::for_scanner(
            s.sigma_range,
            s.sigma_bearing,
            s.range_max,
            s.fov / 2.0,
            scenario.mount,
        );
        cfg.filter.seed = seed;
        let mut tracker = PeopleTracker::new(cfg)?;
        let mut labels = LabelConsistency::new(C)?;
        let mut truth_frames = Vec::new();
        let mut est_frames = Vec::new();
        let t0 = Instant::now();
        let mut all_est = Vec::new();
        for (k, scan) in run.scans.iter().enumerate() {
            let mut scan = scan.clone();
            match args.pose.as_str() {
                "odometry" => {}
                "truth" => scan.odometry = Some(run.robot_truth[k]),
                other => anyhow::bail!("--pose {other}: expected odometry or truth"),
            }
            all_est.push(tracker.step(&scan)?);
        }
        seconds += t0.elapsed().as_secs_f64();
        scans += run.scans.len();
        for (k, est) in all_est.iter().enumerate() {
            let seen = &run.visible[k];
            let truth: Vec<(u64, Vec<f64>)> = run.people_truth[k]
                .iter()
                .filter(|(id, _, _)| seen.contains(id))
                .map(|(id, p, _)| (*id, p.to_vec()))
                .collect();
            let x: Vec<_> = est
                .iter()
                .map(|e| (e.label, vec![e.state[0], e.state[2]]))
                .collect();
            let tp: Vec<&Vec<f64>> = truth.iter().map(|(_, p)| p).collect();
            let xp: Vec<&Vec<f64>> = x.iter().map(|(_, p)| p).collect();
            ospa_all.push(ospa(&tp, &xp, C, 1.0)?.distance);
            labels.add_step(&truth, &x)?;
            truth_frames.push(truth);
            est_frames.push(x);
        }
        let tt = tracks_from_frames(&truth_frames)?;
        let te = tracks_from_frames(&est_frames)?;
        ospa2_all.push(ospa2(&tt, &te, 0..run.scans.len(), C, 1.0, 1.0)?);
        let stats = labels.finish();
        switches += stats.switches;
        kept += stats.all_kept as usize;
        if !args.json {
            eprintln!(
                "run {r}: label switches {}, all labels kept {}",
                stats.switches, stats.all_kept
            );
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let lmb = serde_json::json!({
        "mean_ospa": mean(&ospa_all),
        "mean_ospa2": mean(&ospa2_all),
        "label_switches": switches,
        "all_labels_kept_fraction": kept as f64 / args.runs as f64,
        "scans_per_second": scans as f64 / seconds,
    });
    if args.json {
        println!(
            "{}",
            serde_json::json!({ "scenario": args.scenario, "runs": args.runs, "seed": args.seed, "pose": args.pose, "lmb": lmb })
        );
    } else {
        println!(
            "scenario {}, {} run(s), {} scans",
            args.scenario, args.runs, scans
        );
        println!("LMB: mean OSPA {:.3} m, OSPA(2) {:.3} m (c = {C} m, p = 1), label switches {}, all labels kept in {:.0} % of runs, {:.0} scans/s",
            mean(&ospa_all), mean(&ospa2_all), switches, 100.0 * kept as f64 / args.runs as f64, scans as f64 / seconds);
    }
    Ok(())
}
