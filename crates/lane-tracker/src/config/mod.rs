//! Tracker configuration: TOML files and the `indoor` / `outdoor` presets.
//!
//! Every field carries its unit in its name or its doc. Unknown fields are refused
//! (`deny_unknown_fields`) and [`TrackerConfig::validate`] names the first field out of range.

use hough_init::{AngleBand, EgoPairParams, HoughError, HoughParams, LaneInitParams};
use serde::{Deserialize, Serialize};
use toml_config::TomlDoc;
use vision_gradient::{GradientError, GradientParams, Threshold};

use crate::TrackerError;

/// The default configuration (`nav-app` with no `--config`), as shipped in `configs/default.toml`.
pub const DEFAULT_TOML: &str = include_str!("../../../../configs/default.toml");
/// The `outdoor` preset (highway, strong light/shadow contrast), as shipped in `configs/outdoor.toml`.
pub const OUTDOOR_TOML: &str = include_str!("../../../../configs/outdoor.toml");
/// The `indoor` preset (corridor floor lines, low contrast), as shipped in `configs/indoor.toml`.
pub const INDOOR_TOML: &str = include_str!("../../../../configs/indoor.toml");

/// Stage I: directional gradient (3×3 Sobel; see the `vision-gradient` crate).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GradientConfig {
    /// Threshold on the Sobel L1 magnitude `|gx| + |gy|`, grey levels (0..=2040; an ideal 45°
    /// step of `h` grey levels gives `6h`). With the adaptive mode it is the floor. (Ranges of
    /// this section are `vision_gradient::GradientParams::validate`'s: see [`Self::params`].)
    pub magnitude_threshold: u16,
    /// Adaptive threshold: keep this fraction of the in-band pixels of the searched region (the
    /// `1 − f` quantile of their magnitudes, floored at `magnitude_threshold`), in (0, 1].
    /// 0 disables it (fixed threshold).
    pub adaptive_keep_fraction: f64,
    /// Edge directions kept: the angle of the edge line from the image horizontal must lie in
    /// [`min_edge_angle_deg`, `max_edge_angle_deg`], degrees (0 ≤ min < max ≤ 90). The Hough
    /// search of each lane uses the matching band of line tilts from the vertical,
    /// `±[90 − max, 90 − min]`.
    pub min_edge_angle_deg: f64,
    /// Upper limit of the edge-line angle band, degrees.
    pub max_edge_angle_deg: f64,
    /// Stripe pairing (an addition beyond the paper; `vision_gradient::keep_bright_stripes`):
    /// keep only edge pixels that pair, along their row, with an edge of the same class and the
    /// opposite polarity within this many columns (rising on the left, falling on the right:
    /// the two sides of a bright mark), px, 0..=200; 0 (default when absent) keeps every edge
    /// pixel (the paper). Also the widest mark and the widest kerb face for `init.kerb_foot`,
    /// which needs at least 4 px, and the widest stripe `init.stripe_trace` follows, which
    /// needs at least 2 px.
    #[serde(default)]
    pub stripe_max_width_px: u16,
    /// With stripe pairing that drops unpaired pixels (`stripe_paired_votes = 0`): also keep
    /// an unpaired edge pixel whose bright side faces away from the image's middle column (a
    /// kerb or road edge, the road being the darker side towards the middle). Default `false`.
    #[serde(default)]
    pub stripe_keep_outward_steps: bool,
    /// With stripe pairing: 0 (default when absent) drops the unpaired edge pixels; `k` in
    /// 1..=4 keeps them instead and lets the paired ones count `k` times in the initialisation
    /// (Hough votes and least squares) against once for an unpaired one (kerbs and road edges
    /// still count, marks count more); tracking windows then keep every pixel. Votes per pixel.
    #[serde(default)]
    pub stripe_paired_votes: u8,
    /// With `stripe_paired_votes > 0`: drop the edge pixels that bound only a dark stripe at
    /// most `stripe_max_width_px` wide (the seam beside a mark, a tar joint, a crack); single
    /// steps still count. Default `false`.
    #[serde(default)]
    pub stripe_drop_dark: bool,
    /// Periodic stripes (an addition beyond the paper; `vision_gradient::drop_periodic_stripes`):
    /// before the initialisation's vote, drop the edge pixels of every chain of at least this
    /// many bright stripes along a row, neighbours within a factor 2 in width and at most three
    /// widths apart, that a chain on an adjacent row overlaps, on its row and the two adjacent
    /// ones (a crosswalk, road text, a railing; a double line is two). Count, 0 or 3..=16;
    /// 0 (default when absent) drops nothing. Tracking windows are not filtered.
    #[serde(default)]
    pub periodic_min_stripes: usize,
    /// Widest stripe of such a chain, px (along the row), 1..=200. Default 48 when absent.
    #[serde(default = "default_periodic_max_width_px")]
    pub periodic_max_width_px: u16,
}

