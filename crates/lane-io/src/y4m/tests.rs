use super::*;

fn stream(header: &str, frames: &[&[u8]]) -> Vec<u8> {
    let mut s = header.as_bytes().to_vec();
    s.push(b'\n');
    for f in frames {
        s.extend_from_slice(b"FRAME\n");
        s.extend_from_slice(f);
    }
    s
}

#[test]
fn mono_frames_are_read_in_order_with_time_stamps() {
    let f0: Vec<u8> = (0..12).collect();
    let f1: Vec<u8> = (100..112).collect();
    let s = stream("YUV4MPEG2 W4 H3 F25:1 Ip A1:1 Cmono", &[&f0, &f1]);
    let mut src = Y4mSource::new(&s[..], "t").unwrap();
    let mut frame = GreyFrame::default();
    let m0 = src.next_frame(&mut frame).unwrap().unwrap();
    assert_eq!((frame.width(), frame.height()), (4, 3));
    assert_eq!(frame.data(), f0);
    assert_eq!(m0.index, 0);
    let m1 = src.next_frame(&mut frame).unwrap().unwrap();
    assert_eq!(frame.data(), f1);
    assert_eq!(m1.index, 1);
    assert!((m1.t_s - 0.04).abs() < 1e-12);
    assert!(src.next_frame(&mut frame).unwrap().is_none());
}

#[test]
fn every_420_variant_yields_the_y_plane_and_skips_chroma() {
    // 5×3 → chroma planes 3×2 each.
    for c in ["", " C420", " C420jpeg", " C420paldv", " C420mpeg2"] {
        let mut f0: Vec<u8> = (0..15).collect();
        f0.extend(std::iter::repeat_n(200u8, 12));
        let mut f1: Vec<u8> = (50..65).collect();
        f1.extend(std::iter::repeat_n(7u8, 12));
        let s = stream(&format!("YUV4MPEG2 W5 H3 F30000:1001{c}"), &[&f0, &f1]);
        let mut src = Y4mSource::new(&s[..], "t").unwrap();
        assert_eq!(src.header().chroma, Y4mChroma::C420, "chroma tag {c:?}");
        let mut frame = GreyFrame::default();
        src.next_frame(&mut frame).unwrap().unwrap();
        assert_eq!(
            frame.data(),
            (0..15).collect::<Vec<u8>>(),
            "chroma tag {c:?}"
        );
        src.next_frame(&mut frame).unwrap().unwrap();
        assert_eq!(
            frame.data(),
            (50..65).collect::<Vec<u8>>(),
            "chroma tag {c:?}"
        );
        assert!(src.next_frame(&mut frame).unwrap().is_none());
    }
}

#[test]
fn frame_parameters_after_frame_are_accepted() {
    let s = b"YUV4MPEG2 W2 H1 Cmono\nFRAME Ixyz\n\x01\x02".to_vec();
    let mut src = Y4mSource::new(&s[..], "t").unwrap();
    let mut frame = GreyFrame::default();
    src.next_frame(&mut frame).unwrap().unwrap();
    assert_eq!(frame.data(), vec![1, 2]);
}

#[test]
fn bad_headers_are_typed_errors_naming_the_stream() {
    let cases: &[(&[u8], &str)] = &[
        (b"", "empty"),
        (b"YUV4MPEG W4 H3\n", "magic"),
        (b"YUV4MPEG2 H3 Cmono\n", "width"),
        (b"YUV4MPEG2 W4 Cmono\n", "height"),
        (b"YUV4MPEG2 Wx H3\n", "width"),
        (b"YUV4MPEG2 W4 H3 Fabc\n", "frame rate"),
        (b"YUV4MPEG2 W4 H3 Q9\n", "unknown tag"),
        (b"\xff\xfe\n", "ASCII"),
        // A token starting with a character of more than one byte: a tag error, not a panic.
        (
            "YUV4MPEG2 W4 H3 \u{a9}\n".as_bytes(),
            "unknown tag `\u{a9}`",
        ),
    ];
    for (bytes, what) in cases {
        let err = Y4mSource::new(*bytes, "clip.y4m").unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, LaneIoError::Y4mHeader { .. }), "{msg}");
        assert!(
            msg.contains("clip.y4m") && msg.contains(what),
            "{msg} lacks {what}"
        );
        assert!(err.is_fatal());
    }
}

