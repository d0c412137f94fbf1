//! People in a planar scan found by their legs: segments of returns described by the
//! geometric features of Arras, Mozos & Burgard (ICRA 2007, [`super::features`]), classed
//! leg or not by a boosted classifier ([`super::boost`]) trained on annotated recordings,
//! and legs paired into people.
//!
//! 1. **Segments** ([`leg_segments`]): consecutive returns (in beam order, across "no
//!    return" beams) closer than [`LegDetectorConfig::cluster_distance`] (0.13 m, as the ROS
//!    `leg_tracker`) are one segment; segments with fewer than `min_points` returns, wider
//!    than `max_width` or farther than `max_range` are dropped. Once the scanner has moved
//!    [`CARRIED_MOTION`] (or turned [`CARRIED_TURN`]) over the last [`MOTION_LAG`], a segment
//!    whose returns kept their ranges beam for beam (within [`FIXED_RANGE`], [`FIXED_SHARE`]
//!    of them) is carried along with the scanner — a part of the robot, a cable — and is
//!    dropped too: the right laser of the empty-room recording sees such a thing 0.6 m away
//!    for 40 s, and a model that had not seen that laser took it for a person walking
//!    beside the robot.
//! 2. **Features** ([`LegCandidate::features`], [`NUM_LEG_FEATURES`]): the thirteen shape features of
//!    [`super::features`] without the speed (number of points, standard deviation, mean
//!    deviation from the median, jump distances to the neighbouring segments, width,
//!    linearity, circularity, radius, boundary length and regularity, mean curvature, mean
//!    angular difference), then the range of the centroid and the occlusion of each end
//!    (neighbour end range minus own end range, clipped to ±2 m; +2 m with no neighbour),
//!    and the motion. The two jumps and the two occlusions are given as the smaller and the
//!    larger of the pair, not by side: the order of the beams (a scanner turning one way or
//!    the other, mounted upright or upside down) says nothing about legs, and a classifier
//!    that must learn that from a few recordings generalises worse (held-out F1 0.768 →
//!    0.823, `docs/people_real.md`). Then the scan is aligned onto the previous scan by ICP ([`super::icp`]
//!    with [`LEG_ICP`]: the scanner's own motion, no odometry needed) and the motion is the
//!    mean distance from the segment's aligned returns to the nearest return of the previous
//!    scan, capped at 1 m (−1 on the first scan or when the alignment fails). Walls and furniture stay
//!    put; a walking person's legs do not. Between two scans a leg in its stance phase does
//!    not move either, so the last feature looks [`MOTION_LAG`] seconds back (0.6 s: five
//!    scans at 7.5 Hz), when a walking person stood elsewhere: the share of the segment's
//!    returns whose place that scan saw through (placed there by the chained alignments, the
//!    three beams around its bearing all reached [`SEEN_THROUGH_MARGIN`] farther), among
//!    those it saw at all (not hidden behind something nearer); −1 when it saw none. A place
//!    newly in view because the scanner moved was hidden or out of view then, not free, so a
//!    moving scanner does not make its room move.
//! 3. **Legs**: a segment whose boosted score exceeds [`LegDetectorConfig::leg_score`].
//! 4. **People** ([`pair_legs`]): legs closer than `pair_distance` are paired, closest pairs
//!    first, into a person at their mean; a leg left alone is a person only when its score
//!    exceeds `single_leg_score` (the other leg hidden behind it). Each person carries its
//!    score (a pair's two leg scores added). For a tracker that weighs people by their score,
//!    [`LegDetector::people_for_tracking`] also pairs the candidates down to the lower
//!    `tracking_leg_score`: legs the classifier doubts still feed the tracks there are.
//!
//! The shipped model ([`LegModel::shipped`], `leg_model.json` beside this file) is trained
//! by `cargo run --release --example train_legs` on the annotated recordings of
//! `../shared/data/laser2d/leg_annotated` (see `docs/people_real.md`).
//!
//! Not for: tracking people over scans, or scans in which legs are not visible (a laser at
//! torso height).

use super::boost::Boosted;
use super::features::{segment_features, SegmentContext};
use super::icp::{Icp, IcpConfig};
use super::scan::Scan;
use crate::error::{Error, Result};
use crate::geometry::pose2::{compose, identity, inverse, transform_point};
use crate::geometry::Pose2;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// Number of features of a leg candidate.
pub const NUM_LEG_FEATURES: usize = 18;

/// Feature names, in the order of [`LegCandidate::features`].
pub const LEG_FEATURE_NAMES: [&str; NUM_LEG_FEATURES] = [
    "points",
    "std_dev",
    "mad_median",
    "jump_smaller",
    "jump_larger",
    "width",
    "linearity",
    "circularity",
    "radius",
    "boundary_length",
    "boundary_regularity",
    "mean_curvature",
    "mean_angular_difference",
    "range",
    "occlusion_smaller",
    "occlusion_larger",
    "motion",
    "seen_through",
];

