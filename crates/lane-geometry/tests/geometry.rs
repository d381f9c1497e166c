//! Camera, homography and ego-lane maths checked against independent forms: ray–plane
//! intersection, the DLT from four pairs, finite differences, exact straight-lane geometry,
//! rendered arcs and Monte Carlo.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use lane_geometry::{
    ArcRoad, EgoGeometry, EgoLaneEstimator, FitRows, GeometryError, Homography, Intrinsics,
    Mounting, PinholeCamera,
};
use nalgebra::{Matrix3, Matrix4, SMatrix, Vector3, Vector4};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

fn robot_camera(roll_rad: f64, yaw_rad: f64) -> PinholeCamera {
    PinholeCamera::new(
        Intrinsics {
            focal_length_px: 300.0,
            principal_point_px: [159.5, 119.5],
        },
        Mounting {
            height_m: 0.3,
            pitch_down_rad: 0.2,
            roll_rad,
            yaw_rad,
        },
    )
    .unwrap()
}

fn highway_camera() -> PinholeCamera {
    PinholeCamera::new(
        Intrinsics {
            focal_length_px: 385.0,
            principal_point_px: [159.5, 119.5],
        },
        Mounting {
            height_m: 1.4,
            pitch_down_rad: 0.08,
            roll_rad: 0.0,
            yaw_rad: 0.0,
        },
    )
    .unwrap()
}

/// Least-squares image parabola `u = a1 v² + a2 v + a3` through the image of a mark, sampled
/// uniformly over the image rows where the mark is between `s_range.0` and `s_range.1` metres
/// along the road (as the tracker samples edge pixels row by row).
fn image_parabola(h: &Homography, road: &ArcRoad, n_m: f64, s_range: (f64, f64)) -> [f64; 3] {
    let row_of = |s: f64| h.ground_to_image(road.point(s, n_m)).unwrap()[1];
    let (v_near, v_far) = (row_of(s_range.0), row_of(s_range.1));
    let mut n = Matrix3::<f64>::zeros();
    let mut b = Vector3::<f64>::zeros();
    for i in 0..=200 {
        let v = v_far + (v_near - v_far) * f64::from(i) / 200.0;
        // Rows decrease with distance: bisect s for the mark point on row v.
        let (mut lo, mut hi) = (s_range.0, s_range.1);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if row_of(mid) > v { lo = mid } else { hi = mid }
        }
        let [u, v] = h.ground_to_image(road.point(0.5 * (lo + hi), n_m)).unwrap();
        let phi = Vector3::new(v * v, v, 1.0);
        n += phi * phi.transpose();
        b += phi * u;
    }
    let a = n.lu().solve(&b).unwrap();
    [a[0], a[1], a[2]]
}

fn road(d: f64, psi: f64, kappa: f64, w: f64) -> ArcRoad {
    ArcRoad {
        geometry: EgoGeometry {
            lateral_offset_m: d,
            heading_rad: psi,
            curvature_per_m: kappa,
            lane_width_m: w,
        },
    }
}

#[test]
fn homography_equals_ray_plane_intersection_and_projection() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    for (roll, yaw) in [(0.0, 0.0), (0.05, -0.1), (-0.1, 0.2)] {
        let cam = robot_camera(roll, yaw);
        let h = cam.homography().unwrap();
        let c = Vector3::new(0.0, 0.0, -cam.mounting().height_m);
        let mut checked = 0;
        for _ in 0..200 {
            let px = [rng.random_range(0.0..320.0), rng.random_range(0.0..240.0)];
            let ray = cam.ray(px);
            if ray.z <= 1e-3 {
                continue; // at or above the horizon
            }
            // Independent form: intersect the viewing ray with the plane Z = 0.
            let t = -c.z / ray.z;
            let p = c + ray * t;
            let g = h.image_to_ground(px).unwrap();
            assert!((g[0] - p.x).abs() < 1e-9 * (1.0 + p.x.abs()), "{g:?} {p:?}");
            assert!((g[1] - p.y).abs() < 1e-9 * (1.0 + p.y.abs()), "{g:?} {p:?}");
            let back = cam.project([p.x, p.y, 0.0]).unwrap();
            let via_h = h.ground_to_image([p.x, p.y]).unwrap();
            for k in 0..2 {
                assert!((back[k] - px[k]).abs() < 1e-7);
                assert!((via_h[k] - px[k]).abs() < 1e-7);
            }
            checked += 1;
        }
        assert!(checked > 100, "{checked}");
        // Rows above the horizon are refused.
        let hz = cam.horizon_row_px(160.0);
        assert!(h.image_to_ground([160.0, hz - 2.0]).is_err());
        assert!(h.image_to_ground([160.0, hz + 2.0]).is_ok());
    }
}

