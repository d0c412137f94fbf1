//! Object classes of lidar clusters: a per-frame class likelihood from a fitted box (its
//! footprint sides, its height above the ground), the point count against the count expected
//! at that range for an object of that class, and optionally the speed and the angle between
//! the seen long side and the direction of travel; and [`ClassBelief`], the categorical
//! posterior a track keeps and updates each frame.
//!
//! Every number below states its source. Class sizes are the mean KITTI label dimensions
//! (length, width, height) of the object benchmark's training set as used for the size
//! clusters of Frustum PointNets (Qi et al., CVPR 2018, `g_type_mean_size`); their spreads
//! come from the labels shipped in this project's data (the 21 Car labels of KITTI object
//! frames 000000–000009: σ = 0.47, 0.10, 0.10 m; the one van labelled 95 times in tracking
//! sequence 0000: σ_l = 0.55 m, which is the labellers' own spread) and from the common range
//! of vehicle sizes where those few labels cannot tell (trucks from 6 m rigid lorries to
//! 12 m; van roofs 1.9–2.6 m; adult stature σ ≈ 0.07–0.09 m, widened for posture). A fitted
//! side is compared with the class size with the label spread and a fitting error of
//! [`ClassModel::fit_sigma`] added in quadrature.
//!
//! The sides a lidar sees are at most the object's: a side may be short because the far faces
//! are hidden or the object is occluded. Each side's likelihood is therefore a mixture of a
//! whole view (Gaussian about the class size) and a partial view (uniform from 0 to the class
//! size), with equal weights for the footprint and 0.8/0.2 for the height (the top is nearly
//! always in view of a roof-mounted scanner; only the bottom is cut by ground removal, and the
//! height is measured from the ground when it is known). The fit reports its footprint sides
//! sorted, and the longer seen side is not always the length: a car seen end-on shows its
//! width whole and a sliver of its side. The footprint's density is therefore that of the
//! sorted pair, both assignments of the seen sides to length and width added.
//!
//! `Other` (everything a clusterer returns that is no road user) has by default the density
//! learned from KITTI clusters that lie in no label box ([`super::other_class`], a Gaussian
//! mixture over log sides, height and log point density); the former uniform density over
//! [0, 20] × [0, 6] × [0, 6] m and ln(points) stays selectable ([`OtherModel::Uniform`]).
//!
//! The height profile enters through the top's height above the ground; the height of the
//! point mass ([`BoxFit::mass_height`]) is kept by the fit but not used here, for want of
//! published per-class statistics to set its likelihood from.
//!
//! Not for: fitting the box (see [`super::boxes`]), tracking (the track's motion enters only
//! through the optional speed), or KITTI's label types (see [`crate::kitti::labels`]).

use super::boxes::{BoxFit, SizePrior};
use super::other_class::OtherDensity;
use crate::error::{ensure_non_negative, ensure_probability, Error, Result};
use std::f64::consts::{FRAC_2_PI, PI};

/// The classes a cluster track is given.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ObjectClass {
    /// Passenger car.
    Car,
    /// Van, minibus, camper.
    Van,
    /// Lorry, bus.
    Truck,
    /// Walking or standing person.
    Pedestrian,
    /// Person on a bicycle.
    Cyclist,
    /// Anything else: poles, trees, walls' pieces, clutter.
    Other,
}

/// Number of classes.
pub const CLASS_COUNT: usize = 6;

/// Mean label size (length, width, height, m) and its spread per road-user class; see the
/// module notes for the sources.
const SIZES: [([f64; 3], [f64; 3]); 5] = [
    // Car: Frustum PointNets' KITTI mean; σ from the 21 local Car labels, σ_h widened to
    // 0.13 for the hatchback-to-SUV range.
    ([3.883, 1.629, 1.526], [0.45, 0.10, 0.13]),
    // Van: KITTI mean; σ_l from the labelled van of tracking sequence 0000, σ_h for roofs of
    // 1.9–2.6 m.
    ([5.068, 1.901, 2.205], [0.55, 0.12, 0.20]),
    // Truck: KITTI mean (one local label: 12.3 × 2.6 × 2.9); lorries 6–12 m long, 2.5–2.6 m
    // wide, 2.6–4 m high.
    ([10.136, 2.585, 3.252], [2.50, 0.15, 0.45]),
    // Pedestrian: KITTI mean; the footprint of a walking person varies with the stride
    // (the local labels: 0.84–1.20 m long, 0.48–0.96 m wide).
    ([0.844, 0.661, 1.763], [0.25, 0.15, 0.11]),
    // Cyclist: KITTI mean; bicycles are 1.6–1.9 m long, riders' height varies as above.
    ([1.763, 0.597, 1.737], [0.25, 0.15, 0.12]),
];

impl ObjectClass {
    /// Every class, in index order.
    pub const ALL: [ObjectClass; CLASS_COUNT] = [
        ObjectClass::Car,
        ObjectClass::Van,
        ObjectClass::Truck,
        ObjectClass::Pedestrian,
        ObjectClass::Cyclist,
        ObjectClass::Other,
    ];

