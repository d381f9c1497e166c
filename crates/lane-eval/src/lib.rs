//! # lane-eval — how well the lane tracker does
//!
//! Synthetic scenes with ground truth ([`synth`]: the straight, curved, dashed, shadowed, noisy,
//! occluded and corridor sequences; [`synth::road`]: a road rendered from known 3-D geometry for
//! the metric round trips), their scores ([`eval`]: per-sequence accuracy, continuity, the frame
//! loop over a source), and the real labelled sets ([`labelled`]: `labels.json` schema 1 scored
//! with the TuSimple and Aly rules). Used by `cargo xtask regress` / `eval-lanes`, the tests and the
//! benches; a tracker user does not need it.

pub mod data;
mod error;
pub mod eval;
pub mod labelled;
pub mod synth;

pub use error::EvalError;
