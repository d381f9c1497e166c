use super::*;
use crate::labelled::LabelSide;

/// A 320×180 frame: a horizontal ramp, with a bright 3-px stripe along the lane `x = 0.5·y + 60`.
fn scene() -> GreyFrame {
    let (w, h) = (320, 180);
    let mut data = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let lane_x = 0.5 * y as f64 + 60.0;
            data[y * w + x] = if (x as f64 - lane_x).abs() <= 1.0 {
                230
            } else {
                (40 + x / 4) as u8
            };
        }
    }
    GreyFrame::from_vec(w, h, data).unwrap()
}

/// The labels of [`scene`]: its lane on every row, and another marking on the lower half.
fn labels() -> LabelFrame {
    LabelFrame {
        index: 0,
        file: "frames/0000.png".into(),
        clip: "c".into(),
        lanes: vec![
            LabelLane {
                side: LabelSide::Left,
                points: (0..180)
                    .map(|y| [0.5 * f64::from(y) + 60.0, f64::from(y)])
                    .collect(),
            },
            LabelLane {
                side: LabelSide::Other,
                points: (90..180).map(|y| [300.0, f64::from(y)]).collect(),
            },
        ],
    }
}

fn flat(w: usize, h: usize, v: u8) -> GreyFrame {
    GreyFrame::from_vec(w, h, vec![v; w * h]).unwrap()
}

/// The intensity-weighted mean column of row `y` of `f` over the pixels brighter than `floor`.
fn bright_centroid(f: &GreyFrame, y: usize, floor: u8) -> f64 {
    let row = f.row(y).unwrap();
    let (mut s, mut sx) = (0.0, 0.0);
    for (x, &v) in row.iter().enumerate() {
        if v > floor {
            let m = f64::from(v - floor);
            s += m;
            sx += m * x as f64;
        }
    }
    sx / s
}

const UP: Perturbation = Perturbation::Horizon {
    direction: Direction::Up,
    fraction: 0.15,
};
const DOWN: Perturbation = Perturbation::Horizon {
    direction: Direction::Down,
    fraction: 0.15,
};

#[test]
fn a_shift_up_then_down_restores_the_interior_and_its_labels() {
    let (f, l) = (scene(), labels());
    let up = UP.apply(&f, &l, 108.0, 0).unwrap();
    let back = DOWN
        .apply(&up.frame, &up.labels, up.near_top_px, 0)
        .unwrap();
    let d = 27; // round(0.15 · 180)
    assert_eq!(back.frame.data()[d * 320..], f.data()[d * 320..]);
    // The vacated rows are one flat grey: the mean of the content row beside them.
    let top = &back.frame.data()[..d * 320];
    assert!(top.iter().all(|&v| v == top[0]), "flat fill");
    let bottom_of_up = &up.frame.data()[(180 - d) * 320..];
    let last = f.row(179).unwrap();
    let mean = (last.iter().map(|&v| f64::from(v)).sum::<f64>() / 320.0).round() as u8;
    assert!(bottom_of_up.iter().all(|&v| v == mean));
    // Labels: the rows that left the top are gone, the others are back where they were.
    let want: Vec<[f64; 2]> = l.lanes[0].points[d..].to_vec();
    assert_eq!(back.labels.lanes[0].points, want);
    assert_eq!(up.labels.lanes[0].points[0], [0.5 * 27.0 + 60.0, 0.0]);
    // The near band moves with the content: 108 → 81 → 108.
    assert_eq!((up.near_top_px, back.near_top_px), (81.0, 108.0));
}

#[test]
fn a_shift_down_drops_the_label_points_that_leave_the_frame() {
    let l = labels();
    let down = DOWN.map_labels(&l, 320, 180);
    assert_eq!(down.lanes[0].points.len(), 180 - 27);
    assert_eq!(down.lanes[0].points[0], [60.0, 27.0]);
    assert!(
        down.lanes
            .iter()
            .all(|lane| lane.points.iter().all(|p| p[1] < 180.0))
    );
}

