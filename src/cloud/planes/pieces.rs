//! The geometry of one extracted plane's inliers: splitting them into spatially connected
//! pieces, the points that can bound a piece's rectangle, and the RMS distance to the plane.
//!
//! Not for: finding planes (see the `ransac` module) or deciding what a piece is.

use crate::geometry::Plane;
use crate::numerics::floor::floor_i64;
use nalgebra::{Point3, Vector3};
use rayon::prelude::*;
use std::collections::HashMap;

/// RMS distance of the points `idx` to `plane`.
pub(super) fn rms(plane: &Plane, idx: &[u32], pts: &[[f32; 3]]) -> f64 {
    if idx.is_empty() {
        return 0.0;
    }
    let s: f64 = idx
        .iter()
        .map(|&i| plane.signed_distance(&point64(pts[i as usize])).powi(2))
        .sum();
    (s / idx.len() as f64).sqrt()
}

pub(super) fn point64(p: [f32; 3]) -> Point3<f64> {
    Point3::new(p[0] as f64, p[1] as f64, p[2] as f64)
}

/// The points `idx` that can be corners of their bounding rectangle on `plane`: the first
/// point (it anchors the patch's coordinates) and every point not strictly inside the convex
/// polygon spanned by the extreme points in eight directions (Akl–Toussaint), with a 1 µm
/// margin. The convex hull, and so the minimum-area rectangle, of these points is that of
/// all points; for a large ground plane this drops nearly all of them before the hull sort.
pub(super) fn hull_candidates(plane: &Plane, idx: &[u32], pts: &[[f32; 3]]) -> Vec<Point3<f64>> {
    let all = || idx.iter().map(|&i| point64(pts[i as usize])).collect();
    if idx.len() < 64 {
        return all();
    }
    let (u, v) = plane.basis();
    let origin = plane.project(&point64(pts[idx[0] as usize]));
    let uv_of = |i: u32| {
        let q = point64(pts[i as usize]) - origin;
        [q.dot(&u), q.dot(&v)]
    };
    // Directions in counter-clockwise order; their extreme points lie on the hull in order.
    const DIRS: [[f64; 2]; 8] = [
        [1.0, 0.0],
        [1.0, 1.0],
        [0.0, 1.0],
        [-1.0, 1.0],
        [-1.0, 0.0],
        [-1.0, -1.0],
        [0.0, -1.0],
        [1.0, -1.0],
    ];
    // The extreme point in every direction (ties: the earliest point): per chunk of points in
    // parallel, then the chunks in order, a later one winning only when strictly beyond.
    let extremes = |chunk: &[u32]| {
        let mut best = [(f64::NEG_INFINITY, [0.0f64; 2]); 8];
        for &i in chunk {
            let q = uv_of(i);
            for (b, d) in best.iter_mut().zip(&DIRS) {
                let s = q[0] * d[0] + q[1] * d[1];
                if s > b.0 {
                    *b = (s, q);
                }
            }
        }
        best
    };
    let per_chunk: Vec<_> = idx.par_chunks(HULL_CHUNK).map(extremes).collect();
    let mut best = [(f64::NEG_INFINITY, [0.0f64; 2]); 8];
    for chunk in per_chunk {
        for (b, c) in best.iter_mut().zip(chunk) {
            if c.0 > b.0 {
                *b = c;
            }
        }
    }
    let mut poly: Vec<[f64; 2]> = Vec::with_capacity(8);
    for (_, q) in best {
        if poly.last() != Some(&q) && poly.first() != Some(&q) {
            poly.push(q);
        }
    }
    if poly.len() < 3 {
        return all();
    }
    const MARGIN: f64 = 1e-6;
    let edges: Vec<([f64; 2], [f64; 2], f64)> = (0..poly.len())
        .map(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            (a, b, len)
        })
        .collect();
    let inside = |p: &[f64; 2]| {
        edges.iter().all(|(a, b, len)| {
            (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) > MARGIN * len
        })
    };
    idx.par_iter()
        .enumerate()
        .filter(|&(k, &i)| k == 0 || !inside(&uv_of(i)))
        .map(|(_, &i)| point64(pts[i as usize]))
        .collect()
}

/// Points per parallel chunk of [`hull_candidates`].
const HULL_CHUNK: usize = 8192;

