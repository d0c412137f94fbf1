//! The people trackers' front end: turns one scan into the range-bearing measurements of the
//! people's centres that every tracker (the LMB and the baselines) is handed.
//!
//! * [`FrontEnd::Segments`]: every person-sized group of returns ([`crate::laser2d::person_groups()`]),
//!   whatever it belongs to. Right in an open space; in a room every piece of wall, pillar or
//!   furniture of person size becomes a "person".
//! * [`FrontEnd::Moving`]: the same person groups, kept only when the moving-object detector
//!   ([`crate::laser2d::moving`]) marks at least [`PersonFrontEnd::min_moving_share`] of a group's
//!   returns as belonging to a moving target. The detector decides which returns are moving
//!   (by default [`MovingRule::Attenuation`] with the Fuzzy ART veto off: returns the
//!   propagated background and the static local map do not explain, in clusters of at least
//!   three); the person grouping decides what is one person and where its centre is, exactly
//!   as for `Segments`, so the two front ends differ only in which groups they keep.
//! * [`FrontEnd::Legs`]: people found by their legs ([`crate::laser2d::legs`]): segments
//!   classed as legs by the shipped boosted classifier, paired into people. Made for real
//!   scans of a laser at leg height; the simulated scenarios draw people as discs and keep
//!   the other two. Without a moving-object detector the corrected pose is the leg
//!   detector's chain of scan-to-scan alignments ([`LegDetector::pose`]), so that a scanner
//!   without odometry still sees walls and furniture stand still. Besides its people it
//!   hands a tracker that weighs evidence ([`FrontEndOutput::weighed`]) the legs the
//!   classifier doubts too, each person with its leg score.
//!
//! The detector also refines the odometry by ICP against its local map; the corrected robot
//! pose is returned with the measurements ([`FrontEndOutput::corrected_pose`]) whenever a
//! detector runs, so that a caller can hand it to the trackers instead of the odometry.
//! Measurements are in the sensor frame and do not depend on the pose the tracker is given.
//!
//! Not for: tracking, scoring, or deciding what is moving (the detector and its rule do).

use super::models::Detectability;
use super::tracker::{person_grouping, PeopleTrackerConfig};
use crate::config::MeasurementConfig;
use crate::error::{Error, Result};
use crate::filter::Measurements;
use crate::geometry::pose2::{between, compose};
use crate::geometry::Pose2;
use crate::laser2d::legs::{LegDetector, LegModel, LegPerson};
use crate::laser2d::moving::{
    ClusterStage, MovingDetections, MovingDetectorConfig, MovingObjectDetector,
};
use crate::laser2d::moving_rule::MovingRule;
use crate::laser2d::person_groups::{person_groups, PersonGroup};
use crate::laser2d::Scan;
use serde::Serialize;

/// Which returns become person measurements.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FrontEnd {
    /// Every person-sized group of returns.
    #[default]
    Segments,
    /// Person-sized groups the moving-object detector marks as moving.
    Moving,
    /// Legs found by the leg classifier, paired into people.
    Legs,
}

impl FrontEnd {
    /// `segments`, `moving` or `legs`.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "segments" => Ok(FrontEnd::Segments),
            "moving" => Ok(FrontEnd::Moving),
            "legs" => Ok(FrontEnd::Legs),
            other => Err(Error::invalid(
                "front end",
                format!("`{other}` (expected segments, moving or legs)"),
            )),
        }
    }

    /// The name [`FrontEnd::parse`] reads.
    pub fn name(&self) -> &'static str {
        match self {
            FrontEnd::Segments => "segments",
            FrontEnd::Moving => "moving",
            FrontEnd::Legs => "legs",
        }
    }
}

/// One scan's measurements and what the detector found.
#[derive(Clone, Debug)]
pub struct FrontEndOutput {
    /// Range-bearing rows `[range, bearing]` of the people's centres (sensor frame).
    pub measurements: Measurements,
    /// The detector's ICP-corrected robot pose, when a detector runs.
    pub corrected_pose: Option<Pose2>,
    /// The detector's output, when a detector runs.
    pub detections: Option<MovingDetections>,
    /// For a tracker that weighs each measurement by the classifier's evidence (the LMB
    /// people tracker, [`super::tracker::PeopleTracker::step_measured_with_evidence`]): more
    /// and weaker measurements than `measurements`, each with its evidence. The legs front end
    /// gives its people down to [`crate::laser2d::legs::LegDetectorConfig::tracking_leg_score`]
    /// with their scores ([`crate::laser2d::legs::LegPerson::score`]); the others give none.
    pub weighed: Option<WeighedMeasurements>,
}

