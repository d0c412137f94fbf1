//! Point-to-point iterative closest point (ICP) for planar scans: the rigid motion that best
//! lays a *source* point set onto a *target* point set, as used by seed 003 (Sec. II-B,
//! step 2) to correct the odometry between two scans.
//!
//! Each iteration moves the source by the current estimate, pairs every moved point with its
//! nearest target point (an exact grid search, [`PlanarGrid`]), drops pairs farther apart than
//! [`IcpConfig::max_pair_distance`] and — in the second phase, which starts once the first
//! has converged — also those farther than [`IcpConfig::residual_factor`] times the median
//! pair distance (but never below [`IcpConfig::min_gate`]), and solves the least-squares rigid step in closed form: with the
//! centroids `s̄`, `t̄` of the paired points and the cross terms
//! `Sxx = Σ sx·tx`, `Sxy = Σ sx·ty`, `Syx = Σ sy·tx`, `Syy = Σ sy·ty` of the centred pairs,
//! the rotation is `θ = atan2(Sxy − Syx, Sxx + Syy)` and the translation `t̄ − R(θ)·s̄`
//! (the 2-D case of the SVD solution). It stops when a step of the second phase moves less
//! than both tolerances or after [`IcpConfig::max_iterations`]. (The median gate alone would
//! throw away the informative pairs while the offset is still larger than the gate.)
//!
//! Not for: choosing which scans to match (the moving-object detector does that), global
//! registration from a poor initial guess, or point-to-line refinement.

use super::nearest::PlanarGrid;
use crate::error::{Error, Result};
use crate::geometry::pose2::{compose, transform_point};
use crate::geometry::Pose2;
use crate::numerics::sym2::symmetric2_eigenvalues;

/// ICP parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IcpConfig {
    /// Most iterations (both phases together). Default 50.
    pub max_iterations: usize,
    /// Pairs farther apart than this are never used (m). Default 1.0 m.
    pub max_pair_distance: f64,
    /// Pairs farther apart than this many median pair distances are dropped. Default 3.
    pub residual_factor: f64,
    /// The median-based gate never drops pairs closer than this (m). Default 0.1 m.
    pub min_gate: f64,
    /// Convergence: a step shorter than this (m) ... Default 1e-5 m.
    pub tolerance_translation: f64,
    /// ... and turning less than this (rad) ends the iterations. Default 1e-6 rad.
    pub tolerance_rotation: f64,
    /// Fewer kept pairs than this is a failed fit. Default 10.
    pub min_pairs: usize,
}

impl Default for IcpConfig {
    fn default() -> Self {
        IcpConfig {
            max_iterations: 50,
            max_pair_distance: 1.0,
            residual_factor: 3.0,
            min_gate: 0.1,
            tolerance_translation: 1e-5,
            tolerance_rotation: 1e-6,
            min_pairs: 10,
        }
    }
}

impl IcpConfig {
    /// Checks that every distance and tolerance is positive and finite and that at least one
    /// iteration and three pairs are asked for.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("IcpConfig::max_pair_distance", self.max_pair_distance),
            ("IcpConfig::residual_factor", self.residual_factor),
            ("IcpConfig::min_gate", self.min_gate),
            (
                "IcpConfig::tolerance_translation",
                self.tolerance_translation,
            ),
            ("IcpConfig::tolerance_rotation", self.tolerance_rotation),
        ] {
            crate::error::ensure_positive(name, v)?;
        }
        if self.max_iterations == 0 {
            return Err(Error::invalid(
                "IcpConfig::max_iterations",
                "0 (need at least 1)",
            ));
        }
        if self.min_pairs < 3 {
            return Err(Error::invalid(
                "IcpConfig::min_pairs",
                format!("{} (need at least 3)", self.min_pairs),
            ));
        }
        Ok(())
    }
}

/// [`IcpFit::information_ratio`] looks at every this many'th pair.
const INFORMATION_STRIDE: usize = 4;

/// The outcome of one alignment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IcpFit {
    /// The motion mapping source points into the target frame.
    pub transform: Pose2,
    /// Iterations run.
    pub iterations: usize,
    /// True when the last step was below both tolerances.
    pub converged: bool,
    /// Pairs kept in the last iteration.
    pub pairs: usize,
    /// Fraction of source points kept as pairs in the last iteration.
    pub inlier_fraction: f64,
    /// Root mean square distance of the kept pairs after the last step (m).
    pub rms: f64,
    /// How well the last pairs pin the translation down in every direction: the smaller over
    /// the larger eigenvalue of Σ n nᵀ over every fourth pair, n the normal of the paired
    /// target point's line
    /// ([`PlanarGrid::line_normal`]; pairs at corners and blobs add nothing). About 0 in a
    /// corridor (every line parallel: sliding along it costs nothing), up to 1 in a room.
    pub information_ratio: f64,
    /// Share of the last pairs whose target point has a line normal: where it is small (a
    /// sparse or cluttered map) `information_ratio` says little.
    pub line_share: f64,
}

