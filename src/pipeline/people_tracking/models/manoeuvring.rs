//! Constant velocity with occasional manoeuvres: the white acceleration of
//! [`ConstantVelocity`] drawn from a two-component scale mixture,
//!
//! a ~ (1 − ε) · N(0, σ²) + ε · N(0, σ_m²)  per particle and step (one choice for all axes),
//!
//! so most particles keep walking straight with the calm σ while a share ε explores sudden
//! changes of velocity (a person who stops, turns round or sets off). The density is a proper
//! transition density, heavier-tailed than one Gaussian; the filter needs no mode component
//! because the choice is made afresh at every step.
//!
//! Why: a pedestrian who turns round reverses a velocity of ~1 m/s within a fraction of a
//! second. A calm σ (0.3 m/s²) that keeps crossing people's tracks apart cannot follow that,
//! and a σ large enough to follow it blurs every crossing; with the mixture the few manoeuvring
//! particles catch the turned person and take over the track's weight.
//!
//! Not for: sustained turns at a known rate ([`crate::models::CoordinatedTurn`]).

use crate::error::{ensure_probability, Error, Result};
use crate::filter::ParticleSet;
use crate::filter::{check_state_dim, StepContext, TransitionModel};
use crate::models::ConstantVelocity;
use crate::rng::FilterRng;
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};

/// Constant velocity whose acceleration noise is a calm/manoeuvre mixture (module docs).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ManoeuvringVelocity {
    calm: ConstantVelocity,
    probability: f64,
    sigma_manoeuvre: f64,
}

impl ManoeuvringVelocity {
    /// `calm` for most particles; a share `probability` per step draws its acceleration with
    /// standard deviation `sigma_manoeuvre` (m/s², finite, ≥ 0) instead.
    pub fn new(calm: ConstantVelocity, probability: f64, sigma_manoeuvre: f64) -> Result<Self> {
        ensure_probability("manoeuvre probability", probability)?;
        if !(sigma_manoeuvre.is_finite() && sigma_manoeuvre >= 0.0) {
            return Err(Error::invalid(
                "manoeuvre sigma_accel",
                format!("{sigma_manoeuvre} (must be finite and non-negative)"),
            ));
        }
        Ok(ManoeuvringVelocity {
            calm,
            probability,
            sigma_manoeuvre,
        })
    }

    /// Acceleration variance per axis of the mixture: (1 − ε) σ² + ε σ_m².
    pub fn mixture_variance(&self) -> f64 {
        let s = self.calm.sigma_accel();
        (1.0 - self.probability) * s * s + self.probability * self.sigma_manoeuvre.powi(2)
    }
}

impl TransitionModel for ManoeuvringVelocity {
    fn state_dim(&self) -> usize {
        self.calm.state_dim()
    }

