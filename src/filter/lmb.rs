//! The LMB filter: one call of [`LmbFilter::step`] per frame runs the recursion of Reuter, Vo,
//! Vo & Dietmayer (IEEE TSP 2014) with particle densities (as in the SMC implementation of the
//! planar-feature LMB paper, Sec. 4):
//!
//! predict → birth → gate → likelihoods → associate → update → resample → prune → estimate.
//!
//! Each stage is one function below (gating is part of `likelihoods`), and what a step keeps
//! for inspection afterwards is recorded by one more (`record_diagnostics`). Work per track and
//! per association group runs in parallel with rayon; every track draws from its own random
//! stream derived from the step seed and its label, so results are bit-identical whatever the
//! number of threads. Not for: models (see [`crate::models`]), association algorithms (see
//! [`super::association`]).

use super::association::{AssociationMethod, AssociationProblem, Associator, Marginals};
use super::birth::{unexplained, BirthEvidence, BirthModel, CurrentMeasurements};
use super::estimate::map_estimates;
use super::groups::partition;
use super::merge::{duplicate_pairs, merge_into, MergeDistance, ScaledDistance};
use super::track::{Estimate, Track};
use super::{Jitter, Label, Measurements, ParticleSet, StepData};
use crate::error::{Error, Result};
use crate::filter::{
    ClutterModel, ConstantSurvival, DetectionModel, MeasurementModel, StepContext, SurvivalModel,
    TrackSummary, TransitionModel,
};
use crate::rng::{stream, FilterRng};
use nalgebra::Isometry3;
use rand::Rng;
use rayon::prelude::*;
use std::collections::HashMap;

/// The most particles per track [`LmbConfig::validate`] accepts: ten million (a 6-component
/// state then takes about half a gigabyte per track). Larger values are refused up front
/// rather than failing an allocation in the middle of a run.
pub const MAX_PARTICLES: usize = 10_000_000;

/// The longest [`LmbConfig::smoothing_lag`] accepts: 100 steps (the genealogy of a particle
/// set degenerates to a few ancestors long before).
pub const MAX_SMOOTHING_LAG: usize = 100;

/// The most tracks [`LmbConfig::validate`] accepts in `max_tracks`: one million.
pub const MAX_TRACKS: usize = 1_000_000;

/// Tuning of the recursion. Every field has a documented default.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LmbConfig {
    /// Particles per track after resampling, 1 to [`MAX_PARTICLES`]. Default 1000.
    pub particles: usize,
    /// When set, particles follow existence: a track of existence r is resampled to
    /// max(`min_particles`, ⌈r · `particles`⌉) particles (the allocation of Vo, Vo & Cantoni's
    /// SMC multi-Bernoulli filter, IEEE TSP 2009), so the many unlikely tracks a cluttered
    /// scene proposes cost little; it is resampled to a new count only when its count is less
    /// than half or more than twice that number (or its effective sample size is low), so a
    /// changing existence does not resample every step. At least 1; a value above `particles`
    /// acts as `particles`. Default `None`: every track keeps `particles`.
    pub min_particles: Option<usize>,
    /// Resample a track when its effective sample size falls below this fraction of
    /// `particles` (1.0 resamples after every update that changed the weights). Default 0.5.
    pub resample_threshold: f64,
    /// Diversity added after resampling. Default: regularised kernel at 0.2 × optimal bandwidth.
    pub jitter: Jitter,
    /// Tracks whose existence probability falls below this are removed. Default 1e-3.
    pub prune_threshold: f64,
    /// At most this many tracks (those with the highest existence) are kept, 1 to
    /// [`MAX_TRACKS`]. Default 100.
    pub max_tracks: usize,
    /// Steps of every track's particle history kept for fixed-lag smoothing
    /// ([`crate::filter::smoothing::FixedLagSmoother`]), at most [`MAX_SMOOTHING_LAG`]; each
    /// step of lag copies every particle once more per step. Default 0: none kept.
    pub smoothing_lag: usize,
    /// When set, duplicate tracks are merged after each update ([`super::merge`]): two tracks
    /// whose most probable measurement is the same and whose posterior means lie within this
    /// squared distance (each component scaled by the sum of the two tracks' variances)
    /// become one, under the more probable one's label. Default `None`: no merging.
    pub merge_threshold: Option<f64>,
}

impl Default for LmbConfig {
    fn default() -> Self {
        LmbConfig {
            particles: 1000,
            min_particles: None,
            resample_threshold: 0.5,
            jitter: Jitter::default(),
            prune_threshold: 1e-3,
            max_tracks: 100,
            smoothing_lag: 0,
            merge_threshold: None,
        }
    }
}

