//! A simulated street as data: the street's layout, traffic, clutter, ground, body motion,
//! lidar and recording, each with defaults, and their validation. The default is the plain
//! street (cars and pedestrians between walls); [`StreetConfig::urban`] adds vans, trucks,
//! cyclists and street clutter in numbers like a KITTI city drive's.
//!
//! Not for: simulating (see [`super::StreetSimulator`]).

use super::body::BodyMotionConfig;
use super::clutter::ClutterConfig;
use super::ego::LegSpec;
use super::ground::GroundConfig;
use super::lidar::LidarConfig;
use crate::error::{
    ensure_non_negative, ensure_positive, ensure_probability, ensure_range, Error, Result,
};
use crate::kitti::Timestamp;
use serde::{Deserialize, Serialize};

/// Street cross-section and building walls. Lengths in metres.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StreetLayout {
    /// Distance from the centreline to the kerb.
    pub road_half_width: f64,
    /// Sidewalk width between kerb and walls.
    pub sidewalk_width: f64,
    /// Lane width.
    pub lane_width: f64,
    /// Lateral offset of the ego's path from the centreline (negative = right).
    pub ego_lane_offset: f64,
    /// Range of wall piece lengths.
    pub wall_length: [f64; 2],
    /// Range of gaps between wall pieces.
    pub wall_gap: [f64; 2],
    /// Range of wall heights.
    pub wall_height: [f64; 2],
    /// Shorter pieces left at segment ends are dropped.
    pub min_wall_piece: f64,
    /// The street starts this far behind the ego's start.
    pub behind_start: f64,
    /// The last street segment reaches this far beyond the ego's last position.
    pub beyond_end: f64,
}

impl Default for StreetLayout {
    fn default() -> Self {
        StreetLayout {
            road_half_width: 9.0,
            sidewalk_width: 3.0,
            lane_width: 3.5,
            ego_lane_offset: -1.75,
            wall_length: [20.0, 45.0],
            wall_gap: [3.0, 10.0],
            wall_height: [6.0, 15.0],
            min_wall_piece: 5.0,
            behind_start: 60.0,
            beyond_end: 80.0,
        }
    }
}

/// Road users: cars, vans, trucks, cyclists and pedestrians. Vehicles and cyclists drive in
/// the lanes other than the ego's at their lane's speed (cyclists at their own), parked cars
/// and vans stand at the kerb, pedestrians walk along the sidewalks.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrafficConfig {
    /// Number of parked cars.
    pub parked_cars: usize,
    /// Number of moving cars.
    pub moving_cars: usize,
    /// Number of pedestrians.
    pub pedestrians: usize,
    /// Number of parked vans.
    pub parked_vans: usize,
    /// Number of moving vans.
    pub moving_vans: usize,
    /// Number of (moving) trucks.
    pub trucks: usize,
    /// Number of cyclists.
    pub cyclists: usize,
    /// Car length, width, height, metres.
    pub car_size: [f64; 3],
    /// Van length, width, height, metres.
    pub van_size: [f64; 3],
    /// Truck length, width, height, metres.
    pub truck_size: [f64; 3],
    /// A cyclist with the bicycle: length, width, height, metres.
    pub cyclist_size: [f64; 3],
    /// Range of moving car speeds, m/s (vans and trucks too: a lane has one speed).
    pub car_speed: [f64; 2],
    /// Range of cycling speeds, m/s.
    pub cyclist_speed: [f64; 2],
    /// Pedestrian radius, metres.
    pub pedestrian_radius: f64,
    /// Pedestrian height, metres.
    pub pedestrian_height: f64,
    /// Range of walking speeds, m/s.
    pub pedestrian_speed: [f64; 2],
    /// Distances from the building line of the sidewalks' two walking rows (the first walks
    /// in the ego's direction, the second against it), metres.
    pub pedestrian_rows: [f64; 2],
    /// Objects keep this far from street corners (moving ones vanish there), metres.
    pub corner_clearance: f64,
    /// Objects start within this distance of the ego's path, metres.
    pub spawn_radius: f64,
    /// Rows of parked cars and vans nose to tail at the kerb, on top of the `parked_cars` and
    /// `parked_vans` placed one by one; none by default (and then not written).
    #[serde(skip_serializing_if = "ParkedRows::is_off")]
    pub parked_rows: ParkedRows,
}

