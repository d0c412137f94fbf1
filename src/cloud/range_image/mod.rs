//! The range image of one spinning multi-beam lidar scan (an HDL-64E in KITTI): rows are the
//! rings (beams), highest elevation first; columns are azimuth bins. Each cell holds the
//! index of the nearest point that falls into it and that point's range, so that the
//! neighbours of a point on the sensor's own grid are found in constant time. On it:
//! column-wise ground segmentation ([`ground`]) and angle-criterion clustering
//! ([`cluster`]), both linear in the points.
//!
//! # Which ring a point is on
//! * **Scan order** ([`RingSource::ScanOrder`]), used when the points come ring after ring:
//!   KITTI's `.bin` keeps each laser's full turn in firing order (the azimuth grows through a
//!   whole turn, then the next laser starts again at the cut, the sensor's +x axis). The
//!   azimuth progress summed over consecutive points (each step wrapped to (−π, π]) is then
//!   about one turn per ring, and the ring of a point is how many whole turns lie before it.
//!   The first ring may start late (its laser saw nothing near the cut), so the cut is not the
//!   first point's azimuth: the lead-in `g` (`ring = ⌊(progress + g) / 2π⌋`) is chosen in
//!   `[0, g_max]` (`g_max` is what the last turn leaves over) as the value that puts the
//!   points near the ring boundaries on the ring whose median elevation is closest to theirs
//!   (the sum of absolute tan-elevation misfits is minimised exactly by one sweep over the
//!   lead-ins at which those points change ring).
//!   A step backwards by more than 1° is taken as a forward gap of more than half a turn (a
//!   ring that saw nothing over a wide sector, or ended early); a ring with no point at all
//!   cannot be seen and the image simply has one row less. Rings are then sorted by median
//!   elevation into rows. This order is accepted when the scan makes more than one and a
//!   half turns, at most [`RangeImageConfig::max_rings`], and at most 1 % of the steps run
//!   backwards by more than 1° or jump forward by more than 45°.
//! * **Elevation** ([`RingSource::Elevation`]), used otherwise: points stored column by
//!   column (one turn in all: the simulated street's lidar, raw packet order) or re-sorted
//!   (a LAS/PLY file written in another order). Rows are the groups of the sorted elevations
//!   split at gaps wider than a quarter of the mean beam spacing of
//!   [`RangeImageConfig::rows`] beams over the observed elevation span; when that does not
//!   give between 2 and `max_rings` groups (beams blurred into each other, as the HDL-64E's
//!   per-laser offsets do at short range), `rows` equal elevation bins between the 0.5 % and
//!   99.5 % quantiles. Exact for a lidar whose beams leave from one point (the simulation),
//!   approximate for a real HDL-64E near the car.
//!
//! Columns: the azimuth (in the direction of rotation) binned into
//! [`RangeImageConfig::columns`] bins, or, when that is `None`, as many bins as the scan's
//! typical azimuth step between consecutive points of a ring fits in a turn (for KITTI about
//! 2,080; a scan subsampled to every 8th point gets about 260). Column 0 starts at azimuth 0.
//! Two points of one cell: the nearer one holds the cell; the other keeps its cell
//! coordinates ([`RangeImage::cell_of`]) and follows the holder's labels.
//!
//! # Bad input
//! Points with a non-finite coordinate, or at the sensor's origin (no direction), get no
//! cell; their number is [`RangeImage::skipped`]. A cloud with no usable point, or more than
//! 2³² − 1 points, is an error. Never panics.
//!
//! Not for: clouds that are not one turn of a spinning scanner seen from its own origin
//! (merged or transformed clouds), nor fitting planes (see [`super::planes`]).

pub mod cluster;
pub mod ground;

pub use cluster::{range_image_clusters, ImageClusterParams};
pub use ground::{ground_mask, GroundParams};

use super::PointCloud;
use crate::error::{Error, Result};
use crate::numerics::atan::atan2;
use std::f64::consts::TAU;

/// No point / no cell.
pub const NONE: u32 = u32::MAX;

