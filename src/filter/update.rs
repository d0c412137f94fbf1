//! One sensor's LMB update of a set of predicted tracks: gating and the particle sums of every
//! (track, measurement) pair, the association marginals of independent groups, and each
//! track's posterior from its marginals (the LMB approximation of the GLMB posterior, Reuter
//! et al. 2014). The filter runs it once per step with one sensor, and once per sensor with
//! several (see [`super::fusion`]).
//!
//! Not for: prediction, births, resampling or the order of a step's stages (see
//! [`super::lmb`]).

use super::association::{AssociationProblem, Associator, Marginals};
use super::fusion::SensorPosterior;
use super::groups::partition;
use super::sensor::Sensor;
use super::track::Track;
use super::Measurements;
use crate::error::{Error, Result};
use crate::filter::{StepContext, TrackSummary};
use crate::rng::stream;
use rayon::prelude::*;

/// Stream key of the association stage, combined with a group's key (and, for sensors after
/// the first, the sensor's).
pub(crate) const KEY_ASSOCIATE: u64 = 0x03 << 60;

/// Per-track quantities of one update: detection probabilities and the likelihood of every
/// gated measurement, all in the log domain.
pub(crate) struct TrackLikelihoods {
    /// p_D(xᵢ), clamped to [0, 1].
    pub(crate) pd: Vec<f64>,
    /// η_miss = Σ wᵢ (1 − p_D(xᵢ)) (no underflow risk: a plain sum of probabilities).
    pub(crate) eta_miss: f64,
    /// The gated measurements some particle can explain, in the gate's order. One entry per
    /// pair, so a pair's index and its sums cannot come apart.
    pub(crate) pairs: Vec<GatedPair>,
}

/// One (track, gated measurement) pair with positive likelihood.
pub(crate) struct GatedPair {
    /// Index of the measurement in the step's set.
    pub(crate) measurement: usize,
    /// ln η = ln Σ wᵢ p_D(xᵢ) g(z | xᵢ) (without κ).
    pub(crate) log_eta: f64,
    /// The likelihoods scaled by their largest value, exp(ln g(z | xᵢ) − maxₖ ln g(z | xₖ)),
    /// so the best particle has 1 whatever the scale.
    pub(crate) scaled_g: Vec<f64>,
    /// Σ wᵢ p_D(xᵢ) · scaled_g[i], positive.
    pub(crate) scaled_eta: f64,
}

/// A track's row of association marginals, in its own terms.
pub(crate) struct TrackMarginals {
    pub(crate) miss: f64,
    /// (index into `TrackLikelihoods::pairs`, probability).
    pub(crate) detect: Vec<(usize, f64)>,
}

impl TrackMarginals {
    /// The measurement (its index in the step's measurements) this track most probably
    /// generated, with that probability; `lik` is the same track's row of likelihoods.
    pub(crate) fn most_probable(&self, lik: &TrackLikelihoods) -> Option<(usize, f64)> {
        let best = self.detect.iter().max_by(|a, b| a.1.total_cmp(&b.1));
        best.map(|&(k, p)| (lik.pairs[k].measurement, p))
    }
}

