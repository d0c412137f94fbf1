//! Parameters of plane segmentation: [`PlaneConfig`] with its defaults and checks, and the
//! optional facade test [`WallQuality`].
//!
//! Not for: the segmentation itself (see the parent module).

use crate::error::{Error, Result};

/// Parameters of [`extract_planes`](super::extract_planes). Lengths in metres, areas in m², angles in radians.
///
/// A configuration file (the `planes` section of `track`'s, or `planes --planes-config`) may
/// set any subset of the fields; the others keep their defaults. `wall_quality = null` (JSON)
/// turns the facade test off; TOML has no null, so there a file can only change the test's
/// limits.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlaneConfig {
    /// Maximum number of RANSAC rounds (planes extracted, accepted or not).
    pub max_planes: usize,
    /// Minimum number of inliers of a plane and of a connected piece of a wall.
    pub min_points: usize,
    /// Hypotheses drawn per round.
    pub hypotheses: usize,
    /// Size of the random subsample on which hypotheses are drawn and scored.
    pub score_sample: usize,
    /// Preemptive scoring: about this many subsample points (an even stride through it) score
    /// every hypothesis first.
    pub preemptive_sample: usize,
    /// Preemptive scoring: this many of the best pre-scored hypotheses are scored on the whole
    /// subsample; `hypotheses` or more turns preemptive scoring off.
    pub preemptive_keep: usize,
    /// Edge of the voxel grid used to draw the 2nd and 3rd point of a triple near the 1st (m).
    pub sample_cell: f64,
    /// Distance within which a subsample point supports a hypothesis (m).
    pub score_threshold: f64,
    /// MSSE threshold factor `T` (inliers are within `T·σ`).
    pub msse_t: f64,
    /// Floor of the per-plane inlier threshold (m).
    pub min_threshold: f64,
    /// Ceiling of the per-plane inlier threshold (m).
    pub max_threshold: f64,
    /// Wall rounds: passes over the pool (MSSE threshold, inliers, least-squares refit) made
    /// after the round's two, each from the plane the one before fitted; they stop early once
    /// the inliers no longer change. Two passes leave a fit that still depends on the drawn
    /// triple (its band catches a tilted slice of a wall that is not quite flat); each further
    /// pass moves it towards the fixed point of threshold and fit, which is the same from scan
    /// to scan. At most [`MAX_WALL_REFITS`]. The ground's round makes none (refitting it moved
    /// the walls' normals by hundredths of a degree, and its passes cover the whole scan).
    pub wall_refits: usize,
    /// Ground: maximum angle between the normal and the vertical (rad).
    pub max_ground_tilt: f64,
    /// Ground: the plane must lie at least this far below the sensor origin (m).
    pub min_ground_depth: f64,
    /// After the ground is found, hypotheses are drawn only from points more than this far
    /// above it (m); the points themselves stay available as inliers.
    pub ground_clearance: f64,
    /// Walls: maximum angle between the normal and the horizontal plane (rad).
    pub max_wall_tilt: f64,
    /// Walls: minimum patch area (m²).
    pub min_wall_area: f64,
    /// Walls: minimum patch length, the more horizontal side (m).
    pub min_wall_length: f64,
    /// Walls: minimum patch height, the more vertical side (m).
    pub min_wall_height: f64,
    /// Cell edge of the 2-D grid used to split a plane into connected pieces (m).
    pub grid_cell: f64,
    /// Grid cells with fewer points than this take no part in the pieces (their points stay
    /// unassigned); keeps stray clutter points on the infinite plane from stretching a patch.
    pub min_cell_points: usize,
    /// Walls: two pieces of one plane are one facade when the gap between them along the
    /// wall is at most this many expected point spacings there (a wall seen at a grazing
    /// angle far ahead is sampled so sparsely that its grid cells fall apart); 0 (the
    /// default) joins nothing. The gap is at least `grid_cell` and at most `max_join_gap`.
    /// Joining on KITTI drive 0005 made the frame-to-frame vertex distances worse: the
    /// joined extents come and go with the sparse cells (docs/results/walls_association.md).
    pub join_spacings: f64,
    /// Walls: the largest gap along a wall that joins two pieces (m).
    pub max_join_gap: f64,
    /// Walls with the facade test: a wall's rectangle spans only the columns (`grid_cell`
    /// wide along the wall) whose highest point reaches the test's `min_top_above_sensor`,
    /// when the plane carries low structure beyond them (a fence, a hedge, parked cars in the
    /// facade's plane); the points stay the wall's. The low part's sparse cells come and go
    /// from scan to scan, the facade's extent does not.
    pub facade_span: bool,
    /// Walls: facade test on top of the size limits (default [`WallQuality::BUILDING`];
    /// `None`: every building-scale vertical piece is a wall).
    pub wall_quality: Option<WallQuality>,
    /// Walls: lower each wall's rectangle to the ground plane (when one is found). A wall's
    /// lowest inliers lie `ground_clearance` or more above the road, and higher where parked
    /// cars or hedges hide its foot, which changes from scan to scan; a facade stands on the
    /// ground, so its rectangle's bottom edge is put there.
    pub walls_to_ground: bool,
    /// Ground: find its bounding rectangle (`PlaneDetection::patch`), the hull of its tens of
    /// thousands of inliers, about a millisecond a frame on a real scan. Without it the
    /// ground's patch is the zero-size one at its first inlier; its plane, inliers and RMS
    /// are the same either way.
    pub ground_outline: bool,
}