fn default_periodic_max_width_px() -> u16 {
    48
}

/// Region of interest: the rows where lanes are looked for (the sky is not lane).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoiConfig {
    /// First row of the ROI as a fraction of the image height (0 = top row), dimensionless in [0, 1).
    pub top_row_fraction: f64,
    /// One past the last ROI row as a fraction of the height (1 = down to the bottom row), in (top, 1].
    pub bottom_row_fraction: f64,
    /// Beyond the paper: a side still without a lane after the initialisation in the ROI is
    /// looked for again from this fraction of the height down to `bottom_row_fraction`
    /// (gradient, Hough candidates and choice over the taller region, the side found in the ROI
    /// kept in the pair): a dashed mark whose near field falls in a gap between dashes, or a
    /// camera looking down with the road's far part above the ROI. Its windowed refinement runs
    /// over the same rows, and so does its tracking until it is initialised again from the ROI
    /// (its mark may lie above the ROI only). Dimensionless in `[0, top_row_fraction)`; absent (the default when
    /// absent) = no second search.
    #[serde(default)]
    pub fallback_top_row_fraction: Option<f64>,
    /// Beyond the paper: where the road's lowest row is (absent = `"frame"`, the paper's: the
    /// frame's last row). `"found"`: found on every frame that initialises both lanes — the
    /// edge of a bonnet or a dashboard in view — and the fractions above taken of the road's
    /// rows, not the frame's (module `tracker::road`).
    #[serde(default)]
    pub road_bottom: RoadBottom,
}

/// Where the road's lowest row is taken from (`roi.road_bottom`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RoadBottom {
    /// The frame's last row (the paper's camera sees road down to it).
    #[default]
    Frame,
    /// Found on each frame that initialises both lanes (module `tracker::road`).
    Found,
}