/// How [`RangeImage::new`] lays out the scan.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RangeImageConfig {
    /// Number of beams expected (rows of the elevation fallback). Default 64 (HDL-64E).
    pub rows: usize,
    /// Azimuth bins; `None` derives them from the scan. Default `None`.
    pub columns: Option<usize>,
    /// Most rings the scan order may give before it is rejected. Default 256.
    pub max_rings: usize,
}

impl Default for RangeImageConfig {
    fn default() -> Self {
        RangeImageConfig {
            rows: 64,
            columns: None,
            max_rings: 256,
        }
    }
}

/// Where the rows came from.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum RingSource {
    /// Ring after ring in firing order (KITTI `.bin`).
    ScanOrder,
    /// Binned by elevation angle.
    Elevation,
}

/// A scan laid out on its rings and azimuth bins. See the module documentation.
#[derive(Clone, Debug)]
pub struct RangeImage {
    rows: usize,
    cols: usize,
    source: RingSource,
    /// Per point: its cell `row * cols + col`, or [`NONE`].
    cell_of: Vec<u32>,
    /// Per cell: the nearest point in it, or [`NONE`].
    holder: Vec<u32>,
    /// Per cell: the holder's range (m), `f32::INFINITY` when empty.
    range: Vec<f32>,
    skipped: usize,
}

/// Most columns a derived or configured layout may have.
const MAX_COLUMNS: usize = 1 << 15;
/// Fewest columns a derived layout gets.
const MIN_COLUMNS: usize = 16;

impl RangeImage {
    /// Lays `cloud` out on its rings and azimuth bins (see the module documentation).
    pub fn new(cloud: &PointCloud, config: &RangeImageConfig) -> Result<RangeImage> {
        if config.rows == 0 || config.max_rings < 2 {
            return Err(Error::invalid(
                "range image config",
                format!(
                    "rows {} and max_rings {} (need rows ≥ 1, max_rings ≥ 2)",
                    config.rows, config.max_rings
                ),
            ));
        }
        if let Some(c) = config.columns {
            if !(1..=MAX_COLUMNS).contains(&c) {
                return Err(Error::invalid(
                    "range image columns",
                    format!("{c} (must be 1 ..= {MAX_COLUMNS})"),
                ));
            }
        }
        if cloud.len() >= u32::MAX as usize {
            return Err(Error::invalid(
                "range image input",
                format!("{} points (at most 2³² − 2)", cloud.len()),
            ));
        }
        let (xs, ys, zs) = (cloud.xs(), cloud.ys(), cloud.zs());
        // Usable points, their azimuth and tan(elevation).
        let mut used: Vec<u32> = Vec::with_capacity(cloud.len());
        for i in 0..cloud.len() {
            let (x, y, z) = (xs[i], ys[i], zs[i]);
            if x.is_finite() && y.is_finite() && z.is_finite() && (x != 0.0 || y != 0.0) {
                used.push(i as u32);
            }
        }
        if used.is_empty() {
            return Err(Error::invalid(
                "range image input",
                format!(
                    "no point with a finite position off the sensor's axis among {}",
                    cloud.len()
                ),
            ));
        }
        let az: Vec<f64> = used
            .iter()
            .map(|&i| atan2(ys[i as usize] as f64, xs[i as usize] as f64))
            .collect();
        let tan_el: Vec<f32> = used
            .iter()
            .map(|&i| {
                let i = i as usize;
                zs[i] / (xs[i] * xs[i] + ys[i] * ys[i]).sqrt()
            })
            .collect();

        let order = scan_order_rings(&az, &tan_el, config.max_rings);
        let (source, dir, ring_of, rings) = match order {
            Some((dir, ring_of, rings)) => (RingSource::ScanOrder, dir, ring_of, rings),
            None => {
                let (ring_of, rings) = elevation_rings(&tan_el, config);
                // Direction does not matter without an order: counter-clockwise.
                (RingSource::Elevation, 1.0, ring_of, rings)
            }
        };
        // Rows: rings by median elevation, highest first.
        let row_of_ring = rows_by_elevation(&ring_of, &tan_el, rings);
        let cols = match config.columns {
            Some(c) => c,
            None => derive_columns(&az, &ring_of, source, dir),
        };

        let mut cell_of = vec![NONE; cloud.len()];
        let mut holder = vec![NONE; rings * cols];
        let mut range = vec![f32::INFINITY; rings * cols];
        let scale = cols as f64 / TAU;
        for (k, &i) in used.iter().enumerate() {
            let a = dir * az[k];
            let a = if a < 0.0 { a + TAU } else { a };
            let col = ((a * scale) as usize).min(cols - 1);
            let row = row_of_ring[ring_of[k] as usize] as usize;
            let cell = row * cols + col;
            let i = i as usize;
            let r = (xs[i] * xs[i] + ys[i] * ys[i] + zs[i] * zs[i]).sqrt();
            cell_of[i] = cell as u32;
            if r < range[cell] {
                range[cell] = r;
                holder[cell] = i as u32;
            }
        }
        Ok(RangeImage {
            rows: rings,
            cols,
            source,
            cell_of,
            holder,
            range,
            skipped: cloud.len() - used.len(),
        })
    }

