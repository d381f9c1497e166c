//! Axes and lines that read: tick labels on every axis ([`tick_label`], [`log_ticks`] for log
//! axes), a light grid ([`style_mesh`]) and lines drawn without join artefacts ([`segments`]).
//!
//! - **Log axes.** plotters labels a log axis only at powers of its base, so an axis spanning
//!   less than a decade or two (the run-averaged NIS, 2–15) carried one label or none, and its
//!   light lines at every tenth of a decade read as hatching. [`log_ticks`] labels the powers of
//!   ten when at least three fall inside the range, else the 1-2-5 values, else every 1…9
//!   multiple, else evenly spaced values; the unlabelled 1…9 multiples are the light lines.
//! - **Linear axes.** At most [`MINOR_LINES_PER_MAJOR`] light line between two labelled ticks,
//!   in [`GRID_MINOR`] (plotters' default: up to ten, darker).
//! - **Lines.** plotters turns a path wider than 1 px into one polygon with mitred joins and
//!   fills it even-odd. At a sharp reversal — a σ envelope dropping at an update, a noisy error
//!   line — the inner mitre lies far along the segments, which throws a spike far outside the
//!   data, and where the polygon overlaps itself it is left unfilled, so the line looks broken.
//!   [`segments`] draws each straight piece as its own two-point path: no joins, no spikes.

use plotters::chart::MeshStyle;
use plotters::coord::ranged1d::Ranged;
use plotters::element::PathElement;
use plotters::prelude::*;

/// Colour of the grid lines at the labelled ticks.
pub const GRID_MAJOR: RGBColor = RGBColor(210, 210, 210);
/// Colour of the grid lines between labelled ticks.
pub const GRID_MINOR: RGBColor = RGBColor(238, 238, 238);
/// Light grid lines between two labelled ticks of a linear axis, at most.
pub const MINOR_LINES_PER_MAJOR: usize = 1;
/// Size of the tick labels, px.
pub const TICK_LABEL_PX: u32 = 14;

/// A tick value as text: at most six significant digits, no trailing zeros (`0`, `0.25`,
/// `100`, `-1.5`); exponent form below 10⁻⁴ and from 10⁶ on (`1e-5`, `2e6`).
pub fn tick_label(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v.is_finite() {
            "0".to_string()
        } else {
            format!("{v}")
        };
    }
    let a = v.abs();
    if !(1e-4..1e6).contains(&a) {
        let s = format!("{v:.5e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        return format!("{}e{exponent}", trim_zeros(mantissa));
    }
    let decimals = (5 - a.log10().floor() as i32).clamp(0, 10) as usize;
    let s = trim_zeros(&format!("{v:.decimals$}"));
    if s == "-0" { "0".to_string() } else { s }
}

fn trim_zeros(s: &str) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s.to_string()
    }
}

/// [`tick_label`] in the form plotters' label formatters take.
pub fn tick_label_ref(v: &f64) -> String {
    tick_label(*v)
}

