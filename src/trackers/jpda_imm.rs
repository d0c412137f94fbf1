//! Joint probabilistic data association (JPDA) over IMM tracks (CV + coordinated turn), the
//! tracker of seed 003, Sec. V.
//!
//! Each step: IMM interaction and prediction of every track ([`super::imm`]); gating of every
//! measurement against each track's moment-matched predicted measurement (d² below a χ²₂
//! threshold, gate probability P_G); clusters of tracks linked through shared measurements;
//! within a cluster the exact marginal association probabilities β_ij by enumerating every
//! feasible joint event (each track takes at most one gated measurement, each measurement goes
//! to at most one track), an event weighing
//! Π_{assigned} P_D g_ij / λ · Π_{missed} (1 − P_D P_G), with g_ij = Σ_m c̄_m N(ν_ijm; 0, S_m)
//! the mode-mixed measurement likelihood and λ the clutter density; then per model a PDA
//! update with the combined innovation ν_m = Σ_j β_ij ν_ijm and the spread-of-innovations term,
//! and the mode probabilities μ_m ∝ c̄_m [(1 − P_D P_G) + P_D/λ Σ_j N(ν_ijm; 0, S_m)].
//!
//! Clusters whose joint events would number more than `max_events` fall back to independent
//! PDA per track (each track's β as if no other track competed for its measurements); this is
//! the documented approximation and is counted in [`JpdaImmTracker::fallback_clusters`].
//!
//! Track management: a measurement outside every track's gate starts a tentative track; a
//! track counts as detected when Σ_j β_ij ≥ 0.5; confirmation M of N and deletion after 3.5 s
//! unobserved as in [`super::lifecycle`].
//!
//! The innovation diagnostics follow seed 003's appendix: the combined innovation
//! ν̄ = Σ_m c̄_m Σ_j (β_ij / c) ν_ijm with c = Σ_j β_ij, its NIS against S̄ = Σ_m c̄_m S_m, and the
//! combined position error for the RMS prediction error.
//!
//! Not for: track-oriented hypotheses over several scans (MHT).

use super::ekf::{measurement_noise, symmetrise, Gaussian, Linearisation};
use super::gnn::GATE_99;
use super::imm::{ImmConfig, ImmDensity};
use super::lifecycle::{LabelMaker, Lifecycle, LifecycleConfig};
use super::{ensure_range_bearing, Innovation, PointTracker};
use crate::error::{Error, Result};
use crate::filter::StepContext;
use crate::filter::{Estimate, Label, Measurements};
use crate::models::RangeBearing;
use nalgebra::{Matrix2, SMatrix, Vector2};

/// JPDA-IMM tuning.
#[derive(Clone, Debug, PartialEq)]
pub struct JpdaImmConfig {
    /// The sensor: noise, mounting offset, bearing convention.
    pub sensor: RangeBearing,
    /// The two motion models and their switching.
    pub imm: ImmConfig,
    /// Velocity standard deviation of a new track (m/s). Default 1.
    pub velocity_std: f64,
    /// Detection probability P_D. Default 0.9.
    pub detection: f64,
    /// Gate on d². Default χ²₂(0.99) = 9.21, so P_G = 0.99.
    pub gate: f64,
    /// Clutter density λ (per m·rad of measurement space). Default 1 / (π · 30).
    pub clutter_density: f64,
    /// Largest number of joint events enumerated in one cluster. Default 100 000.
    pub max_events: usize,
    /// Confirmation and deletion.
    pub lifecycle: LifecycleConfig,
}

impl JpdaImmConfig {
    /// Defaults for `sensor`.
    pub fn new(sensor: RangeBearing) -> Self {
        JpdaImmConfig {
            sensor,
            imm: ImmConfig::default(),
            velocity_std: 1.0,
            detection: 0.9,
            gate: GATE_99,
            clutter_density: 1.0 / (std::f64::consts::PI * 30.0),
            max_events: 100_000,
            lifecycle: LifecycleConfig::default(),
        }
    }

