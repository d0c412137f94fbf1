//! Occlusion-aware detection probability for a planar range scanner: p_D(x) is zero outside
//! the scanner's field of view and range, and inside it falls with the share of the object's
//! beams that end clearly in front of it in the current scan.
//!
//! The model needs the scan the update is about to use; the caller hands it over before every
//! filter step through a cloned [`OcclusionDetection`] (all clones share one [`BeamView`]).
//! Not for: appearance or shape-dependent detectability, or deciding which returns belong to
//! which object.
//!
//! # The rule
//!
//! A particle at world position (x, y) is seen from the sensor (platform pose of the step moved
//! by the mounting offset, as in [`FieldOfViewDetection`]) at range d and bearing β. The object
//! is a disc of radius ρ, so it covers the bearings β ± asin(ρ / d) (at least the beam nearest
//! to β). A beam of that window is *blocked* when its return is shorter than d − ρ − m, with m
//! a margin of a few range-noise standard deviations: such a return lies clearly nearer than
//! the object's own surface. With b blocked beams out of n,
//!
//! p_D(x) = p_inside · (1 − b / n)  inside the field of view, p_outside elsewhere.
//!
//! Bearings count modulo 2π: the window takes the beams of the scan whose directions fall
//! inside it, whichever turn their bearings are written in, so a person astride the start and
//! end of a full-turn scan (−π and π, or 0 and 2π) keeps the beams on both sides.
//!
//! With `min_returns` = m > 0 the model also accounts for range: a detector that needs m
//! returns on the object cannot see far objects that catch fewer beams. With bearing noise the
//! number of beams ending on the disc is close to Poisson with mean μ = (1 − b / n) ·
//! 2 asin(ρ / d) / |Δθ| (Δθ the beam spacing), and
//!
//! p_D(x) = p_inside · P(N ≥ m),  N ~ Poisson(μ),  P(N ≥ m) = 1 − Σ_{j<m} e^(−μ) μ^j / j!.
//!
//! Without a view set, no beam is blocked and the model equals the field-of-view model.

pub use super::beam_view::BeamView;
use crate::error::{ensure_positive, Error, Result};
use crate::filter::ParticleSet;
use crate::filter::{DetectionModel, StepContext};
use crate::models::cloud_bounds::{CloudBox, PolarBounds};
use crate::models::detection::FieldOfViewDetection;
use crate::numerics::exp::exp_in_place;
use std::sync::{Arc, RwLock};

/// p_D from the field of view and the occlusion by nearer returns of the current scan (see the
/// module documentation). Clones share the view: keep one clone, call
/// [`OcclusionDetection::set_view`] before each step, give the other to the filter.
#[derive(Clone, Debug)]
pub struct OcclusionDetection {
    fov: FieldOfViewDetection,
    object_radius: f64,
    margin: f64,
    min_returns: u32,
    view: Arc<RwLock<BeamView>>,
}

/// atan2(y, x) to within 2e-5 rad by an odd polynomial on [0, 1] and octant symmetry: the
/// beam lookup needs a small fraction of a beam spacing, and the library function dominates
/// the cost of p_D otherwise.
#[inline(always)]
pub(crate) fn fast_atan2(y: f64, x: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    // Every step is a select, not a branch, so loops over many points run on vector lanes.
    let (ax, ay) = (x.abs(), y.abs());
    let swapped = ay > ax;
    let (num, den) = if swapped { (ax, ay) } else { (ay, ax) };
    let z = num / den;
    let z2 = z * z;
    let a = z
        * (0.999_977_26
            + z2 * (-0.332_623_47
                + z2 * (0.193_543_46
                    + z2 * (-0.116_432_87 + z2 * (0.052_653_32 - 0.011_721_20 * z2)))));
    let a = if swapped { FRAC_PI_2 - a } else { a };
    let a = if x < 0.0 { PI - a } else { a };
    let a = if y < 0.0 { -a } else { a };
    if den == 0.0 {
        0.0
    } else {
        a
    }
}

