//! A spinning multi-beam lidar (HDL-64E-like) cast into the street: for every column (azimuth)
//! and beam (elevation) one exact ray from the sensor pose, nearest hit among the ground
//! (see [`super::ground`]), wall rectangles, oriented car boxes and pedestrian cylinders.
//!
//! **Rays.** Beam b of column c has the direction (cos e_b cos a_c, cos e_b sin a_c, sin e_b) in
//! the sensor frame (x forward, y left, z up), with a_c = 2π·c/columns and the elevations of
//! [`LidarConfig::elevations`]. The scan is instantaneous at the given pose (no motion
//! distortion). A hit at range r within [min_range, max_range] is kept unless a dropout draw
//! removes it; the reported point is the ray direction times r + n, n ~ N(0, σ²) (range noise
//! along the ray), in the sensor frame. A porous shape (a hedge: [`Shape::scatter`] > 0) lets a
//! ray in before it returns: its range grows by `scatter·u`, u uniform in [0, 1), drawn after
//! the other draws of that ray. Reflectance is the surface's value scaled by the cosine
//! of the incidence angle (0.5 + 0.5·|cos|), with a little noise, clamped to [0, 1].
//!
//! **Occlusion.** The caster already intersects every ray with every shape of its column, so
//! it also counts, per road user, the rays whose line meets it and those of them whose first
//! hit is another shape nearer the sensor ([`ObjectView`]); [`super::truth`] turns the hidden
//! share into KITTI's occlusion level.
//!
//! **Speed.** Each shape gets its azimuth interval as seen in the sensor frame (the hull of its
//! corners projected on the sensor's xy plane); a column tests only the shapes whose interval
//! holds its azimuth. Columns run in parallel (rayon) into one preallocated buffer; each
//! worker keeps its occlusion counts and the counts are summed at the end (integers, so the
//! sum does not depend on how the columns were split).
//!
//! **Determinism.** Column c of a scan draws from `rng::stream(scan_seed, c)`, so the result
//! does not depend on the number of threads.
//!
//! Not for: the scene's layout (see [`super::world`]) or writing `.bin` files.

use super::ground::Ground;
use crate::cloud::PointCloud;
use crate::rng::stream;
use nalgebra::{Isometry3, Point3, Vector3};
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// What a lidar point hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Surface {
    /// The ground plane.
    Ground,
    /// The wall with this id.
    Wall(u32),
    /// The object with this id.
    Object(u32),
    /// The piece of street furniture or vegetation with this id (see [`super::clutter`]).
    Clutter(u32),
}

/// A shape's geometry in the world frame; every shape stands on the ground (z from 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Geometry {
    /// Vertical rectangle over the ground segment `base`…`base + length·along`.
    Wall {
        /// Ground corner.
        base: [f64; 2],
        /// Unit horizontal direction along the wall.
        along: [f64; 2],
        /// Length, metres.
        length: f64,
        /// Height, metres.
        height: f64,
        /// Unit horizontal normal.
        normal: [f64; 2],
    },
    /// Box with a vertical axis, footprint centred at `centre`, long side along `yaw`.
    Box {
        /// Footprint centre.
        centre: [f64; 2],
        /// Heading of the long side, rad.
        yaw: f64,
        /// Half of the length, metres.
        half_length: f64,
        /// Half of the width, metres.
        half_width: f64,
        /// Height, metres.
        height: f64,
    },
    /// Vertical cylinder.
    Cylinder {
        /// Axis position.
        centre: [f64; 2],
        /// Radius, metres.
        radius: f64,
        /// Height, metres.
        height: f64,
    },
}

/// A shape to cast rays at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shape {
    /// What points on it are attributed to.
    pub surface: Surface,
    /// Where it is.
    pub geometry: Geometry,
    /// Base reflectance in [0, 1].
    pub reflectance: f32,
    /// How deep a ray may enter before it returns, metres (0: a solid surface).
    pub scatter: f64,
}

