//! Point trackers that consume the same range-bearing measurements as the LMB filter, for
//! comparison: the baselines of the seeds (GNN with EKFs, ML-RANSAC of seed 000's Algorithm 2,
//! JPDA with an IMM of seed 003, Sec. V) and an adapter that puts the particle LMB filter
//! behind the same interface.
//!
//! Every tracker is fed, step by step, the measurements of one scan (range and bearing of
//! people's centres in the sensor frame, bearing counter-clockwise from the sensor's x axis) and
//! a [`StepContext`] holding the time, the time since the previous step and the robot's odometry
//! pose; the sensor's mounting offset on the robot is part of each tracker's [`RangeBearing`](crate::models::RangeBearing)
//! model. Every tracker returns labelled [`Estimate`]s with the state `[x, ẋ, y, ẏ, …]` in the
//! world frame, and may report the innovations of its last update
//! ([`PointTracker::innovations`]) for the RMS prediction error and NIS checks.
//!
//! * [`ekf`]: the extended Kalman filter pieces (CV prediction, range-bearing update, Joseph form).
//! * [`gnn`]: global nearest neighbour with EKFs and M-of-N track confirmation.
//! * [`ml_ransac`]: multilevel RANSAC association (seed 000, Algorithm 2).
//! * [`imm`]: interacting multiple models (CV and coordinated turn) on one track.
//! * [`jpda_imm`]: joint probabilistic data association over IMM tracks.
//! * [`LmbTracker`]: the LMB filter behind [`PointTracker`].
//! * [`ab3dmot`]: AB3DMOT, Kalman-filtered oriented 3-D boxes (fed boxes, not a [`PointTracker`]).
//!
//! Not for: segmentation (see [`crate::pipeline::people_tracking::person_measurements`]) or scoring (see
//! [`crate::pipeline::people_tracking::evaluate`]).

pub mod ab3dmot;
pub mod ekf;
pub mod gnn;
pub mod imm;
pub mod jpda_imm;
pub mod lifecycle;
pub mod ml_ransac;

use crate::error::Result;
use crate::filter::StepContext;
use crate::filter::{Estimate, Frame, Label, LmbFilter, Measurements};
use crate::geometry::platform_isometry;
use crate::geometry::Pose2;
use crate::rng::FilterRng;
use nalgebra::Isometry3;

pub use ekf::Gaussian;
pub use gnn::{GnnConfig, GnnTracker};
pub use jpda_imm::{JpdaImmConfig, JpdaImmTracker};
pub use ml_ransac::{MlRansacConfig, MlRansacTracker};

/// What a tracker learned from one measurement update of one track: the innovation of the
/// (combined) measurement and its covariance, for the RMS prediction error and NIS.
#[derive(Clone, Debug, PartialEq)]
pub struct Innovation {
    /// The track.
    pub label: Label,
    /// Measured minus predicted position in the world frame (m): the measurement converted to
    /// a point minus the predicted track position.
    pub position_error: [f64; 2],
    /// Normalised innovation squared νᵀ S⁻¹ ν of the range-bearing innovation (two degrees of
    /// freedom for a consistent filter).
    pub nis: f64,
}

/// The beams of one planar scan as a tracker sees them, whatever sensor or file they came
/// from: beam `i` points at bearing `angle_min + i·angle_increment` (radians, sensor frame,
/// counter-clockwise from x) and ended at `ranges[i]` metres, `+∞` where nothing returned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeamRanges<'a> {
    /// Bearing of the first beam (rad).
    pub angle_min: f64,
    /// Bearing step between consecutive beams (rad).
    pub angle_increment: f64,
    /// Range of every beam (m), `+∞` for no return.
    pub ranges: &'a [f64],
}

/// A multi-object tracker fed one scan's measurements at a time.
pub trait PointTracker {
    /// A short name (`lmb`, `gnn`, `ml_ransac`, `jpda_imm`).
    fn name(&self) -> &str;

