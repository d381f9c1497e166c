//! Typed errors, configuration loading, SIMD ≡ portable, and a real-frame smoke test (its frame
//! read from the data root, `$ITA_NAV_DATA` else `../shared/data` beside the checkout:
//! third-party, never in the repository; missing, it fails the test under CI and skips it,
//! saying so, elsewhere).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use vision_gradient::{
    Backend, ColSpan, EdgeBuffer, EdgeClass, GradientDetector, GradientError, GradientParams,
    GreyImage, Region, Threshold,
};

#[test]
fn bad_images_are_typed_errors() {
    let data = vec![0u8; 100];
    assert_eq!(
        GreyImage::new(&data, 0, 5, 5).unwrap_err(),
        GradientError::EmptyImage {
            width_px: 0,
            height_px: 5
        }
    );
    assert_eq!(
        GreyImage::new(&data, 5, 0, 5).unwrap_err(),
        GradientError::EmptyImage {
            width_px: 5,
            height_px: 0
        }
    );
    assert_eq!(
        GreyImage::new(&data, 10, 5, 9).unwrap_err(),
        GradientError::StrideTooSmall {
            stride: 9,
            width_px: 10
        }
    );
    // 10 rows of stride 11 need 9·11 + 10 = 109 bytes.
    assert_eq!(
        GreyImage::new(&data, 10, 10, 11).unwrap_err(),
        GradientError::DataTooShort {
            len: 100,
            required: 109,
            width_px: 10,
            height_px: 10,
            stride: 11
        }
    );
    assert!(GreyImage::new(&data, 10, 10, 10).is_ok());
    assert!(
        GreyImage::new(&data, 9, 10, 10).is_ok(),
        "last row needs only `width` bytes"
    );
    assert!(matches!(
        GreyImage::new(&data, 70_000, 1, 70_000),
        Err(GradientError::ImageTooLarge {
            width_px: 70_000,
            ..
        })
    ));
}

#[test]
fn bad_regions_and_buffers_are_typed_errors_and_write_nothing() {
    let (w, h) = (12, 8);
    let data: Vec<u8> = (0..w * h).map(|i| (i * 97 % 251) as u8).collect();
    let img = GreyImage::new(&data, w, h, w).unwrap();
    let det = GradientDetector::new(GradientParams::default()).unwrap();
    let mut edges = EdgeBuffer::with_capacity(10);
    let mask = vec![1u8; w * h - 1];
    let short_spans = vec![ColSpan::EMPTY; h - 1];
    let mut bad_span = vec![ColSpan::EMPTY; h];
    bad_span[3] = ColSpan {
        col_start_px: 2,
        col_end_px: 13,
    };
    let mut reversed = vec![ColSpan::EMPTY; h];
    reversed[5] = ColSpan {
        col_start_px: 6,
        col_end_px: 4,
    };
    let cases: Vec<(Region<'_>, GradientError)> = vec![
        (
            Region::Mask(&mask),
            GradientError::MaskSizeMismatch {
                len: w * h - 1,
                expected: w * h,
            },
        ),
        (
            Region::Rows {
                row_start_px: 3,
                row_end_px: 9,
            },
            GradientError::RowRangeInvalid {
                row_start_px: 3,
                row_end_px: 9,
                height_px: h,
            },
        ),
        (
            Region::Rows {
                row_start_px: 4,
                row_end_px: 4,
            },
            GradientError::RowRangeInvalid {
                row_start_px: 4,
                row_end_px: 4,
                height_px: h,
            },
        ),
        (
            Region::Spans(&short_spans),
            GradientError::SpansLengthMismatch {
                len: h - 1,
                expected: h,
            },
        ),
        (
            Region::Spans(&bad_span),
            GradientError::SpanOutOfRange {
                row_px: 3,
                col_start_px: 2,
                col_end_px: 13,
                width_px: w,
            },
        ),
        (
            Region::Spans(&reversed),
            GradientError::SpanOutOfRange {
                row_px: 5,
                col_start_px: 6,
                col_end_px: 4,
                width_px: w,
            },
        ),
    ];
    for (region, want) in cases {
        let mut cls = vec![7u8; w * h];
        assert_eq!(
            det.detect(&img, region, &mut edges, Some(&mut cls))
                .unwrap_err(),
            want
        );
        assert!(cls.iter().all(|&v| v == 7), "{want}: class image touched");
    }
    let mut small = vec![0u8; w * h + 1];
    assert_eq!(
        det.detect(&img, Region::Full, &mut edges, Some(&mut small))
            .unwrap_err(),
        GradientError::ClassImageSizeMismatch {
            len: w * h + 1,
            expected: w * h
        }
    );
}

