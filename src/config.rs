//! A whole filter described as data: which built-in models, with which parameters, and the
//! filter's tuning — what a user writes in a TOML or JSON file to run the filter on their own
//! detections. [`RunConfig::build`] checks every value and builds the [`LmbFilter`].
//!
//! ```toml
//! seed = 7
//! survival = 0.99
//! [filter]                 # LmbConfig; every field optional
//! particles = 500
//! [transition]
//! model = "constant_velocity"   # or "coordinated_turn" (sigma_vel, sigma_turn)
//! dims = 2
//! sigma_accel = 1.0
//! [measurement]
//! model = "position"            # or "range_bearing" (sigma_range, sigma_bearing, offset, convention)
//! sigma = 0.5
//! [detection]
//! model = "constant"            # or "gaussian_range" (peak, scale, center)
//! probability = 0.9
//! [clutter]
//! rate = 5.0                    # expected false measurements per frame
//! volume = 40000.0              # of the measurement space (m², or rad·m for range-bearing)
//! [birth]
//! model = "adaptive"            # or "static" with terms = [{ existence, mean, std }] and particles
//! expected_births = 0.1
//! max_existence = 0.05
//! particles = 500
//! position_std = 1.0
//! velocity_std = 2.0
//! [association]
//! method = "lbp"                # or "murty" (k, min_weight), "gibbs" (samples)
//! ```
//!
//! Several sensors: one `[[sensors]]` table per sensor, each with a `name` and its own
//! `measurement`, `detection` and `clutter` tables (the keys above, with the same meaning), an
//! optional `mounting = [x, y, heading]` on the platform (position measurements only; see
//! [`crate::filter::Mounting`]), and a `[fusion]` table saying how their updates combine
//! ([`crate::filter::Fusion`]); the top-level `measurement`, `detection` and `clutter`
//! tables are then left out. The birth model's measurement-guided sampling follows the first
//! sensor's measurement model.
//!
//! ```toml
//! [[sensors]]
//! name = "front"
//! measurement = { model = "position", sigma = 0.3 }
//! detection = { model = "constant", probability = 0.8 }
//! clutter = { rate = 2.0, volume = 400.0 }
//! mounting = [0.3, 0.0, 0.0]
//! [[sensors]]
//! name = "rear"
//! measurement = { model = "position", sigma = 0.3 }
//! detection = { model = "constant", probability = 0.8 }
//! clutter = { rate = 2.0, volume = 400.0 }
//! mounting = [-0.3, 0.0, 3.14159]
//! [fusion]
//! method = "pu"                 # "ic" (default), "pu", "ga" or "aa"
//! weights = [0.5, 0.5]          # GA and AA; default uniform
//! order = ["rear", "front"]     # IC's update order; default the tables' order
//! ```
//!
//! Static birth terms (`model = "static"`) are sampled near the step's measurements that no
//! existing track explains and importance-weighted, which leaves the birth density as written
//! but puts its particles where a new object is seen ([`crate::filter::BirthProposal`]). This
//! works with position measurements and, converted to world points with the frame's sensor
//! pose, range-bearing ones. To sample every term from its own Gaussian instead, set
//! `measurement_proposal = false`:
//!
//! ```toml
//! [birth]
//! model = "static"
//! particles = 1000
//! measurement_proposal = false  # default true
//! terms = [{ existence = 0.01, mean = [0.0, 0.0, 0.0, 0.0], std = [50.0, 10.0, 50.0, 10.0] }]
//! ```
//!
//! Not for: parsing the file text (the command-line tool does that with `toml`/`serde_json`).

mod birth;

use crate::error::{ensure_finite, Error, Result};
use crate::filter::{
    AdaptiveBirth, AssociationMethod, BirthProposal, BirthTerm, ConstantSurvival, DetectionModel,
    Fusion, FusionMethod, LmbConfig, LmbFilter, MeasurementModel, Mounting, Sensor, StaticBirth,
};
use crate::models::{
    BearingConvention, ConstantDetection, ConstantVelocity, CoordinatedTurn, FieldOfViewDetection,
    GaussianRangeDetection, PositionMeasurement, RangeBearing, UniformClutter,
};
use birth::{MeasurementBirth, RangeBearingGuidedBirth};
use serde::{Deserialize, Serialize};

