//! People tracking from planar scans with the particle LMB filter: each scan is segmented
//! (adaptive breakpoints), segments of person size become range-bearing measurements of the
//! person's centre, and the filter — constant velocity (seed 000, eqs. 6–8), range-bearing from
//! a sensor mounted at (a, b) on the robot's odometry pose (eqs. 10–11), an occlusion-aware
//! detection probability ([`super::models::OcclusionDetection`] against the current scan),
//! survival that forgets people who left the field of view, and measurement-driven birth that
//! is suppressed next to confirmed tracks ([`super::birth`]) — follows them with labels.
//! Each scan's output marks every person as static or dynamic ([`super::motion_state`]) and
//! says how visible the scanner should find them.
//!
//! Not for: deciding which segments belong to moving objects on a cluttered map (background
//! attenuation and shape learning), or the baseline trackers.

use super::birth::{ConfirmedPeople, ConfirmedPerson, Doubted, PeopleBirth};
use super::innovation::particle_innovation;
use super::models::{
    BeamView, Detectability, DetectabilityDetection, DetectabilityTransition, FieldOfViewSurvival,
    ManoeuvringVelocity, Neighbours, OcclusionDetection, ResolutionDetection, ResolutionLikelihood,
};
use super::motion_state::{probability_moving, MotionClassifier, MotionConfig};
use crate::config::{
    BirthConfig, ClutterConfig, DetectionConfig, MeasurementConfig, RunConfig, TransitionConfig,
};
use crate::error::{Error, Result};
use crate::filter::{
    AssociationMethod, Estimate, Frame, Label, LmbConfig, LmbFilter, Measurements, StepData,
};
use crate::filter::{DetectionModel, ParticleSet, StepContext, TransitionModel};
use crate::laser2d::person_groups::{person_groups, PersonGrouping};
use crate::laser2d::{BreakpointConfig, Scan};
use crate::models::{BearingConvention, ConstantVelocity, FieldOfViewDetection, RangeBearing};
use crate::rng::{seeded, FilterRng};
use crate::trackers::{BeamRanges, Innovation, PointTracker};
use nalgebra::{Isometry3, Vector3};

/// What counts as a person and how they are tracked.
#[derive(Clone, Debug, PartialEq)]
pub struct PeopleTrackerConfig {
    /// Scan segmentation.
    pub breakpoint: BreakpointConfig,
    /// Range noise σ_r of one beam (m), for grouping returns into people.
    pub beam_sigma_range: f64,
    /// Bearing noise σ_b of one beam (rad), for grouping returns into people.
    pub beam_sigma_bearing: f64,
    /// Segments wider than this (m) are not people. Default 0.8 m.
    pub max_width: f64,
    /// Groups with fewer points are ignored. Default 2.
    pub min_points: usize,
    /// Returns closer than this (m) laterally, plus 2 σ_b·r, are one group. Default 0.6 m.
    pub merge_gap: f64,
    /// A segment's middle point lies on the body surface; the centre is this much (m) farther
    /// along the beam. Default 0.2 m.
    pub body_radius: f64,
    /// A return blocks the view of a person when it is nearer than the person's surface by
    /// more than this (m). Default 3 σ_range (at least 0.15 m).
    pub occlusion_margin: f64,
    /// Survival per scan of a person outside the field of view (inside it is
    /// `filter.survival`). Default 0.8: out of sight for 2 s at 8 Hz leaves r ≈ 0.03.
    pub survival_outside: f64,
    /// No birth within this distance (m) of a confirmed track. Default 0.8 m.
    pub birth_suppress_radius: f64,
    /// … nor within this many standard deviations of its position spread, when that is
    /// farther: a track that coasted through a run of misses or an occlusion has spread out,
    /// and a person reappearing inside that spread is most likely the one it lost. Default 2
    /// (lobby OSPA(2) 1.245 → 1.235 on seeds 1–8, 1.292 → 1.269 on seeds 11–18; scenario one
    /// 98 % → 96 % of 50 runs keeping every label). 0 turns it off.
    pub birth_suppress_spread: f64,
    /// A person within this distance (m) of another confirmed track is often not resolved
    /// as a separate measurement ([`super::models::ResolutionDetection`]). Default 1.5 m.
    pub resolution_distance: f64,
    /// Beyond `resolution_distance` the effect fades out linearly over this distance (m).
    /// Default 0.5 m.
    pub resolution_fade: f64,
    /// Share of scans in which a person that close is not resolved. Default 0.5.
    pub unresolved_share: f64,
    /// Near another track the measurement noise is scaled by this: a merged measurement of
    /// two people lies anywhere between them and should pull each track less
    /// ([`super::models::ResolutionLikelihood`]). Default 2; 1 turns it off.
    pub unresolved_noise_scale: f64,
    /// Share of particles per scan whose acceleration is drawn with `manoeuvre_sigma` instead
    /// of the filter's calm σ ([`super::models::ManoeuvringVelocity`]): people who turn
    /// round or stop. Default 0.05. People who walk straight barely need it (scenario one, 50
    /// runs: 96 % keep every label, 100 % without); people who turn round do (the lobby,
    /// seeds 1–8, moving front end: OSPA(2) 1.235 against 1.435 without). 0 turns it off.
    pub manoeuvre_probability: f64,
    /// Acceleration noise (m/s²) of a manoeuvring particle. Default 5: a reversal of 1 m/s
    /// within 0.25 s.
    pub manoeuvre_sigma: f64,
    /// Misses that come in runs: when set, each person carries a detectable/undetectable mode
    /// as a fifth state component ([`super::models::detectability`]) and `filter.detection`'s
    /// p_D applies to detectable people only. Default `None` (misses independent per scan).
    pub detectability: Option<Detectability>,
    /// A track becomes a person once its existence has reached this (and stays one while it
    /// is in the filter's estimate): the confirmation threshold of IPDA-style track
    /// management. A track that flickers above 0.5 on a few detections is never reported.
    /// Default 0.99; 0.5 reports every estimate.
    pub confirm_existence: f64,
    /// … and once it has collected this many expected detections (the sum over its life of
    /// the probability that it was detected; the birth scan's measurement is not counted).
    /// Default 0.
    pub confirm_detections: f64,
    /// … and once the measurements it was most probably associated with have brought this
    /// much evidence (the sum over its life of the association probability times the
    /// measurement's evidence: the front end's classifier score, or 1 from a front end
    /// without one, see [`PeopleTracker::step_measured_with_evidence`]). A walking person's
    /// clear leg pairs reach it in a few scans, furniture legs that the classifier takes for
    /// legs now and then only slowly. Default 0.
    pub confirm_evidence: f64,
    /// A measurement whose evidence is 0 or less (one the front end's classifier doubts, see
    /// [`PeopleTracker::step_measured_with_evidence`]) is used only within this distance (m)
    /// of a track's predicted position whose existence is at least `doubted_gate_existence`,
    /// and never starts a track: it may keep a person's track fed through a few doubtful
    /// scans, but not start or feed tracks of its own. Default 0.5 m.
    pub doubted_gate: f64,
    /// See `doubted_gate`. Default 0.5.
    pub doubted_gate_existence: f64,
    /// A person is reported by [`PeopleTracker::step`] when the expected share of their
    /// beams the scanner sees is at least this. Default 0.5.
    pub min_visibility: f64,
    /// Static/dynamic thresholds.
    pub motion: MotionConfig,
    /// The filter: models and tuning (state [x, ẋ, y, ẏ] in the world frame). Its detection
    /// must be `FieldOfView` (occlusion is added on top) and its birth `Adaptive` (its
    /// parameters drive [`PeopleBirth`]).
    pub filter: RunConfig,
}

