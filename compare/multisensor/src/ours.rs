//! Our filter on a peer scenario, with one setting for every scenario: the peer's model
//! (constant velocity with σ_a = the file's process noise, p_S, p_D, σ, clutter rate over the
//! scene's area) and [`PARTICLES`] particles per track, everything else `LmbConfig::default()`.
//!
//! Births: `static` = the peer's 16 birth terms at the file's birth locations, r_B = 0.01,
//! covariance diag(2500, 2500, 100, 100) in the peer's [x, y, vx, vy] (std 50 m and 10 m/s),
//! sampled with the measurement-guided proposal (our default for static terms); `static-plain`
//! = the same terms sampled plainly; `adaptive` = adaptive birth (λ_B = 1, r_B,max = 0.1,
//! position std σ, velocity std 10 m/s = the static terms' velocity spread).

use crate::{timed, Runner, Scenario, StepOut};
use rand_distr::{Distribution, StandardNormal};
use smc_lmb::config::{
    BirthConfig, ClutterConfig, DetectionConfig, FusionConfig, MeasurementConfig, RunConfig,
    SensorConfig, TransitionConfig,
};
use smc_lmb::filter::{
    check_state_dim, BirthTerm, Frame, FusionMethod, LmbConfig, LmbFilter, Measurements,
    ParticleSet, StepContext, TransitionModel,
};
use smc_lmb::rng::{seeded, FilterRng};

/// Particles per track and per birth track, in every scenario (`--particles` changes it for
/// a whole run).
pub const PARTICLES: usize = 1000;

/// Whether this build has the multi-sensor rules.
pub const MULTI_SENSOR: bool = true;

/// How a reported track's state is read from its particles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Estimator {
    /// The filter's own estimate: the weighted mean of all the track's particles.
    Mean,
    /// The weighted mean of the particles in the heaviest 3 × 3 block of square position
    /// cells of side 2σ (σ = measurement noise): the mean of the track's main mode, as the
    /// peer reports the mean of a track's heaviest Gaussian component. For a one-peaked
    /// density (σ/√2 spread or less after an update) the block holds practically every
    /// particle and this is the mean; it differs where a new track's density is split
    /// between several measurements, whose mean lies between the objects.
    Mode,
}

impl Estimator {
    pub fn parse(s: &str) -> Option<Estimator> {
        Some(match s {
            "mean" => Estimator::Mean,
            "mode" => Estimator::Mode,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Estimator::Mean => "mean",
            Estimator::Mode => "mode",
        }
    }
}

/// How σ_a of the scenario file becomes the process noise of the constant-velocity model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motion {
    /// Our built-in model: a constant acceleration a ~ N(0, σ_a²) per step and axis
    /// (Q = σ_a² [dt⁴/4, dt³/2; dt³/2, dt²], rank one per axis).
    Discrete,
    /// The peer's model: continuous white-noise acceleration of spectral density σ_a²
    /// (Q = σ_a² [dt³/3, dt²/2; dt²/2, dt] per axis, full rank), the Q its Kalman filters use.
    Continuous,
}

impl Motion {
    pub fn parse(s: &str) -> Option<Motion> {
        Some(match s {
            "discrete" => Motion::Discrete,
            "continuous" => Motion::Continuous,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Motion::Discrete => "discrete",
            Motion::Continuous => "continuous",
        }
    }
}

/// Constant velocity in 2 axes (state [x, ẋ, y, ẏ]) with continuous white-noise acceleration
/// of spectral density σ²: per axis (Δp, Δv) ~ N(0, σ² [dt³/3, dt²/2; dt²/2, dt]), drawn as
/// Δp = σ√(dt³/3)·e₁, Δv = σ√dt·(√3/2·e₁ + ½·e₂) (the Cholesky factor).
struct ContinuousWhiteNoiseCv {
    sigma: f64,
}

impl TransitionModel for ContinuousWhiteNoiseCv {
    fn state_dim(&self) -> usize {
        4
    }

