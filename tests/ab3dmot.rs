//! Stories of the AB3DMOT baseline on hand-made box sequences: straight runs at constant
//! speed, crossing objects, missed detections, confirmation, flipped headings, classes and
//! bad input. Truth (positions, velocities) is written down from the construction of each
//! scene, never taken from the tracker.

use nalgebra::Point3;
use smc_lmb::geometry::box3::Box3;
use smc_lmb::trackers::ab3dmot::{Ab3dmot, Ab3dmotConfig, Affinity, BoxDetection, TrackedBox};
use std::collections::BTreeSet;
use std::f64::consts::PI;

const CAR: [f64; 3] = [4.0, 1.8, 1.5];

fn bx(x: f64, y: f64, yaw: f64, size: [f64; 3]) -> Box3 {
    Box3 {
        center: Point3::new(x, y, -0.9),
        size,
        yaw,
    }
}

fn car(x: f64, y: f64, yaw: f64) -> BoxDetection {
    BoxDetection::new(bx(x, y, yaw, CAR), "Car", 0.8)
}

/// A fixed, zero-mean, bounded wobble (±`a`) for frame `k` and stream `s`.
fn wobble(k: usize, s: usize, a: f64) -> f64 {
    a * ((k as f64) * 2.399 + (s as f64) * 1.3).sin()
}

fn tracker() -> Ab3dmot {
    Ab3dmot::new(Ab3dmotConfig::default()).unwrap()
}

/// The reported track nearest to (x, y) in bird's eye view, within 1 m.
fn near(out: &[TrackedBox], x: f64, y: f64) -> Option<&TrackedBox> {
    out.iter()
        .map(|t| ((t.bbox.center.x - x).hypot(t.bbox.center.y - y), t))
        .filter(|(d, _)| *d < 1.0)
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, t)| t)
}

#[test]
fn straight_runs_keep_one_id_each_and_velocities_converge() {
    // Three cars: per frame (0.1 s) they move by (1.5, 0), (−1.0, 0.3) and (0, 0.8) metres,
    // i.e. at (15, 0), (−10, 3) and (0, 8) m/s. Detections wobble by up to 10 cm.
    let starts = [(0.0, 0.0), (60.0, 10.0), (20.0, -30.0)];
    let steps = [(1.5, 0.0), (-1.0, 0.3), (0.0, 0.8)];
    let truth_velocity = [(15.0, 0.0), (-10.0, 3.0), (0.0, 8.0)];
    let mut trk = tracker();
    let mut ids: Vec<BTreeSet<u64>> = vec![BTreeSet::new(); 3];
    let mut last = Vec::new();
    for k in 0..40 {
        let truth: Vec<(f64, f64)> = (0..3)
            .map(|i| {
                (
                    starts[i].0 + steps[i].0 * k as f64,
                    starts[i].1 + steps[i].1 * k as f64,
                )
            })
            .collect();
        let dets: Vec<BoxDetection> = truth
            .iter()
            .enumerate()
            .map(|(i, &(x, y))| {
                let yaw = steps[i].1.atan2(steps[i].0);
                car(
                    x + wobble(k, 2 * i, 0.1),
                    y + wobble(k, 2 * i + 1, 0.1),
                    yaw,
                )
            })
            .collect();
        let out = trk.step(&dets).unwrap();
        if k < 2 {
            assert!(out.is_empty(), "frame {k}: reported before 3 hits");
            continue;
        }
        assert_eq!(out.len(), 3, "frame {k}");
        for (i, &(x, y)) in truth.iter().enumerate() {
            let t = near(&out, x, y).unwrap_or_else(|| panic!("frame {k}: car {i} lost"));
            ids[i].insert(t.id);
            assert!(t.detected);
        }
        last = out;
    }
    for (i, set) in ids.iter().enumerate() {
        assert_eq!(set.len(), 1, "car {i} had ids {set:?}");
    }
    for (i, &(vx, vy)) in truth_velocity.iter().enumerate() {
        let id = *ids[i].iter().next().unwrap();
        let t = last.iter().find(|t| t.id == id).unwrap();
        let err = (t.velocity[0] - vx).hypot(t.velocity[1] - vy);
        assert!(
            err < 0.3,
            "car {i}: velocity {:?}, truth ({vx}, {vy})",
            t.velocity
        );
        assert!(t.velocity[2].abs() < 0.3, "car {i}: {:?}", t.velocity);
        assert_eq!(t.hits, 40);
    }
}

