//! Figures equivalent to the paper's Figs. 1–6 (mean and σ over runs of the position and
//! misalignment errors vs time, per configuration), and our Figs. 7 (NEES/NIS vs their bands)
//! and 8 (3-D RMS position error of every configuration), as SVG and PNG, drawn with plotters.
//!
//! The font, the figure size, the time-series panel and the PNG encoding are crate `ins_plot`'s
//! (shared with the replay's error figure, `nav-app ins --plot`).

use std::error::Error;

use ins_plot::{
    HEIGHT_PX as H, Series, WIDTH_PX as W, encode_png, log_ticks, panel, register_font, segments,
    style_mesh,
};
use plotters::coord::Shift;
use plotters::coord::combinators::BindKeyPoints;
use plotters::prelude::*;

use super::McError;
use super::stats::{ModeStats, Stats, qi};
use ins_sim::Mode;

fn plot_error(
    figure: impl Into<String>,
    source: impl Into<Box<dyn Error + Send + Sync>>,
) -> McError {
    McError::Plot(ins_plot::plot_error(figure, source))
}

/// Mean or σ figure.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Kind {
    /// Mean over runs (paper Figs. 1–3).
    Mean,
    /// Standard deviation over runs (paper Figs. 4–6).
    Sigma,
}

/// The paper's figure number for (mode, kind): 1 stand-alone, 2 AKF, 3 KF (means); 4–6 σ.
pub fn figure_number(mode: Mode, kind: Kind) -> Option<u32> {
    let base = match mode {
        Mode::Standalone => 1,
        Mode::Akf => 2,
        Mode::Kf => 3,
        Mode::AkfSageHusa | Mode::AkfStructured => return None,
    };
    Some(if kind == Kind::Mean { base } else { base + 3 })
}

/// A curve with an owned label.
type Labelled = (String, RGBColor, Vec<(f64, f64)>);

fn series(m: &ModeStats, kind: Kind, qs: [usize; 3], scale: f64) -> Vec<Series> {
    let names = ["N", "E", "D"];
    let colours = [
        RGBColor(0, 90, 180),
        RGBColor(220, 80, 0),
        RGBColor(0, 150, 60),
    ];
    (0..3)
        .map(|k| {
            let pts = m
                .bins
                .iter()
                .enumerate()
                .map(|(t, b)| {
                    let v = match kind {
                        Kind::Mean => b[qs[k]].mean(),
                        Kind::Sigma => b[qs[k]].std_dev(),
                    };
                    (t as f64, scale * v)
                })
                .filter(|(_, v)| v.is_finite())
                .collect();
            (names[k], colours[k], pts)
        })
        .collect()
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    m: &ModeStats,
    kind: Kind,
    title: &str,
) -> Result<(), Box<dyn Error + Send + Sync>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let t_end = m.bins.len().saturating_sub(1) as f64;
    let (upper, lower) = root.split_vertically(H / 2);
    let what = if kind == Kind::Mean { "mean" } else { "σ" };
    panel(
        &upper,
        &format!("{title}: position error, {what} over runs"),
        "position error (m)",
        t_end,
        &series(m, kind, [qi::POS_N, qi::POS_E, qi::POS_D], 1.0),
    )?;
    panel(
        &lower,
        &format!("{title}: misalignment ψ, {what} over runs"),
        "misalignment (mrad)",
        t_end,
        &series(m, kind, [qi::PSI_N, qi::PSI_E, qi::PSI_D], 1e3),
    )?;
    root.present()?;
    Ok(())
}