/// The lidar's beams, resolution, range and noise.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LidarConfig {
    /// Number of beams (even): the upper half spread evenly from `elevation_top_deg` to
    /// `elevation_split_deg`, the lower half from half a lower step below the split down to
    /// `elevation_bottom_deg` (the HDL-64E's two laser blocks).
    pub beams: usize,
    /// Elevation of the highest beam, degrees.
    pub elevation_top_deg: f64,
    /// Elevation of the lowest beam of the upper block, degrees.
    pub elevation_split_deg: f64,
    /// Elevation of the lowest beam, degrees.
    pub elevation_bottom_deg: f64,
    /// Azimuth columns per revolution (4500 ≈ 0.08°).
    pub columns: usize,
    /// Largest range reported, metres.
    pub max_range: f64,
    /// Smallest range reported, metres.
    pub min_range: f64,
    /// Standard deviation of the range noise, metres.
    pub range_noise: f64,
    /// Height of the sensor origin above the ground, metres.
    pub mount_height: f64,
    /// Probability that a ray that hits something returns nothing. The default, 0.57, brings
    /// a street scan to about 120,000 points, like a KITTI scan, which holds well under half
    /// of the sensor's possible returns.
    pub dropout: f64,
}

impl Default for LidarConfig {
    fn default() -> Self {
        LidarConfig {
            beams: 64,
            elevation_top_deg: 2.0,
            elevation_split_deg: -8.33,
            elevation_bottom_deg: -24.8,
            columns: 4500,
            max_range: 120.0,
            min_range: 2.0,
            range_noise: 0.02,
            mount_height: 1.73,
            dropout: 0.57,
        }
    }
}

impl LidarConfig {
    /// The beam elevations in radians, highest first.
    pub fn elevations(&self) -> Vec<f64> {
        let half = self.beams / 2;
        let upper = self.elevation_top_deg;
        let split = self.elevation_split_deg;
        let bottom = self.elevation_bottom_deg;
        let up_step = if half > 1 {
            (upper - split) / (half - 1) as f64
        } else {
            0.0
        };
        // Lower block: `half` beams evenly from half a step below the split down to `bottom`.
        let low_step = (split - bottom) / (half as f64 - 0.5).max(0.5);
        let mut e: Vec<f64> = (0..half).map(|i| upper - i as f64 * up_step).collect();
        e.extend((0..self.beams - half).map(|i| bottom + (half - 1 - i) as f64 * low_step));
        e.into_iter().map(f64::to_radians).collect()
    }
}

/// One scan: points in the sensor frame and what each one hit.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LidarScan {
    /// The points (x, y, z in the sensor frame, reflectance).
    pub cloud: PointCloud,
    /// What point i hit.
    pub surfaces: Vec<Surface>,
    /// How much of each object the rays see (see [`ObjectView`]), for every object shape
    /// that at least one ray's line meets, in the order of the shapes.
    pub objects: Vec<ObjectView>,
}

/// How much of one object a scan's rays see. A ray *meets* the object when its line enters
/// the object's shape within the lidar's maximum range; it is *hidden* when its first hit is
/// another shape (a wall, another road user, clutter) nearer the sensor. Rays that reach the
/// ground first are left out: the road's relief is not what hides a road user. Geometry only:
/// dropout and the minimum range do not enter, so the counts do not depend on the scan's seed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ObjectView {
    /// The object's id (as in [`Surface::Object`]).
    pub id: u32,
    /// Rays that meet the object.
    pub rays: u32,
    /// Of those, the rays whose first hit is something else nearer the sensor.
    pub hidden: u32,
}

impl ObjectView {
    /// The share of the rays meeting the object that are hidden, in [0, 1]; `None` when no
    /// ray meets it.
    pub fn hidden_share(&self) -> Option<f64> {
        (self.rays > 0).then(|| f64::from(self.hidden) / f64::from(self.rays))
    }
}

/// What one worker of [`cast_scan`] keeps between columns: the shapes of the column, the
/// objects met by the current ray (slot, shape index, ray parameter) and the per-object
/// (rays, hidden) counts so far.
struct Scratch {
    candidates: Vec<usize>,
    met: Vec<(usize, usize, f64)>,
    counts: Vec<[u32; 2]>,
}

/// Azimuth interval of a shape in the sensor frame: centre and half-width, rad.
#[derive(Clone, Copy, Debug)]
struct Interval {
    centre: f64,
    half: f64,
}

impl Interval {
    const FULL: Interval = Interval {
        centre: 0.0,
        half: 4.0,
    };

    fn contains(&self, a: f64) -> bool {
        self.half >= PI || wrap(a - self.centre).abs() <= self.half
    }
}

fn wrap(a: f64) -> f64 {
    crate::geometry::wrap_angle(a)
}

