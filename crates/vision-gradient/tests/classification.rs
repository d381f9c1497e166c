//! Behaviour of the directional gradient on drawn scenes, against an independent reference.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod common;

use common::{Stripe, ref_classify, ref_sobel, render};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use vision_gradient::{
    EdgeBuffer, EdgeClass, GradientDetector, GradientParams, GreyImage, Region, Threshold,
};

const W: usize = 160;
const H: usize = 120;

fn detector(min_deg: f64, max_deg: f64, thr: u16) -> GradientDetector {
    GradientDetector::new(GradientParams {
        min_edge_angle_deg: min_deg,
        max_edge_angle_deg: max_deg,
        threshold: Threshold::Fixed { min_magnitude: thr },
    })
    .unwrap()
}

fn stripe_image(s: &Stripe) -> Vec<u8> {
    render(W, H, 40.0, 200.0, |x, y| s.inside(x, y))
}

/// Runs the default-band detector (15°..80°, threshold 120) on a stripe image.
fn run(data: &[u8], det: &GradientDetector) -> (EdgeBuffer, vision_gradient::EdgeStats) {
    let img = GreyImage::new(data, W, H, W).unwrap();
    let mut edges = EdgeBuffer::with_capacity(W * H);
    let stats = det.detect(&img, Region::Full, &mut edges, None).unwrap();
    (edges, stats)
}

#[test]
fn diagonal_stripes_are_kept_with_the_right_class_along_both_edges() {
    let det = detector(15.0, 80.0, 120);
    for &alpha in &[25.0, 45.0, 70.0] {
        for &left in &[true, false] {
            let s = Stripe::new(80.3, 60.7, alpha, left, 3.0);
            let data = stripe_image(&s);
            let (edges, stats) = run(&data, &det);
            let (want, other) = if left {
                (EdgeClass::LeftLane, EdgeClass::RightLane)
            } else {
                (EdgeClass::RightLane, EdgeClass::LeftLane)
            };
            assert_eq!(
                edges.iter_class(other).count(),
                0,
                "alpha {alpha} left {left}: wrong class"
            );
            assert_eq!(stats.left_count + stats.right_count, edges.len());
            // Every kept pixel sits on one of the two stripe edges (|dist| = hw ± 2.2 px, the reach
            // of a 3×3 window across a 45° edge);
            // a col/row swap or an offset would break this.
            for p in edges.pixels() {
                let d = s
                    .dist(f64::from(p.col_px) + 0.5, f64::from(p.row_px) + 0.5)
                    .abs();
                assert!(
                    (d - s.hw).abs() <= 2.2,
                    "alpha {alpha}: pixel {p:?} at distance {d}"
                );
            }
            // Both edges are found on every row where the stripe is well inside the image.
            let mut rows_ok = 0;
            let mut rows = 0;
            for r in 2..H - 2 {
                let y = r as f64 + 0.5;
                let xc = s.x0 + s.dx / s.dy * (y - s.y0);
                if !(12.0..W as f64 - 12.0).contains(&xc) {
                    continue;
                }
                rows += 1;
                let on_row: Vec<f64> = edges
                    .iter_class(want)
                    .filter(|p| usize::from(p.row_px) == r)
                    .map(|p| s.dist(f64::from(p.col_px) + 0.5, y))
                    .collect();
                if on_row.iter().any(|&d| d < 0.0) && on_row.iter().any(|&d| d > 0.0) {
                    rows_ok += 1;
                }
            }
            assert!(rows > 20, "test geometry");
            assert_eq!(
                rows_ok, rows,
                "alpha {alpha} left {left}: rows with both edges"
            );
        }
    }
}

