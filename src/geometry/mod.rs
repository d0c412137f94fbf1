//! Geometric primitives shared by sensors, detectors, models and metrics: angles, planar poses
//! and rigid motions, rays, infinite planes in Hessian normal form and bounded rectangular
//! plane patches.
//!
//! * [`angle`]: [`wrap_angle`], the one wrap to (−π, π].
//! * [`box3`]: [`Box3`], oriented boxes upright about z; [`iou_bev`], [`iou_3d`].
//! * [`pose2`]: [`Pose2`] and planar rigid motions, [`platform_isometry`] (a planar pose as the
//!   SE(3) pose a filter step holds).
//! * [`ray`]: [`ray_circle`], where a ray first meets a circle.
//! * [`plane`]: [`Plane`], [`PlanePatch`].
//!
//! Not for: finding planes in point clouds (see [`crate::cloud::planes`]), moving planes
//! with a vehicle model (see [`crate::models::plane`]), or turning KITTI's OXTS readings into
//! poses (see [`crate::kitti::poses`]).

pub mod angle;
pub mod box3;
pub mod plane;
pub mod pose2;
pub mod ray;

pub use angle::wrap_angle;
pub use box3::{bev_intersection_area, iou_3d, iou_bev, Box3};
pub use plane::{Plane, PlanePatch};
pub use pose2::{platform_isometry, Pose2};
pub use ray::ray_circle;
