//! Label consistency: how often the estimate matched to a truth object changes label during a
//! run, and whether every truth object kept a single label. Fed frame by frame through
//! [`LabelConsistency`].
//!
//! At every step truth objects are matched to estimates by the GOSPA (α = 2, order 1)
//! pairing of [`gospa`](mod@super::gospa): the pairing minimises the summed Euclidean distance of
//! matched pairs plus `c/2` per unmatched object on either side, and a pair at distance `c` or
//! more is never matched. A *label switch* of a truth object is a step at which it is matched
//! to an estimate whose label differs from the label it was last matched to; steps at which it
//! is unmatched are skipped (so A, –, A is no switch, A, –, B is one).
//!
//! Not for: a distance between track sets (see [`ospa2`](mod@super::ospa2), which also penalises
//! switches but folds them into one number).

use std::collections::{BTreeMap, BTreeSet};

use serde::{Deserialize, Serialize};

use super::gospa::gated_pairing;
use super::points::{check_cut_off_and_order, check_points};
use crate::error::{Error, Result};
use crate::Label;

/// Label statistics of one truth object.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct TruthLabels {
    /// The truth object's id.
    pub id: u64,
    /// Number of label switches.
    pub switches: usize,
    /// Number of distinct estimate labels it was ever matched to.
    pub distinct_labels: usize,
    /// Steps at which it was present in the truth.
    pub steps_present: usize,
    /// Steps at which it was matched to an estimate.
    pub steps_matched: usize,
}

/// Label statistics of a run.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct LabelStats {
    /// Total number of label switches over all truth objects.
    pub switches: usize,
    /// One entry per truth object ever seen, sorted by id.
    pub per_truth: Vec<TruthLabels>,
    /// True when every truth object that was ever matched was matched to exactly one distinct
    /// label (vacuously true when nothing was ever matched).
    pub all_kept: bool,
    /// Number of steps fed in.
    pub steps: usize,
}

/// Running record of one truth object.
#[derive(Clone, Debug, Default)]
struct Record {
    last: Option<Label>,
    switches: usize,
    labels: BTreeSet<Label>,
    steps_present: usize,
    steps_matched: usize,
}

/// Accumulates label statistics step by step: create with [`LabelConsistency::new`], call
/// [`add_step`](LabelConsistency::add_step) once per frame, read the result with
/// [`stats`](LabelConsistency::stats) or [`finish`](LabelConsistency::finish).
///
/// ```
/// use smc_lmb::{metrics::LabelConsistency, Label};
/// let (a, b) = (Label::new(0, 0), Label::new(3, 0));
/// let mut lc = LabelConsistency::new(2.0).unwrap();
/// for l in [a, a, b] {
///     lc.add_step(&[(1, vec![0.0])], &[(l, vec![0.5])]).unwrap();
/// }
/// let s = lc.finish();
/// assert_eq!(s.switches, 1);
/// assert!(!s.all_kept);
/// ```
#[derive(Clone, Debug)]
pub struct LabelConsistency {
    c: f64,
    records: BTreeMap<u64, Record>,
    steps: usize,
}

impl LabelConsistency {
    /// A new accumulator matching truth to estimates with gate (cut-off) `c`.
    ///
    /// Returns [`Error::InvalidInput`] when `c` is not positive and finite.
    pub fn new(c: f64) -> Result<Self> {
        check_cut_off_and_order(c, 1.0)?;
        Ok(LabelConsistency {
            c,
            records: BTreeMap::new(),
            steps: 0,
        })
    }

    /// Adds one step: the truth objects `(id, position)` and the estimates `(label, position)`
    /// present at that step. Either list may be empty.
    ///
    /// Returns [`Error::InvalidInput`] (and leaves the accumulator unchanged) when a coordinate
    /// is not finite, the points do not share one dimension, or a truth id appears twice.
    pub fn add_step<P, Q>(&mut self, truth: &[(u64, P)], estimates: &[(Label, Q)]) -> Result<()>
    where
        P: AsRef<[f64]>,
        Q: AsRef<[f64]>,
    {
        let mut ids = BTreeSet::new();
        for (id, _) in truth {
            if !ids.insert(*id) {
                return Err(Error::invalid(
                    format!("truth object {id} of step {}", self.steps),
                    "id appears more than once in the step",
                ));
            }
        }
        let xs: Vec<&[f64]> = truth.iter().map(|(_, x)| x.as_ref()).collect();
        let ys: Vec<&[f64]> = estimates.iter().map(|(_, y)| y.as_ref()).collect();
        check_points(&[("truth", &xs), ("estimate", &ys)])?;
        let pairing = gated_pairing(&xs, &ys, self.c, 1.0)?;
        for ((id, _), j) in truth.iter().zip(pairing) {
            let rec = self.records.entry(*id).or_default();
            rec.steps_present += 1;
            if let Some(j) = j {
                let label = estimates[j].0;
                rec.steps_matched += 1;
                if rec.last.is_some_and(|prev| prev != label) {
                    rec.switches += 1;
                }
                rec.last = Some(label);
                rec.labels.insert(label);
            }
        }
        self.steps += 1;
        Ok(())
    }

