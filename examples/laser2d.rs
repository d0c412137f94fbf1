//! Walking people seen by a planar laser on a moving robot (seed 000's simulated scenarios),
//! tracked by the particle LMB and by the seeds' own trackers on the same measurements: GNN
//! with EKFs, ML-RANSAC (seed 000, Algorithm 2) and JPDA with an IMM (seed 003, Sec. V).
//!
//! ```text
//! cargo run --release --example laser2d -- --scenario one --runs 10 --seed 1 [--json]
//!     [--trackers lmb,gnn,ml_ransac,jpda_imm] [--pose odometry|truth|icp] [--frame robot|world]
//!     [--front-end segments|moving|legs]
//! cargo run --release --example laser2d -- --carmen intel.clf.bz2 [--scans 2000..2600] --out people.json --plot tracks.svg
//! cargo run --release --example laser2d -- --bag demo.bag --topic /scan --out people.json --plot tracks.png
//! ```
//!
//! Reports per tracker mean OSPA and OSPA(2) (c = 2 m, p = 1; truth = the people the scanner
//! actually sees, at least 3 beams), label switches, the fraction of runs in which every person
//! kept a single label, scans per second (segmentation + tracking), and for the Gaussian
//! trackers the RMS prediction error and the time-averaged NIS with its 95 % interval.
//! `--json` prints one object with a member per tracker.
//!
//! Front end (`--front-end`): `segments` hands the trackers every person-sized group of
//! returns, `moving` only those the moving-object detector marks as moving. Without the flag
//! it is chosen by scenario, and printed: `segments` for scenario one (no static structure to
//! remove), `moving` for scenario two (the lobby's walls, pillars and desk) and for
//! recordings. `--pose icp` hands the trackers the detector's ICP-corrected pose.
//!
//! With `--carmen` or `--bag` a recording is tracked end to end instead by the LMB: per-scan
//! people as JSON (`--out`), a plot of the tracks over the scan points (`--plot`, `.svg` or
//! `.png`), and a summary of the tracks on standard output. `--truth-topic` scores a bag
//! against its leg annotations, `--empty` a recording without people; a scored recording also
//! runs the baselines of `--trackers` on the people the front end handed the LMB
//! (`pipeline::people_tracking::baselines`) and scores them the same way:
//!
//! ```text
//! cargo run --release --example laser2d -- --bag positive_1_extracted.bag --topic /training_scan \
//!     --truth-topic /leg_cluster_positions
//! cargo run --release --example laser2d -- --bag negative_2.bag --topic /right_scan --empty
//! ```
//!
//! Several lasers (`pipeline::people_tracking::lasers`, `docs/results/people_lasers.md`):
//! `--topics` of one bag at their `--mountings` (the `[[sensors]]` tables of
//! `examples/laser_mounting.rs`) fused by `--fusion ic|pu|ga|aa`, and `--lasers`, the
//! simulated robot with three lasers, each alone against the rules of `--fusion` fused:
//!
//! ```text
//! cargo run --release --example laser2d -- --bag negative_2.bag --topics /left_scan,/right_scan,/rear_scan \
//!     --mountings negative_2_mountings.toml --front-end legs --fusion pu --empty
//! cargo run --release --example laser2d -- --lasers --scenario one --runs 8 --fusion ic,pu,ga,aa
//! ```

