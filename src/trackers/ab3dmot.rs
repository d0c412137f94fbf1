//! AB3DMOT (Weng et al., "3D Multi-Object Tracking: A Baseline and New Evaluation Metrics",
//! IROS 2020): oriented 3-D boxes tracked by one linear Kalman filter each and associated to
//! the frame's detections by the Hungarian method, as a baseline for the LMB filter on the same
//! detections.
//!
//! The recipe, as in the authors' KITTI code:
//!
//! * **State** `[x, y, z, θ, l, w, h, ẋ, ẏ, ż]`: box centre, heading about z, length, width,
//!   height and the centre's velocity in metres per *frame*; constant velocity
//!   (`x ← x + ẋ`, everything else kept). The measurement is the first seven components.
//! * **Covariances** (filterpy's defaults scaled as the authors do): initial
//!   `P₀ = diag(10·I₇, 10⁴·I₃)` (a single box says nothing about the velocity), process noise
//!   `Q = diag(I₇, 0.01·I₃)`, measurement noise `R = I₇`, all in metres, radians and metres per
//!   frame ([`KalmanNoise::AB3DMOT`]). The update is in Joseph form.
//! * **Association** per class: the Hungarian method ([`crate::assignment::solve`]) over every
//!   pair of a detection and a predicted track of the same class, on −IoU₃D (or −IoU in bird's
//!   eye view, or the bird's-eye centre distance: [`Affinity`]), then pairs below the threshold
//!   (IoU₃D 0.01 by default, the authors' value for KITTI) are split again, as in the
//!   authors' code. Tracks of different classes never compete, which is what one tracker per
//!   class does, with ids unique over all classes.
//! * **Orientation correction**: a measured heading more than 90° from the track's is turned
//!   by π before the update (a box with heading θ + π is the same box), and the innovation is
//!   taken the short way round, so the state heading never jumps; it is kept in (−π, π]. The
//!   authors' code turns the *state* by π instead, which makes the track follow a detector's
//!   flipped box; turning the measurement keeps the heading the track had.
//! * **Life cycle**: an unmatched detection starts a track (one hit). A track is reported
//!   from its `min_hits`-th hit on (3), including the frames it is then coasted through, and
//!   dies after `max_age` frames in a row without a detection (2: a track missed once is
//!   reported with its predicted box and kept, missed twice it is dropped). The authors also
//!   report every track during the first `min_hits` frames of a sequence; that is
//!   [`Ab3dmotConfig::report_first_frames`], off by default.
//!
//! A step is one frame: frames without detections are steps with an empty slice. The
//! velocity is reported in metres per second with [`Ab3dmotConfig::frame_period`]. The result
//! is deterministic (tracks in id order, classes in name order).
//!
//! Not for: the LMB filter (see [`crate::filter`]), running a whole drive (see
//! `crate::pipeline::box_baseline`) or writing KITTI results (see
//! `crate::pipeline::kitti_results`).

use crate::assignment;
use crate::error::{ensure_finite, ensure_positive, Error, Result};
use crate::geometry::box3::{iou_3d, iou_bev, Box3};
use crate::geometry::wrap_angle;
use nalgebra::{Point3, SMatrix, SVector};
use std::collections::{BTreeMap, BTreeSet};
use std::f64::consts::{FRAC_PI_2, PI};

type State = SVector<f64, 10>;
type StateCov = SMatrix<f64, 10, 10>;
type Meas = SVector<f64, 7>;

/// How a detection and a predicted track are compared, and when they may be paired.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Affinity {
    /// 3-D intersection over union of the oriented boxes, pairs kept from `min_iou` on.
    Iou3d {
        /// Smallest IoU of a kept pair.
        min_iou: f64,
    },
    /// Bird's-eye-view IoU of the oriented footprints, pairs kept from `min_iou` on.
    IouBev {
        /// Smallest IoU of a kept pair.
        min_iou: f64,
    },
    /// Distance of the box centres in bird's eye view (x, y), pairs kept up to
    /// `max_distance` metres: for detections whose extent is poor (clusters of a few points)
    /// while their position is good.
    CentreDistanceBev {
        /// Largest distance of a kept pair (m).
        max_distance: f64,
    },
}

