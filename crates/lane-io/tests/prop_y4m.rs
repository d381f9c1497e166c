//! Property tests of the YUV4MPEG2 reader: valid streams round-trip through the writer; damaged
//! streams (flipped bytes, truncation, inserted and deleted bytes, absurd headers, random bytes)
//! never panic, always end, allocate no more than the bytes present justify, and either deliver
//! frames or return the typed error; a flipped `FRAME` header loses exactly its frame.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use lane_io::y4m::{Y4mChroma, Y4mSource, Y4mWriter};
use lane_io::{FrameSource, GreyFrame, LaneIoError};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x7934_6d00),
        failure_persistence: None,
        ..Config::default()
    }
}

/// A stream of `frames` (each `w·h` bytes) written by the crate's writer.
fn write(w: usize, h: usize, chroma: Y4mChroma, fps: f64, frames: &[Vec<u8>]) -> Vec<u8> {
    let mut wr = Y4mWriter::new(Vec::new(), w, h, fps, chroma).unwrap();
    for f in frames {
        wr.write_grey(f).unwrap();
    }
    wr.finish().unwrap()
}

/// What reading a whole stream gave.
#[derive(Debug, Default)]
struct Drained {
    frames: Vec<(u64, Vec<u8>)>,
    errors: Vec<LaneIoError>,
    /// The largest capacity the frame buffer reached, bytes.
    max_capacity: usize,
}

/// Read `bytes` to the end, checking the reader's contract on every call: a delivered frame
/// has `width·height` bytes, indices increase, a fatal error ends the stream, the stream ends
/// within one call per byte.
fn drain(bytes: &[u8]) -> Result<Drained, LaneIoError> {
    let mut src = Y4mSource::new(bytes, "p.y4m")?;
    let mut d = Drained::default();
    let mut frame = GreyFrame::default();
    for _ in 0..bytes.len() + 4 {
        let r = src.next_frame(&mut frame);
        d.max_capacity = d.max_capacity.max(frame.capacity());
        match r {
            Ok(Some(m)) => {
                assert_eq!(frame.data().len(), frame.width() * frame.height());
                assert_eq!(
                    (frame.width(), frame.height()),
                    (src.header().width, src.header().height)
                );
                if let Some((last, _)) = d.frames.last() {
                    assert!(m.index > *last, "indices increase");
                }
                d.frames.push((m.index, frame.data().to_vec()));
            }
            Ok(None) => {
                let lost: u64 = d.errors.iter().map(LaneIoError::lost_frames).sum();
                assert_eq!(src.losses().frames, lost, "losses() totals the errors");
                return Ok(d);
            }
            Err(e) => {
                let fatal = e.is_fatal();
                d.errors.push(e);
                if fatal {
                    assert!(matches!(src.next_frame(&mut frame), Ok(None)));
                    return Ok(d);
                }
            }
        }
    }
    panic!("the stream did not end within one call per byte");
}

fn frames_strategy(
    max_w: usize,
    max_h: usize,
    max_n: usize,
    max_px: u8,
) -> impl Strategy<Value = (usize, usize, Vec<Vec<u8>>)> {
    (1..=max_w, 1..=max_h).prop_flat_map(move |(w, h)| {
        (
            Just(w),
            Just(h),
            prop::collection::vec(prop::collection::vec(0..=max_px, w * h), 0..=max_n),
        )
    })
}

fn chroma() -> impl Strategy<Value = Y4mChroma> {
    prop_oneof![Just(Y4mChroma::Mono), Just(Y4mChroma::C420)]
}