    /// Position in [`ALL`](Self::ALL) and in likelihood and probability arrays.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The name, as KITTI writes the corresponding types (`Other` for the rest).
    pub fn name(self) -> &'static str {
        match self {
            ObjectClass::Car => "Car",
            ObjectClass::Van => "Van",
            ObjectClass::Truck => "Truck",
            ObjectClass::Pedestrian => "Pedestrian",
            ObjectClass::Cyclist => "Cyclist",
            ObjectClass::Other => "Other",
        }
    }

    /// Whether the class is a road user (reported as such even when parked or standing).
    pub fn is_road_user(self) -> bool {
        self != ObjectClass::Other
    }

    /// Mean size `[length, width, height]` (m) of the class; `None` for `Other`.
    pub fn mean_size(self) -> Option<[f64; 3]> {
        SIZES.get(self.index()).map(|s| s.0)
    }

    /// The footprint the visible-face model extends a fitted box to (the class's mean length
    /// and width, which minimise the expected centre error); `None` for `Other`, whose boxes
    /// are left as fitted.
    pub fn size_prior(self) -> Option<SizePrior> {
        self.mean_size().map(|[l, w, _]| SizePrior {
            length: l,
            width: w,
        })
    }
}

impl std::fmt::Display for ObjectClass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What the class likelihood looks at.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ClassFeatures {
    /// Longer footprint side of the fitted box (m).
    pub length: f64,
    /// Shorter footprint side (m).
    pub width: f64,
    /// Height of the highest point above the ground (or above the lowest point) (m).
    pub height: f64,
    /// Range of the box centre from the sensor in the x–y plane (m).
    pub range: f64,
    /// Number of points.
    pub points: usize,
    /// Speed over ground (m/s), when a tracker knows it.
    pub speed: Option<f64>,
    /// Angle (rad, in [0, π/2]) between the fitted footprint's longer side and the direction
    /// of travel, when a tracker knows that direction and the footprint is elongated (see
    /// the private `travel_ll`).
    pub travel_angle: Option<f64>,
}

impl ClassFeatures {
    /// The features of a box fit: the fitted (not extended) footprint, the estimated box's
    /// height (from the ground when the fit was given one).
    pub fn from_fit(fit: &BoxFit, speed: Option<f64>) -> Self {
        let [a, b, _] = fit.fitted.size;
        Self {
            length: a.max(b),
            width: a.min(b),
            height: fit.estimated.size[2],
            range: fit.range,
            points: fit.points,
            speed,
            travel_angle: None,
        }
    }
}

/// The parameters of the per-frame likelihood.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ClassModel {
    /// Error of a fitted side or height against the label (m), added in quadrature to the
    /// class spread: about two azimuth steps of the scanner at 20 m (2 × 0.0031 rad × 20 m ≈
    /// 0.12 m) plus range noise (≈ 0.02 m for an HDL-64E).
    pub fit_sigma: f64,
    /// Azimuth spacing of the scanner's points (rad). Default [`super::HDL64E_AZIMUTH_STEP`].
    pub azimuth_step: f64,
    /// Elevation spacing of the scanner's lasers (rad): 26.9° over 64 lasers for the HDL-64E.
    pub elevation_step: f64,
    /// Fraction of the beams hitting an object that return a point (dark paint and glass
    /// return less); 0.8 is a middle value, the spread below absorbs the rest.
    pub return_fraction: f64,
    /// Spread of ln(points) about the expected count for a whole view: a factor of e^0.6 ≈ 1.8
    /// covers the silhouette's change with aspect (end-on vs side-on, ×2.4 for a car).
    pub log_count_sigma: f64,
    /// Size range of `Other` (m): uniform over [0, this] for length, width and height, the
    /// span of street furniture, vegetation and wall pieces a clusterer returns.
    pub other_extent: [f64; 3],
    /// Largest count of points a cluster of `Other` has (uniform in ln count up to it).
    pub other_max_points: f64,
    /// Which density the `Other` class has.
    pub other_model: OtherModel,
}

/// The density of the `Other` class's features.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum OtherModel {
    /// Uniform over [0, [`ClassModel::other_extent`]] in the sides and height and over
    /// [0, ln [`ClassModel::other_max_points`]] in ln(points): no knowledge of clutter.
    Uniform,
    /// The Gaussian mixture fitted on KITTI clusters outside every label box
    /// ([`super::other_class`]).
    Learned,
}

impl Default for ClassModel {
    fn default() -> Self {
        Self {
            fit_sigma: 0.15,
            azimuth_step: super::HDL64E_AZIMUTH_STEP,
            elevation_step: 26.9f64.to_radians() / 64.0,
            return_fraction: 0.8,
            log_count_sigma: 0.6,
            other_extent: [20.0, 6.0, 6.0],
            other_max_points: 1e5,
            other_model: OtherModel::Learned,
        }
    }
}

fn ln_normal(x: f64, mean: f64, sigma: f64) -> f64 {
    let z = (x - mean) / sigma;
    -0.5 * z * z - sigma.ln() - 0.5 * (2.0 * PI).ln()
}

/// ln of a mixture: `w` × normal(mean, sigma) + (1 − w) × uniform on [0, mean].
fn ln_seen_or_partial(x: f64, mean: f64, sigma: f64, w: f64) -> f64 {
    let whole = w * ln_normal(x, mean, sigma).exp();
    let partial = if (0.0..=mean).contains(&x) {
        (1.0 - w) / mean
    } else {
        0.0
    };
    (whole + partial).max(f64::MIN_POSITIVE).ln()
}