/// Stage II: Hough + least-squares (re-)initialisation (see the `hough-init` crate). The ranges
/// are `hough_init::HoughParams::validate`'s and `hough_init::LaneInitParams::validate`'s (see
/// [`Self::hough_params`], [`Self::lane_params`]): one check, in the crate that uses the value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitConfig {
    /// Hough angle resolution, degrees ([0.01, 10]).
    pub theta_step_deg: f64,
    /// Hough distance resolution, px ([0.1, 50]).
    pub rho_step_px: f64,
    /// Half-width of the band around the Hough line whose pixels are fitted by LS, px ((0, 1000]).
    pub band_half_width_px: f64,
    /// Fewest pixels in the band for an initialisation to be accepted (≥ 3).
    pub min_points: usize,
    /// Refits of the LS parabola to the pixels within `band_half_width_px` of the previous fit
    /// (follows a curved mark beyond the straight Hough band), 0..=10; 0 disables.
    pub refit_iterations: u32,
    /// Joint initialisation (an addition beyond the paper): Hough candidate lines taken per
    /// angle band (non-maximum suppression, `hough_init::HoughWorkspace::find_lines`), the ego
    /// pair then chosen among the candidates of both bands by `init.ego_pair`
    /// (`hough_init::choose_ego_pair`), each lane's side given by its position, not its lean;
    /// tracking then takes, per row, the edge class of the predicted slope. Count, 0..=8;
    /// 0 (default when absent): the paper's best line per band, left = `/`, right = `\`.
    #[serde(default)]
    pub candidate_lines: usize,
    /// Non-maximum suppression between candidate lines: angle, degrees (≥ 0).
    #[serde(default = "default_separation_deg")]
    pub candidate_separation_deg: f64,
    /// Non-maximum suppression between candidate lines: normal distance ρ, px (≥ 0).
    #[serde(default = "default_separation_px")]
    pub candidate_separation_px: f64,
    /// Joint initialisation: orientation-restricted Hough vote (an addition beyond the paper;
    /// `hough_init::HoughWorkspace::find_lines_oriented`). Each candidate pixel votes only for
    /// the lines whose normal lies within this many degrees of its own Sobel gradient direction
    /// (stored with the pixel: `vision_gradient::EdgePixel::gradient`, folded to a normal angle
    /// by `vision_gradient::gradient_normal_deg`), instead of for every line of its band: the pixels
    /// of a straight mark share its direction and keep their votes, those of texture, blobs and
    /// jagged borders point every way and no longer add up to strong false lines. Degrees,
    /// 0..=90; 0 (default when absent) votes across the whole band (the paper). The per-pixel
    /// angle spreads by several degrees on real edges: values much below 10° lose marks.
    #[serde(default)]
    pub orientation_tolerance_deg: f64,
    /// Joint initialisation: how a candidate line is weighed for the ego pair. `false` (default
    /// when absent): by its Hough line (its columns at the top and bottom ROI rows) and its Hough
    /// votes (near-field straight-line evidence). `true`: by the least-squares parabola fitted
    /// around it (as an initialisation would) — its columns at the top and bottom ROI rows, and
    /// its row coverage: the sum over the ROI rows of the candidate pixels (stripe-paired ones
    /// counted `gradient.stripe_paired_votes` times) within `band_half_width_px` of the
    /// parabola, at most `2·max(stripe_paired_votes, 1)` per row (both edges of a paired mark),
    /// the unpaired ones at most 2 per row when `stripe_paired_votes ≥ 2` (a step's worth),
    /// so a line seen over the whole ROI beats a short strong one; net of the clutter beside
    /// it (minus the mean coverage of the parallel curves `3·band_half_width_px` to each side,
    /// at least 0), so a line through texture counts for little. A candidate whose fit fails
    /// is not considered.
    #[serde(default)]
    pub candidate_coverage: bool,
    /// The plausible ego lane (`hough_init::EgoPairParams`; widths are fractions of the image
    /// width, dimensionless), used when `candidate_lines > 0`.
    #[serde(default)]
    pub ego_pair: EgoPairParams,
    /// An addition beyond the paper: after a fresh initialisation and its refinement, a lane
    /// whose rows show a second bright line beside its own, parallel, a line width or two
    /// away (a double line), or that lies between two such lines, is moved to the middle of the
    /// two, where lane labels put such a boundary (the image is read across the estimate row by
    /// row; the pair must show on 30 % of the rows where the estimate lies inside the image, and
    /// on 8 at least; module `tracker::double_line`). Default `false` when absent.
    #[serde(default)]
    pub double_line_middle: bool,
    /// An addition beyond the paper: after a fresh initialisation and its refinement (and the
    /// double line's middle, when that did not move it), a lane on the top edge of a raised
    /// kerb — a step to a pavement wider than twice the widest mark
    /// (`gradient.stripe_max_width_px`, at least 4 px with this on), with the kerb's face a
    /// few pixels wide on the road side and a weaker edge of the same polarity at its foot, consistently over
    /// the rows — is reported on the foot, where the road ends and lane labels put the
    /// boundary, while its filter keeps tracking the top edge (the image is read across the
    /// estimate row by row; `lane_tracker` crate docs). Default `false` when absent.
    #[serde(default)]
    pub kerb_foot: bool,
    /// An addition beyond the paper: `true`: after the windowed refinement that follows an
    /// initialisation (before the double line's middle and the kerb's foot), a lane whose
    /// parabola turns back below its points — its vertex (vertical image tangent) lies between
    /// the lowest point's row and the bottom row searched, at a column inside the image — is
    /// replaced by the least-squares line through those points: nothing was measured there, and
    /// a lane does not turn back between its evidence and the camera (module
    /// `tracker::turn_back`). Tracked frames keep the filter's estimate. `false` (default when
    /// absent): the refined parabola as it is (the paper).
    #[serde(default)]
    pub no_turn_back: bool,
    /// An addition beyond the paper: `true`: after the windowed refinement that follows an
    /// initialisation (before no turn back, the double line's middle and the kerb's foot), the
    /// bright stripe under the lane is followed row by row from the lane's evidence (a rising
    /// and a falling edge of at least `gradient.magnitude_threshold / 4` grey levels, and 1 at
    /// least, in central difference, at most `gradient.stripe_max_width_px` apart, needing at
    /// least 2 px; from one row to the next within an eighth of that width, 1 px at least),
    /// and its middles, one a row, are one more update of the lane's KIF (module
    /// `tracker::stripe_trace`): a lane pulled off a tape by the texture beside it, or held
    /// on the rows its first fit saw, is brought back onto the stripe where it runs on.
    /// Tracked frames, WRLS lanes, mark centres and the second search's lanes keep the
    /// paper's measurement. `false` (default when absent): no trace (the paper).
    #[serde(default)]
    pub stripe_trace: bool,
}

