//! Oriented boxes fitted to one cluster's points (sensor frame, z up, sensor at the origin).
//!
//! * Heading: the search-based L-shape fit of Zhang et al., "Efficient L-shape fitting for
//!   vehicle detection using laser scanners" (IEEE IV 2017), Algorithm 1 with the closeness
//!   criterion (Algorithm 4): for each candidate heading θ in [0, 90°) the points are projected
//!   on the rectangle axes e₁ = (cos θ, sin θ), e₂ = (−sin θ, cos θ); for each axis the point
//!   distances to the nearer of its two bounding edges are kept (the edge whose distance vector
//!   has the smaller norm), each point scores 1 / max(min(d₁, d₂), d₀), and the heading with the
//!   highest total wins. The rectangle is the points' bounding rectangle at that heading.
//! * Height: bottom at the ground height when one is given (else the lowest point), top at the
//!   highest point.
//! * Visible-face model: a lidar sees only the faces turned towards it, so the far faces of an
//!   object are missing and the points' centroid (and the fitted rectangle's centre) sit short
//!   of the object's centre. Given a plausible footprint of the object's kind ([`SizePrior`]),
//!   each side shorter than it is extended *away from the sensor*: the face nearer the sensor
//!   stays where it was seen and the far face moves out (both move by half when the sensor lies
//!   between the two faces, which are then both out of its view). A side whose parallel face
//!   is itself in view (the sensor outside the slab between the two faces along the other
//!   axis) is seen whole except for one sampling gap at its far end: the scanner's azimuth step
//!   spread along a face seen at the grazing angle α is r·Δφ / sin α, and such a side is
//!   extended by at most that much (so a short car seen from its corner is not stretched to
//!   the class's mean length). The fitted box is kept next to the extended one in [`BoxFit`].
//!
//! Not for: clustering (see [`super::cluster`]), classes (see [`super::classes`]), tracking
//! box states over time, or box geometry and overlap (see [`crate::geometry::box3`]).

use super::points::PointCloud;
use crate::error::{Error, Result};
use crate::geometry::plane::convex_hull;
use crate::geometry::Box3;
use crate::numerics::floor::floor_i64;
use nalgebra::{Point2, Point3};
use std::f64::consts::{FRAC_PI_2, PI};

/// Settings of the box fit.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct BoxFitParams {
    /// Step of the heading search over [0, 90°) (rad). Zhang et al. use 1° (and report that
    /// finer steps change little); 0.5° halves the quantisation error of the heading at twice
    /// the cost.
    pub angle_step: f64,
    /// d₀ of the closeness criterion (m): distances below it score as d₀, so that points
    /// on an edge do not dominate. Zhang et al. use 0.01 m, about a scanner's range noise.
    pub min_distance: f64,
    /// Azimuth spacing of the scanner's points (rad), for the sampling gap of the visible-face
    /// model. Default [`super::HDL64E_AZIMUTH_STEP`].
    pub azimuth_step: f64,
    /// The heading search scores one point per cell of this size (m) in the bird's-eye view
    /// (the first in the cluster's order), 0 for every point. A lidar sees an object's
    /// surfaces, so its footprint points already lie on the L; a near car's thousands of
    /// points stack up in a few hundred 0.1 m cells, and the search (steps × points) gets
    /// that much cheaper. The rectangle and heights still take every point.
    pub search_cell: f64,
}

impl Default for BoxFitParams {
    fn default() -> Self {
        Self {
            angle_step: 0.5f64.to_radians(),
            min_distance: 0.01,
            azimuth_step: super::HDL64E_AZIMUTH_STEP,
            search_cell: 0.1,
        }
    }
}

/// The plausible footprint of an object of the cluster's kind: sides observed shorter than
/// this are extended away from the sensor. See [`super::classes::ObjectClass::size_prior`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SizePrior {
    /// Length (m), the longer footprint side.
    pub length: f64,
    /// Width (m).
    pub width: f64,
}

/// The boxes fitted to one cluster.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct BoxFit {
    /// The points' bounding box at the fitted heading (length = the longer side unless a
    /// size prior decided otherwise), bottom at the lowest point, top at the highest. Its yaw
    /// lies in (−π/2, π/2]: one frame's points cannot tell the front from the back.
    pub fitted: Box3,
    /// The box with the visible-face model applied: sides extended away from the sensor to
    /// the size prior, bottom at the ground when one was given. Equal to `fitted` (except for
    /// the bottom) without a prior.
    pub estimated: Box3,
    /// Number of points fitted.
    pub points: usize,
    /// Mean height of the points above the estimated box's bottom (m): where the point mass
    /// sits, one of the class features.
    pub mass_height: f64,
    /// Range from the sensor to the fitted box's centre in the x–y plane (m).
    pub range: f64,
}

/// Fits a box to the points `(xs[i], ys[i], zs[i])`. `ground_z` is the ground height under
/// the object when known (bottom of the estimated box); `prior` the plausible footprint of
/// the object's kind (see the module notes). `scratch` is reused between calls (one buffer of
/// 2 × points values). Fails on empty or differently long slices, non-finite coordinates or
/// settings. The same as [`BoxOutline::of`] followed by [`BoxOutline::fit`].
pub fn fit_box(
    xs: &[f32],
    ys: &[f32],
    zs: &[f32],
    ground_z: Option<f64>,
    prior: Option<&SizePrior>,
    params: &BoxFitParams,
    scratch: &mut Vec<f64>,
) -> Result<BoxFit> {
    BoxOutline::of(xs, ys, zs, ground_z, params, scratch)?.fit(prior)
}