/// Corners of a shape's convex hull (walls 4, boxes 8, cylinders the 8 of the enclosing box).
fn corners(g: &Geometry) -> ([[f64; 3]; 8], usize) {
    let mut c = [[0.0; 3]; 8];
    match *g {
        Geometry::Wall {
            base,
            along,
            length,
            height,
            ..
        } => {
            let e = [base[0] + length * along[0], base[1] + length * along[1]];
            c[0] = [base[0], base[1], 0.0];
            c[1] = [e[0], e[1], 0.0];
            c[2] = [e[0], e[1], height];
            c[3] = [base[0], base[1], height];
            (c, 4)
        }
        Geometry::Box {
            centre,
            yaw,
            half_length,
            half_width,
            height,
        } => {
            let (s, co) = yaw.sin_cos();
            box_corners(&mut c, centre, [co, s], half_length, half_width, height);
            (c, 8)
        }
        Geometry::Cylinder {
            centre,
            radius,
            height,
        } => {
            box_corners(&mut c, centre, [1.0, 0.0], radius, radius, height);
            (c, 8)
        }
    }
}

fn box_corners(c: &mut [[f64; 3]; 8], centre: [f64; 2], u: [f64; 2], hl: f64, hw: f64, h: f64) {
    let v = [-u[1], u[0]];
    let mut i = 0;
    for a in [-hl, hl] {
        for b in [-hw, hw] {
            for z in [0.0, h] {
                c[i] = [
                    centre[0] + a * u[0] + b * v[0],
                    centre[1] + a * u[1] + b * v[1],
                    z,
                ];
                i += 1;
            }
        }
    }
}

fn interval(g: &Geometry, world_to_sensor: &Isometry3<f64>) -> Interval {
    let (c, n) = corners(g);
    let angles: Vec<f64> = c[..n]
        .iter()
        .map(|p| {
            let q = world_to_sensor * Point3::new(p[0], p[1], p[2]);
            q.y.atan2(q.x)
        })
        .collect();
    let centre = angles[0];
    let (mut lo, mut hi) = (0.0f64, 0.0f64);
    for a in &angles {
        let d = wrap(a - centre);
        lo = lo.min(d);
        hi = hi.max(d);
    }
    if hi - lo >= PI - 1e-6 {
        return Interval::FULL;
    }
    Interval {
        centre: wrap(centre + 0.5 * (lo + hi)),
        half: 0.5 * (hi - lo) + 1e-6,
    }
}

/// Nearest positive ray parameter at which the ray o + t·d hits `g`, and the cosine of the
/// incidence angle there.
fn intersect(g: &Geometry, o: &Vector3<f64>, d: &Vector3<f64>) -> Option<(f64, f64)> {
    match *g {
        Geometry::Wall {
            base,
            along,
            length,
            height,
            normal,
        } => {
            let nd = normal[0] * d.x + normal[1] * d.y;
            if nd.abs() < 1e-12 {
                return None;
            }
            let t = (normal[0] * (base[0] - o.x) + normal[1] * (base[1] - o.y)) / nd;
            if t <= 0.0 {
                return None;
            }
            let (px, py, pz) = (o.x + t * d.x, o.y + t * d.y, o.z + t * d.z);
            let s = along[0] * (px - base[0]) + along[1] * (py - base[1]);
            (s >= 0.0 && s <= length && pz >= 0.0 && pz <= height).then_some((t, nd.abs()))
        }
        Geometry::Box {
            centre,
            yaw,
            half_length,
            half_width,
            height,
        } => {
            let (s, c) = yaw.sin_cos();
            let (rx, ry) = (o.x - centre[0], o.y - centre[1]);
            let lo = [c * rx + s * ry, -s * rx + c * ry, o.z];
            let ld = [c * d.x + s * d.y, -s * d.x + c * d.y, d.z];
            let min = [-half_length, -half_width, 0.0];
            let max = [half_length, half_width, height];
            let (mut t0, mut t1, mut axis) = (f64::NEG_INFINITY, f64::INFINITY, 0);
            for k in 0..3 {
                if ld[k].abs() < 1e-15 {
                    if lo[k] < min[k] || lo[k] > max[k] {
                        return None;
                    }
                    continue;
                }
                let (a, b) = ((min[k] - lo[k]) / ld[k], (max[k] - lo[k]) / ld[k]);
                let (a, b) = if a < b { (a, b) } else { (b, a) };
                if a > t0 {
                    t0 = a;
                    axis = k;
                }
                t1 = t1.min(b);
            }
            (t0 <= t1 && t0 > 0.0).then(|| (t0, ld[axis].abs()))
        }
        Geometry::Cylinder {
            centre,
            radius,
            height,
        } => {
            let (rx, ry) = (o.x - centre[0], o.y - centre[1]);
            let a = d.x * d.x + d.y * d.y;
            let mut best: Option<(f64, f64)> = None;
            if a > 1e-15 {
                let b = rx * d.x + ry * d.y;
                let c = rx * rx + ry * ry - radius * radius;
                let disc = b * b - a * c;
                if disc >= 0.0 {
                    let t = (-b - disc.sqrt()) / a;
                    let z = o.z + t * d.z;
                    if t > 0.0 && (0.0..=height).contains(&z) {
                        let (nx, ny) = ((rx + t * d.x) / radius, (ry + t * d.y) / radius);
                        best = Some((t, (nx * d.x + ny * d.y).abs()));
                    }
                }
            }
            if d.z < 0.0 && o.z > height {
                let t = (height - o.z) / d.z;
                let (px, py) = (rx + t * d.x, ry + t * d.y);
                if px * px + py * py <= radius * radius && best.is_none_or(|(b, _)| t < b) {
                    best = Some((t, d.z.abs()));
                }
            }
            best
        }
    }
}