fn default_separation_deg() -> f64 {
    3.0
}

fn default_separation_px() -> f64 {
    8.0
}

impl GradientConfig {
    /// The `vision-gradient` parameters this section stands for (`adaptive_keep_fraction` 0 →
    /// fixed threshold; any other value is the adaptive mode's keep fraction, which
    /// `GradientParams::validate` checks).
    pub fn params(&self) -> GradientParams {
        let threshold = if self.adaptive_keep_fraction == 0.0 {
            Threshold::Fixed {
                min_magnitude: self.magnitude_threshold,
            }
        } else {
            Threshold::Adaptive {
                keep_fraction: self.adaptive_keep_fraction,
                min_magnitude: self.magnitude_threshold,
            }
        };
        GradientParams {
            min_edge_angle_deg: self.min_edge_angle_deg,
            max_edge_angle_deg: self.max_edge_angle_deg,
            threshold,
        }
    }

    /// The periodic-stripe rule of `periodic_min_stripes` and `periodic_max_width_px` (the other
    /// bounds are `vision_gradient::PeriodicStripeParams`'s defaults).
    pub fn periodic_params(&self) -> vision_gradient::PeriodicStripeParams {
        vision_gradient::PeriodicStripeParams {
            min_stripes: self.periodic_min_stripes,
            max_width_px: f64::from(self.periodic_max_width_px),
            ..Default::default()
        }
    }

    /// The Hough θ bands of the left and right lanes that match the edge-angle band: line tilts
    /// from the vertical `±[90 − max, 90 − min]`.
    pub fn hough_bands(&self) -> [AngleBand; 2] {
        let lo = 90.0 - self.max_edge_angle_deg;
        let hi = 90.0 - self.min_edge_angle_deg;
        [AngleBand::new(lo, hi), AngleBand::new(-hi, -lo)]
    }
}

impl InitConfig {
    /// The `hough-init` accumulator parameters (peak smoothing and sub-bin refinement on).
    pub fn hough_params(&self) -> HoughParams {
        HoughParams {
            theta_step_deg: self.theta_step_deg,
            rho_step_px: self.rho_step_px,
            ..HoughParams::default()
        }
    }

    /// The `hough-init` least-squares parameters.
    pub fn lane_params(&self) -> LaneInitParams {
        LaneInitParams {
            band_px: self.band_half_width_px,
            min_points: self.min_points,
            refit_iterations: self.refit_iterations,
        }
    }
}

