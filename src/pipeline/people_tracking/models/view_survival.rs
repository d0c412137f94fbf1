//! Survival that depends on whether an object is inside a sensor's field of view: objects the
//! sensor can see keep a high p_S, objects that left the sector (behind a moving robot, beyond
//! its range) are forgotten at a faster rate, since no measurement will ever confirm them.
//!
//! Not for: occlusion inside the field of view (an occluded object is still there; see
//! [`super::occlusion`] for its detection probability).

use crate::error::{ensure_probability, Result};
use crate::filter::ParticleSet;
use crate::filter::{StepContext, SurvivalModel};
use crate::models::cloud_bounds::CloudBox;
use crate::models::detection::FieldOfViewDetection;

/// p_S(x) = `inside` when x lies in the sector of `fov` at the step, `outside` elsewhere
/// (the sector's own detection probabilities are not used).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct FieldOfViewSurvival {
    fov: FieldOfViewDetection,
    inside: f64,
    outside: f64,
}

impl FieldOfViewSurvival {
    /// Survival `inside` / `outside` the sector of `fov`, both in [0, 1].
    pub fn new(fov: FieldOfViewDetection, inside: f64, outside: f64) -> Result<Self> {
        ensure_probability("survival inside the field of view", inside)?;
        ensure_probability("survival outside the field of view", outside)?;
        Ok(FieldOfViewSurvival {
            fov,
            inside,
            outside,
        })
    }
}

impl SurvivalModel for FieldOfViewSurvival {
    fn survival_probability(&self, particles: &ParticleSet, ctx: &StepContext, out: &mut [f64]) {
        if particles.dim() < 3 {
            out.fill(self.outside);
            return;
        }
        let (sx, sy, c, s) = self.fov.sensor(ctx);
        let bounds = CloudBox::of(particles).and_then(|b| b.polar_from(sx, sy, c, s));
        if bounds.is_some_and(|b| self.fov.surely_contains(&b)) {
            out.fill(self.inside);
            return;
        }
        let xs = particles.component(0);
        let ys = particles.component(2);
        for ((o, &x), &y) in out.iter_mut().zip(xs).zip(ys) {
            *o = if self.fov.contains_from(x, y, sx, sy, c, s) {
                self.inside
            } else {
                self.outside
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn inside_and_outside_the_sector() {
        let fov = FieldOfViewDetection::new(0.9, 0.0, 10.0, FRAC_PI_2).unwrap();
        let m = FieldOfViewSurvival::new(fov, 0.99, 0.7).unwrap();
        let rows = vec![
            vec![5.0, 0.0, 0.0, 0.0],  // ahead
            vec![-5.0, 0.0, 0.0, 0.0], // behind
            vec![20.0, 0.0, 0.0, 0.0], // too far
        ];
        let set = ParticleSet::from_rows(&rows, &[1.0; 3]).unwrap();
        let mut out = vec![0.0; 3];
        m.survival_probability(&set, &StepContext::new(1, 0.1, 0.1), &mut out);
        assert_eq!(out, vec![0.99, 0.7, 0.7]);
        assert!(FieldOfViewSurvival::new(fov, 1.2, 0.7).is_err());
    }

    proptest::proptest! {
        /// A cloud found wholly inside the sector gets the same p_S as particle by particle:
        /// clouds near the sector's edges (range 10 m, ±60°), from a moved and turned platform.
        #[test]
        fn whole_cloud_answer_matches_each_particle(
            centre in (0.5f64..11.0, -1.3f64..1.3),
            spread in 0.001f64..1.0,
            offsets in proptest::collection::vec((-1.0f64..1.0, -1.0f64..1.0), 1..40),
            pose in (-1.0f64..1.0, -1.0f64..1.0, -0.3f64..0.3),
        ) {
            let fov = FieldOfViewDetection::new(0.9, 0.0, 10.0, 60f64.to_radians()).unwrap();
            let m = FieldOfViewSurvival::new(fov, 0.99, 0.7).unwrap();
            let mut ctx = StepContext::new(1, 0.1, 0.1);
            ctx.platform = Some(nalgebra::Isometry3::new(
                nalgebra::Vector3::new(pose.0, pose.1, 0.0),
                nalgebra::Vector3::new(0.0, 0.0, pose.2),
            ));
            let (c0, s0) = (pose.2.cos(), pose.2.sin());
            let (lx, ly) = (centre.0 * centre.1.cos(), centre.0 * centre.1.sin());
            let (cx, cy) = (pose.0 + c0 * lx - s0 * ly, pose.1 + s0 * lx + c0 * ly);
            let rows: Vec<Vec<f64>> = offsets
                .iter()
                .map(|o| vec![cx + spread * o.0, 0.0, cy + spread * o.1, 0.0])
                .collect();
            let set = ParticleSet::from_rows(&rows, &vec![1.0; rows.len()]).unwrap();
            let mut out = vec![0.0; rows.len()];
            m.survival_probability(&set, &ctx, &mut out);
            let (sx, sy, c, s) = fov.sensor(&ctx);
            for (row, o) in rows.iter().zip(&out) {
                let want = if fov.contains_from(row[0], row[2], sx, sy, c, s) { 0.99 } else { 0.7 };
                proptest::prop_assert_eq!(*o, want);
            }
        }
    }
}
