//! Measurement-guided sampling of a Gaussian birth term: draws the term's particles from a
//! defensive mixture of the term's own density and, for each measurement of the step that no
//! existing track explains, the term's density conditioned on that measurement, and weights
//! each particle by prior density / mixture density. The weighted set represents the same
//! birth density as plain sampling (an importance sample, self-normalised), only with its
//! particles where the update will look. Not for: choosing existence probabilities or terms
//! (that is the birth model's own business), nor for nonlinear measurements.
//!
//! The measurement is linear-Gaussian in some state components (`z_k = x[observed[k]] + v_k`,
//! `v_k ~ N(0, σ_k²)`) and the term's Gaussian is diagonal, so the conditional density is
//! Gaussian in closed form, component by component: variance `s²σ²/(s² + σ²)`, mean
//! `m + s²/(s² + σ²)·(z − m)`; unobserved components keep the prior.
//!
//! Other measurements (range-bearing, boxes) can use it once converted to points in the
//! observed components, with the converted points' spread as noise: any conversion keeps the
//! sample unbiased, since the weights involve only the term's density and the mixture actually
//! sampled, never the measurement model; a poor conversion only wastes particles.
//!
//! The mixture is allocated deterministically (stratified): `n_j` particles from component
//! `j`, with the mixture coefficients exactly `n_j / n`, so the weights b(x)/q(x) with
//! q = Σ_j (n_j/n)·q_j are those of the deterministic-mixture (balance heuristic) estimator,
//! unbiased for every integral of the birth density. The prior keeps at least
//! `prior_share · n` particles, so no weight exceeds `1 / prior_share` times the mean.

use super::{BirthTerm, CurrentMeasurements};
use crate::error::{ensure_finite, Error, Result};
use crate::filter::{Measurements, ParticleSet};
use crate::numerics::exp::exp_in_place;
use crate::rng::FilterRng;
use rand_distr::{Distribution, StandardNormal};

/// Default share of a term's particles drawn from the term's own density: 0.2, so that no
/// importance weight exceeds five times the mean weight (defensive importance sampling,
/// Hesterberg 1995), while four in five particles can go where measurements are.
pub const DEFAULT_PRIOR_SHARE: f64 = 0.2;

/// A measurement is considered for a term when each observed component lies within this many
/// standard deviations of the term's predicted measurement (the prior puts less than 6·10⁻⁷
/// of its mass beyond, per component).
const GATE_SIGMAS: f64 = 5.0;

/// Particles per block of the weight computation (bounds its buffers whatever the count).
const CHUNK: usize = 4096;

/// How the measurements observe the state, for guiding birth particles to them: measurement
/// component `k` is state component `observed[k]` plus Gaussian noise of standard deviation
/// `noise_std[k]` (the built-in position measurement with the built-in state layouts:
/// `observed = [0, 2]` or `[0, 2, 4]`).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BirthProposal {
    observed: Vec<usize>,
    noise_std: Vec<f64>,
    prior_share: f64,
}

impl BirthProposal {
    /// A proposal for measurements `z_k = x[observed[k]] + N(0, noise_std[k]²)`, with
    /// [`DEFAULT_PRIOR_SHARE`]. The observed components must be distinct, the noise finite
    /// and positive.
    pub fn new(observed: Vec<usize>, noise_std: Vec<f64>) -> Result<Self> {
        if observed.is_empty() || observed.len() != noise_std.len() {
            return Err(Error::invalid(
                "birth proposal",
                "observed components and noise must have the same, positive length",
            ));
        }
        for (i, c) in observed.iter().enumerate() {
            if observed[..i].contains(c) {
                return Err(Error::invalid(
                    "birth proposal",
                    format!("state component {c} is observed twice"),
                ));
            }
        }
        ensure_finite("birth proposal noise", &noise_std)?;
        if noise_std.iter().any(|s| *s <= 0.0) {
            return Err(Error::invalid(
                "birth proposal",
                "measurement noise must be positive",
            ));
        }
        Ok(BirthProposal {
            observed,
            noise_std,
            prior_share: DEFAULT_PRIOR_SHARE,
        })
    }

    /// The same with another share of particles kept on the prior, in (0, 1] (1 samples the
    /// prior only).
    pub fn with_prior_share(mut self, share: f64) -> Result<Self> {
        if !(share > 0.0 && share <= 1.0) {
            return Err(Error::invalid(
                "birth proposal prior share",
                format!("{share} outside (0, 1]"),
            ));
        }
        self.prior_share = share;
        Ok(self)
    }

    /// The share of particles drawn from the prior.
    pub fn prior_share(&self) -> f64 {
        self.prior_share
    }

    /// The observed state components.
    pub fn observed(&self) -> &[usize] {
        &self.observed
    }

    /// Checks that the observed components exist in a state of `dim` components.
    pub(super) fn check_state_dim(&self, dim: usize) -> Result<()> {
        match self.observed.iter().find(|&&c| c >= dim) {
            Some(c) => Err(Error::invalid(
                "birth proposal",
                format!("observes state component {c}, the birth terms have {dim}"),
            )),
            None => Ok(()),
        }
    }

