//! The one frame loop: next frame from a [`FrameSource`] → tracker (built on the first frame's
//! size) → the caller's handling of the report. The `nav-app` binary (JSON, overlays, capture
//! counters), the evaluation (`lane_eval::eval::run_tracker`) and the labelled benchmark
//! (`lane_bench::labelled::track_label_set`) all drive it, so what a frame
//! error does, when the tracker is built and what a size change means are decided once.
//!
//! ```no_run
//! use lane_io::frame_loop::{FrameLoop, Step};
//! use lane_tracker::{Estimator, TrackerConfig};
//! # fn main() -> Result<(), lane_io::LaneIoError> {
//! let mut source = lane_io::sources::open_input("clip.y4m".as_ref(), 25.0)?;
//! let mut lanes = FrameLoop::new(TrackerConfig::default_preset()?, Estimator::Kif);
//! loop {
//!     match lanes.step(&mut source)? {
//!         Step::Tracked(t) => println!("{}: {:?}", t.meta.index, t.report.lanes[0].coeffs),
//!         Step::Skipped(e) => eprintln!("skipped: {e}"),
//!         Step::End => break,
//!     }
//! }
//! # Ok(()) }
//! ```

use std::time::{Duration, Instant};

use lane_tracker::{Estimator, GreyFrame, LaneTracker, TrackReport, TrackerConfig};

use crate::{FrameMeta, FrameSource, LaneIoError};

/// One frame that went through the tracker.
#[derive(Debug)]
pub struct Tracked<'a> {
    /// Where the frame sits in its source.
    pub meta: FrameMeta,
    /// The frame.
    pub frame: &'a GreyFrame,
    /// The tracker after this frame (covariances, counters, fit rows).
    pub tracker: &'a LaneTracker,
    /// The tracker's report for this frame.
    pub report: TrackReport,
    /// Time spent in [`LaneTracker::track`] for this frame.
    pub track_time: Duration,
}

/// What one [`FrameLoop::step`] did.
// The tracked frame's report (both lanes with their far segments, the road) is most of a step;
// a step is returned once per frame and read at once, and boxing it would allocate per frame.
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
pub enum Step<'a> {
    /// A frame was tracked.
    Tracked(Tracked<'a>),
    /// The source reported a frame it could not deliver (not fatal: it was skipped; see
    /// [`LaneIoError::lost_frames`]); the loop can go on.
    Skipped(LaneIoError),
    /// The source has no more frames.
    End,
}

/// The frame loop's state: the caller-owned frame buffer and the tracker.
#[derive(Debug)]
pub struct FrameLoop {
    cfg: TrackerConfig,
    estimator: Estimator,
    frame: GreyFrame,
    tracker: Option<LaneTracker>,
}

impl FrameLoop {
    /// A loop that builds its tracker from `cfg` on the first frame.
    pub fn new(cfg: TrackerConfig, estimator: Estimator) -> Self {
        FrameLoop {
            cfg,
            estimator,
            frame: GreyFrame::default(),
            tracker: None,
        }
    }

    /// The tracker, once the first frame has arrived.
    pub fn tracker(&self) -> Option<&LaneTracker> {
        self.tracker.as_ref()
    }

    /// Forget the tracked lanes ([`LaneTracker::reset`]), keeping the tracker and its buffers: the
    /// next frame starts a new clip (the labelled benchmark's clips, `lane_bench::labelled`).
    pub fn reset(&mut self) {
        if let Some(t) = &mut self.tracker {
            t.reset();
        }
    }

    /// Reads the next frame of `source` and tracks it.
    ///
    /// # Errors
    /// A fatal source error ([`LaneIoError::is_fatal`]), a frame whose size differs from the first
    /// frame's ([`LaneIoError::SizeChanged`]), or a tracker error.
    pub fn step(&mut self, source: &mut dyn FrameSource) -> Result<Step<'_>, LaneIoError> {
        let meta = match source.next_frame(&mut self.frame) {
            Ok(Some(m)) => m,
            Ok(None) => return Ok(Step::End),
            Err(e) if !e.is_fatal() => return Ok(Step::Skipped(e)),
            Err(e) => return Err(e),
        };
        let (w, h) = (self.frame.width(), self.frame.height());
        if let Some(t) = &self.tracker
            && t.frame_size() != (w, h)
        {
            let (from_w, from_h) = t.frame_size();
            return Err(LaneIoError::SizeChanged {
                name: source.describe(),
                frame: meta.index,
                from_w,
                from_h,
                to_w: w,
                to_h: h,
            });
        }
        let tracker = match &mut self.tracker {
            Some(t) => t,
            slot => slot.insert(LaneTracker::new(&self.cfg, self.estimator, w, h)?),
        };
        let t0 = Instant::now();
        let report = tracker.track(&self.frame)?;
        let track_time = t0.elapsed();
        Ok(Step::Tracked(Tracked {
            meta,
            frame: &self.frame,
            tracker,
            report,
            track_time,
        }))
    }
}