impl PeopleTrackerConfig {
    /// Defaults for a scanner with range noise `sigma_range` (m), bearing noise
    /// `sigma_bearing` (rad), `max_range` (m), a field of view of ±`half_angle` (rad), mounted
    /// at `mount` = (a, b) on the robot.
    pub fn for_scanner(
        sigma_range: f64,
        sigma_bearing: f64,
        max_range: f64,
        half_angle: f64,
        mount: [f64; 2],
    ) -> Self {
        let (centre_sigma_range, centre_sigma_bearing) = centre_noise(sigma_range, sigma_bearing);
        PeopleTrackerConfig {
            // Breakpoints at the scanner's own range noise, or a person's noisy outline splits.
            breakpoint: BreakpointConfig {
                sigma_r: sigma_range.max(BreakpointConfig::default().sigma_r),
                ..BreakpointConfig::default()
            },
            beam_sigma_range: sigma_range,
            beam_sigma_bearing: sigma_bearing,
            max_width: 0.8,
            min_points: 2,
            merge_gap: 0.6,
            body_radius: 0.2,
            occlusion_margin: (3.0 * sigma_range).max(0.15),
            survival_outside: 0.8,
            birth_suppress_radius: 0.8,
            birth_suppress_spread: 2.0,
            resolution_distance: 1.5,
            resolution_fade: 0.5,
            unresolved_share: 0.5,
            unresolved_noise_scale: 2.0,
            manoeuvre_probability: 0.05,
            manoeuvre_sigma: 5.0,
            detectability: None,
            confirm_existence: 0.99,
            confirm_detections: 0.0,
            confirm_evidence: 0.0,
            doubted_gate: 0.5,
            doubted_gate_existence: 0.5,
            min_visibility: 0.5,
            motion: MotionConfig::default(),
            filter: RunConfig {
                seed: 0,
                // People in view vanish only by leaving it (that is `survival_outside`): a mean
                // lifetime of 1,000 scans.
                survival: 0.999,
                filter: LmbConfig {
                    particles: 500,
                    ..LmbConfig::default()
                },
                transition: TransitionConfig::ConstantVelocity {
                    dims: 2,
                    // Walkers change velocity slowly.
                    sigma_accel: 0.3,
                },
                measurement: Some(MeasurementConfig::RangeBearing {
                    sigma_range: centre_sigma_range,
                    sigma_bearing: centre_sigma_bearing,
                    offset: mount,
                    convention: BearingConvention::FromXAxis,
                }),
                detection: Some(DetectionConfig::FieldOfView {
                    p_inside: 0.9,
                    p_outside: 0.0,
                    max_range,
                    half_angle,
                    offset: mount,
                }),
                clutter: Some(ClutterConfig {
                    rate: 1.0,
                    volume: 2.0 * half_angle * max_range,
                }),
                sensors: Vec::new(),
                fusion: None,
                birth: BirthConfig::Adaptive {
                    expected_births: 0.2,
                    max_existence: 0.2,
                    particles: 500,
                    position_std: 0.2,
                    velocity_std: 0.8,
                    turn_rate_std: 0.0,
                },
                association: AssociationMethod::default(),
            },
        }
    }
}

impl PeopleTrackerConfig {
    /// Sets the number of particles per track, for the filter's resampling and for new
    /// tracks (the birth model's draw).
    pub fn set_particles(&mut self, n: usize) {
        self.filter.filter.particles = n;
        if let BirthConfig::Adaptive { particles, .. } = &mut self.filter.birth {
            *particles = n;
        }
    }
}

/// Noise (σ_range m, σ_bearing rad) of a person's measured centre for a scanner whose beams
/// have noise `sigma_range`, `sigma_bearing`: the centre is the mean of the person's returns
/// (four or more on a person within 15 m of a 0.5° scanner), so its noise is about half a
/// beam's; at least 5 cm and 0.005 rad for the body's own shape (legs, clothes). In scenario
/// one (0.2 m, 2° beams) the measured spread of the centres is 0.10 m and 0.017 rad.
pub fn centre_noise(sigma_range: f64, sigma_bearing: f64) -> (f64, f64) {
    (sigma_range.max(0.05), sigma_bearing.max(0.005))
}

