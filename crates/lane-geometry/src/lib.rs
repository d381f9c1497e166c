//! # lane-geometry — lanes in metres
//!
//! The lane paper (Pimentel & Hemerly, ITA) ends with its next step: recover the robot's pose
//! relative to the lane through a perspective transform. This crate does that for the ego lane:
//! from the two image parabolas of the tracker (`x = a1·y² + a2·y + a3`, pixels) and their
//! covariances, it computes the camera's lateral offset from the lane centre, its heading
//! relative to the lane, the lane's curvature and width on the ground plane, each with a
//! standard deviation. No I/O, no allocation per call.
//!
//! ## Frames
//!
//! * **Image**: `u` column (px, rightwards), `v` row (px, downwards), origin at the top-left
//!   pixel centre (the project's convention).
//! * **Vehicle ground frame**: origin on the ground directly below the camera centre, `X`
//!   forward, `Y` right, `Z` down (FRD); the road is the plane `Z = 0`, assumed flat.
//!
//! ## Pinhole camera ([`PinholeCamera`])
//!
//! Intrinsics `K = [[f, 0, c_u], [0, f, c_v], [0, 0, 1]]` (square pixels, no distortion);
//! mounting: height `h` above the ground and the orientation
//! `R = Rz(yaw)·Ry(−pitch_down)·Rx(roll)` of the camera's forward/right/down axes in the vehicle
//! frame. With `A = P·Rᵀ` (`P` reorders forward/right/down into the optical right/down/forward),
//! a point `p` of the vehicle frame projects as
//!
//! ```text
//! (x_c, y_c, z_c) = A·(p − (0, 0, −h)),   u = c_u + f·x_c/z_c,   v = c_v + f·y_c/z_c.
//! ```
//!
//! ## Ground-plane homography ([`Homography`])
//!
//! For a ground point `(X, Y, 0)`, `p − c = diag(1, 1, h)·(X, Y, 1)`, so
//!
//! ```text
//! z_c·(u, v, 1)ᵀ = H·(X, Y, 1)ᵀ,   H = K·A·diag(1, 1, h),   (X, Y, 1)ᵀ/z_c = G·(u, v, 1)ᵀ,  G = H⁻¹.
//! ```
//!
//! `H` can also be measured instead of modelled: [`Homography::from_point_pairs`] solves it from
//! four image↔ground point pairs (DLT, Hartley-normalised). Everything below uses only `G`.
//! The Jacobian of the image→ground map at `(u, v)`, with `q = G·(u, v, 1)ᵀ`, is
//! `∂X/∂u = (G₀₀ − X·G₂₀)/q₂`, `∂Y/∂u = (G₁₀ − Y·G₂₀)/q₂` (and likewise in `v`).
//!
//! ## Image parabolas → ground-plane lane ([`EgoLaneEstimator`])
//!
//! 1. **Look-ahead range.** The lanes are sampled at [`SAMPLE_ROWS`] fixed image rows `v_k`:
//!    the rows where ground points `(X_k, 0)`, `X_k` evenly spaced over the look-ahead range
//!    `[lookahead_near_m, lookahead_far_m]`, appear. Choose the range inside the ground
//!    distances the tracker's region of interest covers (the rows the filters see), so the
//!    geometry interpolates the tracked lanes rather than extrapolating them.
//! 2. **Back-projection.** Each lane `s ∈ {L, R}` gives the image points
//!    `(u_{s,k}, v_k)`, `u_{s,k} = a1_s·v_k² + a2_s·v_k + a3_s`, mapped to ground points
//!    `(X_{s,k}, Y_{s,k})` by `G`.
//! 3. **Ground model.** Both marks are fitted together, by unweighted least squares over the
//!    `2·SAMPLE_ROWS` ground points, with the lane model of a vehicle frame (small-angle road
//!    model; parallel marks)
//!
//!    ```text
//!    Y = y0 + m·X + c·X² ∓ W/2      (− for the left mark, + for the right),
//!    ```
//!
//!    a linear fit in `p = (y0, m, c, W)` with design rows `a_i = (1, X_i, X_i², ∓1/2)`:
//!    `N·p = Σ a_i·Y_i`, `N = Σ a_i·a_iᵀ` (4×4 Cholesky).
//! 4. **Outputs at the camera (`X = 0`).** With `s = √(1 + m²)`:
//!
//!    ```text
//!    lateral_offset_m = −y0/s          (camera right of the lane centre > 0; perpendicular distance)
//!    heading_rad      = −atan(m)       (vehicle pointing right of the lane > 0)
//!    curvature_per_m  = 2c/s³          (curvature of the centre line, bending right > 0)
//!    lane_width_m     = W/s            (across the lane, not along Y)
//!    ```
//!
//!    The quadratic is the small-angle approximation of a circular arc: for an arc of curvature
//!    `κ`, `Y(X) = X²·κ/2 + X⁴·κ³/8 + …`, so over a look-ahead range `X ≤ L` the fit is exact to
//!    about `κ³L⁴/8` (1 mm for `κ = 0.1 /m`, `L = 3 m`; 1 mm for `κ = 1/500 m`, `L = 40 m`).
//!
//! ## The limit of the image-parabola model
//!
//! Straight marks are straight image lines, so for them the paper's parabola is exact and the
//! geometry is recovered exactly (tested, for any mounting). A curved mark is not an image
//! parabola: with depth `z` along the optical axis, a ground term `c·X²` appears in the image as
//! `u ∝ c·X²/z`, which holds a term in `z`, i.e. in `1/(α + β·v)`, that a parabola in `v`
//! only approximates over the rows it is fitted on. Steps 1–4 alone then return the curvature
//! low and the heading at the camera absorbs part of it (measured in the tests, with image
//! parabolas fitted row by row as the tracker does: robot scale, look-ahead 0.55–1.0 m,
//! curvature 10–14 % low, heading off by ≤ 0.12·|κ|·1 m, offset ≤ 4 mm; highway scale,
//! look-ahead 7–20 m, curvature 37 % low, heading off by ≈ 5·|κ|·1 m). Step 5 removes it.
//!
//! 5. **Model-consistent inversion** ([`EgoLaneEstimator::estimate_fitted`]; an addition
//!    beyond the paper). The tracked parabola is the least-squares projection of the true
//!    image curve onto parabolas, over the rows and with the weights the tracker fitted
//!    ([`FitRows`]: per lane, the weighted mean row and the summed weight of its points in each
//!    of [`FIT_SAMPLES`] bins). The forward model `F(p)` does the same to the ground model
//!    `p = (y0, m, c, W)`: it projects each mark `Y = y0 + m·X + c·X² ∓ W/2` into the image at
//!    two rows per bin (`±h/(2√3)` about the bin's row, `h` the bin spacing, half the bin's
//!    weight each) and fits the parabola with those weights. With `G = E∘F` (`E` steps 2–3),
//!    the estimate `p*` solves `G(p*) = p_E = E(tracked parabolas)` by one Newton step from
//!    `p_E`: `p* = p_E + D⁻¹·(p_E − G(p_E))`, `D = ∂G/∂p ≈ I + β·e_cᵀ` (straight lanes are
//!    exact, so only the curvature column departs from the identity; `β` by a forward
//!    difference in `c`), `D⁻¹ = I − β·e_cᵀ/(1 + β_c)`. The Jacobian becomes `D⁻¹·∂p_E/∂θ`
//!    (checked against finite differences of the corrected map). Measured on the cases above
//!    (parabolas fitted to 201 rows, told to the estimator as [`FitRows::uniform`]): heading
//!    error 15–180× smaller (≤ 6·10⁻⁴ rad at κ = −0.08 /m), curvature within 1 % of κ, offset
//!    ≤ 0.05 mm at the robot scale and ≤ 0.4 mm on the highway. The truth the tests hold it
//!    to is `ArcRoad`'s: the heading relative to the centre line's tangent at its point
//!    nearest the camera, the curvature of the centre line, the perpendicular offset.
//!
//! ## Uncertainty
//!
//! The tracker's KIF carries each lane's information matrix `Y_u` in its normalised row
//! coordinate; `P_px = T·Y_u⁻¹·Tᵀ` (with `T` the exact linear map between the normalised and
//! the pixel coefficients, `info_filter::RowNorm`) is each lane's coefficient covariance in
//! pixels. The two lanes' filters are independent, so
//!
//! ```text
//! Cov(offset, heading, curvature, width) = J·diag(P_L, P_R)·Jᵀ,   J = ∂(outputs)/∂(a_L, a_R)  (4×6)
//! ```
//!
//! with `J` by the chain rule: `∂u_{s,k}/∂a_s = (v_k², v_k, 1)`; the ground Jacobian above; the
//! least-squares fit differentiated implicitly,
//! `N·∂p = Σ_i [(0, r_i, 2X_i·r_i, 0)ᵀ·∂X_i + a_i·(∂Y_i − (m + 2c·X_i)·∂X_i)]` with the residuals
//! `r_i = Y_i − a_iᵀp`; step 5's factor `D⁻¹` when it is used; and the output map of step 4.
//! The tests check `J` against central finite differences of the nonlinear map and the
//! propagated covariance against Monte Carlo.
//!
//! ## Ground truth ([`ArcRoad`])
//!
//! A road whose centre line is a circular arc, with the camera posed on it by the same four
//! quantities, for renderers and tests: it gives the mark points in the vehicle frame and, for
//! any ground point, its distance across and along the road.
//!
//! ## Example
//!
//! ```
//! use lane_geometry::{EgoLaneEstimator, Intrinsics, Mounting, PinholeCamera};
//! use nalgebra::Matrix3;
//!
//! # fn main() -> Result<(), lane_geometry::GeometryError> {
//! let camera = PinholeCamera::new(
//!     Intrinsics { focal_length_px: 300.0, principal_point_px: [159.5, 119.5] },
//!     Mounting { height_m: 0.3, pitch_down_rad: 0.2, roll_rad: 0.0, yaw_rad: 0.0 },
//! )?;
//! let h = camera.homography()?;
//! // Two straight marks 0.8 m apart, the camera 0.1 m right of the centre, heading 0:
//! // each mark is the image line through the images of two of its ground points.
//! let line = |y_m: f64| -> Result<[f64; 3], lane_geometry::GeometryError> {
//!     let [u1, v1] = h.ground_to_image([1.0, y_m])?;
//!     let [u2, v2] = h.ground_to_image([2.0, y_m])?;
//!     let slope = (u2 - u1) / (v2 - v1);
//!     Ok([0.0, slope, u1 - slope * v1])
//! };
//! let (left, right) = (line(-0.5)?, line(0.3)?);
//! let ego = EgoLaneEstimator::new(h, 0.8, 2.0)?;
//! let cov = Matrix3::from_diagonal(&nalgebra::Vector3::new(1e-10, 1e-5, 0.5));
//! let lane = ego.estimate(&left, &cov, &right, &cov)?;
//! assert!((lane.geometry.lateral_offset_m - 0.1).abs() < 1e-9);
//! assert!((lane.geometry.lane_width_m - 0.8).abs() < 1e-9);
//! assert!(lane.geometry.heading_rad.abs() < 1e-9);
//! assert!(lane.sigma.lateral_offset_m > 0.0);
//! # Ok(())
//! # }
//! ```

mod camera;
mod ego;
mod error;
mod homography;
mod road;

pub use camera::{Intrinsics, Mounting, PinholeCamera};
pub use ego::{
    EgoGeometry, EgoJacobian, EgoLane, EgoLaneEstimator, FIT_SAMPLES, FitRows, SAMPLE_ROWS,
};
pub use error::GeometryError;
pub use homography::Homography;
pub use road::ArcRoad;

/// `a > b`, false when either is NaN.
#[inline]
fn greater(a: f64, b: f64) -> bool {
    a > b
}
