//! The replay's error figure (`nav-app ins --plot`): the errors of a solution against its
//! reference with their ±3σ envelopes, per axis, for position, velocity and (with a reference
//! attitude) the misalignment ψ.
//!
//! The errors are drawn at the compared times (the reference's rows inside the replay,
//! [`ErrorSample`]); the envelopes at the solution's rows, from the σ columns of the solution
//! file ([`SolutionSigma`]): the envelope is exactly the σ the CSV carries, row by row, so it
//! drops where the CSV's σ drops (a sighting epoch) and never exceeds 3 × the CSV's largest σ.
//! How many rows that is follows `--rate`. Every line is drawn a segment at a time
//! ([`crate::segments`]): plotters' wide paths threw spikes far outside the data at the drops.
//! Time runs from the earlier of the first solution row and the first compared time.

use std::error::Error;

use ins_sim::logs::{ErrorSample, SolutionSigma};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::{HEIGHT_PX, PlotError, Series, WIDTH_PX, encode_png, panel, plot_error, register_font};

const REPLAY_AXES: [(&str, &str, RGBColor, RGBColor); 3] = [
    ("N", "±3σ N", RGBColor(200, 30, 30), RGBColor(240, 160, 160)),
    ("E", "±3σ E", RGBColor(30, 140, 30), RGBColor(150, 215, 150)),
    ("D", "±3σ D", RGBColor(30, 60, 200), RGBColor(150, 170, 240)),
];

/// The curves of one block (0 position, 1 velocity, 2 attitude) of a replay: per axis the
/// error at the compared times (`errors`) and its ±3σ envelope at the solution rows (`rows`),
/// time from `t0_s`, values × `scale`. Order per axis: error, +3σ, −3σ; curves without a finite
/// point are left out.
pub fn replay_series(
    errors: &[ErrorSample],
    rows: &[SolutionSigma],
    block: usize,
    scale: f64,
    t0_s: f64,
) -> Vec<Series> {
    let mut out = Vec::new();
    for (axis, (name, band, colour, light)) in REPLAY_AXES.iter().enumerate() {
        let k = 3 * block + axis;
        let error: Vec<(f64, f64)> = errors
            .iter()
            .filter(|s| s.error[k].is_finite())
            .map(|s| (s.t_s - t0_s, s.error[k] * scale))
            .collect();
        let envelope = |sign: f64| -> Vec<(f64, f64)> {
            rows.iter()
                .filter(|r| r.sigma[k].is_finite())
                .map(|r| (r.t_s - t0_s, sign * 3.0 * r.sigma[k] * scale))
                .collect()
        };
        out.push((*name, *colour, error));
        out.push((*band, *light, envelope(1.0)));
        out.push(("", *light, envelope(-1.0)));
    }
    out.retain(|(_, _, p)| !p.is_empty());
    out
}

/// First and last time of the figure: over the solution rows and the compared times.
fn time_span(errors: &[ErrorSample], rows: &[SolutionSigma]) -> (f64, f64) {
    let times = errors
        .iter()
        .map(|s| s.t_s)
        .chain(rows.iter().map(|r| r.t_s))
        .filter(|t| t.is_finite());
    let (lo, hi) = times.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
        (a.min(t), b.max(t))
    });
    if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) }
}

fn draw_replay<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    errors: &[ErrorSample],
    rows: &[SolutionSigma],
    title: &str,
) -> Result<(), Box<dyn Error + Send + Sync>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (t0_s, t1_s) = time_span(errors, rows);
    let with_attitude = errors.iter().any(|s| s.error[6].is_finite());
    let panels: &[(&str, &str, usize, f64)] = if with_attitude {
        &[
            ("position error", "m", 0, 1.0),
            ("velocity error", "m/s", 1, 1.0),
            ("attitude error ψ", "mrad", 2, 1e3),
        ]
    } else {
        &[
            ("position error", "m", 0, 1.0),
            ("velocity error", "m/s", 1, 1.0),
        ]
    };
    let areas = root.split_evenly((panels.len(), 1));
    for (area, &(what, unit, block, scale)) in areas.iter().zip(panels) {
        let data = replay_series(errors, rows, block, scale, t0_s);
        panel(
            area,
            &format!("{title}: {what}"),
            &format!("{what} ({unit})"),
            t1_s - t0_s,
            &data,
        )?;
    }
    root.present()?;
    Ok(())
}

/// The errors of a replayed solution against its reference (`errors`, at the compared times)
/// with their ±3σ envelopes from the solution's σ columns (`rows`, one per solution row; module
/// docs), for position, velocity, and attitude when the reference has it, as PNG bytes.
///
/// # Errors
/// [`PlotError::Figure`] when drawing or encoding fails.
pub fn replay_figure(
    errors: &[ErrorSample],
    rows: &[SolutionSigma],
    title: &str,
) -> Result<Vec<u8>, PlotError> {
    register_font()?;
    let mut rgb = vec![0u8; (WIDTH_PX * HEIGHT_PX * 3) as usize];
    draw_replay(
        BitMapBackend::with_buffer(&mut rgb, (WIDTH_PX, HEIGHT_PX)).into_drawing_area(),
        errors,
        rows,
        title,
    )
    .map_err(|e| plot_error("replay errors", e))?;
    encode_png(rgb)
}

#[cfg(test)]
#[path = "replay_tests.rs"]
mod tests;
