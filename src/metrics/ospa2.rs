//! OSPA(2): the OSPA construction applied twice, to compare *sets of tracks* over a time window,
//! after Beard, Vo & Vo (2017). It penalises track fragmentation, label swaps and late or early
//! track starts, which a per-step OSPA cannot see.
//!
//! A track is a sequence of per-step states, absent at some steps. Over a window `W` of steps,
//! the base distance between a truth track `x` and an estimated track `y` is a time average of
//! a per-step distance over the steps `D` where at least one of the two is present:
//!
//! ```text
//! d_t = min(c, ‖x(t) − y(t)‖)   both present
//! d_t = c                        exactly one present
//! d̃(x, y) = ( (1/|D|) Σ_{t∈D} d_t^q )^(1/q)
//! ```
//!
//! With `q = 1` this is the plain time average of the paper; `q > 1` is the power mean of order
//! `q` (a natural generalisation offered here, not part of the 2017 definition). OSPA(2) is then
//! the OSPA distance of cut-off `c` and order `p` between the truth tracks and the estimated
//! tracks that are present at least once in the window, with `d̃` as base distance (which never
//! exceeds `c`). Typical settings are `p = q = 1`.
//!
//! Not for: per-step point sets without identities (use [`ospa`](mod@super::ospa) or
//! [`gospa`](mod@super::gospa)) or counting label switches (see [`labels`](super::labels)).

use std::collections::BTreeMap;
use std::ops::Range;

use serde::{Deserialize, Serialize};

use super::ospa::{ospa_with, Ospa};
use super::points::{check_cut_off_and_order, check_points, euclidean};
use crate::error::{Error, Result};

/// One track over a run: its identity and its state at every step (`None` when absent).
///
/// `states[k]` is the state at step `k` (counted from 0); steps at or beyond `states.len()`
/// count as absent. Truth tracks usually use a `u64` id, estimated tracks a
/// [`Label`](crate::Label); OSPA(2) itself never looks at the id.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrackHistory<Id = u64> {
    /// The identity of the track.
    pub id: Id,
    /// The state at each step, `None` when the track does not exist at that step.
    pub states: Vec<Option<Vec<f64>>>,
}

impl<Id> TrackHistory<Id> {
    /// A track with the given identity and per-step states.
    pub fn new(id: Id, states: Vec<Option<Vec<f64>>>) -> Self {
        TrackHistory { id, states }
    }

    /// The state at step `k`, or `None` when the track is absent then.
    pub fn state(&self, k: usize) -> Option<&[f64]> {
        self.states.get(k).and_then(|s| s.as_deref())
    }

    /// Whether the track is present at some step of `window`.
    pub fn present_in(&self, window: &Range<usize>) -> bool {
        (window.start..window.end.min(self.states.len())).any(|k| self.state(k).is_some())
    }
}

/// Regroups per-step lists of `(id, state)` into one [`TrackHistory`] per id, sorted by id.
/// `frames[k]` lists the objects present at step `k`.
///
/// Returns [`Error::InvalidInput`] when an id appears twice in one frame.
pub fn tracks_from_frames<Id, P, F>(frames: &[F]) -> Result<Vec<TrackHistory<Id>>>
where
    Id: Ord + Clone + std::fmt::Debug,
    P: AsRef<[f64]>,
    F: AsRef<[(Id, P)]>,
{
    let mut tracks: BTreeMap<Id, Vec<Option<Vec<f64>>>> = BTreeMap::new();
    for (k, frame) in frames.iter().enumerate() {
        for (id, x) in frame.as_ref() {
            let states = tracks.entry(id.clone()).or_default();
            if states.len() > k {
                return Err(Error::invalid(
                    format!("object {id:?} of frame {k}"),
                    "id appears more than once in the frame",
                ));
            }
            states.resize(k, None);
            states.push(Some(x.as_ref().to_vec()));
        }
    }
    Ok(tracks
        .into_iter()
        .map(|(id, states)| TrackHistory { id, states })
        .collect())
}