/// Sobel's per-pixel angle on a rendered edge spreads around the true angle (pixels at the
/// rim of the 3×3 response lean toward 45°), so an out-of-band stripe loses most, not all, of
/// its pixels; exactly axis-aligned edges lose all of them.
#[test]
fn horizontal_vertical_and_out_of_band_stripes_are_dropped() {
    let det = detector(15.0, 80.0, 120);
    let open = detector(0.0, 90.0, 120);
    for &(alpha, left) in &[
        (0.0, true),
        (90.0, true),
        (6.0, true),
        (6.0, false),
        (87.0, true),
        (87.0, false),
    ] {
        let s = Stripe::new(80.3, 60.7, alpha, left, 3.0);
        let data = stripe_image(&s);
        let (edges, stats) = run(&data, &det);
        let (all, _) = run(&data, &open);
        if alpha == 0.0 || alpha == 90.0 {
            // gx = 0 or gy = 0 exactly: never kept, even with the band disabled.
            assert_eq!(edges.len(), 0, "alpha {alpha}: {stats:?}");
            assert_eq!(all.len(), 0, "alpha {alpha}: axis-aligned edge kept");
        } else {
            // The band disabled (0°, 90°) keeps the stripe; the 15°..80° band drops >= 90 %.
            assert!(
                all.len() > 200,
                "alpha {alpha}: band 0..90 must keep it, got {}",
                all.len()
            );
            assert!(
                edges.len() * 10 < all.len(),
                "alpha {alpha}: kept {} of {}",
                edges.len(),
                all.len()
            );
        }
    }
}

#[test]
fn band_limits_follow_the_configured_angles() {
    // 30° stripe: kept by 25..90, mostly dropped by 35..90;
    // 60° stripe: kept by 0..65, mostly dropped by 0..55.
    let s30 = stripe_image(&Stripe::new(80.3, 60.7, 30.0, true, 4.0));
    let s60 = stripe_image(&Stripe::new(80.3, 60.7, 60.0, false, 4.0));
    let count = |data: &[u8], lo, hi| run(data, &detector(lo, hi, 200)).0.len();
    let (in30, out30) = (count(&s30, 25.0, 90.0), count(&s30, 35.0, 90.0));
    let (in60, out60) = (count(&s60, 0.0, 65.0), count(&s60, 0.0, 55.0));
    assert!(in30 > 200 && out30 * 5 < in30, "30°: {in30} vs {out30}");
    assert!(in60 > 200 && out60 * 5 < in60, "60°: {in60} vs {out60}");
}

/// Every pixel of random images against the f64 reference Sobel + atan2 band test.
#[test]
fn kernel_matches_float_reference_on_random_images() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for case in 0..6 {
        let (w, h) = (rng.random_range(3..90), rng.random_range(3..70));
        let data: Vec<u8> = (0..w * h).map(|_| rng.random()).collect();
        let lo = rng.random_range(0.0..40.0);
        let hi = rng.random_range(50.0..=90.0);
        let thr: u16 = rng.random_range(0..600);
        let det = GradientDetector::new(GradientParams {
            min_edge_angle_deg: lo,
            max_edge_angle_deg: hi,
            threshold: Threshold::Fixed { min_magnitude: thr },
        })
        .unwrap();
        let img = GreyImage::new(&data, w, h, w).unwrap();
        let mut edges = EdgeBuffer::with_capacity(w * h);
        let mut cls = vec![9u8; w * h];
        det.detect(&img, Region::Full, &mut edges, Some(&mut cls))
            .unwrap();
        let mut checked = 0;
        for r in 0..h {
            for c in 0..w {
                let got = cls[r * w + c];
                if r == 0 || c == 0 || r == h - 1 || c == w - 1 {
                    assert_eq!(got, 0, "case {case}: border pixel ({c},{r})");
                    continue;
                }
                let (gx, gy) = ref_sobel(&data, w, c, r);
                let (want, ambiguous) = ref_classify(gx, gy, lo, hi, f64::from(thr), 0.01);
                if ambiguous {
                    continue;
                }
                checked += 1;
                assert_eq!(
                    got,
                    want.map_or(0, |k| k as u8),
                    "case {case}: ({c},{r}) g=({gx},{gy})"
                );
            }
        }
        assert!(checked > (w - 2) * (h - 2) * 9 / 10);
        // The list holds exactly the class-image pixels, bottom row first, with reference magnitudes.
        let n_cls = cls.iter().filter(|&&v| v != 0).count();
        assert_eq!(edges.len(), n_cls);
        for pair in edges.pixels().windows(2) {
            assert!(
                (pair[0].row_px, std::cmp::Reverse(pair[0].col_px))
                    > (pair[1].row_px, std::cmp::Reverse(pair[1].col_px))
            );
        }
        for p in edges.pixels() {
            let (c, r) = (usize::from(p.col_px), usize::from(p.row_px));
            assert_eq!(cls[r * w + c], p.class as u8);
            let (gx, gy) = ref_sobel(&data, w, c, r);
            assert_eq!(f64::from(p.magnitude), gx.abs() + gy.abs());
        }
    }
}

