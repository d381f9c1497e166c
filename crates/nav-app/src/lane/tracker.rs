//! The tracking loop (paper Fig. 1): directional gradient → Hough + LS initialisation → KIF
//! (or WRLS) recursion, per lane, with a state machine and sanity gates.

use hough_init::{AngleBand, HoughWorkspace, LaneInitParams, Parabola, init_lane};
use info_filter::{ParabolaKif, PowerSums, ProcessNoise, RowNorm, ThetaCov};
use lane_geometry::{FIT_SAMPLES, FitRows};
use nalgebra::{Matrix3, Vector3};
use serde::Serialize;
use vision_gradient::{ColSpan, EdgeBuffer, EdgeClass, GradientDetector, GreyImage, Region};

use crate::{GreyFrame, NavError, TrackerConfig};

/// Which lane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// The left lane mark (edge class [`EdgeClass::LeftLane`], a `/` in the image).
    Left,
    /// The right lane mark (edge class [`EdgeClass::RightLane`], a `\` in the image).
    Right,
}

/// Per-lane state, reported every frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LaneState {
    /// No estimate yet: the first initialisation has not succeeded.
    Initialising,
    /// Updated from this frame's points (or initialised on this frame).
    Tracking,
    /// Too few points (or a gated update) this frame, for fewer than
    /// `track.lost_after_frames` frames in a row: the reported coefficients are the prediction.
    Coasting,
    /// Too many missed frames in a row: no coefficients are reported and the lane is
    /// re-initialised (Hough + LS over the whole region of interest) every frame until it is found.
    Lost,
}

impl LaneState {
    /// Lowercase name, as in the JSON output.
    pub fn name(self) -> &'static str {
        match self {
            LaneState::Initialising => "initialising",
            LaneState::Tracking => "tracking",
            LaneState::Coasting => "coasting",
            LaneState::Lost => "lost",
        }
    }
}

/// The recursive estimator of the lane coefficients.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Estimator {
    /// Kalman information filter, positive-definite form (paper eqs. 6–12, 24). The default.
    #[default]
    Kif,
    /// Exponentially weighted recursive least squares (paper eqs. 25–27), λ =
    /// `filter.wrls_lambda`, applied once per frame.
    Wrls,
}

/// One lane's result for one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LaneReport {
    /// Which lane.
    pub side: Side,
    /// Its state after this frame.
    pub state: LaneState,
    /// `[a1, a2, a3]` of `x = a1·y² + a2·y + a3` (x column, y row, pixels of the input image);
    /// `None` when the lane is [`LaneState::Initialising`] or [`LaneState::Lost`].
    pub coeffs: Option<[f64; 3]>,
    /// `[y_min, y_max]`, rows (px) of the points behind the estimate (last update or initialisation).
    pub rows: [f64; 2],
    /// Points used this frame (filter update, or LS fit of an initialisation); 0 when missed.
    pub points: usize,
    /// `true` if the lane was (re-)initialised by Hough + LS on this frame.
    pub initialised: bool,
}

impl LaneReport {
    /// Column of the reported parabola at `row_px`, if there is one.
    pub fn col_at_row(&self, row_px: f64) -> Option<f64> {
        self.coeffs
            .map(|c| Parabola::from_coeffs(c).col_at_row(row_px))
    }
}

/// The tracker's result for one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TrackReport {
    /// Left then right.
    pub lanes: [LaneReport; 2],
    /// `true` if the full region of interest went through the gradient (an initialisation was
    /// attempted); `false` on a pure tracking frame (gradient inside the windows only).
    pub full_gradient: bool,
}

/// Counters over the tracker's life.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct TrackerCounters {
    /// Frames processed.
    pub frames: u64,
    /// Successful initialisations per lane (left, right), the first one included.
    pub initialisations: [u64; 2],
    /// Updates rejected by the jump gate, per lane.
    pub gated_jumps: [u64; 2],
    /// Estimates rejected because the lanes crossed, per lane.
    pub gated_crossings: [u64; 2],
    /// Filter failures (numerical: a non-positive-definite matrix), per lane.
    pub filter_failures: [u64; 2],
}

/// The per-lane recursive estimator state.
#[derive(Debug, Clone)]
enum LaneFilter {
    Kif(ParabolaKif),
    Wrls(super::wrls_lane::WrlsLane),
}

impl LaneFilter {
    fn col_at_row(&self, row_px: f64) -> f64 {
        match self {
            LaneFilter::Kif(k) => k.col_at_row_px(row_px),
            LaneFilter::Wrls(w) => w.col_at_row_px(row_px),
        }
    }
    fn coeffs(&self) -> [f64; 3] {
        let v = match self {
            LaneFilter::Kif(k) => k.estimate(),
            LaneFilter::Wrls(w) => w.estimate(),
        };
        [v[0], v[1], v[2]]
    }
}

