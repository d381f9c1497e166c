//! Every axis of every figure carries tick labels, read from the SVG text: each panel at least
//! three numbers on its time (or swept-value) axis and three on its value axis (issue 54: the
//! NIS axis of fig7, a log axis over one decade, had one label).
#![allow(clippy::unwrap_used)]

use super::*;
use crate::{RunOptions, Silent, resolve, simulate_stats};

/// A text element of an SVG: position, anchor and content (rotated texts, the axis names, left
/// out).
struct Text {
    y: f64,
    anchor: String,
    text: String,
}

fn texts(svg: &str) -> Vec<Text> {
    let attr = |tag: &str, name: &str| -> Option<String> {
        let start = tag.find(&format!(" {name}=\""))? + name.len() + 3;
        let end = tag[start..].find('"')? + start;
        Some(tag[start..end].to_string())
    };
    svg.split("<text")
        .skip(1)
        .filter_map(|chunk| {
            let (tag, rest) = chunk.split_once('>')?;
            let (content, _) = rest.split_once("</text>")?;
            if tag.contains("rotate(") {
                return None;
            }
            Some(Text {
                y: attr(tag, "y")?.parse().ok()?,
                anchor: attr(tag, "text-anchor").unwrap_or_default(),
                text: content.trim().to_string(),
            })
        })
        .collect()
}

/// Per panel (one row of numeric x labels each, top to bottom): the numeric x labels and the
/// numeric y labels above that row and below the previous one.
fn labels_per_panel(svg: &str) -> Vec<(Vec<String>, Vec<String>)> {
    let numeric: Vec<Text> = texts(svg)
        .into_iter()
        .filter(|t| t.text.parse::<f64>().is_ok())
        .collect();
    let mut rows: Vec<f64> = numeric
        .iter()
        .filter(|t| t.anchor == "middle")
        .map(|t| t.y)
        .collect();
    rows.sort_by(f64::total_cmp);
    rows.dedup();
    let mut previous = f64::NEG_INFINITY;
    rows.iter()
        .map(|&row| {
            let x: Vec<String> = numeric
                .iter()
                .filter(|t| t.anchor == "middle" && t.y == row)
                .map(|t| t.text.clone())
                .collect();
            let y: Vec<String> = numeric
                .iter()
                .filter(|t| t.anchor == "end" && t.y > previous && t.y < row)
                .map(|t| t.text.clone())
                .collect();
            previous = row;
            (x, y)
        })
        .collect()
}

fn check(name: &str, svg: &str, panels: usize) {
    let per_panel = labels_per_panel(svg);
    assert_eq!(per_panel.len(), panels, "{name}: panels");
    for (i, (x, y)) in per_panel.iter().enumerate() {
        assert!(x.len() >= 3, "{name} panel {i}: x labels {x:?}");
        assert!(y.len() >= 3, "{name} panel {i}: y labels {y:?}");
    }
}

#[test]
fn every_axis_of_every_figure_carries_tick_labels() {
    let paper =
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../configs/paper.toml");
    let out = std::env::temp_dir().join(format!("nav-app-mc-ticks-{}", std::process::id()));
    let opts = RunOptions {
        runs: Some(2),
        duration_s: Some(60.0),
        threads: Some(1),
        seed: Some(77),
        ..RunOptions::new(paper, out)
    };
    let stats = simulate_stats(&resolve(&opts).unwrap(), &Silent).unwrap();
    let figs = figures(&stats).unwrap();
    let svgs: Vec<_> = figs.iter().filter(|(n, _)| n.ends_with(".svg")).collect();
    assert_eq!(svgs.len(), 8, "fig1–fig8");
    for (name, bytes) in svgs {
        let svg = std::str::from_utf8(bytes).unwrap();
        check(name, svg, if name.starts_with("fig8") { 1 } else { 2 });
    }
    let pts: Vec<SweepPoint> = [5.0, 10.0, 20.0, 40.0]
        .iter()
        .flat_map(|&value| {
            [(Mode::Kf, 1.2), (Mode::Akf, 3.0)].map(|(mode, m)| SweepPoint {
                mode,
                value,
                median_m: m * value.sqrt(),
                p10_m: 0.8 * m * value.sqrt(),
                p90_m: 1.3 * m * value.sqrt(),
            })
        })
        .collect();
    let (svg, _) = sweep_figure("filter.akf_window", 2, &pts).unwrap();
    check("sweep", &svg, 1);
}