/// Gating and the particle sums η_j(ℓ) and η_miss(ℓ) for every track, in parallel; the
/// tracks that `summaries` covers (the predicted ones) are gated by them, this step's
/// births by their own. A measurement model that returns NaN or +∞ as a log-likelihood is
/// an error naming the track and measurement (the first in track order); −∞ is a valid
/// "impossible".
pub(crate) fn likelihoods(
    tracks: &[Track],
    m: &Sensor,
    z: &Measurements,
    ctx: &StepContext,
    summaries: &[TrackSummary],
) -> Result<Vec<TrackLikelihoods>> {
    let step = ctx.step;
    let all: Vec<Result<TrackLikelihoods>> = tracks
        .par_iter()
        .enumerate()
        .map(|(k, t)| {
            let p = &t.particles;
            let n = p.len();
            let mut pd = vec![0.0; n];
            m.detection.detection_probability(p, ctx, &mut pd);
            pd.iter_mut()
                .for_each(|d| *d = if d.is_nan() { 0.0 } else { d.clamp(0.0, 1.0) });
            let w = p.weights();
            let eta_miss: f64 = w.iter().zip(&pd).map(|(w, d)| w * (1.0 - d)).sum();
            let detectable = w.iter().zip(&pd).any(|(w, d)| w * d > 0.0);
            let mut gated: Vec<usize> = Vec::new();
            if detectable && !z.is_empty() {
                match summaries.get(k) {
                    Some(s) => m.measurement.gate_all(z, s, ctx, &mut gated),
                    None => m
                        .measurement
                        .gate_all(z, &TrackSummary::of(p), ctx, &mut gated),
                }
            }
            let zs: Vec<&[f64]> = gated.iter().map(|&j| z.get(j)).collect();
            let mut scaled_g = vec![vec![0.0; n]; zs.len()];
            let mut tops = vec![f64::NEG_INFINITY; zs.len()];
            if let Err(f) =
                m.measurement
                    .relative_likelihood_batch(&zs, p, ctx, &mut scaled_g, &mut tops)
            {
                return Err(Error::invalid(
                    format!("update of step {step}"),
                    format!(
                        "the measurement model's log-likelihood of measurement {} for \
                         particle {} of track {} is {}",
                        gated.get(f.measurement).copied().unwrap_or(f.measurement),
                        f.particle,
                        t.label,
                        f.value
                    ),
                ));
            }
            let mut pairs = Vec::with_capacity(zs.len());
            for ((g, measurement), top) in scaled_g.into_iter().zip(gated).zip(tops) {
                if !top.is_finite() {
                    continue; // no particle can explain it
                }
                let sum: f64 = g.iter().zip(w).zip(&pd).map(|((g, w), d)| g * w * d).sum();
                if sum > 0.0 {
                    pairs.push(GatedPair {
                        measurement,
                        log_eta: top + sum.ln(),
                        scaled_g: g,
                        scaled_eta: sum,
                    });
                }
            }
            Ok(TrackLikelihoods {
                pd,
                eta_miss,
                pairs,
            })
        })
        .collect();
    all.into_iter().collect()
}

/// Association: independent groups, each solved by the associator, in parallel.
///
/// `sensor_key` is 0 for a filter's first sensor (so that a filter with one sensor draws
/// what it always drew) and distinct for every other.
#[allow(clippy::too_many_arguments)]
pub(crate) fn associate(
    tracks: &[Track],
    sensor: &Sensor,
    associator: &dyn Associator,
    z: &Measurements,
    ctx: &StepContext,
    lik: &[TrackLikelihoods],
    seed: u64,
    sensor_key: u64,
) -> Vec<TrackMarginals> {
    let log_kappa: Vec<f64> = z
        .iter()
        .map(|zj| sensor.clutter.log_intensity(zj, ctx))
        .collect();
    let gated: Vec<Vec<usize>> = lik
        .iter()
        .map(|l| l.pairs.iter().map(|p| p.measurement).collect())
        .collect();
    let groups = partition(&gated, z.len());
    let solved: Vec<Vec<(usize, TrackMarginals)>> = groups
        .par_iter()
        .map(|g| {
            let n = g.tracks.len();
            let m = g.measurements.len();
            let mut problem = AssociationProblem {
                n_tracks: n,
                n_meas: m,
                log_miss: Vec::with_capacity(n),
                log_detect: vec![f64::NEG_INFINITY; n * m],
            };
            for (row, &ti) in g.tracks.iter().enumerate() {
                let r = tracks[ti].existence;
                let l = &lik[ti];
                problem.log_miss.push(log_miss_weight(r, l.eta_miss));
                for pair in &l.pairs {
                    let j = pair.measurement;
                    let col = g
                        .measurements
                        .binary_search(&j)
                        .expect("gated measurement in its group");
                    problem.log_detect[row * m + col] = r.ln() + pair.log_eta - log_kappa[j];
                }
            }
            let marg: Marginals = if m == 0 {
                Marginals {
                    n_tracks: n,
                    n_meas: 0,
                    miss: vec![1.0; n],
                    detect: Vec::new(),
                }
            } else {
                let key = tracks[g.tracks[0]].label.key();
                associator.marginals(
                    &problem,
                    &mut stream(seed, KEY_ASSOCIATE ^ key ^ sensor_key),
                )
            };
            g.tracks
                .iter()
                .enumerate()
                .map(|(row, &ti)| {
                    let detect = lik[ti]
                        .pairs
                        .iter()
                        .enumerate()
                        .map(|(k, pair)| {
                            let col = g
                                .measurements
                                .binary_search(&pair.measurement)
                                .expect("gated measurement in its group");
                            (k, marg.detect[row * m + col])
                        })
                        .collect();
                    (
                        ti,
                        TrackMarginals {
                            miss: marg.miss[row],
                            detect,
                        },
                    )
                })
                .collect()
        })
        .collect();
    let mut out: Vec<Option<TrackMarginals>> = (0..tracks.len()).map(|_| None).collect();
    for (ti, tm) in solved.into_iter().flatten() {
        out[ti] = Some(tm);
    }
    out.into_iter()
        .map(|o| o.expect("every track is in one group"))
        .collect()
}

