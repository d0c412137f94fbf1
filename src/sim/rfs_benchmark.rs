//! The two standard random-finite-set benchmark scenarios (Vo & Vo's published examples) as
//! plain data plus a seeded generator of ground truth and measurements.
//!
//! * [`Scenario::linear`]: 12 targets with constant-velocity motion, position measurements,
//!   p_D = 0.98, 30 clutter points per scan on a 2 km square.
//! * [`Scenario::nonlinear`]: 10 targets with coordinated-turn motion seen by a range-bearing
//!   sensor at the origin whose bearing is measured from the y axis (θ = atan2(x, y)), with a
//!   detection probability that fades with range and 10 clutter points per scan.
//!
//! Truth is noiseless: a target born at step b holds its initial state moved by one
//! transition at step b, and is moved again at every later step; it exists at every step k
//! with b ≤ k ≤ min(d, K). The noiseless motion here is written independently of
//! [`crate::models`], so tests can check one against the other.
//!
//! Measurements of a step are the detections of present targets followed by Poisson clutter,
//! then shuffled (origins are kept alongside, in [`SimRun::origins`]). Range-bearing
//! measurements are `[range, bearing]`, bearing wrapped to (−π, π].
//!
//! Not for: running a filter or scoring it (see [`crate::filter`] and [`crate::metrics`]).

use crate::error::{
    ensure_finite, ensure_non_negative, ensure_positive, ensure_probability, Error, Result,
};
use crate::filter::{Associator, BirthTerm, LmbConfig, LmbFilter, StaticBirth};
use crate::filter::{
    ClutterModel, ConstantSurvival, DetectionModel, MeasurementModel, StepContext, SurvivalModel,
    TransitionModel,
};
use crate::geometry::wrap_angle;
use crate::models::{
    BearingConvention, ConstantDetection, ConstantVelocity, CoordinatedTurn,
    GaussianRangeDetection, PositionMeasurement, RangeBearing, UniformClutter,
};
use crate::rng::{stream, FilterRng};
use rand::seq::SliceRandom;
use rand::RngExt;
use rand_distr::{Distribution, Poisson, StandardNormal};
use std::f64::consts::{FRAC_PI_2, PI};

/// How targets move.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum DynamicsSpec {
    /// Planar constant velocity, state `[x, ẋ, y, ẏ]` (see [`ConstantVelocity`]).
    ConstantVelocity {
        /// Acceleration noise standard deviation of the filter model (m/s²).
        sigma_accel: f64,
    },
    /// Coordinated turn, state `[x, ẋ, y, ẏ, ω]` (see [`CoordinatedTurn`]).
    CoordinatedTurn {
        /// Acceleration noise standard deviation of the filter model (m/s²).
        sigma_vel: f64,
        /// Turn-rate noise standard deviation of the filter model (rad/s²).
        sigma_turn: f64,
    },
}

impl DynamicsSpec {
    /// Dimension of the state.
    pub fn state_dim(&self) -> usize {
        match self {
            DynamicsSpec::ConstantVelocity { .. } => 4,
            DynamicsSpec::CoordinatedTurn { .. } => 5,
        }
    }
}

/// What the sensor measures (the sensor sits at the world origin).
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SensorSpec {
    /// z = (x, y) + N(0, σ² I).
    Position {
        /// Noise standard deviation per axis (m).
        sigma: f64,
    },
    /// z = [√(x² + y²), atan2(x, y)] + N(0, diag(σ_ρ², σ_θ²)): bearing from the y axis.
    RangeBearing {
        /// Range noise standard deviation (m).
        sigma_range: f64,
        /// Bearing noise standard deviation (rad).
        sigma_bearing: f64,
    },
}

/// Detection probability.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum DetectionSpec {
    /// p_D = p everywhere.
    Constant {
        /// The probability.
        p: f64,
    },
    /// p_D = peak · exp(−(x² + y²) / (2 scale²)).
    GaussianRange {
        /// p_D at the origin.
        peak: f64,
        /// Length scale (m).
        scale: f64,
    },
}

/// Poisson clutter, uniform over a box in measurement space.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ClutterSpec {
    /// Uniform on `x` × `y` (position measurements).
    Rectangle {
        /// Mean number per scan.
        rate: f64,
        /// [min, max] of x.
        x: [f64; 2],
        /// [min, max] of y.
        y: [f64; 2],
    },
    /// Uniform on `range` × `bearing` (range-bearing measurements).
    RangeBearing {
        /// Mean number per scan.
        rate: f64,
        /// [min, max] of the range.
        range: [f64; 2],
        /// [min, max] of the bearing (rad).
        bearing: [f64; 2],
    },
}

