//! The people tracker fed by several lasers at their mounting poses on one robot: each laser is
//! one sensor of the filter ([`crate::filter::Sensor`]), and their updates combine by the
//! chosen fusion rule (iterated corrector, parallel update, geometric or arithmetic average;
//! [`crate::filter::FusionMethod`]).
//!
//! # Each laser about itself
//!
//! A laser measures range and bearing from itself. The filter's [`crate::filter::Mounting`]
//! moves positions into the platform frame, which is wrong for range and bearing, so a laser's
//! models are instead written for a laser at the platform's origin (no mounting offset) and
//! each laser's scan carries its own platform pose ([`crate::filter::Scan::platform`]): the
//! laser's world pose at its own scan time, robot pose ∘ mounting. That laser's range-bearing
//! likelihood, field of view, occlusion (against its own beams, a [`BeamView`] in the scan's
//! data) and resolution models read it as the step's platform. The births see every laser's
//! measurements one after another in sensor order, so the frame's data lists each reporting
//! laser's pose and measurement count ([`LaserOrigins`]), which [`PeopleBirth`] reads each
//! measurement by. Survival forgets people outside every reporting laser's field of view.
//!
//! The confirmation evidence, the doubted-measurement gate and the most-probable measurement
//! bookkeeping of [`super::PeopleTracker`] work here on the concatenated measurements (the
//! filter's [`LmbFilter::most_probable_measurements_all`]). Confirmation counts frames, not
//! lasers: per frame a track collects the mean evidence of the lasers that could explain
//! a measurement by it and the largest probability that it made its most probable
//! measurement (which stands for the filter's expected detections, summed over lasers), so
//! three lasers seeing one person confirm it no sooner than one would. A person's visibility is the largest over the lasers that reported.
//!
//! # Asynchronous lasers
//!
//! Lasers scan at their own times. [`group_scans`] builds one frame around each scan of the
//! anchor laser (the one with the most scans) with every other laser's scans nearest to it
//! within half the anchor's period (each scan in at most one frame); the frame's time is the
//! anchor scan's, and each laser sits at its own pose for its own scan time.
//!
//! Not for: estimating the mountings ([`crate::laser2d::mounting`]), the single-laser tracker
//! ([`super::PeopleTracker`], which stays as it was), reading recordings.

use super::birth::{LaserOrigin, LaserOrigins};
use super::front_end::{adapt_tracker_config, FrontEnd, PersonFrontEnd};
use super::models::{
    BeamView, DetectabilityDetection, DetectabilityTransition, OcclusionDetection,
    ResolutionDetection, ResolutionLikelihood,
};
use super::motion_state::{probability_moving, MotionClassifier};
use super::run::{PeopleRun, ScanPeople};
use super::tracker::{
    people_data, people_motion, track_summary, FilterParts, PeopleTrackerConfig, PersonEstimate,
};
use crate::config::{DetectionConfig, MeasurementConfig};
use crate::error::{Error, Result};
use crate::filter::{
    DetectionModel, Frame, Fusion, Label, LmbFilter, MeasurementModel, Measurements, ParticleSet,
    Scan as FilterScan, Sensor, StepContext, StepData, SurvivalModel,
};
use crate::geometry::pose2::{between, compose, inverse};
use crate::geometry::{platform_isometry, wrap_angle, Pose2};
use crate::laser2d::Scan;
use crate::models::cloud_bounds::CloudBox;
use crate::models::detection::FieldOfViewDetection;
use crate::models::{RangeBearing, UniformClutter};
use crate::rng::{seeded, FilterRng};
use std::collections::{BTreeMap, BTreeSet};

/// One laser of the robot: its name, its pose on the robot and its field of view.
#[derive(Clone, Debug, PartialEq)]
pub struct LaserMount {
    /// The laser's name (its topic, or the rig's name).
    pub name: String,
    /// Pose of the laser in the robot frame (x forward, y left, heading counter-clockwise).
    pub mounting: Pose2,
    /// Farthest range it sees people at (m).
    pub max_range: f64,
    /// Half its field of view about its own x axis (rad, at most π).
    pub half_angle: f64,
}