#[derive(Debug)]
struct Lane {
    side: Side,
    class: EdgeClass,
    band: AngleBand,
    state: LaneState,
    filter: Option<LaneFilter>,
    predicted: Option<LaneFilter>,
    misses: u32,
    points: Vec<(f32, f32)>,
    /// Relative precision `1/v` of each point of `points` after a tracking update
    /// ([`mark_centre`]).
    weights: Vec<f64>,
    spans: Vec<ColSpan>,
    rows: [f64; 2],
    /// Rows and weights of the points behind the last update or initialisation.
    fit: FitRows,
    points_now: usize,
    initialised_now: bool,
    updated_now: bool,
    fresh: bool,
}

impl Lane {
    fn report(&self) -> LaneReport {
        let coeffs = match self.state {
            LaneState::Tracking | LaneState::Coasting => {
                self.filter.as_ref().map(LaneFilter::coeffs)
            }
            LaneState::Initialising | LaneState::Lost => None,
        };
        LaneReport {
            side: self.side,
            state: self.state,
            coeffs,
            rows: self.rows,
            points: self.points_now,
            initialised: self.initialised_now,
        }
    }

    fn has_estimate(&self) -> bool {
        matches!(self.state, LaneState::Tracking | LaneState::Coasting) && self.filter.is_some()
    }
}

/// What an overlay needs of one lane: its windows, its points and its estimate.
#[derive(Debug, Clone, Copy)]
pub struct LaneView<'a> {
    /// The lane's report for the last frame.
    pub report: LaneReport,
    /// Window of interest per image row (empty spans outside it) used on the last frame; all
    /// empty if the lane was not tracked on it.
    pub spans: &'a [ColSpan],
    /// The points fed to the filter or the LS fit on the last frame, `(col_px, row_px)`.
    pub points: &'a [(f32, f32)],
}

/// The lane tracker for frames of one size. Build once; [`LaneTracker::track`] per frame does
/// not allocate.
#[derive(Debug)]
pub struct LaneTracker {
    cfg: TrackerConfig,
    estimator: Estimator,
    width: usize,
    height: usize,
    roi: (usize, usize),
    detector: GradientDetector,
    edges: EdgeBuffer,
    hough: HoughWorkspace,
    init_params: LaneInitParams,
    candidates: Vec<(f32, f32)>,
    scratch: Vec<Candidate>,
    row_norm: RowNorm,
    q: ProcessNoise<3>,
    p0: ThetaCov,
    lanes: [Lane; 2],
    counters: TrackerCounters,
}

/// A window pixel during point selection.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    col_px: u16,
    row_px: u16,
    /// Residual `x − x̂(y)` rounded, plus the window half-width (0..=2w).
    bin: u16,
    /// Third of the ROI rows (0, 1, 2).
    band: u8,
}

/// Sub-pixel column of a lane mark in one image row: the centroid of its grey level above the
/// local background, over the columns `lo..=hi` of the row's inlier edge pixels widened on each
/// side by `2 + ⌈|slope|⌉` px (`slope` = the predicted `dx/dy` of the lane: the 3×3 gradient of a
/// slanted edge reaches that far from it), at most 6 px. The background is the mean of the two
/// end pixels; the mark is the brighter or the darker side (whichever deviates more). When the
/// two ends differ by more than half the mark's contrast the window holds a single step edge
/// (a floor/wall boundary, a shadow border, a mark cut by the image border), and the point is
/// that edge's sub-pixel position ([`step_edge`]). `None` when there is no contrast.
///
/// Returns the column and `v = Σ_k (k − c)²/S²` over the window (`S` the summed excess grey,
/// `c` the centroid): the centroid's variance per unit of grey-level noise variance, so `1/v`
/// is the point's relative precision (a narrow or faint mark gives a noisier centre).
///
/// For a mark drawn with area anti-aliasing the centroid is exact up to a sawtooth of at most
/// `1/(8·w)` px for a mark `w` px wide (exact for whole-pixel widths), against up to half a pixel
/// for the integer columns of its edge pixels.
fn mark_centre(row: &[u8], lo: u16, hi: u16, slope: f64) -> Option<(f64, f64)> {
    let margin = if slope.is_finite() {
        (2.0 + slope.abs().ceil()).min(6.0) as usize
    } else {
        2
    };
    let a = usize::from(lo).saturating_sub(margin);
    let b = (usize::from(hi) + margin).min(row.len().checked_sub(1)?);
    let pixels = row.get(a..=b)?;
    let (&first, &last) = (pixels.first()?, pixels.last()?);
    let bg = 0.5 * (f64::from(first) + f64::from(last));
    let (mut hi_dev, mut lo_dev) = (0.0f64, 0.0f64);
    for &p in pixels {
        let d = f64::from(p) - bg;
        hi_dev = hi_dev.max(d);
        lo_dev = lo_dev.min(d);
    }
    let (polarity, contrast) = if hi_dev >= -lo_dev {
        (1.0, hi_dev)
    } else {
        (-1.0, -lo_dev)
    };
    let step = f64::from(last) - f64::from(first);
    if step.abs() > 0.5 * contrast {
        return step_edge(pixels, step).map(|(c, v)| (a as f64 + c, v));
    }
    if contrast <= 0.0 {
        return None;
    }
    let (mut sw, mut swx) = (0.0, 0.0);
    for (k, &p) in pixels.iter().enumerate() {
        let w = (polarity * (f64::from(p) - bg)).max(0.0);
        sw += w;
        swx += w * k as f64;
    }
    if sw <= 0.0 {
        return None;
    }
    let c = swx / sw;
    let spread: f64 = (0..pixels.len()).map(|k| (k as f64 - c).powi(2)).sum();
    Some((a as f64 + c, spread / (sw * sw)))
}

