//! Reading a bag's topic costs no allocation per message once the reader's buffers have grown
//! (a chunk, a payload): none at all from uncompressed chunks, and at most one per compressed
//! chunk (the `mcap` crate parses each chunk header's compression name into a `String`).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::collections::BTreeMap;

use alloc_counter::allocations_in;
use ros_bag::bag::{TopicInfo, TopicReader};
use ros_bag::msgs::{Header, Image};

#[global_allocator]
static ALLOC: alloc_counter::CountingAllocator = alloc_counter::CountingAllocator::new();

const FRAMES: usize = 40;

fn write_bag(path: &std::path::Path, compression: Option<mcap::Compression>) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = mcap::WriteOptions::new()
        .compression(compression)
        .chunk_size(Some(16 * 1024))
        .create(file)
        .unwrap();
    let schema = w
        .add_schema("sensor_msgs/msg/Image", "ros2msg", b"uint32 height")
        .unwrap();
    let channel = w
        .add_channel(schema, "/camera", "cdr", &BTreeMap::new())
        .unwrap();
    for i in 0..FRAMES {
        let pixels: Vec<u8> = (0..64 * 48)
            .map(|p| ((p * 7 + i * 13) % 251) as u8)
            .collect();
        let data = Image {
            header: Header {
                sec: i as i32,
                nanosec: 0,
                frame_id: "camera",
            },
            height: 48,
            width: 64,
            encoding: "mono8",
            is_bigendian: 0,
            step: 64,
            data: &pixels,
        }
        .encode();
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: i as u32,
            log_time: i as u64,
            publish_time: i as u64,
        };
        w.write_to_known_channel(&header, &data).unwrap();
    }
    w.finish().unwrap();
}

#[test]
fn reading_a_topic_does_not_allocate_per_message() {
    for compression in [
        None,
        Some(mcap::Compression::Zstd),
        Some(mcap::Compression::Lz4),
    ] {
        let path = std::env::temp_dir().join(format!(
            "ros-bag-no-alloc-{}-{compression:?}.mcap",
            std::process::id()
        ));
        write_bag(&path, compression);
        let topic = TopicInfo {
            topic: "/camera".to_owned(),
            schema: "sensor_msgs/msg/Image".to_owned(),
            encoding: "cdr".to_owned(),
        };
        let mut reader = TopicReader::open(path.to_str().unwrap(), topic).unwrap();
        // Warm-up: the first chunks and messages grow the buffers.
        for _ in 0..10 {
            assert!(reader.next_message().unwrap().is_some());
        }
        let (read, n) = allocations_in(|| {
            let mut read = 0;
            while let Some(m) = reader.next_message().unwrap() {
                assert!(Image::decode(m.data).unwrap().data.len() == 64 * 48);
                read += 1;
            }
            read
        });
        let bytes = std::fs::read(&path).unwrap();
        let chunks = mcap::Summary::read(&bytes)
            .unwrap()
            .unwrap()
            .chunk_indexes
            .len();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(read, FRAMES - 10, "{compression:?}");
        assert!(chunks >= 5, "{chunks} chunks: the test needs several");
        let allowed = if compression.is_some() {
            chunks as u64
        } else {
            0
        };
        assert!(
            n <= allowed,
            "{compression:?}: {n} allocations in {read} messages over {chunks} chunks"
        );
    }
}