/// A track's position, its position predicted `dt` ahead, its existence and its position
/// spread σ.
pub(super) type TrackSummary = ([f64; 2], [f64; 2], f64, f64);

/// [`TrackSummary`] of a track of particles `p` (state `[x, vx, y, vy, ...]`).
pub(super) fn track_summary(p: &ParticleSet, existence: f64, dt: f64) -> TrackSummary {
    let w = p.weights();
    let mut mean = [0.0; 4];
    p.mean_into(&mut mean);
    let [x, vx, y, vy] = mean;
    let var: f64 = w
        .iter()
        .zip(p.component(0).iter().zip(p.component(2)))
        .map(|(w, (px, py))| w * ((px - x).powi(2) + (py - y).powi(2)))
        .sum();
    (
        [x, y],
        [x + vx * dt, y + vy * dt],
        existence,
        (0.5 * var).sqrt(),
    )
}

/// What the people models need of a step besides the scan: the tracks (`confirmed`, with
/// existence at least `min_existence`) births keep away from and p_D is lowered near, the
/// tracks with their spread, and which measurements may not start a track (evidence ≤ 0).
pub(super) fn people_data(
    confirmed: &[TrackSummary],
    min_existence: f64,
    evidence: Option<&[f64]>,
) -> StepData {
    let neighbours = confirmed
        .iter()
        .filter(|c| c.2 >= min_existence)
        .map(|&(_, next, _, _)| next)
        .collect();
    let people = confirmed
        .iter()
        .map(|&(position, _, existence, spread)| ConfirmedPerson {
            position,
            existence,
            spread,
        })
        .collect();
    let doubted = evidence.map_or_else(Vec::new, |e| e.iter().map(|&v| v <= 0.0).collect());
    StepData::new()
        .with(Neighbours(neighbours))
        .with(ConfirmedPeople(people))
        .with(Doubted(doubted))
}

/// The people's motion: the filter's transition, with manoeuvres when configured.
pub(super) fn people_motion(config: &PeopleTrackerConfig) -> Result<Box<dyn TransitionModel>> {
    if config.manoeuvre_probability == 0.0 {
        return config.filter.transition.model();
    }
    let TransitionConfig::ConstantVelocity { dims, sigma_accel } = config.filter.transition else {
        return Err(Error::invalid(
            "people tracker config field `manoeuvre_probability`",
            "manoeuvres need a constant-velocity `filter.transition`",
        ));
    };
    Ok(Box::new(ManoeuvringVelocity::new(
        ConstantVelocity::new(dims, sigma_accel)?,
        config.manoeuvre_probability,
        config.manoeuvre_sigma,
    )?))
}

/// What the people models are built from in a tracker's filter configuration: the field of
/// view, the adaptive birth and the range-bearing likelihood (an error naming the field when
/// one is of another kind).
pub(super) struct FilterParts {
    pub(super) p_inside: f64,
    pub(super) p_outside: f64,
    pub(super) max_range: f64,
    pub(super) half_angle: f64,
    pub(super) fov_offset: [f64; 2],
    expected_births: f64,
    max_existence: f64,
    particles: usize,
    position_std: f64,
    velocity_std: f64,
    sigma_range: f64,
    sigma_bearing: f64,
    pub(super) sensor_offset: [f64; 2],
    convention: BearingConvention,
}

impl FilterParts {
    pub(super) fn of(config: &PeopleTrackerConfig) -> Result<Self> {
        let Some(DetectionConfig::FieldOfView {
            p_inside,
            p_outside,
            max_range,
            half_angle,
            offset: fov_offset,
        }) = config.filter.detection
        else {
            return Err(Error::invalid(
                "people tracker config field `filter.detection`",
                "must be FieldOfView (occlusion is added on top)",
            ));
        };
        let BirthConfig::Adaptive {
            expected_births,
            max_existence,
            particles,
            position_std,
            velocity_std,
            ..
        } = config.filter.birth
        else {
            return Err(Error::invalid(
                "people tracker config field `filter.birth`",
                "must be Adaptive",
            ));
        };
        let Some(MeasurementConfig::RangeBearing {
            sigma_range,
            sigma_bearing,
            offset: sensor_offset,
            convention,
        }) = config.filter.measurement
        else {
            return Err(Error::invalid(
                "people tracker config field `filter.measurement`",
                "must be RangeBearing",
            ));
        };
        Ok(FilterParts {
            p_inside,
            p_outside,
            max_range,
            half_angle,
            fov_offset,
            expected_births,
            max_existence,
            particles,
            position_std,
            velocity_std,
            sigma_range,
            sigma_bearing,
            sensor_offset,
            convention,
        })
    }

    /// The range-bearing likelihood about the sensor (no offset).
    pub(super) fn range_bearing(&self) -> Result<RangeBearing> {
        Ok(RangeBearing::new(self.sigma_range, self.sigma_bearing)?
            .with_convention(self.convention))
    }

    /// The people birth drawing through `sensor`.
    pub(super) fn birth(
        &self,
        sensor: RangeBearing,
        config: &PeopleTrackerConfig,
    ) -> Result<PeopleBirth> {
        let mut birth = PeopleBirth::new(
            sensor,
            self.expected_births,
            self.max_existence,
            self.particles,
            self.position_std,
            self.velocity_std,
            config.birth_suppress_radius,
        )?;
        birth.with_detectability = config.detectability.is_some();
        birth.suppress_spread = config.birth_suppress_spread;
        Ok(birth)
    }
}

/// One person in one scan's output.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PersonEstimate {
    /// Track label (birth scan, index).
    pub label: Label,
    /// Existence probability.
    pub existence: f64,
    /// World position (m).
    pub position: [f64; 2],
    /// World velocity (m/s).
    pub velocity: [f64; 2],
    /// P(speed > v_min) from the particles.
    pub p_moving: f64,
    /// The static/dynamic class after hysteresis (true = dynamic).
    pub moving: bool,
    /// Expected share of the person's beams the scanner sees: Σ wᵢ p_D(xᵢ) / p_D,max (0 when
    /// outside the field of view or hidden behind nearer returns).
    pub visibility: f64,
    /// Scans since the track was born.
    pub age: u32,
}

