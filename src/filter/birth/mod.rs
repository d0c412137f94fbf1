//! Where new tracks come from: the birth LMB of each step.
//!
//! Two models are built in. [`StaticBirth`] is a fixed list of Gaussian birth terms, for
//! scenes where objects appear at known places (the standard benchmarks). [`AdaptiveBirth`] is
//! the measurement-driven birth of Reuter, Vo, Vo & Dietmayer (IEEE TSP 2014, Sec. IV): every
//! measurement of the previous step that the existing tracks explained poorly proposes a new
//! track, with an existence probability that grows with how unexplained it was. Not for:
//! assigning labels (the filter does that).
//!
//! A static birth term is a broad density, and few of its particles would land where a new
//! object is seen. Given a [`BirthProposal`] (the default in [`crate::config`]), static birth
//! samples each term from a mixture of the term and the term conditioned on each of the
//! step's measurements that no existing track explains (`proposal`, [`unexplained`]), and
//! weights the particles prior / proposal: the same birth density, better sampled. The filter
//! hands a birth model the step's measurements through [`BirthModel::birth_guided`].

mod proposal;
mod unexplained;

pub use proposal::{BirthProposal, DEFAULT_PRIOR_SHARE};
pub use unexplained::unexplained;

use super::{Measurements, ParticleSet};
use crate::error::{ensure_finite, Error, Result};
use crate::filter::{StepContext, MAX_PARTICLES};
use crate::rng::{stream, FilterRng};
use rand::Rng;
use rayon::prelude::*;

/// A proposed new track, before it gets its label.
#[derive(Clone, Debug, PartialEq)]
pub struct BirthTrack {
    /// Existence probability r_B ∈ (0, 1].
    pub existence: f64,
    /// The state density.
    pub particles: ParticleSet,
    /// True when `particles` describe the object at the *previous* step (adaptive birth
    /// from last step's measurements): the filter then applies the transition to it.
    pub at_previous_step: bool,
}

/// What the previous step saw, handed to birth models that learn from measurements.
#[derive(Clone, Debug)]
pub struct BirthEvidence<'a> {
    /// The previous step's measurements.
    pub measurements: &'a Measurements,
    /// For each of them, the probability r_A(z) that an existing track generated it.
    pub assigned: &'a [f64],
    /// The previous step's context (platform pose there).
    pub context: &'a StepContext,
}

/// The step's own measurements, the ones its birth tracks will be updated with, for birth
/// models that sample where they are.
#[derive(Clone, Debug)]
pub struct CurrentMeasurements<'a> {
    /// This step's measurements.
    pub measurements: &'a Measurements,
    /// For each of them, u(z) ∈ [0, 1]: how unexplained the predicted tracks leave it (see
    /// [`unexplained`]). An empty slice means every measurement counts as unexplained.
    pub unexplained: &'a [f64],
}

