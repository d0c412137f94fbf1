//! From OXTS packets to vehicle poses, following the KITTI raw-data devkit's conventions.
//!
//! **Position.** Latitude/longitude are projected with a Mercator projection whose scale is
//! fixed by the *first* packet, s = cos(lat₀·π/180), so that one unit is about one metre near
//! the start of the drive:
//! x = s·R·lon·π/180 (east), y = s·R·ln tan((90 + lat)·π/360) (north), z = altitude,
//! with R = 6 378 137 m. [`Mercator::unproject`] inverts it (used to write synthetic packets).
//!
//! **Orientation.** R = Rz(yaw)·Ry(pitch)·Rx(roll): the IMU axes (x forward, y left, z up)
//! expressed in the east-north-up projection frame.
//!
//! **Relative poses.** Like the devkit, [`imu_poses`] returns T_k = T_0⁻¹·W_k where W_k is the
//! world (projection-frame) pose of packet k, so the first pose is the identity and every pose
//! maps IMU coordinates of frame k to IMU coordinates of frame 0.
//!
//! **Velodyne poses.** `calib_imu_to_velo.txt` holds T_velo_imu, which maps IMU coordinates to
//! Velodyne coordinates: p_velo = T_velo_imu·p_imu. The Velodyne's pose in a world frame is
//! therefore W_velo = W_imu·T_velo_imu⁻¹ ([`velodyne_pose_from_imu`]), and the Velodyne poses
//! relative to the first Velodyne frame are T_velo_imu·T_k·T_velo_imu⁻¹ ([`velodyne_poses`]).
//!
//! **Planar vehicle state** for the extended constant-turn model, see [`VehicleState`].
//!
//! Not for: reading files (see [`super::oxts`], [`super::calib`]).

use super::oxts::OxtsPacket;
use crate::error::{Error, Result};
use crate::geometry::wrap_angle;
pub use crate::models::vehicle::VehicleState;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use std::f64::consts::PI;

/// Earth radius used by the KITTI devkit's Mercator projection, metres.
pub const EARTH_RADIUS: f64 = 6_378_137.0;

/// The devkit's Mercator projection with a fixed scale.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Mercator {
    scale: f64,
}

impl Mercator {
    /// The projection whose scale is cos(lat₀) for the reference latitude `lat0_deg` (degrees;
    /// KITTI uses the first packet of a drive).
    pub fn from_reference_latitude(lat0_deg: f64) -> Result<Mercator> {
        if !lat0_deg.is_finite() || lat0_deg.abs() >= 90.0 {
            return Err(Error::invalid(
                "reference latitude",
                format!("{lat0_deg} deg is outside (-90, 90)"),
            ));
        }
        Ok(Mercator {
            scale: (lat0_deg * PI / 180.0).cos(),
        })
    }

    /// The scale s = cos(lat₀).
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// (x, y) in metres (east, north) of a latitude/longitude in degrees.
    pub fn project(&self, lat_deg: f64, lon_deg: f64) -> (f64, f64) {
        let k = self.scale * EARTH_RADIUS;
        let x = k * lon_deg * PI / 180.0;
        let y = k * ((90.0 + lat_deg) * PI / 360.0).tan().ln();
        (x, y)
    }

    /// Latitude and longitude in degrees of a projected (x, y); inverse of
    /// [`project`](Self::project).
    pub fn unproject(&self, x: f64, y: f64) -> (f64, f64) {
        let k = self.scale * EARTH_RADIUS;
        let lon = x / k * 180.0 / PI;
        let lat = 360.0 / PI * (y / k).exp().atan() - 90.0;
        (lat, lon)
    }
}

/// Orientation of the IMU from OXTS angles: Rz(yaw)·Ry(pitch)·Rx(roll).
pub fn oxts_rotation(roll: f64, pitch: f64, yaw: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw)
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), pitch)
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), roll)
}

fn check_latitude(k: usize, p: &OxtsPacket) -> Result<()> {
    if !(p.lat.is_finite() && p.lat.abs() < 90.0 && p.lon.is_finite() && p.alt.is_finite()) {
        return Err(Error::invalid(
            format!("OXTS packet {k}"),
            format!(
                "lat {} / lon {} / alt {} cannot be projected",
                p.lat, p.lon, p.alt
            ),
        ));
    }
    Ok(())
}