#[test]
fn stride_padding_is_ignored() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let (w, h, stride) = (53, 41, 64);
    let tight: Vec<u8> = (0..w * h).map(|_| rng.random()).collect();
    let mut padded = vec![255u8; stride * (h - 1) + w];
    for r in 0..h {
        padded[r * stride..r * stride + w].copy_from_slice(&tight[r * w..(r + 1) * w]);
    }
    // Padding bytes alternate 0/255 so reading them would create strong gradients.
    for r in 0..h - 1 {
        for (i, v) in padded[r * stride + w..(r + 1) * stride]
            .iter_mut()
            .enumerate()
        {
            *v = if (i + r) % 2 == 0 { 0 } else { 255 };
        }
    }
    let det = detector(10.0, 80.0, 100);
    let mut a = EdgeBuffer::with_capacity(w * h);
    let mut b = EdgeBuffer::with_capacity(w * h);
    det.detect(
        &GreyImage::new(&tight, w, h, w).unwrap(),
        Region::Full,
        &mut a,
        None,
    )
    .unwrap();
    det.detect(
        &GreyImage::new(&padded, w, h, stride).unwrap(),
        Region::Full,
        &mut b,
        None,
    )
    .unwrap();
    assert!(!a.is_empty());
    assert_eq!(a.pixels(), b.pixels());
}

#[test]
fn truncation_keeps_the_bottom_rows_and_reports_the_rest() {
    let s = Stripe::new(80.3, 60.7, 45.0, true, 3.0);
    let data = stripe_image(&s);
    let det = detector(15.0, 80.0, 120);
    let (full, _) = run(&data, &det);
    let cap = full.len() / 3;
    let img = GreyImage::new(&data, W, H, W).unwrap();
    let mut small = EdgeBuffer::with_capacity(cap);
    let stats = det.detect(&img, Region::Full, &mut small, None).unwrap();
    assert_eq!(small.len(), cap);
    assert!(small.is_truncated());
    assert_eq!(stats.dropped, full.len() - cap);
    assert_eq!(stats.left_count, full.len());
    assert_eq!(small.pixels(), &full.pixels()[..cap]);
    let min_kept_row = small.pixels().iter().map(|p| p.row_px).min().unwrap();
    assert!(
        full.pixels()[cap..]
            .iter()
            .all(|p| p.row_px <= min_kept_row)
    );
    // Reuse: a second call refills instead of appending.
    det.detect(&img, Region::Full, &mut small, None).unwrap();
    assert_eq!(small.len(), cap);
    assert_eq!(small.capacity(), cap);
}

#[test]
fn tiny_images_give_edges_only_inside_their_border_without_error() {
    // The 3×3 Sobel needs a pixel's 8 neighbours: below 3×3 there is no such pixel, and a 3×3
    // image has one, its centre.
    let det = detector(15.0, 80.0, 0);
    for &(w, h) in &[(1, 1), (2, 9), (9, 2), (3, 3)] {
        let data: Vec<u8> = (0..w * h).map(|i| (i * 37 % 256) as u8).collect();
        let img = GreyImage::new(&data, w, h, w).unwrap();
        let mut e = EdgeBuffer::with_capacity(16);
        let mut cls = vec![7u8; w * h];
        let stats = det
            .detect(&img, Region::Full, &mut e, Some(&mut cls))
            .unwrap();
        if w < 3 || h < 3 {
            assert_eq!(stats.stored, 0);
        } else {
            assert!(stats.stored <= 1, "{stats:?}");
        }
        assert!(
            cls.iter()
                .enumerate()
                .all(|(i, &v)| v == 0 || (w == 3 && h == 3 && i == 4))
        );
    }
}
