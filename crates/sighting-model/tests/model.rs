//! Behaviour of the nonlinear model: zero error, directions of simple errors, camera frame,
//! errors on bad geometry, noise statistics.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod common;

use common::{paper_pose, paper_start, random_geometry};
use nalgebra::{Matrix3, Rotation3, SVector, Vector2, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sighting_model::{
    Geodetic, Landmark, NavPose, SightingError, add_sighting_noise, check_geometry, line_of_sight,
    paper_landmarks, sighting_offset_m, sighting_offsets3_m, true_pose_from_errors,
};

/// A landmark `dist_m` away from `from` along `bearing_deg` (approximate great-circle step) at
/// altitude `alt_m`.
fn landmark_at(from: &Geodetic, bearing_deg: f64, dist_m: f64, alt_m: f64) -> Landmark {
    let b = bearing_deg.to_radians();
    let r = 6.37e6;
    Landmark::new(
        0,
        Geodetic {
            lat_rad: from.lat_rad + dist_m * b.cos() / r,
            lon_rad: from.lon_rad + dist_m * b.sin() / (r * from.lat_rad.cos()),
            alt_m,
        },
    )
    .unwrap()
}

#[test]
fn zero_error_gives_zero_offsets() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for i in 0..100 {
        let (pose, l) = random_geometry(&mut rng, i);
        let z = sighting_offset_m(&pose, &pose, &l).unwrap();
        assert!(z.amax() < 1e-8, "geometry {i}: {z}");
    }
    let z = sighting_offsets3_m(&paper_pose(), &paper_pose(), &paper_landmarks()).unwrap();
    assert!(z.amax() < 1e-8, "{z}");
}

#[test]
fn north_error_with_landmark_due_east_moves_it_left_by_the_error() {
    // Computed position 20 m north of the truth (δp_N = +20 m). Looking east from the truth
    // with the boresight parallel to the computed line of sight, the landmark lies 20 m north
    // of the boresight, i.e. to the LEFT (image-right w is south when looking east): w ≈ −20 m.
    let computed = NavPose {
        position: paper_start(),
        c_b_n: Rotation3::identity(),
    };
    let l = landmark_at(&computed.position, 90.0, 8_000.0, 6_000.0); // level, due east
    let truth = true_pose_from_errors(&computed, &Vector3::new(20.0, 0.0, 0.0), &Vector3::zeros());
    let z = sighting_offset_m(&truth, &computed, &l).unwrap();
    assert!((z.x + 20.0).abs() < 0.2, "w = {}", z.x);
    assert!(z.y.abs() < 0.2, "h = {}", z.y);
}

#[test]
fn north_error_with_landmark_due_north_below_moves_it_up_in_the_image() {
    // Landmark 10 km north, 6 km below (depression ε = atan(0.6)). Truth 20 m south of the
    // computed position: seen from farther back at the same pointing angle, the landmark lies
    // above the image centre by 20 m · sin ε (h is image-DOWN, so h ≈ −20 sin ε), w ≈ 0.
    let computed = NavPose {
        position: paper_start(),
        c_b_n: Rotation3::identity(),
    };
    let l = landmark_at(&computed.position, 0.0, 10_000.0, 0.0);
    let eps = line_of_sight(&computed.position, &l)
        .unwrap()
        .depression_rad();
    assert!((eps - 0.6_f64.atan()).abs() < 0.01);
    let truth = true_pose_from_errors(&computed, &Vector3::new(20.0, 0.0, 0.0), &Vector3::zeros());
    let z = sighting_offset_m(&truth, &computed, &l).unwrap();
    assert!(
        (z.y + 20.0 * eps.sin()).abs() < 0.2,
        "h = {}, expected {}",
        z.y,
        -20.0 * eps.sin()
    );
    assert!(z.x.abs() < 0.2, "w = {}", z.x);
}