    fn validate(&self) -> Result<()> {
        self.imm.validate()?;
        crate::error::ensure_positive("JPDA velocity_std", self.velocity_std)?;
        crate::error::ensure_positive("JPDA gate", self.gate)?;
        crate::error::ensure_positive("JPDA clutter density", self.clutter_density)?;
        if !(self.detection > 0.0 && self.detection < 1.0) || self.max_events == 0 {
            return Err(Error::invalid(
                "JPDA",
                format!(
                    "P_D {}, max_events {} (need 0 < P_D < 1, max_events ≥ 1)",
                    self.detection, self.max_events
                ),
            ));
        }
        self.lifecycle.validate()
    }

    /// P_G of the χ²₂ gate: 1 − exp(−γ/2).
    pub fn gate_probability(&self) -> f64 {
        1.0 - (-0.5 * self.gate).exp()
    }
}

#[derive(Clone, Debug)]
struct ImmTrack {
    label: Label,
    density: ImmDensity,
    life: Lifecycle,
    born_step: u32,
}

/// Per track and step: the linearised predicted measurement of each model and of the
/// combined density.
struct Predicted {
    models: [Linearisation<5>; 2],
    combined: Linearisation<5>,
}

/// The JPDA-IMM tracker.
#[derive(Clone, Debug)]
pub struct JpdaImmTracker {
    config: JpdaImmConfig,
    tracks: Vec<ImmTrack>,
    labels: LabelMaker,
    innovations: Vec<Innovation>,
    fallback_clusters: usize,
}

/// Exact marginals β (row i: [miss, measurement 0, …]) of the tracks `rows` over the
/// measurements `cols` by enumerating the joint events; `weight[i][j]` is the weight of track
/// `rows[i]` taking `cols[j]` (0 outside the gate) and `miss` that of a missed track.
pub fn exact_marginals(weight: &[Vec<f64>], miss: f64) -> Vec<Vec<f64>> {
    let n = weight.len();
    let m = weight.first().map_or(0, |w| w.len());
    let mut beta = vec![vec![0.0; m + 1]; n];
    let mut choice = vec![0usize; n];
    let mut used = vec![false; m];
    fn visit(
        i: usize,
        w: f64,
        weight: &[Vec<f64>],
        miss: f64,
        choice: &mut [usize],
        used: &mut [bool],
        beta: &mut [Vec<f64>],
    ) {
        if i == weight.len() {
            for (row, &c) in beta.iter_mut().zip(choice.iter()) {
                row[c] += w;
            }
            return;
        }
        choice[i] = 0;
        visit(i + 1, w * miss, weight, miss, choice, used, beta);
        for j in 0..used.len() {
            if !used[j] && weight[i][j] > 0.0 {
                used[j] = true;
                choice[i] = j + 1;
                visit(i + 1, w * weight[i][j], weight, miss, choice, used, beta);
                used[j] = false;
            }
        }
    }
    visit(0, 1.0, weight, miss, &mut choice, &mut used, &mut beta);
    normalise_rows(&mut beta);
    beta
}

/// Independent PDA marginals (the fallback for oversized clusters).
pub fn independent_marginals(weight: &[Vec<f64>], miss: f64) -> Vec<Vec<f64>> {
    let mut beta: Vec<Vec<f64>> = weight
        .iter()
        .map(|row| std::iter::once(miss).chain(row.iter().copied()).collect())
        .collect();
    normalise_rows(&mut beta);
    beta
}

fn normalise_rows(beta: &mut [Vec<f64>]) {
    for row in beta {
        let total: f64 = row.iter().sum();
        if total > 0.0 && total.is_finite() {
            row.iter_mut().for_each(|b| *b /= total);
        } else {
            row.iter_mut().for_each(|b| *b = 0.0);
            row[0] = 1.0;
        }
    }
}