/// What a box fit knows of its points before a size prior enters: the heading the L-shape
/// search chose, the points' bounding rectangle at that heading and their heights. One
/// outline gives the [`BoxFit`] for any number of priors ([`BoxOutline::fit`]) without
/// searching the heading again.
#[derive(Clone, Debug, PartialEq)]
pub struct BoxOutline {
    /// The points' x–y mean, which the rectangle is given about.
    mean: [f64; 2],
    theta: f64,
    rect: Rect,
    z_lo: f64,
    z_hi: f64,
    z_sum: f64,
    n: usize,
    ground_z: Option<f64>,
    azimuth_step: f64,
}

impl BoxOutline {
    /// Searches the heading of the points `(xs[i], ys[i], zs[i])` and bounds them (see
    /// [`fit_box`] for the arguments and the errors).
    pub fn of(
        xs: &[f32],
        ys: &[f32],
        zs: &[f32],
        ground_z: Option<f64>,
        params: &BoxFitParams,
        scratch: &mut Vec<f64>,
    ) -> Result<Self> {
        let n = xs.len();
        if n == 0 || ys.len() != n || zs.len() != n {
            return Err(Error::invalid(
                "box fit points",
                format!(
                    "{} x, {} y, {} z values (need the same number, at least one)",
                    n,
                    ys.len(),
                    zs.len()
                ),
            ));
        }
        check_settings(ground_z, params)?;
        // Centre the x–y coordinates on their mean (keeps the projections' rounding small).
        let (mut mx, mut my) = (0.0f64, 0.0f64);
        let (mut z_lo, mut z_hi, mut z_sum) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        for i in 0..n {
            let (x, y, z) = (xs[i] as f64, ys[i] as f64, zs[i] as f64);
            if !(x.is_finite() && y.is_finite() && z.is_finite()) {
                return Err(Error::invalid(
                    "box fit points",
                    format!("point {i} is ({x}, {y}, {z}) (must be finite)"),
                ));
            }
            mx += x;
            my += y;
            z_lo = z_lo.min(z);
            z_hi = z_hi.max(z);
            z_sum += z;
        }
        mx /= n as f64;
        my /= n as f64;
        scratch.clear();
        scratch.reserve(2 * n);
        for i in 0..n {
            scratch.push(xs[i] as f64 - mx);
            scratch.push(ys[i] as f64 - my);
        }
        let theta = if params.search_cell > 0.0 {
            one_point_per_cell(scratch, 2 * n, params.search_cell);
            lshape_heading(&scratch[2 * n..], params)
        } else {
            lshape_heading(scratch, params)
        };
        scratch.truncate(2 * n);
        let rect = Rect::bounding(scratch, theta);
        Ok(BoxOutline {
            mean: [mx, my],
            theta,
            rect,
            z_lo,
            z_hi,
            z_sum,
            n,
            ground_z,
            azimuth_step: params.azimuth_step,
        })
    }

    /// The boxes of these points for the footprint `prior` (none: the fitted box alone).
    /// Fails on a negative prior side.
    pub fn fit(&self, prior: Option<&SizePrior>) -> Result<BoxFit> {
        if let Some(p) = prior {
            crate::error::ensure_non_negative("size prior length", p.length)?;
            crate::error::ensure_non_negative("size prior width", p.width)?;
        }
        let [mx, my] = self.mean;
        let theta = self.theta;
        let rect = &self.rect;
        // The sensor (origin) in the centred frame, projected on the rectangle axes.
        let (s, c) = theta.sin_cos();
        let sensor = [-(c * mx + s * my), -(-s * mx + c * my)];
        let length_axis = choose_length_axis(rect, prior);
        let bottom = self.ground_z.unwrap_or(self.z_lo);
        let z_hi = self.z_hi;
        let to_box = |r: &Rect, z0: f64| {
            let [a, b] = r.centre();
            let centre_xy = [mx + c * a - s * b, my + s * a + c * b];
            let (l, w, yaw) = if length_axis == 0 {
                (r.extent(0), r.extent(1), theta)
            } else {
                (r.extent(1), r.extent(0), theta + FRAC_PI_2)
            };
            Box3::new(
                Point3::new(centre_xy[0], centre_xy[1], (z0 + z_hi) / 2.0),
                [l, w, (z_hi - z0).max(0.0)],
                heading_mod_pi(yaw),
            )
        };
        let fitted = to_box(rect, self.z_lo);
        let estimated = match prior {
            Some(p) => {
                let mut target = [p.length, p.width];
                if length_axis == 1 {
                    target.swap(0, 1);
                }
                let extended = rect.extended_away(sensor, target, self.azimuth_step);
                to_box(&extended, bottom)
            }
            None => to_box(rect, bottom),
        };
        Ok(BoxFit {
            fitted,
            estimated,
            points: self.n,
            mass_height: self.z_sum / self.n as f64 - bottom,
            range: fitted.center.x.hypot(fitted.center.y),
        })
    }
}

/// [`fit_box`] on the points `indices` of `cloud`, gathered into `scratch` (reused storage;
/// fails on an index past the cloud's end).
pub fn fit_box_of(
    cloud: &PointCloud,
    indices: &[u32],
    ground_z: Option<f64>,
    prior: Option<&SizePrior>,
    params: &BoxFitParams,
    scratch: &mut BoxScratch,
) -> Result<BoxFit> {
    outline_of(cloud, indices, ground_z, params, scratch)?.fit(prior)
}

