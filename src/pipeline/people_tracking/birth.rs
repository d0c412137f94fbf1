//! Measurement-driven birth for the people tracker: a range-bearing measurement of the previous
//! scan that no track explained proposes a new person there, unless a confirmed track already
//! stands close by.
//!
//! Two differences from the normalised rule of Reuter et al. (2014, Sec. IV) that
//! [`crate::filter::AdaptiveBirth`] implements:
//!
//! * r_B(z) = min(r_max, λ_B · (1 − r_A(z))), *not* divided by the total unexplained mass
//!   Σ_ξ (1 − r_A(ξ)). The normalised rule hands out λ_B in total at every scan, so when all
//!   measurements are well explained their tiny remainders are scaled up to r_max and every
//!   person spawns a duplicate proposal at every scan.
//! * Suppression: a measurement within `suppress_radius` of a track whose existence is at
//!   least `suppress_existence` proposes nothing. A person whose outline the range noise
//!   breaks into two pieces yields one measurement the track takes and one it cannot; without
//!   suppression the second piece starts a duplicate that the next split confirms.
//!
//! The tracks to suppress around come with each step's frame, as [`ConfirmedPeople`] in its
//! step data; the measurements that may not propose at all, those the front end's classifier
//! doubts, come with the frame that holds them, as [`Doubted`] (births are proposed from the
//! previous step's measurements, and so read its data).
//! Not for: the filter's other birth models or deciding what a measurement is.

use crate::error::{ensure_positive, ensure_probability, Result};
use crate::filter::birth::BirthEvidence;
use crate::filter::StepContext;
use crate::filter::{BirthModel, BirthTrack, ParticleSet};
use crate::models::RangeBearing;
use crate::rng::FilterRng;
use rand_distr::{Distribution, StandardNormal};

/// The tracks around which [`PeopleBirth`] proposes nothing in a step: each track's world
/// position at the previous scan, its existence and its position spread σ (m). Tracks below
/// [`PeopleBirth::suppress_existence`] are ignored. Handed with the step
/// ([`crate::filter::Frame::data`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConfirmedPeople(pub Vec<ConfirmedPerson>);

/// One track of [`ConfirmedPeople`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConfirmedPerson {
    /// World position (x, y) at the previous scan.
    pub position: [f64; 2],
    /// Existence probability.
    pub existence: f64,
    /// Position spread σ (m).
    pub spread: f64,
}

/// Per measurement of the frame that brings it, whether it may not start a track (e.g. the
/// front end's classifier doubts it); indexed like that frame's measurements; missing or
/// shorter: the others may. Handed with the step ([`crate::filter::Frame::data`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Doubted(pub Vec<bool>);

/// Where the measurements of a frame with several lasers come from: one entry per laser that
/// reported, in the filter's sensor order, with the laser's world pose at its scan and how
/// many of the frame's measurements (all lasers' one after another, as the births see them)
/// are its own. With it [`PeopleBirth`] reads each measurement about its own laser (its sensor
/// model then has no mounting offset); without it, about the frame's platform. Handed with the
/// frame ([`crate::filter::Frame::data`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LaserOrigins(pub Vec<LaserOrigin>);

/// One laser of [`LaserOrigins`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LaserOrigin {
    /// The laser's index among the filter's sensors.
    pub laser: usize,
    /// Its world pose at its scan.
    pub pose: crate::geometry::Pose2,
    /// Its number of measurements in the frame.
    pub measurements: usize,
}

impl LaserOrigins {
    /// For each laser, the end (exclusive) of its measurements among the frame's and a
    /// context like `ctx` with the platform at the laser's pose.
    pub fn contexts(&self, ctx: &StepContext) -> Vec<(usize, StepContext)> {
        let mut end = 0;
        self.0
            .iter()
            .map(|o| {
                end += o.measurements;
                let mut c = ctx.clone();
                c.platform = Some(crate::geometry::platform_isometry(o.pose));
                (end, c)
            })
            .collect()
    }
}

/// Measurement-driven birth with suppression near confirmed tracks (module documentation).
#[derive(Clone, Debug)]
pub struct PeopleBirth {
    sensor: RangeBearing,
    /// λ_B: existence of a proposal from a wholly unexplained measurement, before the cap.
    pub expected_births: f64,
    /// r_max.
    pub max_existence: f64,
    /// Proposals below this existence are not made.
    pub min_existence: f64,
    /// Particles per proposal.
    pub particles: usize,
    /// Position spread (m) added to the measurement's own spread.
    pub position_std: f64,
    /// Velocity spread (m/s) per axis around zero.
    pub velocity_std: f64,
    /// No proposal within this distance (m) of a confirmed track.
    pub suppress_radius: f64,
    /// Tracks with at least this existence count as confirmed.
    pub suppress_existence: f64,
    /// … and no proposal within this many standard deviations of a confirmed track's
    /// position spread either (when larger than `suppress_radius`): a track that coasted
    /// unseen has spread out, and the person it lost is still most likely its own.
    pub suppress_spread: f64,
    /// Births carry a fifth state component, the detectability mode
    /// ([`super::models::detectability`]), set to detectable (the person was just detected).
    pub with_detectability: bool,
}

