//! The settings of the mounting estimation: the coarse search's and the whole estimation's,
//! with their checks.
//!
//! Not for: the estimation itself (the parent module).

use super::*;
/// The coarse (global) search of [`coarse_align`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoarseConfig {
    /// Heading grid step over the full turn (rad). Default 2°.
    pub heading_step: f64,
    /// Translations are searched in `[−range, range]²` (m). Default 1.5 m.
    pub translation_range: f64,
    /// Translation grid step (m). Default 0.05 m.
    pub translation_step: f64,
    /// A sensor point scores when it lands within this of a reference point (m). Default 0.1 m.
    pub hit_radius: f64,
    /// The sensor scan is thinned to at most this many points for the search. Default 200.
    pub max_points: usize,
    /// Candidates refined by ICP per pair. Default 5.
    pub candidates: usize,
    /// Two pairs' results agree when their positions are at most this far apart (m). Default 0.1 m.
    pub agree_distance: f64,
    /// ... and their headings at most this far apart (rad). Default 3°.
    pub agree_heading: f64,
}

impl Default for CoarseConfig {
    fn default() -> Self {
        CoarseConfig {
            heading_step: 2f64.to_radians(),
            translation_range: 1.5,
            translation_step: 0.05,
            hit_radius: 0.1,
            max_points: 200,
            candidates: 5,
            agree_distance: 0.1,
            agree_heading: 3f64.to_radians(),
        }
    }
}

/// Parameters of [`estimate_mounting`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MountingConfig {
    /// Returns farther than this are not used (m); far returns are sparse and noisy. Default 8 m.
    pub max_range: f64,
    /// Use every n'th sensor scan. Default 1 (all).
    pub pair_stride: usize,
    /// Interpolate the platform's motion between the bracketing reference scans (module
    /// documentation, step 2). Default true.
    pub motion_compensation: bool,
    /// Reference scans more than this many median reference periods apart do not bracket a
    /// sensor scan (a gap in the recording). Default 1.5.
    pub max_gap_periods: f64,
    /// Without motion compensation, the largest time offset between a sensor scan and its
    /// reference scan (s). Default 0.02 s.
    pub max_time_offset: f64,
    /// Pairs used by the coarse search, spread evenly over the recording. Default 9.
    pub coarse_pairs: usize,
    /// The coarse search.
    pub coarse: CoarseConfig,
    /// ICP of the fine registration (and of the reference laser's own motion).
    pub icp: IcpConfig,
    /// A fit farther than this from the coarse guess is rejected (m). Default 0.3 m.
    pub max_jump: f64,
    /// ... or turned farther than this (rad). Default 10°.
    pub max_heading_jump: f64,
    /// Least share of sensor points paired for a fit to count. Default 0.2.
    pub min_overlap: f64,
    /// Largest RMS of the point-to-line residuals for a fit to count (m). Default 0.05 m.
    pub max_rms: f64,
    /// Fewest kept fits for an estimate. Default 10.
    pub min_fits: usize,
    /// Time windows whose medians are reported. Default 4.
    pub windows: usize,
    /// Pairs of the point-to-line refinement that follows each ICP are at most this far apart
    /// (m). Default 0.15 m.
    pub line_gate: f64,
    /// Sensor points within this of a reference point, at the final pose, are the overlap
    /// whose distances are the residuals (m). Default 0.2 m.
    pub overlap_gate: f64,
}

impl Default for MountingConfig {
    fn default() -> Self {
        MountingConfig {
            max_range: 8.0,
            pair_stride: 1,
            motion_compensation: true,
            max_gap_periods: 1.5,
            max_time_offset: 0.02,
            coarse_pairs: 9,
            coarse: CoarseConfig::default(),
            icp: IcpConfig {
                max_pair_distance: 0.5,
                ..IcpConfig::default()
            },
            max_jump: 0.3,
            max_heading_jump: 10f64.to_radians(),
            min_overlap: 0.2,
            max_rms: 0.05,
            min_fits: 10,
            windows: 4,
            line_gate: 0.15,
            overlap_gate: 0.2,
        }
    }
}

fn positive(field: &'static str, v: f64) -> Result<(), MountingError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(MountingError::Config {
            field,
            reason: format!("{v} (must be finite and positive)"),
        })
    }
}

fn at_least(field: &'static str, v: usize, min: usize) -> Result<(), MountingError> {
    if v >= min {
        Ok(())
    } else {
        Err(MountingError::Config {
            field,
            reason: format!("{v} (need at least {min})"),
        })
    }
}

impl CoarseConfig {
    /// Checks that steps, ranges and radii are positive and finite and the counts non-zero.
    pub fn validate(&self) -> Result<(), MountingError> {
        positive("CoarseConfig::heading_step", self.heading_step)?;
        positive("CoarseConfig::translation_range", self.translation_range)?;
        positive("CoarseConfig::translation_step", self.translation_step)?;
        positive("CoarseConfig::hit_radius", self.hit_radius)?;
        positive("CoarseConfig::agree_distance", self.agree_distance)?;
        positive("CoarseConfig::agree_heading", self.agree_heading)?;
        at_least("CoarseConfig::max_points", self.max_points, 3)?;
        at_least("CoarseConfig::candidates", self.candidates, 1)?;
        if self.translation_range / self.translation_step > 1000.0 {
            return Err(MountingError::Config {
                field: "CoarseConfig::translation_step",
                reason: format!(
                    "{} m over a range of {} m: more than 1000 steps a side",
                    self.translation_step, self.translation_range
                ),
            });
        }
        Ok(())
    }
}

impl MountingConfig {
    /// Checks every value (see the field documentation for the ranges).
    pub fn validate(&self) -> Result<(), MountingError> {
        positive("MountingConfig::max_range", self.max_range)?;
        positive("MountingConfig::max_gap_periods", self.max_gap_periods)?;
        positive("MountingConfig::max_time_offset", self.max_time_offset)?;
        positive("MountingConfig::max_jump", self.max_jump)?;
        positive("MountingConfig::max_heading_jump", self.max_heading_jump)?;
        positive("MountingConfig::max_rms", self.max_rms)?;
        positive("MountingConfig::overlap_gate", self.overlap_gate)?;
        positive("MountingConfig::line_gate", self.line_gate)?;
        if !(0.0..=1.0).contains(&self.min_overlap) {
            return Err(MountingError::Config {
                field: "MountingConfig::min_overlap",
                reason: format!("{} (must lie in [0, 1])", self.min_overlap),
            });
        }
        at_least("MountingConfig::pair_stride", self.pair_stride, 1)?;
        at_least("MountingConfig::coarse_pairs", self.coarse_pairs, 1)?;
        at_least("MountingConfig::min_fits", self.min_fits, 1)?;
        at_least("MountingConfig::windows", self.windows, 1)?;
        self.coarse.validate()?;
        self.icp.validate()?;
        Ok(())
    }
}