#[test]
fn four_point_pairs_reproduce_the_camera_homography() {
    for cam in [robot_camera(0.03, -0.05), highway_camera()] {
        let h = cam.homography().unwrap();
        let scale = cam.mounting().height_m;
        let ground = [
            [3.0 * scale, -2.0 * scale],
            [3.0 * scale, 2.0 * scale],
            [9.0 * scale, -3.0 * scale],
            [9.0 * scale, 2.5 * scale],
        ];
        let image = ground.map(|g| h.ground_to_image(g).unwrap());
        let h4 = Homography::from_point_pairs(&image, &ground).unwrap();
        for g in [[4.0 * scale, 0.3 * scale], [12.0 * scale, -scale]] {
            let a = h.ground_to_image(g).unwrap();
            let b = h4.ground_to_image(g).unwrap();
            assert!((a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6);
            let back = h4.image_to_ground(a).unwrap();
            assert!((back[0] - g[0]).abs() < 1e-8 * g[0].abs().max(1.0));
            assert!((back[1] - g[1]).abs() < 1e-8 * g[0].abs().max(1.0));
        }
    }
}

#[test]
fn degenerate_point_pairs_are_refused() {
    let image = [
        [10.0, 200.0],
        [300.0, 200.0],
        [100.0, 150.0],
        [220.0, 150.0],
    ];
    let collinear = [[1.0, 0.0], [2.0, 0.0], [3.0, 0.0], [2.0, 1.0]];
    assert!(matches!(
        Homography::from_point_pairs(&image, &collinear),
        Err(GeometryError::DegenerateHomography { .. })
    ));
    let mut nan = image;
    nan[2][1] = f64::NAN;
    assert!(matches!(
        Homography::from_point_pairs(&nan, &[[1.0, -1.0], [1.0, 1.0], [3.0, -1.0], [3.0, 1.0]]),
        Err(GeometryError::NonFinite { .. })
    ));
    assert!(Homography::from_ground_to_image(&Matrix3::zeros()).is_err());
}

#[test]
fn invalid_camera_parameters_are_named() {
    let i = Intrinsics {
        focal_length_px: 300.0,
        principal_point_px: [160.0, 120.0],
    };
    let m = Mounting {
        height_m: 0.3,
        pitch_down_rad: 0.2,
        roll_rad: 0.0,
        yaw_rad: 0.0,
    };
    let cases: [(&str, Intrinsics, Mounting); 5] = [
        (
            "focal_length_px",
            Intrinsics {
                focal_length_px: 0.0,
                ..i
            },
            m,
        ),
        (
            "principal_point_px[1]",
            Intrinsics {
                principal_point_px: [1.0, f64::NAN],
                ..i
            },
            m,
        ),
        (
            "height_m",
            i,
            Mounting {
                height_m: -1.0,
                ..m
            },
        ),
        (
            "pitch_down_rad",
            i,
            Mounting {
                pitch_down_rad: 2.0,
                ..m
            },
        ),
        (
            "yaw_rad",
            i,
            Mounting {
                yaw_rad: f64::INFINITY,
                ..m
            },
        ),
    ];
    for (name, ii, mm) in cases {
        match PinholeCamera::new(ii, mm) {
            Err(GeometryError::InvalidParameter { field, .. }) => assert_eq!(field, name),
            other => panic!("{name}: {other:?}"),
        }
    }
    let h = robot_camera(0.0, 0.0).homography().unwrap();
    assert!(matches!(
        EgoLaneEstimator::new(h, 2.0, 1.0),
        Err(GeometryError::InvalidParameter {
            field: "lookahead_far_m",
            ..
        })
    ));
    assert!(matches!(
        EgoLaneEstimator::new(h, 0.0, 1.0),
        Err(GeometryError::InvalidParameter {
            field: "lookahead_near_m",
            ..
        })
    ));
    // A camera looking nearly straight up sees no ground ahead.
    let up = PinholeCamera::new(
        i,
        Mounting {
            pitch_down_rad: -1.4,
            ..m
        },
    )
    .unwrap();
    assert!(matches!(
        EgoLaneEstimator::new(up.homography().unwrap(), 1.0, 3.0),
        Err(GeometryError::BeyondHorizon { .. })
    ));
}

#[test]
fn image_to_ground_jacobian_matches_finite_differences() {
    let h = robot_camera(0.04, -0.07).homography().unwrap();
    for px in [[40.0, 200.0], [160.0, 120.0], [300.0, 230.0]] {
        let (_, j) = h.image_to_ground_with_jacobian(px).unwrap();
        let e = 1e-4;
        for c in 0..2 {
            let (mut p, mut m) = (px, px);
            p[c] += e;
            m[c] -= e;
            let (gp, gm) = (h.image_to_ground(p).unwrap(), h.image_to_ground(m).unwrap());
            for r in 0..2 {
                let fd = (gp[r] - gm[r]) / (2.0 * e);
                assert!(
                    (fd - j[(r, c)]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "{r}{c}: {fd} vs {}",
                    j[(r, c)]
                );
            }
        }
    }
}

#[test]
fn straight_lanes_are_recovered_exactly_for_any_mounting() {
    // Straight marks are straight image lines (a1 = 0), so the parabola model is exact and so is
    // the recovered geometry.
    for (roll, yaw) in [(0.0, 0.0), (0.05, 0.08), (-0.08, -0.04)] {
        let h = robot_camera(roll, yaw).homography().unwrap();
        let ego = EgoLaneEstimator::new(h, 0.7, 2.0).unwrap();
        for (d, psi, w) in [(0.0, 0.0, 0.8), (0.12, -0.1, 0.8), (-0.2, 0.15, 0.6)] {
            let r = road(d, psi, 0.0, w);
            let left = image_parabola(&h, &r, -0.5 * w, (0.6, 2.5));
            let right = image_parabola(&h, &r, 0.5 * w, (0.6, 2.5));
            assert!(left[0].abs() < 1e-9 && right[0].abs() < 1e-9);
            let g = ego.geometry(&left, &right).unwrap();
            assert!((g.lateral_offset_m - d).abs() < 1e-7, "{g:?}");
            assert!((g.heading_rad - psi).abs() < 1e-7, "{g:?}");
            assert!(g.curvature_per_m.abs() < 1e-6, "{g:?}");
            assert!((g.lane_width_m - w).abs() < 1e-7, "{g:?}");
        }
    }
}

#[test]
fn curved_lanes_are_recovered_within_the_model_error() {
    // Arcs are not image parabolas: a ground curve maps to the image with a term in 1/depth that
    // a parabola in the row only approximates, so the curvature comes out low and the heading
    // absorbs part of it. Measured model error (this test's cases): robot scale, look-ahead
    // 0.55–1.0 m, curvature 10–14 % low, heading off by ≤ 0.12·|κ|·1 m, offset ≤ 4 mm.
    let h = robot_camera(0.0, 0.0).homography().unwrap();
    let ego = EgoLaneEstimator::new(h, 0.55, 1.0).unwrap();
    for (d, psi, kappa) in [
        (0.05, 0.05, 0.02),
        (0.05, 0.05, 0.05),
        (-0.1, -0.08, -0.08),
        (0.0, 0.0, 0.1),
    ] {
        let r = road(d, psi, kappa, 0.8);
        let left = image_parabola(&h, &r, -0.4, (0.5, 1.1));
        let right = image_parabola(&h, &r, 0.4, (0.5, 1.1));
        let g = ego.geometry(&left, &right).unwrap();
        assert!((g.lateral_offset_m - d).abs() < 0.01, "{g:?}");
        assert!(
            (g.heading_rad - psi).abs() < 0.15 * kappa.abs() + 1e-6,
            "{g:?}"
        );
        assert!(
            (g.curvature_per_m - kappa).abs() < 0.2 * kappa.abs(),
            "{g:?}"
        );
        assert!((g.lane_width_m - 0.8).abs() < 0.01, "{g:?}");
    }
    // Highway scale, look-ahead 7–20 m, gentle curves: the same effect, larger in metres
    // (measured: curvature 37 % low, heading off by 4.8·|κ|·1 m, offset by 27·|κ|·1 m²).
    let h = highway_camera().homography().unwrap();
    let ego = EgoLaneEstimator::new(h, 7.0, 20.0).unwrap();
    for (d, psi, kappa) in [(0.3, 0.02, 1.0 / 400.0), (-0.5, -0.01, -1.0 / 1000.0)] {
        let r = road(d, psi, kappa, 3.7);
        let left = image_parabola(&h, &r, -1.85, (6.0, 22.0));
        let right = image_parabola(&h, &r, 1.85, (6.0, 22.0));
        let g = ego.geometry(&left, &right).unwrap();
        assert!((g.lateral_offset_m - d).abs() < 30.0 * kappa.abs(), "{g:?}");
        assert!((g.heading_rad - psi).abs() < 6.0 * kappa.abs(), "{g:?}");
        assert!(
            (g.curvature_per_m - kappa).abs() < 0.5 * kappa.abs(),
            "{g:?}"
        );
        assert!((g.lane_width_m - 3.7).abs() < 0.02, "{g:?}");
    }
}

/// Central differences with a step per coefficient matched to its scale (a1 ~ 1/px, a3 ~ px).
fn fd_jacobian(ego: &EgoLaneEstimator, l: [f64; 3], r: [f64; 3]) -> SMatrix<f64, 4, 6> {
    let steps = [1e-8, 1e-5, 1e-3];
    let mut j = SMatrix::<f64, 4, 6>::zeros();
    for c in 0..6 {
        let (mut lp, mut rp, mut lm, mut rm) = (l, r, l, r);
        let e = steps[c % 3];
        if c < 3 {
            lp[c] += e;
            lm[c] -= e;
        } else {
            rp[c - 3] += e;
            rm[c - 3] -= e;
        }
        let gp = ego.geometry(&lp, &rp).unwrap().to_vector();
        let gm = ego.geometry(&lm, &rm).unwrap().to_vector();
        j.set_column(c, &((gp - gm) / (2.0 * e)));
    }
    j
}

#[test]
fn ego_jacobian_matches_finite_differences() {
    let cases = [
        (
            robot_camera(0.0, 0.0),
            0.7,
            2.0,
            road(0.1, 0.06, 0.2, 0.8),
            (0.6, 2.3),
            0.4,
        ),
        (
            robot_camera(0.05, -0.08),
            0.7,
            2.0,
            road(-0.15, -0.1, -0.3, 0.8),
            (0.6, 2.3),
            0.4,
        ),
        (
            highway_camera(),
            8.0,
            30.0,
            road(0.4, 0.03, 1.0 / 300.0, 3.7),
            (7.0, 35.0),
            1.85,
        ),
    ];
    for (cam, near, far, r, range, half) in cases {
        let h = cam.homography().unwrap();
        let ego = EgoLaneEstimator::new(h, near, far).unwrap();
        let left = image_parabola(&h, &r, -half, range);
        let right = image_parabola(&h, &r, half, range);
        let (_, j) = ego.geometry_with_jacobian(&left, &right).unwrap();
        let fd = fd_jacobian(&ego, left, right);
        for row in 0..4 {
            let scale = j.row(row).abs().max() + fd.row(row).abs().max();
            for c in 0..6 {
                assert!(
                    (j[(row, c)] - fd[(row, c)]).abs() < 1e-5 * scale,
                    "({row},{c}): analytic {} vs fd {}",
                    j[(row, c)],
                    fd[(row, c)]
                );
            }
        }
    }
}

#[test]
fn propagated_covariance_matches_monte_carlo() {
    // Perturb both lanes' coefficients with their covariance and compare the sample covariance of
    // the outputs with J·diag(P_L, P_R)·Jᵀ (the linearisation is good at tracker-sized errors).
    let h = robot_camera(0.02, 0.03).homography().unwrap();
    let ego = EgoLaneEstimator::new(h, 0.7, 2.0).unwrap();
    let r = road(0.08, -0.05, 0.15, 0.8);
    let left = image_parabola(&h, &r, -0.4, (0.6, 2.3));
    let right = image_parabola(&h, &r, 0.4, (0.6, 2.3));
    // A covariance shaped like a converged KIF's: built in the normalised rows u = (v − 180)/60
    // (σ 0.3 px per coefficient, some correlation), mapped exactly to pixels.
    let (c, s) = (180.0, 60.0);
    let t = Matrix3::new(
        1.0 / (s * s),
        0.0,
        0.0,
        -2.0 * c / (s * s),
        1.0 / s,
        0.0,
        c * c / (s * s),
        -c / s,
        1.0,
    );
    let pu = Matrix3::new(0.09, 0.02, -0.03, 0.02, 0.09, 0.01, -0.03, 0.01, 0.09);
    let p = t * pu * t.transpose();
    let lane = ego.estimate(&left, &p, &right, &p).unwrap();
    let chol = pu.cholesky().unwrap().l();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let n = 4000;
    let mut mean = Vector4::<f64>::zeros();
    let mut outer = Matrix4::<f64>::zeros();
    let mut samples = Vec::with_capacity(n);
    for _ in 0..n {
        let mut draw = |theta: [f64; 3]| {
            let z = Vector3::from_fn(|_, _| StandardNormal.sample(&mut rng));
            let d = t * (chol * z);
            [theta[0] + d[0], theta[1] + d[1], theta[2] + d[2]]
        };
        let (l, rr) = (draw(left), draw(right));
        let g = ego.geometry(&l, &rr).unwrap().to_vector();
        mean += g / n as f64;
        samples.push(g);
    }
    for g in &samples {
        outer += (g - mean) * (g - mean).transpose() / (n - 1) as f64;
    }
    for i in 0..4 {
        let ratio = (outer[(i, i)] / lane.covariance[(i, i)]).sqrt();
        // σ of a sample σ from 4000 draws is about 1.1 %; allow 5 %.
        assert!(
            (ratio - 1.0).abs() < 0.05,
            "output {i}: MC/propagated σ = {ratio}"
        );
        assert!((lane.sigma.to_vector()[i] - lane.covariance[(i, i)].sqrt()).abs() < 1e-15);
    }
}

#[test]
fn bad_lane_input_is_an_error_not_a_panic() {
    let h = robot_camera(0.0, 0.0).homography().unwrap();
    let ego = EgoLaneEstimator::new(h, 0.7, 2.0).unwrap();
    let ok = [0.0, -1.0, 300.0];
    let p = Matrix3::identity();
    assert!(matches!(
        ego.geometry(&[f64::NAN, 0.0, 0.0], &ok),
        Err(GeometryError::NonFinite { .. })
    ));
    let mut bad = p;
    bad[(1, 2)] = f64::INFINITY;
    assert!(matches!(
        ego.estimate(&ok, &bad, &ok, &p),
        Err(GeometryError::NonFinite { .. })
    ));
    // A mark thrown far to the side: a finite geometry or an error, never a panic.
    if let Ok(g) = ego.geometry(&[0.0, 0.0, -1.0e7], &ok) {
        assert!(g.to_vector().iter().all(|v| v.is_finite()), "{g:?}");
    }
    // Random coefficients never panic: each gives a finite estimate (geometry, σ, covariance)
    // or an error (these draws all give estimates).
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let (mut finite, mut refused) = (0, 0);
    for _ in 0..2000 {
        let l = [
            rng.random_range(-1.0..1.0),
            rng.random_range(-50.0..50.0),
            rng.random_range(-1e4..1e4),
        ];
        match ego.estimate(&l, &p, &ok, &p) {
            Ok(lane) => {
                assert!(
                    lane.geometry.to_vector().iter().all(|v| v.is_finite())
                        && lane.sigma.to_vector().iter().all(|v| v.is_finite())
                        && lane.covariance.iter().all(|v| v.is_finite()),
                    "a non-finite estimate for {l:?}: {lane:?}"
                );
                finite += 1;
            }
            Err(_) => refused += 1,
        }
    }
    assert!(finite > 1000, "{finite} finite, {refused} refused");
}

/// Rows `[far, near]` of a mark's image over a ground range, as `image_parabola` fits them.
fn fitted_rows(h: &Homography, road: &ArcRoad, n_m: f64, s_range: (f64, f64)) -> FitRows {
    let row_of = |s: f64| h.ground_to_image(road.point(s, n_m)).unwrap()[1];
    FitRows::uniform(row_of(s_range.1), row_of(s_range.0))
}

#[test]
fn the_forward_model_removes_the_image_parabola_model_error() {
    // The same arcs as above, now told over which rows the parabolas were fitted (step 5):
    // the model error of the image parabola is gone to within the forward model's sampling.
    for (cam, near, far, range, w, cases) in [
        (
            robot_camera(0.0, 0.0),
            0.55,
            1.0,
            (0.5, 1.1),
            0.8,
            vec![
                (0.05, 0.05, 0.02),
                (0.05, 0.05, 0.05),
                (-0.1, -0.08, -0.08),
                (0.0, 0.0, 0.1),
            ],
        ),
        (
            highway_camera(),
            7.0,
            20.0,
            (6.0, 22.0),
            3.7,
            vec![(0.3, 0.02, 1.0 / 400.0), (-0.5, -0.01, -1.0 / 1000.0)],
        ),
    ] {
        let h = cam.homography().unwrap();
        let ego = EgoLaneEstimator::new(h, near, far).unwrap();
        for (d, psi, kappa) in cases {
            let r = road(d, psi, kappa, w);
            let left = image_parabola(&h, &r, -0.5 * w, range);
            let right = image_parabola(&h, &r, 0.5 * w, range);
            let fit = [
                fitted_rows(&h, &r, -0.5 * w, range),
                fitted_rows(&h, &r, 0.5 * w, range),
            ];
            let plain = ego.geometry(&left, &right).unwrap();
            let (g, j) = ego
                .geometry_with_jacobian_fitted(&left, &right, &fit)
                .unwrap();
            let errs = [
                g.lateral_offset_m - d,
                g.heading_rad - psi,
                g.curvature_per_m - kappa,
                g.lane_width_m - w,
            ];
            eprintln!(
                "κ {kappa}: heading error {:.2e} rad (uncorrected {:.2e}), curvature {:.2e} ({:.2e}), offset {:.2e} ({:.2e})",
                errs[1],
                plain.heading_rad - psi,
                errs[2],
                plain.curvature_per_m - kappa,
                errs[0],
                plain.lateral_offset_m - d
            );
            assert!(
                errs[1].abs() < 0.1 * (plain.heading_rad - psi).abs() + 1e-6,
                "{errs:?}"
            );
            assert!(errs[2].abs() < 0.05 * kappa.abs(), "{errs:?}");
            assert!(
                errs[0].abs() < 0.2 * (plain.lateral_offset_m - d).abs() + 1e-5,
                "{errs:?}"
            );
            assert!(errs[3].abs() < 0.01 * w, "{errs:?}");
            // The Jacobian of the corrected map against central differences.
            let base = [left, right];
            for c in 0..6 {
                let step = [1e-7, 1e-5, 1e-3][c % 3];
                let mut p = base;
                let mut m = base;
                p[c / 3][c % 3] += step;
                m[c / 3][c % 3] -= step;
                let gp = ego
                    .geometry_with_jacobian_fitted(&p[0], &p[1], &fit)
                    .unwrap()
                    .0
                    .to_vector();
                let gm = ego
                    .geometry_with_jacobian_fitted(&m[0], &m[1], &fit)
                    .unwrap()
                    .0
                    .to_vector();
                for row in 0..4 {
                    let fd = (gp[row] - gm[row]) / (2.0 * step);
                    let scale = j.row(row).iter().fold(0.0f64, |a, v| a.max(v.abs())) * 1e-6;
                    assert!(
                        (fd - j[(row, c)]).abs() <= 0.03 * fd.abs() + scale,
                        "κ {kappa}: ∂{row}/∂{c}: FD {fd:e}, J {:e}",
                        j[(row, c)]
                    );
                }
            }
        }
    }
}