impl LmbConfig {
    /// Checks ranges; names the first bad field.
    pub fn validate(&self) -> Result<()> {
        if self.particles == 0 {
            return Err(Error::invalid(
                "config field `particles`",
                "must be positive",
            ));
        }
        if self.particles > MAX_PARTICLES {
            return Err(Error::invalid(
                "config field `particles`",
                format!("{} is above the limit of {MAX_PARTICLES}", self.particles),
            ));
        }
        if self.min_particles == Some(0) {
            return Err(Error::invalid(
                "config field `min_particles`",
                "must be positive",
            ));
        }
        if !(0.0..=1.0).contains(&self.resample_threshold) {
            return Err(Error::invalid(
                "config field `resample_threshold`",
                format!("{} outside [0, 1]", self.resample_threshold),
            ));
        }
        if !(0.0..1.0).contains(&self.prune_threshold) {
            return Err(Error::invalid(
                "config field `prune_threshold`",
                format!("{} outside [0, 1)", self.prune_threshold),
            ));
        }
        if self.smoothing_lag > MAX_SMOOTHING_LAG {
            return Err(Error::invalid(
                "config field `smoothing_lag`",
                format!(
                    "{} is above the limit of {MAX_SMOOTHING_LAG}",
                    self.smoothing_lag
                ),
            ));
        }
        if let Some(t) = self.merge_threshold {
            if !(t >= 0.0 && t.is_finite()) {
                return Err(Error::invalid(
                    "config field `merge_threshold`",
                    format!("{t} must be finite and ≥ 0"),
                ));
            }
        }
        if self.max_tracks == 0 {
            return Err(Error::invalid(
                "config field `max_tracks`",
                "must be positive",
            ));
        }
        if self.max_tracks > MAX_TRACKS {
            return Err(Error::invalid(
                "config field `max_tracks`",
                format!("{} is above the limit of {MAX_TRACKS}", self.max_tracks),
            ));
        }
        match self.jitter {
            Jitter::Roughening { k: s } | Jitter::Regularised { scale: s }
                if !(s >= 0.0 && s.is_finite()) =>
            {
                Err(Error::invalid(
                    "config field `jitter`",
                    format!("scale {s} must be finite and ≥ 0"),
                ))
            }
            _ => Ok(()),
        }
    }
}

/// One frame handed to the filter.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Time stamp, seconds (must not decrease).
    pub time: f64,
    /// The frame's measurements.
    pub measurements: Measurements,
    /// Pose of the sensing platform in the world frame, if it moves.
    pub platform: Option<Isometry3<f64>>,
    /// What the frame brings for particular models (a vehicle state, a scan's beams, ...),
    /// handed to every model in the step's [`StepContext::data`].
    pub data: StepData,
}

impl Frame {
    /// A frame from a static sensor.
    pub fn new(time: f64, measurements: Measurements) -> Self {
        Frame {
            time,
            measurements,
            platform: None,
            data: StepData::new(),
        }
    }

    /// The same frame seen from `platform` (world frame).
    pub fn at(mut self, platform: Isometry3<f64>) -> Self {
        self.platform = Some(platform);
        self
    }

    /// The same frame with `data` for the models.
    pub fn with_data(mut self, data: StepData) -> Self {
        self.data = data;
        self
    }
}

/// Collects the models and settings of an [`LmbFilter`].
#[derive(Default)]
pub struct LmbFilterBuilder {
    transition: Option<Box<dyn TransitionModel>>,
    survival: Option<Box<dyn SurvivalModel>>,
    measurement: Option<Box<dyn MeasurementModel>>,
    detection: Option<Box<dyn DetectionModel>>,
    clutter: Option<Box<dyn ClutterModel>>,
    birth: Option<Box<dyn BirthModel>>,
    associator: Option<Box<dyn Associator>>,
    merge_distance: Option<Box<dyn MergeDistance>>,
    config: LmbConfig,
}

impl LmbFilterBuilder {
    /// The transition model (required).
    pub fn transition(mut self, m: impl TransitionModel + 'static) -> Self {
        self.transition = Some(Box::new(m));
        self
    }
    /// The survival model (default: p_S = 0.99 everywhere).
    pub fn survival(mut self, m: impl SurvivalModel + 'static) -> Self {
        self.survival = Some(Box::new(m));
        self
    }
    /// The measurement model (required).
    pub fn measurement(mut self, m: impl MeasurementModel + 'static) -> Self {
        self.measurement = Some(Box::new(m));
        self
    }
    /// The detection model (required).
    pub fn detection(mut self, m: impl DetectionModel + 'static) -> Self {
        self.detection = Some(Box::new(m));
        self
    }
    /// The clutter model (required).
    pub fn clutter(mut self, m: impl ClutterModel + 'static) -> Self {
        self.clutter = Some(Box::new(m));
        self
    }
    /// The birth model (required).
    pub fn birth(mut self, m: impl BirthModel + 'static) -> Self {
        self.birth = Some(Box::new(m));
        self
    }
    /// The association method (default: [`AssociationMethod::default`]).
    pub fn associator(mut self, a: impl Associator + 'static) -> Self {
        self.associator = Some(Box::new(a));
        self
    }
    /// How far apart two tracks are for the duplicate merge, which
    /// [`LmbConfig::merge_threshold`] turns on (default: [`ScaledDistance`]).
    pub fn merge_distance(mut self, d: impl MergeDistance + 'static) -> Self {
        self.merge_distance = Some(Box::new(d));
        self
    }
    /// Tuning (default: [`LmbConfig::default`]).
    pub fn config(mut self, c: LmbConfig) -> Self {
        self.config = c;
        self
    }