/// ln(1 − r + r·η_miss); −∞ when the track surely exists and is surely detected.
fn log_miss_weight(r: f64, eta_miss: f64) -> f64 {
    (1.0 - r + r * eta_miss).max(0.0).ln()
}

/// Stream key of sensor `index` for [`associate`]: 0 for the first sensor, a distinct
/// constant for every other.
pub(crate) fn sensor_key(index: usize) -> u64 {
    (index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

/// Applies one sensor's posterior of a track to it: existence, expected detections, weights.
pub(crate) fn apply_posterior(t: &mut Track, post: SensorPosterior) {
    t.existence = post.existence;
    t.expected_detections += post.detected;
    if let (Some(factor), true) = (post.factor, post.existence > 0.0) {
        t.particles.reweight(&factor);
    }
}

/// Posterior existence and particle weight factors of one track (predicted existence `r`)
/// from its association marginals (the LMB approximation of the GLMB posterior, Reuter et al.
/// 2014, eqs. 20–21, with the miss/absence hypotheses split as in the marginal form of the
/// fast LMB update).
pub(crate) fn posterior(r: f64, l: &TrackLikelihoods, mg: &TrackMarginals) -> SensorPosterior {
    let denom = 1.0 - r + r * l.eta_miss;
    // Probability that the track exists and was missed.
    let p_missed = if denom > 0.0 {
        mg.miss * (r * l.eta_miss / denom)
    } else {
        0.0
    };
    let p_detected: f64 = mg.detect.iter().map(|(_, p)| p).sum();
    let r_post = (p_missed + p_detected).clamp(0.0, 1.0);
    let mut post = SensorPosterior {
        existence: r_post,
        detected: p_detected,
        factor: None,
    };
    if r_post <= 0.0 {
        return post;
    }
    let detected: Vec<(usize, f64)> = mg
        .detect
        .iter()
        .copied()
        .filter(|(_, p)| *p > 0.0)
        .collect();
    if detected.is_empty() && l.pd.windows(2).all(|w| w[0] == w[1]) {
        return post; // only the miss term, constant over particles: weights unchanged
    }
    // Particle i's factor: P_missed·(1 − p_D,i)/η_miss + p_D,i · Σ_j P_j·ĝ_j,i / η̂_j, where ĝ and
    // η̂ are the likelihoods and sums scaled by the same constant (which cancels). The
    // particle with ĝ = 1 of any detection term keeps a positive factor, so the set never empties.
    let miss = if p_missed > 0.0 && l.eta_miss > 0.0 {
        p_missed / l.eta_miss
    } else {
        0.0
    };
    let mut factor: Vec<f64> = l.pd.iter().map(|d| miss * (1.0 - d)).collect();
    if let Some((&(k0, p0), rest)) = detected.split_first() {
        // Σ_j P_j·ĝ_j,i / η̂_j, started from the first term (no zero-filled buffer).
        let first = &l.pairs[k0];
        let c0 = p0 / first.scaled_eta;
        let mut detect_sum: Vec<f64> = first.scaled_g.iter().map(|g| c0 * g).collect();
        for &(k, p) in rest {
            let pair = &l.pairs[k];
            let c = p / pair.scaled_eta;
            detect_sum
                .iter_mut()
                .zip(&pair.scaled_g)
                .for_each(|(s, g)| *s += c * g);
        }
        factor
            .iter_mut()
            .zip(&l.pd)
            .zip(&detect_sum)
            .for_each(|((f, d), s)| *f += d * s);
    }
    post.factor = Some(factor);
    post
}

/// For every measurement of a set of `n_meas`, the probability that some track generated it
/// (capped at one), from the tracks' likelihood rows `lik` and marginals `marg`.
pub(crate) fn assigned(
    lik: &[TrackLikelihoods],
    marg: &[TrackMarginals],
    n_meas: usize,
) -> Vec<f64> {
    let mut assigned = vec![0.0; n_meas];
    for (l, mg) in lik.iter().zip(marg) {
        for &(k, p) in &mg.detect {
            assigned[l.pairs[k].measurement] += p;
        }
    }
    assigned.iter_mut().for_each(|a| *a = a.min(1.0));
    assigned
}