/// Settings of the detector (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LegDetectorConfig {
    /// Consecutive returns closer than this are one segment (m).
    pub cluster_distance: f64,
    /// Fewest returns of a leg candidate.
    pub min_points: usize,
    /// Widest leg candidate (m).
    pub max_width: f64,
    /// Farthest leg candidate (m).
    pub max_range: f64,
    /// A candidate is a leg when its score exceeds this.
    pub leg_score: f64,
    /// A leg without a partner is a person when its score exceeds this.
    pub single_leg_score: f64,
    /// Legs closer than this are one person (m).
    pub pair_distance: f64,
    /// For a tracker that weighs its measurements by their score
    /// ([`LegDetector::people_for_tracking`]): candidates scoring above this are legs, paired
    /// the same way, and a lone one is a person too. Default −0.08, below `leg_score`: a
    /// tracked person whose legs the classifier doubts for a few scans still gets its
    /// measurements, and the low scores keep such candidates from confirming tracks of their
    /// own. Models written before this setting existed read the default.
    #[serde(default = "default_tracking_leg_score")]
    pub tracking_leg_score: f64,
}

fn default_tracking_leg_score() -> f64 {
    -0.08
}

impl Default for LegDetectorConfig {
    fn default() -> Self {
        LegDetectorConfig {
            cluster_distance: 0.13,
            min_points: 3,
            max_width: 0.8,
            max_range: 8.0,
            leg_score: 0.0,
            single_leg_score: 0.025,
            pair_distance: 0.6,
            tracking_leg_score: default_tracking_leg_score(),
        }
    }
}

/// One leg candidate.
#[derive(Clone, Debug, PartialEq)]
pub struct LegCandidate {
    /// First and one-past-last beam.
    pub beams: (usize, usize),
    /// Centroid of its returns, sensor frame (m).
    pub centroid: [f64; 2],
    /// Its features.
    pub features: [f64; NUM_LEG_FEATURES],
}

/// The leg candidates of `scan` (steps 1 and 2 of the module documentation); `motion` gives
/// the two motion features of a segment's returns ([`LegDetector::candidates`] measures them
/// against the previous scan and the scan [`MOTION_LAG`] earlier).
pub fn leg_segments(
    scan: &Scan,
    config: &LegDetectorConfig,
    motion: &dyn Fn(&[[f64; 2]]) -> [f64; 2],
) -> Result<Vec<LegCandidate>> {
    // Every segment, filtered or not, so that jumps and occlusions see all neighbours.
    let mut segs: Vec<Vec<(usize, [f64; 2])>> = Vec::new();
    let mut last: Option<[f64; 2]> = None;
    for (i, p) in scan.points() {
        let near = last.is_some_and(|q| (p[0] - q[0]).hypot(p[1] - q[1]) < config.cluster_distance);
        if near {
            segs.last_mut().expect("a segment").push((i, p));
        } else {
            segs.push(vec![(i, p)]);
        }
        last = Some(p);
    }
    let norm = |p: [f64; 2]| p[0].hypot(p[1]);
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let mut out = Vec::new();
    let mut pts: Vec<[f64; 2]> = Vec::new();
    for (k, s) in segs.iter().enumerate() {
        if s.len() < config.min_points {
            continue;
        }
        let (first, lastp) = (s[0].1, s[s.len() - 1].1);
        if dist(first, lastp) > config.max_width {
            continue;
        }
        pts.clear();
        pts.extend(s.iter().map(|x| x.1));
        let n = pts.len() as f64;
        let c = pts
            .iter()
            .fold([0.0, 0.0], |a, p| [a[0] + p[0] / n, a[1] + p[1] / n]);
        let range = norm(c);
        if range > config.max_range {
            continue;
        }
        let prev = k.checked_sub(1).map(|j| segs[j][segs[j].len() - 1].1);
        let next = segs.get(k + 1).map(|s| s[0].1);
        let jump = |q: Option<[f64; 2]>, own: [f64; 2]| q.map_or(5.0, |q| dist(q, own).min(5.0));
        let occl = |q: Option<[f64; 2]>, own: [f64; 2]| {
            q.map_or(2.0, |q| (norm(q) - norm(own)).clamp(-2.0, 2.0))
        };
        let ctx = SegmentContext {
            jump_prev: jump(prev, first),
            jump_next: jump(next, lastp),
            speed: 0.0,
        };
        let f = segment_features(&pts, &ctx).map_err(|e| {
            Error::invalid(
                format!("scan at {} s, beam {}", scan.time, s[0].0),
                e.to_string(),
            )
        })?;
        let mut features = [0.0; NUM_LEG_FEATURES];
        features[..13].copy_from_slice(&f[..13]);
        // Side-free: the smaller and the larger of each pair (see the module documentation).
        let (j0, j1) = (features[3], features[4]);
        [features[3], features[4]] = [j0.min(j1), j0.max(j1)];
        let (o0, o1) = (occl(prev, first), occl(next, lastp));
        features[13] = range;
        [features[14], features[15]] = [o0.min(o1), o0.max(o1)];
        [features[16], features[17]] = motion(&pts);
        out.push(LegCandidate {
            beams: (s[0].0, s[s.len() - 1].0 + 1),
            centroid: c,
            features,
        });
    }
    Ok(out)
}

