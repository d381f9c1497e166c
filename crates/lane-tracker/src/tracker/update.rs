//! Stage III, measurement update and gates: the filter update (KIF eqs. 6, 12 or WRLS eqs.
//! 25–27), the jump gate, misses, and the crossing gate between the two lanes.

use hough_init::{EgoPairParams, pair_shape_is_plausible};
use vision_gradient::{GreyImage, Region, keep_bright_stripes};

use super::points::{fit_profile, weighted_scatter};
use super::{Lane, LaneFilter, LaneState, LaneTracker};
use crate::error::FilterFailure;
use crate::{TrackerConfig, TrackerError};

impl LaneTracker {
    /// One frame of lane `i` in its windows: prediction (when `predict`), windows, gradient
    /// inside them, point selection, update and jump gate. A lane that cannot be updated is
    /// a miss, not an error.
    pub(super) fn track_lane(
        &mut self,
        i: usize,
        image: &GreyImage<'_>,
        predict: bool,
    ) -> Result<(), TrackerError> {
        let Some(coeffs) = self.predict_windows(i, predict) else {
            return Ok(());
        };
        self.detector.detect(
            image,
            Region::Spans(&self.lanes[i].spans),
            &mut self.edges,
            None,
        )?;
        // Stripe pairing that drops unpaired pixels (`gradient.stripe_paired_votes = 0`) applies
        // in the windows too; with weighted pairing the windows keep every pixel.
        let stripe_px = if self.cfg.gradient.stripe_paired_votes > 0 {
            0
        } else {
            self.cfg.gradient.stripe_max_width_px
        };
        let outward = self.outward_col();
        keep_bright_stripes(&mut self.edges, stripe_px, outward);
        self.select_points(
            i,
            image,
            coeffs,
            self.window_half_width(i, predict),
            !predict,
        );
        if self.lanes[i].points.len() < self.cfg.track.reinit_min_points {
            Self::miss(&mut self.lanes[i], &self.cfg);
            return Ok(());
        }
        self.update_and_gate(i, coeffs);
        Ok(())
    }

    /// The measurement update of lane `i` with its selected points, then the jump gate at the
    /// top and bottom rows searched (the ROI's, or the taller rows of a lane tracked there).
    fn update_and_gate(&mut self, i: usize, coeffs: [f64; 3]) {
        let (top, bottom) = self.search_rows;
        let mark_centres = self.cfg.track.mark_centres;
        let lane = &mut self.lanes[i];
        let Some(filter) = lane.filter.as_mut() else {
            return;
        };
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
                .map_err(FilterFailure::Kif)
            }
            LaneFilter::Wrls(wl) => wl.update(&lane.points).map_err(FilterFailure::Wrls),
        };
        if let Err(e) = updated {
            self.counters.filter_failures[i] += 1;
            self.last_failure[i] = Some(e);
            lane.filter.clone_from(&lane.predicted);
            Self::miss(lane, &self.cfg);
            return;
        }
        // Jump gate at the top and bottom rows searched.
        let (Some(new), Some(pred)) = (lane.filter.as_ref(), lane.predicted.as_ref()) else {
            return;
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
            return;
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

    /// The ego pair's rules for a pair with a tracked lane in it (the pair gate, and the joint
    /// choice while tracked lanes compete): `[init.ego_pair]`, except that a tracked pair need
    /// only not diverge upwards (top width ≤ bottom width): `max_top_width_ratio` is a margin for
    /// choosing among candidates, and labelled ego pairs on a camera looking down reach a ratio
    /// of 0.92 (`seame`).
    pub(super) fn tracked_pair_rules(&self) -> EgoPairParams {
        EgoPairParams {
            max_top_width_ratio: 1.0,
            ..self.cfg.init.ego_pair
        }
    }

    /// The pair gate (joint initialisation only, `init.candidate_lines > 0`): two tracked lanes
    /// whose chords over the ROI rows no longer have the shape of an ego lane have lost at
    /// least one boundary to something else — and which one cannot be told from the pair
    /// alone. Both are dropped, and the joint initialisation that follows on the same frame
    /// chooses the pair again among all candidates. The shape is
    /// `hough_init::pair_shape_is_plausible` with [`Self::tracked_pair_rules`] (the width at the
    /// bottom ROI row, in order below the ROI's top `meet_top_frac`, not diverging upwards).
    /// Returns whether the pair was dropped.
    pub(super) fn pair_gate(&mut self) -> bool {
        if self.cfg.init.candidate_lines == 0 {
            return false;
        }
        let [l, r] = &self.lanes;
        let (Some(lf), Some(rf)) = (l.filter.as_ref(), r.filter.as_ref()) else {
            return false;
        };
        if !(l.has_estimate() && r.has_estimate()) {
            return false;
        }
        let (top, bottom) = self.search_rows;
        let (yt, yb) = (top as f64, (bottom - 1) as f64);
        let (left, right) = (lf.chord(yt, yb, 0.0), rf.chord(yt, yb, 0.0));
        if pair_shape_is_plausible(&left, &right, self.width as f64, &self.tracked_pair_rules()) {
            return false;
        }
        self.counters.gated_pairs += 1;
        for lane in &mut self.lanes {
            lane.drop_estimate();
        }
        true
    }

    /// Left and right lanes may not cross below the top `init.ego_pair.meet_top_frac` of the ROI
    /// rows (at the top row when it is 0: where the vanishing point may lie, as for the ego
    /// pair's choice), nor come closer than `min_lane_separation_px` at the middle and bottom
    /// ROI rows. The offending estimate is the one that changed on this
    /// frame by initialisation, else the one backed by fewer points; it is undone. The gate
    /// compares the edges the filters track: a kerb's offset (`init.kerb_foot`, at most
    /// `gradient.stripe_max_width_px + 1` px towards the road) is not part of it.
    pub(super) fn crossing_gate(&mut self) {
        let [l, r] = &self.lanes;
        let (Some(lf), Some(rf)) = (l.filter.as_ref(), r.filter.as_ref()) else {
            return;
        };
        if !(l.has_estimate() && r.has_estimate()) {
            return;
        }
        let (top, bottom) = self.search_rows;
        let sep = self.cfg.track.min_lane_separation_px;
        // Lanes converge towards the horizon: at the row `meet_top_frac` of the ROI down (the top
        // row for 0) they need only be in order, at the middle and bottom rows `sep` apart.
        let meet = self.cfg.init.ego_pair.meet_top_frac;
        let rows = [
            (top as f64 + meet * (bottom - 1 - top) as f64, 0.0),
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
        if let Some(before) = lane.replaced.take() {
            // A switch to another candidate (re-validation), or a lane set aside and replaced
            // by the frame's searches: the tracked lane comes back as it was after this frame's
            // update (or miss).
            lane.restore(before);
            let c = &mut self.counters;
            c.initialisations[victim] = c.initialisations[victim].saturating_sub(1);
            c.revalidation_switches[victim] = c.revalidation_switches[victim].saturating_sub(1);
        } else if lane.initialised_now {
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
