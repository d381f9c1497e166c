//! Lane initialisation — stage II of Pimentel & Hemerly (ITA), "lane-mark detection and
//! tracking": a Hough transform finds each lane's best straight line among its candidate edge
//! pixels, and the pixels in a band around that line are fitted by least squares with the
//! parabola of **eq. 1**
//!
//! ```text
//!     x = a1·y² + a2·y + a3            (x = column, y = row, pixels)
//! ```
//!
//! The paper runs this stage on the first frame and whenever the tracker (stage III, the
//! Kalman information filter) has too few lane pixels; it reports 122.2 ms for it on a
//! Pentium II 450 MHz. The paper leaves the Hough parameterisation, resolutions and band width
//! open; the choices below are this crate's.
//!
//! # Coordinates
//!
//! Image coordinates in pixels: `x = col_px` to the right, `y = row_px` downwards, origin at
//! the **centre of the top-left pixel**. Point inputs are any re-iterable collection
//! (`IntoIterator + Clone`) of [`PixelPoint`] items: slices or `&Vec` of [`Point`], of
//! `(col, row)` tuples or `[col, row]` arrays of `f32`/`f64`/`u16`/`u32`/`i32`, or a cheap
//! iterator chain such as `pixels.iter().filter(..).map(|p| (p.col_px, p.row_px))` (no copy
//! needed). The points are iterated several times (Hough: check + vote; each least-squares
//! fit: three passes), so the iterator must be cheap to clone and yield the same sequence.
//!
//! # Hough transform
//!
//! Lines are in normal form
//!
//! ```text
//!     ρ = x·cos θ + y·sin θ,     θ ∈ [−90°, 90°),   ρ signed, pixels
//! ```
//!
//! with the same origin (top-left pixel centre) for the reported [`HoughLine`]. θ is the angle
//! of the line's normal from the column axis towards the (downward) row axis, which equals the
//! line's tilt from the image vertical; along the line `dx/dy = −tan θ`. So a left-lane mark
//! (`/`, top leaning right) has θ > 0 and a right-lane mark (`\`) has θ < 0:
//! [`AngleBand::LEFT_LANE`] = [15°, 75°], [`AngleBand::RIGHT_LANE`] = [−75°, −15°]. Only the θ
//! bins of the lane's band are voted and searched.
//!
//! The accumulator ([`HoughWorkspace`]) is built once per image size and reused: θ bins
//! `θ_k = −90° + k·Δθ` (`theta_step_deg`, default 0.5°) with precomputed cos/sin tables, ρ
//! bins of `rho_step_px` (default 1 px) over `±hypot(W/2, H/2)` measured from the image
//! centre (internally; converted to the top-left origin on output). Each point votes once per
//! θ bin in the band for its nearest ρ bin. The peak is the maximum of the 3×3 box-summed votes
//! (`peak_smoothing`), refined to sub-bin precision by three-point parabolas along θ and ρ
//! (`subbin_refinement`).
//!
//! # Least squares
//!
//! The pixels with perpendicular distance `|x cos θ + y sin θ − ρ| ≤ band_px` (default 4 px)
//! are fitted by ordinary least squares, minimising `Σ (x_i − a1·y_i² − a2·y_i − a3)²` (the
//! horizontal residual, as in eq. 1 and the paper's measurement model `x = φᵀθ + v`,
//! `φ = (y², y, 1)`). Raw rows up to 480 make the normal matrix's entries span `1 … 480⁴ ≈ 5·10¹⁰`,
//! so the rows are normalised, `y' = (y − y0)/s` with `y0, s` the mid-row and half-span of the
//! fitted rows (`y' ∈ [−1, 1]`); the 3×3 normal equations in the basis `(1, y', y'²)`,
//!
//! ```text
//!     ⎡ Σ1    Σy'   Σy'² ⎤ ⎡b0⎤   ⎡ Σx    ⎤
//!     ⎢ Σy'   Σy'²  Σy'³ ⎥ ⎢b1⎥ = ⎢ Σx·y' ⎥ ,
//!     ⎣ Σy'²  Σy'³  Σy'⁴ ⎦ ⎣b2⎦   ⎣ Σx·y'²⎦
//! ```
//!
//! are solved by Cholesky with a relative pivot test ([`MIN_RELATIVE_PIVOT`]; the error names
//! the failed pivot), and mapped back to pixels:
//!
//! ```text
//!     a1 = b2/s²,   a2 = b1/s − 2·b2·y0/s²,   a3 = b0 − b1·y0/s + b2·y0²/s².
//! ```
//!
//! Fewer than 3 points, a single row, fewer than three distinct rows, or a non-finite
//! coordinate give a [`HoughError`], never NaN coefficients.
//!
//! # Decisions where the paper is silent
//!
//! - Parameterisation: normal form above (no slope–intercept singularity), θ restricted to
//!   the lane's band so that only a third of the accumulator is voted for a 60° band.
//! - Resolution: Δθ = 0.5°, Δρ = 1 px at 320×240; with sub-bin refinement the round trip is
//!   well inside 1 px / 1° (tested). Ties between equal peak scores go to the smallest θ, then
//!   the smallest ρ.
//! - Band: 4 px perpendicular half-width at 320×240 (scale with the image width).
//! - Plain (unweighted, non-robust) least squares as in the paper: clutter pixels that fall
//!   inside the band pull the fit. `refit_iterations` (off by default) re-selects the pixels
//!   within `band_px` of the fitted parabola and refits, which follows curved lanes further
//!   and resists clutter better (tested); it is an addition, not the paper's method.
//! - Pixels outside the workspace's image, non-finite coordinates and degenerate fits are
//!   errors, not silently skipped.
//!
//! # Checks (tests)
//!
//! Hough round trip on rasterised lines with noise and 30 % clutter (proptest, 64 seeded
//! cases) within 1 px and 1°; band restriction; reuse of the workspace ≡ a fresh one; the fast
//! peak search ≡ a brute-force 3×3 argmax; least squares exact on noiseless points (1e-9
//! relative, rows up to 480), equal to an independent SVD solve of the raw-pixel problem,
//! unbiased with the theoretical spread σ²(ΦᵀΦ)⁻¹ under noise; degenerate inputs → errors;
//! no allocation once the workspace exists (the oriented vote once its points are reserved,
//! `HoughWorkspace::reserve_oriented_points`); the θ-major oriented vote ≡ a point-major
//! reference; the AVX2 build of the oriented vote and its peak search ≡ the portable one
//! (accumulator, smoothed votes and peaks, 60 seeded scenes); the one-pass check of the
//! oriented points ≡ the checks that name the first bad point; labelled real frames
//! (lanenet ground truth) within the TuSimple tolerance.
//!
//! # Beyond the paper: several candidates and a joint ego-pair choice
//!
//! [`HoughWorkspace::find_lines`] returns the strongest few lines of a band (non-maximum
//! suppression in θ and ρ) instead of the single best; [`choose_ego_pair`] picks the ego lane's
//! two boundaries among the candidates of both bands jointly — a plausible lane width at the
//! bottom ROI row, boundaries that converge towards a vanishing point above the ROI (or within
//! its top rows, `EgoPairParams::meet_top_frac`), the camera
//! inside the lane, the pair nearest the image centre — so a neighbour lane's stronger line, a
//! crosswalk stripe or a car edge leaning the wrong way no longer wins on votes alone, and on a
//! curve the two boundaries may lean the same way. Without a plausible pair a single line is
//! reported, with `EgoPairParams::lone_min_lean_deg` not a near-vertical one (alone, it may be a
//! door frame or a pole). [`fit_around_line`] is the least-squares
//! half of [`init_lane`] for a chosen line; [`fit_around_line_where`] the same fit on the points
//! near the line only, when the caller can vouch before each selection that none left out would
//! be kept (then equal bit for bit).
//!
//! [`HoughWorkspace::find_lines_oriented`] restricts the vote by orientation: an
//! [`OrientedPoint`] carries the normal angle `θ_p` of its edge (its Sobel gradient direction,
//! folded into `[−90°, 90°)`) and votes only in the bins `|θ_k − θ_p| ≤ τ` (modulo 180°), with a
//! vote weight instead of repetition. The accumulator of a straight mark is unchanged; a pixel of
//! texture or of a jagged border votes in `2τ/Δθ + 1` bins instead of the whole band, around its
//! own (wrong) direction, so clutter no longer builds strong false peaks. With `τ ≥ 90°` the
//! accumulator equals the plain vote's (tested, with θ steps that divide 180° and one that does
//! not), which is the check of the restricted form.
//!
//! On a CPU with AVX2 (detected at run time, once per workspace) the oriented vote and its peak
//! search run as a copy of the same code compiled for AVX2 (`#[target_feature]`, as
//! `vision-gradient`'s kernel): the loops the compiler vectorises (the 3×3 smoothing and the
//! row maxima of the peak search, the ρ bins of the θ-major vote) on 256-bit vectors. The same integer sums and the
//! same unfused `f32` operations in the same order, so the same votes and peaks on either path.
//!
//! # Parameters and units
//!
//! | struct | field | unit | default | disables |
//! |---|---|---|---|---|
//! | [`HoughParams`] | `theta_step_deg` | degrees | 0.5 | — |
//! | [`HoughParams`] | `rho_step_px` | pixels | 1.0 | — |
//! | [`HoughParams`] | `peak_smoothing` | — | `true` | `false` |
//! | [`HoughParams`] | `subbin_refinement` | — | `true` | `false` |
//! | [`LaneInitParams`] | `band_px` | pixels | 4.0 | — |
//! | [`LaneInitParams`] | `min_points` | points | 10 | — (≥ 3) |
//! | [`LaneInitParams`] | `refit_iterations` | iterations | 0 | `0` |
//! | [`AngleBand`] | `min_deg`, `max_deg` | degrees of θ | see above | — |
//!
//! # Example
//!
//! ```
//! use hough_init::{init_lane, AngleBand, HoughParams, HoughWorkspace, LaneInitParams, Point};
//!
//! // A right-lane mark x = 0.001·y² + 0.4·y + 130 on rows 100..240 of a 320×240 frame,
//! // plus a few stray pixels.
//! let truth = |y: f64| 0.001 * y * y + 0.4 * y + 130.0;
//! let mut points: Vec<Point> = (100..240).map(|r| Point::new(truth(f64::from(r)), f64::from(r))).collect();
//! points.extend([Point::new(10.0, 20.0), Point::new(300.0, 50.0), Point::new(40.0, 230.0)]);
//!
//! let mut ws = HoughWorkspace::new(320, 240, HoughParams::default())?;
//! let params = LaneInitParams { band_px: 6.0, ..LaneInitParams::default() };
//! let lane = init_lane(&points, &AngleBand::RIGHT_LANE, &mut ws, &params)?;
//!
//! assert!(lane.line.theta_deg() < 0.0); // a `\` line
//! assert!((lane.parabola.col_at_row(200.0) - truth(200.0)).abs() < 0.5);
//! # Ok::<(), hough_init::HoughError>(())
//! ```

mod ego;
mod error;
mod hough;
mod init;
mod parabola;
mod params;
mod point;

pub use ego::{Chord, EgoChoice, EgoPairParams, choose_ego_pair, pair_shape_is_plausible};
pub use error::{HoughError, PointSet};
/// The workspace's one pixel point type (crate `grey-frame`), re-exported.
pub use grey_frame::PixelPoint;
pub use hough::{HoughLine, HoughWorkspace, MAX_ACCUMULATOR_CELLS, MAX_IMAGE_SIDE_PX};
pub use init::{LaneInit, MIN_WHERE_COS, fit_around_line, fit_around_line_where, init_lane};
pub use parabola::{MIN_RELATIVE_PIVOT, Parabola, ParabolaFit, fit_parabola, fit_parabola_where};
pub use params::{AngleBand, HoughParams, LaneInitParams};
pub use point::{OrientedPoint, Point};
