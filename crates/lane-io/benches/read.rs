//! Reading 320×240 mono8 frames: from a YUV4MPEG2 file and from a ROS 2 bag (MCAP,
//! `sensor_msgs/msg/Image`, uncompressed chunks), 200 frames per iteration; the per-frame cost
//! of the bag over the y4m reader is the difference of the two (criterion's time / 200).
//!
//! `cargo bench -p lane-io --bench read -- --warm-up-time 1 --measurement-time 4`
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use lane_io::y4m::{Y4mChroma, Y4mSource, Y4mWriter};
use lane_io::{FrameSource, GreyFrame};
use ros_bag::msgs::{Header, Image};

const FRAMES: usize = 200;
const W: usize = 320;
const H: usize = 240;

fn frame(k: usize) -> Vec<u8> {
    (0..W * H).map(|i| ((i * 7 + k * 13) % 251) as u8).collect()
}

fn files() -> (PathBuf, PathBuf) {
    let dir = std::env::temp_dir().join(format!("ita-nav-bench-read-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let y4m = dir.join("frames.y4m");
    let mut w = Y4mWriter::new(
        std::fs::File::create(&y4m).unwrap(),
        W,
        H,
        25.0,
        Y4mChroma::Mono,
    )
    .unwrap();
    for k in 0..FRAMES {
        w.write_grey(&frame(k)).unwrap();
    }
    w.finish().unwrap();
    let bag = dir.join("frames.mcap");
    let options = mcap::WriteOptions::new().compression(None);
    let mut m = mcap::Writer::with_options(
        std::io::BufWriter::new(std::fs::File::create(&bag).unwrap()),
        options,
    )
    .unwrap();
    let schema = m
        .add_schema("sensor_msgs/msg/Image", "ros2msg", b"")
        .unwrap();
    let channel = m
        .add_channel(schema, "/camera/image_raw", "cdr", &BTreeMap::new())
        .unwrap();
    for k in 0..FRAMES {
        let data = frame(k);
        let msg = Image {
            header: Header {
                sec: 0,
                nanosec: (k * 40_000_000) as u32,
                frame_id: "camera",
            },
            height: H as u32,
            width: W as u32,
            encoding: "mono8",
            is_bigendian: 0,
            step: W as u32,
            data: &data,
        }
        .encode();
        let t = (k * 40_000_000) as u64;
        m.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: channel,
                sequence: k as u32,
                log_time: t,
                publish_time: t,
            },
            &msg,
        )
        .unwrap();
    }
    m.finish().unwrap();
    (y4m, bag)
}

fn read_all(src: &mut dyn FrameSource, frame: &mut GreyFrame) -> usize {
    let mut n = 0;
    while src.next_frame(frame).unwrap().is_some() {
        n += 1;
    }
    n
}

fn bench(c: &mut Criterion) {
    let (y4m, bag) = files();
    let mut g = c.benchmark_group("read_frames_320x240_mono8");
    g.throughput(Throughput::Elements(FRAMES as u64));
    let mut frame = GreyFrame::default();
    g.bench_function("y4m", |b| {
        b.iter(|| {
            let file =
                std::io::BufReader::with_capacity(1 << 16, std::fs::File::open(&y4m).unwrap());
            let mut src = Y4mSource::new(file, "bench").unwrap();
            assert_eq!(black_box(read_all(&mut src, &mut frame)), FRAMES);
        })
    });
    g.bench_function("mcap", |b| {
        b.iter(|| {
            let mut src =
                lane_io::mcap_source::McapImageSource::open(Path::new(&bag), None).unwrap();
            assert_eq!(black_box(read_all(&mut src, &mut frame)), FRAMES);
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
