//! Regions of interest and the adaptive threshold.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod common;

use common::{Stripe, ref_sobel};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use vision_gradient::{
    ColSpan, EdgeBuffer, EdgePixel, EdgeStats, GradientDetector, GradientParams, GreyImage, Region,
    Threshold,
};

/// Membership test `(col, row) -> inside`.
type Inside<'a> = Box<dyn Fn(usize, usize) -> bool + 'a>;

fn random_image(rng: &mut ChaCha8Rng, w: usize, h: usize) -> Vec<u8> {
    (0..w * h).map(|_| rng.random()).collect()
}

fn fixed(thr: u16) -> GradientDetector {
    GradientDetector::new(GradientParams {
        threshold: Threshold::Fixed { min_magnitude: thr },
        ..GradientParams::default()
    })
    .unwrap()
}

fn adaptive(lo: f64, hi: f64, keep_fraction: f64, min_magnitude: u16) -> GradientDetector {
    GradientDetector::new(GradientParams {
        min_edge_angle_deg: lo,
        max_edge_angle_deg: hi,
        threshold: Threshold::Adaptive {
            keep_fraction,
            min_magnitude,
        },
    })
    .unwrap()
}

fn detect(
    det: &GradientDetector,
    data: &[u8],
    w: usize,
    h: usize,
    region: Region<'_>,
) -> (Vec<EdgePixel>, EdgeStats, Vec<u8>) {
    let img = GreyImage::new(data, w, h, w).unwrap();
    let mut edges = EdgeBuffer::with_capacity(w * h);
    let mut cls = vec![0xAAu8; w * h];
    let stats = det
        .detect(&img, region, &mut edges, Some(&mut cls))
        .unwrap();
    (edges.pixels().to_vec(), stats, cls)
}

/// Each region kind gives exactly the full-frame result filtered by the region, and the class
/// image is zero outside it.
#[test]
fn regions_select_exactly_their_pixels() {
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let (w, h) = (97, 61);
    let data = random_image(&mut rng, w, h);
    let det = fixed(300);
    let (full, _, full_cls) = detect(&det, &data, w, h, Region::Full);
    assert!(full.len() > 100);

    let mask: Vec<u8> = (0..w * h)
        .map(|_| u8::from(rng.random_bool(0.4)) * 255)
        .collect();
    let spans: Vec<ColSpan> = (0..h)
        .map(|_| {
            let a: i64 = rng.random_range(-10..(w as i64));
            ColSpan::clamped(a, a + rng.random_range(0..40), w)
        })
        .collect();
    let in_rows = |r: usize| (17..45).contains(&r);
    let cases: [(Region<'_>, Inside<'_>); 3] = [
        (
            Region::Rows {
                row_start_px: 17,
                row_end_px: 45,
            },
            Box::new(move |_c, r| in_rows(r)),
        ),
        (Region::Mask(&mask), Box::new(|c, r| mask[r * w + c] != 0)),
        (
            Region::Spans(&spans),
            Box::new(|c, r| {
                (usize::from(spans[r].col_start_px)..usize::from(spans[r].col_end_px)).contains(&c)
            }),
        ),
    ];
    for (i, (region, inside)) in cases.into_iter().enumerate() {
        let (got, stats, cls) = detect(&det, &data, w, h, region);
        let want: Vec<EdgePixel> = full
            .iter()
            .copied()
            .filter(|p| inside(usize::from(p.col_px), usize::from(p.row_px)))
            .collect();
        assert!(
            !want.is_empty() && want.len() < full.len(),
            "case {i}: test geometry"
        );
        assert_eq!(got, want, "case {i}");
        let left = want
            .iter()
            .filter(|p| p.class == vision_gradient::EdgeClass::LeftLane)
            .count();
        assert!(left > 0 && left < want.len(), "case {i}: both classes");
        assert_eq!(
            (stats.left_count, stats.right_count),
            (left, want.len() - left),
            "case {i}: the counts per class"
        );
        for r in 0..h {
            for c in 0..w {
                let expect = if inside(c, r) { full_cls[r * w + c] } else { 0 };
                assert_eq!(cls[r * w + c], expect, "case {i}: class image at ({c},{r})");
            }
        }
    }
}