/// The kerb sides a row of parked vehicles stands on, seen in the ego's direction of travel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RowSides {
    /// No rows.
    #[default]
    None,
    /// The ego's (right) kerb.
    Right,
    /// The far (left) kerb.
    Left,
    /// Both kerbs.
    Both,
}

impl RowSides {
    /// The signed lateral directions (left > 0) of the kerbs with rows.
    pub fn signs(self) -> &'static [f64] {
        match self {
            RowSides::None => &[],
            RowSides::Right => &[-1.0],
            RowSides::Left => &[1.0],
            RowSides::Both => &[-1.0, 1.0],
        }
    }
}

/// Parked cars and vans in rows at the kerb, nose to tail, as along a residential street: from
/// the road the vehicles farther along a row are largely hidden behind the nearer ones. A row
/// runs along each street segment between the corner clearances, only where it is within the
/// spawn radius of the ego's path; vehicle after vehicle, a van with probability `van_share`,
/// each gap drawn uniformly from `gap`, and, with probability `opening_share`, a longer
/// opening (a driveway or a crossing) drawn from `opening`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ParkedRows {
    /// Kerbs with a row.
    pub sides: RowSides,
    /// Range of the gaps between consecutive vehicles, metres.
    pub gap: [f64; 2],
    /// Probability that a vehicle of a row is a van.
    pub van_share: f64,
    /// Probability that a gap is an opening instead.
    pub opening_share: f64,
    /// Range of the openings' lengths, metres.
    pub opening: [f64; 2],
}

impl Default for ParkedRows {
    fn default() -> Self {
        ParkedRows {
            sides: RowSides::None,
            gap: [0.5, 2.0],
            van_share: 0.2,
            opening_share: 0.1,
            opening: [4.0, 10.0],
        }
    }
}

impl ParkedRows {
    /// Whether there are no rows (the default).
    pub fn is_off(&self) -> bool {
        self.sides == RowSides::None
    }
}

impl Default for TrafficConfig {
    fn default() -> Self {
        TrafficConfig {
            parked_cars: 8,
            moving_cars: 5,
            pedestrians: 8,
            parked_vans: 0,
            moving_vans: 0,
            trucks: 0,
            cyclists: 0,
            car_size: [4.5, 1.8, 1.5],
            // KITTI's mean labelled sizes (van 5.1 × 1.9 × 2.2 m, truck 10.1 × 2.6 × 3.3 m,
            // cyclist 1.8 × 0.6 × 1.7 m), the truck a little shorter for a city street.
            van_size: [5.1, 1.9, 2.2],
            truck_size: [8.5, 2.5, 3.3],
            cyclist_size: [1.8, 0.6, 1.7],
            car_speed: [5.0, 12.0],
            cyclist_speed: [3.0, 7.0],
            pedestrian_radius: 0.3,
            pedestrian_height: 1.75,
            pedestrian_speed: [1.2, 1.4],
            pedestrian_rows: [1.0, 2.0],
            corner_clearance: 20.0,
            spawn_radius: 60.0,
            parked_rows: ParkedRows::default(),
        }
    }
}

/// Where and when the drive is recorded.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Recording {
    /// Latitude of the start, degrees (also the Mercator reference).
    pub latitude: f64,
    /// Longitude of the start, degrees.
    pub longitude: f64,
    /// Ground altitude, metres.
    pub altitude: f64,
    /// Date folder name, `YYYY_MM_DD`.
    pub date: String,
    /// Time of frame 0, `hh:mm:ss[.fraction]`.
    pub start_time: String,
    /// Drive number (`DATE_drive_NNNN_sync`).
    pub drive_number: u32,
}

