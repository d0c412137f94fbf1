//! [`PlanarGrid`]: exact nearest-neighbour queries over a fixed set of planar points, for the
//! scan matching's pairing step, which asks for the nearest target point of every source
//! point once per iteration.
//!
//! The points are sorted into a uniform grid of square cells (a counting sort: one offset
//! per cell and the point indices cell by cell, so a cell's points are one contiguous run).
//! A query visits the cells ring by ring around its own cell and stops once the next ring
//! cannot hold anything nearer than the best point found (or than the query's bound). Near a
//! wall the answer comes from the first two rings, a handful of array reads. A query may
//! name a hint, a point it expects to be near (an iterative matcher's last answer): only the
//! cells within the hint's distance are then searched, usually one to four. Exact either way:
//! the same answer as a brute-force search, ties going to the lowest point index.
//!
//! Not for: point sets that change between queries (rebuild instead; building is linear in
//! the points and cells), or k nearest neighbours.

use crate::numerics::floor::floor_i64;
use crate::numerics::sym2::symmetric2_eigenvalues;

/// A uniform grid over a fixed planar point set; see the module docs.
#[derive(Clone, Debug)]
pub struct PlanarGrid {
    cell: f64,
    origin: [f64; 2],
    nx: usize,
    ny: usize,
    /// `start[c]..start[c + 1]` are cell `c`'s entries in `items` and `coords` (c = i·ny + j).
    start: Vec<u32>,
    /// Point indices, cell by cell.
    items: Vec<u32>,
    /// Their coordinates, in the same order.
    coords: Vec<[f64; 2]>,
    /// The coordinates in the caller's order (for hints).
    points: Vec<[f64; 2]>,
    /// Per point, a quarter of the squared distance to its nearest other point; NaN until a
    /// hint needs it.
    separation: Vec<f64>,
    /// Per point, the normal of the line through it and its neighbours (see
    /// [`PlanarGrid::line_normal`]), once asked for.
    normals: Vec<Option<Option<[f64; 2]>>>,
}

/// At most this many cells per point (plus a few): a sparse, wide point set gets larger
/// cells rather than a huge empty grid.
const CELLS_PER_POINT: f64 = 8.0;

