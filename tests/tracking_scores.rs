//! Our KITTI tracking scores against TrackEval's: every tracker under
//! `tests/data/trackeval/` (derived from KITTI's real labels of sequence 0000) scored in the
//! 2-D image-box IoU mode with KITTI's preprocessing, every number compared to the one
//! TrackEval's `Kitti2DBox` wrote to `expected.json` (see that folder's README).

use serde_json::Value;
use smc_lmb::kitti::read_tracking_labels;
use smc_lmb::pipeline::kitti_tracking_eval::{
    evaluate_kitti_tracking, ClassScores, EvalClass, KittiEvalConfig,
};
use std::path::{Path, PathBuf};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/trackeval")
}

/// Our value of TrackEval's field `name`.
fn ours(c: &ClassScores, name: &str) -> f64 {
    let (h, cl, id) = (&c.scores.hota, &c.scores.clear, &c.scores.identity);
    match name {
        "HOTA" => h.hota,
        "DetA" => h.det_a,
        "AssA" => h.ass_a,
        "LocA" => h.loc_a,
        "DetRe" => h.det_re,
        "DetPr" => h.det_pr,
        "AssRe" => h.ass_re,
        "AssPr" => h.ass_pr,
        "HOTA(0)" => h.hota_0,
        "LocA(0)" => h.loc_a_0,
        "MOTA" => cl.mota,
        "MOTP" => cl.motp,
        "IDSW" => cl.idsw as f64,
        "Frag" => cl.frag as f64,
        "MT" => cl.mt as f64,
        "PT" => cl.pt as f64,
        "ML" => cl.ml as f64,
        "CLR_TP" => cl.tp as f64,
        "CLR_FN" => cl.fn_count as f64,
        "CLR_FP" => cl.fp as f64,
        "IDF1" => id.idf1,
        "IDP" => id.idp,
        "IDR" => id.idr,
        "IDTP" => id.idtp as f64,
        "IDFN" => id.idfn as f64,
        "IDFP" => id.idfp as f64,
        other => panic!("unknown field {other}"),
    }
}

#[test]
fn tracking_scores_match_trackeval_kitti_2d_box() {
    let dir = fixtures();
    let text = std::fs::read_to_string(dir.join("expected.json")).expect("expected.json");
    let expected: Value = serde_json::from_str(&text).expect("expected.json parses");
    let frames = expected["frames"].as_u64().expect("frames") as usize;
    let trackers = expected["trackers"].as_object().expect("trackers");
    assert_eq!(trackers.len(), 6);
    let mut compared = 0;
    let mut failures = Vec::new();
    for (tracker, per_seq) in trackers {
        for (seq, per_class) in per_seq.as_object().expect("sequences") {
            let truth = read_tracking_labels(dir.join(format!("gt/label_02/{seq}.txt"))).unwrap();
            let results =
                read_tracking_labels(dir.join(format!("trackers/{tracker}/data/{seq}.txt")))
                    .unwrap();
            let eval =
                evaluate_kitti_tracking(&truth, &results, frames, &KittiEvalConfig::iou_2d(), None)
                    .unwrap();
            // TrackEval scores KITTI's two classes; the groups after them have no reference.
            for c in eval
                .classes
                .iter()
                .filter(|c| EvalClass::ALL.contains(&c.class))
            {
                let key = match c.class {
                    EvalClass::Car => "car",
                    EvalClass::Pedestrian => "pedestrian",
                    EvalClass::CarVan | EvalClass::RoadUser => unreachable!("filtered out"),
                };
                let exp = per_class[key].as_object().expect("class");
                for (field, v) in exp {
                    if field == "HOTA_alpha" {
                        let alphas = v.as_array().expect("HOTA per α");
                        assert_eq!(alphas.len(), c.scores.hota.per_alpha.len());
                        for (a, p) in alphas.iter().zip(&c.scores.hota.per_alpha) {
                            let e = a.as_f64().unwrap();
                            if (p.hota - e).abs() > 1e-9 {
                                failures.push(format!(
                                    "{tracker} {seq} {key} HOTA at α {}: ours {} TrackEval {e}",
                                    p.alpha, p.hota
                                ));
                            }
                            compared += 1;
                        }
                        continue;
                    }
                    let e = v.as_f64().expect("number");
                    let o = ours(c, field);
                    if (o - e).abs() > 1e-9 {
                        failures.push(format!(
                            "{tracker} {seq} {key} {field}: ours {o} TrackEval {e}"
                        ));
                    }
                    compared += 1;
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} differences:\n{}",
        failures.len(),
        failures.join("\n")
    );
    // 6 trackers × 2 sequences × 2 classes × (26 fields + 19 α values).
    assert_eq!(compared, 6 * 2 * 2 * (26 + 19));
}

#[test]
fn tracking_scores_of_real_truth_against_itself_are_perfect_in_bev_mode() {
    // KITTI's labels of sequence 0000 scored against themselves in the bird's-eye mode: every
    // counted Pedestrian is found with similarity 1 (the truth has no Car).
    let truth = read_tracking_labels(fixtures().join("gt/label_02/0000.txt")).unwrap();
    let eval =
        evaluate_kitti_tracking(&truth, &truth, 50, &KittiEvalConfig::bev(2.0), None).unwrap();
    let ped = &eval.classes[1];
    assert_eq!(ped.class, EvalClass::Pedestrian);
    // 6 Pedestrian lines, 2 of them truncated (level 1 or 2) and so not counted.
    assert_eq!(ped.truth_objects, 4);
    assert!((ped.scores.hota.hota - 1.0).abs() < 1e-12);
    assert!((ped.scores.clear.motp - 1.0).abs() < 1e-12);
    let car = &eval.classes[0];
    assert_eq!((car.truth_objects, car.tracker_objects), (0, 0));
}