/// One figure as (SVG text, PNG bytes).
pub fn figure(m: &ModeStats, kind: Kind, runs: u64) -> Result<(String, Vec<u8>), McError> {
    register_font()?;
    let label = match m.mode {
        Mode::Standalone => "Stand-alone INS",
        Mode::Kf => "INS/SD, manually tuned KF",
        Mode::Akf => "INS/SD, adaptive KF",
        other => other.name(),
    };
    let title = format!("{label} ({runs} runs)");
    let mut svg = String::new();
    draw(
        SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area(),
        m,
        kind,
        &title,
    )
    .map_err(|e| plot_error(format!("SVG figure for {}", m.mode), e))?;
    let mut rgb = vec![0u8; (W * H * 3) as usize];
    draw(
        BitMapBackend::with_buffer(&mut rgb, (W, H)).into_drawing_area(),
        m,
        kind,
        &title,
    )
    .map_err(|e| plot_error(format!("PNG figure for {}", m.mode), e))?;
    Ok((svg, encode_png(rgb)?))
}

/// A log-scale panel of several named curves plus optional dashed horizontal band lines.
fn log_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    y_desc: &str,
    t_end: f64,
    data: &[Labelled],
    bands: &[(f64, RGBColor)],
) -> Result<(), Box<dyn Error + Send + Sync>>
where
    DB::ErrorType: 'static,
{
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (_, _, pts) in data {
        for &(_, y) in pts {
            lo = lo.min(y);
            hi = hi.max(y);
        }
    }
    for &(y, _) in bands {
        lo = lo.min(y);
        hi = hi.max(y);
    }
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0) {
        (lo, hi) = (0.1, 10.0);
    }
    let (y0, y1) = (0.8 * lo, 1.25 * hi);
    let (labelled, light) = log_ticks(y0, y1);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .margin_right(36)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(
            0.0..t_end.max(1.0),
            (y0..y1)
                .log_scale()
                .with_key_points(labelled)
                .with_light_points(light),
        )?;
    let mut mesh = chart.configure_mesh();
    style_mesh(&mut mesh);
    mesh.x_desc("time (s)").y_desc(y_desc).draw()?;
    for &(y, c) in bands {
        chart.draw_series(DashedLineSeries::new(
            [(0.0, y), (t_end, y)],
            6,
            4,
            c.stroke_width(1),
        ))?;
    }
    for (name, colour, pts) in data {
        let c = *colour;
        chart
            .draw_series(segments(pts, c.stroke_width(2)))?
            .label(name.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()?;
    Ok(())
}

fn mode_colour(mode: Mode) -> RGBColor {
    match mode {
        Mode::Standalone => RGBColor(120, 120, 120),
        Mode::Kf => RGBColor(0, 90, 180),
        Mode::AkfSageHusa => RGBColor(0, 150, 60),
        Mode::AkfStructured => RGBColor(140, 40, 160),
        Mode::Akf => RGBColor(220, 80, 0),
    }
}

/// Fig. 7 (ours): run-averaged NEES and NIS of the filters vs time with their 95 % bands
/// (dashed) for the number of runs kept.
fn draw_consistency<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    stats: &Stats,
) -> Result<(), Box<dyn Error + Send + Sync>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let t_end = stats
        .modes()
        .first()
        .map_or(1, |m| m.bins.len().saturating_sub(1)) as f64;
    let (upper, lower) = root.split_vertically(H / 2);
    for (area, name, q, dof) in [
        (&upper, "NEES", qi::NEES, super::report::NEES_DOF),
        (&lower, "NIS", qi::NIS, super::report::NIS_DOF),
    ] {
        let mut data = Vec::new();
        let mut bands = Vec::new();
        for m in stats.modes().iter().filter(|m| m.mode != Mode::Standalone) {
            let pts: Vec<(f64, f64)> = m
                .bins
                .iter()
                .enumerate()
                .filter(|(_, b)| b[q].n > 0)
                .map(|(t, b)| (t as f64, b[q].mean()))
                .filter(|(_, v)| v.is_finite() && *v > 0.0)
                .collect();
            if let Some((lo, hi)) = super::report::band(dof, m.runs_used) {
                bands.push((lo, mode_colour(m.mode)));
                bands.push((hi, mode_colour(m.mode)));
            }
            data.push((
                format!("{} ({} runs)", m.mode, m.runs_used),
                mode_colour(m.mode),
                pts,
            ));
        }
        log_panel(
            area,
            &format!(
                "{name} averaged over runs, n = {dof}; dashed: 95 % band of a mean of independent runs"
            ),
            name,
            t_end,
            &data,
            &bands,
        )?;
    }
    root.present()?;
    Ok(())
}

