//! # ins-plot — drawing the INS figures
//!
//! What the Monte Carlo's figures (crate `ins-monte-carlo`) and the replay's error figure
//! (`nav-app ins --plot`, [`replay_figure`]) share: the bundled font ([`register_font`]), the
//! figure size ([`WIDTH_PX`] × [`HEIGHT_PX`]), the time-series [`panel`] and the PNG encoding
//! ([`encode_png`]). A replay's figure thus needs no Monte Carlo.
//!
//! Text needs a font: plotters' `ab_glyph` feature with DejaVu Sans bundled in
//! `crates/ins-plot/assets/` (Bitstream Vera licence, `DejaVuSans-LICENSE.txt` beside it), so
//! PNGs and SVGs carry the same labels and no system font is looked up. PNGs are rendered into
//! an RGB buffer (plotters' bitmap backend without its own encoder) and encoded with the
//! workspace's `image` crate.

use std::error::Error;
use std::sync::Once;

use ins_sim::logs::ErrorSample;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

/// A figure that could not be drawn or encoded.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Drawing or encoding the figure failed.
    #[error("figure {figure}")]
    Figure {
        /// The figure, e.g. `fig3_kf_mean`, `sweep` or `replay errors`.
        figure: String,
        /// The plotting or PNG layer's error.
        #[source]
        source: Box<dyn Error + Send + Sync>,
    },
}

/// The error for `figure` caused by `source`.
pub fn plot_error(
    figure: impl Into<String>,
    source: impl Into<Box<dyn Error + Send + Sync>>,
) -> PlotError {
    PlotError::Figure {
        figure: figure.into(),
        source: source.into(),
    }
}

static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// Width of every figure, pixels.
pub const WIDTH_PX: u32 = 1000;
/// Height of every figure, pixels.
pub const HEIGHT_PX: u32 = 760;

/// Registers the bundled font as `sans-serif` (once per process).
///
/// # Errors
/// [`PlotError::Figure`] (`(font)`) when the bundled font cannot be parsed.
pub fn register_font() -> Result<(), PlotError> {
    let mut err = None;
    REGISTER.call_once(|| {
        if plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_err() {
            err = Some(plot_error(
                "(font)",
                "the bundled DejaVu Sans font could not be parsed",
            ));
        }
    });
    err.map_or(Ok(()), Err)
}

/// A curve: its legend label (empty: none), colour and points (time s, value).
pub type Series = (&'static str, RGBColor, Vec<(f64, f64)>);

/// The value range of `all`, padded by 5 % (−1…1 when empty).
pub fn y_range(all: &[Series]) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (_, _, pts) in all {
        for &(_, y) in pts {
            lo = lo.min(y);
            hi = hi.max(y);
        }
    }
    if !lo.is_finite() || !hi.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = 0.05 * (hi - lo).max(1e-9 * hi.abs().max(1e-9));
    (lo - pad, hi + pad)
}

/// One time-series panel: `data` over 0…`t_end` s with its caption, the y axis named
/// `y_desc`, and a legend of the labelled curves.
///
/// # Errors
/// The drawing backend's.
pub fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    y_desc: &str,
    t_end: f64,
    data: &[Series],
) -> Result<(), Box<dyn Error + Send + Sync>>
where
    DB::ErrorType: 'static,
{
    let (lo, hi) = y_range(data);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .margin_right(36)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(0.0..t_end.max(1.0), lo..hi)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc(y_desc)
        .label_style(("sans-serif", 14))
        .draw()?;
    for (name, colour, pts) in data {
        let c = *colour;
        let drawn = chart.draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(2)))?;
        if !name.is_empty() {
            drawn.label(*name).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
            });
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()?;
    Ok(())
}

/// A [`WIDTH_PX`] × [`HEIGHT_PX`] RGB buffer as PNG bytes.
///
/// # Errors
/// [`PlotError::Figure`] (`PNG`) for a buffer of another size or an encoder failure.
pub fn encode_png(rgb: Vec<u8>) -> Result<Vec<u8>, PlotError> {
    let img = image::RgbImage::from_raw(WIDTH_PX, HEIGHT_PX, rgb)
        .ok_or_else(|| plot_error("PNG", "the pixel buffer has the wrong size"))?;
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| plot_error("PNG", e))?;
    Ok(png)
}

