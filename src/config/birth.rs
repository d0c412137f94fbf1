//! The samplers and birth wrappers the configured birth models use: particles around a
//! measured point for adaptive birth ([`MeasurementBirth`]), and static birth guided by
//! range-bearing measurements converted to world points ([`RangeBearingGuidedBirth`]). Not
//! for: the configuration data itself (see the parent module).

use crate::filter::birth::{BirthEvidence, CurrentMeasurements};
use crate::filter::{BirthModel, BirthTrack, Measurements, ParticleSet, StaticBirth, StepContext};
use crate::models::RangeBearing;
use crate::rng::FilterRng;
use rand_distr::{Distribution, StandardNormal};

/// Static birth guided by range-bearing measurements: each measurement converted to the world
/// point it reads (with the frame's sensor pose), spread per axis as the measurement's
/// along-range and cross-range noise (σ_r, r·σ_b) rotated into x and y (the diagonal of that
/// covariance; the proposal stays unbiased whatever the spread, see
/// [`crate::filter::BirthProposal::sample_points`]).
pub(super) struct RangeBearingGuidedBirth {
    pub(super) birth: StaticBirth,
    pub(super) sensor: RangeBearing,
}

impl RangeBearingGuidedBirth {
    /// World points and their per-axis spreads for the measurements `z`; `None` when a
    /// conversion is not finite.
    fn points(&self, z: &Measurements, ctx: &StepContext) -> Option<(Measurements, Vec<f64>)> {
        let (sr, sb) = self.sensor.noise();
        let (sx, sy, _) = ctx.platform_xy_heading();
        let mut rows = Vec::with_capacity(z.len());
        let mut noise = Vec::with_capacity(2 * z.len());
        for zj in z.iter() {
            let p = self.sensor.to_cartesian([zj[0], zj[1]], ctx);
            // Direction of the line of sight, from the platform to the point (close enough
            // to the sensor's for the spread's orientation).
            let theta = (p[1] - sy).atan2(p[0] - sx);
            let (s, c) = theta.sin_cos();
            let cross = zj[0].abs() * sb;
            noise.push((sr * sr * c * c + cross * cross * s * s).sqrt());
            noise.push((sr * sr * s * s + cross * cross * c * c).sqrt());
            rows.push(p);
        }
        let points = Measurements::from_rows(2, &rows).ok()?;
        noise
            .iter()
            .all(|v| v.is_finite())
            .then_some((points, noise))
    }
}

