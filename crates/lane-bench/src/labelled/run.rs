//! A labelled set through the tracker: the frames of each clip as a frame source
//! (`lane_io::FrameSource`) driven by the binary's frame loop (`lane_io::frame_loop`), the
//! tracker reset at the start of every clip. A frame whose image cannot be read, or has another
//! size than the set declares, is reported and skipped (a [`SkippedFrame`], scored as a frame
//! with no prediction), as `nav-app` skips a bad image of a directory.
//!
//! The images come from [`Stills`]: the set's files ([`FileStills`]), or frames made in memory
//! (the perturbed frames of `eval-lanes --perturb`, `crate::protocol::perturbed`), never
//! written to disk.

use std::path::Path;

use lane_io::frame_loop::{FrameLoop, Step, Tracked};
use lane_io::{FrameMeta, FrameSource, GreyFrame, LaneIoError};
use lane_tracker::{Estimator, TrackerConfig};

use super::{EgoPrediction, LabelFrame, LabelSet, PredictedLane};
use crate::BenchError;

/// A frame of a labelled set that could not be tracked: its image cannot be read or has another
/// size than the set declares.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SkippedFrame {
    /// Position of the frame in the set.
    pub position: usize,
    /// Why (the frame loop's message: the file, the frame and the cause).
    pub reason: String,
}

impl std::fmt::Display for SkippedFrame {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.reason)
    }
}

/// The tracker's ego prediction of every frame of a set, in set order (`[None, None]` for a
/// skipped frame), and the frames skipped.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrackedSet {
    /// One per frame of the set.
    pub predictions: Vec<EgoPrediction>,
    /// The frames that could not be tracked.
    pub skipped: Vec<SkippedFrame>,
}

/// Run a tracker over a labelled set, clip by clip (the tracker is reset at the start of every
/// clip), and return the ego prediction of every frame in set order. `dir` is the set's
/// directory. A frame whose image cannot be read, or has another size than the set declares, is
/// skipped and listed (module docs).
pub fn track_label_set(
    dir: &Path,
    set: &LabelSet,
    cfg: &TrackerConfig,
    estimator: Estimator,
) -> Result<TrackedSet, BenchError> {
    let mut predictions = Vec::with_capacity(set.frames.len());
    let skipped = run_label_set(dir, set, cfg, estimator, set.frames.len(), |_, _, t| {
        predictions.push(t.map_or([None, None], |t| ego_of(&t.report)));
        Ok(())
    })?;
    Ok(TrackedSet {
        predictions,
        skipped,
    })
}

/// The tracker's ego prediction in a report: each side's coefficients with its row extent.
pub(crate) fn ego_of(report: &lane_tracker::TrackReport) -> EgoPrediction {
    [
        PredictedLane::from_report(&report.lanes[0]),
        PredictedLane::from_report(&report.lanes[1]),
    ]
}

/// Where the images of a labelled set's frames come from.
pub(crate) trait Stills {
    /// Fill `out` with the image of the frame at `position` in the set (`frame` its labels). An
    /// error is that frame's: it is reported and skipped.
    fn fill(
        &mut self,
        position: usize,
        frame: &LabelFrame,
        out: &mut GreyFrame,
    ) -> Result<(), LaneIoError>;

    /// The name of a frame in messages (its file).
    fn name(&self, frame: &LabelFrame) -> String;

    /// What the frames are, for the frame loop's messages.
    fn describe(&self) -> String;
}

/// The images of a set's files, `dir` the set's directory.
pub(crate) struct FileStills<'a>(pub(crate) &'a Path);

impl Stills for FileStills<'_> {
    fn fill(
        &mut self,
        _: usize,
        frame: &LabelFrame,
        out: &mut GreyFrame,
    ) -> Result<(), LaneIoError> {
        lane_io::sources::decode_image_file(&LabelSet::frame_path(self.0, frame), out)
    }

    fn name(&self, frame: &LabelFrame) -> String {
        LabelSet::frame_path(self.0, frame).display().to_string()
    }

    fn describe(&self) -> String {
        format!("{} (labelled frames)", self.0.display())
    }
}

/// Run a tracker over the frames of a labelled set before position `until`, clip by clip (reset
/// at the start of every clip), calling `on_frame(position in the set, labels, tracked frame)`
/// after every frame, in set order, with `None` for a skipped frame; its first error stops the
/// run and is returned. Returns the skipped frames. The images are the files under `dir`.
pub(crate) fn run_label_set(
    dir: &Path,
    set: &LabelSet,
    cfg: &TrackerConfig,
    estimator: Estimator,
    until: usize,
    on_frame: impl FnMut(usize, &LabelFrame, Option<&Tracked<'_>>) -> Result<(), BenchError>,
) -> Result<Vec<SkippedFrame>, BenchError> {
    run_stills(&mut FileStills(dir), set, cfg, estimator, until, on_frame)
}

/// [`run_label_set`] over the images of `stills`.
pub(crate) fn run_stills(
    stills: &mut dyn Stills,
    set: &LabelSet,
    cfg: &TrackerConfig,
    estimator: Estimator,
    until: usize,
    mut on_frame: impl FnMut(usize, &LabelFrame, Option<&Tracked<'_>>) -> Result<(), BenchError>,
) -> Result<Vec<SkippedFrame>, BenchError> {
    let mut lanes = FrameLoop::new(*cfg, estimator);
    let mut skipped = Vec::new();
    let mut position = 0;
    for clip in set.clips() {
        if position >= until {
            break;
        }
        lanes.reset();
        let clip = &clip[..clip.len().min(until - position)];
        let mut source = ClipSource {
            stills: &mut *stills,
            frames: clip,
            first_position: position,
            next: 0,
            size: (set.width, set.height),
        };
        for f in clip {
            match lanes.step(&mut source)? {
                Step::Tracked(t) => on_frame(position, f, Some(&t))?,
                Step::Skipped(e) => {
                    skipped.push(SkippedFrame {
                        position,
                        reason: crate::error::with_causes(&e),
                    });
                    on_frame(position, f, None)?;
                }
                Step::End => break,
            }
            position += 1;
        }
    }
    Ok(skipped)
}

/// The frames of one clip of a labelled set as a frame source; frame indices are positions in
/// the set.
struct ClipSource<'a> {
    stills: &'a mut dyn Stills,
    frames: &'a [LabelFrame],
    first_position: usize,
    next: usize,
    /// The size the set declares.
    size: (usize, usize),
}

impl FrameSource for ClipSource<'_> {
    fn next_frame(&mut self, frame: &mut GreyFrame) -> Result<Option<FrameMeta>, LaneIoError> {
        let Some(f) = self.frames.get(self.next) else {
            return Ok(None);
        };
        let position = self.first_position + self.next;
        let index = position as u64;
        self.next += 1;
        if let Err(e) = self.stills.fill(position, f, frame) {
            return Err(LaneIoError::BadFrame {
                name: self.stills.name(f),
                frame: index,
                source: Box::new(e),
            });
        }
        let (w, h) = (frame.width(), frame.height());
        if (w, h) != self.size {
            return Err(LaneIoError::FrameSizeDiffers {
                name: self.stills.name(f),
                frame: index,
                got_w: w,
                got_h: h,
                want_w: self.size.0,
                want_h: self.size.1,
            });
        }
        Ok(Some(FrameMeta { index, t_s: 0.0 }))
    }

    fn describe(&self) -> String {
        self.stills.describe()
    }
}