impl Affinity {
    /// The authors' KITTI association: 3-D IoU of at least 0.01.
    pub const AB3DMOT: Affinity = Affinity::Iou3d { min_iou: 0.01 };

    fn validate(&self) -> Result<()> {
        match *self {
            Affinity::Iou3d { min_iou } | Affinity::IouBev { min_iou } => {
                if !(min_iou > 0.0 && min_iou <= 1.0) {
                    return Err(Error::invalid(
                        "AB3DMOT min_iou",
                        format!("{min_iou} (must lie in (0, 1])"),
                    ));
                }
                Ok(())
            }
            Affinity::CentreDistanceBev { max_distance } => {
                ensure_positive("AB3DMOT max_distance", max_distance)
            }
        }
    }

    /// The cost the Hungarian method minimises (finite for finite boxes) and whether the pair
    /// may be kept.
    fn cost(&self, det: &Box3, trk: &Box3) -> (f64, bool) {
        match *self {
            Affinity::Iou3d { min_iou } => iou_cost(iou_3d(det, trk), min_iou),
            Affinity::IouBev { min_iou } => iou_cost(iou_bev(det, trk), min_iou),
            Affinity::CentreDistanceBev { max_distance } => {
                let d = (det.center.x - trk.center.x).hypot(det.center.y - trk.center.y);
                if d.is_finite() {
                    (d, d <= max_distance)
                } else {
                    (f64::MAX / 1e6, false)
                }
            }
        }
    }
}

fn iou_cost(iou: f64, min_iou: f64) -> (f64, bool) {
    if iou.is_finite() {
        (-iou, iou >= min_iou)
    } else {
        (0.0, false)
    }
}

/// The Kalman filter's covariances, in metres, radians and metres per frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KalmanNoise {
    /// Initial variance of centre, heading and size.
    pub initial_box: f64,
    /// Initial variance of each velocity component.
    pub initial_velocity: f64,
    /// Process variance per frame of centre, heading and size.
    pub process_box: f64,
    /// Process variance per frame of each velocity component.
    pub process_velocity: f64,
    /// Measurement variance of every box component.
    pub measurement: f64,
}

impl KalmanNoise {
    /// The authors' values: P₀ = diag(10·I₇, 10⁴·I₃), Q = diag(I₇, 0.01·I₃), R = I₇.
    pub const AB3DMOT: KalmanNoise = KalmanNoise {
        initial_box: 10.0,
        initial_velocity: 10_000.0,
        process_box: 1.0,
        process_velocity: 0.01,
        measurement: 1.0,
    };

    fn validate(&self) -> Result<()> {
        ensure_positive("AB3DMOT initial_box", self.initial_box)?;
        ensure_positive("AB3DMOT initial_velocity", self.initial_velocity)?;
        ensure_positive("AB3DMOT process_box", self.process_box)?;
        ensure_positive("AB3DMOT process_velocity", self.process_velocity)?;
        ensure_positive("AB3DMOT measurement", self.measurement)
    }
}

impl Default for KalmanNoise {
    fn default() -> Self {
        KalmanNoise::AB3DMOT
    }
}

/// Settings of [`Ab3dmot`]; the default is the authors' KITTI setting.
#[derive(Clone, Debug, PartialEq)]
pub struct Ab3dmotConfig {
    /// Association of every class without an entry in `class_affinity` (3-D IoU ≥ 0.01).
    pub affinity: Affinity,
    /// Association of particular classes, by class name.
    pub class_affinity: BTreeMap<String, Affinity>,
    /// Hits from which a track is reported (3).
    pub min_hits: u32,
    /// Frames in a row without a detection after which a track dies (2).
    pub max_age: u32,
    /// Time between frames (s), only to report velocities in m/s (0.1, KITTI's 10 Hz).
    pub frame_period: f64,
    /// Whether every track is reported during the first `min_hits` frames, hits or not, as the
    /// authors' code does (false).
    pub report_first_frames: bool,
    /// The Kalman filter's covariances.
    pub noise: KalmanNoise,
}