impl BirthModel for RangeBearingGuidedBirth {
    fn birth(
        &self,
        ctx: &StepContext,
        evidence: Option<&BirthEvidence<'_>>,
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack> {
        self.birth.birth(ctx, evidence, rng)
    }

    fn uses_current_measurements(&self) -> bool {
        true
    }

    fn birth_guided(
        &self,
        ctx: &StepContext,
        evidence: Option<&BirthEvidence<'_>>,
        current: &CurrentMeasurements<'_>,
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack> {
        if current.measurements.dim() != 2 {
            return self.birth.birth(ctx, evidence, rng);
        }
        match self.points(current.measurements, ctx) {
            Some((points, noise)) => {
                self.birth
                    .birth_near_points(&points, &noise, current.unexplained, rng)
            }
            None => self.birth.birth(ctx, evidence, rng),
        }
    }
}

/// Birth particles around a measured point: position from the measurement (converted from
/// range-bearing with the frame's sensor pose) plus Gaussian spread, velocity and turn rate
/// around zero.
pub(super) struct MeasurementBirth {
    pub(super) range_bearing: Option<RangeBearing>,
    pub(super) axes: usize,
    pub(super) turn_rate: bool,
    pub(super) position_std: f64,
    pub(super) velocity_std: f64,
    pub(super) turn_rate_std: f64,
}

impl crate::filter::BirthSampler for MeasurementBirth {
    fn sample(&self, z: &[f64], ctx: &StepContext, n: usize, rng: &mut FilterRng) -> ParticleSet {
        let position: Vec<f64> = match &self.range_bearing {
            Some(rb) => rb.to_cartesian([z[0], z[1]], ctx).to_vec(),
            None => z[..self.axes].to_vec(),
        };
        let mut mean: Vec<f64> = position.iter().flat_map(|&p| [p, 0.0]).collect();
        let mut std: Vec<f64> = position
            .iter()
            .flat_map(|_| [self.position_std, self.velocity_std])
            .collect();
        if self.turn_rate {
            mean.push(0.0);
            std.push(self.turn_rate_std);
        }
        let mut set = ParticleSet::sampled(&mean, &std, n, rng);
        if let Some(rb) = &self.range_bearing {
            // Spread along the measurement's own uncertainty as well: perturb each particle's
            // range and bearing and convert again.
            let (sr, sb) = rb.noise();
            let comps = set.components_mut();
            let mut it = comps.into_iter();
            let (x, _, y) = (it.next().unwrap(), it.next().unwrap(), it.next().unwrap());
            for (xi, yi) in x.iter_mut().zip(y.iter_mut()) {
                let er: f64 = StandardNormal.sample(rng);
                let eb: f64 = StandardNormal.sample(rng);
                let p = rb.to_cartesian([z[0] + sr * er, z[1] + sb * eb], ctx);
                *xi += p[0] - position[0];
                *yi += p[1] - position[1];
            }
        }
        set
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::{BirthProposal, BirthTerm};

    #[test]
    fn range_bearing_static_birth_is_guided_to_the_world_point() {
        // Sensor at the origin facing +x; z = (100 m, 90°) reads the point (0, 100). Along the
        // line of sight (y) the spread is σ_r = 1 m, across it (x) r·σ_b = 100 · 0.05 = 5 m.
        let rb = RangeBearing::new(1.0, 0.05).unwrap();
        let term = BirthTerm {
            existence: 0.01,
            mean: vec![0.0; 4],
            std: vec![200.0, 10.0, 200.0, 10.0],
        };
        let proposal = BirthProposal::new(vec![0, 2], vec![1.0, 1.0]).unwrap();
        let guided = RangeBearingGuidedBirth {
            birth: StaticBirth::new(vec![term], 2000)
                .unwrap()
                .with_proposal(proposal)
                .unwrap(),
            sensor: rb,
        };
        let ctx = StepContext::new(1, 1.0, 1.0);
        let z = Measurements::from_rows(2, &[[100.0, std::f64::consts::FRAC_PI_2]]).unwrap();
        let (points, noise) = guided.points(&z, &ctx).unwrap();
        let p = points.get(0);
        assert!(p[0].abs() < 1e-9 && (p[1] - 100.0).abs() < 1e-9, "{p:?}");
        assert!((noise[0] - 5.0).abs() < 1e-9 && (noise[1] - 1.0).abs() < 1e-9);
        let current = CurrentMeasurements {
            measurements: &z,
            unexplained: &[1.0],
        };
        let b = guided.birth_guided(&ctx, None, &current, &mut crate::rng::seeded(1));
        let set = &b[0].particles;
        let near = set
            .component(0)
            .iter()
            .zip(set.component(2))
            .filter(|(x, y)| x.hypot(*y - 100.0) < 15.0)
            .count();
        // The prior puts ≈ 0.3 % of its particles within 15 m of the point.
        assert!(near > 1000, "{near} of 2000 near the point");
        assert!(set.weights().windows(2).any(|w| w[0] != w[1]));
    }

    #[test]
    fn range_bearing_birth_lands_on_the_measured_point() {
        let rb = RangeBearing::new(1.0, 0.01).unwrap();
        let s = MeasurementBirth {
            range_bearing: Some(rb),
            axes: 2,
            turn_rate: true,
            position_std: 0.1,
            velocity_std: 1.0,
            turn_rate_std: 0.1,
        };
        let mut ctx = StepContext::new(0, 0.0, 1.0);
        ctx.platform = Some(nalgebra::Isometry3::translation(10.0, 0.0, 0.0));
        use crate::filter::BirthSampler;
        let p = s.sample(
            &[5.0, std::f64::consts::FRAC_PI_2],
            &ctx,
            4000,
            &mut crate::rng::seeded(2),
        );
        let m = p.mean();
        assert_eq!(p.dim(), 5);
        // sensor at (10, 0) facing +x, bearing 90° → point (10, 5)
        assert!(
            (m[0] - 10.0).abs() < 0.1 && (m[2] - 5.0).abs() < 0.1,
            "{m:?}"
        );
    }
}