/// Measurements with the evidence that each is a person (see [`FrontEndOutput::weighed`]).
#[derive(Clone, Debug)]
pub struct WeighedMeasurements {
    /// Range-bearing rows `[range, bearing]` (sensor frame).
    pub measurements: Measurements,
    /// One evidence value per measurement.
    pub evidence: Vec<f64>,
}

/// The front end; see the module documentation.
#[derive(Debug)]
pub struct PersonFrontEnd {
    kind: FrontEnd,
    people: PeopleTrackerConfig,
    detector: Option<MovingObjectDetector>,
    legs: Option<LegDetector>,
    /// A person group is moving when at least this share of its returns lies on beams of
    /// moving clusters. Default 0.5.
    pub min_moving_share: f64,
    /// Which of the detector's returns count as moving. Default
    /// [`MovingEvidence::MovingClusters`].
    pub evidence: MovingEvidence,
    moving_beams: Vec<bool>,
    /// Without odometry: the stand-in odometry handed to the detector last time, the
    /// detector's corrected pose then, and the motion between its last two corrected poses.
    dead_reckoning: Option<DeadReckoning>,
}

/// Without odometry, the farthest the detector's ICP may move a scan from the
/// constant-velocity guess (m): a robot at walking pace changing speed by 1 m/s within a
/// 5 Hz log's scan interval moves 0.2 m from it; five times that leaves room for rougher
/// starts and stops.
pub const NO_ODOMETRY_MAX_CORRECTION: f64 = 1.0;
/// ... and the farthest it may turn it (rad, 20°: a turn rate changing by 100°/s between
/// two scans of a 5 Hz log).
pub const NO_ODOMETRY_MAX_CORRECTION_ANGLE: f64 = 0.35;

/// Constant-velocity stand-in for odometry when a recording has none: the next scan is
/// predicted to move as much as the last two corrected poses did, and the detector's ICP
/// corrects from there (a turning robot stays registered where a standing-still guess would
/// have to recover the whole turn each scan).
#[derive(Clone, Copy, Debug)]
struct DeadReckoning {
    odometry: Pose2,
    corrected: Pose2,
    step: Pose2,
}

/// Which returns of the detector's output the moving front end counts as moving.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MovingEvidence {
    /// Returns of the clusters the detector's rule marks as moving.
    #[default]
    MovingClusters,
    /// Every candidate return (foreground, off the static map), whatever its cluster: the
    /// rule's size test and vote are skipped.
    Candidates,
}

/// The sensor's mounting offset on the robot, from the tracker's measurement model.
pub fn sensor_mount(people: &PeopleTrackerConfig) -> [f64; 2] {
    match people.filter.measurement {
        Some(MeasurementConfig::RangeBearing { offset, .. }) => offset,
        _ => [0.0, 0.0],
    }
}

/// The detector settings the front end uses by default for a tracker configured as `people`
/// on a scanner with beam spacing `angle_increment`: the scanner defaults
/// ([`MovingDetectorConfig::for_scanner`]) with [`MovingRule::Attenuation`], veto off.
pub fn default_detector_config(
    people: &PeopleTrackerConfig,
    angle_increment: f64,
) -> MovingDetectorConfig {
    MovingDetectorConfig {
        rule: MovingRule::Attenuation { veto: false },
        ..MovingDetectorConfig::for_scanner(
            people.beam_sigma_bearing,
            angle_increment,
            sensor_mount(people),
        )
    }
}

/// Detection probability a tracker behind the moving front end should assume for a person in
/// view when it treats misses as independent (the JPDA-IMM baseline does): the front end hands
/// over 69 % (lobby) to 81 % (scenario one) of the visible people within 0.5 m (seeds 1–3).
pub const MOVING_DETECTION_PROBABILITY: f64 = 0.7;

