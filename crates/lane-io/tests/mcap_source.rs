//! Bag images to grey frames: every supported pixel encoding converts to the expected luma, a
//! PNG `CompressedImage` decodes, and a message that cannot be converted is a non-fatal
//! `BadFrame` naming the frame and the typed problem, after which reading goes on.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::collections::BTreeMap;

use lane_io::mcap_source::McapImageSource;
use lane_io::{BagImageProblem, FrameSource, GreyFrame, LaneIoError};
use ros_bag::msgs::{CompressedImage, Header, Image};

const W: usize = 4;
const H: usize = 3;

/// The test pattern's grey value at (row, column); in colour (below) the three channels differ, so
/// the channel order matters.
fn grey(r: usize, c: usize) -> u8 {
    (40 * r + 17 * c + 5) as u8
}

fn rgb(r: usize, c: usize) -> [u8; 3] {
    let g = grey(r, c);
    [g, g.wrapping_add(60), g.wrapping_add(120)]
}

fn header(sec: i32) -> Header<'static> {
    Header {
        sec,
        nanosec: 0,
        frame_id: "camera",
    }
}

fn image(sec: i32, encoding: &str, bpp: usize, pixel: impl Fn(usize, usize) -> Vec<u8>) -> Vec<u8> {
    let step = W * bpp + 2; // padded rows
    let mut data = vec![0xEE; step * H];
    for r in 0..H {
        for c in 0..W {
            let p = pixel(r, c);
            data[r * step + c * bpp..r * step + (c + 1) * bpp].copy_from_slice(&p);
        }
    }
    Image {
        header: header(sec),
        height: H as u32,
        width: W as u32,
        encoding,
        is_bigendian: 0,
        step: step as u32,
        data: &data,
    }
    .encode()
}

fn write_bag(path: &std::path::Path, messages: &[(&str, Vec<u8>)]) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = mcap::Writer::new(file).unwrap();
    let mut channels = BTreeMap::new();
    for (i, (schema, data)) in messages.iter().enumerate() {
        let topic = if *schema == "sensor_msgs/msg/Image" {
            "/camera/image_raw"
        } else {
            "/camera/compressed"
        };
        let channel = *channels.entry(topic).or_insert_with(|| {
            let s = w.add_schema(schema, "ros2msg", b"").unwrap();
            w.add_channel(s, topic, "cdr", &BTreeMap::new()).unwrap()
        });
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: i as u32,
            log_time: i as u64,
            publish_time: i as u64,
        };
        w.write_to_known_channel(&header, data).unwrap();
    }
    w.finish().unwrap();
}

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("lane-io-mcap-{}-{name}.mcap", std::process::id()))
}

fn expected(f: impl Fn(usize, usize) -> u8) -> Vec<u8> {
    (0..H)
        .flat_map(|r| (0..W).map(move |c| (r, c)))
        .map(|(r, c)| f(r, c))
        .collect()
}

