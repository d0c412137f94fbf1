//! Scoring people found in real scans against human leg annotations (the `leg_tracker`
//! recordings: one `geometry_msgs/PoseArray` of leg positions just before every scan).
//!
//! # Rules
//!
//! * **Truth.** Each scan takes the latest annotation the bag received at or before it
//!   ([`truth_for_scans`]; by receive time, as the annotations' stamps may come from another
//!   clock). Legs closer than [`LEG_MERGE`] (0.6 m) are one person, at their
//!   mean ([`people_from_legs`]; single linkage, so a person's two legs and nothing else in
//!   practice); a lone leg is a person at that leg.
//! * **Matching.** In every scored scan estimates and people are paired one to one, only
//!   pairs closer than [`MATCH_DISTANCE`] (0.5 m), by the GOSPA pairing (the most pairs, then
//!   the smallest summed distance; [`crate::metrics::gospa()`]). A paired estimate is a true
//!   positive, an unpaired estimate a false person, an unpaired person a miss.
//! * **Scans.** Scans before the 10th ([`FIRST_SCORED_SCAN`] = 9, 0-based) are not scored: a
//!   tracker needs a few scans to confirm anyone.
//! * **Per-scan detection scores** ([`DetectionScore`]), pooled over the scored scans:
//!   precision = matched / estimates, recall = matched / people, F1 their harmonic mean, and
//!   false people per scan = unpaired estimates / scored scans (the figure for recordings
//!   without people).
//! * **Tracks** ([`TrackScore`]): the same pairing with labels. Truth people carry no
//!   identity in the annotations, so one is made: a person continues the identity of the
//!   nearest person of the previous scan within [`LEG_MERGE`], otherwise starts a new one. An
//!   ID switch is a person paired with a label other than the one it was last paired with
//!   ([`crate::metrics::LabelConsistency`]); MOTA = 1 − (misses + false people + ID switches)
//!   / people; IDF1 = 2·IDTP / (people + estimates), IDTP the scans in which a truth identity
//!   and the label it is assigned to (one to one over the whole run, the assignment that
//!   maximises IDTP) are paired.
//!
//! Not for: simulated runs (see [`super::evaluate`]) or reading the annotations (see
//! [`crate::laser2d::read_pose_arrays`]).

use crate::error::{Error, Result};
use crate::filter::Label;
use crate::laser2d::PoseArrayRecord;
use crate::metrics::gospa::gated_pairing;
use crate::metrics::LabelConsistency;
use serde::Serialize;
use std::collections::BTreeMap;

/// Legs closer than this (m) are one person.
pub const LEG_MERGE: f64 = 0.6;
/// An estimate matches a person closer than this (m).
pub const MATCH_DISTANCE: f64 = 0.5;
/// The first scan scored (0-based): the 10th.
pub const FIRST_SCORED_SCAN: usize = 9;

/// People from leg positions: legs closer than `merge` (m) are linked (single linkage) and
/// every linked group is one person at the mean of its legs, in order of first leg.
pub fn people_from_legs(legs: &[[f64; 2]], merge: f64) -> Vec<[f64; 2]> {
    let n = legs.len();
    let mut owner: Vec<usize> = (0..n).collect();
    fn root(o: &mut [usize], mut i: usize) -> usize {
        while o[i] != i {
            o[i] = o[o[i]];
            i = o[i];
        }
        i
    }
    for i in 0..n {
        for j in i + 1..n {
            let d = (legs[i][0] - legs[j][0]).hypot(legs[i][1] - legs[j][1]);
            if d < merge {
                let (a, b) = (root(&mut owner, i), root(&mut owner, j));
                owner[a.max(b)] = a.min(b);
            }
        }
    }
    let mut groups: BTreeMap<usize, (f64, f64, usize)> = BTreeMap::new();
    for (i, l) in legs.iter().enumerate() {
        let r = root(&mut owner, i);
        let g = groups.entry(r).or_insert((0.0, 0.0, 0));
        g.0 += l[0];
        g.1 += l[1];
        g.2 += 1;
    }
    groups
        .into_values()
        .map(|(x, y, k)| [x / k as f64, y / k as f64])
        .collect()
}