impl LaserMount {
    /// A laser called `name` at `mounting` whose scans look like `scan`: the field of view
    /// from the scan's bearings (plus half a beam either side, at most a full turn), the
    /// range from its `range_max` capped at `max_range`.
    pub fn for_scan(name: impl Into<String>, mounting: Pose2, scan: &Scan, max_range: f64) -> Self {
        let half =
            0.5 * (scan.angle_max() - scan.angle_min).abs() + 0.5 * scan.angle_increment.abs();
        let range = if scan.range_max.is_finite() {
            scan.range_max.min(max_range)
        } else {
            max_range
        };
        LaserMount {
            name: name.into(),
            mounting,
            max_range: range,
            half_angle: half.min(std::f64::consts::PI),
        }
    }
}

/// What one laser brings to a frame.
#[derive(Clone, Debug)]
pub struct LaserInput {
    /// The laser's index in the tracker's lasers.
    pub laser: usize,
    /// Range-bearing rows of the people's centres, about the laser.
    pub measurements: Measurements,
    /// Each measurement's evidence that it is a person (see
    /// [`super::PeopleTracker::step_measured_with_evidence`]); `None` counts 1 for each.
    pub evidence: Option<Vec<f64>>,
    /// The laser's beams (for its occlusion model).
    pub view: BeamView,
    /// The laser's world pose at its scan.
    pub pose: Pose2,
}

/// p_S = `inside` for particles inside the field of view of some laser of the frame
/// ([`LaserOrigins`] in the step's data), `outside` elsewhere; `inside` everywhere in a frame
/// without lasers.
#[derive(Clone, Debug)]
struct LasersSurvival {
    fovs: Vec<FieldOfViewDetection>,
    inside: f64,
    outside: f64,
}

impl SurvivalModel for LasersSurvival {
    fn survival_probability(&self, particles: &ParticleSet, ctx: &StepContext, out: &mut [f64]) {
        let Some(origins) = ctx.data.get::<LaserOrigins>().filter(|o| !o.0.is_empty()) else {
            out.fill(self.inside);
            return;
        };
        if particles.dim() < 3 {
            out.fill(self.outside);
            return;
        }
        let views: Vec<(&FieldOfViewDetection, f64, f64, f64, f64)> = origins
            .0
            .iter()
            .filter_map(|o| {
                let (s, c) = o.pose.theta.sin_cos();
                self.fovs
                    .get(o.laser)
                    .map(|f| (f, o.pose.x, o.pose.y, c, s))
            })
            .collect();
        let cloud = CloudBox::of(particles);
        let surely = views.iter().any(|&(f, sx, sy, c, s)| {
            cloud
                .and_then(|b| b.polar_from(sx, sy, c, s))
                .is_some_and(|b| f.surely_contains(&b))
        });
        if surely {
            out.fill(self.inside);
            return;
        }
        let xs = particles.component(0);
        let ys = particles.component(2);
        for ((o, &x), &y) in out.iter_mut().zip(xs).zip(ys) {
            let seen = views
                .iter()
                .any(|&(f, sx, sy, c, s)| f.contains_from(x, y, sx, sy, c, s));
            *o = if seen { self.inside } else { self.outside };
        }
    }
}

/// The people tracker of several lasers (module documentation).
#[derive(Debug)]
pub struct LasersTracker {
    config: PeopleTrackerConfig,
    lasers: Vec<LaserMount>,
    filter: LmbFilter,
    rng: FilterRng,
    /// Per laser: field of view and occlusion (visibility).
    detections: Vec<OcclusionDetection>,
    motion: MotionClassifier,
    suppress_existence: f64,
    confirmed: BTreeSet<Label>,
    evidence: BTreeMap<Label, f64>,
    /// Frames in which each track was detected: the sum over frames of the largest
    /// probability over the lasers that it made its most probable measurement (stands for
    /// the filter's expected detections, which add up over the lasers of a frame). The
    /// evidence above is likewise the sum over frames of the lasers' mean.
    detected: BTreeMap<Label, f64>,
    last_time: Option<f64>,
    /// The range-bearing model of a laser at the origin (doubted gate).
    sensor: RangeBearing,
}

