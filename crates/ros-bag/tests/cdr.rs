//! CDR round trips of the ROS 2 messages, their decoding against hand-laid bytes (alignment,
//! big endian), cut or damaged messages as errors (never a panic), and the FLU → FRD axes of
//! an IMU sample.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod common;

use proptest::prelude::*;
use ros_bag::cdr::CdrReader;
use ros_bag::msgs::{CompressedImage, Header, Image, Imu};

fn header(frame_id: &str) -> Header<'_> {
    Header {
        sec: 12,
        nanosec: 345_000_000,
        frame_id,
    }
}

#[test]
fn an_image_is_laid_out_as_the_omg_cdr_spec_says() {
    let data = [1u8, 2, 3, 4, 5, 6];
    let img = Image {
        header: header("cam"),
        height: 2,
        width: 3,
        encoding: "mono8",
        is_bigendian: 0,
        step: 3,
        data: &data,
    };
    let bytes = img.encode();
    // header 00 01 00 00; sec, nanosec; frame_id "cam\0" (len 4); height, width (4-aligned);
    // encoding "mono8\0" (len 6) then 2 bytes of padding before... is_bigendian (1 byte, no
    // alignment), then step aligned to 4.
    let mut want = vec![0, 1, 0, 0];
    want.extend(12i32.to_le_bytes());
    want.extend(345_000_000u32.to_le_bytes());
    want.extend(4u32.to_le_bytes());
    want.extend(b"cam\0");
    want.extend(2u32.to_le_bytes());
    want.extend(3u32.to_le_bytes());
    want.extend(6u32.to_le_bytes());
    want.extend(b"mono8\0");
    want.push(0); // is_bigendian at offset 4 + 34
    want.push(0); // padding to a multiple of 4 (relative to the end of the header)
    want.extend(3u32.to_le_bytes());
    want.extend(6u32.to_le_bytes());
    want.extend(data);
    assert_eq!(bytes, want);
    assert_eq!(Image::decode(&bytes).unwrap(), img);
    assert!((img.header.t_s() - 12.345).abs() < 1e-12);
}

#[test]
fn big_endian_messages_are_read() {
    // CDR_BE: 00 00; an Imu-free check on the header fields.
    let mut b = vec![0u8, 0, 0, 0];
    b.extend(7i32.to_be_bytes());
    b.extend(9u32.to_be_bytes());
    b.extend(1u32.to_be_bytes());
    b.push(0);
    let mut r = CdrReader::new(&b).unwrap();
    assert_eq!(r.i32("sec").unwrap(), 7);
    assert_eq!(r.u32("nanosec").unwrap(), 9);
    assert_eq!(r.string("frame_id").unwrap(), "");
}

#[test]
fn imu_axes_go_from_flu_to_frd() {
    let imu = Imu {
        header: header("imu"),
        angular_velocity_radps: [0.1, 0.2, 0.3],
        linear_acceleration_mps2: [1.0, 2.0, 9.8],
    };
    let encoded = imu.encode();
    let back = Imu::decode(&encoded).unwrap();
    assert_eq!(back, imu);
    // At rest level, ROS (z up) reads +g on z; the FRD body (z down) reads −g.
    let (f, w) = back.frd();
    assert_eq!(f, [1.0, -2.0, -9.8]);
    assert_eq!(w, [0.1, -0.2, -0.3]);
}

#[test]
fn cut_and_damaged_messages_are_errors() {
    let data = vec![7u8; 100];
    let img = Image {
        header: header("camera"),
        height: 10,
        width: 10,
        encoding: "mono8",
        is_bigendian: 0,
        step: 10,
        data: &data,
    };
    let bytes = img.encode();
    for cut in 0..bytes.len() {
        assert!(Image::decode(&bytes[..cut]).is_err(), "cut at {cut}");
    }
    let mut bad = bytes.clone();
    bad[0] = 7; // unknown encapsulation
    let e = Image::decode(&bad).unwrap_err().to_string();
    assert!(e.contains("encapsulation"), "{e}");
}

const SEED: u64 = 0x6364_7200;

proptest! {
    #![proptest_config(common::seeded(256, SEED))]
    #[test]
    fn messages_round_trip(
        frame_id in "[a-z_/]{0,12}",
        sec in any::<i32>(),
        nanosec in 0u32..1_000_000_000,
        w in 1u32..9, h in 1u32..9,
        format in "(jpeg|png)",
        data in proptest::collection::vec(any::<u8>(), 0..200),
    ) {
        let hd = Header { sec, nanosec, frame_id: &frame_id };
        let pixels: Vec<u8> = (0..w * h).map(|i| i as u8).collect();
        let img = Image { header: hd, height: h, width: w, encoding: "mono8", is_bigendian: 0, step: w, data: &pixels };
        let bytes = img.encode();
        prop_assert_eq!(Image::decode(&bytes).unwrap(), img);
        let c = CompressedImage { header: hd, format: &format, data: &data };
        let bytes = c.encode();
        prop_assert_eq!(CompressedImage::decode(&bytes).unwrap(), c);
    }

    /// Arbitrary bytes never panic: each decoder gives a typed error or a message, and a
    /// message it accepts encodes to bytes that decode to the same message.
    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
        if let Ok(m) = Image::decode(&bytes) {
            let encoded = m.encode();
            prop_assert_eq!(Image::decode(&encoded).unwrap(), m);
        }
        if let Ok(m) = CompressedImage::decode(&bytes) {
            let encoded = m.encode();
            prop_assert_eq!(CompressedImage::decode(&encoded).unwrap(), m);
        }
        if let Ok(m) = Imu::decode(&bytes) {
            let encoded = m.encode();
            let again = Imu::decode(&encoded).unwrap();
            // NaN fields are equal in their bits, not as numbers.
            prop_assert_eq!(format!("{again:?}"), format!("{m:?}"));
        }
    }
}
