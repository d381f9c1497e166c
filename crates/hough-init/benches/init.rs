//! Stage II for two lanes: Hough (restricted band) + least squares, per frame size.
//!
//! Scenes: two 7-px-wide (320×240) or 3-px-wide (640×480, "sparse") / 15-px-wide (640×480,
//! "dense") curved marks from a horizon at 0.4·H, σ = 0.5 px column noise, plus 30 % uniform
//! clutter per lane. `oriented-8` is the default tracker's vote without its stripe weights: a
//! 1° θ step as in `configs/default.toml`, each pixel carrying its edge normal (the mark's, or a
//! pseudo-random one for clutter) and voting within ±15° of it, the 8 strongest lines of each
//! band at least 3° / 8 px apart. Run:
//! `cargo bench -p hough-init --bench init -- --warm-up-time 1 --measurement-time 3`
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;

use common::{clutter, draw_mark};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use hough_init::{
    AngleBand, HoughLine, HoughParams, HoughWorkspace, LaneInitParams, OrientedPoint, Parabola,
    Point, init_lane,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn lane(h: f64, x_top: f64, x_bot: f64, sag_px: f64) -> Parabola {
    let (y_t, y_b) = (0.4 * h, h - 1.0);
    let a1 = -4.0 * sag_px / (y_b - y_t).powi(2);
    let slope = (x_bot - x_top) / (y_b - y_t);
    Parabola {
        a1,
        a2: -a1 * (y_t + y_b) + slope,
        a3: a1 * y_t * y_b + x_top - slope * y_t,
    }
}

/// The points with a normal angle each: the lane's own (`dx/dy = −tan θ`) within two mark
/// widths of it, a pseudo-random one (seeded) elsewhere.
fn with_normals(
    pts: &[Point],
    lane: &Parabola,
    half_width_px: f64,
    seed: u64,
) -> Vec<OrientedPoint> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    pts.iter()
        .map(|p| {
            let on_mark = (p.col_px - lane.col_at_row(p.row_px)).abs() <= 2.0 * half_width_px;
            let normal_deg = if on_mark {
                (-(2.0 * lane.a1 * p.row_px + lane.a2)).atan().to_degrees()
            } else {
                rand::Rng::random_range(&mut rng, -90.0..90.0)
            };
            OrientedPoint {
                col_px: p.col_px as f32,
                row_px: p.row_px as f32,
                normal_deg: normal_deg as f32,
                votes: 1,
            }
        })
        .collect()
}

fn lanes(width: usize, height: usize) -> [Parabola; 2] {
    let (w, h) = (width as f64, height as f64);
    [
        lane(h, 0.45 * w, 0.1 * w, 0.025 * h),
        lane(h, 0.55 * w, 0.9 * w, 0.025 * h),
    ]
}

fn candidates(width: usize, height: usize, half_width_px: f64, seed: u64) -> [Vec<Point>; 2] {
    let h = height as f64;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let row_lo = (0.4 * h) as usize;
    lanes(width, height).map(|p| {
        let mut pts = draw_mark(width, height, &p, row_lo, half_width_px, 0.5, &mut rng);
        let n = (0.3 * pts.len() as f64) as usize;
        pts.extend(clutter(width, height, n, &mut rng));
        pts
    })
}

fn bench_init(c: &mut Criterion) {
    let mut group = c.benchmark_group("init_two_lanes");
    for (width, height, half_width, label) in [
        (320, 240, 3.5, "320x240"),
        (640, 480, 1.5, "640x480-sparse"),
        (640, 480, 7.0, "640x480-dense"),
    ] {
        let [left, right] = candidates(width, height, half_width, 1);
        eprintln!(
            "{label}: {} left + {} right candidate pixels",
            left.len(),
            right.len()
        );
        let mut ws = HoughWorkspace::new(width, height, HoughParams::default()).unwrap();
        for (name, params) in [
            ("paper", LaneInitParams::default()),
            (
                "refit2",
                LaneInitParams {
                    refit_iterations: 2,
                    ..LaneInitParams::default()
                },
            ),
        ] {
            group.bench_with_input(BenchmarkId::new(name, label), &(), |b, ()| {
                b.iter(|| {
                    let l = init_lane(black_box(&left), &AngleBand::LEFT_LANE, &mut ws, &params)
                        .unwrap();
                    let r = init_lane(black_box(&right), &AngleBand::RIGHT_LANE, &mut ws, &params)
                        .unwrap();
                    black_box((l, r))
                });
            });
        }
        let [lane_l, lane_r] = lanes(width, height);
        let left_o = with_normals(&left, &lane_l, half_width, 2);
        let right_o = with_normals(&right, &lane_r, half_width, 3);
        let mut ws_oriented = HoughWorkspace::new(
            width,
            height,
            HoughParams {
                theta_step_deg: 1.0,
                ..HoughParams::default()
            },
        )
        .unwrap();
        ws_oriented.reserve_oriented_points(left_o.len().max(right_o.len()));
        let mut found = [HoughLine {
            rho_px: 0.0,
            theta_rad: 0.0,
            votes: 0,
        }; 8];
        group.bench_with_input(BenchmarkId::new("oriented-8", label), &(), |b, ()| {
            b.iter(|| {
                let l = ws_oriented
                    .find_lines_oriented(
                        black_box(&left_o),
                        &AngleBand::LEFT_LANE,
                        15.0,
                        3.0,
                        8.0,
                        &mut found,
                    )
                    .unwrap();
                let r = ws_oriented
                    .find_lines_oriented(
                        black_box(&right_o),
                        &AngleBand::RIGHT_LANE,
                        15.0,
                        3.0,
                        8.0,
                        &mut found,
                    )
                    .unwrap();
                black_box((l, r))
            });
        });
        let mut ws_fast = HoughWorkspace::new(
            width,
            height,
            HoughParams {
                peak_smoothing: false,
                subbin_refinement: false,
                ..HoughParams::default()
            },
        )
        .unwrap();
        let params = LaneInitParams::default();
        group.bench_with_input(
            BenchmarkId::new("paper-no-smoothing", label),
            &(),
            |b, ()| {
                b.iter(|| {
                    let l = init_lane(
                        black_box(&left),
                        &AngleBand::LEFT_LANE,
                        &mut ws_fast,
                        &params,
                    )
                    .unwrap();
                    let r = init_lane(
                        black_box(&right),
                        &AngleBand::RIGHT_LANE,
                        &mut ws_fast,
                        &params,
                    )
                    .unwrap();
                    black_box((l, r))
                });
            },
        );
    }
    group.finish();
}

criterion_group!(benches, bench_init);
criterion_main!(benches);
