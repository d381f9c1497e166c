//! Frame sources and bad input (issue 4 §2, §5): every case gives a typed error naming the file
//! or the frame; fatal ones stop, single bad frames are reported and skipped. Never a panic.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::path::{Path, PathBuf};

use lane_io::sources::{ImageDirectory, StillImage, open_device, open_input};
use lane_io::{FrameSource, GreyFrame, LaneIoError};

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("nav-app-sources")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write_png_grey(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> u8) {
    let img = image::GrayImage::from_fn(w, h, |x, y| image::Luma([f(x, y)]));
    img.save(path).unwrap();
}

fn drain(src: &mut dyn FrameSource) -> (Vec<(u64, Vec<u8>)>, Vec<LaneIoError>) {
    let mut frame = GreyFrame::default();
    let (mut ok, mut bad) = (Vec::new(), Vec::new());
    for _ in 0..100 {
        match src.next_frame(&mut frame) {
            Ok(Some(m)) => ok.push((m.index, frame.data().to_vec())),
            Ok(None) => break,
            Err(e) if !e.is_fatal() => bad.push(e),
            Err(e) => {
                bad.push(e);
                break;
            }
        }
    }
    (ok, bad)
}

#[test]
fn still_png_pgm_and_jpeg_are_read_once_as_grey() {
    let dir = scratch("still");
    let png = dir.join("a.png");
    write_png_grey(&png, 7, 5, |x, y| (10 * x + y) as u8);
    let (ok, bad) = drain(&mut StillImage::new(&png));
    assert!(bad.is_empty());
    assert_eq!(ok.len(), 1, "a still image is one frame");
    assert_eq!(ok[0].1[3 * 7 + 4], 43);

    let pgm = dir.join("b.pgm");
    let mut bytes = b"P5\n3 2\n255\n".to_vec();
    bytes.extend_from_slice(&[1, 2, 3, 4, 5, 6]);
    std::fs::write(&pgm, bytes).unwrap();
    let (ok, _) = drain(&mut StillImage::new(&pgm));
    assert_eq!(ok[0].1, vec![1, 2, 3, 4, 5, 6]);

    let jpg = dir.join("c.jpg");
    image::GrayImage::from_pixel(16, 8, image::Luma([200]))
        .save(&jpg)
        .unwrap();
    let (ok, _) = drain(&mut StillImage::new(&jpg));
    assert!(ok[0].1.iter().all(|&v| v.abs_diff(200) <= 2));
}

#[test]
fn colour_is_converted_to_grey_with_bt601_luma_like_capture_and_y4m() {
    let dir = scratch("colour");
    let path = dir.join("rgb.png");
    let img = image::RgbImage::from_fn(3, 1, |x, _| match x {
        0 => image::Rgb([255, 0, 0]),
        1 => image::Rgb([0, 255, 0]),
        _ => image::Rgb([0, 0, 255]),
    });
    img.save(&path).unwrap();
    let (ok, _) = drain(&mut StillImage::new(&path));
    let g = &ok[0].1;
    // BT.601 luma: 0.299, 0.587, 0.114 of 255 → 76, 150, 29 (Rec. 709 would give 54, 182, 18),
    // exactly what capture's conversion gives for the same pixels.
    assert_eq!(g, &vec![76, 150, 29]);
    for (x, rgb) in [[255u8, 0, 0], [0, 255, 0], [0, 0, 255]].iter().enumerate() {
        assert_eq!(
            g[x],
            bt848_capture::convert::luma_bt601(rgb[0], rgb[1], rgb[2])
        );
    }
}

#[test]
fn truncated_and_corrupt_still_images_are_fatal_errors_naming_the_file() {
    let dir = scratch("corrupt");
    let good = dir.join("good.png");
    write_png_grey(&good, 40, 30, |x, y| (x * y) as u8);
    let bytes = std::fs::read(&good).unwrap();
    let truncated = dir.join("truncated.png");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let garbage = dir.join("garbage.jpg");
    std::fs::write(&garbage, b"\xff\xd8\xff\xe0 this is not a jpeg").unwrap();
    let empty = dir.join("empty.png");
    std::fs::write(&empty, b"").unwrap();
    for path in [&truncated, &garbage, &empty] {
        let (ok, bad) = drain(&mut StillImage::new(path));
        assert!(ok.is_empty());
        assert_eq!(bad.len(), 1);
        assert!(bad[0].is_fatal());
        assert!(
            matches!(bad[0], LaneIoError::ImageDecode { .. }),
            "{}",
            bad[0]
        );
        assert!(
            bad[0].to_string().contains(&path.display().to_string()),
            "{}",
            bad[0]
        );
    }
    let missing = dir.join("missing.png");
    let (_, bad) = drain(&mut StillImage::new(&missing));
    assert!(matches!(bad[0], LaneIoError::Io { .. }) && bad[0].to_string().contains("missing.png"));
}

