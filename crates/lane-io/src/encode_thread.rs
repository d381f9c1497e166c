//! The lane channels' image, annotations and bird's-eye view encoded off the tracker's thread
//! (`nav-app --foxglove` without `--mcap-out`): the tracker's thread copies the grey frame into a
//! buffer of a small pool and hands it over with the frame's `Copy` [`TrackReport`] and ego lane;
//! this thread renders the bird's-eye view (when it was given one) and encodes them with
//! [`LaneEncoder`] (the bytes the MCAP file would get) and gives them to a publish callback (the
//! live server). No allocation per frame once the pool is full; when every buffer
//! is busy (the encoder cannot keep up) the frame is not sent and counted.

use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, sync_channel};
use std::thread::JoinHandle;

use grey_frame::GreyFrame;
use lane_tracker::TrackReport;
use lane_tracker::camera::EgoLaneReport;

use crate::LaneIoError;
use crate::birdseye::BirdseyeView;
use crate::mcap_sink::{ANNOTATIONS, BIRDSEYE, IMAGE, LaneEncoder};

/// Frames that may wait for, or be in, the encoder at once.
const POOL_FRAMES: usize = 4;

struct Job {
    t_ns: u64,
    frame: GreyFrame,
    report: TrackReport,
    ego: Option<EgoLaneReport>,
    /// Indexed as the lane channels (`mcap_sink::IMAGE` …); the lanes' own entry is not read.
    wants: [bool; 4],
}

/// The encoder thread and its buffer pool.
pub struct EncodeThread {
    jobs: Option<SyncSender<Job>>,
    free: Receiver<GreyFrame>,
    made: usize,
    dropped: u64,
    handle: Option<JoinHandle<()>>,
}

impl std::fmt::Debug for EncodeThread {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EncodeThread")
            .field("dropped", &self.dropped)
            .finish()
    }
}

impl EncodeThread {
    /// Starts the thread; `publish(channel, t_ns, json)` receives each encoded message
    /// (`channel` `mcap_sink::IMAGE`, `ANNOTATIONS` or, with a bird's-eye `view`, `BIRDSEYE`).
    ///
    /// # Errors
    /// [`LaneIoError::Io`] when the thread cannot be started.
    pub fn start(
        view: Option<BirdseyeView>,
        mut publish: impl FnMut(usize, u64, &[u8]) + Send + 'static,
    ) -> Result<Self, LaneIoError> {
        let (jobs, job_rx) = sync_channel::<Job>(POOL_FRAMES);
        let (free_tx, free) = sync_channel::<GreyFrame>(POOL_FRAMES);
        let handle = std::thread::Builder::new()
            .name("lane-encode".into())
            .spawn(move || {
                let mut encoder = LaneEncoder::default();
                let mut rgb = Vec::new();
                for job in job_rx {
                    let (w, h) = (job.frame.width(), job.frame.height());
                    if job.wants[IMAGE] && encoder.encode_image(job.t_ns, &job.frame).is_ok() {
                        publish(IMAGE, job.t_ns, encoder.image_json());
                    }
                    if job.wants[ANNOTATIONS]
                        && encoder
                            .encode_annotations(job.t_ns, w, h, &job.report)
                            .is_ok()
                    {
                        publish(ANNOTATIONS, job.t_ns, encoder.annotations_json());
                    }
                    if let Some(view) = view.as_ref().filter(|_| job.wants[BIRDSEYE]) {
                        view.render(&job.frame, &job.report, job.ego, &mut rgb);
                        if encoder.encode_birdseye(job.t_ns, view, &rgb).is_ok() {
                            publish(BIRDSEYE, job.t_ns, encoder.birdseye_json());
                        }
                    }
                    let _ = free_tx.try_send(job.frame);
                }
            })
            .map_err(|source| LaneIoError::Io {
                path: "the lane encoder thread".to_owned(),
                source,
            })?;
        Ok(Self {
            jobs: Some(jobs),
            free,
            made: 0,
            dropped: 0,
            handle: Some(handle),
        })
    }