/// Fig. 8 (ours): RMS over runs of the 3-D position error vs time, every configuration.
fn draw_rms<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    stats: &Stats,
) -> Result<(), Box<dyn Error + Send + Sync>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let t_end = stats
        .modes()
        .first()
        .map_or(1, |m| m.bins.len().saturating_sub(1)) as f64;
    let data: Vec<_> = stats
        .modes()
        .iter()
        .map(|m| {
            let pts = m
                .bins
                .iter()
                .enumerate()
                .map(|(t, b)| (t as f64, b[qi::POS_3D].rms()))
                .filter(|(_, v)| v.is_finite() && *v > 0.0)
                .collect();
            (
                format!("{} ({} runs)", m.mode, m.runs_used),
                mode_colour(m.mode),
                pts,
            )
        })
        .collect();
    log_panel(
        &root,
        "3-D position error, RMS over runs",
        "position error (m)",
        t_end,
        &data,
        &[],
    )?;
    root.present()?;
    Ok(())
}

/// Renders one whole-stats figure to (SVG text, PNG bytes).
fn render_both(
    stats: &Stats,
    what: &str,
    f_svg: impl Fn(
        DrawingArea<SVGBackend<'_>, Shift>,
        &Stats,
    ) -> Result<(), Box<dyn Error + Send + Sync>>,
    f_png: impl Fn(
        DrawingArea<BitMapBackend<'_>, Shift>,
        &Stats,
    ) -> Result<(), Box<dyn Error + Send + Sync>>,
) -> Result<(String, Vec<u8>), McError> {
    let mut svg = String::new();
    f_svg(
        SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area(),
        stats,
    )
    .map_err(|e| plot_error(format!("SVG {what}"), e))?;
    let mut rgb = vec![0u8; (W * H * 3) as usize];
    f_png(
        BitMapBackend::with_buffer(&mut rgb, (W, H)).into_drawing_area(),
        stats,
    )
    .map_err(|e| plot_error(format!("PNG {what}"), e))?;
    Ok((svg, encode_png(rgb)?))
}

/// All figures: `(file name, bytes)`, e.g. `fig3_kf_mean.svg`.
// The closures passed to `render_both` are needed: the generic fn items are not general enough
// over the backends' lifetime (higher-ranked bound), which clippy's suggestion ignores.
#[allow(clippy::redundant_closure)]
pub fn figures(stats: &Stats) -> Result<Vec<(String, Vec<u8>)>, McError> {
    let mut out = Vec::new();
    for m in stats.modes() {
        for kind in [Kind::Mean, Kind::Sigma] {
            let Some(n) = figure_number(m.mode, kind) else {
                continue;
            };
            let suffix = if kind == Kind::Mean { "mean" } else { "sigma" };
            let stem = format!("fig{n}_{}_{suffix}", m.mode);
            let (svg, png) = figure(m, kind, m.runs_used)?;
            out.push((format!("{stem}.svg"), svg.into_bytes()));
            out.push((format!("{stem}.png"), png));
        }
    }
    register_font()?;
    if stats
        .modes()
        .iter()
        .any(|m| m.bins.iter().any(|b| b[qi::NEES].n > 0))
    {
        let (svg, png) = render_both(
            stats,
            "NEES/NIS figure",
            |a, s| draw_consistency(a, s),
            |a, s| draw_consistency(a, s),
        )?;
        out.push(("fig7_nees_nis.svg".to_string(), svg.into_bytes()));
        out.push(("fig7_nees_nis.png".to_string(), png));
    }
    let (svg, png) = render_both(
        stats,
        "RMS figure",
        |a, s| draw_rms(a, s),
        |a, s| draw_rms(a, s),
    )?;
    out.push(("fig8_position_rms.svg".to_string(), svg.into_bytes()));
    out.push(("fig8_position_rms.png".to_string(), png));
    Ok(out)
}