use anyhow::{Context, Result};
use clap::Parser;
use smc_lmb::laser2d::moving::{MovingDetectorConfig, MovingRule};
use smc_lmb::models::RangeBearing;
use smc_lmb::pipeline::people_tracking::evaluate::{
    evaluate_run_with, summarise, EvalConfig, PoseSource, RunMetrics, ScoreFrame, Summary,
};
use smc_lmb::pipeline::people_tracking::front_end::{
    adapt_tracker_config, default_detector_config, FrontEnd, MovingEvidence, PersonFrontEnd,
    MOVING_CLUTTER_RATE, MOVING_DETECTION_PROBABILITY,
};
use smc_lmb::pipeline::people_tracking::{centre_noise, PeopleTracker, PeopleTrackerConfig};
use smc_lmb::sim::PeopleScenario;
use smc_lmb::trackers::{
    GnnConfig, GnnTracker, JpdaImmConfig, JpdaImmTracker, MlRansacConfig, MlRansacTracker,
    PointTracker,
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
    /// Scoring frame: `robot` (truth relative to the robot, placed with the pose the trackers
    /// got — scores tracking apart from odometry drift) or `world` (drift counts as error).
    #[arg(long, default_value = "robot")]
    frame: String,
    /// Which returns become measurements: `segments`, `moving` or `legs` (real scans at leg
    /// height: the boosted leg classifier of `laser2d::legs`); default by scenario (see the
    /// program documentation).
    #[arg(long)]
    front_end: Option<String>,
    /// Moving front end: which returns count as moving, `clusters` (the detector's moving
    /// clusters) or `candidates` (every foreground return).
    #[arg(long, default_value = "clusters")]
    moving_evidence: String,
    /// Moving front end: share of a person group's returns that must be moving.
    #[arg(long, default_value_t = 0.5)]
    moving_share: f64,
    /// Moving front end: the detector's decision rule, `attenuation`, `veto` (attenuation
    /// with the Fuzzy ART veto) or `voting` (seed 003).
    #[arg(long, default_value = "attenuation")]
    moving_rule: String,
    /// LMB: share of particles per scan that manoeuvre (turn round, stop); 0 gives plain
    /// constant velocity. Default: the tracker's (0.05).
    #[arg(long)]
    manoeuvre: Option<f64>,
    /// LMB: particles per track. Default: the tracker's (500).
    #[arg(long)]
    particles: Option<usize>,
    /// Score estimates of people who are present but unseen (hidden, too far, out of view) as
    /// false instead of ignoring them.
    #[arg(long)]
    score_unseen: bool,
    /// Comma-separated trackers to run.
    #[arg(long, default_value = "lmb,gnn,ml_ransac,jpda_imm")]
    trackers: String,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
    /// Track a CARMEN log (FLASER scans, odometry from the laser lines) instead of simulating.
    #[arg(long)]
    carmen: Option<std::path::PathBuf>,
    /// Read the CARMEN log as if the robot had no odometry: the poses come from the front
    /// end's scan matching alone.
    #[arg(long, requires = "carmen")]
    ignore_odometry: bool,
    /// Track a ROS1 bag (sensor_msgs/LaserScan) instead of simulating.
    #[arg(long)]
    bag: Option<std::path::PathBuf>,
    /// Scan topic of `--bag` (default: the only LaserScan topic).
    #[arg(long)]
    topic: Option<String>,
    /// Track only the scans `A..B` of a recording (0-based, B exclusive; `A..` to the end).
    #[arg(long)]
    scans: Option<String>,
    /// Per-scan people of a recording, as JSON.
    #[arg(long)]
    out: Option<std::path::PathBuf>,
    /// Plot of a recording's tracks over its scan points (`.svg` or `.png`).
    #[arg(long)]
    plot: Option<std::path::PathBuf>,
    /// Range noise of the recorded scanner (m).
    #[arg(long, default_value_t = 0.03)]
    sigma_range: f64,
    /// Bearing noise of the recorded scanner (rad).
    #[arg(long, default_value_t = 0.005)]
    sigma_bearing: f64,
    /// Score a `--bag` recording against its leg annotations on this topic
    /// (`geometry_msgs/PoseArray`, e.g. `/leg_cluster_positions`): per-scan precision, recall,
    /// F1 and false people per scan of the front end and of the tracker, and the tracker's
    /// MOTA, IDF1 and ID switches (rules: `smc_lmb::pipeline::people_tracking::score`); the
    /// tracker is scored on all its visible people and on those classed dynamic.
    #[arg(long)]
    truth_topic: Option<String>,
    /// Legs front end: run this model (JSON, as `train_legs` writes) instead of the shipped one.
    #[arg(long)]
    leg_model: Option<std::path::PathBuf>,
    /// Score a recording that holds nobody (every person reported is false).
    #[arg(long, conflicts_with = "truth_topic")]
    empty: bool,
    /// People farther than this (m) are not tracked in recordings.
    #[arg(long, default_value_t = 15.0)]
    max_range: f64,
    /// Several lasers of one `--bag`, tracked together (comma separated, e.g.
    /// `/left_scan,/right_scan,/rear_scan`); needs `--mountings`.
    #[arg(
        long,
        value_delimiter = ',',
        requires = "mountings",
        conflicts_with = "topic"
    )]
    topics: Vec<String>,
    /// The lasers' mounting poses: the `[[sensors]]` tables `examples/laser_mounting.rs`
    /// prints (name = topic without its `/`, mounting = [x, y, heading] on the robot).
    #[arg(long)]
    mountings: Option<std::path::PathBuf>,
    /// How several lasers combine: `ic`, `pu`, `ga` or `aa` (with `--lasers`, a comma
    /// separated list of the fused runs to compare with each laser alone).
    #[arg(long, default_value = "ic")]
    fusion: String,
    /// Simulate the robot with three lasers (`LaserRig::three_lasers`) in `--scenario` and
    /// compare each laser alone with the lasers fused by each rule of `--fusion`.
    #[arg(long)]
    lasers: bool,
}

