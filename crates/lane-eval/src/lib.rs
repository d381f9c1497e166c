//! # lane-eval — how well the lane tracker does on rendered and unlabelled sequences
//!
//! Sequence scores ([`eval`]: per-sequence accuracy against the ground truth of a rendered scene
//! (`lane_scenes`), continuity on a real clip without labels, the frame loop over a source) and
//! the lane regression ([`regress`]: `cargo xtask regress`, the synthetic sequences and the
//! udacity clip against the recorded expectations). The real labelled sets are the benchmark's,
//! crate `lane-bench`. Used by `cargo xtask regress`, the tests and the benches; a tracker user
//! does not need it.

mod error;
pub mod eval;
pub mod regress;

pub use error::EvalError;
