//! Moving-object detection from a moving planar laser, after seed 003 (Secs. II–IV): the
//! odometry is refined by ICP, a per-beam background map removes the static scene, the
//! remaining points are clustered and filtered by local range minima, and an on-line Fuzzy
//! ART classifier with a voting vector learns which cluster shapes belong to moving targets.
//!
//! Not for: tracking (the LMB filter does that from the detections) or building maps.
//!
//! # One scan ([`MovingObjectDetector::process`])
//!
//! 1. **Pose.** The sensor pose is the odometry pose composed with the mounting offset. The
//!    odometry increment since the previous scan predicts the new sensor pose from the
//!    previous *corrected* one; ICP then aligns the scan's returns with a local map of the
//!    static returns seen so far (cell means, see the local-map module). Seed 003 matches
//!    against the previous scan only; with a noisy scanner the per-pair errors of
//!    scan-to-scan matching add up to more drift than the odometry has, while the map's
//!    averaged cells keep the error bounded. Scans with fewer than
//!    [`MovingDetectorConfig::min_icp_points`] returns are not matched.
//!    The ICP result is used when it converged within the gates
//!    [`MovingDetectorConfig::max_correction`] / [`MovingDetectorConfig::max_correction_angle`]
//!    of the prediction with at least [`MovingDetectorConfig::min_inlier_fraction`] inliers,
//!    and its pairs pin the translation down in every direction (where the map is made of
//!    lines: see [`MovingDetectorConfig::min_information_ratio`]); otherwise the prediction
//!    stands and [`MovingDetections::fallback`] says why.
//! 2. **Background** (Sec. II): the background map is carried along the corrected motion and
//!    splits the beams; foreground returns are the candidates, unless they lie within
//!    [`MovingDetectorConfig::static_map_radius`] of the local map (static surfaces seen
//!    before, now reappearing from a new viewpoint; not in the seed).
//! 3. **Clusters** (Sec. III): candidates closer than [`MovingDetectorConfig::cluster_gap`]
//!    to one of the candidates up to [`MovingDetectorConfig::cluster_window`] beams before
//!    them share a cluster; clusters with fewer than
//!    [`MovingDetectorConfig::min_cluster_points`] are dropped. The scan's ranges are
//!    smoothed by a moving average over `2·smoothing + 1` beams (returns only), a beam is a
//!    local minimum when its smoothed range is the smallest within ±`minima_window` beams,
//!    and only clusters holding a local minimum are kept (eq. 7).
//! 4. **Shape learning** (Sec. IV): each kept cluster's fourteen features (see the features
//!    module; jumps to the nearest returns outside the cluster in beam order, speed from the
//!    nearest kept cluster of the previous scan within
//!    [`MovingDetectorConfig::association_gate`]) are normalised and classified by Fuzzy
//!    ART. A cluster *persists* when such a previous cluster exists — the stand-in here for
//!    the seed's track initiation. Each persisting cluster adds one vote to its category
//!    (at most [`MovingDetectorConfig::vote_max`], 50); every
//!    [`MovingDetectorConfig::forget_every`] scans every vote count drops by one (not below
//!    0). A category is *dominant* when its count is within
//!    [`MovingDetectorConfig::vote_margin`] (15) of the highest (eq. 8). A kept cluster is a
//!    moving target when its category is dominant and, with
//!    [`MovingDetectorConfig::require_persistence`], it persists.
//!    That is seed 003's rule ([`MovingRule::Voting`]); [`MovingRule::Attenuation`] instead
//!    takes every cluster of foreground returns as moving (no local-minimum test, no
//!    persistence) and lets a non-dominant category veto it only when asked to (see the
//!    moving-rule module for the reasons). Every cluster is reported with the stage at which
//!    it ended ([`MovingDetections::all_clusters`]), so each stage's recall can be measured.
//! 5. The background is updated (eqs. 4, 6); beams of moving targets keep their weights.
//!    Returns that are not foreground and whose beam weight reached
//!    [`MovingDetectorConfig::map_min_weight`] join the local map (world frame).
//!
//! Everything is deterministic: no randomness, fixed iteration orders.

use super::background::{BackgroundConfig, BackgroundMap, BeamClass};
use super::features::{normalise, segment_features, Features, SegmentContext, NUM_FEATURES};
use super::fuzzy_art::{FuzzyArt, FuzzyArtConfig};
use super::icp::{Icp, IcpConfig, IcpFit};
use super::local_map::LocalMap;
pub use super::moving_rule::{ClusterEvidence, ClusterStage, MovingRule};
use super::scan::Scan;
use crate::error::{ensure_positive, Error, Result};
use crate::geometry::pose2::{between, compose, inverse, transform_point};
use crate::geometry::Pose2;