/// [`BoxOutline::of`] on the points `indices` of `cloud`, gathered into `scratch` (reused
/// storage; fails on an index past the cloud's end).
pub fn outline_of(
    cloud: &PointCloud,
    indices: &[u32],
    ground_z: Option<f64>,
    params: &BoxFitParams,
    scratch: &mut BoxScratch,
) -> Result<BoxOutline> {
    let (xs, ys, zs, _) = cloud.columns();
    scratch.xs.clear();
    scratch.ys.clear();
    scratch.zs.clear();
    for &i in indices {
        let i = i as usize;
        if i >= xs.len() {
            return Err(Error::invalid(
                "box fit indices",
                format!("index {i} with {} points in the cloud", xs.len()),
            ));
        }
        scratch.xs.push(xs[i]);
        scratch.ys.push(ys[i]);
        scratch.zs.push(zs[i]);
    }
    BoxOutline::of(
        &scratch.xs,
        &scratch.ys,
        &scratch.zs,
        ground_z,
        params,
        &mut scratch.centred,
    )
}

/// Storage reused by [`fit_box_of`] across clusters.
#[derive(Clone, Debug, Default)]
pub struct BoxScratch {
    xs: Vec<f32>,
    ys: Vec<f32>,
    zs: Vec<f32>,
    centred: Vec<f64>,
}

/// Checks the fit's settings (a size prior is checked by [`BoxOutline::fit`], which takes it).
fn check_settings(ground_z: Option<f64>, params: &BoxFitParams) -> Result<()> {
    if !(params.angle_step > 0.0 && params.angle_step <= FRAC_PI_2) {
        return Err(Error::invalid(
            "box fit angle_step",
            format!("{} rad (must lie in (0, π/2])", params.angle_step),
        ));
    }
    crate::error::ensure_positive("box fit min_distance", params.min_distance)?;
    crate::error::ensure_non_negative("box fit azimuth_step", params.azimuth_step)?;
    crate::error::ensure_non_negative("box fit search_cell", params.search_cell)?;
    if let Some(g) = ground_z {
        crate::error::ensure_finite("box fit ground_z", &[g])?;
    }
    Ok(())
}

/// Wraps a heading of an axis (direction unknown) to (−π/2, π/2].
fn heading_mod_pi(a: f64) -> f64 {
    let w = a - PI * (a / PI).round();
    if w <= -FRAC_PI_2 {
        w + PI
    } else {
        w
    }
}

/// Appends to `xy` (interleaved x–y, the first `n2` values) the first point of each
/// `cell`-sized square they occupy, in the order the points come, re-centred on their mean.
fn one_point_per_cell(xy: &mut Vec<f64>, n2: usize, cell: f64) {
    let keys: Vec<(i64, i64)> = xy[..n2]
        .chunks_exact(2)
        .map(|p| (floor_i64(p[0] / cell), floor_i64(p[1] / cell)))
        .collect();
    let first = first_in_each_cell(&keys);
    let m = first.len() as f64;
    let (mx, my) = first
        .iter()
        .fold((0.0, 0.0), |(x, y), &i| (x + xy[2 * i], y + xy[2 * i + 1]));
    let (mx, my) = (mx / m, my / m);
    xy.reserve(2 * first.len());
    for i in first {
        let (x, y) = (xy[2 * i] - mx, xy[2 * i + 1] - my);
        xy.push(x);
        xy.push(y);
    }
}

/// The positions in `keys` (cells) where a cell occurs for the first time, ascending: on a
/// dense grid of the cells' bounding box when that is small (a car at 0.1 m: ~1,000 cells),
/// else by sorting.
fn first_in_each_cell(keys: &[(i64, i64)]) -> Vec<usize> {
    let Some(&(x0, y0)) = keys.first() else {
        return Vec::new();
    };
    let (mut lo, mut hi) = ((x0, y0), (x0, y0));
    for &(x, y) in keys {
        lo = (lo.0.min(x), lo.1.min(y));
        hi = (hi.0.max(x), hi.1.max(y));
    }
    let (w, h) = ((hi.0 - lo.0) as u64 + 1, (hi.1 - lo.1) as u64 + 1);
    let cells = w.saturating_mul(h);
    if cells <= (8 * keys.len() as u64).max(1 << 12) {
        let mut seen = vec![false; cells as usize];
        return keys
            .iter()
            .enumerate()
            .filter_map(|(i, &(x, y))| {
                let c = ((y - lo.1) as u64 * w + (x - lo.0) as u64) as usize;
                (!std::mem::replace(&mut seen[c], true)).then_some(i)
            })
            .collect();
    }
    let mut sorted: Vec<(i64, i64, usize)> = keys
        .iter()
        .enumerate()
        .map(|(i, &(x, y))| (x, y, i))
        .collect();
    sorted.sort_unstable();
    sorted.dedup_by(|a, b| a.0 == b.0 && a.1 == b.1);
    let mut first: Vec<usize> = sorted.into_iter().map(|k| k.2).collect();
    first.sort_unstable();
    first
}