/// The front end's misses come in runs (a person is lost for several scans while they slow
/// down or turn, or where the background has not settled): in the lobby (seeds 1–6, odometry
/// pose) a person reported in one scan is missed in the next with probability 0.08, one
/// missed is reported in the next with probability 0.33 only. A two-state chain fitted to
/// those sequences by maximum likelihood — detectable with p_D [`MOVING_DETECTABLE_PROBABILITY`],
/// undetectable with p_D 0 — loses detectability with probability 0.06 per scan and regains
/// it with 0.15 (log-likelihood −956 against −1,377 for independent misses at p_D 0.7; its
/// long-run p_D, 0.95 · 0.15 / 0.21 = 0.68, is the same 0.7).
pub const MOVING_DETECTABILITY: Detectability = Detectability {
    lose: 0.06,
    regain: 0.15,
    undetectable_share: 0.01,
};

/// p_D of a detectable person behind the moving front end ([`MOVING_DETECTABILITY`]).
pub const MOVING_DETECTABLE_PROBABILITY: f64 = 0.95;

/// Expected detections before a track behind the moving front end is reported: the front end
/// also flags static structure as moving for a few scans at a time (a pillar after the robot
/// turned), and with runs of misses modelled such a track lives long enough to be reported
/// unless confirmation asks for more than a few detections. Lobby over seeds 1–8 with 0, 3, 4,
/// 5, 6, 8: OSPA(2) 1.35, 1.30, 1.25, 1.25, 1.25, 1.27; OSPA 0.72, 0.79, 0.82, 0.86, 0.88,
/// 0.95 (each detection asked for delays every report by about a scan).
pub const MOVING_CONFIRM_DETECTIONS: f64 = 5.0;

/// False measurements per scan a tracker behind the moving front end should assume: measured
/// 0.08 (scenario one) and 0.12 (lobby) per scan, rounded up for recordings.
pub const MOVING_CLUTTER_RATE: f64 = 0.3;

/// p_D the tracker assumes behind [`FrontEnd::Legs`], whose tracker gets every person down to
/// the leg model's `tracking_leg_score` (−0.08) with their scores ([`WeighedMeasurements`];
/// the doubted ones, score ≤ 0, only near a likely track and starting none,
/// [`PeopleTrackerConfig::doubted_gate`]). Chosen with [`LEGS_CONFIRM_EVIDENCE`] and that
/// floor on the pooled leave-one-bag-out folds of the annotated `leg_tracker` bags (the
/// held-out positive bags and the held-out lasers of `negative_2.bag`, tracker seeds 1–12
/// pooled, since one seed moves the tracker's F1 by ±0.04; tracker F1 / false people per
/// empty-room scan, without the gate), floor −0.08 and evidence 0.6: p_D 0.7 0.776 / 0.012,
/// 0.8 0.801 / 0.000, 0.9 0.782 / 0.002 (not swept again with the seen-through feature). See
/// `docs/people_real.md`.
pub const LEGS_DETECTION_PROBABILITY: f64 = 0.8;

/// Evidence a track behind [`FrontEnd::Legs`] must collect before it is reported
/// ([`PeopleTrackerConfig::confirm_evidence`]: the sum of the association probability times
/// the person's leg score, [`crate::laser2d::legs::LegPerson::score`]; legs the classifier
/// doubts score below 0 and count against it). Chosen on the leave-one-bag-out folds of
/// `examples/train_legs.rs` (tracker F1 / false people per empty-room scan, seeds 1–12
/// pooled, floor −0.08, p_D 0.8, the 0.5 m gate and [`LEGS_PRUNE_THRESHOLD`]) with the
/// classifier of today (side-free jumps and occlusions, the seen-through feature, things
/// carried along dropped): **0.5 0.826 / 0.006** (0.794–0.855 per four seeds), 0.6 0.811 /
/// 0.002. With the seen-through feature alone: 0.4 0.827 / 0.013 (0.050 on one held-out
/// laser), 0.5 0.826 / 0.006, 0.6 0.811 / 0.000. Before it the classifier's scores took 0.6
/// (0.799 / 0.000). Reporting people only (no doubted
/// legs) with p_D 0.7 and 8 expected detections, as at first, gave 0.646 / 0.017.
pub const LEGS_CONFIRM_EVIDENCE: f64 = 0.5;