impl ClutterSpec {
    /// Mean number of clutter measurements per scan.
    pub fn rate(&self) -> f64 {
        match self {
            ClutterSpec::Rectangle { rate, .. } | ClutterSpec::RangeBearing { rate, .. } => *rate,
        }
    }

    /// The two [min, max] intervals of the clutter box, in measurement order.
    fn bounds(&self) -> [[f64; 2]; 2] {
        match self {
            ClutterSpec::Rectangle { x, y, .. } => [*x, *y],
            ClutterSpec::RangeBearing { range, bearing, .. } => [*range, *bearing],
        }
    }
}

/// One true target.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TargetSpec {
    /// Identity (the row number of the published table, 1-based).
    pub id: u64,
    /// State before the first transition.
    pub initial: Vec<f64>,
    /// First step (1-based) at which the target exists.
    pub birth: usize,
    /// Last step at which it exists; `None` means it outlives the scenario.
    pub death: Option<usize>,
}

impl TargetSpec {
    /// Whether the target exists at step `k` (1-based) of a scenario with `steps` steps.
    pub fn present_at(&self, k: usize, steps: usize) -> bool {
        let last = self.death.unwrap_or(steps).min(steps);
        self.birth <= k && k <= last
    }
}

/// A complete scenario description: motion, sensing, birth model and the true targets.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Scenario {
    /// Short name.
    pub name: String,
    /// Number of scans K.
    pub steps: usize,
    /// Sampling period T (s).
    pub period: f64,
    /// Survival probability p_S used by the filter.
    pub survival: f64,
    /// Target motion.
    pub dynamics: DynamicsSpec,
    /// Measurement model.
    pub sensor: SensorSpec,
    /// Detection probability.
    pub detection: DetectionSpec,
    /// Clutter.
    pub clutter: ClutterSpec,
    /// Birth LMB terms.
    pub birth: Vec<BirthTerm>,
    /// True targets.
    pub targets: Vec<TargetSpec>,
    /// OSPA cut-off c used when reporting (m).
    pub ospa_cutoff: f64,
    /// OSPA order p used when reporting.
    pub ospa_order: f64,
}

/// Ground truth of a run: `truth[k - 1]` lists (id, state) of the targets present at step k,
/// by increasing id.
pub type Truth = Vec<Vec<(u64, Vec<f64>)>>;

/// Ground truth and measurements of one simulated run.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SimRun {
    /// `truth[k - 1]`: the (id, state) of every target present at step k, by increasing id.
    pub truth: Truth,
    /// `measurements[k - 1]`: the measurements of step k, in random order.
    pub measurements: Vec<Vec<Vec<f64>>>,
    /// `origins[k - 1][j]`: the target that produced `measurements[k - 1][j]`, `None` for
    /// clutter.
    pub origins: Vec<Vec<Option<u64>>>,
}

/// The filter-side models matching a scenario.
pub struct ScenarioModels {
    /// Transition model.
    pub transition: Box<dyn TransitionModel>,
    /// Survival model.
    pub survival: Box<dyn SurvivalModel>,
    /// Measurement model.
    pub measurement: Box<dyn MeasurementModel>,
    /// Detection model.
    pub detection: Box<dyn DetectionModel>,
    /// Clutter model.
    pub clutter: Box<dyn ClutterModel>,
}

/// One noiseless constant-velocity step of `[x, ẋ, y, ẏ]`.
fn cv_step(s: &mut [f64], t: f64) {
    s[0] += t * s[1];
    s[2] += t * s[3];
}

/// One noiseless coordinated-turn step of `[x, ẋ, y, ẏ, ω]`, as the benchmark states it.
fn ct_step(s: &mut [f64], t: f64) {
    let (x, vx, y, vy, w) = (s[0], s[1], s[2], s[3], s[4]);
    let (sin_wt, cos_wt) = (w * t).sin_cos();
    let (a, b) = if w.abs() <= 1e-10 {
        (t, 0.0)
    } else {
        (sin_wt / w, (1.0 - cos_wt) / w)
    };
    s[0] = x + a * vx - b * vy;
    s[1] = cos_wt * vx - sin_wt * vy;
    s[2] = y + b * vx + a * vy;
    s[3] = sin_wt * vx + cos_wt * vy;
}

fn normal(rng: &mut FilterRng) -> f64 {
    StandardNormal.sample(rng)
}

fn uniform(rng: &mut FilterRng, [lo, hi]: [f64; 2]) -> f64 {
    lo + (hi - lo) * rng.random::<f64>()
}