/// Splits the points `idx` of `plane` into spatially connected pieces: flood fill with
/// 8-connectivity over the occupied cells of a 2-D grid (edge `cell`) in the plane's
/// coordinates. Cells holding fewer than `min_cell` points are left out (their points are in
/// no piece). Pieces are ordered by their first point in `idx`, points keep their order.
pub(super) fn connected_pieces(
    plane: &Plane,
    idx: &[u32],
    pts: &[[f32; 3]],
    cell: f64,
    min_cell: usize,
) -> Vec<Vec<u32>> {
    let cells = plane_cells(plane, idx, pts, cell);
    let grid = CellSlots::new(&cells);
    let slots: Vec<usize> = cells
        .iter()
        .map(|&c| grid.slot(c).expect("every point's cell has a slot"))
        .collect();
    let mut counts = vec![0usize; grid.len()];
    for &s in &slots {
        counts[s] += 1;
    }
    // Per slot: the component, UNSEEN for a cell kept but not yet labelled, OUT otherwise.
    const UNSEEN: usize = usize::MAX - 1;
    const OUT: usize = usize::MAX;
    let mut label: Vec<usize> = counts
        .iter()
        .map(|&n| if n >= min_cell.max(1) { UNSEEN } else { OUT })
        .collect();
    let mut n_comp = 0usize;
    let mut stack: Vec<(i64, i64)> = Vec::new();
    for (&c, &s) in cells.iter().zip(&slots) {
        if label[s] != UNSEEN {
            continue;
        }
        label[s] = n_comp;
        stack.push(c);
        while let Some((cx, cy)) = stack.pop() {
            for dx in -1..=1i64 {
                for dy in -1..=1i64 {
                    let nb = match (cx.checked_add(dx), cy.checked_add(dy)) {
                        (Some(x), Some(y)) => (x, y),
                        _ => continue,
                    };
                    if let Some(t) = grid.slot(nb) {
                        if label[t] == UNSEEN {
                            label[t] = n_comp;
                            stack.push(nb);
                        }
                    }
                }
            }
        }
        n_comp += 1;
    }
    let mut pieces: Vec<Vec<u32>> = vec![Vec::new(); n_comp];
    for (&i, &s) in idx.iter().zip(&slots) {
        if label[s] < UNSEEN {
            pieces[label[s]].push(i);
        }
    }
    pieces
}

/// How far apart along a wall two pieces of it may lie and still be one facade
/// ([`join_along_wall`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub(super) struct JoinGap {
    /// The scanner's azimuth step (rad).
    pub azimuth_step: f64,
    /// The gap allowed, in expected point spacings along the wall where the gap is.
    pub spacings: f64,
    /// The gap always allowed (m).
    pub least: f64,
    /// The gap never exceeded (m).
    pub most: f64,
}

impl JoinGap {
    /// The gap allowed at the point `at` of a wall of unit normal `normal`, seen from the
    /// sensor at the origin: `spacings` times the spacing of one scan line's points along the
    /// wall there, Δφ·r / |sin γ| with r the horizontal range and γ the angle between the
    /// horizontal ray and the wall (a wall seen at a grazing angle is sampled sparsely, and
    /// its cells then fall below the grid's point count), within [`least`, `most`].
    fn allowed(&self, normal: &Vector3<f64>, at: &Point3<f64>) -> f64 {
        let ray = Vector3::new(at.x, at.y, 0.0);
        let r = ray.norm();
        let flat = Vector3::new(normal.x, normal.y, 0.0);
        let sin_graze = if r > 0.0 && flat.norm() > 0.0 {
            (ray.dot(&flat) / (r * flat.norm())).abs()
        } else {
            1.0
        };
        let spacing = self.azimuth_step * r / sin_graze.max(1e-3);
        (self.spacings * spacing).clamp(self.least, self.most.max(self.least))
    }
}

