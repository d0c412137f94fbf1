//! The LMB filter: one call of [`LmbFilter::step`] per frame runs the recursion of Reuter, Vo,
//! Vo & Dietmayer (IEEE TSP 2014) with particle densities (as in the SMC implementation of the
//! planar-feature LMB paper, Sec. 4):
//!
//! predict → birth → gate → likelihoods → associate → update → resample → prune → estimate.
//!
//! With several sensors the gate → update stages run once per sensor, in turn or on the same
//! predicted tracks and then combined ([`super::fusion`]).
//!
//! Each stage is one function, here or, for one sensor's gate → update, in the private
//! `update` module beside this one (gating is part of `likelihoods`), and what a step keeps
//! for inspection afterwards is recorded by one more (`record_diagnostics`). Work per track and
//! per association group runs in parallel with rayon; every track draws from its own random
//! stream derived from the step seed and its label, so results are bit-identical whatever the
//! number of threads. Not for: models (see [`crate::models`]), association algorithms (see
//! [`super::association`]).

use super::association::{AssociationMethod, Associator};
use super::birth::{unexplained, BirthEvidence, BirthModel, CurrentMeasurements};
use super::estimate::map_estimates;
use super::fusion::{fuse_track, Fusion, FusionMethod, SensorPosterior};
use super::merge::{duplicate_pairs, merge_into, MergeDistance, ScaledDistance};
use super::sensor::{check_sensors, Scan, Sensor, DEFAULT_SENSOR};
use super::track::{Estimate, Track};
use super::update::{
    apply_posterior, assigned, associate, likelihoods, posterior, sensor_key, TrackLikelihoods,
    TrackMarginals,
};
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
use std::borrow::Cow;
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
    /// The measurements of every sensor that reported in the frame, at most one scan per
    /// sensor (a filter with one sensor: its measurements, sensor 0).
    pub scans: Vec<Scan>,
    /// Pose of the sensing platform in the world frame, if it moves.
    pub platform: Option<Isometry3<f64>>,
    /// What the frame brings for particular models (a vehicle state, a scan's beams, ...),
    /// handed to every model in the step's [`StepContext::data`].
    pub data: StepData,
}

impl Frame {
    /// A frame of sensor 0's `measurements` (the one sensor of a filter with one), from a
    /// static platform.
    pub fn new(time: f64, measurements: Measurements) -> Self {
        Frame::at_time(time).with_sensor(0, measurements)
    }

    /// A frame at `time` in which no sensor has reported yet (see [`Frame::with_sensor`]); a
    /// frame with no scan at all predicts the tracks and updates nothing.
    pub fn at_time(time: f64) -> Self {
        Frame {
            time,
            scans: Vec::new(),
            platform: None,
            data: StepData::new(),
        }
    }

    /// The same frame with sensor `sensor`'s `measurements` (its index in the filter's
    /// sensors, see [`LmbFilter::sensor_index`]), in the sensor's own frame.
    pub fn with_sensor(mut self, sensor: usize, measurements: Measurements) -> Self {
        self.scans.push(Scan::new(sensor, measurements));
        self
    }

    /// The same frame with `scan` (a sensor's measurements and the data only its models see).
    pub fn with_scan(mut self, scan: Scan) -> Self {
        self.scans.push(scan);
        self
    }