/// Turns scans into labelled people estimates.
#[derive(Debug)]
pub struct PeopleTracker {
    config: PeopleTrackerConfig,
    filter: LmbFilter,
    rng: FilterRng,
    detection: OcclusionDetection,
    resolution: ResolutionDetection<OcclusionDetection>,
    detectability: Option<DetectabilityDetection<ResolutionDetection<OcclusionDetection>>>,
    birth: PeopleBirth,
    motion: MotionClassifier,
    confirmed: std::collections::BTreeSet<Label>,
    /// Evidence collected by each track (see [`PeopleTrackerConfig::confirm_evidence`]).
    evidence: std::collections::BTreeMap<Label, f64>,
    last_time: Option<f64>,
    /// The range-bearing model of the people's centres (births, innovations).
    sensor: RangeBearing,
    /// Innovations of the last step's reported people, when recorded.
    innovations: Option<Vec<Innovation>>,
    /// The last scan seen ([`PeopleTracker::observe`]), which each step hands the occlusion
    /// model.
    view: BeamView,
}

impl PeopleTracker {
    /// A tracker; the filter's random stream is seeded from `config.filter.seed`.
    pub fn new(config: PeopleTrackerConfig) -> Result<Self> {
        let parts = FilterParts::of(&config)?;
        let (fov_offset, sensor_offset) = (parts.fov_offset, parts.sensor_offset);
        let fov = FieldOfViewDetection::new(
            parts.p_inside,
            parts.p_outside,
            parts.max_range,
            parts.half_angle,
        )?
        .with_offset(fov_offset[0], fov_offset[1])?;
        let detection =
            OcclusionDetection::new(fov, config.body_radius.max(1e-3), config.occlusion_margin)?
                .with_min_returns(config.min_points as u32);
        let sensor = parts
            .range_bearing()?
            .with_offset(sensor_offset[0], sensor_offset[1])?;
        let birth = parts.birth(sensor, &config)?;
        let survival =
            FieldOfViewSurvival::new(fov, config.filter.survival, config.survival_outside)?;
        let resolution = ResolutionDetection::new(
            detection.clone(),
            config.resolution_distance,
            config.resolution_fade,
            config.unresolved_share,
            // two bodies of radius ρ cannot stand closer than 2ρ: nearer is the track itself
            1.5 * config.body_radius,
        )?;
        let mut builder = config.filter.builder()?;
        if config.unresolved_noise_scale != 1.0 {
            builder = builder.measurement(ResolutionLikelihood::new(
                sensor,
                config.unresolved_noise_scale,
                resolution.clone(),
            )?);
        }
        let motion = people_motion(&config)?;
        let detectability = match config.detectability {
            Some(chain) => {
                let transition = DetectabilityTransition::new(motion, chain)?;
                let mode = transition.mode_component();
                builder = builder.transition(transition);
                let d = DetectabilityDetection::new(resolution.clone(), chain, mode)?;
                builder = builder.detection(d.clone());
                Some(d)
            }
            None => {
                builder = builder.transition(motion).detection(resolution.clone());
                None
            }
        };
        let filter = builder.survival(survival).birth(birth.clone()).build()?;
        let rng = seeded(config.filter.seed);
        let motion = MotionClassifier::new(config.motion)?;
        Ok(PeopleTracker {
            config,
            filter,
            rng,
            detection,
            resolution,
            detectability,
            birth,
            motion,
            confirmed: Default::default(),
            evidence: Default::default(),
            last_time: None,
            sensor,
            innovations: None,
            view: BeamView::EMPTY,
        })
    }

    /// Records (or stops recording) the innovation of every reported person's most probable
    /// measurement in each step, against the predicted particle cloud
    /// ([`super::innovation`]), for the RMS prediction error and NIS checks. Off by default:
    /// it copies the predicted particles of every track once per step.
    pub fn record_innovations(&mut self, on: bool) {
        self.filter.keep_predicted(on);
        self.innovations = on.then(Vec::new);
    }

    /// The innovations of the last step (empty unless recorded).
    pub fn innovations(&self) -> &[Innovation] {
        self.innovations.as_deref().unwrap_or(&[])
    }

    /// The configuration.
    pub fn config(&self) -> &PeopleTrackerConfig {
        &self.config
    }

    /// The grouping parameters this tracker uses.
    pub fn grouping(&self) -> PersonGrouping {
        person_grouping(&self.config)
    }

    /// The point groups of `scan` that look like people (see [`person_segments`]).
    pub fn person_segments(&self, scan: &Scan) -> Result<Vec<Vec<[f64; 2]>>> {
        person_segments(&self.config, scan)
    }

    /// Range-bearing measurements of the people's centres (see [`person_measurements`]).
    pub fn measurements(&self, scan: &Scan) -> Result<Measurements> {
        person_measurements(&self.config, scan)
    }

    /// One scan: segment, measure, filter. Returns the people the scanner should see now
    /// (visibility at least `min_visibility`); occluded people and those who left the field
    /// of view stay in the filter, keep their labels, and come back in the output when they
    /// reappear. The robot pose is the scan's odometry (the world origin when the scan has
    /// none).
    pub fn step(&mut self, scan: &Scan) -> Result<Vec<Estimate>> {
        let people = self.step_people(scan)?;
        Ok(self.visible(people))
    }

    /// The people whose visibility reaches `min_visibility`, as filter estimates.
    fn visible(&self, people: Vec<PersonEstimate>) -> Vec<Estimate> {
        let min = self.config.min_visibility;
        people
            .into_iter()
            .filter(|p| p.visibility >= min)
            .map(|p| Estimate {
                label: p.label,
                existence: p.existence,
                state: vec![p.position[0], p.velocity[0], p.position[1], p.velocity[1]],
                age: p.age,
            })
            .collect()
    }