    /// The statistics of the steps added so far.
    pub fn stats(&self) -> LabelStats {
        let per_truth: Vec<TruthLabels> = self
            .records
            .iter()
            .map(|(&id, r)| TruthLabels {
                id,
                switches: r.switches,
                distinct_labels: r.labels.len(),
                steps_present: r.steps_present,
                steps_matched: r.steps_matched,
            })
            .collect();
        LabelStats {
            switches: per_truth.iter().map(|t| t.switches).sum(),
            all_kept: per_truth.iter().all(|t| t.distinct_labels <= 1),
            per_truth,
            steps: self.steps,
        }
    }

    /// Consumes the accumulator and returns the statistics of the whole run.
    pub fn finish(self) -> LabelStats {
        self.stats()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: Label = Label::new(0, 0);
    const B: Label = Label::new(0, 1);

    #[test]
    fn hand_case_a_a_b_b_a() {
        // One truth at 0; one estimate at 0.5 labelled A, A, B, B, A; gate c = 2.
        // Switches: A→A no, A→B yes (1), B→B no, B→A yes (2). Labels {A, B}: not all kept.
        let mut lc = LabelConsistency::new(2.0).unwrap();
        for l in [A, A, B, B, A] {
            lc.add_step(&[(7, vec![0.0])], &[(l, vec![0.5])]).unwrap();
        }
        let s = lc.finish();
        assert_eq!(s.switches, 2);
        assert!(!s.all_kept);
        assert_eq!(s.steps, 5);
        assert_eq!(
            s.per_truth,
            vec![TruthLabels {
                id: 7,
                switches: 2,
                distinct_labels: 2,
                steps_present: 5,
                steps_matched: 5
            }]
        );
    }

    #[test]
    fn unmatched_steps_are_skipped() {
        // Truth at 0, c = 1. Step 1: A at 0.2 (matched). Step 2: A at 5 (distance 5 ≥ c, not
        // matched). Step 3: no estimate. Step 4: A at −0.3 (matched). A, –, –, A → no switch.
        let mut lc = LabelConsistency::new(1.0).unwrap();
        let truth = [(1u64, vec![0.0])];
        lc.add_step(&truth, &[(A, vec![0.2])]).unwrap();
        lc.add_step(&truth, &[(A, vec![5.0])]).unwrap();
        lc.add_step::<_, Vec<f64>>(&truth, &[]).unwrap();
        lc.add_step(&truth, &[(A, vec![-0.3])]).unwrap();
        let s = lc.stats();
        assert_eq!(s.switches, 0);
        assert!(s.all_kept);
        assert_eq!(s.per_truth[0].steps_matched, 2);
        assert_eq!(s.per_truth[0].steps_present, 4);
    }

    #[test]
    fn swapped_labels_count_once_per_truth() {
        // Truth 1 at (0,0), truth 2 at (10,0), c = 3. Step 1: A near truth 1, B near truth 2.
        // Step 2: the labels swap places. Each truth switches once → 2 switches in total.
        let truth = [(1u64, vec![0.0, 0.0]), (2, vec![10.0, 0.0])];
        let mut lc = LabelConsistency::new(3.0).unwrap();
        lc.add_step(&truth, &[(A, vec![0.1, 0.0]), (B, vec![9.9, 0.0])])
            .unwrap();
        lc.add_step(&truth, &[(B, vec![0.1, 0.0]), (A, vec![9.9, 0.0])])
            .unwrap();
        let s = lc.finish();
        assert_eq!(s.switches, 2);
        assert_eq!(
            s.per_truth.iter().map(|t| t.switches).collect::<Vec<_>>(),
            [1, 1]
        );
        assert!(!s.all_kept);
    }

    #[test]
    fn optimal_not_greedy_matching() {
        // 1-D truths 1 at 0 and 2 at 2.2, c = 5.
        // Step 1: A at 0.1, B at 2.1 → 1↔A, 2↔B.
        // Step 2: A at 1.0, B at −1.5. Distances: 1–A 1.0, 2–A 1.2, 1–B 1.5, 2–B 3.7.
        // Greedy closest-first would keep 1↔A, 2↔B (1.0 + 3.7 = 4.7, no switch), but the
        // optimum is 1↔B, 2↔A (1.5 + 1.2 = 2.7): both truths switch → 2 switches.
        let truth = [(1u64, vec![0.0]), (2, vec![2.2])];
        let mut lc = LabelConsistency::new(5.0).unwrap();
        lc.add_step(&truth, &[(A, vec![0.1]), (B, vec![2.1])])
            .unwrap();
        lc.add_step(&truth, &[(A, vec![1.0]), (B, vec![-1.5])])
            .unwrap();
        let s = lc.finish();
        assert_eq!(s.switches, 2);
        assert_eq!(s.per_truth[0].distinct_labels, 2);
    }

    #[test]
    fn empty_and_invalid() {
        let lc = LabelConsistency::new(1.0).unwrap();
        let s = lc.stats();
        assert_eq!((s.switches, s.steps, s.all_kept), (0, 0, true));
        assert!(s.per_truth.is_empty());
        assert!(LabelConsistency::new(0.0).is_err());
        let mut lc = LabelConsistency::new(1.0).unwrap();
        let dup = [(1u64, vec![0.0]), (1, vec![1.0])];
        assert!(lc.add_step(&dup, &[(A, vec![0.0])]).is_err());
        assert!(lc
            .add_step(&[(1u64, vec![f64::NAN])], &[(A, vec![0.0])])
            .is_err());
        assert_eq!(lc.stats().steps, 0);
        assert!(lc.stats().per_truth.is_empty());
    }
}