impl Default for Recording {
    fn default() -> Self {
        Recording {
            latitude: 49.0,
            longitude: 8.43,
            altitude: 115.0,
            date: "2020_01_01".to_string(),
            start_time: "12:00:00.000000000".to_string(),
            drive_number: 1,
        }
    }
}

/// A whole simulated street drive as data (TOML/JSON); every field has a default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StreetConfig {
    /// Ego speed, m/s.
    pub speed: f64,
    /// Time between frames, seconds.
    pub frame_period: f64,
    /// Initial heading, degrees counter-clockwise from east.
    pub start_heading_deg: f64,
    /// The route: straight stretches and turns; straight on after the last.
    pub route: Vec<LegSpec>,
    /// Street geometry.
    pub street: StreetLayout,
    /// The ground's relief.
    pub ground: GroundConfig,
    /// The vehicle body's roll, pitch and heave.
    pub body: BodyMotionConfig,
    /// Road users.
    pub traffic: TrafficConfig,
    /// Poles, tree trunks, hedges and low walls.
    pub clutter: ClutterConfig,
    /// The lidar.
    pub lidar: LidarConfig,
    /// Place and time.
    pub recording: Recording,
}

impl Default for StreetConfig {
    fn default() -> Self {
        StreetConfig {
            speed: 10.0,
            frame_period: 0.1,
            start_heading_deg: 30.0,
            route: vec![
                LegSpec {
                    straight: 25.0,
                    turn_deg: 45.0,
                    turn_seconds: 3.0,
                },
                LegSpec {
                    straight: 50.0,
                    turn_deg: -60.0,
                    turn_seconds: 4.0,
                },
                LegSpec {
                    straight: 60.0,
                    turn_deg: 30.0,
                    turn_seconds: 2.5,
                },
            ],
            street: StreetLayout::default(),
            ground: GroundConfig::default(),
            body: BodyMotionConfig::default(),
            traffic: TrafficConfig::default(),
            clutter: ClutterConfig::default(),
            lidar: LidarConfig::default(),
            recording: Recording::default(),
        }
    }
}

impl StreetConfig {
    /// A city street with a KITTI drive's mix of road users and clutter: per drive 12 parked
    /// cars and 3 parked vans, 6 moving cars, 2 vans and a truck, 3 cyclists and 10
    /// pedestrians, and along the sidewalks 14 poles, 10 tree trunks, 4 hedges and 3 low
    /// walls ([`ClutterConfig::urban`]). Its sidewalks are 4.5 m wide, with the walking rows
    /// 1.6 and 2.6 m from the building line, so that people pass hedges, low walls, poles and
    /// trunks with more than a clusterer's 0.5 m between them; everything else as the default
    /// street.
    pub fn urban() -> Self {
        StreetConfig {
            street: StreetLayout {
                sidewalk_width: 4.5,
                ..StreetLayout::default()
            },
            traffic: TrafficConfig {
                pedestrian_rows: [1.6, 2.6],
                parked_cars: 12,
                moving_cars: 6,
                pedestrians: 10,
                parked_vans: 3,
                moving_vans: 2,
                trucks: 1,
                cyclists: 3,
                ..TrafficConfig::default()
            },
            clutter: ClutterConfig::urban(),
            ..StreetConfig::default()
        }
    }

    /// The urban street ([`StreetConfig::urban`]) with its kerbs lined by parked cars and vans
    /// ([`ParkedRows`]): on both sides vehicle after vehicle with 0.5–2 m gaps, one in five a
    /// van, one gap in ten a 4–10 m opening, in place of the urban street's 12 cars and 3 vans
    /// parked one by one. Seen from the road, the vehicles farther along a row are largely
    /// hidden behind the nearer ones, as along a real street's parked rows.
    pub fn parked_rows() -> Self {
        let urban = StreetConfig::urban();
        StreetConfig {
            traffic: TrafficConfig {
                parked_cars: 0,
                parked_vans: 0,
                parked_rows: ParkedRows {
                    sides: RowSides::Both,
                    ..ParkedRows::default()
                },
                ..urban.traffic
            },
            ..urban
        }
    }

