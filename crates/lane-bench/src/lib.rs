//! # lane-bench — the labelled lane benchmark
//!
//! The lane tracker scored on real labelled frames, what `nav-app eval-lanes` and `nav-app
//! import-lanes` run (and `cargo xtask eval-lanes`, the gate's step, with the OpenCV peer):
//!
//! - [`labelled`]: the label format (`labels.json` schema 1), the TuSimple and Aly scoring
//!   rules, a set through the tracker (the binary's frame loop, `lane_io::frame_loop`), the
//!   census of where lanes are lost and the bound of the tracker's choice, and the parsing of
//!   TuSimple's and CULane's label formats ([`labelled::import`]);
//! - [`protocol`]: the development / hold-out split, the default and the other configurations,
//!   `summary.json`, `summary.md`, `frames.csv`, the contact sheet, and the floors
//!   ([`protocol::floors`]);
//! - [`perturb`]: the frames changed as other cameras would give them (`eval-lanes --perturb`);
//! - [`import_set`]: the file work of importing a user's labels;
//! - [`resample`]: the sets at another resolution;
//! - [`ablation`]: whether each mechanism beyond the paper earns its place (leave-one-set-out);
//! - [`data`]: where the third-party data root is;
//! - `cli` (feature `cli`): the two command lines, shared by `nav-app` and `cargo xtask`.

pub mod ablation;
#[cfg(feature = "cli")]
pub mod cli;
pub mod data;
mod error;
pub mod import_set;
pub mod labelled;
pub mod perturb;
pub mod protocol;
pub mod resample;

pub use error::BenchError;