    fn predict(
        &self,
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> smc_lmb::Result<()> {
        check_state_dim(&self.name(), 4, particles)?;
        let dt = ctx.dt;
        let (sp, sv) = (
            self.sigma * (dt * dt * dt / 3.0).sqrt(),
            self.sigma * dt.sqrt(),
        );
        let half_sqrt3 = 0.5 * 3f64.sqrt();
        let mut comps = particles.components_mut();
        for axis in 0..2 {
            let (head, tail) = comps.split_at_mut(2 * axis + 1);
            for (p, v) in head[2 * axis].iter_mut().zip(tail[0].iter_mut()) {
                let e1: f64 = StandardNormal.sample(rng);
                let e2: f64 = StandardNormal.sample(rng);
                *p += dt * *v + sp * e1;
                *v += sv * (half_sqrt3 * e1 + 0.5 * e2);
            }
        }
        Ok(())
    }
}

/// The settings of our filter in a run (the same for every scenario).
#[derive(Clone, Copy, Debug)]
pub struct Tuning {
    /// Particles per track and per birth track.
    pub particles: usize,
    /// `LmbConfig::min_particles`: particles follow existence when set.
    pub min_particles: Option<usize>,
    pub estimator: Estimator,
    pub motion: Motion,
    /// Particles of each birth track (static and adaptive); `None`: `particles`.
    pub birth_particles: Option<usize>,
}

/// [`Estimator::Mode`] of one particle set with position components 0 and 2.
fn mode_mean(p: &ParticleSet, cell: f64) -> Vec<f64> {
    use std::collections::BTreeMap;
    let (x, y, w) = (p.component(0), p.component(2), p.weights());
    let key = |i: usize| ((x[i] / cell).floor() as i64, (y[i] / cell).floor() as i64);
    let mut cells: BTreeMap<(i64, i64), f64> = BTreeMap::new();
    for (i, &wi) in w.iter().enumerate() {
        *cells.entry(key(i)).or_default() += wi;
    }
    let block = |(a, b): (i64, i64)| -> f64 {
        let mut s = 0.0;
        for da in -1..=1 {
            for db in -1..=1 {
                s += cells.get(&(a + da, b + db)).copied().unwrap_or(0.0);
            }
        }
        s
    };
    // The heaviest block (the first in cell order on ties).
    let mut best = None;
    for &c in cells.keys() {
        let s = block(c);
        if best.is_none_or(|(_, bs)| s > bs) {
            best = Some((c, s));
        }
    }
    let Some(((a, b), _)) = best else {
        return p.mean();
    };
    let mut mean = vec![0.0; p.dim()];
    let mut total = 0.0;
    let mut state = vec![0.0; p.dim()];
    for (i, &wi) in w.iter().enumerate() {
        let (ka, kb) = key(i);
        if (ka - a).abs() <= 1 && (kb - b).abs() <= 1 {
            p.state_into(i, &mut state);
            for (m, v) in mean.iter_mut().zip(&state) {
                *m += wi * v;
            }
            total += wi;
        }
    }
    if total <= 0.0 {
        return p.mean();
    }
    mean.iter_mut().for_each(|m| *m /= total);
    mean
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    /// Today's single-sensor filter on sensor 0's points.
    Single,
    IteratedCorrector,
    ParallelUpdate,
    GeometricAverage,
    ArithmeticAverage,
}

impl Rule {
    pub const FUSED: [Rule; 4] = [
        Rule::IteratedCorrector,
        Rule::ParallelUpdate,
        Rule::GeometricAverage,
        Rule::ArithmeticAverage,
    ];