/// Stage III: windows of interest, point gathering, gates and re-initialisation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackConfig {
    /// Half-width of the window of interest around the predicted parabola, px (> 0), at every row.
    pub window_half_width_px: usize,
    /// Most points per lane per frame fed to the filter, spread over the rows (paper: 150), 3..=1000.
    pub max_points_per_lane: usize,
    /// Inside the window, pixels farther than this from the midhinge residual (mean of the quartiles) of their third of
    /// the ROI rows are dropped as clutter before the update, px (> 0).
    pub inlier_half_width_px: f64,
    /// A tracked lane with fewer points than this in a frame misses that frame (≥ 3).
    pub reinit_min_points: usize,
    /// Consecutive missed frames after which a lane is declared lost and re-initialised (≥ 1).
    pub lost_after_frames: u32,
    /// Gate: an update moving the lane by more than this (px, at the top or bottom ROI row) from
    /// its prediction is rejected (> 0; counts as a missed frame).
    pub max_jump_px: f64,
    /// Left and right lanes must stay at least this far apart at the middle and bottom ROI rows
    /// (and in order at the row `init.ego_pair.meet_top_frac` of the ROI rows down from its
    /// top: the top row for 0), px (≥ 0).
    pub min_lane_separation_px: f64,
    /// Orientation gate on the window pixels (an addition beyond the paper): a pixel enters the
    /// measurement only if its Sobel gradient (`vision_gradient::EdgePixel::gradient`) lies within
    /// this many degrees of the predicted lane's normal at its row, i.e. its edge runs along the
    /// predicted lane. The edges of the mark pass; sensor noise, texture and the outlines of
    /// objects crossing the window at another angle (a car's rear, a crosswalk stripe) do not,
    /// so a band of rows the mark has left holds too few pixels to pin the lane where it was.
    /// Degrees, 0..=90; 0 (default when absent) keeps every window pixel of the lane's class
    /// (the paper).
    #[serde(default)]
    pub orientation_tolerance_deg: f64,
    /// `true`: measure one sub-pixel mark centre per row (or the sub-pixel position of a single
    /// step edge) and give the KIF the measured point scatter as `R` (an addition beyond the
    /// paper, crate docs "Mark centres"); `false` (default when absent): the paper's integer
    /// edge pixels with `R = filter.r_sigma_px²·I`.
    #[serde(default)]
    pub mark_centres: bool,
    /// `true`: in the windowed refinement that follows an initialisation, an edge pixel that
    /// bounds a bright stripe more than `inlier_half_width_px` and at most
    /// `gradient.stripe_max_width_px` wide whose two sides are alike (a mark on the floor, not a
    /// kerb's face) measures the stripe's middle, not its own column, so a lane whose Hough line
    /// lay on one edge of a wide mark is refined onto its middle (an addition beyond the paper,
    /// crate docs "Stripe middles"); tracked frames keep the paper's edge pixels. `false`
    /// (default when absent): the paper's edge pixels. No effect with `mark_centres`, which
    /// measure the middle themselves, or with `gradient.stripe_max_width_px` at most
    /// `inlier_half_width_px` (no stripe both wide enough and paired).
    #[serde(default)]
    pub stripe_middles: bool,
    /// Half-width of the window of the windowed refinement that follows an initialisation on
    /// the same frame, px (1..=200; an addition beyond the paper); 0 (default when absent):
    /// `window_half_width_px`.
    #[serde(default)]
    pub refine_window_half_width_px: usize,
    /// Windowed refinements after an initialisation on the same frame, 1..=5 (default 1 when
    /// absent; 0 is read as 1).
    #[serde(default)]
    pub refine_passes: u32,
    /// Re-validation (an addition beyond the paper; joint initialisation with
    /// `init.candidate_coverage` only, never otherwise): while both
    /// lanes are tracked, every this many frames the whole ROI goes through the joint
    /// initialisation and the tracked lanes compete with its candidates for the ego pair; a
    /// lane the choice replaces by a candidate on another mark is initialised there (and, with
    /// re-validation on — this or `revalidate_below_points`, [`TrackConfig::revalidates`] — a
    /// tracked lane competes so too when the other side is initialised again). Frames,
    /// 0..=100000; 0 (default when absent): no period (with `revalidate_below_points` also 0,
    /// never: the paper, a lane is re-initialised only when lost).
    #[serde(default)]
    pub revalidate_every_frames: u32,
    /// When a tracked lane competes with the candidates (a re-validation, or the other side's
    /// initialisation with re-validation on), its row coverage counts this many times (≥ 1,
    /// finite; default 3 when absent): a candidate replaces it only when clearly stronger, not
    /// on the frame-to-frame noise of the choice.
    #[serde(default = "default_revalidate_keep_factor")]
    pub revalidate_keep_factor: f64,
    /// Re-validation on weak evidence (an addition beyond the paper; as
    /// `revalidate_every_frames`, joint initialisation with `init.candidate_coverage` only):
    /// while both lanes are tracked, a frame on which a tracked lane's window gave fewer
    /// points than this (a miss, a jump-gated or refused update counting 0) is re-validated at
    /// once, not at the period's next frame. A lane that slid onto clutter or whose mark left
    /// the window keeps few points for a few frames before it misses often enough to be lost;
    /// a lane on a solid mark in a camera image fills its window (up to `max_points_per_lane`)
    /// and does not trigger it, a dashed mark between two dashes may (a re-validation keeps a
    /// lane on its own mark). In the ROI's choice a tracked lane competes in (a re-validation,
    /// or the other side's initialisation with re-validation on), a lane this weak on this
    /// frame and the one before that the choice keeps nothing of (neither kept nor replaced)
    /// is set aside while the second search (over `roi.fallback_top_row_fraction`'s rows)
    /// looks for its side on the same frame; if that finds nothing (or there is no second
    /// search) it is put back as it was. A lane weak on one frame only (a dropout) coasts, as
    /// it did: the second search would initialise it from the far field above an occlusion of
    /// the ROI; a longer occlusion is searched for from its second frame (a lost lane's
    /// initialisation, from its third). Points, `0..=max_points_per_lane`; 0 (default
    /// when absent): the period only.
    #[serde(default)]
    pub revalidate_below_points: usize,
    /// The period's re-validation spread over the period's frames (an addition beyond the
    /// paper; with `revalidate_every_frames` ≥ 2): its work — the ROI's gradient, each band's
    /// pixels, vote and candidates' fits — cut into ten steps done on the frames of the period,
    /// on the edges of its first frame, and the choice on its last frame, the frame the whole
    /// re-validation would run on; if that choice would change a lane (its evidence a period
    /// old), the whole re-validation runs at once on that frame and changes it or not. A frame
    /// then costs a tenth of a re-validation more instead of every tenth frame costing a whole
    /// one (module `tracker::revalidation`). The weak-evidence trigger
    /// (`revalidate_below_points`) stays whole and immediate. `false` (default when absent):
    /// the whole re-validation on the period's frame.
    #[serde(default)]
    pub revalidate_spread: bool,
}