/// Joins the `pieces` of one wall `plane` that are one facade with a gap in it: pieces are
/// taken in order along the wall's horizontal direction, and a piece joins the facade before
/// it when the gap between them along the wall is at most what [`JoinGap::allowed`] allows
/// at the gap and their height ranges overlap. A joined piece's points are in ascending order,
/// and the pieces are ordered by their first point (as `connected_pieces` gives them for
/// ascending inliers, so that nothing changes when nothing joins). A plane that is not steep
/// (its normal within 45° of vertical) is returned as it is.
pub(super) fn join_along_wall(
    plane: &Plane,
    pieces: Vec<Vec<u32>>,
    pts: &[[f32; 3]],
    gap: &JoinGap,
) -> Vec<Vec<u32>> {
    let n = plane.normal;
    let horizontal = n.cross(&Vector3::z());
    if pieces.len() < 2 || horizontal.norm() < std::f64::consts::FRAC_1_SQRT_2 {
        return pieces;
    }
    let axis = horizontal.normalize();
    // Per piece: (start, end) along the wall, (bottom, top), and the place of its first point.
    let spans: Vec<((f64, f64), (f64, f64))> = pieces
        .iter()
        .map(|piece| {
            let mut along = (f64::INFINITY, f64::NEG_INFINITY);
            let mut height = (f64::INFINITY, f64::NEG_INFINITY);
            for &i in piece {
                let p = pts[i as usize];
                let s = axis.x * p[0] as f64 + axis.y * p[1] as f64;
                along = (along.0.min(s), along.1.max(s));
                height = (height.0.min(p[2] as f64), height.1.max(p[2] as f64));
            }
            (along, height)
        })
        .collect();
    let mut order: Vec<usize> = (0..pieces.len())
        .filter(|&k| !pieces[k].is_empty())
        .collect();
    order.sort_by(|&a, &b| spans[a].0 .0.total_cmp(&spans[b].0 .0).then(a.cmp(&b)));
    // Groups of piece indices, each growing along the wall.
    let mut groups: Vec<(Vec<usize>, f64, (f64, f64))> = Vec::new();
    for k in order {
        let ((s0, s1), (z0, z1)) = spans[k];
        if let Some((members, end, (b, t))) = groups.last_mut() {
            let middle = 0.5 * (*end + s0);
            // The gap's middle point on the wall, at mid height: the plane's foot point
            // moved along the wall.
            let foot = Point3::from(-n * plane.offset);
            let at = foot + axis * (middle - axis.dot(&foot.coords));
            let heights_meet = z0.max(*b) <= z1.min(*t);
            if s0 - *end <= gap.allowed(&n, &at) && heights_meet {
                members.push(k);
                *end = end.max(s1);
                *b = b.min(z0);
                *t = t.max(z1);
                continue;
            }
        }
        groups.push((vec![k], s1, (z0, z1)));
    }
    let mut joined: Vec<Vec<u32>> = groups
        .into_iter()
        .map(|(members, _, _)| {
            if members.len() == 1 {
                return pieces[members[0]].clone();
            }
            let mut points: Vec<u32> = members
                .iter()
                .flat_map(|&k| pieces[k].iter().copied())
                .collect();
            points.sort_unstable();
            points
        })
        .collect();
    joined.sort_by_key(|piece| piece[0]);
    joined
}

/// The grid cell (edge `cell`, in the plane's own coordinates) of each point `idx`.
fn plane_cells(plane: &Plane, idx: &[u32], pts: &[[f32; 3]], cell: f64) -> Vec<(i64, i64)> {
    let (u, v) = plane.basis();
    let inv = 1.0 / cell;
    idx.iter()
        .map(|&i| {
            let p = pts[i as usize];
            let q = Vector3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            (floor_i64(q.dot(&u) * inv), floor_i64(q.dot(&v) * inv))
        })
        .collect()
}

/// Numbers the cells of a set: every cell of the bounding box when the box is small (a plane's
/// pieces fill much of theirs), else only the occupied cells through a hash table.
enum CellSlots {
    /// Row-major over the box `[x0, x0 + w) × [y0, y0 + h)`.
    Dense { x0: i64, y0: i64, w: i64, h: i64 },
    /// One slot per occupied cell.
    Sparse(HashMap<(i64, i64), usize>),
}