/// A complete, serialisable filter description.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
    /// Seed of the filter's random stream. Default 0.
    #[serde(default)]
    pub seed: u64,
    /// Constant survival probability p_S. Default 0.99.
    #[serde(default = "default_survival")]
    pub survival: f64,
    /// Filter tuning.
    #[serde(default)]
    pub filter: LmbConfig,
    /// Motion model.
    pub transition: TransitionConfig,
    /// Measurement model of a filter with one sensor (left out with `sensors`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measurement: Option<MeasurementConfig>,
    /// Detection probability of a filter with one sensor (left out with `sensors`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub detection: Option<DetectionConfig>,
    /// Uniform clutter of a filter with one sensor (left out with `sensors`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clutter: Option<ClutterConfig>,
    /// Several sensors, each with its own models. Default none: one sensor, described by
    /// `measurement`, `detection` and `clutter`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sensors: Vec<SensorConfig>,
    /// How several sensors' updates combine. Default: the iterated corrector, sensors in
    /// table order, uniform weights.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fusion: Option<FusionConfig>,
    /// Birth model.
    pub birth: BirthConfig,
    /// Association method. Default: loopy belief propagation.
    #[serde(default)]
    pub association: AssociationMethod,
}

fn default_survival() -> f64 {
    0.99
}

/// One sensor of a filter with several.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorConfig {
    /// The name detections files use for it (their `sensor` column or key).
    pub name: String,
    /// Its measurement model.
    pub measurement: MeasurementConfig,
    /// Its detection probability.
    pub detection: DetectionConfig,
    /// Its clutter.
    pub clutter: ClutterConfig,
    /// Where it sits on the platform, `[x, y, heading]` (m, m, rad). Default: at the origin,
    /// measurements taken as given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mounting: Option<[f64; 3]>,
}

/// The `[fusion]` table: [`Fusion`] with sensors named.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FusionConfig {
    /// `"ic"`, `"pu"`, `"ga"` or `"aa"`. Default `"ic"`.
    pub method: FusionMethod,
    /// One weight per sensor, in table order, ≥ 0 and summing to one. Default uniform.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub weights: Option<Vec<f64>>,
    /// IC's update order by sensor name. Default the tables' order.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub order: Option<Vec<String>>,
}

impl FusionConfig {
    /// The fusion for sensors named `names` (in table order); an unknown name is an error.
    pub fn fusion(&self, names: &[&str]) -> Result<Fusion> {
        let order = match &self.order {
            None => None,
            Some(o) => Some(
                o.iter()
                    .map(|n| {
                        names.iter().position(|m| m == n).ok_or_else(|| {
                            Error::invalid(
                                "config field `fusion.order`",
                                format!("names sensor {n:?}, which no [[sensors]] table defines"),
                            )
                        })
                    })
                    .collect::<Result<Vec<usize>>>()?,
            ),
        };
        let f = Fusion {
            method: self.method,
            weights: self.weights.clone(),
            order,
        };
        f.validate(names.len())
            .map_err(|e| Error::invalid("config field `fusion`", e.to_string()))?;
        Ok(f)
    }
}

/// Built-in motion models.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum TransitionConfig {
    /// [`ConstantVelocity`]: state `[x, ẋ, y, ẏ(, z, ż)]`.
    ConstantVelocity {
        /// 2 or 3 axes.
        dims: usize,
        /// Acceleration noise standard deviation (m/s²).
        sigma_accel: f64,
    },
    /// [`CoordinatedTurn`]: state `[x, ẋ, y, ẏ, ω]`.
    CoordinatedTurn {
        /// Acceleration noise standard deviation (m/s²).
        sigma_vel: f64,
        /// Turn-rate noise standard deviation (rad/s).
        sigma_turn: f64,
    },
}