impl Scenario {
    /// The linear benchmark: constant velocity (σ_v = 5 m/s²), position measurements
    /// (σ = 10 m), p_D = 0.98, clutter 30 per scan on [−1000, 1000]², four birth terms
    /// (r = 0.03, std 10), 12 targets over K = 100 scans of T = 1 s.
    pub fn linear() -> Self {
        let target = |id: u64, initial: [f64; 4], birth: usize, death: Option<usize>| TargetSpec {
            id,
            initial: initial.to_vec(),
            birth,
            death,
        };
        let birth_at = |x: f64, y: f64| BirthTerm {
            existence: 0.03,
            mean: vec![x, 0.0, y, 0.0],
            std: vec![10.0; 4],
        };
        Scenario {
            name: "linear".into(),
            steps: 100,
            period: 1.0,
            survival: 0.99,
            dynamics: DynamicsSpec::ConstantVelocity { sigma_accel: 5.0 },
            sensor: SensorSpec::Position { sigma: 10.0 },
            detection: DetectionSpec::Constant { p: 0.98 },
            clutter: ClutterSpec::Rectangle {
                rate: 30.0,
                x: [-1000.0, 1000.0],
                y: [-1000.0, 1000.0],
            },
            birth: vec![
                birth_at(0.1, 0.1),
                birth_at(400.0, -600.0),
                birth_at(-800.0, -200.0),
                birth_at(-200.0, 800.0),
            ],
            targets: vec![
                target(1, [0.0, 0.0, 0.0, -10.0], 1, Some(70)),
                target(2, [400.0, -10.0, -600.0, 5.0], 1, None),
                target(3, [-800.0, 20.0, -200.0, -5.0], 1, Some(70)),
                target(4, [400.0, -7.0, -600.0, -4.0], 20, None),
                target(5, [400.0, -2.5, -600.0, 10.0], 20, None),
                target(6, [0.0, 7.5, 0.0, -5.0], 20, None),
                target(7, [-800.0, 12.0, -200.0, 7.0], 40, None),
                target(8, [-200.0, 15.0, 800.0, -10.0], 40, None),
                target(9, [-800.0, 3.0, -200.0, 15.0], 60, None),
                target(10, [-200.0, -3.0, 800.0, -15.0], 60, None),
                target(11, [0.0, -20.0, 0.0, -15.0], 80, None),
                target(12, [-200.0, 15.0, 800.0, -5.0], 80, None),
            ],
            ospa_cutoff: 100.0,
            ospa_order: 1.0,
        }
    }

    /// The nonlinear (SMC) benchmark: coordinated turn (σ_vel = 5 m/s², σ_turn = 1°/s),
    /// range-bearing sensor at the origin (σ_ρ = 10 m, σ_θ = 2°, θ = atan2(x, y)),
    /// p_D = 0.98 · exp(−(x² + y²)/(2 · 2000²)), clutter 10 per scan uniform on
    /// [0, 2000] m × [−π/2, π/2], four birth terms, 10 targets over K = 100 scans of T = 1 s.
    ///
    /// The published particle LMB for this scenario uses 1000 particles per track
    /// (resampled every step), prunes tracks with r < 1e-3 and keeps at most 100.
    pub fn nonlinear() -> Self {
        let w = 2.0 * PI / 180.0;
        let target = |id: u64, initial: [f64; 5], birth: usize, death: Option<usize>| TargetSpec {
            id,
            initial: initial.to_vec(),
            birth,
            death,
        };
        let birth_std = vec![50.0, 50.0, 50.0, 50.0, 6f64.to_radians()];
        let birth_at = |r: f64, x: f64, y: f64| BirthTerm {
            existence: r,
            mean: vec![x, 0.0, y, 0.0, 0.0],
            std: birth_std.clone(),
        };
        Scenario {
            name: "nonlinear".into(),
            steps: 100,
            period: 1.0,
            survival: 0.99,
            dynamics: DynamicsSpec::CoordinatedTurn {
                sigma_vel: 5.0,
                sigma_turn: PI / 180.0,
            },
            sensor: SensorSpec::RangeBearing {
                sigma_range: 10.0,
                sigma_bearing: 2f64.to_radians(),
            },
            detection: DetectionSpec::GaussianRange {
                peak: 0.98,
                scale: 2000.0,
            },
            clutter: ClutterSpec::RangeBearing {
                rate: 10.0,
                range: [0.0, 2000.0],
                bearing: [-FRAC_PI_2, FRAC_PI_2],
            },
            birth: vec![
                birth_at(0.02, -1500.0, 250.0),
                birth_at(0.02, -250.0, 1000.0),
                birth_at(0.03, 250.0, 750.0),
                birth_at(0.03, 1000.0, 1500.0),
            ],
            targets: vec![
                target(
                    1,
                    [1000.0 + 3.8676, -10.0, 1500.0 - 11.7457, -10.0, w / 8.0],
                    1,
                    None,
                ),
                target(
                    2,
                    [-250.0 - 5.8857, 20.0, 1000.0 + 11.4102, 3.0, -w / 3.0],
                    10,
                    None,
                ),
                target(
                    3,
                    [-1500.0 - 7.3806, 11.0, 250.0 + 6.7993, 10.0, -w / 2.0],
                    10,
                    None,
                ),
                target(4, [-1500.0, 43.0, 250.0, 0.0, 0.0], 10, Some(66)),
                target(
                    5,
                    [250.0 - 3.8676, 11.0, 750.0 - 11.0747, 5.0, w / 4.0],
                    20,
                    Some(80),
                ),
                target(
                    6,
                    [-250.0 + 7.3806, -12.0, 1000.0 - 6.7993, -12.0, w / 2.0],
                    40,
                    None,
                ),
                target(7, [1000.0, 0.0, 1500.0, -10.0, w / 4.0], 40, None),
                target(8, [250.0, -50.0, 750.0, 0.0, -w / 4.0], 40, Some(80)),
                target(9, [1000.0, -50.0, 1500.0, 0.0, -w / 4.0], 60, None),
                target(10, [250.0, -40.0, 750.0, 25.0, w / 4.0], 60, None),
            ],
            ospa_cutoff: 100.0,
            ospa_order: 1.0,
        }
    }