/// ln of the density of a footprint whose seen sides are `longer` ≥ `shorter`, for an object
/// of footprint `size` (length, width) with the sides' spreads `sigma`. Each seen side is
/// whole or partial ([`ln_seen_or_partial`], even odds); the fit reports the two sides sorted,
/// and the sorted pair has the density of both ways of getting it: the longer seen side is
/// the length and the shorter the width, or the longer is the width and the shorter a part
/// of the length (a car seen end-on, its rear 1.6 m wide and a sliver of its side 0.6 m
/// deep). The density of `Other` is one over sorted sides too ([`super::other_class`]).
fn ln_footprint(longer: f64, shorter: f64, size: [f64; 2], sigma: [f64; 2]) -> f64 {
    let seen = |along: f64, across: f64| {
        ln_seen_or_partial(along, size[0], sigma[0], 0.5)
            + ln_seen_or_partial(across, size[1], sigma[1], 0.5)
    };
    let (a, b) = (seen(longer, shorter), seen(shorter, longer));
    a.max(b) + (-(a - b).abs()).exp().ln_1p()
}

/// ln of a half-normal density with scale `sigma` at `v ≥ 0`.
fn ln_half_normal(v: f64, sigma: f64) -> f64 {
    ln_normal(v, 0.0, sigma) + 2f64.ln()
}

impl ClassModel {
    /// Points expected on an object of size `[l, w, h]` at `range`: the scanner's point
    /// density at that range, 1 / (r² Δφ Δθ), times the mean silhouette area over headings,
    /// (2/π)(l + w)·h (the mean projected width of an l × w rectangle), times the return
    /// fraction.
    pub fn expected_points(&self, size: [f64; 3], range: f64) -> f64 {
        let r = range.max(1.0);
        let density = 1.0 / (r * r * self.azimuth_step * self.elevation_step);
        density * FRAC_2_PI * (size[0] + size[1]) * size[2] * self.return_fraction
    }

    /// ln p(features | class) for every class, in [`ObjectClass::ALL`] order (up to a common
    /// constant). Fails on non-finite or negative features.
    pub fn log_likelihoods(&self, f: &ClassFeatures) -> Result<[f64; CLASS_COUNT]> {
        for (what, v) in [
            ("class feature length", f.length),
            ("class feature width", f.width),
            ("class feature height", f.height),
            ("class feature range", f.range),
        ] {
            ensure_non_negative(what, v)?;
        }
        if let Some(s) = f.speed {
            ensure_non_negative("class feature speed", s)?;
        }
        if let Some(a) = f.travel_angle {
            if !(0.0..=std::f64::consts::FRAC_PI_2).contains(&a) {
                return Err(Error::invalid(
                    "class feature travel_angle",
                    format!("{a} (must lie in [0, π/2])"),
                ));
            }
        }
        if f.points == 0 {
            return Err(Error::invalid(
                "class feature points",
                "0 (need at least one)",
            ));
        }
        let ln_n = (f.points as f64).ln();
        let mut out = [0.0; CLASS_COUNT];
        for (k, &(mean, sd)) in SIZES.iter().enumerate() {
            let s = |i: usize| sd[i].hypot(self.fit_sigma);
            let mut ll = ln_footprint(f.length, f.width, [mean[0], mean[1]], [s(0), s(1)])
                + ln_seen_or_partial(f.height, mean[2], s(2), 0.8);
            let expected = self.expected_points(mean, f.range).max(1.0);
            ll += ln_seen_or_partial(ln_n, expected.ln(), self.log_count_sigma, 0.5);
            if let Some(v) = f.speed {
                ll += speed_ll(ObjectClass::ALL[k], v);
            }
            if let Some(a) = f.travel_angle {
                ll += travel_ll(ObjectClass::ALL[k], a);
            }
            out[k] = ll;
        }
        let mut other = match self.other_model {
            OtherModel::Uniform => {
                let [lx, wx, hx] = self.other_extent;
                let uniform = |x: f64, top: f64| if x <= top { -top.ln() } else { -1e3 };
                uniform(f.length, lx)
                    + uniform(f.width, wx)
                    + uniform(f.height, hx)
                    + uniform(ln_n, self.other_max_points.ln())
            }
            OtherModel::Learned => {
                let unit = self.expected_points([1.0; 3], f.range).ln();
                OtherDensity::embedded()?.ln_density(f.length, f.width, f.height, ln_n, unit)
            }
        };
        if let Some(v) = f.speed {
            other += speed_ll(ObjectClass::Other, v);
        }
        if let Some(a) = f.travel_angle {
            other += travel_ll(ObjectClass::Other, a);
        }
        out[ObjectClass::Other.index()] = other;
        Ok(out)
    }

    /// The most likely class of one frame's features under `prior` (probabilities in
    /// [`ObjectClass::ALL`] order).
    pub fn classify(&self, f: &ClassFeatures, prior: &[f64; CLASS_COUNT]) -> Result<ObjectClass> {
        let mut b = ClassBelief::new(*prior)?;
        b.update(&self.log_likelihoods(f)?, 0.0)?;
        Ok(b.most_likely())
    }
}

/// A class's density of speed over ground (m/s).
#[derive(Copy, Clone, Debug)]
enum SpeedModel {
    /// Uniform on [0, max].
    Uniform(f64),
    /// Half-normal with this scale.
    HalfNormal(f64),
}