    /// Hands `frame`, `report` and `ego` at `t_ns` to the thread for the channels `wants`
    /// (indexed as the lane channels; image, annotations and bird's-eye view are read); false
    /// when every buffer is busy (the messages are counted as dropped).
    pub fn offer(
        &mut self,
        t_ns: u64,
        frame: &GreyFrame,
        report: &TrackReport,
        ego: Option<EgoLaneReport>,
        wants: [bool; 4],
    ) -> bool {
        let buffer = match self.free.try_recv() {
            Ok(b) => Some(b),
            Err(TryRecvError::Empty | TryRecvError::Disconnected) if self.made < POOL_FRAMES => {
                self.made += 1;
                Some(GreyFrame::default())
            }
            Err(_) => None,
        };
        let messages = [IMAGE, ANNOTATIONS, BIRDSEYE]
            .iter()
            .filter(|&&k| wants[k])
            .count() as u64;
        let Some(mut buffer) = buffer else {
            self.dropped += messages;
            return false;
        };
        if buffer.reshape(frame.width(), frame.height()).is_err() {
            self.dropped += messages;
            return false;
        }
        buffer.data_mut().copy_from_slice(frame.data());
        let job = Job {
            t_ns,
            frame: buffer,
            report: *report,
            ego,
            wants,
        };
        // Never full: the pool holds no more frames than the channel does.
        let sent = self.jobs.as_ref().is_some_and(|j| j.try_send(job).is_ok());
        if !sent {
            self.dropped += messages;
        }
        sent
    }

    /// Messages not encoded because the encoder was busy.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Lets the thread encode what it was handed, and joins it; returns [`Self::dropped`].
    pub fn finish(mut self) -> u64 {
        self.join();
        self.dropped
    }

    fn join(&mut self) {
        self.jobs = None;
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

impl Drop for EncodeThread {
    fn drop(&mut self) {
        self.join();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{report, tracked_lane};
    use lane_tracker::Side;
    use std::sync::{Arc, Mutex};

    /// Image, annotations and bird's-eye view, each as [`LaneEncoder`] and [`BirdseyeView`] give
    /// them on the caller's thread, in the order offered; a channel not wanted is not sent.
    #[test]
    fn every_frame_offered_is_encoded_as_the_encoder_does_it_on_the_callers_thread() {
        let (_, view) = crate::test_support::robot_view();
        let got = Arc::new(Mutex::new(Vec::new()));
        let sink = Arc::clone(&got);
        let mut thread =
            EncodeThread::start(Some(view.clone()), move |channel, t_ns, json: &[u8]| {
                sink.lock().unwrap().push((channel, t_ns, json.to_vec()));
            })
            .unwrap();
        let (w, h) = (320, 240);
        let lane = |side| tracked_lane(side, [0.001, -0.5, 200.0], [120.0, 239.0]);
        let report = report([lane(Side::Left), lane(Side::Right)], Some(60.0));
        let mut expected = Vec::new();
        let mut encoder = LaneEncoder::default();
        let mut rgb = Vec::new();
        for k in 0..20u64 {
            let data: Vec<u8> = (0..w * h).map(|i| (i as u64 * 3 + k) as u8).collect();
            let frame = GreyFrame::from_vec(w, h, data).unwrap();
            // Every channel on even frames; on odd ones the bird's-eye view only.
            let wants = [k % 2 == 0, k % 2 == 0, true, true];
            while !thread.offer(k, &frame, &report, None, wants) {
                std::thread::yield_now();
            }
            if wants[IMAGE] {
                encoder.encode_image(k, &frame).unwrap();
                expected.push((IMAGE, k, encoder.image_json().to_vec()));
                encoder.encode_annotations(k, w, h, &report).unwrap();
                expected.push((ANNOTATIONS, k, encoder.annotations_json().to_vec()));
            }
            view.render(&frame, &report, None, &mut rgb);
            encoder.encode_birdseye(k, &view, &rgb).unwrap();
            expected.push((BIRDSEYE, k, encoder.birdseye_json().to_vec()));
        }
        thread.finish();
        assert_eq!(*got.lock().unwrap(), expected);
    }
}