#[test]
fn colspan_clamped_clips_to_the_image() {
    assert_eq!(
        ColSpan::clamped(-5, 7, 20),
        ColSpan {
            col_start_px: 0,
            col_end_px: 7
        }
    );
    assert_eq!(
        ColSpan::clamped(15, 40, 20),
        ColSpan {
            col_start_px: 15,
            col_end_px: 20
        }
    );
    assert_eq!(ColSpan::clamped(25, 40, 20), ColSpan::EMPTY);
    assert_eq!(ColSpan::clamped(9, 3, 20), ColSpan::EMPTY);
}

#[test]
fn params_validate_names_the_field() {
    let base = GradientParams::default();
    assert!(base.validate().is_ok());
    let field = |p: GradientParams| match p.validate() {
        Err(GradientError::InvalidParam { field, .. }) => field,
        other => panic!("expected InvalidParam, got {other:?}"),
    };
    let with = |f: &dyn Fn(&mut GradientParams)| {
        let mut p = base.clone();
        f(&mut p);
        p
    };
    assert_eq!(
        field(with(&|p| p.min_edge_angle_deg = -1.0)),
        "min_edge_angle_deg"
    );
    assert_eq!(
        field(with(&|p| p.min_edge_angle_deg = f64::NAN)),
        "min_edge_angle_deg"
    );
    assert_eq!(
        field(with(&|p| p.max_edge_angle_deg = 91.0)),
        "max_edge_angle_deg"
    );
    assert_eq!(
        field(with(&|p| p.max_edge_angle_deg = 10.0)),
        "max_edge_angle_deg"
    );
    assert_eq!(
        field(with(&|p| p.threshold = Threshold::Fixed {
            min_magnitude: 2041
        })),
        "threshold.min_magnitude"
    );
    assert_eq!(
        field(with(&|p| {
            p.threshold = Threshold::Adaptive {
                keep_fraction: 0.0,
                min_magnitude: 10,
            }
        })),
        "threshold.keep_fraction"
    );
    assert_eq!(
        field(with(&|p| {
            p.threshold = Threshold::Adaptive {
                keep_fraction: 1.5,
                min_magnitude: 10,
            }
        })),
        "threshold.keep_fraction"
    );
    // The limits' disabling values are valid.
    let open = GradientParams {
        min_edge_angle_deg: 0.0,
        max_edge_angle_deg: 90.0,
        ..base
    };
    assert!(GradientDetector::new(open).is_ok());
    // The detector refuses what validate refuses.
    assert!(matches!(
        GradientDetector::new(with(&|p| p.max_edge_angle_deg = 5.0)),
        Err(GradientError::InvalidParam {
            field: "max_edge_angle_deg",
            ..
        })
    ));
}

#[test]
fn params_load_from_toml_and_refuse_unknown_fields() {
    let text = r#"
        min_edge_angle_deg = 20.0
        max_edge_angle_deg = 75.0
        [threshold]
        mode = "adaptive"
        keep_fraction = 0.08
        min_magnitude = 40
    "#;
    let p: GradientParams = toml::from_str(text).unwrap();
    assert_eq!(
        p,
        GradientParams {
            min_edge_angle_deg: 20.0,
            max_edge_angle_deg: 75.0,
            threshold: Threshold::Adaptive {
                keep_fraction: 0.08,
                min_magnitude: 40
            },
        }
    );
    let fixed: GradientParams = toml::from_str(
        "min_edge_angle_deg = 15.0\nmax_edge_angle_deg = 80.0\n[threshold]\nmode = \"fixed\"\nmin_magnitude = 90\n",
    )
    .unwrap();
    assert_eq!(fixed.threshold, Threshold::Fixed { min_magnitude: 90 });
    let top = format!("{text}\n");
    assert!(toml::from_str::<GradientParams>(&top.replace("max_edge", "mx_edge")).is_err());
    assert!(toml::from_str::<GradientParams>(&text.replace("min_magnitude", "min_mag")).is_err());
    let extra = text.replace("min_magnitude = 40", "min_magnitude = 40\nsigma = 2");
    assert!(toml::from_str::<GradientParams>(&extra).is_err());
}