#[test]
fn labels_mapped_under_a_resize_land_on_the_same_image_feature() {
    let (f, l) = (scene(), labels());
    for width_px in [256, 512, 640, 1280, 1920] {
        let p = Perturbation::Width { width_px };
        let out = p.apply(&f, &l, 108.0, 0).unwrap();
        let (w2, h2) = p.size(320, 180);
        assert_eq!((out.frame.width(), out.frame.height()), (w2, h2));
        assert_eq!(w2 * 180, h2 * 320, "same aspect");
        // Every few mapped label points: the stripe's centre on that row is within a quarter
        // of an input pixel of the mapped point (the ramp below the floor does not count).
        let k = w2 as f64 / 320.0;
        for &[x, y] in out.labels.lanes[0].points.iter().step_by(17) {
            let c = bright_centroid(&out.frame, y as usize, 125);
            assert!(
                (c - x).abs() < 0.25 * k.max(1.0),
                "{width_px}: row {y}: {c} vs {x}"
            );
        }
        // One point per integer row, inside the frame.
        let rows: Vec<f64> = out.labels.lanes[0].points.iter().map(|p| p[1]).collect();
        assert!(rows.windows(2).all(|r| r[1] - r[0] == 1.0), "{width_px}");
        assert!(rows.iter().all(|&r| r >= 0.0 && r < h2 as f64));
        // The near band's top maps by the pixel-centre rule.
        assert_eq!(out.near_top_px, (108.0 + 0.5) * k - 0.5);
    }
}

#[test]
fn the_identity_width_changes_nothing() {
    let (f, l) = (scene(), labels());
    let out = Perturbation::Width { width_px: 320 }
        .apply(&f, &l, 108.0, 0)
        .unwrap();
    assert_eq!(out.frame, f);
    assert_eq!(out.labels, l);
    assert_eq!(out.near_top_px, 108.0);
}

#[test]
fn resizing_keeps_a_flat_image_flat_and_area_resampling_keeps_the_mean() {
    for (w2, h2) in [(256, 144), (640, 360), (1920, 1080), (100, 33)] {
        let out = resize(&flat(320, 180, 97), w2, h2);
        assert!(out.data().iter().all(|&v| v == 97), "{w2}×{h2}");
    }
    // A 4×1 row [0, 100, 200, 40] halved: each output the mean of its two inputs.
    let row = GreyFrame::from_vec(4, 1, vec![0, 100, 200, 40]).unwrap();
    assert_eq!(resize(&row, 2, 1).data(), &[50, 120]);
    // Doubled, bilinear: output 1 reads input 0.25 → 25; the borders clamp.
    assert_eq!(
        resize(&row, 8, 1).data(),
        &[0, 25, 75, 125, 175, 160, 80, 40]
    );
}

#[test]
fn a_bonnet_keeps_the_road_whole_compressed_and_looks_like_a_bonnet() {
    let (f, l) = (scene(), labels());
    for fraction in [0.20, 0.35] {
        let p = Perturbation::Bonnet { fraction };
        let out = p.apply(&f, &l, 108.0, 0).unwrap();
        assert_eq!((out.frame.width(), out.frame.height()), (320, 180));
        let h2 = geometry::bonnet_frame_height(180, fraction) as f64;
        let ky = 180.0 / h2;
        // The bonnet takes the fraction of the new height at the centre column.
        assert!(((h2 - 180.0) / h2 - fraction).abs() < 0.005, "{h2}");
        // Every label point kept (the road is whole), on the stripe, within the road's rows.
        let last_row = ((180.0 - 0.5) * ky - 0.5).floor() as usize;
        assert_eq!(out.labels.lanes[0].points.len(), last_row + 1);
        for &[x, y] in out.labels.lanes[0].points.iter().step_by(11) {
            let c = bright_centroid(&out.frame, y as usize, 125);
            assert!((c - x).abs() < 0.3, "{fraction}: row {y}: {c} vs {x}");
        }
        assert_eq!(out.near_top_px, (108.0 + 0.5) * ky - 0.5);
        // Below the road: not a flat bar — darker than the highlight, shaded across its depth
        // and its width, and brighter at the centre than at the sides on its highlight.
        let road_rows = (180.0 * ky).ceil() as usize + 1;
        let bonnet: Vec<&[u8]> = (road_rows..180)
            .map(|y| out.frame.row(y).unwrap())
            .collect();
        let col = |x: usize| bonnet.iter().map(|r| r[x]).collect::<Vec<u8>>();
        let centre = col(160);
        let (lo, hi) = (centre.iter().min().unwrap(), centre.iter().max().unwrap());
        assert!(*hi >= lo + 25, "{fraction}: highlight {centre:?}");
        assert!(*hi < 200 && *lo < 90, "{fraction}: dark paint {centre:?}");
        let brightest = centre.iter().position(|v| v == hi).unwrap();
        assert!(
            bonnet[brightest][160] > bonnet[brightest][5],
            "shaded to the sides"
        );
    }
}

