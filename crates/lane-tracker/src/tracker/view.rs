//! # The working view: which input pixels each working pixel stands for
//!
//! Each axis of the working frame is an affine view of the input's (module `working` for why,
//! module `road` for where the rows come from). Working pixel `j` of an axis stands for the
//! input interval `[start + s·j, start + s·(j + 1))` (input pixel `i` covering `[i, i + 1)`),
//! centred on input coordinate
//!
//! ```text
//! v = s·j + o,   o = start + (s − 1)/2,
//! ```
//!
//! with `s > 0` input pixels per working pixel. The columns have `s_x = w / W` and `start = 0`;
//! the rows the same scale and start by default (`s_y = s_x`: square pixels, the working frame
//! the input's top-left), or, when the road is found to end above the frame's bottom (a bonnet
//! or a dashboard in view; module `road`), the rows of the road stretched over the working
//! frame's height (`start = 0`, `s_y = bottom / H'`).
//!
//! A working-frame parabola `x' = b1·y'² + b2·y' + b3` is, in input pixels (`x = s_x·x' + o_x`,
//! `y' = (y − o_y)/s_y`),
//!
//! ```text
//! x = (s_x·b1/s_y²)·(y − o_y)² + (s_x·b2/s_y)·(y − o_y) + s_x·b3 + o_x
//!   ⇒ a1 = s_x·b1/s_y²,
//!     a2 = s_x·b2/s_y − 2·o_y·s_x·b1/s_y²,
//!     a3 = s_x·b1·o_y²/s_y² − s_x·b2·o_y/s_y + s_x·b3 + o_x,
//! ```
//!
//! the affine map `a = T·b + t`,
//!
//! ```text
//!     ⎡  s_x/s_y²            0           0  ⎤        ⎡  0  ⎤
//! T = ⎢ −2·o_y·s_x/s_y²      s_x/s_y     0  ⎥,   t = ⎢  0  ⎥,   Cov(a) = T·Cov(b)·Tᵀ,
//!     ⎣  o_y²·s_x/s_y²      −o_y·s_x/s_y s_x ⎦        ⎣ o_x ⎦
//! ```
//!
//! which for square pixels (`s_x = s_y = s`, `o_x = o_y = o`) is module `working`'s.

use nalgebra::{Matrix3, Vector3};
use vision_gradient::ColSpan;

use super::report::{FarSegment, LaneReport};
use super::setup::Rows;

/// One axis of the view: working pixel `j` stands for input `[start + s·j, start + s·(j + 1))`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AxisMap {
    /// Input pixels per working pixel, > 0.
    pub(crate) scale: f64,
    /// Input coordinate of working pixel 0's leading edge, px.
    pub(crate) start_px: f64,
}

impl AxisMap {
    /// This axis as the resampling kernel takes it (`vision_gradient::AxisSpan`, the same
    /// convention: its `centre_px` is [`Self::to_input_px`]).
    pub(crate) fn span(self) -> vision_gradient::AxisSpan {
        vision_gradient::AxisSpan {
            scale: self.scale,
            start_px: self.start_px,
        }
    }

    /// `o = start + (s − 1)/2`, px: the input coordinate of working pixel 0's centre.
    pub(crate) fn offset_px(self) -> f64 {
        self.start_px + (self.scale - 1.0) / 2.0
    }

    /// A working coordinate `v'` in input pixels: `s·v' + o`.
    pub(crate) fn to_input_px(self, working_px: f64) -> f64 {
        self.scale * working_px + self.offset_px()
    }

    /// The working pixel whose interval holds input pixel `v` (its leading edge), if any.
    pub(crate) fn working_px(self, input_px: usize) -> Option<usize> {
        let j = (input_px as f64 - self.start_px) / self.scale + 1e-9;
        (j >= 0.0).then(|| j.floor() as usize)
    }

    /// The input edge of working edge `j`: `start + s·j`.
    fn input_edge(self, j: usize) -> f64 {
        self.start_px + self.scale * j as f64
    }
}

/// The view of both axes (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct WorkingView {
    pub(crate) cols: AxisMap,
    pub(crate) rows: AxisMap,
}