/// World poses W_k of the IMU in the Mercator frame (east, north, up) whose scale comes from
/// the first packet. Empty input gives an empty list.
pub fn oxts_world_poses(packets: &[OxtsPacket]) -> Result<Vec<Isometry3<f64>>> {
    let Some(first) = packets.first() else {
        return Ok(Vec::new());
    };
    check_latitude(0, first)?;
    let merc = Mercator::from_reference_latitude(first.lat)?;
    packets
        .iter()
        .enumerate()
        .map(|(k, p)| {
            check_latitude(k, p)?;
            let (x, y) = merc.project(p.lat, p.lon);
            Ok(Isometry3::from_parts(
                Translation3::new(x, y, p.alt),
                oxts_rotation(p.roll, p.pitch, p.yaw),
            ))
        })
        .collect()
}

/// IMU poses relative to the first packet, T_k = W_0⁻¹·W_k (the first is the identity).
pub fn imu_poses(packets: &[OxtsPacket]) -> Result<Vec<Isometry3<f64>>> {
    let world = oxts_world_poses(packets)?;
    Ok(relative_to_first(&world))
}

/// Re-expresses poses relative to the first one: P_0⁻¹·P_k.
pub fn relative_to_first(poses: &[Isometry3<f64>]) -> Vec<Isometry3<f64>> {
    match poses.first() {
        None => Vec::new(),
        Some(first) => {
            let inv = first.inverse();
            poses.iter().map(|p| inv * p).collect()
        }
    }
}

/// The Velodyne's pose from the IMU's: W_velo = W_imu·T_velo_imu⁻¹, where `t_velo_imu` maps
/// IMU coordinates to Velodyne coordinates (the content of `calib_imu_to_velo.txt`).
pub fn velodyne_pose_from_imu(
    world_imu: &Isometry3<f64>,
    t_velo_imu: &Isometry3<f64>,
) -> Isometry3<f64> {
    world_imu * t_velo_imu.inverse()
}

/// Velodyne poses relative to the first Velodyne frame, from IMU poses in any common frame:
/// V_k = T_velo_imu·P_0⁻¹·P_k·T_velo_imu⁻¹. The first is the identity; V_k maps Velodyne
/// coordinates of frame k to Velodyne coordinates of frame 0.
pub fn velodyne_poses(
    imu_poses: &[Isometry3<f64>],
    t_velo_imu: &Isometry3<f64>,
) -> Vec<Isometry3<f64>> {
    let world_velo: Vec<_> = imu_poses
        .iter()
        .map(|p| velodyne_pose_from_imu(p, t_velo_imu))
        .collect();
    relative_to_first(&world_velo)
}