    /// One step: `z` holds range-bearing rows (sensor frame), `ctx` the time, the time step
    /// and the platform pose. Returns the confirmed tracks.
    fn step(&mut self, z: &Measurements, ctx: &StepContext) -> Result<Vec<Estimate>>;

    /// Sees the beams of the scan the next step's measurements come from, before
    /// [`PointTracker::step`] (trackers whose detection model looks at the scan, e.g. for
    /// occlusions, keep what they need; the default ignores it).
    fn observe_beams(&mut self, beams: BeamRanges<'_>) {
        let _ = beams;
    }

    /// Innovations of the tracks updated in the last step (empty when the tracker does not
    /// keep Gaussian track densities).
    fn innovations(&self) -> &[Innovation] {
        &[]
    }
}

/// Builds the step contexts of a sequence of scans: step index, time, time since the
/// previous step (0 for the first) and platform pose.
#[derive(Clone, Debug, Default)]
pub struct StepClock {
    step: u32,
    last: Option<(f64, Option<Isometry3<f64>>)>,
}

impl StepClock {
    /// A clock before its first step.
    pub fn new() -> Self {
        StepClock::default()
    }

    /// The context of the next step at `time` with the platform at `pose`. Time must not run
    /// backwards.
    pub fn tick(&mut self, time: f64, pose: Option<Pose2>) -> Result<StepContext> {
        crate::error::ensure_finite("step time", &[time])?;
        let platform = pose.map(platform_isometry);
        let (dt, previous_platform) = match self.last {
            None => (0.0, None),
            Some((t, p)) => {
                if time < t {
                    return Err(crate::Error::invalid(
                        "step time",
                        format!("{time} s is before the previous step at {t} s"),
                    ));
                }
                (time - t, p)
            }
        };
        let step = self.step;
        self.step += 1;
        self.last = Some((time, platform));
        Ok(StepContext {
            step,
            time,
            dt,
            platform,
            previous_platform,
            data: crate::filter::StepData::new(),
        })
    }
}

/// The particle LMB filter behind [`PointTracker`].
#[derive(Debug)]
pub struct LmbTracker {
    filter: LmbFilter,
    rng: FilterRng,
}

impl LmbTracker {
    /// Wraps `filter`, drawing from `rng`.
    pub fn new(filter: LmbFilter, rng: FilterRng) -> Self {
        LmbTracker { filter, rng }
    }

    /// The wrapped filter.
    pub fn filter(&self) -> &LmbFilter {
        &self.filter
    }
}

impl PointTracker for LmbTracker {
    fn name(&self) -> &str {
        "lmb"
    }

    fn step(&mut self, z: &Measurements, ctx: &StepContext) -> Result<Vec<Estimate>> {
        let mut frame = Frame::new(ctx.time, z.clone()).with_data(ctx.data.clone());
        frame.platform = ctx.platform;
        self.filter.step(&frame, &mut self.rng)
    }
}

/// Checks that a measurement set holds range-bearing rows.
pub(crate) fn ensure_range_bearing(z: &Measurements) -> Result<()> {
    if z.dim() != 2 && !z.is_empty() {
        return Err(crate::Error::invalid(
            "tracker measurements",
            format!("rows of {} values (expected range and bearing)", z.dim()),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_clock_counts_steps_and_time() {
        let mut clock = StepClock::new();
        let a = clock.tick(10.0, None).unwrap();
        assert_eq!((a.step, a.dt), (0, 0.0));
        let b = clock.tick(10.125, Some(Pose2::new(1.0, 2.0, 0.5))).unwrap();
        assert_eq!(b.step, 1);
        assert!((b.dt - 0.125).abs() < 1e-12);
        let (x, y, phi) = b.platform_xy_heading();
        assert!((x - 1.0).abs() < 1e-12 && (y - 2.0).abs() < 1e-12 && (phi - 0.5).abs() < 1e-12);
        assert!(clock.tick(10.0, None).is_err());
        assert!(clock.tick(f64::NAN, None).is_err());
    }
}