#[test]
fn every_pixel_encoding_converts_and_bad_messages_are_skipped_with_their_problem() {
    const IMG: &str = "sensor_msgs/msg/Image";
    let luma = |r, c| {
        let [x, y, z] = rgb(r, c);
        grey_frame::luma_bt601(x, y, z)
    };
    let messages = vec![
        (IMG, image(0, "mono8", 1, |r, c| vec![grey(r, c)])),
        (IMG, image(1, "rgb8", 3, |r, c| rgb(r, c).to_vec())),
        (
            IMG,
            image(2, "bgr8", 3, |r, c| {
                let [x, y, z] = rgb(r, c);
                vec![z, y, x]
            }),
        ),
        (
            IMG,
            image(3, "rgba8", 4, |r, c| {
                let [x, y, z] = rgb(r, c);
                vec![x, y, z, 255]
            }),
        ),
        (
            IMG,
            image(4, "bgra8", 4, |r, c| {
                let [x, y, z] = rgb(r, c);
                vec![z, y, x, 0]
            }),
        ),
        // mono16 little endian: the high byte is the grey value.
        (IMG, image(5, "mono16", 2, |r, c| vec![0x7F, grey(r, c)])),
        (IMG, image(6, "yuv422", 2, |_, _| vec![0, 0])),
        (IMG, {
            let mut m = image(7, "mono8", 1, |r, c| vec![grey(r, c)]);
            m.truncate(m.len() - 8); // the data array claims more bytes than follow
            m
        }),
        (IMG, image(8, "mono8", 1, |r, c| vec![grey(r, c)])),
        // A row step and a height at u32::MAX (rows that fit their step): the bytes they need
        // exceed what follows, and overflow usize on a 32-bit target: short data.
        (
            IMG,
            Image {
                header: header(9),
                height: u32::MAX,
                width: 1,
                encoding: "mono8",
                is_bigendian: 0,
                step: u32::MAX,
                data: &[0; 16],
            }
            .encode(),
        ),
    ];
    let path = temp("encodings");
    write_bag(&path, &messages);
    let mut source = McapImageSource::open(&path, None).unwrap();
    let mut frame = GreyFrame::new(1, 1);
    let mut got = Vec::new();
    loop {
        match source.next_frame(&mut frame) {
            Ok(Some(meta)) => got.push(Ok((meta.t_s, frame.data().to_vec()))),
            Ok(None) => break,
            Err(e) => {
                assert!(!e.is_fatal(), "{e}");
                got.push(Err(e));
            }
        }
    }
    std::fs::remove_file(&path).unwrap();
    assert_eq!(got.len(), 10);
    let frame_ok = |i: usize, want: Vec<u8>| match &got[i] {
        Ok((t, data)) => {
            assert_eq!(*t, i as f64, "frame {i}");
            assert_eq!(*data, want, "frame {i}");
        }
        Err(e) => panic!("frame {i}: {e}"),
    };
    frame_ok(0, expected(grey));
    for i in 1..5 {
        frame_ok(i, expected(luma));
    }
    frame_ok(5, expected(grey));
    frame_ok(8, expected(grey));
    let problem = |i: usize| match &got[i] {
        Err(LaneIoError::BadFrame { frame, source, .. }) => {
            assert_eq!(*frame, i as u64);
            match &**source {
                LaneIoError::BagImage { topic, problem } => {
                    assert_eq!(topic, "/camera/image_raw");
                    problem
                }
                other => panic!("frame {i}: {other}"),
            }
        }
        other => panic!("frame {i}: {other:?}"),
    };
    assert!(matches!(
        problem(6),
        BagImageProblem::PixelEncoding { encoding } if encoding == "yuv422"
    ));
    assert!(matches!(problem(7), BagImageProblem::Message(_)));
    assert!(matches!(
        problem(9),
        BagImageProblem::ShortData { width_px, step, .. }
            if *width_px == 1 && *step == u32::MAX as usize
    ));
}

#[test]
fn a_png_compressed_image_decodes_and_an_unknown_format_is_skipped() {
    const COMPRESSED: &str = "sensor_msgs/msg/CompressedImage";
    let pixels = expected(grey);
    let mut png = Vec::new();
    image::GrayImage::from_raw(W as u32, H as u32, pixels.clone())
        .unwrap()
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let message = |sec, format| {
        CompressedImage {
            header: header(sec),
            format,
            data: &png,
        }
        .encode()
    };
    let messages = vec![
        (COMPRESSED, message(0, "png")),
        (COMPRESSED, message(1, "webp")),
        (COMPRESSED, message(2, "mono8; png compressed")),
    ];
    let path = temp("png");
    write_bag(&path, &messages);
    let mut source = McapImageSource::open(&path, Some("/camera/compressed")).unwrap();
    let mut frame = GreyFrame::new(1, 1);
    assert!(source.next_frame(&mut frame).unwrap().is_some());
    assert_eq!(frame.data(), &pixels[..]);
    let e = source.next_frame(&mut frame).unwrap_err();
    assert!(!e.is_fatal());
    assert!(e.to_string().contains("frame 1"), "{e}");
    let LaneIoError::BadFrame { source: inner, .. } = &e else {
        panic!("{e:?}")
    };
    assert!(
        matches!(&**inner, LaneIoError::BagImage { problem: BagImageProblem::CompressedFormat { format }, .. } if format == "webp"),
        "{inner:?}"
    );
    assert!(source.next_frame(&mut frame).unwrap().is_some());
    assert_eq!(frame.data(), &pixels[..]);
    assert!(source.next_frame(&mut frame).unwrap().is_none());
    std::fs::remove_file(&path).unwrap();
}