/// One damage to a byte stream, at a position given as a fraction of its length.
#[derive(Debug, Clone)]
enum Damage {
    FlipBit(f64, u8),
    Insert(f64, Vec<u8>),
    Delete(f64, usize),
    Truncate(f64),
    /// Overwrite with a marker or header text (a false `FRAME`, a second header).
    Splice(f64, &'static [u8]),
}

fn damage() -> impl Strategy<Value = Damage> {
    let at = 0.0f64..1.0;
    prop_oneof![
        (at.clone(), 0u8..8).prop_map(|(a, b)| Damage::FlipBit(a, b)),
        (at.clone(), prop::collection::vec(any::<u8>(), 1..40))
            .prop_map(|(a, v)| Damage::Insert(a, v)),
        (at.clone(), 1usize..200).prop_map(|(a, n)| Damage::Delete(a, n)),
        at.clone().prop_map(Damage::Truncate),
        (
            at,
            prop::sample::select(vec![
                &b"FRAME\n"[..],
                b"FRAME Ixyz\n",
                b"FRAME",
                b"YUV4MPEG2 W99999 H99999 Cmono\n",
                b"YUV4MPEG2 W7 H3 C444\n",
                b"YUV4MPEG2 Wabc\n",
            ])
        )
            .prop_map(|(a, s)| Damage::Splice(a, s)),
    ]
}

fn apply(bytes: &mut Vec<u8>, d: &Damage) {
    let pos = |f: f64, len: usize| ((f * len as f64) as usize).min(len);
    match d {
        Damage::FlipBit(f, bit) if !bytes.is_empty() => {
            let i = pos(*f, bytes.len() - 1);
            bytes[i] ^= 1 << bit;
        }
        Damage::Insert(f, v) => {
            let i = pos(*f, bytes.len());
            bytes.splice(i..i, v.iter().copied());
        }
        Damage::Delete(f, n) => {
            let i = pos(*f, bytes.len());
            let end = (i + n).min(bytes.len());
            bytes.drain(i..end);
        }
        Damage::Truncate(f) => {
            let i = pos(*f, bytes.len());
            bytes.truncate(i);
        }
        Damage::Splice(f, s) => {
            let i = pos(*f, bytes.len());
            let end = (i + s.len()).min(bytes.len());
            bytes.splice(i..end, s.iter().copied());
        }
        Damage::FlipBit(..) => {}
    }
}

/// The frame buffer may grow to 1 MiB before it knows the stream is short, and to twice the
/// bytes actually present after that.
fn capacity_bound(stream_len: usize) -> usize {
    (1 << 20) + 2 * stream_len
}

proptest! {
    #![proptest_config(config(128))]

    /// write → read gives the same frames, indices, time stamps and no loss.
    #[test]
    fn valid_streams_round_trip(
        (w, h, frames) in frames_strategy(24, 16, 6, 255),
        chroma in chroma(),
        fps in prop_oneof![Just(25.0), Just(29.97), 1.0f64..120.0],
    ) {
        let bytes = write(w, h, chroma, fps, &frames);
        let mut src = Y4mSource::new(&bytes[..], "rt.y4m").unwrap();
        prop_assert_eq!((src.header().width, src.header().height), (w, h));
        prop_assert_eq!(src.header().chroma, chroma);
        let fps_read = src.frame_rate_hz().unwrap();
        prop_assert!((fps_read - fps).abs() <= 5e-4, "{} vs {}", fps_read, fps);
        let mut frame = GreyFrame::default();
        for (i, want) in frames.iter().enumerate() {
            let m = src.next_frame(&mut frame).unwrap().unwrap();
            prop_assert_eq!(m.index, i as u64);
            prop_assert!((m.t_s - i as f64 / fps_read).abs() < 1e-9);
            prop_assert_eq!(frame.data(), want);
        }
        prop_assert!(src.next_frame(&mut frame).unwrap().is_none());
        prop_assert_eq!(src.losses(), Default::default());
    }

    /// One flipped byte in the `FRAME` header of some frames loses exactly those frames: the
    /// others arrive intact under their true indices, and the loss is counted in frames and
    /// bytes. (Pixels stay below `F`, so no false marker hides in the data.)
    #[test]
    fn flipped_frame_headers_lose_exactly_their_frames(
        (w, h, frames) in frames_strategy(12, 8, 10, b'E'),
        chroma in chroma(),
        damaged in prop::collection::vec((any::<bool>(), 0usize..6, 1u8..=255), 0..10),
    ) {
        let mut bytes = write(w, h, chroma, 25.0, &frames);
        let header_len = bytes.iter().position(|&b| b == b'\n').unwrap() + 1;
        let plane = bytes.len() - header_len;
        let record = if frames.is_empty() { 6 } else { plane / frames.len() };
        let mut lost = Vec::new();
        for (i, (hit, at, mask)) in damaged.iter().enumerate().take(frames.len()) {
            // `FRAME\n` → `FRAME ` would be a valid header with parameters: not a flip of interest.
            if !hit || (*at == 5 && b'\n' ^ mask == b' ') {
                continue;
            }
            bytes[header_len + i * record + at] ^= mask;
            lost.push(i as u64);
        }
        let d = drain(&bytes).unwrap();
        let want: Vec<(u64, Vec<u8>)> = frames
            .iter()
            .enumerate()
            .filter(|(i, _)| !lost.contains(&(*i as u64)))
            .map(|(i, f)| (i as u64, f.clone()))
            .collect();
        prop_assert_eq!(&d.frames, &want);
        prop_assert!(
            d.errors.iter().all(|e| matches!(e, LaneIoError::Y4mResync { .. })),
            "{:?}",
            d.errors
        );
        let lost_frames: u64 = d.errors.iter().map(LaneIoError::lost_frames).sum();
        let skipped: u64 = d.errors.iter().map(LaneIoError::skipped_bytes).sum();
        prop_assert_eq!(lost_frames, lost.len() as u64);
        prop_assert_eq!(skipped, (lost.len() * record) as u64);
    }

    /// A stream cut anywhere after its header delivers exactly the whole frames before the cut,
    /// then at most one non-fatal error for the partial one.
    #[test]
    fn truncated_streams_deliver_the_whole_frames_before_the_cut(
        (w, h, frames) in frames_strategy(12, 8, 6, 255),
        chroma in chroma(),
        cut in 0.0f64..1.0,
    ) {
        let bytes = write(w, h, chroma, 25.0, &frames);
        let header_len = bytes.iter().position(|&b| b == b'\n').unwrap() + 1;
        let at = header_len + ((bytes.len() - header_len) as f64 * cut) as usize;
        let d = drain(&bytes[..at]).unwrap();
        let record = if frames.is_empty() { 1 } else { (bytes.len() - header_len) / frames.len() };
        let whole = (at - header_len) / record;
        prop_assert_eq!(d.frames.len(), whole);
        for (i, (index, data)) in d.frames.iter().enumerate() {
            prop_assert_eq!(*index, i as u64);
            prop_assert_eq!(data, &frames[i]);
        }
        let partial = !(at - header_len).is_multiple_of(record);
        prop_assert_eq!(d.errors.len(), usize::from(partial), "{:?}", d.errors);
        prop_assert!(d.errors.iter().all(|e| !e.is_fatal() && e.lost_frames() == 1));
    }

    /// Any mix of damage: no panic, the stream ends, every error is typed, and the frame
    /// buffer stays within what the bytes present justify.
    #[test]
    fn damaged_streams_never_panic_and_stay_bounded(
        (w, h, frames) in frames_strategy(16, 8, 6, 255),
        chroma in chroma(),
        damages in prop::collection::vec(damage(), 1..6),
    ) {
        let mut bytes = write(w, h, chroma, 25.0, &frames);
        for dmg in &damages {
            apply(&mut bytes, dmg);
        }
        match drain(&bytes) {
            Ok(d) => {
                prop_assert!(d.max_capacity <= capacity_bound(bytes.len()), "{}", d.max_capacity);
                for e in &d.errors {
                    prop_assert!(
                        matches!(
                            e,
                            LaneIoError::Y4mResync { .. }
                                | LaneIoError::ShortFrame { .. }
                                | LaneIoError::SizeChanged { .. }
                                | LaneIoError::Y4mHeader { .. }
                                | LaneIoError::UnsupportedChroma { .. }
                                | LaneIoError::ZeroSize { .. }
                        ),
                        "{e}"
                    );
                    prop_assert!(e.to_string().contains("p.y4m"), "{e}");
                }
            }
            Err(e) => prop_assert!(
                matches!(
                    e,
                    LaneIoError::Y4mHeader { .. }
                        | LaneIoError::UnsupportedChroma { .. }
                        | LaneIoError::ZeroSize { .. }
                ),
                "{e}"
            ),
        }
    }

    /// Absurd header numbers (huge, negative, non-numeric sizes and rates) are typed header
    /// errors; an accepted size is within the 2³⁰-pixel cap, and a short stream after it does
    /// not make the reader allocate the announced frame.
    #[test]
    fn absurd_headers_are_typed_errors_and_never_allocate_the_announced_size(
        w in prop_oneof![any::<u64>().prop_map(|v| v.to_string()), "[0-9]{15,40}", "-?[0-9]{1,6}", "[a-z]{0,3}"],
        h in prop_oneof![any::<u64>().prop_map(|v| v.to_string()), "[0-9]{15,40}", "-?[0-9]{1,6}"],
        rate in prop_oneof![Just(String::new()), "F[0-9]{1,25}:[0-9]{1,25}", "F[a-z0-9:]{0,6}"],
        c in prop_oneof![Just(String::new()), Just(" Cmono".to_owned()), " C[a-z0-9]{0,8}"],
        tail in prop::collection::vec(any::<u8>(), 0..64),
    ) {
        let mut bytes = format!("YUV4MPEG2 W{w} H{h} {rate}{c}\nFRAME\n").into_bytes();
        bytes.extend_from_slice(&tail);
        match Y4mSource::new(&bytes[..], "h.y4m") {
            Ok(mut src) => {
                let (sw, sh) = (src.header().width, src.header().height);
                prop_assert!(sw > 0 && sh > 0 && sw * sh <= 1 << 30);
                prop_assert!(src.header().fps.is_finite() && src.header().fps >= 0.0);
                let mut frame = GreyFrame::default();
                let _ = src.next_frame(&mut frame);
                prop_assert!(frame.capacity() <= capacity_bound(bytes.len()));
            }
            Err(e) => prop_assert!(
                matches!(
                    e,
                    LaneIoError::Y4mHeader { .. }
                        | LaneIoError::UnsupportedChroma { .. }
                        | LaneIoError::ZeroSize { .. }
                ),
                "{e}"
            ),
        }
    }

    /// Random bytes, with or without a plausible header in front.
    #[test]
    fn random_bytes_never_panic(
        header in prop_oneof![Just(&b""[..]), Just(&b"YUV4MPEG2 W4 H3 Cmono\n"[..]), Just(&b"YUV4MPEG2 W3 H3\n"[..])],
        body in prop::collection::vec(prop_oneof![any::<u8>(), Just(b'F'), Just(b'\n')], 0..600),
    ) {
        let mut bytes = header.to_vec();
        bytes.extend_from_slice(&body);
        if let Ok(d) = drain(&bytes) {
            prop_assert!(d.max_capacity <= capacity_bound(bytes.len()));
        }
    }
}