/// Parameters of the detector; defaults follow seed 003 where it gives values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MovingDetectorConfig {
    /// Sensor offset `[a, b]` on the robot (m): `a` forward, `b` left. Default `[0, 0]`.
    pub mount: [f64; 2],
    /// ICP parameters.
    pub icp: IcpConfig,
    /// Side of the local map's cells (m). Default 0.2 m.
    pub map_cell: f64,
    /// Returns enter the map once their beam's background weight reaches this. Default 2
    /// (so the first scan builds the map).
    pub map_min_weight: u8,
    /// Map cells farther than this from the sensor are dropped every 20 scans (m).
    /// Default 30 m.
    pub map_radius: f64,
    /// Scans with fewer returns are not matched (odometry only). Default 80.
    pub min_icp_points: usize,
    /// ICP results farther than this from the odometry prediction are rejected (m).
    /// Default 0.3 m.
    pub max_correction: f64,
    /// ... or turning more than this away from it (rad). Default 0.05 rad.
    pub max_correction_angle: f64,
    /// ICP results with fewer inliers (fraction of the scan's returns) are rejected.
    /// Default 0.5.
    pub min_inlier_fraction: f64,
    /// ICP results whose pairs leave a direction unconstrained are rejected: an
    /// [`IcpFit::information_ratio`] below this (a corridor, where the fit can slide along
    /// the walls) when at least [`MovingDetectorConfig::min_line_share`] of the pairs lie on
    /// lines. Default 1e-3 (a corridor of straight walls scores below 1e-6, rooms and real
    /// recordings' hallways 0.002–0.5).
    pub min_information_ratio: f64,
    /// The share of pairs on lines below which the map is too sparse or cluttered for the
    /// information test, which is then skipped. Default 0.5.
    pub min_line_share: f64,
    /// The background map.
    pub background: BackgroundConfig,
    /// Foreground returns closer than this to a cell of the local map (static returns seen
    /// before, world frame) are not candidates (m); 0 turns the test off. Not in seed 003:
    /// it removes static surfaces that reappear in front of the propagated background as the
    /// robot's viewpoint changes. Default 0.3 m.
    pub static_map_radius: f64,
    /// Largest distance between neighbouring candidates of one cluster (m). Default 0.6 m.
    pub cluster_gap: f64,
    /// Candidates are linked to candidates up to this many beams back. Default 12 (bearing
    /// noise shuffles the beam order of a small object's returns).
    pub cluster_window: usize,
    /// Smallest cluster (points). Default 3.
    pub min_cluster_points: usize,
    /// Half-width of the range smoothing (beams). Default 2.
    pub smoothing: usize,
    /// Half-width of the local-minimum test (beams). Default 4.
    pub minima_window: usize,
    /// Fuzzy ART parameters (seed 003: ρ 0.85, α 1e-6, β 1, ten categories).
    pub art: FuzzyArtConfig,
    /// Largest vote count; seed 003: 50.
    pub vote_max: u32,
    /// Dominance margin; seed 003: 15.
    pub vote_margin: u32,
    /// One vote is forgotten every this many scans; seed 003: 10.
    pub forget_every: u64,
    /// Largest centroid displacement between scans for a cluster to persist (m).
    /// Default 0.8 m.
    pub association_gate: f64,
    /// Only persisting clusters can be moving targets (with [`MovingRule::Voting`]).
    /// Default true.
    pub require_persistence: bool,
    /// How clusters become moving targets. Default [`MovingRule::Voting`] (seed 003).
    pub rule: MovingRule,
}

impl Default for MovingDetectorConfig {
    fn default() -> Self {
        MovingDetectorConfig {
            mount: [0.0, 0.0],
            icp: IcpConfig::default(),
            map_cell: 0.2,
            map_min_weight: 2,
            map_radius: 30.0,
            min_icp_points: 80,
            max_correction: 0.3,
            max_correction_angle: 0.05,
            min_inlier_fraction: 0.5,
            min_information_ratio: 1e-3,
            min_line_share: 0.5,
            background: BackgroundConfig::default(),
            static_map_radius: 0.3,
            cluster_gap: 0.6,
            cluster_window: 12,
            min_cluster_points: 3,
            smoothing: 2,
            minima_window: 4,
            art: FuzzyArtConfig::default(),
            vote_max: 50,
            vote_margin: 15,
            forget_every: 10,
            association_gate: 0.8,
            require_persistence: true,
            rule: MovingRule::Voting,
        }
    }
}