/// Labelled ticks and light grid values of a log axis over `lo..hi` (`0 < lo < hi`): the
/// powers of ten inside when at least three (every k-th when more than eight), else the 1-2-5
/// values, else every 1…9 multiple, else five evenly spaced values; the light values are the
/// 1…9 multiples inside that are not labelled (none over more than eight decades).
pub fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return (Vec::new(), Vec::new());
    }
    let inside = |v: f64| v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12);
    let (e0, e1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let multiples = |ms: &[f64]| -> Vec<f64> {
        (e0..=e1)
            .flat_map(|e| ms.iter().map(move |m| m * 10f64.powi(e)))
            .filter(|&v| inside(v))
            .collect()
    };
    let all = multiples(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    let mut bold = multiples(&[1.0]);
    if bold.len() >= 3 {
        let every = bold.len().div_ceil(8);
        bold = bold.into_iter().step_by(every).collect();
    } else {
        bold = multiples(&[1.0, 2.0, 5.0]);
        if bold.len() < 3 {
            bold.clone_from(&all);
        }
        if bold.len() < 3 {
            let step = (hi - lo) / 4.0;
            bold = (0..5).map(|i| lo + step * f64::from(i)).collect();
        }
    }
    let light = if e1 - e0 > 8 {
        Vec::new()
    } else {
        all.into_iter()
            .filter(|v| !bold.iter().any(|b| (b - v).abs() <= 1e-9 * v.abs()))
            .collect()
    };
    (bold, light)
}

/// The mesh style of every figure: tick labels ([`tick_label`], [`TICK_LABEL_PX`]) on both
/// axes, the grid at the labelled ticks in [`GRID_MAJOR`], at most
/// [`MINOR_LINES_PER_MAJOR`] light line between them in [`GRID_MINOR`].
pub fn style_mesh<'a, 'b, X, Y, DB>(mesh: &mut MeshStyle<'a, 'b, X, Y, DB>)
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
    DB: DrawingBackend,
{
    mesh.label_style(("sans-serif", TICK_LABEL_PX))
        .bold_line_style(GRID_MAJOR.stroke_width(1))
        .light_line_style(GRID_MINOR.stroke_width(1))
        .max_light_lines(MINOR_LINES_PER_MAJOR)
        .x_label_formatter(&tick_label_ref)
        .y_label_formatter(&tick_label_ref);
}

/// `pts` as straight two-point paths in `style`, one per consecutive pair (module docs: a
/// wide path's joins throw spikes and leave holes).
pub fn segments<C: Clone + 'static>(
    pts: &[C],
    style: ShapeStyle,
) -> impl Iterator<Item = PathElement<C>> + '_ {
    pts.windows(2)
        .map(move |w| PathElement::new(vec![w[0].clone(), w[1].clone()], style))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short_and_exact() {
        for (v, s) in [
            (0.0, "0"),
            (-0.0, "0"),
            (100.0, "100"),
            (0.15000000000000002, "0.15"),
            (0.30000000000000004, "0.3"),
            (-1.5, "-1.5"),
            (2.0, "2"),
            (1e-5, "1e-5"),
            (2e6, "2e6"),
            (12345.0, "12345"),
            (0.05, "0.05"),
        ] {
            assert_eq!(tick_label(v), s, "{v}");
        }
    }

    /// The ranges of the Monte Carlo's log axes get at least three labels: NIS (one decade),
    /// NEES, the RMS position error over six decades.
    #[test]
    fn log_axes_get_at_least_three_labelled_ticks() {
        for (lo, hi, want) in [
            (1.5, 15.0, &[2.0, 5.0, 10.0][..]),
            (2.4, 25.0, &[5.0, 10.0, 20.0][..]),
            (0.02, 2e4, &[0.1, 1.0, 10.0, 100.0, 1000.0, 10000.0][..]),
            (3.0, 9.5, &[3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0][..]),
        ] {
            let (bold, light) = log_ticks(lo, hi);
            assert_eq!(bold.len(), want.len(), "{lo}..{hi}: {bold:?}");
            for (b, w) in bold.iter().zip(want) {
                assert!((b - w).abs() < 1e-9 * w, "{lo}..{hi}: {bold:?}");
            }
            assert!(light.iter().all(|v| (lo..=hi).contains(v)));
            assert!(light.iter().all(|v| !bold.contains(v)));
        }
        // Narrower than one step of the 1…9 multiples: evenly spaced.
        let (bold, _) = log_ticks(2.1, 2.9);
        assert_eq!(bold.len(), 5);
        assert!((bold[0] - 2.1).abs() < 1e-12 && (bold[4] - 2.9).abs() < 1e-12);
        // Many decades: at most eight labels, no light lines.
        let (bold, light) = log_ticks(1e-3, 1e12);
        assert!((3..=8).contains(&bold.len()), "{bold:?}");
        assert!(light.is_empty());
        assert_eq!(log_ticks(0.0, 1.0), (Vec::new(), Vec::new()));
    }
}