/// A reusable aligner: holds the target's search grid and scratch buffers, so that repeated
/// alignments against one target allocate nothing but the grid.
pub struct Icp {
    config: IcpConfig,
    target: Vec<[f64; 2]>,
    grid: Option<PlanarGrid>,
    pairs: Vec<(usize, usize, f64)>,
    distances: Vec<f64>,
    /// Each source point's nearest target point in the last iteration, or `usize::MAX`.
    hints: Vec<usize>,
}

impl std::fmt::Debug for Icp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Icp")
            .field("config", &self.config)
            .field("target_points", &self.target.len())
            .finish()
    }
}

impl Icp {
    /// An aligner without a target; checks the configuration.
    pub fn new(config: IcpConfig) -> Result<Self> {
        config.validate()?;
        Ok(Icp {
            config,
            target: Vec::new(),
            grid: None,
            pairs: Vec::new(),
            distances: Vec::new(),
            hints: Vec::new(),
        })
    }

    /// The configuration.
    pub fn config(&self) -> &IcpConfig {
        &self.config
    }

    /// Number of target points.
    pub fn target_len(&self) -> usize {
        self.target.len()
    }

    /// Replaces the target point set; every coordinate must be finite.
    pub fn set_target(&mut self, points: &[[f64; 2]]) -> Result<()> {
        if let Some(p) = points
            .iter()
            .find(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(Error::invalid(
                "ICP target",
                format!("point {p:?} is not finite"),
            ));
        }
        self.target.clear();
        self.target.extend_from_slice(points);
        // Cells of half the pairing distance: a pair is found within the first rings.
        self.grid = PlanarGrid::new(points, 0.5 * self.config.max_pair_distance);
        Ok(())
    }

    /// Distance from `p` to the nearest target point, `None` without a target.
    pub fn nearest_target_distance(&self, p: [f64; 2]) -> Option<f64> {
        let grid = self.grid.as_ref()?;
        grid.nearest(p, f64::INFINITY).map(|(_, d2)| d2.sqrt())
    }