    /// Checks that every required model is present, that the models agree on the state
    /// (the birth model draws states of the transition's length, the measurement model reads
    /// no more components than the transition moves; see [`TransitionModel::state_dim`],
    /// [`BirthModel::state_dim`], [`MeasurementModel::state_dim`]) and that the config is
    /// valid. A disagreement names both models and their dimensions.
    pub fn build(self) -> Result<LmbFilter> {
        self.config.validate()?;
        let missing = |what: &str| Error::invalid("filter", format!("no {what} model given"));
        let transition = self.transition.ok_or_else(|| missing("transition"))?;
        let measurement = self.measurement.ok_or_else(|| missing("measurement"))?;
        let birth = self.birth.ok_or_else(|| missing("birth"))?;
        check_dimensions(&*transition, &*measurement, &*birth)?;
        Ok(LmbFilter {
            models: Models {
                transition,
                survival: self
                    .survival
                    .unwrap_or_else(|| Box::new(ConstantSurvival(0.99))),
                measurement,
                detection: self.detection.ok_or_else(|| missing("detection"))?,
                clutter: self.clutter.ok_or_else(|| missing("clutter"))?,
                birth,
                associator: self
                    .associator
                    .unwrap_or_else(|| Box::new(AssociationMethod::default())),
                merge_distance: self
                    .merge_distance
                    .unwrap_or_else(|| Box::new(ScaledDistance)),
            },
            config: self.config,
            tracks: Vec::new(),
            step: 0,
            previous: None,
            unmoved_detection: Vec::new(),
            most_probable: Vec::new(),
            keep_predicted: false,
            predicted: Vec::new(),
            particle_caps: HashMap::new(),
            pending: None,
        })
    }
}

/// The builder's comparison of the models' dimensions (see [`LmbFilterBuilder::build`]).
fn check_dimensions(
    transition: &dyn TransitionModel,
    measurement: &dyn MeasurementModel,
    birth: &dyn BirthModel,
) -> Result<()> {
    let d = transition.state_dim();
    if d == 0 {
        return Err(Error::invalid(
            "filter",
            format!("{} moves states of 0 components", transition.name()),
        ));
    }
    let md = measurement.measurement_dim();
    if let Some(b) = birth.state_dim(md) {
        if b != d {
            return Err(Error::invalid(
                "filter",
                format!(
                    "the birth model {} draws states of {b} components (for measurements of {md}), \
                     but the transition {} moves states of {d}",
                    birth.name(),
                    transition.name()
                ),
            ));
        }
    }
    if let Some(m) = measurement.state_dim() {
        if m > d {
            return Err(Error::invalid(
                "filter",
                format!(
                    "the measurement model {} reads states of {m} components, but the \
                     transition {} moves states of {d}",
                    measurement.name(),
                    transition.name()
                ),
            ));
        }
    }
    Ok(())
}

struct Models {
    transition: Box<dyn TransitionModel>,
    survival: Box<dyn SurvivalModel>,
    measurement: Box<dyn MeasurementModel>,
    detection: Box<dyn DetectionModel>,
    clutter: Box<dyn ClutterModel>,
    birth: Box<dyn BirthModel>,
    associator: Box<dyn Associator>,
    merge_distance: Box<dyn MergeDistance>,
}

/// What the previous step leaves for the next: its context and, for adaptive birth, its
/// measurements and their association probabilities.
struct Previous {
    context: StepContext,
    measurements: Measurements,
    assigned: Vec<f64>,
}

/// Per-track quantities of one update: detection probabilities and the likelihood of every
/// gated measurement, all in the log domain.
struct TrackLikelihoods {
    /// p_D(xᵢ), clamped to [0, 1].
    pd: Vec<f64>,
    /// η_miss = Σ wᵢ (1 − p_D(xᵢ)) (no underflow risk: a plain sum of probabilities).
    eta_miss: f64,
    /// The gated measurements some particle can explain, in the gate's order. One entry per
    /// pair, so a pair's index and its sums cannot come apart.
    pairs: Vec<GatedPair>,
}

/// One (track, gated measurement) pair with positive likelihood.
struct GatedPair {
    /// Index of the measurement in the step's set.
    measurement: usize,
    /// ln η = ln Σ wᵢ p_D(xᵢ) g(z | xᵢ) (without κ).
    log_eta: f64,
    /// The likelihoods scaled by their largest value, exp(ln g(z | xᵢ) − maxₖ ln g(z | xₖ)),
    /// so the best particle has 1 whatever the scale.
    scaled_g: Vec<f64>,
    /// Σ wᵢ p_D(xᵢ) · scaled_g[i], positive.
    scaled_eta: f64,
}

/// A track's row of association marginals, in its own terms.
struct TrackMarginals {
    miss: f64,
    /// (index into `TrackLikelihoods::pairs`, probability).
    detect: Vec<(usize, f64)>,
}

impl TrackMarginals {
    /// The measurement (its index in the step's measurements) this track most probably
    /// generated, with that probability; `lik` is the same track's row of likelihoods.
    fn most_probable(&self, lik: &TrackLikelihoods) -> Option<(usize, f64)> {
        let best = self.detect.iter().max_by(|a, b| a.1.total_cmp(&b.1));
        best.map(|&(k, p)| (lik.pairs[k].measurement, p))
    }
}