/// OSPA(2) distance between `truth` and `estimated` track sets over the steps in `window`, with
/// cut-off `c`, outer order `p` and time-averaging order `q` (see the [module docs](self)).
///
/// Tracks absent throughout the window are ignored; with no track on either side (or an empty
/// window) the result is 0, and with tracks on one side only it is `c`. States are compared by
/// Euclidean distance, so truth and estimates must use the same state components (project
/// them first if needed).
///
/// Returns [`Error::InvalidInput`] when `c` is not positive and finite, `p` or `q` is not finite
/// or below 1, or a state inside the window is not finite or of a different dimension.
pub fn ospa2<A, B>(
    truth: &[TrackHistory<A>],
    estimated: &[TrackHistory<B>],
    window: Range<usize>,
    c: f64,
    p: f64,
    q: f64,
) -> Result<f64> {
    ospa2_parts(truth, estimated, window, c, p, q).map(|o| o.distance)
}

/// Like [`ospa2`], but also returns the localisation and cardinality components of the outer
/// OSPA (with `distance^p = localisation^p + cardinality^p`). The localisation part measures
/// how well paired tracks agree over the window; the cardinality part counts tracks with no
/// counterpart.
pub fn ospa2_parts<A, B>(
    truth: &[TrackHistory<A>],
    estimated: &[TrackHistory<B>],
    window: Range<usize>,
    c: f64,
    p: f64,
    q: f64,
) -> Result<Ospa> {
    check_orders(c, p, q)?;
    check_states(truth, estimated, &window)?;
    Ok(window_ospa(truth, estimated, &window, c, p, q))
}

/// OSPA(2) over a sliding window of `window_len` steps ending at every step: element `k` is
/// OSPA(2) over steps `k + 1 − window_len ..= k`, or over `0 ..= k` while `k + 1 < window_len`.
/// The series has one value per step up to the last step at which any track has a state entry
/// (`max states.len()` over all tracks).
///
/// Errors as for [`ospa2`]; in addition `window_len` must be at least 1.
pub fn ospa2_series<A, B>(
    truth: &[TrackHistory<A>],
    estimated: &[TrackHistory<B>],
    window_len: usize,
    c: f64,
    p: f64,
    q: f64,
) -> Result<Vec<f64>> {
    check_orders(c, p, q)?;
    if window_len == 0 {
        return Err(Error::invalid("OSPA(2) window length", "0 (must be ≥ 1)"));
    }
    let steps = truth
        .iter()
        .map(|t| t.states.len())
        .chain(estimated.iter().map(|t| t.states.len()))
        .max()
        .unwrap_or(0);
    check_states(truth, estimated, &(0..steps))?;
    Ok((0..steps)
        .map(|k| {
            let window = (k + 1).saturating_sub(window_len)..k + 1;
            window_ospa(truth, estimated, &window, c, p, q).distance
        })
        .collect())
}

fn check_orders(c: f64, p: f64, q: f64) -> Result<()> {
    check_cut_off_and_order(c, p)?;
    if !(q.is_finite() && q >= 1.0) {
        return Err(Error::invalid(
            "order q",
            format!("{q} (must be finite and at least 1)"),
        ));
    }
    Ok(())
}

/// Checks every state inside `window` (finite, common dimension).
fn check_states<A, B>(
    truth: &[TrackHistory<A>],
    estimated: &[TrackHistory<B>],
    window: &Range<usize>,
) -> Result<()> {
    let truth_states = present_states(truth, window);
    let est_states = present_states(estimated, window);
    check_points(&[
        ("truth track state", &truth_states),
        ("estimated track state", &est_states),
    ])
}

/// Every state of every track inside `window`.
fn present_states<'a, Id>(tracks: &'a [TrackHistory<Id>], window: &Range<usize>) -> Vec<&'a [f64]> {
    tracks
        .iter()
        .flat_map(|t| {
            (window.start..window.end.min(t.states.len())).filter_map(move |k| t.state(k))
        })
        .collect()
}

/// OSPA(2) over one window; inputs already checked.
fn window_ospa<A, B>(
    truth: &[TrackHistory<A>],
    estimated: &[TrackHistory<B>],
    window: &Range<usize>,
    c: f64,
    p: f64,
    q: f64,
) -> Ospa {
    let xs: Vec<&TrackHistory<A>> = truth.iter().filter(|t| t.present_in(window)).collect();
    let ys: Vec<&TrackHistory<B>> = estimated.iter().filter(|t| t.present_in(window)).collect();
    let base = |i: usize, j: usize| track_distance(xs[i], ys[j], window, c, q);
    // The base distance is finite and non-negative after the checks, so the solver cannot fail.
    ospa_with(xs.len(), ys.len(), base, c, p).unwrap_or(Ospa {
        distance: f64::NAN,
        localisation: f64::NAN,
        cardinality: f64::NAN,
    })
}