    /// Aligns `source` to the current target starting from `initial`. Errors when the
    /// target is empty, a source point is not finite, or fewer than
    /// [`IcpConfig::min_pairs`] pairs survive the gates.
    pub fn align(&mut self, source: &[[f64; 2]], initial: Pose2) -> Result<IcpFit> {
        if self.grid.is_none() {
            return Err(Error::invalid("ICP target", "empty"));
        }
        if !initial.is_finite() {
            return Err(Error::invalid(
                "ICP initial pose",
                format!("{initial:?} is not finite"),
            ));
        }
        if let Some(p) = source
            .iter()
            .find(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(Error::invalid(
                "ICP source",
                format!("point {p:?} is not finite"),
            ));
        }
        let c = self.config;
        let max_d2 = c.max_pair_distance * c.max_pair_distance;
        let mut transform = initial;
        let mut fit = IcpFit {
            transform,
            iterations: 0,
            converged: false,
            pairs: 0,
            inlier_fraction: 0.0,
            rms: f64::INFINITY,
            information_ratio: 0.0,
            line_share: 0.0,
        };
        let mut tight = false;
        self.hints.clear();
        self.hints.resize(source.len(), usize::MAX);
        for iteration in 1..=c.max_iterations {
            // Pair every moved source point with its nearest target point.
            self.pairs.clear();
            self.distances.clear();
            for (i, &p) in source.iter().enumerate() {
                let q = transform_point(transform, p);
                // The last iteration's partner is a near bound: few cells are searched.
                let found = match self.grid.as_mut() {
                    Some(grid) => grid.nearest_from(q, max_d2, self.hints[i]),
                    None => None,
                };
                self.hints[i] = found.map_or(usize::MAX, |(j, _)| j);
                if let Some((j, d2)) = found {
                    let d = d2.sqrt();
                    self.pairs.push((i, j, d));
                    self.distances.push(d);
                }
            }
            if self.pairs.len() < c.min_pairs {
                return Err(Error::invalid(
                    "ICP",
                    format!(
                        "only {} pairs within {} m (need {})",
                        self.pairs.len(),
                        c.max_pair_distance,
                        c.min_pairs
                    ),
                ));
            }
            // Median-based outlier gate, once the distance gate alone has converged.
            let mid = self.distances.len() / 2;
            let (_, median, _) = self.distances.select_nth_unstable_by(mid, f64::total_cmp);
            let gate = if tight {
                (c.residual_factor * *median).max(c.min_gate)
            } else {
                c.max_pair_distance
            };
            self.pairs.retain(|&(_, _, d)| d <= gate);
            if self.pairs.len() < c.min_pairs {
                return Err(Error::invalid(
                    "ICP",
                    format!(
                        "only {} pairs within the median gate {gate} m (need {})",
                        self.pairs.len(),
                        c.min_pairs
                    ),
                ));
            }
            // Closed-form rigid step on the moved source.
            let n = self.pairs.len() as f64;
            let (mut sx, mut sy, mut tx, mut ty) = (0.0, 0.0, 0.0, 0.0);
            for &(i, j, _) in &self.pairs {
                let q = transform_point(transform, source[i]);
                sx += q[0];
                sy += q[1];
                tx += self.target[j][0];
                ty += self.target[j][1];
            }
            let (sx, sy, tx, ty) = (sx / n, sy / n, tx / n, ty / n);
            let (mut sxx, mut sxy, mut syx, mut syy) = (0.0, 0.0, 0.0, 0.0);
            for &(i, j, _) in &self.pairs {
                let q = transform_point(transform, source[i]);
                let (ax, ay) = (q[0] - sx, q[1] - sy);
                let (bx, by) = (self.target[j][0] - tx, self.target[j][1] - ty);
                sxx += ax * bx;
                sxy += ax * by;
                syx += ay * bx;
                syy += ay * by;
            }
            let theta = (sxy - syx).atan2(sxx + syy);
            let (s, co) = theta.sin_cos();
            let step = Pose2::new(tx - (co * sx - s * sy), ty - (s * sx + co * sy), theta);
            transform = compose(step, transform);
            let rms = (self
                .pairs
                .iter()
                .map(|&(i, j, _)| {
                    let q = transform_point(transform, source[i]);
                    let (dx, dy) = (q[0] - self.target[j][0], q[1] - self.target[j][1]);
                    dx * dx + dy * dy
                })
                .sum::<f64>()
                / n)
                .sqrt();
            let converged = step.x.hypot(step.y) < c.tolerance_translation
                && step.theta.abs() < c.tolerance_rotation;
            fit = IcpFit {
                transform,
                iterations: iteration,
                converged,
                pairs: self.pairs.len(),
                inlier_fraction: self.pairs.len() as f64 / source.len() as f64,
                rms,
                information_ratio: 0.0,
                line_share: 0.0,
            };
            if converged {
                if tight {
                    break;
                }
                tight = true;
                fit.converged = false;
            }
        }
        (fit.information_ratio, fit.line_share) = self.information();
        Ok(fit)
    }

    /// [`IcpFit::information_ratio`] and [`IcpFit::line_share`] of the current pairs.
    fn information(&mut self) -> (f64, f64) {
        let Some(grid) = self.grid.as_mut() else {
            return (0.0, 0.0);
        };
        let (mut a, mut b, mut c, mut lines) = (0.0, 0.0, 0.0, 0usize);
        // Every fourth pair: a ratio of sums over a few hundred pairs needs no more, and the
        // line fits are most of the cost.
        let sample = self.pairs.iter().step_by(INFORMATION_STRIDE);
        let sampled = sample.len();
        for &(_, j, _) in sample {
            if let Some([nx, ny]) = grid.line_normal(j) {
                a += nx * nx;
                b += nx * ny;
                c += ny * ny;
                lines += 1;
            }
        }
        let share = lines as f64 / sampled.max(1) as f64;
        let (small, large) = symmetric2_eigenvalues(a, b, c);
        let ratio = if large > 0.0 {
            (small / large).max(0.0)
        } else {
            0.0
        };
        (ratio, share)
    }
}