#[test]
fn zero_size_is_refused() {
    let err = Y4mSource::new(&b"YUV4MPEG2 W0 H240 Cmono\n"[..], "z.y4m").unwrap_err();
    assert!(
        matches!(
            err,
            LaneIoError::ZeroSize {
                width: 0,
                height: 240,
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn unsupported_chroma_is_named() {
    for c in ["422", "444", "444alpha", "411", "mono16", "420p10"] {
        let err =
            Y4mSource::new(format!("YUV4MPEG2 W4 H2 C{c}\n").as_bytes(), "c.y4m").unwrap_err();
        match &err {
            LaneIoError::UnsupportedChroma { chroma, name } => {
                assert_eq!(chroma, c);
                assert_eq!(name, "c.y4m");
            }
            other => panic!("C{c}: {other}"),
        }
    }
}

#[test]
fn short_last_frame_is_reported_non_fatal_then_the_stream_ends() {
    let mut s = stream("YUV4MPEG2 W4 H3 Cmono", &[&[9u8; 12]]);
    s.extend_from_slice(b"FRAME\n");
    s.extend_from_slice(&[1u8; 5]);
    let mut src = Y4mSource::new(&s[..], "short.y4m").unwrap();
    let mut frame = GreyFrame::default();
    assert!(src.next_frame(&mut frame).unwrap().is_some());
    let err = src.next_frame(&mut frame).unwrap_err();
    assert!(
        matches!(
            err,
            LaneIoError::ShortFrame {
                frame: 1,
                expected: 12,
                got: 5,
                ..
            }
        ),
        "{err}"
    );
    assert!(!err.is_fatal());
    assert!(err.to_string().contains("short.y4m"));
    assert!(src.next_frame(&mut frame).unwrap().is_none());
}

#[test]
fn short_chroma_in_a_420_frame_is_a_short_frame() {
    let mut s = b"YUV4MPEG2 W2 H2 C420jpeg\nFRAME\n".to_vec();
    s.extend_from_slice(&[1, 2, 3, 4, 128]); // Y plane + 1 of 2 chroma bytes
    let mut src = Y4mSource::new(&s[..], "t").unwrap();
    let err = src.next_frame(&mut GreyFrame::default()).unwrap_err();
    assert!(
        matches!(
            err,
            LaneIoError::ShortFrame {
                expected: 6,
                got: 5,
                ..
            }
        ),
        "{err}"
    );
}

/// Frames `0..n` of 4×3 mono, frame `i` filled with `i`.
fn numbered(n: u8) -> Vec<u8> {
    let frames: Vec<Vec<u8>> = (0..n).map(|i| vec![i; 12]).collect();
    let refs: Vec<&[u8]> = frames.iter().map(Vec::as_slice).collect();
    stream("YUV4MPEG2 W4 H3 F25:1 Cmono", &refs)
}

/// Byte offset of frame `i`'s `FRAME` line in [`numbered`] (header 28 bytes, records 18).
fn record(i: usize) -> usize {
    "YUV4MPEG2 W4 H3 F25:1 Cmono\n".len() + i * 18
}

/// Everything a source yields: delivered (index, first pixel), and the errors.
fn drain<R: BufRead>(src: &mut Y4mSource<R>) -> (Vec<(u64, u8)>, Vec<LaneIoError>) {
    let (mut frames, mut errors) = (Vec::new(), Vec::new());
    let mut frame = GreyFrame::default();
    for _ in 0..1000 {
        match src.next_frame(&mut frame) {
            Ok(Some(m)) => {
                assert_eq!(frame.data().len(), frame.width() * frame.height());
                frames.push((m.index, frame.data()[0]));
            }
            Ok(None) => return (frames, errors),
            Err(e) => {
                assert!(!e.is_fatal(), "{e}");
                errors.push(e);
            }
        }
    }
    panic!("source never ended");
}

#[test]
fn a_flipped_byte_in_a_frame_header_loses_that_frame_only() {
    for offset in 0..6 {
        let mut s = numbered(8);
        s[record(3) + offset] ^= 0x20;
        let mut src = Y4mSource::new(&s[..], "flip.y4m").unwrap();
        let (frames, errors) = drain(&mut src);
        let want: Vec<(u64, u8)> = [0u8, 1, 2, 4, 5, 6, 7]
            .iter()
            .map(|&i| (u64::from(i), i))
            .collect();
        assert_eq!(frames, want, "byte {offset} of the header flipped");
        assert_eq!(errors.len(), 1);
        assert!(
            matches!(
                errors[0],
                LaneIoError::Y4mResync {
                    frame: 3,
                    lost_frames: 1,
                    skipped_bytes: 18,
                    end_of_stream: false,
                    ..
                }
            ),
            "{}",
            errors[0]
        );
        let msg = errors[0].to_string();
        assert!(msg.contains("flip.y4m") && msg.contains("frame 3"), "{msg}");
        assert_eq!(
            src.losses(),
            Y4mLosses {
                frames: 1,
                bytes: 18,
                resyncs: 1
            }
        );
        // Time stamps stay those of the true indices.
        let mut src = Y4mSource::new(&s[..], "flip.y4m").unwrap();
        let mut frame = GreyFrame::default();
        let mut last = None;
        loop {
            match src.next_frame(&mut frame) {
                Ok(Some(m)) => last = Some(m),
                Ok(None) => break,
                Err(_) => {}
            }
        }
        let last = last.unwrap();
        assert_eq!(last.index, 7);
        assert!((last.t_s - 7.0 / 25.0).abs() < 1e-12);
    }
}

#[test]
fn garbage_of_several_frames_is_skipped_and_counted() {
    let mut s = numbered(10);
    // Frames 2, 3, 4 wholly overwritten with junk (no marker in it).
    for b in &mut s[record(2)..record(5)] {
        *b = b'x';
    }
    let mut src = Y4mSource::new(&s[..], "g.y4m").unwrap();
    let (frames, errors) = drain(&mut src);
    let idx: Vec<u64> = frames.iter().map(|f| f.0).collect();
    assert_eq!(idx, vec![0, 1, 5, 6, 7, 8, 9]);
    assert!(frames.iter().all(|&(i, v)| u64::from(v) == i));
    assert!(
        matches!(
            errors[..],
            [LaneIoError::Y4mResync {
                frame: 2,
                lost_frames: 3,
                skipped_bytes: 54,
                ..
            }]
        ),
        "{errors:?}"
    );
}

#[test]
fn a_frame_cut_short_mid_stream_costs_the_next_frame_and_indices_stay_true() {
    let mut s = numbered(8);
    // Frame 2 loses 5 of its 12 bytes: it swallows frame 3's `FRAME` line.
    s.drain(record(2) + 6..record(2) + 11);
    let mut src = Y4mSource::new(&s[..], "cut.y4m").unwrap();
    let (frames, errors) = drain(&mut src);
    let idx: Vec<u64> = frames.iter().map(|f| f.0).collect();
    assert_eq!(idx, vec![0, 1, 2, 4, 5, 6, 7]);
    assert!(frames[3..].iter().all(|&(i, v)| u64::from(v) == i));
    assert!(
        matches!(
            errors[..],
            [LaneIoError::Y4mResync {
                frame: 3,
                lost_frames: 1,
                ..
            }]
        ),
        "{errors:?}"
    );
}

#[test]
fn damage_at_the_start_and_at_the_end_is_counted() {
    let mut s = numbered(5);
    s[record(0)] = b'G';
    s[record(4) + 2] = b'?';
    let mut src = Y4mSource::new(&s[..], "e.y4m").unwrap();
    let (frames, errors) = drain(&mut src);
    assert_eq!(
        frames.iter().map(|f| f.0).collect::<Vec<_>>(),
        vec![1, 2, 3]
    );
    assert!(
        matches!(
            errors[..],
            [
                LaneIoError::Y4mResync {
                    frame: 0,
                    lost_frames: 1,
                    end_of_stream: false,
                    ..
                },
                LaneIoError::Y4mResync {
                    frame: 4,
                    lost_frames: 1,
                    skipped_bytes: 18,
                    end_of_stream: true,
                    ..
                }
            ]
        ),
        "{errors:?}"
    );
    assert_eq!(src.losses().frames, 2);
}

#[test]
fn a_huge_declared_frame_over_a_short_stream_allocates_what_is_there() {
    let mut s = b"YUV4MPEG2 W30000 H30000 Cmono\nFRAME\n".to_vec();
    s.extend_from_slice(&[7; 1000]);
    let mut src = Y4mSource::new(&s[..], "big.y4m").unwrap();
    let mut frame = GreyFrame::default();
    let err = src.next_frame(&mut frame).unwrap_err();
    assert!(
        matches!(err, LaneIoError::ShortFrame { got: 1000, .. }),
        "{err}"
    );
    assert!(frame.capacity() <= 1 << 21, "{}", frame.capacity());
    assert_eq!(
        (frame.width(), frame.height(), frame.data().len()),
        (0, 0, 0)
    );
}

#[test]
fn concatenated_streams_of_the_same_size_continue_and_a_new_size_is_an_error() {
    let mut same = stream("YUV4MPEG2 W2 H1 Cmono", &[&[1, 2]]);
    same.extend(stream("YUV4MPEG2 W2 H1 Cmono", &[&[3, 4]]));
    let mut src = Y4mSource::new(&same[..], "s").unwrap();
    let mut frame = GreyFrame::default();
    src.next_frame(&mut frame).unwrap().unwrap();
    let m = src.next_frame(&mut frame).unwrap().unwrap();
    assert_eq!((m.index, frame.data()), (1, &[3u8, 4][..]));

    let mut changed = stream("YUV4MPEG2 W2 H1 Cmono", &[&[1, 2]]);
    changed.extend(stream("YUV4MPEG2 W3 H1 Cmono", &[&[3, 4, 5]]));
    let mut src = Y4mSource::new(&changed[..], "c.y4m").unwrap();
    src.next_frame(&mut frame).unwrap().unwrap();
    let err = src.next_frame(&mut frame).unwrap_err();
    assert!(
        matches!(
            err,
            LaneIoError::SizeChanged {
                frame: 1,
                from_w: 2,
                to_w: 3,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.is_fatal());
}

#[test]
fn writer_round_trips_grey_and_colour_streams() {
    let grey: Vec<u8> = (0..15).map(|i| i * 10).collect();
    for chroma in [Y4mChroma::Mono, Y4mChroma::C420] {
        let mut w = Y4mWriter::new(Vec::new(), 5, 3, 25.0, chroma).unwrap();
        w.write_grey(&grey).unwrap();
        let rgb: Vec<u8> = grey.iter().flat_map(|&g| [g, g, g]).collect();
        w.write_rgb(&rgb, &mut Vec::new()).unwrap();
        let bytes = w.finish().unwrap();
        let mut src = Y4mSource::new(&bytes[..], "rt").unwrap();
        assert_eq!(src.header().chroma, chroma);
        assert!((src.frame_rate_hz().unwrap() - 25.0).abs() < 1e-9);
        let mut frame = GreyFrame::default();
        src.next_frame(&mut frame).unwrap().unwrap();
        assert_eq!(frame.data(), grey);
        src.next_frame(&mut frame).unwrap().unwrap();
        assert_eq!(frame.data(), grey, "grey RGB → Y is the identity");
        assert!(src.next_frame(&mut frame).unwrap().is_none());
    }
}

#[test]
fn writer_refuses_a_frame_of_the_wrong_size() {
    let mut w = Y4mWriter::new(Vec::new(), 4, 4, 30.0, Y4mChroma::Mono).unwrap();
    assert!(w.write_grey(&[0; 15]).is_err());
    assert!(w.write_rgb(&[0; 47], &mut Vec::new()).is_err());
}