    fn predict(
        &self,
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> Result<()> {
        check_state_dim(&self.name(), self.state_dim(), particles)?;
        if particles.is_empty() {
            return Ok(());
        }
        let dt = ctx.dt;
        let half_dt2 = 0.5 * dt * dt;
        let dims = self.calm.dims();
        let (calm, wide, eps) = (
            self.calm.sigma_accel(),
            self.sigma_manoeuvre,
            self.probability,
        );
        let mut comps = particles.components_mut();
        if dims == 2 {
            // The planar case as one zipped pass (no index checks), the hot path of people.
            let mut it = comps.iter_mut();
            let (x, vx, y, vy) = match (it.next(), it.next(), it.next(), it.next()) {
                (Some(x), Some(vx), Some(y), Some(vy)) => (x, vx, y, vy),
                _ => return Ok(()),
            };
            for (((x, vx), y), vy) in x
                .iter_mut()
                .zip(vx.iter_mut())
                .zip(y.iter_mut())
                .zip(vy.iter_mut())
            {
                let u: f64 = rng.random();
                let sigma = if u < eps { wide } else { calm };
                let ex: f64 = StandardNormal.sample(rng);
                let ey: f64 = StandardNormal.sample(rng);
                let (ax, ay) = (sigma * ex, sigma * ey);
                *x += dt * *vx + half_dt2 * ax;
                *vx += dt * ax;
                *y += dt * *vy + half_dt2 * ay;
                *vy += dt * ay;
            }
            return Ok(());
        }
        for i in 0..comps[0].len() {
            let u: f64 = rng.random();
            let sigma = if u < eps { wide } else { calm };
            for axis in 0..dims {
                let e: f64 = StandardNormal.sample(rng);
                let a = sigma * e;
                let v = comps[2 * axis + 1][i];
                comps[2 * axis][i] += dt * v + half_dt2 * a;
                comps[2 * axis + 1][i] = v + dt * a;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;

    #[test]
    fn rejects_bad_parameters() {
        let cv = ConstantVelocity::planar(0.3).unwrap();
        assert!(ManoeuvringVelocity::new(cv, 1.2, 2.0).is_err());
        assert!(ManoeuvringVelocity::new(cv, 0.1, -1.0).is_err());
        assert!(ManoeuvringVelocity::new(cv, 0.1, f64::INFINITY).is_err());
        assert!(ManoeuvringVelocity::new(cv, 0.1, 2.0).is_ok());
    }

    /// Velocity changes over one step have the mixture's variance T² ((1 − ε) σ² + ε σ_m²),
    /// and a heavier tail than a Gaussian of that variance: the share beyond 3 standard
    /// deviations of the calm component is about ε · P(|N| > 3σ/σ_m).
    #[test]
    fn velocity_changes_follow_the_mixture() {
        let cv = ConstantVelocity::planar(0.3).unwrap();
        let m = ManoeuvringVelocity::new(cv, 0.1, 3.0).unwrap();
        let n = 100_000;
        let mut p = ParticleSet::zeroed(4, n);
        let dt = 0.5;
        m.predict(&mut p, &StepContext::new(1, dt, dt), &mut seeded(3))
            .unwrap();
        let dv = p.component(1);
        let var = dv.iter().map(|v| v * v).sum::<f64>() / n as f64;
        let want = dt * dt * (0.9 * 0.09 + 0.1 * 9.0);
        // the heavy tail makes the sample variance noisy: its standard error is ≈ 0.004 here
        assert!((var - want).abs() < 0.08 * want, "{var} vs {want}");
        // beyond 3 calm sigmas (0.45 m/s): 0.9·0.0027 + 0.1·P(|N| > 0.3) = 0.0024 + 0.0764
        let tail = dv.iter().filter(|v| v.abs() > 3.0 * 0.3 * dt).count() as f64 / n as f64;
        assert!((tail - 0.0788).abs() < 0.004, "{tail}");
        // positions move by T²/2 · a, i.e. x = T/2 · Δv for a particle at rest
        for (x, v) in p.component(0).iter().zip(dv) {
            assert!((x - 0.5 * dt * v).abs() < 1e-12);
        }
    }

    /// With ε = 0 the model moves particles exactly as the calm constant-velocity model
    /// would in distribution: no manoeuvre ever adds spread.
    #[test]
    fn without_manoeuvres_the_spread_is_the_calm_one() {
        let cv = ConstantVelocity::planar(0.3).unwrap();
        let m = ManoeuvringVelocity::new(cv, 0.0, 3.0).unwrap();
        let n = 20_000;
        let mut p = ParticleSet::zeroed(4, n);
        m.predict(&mut p, &StepContext::new(1, 1.0, 1.0), &mut seeded(5))
            .unwrap();
        let max = p.component(3).iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(max < 0.3 * 5.0, "{max}");
        let var = p.component(3).iter().map(|v| v * v).sum::<f64>() / n as f64;
        assert!((var - 0.09).abs() < 0.006, "{var}");
    }
}
