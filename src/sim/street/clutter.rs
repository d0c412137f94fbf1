//! Street clutter: poles, tree trunks, hedges and low walls along the sidewalks, the static
//! things a lidar clusters that are not road users (KITTI labels none of them, so neither
//! does the tracking layout's `label_02`).
//!
//! **Shapes.** Poles and tree trunks are vertical cylinders, low walls boxes, hedges boxes that
//! a ray enters before it returns ([`Shape::scatter`]: a hedge's returns scatter through its
//! outer 0.3 m, as foliage's do).
//!
//! Where the pieces stand is the street's business ([`super::world`]: poles and trunks
//! [`ClutterConfig::kerb_setback`] behind the kerb, hedges and low walls against the building
//! line, clear of the road users' rows).
//!
//! Not for: placing the pieces or road users (see [`super::world`]) or building walls.

use super::lidar::{Geometry, Shape, Surface};
use crate::error::{ensure_non_negative, ensure_positive, ensure_range, Error, Result};
use serde::{Deserialize, Serialize};

/// What a piece of clutter is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ClutterKind {
    /// A street-lamp or sign pole (thin cylinder).
    Pole,
    /// A tree trunk (cylinder).
    Trunk,
    /// A hedge (porous box).
    Hedge,
    /// A low garden or boundary wall (box).
    LowWall,
}

/// How many pieces of each kind and their sizes (ranges drawn uniformly), metres.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ClutterConfig {
    /// Number of poles.
    pub poles: usize,
    /// Number of tree trunks.
    pub trunks: usize,
    /// Number of hedges.
    pub hedges: usize,
    /// Number of low walls.
    pub low_walls: usize,
    /// How far behind the kerb poles and tree trunks stand (axis to kerb, m). The default,
    /// 0.8 m, is a street lamp's usual setback and leaves a parked car (0.1 m from the kerb)
    /// more than a clusterer's 0.5 m from them; 0.4 m puts them within reach, so that parked
    /// cars and poles merge into one cluster.
    pub kerb_setback: f64,
    /// Pole radius.
    pub pole_radius: [f64; 2],
    /// Pole height.
    pub pole_height: [f64; 2],
    /// Trunk radius.
    pub trunk_radius: [f64; 2],
    /// Trunk height (up to the crown, which the lidar's upward field of view barely reaches).
    pub trunk_height: [f64; 2],
    /// Hedge length along the street.
    pub hedge_length: [f64; 2],
    /// Hedge depth across the street.
    pub hedge_width: [f64; 2],
    /// Hedge height.
    pub hedge_height: [f64; 2],
    /// How deep a ray enters a hedge before it returns.
    pub hedge_scatter: f64,
    /// Low wall length along the street.
    pub low_wall_length: [f64; 2],
    /// Low wall thickness.
    pub low_wall_width: [f64; 2],
    /// Low wall height.
    pub low_wall_height: [f64; 2],
}

impl Default for ClutterConfig {
    /// No clutter (the plain street), with the sizes [`ClutterConfig::urban`] uses.
    fn default() -> Self {
        ClutterConfig {
            poles: 0,
            trunks: 0,
            hedges: 0,
            low_walls: 0,
            kerb_setback: 0.8,
            pole_radius: [0.06, 0.12],
            pole_height: [3.0, 8.0],
            trunk_radius: [0.12, 0.22],
            trunk_height: [2.5, 4.5],
            hedge_length: [3.0, 10.0],
            hedge_width: [0.5, 0.6],
            hedge_height: [0.8, 1.8],
            hedge_scatter: 0.3,
            low_wall_length: [4.0, 15.0],
            low_wall_width: [0.25, 0.35],
            low_wall_height: [0.5, 1.1],
        }
    }
}

impl ClutterConfig {
    /// A city street's clutter: 14 poles, 10 trunks, 4 hedges and 3 low walls a drive.
    pub fn urban() -> Self {
        ClutterConfig {
            poles: 14,
            trunks: 10,
            hedges: 4,
            low_walls: 3,
            ..ClutterConfig::default()
        }
    }

    /// Checks every field; errors name the field.
    pub fn validate(&self) -> Result<()> {
        let ranges = [
            ("pole_radius", self.pole_radius),
            ("pole_height", self.pole_height),
            ("trunk_radius", self.trunk_radius),
            ("trunk_height", self.trunk_height),
            ("hedge_length", self.hedge_length),
            ("hedge_width", self.hedge_width),
            ("hedge_height", self.hedge_height),
            ("low_wall_length", self.low_wall_length),
            ("low_wall_width", self.low_wall_width),
            ("low_wall_height", self.low_wall_height),
        ];
        for (name, r) in ranges {
            let what = format!("clutter.{name}");
            ensure_positive(&what, r[0])?;
            ensure_range(&what, r)?;
        }
        ensure_non_negative("clutter.hedge_scatter", self.hedge_scatter)?;
        ensure_non_negative("clutter.kerb_setback", self.kerb_setback)?;
        // Poles and trunks stand on the sidewalk, behind the kerb.
        for (name, r) in [
            ("pole_radius", self.pole_radius),
            ("trunk_radius", self.trunk_radius),
        ] {
            if r[1] > self.kerb_setback {
                return Err(Error::invalid(
                    format!("clutter.{name}"),
                    format!(
                        "{} m (at most clutter.kerb_setback, {} m: the row stands behind the kerb)",
                        r[1], self.kerb_setback
                    ),
                ));
            }
        }
        for (name, r) in [
            ("hedge_width", self.hedge_width),
            ("low_wall_width", self.low_wall_width),
        ] {
            if r[1] > 0.6 {
                return Err(Error::invalid(
                    format!("clutter.{name}"),
                    format!(
                        "{} m (at most 0.6 m: it stands against the building line)",
                        r[1]
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// One piece of clutter in the world frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Clutter {
    /// Identifier (matches `Surface::Clutter`).
    pub id: u32,
    /// Kind.
    pub kind: ClutterKind,
    /// Centre of the footprint in the world, metres.
    pub centre: [f64; 2],
    /// Heading of the long side, rad counter-clockwise from the world x axis.
    pub yaw: f64,
    /// Length, width, height, metres (a cylinder: diameter, diameter, height).
    pub size: [f64; 3],
    /// Reflectance of the surface.
    pub reflectance: f32,
}

impl Clutter {
    /// The piece as a shape for the ray caster; a hedge scatters its returns by `hedge_scatter`.
    pub fn shape(&self, hedge_scatter: f64) -> Shape {
        let [length, width, height] = self.size;
        let geometry = match self.kind {
            ClutterKind::Pole | ClutterKind::Trunk => Geometry::Cylinder {
                centre: self.centre,
                radius: 0.5 * width,
                height,
            },
            ClutterKind::Hedge | ClutterKind::LowWall => Geometry::Box {
                centre: self.centre,
                yaw: self.yaw,
                half_length: 0.5 * length,
                half_width: 0.5 * width,
                height,
            },
        };
        Shape {
            surface: Surface::Clutter(self.id),
            geometry,
            reflectance: self.reflectance,
            scatter: if self.kind == ClutterKind::Hedge {
                hedge_scatter
            } else {
                0.0
            },
        }
    }
}