/// Existence below which a track behind [`FrontEnd::Legs`] is dropped (the filter's default
/// is 0.001). The front end hands over many weak candidates in cluttered rooms, each starting
/// a faint track; dropping them at 1 % halves the tracks kept in the empty rooms. On the same
/// folds (seeds 1–12, F1 / false people per empty-room scan): 0.001 0.794 / 0.001, 0.005
/// 0.801 / 0.002, 0.01 0.799 / 0.000, 0.02 0.776 / 0.001, 0.03 0.786 / 0.002; with 0.01 the
/// empty rooms' slowest laser runs 1.5 times as fast as with 0.001 (1,819 against 1,210
/// scans/s back to back on a loaded machine).
pub const LEGS_PRUNE_THRESHOLD: f64 = 0.01;

/// Adapts the LMB people tracker to the front end `kind`: behind [`FrontEnd::Moving`] misses
/// come in runs ([`MOVING_DETECTABILITY`], p_D [`MOVING_DETECTABLE_PROBABILITY`] while
/// detectable), tracks are confirmed after [`MOVING_CONFIRM_DETECTIONS`] and the clutter rate
/// is [`MOVING_CLUTTER_RATE`]; behind [`FrontEnd::Legs`] p_D is [`LEGS_DETECTION_PROBABILITY`]
/// and tracks are confirmed on the leg classifier's evidence ([`LEGS_CONFIRM_EVIDENCE`], no
/// count of detections) and pruned below [`LEGS_PRUNE_THRESHOLD`]; the segment front end
/// keeps the tracker's own settings.
pub fn adapt_tracker_config(people: &mut PeopleTrackerConfig, kind: FrontEnd) {
    if kind == FrontEnd::Legs {
        if let Some(crate::config::DetectionConfig::FieldOfView { p_inside, .. }) =
            &mut people.filter.detection
        {
            *p_inside = LEGS_DETECTION_PROBABILITY;
        }
        people.confirm_detections = 0.0;
        people.confirm_evidence = LEGS_CONFIRM_EVIDENCE;
        people.filter.filter.prune_threshold = LEGS_PRUNE_THRESHOLD;
        return;
    }
    if kind != FrontEnd::Moving {
        return;
    }
    if let Some(crate::config::DetectionConfig::FieldOfView { p_inside, .. }) =
        &mut people.filter.detection
    {
        *p_inside = MOVING_DETECTABLE_PROBABILITY;
    }
    people.detectability = Some(MOVING_DETECTABILITY);
    people.confirm_detections = MOVING_CONFIRM_DETECTIONS;
    if let Some(c) = &mut people.filter.clutter {
        c.rate = MOVING_CLUTTER_RATE;
    }
}

impl PersonFrontEnd {
    /// A front end grouping returns as `people` says. A detector runs when `detector` is
    /// given (with [`FrontEnd::Segments`] it only corrects the pose); [`FrontEnd::Moving`]
    /// needs one; [`FrontEnd::Legs`] runs the shipped leg model ([`LegDetector::shipped`]).
    pub fn new(
        kind: FrontEnd,
        people: &PeopleTrackerConfig,
        detector: Option<MovingDetectorConfig>,
    ) -> Result<Self> {
        if kind == FrontEnd::Moving && detector.is_none() {
            return Err(Error::invalid(
                "front end",
                "the moving front end needs a moving-object detector configuration",
            ));
        }
        Ok(PersonFrontEnd {
            kind,
            people: people.clone(),
            detector: detector.map(MovingObjectDetector::new).transpose()?,
            legs: match kind {
                FrontEnd::Legs => Some(LegDetector::shipped()?),
                _ => None,
            },
            min_moving_share: 0.5,
            evidence: MovingEvidence::MovingClusters,
            moving_beams: Vec::new(),
            dead_reckoning: None,
        })
    }

    /// Runs `model` instead of the shipped leg model (the [`FrontEnd::Legs`] front end
    /// only; an error for the others).
    pub fn set_leg_model(&mut self, model: LegModel) -> Result<()> {
        if self.kind != FrontEnd::Legs {
            return Err(Error::invalid(
                "front end",
                format!(
                    "a leg model needs the legs front end, not {}",
                    self.kind.name()
                ),
            ));
        }
        self.legs = Some(LegDetector::new(model)?);
        Ok(())
    }

    /// Which front end this is.
    pub fn kind(&self) -> FrontEnd {
        self.kind
    }

