//! Pixel formats a BT848/878 (or vivid) capture can deliver, and their conversion to 8-bit grey.
//!
//! This module has no V4L2 dependency: it builds with the `v4l` feature off.
//!
//! # Luma
//!
//! * Y'CbCr formats (`YUYV`, `UYVY`, `YU12`): the grey value is the stored Y' sample, unchanged
//!   (no studio-range expansion: the lane tracker works on gradients, which an affine range
//!   change only scales).
//! * R'G'B' formats (`BGR3`, `RGBP`, `BGR4`): ITU-R BT.601 luma on the gamma-encoded components,
//!
//!   `Y' = 0.299 R' + 0.587 G' + 0.114 B'`,
//!
//!   computed exactly in 16-bit fixed point, `Y' = (19595 R' + 38470 G' + 7471 B' + 2^15) >> 16`
//!   (the weights sum to 2^16, so white stays 255). RGB565's 5- and 6-bit fields are first
//!   widened to 8 bits by bit replication (`r8 = r5 << 3 | r5 >> 2`, `g8 = g6 << 2 | g6 >> 4`).
//!
//! # Layouts (bytes in memory order)
//!
//! | format | fourcc | bytes per pixel (luma plane) | layout |
//! |--------|--------|------------------------------|--------|
//! | GREY   | `GREY` | 1 | `Y` |
//! | YUYV   | `YUYV` | 2 | `Y0 U Y1 V` per pixel pair |
//! | UYVY   | `UYVY` | 2 | `U Y0 V Y1` per pixel pair |
//! | YU12   | `YU12` | 1 | Y plane (`stride` bytes per row), then Cb and Cr planes at quarter size |
//! | BGR24  | `BGR3` | 3 | `B G R` |
//! | RGB565 | `RGBP` | 2 | little-endian 16-bit word `rrrrrggg gggbbbbb` |
//! | BGR32  | `BGR4` | 4 | `B G R X` |
//!
//! Rows are `stride` bytes apart (V4L2's `bytesperline`; for `YU12` the Y plane's).

use serde::{Deserialize, Serialize};

use crate::CaptureError;

/// A pixel format the crate converts to grey. Serialised as its V4L2 fourcc (`"GREY"`, `"YUYV"`…).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum PixelFormat {
    /// 8-bit grey, `V4L2_PIX_FMT_GREY`.
    #[serde(rename = "GREY")]
    Grey,
    /// Packed 4:2:2 `Y0 U Y1 V`, `V4L2_PIX_FMT_YUYV`.
    #[serde(rename = "YUYV")]
    Yuyv,
    /// Packed 4:2:2 `U Y0 V Y1`, `V4L2_PIX_FMT_UYVY`.
    #[serde(rename = "UYVY")]
    Uyvy,
    /// Planar 4:2:0 Y, Cb, Cr, `V4L2_PIX_FMT_YUV420`.
    #[serde(rename = "YU12")]
    Yu12,
    /// Packed `B G R`, `V4L2_PIX_FMT_BGR24`.
    #[serde(rename = "BGR3")]
    Bgr24,
    /// Packed little-endian 5-6-5 RGB, `V4L2_PIX_FMT_RGB565`.
    #[serde(rename = "RGBP")]
    Rgb565,
    /// Packed `B G R X`, `V4L2_PIX_FMT_BGR32`.
    #[serde(rename = "BGR4")]
    Bgr32,
}

impl PixelFormat {
    /// Every supported format, in the default order of preference (cheapest conversion first).
    pub const ALL: [PixelFormat; 7] = [
        PixelFormat::Grey,
        PixelFormat::Yuyv,
        PixelFormat::Uyvy,
        PixelFormat::Yu12,
        PixelFormat::Bgr24,
        PixelFormat::Rgb565,
        PixelFormat::Bgr32,
    ];

    /// The V4L2 fourcc code's four characters.
    pub const fn fourcc(self) -> [u8; 4] {
        match self {
            PixelFormat::Grey => *b"GREY",
            PixelFormat::Yuyv => *b"YUYV",
            PixelFormat::Uyvy => *b"UYVY",
            PixelFormat::Yu12 => *b"YU12",
            PixelFormat::Bgr24 => *b"BGR3",
            PixelFormat::Rgb565 => *b"RGBP",
            PixelFormat::Bgr32 => *b"BGR4",
        }
    }

    /// The fourcc as V4L2's little-endian `u32` (`v4l2_pix_format.pixelformat`).
    pub const fn fourcc_u32(self) -> u32 {
        u32::from_le_bytes(self.fourcc())
    }

