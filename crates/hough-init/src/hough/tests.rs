//! The Hough transform's tests.

use super::peaks::parabolic_offset;

use super::*;
use crate::Point;

/// The θ-major oriented vote (runs counting-sorted by their first bin) fills the same
/// accumulator as a point-major reference: every point, every bin of the band, a vote
/// where the bin is within `⌊tolerance/Δθ⌋` bins of the bin nearest the point's normal
/// taken modulo 180° (every bin for a window covering the half circle) — with θ steps that
/// do and do not divide 180°, narrow and wide windows, bands at both ends of the range, and
/// weighted points.
#[test]
fn the_theta_major_oriented_vote_equals_a_point_major_reference() {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || xorshift(&mut state);
    for step in [1.0, 0.7, 2.5] {
        let params = HoughParams {
            theta_step_deg: step,
            ..HoughParams::default()
        };
        let mut ws = HoughWorkspace::new(160, 120, params).unwrap();
        let (nr, nt) = (ws.rho_bins, ws.theta_bins);
        let points: Vec<OrientedPoint> = (0..400)
            .map(|_| OrientedPoint {
                col_px: (next() % 160) as f32,
                row_px: (next() % 120) as f32,
                normal_deg: -90.0 + (next() % 18_000) as f32 / 100.0,
                votes: (next() % 4) as u16,
            })
            .collect();
        ws.reserve_oriented_points(points.len());
        for (k0, k1) in [(0, nt - 1), (0, nt / 6), (nt / 3, nt / 2), (nt - 5, nt - 1)] {
            for tolerance_deg in [0.0, 1.0, 15.0, 40.0, 89.0, 90.0] {
                ws.vote_oriented(&points, k0, k1, tolerance_deg);
                let half = (tolerance_deg / step + 1e-9).floor() as i64;
                // A window covering the half circle votes in every bin.
                let every = tolerance_deg >= 90.0 || 2 * half + 1 >= nt as i64;
                let mut expected = vec![0u32; (k1 - k0 + 1) * nr];
                let (cx, cy) = (ws.center_col_px, ws.center_row_px);
                for p in &points {
                    let x = (f64::from(p.col_px) - cx) as f32;
                    let y = (f64::from(p.row_px) - cy) as f32;
                    let centres = [0.0, 180.0, -180.0]
                        .map(|d| ((f64::from(p.normal_deg) + d + 90.0) / step).round() as i64);
                    for k in k0..=k1 {
                        if every || centres.iter().any(|&c| (k as i64 - c).abs() <= half) {
                            let (c, s) = (ws.cos_over_step[k], ws.sin_over_step[k]);
                            let r = rho_bin(x, y, c, s, ws.rho_zero_bin as f32) as usize;
                            expected[(k - k0) * nr + r] += u32::from(p.votes);
                        }
                    }
                }
                assert!(
                    ws.acc[k0 * nr..(k1 + 1) * nr] == expected[..],
                    "step {step}, band {k0}..={k1}, tolerance {tolerance_deg}"
                );
            }
        }
    }
}

/// Random oriented points with lines in them: `lines` lines of 60 points (normals along
/// the line's, jittered) among `clutter` random points, votes 0–3.
fn oriented_scene(
    next: &mut impl FnMut() -> u64,
    lines: usize,
    clutter: usize,
) -> Vec<OrientedPoint> {
    let mut points = Vec::new();
    for _ in 0..lines {
        let theta_deg = -80.0 + (next() % 16_000) as f32 / 100.0;
        let (s, c) = theta_deg.to_radians().sin_cos();
        let (x0, y0) = ((next() % 320) as f32, (next() % 240) as f32);
        for t in 0..60 {
            // Along the line (direction (−sin θ, cos θ)), inside the image.
            let d = t as f32 * 2.0 - 60.0;
            let (x, y) = (x0 - d * s, y0 + d * c);
            if (0.0..=319.0).contains(&x) && (0.0..=239.0).contains(&y) {
                let jitter = (next() % 600) as f32 / 100.0 - 3.0;
                points.push(OrientedPoint {
                    col_px: x.round(),
                    row_px: y.round(),
                    normal_deg: (theta_deg + jitter).clamp(-90.0, 89.99),
                    votes: (next() % 4) as u16,
                });
            }
        }
    }
    points.extend((0..clutter).map(|_| OrientedPoint {
        col_px: (next() % 320) as f32,
        row_px: (next() % 240) as f32,
        normal_deg: -90.0 + (next() % 18_000) as f32 / 100.0,
        votes: (next() % 4) as u16,
    }));
    points
}

