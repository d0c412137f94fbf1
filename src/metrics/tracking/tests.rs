//! Hand-computed cases and invariants of the tracking scores.

use super::*;
use proptest::prelude::*;

fn frame(gt: &[i64], tr: &[i64], sim: &[f64]) -> TrackingFrame {
    TrackingFrame::new(gt.to_vec(), tr.to_vec(), sim.to_vec()).unwrap()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-12
}

#[test]
fn perfect_tracker_scores_one() {
    // Two objects over four frames, the second leaving after frame 2; tracker ids differ from
    // the truth's but follow them exactly.
    let frames = vec![
        frame(&[1, 2], &[10, 20], &[1.0, 0.0, 0.0, 1.0]),
        frame(&[1, 2], &[10, 20], &[1.0, 0.2, 0.1, 1.0]),
        frame(&[1, 2], &[20, 10], &[0.0, 1.0, 1.0, 0.0]),
        frame(&[1], &[10], &[1.0]),
    ];
    let s = evaluate(&frames, &ScoreConfig::default()).unwrap();
    for v in [
        s.hota.hota,
        s.hota.det_a,
        s.hota.ass_a,
        s.hota.loc_a,
        s.clear.mota,
        s.clear.motp,
        s.identity.idf1,
        s.identity.idp,
        s.identity.idr,
    ] {
        assert!(close(v, 1.0), "{v}");
    }
    assert_eq!((s.clear.tp, s.clear.fn_count, s.clear.fp), (7, 0, 0));
    assert_eq!(
        (s.clear.idsw, s.clear.frag, s.clear.mt, s.clear.ml),
        (0, 0, 2, 0)
    );
}

#[test]
fn one_id_switch_by_hand() {
    // One object over four frames, tracked as id 10 in frames 0–1 and as id 11 in 2–3.
    let frames = vec![
        frame(&[1], &[10], &[1.0]),
        frame(&[1], &[10], &[1.0]),
        frame(&[1], &[11], &[1.0]),
        frame(&[1], &[11], &[1.0]),
    ];
    let s = evaluate(&frames, &ScoreConfig::default()).unwrap();
    // MOTA = (TP − FP − IDSW) / GT = (4 − 0 − 1) / 4.
    assert_eq!(s.clear.idsw, 1);
    assert!(close(s.clear.mota, 0.75));
    // Best id pairing: 1 ↔ 10 (or 11): IDTP 2, IDFN 2, IDFP 2 → IDF1 = 4 / 8.
    assert_eq!(
        (s.identity.idtp, s.identity.idfn, s.identity.idfp),
        (2, 2, 2)
    );
    assert!(close(s.identity.idf1, 0.5));
    // Every true positive c: TPA 2, FNA 2, FPA 0 → AssA = 1/2; DetA = 1; HOTA = √(1/2).
    assert!(close(s.hota.ass_a, 0.5));
    assert!(close(s.hota.det_a, 1.0));
    assert!(close(s.hota.hota, 0.5f64.sqrt()));
    assert_eq!(s.clear.frag, 0);
}

#[test]
fn two_ids_exchanged_by_hand() {
    // Objects 1, 2 over four frames; tracker ids 10, 20 follow them, then exchange at frame 2.
    let a = [1.0, 0.0, 0.0, 1.0];
    let b = [0.0, 1.0, 1.0, 0.0];
    let frames = vec![
        frame(&[1, 2], &[10, 20], &a),
        frame(&[1, 2], &[10, 20], &a),
        frame(&[1, 2], &[10, 20], &b),
        frame(&[1, 2], &[10, 20], &b),
    ];
    let s = evaluate(&frames, &ScoreConfig::default()).unwrap();
    assert_eq!(s.clear.idsw, 2);
    assert!(close(s.clear.mota, (8.0 - 2.0) / 8.0));
    // IDTP 4 of 8 each way.
    assert!(close(s.identity.idf1, 0.5));
    // TPA 2, FNA 2, FPA 2 for every true positive.
    assert!(close(s.hota.ass_a, 1.0 / 3.0));
    assert!(close(s.hota.ass_re, 0.5));
    assert!(close(s.hota.ass_pr, 0.5));
}