    /// Checks every parameter: positive period and noise, probabilities in [0, 1], clutter
    /// boxes with max > min, states and birth terms of the dynamics' dimension.
    pub fn validate(&self) -> Result<()> {
        if self.steps == 0 {
            return Err(Error::invalid("scenario steps", "0 (must be at least 1)"));
        }
        ensure_positive("scenario period", self.period)?;
        ensure_probability("scenario survival probability", self.survival)?;
        match self.dynamics {
            DynamicsSpec::ConstantVelocity { sigma_accel } => {
                ensure_non_negative("scenario sigma_accel", sigma_accel)?
            }
            DynamicsSpec::CoordinatedTurn {
                sigma_vel,
                sigma_turn,
            } => {
                ensure_non_negative("scenario sigma_vel", sigma_vel)?;
                ensure_non_negative("scenario sigma_turn", sigma_turn)?;
            }
        }
        match self.sensor {
            SensorSpec::Position { sigma } => ensure_positive("scenario sensor sigma", sigma)?,
            SensorSpec::RangeBearing {
                sigma_range,
                sigma_bearing,
            } => {
                ensure_positive("scenario sigma_range", sigma_range)?;
                ensure_positive("scenario sigma_bearing", sigma_bearing)?;
            }
        }
        match self.detection {
            DetectionSpec::Constant { p } => {
                ensure_probability("scenario detection probability", p)?
            }
            DetectionSpec::GaussianRange { peak, scale } => {
                ensure_probability("scenario detection peak", peak)?;
                ensure_positive("scenario detection scale", scale)?;
            }
        }
        ensure_non_negative("scenario clutter rate", self.clutter.rate())?;
        if self.clutter.rate() > 0.0 && Poisson::<f64>::new(self.clutter.rate()).is_err() {
            return Err(Error::invalid(
                "scenario clutter rate",
                format!("{} (too large to sample)", self.clutter.rate()),
            ));
        }
        for (j, [lo, hi]) in self.clutter.bounds().into_iter().enumerate() {
            ensure_finite(&format!("scenario clutter interval {j}"), &[lo, hi])?;
            if hi <= lo {
                return Err(Error::invalid(
                    format!("scenario clutter interval {j}"),
                    format!("[{lo}, {hi}] (max must exceed min)"),
                ));
            }
        }
        let dim = self.dynamics.state_dim();
        for (i, b) in self.birth.iter().enumerate() {
            ensure_probability(
                &format!("birth term {i} existence probability"),
                b.existence,
            )?;
            if b.mean.len() != dim || b.std.len() != dim {
                return Err(Error::invalid(
                    format!("birth term {i}"),
                    format!(
                        "mean/std of length {}/{} (state has {dim})",
                        b.mean.len(),
                        b.std.len()
                    ),
                ));
            }
            ensure_finite(&format!("birth term {i} mean"), &b.mean)?;
            for &s in &b.std {
                ensure_non_negative(&format!("birth term {i} std"), s)?;
            }
        }
        for t in &self.targets {
            if t.initial.len() != dim {
                return Err(Error::invalid(
                    format!("target {} initial state", t.id),
                    format!("length {} (state has {dim})", t.initial.len()),
                ));
            }
            ensure_finite(&format!("target {} initial state", t.id), &t.initial)?;
            if t.birth == 0 {
                return Err(Error::invalid(
                    format!("target {} birth step", t.id),
                    "0 (steps are counted from 1)",
                ));
            }
        }
        Ok(())
    }

