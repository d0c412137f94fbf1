//! Trains the leg classifier of `smc_lmb::laser2d::legs` on the annotated recordings of the
//! ROS `leg_tracker` (`../shared/data/laser2d/leg_annotated`), checks it by leave-one-bag-out
//! cross-validation and writes the model shipped with the library:
//!
//! ```text
//! cargo run --release --example train_legs -- --out src/laser2d/leg_model.json
//! ```
//!
//! Samples are the leg candidates of every scan (`LegDetector::candidates`, in scan order
//! for the motion feature). In the positive bags a
//! candidate whose centroid lies within 0.25 m of an annotated leg is a leg; one between
//! 0.25 and 0.6 m from the nearest annotated leg is left out (a piece of a leg, or a leg and
//! something beside it); the rest are not legs. Every candidate of `negative_2.bag` (all
//! three lasers; nobody in the rooms) is not a leg.
//!
//! Cross-validation: fold `i` (i = 1…4) trains on the three other positive bags and two of
//! the three lasers of `negative_2.bag`, and scores the detector (people from legs, scans
//! from the 10th, the rules of `smc_lmb::pipeline::people_tracking::score`) on the held-out
//! positive bag and the held-out laser (`/left_scan`, `/right_scan`, `/rear_scan`,
//! `/left_scan` for folds 1–4). The shipped model is then trained on everything; its scores
//! on the training recordings are printed too.

use anyhow::{Context, Result};
use clap::Parser;
use smc_lmb::laser2d::boost::Boosted;
use smc_lmb::laser2d::legs::{
    pair_legs, Leg, LegCandidate, LegDetector, LegDetectorConfig, LegModel, LEG_FEATURE_NAMES,
};
use smc_lmb::laser2d::{read_bag, read_pose_arrays, BagOptions};
use smc_lmb::pipeline::people_tracking::score::{
    legs_for_scans, people_from_legs, DetectionScore, FIRST_SCORED_SCAN, LEG_MERGE,
};
use std::path::PathBuf;

#[derive(Parser, Debug)]
#[command(about = "Train the leg classifier on the annotated leg_tracker recordings")]
struct Args {
    /// The folder of the recordings.
    #[arg(long, default_value = "../shared/data/laser2d/leg_annotated")]
    data: PathBuf,
    /// Boosting rounds.
    #[arg(long, default_value_t = 400)]
    rounds: usize,
    /// Write the model trained on all recordings here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write each fold's model here as `fold_<i>.json` (to run the tracker on its held-out
    /// recordings with `laser2d --leg-model`).
    #[arg(long)]
    fold_models: Option<PathBuf>,
    /// Train without these features (comma-separated names; their column is set to 0, so
    /// no stump splits on it): for measuring what a feature is worth.
    #[arg(long, value_delimiter = ',')]
    drop_features: Vec<String>,
}

const POSITIVE: [&str; 4] = [
    "positive_1_extracted.bag",
    "positive_2_extracted.bag",
    "positive_3_extracted.bag",
    "positive_4_extracted.bag",
];
const LASERS: [&str; 3] = ["/left_scan", "/right_scan", "/rear_scan"];

/// One recording's candidates per scan, with labels (None: left out) and people.
struct Recording {
    name: String,
    scans: Vec<Vec<(LegCandidate, Option<bool>)>>,
    people: Vec<Vec<[f64; 2]>>,
}

/// A detector that only finds candidates (its classifier is empty).
fn candidate_finder(cfg: &LegDetectorConfig) -> Result<LegDetector> {
    Ok(LegDetector::new(LegModel {
        description: String::new(),
        features: LEG_FEATURE_NAMES.iter().map(|s| s.to_string()).collect(),
        config: *cfg,
        classifier: Boosted::default(),
    })?)
}