/// The AVX2 build of the oriented vote and its peak search finds the same peaks, from the
/// same accumulator and smoothed votes, as the portable one (the same integer sums and
/// unfused `f32` products): 60 seeded scenes, both bands, several tolerances and
/// separations, under the default Hough parameters and with peak smoothing, sub-bin
/// refinement and other bin sizes changed. Both paths are reached through
/// [`HoughWorkspace::find_lines_oriented`], which takes the AVX2 one wherever
/// [`HoughWorkspace::new`] detected AVX2 (checked here too). Skipped (and said so) on a CPU
/// without AVX2.
#[test]
#[cfg(target_arch = "x86_64")]
fn the_avx2_vote_and_peak_search_equal_the_portable_ones() {
    let detected = std::arch::is_x86_feature_detected!("avx2");
    let param_sets = [
        HoughParams::default(),
        HoughParams {
            peak_smoothing: false,
            ..HoughParams::default()
        },
        HoughParams {
            subbin_refinement: false,
            ..HoughParams::default()
        },
        HoughParams {
            theta_step_deg: 1.0,
            rho_step_px: 2.0,
            peak_smoothing: false,
            subbin_refinement: false,
        },
    ];
    let none = HoughLine {
        rho_px: 0.0,
        theta_rad: 0.0,
        votes: 0,
    };
    let mut compared = 0;
    for params in param_sets {
        let mut ws = HoughWorkspace::new(320, 240, params).unwrap();
        assert_eq!(ws.avx2, detected, "the path follows the CPU's AVX2");
        if !detected {
            eprintln!("no AVX2 on this CPU: only the portable path exists to test");
            return;
        }
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || xorshift(&mut state);
        for scene in 0..60 {
            let points = oriented_scene(&mut next, 1 + scene % 4, 50 * (scene % 7));
            ws.reserve_oriented_points(points.len());
            for band in [AngleBand::LEFT_LANE, AngleBand::RIGHT_LANE] {
                for (tolerance_deg, (sep_theta_deg, sep_rho_px)) in
                    [(15.0, (3.0, 8.0)), (5.0, (1.0, 2.0)), (90.0, (6.0, 20.0))]
                {
                    let mut run = |avx2: bool, out: &mut [HoughLine; 8]| {
                        ws.avx2 = avx2;
                        let runs = ws.avx2_runs;
                        let n = ws
                            .find_lines_oriented(
                                &points,
                                &band,
                                tolerance_deg,
                                sep_theta_deg,
                                sep_rho_px,
                                out,
                            )
                            .unwrap();
                        assert_eq!(ws.avx2_runs, runs + usize::from(avx2), "path taken");
                        (n, ws.acc.clone(), ws.smoothed.clone())
                    };
                    let (mut portable, mut avx2) = ([none; 8], [none; 8]);
                    let (n, acc, smoothed) = run(false, &mut portable);
                    let (m, acc_avx2, smoothed_avx2) = run(true, &mut avx2);
                    assert_eq!(
                        (n, &portable[..n]),
                        (m, &avx2[..m]),
                        "{params:?}, scene {scene}, {band:?}"
                    );
                    assert!(
                        acc == acc_avx2 && smoothed == smoothed_avx2,
                        "{params:?}, scene {scene}, {band:?}"
                    );
                    compared += n;
                }
            }
        }
    }
    // The scenes hold lines: most searches return several peaks.
    assert!(compared > 4 * 60 * 2 * 3 * 4, "{compared} peaks compared");
}

/// The one-pass validity test of the oriented points agrees with the checks that name the
/// first bad point: normals at and around ±90°, coordinates at and around the image's
/// bounds (half a pixel outside), NaN and infinities.
#[test]
fn the_fast_validity_pass_agrees_with_the_point_checks() {
    let ws = HoughWorkspace::new(320, 240, HoughParams::default()).unwrap();
    let around = |v: f32| [v, v.next_down(), v.next_up()];
    let mut cols = vec![f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 100.0];
    cols.extend(around(-0.5).into_iter().chain(around(319.5)));
    let mut rows = vec![f32::NAN, f32::INFINITY, 50.0];
    rows.extend(around(-0.5).into_iter().chain(around(239.5)));
    let mut normals = vec![f32::NAN, f32::NEG_INFINITY, 0.0];
    normals.extend(around(-90.0).into_iter().chain(around(90.0)));
    let good = OrientedPoint {
        col_px: 10.0,
        row_px: 10.0,
        normal_deg: 10.0,
        votes: 1,
    };
    let mut seen = [0; 2];
    for &col_px in &cols {
        for &row_px in &rows {
            for &normal_deg in &normals {
                let odd = OrientedPoint {
                    col_px,
                    row_px,
                    normal_deg,
                    votes: 1,
                };
                let points = [good, odd, good];
                let checked = points
                    .iter()
                    .all(|p| p.normal_deg.is_finite() && (-90.0..90.0).contains(&p.normal_deg))
                    && ws.check_points(points.iter()).is_ok();
                assert_eq!(ws.oriented_points_valid(&points), checked, "{odd:?}");
                seen[usize::from(checked)] += 1;
            }
        }
    }
    assert!(seen[0] > 0 && seen[1] > 0, "{seen:?}");
}