    /// Number of targets present at step `k` (1-based), read from the target table.
    pub fn target_count(&self, k: usize) -> usize {
        self.targets
            .iter()
            .filter(|t| t.present_at(k, self.steps))
            .count()
    }

    /// The filter context of step `k` (1-based): step index k − 1, time k·T, dt = T, static
    /// sensor at the origin.
    pub fn context(&self, k: usize) -> StepContext {
        let index = k.saturating_sub(1);
        StepContext::new(
            u32::try_from(index).unwrap_or(u32::MAX),
            k as f64 * self.period,
            self.period,
        )
    }

    fn step(&self, s: &mut [f64]) {
        match self.dynamics {
            DynamicsSpec::ConstantVelocity { .. } => cv_step(s, self.period),
            DynamicsSpec::CoordinatedTurn { .. } => ct_step(s, self.period),
        }
    }

    /// The noiseless ground truth: `truth[k - 1]` lists (id, state) of the targets present
    /// at step k, by increasing id.
    pub fn truth(&self) -> Result<Truth> {
        self.validate()?;
        let mut truth = vec![Vec::new(); self.steps];
        let mut targets: Vec<&TargetSpec> = self.targets.iter().collect();
        targets.sort_by_key(|t| t.id);
        for t in targets {
            let mut s = t.initial.clone();
            for (index, slot) in truth.iter_mut().enumerate() {
                let k = index + 1;
                if k < t.birth {
                    continue;
                }
                if !t.present_at(k, self.steps) {
                    break;
                }
                self.step(&mut s);
                slot.push((t.id, s.clone()));
            }
        }
        Ok(truth)
    }

    fn detection_probability(&self, s: &[f64]) -> f64 {
        match self.detection {
            DetectionSpec::Constant { p } => p,
            DetectionSpec::GaussianRange { peak, scale } => {
                peak * (-(s[0] * s[0] + s[2] * s[2]) / (2.0 * scale * scale)).exp()
            }
        }
    }

    fn measure(&self, s: &[f64], rng: &mut FilterRng) -> Vec<f64> {
        match self.sensor {
            SensorSpec::Position { sigma } => {
                vec![s[0] + sigma * normal(rng), s[2] + sigma * normal(rng)]
            }
            SensorSpec::RangeBearing {
                sigma_range,
                sigma_bearing,
            } => {
                let range = s[0].hypot(s[2]) + sigma_range * normal(rng);
                let bearing = wrap_angle(s[0].atan2(s[2]) + sigma_bearing * normal(rng));
                vec![range, bearing]
            }
        }
    }

    /// Simulates one run: the noiseless truth and, per step, detections (each present target
    /// with probability p_D, noise per the sensor) plus Poisson clutter, shuffled. The same
    /// seed gives the same run; step k draws from its own stream `(seed, k)`.
    pub fn generate(&self, seed: u64) -> Result<SimRun> {
        let truth = self.truth()?;
        let clutter_count = if self.clutter.rate() > 0.0 {
            Some(
                Poisson::<f64>::new(self.clutter.rate())
                    .map_err(|e| Error::invalid("scenario clutter rate", format!("{e}")))?,
            )
        } else {
            None
        };
        let bounds = self.clutter.bounds();
        let mut measurements = Vec::with_capacity(self.steps);
        let mut origins = Vec::with_capacity(self.steps);
        for (index, present) in truth.iter().enumerate() {
            let mut rng = stream(seed, index as u64 + 1);
            let mut scan: Vec<(Vec<f64>, Option<u64>)> = Vec::new();
            for (id, s) in present {
                if rng.random::<f64>() < self.detection_probability(s) {
                    scan.push((self.measure(s, &mut rng), Some(*id)));
                }
            }
            let n_clutter = clutter_count.as_ref().map_or(0.0, |d| d.sample(&mut rng)) as usize;
            for _ in 0..n_clutter {
                let z = vec![uniform(&mut rng, bounds[0]), uniform(&mut rng, bounds[1])];
                scan.push((z, None));
            }
            scan.shuffle(&mut rng);
            let (z, o): (Vec<_>, Vec<_>) = scan.into_iter().unzip();
            measurements.push(z);
            origins.push(o);
        }
        Ok(SimRun {
            truth,
            measurements,
            origins,
        })
    }

