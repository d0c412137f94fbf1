//! The simulated street scene in the world frame (x east, y north, z up, ground near z = 0,
//! see [`super::ground`]): the street segments that follow the ego route, building walls along
//! both sides, the road users (parked cars and vans, moving cars, vans, trucks and cyclists,
//! pedestrians) with their motion, and the street clutter of [`super::clutter`].
//!
//! **Layout.** Each straight stretch of the ego route is one street segment; its centreline is
//! the ego's straight line shifted by the ego lane offset. Consecutive segments meet at a
//! corner, the intersection of their centrelines. Building walls stand on lines parallel to
//! the centreline at ±(road half-width + sidewalk width); along each side they run from the
//! side's corner with the previous segment to the side's corner with the next one (so walls of
//! consecutive segments meet at building corners), cut into pieces of random length with random
//! gaps, each piece a vertical rectangle of random height.
//!
//! **Objects.** Parked cars and vans stand at the kerb; moving cars, vans and trucks drive at
//! their lane's constant speed and cyclists at their own in a lane (right of the centreline in
//! the ego's direction, left against it), never in the ego's lane; pedestrians walk along the
//! sidewalks. Positions are drawn at random near the ego's path and
//! rejected when too close to a corner, to another object of the same row, or (at any frame)
//! to the ego vehicle. A moving object exists while it is on its segment and more than the
//! corner clearance away from the segment's corners.
//!
//! Not for: ray casting (see [`super::lidar`]) or the ego motion (see [`super::ego`]).

use super::clutter::{Clutter, ClutterKind};
use super::lidar::{Geometry, Shape, Surface};
use super::StreetConfig;
use crate::error::{Error, Result};
use crate::rng::FilterRng;
use rand::RngExt;
use serde::{Deserialize, Serialize};

/// One straight street segment: centreline `point + s·dir`, between corners at `s_start` and
/// `s_end`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// A point on the centreline (s = 0), metres.
    pub point: [f64; 2],
    /// Unit direction of travel of the ego.
    pub dir: [f64; 2],
    /// Along-street coordinate of the corner with the previous segment (or the start).
    pub s_start: f64,
    /// Along-street coordinate of the corner with the next segment (or the end).
    pub s_end: f64,
}

impl Segment {
    /// Unit vector to the left of the direction of travel.
    pub fn left(&self) -> [f64; 2] {
        [-self.dir[1], self.dir[0]]
    }

    /// World point at along-street coordinate `s` and lateral offset `lateral` (left > 0).
    pub fn at(&self, s: f64, lateral: f64) -> [f64; 2] {
        let l = self.left();
        [
            self.point[0] + s * self.dir[0] + lateral * l[0],
            self.point[1] + s * self.dir[1] + lateral * l[1],
        ]
    }
}

/// A building wall: the vertical rectangle over the ground segment `base`…`base + length·along`,
/// from z = 0 to `height`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wall {
    /// Identifier (index in the street's wall list).
    pub id: u32,
    /// One ground corner, metres.
    pub base: [f64; 2],
    /// Unit horizontal direction along the wall.
    pub along: [f64; 2],
    /// Length along the wall, metres.
    pub length: f64,
    /// Height, metres.
    pub height: f64,
    /// Unit horizontal normal, pointing towards the street.
    pub normal: [f64; 2],
    /// Reflectance of the facade.
    pub reflectance: f32,
}

impl Wall {
    /// The four corners: ground start, ground end, top end, top start.
    pub fn vertices(&self) -> [[f64; 3]; 4] {
        let (b, a, l, h) = (self.base, self.along, self.length, self.height);
        let e = [b[0] + l * a[0], b[1] + l * a[1]];
        [
            [b[0], b[1], 0.0],
            [e[0], e[1], 0.0],
            [e[0], e[1], h],
            [b[0], b[1], h],
        ]
    }

    /// Plane offset d of n·p + d = 0 with the street-facing normal.
    pub fn offset(&self) -> f64 {
        -(self.normal[0] * self.base[0] + self.normal[1] * self.base[1])
    }
}

/// What an object is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObjectKind {
    /// A moving car (oriented box).
    Car,
    /// A walking pedestrian (vertical cylinder).
    Pedestrian,
    /// A parked car (oriented box, never moves).
    ParkedCar,
    /// A moving van (oriented box).
    Van,
    /// A parked van (oriented box, never moves).
    ParkedVan,
    /// A moving truck (oriented box).
    Truck,
    /// A cyclist on a bicycle (oriented box).
    Cyclist,
}