/// The speed model of each class. Vehicles: uniform on [0, 40 m/s] (parked to motorway).
/// Pedestrians: half-normal, σ = 1.5 m/s (walking 1.2–1.5 m/s, running ≈ 4 m/s at 2.7σ).
/// Cyclists: half-normal, σ = 5 m/s (cruising 4–7 m/s). Other: half-normal, σ = 1 m/s
/// (static; the scale allows for the tracker's velocity noise).
fn speed_model(class: ObjectClass) -> SpeedModel {
    match class {
        ObjectClass::Car | ObjectClass::Van | ObjectClass::Truck => SpeedModel::Uniform(40.0),
        ObjectClass::Pedestrian => SpeedModel::HalfNormal(1.5),
        ObjectClass::Cyclist => SpeedModel::HalfNormal(5.0),
        ObjectClass::Other => SpeedModel::HalfNormal(1.0),
    }
}

/// ln p(speed | class) of [`speed_model`] (−1000 above a uniform's range).
fn speed_ll(class: ObjectClass, v: f64) -> f64 {
    match speed_model(class) {
        SpeedModel::Uniform(max) => {
            if v <= max {
                -(max.ln())
            } else {
                -1e3
            }
        }
        SpeedModel::HalfNormal(sigma) => ln_half_normal(v, sigma),
    }
}

/// ln p(speed | class) for every class, in [`ObjectClass::ALL`] order, when the speed is
/// known only through weighted samples of its posterior (`(speed, weight)` pairs, e.g. a
/// track's particles): ln of the weighted mean of each class's speed density over the
/// samples (see the private `speed_ll`), the evidence the track's measurements give about
/// the class through its motion when the filter's velocity prior is broad. A young track's
/// velocity is mostly its birth spread and a few noisy box centres, so its mean speed can
/// be several m/s for a static object; the density at that mean would call it a mover with
/// certainty, while the average over the posterior keeps the static hypothesis as likely as
/// the samples near zero make it. One sample of weight 1 gives the density at that speed.
/// Fails on an empty sample, a non-finite or negative speed, or weights that do not sum to a
/// positive finite value.
pub fn speed_log_likelihoods(
    samples: impl IntoIterator<Item = (f64, f64)>,
) -> Result<[f64; CLASS_COUNT]> {
    let mut sum = [0.0; CLASS_COUNT];
    let mut total = 0.0;
    for (v, w) in samples {
        ensure_non_negative("speed sample", v)?;
        ensure_non_negative("speed sample weight", w)?;
        if w == 0.0 {
            continue;
        }
        total += w;
        for (k, d) in speed_densities(v).iter().enumerate() {
            sum[k] += w * d;
        }
    }
    if !(total > 0.0 && total.is_finite()) {
        return Err(Error::invalid(
            "speed samples",
            format!("total weight {total} (need a positive finite sum)"),
        ));
    }
    Ok(sum.map(|x| (x / total).max(f64::MIN_POSITIVE).ln()))
}

/// p(speed | class) of [`speed_model`] for every class at speed `v` ≥ 0, in
/// [`ObjectClass::ALL`] order: the densities of [`speed_ll`] without the logarithm.
fn speed_densities(v: f64) -> [f64; CLASS_COUNT] {
    ObjectClass::ALL.map(|c| match speed_model(c) {
        SpeedModel::Uniform(max) => {
            if v <= max {
                1.0 / max
            } else {
                0.0
            }
        }
        SpeedModel::HalfNormal(sigma) => {
            let z = v / sigma;
            (2.0 / (sigma * (2.0 * PI).sqrt())) * (-0.5 * z * z).exp()
        }
    })
}

/// Spread of the angle between a footprint's seen long side and the side it lies along
/// (rad): the L-shape heading's error on a partly seen object, about 15°.
const TRAVEL_SIGMA: f64 = 15.0 * PI / 180.0;

/// ln p(travel angle | class), the angle `a` ∈ [0, π/2] between the seen footprint's longer
/// side and the direction of travel. A cyclist's long side is its length, along its travel:
/// half-normal about 0 with [`TRAVEL_SIGMA`], and a tenth uniform for odd fits. A vehicle
/// shows its length (a side in view, about 0) or only its width (seen end-on, about π/2),
/// half and half. A pedestrian's footprint has no long side to speak of and `Other` no
/// travel: uniform.
fn travel_ll(class: ObjectClass, a: f64) -> f64 {
    let uniform = FRAC_2_PI;
    let near = |x: f64| ln_half_normal(x, TRAVEL_SIGMA).exp();
    let p = match class {
        ObjectClass::Cyclist => 0.9 * near(a) + 0.1 * uniform,
        ObjectClass::Car | ObjectClass::Van | ObjectClass::Truck => {
            0.5 * near(a) + 0.5 * near(std::f64::consts::FRAC_PI_2 - a)
        }
        ObjectClass::Pedestrian | ObjectClass::Other => uniform,
    };
    p.max(f64::MIN_POSITIVE).ln()
}

/// Prior class probabilities: the road users in the proportions of KITTI's object training
/// labels (Car 28,742; Van 2,914; Truck 1,094; Pedestrian 4,487 + Person_sitting 222;
/// Cyclist 1,627, as the benchmark's label statistics report them; the ten local frames have
/// 21 cars of 27 road users, the same share), and `Other` at 1/2: how many clusters are not
/// road users depends on the clusterer and the street, so the prior takes no side.
pub fn default_prior() -> [f64; CLASS_COUNT] {
    let counts = [28_742.0, 2_914.0, 1_094.0, 4_709.0, 1_627.0];
    let total: f64 = counts.iter().sum();
    let mut p = [0.5; CLASS_COUNT];
    for (k, c) in counts.iter().enumerate() {
        p[k] = 0.5 * c / total;
    }
    p
}