/// Number of joint events of a cluster, saturating at `cap + 1`: a product bound
/// Π_i (1 + gated_i).
fn event_bound(gated: &[usize], cap: usize) -> usize {
    gated
        .iter()
        .try_fold(1usize, |acc, &g| {
            let v = acc.saturating_mul(g + 1);
            (v <= cap).then_some(v)
        })
        .unwrap_or(cap + 1)
}

impl JpdaImmTracker {
    /// A tracker with no tracks.
    pub fn new(config: JpdaImmConfig) -> Result<Self> {
        config.validate()?;
        Ok(JpdaImmTracker {
            config,
            tracks: Vec::new(),
            labels: LabelMaker::default(),
            innovations: Vec::new(),
            fallback_clusters: 0,
        })
    }

    /// Clusters handled by the independent-PDA fallback so far.
    pub fn fallback_clusters(&self) -> usize {
        self.fallback_clusters
    }

    /// Current mode probabilities [CV, CT] of every track, with labels.
    pub fn modes(&self) -> Vec<(Label, [f64; 2])> {
        self.tracks
            .iter()
            .map(|t| (t.label, t.density.modes))
            .collect()
    }

    /// β for every track (row: [miss, measurement 0, …, measurement m−1]).
    fn association(&mut self, lik: &[Vec<f64>], gated: &[Vec<bool>], m: usize) -> Vec<Vec<f64>> {
        let cfg = &self.config;
        let n = self.tracks.len();
        let miss = 1.0 - cfg.detection * cfg.gate_probability();
        // Clusters: union-find over tracks sharing a gated measurement.
        let mut owner: Vec<usize> = (0..n).collect();
        fn root(o: &mut [usize], mut i: usize) -> usize {
            while o[i] != i {
                o[i] = o[o[i]];
                i = o[i];
            }
            i
        }
        for j in 0..m {
            let mut first = None;
            for (i, row) in gated.iter().enumerate() {
                if row[j] {
                    match first {
                        None => first = Some(i),
                        Some(f) => {
                            let (a, b) = (root(&mut owner, f), root(&mut owner, i));
                            owner[a.max(b)] = a.min(b);
                        }
                    }
                }
            }
        }
        let mut beta = vec![vec![0.0; m + 1]; n];
        let mut done = vec![false; n];
        for start in 0..n {
            if done[start] {
                continue;
            }
            let r = root(&mut owner, start);
            let rows: Vec<usize> = (0..n).filter(|&i| root(&mut owner, i) == r).collect();
            let cols: Vec<usize> = (0..m)
                .filter(|&j| rows.iter().any(|&i| gated[i][j]))
                .collect();
            let weight: Vec<Vec<f64>> = rows
                .iter()
                .map(|&i| {
                    cols.iter()
                        .map(|&j| {
                            if gated[i][j] {
                                cfg.detection * lik[i][j] / cfg.clutter_density
                            } else {
                                0.0
                            }
                        })
                        .collect()
                })
                .collect();
            let counts: Vec<usize> = rows
                .iter()
                .map(|&i| cols.iter().filter(|&&j| gated[i][j]).count())
                .collect();
            let local = if event_bound(&counts, cfg.max_events) <= cfg.max_events {
                exact_marginals(&weight, miss)
            } else {
                self.fallback_clusters += 1;
                independent_marginals(&weight, miss)
            };
            for (row, &i) in local.iter().zip(&rows) {
                done[i] = true;
                beta[i][0] = row[0];
                for (b, &j) in row[1..].iter().zip(&cols) {
                    beta[i][j + 1] = *b;
                }
            }
        }
        beta
    }
}

impl PointTracker for JpdaImmTracker {
    fn name(&self) -> &str {
        "jpda_imm"
    }