/// The heading in [0, π/2) maximising the closeness criterion over the interleaved x–y
/// coordinates `xy`, centred on their mean (see the module notes).
///
/// The candidates are the multiples of `angle_step`. With more than [`COARSE_STEPS`]·4 of
/// them the search runs coarse to fine: every [`COARSE_STEPS`]-th candidate is scored, then
/// every candidate within [`COARSE_STEPS`] − 1 steps of the two best coarse ones. Near its
/// peak the criterion falls off steadily as the heading turns away (the points leave the
/// edges in proportion to the angle), so the best coarse candidate lies next to the peak;
/// the second covers a cluster with two rival L's. Of the headings scored the highest wins,
/// the smallest on ties. The rectangle of each candidate is bounded by the points' convex
/// hull, whose vertices hold every extreme projection.
pub fn lshape_heading(xy: &[f64], params: &BoxFitParams) -> f64 {
    let steps = ((FRAC_PI_2 / params.angle_step).ceil() as usize).max(1);
    let hull = hull_xy(xy);
    // The candidates below π/2 among `ks`, with their scores.
    let scored = |mut ks: Vec<usize>| -> Vec<(f64, usize)> {
        ks.retain(|&k| (k as f64 * params.angle_step) < FRAC_PI_2);
        let mut out = Vec::with_capacity(ks.len());
        for batch in ks.chunks(LANES) {
            let mut lanes = [Heading::default(); LANES];
            for (lane, &k) in lanes.iter_mut().zip(batch) {
                *lane = Heading::new(&hull, k as f64 * params.angle_step);
            }
            let totals = closeness(xy, &lanes, params.min_distance);
            out.extend(batch.iter().zip(totals).map(|(&k, v)| (v, k)));
        }
        out
    };
    // (score, step), the higher score first, then the smaller step.
    let better = |a: (f64, usize), b: (f64, usize)| a.0 > b.0 || (a.0 == b.0 && a.1 < b.1);
    let mut best = (f64::NEG_INFINITY, 0);
    let mut consider = |candidates: &[(f64, usize)]| {
        for &c in candidates {
            if better(c, best) {
                best = c;
            }
        }
    };
    if steps <= 4 * COARSE_STEPS {
        consider(&scored((0..steps).collect()));
    } else {
        let coarse = scored((0..steps).step_by(COARSE_STEPS).collect());
        consider(&coarse);
        let mut top = [(f64::NEG_INFINITY, 0); 2];
        for &c in &coarse {
            if better(c, top[0]) {
                top = [c, top[0]];
            } else if better(c, top[1]) {
                top[1] = c;
            }
        }
        let fine = top
            .iter()
            .filter(|t| t.0 != f64::NEG_INFINITY)
            .flat_map(|&(_, kc)| {
                let lo = kc.saturating_sub(COARSE_STEPS - 1);
                let hi = (kc + COARSE_STEPS - 1).min(steps - 1);
                (lo..=hi).filter(|k| k % COARSE_STEPS != 0)
            });
        consider(&scored(fine.collect()));
    }
    best.1 as f64 * params.angle_step
}

/// Headings [`closeness`] scores at once: independent sums, one a lane.
const LANES: usize = 4;

/// One candidate heading of [`lshape_heading`]: its rotation and, per axis, the edge of the
/// rectangle the points' distances are taken to.
#[derive(Clone, Copy, Default)]
struct Heading {
    s: f64,
    c: f64,
    /// Per axis: the edge, and whether it is the lower one.
    edge: [f64; 2],
    lower: [bool; 2],
}

impl Heading {
    fn new(hull: &[f64], theta: f64) -> Self {
        let (s, c) = theta.sin_cos();
        let r = Rect::bounding_sc(hull, s, c);
        // Per axis, the edge whose distance vector has the smaller norm: Σ(a − lo)² ≤
        // Σ(hi − a)² ⟺ 2·Σa ≤ n·(lo + hi), and Σa = 0 for the centred points, so the lower
        // edge wins when lo + hi ≥ 0 (the mean lies in the rectangle's lower half).
        let lower = [r.lo[0] + r.hi[0] >= 0.0, r.lo[1] + r.hi[1] >= 0.0];
        let edge = [0, 1].map(|k| if lower[k] { r.lo[k] } else { r.hi[k] });
        Heading { s, c, edge, lower }
    }
}

/// The closeness criterion Σ 1 / max(min(d₁, d₂), d₀) of every heading in `lanes` (d the
/// distances of a point to the heading's two edges), each summed over the points in their
/// order, so every total is what a loop over one heading gives; the lanes' sums are
/// independent chains, and on x86-64 with AVX2 one vector instruction serves four (the same
/// operations, never fused).
fn closeness(xy: &[f64], lanes: &[Heading; LANES], d0: f64) -> [f64; LANES] {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has just been found to support AVX2.
        return unsafe { closeness_avx2(xy, lanes, d0) };
    }
    closeness_lanes(xy, lanes, d0)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn closeness_avx2(xy: &[f64], lanes: &[Heading; LANES], d0: f64) -> [f64; LANES] {
    closeness_lanes(xy, lanes, d0)
}

#[inline(always)]
fn closeness_lanes(xy: &[f64], lanes: &[Heading; LANES], d0: f64) -> [f64; LANES] {
    let s = lanes.map(|h| h.s);
    let c = lanes.map(|h| h.c);
    let e1 = lanes.map(|h| h.edge[0]);
    let e2 = lanes.map(|h| h.edge[1]);
    let l1 = lanes.map(|h| h.lower[0]);
    let l2 = lanes.map(|h| h.lower[1]);
    let mut total = [0.0f64; LANES];
    for p in xy.chunks_exact(2) {
        for l in 0..LANES {
            let (a, b) = (c[l] * p[0] + s[l] * p[1], -s[l] * p[0] + c[l] * p[1]);
            let d1 = if l1[l] { a - e1[l] } else { e1[l] - a };
            let d2 = if l2[l] { b - e2[l] } else { e2[l] - b };
            total[l] += 1.0 / d1.min(d2).max(d0);
        }
    }
    total
}