impl LasersTracker {
    /// A tracker of `lasers` (at least one) with the people models and tuning of `config`
    /// (its field of view, range and mounting are replaced by each laser's), their updates
    /// combined by `fusion`.
    pub fn new(
        config: PeopleTrackerConfig,
        lasers: Vec<LaserMount>,
        fusion: Fusion,
    ) -> Result<Self> {
        if lasers.is_empty() {
            return Err(Error::invalid("people lasers", "no laser given"));
        }
        for l in &lasers {
            let m = l.mounting;
            if !([m.x, m.y, m.theta, l.half_angle]
                .iter()
                .all(|v| v.is_finite())
                && l.max_range > 0.0
                && l.half_angle > 0.0)
            {
                return Err(Error::invalid(
                    format!("laser {:?}", l.name),
                    format!(
                        "mounting [{}, {}, {}], range {} m and half angle {} rad must be \
                         finite (range and angle positive)",
                        m.x, m.y, m.theta, l.max_range, l.half_angle
                    ),
                ));
            }
        }
        let parts = FilterParts::of(&config)?;
        let (p_inside, p_outside) = (parts.p_inside, parts.p_outside);
        let rate = config.filter.clutter.as_ref().map_or(1.0, |c| c.rate);
        // Every laser about itself: no offsets; the scan's platform is the laser's pose.
        let sensor = parts.range_bearing()?;
        let birth = parts.birth(sensor, &config)?;
        let motion = people_motion(&config)?;
        let mut builder = LmbFilter::builder()
            .config(config.filter.filter.clone())
            .associator(config.filter.association);
        let mode = match config.detectability {
            Some(chain) => {
                let transition = DetectabilityTransition::new(motion, chain)?;
                let mode = transition.mode_component();
                builder = builder.transition(transition);
                Some((chain, mode))
            }
            None => {
                builder = builder.transition(motion);
                None
            }
        };
        let mut fovs = Vec::with_capacity(lasers.len());
        let mut detections = Vec::with_capacity(lasers.len());
        for l in &lasers {
            let fov = FieldOfViewDetection::new(p_inside, p_outside, l.max_range, l.half_angle)?;
            let detection = OcclusionDetection::new(
                fov,
                config.body_radius.max(1e-3),
                config.occlusion_margin,
            )?
            .with_min_returns(config.min_points as u32);
            let resolution = ResolutionDetection::new(
                detection.clone(),
                config.resolution_distance,
                config.resolution_fade,
                config.unresolved_share,
                1.5 * config.body_radius,
            )?;
            let measurement: Box<dyn MeasurementModel> = if config.unresolved_noise_scale != 1.0 {
                Box::new(ResolutionLikelihood::new(
                    sensor,
                    config.unresolved_noise_scale,
                    resolution.clone(),
                )?)
            } else {
                Box::new(sensor)
            };
            let detect: Box<dyn DetectionModel> = match mode {
                Some((chain, mode)) => {
                    Box::new(DetectabilityDetection::new(resolution, chain, mode)?)
                }
                None => Box::new(resolution),
            };
            let clutter = UniformClutter::new(rate, 2.0 * l.half_angle * l.max_range)?;
            builder = builder.sensor(Sensor::from_boxes(
                l.name.clone(),
                measurement,
                detect,
                Box::new(clutter),
            ));
            fovs.push(fov);
            detections.push(detection);
        }
        let survival = LasersSurvival {
            fovs,
            inside: config.filter.survival,
            outside: config.survival_outside,
        };
        let suppress_existence = birth.suppress_existence;
        let filter = builder
            .survival(survival)
            .birth(birth)
            .fusion(fusion)
            .build()?;
        Ok(LasersTracker {
            rng: seeded(config.filter.seed),
            motion: MotionClassifier::new(config.motion)?,
            config,
            lasers,
            filter,
            detections,
            suppress_existence,
            confirmed: BTreeSet::new(),
            evidence: BTreeMap::new(),
            detected: BTreeMap::new(),
            last_time: None,
            sensor,
        })
    }

    /// The lasers, in sensor order.
    pub fn lasers(&self) -> &[LaserMount] {
        &self.lasers
    }

    /// The underlying filter.
    pub fn filter(&self) -> &LmbFilter {
        &self.filter
    }

    /// The configuration.
    pub fn config(&self) -> &PeopleTrackerConfig {
        &self.config
    }