/// A categorical posterior over the classes, updated each frame by Bayes' rule after a small
/// step towards the prior (forgetting), so that a wrong early frame can be outvoted.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ClassBelief {
    prior: [f64; CLASS_COUNT],
    p: [f64; CLASS_COUNT],
}

/// Default forgetting per frame: 2 % of the mass goes back to the prior, so evidence older
/// than ≈ 50 frames (5 s at KITTI's 10 Hz) fades.
pub const DEFAULT_FORGETTING: f64 = 0.02;

/// Weight of the shape evidence of each frame after a track's first (its log-likelihoods are
/// multiplied by it) in the track's class belief. Consecutive scans of one object are alike:
/// the same faces in view, the same occluders, nearly the same range. The per-frame class
/// log-likelihood ratios (each road-user class against `Other`) of a track, taken about the
/// track's own mean, have a lag-one autocorrelation ρ of 0.27–0.51 on the 172 tracks of ten
/// or more frames of KITTI tracking sequence 0000, frames 0–49, and 0.29–0.53 on 117 tracks
/// of eight simulated street sequences (pooled over tracks, per class). n values of a first-order
/// autoregressive sequence with correlation ρ inform as much as n² / (n + 2·Σₖ (n − k)·ρᵏ)
/// independent ones: 1 for the first value, then about (1 − ρ)/(1 + ρ) for each further one
/// (0.40, 0.37, 0.37, … → 0.40 for ρ = 0.43, the middle of both ranges). So a track's first
/// frame counts in full and each later one with 0.4.
pub const FRAME_EVIDENCE_WEIGHT: f64 = 0.4;

/// Most that one frame's shape evidence may favour a class over another (nats, before
/// [`FRAME_EVIDENCE_WEIGHT`]): ln(1/ε) for ε = e⁻³ ≈ 5 %. A frame's cluster is sometimes not
/// the object alone: a parked car merged with a pole or a tree trunk within the clusterer's
/// reach, a neighbour joined, a face cut by an occluder. With a share ε of such frames, whose
/// features say nothing of the class, a frame's likelihood under class k is at least ε times
/// the best class's, so its log-likelihoods lie within ln(1/ε) of the best
/// ([`cap_frame_evidence`]). On KITTI tracking sequence 0000's frames 0–49 (road users,
/// bird's-eye 2 m, tracker seeds 1–12) HOTA went 0.627 → 0.649, MOTA 0.518 → 0.539, recall
/// 0.896 → 0.918; on the simulated city street with poles 0.4 m behind the kerb (parked cars
/// and poles merged) Car HOTA 0.682 → 0.709 (22 sequences, seed 1). It costs a little where
/// frames are clean: the default city street (seeds 1–3) Car HOTA 0.748 → 0.743, Pedestrian
/// HOTA 0.462 → 0.453 and MOTA 0.257 → 0.232 (a pedestrian's belief leaves `Other` more
/// slowly); the plain street Car 0.817 → 0.816, Pedestrian 0.750 → 0.749.
pub const FRAME_EVIDENCE_CAP: f64 = 3.0;

/// One frame's class log-likelihoods with each raised to at least the best one less
/// [`FRAME_EVIDENCE_CAP`] (see there). The order of the classes is kept; only how far a
/// single frame can move a belief is bounded.
pub fn cap_frame_evidence(ll: [f64; CLASS_COUNT]) -> [f64; CLASS_COUNT] {
    let best = ll.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    ll.map(|l| l.max(best - FRAME_EVIDENCE_CAP))
}

impl ClassBelief {
    /// A belief equal to `prior` (non-negative, normalised here; fails when it sums to 0 or
    /// has a non-finite entry).
    pub fn new(prior: [f64; CLASS_COUNT]) -> Result<Self> {
        let sum: f64 = prior.iter().sum();
        if !(sum.is_finite() && sum > 0.0) || prior.iter().any(|&v| v < 0.0) {
            return Err(Error::invalid(
                "class prior",
                format!("{prior:?} (must be non-negative with a positive finite sum)"),
            ));
        }
        let p = prior.map(|v| v / sum);
        Ok(Self { prior: p, p })
    }

    /// One frame: p ← (1 − forgetting)·p + forgetting·prior, then p ∝ p·exp(ll). Fails on
    /// a forgetting outside [0, 1] or a NaN log-likelihood (−∞ is allowed: that class is
    /// ruled out for this frame; if every class is, the belief is left unchanged by the
    /// likelihood).
    pub fn update(&mut self, ll: &[f64; CLASS_COUNT], forgetting: f64) -> Result<()> {
        ensure_probability("class forgetting", forgetting)?;
        if ll.iter().any(|v| v.is_nan() || *v == f64::INFINITY) {
            return Err(Error::invalid(
                "class log-likelihoods",
                format!("{ll:?} (NaN or +∞)"),
            ));
        }
        for k in 0..CLASS_COUNT {
            self.p[k] = (1.0 - forgetting) * self.p[k] + forgetting * self.prior[k];
        }
        let top = ll.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        if top == f64::NEG_INFINITY {
            return Ok(());
        }
        let mut post = [0.0; CLASS_COUNT];
        for k in 0..CLASS_COUNT {
            post[k] = self.p[k] * (ll[k] - top).exp();
        }
        let sum: f64 = post.iter().sum();
        if sum > 0.0 {
            self.p = post.map(|v| v / sum);
        }
        Ok(())
    }