#[test]
fn crossing_objects_keep_their_ids() {
    // A drives along +x, B along +y; both pass (0, 0) at frame 15, 1 m per frame. C and D meet
    // head on in lanes 1 m apart (their boxes overlap when they pass), at x = 0 in frame 15.
    let mut trk = tracker();
    let mut seen: [BTreeSet<u64>; 4] = Default::default();
    for k in 0..30 {
        let s = k as f64 - 15.0;
        let truth = [
            (s, 0.0, 0.0),
            (0.0, s, PI / 2.0),
            (s, 30.0, 0.0),
            (-s, 31.0, PI),
        ];
        let dets: Vec<BoxDetection> = truth.iter().map(|&(x, y, yaw)| car(x, y, yaw)).collect();
        let out = trk.step(&dets).unwrap();
        if k < 2 {
            continue;
        }
        for (i, &(x, y, _)) in truth.iter().enumerate() {
            // At the crossing A and B share a centre: tell them apart by heading.
            let t = out
                .iter()
                .filter(|t| (t.bbox.center.x - x).hypot(t.bbox.center.y - y) < 1.0)
                .min_by(|a, b| {
                    let da = (a.bbox.yaw - truth[i].2).sin().abs();
                    let db = (b.bbox.yaw - truth[i].2).sin().abs();
                    da.total_cmp(&db)
                })
                .unwrap_or_else(|| panic!("frame {k}: object {i} lost"));
            seen[i].insert(t.id);
        }
    }
    for (i, s) in seen.iter().enumerate() {
        assert_eq!(s.len(), 1, "object {i} had ids {s:?}");
    }
    let all: BTreeSet<u64> = seen.iter().flatten().copied().collect();
    assert_eq!(all.len(), 4);
}

/// Runs one car along x at 1 m per frame for 12 frames with the detections of `missed`
/// frames left out; returns the reported tracks of every frame.
fn run_with_gaps(missed: &[usize]) -> Vec<Vec<TrackedBox>> {
    let mut trk = tracker();
    (0..12)
        .map(|k| {
            let dets = if missed.contains(&k) {
                vec![]
            } else {
                vec![car(k as f64, 0.0, 0.0)]
            };
            trk.step(&dets).unwrap()
        })
        .collect()
}

#[test]
fn a_target_missed_once_survives() {
    let frames = run_with_gaps(&[6]);
    let ids: BTreeSet<u64> = frames.iter().flatten().map(|t| t.id).collect();
    assert_eq!(ids.len(), 1, "{ids:?}");
    // Frame 6 reports the coasted track at its predicted place, x = 6.
    assert_eq!(frames[6].len(), 1);
    let t = &frames[6][0];
    assert!(!t.detected);
    assert!((t.bbox.center.x - 6.0).abs() < 0.1, "{}", t.bbox.center.x);
    assert!(frames[7][0].detected);
    assert_eq!(frames[7][0].hits, 7);
}

#[test]
fn a_target_missed_three_times_dies() {
    let frames = run_with_gaps(&[6, 7, 8]);
    // Reported at frames 2..=5 as id 0; the coasted frame 6 is reported too (missed once), then
    // nothing until the new track has 3 hits (frames 9, 10, 11).
    for (k, f) in frames.iter().enumerate() {
        let want = match k {
            2..=6 => Some(0),
            11 => Some(1),
            _ => None,
        };
        assert_eq!(f.first().map(|t| t.id), want, "frame {k}");
        assert!(f.len() <= 1);
    }
    // max_age = 2: missed twice is already dead.
    let frames = run_with_gaps(&[6, 7]);
    assert_eq!(frames[7].len(), 0);
    assert_eq!(frames[10].first().map(|t| t.id), Some(1));
}

#[test]
fn birth_only_after_three_hits() {
    let mut trk = tracker();
    // One car from frame 0; another appears at frame 4 and is seen on alternate frames only
    // from frame 10 on (it dies between its detections and never gets 3 hits).
    for k in 0..16usize {
        let mut dets = vec![car(k as f64, 0.0, 0.0)];
        if (4..7).contains(&k) {
            dets.push(car(50.0, 20.0, 0.0));
        }
        if k >= 10 && k % 3 == 1 {
            dets.push(car(-40.0, -20.0, 0.0));
        }
        let out = trk.step(&dets).unwrap();
        let first = near(&out, k as f64, 0.0).is_some();
        assert_eq!(first, k >= 2, "frame {k}");
        let second = near(&out, 50.0, 20.0).is_some();
        assert_eq!(second, (6..=7).contains(&k), "frame {k}");
        assert!(near(&out, -40.0, -20.0).is_none(), "frame {k}");
        for t in &out {
            assert!(t.hits >= 3);
        }
    }
    // The authors' start-up rule reports everything in the first min_hits frames.
    let mut trk = Ab3dmot::new(Ab3dmotConfig {
        report_first_frames: true,
        ..Ab3dmotConfig::default()
    })
    .unwrap();
    assert_eq!(trk.step(&[car(0.0, 0.0, 0.0)]).unwrap().len(), 1);
}