impl TransitionConfig {
    /// Checks the values and builds the model.
    pub fn model(&self) -> Result<Box<dyn crate::filter::TransitionModel>> {
        Ok(match *self {
            TransitionConfig::ConstantVelocity { dims, sigma_accel } => {
                Box::new(ConstantVelocity::new(dims, sigma_accel)?)
            }
            TransitionConfig::CoordinatedTurn {
                sigma_vel,
                sigma_turn,
            } => Box::new(CoordinatedTurn::new(sigma_vel, sigma_turn)?),
        })
    }
}

/// Built-in measurement models.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum MeasurementConfig {
    /// [`PositionMeasurement`]: z = position + noise; as many axes as the transition has.
    Position {
        /// Noise standard deviation per axis (m).
        sigma: f64,
    },
    /// [`RangeBearing`]: z = [range, bearing] from the sensor pose given per frame.
    RangeBearing {
        /// Range noise standard deviation (m).
        sigma_range: f64,
        /// Bearing noise standard deviation (rad).
        sigma_bearing: f64,
        /// Sensor mounting offset (a, b) on the platform (m). Default (0, 0).
        #[serde(default)]
        offset: [f64; 2],
        /// Bearing convention. Default `from_x_axis`.
        #[serde(default)]
        convention: BearingConvention,
    },
}

/// Built-in detection models.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum DetectionConfig {
    /// The same p_D everywhere.
    Constant {
        /// p_D.
        probability: f64,
    },
    /// p_D = peak·exp(−‖p − center‖² / (2 scale²)).
    GaussianRange {
        /// Peak probability.
        peak: f64,
        /// Length scale (m).
        scale: f64,
        /// Centre (m). Default the origin.
        #[serde(default)]
        center: [f64; 2],
    },
    /// p_D inside a range/bearing sector around the sensor (platform pose + mounting offset),
    /// another value outside it.
    FieldOfView {
        /// p_D inside the sector.
        p_inside: f64,
        /// p_D outside it.
        #[serde(default)]
        p_outside: f64,
        /// Sector radius (m).
        max_range: f64,
        /// Half the opening angle around the sensor's x axis (rad).
        half_angle: f64,
        /// Sensor mounting offset (a, b) on the platform (m). Default (0, 0).
        #[serde(default)]
        offset: [f64; 2],
    },
}

/// Uniform clutter: `rate` false measurements per frame spread over `volume`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClutterConfig {
    /// Expected number of clutter measurements per frame.
    pub rate: f64,
    /// Volume of the measurement space they fall in.
    pub volume: f64,
}

/// Built-in birth models.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum BirthConfig {
    /// [`StaticBirth`]: Gaussian terms proposed at every step.
    Static {
        /// The terms (existence, mean, std in the state layout of the transition).
        terms: Vec<BirthTerm>,
        /// Particles per birth track, 1 to [`crate::filter::MAX_PARTICLES`].
        particles: usize,
        /// Sample the terms near the step's unexplained measurements, importance-weighted
        /// ([`BirthProposal`]; range-bearing measurements converted to world points). Default
        /// true.
        #[serde(default = "default_measurement_proposal")]
        measurement_proposal: bool,
    },
    /// [`AdaptiveBirth`] from unexplained measurements.
    Adaptive {
        /// Expected births per step λ_B.
        expected_births: f64,
        /// Cap r_B,max on a birth's existence.
        max_existence: f64,
        /// Particles per birth track, 1 to [`crate::filter::MAX_PARTICLES`].
        particles: usize,
        /// Position spread around the measured point (m).
        position_std: f64,
        /// Velocity spread around zero (m/s).
        velocity_std: f64,
        /// Turn-rate spread around zero (rad/s), for the coordinated-turn state. Default 0.1.
        #[serde(default = "default_turn_std")]
        turn_rate_std: f64,
    },
}

fn default_turn_std() -> f64 {
    0.1
}

fn default_measurement_proposal() -> bool {
    true
}

