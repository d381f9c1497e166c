//! # ins-plot — drawing the INS figures
//!
//! What the Monte Carlo's figures (crate `ins-monte-carlo`) and the replay's error figure
//! (`nav-app ins --plot`, [`replay_figure`]) share: the bundled font ([`register_font`]), the
//! figure size ([`WIDTH_PX`] × [`HEIGHT_PX`]), the time-series [`panel`], the axes, grid and
//! lines (module [`axes`]: tick labels on every axis, a light grid, lines without join
//! artefacts) and the PNG encoding ([`encode_png`]). A replay's figure thus needs no Monte
//! Carlo.
//!
//! Text needs a font: plotters' `ab_glyph` feature with DejaVu Sans bundled in
//! `crates/ins-plot/assets/` (Bitstream Vera licence, `DejaVuSans-LICENSE.txt` beside it), so
//! PNGs and SVGs carry the same labels and no system font is looked up. PNGs are rendered into
//! an RGB buffer (plotters' bitmap backend without its own encoder) and encoded with the
//! workspace's `image` crate.

use std::error::Error;
use std::sync::Once;

use std::ops::Range;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

pub mod axes;
mod replay;

pub use axes::{log_ticks, segments, style_mesh, tick_label};
pub use replay::{replay_figure, replay_series};

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

/// The pixel ranges (columns, rows) of a panel's plotting area, inside its axes.
pub type PixelArea = (Range<i32>, Range<i32>);

/// One time-series panel: `data` over 0…`t_end` s with its caption, the y axis named
/// `y_desc`, and a legend of the labelled curves; returns the plotting area's pixels.
///
/// # Errors
/// The drawing backend's.
pub fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    y_desc: &str,
    t_end: f64,
    data: &[Series],
) -> Result<PixelArea, Box<dyn Error + Send + Sync>>
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
    let mut mesh = chart.configure_mesh();
    style_mesh(&mut mesh);
    mesh.x_desc("time (s)").y_desc(y_desc).draw()?;
    for (name, colour, pts) in data {
        let c = *colour;
        let drawn = chart.draw_series(segments(pts, c.stroke_width(2)))?;
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
    Ok(chart.plotting_area().get_pixel_range())
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
