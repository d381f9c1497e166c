//! The tracking loop (paper Fig. 1) as a pipeline of stages, each a type with its own state and
//! buffers and explicit inputs ([`LaneTracker::track`] reads as the pipeline):
//!
//! | stage | type (module) | reads → writes |
//! |---|---|---|
//! | working frame | `WorkingFrame` (`working`) | input → working frame; lanes → reports in input px |
//! | frame's levels | `Exposure` (`exposure`), `Denoiser` (`denoise`) | working frame → the frame as the stages read it (brightened, smoothed) |
//! | I. gradient | `EdgeStage` (`edges`) | frame, rows or windows → edge pixels |
//! | II. initialisation | `Initialiser` (`init`, `candidates`, `chosen_fit`) | edges → candidates, chosen pair, fresh lanes |
//! | III. windows | `predict_windows` (`windows`) | lane → prediction, windows |
//! | III. points | `PointSelector` (`points`) | window edges → the lane's points |
//! | III. update | `update_and_gate` (`update`) | points → filter update, jump gate, state |
//! | refinement readings | `StripeTracer` (`stripe_trace`), `straighten_turn_back` (`turn_back`), `centre_on_double_line` (`double_line`), `KerbReader` (`kerb`) | frame, fresh lane → moved estimate or kerb offset |
//! | gates | `pair_gate`, `crossing_gate` (`gates`) | both lanes → lanes dropped or undone |
//!
//! What every stage reads and none writes is the `Setup` (module `setup`: the configuration and
//! what it fixes for one frame size); the lanes (`Lanes`, module `lane`, addressed by [`Side`])
//! and the tracker's `Health` (counters, last failures) are what stages write.

use lane_geometry::FitRows;
use nalgebra::Matrix3;
use vision_gradient::{ColSpan, GreyImage};

use crate::error::FilterFailure;
use crate::{GreyFrame, RoadBottom, TrackerConfig, TrackerError};

mod candidates;
mod chosen_fit;
mod denoise;
mod double_line;
mod edges;
mod exposure;
mod gates;
mod init;
mod joint;
mod kerb;
mod lane;
mod points;
mod reach;
mod report;
mod revalidation;
mod road;
mod setup;
mod stripe_trace;
#[cfg(test)]
mod tests;
mod turn_back;
mod update;
mod view;
mod windows;
mod working;

pub(crate) use report::MAX_CANDIDATE_LINES;
pub use report::{
    Estimator, FarSegment, InitCandidate, LaneReport, LaneState, LaneView, RoadRefusal, RoadReport,
    Side, TrackReport, TrackerCounters,
};

use denoise::Denoiser;
pub use denoise::FrameNoise;
use edges::EdgeStage;
use exposure::Exposure;
pub use exposure::{FrameExposure, MAX_EXPOSURE_GAIN};
use init::Initialiser;
use kerb::KerbReader;
use lane::{Health, LaneFilter, Lanes};
use points::PointSelector;
use road::RoadFinder;
use setup::{Pass, Setup};
use stripe_trace::StripeTracer;
use view::AxisMap;
use working::{WorkingFrame, working_scale, working_size};

/// The lane tracker for frames of one size. Build once; [`LaneTracker::track`] per frame does
/// not allocate.
#[derive(Debug)]
pub struct LaneTracker {
    /// The configuration and what it fixes for this frame size.
    setup: Setup,
    /// The input's size and the working frame (module `working`).
    frame: WorkingFrame,
    /// Where the road ends at the bottom (`roi.road_bottom`, module `road`).
    road: RoadFinder,
    /// The frame's exposure (`[exposure]`, module `exposure`).
    exposure: Exposure,
    /// The frame's noise (`[denoise]`, module `denoise`).
    denoiser: Denoiser,
    /// Stage I.
    edges: EdgeStage,
    /// Stage II.
    init: Initialiser,
    /// Stage III's point selection.
    points: PointSelector,
    /// The refinement's stripe trace (`init.stripe_trace`).
    tracer: StripeTracer,
    /// The kerb reading (`init.kerb_foot`).
    kerb: KerbReader,
    /// Both lanes.
    lanes: Lanes,
    /// Counters and the last filter failures.
    health: Health,
}