    fn step(&mut self, z: &Measurements, ctx: &StepContext) -> Result<Vec<Estimate>> {
        ensure_range_bearing(z)?;
        self.innovations.clear();
        self.labels.start_step(ctx.step);
        let (sensor, imm) = (self.config.sensor, self.config.imm);
        for t in &mut self.tracks {
            t.density.predict(ctx.dt, &imm);
        }
        // Tracks whose prediction cannot be linearised (on the sensor) are dropped.
        let mut predicted = Vec::with_capacity(self.tracks.len());
        self.tracks.retain(|t| {
            let p = (|| {
                Some(Predicted {
                    models: [
                        Linearisation::new(&t.density.models[0], &sensor, ctx)?,
                        Linearisation::new(&t.density.models[1], &sensor, ctx)?,
                    ],
                    combined: Linearisation::new(&t.density.combined(), &sensor, ctx)?,
                })
            })();
            let keep = p.is_some();
            predicted.extend(p);
            keep
        });
        let (n, m) = (self.tracks.len(), z.len());
        let gate = self.config.gate;
        let gated: Vec<Vec<bool>> = predicted
            .iter()
            .map(|p| {
                z.iter()
                    .map(|zj| p.combined.mahalanobis2(&p.combined.innovation(zj)) < gate)
                    .collect()
            })
            .collect();
        // Per model and measurement: N(ν; 0, S_m); the mode-mixed likelihood g_ij.
        let model_lik: Vec<Vec<[f64; 2]>> = predicted
            .iter()
            .map(|p| {
                z.iter()
                    .map(|zj| {
                        let f = |l: &Linearisation<5>| l.log_likelihood(&l.innovation(zj)).exp();
                        [f(&p.models[0]), f(&p.models[1])]
                    })
                    .collect()
            })
            .collect();
        let lik: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                let c = self.tracks[i].density.modes;
                model_lik[i]
                    .iter()
                    .map(|l| c[0] * l[0] + c[1] * l[1])
                    .collect()
            })
            .collect();
        let beta = self.association(&lik, &gated, m);
        let cfg = &self.config;
        let miss = 1.0 - cfg.detection * cfg.gate_probability();
        let r = measurement_noise(&sensor);
        for (i, track) in self.tracks.iter_mut().enumerate() {
            let b = &beta[i];
            let c: f64 = b[1..].iter().sum();
            let cbar = track.density.modes;
            let mut mode_lik = [miss; 2];
            let mut nu_bar = Vector2::zeros();
            let mut s_bar = Matrix2::zeros();
            let mut pos_err = [0.0; 2];
            for (k, g) in track.density.models.iter_mut().enumerate() {
                let lin = &predicted[i].models[k];
                let nus: Vec<Vector2<f64>> = z.iter().map(|zj| lin.innovation(zj)).collect();
                let mut nu = Vector2::zeros();
                let mut spread = Matrix2::zeros();
                for j in 0..m {
                    if gated[i][j] {
                        nu += nus[j] * b[j + 1];
                        spread += nus[j] * nus[j].transpose() * b[j + 1];
                        mode_lik[k] += cfg.detection * model_lik[i][j][k] / cfg.clutter_density;
                        if c > 0.0 {
                            let p = sensor.to_cartesian([z.get(j)[0], z.get(j)[1]], ctx);
                            let w = cbar[k] * b[j + 1] / c;
                            pos_err[0] += w * (p[0] - g.mean[0]);
                            pos_err[1] += w * (p[1] - g.mean[2]);
                        }
                    }
                }
                if c > 0.0 {
                    nu_bar += nu * (cbar[k] / c);
                }
                s_bar += lin.s * cbar[k];
                let kg: SMatrix<f64, 5, 2> = lin.gain(g);
                let i_kh = SMatrix::<f64, 5, 5>::identity() - kg * lin.h;
                let updated = i_kh * g.cov * i_kh.transpose() + kg * r * kg.transpose();
                let mut cov = g.cov * b[0]
                    + updated * (1.0 - b[0])
                    + kg * (spread - nu * nu.transpose()) * kg.transpose();
                symmetrise(&mut cov);
                *g = Gaussian {
                    mean: g.mean + kg * nu,
                    cov,
                };
            }
            track.density.update_modes(mode_lik);
            let detected = c >= 0.5;
            if detected {
                if let Some(s_inv) = s_bar.try_inverse() {
                    self.innovations.push(Innovation {
                        label: track.label,
                        position_error: pos_err,
                        nis: (nu_bar.transpose() * s_inv * nu_bar)[(0, 0)],
                    });
                }
            }
            track.life.record(detected, ctx.time, &cfg.lifecycle);
        }
        let lifecycle = cfg.lifecycle;
        self.tracks
            .retain(|t| !t.life.is_dead(ctx.time, &lifecycle));
        for (j, zj) in z.iter().enumerate() {
            if (0..n).all(|i| !gated[i][j]) {
                let g = Gaussian::from_measurement([zj[0], zj[1]], &sensor, ctx, cfg.velocity_std);
                self.tracks.push(ImmTrack {
                    label: self.labels.next_label(),
                    density: ImmDensity::from_cv(&g, &imm),
                    life: Lifecycle::born(ctx.time),
                    born_step: ctx.step,
                });
            }
        }
        Ok(self
            .tracks
            .iter()
            .filter(|t| t.life.confirmed())
            .map(|t| Estimate {
                label: t.label,
                existence: 1.0,
                state: t.density.combined().mean_vec(),
                age: ctx.step - t.born_step,
            })
            .collect())
    }

    fn innovations(&self) -> &[Innovation] {
        &self.innovations
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trackers::gnn::tests::{
        check_crossing, check_deletion, check_single_target, sensor,
    };

    fn tracker() -> JpdaImmTracker {
        JpdaImmTracker::new(JpdaImmConfig::new(sensor())).unwrap()
    }

    #[test]
    fn single_target_one_label_small_error() {
        check_single_target(&mut tracker());
    }

    #[test]
    fn crossing_targets_keep_labels() {
        check_crossing(&mut tracker());
    }

    #[test]
    fn deleted_after_3_5_s_unobserved() {
        check_deletion(&mut tracker());
    }

    #[test]
    fn exact_marginals_by_hand() {
        // Two tracks, two measurements; weights a_ij and miss weight q = 1:
        // track 0: [2, 1], track 1: [0, 3]. Events (t0, t1):
        // (–,–) 1, (–,1) 3, (0,–) 2, (0,1) 6, (1,–) 1  → total 13
        let beta = exact_marginals(&[vec![2.0, 1.0], vec![0.0, 3.0]], 1.0);
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(close(beta[0][0], 4.0 / 13.0) && close(beta[0][1], 8.0 / 13.0));
        assert!(close(beta[0][2], 1.0 / 13.0));
        assert!(close(beta[1][0], 4.0 / 13.0) && close(beta[1][2], 9.0 / 13.0));
        assert_eq!(beta[1][1], 0.0);
        // the independent fallback ignores the competition: track 0 → [1, 2, 1] / 4
        let ind = independent_marginals(&[vec![2.0, 1.0], vec![0.0, 3.0]], 1.0);
        assert!(close(ind[0][1], 0.5));
    }

    #[test]
    fn event_bound_saturates() {
        assert_eq!(event_bound(&[1, 2], 100), 6);
        assert_eq!(event_bound(&[9, 9, 9], 100), 101);
    }

    #[test]
    fn a_turning_target_raises_the_turn_mode() {
        // walking a circle of radius 3 m at 1.2 m/s (ω = 0.4 rad/s) around (8, 0)
        let circle = |t: f64| vec![[8.0 + 3.0 * (0.4 * t).cos(), 3.0 * (0.4 * t).sin()]];
        let straight = |t: f64| vec![[6.0 + 0.5 * t, -2.0 + 0.7 * t]];
        let mut a = tracker();
        crate::trackers::gnn::tests::run(&mut a, 80, circle, |_| true);
        let mut b = tracker();
        crate::trackers::gnn::tests::run(&mut b, 80, straight, |_| true);
        let ct = |t: &JpdaImmTracker| t.modes()[0].1[1];
        assert!(ct(&a) > ct(&b), "turning {} vs straight {}", ct(&a), ct(&b));
    }
}