    /// One frame: the scans of the lasers that reported (`inputs`, each laser at most once)
    /// at `time`, the robot at `robot` (world frame; `None`: at the origin). Returns every
    /// confirmed person of the filter's estimate, as [`super::PeopleTracker::step_people`]
    /// does.
    pub fn step(
        &mut self,
        mut inputs: Vec<LaserInput>,
        time: f64,
        robot: Option<Pose2>,
    ) -> Result<Vec<PersonEstimate>> {
        inputs.sort_by_key(|i| i.laser);
        for (k, i) in inputs.iter().enumerate() {
            let Some(laser) = self.lasers.get(i.laser) else {
                return Err(Error::invalid(
                    "people lasers frame",
                    format!(
                        "a scan of laser {}, but there are {}",
                        i.laser,
                        self.lasers.len()
                    ),
                ));
            };
            if k > 0 && inputs[k - 1].laser == i.laser {
                return Err(Error::invalid(
                    "people lasers frame",
                    format!("two scans of laser {:?}", laser.name),
                ));
            }
            if let Some(e) = &i.evidence {
                if e.len() != i.measurements.len() || e.iter().any(|v| !v.is_finite()) {
                    return Err(Error::invalid(
                        format!("measurement evidence of laser {:?}", laser.name),
                        format!(
                            "{} finite values needed, one per measurement (got {})",
                            i.measurements.len(),
                            e.len()
                        ),
                    ));
                }
            }
            if !i.measurements.is_empty() && i.measurements.dim() != 2 {
                return Err(Error::invalid(
                    format!("measurements of laser {:?}", laser.name),
                    format!(
                        "have {} components, range and bearing expected",
                        i.measurements.dim()
                    ),
                ));
            }
        }
        let dt = self.last_time.map_or(0.0, |t0| (time - t0).max(0.0));
        self.last_time = Some(time);
        let confirmed: Vec<([f64; 2], [f64; 2], f64, f64)> = self
            .filter
            .tracks()
            .iter()
            .map(|t| track_summary(&t.particles, t.existence, dt))
            .collect();
        // Doubted measurements (evidence ≤ 0) only near a likely track, each about its laser.
        let any_evidence = inputs.iter().any(|i| i.evidence.is_some());
        let (gate, min_r) = (self.config.doubted_gate, self.config.doubted_gate_existence);
        let mut all_evidence: Vec<f64> = Vec::new();
        let mut scans = Vec::with_capacity(inputs.len());
        let mut origins = Vec::with_capacity(inputs.len());
        for input in &inputs {
            let mut gctx = StepContext::new(self.filter.steps(), time, 0.0);
            gctx.platform = Some(platform_isometry(input.pose));
            let mut rows = Vec::with_capacity(input.measurements.len());
            for j in 0..input.measurements.len() {
                let z = input.measurements.get(j);
                let e = input.evidence.as_ref().map_or(1.0, |e| e[j]);
                let keep = e > 0.0 || {
                    let p = self.sensor.to_cartesian([z[0], z[1]], &gctx);
                    confirmed.iter().any(|&(_, next, r, _)| {
                        r >= min_r && (next[0] - p[0]).hypot(next[1] - p[1]) < gate
                    })
                };
                if keep {
                    rows.push([z[0], z[1]]);
                    all_evidence.push(e);
                }
            }
            let z = Measurements::from_rows(2, &rows)?;
            origins.push(LaserOrigin {
                laser: input.laser,
                pose: input.pose,
                measurements: z.len(),
            });
            scans.push(
                FilterScan::new(input.laser, z)
                    .with_data(StepData::new().with(input.view.clone()))
                    .at(platform_isometry(input.pose)),
            );
        }
        let evidence = any_evidence.then_some(&all_evidence[..]);
        let data =
            people_data(&confirmed, self.suppress_existence, evidence).with(LaserOrigins(origins));
        let mut frame = Frame::at_time(time).with_data(data.clone());
        frame.platform = robot.map(platform_isometry);
        for s in scans {
            frame = frame.with_scan(s);
        }
        let estimates = self.filter.step(&frame, &mut self.rng)?;
        let tracks = self.filter.tracks();
        // Per frame, over the lasers that could explain some measurement by each track: the
        // mean of their evidence (a laser that doubts counts against one that believes) and
        // the largest probability that the track made its most probable measurement; several
        // lasers seeing one person in one frame confirm it no sooner than one laser would.
        let mut views: BTreeMap<Label, (f64, usize, f64)> = BTreeMap::new();
        for m in self.filter.most_probable_measurements_all() {
            let e = evidence.map_or(1.0, |e| e.get(m.measurement).copied().unwrap_or(0.0));
            let v = views.entry(m.label).or_insert((0.0, 0, 0.0));
            v.0 += m.probability * e;
            v.1 += 1;
            v.2 = v.2.max(m.probability);
        }
        for (label, (e, n, d)) in views {
            *self.evidence.entry(label).or_insert(0.0) += e / n as f64;
            *self.detected.entry(label).or_insert(0.0) += d;
        }
        self.evidence
            .retain(|l, _| tracks.iter().any(|t| t.label == *l));
        self.detected
            .retain(|l, _| tracks.iter().any(|t| t.label == *l));
        self.confirmed
            .retain(|l| tracks.iter().any(|t| t.label == *l));
        let (confirm, detections, needed) = (
            self.config.confirm_existence,
            self.config.confirm_detections,
            self.config.confirm_evidence,
        );
        let (evidence_of, detected) = (&self.evidence, &self.detected);
        self.confirmed.extend(
            tracks
                .iter()
                .filter(|t| {
                    t.existence >= confirm
                        && detected.get(&t.label).copied().unwrap_or(0.0) >= detections
                        && (needed <= 0.0
                            || evidence_of.get(&t.label).copied().unwrap_or(0.0) >= needed)
                })
                .map(|t| t.label),
        );
        // Each reporting laser's view, for visibility.
        let views: Vec<(usize, StepContext)> = inputs
            .iter()
            .map(|i| {
                let mut c = StepContext::new(self.filter.steps(), time, 0.0)
                    .with_data(data.clone().with(i.view.clone()));
                c.platform = Some(platform_isometry(i.pose));
                (i.laser, c)
            })
            .collect();
        let mut out = Vec::with_capacity(estimates.len());
        let mut pd = Vec::new();
        for e in estimates {
            if !self.confirmed.contains(&e.label) {
                continue;
            }
            let Some(t) = tracks.iter().find(|t| t.label == e.label) else {
                continue;
            };
            let p = &t.particles;
            pd.resize(p.len(), 0.0);
            let mut visibility: f64 = 0.0;
            for (laser, ctx) in &views {
                let d = &self.detections[*laser];
                d.detection_probability(p, ctx, &mut pd);
                let p_max = d.field_of_view().p_inside();
                let seen: f64 = p.weights().iter().zip(&pd).map(|(w, d)| w * d).sum();
                if p_max > 0.0 {
                    visibility = visibility.max((seen / p_max).clamp(0.0, 1.0));
                }
            }
            let p_moving = probability_moving(p, self.config.motion.v_min);
            out.push(PersonEstimate {
                label: e.label,
                existence: e.existence,
                position: [e.state[0], e.state[2]],
                velocity: [e.state[1], e.state[3]],
                p_moving,
                moving: self.motion.update(e.label, p_moving, e.age),
                visibility,
                age: e.age,
            });
        }
        self.motion.retain(|l| tracks.iter().any(|t| t.label == l));
        Ok(out)
    }
}