    /// Number of rows (rings).
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of columns (azimuth bins).
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Where the rows came from.
    pub fn source(&self) -> RingSource {
        self.source
    }

    /// Number of points that got no cell (non-finite, or on the sensor's vertical axis).
    pub fn skipped(&self) -> usize {
        self.skipped
    }

    /// Number of points the image was built from (usable or not).
    pub fn points(&self) -> usize {
        self.cell_of.len()
    }

    /// An error unless `cloud` has as many points as the image was built from (the image's
    /// cells index the points of the cloud it was built from).
    pub fn check_cloud(&self, cloud: &PointCloud) -> Result<()> {
        if self.points() != cloud.len() {
            return Err(Error::invalid(
                "range image",
                format!(
                    "built from {} points, the cloud has {}",
                    self.points(),
                    cloud.len()
                ),
            ));
        }
        Ok(())
    }

    /// The (row, column) of point `i`, `None` when it has no cell or is out of range.
    pub fn cell_of(&self, i: usize) -> Option<(usize, usize)> {
        match self.cell_of.get(i) {
            Some(&c) if c != NONE => Some((c as usize / self.cols, c as usize % self.cols)),
            _ => None,
        }
    }

    /// The point holding cell (row, col), `None` when it is empty or outside the image.
    pub fn point_at(&self, row: usize, col: usize) -> Option<u32> {
        if row >= self.rows || col >= self.cols {
            return None;
        }
        Some(self.holder[row * self.cols + col]).filter(|&p| p != NONE)
    }

    /// The range (m) of the point holding cell (row, col).
    pub fn range_at(&self, row: usize, col: usize) -> Option<f32> {
        self.point_at(row, col)
            .map(|_| self.range[row * self.cols + col])
    }

    /// Number of cells holding a point.
    pub fn occupied(&self) -> usize {
        self.holder.iter().filter(|&&p| p != NONE).count()
    }

    /// Per point, its flat cell index or [`NONE`] (crate-internal, for the passes over it).
    pub(crate) fn cells_of_points(&self) -> &[u32] {
        &self.cell_of
    }

    /// Per cell, its holder or [`NONE`].
    pub(crate) fn holders(&self) -> &[u32] {
        &self.holder
    }
}