impl RunConfig {
    /// Checks every value and builds the filter. Errors name the offending field.
    pub fn build(&self) -> Result<LmbFilter> {
        self.builder()?.build()
    }

    /// Checks every value and returns the filter's builder with every model set, so that a
    /// caller can replace one model (e.g. a detection model with run-time state) before
    /// building. Errors name the offending field.
    pub fn builder(&self) -> Result<crate::filter::LmbFilterBuilder> {
        if !(0.0..=1.0).contains(&self.survival) {
            return Err(Error::invalid(
                "config field `survival`",
                format!("{} outside [0, 1]", self.survival),
            ));
        }
        let (state_dim, axes) = match self.transition {
            TransitionConfig::ConstantVelocity { dims, .. } => (2 * dims, dims),
            TransitionConfig::CoordinatedTurn { .. } => (5, 2),
        };
        self.association.validate()?;
        let builder = LmbFilter::builder()
            .survival(ConstantSurvival::new(self.survival)?)
            .config(self.filter.clone())
            .associator(self.association);
        let builder = builder.transition(self.transition.model()?);
        let (builder, first_measurement, range_bearing) = if self.sensors.is_empty() {
            let missing = |what: &str| {
                Error::invalid(
                    format!("config field `{what}`"),
                    "missing (give it, or one [[sensors]] table per sensor)",
                )
            };
            let measurement = self
                .measurement
                .as_ref()
                .ok_or_else(|| missing("measurement"))?;
            let detection = self
                .detection
                .as_ref()
                .ok_or_else(|| missing("detection"))?;
            let clutter = self.clutter.as_ref().ok_or_else(|| missing("clutter"))?;
            let (m, rb) = measurement_model(measurement, axes, "measurement")?;
            let builder = builder
                .clutter(clutter_model(clutter)?)
                .detection_box(detection_model(detection)?)
                .measurement_box(m);
            (builder, measurement, rb)
        } else {
            if let Some(what) = [
                self.measurement.as_ref().map(|_| "measurement"),
                self.detection.as_ref().map(|_| "detection"),
                self.clutter.as_ref().map(|_| "clutter"),
            ]
            .into_iter()
            .flatten()
            .next()
            {
                return Err(Error::invalid(
                    format!("config field `{what}`"),
                    "given beside [[sensors]]; each sensor has its own",
                ));
            }
            let mut builder = builder;
            let mut first = None;
            for (i, sc) in self.sensors.iter().enumerate() {
                let field = |f: &str| format!("sensors[{i}].{f}");
                let (m, rb) = measurement_model(&sc.measurement, axes, &field("measurement"))?;
                let mut sensor = Sensor::from_boxes(
                    sc.name.clone(),
                    m,
                    detection_model(&sc.detection).map_err(|e| {
                        Error::invalid(
                            format!("config field `{}`", field("detection")),
                            e.to_string(),
                        )
                    })?,
                    Box::new(clutter_model(&sc.clutter).map_err(|e| {
                        Error::invalid(
                            format!("config field `{}`", field("clutter")),
                            e.to_string(),
                        )
                    })?),
                );
                if let Some([x, y, h]) = sc.mounting {
                    if rb.is_some() {
                        return Err(Error::invalid(
                            format!("config field `{}`", field("mounting")),
                            "a mounting moves positions; a range-bearing sensor takes its \
                             mounting offset in the measurement model's `offset`",
                        ));
                    }
                    sensor = sensor.mounted(Mounting::new(x, y, h).map_err(|e| {
                        Error::invalid(
                            format!("config field `{}`", field("mounting")),
                            e.to_string(),
                        )
                    })?);
                }
                builder = builder.sensor(sensor);
                if first.is_none() {
                    first = Some((&sc.measurement, rb));
                }
            }
            let names: Vec<&str> = self.sensors.iter().map(|s| s.name.as_str()).collect();
            let builder = builder.fusion(self.fusion.clone().unwrap_or_default().fusion(&names)?);
            let (m, rb) = first.expect("at least one sensor");
            (builder, m, rb)
        };
        let builder = match &self.birth {
            BirthConfig::Static {
                terms,
                particles,
                measurement_proposal,
            } => {
                if let Some((i, t)) = terms
                    .iter()
                    .enumerate()
                    .find(|(_, t)| t.mean.len() != state_dim)
                {
                    return Err(Error::invalid(
                        format!("config field `birth.terms[{i}]`"),
                        format!(
                            "has {} state components, the transition has {state_dim}",
                            t.mean.len()
                        ),
                    ));
                }
                let birth = StaticBirth::new(terms.clone(), *particles)?;
                // The built-in layouts keep position in components 0, 2 (and 4).
                let observed: Vec<usize> = (0..axes).map(|a| 2 * a).collect();
                match (first_measurement, &range_bearing, measurement_proposal) {
                    (MeasurementConfig::Position { sigma }, _, true) => builder.birth(
                        birth.with_proposal(BirthProposal::new(observed, vec![*sigma; axes])?)?,
                    ),
                    (_, Some(rb), true) => {
                        // The proposal's own noise is not used: every point brings its spread.
                        let (sr, _) = rb.noise();
                        let proposal = BirthProposal::new(observed, vec![sr; axes])?;
                        builder.birth(RangeBearingGuidedBirth {
                            birth: birth.with_proposal(proposal)?,
                            sensor: *rb,
                        })
                    }
                    _ => builder.birth(birth),
                }
            }
            BirthConfig::Adaptive {
                expected_births,
                max_existence,
                particles,
                position_std,
                velocity_std,
                turn_rate_std,
            } => {
                ensure_finite(
                    "config field `birth` spreads",
                    &[*position_std, *velocity_std, *turn_rate_std],
                )?;
                if *position_std < 0.0 || *velocity_std < 0.0 || *turn_rate_std < 0.0 {
                    return Err(Error::invalid(
                        "config field `birth`",
                        "standard deviations must be ≥ 0",
                    ));
                }
                let sampler = MeasurementBirth {
                    range_bearing,
                    axes,
                    turn_rate: state_dim == 5,
                    position_std: *position_std,
                    velocity_std: *velocity_std,
                    turn_rate_std: *turn_rate_std,
                };
                builder.birth(AdaptiveBirth::new(
                    sampler,
                    *expected_births,
                    *max_existence,
                    *particles,
                )?)
            }
        };
        Ok(builder)
    }
}

