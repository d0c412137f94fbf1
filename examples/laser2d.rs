//! Walking people seen by a planar laser on a moving robot (seed 000's simulated scenarios),
//! tracked by the particle LMB and by the seeds' own trackers on the same measurements: GNN
//! with EKFs, ML-RANSAC (seed 000, Algorithm 2) and JPDA with an IMM (seed 003, Sec. V).
//!
//! ```text
//! cargo run --release --example laser2d -- --scenario one --runs 10 --seed 1 [--json]
//!     [--trackers lmb,gnn,ml_ransac,jpda_imm] [--pose odometry|truth]
//! ```
//!
//! Reports per tracker mean OSPA and OSPA(2) (c = 2 m, p = 1; truth = the people the scanner
//! actually sees, at least 3 beams), label switches, the fraction of runs in which every person
//! kept a single label, scans per second (segmentation + tracking), and for the Gaussian
//! trackers the RMS prediction error and the time-averaged NIS with its 95 % interval.
//! `--json` prints one object with a member per tracker.

use anyhow::{Context, Result};
use clap::Parser;
use smc_lmb::laser2d::evaluate::{
    evaluate_run, summarise, EvalConfig, PoseSource, RunMetrics, Summary,
};
use smc_lmb::laser2d::PeopleTrackerConfig;
use smc_lmb::models::RangeBearing;
use smc_lmb::rng::seeded;
use smc_lmb::sim::PeopleScenario;
use smc_lmb::trackers::{
    GnnConfig, GnnTracker, JpdaImmConfig, JpdaImmTracker, LmbTracker, MlRansacConfig,
    MlRansacTracker, PointTracker,
};

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
    /// Robot pose handed to the trackers: `odometry` (noisy, drifting — what a robot has) or
    /// `truth` (the simulator's pose, to judge the trackers apart from localisation).
    #[arg(long, default_value = "odometry")]
    pose: String,
    /// Comma-separated trackers to run.
    #[arg(long, default_value = "lmb,gnn,ml_ransac,jpda_imm")]
    trackers: String,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

fn main() -> Result<()> {
    let args = Args::parse();
    run_simulated(&args)
}

/// The simulated scenarios: every tracker on the same runs, pooled per tracker.
fn run_simulated(args: &Args) -> Result<()> {
    let scenario = match args.scenario.as_str() {
        "one" => PeopleScenario::one(),
        "two" => PeopleScenario::two(),
        other => anyhow::bail!("unknown scenario `{other}` (expected one or two)"),
    };
    anyhow::ensure!(args.runs > 0, "--runs must be at least 1");
    let eval = EvalConfig {
        pose: match args.pose.as_str() {
            "odometry" => PoseSource::Odometry,
            "truth" => PoseSource::Truth,
            other => anyhow::bail!("--pose {other}: expected odometry or truth"),
        },
        ..EvalConfig::default()
    };
    let names: Vec<&str> = args.trackers.split(',').map(str::trim).collect();
    let detector = detector_config(&scenario, 0);
    let mut per_tracker: Vec<Vec<RunMetrics>> = vec![Vec::new(); names.len()];
    for r in 0..args.runs {
        let seed = args.seed + r as u64;
        let run = scenario
            .generate(seed)
            .with_context(|| format!("scenario {} seed {seed}", args.scenario))?;
        for (name, results) in names.iter().zip(per_tracker.iter_mut()) {
            let mut tracker = build_tracker(name, &scenario, seed)?;
            let m = evaluate_run(tracker.as_mut(), &run, &detector, &eval)
                .with_context(|| format!("{name} on seed {seed}"))?;
            if !args.json {
                eprintln!(
                    "run {r} {name}: OSPA {:.3}, OSPA(2) {:.3}, label switches {}, all labels kept {}",
                    m.mean_ospa, m.ospa2, m.label_switches, m.all_labels_kept
                );
            }
            results.push(m);
        }
    }
    let summaries: Vec<Summary> = per_tracker
        .iter()
        .map(|r| summarise(r))
        .collect::<smc_lmb::Result<_>>()?;
    if args.json {
        print_json(args, &names, &summaries)
    } else {
        print_table(args, &names, &summaries);
        Ok(())
    }
}