impl WorkingView {
    /// Square pixels of `s` input pixels, from the input's top-left.
    pub(crate) fn square(s: f64) -> Self {
        let axis = AxisMap {
            scale: s,
            start_px: 0.0,
        };
        WorkingView {
            cols: axis,
            rows: axis,
        }
    }

    /// `true` when the working frame is the input itself.
    pub(crate) fn is_identity(self) -> bool {
        self == Self::square(1.0)
    }

    /// `s` when the view is square from the top-left with a whole `s ≥ 2`: the working frame is
    /// then the box average over `s × s` blocks.
    pub(crate) fn whole_factor(self) -> Option<usize> {
        let s = self.cols.scale;
        (self == Self::square(s) && s >= 2.0 && s.fract() == 0.0).then_some(s as usize)
    }

    /// `T` of the module docs.
    fn coeff_map(self) -> Matrix3<f64> {
        let (sx, sy, oy) = (self.cols.scale, self.rows.scale, self.rows.offset_px());
        let k = sx / (sy * sy);
        Matrix3::new(
            k,
            0.0,
            0.0,
            -2.0 * oy * k,
            sx / sy,
            0.0,
            oy * oy * k,
            -oy * sx / sy,
            sx,
        )
    }

    /// Working-frame coefficients `[b1, b2, b3]` as input-pixel `[a1, a2, a3]`: `T·b + t`.
    pub(crate) fn coeffs_to_input(self, b: [f64; 3]) -> [f64; 3] {
        let a = self.coeff_map() * Vector3::from(b);
        [a[0], a[1], a[2] + self.cols.offset_px()]
    }

    /// A lane's report with its coefficients and rows in input pixels.
    pub(crate) fn report_to_input(self, mut report: LaneReport) -> LaneReport {
        report.coeffs = report.coeffs.map(|b| self.coeffs_to_input(b));
        report.rows = report.rows.map(|r| self.rows.to_input_px(r));
        report.far = report.far.map(|far| FarSegment {
            coeffs: self.coeffs_to_input(far.coeffs),
            rows: far.rows.map(|r| self.rows.to_input_px(r)),
        });
        report
    }

    /// A covariance of working-frame coefficients as one of input-pixel coefficients:
    /// `T·P·Tᵀ`.
    pub(crate) fn cov_to_input(self, p: &Matrix3<f64>) -> Matrix3<f64> {
        let t = self.coeff_map();
        t * p * t.transpose()
    }

    /// A working-frame window span as the input columns it covers, `[⌊start + s·c0⌋,
    /// ⌈start + s·c1⌉)`.
    pub(crate) fn span_to_input(self, span: ColSpan) -> ColSpan {
        // `end ≤ working width`, so the input column ≤ input width ≤ u16::MAX (`MAX_SIDE_PX`).
        let col = |c: f64| u16::try_from(c.max(0.0) as u64).unwrap_or(u16::MAX);
        ColSpan {
            col_start_px: col(self.cols.input_edge(usize::from(span.col_start_px)).floor()),
            col_end_px: col((self.cols.input_edge(usize::from(span.col_end_px)) - 1e-9).ceil()),
        }
    }