#[test]
fn heading_error_moves_the_landmark_sideways_by_horizontal_range_times_angle() {
    // ψ = (0, 0, ψ_D): C̃ = exp(−[ψ×]) C_b^c, the INS heading is ψ_D too small, so the camera
    // really points ψ_D further clockwise (to the right) and the landmark appears to the left
    // by d₀ ψ_D.
    let computed = paper_pose();
    let l = paper_landmarks()[0];
    let d0 = line_of_sight(&computed.position, &l)
        .unwrap()
        .horizontal_range_m;
    let psi_d = 2e-3;
    let truth = true_pose_from_errors(&computed, &Vector3::zeros(), &Vector3::new(0.0, 0.0, psi_d));
    let z = sighting_offset_m(&truth, &computed, &l).unwrap();
    assert!(
        (z.x + d0 * psi_d).abs() < 1e-2 * d0 * psi_d,
        "w = {}, d0 ψ = {}",
        z.x,
        d0 * psi_d
    );
    assert!(z.y.abs() < 1e-2 * d0 * psi_d, "h = {}", z.y);
}

#[test]
fn offsets_are_the_perpendicular_offset_on_the_plane_through_the_landmark() {
    // Independent construction in ECEF: boresight from the computed state, realised by the true
    // attitude; intersect the plane through the landmark normal to it.
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    for i in 0..50 {
        let (computed, l) = random_geometry(&mut rng, i);
        let dp = Vector3::new(35.0, -20.0, 12.0);
        let psi = Vector3::new(1e-3, -2e-3, 3e-3);
        let truth = true_pose_from_errors(&computed, &dp, &psi);
        let c_e = |g: &Geodetic| ins_errors::earth::ned_from_ecef(g.lat_rad, g.lon_rad);
        let x_c = ins_errors::earth::geodetic_to_ecef(&computed.position);
        let x_t = ins_errors::earth::geodetic_to_ecef(&truth.position);
        let los_c_ecef = l.ecef_m() - x_c;
        // Commanded camera axes in ECEF (for the computed state), then in body axes.
        let los_ned = c_e(&computed.position) * los_c_ecef;
        let b = los_ned.normalize();
        let w_axis = Vector3::z().cross(&b).normalize(); // horizontal, right of b (z = down)
        let h_axis = b.cross(&w_axis);
        let cam_ned = Matrix3::from_columns(&[w_axis, h_axis, b]);
        let cam_body = computed.c_b_n.matrix().transpose() * cam_ned;
        // Real camera axes in ECEF: body → true NED → ECEF.
        let cam_ecef = c_e(&truth.position).transpose() * truth.c_b_n.matrix() * cam_body;
        let r = l.ecef_m() - x_t;
        let bore = cam_ecef.column(2);
        let pierce = bore * bore.dot(&r);
        let offset = r - pierce;
        let expected = Vector2::new(
            offset.dot(&cam_ecef.column(0)),
            offset.dot(&cam_ecef.column(1)),
        );
        let z = sighting_offset_m(&truth, &computed, &l).unwrap();
        assert!(
            (z - expected).amax() < 1e-6,
            "geometry {i}: {z} vs {expected}"
        );
    }
}

#[test]
fn camera_axes_are_right_handed_orthonormal_with_horizontal_w() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for i in 0..100 {
        let (pose, l) = random_geometry(&mut rng, i);
        let los = line_of_sight(&pose.position, &l).unwrap();
        let c = los.camera_axes_ned();
        assert!((c.transpose() * c - Matrix3::identity()).amax() < 1e-14);
        assert!((c.determinant() - 1.0).abs() < 1e-14);
        assert_eq!(c[(2, 0)], 0.0, "w axis horizontal");
        assert!(
            (c.column(2) - los.los_ned_m / los.range_m).amax() < 1e-15,
            "boresight = LOS"
        );
        // Looking along the boresight with down = +z, image-right is e_w: (b × e_w)·down ≥ 0
        // means e_h has a non-negative down component (image down points towards the ground).
        assert!(c[(2, 1)] >= 0.0);
    }
}

#[test]
fn three_landmark_offsets_stack_the_single_ones() {
    let computed = paper_pose();
    let truth = true_pose_from_errors(
        &computed,
        &Vector3::new(40.0, -25.0, 10.0),
        &Vector3::new(1e-3, 2e-3, -3e-3),
    );
    let ls = paper_landmarks();
    let z3 = sighting_offsets3_m(&truth, &computed, &ls).unwrap();
    for (i, l) in ls.iter().enumerate() {
        assert_eq!(
            z3.fixed_rows::<2>(2 * i),
            sighting_offset_m(&truth, &computed, l).unwrap()
        );
    }
}

