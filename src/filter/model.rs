//! The filter's contract with its models: how objects move ([`TransitionModel`],
//! [`SurvivalModel`]), how they are seen ([`MeasurementModel`], [`DetectionModel`]) and what
//! else is seen ([`ClutterModel`]), with what the models may know about a step
//! ([`StepContext`]) and about a track when gating ([`TrackSummary`]). Each trait has one verb
//! and works on a whole [`ParticleSet`] at a time, so a user's own model is a small struct and
//! the per-call cost of dynamic dispatch is paid once per track, not once per particle. A boxed
//! model is a model too, so models chosen at run time go wherever a model is expected.
//!
//! # State layout of the built-in models
//!
//! Position and velocity are interleaved per axis, as in the standard RFS benchmarks:
//!
//! | model | state |
//! |---|---|
//! | planar constant velocity ([`crate::models::ConstantVelocity`] with 2 axes) | `[x, ẋ, y, ẏ]` |
//! | spatial constant velocity ([`crate::models::ConstantVelocity`] with 3 axes) | `[x, ẋ, y, ẏ, z, ż]` |
//! | coordinated turn ([`crate::models::CoordinatedTurn`]) | `[x, ẋ, y, ẏ, ω]` |
//!
//! So the position of every built-in state is found in components 0, 2 (and 4 in 3-D); the
//! built-in measurement and detection models read it from there and ignore the rest. A user's
//! model may use any layout, as long as its transition, measurement and detection models agree.
//!
//! Not for: the built-in models (see [`crate::models`]) or the recursion that calls them (see
//! [`super::lmb`]).

use super::{Measurements, ParticleSet, StepData};
use crate::error::{Error, Result};
use crate::rng::FilterRng;
use nalgebra::Isometry3;

/// What the models may know about the current step.
///
/// `platform` is the pose of the sensing platform (robot, vehicle) in the world frame at this
/// step; `previous_platform` the pose at the previous step. Planar platforms use a rotation
/// about z. Both are `None` for a static sensor at the world origin. `data` holds what the
/// frame brought for particular models, by type ([`StepData`]).
#[derive(Clone, Debug, PartialEq)]
pub struct StepContext {
    /// Filter step index (0 for the first frame).
    pub step: u32,
    /// Time stamp of this step, seconds.
    pub time: f64,
    /// Time since the previous step, seconds.
    pub dt: f64,
    /// Platform pose at this step (world frame).
    pub platform: Option<Isometry3<f64>>,
    /// Platform pose at the previous step (world frame).
    pub previous_platform: Option<Isometry3<f64>>,
    /// The frame's data for particular models ([`crate::filter::Frame::data`]).
    pub data: StepData,
}

impl StepContext {
    /// A context for a static sensor.
    pub fn new(step: u32, time: f64, dt: f64) -> Self {
        StepContext {
            step,
            time,
            dt,
            platform: None,
            previous_platform: None,
            data: StepData::new(),
        }
    }

    /// The same context with `data` for the models.
    pub fn with_data(mut self, data: StepData) -> Self {
        self.data = data;
        self
    }

    /// Planar platform pose (x, y, heading) at this step; the origin when none is set.
    pub fn platform_xy_heading(&self) -> (f64, f64, f64) {
        match &self.platform {
            None => (0.0, 0.0, 0.0),
            Some(p) => {
                let t = p.translation.vector;
                let (_, _, yaw) = p.rotation.euler_angles();
                (t.x, t.y, yaw)
            }
        }
    }
}

/// Per-track summary handed to gates: weighted mean and per-component standard deviation of
/// the predicted particle set, and the set's tag ([`ParticleSet::tag`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TrackSummary {
    /// Weighted mean state.
    pub mean: Vec<f64>,
    /// Weighted standard deviation of each state component.
    pub std: Vec<f64>,
    /// The particle set's tag.
    pub tag: Option<u32>,
}

impl TrackSummary {
    /// The weighted mean and standard deviation of `particles`, and its tag.
    pub fn of(particles: &ParticleSet) -> TrackSummary {
        let (mean, std) = particles.mean_and_std_dev();
        TrackSummary {
            mean,
            std,
            tag: particles.tag(),
        }
    }