/// The classifier and the settings it was trained with.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LegModel {
    /// What the model is and how it was made.
    pub description: String,
    /// Feature names, in order.
    pub features: Vec<String>,
    /// The segmentation (and decision) settings the model was trained with.
    pub config: LegDetectorConfig,
    /// The boosted stumps.
    pub classifier: Boosted,
}

impl LegModel {
    /// The model shipped with the library (`src/laser2d/leg_model.json`).
    pub fn shipped() -> Result<LegModel> {
        LegModel::from_json(include_str!("leg_model.json"))
    }

    /// Parses a model and checks it against this build's features.
    pub fn from_json(text: &str) -> Result<LegModel> {
        let m: LegModel =
            serde_json::from_str(text).map_err(|e| Error::invalid("leg model", e.to_string()))?;
        if m.features != LEG_FEATURE_NAMES {
            return Err(Error::invalid(
                "leg model",
                format!(
                    "features {:?} differ from {:?}",
                    m.features, LEG_FEATURE_NAMES
                ),
            ));
        }
        if m.classifier
            .stumps
            .iter()
            .any(|s| s.feature >= NUM_LEG_FEATURES)
        {
            return Err(Error::invalid("leg model", "a stump names no feature"));
        }
        Ok(m)
    }

    /// Writes the model as pretty JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("serialisable")
    }
}

/// A leg found in a scan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Leg {
    /// Centroid, sensor frame (m).
    pub position: [f64; 2],
    /// Classifier score in `[−1, 1]`.
    pub score: f64,
}

/// A person found by their legs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LegPerson {
    /// Position (m, sensor frame): the mean of a pair's legs, or the lone leg's position.
    pub position: [f64; 2],
    /// The classifier's evidence: the sum of a pair's two leg scores, or the lone leg's
    /// score (in `(−2, 2]`; a pair of clear legs scores higher than one).
    pub score: f64,
    /// Number of legs seen: 2 for a pair, 1 for a lone leg.
    pub legs: usize,
}

/// One scan's people twice: as the detector reports them, and down to the lower score of
/// [`LegDetectorConfig::tracking_leg_score`] for a tracker that weighs them by their scores.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LegPeople {
    /// The detector's people ([`pair_legs_scored`] with `leg_score` and `single_leg_score`).
    pub reported: Vec<LegPerson>,
    /// The people of every candidate scoring above `tracking_leg_score`, paired the same way.
    pub for_tracking: Vec<LegPerson>,
}

/// Legs paired into people (step 4 of the module documentation): positions in the sensor
/// frame.
pub fn pair_legs(legs: &[Leg], config: &LegDetectorConfig) -> Vec<[f64; 2]> {
    pair_legs_scored(legs, config)
        .into_iter()
        .map(|p| p.position)
        .collect()
}

/// [`pair_legs`] with each person's score ([`LegPerson::score`]).
pub fn pair_legs_scored(legs: &[Leg], config: &LegDetectorConfig) -> Vec<LegPerson> {
    let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
    for i in 0..legs.len() {
        for j in i + 1..legs.len() {
            let (a, b) = (legs[i].position, legs[j].position);
            let d = (a[0] - b[0]).hypot(a[1] - b[1]);
            if d < config.pair_distance {
                pairs.push((d, i, j));
            }
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut used = vec![false; legs.len()];
    let mut people = Vec::new();
    for (_, i, j) in pairs {
        if used[i] || used[j] {
            continue;
        }
        used[i] = true;
        used[j] = true;
        let (a, b) = (legs[i].position, legs[j].position);
        people.push(LegPerson {
            position: [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])],
            score: legs[i].score + legs[j].score,
            legs: 2,
        });
    }
    for (l, u) in legs.iter().zip(&used) {
        if !u && l.score > config.single_leg_score {
            people.push(LegPerson {
                position: l.position,
                score: l.score,
                legs: 1,
            });
        }
    }
    people
}

/// The detector: a model, the settings it runs with, and the previous scan for the motion
/// feature. Hand it the scans of one scanner in order.
#[derive(Debug)]
pub struct LegDetector {
    model: LegModel,
    /// The settings (initially the model's).
    pub config: LegDetectorConfig,
    icp: Icp,
    previous: Vec<[f64; 2]>,
    current: Vec<[f64; 2]>,
    source: Vec<[f64; 2]>,
    pose: Pose2,
    /// The last alignment's motion, the next alignment's first guess.
    step: Pose2,
    /// The recent scans with their poses in the first scan's frame, oldest first: the
    /// lagged motion's reference.
    recent: VecDeque<(Pose2, Scan)>,
}

/// Motion feature when it cannot be measured.
pub const UNKNOWN_MOTION: f64 = -1.0;