/// P(N ≥ m) for N ~ Poisson(μ).
pub fn poisson_at_least(m: u32, mu: f64) -> f64 {
    if m == 0 {
        return 1.0;
    }
    if mu.is_nan() || mu <= 0.0 {
        return 0.0;
    }
    let mut term = (-mu).exp();
    let mut below = term;
    for j in 1..m {
        term *= mu / j as f64;
        below += term;
    }
    (1.0 - below).clamp(0.0, 1.0)
}

impl OcclusionDetection {
    /// Occlusion on top of the sector `fov`, for objects of radius `object_radius` > 0 (m),
    /// with returns counting as blockers when nearer than the object's surface by more than
    /// `margin` ≥ 0 (m).
    pub fn new(fov: FieldOfViewDetection, object_radius: f64, margin: f64) -> Result<Self> {
        ensure_positive("occlusion object radius", object_radius)?;
        if !(margin.is_finite() && margin >= 0.0) {
            return Err(Error::invalid(
                "occlusion margin",
                format!("{margin} must be finite and ≥ 0"),
            ));
        }
        Ok(OcclusionDetection {
            fov,
            object_radius,
            margin,
            min_returns: 0,
            view: Arc::new(RwLock::new(BeamView::default())),
        })
    }

    /// The same model for a detector that needs `m` returns on an object (0: off).
    pub fn with_min_returns(mut self, m: u32) -> Self {
        self.min_returns = m;
        self
    }

    /// Sets the scan that the next steps' p_D is computed against (shared by all clones).
    pub fn set_view(&self, view: BeamView) {
        *self.view.write().unwrap_or_else(|e| e.into_inner()) = view;
    }

    /// Replaces the shared view's header and ranges in place (no allocation once the buffer
    /// is large enough).
    pub fn update_view(
        &self,
        angle_min: f64,
        angle_increment: f64,
        ranges: impl IntoIterator<Item = f64>,
    ) {
        let mut v = self.view.write().unwrap_or_else(|e| e.into_inner());
        v.angle_min = angle_min;
        v.angle_increment = angle_increment;
        v.set_ranges(ranges);
    }

    /// The field-of-view part.
    pub fn field_of_view(&self) -> &FieldOfViewDetection {
        &self.fov
    }

    /// p_D of one world point at this step.
    pub fn at(&self, x: f64, y: f64, ctx: &StepContext) -> f64 {
        let set = ParticleSet::from_rows(&[vec![x, 0.0, y, 0.0]], &[1.0]).expect("one particle");
        let mut out = [0.0];
        self.detection_probability(&set, ctx, &mut out);
        out[0]
    }
}

/// The beams that any particle's window of one cloud can cover, summarised by their range
/// extremes: a particle whose blocking limit is at most `min` has all its beams free; one
/// whose limit exceeds `max` has all of them blocked, provided every window lies inside the
/// scan (`inside`). Either answer is exactly what the particle's own window gives, without
/// computing that window.
#[derive(Copy, Clone, Debug, PartialEq)]
struct CloudReach {
    min: f64,
    max: f64,
    inside: bool,
}

impl CloudReach {
    /// Nothing known: every particle needs its own window.
    const UNKNOWN: CloudReach = CloudReach {
        min: f64::NEG_INFINITY,
        max: f64::INFINITY,
        inside: false,
    };
    /// Every window misses the scan: nothing blocks.
    const NOTHING: CloudReach = CloudReach {
        min: f64::INFINITY,
        max: f64::INFINITY,
        inside: false,
    };
}

/// Extra bearing (rad) allowed around a cloud's bearing interval for the per-particle
/// bearing's approximation error (below 2e-5 rad, [`fast_atan2`]).
const BEARING_SLACK: f64 = 1e-4;