/// Rings from the scan order: `(direction, ring per used point, ring count)`, or `None` when
/// the points are not ring after ring (see the module documentation).
fn scan_order_rings(
    az: &[f64],
    tan_el: &[f32],
    max_rings: usize,
) -> Option<(f64, Vec<u32>, usize)> {
    let n = az.len();
    if n < 3 {
        return None;
    }
    let wrap = |d: f64| {
        if d > std::f64::consts::PI {
            d - TAU
        } else if d <= -std::f64::consts::PI {
            d + TAU
        } else {
            d
        }
    };
    let total: f64 = (1..n).map(|k| wrap(az[k] - az[k - 1])).sum();
    let dir = if total < 0.0 { -1.0 } else { 1.0 };
    let back = 1f64.to_radians();
    let jump = std::f64::consts::FRAC_PI_4;
    let bad = (1..n)
        .filter(|&k| {
            let s = dir * wrap(az[k] - az[k - 1]);
            s < -back || s > jump
        })
        .count();
    if bad * 100 > n - 1 {
        return None;
    }
    // Progress (rad, in the direction of rotation) from the first point. A step back by
    // more than `back` is a forward gap of more than half a turn (a ring that saw nothing
    // over a large sector, or that ended early), not the scanner turning back.
    let mut progress = Vec::with_capacity(n);
    let mut u = 0.0;
    progress.push(0.0);
    for k in 1..n {
        let s = dir * wrap(az[k] - az[k - 1]);
        u += if s < -back { s + TAU } else { s };
        progress.push(u);
    }
    let last = progress[n - 1].max(0.0);
    if last < 1.5 * TAU {
        return None;
    }
    let rings = (last / TAU).floor() as usize + 1;
    if rings < 2 || rings > max_rings {
        return None;
    }
    let g_max = rings as f64 * TAU - last;
    // Whole turns before a point and the lead-in that moves it on to the next ring (progress
    // is ≥ 0 up to jitter, so truncation is the floor).
    let turn = |u: f64| ((u.max(0.0) / TAU) as usize).min(rings - 1);
    let threshold = |u: f64| (turn(u) + 1) as f64 * TAU - u.max(0.0);
    // Reference elevation per ring from the points that no lead-in in [0, g_max] moves.
    let mut per_ring: Vec<Vec<f32>> = vec![Vec::new(); rings];
    for k in (0..n).step_by(2) {
        if threshold(progress[k]) > g_max {
            per_ring[turn(progress[k])].push(tan_el[k]);
        }
    }
    let reference: Vec<f32> = per_ring.iter_mut().map(|v| median(v)).collect();
    let misfit = |k: usize, ring: usize| -> f64 {
        match reference.get(ring) {
            Some(r) if !r.is_nan() => (tan_el[k] - r).abs() as f64,
            _ => 1.0,
        }
    };
    // Each movable point, by the lead-in that moves it, with the change of misfit when it
    // moves; the best lead-in is 0 or just past one of these thresholds (a sweep over their
    // sorted order with a running sum).
    let mut moves: Vec<(f64, f64)> = (0..n)
        .filter(|&k| threshold(progress[k]) <= g_max)
        .map(|k| {
            let r = turn(progress[k]);
            (threshold(progress[k]), misfit(k, r + 1) - misfit(k, r))
        })
        .collect();
    moves.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let (mut best, mut g, mut sum) = (0.0f64, 0.0f64, 0.0f64);
    for &(t, delta) in &moves {
        sum += delta;
        if sum < best {
            best = sum;
            g = t + 1e-9;
        }
    }
    let ring_with = |u: f64| {
        let u = u.max(0.0) + g;
        (((u / TAU) as usize).min(rings - 1)) as u32
    };
    let ring_of = progress.iter().map(|&u| ring_with(u)).collect();
    Some((dir, ring_of, rings))
}

/// Rings by elevation: `(ring per used point, ring count)`, ring 0 the lowest elevation.
fn elevation_rings(tan_el: &[f32], config: &RangeImageConfig) -> (Vec<u32>, usize) {
    let mut sorted = tan_el.to_vec();
    sorted.sort_unstable_by(f32::total_cmp);
    let n = sorted.len();
    let (lo, hi) = (sorted[0], sorted[n - 1]);
    let gap = 0.25 * (hi - lo) / config.rows as f32;
    // Group starts: the first value and every value after a wide gap.
    let mut starts: Vec<f32> = vec![lo];
    for w in sorted.windows(2) {
        if gap > 0.0 && w[1] - w[0] > gap {
            starts.push(w[1]);
        }
    }
    if (2..=config.max_rings).contains(&starts.len()) {
        let ring_of = tan_el
            .iter()
            .map(|&t| (starts.partition_point(|&s| s <= t) - 1) as u32)
            .collect();
        return (ring_of, starts.len());
    }
    let q = |p: f64| sorted[((p * (n - 1) as f64).round() as usize).min(n - 1)];
    let (a, b) = (q(0.005), q(0.995));
    let rows = config.rows;
    let width = (b - a) / rows as f32;
    let ring_of = tan_el
        .iter()
        .map(|&t| {
            if width > 0.0 {
                (((t - a) / width).floor().max(0.0) as usize).min(rows - 1) as u32
            } else {
                0
            }
        })
        .collect();
    (ring_of, rows)
}

