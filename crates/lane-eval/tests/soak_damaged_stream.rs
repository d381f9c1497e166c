//! Soak: a 20 000-frame YUV4MPEG2 stream (the `straight_solid` fixture looped, 320×240) with
//! damage injected every 250 frames, read through a pipe-like reader (no seeking, bytes made on
//! the fly) and tracked to its end. The lost frames are counted exactly, every other frame is
//! delivered under its true index and tracked, and memory stays flat: no allocation per frame
//! (counted with `alloc-counter`), and the live heap at the end equals the live heap after the
//! first 500 frames (tracked by the byte-counting allocator below).
//!
//! Damage kinds, in turn: a flipped byte in a `FRAME` header (loses that frame); a frame cut
//! short by 1000 bytes and by 3 bytes (it swallows the next frame's header: the next frame is
//! lost); three whole frames overwritten with junk (lost); bytes dropped across a frame boundary
//! (the next frame is lost).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::alloc::{GlobalAlloc, Layout};
use std::io::{BufReader, Read};
use std::sync::atomic::{AtomicI64, Ordering};
use std::time::Instant;

use alloc_counter::{CountingAllocator, allocations_in};
use lane_io::y4m::Y4mSource;
use lane_io::{FrameSource, GreyFrame, LaneIoError};
use lane_tracker::{Estimator, LaneState, LaneTracker, TrackerConfig};

/// Counts allocation calls per thread (through `alloc-counter`) and live heap bytes overall.
struct LiveBytes;

static LIVE: AtomicI64 = AtomicI64::new(0);
static INNER: CountingAllocator = CountingAllocator::new();