/// Produces the birth LMB of a step.
pub trait BirthModel: Send + Sync {
    /// The birth tracks of the step described by `ctx`. `evidence` holds the previous step's
    /// measurements and their association probabilities (`None` at the first step).
    fn birth(
        &self,
        ctx: &StepContext,
        evidence: Option<&BirthEvidence<'_>>,
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack>;

    /// Whether [`BirthModel::birth_guided`] looks at the step's measurements; when false the
    /// filter does not work out which of them are unexplained. Default false.
    fn uses_current_measurements(&self) -> bool {
        false
    }

    /// The birth tracks of the step, told also the step's own measurements. The filter calls
    /// this one. A model may use the measurements to decide *how* to sample its densities
    /// (importance sampling), never *what* they are: its existence probabilities and densities
    /// must be those of [`BirthModel::birth`]. Default: [`BirthModel::birth`].
    fn birth_guided(
        &self,
        ctx: &StepContext,
        evidence: Option<&BirthEvidence<'_>>,
        current: &CurrentMeasurements<'_>,
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack> {
        let _ = current;
        self.birth(ctx, evidence, rng)
    }

    /// The length of the states this model's births have, for measurements of
    /// `measurement_dim` components, when it knows it: the filter's builder compares it with
    /// the transition's. `None` (the default) skips that check; the filter still refuses a
    /// birth of the wrong length when it is drawn.
    fn state_dim(&self, measurement_dim: usize) -> Option<usize> {
        let _ = measurement_dim;
        None
    }

    /// The model's name in errors; the type's name by default.
    fn name(&self) -> String {
        crate::filter::model_name::<Self>()
    }
}

impl<T: BirthModel + ?Sized> BirthModel for Box<T> {
    fn birth(
        &self,
        ctx: &StepContext,
        evidence: Option<&BirthEvidence<'_>>,
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack> {
        (**self).birth(ctx, evidence, rng)
    }
    fn uses_current_measurements(&self) -> bool {
        (**self).uses_current_measurements()
    }
    fn birth_guided(
        &self,
        ctx: &StepContext,
        evidence: Option<&BirthEvidence<'_>>,
        current: &CurrentMeasurements<'_>,
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack> {
        (**self).birth_guided(ctx, evidence, current, rng)
    }
    fn state_dim(&self, measurement_dim: usize) -> Option<usize> {
        (**self).state_dim(measurement_dim)
    }
    fn name(&self) -> String {
        (**self).name()
    }
}

/// One Gaussian birth term: existence probability, mean and per-component standard deviation.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BirthTerm {
    /// Existence probability.
    pub existence: f64,
    /// Mean state.
    pub mean: Vec<f64>,
    /// Standard deviation of each state component.
    pub std: Vec<f64>,
}

/// Checks a birth track's particle count: 1 to [`MAX_PARTICLES`], like the filter's own (a
/// larger count would fail its allocation at the first birth, in the middle of a run).
fn check_particles(particles: usize) -> Result<()> {
    if particles == 0 {
        return Err(Error::invalid("birth particle count", "must be positive"));
    }
    if particles > MAX_PARTICLES {
        return Err(Error::invalid(
            "birth particle count",
            format!("{particles} is above the limit of {MAX_PARTICLES}"),
        ));
    }
    Ok(())
}

/// A fixed list of Gaussian birth terms, proposed at every step. Without a proposal each
/// term's particles are drawn from the term itself; with one ([`StaticBirth::with_proposal`])
/// they are drawn near the step's unexplained measurements and importance-weighted.
#[derive(Clone, Debug, PartialEq)]
pub struct StaticBirth {
    terms: Vec<BirthTerm>,
    particles: usize,
    proposal: Option<BirthProposal>,
}

impl StaticBirth {
    /// A birth list; each term is sampled with `particles` particles.
    pub fn new(terms: Vec<BirthTerm>, particles: usize) -> Result<Self> {
        for (i, t) in terms.iter().enumerate() {
            let what = format!("birth term {i}");
            if !(t.existence > 0.0 && t.existence <= 1.0) {
                return Err(Error::invalid(
                    what,
                    format!("existence {} outside (0, 1]", t.existence),
                ));
            }
            if t.mean.is_empty() || t.mean.len() != t.std.len() {
                return Err(Error::invalid(
                    what,
                    "mean and std must have the same, positive length",
                ));
            }
            ensure_finite(&format!("mean of {what}"), &t.mean)?;
            ensure_finite(&format!("std of {what}"), &t.std)?;
            if t.std.iter().any(|s| *s < 0.0) {
                return Err(Error::invalid(what, "negative standard deviation"));
            }
            if t.mean.len() != terms[0].mean.len() {
                return Err(Error::invalid(
                    what,
                    format!(
                        "a state of {} components, but term 0 has {} (one filter moves states \
                         of one length)",
                        t.mean.len(),
                        terms[0].mean.len()
                    ),
                ));
            }
        }
        check_particles(particles)?;
        Ok(StaticBirth {
            terms,
            particles,
            proposal: None,
        })
    }

    /// The same terms, sampled with a measurement-guided proposal (the birth density is
    /// unchanged). Fails when the proposal observes a component the terms do not have.
    pub fn with_proposal(mut self, proposal: BirthProposal) -> Result<Self> {
        for t in &self.terms {
            proposal.check_state_dim(t.mean.len())?;
        }
        self.proposal = Some(proposal);
        Ok(self)
    }

    /// The terms.
    pub fn terms(&self) -> &[BirthTerm] {
        &self.terms
    }

    /// The measurement-guided proposal, if any.
    pub fn proposal(&self) -> Option<&BirthProposal> {
        self.proposal.as_ref()
    }
}

impl BirthModel for StaticBirth {
    fn state_dim(&self, _measurement_dim: usize) -> Option<usize> {
        self.terms.first().map(|t| t.mean.len())
    }

    fn birth(
        &self,
        _: &StepContext,
        _: Option<&BirthEvidence<'_>>,
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack> {
        self.terms
            .iter()
            .map(|t| BirthTrack {
                existence: t.existence,
                particles: ParticleSet::sampled(&t.mean, &t.std, self.particles, rng),
                at_previous_step: false,
            })
            .collect()
    }

    fn uses_current_measurements(&self) -> bool {
        self.proposal.is_some()
    }

    /// With a proposal, every term is sampled from its own random stream (derived from one
    /// draw of `rng` and the term's index), in parallel; the result does not depend on the
    /// thread count.
    fn birth_guided(
        &self,
        ctx: &StepContext,
        evidence: Option<&BirthEvidence<'_>>,
        current: &CurrentMeasurements<'_>,
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack> {
        match &self.proposal {
            None => self.birth(ctx, evidence, rng),
            Some(proposal) => self.each_term(rng, |t, n, rng| proposal.sample(t, current, n, rng)),
        }
    }
}

impl StaticBirth {
    /// The birth tracks of a step with every term sampled near `points`: the step's
    /// measurements converted to the proposal's observed components, with their spreads and
    /// u(z) (see [`BirthProposal::sample_points`]). For birth models that wrap a static birth
    /// for measurements that are not positions (range-bearing); without a proposal this is
    /// [`BirthModel::birth`].
    pub fn birth_near_points(
        &self,
        points: &Measurements,
        noise_std: &[f64],
        unexplained: &[f64],
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack> {
        match &self.proposal {
            None => self.birth(&StepContext::new(0, 0.0, 0.0), None, rng),
            Some(proposal) => self.each_term(rng, |t, n, rng| {
                proposal.sample_points(t, points, noise_std, unexplained, n, rng)
            }),
        }
    }

    /// One birth track per term, its particles from `sample` with the term's own stream.
    fn each_term<F>(&self, rng: &mut FilterRng, sample: F) -> Vec<BirthTrack>
    where
        F: Fn(&BirthTerm, usize, &mut FilterRng) -> ParticleSet + Sync,
    {
        let seed = rng.next_u64();
        self.terms
            .par_iter()
            .enumerate()
            .map(|(i, t)| BirthTrack {
                existence: t.existence,
                particles: sample(t, self.particles, &mut stream(seed, i as u64)),
                at_previous_step: false,
            })
            .collect()
    }
}

/// Draws a particle set of object states consistent with one measurement (an inverse
/// measurement model with a prior on what the measurement does not see, e.g. velocity).
pub trait BirthSampler: Send + Sync {
    /// `n` particles for an object that produced `z` at the step described by `ctx`.
    fn sample(&self, z: &[f64], ctx: &StepContext, n: usize, rng: &mut FilterRng) -> ParticleSet;

    /// The length of the states drawn for a measurement of `measurement_dim` components,
    /// when the sampler knows it (see [`BirthModel::state_dim`]); `None` by default.
    fn state_dim(&self, measurement_dim: usize) -> Option<usize> {
        let _ = measurement_dim;
        None
    }

    /// The sampler's name in errors; the type's name by default.
    fn name(&self) -> String {
        crate::filter::model_name::<Self>()
    }
}

impl<F> BirthSampler for F
where
    F: Fn(&[f64], &StepContext, usize, &mut FilterRng) -> ParticleSet + Send + Sync,
{
    fn sample(&self, z: &[f64], ctx: &StepContext, n: usize, rng: &mut FilterRng) -> ParticleSet {
        self(z, ctx, n, rng)
    }
}

/// Birth sampler for Cartesian position measurements and interleaved constant-velocity states
/// `[x, ẋ, y, ẏ(, z, ż)]`: position ~ N(z, σ_p²), velocity ~ N(0, σ_v²) per axis.
#[derive(Clone, Debug, PartialEq)]
pub struct PositionBirthSampler {
    /// Standard deviation of the position around the measurement.
    pub position_std: f64,
    /// Standard deviation of each velocity component around zero.
    pub velocity_std: f64,
}

impl BirthSampler for PositionBirthSampler {
    fn sample(&self, z: &[f64], _: &StepContext, n: usize, rng: &mut FilterRng) -> ParticleSet {
        let mean: Vec<f64> = z.iter().flat_map(|&p| [p, 0.0]).collect();
        let std: Vec<f64> = z
            .iter()
            .flat_map(|_| [self.position_std, self.velocity_std])
            .collect();
        ParticleSet::sampled(&mean, &std, n, rng)
    }

    fn state_dim(&self, measurement_dim: usize) -> Option<usize> {
        Some(2 * measurement_dim)
    }
}

/// Measurement-driven birth (Reuter et al. 2014, Sec. IV).
///
/// A measurement z of the previous step with association probability r_A(z) proposes a track
/// with r_B(z) = min(r_B,max, 1 − r_A(z), λ_B · (1 − r_A(z)) / Σ_ξ (1 − r_A(ξ))), where λ_B
/// is the expected number of births per step. Proposals below `min_existence` are dropped.
///
/// The bound 1 − r_A(z) is ours, not Reuter's: the probability that z came from a new object
/// cannot exceed the probability that it came from none of the tracks. Without it, a scene
/// whose few measurements are all well explained still shares out λ_B among them: every
/// frame each of them proposes a duplicate of the track that explains it at r_B,max. Cluster
/// duplicates are merged ([`crate::filter::LmbConfig::merge_threshold`]), but duplicates of a
/// plane share its measurement and neither confirm nor die; on a simulated 400-frame street
/// drive they filled the 200 tracks the drive tracker keeps.
pub struct AdaptiveBirth {
    sampler: Box<dyn BirthSampler>,
    /// Expected number of births per step, λ_B.
    pub expected_births: f64,
    /// Upper bound r_B,max on a proposal's existence probability.
    pub max_existence: f64,
    /// Proposals with smaller existence are not created.
    pub min_existence: f64,
    /// Particles per proposed track.
    pub particles: usize,
}

impl AdaptiveBirth {
    /// Adaptive birth drawing each proposal's particles from `sampler`.
    pub fn new(
        sampler: impl BirthSampler + 'static,
        expected_births: f64,
        max_existence: f64,
        particles: usize,
    ) -> Result<Self> {
        if !(expected_births > 0.0 && expected_births.is_finite()) {
            return Err(Error::invalid(
                "expected births per step",
                format!("{expected_births} must be positive"),
            ));
        }
        if !(max_existence > 0.0 && max_existence <= 1.0) {
            return Err(Error::invalid(
                "maximum birth existence",
                format!("{max_existence} outside (0, 1]"),
            ));
        }
        check_particles(particles)?;
        Ok(AdaptiveBirth {
            sampler: Box::new(sampler),
            expected_births,
            max_existence,
            min_existence: 1e-5,
            particles,
        })
    }

    /// The existence probabilities r_B(z) for association probabilities `assigned`.
    pub fn birth_existence(&self, assigned: &[f64]) -> Vec<f64> {
        let total: f64 = assigned.iter().map(|a| 1.0 - a.clamp(0.0, 1.0)).sum();
        assigned
            .iter()
            .map(|a| {
                if total <= 0.0 {
                    0.0
                } else {
                    let unexplained = 1.0 - a.clamp(0.0, 1.0);
                    (self.expected_births * unexplained / total)
                        .min(self.max_existence)
                        .min(unexplained)
                }
            })
            .collect()
    }
}

impl BirthModel for AdaptiveBirth {
    fn state_dim(&self, measurement_dim: usize) -> Option<usize> {
        self.sampler.state_dim(measurement_dim)
    }

    fn name(&self) -> String {
        format!("AdaptiveBirth with {}", self.sampler.name())
    }

    fn birth(
        &self,
        _: &StepContext,
        evidence: Option<&BirthEvidence<'_>>,
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack> {
        let Some(ev) = evidence else {
            return Vec::new();
        };
        self.birth_existence(ev.assigned)
            .into_iter()
            .zip(ev.measurements.iter())
            .filter(|(r, _)| *r >= self.min_existence)
            .map(|(r, z)| BirthTrack {
                existence: r,
                particles: self.sampler.sample(z, ev.context, self.particles, rng),
                at_previous_step: true,
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;

    #[test]
    fn adaptive_existence_follows_reuter_rule() {
        let b = AdaptiveBirth::new(
            PositionBirthSampler {
                position_std: 1.0,
                velocity_std: 1.0,
            },
            0.2,
            0.05,
            10,
        )
        .unwrap();
        // unexplained masses 1, 0.5, 0 → total 1.5; λ_B = 0.2 → 0.1333 (capped 0.05), 0.0667 (capped), 0
        let r = b.birth_existence(&[0.0, 0.5, 1.0]);
        assert_eq!(r, vec![0.05, 0.05, 0.0]);
        let b = AdaptiveBirth::new(
            PositionBirthSampler {
                position_std: 1.0,
                velocity_std: 1.0,
            },
            0.03,
            0.05,
            10,
        )
        .unwrap();
        let r = b.birth_existence(&[0.0, 0.5, 1.0]);
        assert!((r[0] - 0.02).abs() < 1e-12 && (r[1] - 0.01).abs() < 1e-12 && r[2] == 0.0);
    }

    #[test]
    fn a_birth_is_no_more_probable_than_its_measurement_is_unexplained() {
        let b = AdaptiveBirth::new(
            PositionBirthSampler {
                position_std: 1.0,
                velocity_std: 1.0,
            },
            1.0,
            0.5,
            10,
        )
        .unwrap();
        // Two measurements explained with probability 0.95 and 0.9: unexplained 0.05 and
        // 0.1, total 0.15; Reuter's share λ_B · 0.05 / 0.15 = 1/3 and 2/3 (then 0.5 at most).
        let r = b.birth_existence(&[0.95, 0.9]);
        assert!(
            (r[0] - 0.05).abs() < 1e-12 && (r[1] - 0.1).abs() < 1e-12,
            "{r:?}"
        );
    }

    #[test]
    fn adaptive_birth_places_particles_at_unexplained_measurements() {
        let b = AdaptiveBirth::new(
            PositionBirthSampler {
                position_std: 0.5,
                velocity_std: 1.0,
            },
            1.0,
            0.5,
            2000,
        )
        .unwrap();
        let m = Measurements::from_rows(2, &[[10.0, -4.0], [0.0, 0.0]]).unwrap();
        let ctx = StepContext::new(0, 0.0, 1.0);
        let ev = BirthEvidence {
            measurements: &m,
            assigned: &[0.0, 1.0],
            context: &ctx,
        };
        let births = b.birth(&ctx, Some(&ev), &mut seeded(4));
        assert_eq!(births.len(), 1);
        let mean = births[0].particles.mean();
        assert!((mean[0] - 10.0).abs() < 0.1 && (mean[2] + 4.0).abs() < 0.1 && mean[1].abs() < 0.1);
        assert!(births[0].at_previous_step);
        assert!(b.birth(&ctx, None, &mut seeded(4)).is_empty());
    }

    #[test]
    fn guided_static_birth_does_not_depend_on_the_thread_count() {
        let terms: Vec<BirthTerm> = (0..6)
            .map(|i| BirthTerm {
                existence: 0.01,
                mean: vec![30.0 * i as f64, 0.0, 0.0, 0.0],
                std: vec![50.0, 10.0, 50.0, 10.0],
            })
            .collect();
        let proposal = BirthProposal::new(vec![0, 2], vec![1.0, 1.0]).unwrap();
        let birth = StaticBirth::new(terms, 500)
            .unwrap()
            .with_proposal(proposal)
            .unwrap();
        assert!(birth.uses_current_measurements());
        let z = Measurements::from_rows(2, &[[40.0, 10.0], [100.0, -30.0]]).unwrap();
        let ctx = StepContext::new(1, 1.0, 1.0);
        let current = CurrentMeasurements {
            measurements: &z,
            unexplained: &[1.0, 1.0],
        };
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| birth.birth_guided(&ctx, None, &current, &mut seeded(8)))
        };
        let one = run(1);
        assert_eq!(one.len(), 6);
        assert!(one
            .iter()
            .all(|b| b.existence == 0.01 && !b.at_previous_step));
        // Guided: some term's weights are not all equal.
        assert!(one
            .iter()
            .any(|b| b.particles.weights().windows(2).any(|w| w[0] != w[1])));
        assert_eq!(one, run(3));
        // Without the proposal the same model samples every term plainly.
        let plain = StaticBirth::new(birth.terms().to_vec(), 500).unwrap();
        assert!(!plain.uses_current_measurements());
        let b = plain.birth_guided(&ctx, None, &current, &mut seeded(8));
        assert!(b
            .iter()
            .all(|b| b.particles.weights().windows(2).all(|w| w[0] == w[1])));
        assert!(StaticBirth::new(birth.terms().to_vec(), 10)
            .unwrap()
            .with_proposal(BirthProposal::new(vec![0, 4], vec![1.0, 1.0]).unwrap())
            .is_err());
    }

    #[test]
    fn static_birth_validates_terms() {
        let bad = BirthTerm {
            existence: 1.5,
            mean: vec![0.0],
            std: vec![1.0],
        };
        assert!(StaticBirth::new(vec![bad], 10).is_err());
        let nan = BirthTerm {
            existence: 0.1,
            mean: vec![f64::NAN],
            std: vec![1.0],
        };
        assert!(StaticBirth::new(vec![nan], 10)
            .unwrap_err()
            .to_string()
            .contains("birth term 0"));
    }

    #[test]
    fn particle_counts_above_the_filters_limit_are_refused() {
        let term = BirthTerm {
            existence: 0.1,
            mean: vec![0.0],
            std: vec![1.0],
        };
        assert!(StaticBirth::new(vec![term.clone()], MAX_PARTICLES).is_ok());
        let msg = StaticBirth::new(vec![term], MAX_PARTICLES + 1)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("above the limit"), "{msg}");
        let sampler = PositionBirthSampler {
            position_std: 0.5,
            velocity_std: 1.0,
        };
        assert!(AdaptiveBirth::new(sampler, 1.0, 0.5, 1_000_000_000_000).is_err());
    }
}