/// [`LaneTracker::lane_fit_rows`] of `points` (with `weights`, or 1 each when `weights` is
/// shorter) over `rows` `[first, last]`.
fn fit_profile(points: &[(f32, f32)], weights: &[f64], rows: [f64; 2]) -> FitRows {
    let mut sum_w = [0.0; FIT_SAMPLES];
    let mut sum_wy = [0.0; FIT_SAMPLES];
    let span = rows[1] - rows[0];
    for (i, &(_, y)) in points.iter().enumerate() {
        let w = weights.get(i).copied().unwrap_or(1.0);
        let y = f64::from(y);
        let t = if span > 0.0 {
            (y - rows[0]) / span
        } else {
            0.0
        };
        let b = ((t * FIT_SAMPLES as f64).max(0.0) as usize).min(FIT_SAMPLES - 1);
        sum_w[b] += w;
        sum_wy[b] += w * y;
    }
    let mut fit = FitRows {
        rows_px: [0.0; FIT_SAMPLES],
        weights: sum_w,
    };
    for (b, r) in fit.rows_px.iter_mut().enumerate() {
        *r = if sum_w[b] > 0.0 {
            sum_wy[b] / sum_w[b]
        } else {
            rows[0] + span * (b as f64 + 0.5) / FIT_SAMPLES as f64
        };
    }
    fit
}

/// Floor of the per-point σ the KIF is given, px: a scatter estimate below it (a noise-free
/// rendering) is not trusted further.
const MIN_R_SIGMA_PX: f64 = 0.02;

/// Fewest points for the scatter estimate of [`weighted_scatter`].
const MIN_SCATTER_POINTS: usize = 8;

/// The KIF's measurement for one frame of weighted points: the weighted power sums
/// (`info_filter::PowerSums::from_weighted_points`) and the scale `s²` of `R = s²·diag(1/w_i)`,
/// the unbiased weighted variance (`N − 3` degrees of freedom) of the points about their own
/// weighted least-squares parabola, floored so that the points' mean variance `s²·N/Σw` is at
/// least `MIN_R_SIGMA_PX²`. The residuals are taken about `pred` (the predicted coefficients)
/// first so the sums stay small. `None` for fewer than [`MIN_SCATTER_POINTS`] points, a
/// singular fit or bad weights.
fn weighted_scatter(
    points: &[(f32, f32)],
    weights: &[f64],
    pred: [f64; 3],
    row_norm: &RowNorm,
) -> Option<(PowerSums, f64)> {
    if points.len() < MIN_SCATTER_POINTS || weights.len() != points.len() {
        return None;
    }
    let mut n = Matrix3::<f64>::zeros();
    let mut b = Vector3::<f64>::zeros();
    let (mut wrr, mut sw) = (0.0, 0.0);
    for (&(x, y), &w) in points.iter().zip(weights) {
        let y = f64::from(y);
        let r = f64::from(x) - Parabola::from_coeffs(pred).col_at_row(y);
        let u = row_norm.normalise_row(y);
        let phi = Vector3::new(u * u, u, 1.0);
        n += w * phi * phi.transpose();
        b += w * r * phi;
        wrr += w * r * r;
        sw += w;
    }
    let theta = n.cholesky()?.solve(&b);
    let count = points.len() as f64;
    let s2 = ((wrr - theta.dot(&b)).max(0.0) / (count - 3.0))
        .max(MIN_R_SIGMA_PX * MIN_R_SIGMA_PX * sw / count);
    let sums = PowerSums::from_weighted_points(points, weights, row_norm).ok()?;
    (s2.is_finite() && s2 > 0.0).then_some((sums, s2))
}

/// Sub-pixel position (from the window's first pixel) of a single step edge rising by `step`
/// (grey levels, either sign) across `pixels`, and its relative variance: the centroid of the
/// forward differences of the step's sign, each at its half-pixel position — exact for an
/// area-anti-aliased step. `None` if the window holds no difference of that sign.
fn step_edge(pixels: &[u8], step: f64) -> Option<(f64, f64)> {
    let sign = step.signum();
    let (mut sw, mut swx) = (0.0, 0.0);
    for (k, pair) in pixels.windows(2).enumerate() {
        let d = (sign * (f64::from(pair[1]) - f64::from(pair[0]))).max(0.0);
        sw += d;
        swx += d * (k as f64 + 0.5);
    }
    if sw <= 0.0 {
        return None;
    }
    let c = swx / sw;
    // Each difference carries two pixels' noise.
    let spread: f64 = (0..pixels.len().saturating_sub(1))
        .map(|k| 2.0 * (k as f64 + 0.5 - c).powi(2))
        .sum();
    Some((c, spread / (sw * sw)))
}