/// Planar vehicle states, one per packet (see [`VehicleState`] for the frame and the choices).
pub fn vehicle_states(packets: &[OxtsPacket]) -> Result<Vec<VehicleState>> {
    let Some(first) = packets.first() else {
        return Ok(Vec::new());
    };
    check_latitude(0, first)?;
    let merc = Mercator::from_reference_latitude(first.lat)?;
    let (x0, y0) = merc.project(first.lat, first.lon);
    let (s, c) = (-first.yaw).sin_cos();
    let rot = |ex: f64, ny: f64| (c * ex - s * ny, s * ex + c * ny);
    let mut heading = 0.0;
    let mut prev_yaw = first.yaw;
    let mut out = Vec::with_capacity(packets.len());
    for (k, p) in packets.iter().enumerate() {
        check_latitude(k, p)?;
        if k > 0 {
            heading += wrap_angle(p.yaw - prev_yaw);
            prev_yaw = p.yaw;
        }
        let (px, py) = merc.project(p.lat, p.lon);
        let (x, y) = rot(px - x0, py - y0);
        let (vx, vy) = rot(p.ve, p.vn);
        out.push(VehicleState {
            x,
            vx,
            y,
            vy,
            heading,
            yaw_rate: p.wu,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    fn packet(lat: f64, lon: f64, yaw: f64) -> OxtsPacket {
        OxtsPacket {
            lat,
            lon,
            alt: 100.0,
            yaw,
            ..Default::default()
        }
    }

    #[test]
    fn mercator_round_trip() {
        let m = Mercator::from_reference_latitude(49.015).unwrap();
        for (lat, lon) in [
            (49.015003823272, 8.4342971002335),
            (48.9, 8.5),
            (-33.0, 151.2),
        ] {
            let (x, y) = m.project(lat, lon);
            let (la, lo) = m.unproject(x, y);
            assert!((la - lat).abs() < 1e-9 && (lo - lon).abs() < 1e-9);
        }
        assert!(Mercator::from_reference_latitude(90.0).is_err());
    }

    #[test]
    fn mercator_units_are_metres_near_the_reference() {
        let m = Mercator::from_reference_latitude(49.0).unwrap();
        // One arc-second of latitude is ~30.9 m on the meridian; compare a small step.
        let (_, y0) = m.project(49.0, 8.0);
        let (_, y1) = m.project(49.0 + 1e-4, 8.0);
        let expected = EARTH_RADIUS * 1e-4 * PI / 180.0;
        assert!(((y1 - y0) - expected).abs() / expected < 1e-3);
    }

    #[test]
    fn rotation_order_is_z_y_x() {
        let q = oxts_rotation(0.1, 0.2, 0.3);
        let expected = UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3);
        assert!(q.angle_to(&expected) < 1e-12);
        // Pure yaw of 90°: the IMU's forward axis points north.
        let f = oxts_rotation(0.0, 0.0, PI / 2.0) * Vector3::x();
        assert!((f - Vector3::y()).norm() < 1e-12);
    }

    #[test]
    fn relative_poses_start_at_identity() {
        let m = Mercator::from_reference_latitude(49.0).unwrap();
        let (x0, y0) = m.project(49.0, 8.0);
        let (lat1, lon1) = m.unproject(x0, y0 + 10.0); // 10 m north
        let poses =
            imu_poses(&[packet(49.0, 8.0, PI / 2.0), packet(lat1, lon1, PI / 2.0)]).unwrap();
        assert!(poses[0].translation.vector.norm() < 1e-12);
        assert!(poses[0].rotation.angle() < 1e-12);
        // Heading north, 10 m north is 10 m forward in the first IMU frame.
        let t = poses[1].translation.vector;
        assert!((t - Vector3::new(10.0, 0.0, 0.0)).norm() < 1e-6, "{t}");
        assert!(imu_poses(&[]).unwrap().is_empty());
        assert!(imu_poses(&[packet(90.0, 0.0, 0.0)]).is_err());
    }

    #[test]
    fn velodyne_pose_direction() {
        // Velodyne 1 m above and 0.5 m ahead of the IMU: an IMU point (0.5, 0, 1) is the
        // Velodyne origin, so p_velo = p_imu − (0.5, 0, 1).
        let t_velo_imu = Isometry3::translation(-0.5, 0.0, -1.0);
        let world_imu = Isometry3::from_parts(
            Translation3::new(10.0, 20.0, 0.0),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), PI / 2.0),
        );
        let w = velodyne_pose_from_imu(&world_imu, &t_velo_imu);
        let origin = w * Point3::origin();
        // Heading north: 0.5 m ahead is +y in the world.
        assert!((origin.coords - Vector3::new(10.0, 20.5, 1.0)).norm() < 1e-12);
        // A vehicle moving 2 m forward moves the Velodyne 2 m forward in its own frame too.
        let imu = vec![Isometry3::identity(), Isometry3::translation(2.0, 0.0, 0.0)];
        let v = velodyne_poses(&imu, &t_velo_imu);
        assert!((v[1].translation.vector - Vector3::new(2.0, 0.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn vehicle_state_frame_and_unwrapped_heading() {
        let m = Mercator::from_reference_latitude(49.0).unwrap();
        let (x0, y0) = m.project(49.0, 8.0);
        let (lat1, lon1) = m.unproject(x0 - 3.0, y0); // 3 m west
        let mut a = packet(49.0, 8.0, 3.1);
        a.ve = -5.0;
        let mut b = packet(lat1, lon1, -3.1); // crossed ±π turning left
        b.wu = 0.2;
        let s = vehicle_states(&[a, b]).unwrap();
        assert_eq!(s[0].x, 0.0);
        // Heading ≈ west; 3 m west is ≈ 3 m forward.
        assert!(
            (s[1].x - 3.0 * 3.1f64.cos().abs()).abs() < 1e-6,
            "{:?}",
            s[1]
        );
        assert!((s[0].vx - 5.0 * 3.1f64.cos().abs()).abs() < 1e-9);
        assert!((s[1].heading - (2.0 * PI - 6.2)).abs() < 1e-12);
        assert_eq!(s[1].yaw_rate, 0.2);
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
    }
}
