//! The paper's printed H (eqs. 15–18) against the verified H and the finite differences:
//! establishes, entry by entry, the differences stated in the crate documentation.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod common;

use common::{fd_jacobian, fd_jacobian_with, paper_pose, paper_start, random_geometry};
use ins_errors::earth::{displace_by_ned_m, frame_tilt_rad, pos_err_ned_m, radii_of_curvature_m};
use nalgebra::{Matrix2x3, Matrix3, Rotation3, SMatrix, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sighting_model::{
    Geodetic, Landmark, NavPose, POS_ERR_COL, PSI_COL, PaperAlphaReading as AlphaReading,
    STATE_DIM, line_of_sight, paper_eq15_jacobian3, paper_landmarks, paper_printed_blocks,
    paper_printed_jacobian, paper_printed_jacobian3, sighting_jacobian, sighting_jacobian3,
    true_pose_from_errors,
};

struct Printed {
    h2: Matrix2x3<f64>,
    /// H₃ as printed: entry (1, 2) = −(d₁₁ + d₁₃ tan λ)/(R_E + H).
    h3: Matrix2x3<f64>,
    /// H₃ with the sign of the tan λ term flipped: −(d₁₁ − d₁₃ tan λ)/(R_E + H).
    h3_tan_flipped: Matrix2x3<f64>,
    h4: Matrix2x3<f64>,
}

/// Eqs. 16–18 as evaluated by the library (`paper_printed_blocks`), plus H₃ with the tan λ
/// term's sign flipped: adds 2 d₁₃ tan λ/(R_E + H) to entry (1, 2), d₁₃ = H₄(1, 3).
fn printed(pos: &Geodetic, landmark: &Landmark, reading: AlphaReading) -> Printed {
    let b = paper_printed_blocks(pos, landmark, reading).unwrap();
    let (_, r_e) = radii_of_curvature_m(pos.lat_rad);
    let mut h3_tan_flipped = b.h3_tilt;
    h3_tan_flipped[(0, 1)] += 2.0 * b.h4_att[(0, 2)] * pos.lat_rad.tan() / (r_e + pos.alt_m);
    Printed {
        h2: b.h2_pos,
        h3: b.h3_tilt,
        h3_tan_flipped,
        h4: b.h4_att,
    }
}

fn pos_block(h: &SMatrix<f64, 2, STATE_DIM>) -> Matrix2x3<f64> {
    h.fixed_view::<2, 3>(0, POS_ERR_COL).into()
}
fn psi_block(h: &SMatrix<f64, 2, STATE_DIM>) -> Matrix2x3<f64> {
    h.fixed_view::<2, 3>(0, PSI_COL).into()
}

fn rel_diff(a: &Matrix2x3<f64>, b: &Matrix2x3<f64>) -> f64 {
    (a - b).amax() / b.amax()
}

/// Geometries: the paper's start with its three landmarks, and random ones (skipping
/// landmarks almost due east/west, where the printed β_x, β_y divide by ~0).
fn geometries() -> Vec<(NavPose, Landmark)> {
    let mut v: Vec<_> = paper_landmarks()
        .into_iter()
        .map(|l| (paper_pose(), l))
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(18);
    while v.len() < 60 {
        let (pose, l) = random_geometry(&mut rng, v.len());
        if line_of_sight(&pose.position, &l).unwrap().los_ned_m.x.abs() > 50.0 {
            v.push((pose, l));
        }
    }
    v
}

#[test]
fn printed_h2_and_h4_with_elevation_reading_equal_the_verified_h() {
    for (pose, l) in geometries() {
        let h = sighting_jacobian(&pose.position, &l).unwrap();
        let p = printed(&pose.position, &l, AlphaReading::Elevation);
        assert!(
            rel_diff(&p.h2, &pos_block(&h)) < 1e-9,
            "H2 vs δp block, landmark {}",
            l.id()
        );
        assert!(
            rel_diff(&p.h4, &psi_block(&h)) < 1e-9,
            "H4 vs ψ block, landmark {}",
            l.id()
        );
    }
}

#[test]
fn printed_alpha_read_literally_scales_the_h_row_by_cos_2alpha() {
    for (pose, l) in geometries() {
        let h = sighting_jacobian(&pose.position, &l).unwrap();
        let p = printed(&pose.position, &l, AlphaReading::AsPrinted);
        let eps = line_of_sight(&pose.position, &l).unwrap().depression_rad();
        let k = (2.0 * eps).cos();
        // w row unchanged (no sin α₀ in it)…
        assert!((p.h2.row(0) - h.fixed_view::<1, 3>(0, POS_ERR_COL)).amax() < 1e-9);
        assert!((p.h4.row(0) - h.fixed_view::<1, 3>(0, PSI_COL)).amax() < 1e-9 * h.amax());
        // …h row multiplied by cos 2ε.
        assert!((p.h2.row(1) - k * h.fixed_view::<1, 3>(1, POS_ERR_COL)).amax() < 1e-9);
        assert!((p.h4.row(1) - k * h.fixed_view::<1, 3>(1, PSI_COL)).amax() < 1e-9 * h.amax());
    }
    // At the paper's start point the literal reading weakens or flips the h rows: depression
    // of landmark 1 is below 45°, landmark 2 far above, landmark 3 close to 45°.
    let pos = paper_pose().position;
    let k: Vec<f64> = paper_landmarks()
        .iter()
        .map(|l| (2.0 * line_of_sight(&pos, l).unwrap().depression_rad()).cos())
        .collect();
    assert!(
        k[0] > 0.3 && k[1] < -0.5 && k[2].abs() < 0.2,
        "cos 2ε at start: {k:?}"
    );
}

#[test]
fn printed_h3_is_minus_h4_times_the_frame_tilt_jacobian_up_to_the_tan_lat_sign() {
    for (pose, l) in geometries() {
        let p = printed(&pose.position, &l, AlphaReading::Elevation);
        let mut dtheta_ddp = Matrix3::zeros();
        for k in 0..3 {
            let mut e = Vector3::zeros();
            e[k] = 1.0;
            dtheta_ddp.set_column(
                k,
                &frame_tilt_rad(&e, pose.position.lat_rad, pose.position.alt_m),
            );
        }
        let expected = -p.h4 * dtheta_ddp;
        assert!(
            rel_diff(&p.h3_tan_flipped, &expected) < 1e-12,
            "landmark {}: H3 (tan λ flipped) {} expected {}",
            l.id(),
            p.h3_tan_flipped,
            expected
        );
        // As printed, the (w, δp_E) entry carries +d₁₃ tan λ where the tilt needs −d₁₃ tan λ.
        let diff = p.h3 - expected;
        let (_, r_e) = radii_of_curvature_m(pose.position.lat_rad);
        let d13 = p.h4[(0, 2)];
        let want = -2.0 * d13 * pose.position.lat_rad.tan() / (r_e + pose.position.alt_m);
        assert!((diff[(0, 1)] - want).abs() < 1e-12 * p.h3.amax().max(1e-3));
        assert!(diff[(0, 0)].abs() + diff.row(1).amax() < 1e-12 * p.h3.amax());
        // Size of the block relative to the δp entries: ≈ ρ/(R + h).
        let rho = line_of_sight(&pose.position, &l).unwrap().range_m;
        let ratio = p.h3.amax() / p.h2.amax();
        assert!(
            ratio > 0.1 * rho / 6.4e6 && ratio < 5.0 * rho / 6.3e6,
            "H3 size {ratio}"
        );
    }
}

/// Truth for a misalignment φ measured against the TRUE frame: C̃_b^n = exp(−[φ×]) C_b^t.
fn truth_for_phi(computed: &NavPose, dp: &Vector3<f64>, phi: &Vector3<f64>) -> NavPose {
    let position = true_pose_from_errors(computed, dp, &Vector3::zeros()).position;
    NavPose {
        position,
        c_b_n: Rotation3::new(*phi) * computed.c_b_n,
    }
}

#[test]
fn printed_eq15_is_the_jacobian_for_a_phi_state_and_fails_for_psi() {
    for (pose, l) in geometries() {
        let h = sighting_jacobian(&pose.position, &l).unwrap();
        let p = printed(&pose.position, &l, AlphaReading::Elevation);
        let fd_phi = fd_jacobian_with(&pose, &l, truth_for_phi);
        let fd_psi = fd_jacobian(&pose, &l);
        let printed_pos = p.h2 + p.h3_tan_flipped;
        // φ state: (H2 + H3 | H4), with the tan λ sign of H3 flipped, matches the finite
        // differences.
        assert!(
            rel_diff(&printed_pos, &pos_block(&fd_phi)) < 1e-6,
            "φ: δp block, {}",
            l.id()
        );
        assert!(
            rel_diff(&p.h4, &psi_block(&fd_phi)) < 1e-6,
            "φ: attitude block, {}",
            l.id()
        );
        // ψ state (the contract): H3 must go; with it the δp block is off by ≈ ρ/R.
        assert!(
            rel_diff(&pos_block(&h), &pos_block(&fd_psi)) < 1e-6,
            "ψ: verified H, {}",
            l.id()
        );
        let off = rel_diff(&printed_pos, &pos_block(&fd_psi));
        assert!(
            off > 1e-5,
            "ψ: printed H2 + H3 should be rejected, off by {off}"
        );
    }
    // At the paper's latitude the printed tan λ sign is rejected by the φ-state check too.
    for l in paper_landmarks() {
        let pose = paper_pose();
        let p = printed(&pose.position, &l, AlphaReading::Elevation);
        let fd_phi = fd_jacobian_with(&pose, &l, truth_for_phi);
        let off = rel_diff(&(p.h2 + p.h3), &pos_block(&fd_phi));
        assert!(
            off > 1e-5,
            "φ: printed tan λ sign should be rejected, off by {off}"
        );
    }
}

#[test]
fn true_pose_from_errors_inverts_the_contract_definitions() {
    let computed = paper_pose();
    let dp = Vector3::new(1_200.0, -800.0, 150.0);
    let psi = Vector3::new(2e-3, -1e-3, 5e-3);
    let truth = true_pose_from_errors(&computed, &dp, &psi);
    // δp = pos_err_ned_m(computed, truth), the contract's helper in ins-errors.
    assert!((pos_err_ned_m(&computed.position, &truth.position) - dp).amax() < 1e-6);
    let back = displace_by_ned_m(&truth.position, &dp);
    assert!((back.lat_rad - computed.position.lat_rad).abs() < 1e-12);
    // ψ: C̃_b^n (C_b^c)ᵀ = exp(−[ψ×]) with C_b^c = C_t^c C_b^t, C_t^c = C_e^c C_e^tᵀ.
    let c_e = |g: &Geodetic| ins_errors::earth::ned_from_ecef(g.lat_rad, g.lon_rad);
    let c_t_c = c_e(&computed.position) * c_e(&truth.position).transpose();
    let c_b_c = c_t_c * truth.c_b_n.matrix();
    let err = Rotation3::from_matrix_unchecked(computed.c_b_n.matrix() * c_b_c.transpose());
    assert!(
        (err.scaled_axis() + psi).amax() < 1e-12,
        "{}",
        err.scaled_axis()
    );
    // First-order contract form C_t^c ≈ I − [δθ×].
    let dth = frame_tilt_rad(&dp, truth.position.lat_rad, truth.position.alt_m);
    assert!((c_t_c - (Matrix3::identity() - ins_errors::earth::skew(&dth))).amax() < 1e-7);
}

#[test]
fn paper_printed_jacobian_is_the_verified_h_with_the_h_row_scaled_by_cos_2eps_plus_printed_h3() {
    for (pose, l) in geometries() {
        let pos = pose.position;
        let h = sighting_jacobian(&pos, &l).unwrap();
        let hp = paper_printed_jacobian(&pos, &l).unwrap();
        let p = printed(&pos, &l, AlphaReading::AsPrinted);
        let eps = line_of_sight(&pos, &l).unwrap().depression_rad();
        let k = (2.0 * eps).cos();
        let scale = h.amax();
        // ψ block: w row as verified, h row × cos 2ε.
        assert!(
            (hp.fixed_view::<1, 3>(0, PSI_COL) - h.fixed_view::<1, 3>(0, PSI_COL)).amax()
                < 1e-9 * scale
        );
        assert!(
            (hp.fixed_view::<1, 3>(1, PSI_COL) - k * h.fixed_view::<1, 3>(1, PSI_COL)).amax()
                < 1e-9 * scale
        );
        // δp block: the same scaling plus the printed H₃ (≈ ρ/R of the entries, but present).
        let mut expected_pos = pos_block(&h);
        for j in 0..3 {
            expected_pos[(1, j)] *= k;
        }
        expected_pos += p.h3;
        assert!(
            (pos_block(&hp) - expected_pos).amax() < 1e-9,
            "landmark {}",
            l.id()
        );
        assert!(p.h3.amax() > 1e-5, "H3 included");
        // Nothing outside the δp and ψ columns.
        let mut rest = hp;
        rest.fixed_view_mut::<2, 3>(0, POS_ERR_COL).fill(0.0);
        rest.fixed_view_mut::<2, 3>(0, PSI_COL).fill(0.0);
        assert_eq!(rest.amax(), 0.0);
    }
    // Three-landmark form stacks the single-landmark rows.
    let pos = paper_pose().position;
    let ls = paper_landmarks();
    let h3 = paper_printed_jacobian3(&pos, &ls).unwrap();
    for (i, l) in ls.iter().enumerate() {
        assert_eq!(
            h3.fixed_rows::<2>(2 * i),
            paper_printed_jacobian(&pos, l).unwrap()
        );
    }
    // And differs from the verified H where the printed α₀ bites (h rows at the start point).
    let hv = sighting_jacobian3(&pos, &ls).unwrap();
    assert!((h3 - hv).amax() > 0.5 * hv.amax());
    // With α₀ repaired (elevation), eq. 15 is the verified H plus the printed H₃ only.
    let he = paper_eq15_jacobian3(&pos, &ls, AlphaReading::Elevation).unwrap();
    for (i, l) in ls.iter().enumerate() {
        let p = printed(&pos, l, AlphaReading::Elevation);
        let mut want = hv.fixed_rows::<2>(2 * i).into_owned();
        let mut blk = want.fixed_view_mut::<2, 3>(0, POS_ERR_COL);
        blk += p.h3;
        assert!((he.fixed_rows::<2>(2 * i) - want).amax() < 1e-9 * hv.amax());
    }
    assert!((he - hv).amax() > 1e-5 && (he - hv).amax() < 1e-2);
}

#[test]
fn paper_printed_jacobian_stays_finite_and_accurate_for_a_landmark_almost_due_east() {
    // The printed β_x, β_y divide by x_L − x₀; their products with d_β₁ have a finite limit.
    // (The exactly-zero case is a unit test in src/paper_printed.rs.)
    let pos = paper_start();
    for north_m in [1e-3, -0.5, 3.0] {
        let target = displace_by_ned_m(&pos, &Vector3::new(north_m, 10_000.0, -500.0));
        let l = Landmark::new(7, target).unwrap();
        let north = line_of_sight(&pos, &l).unwrap().los_ned_m.x;
        assert!(north.abs() < 20.0, "north offset {north}");
        let h = paper_printed_jacobian(&pos, &l).unwrap();
        let hv = sighting_jacobian(&pos, &l).unwrap();
        let d =
            (h.fixed_view::<1, 3>(0, POS_ERR_COL) - hv.fixed_view::<1, 3>(0, POS_ERR_COL)).amax();
        // w row of the δp block: verified + H₃ row (≈ ρ/R ≈ 2e-3).
        assert!(d < 5e-3, "north {north}: w row off by {d}");
    }
}