/// The most [`PlaneConfig::wall_refits`] [`PlaneConfig::validate`] accepts.
pub const MAX_WALL_REFITS: usize = 100;

/// A facade test for wall pieces that already pass the size limits, so that parked cars,
/// hedges, fences and vegetation are not kept as walls.
///
/// Reasoning: on a Velodyne HDL-64E (KITTI: vertical field of view about +2° to −24.8°,
/// mounted 1.73 m above the road) a wall is seen only up to `1.73 m + r·tan 2°` at range `r`,
/// so the visible height of a building at 10-30 m is just 2-3 m and height alone cannot tell
/// it from a hedge. Three things can:
/// - a building rises above the sensor (cars and most hedges and fences do not);
/// - a facade is flat, while vegetation fills the whole inlier band (a uniform band of
///   half-width `τ` has an RMS of `τ/√3`, 0.115 m at the 0.2 m threshold ceiling);
/// - a facade is plumb: its normal is perpendicular to the local vertical (the ground plane's
///   normal), up to the slope of the road the ground was fitted to. The fitted plane of a hedge,
///   a tree row or a car side leans by several degrees, and leans differently from scan to
///   scan, which is what makes such "walls" unrepeatable.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WallQuality {
    /// The patch's top must be at least this high above the sensor's horizontal plane
    /// (z = 0 of the sensor frame), m; negative values admit tops below the sensor.
    pub min_top_above_sensor: f64,
    /// Largest RMS point-to-plane distance of the piece (m).
    pub max_rms: f64,
    /// Largest angle between the piece's plane and the local vertical (rad): the normal's
    /// elevation above the ground plane (or, without a ground, above the sensor's x-y plane).
    pub max_lean: f64,
}

impl Default for WallQuality {
    /// [`WallQuality::BUILDING`].
    fn default() -> Self {
        WallQuality::BUILDING
    }
}

impl WallQuality {
    /// Building scale on a roof-mounted automotive lidar: the top above the sensor, RMS at
    /// most 0.08 m (below the 0.115 m of a band filling the threshold ceiling), and at most
    /// 5° from plumb relative to the ground (admits streets of up to about 9 % grade).
    pub const BUILDING: WallQuality = WallQuality {
        min_top_above_sensor: 0.0,
        max_rms: 0.08,
        max_lean: 5.0 * std::f64::consts::PI / 180.0,
    };
}

impl Default for PlaneConfig {
    fn default() -> Self {
        PlaneConfig {
            max_planes: 16,
            min_points: 150,
            hypotheses: 256,
            score_sample: 6000,
            preemptive_sample: 1000,
            preemptive_keep: 32,
            sample_cell: 2.0,
            score_threshold: 0.10,
            msse_t: 2.5,
            min_threshold: 0.05,
            max_threshold: 0.20,
            wall_refits: 2,
            max_ground_tilt: 10f64.to_radians(),
            min_ground_depth: 0.5,
            ground_clearance: 0.3,
            max_wall_tilt: 15f64.to_radians(),
            min_wall_area: 15.0,
            min_wall_length: 4.0,
            min_wall_height: 2.0,
            grid_cell: 1.0,
            min_cell_points: 3,
            join_spacings: 0.0,
            max_join_gap: 5.0,
            facade_span: true,
            wall_quality: Some(WallQuality::BUILDING),
            walls_to_ground: true,
            ground_outline: true,
        }
    }
}

