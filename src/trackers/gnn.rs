//! Global nearest neighbour (GNN) tracking with one EKF per track — the conventional tracker
//! seed 000 compares ML-RANSAC with.
//!
//! Each step: predict every track with constant velocity; gate every (track, measurement)
//! pair by the squared Mahalanobis distance d² = νᵀ S⁻¹ ν against a χ²₂ threshold; solve the
//! assignment that minimises the summed d² (Hungarian, [`crate::assignment`]), where a track may
//! also stay unassigned at the cost of the gate threshold; update assigned tracks (Joseph
//! form); start a tentative track at every unassigned measurement outside every track's gate. Tracks are confirmed after M
//! detections in their first N steps and deleted after 3.5 s unobserved
//! ([`super::lifecycle`]). Only confirmed tracks are reported.
//!
//! Not for: ambiguous crossings (it commits to one assignment per step; see
//! [`super::jpda_imm`]).

use super::ekf::{position_error, update, Gaussian, Linearisation};
use super::lifecycle::{LabelMaker, Lifecycle, LifecycleConfig};
use super::{ensure_range_bearing, Innovation, PointTracker};
use crate::error::Result;
use crate::filter::StepContext;
use crate::filter::{Estimate, Label, Measurements};
use crate::models::RangeBearing;

/// χ²₂ quantile at 0.99: the default gate on d².
pub const GATE_99: f64 = 9.2103;

/// GNN tuning.
#[derive(Clone, Debug, PartialEq)]
pub struct GnnConfig {
    /// The sensor: noise, mounting offset, bearing convention.
    pub sensor: RangeBearing,
    /// White acceleration noise of the CV model (m/s²). Default 1.
    pub sigma_accel: f64,
    /// Velocity standard deviation of a new track (m/s). Default 1.
    pub velocity_std: f64,
    /// Gate on the squared Mahalanobis distance. Default [`GATE_99`].
    pub gate: f64,
    /// Confirmation and deletion.
    pub lifecycle: LifecycleConfig,
}

impl GnnConfig {
    /// Defaults for `sensor`.
    pub fn new(sensor: RangeBearing) -> Self {
        GnnConfig {
            sensor,
            sigma_accel: 1.0,
            velocity_std: 1.0,
            gate: GATE_99,
            lifecycle: LifecycleConfig::default(),
        }
    }

    fn validate(&self) -> Result<()> {
        crate::error::ensure_non_negative("GNN sigma_accel", self.sigma_accel)?;
        crate::error::ensure_positive("GNN velocity_std", self.velocity_std)?;
        crate::error::ensure_positive("GNN gate", self.gate)?;
        self.lifecycle.validate()
    }
}

/// One EKF track.
#[derive(Clone, Debug)]
pub(crate) struct EkfTrack {
    pub(crate) label: Label,
    pub(crate) density: Gaussian<4>,
    pub(crate) life: Lifecycle,
    pub(crate) born_step: u32,
}

impl EkfTrack {
    pub(crate) fn estimate(&self, step: u32) -> Estimate {
        Estimate {
            label: self.label,
            existence: 1.0,
            state: self.density.mean_vec(),
            age: step - self.born_step,
        }
    }
}

/// The GNN tracker.
#[derive(Clone, Debug)]
pub struct GnnTracker {
    config: GnnConfig,
    tracks: Vec<EkfTrack>,
    labels: LabelMaker,
    innovations: Vec<Innovation>,
}

impl GnnTracker {
    /// A tracker with no tracks.
    pub fn new(config: GnnConfig) -> Result<Self> {
        config.validate()?;
        Ok(GnnTracker {
            config,
            tracks: Vec::new(),
            labels: LabelMaker::default(),
            innovations: Vec::new(),
        })
    }

    /// Number of tracks, tentative ones included.
    pub fn num_tracks(&self) -> usize {
        self.tracks.len()
    }
}

impl PointTracker for GnnTracker {
    fn name(&self) -> &str {
        "gnn"
    }

