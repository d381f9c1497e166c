//! One tracking frame (gradient in the windows + point gathering + KIF, two lanes) and the
//! paper's Table 1 stages, one thread.
//!
//! `cargo bench -p lane-eval --bench track -- --warm-up-time 1 --measurement-time 3`
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use hough_init::{AngleBand, HoughParams, HoughWorkspace, LaneInitParams, init_lane};
use info_filter::{ParabolaKif, ProcessNoise, RowNorm, ThetaCov};
use lane_io::FrameSource;
use lane_io::y4m::Y4mSource;
use lane_scenes::{SCENES, SceneRenderer};
use lane_tracker::{Estimator, GreyFrame, LaneTracker, Side, TrackerConfig};
use nalgebra::{Matrix3, Vector3};
use vision_gradient::{EdgeBuffer, EdgeClass, GradientDetector, GradientParams, GreyImage, Region};
use wrls::{WrlsFast, WrlsPaper};

fn udacity_frame() -> GreyFrame {
    let path = lane_bench::data::data_file(lane_bench::data::UDACITY_CLIP).unwrap();
    let mut src = Y4mSource::new(
        std::io::BufReader::new(std::fs::File::open(&path).unwrap()),
        path.display().to_string(),
    )
    .unwrap();
    let mut frame = GreyFrame::default();
    for _ in 0..10 {
        src.next_frame(&mut frame).unwrap().unwrap();
    }
    frame
}

fn synthetic_frame(w: usize, h: usize) -> GreyFrame {
    let mut r = SceneRenderer::new(SCENES[0], w, h);
    let mut frame = GreyFrame::default();
    r.render(3, &mut frame);
    frame
}

/// `frame` with seeded Gaussian noise of σ = 8 grey levels.
fn noisy(frame: &GreyFrame) -> GreyFrame {
    let mut out = frame.clone();
    lane_scenes::add_sensor_noise(&mut out, 8.0, 8);
    out
}

/// `frame` at a third of its exposure (every grey level divided by 3, rounded down).
fn dark(frame: &GreyFrame) -> GreyFrame {
    let mut out = frame.clone();
    for v in out.data_mut() {
        *v /= 3;
    }
    out
}

/// A tracker for `frame`'s size that has tracked it five times (its lanes settled on it).
fn warmed_up(cfg: &TrackerConfig, estimator: Estimator, frame: &GreyFrame) -> LaneTracker {
    let mut tracker = LaneTracker::new(cfg, estimator, frame.width(), frame.height()).unwrap();
    for _ in 0..5 {
        tracker.track(frame).unwrap();
    }
    tracker
}