/// A track's most probable measurement in a step, with the association's marginal
/// probability that the track generated it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MostProbableMeasurement {
    /// The track.
    pub label: Label,
    /// Index of the measurement in the step's [`Measurements`].
    pub measurement: usize,
    /// P(the track exists and generated this measurement).
    pub probability: f64,
}

/// Stream keys, combined with a label key or group key, for each random stage.
const KEY_PREDICT: u64 = 0x01 << 60;
const KEY_BIRTH: u64 = 0x02 << 60;
const KEY_ASSOCIATE: u64 = 0x03 << 60;
const KEY_RESAMPLE: u64 = 0x04 << 60;

/// The labelled multi-Bernoulli filter with particle densities.
pub struct LmbFilter {
    models: Models,
    config: LmbConfig,
    tracks: Vec<Track>,
    step: u32,
    previous: Option<Previous>,
    /// p_D of every particle from the last update, for the tracks whose particles have not
    /// moved since (not resampled), by label.
    unmoved_detection: Vec<(Label, Vec<f64>)>,
    /// Each track's most probable measurement of the last step (tracks that could explain
    /// some measurement).
    most_probable: Vec<MostProbableMeasurement>,
    /// Whether to keep the predicted particle sets of each step (consistency checks).
    keep_predicted: bool,
    /// The predicted particle sets of the last step (births as drawn), when kept.
    predicted: Vec<(Label, ParticleSet)>,
    /// Per-track upper bounds on the particle count, set by the caller
    /// ([`LmbFilter::set_particle_caps`]).
    particle_caps: HashMap<Label, usize>,
    /// A step predicted by [`LmbFilter::predict_step`] and not yet updated.
    pending: Option<Pending>,
}

/// The first half of a step, between [`LmbFilter::predict_step`] and
/// [`LmbFilter::update_step`].
struct Pending {
    context: StepContext,
    seed: u64,
    /// The gates' summaries of the predicted tracks, for the births' and the update's gating
    /// (empty when the step's measurements are known to be none).
    summaries: Vec<TrackSummary>,
}

impl std::fmt::Debug for LmbFilter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LmbFilter")
            .field("config", &self.config)
            .field("steps", &self.step)
            .field("tracks", &self.tracks.len())
            .finish_non_exhaustive()
    }
}

impl LmbFilter {
    /// Starts building a filter.
    pub fn builder() -> LmbFilterBuilder {
        LmbFilterBuilder::default()
    }

    /// The current tracks (after the last step's pruning).
    pub fn tracks(&self) -> &[Track] {
        &self.tracks
    }

    /// The tuning in use.
    pub fn config(&self) -> &LmbConfig {
        &self.config
    }

    /// Number of steps run so far.
    pub fn steps(&self) -> u32 {
        self.step
    }

    /// Forgets every track and the previous step.
    pub fn reset(&mut self) {
        self.tracks.clear();
        self.step = 0;
        self.previous = None;
        self.unmoved_detection.clear();
        self.most_probable.clear();
        self.predicted.clear();
        self.pending = None;
    }

    /// Each track's most probable measurement of the last step, with its marginal
    /// association probability (tracks that could explain no measurement are left out).
    pub fn most_probable_measurements(&self) -> &[MostProbableMeasurement] {
        &self.most_probable
    }

    /// Keeps (or stops keeping) a copy of every track's predicted particle set in each step,
    /// for consistency checks of the prediction (innovations, NIS); off by default, as it
    /// copies every particle once per step.
    pub fn keep_predicted(&mut self, on: bool) {
        self.keep_predicted = on;
        if !on {
            self.predicted.clear();
        }
    }

    /// Caps the particle count of the tracks named in `caps` (label → at most that many
    /// particles, at least one) from the next resampling on, replacing earlier caps; tracks
    /// not named keep the configured count. For a caller that knows some tracks need less
    /// accuracy than others, e.g. confirmed objects it does not report. A capped track is
    /// resampled to its cap when it holds more than twice as many particles, and back to its
    /// configured count when the cap is lifted and it holds fewer than half of that. The
    /// caps only change how densities are sampled, never the model.
    pub fn set_particle_caps(&mut self, caps: HashMap<Label, usize>) {
        self.particle_caps = caps;
    }

    /// The predicted particle set of track `label` in the last step (the density the update
    /// started from; for a track born in that step, its birth draw), when kept.
    pub fn predicted(&self, label: Label) -> Option<&ParticleSet> {
        self.predicted
            .iter()
            .find(|(l, _)| *l == label)
            .map(|(_, p)| p)
    }

    /// The detection probability of every particle of track `label` as the last step's update
    /// computed it (clamped to [0, 1]), when that track's particles have not moved since (it
    /// was not resampled): the same numbers the detection model gives for those particles at
    /// that step, without evaluating it again. `None` for other tracks.
    pub fn detection_probabilities(&self, label: Label) -> Option<&[f64]> {
        self.unmoved_detection
            .iter()
            .find(|(l, _)| *l == label)
            .map(|(_, pd)| pd.as_slice())
    }