impl MovingDetectorConfig {
    /// Defaults for a scanner with bearing noise `sigma_bearing` (rad) and beam spacing
    /// `angle_increment` (rad) mounted at `mount` on the robot: the background's
    /// neighbourhood test spans one bearing standard deviation, `⌈σ_b / |Δθ|⌉` beams (at
    /// most 10; on the simulated scanner, σ_b = 2° and 0.5° beams, 4 beams gave the best
    /// precision for its recall among 0, 2, 3, 4 and 6).
    pub fn for_scanner(sigma_bearing: f64, angle_increment: f64, mount: [f64; 2]) -> Self {
        let beams = (sigma_bearing / angle_increment.abs()).ceil();
        let neighbour_beams = if beams.is_finite() && beams > 0.0 {
            (beams as usize).min(10)
        } else {
            0
        };
        MovingDetectorConfig {
            mount,
            background: BackgroundConfig {
                neighbour_beams,
                ..BackgroundConfig::default()
            },
            ..MovingDetectorConfig::default()
        }
    }

    /// Checks every part.
    pub fn validate(&self) -> Result<()> {
        if !self.mount.iter().all(|v| v.is_finite()) {
            return Err(Error::invalid(
                "MovingDetectorConfig::mount",
                format!("{:?} is not finite", self.mount),
            ));
        }
        self.icp.validate()?;
        self.background.validate()?;
        self.art.validate()?;
        for (name, v) in [
            ("map_cell", self.map_cell),
            ("map_radius", self.map_radius),
            ("max_correction", self.max_correction),
            ("max_correction_angle", self.max_correction_angle),
            ("cluster_gap", self.cluster_gap),
            ("association_gate", self.association_gate),
        ] {
            ensure_positive(&format!("MovingDetectorConfig::{name}"), v)?;
        }
        crate::error::ensure_non_negative(
            "MovingDetectorConfig::static_map_radius",
            self.static_map_radius,
        )?;
        for (name, v) in [
            ("min_inlier_fraction", self.min_inlier_fraction),
            ("min_information_ratio", self.min_information_ratio),
            ("min_line_share", self.min_line_share),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(Error::invalid(
                    format!("MovingDetectorConfig::{name}"),
                    format!("{v} (must lie in [0, 1])"),
                ));
            }
        }
        if self.cluster_window == 0 || self.min_cluster_points == 0 || self.forget_every == 0 {
            return Err(Error::invalid(
                "MovingDetectorConfig",
                "cluster_window, min_cluster_points and forget_every must be at least 1",
            ));
        }
        Ok(())
    }
}

/// One cluster the detector reports as a moving target.
#[derive(Clone, Debug, PartialEq)]
pub struct MovingCluster {
    /// Beam indices of its points, increasing.
    pub beams: Vec<usize>,
    /// Its points in the world (corrected odometry) frame.
    pub points: Vec<[f64; 2]>,
    /// Mean of the points, world frame.
    pub centroid: [f64; 2],
    /// Mean of the points in the sensor frame (for range-bearing measurements).
    pub centroid_sensor: [f64; 2],
    /// The fourteen raw features (features module order).
    pub features: Features,
    /// Its Fuzzy ART category.
    pub category: usize,
    /// True when a cluster of the previous scan lay within the association gate.
    pub persistent: bool,
}

/// One cluster of foreground returns and the stage at which it ended.
#[derive(Clone, Debug, PartialEq)]
pub struct ClusterReport {
    /// Beam indices of its points, increasing.
    pub beams: Vec<usize>,
    /// Mean of the points, world (corrected odometry) frame.
    pub centroid: [f64; 2],
    /// Where the decision rule left it.
    pub stage: ClusterStage,
}

/// What [`MovingObjectDetector::process`] found in one scan.
#[derive(Clone, Debug, PartialEq)]
pub struct MovingDetections {
    /// The corrected robot pose (odometry frame).
    pub pose: Pose2,
    /// The corrected sensor pose (robot pose plus mounting offset).
    pub sensor_pose: Pose2,
    /// The ICP fit, when ICP ran and its result was used.
    pub icp: Option<IcpFit>,
    /// Why the predicted pose was kept instead of an ICP result (never on the first scan,
    /// which defines the map).
    pub fallback: Option<PoseFallback>,
    /// The moving targets.
    pub clusters: Vec<MovingCluster>,
    /// Clusters that passed the size and local-minimum filters (moving or not).
    pub kept_clusters: usize,
    /// Returns classified as foreground (candidates).
    pub candidate_points: usize,
    /// Returns not classified as foreground.
    pub background_points: usize,
    /// Beam indices of the candidates (foreground returns off the static map), increasing.
    pub candidates: Vec<usize>,
    /// Every cluster of candidates, in order of its first beam, with its stage.
    pub all_clusters: Vec<ClusterReport>,
}

