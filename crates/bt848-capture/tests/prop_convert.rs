//! Property tests of the format conversions and the size parser: any buffer, size and stride
//! gives either the typed error the checks promise or a grey frame of the right size equal to an
//! independent per-pixel reference; never a panic.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use bt848_capture::convert::{luma_bt601, to_grey};
use bt848_capture::{CaptureError, PixelFormat, parse_size};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x6274_3834),
        failure_persistence: None,
        ..Config::default()
    }
}

fn format() -> impl Strategy<Value = PixelFormat> {
    proptest::sample::select(PixelFormat::ALL.to_vec())
}

/// Grey of pixel `x` of a row in `format`, read the slow obvious way.
fn reference(format: PixelFormat, row: &[u8], x: usize) -> u8 {
    match format {
        PixelFormat::Grey | PixelFormat::Yu12 => row[x],
        PixelFormat::Yuyv => row[2 * x],
        PixelFormat::Uyvy => row[2 * x + 1],
        PixelFormat::Bgr24 => luma_bt601(row[3 * x + 2], row[3 * x + 1], row[3 * x]),
        PixelFormat::Bgr32 => luma_bt601(row[4 * x + 2], row[4 * x + 1], row[4 * x]),
        PixelFormat::Rgb565 => {
            let word = u16::from(row[2 * x]) | u16::from(row[2 * x + 1]) << 8;
            let (r5, g6, b5) = (word >> 11, (word >> 5) & 0x3f, word & 0x1f);
            let widen = |v: u16, bits: u32| ((v << (8 - bits)) | (v >> (2 * bits - 8))) as u8;
            luma_bt601(widen(r5, 5), widen(g6, 6), widen(b5, 5))
        }
    }
}

proptest! {
    #![proptest_config(config(256))]

    /// Wrong sizes of every kind (output, stride, source, absurd strides) are typed errors.
    #[test]
    fn any_buffers_give_grey_or_the_typed_error(
        format in format(),
        width in 0u32..24,
        height in 0u32..24,
        stride_pick in prop_oneof![0usize..128, Just(usize::MAX), (usize::MAX / 4)..usize::MAX],
        src_len in 0usize..4096,
        dst_delta in -2isize..=2,
        fill in any::<u8>(),
    ) {
        let (w, h) = (width as usize, height as usize);
        let src = vec![fill; src_len];
        let dst_len = ((w * h) as isize + dst_delta).max(0) as usize;
        let mut dst = vec![0u8; dst_len];
        let row_bytes = w * format.bytes_per_pixel();
        let result = to_grey(format, &src, width, height, stride_pick, &mut dst);
        match result {
            Ok(()) => {
                prop_assert_eq!(dst_len, w * h);
                if w * h > 0 {
                    prop_assert!(stride_pick >= row_bytes);
                    prop_assert!(src_len >= format.bytes_needed(w, h, stride_pick));
                }
            }
            Err(CaptureError::OutputSize { expected, got, .. }) => {
                prop_assert_eq!((expected, got), (w * h, dst_len));
                prop_assert_ne!(dst_len, w * h);
            }
            Err(CaptureError::StrideTooSmall { stride_bytes, row_bytes: rb, .. }) => {
                prop_assert_eq!(dst_len, w * h);
                prop_assert!(stride_bytes < rb);
                prop_assert_eq!(rb, row_bytes);
            }
            Err(CaptureError::SourceTooShort { needed, got, .. }) => {
                prop_assert_eq!(dst_len, w * h);
                prop_assert!(got < needed);
                prop_assert_eq!(got, src_len);
            }
            Err(other) => prop_assert!(false, "unexpected error {other}"),
        }
    }

    /// A valid frame converts to `width·height` grey bytes equal to the per-pixel reference,
    /// whatever the padding between rows holds.
    #[test]
    fn a_valid_frame_converts_pixel_by_pixel(
        format in format(),
        width in 1u32..20,
        height in 1u32..12,
        pad in 0usize..9,
        seed in any::<u64>(),
    ) {
        let (w, h) = (width as usize, height as usize);
        let stride = w * format.bytes_per_pixel() + pad;
        let needed = format.bytes_needed(w, h, stride);
        let mut state = seed | 1;
        let src: Vec<u8> = (0..needed)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 24) as u8
            })
            .collect();
        let mut dst = vec![0u8; w * h];
        to_grey(format, &src, width, height, stride, &mut dst).unwrap();
        for y in 0..h {
            let row = &src[y * stride..];
            for x in 0..w {
                prop_assert_eq!(dst[y * w + x], reference(format, row, x), "({}, {})", x, y);
            }
        }
    }

    /// `parse_size` takes `WxH` back exactly and refuses anything else with a typed error.
    #[test]
    fn parse_size_round_trips_and_refuses_junk(
        w in any::<u32>(),
        h in any::<u32>(),
        junk in "\\PC{0,12}",
    ) {
        prop_assert_eq!(parse_size(&format!("{w}x{h}")).unwrap(), (w, h));
        prop_assert_eq!(parse_size(&format!("{w}X{h}")).unwrap(), (w, h));
        match parse_size(&junk) {
            Ok((a, b)) => prop_assert!(junk.contains(['x', 'X']), "{} gave {}x{}", junk, a, b),
            Err(CaptureError::Config { field, .. }) => prop_assert_eq!(field, "size"),
            Err(other) => prop_assert!(false, "unexpected error {other}"),
        }
    }
}
