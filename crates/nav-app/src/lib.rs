//! # nav-app — the lane tracker of Pimentel & Hemerly
//!
//! (work in progress; see the full crate docs once the tracker lands)

mod config;
mod error;
mod frame;
pub mod sources;
pub mod y4m;

pub use config::{
    FilterConfig, GradientConfig, INDOOR_TOML, InitConfig, OUTDOOR_TOML, RoiConfig, TrackConfig,
    TrackerConfig,
};
pub use error::NavError;
pub use frame::{FrameMeta, FrameSource, GreyFrame};
mod tracker;
mod wrls_lane;

pub use tracker::{
    Estimator, LaneReport, LaneState, LaneTracker, LaneView, Side, TrackReport, TrackerCounters,
};
pub mod eval;
pub mod overlay;
pub mod synth;
pub mod ins_sd;