    /// The class of highest probability (the first on ties).
    pub fn most_likely(&self) -> ObjectClass {
        let mut best = 0;
        for k in 1..CLASS_COUNT {
            if self.p[k] > self.p[best] {
                best = k;
            }
        }
        ObjectClass::ALL[best]
    }

    /// Probabilities in [`ObjectClass::ALL`] order (summing to 1).
    pub fn probabilities(&self) -> [f64; CLASS_COUNT] {
        self.p
    }

    /// Probability of one class.
    pub fn probability(&self, class: ObjectClass) -> f64 {
        self.p[class.index()]
    }
}

impl Default for ClassBelief {
    fn default() -> Self {
        let p = default_prior();
        Self { prior: p, p }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        #[test]
        fn a_capped_frame_keeps_its_best_class_and_moves_no_pair_beyond_the_cap(
            ll in proptest::array::uniform6(-60.0f64..10.0)
        ) {
            let c = cap_frame_evidence(ll);
            let best = ll.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            for (a, b) in ll.iter().zip(&c) {
                // Within the cap of the best: unchanged; below it: raised to it.
                proptest::prop_assert_eq!(*b, a.max(best - FRAME_EVIDENCE_CAP));
            }
            for i in 0..CLASS_COUNT {
                for j in 0..CLASS_COUNT {
                    proptest::prop_assert!(c[i] - c[j] <= FRAME_EVIDENCE_CAP + 1e-12);
                    // The order of any two classes is kept (ties may appear, never swaps).
                    if ll[i] > ll[j] {
                        proptest::prop_assert!(c[i] >= c[j]);
                    }
                }
            }
        }
    }

    #[test]
    fn a_merged_frame_cannot_undo_a_settled_belief_in_one_step() {
        // A belief settled on Car at 0.99; one frame whose evidence favours Van by 12 nats
        // (a parked car merged with a pole) would flip it, the capped one does not.
        let mut prior = [0.002; CLASS_COUNT];
        prior[ObjectClass::Car.index()] = 0.99;
        let mut ll = [0.0; CLASS_COUNT];
        ll[ObjectClass::Van.index()] = 12.0;
        let mut raw = ClassBelief::new(prior).unwrap();
        raw.update(&ll, 0.0).unwrap();
        assert_eq!(raw.most_likely(), ObjectClass::Van);
        let mut capped = ClassBelief::new(prior).unwrap();
        capped.update(&cap_frame_evidence(ll), 0.0).unwrap();
        assert_eq!(capped.most_likely(), ObjectClass::Car);
    }

    fn features(l: f64, w: f64, h: f64, range: f64, points: usize) -> ClassFeatures {
        ClassFeatures {
            length: l,
            width: w,
            height: h,
            range,
            points,
            speed: None,
            travel_angle: None,
        }
    }

    fn best(f: &ClassFeatures) -> ObjectClass {
        ClassModel::default().classify(f, &default_prior()).unwrap()
    }

    #[test]
    fn typical_objects_get_their_class() {
        // Sizes from common knowledge, not from the table: a VW Golf (4.26 × 1.80 × 1.48), a
        // Mercedes Sprinter (5.9 × 2.0 × 2.4), a 12 m lorry, an adult, an adult on a bicycle.
        // Point counts: what a 20 m-away object gets from the scanner (hand arithmetic:
        // 1/(400·0.0031·0.0073) ≈ 110 points/m², × 0.8 × silhouette).
        assert_eq!(
            best(&features(4.26, 1.80, 1.48, 20.0, 350)),
            ObjectClass::Car
        );
        assert_eq!(best(&features(5.9, 2.0, 2.4, 20.0, 700)), ObjectClass::Van);
        assert_eq!(
            best(&features(12.0, 2.55, 3.6, 20.0, 2500)),
            ObjectClass::Truck
        );
        assert_eq!(
            best(&features(0.6, 0.5, 1.75, 20.0, 100)),
            ObjectClass::Pedestrian
        );
        assert_eq!(
            best(&features(1.8, 0.6, 1.75, 20.0, 150)),
            ObjectClass::Cyclist
        );
        // A lamp post and a 9 m wall piece fit no road user.
        assert_eq!(
            best(&features(0.3, 0.3, 4.5, 10.0, 300)),
            ObjectClass::Other
        );
        assert_eq!(
            best(&features(9.0, 0.3, 1.2, 10.0, 3000)),
            ObjectClass::Other
        );
    }

    #[test]
    fn the_sorted_footprint_density_integrates_to_one() {
        // The density of the sorted seen sides (longer, shorter) over longer ≥ shorter ≥ 0,
        // integrated by the midpoint rule on a 2 cm grid: each seen side is a density on
        // [0, ∞) up to the Gaussian's tail below 0, so the sorted pair's total is 1 less that
        // tail. With only the first ordering it was 0.85 for a car, 0.62 for a pedestrian.
        for (size, sigma) in [([3.9, 1.6], [0.47, 0.18]), ([0.84, 0.66], [0.29, 0.21])] {
            let h = 0.02;
            let mut total = 0.0;
            for i in 0..600 {
                let a = (i as f64 + 0.5) * h;
                for j in 0..=i {
                    let b = (j as f64 + 0.5) * h;
                    let w = if i == j { 0.5 } else { 1.0 };
                    total += w * ln_footprint(a, b, size, sigma).exp() * h * h;
                }
            }
            assert!((total - 1.0).abs() < 0.03, "{size:?}: {total}");
        }
    }