impl PeopleBirth {
    /// Birth for measurements of `sensor` (noise, mount offset, bearing convention).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        sensor: RangeBearing,
        expected_births: f64,
        max_existence: f64,
        particles: usize,
        position_std: f64,
        velocity_std: f64,
        suppress_radius: f64,
    ) -> Result<Self> {
        ensure_positive("expected births", expected_births)?;
        ensure_probability("maximum birth existence", max_existence)?;
        ensure_positive("birth particle count", particles as f64)?;
        crate::error::ensure_finite(
            "birth spreads",
            &[position_std, velocity_std, suppress_radius],
        )?;
        Ok(PeopleBirth {
            sensor,
            expected_births,
            max_existence,
            min_existence: 1e-3,
            particles,
            position_std: position_std.abs(),
            velocity_std: velocity_std.abs(),
            suppress_radius: suppress_radius.max(0.0),
            suppress_existence: 0.5,
            suppress_spread: 0.0,
            with_detectability: false,
        })
    }

    /// The step's confirmed tracks (at least `suppress_existence`), each with the squared
    /// radius max(`suppress_radius`, `suppress_spread` · σ)² around it in which no birth is
    /// proposed.
    fn suppressors(&self, ctx: &StepContext) -> Vec<([f64; 2], f64)> {
        let Some(people) = ctx.data.get::<ConfirmedPeople>() else {
            return Vec::new();
        };
        let k = self.suppress_spread;
        people
            .0
            .iter()
            .filter(|p| p.existence >= self.suppress_existence)
            .map(|p| (p.position, self.suppress_radius.max(k * p.spread).powi(2)))
            .collect()
    }

    /// r_B for an association probability `assigned` (before suppression).
    pub fn existence(&self, assigned: f64) -> f64 {
        (self.expected_births * (1.0 - assigned.clamp(0.0, 1.0))).min(self.max_existence)
    }

    fn sample(&self, z: [f64; 2], ctx: &StepContext, rng: &mut FilterRng) -> ParticleSet {
        let centre = self.sensor.to_cartesian(z, ctx);
        let (p, v) = (self.position_std, self.velocity_std);
        let mean = [centre[0], 0.0, centre[1], 0.0, 1.0];
        let std = [p, v, p, v, 0.0];
        let dim = if self.with_detectability { 5 } else { 4 };
        let mut set = ParticleSet::sampled(&mean[..dim], &std[..dim], self.particles, rng);
        let (sr, sb) = self.sensor.noise();
        let mut comps = set.components_mut().into_iter();
        let (x, _, y) = (
            comps.next().expect("x"),
            comps.next(),
            comps.next().expect("y"),
        );
        for (xi, yi) in x.iter_mut().zip(y.iter_mut()) {
            let er: f64 = StandardNormal.sample(rng);
            let eb: f64 = StandardNormal.sample(rng);
            let p = self
                .sensor
                .to_cartesian([z[0] + sr * er, z[1] + sb * eb], ctx);
            *xi += p[0] - centre[0];
            *yi += p[1] - centre[1];
        }
        set
    }
}