#[test]
fn misses_and_false_positives_by_hand() {
    // Frame 0: object 1 matched (0.8); frame 1: missed, tracker 10 elsewhere (0.3 < 0.5) and
    // a second tracker 11 with nothing; frame 2: matched again (0.6).
    let frames = vec![
        frame(&[1], &[10], &[0.8]),
        frame(&[1], &[10, 11], &[0.3, 0.0]),
        frame(&[1], &[10], &[0.6]),
    ];
    let s = evaluate(&frames, &ScoreConfig::default()).unwrap();
    assert_eq!((s.clear.tp, s.clear.fn_count, s.clear.fp), (2, 1, 2));
    assert!(close(s.clear.mota, (2.0 - 2.0) / 3.0));
    assert!(close(s.clear.motp, 0.7));
    assert_eq!(s.clear.frag, 1);
    assert_eq!((s.clear.mt, s.clear.pt, s.clear.ml), (0, 1, 0));
    // At α = 0.05 all three frames match 1 ↔ 10 (0.3 ≥ α): DetA = 3 / (3 + 0 + 1).
    let a0 = &s.hota.per_alpha[0];
    assert_eq!((a0.tp, a0.fn_count, a0.fp), (3, 0, 1));
    assert!(close(a0.loc_a, (0.8 + 0.3 + 0.6) / 3.0));
    // At α = 0.95 nothing matches.
    let a18 = &s.hota.per_alpha[18];
    assert_eq!((a18.tp, a18.fn_count, a18.fp), (0, 3, 4));
    assert!(close(a18.hota, 0.0));
    assert!(close(a18.loc_a, 1.0));
}

#[test]
fn empty_sides_follow_trackeval() {
    let none = vec![frame(&[1], &[], &[]), frame(&[1, 2], &[], &[])];
    let s = evaluate(&none, &ScoreConfig::default()).unwrap();
    assert_eq!((s.clear.fn_count, s.clear.ml, s.identity.idfn), (3, 2, 3));
    assert!(close(s.hota.hota, 0.0) && close(s.hota.loc_a, 1.0));
    let only_fp = vec![frame(&[], &[5], &[])];
    let s = evaluate(&only_fp, &ScoreConfig::default()).unwrap();
    assert_eq!((s.clear.fp, s.identity.idfp), (1, 1));
    assert!(close(s.clear.mota, 0.0));
}

#[test]
fn bad_frames_are_errors() {
    assert!(TrackingFrame::new(vec![1], vec![2], vec![]).is_err());
    assert!(TrackingFrame::new(vec![1], vec![2], vec![1.5]).is_err());
    assert!(TrackingFrame::new(vec![1], vec![2], vec![f64::NAN]).is_err());
    assert!(TrackingFrame::new(vec![1, 1], vec![], vec![]).is_err());
    let f = vec![TrackingFrame {
        gt_ids: vec![1],
        tracker_ids: vec![2],
        similarity: vec![2.0],
    }];
    assert!(evaluate(&f, &ScoreConfig::default()).is_err());
    let cfg = ScoreConfig {
        clear_threshold: 0.0,
        ..ScoreConfig::default()
    };
    assert!(evaluate(&[], &cfg).is_err());
}

/// The most identity true positives any one-to-one id pairing gives, by enumeration.
fn brute_idtp(potential: &[Vec<u64>], g: usize, used: &mut Vec<bool>) -> u64 {
    if g == potential.len() {
        return 0;
    }
    let mut best = brute_idtp(potential, g + 1, used);
    for t in 0..used.len() {
        if !used[t] {
            used[t] = true;
            best = best.max(potential[g][t] + brute_idtp(potential, g + 1, used));
            used[t] = false;
        }
    }
    best
}

