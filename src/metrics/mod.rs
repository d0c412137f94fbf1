//! Multi-object performance metrics.