    /// One scan, with every person of the filter's MAP estimate (visible or not), their
    /// static/dynamic class and visibility.
    pub fn step_people(&mut self, scan: &Scan) -> Result<Vec<PersonEstimate>> {
        let measurements = self.measurements(scan)?;
        let platform = scan
            .odometry
            .map(|p| Isometry3::new(Vector3::new(p.x, p.y, 0.0), Vector3::new(0.0, 0.0, p.theta)));
        self.observe(scan);
        self.step_measured(measurements, scan.time, platform)
    }

    /// Keeps the scan's ranges, which the next steps hand the occlusion-aware detection
    /// model.
    pub fn observe(&mut self, scan: &Scan) {
        self.view
            .reset(scan.angle_min, scan.angle_increment, scan.beam_ranges());
    }

    /// One step on measurements made elsewhere (range-bearing rows of the people's centres),
    /// after [`PeopleTracker::observe`] has seen the scan they come from.
    pub fn step_measured(
        &mut self,
        measurements: Measurements,
        time: f64,
        platform: Option<Isometry3<f64>>,
    ) -> Result<Vec<PersonEstimate>> {
        self.step_measured_with_evidence(measurements, None, time, platform)
    }

    /// [`PeopleTracker::step_measured`] with each measurement's evidence that it is a person
    /// (e.g. a classifier's score; `None` counts 1 for each), which the tracks collect
    /// towards [`PeopleTrackerConfig::confirm_evidence`].
    pub fn step_measured_with_evidence(
        &mut self,
        measurements: Measurements,
        evidence: Option<&[f64]>,
        time: f64,
        platform: Option<Isometry3<f64>>,
    ) -> Result<Vec<PersonEstimate>> {
        if let Some(e) = evidence {
            if e.len() != measurements.len() || e.iter().any(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    "measurement evidence",
                    format!(
                        "{} finite values needed, one per measurement (got {})",
                        measurements.len(),
                        e.len()
                    ),
                ));
            }
        }
        let dt = self.last_time.map_or(0.0, |t0| (time - t0).max(0.0));
        self.last_time = Some(time);
        let confirmed: Vec<_> = self
            .filter
            .tracks()
            .iter()
            .map(|t| track_summary(&t.particles, t.existence, dt))
            .collect();
        // Doubted measurements (evidence ≤ 0) only near a likely track.
        let mut kept_evidence = Vec::new();
        let (measurements, evidence) = match evidence {
            Some(e) if e.iter().any(|&v| v <= 0.0) => {
                let mut gctx = StepContext::new(self.filter.steps(), time, 0.0);
                gctx.platform = platform;
                let (gate, min_r) = (self.config.doubted_gate, self.config.doubted_gate_existence);
                let mut rows = Vec::with_capacity(e.len());
                for (j, &ej) in e.iter().enumerate() {
                    let z = measurements.get(j);
                    let keep = ej > 0.0 || {
                        let p = self.sensor.to_cartesian([z[0], z[1]], &gctx);
                        confirmed.iter().any(|&(_, next, r, _)| {
                            r >= min_r && (next[0] - p[0]).hypot(next[1] - p[1]) < gate
                        })
                    };
                    if keep {
                        rows.push([z[0], z[1]]);
                        kept_evidence.push(ej);
                    }
                }
                (Measurements::from_rows(2, &rows)?, Some(&kept_evidence[..]))
            }
            other => (measurements, other),
        };
        // What the models need of this step: the scan, the tracks births keep away from and
        // p_D is lowered near, and which of these measurements may not start a track (the
        // next step's births come from them).
        let data = people_data(&confirmed, self.birth.suppress_existence, evidence)
            .with(self.view.clone());
        let recorded = self.innovations.is_some().then(|| measurements.clone());
        let mut frame = Frame::new(time, measurements).with_data(data.clone());
        frame.platform = platform;
        let estimates = self.filter.step(&frame, &mut self.rng)?;
        let mut ctx = StepContext::new(self.filter.steps(), time, 0.0).with_data(data);
        ctx.platform = platform;
        let p_max = self.detection.field_of_view().p_inside();
        let tracks = self.filter.tracks();
        let (confirm, detections, needed) = (
            self.config.confirm_existence,
            self.config.confirm_detections,
            self.config.confirm_evidence,
        );
        for m in self.filter.most_probable_measurements() {
            let e = evidence.map_or(1.0, |e| e[m.measurement]);
            *self.evidence.entry(m.label).or_insert(0.0) += m.probability * e;
        }
        self.evidence
            .retain(|l, _| tracks.iter().any(|t| t.label == *l));
        self.confirmed
            .retain(|l| tracks.iter().any(|t| t.label == *l));
        let collected = |l: &Label| self.evidence.get(l).copied().unwrap_or(0.0);
        self.confirmed.extend(
            tracks
                .iter()
                .filter(|t| {
                    t.existence >= confirm
                        && t.expected_detections >= detections
                        && (needed <= 0.0 || collected(&t.label) >= needed)
                })
                .map(|t| t.label),
        );
        let mut out = Vec::with_capacity(estimates.len());
        let mut pd_buffer = Vec::new();
        for e in estimates {
            if !self.confirmed.contains(&e.label) {
                continue;
            }
            let Some(t) = tracks.iter().find(|t| t.label == e.label) else {
                continue;
            };
            let p = &t.particles;
            // Visibility is geometric (field of view, occlusion): the filter's own p_D when the
            // particles have not moved since it computed them, with the neighbours' lowering
            // and the detectability mode divided out again.
            let pd = match self.filter.detection_probabilities(e.label) {
                Some(known) if known.len() == p.len() => {
                    pd_buffer.clear();
                    pd_buffer.extend_from_slice(known);
                    self.resolution
                        .apply_factors(p, &ctx, &mut pd_buffer, |o, f| *o /= f);
                    if let Some(d) = &self.detectability {
                        d.remove_mode(p, &mut pd_buffer);
                    }
                    &pd_buffer[..]
                }
                _ => {
                    pd_buffer.resize(p.len(), 0.0);
                    self.detection
                        .detection_probability(p, &ctx, &mut pd_buffer);
                    &pd_buffer[..]
                }
            };
            let seen: f64 = p.weights().iter().zip(pd).map(|(w, d)| w * d).sum();
            let p_moving = probability_moving(p, self.config.motion.v_min);
            out.push(PersonEstimate {
                label: e.label,
                existence: e.existence,
                position: [e.state[0], e.state[2]],
                velocity: [e.state[1], e.state[3]],
                p_moving,
                moving: self.motion.update(e.label, p_moving, e.age),
                visibility: if p_max > 0.0 {
                    (seen / p_max).clamp(0.0, 1.0)
                } else {
                    0.0
                },
                age: e.age,
            });
        }
        self.motion.retain(|l| tracks.iter().any(|t| t.label == l));
        if let (Some(z), Some(innovations)) = (recorded, self.innovations.as_mut()) {
            innovations.clear();
            // The people reported now, by the measurement they most probably made (not
            // people born in this step, whose cloud was drawn from their measurement).
            let born_now = self.filter.steps() - 1;
            for m in self.filter.most_probable_measurements() {
                if m.probability <= 0.5
                    || m.label.birth_step == born_now
                    || !out.iter().any(|p| p.label == m.label)
                {
                    continue;
                }
                let Some(predicted) = self.filter.predicted(m.label) else {
                    continue;
                };
                let row = z.get(m.measurement);
                innovations.extend(particle_innovation(
                    m.label,
                    predicted,
                    [row[0], row[1]],
                    &self.sensor,
                    &ctx,
                ));
            }
        }
        Ok(out)
    }

    /// The underlying filter.
    pub fn filter(&self) -> &LmbFilter {
        &self.filter
    }
}