    /// One scan with the robot's odometry pose at its time. Without odometry the detector is
    /// handed a constant-velocity prediction from its own last two corrected poses (the
    /// origin at first), which its scan-to-map ICP then corrects.
    pub fn measure(&mut self, scan: &Scan, odometry: Option<Pose2>) -> Result<FrontEndOutput> {
        let detections = match &mut self.detector {
            Some(det) => {
                if odometry.is_none() && self.dead_reckoning.is_none() {
                    // The first scan of a recording without odometry: the scan matcher alone
                    // must follow the robot, so its correction may go farther from the
                    // constant-velocity guess than from an odometry reading.
                    let mut c = *det.config();
                    c.max_correction = c.max_correction.max(NO_ODOMETRY_MAX_CORRECTION);
                    c.max_correction_angle =
                        c.max_correction_angle.max(NO_ODOMETRY_MAX_CORRECTION_ANGLE);
                    *det = MovingObjectDetector::new(c)?;
                }
                let stand_in = match (odometry, self.dead_reckoning) {
                    (Some(odo), _) => odo,
                    (None, Some(d)) => compose(d.odometry, d.step),
                    (None, None) => Pose2::new(0.0, 0.0, 0.0),
                };
                let out = det.process(scan, stand_in)?;
                if odometry.is_none() {
                    let step = self.dead_reckoning.map_or(Pose2::new(0.0, 0.0, 0.0), |d| {
                        between(d.corrected, out.pose)
                    });
                    self.dead_reckoning = Some(DeadReckoning {
                        odometry: stand_in,
                        corrected: out.pose,
                        step,
                    });
                }
                Some(out)
            }
            None => None,
        };
        if let Some(legs) = &mut self.legs {
            let people = legs.people_for_tracking(scan)?;
            let rows = |people: &[LegPerson]| -> Result<Measurements> {
                let rows: Vec<[f64; 2]> = people
                    .iter()
                    .map(|p| {
                        let [x, y] = p.position;
                        [x.hypot(y), y.atan2(x)]
                    })
                    .collect();
                Measurements::from_rows(2, &rows)
            };
            return Ok(FrontEndOutput {
                measurements: rows(&people.reported)?,
                corrected_pose: detections.as_ref().map(|d| d.pose).or(Some(legs.pose())),
                detections,
                weighed: Some(WeighedMeasurements {
                    measurements: rows(&people.for_tracking)?,
                    evidence: people.for_tracking.iter().map(|p| p.score).collect(),
                }),
            });
        }
        let groups = person_groups(scan, &person_grouping(&self.people))?;
        let groups = match (&detections, self.kind) {
            (Some(d), FrontEnd::Moving) => {
                self.moving_beams.clear();
                self.moving_beams.resize(scan.len(), false);
                match self.evidence {
                    MovingEvidence::MovingClusters => {
                        for c in d
                            .all_clusters
                            .iter()
                            .filter(|c| c.stage == ClusterStage::Moving)
                        {
                            for &b in &c.beams {
                                self.moving_beams[b] = true;
                            }
                        }
                    }
                    MovingEvidence::Candidates => {
                        for &b in &d.candidates {
                            self.moving_beams[b] = true;
                        }
                    }
                }
                moving_groups(groups, scan, &self.moving_beams, self.min_moving_share)
            }
            _ => groups,
        };
        let rows: Vec<[f64; 2]> = groups.iter().map(|g| [g.range, g.bearing]).collect();
        Ok(FrontEndOutput {
            measurements: Measurements::from_rows(2, &rows)?,
            corrected_pose: detections.as_ref().map(|d| d.pose),
            detections,
            weighed: None,
        })
    }
}

