//! The legs front end on the annotated `leg_tracker` recordings of
//! `../shared/data/laser2d/leg_annotated`, scored by the rules of
//! `pipeline::people_tracking::score`, against the targets of issue 22: per-scan F1 ≥ 0.8 for
//! the detector and for the tracker's people, ≤ 0.05 false people per scan in the empty rooms
//! of `negative_2.bag`. The numbers these bounds are checked against are in
//! `docs/people_real.md`. The held-out tests retrain the classifier leaving each bag out.

mod common;

use smc_lmb::laser2d::boost::Boosted;
use smc_lmb::laser2d::legs::{LegDetector, LegModel};
use smc_lmb::laser2d::{read_bag, read_pose_arrays, BagOptions, Scan};
use smc_lmb::pipeline::people_tracking::front_end::FrontEnd;
use smc_lmb::pipeline::people_tracking::score::{
    legs_for_scans, people_from_legs, truth_for_scans, DetectionScore, TrackScore,
    FIRST_SCORED_SCAN, LEG_MERGE,
};
use smc_lmb::pipeline::people_tracking::{config_for_scans, track_scans_with_model, PeopleRun};
use std::path::PathBuf;

const F1_TARGET: f64 = 0.8;
const EMPTY_ROOM_TARGET: f64 = 0.05;
const LASERS: [&str; 3] = ["/left_scan", "/right_scan", "/rear_scan"];

fn bag(name: &str) -> Option<PathBuf> {
    common::shared_laser2d(&format!("leg_annotated/{name}"))
}

fn positive(i: usize) -> Option<PathBuf> {
    bag(&format!("positive_{i}_extracted.bag"))
}

/// Scans and per-scan people of a positive bag.
fn annotated(path: &PathBuf) -> (Vec<Scan>, Vec<Vec<[f64; 2]>>) {
    let b = read_bag(path, &BagOptions::topic("/training_scan")).unwrap();
    let ann = read_pose_arrays(path, "/leg_cluster_positions").unwrap();
    let truth = truth_for_scans(&b.receive_times, &ann, "test").unwrap();
    (b.scans, truth)
}

fn run(scans: &[Scan], model: Option<LegModel>) -> PeopleRun {
    run_seeded(scans, model, None)
}

/// [`run`] with the tracker's random stream seeded by `seed` (None: the default seed).
fn run_seeded(scans: &[Scan], model: Option<LegModel>, seed: Option<u64>) -> PeopleRun {
    let mut cfg = config_for_scans(scans, 0.03, 0.005, 15.0, [0.0, 0.0]).unwrap();
    if let Some(s) = seed {
        cfg.filter.seed = s;
    }
    track_scans_with_model(scans, cfg, FrontEnd::Legs, model).unwrap()
}

/// (front end, tracker) scores of a run.
fn score(run: &PeopleRun, truth: &[Vec<[f64; 2]>]) -> (DetectionScore, DetectionScore) {
    let mut d = DetectionScore::default();
    let mut t = TrackScore::default();
    for (s, people) in run.scans.iter().zip(truth) {
        let scored = s.scan >= FIRST_SCORED_SCAN;
        if scored {
            d.add_scan(people, &s.detections).unwrap();
        }
        // The pose is the detector's chain of alignments: back into the scan's frame.
        let [x, y, th] = s.pose.unwrap();
        let (sn, cs) = th.sin_cos();
        let est: Vec<_> = s
            .people
            .iter()
            .filter(|p| p.visibility >= 0.5)
            .map(|p| {
                let (dx, dy) = (p.position[0] - x, p.position[1] - y);
                (p.label, [cs * dx + sn * dy, -sn * dx + cs * dy])
            })
            .collect();
        t.add_scan(people, &est, scored).unwrap();
    }
    (d, t.summary().detection)
}

/// Pooled (front end, tracker) scores of the shipped model on the four bags, `None` without
/// the data.
fn shipped_on_the_shared_recordings() -> Option<(DetectionScore, DetectionScore)> {
    let (mut d, mut t) = (DetectionScore::default(), DetectionScore::default());
    for i in 1..=4 {
        let (scans, truth) = annotated(&positive(i)?);
        let (di, ti) = score(&run(&scans, None), &truth);
        d.merge(&di);
        t.merge(&ti);
    }
    Some((d, t))
}

#[test]
fn shipped_detector_reaches_the_f1_target_on_the_shared_recordings() {
    // The four bags are the model's training data: this checks the shipped model and the
    // pipeline end to end, not generalisation (see the held-out test below).
    let Some((d, _)) = shipped_on_the_shared_recordings() else {
        return;
    };
    assert!(d.f1() >= F1_TARGET, "detector F1 {:.3}", d.f1());
}

#[test]
fn shipped_tracker_reaches_the_f1_target_on_the_shared_recordings() {
    let Some((_, t)) = shipped_on_the_shared_recordings() else {
        return;
    };
    assert!(t.f1() >= F1_TARGET, "tracker F1 {:.3}", t.f1());
}