/// One-shot alignment of `source` onto `target` from `initial` (see [`Icp::align`]).
pub fn align(
    source: &[[f64; 2]],
    target: &[[f64; 2]],
    initial: Pose2,
    config: &IcpConfig,
) -> Result<IcpFit> {
    let mut icp = Icp::new(*config)?;
    icp.set_target(target)?;
    icp.align(source, initial)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::pose2::{identity, inverse};
    use proptest::prelude::*;

    /// Points every `step` metres (the first `offset` metres in) along the walls of an L-shaped room: the 8 × 6 m box with the
    /// 4 × 3 m corner at (4..8, 3..6) cut away, plus a 0.5 m pillar-like box inside.
    fn l_room(offset: f64, step: f64) -> Vec<[f64; 2]> {
        let corners = [
            [0.0, 0.0],
            [8.0, 0.0],
            [8.0, 3.0],
            [4.0, 3.0],
            [4.0, 6.0],
            [0.0, 6.0],
            [0.0, 0.0],
        ];
        let mut out = Vec::new();
        let mut walk = |a: [f64; 2], b: [f64; 2]| {
            let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            let mut s = offset;
            while s < len {
                let u = s / len;
                out.push([a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1])]);
                s += step;
            }
        };
        for w in corners.windows(2) {
            walk(w[0], w[1]);
        }
        for w in [[1.5, 1.5], [2.0, 1.5], [2.0, 2.0], [1.5, 2.0], [1.5, 1.5]].windows(2) {
            walk(w[0], w[1]);
        }
        out
    }

    fn moved(points: &[[f64; 2]], pose: Pose2) -> Vec<[f64; 2]> {
        points.iter().map(|&p| transform_point(pose, p)).collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn recovers_small_rigid_motions(
            x in -0.3f64..0.3, y in -0.3f64..0.3, th in -0.15f64..0.15,
        ) {
            let truth = Pose2::new(x, y, th);
            let target = l_room(0.0, 0.01);
            // The source samples the walls at other places, seen from the moved frame.
            let source = moved(&l_room(0.003, 0.05), inverse(truth));
            let fit = align(&source, &target, identity(), &IcpConfig::default()).unwrap();
            // Point-to-point pairs of non-coincident samples leave a small bias.
            prop_assert!((fit.transform.x - x).abs() < 0.02, "{fit:?}");
            prop_assert!((fit.transform.y - y).abs() < 0.02, "{fit:?}");
            prop_assert!((fit.transform.theta - th).abs() < 0.005, "{fit:?}");
            prop_assert!(fit.rms < 0.03);
        }
    }

    #[test]
    fn robust_to_twenty_percent_outliers() {
        let truth = Pose2::new(0.2, -0.15, 0.08);
        let target = l_room(0.0, 0.01);
        let mut source = moved(&l_room(0.003, 0.05), inverse(truth));
        // 20 % of the source: points scattered inside the room, a deterministic pattern
        // (moving objects that the target never saw).
        let n_out = source.len() / 4; // 20 % of the total after adding
        for k in 0..n_out {
            let u = (k as f64 * 0.618_033_988_7).fract();
            let v = (k as f64 * 0.414_213_562_3).fract();
            source.push([0.5 + 3.0 * u, 0.5 + 5.0 * v]);
        }
        let outlier_share = n_out as f64 / source.len() as f64;
        assert!((outlier_share - 0.2).abs() < 0.01);
        let fit = align(&source, &target, identity(), &IcpConfig::default()).unwrap();
        assert!((fit.transform.x - 0.2).abs() < 0.02, "{fit:?}");
        assert!((fit.transform.y + 0.15).abs() < 0.02, "{fit:?}");
        assert!((fit.transform.theta - 0.08).abs() < 0.005, "{fit:?}");
        assert!(fit.inlier_fraction < 0.95 && fit.inlier_fraction > 0.7);
    }

    #[test]
    fn a_corridor_pins_down_one_direction_a_room_both() {
        // Two parallel walls 2 m apart, 20 m long, against the L-shaped room.
        let corridor: Vec<[f64; 2]> = (0..400)
            .flat_map(|k| [[k as f64 * 0.05, 0.0], [k as f64 * 0.05, 2.0]])
            .collect();
        let source = moved(&corridor, Pose2::new(0.02, 0.01, 0.0));
        let fit = align(&source, &corridor, identity(), &IcpConfig::default()).unwrap();
        assert!(
            fit.information_ratio < 1e-6 && fit.line_share > 0.99,
            "{fit:?}"
        );
        let target = l_room(0.0, 0.01);
        let source = moved(&l_room(0.003, 0.05), Pose2::new(0.02, 0.01, 0.01));
        let fit = align(&source, &target, identity(), &IcpConfig::default()).unwrap();
        assert!(
            fit.information_ratio > 0.3 && fit.line_share > 0.6,
            "{fit:?}"
        );
    }

    #[test]
    fn bad_input_is_an_error() {
        let target = l_room(0.0, 0.01);
        assert!(align(&[[0.0, 0.0]; 3], &[], identity(), &IcpConfig::default()).is_err());
        assert!(align(
            &[[f64::NAN, 0.0]],
            &target,
            identity(),
            &IcpConfig::default()
        )
        .is_err());
        // Nothing within reach.
        let far = vec![[100.0, 100.0]; 20];
        assert!(align(&far, &target, identity(), &IcpConfig::default()).is_err());
        let bad = IcpConfig {
            max_iterations: 0,
            ..IcpConfig::default()
        };
        assert!(Icp::new(bad).is_err());
    }
}