/// The time-averaged base distance between two tracks over `window` (0 when neither is ever
/// present).
fn track_distance<A, B>(
    x: &TrackHistory<A>,
    y: &TrackHistory<B>,
    window: &Range<usize>,
    c: f64,
    q: f64,
) -> f64 {
    let mut sum = 0.0;
    let mut count = 0usize;
    // Past the end of both state vectors neither track is present.
    let end = window.end.min(x.states.len().max(y.states.len()));
    for k in window.start..end {
        let d = match (x.state(k), y.state(k)) {
            (Some(a), Some(b)) => euclidean(a, b).min(c),
            (Some(_), None) | (None, Some(_)) => c,
            (None, None) => continue,
        };
        sum += d.powf(q);
        count += 1;
    }
    if count == 0 {
        0.0
    } else {
        (sum / count as f64).powf(1.0 / q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Label;
    use approx::assert_relative_eq;

    /// A 1-D track at a constant position over `present`, within `len` steps.
    fn track<Id>(id: Id, len: usize, present: Range<usize>, at: f64) -> TrackHistory<Id> {
        let states = (0..len)
            .map(|k| present.contains(&k).then(|| vec![at]))
            .collect();
        TrackHistory::new(id, states)
    }

    /// Truth A at 0 and B at 100 over steps 0..4; one estimate E at 1 over steps 1..3.
    fn scenario() -> (Vec<TrackHistory>, Vec<TrackHistory<Label>>) {
        let truth = vec![track(1, 4, 0..4, 0.0), track(2, 4, 0..4, 100.0)];
        let est = vec![track(Label::new(1, 0), 3, 1..3, 1.0)];
        (truth, est)
    }

    #[test]
    fn hand_case_two_truths_one_partial_estimate() {
        let (truth, est) = scenario();
        // Window 0..4, c = 10, p = q = 1.
        // d̃(A, E): steps 0 and 3 only A → 10 each; steps 1, 2 both → min(10, 1) = 1 each.
        //          (10 + 1 + 1 + 10) / 4 = 5.5.
        // d̃(B, E): steps 0, 3 → 10; steps 1, 2 → min(10, 99) = 10 → 10.
        // Outer OSPA, sets {A, B} vs {E}: pair E↔A (5.5), B unpaired (c = 10):
        //          (5.5 + 10) / 2 = 7.75.
        let d = ospa2(&truth, &est, 0..4, 10.0, 1.0, 1.0).unwrap();
        assert_relative_eq!(d, 7.75, epsilon = 1e-12);
        // Components: localisation = 5.5 / 2 = 2.75, cardinality = 10 / 2 = 5.
        let o = ospa2_parts(&truth, &est, 0..4, 10.0, 1.0, 1.0).unwrap();
        assert_relative_eq!(o.localisation, 2.75, epsilon = 1e-12);
        assert_relative_eq!(o.cardinality, 5.0, epsilon = 1e-12);
    }

    #[test]
    fn hand_case_order_q_two() {
        let (truth, est) = scenario();
        // q = 2: d̃(A, E) = √((100 + 1 + 1 + 100) / 4) = √50.5; d̃(B, E) = 10.
        // p = 1: (√50.5 + 10) / 2.
        let d = ospa2(&truth, &est, 0..4, 10.0, 1.0, 2.0).unwrap();
        assert_relative_eq!(d, (50.5f64.sqrt() + 10.0) / 2.0, epsilon = 1e-12);
    }

    #[test]
    fn window_restricts_steps_and_tracks() {
        let (truth, est) = scenario();
        // Window 1..3: d̃(A, E) = (1 + 1) / 2 = 1; d̃(B, E) = 10 → (1 + 10) / 2 = 5.5.
        let d = ospa2(&truth, &est, 1..3, 10.0, 1.0, 1.0).unwrap();
        assert_relative_eq!(d, 5.5, epsilon = 1e-12);
        // Window 0..1: E absent, so it is not in the estimated set → c.
        let d = ospa2(&truth, &est, 0..1, 10.0, 1.0, 1.0).unwrap();
        assert_relative_eq!(d, 10.0, epsilon = 1e-12);
        // Window past every track, and an empty window: nothing on either side → 0.
        assert_eq!(ospa2(&truth, &est, 4..9, 10.0, 1.0, 1.0).unwrap(), 0.0);
        assert_eq!(ospa2(&truth, &est, 2..2, 10.0, 1.0, 1.0).unwrap(), 0.0);
        // An unbounded window ends where the data ends: same as 0..4.
        let d = ospa2(&truth, &est, 0..usize::MAX, 10.0, 1.0, 1.0).unwrap();
        assert_relative_eq!(d, 7.75, epsilon = 1e-12);
    }

    #[test]
    fn sliding_series_hand_case() {
        let (truth, est) = scenario();
        // window_len = 2, c = 10, p = q = 1:
        // k = 0, steps {0}:    E absent → 10.
        // k = 1, steps {0, 1}: d̃(A, E) = (10 + 1)/2 = 5.5, d̃(B, E) = 10 → (5.5 + 10)/2 = 7.75.
        // k = 2, steps {1, 2}: d̃(A, E) = 1 → (1 + 10)/2 = 5.5.
        // k = 3, steps {2, 3}: d̃(A, E) = (1 + 10)/2 = 5.5 → 7.75.
        let s = ospa2_series(&truth, &est, 2, 10.0, 1.0, 1.0).unwrap();
        assert_eq!(s.len(), 4);
        for (got, want) in s.iter().zip([10.0, 7.75, 5.5, 7.75]) {
            assert_relative_eq!(*got, want, epsilon = 1e-12);
        }
    }

    #[test]
    fn perfect_tracking_is_zero_and_empty_is_fine() {
        let (truth, _) = scenario();
        let copy: Vec<TrackHistory<Label>> = truth
            .iter()
            .map(|t| TrackHistory::new(Label::new(0, t.id as u32), t.states.clone()))
            .collect();
        assert_eq!(ospa2(&truth, &copy, 0..4, 10.0, 2.0, 1.0).unwrap(), 0.0);
        let none: Vec<TrackHistory> = Vec::new();
        assert_eq!(ospa2(&none, &none, 0..10, 5.0, 1.0, 1.0).unwrap(), 0.0);
        assert_eq!(ospa2(&truth, &none, 0..4, 5.0, 1.0, 1.0).unwrap(), 5.0);
        assert!(ospa2_series(&none, &none, 3, 5.0, 1.0, 1.0)
            .unwrap()
            .is_empty());
    }

    #[test]
    fn invalid_inputs_are_errors() {
        let (truth, est) = scenario();
        assert!(ospa2(&truth, &est, 0..4, 0.0, 1.0, 1.0).is_err());
        assert!(ospa2(&truth, &est, 0..4, 1.0, 1.0, 0.5).is_err());
        assert!(ospa2_series(&truth, &est, 0, 1.0, 1.0, 1.0).is_err());
        let bad = vec![track(Label::new(0, 0), 2, 0..2, f64::NAN)];
        assert!(ospa2(&truth, &bad, 0..4, 1.0, 1.0, 1.0).is_err());
        // A bad state outside the window is not looked at.
        assert!(ospa2(&truth, &bad, 2..4, 1.0, 1.0, 1.0).is_ok());
    }

    #[test]
    fn frames_regroup_into_tracks() {
        let frames = vec![
            vec![(7u64, vec![0.0]), (3, vec![5.0])],
            vec![(3, vec![6.0])],
            vec![(7, vec![2.0])],
        ];
        let t = tracks_from_frames(&frames).unwrap();
        assert_eq!(t.len(), 2);
        assert_eq!(t[0].id, 3);
        assert_eq!(t[0].states, vec![Some(vec![5.0]), Some(vec![6.0])]);
        assert_eq!(t[1].id, 7);
        assert_eq!(t[1].states, vec![Some(vec![0.0]), None, Some(vec![2.0])]);
        let dup = vec![vec![(1u64, vec![0.0]), (1, vec![1.0])]];
        assert!(tracks_from_frames(&dup).is_err());
    }
}