/// Largest window half-width accepted by the configuration, px.
const MAX_WINDOW_HALF_WIDTH: usize = 200;

impl LaneTracker {
    /// A tracker for `width × height` frames. Validates `cfg`.
    pub fn new(
        cfg: &TrackerConfig,
        estimator: Estimator,
        width: usize,
        height: usize,
    ) -> Result<Self, NavError> {
        cfg.validate()?;
        if width < 3 || height < 3 {
            return Err(NavError::ZeroSize {
                name: "tracker".to_owned(),
                width,
                height,
            });
        }
        let detector = GradientDetector::new(cfg.gradient.params())?;
        let roi = cfg.roi_rows(height);
        let capacity = width * (roi.1 - roi.0);
        let hough = HoughWorkspace::new(width, height, cfg.init.hough_params())?;
        let init_params = cfg.init.lane_params();
        init_params.validate()?;
        let center = (roi.0 + roi.1 - 1) as f64 / 2.0;
        let scale = ((roi.1 - 1 - roi.0) as f64 / 2.0).max(1.0);
        let row_norm = RowNorm::new(center, scale)?;
        let f = &cfg.filter;
        let q_u = Matrix3::from_diagonal(&Vector3::from(f.q_sigma_px.map(|s| s * s)));
        let q = ProcessNoise::new(&q_u)?;
        let p0 = ThetaCov::Normalised(Matrix3::from_diagonal(&Vector3::from(
            f.p0_sigma_px.map(|s| s * s),
        )));
        let [left_band, right_band] = cfg.gradient.hough_bands();
        let make_lane = |side, class, band| Lane {
            side,
            class,
            band,
            state: LaneState::Initialising,
            filter: None,
            predicted: None,
            misses: 0,
            points: Vec::with_capacity(cfg.track.max_points_per_lane.max(capacity.min(1 << 16))),
            weights: Vec::with_capacity(cfg.track.max_points_per_lane.max(capacity.min(1 << 16))),
            spans: vec![ColSpan::EMPTY; height],
            rows: [0.0, 0.0],
            fit: FitRows::uniform(0.0, 0.0),
            points_now: 0,
            initialised_now: false,
            updated_now: false,
            fresh: false,
        };
        let lanes = [
            make_lane(Side::Left, EdgeClass::LeftLane, left_band),
            make_lane(Side::Right, EdgeClass::RightLane, right_band),
        ];
        for lane in &lanes {
            lane.band.validate()?;
        }
        Ok(LaneTracker {
            cfg: *cfg,
            estimator,
            width,
            height,
            roi,
            detector,
            edges: EdgeBuffer::with_capacity(capacity),
            hough,
            init_params,
            candidates: Vec::with_capacity(capacity),
            scratch: Vec::with_capacity(capacity),
            row_norm,
            q,
            p0,
            lanes,
            counters: TrackerCounters::default(),
        })
    }

    /// Frame size this tracker takes, px.
    pub fn frame_size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Rows searched, `[top, bottom)`, px.
    pub fn roi_rows(&self) -> (usize, usize) {
        self.roi
    }

    /// The configuration in use.
    pub fn config(&self) -> &TrackerConfig {
        &self.cfg
    }

    /// The estimator in use.
    pub fn estimator(&self) -> Estimator {
        self.estimator
    }

    /// Counters since construction (or the last [`LaneTracker::reset`]).
    pub fn counters(&self) -> &TrackerCounters {
        &self.counters
    }

    /// Forget both lanes (next frame initialises again) and zero the counters.
    pub fn reset(&mut self) {
        for lane in &mut self.lanes {
            lane.state = LaneState::Initialising;
            lane.filter = None;
            lane.predicted = None;
            lane.misses = 0;
            lane.points.clear();
            lane.weights.clear();
            lane.spans.fill(ColSpan::EMPTY);
            lane.points_now = 0;
        }
        self.counters = TrackerCounters::default();
    }

    /// Covariance of one lane's reported coefficients `(a1, a2, a3)` in the pixel
    /// parameterisation (entry `(i, j)` in units of `a_i·a_j`), `None` when the lane has no
    /// estimate (initialising or lost) or its information matrix cannot be inverted.
    ///
    /// KIF: `P_px = T·Y_u⁻¹·Tᵀ`, the inverse of the information matrix the filter propagates in
    /// the normalised rows `u = (y − y_c)/s`, mapped by the exact linear map `T` between the
    /// normalised and the pixel coefficients (`info_filter::RowNorm`). WRLS: its `P` (a scaled
    /// inverse normal matrix) times `filter.r_sigma_px²`, the least-squares covariance for that
    /// pixel noise. No allocation.
    pub fn lane_covariance_px(&self, side: Side) -> Option<Matrix3<f64>> {
        let lane = &self.lanes[side as usize];
        if !lane.has_estimate() {
            return None;
        }
        match lane.filter.as_ref()? {
            LaneFilter::Kif(k) => k.covariance().ok(),
            LaneFilter::Wrls(w) => {
                let r = self.cfg.filter.r_sigma_px;
                w.covariance_px().map(|p| p * (r * r))
            }
        }
    }