impl OcclusionDetection {
    /// The beams the windows of the particles can cover, from the bounds of the cloud's
    /// positions: bearings widened by the widest window (that of the nearest possible
    /// particle), a bearing slack and one beam on either side, and the copies of that
    /// interval a whole turn away that meet the scan (bearings count modulo 2π).
    fn reach(&self, view: &BeamView, bounds: Option<&PolarBounds>) -> CloudReach {
        let n = view.ranges.len();
        let inc = view.angle_increment;
        if n == 0 {
            return CloudReach::NOTHING;
        }
        let Some(b) = bounds else {
            return CloudReach::UNKNOWN;
        };
        if inc.is_nan() || inc <= 0.0 || b.d_min <= self.object_radius * (1.0 + 1e-9) {
            return CloudReach::UNKNOWN;
        }
        // The series used per particle stays below asin.
        let half_max = (self.object_radius / b.d_min).min(1.0).asin() * (1.0 + 1e-9);
        let lo = ((b.bearing_min - half_max - BEARING_SLACK - view.angle_min) / inc).floor() - 1.0;
        let hi = ((b.bearing_max + half_max + BEARING_SLACK - view.angle_min) / inc).ceil() + 1.0;
        // beams per turn
        let turn = std::f64::consts::TAU / inc;
        if !(lo.is_finite() && hi.is_finite() && turn >= 1.0) {
            return CloudReach::UNKNOWN;
        }
        let last_beam = (n - 1) as f64;
        let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut copies, mut inside) = (0, false);
        let mut k = (-hi / turn).ceil();
        let k_last = ((last_beam - lo) / turn).floor();
        while k <= k_last {
            let (from, to) = (lo + k * turn, hi + k * turn);
            let (first, last) = (from.ceil().max(0.0), to.floor().min(last_beam));
            if first <= last {
                let (a, b) = view.extremes.query(first as usize, last as usize);
                (min, max) = (min.min(a), max.max(b));
                copies += 1;
                inside = from >= 0.0 && to <= last_beam;
            }
            k += 1.0;
        }
        if copies == 0 {
            return CloudReach::NOTHING;
        }
        CloudReach {
            min,
            max,
            // every window within one copy that lies wholly in the scan
            inside: copies == 1 && inside,
        }
    }

    /// p_D inside the field of view of a particle at distance `d` with the share `free` of
    /// its beams unblocked.
    #[inline]
    fn probability(&self, d: f64, free: f64, spacing: f64) -> f64 {
        let p_in = self.fov.p_inside();
        if self.min_returns == 0 {
            return p_in * free;
        }
        let half = self.half_width(d);
        if spacing > 0.0 {
            p_in * poisson_at_least(self.min_returns, free * 2.0 * half / spacing)
        } else {
            p_in * free
        }
    }

    /// Half the bearing width asin(ρ / d) of the object at distance `d`.
    #[inline]
    fn half_width(&self, d: f64) -> f64 {
        if d > self.object_radius {
            let q = self.object_radius / d;
            if q < 0.3 {
                asin_series(q)
            } else {
                q.asin()
            }
        } else {
            std::f64::consts::FRAC_PI_2
        }
    }
}

/// asin(q) by its series to q⁷: error below 1e-5 rad for 0 ≤ q < 0.3.
#[inline(always)]
fn asin_series(q: f64) -> f64 {
    let q2 = q * q;
    q * (1.0 + q2 * (1.0 / 6.0 + q2 * (3.0 / 40.0 + q2 * 5.0 / 112.0)))
}

/// Particles per pass of [`OcclusionDetection::fill`]: stack arrays of this length carry the
/// per-particle quantities from one pass to the next.
const CHUNK: usize = 64;

/// The per-particle quantities of one chunk, in the sensor frame.
struct Lanes {
    /// 1 inside the field of view, 0 outside.
    inside: [f64; CHUNK],
    d: [f64; CHUNK],
    limit: [f64; CHUNK],
    half: [f64; CHUNK],
    bearing: [f64; CHUNK],
}

impl DetectionModel for OcclusionDetection {
    fn detection_probability(&self, particles: &ParticleSet, ctx: &StepContext, out: &mut [f64]) {
        self.fill(particles, ctx, out, true);
    }
}