fn load(args: &Args, cfg: &LegDetectorConfig) -> Result<(Vec<Recording>, Vec<Recording>)> {
    let mut pos = Vec::new();
    for name in POSITIVE {
        let path = args.data.join(name);
        let bag = read_bag(&path, &BagOptions::topic("/training_scan"))
            .with_context(|| format!("reading {}", path.display()))?;
        let scans = bag.scans;
        let ann = read_pose_arrays(&path, "/leg_cluster_positions")?;
        let legs = legs_for_scans(
            &bag.receive_times,
            &ann,
            &format!("{name} /leg_cluster_positions"),
        )?;
        let mut per_scan: Vec<Vec<(LegCandidate, Option<bool>)>> = Vec::new();
        let mut finder = candidate_finder(cfg)?;
        for (s, l) in scans.iter().zip(&legs) {
            let c = finder.candidates(s)?;
            per_scan.push(
                c.into_iter()
                    .map(|c| {
                        let d = l
                            .iter()
                            .map(|a| (a[0] - c.centroid[0]).hypot(a[1] - c.centroid[1]))
                            .fold(f64::INFINITY, f64::min);
                        let label = if d < 0.25 {
                            Some(true)
                        } else if d < 0.6 {
                            None
                        } else {
                            Some(false)
                        };
                        (c, label)
                    })
                    .collect(),
            );
        }
        pos.push(Recording {
            name: name.to_string(),
            scans: per_scan,
            people: legs
                .iter()
                .map(|l| people_from_legs(l, LEG_MERGE))
                .collect(),
        });
    }
    let mut neg = Vec::new();
    let path = args.data.join("negative_2.bag");
    for topic in LASERS {
        let scans = read_bag(&path, &BagOptions::topic(topic))
            .with_context(|| format!("reading {} {topic}", path.display()))?
            .scans;
        let mut finder = candidate_finder(cfg)?;
        let per_scan = scans
            .iter()
            .map(|s| {
                Ok(finder
                    .candidates(s)?
                    .into_iter()
                    .map(|c| (c, Some(false)))
                    .collect())
            })
            .collect::<smc_lmb::Result<Vec<_>>>()?;
        neg.push(Recording {
            name: format!("negative_2 {topic}"),
            people: vec![Vec::new(); per_scan.len()],
            scans: per_scan,
        });
    }
    Ok((pos, neg))
}

fn train(recs: &[&Recording], rounds: usize, drop: &[usize]) -> Result<Boosted> {
    let mut xs: Vec<Vec<f64>> = Vec::new();
    let mut ys = Vec::new();
    for r in recs {
        for s in &r.scans {
            for (c, label) in s {
                if let Some(l) = label {
                    let mut x = c.features.to_vec();
                    drop.iter().for_each(|&f| x[f] = 0.0);
                    xs.push(x);
                    ys.push(*l);
                }
            }
        }
    }
    eprintln!(
        "training on {} candidates ({} legs)",
        xs.len(),
        ys.iter().filter(|&&y| y).count()
    );
    Ok(Boosted::train(&xs, &ys, rounds)?)
}

/// Every candidate of a recording as a leg with the model's score.
fn scored(model: &Boosted, rec: &Recording) -> Vec<Vec<Leg>> {
    rec.scans
        .iter()
        .map(|s| {
            s.iter()
                .map(|(c, _)| Leg {
                    position: c.centroid,
                    score: model.score(&c.features),
                })
                .collect()
        })
        .collect()
}

fn score_legs(
    legs: &[Vec<Leg>],
    rec: &Recording,
    cfg: &LegDetectorConfig,
) -> Result<DetectionScore> {
    let mut d = DetectionScore::default();
    for (k, (s, truth)) in legs.iter().zip(&rec.people).enumerate() {
        if k < FIRST_SCORED_SCAN {
            continue;
        }
        let legs: Vec<Leg> = s
            .iter()
            .copied()
            .filter(|l| l.score > cfg.leg_score)
            .collect();
        d.add_scan(truth, &pair_legs(&legs, cfg))?;
    }
    Ok(d)
}

fn score(model: &Boosted, rec: &Recording, cfg: &LegDetectorConfig) -> Result<DetectionScore> {
    score_legs(&scored(model, rec), rec, cfg)
}

/// The decision thresholds tried on the held-out folds.
fn grid(base: &LegDetectorConfig) -> Vec<LegDetectorConfig> {
    let mut out = Vec::new();
    for leg_score in [-0.05, -0.025, 0.0, 0.025, 0.05, 0.1] {
        for single in [0.0, 0.025, 0.05, 0.075, 0.1, 0.15, 1.0] {
            if single >= leg_score {
                out.push(LegDetectorConfig {
                    leg_score,
                    single_leg_score: single,
                    ..*base
                });
            }
        }
    }
    out
}

fn row(name: &str, d: &DetectionScore) {
    println!(
        "| {name} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} |",
        d.scans,
        d.people,
        d.precision(),
        d.recall(),
        d.f1(),
        d.false_per_scan()
    );
}

fn header(title: &str) {
    println!("\n{title}\n");
    println!("| recording | scans | people | precision | recall | F1 | false people per scan |");
    println!("|---|---|---|---|---|---|---|");
}

