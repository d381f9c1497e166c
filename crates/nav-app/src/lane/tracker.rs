//! The tracking loop (paper Fig. 1): directional gradient → Hough + LS initialisation → KIF
//! (or WRLS) recursion, per lane, with a state machine and sanity gates.

use hough_init::{AngleBand, HoughWorkspace, LaneInitParams, Parabola, init_lane};
use info_filter::{ParabolaKif, ProcessNoise, RowNorm, ThetaCov};
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
    spans: Vec<ColSpan>,
    rows: [f64; 2],
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
            spans: vec![ColSpan::EMPTY; height],
            rows: [0.0, 0.0],
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
        // Uniform decimation of the row-ordered inliers down to max_points: spreads the points
        // over the rows in proportion to the edge density, and over both edges of a mark.
        let total = self.scratch.iter().filter(|c| is_inlier(c)).count();
        lane.points.clear();
        for (j, c) in self.scratch.iter().filter(|c| is_inlier(c)).enumerate() {
            if total <= max_points || (j + 1) * max_points / total > j * max_points / total {
                lane.points.push((f32::from(c.col_px), f32::from(c.row_px)));
            }
        }
        if lane.points.len() < self.cfg.track.reinit_min_points {
            Self::miss(lane, &self.cfg);
            return Ok(());
        }
        let r2 = self.cfg.filter.r_sigma_px * self.cfg.filter.r_sigma_px;
        let updated = match filter {
            LaneFilter::Kif(k) => k.update(&lane.points, r2).map_err(|e| e.to_string()),
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