impl OcclusionDetection {
    /// p_D of every particle; with `whole_cloud_first`, the beams the whole cloud can reach are
    /// summarised first, so that most particles need no window of their own.
    fn fill(
        &self,
        particles: &ParticleSet,
        ctx: &StepContext,
        out: &mut [f64],
        whole_cloud_first: bool,
    ) {
        if particles.dim() < 3 {
            out.fill(0.0);
            return;
        }
        let view = self.view.read().unwrap_or_else(|e| e.into_inner());
        let sensor = self.fov.sensor(ctx);
        let (sx, sy, c, s) = sensor;
        let p_out = self.fov.p_outside();
        let spacing = view.angle_increment.abs();
        let xs = particles.component(0);
        let ys = particles.component(2);
        let poisson = self.min_returns > 0 && spacing > 0.0;
        let bounds = if whole_cloud_first {
            CloudBox::of(particles).and_then(|b| b.polar_from(sx, sy, c, s))
        } else {
            None
        };
        let reach = if whole_cloud_first {
            self.reach(&view, bounds.as_ref())
        } else {
            CloudReach::UNKNOWN
        };
        let all_inside = bounds.is_some_and(|b| self.fov.surely_contains(&b));
        let cos_half = self.fov.cos_half_angle();
        let mut lanes = Lanes {
            inside: [0.0; CHUNK],
            d: [0.0; CHUNK],
            limit: [0.0; CHUNK],
            half: [0.0; CHUNK],
            bearing: [0.0; CHUNK],
        };
        for ((out, xs), ys) in out
            .chunks_mut(CHUNK)
            .zip(xs.chunks(CHUNK))
            .zip(ys.chunks(CHUNK))
        {
            let m = out.len();
            // Geometry of every particle, on vector lanes: field of view, distance, blocking
            // limit, half width (by the series where it holds) and bearing.
            let geometry = lanes.inside[..m]
                .iter_mut()
                .zip(&mut lanes.d[..m])
                .zip(&mut lanes.limit[..m])
                .zip(&mut lanes.half[..m])
                .zip(&mut lanes.bearing[..m])
                .zip(xs.iter().zip(ys));
            for (((((inside, d_out), limit), half), bearing), (&x, &y)) in geometry {
                let (dx, dy) = (x - sx, y - sy);
                let (lx, ly) = (c * dx + s * dy, -s * dx + c * dy);
                let d2 = lx * lx + ly * ly;
                let d = d2.sqrt();
                *inside = if all_inside | self.fov.contains_local(lx, d2, cos_half) {
                    1.0
                } else {
                    0.0
                };
                *d_out = d;
                *limit = d - self.object_radius - self.margin;
                *half = asin_series(self.object_radius / d);
                *bearing = fast_atan2(ly, lx);
            }
            // The series holds for d > ρ and ρ / d < 0.3 (NaN fails both).
            let rare = lanes.d[..m]
                .iter()
                .any(|&d| !((d > self.object_radius) & (self.object_radius / d < 0.3)));
            if rare {
                for (h, &d) in lanes.half[..m].iter_mut().zip(&lanes.d[..m]) {
                    *h = self.half_width(d);
                }
            }
            // The share of free beams, particle by particle.
            for (k, o) in out.iter_mut().enumerate() {
                if lanes.inside[k] == 0.0 {
                    *o = if poisson { -1.0 } else { p_out };
                    continue;
                }
                let (limit, half) = (lanes.limit[k], lanes.half[k]);
                let free = if reach.min >= limit {
                    1.0
                } else if reach.inside && reach.max < limit {
                    0.0
                } else {
                    let (blocked, total) = view.blocked(lanes.bearing[k], half, limit);
                    if total == 0 {
                        1.0
                    } else {
                        // counts far below 2^63: through i64 is exact and one instruction
                        1.0 - blocked as i64 as f64 / total as i64 as f64
                    }
                };
                *o = if poisson {
                    // μ for now; the Poisson tail follows for the whole chunk at once
                    free * 2.0 * half / spacing
                } else {
                    self.probability(lanes.d[k], free, spacing)
                };
            }
            if poisson {
                self.poisson_tails(out, p_out);
            }
        }
    }