fn main() -> Result<()> {
    let args = Args::parse();
    if !args.topics.is_empty() {
        return lasers::run_bag(&args).map(|_| ());
    }
    if args.lasers {
        return lasers::run_simulated(&args);
    }
    if args.carmen.is_some() || args.bag.is_some() {
        return recording::run(&args).map(|_| ());
    }
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
            "icp" => PoseSource::Icp,
            other => anyhow::bail!("--pose {other}: expected odometry, truth or icp"),
        },
        frame: match args.frame.as_str() {
            "robot" => ScoreFrame::Robot,
            "world" => ScoreFrame::World,
            other => anyhow::bail!("--frame {other}: expected robot or world"),
        },
        front_end: front_end(args)?,
        ignore_unseen: !args.score_unseen,
        ..EvalConfig::default()
    };
    let names: Vec<&str> = args.trackers.split(',').map(str::trim).collect();
    let detector = detector_config(&scenario, 0, eval.front_end);
    let mut per_tracker: Vec<Vec<RunMetrics>> = vec![Vec::new(); names.len()];
    for r in 0..args.runs {
        let seed = args.seed + r as u64;
        let run = scenario
            .generate(seed)
            .with_context(|| format!("scenario {} seed {seed}", args.scenario))?;
        for (name, results) in names.iter().zip(per_tracker.iter_mut()) {
            let mut tracker = build_tracker(args, name, &scenario, seed, eval.front_end)?;
            let mut fe = build_front_end(args, &eval, &detector, &run)?;
            let m = evaluate_run_with(tracker.as_mut(), &run, &mut fe, &eval)
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

/// The `--front-end` choice, or the scenario's default: `moving` wherever static structure
/// is in view (the lobby, recordings), `segments` in scenario one's open space.
fn front_end(args: &Args) -> Result<FrontEnd> {
    Ok(match &args.front_end {
        Some(name) => FrontEnd::parse(name)?,
        None if args.carmen.is_none() && args.bag.is_none() && args.scenario == "one" => {
            FrontEnd::Segments
        }
        None => FrontEnd::Moving,
    })
}

/// The front end of `eval` with the moving detector's options from the command line.
fn build_front_end(
    args: &Args,
    eval: &EvalConfig,
    people: &PeopleTrackerConfig,
    run: &smc_lmb::sim::People2dRun,
) -> Result<PersonFrontEnd> {
    let needs_detector = eval.front_end == FrontEnd::Moving || eval.pose == PoseSource::Icp;
    let moving = match run.scans.first() {
        Some(scan) if needs_detector => Some(MovingDetectorConfig {
            rule: moving_rule(args)?,
            ..default_detector_config(people, scan.angle_increment)
        }),
        _ => None,
    };
    let mut fe = PersonFrontEnd::new(eval.front_end, people, moving)?;
    fe.min_moving_share = args.moving_share;
    fe.evidence = match args.moving_evidence.as_str() {
        "clusters" => MovingEvidence::MovingClusters,
        "candidates" => MovingEvidence::Candidates,
        other => anyhow::bail!("--moving-evidence {other}: expected clusters or candidates"),
    };
    Ok(fe)
}

fn moving_rule(args: &Args) -> Result<MovingRule> {
    Ok(match args.moving_rule.as_str() {
        "attenuation" => MovingRule::Attenuation { veto: false },
        "veto" => MovingRule::Attenuation { veto: true },
        "voting" => MovingRule::Voting,
        other => anyhow::bail!("--moving-rule {other}: expected attenuation, veto or voting"),
    })
}

/// Segmentation (and, for the LMB, filter) settings for the scenario's scanner.
/// With the moving front end the LMB assumes its detection probability and clutter rate.
fn detector_config(scenario: &PeopleScenario, seed: u64, fe: FrontEnd) -> PeopleTrackerConfig {
    let s = &scenario.scanner;
    let mut cfg = PeopleTrackerConfig::for_scanner(
        s.sigma_range,
        s.sigma_bearing,
        s.range_max,
        s.fov / 2.0,
        scenario.mount,
    );
    cfg.filter.seed = seed;
    adapt_tracker_config(&mut cfg, fe);
    cfg
}

/// [`detector_config`] with the command line's LMB settings.
fn lmb_config(
    args: &Args,
    scenario: &PeopleScenario,
    seed: u64,
    fe: FrontEnd,
) -> PeopleTrackerConfig {
    let mut cfg = detector_config(scenario, seed, fe);
    apply_lmb_args(args, &mut cfg);
    cfg
}

/// The command line's LMB settings: manoeuvre share and particles per track.
/// The people tracker's configuration for a recording's `scans`, with the command line's
/// noise, range, seed and filter settings.
fn recording_config(
    args: &Args,
    scans: &[smc_lmb::laser2d::Scan],
) -> smc_lmb::Result<PeopleTrackerConfig> {
    let mut cfg = smc_lmb::pipeline::people_tracking::config_for_scans(
        scans,
        args.sigma_range,
        args.sigma_bearing,
        args.max_range,
        [0.0, 0.0],
    )?;
    cfg.filter.seed = args.seed;
    apply_lmb_args(args, &mut cfg);
    Ok(cfg)
}

fn apply_lmb_args(args: &Args, cfg: &mut PeopleTrackerConfig) {
    if let Some(p) = args.manoeuvre {
        cfg.manoeuvre_probability = p;
    }
    if let Some(n) = args.particles {
        cfg.set_particles(n);
    }
}

/// The range-bearing sensor every baseline assumes: the noise of a person's measured centre,
/// as the LMB assumes it, and the scanner's mounting offset.
fn sensor_model(scenario: &PeopleScenario) -> Result<RangeBearing> {
    let s = &scenario.scanner;
    let (sr, sb) = centre_noise(s.sigma_range, s.sigma_bearing);
    Ok(RangeBearing::new(sr, sb)?.with_offset(scenario.mount[0], scenario.mount[1])?)
}

fn build_tracker(
    args: &Args,
    name: &str,
    scenario: &PeopleScenario,
    seed: u64,
    fe: FrontEnd,
) -> Result<Box<dyn PointTracker>> {
    if name == "lmb" {
        let mut t = PeopleTracker::new(lmb_config(args, scenario, seed, fe))?;
        // RMS prediction error and NIS as the baselines report them.
        t.record_innovations(true);
        return Ok(Box::new(t));
    }
    let s = &scenario.scanner;
    // The JPDA's P_D and clutter follow the front end as the LMB's do.
    let (rate, detection) = if fe == FrontEnd::Moving {
        (MOVING_CLUTTER_RATE, Some(MOVING_DETECTION_PROBABILITY))
    } else {
        (1.0, None)
    };
    baseline_tracker(
        name,
        sensor_model(scenario)?,
        seed,
        rate / (s.fov * s.range_max),
        detection,
    )
}

/// The baseline `name` (`gnn`, `ml_ransac`, `jpda_imm`) assuming `sensor`: ML-RANSAC draws
/// from `seed`; the JPDA takes `clutter_density` false measurements per unit of range ×
/// bearing and, when given, its probability of detection.
fn baseline_tracker(
    name: &str,
    sensor: RangeBearing,
    seed: u64,
    clutter_density: f64,
    detection: Option<f64>,
) -> Result<Box<dyn PointTracker>> {
    Ok(match name {
        "gnn" => Box::new(GnnTracker::new(GnnConfig::new(sensor))?),
        "ml_ransac" => {
            let mut cfg = MlRansacConfig::new(sensor);
            cfg.seed = seed;
            Box::new(MlRansacTracker::new(cfg)?)
        }
        "jpda_imm" => {
            let mut cfg = JpdaImmConfig::new(sensor);
            cfg.clutter_density = clutter_density;
            if let Some(p) = detection {
                cfg.detection = p;
            }
            Box::new(JpdaImmTracker::new(cfg)?)
        }
        other => {
            anyhow::bail!("unknown tracker `{other}` (expected lmb, gnn, ml_ransac, jpda_imm)")
        }
    })
}

fn print_json(args: &Args, names: &[&str], summaries: &[Summary]) -> Result<()> {
    let mut out = serde_json::json!({
        "scenario": args.scenario, "runs": args.runs, "seed": args.seed, "pose": args.pose, "frame": args.frame,
        "front_end": front_end(args)?.name(),
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
        "scenario {}, {} run(s) from seed {}, pose {}, {} frame, front end {}; OSPA and OSPA(2) with c = 2 m, p = 1",
        args.scenario,
        summaries.first().map_or(0, scans),
        args.seed,
        args.pose,
        args.frame,
        front_end(args).map_or("?", |f| f.name()),
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

/// The `--carmen` / `--bag` path: real recordings, no ground truth.
mod recording {
    use super::Args;
    use anyhow::{Context, Result};
    use smc_lmb::laser2d::legs::LegModel;
    use smc_lmb::laser2d::{
        read_bag, read_carmen, read_pose_arrays, BagOptions, CarmenOptions, Scan, TimeOrder,
    };
    use smc_lmb::models::RangeBearing;
    use smc_lmb::pipeline::people_tracking::baselines::track_front_end_people;
    use smc_lmb::pipeline::people_tracking::score::{
        truth_for_scans, DetectionScore, TrackScore, TrackScoreSummary, FIRST_SCORED_SCAN,
    };
    use smc_lmb::pipeline::people_tracking::{
        centre_noise, track_scans_with_model, write_people_json, PeopleRun,
    };
    use smc_lmb::pipeline::people_tracking::{write_people_plot, PeoplePlotOptions};
    use std::path::Path;
    use std::time::Instant;

    /// What `--truth-topic` or `--empty` scored (as printed).
    #[derive(Debug)]
    #[cfg_attr(not(test), allow(dead_code))] // the program prints them; its tests read them
    pub struct Scores {
        /// The front end's people.
        pub front_end: DetectionScore,
        /// The tracker's visible people.
        pub tracker: TrackScoreSummary,
        /// The tracker's visible people classed dynamic.
        pub dynamic: TrackScoreSummary,
        /// The baselines of `--trackers` on the front end's people, by name.
        pub baselines: Vec<(String, TrackScoreSummary)>,
    }

    /// Tracks the recording, writes and prints what `args` ask for; the scores when the run
    /// was scored.
    pub fn run(args: &Args) -> Result<Option<Scores>> {
        let t_read = Instant::now();
        let scans = window(args, load(args)?)?;
        let read_s = t_read.elapsed().as_secs_f64();
        anyhow::ensure!(!scans.is_empty(), "the recording holds no scan");
        let cfg = super::recording_config(args, &scans)?;
        let min_visibility = cfg.min_visibility;
        let clutter_volume = cfg.filter.clutter.as_ref().map_or(0.0, |c| c.volume);
        let t0 = Instant::now();
        let fe = super::front_end(args)?;
        println!("front end {}", fe.name());
        let model = match &args.leg_model {
            Some(p) => Some(
                LegModel::from_json(&std::fs::read_to_string(p)?)
                    .with_context(|| format!("reading {}", p.display()))?,
            ),
            None => None,
        };
        let run = track_scans_with_model(&scans, cfg, fe, model)?;
        let secs = t0.elapsed().as_secs_f64();
        if let Some(path) = &args.out {
            write_people_json(path, &run).with_context(|| format!("writing {}", path.display()))?;
        }
        if let Some(path) = &args.plot {
            plot(path, args, &scans, &run)
                .with_context(|| format!("plotting {}", path.display()))?;
        }
        report(&scans, &run, read_s, secs);
        if args.truth_topic.is_some() || args.empty {
            let truth = truth(args, &scans)?;
            let mut scores = score(&run, &truth, min_visibility)?;
            for name in args.trackers.split(',').map(str::trim) {
                if name != "lmb" {
                    let b = score_baseline(args, name, &scans, &run, &truth, clutter_volume)?;
                    scores.baselines.push((name.to_string(), b));
                }
            }
            return Ok(Some(scores));
        }
        Ok(None)
    }

    /// Runs the baseline `name` on the front end's people of `run` (the JPDA with one false
    /// measurement per `clutter_volume`, the LMB's range × bearing field of view), prints its
    /// scores as the LMB's are printed and returns them.
    fn score_baseline(
        args: &Args,
        name: &str,
        scans: &[Scan],
        run: &PeopleRun,
        truth: &[Vec<[f64; 2]>],
        clutter_volume: f64,
    ) -> Result<TrackScoreSummary> {
        // The noise of a person's centre and the clutter volume the LMB assumes.
        let (sr, sb) = centre_noise(args.sigma_range, args.sigma_bearing);
        let sensor = RangeBearing::new(sr, sb)?;
        let mut tracker =
            super::baseline_tracker(name, sensor, args.seed, 1.0 / clutter_volume, None)?;
        let t0 = Instant::now();
        let tracks = track_front_end_people(run, scans, tracker.as_mut())
            .with_context(|| format!("{name} on the front end's people"))?;
        let secs = t0.elapsed().as_secs_f64();
        let mut score = TrackScore::default();
        for ((s, t), est) in run.scans.iter().zip(truth).zip(&tracks) {
            score.add_scan(t, est, s.scan >= FIRST_SCORED_SCAN)?;
        }
        let t = score.summary();
        let d = &t.detection;
        println!(
            "{name}: {} scans scored, {} people, {} reported; precision {:.3}, recall {:.3}, F1 {:.3}, false people per scan {:.3}",
            d.scans, d.people, d.estimates, d.precision(), d.recall(), d.f1(), d.false_per_scan()
        );
        println!(
            "{name}: MOTA {:.3}, IDF1 {:.3}, ID switches {} (tracked in {:.3} s)",
            t.mota, t.idf1, t.id_switches, secs
        );
        Ok(t)
    }

    /// The people of every scan: from the annotations of `--truth-topic`, or nobody.
    fn truth(args: &Args, scans: &[Scan]) -> Result<Vec<Vec<[f64; 2]>>> {
        let Some(topic) = &args.truth_topic else {
            return Ok(vec![Vec::new(); scans.len()]);
        };
        let path = args.bag.as_ref().context("--truth-topic needs --bag")?;
        anyhow::ensure!(
            args.scans.is_none(),
            "--truth-topic scores whole recordings: drop --scans"
        );
        let annotations =
            read_pose_arrays(path, topic).with_context(|| format!("reading {}", path.display()))?;
        let options = match &args.topic {
            Some(t) => BagOptions::topic(t.clone()),
            None => BagOptions::default(),
        };
        let received = read_bag(path, &options)?.receive_times;
        anyhow::ensure!(
            received.len() == scans.len(),
            "the bag changed while reading"
        );
        Ok(truth_for_scans(
            &received,
            &annotations,
            &format!("{} {topic}", path.display()),
        )?)
    }

    /// Prints the scores of the front end's people and of the tracker's visible people.
    fn score(run: &PeopleRun, truth: &[Vec<[f64; 2]>], min_visibility: f64) -> Result<Scores> {
        let mut detector = DetectionScore::default();
        let mut tracks = TrackScore::default();
        let mut walking = TrackScore::default();
        for (s, t) in run.scans.iter().zip(truth) {
            let scored = s.scan >= FIRST_SCORED_SCAN;
            if scored {
                detector.add_scan(t, &s.detections)?;
            }
            // Estimates back into the sensor frame of the scan.
            let to_sensor = |p: [f64; 2]| match s.pose {
                Some([x, y, th]) => {
                    let (dx, dy) = (p[0] - x, p[1] - y);
                    let (sn, cs) = th.sin_cos();
                    [cs * dx + sn * dy, -sn * dx + cs * dy]
                }
                None => p,
            };
            let visible = s.people.iter().filter(|p| p.visibility >= min_visibility);
            let est: Vec<_> = visible
                .clone()
                .map(|p| (p.label, to_sensor(p.position)))
                .collect();
            tracks.add_scan(t, &est, scored)?;
            let est: Vec<_> = visible
                .filter(|p| p.moving)
                .map(|p| (p.label, to_sensor(p.position)))
                .collect();
            walking.add_scan(t, &est, scored)?;
        }
        let line = |what: &str, d: &DetectionScore| {
            println!(
                "{what}: {} scans scored, {} people, {} reported; precision {:.3}, recall {:.3}, F1 {:.3}, false people per scan {:.3}",
                d.scans, d.people, d.estimates, d.precision(), d.recall(), d.f1(), d.false_per_scan()
            )
        };
        line("front end", &detector);
        let scores = Scores {
            front_end: detector,
            tracker: tracks.summary(),
            dynamic: walking.summary(),
            baselines: Vec::new(),
        };
        for (what, t) in [
            ("tracker", &scores.tracker),
            ("tracker, dynamic only", &scores.dynamic),
        ] {
            line(what, &t.detection);
            println!(
                "{what}: MOTA {:.3}, IDF1 {:.3}, ID switches {}",
                t.mota, t.idf1, t.id_switches
            );
        }
        Ok(scores)
    }

    fn load(args: &Args) -> Result<Vec<Scan>> {
        if let Some(path) = &args.carmen {
            // Real logs have the odd stamp that jumps while the file order is right: drop the
            // fewest scans that leave time in order.
            let options = CarmenOptions {
                time_order: TimeOrder::DropFewest,
                ignore_odometry: args.ignore_odometry,
                ..CarmenOptions::default()
            };
            let log = read_carmen(path, options)
                .with_context(|| format!("reading {}", path.display()))?;
            return Ok(if log.flaser.is_empty() {
                log.robot_laser
            } else {
                log.flaser
            });
        }
        let path = args.bag.as_ref().expect("--bag given");
        let options = match &args.topic {
            Some(t) => BagOptions::topic(t.clone()),
            None => BagOptions::default(),
        };
        Ok(read_bag(path, &options)
            .with_context(|| format!("reading {}", path.display()))?
            .scans)
    }

    fn report(scans: &[Scan], run: &PeopleRun, read_s: f64, secs: f64) {
        let span = scans.last().map_or(0.0, |s| s.time) - scans[0].time;
        println!(
            "{} scans over {:.1} s ({} beams); read in {:.2} s, tracked in {:.2} s ({:.0} scans/s)",
            scans.len(),
            span,
            scans[0].len(),
            read_s,
            secs,
            scans.len() as f64 / secs
        );
        let per_scan: Vec<usize> = run
            .scans
            .iter()
            .map(|s| s.people.iter().filter(|p| p.visibility >= 0.5).count())
            .collect();
        let mean_people = per_scan.iter().sum::<usize>() as f64 / per_scan.len().max(1) as f64;
        println!(
            "visible people per scan: mean {mean_people:.2}, max {}",
            per_scan.iter().max().copied().unwrap_or(0)
        );
        let fallbacks = run.pose_fallbacks();
        if !fallbacks.is_empty() {
            let parts: Vec<String> = fallbacks
                .iter()
                .map(|(why, n)| format!("{n} for {}", why.describe()))
                .collect();
            eprintln!(
                "warning: the scan matching's pose was not used on {} of {} scans ({}); the \
                 predicted pose stood",
                fallbacks.values().sum::<usize>(),
                run.scans.len(),
                parts.join(", ")
            );
        }
        for (what, min) in [
            ("all", 1usize),
            ("at least 8 scans (1 s at 8 Hz)", 8),
            ("at least 40 scans", 40),
        ] {
            let t: Vec<_> = run.tracks_with(min).collect();
            let dynamic: Vec<_> = t.iter().filter(|t| t.dynamic_fraction >= 0.5).collect();
            // "–" for no tracks, not NaN.
            let median = |mut v: Vec<f64>, digits: usize| {
                v.sort_by(f64::total_cmp);
                v.get(v.len() / 2)
                    .map_or_else(|| "–".to_string(), |m| format!("{m:.digits$}"))
            };
            println!(
                "tracks ({what}): {} ({} mostly dynamic); median length {} scans / {} s; median speed of dynamic ones {} m/s, median displacement {} m",
                t.len(),
                dynamic.len(),
                median(t.iter().map(|t| t.scans as f64).collect(), 0),
                median(t.iter().map(|t| t.last_time - t.first_time).collect(), 1),
                median(dynamic.iter().map(|t| t.mean_speed).collect(), 2),
                median(dynamic.iter().map(|t| t.displacement).collect(), 1),
            );
        }
    }

    fn plot(path: &Path, args: &Args, scans: &[Scan], run: &PeopleRun) -> Result<()> {
        let source = args
            .carmen
            .as_ref()
            .or(args.bag.as_ref())
            .expect("a recording");
        let mut title = source
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        if let Some(range) = &args.scans {
            title = format!("{title}, scans {range}");
        }
        let options = PeoplePlotOptions {
            title,
            ..PeoplePlotOptions::default()
        };
        write_people_plot(path, scans, run, &options)?;
        Ok(())
    }

    /// The scans `A..B` (0-based, B exclusive) of `--scans`, all without it.
    fn window(args: &Args, scans: Vec<Scan>) -> Result<Vec<Scan>> {
        let Some(range) = &args.scans else {
            return Ok(scans);
        };
        let (a, b) = range
            .split_once("..")
            .with_context(|| format!("--scans {range}: expected A..B"))?;
        let a: usize = a
            .trim()
            .parse()
            .with_context(|| format!("--scans {range}"))?;
        let b: usize = if b.trim().is_empty() {
            scans.len()
        } else {
            b.trim()
                .parse()
                .with_context(|| format!("--scans {range}"))?
        };
        anyhow::ensure!(
            a < b && b <= scans.len(),
            "--scans {range}: the recording has {} scans",
            scans.len()
        );
        Ok(scans[a..b].to_vec())
    }
}

/// Several lasers: `--topics` of a bag at their `--mountings`, or the simulated rig of
/// `--lasers`; the work is `smc_lmb::pipeline::people_tracking::lasers`'.
mod lasers {
    use super::Args;
    use anyhow::{Context, Result};
    use smc_lmb::filter::{Fusion, FusionMethod};
    use smc_lmb::pipeline::people_tracking::lasers::{read_bag_lasers, track_lasers};
    use smc_lmb::pipeline::people_tracking::lasers_eval::{
        evaluate_lasers, summarise_variant, LaserVariant, VariantSummary,
    };
    use smc_lmb::pipeline::people_tracking::score::FIRST_SCORED_SCAN;
    use smc_lmb::pipeline::people_tracking::{write_people_json, PeopleRun};
    use smc_lmb::sim::people2d::lasers::LaserRig;

    /// Tracks `--topics` of `--bag` together; with `--empty` prints (and returns) the false
    /// people per frame from the 10th frame on.
    pub fn run_bag(args: &Args) -> Result<(PeopleRun, Option<f64>)> {
        let bag = args.bag.as_ref().context("--topics needs --bag")?;
        let mountings = args
            .mountings
            .as_ref()
            .context("--topics needs --mountings")?;
        let recordings = read_bag_lasers(bag, &args.topics, mountings, args.max_range)?;
        let first = &recordings[0];
        let cfg = super::recording_config(args, &first.scans)?;
        let min_visibility = cfg.min_visibility;
        let fe = super::front_end(args)?;
        let fusion = FusionMethod::from_short_name(&args.fusion)?;
        let t0 = std::time::Instant::now();
        let run = track_lasers(&recordings, cfg, fe, Fusion::new(fusion))?;
        let secs = t0.elapsed().as_secs_f64();
        if let Some(path) = &args.out {
            write_people_json(path, &run).with_context(|| format!("writing {}", path.display()))?;
        }
        let scans: usize = recordings.iter().map(|r| r.scans.len()).sum();
        println!(
            "lasers {} (front end {}, fusion {}): {} frames from {scans} scans, tracked in {secs:.2} s",
            args.topics.join(","),
            fe.name(),
            fusion.short_name(),
            run.scans.len()
        );
        if !args.empty {
            return Ok((run, None));
        }
        let scored: Vec<usize> = run
            .scans
            .iter()
            .skip(FIRST_SCORED_SCAN)
            .map(|s| {
                s.people
                    .iter()
                    .filter(|p| p.visibility >= min_visibility)
                    .count()
            })
            .collect();
        let false_people = scored.iter().sum::<usize>() as f64 / scored.len().max(1) as f64;
        println!(
            "empty recording: {} frames scored, {} people reported, false people per frame {false_people:.4}; tracks visible in ≥ 8 frames: {}",
            scored.len(),
            scored.iter().sum::<usize>(),
            run.tracks_with(8).count()
        );
        Ok((run, Some(false_people)))
    }

    /// Each laser of the three-laser rig alone and the lasers fused by each rule of
    /// `--fusion`, on `--runs` seeds of `--scenario`; prints the means.
    pub fn run_simulated(args: &Args) -> Result<()> {
        let scenario = match args.scenario.as_str() {
            "one" => smc_lmb::sim::PeopleScenario::one(),
            "two" => smc_lmb::sim::PeopleScenario::two(),
            other => anyhow::bail!("unknown scenario `{other}` (expected one or two)"),
        };
        anyhow::ensure!(args.runs > 0, "--runs must be at least 1");
        let rig = LaserRig::three_lasers(scenario.scanner);
        let rules = args
            .fusion
            .split(',')
            .map(|r| FusionMethod::from_short_name(r.trim()))
            .collect::<smc_lmb::Result<Vec<_>>>()?;
        let variants = LaserVariant::singles_and_fused(&rig, &rules);
        let fe = super::front_end(args)?;
        let mut per_variant = vec![Vec::new(); variants.len()];
        for r in 0..args.runs {
            let seed = args.seed + r as u64;
            let run = scenario.generate_lasers(&rig, seed)?;
            for (v, scores) in variants.iter().zip(per_variant.iter_mut()) {
                let mut cfg = super::lmb_config(args, &scenario, seed, fe);
                cfg.filter.seed = seed;
                let s = evaluate_lasers(&run, &rig, &v.lasers, &cfg, fe, Fusion::new(v.fusion))
                    .with_context(|| format!("{} on seed {seed}", v.name))?;
                if !args.json {
                    eprintln!(
                        "seed {seed} {}: F1 {:.3}, OSPA {:.3}, OSPA(2) {:.3}, label switches {}",
                        v.name,
                        s.detection.f1(),
                        s.mean_ospa,
                        s.ospa2,
                        s.label_switches
                    );
                }
                scores.push(s);
            }
        }
        let summaries: Vec<VariantSummary> = variants
            .into_iter()
            .zip(per_variant)
            .map(|(v, s)| summarise_variant(v, s))
            .collect::<smc_lmb::Result<_>>()?;
        if args.json {
            println!("{}", serde_json::to_string_pretty(&summaries)?);
            return Ok(());
        }
        println!(
            "scenario {}, three lasers, {} run(s) from seed {}, front end {}; means over runs (OSPA c = 2 m, p = 1)",
            args.scenario,
            args.runs,
            args.seed,
            fe.name()
        );
        println!("| lasers | F1 | precision | recall | OSPA (m) | OSPA(2) (m) | label switches | frames/s |");
        println!("|---|---|---|---|---|---|---|---|");
        for s in &summaries {
            println!(
                "| {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {:.0} |",
                s.variant.name,
                s.f1,
                s.precision,
                s.recall,
                s.mean_ospa,
                s.ospa2,
                s.label_switches,
                s.frames_per_second
            );
        }
        Ok(())
    }
}

/// The recording path as the command line runs it, on the ROS bag excerpt vendored for the
/// tests (`tests/data/laser2d/positive_1_excerpt.bag`: 39 scans of one person walking away
/// from the scanner, with leg annotations): `cargo test --example laser2d`.
#[cfg(test)]
mod tests {
    use super::*;
    use smc_lmb::pipeline::people_tracking::score::DetectionScore;
    use smc_lmb::pipeline::people_tracking::PeopleRun;

    const EXCERPT: &str = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/laser2d/positive_1_excerpt.bag"
    );
    /// Scans in the excerpt, and those scored (from the 10th).
    const SCANS: usize = 39;
    const SCORED: usize = 30;

    /// `laser2d --bag EXCERPT --topic /training_scan --out J --plot P EXTRA`: the scores, the
    /// people JSON read back and the plot.
    fn laser2d(extra: &[&str]) -> Result<(Option<recording::Scores>, PeopleRun, String)> {
        let dir = tempfile::tempdir()?;
        let (out, plot) = (
            dir.path().join("people.json"),
            dir.path().join("tracks.svg"),
        );
        let mut argv = vec!["laser2d", "--bag", EXCERPT, "--topic", "/training_scan"];
        argv.extend([
            "--out",
            out.to_str().unwrap(),
            "--plot",
            plot.to_str().unwrap(),
        ]);
        argv.extend(extra);
        let scores = recording::run(&Args::try_parse_from(argv)?)?;
        let run = serde_json::from_slice(&std::fs::read(&out)?)?;
        Ok((scores, run, std::fs::read_to_string(&plot)?))
    }

    fn assert_sane(d: &DetectionScore) {
        for v in [d.precision(), d.recall(), d.f1(), d.false_per_scan()] {
            assert!(v.is_finite() && v >= 0.0, "{d:?}");
        }
        assert!(d.precision() <= 1.0 && d.recall() <= 1.0 && d.f1() <= 1.0);
    }

    #[test]
    fn bag_excerpt_is_tracked_and_scored_against_its_annotations() {
        let (scores, run, svg) = laser2d(&["--truth-topic", "/leg_cluster_positions"]).unwrap();
        let s = scores.expect("--truth-topic scores the run");
        // One annotated person in every scored scan.
        for d in [&s.front_end, &s.tracker.detection, &s.dynamic.detection] {
            assert_eq!((d.scans, d.people), (SCORED, SCORED), "{d:?}");
            assert_sane(d);
        }
        for t in [&s.tracker, &s.dynamic] {
            assert!(t.mota.is_finite() && t.mota <= 1.0, "{t:?}");
            assert!((0.0..=1.0).contains(&t.idf1), "{t:?}");
        }
        assert_eq!(run.scans.len(), SCANS);
        assert!(run.scans.iter().enumerate().all(|(k, s)| s.scan == k));
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    }

    #[test]
    fn bag_excerpt_with_the_legs_front_end_finds_its_walker() {
        // The excerpt is part of the shipped leg model's training data: an end-to-end check
        // of the legs path, not of how well the model generalises.
        let extra = [
            "--truth-topic",
            "/leg_cluster_positions",
            "--front-end",
            "legs",
        ];
        let (scores, run, _) = laser2d(&extra).unwrap();
        let s = scores.unwrap();
        assert!(
            s.front_end.recall() >= 0.9 && s.front_end.precision() >= 0.9,
            "{s:?}"
        );
        assert!(s.tracker.detection.f1() >= 0.9, "{s:?}");
        assert_eq!(s.tracker.id_switches, 0);
        assert_eq!(run.tracks_with(20).count(), 1, "{:?}", run.tracks);
        // The baselines ran on the same people and were scored on the same scans.
        let names: Vec<&str> = s.baselines.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["gnn", "ml_ransac", "jpda_imm"]);
        for (name, b) in &s.baselines {
            assert_eq!(b.detection.scans, s.tracker.detection.scans, "{name}");
            assert_eq!(b.detection.people, s.tracker.detection.people, "{name}");
            assert_sane(&b.detection);
            assert!(b.detection.recall() >= 0.8, "{name}: {b:?}");
        }
    }

    #[test]
    fn bag_excerpt_window_runs_unscored_and_bad_requests_are_refused() {
        let (scores, run, _) = laser2d(&["--scans", "5..25"]).unwrap();
        assert!(scores.is_none());
        assert_eq!(run.scans.len(), 20);
        let e = laser2d(&[
            "--scans",
            "5..25",
            "--truth-topic",
            "/leg_cluster_positions",
        ])
        .unwrap_err();
        assert!(format!("{e:#}").contains("drop --scans"), "{e:#}");
        let e = laser2d(&["--truth-topic", "/training_scan"]).unwrap_err();
        assert!(
            format!("{e:#}").contains("geometry_msgs/PoseArray"),
            "{e:#}"
        );
    }
}