fn random_sequence() -> impl Strategy<Value = Vec<TrackingFrame>> {
    let frame = (
        proptest::sample::subsequence(vec![0i64, 1, 2, 3], 0..=4),
        proptest::sample::subsequence(vec![10i64, 11, 12, 13], 0..=4),
        proptest::collection::vec(0.0f64..1.0, 16),
    )
        .prop_map(|(g, t, s)| {
            let sim = s[..g.len() * t.len()].to_vec();
            TrackingFrame::new(g, t, sim).unwrap()
        });
    proptest::collection::vec(frame, 0..7)
}

proptest! {
    #[test]
    fn counts_add_up_and_scores_are_bounded(frames in random_sequence()) {
        let s = evaluate(&frames, &ScoreConfig::default()).unwrap();
        let gt: u64 = frames.iter().map(|f| f.gt_ids.len() as u64).sum();
        let tr: u64 = frames.iter().map(|f| f.tracker_ids.len() as u64).sum();
        prop_assert_eq!(s.clear.tp + s.clear.fn_count, gt);
        if gt > 0 {
            prop_assert_eq!(s.clear.tp + s.clear.fp, tr);
        }
        prop_assert_eq!(s.identity.idtp + s.identity.idfn, gt);
        prop_assert_eq!(s.identity.idtp + s.identity.idfp, tr);
        for p in &s.hota.per_alpha {
            prop_assert_eq!(p.tp + p.fn_count, gt);
            prop_assert_eq!(p.tp + p.fp, tr);
            for v in [p.hota, p.det_a, p.ass_a, p.loc_a, p.det_re, p.det_pr, p.ass_re, p.ass_pr] {
                prop_assert!((0.0..=1.0 + 1e-12).contains(&v), "{}", v);
            }
            prop_assert!(p.det_a <= p.det_re.min(p.det_pr) + 1e-12);
            prop_assert!(p.ass_a <= p.ass_re.min(p.ass_pr) + 1e-12);
        }
        // Larger α never finds more true positives.
        for w in s.hota.per_alpha.windows(2) {
            prop_assert!(w[1].tp <= w[0].tp);
        }
        prop_assert!(s.clear.mota <= 1.0 && s.identity.idf1 <= 1.0);
    }

    #[test]
    fn identity_matches_brute_force(frames in random_sequence()) {
        let s = evaluate(&frames, &ScoreConfig::default()).unwrap();
        let gt: u64 = frames.iter().map(|f| f.gt_ids.len() as u64).sum();
        let tr: u64 = frames.iter().map(|f| f.tracker_ids.len() as u64).sum();
        let mut potential = vec![vec![0u64; 4]; 4];
        for f in &frames {
            for (i, &g) in f.gt_ids.iter().enumerate() {
                for (j, &t) in f.tracker_ids.iter().enumerate() {
                    if f.sim(i, j) >= 0.5 {
                        potential[g as usize][(t - 10) as usize] += 1;
                    }
                }
            }
        }
        let idtp = if gt == 0 || tr == 0 { 0 } else { brute_idtp(&potential, 0, &mut vec![false; 4]) };
        prop_assert_eq!(s.identity.idtp, idtp);
    }
}

#[test]
fn clear_matches_keep_the_previous_match_by_hand() {
    // Frame 0: one tracker between two truths, nearer truth 1 (0.9 against 0.6): truth 1 is
    // matched. Frame 1: now nearer truth 2 (0.6 against 0.9), but truth 1 still reaches the
    // threshold and keeps its match by the continuation bonus. Frame 2: no tracker.
    let frames = vec![
        frame(&[1, 2], &[10], &[0.9, 0.6]),
        frame(&[1, 2], &[10], &[0.6, 0.9]),
        frame(&[1], &[], &[]),
    ];
    let m = clear_matches(&frames, 0.5).unwrap();
    assert_eq!(m, vec![vec![true, false], vec![true, false], vec![false]]);
    let c = clear(&frames, 0.5).unwrap();
    assert_eq!(c.tp, 2);
}
