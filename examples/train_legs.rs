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
//!
//! That table is optimistic where its settings were chosen on the same folds. `--nested`
//! makes every choice inside each fold: the number of rounds (`--rounds-grid`) and the two
//! score thresholds are chosen by leave-one-bag-out on the fold's three training bags alone
//! (inner folds: two bags and one laser train, the third bag and the other laser score; the
//! highest pooled F1 with at most `--max-false` false people per empty-room scan), and only
//! then is the fold's model trained on its three bags and two lasers and scored on the
//! held-out bag and laser. The same selection on all four bags gives the shipped model's
//! settings (with `--out`). Training is deterministic; `--seeds 1,2,3` repeats the estimate
//! with each training recording's scans drawn with replacement (a bootstrap, seed 0: as
//! recorded), for the spread a different recording of the same scenes would give.
//!
//! `--augment` adds varied copies of every training recording (`smc_lmb::laser2d::leg_augment`:
//! `mirror`, `scale:F` for the ranges times F, `half` for every other beam); held-out
//! recordings are always scored as recorded, and with `--half-eval` also at half the angular
//! resolution. `--shrinkage` and `--min-leaf` regularise the boosting; `--importance` prints
//! each fold model's feature weights and thresholds.

use anyhow::{Context, Result};
use clap::Parser;
use smc_lmb::laser2d::boost::{BoostConfig, Boosted};
use smc_lmb::laser2d::leg_augment::Augmentation;
use smc_lmb::laser2d::legs::{
    pair_legs, Leg, LegCandidate, LegDetector, LegDetectorConfig, LegModel, LEG_FEATURE_NAMES,
};
use smc_lmb::laser2d::{read_bag, read_pose_arrays, BagOptions, Scan};
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
    /// Nested leave-one-bag-out: every setting chosen on the training bags of a fold only.
    #[arg(long)]
    nested: bool,
    /// Rounds tried by the nested selection (prefixes of one model trained with the most).
    #[arg(long, value_delimiter = ',', default_value = "50,100,200,400")]
    rounds_grid: Vec<usize>,
    /// Most false people per empty-room scan the selection accepts (held-out lasers).
    #[arg(long, default_value_t = 0.6)]
    max_false: f64,
    /// Seeds of the bootstrap of training scans (0: every scan once, as recorded).
    #[arg(long, value_delimiter = ',', default_value = "0")]
    seeds: Vec<u64>,
    /// Varied copies of the training recordings: mirror, scale:F, half.
    #[arg(long, value_delimiter = ',')]
    augment: Vec<String>,
    /// Boosting learning rate (1: plain AdaBoost).
    #[arg(long, default_value_t = 1.0)]
    shrinkage: f64,
    /// Fewest training samples on either side of a stump.
    #[arg(long, default_value_t = 1)]
    min_leaf: usize,
    /// Also score the held-out recordings at half the angular resolution.
    #[arg(long)]
    half_eval: bool,
    /// Print each fold model's feature weights and thresholds.
    #[arg(long)]
    importance: bool,
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

/// A recording's scans and, for a positive bag, the annotated legs of every scan.
struct Source {
    name: String,
    scans: Vec<Scan>,
    legs: Option<Vec<Vec<[f64; 2]>>>,
}

