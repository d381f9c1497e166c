use super::*;

const W: usize = 40;
const H: usize = 30;

/// A road-like frame: every level 0..=199 once per row in a shuffled order, then grey 90 to the
/// row's end (the median of a row: 90).
fn frame() -> Vec<u8> {
    (0..W * H)
        .map(|i| {
            let x = i % W;
            if x < 20 {
                ((x * 37 + i / W * 11) % 200) as u8
            } else {
                90
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
    // Rows of one grey each: rows 0..10 at 20, 10..30 at 200 (only rows 5..15 asked: 5 and 5).
    let banded: Vec<u8> = (0..W * H)
        .map(|i| if i / W < 10 { 20 } else { 200 })
        .collect();
    assert_eq!(median_grey(&image(&banded), (5, 15), &mut hist), Some(20));
    assert_eq!(median_grey(&image(&banded), (5, 16), &mut hist), Some(200));
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