fn default_revalidate_keep_factor() -> f64 {
    3.0
}

impl TrackConfig {
    /// Whether re-validation is on: a period (`revalidate_every_frames`) or a trigger on weak
    /// evidence (`revalidate_below_points`).
    pub fn revalidates(&self) -> bool {
        self.revalidate_every_frames > 0 || self.revalidate_below_points > 0
    }

    /// The window half-width of the refinement after an initialisation, px.
    pub fn refine_window_half_width(&self) -> usize {
        if self.refine_window_half_width_px == 0 {
            self.window_half_width_px
        } else {
            self.refine_window_half_width_px
        }
    }
}

/// Filter noise models (KIF and WRLS).
///
/// The filters' coefficients are expressed internally in a normalised row coordinate
/// `u = (y − y_c)/s`, with `y_c` the middle ROI row and `s` half the ROI height, so that
/// `x = b1·u² + b2·u + b3` with `b1`, `b2`, `b3` all in pixels over `u ∈ [−1, 1]`. Q and P0 are
/// given as standard deviations of those coefficients and mapped to the paper's pixel
/// coefficients `(a1, a2, a3)` by the linear map between the two parameterisations.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilterConfig {
    /// Random-walk standard deviation per frame of `(b1, b2, b3)`, px/frame (each > 0). Q = diag(σ²).
    pub q_sigma_px: [f64; 3],
    /// Standard deviation of one pixel measurement (column of an edge pixel about the lane), px (> 0).
    /// R = σ²·I; with `track.mark_centres` the KIF estimates R from the points instead and uses
    /// this only for frames with fewer than 8 points.
    pub r_sigma_px: f64,
    /// Initial standard deviation of `(b1, b2, b3)` after an initialisation, px (each > 0).
    pub p0_sigma_px: [f64; 3],
    /// WRLS forgetting factor per frame, in (0, 1] (paper: 0.70).
    pub wrls_lambda: f64,
}

/// The resolution the tracker works at (an addition beyond the paper, whose frames are the
/// BT848's 320×240): every pixel-valued field of the configuration is in pixels of the
/// **working frame**: the input resampled to exactly `working_width_px` wide, by `s = input
/// width / working_width_px` input pixels per working pixel along both axes, any real (area
/// average down, linear interpolation up to 2×; at most a third of either side; module
/// `tracker::working`). Reports stay in input pixels.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FrameConfig {
    /// The working width, px: 320 (the default when absent; the presets and the default are
    /// tuned there), 16..=16384, or 0: track every frame at its own size (the paper; pixel
    /// fields then mean input pixels, and a user scales them with
    /// [`TrackerConfig::scale_pixels`]).
    pub working_width_px: usize,
}

