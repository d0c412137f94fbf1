//! The per-beam background range map of seed 003 (Sec. II-B and II-C): for every beam of the
//! scanner, the range of the stationary background behind it, a consistency weight 1…20, and
//! the last ten background ranges of that beam. Returns clearly in front of the background
//! are the candidates for moving objects.
//!
//! Not for: deciding which candidates are moving targets (clustering, shape learning and
//! voting live in the moving-object detector), estimating the motion (ICP), or mapping.
//!
//! # One scan
//!
//! 1. [`BackgroundMap::propagate`] carries the map into the new sensor frame (seed 003,
//!    eqs. 1–3): every background beam becomes a point, is moved by the inverse of the sensor
//!    motion (odometry refined by ICP), and lands in the beam nearest to its new bearing;
//!    when several land in one beam the nearest wins (what the scanner would see), and it
//!    brings its weight along. Beams left empty take the nearer of their neighbours within
//!    [`BackgroundConfig::fill_gap`] beams (small holes open as the robot drives forward);
//!    wider holes are *new* beams that start from the next reading. "No return" background
//!    beams (stored as `+∞`) only turn with the sensor.
//! 2. [`BackgroundMap::classify`] compares each return `r` with the propagated background
//!    `r_b` using the tolerance `τ = δ + σ`, where `δ` is [`BackgroundConfig::delta`]
//!    (0.4 m) and `σ` the standard deviation of the beam's last ten background ranges
//!    (capped at [`BackgroundConfig::max_spread`]): `r < r_b − τ` is *foreground* (a
//!    candidate), `r ≥ r_b + τ` is *beyond* (the background was not static), anything else
//!    is *background*. A "no return" reading counts as `r = +∞`. With
//!    [`BackgroundConfig::neighbour_beams`] `k > 0` the foreground test uses the nearest
//!    background among the beams `i − k ..= i + k` instead of `r_b` (not in the seed: it
//!    keeps bearing noise at depth edges and on grazing walls from making candidates).
//! 3. [`BackgroundMap::update`] applies seed 003 eqs. 4 and 6: background → `r_b = r`,
//!    weight + 1 (at most 20); beyond → `r_b = r`, weight 20; foreground → `r_b` kept, weight
//!    − 1 (at least 1), and once the weight is 1 the background is renewed with `r`.
//!    Foreground beams the caller marks as occluded by a verified target keep their weight
//!    (end of Sec. II-C). *Uncertain* beams (see [`BeamClass::Uncertain`]) change nothing:
//!    taking their return as background would let an object's own returns spread into the
//!    background of its neighbours. The resulting `r_b` joins the beam's history.
//!
//! The history of the last ten values stays with the beam *index* (a fixed bearing in the
//! sensor frame) and is not moved in step 1, so that it widens the tolerance while the robot
//! moves — the purpose the seed gives it. Weights move with the background points.
//!
//! All state is structure-of-arrays per beam, double-buffered for the propagation; after the
//! first scan nothing is allocated.

use super::scan::{nearest_beam, Scan};
use crate::error::{ensure_positive, Error, Result};
use crate::geometry::pose2::{inverse, transform_point};
use crate::geometry::Pose2;

/// How many past background ranges each beam keeps for its spread.
pub const HISTORY_LEN: usize = 10;

/// Parameters of the background map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BackgroundConfig {
    /// Range tolerance δ (m); seed 003: 0.4 m.
    pub delta: f64,
    /// Largest weight; seed 003: 20.
    pub max_weight: u8,
    /// Largest spread σ added to δ (m). Default 1.0 m.
    pub max_spread: f64,
    /// Empty beams after propagation are filled from neighbours up to this many beams away.
    /// Default 2.
    pub fill_gap: usize,
    /// A return is foreground only when it is nearer than the background of every beam
    /// within ±this many beams (by more than the tolerance). 0 is seed 003's beam-by-beam
    /// test; a few beams absorb bearing noise at depth edges and grazing walls. Default 0.
    pub neighbour_beams: usize,
}

