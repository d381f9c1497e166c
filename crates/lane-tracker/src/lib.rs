//! # lane-tracker — the lane-mark tracker of Pimentel & Hemerly
//!
//! Stages I–III of the paper's Fig. 1 (English reading in `shared/docs/lanes.md`), composed from
//! the numeric crates `vision-gradient` (stage I, directional gradient), `hough-init` (stage II,
//! Hough line + least-squares parabola) and `info-filter` / `wrls` (stage III, Kalman
//! information filter or WRLS), with a per-lane state machine and sanity gates; its
//! configuration ([`TrackerConfig`]: TOML text and the compiled-in presets); and the ego lane in
//! metres ([`camera`], over `lane-geometry`).
//!
//! Numeric like `ins-sd-filter`: no file or device I/O and no image codecs. Frames arrive as a
//! [`GreyFrame`] or as borrowed pixels ([`LaneTracker::track_pixels`]); frame sources, config
//! files, overlays are the `lane-io` crate, synthetic scenes `lane-scenes`, the labelled benchmark
//! `lane-bench`, sequence scores and the regression `lane-eval`.
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
//! `track.mark_centres = true` the tracker therefore measures **one
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
//! ## Stripe middles (an addition beyond the paper; `track.stripe_middles`, default on)
//! The lane model and the labels mean a mark's middle; the paper measures its edge pixels,
//! whose mean is the middle only while both edges are measured. Point selection keeps the
//! window pixels within `track.inlier_half_width_px` (`w_in`, 6 px) of their row band's midhinge
//! residual. On a mark at most `w_in` wide, from either of its edges the other lies within the
//! band, so the band settles on the middle and the edge pixels measure it. From one edge of a
//! wider mark (a tape beside a small robot's camera, 12–21 px at 320 × 180 on `seame`; a road
//! mark near the camera) the other edge lies beyond the band: the edge pixels hold the lane on
//! the edge the Hough line found, 5.6–12.6 px from the labelled middle on the `seame` frames
//! looked at, a miss for the scorer (5 px at 320 px width). (Tapes wider than
//! `gradient.stripe_max_width_px` at their bottom rows are not paired there either.)
//!
//! With `track.stripe_middles`, in the windowed refinement that follows an initialisation an
//! edge pixel that bounds a bright stripe more than `w_in` and at most
//! `gradient.stripe_max_width_px` wide measures the stripe's middle (half-pixel columns) instead
//! of its own column. The stripe is the one stripe pairing finds (the nearest pixel of the same
//! class and the opposite polarity on the pixel's bright side), and it counts only on a floor
//! alike on both sides: the grey levels two columns outside its edges differ by at most half its
//! contrast (the test the mark centres use to tell a mark from a step). A kerb's face, bright
//! between the road and a pavement of another grey, stays a step, whose foot
//! `init.kerb_foot` keeps. Narrower stripes keep their edge pixels: they need no middle, and the
//! two lines of a double line, each narrow, go on measuring the middle between them.
//!
//! Tracked frames keep the paper's edge pixels. From a mark's middle they hold it while both
//! edges lie within the band, up to `2·w_in` (12 px); a lane on a wider mark slides back onto one
//! of its edges within a few frames (a rendered mark 15 px wide at the bottom row: 7–10 px off
//! its middle there from the fourth tracked frame on). Middles on every tracked frame held it on
//! the middle but cost 30 % more instructions per tracked frame (447 k against 344 k: about
//! 27 µs on the development VM, beyond the 25 µs budget) and scored lower on the stress test
//! (`cargo xtask eval-lanes --one-sequence`: 65.2 % against 66.9 %). How it was measured:
//! `docs/lanes/history/stripe-middles.md`.
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
//! **No preset turns mark centres on.** On rendered scenes they make every sequence of `cargo
//! xtask regress` 2–25× more accurate and the metric round trips tight (`lane-eval`'s
//! `metric_roundtrip` sets them), and on the labelled real stills they help the indoor preset a
//! little (dev part 39.4 → 42.4 %); but on a consecutive real indoor sequence measured outside
//! this repository the indoor preset fell from 99.5 % of lines found / 0.5 % false to 85.1 % /
//! 8.7 % when they were switched on — a tracking effect (the scatter-based `R` makes the filter
//! follow whatever the row windows catch) that the stills cannot show and that is not yet
//! understood. Until a real labelled sequence shows why, they stay an option.
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
//!    instead, *Mark centres* above); KIF measurement update (eqs. 6, 12) or WRLS (eqs. 25–27,
//!    λ once per frame). Too few points (`track.reinit_min_points`) or an update moving the
//!    lane by more than `track.max_jump_px` at the top or bottom ROI row (the *jump gate*) is a miss: the lane
//!    coasts on its prediction; after `track.lost_after_frames` misses in a row it is
//!    [`LaneState::Lost`] and reported without coefficients.
//! 2. *Pair gate* (joint initialisation only, an addition beyond the paper): two tracked lanes
//!    whose chords over the ROI rows no longer have an ego lane's shape — the width at the bottom
//!    row within `[init.ego_pair.min_width_frac, max_width_frac]·W`, not wider at the top than at
//!    the bottom, in order below the top `init.ego_pair.meet_top_frac` of the rows
//!    (`hough_init::pair_shape_is_plausible`, the rules the pair was chosen by, with the
//!    choice's 0.9 top/bottom margin relaxed to 1) — have lost a boundary to something else,
//!    and the pair cannot tell which: both are dropped and initialised again on the same frame
//!    ([`TrackerCounters::gated_pairs`]). Without it a lane that had slid onto a kerb, a pole or
//!    a car kept its points and was never lost (a lane is lost only when its windows run out
//!    of points).
//! 3. *(Re-)initialisation* (first frame, every frame a lane is lost, and — the *re-validation*,
//!    an addition beyond the paper, joint initialisation only — every
//!    `track.revalidate_every_frames`-th frame while both lanes are tracked, and at once on a
//!    frame a tracked lane's window gave fewer than `track.revalidate_below_points` points — a
//!    lane on clutter or whose mark left its window; a lane that weak on two frames in a row
//!    that the choice keeps nothing of is set aside while the second search looks for its
//!    side, and put back if it finds nothing —, where the tracked lanes compete with the
//!    candidates, each weighed by its own row coverage ×
//!    `track.revalidate_keep_factor`, and a lane is replaced only by a candidate off its mark,
//!    [`TrackerCounters::revalidations`]; with `track.revalidate_spread` (the default) the
//!    period's re-validation is spread over the period's frames, a tenth of its work a frame on
//!    the edges of the period's first frame, and runs whole on the period's last frame only
//!    when its choice there would change a lane (module `tracker::revalidation`); with
//!    re-validation on, a lane tracked from earlier
//!    frames competes so too when the other side is initialised again, instead of being locked
//!    into the pair; a tracked lane the joint choice puts on the other side
//!    of the pair — the camera crossed it, a lane change — is handed over to that side with its
//!    filter, [`TrackerCounters::lane_changes`]): gradient over the
//!    whole ROI, Hough over the lane's angle band and LS parabola on the band around the line
//!    (`hough-init`, with `init.refit_iterations` refits); accepted if it spans ≥ 25 % of the
//!    ROI rows; then refined on the same frame by `track.refine_passes` windowed updates (at
//!    least one; windows `±track.refine_window_half_width_px`).
//!    With `init.candidate_lines > 0` (the default configuration) the initialisation is
//!    *joint* instead, see *Joint initialisation* below.
//! 4. *Crossing gate*: the lanes may not cross at the top ROI row (with
//!    `init.ego_pair.meet_top_frac`, below the top fraction of the ROI rows where the vanishing
//!    point may lie) nor come closer than `track.min_lane_separation_px` at the middle and
//!    bottom rows; the estimate just initialised, else the one with fewer points, is undone.
//!
//! No allocation in [`LaneTracker::track`] (tested with a counting allocator).
//!
//! ## Joint initialisation and stripe pairing (additions beyond the paper; default configuration)
//! The paper initialises each lane from the best Hough line of its edge class (`/` left, `\`
//! right). On real frames that line is often a neighbour lane's mark, a car edge, a crosswalk
//! stripe or floor texture, and on a curve both ego boundaries lean the same way. The default
//! configuration therefore:
//! - **pairs stripe edges** (`gradient.stripe_max_width_px`, `gradient.stripe_paired_votes`;
//!   `vision_gradient::split_stripes` / `keep_bright_stripes`): an edge pixel whose row
//!   holds an edge of its class and the opposite polarity within the mark width on the correct
//!   side (rising left, falling right) bounds a bright mark and counts `stripe_paired_votes`
//!   times in the Hough votes and the least squares; other edge pixels (kerbs, road edges, but
//!   also cars and seams) count once (`stripe_paired_votes = 0` drops them);
//! - **drops periodic stripes** before the vote (`gradient.periodic_min_stripes`;
//!   `vision_gradient::drop_periodic_stripes`): a chain of four or more bright stripes along a
//!   row, of like width and at most three widths apart, that a chain on an adjacent row
//!   confirms — a crosswalk, road text, a railing — loses its edge pixels on its row and the two
//!   beside it (a mark crosses a row once, a double line twice);
//! - takes the **`init.candidate_lines` strongest lines** of each band
//!   (`hough_init::HoughWorkspace::find_lines`, non-maximum suppression) and **chooses the ego
//!   pair jointly** (`hough_init::choose_ego_pair`, `[init.ego_pair]`): a lane width at the
//!   bottom ROI row within `[0.2, 1.5]·W`, boundaries converging upwards and meeting above the
//!   ROI or within its top quarter of rows (`init.ego_pair.meet_top_frac = 0.25`: with the
//!   camera pitched up, or the ROI's top fraction set for another camera, its top rows reach
//!   above the vanishing point), the camera
//!   inside the lane, then support minus the pair's offset from the image centre and its width
//!   (`init.ego_pair.width_weight`: the nearest boundary on each side). With
//!   `init.candidate_coverage` a candidate is seen as the least-squares parabola it would be
//!   initialised with, its support the row coverage of that parabola (paired pixels in the LS
//!   band per ROI row, unpaired ones at most a step's two a row, capped) minus that of the
//!   parallel curves three bands to each side (texture and clutter are as dense beside a line as
//!   on it; a step through noise no longer matches a bright stripe). Lanes are sided
//!   by position, not lean; a frame with no plausible pair reports the single best line on its
//!   side of the centre, among those leaning at least `init.ego_pair.lone_min_lean_deg` from
//!   the vertical (a vertical line alone may be a door frame or a pole: one still gives no
//!   ground plane; a mark straight ahead is found with its partner). A lane still tracked stays
//!   in the pair (with re-validation on, one tracked from earlier frames competes instead: *The
//!   loop*, step 3). Each band's vote, support and least squares take the pixels of its edge
//!   class **and every pixel whose edge runs within 10° of the vertical** (`|gy| ≤ tan 10°·|gx|`,
//!   `tracker::init::counts_as`): along a mark straight ahead `gy` is the floor's noise, its
//!   sign — the class — falls either way, and each band saw about half of the mark. While
//!   tracking, each row takes the edge class of the predicted slope (either class where the
//!   mark is within the same 10° of the vertical);
//! - refines a fresh initialisation `track.refine_passes` times on the same frame in a wider
//!   window (`track.refine_window_half_width_px`): the Hough line of a thick or curved mark can
//!   sit several pixels off it;
//! - **measures stripe middles in that refinement** (`track.stripe_middles`; *Stripe middles*
//!   above): a lane the Hough line put on one edge of a wide mark is refined onto its middle;
//! - **traces the stripe under the lane row by row after that refinement**
//!   (`init.stripe_trace`; module `tracker::stripe_trace`): from the row of the refinement's
//!   middle point the bright stripe under the estimate is followed up and down the rows (its
//!   middle placed between its edges to a fraction of a pixel, and looked for within 2 px
//!   (an eighth of the widest stripe) of the last one carried on by a slowly following slope;
//!   more than 3 rows in a row without one end it), and its middles, one a row at `σ/2`, are
//!   one more KIF update — a lane the texture beside a tape pulled off it, or held on the rows
//!   its first fit saw, comes back onto the stripe where the stripe runs on (development part
//!   74.6 → 74.8 %, FP 30.3 → 30.1 %; held out 77.9 → 78.5 %, FP 30.5 → 29.1 %, `seame`
//!   72.6 → 73.9 %, FP 44.9 → 38.8 %);
//! - **lets no lane turn back below its evidence** (`init.no_turn_back`; module
//!   `tracker::turn_back`): after that refinement, a parabola whose vertex `−a2/(2·a1)` (its
//!   vertical image tangent) lies between the lowest row of its points and the bottom row
//!   searched, at a column inside the image, is replaced by the least-squares line through its
//!   points — nothing was measured there, and a lane does not turn back between its evidence and
//!   the camera (development part 74.1 → 74.3 %, held out 76.3 → 77.0 %, `f1tenth` held out
//!   78.0 → 79.6 %);
//! - **votes by orientation** (`init.orientation_tolerance_deg`; `hough_init::HoughWorkspace::
//!   find_lines_oriented`): each candidate pixel votes only for the lines whose normal lies
//!   within the tolerance of its own Sobel gradient direction (stored with the pixel,
//!   `vision_gradient::EdgePixel::gradient`, folded to a normal angle by
//!   `vision_gradient::gradient_normal_deg`), weighted like the plain vote (a paired pixel
//!   `stripe_paired_votes` times). The pixels of a straight mark share its normal; those of
//!   texture, blobs and jagged borders do not add up to false lines any more;
//! - **gates the window pixels by orientation** (`track.orientation_tolerance_deg`): with the
//!   predicted slope `x̂′(y)`, the lane's normal at row `y` is `n = (1, −x̂′)`, and a pixel with
//!   gradient `g = (gx, gy)` is kept iff the angle between `g` and `±n` is at most `τ`:
//!
//!   ```text
//!       |g × n| ≤ tan τ · |g · n|,   g × n = −(gx·x̂′ + gy),   g · n = gx − gy·x̂′
//!   ```
//!
//!   (no angle computed per pixel). The edges of the mark pass; noise, texture and the outlines
//!   of objects crossing the window at another angle do not, so a band of rows the mark has left
//!   no longer holds enough pixels to pin the lane where it was (the noisy rendered scene, σ = 8:
//!   0.71 px mean error with the gate, 3.02 px without it; printed by
//!   `cargo test -p lane-eval --test tracking every_synthetic -- --nocapture`);
//! - **searches again over taller rows** (`roi.fallback_top_row_fraction`): a side still
//!   without a lane after the initialisation in the ROI is looked for over the rows from that
//!   fraction of the height down (gradient, candidates, coverage and choice as above, the side
//!   found in the ROI locked into the pair; the lane is refined, then tracked, over the same
//!   rows until it is initialised again from the ROI — tracked over the ROI's rows alone, a
//!   lane whose mark lies only above them would miss on every frame and be searched for again
//!   every other frame). A dashed mark whose near field falls in the gap between two dashes, or a camera
//!   tilted down so that a mark is visible only far ahead, is then found where it is. A fit
//!   needs as many rows as in the first search (a quarter of the ROI's, not of the taller
//!   rows': a dash far ahead is no longer there than one near the camera). A fit
//!   whose pixels all lie above the ROI starts as its chord over its rows, `x = a2·y + a3`: it
//!   is extrapolated down over the ROI, and a short far segment fixes a slope, not a curvature.
//!   The second search costs a second gradient, vote and choice, on the frames that need it
//!   only;
//! - **puts a double line's boundary on its middle** (`init.double_line_middle`; module
//!   `tracker::double_line`): after a fresh initialisation and its refinement, the image is
//!   read across the estimate row by row; where the mark under it has a second bright line
//!   beside it, parallel, a line width or two away and about as bright and as wide, on the
//!   same side in most rows, the estimate moves to the middle of the two (fitted as a shift
//!   linear in the row: the gap widens towards the camera), where lane labels put a double
//!   line; an estimate between the two lines (where the edge pixels of two narrow lines
//!   settle) is read from the brightest pixel within `w_max/2` on each side, and the pair is
//!   asked for on 30 % of the rows where the estimate lies inside the image and on 8 at least
//!   (development part 74.3 → 74.6 %, held out 77.0 → 77.9 %, `f1tenth` held out 79.6 →
//!   81.7 %);
//! - **puts a kerb's boundary on its foot** (`init.kerb_foot`; module `tracker::kerb`): after
//!   the same refinement (when the double line did not move the lane), the image is read across
//!   the estimate row by row; where the estimate lies on a step to a pavement wider than twice
//!   any mark, with a band of the inner level (the kerb's face) on the road side ending in a
//!   weaker edge of the same polarity `max(3, w_max/4)` to `w_max` px away (`w_max =
//!   gradient.stripe_max_width_px`, 16 in the default; the rise out of the groove at the foot,
//!   or onto a lighter face), consistently over at least 30 % of the rows, the boundary reported moves to that foot (a shift linear in the row), where the
//!   road ends and lane labels put the boundary; the filter keeps tracking the top edge its
//!   windows measure; on tracked frames the kerb is read again on every eighth row and the
//!   shift follows it, or is dropped after `track.lost_after_frames` frames without a kerb.
//!
//! `init.ego_pair.min_support_frac = 0.1` keeps a dashed ego mark beside a solid one (the real
//! udacity clip: both lanes on 220 of 221 stills initialised alone, 163 with 0.2). The presets
//! (`indoor`, `outdoor`, used by the rendered regression sequences) keep the paper's
//! initialisation. What each of these mechanisms earns on the labelled real sets, switched off
//! in turn and leave-one-set-out, is `docs/results/ablation.md` (`cargo xtask ablation`); the
//! decisions and figures behind each, `docs/lanes/history/`.
//!
//! ## Lanes in metres
//! [`camera`]: a camera configuration (pinhole intrinsics + mounting, or a measured ground-plane
//! homography) turns the two lanes' parabolas and their KIF covariances
//! ([`LaneTracker::lane_covariance_px`]) into the ego lane's lateral offset, heading, curvature
//! and width with standard deviations (`lane-geometry` crate); `lane-io` loads camera files and
//! draws the ground from above, `lane-scenes` renders roads from
//! known 3-D geometry for the round-trip tests.
//!
//! ## Working resolution (an addition beyond the paper; `frame.working_width_px`, default 320)
//! The paper's frames are 320×240, and so are the pixel fields of the default and the presets.
//! A frame of another width is resampled to exactly the working width, by any real factor, and
//! every report is mapped back to the input's pixels by the exact affine map of the coefficients
//! (module `tracker::working`, the derivation and figures there); `working_width_px = 0` tracks
//! every frame at its own size (the paper). [`LaneTracker::working_scale`] gives the factor and
//! [`LaneTracker::working_frame`] the last frame's working pixels, for diagnostics that must read
//! the frame as the stages do (`lane_bench::labelled::census_lanes`).
//!
//! ## Units of the configuration
//! See [`TrackerConfig`] and `configs/outdoor.toml` / `configs/indoor.toml`: every field
//! carries its unit; pixel fields are pixels of the working frame (320 px wide by default).
//!
//! ## Example
//! Two bright marks drawn on a dark floor, tracked over five frames:
//! ```
//! use lane_tracker::{Estimator, GreyFrame, LaneState, LaneTracker, TrackerConfig};
//!
//! let (w, h) = (320usize, 240usize);
//! // Left mark x = 100 + 0.45·(239 − y)… in image terms a `/`, right mark a `\`.
//! let left = |y: f64| 100.0 - 0.45 * (y - 239.0);
//! let right = |y: f64| 220.0 + 0.45 * (y - 239.0);
//! let mut pixels = vec![60u8; w * h];
//! for y in 0..h {
//!     for x in 0..w {
//!         let (xf, yf) = (x as f64, y as f64);
//!         if (xf - left(yf)).abs() < 2.5 || (xf - right(yf)).abs() < 2.5 {
//!             pixels[y * w + x] = 200;
//!         }
//!     }
//! }
//! let frame = GreyFrame::from_vec(w, h, pixels).expect("a whole frame");
//! let cfg = TrackerConfig::default_preset()?;
//! let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, w, h)?;
//! for _ in 0..5 {
//!     let report = tracker.track(&frame)?;
//!     for (lane, truth) in report.lanes.iter().zip([left, right]) {
//!         assert_eq!(lane.state, LaneState::Tracking);
//!         let x = lane.col_at_row(220.0).expect("a tracked lane has coefficients");
//!         assert!((x - truth(220.0)).abs() < 2.0, "{x} vs {}", truth(220.0));
//!     }
//! }
//! # Ok::<(), lane_tracker::TrackerError>(())
//! ```

pub mod camera;
mod config;
mod error;
mod tracker;
mod wrls_lane;

pub use config::{
    DEFAULT_TOML, DEFAULT_WORKING_WIDTH_PX, DenoiseConfig, ExposureConfig, FilterConfig,
    FrameConfig, GradientConfig, INDOOR_TOML, InitConfig, OUTDOOR_TOML, RoadBottom, RoiConfig,
    TrackConfig, TrackerConfig,
};
pub use error::{FilterFailure, TrackerError};
/// The workspace's one grey frame (crate `grey-frame`).
pub use grey_frame::{FrameError, GreyFrame};
pub use tracker::{
    Estimator, FarSegment, FrameExposure, FrameNoise, InitCandidate, LaneReport, LaneState,
    LaneTracker, LaneView, MAX_EXPOSURE_GAIN, RoadRefusal, RoadReport, Side, TrackReport,
    TrackerCounters,
};
