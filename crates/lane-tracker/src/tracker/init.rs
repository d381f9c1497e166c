//! Stages I–II, (re-)initialisation: gradient over the whole ROI, Hough line in the lane's
//! angle band and least-squares parabola (`hough-init`), with the sanity checks that accept it.

use hough_init::init_lane;
use info_filter::ParabolaKif;
use nalgebra::Vector3;
use vision_gradient::{GreyImage, Region};

use super::points::fit_profile;
use super::{Estimator, LaneFilter, LaneState, LaneTracker};
use crate::TrackerError;
use crate::error::FilterFailure;
use crate::wrls_lane::WrlsLane;

impl LaneTracker {
    pub(super) fn initialise(&mut self, image: &GreyImage<'_>) -> Result<(), TrackerError> {
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
                    .map_err(FilterFailure::Kif),
                Estimator::Wrls => {
                    WrlsLane::new(&theta, &self.p0, self.row_norm, self.cfg.filter.wrls_lambda)
                        .map(LaneFilter::Wrls)
                        .map_err(FilterFailure::Wrls)
                }
            };
            let filter = match filter {
                Ok(filter) => filter,
                Err(e) => {
                    self.counters.filter_failures[i] += 1;
                    self.last_failure[i] = Some(e);
                    continue;
                }
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
}