impl Default for BackgroundConfig {
    fn default() -> Self {
        BackgroundConfig {
            delta: 0.4,
            max_weight: 20,
            max_spread: 1.0,
            fill_gap: 2,
            neighbour_beams: 0,
        }
    }
}

impl BackgroundConfig {
    /// Checks `δ > 0`, `max_spread ≥ 0` finite and `max_weight ≥ 2`.
    pub fn validate(&self) -> Result<()> {
        ensure_positive("BackgroundConfig::delta", self.delta)?;
        crate::error::ensure_non_negative("BackgroundConfig::max_spread", self.max_spread)?;
        if self.max_weight < 2 {
            return Err(Error::invalid(
                "BackgroundConfig::max_weight",
                format!("{} (need at least 2)", self.max_weight),
            ));
        }
        Ok(())
    }
}

/// How one beam's reading relates to the background.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BeamClass {
    /// Within the tolerance of the background (or a new beam without background yet).
    Background,
    /// Farther than the background by more than the tolerance.
    Beyond,
    /// Nearer than the background by more than the tolerance: a moving-object candidate.
    Foreground,
    /// Nearer than its own beam's background by more than the tolerance, but not nearer
    /// than a neighbouring beam's (only with [`BackgroundConfig::neighbour_beams`] > 0):
    /// no candidate, and the beam's background and weight stay as they are.
    Uncertain,
}

/// The background map; see the module documentation.
#[derive(Clone, Debug)]
pub struct BackgroundMap {
    config: BackgroundConfig,
    angle_min: f64,
    angle_increment: f64,
    initialised: bool,
    /// Background range per beam (m); `+∞` for "no return", NaN for a new beam.
    range: Vec<f32>,
    weight: Vec<u8>,
    history: Vec<f32>,
    history_len: Vec<u8>,
    history_head: Vec<u8>,
    tolerance: Vec<f32>,
    class: Vec<BeamClass>,
    // Propagation buffers.
    next_range: Vec<f32>,
    next_weight: Vec<u8>,
}

impl BackgroundMap {
    /// An empty map; the first scan given to [`BackgroundMap::classify`] sizes and fills it.
    pub fn new(config: BackgroundConfig) -> Result<Self> {
        config.validate()?;
        Ok(BackgroundMap {
            config,
            angle_min: 0.0,
            angle_increment: 0.0,
            initialised: false,
            range: Vec::new(),
            weight: Vec::new(),
            history: Vec::new(),
            history_len: Vec::new(),
            history_head: Vec::new(),
            tolerance: Vec::new(),
            class: Vec::new(),
            next_range: Vec::new(),
            next_weight: Vec::new(),
        })
    }

    /// Number of beams (0 before the first scan).
    pub fn len(&self) -> usize {
        self.range.len()
    }

    /// True before the first scan.
    pub fn is_empty(&self) -> bool {
        self.range.is_empty()
    }

    /// Background range per beam (m): `+∞` where the background is "no return", NaN where
    /// the beam is new and has no background yet.
    pub fn ranges(&self) -> &[f32] {
        &self.range
    }

    /// Weight per beam, 1…`max_weight`.
    pub fn weights(&self) -> &[u8] {
        &self.weight
    }

    /// The tolerance `τ = δ + σ` of each beam used by the last [`BackgroundMap::classify`].
    pub fn tolerances(&self) -> &[f32] {
        &self.tolerance
    }

    /// The classes found by the last [`BackgroundMap::classify`].
    pub fn classes(&self) -> &[BeamClass] {
        &self.class
    }

