//! The sensors of a filter: each with its own name, measurement, detection and clutter models,
//! and where it sits on the platform; and one sensor's measurements of a frame ([`Scan`]).
//!
//! A filter built with one set of models ([`super::LmbFilterBuilder::measurement`] and so on)
//! has one sensor, named [`DEFAULT_SENSOR`]. A filter built with
//! [`super::LmbFilterBuilder::sensor`] has one sensor per call, numbered in call order; how
//! their updates combine is [`super::Fusion`]'s.
//!
//! Not for: the fusion rules (see [`super::fusion`]) or the update itself.

use super::{Measurements, StepData};
use crate::error::{Error, Result};
use crate::filter::{ClutterModel, DetectionModel, MeasurementModel};
use nalgebra::Isometry3;

/// The name of the one sensor of a filter built without [`Sensor`]s.
pub const DEFAULT_SENSOR: &str = "default";

/// Where a sensor sits on the platform, in the platform's frame: position (m) and heading
/// (rad, counter-clockwise). A sensor with a mounting measures positions in its own frame;
/// the filter moves the first two components of each of its measurements into the platform
/// frame, `p = R(heading)·z + (x, y)`, before any model sees them, so a mounted sensor's
/// models are written for measurements in the platform frame. Further components (a size, a
/// class score, ...) are left as they are.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Mounting {
    /// Position along the platform's x axis, m.
    pub x: f64,
    /// Position along the platform's y axis, m.
    pub y: f64,
    /// Heading of the sensor's x axis from the platform's, rad.
    pub heading: f64,
}

impl Mounting {
    /// A mounting at `(x, y)` facing `heading`; an error when a value is not finite.
    pub fn new(x: f64, y: f64, heading: f64) -> Result<Self> {
        if !(x.is_finite() && y.is_finite() && heading.is_finite()) {
            return Err(Error::invalid(
                "sensor mounting",
                format!("[{x}, {y}, {heading}] is not finite"),
            ));
        }
        Ok(Mounting { x, y, heading })
    }

    /// `z` with its first two components moved from the sensor's frame to the platform's.
    pub fn to_platform(&self, z: &Measurements) -> Measurements {
        let (s, c) = self.heading.sin_cos();
        let mut out = Measurements::empty(z.dim());
        let mut row = vec![0.0; z.dim()];
        for zj in z.iter() {
            row.copy_from_slice(zj);
            row[0] = c * zj[0] - s * zj[1] + self.x;
            row[1] = s * zj[0] + c * zj[1] + self.y;
            out.push(&row)
                .expect("a rotation and a shift of finite values are finite");
        }
        out
    }
}

/// One sensor of a filter: its models and, optionally, its mounting.
pub struct Sensor {
    pub(crate) name: String,
    pub(crate) measurement: Box<dyn MeasurementModel>,
    pub(crate) detection: Box<dyn DetectionModel>,
    pub(crate) clutter: Box<dyn ClutterModel>,
    pub(crate) mounting: Option<Mounting>,
}

impl std::fmt::Debug for Sensor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Sensor")
            .field("name", &self.name)
            .field("measurement", &self.measurement.name())
            .field("mounting", &self.mounting)
            .finish_non_exhaustive()
    }
}

impl Sensor {
    /// A sensor called `name` with its measurement, detection and clutter models, mounted at
    /// the platform's origin.
    pub fn new(
        name: impl Into<String>,
        measurement: impl MeasurementModel + 'static,
        detection: impl DetectionModel + 'static,
        clutter: impl ClutterModel + 'static,
    ) -> Self {
        Sensor::from_boxes(
            name.into(),
            Box::new(measurement),
            Box::new(detection),
            Box::new(clutter),
        )
    }

    /// [`Sensor::new`] from models already boxed.
    pub fn from_boxes(
        name: String,
        measurement: Box<dyn MeasurementModel>,
        detection: Box<dyn DetectionModel>,
        clutter: Box<dyn ClutterModel>,
    ) -> Self {
        Sensor {
            name,
            measurement,
            detection,
            clutter,
            mounting: None,
        }
    }

    /// The same sensor mounted at `mounting` (see [`Mounting`]).
    pub fn mounted(mut self, mounting: Mounting) -> Self {
        self.mounting = Some(mounting);
        self
    }

    /// The sensor's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Where the sensor sits on the platform, if it was given.
    pub fn mounting(&self) -> Option<Mounting> {
        self.mounting
    }