impl Default for Ab3dmotConfig {
    fn default() -> Self {
        Ab3dmotConfig {
            affinity: Affinity::AB3DMOT,
            class_affinity: BTreeMap::new(),
            min_hits: 3,
            max_age: 2,
            frame_period: 0.1,
            report_first_frames: false,
            noise: KalmanNoise::AB3DMOT,
        }
    }
}

impl Ab3dmotConfig {
    /// Checks every setting; errors name the one at fault.
    pub fn validate(&self) -> Result<()> {
        self.affinity.validate()?;
        for a in self.class_affinity.values() {
            a.validate()?;
        }
        if self.min_hits == 0 {
            return Err(Error::invalid("AB3DMOT min_hits", "0 (must be at least 1)"));
        }
        if self.max_age == 0 {
            return Err(Error::invalid("AB3DMOT max_age", "0 (must be at least 1)"));
        }
        ensure_positive("AB3DMOT frame_period", self.frame_period)?;
        self.noise.validate()
    }

    fn affinity_of(&self, class: &str) -> Affinity {
        self.class_affinity
            .get(class)
            .copied()
            .unwrap_or(self.affinity)
    }
}

/// One detection: an oriented box, its class and its score.
#[derive(Clone, Debug, PartialEq)]
pub struct BoxDetection {
    /// The box (any frame, the same for every step of a run).
    pub bbox: Box3,
    /// Class name; only detections and tracks of the same class are associated.
    pub class: String,
    /// Detector score, reported with the track it updates.
    pub score: f64,
}

impl BoxDetection {
    /// A detection.
    pub fn new(bbox: Box3, class: impl Into<String>, score: f64) -> Self {
        BoxDetection {
            bbox,
            class: class.into(),
            score,
        }
    }

    fn validate(&self, i: usize) -> Result<()> {
        let b = &self.bbox;
        let what = format!("AB3DMOT detection {i}");
        ensure_finite(
            &what,
            &[b.center.x, b.center.y, b.center.z, b.yaw, self.score],
        )?;
        if !b.size.iter().all(|s| s.is_finite() && *s > 0.0) {
            return Err(Error::invalid(
                what,
                format!("box size {:?} (must be finite and positive)", b.size),
            ));
        }
        Ok(())
    }
}

/// A reported track in one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackedBox {
    /// Track id, unique over the run (from 0, in order of birth).
    pub id: u64,
    /// The filtered box (the predicted box when the track was not detected this frame).
    pub bbox: Box3,
    /// Class name.
    pub class: String,
    /// Score of the last detection that updated the track.
    pub score: f64,
    /// Velocity of the box centre (m/s).
    pub velocity: [f64; 3],
    /// Detections that updated the track so far, its first included.
    pub hits: u32,
    /// Whether a detection updated the track in this frame.
    pub detected: bool,
}

#[derive(Clone, Debug)]
struct Track {
    id: u64,
    class: String,
    x: State,
    p: StateCov,
    score: f64,
    hits: u32,
    since_update: u32,
}

impl Track {
    fn new(id: u64, det: &BoxDetection, noise: &KalmanNoise) -> Track {
        let m = measurement(&det.bbox);
        let mut x = State::zeros();
        x.fixed_rows_mut::<7>(0).copy_from(&m);
        x[3] = wrap_angle(x[3]);
        let mut p = StateCov::zeros();
        for i in 0..10 {
            p[(i, i)] = if i < 7 {
                noise.initial_box
            } else {
                noise.initial_velocity
            };
        }
        Track {
            id,
            class: det.class.clone(),
            x,
            p,
            score: det.score,
            hits: 1,
            since_update: 0,
        }
    }