/// The scan-to-scan alignment of the detector. A motion cue needs centimetres, not the
/// default's hundredth of a millimetre: it aligns every [`ICP_STRIDE`]th return, stops
/// after 12 iterations or once a step moves less than 0.1 mm and turns less than 0.1 mrad,
/// and starts from the previous scan's motion (a scanner moves on much as it moved). On
/// `negative_2.bag` (`/right_scan`, a moving scanner) the alignments run 6.6 times as fast as
/// with the default settings from the identity (3,600 against 550 per second; 11.6 against
/// 31.1 iterations) and differ from them by about 1 mm and 0.5 mrad.
pub const LEG_ICP: IcpConfig = IcpConfig {
    max_iterations: 12,
    max_pair_distance: 1.0,
    residual_factor: 3.0,
    min_gate: 0.1,
    tolerance_translation: 1e-4,
    tolerance_rotation: 1e-4,
    min_pairs: 10,
};

/// The alignment uses every this many'th return of a scan as its source (all returns as
/// its target).
pub const ICP_STRIDE: usize = 3;

/// The seen-through feature looks back to the latest scan at least this much older (s).
pub const MOTION_LAG: f64 = 0.6;

/// A place counts as seen through when the earlier scan's beams reached this much beyond it
/// (m).
pub const SEEN_THROUGH_MARGIN: f64 = 0.15;

/// The scanner counts as moved over [`MOTION_LAG`] from this far (m) ...
pub const CARRIED_MOTION: f64 = 0.2;
/// ... or this much turned (rad).
pub const CARRIED_TURN: f64 = 0.2;
/// A return kept its place in the scanner's frame within this range difference (m) ...
pub const FIXED_RANGE: f64 = 0.03;
/// ... and a candidate when this share of its returns did.
pub const FIXED_SHARE: f64 = 0.8;

/// Scans kept for the seen-through feature at most (a fast scanner keeps [`MOTION_LAG`] of
/// them only as far as this goes).
const MAX_RECENT_SCANS: usize = 64;

/// Share of `places` (in the frame of the scan `then`) that `then` saw through: the three
/// beams nearest the place's bearing all reached [`SEEN_THROUGH_MARGIN`] beyond it (a "no
/// return" beam reaches everywhere), among the places it saw at all (a place hidden behind a
/// nearer return, or outside its field of view, does not count); [`UNKNOWN_MOTION`] when it
/// saw none.
fn seen_through(then: &Scan, places: impl Iterator<Item = [f64; 2]>) -> f64 {
    let reach = |i: usize| then.range(i).unwrap_or(f64::INFINITY);
    let (mut free, mut seen) = (0usize, 0usize);
    for q in places {
        let d = q[0].hypot(q[1]);
        let Some(j) = then.beam_of(q).filter(|&j| j >= 1 && j + 1 < then.len()) else {
            continue;
        };
        let (a, b, c) = (reach(j - 1), reach(j), reach(j + 1));
        if a.min(b).min(c) > d + SEEN_THROUGH_MARGIN {
            free += 1;
            seen += 1;
        } else if a.max(b).max(c) > d - SEEN_THROUGH_MARGIN {
            seen += 1;
        }
    }
    if seen == 0 {
        UNKNOWN_MOTION
    } else {
        free as f64 / seen as f64
    }
}

/// Whether the scanner moved by at least [`CARRIED_MOTION`] m or [`CARRIED_TURN`] rad
/// between two scans (`to_then`: the later scan's frame into the earlier one's).
fn carried_along(to_then: Pose2) -> bool {
    to_then.x.hypot(to_then.y) >= CARRIED_MOTION || to_then.theta.abs() >= CARRIED_TURN
}

/// Whether the returns of `beams` in `now` have the ranges of the same beams in `then`
/// (within [`FIXED_RANGE`], at least [`FIXED_SHARE`] of them): a thing that kept its place in
/// the scanner's frame.
fn fixed_to_scanner(now: &Scan, then: &Scan, beams: (usize, usize)) -> bool {
    let (mut same, mut all) = (0usize, 0usize);
    for i in beams.0..beams.1 {
        if let Some(r) = now.range(i) {
            all += 1;
            if then.range(i).is_some_and(|q| (q - r).abs() <= FIXED_RANGE) {
                same += 1;
            }
        }
    }
    all > 0 && same as f64 >= FIXED_SHARE * all as f64
}

impl LegDetector {
    /// A detector running `model` with its own settings.
    pub fn new(model: LegModel) -> Result<Self> {
        let config = model.config;
        Ok(LegDetector {
            model,
            config,
            icp: Icp::new(LEG_ICP)?,
            previous: Vec::new(),
            current: Vec::new(),
            source: Vec::new(),
            pose: identity(),
            step: identity(),
            recent: VecDeque::new(),
        })
    }

    /// The shipped model's detector.
    pub fn shipped() -> Result<Self> {
        LegDetector::new(LegModel::shipped()?)
    }