impl LaneTracker {
    /// A tracker for `width × height` frames. Validates `cfg`.
    pub fn new(
        cfg: &TrackerConfig,
        estimator: Estimator,
        width: usize,
        height: usize,
    ) -> Result<Self, TrackerError> {
        cfg.validate()?;
        if width < 3 || height < 3 {
            return Err(TrackerError::ZeroSize { width, height });
        }
        if width > hough_init::MAX_IMAGE_SIDE_PX || height > hough_init::MAX_IMAGE_SIDE_PX {
            return Err(hough_init::HoughError::InvalidImageSize {
                width_px: width,
                height_px: height,
                reason: "a side exceeds MAX_IMAGE_SIDE_PX (16384 px)",
            }
            .into());
        }
        let input_size = (width, height);
        let scale = working_scale(width, height, cfg.frame.working_width_px);
        let (width, height) = working_size(width, height, scale);
        if width < 3 || height < 3 {
            return Err(TrackerError::ZeroSize {
                width: input_size.0,
                height: input_size.1,
            });
        }
        let setup = Setup::new(cfg, estimator, width, height)?;
        let (roi, fallback_roi) = (setup.roi, setup.fallback_roi);
        // The buffers hold the pixels of the tallest region searched.
        let capacity = width * (roi.1 - fallback_roi.map_or(roi.0, |r| r.0));
        let edges = EdgeStage::new(&setup, capacity)?;
        let init = Initialiser::new(&setup, capacity)?;
        let lanes = Lanes::new(
            cfg.track.max_points_per_lane.max(capacity.min(1 << 16)),
            height,
        );
        // From the top: the reach (module `reach`) follows the lanes up to the horizon.
        let work_rows = (0, (roi.1 + 1).min(height));
        let frame = WorkingFrame::new(scale, input_size, (width, height), work_rows, &lanes);
        let (top, bottom) = frame.view.rows_to_input(roi, input_size.1);
        let whole_frame = RoadReport {
            bottom_row_px: input_size.1 as f64,
            search_rows_px: [top as f64, bottom as f64],
            horizon_row_px: None,
            refused: None,
        };
        Ok(LaneTracker {
            frame,
            road: RoadFinder::new(width, height, whole_frame),
            exposure: Exposure::new(cfg.exposure.below_median_grey),
            denoiser: Denoiser::new(
                cfg.denoise.above_noise_grey,
                cfg.exposure.below_median_grey > 0.0,
                width,
                height,
            ),
            edges,
            init,
            points: PointSelector::new(capacity),
            tracer: StripeTracer::new(height),
            kerb: KerbReader::new(height),
            lanes,
            health: Health::default(),
            setup,
        })
    }

    /// Frame size this tracker takes, px (the input's; it may work on a resampled frame:
    /// [`LaneTracker::working_size`]).
    pub fn frame_size(&self) -> (usize, usize) {
        self.frame.input_size
    }

    /// The size of the frame the stages work on, px: the input resampled to
    /// `frame.working_width_px` wide by `s` input pixels per working pixel (module
    /// `tracker::working`); the input's own size when `s = 1`. The configuration's pixel fields
    /// are in these pixels; everything the tracker reports is in input pixels.
    pub fn working_size(&self) -> (usize, usize) {
        (self.setup.width, self.setup.height)
    }

    /// Input pixels per working pixel along each axis (`s > 0`; module `tracker::working`):
    /// working pixel `c'` stands for input columns `[s·c', s·(c' + 1))`, centred on input
    /// `x = s·c' + (s − 1)/2`. 1 when the stages work on the input itself.
    pub fn working_scale(&self) -> f64 {
        self.frame.view.cols.scale
    }

    /// What the stages read of the last frame, when the input is resampled (`s ≠ 1`): the
    /// working frame ([`LaneTracker::working_size`]) and the rows `[first, end)` of it that are
    /// written — the rows any stage reads (the ROI, the second search's rows, a row beside
    /// them for the Sobel); the other rows are not (zero). All zero before the first frame.
    /// `None` with `s = 1`: the stages read the input frame as it is. For diagnostics on the
    /// working frame (`lane_bench::labelled::census_lanes`); no copy.
    pub fn working_frame(&self) -> Option<(GreyImage<'_>, (usize, usize))> {
        self.frame.image()
    }

    /// Rows searched, `[top, bottom)`, px of the input (with a resampled input, the input rows
    /// the working ROI's rows average).
    pub fn roi_rows(&self) -> (usize, usize) {
        self.frame
            .view
            .rows_to_input(self.setup.roi, self.frame.input_size.1)
    }