fn tracking_frame(c: &mut Criterion) {
    let cfg = TrackerConfig::outdoor().unwrap();
    let mut group = c.benchmark_group("tracking_frame");
    let cases = [
        ("udacity_320x240", udacity_frame()),
        ("synthetic_320x240", synthetic_frame(320, 240)),
        // Other widths are resampled to 320 px wide (`frame.working_width_px`): 640×480 at
        // 320×240 and 1280×720 at 320×180 by the box average, 512×288 by the area average.
        ("synthetic_640x480", synthetic_frame(640, 480)),
        ("synthetic_512x288", synthetic_frame(512, 288)),
        ("synthetic_1280x720", synthetic_frame(1280, 720)),
    ];
    for (name, frame) in &cases {
        for (est_name, est) in [("kif", Estimator::Kif), ("wrls", Estimator::Wrls)] {
            let mut tracker = warmed_up(&cfg, est, frame);
            let r = tracker.track(frame).unwrap();
            assert!(
                !r.full_gradient,
                "{name}: steady state must be a tracking frame"
            );
            group.bench_function(BenchmarkId::new(est_name, name), |b| {
                b.iter(|| black_box(tracker.track(black_box(frame)).unwrap()));
            });
        }
        // The KIF with sub-pixel mark centres and the measured R (`track.mark_centres`).
        let mut centres = cfg;
        centres.track.mark_centres = true;
        let mut tracker = warmed_up(&centres, Estimator::Kif, frame);
        assert!(!tracker.track(frame).unwrap().full_gradient, "{name}");
        group.bench_function(BenchmarkId::new("kif_mark_centres", name), |b| {
            b.iter(|| black_box(tracker.track(black_box(frame)).unwrap()));
        });
        // An initialisation frame: full-ROI gradient + Hough + LS (both lanes) + refinement.
        let mut tracker =
            LaneTracker::new(&cfg, Estimator::Kif, frame.width(), frame.height()).unwrap();
        group.bench_function(BenchmarkId::new("init_frame", name), |b| {
            b.iter(|| {
                tracker.reset();
                black_box(tracker.track(black_box(frame)).unwrap())
            });
        });
        // The default configuration (joint initialisation, stripe pairing): a tracking frame, a
        // re-validation frame and initialisation frames (several Hough candidates per band,
        // ego-pair choice, two refinements in the wider window). The default re-validates every
        // `track.revalidate_every_frames`-th frame (and on a frame with a weak lane,
        // `track.revalidate_below_points`), so the tracked frame alone is measured with
        // re-validation off and a re-validation frame with it on every frame.
        let default = TrackerConfig::default_preset().unwrap();
        let mut tracked_only = default;
        tracked_only.track.revalidate_every_frames = 0;
        tracked_only.track.revalidate_below_points = 0;
        let mut tracking = warmed_up(&tracked_only, Estimator::Kif, frame);
        if !tracking.track(frame).unwrap().full_gradient {
            group.bench_function(BenchmarkId::new("kif_default", name), |b| {
                b.iter(|| black_box(tracking.track(black_box(frame)).unwrap()));
            });
        }
        // The same frame with sensor noise of σ = 8 grey levels: measured as noisy on the first
        // frame, every tracked frame smoothed before the stages read it (`[denoise]`).
        if *name == "udacity_320x240" {
            let noisy_frame = noisy(frame);
            let mut tracking = warmed_up(&tracked_only, Estimator::Kif, &noisy_frame);
            assert!(tracking.frame_noise().denoised, "σ 8 must be smoothed");
            if !tracking.track(&noisy_frame).unwrap().full_gradient {
                group.bench_function(BenchmarkId::new("kif_default_noisy", name), |b| {
                    b.iter(|| black_box(tracking.track(black_box(&noisy_frame)).unwrap()));
                });
            }
        }
        // The same frame at a third of its exposure: brightened on every frame before the stages
        // read it (`[exposure]`).
        if *name == "udacity_320x240" {
            let dark_frame = dark(frame);
            let mut tracking = warmed_up(&tracked_only, Estimator::Kif, &dark_frame);
            assert!(
                tracking.frame_exposure().gain > 1.0,
                "a third must be brightened"
            );
            if !tracking.track(&dark_frame).unwrap().full_gradient {
                group.bench_function(BenchmarkId::new("kif_default_dark", name), |b| {
                    b.iter(|| black_box(tracking.track(black_box(&dark_frame)).unwrap()));
                });
            }
        }
        let mut every_frame = default;
        every_frame.track.revalidate_every_frames = 1;
        let mut revalidating = warmed_up(&every_frame, Estimator::Kif, frame);
        group.bench_function(BenchmarkId::new("revalidation_frame_default", name), |b| {
            b.iter(|| black_box(revalidating.track(black_box(frame)).unwrap()));
        });
        let mut tracker =
            LaneTracker::new(&default, Estimator::Kif, frame.width(), frame.height()).unwrap();
        tracker.track(frame).unwrap();
        group.bench_function(BenchmarkId::new("init_frame_default", name), |b| {
            b.iter(|| {
                tracker.reset();
                black_box(tracker.track(black_box(frame)).unwrap())
            });
        });
        // The worst initialisation frames of the default: the ROI's right half blanked, so that
        // the right side is searched for again over the taller rows
        // (`roi.fallback_top_row_fraction`), and the whole ROI blanked, both bands voting there.
        let (top, bottom) = tracker.roi_rows();
        let w = frame.width();
        let fill = frame.data()[top * w];
        for (case, from_col) in [
            ("init_frame_default_second_search", w / 2),
            ("init_frame_default_second_search_both", 0),
        ] {
            let mut blanked = frame.clone();
            for row in blanked.data_mut()[top * w..bottom * w].chunks_mut(w) {
                row[from_col..].fill(fill);
            }
            tracker.reset();
            let r = tracker.track(&blanked).unwrap();
            println!(
                "{name}, ROI blanked from column {from_col} (ROI from row {top}): {} candidates, lanes {:?} / {:?}",
                tracker.init_candidates().len(),
                r.lanes[0].state,
                r.lanes[1].state
            );
            group.bench_function(BenchmarkId::new(case, name), |b| {
                b.iter(|| {
                    tracker.reset();
                    black_box(tracker.track(black_box(&blanked)).unwrap())
                });
            });
        }
    }
    group.finish();
}