    /// An untagged summary of `mean` and `std`.
    pub fn new(mean: Vec<f64>, std: Vec<f64>) -> TrackSummary {
        TrackSummary {
            mean,
            std,
            tag: None,
        }
    }
}

/// The short name of a model type (its path without the modules), for errors that name a
/// model: `ConstantVelocity`, `Box<dyn TransitionModel>` forwards to the boxed model's.
pub fn model_name<T: ?Sized>() -> String {
    let full = std::any::type_name::<T>();
    // Keep generic arguments readable: strip the module path of every path segment.
    let mut out = String::with_capacity(full.len());
    let mut word = String::new();
    for ch in full.chars() {
        if ch.is_alphanumeric() || ch == '_' || ch == ':' {
            word.push(ch);
        } else {
            out.push_str(word.rsplit("::").next().unwrap_or(""));
            word.clear();
            out.push(ch);
        }
    }
    out.push_str(word.rsplit("::").next().unwrap_or(""));
    out
}

/// Checks the contract of [`TransitionModel::predict`]: a non-empty particle set must have at
/// least `state_dim` components (a model reads and moves the first `state_dim`; a longer
/// state, such as the drive tracker's kind-tagged one, keeps its extra components). Names
/// `model` and both dimensions otherwise.
pub fn check_state_dim(model: &str, state_dim: usize, particles: &ParticleSet) -> Result<()> {
    if particles.is_empty() || particles.dim() >= state_dim {
        return Ok(());
    }
    Err(Error::invalid(
        format!("state handed to {model}"),
        format!(
            "{} components, but the model moves states of {state_dim}",
            particles.dim()
        ),
    ))
}

/// Moves a whole particle set one step forward (Markov transition density f(x' | x)).
///
/// Implementations sample the process noise themselves, from `rng`, so that a user's model
/// can be any simulator: linear, nonlinear, or driven by the ego motion in `ctx`.
pub trait TransitionModel: Send + Sync {
    /// Dimension of the state vector this model moves.
    fn state_dim(&self) -> usize;
    /// Replaces every particle by a draw from f(· | particle). A set whose states are shorter
    /// than [`TransitionModel::state_dim`] is an error (see [`check_state_dim`]), never left
    /// unchanged; so is anything else the model cannot do with the set. The filter turns the
    /// error into the step's, naming the track.
    fn predict(
        &self,
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> Result<()>;
    /// The model's name in errors; the type's name by default.
    fn name(&self) -> String {
        model_name::<Self>()
    }
}

/// A transition model held by a configuration: shared, compared by identity, shown by name.
#[derive(Clone)]
pub struct SharedTransitionModel(pub std::sync::Arc<dyn TransitionModel>);

impl SharedTransitionModel {
    /// Shares `model`.
    pub fn new(model: impl TransitionModel + 'static) -> Self {
        SharedTransitionModel(std::sync::Arc::new(model))
    }
}

impl std::fmt::Debug for SharedTransitionModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0.name())
    }
}

impl PartialEq for SharedTransitionModel {
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
}

impl<T: TransitionModel + ?Sized> TransitionModel for std::sync::Arc<T> {
    fn state_dim(&self) -> usize {
        (**self).state_dim()
    }
    fn predict(
        &self,
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> Result<()> {
        (**self).predict(particles, ctx, rng)
    }
    fn name(&self) -> String {
        (**self).name()
    }
}

/// Probability p_S(x) that an object survives from the previous step to this one.
pub trait SurvivalModel: Send + Sync {
    /// Writes p_S of every particle into `out` (values in [0, 1]).
    fn survival_probability(&self, particles: &ParticleSet, ctx: &StepContext, out: &mut [f64]);
}

/// A log-likelihood that is NaN or +∞: measurement `measurement` of the batch, particle
/// `particle`, its value.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct LikelihoodFault {
    /// Index of the measurement in the batch.
    pub measurement: usize,
    /// Index of the particle.
    pub particle: usize,
    /// The offending log-likelihood.
    pub value: f64,
}