/// The measurement model of `m` for a transition with `axes` position axes, and the
/// range-bearing model again when it is one (the birth samplers convert with it); `field`
/// names the table in errors.
fn measurement_model(
    m: &MeasurementConfig,
    axes: usize,
    field: &str,
) -> Result<(Box<dyn MeasurementModel>, Option<RangeBearing>)> {
    Ok(match m {
        MeasurementConfig::Position { sigma } => {
            (Box::new(PositionMeasurement::new(axes, *sigma)?), None)
        }
        MeasurementConfig::RangeBearing {
            sigma_range,
            sigma_bearing,
            offset,
            convention,
        } => {
            if axes != 2 {
                return Err(Error::invalid(
                    format!("config field `{field}`"),
                    "range-bearing needs a planar transition",
                ));
            }
            let rb = RangeBearing::new(*sigma_range, *sigma_bearing)?
                .with_offset(offset[0], offset[1])?
                .with_convention(*convention);
            (Box::new(rb), Some(rb))
        }
    })
}

/// The detection model of `d`.
fn detection_model(d: &DetectionConfig) -> Result<Box<dyn DetectionModel>> {
    Ok(match d {
        DetectionConfig::Constant { probability } => {
            Box::new(ConstantDetection::new(*probability)?)
        }
        DetectionConfig::GaussianRange {
            peak,
            scale,
            center,
        } => Box::new(GaussianRangeDetection::new(*peak, *scale, *center)?),
        DetectionConfig::FieldOfView {
            p_inside,
            p_outside,
            max_range,
            half_angle,
            offset,
        } => Box::new(
            FieldOfViewDetection::new(*p_inside, *p_outside, *max_range, *half_angle)?
                .with_offset(offset[0], offset[1])?,
        ),
    })
}