/// The paper's Table 1, per frame, on the udacity frame: directional gradient (full frame),
/// Hough + LS (two lanes), KIF (two lanes, ≤ 150 points each), WRLS (paper N×N form and fast form).
fn table1(c: &mut Criterion) {
    let frame = udacity_frame();
    let (w, h) = (frame.width(), frame.height());
    let cfg = TrackerConfig::outdoor().unwrap();
    let image = GreyImage::new(frame.data(), w, h, w).unwrap();
    let det = GradientDetector::new(GradientParams {
        min_edge_angle_deg: cfg.gradient.min_edge_angle_deg,
        max_edge_angle_deg: cfg.gradient.max_edge_angle_deg,
        threshold: vision_gradient::Threshold::Fixed {
            min_magnitude: cfg.gradient.magnitude_threshold,
        },
    })
    .unwrap();
    let mut edges = EdgeBuffer::with_capacity(w * h);
    let (top, bottom) = cfg.roi_rows(h);
    let mut group = c.benchmark_group("table1");
    group.bench_function("directional_gradient_full_frame", |b| {
        b.iter(|| black_box(det.detect(&image, Region::Full, &mut edges, None).unwrap()));
    });
    det.detect(
        &image,
        Region::Rows {
            row_start_px: top,
            row_end_px: bottom,
        },
        &mut edges,
        None,
    )
    .unwrap();
    let pts = |class| -> Vec<(f32, f32)> {
        edges
            .iter_class(class)
            .map(|p| (f32::from(p.col_px), f32::from(p.row_px)))
            .collect()
    };
    let (left, right) = (pts(EdgeClass::LeftLane), pts(EdgeClass::RightLane));
    let mut ws = HoughWorkspace::new(
        w,
        h,
        HoughParams {
            theta_step_deg: 1.0,
            ..HoughParams::default()
        },
    )
    .unwrap();
    let ip = LaneInitParams {
        band_px: 4.0,
        min_points: 25,
        refit_iterations: 2,
    };
    let (lb, rb) = (AngleBand::new(10.0, 75.0), AngleBand::new(-75.0, -10.0));
    group.bench_function("hough_ls_two_lanes", |b| {
        b.iter(|| {
            black_box(init_lane(&left, &lb, &mut ws, &ip).unwrap());
            black_box(init_lane(&right, &rb, &mut ws, &ip).unwrap());
        });
    });
    let l_init = init_lane(&left, &lb, &mut ws, &ip).unwrap().parabola;
    let r_init = init_lane(&right, &rb, &mut ws, &ip).unwrap().parabola;
    // ≤ 150 points per lane, as the tracker gathers them.
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, w, h).unwrap();
    for _ in 0..3 {
        tracker.track(&frame).unwrap();
    }
    let lp: Vec<(f32, f32)> = tracker.lane_view(Side::Left).points.to_vec();
    let rp: Vec<(f32, f32)> = tracker.lane_view(Side::Right).points.to_vec();
    let rn = RowNorm::new(
        0.5 * (top + bottom - 1) as f64,
        0.5 * (bottom - 1 - top) as f64,
    )
    .unwrap();
    let p0 = ThetaCov::Normalised(Matrix3::identity() * 16.0);
    let th = |p: hough_init::Parabola| Vector3::new(p.a1, p.a2, p.a3);
    let q = ProcessNoise::new(&Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 2.25))).unwrap();
    let mut kl = ParabolaKif::new(&th(l_init), &p0, rn).unwrap();
    let mut kr = ParabolaKif::new(&th(r_init), &p0, rn).unwrap();
    group.bench_function(
        BenchmarkId::new("kif_two_lanes", format!("{}+{}pts", lp.len(), rp.len())),
        |b| {
            b.iter(|| {
                kl.predict(&q).unwrap();
                kl.update(black_box(&lp), 4.0).unwrap();
                kr.predict(&q).unwrap();
                kr.update(black_box(&rp), 4.0).unwrap();
            });
        },
    );
    let mut wl = WrlsPaper::new(&th(l_init), &p0, 0.7, rn, 150).unwrap();
    let mut wr = WrlsPaper::new(&th(r_init), &p0, 0.7, rn, 150).unwrap();
    group.bench_function(
        BenchmarkId::new(
            "wrls_paper_nxn_two_lanes",
            format!("{}+{}pts", lp.len(), rp.len()),
        ),
        |b| {
            b.iter(|| {
                wl.update(black_box(&lp)).unwrap();
                wr.update(black_box(&rp)).unwrap();
            });
        },
    );
    let mut fl = WrlsFast::new(&th(l_init), &p0, 0.7, rn).unwrap();
    let mut fr = WrlsFast::new(&th(r_init), &p0, 0.7, rn).unwrap();
    group.bench_function(
        BenchmarkId::new(
            "wrls_fast_two_lanes",
            format!("{}+{}pts", lp.len(), rp.len()),
        ),
        |b| {
            b.iter(|| {
                fl.update(black_box(&lp)).unwrap();
                fr.update(black_box(&rp)).unwrap();
            });
        },
    );
    group.finish();
}

criterion_group!(benches, tracking_frame, table1);
criterion_main!(benches);