/// One point of a sweep figure: the final 3-D error over runs at one swept value.
#[derive(Clone, Debug)]
pub struct SweepPoint {
    /// Configuration.
    pub mode: Mode,
    /// Swept value.
    pub value: f64,
    /// Median final 3-D error, m.
    pub median_m: f64,
    /// 10th and 90th percentiles of the final 3-D error, m.
    pub p10_m: f64,
    /// 90th percentile, m.
    pub p90_m: f64,
}

fn draw_sweep<DB: DrawingBackend>(
    area: DrawingArea<DB, Shift>,
    key: &str,
    runs: u64,
    pts: &[SweepPoint],
) -> Result<(), Box<dyn Error + Send + Sync>>
where
    DB::ErrorType: 'static,
{
    area.fill(&WHITE)?;
    let xs: Vec<f64> = pts.iter().map(|p| p.value).collect();
    let (x0, x1) = xs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let ys: Vec<f64> = pts
        .iter()
        .flat_map(|p| [p.p10_m, p.p90_m, p.median_m])
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    let y0 = ys.iter().copied().fold(f64::INFINITY, f64::min).max(1e-3) / 1.5;
    let y1 = ys.iter().copied().fold(0.0, f64::max).max(y0 * 10.0) * 1.5;
    let pad = if x1 > x0 { 0.05 * (x1 - x0) } else { 1.0 };
    let (labelled, light) = log_ticks(y0, y1);
    let mut chart = ChartBuilder::on(&area)
        .caption(
            format!("Final 3-D position error vs {key} ({runs} runs: median, 10–90 % bars)"),
            ("sans-serif", 22),
        )
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (x0 - pad)..(x1 + pad),
            (y0..y1)
                .log_scale()
                .with_key_points(labelled)
                .with_light_points(light),
        )?;
    let mut mesh = chart.configure_mesh();
    style_mesh(&mut mesh);
    mesh.x_desc(key)
        .y_desc("final 3-D position error (m)")
        .draw()?;
    let mut modes: Vec<Mode> = Vec::new();
    for p in pts {
        if !modes.contains(&p.mode) {
            modes.push(p.mode);
        }
    }
    for mode in modes {
        let c = mode_colour(mode);
        let mine: Vec<&SweepPoint> = pts.iter().filter(|p| p.mode == mode).collect();
        chart
            .draw_series(segments(
                &mine
                    .iter()
                    .map(|p| (p.value, p.median_m.max(y0)))
                    .collect::<Vec<_>>(),
                c.stroke_width(2),
            ))?
            .label(mode.to_string())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        chart.draw_series(
            mine.iter()
                .map(|p| Circle::new((p.value, p.median_m.max(y0)), 4, c.filled())),
        )?;
        for p in &mine {
            chart.draw_series(LineSeries::new(
                [(p.value, p.p10_m.max(y0)), (p.value, p.p90_m.max(y0))],
                c.stroke_width(1),
            ))?;
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 16))
        .draw()?;
    area.present()?;
    Ok(())
}

/// The sweep figure as (SVG text, PNG bytes).
pub fn sweep_figure(
    key: &str,
    runs: u64,
    pts: &[SweepPoint],
) -> Result<(String, Vec<u8>), McError> {
    register_font()?;
    let mut svg = String::new();
    draw_sweep(
        SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area(),
        key,
        runs,
        pts,
    )
    .map_err(|e| plot_error("SVG sweep figure", e))?;
    let mut rgb = vec![0u8; (W * H * 3) as usize];
    draw_sweep(
        BitMapBackend::with_buffer(&mut rgb, (W, H)).into_drawing_area(),
        key,
        runs,
        pts,
    )
    .map_err(|e| plot_error("PNG sweep figure", e))?;
    Ok((svg, encode_png(rgb)?))
}

#[cfg(test)]
#[path = "plot_tests.rs"]
mod tests;