impl ObjectKind {
    /// Whether the object never moves.
    pub fn is_parked(self) -> bool {
        matches!(self, ObjectKind::ParkedCar | ObjectKind::ParkedVan)
    }
}

/// A car or pedestrian moving at constant velocity along its street segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Object {
    /// Identifier.
    pub id: u32,
    /// Kind.
    pub kind: ObjectKind,
    /// Length, width, height (a pedestrian: diameter, diameter, height), metres.
    pub size: [f64; 3],
    /// Segment the object moves on.
    pub segment: usize,
    /// Along-street coordinate at time 0.
    pub s0: f64,
    /// Lateral offset from the centreline (left > 0).
    pub lateral: f64,
    /// Signed speed along the segment direction, m/s.
    pub speed: f64,
    /// Heading, rad (counter-clockwise from east).
    pub yaw: f64,
    /// The object exists while its along-street coordinate is within this range.
    pub s_range: (f64, f64),
    /// Reflectance of the surface.
    pub reflectance: f32,
}

impl Object {
    /// Ground position (centre of the footprint) and velocity at time `t`, or `None` when the
    /// object does not exist then.
    pub fn state_at(&self, segments: &[Segment], t: f64) -> Option<([f64; 2], [f64; 2])> {
        let s = self.s0 + self.speed * t;
        if s < self.s_range.0 || s > self.s_range.1 {
            return None;
        }
        let seg = &segments[self.segment];
        let v = [self.speed * seg.dir[0], self.speed * seg.dir[1]];
        Some((seg.at(s, self.lateral), v))
    }

    /// The object's shape at time `t` if it exists then.
    pub fn shape_at(&self, segments: &[Segment], t: f64) -> Option<Shape> {
        let (p, _) = self.state_at(segments, t)?;
        let geometry = match self.kind {
            ObjectKind::Pedestrian => Geometry::Cylinder {
                centre: p,
                radius: 0.5 * self.size[0],
                height: self.size[2],
            },
            _ => Geometry::Box {
                centre: p,
                yaw: self.yaw,
                half_length: 0.5 * self.size[0],
                half_width: 0.5 * self.size[1],
                height: self.size[2],
            },
        };
        Some(Shape {
            surface: Surface::Object(self.id),
            geometry,
            reflectance: self.reflectance,
            scatter: 0.0,
        })
    }
}

/// The whole static and moving scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Street {
    /// Street segments in route order.
    pub segments: Vec<Segment>,
    /// Building walls.
    pub walls: Vec<Wall>,
    /// Road users.
    pub objects: Vec<Object>,
    /// Poles, trunks, hedges and low walls.
    pub clutter: Vec<Clutter>,
    /// How deep a ray enters a hedge (the configuration's `clutter.hedge_scatter`).
    pub hedge_scatter: f64,
}

