//! Point selection's pieces: mark centres, stripe middles, residual bins, the decimation.

use super::*;

/// One row of a mark `[left, right)` (columns, px) drawn with area anti-aliasing, grey 90
/// on the floor and 200 on the mark, or a step from 90 up to 200 at `left` when `right` is ∞.
fn row(left: f64, right: f64) -> Vec<u8> {
    (0..40)
        .map(|x| {
            let (lo, hi) = (x as f64 - 0.5, x as f64 + 0.5);
            let cover = (hi.min(right) - lo.max(left)).clamp(0.0, 1.0);
            (90.0 + 110.0 * cover).round() as u8
        })
        .collect()
}

#[test]
fn mark_centre_is_within_the_sawtooth_bound_of_the_true_centre() {
    for width in [1.5, 2.0, 2.7, 4.0, 6.3] {
        for k in 0..20 {
            let centre = 17.0 + 0.05 * k as f64;
            let pixels = row(centre - 0.5 * width, centre + 0.5 * width);
            let (lo, hi) = ((centre - 0.5 * width) as u16, (centre + 0.5 * width) as u16);
            let (x, v) = mark_centre(&pixels, lo, hi, 0.3).unwrap();
            // 1/(8w) px, plus the rounding of the grey levels to integers.
            let bound = 1.0 / (8.0 * width) + 0.01;
            assert!(
                (x - centre).abs() <= bound,
                "width {width}, centre {centre}: {x} (bound {bound})"
            );
            assert!(v > 0.0 && v.is_finite());
        }
    }
    // A dark mark on a bright floor is found the same way.
    let dark: Vec<u8> = row(15.2, 18.9).iter().map(|&p| 255 - p + 35).collect();
    let (x, _) = mark_centre(&dark, 15, 18, 0.0).unwrap();
    assert!((x - 17.05).abs() < 0.04, "{x}");
}

/// An edge pixel of `class` at `col` on row 0, rising (`gx > 0`) or falling.
fn edge(col: u16, rising: bool, class: EdgeClass) -> EdgePixel {
    EdgePixel {
        col_px: col,
        row_px: 0,
        magnitude: 300,
        class,
        gx: if rising { 150 } else { -150 },
    }
}

#[test]
fn an_edge_pixel_of_a_bright_stripe_on_an_even_floor_measures_the_stripe_middle() {
    use EdgeClass::{LeftLane as L, RightLane as R};
    // Each pixel's measured column, for stripes more than `widths.0` and at most
    // `widths.1` columns wide.
    let measured = |px: &[EdgePixel], grey: &[u8], widths: (u16, u16)| -> Vec<f32> {
        (0..px.len())
            .map(|j| match stripe_middle(px, j, grey, widths) {
                Some((col, half)) => f32::from(col) + if half { 0.5 } else { 0.0 },
                None => f32::from(px[j].col_px),
            })
            .collect()
    };
    // A mark [15, 25) on a floor of 90 on both sides: edges at 14/15 and 24/25.
    let mark = row(15.0, 25.0);
    let px = [
        edge(14, true, L),
        edge(15, true, L),
        edge(24, false, L),
        edge(25, false, L),
    ];
    assert_eq!(measured(&px, &mark, (0, 16)), [19.0, 19.5, 19.5, 20.0]);
    // Wider than the widest stripe: each pixel its own column; the nearest partner counts.
    assert_eq!(measured(&px, &mark, (0, 9)), [14.0, 19.5, 19.5, 25.0]);
    assert_eq!(measured(&px, &mark, (0, 8)), [14.0, 15.0, 24.0, 25.0]);
    // Not wider than the narrowest (14–24 and 15–25 are 10 columns apart, 15–24 nine).
    assert_eq!(measured(&px, &mark, (9, 16)), [19.0, 15.0, 24.0, 20.0]);
    assert_eq!(measured(&px, &mark, (10, 16)), [14.0, 15.0, 24.0, 25.0]);
    // The partner must be of the pixel's class.
    let mixed = [edge(15, true, L), edge(24, false, R)];
    assert_eq!(measured(&mixed, &mark, (0, 16)), [15.0, 24.0]);
    // A dark stripe (falling, then rising) is not a mark.
    let dark = [edge(15, false, L), edge(24, true, L)];
    assert_eq!(measured(&dark, &mark, (0, 16)), [15.0, 24.0]);
    // A kerb's face: bright between the road (90) and a pavement of another grey (150 from
    // column 26 on): a step, whose foot the lane keeps.
    let mut kerb = mark.clone();
    for g in &mut kerb[26..] {
        *g = 150;
    }
    assert_eq!(measured(&px, &kerb, (0, 16)), [14.0, 15.0, 24.0, 25.0]);
    // A pavement of almost the floor's grey is still a floor alike on both sides.
    for g in &mut kerb[26..] {
        *g = 110;
    }
    assert_eq!(measured(&px, &kerb, (0, 16)), [19.0, 19.5, 19.5, 20.0]);
    // A stripe whose outside lies beyond the row is not measured; nor a pixel not in it.
    assert_eq!(
        measured(&px, &mark[..26], (0, 16)),
        [14.0, 15.0, 24.0, 25.0]
    );
    assert_eq!(stripe_middle(&px, 4, &mark, (0, 16)), None);
}