    /// Sensor `sensor`'s measurements in this frame, if it reported.
    pub fn measurements_of(&self, sensor: usize) -> Option<&Measurements> {
        self.scans
            .iter()
            .find(|s| s.sensor == sensor)
            .map(|s| &s.measurements)
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
    sensors: Vec<Sensor>,
    fusion: Fusion,
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
    /// The measurement model of a filter with one sensor (required, unless the sensors are
    /// given by [`LmbFilterBuilder::sensor`]).
    pub fn measurement(mut self, m: impl MeasurementModel + 'static) -> Self {
        self.measurement = Some(Box::new(m));
        self
    }
    /// The detection model of a filter with one sensor (required, unless the sensors are given
    /// by [`LmbFilterBuilder::sensor`]).
    pub fn detection(mut self, m: impl DetectionModel + 'static) -> Self {
        self.detection = Some(Box::new(m));
        self
    }
    /// The clutter model of a filter with one sensor (required, unless the sensors are given
    /// by [`LmbFilterBuilder::sensor`]).
    pub fn clutter(mut self, m: impl ClutterModel + 'static) -> Self {
        self.clutter = Some(Box::new(m));
        self
    }
    /// [`LmbFilterBuilder::measurement`] with a model already boxed.
    pub(crate) fn measurement_box(mut self, m: Box<dyn MeasurementModel>) -> Self {
        self.measurement = Some(m);
        self
    }
    /// [`LmbFilterBuilder::detection`] with a model already boxed.
    pub(crate) fn detection_box(mut self, m: Box<dyn DetectionModel>) -> Self {
        self.detection = Some(m);
        self
    }
    /// Adds a sensor with its own models; sensors are numbered in the order they are added.
    /// A filter is built either with sensors or with one set of measurement, detection and
    /// clutter models, not both.
    pub fn sensor(mut self, s: Sensor) -> Self {
        self.sensors.push(s);
        self
    }
    /// How several sensors' updates combine (default: [`Fusion::default`], the iterated
    /// corrector in sensor order).
    pub fn fusion(mut self, f: Fusion) -> Self {
        self.fusion = f;
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
    ///
    /// With several sensors: the sensors' names are unique, their measurements have one
    /// dimension, and the fusion's weights and order fit them (see [`Fusion::validate`]).
    pub fn build(self) -> Result<LmbFilter> {
        self.config.validate()?;
        let missing = |what: &str| Error::invalid("filter", format!("no {what} model given"));
        let transition = self.transition.ok_or_else(|| missing("transition"))?;
        let birth = self.birth.ok_or_else(|| missing("birth"))?;
        let sensors = if self.sensors.is_empty() {
            vec![Sensor::from_boxes(
                DEFAULT_SENSOR.to_string(),
                self.measurement.ok_or_else(|| missing("measurement"))?,
                self.detection.ok_or_else(|| missing("detection"))?,
                self.clutter.ok_or_else(|| missing("clutter"))?,
            )]
        } else {
            if self.measurement.is_some() || self.detection.is_some() || self.clutter.is_some() {
                return Err(Error::invalid(
                    "filter",
                    "both sensors and a filter-wide measurement, detection or clutter model \
                     given; give each sensor its own",
                ));
            }
            self.sensors
        };
        check_sensors(&sensors)?;
        for s in &sensors {
            check_dimensions(&*transition, &*s.measurement, &*birth).map_err(|e| match e {
                Error::InvalidInput { what, reason } if sensors.len() > 1 => {
                    Error::invalid(what, format!("sensor {:?}: {reason}", s.name))
                }
                other => other,
            })?;
        }
        self.fusion.validate(sensors.len())?;
        Ok(LmbFilter {
            models: Models {
                transition,
                survival: self
                    .survival
                    .unwrap_or_else(|| Box::new(ConstantSurvival(0.99))),
                sensors,
                fusion: self.fusion,
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
            most_probable_all: Vec::new(),
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
    /// At least one; every sensor's measurements have the same dimension.
    sensors: Vec<Sensor>,
    fusion: Fusion,
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

/// What a step's sensor updates leave for the rest of the step.
struct SensorUpdates {
    /// The first updating sensor's likelihood rows, one per track (duplicate merge,
    /// diagnostics).
    likelihoods: Vec<TrackLikelihoods>,
    /// Its association marginals, one row per track.
    marginals: Vec<TrackMarginals>,
    /// Whether it was the only sensor (the tracks' particles are those its rows saw).
    only: bool,
    /// For every measurement of every sensor, in sensor order, the probability that some
    /// track generated it.
    assigned: Vec<f64>,
    /// With several sensors: for each sensor, each track's most probable measurement of that
    /// sensor's scan with its probability (empty with one sensor).
    most_probable_by_sensor: Vec<(usize, Vec<MostProbableRow>)>,
}

/// A track's most probable measurement of one sensor's scan and its probability, if any.
type MostProbableRow = Option<(usize, f64)>;

/// Each track's most probable measurement by the rows of one sensor's likelihoods and
/// marginals.
fn most_probable_rows(lik: &[TrackLikelihoods], marg: &[TrackMarginals]) -> Vec<MostProbableRow> {
    lik.iter()
        .zip(marg)
        .map(|(l, mg)| mg.most_probable(l))
        .collect()
}

/// The measurements of `scans` (in sensor order) one after another; borrowed when there is
/// one scan. `dim` is the dimension of an empty result.
fn concatenated<'a>(scans: &'a [SensorScan<'a>], dim: usize) -> Cow<'a, Measurements> {
    match scans {
        [] => Cow::Owned(Measurements::empty(dim)),
        [one] => Cow::Borrowed(one.z.as_ref()),
        _ => {
            let mut all = Measurements::empty(dim);
            for z in scans.iter().flat_map(|s| s.z.iter()) {
                all.push(z).expect("checked: one dimension, finite");
            }
            Cow::Owned(all)
        }
    }
}

/// One sensor's scan inside an update: its measurements (moved to the platform frame where
/// the sensor is mounted) and, when the scan brought data of its own, the context its models
/// see (the step's with that data added).
struct SensorScan<'a> {
    sensor: usize,
    z: Cow<'a, Measurements>,
    own: Option<StepContext>,
}

impl SensorScan<'_> {
    /// The context this sensor's models see in a step whose context is `step`.
    fn ctx<'b>(&'b self, step: &'b StepContext) -> &'b StepContext {
        self.own.as_ref().unwrap_or(step)
    }
}

/// A scan as the update takes it: sensor index, measurements, the scan's own data and
/// platform pose if any.
type ScanRef<'a> = (
    usize,
    &'a Measurements,
    Option<&'a StepData>,
    Option<Isometry3<f64>>,
);

/// Per-sensor vectors joined in sensor order.
fn in_sensor_order(mut by_sensor: Vec<(usize, Vec<f64>)>) -> Vec<f64> {
    by_sensor.sort_by_key(|(s, _)| *s);
    by_sensor.into_iter().flat_map(|(_, v)| v).collect()
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
    /// … of every sensor's scan, indexed among all sensors' measurements in sensor order.
    most_probable_all: Vec<MostProbableMeasurement>,
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
        self.most_probable_all.clear();
        self.predicted.clear();
        self.pending = None;
    }

    /// Each track's most probable measurement of the last step, with its marginal
    /// association probability (tracks that could explain no measurement are left out).
    pub fn most_probable_measurements(&self) -> &[MostProbableMeasurement] {
        &self.most_probable
    }

    /// Each track's most probable measurement of the last step in the scan of every sensor
    /// that reported (with one sensor, [`LmbFilter::most_probable_measurements`]): a track
    /// appears once per sensor whose measurements it could explain, and
    /// [`MostProbableMeasurement::measurement`] indexes the measurements of all sensors one
    /// after another in sensor order (those the births and [`BirthEvidence`] see).
    pub fn most_probable_measurements_all(&self) -> &[MostProbableMeasurement] {
        &self.most_probable_all
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
        let scans: Vec<ScanRef> = frame
            .scans
            .iter()
            .map(|s| (s.sensor, &s.measurements, Some(&s.data), s.platform))
            .collect();
        self.check_scans(&scans)?;
        self.predict_phase(
            frame.time,
            frame.platform,
            frame.data.clone(),
            rng,
            scans.iter().any(|(_, z, _, _)| !z.is_empty()),
        )?;
        self.update_scans(&scans, StepData::new())
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
        let scans: [ScanRef; 1] = [(0, measurements, None, None)];
        self.check_scans(&scans)?;
        self.update_scans(&scans, data)
    }

    /// [`LmbFilter::update_step_with`] for a filter with several sensors: `scans` holds a
    /// scan for every sensor that reported, each at most once (with the data only that
    /// sensor's models see, [`Scan::data`]).
    pub fn update_step_scans(&mut self, scans: &[Scan], data: StepData) -> Result<Vec<Estimate>> {
        let scans: Vec<ScanRef> = scans
            .iter()
            .map(|s| (s.sensor, &s.measurements, Some(&s.data), s.platform))
            .collect();
        self.check_scans(&scans)?;
        self.update_scans(&scans, data)
    }

    /// The filter's sensors, in index order.
    pub fn sensors(&self) -> &[Sensor] {
        &self.models.sensors
    }

    /// The index of the sensor called `name`.
    pub fn sensor_index(&self, name: &str) -> Option<usize> {
        self.models.sensors.iter().position(|s| s.name == name)
    }

    /// How the sensors' updates combine.
    pub fn fusion(&self) -> &Fusion {
        &self.models.fusion
    }

    /// The second half of a step, with scans already checked by [`LmbFilter::check_scans`].
    fn update_scans(&mut self, scans: &[ScanRef], data: StepData) -> Result<Vec<Estimate>> {
        let Some(Pending {
            context: mut ctx,
            seed,
            summaries,
        }) = self.pending.take()
        else {
            return Err(Error::invalid(
                format!("update of step {}", self.step),
                "the step was not predicted (call predict_step first)",
            ));
        };
        ctx.data.extend(data);
        // In sensor order, moved to the platform frame where a sensor is mounted, each with
        // the context its models see.
        let mut scans: Vec<SensorScan> = scans
            .iter()
            .map(|&(sensor, z, own, platform)| SensorScan {
                sensor,
                z: match self.models.sensors[sensor].mounting {
                    Some(m) => Cow::Owned(m.to_platform(z)),
                    None => Cow::Borrowed(z),
                },
                own: match (own.filter(|d| !d.is_empty()), platform) {
                    (None, None) => None,
                    (d, p) => {
                        let mut c = ctx.clone();
                        if let Some(d) = d {
                            c.data.extend(d.clone());
                        }
                        if p.is_some() {
                            c.platform = p;
                        }
                        Some(c)
                    }
                },
            })
            .collect();
        scans.sort_by_key(|s| s.sensor);
        let all = concatenated(&scans, self.models.sensors[0].measurement_dim());
        self.add_births(&ctx, &scans, &all, seed, &summaries)?;
        let predicted = self.predicted_copies();
        let updated = match (scans.len(), self.models.fusion.method) {
            (0, _) => None,
            (1, _) | (_, FusionMethod::IteratedCorrector) => {
                Some(self.update_in_turn(&scans, &ctx, seed, summaries)?)
            }
            (_, method) => Some(self.update_in_parallel(method, &scans, &ctx, seed, &summaries)?),
        };
        let (merged, assigned, first) = match updated {
            None => (vec![false; self.tracks.len()], Vec::new(), None),
            Some(mut u) => (
                self.merge_duplicates(&u.likelihoods, &u.marginals),
                std::mem::take(&mut u.assigned),
                Some(u),
            ),
        };
        let resampled = self.resample(seed, &merged);
        // Where each sensor's measurements start among all of them (sensor order).
        let offsets: Vec<(usize, usize)> = scans
            .iter()
            .scan(0, |at, s| {
                let here = *at;
                *at += s.z.len();
                Some((s.sensor, here))
            })
            .collect();
        self.record_diagnostics(predicted, first, &resampled, &offsets);
        self.prune();
        let estimates = map_estimates(&self.tracks);

        self.carry_over(ctx, &all, assigned);
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

    /// Rejects a scan of a sensor the filter does not have, two scans of one sensor, and
    /// measurements that do not have their sensor's measurement dimension (an empty scan may
    /// have any), naming the sensor.
    fn check_scans(&self, scans: &[ScanRef]) -> Result<()> {
        let sensors = &self.models.sensors;
        let what = || format!("measurements of step {}", self.step);
        for (k, &(s, z, _, platform)) in scans.iter().enumerate() {
            let Some(sensor) = sensors.get(s) else {
                return Err(Error::invalid(
                    what(),
                    format!(
                        "a scan of sensor {s}, but the filter has {} sensor{}",
                        sensors.len(),
                        if sensors.len() == 1 { "" } else { "s" }
                    ),
                ));
            };
            if let Some(p) = platform {
                if p.to_homogeneous().iter().any(|x| !x.is_finite()) {
                    return Err(Error::invalid(
                        what(),
                        format!(
                            "the platform pose of sensor {s} ({:?}) is not finite",
                            sensor.name
                        ),
                    ));
                }
            }
            if scans[..k].iter().any(|&(o, _, _, _)| o == s) {
                return Err(Error::invalid(
                    what(),
                    format!("two scans of sensor {s} ({:?}) in one frame", sensor.name),
                ));
            }
            if !z.is_empty() && z.dim() != sensor.measurement_dim() {
                let whose = if sensors.len() == 1 {
                    String::new()
                } else {
                    format!(" of sensor {s} ({:?})", sensor.name)
                };
                return Err(Error::invalid(
                    format!("{}{whose}", what()),
                    format!(
                        "have dimension {}, the measurement model expects {}",
                        z.dim(),
                        sensor.measurement_dim()
                    ),
                ));
            }
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
    ///
    /// The birth model sees the measurements of every sensor that reported, in sensor order
    /// (`all`, the concatenation of `scans`), each judged unexplained by its own sensor's
    /// measurement model.
    fn add_births(
        &mut self,
        ctx: &StepContext,
        scans: &[SensorScan],
        all: &Measurements,
        seed: u64,
        summaries: &[TrackSummary],
    ) -> Result<()> {
        let evidence = self.previous.as_ref().map(|p| BirthEvidence {
            measurements: &p.measurements,
            assigned: &p.assigned,
            context: &p.context,
        });
        let m = &self.models;
        let u: Vec<f64> = if m.birth.uses_current_measurements() {
            scans
                .iter()
                .flat_map(|s| {
                    let sensor = &*m.sensors[s.sensor].measurement;
                    unexplained(&self.tracks, summaries, &s.z, sensor, s.ctx(ctx))
                })
                .collect()
        } else {
            Vec::new()
        };
        let current = CurrentMeasurements {
            measurements: all,
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

    /// The update by each sensor of `scans` in turn (IC; with one sensor, the single-sensor
    /// update): gating, likelihoods, association and the posterior of every track, then, when
    /// another sensor follows, resampling of the tracks whose weights collapsed and fresh gate
    /// summaries. `summaries` gate the predicted tracks for the first sensor.
    fn update_in_turn(
        &mut self,
        scans: &[SensorScan],
        ctx: &StepContext,
        seed: u64,
        summaries: Vec<TrackSummary>,
    ) -> Result<SensorUpdates> {
        let order = self
            .models
            .fusion
            .ordered(&scans.iter().map(|s| s.sensor).collect::<Vec<_>>());
        let mut assigned_by_sensor: Vec<(usize, Vec<f64>)> = Vec::with_capacity(order.len());
        let mut most_probable_by_sensor = Vec::new();
        let mut first = None;
        let mut summaries = summaries;
        for (k, &s) in order.iter().enumerate() {
            let scan = scans.iter().find(|i| i.sensor == s).expect("present");
            let (z, ctx) = (&*scan.z, scan.ctx(ctx));
            let sensor = &self.models.sensors[s];
            let lik = likelihoods(&self.tracks, sensor, z, ctx, &summaries)?;
            let marg = associate(
                &self.tracks,
                sensor,
                &*self.models.associator,
                z,
                ctx,
                &lik,
                seed,
                sensor_key(s),
            );
            self.tracks
                .par_iter_mut()
                .zip(lik.par_iter())
                .zip(marg.par_iter())
                .for_each(|((t, l), mg)| {
                    let post = posterior(t.existence, l, mg);
                    apply_posterior(t, post)
                });
            assigned_by_sensor.push((s, assigned(&lik, &marg, z.len())));
            if order.len() > 1 {
                most_probable_by_sensor.push((s, most_probable_rows(&lik, &marg)));
            }
            if k + 1 < order.len() {
                self.resample_collapsed(seed ^ sensor_key(s + 1));
                summaries = self
                    .tracks
                    .par_iter()
                    .map(|t| TrackSummary::of(&t.particles))
                    .collect();
            }
            if first.is_none() {
                first = Some((lik, marg));
            }
        }
        let (likelihoods, marginals) = first.expect("at least one scan");
        Ok(SensorUpdates {
            likelihoods,
            marginals,
            only: order.len() == 1,
            assigned: in_sensor_order(assigned_by_sensor),
            most_probable_by_sensor,
        })
    }

    /// The update by every sensor of `scans` from the same predicted tracks (associations in
    /// parallel across sensors), combined per track by `method` ([`super::fusion`]).
    fn update_in_parallel(
        &mut self,
        method: FusionMethod,
        scans: &[SensorScan],
        ctx: &StepContext,
        seed: u64,
        summaries: &[TrackSummary],
    ) -> Result<SensorUpdates> {
        let present: Vec<usize> = scans.iter().map(|s| s.sensor).collect();
        let weights = self.models.fusion.weights_of(&present);
        let m = &self.models;
        let tracks = &self.tracks;
        let per_sensor: Vec<Result<(Vec<TrackLikelihoods>, Vec<TrackMarginals>)>> = scans
            .par_iter()
            .map(|scan| {
                let (s, z, ctx) = (&scan.sensor, &*scan.z, scan.ctx(ctx));
                let sensor = &m.sensors[*s];
                let lik = likelihoods(tracks, sensor, z, ctx, summaries)?;
                let marg = associate(
                    tracks,
                    sensor,
                    &*m.associator,
                    z,
                    ctx,
                    &lik,
                    seed,
                    sensor_key(*s),
                );
                Ok((lik, marg))
            })
            .collect();
        let per_sensor = per_sensor.into_iter().collect::<Result<Vec<_>>>()?;
        self.tracks.par_iter_mut().enumerate().for_each(|(ti, t)| {
            let posts: Vec<SensorPosterior> = per_sensor
                .iter()
                .map(|(lik, marg)| posterior(t.existence, &lik[ti], &marg[ti]))
                .collect();
            let r0 = t.existence;
            t.expected_detections += posts.iter().map(|p| p.detected).sum::<f64>();
            t.existence = fuse_track(method, &weights, r0, &mut t.particles, &posts);
        });
        let assigned_by_sensor = per_sensor
            .iter()
            .zip(scans)
            .map(|((lik, marg), scan)| (scan.sensor, assigned(lik, marg, scan.z.len())))
            .collect();
        let most_probable_by_sensor = per_sensor
            .iter()
            .zip(scans)
            .map(|((lik, marg), scan)| (scan.sensor, most_probable_rows(lik, marg)))
            .collect();
        let (likelihoods, marginals) = per_sensor.into_iter().next().expect("several scans");
        Ok(SensorUpdates {
            likelihoods,
            marginals,
            only: false,
            assigned: in_sensor_order(assigned_by_sensor),
            most_probable_by_sensor,
        })
    }

    /// Between two sensors' updates: resamples (to its current count, with the configured
    /// jitter) every track whose effective sample size fell below
    /// [`LmbConfig::resample_threshold`] of its count.
    fn resample_collapsed(&mut self, seed: u64) {
        let cfg = &self.config;
        self.tracks.par_iter_mut().for_each(|t| {
            let n = t.particles.len();
            if t.existence > 0.0
                && t.particles.effective_sample_size() < cfg.resample_threshold * n as f64
            {
                let mut rng = stream(seed, KEY_RESAMPLE ^ t.label.key());
                t.particles.resample(n, cfg.jitter, &mut rng);
            }
        });
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
    /// up with the first updating sensor's rows in `first` and with `resampled`: the
    /// predicted particle sets (when kept), each track's most probable measurement of that
    /// sensor, and, when that sensor was the only one, the detection probabilities of the
    /// tracks whose particles did not move in resampling.
    fn record_diagnostics(
        &mut self,
        predicted: Vec<(Label, ParticleSet)>,
        first: Option<SensorUpdates>,
        resampled: &[bool],
        offsets: &[(usize, usize)],
    ) {
        self.predicted.clear();
        self.predicted.extend(predicted);
        self.most_probable.clear();
        self.most_probable_all.clear();
        self.unmoved_detection.clear();
        let Some(first) = first else {
            return;
        };
        for (sensor, rows) in &first.most_probable_by_sensor {
            let offset = offsets
                .iter()
                .find(|(s, _)| s == sensor)
                .map_or(0, |&(_, o)| o);
            for (t, row) in self.tracks.iter().zip(rows) {
                if let Some((j, probability)) = *row {
                    self.most_probable_all.push(MostProbableMeasurement {
                        label: t.label,
                        measurement: offset + j,
                        probability,
                    });
                }
            }
        }
        for ((t, l), mg) in self
            .tracks
            .iter()
            .zip(&first.likelihoods)
            .zip(&first.marginals)
        {
            if let Some((measurement, probability)) = mg.most_probable(l) {
                self.most_probable.push(MostProbableMeasurement {
                    label: t.label,
                    measurement,
                    probability,
                });
            }
        }
        if first.most_probable_by_sensor.is_empty() {
            self.most_probable_all.clone_from(&self.most_probable);
        }
        if !first.only {
            return;
        }
        for ((t, l), &moved) in self.tracks.iter().zip(first.likelihoods).zip(resampled) {
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