/// Candidate headings per coarse step of [`lshape_heading`].
pub const COARSE_STEPS: usize = 8;

/// The convex hull's vertices of the interleaved x–y coordinates `xy`, interleaved (every
/// point when there are fewer than three).
fn hull_xy(xy: &[f64]) -> Vec<f64> {
    if xy.len() < 6 {
        return xy.to_vec();
    }
    let mut pts: Vec<Point2<f64>> = xy
        .chunks_exact(2)
        .map(|p| Point2::new(p[0], p[1]))
        .collect();
    convex_hull(&mut pts)
        .into_iter()
        .flat_map(|p| [p.x, p.y])
        .collect()
}

/// An axis-aligned rectangle in the frame turned by θ: `lo[k] ≤ coordinate k ≤ hi[k]`.
#[derive(Copy, Clone, Debug, PartialEq)]
struct Rect {
    lo: [f64; 2],
    hi: [f64; 2],
}

impl Rect {
    fn bounding(xy: &[f64], theta: f64) -> Rect {
        let (s, c) = theta.sin_cos();
        Rect::bounding_sc(xy, s, c)
    }

    fn bounding_sc(xy: &[f64], s: f64, c: f64) -> Rect {
        let mut r = Rect {
            lo: [f64::INFINITY; 2],
            hi: [f64::NEG_INFINITY; 2],
        };
        for p in xy.chunks_exact(2) {
            let (a, b) = (c * p[0] + s * p[1], -s * p[0] + c * p[1]);
            r.lo = [r.lo[0].min(a), r.lo[1].min(b)];
            r.hi = [r.hi[0].max(a), r.hi[1].max(b)];
        }
        r
    }

    fn extent(&self, k: usize) -> f64 {
        self.hi[k] - self.lo[k]
    }

    fn centre(&self) -> [f64; 2] {
        [
            (self.lo[0] + self.hi[0]) / 2.0,
            (self.lo[1] + self.hi[1]) / 2.0,
        ]
    }

    /// Each side shorter than `target[k]` grown towards it away from `sensor` (the
    /// visible-face model, see the module notes): the near face stays, the far face moves;
    /// both move by half when the sensor lies between them. A side whose parallel face is in
    /// view grows by at most one sampling gap, `range·azimuth_step / sin α`.
    fn extended_away(&self, sensor: [f64; 2], target: [f64; 2], azimuth_step: f64) -> Rect {
        let [cx, cy] = self.centre();
        let range = (sensor[0] - cx).hypot(sensor[1] - cy);
        let mut r = *self;
        for k in 0..2 {
            let mut missing = target[k] - self.extent(k);
            if missing <= 0.0 {
                continue;
            }
            let j = 1 - k;
            let outside = (self.lo[j] - sensor[j]).max(sensor[j] - self.hi[j]);
            if outside > 0.0 && range > 0.0 {
                let sin_grazing = (outside / range).min(1.0);
                missing = missing.min(range * azimuth_step / sin_grazing);
            }
            if sensor[k] < self.lo[k] {
                r.hi[k] += missing;
            } else if sensor[k] > self.hi[k] {
                r.lo[k] -= missing;
            } else {
                r.lo[k] -= missing / 2.0;
                r.hi[k] += missing / 2.0;
            }
        }
        r
    }
}