#[test]
fn a_stripe_middle_between_two_columns_is_binned_by_its_rounded_residual() {
    use EdgeClass::LeftLane as L;
    // The mark [15, 25): edge pixels 15 and 24, middle 19.5; predicted at 19.9, the
    // residual −0.4 rounds to 0 (bin w), where the left column's −0.9 would round to −1.
    let mark = row(15.0, 25.0);
    let image = GreyImage::new(&mark, mark.len(), 1, mark.len()).expect("a one-row image");
    let edges = [edge(15, true, L), edge(24, false, L)];
    let w = 10;
    let pass = |widths_px| WindowPass {
        predicted: Parabola::from_coeffs([0.0, 0.0, 19.9]),
        joint: false,
        lane_class: L,
        gate: false,
        tan_tolerance: 0.0,
        band_rows: [1, 1],
        w,
        image: &image,
        stripe_widths_px: widths_px,
    };
    let mut hist = Box::new([[0u32; 2 * MAX_WINDOW_HALF_WIDTH + 1]; BANDS]);
    let mut scratch = Vec::with_capacity(4);
    pass((6, 16)).gather::<true>(&edges, &mut hist, &mut scratch);
    let got: Vec<_> = scratch.iter().map(|c| (c.point(), c.bin, c.band)).collect();
    assert_eq!(got, [((19.5, 0.0), 10, 0), ((19.5, 0.0), 10, 0)]);
    assert_eq!(hist[0][10], 2);
    // Without middles (or narrower than the narrowest): each its own column and bin.
    for (widths_px, middles) in [((6, 16), false), ((9, 16), true)] {
        hist[0].fill(0);
        scratch.clear();
        if middles {
            pass(widths_px).gather::<true>(&edges, &mut hist, &mut scratch);
        } else {
            pass(widths_px).gather::<false>(&edges, &mut hist, &mut scratch);
        }
        let got: Vec<_> = scratch.iter().map(|c| (c.point(), c.bin)).collect();
        assert_eq!(got, [((15.0, 0.0), 5), ((24.0, 0.0), 14)]);
    }
}

#[test]
fn the_residual_bin_is_the_rounded_residual_shifted_into_the_window() {
    // The per-pixel formula the per-row offset replaces: ⌊x − x̂ + w + ½⌋, negative → 0,
    // capped at 2w.
    let direct = |x: u16, pred: f64, w: i64| {
        let v = f64::from(x) - pred;
        ((v + w as f64 + 0.5).max(0.0) as usize).min(2 * w as usize)
    };
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..20_000 {
        let w = 1 + (uniform() * 40.0) as i64;
        let x = (uniform() * 640.0) as u16;
        // Predictions near the pixel (in the window and just outside it), on half-pixel
        // ties, and far away.
        let pred = match (uniform() * 4.0) as u32 {
            0 => f64::from(x) + (uniform() - 0.5) * 4.0 * w as f64,
            1 => f64::from(x) + ((uniform() * 8.0) as i64 - 4) as f64 + 0.5,
            2 => (uniform() - 0.5) * 1e7,
            _ => f64::from(x) - w as f64 - 0.5 + (uniform() - 0.5) * 1e-9,
        };
        let bin = residual_bin(x, bin_offset(pred, w), 2 * w as i32);
        assert_eq!(bin, direct(x, pred, w), "x {x}, prediction {pred}, w {w}");
    }
    for pred in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300] {
        for x in [0u16, 17, u16::MAX] {
            let bin = residual_bin(x, bin_offset(pred, 10), 20);
            assert_eq!(bin, direct(x, pred, 10), "x {x}, prediction {pred}");
        }
    }
}

#[test]
fn the_decimation_keeps_the_items_of_the_division_rule() {
    for total in 0..400usize {
        for max in [1usize, 3, 7, 150, 399] {
            let mut decimation = Decimation::new(max, total);
            let kept: Vec<usize> = (0..total).filter(|_| decimation.keep()).collect();
            let expected: Vec<usize> = (0..total)
                .filter(|&j| total <= max || (j + 1) * max / total > j * max / total)
                .collect();
            assert_eq!(kept, expected, "total {total}, max {max}");
            assert_eq!(kept.len(), total.min(max));
        }
    }
}

#[test]
fn a_single_step_edge_is_located_exactly() {
    for k in 0..20 {
        let edge = 20.0 + 0.05 * k as f64;
        let up = row(edge, f64::INFINITY);
        let (x, _) = mark_centre(&up, edge as u16, edge as u16 + 1, 0.5).unwrap();
        assert!((x - edge).abs() < 0.01, "rising {edge}: {x}");
        let down: Vec<u8> = up.iter().rev().copied().collect();
        let mirrored = 39.0 - edge;
        let (x, _) = mark_centre(&down, mirrored as u16, mirrored as u16 + 1, 0.5).unwrap();
        assert!((x - mirrored).abs() < 0.01, "falling {mirrored}: {x}");
    }
    // No contrast, no point.
    assert!(mark_centre(&[100; 40], 10, 12, 0.0).is_none());
}
