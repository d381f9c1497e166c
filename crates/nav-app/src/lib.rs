//! # nav-app — the lane tracker of Pimentel & Hemerly, and the INS/SD closed loop
//!
//! The one crate that composes the others (ARCHITECTURE.md), in two halves behind features: the
//! lane tracker below (`src/lane`, feature `lane`; its modules are re-exported at the crate root),
//! and [`ins_sd`] (feature `ins`), the sighting-device-aided INS of Lustosa, Chagas & Waldmann
//! (truth → IMU → strapdown INS → 15-state error KF or adaptive KF with landmark sightings every
//! 1 s, open loop to 195 s then feedback), which `cargo xtask monte-carlo` runs; its module docs
//! give the model, the tuning and the measured results.
//!
//! The application layer of the lane-mark tracker of Pimentel & Hemerly (ITA; English reading
//! in `shared/docs/lanes.md`, paper Fig. 1): frame sources, the tracking loop composed of
//! `vision-gradient` (stage I), `hough-init` (stage II) and `info-filter` / `wrls` (stage III),
//! configuration presets, overlays, synthetic fixtures with ground truth, and scoring.
//!
//! ## Model
//! Each lane mark is the parabola of eq. 1, `x = a1·y² + a2·y + a3` (x column, y row, pixels of
//! the **input** image; `a1` in px⁻¹, `a2` dimensionless, `a3` in px), a random walk observed
//! through the lane's edge pixels (eqs. 2–5):
//!
//! ```text
//! θ_{t+1} = θ_t + w_t,  Cov(w) = Q;      x_i = (y_i², y_i, 1)·θ_t + v_i,  Var(v_i) = σ_R²
//! ```
//!
//! The filters run on normalised rows `u = (y − y_c)/s` (`y_c` the middle ROI row, `s` half its
//! height), where `x = b1·u² + b2·u + b3` with all `b` in px; `Q = diag(filter.q_sigma_px²)` and
//! `P0 = diag(filter.p0_sigma_px²)` are given there (px²). `R`: see *Measurement noise* below
//! (`filter.r_sigma_px` is the WRLS covariance scale and the KIF's fallback). Coefficients are
//! always reported in the pixel convention.
//!
//! ## Mark centres (an addition beyond the paper; `track.mark_centres`)
//! The paper feeds the filter the lane's edge pixels, i.e. integer columns of both edges of the
//! mark. Their mean is the mark's centre only when both edges give as many pixels in every row;
//! measured on rendered roads, the integer edge pixels are off the true centre by 0.2–0.9 px,
//! an error that stays put while the scene does (the filter's white `R` cannot model it) and
//! that became a 0.3–0.7° heading error and a 1.2–1.6σ bias in metres (`lane-geometry`). With
//! `track.mark_centres = true` (the indoor preset) the tracker therefore measures **one
//! sub-pixel point per row**: the row's inlier edge pixels
//! bracket the mark, and the point is the centroid of the grey level above the local background
//! over that span widened by `2 + ⌈|dx/dy|⌉` px (at most 6; the background is the mean of the two
//! end pixels; the mark is whichever of the brighter or darker side deviates more). In a row
//! whose two ends differ by more than half the mark's contrast the window holds a single step
//! edge (a floor/wall boundary as in the corridor scene, a shadow border, a mark cut by the
//! image border), and the point is the centroid of the forward differences of the step's sign,
//! exact for an area-anti-aliased step. For an area-anti-aliased mark `w` px wide the
//! centroid is exact up to a sawtooth of at most `1/(8w)` px; measured on the rendered robot road
//! (σ = 4 grey levels of noise) the points sit 0.01 px from the true centre on average with a
//! scatter of 0.09 px.
//!
//! ## Measurement noise (an addition beyond the paper; with `track.mark_centres`)
//! The centroid's variance depends on the mark: `Var(x_i) ≈ σ_grey²·v_i` with
//! `v_i = Σ_k (k − c)²/S²` over the row's window (`S` the summed excess grey), so a narrow or
//! faint (far) mark is noisier than a wide near one. The KIF is given `R = s²·diag(v_i)`: the
//! relative variances `v_i` of the points (weighted power sums,
//! `info_filter::PowerSums::from_weighted_points`) and the scale `s²`, estimated on every frame
//! as the weighted scatter of that frame's points about their own least-squares parabola
//! (`N − 3` degrees of freedom), floored so the mean point σ is at least 0.02 px. The reported
//! covariance (`LaneTracker::lane_covariance_px`) then matches the actual scatter of the errors
//! (tested in `tests/metric_roundtrip.rs`: mean square of error/σ inside its χ² interval). With
//! fewer than 8 points the KIF falls back to `R = filter.r_sigma_px²·I`. WRLS keeps the paper's
//! unweighted update.
//!
//! The default and outdoor presets keep the paper's edge pixels (`mark_centres = false`): on the
//! six labelled real highway stills (`cargo xtask eval-lanes`) mark centres moved one lane of
//! twelve from a match to a false positive (TuSimple accuracy 78.7 → 77.9 %, FP 33.3 → 41.7 %;
//! the indoor preset 77.2 → 79.4 %, FP 41.7 % both ways), while every rendered sequence of
//! `cargo xtask regress` got 2–25× more accurate. Real-data tuning of the row windows (clutter
//! beside a dash merges into a row's span) is left open.
//!
//! ## The loop, per frame ([`LaneTracker::track`])
//! For each lane (left = `/` edges, right = `\` edges):
//! 1. *Tracking* (state [`LaneState::Tracking`] or [`LaneState::Coasting`]): KIF time update
//!    (`Y ← (I−B)Y(I−B)ᵀ + BQ⁻¹Bᵀ`, eq. 24); window `x̂(y) ± track.window_half_width_px` on every
//!    ROI row; directional gradient **inside the windows only**; window pixels of the lane's
//!    class whose residual `x − x̂(y)` is farther than `track.inlier_half_width_px` from the
//!    midhinge of the residuals of their third of the ROI are dropped; the rest are uniformly
//!    decimated (in row order) to at most `track.max_points_per_lane` (paper: 150), so they
//!    spread over the rows (with `track.mark_centres`: one sub-pixel mark centre per row
//!    instead, *Mark centres* below); KIF measurement update (eqs. 6, 12) or WRLS (eqs. 25–27,
//!    λ once per frame). Too few points (`track.reinit_min_points`) or an update moving the
//!    lane by more than `track.max_jump_px` at the top or bottom ROI row (the *jump gate*) is a miss: the lane
//!    coasts on its prediction; after `track.lost_after_frames` misses in a row it is
//!    [`LaneState::Lost`] and reported without coefficients.
//! 2. *(Re-)initialisation* (first frame, and every frame a lane is lost): gradient over the
//!    whole ROI, Hough over the lane's angle band and LS parabola on the band around the line
//!    (`hough-init`, with `init.refit_iterations` refits); accepted if it spans ≥ 25 % of the
//!    ROI rows; then refined by one windowed update on the same frame.
//! 3. *Crossing gate*: the lanes may not cross at the top ROI row nor come closer than
//!    `track.min_lane_separation_px` at the middle and bottom rows; the estimate just
//!    initialised, else the one with fewer points, is undone.
//!
//! No allocation in [`LaneTracker::track`] (tested with a counting allocator).
//!
//! ## Frame sources
//! [`FrameSource`] fills a caller-owned [`GreyFrame`]. [`sources::StillImage`] (PNG, JPEG,
//! PGM; colour → grey), [`sources::ImageDirectory`] (sorted), [`y4m::Y4mSource`] (file or
//! stdin; `C mono` and 4:2:0, Y plane), and live V4L2 capture from a BT848/878 card
//! ([`capture_source`]: `CaptureSource` over the `bt848-capture` crate, feature `capture`,
//! default on; without it `--device` says capture is not in the build).
//! Errors are [`NavError`]; [`NavError::is_fatal`] separates a fatal error from one bad frame
//! (or one capture timeout) that is reported, counted and skipped, and
//! [`NavError::lost_frames`] says how many input frames a non-fatal error stands for (a damaged
//! YUV4MPEG2 stream is resynchronised at the next `FRAME` marker: [`NavError::Y4mResync`]).
//!
//! ## Lanes in metres
//! [`camera`]: a camera file (pinhole intrinsics + mounting, or a measured ground-plane
//! homography) turns the two lanes' parabolas and their KIF covariances
//! ([`LaneTracker::lane_covariance_px`]) into the ego lane's lateral offset, heading, curvature
//! and width with standard deviations (`lane-geometry` crate); [`birdseye`] draws the ground
//! from above; `synth::road` (feature `eval`) renders a road from known 3-D geometry for the round-trip tests.
//!
//! ## Units of the configuration
//! See [`TrackerConfig`] and `configs/outdoor.toml` / `configs/indoor.toml`: every field
//! carries its unit.
//!
//! ## Example
//! (The renderer is `nav_app::synth`, feature `eval`.)
//! ```
//! # #[cfg(feature = "eval")] {
//! use nav_app::synth::{SceneRenderer, SCENES};
//! use nav_app::{Estimator, GreyFrame, LaneState, LaneTracker, TrackerConfig};
//!
//! let cfg = TrackerConfig::outdoor()?;
//! let mut scene = SceneRenderer::new(SCENES[0], 320, 240); // straight road, solid marks
//! let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240)?;
//! let mut frame = GreyFrame::default();
//! for i in 0..5 {
//!     scene.render(i, &mut frame);
//!     let report = tracker.track(&frame)?;
//!     let truth = scene.truth(i);
//!     for (lane, gt) in report.lanes.iter().zip(truth.lanes.iter()) {
//!         assert_eq!(lane.state, LaneState::Tracking);
//!         let x = lane.col_at_row(220.0).unwrap();
//!         assert!((x - gt.col_at_row(220.0)).abs() < 2.0);
//!     }
//! }
//! # }
//! # Ok::<(), nav_app::NavError>(())
//! ```

mod error;
#[cfg(feature = "lane")]
pub mod lane;

pub use error::NavError;

#[cfg(feature = "lane")]
pub use lane::config::{
    DEFAULT_TOML, FilterConfig, GradientConfig, INDOOR_TOML, InitConfig, OUTDOOR_TOML, RoiConfig,
    TrackConfig, TrackerConfig,
};
#[cfg(feature = "lane")]
pub use lane::frame::{FrameMeta, FrameSource, GreyFrame};
#[cfg(feature = "lane")]
pub use lane::tracker::{
    Estimator, LaneReport, LaneState, LaneTracker, LaneView, Side, TrackReport, TrackerCounters,
};
#[cfg(feature = "lane")]
pub use lane::{birdseye, camera, capture_source, frame_loop, overlay, sources, y4m};
// Evaluation and synthesis (feature `eval`): rendered sequences with ground truth, scoring, the
// real labelled sets.
#[cfg(feature = "eval")]
pub use lane::{eval, labelled, synth};

// The INS half (feature `ins`): the closed loop, its runs, statistics and the log replay.
#[cfg(feature = "ins")]
pub mod ins_sd;