    /// Runs one frame and returns the MAP multi-object estimate.
    ///
    /// One call per stage of the recursion; the step seed is the only draw from `rng`, and each
    /// random stage derives its own streams from it. The same as [`LmbFilter::predict_step`]
    /// followed by [`LmbFilter::update_step`], with the frame checked whole before either.
    pub fn step(&mut self, frame: &Frame, rng: &mut FilterRng) -> Result<Vec<Estimate>> {
        self.check_measurements(&frame.measurements)?;
        self.predict_phase(
            frame.time,
            frame.platform,
            frame.data.clone(),
            rng,
            !frame.measurements.is_empty(),
        )?;
        self.update_step(&frame.measurements)
    }

    /// The first half of a step: the survival and transition of every track to `time`, the
    /// platform at `platform`, the models handed `data` (as [`Frame::data`]; it stays the
    /// step's through the update). Needs no measurements, so a caller can run it while the
    /// frame's measurements are still being made (the drive tracker predicts while it
    /// segments the scan). Draws the step seed from `rng`, as [`LmbFilter::step`] does; an
    /// error when the step before is predicted and not yet updated.
    pub fn predict_step(
        &mut self,
        time: f64,
        platform: Option<Isometry3<f64>>,
        data: StepData,
        rng: &mut FilterRng,
    ) -> Result<()> {
        self.predict_phase(time, platform, data, rng, true)
    }

    /// The second half of a step predicted by [`LmbFilter::predict_step`]: births, update with
    /// `measurements`, resampling and pruning; returns the MAP multi-object estimate. An error
    /// when no step is predicted or the measurements have the wrong dimension (the prediction
    /// then stays pending).
    pub fn update_step(&mut self, measurements: &Measurements) -> Result<Vec<Estimate>> {
        self.update_step_with(measurements, StepData::new())
    }

    /// [`LmbFilter::update_step`] with `data` added to the step's data (replacing values of the
    /// same types) before the update's models see it: data that exists only once the frame's
    /// measurements do, such as what the scan's detections hide (the drive tracker's
    /// occlusion of clusters). The prediction's models saw the step's data without it.
    pub fn update_step_with(
        &mut self,
        measurements: &Measurements,
        data: StepData,
    ) -> Result<Vec<Estimate>> {
        if self.pending.is_none() {
            return Err(Error::invalid(
                format!("update of step {}", self.step),
                "the step was not predicted (call predict_step first)",
            ));
        }
        let z = measurements;
        self.check_measurements(z)?;
        let Some(Pending {
            context: mut ctx,
            seed,
            summaries,
        }) = self.pending.take()
        else {
            unreachable!("checked above");
        };
        ctx.data.extend(data);
        self.add_births(&ctx, z, seed, &summaries)?;
        let predicted = self.predicted_copies();
        let likelihoods = self.likelihoods(z, &ctx, &summaries)?;
        let marginals = self.associate(z, &ctx, &likelihoods, seed);
        let assigned = self.update(&likelihoods, &marginals, z.len());
        let merged = self.merge_duplicates(&likelihoods, &marginals);
        let resampled = self.resample(seed, &merged);
        self.record_diagnostics(predicted, likelihoods, &marginals, &resampled);
        self.prune();
        let estimates = map_estimates(&self.tracks);

        self.carry_over(ctx, z, assigned);
        Ok(estimates)
    }

    /// Prediction and, when `summaries`, the predicted tracks' gate summaries; the step is
    /// then pending.
    fn predict_phase(
        &mut self,
        time: f64,
        platform: Option<Isometry3<f64>>,
        data: StepData,
        rng: &mut FilterRng,
        summaries: bool,
    ) -> Result<()> {
        if self.pending.is_some() {
            return Err(Error::invalid(
                format!("prediction of step {}", self.step),
                "the step is predicted already and not yet updated (call update_step)",
            ));
        }
        let ctx = self.context(time, platform, data)?;
        let seed = rng.next_u64();
        self.predict(&ctx, seed)?;
        let summaries: Vec<TrackSummary> = if summaries {
            self.tracks
                .par_iter()
                .map(|t| TrackSummary::of(&t.particles))
                .collect()
        } else {
            Vec::new()
        };
        self.pending = Some(Pending {
            context: ctx,
            seed,
            summaries,
        });
        Ok(())
    }

    /// Rejects measurements that do not have the measurement model's dimension.
    fn check_measurements(&self, z: &Measurements) -> Result<()> {
        if !z.is_empty() && z.dim() != self.models.measurement.measurement_dim() {
            return Err(Error::invalid(
                format!("measurements of step {}", self.step),
                format!(
                    "have dimension {}, the measurement model expects {}",
                    z.dim(),
                    self.models.measurement.measurement_dim()
                ),
            ));
        }
        Ok(())
    }

