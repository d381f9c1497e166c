//! Damaged bags at the container level: a bag written with the `mcap` crate (several chunks,
//! each compression), then cut short anywhere or with any byte flipped. Reading it must never
//! panic, and whatever it delivers before the damage must be the messages as written, in order —
//! a damaged chunk is an error (its CRC), never a wrong pixel. Bags whose image topic is not CDR,
//! or is chosen with the wrong type, are clear errors naming the topic.

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod common;

use std::collections::BTreeMap;
use std::io::Write;

use proptest::prelude::*;
use ros_bag::BagError;
use ros_bag::bag::{self, TopicReader};
use ros_bag::msgs::{Header, Image, Imu};

const IMAGE_TOPIC: &str = "/camera/image_raw";
const FRAMES: usize = 24;

/// The image messages of the test bag: 16×12 `mono8` frames, each a different pattern.
fn images() -> Vec<Vec<u8>> {
    (0..FRAMES)
        .map(|i| {
            let pixels: Vec<u8> = (0..16 * 12).map(|p| (p * 7 + i * 31) as u8).collect();
            Image {
                header: Header {
                    sec: i as i32,
                    nanosec: 0,
                    frame_id: "camera",
                },
                height: 12,
                width: 16,
                encoding: "mono8",
                is_bigendian: 0,
                step: 16,
                data: &pixels,
            }
            .encode()
        })
        .collect()
}

/// A bag with an image topic (message encoding `image_encoding`) and an IMU topic, in chunks of
/// about 1 KiB.
fn bag_bytes(compression: Option<mcap::Compression>, image_encoding: &str) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    let mut w = mcap::WriteOptions::new()
        .compression(compression)
        .chunk_size(Some(1024))
        .create(&mut out)
        .unwrap();
    let image_schema = w
        .add_schema("sensor_msgs/msg/Image", "ros2msg", b"uint32 height")
        .unwrap();
    let imu_schema = w
        .add_schema("sensor_msgs/msg/Imu", "ros2msg", b"float64[9] x")
        .unwrap();
    let image = w
        .add_channel(image_schema, IMAGE_TOPIC, image_encoding, &BTreeMap::new())
        .unwrap();
    let imu = w
        .add_channel(imu_schema, "/imu", "cdr", &BTreeMap::new())
        .unwrap();
    let imu_msg = Imu {
        header: Header {
            sec: 0,
            nanosec: 0,
            frame_id: "imu",
        },
        angular_velocity_radps: [0.0, 0.0, 0.01],
        linear_acceleration_mps2: [0.1, 0.0, 9.81],
    }
    .encode();
    for (i, data) in images().iter().enumerate() {
        let t = i as u64 * 100_000_000;
        let header = |channel_id| mcap::records::MessageHeader {
            channel_id,
            sequence: i as u32,
            log_time: t,
            publish_time: t,
        };
        w.write_to_known_channel(&header(image), data).unwrap();
        w.write_to_known_channel(&header(imu), &imu_msg).unwrap();
    }
    w.finish().unwrap();
    drop(w);
    out.into_inner()
}

/// A file in the temporary directory, removed when dropped.
struct TempBag(std::path::PathBuf);

impl TempBag {
    fn path(&self) -> &std::path::Path {
        &self.0
    }
}