#[test]
fn a_flipped_heading_does_not_flip_the_track() {
    let mut trk = tracker();
    let heading: f64 = 0.3;
    let (s, c) = heading.sin_cos();
    for k in 0..20usize {
        // Frames 8 and 13: the detector reports the same box with its heading turned by π.
        let yaw = if k == 8 || k == 13 {
            heading - PI
        } else {
            heading
        };
        let d = k as f64;
        let out = trk.step(&[car(d * c, d * s, yaw)]).unwrap();
        for t in &out {
            assert_eq!(t.id, 0);
            assert!(
                (t.bbox.yaw - heading).abs() < 1e-9,
                "frame {k}: {}",
                t.bbox.yaw
            );
            assert!(t.bbox.yaw > -PI && t.bbox.yaw <= PI);
        }
    }
    // Near ±π the state heading stays wrapped and continuous.
    let mut trk = tracker();
    for k in 0..10usize {
        let yaw = if k % 2 == 0 { PI - 0.01 } else { -PI + 0.01 };
        let out = trk.step(&[car(-(k as f64), 0.0, yaw)]).unwrap();
        for t in &out {
            assert_eq!(t.id, 0);
            assert!(t.bbox.yaw > -PI && t.bbox.yaw <= PI);
            assert!((t.bbox.yaw.abs() - PI).abs() < 0.02, "{}", t.bbox.yaw);
        }
    }
}

#[test]
fn classes_are_tracked_apart() {
    // A pedestrian box inside a car box: 3-D IoU > 0.01, but they never share a track.
    let mut trk = tracker();
    for k in 0..6usize {
        let x = 0.5 * k as f64;
        let ped = BoxDetection::new(bx(x, 0.0, 0.0, [0.8, 0.8, 1.7]), "Pedestrian", 0.6);
        let out = trk.step(&[car(x, 0.0, 0.0), ped]).unwrap();
        if k >= 2 {
            assert_eq!(out.len(), 2, "frame {k}");
            let classes: BTreeSet<&str> = out.iter().map(|t| t.class.as_str()).collect();
            assert_eq!(classes, ["Car", "Pedestrian"].into_iter().collect());
            let ped = out.iter().find(|t| t.class == "Pedestrian").unwrap();
            assert_eq!(ped.score, 0.6);
        }
    }
    assert_eq!(trk.live_tracks(), 2);
}

#[test]
fn centre_distance_gating_tracks_boxes_that_do_not_overlap() {
    // Small boxes (0.5 m) moving 0.8 m per frame never overlap their predictions at the second
    // frame (no velocity yet): 3-D IoU starts a new track each frame, centre distance does not.
    let small = |k: usize| BoxDetection::new(bx(0.8 * k as f64, 0.0, 0.0, [0.5; 3]), "Misc", 0.5);
    let mut iou = tracker();
    let mut dist = Ab3dmot::new(Ab3dmotConfig {
        affinity: Affinity::CentreDistanceBev { max_distance: 1.5 },
        ..Ab3dmotConfig::default()
    })
    .unwrap();
    let mut iou_out = Vec::new();
    let mut dist_out = Vec::new();
    for k in 0..8 {
        iou_out = iou.step(&[small(k)]).unwrap();
        dist_out = dist.step(&[small(k)]).unwrap();
    }
    assert!(iou_out.is_empty());
    assert_eq!(dist_out.len(), 1);
    assert_eq!(dist_out[0].id, 0);
    assert!(
        (dist_out[0].velocity[0] - 8.0).abs() < 0.5,
        "{:?}",
        dist_out[0].velocity
    );
}

#[test]
fn empty_frames_and_bad_input() {
    let mut trk = tracker();
    for _ in 0..3 {
        assert!(trk.step(&[]).unwrap().is_empty());
    }
    let mut d = car(0.0, 0.0, 0.0);
    d.bbox.yaw = f64::INFINITY;
    assert!(trk.step(&[d]).is_err());
    let mut d = car(0.0, 0.0, 0.0);
    d.score = f64::NAN;
    assert!(trk.step(&[d]).is_err());
    let mut d = car(0.0, 0.0, 0.0);
    d.bbox.size[2] = -1.0;
    assert!(trk.step(&[d]).is_err());
    assert_eq!(trk.live_tracks(), 0);
    let bad = Ab3dmotConfig {
        affinity: Affinity::CentreDistanceBev { max_distance: 0.0 },
        ..Ab3dmotConfig::default()
    };
    assert!(Ab3dmot::new(bad).is_err());
}

#[test]
fn runs_are_deterministic() {
    let run = || {
        let mut trk = tracker();
        (0..15usize)
            .map(|k| {
                let dets: Vec<BoxDetection> = (0..6)
                    .map(|i| car(k as f64 + wobble(k, i, 0.3), 5.0 * i as f64, 0.0))
                    .collect();
                trk.step(&dets).unwrap()
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(run(), run());
}