    /// x ← F x, P ← F P Fᵀ + Q with F the constant-velocity transition of one frame.
    fn predict(&mut self, noise: &KalmanNoise) {
        let f = transition();
        self.x = f * self.x;
        self.x[3] = wrap_angle(self.x[3]);
        self.p = f * self.p * f.transpose();
        for i in 0..10 {
            self.p[(i, i)] += if i < 7 {
                noise.process_box
            } else {
                noise.process_velocity
            };
        }
        self.since_update += 1;
    }

    fn update(&mut self, det: &BoxDetection, noise: &KalmanNoise) -> Result<()> {
        let mut z = measurement(&det.bbox);
        z[3] = corrected_heading(self.x[3], z[3]);
        // H picks the first seven components: S = P₇₇ + R, K = P[:, :7] S⁻¹.
        let mut s = self.p.fixed_view::<7, 7>(0, 0).into_owned();
        for i in 0..7 {
            s[(i, i)] += noise.measurement;
        }
        let s_inv = s.cholesky().map(|c| c.inverse()).ok_or_else(|| {
            Error::invalid(
                format!("AB3DMOT track {}", self.id),
                "innovation covariance is not positive definite",
            )
        })?;
        let k = self.p.fixed_view::<10, 7>(0, 0) * s_inv;
        let innovation = z - self.x.fixed_rows::<7>(0);
        self.x += k * innovation;
        self.x[3] = wrap_angle(self.x[3]);
        // Joseph form: (I − KH) P (I − KH)ᵀ + K R Kᵀ.
        let mut i_kh = StateCov::identity();
        let mut top = i_kh.fixed_view_mut::<10, 7>(0, 0);
        top -= &k;
        self.p = i_kh * self.p * i_kh.transpose() + k * k.transpose() * noise.measurement;
        self.score = det.score;
        self.hits += 1;
        self.since_update = 0;
        Ok(())
    }

    fn bbox(&self) -> Box3 {
        Box3 {
            center: Point3::new(self.x[0], self.x[1], self.x[2]),
            size: [self.x[4], self.x[5], self.x[6]],
            yaw: self.x[3],
        }
    }

    fn report(&self, frame_period: f64) -> TrackedBox {
        TrackedBox {
            id: self.id,
            bbox: self.bbox(),
            class: self.class.clone(),
            score: self.score,
            velocity: [
                self.x[7] / frame_period,
                self.x[8] / frame_period,
                self.x[9] / frame_period,
            ],
            hits: self.hits,
            detected: self.since_update == 0,
        }
    }
}

fn transition() -> StateCov {
    let mut f = StateCov::identity();
    for i in 0..3 {
        f[(i, 7 + i)] = 1.0;
    }
    f
}

fn measurement(b: &Box3) -> Meas {
    Meas::from([
        b.center.x, b.center.y, b.center.z, b.yaw, b.size[0], b.size[1], b.size[2],
    ])
}

/// The measured heading as the update uses it: turned by π when it is more than 90° from the
/// track's, then moved by a multiple of 2π to within π of the track's heading.
pub fn corrected_heading(track: f64, measured: f64) -> f64 {
    let mut d = wrap_angle(measured - track);
    if d.abs() > FRAC_PI_2 {
        d = wrap_angle(d + PI);
    }
    track + d
}

/// The AB3DMOT tracker; see the module notes.
#[derive(Clone, Debug)]
pub struct Ab3dmot {
    config: Ab3dmotConfig,
    tracks: Vec<Track>,
    next_id: u64,
    frames: u64,
}