/// Why a scan kept the predicted pose (odometry, or constant velocity without it) instead
/// of the scan matching's.
#[derive(
    Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum PoseFallback {
    /// Fewer returns than [`MovingDetectorConfig::min_icp_points`].
    TooFewPoints,
    /// Too few returns found a map point within reach ([`IcpConfig::min_pairs`]).
    TooFewPairs,
    /// ICP did not converge within its iterations.
    NotConverged,
    /// The result lies beyond [`MovingDetectorConfig::max_correction`] or
    /// [`MovingDetectorConfig::max_correction_angle`] of the prediction.
    Jump,
    /// Fewer inliers than [`MovingDetectorConfig::min_inlier_fraction`].
    FewInliers,
    /// The pairs leave a direction unconstrained
    /// ([`MovingDetectorConfig::min_information_ratio`]).
    Degenerate,
}

impl PoseFallback {
    /// Every reason, in order.
    pub const ALL: [PoseFallback; 6] = [
        PoseFallback::TooFewPoints,
        PoseFallback::TooFewPairs,
        PoseFallback::NotConverged,
        PoseFallback::Jump,
        PoseFallback::FewInliers,
        PoseFallback::Degenerate,
    ];

    /// A short description for warnings.
    pub fn describe(self) -> &'static str {
        match self {
            PoseFallback::TooFewPoints => "too few returns",
            PoseFallback::TooFewPairs => "too few returns near the map",
            PoseFallback::NotConverged => "no convergence",
            PoseFallback::Jump => "a jump beyond the gates",
            PoseFallback::FewInliers => "too few inliers",
            PoseFallback::Degenerate => "a direction left unconstrained (corridor)",
        }
    }
}

/// A kept cluster before the voting decides (internal).
struct Kept {
    beams: Vec<usize>,
    centroid: [f64; 2],
    centroid_sensor: [f64; 2],
    features: Features,
    category: usize,
    persistent: bool,
}

/// The detector; see the module documentation.
#[derive(Debug)]
pub struct MovingObjectDetector {
    config: MovingDetectorConfig,
    icp: Icp,
    background: BackgroundMap,
    art: FuzzyArt,
    votes: Vec<u32>,
    scans: u64,
    /// Previous scan: raw odometry sensor pose, corrected sensor pose, time.
    previous: Option<(Pose2, Pose2, f64)>,
    map: LocalMap,
    previous_centroids: Vec<[f64; 2]>,
    // Scratch.
    points: Vec<[f64; 2]>,
    sensor_points: Vec<Option<[f64; 2]>>,
    smoothed: Vec<f64>,
    occluded: Vec<bool>,
}