    /// Rows of the second search (`roi.fallback_top_row_fraction`), `[top, bottom)`, px of the
    /// input as [`LaneTracker::roi_rows`]; `None` without a second search.
    pub fn second_search_rows(&self) -> Option<(usize, usize)> {
        self.setup
            .fallback_roi
            .map(|rows| self.frame.view.rows_to_input(rows, self.frame.input_size.1))
    }

    /// The road region of the last frame ([`TrackReport::road`]; before the first frame, the
    /// whole frame's rows with the ROI searched and no horizon).
    pub fn road(&self) -> RoadReport {
        self.road.last
    }

    /// The last measurement of the frames' noise and whether it smooths them (`[denoise]`;
    /// [`FrameNoise::NONE`] before the first measurement or with it off).
    pub fn frame_noise(&self) -> FrameNoise {
        self.denoiser.last()
    }

    /// The last measurement of the frames' exposure and the gain it brightens them by
    /// (`[exposure]`; [`FrameExposure::NONE`] before the first measurement or with it off).
    pub fn frame_exposure(&self) -> FrameExposure {
        self.exposure.last()
    }

    /// The configuration in use.
    pub fn config(&self) -> &TrackerConfig {
        &self.setup.cfg
    }

    /// The estimator in use.
    pub fn estimator(&self) -> Estimator {
        self.setup.estimator
    }

    /// Counters since construction (or the last [`LaneTracker::reset`]).
    pub fn counters(&self) -> &TrackerCounters {
        &self.health.counters
    }

    /// Forget both lanes (next frame initialises again) and zero the counters.
    pub fn reset(&mut self) {
        for lane in self.lanes.iter_mut() {
            lane.reset();
        }
        self.init.found.clear();
        self.health = Health::default();
        self.road.reset();
        self.exposure.reset();
        self.denoiser.reset();
        // What the accessors hand out with a resampled input: the cleared lanes, mapped.
        if self.frame.resamples() {
            self.frame.publish(&self.lanes, &self.init.found);
        }
    }

    /// Why lane `side`'s filter last refused a prediction, an update or an initialisation (the
    /// component's typed error; counted in [`TrackerCounters::filter_failures`]), `None` if it
    /// never has since construction or the last [`LaneTracker::reset`].
    pub fn last_filter_error(&self, side: Side) -> Option<FilterFailure> {
        self.health.last_failure[side.index()]
    }

    /// Covariance of one lane's reported coefficients `(a1, a2, a3)` in the pixel
    /// parameterisation (entry `(i, j)` in units of `a_i·a_j`), `None` when the lane has no
    /// estimate (initialising or lost) or its information matrix cannot be inverted. A kerb's
    /// offset (`init.kerb_foot`) is added to the reported coefficients as a shift whose own
    /// uncertainty (it is re-measured on each frame from a few rows) is not included: the
    /// covariance is the tracked edge's.
    ///
    /// KIF: `P_px = T·Y_u⁻¹·Tᵀ`, the inverse of the information matrix the filter propagates in
    /// the normalised rows `u = (y − y_c)/s`, mapped by the exact linear map `T` between the
    /// normalised and the pixel coefficients (`info_filter::RowNorm`). WRLS: its `P` (a scaled
    /// inverse normal matrix) times `filter.r_sigma_px²`, the least-squares covariance for that
    /// pixel noise. With a resampled input, mapped once more from working to input pixels
    /// (`T_w·P·T_wᵀ`, module `working`). No allocation.
    pub fn lane_covariance_px(&self, side: Side) -> Option<Matrix3<f64>> {
        let lane = &self.lanes[side];
        if !lane.has_estimate() {
            return None;
        }
        let p = match lane.filter.as_ref()? {
            LaneFilter::Kif(k) => k.covariance().ok(),
            LaneFilter::Wrls(w) => {
                let r = self.setup.cfg.filter.r_sigma_px;
                w.covariance_px().map(|p| p * (r * r))
            }
        }?;
        // In input pixels: `T·P·Tᵀ` (module `working`).
        Some(if self.frame.resamples() {
            self.frame.view.cov_to_input(&p)
        } else {
            p
        })
    }