impl CellSlots {
    fn new(cells: &[(i64, i64)]) -> Self {
        let (mut lo, mut hi) = ((i64::MAX, i64::MAX), (i64::MIN, i64::MIN));
        for &(x, y) in cells {
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
        let extent = |a: i64, b: i64| (b as i128 - a as i128 + 1).max(0);
        let area = extent(lo.0, hi.0) * extent(lo.1, hi.1);
        if !cells.is_empty() && area <= 4 * cells.len() as i128 + 4096 {
            return CellSlots::Dense {
                x0: lo.0,
                y0: lo.1,
                w: extent(lo.0, hi.0) as i64,
                h: extent(lo.1, hi.1) as i64,
            };
        }
        let mut map = HashMap::with_capacity(cells.len() / 4);
        for &c in cells {
            let next = map.len();
            map.entry(c).or_insert(next);
        }
        CellSlots::Sparse(map)
    }

    /// Number of slots.
    fn len(&self) -> usize {
        match self {
            CellSlots::Dense { w, h, .. } => (w * h) as usize,
            CellSlots::Sparse(map) => map.len(),
        }
    }

    /// The slot of cell `c` (`None` outside the box or not occupied).
    fn slot(&self, c: (i64, i64)) -> Option<usize> {
        match self {
            CellSlots::Dense { x0, y0, w, h } => {
                let (dx, dy) = (c.0 as i128 - *x0 as i128, c.1 as i128 - *y0 as i128);
                ((0..*w as i128).contains(&dx) && (0..*h as i128).contains(&dy))
                    .then(|| (dx + dy * *w as i128) as usize)
            }
            CellSlots::Sparse(map) => map.get(&c).copied(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The pieces by their definition: two kept cells are joined when they touch (including
    /// diagonally), found by repeated merging of cell sets without any grid index.
    fn pieces_by_definition(cells: &[(i64, i64)], min_cell: usize) -> Vec<Vec<usize>> {
        let mut count: std::collections::BTreeMap<(i64, i64), usize> = Default::default();
        for &c in cells {
            *count.entry(c).or_default() += 1;
        }
        let kept: Vec<(i64, i64)> = count
            .iter()
            .filter(|(_, &n)| n >= min_cell.max(1))
            .map(|(&c, _)| c)
            .collect();
        let mut comp: Vec<usize> = (0..kept.len()).collect();
        loop {
            let mut changed = false;
            for a in 0..kept.len() {
                for b in 0..kept.len() {
                    let touch =
                        (kept[a].0 - kept[b].0).abs() <= 1 && (kept[a].1 - kept[b].1).abs() <= 1;
                    if touch && comp[a] != comp[b] {
                        let m = comp[a].min(comp[b]);
                        comp[a] = m;
                        comp[b] = m;
                        changed = true;
                    }
                }
            }
            if !changed {
                break;
            }
        }
        // Points grouped by component, components in order of their first point.
        let mut order: Vec<usize> = Vec::new();
        let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
        for (k, c) in cells.iter().enumerate() {
            if let Ok(j) = kept.binary_search(c) {
                if !groups.contains_key(&comp[j]) {
                    order.push(comp[j]);
                }
                groups.entry(comp[j]).or_default().push(k);
            }
        }
        order.iter().map(|c| groups[c].clone()).collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        #[test]
        fn hull_candidates_keep_the_patch_of_all_points(
            n in 64usize..20_000,
            seed in 0u64..1000,
            tilt in 0.0f64..1.5,
        ) {
            // Points scattered over a blob on a tilted plane (several parallel chunks when n
            // is large): the rectangle of the candidates is that of all points.
            use rand::RngExt;
            let mut rng = crate::rng::seeded(seed);
            let normal = Vector3::new(tilt.sin(), 0.2, tilt.cos());
            let plane = Plane::from_point_normal(&Point3::new(1.0, 2.0, 3.0), normal).unwrap();
            let (u, v) = plane.basis();
            let pts: Vec<[f32; 3]> = (0..n)
                .map(|_| {
                    let (a, b): (f64, f64) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                    let p = Point3::new(1.0, 2.0, 3.0) + u * (20.0 * a * a.abs()) + v * (5.0 * b);
                    [p.x as f32, p.y as f32, p.z as f32]
                })
                .collect();
            let idx: Vec<u32> = (0..n as u32).rev().collect();
            let all: Vec<Point3<f64>> = idx.iter().map(|&i| point64(pts[i as usize])).collect();
            let cand = hull_candidates(&plane, &idx, &pts);
            prop_assert!(cand.len() < all.len() / 2, "{} of {}", cand.len(), all.len());
            prop_assert_eq!(cand[0], all[0]);
            let whole = crate::geometry::PlanePatch::from_points(plane, &all).unwrap();
            let kept = crate::geometry::PlanePatch::from_points(plane, &cand).unwrap();
            prop_assert_eq!(kept, whole);
        }

        #[test]
        fn pieces_are_the_touching_cell_sets(
            raw in proptest::collection::vec((-12i64..12, -6i64..6), 0..120),
            far in proptest::option::of(1_000_000i64..2_000_000),
            min_cell in 1usize..3,
        ) {
            // Points of a vertical plane x = 0 (basis u, v of its normal), one per listed cell
            // centre, and optionally one cell far away (the sparse index).
            let plane = Plane::from_point_normal(&Point3::origin(), Vector3::x()).unwrap();
            let (u, v) = plane.basis();
            let mut cells = raw.clone();
            if let Some(f) = far {
                cells.push((f, 0));
            }
            let pts: Vec<[f32; 3]> = cells
                .iter()
                .map(|&(a, b)| {
                    let p = u * (a as f64 + 0.5) + v * (b as f64 + 0.5);
                    [p.x as f32, p.y as f32, p.z as f32]
                })
                .collect();
            let idx: Vec<u32> = (0..pts.len() as u32).collect();
            prop_assert_eq!(plane_cells(&plane, &idx, &pts, 1.0), cells.clone());
            let got = connected_pieces(&plane, &idx, &pts, 1.0, min_cell);
            let want: Vec<Vec<u32>> = pieces_by_definition(&cells, min_cell)
                .into_iter()
                .map(|g| g.into_iter().map(|k| k as u32).collect())
                .collect();
            prop_assert_eq!(got, want);
        }
    }
}