    /// Checks every field; errors name the field.
    pub fn validate(&self) -> Result<()> {
        ensure_positive("speed", self.speed)?;
        ensure_positive("frame_period", self.frame_period)?;
        crate::error::ensure_finite("start_heading_deg", &[self.start_heading_deg])?;
        for (i, leg) in self.route.iter().enumerate() {
            ensure_non_negative(&format!("route[{i}].straight"), leg.straight)?;
            ensure_positive(&format!("route[{i}].turn_seconds"), leg.turn_seconds)?;
            if !(leg.turn_deg.abs() >= 10.0 && leg.turn_deg.abs() <= 120.0) {
                return Err(Error::invalid(
                    format!("route[{i}].turn_deg"),
                    format!("{} (turns must be 10° to 120° either way)", leg.turn_deg),
                ));
            }
        }
        let s = &self.street;
        ensure_positive("street.road_half_width", s.road_half_width)?;
        ensure_positive("street.sidewalk_width", s.sidewalk_width)?;
        ensure_positive("street.lane_width", s.lane_width)?;
        if s.ego_lane_offset.is_nan() || s.ego_lane_offset.abs() >= s.road_half_width {
            return Err(Error::invalid(
                "street.ego_lane_offset",
                format!("{} is not inside the road", s.ego_lane_offset),
            ));
        }
        ensure_range("street.wall_length", s.wall_length)?;
        ensure_positive("street.wall_length", s.wall_length[0])?;
        ensure_range("street.wall_gap", s.wall_gap)?;
        ensure_range("street.wall_height", s.wall_height)?;
        ensure_positive("street.wall_height", s.wall_height[0])?;
        ensure_non_negative("street.min_wall_piece", s.min_wall_piece)?;
        ensure_non_negative("street.behind_start", s.behind_start)?;
        ensure_positive("street.beyond_end", s.beyond_end)?;
        self.ground.validate()?;
        self.body.validate()?;
        let t = &self.traffic;
        for (name, size) in [
            ("car_size", t.car_size),
            ("van_size", t.van_size),
            ("truck_size", t.truck_size),
            ("cyclist_size", t.cyclist_size),
        ] {
            for (i, v) in size.iter().enumerate() {
                ensure_positive(&format!("traffic.{name}[{i}]"), *v)?;
            }
        }
        ensure_range("traffic.car_speed", t.car_speed)?;
        ensure_range("traffic.cyclist_speed", t.cyclist_speed)?;
        ensure_positive("traffic.pedestrian_radius", t.pedestrian_radius)?;
        ensure_positive("traffic.pedestrian_height", t.pedestrian_height)?;
        ensure_range("traffic.pedestrian_speed", t.pedestrian_speed)?;
        for (i, d) in t.pedestrian_rows.iter().enumerate() {
            let r = t.pedestrian_radius;
            if !(*d >= r && *d <= s.sidewalk_width - r) {
                return Err(Error::invalid(
                    format!("traffic.pedestrian_rows[{i}]"),
                    format!(
                        "{d} m from the building line is not on the {} m sidewalk",
                        s.sidewalk_width
                    ),
                ));
            }
        }
        ensure_non_negative("traffic.corner_clearance", t.corner_clearance)?;
        ensure_positive("traffic.spawn_radius", t.spawn_radius)?;
        let rows = &t.parked_rows;
        ensure_range("traffic.parked_rows.gap", rows.gap)?;
        ensure_positive("traffic.parked_rows.gap", rows.gap[0])?;
        ensure_range("traffic.parked_rows.opening", rows.opening)?;
        ensure_probability("traffic.parked_rows.van_share", rows.van_share)?;
        ensure_probability("traffic.parked_rows.opening_share", rows.opening_share)?;
        self.clutter.validate()?;
        // Clutter keeps out of the pedestrians' rows (0.5 m clear of a walker's shoulder).
        let c = &self.clutter;
        let walker = |d: f64| s.sidewalk_width - d;
        let nearest_walk = t
            .pedestrian_rows
            .iter()
            .map(|&d| walker(d) - t.pedestrian_radius)
            .fold(f64::INFINITY, f64::min);
        let furthest_walk = t
            .pedestrian_rows
            .iter()
            .map(|&d| d - t.pedestrian_radius)
            .fold(f64::INFINITY, f64::min);
        if c.poles + c.trunks > 0 {
            let edge = c.kerb_setback + c.pole_radius[1].max(c.trunk_radius[1]);
            if edge + 0.5 > nearest_walk {
                return Err(Error::invalid(
                    "clutter.poles / clutter.trunks",
                    format!(
                        "reach {edge:.2} m onto the sidewalk, within 0.5 m of the walkers \
                         {nearest_walk:.2} m from the kerb (widen street.sidewalk_width or move \
                         traffic.pedestrian_rows)"
                    ),
                ));
            }
        }
        if c.hedges + c.low_walls > 0 {
            let depth = 0.05 + c.hedge_width[1].max(c.low_wall_width[1]);
            if depth + 0.5 > furthest_walk {
                return Err(Error::invalid(
                    "clutter.hedges / clutter.low_walls",
                    format!(
                        "reach {depth:.2} m from the building line, within 0.5 m of the walkers \
                         {furthest_walk:.2} m from it (widen street.sidewalk_width or move \
                         traffic.pedestrian_rows)"
                    ),
                ));
            }
        }
        let l = &self.lidar;
        if l.beams < 2 || !l.beams.is_multiple_of(2) || l.beams > 256 {
            return Err(Error::invalid(
                "lidar.beams",
                format!("{} (must be even, 2 to 256)", l.beams),
            ));
        }
        if !(l.elevation_top_deg < 90.0
            && l.elevation_top_deg > l.elevation_split_deg
            && l.elevation_split_deg > l.elevation_bottom_deg
            && l.elevation_bottom_deg > -90.0)
        {
            return Err(Error::invalid(
                "lidar elevations",
                "need 90 > top > split > bottom > -90 degrees",
            ));
        }
        if l.columns == 0 || l.columns > 100_000 {
            return Err(Error::invalid(
                "lidar.columns",
                format!("{} (must be 1 to 100000)", l.columns),
            ));
        }
        ensure_positive("lidar.max_range", l.max_range)?;
        ensure_non_negative("lidar.min_range", l.min_range)?;
        ensure_non_negative("lidar.range_noise", l.range_noise)?;
        ensure_positive("lidar.mount_height", l.mount_height)?;
        if !(0.0..1.0).contains(&l.dropout) {
            return Err(Error::invalid(
                "lidar.dropout",
                format!("{} (must be in [0, 1))", l.dropout),
            ));
        }
        let r = &self.recording;
        if !(r.latitude.abs() < 80.0 && r.longitude.abs() <= 180.0 && r.altitude.is_finite()) {
            return Err(Error::invalid(
                "recording latitude/longitude/altitude",
                format!("{} / {} / {}", r.latitude, r.longitude, r.altitude),
            ));
        }
        self.start_stamp()?;
        Ok(())
    }

    /// The time stamp of frame 0 from `recording.date` and `recording.start_time`.
    pub fn start_stamp(&self) -> Result<Timestamp> {
        let r = &self.recording;
        let ok = r.date.len() == 10 && r.date.bytes().all(|b| b.is_ascii_digit() || b == b'_');
        let text = format!("{} {}", r.date.replace('_', "-"), r.start_time);
        match Timestamp::parse(&text) {
            Ok(t) if ok => Ok(t),
            Ok(_) => Err(Error::invalid(
                "recording.date",
                format!("`{}` is not YYYY_MM_DD", r.date),
            )),
            Err(e) => Err(Error::invalid("recording date/start_time", e)),
        }
    }

    /// Drive folder name, `DATE_drive_NNNN_sync`.
    pub fn drive_name(&self) -> String {
        format!(
            "{}_drive_{:04}_sync",
            self.recording.date, self.recording.drive_number
        )
    }
}