    fn step(&mut self, z: &Measurements, ctx: &StepContext) -> Result<Vec<Estimate>> {
        ensure_range_bearing(z)?;
        let cfg = &self.config;
        self.innovations.clear();
        self.labels.start_step(ctx.step);
        for t in &mut self.tracks {
            t.density.predict_cv(ctx.dt, cfg.sigma_accel);
        }
        let lins: Vec<_> = self
            .tracks
            .iter()
            .map(|t| Linearisation::new(&t.density, &cfg.sensor, ctx))
            .collect();
        // Rows: tracks; columns: measurements, then one "unassigned" column per track.
        let (n, m) = (self.tracks.len(), z.len());
        let cols = m + n;
        let mut cost = vec![f64::INFINITY; n * cols];
        for (i, lin) in lins.iter().enumerate() {
            if let Some(lin) = lin {
                for (j, zj) in z.iter().enumerate() {
                    let d2 = lin.mahalanobis2(&lin.innovation(zj));
                    if d2 < cfg.gate {
                        cost[i * cols + j] = d2;
                    }
                }
            }
            cost[i * cols + m + i] = cfg.gate;
        }
        let assignment = crate::assignment::solve(&cost, n, cols)
            .map(|(a, _)| a)
            .unwrap_or_else(|| (0..n).map(|i| m + i).collect());
        let mut used = vec![false; m];
        for (i, &j) in assignment.iter().enumerate() {
            let track = &mut self.tracks[i];
            let hit = j < m;
            if let (true, Some(lin)) = (hit, &lins[i]) {
                let zj = z.get(j);
                let nu = lin.innovation(zj);
                self.innovations.push(Innovation {
                    label: track.label,
                    position_error: position_error(&track.density, zj, &cfg.sensor, ctx),
                    nis: lin.mahalanobis2(&nu),
                });
                update(&mut track.density, lin, &nu, &cfg.sensor);
                used[j] = true;
            }
            track.life.record(hit, ctx.time, &cfg.lifecycle);
        }
        self.tracks
            .retain(|t| !t.life.is_dead(ctx.time, &cfg.lifecycle));
        // A measurement inside some track's gate is that track's rival, not a new object.
        let gated = |j: usize| (0..n).any(|i| cost[i * cols + j].is_finite());
        for (j, zj) in z.iter().enumerate() {
            if !used[j] && !gated(j) {
                self.tracks.push(EkfTrack {
                    label: self.labels.next_label(),
                    density: Gaussian::from_measurement(
                        [zj[0], zj[1]],
                        &cfg.sensor,
                        ctx,
                        cfg.velocity_std,
                    ),
                    life: Lifecycle::born(ctx.time),
                    born_step: ctx.step,
                });
            }
        }
        Ok(self
            .tracks
            .iter()
            .filter(|t| t.life.confirmed())
            .map(|t| t.estimate(ctx.step))
            .collect())
    }