const REPLAY_AXES: [(&str, &str, RGBColor, RGBColor); 3] = [
    ("N", "±3σ N", RGBColor(200, 30, 30), RGBColor(240, 160, 160)),
    ("E", "±3σ E", RGBColor(30, 140, 30), RGBColor(150, 215, 150)),
    ("D", "±3σ D", RGBColor(30, 60, 200), RGBColor(150, 170, 240)),
];

/// The curves of one block (0 position, 1 velocity, 2 attitude) of a replay: the error on each
/// axis and its ±3σ envelope, time from the first sample, values × `scale`.
fn replay_series(series: &[ErrorSample], block: usize, scale: f64) -> Vec<Series> {
    let t0 = series.first().map_or(0.0, |s| s.t_s);
    let mut out = Vec::new();
    for (axis, (name, band, colour, light)) in REPLAY_AXES.iter().enumerate() {
        let k = 3 * block + axis;
        let pts = |f: &dyn Fn(&ErrorSample) -> f64| -> Vec<(f64, f64)> {
            series
                .iter()
                .filter(|s| f(s).is_finite())
                .map(|s| (s.t_s - t0, f(s) * scale))
                .collect()
        };
        out.push((*name, *colour, pts(&|s| s.error[k])));
        out.push((*band, *light, pts(&|s| 3.0 * s.sigma[k])));
        out.push(("", *light, pts(&|s| -3.0 * s.sigma[k])));
    }
    out.retain(|(_, _, p)| !p.is_empty());
    out
}

fn draw_replay<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    series: &[ErrorSample],
    title: &str,
    with_attitude: bool,
) -> Result<(), Box<dyn Error + Send + Sync>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let t_end = match (series.first(), series.last()) {
        (Some(a), Some(b)) => b.t_s - a.t_s,
        _ => 1.0,
    };
    let panels: Vec<(&str, &str, usize, f64)> = if with_attitude {
        vec![
            ("position error", "m", 0, 1.0),
            ("velocity error", "m/s", 1, 1.0),
            ("attitude error ψ", "mrad", 2, 1e3),
        ]
    } else {
        vec![
            ("position error", "m", 0, 1.0),
            ("velocity error", "m/s", 1, 1.0),
        ]
    };
    let areas = root.split_evenly((panels.len(), 1));
    for (area, (what, unit, block, scale)) in areas.iter().zip(panels) {
        let data = replay_series(series, block, scale);
        panel(
            area,
            &format!("{title}: {what}"),
            &format!("{what} ({unit})"),
            t_end,
            &data,
        )?;
    }
    root.present()?;
    Ok(())
}

/// The errors of a replayed solution against its reference with their ±3σ envelopes (position,
/// velocity, and attitude when the reference has it), as PNG bytes.
///
/// # Errors
/// [`PlotError::Figure`] when drawing or encoding fails.
pub fn replay_figure(series: &[ErrorSample], title: &str) -> Result<Vec<u8>, PlotError> {
    register_font()?;
    let with_attitude = series.iter().any(|s| s.error[6].is_finite());
    let mut rgb = vec![0u8; (WIDTH_PX * HEIGHT_PX * 3) as usize];
    draw_replay(
        BitMapBackend::with_buffer(&mut rgb, (WIDTH_PX, HEIGHT_PX)).into_drawing_area(),
        series,
        title,
        with_attitude,
    )
    .map_err(|e| plot_error("replay errors", e))?;
    encode_png(rgb)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// The replay figure is a PNG of the figure size, with or without attitude errors.
    #[test]
    fn the_replay_figure_is_a_png_of_the_figure_size() {
        let sample = |t_s: f64, attitude: bool| ErrorSample {
            t_s,
            error: std::array::from_fn(|k| {
                if k >= 6 && !attitude {
                    f64::NAN
                } else {
                    (t_s + k as f64).sin()
                }
            }),
            sigma: [0.5; 9],
        };
        for attitude in [true, false] {
            let series: Vec<_> = (0..50)
                .map(|i| sample(0.1 * f64::from(i), attitude))
                .collect();
            let png = replay_figure(&series, "test").unwrap();
            let img = image::load_from_memory(&png).unwrap();
            assert_eq!((img.width(), img.height()), (WIDTH_PX, HEIGHT_PX));
        }
        // No samples: still a figure.
        assert!(replay_figure(&[], "empty").is_ok());
    }
}