/// Row of each ring: rings sorted by median tan(elevation), highest first (ties by ring).
fn rows_by_elevation(ring_of: &[u32], tan_el: &[f32], rings: usize) -> Vec<u32> {
    let mut per_ring: Vec<Vec<f32>> = vec![Vec::new(); rings];
    let stride = (ring_of.len() / (64 * rings)).max(1);
    for k in (0..ring_of.len()).step_by(stride) {
        per_ring[ring_of[k] as usize].push(tan_el[k]);
    }
    let medians: Vec<f32> = per_ring.iter_mut().map(|v| median(v)).collect();
    let mut order: Vec<usize> = (0..rings).collect();
    // Empty rings (NaN median) go last.
    order.sort_by(|&a, &b| {
        let (ma, mb) = (medians[a], medians[b]);
        match (ma.is_nan(), mb.is_nan()) {
            (false, false) => mb.total_cmp(&ma).then(a.cmp(&b)),
            (true, true) => a.cmp(&b),
            (x, _) => x.cmp(&false).then(a.cmp(&b)),
        }
    });
    let mut row_of = vec![0u32; rings];
    for (row, &ring) in order.iter().enumerate() {
        row_of[ring] = row as u32;
    }
    row_of
}

/// Columns from the typical azimuth step between consecutive points of one ring: in scan
/// order the median step, otherwise the lower quartile of the steps of the fullest row once
/// sorted by azimuth (dropouts make some steps multiples of the spacing).
fn derive_columns(az: &[f64], ring_of: &[u32], source: RingSource, dir: f64) -> usize {
    let small = std::f64::consts::FRAC_PI_4;
    let mut steps: Vec<f64> = match source {
        RingSource::ScanOrder => (1..az.len())
            .filter(|&k| ring_of[k] == ring_of[k - 1])
            .map(|k| dir * (az[k] - az[k - 1]))
            .filter(|&s| s > 0.0 && s < small)
            .collect(),
        RingSource::Elevation => {
            let rings = ring_of.iter().max().map_or(0, |&r| r as usize + 1);
            let mut count = vec![0usize; rings];
            for &r in ring_of {
                count[r as usize] += 1;
            }
            let full = (0..rings)
                .max_by_key(|&r| (count[r], usize::MAX - r))
                .unwrap_or(0);
            let mut a: Vec<f64> = az
                .iter()
                .zip(ring_of)
                .filter(|(_, &r)| r as usize == full)
                .map(|(&a, _)| a)
                .collect();
            a.sort_unstable_by(f64::total_cmp);
            a.windows(2)
                .map(|w| w[1] - w[0])
                .filter(|&s| s > 1e-7 && s < small)
                .collect()
        }
    };
    if steps.is_empty() {
        return 2048;
    }
    let q = match source {
        RingSource::ScanOrder => 0.5,
        RingSource::Elevation => 0.25,
    };
    let k = ((steps.len() - 1) as f64 * q) as usize;
    let (_, step, _) = steps.select_nth_unstable_by(k, f64::total_cmp);
    ((TAU / *step).round() as usize).clamp(MIN_COLUMNS, MAX_COLUMNS)
}

/// Median of `v` (reorders it); NaN for an empty slice.
fn median(v: &mut [f32]) -> f32 {
    if v.is_empty() {
        return f32::NAN;
    }
    let k = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(k, f32::total_cmp);
    *m
}

#[cfg(test)]
mod tests;
