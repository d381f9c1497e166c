//! # The lane half: the lane-mark tracker of Pimentel & Hemerly, its inputs and outputs
//!
//! Feature `lane` (on by default). Stage I–III of the paper's Fig. 1 are composed in
//! [`tracker`] from the numeric crates `vision-gradient`, `hough-init`, `info-filter` and `wrls`;
//! around it: the configuration ([`config`], `configs/*.toml`), the frame sources ([`frame`]'s
//! trait, [`sources`] for stills and directories, [`y4m`] for YUV4MPEG2 streams,
//! [`capture_source`] for V4L2 through `bt848-capture`), overlays ([`overlay`], [`birdseye`]),
//! the ego lane in metres ([`camera`] over `lane-geometry`), and, behind the feature `eval` (on by
//! default), evaluation: synthetic sequences with ground truth (`synth`), scoring (`eval`) and
//! the real labelled sets (`labelled`).
//! The crate root re-exports every module and the main types, so `nav_app::LaneTracker` and
//! `nav_app::sources` are the paths to use. Nothing here depends on the INS half.

pub mod birdseye;
pub mod camera;
pub mod capture_source;
pub mod config;
#[cfg(feature = "eval")]
pub mod eval;
pub mod frame;
pub mod frame_loop;
#[cfg(feature = "eval")]
pub mod labelled;
pub mod overlay;
pub mod sources;
#[cfg(feature = "eval")]
pub mod synth;
pub mod tracker;
mod wrls_lane;
pub mod y4m;