impl Drop for TempBag {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

fn write_temp(bytes: &[u8]) -> TempBag {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let path =
        std::env::temp_dir().join(format!("ros-bag-damaged-{}-{n}.mcap", std::process::id()));
    let mut f = std::fs::File::create(&path).unwrap();
    f.write_all(bytes).unwrap();
    TempBag(path)
}

/// Reads the image topic as `nav-app` does; returns the payloads delivered and the error that
/// stopped the reading, if any.
fn read_images(path: &str) -> (Vec<Vec<u8>>, Option<BagError>) {
    let topics = match bag::topics(path) {
        Ok(t) => t,
        Err(e) => return (Vec::new(), Some(e)),
    };
    let topic = match bag::choose_topic(
        path,
        &topics,
        Some(IMAGE_TOPIC),
        &["sensor_msgs/msg/Image"],
        "image",
    ) {
        Ok(t) => t,
        Err(e) => return (Vec::new(), Some(e)),
    };
    let mut reader = match TopicReader::open(path, topic) {
        Ok(r) => r,
        Err(e) => return (Vec::new(), Some(e)),
    };
    let mut got = Vec::new();
    loop {
        match reader.next_message() {
            Ok(Some(m)) => got.push(m.data.to_vec()),
            Ok(None) => return (got, None),
            Err(e) => return (got, Some(e)),
        }
    }
}

/// Every delivered payload is one of the written ones, in the written order (none altered,
/// none repeated), and decodes as the image it was.
fn assert_faithful(got: &[Vec<u8>], written: &[Vec<u8>]) -> Result<(), TestCaseError> {
    let mut next = 0;
    for g in got {
        let Some(at) = written[next..].iter().position(|w| w == g) else {
            return Err(TestCaseError::fail(format!(
                "a delivered message (after {next} written ones) is not one that was written"
            )));
        };
        next += at + 1;
        prop_assert!(Image::decode(g).is_ok());
    }
    Ok(())
}

const COMPRESSIONS: [Option<mcap::Compression>; 3] = [
    None,
    Some(mcap::Compression::Zstd),
    Some(mcap::Compression::Lz4),
];

#[test]
fn an_intact_bag_delivers_every_image_as_written_with_each_compression() {
    for c in COMPRESSIONS {
        let f = write_temp(&bag_bytes(c, "cdr"));
        let (got, err) = read_images(f.path().to_str().unwrap());
        assert!(err.is_none(), "{c:?}: {err:?}");
        assert_eq!(got, images(), "{c:?}");
    }
}

#[test]
fn a_topic_that_is_not_cdr_is_an_encoding_error_naming_it() {
    let f = write_temp(&bag_bytes(None, "protobuf"));
    let (got, err) = read_images(f.path().to_str().unwrap());
    assert!(got.is_empty());
    match err {
        Some(e @ BagError::Encoding { .. }) => {
            let text = e.to_string();
            assert!(
                text.contains(IMAGE_TOPIC) && text.contains("protobuf"),
                "{text}"
            );
        }
        other => panic!("expected an encoding error, got {other:?}"),
    }
}

#[test]
fn a_topic_of_the_wrong_type_is_refused_with_the_list_of_topics() {
    let f = write_temp(&bag_bytes(None, "cdr"));
    let path = f.path().to_str().unwrap();
    let topics = bag::topics(path).unwrap();
    let e = bag::choose_topic(
        path,
        &topics,
        Some("/imu"),
        &["sensor_msgs/msg/Image"],
        "image",
    )
    .unwrap_err();
    let text = e.to_string();
    assert!(text.contains("/imu is sensor_msgs/msg/Imu"), "{text}");
    assert!(
        text.contains("/camera/image_raw (sensor_msgs/msg/Image)"),
        "{text}"
    );
}

const SEED: u64 = 0x6d63_6170;

proptest! {
    #![proptest_config(common::seeded(256, SEED))]

    #[test]
    fn a_bag_cut_short_anywhere_delivers_a_faithful_prefix(
        compression in 0usize..3,
        keep in 0.0f64..1.0,
    ) {
        let bytes = bag_bytes(COMPRESSIONS[compression], "cdr");
        let cut = (keep * bytes.len() as f64) as usize;
        let f = write_temp(&bytes[..cut]);
        let (got, err) = read_images(f.path().to_str().unwrap());
        let written = images();
        prop_assert!(got.len() <= written.len());
        prop_assert_eq!(&got[..], &written[..got.len()]);
        // Losing messages is only allowed with an error saying so.
        if got.len() < written.len() {
            prop_assert!(err.is_some());
        }
        if let Some(e) = err {
            prop_assert!(e.to_string().contains(f.path().to_str().unwrap()), "{}", e);
        }
    }

    #[test]
    fn a_bag_with_any_byte_flipped_never_delivers_an_altered_message(
        compression in 0usize..3,
        at in 0.0f64..1.0,
        mask in 1u8..=255,
    ) {
        let mut bytes = bag_bytes(COMPRESSIONS[compression], "cdr");
        let i = ((at * bytes.len() as f64) as usize).min(bytes.len() - 1);
        bytes[i] ^= mask;
        let f = write_temp(&bytes);
        let (got, err) = read_images(f.path().to_str().unwrap());
        assert_faithful(&got, &images())?;
        if let Some(e) = err {
            prop_assert!(e.to_string().contains(f.path().to_str().unwrap()), "{}", e);
        }
    }
}