/// The legs of every scan: the latest annotation the bag received at or before the scan (in
/// the laser frame, z dropped); `scan_times` are the scans' receive times
/// ([`crate::laser2d::BagScans::receive_times`]: the annotations' header stamps may come from
/// another clock, as in the `leg_tracker` recordings). `source` names the bag and topic in
/// errors: the counts of annotations and scans must agree, and every scan must have an
/// annotation before it.
pub fn legs_for_scans(
    scan_times: &[f64],
    annotations: &[PoseArrayRecord],
    source: &str,
) -> Result<Vec<Vec<[f64; 2]>>> {
    if annotations.len() != scan_times.len() {
        return Err(Error::invalid(
            source,
            format!(
                "{} annotations for {} scans (one annotation per scan expected)",
                annotations.len(),
                scan_times.len()
            ),
        ));
    }
    let mut order: Vec<usize> = (0..annotations.len()).collect();
    order.sort_by(|&a, &b| {
        annotations[a]
            .receive_time
            .total_cmp(&annotations[b].receive_time)
    });
    let times: Vec<f64> = order.iter().map(|&i| annotations[i].receive_time).collect();
    scan_times
        .iter()
        .enumerate()
        .map(|(k, &t_scan)| {
            let before = times.partition_point(|&t| t <= t_scan);
            if before == 0 {
                return Err(Error::invalid(
                    source,
                    format!("scan {k} (received {t_scan:.6}) has no annotation before it"),
                ));
            }
            Ok(annotations[order[before - 1]]
                .positions
                .iter()
                .map(|p| [p[0], p[1]])
                .collect())
        })
        .collect()
}

/// The people of every scan: [`legs_for_scans`] merged by [`people_from_legs`].
pub fn truth_for_scans(
    scan_times: &[f64],
    annotations: &[PoseArrayRecord],
    source: &str,
) -> Result<Vec<Vec<[f64; 2]>>> {
    Ok(legs_for_scans(scan_times, annotations, source)?
        .iter()
        .map(|legs| people_from_legs(legs, LEG_MERGE))
        .collect())
}

/// The one-to-one pairing of one scan: for every person the estimate paired with it.
pub fn match_people(truth: &[[f64; 2]], estimates: &[[f64; 2]]) -> Result<Vec<Option<usize>>> {
    let t: Vec<&[f64]> = truth.iter().map(|p| &p[..]).collect();
    let e: Vec<&[f64]> = estimates.iter().map(|p| &p[..]).collect();
    if t.iter()
        .chain(&e)
        .flat_map(|p| p.iter())
        .any(|v| !v.is_finite())
    {
        return Err(Error::invalid("people score", "non-finite position"));
    }
    gated_pairing(&t, &e, MATCH_DISTANCE, 1.0)
}

/// Per-scan detection counts pooled over scans (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct DetectionScore {
    /// Scored scans.
    pub scans: usize,
    /// People in them.
    pub people: usize,
    /// Estimates in them.
    pub estimates: usize,
    /// Estimates paired with a person.
    pub matched: usize,
}

impl DetectionScore {
    /// Adds one scan's people and estimates.
    pub fn add_scan(&mut self, truth: &[[f64; 2]], estimates: &[[f64; 2]]) -> Result<()> {
        let pairs = match_people(truth, estimates)?;
        self.scans += 1;
        self.people += truth.len();
        self.estimates += estimates.len();
        self.matched += pairs.iter().flatten().count();
        Ok(())
    }

    /// Adds another score's counts.
    pub fn merge(&mut self, other: &DetectionScore) {
        self.scans += other.scans;
        self.people += other.people;
        self.estimates += other.estimates;
        self.matched += other.matched;
    }

    /// matched / estimates (1 with no estimate).
    pub fn precision(&self) -> f64 {
        if self.estimates == 0 {
            1.0
        } else {
            self.matched as f64 / self.estimates as f64
        }
    }

    /// matched / people (1 with no person).
    pub fn recall(&self) -> f64 {
        if self.people == 0 {
            1.0
        } else {
            self.matched as f64 / self.people as f64
        }
    }

    /// Harmonic mean of precision and recall (0 when both are 0).
    pub fn f1(&self) -> f64 {
        let (p, r) = (self.precision(), self.recall());
        if p + r == 0.0 {
            0.0
        } else {
            2.0 * p * r / (p + r)
        }
    }

    /// Unpaired estimates per scored scan.
    pub fn false_per_scan(&self) -> f64 {
        if self.scans == 0 {
            0.0
        } else {
            (self.estimates - self.matched) as f64 / self.scans as f64
        }
    }
}

/// Tracking scores of one run (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrackScoreSummary {
    /// The per-scan detection counts of the tracks.
    pub detection: DetectionScore,
    /// ID switches.
    pub id_switches: usize,
    /// 1 − (misses + false people + ID switches) / people.
    pub mota: f64,
    /// 2·IDTP / (people + estimates).
    pub idf1: f64,
}