/// Working width of the default and the presets, px.
pub const DEFAULT_WORKING_WIDTH_PX: usize = 320;

impl Default for FrameConfig {
    fn default() -> Self {
        FrameConfig {
            working_width_px: DEFAULT_WORKING_WIDTH_PX,
        }
    }
}

/// The frame's noise (an addition beyond the paper; module `tracker::denoise`): measured on the
/// rows searched when a scene starts and every 30 frames, and the working frame smoothed where it
/// is far above what the grey-level settings assume. Absent: never.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DenoiseConfig {
    /// Noise σ̂ (the robust Laplacian estimate), grey levels, above which the frame is smoothed
    /// by a 3 × 3 binomial before the stages read it; 0 = never (the
    /// default when absent).
    pub above_noise_grey: f64,
}

/// The frame's exposure (an addition beyond the paper; module `tracker::exposure`): the median
/// grey of the rows searched, measured on every frame, and a frame darker than the exposures the
/// settings were tuned on brightened up to them. Absent: never.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExposureConfig {
    /// Median grey of the rows searched, grey levels, below which the frame's grey levels are
    /// multiplied by `below_median_grey / median` (at most 2) before the stages read them; 0 =
    /// never (the default when absent).
    pub below_median_grey: f64,
}

/// The whole tracker configuration (one TOML file).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackerConfig {
    /// The working resolution (`[frame]`; absent: 320 px wide).
    #[serde(default)]
    pub frame: FrameConfig,
    /// The frame's exposure (`[exposure]`; absent: never brightened).
    #[serde(default)]
    pub exposure: ExposureConfig,
    /// The frame's noise (`[denoise]`; absent: never smoothed).
    #[serde(default)]
    pub denoise: DenoiseConfig,
    /// Stage I.
    pub gradient: GradientConfig,
    /// Rows searched.
    pub roi: RoiConfig,
    /// Stage II.
    pub init: InitConfig,
    /// Stage III.
    pub track: TrackConfig,
    /// Noise models.
    pub filter: FilterConfig,
}

/// Parse `text` (file `name`) with the workspace's one TOML loader and validate it: every error
/// is a [`TrackerError::ConfigFile`] naming the file, line and column — syntax, unknown, missing or
/// mistyped keys, and the first field out of range (located at its key). Shared by every lane
/// configuration file (tracker, camera).
pub(crate) fn parse_validated<T: serde::de::DeserializeOwned>(
    name: &str,
    text: &str,
    validate: impl FnOnce(&T) -> Result<(), TrackerError>,
) -> Result<T, TrackerError> {
    let doc = TomlDoc::parse(name, text).map_err(TrackerError::ConfigFile)?;
    let cfg: T = doc.deserialize().map_err(TrackerError::ConfigFile)?;
    validate(&cfg).map_err(|e| {
        // A field error of any kind is located at its key (`TrackerError::config_field`).
        let Some(field) = e.config_field() else {
            return e;
        };
        let what = match &e {
            TrackerError::ConfigField { value, reason, .. } => format!(" = {value}: {reason}"),
            other => {
                std::error::Error::source(other).map_or_else(String::new, |s| format!(": {s}"))
            }
        };
        TrackerError::ConfigFile(doc.error_at(field, format!("`{field}`{what}")))
    })?;
    Ok(cfg)
}

impl TrackerConfig {
    /// The default configuration (`configs/default.toml`): what `nav-app` runs with no
    /// `--config`, meant to need no preset on roads and indoor floors alike.
    pub fn default_preset() -> Result<Self, TrackerError> {
        Self::from_toml_str("preset default", DEFAULT_TOML)
    }

    /// The `outdoor` preset.
    pub fn outdoor() -> Result<Self, TrackerError> {
        Self::from_toml_str("preset outdoor", OUTDOOR_TOML)
    }

    /// The `indoor` preset.
    pub fn indoor() -> Result<Self, TrackerError> {
        Self::from_toml_str("preset indoor", INDOOR_TOML)
    }