/// Row segments of every length from 1 to 200 px: each gives exactly the full frame's pixels
/// inside it, and the full frame's list holds exactly its class image's pixels. The kernel
/// works in blocks of 16 px, the last one of a segment overlapping the one before it, and
/// segments shorter than a block pixel by pixel: every remainder, every count of blocks.
#[test]
fn segments_of_every_length_emit_exactly_their_pixels() {
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    let (w, h) = (260, 203);
    let data = random_image(&mut rng, w, h);
    let det = fixed(300);
    let (full, _, full_cls) = detect(&det, &data, w, h, Region::Full);
    let from_class_image: Vec<(u16, u16)> = (0..h)
        .rev()
        .flat_map(|r| (0..w).map(move |c| (r, c)))
        .filter(|&(r, c)| full_cls[r * w + c] != 0)
        .map(|(r, c)| (r as u16, c as u16))
        .collect();
    let listed: Vec<(u16, u16)> = full.iter().map(|p| (p.row_px, p.col_px)).collect();
    assert_eq!(listed, from_class_image);
    // Row r (1..=200) holds a segment r px long, its start spread over the row.
    let spans: Vec<ColSpan> = (0..h)
        .map(|r| {
            if r == 0 || r > 200 {
                return ColSpan::EMPTY;
            }
            let start = 1 + (r * 37) % (w - 2 - r);
            ColSpan::clamped(start as i64, (start + r) as i64, w)
        })
        .collect();
    let (got, _, _) = detect(&det, &data, w, h, Region::Spans(&spans));
    let want: Vec<EdgePixel> = full
        .iter()
        .copied()
        .filter(|p| {
            let span = spans[usize::from(p.row_px)];
            (span.col_start_px..span.col_end_px).contains(&p.col_px)
        })
        .collect();
    assert!(want.len() > 1000, "test geometry: {} pixels", want.len());
    assert_eq!(got, want);
}

/// The adaptive threshold is the (1 - f) quantile of the in-band magnitudes, checked against a
/// sort of the f64 reference magnitudes (band disabled, so the population is every interior
/// pixel with gx != 0 and gy != 0).
#[test]
fn adaptive_threshold_is_the_upper_quantile_of_reference_magnitudes() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for &(f, floor) in &[(0.05, 0), (0.2, 0), (1.0, 0), (0.01, 1500)] {
        let (w, h) = (rng.random_range(10..80), rng.random_range(10..60));
        let data = random_image(&mut rng, w, h);
        let (edges, stats, _) = detect(&adaptive(0.0, 90.0, f, floor), &data, w, h, Region::Full);
        let mut mags: Vec<f64> = Vec::new();
        for r in 1..h - 1 {
            for c in 1..w - 1 {
                let (gx, gy) = ref_sobel(&data, w, c, r);
                if gx != 0.0 && gy != 0.0 {
                    mags.push(gx.abs() + gy.abs());
                }
            }
        }
        mags.sort_by(|a, b| b.partial_cmp(a).unwrap());
        let k = ((f * mags.len() as f64).ceil() as usize).max(1);
        let t = mags[k - 1].max(f64::from(floor));
        assert_eq!(stats.in_band_count, Some(mags.len()), "f {f}");
        assert_eq!(f64::from(stats.threshold_magnitude), t, "f {f}");
        let kept = mags.iter().filter(|&&m| m >= t).count();
        assert_eq!(edges.len(), kept, "f {f}");
        if floor == 0 {
            assert!(kept >= k);
        }
    }
}