/// The next value of a xorshift sequence (`state` never 0): deterministic, no external RNG.
fn xorshift(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}

/// Deterministic pseudo-random votes (xorshift).
fn fill_votes(ws: &mut HoughWorkspace, k0: usize, k1: usize, seed: u64) {
    let mut state = seed | 1;
    let nr = ws.rho_bins;
    for v in &mut ws.acc[k0 * nr..(k1 + 1) * nr] {
        *v = (xorshift(&mut state) % 50) as u32;
    }
}

/// Brute-force argmax of `score` in scan order (first maximum wins).
fn naive_peak(ws: &HoughWorkspace, k0: usize, k1: usize) -> (usize, usize) {
    let mut best = (-1.0, k0, 0);
    for k in k0..=k1 {
        for r in 0..ws.rho_bins {
            let v = ws.score(k, r, k0, k1);
            if v > best.0 {
                best = (v, k, r);
            }
        }
    }
    (best.1, best.2)
}

/// The ring-buffer 3×3 peak and the raw peak equal a brute-force argmax of the
/// independently written `score` (direct 3×3 sums clipped to the band), for bands of
/// 1, 2, 3 and many θ bins.
#[test]
fn fast_peak_search_matches_brute_force() {
    for smoothing in [true, false] {
        let params = HoughParams {
            peak_smoothing: smoothing,
            ..HoughParams::default()
        };
        let mut ws = HoughWorkspace::new(64, 48, params).unwrap();
        for (i, (k0, k1)) in [(10, 10), (10, 11), (10, 12), (0, 359), (200, 317)]
            .into_iter()
            .enumerate()
        {
            fill_votes(&mut ws, k0, k1, 17 + i as u64);
            let fast = if smoothing {
                ws.peak_smoothed(k0, k1)
            } else {
                ws.peak_raw(k0, k1)
            };
            assert_eq!(
                fast,
                naive_peak(&ws, k0, k1),
                "band {k0}..={k1}, smoothing {smoothing}"
            );
        }
    }
}

/// The peaks `take_peaks` takes from its smoothed rows, updated only where a suppression
/// changed them, are those of a brute-force argmax of `score` over the whole band after
/// every suppression, in the same order, for bands of 1, 2, 3 and many θ bins.
#[test]
fn incremental_peaks_match_a_brute_force_search_after_every_suppression() {
    for smoothing in [true, false] {
        let params = HoughParams {
            peak_smoothing: smoothing,
            subbin_refinement: false,
            ..HoughParams::default()
        };
        let mut ws = HoughWorkspace::new(64, 48, params).unwrap();
        let mut reference = HoughWorkspace::new(64, 48, params).unwrap();
        let nr = ws.rho_bins;
        let none = HoughLine {
            rho_px: 0.0,
            theta_rad: 0.0,
            votes: 0,
        };
        for (i, (k0, k1)) in [(10, 10), (10, 11), (10, 12), (0, 359), (200, 317)]
            .into_iter()
            .enumerate()
        {
            fill_votes(&mut ws, k0, k1, 29 + i as u64);
            // A broad hill: after the suppression of its top the strongest cells lie just
            // outside the cleared cells, where stale smoothed sums would be wrong.
            let (kc, rc) = ((k0 + k1) / 2, nr / 2);
            for k in k0..=k1 {
                for r in 0..nr {
                    let d = k.abs_diff(kc) + r.abs_diff(rc);
                    ws.acc[k * nr + r] += 400u32.saturating_sub(20 * d as u32);
                }
            }
            reference.acc.copy_from_slice(&ws.acc);
            let mut out = [none; 12];
            let n = ws.take_peaks(k0, k1, 3.0, 4.0, &mut out);
            let dk = (3.0 / params.theta_step_deg).round() as usize;
            let dr = (4.0 / params.rho_step_px).round() as usize;
            let mut expected = Vec::new();
            while expected.len() < out.len() {
                let (k, r) = naive_peak(&reference, k0, k1);
                if reference.score(k, r, k0, k1) <= 0.0 {
                    break;
                }
                expected.push(reference.refined_line(k, r, k0, k1));
                for kk in k.saturating_sub(dk).max(k0)..=(k + dk).min(k1) {
                    reference.acc[kk * nr + r.saturating_sub(dr)..=kk * nr + (r + dr).min(nr - 1)]
                        .fill(0);
                }
            }
            assert!(n > 1, "band {k0}..={k1}: {n} peaks");
            assert_eq!(
                &out[..n],
                &expected[..],
                "band {k0}..={k1}, smoothing {smoothing}"
            );
            let differing = ws
                .acc
                .iter()
                .zip(&reference.acc)
                .filter(|(a, b)| a != b)
                .count();
            assert_eq!(
                differing, 0,
                "band {k0}..={k1}, smoothing {smoothing}: cells cleared differently"
            );
        }
    }
}

