//! The geometry of one extracted plane's inliers: splitting them into spatially connected
//! pieces, the points that can bound a piece's rectangle, and the RMS distance to the plane.
//!
//! Not for: finding planes (see the `ransac` module) or deciding what a piece is.

use crate::geometry::Plane;
use nalgebra::{Point3, Vector3};
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
    let uv: Vec<[f64; 2]> = idx
        .iter()
        .map(|&i| {
            let q = point64(pts[i as usize]) - origin;
            [q.dot(&u), q.dot(&v)]
        })
        .collect();
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
    // One pass for the extreme point in every direction (ties: the earliest point).
    let mut best = [(f64::NEG_INFINITY, [0.0f64; 2]); 8];
    for q in &uv {
        for (b, d) in best.iter_mut().zip(&DIRS) {
            let s = q[0] * d[0] + q[1] * d[1];
            if s > b.0 {
                *b = (s, *q);
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
    idx.iter()
        .zip(&uv)
        .enumerate()
        .filter(|(k, (_, q))| *k == 0 || !inside(q))
        .map(|(_, (&i, _))| point64(pts[i as usize]))
        .collect()
}

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
    let (u, v) = plane.basis();
    let inv = 1.0 / cell;
    let cell_of = |i: u32| {
        let p = pts[i as usize];
        let q = Vector3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        (
            (q.dot(&u) * inv).floor() as i64,
            (q.dot(&v) * inv).floor() as i64,
        )
    };
    let cells: Vec<(i64, i64)> = idx.iter().map(|&i| cell_of(i)).collect();
    let mut counts: HashMap<(i64, i64), usize> = HashMap::with_capacity(idx.len() / 4);
    for c in &cells {
        *counts.entry(*c).or_default() += 1;
    }
    // Occupied cell -> component id (usize::MAX = not yet labelled).
    let mut label: HashMap<(i64, i64), usize> = counts
        .iter()
        .filter(|(_, &n)| n >= min_cell.max(1))
        .map(|(c, _)| (*c, usize::MAX))
        .collect();
    let mut n_comp = 0usize;
    let mut stack: Vec<(i64, i64)> = Vec::new();
    for c in &cells {
        if label.get(c).is_none_or(|&l| l != usize::MAX) {
            continue;
        }
        label.insert(*c, n_comp);
        stack.push(*c);
        while let Some((cx, cy)) = stack.pop() {
            for dx in -1..=1 {
                for dy in -1..=1 {
                    let nb = (cx + dx, cy + dy);
                    if let Some(l) = label.get_mut(&nb) {
                        if *l == usize::MAX {
                            *l = n_comp;
                            stack.push(nb);
                        }
                    }
                }
            }
        }
        n_comp += 1;
    }
    let mut pieces: Vec<Vec<u32>> = vec![Vec::new(); n_comp];
    for (&i, c) in idx.iter().zip(&cells) {
        if let Some(&l) = label.get(c) {
            pieces[l].push(i);
        }
    }
    pieces
}