/// Which rectangle axis (0 or 1) is the object's length. Without a prior, the longer side.
/// With one, the assignment of (length, width) to the two sides whose relative misfit
/// Σ ((target − side) / target)² is smaller, a side longer than its target counting four
/// times (an object is seen at most whole, so excess is the stronger evidence): a car seen
/// end-on shows a ≈ 1.6 m face and a short depth, which fits "width seen whole, length
/// hidden" better than "part of the length, part of the width".
fn choose_length_axis(rect: &Rect, prior: Option<&SizePrior>) -> usize {
    let (d0, d1) = (rect.extent(0), rect.extent(1));
    let Some(p) = prior.filter(|p| p.length > 0.0 && p.width > 0.0) else {
        return if d1 > d0 { 1 } else { 0 };
    };
    let misfit = |side: f64, target: f64| {
        let r = (target - side) / target;
        if r < 0.0 {
            4.0 * r * r
        } else {
            r * r
        }
    };
    let axis0 = misfit(d0, p.length) + misfit(d1, p.width);
    let axis1 = misfit(d1, p.length) + misfit(d0, p.width);
    if axis1 < axis0 {
        1
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::iou_bev;
    use crate::rng::seeded;
    use proptest::prelude::*;
    use rand::RngExt;

    const CAR: SizePrior = SizePrior {
        length: 4.5,
        width: 1.8,
    };

    /// Points on the faces of `b` that a sensor at the origin sees (outward normal towards
    /// it), `per_metre` per metre of face, z spread over the box's height, with uniform noise
    /// of ±`noise` metres across the face. Independent of the fitting code.
    fn visible_faces(b: &Box3, per_metre: f64, noise: f64, seed: u64) -> [Vec<f32>; 3] {
        let mut rng = seeded(seed);
        let c = b.bev_corners();
        let (mut xs, mut ys, mut zs) = (vec![], vec![], vec![]);
        let (z0, z1) = b.z_range();
        for i in 0..4 {
            let (p, q) = (c[i], c[(i + 1) % 4]);
            // Corners run counter-clockwise, so the outward normal is (dy, −dx).
            let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
            let len = dx.hypot(dy);
            let normal = [dy / len, -dx / len];
            let mid = [(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0];
            if normal[0] * -mid[0] + normal[1] * -mid[1] <= 0.0 {
                continue;
            }
            let count = (len * per_metre).round() as usize;
            for _ in 0..count {
                let t: f64 = rng.random_range(0.0..1.0);
                let e: f64 = rng.random_range(-noise..=noise);
                xs.push((p[0] + t * dx + e * normal[0]) as f32);
                ys.push((p[1] + t * dy + e * normal[1]) as f32);
                zs.push(rng.random_range(z0..z1) as f32);
            }
        }
        [xs, ys, zs]
    }

    fn axis_error(a: f64, b: f64) -> f64 {
        heading_mod_pi(a - b).abs()
    }

    fn bev_distance(a: &Box3, b: &Box3) -> f64 {
        (a.center.x - b.center.x).hypot(a.center.y - b.center.y)
    }

    #[test]
    fn corner_view_of_a_car_recovers_heading_and_centre() {
        let truth = Box3::new(Point3::new(12.0, 6.0, -0.95), [4.5, 1.8, 1.5], 0.4);
        let [xs, ys, zs] = visible_faces(&truth, 60.0, 0.02, 1);
        let mut scratch = Vec::new();
        let p = BoxFitParams::default();
        let fit = fit_box(&xs, &ys, &zs, Some(-1.7), Some(&CAR), &p, &mut scratch).unwrap();
        // Both faces are seen whole: the fitted box is already the truth.
        assert!(axis_error(fit.fitted.yaw, truth.yaw) < 0.6f64.to_radians());
        assert!(bev_distance(&fit.estimated, &truth) < 0.1);
        assert!(iou_bev(&fit.estimated, &truth) > 0.9, "{:?}", fit.estimated);
        assert!((fit.estimated.center.z - (-1.7 + (-0.2)) / 2.0).abs() < 0.02);
        assert_eq!(fit.points, xs.len());
    }

    #[test]
    fn a_short_car_seen_from_its_corner_is_not_stretched() {
        // 3.2 m long, 1.5 m wide (a small city car) at 6 m: both faces in full view.
        let truth = Box3::new(Point3::new(5.0, 3.5, -0.95), [3.2, 1.5, 1.5], 0.3);
        let [xs, ys, zs] = visible_faces(&truth, 100.0, 0.02, 4);
        let mut scratch = Vec::new();
        let p = BoxFitParams::default();
        let fit = fit_box(&xs, &ys, &zs, None, Some(&CAR), &p, &mut scratch).unwrap();
        // The sensor is 1.1 m off the plane of the side at 6.1 m (grazing angle ≈ 11°): the
        // side may hide one sampling gap, 6.1 · 0.0031 / 0.18 ≈ 0.1 m, instead of the 1.3 m
        // a mean-length car would add.
        assert!(fit.estimated.size[0] < 3.2 + 0.15, "{fit:?}");
        assert!(fit.estimated.size[1] < 1.6, "{fit:?}");
        assert!(bev_distance(&fit.estimated, &truth) < 0.08, "{fit:?}");
    }

    #[test]
    fn end_on_view_is_extended_away_from_the_sensor() {
        // A car straight ahead, heading along x: only its rear face (at x = 9.75) is visible.
        let truth = Box3::new(Point3::new(12.0, 0.3, -0.95), [4.5, 1.8, 1.5], 0.0);
        let [xs, ys, zs] = visible_faces(&truth, 80.0, 0.02, 2);
        let mut scratch = Vec::new();
        let p = BoxFitParams::default();
        let fit = fit_box(&xs, &ys, &zs, None, Some(&CAR), &p, &mut scratch).unwrap();
        assert!(
            axis_error(fit.estimated.yaw, 0.0) < 1f64.to_radians(),
            "{fit:?}"
        );
        assert!((fit.estimated.size[0] - 4.5).abs() < 1e-9);
        // The fitted rectangle's centre sits on the rear face, ~2.2 m short of the centre;
        // the estimated box's centre is the truth's to within the noise.
        assert!(bev_distance(&fit.fitted, &truth) > 2.0);
        assert!(bev_distance(&fit.estimated, &truth) < 0.1, "{fit:?}");
        // Without a prior the rear face is the longer side: the fitted box comes back.
        let bare = fit_box(&xs, &ys, &zs, None, None, &p, &mut scratch).unwrap();
        assert_eq!(bare.estimated, bare.fitted);
        assert!(axis_error(bare.fitted.yaw, FRAC_PI_2) < 1f64.to_radians());
    }

    #[test]
    fn side_view_extends_the_width_away() {
        // A car to the left, parallel to x: its right side (y = 4.1) is seen, 4.5 m long.
        let truth = Box3::new(Point3::new(0.5, 5.0, -0.95), [4.5, 1.8, 1.5], 0.0);
        let [xs, ys, zs] = visible_faces(&truth, 60.0, 0.02, 3);
        let mut scratch = Vec::new();
        let p = BoxFitParams::default();
        let fit = fit_box(&xs, &ys, &zs, None, Some(&CAR), &p, &mut scratch).unwrap();
        assert!(axis_error(fit.estimated.yaw, 0.0) < 1f64.to_radians());
        assert!(fit.estimated.center.y > fit.fitted.center.y + 0.8);
        assert!(bev_distance(&fit.estimated, &truth) < 0.1, "{fit:?}");
    }

    #[test]
    fn heading_search_on_a_hand_made_l() {
        // Points on the lines y = 0 (x in 0..4) and x = 0 (y in 0..2), turned by 30°.
        let turn = 30f64.to_radians();
        let (s, c) = turn.sin_cos();
        let mut xy = Vec::new();
        for i in 0..=40 {
            let (x, y) = (i as f64 * 0.1, 0.0);
            xy.extend([c * x - s * y, s * x + c * y]);
        }
        for i in 1..=20 {
            let (x, y) = (0.0, i as f64 * 0.1);
            xy.extend([c * x - s * y, s * x + c * y]);
        }
        let p = BoxFitParams {
            angle_step: 1f64.to_radians(),
            ..Default::default()
        };
        assert!((lshape_heading(&xy, &p) - turn).abs() < 1e-9);
    }

    #[test]
    fn bad_input_is_an_error() {
        let mut scratch = Vec::new();
        let p = BoxFitParams::default();
        assert!(fit_box(&[], &[], &[], None, None, &p, &mut scratch).is_err());
        assert!(fit_box(&[1.0], &[1.0, 2.0], &[0.0], None, None, &p, &mut scratch).is_err());
        let msg = fit_box(
            &[1.0, f32::NAN],
            &[1.0; 2],
            &[0.0; 2],
            None,
            None,
            &p,
            &mut scratch,
        )
        .unwrap_err()
        .to_string();
        assert!(msg.contains("point 1"), "{msg}");
        let zero = BoxFitParams {
            angle_step: 0.0,
            ..p
        };
        assert!(fit_box(&[1.0], &[1.0], &[0.0], None, None, &zero, &mut scratch).is_err());
        let cloud = PointCloud::from_records(&[[1.0, 2.0, 0.0, 0.0]]);
        let mut bs = BoxScratch::default();
        assert!(fit_box_of(&cloud, &[1], None, None, &p, &mut bs).is_err());
        let one = fit_box_of(&cloud, &[0], None, None, &p, &mut bs).unwrap();
        assert_eq!(one.fitted.size, [0.0, 0.0, 0.0]);
        assert!((one.fitted.center.x - 1.0).abs() < 1e-12);
        let outline = outline_of(&cloud, &[0], None, &p, &mut bs).unwrap();
        let negative = SizePrior {
            length: -1.0,
            width: 1.0,
        };
        let msg = outline.fit(Some(&negative)).unwrap_err().to_string();
        assert!(msg.contains("size prior length"), "{msg}");
    }

    #[test]
    fn one_outline_gives_the_boxes_of_every_prior() {
        // A car seen from its corner, fitted bare and with two priors from one heading search.
        let b = Box3::new(Point3::new(12.0, 5.0, -0.9), [4.5, 1.8, 1.5], 0.3);
        let [xs, ys, zs] = visible_faces(&b, 40.0, 0.02, 5);
        let p = BoxFitParams::default();
        let mut scratch = Vec::new();
        let outline = BoxOutline::of(&xs, &ys, &zs, Some(-1.73), &p, &mut scratch).unwrap();
        let van = SizePrior {
            length: 5.1,
            width: 1.9,
        };
        for prior in [None, Some(&CAR), Some(&van)] {
            let alone = fit_box(&xs, &ys, &zs, Some(-1.73), prior, &p, &mut scratch).unwrap();
            assert_eq!(outline.fit(prior).unwrap(), alone);
        }
        // The van's footprint pushes the far faces out: a longer box, centred further away.
        let (car, van) = (
            outline.fit(Some(&CAR)).unwrap(),
            outline.fit(Some(&van)).unwrap(),
        );
        assert!(van.estimated.size[0] > car.estimated.size[0] + 0.5);
        let r = |f: &BoxFit| f.estimated.center.x.hypot(f.estimated.center.y);
        assert!(r(&van) > r(&car));
    }

    /// The closeness criterion of Zhang et al. (Algorithm 4) at heading `theta`, computed as
    /// the paper states it: every point projected, the bounding edges from all projections,
    /// per axis the edge whose distance vector has the smaller norm.
    fn closeness_reference(xy: &[[f64; 2]], theta: f64, d0: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        let c1: Vec<f64> = xy.iter().map(|p| c * p[0] + s * p[1]).collect();
        let c2: Vec<f64> = xy.iter().map(|p| -s * p[0] + c * p[1]).collect();
        let nearer = |v: &[f64]| -> Vec<f64> {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let to_lo: Vec<f64> = v.iter().map(|a| a - lo).collect();
            let to_hi: Vec<f64> = v.iter().map(|a| hi - a).collect();
            let norm = |d: &[f64]| d.iter().map(|x| x * x).sum::<f64>();
            if norm(&to_lo) <= norm(&to_hi) {
                to_lo
            } else {
                to_hi
            }
        };
        let (d1, d2) = (nearer(&c1), nearer(&c2));
        d1.iter()
            .zip(&d2)
            .map(|(a, b)| 1.0 / a.min(*b).max(d0))
            .sum()
    }

    proptest! {
        /// The first point of every occupied cell, on the dense grid or by sorting (a spread
        /// of keys too wide for the grid), is what a plain scan with a set of seen cells keeps.
        #[test]
        fn first_in_each_cell_keeps_each_cells_first_point(
            keys in proptest::collection::vec((-40i64..40, -40i64..40), 0..300),
            spread in prop_oneof![Just(1i64), Just(1_000_000_000)],
        ) {
            let keys: Vec<(i64, i64)> = keys.iter().map(|&(x, y)| (x * spread, y)).collect();
            let mut seen = std::collections::HashSet::new();
            let expected: Vec<usize> = (0..keys.len()).filter(|&i| seen.insert(keys[i])).collect();
            prop_assert_eq!(first_in_each_cell(&keys), expected);
        }
    }

    proptest! {
        /// Headings scored four at once (on vector lanes where the CPU has them) get, bit for
        /// bit, the total of a plain loop over one heading's points in their order.
        #[test]
        fn headings_scored_together_sum_as_one_at_a_time(
            pts in proptest::collection::vec((-5.0..5.0f64, -5.0..5.0f64), 1..80),
            thetas in proptest::array::uniform4(0.0..FRAC_PI_2),
            d0 in 0.001..0.5f64,
        ) {
            let xy: Vec<f64> = pts.iter().flat_map(|&(x, y)| [x, y]).collect();
            let hull = hull_xy(&xy);
            let lanes = thetas.map(|t| Heading::new(&hull, t));
            let together = closeness(&xy, &lanes, d0);
            for (h, total) in lanes.iter().zip(together) {
                let mut alone = 0.0;
                for p in xy.chunks_exact(2) {
                    let (a, b) = (h.c * p[0] + h.s * p[1], -h.s * p[0] + h.c * p[1]);
                    let d1 = if h.lower[0] { a - h.edge[0] } else { h.edge[0] - a };
                    let d2 = if h.lower[1] { b - h.edge[1] } else { h.edge[1] - b };
                    alone += 1.0 / d1.min(d2).max(d0);
                }
                prop_assert_eq!(total.to_bits(), alone.to_bits());
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// The coarse-to-fine search finds the heading an exhaustive search over every
        /// candidate finds, on the visible faces of cars, vans and pedestrians seen from any
        /// side, near and far.
        #[test]
        fn coarse_to_fine_search_matches_the_exhaustive_one(
            yaw in -3.2..3.2f64,
            range in 3.0..40.0f64,
            bearing in -3.2..3.2f64,
            size in prop_oneof![Just((4.5, 1.8)), Just((5.5, 2.1)), Just((0.8, 0.6))],
            noise in 0.0..0.04f64,
            seed in 0u64..1000,
        ) {
            let b = Box3::new(
                Point3::new(range * bearing.cos(), range * bearing.sin(), -1.0),
                [size.0, size.1, 1.5],
                yaw,
            );
            let [xs, ys, _] = visible_faces(&b, 40.0, noise, seed);
            prop_assume!(xs.len() >= 3);
            let n = xs.len() as f64;
            let (mx, my) = (
                xs.iter().map(|&x| x as f64).sum::<f64>() / n,
                ys.iter().map(|&y| y as f64).sum::<f64>() / n,
            );
            let pts: Vec<[f64; 2]> =
                xs.iter().zip(&ys).map(|(&x, &y)| [x as f64 - mx, y as f64 - my]).collect();
            let xy: Vec<f64> = pts.iter().flatten().copied().collect();
            let p = BoxFitParams::default();
            let steps = (FRAC_PI_2 / p.angle_step).ceil() as usize;
            let (best_k, best) = (0..steps)
                .map(|k| (k, closeness_reference(&pts, k as f64 * p.angle_step, p.min_distance)))
                .fold((0, f64::NEG_INFINITY), |a, b| if b.1 > a.1 { b } else { a });
            let found = lshape_heading(&xy, &p);
            let score = closeness_reference(&pts, found, p.min_distance);
            prop_assert!(
                score >= best * (1.0 - 1e-9),
                "found {:.2}° scoring {score}, exhaustive {:.2}° scoring {best}",
                found.to_degrees(),
                (best_k as f64 * p.angle_step).to_degrees()
            );
        }

        #[test]
        fn boxes_hold_the_points_and_grow_at_most_to_the_prior(
            pts in proptest::collection::vec((-30.0..30.0f32, -30.0..30.0f32, -2.0..1.0f32), 1..60),
            length in 0.0..6.0f64,
            width in 0.0..3.0f64,
        ) {
            let xs: Vec<f32> = pts.iter().map(|p| p.0).collect();
            let ys: Vec<f32> = pts.iter().map(|p| p.1).collect();
            let zs: Vec<f32> = pts.iter().map(|p| p.2).collect();
            let prior = SizePrior { length, width };
            let mut scratch = Vec::new();
            let p = BoxFitParams { angle_step: 2f64.to_radians(), ..Default::default() };
            let fit = fit_box(&xs, &ys, &zs, None, Some(&prior), &p, &mut scratch).unwrap();
            for i in 0..xs.len() {
                let q = Point3::new(xs[i] as f64, ys[i] as f64, zs[i] as f64);
                prop_assert!(fit.fitted.contains(&q, 1e-4));
                prop_assert!(fit.estimated.contains(&q, 1e-4));
            }
            prop_assert!(fit.estimated.size[0] + 1e-9 >= fit.fitted.size[0]);
            prop_assert!(fit.estimated.size[1] + 1e-9 >= fit.fitted.size[1]);
            // Never past the prior: the box grows to it at most.
            prop_assert!(fit.estimated.size[0] <= fit.fitted.size[0].max(length) + 1e-9);
            prop_assert!(fit.estimated.size[1] <= fit.fitted.size[1].max(width) + 1e-9);
            prop_assert!(fit.fitted.yaw > -FRAC_PI_2 && fit.fitted.yaw <= FRAC_PI_2);
        }
    }
}