/// Rows of log-likelihoods (`rows[j]`) turned into likelihoods relative to each row's largest,
/// with that largest in `tops[j]`; a row whose largest is −∞ is left as it is. The first NaN
/// or +∞ is a [`LikelihoodFault`] (rows before it are converted, the rest are not).
pub fn relative_from_logs(rows: &mut [Vec<f64>], tops: &mut [f64]) -> Result<(), LikelihoodFault> {
    for (j, (g, top_out)) in rows.iter_mut().zip(tops.iter_mut()).enumerate() {
        let (mut top, mut bad) = (f64::NEG_INFINITY, false);
        for &v in g.iter() {
            bad |= v.is_nan() || v == f64::INFINITY;
            top = top.max(v);
        }
        if bad {
            let i = g
                .iter()
                .position(|v| v.is_nan() || *v == f64::INFINITY)
                .unwrap_or(0);
            return Err(LikelihoodFault {
                measurement: j,
                particle: i,
                value: g[i],
            });
        }
        *top_out = top;
        if top.is_finite() {
            // Relative likelihoods below e^−707 ≈ 1e-307 count as 0.
            g.iter_mut().for_each(|v| *v -= top);
            crate::numerics::exp::exp_in_place(g);
        }
    }
    Ok(())
}

/// The single-object likelihood g(z | x).
pub trait MeasurementModel: Send + Sync {
    /// Dimension of one measurement vector.
    fn measurement_dim(&self) -> usize;
    /// The length of the states the model reads (its likelihood looks at their first
    /// `state_dim` components), when it knows it: the filter's builder refuses a transition
    /// whose states are shorter. `None` (the default) skips that check.
    fn state_dim(&self) -> Option<usize> {
        None
    }
    /// The model's name in errors; the type's name by default.
    fn name(&self) -> String {
        model_name::<Self>()
    }
    /// Writes log g(z | xᵢ) of every particle into `out`. Must be finite or −∞: NaN or +∞
    /// makes the filter step fail with an error naming the track.
    fn log_likelihood(
        &self,
        z: &[f64],
        particles: &ParticleSet,
        ctx: &StepContext,
        out: &mut [f64],
    );
    /// log g(z | xᵢ) for several measurements at once: `out[j]` (one slot per particle) gets
    /// the row of `zs[j]`. The default calls [`MeasurementModel::log_likelihood`] for each;
    /// models whose predicted measurement h(xᵢ) is costly override it to compute h once.
    fn log_likelihood_batch(
        &self,
        zs: &[&[f64]],
        particles: &ParticleSet,
        ctx: &StepContext,
        out: &mut [Vec<f64>],
    ) {
        for (z, o) in zs.iter().zip(out.iter_mut()) {
            self.log_likelihood(z, particles, ctx, o);
        }
    }
    /// The likelihoods relative to the largest, for several measurements at once: `out[j][i]
    /// = g(zs[j] | xᵢ) / maxₖ g(zs[j] | xₖ)` and `tops[j] = ln maxₖ g(zs[j] | xₖ)` (−∞ when
    /// no particle can explain `zs[j]`; its row is then left unspecified). What the update
    /// needs, without leaving the log domain too early: likelihoods that would underflow keep
    /// their ratios. The default takes [`MeasurementModel::log_likelihood_batch`] and shifts
    /// each row by its maximum before exponentiating; models whose likelihood has a closed
    /// form for the ratio override it to skip the logarithms. A NaN or +∞ log-likelihood is
    /// returned as the first such [`LikelihoodFault`] (the filter turns it into an error
    /// naming the track).
    fn relative_likelihood_batch(
        &self,
        zs: &[&[f64]],
        particles: &ParticleSet,
        ctx: &StepContext,
        out: &mut [Vec<f64>],
        tops: &mut [f64],
    ) -> Result<(), LikelihoodFault> {
        self.log_likelihood_batch(zs, particles, ctx, out);
        relative_from_logs(out, tops)
    }
    /// A cheap test whether `z` could come from a track summarised by `track`; pairs that fail
    /// are never evaluated by [`MeasurementModel::log_likelihood`]. The default admits all.
    fn gate(&self, z: &[f64], track: &TrackSummary, ctx: &StepContext) -> bool {
        let _ = (z, track, ctx);
        true
    }
    /// The indices of the measurements `zs` that pass [`MeasurementModel::gate`] for `track`,
    /// in order, into `out` (cleared first). The default tests each; models whose gate has
    /// per-track work (the track's predicted measurement) override it to do that once.
    fn gate_all(
        &self,
        zs: &Measurements,
        track: &TrackSummary,
        ctx: &StepContext,
        out: &mut Vec<usize>,
    ) {
        out.clear();
        out.extend((0..zs.len()).filter(|&j| self.gate(zs.get(j), track, ctx)));
    }
}

