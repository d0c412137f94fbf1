//! A short drive past the parked rows of `StreetConfig::parked_rows`, written in the KITTI
//! tracking layout: some of its parked cars are labelled largely occluded (level 2), the
//! labels read back with the levels written, and the tracking evaluation's Car+Van recall
//! by occlusion level and range adds up to the whole, with the found labels those of the
//! results given.

use smc_lmb::kitti::{ObjectType, TrackingSequence};
use smc_lmb::metrics::recall::{RecallBreakdown, Tally};
use smc_lmb::pipeline::kitti_tracking_eval::{evaluate_kitti_tracking, EvalClass, KittiEvalConfig};
use smc_lmb::sim::street::{occlusion_level, write_tracking_sequence, ObjectKind, StreetConfig};

fn sum(t: &[Tally]) -> Tally {
    t.iter().fold(Tally::default(), |a, b| Tally {
        hits: a.hits + b.hits,
        total: a.total + b.total,
    })
}

#[test]
fn parked_rows_drive_has_largely_occluded_cars_and_the_breakdown_adds_up() {
    let dir = tempfile::tempdir().unwrap();
    let config = StreetConfig::parked_rows();
    let frames = 10;
    let w = write_tracking_sequence(dir.path(), &config, frames, 11, 0, |_| {}).unwrap();
    let seq = TrackingSequence::open(dir.path(), 0).unwrap();
    let labels = seq.labels().unwrap();
    assert_eq!(labels, w.labels);

    // The truth's levels follow from its ray counts, and the labels carry them.
    let mut parked_levels = [0usize; 4];
    for o in &w.truth.objects {
        for s in o.states.iter().filter(|s| s.points > 0) {
            assert_eq!(s.occluded, occlusion_level(s.hidden_share()));
            let l = labels
                .iter()
                .find(|l| l.frame == s.frame && l.track_id == o.id as i64)
                .unwrap();
            assert_eq!(l.occluded, s.occluded);
            if o.kind == ObjectKind::ParkedCar {
                parked_levels[s.occluded as usize] += 1;
            }
        }
    }
    assert!(parked_levels[2] > 0, "{parked_levels:?}");
    assert!(parked_levels[0] > 0, "{parked_levels:?}");

    // Results: the labels of even track id, exactly where they are.
    let results: Vec<_> = labels
        .iter()
        .filter(|l| l.is_object() && l.track_id % 2 == 0)
        .copied()
        .collect();
    let e = evaluate_kitti_tracking(&labels, &results, frames, &KittiEvalConfig::bev(2.0), None)
        .unwrap();
    let car_van = e
        .classes
        .iter()
        .find(|c| c.class == EvalClass::CarVan)
        .unwrap();
    let r: &RecallBreakdown = car_van.recall_breakdown.as_ref().unwrap();
    // The reference, counted from the labels: cars and vans of levels 0–2 within 40 m of the
    // camera, found when their id is even.
    let mut expected = Tally::default();
    let mut by_level = [Tally::default(); 4];
    for l in &labels {
        let range = l.location[0].hypot(l.location[2]);
        if matches!(l.object_type, ObjectType::Car | ObjectType::Van)
            && l.occluded <= 2
            && range <= 40.0
        {
            let found = l.track_id % 2 == 0;
            expected.add(found);
            by_level[l.occluded as usize].add(found);
        }
    }
    assert_eq!(r.recall, expected);
    assert_eq!(r.by_occlusion, by_level);
    assert!(r.by_occlusion[2].total > 0, "{r:?}");
    assert_eq!(sum(&r.by_occlusion), r.recall);
    assert_eq!(sum(&r.by_range), r.recall);
    assert!(r.recall.total <= car_van.truth_objects);
}
