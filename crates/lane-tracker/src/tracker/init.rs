//! Stages I–II, (re-)initialisation: gradient over the whole ROI, then either the paper's Hough
//! line per angle band and least-squares parabola (`hough-init`), or the joint initialisation
//! (crate docs: the strongest lines of both bands, the ego pair chosen together), with the sanity
//! checks that accept a fit.

use hough_init::{
    Chord, HoughLine, LaneInit, Parabola, choose_ego_pair, fit_around_line, init_lane,
};
use info_filter::ParabolaKif;
use nalgebra::Vector3;
use vision_gradient::{EdgeClass, GreyImage, Region, keep_bright_stripes, split_stripes};

use super::points::fit_profile;
use super::{Estimator, LaneFilter, LaneState, LaneTracker};
use crate::TrackerError;
use crate::error::FilterFailure;
use crate::wrls_lane::WrlsLane;

/// The background of a candidate's row coverage is read on the parallel curves this many LS band
/// half-widths to each side (a gap of one band between them and the band of the candidate).
const BACKGROUND_SHIFT_BANDS: f64 = 3.0;

impl LaneTracker {
    pub(super) fn initialise(&mut self, image: &GreyImage<'_>) -> Result<(), TrackerError> {
        let outward = self.outward_col();
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
        if self.cfg.gradient.stripe_paired_votes > 0 {
            split_stripes(
                image,
                &mut self.edges,
                &mut self.paired,
                self.cfg.gradient.stripe_max_width_px,
                self.cfg.gradient.stripe_drop_dark,
            );
        } else {
            keep_bright_stripes(
                image,
                &mut self.edges,
                None,
                self.cfg.gradient.stripe_max_width_px,
                outward,
            );
        }
        if self.cfg.init.candidate_lines > 0 {
            self.initialise_jointly();
            return Ok(());
        }
        for i in 0..2 {
            if self.lanes[i].has_estimate() {
                continue;
            }
            self.fill_candidates(self.lanes[i].class);
            let Ok(init) = init_lane(
                &self.candidates,
                &self.lanes[i].band,
                &mut self.hough,
                &self.init_params,
            ) else {
                continue;
            };
            self.install(i, &init);
        }
        Ok(())
    }

    /// Centre column for `gradient.stripe_keep_outward_steps`.
    pub(super) fn outward_col(&self) -> Option<u16> {
        self.cfg
            .gradient
            .stripe_keep_outward_steps
            .then(|| u16::try_from(self.width / 2).unwrap_or(u16::MAX))
    }

    /// `self.candidates` = the edge pixels of `class` (from the last full-ROI gradient).
    fn fill_candidates(&mut self, class: EdgeClass) {
        self.candidates.clear();
        self.candidates.extend(
            self.edges
                .iter_class(class)
                .map(|p| (f32::from(p.col_px), f32::from(p.row_px))),
        );
        // Weighted stripe pairing: the sides of bright stripes count `stripe_paired_votes`
        // times in all, the other edge pixels once.
        if self.cfg.gradient.stripe_paired_votes > 0 {
            for _ in 1..self.cfg.gradient.stripe_paired_votes {
                self.candidates.extend(
                    self.paired
                        .iter_class(class)
                        .map(|p| (f32::from(p.col_px), f32::from(p.row_px))),
                );
            }
        }
    }