impl PlaneConfig {
    /// The default configuration, whose facade test is [`WallQuality::BUILDING`]: walls must
    /// rise above the sensor, be flat and be plumb.
    pub fn building_scale() -> Self {
        PlaneConfig::default()
    }

    /// The default configuration without the facade test: every building-scale vertical piece
    /// is a wall (hedges, fences and large vehicles included).
    pub fn any_vertical() -> Self {
        PlaneConfig {
            wall_quality: None,
            ..Default::default()
        }
    }

    /// Checks every field for a usable value.
    pub fn validate(&self) -> Result<()> {
        let positive = [
            ("sample_cell", self.sample_cell),
            ("score_threshold", self.score_threshold),
            ("msse_t", self.msse_t),
            ("min_threshold", self.min_threshold),
            ("grid_cell", self.grid_cell),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    format!("plane config field {name}"),
                    format!("must be finite and positive, got {v}"),
                ));
            }
        }
        let non_negative = [
            ("max_ground_tilt", self.max_ground_tilt),
            ("min_ground_depth", self.min_ground_depth),
            ("ground_clearance", self.ground_clearance),
            ("join_spacings", self.join_spacings),
            ("max_join_gap", self.max_join_gap),
            ("max_wall_tilt", self.max_wall_tilt),
            ("min_wall_area", self.min_wall_area),
            ("min_wall_length", self.min_wall_length),
            ("min_wall_height", self.min_wall_height),
        ];
        for (name, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    format!("plane config field {name}"),
                    format!("must be finite and non-negative, got {v}"),
                ));
            }
        }
        if let Some(q) = &self.wall_quality {
            if !(q.min_top_above_sensor.is_finite() && q.max_rms > 0.0 && q.max_lean >= 0.0) {
                return Err(Error::invalid(
                    "plane config field wall_quality",
                    "min_top_above_sensor must be finite, max_rms positive and max_lean \
                     non-negative",
                ));
            }
        }
        if self.wall_refits > MAX_WALL_REFITS {
            return Err(Error::invalid(
                "plane config field wall_refits",
                format!("at most {MAX_WALL_REFITS}, got {}", self.wall_refits),
            ));
        }
        if !(self.max_threshold.is_finite() && self.max_threshold >= self.min_threshold) {
            return Err(Error::invalid(
                "plane config field max_threshold",
                "must be finite and at least min_threshold",
            ));
        }
        if self.min_points < 3
            || self.hypotheses == 0
            || self.score_sample < 3
            || self.preemptive_sample == 0
            || self.preemptive_keep == 0
        {
            return Err(Error::invalid(
                "plane config",
                "min_points and score_sample must be at least 3, hypotheses, preemptive_sample \
                 and preemptive_keep at least 1",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_sets_a_subset_and_the_rest_keeps_the_defaults() {
        let c: PlaneConfig = serde_json::from_str(r#"{"wall_refits": 4}"#).unwrap();
        assert_eq!(
            c,
            PlaneConfig {
                wall_refits: 4,
                ..PlaneConfig::default()
            }
        );
        let c: PlaneConfig = serde_json::from_str(r#"{"wall_quality": {"max_rms": 0.1}}"#).unwrap();
        assert_eq!(
            c.wall_quality,
            Some(WallQuality {
                max_rms: 0.1,
                ..WallQuality::BUILDING
            })
        );
        let c: PlaneConfig = serde_json::from_str(r#"{"wall_quality": null}"#).unwrap();
        assert_eq!(c.wall_quality, None);
        let back: PlaneConfig =
            serde_json::from_str(&serde_json::to_string(&PlaneConfig::default()).unwrap()).unwrap();
        assert_eq!(back, PlaneConfig::default());
        assert!(serde_json::from_str::<PlaneConfig>(r#"{"wall_refit": 4}"#).is_err());
    }
}