    #[test]
    fn a_car_seen_end_on_is_a_car() {
        // The rear of a car 20 m ahead (1.65 m wide, 1.45 m high) and 0.6 m of its sides: the
        // fit's longer side is the car's width. Points: ≈ 110 points/m² at 20 m (see above) ×
        // 0.8 × 1.65 m × 1.45 m ≈ 210.
        assert_eq!(
            best(&features(1.65, 0.6, 1.45, 20.0, 210)),
            ObjectClass::Car
        );
    }

    #[test]
    fn clutter_and_road_users_at_ten_metres() {
        // Sizes from common knowledge: a lamp or sign pole, a piece of hedge, an adult, a
        // VW Golf. Point counts: ≈ 440 points/m² at 10 m (1/(100 · 0.0031 · 0.0073)) times
        // 0.8 and the mean silhouette (2/π)(l + w)h (pole ≈ 540, hedge ≈ 1,020, adult ≈ 550,
        // car ≈ 1,900), rounded down for dark or porous targets (foliage returns about half).
        // A hedge piece as dense as a solid surface (≥ 900 points here) is a partly seen car
        // for one frame's evidence: its sides and height fit a car's partial view.
        let pole = features(0.3, 0.3, 4.0, 10.0, 250);
        let hedge = features(3.0, 0.8, 1.2, 10.0, 600);
        let person = features(0.8, 0.6, 1.75, 10.0, 450);
        let car = features(4.2, 1.7, 1.5, 10.0, 1800);
        assert_eq!(best(&pole), ObjectClass::Other);
        assert_eq!(best(&hedge), ObjectClass::Other);
        assert_eq!(best(&person), ObjectClass::Pedestrian);
        assert_eq!(best(&car), ObjectClass::Car);
        // Under the uniform Other model the hedge piece is not recognised as clutter.
        let uniform = ClassModel {
            other_model: OtherModel::Uniform,
            ..ClassModel::default()
        };
        let ll = uniform.log_likelihoods(&hedge).unwrap();
        let learned = ClassModel::default().log_likelihoods(&hedge).unwrap();
        let other = ObjectClass::Other.index();
        assert!(learned[other] > ll[other]);
    }

    #[test]
    fn expected_points_by_hand() {
        let m = ClassModel::default();
        // 1 / (10² · 0.0031 · (26.9°/64 in rad)) · (2/π)(4 + 2)·1.5 · 0.8.
        let dens = 1.0 / (100.0 * 0.0031 * (26.9 / 64.0 * PI / 180.0));
        let want = dens * (2.0 / PI) * 6.0 * 1.5 * 0.8;
        assert!((m.expected_points([4.0, 2.0, 1.5], 10.0) - want).abs() < 1e-9 * want);
        // Quadratic fall-off.
        let ratio =
            m.expected_points([4.0, 2.0, 1.5], 10.0) / m.expected_points([4.0, 2.0, 1.5], 20.0);
        assert!((ratio - 4.0).abs() < 1e-12);
    }

    #[test]
    fn speed_evidence_averages_the_class_densities_over_the_samples() {
        // Reference values by hand: half-normal 2·N(v; 0, σ), vehicles uniform on [0, 40].
        let idx = |c: ObjectClass| c.index();
        let one = speed_log_likelihoods([(2.0, 1.0)]).unwrap();
        for (c, want) in [
            (ObjectClass::Other, -2.2257913526447273),
            (ObjectClass::Pedestrian, -1.5201453496417807),
            (ObjectClass::Cyclist, -1.9152292650788278),
            (ObjectClass::Car, -3.6888794541139363),
            (ObjectClass::Truck, -3.6888794541139363),
        ] {
            assert!((one[idx(c)] - want).abs() < 1e-12, "{c}: {}", one[idx(c)]);
        }
        // Half the posterior standing, half at 6 m/s: the mean speed (3 m/s) would make
        // `Other` (2·N(3; 0, 1), ln = −4.726) less likely than a vehicle (ln 1/40 = −3.689);
        // averaged over the samples, standing still keeps it the more likely.
        let split = speed_log_likelihoods([(0.0, 0.5), (6.0, 0.5)]).unwrap();
        assert!((split[idx(ObjectClass::Other)] - -0.9189385179746931).abs() < 1e-12);
        assert!((split[idx(ObjectClass::Pedestrian)] - -1.324068234939941).abs() < 1e-12);
        assert!((split[idx(ObjectClass::Cyclist)] - -2.1317823986585487).abs() < 1e-12);
        assert!(split[idx(ObjectClass::Other)] > split[idx(ObjectClass::Van)]);
        // Weights are normalised; zero-weight samples are left out.
        let scaled = speed_log_likelihoods([(0.0, 3.0), (6.0, 3.0), (30.0, 0.0)]).unwrap();
        for (a, b) in scaled.iter().zip(&split) {
            assert!((a - b).abs() < 1e-12);
        }
        // The densities are those of the plug-in log-likelihood.
        for v in [0.0, 0.7, 3.0, 12.0, 30.0] {
            for (k, c) in ObjectClass::ALL.iter().enumerate() {
                let (d, l) = (speed_densities(v)[k], speed_ll(*c, v));
                assert!((d.ln() - l).abs() < 1e-9, "{c} at {v}: {d} vs e^{l}");
            }
        }
        assert!(speed_log_likelihoods([]).is_err());
        assert!(speed_log_likelihoods([(f64::NAN, 1.0)]).is_err());
        assert!(speed_log_likelihoods([(-1.0, 1.0)]).is_err());
        assert!(speed_log_likelihoods([(1.0, -1.0)]).is_err());
        assert!(speed_log_likelihoods([(1.0, 0.0)]).is_err());
    }

