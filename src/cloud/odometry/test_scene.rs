//! A synthetic scene for the unit tests: a walled yard with a floor and three boxes, sampled
//! as points drawn uniformly on the faces (no sensor model), so that any rigid motion is
//! observable and no sampling grid is shared between two samplings.

use crate::rng::seeded;
use nalgebra::Vector3;
use rand::RngExt;

/// About one point per `spacing²` of surface, uniformly on the faces of the box `[lo, hi]`.
fn box_faces(
    lo: [f64; 3],
    hi: [f64; 3],
    spacing: f64,
    rng: &mut crate::rng::FilterRng,
    out: &mut Vec<Vector3<f64>>,
) {
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let area = (hi[u] - lo[u]) * (hi[v] - lo[v]);
        let n = (area / (spacing * spacing)).round() as usize;
        for side in [lo[axis], hi[axis]] {
            for _ in 0..n {
                let mut p = [0.0; 3];
                p[axis] = side;
                p[u] = rng.random_range(lo[u]..hi[u]);
                p[v] = rng.random_range(lo[v]..hi[v]);
                out.push(Vector3::from(p));
            }
        }
    }
}

/// The yard (40 × 24 m, walls 4 m high, sensor near the middle at z = 0, floor at −1.7 m)
/// with three boxes of different sizes, about `spacing` m between points; `seed` picks the
/// sampling.
pub fn yard(spacing: f64, seed: u64) -> Vec<Vector3<f64>> {
    let mut rng = seeded(seed);
    let mut out = Vec::new();
    box_faces(
        [-20.0, -12.0, -1.7],
        [20.0, 12.0, 2.3],
        spacing,
        &mut rng,
        &mut out,
    );
    box_faces(
        [4.0, 3.0, -1.7],
        [6.0, 4.0, 0.3],
        spacing,
        &mut rng,
        &mut out,
    );
    box_faces(
        [-7.0, -5.0, -1.7],
        [-4.5, -4.0, 1.0],
        spacing,
        &mut rng,
        &mut out,
    );
    box_faces(
        [9.0, -8.0, -1.7],
        [10.0, -3.0, -0.2],
        spacing,
        &mut rng,
        &mut out,
    );
    out
}