/// A ray's result before flattening: the point and what it hit.
#[derive(Clone, Copy)]
struct Hit {
    point: [f32; 4],
    surface: Option<Surface>,
}

const NO_HIT: Hit = Hit {
    point: [0.0; 4],
    surface: None,
};

/// Ground reflectance (asphalt).
const GROUND_REFLECTANCE: f64 = 0.25;

/// Casts one scan from `sensor_to_world` (the sensor's pose in the world frame) into `shapes`
/// and the `ground`. `seed` identifies the scan's random streams.
pub fn cast_scan(
    shapes: &[Shape],
    ground: &Ground,
    sensor_to_world: &Isometry3<f64>,
    lidar: &LidarConfig,
    seed: u64,
) -> LidarScan {
    let world_to_sensor = sensor_to_world.inverse();
    let intervals: Vec<Interval> = shapes
        .iter()
        .map(|s| interval(&s.geometry, &world_to_sensor))
        .collect();
    let elevations = lidar.elevations();
    let beams = elevations.len();
    let (sin_e, cos_e): (Vec<f64>, Vec<f64>) = elevations.iter().map(|e| e.sin_cos()).unzip();
    let origin = sensor_to_world.translation.vector;
    let rotation = sensor_to_world.rotation.to_rotation_matrix();
    // Slot of each object shape in the occlusion counts.
    let mut slots = vec![usize::MAX; shapes.len()];
    let mut object_shapes = Vec::new();
    for (i, shape) in shapes.iter().enumerate() {
        if let Surface::Object(id) = shape.surface {
            slots[i] = object_shapes.len();
            object_shapes.push(id);
        }
    }
    let n_objects = object_shapes.len();
    let mut buffer = vec![NO_HIT; lidar.columns * beams];
    let counts = buffer
        .par_chunks_mut(beams)
        .enumerate()
        .fold(
            || Scratch {
                candidates: Vec::new(),
                met: Vec::new(),
                counts: vec![[0; 2]; n_objects],
            },
            |mut scratch, (c, out)| {
                let Scratch {
                    candidates,
                    met,
                    counts,
                } = &mut scratch;
                let a = 2.0 * PI * c as f64 / lidar.columns as f64;
                let (sa, ca) = a.sin_cos();
                candidates.clear();
                candidates.extend((0..shapes.len()).filter(|&i| intervals[i].contains(a)));
                let mut rng = stream(seed, c as u64);
                for b in 0..beams {
                    let local = Vector3::new(cos_e[b] * ca, cos_e[b] * sa, sin_e[b]);
                    let d = rotation * local;
                    let mut best: Option<(f64, f64, usize)> = None;
                    met.clear();
                    for &i in candidates.iter() {
                        if let Some((t, cos)) = intersect(&shapes[i].geometry, &origin, &d) {
                            if best.is_none_or(|(bt, _, _)| t < bt) {
                                best = Some((t, cos, i));
                            }
                            if slots[i] != usize::MAX && t <= lidar.max_range {
                                met.push((slots[i], i, t));
                            }
                        }
                    }
                    // The ground, if it comes first (searched no farther than the nearest
                    // shape).
                    let limit = best.map_or(lidar.max_range, |(bt, _, _)| bt.min(lidar.max_range));
                    let (o, dir) = ([origin.x, origin.y, origin.z], [d.x, d.y, d.z]);
                    if let Some(t) = ground.intersect(o, dir, limit) {
                        if best.is_none_or(|(bt, _, _)| t < bt) {
                            best = Some((t, -d.z, usize::MAX));
                        }
                    }
                    // Occlusion: every object the ray meets is seen when it is the first hit,
                    // hidden when a nearer shape is; a ray that reaches the ground first counts
                    // for none.
                    if let Some((_, _, first)) = best {
                        if first != usize::MAX {
                            for &(slot, i, _) in met.iter() {
                                counts[slot][0] += 1;
                                counts[slot][1] += u32::from(i != first);
                            }
                        }
                    }
                    let Some((t, cos, i)) = best else { continue };
                    if t < lidar.min_range || t > lidar.max_range {
                        continue;
                    }
                    let keep: f64 = rng.random();
                    let noise: f64 = StandardNormal.sample(&mut rng);
                    let shade: f64 = StandardNormal.sample(&mut rng);
                    if keep < lidar.dropout {
                        continue;
                    }
                    let mut r = t + lidar.range_noise * noise;
                    let (surface, base) = if i == usize::MAX {
                        (Surface::Ground, GROUND_REFLECTANCE)
                    } else {
                        let shape = &shapes[i];
                        if shape.scatter > 0.0 {
                            let u: f64 = rng.random();
                            r += shape.scatter * u;
                        }
                        (shape.surface, shape.reflectance as f64)
                    };
                    let refl = (base * (0.5 + 0.5 * cos) + 0.02 * shade).clamp(0.0, 1.0);
                    out[b] = Hit {
                        point: [
                            (local.x * r) as f32,
                            (local.y * r) as f32,
                            (local.z * r) as f32,
                            refl as f32,
                        ],
                        surface: Some(surface),
                    };
                }
                scratch
            },
        )
        .map(|scratch| scratch.counts)
        .reduce(
            || vec![[0; 2]; n_objects],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(&b) {
                    x[0] += y[0];
                    x[1] += y[1];
                }
                a
            },
        );
    let count = buffer.iter().filter(|h| h.surface.is_some()).count();
    let mut scan = LidarScan {
        cloud: PointCloud::with_capacity(count),
        surfaces: Vec::with_capacity(count),
        objects: object_shapes
            .iter()
            .zip(&counts)
            .filter(|(_, n)| n[0] > 0)
            .map(|(&id, n)| ObjectView {
                id,
                rays: n[0],
                hidden: n[1],
            })
            .collect(),
    };
    for h in &buffer {
        if let Some(s) = h.surface {
            scan.cloud
                .push(h.point[0], h.point[1], h.point[2], h.point[3]);
            scan.surfaces.push(s);
        }
    }
    scan
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> LidarConfig {
        LidarConfig {
            columns: 720,
            dropout: 0.0,
            range_noise: 0.0,
            ..LidarConfig::default()
        }
    }

    #[test]
    fn elevations_span_the_hdl64_range() {
        let e: Vec<f64> = LidarConfig::default()
            .elevations()
            .iter()
            .map(|e| e.to_degrees())
            .collect();
        assert_eq!(e.len(), 64);
        assert!((e[0] - 2.0).abs() < 1e-9 && (e[63] + 24.8).abs() < 1e-9);
        assert!((e[31] + 8.33).abs() < 1e-9);
        assert!(e.windows(2).all(|w| w[1] < w[0]), "{e:?}");
    }

    #[test]
    fn ground_points_lie_on_the_ground_in_the_world() {
        let pose = Isometry3::new(
            Vector3::new(3.0, -2.0, 1.73),
            Vector3::new(0.02, -0.01, 0.7),
        );
        let scan = cast_scan(&[], &Ground::flat(), &pose, &small(), 1);
        assert!(!scan.cloud.is_empty());
        for p in scan.cloud.iter() {
            let w = pose * Point3::new(p.x as f64, p.y as f64, p.z as f64);
            assert!(w.z.abs() < 1e-4, "{w}");
            assert!((0.0..=1.0).contains(&p.intensity));
        }
        assert!(scan.surfaces.iter().all(|s| *s == Surface::Ground));
    }

    #[test]
    fn shapes_hit_where_expected_and_occlude() {
        // Sensor at the origin 1.73 m up, looking along x. A wall 10 m ahead (normal −x), a
        // cylinder 5 m ahead on the x axis in front of it, a box behind the sensor.
        let wall = Shape {
            surface: Surface::Wall(0),
            geometry: Geometry::Wall {
                base: [10.0, -5.0],
                along: [0.0, 1.0],
                length: 10.0,
                height: 8.0,
                normal: [-1.0, 0.0],
            },
            reflectance: 0.5,
            scatter: 0.0,
        };
        let person = Shape {
            surface: Surface::Object(1),
            geometry: Geometry::Cylinder {
                centre: [5.0, 0.0],
                radius: 0.3,
                height: 1.75,
            },
            reflectance: 0.5,
            scatter: 0.0,
        };
        let car = Shape {
            surface: Surface::Object(2),
            geometry: Geometry::Box {
                centre: [-8.0, 0.0],
                yaw: 0.3,
                half_length: 2.25,
                half_width: 0.9,
                height: 1.5,
            },
            reflectance: 0.5,
            scatter: 0.0,
        };
        // A hedge to the left, taller than the sensor, whose returns scatter 0.3 m into it.
        let hedge = Shape {
            surface: Surface::Clutter(0),
            geometry: Geometry::Box {
                centre: [0.0, 6.0],
                yaw: 0.0,
                half_length: 3.0,
                half_width: 0.3,
                height: 2.5,
            },
            reflectance: 0.3,
            scatter: 0.3,
        };
        let pose = Isometry3::translation(0.0, 0.0, 1.73);
        let scan = cast_scan(
            &[wall, person, car, hedge],
            &Ground::flat(),
            &pose,
            &small(),
            2,
        );
        let mut seen = [0usize; 3];
        let mut hedge_y: Vec<f64> = Vec::new();
        for (p, s) in scan.cloud.iter().zip(&scan.surfaces) {
            let (x, y, z) = (p.x as f64, p.y as f64, p.z as f64 + 1.73);
            match s {
                Surface::Wall(_) => {
                    seen[0] += 1;
                    assert!((x - 10.0).abs() < 1e-4 && y.abs() <= 5.0 + 1e-4 && z <= 8.0);
                    // Not behind the pedestrian's shadow at the same azimuth and height.
                    assert!(!(y.abs() < 0.2 && z < 1.0));
                }
                Surface::Object(1) => {
                    seen[1] += 1;
                    assert!(((x - 5.0).hypot(y) - 0.3).abs() < 1e-4 && z <= 1.75 + 1e-6);
                }
                Surface::Object(_) => {
                    seen[2] += 1;
                    assert!(x < -5.0 && z <= 1.5 + 1e-6);
                }
                Surface::Clutter(_) => {
                    // Entered through the face at y = 5.7 and no deeper than 0.3 m along the ray.
                    assert!(
                        x.abs() <= 3.3 && (5.7 - 1e-4..=6.0 + 1e-4).contains(&y),
                        "{x} {y} {z}"
                    );
                    hedge_y.push(y);
                }
                Surface::Ground => assert!(z.abs() < 1e-4),
            }
        }
        assert!(seen.iter().all(|&n| n > 10), "{seen:?}");
        assert!(hedge_y.len() > 10, "{}", hedge_y.len());
        let (lo, hi) = hedge_y
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &y| {
                (a.min(y), b.max(y))
            });
        assert!(hi - lo > 0.2, "hedge returns from {lo} to {hi} m");
    }

    fn car_at(id: u32, x: f64, y: f64) -> Shape {
        Shape {
            surface: Surface::Object(id),
            geometry: Geometry::Box {
                centre: [x, y],
                yaw: 0.0,
                half_length: 2.25,
                half_width: 0.9,
                height: 1.5,
            },
            reflectance: 0.5,
            scatter: 0.0,
        }
    }

    fn view(scan: &LidarScan, id: u32) -> ObjectView {
        *scan.objects.iter().find(|v| v.id == id).unwrap()
    }

    #[test]
    fn a_car_behind_another_is_largely_hidden_and_one_alone_is_not() {
        // Sensor 1.73 m up at the origin; car 1 centred 10 m ahead, car 2 20 m ahead on the
        // same line, car 3 alone 15 m to the left, a wall 40 m ahead behind them all. Car 2
        // spans azimuths ±atan(0.9/17.75) = ±2.9°, inside car 1's ±atan(0.9/7.75) = ±6.6°;
        // in elevation it spans atan(−1.73/17.75) = −5.6° up to its roof's far edge,
        // atan(−0.23/22.25) = −0.6°, and car 1's top rear edge hides all below
        // atan(−0.23/12.25) = −1.1°: about 0.5° of 5°, so some nine tenths are hidden.
        let wall = Shape {
            surface: Surface::Wall(0),
            geometry: Geometry::Wall {
                base: [40.0, -20.0],
                along: [0.0, 1.0],
                length: 40.0,
                height: 8.0,
                normal: [-1.0, 0.0],
            },
            reflectance: 0.5,
            scatter: 0.0,
        };
        let shapes = [
            car_at(1, 10.0, 0.0),
            car_at(2, 20.0, 0.0),
            car_at(3, 0.0, 15.0),
            wall,
        ];
        let pose = Isometry3::translation(0.0, 0.0, 1.73);
        let cfg = LidarConfig {
            columns: 2000,
            ..small()
        };
        let scan = cast_scan(&shapes, &Ground::flat(), &pose, &cfg, 3);
        let (front, behind, alone) = (view(&scan, 1), view(&scan, 2), view(&scan, 3));
        assert_eq!(front.hidden, 0, "{front:?}");
        assert_eq!(alone.hidden, 0, "{alone:?}");
        assert!(front.rays > 100 && alone.rays > 100, "{front:?} {alone:?}");
        let share = behind.hidden_share().unwrap();
        assert!((0.8..0.98).contains(&share), "{behind:?}");
        use crate::sim::street::truth::occlusion_level;
        assert_eq!(occlusion_level(front.hidden_share()), 0);
        assert_eq!(occlusion_level(alone.hidden_share()), 0);
        assert_eq!(occlusion_level(Some(share)), 2);
        // The occlusion counts are geometry: dropout and the seed do not change them.
        let dropped = cast_scan(
            &shapes,
            &Ground::flat(),
            &pose,
            &LidarConfig {
                dropout: 0.5,
                ..cfg
            },
            4,
        );
        assert_eq!(dropped.objects, scan.objects);
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]
        #[test]
        fn hidden_counts_stay_within_the_rays(
            cars in proptest::collection::vec((-30.0f64..30.0, -30.0f64..30.0), 1..8),
        ) {
            let shapes: Vec<Shape> = cars
                .iter()
                .enumerate()
                .map(|(i, &(x, y))| car_at(i as u32, x, y))
                .collect();
            let pose = Isometry3::translation(0.0, 0.0, 1.73);
            let cfg = LidarConfig { columns: 360, ..small() };
            let scan = cast_scan(&shapes, &Ground::flat(), &pose, &cfg, 5);
            for v in &scan.objects {
                proptest::prop_assert!(v.rays > 0 && v.hidden <= v.rays, "{:?}", v);
                let h = v.hidden_share().unwrap();
                proptest::prop_assert!((0.0..=1.0).contains(&h));
            }
        }
    }

    #[test]
    fn occlusion_counts_do_not_depend_on_the_thread_count() {
        let shapes: Vec<Shape> = (0..12)
            .map(|i| car_at(i, 6.0 + 5.5 * i as f64, if i % 2 == 0 { 4.0 } else { -4.0 }))
            .collect();
        let pose = Isometry3::translation(0.0, 0.0, 1.73);
        let cfg = LidarConfig::default();
        let a = cast_scan(&shapes, &Ground::flat(), &pose, &cfg, 9);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let b = pool.install(|| cast_scan(&shapes, &Ground::flat(), &pose, &cfg, 9));
        assert_eq!(a, b);
        assert_eq!(a.objects.len(), 12);
    }

    #[test]
    fn same_seed_same_scan_any_thread_count() {
        let pose = Isometry3::translation(0.0, 0.0, 1.73);
        let cfg = LidarConfig {
            columns: 500,
            ..LidarConfig::default()
        };
        let a = cast_scan(&[], &Ground::flat(), &pose, &cfg, 9);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let b = pool.install(|| cast_scan(&[], &Ground::flat(), &pose, &cfg, 9));
        assert_eq!(a, b);
        assert_ne!(a, cast_scan(&[], &Ground::flat(), &pose, &cfg, 10));
    }
}