    /// How one lane's estimate was fitted on the last update or initialisation: the weighted
    /// mean row and the summed weight of its points in each eighth of their rows (edge pixels
    /// weigh 1, mark centres their relative precision). `lane-geometry` uses it to remove the
    /// image-parabola model error ([`crate::camera::CameraModel::ego_lane`]). `None` when the
    /// lane has no estimate.
    pub fn lane_fit_rows(&self, side: Side) -> Option<FitRows> {
        let lane = &self.lanes[side];
        let mut fit = lane.fit;
        for r in &mut fit.rows_px {
            *r = self.frame.view.rows.to_input_px(*r);
        }
        lane.has_estimate().then_some(fit)
    }

    /// The Hough candidate lines of the last frame's joint initialisation or re-validation, both
    /// angle bands (at most `init.candidate_lines` each), with their support and the side the
    /// choice gave them ([`InitCandidate`]). Empty when the last frame ran neither (both lanes
    /// tracked between re-validations, or `init.candidate_lines = 0`, the paper's one line per
    /// band), and on the frames of a re-validation spread over its period
    /// (`track.revalidate_spread`: its candidates are of the period's first frame).
    pub fn init_candidates(&self) -> &[InitCandidate] {
        if self.frame.resamples() {
            self.frame.candidates()
        } else {
            &self.init.found
        }
    }