/// The groups at least `min_share` of whose returns lie on beams marked in `moving`
/// (indexed like the scan's beams).
pub fn moving_groups(
    groups: Vec<PersonGroup>,
    scan: &Scan,
    moving: &[bool],
    min_share: f64,
) -> Vec<PersonGroup> {
    groups
        .into_iter()
        .filter(|g| {
            let on = g
                .points
                .iter()
                .filter(|&&p| {
                    scan.beam_of(p)
                        .is_some_and(|b| moving.get(b) == Some(&true))
                })
                .count();
            !g.points.is_empty() && on as f64 >= min_share * g.points.len() as f64
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scan() -> Scan {
        // 181 beams over 180°, ranges 5 m.
        Scan::new(
            0.0,
            -std::f64::consts::FRAC_PI_2,
            std::f64::consts::PI / 180.0,
            vec![5.0; 181],
            0.0,
            30.0,
        )
        .unwrap()
    }

    fn group(beams: &[usize], s: &Scan) -> PersonGroup {
        PersonGroup {
            points: beams.iter().map(|&b| s.point(b).unwrap()).collect(),
            range: 5.2,
            bearing: s.bearing(beams[0]),
        }
    }

    #[test]
    fn a_group_is_kept_when_enough_of_its_returns_are_moving() {
        let s = scan();
        let mut moving = vec![false; 181];
        moving[10..=12].fill(true);
        // 3 of 4 moving; 1 of 4 moving; none.
        let groups = vec![
            group(&[10, 11, 12, 13], &s),
            group(&[9, 12, 40, 41], &s),
            group(&[100, 101], &s),
        ];
        let kept = moving_groups(groups.clone(), &s, &moving, 0.5);
        assert_eq!(kept, vec![groups[0].clone()]);
        // A share of 0.25 also keeps the second group; 1.0 keeps none.
        assert_eq!(moving_groups(groups.clone(), &s, &moving, 0.25).len(), 2);
        assert!(moving_groups(groups, &s, &moving, 1.0).is_empty());
    }

    #[test]
    fn the_moving_front_end_needs_a_detector_and_names_parse() {
        let people = PeopleTrackerConfig::for_scanner(0.03, 0.01, 20.0, 1.5, [0.1, 0.0]);
        assert!(PersonFrontEnd::new(FrontEnd::Moving, &people, None).is_err());
        assert_eq!(sensor_mount(&people), [0.1, 0.0]);
        for f in [FrontEnd::Segments, FrontEnd::Moving, FrontEnd::Legs] {
            assert_eq!(FrontEnd::parse(f.name()).unwrap(), f);
        }
        assert!(FrontEnd::parse("walls").is_err());
    }

    #[test]
    fn the_tracker_behind_the_legs_front_end_confirms_late() {
        let base = PeopleTrackerConfig::for_scanner(0.03, 0.01, 20.0, 1.5, [0.0, 0.0]);
        let mut legs = base.clone();
        adapt_tracker_config(&mut legs, FrontEnd::Legs);
        assert_eq!(legs.confirm_evidence, LEGS_CONFIRM_EVIDENCE);
        assert_eq!(legs.filter.filter.prune_threshold, LEGS_PRUNE_THRESHOLD);
        assert_eq!(base.confirm_evidence, 0.0);
        assert!(matches!(
            legs.filter.detection,
            Some(crate::config::DetectionConfig::FieldOfView { p_inside, .. })
                if p_inside == LEGS_DETECTION_PROBABILITY
        ));
        assert_eq!(legs.filter.clutter, base.filter.clutter);
        assert_eq!(legs.detectability, None);
    }

    #[test]
    fn the_tracker_is_adapted_to_the_moving_front_end_only() {
        let base = PeopleTrackerConfig::for_scanner(0.03, 0.01, 20.0, 1.5, [0.0, 0.0]);
        let mut seg = base.clone();
        adapt_tracker_config(&mut seg, FrontEnd::Segments);
        assert_eq!(seg, base);
        let mut mov = base.clone();
        adapt_tracker_config(&mut mov, FrontEnd::Moving);
        assert_eq!(mov.filter.clutter.unwrap().rate, MOVING_CLUTTER_RATE);
        assert!(matches!(
            mov.filter.detection,
            Some(crate::config::DetectionConfig::FieldOfView { p_inside, .. })
                if p_inside == MOVING_DETECTABLE_PROBABILITY
        ));
        assert_eq!(mov.detectability, Some(MOVING_DETECTABILITY));
        assert_eq!(mov.confirm_detections, MOVING_CONFIRM_DETECTIONS);
        // the chain's long-run p_D is the independent-miss p_D the front end was measured at
        let long_run = MOVING_DETECTABLE_PROBABILITY * MOVING_DETECTABILITY.stationary_detectable();
        assert!(
            (long_run - MOVING_DETECTION_PROBABILITY).abs() < 0.03,
            "{long_run}"
        );
    }
}