    /// Carries the map into the frame of a sensor that moved by `motion` (the new sensor
    /// pose expressed in the old sensor frame). Does nothing before the first scan.
    pub fn propagate(&mut self, motion: Pose2) -> Result<()> {
        if !motion.is_finite() {
            return Err(Error::invalid(
                "background motion",
                format!("{motion:?} is not finite"),
            ));
        }
        if !self.initialised {
            return Ok(());
        }
        let n = self.range.len();
        let to_new = inverse(motion);
        self.next_range.clear();
        self.next_range.resize(n, f32::NAN);
        self.next_weight.clear();
        self.next_weight.resize(n, 1);
        // Bearings modulo a full turn: a 360° scanner's points cross its seam.
        let beam_of = |bearing: f64| nearest_beam(self.angle_min, self.angle_increment, n, bearing);
        // Finite background points first (nearest wins), then "no return" directions into
        // beams nothing finite reached.
        for l in 0..n {
            let r = self.range[l];
            if !r.is_finite() {
                continue;
            }
            let phi = self.angle_min + l as f64 * self.angle_increment;
            let (s, c) = phi.sin_cos();
            let p = transform_point(to_new, [f64::from(r) * c, f64::from(r) * s]);
            let Some(j) = beam_of(p[1].atan2(p[0])) else {
                continue;
            };
            let r_new = p[0].hypot(p[1]) as f32;
            let cur = self.next_range[j];
            if cur.is_nan() || r_new < cur {
                self.next_range[j] = r_new;
                self.next_weight[j] = self.weight[l];
            }
        }
        for l in 0..n {
            if self.range[l] != f32::INFINITY {
                continue;
            }
            let phi = self.angle_min + l as f64 * self.angle_increment - motion.theta;
            if let Some(j) = beam_of(phi) {
                if self.next_range[j].is_nan() {
                    self.next_range[j] = f32::INFINITY;
                    self.next_weight[j] = self.weight[l];
                }
            }
        }
        // Fill small holes from the nearer neighbour.
        let g = self.config.fill_gap;
        for j in 0..n {
            if !self.next_range[j].is_nan() {
                continue;
            }
            let mut best: Option<usize> = None;
            for d in 1..=g {
                for k in [j.checked_sub(d), j.checked_add(d).filter(|&k| k < n)]
                    .into_iter()
                    .flatten()
                {
                    // Only beams that received a value in the projection itself.
                    if self.range_is_projected(k)
                        && best.is_none_or(|b| self.next_range[k] < self.next_range[b])
                    {
                        best = Some(k);
                    }
                }
                if best.is_some() {
                    break;
                }
            }
            if let Some(k) = best {
                self.next_range[j] = self.next_range[k];
                self.next_weight[j] = self.next_weight[k];
                self.filled_mark(j);
            }
        }
        self.clear_fill_marks();
        std::mem::swap(&mut self.range, &mut self.next_range);
        std::mem::swap(&mut self.weight, &mut self.next_weight);
        Ok(())
    }

    /// True when beam `k` of the propagation buffer holds a projected (not hole-filled, not
    /// empty) value.
    fn range_is_projected(&self, k: usize) -> bool {
        let r = self.next_range[k];
        !r.is_nan() && r.is_sign_positive()
    }

    /// Hole-filled values are stored negated until the filling pass ends, so that they are
    /// not used to fill further holes.
    fn filled_mark(&mut self, j: usize) {
        self.next_range[j] = -self.next_range[j];
    }

    fn clear_fill_marks(&mut self) {
        for r in &mut self.next_range {
            if r.is_sign_negative() && !r.is_nan() {
                *r = -*r;
            }
        }
    }