impl BirthModel for PeopleBirth {
    fn birth(
        &self,
        ctx: &StepContext,
        evidence: Option<&BirthEvidence<'_>>,
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack> {
        let Some(ev) = evidence else {
            return Vec::new();
        };
        let confirmed = self.suppressors(ctx);
        // the doubts came with the measurements' own frame
        let barren = ev
            .context
            .data
            .get::<Doubted>()
            .map_or(&[][..], |d| &d.0[..]);
        // with several lasers each measurement about its own laser
        let origins = ev
            .context
            .data
            .get::<LaserOrigins>()
            .map(|o| o.contexts(ev.context));
        let context_of = |j: usize| match &origins {
            Some(o) => o
                .iter()
                .find(|(end, _)| j < *end)
                .map_or(ev.context, |(_, c)| c),
            None => ev.context,
        };
        ev.measurements
            .iter()
            .zip(ev.assigned)
            .enumerate()
            .filter_map(|(j, (z, &a))| {
                let r = self.existence(a);
                if r < self.min_existence || z.len() < 2 || barren.get(j) == Some(&true) {
                    return None;
                }
                let zz = [z[0], z[1]];
                let at = context_of(j);
                let p = self.sensor.to_cartesian(zz, at);
                let near = confirmed.iter().any(|(c, r2)| {
                    let (dx, dy) = (c[0] - p[0], c[1] - p[1]);
                    dx * dx + dy * dy < *r2
                });
                (!near).then(|| BirthTrack {
                    existence: r,
                    particles: self.sample(zz, at, rng),
                    at_previous_step: true,
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::Measurements;
    use crate::filter::StepData;
    use crate::rng::seeded;

    /// A step context whose frame brings `people` as (position, existence, spread).
    fn confirmed(people: &[([f64; 2], f64, f64)]) -> StepContext {
        let people = people
            .iter()
            .map(|&(position, existence, spread)| ConfirmedPerson {
                position,
                existence,
                spread,
            })
            .collect();
        StepContext::new(1, 0.1, 0.1).with_data(StepData::new().with(ConfirmedPeople(people)))
    }

    fn birth() -> PeopleBirth {
        let rb = RangeBearing::new(0.1, 0.01).unwrap();
        PeopleBirth::new(rb, 0.2, 0.2, 400, 0.1, 0.5, 1.0).unwrap()
    }

    #[test]
    fn existence_is_not_normalised() {
        let b = birth();
        // well explained measurements stay near zero whatever the others do
        assert!((b.existence(0.99) - 0.002).abs() < 1e-12);
        assert!((b.existence(0.0) - 0.2).abs() < 1e-12);
        assert!((b.existence(0.5) - 0.1).abs() < 1e-12);
    }

    /// A track that has spread out (σ = 1 m after coasting) suppresses proposals within
    /// 2 σ of it, a tight one only within the fixed radius.
    #[test]
    fn spread_out_tracks_suppress_farther() {
        let mut b = birth();
        b.suppress_spread = 2.0;
        let ctx = StepContext::new(0, 0.0, 0.1);
        let m = Measurements::from_rows(2, &[[5.0, 0.0]]).unwrap();
        let ev = BirthEvidence {
            measurements: &m,
            assigned: &[0.0],
            context: &ctx,
        };
        // the track stands 1.5 m from the measurement's (5, 0)
        let tight = confirmed(&[([6.5, 0.0], 0.9, 0.1)]);
        assert_eq!(b.birth(&tight, Some(&ev), &mut seeded(1)).len(), 1);
        let spread = confirmed(&[([6.5, 0.0], 0.9, 1.0)]);
        assert!(b.birth(&spread, Some(&ev), &mut seeded(1)).is_empty());
        // without the spread rule only the fixed radius counts
        b.suppress_spread = 0.0;
        assert_eq!(b.birth(&spread, Some(&ev), &mut seeded(1)).len(), 1);
    }

    #[test]
    fn proposals_sit_at_the_measurement_and_avoid_confirmed_tracks() {
        let b = birth();
        let ctx = StepContext::new(0, 0.0, 0.1);
        // (range 5, bearing 0) → (5, 0); (range 4, bearing π/2) → (0, 4)
        let m =
            Measurements::from_rows(2, &[[5.0, 0.0], [4.0, std::f64::consts::FRAC_PI_2]]).unwrap();
        let ev = BirthEvidence {
            measurements: &m,
            assigned: &[0.0, 0.0],
            context: &ctx,
        };
        let all = b.birth(&ctx, Some(&ev), &mut seeded(1));
        assert_eq!(all.len(), 2);
        let mean = all[0].particles.mean();
        assert!(
            (mean[0] - 5.0).abs() < 0.05 && mean[2].abs() < 0.05,
            "{mean:?}"
        );
        // a confirmed track 0.5 m from (0, 4) suppresses that proposal; a weak one does not
        let now = confirmed(&[([0.3, 4.4], 0.9, 0.0), ([5.0, 0.2], 0.1, 0.0)]);
        let some = b.birth(&now, Some(&ev), &mut seeded(1));
        assert_eq!(some.len(), 1);
        assert!((some[0].particles.mean()[0] - 5.0).abs() < 0.05);
        // a doubted measurement proposes nothing: the doubts come with the measurements'
        // frame (the evidence's context), not with the step that proposes
        let doubted = ctx
            .clone()
            .with_data(StepData::new().with(Doubted(vec![true, false])));
        let ev_doubted = BirthEvidence {
            context: &doubted,
            ..ev
        };
        let one = b.birth(&ctx, Some(&ev_doubted), &mut seeded(1));
        assert_eq!(one.len(), 1);
        assert!(
            one[0].particles.mean()[2] > 3.9,
            "{:?}",
            one[0].particles.mean()
        );
        assert_eq!(b.birth(&doubted, Some(&ev), &mut seeded(1)).len(), 2);
        let none = ctx.clone().with_data(StepData::new().with(Doubted(vec![])));
        let ev_none = BirthEvidence {
            context: &none,
            ..ev
        };
        assert_eq!(b.birth(&ctx, Some(&ev_none), &mut seeded(1)).len(), 2);
    }
}