    /// `n` particles of `term`'s density, drawn from the measurement-guided mixture and
    /// weighted prior / proposal. With no usable measurement (none unexplained near the term,
    /// a measurement of another dimension, or a zero prior spread in an observed component)
    /// this is plain sampling of the prior, with equal weights.
    pub fn sample(
        &self,
        term: &BirthTerm,
        current: &CurrentMeasurements<'_>,
        n: usize,
        rng: &mut FilterRng,
    ) -> ParticleSet {
        let noise = |_: usize, k: usize| self.noise_std[k];
        let plan = self.plan(term, current.measurements, current.unexplained, &noise, n);
        sample_plan(term, &self.observed, &plan, n, rng)
    }

    /// As [`BirthProposal::sample`], with the components centred on `points` — measurements
    /// converted to the observed components (e.g. range-bearing to Cartesian) — each with its
    /// own spread: `noise_std[j · d + k]` for point `j`, component `k` of `d`. `unexplained`
    /// holds u(z) of each point's measurement (empty: all 1). Points whose spread is not
    /// finite and positive get no component.
    pub fn sample_points(
        &self,
        term: &BirthTerm,
        points: &Measurements,
        noise_std: &[f64],
        unexplained: &[f64],
        n: usize,
        rng: &mut FilterRng,
    ) -> ParticleSet {
        let d = points.dim();
        let noise = |j: usize, k: usize| noise_std.get(j * d + k).copied().unwrap_or(f64::NAN);
        let plan = self.plan(term, points, unexplained, &noise, n);
        sample_plan(term, &self.observed, &plan, n, rng)
    }

    /// The mixture for one term: the conditional components and their particle counts;
    /// `noise(j, k)` is the spread of point `j` in observed component `k`.
    fn plan(
        &self,
        term: &BirthTerm,
        z: &Measurements,
        unexplained: &[f64],
        noise: &dyn Fn(usize, usize) -> f64,
        n: usize,
    ) -> Plan {
        let obs = &self.observed;
        let empty = Plan {
            components: Vec::new(),
            prior_count: n,
        };
        if z.is_empty() || z.dim() != obs.len() || obs.iter().any(|&c| term.std[c] <= 0.0) {
            return empty;
        }
        // Per observed component: prior variance s², predictive variance s² + σ², gain.
        let s2: Vec<f64> = obs.iter().map(|&c| term.std[c] * term.std[c]).collect();
        // Candidates: (measurement, log of u_j times its prior predictive density).
        let mut cand: Vec<(usize, f64)> = Vec::new();
        let mut total_u = 0.0;
        for (j, zj) in z.iter().enumerate() {
            let u = unexplained.get(j).copied().unwrap_or(1.0);
            if !(u > 0.0 && u <= 1.0) {
                continue;
            }
            let mut log_pred = u.ln();
            let mut inside = true;
            for (k, &c) in obs.iter().enumerate() {
                let nz = noise(j, k);
                let pred_var = s2[k] + nz * nz;
                let d = zj[k] - term.mean[c];
                if !(nz > 0.0 && pred_var.is_finite()) || d.abs() > GATE_SIGMAS * pred_var.sqrt() {
                    inside = false;
                    break;
                }
                log_pred -= 0.5 * (d * d / pred_var + pred_var.ln());
            }
            if inside {
                cand.push((j, log_pred));
                total_u += u;
            }
        }
        if cand.is_empty() {
            return empty;
        }
        // Share of the particles near measurements: (1 − prior_share) when at least one
        // unexplained measurement is expected near the term, less when fewer are.
        let share = (1.0 - self.prior_share) * total_u.min(1.0);
        let top = cand.iter().map(|c| c.1).fold(f64::NEG_INFINITY, f64::max);
        let total: f64 = cand.iter().map(|c| (c.1 - top).exp()).sum();
        let budget = share * n as f64;
        let mut components = Vec::new();
        let mut used = 0;
        for (j, lp) in cand {
            // Whole particles only: a component expected to get less than one is left out.
            let count = (budget * (lp - top).exp() / total).floor() as usize;
            if count == 0 {
                continue;
            }
            let zj = z.get(j);
            let mut mean = Vec::with_capacity(obs.len());
            let mut post_var = Vec::with_capacity(obs.len());
            for (k, &c) in obs.iter().enumerate() {
                let (m, nz) = (term.mean[c], noise(j, k));
                let pred_var = s2[k] + nz * nz;
                mean.push(m + s2[k] / pred_var * (zj[k] - m));
                post_var.push(s2[k] * nz * nz / pred_var);
            }
            used += count;
            components.push(Component {
                mean,
                post_var,
                count,
            });
        }
        Plan {
            components,
            prior_count: n - used,
        }
    }
}

/// One conditional component: its mean and variance in the observed components and its
/// particle count.
struct Component {
    mean: Vec<f64>,
    post_var: Vec<f64>,
    count: usize,
}

