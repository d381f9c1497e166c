use super::*;

const W: usize = 40;
const H: usize = 30;

/// A road-like frame: a dark band (columns 0..8, grey 20), a bright one (8..16, 220), road grey
/// 90 on the other 24 columns: the median of any rows is 90; a row's texture on top (0..=4).
fn frame() -> Vec<u8> {
    (0..W * H)
        .map(|i| {
            let (x, y) = (i % W, i / W);
            let texture = ((x * 7 + y * 11) % 5) as u8;
            match x {
                0..8 => 20 + texture,
                8..16 => 220 + texture,
                _ => 90,
            }
        })
        .collect()
}

fn image(px: &[u8]) -> GreyImage<'_> {
    GreyImage::new(px, W, H, W).expect("test image")
}

#[test]
fn the_median_grey_is_the_level_half_the_rows_pixels_reach() {
    let mut hist = [0u32; 256];
    let px = frame();
    assert_eq!(median_grey(&image(&px), (0, H), &mut hist), Some(90));
    // Rows of one grey each: rows 0..10 at 20, 10..30 at 200. Rows 4..14 asked: 4, 6, 8 at 20
    // and 10, 12 at 200 counted; rows 6..16: 6, 8 and 10, 12, 14.
    let banded: Vec<u8> = (0..W * H)
        .map(|i| if i / W < 10 { 20 } else { 200 })
        .collect();
    assert_eq!(median_grey(&image(&banded), (4, 14), &mut hist), Some(20));
    assert_eq!(median_grey(&image(&banded), (6, 16), &mut hist), Some(200));
    assert_eq!(
        hist[200],
        3 * W as u32 / 2,
        "every other pixel of rows 10, 12, 14"
    );
    assert_eq!(median_grey(&image(&banded), (30, 40), &mut hist), None);
}

#[test]
fn a_frame_darkened_then_brightened_by_the_inverse_gain_comes_back_within_a_level() {
    let px = frame();
    let dark: Vec<u8> = px.iter().map(|&v| v / 2).collect();
    let mut out = vec![7u8; W * H];
    brighten(&image(&dark), (3, H), 2.0, &mut out).expect("buffer holds the frame");
    for (i, (&o, &v)) in out.iter().zip(&px).enumerate() {
        if i < 3 * W {
            assert_eq!(o, 7, "rows above `top` are left as they are");
        } else {
            assert!(o.abs_diff(v) <= 1, "pixel {i}: {o} against {v}");
        }
    }
    // In place, the same table; levels clamp at 255.
    let mut row = [0u8, 100, 128, 200, 255];
    brighten_in_place(&mut row, 2.0);
    assert_eq!(row, [0, 200, 255, 255, 255]);
    let mut same = [0u8, 1, 254, 255];
    brighten_in_place(&mut same, 1.0);
    assert_eq!(same, [0, 1, 254, 255]);
}

#[test]
fn a_buffer_too_small_is_a_typed_error_and_nothing_is_written() {
    let px = frame();
    let mut out = vec![9u8; W * H - 1];
    let err = brighten(&image(&px), (0, H), 2.0, &mut out).unwrap_err();
    assert_eq!(
        err,
        GradientError::BufferTooSmall {
            buffer: "out",
            len: W * H - 1,
            required: W * H
        }
    );
    assert!(out.iter().all(|&v| v == 9));
}
