//! Occlusion-aware detection probability for a planar range scanner: p_D(x) is zero outside
//! the scanner's field of view and range, and inside it falls with the share of the object's
//! beams that end clearly in front of it in the current scan.
//!
//! The model needs the scan the update is about to use: each step's frame brings it as a
//! [`BeamView`] in its step data ([`crate::filter::Frame::data`]).
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
//! In a step whose frame brings no view, no beam is blocked and the model equals the
//! field-of-view model.

pub use super::beam_view::BeamView;
use crate::error::{ensure_positive, Error, Result};
use crate::filter::ParticleSet;
use crate::filter::{DetectionModel, StepContext};
use crate::models::cloud_bounds::{CloudBox, PolarBounds};
use crate::models::detection::FieldOfViewDetection;
use crate::numerics::exp::exp_in_place;

/// p_D from the field of view and the occlusion by nearer returns of the step's scan, the
/// [`BeamView`] of the step data (see the module documentation).
#[derive(Clone, Debug)]
pub struct OcclusionDetection {
    fov: FieldOfViewDetection,
    object_radius: f64,
    margin: f64,
    min_returns: u32,
}

/// The view of a step whose frame brings none: no beam, nothing blocked.
static NO_VIEW: BeamView = BeamView::EMPTY;

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
        })
    }

    /// The same model for a detector that needs `m` returns on an object (0: off).
    pub fn with_min_returns(mut self, m: u32) -> Self {
        self.min_returns = m;
        self
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
        let view = ctx.data.get::<BeamView>().unwrap_or(&NO_VIEW);
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
            self.reach(view, bounds.as_ref())
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
    use crate::filter::StepData;

    fn model() -> OcclusionDetection {
        let fov = FieldOfViewDetection::new(0.9, 0.0, 30.0, FRAC_PI_2).unwrap();
        OcclusionDetection::new(fov, 0.2, 0.3).unwrap()
    }

    /// A step context of a static sensor whose frame brings `view`.
    fn seeing(view: BeamView) -> StepContext {
        StepContext::new(0, 0.0, 0.1).with_data(StepData::new().with(view))
    }

    /// The model (people of 0.2 m, margin 0.6 m) on a 361-beam half-circle scan of 30 m
    /// returns, with pieces of wall (first beam, beams, range) in front.
    fn behind_walls(
        blockers: &[(usize, usize, f64)],
        min_returns: u32,
    ) -> (OcclusionDetection, BeamView) {
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
        (m, BeamView::new(-FRAC_PI_2, PI / 360.0, &ranges).unwrap())
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
            let (m, view) = behind_walls(&blockers, min_returns);
            let mut ctx = seeing(view);
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
            let (m, view) = behind_walls(&blockers, min_returns);
            let ctx = seeing(view.clone());
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
        let ctx = seeing(view());
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
        let p = m.at(10.0 * c, 10.0 * s, &seeing(view()));
        assert!((p - 0.3).abs() < 1e-12, "{p}");
    }

    #[test]
    fn the_view_follows_the_platform() {
        // platform at (100, 50) facing +y; the wall piece is now 3 m north of it
        let m = model();
        let mut ctx = seeing(view());
        ctx.step = 3;
        ctx.platform = Some(Isometry3::new(
            Vector3::new(100.0, 50.0, 0.0),
            Vector3::new(0.0, 0.0, FRAC_PI_2),
        ));
        assert_eq!(m.at(100.0, 60.0, &ctx), 0.0);
        assert_eq!(m.at(105.0, 55.0, &ctx), 0.9);
        // the view is the step's: a step whose scan has no returns, or that brings no scan,
        // leaves the point unblocked
        let empty = BeamView::new(-FRAC_PI_2, PI / 180.0, &[f64::NAN; 181]).unwrap();
        let mut clear = ctx.clone().with_data(StepData::new().with(empty));
        assert_eq!(m.at(100.0, 60.0, &clear), 0.9);
        clear.data = StepData::new();
        assert_eq!(m.at(100.0, 60.0, &clear), 0.9);
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
        let ctx = seeing(BeamView::new(-FRAC_PI_2, PI / 180.0, &[30.0; 181]).unwrap());
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

    /// An independent reference for the rule of the module documentation, by ray casting:
    /// plane geometry and the standard library only (nothing of this module, of the beam view
    /// or of the field-of-view model), so that an error shared by the model's own helpers
    /// shows up.
    ///
    /// The scene's obstacles (discs and wall segments) make the scan: every beam is a ray from
    /// the scanner, intersected analytically with every obstacle, and reports the nearest hit.
    /// A person is a disc of radius ρ centred at distance d; a beam is one of theirs when its
    /// ray meets that disc (ray–circle intersection: directions are directions, whatever the
    /// scan's bearing range, so nothing is special about ±π or about where the scan starts);
    /// when no ray does, the beam whose direction lies within half a spacing of the centre's,
    /// if any. One of their beams is blocked when its return is shorter than d − ρ − m.
    mod ray_cast {
        use std::collections::BTreeSet;
        use std::f64::consts::PI;

        /// A beam whose direction lies within this angle (rad) of the person's tangent (or of
        /// half a spacing from their centre, for the nearest beam) may go either way: the model
        /// takes the bearing from a fast arctangent (error below 2e-5 rad) and the half width
        /// asin(ρ / d) from a series (below 6.5e-7 rad where it uses it, ρ / d < 0.3).
        pub(super) const EDGE: f64 = 3e-5;

        /// Something that returns beams.
        #[derive(Clone, Copy, Debug)]
        pub(super) enum Obstacle {
            Disc { centre: (f64, f64), radius: f64 },
            Wall { a: (f64, f64), b: (f64, f64) },
        }

        fn dot(p: (f64, f64), q: (f64, f64)) -> f64 {
            p.0 * q.0 + p.1 * q.1
        }

        fn cross(p: (f64, f64), q: (f64, f64)) -> f64 {
            p.0 * q.1 - p.1 * q.0
        }

        impl Obstacle {
            /// Distance along the ray from `o` in the unit direction `u` to its first point on
            /// the obstacle, if it meets it.
            pub(super) fn hit(&self, o: (f64, f64), u: (f64, f64)) -> Option<f64> {
                match *self {
                    Obstacle::Disc { centre, radius } => {
                        // |o + t u − c|² = r²: t = w·u ∓ √(r² − (u × w)²), w = c − o
                        let w = (centre.0 - o.0, centre.1 - o.1);
                        let (along, off) = (dot(w, u), cross(u, w));
                        let chord2 = radius * radius - off * off;
                        if chord2 < 0.0 {
                            return None;
                        }
                        let half_chord = chord2.sqrt();
                        [along - half_chord, along + half_chord]
                            .into_iter()
                            .find(|&t| t > 0.0)
                    }
                    Obstacle::Wall { a, b } => {
                        // o + t u = a + s e, s ∈ [0, 1]: cross with e and with u
                        let e = (b.0 - a.0, b.1 - a.1);
                        let denom = cross(u, e);
                        if denom == 0.0 {
                            return None;
                        }
                        let ao = (a.0 - o.0, a.1 - o.1);
                        let (t, s) = (cross(ao, e) / denom, cross(ao, u) / denom);
                        (t > 0.0 && (0.0..=1.0).contains(&s)).then_some(t)
                    }
                }
            }
        }

        /// A scanner in the world: beam i leaves `position` in the direction `heading +
        /// angle_min + i · increment`; it sees people within `max_range` and `half_angle` of
        /// its heading.
        pub(super) struct Scanner {
            pub(super) position: (f64, f64),
            pub(super) heading: f64,
            pub(super) angle_min: f64,
            pub(super) increment: f64,
            pub(super) beams: usize,
            pub(super) max_range: f64,
            pub(super) half_angle: f64,
        }

        impl Scanner {
            fn direction(&self, i: usize) -> (f64, f64) {
                let psi = self.heading + self.angle_min + i as f64 * self.increment;
                (psi.cos(), psi.sin())
            }

            /// The scan of `obstacles`: every beam's nearest hit, and beyond `reach` "no
            /// return", written in each of the ways drivers write it (∞, NaN, 0, negative).
            pub(super) fn scan(&self, obstacles: &[Obstacle], reach: f64) -> Vec<f64> {
                (0..self.beams)
                    .map(|i| self.ray(obstacles, self.direction(i)))
                    .enumerate()
                    .map(|(i, t)| {
                        if t <= reach {
                            t
                        } else {
                            [f64::INFINITY, f64::NAN, 0.0, -1.0][i % 4]
                        }
                    })
                    .collect()
            }

            /// Distance to the nearest obstacle along the unit direction `u` (∞: none).
            fn ray(&self, obstacles: &[Obstacle], u: (f64, f64)) -> f64 {
                obstacles
                    .iter()
                    .filter_map(|o| o.hit(self.position, u))
                    .fold(f64::INFINITY, f64::min)
            }
        }

        /// The people (discs of `radius`) and the detector.
        pub(super) struct People {
            pub(super) radius: f64,
            pub(super) margin: f64,
            pub(super) p_inside: f64,
            pub(super) p_outside: f64,
            pub(super) min_returns: u32,
        }

        /// An answer that the model's rounding may turn either way.
        #[derive(Clone, Copy, Debug, PartialEq)]
        enum Call {
            Yes,
            No,
            Either,
        }

        /// `value` < `bound`, with a band of `band` on either side where it may go either way.
        fn below(value: f64, bound: f64, band: f64) -> Call {
            if (value - bound).abs() <= band {
                Call::Either
            } else if value < bound {
                Call::Yes
            } else {
                Call::No
            }
        }

        /// The (blocked, total) counts of `counts`, each with one more beam whose membership
        /// is `member` and whose blocking is `blocked`.
        fn with_beam(
            counts: &BTreeSet<(usize, usize)>,
            member: Call,
            blocked: Call,
        ) -> BTreeSet<(usize, usize)> {
            let mut out = BTreeSet::new();
            for &(b, n) in counts {
                if member != Call::Yes {
                    out.insert((b, n));
                }
                if member != Call::No {
                    if blocked != Call::Yes {
                        out.insert((b, n + 1));
                    }
                    if blocked != Call::No {
                        out.insert((b + 1, n + 1));
                    }
                }
            }
            out
        }

        /// P(N ≥ m) for N ~ Poisson(μ), term by term.
        fn tail(m: u32, mu: f64) -> f64 {
            let below: f64 = (0..m)
                .map(|j| {
                    let factorial: f64 = (1..=j).map(f64::from).product();
                    (-mu).exp() * mu.powi(j as i32) / factorial
                })
                .sum();
            (1.0 - below).max(0.0)
        }

        /// Every p_D that the rule allows for a person centred at `target` (the world point
        /// (x, y)), seen by `scanner` whose scan is `ranges`: one value, or several when a
        /// beam lies within [`EDGE`] of a boundary, a return within 1e-9 m of the blocking
        /// limit or the person within 1e-9 of the edge of the field of view.
        pub(super) fn p_d(
            scanner: &Scanner,
            ranges: &[f64],
            people: &People,
            target: (f64, f64),
        ) -> Vec<f64> {
            let w = (target.0 - scanner.position.0, target.1 - scanner.position.1);
            let d = w.0.hypot(w.1);
            assert!(d > people.radius, "the scanner stands inside the person");
            let axis = (scanner.heading.cos(), scanner.heading.sin());
            let off_axis = cross(axis, w).atan2(dot(axis, w)).abs();
            let in_range = below(d, scanner.max_range, 1e-9 * scanner.max_range);
            let in_angle = if scanner.half_angle >= PI {
                Call::Yes
            } else {
                below(off_axis, scanner.half_angle, 1e-9)
            };
            let inside = match (in_range, in_angle) {
                (Call::No, _) | (_, Call::No) => Call::No,
                (Call::Yes, Call::Yes) => Call::Yes,
                _ => Call::Either,
            };
            let mut out = Vec::new();
            if inside != Call::Yes {
                out.push(people.p_outside);
            }
            if inside == Call::No {
                return out;
            }
            let limit = d - people.radius - people.margin;
            let tangent = (people.radius / d).asin();
            let spacing = scanner.increment.abs();
            let mut counts = BTreeSet::from([(0, 0)]);
            let mut nearest = Vec::new();
            for (i, &r) in ranges.iter().enumerate() {
                let u = scanner.direction(i);
                // the ray meets the disc: in front, and passing within ρ of its centre
                let meets = dot(u, w) > 0.0 && cross(u, w).abs() <= people.radius;
                let angle = cross(u, w).abs().atan2(dot(u, w));
                let member = match below(angle, tangent, EDGE) {
                    Call::Either => Call::Either,
                    call => {
                        assert_eq!(call == Call::Yes, meets, "beam {i}");
                        call
                    }
                };
                let blocked = if r.is_finite() && r > 0.0 {
                    below(r, limit, 1e-9)
                } else {
                    Call::No
                };
                counts = with_beam(&counts, member, blocked);
                let near = below(angle, 0.5 * spacing, EDGE);
                if near != Call::No {
                    nearest.push((near, blocked));
                }
            }
            if counts.remove(&(0, 0)) {
                // no beam on the disc: the nearest one stands in, if there is one
                if nearest.iter().all(|&(near, _)| near != Call::Yes) {
                    counts.insert((0, 0));
                }
                for &(_, blocked) in &nearest {
                    counts.extend(with_beam(&BTreeSet::from([(0, 0)]), Call::Yes, blocked));
                }
            }
            out.extend(counts.iter().map(|&(b, n)| {
                let free = if n == 0 {
                    1.0
                } else {
                    1.0 - b as f64 / n as f64
                };
                if people.min_returns == 0 {
                    people.p_inside * free
                } else {
                    let mu = free * 2.0 * tangent / spacing;
                    people.p_inside * tail(people.min_returns, mu)
                }
            }));
            out
        }

        /// The share of the person's angular extent, as seen from the scanner, over which an
        /// obstacle lies nearer than d − ρ − m: `rays` directions at the middles of equal
        /// steps across the extent, each intersected with every obstacle. Each edge between
        /// hidden and open directions is placed to within one step, 1 / `rays` of the extent.
        pub(super) fn hidden_share(
            scanner: &Scanner,
            obstacles: &[Obstacle],
            people: &People,
            target: (f64, f64),
            rays: usize,
        ) -> f64 {
            let w = (target.0 - scanner.position.0, target.1 - scanner.position.1);
            let d = w.0.hypot(w.1);
            let (centre, tangent) = (w.1.atan2(w.0), (people.radius / d).asin());
            let limit = d - people.radius - people.margin;
            let hidden = (0..rays)
                .filter(|&j| {
                    let step = (j as f64 + 0.5) / rays as f64;
                    let psi = centre - tangent + 2.0 * tangent * step;
                    scanner.ray(obstacles, (psi.cos(), psi.sin())) < limit
                })
                .count();
            hidden as f64 / rays as f64
        }
    }

    /// The scanners of the ray-casting comparisons, as (angle_min, increment, beams, half
    /// opening of the field of view): 180° at 0.5°; a full turn from −180° to 180° with both
    /// ends (the simulator's 360° scanner); a full turn from 0 (drivers that count from the x
    /// axis); 270° at 0.25°; 180° swept clockwise.
    const SCANNERS: [(f64, f64, usize, f64); 5] = [
        (-FRAC_PI_2, PI / 360.0, 361, FRAC_PI_2),
        (-PI, PI / 360.0, 721, PI),
        (0.0, PI / 360.0, 720, PI),
        (-0.75 * PI, PI / 720.0, 1081, 0.75 * PI),
        (FRAC_PI_2, -PI / 360.0, 361, FRAC_PI_2),
    ];

    /// The model and the reference's scanner for a scanner of [`SCANNERS`] (or any header)
    /// mounted at `mount` on a platform at `pose` (x, y, heading), seeing `people`, with the
    /// scan of `obstacles` (returns beyond 29.5 m: none) set as the model's view; and the step
    /// context of that pose and the scan.
    fn ray_cast_scene(
        (angle_min, increment, beams, half_angle): (f64, f64, usize, f64),
        pose: (f64, f64, f64),
        mount: (f64, f64),
        people: &ray_cast::People,
        obstacles: &[ray_cast::Obstacle],
    ) -> (OcclusionDetection, ray_cast::Scanner, StepContext, Vec<f64>) {
        let (s, c) = pose.2.sin_cos();
        let scanner = ray_cast::Scanner {
            position: (
                pose.0 + c * mount.0 - s * mount.1,
                pose.1 + s * mount.0 + c * mount.1,
            ),
            heading: pose.2,
            angle_min,
            increment,
            beams,
            max_range: 30.0,
            half_angle,
        };
        let fov = FieldOfViewDetection::new(people.p_inside, people.p_outside, 30.0, half_angle)
            .unwrap()
            .with_offset(mount.0, mount.1)
            .unwrap();
        let m = OcclusionDetection::new(fov, people.radius, people.margin)
            .unwrap()
            .with_min_returns(people.min_returns);
        let ranges = scanner.scan(obstacles, 29.5);
        let mut ctx = seeing(BeamView::new(angle_min, increment, &ranges).unwrap());
        ctx.platform = Some(Isometry3::new(
            Vector3::new(pose.0, pose.1, 0.0),
            Vector3::new(0.0, 0.0, pose.2),
        ));
        (m, scanner, ctx, ranges)
    }

    proptest::proptest! {
        /// The model gives every person what ray casting gives (see [`ray_cast`]), from a
        /// moved, turned platform with an offset scanner of each kind of [`SCANNERS`], with up
        /// to six discs and walls at random ranges and bearings all around; people anywhere
        /// (beyond the range too), just behind an obstacle (partly or wholly hidden), astride
        /// the bearing ±180° or next to the first or last beam. Every person alone (the cloud
        /// summary on a single point) and all together (several chunks, the per-particle
        /// windows).
        ///
        /// The comparison is beam by beam, so the beams sample nothing: the share of blocked
        /// beams must be exact (1e-12) but for beams within [`ray_cast::EDGE`] of the person's
        /// tangent, which may count either way. With a minimum number of returns the model's
        /// half width enters μ = free · 2 asin(ρ / d) / Δθ with an error below 6.5e-7 rad, and
        /// P(N ≥ m) moves by at most |δμ| (its derivative in μ is a Poisson probability), so
        /// the tolerance is 0.9 · 1.3e-6 / Δθ.
        #[test]
        fn ray_casting_agrees_with_the_model(
            scanner in 0usize..SCANNERS.len(),
            pose in (-5.0f64..5.0, -5.0f64..5.0, -PI..PI),
            mount in (-0.5f64..0.5, -0.5f64..0.5),
            obstacles in proptest::collection::vec(
                (proptest::bool::ANY, 0.1f64..20.0, -PI..PI, 0.05f64..1.0, 0.2f64..6.0, -PI..PI),
                0..7,
            ),
            targets in proptest::collection::vec(
                (0usize..4, 0.0f64..1.0, 0.0f64..1.0, 0usize..8),
                1..40,
            ),
            radius in 0.1f64..0.4,
            margin in 0.0f64..0.6,
            min_returns in 0u32..3,
        ) {
            let people = ray_cast::People {
                radius,
                margin,
                p_inside: 0.9,
                p_outside: 0.1,
                min_returns,
            };
            let header = SCANNERS[scanner];
            // positions from the sensor's range and bearing, in the world
            let (s, c) = pose.2.sin_cos();
            let sensor = (
                pose.0 + c * mount.0 - s * mount.1,
                pose.1 + s * mount.0 + c * mount.1,
            );
            let world = |r: f64, b: f64| {
                let (lx, ly) = (r * b.cos(), r * b.sin());
                (sensor.0 + c * lx - s * ly, sensor.1 + s * lx + c * ly)
            };
            // (range, bearing, angular half width) of every obstacle, and the obstacles
            let mut placed = Vec::new();
            let mut things = Vec::new();
            for &(disc, range, bearing, size, length, turn) in &obstacles {
                if disc {
                    let range = range + size + 0.1;
                    placed.push((range, bearing, (size / range).asin()));
                    things.push(ray_cast::Obstacle::Disc {
                        centre: world(range, bearing),
                        radius: size,
                    });
                } else {
                    let (x, y) = world(range, bearing);
                    let (dx, dy) = (0.5 * length * turn.cos(), 0.5 * length * turn.sin());
                    placed.push((range, bearing, (0.5 * length / range).atan()));
                    things.push(ray_cast::Obstacle::Wall {
                        a: (x - dx, y - dy),
                        b: (x + dx, y + dy),
                    });
                }
            }
            let (m, scan, ctx, ranges) = ray_cast_scene(header, pose, mount, &people, &things);
            let near = 1.05 * radius;
            let (first, last) = (header.0, header.0 + (header.2 - 1) as f64 * header.1);
            let points: Vec<(f64, f64)> = targets
                .iter()
                .map(|&(kind, u, v, k)| match kind {
                    1 if !placed.is_empty() => {
                        let (range, bearing, half) = placed[k % placed.len()];
                        let r = (range + 0.05 + 8.0 * u).max(near);
                        world(r, bearing + 1.5 * (2.0 * v - 1.0) * half)
                    }
                    2 => world(near + 15.0 * u, PI + 0.1 * (v - 0.5)),
                    3 => {
                        let (end, v) = if v < 0.5 { (first, v) } else { (last, v - 0.5) };
                        world(near + 15.0 * u, end + 0.4 * (v - 0.25))
                    }
                    _ => world(near + 35.0 * u, PI * (2.0 * v - 1.0)),
                })
                .collect();
            let rows: Vec<Vec<f64>> = points.iter().map(|p| vec![p.0, 0.0, p.1, 0.0]).collect();
            let set = ParticleSet::from_rows(&rows, &vec![1.0; rows.len()]).unwrap();
            let mut together = vec![0.0; rows.len()];
            m.detection_probability(&set, &ctx, &mut together);
            let tol = if min_returns == 0 {
                1e-12
            } else {
                1e-12 + 0.9 * 1.3e-6 / header.1.abs()
            };
            for (&(x, y), &got) in points.iter().zip(&together) {
                let want = ray_cast::p_d(&scan, &ranges, &people, (x, y));
                let alone = m.at(x, y, &ctx);
                for got in [got, alone] {
                    proptest::prop_assert!(
                        want.iter().any(|w| (got - w).abs() <= tol),
                        "model {got}, ray casting {want:?} at ({x}, {y})"
                    );
                }
            }
        }
    }

    /// For a person of 0.2 m (margin 0.3 m, p_D 0.9 inside and 0.1 outside the field of view)
    /// at `target`, seen by a scanner at the origin facing +x with `beams` beams 0.1° apart
    /// from `angle_min` (field of view ±`half_angle`), whose scan holds the person's own
    /// returns and those of `obstacles`: the model's p_D, the reference's answers and the
    /// hidden share of the person's angular extent swept with 20,000 rays.
    fn by_hand(
        angle_min: f64,
        beams: usize,
        half_angle: f64,
        target: (f64, f64),
        obstacles: &[ray_cast::Obstacle],
    ) -> (f64, Vec<f64>, f64) {
        let people = ray_cast::People {
            radius: 0.2,
            margin: 0.3,
            p_inside: 0.9,
            p_outside: 0.1,
            min_returns: 0,
        };
        let mut scene = vec![ray_cast::Obstacle::Disc {
            centre: target,
            radius: 0.2,
        }];
        scene.extend_from_slice(obstacles);
        let header = (angle_min, 0.1f64.to_radians(), beams, half_angle);
        let (m, scan, ctx, ranges) =
            ray_cast_scene(header, (0.0, 0.0, 0.0), (0.0, 0.0), &people, &scene);
        let want = ray_cast::p_d(&scan, &ranges, &people, target);
        let share = ray_cast::hidden_share(&scan, &scene, &people, target, 20_000);
        (m.at(target.0, target.1, &ctx), want, share)
    }

    /// Checks a [`by_hand`] answer against p_D and the hidden share worked out by hand. The
    /// beams sample the share: a hidden run of directions holds its length in beams to within
    /// one beam, and the window holds its width to within one beam, so with `runs` hidden
    /// runs and n beams the share of blocked beams lies within (runs + 1) / n of it (here
    /// given as `beams_tolerance`); the sweep places each edge to within 1 / 20,000.
    fn agrees_by_hand(got: (f64, Vec<f64>, f64), p: f64, share: f64, beams_tolerance: f64) {
        let (model, reference, swept) = got;
        assert!((model - p).abs() < 1e-12, "model {model}, by hand {p}");
        assert_eq!(reference.len(), 1, "{reference:?}");
        assert!(
            (reference[0] - p).abs() < 1e-12,
            "ray casting {reference:?}, by hand {p}"
        );
        assert!(
            (swept - share).abs() <= 2.0 / 20_000.0,
            "swept {swept}, by hand {share}"
        );
        let blocked_share = 1.0 - model / 0.9;
        assert!(
            (blocked_share - share).abs() <= beams_tolerance,
            "{blocked_share} {share}"
        );
    }

    #[test]
    fn ray_casting_by_hand_in_front_of_a_half_turn_scanner() {
        use ray_cast::Obstacle::{Disc, Wall};
        let half_turn = |obstacles: &[ray_cast::Obstacle]| {
            by_hand(-FRAC_PI_2, 1801, FRAC_PI_2, (10.0, 0.0), obstacles)
        };
        // The person 10 m ahead spans ±asin(0.02) = ±0.020001 rad = ±11.46 beams: beams −11
        // to 11 about straight ahead, 23 of them; returns nearer than 10 − 0.2 − 0.3 = 9.5 m
        // block.
        //
        // A 0.1 m post at 5 m has the same angular width and hides every beam.
        let post = Disc {
            centre: (5.0, 0.0),
            radius: 0.1,
        };
        agrees_by_hand(half_turn(&[post]), 0.0, 1.0, 0.0);
        // Behind the person it hides nothing (the person's own returns, from 9.8 m on, are
        // not clearly nearer than their surface).
        let behind = Disc {
            centre: (12.0, 0.0),
            radius: 0.12,
        };
        agrees_by_hand(half_turn(&[behind]), 0.9, 0.0, 0.0);
        // A wall at 5 m ending at y = 2.5 mm (bearing 0.0005 rad, 0.29 beams) covers the right
        // half and a little more: beams −11 to 0 blocked, 12 of 23, p = 0.9 · 11/23; hidden
        // share (0.020001 + 0.0005) / 0.040003 = 0.5125.
        let wall = Wall {
            a: (5.0, 0.0025),
            b: (5.0, -1.0),
        };
        let share = (0.02f64.asin() + 0.0005) / (2.0 * 0.02f64.asin());
        agrees_by_hand(half_turn(&[wall]), 0.9 * 11.0 / 23.0, share, 2.0 / 23.0);
        // A 0.06 m post at 9.46 m returns from 9.40 m, nearer than 9.5 m, on the beams within
        // asin(0.06 / 9.46) = 3.63 beams: 7 of 23 blocked. At 9.66 m its returns (9.60 m) are
        // nearer than the person's surface by less than the margin and block nothing.
        let near = |x: f64| Disc {
            centre: (x, 0.0),
            radius: 0.06,
        };
        let share = (0.06f64 / 9.46).asin() / 0.02f64.asin();
        agrees_by_hand(
            half_turn(&[near(9.46)]),
            0.9 * 16.0 / 23.0,
            share,
            2.0 / 23.0,
        );
        agrees_by_hand(half_turn(&[near(9.66)]), 0.9, 0.0, 0.0);
    }

    #[test]
    fn ray_casting_by_hand_across_the_seam_of_full_turn_scanners() {
        use ray_cast::Obstacle::{Disc, Wall};
        let width = 0.02f64.asin();
        // 3601 beams from −180° to 180° (the beam at ±180° twice). The person 10 m behind the
        // scanner spans ±11.46 beams about 180°: beams 3589 to 3600 and 0 to 11, 24 of them. A
        // wall at x = −5 m from y = 2.5 mm on covers bearings 180° − 0.0005 rad and below:
        // beams 3589 to 3599 blocked, 11 of 24, p = 0.9 · 13/24; hidden share
        // (0.020001 − 0.0005) / 0.040003.
        let wall = Wall {
            a: (-5.0, 0.0025),
            b: (-5.0, 1.0),
        };
        let got = by_hand(-PI, 3601, PI, (-10.0, 0.0), &[wall]);
        let share = (width - 0.0005) / (2.0 * width);
        agrees_by_hand(got, 0.9 * 13.0 / 24.0, share, 2.0 / 24.0);
        // 3600 beams from 0°: the person 10 m ahead spans beams 3589 to 3599 and 0 to 11, 23
        // of them; the same wall mirrored to the right blocks beams 3589 to 3599, 11 of 23.
        let wall = Wall {
            a: (5.0, -0.0025),
            b: (5.0, -1.0),
        };
        let got = by_hand(0.0, 3600, PI, (10.0, 0.0), &[wall]);
        agrees_by_hand(got, 0.9 * 12.0 / 23.0, share, 2.0 / 23.0);
        // ... and a person at −5° (beams 3539 to 3561) behind a post of their angular width
        // is hidden entirely.
        let (s, c) = (-5f64).to_radians().sin_cos();
        let post = Disc {
            centre: (5.0 * c, 5.0 * s),
            radius: 0.1,
        };
        let got = by_hand(0.0, 3600, PI, (10.0 * c, 10.0 * s), &[post]);
        agrees_by_hand(got, 0.0, 1.0, 0.0);
    }
}
