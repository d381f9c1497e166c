//! What every stage reads and none writes: the validated configuration and what follows from it
//! for frames of one working size — the rows searched, the Hough bands and initialisation
//! parameters, and the filters' row normalisation, process noise and initial covariance.

use hough_init::{AngleBand, EgoPairParams, LaneInitParams};
use info_filter::{ParabolaKif, ProcessNoise, RowNorm, ThetaCov};
use nalgebra::{Matrix3, Vector3};

use super::init::LEAN_SCALE;
use super::lane::{Lane, LaneFilter};
use super::points::{MAX_WINDOW_HALF_WIDTH, NEAR_VERTICAL_SLOPE};
use super::report::{Estimator, Side};
use crate::error::FilterFailure;
use crate::wrls_lane::WrlsLane;
use crate::{TrackerConfig, TrackerError};

/// Rows `[top, bottom)` of the working frame, px.
pub(super) type Rows = (usize, usize);

/// Which pass of the windowed update a lane goes through.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Pass {
    /// A tracked frame: the filter's time update, then the windows
    /// (`track.window_half_width_px`).
    Tracking,
    /// The refinement of a fresh initialisation on its own frame: no time update, the wider
    /// windows `track.refine_window_half_width_px`, stripe middles (`track.stripe_middles`).
    Refinement,
}

/// The configuration and what it fixes for frames of one working size.
#[derive(Debug)]
pub(super) struct Setup {
    pub(super) cfg: TrackerConfig,
    pub(super) estimator: Estimator,
    /// The working frame's size, px (module `working`).
    pub(super) width: usize,
    pub(super) height: usize,
    /// The ROI's rows (`roi.*_row_fraction`).
    pub(super) roi: Rows,
    /// The rows of the second search (`roi.fallback_top_row_fraction`), if any.
    pub(super) fallback_roi: Option<Rows>,
    pub(super) init_params: LaneInitParams,
    /// The Hough angle band of each side's edge class, left then right.
    pub(super) bands: [AngleBand; 2],
    pub(super) row_norm: RowNorm,
    pub(super) q: ProcessNoise<3>,
    pub(super) p0: ThetaCov,
}

impl Setup {
    /// The setup for `width × height` working frames; `cfg` already validated.
    pub(super) fn new(
        cfg: &TrackerConfig,
        estimator: Estimator,
        width: usize,
        height: usize,
    ) -> Result<Self, TrackerError> {
        let roi = cfg.roi_rows(height);
        let fallback_roi = cfg.fallback_roi_rows(height);
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
        let bands = cfg.gradient.hough_bands();
        for band in &bands {
            band.validate()?;
        }
        Ok(Setup {
            cfg: *cfg,
            estimator,
            width,
            height,
            roi,
            fallback_roi,
            init_params,
            bands,
            row_norm,
            q,
            p0,
        })
    }

    /// The Hough angle band of `side`'s edge class.
    pub(super) fn band(&self, side: Side) -> AngleBand {
        self.bands[side.index()]
    }

    /// The rows a lane is refined, tracked and its kerb read over: the second search's taller
    /// rows for a lane it found (`Lane::tracked_tall`), else the ROI's.
    pub(super) fn rows_of(&self, lane: &Lane) -> Rows {
        match self.fallback_roi {
            Some(tall) if lane.tracked_tall => tall,
            _ => self.roi,
        }
    }

    /// A fresh estimator at `theta = (a1, a2, a3)` (pixel coefficients) with the initial
    /// covariance `filter.p0_sigma_px`.
    pub(super) fn new_filter(&self, theta: &Vector3<f64>) -> Result<LaneFilter, FilterFailure> {
        match self.estimator {
            Estimator::Kif => ParabolaKif::new(theta, &self.p0, self.row_norm)
                .map(LaneFilter::Kif)
                .map_err(FilterFailure::Kif),
            Estimator::Wrls => {
                WrlsLane::new(theta, &self.p0, self.row_norm, self.cfg.filter.wrls_lambda)
                    .map(LaneFilter::Wrls)
                    .map_err(FilterFailure::Wrls)
            }
        }
    }

    /// Centre column for `gradient.stripe_keep_outward_steps`.
    pub(super) fn outward_col(&self) -> Option<u16> {
        self.cfg
            .gradient
            .stripe_keep_outward_steps
            .then(|| u16::try_from(self.width / 2).unwrap_or(u16::MAX))
    }

    /// The lean bound below which an edge pixel counts in both classes in the initialisation
    /// (`init::counts_as`, 2^14 fixed point): the joint initialisation's, `tan 10°` (as the
    /// tracking windows take either class where the lane is within 10° of the vertical,
    /// `points::NEAR_VERTICAL_SLOPE`); none for the paper's line per band
    /// (`init.candidate_lines = 0`).
    pub(super) fn near_vertical_either_class(&self) -> i32 {
        if self.cfg.init.candidate_lines > 0 {
            (NEAR_VERTICAL_SLOPE * LEAN_SCALE).round() as i32
        } else {
            0
        }
    }

    /// A lane's window half-width, px: `track.window_half_width_px` while tracking; the
    /// refinement of a fresh initialisation may take a wider one
    /// (`track.refine_window_half_width_px`: the Hough line can sit a few pixels off the mark).
    /// A lane on the middle of a double line takes at least twice its half gap, so that its
    /// windows hold both lines (`double_line` module docs); at most
    /// `points::MAX_WINDOW_HALF_WIDTH`.
    pub(super) fn window_half_width(&self, lane: &Lane, pass: Pass) -> i64 {
        let base = match pass {
            Pass::Tracking => self.cfg.track.window_half_width_px,
            Pass::Refinement => self.cfg.track.refine_window_half_width(),
        };
        let pair = (2.0 * lane.pair_half_gap_px).ceil();
        let pair = if pair.is_finite() && pair > 0.0 {
            pair as usize
        } else {
            0
        };
        base.max(pair).min(MAX_WINDOW_HALF_WIDTH) as i64
    }

    /// The ego pair's rules for a pair with a tracked lane in it (the pair gate, and the joint
    /// choice while tracked lanes compete): `[init.ego_pair]`, except that a tracked pair need
    /// only not diverge upwards (top width ≤ bottom width): `max_top_width_ratio` is a margin
    /// for choosing among candidates, and labelled ego pairs on a camera looking down reach a
    /// ratio of 0.92 (`seame`).
    pub(super) fn tracked_pair_rules(&self) -> EgoPairParams {
        EgoPairParams {
            max_top_width_ratio: 1.0,
            ..self.cfg.init.ego_pair
        }
    }
}