    /// Parse and validate TOML text; `name` (the file path) is used in errors. Every error is a
    /// [`TrackerError::ConfigFile`] naming `name`, the line and the column: syntax, unknown, missing
    /// or mistyped keys, and fields out of range (located at their key).
    pub fn from_toml_str(name: &str, text: &str) -> Result<Self, TrackerError> {
        parse_validated(name, text, Self::validate)
    }

    /// Names of the compiled-in presets, for [`Self::preset`].
    pub const PRESETS: [&'static str; 3] = ["default", "outdoor", "indoor"];

    /// The preset `name` (`default`, `outdoor`, `indoor`), or `None` for any other name (a file
    /// path, for `lane-io` to read).
    pub fn preset(name: &str) -> Option<Result<Self, TrackerError>> {
        match name {
            "default" => Some(Self::default_preset()),
            "outdoor" => Some(Self::outdoor()),
            "indoor" => Some(Self::indoor()),
            _ => None,
        }
    }

    /// Multiply every pixel-valued parameter by `k` (> 0): the presets are tuned for 320-px-wide
    /// frames, which the tracker works at by default whatever the input's size
    /// (`frame.working_width_px`); with `frame.working_width_px = 0` (tracking at the input's own
    /// size) a 1280-px frame takes `k = 4`. The working width itself is not scaled. Scaled: window and inlier half-widths, jump
    /// gate, lane separation, Hough band and candidate separation, stripe width and the periodic
    /// stripes' widest (at least 4 px
    /// with `init.kerb_foot`, which reads a kerb's face within it, and 2 px with
    /// `init.stripe_trace`: with either on, a width of 0 — no pairing — becomes that floor),
    /// R, Q and P0 standard
    /// deviations. Not scaled: the gradient threshold (grey levels), the Hough distance
    /// resolution `init.rho_step_px` (a bin size), fractions, angles, counts.
    pub fn scale_pixels(&mut self, k: f64) {
        let t = &mut self.track;
        t.window_half_width_px = ((t.window_half_width_px as f64 * k).round() as usize).max(1);
        t.refine_window_half_width_px =
            ((t.refine_window_half_width_px as f64 * k).round() as usize).min(200);
        t.inlier_half_width_px *= k;
        t.max_jump_px *= k;
        t.min_lane_separation_px *= k;
        self.init.band_half_width_px *= k;
        self.init.candidate_separation_px *= k;
        let g = &mut self.gradient;
        g.stripe_max_width_px = (f64::from(g.stripe_max_width_px) * k).round().min(200.0) as u16;
        g.periodic_max_width_px = (f64::from(g.periodic_max_width_px) * k)
            .round()
            .clamp(1.0, 200.0) as u16;
        if self.init.kerb_foot {
            // The kerb's reading needs a face range (validated ≥ 4 px).
            g.stripe_max_width_px = g.stripe_max_width_px.max(4);
        }
        if self.init.stripe_trace {
            // The trace needs a stripe with two edges (validated ≥ 2 px).
            g.stripe_max_width_px = g.stripe_max_width_px.max(2);
        }
        let f = &mut self.filter;
        f.r_sigma_px *= k;
        f.q_sigma_px = f.q_sigma_px.map(|q| q * k);
        f.p0_sigma_px = f.p0_sigma_px.map(|q| q * k);
    }

    /// The ROI row range `[top, bottom)` for an image `height_px` rows high (at least 3 rows).
    pub fn roi_rows(&self, height_px: usize) -> (usize, usize) {
        let top = ((self.roi.top_row_fraction * height_px as f64).floor() as usize)
            .min(height_px.saturating_sub(3));
        let bottom = ((self.roi.bottom_row_fraction * height_px as f64).ceil() as usize)
            .clamp(top + 3, height_px.max(top + 3));
        (top, bottom.min(height_px))
    }

    /// The rows `[top, bottom)` of the second search (`roi.fallback_top_row_fraction`) for an
    /// image `height_px` rows high: from that fraction of the height down to the ROI's bottom,
    /// never starting below the ROI's top. `None` without a second search.
    pub fn fallback_roi_rows(&self, height_px: usize) -> Option<(usize, usize)> {
        let (top, bottom) = self.roi_rows(height_px);
        self.roi
            .fallback_top_row_fraction
            .map(|f| (((f * height_px as f64).floor() as usize).min(top), bottom))
    }
}

mod validate;

#[cfg(test)]
mod tests;