/// The detection probability p_D(x).
pub trait DetectionModel: Send + Sync {
    /// Writes p_D of every particle into `out` (values in [0, 1]).
    fn detection_probability(&self, particles: &ParticleSet, ctx: &StepContext, out: &mut [f64]);
}

/// The clutter intensity κ(z) = λ_c · c(z): expected number of false measurements times their
/// spatial density.
pub trait ClutterModel: Send + Sync {
    /// log κ(z).
    fn log_intensity(&self, z: &[f64], ctx: &StepContext) -> f64;
}

// A boxed model is a model: lets trait objects (e.g. chosen at run time) go wherever a model
// is expected.
impl<T: TransitionModel + ?Sized> TransitionModel for Box<T> {
    fn state_dim(&self) -> usize {
        (**self).state_dim()
    }
    fn predict(
        &self,
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> Result<()> {
        (**self).predict(particles, ctx, rng)
    }
    fn name(&self) -> String {
        (**self).name()
    }
}

impl<T: SurvivalModel + ?Sized> SurvivalModel for Box<T> {
    fn survival_probability(&self, particles: &ParticleSet, ctx: &StepContext, out: &mut [f64]) {
        (**self).survival_probability(particles, ctx, out)
    }
}

impl<T: MeasurementModel + ?Sized> MeasurementModel for Box<T> {
    fn measurement_dim(&self) -> usize {
        (**self).measurement_dim()
    }
    fn state_dim(&self) -> Option<usize> {
        (**self).state_dim()
    }
    fn name(&self) -> String {
        (**self).name()
    }
    fn log_likelihood(
        &self,
        z: &[f64],
        particles: &ParticleSet,
        ctx: &StepContext,
        out: &mut [f64],
    ) {
        (**self).log_likelihood(z, particles, ctx, out)
    }
    fn log_likelihood_batch(
        &self,
        zs: &[&[f64]],
        particles: &ParticleSet,
        ctx: &StepContext,
        out: &mut [Vec<f64>],
    ) {
        (**self).log_likelihood_batch(zs, particles, ctx, out)
    }
    fn relative_likelihood_batch(
        &self,
        zs: &[&[f64]],
        particles: &ParticleSet,
        ctx: &StepContext,
        out: &mut [Vec<f64>],
        tops: &mut [f64],
    ) -> Result<(), LikelihoodFault> {
        (**self).relative_likelihood_batch(zs, particles, ctx, out, tops)
    }
    fn gate(&self, z: &[f64], track: &TrackSummary, ctx: &StepContext) -> bool {
        (**self).gate(z, track, ctx)
    }
    fn gate_all(
        &self,
        zs: &Measurements,
        track: &TrackSummary,
        ctx: &StepContext,
        out: &mut Vec<usize>,
    ) {
        (**self).gate_all(zs, track, ctx, out)
    }
}

impl<T: DetectionModel + ?Sized> DetectionModel for Box<T> {
    fn detection_probability(&self, particles: &ParticleSet, ctx: &StepContext, out: &mut [f64]) {
        (**self).detection_probability(particles, ctx, out)
    }
}

impl<T: ClutterModel + ?Sized> ClutterModel for Box<T> {
    fn log_intensity(&self, z: &[f64], ctx: &StepContext) -> f64 {
        (**self).log_intensity(z, ctx)
    }
}