fn leg_model(model: &Boosted, cfg: &LegDetectorConfig, trained_on: &str) -> LegModel {
    LegModel {
        description: format!(
            "AdaBoost, {} decision stumps on the leg candidates of {trained_on}",
            model.stumps.len()
        ),
        features: LEG_FEATURE_NAMES.iter().map(|s| s.to_string()).collect(),
        config: *cfg,
        classifier: model.clone(),
    }
}

fn main() -> Result<()> {
    let args = Args::parse();
    let cfg = LegDetectorConfig::default();
    let drop = args
        .drop_features
        .iter()
        .map(|n| {
            LEG_FEATURE_NAMES
                .iter()
                .position(|f| f == n)
                .with_context(|| format!("no feature {n}"))
        })
        .collect::<Result<Vec<usize>>>()?;
    let (pos, neg) = load(&args, &cfg)?;
    header("Leave-one-bag-out (each row scored by a model that never saw it)");
    let (mut pooled_pos, mut pooled_neg) = (DetectionScore::default(), DetectionScore::default());
    let settings = grid(&cfg);
    let mut grid_pos = vec![DetectionScore::default(); settings.len()];
    let mut grid_neg = vec![DetectionScore::default(); settings.len()];
    for i in 0..pos.len() {
        let held_laser = i % neg.len();
        let train_set: Vec<&Recording> = pos
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, r)| r)
            .chain(
                neg.iter()
                    .enumerate()
                    .filter(|(j, _)| *j != held_laser)
                    .map(|(_, r)| r),
            )
            .collect();
        let model = train(&train_set, args.rounds, &drop)?;
        if let Some(dir) = &args.fold_models {
            std::fs::create_dir_all(dir)?;
            let path = dir.join(format!("fold_{}.json", i + 1));
            let held = format!("{} and negative_2 {}", pos[i].name, LASERS[held_laser]);
            std::fs::write(
                &path,
                leg_model(&model, &cfg, &format!("fold {}: all but {held}", i + 1)).to_json(),
            )?;
        }
        let (lp, ln) = (scored(&model, &pos[i]), scored(&model, &neg[held_laser]));
        for (k, c) in settings.iter().enumerate() {
            grid_pos[k].merge(&score_legs(&lp, &pos[i], c)?);
            grid_neg[k].merge(&score_legs(&ln, &neg[held_laser], c)?);
        }
        let p = score_legs(&lp, &pos[i], &cfg)?;
        let n = score_legs(&ln, &neg[held_laser], &cfg)?;
        row(&format!("{} (fold {})", pos[i].name, i + 1), &p);
        row(&format!("{} (fold {})", neg[held_laser].name, i + 1), &n);
        pooled_pos.merge(&p);
        pooled_neg.merge(&n);
    }
    row("pooled positive folds", &pooled_pos);
    row("pooled negative folds", &pooled_neg);
    println!("\nDecision thresholds over the pooled folds\n");
    println!("| leg score | single leg score | precision | recall | F1 | false people per scan, empty rooms |");
    println!("|---|---|---|---|---|---|");
    for (k, c) in settings.iter().enumerate() {
        println!(
            "| {} | {} | {:.3} | {:.3} | {:.3} | {:.3} |",
            c.leg_score,
            c.single_leg_score,
            grid_pos[k].precision(),
            grid_pos[k].recall(),
            grid_pos[k].f1(),
            grid_neg[k].false_per_scan()
        );
    }

    let all: Vec<&Recording> = pos.iter().chain(&neg).collect();
    let model = train(&all, args.rounds, &drop)?;
    header("Trained on everything, scored on its own training recordings");
    let mut pooled = DetectionScore::default();
    for r in &pos {
        let d = score(&model, r, &cfg)?;
        row(&r.name, &d);
        pooled.merge(&d);
    }
    row("pooled positive", &pooled);
    for r in &neg {
        row(&r.name, &score(&model, r, &cfg)?);
    }
    if let Some(out) = &args.out {
        let m = leg_model(
            &model,
            &cfg,
            &format!(
                "positive_{{1,2,3,4}}_extracted.bag and negative_2.bag (all lasers); \
                 `cargo run --release --example train_legs -- --rounds {} --out {}`",
                args.rounds,
                out.display()
            ),
        );
        std::fs::write(out, m.to_json() + "\n")
            .with_context(|| format!("writing {}", out.display()))?;
        eprintln!("wrote {}", out.display());
    }
    Ok(())
}
