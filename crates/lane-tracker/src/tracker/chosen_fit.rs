//! The least-squares fit of a chosen Hough line (`hough_init::fit_around_line`) read from the
//! candidate pixels near the line instead of all of them: the same fit, bit for bit, its passes
//! running over a fraction of the pixels (gathering them is one scan of the edge pixels).

use hough_init::{
    HoughError, HoughLine, LaneInit, MIN_WHERE_COS, Parabola, fit_around_line,
    fit_around_line_where,
};
use vision_gradient::EdgeClass;

use super::candidates::{CandidateIndex, candidate_sources, counts_as};
use super::edges::EdgeStage;
use super::setup::{Rows, Setup};

/// How far beyond its own band a chosen line's candidate pixels are gathered for its fit, in
/// bands of `init.band_half_width_px` (`CandidateIndex::fit_chosen_line`): a selection of the fit
/// that reaches farther, to a pixel left out, has the full set fitted instead.
const CHOSEN_LINE_REACH_BANDS: f64 = 5.0;

impl CandidateIndex {
    /// `hough_init::fit_around_line` of a chosen `line` on the candidate pixels of `class`,
    /// leaving in `self.candidates` the pixels it was fitted on (`install` reads them): first on
    /// those within the line's band plus [`CHOSEN_LINE_REACH_BANDS`] bands of
    /// `init.band_half_width_px` of its columns, in their order in the full set — the same fit
    /// bit for bit as long as no selection of the fit reaches a pixel left out
    /// (`hough_init::fit_around_line_where`, asked row by row against the nearest pixels left
    /// out on each side), its passes running over a fraction of the pixels — else on the full set.
    pub(super) fn fit_chosen_line(
        &mut self,
        edges: &EdgeStage,
        class: EdgeClass,
        line: HoughLine,
        rows: Rows,
        setup: &Setup,
    ) -> Result<LaneInit, HoughError> {
        if let Some(init) = self.fit_chosen_line_near(edges, class, line, rows, setup)? {
            return Ok(init);
        }
        self.fill(edges, class, setup);
        fit_around_line(&self.candidates, line, &setup.init_params)
    }

    /// [`Self::fit_chosen_line`]'s fit on the pixels near the line, `None` where a selection
    /// of the fit reaches a pixel left out (or the line is degenerate).
    pub(super) fn fit_chosen_line_near(
        &mut self,
        edges: &EdgeStage,
        class: EdgeClass,
        line: HoughLine,
        rows: Rows,
        setup: &Setup,
    ) -> Result<Option<LaneInit>, HoughError> {
        let band_px = setup.init_params.band_px;
        // (A line `fit_around_line_where` would not fit on a subset is fitted on the full set.)
        let Some((line_cols, cos_abs)) = line.columns(MIN_WHERE_COS) else {
            return Ok(None);
        };
        let reach_px = band_px / cos_abs + CHOSEN_LINE_REACH_BANDS * band_px;
        self.fill_near(edges, class, &line_cols, reach_px, rows, setup);
        let (top, bottom) = rows;
        let left_out = &self.left_out_cols;
        // Whether no pixel left out lies within `h` (and half a pixel, for rounding) of the
        // curve `c` on any row: the nearest ones on each side are farther.
        let complete = |c: &Parabola, h: f64| {
            (top..bottom).all(|r| {
                let Some(&(left, right)) = left_out.get(r) else {
                    return true;
                };
                let x = c.col_at_row(r as f64);
                f64::from(left) < x - h - 0.5 && f64::from(right) > x + h + 0.5
            })
        };
        fit_around_line_where(&self.candidates, line, &setup.init_params, complete)
    }

    /// [`Self::fill`] restricted to the pixels within `reach_px` columns of the line
    /// `line_cols` (its column by row), in the same order (`candidates::candidate_sources`); `self.left_out_cols[r]` = the columns of
    /// the nearest candidate pixels of row `r` left out on each side (`±∞` without one), over
    /// the rows searched. No allocation (a subset of what `fill` holds).
    fn fill_near(
        &mut self,
        edges: &EdgeStage,
        class: EdgeClass,
        line_cols: &Parabola,
        reach_px: f64,
        rows: Rows,
        setup: &Setup,
    ) {
        self.candidates.clear();
        let (top, bottom) = rows;
        if let Some(rows) = self.left_out_cols.get_mut(top..bottom) {
            rows.fill((f32::NEG_INFINITY, f32::INFINITY));
        }
        let near_vertical = setup.near_vertical_either_class();
        let votes = setup.cfg.gradient.stripe_paired_votes;
        for pixels in candidate_sources(&edges.edges, &edges.paired, votes) {
            for row in pixels.chunk_by(|a, b| a.row_px == b.row_px) {
                let Some(first) = row.first() else { continue };
                let centre = line_cols.col_at_row(f64::from(first.row_px));
                let Some(left_out) = self.left_out_cols.get_mut(usize::from(first.row_px)) else {
                    continue;
                };
                for p in row.iter().filter(|p| counts_as(p, class, near_vertical)) {
                    let offset = f64::from(p.col_px) - centre;
                    let col = f32::from(p.col_px);
                    if offset.abs() <= reach_px {
                        self.candidates.push((col, f32::from(p.row_px)));
                    } else if offset < 0.0 {
                        left_out.0 = left_out.0.max(col);
                    } else {
                        left_out.1 = left_out.1.min(col);
                    }
                }
            }
        }
    }
}