    /// Compares the scan with the (propagated) background and returns each beam's class.
    /// The first scan only sizes and fills the map: every beam is background. Errors when
    /// the scan's beam count or geometry differs from the first scan's.
    pub fn classify(&mut self, scan: &Scan) -> Result<&[BeamClass]> {
        scan.validate()?;
        let n = scan.len();
        if !self.initialised {
            self.angle_min = scan.angle_min;
            self.angle_increment = scan.angle_increment;
            self.range = (0..n).map(|i| reading(scan, i)).collect();
            self.weight = vec![1; n];
            self.history = vec![f32::NAN; n * HISTORY_LEN];
            self.history_len = vec![0; n];
            self.history_head = vec![0; n];
            self.tolerance = vec![self.config.delta as f32; n];
            self.class = vec![BeamClass::Background; n];
            self.next_range = Vec::with_capacity(n);
            self.next_weight = Vec::with_capacity(n);
            self.initialised = true;
            return Ok(&self.class);
        }
        if n != self.range.len()
            || scan.angle_min != self.angle_min
            || scan.angle_increment != self.angle_increment
        {
            return Err(Error::invalid(
                "background map",
                format!(
                    "scan of {n} beams from {} rad step {} rad does not match the map's {} \
                     beams from {} rad step {} rad",
                    scan.angle_min,
                    scan.angle_increment,
                    self.range.len(),
                    self.angle_min,
                    self.angle_increment
                ),
            ));
        }
        let k = self.config.neighbour_beams;
        for i in 0..n {
            let tau = self.config.delta + self.spread(i).min(self.config.max_spread);
            self.tolerance[i] = tau as f32;
            let rb = f64::from(self.range[i]);
            let r = f64::from(reading(scan, i));
            // The nearest background within ±k beams (NaN = new beams are skipped).
            let near_b = self.range[i.saturating_sub(k)..(i + k + 1).min(n)]
                .iter()
                .filter(|v| !v.is_nan())
                .fold(f64::INFINITY, |m, &v| m.min(f64::from(v)));
            self.class[i] = if rb.is_nan() || (r.is_infinite() && rb.is_infinite()) {
                BeamClass::Background
            } else if r < near_b - tau {
                BeamClass::Foreground
            } else if r < rb - tau {
                BeamClass::Uncertain
            } else if r >= rb + tau {
                BeamClass::Beyond
            } else {
                BeamClass::Background
            };
        }
        Ok(&self.class)
    }

    /// Applies the update rules to the scan last classified. `occluded_by_target[i]` true
    /// keeps the weight of a foreground beam (a verified target hides the background); pass
    /// an empty slice when no target is verified. Must follow [`BackgroundMap::classify`]
    /// with the same scan.
    pub fn update(&mut self, scan: &Scan, occluded_by_target: &[bool]) -> Result<()> {
        let n = self.range.len();
        if scan.len() != n || !(occluded_by_target.is_empty() || occluded_by_target.len() == n) {
            return Err(Error::invalid(
                "background update",
                format!(
                    "scan of {} beams and an occlusion mask of {} for a map of {n} beams",
                    scan.len(),
                    occluded_by_target.len()
                ),
            ));
        }
        let max_w = self.config.max_weight;
        for i in 0..n {
            let r = reading(scan, i);
            match self.class[i] {
                BeamClass::Background => {
                    self.weight[i] = if self.range[i].is_nan() {
                        1
                    } else {
                        (self.weight[i] + 1).min(max_w)
                    };
                    self.range[i] = r;
                }
                BeamClass::Beyond => {
                    self.range[i] = r;
                    self.weight[i] = max_w;
                }
                BeamClass::Uncertain => {}
                BeamClass::Foreground => {
                    if !occluded_by_target.get(i).copied().unwrap_or(false) {
                        self.weight[i] = self.weight[i].saturating_sub(1).max(1);
                        if self.weight[i] == 1 {
                            self.range[i] = r;
                        }
                    }
                }
            }
            let rb = self.range[i];
            self.push_history(i, rb);
        }
        Ok(())
    }

    /// Standard deviation of the finite values among beam `i`'s last ten background
    /// ranges (0 with fewer than two).
    pub fn spread(&self, i: usize) -> f64 {
        let len = self.history_len[i] as usize;
        let h = &self.history[i * HISTORY_LEN..i * HISTORY_LEN + len];
        let (mut n, mut s, mut s2) = (0.0, 0.0, 0.0);
        for &v in h {
            if v.is_finite() {
                let v = f64::from(v);
                n += 1.0;
                s += v;
                s2 += v * v;
            }
        }
        if n < 2.0 {
            return 0.0;
        }
        let mean = s / n;
        ((s2 / n - mean * mean).max(0.0)).sqrt()
    }

    fn push_history(&mut self, i: usize, value: f32) {
        let head = self.history_head[i] as usize;
        self.history[i * HISTORY_LEN + head] = value;
        self.history_head[i] = ((head + 1) % HISTORY_LEN) as u8;
        if (self.history_len[i] as usize) < HISTORY_LEN {
            self.history_len[i] += 1;
        }
    }
}