impl MovingObjectDetector {
    /// A detector that has seen no scan yet.
    pub fn new(config: MovingDetectorConfig) -> Result<Self> {
        config.validate()?;
        Ok(MovingObjectDetector {
            icp: Icp::new(config.icp)?,
            background: BackgroundMap::new(config.background)?,
            art: FuzzyArt::new(NUM_FEATURES, config.art)?,
            votes: Vec::new(),
            scans: 0,
            previous: None,
            map: LocalMap::new(config.map_cell)?,
            previous_centroids: Vec::new(),
            points: Vec::new(),
            sensor_points: Vec::new(),
            smoothed: Vec::new(),
            occluded: Vec::new(),
            config,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &MovingDetectorConfig {
        &self.config
    }

    /// The vote count of every category learned so far.
    pub fn votes(&self) -> &[u32] {
        &self.votes
    }

    /// The background map.
    pub fn background(&self) -> &BackgroundMap {
        &self.background
    }

    /// Processes one scan with the robot's odometry pose at the scan's time.
    pub fn process(&mut self, scan: &Scan, odometry: Pose2) -> Result<MovingDetections> {
        scan.validate()?;
        if !odometry.is_finite() {
            return Err(Error::invalid(
                "odometry pose",
                format!("{odometry:?} is not finite"),
            ));
        }
        let mount = Pose2::new(self.config.mount[0], self.config.mount[1], 0.0);
        let sensor_odometry = compose(odometry, mount);
        self.points.clear();
        self.sensor_points.clear();
        for i in 0..scan.len() {
            let p = scan.point(i);
            self.sensor_points.push(p);
            if let Some(p) = p {
                self.points.push(p);
            }
        }
        // 1. Pose.
        let (sensor_pose, icp_fit, fallback, dt) = match self.previous {
            None => (sensor_odometry, None, None, 0.0),
            Some((prev_odometry, prev_corrected, prev_time)) => {
                let predicted = compose(prev_corrected, between(prev_odometry, sensor_odometry));
                let (pose, fit) = if self.points.len() >= self.config.min_icp_points {
                    self.correct(predicted)
                } else {
                    (predicted, Err(PoseFallback::TooFewPoints))
                };
                self.background.propagate(between(prev_corrected, pose))?;
                (pose, fit.ok(), fit.err(), scan.time - prev_time)
            }
        };
        // 2. Background.
        let classes = self.background.classify(scan)?;
        let mut candidates = Vec::new();
        let mut background_points = 0;
        for (i, c) in classes.iter().enumerate() {
            if let Some(p) = self.sensor_points[i] {
                let on_map = self.config.static_map_radius > 0.0
                    && self
                        .icp
                        .nearest_target_distance(transform_point(sensor_pose, p))
                        .is_some_and(|d| d <= self.config.static_map_radius);
                if *c == BeamClass::Foreground && !on_map {
                    candidates.push(i);
                } else {
                    background_points += 1;
                }
            }
        }
        // 3. Clusters (with a local minimum when the rule asks for one).
        let clusters = self.cluster(&candidates);
        self.smooth(scan);
        let rule = self.config.rule;
        let mut all_clusters = Vec::new();
        let mut kept_beams: Vec<Vec<usize>> = Vec::new();
        for c in clusters {
            let local_minimum = c.iter().any(|&i| self.is_local_minimum(i));
            let early = rule.decide(
                &ClusterEvidence {
                    points: c.len(),
                    local_minimum,
                    persistent: true,
                    dominant: true,
                },
                self.config.min_cluster_points,
                false,
            );
            if early == ClusterStage::Moving {
                kept_beams.push(c);
            } else {
                all_clusters.push(ClusterReport {
                    centroid: self.world_centroid(&c, sensor_pose),
                    beams: c,
                    stage: early,
                });
            }
        }
        // 4. Features, categories, votes.
        let mut kept = Vec::with_capacity(kept_beams.len());
        for beams in kept_beams {
            kept.push(self.describe(scan, beams, sensor_pose, dt)?);
        }
        self.scans += 1;
        if self.scans.is_multiple_of(self.config.forget_every) {
            for v in &mut self.votes {
                *v = v.saturating_sub(1);
            }
        }
        for k in &kept {
            if self.votes.len() <= k.category {
                self.votes.resize(k.category + 1, 0);
            }
            if k.persistent {
                let v = &mut self.votes[k.category];
                *v = (*v + 1).min(self.config.vote_max);
            }
        }
        let highest = self.votes.iter().copied().max().unwrap_or(0);
        let dominant = |c: usize| self.votes[c] + self.config.vote_margin >= highest;
        self.occluded.clear();
        self.occluded.resize(scan.len(), false);
        let kept_clusters = kept.len();
        let mut moving = Vec::new();
        for k in &kept {
            let stage = rule.decide(
                &ClusterEvidence {
                    points: k.beams.len(),
                    local_minimum: true,
                    persistent: k.persistent,
                    dominant: dominant(k.category),
                },
                self.config.min_cluster_points,
                self.config.require_persistence,
            );
            all_clusters.push(ClusterReport {
                beams: k.beams.clone(),
                centroid: k.centroid,
                stage,
            });
            if stage == ClusterStage::Moving {
                for &b in &k.beams {
                    self.occluded[b] = true;
                }
                moving.push(MovingCluster {
                    points: k
                        .beams
                        .iter()
                        .filter_map(|&b| self.sensor_points[b])
                        .map(|p| transform_point(sensor_pose, p))
                        .collect(),
                    beams: k.beams.clone(),
                    centroid: k.centroid,
                    centroid_sensor: k.centroid_sensor,
                    features: k.features,
                    category: k.category,
                    persistent: k.persistent,
                });
            }
        }
        all_clusters.sort_by_key(|c| c.beams[0]);
        self.previous_centroids.clear();
        self.previous_centroids
            .extend(kept.iter().map(|k| k.centroid));
        // 5. Background update, then the map for the next scan's ICP.
        self.background.update(scan, &self.occluded)?;
        self.grow_map(sensor_pose)?;
        self.previous = Some((sensor_odometry, sensor_pose, scan.time));
        Ok(MovingDetections {
            pose: compose(sensor_pose, inverse(mount)),
            sensor_pose,
            icp: icp_fit,
            fallback,
            clusters: moving,
            kept_clusters,
            candidate_points: candidates.len(),
            background_points,
            candidates,
            all_clusters,
        })
    }

    /// ICP of the scan's returns against the local map from the predicted pose; the
    /// corrected pose and the fit when it passed the gates, else the prediction and why.
    fn correct(&mut self, predicted: Pose2) -> (Pose2, std::result::Result<IcpFit, PoseFallback>) {
        let c = self.config;
        let Ok(fit) = self.icp.align(&self.points, predicted) else {
            return (predicted, Err(PoseFallback::TooFewPairs));
        };
        let d = between(predicted, fit.transform);
        let verdict = if !fit.converged {
            Err(PoseFallback::NotConverged)
        } else if d.x.hypot(d.y) > c.max_correction || d.theta.abs() > c.max_correction_angle {
            Err(PoseFallback::Jump)
        } else if fit.inlier_fraction < c.min_inlier_fraction {
            Err(PoseFallback::FewInliers)
        } else if fit.line_share >= c.min_line_share
            && fit.information_ratio < c.min_information_ratio
        {
            Err(PoseFallback::Degenerate)
        } else {
            Ok(fit)
        };
        match verdict {
            Ok(fit) => (fit.transform, Ok(fit)),
            Err(why) => (predicted, Err(why)),
        }
    }

    /// Adds the scan's settled static returns to the local map, prunes it now and then and
    /// makes it the ICP target.
    fn grow_map(&mut self, sensor_pose: Pose2) -> Result<()> {
        let classes = self.background.classes();
        let weights = self.background.weights();
        for (i, p) in self.sensor_points.iter().enumerate() {
            if let Some(p) = *p {
                let settled = matches!(classes[i], BeamClass::Background | BeamClass::Beyond);
                if settled && weights[i] >= self.config.map_min_weight {
                    self.map.insert(transform_point(sensor_pose, p));
                }
            }
        }
        if self.scans.is_multiple_of(20) {
            self.map
                .prune([sensor_pose.x, sensor_pose.y], self.config.map_radius);
        }
        let target = self.map.means(1);
        self.icp.set_target(target)
    }

    /// Distance clustering of the candidate beams (see the module docs); clusters in order
    /// of their first beam, beams increasing.
    fn cluster(&self, candidates: &[usize]) -> Vec<Vec<usize>> {
        let n = candidates.len();
        let mut parent: Vec<usize> = (0..n).collect();
        fn root(parent: &mut [usize], mut i: usize) -> usize {
            while parent[i] != i {
                parent[i] = parent[parent[i]];
                i = parent[i];
            }
            i
        }
        let gap2 = self.config.cluster_gap * self.config.cluster_gap;
        for k in 0..n {
            let pk = self.sensor_points[candidates[k]].expect("candidates are returns");
            for m in (0..k).rev() {
                if candidates[k] - candidates[m] > self.config.cluster_window {
                    break;
                }
                let pm = self.sensor_points[candidates[m]].expect("candidates are returns");
                let d2 = (pk[0] - pm[0]).powi(2) + (pk[1] - pm[1]).powi(2);
                if d2 <= gap2 {
                    let (a, b) = (root(&mut parent, k), root(&mut parent, m));
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
        let mut out: Vec<Vec<usize>> = Vec::new();
        let mut slot = vec![usize::MAX; n];
        for (k, &beam) in candidates.iter().enumerate() {
            let r = root(&mut parent, k);
            if slot[r] == usize::MAX {
                slot[r] = out.len();
                out.push(Vec::new());
            }
            out[slot[r]].push(beam);
        }
        out
    }

    /// Moving average of the returns' ranges over `2·smoothing + 1` beams (`+∞` where the
    /// window holds no return).
    fn smooth(&mut self, scan: &Scan) {
        let n = scan.len();
        let h = self.config.smoothing;
        self.smoothed.clear();
        for i in 0..n {
            let (mut s, mut c) = (0.0, 0.0);
            for j in i.saturating_sub(h)..(i + h + 1).min(n) {
                if let Some(r) = scan.range(j) {
                    s += r;
                    c += 1.0;
                }
            }
            self.smoothed
                .push(if c > 0.0 { s / c } else { f64::INFINITY });
        }
    }

    fn is_local_minimum(&self, i: usize) -> bool {
        if !self.config.rule.uses_local_minimum() {
            return false;
        }
        let n = self.smoothed.len();
        let w = self.config.minima_window;
        let v = self.smoothed[i];
        v.is_finite() && (i.saturating_sub(w)..(i + w + 1).min(n)).all(|j| self.smoothed[j] >= v)
    }

    /// Mean of the cluster's returns in the world frame.
    fn world_centroid(&self, beams: &[usize], sensor_pose: Pose2) -> [f64; 2] {
        let n = beams.len().max(1) as f64;
        let c = beams
            .iter()
            .filter_map(|&b| self.sensor_points[b])
            .fold([0.0, 0.0], |a, p| [a[0] + p[0] / n, a[1] + p[1] / n]);
        transform_point(sensor_pose, c)
    }

    /// Features, category and persistence of one kept cluster.
    fn describe(
        &mut self,
        scan: &Scan,
        beams: Vec<usize>,
        sensor_pose: Pose2,
        dt: f64,
    ) -> Result<Kept> {
        let pts: Vec<[f64; 2]> = beams
            .iter()
            .map(|&b| self.sensor_points[b].expect("candidates are returns"))
            .collect();
        let nf = pts.len() as f64;
        let centroid_sensor = pts
            .iter()
            .fold([0.0, 0.0], |a, p| [a[0] + p[0] / nf, a[1] + p[1] / nf]);
        let centroid = transform_point(sensor_pose, centroid_sensor);
        let first = beams[0];
        let last = *beams.last().expect("clusters are not empty");
        let far = super::features::FEATURE_RANGES[3][1];
        let jump = |p: [f64; 2], other: Option<[f64; 2]>| {
            other.map_or(far, |q| (p[0] - q[0]).hypot(p[1] - q[1]))
        };
        let before = (0..first).rev().find_map(|j| self.sensor_points[j]);
        let after = (last + 1..scan.len()).find_map(|j| self.sensor_points[j]);
        let nearest = self
            .previous_centroids
            .iter()
            .map(|q| (centroid[0] - q[0]).hypot(centroid[1] - q[1]))
            .min_by(f64::total_cmp)
            .filter(|&d| d <= self.config.association_gate);
        let speed = match nearest {
            Some(d) if dt > 0.0 => d / dt,
            _ => 0.0,
        };
        let features = segment_features(
            &pts,
            &SegmentContext {
                jump_prev: jump(pts[0], before),
                jump_next: jump(pts[pts.len() - 1], after),
                speed,
            },
        )?;
        let category = self.art.classify(&normalise(&features))?.category;
        Ok(Kept {
            beams,
            centroid,
            centroid_sensor,
            features,
            category,
            persistent: nearest.is_some(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A room 10 m wide seen from its middle with 361 beams over 180°, and optionally a
    /// person (disc of radius 0.2 m) at `person` in the sensor frame; exact ranges.
    fn room_scan(t: f64, person: Option<[f64; 2]>) -> Scan {
        let n = 361;
        let inc = std::f64::consts::PI / 360.0;
        let ranges: Vec<f32> = (0..n)
            .map(|i| {
                let phi = -std::f64::consts::FRAC_PI_2 + i as f64 * inc;
                let dir = [phi.cos(), phi.sin()];
                // Walls x = 6, y = ±5.
                let mut r = f64::INFINITY;
                if dir[0] > 1e-9 {
                    r = r.min(6.0 / dir[0]);
                }
                if dir[1].abs() > 1e-9 {
                    r = r.min(5.0 / dir[1].abs());
                }
                if let Some(c) = person {
                    if let Some(d) = crate::geometry::ray_circle([0.0, 0.0], dir, c, 0.2) {
                        r = r.min(d);
                    }
                }
                r as f32
            })
            .collect();
        Scan::new(t, -std::f64::consts::FRAC_PI_2, inc, ranges, 0.0, 30.0).unwrap()
    }

    #[test]
    fn a_walking_person_in_a_static_room_is_the_only_detection() {
        let mut det = MovingObjectDetector::new(MovingDetectorConfig::default()).unwrap();
        let still = Pose2::new(0.0, 0.0, 0.0);
        let mut found = 0;
        for k in 0..40 {
            let t = k as f64 * 0.125;
            let person = (k >= 5).then(|| [3.0, -2.0 + 0.1 * k as f64]);
            let d = det.process(&room_scan(t, person), still).unwrap();
            // A static robot in a static room: the pose never moves.
            assert!(d.pose.x.abs() < 0.01 && d.pose.y.abs() < 0.01 && d.pose.theta.abs() < 1e-3);
            for c in &d.clusters {
                let p = person.expect("no detection without a person");
                let err = (c.centroid[0] - p[0]).hypot(c.centroid[1] - p[1]);
                assert!(err < 0.3, "cluster at {:?}, person at {p:?}", c.centroid);
                found += 1;
            }
        }
        // Walking 0.1 m per scan, the person is seen from the second scan on.
        assert!(found >= 30, "found in {found} scans");
    }

    #[test]
    fn icp_corrects_a_biased_odometry() {
        let mut det = MovingObjectDetector::new(MovingDetectorConfig::default()).unwrap();
        // The robot stands still but the odometry claims it drives 2 cm and turns 0.2° a scan.
        for k in 0..20 {
            let odo = Pose2::new(0.02 * k as f64, 0.0, (0.2f64 * k as f64).to_radians());
            let d = det
                .process(&room_scan(k as f64 * 0.125, None), odo)
                .unwrap();
            assert!(
                d.pose.x.abs() < 0.01 && d.pose.y.abs() < 0.01,
                "{:?}",
                d.pose
            );
            // The drift the odometry would have reached by the last scan: 3.8°.
            assert!(d.pose.theta.abs() < 3e-3, "{:?}", d.pose);
            assert!(d.clusters.is_empty());
        }
    }

    /// An endless corridor 3 m wide along x, seen from its axis: two parallel walls.
    fn corridor_scan(t: f64) -> Scan {
        let n = 361;
        let inc = std::f64::consts::PI / 360.0;
        let ranges: Vec<f32> = (0..n)
            .map(|i| {
                let phi = -std::f64::consts::FRAC_PI_2 + i as f64 * inc;
                let s = phi.sin().abs();
                (if s > 1e-9 { 1.5 / s } else { f64::INFINITY }) as f32
            })
            .collect();
        Scan::new(t, -std::f64::consts::FRAC_PI_2, inc, ranges, 0.0, 30.0).unwrap()
    }

    #[test]
    fn a_corridor_keeps_the_odometry_and_says_why() {
        let mut det = MovingObjectDetector::new(MovingDetectorConfig::default()).unwrap();
        // The robot drives 5 cm a scan along the corridor; every scan looks the same, so
        // only the odometry knows how far it went.
        for k in 0..10 {
            let odo = Pose2::new(0.05 * k as f64, 0.0, 0.0);
            let d = det.process(&corridor_scan(k as f64 * 0.1), odo).unwrap();
            if k == 0 {
                assert_eq!(d.fallback, None);
                continue;
            }
            assert_eq!(d.fallback, Some(PoseFallback::Degenerate), "scan {k}");
            assert!(d.icp.is_none());
            assert!((d.pose.x - odo.x).abs() < 1e-12, "{:?}", d.pose);
        }
        // In the room, ICP is trusted: no fallback after the first scan.
        let mut det = MovingObjectDetector::new(MovingDetectorConfig::default()).unwrap();
        for k in 0..5 {
            let d = det
                .process(&room_scan(k as f64 * 0.1, None), Pose2::new(0.0, 0.0, 0.0))
                .unwrap();
            assert_eq!(d.fallback, None, "scan {k}");
            assert_eq!(d.icp.is_some(), k > 0);
        }
        // Too few returns: the prediction, and the reason.
        let mut sparse = room_scan(0.5, None);
        for r in sparse.ranges.iter_mut().skip(40) {
            *r = f32::INFINITY;
        }
        let d = det.process(&sparse, Pose2::new(0.0, 0.0, 0.0)).unwrap();
        assert_eq!(d.fallback, Some(PoseFallback::TooFewPoints));
    }

    #[test]
    fn deterministic() {
        let run = || {
            let mut det = MovingObjectDetector::new(MovingDetectorConfig::default()).unwrap();
            (0..15)
                .map(|k| {
                    let s = room_scan(k as f64 * 0.125, Some([2.0 + 0.1 * k as f64, 1.0]));
                    det.process(&s, Pose2::new(0.0, 0.0, 0.0)).unwrap()
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(run(), run());
    }

    #[test]
    fn bad_input_is_an_error() {
        let mut det = MovingObjectDetector::new(MovingDetectorConfig::default()).unwrap();
        assert!(det
            .process(&room_scan(0.0, None), Pose2::new(f64::NAN, 0.0, 0.0))
            .is_err());
        let bad = MovingDetectorConfig {
            cluster_gap: -1.0,
            ..MovingDetectorConfig::default()
        };
        assert!(MovingObjectDetector::new(bad).is_err());
    }
}