#[test]
fn a_missing_annotation_topic_names_the_bag_and_topic() {
    let Some(p) = bag("negative_2.bag") else {
        return;
    };
    let e = read_pose_arrays(&p, "/leg_cluster_positions")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("negative_2.bag") && e.contains("/leg_cluster_positions"),
        "{e}"
    );
    // One annotation short of the scans: an error naming the source.
    let Some(p) = positive(2) else { return };
    let b = read_bag(&p, &BagOptions::topic("/training_scan")).unwrap();
    let ann = read_pose_arrays(&p, "/leg_cluster_positions").unwrap();
    let e = truth_for_scans(
        &b.receive_times,
        &ann[1..],
        "positive_2 /leg_cluster_positions",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("positive_2 /leg_cluster_positions"), "{e}");
}

/// The rate is pooled over the tracker's seeds 0–3: one run's count moves by a track or so
/// with the seed (the shipped model before the 1 % pruning of faint tracks, `/rear_scan`:
/// 0.000, 0.000, 0.000, 0.085 false people per scan with seeds 0–3; with it 0.000 on every
/// laser and seed 0–5; docs/people_real.md).
#[test]
fn empty_rooms_stay_empty() {
    let Some(p) = bag("negative_2.bag") else {
        return;
    };
    for topic in LASERS {
        let scans = read_bag(&p, &BagOptions::topic(topic)).unwrap().scans;
        let truth = vec![Vec::new(); scans.len()];
        let mut t = DetectionScore::default();
        for seed in 0..4 {
            t.merge(&score(&run_seeded(&scans, None, Some(seed)), &truth).1);
        }
        assert!(
            t.false_per_scan() <= EMPTY_ROOM_TARGET,
            "{topic}: {:.3} false people per scan",
            t.false_per_scan()
        );
    }
}

/// Detector and tracker scores pooled over the four bags, each scored by a model trained
/// without it (leave one bag out, as `examples/train_legs.rs` does, with all three lasers of
/// `negative_2.bag` as negatives); the tracker pooled over `seeds` too.
fn held_out_scores(seeds: std::ops::Range<u64>) -> Option<(DetectionScore, DetectionScore)> {
    let mut bags = Vec::new();
    for i in 1..=4 {
        let p = positive(i)?;
        let b = read_bag(&p, &BagOptions::topic("/training_scan")).unwrap();
        let ann = read_pose_arrays(&p, "/leg_cluster_positions").unwrap();
        let legs = legs_for_scans(&b.receive_times, &ann, "test").unwrap();
        bags.push((b.scans, legs));
    }
    let neg = bag("negative_2.bag")?;
    let shipped = LegModel::shipped().unwrap();
    let finder = {
        let mut m = shipped.clone();
        m.classifier = Boosted::default();
        move || LegDetector::new(m.clone()).unwrap()
    };
    let mut negatives = Vec::new();
    for topic in LASERS {
        let mut f = finder();
        for s in read_bag(&neg, &BagOptions::topic(topic)).unwrap().scans {
            negatives.extend(
                f.candidates(&s)
                    .unwrap()
                    .into_iter()
                    .map(|c| c.features.to_vec()),
            );
        }
    }
    let (mut d, mut t) = (DetectionScore::default(), DetectionScore::default());
    for held in 0..bags.len() {
        let (mut xs, mut ys) = (negatives.clone(), vec![false; negatives.len()]);
        for (j, (scans, legs)) in bags.iter().enumerate() {
            if j == held {
                continue;
            }
            let mut f = finder();
            for (s, l) in scans.iter().zip(legs) {
                for c in f.candidates(s).unwrap() {
                    let dist = l
                        .iter()
                        .map(|a| (a[0] - c.centroid[0]).hypot(a[1] - c.centroid[1]))
                        .fold(f64::INFINITY, f64::min);
                    if !(0.25..0.6).contains(&dist) {
                        xs.push(c.features.to_vec());
                        ys.push(dist < 0.25);
                    }
                }
            }
        }
        let model = LegModel {
            classifier: Boosted::train(&xs, &ys, 400).unwrap(),
            ..shipped.clone()
        };
        let (scans, legs) = &bags[held];
        let truth: Vec<_> = legs
            .iter()
            .map(|l| people_from_legs(l, LEG_MERGE))
            .collect();
        for seed in seeds.clone() {
            let (di, ti) = score(&run_seeded(scans, Some(model.clone()), Some(seed)), &truth);
            if seed == seeds.start {
                d.merge(&di);
            }
            t.merge(&ti);
        }
    }
    Some((d, t))
}

#[test]
fn held_out_detector_reaches_the_f1_target() {
    let Some((d, _)) = held_out_scores(0..1) else {
        return;
    };
    assert!(d.f1() >= F1_TARGET, "held-out detector F1 {:.3}", d.f1());
}

/// Pooled over twelve tracker seeds: one seed moves a bag's F1 by several hundredths, four
/// seeds pooled still by ±0.03 (0.840 with seeds 0–11 here; the folds of `train_legs`, which
/// keep one laser of `negative_2.bag` out, 0.794–0.855 per four seeds, 0.826 with 1–12).
#[test]
fn held_out_tracker_reaches_the_f1_target() {
    let Some((_, t)) = held_out_scores(0..12) else {
        return;
    };
    assert!(t.f1() >= F1_TARGET, "held-out tracker F1 {:.3}", t.f1());
}