/// `find_lines` returns the drawn lines strongest first, separated, and stops when no vote
/// is left; its first line is `find_line`'s.
#[test]
fn find_lines_returns_separate_lines_strongest_first() {
    let mut ws = HoughWorkspace::new(320, 240, HoughParams::default()).unwrap();
    // Two `/` lines: x = 200 − 0.6·(y − 100) over 140 rows and x = 100 − 0.5·(y − 100) over
    // 80 rows (weaker), both θ > 0.
    let mut pts: Vec<Point> = (100..240)
        .map(|y| Point::new(200.0 - 0.6 * f64::from(y - 100), f64::from(y)))
        .collect();
    pts.extend((100..180).map(|y| Point::new(100.0 - 0.5 * f64::from(y - 100), f64::from(y))));
    let band = AngleBand::LEFT_LANE;
    let best = ws.find_line(&pts, &band).unwrap();
    let none = HoughLine {
        rho_px: 0.0,
        theta_rad: 0.0,
        votes: 0,
    };
    let mut out = [none; 6];
    let n = ws.find_lines(&pts, &band, 3.0, 8.0, &mut out).unwrap();
    assert!(n >= 2, "{n} lines");
    assert_eq!(out[0], best);
    assert!(out[0].votes >= out[1].votes);
    let at = |l: &HoughLine, y: f64| l.col_at_row(y).unwrap();
    assert!((at(&out[0], 200.0) - 140.0).abs() < 1.0, "{:?}", out[0]);
    // The second line is the weaker drawn one, not a near copy of the first.
    assert!((at(&out[1], 150.0) - 75.0).abs() < 1.0, "{:?}", out[1]);
    for l in &out[..n] {
        assert!(band.contains_deg(l.theta_deg()));
    }
    // Two points only: at most as many lines as there are votes, never an error.
    let two = [Point::new(10.0, 10.0), Point::new(20.0, 30.0)];
    let k = ws.find_lines(&two, &band, 3.0, 8.0, &mut out).unwrap();
    assert!((1..=6).contains(&k));
    assert!(ws.find_lines(&pts, &band, -1.0, 8.0, &mut out).is_err());
}

/// The three-point vertex formula is exact on a sampled parabola and clamps outside ±½.
#[test]
fn parabolic_offset_recovers_the_vertex() {
    for d in [-0.45, -0.2, 0.0, 0.13, 0.5] {
        let f = |x: f64| 10.0 - 3.0 * (x - d) * (x - d);
        assert!((parabolic_offset(f(-1.0), f(0.0), f(1.0)) - d).abs() < 1e-12);
    }
    assert_eq!(parabolic_offset(0.0, 1.0, 5.0), 0.0); // not a maximum: convex → no shift
    assert_eq!(parabolic_offset(1.0, 1.0, 1.0), 0.0);
    assert_eq!(parabolic_offset(0.0, 1.0, 1.9), 0.5); // vertex beyond the bin → clamped
}

/// Every in-image point (corners included) votes exactly once per θ bin of the band,
/// also across vote-chunk boundaries and for iterator inputs.
#[test]
fn each_point_votes_once_per_theta_bin() {
    let mut ws = HoughWorkspace::new(320, 240, HoughParams::default()).unwrap();
    let band = AngleBand::new(-90.0, 90.0);
    let (k0, k1) = ws.band_bins(&band).unwrap();
    assert_eq!((k0, k1), (0, 359));
    let corners = [
        Point::new(-0.5, -0.5),
        Point::new(319.5, -0.5),
        Point::new(-0.5, 239.5),
        Point::new(319.5, 239.5),
    ];
    for n in [4, VOTE_CHUNK, VOTE_CHUNK + 1, 2 * VOTE_CHUNK + 3] {
        // Cycle the corners and the centre through n points, fed as an iterator.
        let pts = (0..n).map(|i| {
            corners
                .get(i % 5)
                .copied()
                .unwrap_or(Point::new(160.0, 120.0))
        });
        ws.vote(pts, k0, k1);
        let nr = ws.rho_bins;
        for k in k0..=k1 {
            let total: u32 = ws.acc[k * nr..(k + 1) * nr].iter().sum();
            assert_eq!(total as usize, n, "θ bin {k}, {n} points");
        }
    }
}