mod frames;
mod mountings;
mod recording;

pub use frames::{extrapolate, group_scans, LaserFrame};
pub use mountings::{mountings_for_topics, parse_mountings, read_mountings, NamedMounting};
pub use recording::{read_bag_lasers, track_lasers, LaserRecording};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::FusionMethod;
    use std::f64::consts::{FRAC_PI_2, PI};
    use std::path::Path;

    #[test]
    fn scans_group_around_the_fastest_laser() {
        // laser 1 at 8 Hz is the anchor; laser 0 at 5 Hz; laser 2 half a period late.
        let a: Vec<f64> = (0..10).map(|k| 0.03 + k as f64 * 0.2).collect();
        let b: Vec<f64> = (0..16).map(|k| k as f64 * 0.125).collect();
        let c: Vec<f64> = (0..16).map(|k| 0.0625 + k as f64 * 0.125).collect();
        let (anchor, frames) = group_scans(&[a.clone(), b.clone(), c]).unwrap();
        assert_eq!(anchor, 1);
        assert_eq!(frames.len(), 16);
        // every scan in at most one frame, laser order within a frame
        let mut used = BTreeSet::new();
        for f in &frames {
            assert!(f.scans.windows(2).all(|w| w[0].0 < w[1].0), "{f:?}");
            assert!(f.scans.contains(&(1, f.anchor)));
            for &s in &f.scans {
                assert!(used.insert(s), "{s:?} twice");
            }
        }
        // each 5 Hz scan went to its nearest anchor scan
        for (k, &t) in a.iter().enumerate() {
            let f = frames.iter().find(|f| f.scans.contains(&(0, k))).unwrap();
            assert!((f.time - t).abs() <= 0.0625 + 1e-9, "{k}: {f:?}");
        }
        // a scan midway goes to the later anchor scan: the frame never waits for the future
        assert_eq!(frames[1].scans, vec![(1, 1), (2, 0)]);
        assert!(frames[0].scans.iter().all(|&(j, _)| j != 2));
        assert!(group_scans(&[vec![1.0, 0.5]]).is_err());
        assert!(group_scans(&[]).is_err());
    }

    #[test]
    fn extrapolation_continues_the_last_motion() {
        let before = Pose2::new(0.0, 0.0, 0.0);
        let now = Pose2::new(1.0, 0.0, 0.1);
        let p = extrapolate(now, 1.0, Some((before, 0.0)), 1.5);
        assert!((p.theta - 0.15).abs() < 1e-12, "{p:?}");
        assert!(p.x > 1.4 && p.x < 1.5 && p.y > 0.0, "{p:?}");
        assert_eq!(extrapolate(now, 1.0, None, 1.5), now);
    }

    #[test]
    fn mountings_files_are_read_and_bad_ones_named() {
        let path = Path::new("m.toml");
        let text = "# mounting poses\n[[sensors]]\nname = \"left_scan\"\nmounting = [0.0, 0.0, 0.0]\n\n[[sensors]]\nname = \"rear_scan\"\nmounting = [-0.8557, 0.5428, 2.3529] # comment\n";
        let m = parse_mountings(text, path).unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(m[1].name, "rear_scan");
        assert_eq!(m[1].mounting, Pose2::new(-0.8557, 0.5428, 2.3529));
        let poses =
            mountings_for_topics(&m, &["/rear_scan".into(), "/left_scan".into()], path).unwrap();
        assert_eq!(poses[0], m[1].mounting);
        let e = mountings_for_topics(&m, &["/right_scan".into()], path).unwrap_err();
        assert!(
            e.to_string().contains("m.toml") && e.to_string().contains("/right_scan"),
            "{e}"
        );
        for (bad, line, what) in [
            ("[[sensors]]\nname = \"a\"\nmounting = [0, 0]\n", 3, "2 values"),
            ("[[sensors]]\nname = \"a\"\nmounting = [0, x, 0]\n", 3, "mounting"),
            ("[[sensors]]\nname = a\nmounting = [0, 0, 0]\n", 2, "quoted"),
            ("name = \"a\"\n", 1, "before the first"),
            ("[[sensors]]\nname = \"a\"\nheight = 3\n", 3, "unknown key"),
            ("[fusion]\n", 1, "only [[sensors]]"),
            ("[[sensors]]\nname = \"a\"\n", 1, "mounting"),
            ("[[sensors]]\nname = \"a\"\nmounting = [0, 0, 0]\n[[sensors]]\nname = \"a\"\nmounting = [1, 0, 0]\n", 4, "twice"),
            ("# nothing\n", 0, "no [[sensors]]"),
            ("[[sensors]\n", 1, "only [[sensors]]"),
        ] {
            let e = parse_mountings(bad, path).unwrap_err().to_string();
            assert!(e.starts_with(&format!("m.toml:{line}:")), "{bad:?}: {e}");
            assert!(e.contains(what), "{bad:?}: {e}");
        }
        assert!(
            FusionMethod::from_short_name("pu").is_ok()
                && FusionMethod::from_short_name("xx").is_err()
        );
    }

    /// A person (disc of radius 0.2 m) at world `person` seen by a laser at world pose `laser`
    /// with a fan of ±`half` rad of 0.5° beams; returns the scan's range-bearing measurement
    /// of the person (exact) and its beams.
    fn look(laser: Pose2, half: f64, person: [f64; 2]) -> (Measurements, BeamView) {
        let n = (2.0 * half / 0.5f64.to_radians()).round() as usize + 1;
        let inc = 2.0 * half / (n - 1) as f64;
        let (s, c) = laser.theta.sin_cos();
        let (dx, dy) = (person[0] - laser.x, person[1] - laser.y);
        let (px, py) = (c * dx + s * dy, -s * dx + c * dy);
        let ranges: Vec<f64> = (0..n)
            .map(|i| {
                let a = -half + i as f64 * inc;
                let (ux, uy) = (a.cos(), a.sin());
                let b = ux * px + uy * py;
                let d = b * b - (px * px + py * py - 0.04);
                if d >= 0.0 && b - d.sqrt() > 0.0 {
                    b - d.sqrt()
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        let bearing = py.atan2(px);
        let visible = bearing.abs() <= half && px.hypot(py) < 20.0;
        let rows: Vec<[f64; 2]> = if visible {
            vec![[px.hypot(py), bearing]]
        } else {
            vec![]
        };
        let z = Measurements::from_rows(2, &rows).unwrap();
        (z, BeamView::new(-half, inc, &ranges).unwrap())
    }

    fn config() -> PeopleTrackerConfig {
        PeopleTrackerConfig::for_scanner(0.02, 0.005, 20.0, FRAC_PI_2, [0.0, 0.0])
    }

    /// A person walks past the robot from behind to its front; the rear laser (facing back,
    /// 200° of view) sees them first, both lasers beside the robot, the front one last. Fused, the track is one person throughout, at
    /// the right place in the world whatever laser measured it.
    fn walk_round(fusion: FusionMethod) -> Vec<Vec<PersonEstimate>> {
        let lasers = vec![
            LaserMount {
                name: "front".into(),
                mounting: Pose2::new(0.3, 0.0, 0.0),
                max_range: 20.0,
                half_angle: 1.75,
            },
            LaserMount {
                name: "rear".into(),
                mounting: Pose2::new(-0.3, 0.1, PI),
                max_range: 20.0,
                half_angle: 1.75,
            },
        ];
        let mut t = LasersTracker::new(config(), lasers.clone(), Fusion::new(fusion)).unwrap();
        let robot = Pose2::new(10.0, -5.0, 0.5);
        let mut out = Vec::new();
        for k in 0..48 {
            let time = k as f64 * 0.125;
            // in the robot frame: from (−4, 3) to (4, 3)
            let local = [-4.0 + time * 8.0 / 6.0, 3.0];
            let person = crate::geometry::pose2::transform_point(robot, local);
            let inputs = lasers
                .iter()
                .enumerate()
                .map(|(j, l)| {
                    let pose = compose(robot, l.mounting);
                    let (z, view) = look(pose, l.half_angle, person);
                    LaserInput {
                        laser: j,
                        measurements: z,
                        evidence: None,
                        view,
                        pose,
                    }
                })
                .collect();
            let people = t.step(inputs, time, Some(robot)).unwrap();
            if k >= 8 {
                assert_eq!(people.len(), 1, "step {k}: {people:?}");
                let p = people[0].position;
                assert!(
                    (p[0] - person[0]).hypot(p[1] - person[1]) < 0.3,
                    "step {k}: {p:?} vs {person:?}"
                );
                assert!(people[0].visibility > 0.5, "step {k}: {people:?}");
            }
            out.push(people);
        }
        let labels: BTreeSet<Label> = out.iter().flatten().map(|p| p.label).collect();
        assert_eq!(labels.len(), 1, "{labels:?}");
        out
    }

    #[test]
    fn a_person_walking_round_the_robot_is_one_track_under_every_rule() {
        for m in [
            FusionMethod::IteratedCorrector,
            FusionMethod::ParallelUpdate,
            FusionMethod::GeometricAverage,
            FusionMethod::ArithmeticAverage,
        ] {
            walk_round(m);
        }
    }

    #[test]
    fn bad_frames_and_lasers_are_errors() {
        let laser = LaserMount {
            name: "l".into(),
            mounting: Pose2::new(0.0, 0.0, 0.0),
            max_range: 20.0,
            half_angle: FRAC_PI_2,
        };
        assert!(LasersTracker::new(config(), vec![], Fusion::default()).is_err());
        let mut bad = laser.clone();
        bad.mounting.theta = f64::NAN;
        assert!(LasersTracker::new(config(), vec![bad], Fusion::default()).is_err());
        let mut t = LasersTracker::new(config(), vec![laser], Fusion::default()).unwrap();
        let input = |laser: usize, evidence: Option<Vec<f64>>| LaserInput {
            laser,
            measurements: Measurements::from_rows(2, &[[5.0, 0.0]]).unwrap(),
            evidence,
            view: BeamView::EMPTY,
            pose: Pose2::new(0.0, 0.0, 0.0),
        };
        assert!(t.step(vec![input(1, None)], 0.0, None).is_err());
        assert!(t
            .step(vec![input(0, None), input(0, None)], 0.0, None)
            .is_err());
        let e = t.step(vec![input(0, Some(vec![]))], 0.0, None).unwrap_err();
        assert!(e.to_string().contains("evidence"), "{e}");
        assert!(t.step(vec![input(0, Some(vec![0.5]))], 0.0, None).is_ok());
    }
}
