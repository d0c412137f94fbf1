//! Per-frame data handed to the models with the step, by type: the vehicle state a plane
//! transition starts from, the ranges of the scan an occlusion model looks through, the
//! confirmed neighbours a detection model lowers p_D near. A pipeline puts each value into the
//! [`Frame`](super::Frame)'s [`StepData`]; the filter hands it to every model in the step's
//! [`StepContext`](super::StepContext), where a model finds it by its type
//! ([`StepData::get`], or [`StepData::require`] for data the model cannot do without).
//!
//! What a model reads thus belongs to the step it reads it in: nothing has to be set on a
//! model before a step, a clone of a model shares nothing with its original, and a step whose
//! frame lacks data a model needs is an error naming the model and the type.
//!
//! ```
//! use smc_lmb::filter::{Frame, Measurements, StepContext, StepData};
//!
//! /// The wind a user's drift model reads in each step (m/s along x).
//! struct Wind(f64);
//!
//! let frame = Frame::new(0.1, Measurements::empty(2)).with_data(StepData::new().with(Wind(3.0)));
//! // the filter hands the frame's data to every model in the step's context
//! let ctx = StepContext::new(1, 0.1, 0.1).with_data(frame.data.clone());
//! assert_eq!(ctx.data.get::<Wind>().map(|w| w.0), Some(3.0));
//! assert!(ctx.data.require::<String>("DriftModel").is_err());
//! ```
//!
//! Values are kept behind `Arc`s: cloning a context (the filter keeps the previous step's for
//! adaptive birth) copies a few pointers, never the data.
//!
//! Not for: the filter's own per-step values (time, time step, platform pose: fields of
//! [`StepContext`](super::StepContext)) or settings that do not change from frame to frame
//! (those belong in the model).

use crate::error::{Error, Result};
use std::any::{Any, TypeId};
use std::sync::Arc;

/// One value of a type.
#[derive(Clone)]
struct Entry {
    id: TypeId,
    name: &'static str,
    value: Arc<dyn Any + Send + Sync>,
}

/// Values of distinct types handed to the models with one step (module documentation).
#[derive(Clone, Default)]
pub struct StepData {
    entries: Vec<Entry>,
}

impl StepData {
    /// No data.
    pub fn new() -> Self {
        StepData::default()
    }

    /// The same data with `value` added, replacing any earlier value of its type.
    pub fn with<T: Any + Send + Sync>(mut self, value: T) -> Self {
        self.insert(value);
        self
    }

    /// Adds `value`, replacing any earlier value of its type.
    pub fn insert<T: Any + Send + Sync>(&mut self, value: T) {
        let entry = Entry {
            id: TypeId::of::<T>(),
            name: std::any::type_name::<T>(),
            value: Arc::new(value),
        };
        match self.entries.iter_mut().find(|e| e.id == entry.id) {
            Some(e) => *e = entry,
            None => self.entries.push(entry),
        }
    }

    /// Adds every value of `other`, replacing values of the same types.
    pub fn extend(&mut self, other: StepData) {
        for entry in other.entries {
            match self.entries.iter_mut().find(|e| e.id == entry.id) {
                Some(e) => *e = entry,
                None => self.entries.push(entry),
            }
        }
    }

    /// The value of type `T`, if the step has one.
    pub fn get<T: Any + Send + Sync>(&self) -> Option<&T> {
        let id = TypeId::of::<T>();
        self.entries
            .iter()
            .find(|e| e.id == id)
            .and_then(|e| e.value.downcast_ref::<T>())
    }

    /// The value of type `T`, or an error naming `model` (the model that needs it) and the
    /// type when the step has none.
    pub fn require<T: Any + Send + Sync>(&self, model: &str) -> Result<&T> {
        self.get::<T>().ok_or_else(|| {
            Error::invalid(
                format!("step data of {model}"),
                format!(
                    "the frame holds no {}; hand it with the frame (Frame::data)",
                    crate::filter::model_name::<T>()
                ),
            )
        })
    }

    /// Whether the step has no data.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The number of values.
    pub fn len(&self) -> usize {
        self.entries.len()
    }
}

impl std::fmt::Debug for StepData {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_set()
            .entries(self.entries.iter().map(|e| e.name))
            .finish()
    }
}

/// Two step data are equal when they hold the same values: the same types, each the same
/// shared value (not compared by content, which may not be comparable).
impl PartialEq for StepData {
    fn eq(&self, other: &Self) -> bool {
        self.entries.len() == other.entries.len()
            && self.entries.iter().all(|a| {
                other
                    .entries
                    .iter()
                    .any(|b| a.id == b.id && Arc::ptr_eq(&a.value, &b.value))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, PartialEq)]
    struct Beams(Vec<f64>);
    #[derive(Debug, PartialEq)]
    struct Speed(f64);

    #[test]
    fn values_are_found_by_type_and_replaced_by_type() {
        let mut d = StepData::new().with(Beams(vec![1.0, 2.0])).with(Speed(3.0));
        assert_eq!(d.len(), 2);
        assert_eq!(d.get::<Beams>(), Some(&Beams(vec![1.0, 2.0])));
        assert_eq!(d.get::<Speed>(), Some(&Speed(3.0)));
        assert_eq!(d.get::<f64>(), None);
        d.insert(Speed(4.0));
        assert_eq!(d.len(), 2);
        assert_eq!(d.get::<Speed>(), Some(&Speed(4.0)));
    }

    #[test]
    fn missing_data_names_the_model_and_the_type() {
        let d = StepData::new().with(Speed(1.0));
        let e = d
            .require::<Beams>("OcclusionDetection")
            .unwrap_err()
            .to_string();
        assert!(e.contains("OcclusionDetection"), "{e}");
        assert!(e.contains("Beams"), "{e}");
        assert!(d.require::<Speed>("X").is_ok());
    }

    #[test]
    fn clones_share_values_and_compare_equal() {
        let d = StepData::new().with(Beams(vec![0.5]));
        let c = d.clone();
        assert_eq!(c, d);
        assert_ne!(StepData::new().with(Beams(vec![0.5])), d);
        assert!(StepData::new().is_empty());
        assert_eq!(format!("{:?}", StepData::new()), "{}");
    }
}