/// The candidates of `src` varied by `aug`, labelled by the annotated legs (see the module
/// documentation); without annotations every candidate is not a leg.
fn extract(src: &Source, aug: Augmentation, cfg: &LegDetectorConfig) -> Result<Recording> {
    let mut finder = candidate_finder(cfg)?;
    let mut scans = Vec::with_capacity(src.scans.len());
    let mut people = Vec::with_capacity(src.scans.len());
    for (k, scan) in src.scans.iter().enumerate() {
        let c = finder.candidates(&aug.apply(scan)?)?;
        let legs: Vec<[f64; 2]> = src.legs.as_ref().map_or(Vec::new(), |l| {
            l[k].iter().map(|&p| aug.map_point(p)).collect()
        });
        scans.push(
            c.into_iter()
                .map(|c| {
                    if src.legs.is_none() {
                        return (c, Some(false));
                    }
                    let d = legs
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
        people.push(people_from_legs(&legs, LEG_MERGE));
    }
    let name = match aug {
        Augmentation::Identity => src.name.clone(),
        a => format!("{} {a:?}", src.name),
    };
    Ok(Recording {
        name,
        scans,
        people,
    })
}

fn sources(args: &Args) -> Result<(Vec<Source>, Vec<Source>)> {
    let mut pos = Vec::new();
    for name in POSITIVE {
        let path = args.data.join(name);
        let bag = read_bag(&path, &BagOptions::topic("/training_scan"))
            .with_context(|| format!("reading {}", path.display()))?;
        let ann = read_pose_arrays(&path, "/leg_cluster_positions")?;
        let legs = legs_for_scans(
            &bag.receive_times,
            &ann,
            &format!("{name} /leg_cluster_positions"),
        )?;
        pos.push(Source {
            name: name.to_string(),
            scans: bag.scans,
            legs: Some(legs),
        });
    }
    let mut neg = Vec::new();
    let path = args.data.join("negative_2.bag");
    for topic in LASERS {
        let scans = read_bag(&path, &BagOptions::topic(topic))
            .with_context(|| format!("reading {} {topic}", path.display()))?
            .scans;
        neg.push(Source {
            name: format!("negative_2 {topic}"),
            scans,
            legs: None,
        });
    }
    Ok((pos, neg))
}

fn load(args: &Args, cfg: &LegDetectorConfig) -> Result<(Vec<Recording>, Vec<Recording>)> {
    let (pos, neg) = sources(args)?;
    let ex = |v: &[Source]| {
        v.iter()
            .map(|s| extract(s, Augmentation::Identity, cfg))
            .collect::<Result<Vec<_>>>()
    };
    Ok((ex(&pos)?, ex(&neg)?))
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

/// The varied copies of one recording: as recorded first, then one per augmentation.
type Bag = Vec<Recording>;

/// How a model is trained.
struct Learner {
    boost: BoostConfig,
    drop: Vec<usize>,
    seed: u64,
}

/// SplitMix64 (Steele, Lea & Flood 2014): the bootstrap's random stream.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

/// The scans of `rec` a training set takes: each once for seed 0, else as many drawn with
/// replacement (the draw fixed by the seed and the recording's name).
fn drawn_scans(rec: &Recording, seed: u64) -> Vec<usize> {
    let n = rec.scans.len();
    if seed == 0 || n == 0 {
        return (0..n).collect();
    }
    let h = rec.name.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
    });
    let mut rng = SplitMix(h ^ seed.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    (0..n).map(|_| (rng.next() % n as u64) as usize).collect()
}

fn fit(recs: &[&Recording], learner: &Learner) -> Result<Boosted> {
    let mut xs: Vec<Vec<f64>> = Vec::new();
    let mut ys = Vec::new();
    for r in recs {
        for k in drawn_scans(r, learner.seed) {
            for (c, label) in &r.scans[k] {
                if let Some(l) = label {
                    let mut x = c.features.to_vec();
                    learner.drop.iter().for_each(|&f| x[f] = 0.0);
                    xs.push(x);
                    ys.push(*l);
                }
            }
        }
    }
    Ok(Boosted::train_with(&xs, &ys, &learner.boost)?)
}

/// Every candidate of a recording as a leg, scored by the model's first `rounds[r]` stumps:
/// `out[r][scan]`.
fn prefix_legs(model: &Boosted, rec: &Recording, rounds: &[usize]) -> Vec<Vec<Vec<Leg>>> {
    let mut out = vec![vec![Vec::new(); rec.scans.len()]; rounds.len()];
    for (k, s) in rec.scans.iter().enumerate() {
        for (c, _) in s {
            let (mut sum, mut total, mut t) = (0.0, 0.0, 0);
            for (r, &n) in rounds.iter().enumerate() {
                while t < n.min(model.stumps.len()) {
                    let st = &model.stumps[t];
                    let vote = if st.polarity * (c.features[st.feature] - st.threshold) > 0.0 {
                        1.0
                    } else {
                        -1.0
                    };
                    sum += st.alpha * vote;
                    total += st.alpha;
                    t += 1;
                }
                let score = if total > 0.0 { sum / total } else { 0.0 };
                out[r][k].push(Leg {
                    position: c.centroid,
                    score,
                });
            }
        }
    }
    out
}

/// A setting chosen by leave-one-bag-out, and its pooled held-out figures.
#[derive(Clone, Copy, Debug)]
struct Choice {
    rounds: usize,
    config: LegDetectorConfig,
    f1: f64,
    false_per_scan: f64,
}

/// The training set of a fold: every copy of the positive bags and lasers not held out.
fn training<'a>(
    pos: &[&'a Bag],
    neg: &[&'a Bag],
    held: usize,
    held_laser: usize,
) -> Vec<&'a Recording> {
    let p = pos
        .iter()
        .enumerate()
        .filter(|(j, _)| *j != held)
        .flat_map(|(_, b)| b.iter());
    let n = neg
        .iter()
        .enumerate()
        .filter(|(j, _)| *j != held_laser)
        .flat_map(|(_, b)| b.iter());
    p.chain(n).collect()
}

/// Pooled held-out scores of every (rounds, thresholds) pair: `[rounds][setting]`.
type Grid = Vec<Vec<(DetectionScore, DetectionScore)>>;

fn grid_scores(
    model: &Boosted,
    pos: &Recording,
    neg: &Recording,
    rounds: &[usize],
    settings: &[LegDetectorConfig],
    into: &mut Grid,
) -> Result<()> {
    let (lp, ln) = (
        prefix_legs(model, pos, rounds),
        prefix_legs(model, neg, rounds),
    );
    for r in 0..rounds.len() {
        for (k, c) in settings.iter().enumerate() {
            into[r][k].0.merge(&score_legs(&lp[r], pos, c)?);
            into[r][k].1.merge(&score_legs(&ln[r], neg, c)?);
        }
    }
    Ok(())
}

/// The best of a grid: the highest pooled F1 with at most `max_false` false people per
/// empty-room scan (the fewest false people when none qualifies); fewer rounds win ties.
fn best(grid: &Grid, rounds: &[usize], settings: &[LegDetectorConfig], max_false: f64) -> Choice {
    let mut all = Vec::new();
    for (r, row) in grid.iter().enumerate() {
        for (k, (p, n)) in row.iter().enumerate() {
            all.push(Choice {
                rounds: rounds[r],
                config: settings[k],
                f1: p.f1(),
                false_per_scan: n.false_per_scan(),
            });
        }
    }
    let ok: Vec<&Choice> = all
        .iter()
        .filter(|c| c.false_per_scan <= max_false)
        .collect();
    if ok.is_empty() {
        *all.iter()
            .min_by(|a, b| a.false_per_scan.total_cmp(&b.false_per_scan))
            .expect("a setting")
    } else {
        **ok.iter()
            .max_by(|a, b| a.f1.total_cmp(&b.f1).then(b.rounds.cmp(&a.rounds)))
            .expect("a setting")
    }
}

/// Chooses rounds and thresholds by leave-one-bag-out over `pos` (fold k holds out bag k and
/// laser k mod the number of lasers).
fn select(
    pos: &[&Bag],
    neg: &[&Bag],
    learner: &Learner,
    rounds: &[usize],
    settings: &[LegDetectorConfig],
    max_false: f64,
) -> Result<Choice> {
    let mut grid: Grid = vec![vec![Default::default(); settings.len()]; rounds.len()];
    for k in 0..pos.len() {
        let hl = k % neg.len();
        let model = fit(&training(pos, neg, k, hl), learner)?;
        grid_scores(&model, &pos[k][0], &neg[hl][0], rounds, settings, &mut grid)?;
    }
    Ok(best(&grid, rounds, settings, max_false))
}

/// Feature weights of a model: per feature the share of the stumps' weight, the number of
/// stumps and the weighted median threshold.
fn importance(model: &Boosted) -> Vec<(f64, usize, f64)> {
    let total: f64 = model.stumps.iter().map(|s| s.alpha).sum();
    (0..LEG_FEATURE_NAMES.len())
        .map(|f| {
            let mut st: Vec<(f64, f64)> = model
                .stumps
                .iter()
                .filter(|s| s.feature == f)
                .map(|s| (s.threshold, s.alpha))
                .collect();
            st.sort_by(|a, b| a.0.total_cmp(&b.0));
            let w: f64 = st.iter().map(|s| s.1).sum();
            let mut acc = 0.0;
            let median = st
                .iter()
                .find(|s| {
                    acc += s.1;
                    acc >= 0.5 * w
                })
                .map_or(f64::NAN, |s| s.0);
            (w / total, st.len(), median)
        })
        .collect()
}

/// One seed's nested estimate.
struct Nested {
    folds: Vec<(Choice, DetectionScore, DetectionScore)>,
    half: Vec<(DetectionScore, DetectionScore)>,
    fixed: (DetectionScore, DetectionScore),
    oracle: Choice,
    weights: Vec<Vec<(f64, usize, f64)>>,
}

#[allow(clippy::too_many_arguments)]
fn nested(
    pos: &[Bag],
    neg: &[Bag],
    half: Option<(&[Recording], &[Recording])>,
    learner: &Learner,
    rounds: &[usize],
    fixed_rounds: usize,
    cfg: &LegDetectorConfig,
    max_false: f64,
) -> Result<Nested> {
    let settings = grid(cfg);
    let mut all_rounds: Vec<usize> = rounds.to_vec();
    all_rounds.push(fixed_rounds);
    all_rounds.sort_unstable();
    all_rounds.dedup();
    let mut oracle: Grid = vec![vec![Default::default(); settings.len()]; all_rounds.len()];
    let mut out = Nested {
        folds: Vec::new(),
        half: Vec::new(),
        fixed: Default::default(),
        oracle: best(&oracle, &all_rounds, &settings, max_false),
        weights: Vec::new(),
    };
    let pos_refs: Vec<&Bag> = pos.iter().collect();
    let neg_refs: Vec<&Bag> = neg.iter().collect();
    for i in 0..pos.len() {
        let hl = i % neg.len();
        let inner_pos: Vec<&Bag> = pos_refs
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, b)| *b)
            .collect();
        let inner_neg: Vec<&Bag> = neg_refs
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != hl)
            .map(|(_, b)| *b)
            .collect();
        let choice = select(
            &inner_pos, &inner_neg, learner, rounds, &settings, max_false,
        )?;
        let full = fit(&training(&pos_refs, &neg_refs, i, hl), learner)?;
        let model = full.truncated(choice.rounds);
        let p = score(&model, &pos[i][0], &choice.config)?;
        let n = score(&model, &neg[hl][0], &choice.config)?;
        out.folds.push((choice, p, n));
        if let Some((hp, hn)) = half {
            out.half.push((
                score(&model, &hp[i], &choice.config)?,
                score(&model, &hn[hl], &choice.config)?,
            ));
        }
        let fixed = full.truncated(fixed_rounds);
        out.fixed.0.merge(&score(&fixed, &pos[i][0], cfg)?);
        out.fixed.1.merge(&score(&fixed, &neg[hl][0], cfg)?);
        grid_scores(
            &full,
            &pos[i][0],
            &neg[hl][0],
            &all_rounds,
            &settings,
            &mut oracle,
        )?;
        out.weights.push(importance(&model));
    }
    out.oracle = best(&oracle, &all_rounds, &settings, max_false);
    Ok(out)
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = if v.len() > 1 {
        v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    (m, var.sqrt())
}

fn parse_augment(names: &[String]) -> Result<Vec<Augmentation>> {
    names
        .iter()
        .map(|a| {
            let aug = match a.as_str() {
                "mirror" => Augmentation::Mirror,
                "half" => Augmentation::Subsample {
                    stride: 2,
                    offset: 0,
                },
                s => match s.strip_prefix("scale:") {
                    Some(f) => Augmentation::Scale(f.parse()?),
                    None => anyhow::bail!("no augmentation {s} (mirror, scale:F, half)"),
                },
            };
            aug.validate()?;
            Ok(aug)
        })
        .collect()
}

fn run_nested(args: &Args, cfg: &LegDetectorConfig, drop: &[usize]) -> Result<Option<Choice>> {
    let t0 = std::time::Instant::now();
    let augs = parse_augment(&args.augment)?;
    let (ps, ns) = sources(args)?;
    let bags = |v: &[Source]| -> Result<Vec<Bag>> {
        v.iter()
            .map(|s| {
                std::iter::once(Augmentation::Identity)
                    .chain(augs.iter().copied())
                    .map(|a| extract(s, a, cfg))
                    .collect()
            })
            .collect()
    };
    let (pos, neg) = (bags(&ps)?, bags(&ns)?);
    let halve = Augmentation::Subsample {
        stride: 2,
        offset: 0,
    };
    let half = if args.half_eval {
        let h = |v: &[Source]| -> Result<Vec<Recording>> {
            v.iter().map(|s| extract(s, halve, cfg)).collect()
        };
        Some((h(&ps)?, h(&ns)?))
    } else {
        None
    };
    eprintln!(
        "candidates extracted in {:.1} s",
        t0.elapsed().as_secs_f64()
    );
    let mut rounds = args.rounds_grid.clone();
    rounds.sort_unstable();
    rounds.dedup();
    let max_rounds = rounds
        .iter()
        .copied()
        .max()
        .unwrap_or(args.rounds)
        .max(args.rounds);
    let boost = BoostConfig {
        rounds: max_rounds,
        shrinkage: args.shrinkage,
        min_leaf: args.min_leaf,
    };
    println!(
        "\nNested leave-one-bag-out: augment {:?}, learning rate {}, min leaf {}, rounds from {:?}, \
         thresholds from the grid below, at most {} false people per empty-room scan\n",
        args.augment, args.shrinkage, args.min_leaf, rounds, args.max_false
    );
    println!("| seed | fold | rounds | leg score | single leg score | inner F1 | inner false/scan | precision | recall | F1 | empty rooms, false/scan |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let mut pooled_f1 = Vec::new();
    let mut pooled_empty = Vec::new();
    let mut fold_f1: Vec<Vec<f64>> = vec![Vec::new(); pos.len()];
    let mut half_f1 = Vec::new();
    let mut summary = Vec::new();
    for &seed in &args.seeds {
        let learner = Learner {
            boost,
            drop: drop.to_vec(),
            seed,
        };
        let t = std::time::Instant::now();
        let hv = half.as_ref().map(|(a, b)| (a.as_slice(), b.as_slice()));
        let r = nested(
            &pos,
            &neg,
            hv,
            &learner,
            &rounds,
            args.rounds,
            cfg,
            args.max_false,
        )?;
        let (mut pp, mut pn) = (DetectionScore::default(), DetectionScore::default());
        for (i, (c, p, n)) in r.folds.iter().enumerate() {
            println!(
                "| {seed} | {} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
                i + 1,
                c.rounds,
                c.config.leg_score,
                c.config.single_leg_score,
                c.f1,
                c.false_per_scan,
                p.precision(),
                p.recall(),
                p.f1(),
                n.false_per_scan()
            );
            pp.merge(p);
            pn.merge(n);
            fold_f1[i].push(p.f1());
        }
        println!(
            "| {seed} | pooled | | | | | | {:.3} | {:.3} | **{:.3}** | {:.3} |",
            pp.precision(),
            pp.recall(),
            pp.f1(),
            pn.false_per_scan()
        );
        pooled_f1.push(pp.f1());
        pooled_empty.push(pn.false_per_scan());
        let (hp, hn) = r.half.iter().fold(
            (DetectionScore::default(), DetectionScore::default()),
            |(mut a, mut b), (p, n)| {
                a.merge(p);
                b.merge(n);
                (a, b)
            },
        );
        if !r.half.is_empty() {
            half_f1.push(hp.f1());
        }
        summary.push(format!(
            "seed {seed}: nested {:.3} (empty {:.3}); fixed {} rounds at leg score {} / lone leg {}: {:.3} (empty {:.3}); \
             best on the outer folds themselves: {:.3} (empty {:.3}; {} rounds, {} / {}){}; {:.0} s",
            pp.f1(),
            pn.false_per_scan(),
            args.rounds,
            cfg.leg_score,
            cfg.single_leg_score,
            r.fixed.0.f1(),
            r.fixed.1.false_per_scan(),
            r.oracle.f1,
            r.oracle.false_per_scan,
            r.oracle.rounds,
            r.oracle.config.leg_score,
            r.oracle.config.single_leg_score,
            if r.half.is_empty() {
                String::new()
            } else {
                format!(
                    "; half resolution: F1 {:.3} (P {:.3}, R {:.3}), empty {:.3}",
                    hp.f1(),
                    hp.precision(),
                    hp.recall(),
                    hn.false_per_scan()
                )
            },
            t.elapsed().as_secs_f64()
        ));
        if args.importance {
            println!("\nSeed {seed}: feature weight share (stumps, weighted median threshold) per fold model\n");
            println!("| feature | fold 1 | fold 2 | fold 3 | fold 4 |");
            println!("|---|---|---|---|---|");
            for (f, name) in LEG_FEATURE_NAMES.iter().enumerate() {
                let cells: Vec<String> = r
                    .weights
                    .iter()
                    .map(|w| format!("{:.3} ({}, {:.3})", w[f].0, w[f].1, w[f].2))
                    .collect();
                println!("| {name} | {} |", cells.join(" | "));
            }
            println!();
        }
    }
    println!();
    for s in &summary {
        println!("{s}");
    }
    let (m, sd) = mean_sd(&pooled_f1);
    let (em, _) = mean_sd(&pooled_empty);
    println!(
        "\nover seeds {:?}: pooled nested F1 {m:.3} ± {sd:.3} (min {:.3}, max {:.3}); empty rooms {em:.3} false people per scan (max {:.3})",
        args.seeds,
        pooled_f1.iter().copied().fold(f64::INFINITY, f64::min),
        pooled_f1.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        pooled_empty.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    let per_fold: Vec<String> = fold_f1
        .iter()
        .map(|v| {
            let (m, sd) = mean_sd(v);
            format!("{m:.3} ± {sd:.3}")
        })
        .collect();
    let means: Vec<f64> = fold_f1.iter().map(|v| mean_sd(v).0).collect();
    println!(
        "per fold over seeds: {}; spread over folds (sd of the fold means) {:.3}",
        per_fold.join(", "),
        mean_sd(&means).1
    );
    if !half_f1.is_empty() {
        let (m, sd) = mean_sd(&half_f1);
        println!("half angular resolution, held out: F1 {m:.3} ± {sd:.3}");
    }
    eprintln!("nested estimate in {:.1} s", t0.elapsed().as_secs_f64());
    if args.out.is_none() {
        return Ok(None);
    }
    // The shipped model's settings: the same selection on all four bags.
    let learner = Learner {
        boost,
        drop: drop.to_vec(),
        seed: 0,
    };
    let pr: Vec<&Bag> = pos.iter().collect();
    let nr: Vec<&Bag> = neg.iter().collect();
    let c = select(&pr, &nr, &learner, &rounds, &grid(cfg), args.max_false)?;
    println!(
        "\nChosen on all four bags: {} rounds, leg score {}, lone leg {} (pooled folds F1 {:.3}, empty rooms {:.3})",
        c.rounds, c.config.leg_score, c.config.single_leg_score, c.f1, c.false_per_scan
    );
    let all: Vec<&Recording> = pos.iter().flatten().chain(neg.iter().flatten()).collect();
    let model = fit(&all, &learner)?.truncated(c.rounds);
    header("Trained on everything, scored on its own training recordings");
    for r in &pos {
        row(&r[0].name, &score(&model, &r[0], &c.config)?);
    }
    for r in &neg {
        row(&r[0].name, &score(&model, &r[0], &c.config)?);
    }
    let out = args.out.as_ref().expect("checked");
    let mut cmd = format!(
        "`cargo run --release --example train_legs -- --nested --rounds-grid {}",
        rounds
            .iter()
            .map(|r| r.to_string())
            .collect::<Vec<_>>()
            .join(",")
    );
    if !args.augment.is_empty() {
        cmd += &format!(" --augment {}", args.augment.join(","));
    }
    if args.shrinkage != 1.0 {
        cmd += &format!(" --shrinkage {}", args.shrinkage);
    }
    if args.min_leaf != 1 {
        cmd += &format!(" --min-leaf {}", args.min_leaf);
    }
    if !args.drop_features.is_empty() {
        cmd += &format!(" --drop-features {}", args.drop_features.join(","));
    }
    cmd += &format!(" --max-false {} --out {}`", args.max_false, out.display());
    let augmented = if augs.is_empty() {
        String::new()
    } else {
        format!(" with varied copies ({})", args.augment.join(", "))
    };
    let dropped = if args.drop_features.is_empty() {
        String::new()
    } else {
        format!(", without {}", args.drop_features.join(", "))
    };
    let m = LegModel {
        description: format!(
            "AdaBoost, {} decision stumps (learning rate {}, at least {} samples a side) on the leg \
             candidates of positive_{{1,2,3,4}}_extracted.bag and negative_2.bag (all lasers){augmented}{dropped}; \
             rounds and thresholds chosen by leave-one-bag-out; {cmd}",
            model.stumps.len(),
            args.shrinkage,
            args.min_leaf
        ),
        features: LEG_FEATURE_NAMES.iter().map(|s| s.to_string()).collect(),
        config: c.config,
        classifier: model,
    };
    std::fs::write(out, m.to_json() + "\n")
        .with_context(|| format!("writing {}", out.display()))?;
    eprintln!("wrote {}", out.display());
    Ok(Some(c))
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
    if args.nested {
        run_nested(&args, &cfg, &drop)?;
        return Ok(());
    }
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