/// Segmentation (and, for the LMB, filter) settings for the scenario's scanner.
fn detector_config(scenario: &PeopleScenario, seed: u64) -> PeopleTrackerConfig {
    let s = &scenario.scanner;
    let mut cfg = PeopleTrackerConfig::for_scanner(
        s.sigma_range,
        s.sigma_bearing,
        s.range_max,
        s.fov / 2.0,
        scenario.mount,
    );
    cfg.filter.seed = seed;
    cfg
}

/// The range-bearing sensor every baseline assumes: the scanner's noise (floored as the LMB
/// floors it) and its mounting offset.
fn sensor_model(scenario: &PeopleScenario) -> Result<RangeBearing> {
    let s = &scenario.scanner;
    Ok(
        RangeBearing::new(s.sigma_range.max(0.05), s.sigma_bearing.max(0.005))?
            .with_offset(scenario.mount[0], scenario.mount[1])?,
    )
}

fn build_tracker(
    name: &str,
    scenario: &PeopleScenario,
    seed: u64,
) -> Result<Box<dyn PointTracker>> {
    let sensor = sensor_model(scenario)?;
    Ok(match name {
        "lmb" => {
            let cfg = detector_config(scenario, seed);
            Box::new(LmbTracker::new(cfg.filter.build()?, seeded(seed)))
        }
        "gnn" => Box::new(GnnTracker::new(GnnConfig::new(sensor))?),
        "ml_ransac" => {
            let mut cfg = MlRansacConfig::new(sensor);
            cfg.seed = seed;
            Box::new(MlRansacTracker::new(cfg)?)
        }
        "jpda_imm" => {
            let mut cfg = JpdaImmConfig::new(sensor);
            let s = &scenario.scanner;
            cfg.clutter_density = 1.0 / (s.fov * s.range_max);
            Box::new(JpdaImmTracker::new(cfg)?)
        }
        other => {
            anyhow::bail!("unknown tracker `{other}` (expected lmb, gnn, ml_ransac, jpda_imm)")
        }
    })
}

fn print_json(args: &Args, names: &[&str], summaries: &[Summary]) -> Result<()> {
    let mut out = serde_json::json!({
        "scenario": args.scenario, "runs": args.runs, "seed": args.seed, "pose": args.pose,
    });
    for (name, s) in names.iter().zip(summaries) {
        out[*name] = serde_json::to_value(s)?;
    }
    println!("{out}");
    Ok(())
}

fn print_table(args: &Args, names: &[&str], summaries: &[Summary]) {
    let scans = |s: &Summary| s.runs;
    println!(
        "scenario {}, {} run(s) from seed {}, pose {}; OSPA and OSPA(2) with c = 2 m, p = 1",
        args.scenario,
        summaries.first().map_or(0, scans),
        args.seed,
        args.pose
    );
    println!(
        "{:<10} {:>8} {:>8} {:>9} {:>10} {:>9} {:>8} {:>22}",
        "tracker",
        "OSPA",
        "OSPA(2)",
        "switches",
        "all kept",
        "scans/s",
        "RMS",
        "NIS [95 % interval]"
    );
    for (name, s) in names.iter().zip(summaries) {
        let rms = s
            .rms_prediction_error
            .map_or("–".to_string(), |v| format!("{v:.3}"));
        let nis = s.nis.map_or("–".to_string(), |n| {
            format!("{:.2} [{:.2}, {:.2}]", n.mean, n.lower, n.upper)
        });
        println!(
            "{:<10} {:>8.3} {:>8.3} {:>9} {:>9.0}% {:>9.0} {:>8} {:>22}",
            name,
            s.mean_ospa,
            s.mean_ospa2,
            s.label_switches,
            100.0 * s.all_labels_kept_fraction,
            s.scans_per_second,
            rms,
            nis
        );
    }
}