    fn innovations(&self) -> &[Innovation] {
        &self.innovations
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::geometry::Pose2;
    use crate::trackers::StepClock;
    use std::collections::BTreeSet;

    /// Range-bearing measurements of `people` (world positions) from a sensor at `mount` on
    /// a robot at `pose`, without noise.
    pub(crate) fn measure(
        sensor: &RangeBearing,
        ctx: &StepContext,
        people: &[[f64; 2]],
    ) -> Measurements {
        let rows: Vec<[f64; 2]> = people
            .iter()
            .map(|p| sensor.predict_measurement(&[p[0], 0.0, p[1], 0.0], ctx))
            .collect();
        Measurements::from_rows(2, &rows).unwrap()
    }

    pub(crate) fn sensor() -> RangeBearing {
        RangeBearing::new(0.2, 2f64.to_radians())
            .unwrap()
            .with_offset(0.2, 0.0)
            .unwrap()
    }

    /// Runs `tracker` over `steps` scans at 8 Hz from a robot driving along +x at 0.5 m/s,
    /// people at `truth(t)`, (optionally) only while `visible(t)`. Returns the estimates.
    pub(crate) fn run(
        tracker: &mut dyn PointTracker,
        steps: usize,
        truth: impl Fn(f64) -> Vec<[f64; 2]>,
        visible: impl Fn(f64) -> bool,
    ) -> Vec<Vec<Estimate>> {
        let s = sensor();
        let mut clock = StepClock::new();
        (0..steps)
            .map(|k| {
                let t = k as f64 / 8.0;
                let ctx = clock.tick(t, Some(Pose2::new(0.5 * t, 0.0, 0.0))).unwrap();
                let z = if visible(t) {
                    measure(&s, &ctx, &truth(t))
                } else {
                    Measurements::empty(2)
                };
                tracker.step(&z, &ctx).unwrap()
            })
            .collect()
    }

    /// A single target on a straight line: one label, small error at the end.
    pub(crate) fn check_single_target(tracker: &mut dyn PointTracker) {
        let path = |t: f64| vec![[6.0 + 0.5 * t, -2.0 + 0.7 * t]];
        let est = run(tracker, 64, path, |_| true);
        let labels: BTreeSet<Label> = est[8..].iter().flatten().map(|e| e.label).collect();
        assert_eq!(labels.len(), 1, "{}: {labels:?}", tracker.name());
        let last = &est[63];
        assert_eq!(last.len(), 1);
        let t = 63.0 / 8.0;
        let e = &last[0].state;
        let err = (e[0] - (6.0 + 0.5 * t)).hypot(e[2] - (-2.0 + 0.7 * t));
        assert!(err < 0.1, "{}: position error {err}", tracker.name());
        assert!(
            (e[1] - 0.5).abs() < 0.15 && (e[3] - 0.7).abs() < 0.15,
            "{}: velocity {e:?}",
            tracker.name()
        );
    }

    /// Two targets crossing at a right angle at 8 m range: each keeps its label.
    pub(crate) fn check_crossing(tracker: &mut dyn PointTracker) {
        // A walks up and right, B down and left; at t = 4 s both are on y = 0, 0.6 m apart
        let paths = |t: f64| {
            vec![
                [8.0 + 0.6 * t, -3.0 + 0.75 * t],
                [12.6 - 0.4 * t, 3.0 - 0.75 * t],
            ]
        };
        let est = run(tracker, 64, paths, |_| true);
        let mut owner: [BTreeSet<Label>; 2] = Default::default();
        for (k, frame) in est.iter().enumerate().skip(8) {
            let truth = paths(k as f64 / 8.0);
            for e in frame {
                let d: Vec<f64> = truth
                    .iter()
                    .map(|p| (e.state[0] - p[0]).hypot(e.state[2] - p[1]))
                    .collect();
                let i = if d[0] < d[1] { 0 } else { 1 };
                if d[i] < 1.0 {
                    owner[i].insert(e.label);
                }
            }
        }
        assert_eq!(owner[0].len(), 1, "{}: {owner:?}", tracker.name());
        assert_eq!(owner[1].len(), 1, "{}: {owner:?}", tracker.name());
        assert_ne!(owner[0], owner[1]);
    }

    /// A confirmed target that vanishes is deleted after 3.5 s unobserved, not before.
    pub(crate) fn check_deletion(tracker: &mut dyn PointTracker) {
        // last seen at t = 2.0 s (step 16); deletion due after 5.5 s (step 44)
        let est = run(tracker, 60, |t| vec![[6.0, 0.3 * t]], |t| t <= 2.0);
        assert_eq!(est[16].len(), 1, "{}", tracker.name());
        assert_eq!(est[43].len(), 1, "{}: deleted too early", tracker.name());
        assert!(est[45].is_empty(), "{}: not deleted", tracker.name());
    }

    #[test]
    fn single_target_one_label_small_error() {
        check_single_target(&mut GnnTracker::new(GnnConfig::new(sensor())).unwrap());
    }

    #[test]
    fn crossing_targets_keep_labels() {
        check_crossing(&mut GnnTracker::new(GnnConfig::new(sensor())).unwrap());
    }

    #[test]
    fn deleted_after_3_5_s_unobserved() {
        check_deletion(&mut GnnTracker::new(GnnConfig::new(sensor())).unwrap());
    }

    #[test]
    fn rejects_measurements_of_the_wrong_size() {
        let mut g = GnnTracker::new(GnnConfig::new(sensor())).unwrap();
        let z = Measurements::from_rows(3, &[[1.0, 2.0, 3.0]]).unwrap();
        assert!(g.step(&z, &StepContext::new(0, 0.0, 0.0)).is_err());
    }
}
