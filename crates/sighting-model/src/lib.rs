//! Sighting-device (SD) measurement model for INS aiding — Lustosa, Chagas & Waldmann,
//! "Sighting device-aided inertial navigation: fusion with adaptive Kalman filtering techniques"
//! (§4, eqs. 15–18, after Bar-Itzhack 1978; Table 1).
//!
//! A gimballed camera is pointed at a landmark of known position using the INS's *computed*
//! position and attitude. Because those are wrong, the landmark appears displaced from the image
//! centre by (w, h). This crate provides
//!
//! * the nonlinear model (truth, computed state, landmark) → (w, h): [`sighting_offset_m`],
//!   [`sighting_offsets3_m`], plus the noise [`add_sighting_noise`];
//! * its analytic Jacobian H with respect to the shared 15-state error vector, at the computed
//!   state: [`sighting_jacobian`] (2×15) and [`sighting_jacobian3`] (6×15), checked against
//!   central finite differences of the nonlinear model (`tests/jacobian_fd.rs`);
//! * the paper's H **as printed** (eqs. 15–18 read literally, for comparison runs only):
//!   [`paper_printed_jacobian`], [`paper_printed_jacobian3`], [`paper_printed_blocks`];
//! * sightings that carry their pointing (a measured direction in body or local-level axes, so
//!   that any filter state predicts them): [`offsets_from_los`], [`los_from_offsets`],
//!   [`los_from_truth`], [`jacobian_for_frame`] (module `pointed`);
//! * the `[sighting]` configuration section [`SightingConfig`] and geometry checks.
//!
//! # Frames and conventions (shared contract with `ins-errors`)
//!
//! n = local-level NED (north, east, down) at a position; c = NED at the *computed* position,
//! t = NED at the *true* position; b = body FRD; e = ECEF (WGS-84, [`ins_errors::earth`]).
//! Error state (15): δp (0..3, NED, m), δv (3..6), ψ (6..9, rad), ∇ (9..12), ε (12..15).
//! δ(·) = computed − true; δp = C_e^t (x̃ − x) (metres, NED at the truth);
//! ψ: C̃_b^n = (I − [ψ×]) C_b^c with C_b^c = C_t^c C_b^t and C_t^c = I − [δθ×] (the attitude
//! error measured against the computed local-level frame, Benson's psi angle).
//!
//! # Camera frame
//!
//! For the computed line of sight r̃ = C_e^c (x_L − x̃) (landmark minus computed position, in c),
//! slant range ρ = |r̃|, horizontal range d₀ = √(r̃_N² + r̃_E²), azimuth β (north → east) and
//! depression ε (positive below the horizon):
//!
//! ```text
//! b   = r̃/ρ                    = ( cos ε cos β,  cos ε sin β,  sin ε)   boresight (camera z)
//! e_w = (−r̃_E, r̃_N, 0)/d₀      = (−sin β,        cos β,        0    )   image right (camera x)
//! e_h = b × e_w                 = (−sin ε cos β, −sin ε sin β,  cos ε)   image down  (camera y)
//! C_cam^c = [e_w | e_h | b]
//! ```
//!
//! (e_w, e_h, b) is right-handed (the usual image convention: x right, y down, z forward). The
//! gimbal keeps the image w axis horizontal in the computed level frame (an azimuth/elevation
//! gimbal with image de-rotation — the geometry of the paper's β₀/α₀ formulation). A vertical
//! line of sight (d₀ = 0) leaves w undefined and is rejected
//! ([`SightingError::VerticalLineOfSight`]).
//!
//! # Nonlinear model
//!
//! The gimbal fixes the camera in the body at C_cam^b = C̃_b^nᵀ C_cam^c (computed attitude
//! C̃_b^n). The body really has attitude C_b^t, so the camera's true axes in t are
//! C_b^t C_cam^b. The true line of sight r = C_e^t (x_L − x) resolved in those axes,
//!
//! ```text
//! r_cam = (C_b^t C̃_b^nᵀ C_cam^c)ᵀ C_e^t (x_L − x) = C_cam^cᵀ C̃_b^n C_b^tᵀ C_e^t (x_L − x),
//! (w, h) = (r_cam,x , r_cam,y),
//! ```
//!
//! is the landmark's offset from the image centre **on the plane through the landmark normal to
//! the boresight** (the boresight pierces that plane at (r·b) b; the landmark is at r), in
//! metres. It equals "angle × range" to first order; the two differ by a relative
//! O((w/ρ)²) ≈ 10⁻⁴ for 100 m offsets at 10 km. A landmark behind the image plane
//! (r_cam,z ≤ 0) is an error. The measurement adds independent N(0, σ²_SD) noise to w and h,
//! σ²_SD = 40 m² (Table 1), in [`add_sighting_noise`].
//!
//! Substituting the contract's error definitions, C̃_b^n C_b^tᵀ C_e^t = (I − [ψ×]) C_t^c C_e^t
//! = (I − [ψ×]) C_e^c, and C_e^c (x_L − x) = r̃ + C_e^c C_e^tᵀ δp, so exactly
//!
//! ```text
//! (w, h) = S C_cam^cᵀ (I − [ψ×]) (r̃ + C_t^c δp),   S = [I₂ 0],
//! ```
//!
//! which vanishes at zero error (r̃ ∥ b).
//!
//! # Measurement matrix H (verified)
//!
//! To first order (C_t^c δp = δp + O(δp²/R)):
//! (w, h) ≈ S C_cam^cᵀ (δp + [r̃×] ψ), i.e. per landmark
//!
//! ```text
//!            δp (m)        δv    ψ (rad)         ∇    ε
//! row w:  [  e_wᵀ          0     −ρ e_hᵀ         0    0 ]
//! row h:  [  e_hᵀ          0      ρ e_wᵀ         0    0 ]
//!
//! e_wᵀ = (−sin β, cos β, 0),   e_hᵀ = (−sin ε cos β, −sin ε sin β, cos ε)
//! ```
//!
//! evaluated at the computed position only (no attitude dependence). There is **no**
//! position-induced tilt δθ term: the gimbal command and the landmark direction are both formed
//! in the computed frame c, so δθ cancels exactly between the pointing error and the line of
//! sight. A test shows that adding the tilt term (the paper's H₃, below) makes the δp columns
//! fail the finite-difference check by ≈ ρ/R ≈ 10⁻³ relative, while the H above passes it with
//! a per-entry tolerance of 10⁻⁶ relative (plus round-off floors of 10⁻⁷ m/m and 10⁻³ m/rad for
//! entries that are ~0, e.g. H[w, δp_D] = e_w,D = 0 exactly because e_w is horizontal).
//!
//! # Comparison with the printed eqs. 15–18, term by term
//!
//! The paper writes (w, h) = [H₁ | H₄] diag(1, −1, −1, 1, −1, −1) (δp_c, ψ_c) + v with
//! H₁ = H₂ + H₃ and the scalars of eq. 18 (x, y, z = landmark/vehicle coordinates). The finite
//! difference tests (`tests/paper_h.rs`) establish:
//!
//! * **Frame.** H₁–H₄ are written in NED coordinates (x north, y east, z down); the diag maps
//!   the paper's (north, west, up) state into NED. With this crate's NED states the diag is the
//!   identity.
//! * **Extraction damage.** β₀ = tan⁻¹((y_L − y₀)/(x_L − x₀)) (use atan2), β_x =
//!   sin 2β₀ / (2(x_L − x₀)) — both lost their parentheses. d₁₃ is defined twice, as
//!   −(cos β₀ (x_L − x₀) + sin β₀ (y_L − y₀)) and as d_β₁; the two definitions agree (= −d₀).
//! * **α₀ sign.** Printed α₀ = tan⁻¹((z_L − z₀)/d₀), which in NED is the *depression* ε. Every
//!   other entry (α_x, α_y, α_z, d₂₁, d₂₂, d_α₂) is consistent only with the *elevation*
//!   α₀ = tan⁻¹((z₀ − z_L)/d₀) = −ε. Read literally, the sin α₀ terms of d₂₁, d₂₂ and d_α₂
//!   flip sign and the whole h row of H₂ and H₄ is multiplied by cos 2α₀ (d_α₂ = ρ cos 2ε
//!   instead of ρ) — zero at 45° depression, negative beyond (at the paper's start point
//!   landmark 2 is seen at ≈ 74° and landmark 3 at ≈ 45°). With the elevation reading:
//! * **H₂ = δp part of H:** row 1 = d_β₁ (β_x, β_y, 0) = −d₀ ∂β₀/∂(x₀, y₀) = (−sin β, cos β, 0)
//!   = e_wᵀ; row 2 = d_α₂ (α_x, α_y, α_z) = ρ ∂α₀/∂(x₀, y₀, z₀) = e_hᵀ. Identical to this crate.
//!   (The printed β_x, β_y divide by x_L − x₀ and are singular for a landmark due east/west,
//!   although the limit is finite; e_w has no such singularity.)
//! * **H₄ = ψ part of H:** row 1 = (d₁₁, d₁₂, d₁₃) = ρ (cos β sin ε, sin β sin ε, −cos ε)
//!   = −ρ e_hᵀ; row 2 = (d₂₁, d₂₂, 0) = ρ (−sin β, cos β, 0) = ρ e_wᵀ. Identical.
//! * **H₃** is (−H₄ ∂δθ/∂δp, δθ = the contract's frame tilt) *up to one sign*: its (w, δp_E)
//!   entry is printed −(d₁₁ + d₁₃ tan λ)/(R_E + H), the tilt gives −(d₁₁ − d₁₃ tan λ)/(R_E + H)
//!   (δθ_D = −δp_E tan λ/(R_E + h) for geographic latitude λ, verified in `ins-errors` against
//!   the exact ECEF rotation). With that sign fixed, H₃ converts a misalignment measured
//!   against the *true* frame, φ = ψ + δθ, into ψ: H₂ δp + H₄ ψ = (H₂ + H₃) δp + H₄ φ. So
//!   eq. 15 is the correct Jacobian for a φ-angle attitude state (verified by finite
//!   differences holding φ fixed; the printed tan λ sign fails that check at −23°), but the
//!   paper's state and its eq. 8 are psi-angle; with ψ, H₃ must be dropped. Its entries are
//!   ≈ ρ/(R + h) ≈ 2·10⁻³ of the δp entries — far below σ_SD in practice, but the finite
//!   difference check rejects it.
//!
//! [`paper_printed_jacobian`] / [`paper_printed_jacobian3`] evaluate eq. 15 literally (α₀ as
//! printed, H₃ as printed) and [`paper_eq15_jacobian3`] with α₀ read either way, for runs that
//! reproduce the paper's filter (`nav-app`, `[filter] measurement_jacobian`): with the literal
//! α₀ the paper's closed loop diverges; with the elevation reading it matches this crate's H.
//!
//! (The reading note's form δu^c = −C_n^c (δp + u × φ) matches this crate's
//! S C_cam^cᵀ (δp + r̃ × ψ) up to its sign convention only with ψ in place of φ, for the same
//! reason.)
//!
//! # Use in the Kalman filter
//!
//! Per update, stack the three landmarks: z = (w₀, h₀, w₁, h₁, w₂, h₂) measured
//! ([`sighting_offsets3_m`] on the simulated truth plus [`add_sighting_noise`]), H from
//! [`sighting_jacobian3`] at the INS's computed position, R = σ²_SD I₆. The camera is pointed
//! at where the INS believes the landmark is, so the predicted offset of the computed state is
//! zero and z itself is the measurement of the error state: z = H x + v, innovation
//! ν = z − H x̂⁻ (x̂⁻ = 0 after a feedback reset). Call [`SightingConfig::check_vehicle`] once
//! at the start of a run to reject landmarks at (or too close to, or straight below) the
//! vehicle.
//!
//! # Units
//!
//! | quantity | unit |
//! |---|---|
//! | positions ([`Geodetic`]) | rad, rad, m above the WGS-84 ellipsoid |
//! | (w, h), noise σ | m at the landmark; variance m² |
//! | H, δp columns | m/m |
//! | H, ψ columns | m/rad |
//! | config `lat_deg`, `lon_deg` / `alt_m`, `min_range_m` / `update_period_s` | ° / m / s |
//!
//! # Example
//!
//! ```
//! use nalgebra::{Rotation3, Vector3};
//! use sighting_model::{
//!     Geodetic, NavPose, paper_landmarks, sighting_jacobian3, sighting_offsets3_m,
//!     true_pose_from_errors,
//! };
//!
//! let start = Geodetic::from_deg(-(23.0 + 12.0 / 60.0), -(45.0 + 52.0 / 60.0), 6000.0);
//! let computed = NavPose { position: start, c_b_n: Rotation3::from_euler_angles(0.0, 0.0, 0.3) };
//! let landmarks = paper_landmarks();
//!
//! // Truth 30 m south of the computed position (δp_N = +30 m), 1 mrad azimuth error.
//! let dp = Vector3::new(30.0, 0.0, 0.0);
//! let psi = Vector3::new(0.0, 0.0, 1e-3);
//! let truth = true_pose_from_errors(&computed, &dp, &psi);
//!
//! let z = sighting_offsets3_m(&truth, &computed, &landmarks)?;
//! let h = sighting_jacobian3(&computed.position, &landmarks)?;
//! let mut x = nalgebra::SVector::<f64, 15>::zeros();
//! x.fixed_rows_mut::<3>(0).copy_from(&dp);
//! x.fixed_rows_mut::<3>(6).copy_from(&psi);
//! // The linear model reproduces the nonlinear offsets to well below the 6.3 m noise σ.
//! assert!((z - h * x).amax() < 0.1);
//! # Ok::<(), sighting_model::SightingError>(())
//! ```

mod config;
mod error;
mod jacobian;
mod model;
mod paper_printed;
mod pointed;

pub use config::{LandmarkConfig, SightingConfig};
pub use error::SightingError;
pub use ins_errors::earth::Geodetic;
pub use jacobian::{
    POS_ERR_COL, PSI_COL, ROWS_PER_LANDMARK, STATE_DIM, sighting_jacobian, sighting_jacobian3,
};
pub use model::{
    DEGENERATE_RANGE_M, Landmark, LineOfSight, NavPose, PAPER_LANDMARKS_DEG_M, PAPER_NOISE_VAR_M2,
    VERTICAL_LOS_FRACTION, add_sighting_noise, check_geometry, line_of_sight, paper_landmarks,
    sighting_offset_m, sighting_offset_surveyed_m, sighting_offsets3_m, true_pose_from_errors,
};
pub use paper_printed::{
    PaperAlphaReading, PaperPrintedBlocks, paper_eq15_jacobian, paper_eq15_jacobian3,
    paper_printed_blocks, paper_printed_jacobian, paper_printed_jacobian3,
};
pub use pointed::{
    LosFrame, jacobian_for_frame, los_from_offsets, los_from_truth, offsets_from_los,
};
