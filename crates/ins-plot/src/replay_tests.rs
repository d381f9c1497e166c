#![allow(clippy::unwrap_used)]
use super::*;
use crate::{PixelArea, Series, panel};

fn sample(t_s: f64, attitude: bool) -> ErrorSample {
    ErrorSample {
        t_s,
        error: std::array::from_fn(|k| {
            if k >= 6 && !attitude {
                f64::NAN
            } else {
                (t_s + k as f64).sin()
            }
        }),
        sigma: [0.5; 9],
    }
}

/// A σ that grows between 1 Hz updates and drops at each (the replay's sawtooth), at 10 Hz
/// rows offset from the epochs as a real log's are.
fn sawtooth_rows(n: usize) -> Vec<SolutionSigma> {
    (0..n)
        .map(|i| {
            let t_s = 0.1 * i as f64 + 0.02;
            let since_update_s = t_s.fract();
            let s = 0.5 + 1.9 * since_update_s;
            SolutionSigma {
                t_s,
                sigma: std::array::from_fn(|k| s * (1.0 + 0.1 * k as f64)),
            }
        })
        .collect()
}

/// The replay figure is a PNG of the figure size, with or without attitude errors or σ.
#[test]
fn the_replay_figure_is_a_png_of_the_figure_size() {
    for attitude in [true, false] {
        let errors: Vec<_> = (0..50)
            .map(|i| sample(0.1 * f64::from(i), attitude))
            .collect();
        for rows in [sawtooth_rows(40), Vec::new()] {
            let png = replay_figure(&errors, &rows, "test").unwrap();
            let img = image::load_from_memory(&png).unwrap();
            assert_eq!((img.width(), img.height()), (WIDTH_PX, HEIGHT_PX));
        }
    }
    // No samples: still a figure.
    assert!(replay_figure(&[], &[], "empty").is_ok());
}

/// The envelopes are ±3σ of each solution row, row by row (not the σ at the compared times);
/// the errors are the compared times'.
#[test]
fn the_envelopes_are_the_solution_rows_sigma_row_by_row() {
    let errors: Vec<_> = (0..30).map(|i| sample(0.25 * f64::from(i), true)).collect();
    let rows = sawtooth_rows(77);
    let t0_s = 0.0;
    for (block, scale) in [(0, 1.0), (1, 1.0), (2, 1e3)] {
        let series = replay_series(&errors, &rows, block, scale, t0_s);
        assert_eq!(series.len(), 9);
        for axis in 0..3 {
            let k = 3 * block + axis;
            let (_, _, error) = &series[3 * axis];
            assert_eq!(error.len(), errors.len());
            for (p, s) in error.iter().zip(&errors) {
                assert_eq!(*p, (s.t_s - t0_s, s.error[k] * scale));
            }
            for (j, sign) in [(1, 1.0), (2, -1.0)] {
                let (_, _, envelope) = &series[3 * axis + j];
                assert_eq!(envelope.len(), rows.len());
                for (p, r) in envelope.iter().zip(&rows) {
                    assert_eq!(*p, (r.t_s - t0_s, sign * 3.0 * r.sigma[k] * scale));
                }
            }
        }
    }
    // Without σ (an unaided run) no envelope; without a reference attitude no ψ error.
    let none = [SolutionSigma {
        t_s: 0.0,
        sigma: [f64::NAN; 9],
    }];
    let series = replay_series(&[sample(0.0, false)], &none, 2, 1e3, 0.0);
    assert!(series.is_empty(), "{series:?}");
}

/// The drawn envelope is the solution file's σ columns: a simulated run's solution CSV read
/// back with `read_solution_sigma` gives, point by point, ±3 × the numbers in its columns.
#[test]
fn the_drawn_envelope_is_the_solution_files_sigma_columns() {
    let dir = std::env::temp_dir().join(format!("ins-plot-envelope-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let sc = ins_sim::Scenario::paper_default().truncated(30.0).unwrap();
    ins_sim::logs::export_run(&sc, ins_sim::Mode::Kf, 3, &dir).unwrap();
    let path = dir.join(ins_sim::logs::names::SOLUTION);
    let rows = ins_sim::logs::read_solution_sigma(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let columns: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').take(20).map(|f| f.parse().unwrap()).collect())
        .collect();
    assert!(columns.len() >= 25, "{} rows", columns.len());
    assert_eq!(rows.len(), columns.len());
    let t0_s = columns[0][0];
    for block in 0..3 {
        let series = replay_series(&[], &rows, block, 1.0, t0_s);
        for axis in 0..3 {
            let col = 11 + 3 * block + axis;
            let (name, _, upper) = &series[2 * axis];
            let (_, _, lower) = &series[2 * axis + 1];
            assert!(name.starts_with("±3σ"), "{name}");
            for ((u, l), c) in upper.iter().zip(lower).zip(&columns) {
                assert_eq!(*u, (c[0] - t0_s, 3.0 * c[col]));
                assert_eq!(*l, (c[0] - t0_s, -3.0 * c[col]));
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Where the σ drops at an update, the envelope's pixels stay inside the plotting area: drawn
/// as one wide path, plotters' mitred joins threw spikes across the whole panel (issue 54).
#[test]
fn no_line_pixel_leaves_the_plotting_area_at_the_updates() {
    let rows = sawtooth_rows(5000);
    let errors: Vec<ErrorSample> = (0..2000)
        .map(|i| {
            let t_s = 0.25 * f64::from(i);
            // A noisy error that turns back on itself from one sample to the next.
            let noise = (((i * 7919) % 1000) as f64 / 500.0 - 1.0) * 2.0;
            ErrorSample {
                t_s,
                error: [noise; 9],
                sigma: [f64::NAN; 9],
            }
        })
        .collect();
    let data: Vec<Series> = replay_series(&errors, &rows, 0, 1.0, 0.0);
    let colours: Vec<RGBColor> = data.iter().map(|(_, c, _)| *c).collect();
    let mut rgb = vec![0u8; (WIDTH_PX * HEIGHT_PX * 3) as usize];
    let (xs, ys): PixelArea = {
        register_font().unwrap();
        let root = BitMapBackend::with_buffer(&mut rgb, (WIDTH_PX, HEIGHT_PX)).into_drawing_area();
        root.fill(&WHITE).unwrap();
        let area = panel(&root, "sawtooth", "position error (m)", 500.0, &data).unwrap();
        root.present().unwrap();
        area
    };
    let mut outside = 0;
    let mut worst = (0, 0);
    for y in 0..HEIGHT_PX as i32 {
        for x in 0..WIDTH_PX as i32 {
            let i = 3 * (y as usize * WIDTH_PX as usize + x as usize);
            let px = RGBColor(rgb[i], rgb[i + 1], rgb[i + 2]);
            if !colours.contains(&px) {
                continue;
            }
            let dy = (ys.start - 2 - y).max(y - (ys.end + 2)).max(0);
            let dx = (xs.start - 2 - x).max(x - (xs.end + 2)).max(0);
            if dx > 0 || dy > 0 {
                outside += 1;
                worst = worst.max((dy, dx));
            }
        }
    }
    assert_eq!(
        outside, 0,
        "{outside} line pixels outside the plotting area {xs:?} × {ys:?}, the farthest {worst:?} px (rows, columns)"
    );
}