impl Ab3dmot {
    /// A tracker with no tracks; errors on an invalid setting.
    pub fn new(config: Ab3dmotConfig) -> Result<Ab3dmot> {
        config.validate()?;
        Ok(Ab3dmot {
            config,
            tracks: Vec::new(),
            next_id: 0,
            frames: 0,
        })
    }

    /// The settings.
    pub fn config(&self) -> &Ab3dmotConfig {
        &self.config
    }

    /// Tracks alive, reported or not.
    pub fn live_tracks(&self) -> usize {
        self.tracks.len()
    }

    /// One frame: predicts every track, associates `detections`, updates, starts tracks from
    /// the unmatched detections, drops the dead, and returns the reported tracks in id order.
    /// A detection with a non-finite value or a size that is not positive is an error naming
    /// it, and the tracker is left as it was.
    pub fn step(&mut self, detections: &[BoxDetection]) -> Result<Vec<TrackedBox>> {
        for (i, d) in detections.iter().enumerate() {
            d.validate(i)?;
        }
        self.frames += 1;
        let noise = self.config.noise;
        for t in &mut self.tracks {
            t.predict(&noise);
        }
        let matches = self.associate(detections)?;
        let mut matched_det = vec![false; detections.len()];
        for &(d, t) in &matches {
            self.tracks[t].update(&detections[d], &noise)?;
            matched_det[d] = true;
        }
        for (d, det) in detections.iter().enumerate() {
            if !matched_det[d] {
                self.tracks.push(Track::new(self.next_id, det, &noise));
                self.next_id += 1;
            }
        }
        let max_age = self.config.max_age;
        self.tracks.retain(|t| t.since_update < max_age);
        let early = self.config.report_first_frames && self.frames <= self.config.min_hits as u64;
        Ok(self
            .tracks
            .iter()
            .filter(|t| early || t.hits >= self.config.min_hits)
            .map(|t| t.report(self.config.frame_period))
            .collect())
    }

    /// Pairs (detection, track) of the same class, per class by the Hungarian method over
    /// every pair, keeping the pairs the class's [`Affinity`] accepts.
    fn associate(&self, detections: &[BoxDetection]) -> Result<Vec<(usize, usize)>> {
        let classes: BTreeSet<&str> = detections.iter().map(|d| d.class.as_str()).collect();
        let mut matches = Vec::new();
        for class in classes {
            let dets: Vec<usize> = (0..detections.len())
                .filter(|&i| detections[i].class == class)
                .collect();
            let trks: Vec<usize> = (0..self.tracks.len())
                .filter(|&j| self.tracks[j].class == class)
                .collect();
            if trks.is_empty() {
                continue;
            }
            let affinity = self.config.affinity_of(class);
            let boxes: Vec<Box3> = trks.iter().map(|&j| self.tracks[j].bbox()).collect();
            let (n, m) = (dets.len(), trks.len());
            let mut cost = vec![0.0; n * m];
            let mut keep = vec![false; n * m];
            for (a, &i) in dets.iter().enumerate() {
                for (b, tb) in boxes.iter().enumerate() {
                    let (c, k) = affinity.cost(&detections[i].bbox, tb);
                    cost[a * m + b] = c;
                    keep[a * m + b] = k;
                }
            }
            // The solver wants rows ≤ columns: rows are the smaller side.
            let pairs: Vec<(usize, usize)> = if n <= m {
                solve(&cost, n, m, class)?.into_iter().enumerate().collect()
            } else {
                let mut t = vec![0.0; n * m];
                for a in 0..n {
                    for b in 0..m {
                        t[b * n + a] = cost[a * m + b];
                    }
                }
                solve(&t, m, n, class)?
                    .into_iter()
                    .enumerate()
                    .map(|(b, a)| (a, b))
                    .collect()
            };
            matches.extend(
                pairs
                    .into_iter()
                    .filter(|&(a, b)| keep[a * m + b])
                    .map(|(a, b)| (dets[a], trks[b])),
            );
        }
        matches.sort_unstable();
        Ok(matches)
    }
}

