//! Geometric primitives shared by sensors, detectors, models and metrics: angles, planar poses
//! and rigid motions, rays, infinite planes in Hessian normal form and bounded rectangular
//! plane patches.
//!
//! * [`angle`]: [`wrap_angle`], the one wrap to (−π, π].
//! * [`box3`]: [`Box3`], oriented boxes upright about z; [`iou_bev`], [`iou_3d`].
//! * [`pose2`]: [`Pose2`] and planar rigid motions, [`platform_isometry`] (a planar pose as the
//!   SE(3) pose a filter step holds).
//! * [`ray`]: [`ray_circle`], where a ray first meets a circle.
//! * [`plane`]: [`Plane`], [`PlanePatch`], the one canonical sign of a plane
//!   ([`plane::canonical`]).
//! * [`frame_change`]: [`FrameChange`], how the sensor's frame changes between two steps and
//!   the one function that carries planes and points into the new frame.
//!
//! Not for: finding planes in point clouds (see [`crate::cloud::planes`]), drawing the ego
//! motion from a vehicle model (see [`crate::models::vehicle`]), or turning KITTI's OXTS readings into
//! poses (see [`crate::kitti::poses`]).

pub mod angle;
pub mod box3;
pub mod frame_change;
pub mod plane;
pub mod pose2;
pub mod ray;

pub use angle::wrap_angle;
pub use box3::{bev_intersection_area, iou_3d, iou_bev, Box3};
pub use frame_change::FrameChange;
pub use plane::{Plane, PlanePatch};
pub use pose2::{platform_isometry, Pose2};
pub use ray::ray_circle;