    /// The format with this fourcc, if the crate converts it.
    pub fn from_fourcc(fourcc: [u8; 4]) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.fourcc() == fourcc)
    }

    /// Bytes per pixel in the (luma) plane the conversion reads.
    pub const fn bytes_per_pixel(self) -> usize {
        match self {
            PixelFormat::Grey | PixelFormat::Yu12 => 1,
            PixelFormat::Yuyv | PixelFormat::Uyvy | PixelFormat::Rgb565 => 2,
            PixelFormat::Bgr24 => 3,
            PixelFormat::Bgr32 => 4,
        }
    }

    /// Bytes of source the conversion of a `width`×`height` frame with rows `stride_bytes` apart
    /// reads: `stride·(height−1) + width·bytes_per_pixel` (for `YU12`, the Y plane only),
    /// saturating at `usize::MAX` (no buffer is that long, so an absurd stride is refused as
    /// [`CaptureError::SourceTooShort`] instead of overflowing).
    pub const fn bytes_needed(self, width: usize, height: usize, stride_bytes: usize) -> usize {
        if width == 0 || height == 0 {
            return 0;
        }
        stride_bytes
            .saturating_mul(height - 1)
            .saturating_add(width.saturating_mul(self.bytes_per_pixel()))
    }
}

impl std::fmt::Display for PixelFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&fourcc_string(self.fourcc()))
    }
}

/// A fourcc as text, non-printable bytes escaped (`"GREY"`, `"\x00BAD"`).
pub fn fourcc_string(fourcc: [u8; 4]) -> String {
    fourcc
        .iter()
        .flat_map(|b| std::ascii::escape_default(*b))
        .map(char::from)
        .collect()
}

/// BT.601 luma of one gamma-encoded R'G'B' pixel, rounded to nearest: the workspace's one
/// conversion, [`grey_frame::luma_bt601`] (see the module docs).
pub use grey_frame::luma_bt601;

/// Convert one `width`×`height` frame in `format`, rows `stride_bytes` apart in `src`, to
/// tightly packed 8-bit grey in `dst_grey` (`width·height` bytes, row-major).
///
/// Writes only into the caller's buffer; no allocation.
///
/// # Errors
/// [`CaptureError::OutputSize`] if `dst_grey` is not `width·height` bytes,
/// [`CaptureError::StrideTooSmall`] if a row of `stride_bytes` cannot hold `width` pixels,
/// [`CaptureError::SourceTooShort`] if `src` is shorter than [`PixelFormat::bytes_needed`].
pub fn to_grey(
    format: PixelFormat,
    src: &[u8],
    width: u32,
    height: u32,
    stride_bytes: usize,
    dst_grey: &mut [u8],
) -> Result<(), CaptureError> {
    let (w, h) = (width as usize, height as usize);
    let expected = w.saturating_mul(h);
    if dst_grey.len() != expected {
        return Err(CaptureError::OutputSize {
            expected,
            got: dst_grey.len(),
            width,
            height,
        });
    }
    if expected == 0 {
        return Ok(());
    }
    let row_bytes = w.saturating_mul(format.bytes_per_pixel());
    if stride_bytes < row_bytes {
        return Err(CaptureError::StrideTooSmall {
            format,
            width,
            stride_bytes,
            row_bytes,
        });
    }
    let needed = format.bytes_needed(w, h, stride_bytes);
    if src.len() < needed {
        return Err(CaptureError::SourceTooShort {
            format,
            width,
            height,
            stride_bytes,
            needed,
            got: src.len(),
        });
    }
    for (row_idx, dst_row) in dst_grey.chunks_exact_mut(w).enumerate() {
        let start = row_idx * stride_bytes;
        let src_row = &src[start..start + row_bytes];
        convert_row(format, src_row, dst_row);
    }
    Ok(())
}