/// Road-like scene (textured asphalt, two marks) rendered at contrast `c` about grey 128.
fn scene(c: f64, w: usize, h: usize) -> Vec<u8> {
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    let texture: Vec<f64> = (0..w * h).map(|_| rng.random_range(-12.0..12.0)).collect();
    let left = Stripe::new(w as f64 * 0.3, h as f64 * 0.75, 40.0, true, 2.5);
    let right = Stripe::new(w as f64 * 0.7, h as f64 * 0.75, 50.0, false, 2.5);
    common::render(w, h, 0.0, 255.0, |x, y| {
        left.inside(x, y) || right.inside(x, y)
    })
    .iter()
    .zip(&texture)
    .map(|(&cov, &t)| {
        let v = 90.0 + 130.0 * f64::from(cov) / 255.0 + t;
        (128.0 + c * (v - 128.0)).round().clamp(0.0, 255.0) as u8
    })
    .collect()
}

/// Same scene at contrast 1.0 and 0.3: the adaptive rule keeps comparable point counts (within
/// ×1.25), the fixed threshold tuned on the 1.0 frame loses most of the 0.3 frame.
#[test]
fn adaptive_threshold_adapts_to_contrast_and_fixed_does_not() {
    let (w, h) = (320, 240);
    let hi = scene(1.0, w, h);
    let lo = scene(0.3, w, h);
    let det = adaptive(15.0, 80.0, 0.05, 8);
    let (_, s_hi, _) = detect(&det, &hi, w, h, Region::Full);
    let (_, s_lo, _) = detect(&det, &lo, w, h, Region::Full);
    let n_hi = (s_hi.left_count + s_hi.right_count) as f64;
    let n_lo = (s_lo.left_count + s_lo.right_count) as f64;
    assert!(n_hi > 500.0);
    assert!(
        (0.8..=1.25).contains(&(n_lo / n_hi)),
        "adaptive: {n_hi} vs {n_lo} (thresholds {} / {})",
        s_hi.threshold_magnitude,
        s_lo.threshold_magnitude
    );
    assert!(s_lo.threshold_magnitude < s_hi.threshold_magnitude);
    let fixed_det = fixed(s_hi.threshold_magnitude);
    let (_, f_hi, _) = detect(&fixed_det, &hi, w, h, Region::Full);
    let (_, f_lo, _) = detect(&fixed_det, &lo, w, h, Region::Full);
    let m_hi = (f_hi.left_count + f_hi.right_count) as f64;
    let m_lo = (f_lo.left_count + f_lo.right_count) as f64;
    assert_eq!(m_hi, n_hi);
    assert!(m_lo < 0.5 * m_hi, "fixed: {m_hi} vs {m_lo}");
}

/// The adaptive histogram is built inside the region only.
#[test]
fn adaptive_histogram_uses_only_the_region() {
    let (w, h) = (120, 90);
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    // Strong texture in the top half, weak in the bottom half.
    let data: Vec<u8> = (0..w * h)
        .map(|i| {
            let amp = if i / w < h / 2 { 120 } else { 10 };
            (128 + rng.random_range(-amp..=amp)) as u8
        })
        .collect();
    let det = adaptive(15.0, 80.0, 0.1, 0);
    let (_, full, _) = detect(&det, &data, w, h, Region::Full);
    let (_, bottom, _) = detect(
        &det,
        &data,
        w,
        h,
        Region::Rows {
            row_start_px: h / 2 + 1,
            row_end_px: h,
        },
    );
    let (_, count_bottom, _) = detect(
        &GradientDetector::new(GradientParams {
            threshold: Threshold::Fixed { min_magnitude: 0 },
            ..GradientParams::default()
        })
        .unwrap(),
        &data,
        w,
        h,
        Region::Rows {
            row_start_px: h / 2 + 1,
            row_end_px: h,
        },
    );
    assert_eq!(
        bottom.in_band_count,
        Some(count_bottom.left_count + count_bottom.right_count)
    );
    assert!(
        bottom.threshold_magnitude * 4 < full.threshold_magnitude,
        "{} vs {}",
        bottom.threshold_magnitude,
        full.threshold_magnitude
    );
}