fn solve(cost: &[f64], rows: usize, cols: usize, class: &str) -> Result<Vec<usize>> {
    assignment::solve(cost, rows, cols)
        .map(|(cols, _)| cols)
        .ok_or_else(|| {
            Error::invalid(
                format!("AB3DMOT association of class {class}"),
                "the assignment has no solution (non-finite costs)",
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn car(x: f64, y: f64, yaw: f64) -> BoxDetection {
        BoxDetection::new(
            Box3 {
                center: Point3::new(x, y, -0.8),
                size: [4.0, 1.8, 1.5],
                yaw,
            },
            "Car",
            0.9,
        )
    }

    #[test]
    fn heading_correction_by_hand() {
        // Within 90°: kept, moved next to the track's heading.
        assert!((corrected_heading(0.1, 0.3) - 0.3).abs() < 1e-12);
        assert!((corrected_heading(3.0, -3.0) - (2.0 * PI - 3.0)).abs() < 1e-12);
        // 180° off: turned back onto the track's heading.
        assert!((corrected_heading(0.2, 0.2 - PI) - 0.2).abs() < 1e-12);
        // 100° off: turned by π, 80° the other way.
        let d = 100f64.to_radians();
        assert!((corrected_heading(0.0, d) - (d - PI)).abs() < 1e-12);
        assert!((corrected_heading(-3.0, 3.1 - PI) - (3.1 - 2.0 * PI)).abs() < 1e-12);
    }

    #[test]
    fn kalman_first_update_by_hand() {
        // Scalar check of one position component: after birth P = [[10, 0], [0, 1e4]] (pos,
        // vel); predict: P = [[10 + 1e4 + 1, 1e4], [1e4, 1e4 + 0.01]], x = (0, 0). Measuring
        // z = 1: S = 10012, K = (10011, 10000)/10012, velocity = 10000/10012.
        let noise = KalmanNoise::AB3DMOT;
        let mut t = Track::new(0, &car(0.0, 0.0, 0.0), &noise);
        t.predict(&noise);
        assert!((t.p[(0, 0)] - 10011.0).abs() < 1e-9);
        t.update(&car(1.0, 0.0, 0.0), &noise).unwrap();
        assert!((t.x[0] - 10011.0 / 10012.0).abs() < 1e-12);
        assert!((t.x[7] - 10000.0 / 10012.0).abs() < 1e-12);
        // Posterior variance of x: P₀₀ − K₀² S = 10011 − 10011²/10012.
        let want = 10011.0 - 10011.0f64.powi(2) / 10012.0;
        assert!((t.p[(0, 0)] - want).abs() < 1e-9, "{}", t.p[(0, 0)]);
    }

    #[test]
    fn invalid_settings_and_detections_are_errors() {
        let bad = Ab3dmotConfig {
            min_hits: 0,
            ..Ab3dmotConfig::default()
        };
        assert!(Ab3dmot::new(bad).is_err());
        let bad = Ab3dmotConfig {
            affinity: Affinity::Iou3d { min_iou: f64::NAN },
            ..Ab3dmotConfig::default()
        };
        assert!(Ab3dmot::new(bad).is_err());
        let mut trk = Ab3dmot::new(Ab3dmotConfig::default()).unwrap();
        trk.step(&[car(0.0, 0.0, 0.0)]).unwrap();
        let mut nan = car(f64::NAN, 0.0, 0.0);
        let msg = trk.step(&[car(1.0, 0.0, 0.0), nan.clone()]).unwrap_err();
        assert!(msg.to_string().contains("detection 1"), "{msg}");
        nan.bbox.center.x = 0.0;
        nan.bbox.size[1] = 0.0;
        assert!(trk.step(&[nan]).is_err());
        // Untouched by the failed steps: one track, one hit.
        assert_eq!(trk.live_tracks(), 1);
        assert!(trk.step(&[]).unwrap().is_empty());
    }
}