/// Accumulates [`TrackScoreSummary`] scan by scan.
#[derive(Clone, Debug)]
pub struct TrackScore {
    detection: DetectionScore,
    labels: LabelConsistency,
    previous: Vec<(u64, [f64; 2])>,
    next_id: u64,
    /// (truth id, label) → scans paired.
    together: BTreeMap<(u64, Label), usize>,
}

impl Default for TrackScore {
    fn default() -> Self {
        TrackScore {
            detection: DetectionScore::default(),
            labels: LabelConsistency::new(MATCH_DISTANCE).expect("a valid cut-off"),
            previous: Vec::new(),
            next_id: 0,
            together: BTreeMap::new(),
        }
    }
}

impl TrackScore {
    /// Adds one scan: the people (no identities) and the labelled estimates. Every scan is
    /// handed in, scored or not, so that identities carry over; `scored` says whether it
    /// counts.
    pub fn add_scan(
        &mut self,
        truth: &[[f64; 2]],
        estimates: &[(Label, [f64; 2])],
        scored: bool,
    ) -> Result<()> {
        // Identities: the nearest person of the previous scan within LEG_MERGE, one to one.
        let prev: Vec<&[f64]> = self.previous.iter().map(|(_, p)| &p[..]).collect();
        let now: Vec<&[f64]> = truth.iter().map(|p| &p[..]).collect();
        let link = gated_pairing(&now, &prev, LEG_MERGE, 1.0)?;
        let ids: Vec<u64> = link
            .iter()
            .map(|l| match l {
                Some(j) => self.previous[*j].0,
                None => {
                    self.next_id += 1;
                    self.next_id - 1
                }
            })
            .collect();
        self.previous = ids.iter().copied().zip(truth.iter().copied()).collect();
        if !scored {
            return Ok(());
        }
        let positions: Vec<[f64; 2]> = estimates.iter().map(|e| e.1).collect();
        let pairs = match_people(truth, &positions)?;
        self.detection.add_scan(truth, &positions)?;
        for (t, e) in pairs.iter().enumerate() {
            if let Some(e) = e {
                *self.together.entry((ids[t], estimates[*e].0)).or_default() += 1;
            }
        }
        let t: Vec<(u64, Vec<f64>)> = ids
            .iter()
            .zip(truth)
            .map(|(i, p)| (*i, p.to_vec()))
            .collect();
        let e: Vec<(Label, Vec<f64>)> = estimates.iter().map(|(l, p)| (*l, p.to_vec())).collect();
        self.labels.add_step(&t, &e)
    }