    /// The dimension of the sensor's measurements.
    pub fn measurement_dim(&self) -> usize {
        self.measurement.measurement_dim()
    }
}

/// One sensor's measurements in a frame. A frame holds a scan for each sensor that reported
/// in it (an empty scan: the sensor looked and saw nothing); a sensor without a scan is not
/// used in that frame's update.
#[derive(Clone, Debug, PartialEq)]
pub struct Scan {
    /// The sensor's index, in the order the filter's sensors were given.
    pub sensor: usize,
    /// What it measured, in its own frame.
    pub measurements: Measurements,
    /// What only this sensor's models are handed with the step (its own beams, say): added to
    /// the frame's data, replacing values of the same types, for this sensor's measurement,
    /// detection and clutter models. Empty by default.
    pub data: StepData,
    /// Where the platform stood for this sensor's models, when not at the frame's pose: a
    /// sensor that measured at another time than the frame's (an asynchronous laser), or one
    /// whose models are written for measurements about the sensor itself (range and bearing
    /// from a laser at its own pose: give its world pose here and its models no offset). The
    /// sensor's measurement, detection and clutter models see it as the step's platform
    /// ([`crate::filter::StepContext::platform`]); the other models of the step, and the
    /// births, see the frame's. `None` by default.
    pub platform: Option<Isometry3<f64>>,
}

impl Scan {
    /// Sensor `sensor`'s `measurements`, with no data of its own.
    pub fn new(sensor: usize, measurements: Measurements) -> Self {
        Scan {
            sensor,
            measurements,
            data: StepData::new(),
            platform: None,
        }
    }

    /// The same scan with `data` for its sensor's models.
    pub fn with_data(mut self, data: StepData) -> Self {
        self.data = data;
        self
    }

    /// The same scan with the platform at `platform` for its sensor's models (see
    /// [`Scan::platform`]).
    pub fn at(mut self, platform: Isometry3<f64>) -> Self {
        self.platform = Some(platform);
        self
    }
}

/// Checks a set of sensors for a filter: at least one, names unique and not empty, every
/// measurement of the same dimension (births are drawn from the measurements of all sensors
/// together), a mounted sensor's measurements at least two-dimensional.
pub(crate) fn check_sensors(sensors: &[Sensor]) -> Result<()> {
    let first = sensors
        .first()
        .ok_or_else(|| Error::invalid("filter", "no sensor given"))?;
    for (i, s) in sensors.iter().enumerate() {
        let what = || format!("sensor {i} ({:?})", s.name);
        if s.name.trim().is_empty() {
            return Err(Error::invalid(what(), "has an empty name"));
        }
        if let Some(j) = sensors[..i].iter().position(|o| o.name == s.name) {
            return Err(Error::invalid(
                what(),
                format!("has the same name as sensor {j}"),
            ));
        }
        if s.measurement_dim() != first.measurement_dim() {
            return Err(Error::invalid(
                what(),
                format!(
                    "its measurement model {} gives measurements of {} components, but sensor \
                     0 ({:?})'s {} gives {}; every sensor of a filter measures in one space",
                    s.measurement.name(),
                    s.measurement_dim(),
                    first.name,
                    first.measurement.name(),
                    first.measurement_dim()
                ),
            ));
        }
        if s.mounting.is_some() && s.measurement_dim() < 2 {
            return Err(Error::invalid(
                what(),
                "is mounted, but its measurements have fewer than two components (a mounting \
                 moves positions)",
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mounting_moves_positions_and_keeps_other_components() {
        let m = Mounting::new(1.0, -2.0, std::f64::consts::FRAC_PI_2).unwrap();
        let z = Measurements::from_rows(3, &[[1.0, 0.0, 7.0], [0.0, 2.0, -1.0]]).unwrap();
        let p = m.to_platform(&z);
        // (1, 0) turned a quarter left is (0, 1); shifted by (1, −2): (1, −1).
        assert!((p.get(0)[0] - 1.0).abs() < 1e-12 && (p.get(0)[1] + 1.0).abs() < 1e-12);
        // (0, 2) turned is (−2, 0); shifted: (−1, −2).
        assert!((p.get(1)[0] + 1.0).abs() < 1e-12 && (p.get(1)[1] + 2.0).abs() < 1e-12);
        assert_eq!((p.get(0)[2], p.get(1)[2]), (7.0, -1.0));
        assert!(Mounting::new(f64::NAN, 0.0, 0.0).is_err());
    }
}