    /// Joint initialisation (`init.candidate_lines > 0`, crate docs): the strongest
    /// `candidate_lines` Hough lines of each band, the ego pair chosen among all of them by
    /// `hough_init::choose_ego_pair` (a lane still tracked is kept in the pair), each chosen
    /// line refined by least squares on the pixels of its own class.
    fn initialise_jointly(&mut self) {
        const MAX_LINES: usize = 8;
        let none = HoughLine {
            rho_px: 0.0,
            theta_rad: 0.0,
            votes: 0,
        };
        let n = self.cfg.init.candidate_lines.min(MAX_LINES);
        let (top, bottom) = self.roi;
        let (yt, yb) = (top as f64, (bottom - 1) as f64);
        let mut lines = [none; 2 * MAX_LINES];
        let mut classes = [EdgeClass::LeftLane; 2 * MAX_LINES];
        let mut chords = [Chord::default(); 2 * MAX_LINES + 1];
        let mut found = [none; MAX_LINES];
        // With `init.candidate_coverage`, each candidate's fit (reused when it is chosen).
        let mut fits: [Option<LaneInit>; 2 * MAX_LINES] = [None; 2 * MAX_LINES];
        let mut m = 0;
        for k in 0..2 {
            let (class, band) = (self.lanes[k].class, self.lanes[k].band);
            self.fill_candidates(class);
            if self.candidates.len() < self.init_params.min_points {
                continue;
            }
            let Ok(count) = self.hough.find_lines(
                &self.candidates,
                &band,
                self.cfg.init.candidate_separation_deg,
                self.cfg.init.candidate_separation_px,
                &mut found[..n],
            ) else {
                continue;
            };
            for line in &found[..count] {
                let chord = if self.cfg.init.candidate_coverage {
                    let Ok(init) = fit_around_line(&self.candidates, *line, &self.init_params)
                    else {
                        continue;
                    };
                    fits[m] = Some(init);
                    let p = init.parabola;
                    Chord {
                        col_top_px: p.col_at_row(yt),
                        col_bottom_px: p.col_at_row(yb),
                        support: self.row_coverage(&p),
                    }
                } else {
                    let (Some(xt), Some(xb)) = (line.col_at_row(yt), line.col_at_row(yb)) else {
                        continue;
                    };
                    Chord {
                        col_top_px: xt,
                        col_bottom_px: xb,
                        support: f64::from(line.votes),
                    }
                };
                lines[m] = *line;
                classes[m] = class;
                chords[m] = chord;
                m += 1;
            }
        }
        let s_max = chords[..m].iter().map(|c| c.support).fold(0.0, f64::max);
        let mut locked = None;
        for (i, lane) in self.lanes.iter().enumerate() {
            if let (true, Some(f)) = (lane.has_estimate(), lane.filter.as_ref()) {
                chords[m] = Chord {
                    col_top_px: f.col_at_row(yt),
                    col_bottom_px: f.col_at_row(yb),
                    support: s_max,
                };
                locked = Some((m, i));
                m += 1;
                break;
            }
        }
        let choice = choose_ego_pair(
            &chords[..m],
            self.width as f64,
            &self.cfg.init.ego_pair,
            locked.map(|(j, _)| j),
        );
        // A tracked lane the choice put on the other side: leave both as they are.
        if let Some((j, i)) = locked
            && [choice.left, choice.right][i] != Some(j)
        {
            return;
        }
        for (i, pick) in [choice.left, choice.right].into_iter().enumerate() {
            let Some(j) = pick else { continue };
            if locked.is_some_and(|(l, _)| l == j) || self.lanes[i].has_estimate() {
                continue;
            }
            self.fill_candidates(classes[j]);
            let init = match fits[j] {
                Some(init) => Ok(init),
                None => fit_around_line(&self.candidates, lines[j], &self.init_params),
            };
            if let Ok(init) = init {
                self.install(i, &init);
            }
        }
    }

    /// Row coverage of parabola `p` (`init.candidate_coverage`), net of the clutter around it:
    /// over the ROI rows, the candidate pixels in `self.candidates` (paired ones repeated) within
    /// the LS band (`±band_half_width_px`) of `p`, at most `2·max(gradient.stripe_paired_votes,
    /// 1)` per row, summed; minus the mean of the same sum for the two parallel curves
    /// `p ± 3·band_half_width_px` (a mark on a clean floor keeps its coverage, a line through
    /// texture or clutter, as dense beside it as on it, loses it); at least 0. Counts in
    /// `self.row_cover` (three per image row); no allocation.
    fn row_coverage(&mut self, p: &Parabola) -> f64 {
        let (top, bottom) = self.roi;
        let band = self.init_params.band_px;
        let shift = BACKGROUND_SHIFT_BANDS * band;
        let cap = 2 * u32::from(self.cfg.gradient.stripe_paired_votes.max(1));
        let h = self.height;
        let cover = &mut self.row_cover;
        cover.fill(0);
        for &(x, y) in &self.candidates {
            let r = f64::from(x) - p.col_at_row(f64::from(y));
            let row = y as usize;
            for (k, offset) in [0.0, shift, -shift].into_iter().enumerate() {
                if (r - offset).abs() <= band
                    && let Some(c) = cover.get_mut(k * h + row)
                {
                    *c = c.saturating_add(1);
                }
            }
        }
        let sum = |k: usize| -> f64 {
            cover
                .get(k * h + top..k * h + bottom)
                .unwrap_or(&[])
                .iter()
                .map(|&c| f64::from(c.min(cap)))
                .sum()
        };
        (sum(0) - 0.5 * (sum(1) + sum(2))).max(0.0)
    }

    /// Accept an initialisation of lane `i` (`self.candidates` holds the pixels it was fitted
    /// to): sanity checks, a fresh filter, the lane's state. `false` if refused.
    fn install(&mut self, i: usize, init: &LaneInit) -> bool {
        let (top, bottom) = self.roi;
        // Sanity: the fit must cover a fair part of the ROI and stay near the image.
        let span_rows = init.rows_px.1 - init.rows_px.0;
        let min_span = 0.25 * (bottom - top) as f64;
        let x_bottom = init.parabola.col_at_row((bottom - 1) as f64);
        let w = self.width as f64;
        if span_rows < min_span || !x_bottom.is_finite() || x_bottom < -w || x_bottom > 2.0 * w {
            return false;
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
                return false;
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
        true
    }
}