    pub fn parse(s: &str) -> Option<Rule> {
        Some(match s {
            "single" => Rule::Single,
            "ic" => Rule::IteratedCorrector,
            "pu" => Rule::ParallelUpdate,
            "ga" => Rule::GeometricAverage,
            "aa" => Rule::ArithmeticAverage,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Rule::Single => "single",
            Rule::IteratedCorrector => "ic",
            Rule::ParallelUpdate => "pu",
            Rule::GeometricAverage => "ga",
            Rule::ArithmeticAverage => "aa",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Birth {
    Static,
    StaticPlain,
    Adaptive,
}

impl Birth {
    pub fn parse(s: &str) -> Option<Birth> {
        Some(match s {
            "static" => Birth::Static,
            "static-plain" => Birth::StaticPlain,
            "adaptive" => Birth::Adaptive,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Birth::Static => "static",
            Birth::StaticPlain => "static-plain",
            Birth::Adaptive => "adaptive",
        }
    }
}

/// The configuration of a scenario: with [`Rule::Single`] today's single-sensor form (one set
/// of models, fed sensor 0's points), otherwise one `[[sensors]]` entry per sensor of the
/// scenario (named `s0`, `s1`, ...; the same models) and `[fusion] method = rule`, uniform
/// weights, IC in sensor order.
pub fn config(s: &Scenario, rule: Rule, birth: Birth, seed: u64, tuning: Tuning) -> RunConfig {
    let particles = tuning.particles;
    let birth_particles = tuning.birth_particles.unwrap_or(particles);
    let birth = match birth {
        Birth::Static | Birth::StaticPlain => BirthConfig::Static {
            // Our state is [x, ẋ, y, ẏ]; the peer's birth locations are [x, y, vx, vy].
            terms: s
                .birth_locations
                .iter()
                .map(|b| BirthTerm {
                    existence: 0.01,
                    mean: vec![b[0], b[2], b[1], b[3]],
                    std: vec![50.0, 10.0, 50.0, 10.0],
                })
                .collect(),
            particles: birth_particles,
            measurement_proposal: birth == Birth::Static,
        },
        Birth::Adaptive => BirthConfig::Adaptive {
            expected_births: 1.0,
            max_existence: 0.1,
            particles: birth_particles,
            position_std: s.measurement_noise_std,
            velocity_std: 10.0,
            turn_rate_std: 0.1,
        },
    };
    let measurement = MeasurementConfig::Position {
        sigma: s.measurement_noise_std,
    };
    let detection = DetectionConfig::Constant {
        probability: s.detection_probability,
    };
    let clutter = ClutterConfig {
        rate: s.clutter_rate,
        volume: s.area,
    };
    let method = match rule {
        Rule::Single => None,
        Rule::IteratedCorrector => Some(FusionMethod::IteratedCorrector),
        Rule::ParallelUpdate => Some(FusionMethod::ParallelUpdate),
        Rule::GeometricAverage => Some(FusionMethod::GeometricAverage),
        Rule::ArithmeticAverage => Some(FusionMethod::ArithmeticAverage),
    };
    let (one, sensors, fusion) = match method {
        None => (Some((measurement, detection, clutter)), Vec::new(), None),
        Some(method) => (
            None,
            (0..s.sensors)
                .map(|i| SensorConfig {
                    name: format!("s{i}"),
                    measurement: measurement.clone(),
                    detection: detection.clone(),
                    clutter: clutter.clone(),
                    mounting: None,
                })
                .collect(),
            Some(FusionConfig {
                method,
                ..FusionConfig::default()
            }),
        ),
    };
    RunConfig {
        seed,
        survival: s.survival_probability,
        filter: LmbConfig {
            particles,
            min_particles: tuning.min_particles,
            ..LmbConfig::default()
        },
        transition: TransitionConfig::ConstantVelocity {
            dims: 2,
            sigma_accel: s.process_noise_std,
        },
        measurement: one.as_ref().map(|o| o.0.clone()),
        detection: one.as_ref().map(|o| o.1.clone()),
        clutter: one.map(|o| o.2),
        sensors,
        fusion,
        birth,
        association: Default::default(),
    }
}

pub struct OurRunner<'a> {
    scenario: &'a Scenario,
    rule: Rule,
    filter: LmbFilter,
    rng: FilterRng,
    estimator: Estimator,
}

impl<'a> OurRunner<'a> {
    pub fn new(
        s: &'a Scenario,
        rule: Rule,
        birth: Birth,
        seed: u64,
        tuning: Tuning,
    ) -> Result<Self, String> {
        let builder = config(s, rule, birth, seed, tuning)
            .builder()
            .map_err(|e| e.to_string())?;
        let builder = match tuning.motion {
            Motion::Discrete => builder,
            Motion::Continuous => builder.transition(ContinuousWhiteNoiseCv {
                sigma: s.process_noise_std,
            }),
        };
        let filter = builder.build().map_err(|e| e.to_string())?;
        Ok(OurRunner {
            scenario: s,
            rule,
            filter,
            rng: seeded(seed),
            estimator: tuning.estimator,
        })
    }
}

impl Runner for OurRunner<'_> {
    fn step(&mut self, k: usize) -> Result<StepOut, String> {
        let t = k as f64 * self.scenario.dt;
        let z = &self.scenario.readings[k];
        let frame = match self.rule {
            Rule::Single => Frame::new(
                t,
                Measurements::from_rows(2, &z[0]).map_err(|e| e.to_string())?,
            ),
            _ => {
                let mut f = Frame::at_time(t);
                for (i, zi) in z.iter().enumerate() {
                    f = f.with_sensor(
                        i,
                        Measurements::from_rows(2, zi).map_err(|e| e.to_string())?,
                    );
                }
                f
            }
        };
        let cell = 2.0 * self.scenario.measurement_noise_std;
        let (filter, rng, estimator) = (&mut self.filter, &mut self.rng, self.estimator);
        // The mode estimate is part of the step's time.
        let (est, ms, cpu_ms) = timed(|| {
            let est = filter.step(&frame, rng)?;
            Ok::<_, smc_lmb::Error>(match estimator {
                Estimator::Mean => est.into_iter().map(|e| e.state).collect::<Vec<_>>(),
                Estimator::Mode => est
                    .iter()
                    .map(|e| {
                        filter
                            .tracks()
                            .iter()
                            .find(|t| t.label == e.label)
                            .map_or_else(|| e.state.clone(), |t| mode_mean(&t.particles, cell))
                    })
                    .collect(),
            })
        });
        let est = est.map_err(|e| format!("step {k}: {e}"))?;
        Ok(StepOut {
            ms,
            cpu_ms,
            estimates: est.iter().map(|x| [x[0], x[2]]).collect(),
        })
    }
}