/// A term's mixture: the conditional components and the count drawn from the prior.
struct Plan {
    components: Vec<Component>,
    prior_count: usize,
}

/// Draws the plan's particles (prior first, then each component in order) and weights them.
fn sample_plan(
    term: &BirthTerm,
    observed: &[usize],
    plan: &Plan,
    n: usize,
    rng: &mut FilterRng,
) -> ParticleSet {
    let mut set = ParticleSet::zeroed(term.mean.len(), n);
    let p0 = plan.prior_count;
    for (c, (&m, &s)) in term.mean.iter().zip(&term.std).enumerate() {
        let k = observed.iter().position(|&o| o == c);
        let v = set.component_mut(c);
        let (prior, rest) = v.split_at_mut(p0);
        for x in prior.iter_mut() {
            let e: f64 = StandardNormal.sample(rng);
            *x = m + s * e;
        }
        let mut rest = rest;
        for comp in &plan.components {
            let (block, tail) = rest.split_at_mut(comp.count);
            rest = tail;
            let (mean, std) = match k {
                Some(k) => (comp.mean[k], comp.post_var[k].sqrt()),
                None => (m, s),
            };
            for x in block.iter_mut() {
                let e: f64 = StandardNormal.sample(rng);
                *x = mean + std * e;
            }
        }
    }
    if plan.components.is_empty() {
        return set;
    }
    // w = b(x) / q(x) over the observed components only: the unobserved ones are drawn from
    // the prior in every component and cancel, and so do common constants (2π). Component by
    // component over all particles (contiguous rows, vectorised exp): row 0 holds
    // ln π₀ + ln b(xᵢ), row j the j-th conditional's ln π_j + ln q_j(xᵢ); with each particle's
    // largest entry t, b/q = e^(row₀ − t) / (π₀ · Σ_j e^(row_j − t)).
    let nf = n as f64;
    let pi0 = p0 as f64 / nf;
    let m = plan.components.len();
    let prior_var: Vec<f64> = observed.iter().map(|&c| term.std[c].powi(2)).collect();
    let prior_norm: f64 = -0.5 * prior_var.iter().map(|v| v.ln()).sum::<f64>();
    // (coefficient, mean, variance) of every row.
    let mut row_params: Vec<(f64, Vec<f64>, &[f64])> = Vec::with_capacity(m + 1);
    let prior_mean: Vec<f64> = observed.iter().map(|&c| term.mean[c]).collect();
    row_params.push((pi0.ln() + prior_norm, prior_mean, &prior_var));
    for comp in &plan.components {
        let post_norm = -0.5 * comp.post_var.iter().map(|v| v.ln()).sum::<f64>();
        let coef = (comp.count as f64 / nf).ln() + post_norm;
        row_params.push((coef, comp.mean.clone(), &comp.post_var));
    }
    let cols: Vec<&[f64]> = observed.iter().map(|&c| set.component(c)).collect();
    // Particles in blocks, so the rows take (m + 1) · CHUNK values whatever n is.
    let chunk = n.min(CHUNK);
    let mut rows = vec![0.0; (m + 1) * chunk];
    let mut top = vec![0.0; chunk];
    let mut sum = vec![0.0; chunk];
    let mut factor = vec![0.0; n];
    for (b, out) in factor.chunks_mut(chunk).enumerate() {
        let (lo, len) = (b * chunk, out.len());
        let rows = &mut rows[..(m + 1) * len];
        for (row, (coef, mean, var)) in rows.chunks_exact_mut(len).zip(&row_params) {
            row.fill(*coef);
            for ((col, mu), v) in cols.iter().zip(mean).zip(var.iter()) {
                let h = -0.5 / v;
                row.iter_mut().zip(&col[lo..lo + len]).for_each(|(l, x)| {
                    let d = x - mu;
                    *l += h * d * d;
                });
            }
        }
        let (top, sum) = (&mut top[..len], &mut sum[..len]);
        top.fill(f64::NEG_INFINITY);
        for row in rows.chunks_exact(len) {
            top.iter_mut().zip(row).for_each(|(t, l)| *t = t.max(*l));
        }
        for row in rows.chunks_exact_mut(len) {
            row.iter_mut().zip(top.iter()).for_each(|(l, t)| *l -= t);
            exp_in_place(row);
        }
        let (first, rest) = rows.split_at(len);
        sum.fill(0.0);
        for row in rest.chunks_exact(len) {
            sum.iter_mut().zip(row).for_each(|(s, e)| *s += e);
        }
        // first[i] ≤ 1 and first[i] + sum[i] ≥ 1 (the largest entry is e⁰), so w ≤ 1/π₀.
        out.iter_mut()
            .zip(first)
            .zip(sum.iter())
            .for_each(|((w, f), s)| *w = f / (pi0 * (f + s)));
    }
    set.reweight(&factor);
    set
}

#[cfg(test)]
mod tests;