#[test]
fn zero_size_images_are_refused() {
    let dir = scratch("zero");
    let pgm = dir.join("zero.pgm");
    std::fs::write(&pgm, b"P5\n0 0\n255\n").unwrap();
    let (ok, bad) = drain(&mut StillImage::new(&pgm));
    assert!(ok.is_empty());
    assert!(bad[0].is_fatal());
    assert!(
        matches!(
            bad[0],
            LaneIoError::ZeroSize { .. } | LaneIoError::ImageDecode { .. }
        ),
        "{}",
        bad[0]
    );
    assert!(bad[0].to_string().contains("zero.pgm"));
    let y4m = dir.join("zero.y4m");
    std::fs::write(&y4m, b"YUV4MPEG2 W320 H0 Cmono\n").unwrap();
    let err = open_input(&y4m, 25.0).err().unwrap();
    assert!(
        matches!(err, LaneIoError::ZeroSize { height: 0, .. }),
        "{err}"
    );
}

#[test]
fn a_directory_is_a_sorted_sequence() {
    let dir = scratch("sorted");
    for (name, v) in [("0003.png", 3u8), ("0001.png", 1), ("0002.png", 2)] {
        write_png_grey(&dir.join(name), 4, 4, |_, _| v);
    }
    std::fs::write(dir.join(".hidden"), b"ignored").unwrap();
    std::fs::create_dir_all(dir.join("subdir")).unwrap();
    let mut src = ImageDirectory::open(&dir, 10.0).unwrap();
    let (ok, bad) = drain(&mut src);
    assert!(bad.is_empty());
    let firsts: Vec<u8> = ok.iter().map(|(_, d)| d[0]).collect();
    assert_eq!(firsts, vec![1, 2, 3]);
}

#[test]
fn a_directory_holding_a_non_image_is_refused_naming_the_file() {
    let dir = scratch("nonimage");
    write_png_grey(&dir.join("0001.png"), 4, 4, |_, _| 0);
    std::fs::write(dir.join("notes.txt"), b"hello").unwrap();
    let err = ImageDirectory::open(&dir, 25.0).unwrap_err();
    assert!(matches!(err, LaneIoError::NotAnImage { .. }), "{err}");
    assert!(err.to_string().contains("notes.txt"), "{err}");
    assert!(err.is_fatal());
    let empty = scratch("emptydir");
    assert!(matches!(
        ImageDirectory::open(&empty, 25.0),
        Err(LaneIoError::EmptyDirectory { .. })
    ));
}

#[test]
fn a_corrupt_or_resized_frame_in_a_directory_is_reported_counted_and_skipped() {
    let dir = scratch("badframe");
    write_png_grey(&dir.join("0001.png"), 8, 6, |_, _| 1);
    std::fs::write(dir.join("0002.png"), b"\x89PNG\r\n\x1a\n truncated").unwrap();
    write_png_grey(&dir.join("0003.png"), 9, 6, |_, _| 3);
    write_png_grey(&dir.join("0004.png"), 8, 6, |_, _| 4);
    let mut src = ImageDirectory::open(&dir, 25.0).unwrap();
    let (ok, bad) = drain(&mut src);
    assert_eq!(
        ok.iter().map(|(i, d)| (*i, d[0])).collect::<Vec<_>>(),
        vec![(0, 1), (3, 4)]
    );
    assert_eq!(bad.len(), 2);
    assert!(bad.iter().all(|e| !e.is_fatal()));
    assert!(
        matches!(&bad[0], LaneIoError::BadFrame { frame: 1, name, .. } if name.ends_with("0002.png"))
    );
    assert!(matches!(
        &bad[1],
        LaneIoError::FrameSizeDiffers {
            frame: 2,
            got_w: 9,
            got_h: 6,
            ..
        }
    ));
}

#[test]
fn open_input_dispatches_on_kind_and_device_says_capture_is_unavailable() {
    let dir = scratch("dispatch");
    let y4m = dir.join("clip.y4m");
    let mut s = b"YUV4MPEG2 W2 H2 F25:1 C420jpeg\nFRAME\n".to_vec();
    s.extend_from_slice(&[1, 2, 3, 4, 128, 128]);
    std::fs::write(&y4m, &s).unwrap();
    let (ok, _) = drain(&mut *open_input(&y4m, 25.0).unwrap());
    assert_eq!(ok[0].1, vec![1, 2, 3, 4]);
    // A y4m without the extension is recognised by its magic.
    let noext = dir.join("stream");
    std::fs::write(&noext, &s).unwrap();
    assert_eq!(drain(&mut *open_input(&noext, 25.0).unwrap()).0.len(), 1);
    let bad = dir.join("bad.y4m");
    std::fs::write(&bad, b"YUV4MPEG2 W2 H2 C444\nFRAME\n").unwrap();
    let err = open_input(&bad, 25.0).err().unwrap();
    assert!(
        matches!(err, LaneIoError::UnsupportedChroma { .. }) && err.to_string().contains("bad.y4m")
    );
    let err = open_device(Path::new("/nonexistent/video0")).err().unwrap();
    if cfg!(feature = "capture") {
        // Built with capture: the open itself fails, naming the path.
        assert!(matches!(err, LaneIoError::Capture { .. }), "{err}");
        assert!(err.to_string().contains("/nonexistent/video0"), "{err}");
    } else {
        assert!(matches!(err, LaneIoError::CaptureUnavailable { .. }));
        assert!(err.to_string().contains("not available in this build"));
    }
}