impl Street {
    /// Walls and existing objects at time `t`, as shapes for the ray caster.
    pub fn shapes_at(&self, t: f64) -> Vec<Shape> {
        let walls = self.walls.iter().map(|w| Shape {
            surface: Surface::Wall(w.id),
            geometry: Geometry::Wall {
                base: w.base,
                along: w.along,
                length: w.length,
                height: w.height,
                normal: w.normal,
            },
            reflectance: w.reflectance,
            scatter: 0.0,
        });
        let objects = self
            .objects
            .iter()
            .filter_map(|o| o.shape_at(&self.segments, t));
        let clutter = self.clutter.iter().map(|c| c.shape(self.hedge_scatter));
        walls.chain(objects).chain(clutter).collect()
    }
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Along-coordinate on line (p, d) of its intersection with line (q, e).
fn intersect(p: [f64; 2], d: [f64; 2], q: [f64; 2], e: [f64; 2]) -> f64 {
    cross([q[0] - p[0], q[1] - p[1]], e) / cross(d, e)
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// A draw uniform in `[range[0], range[1])`, or `range[0]` for an empty range.
fn uniform(rng: &mut FilterRng, range: [f64; 2]) -> f64 {
    if range[1] > range[0] {
        rng.random_range(range[0]..range[1])
    } else {
        range[0]
    }
}

/// Builds the street around the ego's straight lines (`lines`, see
/// [`super::ego::EgoTrajectory::straight_lines`]) for a drive whose ego positions are `ego` at
/// times `times`.
///
/// Errors: a route leg too short for the street width, so that consecutive corners overlap.
pub fn build_street(
    config: &StreetConfig,
    lines: &[([f64; 2], [f64; 2])],
    ego: &[[f64; 2]],
    times: &[f64],
    rng: &mut FilterRng,
) -> Result<Street> {
    let layout = &config.street;
    let centre_shift = -layout.ego_lane_offset;
    let segments_raw: Vec<([f64; 2], [f64; 2])> = lines
        .iter()
        .map(|&(p, d)| {
            let l = [-d[1], d[0]];
            ([p[0] + centre_shift * l[0], p[1] + centre_shift * l[1]], d)
        })
        .collect();
    let n = segments_raw.len();
    let last_ego = *ego.last().unwrap_or(&segments_raw[0].0);
    // Along-coordinate of a line's intersection with the neighbour, for a lateral offset.
    let corner = |j: usize, k: usize, lateral: f64| -> f64 {
        let (p, d) = segments_raw[j];
        let (q, e) = segments_raw[k];
        let (lp, le) = ([-d[1], d[0]], [-e[1], e[0]]);
        let p = [p[0] + lateral * lp[0], p[1] + lateral * lp[1]];
        let q = [q[0] + lateral * le[0], q[1] + lateral * le[1]];
        intersect(p, d, q, e)
    };
    let end_s = |j: usize| -> f64 {
        let (p, d) = segments_raw[j];
        (last_ego[0] - p[0]) * d[0] + (last_ego[1] - p[1]) * d[1] + layout.beyond_end
    };
    let extent = |j: usize, lateral: f64| -> (f64, f64) {
        let start = if j == 0 {
            -layout.behind_start
        } else {
            corner(j, j - 1, lateral)
        };
        let end = if j + 1 == n {
            end_s(j).max(start + layout.beyond_end)
        } else {
            corner(j, j + 1, lateral)
        };
        (start, end)
    };
    let wall_offset = layout.road_half_width + layout.sidewalk_width;
    let mut segments = Vec::with_capacity(n);
    for (j, &(point, dir)) in segments_raw.iter().enumerate().take(n) {
        let (s_start, s_end) = extent(j, 0.0);
        for lateral in [-wall_offset, 0.0, wall_offset] {
            let (a, b) = extent(j, lateral);
            if b - a < 1.0 {
                return Err(Error::invalid(
                    format!("route leg {j}"),
                    format!(
                        "too short for a street {:.1} m wide between walls: its corners overlap \
                         (lengthen the straight or soften the turns)",
                        2.0 * wall_offset
                    ),
                ));
            }
        }
        segments.push(Segment {
            point,
            dir,
            s_start,
            s_end,
        });
    }

    let mut walls = Vec::new();
    for (j, seg) in segments.iter().enumerate() {
        for side in [1.0, -1.0] {
            let lateral = side * wall_offset;
            let (a, b) = extent(j, lateral);
            let mut s = a;
            let normal_dir = [-side * seg.left()[0], -side * seg.left()[1]];
            while s < b {
                let end = (s + uniform(rng, layout.wall_length)).min(b);
                if end - s >= layout.min_wall_piece {
                    walls.push(Wall {
                        id: walls.len() as u32,
                        base: seg.at(s, lateral),
                        along: seg.dir,
                        length: end - s,
                        height: uniform(rng, layout.wall_height),
                        normal: normal_dir,
                        reflectance: rng.random_range(0.15f32..0.6),
                    });
                }
                s = end + uniform(rng, layout.wall_gap);
            }
        }
    }

    let objects = place_objects(config, &segments, ego, times, rng);
    let clutter = place_clutter(config, &segments, ego, rng);
    Ok(Street {
        segments,
        walls,
        objects,
        clutter,
        hedge_scatter: config.clutter.hedge_scatter,
    })
}

/// Places the configured clutter along `segments` near the ego's positions `ego`. Every piece
/// stands in one of two rows on each side of the street, clear of the road users' rows
/// (parked cars at the kerb, pedestrians on the sidewalk): poles and trunks
/// [`ClutterConfig::kerb_setback`](super::clutter::ClutterConfig::kerb_setback) behind the
/// kerb, hedges and low walls against the building line. A piece is drawn at random along a
/// segment (away from its corners by the traffic's `corner_clearance`, within `spawn_radius`
/// of the ego's path) and redrawn when it would come within 1 m of another piece of its row;
/// one that finds no free place in 2000 draws is left out.
fn place_clutter(
    config: &StreetConfig,
    segments: &[Segment],
    ego: &[[f64; 2]],
    rng: &mut FilterRng,
) -> Vec<Clutter> {
    let c = &config.clutter;
    let layout = &config.street;
    let traffic = &config.traffic;
    let kerb_row = layout.road_half_width + c.kerb_setback;
    let building_row = layout.road_half_width + layout.sidewalk_width;
    let kinds = std::iter::repeat_n(ClutterKind::Pole, c.poles)
        .chain(std::iter::repeat_n(ClutterKind::Trunk, c.trunks))
        .chain(std::iter::repeat_n(ClutterKind::Hedge, c.hedges))
        .chain(std::iter::repeat_n(ClutterKind::LowWall, c.low_walls));
    // Each piece placed with its segment, along- and signed lateral coordinates.
    let mut out: Vec<(usize, f64, f64, Clutter)> = Vec::new();
    for kind in kinds {
        let size = match kind {
            ClutterKind::Pole => {
                let d = 2.0 * uniform(rng, c.pole_radius);
                [d, d, uniform(rng, c.pole_height)]
            }
            ClutterKind::Trunk => {
                let d = 2.0 * uniform(rng, c.trunk_radius);
                [d, d, uniform(rng, c.trunk_height)]
            }
            ClutterKind::Hedge => [
                uniform(rng, c.hedge_length),
                uniform(rng, c.hedge_width),
                uniform(rng, c.hedge_height),
            ],
            ClutterKind::LowWall => [
                uniform(rng, c.low_wall_length),
                uniform(rng, c.low_wall_width),
                uniform(rng, c.low_wall_height),
            ],
        };
        let (lateral_abs, reflectance) = match kind {
            ClutterKind::Pole => (kerb_row, rng.random_range(0.3f32..0.6)),
            ClutterKind::Trunk => (kerb_row, rng.random_range(0.2f32..0.4)),
            // Against the building line, 5 cm in front of it.
            ClutterKind::Hedge | ClutterKind::LowWall => (
                building_row - 0.5 * size[1] - 0.05,
                rng.random_range(0.15f32..0.5),
            ),
        };
        for _attempt in 0..2000 {
            let j = rng.random_range(0..segments.len());
            let seg = &segments[j];
            let side = if rng.random_range(0..2) == 0 {
                1.0
            } else {
                -1.0
            };
            let clear = traffic.corner_clearance;
            let (lo, hi) = (seg.s_start + clear, seg.s_end - clear);
            if hi <= lo {
                continue;
            }
            let s = rng.random_range(lo..hi);
            let lateral = side * lateral_abs;
            let centre = seg.at(s, lateral);
            if !ego.iter().any(|e| dist(*e, centre) <= traffic.spawn_radius) {
                continue;
            }
            let crowded = out.iter().any(|(k, other_s, other_lateral, o)| {
                *k == j
                    && (other_lateral - lateral).abs() < 1.0
                    && (other_s - s).abs() < 0.5 * (o.size[0] + size[0]) + 1.0
            });
            if crowded {
                continue;
            }
            let piece = Clutter {
                id: out.len() as u32,
                kind,
                centre,
                yaw: seg.dir[1].atan2(seg.dir[0]),
                size,
                reflectance,
            };
            out.push((j, s, lateral, piece));
            break;
        }
    }
    out.into_iter().map(|(_, _, _, p)| p).collect()
}

/// One row of objects: where on the street and how it moves.
struct Row {
    kind: ObjectKind,
    lateral: f64,
    speed: f64,
    min_spacing: f64,
    clearance_to_ego: f64,
}

fn place_objects(
    config: &StreetConfig,
    segments: &[Segment],
    ego: &[[f64; 2]],
    times: &[f64],
    rng: &mut FilterRng,
) -> Vec<Object> {
    let layout = &config.street;
    let traffic = &config.traffic;
    let wall_offset = layout.road_half_width + layout.sidewalk_width;
    let lane = layout.lane_width;
    let ego_lane = layout.ego_lane_offset;
    // Lanes other than the ego's: centres at ±(i + 1/2)·lane inside the road.
    let mut lanes = Vec::new();
    let mut c = 0.5 * lane;
    while c + 0.5 * traffic.car_size[1] <= layout.road_half_width - traffic.car_size[1] - 0.2 {
        for lat in [c, -c] {
            if (lat - ego_lane).abs() > 0.5 * lane {
                lanes.push(lat);
            }
        }
        c += lane;
    }
    // Per (segment, lane) speed, so cars of one lane never run into each other.
    let lane_speeds: Vec<Vec<f64>> = segments
        .iter()
        .map(|_| {
            lanes
                .iter()
                .map(|_| uniform(rng, traffic.car_speed))
                .collect()
        })
        .collect();
    let kerb = |width: f64| layout.road_half_width - 0.5 * width - 0.1;
    let size_of = |kind: ObjectKind| match kind {
        ObjectKind::Pedestrian => [
            2.0 * traffic.pedestrian_radius,
            2.0 * traffic.pedestrian_radius,
            traffic.pedestrian_height,
        ],
        ObjectKind::Car | ObjectKind::ParkedCar => traffic.car_size,
        ObjectKind::Van | ObjectKind::ParkedVan => traffic.van_size,
        ObjectKind::Truck => traffic.truck_size,
        ObjectKind::Cyclist => traffic.cyclist_size,
    };
    let mut objects: Vec<Object> = Vec::new();
    // The plain street's kinds first, so that adding the others leaves its objects as they were.
    let kinds = std::iter::repeat_n(ObjectKind::ParkedCar, traffic.parked_cars)
        .chain(std::iter::repeat_n(ObjectKind::Car, traffic.moving_cars))
        .chain(std::iter::repeat_n(
            ObjectKind::Pedestrian,
            traffic.pedestrians,
        ))
        .chain(std::iter::repeat_n(
            ObjectKind::ParkedVan,
            traffic.parked_vans,
        ))
        .chain(std::iter::repeat_n(ObjectKind::Van, traffic.moving_vans))
        .chain(std::iter::repeat_n(ObjectKind::Truck, traffic.trucks))
        .chain(std::iter::repeat_n(ObjectKind::Cyclist, traffic.cyclists));
    for kind in kinds {
        for _attempt in 0..2000 {
            let j = rng.random_range(0..segments.len());
            let seg = &segments[j];
            let side: f64 = if rng.random_range(0..2) == 0 {
                1.0
            } else {
                -1.0
            };
            let size = size_of(kind);
            let row = match kind {
                ObjectKind::ParkedCar | ObjectKind::ParkedVan => Row {
                    kind,
                    lateral: side * kerb(size[1]),
                    speed: 0.0,
                    min_spacing: size[0] + 1.5,
                    clearance_to_ego: 2.0,
                },
                ObjectKind::Car | ObjectKind::Van | ObjectKind::Truck | ObjectKind::Cyclist => {
                    if lanes.is_empty() {
                        break;
                    }
                    let i = rng.random_range(0..lanes.len());
                    let lateral = lanes[i];
                    let v = if kind == ObjectKind::Cyclist {
                        uniform(rng, traffic.cyclist_speed)
                    } else {
                        lane_speeds[j][i]
                    };
                    Row {
                        kind,
                        lateral,
                        // Right of the centreline: the ego's direction; left: against it.
                        speed: if lateral < 0.0 { v } else { -v },
                        // Clear of a car (or a truck) ahead and behind at every frame.
                        min_spacing: 2.0 * traffic.car_size[0]
                            + (size[0] - traffic.car_size[0]).max(0.0),
                        clearance_to_ego: if kind == ObjectKind::Cyclist {
                            3.0
                        } else {
                            4.0
                        },
                    }
                }
                ObjectKind::Pedestrian => {
                    let forward = rng.random_range(0..2) == 0;
                    let v = uniform(rng, traffic.pedestrian_speed);
                    // Two walking rows per sidewalk, one per direction.
                    let depth = traffic.pedestrian_rows[usize::from(!forward)];
                    Row {
                        kind,
                        lateral: side * (wall_offset - depth),
                        speed: if forward { v } else { -v },
                        min_spacing: 2.0,
                        clearance_to_ego: 2.0,
                    }
                }
            };
            let clear = traffic.corner_clearance;
            let (lo, hi) = (seg.s_start + clear, seg.s_end - clear);
            if hi <= lo {
                continue;
            }
            let s0 = rng.random_range(lo..hi);
            let p0 = seg.at(s0, row.lateral);
            if !ego.iter().any(|e| dist(*e, p0) <= traffic.spawn_radius) {
                continue;
            }
            let crowded = objects.iter().any(|o| {
                o.segment == j
                    && (o.lateral - row.lateral).abs() < 0.5
                    && times.iter().any(|&t| {
                        let a = o.s0 + o.speed * t;
                        let b = s0 + row.speed * t;
                        (a - b).abs() < row.min_spacing
                    })
            });
            if crowded {
                continue;
            }
            let mut object = Object {
                id: objects.len() as u32,
                kind: row.kind,
                size,
                segment: j,
                s0,
                lateral: row.lateral,
                speed: row.speed,
                yaw: 0.0,
                s_range: if row.speed == 0.0 {
                    (f64::NEG_INFINITY, f64::INFINITY)
                } else {
                    (lo, hi)
                },
                reflectance: rng.random_range(0.1f32..0.9),
            };
            let backwards = row.speed < 0.0
                || (row.speed == 0.0 && rng.random_range(0..2) == 0 && kind != ObjectKind::Car);
            let heading = seg.dir[1].atan2(seg.dir[0]);
            object.yaw = if backwards {
                crate::geometry::wrap_angle(heading + std::f64::consts::PI)
            } else {
                heading
            };
            let hits_ego = ego.iter().zip(times).any(|(e, &t)| {
                object
                    .state_at(segments, t)
                    .is_some_and(|(p, _)| dist(*e, p) < row.clearance_to_ego + 2.5)
            });
            if hits_ego {
                continue;
            }
            objects.push(object);
            break;
        }
    }
    place_parked_rows(config, segments, ego, times, rng, &mut objects);
    objects
}

/// Appends the rows of parked vehicles of `config.traffic.parked_rows` to `objects`: per
/// segment and kerb with a row, from the first corner clearance on, vehicle after vehicle
/// nose to tail with drawn gaps (see [`ParkedRows`](super::config::ParkedRows)). A vehicle
/// is kept only when it starts within the spawn radius of the ego's path, keeps 0.5 m clear of
/// the objects already parked at that kerb, and never comes near the ego. Draws nothing when
/// there are no rows, so streets without them are as before.
fn place_parked_rows(
    config: &StreetConfig,
    segments: &[Segment],
    ego: &[[f64; 2]],
    times: &[f64],
    rng: &mut FilterRng,
    objects: &mut Vec<Object>,
) {
    let traffic = &config.traffic;
    let rows = &traffic.parked_rows;
    let layout = &config.street;
    for (j, seg) in segments.iter().enumerate() {
        let clear = traffic.corner_clearance;
        let (lo, hi) = (seg.s_start + clear, seg.s_end - clear);
        let heading = seg.dir[1].atan2(seg.dir[0]);
        for &side in rows.sides.signs() {
            // `s` is where the next vehicle's rear (in the ego's direction) may start.
            let mut s = lo + uniform(rng, rows.gap);
            loop {
                let van = rng.random::<f64>() < rows.van_share;
                let (kind, size) = if van {
                    (ObjectKind::ParkedVan, traffic.van_size)
                } else {
                    (ObjectKind::ParkedCar, traffic.car_size)
                };
                let reflectance = rng.random_range(0.1f32..0.9);
                let gap = if rng.random::<f64>() < rows.opening_share {
                    uniform(rng, rows.opening)
                } else {
                    uniform(rng, rows.gap)
                };
                if s + size[0] > hi {
                    break;
                }
                let s0 = s + 0.5 * size[0];
                s += size[0] + gap;
                let lateral = side * (layout.road_half_width - 0.5 * size[1] - 0.1);
                let p0 = seg.at(s0, lateral);
                if !ego.iter().any(|e| dist(*e, p0) <= traffic.spawn_radius) {
                    continue;
                }
                let crowded = objects.iter().any(|o| {
                    o.segment == j
                        && o.speed == 0.0
                        && (o.lateral - lateral).abs() < 0.5
                        && (o.s0 - s0).abs() < 0.5 * (o.size[0] + size[0]) + 0.5
                });
                if crowded {
                    continue;
                }
                // Parked with the traffic of its kerb: on the right in the ego's direction.
                let yaw = if side < 0.0 {
                    heading
                } else {
                    crate::geometry::wrap_angle(heading + std::f64::consts::PI)
                };
                let object = Object {
                    id: objects.len() as u32,
                    kind,
                    size,
                    segment: j,
                    s0,
                    lateral,
                    speed: 0.0,
                    yaw,
                    s_range: (f64::NEG_INFINITY, f64::INFINITY),
                    reflectance,
                };
                let hits_ego = ego.iter().zip(times).any(|(e, &t)| {
                    object
                        .state_at(segments, t)
                        .is_some_and(|(p, _)| dist(*e, p) < 2.0 + 2.5)
                });
                if !hits_ego {
                    objects.push(object);
                }
            }
        }
    }
}