// SAFETY: forwards every call unchanged to `CountingAllocator` (itself forwarding to `System`);
// the only extra work is an atomic add, which neither allocates nor unwinds.
unsafe impl GlobalAlloc for LiveBytes {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LIVE.fetch_add(layout.size() as i64, Ordering::Relaxed);
        // SAFETY: the caller upholds `alloc`'s contract.
        unsafe { INNER.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        LIVE.fetch_add(layout.size() as i64, Ordering::Relaxed);
        // SAFETY: the caller upholds `alloc_zeroed`'s contract.
        unsafe { INNER.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size() as i64, Ordering::Relaxed);
        // SAFETY: the caller upholds `dealloc`'s contract.
        unsafe { INNER.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LIVE.fetch_add(new_size as i64 - layout.size() as i64, Ordering::Relaxed);
        // SAFETY: the caller upholds `realloc`'s contract.
        unsafe { INNER.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOC: LiveBytes = LiveBytes;

const FRAMES: u64 = 20_000;
const EVERY: u64 = 250;
const W: usize = 320;
const H: usize = 240;
const PLANE: usize = W * H;

/// The damaged stream, made record by record as it is read (like a pipe: no seeking, and never
/// more than one record in memory).
struct DamagedStream {
    header: Vec<u8>,
    frames: Vec<Vec<u8>>,
    next: u64,
    buf: Vec<u8>,
    pos: usize,
    /// Frames the damage costs (filled in as the stream is made).
    lost: Vec<u64>,
    /// Bytes to drop from the start of the next record.
    drop_next: usize,
    /// Records still to overwrite with junk.
    junk_left: u32,
}

impl DamagedStream {
    fn new(fixture: &[u8]) -> Self {
        let header_len = fixture.iter().position(|&b| b == b'\n').unwrap() + 1;
        let frames = fixture[header_len..]
            .chunks_exact(6 + PLANE)
            .map(|r| {
                assert_eq!(&r[..6], b"FRAME\n");
                r[6..].to_vec()
            })
            .collect();
        DamagedStream {
            header: fixture[..header_len].to_vec(),
            frames,
            next: 0,
            buf: Vec::with_capacity(6 + PLANE),
            pos: 0,
            // Reserved up front: the test's own bookkeeping must not grow the heap it measures.
            lost: Vec::with_capacity(256),
            drop_next: 0,
            junk_left: 0,
        }
    }

    /// Make record `i` (the header first) into `buf`.
    fn make(&mut self, i: u64) {
        self.buf.clear();
        if i == 0 {
            self.buf.extend_from_slice(&self.header);
        }
        let start = self.buf.len();
        self.buf.extend_from_slice(b"FRAME\n");
        let frame = &self.frames[i as usize % self.frames.len()];
        self.buf.extend_from_slice(frame);
        if self.junk_left > 0 {
            self.junk_left -= 1;
            self.buf[start..].fill(b'x');
            self.lost.push(i);
        } else if i % EVERY == EVERY / 2 {
            match (i / EVERY) % 5 {
                0 => {
                    let at = start + (i / EVERY) as usize % 6;
                    self.buf[at] ^= 0x04;
                    self.lost.push(i);
                }
                1 => {
                    self.buf.truncate(self.buf.len() - 1000);
                    self.lost.push(i + 1);
                }
                2 => {
                    self.buf[start..].fill(b'x');
                    self.junk_left = 2;
                    self.lost.push(i);
                }
                3 => {
                    self.buf.truncate(self.buf.len() - 3);
                    self.lost.push(i + 1);
                }
                _ => {
                    self.buf.truncate(self.buf.len() - 100);
                    self.drop_next = 3;
                    self.lost.push(i + 1);
                }
            }
        }
        let drop = std::mem::take(&mut self.drop_next).min(self.buf.len() - start);
        if i % EVERY != EVERY / 2 && drop > 0 {
            self.buf.drain(start..start + drop);
        } else if drop > 0 {
            self.drop_next = drop;
        }
        self.pos = 0;
    }
}

impl Read for DamagedStream {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        if self.pos == self.buf.len() {
            if self.next == FRAMES {
                return Ok(0);
            }
            let i = self.next;
            self.next += 1;
            self.make(i);
        }
        // Deliver in uneven pieces, as a pipe does.
        let n = out.len().min(self.buf.len() - self.pos).min(4093);
        out[..n].copy_from_slice(&self.buf[self.pos..self.pos + n]);
        self.pos += n;
        Ok(n)
    }
}

#[test]
fn a_long_damaged_stream_plays_to_its_end_with_exact_losses_and_flat_memory() {
    assert_eq!(
        allocations_in(|| std::hint::black_box(Box::new(1u8))).1,
        1,
        "the counting allocator is installed"
    );
    // The rendered straight road (deterministic), as the YUV4MPEG2 bytes `cargo xtask fixtures`
    // writes.
    let spec = lane_scenes::SCENES
        .iter()
        .find(|s| s.name == "straight_solid")
        .copied()
        .unwrap();
    let mut fixture = Vec::new();
    lane_scenes::write_scene_y4m(spec, W, H, &mut fixture, "straight_solid").unwrap();
    let started = Instant::now();
    let mut stream = DamagedStream::new(&fixture);
    drop(fixture);
    // `&mut` so that the stream's record of what it damaged can be read afterwards.
    let mut src = Y4mSource::new(BufReader::with_capacity(1 << 16, &mut stream), "soak").unwrap();
    let cfg = TrackerConfig::outdoor().unwrap();
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, W, H).unwrap();
    let mut frame = GreyFrame::default();
    let mut delivered = Vec::with_capacity(FRAMES as usize);
    let (mut lost_reported, mut resyncs, mut steady_allocs) = (0u64, 0u64, 0u64);
    let (mut tracking, mut reported) = (0u64, 0u64);
    let mut live_warm = None;
    loop {
        let ((r, report), n) = allocations_in(|| {
            let r = src.next_frame(&mut frame);
            let report = matches!(r, Ok(Some(_))).then(|| tracker.track(&frame));
            (r, report)
        });
        if live_warm.is_some() {
            steady_allocs += n;
        }
        match r {
            Ok(Some(m)) => {
                let report = report.unwrap().unwrap();
                delivered.push(m.index);
                for lane in &report.lanes {
                    reported += u64::from(matches!(
                        lane.state,
                        LaneState::Tracking | LaneState::Coasting
                    ));
                    tracking += u64::from(lane.state == LaneState::Tracking);
                }
                if delivered.len() == 500 {
                    live_warm = Some(LIVE.load(Ordering::Relaxed));
                }
            }
            Ok(None) => break,
            Err(e @ LaneIoError::Y4mResync { .. }) => {
                lost_reported += e.lost_frames();
                resyncs += 1;
            }
            Err(e) => panic!("unexpected {e}"),
        }
    }
    let live_end = LIVE.load(Ordering::Relaxed);
    let elapsed = started.elapsed();
    drop(src);
    let lost = &stream.lost;
    let events = FRAMES / EVERY;
    // Exact accounting: every frame either delivered under its index or counted as lost.
    let want: Vec<u64> = (0..FRAMES).filter(|i| !lost.contains(i)).collect();
    assert_eq!(delivered, want);
    assert_eq!(lost_reported, lost.len() as u64);
    assert_eq!(resyncs, events);
    // Five kinds in turn: (1 + 1 + 3 + 1 + 1) frames per five events.
    assert_eq!(lost.len() as u64, events / 5 * 7);
    // Tracked throughout: both lanes reported on every delivered frame but a few after each
    // frame that arrived damaged, and actually updated on ≥ 98 % of them.
    let lanes = 2 * delivered.len() as u64;
    assert!(
        reported + 2 * 3 * events >= lanes,
        "{reported} of {lanes} lane reports"
    );
    assert!(
        tracking * 100 >= lanes * 98,
        "{tracking} of {lanes} lanes tracking"
    );
    // Flat memory: the only steady-state allocations are the resync errors' (their stream
    // name), and the heap in use at the end is what it was after 500 frames.
    let live_warm = live_warm.unwrap();
    assert!(
        steady_allocs <= 2 * events,
        "{steady_allocs} allocations after warm-up"
    );
    assert_eq!(
        live_end, live_warm,
        "live heap bytes after 500 frames and at the end"
    );
    eprintln!(
        "soak: {FRAMES} frames, {} lost in {resyncs} resyncs, {steady_allocs} allocations after \
         warm-up, live heap {live_warm} → {live_end} B, {:.2} s",
        lost.len(),
        elapsed.as_secs_f64()
    );
}