    /// The leg candidates of the next scan, with the motion features measured against the
    /// scan before it and against the scan [`MOTION_LAG`] earlier.
    pub fn candidates(&mut self, scan: &Scan) -> Result<Vec<LegCandidate>> {
        self.current.clear();
        self.current.extend(scan.points().map(|(_, p)| p));
        self.source.clear();
        self.source
            .extend(self.current.iter().step_by(ICP_STRIDE).copied());
        let fit = if self.previous.len() >= 10 && self.source.len() >= 10 {
            self.icp.set_target(&self.previous)?;
            self.icp.align(&self.source, self.step).ok()
        } else {
            None
        };
        if let Some(f) = fit {
            self.step = f.transform;
        }
        // A failed alignment counts as standing still.
        let pose = fit.map_or(self.pose, |f| compose(self.pose, f.transform));
        while self.recent.len() > 1 && self.recent[1].1.time <= scan.time - MOTION_LAG {
            self.recent.pop_front();
        }
        let lagged = self
            .recent
            .front()
            .filter(|(_, s)| s.time <= scan.time - MOTION_LAG)
            .map(|(p, s)| (compose(inverse(*p), pose), s));
        let icp = &self.icp;
        let motion = |pts: &[[f64; 2]]| {
            let last = fit.map_or(UNKNOWN_MOTION, |f| {
                pts.iter()
                    .map(|&p| {
                        icp.nearest_target_distance(transform_point(f.transform, p))
                            .map_or(1.0, |d| d.min(1.0))
                    })
                    .sum::<f64>()
                    / pts.len() as f64
            });
            let through = lagged.map_or(UNKNOWN_MOTION, |(to_then, then)| {
                seen_through(then, pts.iter().map(|&p| transform_point(to_then, p)))
            });
            [last, through]
        };
        let mut out = leg_segments(scan, &self.config, &motion)?;
        if let Some((to_then, then)) = lagged {
            if carried_along(to_then) {
                out.retain(|c| !fixed_to_scanner(scan, then, c.beams));
            }
        }
        self.pose = pose;
        if self.recent.len() == MAX_RECENT_SCANS {
            self.recent.pop_front();
        }
        self.recent.push_back((pose, scan.clone()));
        std::mem::swap(&mut self.previous, &mut self.current);
        Ok(out)
    }

    /// The scanner's pose in the frame of the first scan, chained from the scan-to-scan
    /// alignments (a failed alignment counts as standing still): odometry for a scanner
    /// that has none.
    pub fn pose(&self) -> Pose2 {
        self.pose
    }

    /// The model's score of a candidate.
    pub fn score(&self, candidate: &LegCandidate) -> f64 {
        self.model.classifier.score(&candidate.features)
    }

    /// The legs of the next scan.
    pub fn legs(&mut self, scan: &Scan) -> Result<Vec<Leg>> {
        self.scored_candidates(scan, self.config.leg_score)
    }

    /// Every candidate of the next scan scoring above `floor`, as a leg with its score.
    fn scored_candidates(&mut self, scan: &Scan, floor: f64) -> Result<Vec<Leg>> {
        let c = self.candidates(scan)?;
        Ok(c.iter()
            .map(|c| Leg {
                position: c.centroid,
                score: self.score(c),
            })
            .filter(|l| l.score > floor)
            .collect())
    }

    /// The people of the next scan, sensor frame.
    pub fn people(&mut self, scan: &Scan) -> Result<Vec<[f64; 2]>> {
        let legs = self.legs(scan)?;
        Ok(pair_legs(&legs, &self.config))
    }

