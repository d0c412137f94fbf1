//! People tracking from planar laser scans, the role [`super::drive_tracking`] plays for
//! 3-D drives: a scan becomes range-bearing measurements of people's centres ([`front_end`]:
//! every person-sized segment, or only those the moving-object detector of
//! [`crate::laser2d::moving`] marks as moving), the particle LMB filter tracks them
//! ([`tracker`], with its birth model [`birth`] and the people models of [`models`]), tracks
//! are classed static or dynamic ([`motion_state`]), a whole recording becomes a
//! [`PeopleRun`] ([`run`]) drawn by [`plot`], and any tracker — the LMB or a baseline of
//! [`crate::trackers`] — is scored on a simulated run ([`evaluate`], with the innovations of
//! [`innovation`] for the consistency checks); a recording with leg annotations is scored by
//! [`score`].
//!
//! Not for: reading or segmenting scans (see [`crate::laser2d`]) or the baseline trackers
//! themselves (see [`crate::trackers`]).

pub mod baselines;
pub mod birth;
pub mod evaluate;
pub mod front_end;
pub mod innovation;
pub mod lasers;
pub mod lasers_eval;
pub mod models;
pub mod motion_state;
#[cfg(feature = "plot")]
pub mod plot;
pub mod run;
pub mod score;
pub mod tracker;

pub use birth::{
    ConfirmedPeople, ConfirmedPerson, Doubted, LaserOrigin, LaserOrigins, PeopleBirth,
};
pub use motion_state::{probability_moving, MotionClassifier, MotionConfig};
#[cfg(feature = "plot")]
pub use plot::{write_people_plot, PeoplePlotCounts, PeoplePlotOptions};
pub use run::{
    config_for_scans, track_scans, track_scans_with, track_scans_with_model, write_people_json,
    PeopleRun, PersonTrack, ScanPeople,
};
pub use tracker::{
    centre_noise, person_measurements, person_segments, PeopleTracker, PeopleTrackerConfig,
    PersonEstimate,
};