impl PlanarGrid {
    /// The grid of `points` with cells of side `cell` metres, enlarged where the points'
    /// extent would need more than about eight cells per point. `None` when there is no
    /// point, a coordinate is not finite, `cell` is not positive and finite, or there are
    /// 2³² points or more.
    pub fn new(points: &[[f64; 2]], cell: f64) -> Option<Self> {
        if points.is_empty()
            || points.len() >= u32::MAX as usize
            || !(cell.is_finite() && cell > 0.0)
            || points
                .iter()
                .any(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return None;
        }
        let (mut lo, mut hi) = (points[0], points[0]);
        for p in points {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let budget = CELLS_PER_POINT * points.len() as f64 + 64.0;
        let area = |c: f64| ((hi[0] - lo[0]) / c + 1.0) * ((hi[1] - lo[1]) / c + 1.0);
        let mut cell = cell;
        if area(cell) > budget {
            // The side at which the extent fits the budget (the +1 per axis aside), then
            // doubled until it does.
            cell = cell.max(((hi[0] - lo[0]) * (hi[1] - lo[1]) / budget).sqrt());
            while area(cell) > budget {
                cell *= 2.0;
            }
        }
        let nx = ((hi[0] - lo[0]) / cell) as usize + 1;
        let ny = ((hi[1] - lo[1]) / cell) as usize + 1;
        let mut grid = PlanarGrid {
            cell,
            origin: lo,
            nx,
            ny,
            start: vec![0; nx * ny + 1],
            items: vec![0; points.len()],
            coords: vec![[0.0; 2]; points.len()],
            points: points.to_vec(),
            separation: vec![f64::NAN; points.len()],
            normals: vec![None; points.len()],
        };
        let cell_of = |p: &[f64; 2]| -> usize {
            let i = (((p[0] - lo[0]) / cell) as usize).min(nx - 1);
            let j = (((p[1] - lo[1]) / cell) as usize).min(ny - 1);
            i * ny + j
        };
        for p in points {
            grid.start[cell_of(p) + 1] += 1;
        }
        for c in 0..nx * ny {
            grid.start[c + 1] += grid.start[c];
        }
        let mut next = grid.start.clone();
        for (k, p) in points.iter().enumerate() {
            let c = cell_of(p);
            let at = next[c] as usize;
            next[c] += 1;
            grid.items[at] = k as u32;
            grid.coords[at] = *p;
        }
        Some(grid)
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Always false: a grid holds at least one point.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The cell side actually used (m).
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// The index of the point nearest to `q` and its squared distance, if that is at most
    /// `max_d2` (`f64::INFINITY` for no bound). Ties go to the lowest index.
    pub fn nearest(&self, q: [f64; 2], max_d2: f64) -> Option<(usize, f64)> {
        self.nearest_excluding(q, max_d2, u32::MAX)
    }

    /// [`nearest`](Self::nearest) among the points other than `exclude`.
    fn nearest_excluding(&self, q: [f64; 2], max_d2: f64, exclude: u32) -> Option<(usize, f64)> {
        if !(q[0].is_finite() && q[1].is_finite()) || max_d2.is_nan() {
            return None;
        }
        let s = self.cell;
        let fx = (q[0] - self.origin[0]) / s;
        let fy = (q[1] - self.origin[1]) / s;
        // The query's cell may lie outside the grid; rings are clipped to it.
        let ci = floor_i64(fx.clamp(-1e15, 1e15));
        let cj = floor_i64(fy.clamp(-1e15, 1e15));
        // Distance from q to its own cell's border: ring r ≥ 1 is at least (r − 1)·s + edge away.
        let edge = s
            * (fx - ci as f64)
                .min(1.0 - (fx - ci as f64))
                .min(fy - cj as f64)
                .min(1.0 - (fy - cj as f64))
                .max(0.0);
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        // Rings beyond this one lie entirely outside the grid.
        let last = (ci.max(nx - 1 - ci).max(cj).max(ny - 1 - cj)).max(0);
        let mut search = Search {
            q,
            exclude,
            best: None,
            bound: max_d2,
        };
        let mut r = 0i64;
        while r <= last {
            if r >= 1 {
                let lb = (r - 1) as f64 * s + edge;
                if lb * lb > search.bound {
                    break;
                }
            }
            let (i0, i1) = ((ci - r).max(0), (ci + r).min(nx - 1));
            let (j0, j1) = ((cj - r).max(0), (cj + r).min(ny - 1));
            for i in i0..=i1 {
                let whole_column = i == ci - r || i == ci + r;
                if whole_column {
                    self.scan_cells(i, j0, j1, &mut search);
                } else {
                    // Only the ring's top and bottom cells of this column.
                    if cj - r >= 0 && cj - r < ny {
                        self.scan_cells(i, cj - r, cj - r, &mut search);
                    }
                    if r > 0 && cj + r >= 0 && cj + r < ny {
                        self.scan_cells(i, cj + r, cj + r, &mut search);
                    }
                }
            }
            r += 1;
        }
        search.best.map(|(k, d2)| (k as usize, d2))
    }

    /// [`nearest`](Self::nearest), starting from point `hint` (an index below
    /// [`len`](Self::len)): when the hint lies within the bound, only the cells that reach
    /// nearer than the hint are searched, and none at all when the query is nearer to the
    /// hint than half the hint's distance to its own nearest neighbour (then no other point
    /// can be as near). The answer does not depend on the hint.
    pub fn nearest_from(&mut self, q: [f64; 2], max_d2: f64, hint: usize) -> Option<(usize, f64)> {
        let Some(&h) = self.points.get(hint) else {
            return self.nearest(q, max_d2);
        };
        let d2 = (h[0] - q[0]).powi(2) + (h[1] - q[1]).powi(2);
        let usable = d2 <= max_d2 && q[0].is_finite() && q[1].is_finite();
        if !usable {
            return self.nearest(q, max_d2);
        }
        if self.separation[hint].is_nan() {
            // A quarter of the squared distance to the nearest other point (∞ when alone).
            let other = self.nearest_excluding(h, f64::INFINITY, hint as u32);
            // (A hair less, so that rounding cannot make a tie look strictly farther.)
            self.separation[hint] = other.map_or(f64::INFINITY, |(_, o2)| 0.249_999_99 * o2);
        }
        if d2 < self.separation[hint] {
            return Some((hint, d2));
        }
        let mut search = Search {
            q,
            exclude: u32::MAX,
            best: Some((hint as u32, d2)),
            bound: d2,
        };
        // A hair wider than the hint's distance, so that rounding cannot drop a cell that
        // holds a tie.
        let reach = d2.sqrt() * (1.0 + 1e-9) + 1e-12;
        let ((i0, i1), (j0, j1)) = self.cells_around(q, reach);
        for i in i0..=i1 {
            self.scan_cells(i, j0, j1, &mut search);
        }
        search.best.map(|(k, d2)| (k as usize, d2))
    }

    /// The unit normal of the line through point `j` and the points within one cell side of
    /// it (the principal axis of their scatter), or `None` when fewer than three points lie
    /// there, their spread across the line is more than a fifth of their spread along it (a
    /// corner, a blob), or `j` is out of range. Computed once per point.
    pub fn line_normal(&mut self, j: usize) -> Option<[f64; 2]> {
        if let Some(n) = *self.normals.get(j)? {
            return n;
        }
        let n = self.fit_line_normal(self.points[j]);
        self.normals[j] = Some(n);
        n
    }

    fn fit_line_normal(&self, c: [f64; 2]) -> Option<[f64; 2]> {
        let s = self.cell;
        let r2 = s * s;
        let ((i0, i1), (j0, j1)) = self.cells_around(c, s);
        // Moments about c (shifted sums keep the scatter exact at any coordinate size).
        let (mut n, mut sx, mut sy, mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for i in i0..=i1 {
            for p in &self.coords[self.run(i, j0, j1)] {
                let (x, y) = (p[0] - c[0], p[1] - c[1]);
                if x * x + y * y <= r2 {
                    n += 1.0;
                    sx += x;
                    sy += y;
                    sxx += x * x;
                    sxy += x * y;
                    syy += y * y;
                }
            }
        }
        if n < 3.0 {
            return None;
        }
        let (mx, my) = (sx / n, sy / n);
        let (cxx, cxy, cyy) = (sxx / n - mx * mx, sxy / n - mx * my, syy / n - my * my);
        let (small, large) = symmetric2_eigenvalues(cxx, cxy, cyy);
        if large.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || small > 0.04 * large {
            return None;
        }
        // The line runs along the large eigenvalue's eigenvector; the normal is across it.
        let (sin, cos) = (0.5 * (2.0 * cxy).atan2(cxx - cyy)).sin_cos();
        Some([-sin, cos])
    }

    /// The columns and rows of the cells that the square of half-side `reach` about `c`
    /// touches, clipped to the grid (an empty range when the square lies outside it).
    fn cells_around(&self, c: [f64; 2], reach: f64) -> ((i64, i64), (i64, i64)) {
        let s = self.cell;
        let cell = |v: f64, o: f64, n: usize| -> i64 {
            floor_i64(((v - o) / s).clamp(-1e15, 1e15)).clamp(-1, n as i64)
        };
        let span = |a: usize, n: usize| {
            let o = self.origin[a];
            (
                cell(c[a] - reach, o, n).max(0),
                cell(c[a] + reach, o, n).min(n as i64 - 1),
            )
        };
        (span(0, self.nx), span(1, self.ny))
    }

    /// Where the points of cells (i, j0..=j1), one contiguous run, lie in `items` and
    /// `coords` (`j0 ≤ j1`, all inside the grid).
    #[inline]
    fn run(&self, i: i64, j0: i64, j1: i64) -> std::ops::Range<usize> {
        let base = i as usize * self.ny;
        self.start[base + j0 as usize] as usize..self.start[base + j1 as usize + 1] as usize
    }

    /// Offers the points of cells (i, j0..=j1) (one contiguous run) to the search.
    #[inline]
    fn scan_cells(&self, i: i64, j0: i64, j1: i64, search: &mut Search) {
        if j0 > j1 {
            return;
        }
        let r = self.run(i, j0, j1);
        let q = search.q;
        for (p, &k) in self.coords[r.clone()].iter().zip(&self.items[r]) {
            let (dx, dy) = (p[0] - q[0], p[1] - q[1]);
            let d2 = dx * dx + dy * dy;
            if d2 <= search.bound && k != search.exclude {
                let better = match search.best {
                    None => true,
                    Some((bk, bd)) => d2 < bd || (d2 == bd && k < bk),
                };
                if better {
                    search.best = Some((k, d2));
                    search.bound = d2;
                }
            }
        }
    }
}

/// One query's state: the best point so far and the squared distance a point must not exceed.
struct Search {
    q: [f64; 2],
    /// A point index never returned (`u32::MAX`: none).
    exclude: u32,
    best: Option<(u32, f64)>,
    bound: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn brute(points: &[[f64; 2]], q: [f64; 2], max_d2: f64) -> Option<(usize, f64)> {
        let mut best: Option<(usize, f64)> = None;
        for (k, p) in points.iter().enumerate() {
            let d2 = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
            if d2 <= max_d2 && best.is_none_or(|(_, b)| d2 < b) {
                best = Some((k, d2));
            }
        }
        best
    }

    #[test]
    fn bad_sets_have_no_grid() {
        assert!(PlanarGrid::new(&[], 0.2).is_none());
        assert!(PlanarGrid::new(&[[0.0, f64::NAN]], 0.2).is_none());
        assert!(PlanarGrid::new(&[[0.0, 0.0]], 0.0).is_none());
        assert!(PlanarGrid::new(&[[0.0, 0.0]], f64::INFINITY).is_none());
    }

    #[test]
    fn a_query_far_outside_finds_the_corner_or_nothing() {
        let g = PlanarGrid::new(&[[0.0, 0.0], [1.0, 1.0], [0.5, 0.2]], 0.1).unwrap();
        assert_eq!(g.nearest([50.0, 60.0], f64::INFINITY).map(|x| x.0), Some(1));
        assert_eq!(g.nearest([50.0, 60.0], 1.0), None);
        assert_eq!(g.nearest([f64::NAN, 0.0], 1.0), None);
    }

    #[test]
    fn a_wide_sparse_set_gets_larger_cells() {
        let g = PlanarGrid::new(&[[0.0, 0.0], [1000.0, 1000.0]], 0.1).unwrap();
        assert!(g.cell() > 100.0, "{}", g.cell());
        assert_eq!(
            g.nearest([990.0, 999.0], f64::INFINITY).map(|x| x.0),
            Some(1)
        );
    }

    #[test]
    fn normals_of_a_wall_a_corner_and_a_lone_point() {
        // A wall along y = 0.5 x (every 5 cm), a lone point far off.
        let mut pts: Vec<[f64; 2]> = (0..40)
            .map(|k| [k as f64 * 0.05, k as f64 * 0.025])
            .collect();
        pts.push([10.0, -10.0]);
        // An L corner at (20, 0): both legs within the cell.
        for k in 0..10 {
            pts.push([20.0 + k as f64 * 0.05, 0.0]);
            pts.push([20.0, k as f64 * 0.05]);
        }
        let mut g = PlanarGrid::new(&pts, 0.5).unwrap();
        let n = g.line_normal(20).unwrap();
        // Across (1, 0.5): ±(−0.5, 1)/√1.25.
        let dot = (n[0] * -0.5 + n[1]) / 1.25f64.sqrt();
        assert!((dot.abs() - 1.0).abs() < 1e-9, "{n:?}");
        assert_eq!(g.line_normal(40), None);
        assert_eq!(g.line_normal(41), None);
        assert_eq!(g.line_normal(1000), None);
    }

    proptest! {
        #[test]
        fn agrees_with_brute_force(
            raw in prop::collection::vec((-5.0f64..5.0, -3.0f64..3.0), 1..200),
            queries in prop::collection::vec((-8.0f64..8.0, -6.0f64..6.0), 1..40),
            cell in 0.05f64..2.0,
            bound in prop::option::of(0.01f64..3.0),
            snap in any::<bool>(),
        ) {
            // Snapped to a 0.25 m lattice, many points tie; they go to the lowest index.
            let f = |v: f64| if snap { (v * 4.0).round() / 4.0 } else { v };
            let points: Vec<[f64; 2]> = raw.iter().map(|&(x, y)| [f(x), f(y)]).collect();
            let mut g = PlanarGrid::new(&points, cell).unwrap();
            let max_d2 = bound.map_or(f64::INFINITY, |b| b * b);
            for (n, &(x, y)) in queries.iter().enumerate() {
                let q = [f(x), f(y)];
                let truth = brute(&points, q, max_d2);
                prop_assert_eq!(g.nearest(q, max_d2), truth);
                // Any hint, near or far, in range or not, gives the same answer.
                let hint = (n * 7919) % (points.len() + 1);
                prop_assert_eq!(g.nearest_from(q, max_d2, hint), truth);
            }
        }
    }
}