/// The AVX2 build of the kernel and the portable build give identical output (pixels, stats,
/// class image) on seeded random images of awkward sizes, strides, regions and parameters.
#[test]
fn avx2_and_portable_paths_agree_exactly() {
    let Ok(probe) = GradientDetector::with_backend(GradientParams::default(), Backend::Avx2) else {
        eprintln!("NOTE: AVX2 not available on this CPU; SIMD ≡ portable check skipped");
        return;
    };
    assert_eq!(probe.backend(), Backend::Avx2);
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    for case in 0..40 {
        let w = rng.random_range(1..700);
        let h = rng.random_range(1..60);
        let stride = w + rng.random_range(0..20);
        // Smooth-ish content so all magnitudes and angles occur, not only noise.
        let data: Vec<u8> = (0..stride * h)
            .map(|i| {
                let (x, y) = ((i % stride) as f64, (i / stride) as f64);
                let v = 128.0 + 90.0 * ((x * 0.13 + y * 0.07).sin() * (y * 0.11 - x * 0.05).cos());
                (v + rng.random_range(-20.0..20.0)).clamp(0.0, 255.0) as u8
            })
            .collect();
        let img = GreyImage::new(&data, w, h, stride).unwrap();
        let lo = rng.random_range(0.0..45.0);
        let params = GradientParams {
            min_edge_angle_deg: lo,
            max_edge_angle_deg: rng.random_range(lo + 1.0..=90.0),
            threshold: if rng.random_bool(0.5) {
                Threshold::Fixed {
                    min_magnitude: rng.random_range(0..400),
                }
            } else {
                Threshold::Adaptive {
                    keep_fraction: rng.random_range(0.01..=1.0),
                    min_magnitude: rng.random_range(0..100),
                }
            },
        };
        let mask: Vec<u8> = (0..w * h).map(|_| u8::from(rng.random_bool(0.7))).collect();
        let spans: Vec<ColSpan> = (0..h)
            .map(|_| {
                let a = rng.random_range(-20..w as i64 + 5);
                ColSpan::clamped(a, a + rng.random_range(0..80), w)
            })
            .collect();
        let region = match case % 4 {
            0 => Region::Full,
            1 => Region::Rows {
                row_start_px: h / 3,
                row_end_px: h,
            },
            2 => Region::Mask(&mask),
            _ => Region::Spans(&spans),
        };
        let capacity = rng.random_range(0..w * h + 1);
        let run = |backend| {
            let det = GradientDetector::with_backend(params.clone(), backend).unwrap();
            let mut edges = EdgeBuffer::with_capacity(capacity);
            let mut cls = vec![3u8; w * h];
            let stats = det
                .detect(&img, region, &mut edges, Some(&mut cls))
                .unwrap();
            (edges.pixels().to_vec(), stats, cls)
        };
        let simd = run(Backend::Avx2);
        let portable = run(Backend::Portable);
        assert_eq!(simd.1, portable.1, "case {case} ({w}x{h}): stats");
        assert_eq!(simd.0, portable.0, "case {case} ({w}x{h}): pixels");
        assert!(simd.2 == portable.2, "case {case} ({w}x{h}): class image");
    }
}

/// `relative` under the data root (`$ITA_NAV_DATA`, else `../shared/data` beside the checkout,
/// as `lane_bench::data`, which this crate cannot depend on); `None` (skipped, said on stderr)
/// when it is missing outside CI, a failure naming it under CI (`$CI` set).
fn test_data_file(relative: &str) -> Option<std::path::PathBuf> {
    let root = std::env::var_os("ITA_NAV_DATA").map_or_else(
        || std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
        std::path::PathBuf::from,
    );
    let path = root.join(relative);
    if path.exists() {
        return Some(path);
    }
    let missing = format!(
        "{}: missing test data `{relative}` (third-party, not in the repository: put the shared \
         data root beside the checkout as ../shared/data, or name it with ITA_NAV_DATA)",
        path.display()
    );
    assert!(std::env::var_os("CI").is_none(), "{missing}");
    eprintln!("SKIPPED (outside CI): {missing}");
    None
}

#[test]
fn real_frame_gives_both_classes_in_the_lower_half() {
    let Some(path) = test_data_file("udacity/frames-320x240/0001.png") else {
        return;
    };
    let grey = image::open(&path).unwrap().to_luma8();
    let (w, h) = (grey.width() as usize, grey.height() as usize);
    assert_eq!((w, h), (320, 240));
    let img = GreyImage::new(grey.as_raw(), w, h, w).unwrap();
    let mut edges = EdgeBuffer::with_capacity(w * h);
    for params in [
        GradientParams::default(),
        GradientParams {
            threshold: Threshold::Adaptive {
                keep_fraction: 0.05,
                min_magnitude: 40,
            },
            ..GradientParams::default()
        },
    ] {
        let det = GradientDetector::new(params.clone()).unwrap();
        let stats = det
            .detect(
                &img,
                Region::Rows {
                    row_start_px: h / 2,
                    row_end_px: h,
                },
                &mut edges,
                None,
            )
            .unwrap();
        let cols = |class| {
            let mut v: Vec<u16> = edges.iter_class(class).map(|p| p.col_px).collect();
            v.sort_unstable();
            v
        };
        let (left, right) = (cols(EdgeClass::LeftLane), cols(EdgeClass::RightLane));
        assert!(
            left.len() >= 50 && right.len() >= 50,
            "{params:?}: {stats:?}"
        );
        assert!(
            edges
                .pixels()
                .iter()
                .all(|p| usize::from(p.row_px) >= h / 2)
        );
        // Left-leaning marks lie mostly left of the right-leaning ones in this frame (dashed
        // left lane, solid right lane).
        let (ml, mr) = (left[left.len() / 2], right[right.len() / 2]);
        assert!(ml < mr, "{params:?}: median columns left {ml}, right {mr}");
    }
}