    /// How one lane's estimate was fitted on the last update or initialisation: the weighted
    /// mean row and the summed weight of its points in each eighth of their rows (edge pixels
    /// weigh 1, mark centres their relative precision). `lane-geometry` uses it to remove the
    /// image-parabola model error ([`crate::camera::CameraModel::ego_lane`]). `None` when the
    /// lane has no estimate.
    pub fn lane_fit_rows(&self, side: Side) -> Option<FitRows> {
        let lane = &self.lanes[side as usize];
        lane.has_estimate().then_some(lane.fit)
    }

    /// Windows, points and report of one lane after the last frame (for overlays).
    pub fn lane_view(&self, side: Side) -> LaneView<'_> {
        let lane = &self.lanes[side as usize];
        LaneView {
            report: lane.report(),
            spans: &lane.spans,
            points: &lane.points,
        }
    }

    /// Process one frame. Errors only for a frame of the wrong size or a component refusing
    /// its (validated) input; a lane that cannot be tracked is reported as such, not as an error.
    pub fn track(&mut self, frame: &GreyFrame) -> Result<TrackReport, NavError> {
        self.track_pixels(frame.data(), frame.width(), frame.height(), frame.width())
    }

    /// [`LaneTracker::track`] on borrowed pixels: `width × height` grey pixels, row `y` starting at
    /// `data[y * stride_px]` (`stride_px ≥ width`), so a caller's buffer (a numpy array, a capture
    /// buffer with padded rows) is read in place without a copy. Errors for a size other than the
    /// tracker's or a `data` too short for the stride.
    pub fn track_pixels(
        &mut self,
        data: &[u8],
        width: usize,
        height: usize,
        stride_px: usize,
    ) -> Result<TrackReport, NavError> {
        if width != self.width || height != self.height {
            return Err(NavError::FrameSize {
                expected_w: self.width,
                expected_h: self.height,
                got_w: width,
                got_h: height,
            });
        }
        let image = GreyImage::new(data, self.width, self.height, stride_px)?;
        self.counters.frames += 1;
        for i in 0..2 {
            let lane = &mut self.lanes[i];
            lane.initialised_now = false;
            lane.updated_now = false;
            lane.points_now = 0;
            if lane.has_estimate() {
                self.track_lane(i, &image, true)?;
            } else {
                lane.spans.fill(ColSpan::EMPTY);
                lane.points.clear();
            }
        }
        let need_init = self.lanes.iter().any(|l| !l.has_estimate());
        if need_init {
            self.initialise(&image)?;
            // Refine a fresh initialisation on the same frame: one windowed update around the
            // LS parabola, with the window's outlier rejection (the Hough band keeps clutter).
            for i in 0..2 {
                if self.lanes[i].initialised_now {
                    self.track_lane(i, &image, false)?;
                    let lane = &mut self.lanes[i];
                    if lane.state != LaneState::Tracking {
                        // The refinement missed: keep the LS initialisation as it was.
                        lane.state = LaneState::Tracking;
                        lane.misses = 0;
                    }
                    lane.initialised_now = true;
                }
            }
        }
        self.crossing_gate();
        Ok(TrackReport {
            lanes: [self.lanes[0].report(), self.lanes[1].report()],
            full_gradient: need_init,
        })
    }

    fn track_lane(
        &mut self,
        i: usize,
        image: &GreyImage<'_>,
        predict: bool,
    ) -> Result<(), NavError> {
        let (top, bottom) = self.roi;
        let w = self.cfg.track.window_half_width_px as i64;
        let max_points = self.cfg.track.max_points_per_lane;
        let lane = &mut self.lanes[i];
        let Some(filter) = lane.filter.as_mut() else {
            return Ok(());
        };
        let predicted = match filter {
            LaneFilter::Kif(k) if predict => k.predict(&self.q).map_err(|e| e.to_string()),
            LaneFilter::Kif(_) | LaneFilter::Wrls(_) => Ok(()),
        };
        if predicted.is_err() {
            self.counters.filter_failures[i] += 1;
            lane.state = LaneState::Lost;
            return Ok(());
        }
        lane.predicted.clone_from(&lane.filter);
        let Some(filter) = lane.filter.as_mut() else {
            return Ok(());
        };
        let coeffs = filter.coeffs();
        for (row, span) in lane.spans.iter_mut().enumerate() {
            *span = if row >= top && row < bottom {
                let x = Parabola::from_coeffs(coeffs).col_at_row(row as f64);
                if x.is_finite() && x.abs() < 1e6 {
                    let c = x.round() as i64;
                    ColSpan::clamped(c - w, c + w + 1, self.width)
                } else {
                    ColSpan::EMPTY
                }
            } else {
                ColSpan::EMPTY
            };
        }
        self.detector
            .detect(image, Region::Spans(&lane.spans), &mut self.edges, None)?;
        // Outlier rejection: the residuals r = x − x̂(y) of the window pixels are histogrammed
        // in three row bands; pixels farther than `inlier_half_width_px` from their band's
        // midhinge residual (mean of the quartiles) are dropped (clutter, noise, the edges of a shadow).
        const BANDS: usize = 3;
        let band_rows = [top + (bottom - top) / 3, top + 2 * (bottom - top) / 3];
        let w_us = w as usize;
        // One pass over the window pixels of the lane's class: residual bin (r + w, rounded;
        // window pixels are within ±w of the prediction) and row band, histogrammed per band.
        let mut hist = [[0u32; 2 * MAX_WINDOW_HALF_WIDTH + 1]; BANDS];
        self.scratch.clear();
        for p in self.edges.iter_class(lane.class) {
            let v =
                f64::from(p.col_px) - Parabola::from_coeffs(coeffs).col_at_row(f64::from(p.row_px));
            // Truncation of a non-negative value is floor: this rounds v to the nearest bin.
            let bin = ((v + w as f64 + 0.5).max(0.0) as usize).min(2 * w_us);
            let row = usize::from(p.row_px);
            let band = usize::from(row >= band_rows[0]) + usize::from(row >= band_rows[1]);
            hist[band][bin] += 1;
            if self.scratch.len() < self.scratch.capacity() {
                self.scratch.push(Candidate {
                    col_px: p.col_px,
                    row_px: p.row_px,
                    bin: bin as u16,
                    band: band as u8,
                });
            }
        }
        // Band centre = midhinge (mean of the quartiles): with the two edges of a mark it
        // lands between them, where a median would pick one edge.
        let mut centre = [w; BANDS];
        for (b, h) in hist.iter().enumerate() {
            let n: u32 = h[..=2 * w_us].iter().sum();
            if n == 0 {
                continue;
            }
            let (q1, q3) = (n.div_ceil(4), (3 * n).div_ceil(4));
            let (mut acc, mut r1, mut r3) = (0u32, None, None);
            for (r, &c) in h[..=2 * w_us].iter().enumerate() {
                acc += c;
                if r1.is_none() && acc >= q1 {
                    r1 = Some(r as i64);
                }
                if acc >= q3 {
                    r3 = Some(r as i64);
                    break;
                }
            }
            if let (Some(a), Some(c)) = (r1, r3) {
                centre[b] = (a + c).div_euclid(2);
            }
        }
        let inlier = self.cfg.track.inlier_half_width_px;
        let is_inlier =
            |c: &Candidate| (i64::from(c.bin) - centre[usize::from(c.band)]).abs() as f64 <= inlier;
        // With `track.mark_centres`, one sub-pixel point per row (crate docs, "Mark centres"):
        // the inlier edge pixels of a row (both edges of the mark; the detector emits them row
        // by row) bracket the mark, and the centroid of its grey level above the local
        // background is the measurement.
        lane.points.clear();
        lane.weights.clear();
        let mark_centres = self.cfg.track.mark_centres;
        if !mark_centres {
            // The paper's measurement: the inlier edge pixels, uniformly decimated (in row
            // order) down to max_points, spread over the rows and over both edges of a mark.
            let total = self.scratch.iter().filter(|c| is_inlier(c)).count();
            for (j, c) in self.scratch.iter().filter(|c| is_inlier(c)).enumerate() {
                if total <= max_points || (j + 1) * max_points / total > j * max_points / total {
                    lane.points.push((f32::from(c.col_px), f32::from(c.row_px)));
                }
            }
        }
        let mut run: Option<(u16, u16, u16)> = None;
        let rows_out = self
            .scratch
            .iter()
            .filter(|c| mark_centres && is_inlier(c))
            .map(Some)
            .chain([None]);
        for c in rows_out {
            match (run, c) {
                (Some((row, lo, hi)), Some(c)) if c.row_px == row => {
                    run = Some((row, lo.min(c.col_px), hi.max(c.col_px)));
                }
                (prev, next) => {
                    if let Some((row, lo, hi)) = prev {
                        let y = f64::from(row);
                        let slope = 2.0 * coeffs[0] * y + coeffs[1];
                        if let Some((x, v)) = image
                            .row(usize::from(row))
                            .and_then(|pixels| mark_centre(pixels, lo, hi, slope))
                            && lane.points.len() < lane.points.capacity()
                        {
                            lane.points.push((x as f32, f32::from(row)));
                            lane.weights.push(1.0 / v);
                        }
                    }
                    run = next.map(|c| (c.row_px, c.col_px, c.col_px));
                }
            }
        }
        // Mark centres: uniform decimation over the rows down to max_points (frames taller
        // than the limit).
        let total = lane.points.len();
        if mark_centres && total > max_points {
            let mut k = 0;
            for j in 0..total {
                if (j + 1) * max_points / total > j * max_points / total {
                    lane.points[k] = lane.points[j];
                    lane.weights[k] = lane.weights[j];
                    k += 1;
                }
            }
            lane.points.truncate(k);
            lane.weights.truncate(k);
        }
        if lane.points.len() < self.cfg.track.reinit_min_points {
            Self::miss(lane, &self.cfg);
            return Ok(());
        }
        // KIF with mark centres: R = s²·diag(1/w_i), the points' relative precisions w_i scaled
        // by this frame's weighted scatter s² about their own LS parabola (crate docs,
        // "Measurement noise"); the configured σ for every point when there are too few points
        // to estimate it, and always with edge pixels (the paper's R = σ²·I).
        let r_cfg = self.cfg.filter.r_sigma_px;
        let updated = match filter {
            LaneFilter::Kif(k) => {
                let row_norm = *k.row_norm();
                let measured = if mark_centres {
                    weighted_scatter(&lane.points, &lane.weights, coeffs, &row_norm)
                } else {
                    None
                };
                match measured {
                    Some((sums, s2)) => k.update_sums(&sums, s2),
                    None => k.update(&lane.points, r_cfg * r_cfg),
                }
                .map_err(|e| e.to_string())
            }
            LaneFilter::Wrls(wl) => wl.update(&lane.points).map_err(|e| e.to_string()),
        };
        if updated.is_err() {
            self.counters.filter_failures[i] += 1;
            lane.filter.clone_from(&lane.predicted);
            Self::miss(lane, &self.cfg);
            return Ok(());
        }
        // Jump gate at the top and bottom ROI rows.
        let (Some(new), Some(pred)) = (lane.filter.as_ref(), lane.predicted.as_ref()) else {
            return Ok(());
        };
        let jump = [top as f64, (bottom - 1) as f64]
            .iter()
            .map(|&y| (new.col_at_row(y) - pred.col_at_row(y)).abs())
            .fold(0.0f64, f64::max);
        // The first update after an initialisation corrects the LS fit (P0) and is not gated.
        let within = jump <= self.cfg.track.max_jump_px; // false for NaN too
        if !lane.fresh && !within {
            self.counters.gated_jumps[i] += 1;
            lane.filter.clone_from(&lane.predicted);
            Self::miss(lane, &self.cfg);
            return Ok(());
        }
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &(_, y) in &lane.points {
            lo = lo.min(f64::from(y));
            hi = hi.max(f64::from(y));
        }
        lane.rows = [lo, hi];
        lane.fit = fit_profile(&lane.points, &lane.weights, lane.rows);
        lane.points_now = lane.points.len();
        lane.state = LaneState::Tracking;
        lane.misses = 0;
        lane.updated_now = true;
        lane.fresh = false;
        Ok(())
    }

    fn miss(lane: &mut Lane, cfg: &TrackerConfig) {
        lane.misses += 1;
        lane.points_now = 0;
        lane.state = if lane.misses >= cfg.track.lost_after_frames {
            LaneState::Lost
        } else {
            LaneState::Coasting
        };
    }

    fn initialise(&mut self, image: &GreyImage<'_>) -> Result<(), NavError> {
        let (top, bottom) = self.roi;
        self.detector.detect(
            image,
            Region::Rows {
                row_start_px: top,
                row_end_px: bottom,
            },
            &mut self.edges,
            None,
        )?;
        for i in 0..2 {
            if self.lanes[i].has_estimate() {
                continue;
            }
            let class = self.lanes[i].class;
            self.candidates.clear();
            self.candidates.extend(
                self.edges
                    .iter_class(class)
                    .map(|p| (f32::from(p.col_px), f32::from(p.row_px))),
            );
            let Ok(init) = init_lane(
                &self.candidates,
                &self.lanes[i].band,
                &mut self.hough,
                &self.init_params,
            ) else {
                continue;
            };
            // Sanity: the fit must cover a fair part of the ROI and stay near the image.
            let span_rows = init.rows_px.1 - init.rows_px.0;
            let min_span = 0.25 * (bottom - top) as f64;
            let x_bottom = init.parabola.col_at_row((bottom - 1) as f64);
            let w = self.width as f64;
            if span_rows < min_span || !x_bottom.is_finite() || x_bottom < -w || x_bottom > 2.0 * w
            {
                continue;
            }
            let theta = Vector3::new(init.parabola.a1, init.parabola.a2, init.parabola.a3);
            let filter = match self.estimator {
                Estimator::Kif => ParabolaKif::new(&theta, &self.p0, self.row_norm)
                    .map(LaneFilter::Kif)
                    .map_err(|e| e.to_string()),
                Estimator::Wrls => super::wrls_lane::WrlsLane::new(
                    &theta,
                    &self.p0,
                    self.row_norm,
                    self.cfg.filter.wrls_lambda,
                )
                .map(LaneFilter::Wrls)
                .map_err(|e| e.to_string()),
            };
            let Ok(filter) = filter else {
                self.counters.filter_failures[i] += 1;
                continue;
            };
            let lane = &mut self.lanes[i];
            // Keep the points the LS fit used, for overlays.
            lane.points.clear();
            let (s, c) = init.line.theta_rad.sin_cos();
            let band = self.init_params.band_px;
            for &(x, y) in &self.candidates {
                let (xf, yf) = (f64::from(x), f64::from(y));
                if (xf * c + yf * s - init.line.rho_px).abs() <= band
                    && lane.points.len() < lane.points.capacity()
                {
                    lane.points.push((x, y));
                }
            }
            lane.filter = Some(filter);
            lane.predicted = None;
            lane.fresh = true;
            lane.state = LaneState::Tracking;
            lane.misses = 0;
            lane.rows = [init.rows_px.0, init.rows_px.1];
            lane.weights.clear();
            lane.fit = fit_profile(&lane.points, &lane.weights, lane.rows);
            lane.points_now = init.points_used;
            lane.initialised_now = true;
            self.counters.initialisations[i] += 1;
        }
        Ok(())
    }

    /// Left and right lanes may not cross at the top ROI row, nor come closer than
    /// `min_lane_separation_px` at the middle and bottom ROI rows. The offending estimate is the one that changed on this
    /// frame by initialisation, else the one backed by fewer points; it is undone.
    fn crossing_gate(&mut self) {
        let [l, r] = &self.lanes;
        let (Some(lf), Some(rf)) = (l.filter.as_ref(), r.filter.as_ref()) else {
            return;
        };
        if !(l.has_estimate() && r.has_estimate()) {
            return;
        }
        let (top, bottom) = self.roi;
        let sep = self.cfg.track.min_lane_separation_px;
        // Lanes converge towards the horizon: at the top ROI row they need only be in order,
        // at the middle and bottom rows `sep` apart.
        let rows = [
            (top as f64, 0.0),
            (0.5 * (top + bottom - 1) as f64, sep),
            ((bottom - 1) as f64, sep),
        ];
        let crossed = rows.iter().any(|&(y, s)| {
            (rf.col_at_row(y) - lf.col_at_row(y))
                .partial_cmp(&s)
                .is_none_or(|o| o.is_lt())
        });
        if !crossed {
            return;
        }
        let victim = match (l.initialised_now, r.initialised_now) {
            (true, false) => 0,
            (false, true) => 1,
            _ => usize::from(r.points_now < l.points_now),
        };
        self.counters.gated_crossings[victim] += 1;
        let lane = &mut self.lanes[victim];
        if lane.initialised_now {
            lane.initialised_now = false;
            lane.filter = None;
            lane.points_now = 0;
            lane.state = if self.counters.initialisations[victim] > 1 {
                LaneState::Lost
            } else {
                LaneState::Initialising
            };
            self.counters.initialisations[victim] -= 1;
        } else {
            if lane.predicted.is_some() {
                lane.filter.clone_from(&lane.predicted);
            }
            Self::miss(lane, &self.cfg);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One row of a mark `[left, right)` (columns, px) drawn with area anti-aliasing, grey 90
    /// on the floor and 200 on the mark, or a step from 90 up to 200 at `left` when `right` is ∞.
    fn row(left: f64, right: f64) -> Vec<u8> {
        (0..40)
            .map(|x| {
                let (lo, hi) = (x as f64 - 0.5, x as f64 + 0.5);
                let cover = (hi.min(right) - lo.max(left)).clamp(0.0, 1.0);
                (90.0 + 110.0 * cover).round() as u8
            })
            .collect()
    }

    #[test]
    fn mark_centre_is_within_the_sawtooth_bound_of_the_true_centre() {
        for width in [1.5, 2.0, 2.7, 4.0, 6.3] {
            for k in 0..20 {
                let centre = 17.0 + 0.05 * k as f64;
                let pixels = row(centre - 0.5 * width, centre + 0.5 * width);
                let (lo, hi) = ((centre - 0.5 * width) as u16, (centre + 0.5 * width) as u16);
                let (x, v) = mark_centre(&pixels, lo, hi, 0.3).unwrap();
                // 1/(8w) px, plus the rounding of the grey levels to integers.
                let bound = 1.0 / (8.0 * width) + 0.01;
                assert!(
                    (x - centre).abs() <= bound,
                    "width {width}, centre {centre}: {x} (bound {bound})"
                );
                assert!(v > 0.0 && v.is_finite());
            }
        }
        // A dark mark on a bright floor is found the same way.
        let dark: Vec<u8> = row(15.2, 18.9).iter().map(|&p| 255 - p + 35).collect();
        let (x, _) = mark_centre(&dark, 15, 18, 0.0).unwrap();
        assert!((x - 17.05).abs() < 0.04, "{x}");
    }

    #[test]
    fn a_single_step_edge_is_located_exactly() {
        for k in 0..20 {
            let edge = 20.0 + 0.05 * k as f64;
            let up = row(edge, f64::INFINITY);
            let (x, _) = mark_centre(&up, edge as u16, edge as u16 + 1, 0.5).unwrap();
            assert!((x - edge).abs() < 0.01, "rising {edge}: {x}");
            let down: Vec<u8> = up.iter().rev().copied().collect();
            let mirrored = 39.0 - edge;
            let (x, _) = mark_centre(&down, mirrored as u16, mirrored as u16 + 1, 0.5).unwrap();
            assert!((x - mirrored).abs() < 0.01, "falling {mirrored}: {x}");
        }
        // No contrast, no point.
        assert!(mark_centre(&[100; 40], 10, 12, 0.0).is_none());
    }
}