    /// Windows, points and report of one lane after the last frame (for overlays).
    pub fn lane_view(&self, side: Side) -> LaneView<'_> {
        if self.frame.resamples() {
            let (report, spans, points) = self.frame.lane(side.index());
            return LaneView {
                report,
                spans,
                points,
            };
        }
        let lane = &self.lanes[side];
        LaneView {
            report: lane.report(side),
            spans: &lane.spans,
            points: &lane.points,
        }
    }

    /// Process one frame. Errors only for a frame of the wrong size or a component refusing
    /// its (validated) input; a lane that cannot be tracked is reported as such, not as an error.
    pub fn track(&mut self, frame: &GreyFrame) -> Result<TrackReport, TrackerError> {
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
    ) -> Result<TrackReport, TrackerError> {
        let (expected_w, expected_h) = self.frame.input_size;
        if (width, height) != (expected_w, expected_h) {
            return Err(TrackerError::FrameSize {
                expected_w,
                expected_h,
                got_w: width,
                got_h: height,
            });
        }
        let input = GreyImage::new(data, width, height, stride_px)?;
        let new_scene = !self.lanes.iter().any(|l| l.has_estimate());
        if new_scene && self.setup.cfg.roi.road_bottom == RoadBottom::Found {
            self.place_road(&input)?;
        }
        let (lanes, full_gradient) = self.track_view(&input, new_scene)?;
        let view = self.frame.view;
        let search = view.rows_to_input(self.setup.roi, height);
        let bottom = view.rows_to_input((0, self.setup.height), height).1;
        let road = RoadReport::of(&lanes, [search.0 as f64, search.1 as f64], bottom as f64);
        self.road.last = road;
        Ok(TrackReport {
            lanes,
            full_gradient,
            road,
        })
    }

    /// The tracked frame in the view in force: `(lanes, full_gradient)` in input pixels.
    fn track_view(
        &mut self,
        input: &GreyImage<'_>,
        new_scene: bool,
    ) -> Result<([LaneReport; 2], bool), TrackerError> {
        Ok(if self.frame.resamples() {
            // The working frame (module `working`), in a buffer lent out of the stage for the
            // frame and put back whatever happens.
            let pixels = self.frame.resample(input)?;
            let (w, h) = (self.setup.width, self.setup.height);
            let tracked = GreyImage::new(&pixels, w, h, w)
                .map_err(TrackerError::from)
                .and_then(|image| self.track_denoised(image, new_scene));
            self.frame.put_back(pixels);
            // Published whatever happened, so the accessors read this frame's state as they
            // do without resampling (also after an error part-way through).
            self.frame.publish(&self.lanes, &self.init.found);
            (self.frame.lanes(), tracked?)
        } else {
            let full_gradient = self.track_denoised(*input, new_scene)?;
            (self.lanes.reports(), full_gradient)
        })
    }

    /// The working frame as the stages read it (modules `exposure`, `denoise`): its exposure
    /// measured, its noise when due (`new_scene`: no lane had an estimate), and the frame
    /// brightened and smoothed where the measurements say so.
    fn track_denoised(
        &mut self,
        image: GreyImage<'_>,
        new_scene: bool,
    ) -> Result<bool, TrackerError> {
        let roi = self.setup.roi;
        self.exposure.measure_frame(&image, roi);
        let gain = self.exposure.last().gain;
        self.denoiser.measure_if_due(&image, roi, new_scene, gain);
        let Some(pixels) = self
            .denoiser
            .frame_as_read(&image, self.frame.resampled_rows())
        else {
            return self.track_working(image);
        };
        let (w, h) = (self.setup.width, self.setup.height);
        let tracked = GreyImage::new(&pixels, w, h, w)
            .map_err(TrackerError::from)
            .and_then(|as_read| self.track_working(as_read));
        self.denoiser.put_back(pixels);
        tracked
    }

    /// The working rows for this frame (`roi.road_bottom = "found"`, module `road`): the road's
    /// bottom found on the square view, and the rows above it stretched over the working
    /// height; the square view's when the road reaches the frame's bottom.
    fn place_road(&mut self, input: &GreyImage<'_>) -> Result<(), TrackerError> {
        let square = self.frame.square_view();
        self.frame.set_rows(square.rows);
        let h = self.setup.height;
        // The road is looked for on the frame as the stages will read it: its exposure's gain
        // (module `exposure`) measured over the square view's ROI.
        let roi = self.setup.roi;
        let bottom = if square.is_identity() {
            let gain = self.exposure.gain_of(input, roi);
            self.road.find(input, (0, input.height()), gain)
        } else {
            let pixels = self.frame.resample(input)?;
            let w = self.setup.width;
            let rows = self.frame.resampled_rows();
            let found = GreyImage::new(&pixels, w, h, w).ok().and_then(|image| {
                let gain = self.exposure.gain_of(&image, roi);
                self.road.find(&image, rows, gain)
            });
            self.frame.put_back(pixels);
            found
        };
        if let Some(b) = bottom.filter(|&b| b < (h - 1) as f64) {
            self.frame.set_rows(AxisMap {
                scale: square.rows.scale * b / h as f64,
                start_px: 0.0,
            });
        }
        Ok(())
    }

    /// [`LaneTracker::track_pixels`] on the working frame: the pipeline. `true` when the whole
    /// ROI went through the gradient ([`TrackReport::full_gradient`]).
    fn track_working(&mut self, image: GreyImage<'_>) -> Result<bool, TrackerError> {
        self.health.counters.frames += 1;
        self.init.found.clear();
        // III. Each lane with an estimate tracked in its windows.
        for side in Side::BOTH {
            let lane = &mut self.lanes[side];
            lane.begin_frame();
            if lane.has_estimate() {
                self.track_lane(side, &image, Pass::Tracking)?;
            } else {
                lane.spans.fill(ColSpan::EMPTY);
                lane.points.clear();
            }
        }
        gates::pair_gate(
            &mut self.lanes,
            self.setup.roi,
            &self.setup,
            &mut self.health,
        );
        // II. (Re-)initialisation, or a re-validation of the tracked pair (whole, or a step of
        // one spread over the period's frames: module `revalidation`).
        let need_init = self.lanes.iter().any(|l| !l.has_estimate());
        let revalidate = !need_init && self.revalidation_due(&image)?;
        self.health.counters.revalidations += u64::from(revalidate);
        self.health.frames_since_full_gradient = if need_init || revalidate {
            0
        } else {
            self.health.frames_since_full_gradient + 1
        };
        if need_init || revalidate {
            self.init.initialise(
                &image,
                &mut self.edges,
                &mut self.lanes,
                &mut self.health,
                &self.setup,
            )?;
            for side in Side::BOTH {
                if self.lanes[side].initialised_now {
                    self.refine(side, &image)?;
                }
            }
        }
        gates::crossing_gate(
            &mut self.lanes,
            self.setup.roi,
            &self.setup,
            &mut self.health,
        );
        // A kerb is read again against the tracked lanes' final estimates (after the crossing
        // gate, which may undo an update); a lane tracked over the taller rows reads its kerb
        // there, as its refinement did.
        for side in Side::BOTH {
            let lane = &mut self.lanes[side];
            if lane.has_estimate() && !lane.initialised_now {
                let rows = self.setup.rows_of(lane);
                self.kerb
                    .recheck_kerb_foot(lane, side, &image, rows, &self.setup.cfg);
            }
        }
        // Each lane followed upwards as far as its mark is seen (module `reach`), no higher
        // than where the two lanes meet.
        let valid_rows = if self.frame.resamples() {
            self.frame.resampled_rows()
        } else {
            (0, image.height())
        };
        let horizon = report::horizon_row_px(&self.lanes.reports(), self.setup.roi.0 as f64);
        reach::reach_up(&mut self.lanes, &image, valid_rows, horizon, &self.setup);
        Ok(need_init || revalidate)
    }

    /// Whether the tracked pair is re-validated whole on this frame (`track.revalidate_every_frames`,
    /// `track.revalidate_below_points`; joint initialisation weighing its candidates by row
    /// coverage only): the joint initialisation runs over the ROI and the tracked lanes compete
    /// with its candidates — every `revalidate_every_frames` frames, and at once on a frame a
    /// lane's window gave fewer than `revalidate_below_points` points. With the period's
    /// re-validation spread over its frames (`track.revalidate_spread`), this frame's steps of
    /// it, and `true` only on the period's last frame when its choice would change a lane
    /// (module `revalidation`).
    fn revalidation_due(&mut self, image: &GreyImage<'_>) -> Result<bool, TrackerError> {
        let cfg = &self.setup.cfg;
        let every = u64::from(cfg.track.revalidate_every_frames);
        let weak = self
            .lanes
            .iter()
            .any(|l| l.points_now < cfg.track.revalidate_below_points);
        if !(cfg.init.candidate_lines > 0 && cfg.init.candidate_coverage) {
            return Ok(false);
        }
        let since = self.health.frames_since_full_gradient;
        if weak || every == 0 || !self.init.spreads() {
            return Ok(weak || (every > 0 && since + 1 >= every));
        }
        self.init.spread_step(
            since,
            every,
            image,
            &self.lanes,
            &self.setup,
            &mut self.health,
        )
    }

    /// III. One frame of the lane on `side` in its windows (over its rows, `Setup::rows_of`):
    /// prediction (on a tracked frame), windows, gradient inside them, point selection, update
    /// and jump gate. A lane that cannot be updated is a miss, not an error.
    fn track_lane(
        &mut self,
        side: Side,
        image: &GreyImage<'_>,
        pass: Pass,
    ) -> Result<(), TrackerError> {
        let setup = &self.setup;
        let lane = &mut self.lanes[side];
        let rows = setup.rows_of(lane);
        let Some(coeffs) =
            windows::predict_windows(lane, side, pass, rows, setup, &mut self.health)
        else {
            return Ok(());
        };
        self.edges.detect_windows(image, &lane.spans, setup)?;
        let w = setup.window_half_width(lane, pass);
        self.points.select(
            &self.edges.edges,
            lane,
            side,
            image,
            coeffs,
            w,
            pass,
            rows,
            &setup.cfg,
        );
        if lane.points.len() < setup.cfg.track.reinit_min_points {
            lane.miss(setup.cfg.track.lost_after_frames);
            return Ok(());
        }
        update::update_and_gate(lane, side, coeffs, rows, setup, &mut self.health);
        Ok(())
    }

    /// A fresh initialisation refined on its own frame, over the rows it was found in:
    /// `track.refine_passes` windowed updates (at least one) from the LS parabola, with the
    /// window's outlier rejection (the Hough band keeps clutter); then the readings of the
    /// image that move it (the stripe trace, no turn back, a double line's middle, a kerb's
    /// foot). A refinement that missed keeps the LS initialisation as it was. Decisions and
    /// figures: `docs/lanes/history/refinement-window.md` (below the ablation's bar, kept).
    fn refine(&mut self, side: Side, image: &GreyImage<'_>) -> Result<(), TrackerError> {
        for _ in 0..self.setup.cfg.track.refine_passes.max(1) {
            self.track_lane(side, image, Pass::Refinement)?;
        }
        let setup = &self.setup;
        let cfg = &setup.cfg;
        let health = &mut self.health;
        let lane = &mut self.lanes[side];
        let rows = setup.rows_of(lane);
        if cfg.init.stripe_trace {
            self.tracer.trace(lane, side, image, rows, cfg, health);
        }
        if cfg.init.no_turn_back {
            turn_back::straighten_turn_back(lane, side, rows, setup, health);
        }
        let doubled = cfg.init.double_line_middle
            && double_line::centre_on_double_line(lane, side, image, rows, setup, health);
        if !doubled && cfg.init.kerb_foot {
            self.kerb.onto_kerb_foot(lane, side, image, rows, cfg);
        }
        if lane.state != LaneState::Tracking {
            // The refinement missed: keep the LS initialisation as it was.
            lane.state = LaneState::Tracking;
            lane.misses = 0;
        }
        lane.initialised_now = true;
        Ok(())
    }
}