    /// Working rows `[first, end)` as the input rows they stand for, their edges rounded, the
    /// end at most `input_height_px`.
    pub(crate) fn rows_to_input(self, rows: Rows, input_height_px: usize) -> Rows {
        let edge = |r: usize| self.rows.input_edge(r).round().max(0.0) as usize;
        (
            edge(rows.0).min(input_height_px),
            edge(rows.1).min(input_height_px),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parabola(c: [f64; 3], y: f64) -> f64 {
        c[0] * y * y + c[1] * y + c[2]
    }

    fn views() -> Vec<WorkingView> {
        let mut v: Vec<WorkingView> = [2.0, 3.0, 4.0, 5.0, 1.6, 0.8, 5.125]
            .into_iter()
            .map(WorkingView::square)
            .collect();
        // Rows stretched (a bonnet cut off) and shifted.
        v.push(WorkingView {
            cols: AxisMap {
                scale: 1.6,
                start_px: 0.0,
            },
            rows: AxisMap {
                scale: 1.1,
                start_px: 0.0,
            },
        });
        v.push(WorkingView {
            cols: AxisMap {
                scale: 1.0,
                start_px: 0.0,
            },
            rows: AxisMap {
                scale: 0.7,
                start_px: 12.5,
            },
        });
        v
    }

    #[test]
    fn mapped_coefficients_pass_through_the_mapped_points() {
        // A working-frame parabola's point (x', y') is the input point (s_x·x' + o_x,
        // s_y·y' + o_y).
        for view in views() {
            let b = [0.0031, -0.42, 97.5];
            let a = view.coeffs_to_input(b);
            for y_w in [0.0, 17.0, 60.5, 179.0] {
                let x_in = view.cols.to_input_px(parabola(b, y_w));
                let y_in = view.rows.to_input_px(y_w);
                assert!(
                    (parabola(a, y_in) - x_in).abs() < 1e-9,
                    "{view:?}, y' = {y_w}"
                );
            }
        }
    }

    #[test]
    fn the_mapped_covariance_is_the_covariance_of_mapped_samples() {
        // Cov(T·b + t) = T·Cov(b)·Tᵀ, checked against the sample covariance of coefficients
        // drawn around a mean and mapped one by one (a fixed lattice: no randomness needed).
        let mean = [0.002, 0.3, 150.0];
        let steps = [1e-4, 0.05, 2.0];
        let mut samples = Vec::new();
        for i in -2i32..=2 {
            for j in -2i32..=2 {
                for k in -2i32..=2 {
                    // Correlated through the sum in the last coordinate.
                    let d = [
                        f64::from(i) * steps[0],
                        f64::from(j) * steps[1],
                        f64::from(k + i) * steps[2],
                    ];
                    samples.push([mean[0] + d[0], mean[1] + d[1], mean[2] + d[2]]);
                }
            }
        }
        let cov = |pts: &[[f64; 3]]| {
            let n = pts.len() as f64;
            let m: [f64; 3] = std::array::from_fn(|r| pts.iter().map(|p| p[r]).sum::<f64>() / n);
            Matrix3::from_fn(|r, c| {
                pts.iter()
                    .map(|p| (p[r] - m[r]) * (p[c] - m[c]))
                    .sum::<f64>()
                    / n
            })
        };
        for view in views() {
            let mapped: Vec<[f64; 3]> = samples.iter().map(|&b| view.coeffs_to_input(b)).collect();
            let want = cov(&mapped);
            let got = view.cov_to_input(&cov(&samples));
            for r in 0..3 {
                for c in 0..3 {
                    let tol = 1e-9 * want[(r, c)].abs().max(1e-12);
                    assert!(
                        (got[(r, c)] - want[(r, c)]).abs() <= tol,
                        "{view:?} ({r}, {c})"
                    );
                }
            }
        }
    }

    #[test]
    fn spans_cover_the_input_columns_of_their_working_columns() {
        let span = |s: f64| {
            let c = WorkingView::square(s).span_to_input(ColSpan {
                col_start_px: 10,
                col_end_px: 21,
            });
            (c.col_start_px, c.col_end_px)
        };
        assert_eq!(span(4.0), (40, 84));
        // Input columns [16, 33.6): every column any of the working columns reads.
        assert_eq!(span(1.6), (16, 34));
    }

    #[test]
    fn an_input_row_falls_in_the_working_row_whose_interval_holds_it() {
        let rows = AxisMap {
            scale: 1.6,
            start_px: 0.0,
        };
        assert_eq!(rows.working_px(0), Some(0));
        assert_eq!(rows.working_px(1), Some(0));
        assert_eq!(rows.working_px(2), Some(1));
        assert_eq!(rows.working_px(16), Some(10));
        let shifted = AxisMap {
            scale: 1.0,
            start_px: 5.0,
        };
        assert_eq!(shifted.working_px(4), None);
        assert_eq!(shifted.working_px(5), Some(0));
    }
}