    #[test]
    fn point_count_and_speed_separate_lookalikes() {
        // A 1.7 m tall cluster seen from the front, 0.7 × 0.6: pedestrian or head-on cyclist.
        // Moving at 8 m/s it is a cyclist; standing it is a pedestrian.
        let m = ClassModel::default();
        let mut f = features(0.7, 0.6, 1.72, 15.0, 180);
        f.speed = Some(8.0);
        assert_eq!(
            m.classify(&f, &default_prior()).unwrap(),
            ObjectClass::Cyclist
        );
        f.speed = Some(0.3);
        assert_eq!(
            m.classify(&f, &default_prior()).unwrap(),
            ObjectClass::Pedestrian
        );
        // A car's rear face (1.6 wide, 1.4 high) at 10 m with a car's worth of points is a
        // car, not a pedestrian (too wide, too many points for a person).
        assert_eq!(
            best(&features(1.6, 0.15, 1.45, 10.0, 900)),
            ObjectClass::Car
        );
    }

    #[test]
    fn travel_across_the_long_side_is_no_cyclist() {
        // The travel densities by hand (σ = 15° = 0.261799 rad): a half-normal's peak is
        // 2 / (σ √(2π)) = 3.047695, its value at π/2 (6σ) e^{-18} of that, negligible.
        // Across (π/2): vehicles 0.5 × 3.047695 = 1.523848, cyclists 0.1 × 2/π = 0.063662.
        // Along (0): vehicles 1.523848, cyclists 0.9 × 3.047695 + 0.063662 = 2.806588.
        let m = ClassModel::default();
        let f = features(1.8, 0.3, 1.4, 30.0, 120);
        let plain = m.log_likelihoods(&f).unwrap();
        let (car, cyc, ped) = (
            ObjectClass::Car.index(),
            ObjectClass::Cyclist.index(),
            ObjectClass::Pedestrian.index(),
        );
        for (angle, vehicle, cyclist) in [
            (std::f64::consts::FRAC_PI_2, 1.523848, 0.063662),
            (0.0, 1.523848, 2.806588),
        ] {
            let with = m
                .log_likelihoods(&ClassFeatures {
                    travel_angle: Some(angle),
                    ..f
                })
                .unwrap();
            let d = |k: usize| with[k] - plain[k];
            assert!((d(car) - f64::ln(vehicle)).abs() < 1e-5, "{}", d(car));
            assert!((d(cyc) - f64::ln(cyclist)).abs() < 1e-5, "{}", d(cyc));
            assert!((d(ped) - FRAC_2_PI.ln()).abs() < 1e-12);
        }
        for bad in [-0.1, 1.6, f64::NAN] {
            let err = m
                .log_likelihoods(&ClassFeatures {
                    travel_angle: Some(bad),
                    ..f
                })
                .unwrap_err();
            assert!(err.to_string().contains("travel_angle"), "{err}");
        }
    }

    #[test]
    fn belief_updates_by_bayes_and_forgets() {
        let mut b = ClassBelief::new([1.0; CLASS_COUNT]).unwrap();
        // ln-likelihood ratio ln 3 for Car over every other class: posterior 3/8.
        let mut ll = [0.0; CLASS_COUNT];
        ll[0] = 3f64.ln();
        b.update(&ll, 0.0).unwrap();
        assert!((b.probability(ObjectClass::Car) - 3.0 / 8.0).abs() < 1e-12);
        assert!((b.probabilities().iter().sum::<f64>() - 1.0).abs() < 1e-12);
        // Forgetting 1 resets to the prior before the update.
        b.update(&[0.0; CLASS_COUNT], 1.0).unwrap();
        assert!((b.probability(ObjectClass::Car) - 1.0 / 6.0).abs() < 1e-12);
        // A wrong first frame is outvoted by later ones.
        let mut b = ClassBelief::default();
        let mut ped = [-5.0; CLASS_COUNT];
        ped[ObjectClass::Pedestrian.index()] = 0.0;
        b.update(&ped, DEFAULT_FORGETTING).unwrap();
        assert_eq!(b.most_likely(), ObjectClass::Pedestrian);
        let mut car = [-2.0; CLASS_COUNT];
        car[0] = 0.0;
        for _ in 0..4 {
            b.update(&car, DEFAULT_FORGETTING).unwrap();
        }
        assert_eq!(b.most_likely(), ObjectClass::Car);
        // Bad input.
        assert!(b.update(&[f64::NAN; CLASS_COUNT], 0.0).is_err());
        assert!(b.update(&[0.0; CLASS_COUNT], 1.5).is_err());
        assert!(ClassBelief::new([0.0; CLASS_COUNT]).is_err());
        let all_out = [f64::NEG_INFINITY; CLASS_COUNT];
        let before = b;
        b.update(&all_out, 0.0).unwrap();
        assert_eq!(b, before);
    }

    #[test]
    fn bad_features_are_errors() {
        let m = ClassModel::default();
        assert!(m
            .log_likelihoods(&features(-1.0, 1.0, 1.0, 5.0, 10))
            .is_err());
        assert!(m
            .log_likelihoods(&features(1.0, f64::NAN, 1.0, 5.0, 10))
            .is_err());
        assert!(m.log_likelihoods(&features(1.0, 1.0, 1.0, 5.0, 0)).is_err());
    }
}
