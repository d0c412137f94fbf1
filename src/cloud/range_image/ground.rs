//! Ground segmentation on a [`RangeImage`], column by column (after Himmelsbach et al. 2010
//! and Bogoslavskyi & Stachniss 2016): in one azimuth bin the road is a chain of points whose
//! consecutive slope stays gentle, so each column is walked from the lowest ring outwards.
//!
//! # Method
//! In a column, from the bottom row up, with ρ the horizontal range and z the height of the
//! cell's point (sensor frame):
//! * the chain starts at the first point within `start_tolerance` of the nominal road height
//!   `z = −sensor_height`;
//! * a later point is ground when it lies farther out than the last ground point and the
//!   slope between them, `|Δz| ≤ tan(max_slope)·Δρ + step_tolerance`, stays gentle; it then
//!   becomes the last ground point. Points that fail (a car's side, a wall, a pole) are not
//!   ground and do not break the chain: the road seen beyond them continues it.
//!
//! Every column costs its rows, so the whole is linear in the points. A point that shares its
//! cell with the nearer holder is ground when the holder is and their heights differ by at
//! most `step_tolerance`.
//!
//! Unlike a RANSAC plane (one plane, [`crate::cloud::planes`]) the chain follows a road that
//! bends up or down and kerbs a few centimetres high; it does not need the whole road to be
//! one plane, and it needs no random draws.
//!
//! Not for: the walls, or points seen from anywhere but the scanner's own origin.

use super::{RangeImage, NONE};
use crate::cloud::PointCloud;
use crate::error::{Error, Result};

/// Parameters of [`ground_mask`].
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GroundParams {
    /// Height of the sensor over the road (m). Default 1.73 (KITTI's Velodyne).
    pub sensor_height: f64,
    /// How far from `−sensor_height` a column's first ground point may be (m). Default 0.4:
    /// the car's pitch on a road and a gentle grade at the lowest ring's 4–6 m.
    pub start_tolerance: f64,
    /// Steepest slope between consecutive ground points (rad). Default 10° (a 17 % grade is
    /// still road; a car's side or a wall is far steeper).
    pub max_slope: f64,
    /// Height step allowed on top of the slope (m): range noise and kerbs. Default 0.1.
    pub step_tolerance: f64,
}

impl Default for GroundParams {
    fn default() -> Self {
        GroundParams {
            sensor_height: 1.73,
            start_tolerance: 0.4,
            max_slope: 10f64.to_radians(),
            step_tolerance: 0.1,
        }
    }
}

impl GroundParams {
    fn validate(&self) -> Result<()> {
        let ok = self.sensor_height.is_finite()
            && self.start_tolerance.is_finite()
            && self.start_tolerance >= 0.0
            && self.max_slope.is_finite()
            && (0.0..std::f64::consts::FRAC_PI_2).contains(&self.max_slope)
            && self.step_tolerance.is_finite()
            && self.step_tolerance >= 0.0;
        if ok {
            Ok(())
        } else {
            Err(Error::invalid(
                "ground parameters",
                format!("{self:?} (finite, tolerances ≥ 0, slope in [0, 90°))"),
            ))
        }
    }
}

/// Per point of `cloud`: whether it is ground. `image` must have been built from `cloud`.
pub fn ground_mask(
    image: &RangeImage,
    cloud: &PointCloud,
    params: &GroundParams,
) -> Result<Vec<bool>> {
    params.validate()?;
    image.check_cloud(cloud)?;
    let (xs, ys, zs) = (cloud.xs(), cloud.ys(), cloud.zs());
    let (rows, cols) = (image.rows(), image.cols());
    let holders = image.holders();
    let slope = params.max_slope.tan() as f32;
    let step = params.step_tolerance as f32;
    let road = -params.sensor_height as f32;
    let start = params.start_tolerance as f32;
    let mut cell_ground = vec![false; rows * cols];
    for col in 0..cols {
        // Last ground point of this column: (ρ, z).
        let mut last: Option<(f32, f32)> = None;
        for row in (0..rows).rev() {
            let cell = row * cols + col;
            let p = holders[cell];
            if p == NONE {
                continue;
            }
            let p = p as usize;
            let (rho, z) = ((xs[p] * xs[p] + ys[p] * ys[p]).sqrt(), zs[p]);
            let ground = match last {
                None => (z - road).abs() <= start,
                Some((r0, z0)) => rho > r0 && (z - z0).abs() <= slope * (rho - r0) + step,
            };
            if ground {
                cell_ground[cell] = true;
                last = Some((rho, z));
            }
        }
    }
    let mut mask = vec![false; cloud.len()];
    for (i, &cell) in image.cells_of_points().iter().enumerate() {
        if cell == NONE || !cell_ground[cell as usize] {
            continue;
        }
        let h = holders[cell as usize] as usize;
        mask[i] = h == i || (zs[i] - zs[h]).abs() <= step;
    }
    Ok(mask)
}