    /// The particle LMB filter the scenario prescribes: its [`models`](Self::models), the birth
    /// terms as a static birth sampled with `config.particles` particles each, the given tuning
    /// and associator (an [`AssociationMethod`](crate::filter::AssociationMethod) or a user's own).
    pub fn filter(
        &self,
        config: LmbConfig,
        associator: impl Associator + 'static,
    ) -> Result<LmbFilter> {
        let m = self.models()?;
        LmbFilter::builder()
            .transition(m.transition)
            .survival(m.survival)
            .measurement(m.measurement)
            .detection(m.detection)
            .clutter(m.clutter)
            .birth(StaticBirth::new(self.birth.clone(), config.particles)?)
            .associator(associator)
            .config(config)
            .build()
    }

    /// The library's models configured as the scenario describes (the filter side).
    pub fn models(&self) -> Result<ScenarioModels> {
        self.validate()?;
        let transition: Box<dyn TransitionModel> = match self.dynamics {
            DynamicsSpec::ConstantVelocity { sigma_accel } => {
                Box::new(ConstantVelocity::planar(sigma_accel)?)
            }
            DynamicsSpec::CoordinatedTurn {
                sigma_vel,
                sigma_turn,
            } => Box::new(CoordinatedTurn::new(sigma_vel, sigma_turn)?),
        };
        let measurement: Box<dyn MeasurementModel> = match self.sensor {
            SensorSpec::Position { sigma } => Box::new(PositionMeasurement::new(2, sigma)?),
            SensorSpec::RangeBearing {
                sigma_range,
                sigma_bearing,
            } => Box::new(
                RangeBearing::new(sigma_range, sigma_bearing)?
                    .with_convention(BearingConvention::FromYAxis),
            ),
        };
        let detection: Box<dyn DetectionModel> = match self.detection {
            DetectionSpec::Constant { p } => Box::new(ConstantDetection::new(p)?),
            DetectionSpec::GaussianRange { peak, scale } => {
                Box::new(GaussianRangeDetection::new(peak, scale, [0.0, 0.0])?)
            }
        };
        let [a, b] = self.clutter.bounds();
        let clutter = UniformClutter::new(self.clutter.rate(), (a[1] - a[0]) * (b[1] - b[0]))?;
        Ok(ScenarioModels {
            transition,
            survival: Box::new(ConstantSurvival::new(self.survival)?),
            measurement,
            detection,
            clutter: Box::new(clutter),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::ParticleSet;
    use crate::rng::seeded;

    #[test]
    fn linear_target_counts_follow_the_table() {
        let sc = Scenario::linear();
        let run = sc.generate(1).unwrap();
        // births at 1 (3), 20 (3), 40 (2), 60 (2), 80 (2); targets 1 and 3 last until 70
        for (k, n) in [
            (1, 3),
            (19, 3),
            (20, 6),
            (39, 6),
            (40, 8),
            (60, 10),
            (70, 10),
            (71, 8),
            (79, 8),
            (80, 10),
            (100, 10),
        ] {
            assert_eq!(run.truth[k - 1].len(), n, "step {k}");
            assert_eq!(sc.target_count(k), n, "step {k}");
        }
        assert_eq!(run.truth.len(), 100);
        assert_eq!(run.measurements.len(), 100);
    }

    #[test]
    fn nonlinear_target_counts_follow_the_table() {
        let sc = Scenario::nonlinear();
        let run = sc.generate(1).unwrap();
        // births 1 (1), 10 (3), 20 (1), 40 (3), 60 (2); deaths after 66 (1) and 80 (2)
        for (k, n) in [
            (1, 1),
            (9, 1),
            (10, 4),
            (19, 4),
            (20, 5),
            (40, 8),
            (60, 10),
            (66, 10),
            (67, 9),
            (80, 9),
            (81, 7),
            (100, 7),
        ] {
            assert_eq!(run.truth[k - 1].len(), n, "step {k}");
        }
    }

    #[test]
    fn linear_truth_is_hand_computable() {
        let truth = Scenario::linear().truth().unwrap();
        // target 1 from (0, 0) with velocity (0, −10): one step at its birth
        assert_eq!(truth[0][0], (1, vec![0.0, 0.0, -10.0, -10.0]));
        // at k = 70 it has moved 70 steps
        let t1 = truth[69].iter().find(|(id, _)| *id == 1).unwrap();
        assert_eq!(t1.1, vec![0.0, 0.0, -700.0, -10.0]);
        // target 2 at k = 100: (400 − 10·100, −600 + 5·100)
        let t2 = truth[99].iter().find(|(id, _)| *id == 2).unwrap();
        assert_eq!(t2.1, vec![-600.0, -10.0, -100.0, 5.0]);
        // target 4 born at 20: one step at k = 20
        let t4 = truth[19].iter().find(|(id, _)| *id == 4).unwrap();
        assert_eq!(t4.1, vec![393.0, -7.0, -604.0, -4.0]);
    }

    #[test]
    fn runs_are_deterministic_by_seed() {
        for sc in [Scenario::linear(), Scenario::nonlinear()] {
            let a = sc.generate(7).unwrap();
            let b = sc.generate(7).unwrap();
            let c = sc.generate(8).unwrap();
            assert_eq!(a, b);
            assert_eq!(a.truth, c.truth);
            assert_ne!(a.measurements, c.measurements);
        }
    }

    /// Mean measurements per scan over several runs against Σ p_D + λ_c.
    fn check_measurement_rate(sc: &Scenario, runs: u64, tolerance: f64) {
        let truth = sc.truth().unwrap();
        let expected_detections: f64 = truth
            .iter()
            .flatten()
            .map(|(_, s)| sc.detection_probability(s))
            .sum::<f64>()
            / sc.steps as f64;
        let (mut total, mut clutter, mut detected) = (0usize, 0usize, 0usize);
        for seed in 0..runs {
            let run = sc.generate(seed).unwrap();
            for (zs, os) in run.measurements.iter().zip(&run.origins) {
                assert_eq!(zs.len(), os.len());
                total += zs.len();
                clutter += os.iter().filter(|o| o.is_none()).count();
                detected += os.iter().filter(|o| o.is_some()).count();
            }
        }
        let scans = (runs as usize * sc.steps) as f64;
        let mean_total = total as f64 / scans;
        let expected = expected_detections + sc.clutter.rate();
        assert!(
            (mean_total - expected).abs() < tolerance,
            "{}: {mean_total} vs {expected}",
            sc.name
        );
        assert!((clutter as f64 / scans - sc.clutter.rate()).abs() < tolerance);
        assert!((detected as f64 / scans - expected_detections).abs() < tolerance / 2.0);
    }

    #[test]
    fn measurement_counts_match_detection_and_clutter_rates() {
        check_measurement_rate(&Scenario::linear(), 10, 1.0);
        check_measurement_rate(&Scenario::nonlinear(), 10, 0.6);
    }

    #[test]
    fn detections_lie_near_their_targets() {
        let sc = Scenario::linear();
        let run = sc.generate(3).unwrap();
        for k in 0..sc.steps {
            for (z, o) in run.measurements[k].iter().zip(&run.origins[k]) {
                if let Some(id) = o {
                    let s = &run.truth[k].iter().find(|(i, _)| i == id).unwrap().1;
                    assert!((z[0] - s[0]).abs() < 60.0 && (z[1] - s[2]).abs() < 60.0);
                } else {
                    assert!(z.iter().all(|v| (-1000.0..=1000.0).contains(v)));
                }
            }
        }
        let sc = Scenario::nonlinear();
        let run = sc.generate(3).unwrap();
        let rb = RangeBearing::benchmark();
        for k in 0..sc.steps {
            let ctx = sc.context(k + 1);
            for (z, o) in run.measurements[k].iter().zip(&run.origins[k]) {
                if let Some(id) = o {
                    let s = &run.truth[k].iter().find(|(i, _)| i == id).unwrap().1;
                    let h = rb.predict_measurement(s, &ctx);
                    assert!((z[0] - h[0]).abs() < 60.0);
                    assert!(wrap_angle(z[1] - h[1]).abs() < 12f64.to_radians());
                } else {
                    assert!((0.0..=2000.0).contains(&z[0]));
                    assert!((-FRAC_PI_2..=FRAC_PI_2).contains(&z[1]));
                }
            }
        }
    }

    #[test]
    fn zero_turn_target_moves_in_a_straight_line() {
        let truth = Scenario::nonlinear().truth().unwrap();
        let track: Vec<&Vec<f64>> = truth
            .iter()
            .flatten()
            .filter(|(id, _)| *id == 4)
            .map(|(_, s)| s)
            .collect();
        assert_eq!(track.len(), 66 - 10 + 1);
        // −1500 + 43 after its first step, then 43 m per step along x at y = 250
        for (j, s) in track.iter().enumerate() {
            let x = -1500.0 + 43.0 * (j + 1) as f64;
            assert!(
                (s[0] - x).abs() < 1e-9 && (s[2] - 250.0).abs() < 1e-9,
                "{s:?}"
            );
            assert_eq!((s[1], s[3], s[4]), (43.0, 0.0, 0.0));
        }
    }

    fn states_for_comparison() -> Vec<Vec<f64>> {
        let w = 2.0 * PI / 180.0;
        vec![
            vec![1000.0, -10.0, 1500.0, -10.0, w / 8.0],
            vec![-250.0, 20.0, 1000.0, 3.0, -w / 3.0],
            vec![-1500.0, 43.0, 250.0, 0.0, 0.0],
            vec![250.0, -40.0, 750.0, 25.0, 1e-12],
            vec![0.0, 5.0, 0.0, -5.0, 1e-3],
            vec![10.0, 1.0, 0.0, 0.0, PI / 2.0],
            vec![-3.0, 12.0, 7.0, -30.0, -2.5],
        ]
    }

    #[test]
    fn sim_turn_step_matches_the_coordinated_turn_model() {
        let rows = states_for_comparison();
        let mut p = ParticleSet::from_rows(&rows, &vec![1.0; rows.len()]).unwrap();
        let model = CoordinatedTurn::new(0.0, 0.0).unwrap();
        model
            .predict(&mut p, &StepContext::new(1, 1.0, 1.0), &mut seeded(1))
            .unwrap();
        for (i, row) in rows.iter().enumerate() {
            let mut s = row.clone();
            ct_step(&mut s, 1.0);
            for (a, b) in s.iter().zip(p.state(i)) {
                assert!((a - b).abs() < 1e-9, "state {i}: {s:?} vs {:?}", p.state(i));
            }
        }
    }

    #[test]
    fn sim_cv_step_matches_the_constant_velocity_model() {
        let rows: Vec<Vec<f64>> = states_for_comparison()
            .into_iter()
            .map(|r| r[..4].to_vec())
            .collect();
        let mut p = ParticleSet::from_rows(&rows, &vec![1.0; rows.len()]).unwrap();
        let model = ConstantVelocity::planar(0.0).unwrap();
        model
            .predict(&mut p, &StepContext::new(1, 2.0, 2.0), &mut seeded(1))
            .unwrap();
        for (i, row) in rows.iter().enumerate() {
            let mut s = row.clone();
            cv_step(&mut s, 2.0);
            assert_eq!(s, p.state(i));
        }
    }

    #[test]
    fn scenario_models_agree_with_the_simulation() {
        for sc in [Scenario::linear(), Scenario::nonlinear()] {
            let m = sc.models().unwrap();
            let truth = sc.truth().unwrap();
            let run = sc.generate(11).unwrap();
            let k = 60;
            let ctx = sc.context(k);
            let rows: Vec<Vec<f64>> = truth[k - 1].iter().map(|(_, s)| s.clone()).collect();
            let p = ParticleSet::from_rows(&rows, &vec![1.0; rows.len()]).unwrap();
            let mut out = vec![0.0; rows.len()];
            let mut p_d = vec![0.0; rows.len()];
            m.detection.detection_probability(&p, &ctx, &mut p_d);
            for (i, (_, s)) in truth[k - 1].iter().enumerate() {
                assert!((p_d[i] - sc.detection_probability(s)).abs() < 1e-12);
            }
            // each detection explains better as its own target than as clutter (targets may
            // cross, so another target can be as likely)
            for (z, o) in run.measurements[k - 1].iter().zip(&run.origins[k - 1]) {
                let Some(id) = o else { continue };
                m.measurement.log_likelihood(z, &p, &ctx, &mut out);
                let own = truth[k - 1].iter().position(|(i, _)| i == id).unwrap();
                assert!(out[own] > m.clutter.log_intensity(z, &ctx), "{}", sc.name);
            }
            assert_eq!(m.transition.state_dim(), sc.dynamics.state_dim());
        }
    }

    #[test]
    fn invalid_scenarios_are_rejected() {
        let mut sc = Scenario::linear();
        sc.period = 0.0;
        assert!(sc.generate(1).is_err());
        let mut sc = Scenario::linear();
        sc.targets[3].initial.pop();
        assert!(sc.truth().is_err());
        let mut sc = Scenario::nonlinear();
        sc.clutter = ClutterSpec::RangeBearing {
            rate: 10.0,
            range: [0.0, 0.0],
            bearing: [-1.0, 1.0],
        };
        assert!(sc.models().is_err());
        let mut sc = Scenario::nonlinear();
        sc.birth[0].std.pop();
        assert!(sc.validate().is_err());
        // no clutter at all is fine
        let mut sc = Scenario::linear();
        sc.clutter = ClutterSpec::Rectangle {
            rate: 0.0,
            x: [0.0, 1.0],
            y: [0.0, 1.0],
        };
        let run = sc.generate(2).unwrap();
        assert!(run.origins.iter().flatten().all(|o| o.is_some()));
    }
}