/// The clutter model of `c`.
fn clutter_model(c: &ClutterConfig) -> Result<UniformClutter> {
    UniformClutter::new(c.rate, c.volume)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> RunConfig {
        serde_json::from_value(serde_json::json!({
            "transition": {"model": "constant_velocity", "dims": 2, "sigma_accel": 1.0},
            "measurement": {"model": "position", "sigma": 0.5},
            "detection": {"model": "constant", "probability": 0.9},
            "clutter": {"rate": 5.0, "volume": 40000.0},
            "birth": {"model": "adaptive", "expected_births": 0.1, "max_existence": 0.05, "particles": 100,
                      "position_std": 1.0, "velocity_std": 2.0}
        }))
        .unwrap()
    }

    #[test]
    fn defaults_fill_in_and_the_filter_builds() {
        let c = sample();
        assert_eq!(c.survival, 0.99);
        assert_eq!(c.filter, LmbConfig::default());
        assert!(c.build().is_ok());
        // The duplicate merge is off unless the [filter] table sets it.
        let f: LmbConfig = serde_json::from_str(r#"{"merge_threshold": 9.0}"#).unwrap();
        assert_eq!(f.merge_threshold, Some(9.0));
        assert_eq!(LmbConfig::default().merge_threshold, None);
    }

    #[test]
    fn bad_values_are_named() {
        let mut c = sample();
        c.clutter.as_mut().unwrap().volume = f64::NAN;
        assert!(c
            .build()
            .unwrap_err()
            .to_string()
            .contains("clutter volume"));
        let mut c = sample();
        c.survival = 1.5;
        assert!(c.build().unwrap_err().to_string().contains("survival"));
        let mut c = sample();
        c.birth = BirthConfig::Static {
            terms: vec![BirthTerm {
                existence: 0.1,
                mean: vec![0.0; 3],
                std: vec![1.0; 3],
            }],
            particles: 10,
            measurement_proposal: true,
        };
        assert!(c
            .build()
            .unwrap_err()
            .to_string()
            .contains("birth.terms[0]"));
        let err = serde_json::from_str::<RunConfig>(r#"{"transition": {"model": "warp_drive"}}"#)
            .unwrap_err();
        assert!(err.to_string().contains("warp_drive"));
    }

    #[test]
    fn static_birth_uses_the_measurement_proposal_unless_turned_off() {
        let static_birth = |extra: &str| -> BirthConfig {
            let text = format!(
                r#"{{"model": "static", "particles": 10{extra},
                    "terms": [{{"existence": 0.01, "mean": [0, 0, 0, 0], "std": [50, 10, 50, 10]}}]}}"#
            );
            serde_json::from_str(&text).unwrap()
        };
        assert!(matches!(
            static_birth(""),
            BirthConfig::Static {
                measurement_proposal: true,
                ..
            }
        ));
        assert!(matches!(
            static_birth(r#", "measurement_proposal": false"#),
            BirthConfig::Static {
                measurement_proposal: false,
                ..
            }
        ));
        let mut c = sample();
        c.birth = static_birth("");
        assert!(c.build().is_ok());
        c.birth = static_birth(r#", "measurement_proposal": false"#);
        assert!(c.build().is_ok());
        // Range-bearing measurements: the guided birth runs through the filter.
        c.measurement = Some(MeasurementConfig::RangeBearing {
            sigma_range: 1.0,
            sigma_bearing: 0.01,
            offset: [0.0, 0.0],
            convention: BearingConvention::default(),
        });
        c.birth = static_birth("");
        let mut f = c.build().unwrap();
        let z = crate::filter::Measurements::from_rows(2, &[[50.0, 0.3], [20.0, -1.0]]).unwrap();
        let mut rng = crate::rng::seeded(1);
        for k in 0..3 {
            let frame = crate::filter::Frame::new(k as f64, z.clone());
            assert!(f.step(&frame, &mut rng).is_ok());
        }
        assert!(!f.tracks().is_empty());
    }
}