    /// The step context: time step from the previous frame, platform poses, the frame's data.
    /// Rejects a time or pose that is not finite, or a time that goes backwards.
    fn context(
        &self,
        time: f64,
        platform: Option<Isometry3<f64>>,
        data: StepData,
    ) -> Result<StepContext> {
        let what = || format!("frame of step {}", self.step);
        if !time.is_finite() {
            return Err(Error::invalid(
                what(),
                format!("time stamp {time} is not finite"),
            ));
        }
        if let Some(p) = &platform {
            let v = p.to_homogeneous();
            if v.iter().any(|x| !x.is_finite()) {
                return Err(Error::invalid(what(), "platform pose is not finite"));
            }
        }
        let (dt, previous_platform) = match &self.previous {
            None => (0.0, None),
            Some(p) => (time - p.context.time, p.context.platform),
        };
        if dt < 0.0 {
            return Err(Error::invalid(
                what(),
                format!("time goes backwards by {} s", -dt),
            ));
        }
        Ok(StepContext {
            step: self.step,
            time,
            dt,
            platform,
            previous_platform,
            data,
        })
    }

    /// Prediction: survival reweighting r₊ = r·Σ wᵢ p_S(xᵢ), then the transition, per track.
    /// Survival and transition of every track, in parallel. A transition model that leaves a
    /// particle with a non-finite state component is an error naming the track (the first such
    /// track in track order, whatever the thread count), never a silently lost track.
    fn predict(&mut self, ctx: &StepContext, seed: u64) -> Result<()> {
        if self.previous.is_none() {
            return Ok(());
        }
        let m = &self.models;
        let step = self.step;
        let lag = self.config.smoothing_lag;
        let bad: Vec<Option<String>> = self
            .tracks
            .par_iter_mut()
            .map(|t| {
                let mut rng = stream(seed, KEY_PREDICT ^ t.label.key());
                let mut ps = vec![0.0; t.particles.len()];
                m.survival.survival_probability(&t.particles, ctx, &mut ps);
                ps.iter_mut()
                    .for_each(|p| *p = if p.is_nan() { 0.0 } else { p.clamp(0.0, 1.0) });
                // η_S = Σ wᵢ p_S(xᵢ); a constant p_S leaves the weights as they are.
                let eta_s = match ps.first() {
                    Some(&p0) if ps.iter().all(|&p| p == p0) => p0,
                    _ => t.particles.reweight(&ps),
                };
                t.existence *= eta_s.clamp(0.0, 1.0);
                t.particles.keep_history(lag);
                t.particles.push_history();
                if let Err(e) = m.transition.predict(&mut t.particles, ctx, &mut rng) {
                    return Some(format!("track {}: {e}", t.label));
                }
                t.age += 1;
                (0..t.particles.dim()).find_map(|c| {
                    let v = t.particles.component(c);
                    v.iter().position(|x| !x.is_finite()).map(|i| {
                        format!(
                            "the transition model left particle {i} of track {} with component \
                         {c} = {}",
                            t.label, v[i]
                        )
                    })
                })
            })
            .collect();
        match bad.into_iter().flatten().next() {
            Some(why) => Err(Error::invalid(format!("prediction of step {step}"), why)),
            None => Ok(()),
        }
    }

    /// Appends the birth tracks of this step, labelled (step, index). A birth model that
    /// samples near this step's measurements is told how unexplained the predicted tracks
    /// (gated by their `summaries`, empty when `z` is) leave each of them.
    fn add_births(
        &mut self,
        ctx: &StepContext,
        z: &Measurements,
        seed: u64,
        summaries: &[TrackSummary],
    ) -> Result<()> {
        let evidence = self.previous.as_ref().map(|p| BirthEvidence {
            measurements: &p.measurements,
            assigned: &p.assigned,
            context: &p.context,
        });
        let m = &self.models;
        let u = if m.birth.uses_current_measurements() {
            unexplained(&self.tracks, summaries, z, &*m.measurement, ctx)
        } else {
            Vec::new()
        };
        let current = CurrentMeasurements {
            measurements: z,
            unexplained: &u,
        };
        let births = m.birth.birth_guided(
            ctx,
            evidence.as_ref(),
            &current,
            &mut stream(seed, KEY_BIRTH),
        );
        let step = self.step;
        let transition = &self.models.transition;
        let dim = transition.state_dim();
        let new: Result<Vec<Track>> = births
            .into_par_iter()
            .enumerate()
            .filter(|(_, b)| b.existence > 0.0 && !b.particles.is_empty())
            .map(|(i, b)| {
                let label = Label::new(step, i as u32);
                if b.particles.dim() != dim {
                    return Err(Error::invalid(
                        format!("birth {label} of step {step}"),
                        format!(
                            "{} drew states of {} components, but {} moves states of {dim}",
                            m.birth.name(),
                            b.particles.dim(),
                            transition.name()
                        ),
                    ));
                }
                let mut particles = b.particles;
                if b.at_previous_step && ctx.dt > 0.0 {
                    transition
                        .predict(
                            &mut particles,
                            ctx,
                            &mut stream(seed, KEY_PREDICT ^ label.key()),
                        )
                        .map_err(|e| {
                            Error::invalid(
                                format!("prediction of birth {label} of step {step}"),
                                e.to_string(),
                            )
                        })?;
                }
                Ok(Track::new(label, b.existence.min(1.0), particles))
            })
            .collect();
        self.tracks.extend(new?);
        Ok(())
    }

