//! Property tests of the image sources: a directory holding any mix of good images, images of
//! another size, junk, empty files and truncated PNGs delivers exactly its good frames in name
//! order and reports every other file as a non-fatal bad frame naming it; a still image of any
//! bytes decodes or is a typed error. Never a panic.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::path::{Path, PathBuf};

use lane_io::sources::{ImageDirectory, decode_image_bytes, open_input};
use lane_io::{FrameSource, GreyFrame, LaneIoError};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x6469_7200),
        failure_persistence: None,
        ..Config::default()
    }
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("nav-app-prop-sources")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn png(w: u32, h: u32, seed: u8) -> Vec<u8> {
    let img = image::GrayImage::from_fn(w, h, |x, y| {
        image::Luma([(x as u8).wrapping_mul(7) ^ (y as u8).wrapping_mul(13) ^ seed])
    });
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// One file of a directory under test.
#[derive(Debug, Clone)]
enum File {
    /// A good PNG of the sequence's size (8×6).
    Good(u8),
    /// A good PNG of another size.
    OtherSize(u32, u32),
    /// Bytes that are no image (they start with `#`, no format's magic).
    Junk(Vec<u8>),
    /// An empty `.png`.
    Empty,
    /// A good PNG cut to this fraction of its length.
    Truncated(f64),
}

fn file() -> impl Strategy<Value = File> {
    prop_oneof![
        3 => any::<u8>().prop_map(File::Good),
        1 => (1u32..12, 1u32..12)
            .prop_filter("another size", |&(w, h)| (w, h) != (8, 6))
            .prop_map(|(w, h)| File::OtherSize(w, h)),
        1 => prop::collection::vec(any::<u8>(), 0..200).prop_map(|mut v| {
            v.insert(0, b'#');
            File::Junk(v)
        }),
        1 => Just(File::Empty),
        1 => (0.0f64..0.9).prop_map(File::Truncated),
    ]
}

impl File {
    fn bytes(&self) -> Vec<u8> {
        match self {
            File::Good(seed) => png(8, 6, *seed),
            File::OtherSize(w, h) => png(*w, *h, 1),
            File::Junk(v) => v.clone(),
            File::Empty => Vec::new(),
            File::Truncated(f) => {
                let p = png(8, 6, 2);
                let n = (p.len() as f64 * f) as usize;
                p[..n].to_vec()
            }
        }
    }
}

proptest! {
    #![proptest_config(config(64))]

    #[test]
    fn a_directory_delivers_its_good_frames_and_reports_every_bad_file(
        files in prop::collection::vec(file(), 1..10),
        case in any::<u32>(),
    ) {
        let dir = scratch(&format!("dir-{case}"));
        let mut expect_size = None;
        let mut want = Vec::new();
        for (i, f) in files.iter().enumerate() {
            let bytes = f.bytes();
            let path = dir.join(format!("f{i:02}.png"));
            std::fs::write(&path, &bytes).unwrap();
            // What the file should give: decoded independently with the `image` crate.
            if let Ok(img) = image::load_from_memory(&bytes) {
                let size = (img.width() as usize, img.height() as usize);
                if *expect_size.get_or_insert(size) == size {
                    want.push((i as u64, img.into_luma8().into_raw()));
                }
            }
        }
        let mut src = ImageDirectory::open(&dir, 25.0).unwrap();
        let mut frame = GreyFrame::default();
        let (mut got, mut bad) = (Vec::new(), Vec::new());
        for _ in 0..=files.len() {
            match src.next_frame(&mut frame) {
                Ok(Some(m)) => {
                    prop_assert_eq!(frame.data().len(), frame.width() * frame.height());
                    prop_assert!((m.t_s - m.index as f64 / 25.0).abs() < 1e-12);
                    got.push((m.index, frame.data().to_vec()));
                }
                Ok(None) => break,
                Err(e) => {
                    prop_assert!(!e.is_fatal(), "{}", e);
                    match &e {
                        LaneIoError::BadFrame { name, frame, .. }
                        | LaneIoError::FrameSizeDiffers { name, frame, .. } => {
                            prop_assert!(name.ends_with(&format!("f{frame:02}.png")), "{}", e);
                            bad.push(*frame);
                        }
                        other => prop_assert!(false, "unexpected {other}"),
                    }
                }
            }
        }
        prop_assert!(src.next_frame(&mut frame).unwrap().is_none());
        prop_assert_eq!(got.len() + bad.len(), files.len());
        prop_assert_eq!(got, want);
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Any bytes as a still image: a grey frame of the decoded size, or a typed error naming
    /// the file.
    #[test]
    fn any_bytes_decode_or_give_a_typed_error(
        base in prop_oneof![
            Just(Vec::new()),
            Just(png(5, 4, 3)),
            Just(b"P5\n3 2\n255\n\x01\x02\x03\x04\x05\x06".to_vec()),
            Just(b"P5\n99999 99999\n255\n".to_vec()),
            Just(b"P2\n0 4\n255\n".to_vec()),
        ],
        flips in prop::collection::vec((0.0f64..1.0, 0u8..8), 0..4),
        cut in 0.0f64..=1.0,
    ) {
        let mut bytes = base;
        for (at, bit) in flips {
            if !bytes.is_empty() {
                let i = ((bytes.len() - 1) as f64 * at) as usize;
                bytes[i] ^= 1 << bit;
            }
        }
        bytes.truncate((bytes.len() as f64 * cut).ceil() as usize);
        let mut frame = GreyFrame::default();
        match decode_image_bytes("img.pgm", &bytes, &mut frame) {
            Ok(()) => {
                prop_assert!(frame.width() > 0 && frame.height() > 0);
                prop_assert_eq!(frame.data().len(), frame.width() * frame.height());
            }
            Err(e) => {
                prop_assert!(
                    matches!(e, LaneIoError::ImageDecode { .. } | LaneIoError::ZeroSize { .. }),
                    "{}",
                    e
                );
                prop_assert!(e.to_string().contains("img.pgm"), "{}", e);
            }
        }
    }

    /// `--input` on a file of any bytes and any of the recognised extensions: a source or a
    /// typed error naming the file; reading it never panics.
    #[test]
    fn open_input_on_any_file_is_a_source_or_a_typed_error(
        ext in prop::sample::select(vec!["y4m", "png", "pgm", "jpg", "bin"]),
        lead in prop::sample::select(vec![&b""[..], b"YUV4MPEG2 W4 H2 Cmono\n", b"\x89PNG\r\n\x1a\n"]),
        body in prop::collection::vec(any::<u8>(), 0..120),
        case in any::<u32>(),
    ) {
        let dir = scratch(&format!("input-{case}"));
        let path = dir.join(format!("in.{ext}"));
        let mut bytes = lead.to_vec();
        bytes.extend_from_slice(&body);
        std::fs::write(&path, &bytes).unwrap();
        let name = path.display().to_string();
        match open_input(&path, 25.0) {
            Ok(mut src) => {
                let mut frame = GreyFrame::default();
                for _ in 0..=bytes.len() + 1 {
                    match src.next_frame(&mut frame) {
                        Ok(Some(_)) => prop_assert_eq!(frame.data().len(), frame.width() * frame.height()),
                        Ok(None) => break,
                        Err(e) => {
                            prop_assert!(e.to_string().contains(&name), "{}", e);
                            if e.is_fatal() {
                                break;
                            }
                        }
                    }
                }
            }
            Err(e) => prop_assert!(e.to_string().contains(&name), "{}", e),
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