    /// Replaces every μ ≥ 0 of `out` (at most [`CHUNK`] entries) by p_inside · P(N ≥ m),
    /// N ~ Poisson(μ) (as [`poisson_at_least`], 0 for μ = 0 or NaN), and every negative entry
    /// (outside the field of view) by `p_out`; in passes that run on vector lanes.
    fn poisson_tails(&self, out: &mut [f64], p_out: f64) {
        let n = out.len();
        let (mut term, mut below) = ([0.0; CHUNK], [0.0; CHUNK]);
        let (term, below) = (&mut term[..n], &mut below[..n]);
        for (t, &mu) in term.iter_mut().zip(out.iter()) {
            *t = -mu;
        }
        exp_in_place(term);
        below.copy_from_slice(term);
        for j in 1..self.min_returns {
            let j = j as f64;
            for ((t, b), &mu) in term.iter_mut().zip(below.iter_mut()).zip(out.iter()) {
                *t *= mu / j;
                *b += *t;
            }
        }
        let p_in = self.fov.p_inside();
        for (o, &b) in out.iter_mut().zip(below.iter()) {
            let mu = *o;
            let tail = (1.0 - b).clamp(0.0, 1.0);
            *o = if mu < 0.0 {
                p_out
            } else if mu > 0.0 {
                p_in * tail
            } else {
                0.0
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Isometry3, Vector3};
    use std::f64::consts::{FRAC_PI_2, PI};

    use super::super::beam_view::tests::view;

    fn model() -> OcclusionDetection {
        let fov = FieldOfViewDetection::new(0.9, 0.0, 30.0, FRAC_PI_2).unwrap();
        let m = OcclusionDetection::new(fov, 0.2, 0.3).unwrap();
        m.set_view(view());
        m
    }

    /// The model (people of 0.2 m, margin 0.6 m) on a 361-beam half-circle scan of 30 m
    /// returns, with pieces of wall (first beam, beams, range) in front.
    fn behind_walls(blockers: &[(usize, usize, f64)], min_returns: u32) -> OcclusionDetection {
        let fov = FieldOfViewDetection::new(0.9, 0.1, 30.0, FRAC_PI_2).unwrap();
        let m = OcclusionDetection::new(fov, 0.2, 0.6)
            .unwrap()
            .with_min_returns(min_returns);
        let mut ranges = vec![30.0; 361];
        for &(first, len, r) in blockers {
            ranges[first..(first + len).min(361)]
                .iter_mut()
                .for_each(|v| *v = r);
        }
        m.set_view(BeamView::new(-FRAC_PI_2, PI / 360.0, &ranges).unwrap());
        m
    }

    proptest::proptest! {
        /// The cloud-wide beam summary never changes a particle's p_D: clouds of people
        /// (0.2 m) at 1–15 m, partly behind pieces of wall at random ranges, with and without the
        /// minimum number of returns, from a moved and turned platform.
        #[test]
        fn cloud_summary_gives_every_particle_its_own_answer(
            blockers in proptest::collection::vec((0usize..361, 1usize..60, 0.3f64..16.0), 0..5),
            centre in (1.0f64..15.0, -1.4f64..1.4),
            spread in 0.01f64..2.0,
            offsets in proptest::collection::vec((-1.0f64..1.0, -1.0f64..1.0), 1..60),
            pose in (-1.0f64..1.0, -1.0f64..1.0, -0.3f64..0.3),
            min_returns in 0u32..3,
        ) {
            let m = behind_walls(&blockers, min_returns);
            let mut ctx = StepContext::new(0, 0.0, 0.1);
            ctx.platform = Some(Isometry3::new(
                Vector3::new(pose.0, pose.1, 0.0),
                Vector3::new(0.0, 0.0, pose.2),
            ));
            let (cx, cy) = (centre.0 * centre.1.cos(), centre.0 * centre.1.sin());
            let rows: Vec<Vec<f64>> = offsets
                .iter()
                .map(|o| vec![cx + spread * o.0, 0.0, cy + spread * o.1, 0.0])
                .collect();
            let set = ParticleSet::from_rows(&rows, &vec![1.0; rows.len()]).unwrap();
            let (mut fast, mut each) = (vec![0.0; rows.len()], vec![0.0; rows.len()]);
            m.fill(&set, &ctx, &mut fast, true);
            m.fill(&set, &ctx, &mut each, false);
            proptest::prop_assert_eq!(fast, each);
        }
    }

    proptest::proptest! {
        /// The chunked passes give every particle what the rule of the module documentation
        /// gives when evaluated one particle at a time: clouds of up to 150 particles (several chunks)
        /// reaching behind the scanner, beyond its range and next to it (where the series for
        /// the half width gives way to asin).
        #[test]
        fn chunked_passes_follow_the_rule_particle_by_particle(
            blockers in proptest::collection::vec((0usize..361, 1usize..60, 0.3f64..16.0), 0..5),
            points in proptest::collection::vec((-2.0f64..32.0, -16.0f64..16.0), 1..150),
            min_returns in 0u32..3,
        ) {
            let m = behind_walls(&blockers, min_returns);
            let view = m.view.read().unwrap().clone();
            let ctx = StepContext::new(0, 0.0, 0.1);
            let rows: Vec<Vec<f64>> = points.iter().map(|p| vec![p.0, 0.0, p.1, 0.0]).collect();
            let set = ParticleSet::from_rows(&rows, &vec![1.0; rows.len()]).unwrap();
            let mut out = vec![0.0; rows.len()];
            m.detection_probability(&set, &ctx, &mut out);
            let spacing = PI / 360.0;
            for (&(x, y), &o) in points.iter().zip(&out) {
                let want = if !m.field_of_view().contains_from(x, y, 0.0, 0.0, 1.0, 0.0) {
                    0.1
                } else {
                    let d = (x * x + y * y).sqrt();
                    let half = m.half_width(d);
                    let (blocked, total) = view.blocked(fast_atan2(y, x), half, d - 0.2 - 0.6);
                    let free = if total == 0 {
                        1.0
                    } else {
                        1.0 - blocked as f64 / total as f64
                    };
                    if min_returns == 0 {
                        0.9 * free
                    } else {
                        0.9 * poisson_at_least(min_returns, free * 2.0 * half / spacing)
                    }
                };
                // the slice exponential is within two units in the last place of the library's
                proptest::prop_assert!((o - want).abs() < 1e-14, "{o} vs {want} at ({x}, {y})");
            }
        }
    }

    #[test]
    fn occluded_visible_and_outside_particles() {
        let m = model();
        let ctx = StepContext::new(0, 0.0, 0.1);
        // 10 m straight ahead, behind the 3 m wall: every beam of its ±1.15° window blocked
        assert_eq!(m.at(10.0, 0.0, &ctx), 0.0);
        // 2.5 m ahead, in front of the wall: the wall (3 m) is not nearer → fully visible
        assert_eq!(m.at(2.5, 0.0, &ctx), 0.9);
        // a particle right at the wall's surface: wall returns are not "clearly nearer"
        assert_eq!(m.at(3.2, 0.0, &ctx), 0.9);
        // 10 m at bearing 30°: free
        let (s, c) = 30f64.to_radians().sin_cos();
        assert_eq!(m.at(10.0 * c, 10.0 * s, &ctx), 0.9);
        // behind the scanner or beyond 30 m: outside the field of view
        assert_eq!(m.at(-5.0, 0.0, &ctx), 0.0);
        assert_eq!(m.at(0.0, 35.0, &ctx), 0.0);
    }

    #[test]
    fn partial_occlusion_scales_the_probability() {
        // the wall ends at bearing 5.5°; an object at 10 m, bearing 5° covers ±1.146°,
        // beams at 4°, 5° (blocked) and 6° (free) → p = 0.9 · 1/3
        let m = model();
        let (s, c) = 5f64.to_radians().sin_cos();
        let p = m.at(10.0 * c, 10.0 * s, &StepContext::new(0, 0.0, 0.1));
        assert!((p - 0.3).abs() < 1e-12, "{p}");
    }

    #[test]
    fn the_view_follows_the_platform() {
        // platform at (100, 50) facing +y; the wall piece is now 3 m north of it
        let m = model();
        let mut ctx = StepContext::new(3, 1.0, 0.1);
        ctx.platform = Some(Isometry3::new(
            Vector3::new(100.0, 50.0, 0.0),
            Vector3::new(0.0, 0.0, FRAC_PI_2),
        ));
        assert_eq!(m.at(100.0, 60.0, &ctx), 0.0);
        assert_eq!(m.at(105.0, 55.0, &ctx), 0.9);
        // a clone shares the view: clearing it through the clone unblocks the point
        let other = m.clone();
        other.update_view(-FRAC_PI_2, PI / 180.0, vec![f64::NAN; 181]);
        assert_eq!(m.at(100.0, 60.0, &ctx), 0.9);
    }

    #[test]
    fn fast_atan2_is_close_to_the_library() {
        let mut worst: f64 = 0.0;
        for i in 0..3600 {
            let a = -PI + (i as f64 + 0.5) * (2.0 * PI / 3600.0);
            for r in [0.1, 1.0, 37.0] {
                let (y, x) = (r * a.sin(), r * a.cos());
                worst = worst.max((fast_atan2(y, x) - y.atan2(x)).abs());
            }
        }
        assert!(worst < 2e-5, "{worst}");
        assert_eq!(fast_atan2(0.0, 0.0), 0.0);
        assert!((fast_atan2(1.0, 0.0) - FRAC_PI_2).abs() < 1e-12);
    }

    #[test]
    fn poisson_tail_matches_hand_values() {
        // P(N ≥ 2 | μ = 2) = 1 − e^(−2)(1 + 2) = 0.593994…
        assert!((poisson_at_least(2, 2.0) - 0.593_994_150_290_161_9).abs() < 1e-12);
        assert!((poisson_at_least(1, 1.0) - (1.0 - (-1.0f64).exp())).abs() < 1e-15);
        assert_eq!(poisson_at_least(0, 0.0), 1.0);
        assert_eq!(poisson_at_least(3, 0.0), 0.0);
    }

    #[test]
    fn far_objects_catch_too_few_beams() {
        // 1° beams, object radius 0.2 m, needs 2 returns. At 10 m: μ = 2 asin(0.02) / 1° =
        // 2.2920…; at 25 m: μ = 0.9167…
        let m = model().with_min_returns(2);
        m.update_view(-FRAC_PI_2, PI / 180.0, vec![30.0; 181]);
        let ctx = StepContext::new(0, 0.0, 0.1);
        let mu = |d: f64| 2.0 * (0.2f64 / d).asin() / (PI / 180.0);
        let (s, c) = 20f64.to_radians().sin_cos();
        let near = m.at(10.0 * c, 10.0 * s, &ctx);
        let far = m.at(25.0 * c, 25.0 * s, &ctx);
        let expect = |mu: f64| 0.9 * (1.0 - (-mu).exp() * (1.0 + mu));
        assert!((near - expect(mu(10.0))).abs() < 1e-12, "{near}");
        assert!((far - expect(mu(25.0))).abs() < 1e-12, "{far}");
        assert!(far < 0.25 && near > 0.6);
    }

    #[test]
    fn invalid_parameters_are_rejected() {
        let fov = FieldOfViewDetection::new(0.9, 0.0, 30.0, FRAC_PI_2).unwrap();
        assert!(OcclusionDetection::new(fov, 0.0, 0.3).is_err());
        assert!(OcclusionDetection::new(fov, 0.2, -1.0).is_err());
        assert!(BeamView::new(0.0, 0.0, &[1.0, 2.0]).is_err());
        assert!(BeamView::new(f64::NAN, 0.1, &[1.0]).is_err());
    }
}