    /// The scores so far.
    pub fn summary(&self) -> TrackScoreSummary {
        let d = self.detection;
        let switches = self.labels.stats().switches;
        let misses = d.people - d.matched;
        let false_people = d.estimates - d.matched;
        let mota = if d.people == 0 {
            0.0
        } else {
            1.0 - (misses + false_people + switches) as f64 / d.people as f64
        };
        // IDTP: the identity ↔ label assignment maximising the scans paired together.
        let truths: Vec<u64> = {
            let mut v: Vec<u64> = self.together.keys().map(|k| k.0).collect();
            v.dedup();
            v
        };
        let mut labels: Vec<Label> = self.together.keys().map(|k| k.1).collect();
        labels.sort();
        labels.dedup();
        let cols = labels.len() + truths.len();
        let mut cost = vec![0.0; truths.len() * cols];
        for ((t, l), n) in &self.together {
            let r = truths.binary_search(t).expect("listed");
            let c = labels.binary_search(l).expect("listed");
            cost[r * cols + c] = -(*n as f64);
        }
        let idtp = crate::assignment::solve(&cost, truths.len(), cols)
            .map_or(0.0, |(_, total)| 0.0 - total);
        let denom = (d.people + d.estimates) as f64;
        let idf1 = if denom == 0.0 {
            1.0
        } else {
            2.0 * idtp / denom
        };
        TrackScoreSummary {
            detection: d,
            id_switches: switches,
            mota,
            idf1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_legs_make_one_person_at_their_mean() {
        let p = people_from_legs(&[[1.0, 0.0], [1.0, 0.3]], LEG_MERGE);
        assert_eq!(p.len(), 1);
        assert!((p[0][0] - 1.0).abs() < 1e-12 && (p[0][1] - 0.15).abs() < 1e-12);
        // Legs 0.6 m apart or more are two people; four legs, two people.
        assert_eq!(
            people_from_legs(&[[0.0, 0.0], [0.0, 0.6]], LEG_MERGE).len(),
            2
        );
        let four = people_from_legs(&[[1.0, 0.0], [3.0, 0.0], [1.2, 0.0], [3.0, 0.2]], LEG_MERGE);
        assert_eq!(four.len(), 2);
        assert!((four[0][0] - 1.1).abs() < 1e-12);
        assert!((four[1][1] - 0.1).abs() < 1e-12);
        assert!(people_from_legs(&[], LEG_MERGE).is_empty());
    }

    #[test]
    fn an_estimate_0_6_m_away_is_a_miss_and_a_false_person() {
        let mut s = DetectionScore::default();
        s.add_scan(&[[2.0, 0.0]], &[[2.0, 0.6]]).unwrap();
        assert_eq!((s.people, s.estimates, s.matched), (1, 1, 0));
        assert_eq!((s.precision(), s.recall(), s.f1()), (0.0, 0.0, 0.0));
        assert_eq!(s.false_per_scan(), 1.0);
        // 0.4 m away: a match.
        s.add_scan(&[[2.0, 0.0]], &[[2.0, 0.4]]).unwrap();
        assert_eq!(s.matched, 1);
        assert_eq!((s.precision(), s.recall()), (0.5, 0.5));
        assert_eq!(s.false_per_scan(), 0.5);
        // One to one: two estimates at one person, one of them false.
        let mut one = DetectionScore::default();
        one.add_scan(&[[0.0, 0.0]], &[[0.1, 0.0], [0.0, 0.1]])
            .unwrap();
        assert_eq!((one.matched, one.estimates), (1, 2));
        // An empty room: every estimate is false, recall is not defined and reported 1.
        let mut empty = DetectionScore::default();
        empty.add_scan(&[], &[[1.0, 1.0], [2.0, 2.0]]).unwrap();
        empty.add_scan(&[], &[]).unwrap();
        assert_eq!(empty.false_per_scan(), 1.0);
        assert_eq!(empty.recall(), 1.0);
    }

    fn ann(t: f64, legs: &[[f64; 2]]) -> PoseArrayRecord {
        PoseArrayRecord {
            time: 1e9 - t,
            receive_time: t,
            positions: legs.iter().map(|l| [l[0], l[1], 0.0]).collect(),
        }
    }

    #[test]
    fn each_scan_takes_the_latest_annotation_before_it() {
        let scans = [1.0, 2.0];
        let anns = [
            ann(1.95, &[[3.0, 0.0], [3.0, 0.2]]),
            ann(0.9, &[[1.0, 0.0]]),
        ];
        let t = truth_for_scans(&scans, &anns, "b.bag /legs").unwrap();
        assert_eq!(t[0], vec![[1.0, 0.0]]);
        assert_eq!(t[1].len(), 1);
        assert!((t[1][0][1] - 0.1).abs() < 1e-12);
        let e = truth_for_scans(&scans, &anns[..1], "b.bag /legs")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("b.bag /legs") && e.contains("1 annotations for 2 scans"),
            "{e}"
        );
        let late = [ann(1.5, &[]), ann(1.9, &[])];
        let e = truth_for_scans(&scans, &late, "b.bag /legs")
            .unwrap_err()
            .to_string();
        assert!(e.contains("scan 0"), "{e}");
    }

    #[test]
    fn tracks_score_switches_mota_and_idf1() {
        let (a, b) = (Label::new(0, 0), Label::new(5, 0));
        let mut s = TrackScore::default();
        // One person walking along x; label a for three scans, then b for one, one scan
        // missed, and one false track in the last scan.
        let walk = |k: usize| [1.0 + 0.1 * k as f64, 0.0];
        s.add_scan(&[walk(0)], &[], false).unwrap();
        for k in 1..4 {
            s.add_scan(&[walk(k)], &[(a, walk(k))], true).unwrap();
        }
        s.add_scan(&[walk(4)], &[(b, walk(4))], true).unwrap();
        s.add_scan(&[walk(5)], &[(b, [9.0, 9.0])], true).unwrap();
        let r = s.summary();
        assert_eq!(r.detection.scans, 5);
        assert_eq!((r.detection.people, r.detection.matched), (5, 4));
        assert_eq!(r.id_switches, 1);
        // misses 1, false 1, switches 1 over 5 people.
        assert!((r.mota - 0.4).abs() < 1e-12, "{}", r.mota);
        // IDTP 3 (the person with a), 5 people + 5 estimates.
        assert!((r.idf1 - 0.6).abs() < 1e-12, "{}", r.idf1);
    }
}