    /// The people of the next scan as reported and for a tracker ([`LegPeople`]).
    pub fn people_for_tracking(&mut self, scan: &Scan) -> Result<LegPeople> {
        let (floor, leg_score) = (self.config.tracking_leg_score, self.config.leg_score);
        let scored = self.scored_candidates(scan, floor.min(leg_score))?;
        let strong: Vec<Leg> = scored
            .iter()
            .copied()
            .filter(|l| l.score > leg_score)
            .collect();
        let weak: Vec<Leg> = scored.into_iter().filter(|l| l.score > floor).collect();
        let tracking = LegDetectorConfig {
            leg_score: floor,
            single_leg_score: floor,
            ..self.config
        };
        Ok(LegPeople {
            reported: pair_legs_scored(&strong, &self.config),
            for_tracking: pair_legs_scored(&weak, &tracking),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scan of a wall at 4 m with two leg-sized discs in front of it at 2 m.
    fn scan_with_legs() -> Scan {
        let n = 401;
        let (a0, inc) = (-0.7f64, 0.0035f64);
        let mut ranges = vec![4.0f32; n];
        for (i, r) in ranges.iter_mut().enumerate() {
            let b = a0 + inc * i as f64;
            for cy in [0.0, 0.25] {
                // Ray from the origin against a disc of radius 0.06 at (2, cy).
                let (dx, dy) = (b.cos(), b.sin());
                let t = 2.0 * dx + cy * dy;
                let d2 = 4.0 + cy * cy - t * t;
                if d2 < 0.06 * 0.06 {
                    let hit = t - (0.06f64 * 0.06 - d2).sqrt();
                    *r = r.min(hit as f32);
                }
            }
        }
        Scan::new(0.0, a0, inc, ranges, 0.0, 30.0).unwrap()
    }

    #[test]
    fn leg_sized_discs_are_candidates_with_their_features() {
        let s = scan_with_legs();
        let c = leg_segments(&s, &LegDetectorConfig::default(), &|_| [0.5, 0.25]).unwrap();
        let near: Vec<_> = c.iter().filter(|c| c.features[13] < 3.0).collect();
        assert_eq!(near.len(), 2, "{c:?}");
        for l in near {
            assert!(l.features[0] >= 3.0);
            assert!(l.features[5] < 0.13, "width {}", l.features[5]);
            // The wall lies 2 m behind on both sides.
            assert!(l.features[14] > 1.5 && l.features[15] > 1.5);
            assert!(
                l.features[8] > 0.02 && l.features[8] < 0.2,
                "radius {}",
                l.features[8]
            );
            assert_eq!(l.features[16], 0.5);
            assert_eq!(l.features[17], 0.25);
        }
        // The wall itself is far wider than max_width: split into pieces or dropped.
        assert!(c.iter().all(|c| c.features[5] <= 0.8));
    }

    /// A model whose score is `near` for candidates nearer than 3 m and −1 beyond: two
    /// stumps on the range feature, the first voting +1 below 3 m, the second −1 always.
    fn range_model(near: f64) -> LegModel {
        let stump = |threshold: f64, polarity: f64, alpha: f64| crate::laser2d::boost::Stump {
            feature: 13,
            threshold,
            polarity,
            alpha,
        };
        // (a − b) / (a + b) = near with a + b = 2
        let (a, b) = (1.0 + near, 1.0 - near);
        LegModel {
            description: "test".into(),
            features: LEG_FEATURE_NAMES.iter().map(|s| s.to_string()).collect(),
            config: LegDetectorConfig::default(),
            classifier: Boosted {
                stumps: vec![stump(3.0, -1.0, a), stump(100.0, 1.0, b)],
            },
        }
    }

    /// A model written before `tracking_leg_score` existed reads its default.
    #[test]
    fn older_models_read_the_default_tracking_score() {
        let json = range_model(0.1).to_json();
        let old = json.replace(",\n    \"tracking_leg_score\": -0.08", "");
        assert_ne!(old, json);
        let m = LegModel::from_json(&old).unwrap();
        assert_eq!(m.config.tracking_leg_score, -0.08);
    }

    /// Legs the classifier doubts (score between `tracking_leg_score` and `leg_score`) are not
    /// reported but are handed to a tracker, paired, with their summed score; legs it
    /// believes are both; the wall behind is neither.
    #[test]
    fn doubted_legs_go_to_the_tracker_only() {
        let s = scan_with_legs();
        let mut doubted = LegDetector::new(range_model(-0.05)).unwrap();
        let p = doubted.people_for_tracking(&s).unwrap();
        assert!(p.reported.is_empty(), "{p:?}");
        assert_eq!(p.for_tracking.len(), 1, "{p:?}");
        let person = p.for_tracking[0];
        assert_eq!(person.legs, 2);
        assert!((person.score + 0.1).abs() < 1e-9, "{person:?}");
        assert!((person.position[0] - 1.95).abs() < 0.05, "{person:?}");
        assert!((person.position[1] - 0.125).abs() < 0.02, "{person:?}");

        let mut believed = LegDetector::new(range_model(0.05)).unwrap();
        let p = believed.people_for_tracking(&s).unwrap();
        assert_eq!(p.reported.len(), 1, "{p:?}");
        assert_eq!(p.reported, p.for_tracking);
        assert!((p.reported[0].score - 0.1).abs() < 1e-9);
        // The same scan through `people`: the reported people.
        let mut again = LegDetector::new(range_model(0.05)).unwrap();
        assert_eq!(again.people(&s).unwrap(), vec![p.reported[0].position]);

        let mut rejected = LegDetector::new(range_model(-0.5)).unwrap();
        let p = rejected.people_for_tracking(&s).unwrap();
        assert!(p.reported.is_empty() && p.for_tracking.is_empty(), "{p:?}");
    }

    #[test]
    fn legs_pair_into_people_and_lone_legs_need_a_high_score() {
        let cfg = LegDetectorConfig::default();
        let leg = |x: f64, y: f64, score: f64| Leg {
            position: [x, y],
            score,
        };
        let people = pair_legs(
            &[
                leg(2.0, 0.0, 0.1),
                leg(2.0, 0.3, 0.1),
                leg(4.0, 0.0, 0.1),
                leg(5.0, 0.0, 0.5),
            ],
            &LegDetectorConfig {
                single_leg_score: 0.3,
                ..cfg
            },
        );
        assert_eq!(people.len(), 2);
        assert!((people[0][1] - 0.15).abs() < 1e-12);
        assert_eq!(people[1], [5.0, 0.0]);
        // Three legs in a row: the closest two pair, the third stands alone.
        let p = pair_legs(
            &[leg(1.0, 0.0, 0.9), leg(1.0, 0.2, 0.9), leg(1.0, 0.5, 0.9)],
            &cfg,
        );
        assert_eq!(p.len(), 2);
        assert!((p[0][1] - 0.1).abs() < 1e-12);
        // Scores: a pair adds its legs' scores, a lone leg keeps its own.
        let scored = pair_legs_scored(
            &[leg(1.0, 0.0, 0.2), leg(1.0, 0.2, 0.3), leg(1.0, 0.5, 0.4)],
            &cfg,
        );
        assert_eq!(scored.len(), 2);
        assert!((scored[0].score - 0.5).abs() < 1e-12 && scored[0].legs == 2);
        assert_eq!((scored[1].score, scored[1].legs), (0.4, 1));
        assert_eq!(scored[1].position, [1.0, 0.5]);
    }

    #[test]
    fn motion_is_unknown_first_and_small_for_a_still_scene() {
        let s = scan_with_legs();
        let mut d = LegDetector::shipped().unwrap();
        let first = d.candidates(&s).unwrap();
        assert!(first.iter().all(|c| c.features[16] == UNKNOWN_MOTION));
        let again = d.candidates(&s).unwrap();
        assert!(
            again.iter().all(|c| (0.0..0.01).contains(&c.features[16])),
            "{again:?}"
        );
    }

    #[test]
    fn features_do_not_depend_on_the_direction_of_the_beams() {
        // The same scene mirrored (beams in the opposite order): the same candidates, each
        // with the same features (the jumps and occlusions of its two sides swap places).
        let s = scan_with_legs();
        let n = s.len();
        let mut ranges = s.ranges.clone();
        ranges.reverse();
        let mirrored = Scan::new(
            s.time,
            -(s.angle_min + s.angle_increment * (n - 1) as f64),
            s.angle_increment,
            ranges,
            s.range_min,
            s.range_max,
        )
        .unwrap();
        let cfg = LegDetectorConfig::default();
        let a = leg_segments(&s, &cfg, &|_| [0.0, 0.0]).unwrap();
        let mut b = leg_segments(&mirrored, &cfg, &|_| [0.0, 0.0]).unwrap();
        b.reverse();
        assert_eq!(a.len(), b.len());
        assert!(a.len() >= 2);
        for (x, y) in a.iter().zip(&b) {
            assert!((x.centroid[1] + y.centroid[1]).abs() < 1e-9);
            for (k, (u, v)) in x.features.iter().zip(&y.features).enumerate() {
                assert!((u - v).abs() < 1e-9, "feature {k}: {u} against {v}");
            }
        }
    }

    #[test]
    fn a_thing_carried_along_by_the_scanner_is_no_candidate_once_the_scanner_has_moved() {
        // The scanner drives 5 cm a scan (0.375 m/s) through a room with a post at (3, 0.6)
        // and a leg-sized disc fixed to the scanner at (1, −0.8) in its own frame: after
        // MOTION_LAG (0.6 s, 0.23 m driven) the disc is dropped, the post is kept.
        let scan_from = |k: usize| {
            let x = 0.05 * k as f64;
            room_scan(k as f64 / 7.5, x, &[[3.0 - x, 0.6], [1.0, -0.8]])
        };
        let near = |c: &[LegCandidate], p: [f64; 2]| {
            c.iter()
                .any(|c| (c.centroid[0] - p[0]).hypot(c.centroid[1] - p[1]) < 0.2)
        };
        let mut d = LegDetector::shipped().unwrap();
        for k in 0..12 {
            let c = d.candidates(&scan_from(k)).unwrap();
            let x = 0.05 * k as f64;
            assert!(near(&c, [3.0 - x, 0.6]), "scan {k}: the post");
            // Carried along: kept until there is a scan MOTION_LAG back (scan 5 sees scan 0,
            // 0.25 m behind).
            assert_eq!(near(&c, [1.0, -0.8]), k < 5, "scan {k}: the carried disc");
        }
        // A still scanner keeps everything that stays put.
        let mut still = LegDetector::shipped().unwrap();
        for _ in 0..8 {
            assert!(near(&still.candidates(&scan_from(0)).unwrap(), [1.0, -0.8]));
        }
    }

    /// A scan of a straight wall at x = 4 m, 201 beams over ±0.5 rad, with "no return" on
    /// the beams of bearings above 0.3 rad.
    fn wall_then() -> Scan {
        let (a0, inc) = (-0.5f64, 0.005f64);
        let ranges = (0..201)
            .map(|i| {
                let b = a0 + inc * i as f64;
                if b > 0.3 {
                    f32::INFINITY
                } else {
                    (4.0 / b.cos()) as f32
                }
            })
            .collect();
        Scan::new(0.0, a0, inc, ranges, 0.0, 30.0).unwrap()
    }

    #[test]
    fn seen_through_counts_free_places_among_those_seen() {
        let then = wall_then();
        // Free in front of the wall, on the wall itself, and behind it (hidden).
        let (free, on, behind) = ([2.0, 0.0], [4.0, 0.1], [6.0, -0.2]);
        assert_eq!(seen_through(&then, [free, free].into_iter()), 1.0);
        assert_eq!(seen_through(&then, [on].into_iter()), 0.0);
        assert_eq!(seen_through(&then, [free, on, behind].into_iter()), 0.5);
        // Within the margin of the wall: seen, not free.
        assert_eq!(seen_through(&then, [[3.9, 0.0]].into_iter()), 0.0);
        // Where the beams returned nothing the scanner saw through everything.
        assert_eq!(seen_through(&then, [[10.0, 5.0]].into_iter()), 1.0);
        // Only hidden places, or places outside the field of view: unknown.
        assert_eq!(seen_through(&then, [behind].into_iter()), UNKNOWN_MOTION);
        assert_eq!(
            seen_through(&then, [[-1.0, 0.0]].into_iter()),
            UNKNOWN_MOTION
        );
        assert_eq!(seen_through(&then, std::iter::empty()), UNKNOWN_MOTION);
    }

    #[test]
    fn a_walking_leg_is_seen_through_and_a_still_post_is_not() {
        // A still scanner in a room, a post at (3, 0.6) and a leg-sized disc at x = 2 m that
        // walks across the line of sight: once the detector has a scan MOTION_LAG old,
        // the disc stands where that scan saw the wall behind (free), the post where it saw
        // the post.
        let scan_at = |t: f64, y: f64| room_scan(t, 0.0, &[[2.0, y], [3.0, 0.6]]);
        let mut d = LegDetector::shipped().unwrap();
        let mut last = Vec::new();
        for k in 0..8 {
            // 1 m/s, 7.5 scans a second.
            let t = k as f64 / 7.5;
            last = d.candidates(&scan_at(t, -0.8 + t)).unwrap();
            if t < MOTION_LAG {
                assert!(last.iter().all(|c| c.features[17] == UNKNOWN_MOTION));
            }
        }
        let near = |x: f64| {
            last.iter()
                .find(|c| (c.centroid[0] - x).abs() < 0.2)
                .expect("a candidate")
                .features[17]
        };
        assert_eq!(near(2.0), 1.0, "{last:?}");
        assert_eq!(near(3.0), 0.0, "{last:?}");
    }

    #[test]
    fn a_still_post_is_not_seen_through_by_a_moving_scanner() {
        // The scanner drives 5 cm a scan through a room (walls at x = 4 m, y = ±2.5 m) with a
        // post at (3, 0.6): only the chained alignments place the post where the earlier scan
        // saw it (0.3 m nearer to the scanner then, which would look free).
        let scan_from = |k: usize| {
            let x = 0.05 * k as f64;
            room_scan(k as f64 / 7.5, x, &[[3.0 - x, 0.6]])
        };
        let mut d = LegDetector::shipped().unwrap();
        let mut last = Vec::new();
        for k in 0..10 {
            last = d.candidates(&scan_from(k)).unwrap();
        }
        let post = last
            .iter()
            .find(|c| (c.centroid[0] - 2.55).abs() < 0.2 && (c.centroid[1] - 0.6).abs() < 0.2)
            .expect("the post is a candidate");
        assert_eq!(post.features[17], 0.0, "{post:?}");
    }

    /// A scan at time `t` from (`x`, 0) facing +x in a room with walls at x = 4 m and
    /// y = ±2.5 m, with leg-sized discs (radius 6 cm) centred at `discs` in the scanner's
    /// frame.
    fn room_scan(t: f64, x: f64, discs: &[[f64; 2]]) -> Scan {
        let (a0, inc) = (-1.2f64, 0.006f64);
        let ranges = (0..401)
            .map(|i| {
                let b = a0 + inc * i as f64;
                let (dx, dy) = (b.cos(), b.sin());
                let mut r = (4.0 - x) / dx;
                if dy.abs() > 1e-9 {
                    r = r.min(2.5 / dy.abs());
                }
                for &[cx, cy] in discs {
                    let tc = cx * dx + cy * dy;
                    let d2 = cx * cx + cy * cy - tc * tc;
                    if d2 < 0.06 * 0.06 {
                        r = r.min(tc - (0.06 * 0.06 - d2).sqrt());
                    }
                }
                r as f32
            })
            .collect();
        Scan::new(t, a0, inc, ranges, 0.0, 30.0).unwrap()
    }

    fn room_from(x: f64) -> Scan {
        room_scan(0.0, x, &[])
    }

    #[test]
    fn the_chained_alignments_follow_a_scanner_driving_through_a_room() {
        // 5 cm forward per scan: after 12 scans the scanner stands 0.55 m from where it
        // started, with the walls the only thing to align on. Point-to-point alignment of
        // sampled walls falls short by about a millimetre per scan (1.2 cm here).
        let mut d = LegDetector::shipped().unwrap();
        for k in 0..12 {
            d.candidates(&room_from(0.05 * k as f64)).unwrap();
        }
        let p = d.pose();
        assert!(
            (p.x - 0.55).abs() < 0.02 && p.y.abs() < 0.005 && p.theta.abs() < 0.002,
            "{p:?}"
        );
    }

    #[test]
    fn the_shipped_model_loads_and_a_wrong_one_is_refused() {
        let m = LegModel::shipped().unwrap();
        assert!(!m.classifier.stumps.is_empty());
        let mut other = m.clone();
        other.features.pop();
        assert!(LegModel::from_json(&other.to_json()).is_err());
        assert!(LegModel::from_json("{").is_err());
    }
}