    /// Gating and the particle sums η_j(ℓ) and η_miss(ℓ) for every track, in parallel; the
    /// tracks that `summaries` covers (the predicted ones) are gated by them, this step's
    /// births by their own. A measurement model that returns NaN or +∞ as a log-likelihood is
    /// an error naming the track and measurement (the first in track order); −∞ is a valid
    /// "impossible".
    fn likelihoods(
        &self,
        z: &Measurements,
        ctx: &StepContext,
        summaries: &[TrackSummary],
    ) -> Result<Vec<TrackLikelihoods>> {
        let m = &self.models;
        let step = self.step;
        let all: Vec<Result<TrackLikelihoods>> = self
            .tracks
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
    fn associate(
        &self,
        z: &Measurements,
        ctx: &StepContext,
        lik: &[TrackLikelihoods],
        seed: u64,
    ) -> Vec<TrackMarginals> {
        let log_kappa: Vec<f64> = z
            .iter()
            .map(|zj| self.models.clutter.log_intensity(zj, ctx))
            .collect();
        let gated: Vec<Vec<usize>> = lik
            .iter()
            .map(|l| l.pairs.iter().map(|p| p.measurement).collect())
            .collect();
        let groups = partition(&gated, z.len());
        let tracks = &self.tracks;
        let associator = &self.models.associator;
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
                    associator.marginals(&problem, &mut stream(seed, KEY_ASSOCIATE ^ key))
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
        let mut out: Vec<Option<TrackMarginals>> = (0..self.tracks.len()).map(|_| None).collect();
        for (ti, tm) in solved.into_iter().flatten() {
            out[ti] = Some(tm);
        }
        out.into_iter()
            .map(|o| o.expect("every track is in one group"))
            .collect()
    }

    /// The GLMB → LMB update of existence and particle weights, per track. Returns, for every
    /// measurement, the probability that some track generated it.
    fn update(
        &mut self,
        lik: &[TrackLikelihoods],
        marg: &[TrackMarginals],
        n_meas: usize,
    ) -> Vec<f64> {
        self.tracks
            .par_iter_mut()
            .zip(lik.par_iter())
            .zip(marg.par_iter())
            .for_each(|((t, l), mg)| update_track(t, l, mg));
        let mut assigned = vec![0.0; n_meas];
        for (l, mg) in lik.iter().zip(marg) {
            for &(k, p) in &mg.detect {
                assigned[l.pairs[k].measurement] += p;
            }
        }
        assigned.iter_mut().for_each(|a| *a = a.min(1.0));
        assigned
    }

    /// Resampling, per track: to the track's particle count ([`LmbConfig::particles`], or the
    /// existence-scaled count of [`LmbConfig::min_particles`]) with jitter, when its count is
    /// off that number (any difference for a fixed count, beyond a factor of two for a scaled
    /// one) or its effective sample size is below `resample_threshold` times its count.
    /// Returns for every track whether it was resampled.
    fn resample(&mut self, seed: u64, merged: &[bool]) -> Vec<bool> {
        let cfg = &self.config;
        let caps = &self.particle_caps;
        self.tracks
            .par_iter_mut()
            .zip(merged)
            .map(|(t, &merged)| {
                let n = t.particles.len();
                let cap = caps.get(&t.label).map(|&c| c.max(1));
                let (target, off) = match (cfg.min_particles, cap) {
                    (None, None) => (cfg.particles, n != cfg.particles),
                    (min, cap) => {
                        let target = match min {
                            None => cfg.particles,
                            Some(min) => {
                                let scaled = (t.existence * cfg.particles as f64).ceil();
                                (scaled as usize).max(min).min(cfg.particles)
                            }
                        };
                        let target = cap.map_or(target, |c| target.min(c));
                        (target, 2 * n < target || n > 2 * target)
                    }
                };
                let resample = merged
                    || off
                    || t.particles.effective_sample_size() < cfg.resample_threshold * n as f64;
                if resample {
                    let mut rng = stream(seed, KEY_RESAMPLE ^ t.label.key());
                    t.particles.resample(target, cfg.jitter, &mut rng);
                }
                resample
            })
            .collect()
    }

    /// Merges duplicate tracks ([`super::merge`]) when [`LmbConfig::merge_threshold`] is set:
    /// tracks whose most probable measurement is the same. Returns for every track whether it
    /// absorbed another (and must be resampled to its count); an absorbed track is left with
    /// existence 0 for pruning.
    fn merge_duplicates(&mut self, lik: &[TrackLikelihoods], marg: &[TrackMarginals]) -> Vec<bool> {
        let mut merged = vec![false; self.tracks.len()];
        let Some(threshold) = self.config.merge_threshold else {
            return merged;
        };
        let claims: Vec<Option<usize>> = lik
            .iter()
            .zip(marg)
            .map(|(l, mg)| {
                mg.most_probable(l)
                    .filter(|&(_, p)| p > 0.0)
                    .map(|(j, _)| j)
            })
            .collect();
        for (keep, drop) in duplicate_pairs(
            &self.tracks,
            &claims,
            &*self.models.merge_distance,
            threshold,
        ) {
            // Two different tracks in range: `duplicate_pairs` pairs a track with another.
            if let Ok([a, b]) = self.tracks.get_disjoint_mut([keep, drop]) {
                merged[keep] |= merge_into(a, b);
            }
        }
        merged
    }

    /// A copy of every track's particle set as predicted (births as drawn), taken before the
    /// update reweights them, for [`LmbFilter::predicted`]; empty unless
    /// [`LmbFilter::keep_predicted`] is on.
    fn predicted_copies(&self) -> Vec<(Label, ParticleSet)> {
        if !self.keep_predicted {
            return Vec::new();
        }
        self.tracks
            .iter()
            .map(|t| (t.label, t.particles.clone()))
            .collect()
    }

    /// What the step leaves for inspection, recorded before pruning while the tracks still line
    /// up with `lik`, `marg` and `resampled`: the predicted particle sets (when kept), each
    /// track's most probable measurement, and the detection probabilities of the tracks whose
    /// particles did not move in resampling.
    fn record_diagnostics(
        &mut self,
        predicted: Vec<(Label, ParticleSet)>,
        lik: Vec<TrackLikelihoods>,
        marg: &[TrackMarginals],
        resampled: &[bool],
    ) {
        self.predicted.clear();
        self.predicted.extend(predicted);
        self.most_probable.clear();
        for ((t, l), mg) in self.tracks.iter().zip(&lik).zip(marg) {
            if let Some((measurement, probability)) = mg.most_probable(l) {
                self.most_probable.push(MostProbableMeasurement {
                    label: t.label,
                    measurement,
                    probability,
                });
            }
        }
        self.unmoved_detection.clear();
        for ((t, l), &moved) in self.tracks.iter().zip(lik).zip(resampled) {
            if !moved {
                self.unmoved_detection.push((t.label, l.pd));
            }
        }
    }

    /// Removes tracks below the existence threshold and keeps at most `max_tracks`.
    fn prune(&mut self) {
        let threshold = self.config.prune_threshold;
        self.tracks
            .retain(|t| t.existence >= threshold && t.existence > 0.0);
        if self.tracks.len() > self.config.max_tracks {
            self.tracks.sort_by(|a, b| {
                b.existence
                    .total_cmp(&a.existence)
                    .then(a.label.cmp(&b.label))
            });
            self.tracks.truncate(self.config.max_tracks);
            self.tracks.sort_by_key(|t| t.label);
        }
    }

    /// Keeps what the next step needs (this step's context, measurements and their
    /// association probabilities, for the time step and adaptive birth) and counts the step.
    fn carry_over(&mut self, ctx: StepContext, z: &Measurements, assigned: Vec<f64>) {
        self.previous = Some(Previous {
            context: ctx,
            measurements: z.clone(),
            assigned,
        });
        self.step += 1;
    }
}

/// ln(1 − r + r·η_miss); −∞ when the track surely exists and is surely detected.
fn log_miss_weight(r: f64, eta_miss: f64) -> f64 {
    (1.0 - r + r * eta_miss).max(0.0).ln()
}

/// Posterior existence and particle weights of one track from its association marginals
/// (the LMB approximation of the GLMB posterior, Reuter et al. 2014, eqs. 20–21, with the
/// miss/absence hypotheses split as in the marginal form of the fast LMB update).
fn update_track(t: &mut Track, l: &TrackLikelihoods, mg: &TrackMarginals) {
    let r = t.existence;
    let denom = 1.0 - r + r * l.eta_miss;
    // Probability that the track exists and was missed.
    let p_missed = if denom > 0.0 {
        mg.miss * (r * l.eta_miss / denom)
    } else {
        0.0
    };
    let p_detected: f64 = mg.detect.iter().map(|(_, p)| p).sum();
    let r_post = (p_missed + p_detected).clamp(0.0, 1.0);
    t.existence = r_post;
    t.expected_detections += p_detected;
    if r_post <= 0.0 {
        return;
    }
    let detected: Vec<(usize, f64)> = mg
        .detect
        .iter()
        .copied()
        .filter(|(_, p)| *p > 0.0)
        .collect();
    if detected.is_empty() && l.pd.windows(2).all(|w| w[0] == w[1]) {
        return; // only the miss term, constant over particles: weights unchanged
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
    t.particles.reweight(&factor);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn config_limits_are_enforced_and_named() {
        assert!(LmbConfig::default().validate().is_ok());
        let at_limits = LmbConfig {
            particles: MAX_PARTICLES,
            max_tracks: MAX_TRACKS,
            ..LmbConfig::default()
        };
        assert!(at_limits.validate().is_ok());
        for (config, field) in [
            (
                LmbConfig {
                    particles: 1_000_000_000_000,
                    ..LmbConfig::default()
                },
                "particles",
            ),
            (
                LmbConfig {
                    particles: 0,
                    ..LmbConfig::default()
                },
                "particles",
            ),
            (
                LmbConfig {
                    max_tracks: MAX_TRACKS + 1,
                    ..LmbConfig::default()
                },
                "max_tracks",
            ),
            (
                LmbConfig {
                    merge_threshold: Some(f64::NAN),
                    ..LmbConfig::default()
                },
                "merge_threshold",
            ),
            (
                LmbConfig {
                    merge_threshold: Some(-1.0),
                    ..LmbConfig::default()
                },
                "merge_threshold",
            ),
        ] {
            let e = config.validate().unwrap_err().to_string();
            assert!(e.contains(field), "{e}");
        }
    }
}