/// The people tracker behind the common tracker interface, so that it runs on exactly the
/// measurements the baselines get ([`super::evaluate`]).
impl PointTracker for PeopleTracker {
    fn name(&self) -> &str {
        "lmb"
    }

    fn observe_beams(&mut self, beams: BeamRanges<'_>) {
        self.view.reset(
            beams.angle_min,
            beams.angle_increment,
            beams.ranges.iter().copied(),
        );
    }

    fn step(&mut self, z: &Measurements, ctx: &StepContext) -> Result<Vec<Estimate>> {
        let people = self.step_measured(z.clone(), ctx.time, ctx.platform)?;
        Ok(self.visible(people))
    }

    fn innovations(&self) -> &[Innovation] {
        PeopleTracker::innovations(self)
    }
}

// Scan → measurements, shared by the filter above and by the baseline trackers
// (`crate::trackers`), which must see exactly the same measurements.

/// The grouping parameters of `config`.
pub fn person_grouping(config: &PeopleTrackerConfig) -> PersonGrouping {
    PersonGrouping {
        breakpoint: config.breakpoint,
        body_radius: config.body_radius,
        max_width: config.max_width,
        min_points: config.min_points,
        merge_gap: config.merge_gap,
        sigma_range: config.beam_sigma_range,
        sigma_bearing: config.beam_sigma_bearing,
    }
}

/// The point groups of `scan` that look like people (see [`crate::laser2d::person_groups()`]), each as
/// its points in the sensor frame.
pub fn person_segments(config: &PeopleTrackerConfig, scan: &Scan) -> Result<Vec<Vec<[f64; 2]>>> {
    Ok(person_groups(scan, &person_grouping(config))?
        .into_iter()
        .map(|g| g.points)
        .collect())
}