/// Beam `i`'s reading as the map sees it: the range of a return, `+∞` for "no return".
fn reading(scan: &Scan, i: usize) -> f32 {
    scan.range(i).map_or(f32::INFINITY, |r| r as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 181-beam half-circle scan (1° apart) of a wall 5 m ahead (beam 90 looks straight
    /// at it), ranges computed exactly; optionally a 5-beam object at `range` centred on
    /// `beam`.
    fn wall_scan(person: Option<(usize, f32)>) -> Scan {
        let n = 181;
        let inc = 1f64.to_radians();
        let ranges: Vec<f32> = (0..n)
            .map(|i| {
                let phi = -std::f64::consts::FRAC_PI_2 + i as f64 * inc;
                // Sensor frame x forward = world +y; wall at distance 5 ahead.
                let r = 5.0 / phi.cos();
                if r > 0.0 && r < 25.0 {
                    r as f32
                } else {
                    30.0
                }
            })
            .collect();
        let mut scan =
            Scan::new(0.0, -std::f64::consts::FRAC_PI_2, inc, ranges, 0.0, 30.0).unwrap();
        if let Some((beam, r)) = person {
            for b in beam.saturating_sub(2)..=(beam + 2) {
                scan.ranges[b] = r;
            }
        }
        scan
    }

    #[test]
    fn first_scan_is_background_and_person_is_foreground() {
        let mut map = BackgroundMap::new(BackgroundConfig::default()).unwrap();
        let s0 = wall_scan(None);
        assert!(map
            .classify(&s0)
            .unwrap()
            .iter()
            .all(|c| *c == BeamClass::Background));
        map.update(&s0, &[]).unwrap();
        map.propagate(Pose2::new(0.0, 0.0, 0.0)).unwrap();
        let s1 = wall_scan(Some((90, 2.0)));
        let classes = map.classify(&s1).unwrap().to_vec();
        for (i, c) in classes.iter().enumerate() {
            let expect = if (88..=92).contains(&i) {
                BeamClass::Foreground
            } else {
                BeamClass::Background
            };
            assert_eq!(*c, expect, "beam {i}");
        }
        // δ = 0.4 and a constant history: the tolerance is exactly δ.
        assert!((map.tolerances()[90] - 0.4).abs() < 1e-6);
    }

    #[test]
    fn weights_follow_the_rules() {
        let mut map = BackgroundMap::new(BackgroundConfig::default()).unwrap();
        let s0 = wall_scan(None);
        map.classify(&s0).unwrap();
        map.update(&s0, &[]).unwrap();
        // The first scan leaves weight 2; four more background scans: 6.
        for _ in 0..4 {
            map.propagate(Pose2::new(0.0, 0.0, 0.0)).unwrap();
            map.classify(&s0).unwrap();
            map.update(&s0, &[]).unwrap();
        }
        assert_eq!(map.weights()[90], 6);
        // A person stands at beam 90: weight falls by one per scan; at 1 the person becomes
        // background.
        let s1 = wall_scan(Some((90, 2.0)));
        for expected in [5u8, 4, 3, 2] {
            map.propagate(Pose2::new(0.0, 0.0, 0.0)).unwrap();
            assert_eq!(map.classify(&s1).unwrap()[90], BeamClass::Foreground);
            map.update(&s1, &[]).unwrap();
            assert_eq!(map.weights()[90], expected);
            assert!((map.ranges()[90] - 5.0).abs() < 1e-5);
        }
        // Occluded by a verified target: the weight is kept.
        let mut mask = vec![false; s1.len()];
        mask[90] = true;
        map.propagate(Pose2::new(0.0, 0.0, 0.0)).unwrap();
        map.classify(&s1).unwrap();
        map.update(&s1, &mask).unwrap();
        assert_eq!(map.weights()[90], 2);
        map.propagate(Pose2::new(0.0, 0.0, 0.0)).unwrap();
        map.classify(&s1).unwrap();
        map.update(&s1, &[]).unwrap();
        assert_eq!(map.weights()[90], 1);
        assert!((map.ranges()[90] - 2.0).abs() < 1e-6);
        // The person leaves: the wall is beyond the (renewed) background → weight 20.
        map.propagate(Pose2::new(0.0, 0.0, 0.0)).unwrap();
        assert_eq!(map.classify(&s0).unwrap()[90], BeamClass::Beyond);
        map.update(&s0, &[]).unwrap();
        assert_eq!(map.weights()[90], 20);
        assert!((map.ranges()[90] - 5.0).abs() < 1e-5);
    }

    #[test]
    fn a_full_turn_scanner_keeps_its_background_across_the_seam() {
        // 360 beams 1° apart from bearing 0, inside a round room of radius 5 m: atan2's
        // bearings in (−π, 0) belong to beams 181–359, and a turn carries beams over the seam.
        let inc = 1f64.to_radians();
        let scan = Scan::new(0.0, 0.0, inc, vec![5.0; 360], 0.0, 30.0).unwrap();
        let mut map = BackgroundMap::new(BackgroundConfig::default()).unwrap();
        map.classify(&scan).unwrap();
        map.update(&scan, &[]).unwrap();
        for turn in [0.0, 10.0, -25.0] {
            map.propagate(Pose2::new(0.0, 0.0, f64::to_radians(turn)))
                .unwrap();
            assert!(
                map.ranges().iter().all(|r| (r - 5.0).abs() < 1e-4),
                "turn {turn}°: {:?}",
                map.ranges()
                    .iter()
                    .enumerate()
                    .filter(|(_, r)| r.is_nan() || (*r - 5.0).abs() >= 1e-4)
                    .take(5)
                    .collect::<Vec<_>>()
            );
            assert!(map
                .classify(&scan)
                .unwrap()
                .iter()
                .all(|c| *c == BeamClass::Background));
            map.update(&scan, &[]).unwrap();
        }
    }

    #[test]
    fn propagation_follows_the_sensor() {
        // Drive 1 m towards the wall: the background must shrink to the new exact ranges.
        let mut map = BackgroundMap::new(BackgroundConfig::default()).unwrap();
        let s0 = wall_scan(None);
        map.classify(&s0).unwrap();
        map.update(&s0, &[]).unwrap();
        map.propagate(Pose2::new(1.0, 0.0, 0.0)).unwrap();
        // Beam 90 looks straight at the wall: 4 m now. Beam 90 ± 30: 4 / cos 30°.
        assert!((map.ranges()[90] - 4.0).abs() < 1e-4);
        let expect = 4.0 / 30f64.to_radians().cos();
        assert!((f64::from(map.ranges()[120]) - expect).abs() < 0.05);
        // No beam inside ±60° stays empty.
        assert!(map.ranges()[30..=150].iter().all(|r| !r.is_nan()));
        // A pure turn by one beam shifts the map by one beam.
        map.propagate(Pose2::new(0.0, 0.0, 1f64.to_radians()))
            .unwrap();
        assert!((map.ranges()[89] - 4.0).abs() < 1e-4);
    }

    #[test]
    fn spread_is_the_history_standard_deviation() {
        let mut map = BackgroundMap::new(BackgroundConfig::default()).unwrap();
        let s0 = wall_scan(None);
        map.classify(&s0).unwrap();
        map.update(&s0, &[]).unwrap();
        // History of beam 90: 5, then 5.3 (within δ, so it becomes the background).
        let mut s = s0.clone();
        s.ranges[90] = 5.3;
        map.propagate(Pose2::new(0.0, 0.0, 0.0)).unwrap();
        map.classify(&s).unwrap();
        map.update(&s, &[]).unwrap();
        let sd = 0.15;
        assert!((map.spread(90) - sd).abs() < 1e-5);
        assert!(map
            .classify(&wall_scan(None))
            .is_ok_and(|c| c[90] == BeamClass::Background));
    }
}
