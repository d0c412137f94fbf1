//! Scenario generators with ground truth.
