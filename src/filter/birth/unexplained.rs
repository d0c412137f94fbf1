//! Which of a step's measurements the existing tracks leave unexplained, judged before the
//! association (the birth of a step is drawn before its update): for measurement `z`,
//! `u(z) = Π (1 − r)` over the predicted tracks whose gate admits `z` — the probability that
//! none of the tracks that could have produced it exists. A cheap guide for where to put birth
//! particles, never a probability the update uses. Not for: association (see
//! [`crate::filter::association`]).

use crate::filter::{MeasurementModel, Measurements, StepContext, Track, TrackSummary};
use rayon::prelude::*;

/// `u(z)` of every measurement of `z` given the predicted `tracks` (in measurement order),
/// whose gate summaries are `summaries` (one per track, in track order; see
/// [`TrackSummary::of`]). Tracks are gated in parallel and combined in track order, so the
/// result does not depend on the thread count.
pub fn unexplained(
    tracks: &[Track],
    summaries: &[TrackSummary],
    z: &Measurements,
    model: &dyn MeasurementModel,
    ctx: &StepContext,
) -> Vec<f64> {
    let mut u = vec![1.0; z.len()];
    if z.is_empty() {
        return u;
    }
    debug_assert_eq!(tracks.len(), summaries.len());
    let gated: Vec<Vec<usize>> = tracks
        .par_iter()
        .zip(summaries)
        .map(|(t, s)| {
            let mut out = Vec::new();
            if t.existence > 0.0 && !t.particles.is_empty() {
                model.gate_all(z, s, ctx, &mut out);
            }
            out
        })
        .collect();
    for (t, g) in tracks.iter().zip(&gated) {
        let keep = 1.0 - t.existence.clamp(0.0, 1.0);
        for &j in g {
            u[j] *= keep;
        }
    }
    u
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::{Label, ParticleSet};

    /// Admits z when it lies within 5 of the track's mean position (components 0, 2) per axis.
    struct BoxGate;
    impl MeasurementModel for BoxGate {
        fn measurement_dim(&self) -> usize {
            2
        }
        fn log_likelihood(&self, _: &[f64], _: &ParticleSet, _: &StepContext, out: &mut [f64]) {
            out.fill(0.0);
        }
        fn gate(&self, z: &[f64], t: &TrackSummary, _: &StepContext) -> bool {
            (z[0] - t.mean[0]).abs() <= 5.0 && (z[1] - t.mean[2]).abs() <= 5.0
        }
    }

    #[test]
    fn products_of_one_minus_existence_over_the_gating_tracks() {
        // Three point-mass tracks at x = 0, 100 and 2.
        let at = |x: f64| ParticleSet::from_rows(&[vec![x, 0.0, 0.0, 0.0]], &[1.0]).unwrap();
        let tracks = vec![
            Track::new(Label::new(0, 0), 0.9, at(0.0)),
            Track::new(Label::new(0, 1), 0.5, at(100.0)),
            Track::new(Label::new(0, 2), 0.4, at(2.0)),
        ];
        let z = Measurements::from_rows(2, &[[1.0, 1.0], [99.0, 0.0], [50.0, 0.0]]).unwrap();
        let summaries: Vec<_> = tracks
            .iter()
            .map(|t| TrackSummary::of(&t.particles))
            .collect();
        let u = unexplained(
            &tracks,
            &summaries,
            &z,
            &BoxGate,
            &StepContext::new(1, 1.0, 1.0),
        );
        // z0: tracks 0 and 2 → 0.1 · 0.6; z1: track 1 → 0.5; z2: none → 1.
        assert!((u[0] - 0.06).abs() < 1e-12, "{u:?}");
        assert!((u[1] - 0.5).abs() < 1e-12, "{u:?}");
        assert_eq!(u[2], 1.0);
    }
}