#[test]
fn brightness_scales_and_clamps() {
    let f = GreyFrame::from_vec(3, 1, vec![10, 100, 200]).unwrap();
    let dim = Perturbation::Brightness { gain: 0.5 };
    let bright = Perturbation::Brightness { gain: 1.6 };
    assert_eq!(dim.perturb_image(&f, 0, "f").unwrap().data(), &[5, 50, 100]);
    assert_eq!(
        bright.perturb_image(&f, 0, "f").unwrap().data(),
        &[16, 160, 255]
    );
}

#[test]
fn noise_is_deterministic_per_seed_and_of_the_given_spread() {
    let f = flat(320, 180, 128);
    let p = Perturbation::Noise { sigma_grey: 8.0 };
    let a = p.perturb_image(&f, 7, "f").unwrap();
    assert_eq!(a, p.perturb_image(&f, 7, "f").unwrap());
    assert_ne!(a, p.perturb_image(&f, 8, "f").unwrap());
    let n = a.data().len() as f64;
    let mean = a.data().iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let var = a
        .data()
        .iter()
        .map(|&v| (f64::from(v) - mean).powi(2))
        .sum::<f64>()
        / n;
    assert!((mean - 128.0).abs() < 0.2, "{mean}");
    // σ² plus the rounding's 1/12.
    assert!(
        (var.sqrt() - (64.0f64 + 1.0 / 12.0).sqrt()).abs() < 0.1,
        "{}",
        var.sqrt()
    );
    // The frames of a set get different seeds, the same every run.
    assert_eq!(frame_seed(53, "culane", 3), frame_seed(53, "culane", 3));
    assert_ne!(frame_seed(53, "culane", 3), frame_seed(53, "culane", 4));
    assert_ne!(frame_seed(53, "culane", 3), frame_seed(53, "seame", 3));
}

#[test]
fn blur_keeps_a_constant_and_spreads_a_point_over_seven_columns() {
    let p = Perturbation::MotionBlur { taps_px: 7 };
    let f = flat(40, 3, 77);
    assert_eq!(p.perturb_image(&f, 0, "f").unwrap(), f);
    let mut data = vec![0u8; 20];
    data[10] = 140;
    let out = p
        .perturb_image(&GreyFrame::from_vec(20, 1, data).unwrap(), 0, "f")
        .unwrap();
    let want: Vec<u8> = (0..20)
        .map(|x| if (7..=13).contains(&x) { 20 } else { 0 })
        .collect();
    assert_eq!(out.data(), &want[..]);
}

#[test]
fn jpeg_keeps_the_size_and_stays_near_the_image() {
    let f = scene();
    let out = Perturbation::Jpeg { quality: 30 }
        .perturb_image(&f, 0, "f")
        .unwrap();
    assert_eq!((out.width(), out.height()), (320, 180));
    assert_ne!(out, f, "lossy");
    let mean_err = f
        .data()
        .iter()
        .zip(out.data())
        .map(|(&a, &b)| (f64::from(a) - f64::from(b)).abs())
        .sum::<f64>()
        / f.data().len() as f64;
    assert!(mean_err < 6.0, "{mean_err}");
}

#[test]
fn the_table_has_unique_names_and_valid_parameters_and_bad_ones_are_refused() {
    let names: Vec<String> = TABLE.iter().map(Perturbation::name).collect();
    let mut unique = names.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), TABLE.len(), "{names:?}");
    assert!(names.contains(&"horizon-up-15".to_owned()) && names.contains(&"blur-7".to_owned()));
    for p in TABLE {
        p.validate().unwrap();
    }
    for bad in [
        Perturbation::MotionBlur { taps_px: 6 },
        Perturbation::Bonnet { fraction: 1.0 },
        Perturbation::Jpeg { quality: 0 },
        Perturbation::Noise {
            sigma_grey: f64::NAN,
        },
    ] {
        assert!(bad.perturb_image(&scene(), 0, "f").is_err(), "{bad:?}");
    }
}