/// Range-bearing measurements (sensor frame, bearing from the sensor's x axis) of the
/// people's centres: one per person group, its mean range pushed `body_radius` farther and
/// its mean bearing.
pub fn person_measurements(config: &PeopleTrackerConfig, scan: &Scan) -> Result<Measurements> {
    let rows: Vec<[f64; 2]> = person_groups(scan, &person_grouping(config))?
        .into_iter()
        .map(|g| [g.range, g.bearing])
        .collect();
    Measurements::from_rows(2, &rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Pose2;

    /// A person (disc of radius 0.2 m) walking across in front of a static scanner, rendered
    /// exactly into 361 beams over 180°.
    fn scan_with_person(t: f64, px: f64, py: f64) -> Scan {
        let n = 361;
        let inc = std::f64::consts::PI / (n - 1) as f64;
        let ranges: Vec<f32> = (0..n)
            .map(|i| {
                let a = -std::f64::consts::FRAC_PI_2 + i as f64 * inc;
                let (dx, dy) = (a.cos(), a.sin());
                // ray–circle: |s·d − p|² = r²
                let b = dx * px + dy * py;
                let c = px * px + py * py - 0.04;
                let disc = b * b - c;
                if disc >= 0.0 && b - disc.sqrt() > 0.0 {
                    (b - disc.sqrt()) as f32
                } else {
                    30.0
                }
            })
            .collect();
        let mut s = Scan::new(t, -std::f64::consts::FRAC_PI_2, inc, ranges, 0.05, 30.0).unwrap();
        s.odometry = Some(Pose2 {
            x: 0.0,
            y: 0.0,
            theta: 0.0,
        });
        s
    }

    /// A 180° scanner of 2 cm / 0.005 rad beams, range 30 m, mounted at the robot's origin.
    fn static_scanner_config() -> PeopleTrackerConfig {
        PeopleTrackerConfig::for_scanner(0.02, 0.005, 30.0, std::f64::consts::FRAC_PI_2, [0.0, 0.0])
    }

    #[test]
    fn a_walking_person_gets_one_label_and_the_right_velocity() {
        let cfg = static_scanner_config();
        let mut tracker = PeopleTracker::new(cfg).unwrap();
        let mut last = Vec::new();
        let mut labels = std::collections::BTreeSet::new();
        for k in 0..40 {
            let t = k as f64 * 0.125;
            let est = tracker
                .step(&scan_with_person(t, 5.0, -2.0 + 0.8 * t))
                .unwrap();
            if k >= 5 {
                assert_eq!(est.len(), 1, "step {k}: {est:?}");
                labels.insert(est[0].label);
            }
            last = est;
        }
        assert_eq!(labels.len(), 1);
        let e = &last[0];
        let t = 39.0 * 0.125;
        assert!(
            (e.state[0] - 5.0).abs() < 0.1 && (e.state[2] - (-2.0 + 0.8 * t)).abs() < 0.15,
            "{e:?}"
        );
        assert!(
            (e.state[3] - 0.8).abs() < 0.25 && e.state[1].abs() < 0.25,
            "velocity {e:?}"
        );
    }

    #[test]
    fn set_particles_sizes_new_and_resampled_tracks() {
        let mut cfg = static_scanner_config();
        cfg.set_particles(64);
        let mut tracker = PeopleTracker::new(cfg).unwrap();
        for k in 0..6 {
            let t = k as f64 * 0.125;
            tracker
                .step(&scan_with_person(t, 5.0, -2.0 + 0.8 * t))
                .unwrap();
            // Births come from the previous scan's measurements.
            let tracks = tracker.filter().tracks();
            assert_eq!(tracks.is_empty(), k == 0, "step {k}");
            assert!(tracks.iter().all(|t| t.particles.len() == 64), "step {k}");
        }
        let mut none = static_scanner_config();
        none.set_particles(0);
        assert!(PeopleTracker::new(none).is_err());
    }

    /// Walks a person at (5, y(t)) past a static scanner for `scans` scans; the front end
    /// misses them in the scans of `missed`. Returns every scan's reported labels and the last
    /// scan's estimates.
    fn walk(
        cfg: PeopleTrackerConfig,
        scans: usize,
        y: impl Fn(f64) -> f64,
        missed: std::ops::Range<usize>,
    ) -> (Vec<Vec<Label>>, Vec<Estimate>) {
        let mut tracker = PeopleTracker::new(cfg).unwrap();
        let mut labels = Vec::new();
        let mut last = Vec::new();
        for k in 0..scans {
            let t = k as f64 * 0.125;
            let scan = scan_with_person(t, 5.0, y(t));
            let z = if missed.contains(&k) {
                Measurements::empty(2)
            } else {
                tracker.measurements(&scan).unwrap()
            };
            tracker.observe(&scan);
            let people = tracker.step_measured(z, t, None).unwrap();
            last = tracker.visible(people);
            labels.push(last.iter().map(|e| e.label).collect());
        }
        (labels, last)
    }

    fn moving_front_end_config() -> PeopleTrackerConfig {
        let mut cfg = static_scanner_config();
        crate::pipeline::people_tracking::front_end::adapt_tracker_config(
            &mut cfg,
            crate::pipeline::people_tracking::front_end::FrontEnd::Moving,
        );
        cfg
    }

    fn labels_of(labels: &[Vec<Label>]) -> std::collections::BTreeSet<Label> {
        labels.iter().flatten().copied().collect()
    }

    /// One label over the whole walk, and the person reported in every scan from the 12th.
    fn assert_one_label(labels: &[Vec<Label>]) {
        let births: Vec<Vec<u32>> = labels
            .iter()
            .map(|l| l.iter().map(|x| x.birth_step).collect())
            .collect();
        assert_eq!(
            labels_of(labels).len(),
            1,
            "birth steps per scan {births:?}"
        );
        assert!(
            labels[12..].iter().all(|l| l.len() == 1),
            "birth steps per scan {births:?}"
        );
    }

    /// A person walks at 1 m/s and turns round between 3 s and 4 s (decelerating at 2 m/s²,
    /// 6.7 σ of the calm model, and walking back). With manoeuvres the track follows them back
    /// under the same label; with plain constant velocity (σ 0.3 m/s²) it overshoots and the
    /// person returns under a new label.
    #[test]
    fn a_person_who_turns_round_keeps_one_label() {
        let y = |t: f64| {
            if t < 3.0 {
                -3.0 + t
            } else if t < 4.0 {
                (t - 3.0) - (t - 3.0).powi(2)
            } else {
                4.0 - t
            }
        };
        let (labels, last) = walk(moving_front_end_config(), 64, y, 0..0);
        assert_one_label(&labels);
        let e = &last[0];
        let t = 63.0 * 0.125;
        assert!((e.state[2] - y(t)).abs() < 0.2, "{e:?}");
        assert!((e.state[3] + 1.0).abs() < 0.3, "velocity {e:?}");

        let mut plain = moving_front_end_config();
        plain.manoeuvre_probability = 0.0;
        let (labels, _) = walk(plain, 64, y, 0..0);
        assert!(labels_of(&labels).len() >= 2, "{labels:?}");
    }

    /// The front end misses a walking person for two seconds (16 scans in a row). With runs
    /// of misses modelled the track survives the gap under its label; with misses taken as
    /// independent (p_D 0.7, the front end's average) its existence collapses and the person
    /// comes back under a new label.
    #[test]
    fn a_run_of_misses_does_not_end_the_track() {
        let y = |t: f64| -3.0 + 0.8 * t;
        let (labels, _) = walk(moving_front_end_config(), 64, y, 24..40);
        assert_one_label(&labels);

        let mut independent = moving_front_end_config();
        independent.detectability = None;
        if let Some(DetectionConfig::FieldOfView { p_inside, .. }) =
            &mut independent.filter.detection
        {
            *p_inside = crate::pipeline::people_tracking::front_end::MOVING_DETECTION_PROBABILITY;
        }
        let (labels, _) = walk(independent, 64, y, 24..40);
        assert!(labels_of(&labels).len() >= 2, "{labels:?}");
    }

    /// A person the front end reports in three scans and then never again is not reported
    /// when confirmation asks for five detections, and is with no such requirement.
    #[test]
    fn a_short_flicker_is_not_confirmed() {
        let y = |t: f64| -2.0 + 0.8 * t;
        let mut cfg = moving_front_end_config();
        assert!(cfg.confirm_detections >= 5.0);
        let (labels, _) = walk(cfg.clone(), 16, y, 3..16);
        assert!(labels.iter().all(Vec::is_empty), "{labels:?}");
        cfg.confirm_detections = 0.0;
        cfg.confirm_existence = 0.5;
        let (labels, _) = walk(cfg, 16, y, 3..16);
        assert!(labels.iter().any(|l| !l.is_empty()), "{labels:?}");
    }

    /// The first scan in which the walking person of [`walk`] is reported when each of the
    /// front end's measurements brings `evidence` (None if never within `scans`).
    fn first_report_with_evidence(
        cfg: &PeopleTrackerConfig,
        scans: usize,
        evidence: f64,
    ) -> Option<usize> {
        let mut tracker = PeopleTracker::new(cfg.clone()).unwrap();
        for k in 0..scans {
            let t = k as f64 * 0.125;
            let scan = scan_with_person(t, 5.0, -2.0 + 0.8 * t);
            let z = tracker.measurements(&scan).unwrap();
            let e = vec![evidence; z.len()];
            tracker.observe(&scan);
            let people = tracker
                .step_measured_with_evidence(z, Some(&e), t, None)
                .unwrap();
            if !tracker.visible(people).is_empty() {
                return Some(k);
            }
        }
        None
    }

    /// With `confirm_evidence` a track is reported once its measurements have brought that
    /// much evidence: sooner when each brings more, not within 24 scans when each brings
    /// little. Without the requirement the evidence changes nothing. Evidence that does not match the
    /// measurements is an error.
    #[test]
    fn confirmation_waits_for_the_measurements_evidence() {
        let mut cfg = static_scanner_config();
        cfg.confirm_evidence = 1.2;
        let strong = first_report_with_evidence(&cfg, 24, 0.5).expect("strong evidence confirms");
        let weak = first_report_with_evidence(&cfg, 24, 0.15).expect("weak evidence confirms");
        assert!(strong + 4 <= weak, "strong {strong}, weak {weak}");
        assert_eq!(first_report_with_evidence(&cfg, 24, 0.02), None);
        cfg.confirm_evidence = 0.0;
        let off = first_report_with_evidence(&cfg, 24, 0.02);
        assert!(off.is_some_and(|k| k <= strong), "{off:?} vs {strong}");

        let mut tracker = PeopleTracker::new(static_scanner_config()).unwrap();
        let scan = scan_with_person(0.0, 5.0, 0.0);
        let z = tracker.measurements(&scan).unwrap();
        assert_eq!(z.len(), 1);
        tracker.observe(&scan);
        for bad in [vec![], vec![0.5, 0.5], vec![f64::NAN]] {
            let e = tracker
                .step_measured_with_evidence(z.clone(), Some(&bad), 0.0, None)
                .unwrap_err()
                .to_string();
            assert!(e.contains("evidence"), "{e}");
        }
    }

    /// Walks the person of [`first_report_with_evidence`] for `scans` scans with the evidence
    /// `evidence(k)` in scan k; returns the tracker and the reported people of every scan.
    fn walk_with_evidence(
        cfg: &PeopleTrackerConfig,
        scans: usize,
        evidence: impl Fn(usize) -> f64,
    ) -> (PeopleTracker, Vec<Vec<Estimate>>) {
        let mut tracker = PeopleTracker::new(cfg.clone()).unwrap();
        let mut reported = Vec::new();
        for k in 0..scans {
            let t = k as f64 * 0.125;
            let scan = scan_with_person(t, 5.0, -2.0 + 0.8 * t);
            let z = tracker.measurements(&scan).unwrap();
            let e = vec![evidence(k); z.len()];
            tracker.observe(&scan);
            let people = tracker
                .step_measured_with_evidence(z, Some(&e), t, None)
                .unwrap();
            reported.push(tracker.visible(people));
        }
        (tracker, reported)
    }

    /// Measurements the classifier doubts (evidence ≤ 0) start no track, and are dropped
    /// away from tracks; near a person's track they keep it updated.
    #[test]
    fn doubted_measurements_only_feed_tracks_there_are() {
        let mut cfg = static_scanner_config();
        cfg.confirm_evidence = 1.0;
        let (tracker, reported) = walk_with_evidence(&cfg, 16, |_| -0.1);
        assert!(tracker.filter().tracks().is_empty());
        assert!(reported.iter().all(Vec::is_empty));

        // Believed for 12 scans, then doubted for 12: still reported, and followed.
        let (_, reported) = walk_with_evidence(&cfg, 24, |k| if k < 12 { 0.5 } else { -0.05 });
        assert!(reported[11].len() == 1, "{:?}", reported[11]);
        for (k, people) in reported.iter().enumerate().skip(12) {
            assert_eq!(people.len(), 1, "scan {k}: {people:?}");
            let y = -2.0 + 0.8 * k as f64 * 0.125;
            assert!((people[0].state[2] - y).abs() < 0.3, "scan {k}: {people:?}");
        }
        // Without the gate's room they are dropped and the track coasts off them.
        cfg.doubted_gate = 0.0;
        let (_, coasting) = walk_with_evidence(&cfg, 24, |k| if k < 12 { 0.5 } else { -0.05 });
        let last = |r: &[Vec<Estimate>]| r[23].first().map(|e| e.existence);
        assert!(
            last(&coasting).unwrap_or(0.0) < last(&reported).unwrap(),
            "{coasting:?}"
        );
    }
}