#[test]
fn degenerate_geometries_are_typed_errors() {
    let pose = paper_pose();
    // Landmark at the vehicle position.
    let here = Landmark::new(4, pose.position).unwrap();
    assert!(matches!(
        sighting_offset_m(&pose, &pose, &here),
        Err(SightingError::RangeTooShort { landmark: 4, .. })
    ));
    // Landmark straight below.
    let below = Landmark::new(
        5,
        Geodetic {
            alt_m: 0.0,
            ..pose.position
        },
    )
    .unwrap();
    assert!(matches!(
        sighting_jacobian_err(&pose.position, &below),
        Some(SightingError::VerticalLineOfSight { landmark: 5, .. })
    ));
    // check_geometry with a minimum range: 50 m away is too close for 100 m.
    let near = landmark_at(&pose.position, 45.0, 50.0, pose.position.alt_m);
    match check_geometry(&pose.position, &near, 100.0) {
        Err(SightingError::RangeTooShort {
            range_m,
            min_range_m,
            ..
        }) => {
            assert!((range_m - 50.0).abs() < 1.0 && min_range_m == 100.0)
        }
        other => panic!("expected RangeTooShort, got {other:?}"),
    }
    assert!(check_geometry(&pose.position, &near, 10.0).is_ok());
    assert!(matches!(
        check_geometry(&pose.position, &near, f64::NAN),
        Err(SightingError::InvalidField { ref field, .. }) if field == "min_range_m"
    ));
    // Errors so large the landmark is behind the camera: heading off by ~180° with landmark 0
    // (depression ≈ 26° < 45°, so the reversed boresight points away from it).
    let truth = true_pose_from_errors(&pose, &Vector3::zeros(), &Vector3::new(0.0, 0.0, 3.1));
    assert!(matches!(
        sighting_offset_m(&truth, &pose, &paper_landmarks()[0]),
        Err(SightingError::BehindCamera { landmark: 0, .. })
    ));
    // NaN in a pose.
    let mut bad = pose;
    bad.position.alt_m = f64::NAN;
    assert!(matches!(
        sighting_offset_m(&bad, &pose, &paper_landmarks()[0]),
        Err(SightingError::NonFinite { .. })
    ));
    assert!(matches!(
        Landmark::from_deg(2, 91.0, 0.0, 0.0),
        Err(SightingError::InvalidField { ref field, .. }) if field == "landmarks[2].lat_deg"
    ));
}

fn sighting_jacobian_err(pos: &Geodetic, l: &Landmark) -> Option<SightingError> {
    sighting_model::sighting_jacobian(pos, l).err()
}

#[test]
fn noise_has_the_requested_variance_and_zero_mean() {
    let mut rng = ChaCha8Rng::seed_from_u64(2024);
    let n = 20_000;
    let (mut sum, mut sum2) = (SVector::<f64, 6>::zeros(), SVector::<f64, 6>::zeros());
    for _ in 0..n {
        let mut z = SVector::<f64, 6>::zeros();
        add_sighting_noise(&mut z, 40.0, &mut rng).unwrap();
        sum += z;
        sum2 += z.component_mul(&z);
    }
    for k in 0..6 {
        let mean = sum[k] / n as f64;
        let var = sum2[k] / n as f64 - mean * mean;
        // σ(mean) = √(40/n) ≈ 0.045; σ(var) = 40 √(2/n) ≈ 0.4: 5σ bounds.
        assert!(mean.abs() < 0.23, "axis {k} mean {mean}");
        assert!((var - 40.0).abs() < 2.0, "axis {k} variance {var}");
    }
    // Independent axes: correlation of w and h of the same landmark is ~0.
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut cross = 0.0;
    for _ in 0..n {
        let mut z = Vector2::zeros();
        add_sighting_noise(&mut z, 1.0, &mut rng).unwrap();
        cross += z.x * z.y;
    }
    assert!((cross / n as f64).abs() < 0.04);
}

#[test]
fn noise_variance_zero_disables_and_invalid_is_rejected() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut z = Vector2::new(1.5, -2.5);
    add_sighting_noise(&mut z, 0.0, &mut rng).unwrap();
    assert_eq!(z, Vector2::new(1.5, -2.5));
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        let r = add_sighting_noise(&mut z, bad, &mut rng);
        assert!(
            matches!(r, Err(SightingError::InvalidNoiseVariance { .. })),
            "{bad}"
        );
        assert_eq!(z, Vector2::new(1.5, -2.5));
    }
}