/// Convert one row; `src_row` holds exactly `dst_row.len()` pixels.
fn convert_row(format: PixelFormat, src_row: &[u8], dst_row: &mut [u8]) {
    match format {
        PixelFormat::Grey | PixelFormat::Yu12 => dst_row.copy_from_slice(src_row),
        PixelFormat::Yuyv => {
            for (d, s) in dst_row.iter_mut().zip(src_row.chunks_exact(2)) {
                *d = s[0];
            }
        }
        PixelFormat::Uyvy => {
            for (d, s) in dst_row.iter_mut().zip(src_row.chunks_exact(2)) {
                *d = s[1];
            }
        }
        PixelFormat::Bgr24 => {
            for (d, s) in dst_row.iter_mut().zip(src_row.chunks_exact(3)) {
                *d = luma_bt601(s[2], s[1], s[0]);
            }
        }
        PixelFormat::Bgr32 => {
            for (d, s) in dst_row.iter_mut().zip(src_row.chunks_exact(4)) {
                *d = luma_bt601(s[2], s[1], s[0]);
            }
        }
        PixelFormat::Rgb565 => {
            for (d, s) in dst_row.iter_mut().zip(src_row.chunks_exact(2)) {
                let word = u16::from_le_bytes([s[0], s[1]]);
                let r5 = ((word >> 11) & 0x1f) as u8;
                let g6 = ((word >> 5) & 0x3f) as u8;
                let b5 = (word & 0x1f) as u8;
                *d = luma_bt601(r5 << 3 | r5 >> 2, g6 << 2 | g6 >> 4, b5 << 3 | b5 >> 2);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Hand-computed references (0.299 R + 0.587 G + 0.114 B, rounded to nearest):
    //   red   (255,0,0)     → 76.245  → 76
    //   green (0,255,0)     → 149.685 → 150
    //   blue  (0,0,255)     → 29.07   → 29
    //   white (255,255,255) → 255
    //   (100,150,200)       → 29.9 + 88.05 + 22.8 = 140.75 → 141
    //   (10,20,30)          → 2.99 + 11.74 + 3.42 = 18.15  → 18
    const RED: u8 = 76;
    const GREEN: u8 = 150;
    const BLUE: u8 = 29;

    #[test]
    fn luma_matches_hand_computed_bt601_values() {
        assert_eq!(luma_bt601(255, 0, 0), RED);
        assert_eq!(luma_bt601(0, 255, 0), GREEN);
        assert_eq!(luma_bt601(0, 0, 255), BLUE);
        assert_eq!(luma_bt601(255, 255, 255), 255);
        assert_eq!(luma_bt601(0, 0, 0), 0);
        assert_eq!(luma_bt601(100, 150, 200), 141);
        assert_eq!(luma_bt601(10, 20, 30), 18);
    }

    #[test]
    fn luma_fixed_point_equals_rounded_float_formula_on_a_grid() {
        // Independent reference form: the floating-point BT.601 weights.
        for r in (0..=255u8).step_by(15) {
            for g in (0..=255u8).step_by(17) {
                for b in (0..=255u8).step_by(5) {
                    let exact = 0.299 * f64::from(r) + 0.587 * f64::from(g) + 0.114 * f64::from(b);
                    let got = f64::from(luma_bt601(r, g, b));
                    assert!(
                        (got - exact).abs() <= 0.5 + 1e-3,
                        "({r},{g},{b}): {got} vs {exact}"
                    );
                }
            }
        }
    }

    #[test]
    fn grey_copies_rows_and_skips_stride_padding() {
        // 3×2, stride 5: the two padding bytes (0xEE) per row must not appear.
        let src = [1, 2, 3, 0xEE, 0xEE, 4, 5, 6];
        let mut dst = [0u8; 6];
        to_grey(PixelFormat::Grey, &src, 3, 2, 5, &mut dst).unwrap();
        assert_eq!(dst, [1, 2, 3, 4, 5, 6]);
    }

    #[test]
    fn yuyv_takes_even_bytes() {
        // 4×1: Y0 U Y1 V Y2 U Y3 V
        let src = [10, 128, 20, 129, 30, 130, 40, 131];
        let mut dst = [0u8; 4];
        to_grey(PixelFormat::Yuyv, &src, 4, 1, 8, &mut dst).unwrap();
        assert_eq!(dst, [10, 20, 30, 40]);
    }

    #[test]
    fn uyvy_takes_odd_bytes() {
        // 4×2 with stride 10 (2 padding bytes 0xEE); each row U Y0 V Y1 U Y2 V Y3.
        let src = [
            128, 10, 129, 20, 130, 30, 131, 40, 0xEE, 0xEE, 0, 50, 0, 60, 0, 70, 0, 80,
        ];
        let mut dst = [0u8; 8];
        to_grey(PixelFormat::Uyvy, &src, 4, 2, 10, &mut dst).unwrap();
        assert_eq!(dst, [10, 20, 30, 40, 50, 60, 70, 80]);
    }

    #[test]
    fn yu12_reads_only_the_y_plane() {
        // 2×2: Y plane [1,2,3,4], then Cb (1 byte) and Cr (1 byte) that must be ignored.
        let src = [1, 2, 3, 4, 200, 201];
        let mut dst = [0u8; 4];
        to_grey(PixelFormat::Yu12, &src, 2, 2, 2, &mut dst).unwrap();
        assert_eq!(dst, [1, 2, 3, 4]);
    }

    #[test]
    fn bgr24_applies_bt601_to_b_g_r_byte_order() {
        // Pixels red, green, blue, (100,150,200) stored B G R.
        let src = [0, 0, 255, 0, 255, 0, 255, 0, 0, 200, 150, 100];
        let mut dst = [0u8; 4];
        to_grey(PixelFormat::Bgr24, &src, 4, 1, 12, &mut dst).unwrap();
        assert_eq!(dst, [RED, GREEN, BLUE, 141]);
    }

    #[test]
    fn bgr32_applies_bt601_and_ignores_the_fourth_byte() {
        let src = [
            0, 0, 255, 0x55, 0, 255, 0, 0xAA, 255, 0, 0, 0xFF, 30, 20, 10, 0,
        ];
        let mut dst = [0u8; 4];
        to_grey(PixelFormat::Bgr32, &src, 4, 1, 16, &mut dst).unwrap();
        assert_eq!(dst, [RED, GREEN, BLUE, 18]);
    }

    #[test]
    fn rgb565_widens_fields_then_applies_bt601() {
        // Little-endian words: red 0xF800 → [0x00,0xF8]; green 0x07E0 → [0xE0,0x07];
        // blue 0x001F → [0x1F,0x00]; white 0xFFFF.
        // Mid grey-ish: r5=16 → r8=132, g6=32 → g8=130, b5=16 → b8=132:
        //   word = 16<<11 | 32<<5 | 16 = 0x8410 → [0x10, 0x84];
        //   luma = 0.299·132 + 0.587·130 + 0.114·132 = 39.468 + 76.31 + 15.048 = 130.826 → 131.
        let src = [0x00, 0xF8, 0xE0, 0x07, 0x1F, 0x00, 0xFF, 0xFF, 0x10, 0x84];
        let mut dst = [0u8; 5];
        to_grey(PixelFormat::Rgb565, &src, 5, 1, 10, &mut dst).unwrap();
        assert_eq!(dst, [RED, GREEN, BLUE, 255, 131]);
    }

    #[test]
    fn short_source_is_a_typed_error_naming_the_sizes() {
        let src = [0u8; 7];
        let mut dst = [0u8; 4];
        let err = to_grey(PixelFormat::Yuyv, &src, 2, 2, 4, &mut dst).unwrap_err();
        match err {
            CaptureError::SourceTooShort { needed, got, .. } => {
                assert_eq!((needed, got), (8, 7));
            }
            other => panic!("wrong error {other:?}"),
        }
    }

    #[test]
    fn wrong_output_size_and_small_stride_are_rejected() {
        let src = [0u8; 64];
        let mut small = [0u8; 3];
        assert!(matches!(
            to_grey(PixelFormat::Grey, &src, 2, 2, 2, &mut small),
            Err(CaptureError::OutputSize {
                expected: 4,
                got: 3,
                ..
            })
        ));
        let mut dst = [0u8; 4];
        assert!(matches!(
            to_grey(PixelFormat::Bgr24, &src, 2, 2, 5, &mut dst),
            Err(CaptureError::StrideTooSmall {
                row_bytes: 6,
                stride_bytes: 5,
                ..
            })
        ));
    }

    #[test]
    fn fourcc_round_trips_for_every_format() {
        for f in PixelFormat::ALL {
            assert_eq!(PixelFormat::from_fourcc(f.fourcc()), Some(f));
            assert_eq!(f.fourcc_u32().to_le_bytes(), f.fourcc());
        }
        assert_eq!(PixelFormat::from_fourcc(*b"MJPG"), None);
        // V4L2's v4l2_fourcc('G','R','E','Y') = 'G' | 'R'<<8 | 'E'<<16 | 'Y'<<24.
        assert_eq!(PixelFormat::Grey.fourcc_u32(), 0x5945_5247);
    }

    #[test]
    fn fourcc_string_escapes_unprintable_bytes() {
        assert_eq!(fourcc_string(*b"GREY"), "GREY");
        assert_eq!(fourcc_string([0, b'A', b'B', b'C']), "\\x00ABC");
    }
}
